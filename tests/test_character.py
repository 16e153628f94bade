"""The character controller: hard cases with exact expectations.

Scenes use 32-unit tiles, a 1/64 s step and speeds of 128 units/s, so a step's horizontal move is
exactly 2 units and the expected positions on 45-degree and 2:1 slopes are exact. The controller
keeps its body ``skin`` clear of surfaces (2**-40 of its smaller size or 2**-44 of its coordinates,
about 1e-11 here), so "feet on the surface" means a gap in [0, 1e-9].
"""

from __future__ import annotations

import math
import os
import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from framework import AABB, Circle, Hitbox, InvalidValue, Polygon, Scene, Transform, Velocity, collide
from framework.character import CharacterController

T = 32.0
DT = 1.0 / 64.0
W, H = 24.0, 28.0
SKIN = 5e-10  # twice this bounds the gap kept (see the module docstring)
G = -1024.0


def scene_with(tiles: list[tuple[float, float, object]]) -> Scene:
    """A scene with gravity and static ``(x, y, shape)`` pieces."""
    s = Scene(gravity=(0.0, G))
    for x, y, shape in tiles:
        s.spawn(Transform(x, y), Hitbox(shape, body="static"))
    return s


def floor_row(n: int, y: float = 16.0, start: int = 0) -> list[tuple[float, float, object]]:
    return [(16.0 + T * (start + i), y, AABB(T, T)) for i in range(n)]


def character(s: Scene, x: float, feet: float, **kw) -> int:
    return s.spawn(Transform(x, feet + H / 2), Velocity(), Hitbox(AABB(W, H), body="kinematic"),
                   CharacterController(**kw))


def feet(s: Scene, e: int) -> float:
    return s.get(e, Transform).y - H / 2


def settle(s: Scene, e: int, steps: int = 40) -> None:
    for _ in range(steps):
        s.step(DT)
    assert s.get(e, CharacterController).on_floor


def hill_level() -> list[tuple[float, float, object]]:
    """Flat ground (top y = 32) to x = 128, a 45-degree slope up to x = 160 (top 64), flat to
    x = 256, a 45-degree slope down to x = 288, flat ground to x = 384."""
    tiles = floor_row(12)
    tiles.append((144.0, 48.0, Polygon([(-16, -16), (16, -16), (16, 16)])))
    tiles += [(16.0 + T * i, 48.0, AABB(T, T)) for i in range(5, 8)]
    tiles.append((272.0, 48.0, Polygon([(-16, -16), (16, -16), (-16, 16)])))
    return tiles


def ground_height(x: float) -> float:
    """The hill level's surface at x."""
    if x <= 128.0 or x >= 288.0:
        return 32.0
    if x < 160.0:
        return 32.0 + (x - 128.0)
    if x <= 256.0:
        return 64.0
    return 64.0 - (x - 256.0)


def support(x: float) -> float:
    """Where the feet of a W-wide box at x rest on the hill: the highest ground under them."""
    xs = [x - W / 2, x + W / 2] + [k for k in (128.0, 160.0, 256.0, 288.0) if x - W / 2 < k < x + W / 2]
    return max(ground_height(v) for v in xs)


@pytest.mark.parametrize("speed", [128.0, -128.0])
def test_walks_over_a_hill_with_feet_on_the_ground_every_step(speed):
    s = scene_with(hill_level())
    start = 60.0 if speed > 0 else 350.0
    e = character(s, start, 32.0)
    settle(s, e)
    c = s.get(e, CharacterController)
    x_prev = s.get(e, Transform).x
    for _ in range(130):
        s.get(e, Velocity).x = speed
        s.step(DT)
        x = s.get(e, Transform).x
        assert x - x_prev == pytest.approx(speed * DT, abs=2 * SKIN)  # no snag at a seam, no stall
        x_prev = x
        gap = feet(s, e) - support(x)
        assert c.on_floor
        assert -1e-9 <= gap <= 2 * SKIN, (x, gap)
        assert s.get(e, Velocity).y == 0.0


def test_constant_speed_up_a_45_degree_slope_is_exact():
    s = scene_with(hill_level())
    e = character(s, 100.0, 32.0)
    settle(s, e)
    ys = []
    for _ in range(40):
        s.get(e, Velocity).x = 128.0
        s.step(DT)
        ys.append(feet(s, e))
    rises = [b - a for a, b in zip(ys, ys[1:])]
    on_slope = [r for r in rises if r > 0.0]
    assert len(on_slope) >= 14
    # On the slope each step rises exactly as far as it goes across: 2 units.
    assert sorted(set(on_slope))[1:-1] in ([], [2.0]) and on_slope.count(2.0) >= 12


def gentle_level() -> list[tuple[float, float, object]]:
    """Flat to x = 128, a 2:1 slope up over two tiles to x = 192 (top 64), flat to 320."""
    tiles = floor_row(10)
    tiles.append((144.0, 48.0, Polygon([(-16, -16), (16, -16), (16, 0)])))
    tiles.append((176.0, 48.0, Polygon([(-16, -16), (16, -16), (16, 16), (-16, 0)])))
    tiles += [(16.0 + T * i, 48.0, AABB(T, T)) for i in range(6, 10)]
    return tiles


def test_walks_up_and_down_a_2_to_1_slope():
    s = scene_with(gentle_level())
    e = character(s, 60.0, 32.0)
    settle(s, e)
    c = s.get(e, CharacterController)

    def ground(x: float) -> float:
        return 32.0 if x <= 128 else 64.0 if x >= 192 else 32.0 + (x - 128.0) / 2

    for speed in (128.0, -128.0):
        for _ in range(90):
            s.get(e, Velocity).x = speed
            s.step(DT)
            x = s.get(e, Transform).x
            under = max(ground(x - W / 2), ground(x + W / 2))
            assert c.on_floor
            assert -1e-9 <= feet(s, e) - under <= 3 * SKIN, (x, feet(s, e) - under)


@pytest.mark.slow
@pytest.mark.parametrize("slope", ["45", "2:1"])
def test_stands_still_on_a_slope(slope):
    tiles = hill_level() if slope == "45" else gentle_level()
    s = scene_with(tiles)
    e = character(s, 144.0 if slope == "45" else 160.0, 80.0)
    settle(s, e, 80)
    t = s.get(e, Transform)
    x, y = t.x, t.y
    for _ in range(600):
        s.step(DT)
        assert (t.x, t.y) == (x, y)
    assert s.get(e, CharacterController).on_floor


def test_steps_up_a_quarter_tile_step_and_down_again():
    tiles = floor_row(10) + [(16.0 + T * i, 36.0, AABB(T, 8.0)) for i in range(4, 6)]  # top 40
    s = scene_with(tiles)
    e = character(s, 60.0, 32.0, step_height=10.0)
    settle(s, e)
    c = s.get(e, CharacterController)
    seen = []
    for _ in range(110):
        s.get(e, Velocity).x = 128.0
        x0 = s.get(e, Transform).x
        s.step(DT)
        assert s.get(e, Transform).x - x0 == pytest.approx(2.0, abs=2 * SKIN)  # never stopped
        assert c.on_floor
        seen.append(round(feet(s, e)))
    assert 40 in seen and seen[0] == 32 and seen[-1] == 32


def test_a_step_higher_than_step_height_is_a_wall():
    tiles = floor_row(10) + [(16.0 + T * i, 40.0, AABB(T, 16.0)) for i in range(4, 6)]  # top 48
    s = scene_with(tiles)
    e = character(s, 60.0, 32.0, step_height=10.0)
    settle(s, e)
    c = s.get(e, CharacterController)
    for _ in range(60):
        s.get(e, Velocity).x = 128.0
        s.step(DT)
    assert c.on_floor and c.on_wall and c.wall_normal == (-1.0, 0.0)
    right = s.get(e, Transform).x + W / 2
    assert 128.0 - 2 * SKIN <= right <= 128.0
    assert s.get(e, Velocity).x == 0.0


V_LEVEL = floor_row(8) + floor_row(3, 48.0) + floor_row(3, 48.0, start=5) + [
    (112.0, 48.0, Polygon([(-16, -16), (16, -16), (-16, 16)])),
    (144.0, 48.0, Polygon([(-16, -16), (16, -16), (16, 16)]))]
"""Ground at 64 on both sides of a V: a 45-degree slope down from x = 96 to 128, up to 160."""


@pytest.mark.slow
@pytest.mark.parametrize("drop_x, rest", [(128.0, 44.0), (125.0, 47.0), (134.0, 50.0)])
def test_stands_in_a_v(drop_x, rest):
    """Dropped into a V of two 45-degree slopes, it stays where it lands: centred, its corners on
    both slopes; off centre, on the slope its lower corner meets (it does not slide down)."""
    s = scene_with(V_LEVEL)
    e = character(s, drop_x, 120.0)
    for _ in range(200):
        s.step(DT)
    c = s.get(e, CharacterController)
    t = s.get(e, Transform)
    x, y = t.x, t.y
    for _ in range(200):
        s.step(DT)
        assert (t.x, t.y) == (x, y)
    assert c.on_floor
    assert x == drop_x and feet(s, e) == pytest.approx(rest, abs=3 * SKIN)  # straight down, no slide


def test_walks_through_a_v():
    s = scene_with(V_LEVEL)
    e = character(s, 40.0, 64.0)
    settle(s, e, 60)
    c = s.get(e, CharacterController)
    for _ in range(90):
        s.get(e, Velocity).x = 128.0
        x0 = s.get(e, Transform).x
        s.step(DT)
        assert s.get(e, Transform).x - x0 == pytest.approx(2.0, abs=2 * SKIN)
        assert c.on_floor


def test_fast_fall_onto_a_slope_never_tunnels():
    s = scene_with(hill_level())
    e = character(s, 144.0, 2000.0)
    s.get(e, Velocity).y = -6000.0  # ~94 units a step: three tiles
    for _ in range(40):
        s.step(DT)
        x = s.get(e, Transform).x
        assert feet(s, e) >= support(x) - 1e-9
    assert s.get(e, CharacterController).on_floor
    assert s.get(e, CharacterController).floor_normal == pytest.approx((-math.sqrt(0.5), math.sqrt(0.5)))


def test_jumping_into_a_wall_never_sticks():
    tiles = floor_row(10) + [(176.0, 16.0 + T * k, AABB(T, T)) for k in range(1, 8)]  # a wall at x = 160
    s = scene_with(tiles)
    e = character(s, 140.0, 32.0)
    settle(s, e)
    s.get(e, Velocity).y = 512.0
    c = s.get(e, CharacterController)
    vys, walls = [], []
    for _ in range(30):
        s.get(e, Velocity).x = 128.0
        s.step(DT)
        vys.append(s.get(e, Velocity).y)
        right = s.get(e, Transform).x + W / 2
        assert right <= 160.0
        walls.append((right == 160.0, c.on_wall, c.wall_normal))
    # Gravity acts every step while pressed against the wall: the jump rises and falls freely.
    assert all(b - a == pytest.approx(G * DT) for a, b in zip(vys, vys[1:]) if a > -400.0 and b != 0.0)
    # It reaches the wall exactly (touching it: not yet on it); from the next step on, pushing into it,
    # it is on the wall (normal to the left) every step, still in the air.
    first = next(i for i, (at, _on, _n) in enumerate(walls) if at)
    assert first < 10 and all(w == (True, True, (-1.0, 0.0)) for w in walls[first + 1:])
    assert not c.on_floor


def platform_scene(vx: float, vy: float, one_way: bool = False) -> tuple[Scene, int, int]:
    s = scene_with(floor_row(20))
    plat = s.spawn(Transform(200.0, 100.0), Velocity(), Hitbox(AABB(96.0, 16.0), body="kinematic", one_way=one_way))
    e = character(s, 200.0, 108.0)
    settle(s, e)
    assert s.get(e, CharacterController).floor_entity == plat
    s.get(plat, Velocity).x, s.get(plat, Velocity).y = vx, vy
    return s, plat, e


@pytest.mark.parametrize("one_way", [False, True])
def test_rides_a_platform_that_turns_back_without_jitter(one_way):
    s, plat, e = platform_scene(64.0, 0.0, one_way)
    pt, t = s.get(plat, Transform), s.get(e, Transform)
    dx, dy = t.x - pt.x, t.y - pt.y
    for k in range(240):
        s.get(plat, Velocity).x = 64.0 if (k // 40) % 2 == 0 else -64.0
        s.get(plat, Velocity).y = 32.0 if (k // 30) % 2 == 0 else -32.0
        s.step(DT)
        assert (t.x - pt.x, t.y - pt.y) == pytest.approx((dx, dy), abs=1e-9)
        assert s.get(e, CharacterController).on_floor


def test_a_platform_carrying_it_into_a_ceiling_crushes_it_never_through():
    s, plat, e = platform_scene(0.0, 0.0)
    s.spawn(Transform(200.0, 180.0), Hitbox(AABB(160.0, 16.0), body="static"))  # ceiling bottom at 172
    s.get(plat, Velocity).y = 64.0
    c = s.get(e, CharacterController)
    crushed = False
    for _ in range(120):
        s.step(DT)
        assert s.get(e, Transform).y + H / 2 <= 172.0
        crushed |= c.crushed
    assert crushed


def test_one_way_platform_pass_up_stand_on_drop_through():
    s = scene_with(floor_row(10))
    s.spawn(Transform(160.0, 88.0), Hitbox(AABB(96.0, 16.0), body="static", one_way=True))  # top 96
    e = character(s, 160.0, 32.0)
    settle(s, e)
    c = s.get(e, CharacterController)
    s.get(e, Velocity).y = 600.0  # up through it
    for _ in range(80):
        s.step(DT)
    assert c.on_floor and feet(s, e) == pytest.approx(96.0, abs=2 * SKIN)
    c.drop_through = True
    for _ in range(60):
        s.step(DT)
    assert c.on_floor and feet(s, e) == pytest.approx(32.0, abs=2 * SKIN)


def test_walking_into_a_one_way_platform_from_the_side_passes():
    s = scene_with(floor_row(12))
    s.spawn(Transform(200.0, 44.0), Hitbox(AABB(64.0, 8.0), body="static", one_way=True))  # 40 .. 48
    e = character(s, 100.0, 32.0)
    settle(s, e)
    for _ in range(80):
        s.get(e, Velocity).x = 128.0
        s.step(DT)
    assert s.get(e, Transform).x > 250.0


def test_pushes_a_crate_it_walks_into():
    s = scene_with(floor_row(20))
    crate = s.spawn(Transform(200.0, 48.0), Velocity(), Hitbox(AABB(32.0, 32.0), mass=1.0))
    e = character(s, 100.0, 32.0)
    settle(s, e)
    for _ in range(120):
        s.get(e, Velocity).x = 128.0
        s.step(DT)
    assert s.get(crate, Transform).x > 240.0
    assert s.get(e, Transform).x + W / 2 <= s.get(crate, Transform).x - 16.0 + 1e-9


@pytest.mark.slow
def test_random_input_on_the_hill_never_enters_a_tile():
    tiles = hill_level() + [(-16.0, 16.0 + T * k, AABB(T, T)) for k in range(8)] + \
        [(400.0, 16.0 + T * k, AABB(T, T)) for k in range(8)]
    s = scene_with(tiles)
    e = character(s, 60.0, 32.0, step_height=8.0)
    rng = random.Random(7)
    statics = [(x, y, shape) for x, y, shape in tiles]
    t, v = s.get(e, Transform), s.get(e, Velocity)
    c = s.get(e, CharacterController)
    for k in range(3000):
        if k % 8 == 0:
            v.x = rng.choice((-256.0, -128.0, 0.0, 128.0, 256.0))
            if c.on_floor and rng.random() < 0.3:
                v.y = rng.choice((300.0, 600.0))
        s.step(DT)
        assert 0.0 < t.x < 384.0 and 32.0 - 1e-9 <= t.y - H / 2 < 2000.0
        if k % 10 == 0:
            for x, y, shape in statics:
                assert collide(AABB(W, H), (t.x, t.y), shape, (x, y)) is None


@pytest.mark.parametrize("field, value", [
    ("max_floor_angle", 0.0), ("max_floor_angle", 90.0), ("max_floor_angle", -5.0), ("max_floor_angle", math.nan),
    ("step_height", -1.0), ("step_height", math.inf), ("snap_length", -0.5), ("skin", 0.0), ("max_slides", 0),
    ("gravity_scale", math.nan), ("push_mass", -1.0), ("solid_mask", -1), ("max_floor_angle", "steep"),
])
def test_bad_settings_are_refused_naming_the_field(field, value):
    with pytest.raises(InvalidValue, match=field):
        CharacterController(**{field: value})
    c = CharacterController()
    before = getattr(c, field)
    with pytest.raises(InvalidValue, match=field):
        setattr(c, field, value)
    assert getattr(c, field) == before or (before is None and getattr(c, field) is None)


def test_a_bad_setting_on_a_spawned_character_names_the_entity_and_changes_nothing():
    s = scene_with(floor_row(4))
    e = character(s, 60.0, 32.0, step_height=4.0)
    c = s.get(e, CharacterController)
    for field, value in (("step_height", -1.0), ("max_floor_angle", 90.0), ("max_floor_angle", math.nan)):
        with pytest.raises(InvalidValue, match=rf"entity {e}: CharacterController {field}"):
            setattr(c, field, value)
    assert (c.step_height, c.max_floor_angle) == (4.0, 50.0)
    other = s.spawn(Transform(0.0, 100.0), Velocity(), Hitbox(AABB(4.0, 4.0), body="kinematic"))
    added = CharacterController()
    s.add_component(other, added)
    with pytest.raises(InvalidValue, match=rf"entity {other}: CharacterController skin"):
        added.skin = -1.0
    s.step(DT)


def test_nan_velocity_and_a_dynamic_body_are_refused_before_the_step():
    s = scene_with(floor_row(4))
    e = character(s, 60.0, 32.0)
    s.step(DT)
    t = s.get(e, Transform)
    before = (t.x, t.y, s.frame)
    s.get(e, Velocity).x = math.nan
    with pytest.raises(InvalidValue, match=rf"entity {e}: Velocity.x"):
        s.step(DT)
    assert (t.x, t.y, s.frame) == before
    s.get(e, Velocity).x = 0.0
    other = s.spawn(Transform(100.0, 100.0), Velocity(), Hitbox(Circle(4.0)), CharacterController())
    with pytest.raises(InvalidValue, match=rf"entity {other}: .*kinematic"):
        s.step(DT)
    assert (t.x, t.y, s.frame) == before
    lone = s.spawn(Transform(0.0, 0.0), Hitbox(Circle(4.0), body="kinematic"), CharacterController())
    s.despawn(other)
    with pytest.raises(InvalidValue, match=rf"entity {lone}: .*Velocity"):
        s.step(DT)
    assert (t.x, t.y, s.frame) == before


def test_a_scene_without_characters_runs_no_character_stage():
    s = scene_with(floor_row(4))
    s.spawn(Transform(16.0, 100.0), Velocity(), Hitbox(Circle(4.0)))
    s.step(DT)
    assert "character" not in s.counters["systems"]
    character(s, 60.0, 32.0)
    s.step(DT)
    assert "character" in s.counters["systems"]


@pytest.mark.parametrize("case", ["slope-45-up", "slope-45-down", "slope-2:1-up", "slope-2:1-down", "step-up",
                                  "ride-reverse"])
def test_the_accuracy_reports_controller_claims(case):
    """docs/accuracy.md's controller rows: feet on the slope to rounding, exact speed, no lost step
    at a quarter-tile step, no drift riding a platform that turns back."""
    from framework.bench.accuracy import run_controller

    row = run_controller(case, "substeps-1")
    if case.startswith("slope"):
        assert 0.0 <= row["gap_min"] and row["gap_max"] <= 1e-11 and row["speed_error"] <= 1e-11
    elif case == "step-up":
        assert row["measured"] == row["expected"] == 80.0 and row["speed_error"] <= 1e-11
    else:
        assert row["measured"] <= 1e-12


def test_a_capsule_character_walks_over_the_hill():
    """Characters are often capsules: the round feet ride over the crests, never entering a tile."""
    from framework.shapes import Capsule

    s = scene_with(hill_level())
    cap = Capsule(10.0, 8.0)  # 20 wide, 28 tall: the box character's height
    e = s.spawn(Transform(60.0, 47.0), Velocity(), Hitbox(cap, body="kinematic"), CharacterController())
    settle(s, e)
    c = s.get(e, CharacterController)
    t = s.get(e, Transform)
    for _ in range(140):
        x0 = t.x
        s.get(e, Velocity).x = 128.0
        s.step(DT)
        assert t.x - x0 == pytest.approx(2.0, abs=1e-9)
        assert c.on_floor
        for x, y, shape in hill_level():
            assert collide(cap, (t.x, t.y), shape, (x, y)) is None
        # Resting on the surface: a short cast down meets it at once.
        hit = s.shape_cast(cap, (t.x, t.y), (t.x, t.y - 1.0), ignore=[e])
        assert hit is not None and hit.fraction <= 1e-9


terrain_kinds = st.sampled_from([None, None, None, "solid", "solid", "slope_up", "slope_down", "slope_up_low",
                                 "slope_up_high", "slope_down_high", "slope_down_low", "step"])


@pytest.mark.slow
@settings(max_examples=int(os.environ.get("CHARACTER_EXAMPLES", "40")), deadline=None)
@given(st.lists(st.lists(terrain_kinds, min_size=10, max_size=10), min_size=3, max_size=3),
       st.lists(st.tuples(st.sampled_from([-256.0, -128.0, 0.0, 128.0, 256.0]), st.booleans()), min_size=5,
                max_size=5),
       st.sampled_from([AABB(W, H), Circle(12.0), "capsule"]))
def test_random_terrain_and_input_never_leave_a_character_inside_the_ground(cells, inputs, shape):
    """Random tile terrain (framework.tiles) walled in on a floor, random running and jumping: the
    character is never inside a piece of terrain and never leaves the walls."""
    from framework.shapes import Capsule
    from framework.tiles import terrain_pieces

    if shape == "capsule":
        shape = Capsule(10.0, 8.0)
    rows = [[None] * 12 for _ in range(6)] + [[("solid" if c in (0, 11) else k) for c, k in
                                               enumerate([None, *row, None])] for row in cells] + [["solid"] * 12]
    for row in rows[:6]:
        row[0] = row[11] = "solid"
    pieces = terrain_pieces(rows, T)
    s = Scene(gravity=(0.0, G))
    try:
        for pc in pieces:
            s.spawn(Transform(pc.x, pc.y), Hitbox(pc.shape, body="static"))
        e = s.spawn(Transform(T * 5.5, T * 9.5), Velocity(), Hitbox(shape, body="kinematic"),
                    CharacterController(step_height=8.0))
        t, v, c = s.get(e, Transform), s.get(e, Velocity), s.get(e, CharacterController)
        for vx, jump in inputs:
            for k in range(24):
                v.x = vx
                if jump and k == 0 and c.on_floor:
                    v.y = 500.0
                s.step(DT)
                assert T < t.x < 11 * T and 0.0 < t.y < 12 * T
                for pc in pieces:
                    assert collide(shape, (t.x, t.y), pc.shape, (pc.x, pc.y)) is None
    finally:
        s.close()
