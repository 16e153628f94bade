"""Property tests of ``collide`` against independent references (shapely, a slow SAT, circle algebra).

Coordinates are dyadic (multiples of 1/8 or 1/16), so translations by 2**20 and midpoints are
exact and the invariance properties can demand bit-for-bit equality.
"""

from __future__ import annotations

import math
from fractions import Fraction

import pytest
import shapely
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from shapely.geometry import MultiPoint, Point
from shapely.geometry import Polygon as SPolygon

from framework import AABB, Circle, Polygon
from framework.collision import collide

FAST = settings(max_examples=150, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])

eighths = st.integers(-24, 24).map(lambda i: i / 8)
sizes = st.integers(1, 32).map(lambda i: i / 8)
angles = st.one_of(
    st.just(0.0), st.floats(-math.pi, math.pi), st.integers(-4, 4).map(lambda i: i * math.pi / 2)
)
hull_points = st.lists(st.tuples(st.integers(-16, 16), st.integers(-16, 16)), min_size=3, max_size=9)


@st.composite
def hull_polygons(draw) -> list[tuple[float, float]]:
    """Outline (as shapely gives it: closed, either winding) of the hull of random 1/8 points."""
    hull = MultiPoint([(x / 8, y / 8) for x, y in draw(hull_points)]).convex_hull
    assume(hull.geom_type == "Polygon" and hull.area >= 1 / 64)
    pts = [(float(x), float(y)) for x, y in hull.exterior.coords]
    return pts[::-1] if draw(st.booleans()) else pts


shapes = st.one_of(
    st.builds(AABB, sizes, sizes),
    st.builds(Circle, sizes),
    st.builds(Polygon.box, sizes, sizes),
    hull_polygons().map(Polygon),
)
poses = st.tuples(eighths, eighths, angles)


def world_outline(shape, pose) -> list[tuple[float, float]]:
    """Independent placement: the shape's world polygon (AABBs never rotate)."""
    x, y, r = pose
    if isinstance(shape, AABB):
        w, h = shape.width / 2, shape.height / 2
        return [(x - w, y - h), (x + w, y - h), (x + w, y + h), (x - w, y + h)]
    c, s = math.cos(r), math.sin(r)
    return [(c * px - s * py + x, s * px + c * py + y) for px, py in shape.points]


def sat_reference(pa, pb) -> tuple[float, tuple[float, float]]:
    """Slow SAT: min over every edge normal n of both polygons, both ways, of B's full push-out.

    Returns (depth, normal); depth <= 0 means separated or touching.
    """
    best = (math.inf, (0.0, 0.0))
    least_gap = math.inf
    for poly in (pa, pb):
        for (x0, y0), (x1, y1) in zip(poly, poly[1:] + poly[:1], strict=True):
            ln = math.hypot(x1 - x0, y1 - y0)
            n = ((y1 - y0) / ln, (x0 - x1) / ln)
            for sign in (1.0, -1.0):
                nx, ny = sign * n[0], sign * n[1]
                push = max(nx * x + ny * y for x, y in pa) - min(nx * x + ny * y for x, y in pb)
                least_gap = min(least_gap, push)
                if push < best[0]:
                    best = (push, (nx, ny))
    return best


def shapely_geom(shape, pose):
    if isinstance(shape, Circle):
        return Point(pose[0], pose[1]).buffer(shape.radius, quad_segs=64)
    return SPolygon(world_outline(shape, pose))


def reference(sa, pa, sb, pb) -> float:
    """Penetration depth (<= 0: no overlap) by independent means."""
    if isinstance(sa, Circle) and isinstance(sb, Circle):
        return sa.radius + sb.radius - math.hypot(pb[0] - pa[0], pb[1] - pa[1])
    if isinstance(sa, Circle) or isinstance(sb, Circle):
        (circ, cp), (poly, pp) = ((sa, pa), (sb, pb)) if isinstance(sa, Circle) else ((sb, pb), (sa, pa))
        geom, centre = SPolygon(world_outline(poly, pp)), Point(cp[0], cp[1])
        if geom.covers(centre):
            return circ.radius + geom.exterior.distance(centre)
        return circ.radius - geom.distance(centre)
    return sat_reference(world_outline(sa, pa), world_outline(sb, pb))[0]


def finite_contact(c) -> bool:
    return c is None or (c.depth > 0 and all(math.isfinite(v) for v in (*c.normal, c.depth, *c.point)))


# --- symmetry -----------------------------------------------------------------------------------

@FAST
@given(shapes, poses, shapes, poses)
def test_swapping_a_and_b_gives_the_same_depth_and_the_negated_normal(sa, pa, sb, pb):
    c, s = collide(sa, pa, sb, pb), collide(sb, pb, sa, pa)
    assert (c is None) == (s is None)
    if c is None:
        return
    assert finite_contact(c) and finite_contact(s)
    # Both orders do the same arithmetic (in the same local frame), so the depth is bit-identical.
    assert s.depth == c.depth
    negated = s.normal == pytest.approx((-c.normal[0], -c.normal[1]), abs=1e-12)
    # The one exception: a direction and its negation tie (undefined direction): both orders
    # then give the same, upward (or rightward) normal.
    undefined = s.normal == pytest.approx(c.normal, abs=1e-12) and (
        c.normal[1] > 1e-12 or (abs(c.normal[1]) <= 1e-12 and c.normal[0] > 0)
    )
    assert negated or undefined, (c, s)


# --- the MTV separates --------------------------------------------------------------------------

@FAST
@given(shapes, poses, shapes, poses)
def test_moving_b_by_the_mtv_separates_and_a_little_less_does_not(sa, pa, sb, pb):
    c = collide(sa, pa, sb, pb)
    if c is None:
        return
    (nx, ny), d = c.normal, c.depth
    out = collide(sa, pa, sb, (pb[0] + nx * d * (1 + 1e-9), pb[1] + ny * d * (1 + 1e-9), pb[2]))
    assert out is None or out.depth < 1e-9
    if d < 1e-9:
        return  # a sliver (e.g. from a rotation by 2 pi): a millionth of it is below the ulp of pb
    still = collide(sa, pa, sb, (pb[0] + nx * d * (1 - 1e-6), pb[1] + ny * d * (1 - 1e-6), pb[2]))
    assert still is not None
    assert still.depth == pytest.approx(d * 1e-6, rel=1e-3, abs=1e-12)


# --- invariances --------------------------------------------------------------------------------

@FAST
@given(hull_polygons(), st.integers(0, 20), st.integers(0, 20), shapes, poses, poses)
def test_vertex_order_winding_duplicates_and_collinear_points_change_nothing(pts, rot, at, sb, pa, pb):
    pts = pts[:-1]  # shapely closes the ring; drop the repeat
    n = len(pts)
    i = at % n
    mid = ((pts[i][0] + pts[(i + 1) % n][0]) / 2, (pts[i][1] + pts[(i + 1) % n][1]) / 2)  # exact
    variant = pts[: i + 1] + [mid] + pts[i + 1:]  # a collinear point
    variant = variant[: i + 1] + [variant[i]] + variant[i + 1:]  # a duplicate
    variant = variant[rot % len(variant):] + variant[: rot % len(variant)]  # another start
    if rot % 2:
        variant = variant[::-1]  # the other winding
    a, b = Polygon(pts), Polygon(variant)
    assert a == b and a.points == b.points
    assert collide(a, pa, sb, pb) == collide(b, pa, sb, pb)
    assert collide(sb, pb, a, pa) == collide(sb, pb, b, pa)


@FAST
@given(shapes, poses, shapes, poses, st.sampled_from([(2.0**20, 0.0), (0.0, -(2.0**20)), (2.0**20, 2.0**20),
                                                      (-(2.0**30), 2.0**25)]))
def test_translation_by_a_power_of_two_changes_nothing_but_the_point(sa, pa, sb, pb, shift):
    c = collide(sa, pa, sb, pb)
    moved = collide(sa, (pa[0] + shift[0], pa[1] + shift[1], pa[2]),
                    sb, (pb[0] + shift[0], pb[1] + shift[1], pb[2]))
    assert (c is None) == (moved is None)
    if c is not None:
        assert moved.normal == c.normal and moved.depth == c.depth
        assert moved.point == pytest.approx((c.point[0] + shift[0], c.point[1] + shift[1]), abs=1e-6)


# --- agreement with independent references ------------------------------------------------------

@pytest.mark.slow
@settings(max_examples=300, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(shapes, poses, shapes, poses)
def test_depth_and_overlap_agree_with_independent_references(sa, pa, sb, pb):
    ref = reference(sa, pa, sb, pb)
    assume(abs(ref) > 1e-9)  # not within rounding of touching
    c = collide(sa, pa, sb, pb)
    if ref < 0:
        assert c is None, (ref, c)
        return
    assert c is not None, ref
    assert c.depth == pytest.approx(ref, rel=1e-9, abs=1e-9)
    # Shapely's intersection agrees on overlap (circles as fine polygons: allow their chords).
    ga, gb = shapely_geom(sa, pa), shapely_geom(sb, pb)
    if ref > 1e-3:
        assert shapely.intersection(ga, gb).area > 0
    # The contact point lies in both closed shapes (to rounding; circles checked analytically).
    for shape, pose in ((sa, pa), (sb, pb)):
        if isinstance(shape, Circle):
            assert math.hypot(c.point[0] - pose[0], c.point[1] - pose[1]) <= shape.radius + 1e-9
        else:
            assert SPolygon(world_outline(shape, pose)).distance(Point(*c.point)) <= 1e-9


@pytest.mark.slow
@settings(max_examples=200, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(hull_polygons(), poses, hull_polygons(), poses)
def test_random_convex_polygons_agree_with_shapely_and_the_slow_sat(pa_pts, pa, pb_pts, pb):
    a, b = Polygon(pa_pts), Polygon(pb_pts)
    wa, wb = world_outline(a, pa), world_outline(b, pb)
    depth, _ = sat_reference(wa, wb)
    area = shapely.intersection(SPolygon(wa), SPolygon(wb)).area
    assume(abs(depth) > 1e-9)
    c = collide(a, pa, b, pb)
    assert (c is not None) == (area > 0) == (depth > 0), (c, area, depth)
    if c is not None:
        assert c.depth == pytest.approx(depth, rel=1e-9, abs=1e-12)


@FAST
@given(sizes, sizes, eighths, eighths, eighths, eighths)
def test_circle_pairs_match_the_analytic_depth(ra, rb, x0, y0, x1, y1):
    d = math.hypot(x1 - x0, y1 - y0)
    c = collide(Circle(ra), (x0, y0), Circle(rb), (x1, y1))
    # Exact decision: squared distance against squared radius sum, in integers (all /8 values).
    d2 = (x1 - x0) ** 2 + (y1 - y0) ** 2
    assert (c is not None) == (d2 < (ra + rb) ** 2)
    if c is not None:
        assert c.depth == pytest.approx(ra + rb - d, abs=1e-12)
        if d > 0:
            assert c.normal == pytest.approx(((x1 - x0) / d, (y1 - y0) / d), abs=1e-15)
        else:
            assert c.normal == (0.0, 1.0)


# --- never NaN or inf ---------------------------------------------------------------------------

wild = st.floats(min_value=-1e300, max_value=1e300, allow_nan=False)
wild_sizes = st.floats(min_value=1e-300, max_value=1e300)
ratios = st.floats(min_value=1e-9, max_value=1e9)
wild_shapes = st.one_of(
    st.builds(AABB, wild_sizes, wild_sizes),
    st.builds(Circle, wild_sizes),
    # Polygon.box of an aspect ratio a polygon can have (1e300 x 1e-300 is a segment in float64).
    st.builds(lambda w, q: Polygon.box(w, min(max(w * q, 1e-300), 1e300)), wild_sizes, ratios),
)


@FAST
@given(wild_shapes, st.tuples(wild, wild, wild), wild_shapes, st.tuples(wild, wild, wild))
def test_wild_magnitudes_never_give_nan_or_inf(sa, pa, sb, pb):
    assert finite_contact(collide(sa, pa, sb, pb))


@FAST
@given(wild_shapes, st.tuples(wild, wild, wild), wild_shapes, st.floats(-4, 4), st.floats(-4, 4))
def test_wild_magnitudes_near_each_other_never_give_nan_or_inf(sa, pa, sb, fx, fy):
    # B placed within a few of its and A's sizes of A, so that overlaps actually happen.
    reach = sa.bounding_radius + sb.bounding_radius
    pb = (pa[0] + fx * reach / 4, pa[1] + fy * reach / 4, 0.5)
    c = collide(sa, pa, sb, pb)
    assert finite_contact(c)
    s = collide(sb, pb, sa, pa)
    assert (c is None) == (s is None)


# --- exact decisions on arbitrary (non-dyadic) floats near touching -----------------------------

def exact_outline(shape, pose) -> list[tuple[Fraction, Fraction]]:
    """World outline in exact rationals: position + local vertex (rotated in float64, as placed)."""
    x, y, r = pose
    if isinstance(shape, AABB):
        w, h = Fraction(shape.width) / 2, Fraction(shape.height) / 2
        X, Y = Fraction(x), Fraction(y)
        return [(X - w, Y - h), (X + w, Y - h), (X + w, Y + h), (X - w, Y + h)]
    local = shape.points
    if r != 0.0:
        c, s = math.cos(r), math.sin(r)
        local = [(c * px - s * py, s * px + c * py) for px, py in local]
    return [(Fraction(x) + Fraction(lx), Fraction(y) + Fraction(ly)) for lx, ly in local]


def exact_polygons_overlap(pa, pb) -> bool:
    for poly in (pa, pb):
        for (x0, y0), (x1, y1) in zip(poly, poly[1:] + poly[:1], strict=True):
            ux, uy = y1 - y0, x0 - x1
            a = [ux * x + uy * y for x, y in pa]
            b = [ux * x + uy * y for x, y in pb]
            if max(a) <= min(b) or max(b) <= min(a):
                return False
    return True


def exact_circle_polygon_overlap(poly, cx, cy, r) -> bool:
    """Exact: squared distance from the centre to the closed CCW polygon < r^2."""
    inside = True
    best = None
    for (x0, y0), (x1, y1) in zip(poly, poly[1:] + poly[:1], strict=True):
        ex, ey = x1 - x0, y1 - y0
        if ex * (cy - y0) - ey * (cx - x0) < 0:
            inside = False
        t = min(max(((cx - x0) * ex + (cy - y0) * ey) / (ex * ex + ey * ey), 0), 1)
        d2 = (cx - x0 - t * ex) ** 2 + (cy - y0 - t * ey) ** 2
        best = d2 if best is None else min(best, d2)
    return inside or best < r * r


def exact_overlap(sa, pa, sb, pb) -> bool:
    if isinstance(sa, Circle) and isinstance(sb, Circle):
        d2 = (Fraction(pb[0]) - Fraction(pa[0])) ** 2 + (Fraction(pb[1]) - Fraction(pa[1])) ** 2
        return d2 < (Fraction(sa.radius) + Fraction(sb.radius)) ** 2
    if isinstance(sa, Circle) or isinstance(sb, Circle):
        (circ, cp), (poly, pp) = ((sa, pa), (sb, pb)) if isinstance(sa, Circle) else ((sb, pb), (sa, pa))
        return exact_circle_polygon_overlap(exact_outline(poly, pp), Fraction(cp[0]), Fraction(cp[1]),
                                            Fraction(circ.radius))
    return exact_polygons_overlap(exact_outline(sa, pa), exact_outline(sb, pb))


def nudge(v: float, steps: int) -> float:
    for _ in range(abs(steps)):
        v = math.nextafter(v, math.copysign(math.inf, steps))
    return v


@st.composite
def float_polygons(draw, scale: float) -> Polygon:
    if draw(st.booleans()):
        return Polygon.box(draw(st.floats(0.1, 2)) * scale, draw(st.floats(0.1, 2)) * scale)
    pts = draw(st.lists(st.tuples(st.floats(-1, 1), st.floats(-1, 1)), min_size=3, max_size=7))
    hull = MultiPoint([(x * scale, y * scale) for x, y in pts]).convex_hull
    assume(hull.geom_type == "Polygon" and hull.area > 0.05 * scale * scale)
    try:
        return Polygon(list(hull.exterior.coords))
    except ValueError:
        assume(False)
        raise


@st.composite
def near_touching(draw):
    """A pair placed touching in real arithmetic (then rounded), nudged by a few ulps."""
    scale = draw(st.sampled_from([1.0, 0.001, 1000.0, 0.1]))
    far = draw(st.sampled_from([0.0, 1.0, 1e6]))
    pa = (draw(st.floats(-1, 1)) * far + draw(st.floats(-3, 3)), draw(st.floats(-1, 1)) * far, 0.0)
    theta = draw(st.floats(-math.pi, math.pi))
    size = st.floats(0.1, 2).map(lambda v: v * scale)
    kind = draw(st.sampled_from(["box-box", "circle-circle", "poly-poly", "poly-circle", "box-circle"]))
    if kind == "circle-circle":
        sa, sb = Circle(draw(size)), Circle(draw(size))
        dist = sa.radius + sb.radius
        pb = (pa[0] + dist * math.cos(theta), pa[1] + dist * math.sin(theta), 0.0)
    elif kind == "box-box":
        sa, sb = AABB(draw(size), draw(size)), AABB(draw(size), draw(size))
        sx, sy = draw(st.sampled_from([-1.0, 1.0])), draw(st.sampled_from([-1.0, 1.0]))
        fx, fy = draw(st.sampled_from([(1.0, None), (None, 1.0), (1.0, 1.0)]))
        reach_x, reach_y = (sa.width + sb.width) / 2, (sa.height + sb.height) / 2
        dx = sx * reach_x if fx else draw(st.floats(-1, 1)) * reach_x
        dy = sy * reach_y if fy else draw(st.floats(-1, 1)) * reach_y
        pb = (pa[0] + dx, pa[1] + dy, 0.0)
    else:
        rot_a = draw(st.sampled_from([0.0, theta]))
        sa = draw(float_polygons(scale)) if kind != "box-circle" else AABB(draw(size), draw(size))
        pa = (pa[0], pa[1], rot_a)
        world = [(float(x), float(y)) for x, y in exact_outline(sa, pa)]
        i = draw(st.integers(0, len(world) - 1))
        (x0, y0), (x1, y1) = world[i], world[(i + 1) % len(world)]
        ln = math.hypot(x1 - x0, y1 - y0)
        nx, ny = (y1 - y0) / ln, (x0 - x1) / ln  # outward (stored CCW; AABB outline CCW)
        t = draw(st.floats(-0.2, 1.2))
        foot = (x0 + t * (x1 - x0), y0 + t * (y1 - y0))
        if kind == "poly-poly":
            sb = draw(float_polygons(scale))
            rot_b = draw(st.floats(-math.pi, math.pi))
            local = [(float(x), float(y)) for x, y in exact_outline(sb, (0.0, 0.0, rot_b))]
            lo = min(local, key=lambda p: p[0] * nx + p[1] * ny)
            pb = (foot[0] - lo[0], foot[1] - lo[1], rot_b)
        else:
            sb = Circle(draw(size))
            if t < 0 or t > 1:  # beyond the edge: touch the vertex instead
                vx, vy = (x0, y0) if t < 0 else (x1, y1)
                pb = (vx + sb.radius * math.cos(theta), vy + sb.radius * math.sin(theta), 0.0)
            else:
                pb = (foot[0] + nx * sb.radius, foot[1] + ny * sb.radius, 0.0)
    steps = draw(st.tuples(st.integers(-3, 3), st.integers(-3, 3)))
    pb = (nudge(pb[0], steps[0]), nudge(pb[1], steps[1]), pb[2])
    if draw(st.booleans()):
        return sb, pb, sa, pa
    return sa, pa, sb, pb


@pytest.mark.slow
@settings(max_examples=400, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(near_touching())
def test_overlap_is_decided_exactly_on_any_floats(case):
    sa, pa, sb, pb = case
    expected = exact_overlap(sa, pa, sb, pb)
    c = collide(sa, pa, sb, pb)
    assert (c is not None) == expected, (c, expected)
    assert finite_contact(c)
