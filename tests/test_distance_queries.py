"""Distance between shapes, and the scene queries games ask (issue 38, part 3): which entities does a
shape overlap (an explosion, a sword's swing), which hitbox is nearest a point, how far apart two
entities are. Analytic cases with dyadic values, shapely as the oracle of distances, brute force
over every entity as the oracle of the scene queries."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from framework import AABB, Capsule, Circle, Hitbox, InvalidValue, Polygon, Scene, Transform
from framework.collision import collide, distance
from framework.collision.distance import point_distance, shape_core

shapely = pytest.importorskip("shapely")
from shapely.geometry import LineString, Point  # noqa: E402
from shapely.geometry import Polygon as ShapelyPolygon  # noqa: E402

HEXAGON = Polygon([(math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)) for k in range(6)])
TRIANGLE = Polygon([(-1.0, -0.5), (1.0, -0.5), (0.0, 1.0)])


# --- distance between two shapes ---------------------------------------------------------------


@pytest.mark.parametrize("a, pa, b, pb, expected, point_a, point_b", [
    (Circle(0.5), (0.0, 0.0), Circle(0.5), (3.0, 0.0), 2.0, (0.5, 0.0), (2.5, 0.0)),
    (AABB(2.0, 2.0), (0.0, 0.0), Circle(1.0), (4.0, 0.0), 2.0, (1.0, 0.0), (3.0, 0.0)),
    (Capsule(0.5, 2.0), (0.0, 0.0), AABB(2.0, 2.0), (3.0, 0.25), 1.5, None, None),  # face to face: points not unique
    # corner to corner: AABBs apart by (1, 1) across their corners, sqrt 2
    (AABB(2.0, 2.0), (0.0, 0.0), AABB(2.0, 2.0), (3.0, 3.0), math.sqrt(2.0), (1.0, 1.0), (2.0, 2.0)),
    # a capsule lying down (turned a quarter) above a box: its segment's underside, 0.75 up
    (Capsule(0.25, 2.0), (0.0, 2.0, math.pi / 2), AABB(4.0, 2.0), (0.0, 0.0), 0.75, None, None),
])
def test_distance_of_shapes_apart(a, pa, b, pb, expected, point_a, point_b):
    d = distance(a, pa, b, pb)
    assert d.distance == pytest.approx(expected, abs=1e-12)
    if point_a is not None:
        assert tuple(d.point_a) == pytest.approx(point_a, abs=1e-12)
        assert tuple(d.point_b) == pytest.approx(point_b, abs=1e-12)
    assert math.dist(d.point_a, d.point_b) == pytest.approx(expected, abs=1e-12)


def test_overlapping_and_touching_shapes_are_at_no_distance():
    over = distance(AABB(2.0, 2.0), (0.0, 0.0), Circle(1.0), (1.5, 0.0))
    contact = collide(AABB(2.0, 2.0), (0.0, 0.0), Circle(1.0), (1.5, 0.0))
    assert over.distance == 0.0 and over.point_a == over.point_b == contact.point
    touch = distance(AABB(2.0, 2.0), (0.0, 0.0), AABB(2.0, 2.0), (2.0, 0.5))  # faces touching
    assert touch.distance == 0.0 and touch.point_a == touch.point_b
    assert touch.point_a[0] == 1.0


def test_bad_arguments_name_the_field():
    with pytest.raises(InvalidValue, match="transform_b"):
        distance(Circle(1.0), (0.0, 0.0), Circle(1.0), (math.nan, 0.0))
    with pytest.raises(InvalidValue, match="shape_a"):
        distance("box", (0.0, 0.0), Circle(1.0), (0.0, 0.0))


def _shapely(shape, x, y, rot):
    core, r = shape_core(shape, x, y, rot)
    geom = Point(core[0]) if len(core) == 1 else LineString(core) if len(core) == 2 else ShapelyPolygon(core)
    return geom, r


SHAPES = st.sampled_from([AABB(1.0, 2.0), AABB(0.5, 0.5), Circle(0.75), Circle(0.25), Capsule(0.25, 1.5),
                          Capsule(0.5, 0.5), HEXAGON, TRIANGLE, Polygon.box(2.0, 0.5)])
COORD = st.integers(-64, 64).map(lambda k: k / 16)
ANGLE = st.integers(0, 63).map(lambda k: k * math.pi / 32)


@settings(max_examples=400, deadline=None)
@given(SHAPES, COORD, COORD, ANGLE, SHAPES, COORD, COORD, ANGLE)
def test_distance_matches_shapely(a, ax, ay, ar, b, bx, by, br):
    d = distance(a, (ax, ay, ar), b, (bx, by, br))
    ga, ra = _shapely(a, ax, ay, ar)
    gb, rb = _shapely(b, bx, by, br)
    expected = max(0.0, ga.distance(gb) - ra - rb)
    assert d.distance == pytest.approx(expected, abs=1e-9)
    if d.distance > 0.0:
        # the points are on the two surfaces, the distance apart
        assert math.dist(d.point_a, d.point_b) == pytest.approx(d.distance, abs=1e-9)
        assert point_distance(a, ax, ay, ar, *d.point_a)[0] == pytest.approx(0.0, abs=1e-9)
        assert point_distance(b, bx, by, br, *d.point_b)[0] == pytest.approx(0.0, abs=1e-9)
        assert ga.distance(Point(d.point_a)) == pytest.approx(ra, abs=1e-9)
        assert gb.distance(Point(d.point_b)) == pytest.approx(rb, abs=1e-9)


@settings(max_examples=300, deadline=None)
@given(SHAPES, COORD, COORD, ANGLE, COORD, COORD)
def test_point_distance_matches_shapely(shape, x, y, rot, px, py):
    d, at = point_distance(shape, x, y, rot, px, py)
    geom, r = _shapely(shape, x, y, rot)
    assert d == pytest.approx(max(0.0, geom.distance(Point(px, py)) - r), abs=1e-9)
    assert math.dist(at, (px, py)) == pytest.approx(d, abs=1e-9)


# --- the scene's queries ---------------------------------------------------------------------


def _field(s: Scene) -> dict[int, tuple]:
    """A few bodies of every kind, one on another layer; entity -> (shape, pose)."""
    placed = {}
    for shape, (x, y, rot), kw in [
        (AABB(4.0, 1.0), (0.0, -0.5, 0.0), {"body": "static"}),
        (Circle(0.5), (3.0, 1.0, 0.0), {}),
        (HEXAGON, (-3.0, 2.0, 0.25), {}),
        (Capsule(0.25, 1.5), (0.0, 3.0, math.pi / 2), {}),
        (TRIANGLE, (5.0, -1.0, 0.0), {"layer": 2}),
        (Polygon.box(1.0, 1.0), (-1.0, 0.5, 0.0), {}),
    ]:
        e = s.spawn(Transform(x, y, rot), Hitbox(shape, **kw))
        placed[e] = (shape, (x, y, rot), kw.get("layer", 1))
    return placed


@pytest.mark.parametrize("probe, at, rot", [
    (Circle(1.0), (2.0, 0.5), 0.0),
    (AABB(2.0, 2.0), (-2.0, 1.5), 0.0),
    (Polygon.box(6.0, 0.25), (0.0, 1.0), 0.5),
    (Capsule(0.5, 4.0), (4.0, 0.0), math.pi / 2),
    (Circle(0.5), (20.0, 20.0), 0.0),
])
def test_query_shape_is_every_overlap_by_brute_force(probe, at, rot):
    with Scene() as s:
        placed = _field(s)
        got = s.query_shape(probe, at, rotation=rot)
        only_layer_2 = s.query_shape(probe, at, rotation=rot, mask=2)
    expected = sorted(e for e, (shape, pose, _layer) in placed.items()
                      if collide(probe, (*at, rot), shape, pose) is not None)
    assert got == expected
    assert only_layer_2 == [e for e in expected if placed[e][2] == 2]


def test_query_shape_touching_is_not_overlapping():
    with Scene() as s:
        e = s.spawn(Transform(0.0, 0.0), Hitbox(AABB(2.0, 2.0)))
        assert s.query_shape(AABB(2.0, 2.0), (2.0, 0.0)) == []  # face to face
        assert s.query_shape(AABB(2.0, 2.0), (1.875, 0.0)) == [e]


@pytest.mark.parametrize("point", [(0.0, 0.0), (3.0, 1.0), (2.0, 2.0), (-6.0, 5.0), (4.5, -0.25), (0.0, 3.0)])
def test_nearest_is_the_least_distance_by_brute_force(point):
    with Scene() as s:
        placed = _field(s)
        got = s.nearest(point)
        near = s.nearest(point, max_distance=0.5)
    dists = {e: point_distance(shape, *pose, *point)[0] for e, (shape, pose, _layer) in placed.items()}
    best = min(dists, key=lambda e: (dists[e], e))
    assert got.entity == best and got.distance == pytest.approx(dists[best], abs=1e-12)
    assert math.dist(got.point, point) == pytest.approx(got.distance, abs=1e-12)
    assert (near is None) == (dists[best] > 0.5)


def test_nearest_inside_ties_masks_and_an_empty_scene():
    with Scene() as s:
        assert s.nearest((0.0, 0.0)) is None
        a = s.spawn(Transform(-1.0, 0.0), Hitbox(Circle(0.5)))
        b = s.spawn(Transform(1.0, 0.0), Hitbox(Circle(0.5), layer=2))
        tie = s.nearest((0.0, 0.0))
        assert (tie.entity, tie.distance, tuple(tie.point)) == (a, 0.5, (-0.5, 0.0))  # a tie: the lower id
        assert s.nearest((0.0, 0.0), mask=2).entity == b
        inside = s.nearest((1.25, 0.0))
        assert (inside.entity, inside.distance, tuple(inside.point)) == (b, 0.0, (1.25, 0.0))
        with pytest.raises(InvalidValue, match="max_distance"):
            s.nearest((0.0, 0.0), max_distance=-1.0)


def test_scene_distance_between_entities():
    with Scene() as s:
        a = s.spawn(Transform(0.0, 0.0), Hitbox(Circle(0.5)))
        b = s.spawn(Transform(4.0, 0.0), Hitbox(AABB(2.0, 2.0), offset=(0.5, 0.0)))  # its box: x 3.5 to 5.5
        d = s.distance(a, b)
        assert (d.distance, tuple(d.point_a), tuple(d.point_b)) == (3.0, (0.5, 0.0), (3.5, 0.0))
        nobody = s.spawn(Transform(0.0, 0.0))
        with pytest.raises(InvalidValue, match="entity_b"):
            s.distance(a, nobody)
