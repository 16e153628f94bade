"""Segments: the shape, its pairs with every other kind (collide, manifold, raycast, time of impact,
distance, the batch kernel), exact on dyadic inputs, and shapely as an independent oracle.

A segment has no interior: another shape collides with it when the segment enters that shape's
interior. The penetration depth is the distance from the origin to the boundary of the Minkowski
difference A - B, which for a segment against a box or polygon is the hull of the vertex
differences, and against a circle or capsule that hull (of the cores) rounded by the radius.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from shapely.geometry import LineString, MultiPoint, Point
from shapely.geometry import Polygon as SPolygon

from framework import AABB, Capsule, Circle, Polygon, Segment
from framework.collision import collide, manifold, raycast, time_of_impact
from framework.collision.batch import collide_many
from framework.collision.distance import distance, point_distance

FAST = settings(max_examples=200, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])

eighths = st.integers(-24, 24).map(lambda i: i / 8)
sizes = st.integers(1, 24).map(lambda i: i / 8)
angles = st.one_of(st.just(0.0), st.floats(-math.pi, math.pi), st.integers(-4, 4).map(lambda i: i * math.pi / 4))
segments = st.tuples(eighths, eighths, eighths, eighths).filter(lambda p: p[:2] != p[2:]).map(
    lambda p: Segment(p[:2], p[2:]))
others = st.one_of(
    st.builds(AABB, sizes, sizes),
    st.builds(Circle, sizes),
    st.builds(Capsule, sizes, sizes),
    st.builds(Polygon.box, sizes, sizes),
    st.sampled_from([Polygon([(-1, -0.5), (1, -0.5), (0, 1)]), Polygon([(0, 0), (2, 0.5), (1.5, 1.5), (-0.5, 1)])]),
)
poses = st.tuples(eighths, eighths, angles)


def core(shape, pose):
    """The shape's core in world coordinates (points) and its radius."""
    x, y, r = pose
    c, s = math.cos(r), math.sin(r)
    if isinstance(shape, Segment):
        return [(x + c * px - s * py, y + s * px + c * py) for px, py in (shape.a, shape.b)], 0.0
    if isinstance(shape, Circle):
        return [(x, y)], shape.radius
    if isinstance(shape, Capsule):
        h = shape.half_length
        return [(x + s * h, y - c * h), (x - s * h, y + c * h)], shape.radius
    if isinstance(shape, AABB):
        w, hh = shape.width / 2, shape.height / 2
        return [(x - w, y - hh), (x + w, y - hh), (x + w, y + hh), (x - w, y + hh)], 0.0
    return [(c * px - s * py + x, s * px + c * py + y) for px, py in shape.points], 0.0


def shapely_of(shape, pose):
    pts, r = core(shape, pose)
    g = Point(pts[0]) if len(pts) == 1 else LineString(pts) if len(pts) == 2 else SPolygon(pts)
    return g, r


def oracle_depth(a, ta, b, tb):
    """The distance from the origin to the boundary of A - B (> 0: they overlap by that much;
    <= 0: apart by minus that), from shapely."""
    pa, ra = core(a, ta)
    pb, rb = core(b, tb)
    hull = MultiPoint([(ax - bx, ay - by) for ax, ay in pa for bx, by in pb]).convex_hull
    o = Point(0, 0)
    if isinstance(hull, SPolygon) and hull.contains(o):
        return ra + rb + hull.exterior.distance(o)
    return ra + rb - hull.distance(o)


def overlaps(a, ta, b, tb):
    """Whether the segment's points enter the other shape's interior, from shapely."""
    ga, r_a = shapely_of(a, ta)
    gb, r_b = shapely_of(b, tb)
    r = r_a + r_b
    if r > 0:
        return ga.distance(gb) < r
    seg, other = (ga, gb) if isinstance(a, Segment) else (gb, ga)
    return seg.relate(other)[0] != "F" or other.contains(Point(seg.coords[0])) or other.contains(
        Point(seg.coords[1]))


def pairs(swap, seg, ts, other, to):
    return (other, to, seg, ts) if swap else (seg, ts, other, to)


# --- the shape ---------------------------------------------------------------------------------

def test_segment_is_validated_and_exact() -> None:
    s = Segment((0, 0), (3, 4))
    assert s.a == (0.0, 0.0) and s.b == (3.0, 4.0) and s.kind == "segment"
    assert s.length == 5.0 and s.bounding_radius == 5.0 and s.area == 0.0
    assert s.normal == (0.8, -0.6)
    assert s.centroid == (1.5, 2.0)
    assert Segment((-0.0, 1), (2, 1)).a == (0.0, 1.0)
    assert Segment((0, 0), (1, 0)) == Segment([0, 0], [1, 0])
    for bad, word in [(((0, 0), (0, 0)), "distinct"), (((0, math.nan), (1, 1)), "nan"),
                      (((0, 0), (1, math.inf)), "inf"), (((0, 0), (1,)), "(1,)"), (("ab", (1, 1)), "'ab'"),
                      (((0, 0), (True, 1)), "True"), (((1e308, 0), (-1e308, 0)), "too long")]:
        with pytest.raises(ValueError, match=word if word != "(1,)" else r"\(1,\)"):
            Segment(*bad)


# --- exact expectations on dyadic inputs ------------------------------------------------------------

FLOOR = Segment((-2, 0), (2, 0))


@pytest.mark.parametrize("other, pose, inward", [
    (AABB(2, 2), (0, 1), (0, -1)),  # resting on it
    (AABB(2, 2), (3, 0), (-1, 0)),  # touching its end with a side
    (AABB(2, 2), (0, -1), (0, 1)),  # from below
    (Polygon.box(2, 2), (0, 1, 0.0), (0, -1)),
    (Polygon([(-1, 0), (1, 0), (0, 1)]), (0.5, 0), (0, -1)),  # an edge along it
    (Circle(1), (0, 1), (0, -1)),  # tangent
    (Circle(1), (3, 0), (-1, 0)),  # touching its end
    (Circle(0.625), (2.375, 0.5), (-3, -4)),  # (3/8, 4/8): 5/8 from the end exactly
    (Capsule(0.5, 2), (0, 0.5 + 1), (0, -1)),  # its cap on the segment
    (Capsule(0.5, 2), (-2.5, 0), (1, 0)),  # its side against the end
    (Segment((0, -1), (0, 1)), (0, 0), None),  # two segments never collide (no interior)
])
def test_touching_is_not_a_collision(other, pose, inward) -> None:
    for tf in ((0, 0), (0, 0, 0.0)):
        assert collide(FLOOR, tf, other, pose) is None
        assert collide(other, pose, FLOOR, tf) is None
    if inward is None:
        return
    # ... and moved in by a hair (2**-50), it is, both ways round.
    hair = (pose[0] + inward[0] * 2.0**-50, pose[1] + inward[1] * 2.0**-50, *pose[2:])
    for c in (collide(FLOOR, (0, 0), other, hair), collide(other, hair, FLOOR, (0, 0))):
        assert c is not None and 0 < c.depth < 2.0**-46


def test_exact_contacts_with_boxes_circles_capsules_and_polygons() -> None:
    from framework.collision.results import Contact, Vec2

    assert collide(FLOOR, (0, 0), AABB(2, 2), (0, 0.75)) == Contact(Vec2(0.0, 1.0), 0.25, Vec2(0.0, 0.0))
    assert collide(AABB(2, 2), (0, 0.75), FLOOR, (0, 0)) == Contact(Vec2(0.0, -1.0), 0.25, Vec2(0.0, 0.0))
    # Over its end: out sideways is shorter (0.5) than up (0.75).
    c = collide(FLOOR, (0, 0), AABB(2, 2), (2.5, 0.25))
    assert (c.normal, c.depth) == (Vec2(1.0, 0.0), 0.5) and 1.5 <= c.point.x <= 2 and c.point.y == 0
    assert collide(FLOOR, (0, 0), Circle(1), (0, 0.5)) == Contact(Vec2(0.0, 1.0), 0.5, Vec2(0.0, 0.0))
    assert collide(Circle(1), (0, 0.5), FLOOR, (0, 0)) == Contact(Vec2(0.0, -1.0), 0.5, Vec2(0.0, 0.0))
    # A circle over the end is pushed from the end: (3, 4) / 5 at 0.3, 0.4 from it, depth 1 - 0.5.
    c = collide(FLOOR, (0, 0), Circle(1), (2.375, 0.5))
    assert c.normal == Vec2(0.6, 0.8) and c.depth == pytest.approx(0.375, abs=1e-15)
    assert collide(FLOOR, (0, 0), Capsule(0.5, 2), (0, 1.25)) == Contact(Vec2(0.0, 1.0), 0.25, Vec2(0.0, 0.0))
    # A tilted segment: the box is pushed along the segment's normal.
    ramp = Segment((-4, -4), (4, 4))
    c = collide(ramp, (0, 0), Polygon.box(1, 1), (-0.25, 0.25))
    assert c.normal.x == pytest.approx(-math.sqrt(0.5)) and c.normal.y == pytest.approx(math.sqrt(0.5))
    assert c.depth == pytest.approx(math.sqrt(0.5) / 2, abs=1e-15)  # the box's corner 0.35 below the line
    # Containment: a short segment inside a box leaves through the nearest face.
    c = collide(AABB(4, 4), (0, 0), Segment((-0.5, 1), (0.5, 1)), (0, 0))
    assert (c.normal, c.depth) == (Vec2(0.0, 1.0), 1.0)


def test_far_from_the_origin_gives_the_same_answers() -> None:
    for other, pose in [(AABB(2, 2), (0.5, 0.75)), (Circle(1), (2.25, 0.5)), (Capsule(0.5, 1), (-1, 0.75))]:
        near = collide(FLOOR, (0, 0), other, pose)
        far = collide(FLOOR, (2.0**30, -(2.0**30)), other, (pose[0] + 2.0**30, pose[1] - 2.0**30))
        assert far.normal == near.normal and far.depth == near.depth
        assert (far.point.x - 2.0**30, far.point.y + 2.0**30) == tuple(near.point)


def test_manifold_of_a_box_on_a_segment_has_two_points() -> None:
    m = manifold(FLOOR, (0, 0), AABB(1, 1), (1.75, 0.25))  # the box over the segment's end
    assert m.normal == (0.0, 1.0)
    assert sorted((tuple(p.point), p.depth) for p in m.points) == [((1.25, -0.25), 0.25), ((2.0, -0.25), 0.25)]
    m = manifold(AABB(1, 1), (0, 0.25), FLOOR, (0, 0))
    assert m.normal == (0.0, -1.0)
    assert sorted((tuple(p.point), p.depth) for p in m.points) == [((-0.5, 0.0), 0.25), ((0.5, 0.0), 0.25)]
    assert len(manifold(FLOOR, (0, 0), Circle(1), (0, 0.5)).points) == 1


# --- rays ------------------------------------------------------------------------------------------

def test_raycast_crosses_a_segment_and_grazing_misses() -> None:
    from framework.collision.results import RayHit, Vec2

    assert raycast(FLOOR, (0, 0), (0, 5), (0, -1)) == RayHit(5.0, Vec2(0.0, 0.0), Vec2(0.0, 1.0))
    assert raycast(FLOOR, (0, 0), (1, -4), (0, 2)) == RayHit(4.0, Vec2(1.0, 0.0), Vec2(0.0, -1.0))
    assert raycast(FLOOR, (0, 0), (-5, 0), (1, 0)) is None  # along it: a graze
    assert raycast(FLOOR, (0, 0), (-5, 0.5), (1, 0)) is None  # parallel
    assert raycast(FLOOR, (0, 0), (2, 5), (0, -1)).point == (2.0, 0.0)  # through its end: a hit
    assert raycast(FLOOR, (0, 0), (math.nextafter(2.0, 3.0), 5), (0, -1)) is None  # an ulp past it
    assert raycast(FLOOR, (0, 0), (0, 5), (0, 1)) is None  # pointing away
    assert raycast(FLOOR, (0, 0), (0, 5), (0, -1), max_distance=5).distance == 5.0
    assert raycast(FLOOR, (0, 0), (0, 5), (0, -1), max_distance=4.75) is None
    # On it: distance 0, the normal facing the ray.
    assert raycast(FLOOR, (0, 0), (1, 0), (1, -3)) == RayHit(0.0, Vec2(1.0, 0.0), Vec2(0.0, 1.0))
    assert raycast(Segment((0, 0), (1, 1)), (0, 0), (-1, 0.5), (1 / 3, 0)).point == (0.5, 0.5)
    # Turned with its transform.
    hit = raycast(FLOOR, (10, 0, math.pi / 2), (5, 1), (1, 0))
    assert hit.distance == pytest.approx(5.0) and hit.normal == pytest.approx((-1.0, 0.0), abs=1e-15)


@FAST
@given(segments, poses, eighths, eighths, st.integers(-8, 8), st.integers(-8, 8))
def test_raycast_against_shapely(seg, pose, ox, oy, dx, dy):
    assume((dx, dy) != (0, 0))
    (p0, p1), _ = core(seg, pose)
    hit = raycast(seg, pose, (ox, oy), (dx, dy))
    far = 1000.0 / math.hypot(dx, dy)
    ray = LineString([(ox, oy), (ox + dx * far, oy + dy * far)])
    line = LineString([p0, p1])
    cross = ray.intersection(line)
    ex, ey = p1[0] - p0[0], p1[1] - p0[1]
    parallel = abs(dx * ey - dy * ex) <= 1e-12 * math.hypot(dx, dy) * math.hypot(ex, ey)
    if parallel:
        assert hit is None
        return
    # Clear of the ends by more than rounding: shapely decides.
    d_ends = min(ray.distance(Point(p0)), ray.distance(Point(p1)))
    assume(d_ends > 1e-9)
    if cross.is_empty:
        assert hit is None
        return
    assert hit is not None
    assert hit.distance == pytest.approx(Point(ox, oy).distance(cross), abs=1e-9)
    assert line.distance(Point(hit.point)) < 1e-9
    assert abs(hit.normal[0] * ex + hit.normal[1] * ey) < 1e-9 * math.hypot(ex, ey)
    assert hit.normal[0] * dx + hit.normal[1] * dy <= 0


# --- pairs against shapely -------------------------------------------------------------------------

@FAST
@given(segments, poses, others, poses, st.booleans())
def test_overlap_and_depth_against_shapely(seg, ts, other, to, swap):
    a, ta, b, tb = pairs(swap, seg, ts, other, to)
    depth = oracle_depth(a, ta, b, tb)
    assume(abs(depth) > 1e-9)
    c = collide(a, ta, b, tb)
    assert (c is not None) == (depth > 0) == overlaps(a, ta, b, tb)
    if c is None:
        return
    assert c.depth == pytest.approx(depth, abs=1e-9)
    assert math.hypot(*c.normal) == pytest.approx(1.0, abs=1e-12)
    # Moving B by the push-out leaves them touching; a little less still overlaps.
    (nx, ny), d = c.normal, c.depth
    out = (tb[0] + nx * d * (1 + 1e-9) + nx * 1e-12, tb[1] + ny * d * (1 + 1e-9) + ny * 1e-12, tb[2])
    assert oracle_depth(a, ta, b, out) <= 1e-9
    if d > 1e-6:
        assert collide(a, ta, b, (tb[0] + nx * d * 0.99, tb[1] + ny * d * 0.99, tb[2])) is not None
    # The point is in the closed overlap: on the segment, and in (or on) the other shape.
    gs, _ = shapely_of(seg, ts)
    go, ro = shapely_of(other, to)
    p = Point(c.point)
    assert gs.distance(p) < 1e-9
    assert (go.distance(p) if not isinstance(go, SPolygon) else go.exterior.distance(p) * (not go.contains(p))) \
        <= ro + 1e-9


@FAST
@given(segments, poses, others, poses)
def test_symmetric_and_batch_agrees(seg, ts, other, to):
    c, s = collide(seg, ts, other, to), collide(other, to, seg, ts)
    assert (c is None) == (s is None)
    many = collide_many([seg, other], [ts, to], [other, seg], [to, ts])
    assert list(many.hit) == [c is not None, s is not None]
    if c is None:
        return
    assert s.depth == c.depth
    negated = s.normal == pytest.approx((-c.normal[0], -c.normal[1]), abs=1e-12)
    undefined = s.normal == pytest.approx(c.normal, abs=1e-12)  # a tie broken upward both ways
    assert negated or undefined
    for i, got in enumerate((c, s)):
        assert (many.nx[i], many.ny[i]) == pytest.approx(tuple(got.normal), abs=1e-12)
        assert many.depth[i] == pytest.approx(got.depth, abs=1e-12)
        assert (many.px[i], many.py[i]) == pytest.approx(tuple(got.point), abs=1e-9)


@FAST
@given(segments, poses, others, poses, eighths, eighths, st.booleans())
def test_time_of_impact_against_collide(seg, ts, other, to, vx, vy, swap):
    """The first moment of overlap: just before it collide finds nothing (up to rounding), just
    after it finds a contact; never an impact when collide finds nothing along the whole way."""
    assume((vx, vy) != (0, 0))
    a, ta, b, tb = pairs(swap, seg, ts, other, to)
    hit = time_of_impact(a, ta, (0, 0), b, tb, (vx, vy))

    def at(f):
        return oracle_depth(a, ta, b, (tb[0] + vx * f, tb[1] + vy * f, tb[2]))

    samples = [at(i / 64) for i in range(65)]
    if hit is None:
        assert max(samples) <= 1e-9
        return
    f = hit.fraction
    assert 0 <= f < 1
    if f > 0:
        assert at(f - 1e-6) <= 1e-9
    assert max(at(min(f + 1e-6, 1.0)), *samples[math.ceil(f * 64):]) > -1e-9
    assert math.hypot(*hit.normal) == pytest.approx(1.0)


def test_time_of_impact_slides_along_a_segment_without_an_impact() -> None:
    for shape, y in [(AABB(1, 1), 0.5), (Circle(0.5), 0.5), (Capsule(0.5, 1), 1.0), (Polygon.box(1, 1), 0.5)]:
        for d in (0.1, 1 / 6, 10.0):
            assert time_of_impact(shape, (-5, y), (d, 0), FLOOR, (0, 0)) is None
        hit = time_of_impact(shape, (0, y + 1), (0, -4), FLOOR, (0, 0))
        assert hit.fraction == 0.25 and hit.normal == (0.0, -1.0)
    assert time_of_impact(FLOOR, (0, 0), (0, 0), FLOOR, (1, 1), (0, -4)) is None  # two segments


def test_distance_to_a_segment() -> None:
    d = distance(FLOOR, (0, 0), Circle(1), (0, 3))
    assert d.distance == 2.0 and d.point_a == (0.0, 0.0) and d.point_b == (0.0, 2.0)
    assert distance(FLOOR, (0, 0), Segment((0, -1), (0, 1)), (0, 0)).distance == 0.0  # crossing
    assert distance(FLOOR, (0, 0), Segment((0, -1), (0, 1)), (3, 0)).distance == 1.0
    assert point_distance(FLOOR, 0, 0, 0, 1, 1)[0] == 1.0
    assert point_distance(FLOOR, 0, 0, 0, 5, 4)[0] == 5.0
