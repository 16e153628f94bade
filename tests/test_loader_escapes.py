"""Loader escapes (issue 34, item 3): values in a file from a stranger that made a loader raise
something other than its own documented error, or hang. Each test gives the loader the value
that escaped and asserts the loader's error type and that its message names the file.

Found by replacing the numbers and literals of valid files with hostile values (``10**400``, an
int of 4,301 digits, ``'²'``, ``'--2'``): see ``tests/test_fuzz.py``'s hostile-value tests.
"""

from __future__ import annotations

import json
import struct
import time
from pathlib import Path

import pytest

from examples.platformer.levels import LevelError, builtin_levels, load_level
from framework import InvalidValue
from framework.replay import Replay
from framework.sprites import MAX_FRAMES, Animation, Frame, SpriteSheet

HUGE = 10**400               # beyond float64: float() raises OverflowError
DIGITS = "1" * 4301          # beyond Python's int max str digits: int() raises ValueError


def _level() -> dict:
    return json.loads(builtin_levels()[2].read_text())


def _objects(level: dict) -> list[dict]:
    return next(layer for layer in level["layers"] if layer["type"] == "objectgroup")["objects"]


def _refused(path: Path, load, error: type[BaseException]) -> str:
    """``load()`` raises exactly the loader's error (not a subclass of something else) naming ``path``."""
    with pytest.raises(error) as info:
        load()
    assert type(info.value) is error, f"{type(info.value).__name__}: {info.value}"
    assert path.name in str(info.value), str(info.value)
    return str(info.value)


# --- Tiled maps ----------------------------------------------------------------------------------------


def test_a_tile_size_beyond_float64_is_a_level_error(tmp_path):
    level = _level()
    level["tilewidth"] = level["tileheight"] = HUGE
    path = tmp_path / "tile.tmj"
    path.write_text(json.dumps(level))
    assert "too large for a float64" in _refused(path, lambda: load_level(path), LevelError)


def test_an_object_x_beyond_float64_is_a_level_error(tmp_path):
    level = _level()
    _objects(level)[0]["x"] = HUGE
    path = tmp_path / "x.tmj"
    path.write_text(json.dumps(level))
    assert "'x' must be a finite number" in _refused(path, lambda: load_level(path), LevelError)


def test_a_platform_dx_beyond_float64_is_a_level_error(tmp_path):
    level = _level()
    platform = next(o for o in _objects(level) if o["type"] == "platform")
    next(p for p in platform["properties"] if p["name"] == "dx")["value"] = HUGE
    path = tmp_path / "dx.tmj"
    path.write_text(json.dumps(level))
    assert "dx must be a number" in _refused(path, lambda: load_level(path), LevelError)


def test_an_int_of_more_than_4300_digits_is_a_level_error(tmp_path):
    path = tmp_path / "digits.tmj"
    path.write_text(json.dumps(_level()).replace('"width": 66', f'"width": {DIGITS}', 1))
    assert DIGITS in path.read_text()
    assert "4300 digits" in _refused(path, lambda: load_level(path), LevelError)


def test_a_map_whose_tile_count_has_more_than_4300_digits_is_a_level_error(tmp_path):
    """width x height of 8,000 digits could not even be printed in the limit's message."""
    path = tmp_path / "area.tmj"
    path.write_text(json.dumps({"width": 10**4000, "height": 10**4000, "tilewidth": 1, "tileheight": 1,
                                "layers": []}))
    _refused(path, lambda: load_level(path), LevelError)


def test_a_layer_nested_near_the_recursion_limit_is_a_level_error(tmp_path):
    """A value the decoder just managed to read is shown in the message without a RecursionError."""
    import sys

    for depth in range(sys.getrecursionlimit() - 60, sys.getrecursionlimit() + 10, 7):
        path = tmp_path / f"deep{depth}.tmj"
        path.write_text('{"width": 1, "height": 1, "tilewidth": 8, "tileheight": 8, "layers": ['
                        + "[" * depth + "]" * depth + "]}")
        _refused(path, lambda p=path: load_level(p), LevelError)


# --- replays -------------------------------------------------------------------------------------------


def _replay_file(path: Path, **header) -> Path:
    head = {"format": "framework-replay", "version": 1, "dt": 0.5, "seed": 1, "frames": 1, "meta": {}} | header
    path.write_text(json.dumps(head) + "\n" + '["left"]\n')
    return path


def test_a_replay_dt_beyond_float64_is_refused(tmp_path):
    path = _replay_file(tmp_path / "dt.jsonl", dt=HUGE)
    message = _refused(path, lambda: Replay.load(path), InvalidValue)
    assert "dt must be a finite number > 0" in message and len(message) < 300


@pytest.mark.parametrize("field, value", [("seed", DIGITS), ("frames", DIGITS), ("dt", DIGITS), ("version", DIGITS)])
def test_a_replay_header_int_of_more_than_4300_digits_is_refused(tmp_path, field, value):
    path = tmp_path / "digits.jsonl"
    path.write_text(json.dumps({"format": "framework-replay", "version": 1, "dt": 0.5, "seed": 1, "frames": 1,
                                "meta": {}}).replace(f'"{field}": ', f'"{field}": {value}, "x{field}": ') + "\n[]\n")
    assert "4300 digits" in _refused(path, lambda: Replay.load(path), InvalidValue)


def test_a_replay_frame_of_unicode_digits_or_odd_values_is_refused_or_loaded_as_names(tmp_path):
    path = tmp_path / "keys.jsonl"
    path.write_text(json.dumps({"format": "framework-replay", "version": 1, "dt": 0.5, "seed": 1, "frames": 3,
                                "meta": {}}) + '\n["\u00b2", "\u0663"]\n[]\n[-0.0]\n')
    assert "key name must be a non-empty string" in _refused(path, lambda: Replay.load(path), InvalidValue)
    path.write_text(path.read_text().replace("[-0.0]", '["--2"]'))
    assert list(Replay.load(path)) == [frozenset({"\u00b2", "\u0663"}), frozenset(), frozenset({"--2"})]


def test_replay_frames_read_fast_still_refuse_what_they_refused(tmp_path):
    """The fast path (one scanner call and C-speed checks a distinct line) refuses what the checks did."""
    head = json.dumps({"format": "framework-replay", "version": 1, "dt": 0.5, "seed": None, "frames": 1, "meta": {}})
    for line, why in [('["a", "a"]', "listed twice"), ('["a", ""]', "non-empty string"), ('["a", 1]', "non-empty"),
                      ('["a", ["b"]]', "non-empty"), ('{"a": 1}', "a frame must be a list"), ('"a"', "must be a list"),
                      ('["a"] ["b"]', "not JSON"), ('[NaN]', "not JSON"), ("[1e999]", "non-empty"),
                      ('["a",', "not JSON"), ("", "not JSON")]:
        path = tmp_path / "f.jsonl"
        path.write_text(head + "\n" + line + "\n")
        assert why in _refused(path, lambda p=path: Replay.load(p), InvalidValue), line
    path.write_text(head + "\n" + ' ["b", "a"] \r\n')  # whitespace around a frame: read as before
    assert list(Replay.load(path)) == [frozenset({"a", "b"})]


# --- golden traces -------------------------------------------------------------------------------------


def _golden(tmp_path: Path) -> tuple[object, Path, dict]:
    from framework import Circle, Hitbox, Transform, Velocity
    from framework.testing import check_golden, text_scene

    def ball(scene, x, y, tile):
        return scene.spawn(Transform(x, y), Velocity(2.0, 0.0), Hitbox(Circle(0.4)))

    def scene():
        return text_scene("#....#\n#.O..#\n######", {"O": ball}).scene

    path = tmp_path / "g.json"
    check_golden(scene(), path, 3, update=True)
    return scene, path, json.loads(path.read_text())


def _check(scene_of, path: Path):
    from framework.testing import check_golden

    scene = scene_of()
    try:
        check_golden(scene, path, 3, update=False)
    finally:
        scene.close()


def test_a_golden_value_beyond_float64_is_refused(tmp_path):
    scene_of, path, golden = _golden(tmp_path)
    body = next(iter(golden["trace"][0]["bodies"]))
    golden["trace"][0]["bodies"][body][0] = HUGE
    path.write_text(json.dumps(golden))
    assert "not a golden trace" in _refused(path, lambda: _check(scene_of, path), InvalidValue)


@pytest.mark.parametrize("key", ["\u00b2", "--2", "\u0663", "-", "1" * 5000, "+1", " 1"])
def test_a_golden_entity_key_that_int_does_not_read_is_refused(tmp_path, key):
    scene_of, path, golden = _golden(tmp_path)
    bodies = golden["trace"][1]["bodies"]
    body = next(iter(bodies))
    bodies[key] = bodies.pop(body)
    path.write_text(json.dumps(golden))
    assert "not a golden trace" in _refused(path, lambda: _check(scene_of, path), InvalidValue)


@pytest.mark.parametrize("field, value", [("dt", HUGE), ("steps", HUGE), ("format", HUGE)])
def test_a_golden_header_beyond_float64_is_refused(tmp_path, field, value):
    scene_of, path, golden = _golden(tmp_path)
    golden[field] = value
    path.write_text(json.dumps(golden))
    message = _refused(path, lambda: _check(scene_of, path), InvalidValue)
    assert len(message) < 600


def test_a_golden_value_of_more_than_4300_digits_is_refused(tmp_path):
    scene_of, path, golden = _golden(tmp_path)
    path.write_text(json.dumps(golden).replace('"steps":3', f'"steps":{DIGITS}').replace('"steps": 3',
                                                                                         f'"steps": {DIGITS}'))
    assert "4300 digits" in _refused(path, lambda: _check(scene_of, path), InvalidValue)


# --- tilesets (SpriteSheet.from_tiled) -----------------------------------------------------------------


def _png(path: Path, width: int, height: int) -> Path:
    """A PNG's signature and header (all ``image_size`` reads): the 24 bytes a stranger controls."""
    header = b"\x89PNG\r\n\x1a\n\x00\x00\x00\x0dIHDR" + struct.pack(">II", width, height)
    path.write_bytes(header + b"\x08\x06\x00\x00\x00")
    return path


def test_a_tileset_animation_duration_beyond_float64_is_refused(tmp_path):
    _png(tmp_path / "s.png", 32, 16)
    path = tmp_path / "dur.tsj"
    path.write_text(json.dumps({"image": "s.png", "tilewidth": 16, "tileheight": 16, "tiles": [
        {"id": 0, "animation": [{"tileid": 0, "duration": 100}, {"tileid": 1, "duration": HUGE}]}]}))
    assert "finite number of milliseconds" in _refused(path, lambda: SpriteSheet.from_tiled(path), InvalidValue)


def test_a_55_byte_tileset_declaring_2_31_one_pixel_tiles_is_refused_at_once(tmp_path):
    """It hung: a Frame was made for each of the 2**31 tiles the image's header declared."""
    _png(tmp_path / "i.png", 2**31 - 1, 1)
    path = tmp_path / "t.tsj"
    path.write_text('{"image":"i.png","tilewidth":1,"tileheight":1}')
    assert len(path.read_bytes()) < 55
    t0 = time.perf_counter()
    message = _refused(path, lambda: SpriteSheet.from_tiled(path), InvalidValue)
    assert time.perf_counter() - t0 < 0.5
    assert f"more than the limit of {MAX_FRAMES} (max_frames)" in message


def test_a_40000_pixel_image_of_16_pixel_tiles_is_refused_at_once_and_the_limit_can_be_raised(tmp_path):
    """It took 36 s and 1.2 GB (6.25 million frames); a sheet at the limit makes no frame until asked."""
    _png(tmp_path / "big.png", 40_000, 40_000)
    path = tmp_path / "big.tsj"
    path.write_text('{"image":"big.png","tilewidth":16,"tileheight":16}')
    t0 = time.perf_counter()
    assert "6250000 frames" in _refused(path, lambda: SpriteSheet.from_tiled(path), InvalidValue)
    assert time.perf_counter() - t0 < 0.5
    sheet = SpriteSheet.from_tiled(path, max_frames=2500 * 2500)  # raised: lazy, so still instant
    assert len(sheet) == 6_250_000 and sheet[-1] == Frame(str(tmp_path / "big.png"), 39_984, 39_984, 16, 16)
    assert time.perf_counter() - t0 < 1.0
    _png(tmp_path / "max.png", 4096, 4096)
    at_limit = SpriteSheet(tmp_path / "max.png", 16, 16)
    assert len(at_limit) == MAX_FRAMES and at_limit[257] == Frame(str(tmp_path / "max.png"), 16, 16, 16, 16)
    assert at_limit[257] is at_limit.frames[257] and list(at_limit.frames[:2]) == [at_limit[0], at_limit[1]]


def test_a_tileset_over_its_size_limit_is_refused_before_it_is_read(tmp_path):
    _png(tmp_path / "s.png", 32, 16)
    path = tmp_path / "big.tsj"
    path.write_text(json.dumps({"image": "s.png", "tilewidth": 16, "tileheight": 16, "name": "x" * 1000}))
    assert "more than the limit of 100 (max_bytes)" in _refused(
        path, lambda: SpriteSheet.from_tiled(path, max_bytes=100), InvalidValue)
    assert len(SpriteSheet.from_tiled(path)) == 2


@pytest.mark.parametrize("field, value", [("tilewidth", HUGE), ("tileheight", DIGITS), ("margin", HUGE),
                                          ("spacing", HUGE), ("tilewidth", "\u00b2"), ("tilewidth", -0.0),
                                          ("tilewidth", 1e999)])
def test_tileset_sizes_of_hostile_values_are_refused(tmp_path, field, value):
    _png(tmp_path / "s.png", 32, 16)
    path = tmp_path / "sizes.tsj"
    text = json.dumps({"image": "s.png", "tilewidth": 16, "tileheight": 16, field: 0}).replace(
        f'"{field}": 0', f'"{field}": {value if isinstance(value, str) and value.isdecimal() else json.dumps(value)}')
    path.write_text(text)
    _refused(path, lambda: SpriteSheet.from_tiled(path), InvalidValue)


def test_a_tileset_image_that_is_not_a_regular_file_is_refused(tmp_path):
    """A device (or a FIFO, which would block the load forever) named as the image."""
    path = tmp_path / "dev.tsj"
    path.write_text('{"image":"/dev/zero","tilewidth":16,"tileheight":16}')
    assert "not a regular file" in _refused(path, lambda: SpriteSheet.from_tiled(path), InvalidValue)


def test_a_tileset_image_named_with_a_nul_character_is_refused(tmp_path):
    """Found by the hostile-value fuzzing: ``"image": "\\u0000"`` raised ``os.stat``'s ValueError."""
    path = tmp_path / "nul.tsj"
    path.write_text('{"image":"\\u0000","tilewidth":16,"tileheight":16}')
    assert "cannot be read" in _refused(path, lambda: SpriteSheet.from_tiled(path), InvalidValue)


def test_animation_durations_beyond_float64_are_refused():
    frame = Frame("x.png", 0, 0, 1, 1)
    with pytest.raises(InvalidValue, match="finite and > 0 seconds"):
        Animation([frame], HUGE)
    with pytest.raises(InvalidValue, match="add up to more seconds than a float64 holds"):
        Animation([frame, frame], [1e308, 1e308])
