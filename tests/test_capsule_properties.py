"""Property tests of capsule pairs: the push-out, symmetry, invariances, the batch kernel, and
shapely as an independent oracle (a capsule is ``LineString(segment).buffer(radius)``).

Coordinates are dyadic (multiples of 1/8), so translations by 2**20 are exact and the invariance
properties can demand bit-for-bit equality.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, assume, event, given, settings
from hypothesis import strategies as st
from shapely.geometry import LineString, Point
from shapely.geometry import Polygon as SPolygon

from framework import AABB, Capsule, Circle, Polygon
from framework.collision import collide, raycast, time_of_impact
from framework.collision.batch import collide_many

FAST = settings(max_examples=150, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])

eighths = st.integers(-24, 24).map(lambda i: i / 8)
sizes = st.integers(1, 24).map(lambda i: i / 8)
angles = st.one_of(st.just(0.0), st.floats(-math.pi, math.pi), st.integers(-4, 4).map(lambda i: i * math.pi / 4))
capsules = st.builds(Capsule, sizes, sizes)
others = st.one_of(
    capsules,
    st.builds(AABB, sizes, sizes),
    st.builds(Circle, sizes),
    st.builds(Polygon.box, sizes, sizes),
    st.sampled_from([Polygon([(-1, -0.5), (1, -0.5), (0, 1)]), Polygon([(0, 0), (2, 0.5), (1.5, 1.5), (-0.5, 1)])]),
)
poses = st.tuples(eighths, eighths, angles)


def geom(shape, pose):
    """The shape as shapely sees it (a capsule and a circle as fine polygons)."""
    x, y, r = pose
    c, s = math.cos(r), math.sin(r)
    if isinstance(shape, Capsule):
        h = shape.half_length
        return LineString([(x + s * h, y - c * h), (x - s * h, y + c * h)]).buffer(shape.radius, quad_segs=64)
    if isinstance(shape, Circle):
        return Point(x, y).buffer(shape.radius, quad_segs=64)
    if isinstance(shape, AABB):
        w, hh = shape.width / 2, shape.height / 2
        return SPolygon([(x - w, y - hh), (x + w, y - hh), (x + w, y + hh), (x - w, y + hh)])
    return SPolygon([(c * px - s * py + x, s * px + c * py + y) for px, py in shape.points])


def moved(pose, dx, dy):
    return (pose[0] + dx, pose[1] + dy, pose[2])


@FAST
@given(capsules, poses, others, poses, st.booleans())
def test_symmetry_same_depth_and_negated_normal(cap, pa, other, pb, swap):
    a, ta, b, tb = (other, pb, cap, pa) if swap else (cap, pa, other, pb)
    c, s = collide(a, ta, b, tb), collide(b, tb, a, ta)
    assert (c is None) == (s is None)
    if c is None:
        return
    assert s.depth == c.depth and c.depth > 0
    negated = s.normal == pytest.approx((-c.normal[0], -c.normal[1]), abs=1e-12)
    undefined = s.normal == pytest.approx(c.normal, abs=1e-12) and (
        c.normal[1] > 1e-12 or (abs(c.normal[1]) <= 1e-12 and c.normal[0] > 0))
    assert negated or undefined, (c, s)


@FAST
@given(capsules, poses, others, poses, st.booleans())
def test_moving_b_by_the_push_out_leaves_them_touching(cap, pa, other, pb, swap):
    a, ta, b, tb = (other, pb, cap, pa) if swap else (cap, pa, other, pb)
    c = collide(a, ta, b, tb)
    if c is None:
        return
    (nx, ny), d = c.normal, c.depth
    out = collide(a, ta, b, moved(tb, nx * d * (1 + 1e-9), ny * d * (1 + 1e-9)))
    assert out is None or out.depth < 1e-9
    if d < 1e-9:
        return
    still = collide(a, ta, b, moved(tb, nx * d * (1 - 1e-6), ny * d * (1 - 1e-6)))
    assert still is not None and still.depth == pytest.approx(d * 1e-6, rel=1e-3, abs=1e-12)


def _push_out(a, ta, b, tb, ux, uy):
    lo, hi = 0.0, 16.0
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        if collide(a, ta, b, moved(tb, ux * mid, uy * mid)):
            lo = mid
        else:
            hi = mid
    return hi


@pytest.mark.slow
@settings(max_examples=60, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(capsules, poses, others, poses)
def test_the_depth_is_the_shortest_push_out(cap, pa, other, pb):
    c = collide(cap, pa, other, pb)
    assume(c is not None)
    shortest = min(_push_out(cap, pa, other, pb, math.cos(t), math.sin(t))
                   for t in (2 * math.pi * i / 180 for i in range(180)))
    assert c.depth <= shortest + 1e-9
    assert c.depth >= shortest - 0.05 * shortest  # (the sampled directions miss the best by < 1 degree)


@FAST
@given(capsules, poses, others, poses, st.sampled_from([(2.0**20, 0.0), (0.0, -(2.0**20)), (-(2.0**30), 2.0**25)]))
def test_translation_changes_nothing_but_the_point(cap, pa, other, pb, shift):
    c = collide(cap, pa, other, pb)
    m = collide(cap, moved(pa, *shift), other, moved(pb, *shift))
    assert (c is None) == (m is None)
    if c is not None:
        assert m.normal == c.normal and m.depth == c.depth
        assert m.point == pytest.approx((c.point[0] + shift[0], c.point[1] + shift[1]), abs=1e-6)


@FAST
@given(capsules, poses, others, poses, st.sampled_from([-60, -3, 5, 70]))
def test_scaling_by_a_power_of_two_scales_the_answer(cap, pa, other, pb, k):
    def scaled(shape):
        s = 2.0**k
        if isinstance(shape, Capsule):
            return Capsule(shape.radius * s, shape.length * s)
        if isinstance(shape, Circle):
            return Circle(shape.radius * s)
        if isinstance(shape, AABB):
            return AABB(shape.width * s, shape.height * s)
        return Polygon([(x * s, y * s) for x, y in shape.points])

    s = 2.0**k
    c = collide(cap, pa, other, pb)
    m = collide(scaled(cap), (pa[0] * s, pa[1] * s, pa[2]), scaled(other), (pb[0] * s, pb[1] * s, pb[2]))
    assert (c is None) == (m is None)
    if c is not None:
        assert m.normal == c.normal and m.depth == c.depth * s


@pytest.mark.slow
@settings(max_examples=300, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(capsules, poses, others, poses)
def test_shapely_agrees_on_overlap_distance_and_the_point(cap, pa, other, pb):
    ga, gb = geom(cap, pa), geom(other, pb)
    gap = ga.distance(gb)
    c = collide(cap, pa, other, pb)
    # (shapely's arcs are chords: 1e-3 of the radius is well clear of them)
    if gap > 1e-3:
        assert c is None
        return
    if ga.intersection(gb).area > 1e-3:
        assert c is not None
    if c is None:
        return
    # The point is in both shapes; the push-out at least the overlap's width along the normal.
    assert ga.distance(Point(*c.point)) <= 1e-3 and gb.distance(Point(*c.point)) <= 1e-3
    if not isinstance(other, (Capsule, Circle)) and ga.intersection(gb).area > 1e-2:
        after = geom(other, moved(pb, c.normal[0] * c.depth, c.normal[1] * c.depth))
        assert ga.intersection(after).area < 1e-3


@pytest.mark.slow
@FAST
@given(st.lists(st.tuples(capsules, poses, others, poses, st.booleans()), min_size=1, max_size=12))
def test_the_batch_kernel_gives_collides_answers(rows):
    sa, ta, sb, tb = [], [], [], []
    for cap, pa, other, pb, swap in rows:
        a, x, b, y = (other, pb, cap, pa) if swap else (cap, pa, other, pb)
        sa.append(a)
        ta.append(x)
        sb.append(b)
        tb.append(y)
    res = collide_many(sa, ta, sb, tb)
    for i in range(len(rows)):
        c = collide(sa[i], ta[i], sb[i], tb[i])
        assert (c is not None) == bool(res.hit[i])
        if c is not None:
            assert (c.normal.x, c.normal.y, c.depth, c.point.x, c.point.y) == (
                res.nx[i], res.ny[i], res.depth[i], res.px[i], res.py[i])


@FAST
@given(capsules, poses, others, poses, st.tuples(eighths, eighths))
def test_time_of_impact_is_the_first_overlap(cap, pa, other, pb, motion):
    mx, my = motion[0] * 4, motion[1] * 4
    imp = time_of_impact(cap, pa, (mx, my), other, pb)
    if imp is None:
        for i in range(1, 32):
            f = i / 32
            c = collide(cap, moved(pa, mx * f, my * f), other, pb)
            assert c is None or c.depth < 1e-9
        return
    f = imp.fraction
    assert 0.0 <= f < 1.0
    if f > 0.0:
        before = collide(cap, moved(pa, mx * f * (1 - 1e-9), my * f * (1 - 1e-9)), other, pb)
        assert before is None or before.depth < 1e-9
    swapped = time_of_impact(other, pb, (0, 0), cap, pa, (mx, my))
    assert swapped is not None and swapped.fraction == f


# --- raycasts against shapely --------------------------------------------------------------------

QUAD_SEGS = 64
# shapely's buffer puts its vertices on the circle: its arcs are chords, inside the true capsule by
# at most r (1 - cos(theta / 2)), theta = (pi / 2) / QUAD_SEGS. The polygon buffered by
# r / cos(theta / 2) has its edges tangent to the circle of radius r: it holds the true capsule.
OUTWARD = 1.0 / math.cos(math.pi / (4 * QUAD_SEGS))
ray_origins = st.tuples(st.integers(-48, 48).map(lambda i: i / 8), st.integers(-48, 48).map(lambda i: i / 8))
ray_aims = st.one_of(st.none(), st.tuples(eighths, eighths))


def _core(cap, pose):
    """The ends of the capsule's core segment in the world."""
    x, y, r = pose
    c, s, h = math.cos(r), math.sin(r), cap.half_length
    return (x + s * h, y - c * h), (x - s * h, y + c * h)


def _from_core(cap, pose, p):
    """How far ``p`` is from the capsule's core segment, and the nearest point of it."""
    (ax, ay), (bx, by) = _core(cap, pose)
    ex, ey = bx - ax, by - ay
    e2 = ex * ex + ey * ey
    t = 0.0 if e2 == 0.0 else min(1.0, max(0.0, ((p[0] - ax) * ex + (p[1] - ay) * ey) / e2))
    cx, cy = ax + t * ex, ay + t * ey
    return math.hypot(p[0] - cx, p[1] - cy), (cx, cy)


@pytest.mark.slow
@settings(max_examples=400, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(capsules, poses, ray_origins, st.tuples(eighths, eighths), ray_aims, st.one_of(st.just(math.inf),
                                                                                       st.floats(0, 20)))
def test_raycast_agrees_with_shapely(cap, pose, origin, direction, aim, max_distance):
    """Hit or miss and the distance, checked against shapely's buffered segment: the capsule lies
    between the buffer of r (inside it, its arcs being chords) and that of r / cos(theta / 2)
    (around it). A ray that misses the outer polygon misses; one through the inner polygon's
    interior hits, between its distances to the two. Rays starting in the band between them, or
    only grazing the inner one, are left out."""
    if aim is not None:  # most rays aimed near the capsule, so that most of them hit
        direction = (pose[0] + aim[0] - origin[0], pose[1] + aim[1] - origin[1])
    assume(direction != (0.0, 0.0))
    (a, b), r = _core(cap, pose), cap.radius
    inner = LineString([a, b]).buffer(r, quad_segs=QUAD_SEGS)
    outer = LineString([a, b]).buffer(r * OUTWARD * (1 + 1e-9) + 1e-12, quad_segs=QUAD_SEGS)
    dl = math.hypot(*direction)
    ux, uy = direction[0] / dl, direction[1] / dl
    line = LineString([origin, (origin[0] + 100.0 * ux, origin[1] + 100.0 * uy)])
    o = Point(origin)
    hit = raycast(cap, pose, origin, direction, max_distance)
    if inner.buffer(-1e-9).contains(o):  # inside: a hit where it starts, facing back along the ray
        event("inside")
        assert hit is not None and hit.distance == 0.0 and hit.point == origin
        assert hit.normal == pytest.approx((-ux, -uy), abs=1e-12)
        return
    if outer.contains(o) or outer.exterior.distance(o) <= 1e-9:
        event("origin in the band: left out")
        return  # in the band where the polygons and the capsule may differ
    if outer.distance(line) > 1e-9:
        event("miss")
        assert hit is None  # clear of the capsule's outside bound
        return
    # (through the interior: a ray along a straight side meets the polygon's boundary only, which
    # shapely counts as meeting it, and the contract as a graze, a miss)
    through = line.intersection(inner.buffer(-1e-7, quad_segs=QUAD_SEGS))
    if through.length <= 1e-6:
        event("graze of the band: left out")
        return  # a graze: the polygons cannot tell
    near, far = o.distance(line.intersection(outer)), o.distance(through)
    assert near <= far
    if max_distance < near * (1 - 1e-9):
        event("short of it")
        assert hit is None
        return
    if max_distance > far * (1 + 1e-9):
        assert hit is not None
    if hit is None:
        return
    event("hit")
    assert near - 1e-9 <= hit.distance <= far + 1e-9
    # The entry point lies on the capsule (radius r from its core) along the ray; the normal is the
    # outward one there, facing the ray.
    assert hit.point == pytest.approx((origin[0] + hit.distance * ux, origin[1] + hit.distance * uy), abs=1e-9)
    d, (cx, cy) = _from_core(cap, pose, hit.point)
    assert d == pytest.approx(r, rel=1e-9, abs=1e-9)
    assert hit.normal == pytest.approx(((hit.point[0] - cx) / d, (hit.point[1] - cy) / d), abs=1e-9)
    assert hit.normal.x * ux + hit.normal.y * uy < 0.0
