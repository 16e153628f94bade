"""Snapshot files without pickle: bit-identical restores, and files that cannot be restored
(another version, another scene, a class not allowed, damaged) refused with the scene unchanged."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_snapshot import Tag, build, run, state_hash  # noqa: I001  (tests/ is on sys.path)

from framework import InvalidValue, Transform
from framework.snapshot_file import load_snapshot, save_snapshot


def test_a_saved_file_restores_bit_identically_into_a_scene_built_the_same_way(tmp_path):
    s = build(11)
    run(s, 25)
    path = tmp_path / "save.npz"
    assert save_snapshot(s, path) == ()
    first = run(s, 90)
    other = build(12, bodies=2)
    load_snapshot(other, path)
    assert run(other, 90) == first


@settings(max_examples=10, deadline=None)
@given(st.integers(0, 10_000), st.integers(0, 40))
def test_random_scenes_round_trip_through_files(tmp_path_factory, seed, before):
    path = tmp_path_factory.mktemp("snap") / "s.npz"
    s = build(seed, bodies=8)
    run(s, before)
    save_snapshot(s, path)
    first = run(s, 30)
    other = build(seed + 7, bodies=3)
    load_snapshot(other, path)
    assert run(other, 30) == first


def test_the_platformer_saves_and_loads(tmp_path):
    from examples.platformer import Game
    from examples.platformer.components import GameState

    g = Game()
    for k in range(200):
        g.step({"right"} if k % 50 < 40 else {"space", "right"})
    path = tmp_path / "game.npz"
    skipped = save_snapshot(g.scene, path)
    assert skipped == ("examples.platformer.game.Game",)  # it holds the levels: classes not allowed in a file

    def play(game):
        out = []
        for k in range(150):
            game.step({"left"} if k % 40 < 20 else {"space"})
            out.append(state_hash(game.scene))
        return out

    first = play(g)
    fresh = Game()
    load_snapshot(fresh.scene, path)
    assert fresh.scene.resources[GameState] is fresh.state
    assert play(fresh) == first
    g.close()
    fresh.close()


def _meta(path):
    with np.load(path, allow_pickle=False) as npz:
        return {k: npz[k] for k in npz.files}


def _rewrite(path, arrays):
    with open(path, "wb") as f:
        np.savez(f, **arrays)


def _edit_meta(path, change):
    arrays = _meta(path)
    meta = json.loads(arrays["__meta__"].tobytes())
    change(meta)
    arrays["__meta__"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    _rewrite(path, arrays)


@pytest.fixture
def saved(tmp_path):
    s = build(13)
    run(s, 10)
    path = tmp_path / "s.npz"
    save_snapshot(s, path)
    target = build(14, bodies=4)
    run(target, 5)
    return path, target, state_hash(target)


def _refused(path, target, before, match):
    with pytest.raises(InvalidValue, match=match):
        load_snapshot(target, path)
    assert state_hash(target) == before


def test_another_version_or_scene_is_refused(saved):
    path, target, before = saved
    _edit_meta(path, lambda m: m.__setitem__("framework", "0.0.1"))
    _refused(path, target, before, "another version")
    _edit_meta(path, lambda m: (m.__setitem__("framework", __import__("framework").__version__),
                                m.__setitem__("version", 99)))
    _refused(path, target, before, "another version")
    _edit_meta(path, lambda m: (m.__setitem__("version", 1), m["shape"][0].pop()))
    _refused(path, target, before, "another shape")


def test_a_class_that_is_not_allowed_is_refused_and_nothing_runs(saved, tmp_path):
    path, target, before = saved
    marker = tmp_path / "ran"

    def plant(meta):
        meta["state"] = {"O": [0, "os:system", [["x", f"touch {marker}"]]]}

    _edit_meta(path, plant)
    _refused(path, target, before, "class 'os:system' is not allowed")
    _edit_meta(path, lambda m: m.__setitem__("state", {"C": "builtins:eval"}))
    _refused(path, target, before, "is not allowed")
    assert not marker.exists()


def test_damaged_files_are_refused(saved, tmp_path):
    path, target, before = saved
    data = path.read_bytes()
    for i, damaged in enumerate([data[: len(data) // 2], b"not a zip at all", b"", data[:100] + b"\x00" * 64]):
        bad = tmp_path / f"bad{i}.npz"
        bad.write_bytes(damaged)
        _refused(bad, target, before, "not a snapshot file")
    pickled = tmp_path / "pickled.npz"
    with open(pickled, "wb") as f:
        np.savez(f, __meta__=np.array([{"format": "framework-snapshot"}], dtype=object))
    _refused(pickled, target, before, "not a snapshot file")  # an object array: allow_pickle=False refuses it
    _edit_meta(path, lambda m: m.__setitem__("state", {"L": [0, [{"R": 5}]]}))
    _refused(path, target, before, "not a snapshot file this scene can take")
    _edit_meta(path, lambda m: m.__setitem__("state", {"Q": 1}))
    _refused(path, target, before, "unknown tag")


def test_a_file_over_the_size_limit_is_refused_before_inflating(saved, tmp_path):
    path, target, before = saved
    bomb = tmp_path / "bomb.npz"
    with zipfile.ZipFile(bomb, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("__meta__.npy", b"\x00" * (64 * 1024 * 1024))  # 64 MiB of zeros: a few KB compressed
    assert bomb.stat().st_size < 1024 * 1024
    with pytest.raises(InvalidValue, match="more than the limit"):
        load_snapshot(target, bomb, max_bytes=16 * 1024 * 1024)
    assert state_hash(target) == before


def test_an_unsaveable_component_is_named(tmp_path):
    class Local:  # a class the scene does not have as a component: not allowed in a file
        pass

    s = build(15, bodies=2)
    e = s.spawn(Transform(0.0, 0.0), Tag(0))
    s.get(e, Tag).n = Local()
    with pytest.raises(InvalidValue, match=rf"entity {e}: its Tag component cannot be saved in a snapshot file"):
        save_snapshot(s, tmp_path / "x.npz")
    save_snapshot(s, tmp_path / "x.npz", allow=[Local])  # allowed on purpose
