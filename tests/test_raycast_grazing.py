"""raycast: a ray that only grazes a shape misses, whatever the digits of its direction.

The contract (CONTRACT.md): "A ray that only grazes the boundary, never entering the interior,
misses." A ray along a box's or polygon's edge, exactly through a corner from outside, tangent to
a circle, or along a capsule's side or tangent to its cap never enters the open interior: ``None``.
Moved one ulp into the shape (the origin, or the direction turned by one ulp), it does enter:
a hit. Moved one ulp away, it misses.

Every placement below is exact in binary (dyadic coordinates; the slanted tangents come from 3-4-5
triangles, whose points (0.375, 0.5) on a circle of radius 0.625 are dyadic), so every expectation
is exact and written beside it. The directions are not round: the speeds 0.1 ... 19.9, 1/6, 1/3,
one ulp either side of 1, and so on; a slanted direction is (4, 3) times such a speed cut to 48
bits, so that it stays exactly parallel to (4, 3).

The bug this guards (ray.py before the fix): a circle was cast with its discriminant in floats, so
a tangent ray with a non-round direction (0.1, 0) got a discriminant of a few ulps and hit at
distance ~5 with normal (-1.5e-8, 1); a capsule's entry was the earliest entry and latest exit
over its rectangle and its two discs, and a ray along its side (tangent to both discs) hit
through the rounding slivers of the two tangents; a polygon's Cyrus-Beck times were compared in
floats, so a ray exactly through a corner could enter, or one entering by a hair could miss.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from shapely.geometry import LineString, Point
from shapely.geometry import Polygon as SPolygon

from framework import AABB, Capsule, Circle, Hitbox, Polygon, Scene, Transform, Velocity
from framework.collision import RayHit, Vec2, raycast

INF = math.inf


def _short(x: float, bits: int = 48) -> float:
    """``x`` rounded to ``bits`` significant bits: a non-round number whose products with small
    integers (3, 4, 6, 8) are exact."""
    m, e = math.frexp(x)
    return math.ldexp(round(math.ldexp(m, bits)), e - bits)


# 199 non-round speeds (the report's grid), and a few odd ones.
SPEEDS = [k / 10 for k in range(1, 200)] + [
    1 / 6, 1 / 3, 0.7, 1e-3, 12345.678, 3.3e7, math.nextafter(1.0, 0.0), math.nextafter(1.0, 2.0),
    2.0**-30 / 3, 1.0, 0.25,
]


def _up(x: float) -> float:
    return math.nextafter(x, INF)


def _down(x: float) -> float:
    return math.nextafter(x, -INF)


def _step(edge: float, centre: float, sign: int) -> float:
    """``edge`` moved by one ulp (up for sign +1): of ``edge`` itself, or of its offset from the
    shape's position ``centre`` where that is coarser. raycast works relative to the shape's
    position (the contract: to float64 rounding), so that is the smallest move it can see; at the
    origin it is one ulp of ``edge``."""
    ulp = max(abs(math.nextafter(edge, sign * INF) - edge),
              abs(math.nextafter(edge - centre, sign * INF) - (edge - centre)))
    v = edge + sign * ulp
    assert v - edge == sign * ulp and (v - centre) - (edge - centre) == sign * ulp  # (exact: dyadic)
    return v


# --- the report --------------------------------------------------------------------------------

def test_report_example():
    # The top of the circle r = 0.3125 at the origin is y = 0.3125: the ray y = 0.3125 only touches
    # it at (0, 0.3125). Before the fix: a hit at about 5 with normal (-1.5e-8, 1).
    assert raycast(Circle(0.3125), Transform(0, 0), (-5, 0.3125), (0.1, 0)) is None
    # One ulp lower the ray does enter, at x = -sqrt(r^2 - y^2), about -5.9e-9: distance about 5.
    y = _down(0.3125)
    hit = raycast(Circle(0.3125), Transform(0, 0), (-5, y), (0.1, 0))
    u = 0.3125 - y  # 2**-54
    chord = math.sqrt(u * (2 * 0.3125 - u))  # sqrt(r^2 - y^2), 5.9e-9
    assert hit.distance == pytest.approx(5 - chord, rel=1e-15, abs=0)
    assert hit.point.y == y
    assert hit.normal.x < 0 and hit.normal.y == pytest.approx(1.0, abs=1e-15)


# --- circles -------------------------------------------------------------------------------------

R = 0.3125  # 5/16


@pytest.mark.parametrize("cx, cy", [(0.0, 0.0), (-7.5, 3.25)])
@pytest.mark.parametrize("side", [1, -1], ids=["top", "bottom"])
@pytest.mark.parametrize("heading", [1, -1], ids=["rightward", "leftward"])
def test_circle_horizontal_tangents(cx, cy, side, heading):
    # The line y = cy + side * R touches the circle at (cx, cy + side * R) only: a miss for every
    # speed. One ulp toward the centre it enters, 5 - sqrt(R^2 - (y - cy)^2) from an origin 5 away
    # (on the side facing the ray); one ulp away it misses.
    top = cy + side * R  # exact
    ox = cx - 5 * heading
    inside, outside = _step(top, cy, -side), _step(top, cy, side)
    u = abs(top - inside)
    chord = math.sqrt(u * (2 * R - u))
    for s in SPEEDS:
        d = (heading * s, 0.0)
        assert raycast(Circle(R), Transform(cx, cy), (ox, top), d) is None, s
        assert raycast(Circle(R), Transform(cx, cy), (ox, outside), d) is None, s
        hit = raycast(Circle(R), Transform(cx, cy), (ox, inside), d)
        assert hit is not None, s
        assert hit.distance == pytest.approx(5 - chord, rel=1e-14, abs=0), s
        assert hit.point.y == inside
        assert hit.normal.x * heading < 0 and hit.normal.y == pytest.approx(side, abs=1e-14)


# Slanted tangents: the circle r = 0.625 at the origin has the dyadic point P = (-0.375, 0.5),
# outward normal n = (-0.6, 0.8); the tangent there runs along (4, 3). Mirrored four ways.
R2 = 0.625
SLANTED = [((sx * -0.375, sy * 0.5), (sx * -0.6, sy * 0.8), (sx * 4, sy * 3)) for sx in (1, -1) for sy in (1, -1)]


def _nudged(origin, direction, which, sign, centre=(0.0, 0.0)):
    """The origin (which 0, 1: by :func:`_step`, the shape at ``centre``) or the direction (which
    2, 3) with one component one ulp up (sign +1) or down (-1)."""
    vals = [*origin, *direction]
    if which < 2:
        vals[which] = _step(vals[which], centre[which], sign)
    else:
        vals[which] = math.nextafter(vals[which], sign * INF)
    return (vals[0], vals[1]), (vals[2], vals[3])


def _nudge_enters(normal, which, sign):
    """Whether the nudged tangent enters: the nudge moves the line at the tangent point by a tiny
    step along +-axis ``which % 2`` (a moved origin moves the whole line; a turned direction moves
    the line ahead of the origin, where the tangent point is), and the line enters exactly when that
    step has a component into the shape, against the outward normal ``n``: ``sign * n[i] < 0``."""
    return sign * normal[which % 2] < 0


@pytest.mark.parametrize("point, normal, tangent", SLANTED)
def test_circle_slanted_tangents(point, normal, tangent):
    # From P - 2 * tangent along tangent * c (c any speed cut to 48 bits: exactly parallel), the
    # ray touches the circle at P only: a miss. Nudged by one ulp, the sign rule of _nudge_enters.
    origin = (point[0] - 2 * tangent[0], point[1] - 2 * tangent[1])
    for s in SPEEDS:
        c = _short(s)
        d = (tangent[0] * c, tangent[1] * c)
        assert raycast(Circle(R2), Transform(0, 0), origin, d) is None, s
        # The reverse ray from beyond P: a miss too.
        beyond = (point[0] + 2 * tangent[0], point[1] + 2 * tangent[1])
        assert raycast(Circle(R2), Transform(0, 0), beyond, (-d[0], -d[1])) is None, s
        for which in range(4):
            for sign in (1, -1):
                o, dd = _nudged(origin, d, which, sign)
                hit = raycast(Circle(R2), Transform(0, 0), o, dd)
                assert (hit is not None) == _nudge_enters(normal, which, sign), (s, which, sign)
                if hit is not None:  # entered by a hair, next to P: its normal
                    assert hit.distance == pytest.approx(2 * math.hypot(*tangent), rel=1e-7)
                    assert hit.normal == pytest.approx(normal, abs=1e-6)


def test_circle_start_on_the_circle_and_inside():
    # On the circle at (0.375, 0.5) (outward normal (0.6, 0.8)): heading in, distance 0 with that
    # normal; along the tangent (4, -3) c, or out: a miss.
    p = (0.375, 0.5)
    for s in SPEEDS:
        c = _short(s)
        assert raycast(Circle(R2), (0, 0), p, (-c, -c)) == RayHit(0.0, Vec2(*p), Vec2(0.6, 0.8)), s
        assert raycast(Circle(R2), (0, 0), p, (4 * c, -3 * c)) is None, s
        assert raycast(Circle(R2), (0, 0), p, (-4 * c, 3 * c)) is None, s
        assert raycast(Circle(R2), (0, 0), p, (c, 0.0)) is None, s
    # At the top (0, R) heading along the tangent: a miss; one ulp below: strictly inside, distance
    # 0 at the origin with the negated unit direction.
    for s in SPEEDS:
        assert raycast(Circle(R), (0, 0), (0, R), (s, 0)) is None, s
        o = (0.0, _down(R))
        assert raycast(Circle(R), (0, 0), o, (s, 0)) == RayHit(0.0, Vec2(*o), Vec2(-1.0, 0.0)), s


# --- capsules ------------------------------------------------------------------------------------

H = 0.5  # half length: Capsule(R, 1) spans y in [-(H + R), H + R] = [-0.8125, 0.8125]


@pytest.mark.parametrize("cx, cy", [(0.0, 0.0), (2.5, -1.75)])
@pytest.mark.parametrize("side", [1, -1], ids=["right", "left"])
@pytest.mark.parametrize("heading", [1, -1], ids=["up", "down"])
def test_capsule_along_its_sides(cx, cy, side, heading):
    # The line x = cx + side * R runs along the capsule's straight side (and is tangent to both
    # caps where the side meets them): a miss at every speed. One ulp toward the axis it enters
    # the first cap, about 5 - H from an origin 5 below (or above) the centre; one ulp out it misses.
    cap = Capsule(R, 2 * H)
    x = cx + side * R
    inside, outside = _step(x, cx, -side), _step(x, cx, side)
    u = abs(x - inside)
    chord = math.sqrt(u * (2 * R - u))
    oy = cy - 5 * heading
    for s in SPEEDS:
        d = (0.0, heading * s)
        assert raycast(cap, Transform(cx, cy), (x, oy), d) is None, s
        assert raycast(cap, Transform(cx, cy), (outside, oy), d) is None, s
        hit = raycast(cap, Transform(cx, cy), (inside, oy), d)
        assert hit is not None, s
        assert hit.distance == pytest.approx(5 - H - chord, rel=1e-14, abs=0), s
        assert hit.point.x == inside
        assert hit.normal.x == pytest.approx(side, abs=1e-7) and hit.normal.y * heading < 0


@pytest.mark.parametrize("side", [1, -1], ids=["top", "bottom"])
@pytest.mark.parametrize("heading", [1, -1], ids=["rightward", "leftward"])
def test_capsule_tangent_to_its_cap_ends(side, heading):
    # The line y = side * (H + R) touches the capsule at its apex only: a miss; one ulp toward the
    # centre it enters the cap there; one ulp out it misses.
    cap = Capsule(R, 2 * H)
    y = side * (H + R)  # 0.8125, exact
    inside = _down(y) if side > 0 else _up(y)
    outside = _up(y) if side > 0 else _down(y)
    u = abs(y - inside)
    chord = math.sqrt(u * (2 * R - u))
    for s in SPEEDS:
        d = (heading * s, 0.0)
        assert raycast(cap, (0, 0), (-5 * heading, y), d) is None, s
        assert raycast(cap, (0, 0), (-5 * heading, outside), d) is None, s
        hit = raycast(cap, (0, 0), (-5 * heading, inside), d)
        assert hit is not None, s
        assert hit.distance == pytest.approx(5 - chord, rel=1e-14, abs=0), s
        assert hit.normal.y == pytest.approx(side, abs=1e-7)


# Slanted cap tangents: Capsule(0.625, 1) has its top cap's centre at (0, 0.5), so the dyadic point
# P = (-0.375, 1.0) of that cap has outward normal (-0.6, 0.8), tangent (4, 3); the line through P
# along (4, 3) stays 1.425 from the bottom cap's centre: it touches the capsule at P only.
CAP_SLANTED = [((sx * -0.375, sy * 1.0), (sx * -0.6, sy * 0.8), (sx * 4, sy * 3)) for sx in (1, -1) for sy in (1, -1)]


@pytest.mark.parametrize("point, normal, tangent", CAP_SLANTED)
def test_capsule_slanted_cap_tangents(point, normal, tangent):
    cap = Capsule(R2, 2 * H)
    origin = (point[0] - 2 * tangent[0], point[1] - 2 * tangent[1])
    beyond = (point[0] + 2 * tangent[0], point[1] + 2 * tangent[1])
    for s in SPEEDS:
        c = _short(s)
        d = (tangent[0] * c, tangent[1] * c)
        assert raycast(cap, (0, 0), origin, d) is None, s
        assert raycast(cap, (0, 0), beyond, (-d[0], -d[1])) is None, s
        for which in range(4):
            for sign in (1, -1):
                o, dd = _nudged(origin, d, which, sign)
                hit = raycast(cap, (0, 0), o, dd)
                assert (hit is not None) == _nudge_enters(normal, which, sign), (s, which, sign)
                if hit is not None:
                    assert hit.distance == pytest.approx(2 * math.hypot(*tangent), rel=1e-7)
                    assert hit.normal == pytest.approx(normal, abs=1e-6)


def test_capsule_start_on_its_boundary():
    cap = Capsule(R, 2 * H)
    for s in SPEEDS:
        # On the right side (R, 0): heading in, distance 0 with the side's normal (1, 0); along
        # the side, or out: a miss.
        assert raycast(cap, (0, 0), (R, 0), (-s, 0.3 * s)) == RayHit(0.0, Vec2(R, 0), Vec2(1, 0)), s
        assert raycast(cap, (0, 0), (R, 0), (0, s)) is None, s
        assert raycast(cap, (0, 0), (R, 0), (0, -s)) is None, s
        assert raycast(cap, (0, 0), (R, 0), (s, 0)) is None, s
        # At the apex (0, H + R): along the tangent, a miss; heading in, distance 0, normal (0, 1).
        assert raycast(cap, (0, 0), (0, H + R), (s, 0)) is None, s
        assert raycast(cap, (0, 0), (0, H + R), (s, -s)) == RayHit(0.0, Vec2(0, H + R), Vec2(0, 1)), s
        # One ulp inside the side: strictly inside, the negated unit direction.
        o = (_down(R), 0.0)
        assert raycast(cap, (0, 0), o, (0, s)) == RayHit(0.0, Vec2(*o), Vec2(0.0, -1.0)), s


# --- boxes and polygons --------------------------------------------------------------------------

BOXES = [AABB(2, 2), Polygon.box(2, 2)]


@pytest.mark.parametrize("shape", BOXES, ids=["aabb", "polygon_box"])
@pytest.mark.parametrize("cx, cy", [(0.0, 0.0), (3.5, -1.25)])
@pytest.mark.parametrize("axis", [0, 1], ids=["horizontal", "vertical"])
@pytest.mark.parametrize("side", [1, -1])
@pytest.mark.parametrize("heading", [1, -1])
def test_box_along_its_edges(shape, cx, cy, axis, side, heading):
    # A ray along an edge line (y = cy +- 1 horizontally, x = cx +- 1 vertically) grazes: a miss.
    # One ulp inside it enters through the face across its path, exactly 4 from an origin 5 from
    # the centre (to rounding of the speed), with that face's normal (0 or -+1, exactly).
    edge = (cy if axis == 0 else cx) + side  # exact
    inside, outside = _step(edge, cy if axis == 0 else cx, -side), _step(edge, cy if axis == 0 else cx, side)
    centre_along = cx if axis == 0 else cy
    start = centre_along - 5 * heading
    entry = centre_along - heading

    def ray(across, s):
        if axis == 0:
            return raycast(shape, (cx, cy), (start, across), (heading * s, 0.0))
        return raycast(shape, (cx, cy), (across, start), (0.0, heading * s))

    normal = (-heading, 0) if axis == 0 else (0, -heading)
    for s in SPEEDS:
        assert ray(edge, s) is None, s
        assert ray(outside, s) is None, s
        hit = ray(inside, s)
        assert hit is not None, s
        assert hit.distance == pytest.approx(4.0, rel=1e-15), s
        assert hit.point == pytest.approx((entry, inside) if axis == 0 else (inside, entry), rel=1e-15)
        assert hit.normal == normal


@pytest.mark.parametrize("shape", BOXES, ids=["aabb", "polygon_box"])
def test_box_exactly_through_a_corner(shape):
    for s in SPEEDS:
        c = _short(s)
        # From (-3, 0) along (2, 1) c: through the corner (-1, 1) and out again, touching the box
        # there only: a miss. (And the same line from beyond the corner, coming back.)
        assert raycast(shape, (0, 0), (-3, 0), (2 * c, c)) is None, s
        assert raycast(shape, (0, 0), (1, 2), (-2 * c, -c)) is None, s
        # From (-3, 3) along (1, -1) c: through the corner (-1, 1) into the box: a hit there,
        # 2 sqrt(2) away; the left and top faces are equally opposed to the ray, and the rule
        # prefers the one closest to vertical: (0, 1).
        hit = raycast(shape, (0, 0), (-3, 3), (c, -c))
        assert hit.distance == pytest.approx(2 * math.sqrt(2), rel=1e-15), s
        assert hit.point == pytest.approx((-1.0, 1.0), rel=1e-15) and hit.normal == (0.0, 1.0), s
        # From (-5, 1) along (2, -1) c: the line y = 1 - (x + 5) / 2 passes the corner (-1, -1)
        # from the left of the box to below it, touching it there only: a miss.
        assert raycast(shape, (0, 0), (-5, 1), (2 * c, -c)) is None, s


TRI = Polygon([(0, 0), (4, 0), (0, 4)])
# A square of side 10 turned by atan(3/4): CCW (0, 0), (8, 6), (2, 14), (-6, 8).
TURNED = Polygon([(0, 0), (8, 6), (2, 14), (-6, 8)])


def test_triangle_along_its_hypotenuse():
    for s in SPEEDS:
        # From (-4, 8) along (1, -1) s: the line x + y = 4 of the hypotenuse: a graze.
        assert raycast(TRI, (0, 0), (-4, 8), (s, -s)) is None, s
        assert raycast(TRI, (0, 0), (8, -4), (-s, s)) is None, s
        # One ulp lower (x + y < 4): it enters through the left face x = 0, 4 sqrt(2) away.
        hit = raycast(TRI, (0, 0), (-4, _down(8.0)), (s, -s))
        assert hit.distance == pytest.approx(4 * math.sqrt(2), rel=1e-14), s
        assert hit.normal == (-1.0, 0.0), s
        assert raycast(TRI, (0, 0), (-4, _up(8.0)), (s, -s)) is None, s
        # The line y = 4 touches the apex (0, 4) only; y = 0 runs along the bottom face.
        assert raycast(TRI, (0, 0), (-3, 4), (s, 0)) is None, s
        assert raycast(TRI, (0, 0), (-3, 0), (s, 0)) is None, s
        # One ulp below the apex: it enters by a hair, through the left face.
        hit = raycast(TRI, (0, 0), (-3, _down(4.0)), (s, 0))
        assert hit.distance == pytest.approx(3.0, rel=1e-15) and hit.normal == (-1.0, 0.0), s


@pytest.mark.parametrize("i", range(4))
def test_turned_square_along_each_edge(i):
    # The edge from v_i to v_{i+1} runs along e = v_{i+1} - v_i (one of (8, 6), (-6, 8), (-8, -6),
    # (6, -8)); its outward normal is (e_y, -e_x) / 10. From v_i - e along e c: a graze. With the
    # origin or the direction moved one ulp, the line moves off the edge: the sign rule of
    # _nudge_enters; entering, it crosses the face before v_i next to v_i, |e| = 10 from the origin.
    pts = TURNED.points
    (x0, y0), (x1, y1) = pts[i], pts[(i + 1) % 4]
    ex, ey = x1 - x0, y1 - y0
    normal = (ey / 10, -ex / 10)
    origin = (x0 - ex, y0 - ey)
    for s in SPEEDS:
        c = _short(s)
        d = (ex * c, ey * c)
        assert raycast(TURNED, (0, 0), origin, d) is None, s
        for which in range(4):
            for sign in (1, -1):
                o, dd = _nudged(origin, d, which, sign)
                hit = raycast(TURNED, (0, 0), o, dd)
                assert (hit is not None) == _nudge_enters(normal, which, sign), (s, which, sign)
                if hit is not None:  # through the previous face, at v_i (10 from the origin)
                    (px, py), (qx, qy) = pts[i - 1], pts[i]
                    assert hit.distance == pytest.approx(10.0, rel=1e-12)
                    assert hit.normal == pytest.approx(((qy - py) / 10, -(qx - px) / 10), abs=1e-15)


def test_turned_square_through_its_top_vertex():
    for s in SPEEDS:
        c = _short(s)
        # y = 14 touches the top vertex (2, 14) only: a miss. So does the line through it along
        # (2, 1), which stays outside the corner's 90-degree cone (between (6, -8) and (-8, -6)).
        assert raycast(TURNED, (0, 0), (-10, 14), (s, 0)) is None, s
        assert raycast(TURNED, (0, 0), (0, 13), (2 * c, c)) is None, s
        # One ulp below y = 14 it enters by a hair, through the upper-left face (normal (-0.6, 0.8)).
        hit = raycast(TURNED, (0, 0), (-10, _down(14.0)), (s, 0))
        assert hit.distance == pytest.approx(12.0, rel=1e-14), s
        assert hit.normal == pytest.approx((-0.6, 0.8), abs=1e-15), s
        # From (4, 16) along (-1, -1) c: through (2, 14) into the square, 2 sqrt(2) away; of the two
        # faces there, the upper-right one (normal (0.8, 0.6)) is the more opposed to the ray.
        hit = raycast(TURNED, (0, 0), (4, 16), (-c, -c))
        assert hit.distance == pytest.approx(2 * math.sqrt(2), rel=1e-15), s
        assert hit.point == pytest.approx((2.0, 14.0), rel=1e-15) and hit.normal == (0.8, 0.6), s


@pytest.mark.parametrize("rot", [0.3, 1.0, 2.5, -0.7])
def test_rotated_box_start_on_a_vertex(rot):
    # Polygon.box(2, 2) turned by a non-round angle: its vertices are whatever floats cos and sin
    # give. Starting exactly on one, heading inward, is "on the boundary heading inward": distance
    # 0 with an adjacent face's normal (facing the ray), never the negated direction (inside).
    c, s = math.cos(rot), math.sin(rot)
    box = Polygon.box(2, 2)
    for x, y in box.points:
        v = (c * x - s * y, s * x + c * y)  # the vertex, as the framework turns it
        for d in [(-v[0], -v[1]), (-0.1 * v[0], -0.1 * v[1])]:
            hit = raycast(box, Transform(0, 0, rot), v, d)
            assert hit.distance == 0.0 and hit.point == v
            dl = math.hypot(*d)
            cos_in = (hit.normal.x * d[0] + hit.normal.y * d[1]) / dl
            assert -1 + 1e-3 < cos_in < 0  # a face's normal facing the ray (about -cos 45 degrees)


# --- max_distance with non-round directions --------------------------------------------------------

@pytest.mark.parametrize(
    "shape, origin, distance, point",
    [
        (Circle(R), (-5, 0), 4.6875, (-R, 0)),  # 5 - 0.3125
        (AABB(2, 2), (-5, 0), 4.0, (-1, 0)),
        (Polygon.box(2, 2), (-5, 0), 4.0, (-1, 0)),
        (Capsule(R, 2 * H), (-5, 0), 4.6875, (-R, 0)),
    ],
)
def test_hit_at_exactly_max_distance(shape, origin, distance, point):
    # (0.1 happens to give the exact distance; other non-round speeds give it to rounding, and a
    # max_distance one ulp short may then still count.)
    for s in (0.1, 0.25, 1.0, 3.0):
        assert raycast(shape, (0, 0), origin, (s, 0), distance) == RayHit(distance, Vec2(*point), Vec2(-1, 0))
        assert raycast(shape, (0, 0), origin, (s, 0), _down(distance)) is None
    for s in SPEEDS:
        hit = raycast(shape, (0, 0), origin, (s, 0), distance * (1 + 1e-15))
        assert hit.distance == pytest.approx(distance, rel=1e-15) and hit.normal == (-1, 0), s


# --- properties ----------------------------------------------------------------------------------

# Dyadic values with few bits, so that a centre plus a half size (the shape's extreme coordinate)
# is exact.
dy = st.integers(-4096, 4096).map(lambda i: i / 64)
size = st.integers(1, 512).map(lambda i: i / 64)
speed = st.floats(1e-6, 1e6, allow_nan=False, allow_infinity=False)
far = st.floats(1, 1e6, allow_nan=False, allow_infinity=False)


@st.composite
def dyadic_polygons(draw):
    pts = draw(st.lists(st.tuples(st.integers(-64, 64), st.integers(-64, 64)), min_size=3, max_size=8, unique=True))
    hull = SPolygon(pts).convex_hull
    assume(hull.geom_type == "Polygon" and hull.area > 4)
    return Polygon([(x / 16, y / 16) for x, y in list(hull.exterior.coords)[:-1]])


shapes = st.one_of(
    st.builds(Circle, size),
    st.builds(AABB, size, size),
    st.builds(Capsule, size, size),
    dyadic_polygons(),
    st.builds(Polygon.box, size, size),
)


def _extremes(shape, x, y):
    """(top, bottom, right, left) of the shape placed unturned at (x, y), each exact."""
    if isinstance(shape, Circle):
        r = shape.radius
        return y + r, y - r, x + r, x - r
    if isinstance(shape, Capsule):
        top = shape.half_length + shape.radius
        return y + top, y - top, x + shape.radius, x - shape.radius
    if isinstance(shape, AABB):
        return y + shape.height / 2, y - shape.height / 2, x + shape.width / 2, x - shape.width / 2
    xs = [p[0] for p in shape.points]
    ys = [p[1] for p in shape.points]
    return y + max(ys), y + min(ys), x + max(xs), x + min(xs)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(shapes, dy, dy, st.sampled_from(range(4)), st.sampled_from([1, -1]), speed, far)
def test_exact_tangents_miss_one_ulp_in_hits(shape, x, y, which, heading, s, dist):
    # A horizontal ray at exactly the shape's top (or bottom) y, or a vertical one at exactly its
    # right (or left) x, touches it without entering: a miss, from either side, at any speed and
    # distance. Moved one ulp into the shape it enters (a hit, facing the ray); one ulp out, a miss.
    ext = _extremes(shape, x, y)[which]  # (exact: every value is a multiple of 1/128, below 2**8)
    # (At 0, one ulp is the subnormal 5e-324, which the local frame's power-of-two scaling flushes.)
    assume(ext != 0.0)
    centre_along = x if which < 2 else y
    start = centre_along - heading * (dist + 64)  # outside the shape, before it
    upper = 1 if which in (0, 2) else -1
    across_centre = y if which < 2 else x
    inside, outside = _step(ext, across_centre, -upper), _step(ext, across_centre, upper)

    def ray(across):
        if which < 2:
            return raycast(shape, (x, y), (start, across), (heading * s, 0.0))
        return raycast(shape, (x, y), (across, start), (0.0, heading * s))

    assert ray(ext) is None
    assert ray(outside) is None
    hit = ray(inside)
    assert hit is not None
    d = (heading, 0.0) if which < 2 else (0.0, heading)
    assert hit.normal.x * d[0] + hit.normal.y * d[1] < 0
    # Entered on the nudged line, within the shape's extent along it.
    top, bottom, right, left = _extremes(shape, x, y)
    if which < 2:
        assert hit.point.y == inside and left - 1e-9 <= hit.point.x <= right + 1e-9
    else:
        assert hit.point.x == inside and bottom - 1e-9 <= hit.point.y <= top + 1e-9


pyth = st.tuples(st.integers(1, 64), st.sampled_from([1, -1]), st.sampled_from([1, -1]), st.booleans())


@settings(max_examples=200, deadline=None)
@given(pyth, dy, dy, speed, st.integers(1, 64), st.sampled_from(range(5)), st.sampled_from([1, -1]),
       st.sampled_from(["circle", "capsule"]))
def test_slanted_tangents_property(p, x, y, s, back, which, sign, kind):
    # A circle of radius 5j/64 (or a capsule's cap of that radius) has the dyadic point
    # P = centre + (3, 4) j / 64 (mirrored, or with 3 and 4 swapped), outward normal (3, 4) / 5;
    # the tangent there runs along (4, -3). From P - back * (4, -3) along (4, -3) c (c cut to 48
    # bits) the ray touches the shape at P only: a miss. Nudged by one ulp (origin or direction),
    # the sign rule of _nudge_enters; "which" 4: no nudge.
    j, sx, sy, swap = p
    a, b = (4, 3) if swap else (3, 4)
    r = 5 * j / 64
    normal = (sx * a / 5, sy * b / 5)
    tangent = (sy * b, -sx * a)
    if kind == "circle":
        shape, cy = Circle(r), y
    else:
        # The cap on the normal's side: the other cap's centre is r + b / 5 from the tangent line.
        shape, cy = Capsule(r, 1.0), y + sy * 0.5
    point = (x + sx * a * j / 64, cy + sy * b * j / 64)
    origin = (point[0] - back * tangent[0], point[1] - back * tangent[1])
    c = _short(s)
    d = (tangent[0] * c, tangent[1] * c)
    if which == 4:
        assert raycast(shape, (x, y), origin, d) is None
        return
    o, dd = _nudged(origin, d, which, sign, (x, y))
    hit = raycast(shape, (x, y), o, dd)
    assert (hit is not None) == _nudge_enters(normal, which, sign)


@st.composite
def placed_shapes(draw):
    shape = draw(st.one_of(
        st.builds(Circle, st.integers(4, 40).map(lambda i: i / 8)),
        st.builds(Capsule, st.integers(4, 24).map(lambda i: i / 8), st.integers(1, 40).map(lambda i: i / 8)),
        st.builds(AABB, st.integers(4, 40).map(lambda i: i / 8), st.integers(4, 40).map(lambda i: i / 8)),
        dyadic_polygons(),
    ))
    x, y = draw(st.floats(-20, 20)), draw(st.floats(-20, 20))
    rot = 0.0 if isinstance(shape, (Circle, AABB)) else draw(st.one_of(st.just(0.0), st.floats(-4, 4)))
    return shape, (x, y, rot)


def _shapely(shape, pose):
    x, y, rot = pose
    c, s = math.cos(rot), math.sin(rot)
    if isinstance(shape, Circle):
        return Point(x, y).buffer(shape.radius, quad_segs=512)
    if isinstance(shape, Capsule):
        h = shape.half_length
        ux, uy = (0.0, h) if rot == 0.0 else (-(s * h), c * h)
        return LineString([(x - ux, y - uy), (x + ux, y + uy)]).buffer(shape.radius, quad_segs=512)
    if isinstance(shape, AABB):
        hw, hh = shape.width / 2, shape.height / 2
        return SPolygon([(x - hw, y - hh), (x + hw, y - hh), (x + hw, y + hh), (x - hw, y + hh)])
    return SPolygon([(c * px - s * py + x, s * px + c * py + y) for px, py in shape.points])


@pytest.mark.slow
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(placed_shapes(), st.floats(0, 2 * math.pi), st.floats(8, 60), st.tuples(st.floats(-3, 3), st.floats(-3, 3)),
       st.floats(1e-3, 1e3))
def test_clear_entries_agree_with_shapely(placed, angle, dist, aim, s):
    # Rays from outside aimed near the shape, at non-round speeds: where shapely says the ray
    # clearly enters (it crosses the shape shrunk by 0.01 for a length of 0.01 or more), raycast
    # hits where shapely's intersection starts (circles and capsules as 512-segment quarter
    # circles: a radial error below 1e-5 of the radius); where it clearly misses, raycast misses.
    shape, pose = placed
    x, y, _ = pose
    origin = (x + dist * math.cos(angle), y + dist * math.sin(angle))
    ux, uy = x + aim[0] - origin[0], y + aim[1] - origin[1]
    ul = math.hypot(ux, uy)
    direction = (ux / ul * s, uy / ul * s)
    poly = _shapely(shape, pose)
    assume(not poly.buffer(0.01).contains(Point(origin)))
    line = LineString([origin, (origin[0] + 200 * ux / ul, origin[1] + 200 * uy / ul)])
    hit = raycast(shape, pose, origin, direction)
    if line.distance(poly) > 0.01:
        assert hit is None
        return
    assume(line.intersection(poly.buffer(-0.01)).length >= 0.01)
    assert hit is not None
    expect = Point(origin).distance(line.intersection(poly))
    assert hit.distance == pytest.approx(expect, abs=1e-3)
    assert hit.normal.x * ux + hit.normal.y * uy < 0


@pytest.mark.parametrize("sign, hit", [(1.0, False), (-1.0, True)])
def test_a_direction_with_a_subnormal_component_from_a_face(sign, hit):
    """From the right face of a box, straight up but for a subnormal sideways component (5e-324):
    the left face is all but parallel, its entry time 0.5 / 5e-324 beyond float's range (the exact
    clip converted it to a float and raised OverflowError, found by hypothesis in
    tests/test_batch_queries.py). Leaning out it leaves at once (a miss); leaning in it enters
    there, at distance 0, through the right face."""
    s = Scene()
    box = s.spawn(Transform(0.0, 0.0), Hitbox(AABB(0.5, 0.5)), Velocity(0.0, 0.0))
    got = s.raycast((0.25, 0.0), (sign * 5e-324, 0.5))
    if not hit:
        assert got is None
    else:
        assert got is not None and got.entity == box and got.distance == 0.0
        assert (got.point.x, got.point.y) == (0.25, 0.0) and (got.normal.x, got.normal.y) == (1.0, 0.0)
