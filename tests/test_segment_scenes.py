"""Segments in scenes: static terrain drawn as lines, in both solvers (``Scene()``, the exact one,
and ``Scene(solver="soft")``): bodies of every shape rest on a segment as on a box floor, a disk
rolls and a crate holds or slides on a tilted one as the textbook says, a segment stops bodies from
either side, and the scene's queries (rays, shape casts, point and shape queries) answer it."""

from __future__ import annotations

import math

import pytest

from framework import AABB, Capsule, Circle, Hitbox, Polygon, Scene, Segment, Transform, Velocity

G = 10.0
DT = 1 / 60
SOLVERS = ["exact", "soft"]


def scene(solver: str) -> Scene:
    s = Scene(solver="soft") if solver == "soft" else Scene()
    s.gravity = (0, -G)
    return s


def test_a_segment_is_the_hitbox_of_static_and_kinematic_bodies_only() -> None:
    seg = Segment((-1, 0), (1, 0))
    with pytest.raises(ValueError, match="no area, so it cannot be a dynamic body's shape"):
        Hitbox(seg)
    assert Hitbox(seg, body="static").shape == seg
    assert Hitbox(seg, body="kinematic").shape == seg
    hb = Hitbox(seg, body="static")
    with pytest.raises(ValueError, match="body='static' or body='kinematic'"):
        hb.body = "dynamic"
    hb = Hitbox(AABB(1, 1))
    with pytest.raises(ValueError, match="no area"):
        hb.shape = seg
    # Written in place inside a scene: refused by the next step, naming the entity.
    s = Scene()
    e = s.spawn(Transform(0, 0), Hitbox(seg, body="static"))
    s.get(e, Hitbox).body = "dynamic"
    with pytest.raises(ValueError, match=f"entity {e}: .*no area"):
        s.step(DT)
    with pytest.raises(ValueError, match="segments of length"):
        Scene().spawn(Transform(0, 0), Hitbox(Segment((1, 0), (1 + 1e-7, 0)), body="static"))


SHAPES = [(AABB(1, 1), 0.5), (Circle(0.5), 0.5), (Polygon.box(1, 1), 0.5), (Capsule(0.5, 1), 1.0),
          (Polygon([(-0.5, -0.5), (0.5, -0.5), (0, 0.5)]), 0.5)]


@pytest.mark.parametrize("solver", SOLVERS)
def test_bodies_rest_on_a_segment_as_on_a_box_floor(solver: str) -> None:
    heights = {}
    for floor in ("box", "segment"):
        s = scene(solver)
        if floor == "box":
            s.spawn(Transform(0, -0.5), Hitbox(AABB(40, 1), body="static"))
        else:
            s.spawn(Transform(0, 0), Hitbox(Segment((-20, 0), (20, 0)), body="static"))
        bodies = [s.spawn(Transform(-12 + 5 * i, h + 0.75), Velocity(0, 0), Hitbox(shape))
                  for i, (shape, h) in enumerate(SHAPES)]
        for _ in range(300):
            s.step(DT)
        heights[floor] = [(s.get(e, Transform).y, s.get(e, Transform).rotation) for e in bodies]
    for (shape, h), on_box, on_seg in zip(SHAPES, heights["box"], heights["segment"], strict=True):
        assert on_seg == pytest.approx(on_box, abs=1e-9), shape
        assert on_seg[0] == pytest.approx(h, abs=1e-3 if solver == "soft" else 1e-12), shape
    if solver == "exact":  # the exact solver's rest heights are exact
        assert [y for y, _ in heights["segment"]] == [h for _, h in SHAPES]


def incline(s: Scene, theta: float, friction: float | None,
            floor: str = "segment") -> tuple[float, float, float, float]:
    """A static segment 100 long through the origin, falling to the right at ``theta`` (or the top
    face of a slab turned as much: ``floor="slab"``); returns its direction down the slope and its
    upward normal."""
    c, sn = math.cos(theta), math.sin(theta)
    if floor == "segment":
        shape, rotation = Segment((-50 * c, 50 * sn), (50 * c, -50 * sn)), 0.0
    else:
        shape, rotation = Polygon([(-50, -1), (50, -1), (50, 0), (-50, 0)]), -theta
    s.spawn(Transform(0, 0, rotation), Hitbox(shape, body="static", friction=friction))
    return c, -sn, sn, c


@pytest.mark.parametrize("solver", SOLVERS)
def test_a_disk_rolls_down_a_tilted_segment_at_two_thirds_g_sin_theta(solver: str) -> None:
    theta, r = math.radians(20), 0.5
    got = {}
    for floor in ("segment", "slab"):
        s = scene(solver)
        dx, dy, nx, ny = incline(s, theta, 1.0, floor)
        ball = s.spawn(Transform(-20 * dx + r * nx, -20 * dy + r * ny), Velocity(0, 0),
                       Hitbox(Circle(r), friction=1.0))
        for _ in range(60):
            s.step(DT)
        v = s.get(ball, Velocity)
        got[floor] = (v.x * dx + v.y * dy, v.x * nx + v.y * ny, -v.angular * r)
    along, across, rim = got["segment"]
    assert got["segment"] == pytest.approx(got["slab"], abs=1e-9)  # the same as on a slab's face
    expected = 2 / 3 * G * math.sin(theta) * 1.0
    assert along == pytest.approx(expected, rel=1e-9 if solver == "exact" else 0.01)
    assert abs(across) < (1e-9 if solver == "exact" else 0.05) * expected  # on the surface, not bouncing
    assert rim == pytest.approx(along, rel=1e-9 if solver == "exact" else 0.01)  # rolling, not sliding


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("friction", [1.0, 0.1])
def test_a_crate_holds_or_slides_on_a_tilted_segment_as_coulomb_says(solver: str, friction: float) -> None:
    theta = math.radians(20)  # tan = 0.364: mu 1 holds, mu 0.1 slides at g (sin - mu cos)
    s = scene(solver)
    dx, dy, nx, ny = incline(s, theta, 1.0)
    start = (-20 * dx + 0.5 * nx, -20 * dy + 0.5 * ny)
    crate = s.spawn(Transform(*start, -theta), Velocity(0, 0), Hitbox(Polygon.box(1, 1), friction=friction))
    for _ in range(120):
        s.step(DT)
    t = s.get(crate, Transform)
    travelled = (t.x - start[0]) * dx + (t.y - start[1]) * dy
    mu = math.sqrt(friction * 1.0)
    if mu > math.tan(theta):
        assert abs(travelled) < 2e-3
    else:
        expected = 0.5 * G * (math.sin(theta) - mu * math.cos(theta)) * 2.0 ** 2
        assert travelled == pytest.approx(expected, rel=0.05)
    assert t.rotation == pytest.approx(-theta, abs=1e-3)  # flat on the slope, not tipped
    assert (t.x - start[0]) * nx + (t.y - start[1]) * ny == pytest.approx(0.0, abs=2e-3)


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("shape", [AABB(1, 1), Circle(0.5), Polygon.box(1, 1), Capsule(0.5, 1)],
                         ids=["aabb", "circle", "polygon", "capsule"])
def test_a_segment_stops_bodies_from_either_side(solver: str, shape) -> None:
    s = scene(solver)
    s.gravity = (0, 0)
    s.spawn(Transform(0, 0), Hitbox(Segment((-5, 0), (5, 0)), body="static"))
    half = shape.height / 2 if isinstance(shape, Capsule) else 0.5
    up = s.spawn(Transform(-2, -3), Velocity(0, 8), Hitbox(shape))
    down = s.spawn(Transform(2, 3), Velocity(0, -8), Hitbox(shape))
    for _ in range(60):
        s.step(DT)
    assert s.get(up, Transform).y == pytest.approx(-half, abs=1e-2)
    assert s.get(down, Transform).y == pytest.approx(half, abs=1e-2)
    assert s.get(up, Velocity).y <= 1e-9 and s.get(down, Velocity).y >= -1e-9


@pytest.mark.parametrize("solver", SOLVERS)
def test_the_scene_queries_answer_a_segment(solver: str) -> None:
    s = scene(solver)
    ramp = s.spawn(Transform(10, 0, math.pi / 4), Hitbox(Segment((-2, 0), (2, 0)), body="static"))
    floor = s.spawn(Transform(0, 0), Hitbox(Segment((-4, 0), (4, 0)), body="static"))
    s.step(DT)
    hit = s.raycast((1, 5), (0, -1))
    assert (hit.entity, hit.distance, tuple(hit.point), tuple(hit.normal)) == (floor, 5.0, (1.0, 0.0), (0.0, 1.0))
    hit = s.raycast((1, -5), (0, 1))
    assert (hit.entity, tuple(hit.normal)) == (floor, (0.0, -1.0))
    assert s.raycast((-10, 0), (1, 0), max_distance=9) is None  # along the floor: a graze
    assert s.raycast((4, 5), (0, -1)).entity == floor  # through its end
    assert s.raycast((4.5, 5), (0, -1), max_distance=10) is None
    hit = s.raycast((5, 1), (1, 0))
    assert hit.entity == ramp and hit.point.x == pytest.approx(11.0) and hit.point.y == pytest.approx(1.0)
    cast = s.shape_cast(AABB(1, 1), (0, 3), (0, -1))
    assert cast.entity == floor and cast.fraction == pytest.approx(0.625) and tuple(cast.normal) == (0.0, 1.0)
    assert s.shape_cast(AABB(1, 1), (-3, 0.5), (3, 0.5)) is None  # slides along it
    assert s.query_point(1, 0) == [floor]
    assert s.query_point(5, 0) == [] and s.query_point(1, 0.5) == []
    assert s.query_shape(Circle(0.5), (1, 0.25)) == [floor]
    assert s.query_shape(Circle(0.5), (1, 0.5)) == []  # touching
    # from the floor's end (4, 0) to the ramp's lower end (10 - sqrt 2, -sqrt 2)
    assert s.distance(floor, ramp).distance == pytest.approx(math.hypot(6 - math.sqrt(2), math.sqrt(2)))
