"""Contact manifolds (issue 23's two-point contacts): exact cases, and shapely as the oracle.

Every point must lie in the closed overlap of the two shapes (shapely's intersection, to rounding),
no deeper than collide's depth; a face resting on a face gives the two ends of the segment they
share; circles give collide's point.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from shapely.geometry import Point
from shapely.geometry import Polygon as SPolygon
from test_collide_properties import poses, shapes, world_outline  # (the same random shapes and poses)

from framework import AABB, Circle, Polygon
from framework.collision import Manifold, collide, manifold


def test_a_box_resting_on_a_face_touches_at_both_bottom_corners():
    m = manifold(AABB(10.0, 1.0), (0.0, -0.5), AABB(1.0, 1.0), (0.0, 0.25))
    assert m == Manifold((0.0, 1.0), (((-0.5, -0.25), 0.25), ((0.5, -0.25), 0.25)))


def test_a_box_over_the_end_of_a_face_touches_where_the_face_ends():
    m = manifold(AABB(10.0, 1.0), (0.0, -0.5), AABB(1.0, 1.0), (4.75, 0.25))
    assert m == Manifold((0.0, 1.0), (((4.25, -0.25), 0.25), ((5.0, -0.25), 0.25)))


def test_the_points_lie_on_b_when_a_is_the_upper_body():
    # A above B: the normal points down (A toward B); the points are on B's top face, under A.
    m = manifold(AABB(1.0, 1.0), (0.0, 0.25), AABB(10.0, 1.0), (0.0, -0.5))
    assert m.normal == (0.0, -1.0)
    assert sorted(p.point for p in m.points) == [(-0.5, 0.0), (0.5, 0.0)]
    assert [p.depth for p in m.points] == [0.25, 0.25]


def test_a_tilted_box_on_a_floor_touches_at_its_corner():
    box = Polygon.box(1.0, 1.0)
    m = manifold(AABB(10.0, 1.0), (0.0, -0.5), box, (0.0, 0.6, 0.3))
    c = collide(AABB(10.0, 1.0), (0.0, -0.5), box, (0.0, 0.6, 0.3))
    assert len(m.points) == 1 and m.normal == c.normal
    corner = min(world_outline(box, (0.0, 0.6, 0.3)), key=lambda p: p[1])  # its lowest corner
    assert m.points[0].point == pytest.approx(corner, abs=1e-12)
    assert m.points[0].depth == pytest.approx(c.depth, rel=1e-12)


def test_circles_touch_at_collides_point():
    c = collide(AABB(10.0, 1.0), (0.0, -0.5), Circle(0.5), (0.0, 0.25))
    m = manifold(AABB(10.0, 1.0), (0.0, -0.5), Circle(0.5), (0.0, 0.25))
    assert m == Manifold(c.normal, ((c.point, c.depth),))


def test_apart_or_touching_is_no_manifold():
    assert manifold(AABB(1.0, 1.0), (0.0, 0.0), AABB(1.0, 1.0), (1.0, 0.0)) is None  # touching
    assert manifold(AABB(1.0, 1.0), (0.0, 0.0), Polygon.box(1.0, 1.0), (3.0, 0.0, 0.5)) is None


def _region(shape, pose):
    if isinstance(shape, Circle):
        return Point(pose[0], pose[1]).buffer(shape.radius, 256)
    return SPolygon(world_outline(shape, pose))


@pytest.mark.slow
@settings(max_examples=300, deadline=None, derandomize=True)
@given(sa=shapes, pa=poses, sb=shapes, pb=poses)
def test_every_point_lies_in_the_overlap_no_deeper_than_collide(sa, pa, sb, pb):
    c = collide(sa, pa, sb, pb)
    m = manifold(sa, pa, sb, pb)
    assert (m is None) == (c is None)
    assume(m is not None)
    assert m.normal == c.normal and 1 <= len(m.points) <= 2
    assert [p.depth for p in m.points] == sorted((p.depth for p in m.points), reverse=True)
    scale = 1.0 + max(abs(v) for v in (*pa[:2], *pb[:2])) + sa.bounding_radius + sb.bounding_radius
    if isinstance(sa, Circle) or isinstance(sb, Circle):
        tol = 1e-3 * scale  # (shapely's circles are 256-gons)
    else:
        tol = 1e-9 * scale
    overlap = _region(sa, pa).intersection(_region(sb, pb))
    for p in m.points:
        assert 0.0 < p.depth <= c.depth * (1.0 + 1e-9) + 1e-12
        assert overlap.distance(Point(*p.point)) <= tol, (p, overlap.wkt)


@settings(max_examples=200, deadline=None, derandomize=True)
@given(w=st.integers(2, 16).map(lambda i: i / 4), h=st.integers(2, 16).map(lambda i: i / 4),
       x=st.integers(-20, 20).map(lambda i: i / 8), sink=st.integers(1, 7).map(lambda i: i / 16),
       angle=st.integers(0, 3).map(lambda k: k * math.pi / 2))
def test_any_box_on_a_wide_floor_touches_at_its_two_bottom_corners(w, h, x, sink, angle):
    # A box (any size, turned by a multiple of a quarter turn: still flat) sunk into a floor
    # wider than it: two points, its bottom corners, each exactly ``sink`` deep.
    box = Polygon.box(w, h)
    hw = (w if angle in (0.0, math.pi) else h) / 2
    hh = (h if angle in (0.0, math.pi) else w) / 2
    m = manifold(AABB(100.0, 2.0), (0.0, -1.0), box, (x, hh - sink, angle))
    assert m.normal == pytest.approx((0.0, 1.0), abs=1e-12) and len(m.points) == 2
    xs = sorted(p.point.x for p in m.points)
    assert xs == pytest.approx([x - hw, x + hw], abs=1e-12)
    for p in m.points:
        assert p.depth == pytest.approx(sink, abs=1e-12) and p.point.y == pytest.approx(-sink, abs=1e-12)


def test_second_moments_of_the_shapes_about_their_origin():
    # Per unit mass: a w x h box (w^2 + h^2) / 12, a disk r^2 / 2, a right triangle with legs a, b
    # from the origin (a^2 + b^2) / 6 (dyadic values: exact).
    assert AABB(2.0, 4.0).second_moment == Polygon.box(2.0, 4.0).second_moment == pytest.approx(20.0 / 12.0)
    assert Circle(2.0).second_moment == 2.0
    assert Polygon([(0.0, 0.0), (4.0, 0.0), (0.0, 2.0)]).second_moment == pytest.approx(20.0 / 6.0, rel=1e-15)
    # the same triangle wound the other way, and a polygon off its origin (parallel axes: + d^2)
    assert Polygon([(0.0, 0.0), (0.0, 2.0), (4.0, 0.0)]).second_moment == pytest.approx(20.0 / 6.0, rel=1e-15)
    off = Polygon([(2.0, -1.0), (4.0, -1.0), (4.0, 1.0), (2.0, 1.0)])  # a 2 x 2 square centred at (3, 0)
    assert off.second_moment == pytest.approx(8.0 / 12.0 + 9.0, rel=1e-15)
