"""Replays: recorded input round-trips through a file, drives a scene exactly like a keyboard, and
bad files are refused with a ValueError naming the file and the line."""

from __future__ import annotations

import json
import math

import pytest

from framework import AABB, Hitbox, Scene, Transform, Velocity
from framework.input import Input
from framework.replay import FORMAT, VERSION, Replay

FRAMES = [[], ["right"], ["right", "space"], ["right", "space"], ["left"], [], ["a", "f1", "shift"]]


def test_round_trip_keeps_frames_dt_seed_and_meta(tmp_path):
    r = Replay(FRAMES, dt=1 / 120, seed=12345, meta={"level": "1-1", "version": [0, 1], "note": "é"})
    path = tmp_path / "run.replay"
    r.save(path)
    back = Replay.load(path)
    assert back == r and len(back) == len(FRAMES)
    assert back.frames[2] == frozenset({"right", "space"}) and back.dt == 1 / 120 and back.seed == 12345
    assert back.meta == {"level": "1-1", "version": [0, 1], "note": "é"}
    lines = path.read_text(encoding="utf-8").splitlines()
    assert json.loads(lines[0]) == {"format": FORMAT, "version": VERSION, "dt": 1 / 120, "seed": 12345,
                                    "frames": len(FRAMES), "meta": r.meta}
    assert lines[3] == '["right", "space"]'  # one frame a line, keys sorted
    path2 = tmp_path / "again.replay"
    back.save(path2)
    assert path2.read_bytes() == path.read_bytes()  # same replay, same bytes


def test_empty_replay_and_defaults_round_trip(tmp_path):
    r = Replay()
    r.save(tmp_path / "empty.replay")
    assert Replay.load(tmp_path / "empty.replay") == r
    assert r.dt == 1 / 60 and r.seed is None and r.meta == {} and len(r) == 0


def test_record_then_apply_drives_input_like_a_keyboard():
    r = Replay()
    for keys in (["right"], ["right", "space"], []):
        r.record(keys)
    with Scene() as s:
        inp = s.resources[Input]
        r.apply(s, 0)
        assert inp.held == {"right"} and inp.pressed == {"right"}
        s.step(r.dt)
        r.apply(s, 1)
        assert inp.held == {"right", "space"} and inp.pressed == {"space"} and not inp.released
        s.step(r.dt)
        r.apply(s, 2)
        assert inp.held == set() and inp.released == {"right", "space"}
        with pytest.raises(ValueError, match="frame"):
            r.apply(s, 3)
        with pytest.raises(ValueError, match="frame"):
            r.apply(s, -1)
        del s.resources[Input]
        r.apply(s, 0)  # a scene without an Input resource gets one
        assert s.resources[Input].held == {"right"}


def test_playing_a_replay_twice_gives_the_same_run():
    r = Replay([["right"]] * 20 + [["right", "up"]] * 10 + [[]] * 30, dt=1 / 60, seed=3)

    def run() -> list[tuple[float, float]]:
        with Scene(gravity=(0.0, -10.0)) as s:
            s.spawn(Transform(0.0, -0.5), Hitbox(AABB(100.0, 1.0), body="static"))
            p = s.spawn(Transform(0.0, 0.5), Velocity(), Hitbox(AABB(1.0, 1.0)))

            def control(scene, dt):
                keys, v = scene.resources[Input], scene.get(p, Velocity)
                v.x = 4.0 if keys.is_held("right") else 0.0
                if keys.was_pressed("up"):
                    v.y = 6.0

            s.add_system(control, before="movement")
            out = []
            for i in range(len(r)):
                r.play(s, i, i + 1)
                t = s.get(p, Transform)
                out.append((t.x, t.y))
            return out

    a, b = run(), run()
    assert a == b and a[-1][0] > 1.9 and max(y for _, y in a) > 1.0


@pytest.mark.parametrize("kwargs,match", [
    (dict(frames=["right"]), "list of key names"),
    (dict(frames=[[1]]), "non-empty string"),
    (dict(frames=[[""]]), "non-empty string"),
    (dict(frames=[["a", "a"]]), "twice"),
    (dict(dt=0), "dt"), (dict(dt=math.nan), "dt"), (dict(dt="1/60"), "dt"), (dict(dt=True), "dt"),
    (dict(seed=1.5), "seed"), (dict(seed=True), "seed"),
    (dict(meta=[]), "meta"), (dict(meta={1: 2}), "meta"), (dict(meta={"x": math.inf}), "meta"),
    (dict(meta={"x": object()}), "meta"),
])
def test_bad_replay_values_are_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        Replay(**kwargs)


HEADER = {"format": FORMAT, "version": VERSION, "dt": 0.0625, "seed": 1, "frames": 1, "meta": {}}


def _header(**changes) -> str:
    h = dict(HEADER, **changes)
    return json.dumps({k: v for k, v in h.items() if v is not _DROP})


_DROP = object()

BAD_FILES = {
    "empty": ("", "empty"),
    "not json": ("{format: replay}\n[]\n", "line 1: not JSON"),
    "not a header": ('["right"]\n', "line 1: not a replay header"),
    "other format": (_header(format="savegame") + "\n[]\n", "not a replay header"),
    "future version": (_header(version=2) + "\n[]\n", "unsupported replay version 2"),
    "unknown field": (_header(speed=2) + "\n[]\n", "unknown header fields"),
    "zero dt": (_header(dt=0) + "\n[]\n", "dt must be"),
    "NaN dt": (_header(dt=_DROP)[:-1] + ', "dt": NaN}\n[]\n', "not JSON"),
    "string seed": (_header(seed="7") + "\n[]\n", "seed must be"),
    "missing count": (_header(frames=_DROP) + "\n[]\n", "frames must be"),
    "truncated": (_header(frames=3) + "\n[]\n", "promises 3 frames but the file has 1"),
    "extra frame": (_header() + "\n[]\n[]\n", "promises 1 frames but the file has 2"),
    "frame not a list": (_header() + '\n{"right": true}\n', "line 2: a frame must be a list"),
    "frame not json": (_header() + "\n[right]\n", "line 2: not JSON"),
    "key not a string": (_header() + "\n[3]\n", "line 2: a key name must be a non-empty string"),
    "key twice": (_header() + '\n["a", "a"]\n', "line 2: a key is listed twice"),
    "blank frame line": (_header(frames=2) + "\n[]\n\n", "line 3: not JSON"),
    "meta not an object": (_header(meta=[1]) + "\n[]\n", "meta must be an object"),
}


@pytest.mark.parametrize("case", sorted(BAD_FILES))
def test_bad_files_are_refused_naming_the_file(tmp_path, case):
    text, match = BAD_FILES[case]
    path = tmp_path / f"{case.replace(' ', '_')}.replay"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ValueError, match=match) as info:
        Replay.load(path)
    assert str(path) in str(info.value)


def test_binary_and_missing_files(tmp_path):
    path = tmp_path / "noise.replay"
    path.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(ValueError, match="not UTF-8") as info:
        Replay.load(path)
    assert str(path) in str(info.value)
    with pytest.raises(FileNotFoundError):
        Replay.load(tmp_path / "nowhere.replay")


def test_save_never_leaves_a_half_written_file(tmp_path):
    path = tmp_path / "run.replay"
    Replay(FRAMES).save(path)
    bad = Replay(FRAMES)
    bad.meta["x"] = object()  # slipped past the constructor
    with pytest.raises(TypeError):
        bad.save(path)
    assert Replay.load(path) == Replay(FRAMES)  # the old file is intact
