"""The character stage's compiled move (:mod:`framework.systems.character_kernel`) against the Python
move it stands in for: the same scenes stepped with the compiled move on and off end in the same
bits (positions, velocities and every controller's state, each step), and the compiled move was
taken where it should be (a box among boxes) and not where it should not (a slope).
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable

import pytest
from test_character import DT, T, character, floor_row, hill_level, scene_with

import framework.systems.character as character_stage
from framework import AABB, Hitbox, Polygon, Scene, Transform, Velocity
from framework.character import CharacterController
from framework.systems.character_kernel import hypot


def _state(s: Scene) -> list[tuple[object, ...]]:
    out: list[tuple[object, ...]] = []
    for e in sorted(s.entities):
        t = s.try_get(e, Transform)
        if t is None:
            continue
        v = s.try_get(e, Velocity)
        out.append((e, t.x.hex(), t.y.hex(), *(() if v is None else (v.x.hex(), v.y.hex()))))
        c = s.try_get(e, CharacterController)
        if c is not None:
            out.append((c.on_floor, *(f.hex() for f in c.floor_normal), c.floor_entity, c.on_wall,
                        *(f.hex() for f in c.wall_normal), c.on_ceiling, c.crushed, sorted(c.dropping)))
    return out


Drive = Callable[[Scene, int], None]


def _run(build: Callable[[], Scene], make_drive: Callable[[], Drive], steps: int,
         fast: bool, monkeypatch: pytest.MonkeyPatch) -> tuple[list[list[tuple[object, ...]]], int]:
    """Every step's state, and how many moves the compiled move made."""
    monkeypatch.setattr(character_stage, "FAST", fast)
    s, drive = build(), make_drive()
    states = []
    for k in range(steps):
        drive(s, k)
        s.step(DT)
        states.append(_state(s))
    return states, s._stages["character"].fast_moves  # type: ignore[attr-defined]


def _same_bits(build: Callable[[], Scene], make_drive: Callable[[], Drive], steps: int,
               monkeypatch: pytest.MonkeyPatch) -> int:
    """Assert the compiled and the Python move step alike (``make_drive``: a fresh input for
    each); return the compiled move's count."""
    fast, fast_moves = _run(build, make_drive, steps, True, monkeypatch)
    slow, slow_moves = _run(build, make_drive, steps, False, monkeypatch)
    assert slow_moves == 0
    for k, (a, b) in enumerate(zip(fast, slow)):
        assert a == b, f"step {k}"
    return fast_moves


def _walker(seed: int) -> Drive:
    """Random-ish input for every character: walk, turn, jump, drop through, now and then."""
    rng = random.Random(seed)

    def drive(s: Scene, k: int) -> None:
        if k % 5:
            return
        for e, c in s.query(CharacterController):
            v = s.get(e, Velocity)
            v.x = rng.choice((-160.0, -128.0, 0.0, 96.0, 128.0, 200.0)) + rng.uniform(-3.0, 3.0)
            if c.on_floor and rng.random() < 0.25:
                v.y = rng.uniform(200.0, 600.0)
            if rng.random() < 0.1:
                c.drop_through = True

    return drive


def _boxes_level() -> Scene:
    """Ground, walls, steps, a one-way slab, a low ceiling: boxes only."""
    tiles = floor_row(24)
    tiles += [(-16.0, 48.0 + T * k, AABB(T, T)) for k in range(6)]  # left wall
    tiles += [(16.0 + T * 24, 48.0 + T * k, AABB(T, T)) for k in range(6)]  # right wall
    tiles += [(16.0 + T * 6, 36.0, AABB(T, 8.0))]  # a step 8 high
    tiles += [(16.0 + T * 9, 40.0, AABB(T, 16.0)), (16.0 + T * 10, 40.0, AABB(T, 16.0))]  # 16 high
    tiles += [(16.0 + T * 15, 120.0, AABB(4 * T, 8.0))]  # a low ceiling
    s = scene_with(tiles)
    s.spawn(Transform(16.0 + T * 12, 96.0), Hitbox(AABB(3 * T, 8.0), body="static", one_way=True))
    s.spawn(Transform(16.0 + T * 19, 90.0), Hitbox(AABB(2 * T, 8.0), body="static", one_way=True))
    for x in (100.0, 300.0, 520.0):
        character(s, x, 32.0, step_height=10.0)
    return s


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_boxes_level_same_bits_and_compiled(seed, monkeypatch):
    assert _same_bits(_boxes_level, lambda: _walker(seed), 400, monkeypatch) > 500


def _moving_platform(one_way: bool, solver: str = "exact") -> Callable[[], Scene]:
    def build() -> Scene:
        s = Scene(gravity=(0.0, -1024.0), solver=solver)
        for x, y, shape in floor_row(20):
            s.spawn(Transform(x, y), Hitbox(shape, body="static"))
        s.spawn(Transform(200.0, 100.0), Velocity(), Hitbox(AABB(96.0, 16.0), body="kinematic", one_way=one_way))
        character(s, 200.0, 108.0)
        character(s, 120.0, 32.0)
        return s

    return build


@pytest.mark.parametrize("solver", ["exact", "soft"])
@pytest.mark.parametrize("one_way", [False, True])
def test_moving_platform_same_bits_and_compiled(one_way, solver, monkeypatch):
    def make_drive() -> Drive:
        walk = _walker(4)

        def drive(s: Scene, k: int) -> None:
            plat = next(e for e, hb in s.query(Hitbox) if hb.body.value == "kinematic"
                        and s.try_get(e, CharacterController) is None)
            v = s.get(plat, Velocity)
            v.x = 64.0 if (k // 40) % 2 == 0 else -64.0
            v.y = 32.0 if (k // 30) % 2 == 0 else -32.0
            if k > 100:
                walk(s, k)

        return drive

    assert _same_bits(_moving_platform(one_way, solver), make_drive, 300, monkeypatch) > 300


@pytest.mark.parametrize("solver", ["exact", "soft"])
def test_crushed_under_a_ceiling_same_bits(solver, monkeypatch):
    def build() -> Scene:
        s = Scene(gravity=(0.0, -1024.0), solver=solver)
        for x, y, shape in floor_row(20):
            s.spawn(Transform(x, y), Hitbox(shape, body="static"))
        s.spawn(Transform(200.0, 100.0), Velocity(0.0, 64.0), Hitbox(AABB(96.0, 16.0), body="kinematic"))
        s.spawn(Transform(200.0, 180.0), Hitbox(AABB(160.0, 16.0), body="static"))
        character(s, 200.0, 108.0 + 1e-9)
        return s

    crushed = []

    def drive(s: Scene, k: int) -> None:
        crushed.extend(c.crushed for _e, c in s.query(CharacterController))

    _same_bits(build, lambda: drive, 120, monkeypatch)
    assert any(crushed)


def test_pushes_crates_same_bits(monkeypatch):
    def build() -> Scene:
        s = scene_with(floor_row(20))
        for k in range(3):
            s.spawn(Transform(200.0 + 40.0 * k, 48.0), Velocity(), Hitbox(AABB(32.0, 32.0), mass=1.0))
        character(s, 100.0, 32.0)
        return s

    def drive(s: Scene, k: int) -> None:
        for e, _c in s.query(CharacterController):
            s.get(e, Velocity).x = 128.0 if k < 150 else -128.0

    assert _same_bits(build, lambda: drive, 240, monkeypatch) > 100


def test_a_slope_falls_back_to_the_python_move(monkeypatch):
    """Near a slope (a polygon) the Python move decides; on flat boxes the compiled one."""
    def build() -> Scene:
        s = scene_with(hill_level())
        character(s, 40.0, 32.0)
        return s

    def drive(s: Scene, k: int) -> None:
        for e, _c in s.query(CharacterController):
            s.get(e, Velocity).x = 128.0

    fast = _same_bits(build, lambda: drive, 150, monkeypatch)
    assert 0 < fast < 150  # (walking over the hill: its flat start compiled, the slopes not)


@pytest.mark.parametrize("level", range(5))
def test_platformer_levels_same_bits(level, monkeypatch):
    """Each shipped level played by its demo script with the compiled move on and off."""
    from examples.platformer import demo, levels
    from examples.platformer.game import Game

    def play(fast: bool) -> tuple[list[list[tuple[object, ...]]], int]:
        monkeypatch.setattr(character_stage, "FAST", fast)
        lv = levels.load_level(levels.builtin_levels()[level])
        game = Game([lv], autoplay=demo.Autoplay(getattr(demo, f"level{level + 1}")),
                    scene=Scene(length_unit=lv.tile))
        states = []
        for _ in range(400):
            game.step()
            states.append(_state(game.scene))
        return states, game.scene._stages["character"].fast_moves

    fast, fast_moves = play(True)
    slow, _ = play(False)
    for k, (a, b) in enumerate(zip(fast, slow)):
        assert a == b, f"step {k}"
    assert fast_moves > 0


@pytest.mark.parametrize("a, b", [(3.0, 4.0), (0.1, 0.7), (1e-200, 3e-200), (1e300, 1e300), (5e-324, 1e-323),
                                  (-8.8495887409525e-311, 1.377324228e-314),  # (subnormal: the last bit)
                                  (-0.0, 0.0), (0.0, -2.5), (math.inf, 1.0), (1.0, -math.inf)])
def test_hypot_is_cpythons(a, b):
    assert hypot(a, b).hex() == math.hypot(a, b).hex()
    rng = random.Random(5)
    for _ in range(2000):
        x, y = rng.uniform(-1, 1) * 10 ** rng.randint(-8, 8), rng.uniform(-1, 1) * 10 ** rng.randint(-8, 8)
        assert hypot(x, y) == math.hypot(x, y)


def test_a_character_walks_the_same_beside_a_character(monkeypatch):
    """Two characters meeting: each is a box the other's move sees."""
    def build() -> Scene:
        s = scene_with(floor_row(16))
        character(s, 100.0, 32.0)
        character(s, 300.0, 32.0)
        return s

    def drive(s: Scene, k: int) -> None:
        for i, (e, _c) in enumerate(sorted(s.query(CharacterController), key=lambda p: p[0])):
            s.get(e, Velocity).x = 128.0 if i == 0 else -128.0

    _same_bits(build, lambda: drive, 150, monkeypatch)


def test_the_whole_move_is_one_compiled_call(monkeypatch):
    """A box character among boxes, not dropping through anything, is moved by one compiled call
    (:func:`~framework.systems.character_kernel.move_character`): no Python gathering of its
    candidates, no Python move; where the whole move hands back (a turning floor) the Python
    move decides, with the same bits."""
    def no_python_move(*args: object) -> None:
        raise AssertionError("the Python move ran")

    s = scene_with(floor_row(16))
    e = character(s, 100.0, 32.0)
    with monkeypatch.context() as m:
        m.setattr(character_stage.CharacterStage, "_move", no_python_move)
        for k in range(120):
            s.get(e, Velocity).x = 128.0 if k < 60 else -96.0
            s.step(DT)
    stage = s._stages["character"]  # type: ignore[attr-defined]
    assert stage.fast_moves == 120 and not stage.fallbacks
    assert s.get(e, CharacterController).on_floor

    def turning_board() -> Scene:
        s = scene_with(floor_row(16))
        board = Polygon([(-64.0, -4.0), (64.0, -4.0), (64.0, 4.0), (-64.0, 4.0)])
        s.spawn(Transform(200.0, 100.0), Velocity(0.0, 0.0, 0.25), Hitbox(board, body="kinematic"))
        character(s, 200.0, 104.0)
        return s

    def walk(s: Scene, k: int) -> None:
        for e, _c in s.query(CharacterController):
            s.get(e, Velocity).x = 32.0

    s = turning_board()
    for _ in range(30):
        s.step(DT)
    assert s._stages["character"].fallbacks.get("standing on a turning floor", 0) > 0  # type: ignore[attr-defined]
    _same_bits(turning_board, lambda: walk, 60, monkeypatch)


def test_hand_backs_are_counted_by_reason():
    """A character near a slope is handed back for its candidate that is not a box."""
    s = scene_with(hill_level())
    e = character(s, 40.0, 32.0)
    for _ in range(120):
        s.get(e, Velocity).x = 128.0
        s.step(DT)
    stage = s._stages["character"]  # type: ignore[attr-defined]
    assert stage.fallbacks["a candidate not a box"] > 0 and stage.fast_moves > 0


def test_snapshots_of_a_scene_moving_by_the_compiled_move_continue_bit_for_bit(tmp_path):
    # a snapshot keeps the stages' state: the character stage's must be savable in memory and in a
    # file while the compiled move runs, and a restored scene continues as the original does
    from framework.snapshot_file import load_snapshot, save_snapshot

    s, drive = _boxes_level(), _walker(7)
    for k in range(40):
        drive(s, k)
        s.step(DT)
    assert s._stages["character"].fast_moves > 0  # type: ignore[attr-defined]
    snap = s.snapshot()
    save_snapshot(s, tmp_path / "level.npz")
    rest = _walker(8)
    want = []
    for k in range(40):
        rest(s, k)
        s.step(DT)
        want.append(_state(s))
    s.restore(snap)
    other = _boxes_level()
    load_snapshot(other, tmp_path / "level.npz")
    for scene in (s, other):
        rest = _walker(8)
        for k in range(40):
            rest(scene, k)
            scene.step(DT)
            assert _state(scene) == want[k], f"step {k}"


def test_the_compiled_move_passes_over_the_live_rows_only(monkeypatch):
    """The compiled move finds its candidates by one pass over the rows' kinds and the geometry's
    bounds: both must be the live rows. A store's columns keep rows past the live ones (its
    capacity, and the rows of despawned bodies); a pass over those read bounds past the
    geometry's end, memory that differs from run to run (a platformer restored from a snapshot
    replayed differently, once in about eighty runs, when such a row happened to meet the
    character's reach). Every array the pass reads is as long as the live rows."""
    import inspect

    from framework.systems import character_kernel as ck

    s = scene_with(floor_row(16))
    e = character(s, 100.0, 32.0)
    walls = [s.spawn(Transform(300.0 + 40.0 * i, 48.0), Hitbox(AABB(T, T), body="static")) for i in range(60)]
    for w in walls[10:]:
        s.despawn(w)  # (their rows stay behind the live ones, with their kinds and layers)
    s.step(DT)
    store = s.bodies.store  # type: ignore[attr-defined]
    assert store.cap > store.n and (store.cols["kind"][store.n:] >= 0).any()
    seen: list[tuple[int, ...]] = []
    real = ck.move_character
    params = inspect.signature(real.py_func).parameters

    def checked(*args: object) -> object:
        got = dict(zip(params, args))
        seen.append(tuple(got[k].size for k in ("kind", "minx", "miny", "maxx", "maxy", "x", "y")))  # type: ignore[attr-defined]
        return real(*args)

    monkeypatch.setattr(ck, "move_character", checked)
    for _ in range(30):
        s.get(e, Velocity).x = 128.0
        s.step(DT)
    assert len(seen) == 30
    assert all(len(set(sizes)) == 1 and sizes[0] == store.n for sizes in seen), seen[:3]
