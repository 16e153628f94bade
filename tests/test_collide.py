"""``collide``: the hard cases, each with its exact expected answer derived in a comment.

Inputs are dyadic (sums of powers of two), so every expected value below is exact in float64.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import Point
from shapely.geometry import Polygon as SPolygon

from framework import AABB, Circle, Polygon, Transform
from framework.collision import Contact, Vec2, collide

T = Transform
ULP1 = 2.0**-52  # ulp of numbers in [1, 2)
SQRT_HALF = math.sqrt(0.5)


def both_orders(sa, ta, sb, tb) -> Contact | None:
    """``collide(A, B)``, checked against ``collide(B, A)``: same depth, negated normal."""
    c = collide(sa, ta, sb, tb)
    s = collide(sb, tb, sa, ta)
    assert (c is None) == (s is None), (c, s)
    if c is not None:
        assert s is not None
        assert s.depth == c.depth  # the same arithmetic in both orders: bit for bit
        assert s.normal == (-c.normal[0] + 0.0, -c.normal[1] + 0.0)
        assert c.depth > 0 and math.isfinite(c.depth)
        assert math.hypot(*c.normal) == pytest.approx(1.0, abs=1e-15)
    return c


def moved(t: Transform, dx: float, dy: float) -> Transform:
    return Transform(t.x + dx, t.y + dy, t.rotation)


# --- touching vs overlapping by one ulp ---------------------------------------------------------

@pytest.mark.parametrize("at", [(0.0, 0.0), (1e9, -1e9), (-2.0**40, 2.0**30)])
def test_box_box_touching_is_no_contact_and_one_ulp_is(at):
    x0, y0 = at
    a, ta = AABB(2, 2), T(x0, y0)
    # B's left edge at x0 + 2 - 1 = x0 + 1 = A's right edge: touching.
    assert both_orders(a, ta, AABB(2, 2), T(x0 + 2, y0)) is None
    assert both_orders(a, ta, AABB(2, 2), T(x0 - 2, y0)) is None
    assert both_orders(a, ta, AABB(2, 2), T(x0, y0 + 2)) is None
    assert both_orders(a, ta, AABB(2, 2), T(x0 + 2, y0 + 2)) is None  # corner to corner
    # One ulp closer (the ulp of x0 + 2): the interiors overlap by exactly that ulp, along +x.
    bx = math.nextafter(x0 + 2, -math.inf)
    ulp = (x0 + 2) - bx
    c = both_orders(a, ta, AABB(2, 2), T(bx, y0))
    assert c is not None
    assert c.normal == (1.0, 0.0) and c.depth == ulp
    # The contact point is in the closed overlap, the strip x in [x0 + 1 - ulp, x0 + 1].
    assert x0 + 1 - ulp <= c.point.x <= x0 + 1 and y0 - 1 <= c.point.y <= y0 + 1
    # One ulp further: apart.
    assert both_orders(a, ta, AABB(2, 2), T(math.nextafter(x0 + 2, math.inf), y0)) is None


def test_box_box_one_ulp_of_size():
    # Width 2 + 2**-51 (next float above 2): half-width 1 + 2**-52 reaches one ulp past x = 1.
    wide = AABB(math.nextafter(2.0, 3.0), 2)
    c = both_orders(wide, T(0, 0), AABB(2, 2), T(2, 0))
    assert c == Contact(Vec2(1.0, 0.0), ULP1, c.point) and 1 - ULP1 <= c.point.x <= 1 + ULP1


def test_circle_circle_three_four_five():
    # Centres (0, 0) and (3, 4) are 5 apart; radii 2 + 3 = 5: touching.
    assert both_orders(Circle(2), T(0, 0), Circle(3), T(3, 4)) is None
    assert both_orders(Circle(2), T(10, 20), Circle(3), T(13, 24)) is None
    assert both_orders(Circle(2), T(1e9, 1e9), Circle(3), T(1e9 + 3, 1e9 + 4)) is None
    # Radius one ulp larger: 2 + 2**-51. Then ra + rb = 5 + 2**-51 is not a float (it rounds to 5),
    # but the overlap is real, so the exact decision finds it and depth ~ 2**-51.
    c = both_orders(Circle(math.nextafter(2.0, 3.0)), T(0, 0), Circle(3), T(3, 4))
    assert c is not None
    assert c.depth == pytest.approx(2.0**-51, rel=1e-12)
    assert c.normal == pytest.approx((0.6, 0.8), abs=1e-15)
    # Centre one ulp closer: y = 4 - 2**-51. |d| = 5 - 0.8 * 2**-51 + O(2**-102), so the depth is
    # 0.8 * 2**-51 (a float computation of 5 - |d| would give 0).
    c = both_orders(Circle(2), T(0, 0), Circle(3), T(3, math.nextafter(4.0, 0.0)))
    assert c is not None
    assert c.depth == pytest.approx(0.8 * 2.0**-51, rel=1e-9)
    assert both_orders(Circle(2), T(0, 0), Circle(3), T(3, math.nextafter(4.0, 5.0))) is None


def test_box_circle_on_a_face():
    box = AABB(2, 2)
    # Circle radius 1 at x = 2: distance 1 from the face x = 1: touching.
    assert both_orders(box, T(0, 0), Circle(1), T(2, 0.5)) is None
    assert both_orders(box, T(0, 0), Circle(1), T(0.5, -2)) is None
    x = math.nextafter(2.0, 0.0)  # 2 - 2**-52: distance 1 - 2**-52 from the face
    c = both_orders(box, T(0, 0), Circle(1), T(x, 0.5))
    assert c is not None
    assert c.normal == (1.0, 0.0) and c.depth == ULP1
    assert c.point == (1.0, 0.5)  # the closest point of the face, in the (closed) overlap
    # The circle first: normal from the circle toward the box.
    c = collide(Circle(1), T(x, 0.5), box, T(0, 0))
    assert c is not None and c.normal == (-1.0, 0.0) and c.depth == ULP1


def test_box_circle_at_a_corner():
    box = AABB(2, 2)
    # Corner (1, 1); circle centre (1 + 3, 1 + 4) = (4, 5) is 5 away: radius 5 touches.
    assert both_orders(box, T(0, 0), Circle(5), T(4, 5)) is None
    assert both_orders(box, T(-8, 0), Circle(5), T(-4, 5)) is None
    # Radius one ulp more (5 + 2**-50): overlap of ~2**-50 along (0.6, 0.8), at the corner.
    c = both_orders(box, T(0, 0), Circle(math.nextafter(5.0, 6.0)), T(4, 5))
    assert c is not None
    assert c.depth == pytest.approx(2.0**-50, rel=1e-12)
    assert c.normal == pytest.approx((0.6, 0.8), abs=1e-15)
    assert c.point == (1.0, 1.0)
    # Rotated box (Polygon.box) by pi: the same square, to rounding; a clear overlap at the corner.
    c = both_orders(Polygon.box(2, 2), T(0, 0, math.pi / 2), Circle(5.5), T(4, 5))
    assert c is not None and c.depth == pytest.approx(0.5, abs=1e-12)


def test_polygon_polygon_touching_along_a_slanted_edge():
    # A: the triangle under x + y = 2; B: the triangle above it, sharing the hypotenuse.
    a = Polygon([(0, 0), (2, 0), (0, 2)])
    b = Polygon([(2, 0), (2, 2), (0, 2)])
    assert both_orders(a, T(0, 0), b, T(0, 0)) is None
    assert both_orders(a, T(100, 50), b, T(100, 50)) is None
    # B moved by -2**-52 in x: its hypotenuse is x + y = 2 - 2**-52, overlapping A's by 2**-52
    # measured along x, i.e. 2**-52 / sqrt(2) along the normal (1, 1) / sqrt(2).
    c = both_orders(a, T(0, 0), b, T(-ULP1, 0))
    assert c is not None
    assert c.normal == pytest.approx((SQRT_HALF, SQRT_HALF), abs=1e-15)
    assert c.depth == pytest.approx(ULP1 * SQRT_HALF, rel=1e-12)
    assert both_orders(a, T(0, 0), b, T(ULP1, 0)) is None


# --- undefined normals --------------------------------------------------------------------------

@pytest.mark.parametrize("at", [(0.0, 0.0), (5.0, -3.0), (1e9, 1e9)])
def test_concentric_circles_push_up_in_both_orders(at):
    ta = T(*at)
    for ra, rb in [(1, 2), (2, 1), (1.5, 1.5)]:
        for c in (collide(Circle(ra), ta, Circle(rb), ta), collide(Circle(rb), ta, Circle(ra), ta)):
            # Depth: B must move ra + rb to stop overlapping, in any direction: up by rule.
            assert c == Contact(Vec2(0.0, 1.0), ra + rb, Vec2(*at))


@pytest.mark.parametrize("sa, sb, normal, depth", [
    (AABB(2, 2), AABB(2, 2), (0.0, 1.0), 2.0),        # all four directions tie: up
    (AABB(4, 2), AABB(4, 2), (0.0, 1.0), 2.0),        # up and down tie (depth = height)
    (AABB(2, 4), AABB(2, 4), (1.0, 0.0), 2.0),        # left and right tie: right, by the rule
    (Polygon.box(2, 2), AABB(2, 2), (0.0, 1.0), 2.0),
    (AABB(2, 2), Circle(1), (0.0, 1.0), 2.0),         # circle at the box's centre: 1 + 1
    (Polygon.box(4, 4), Circle(1), (0.0, 1.0), 3.0),  # 2 + 1
])
def test_identical_placement_gives_the_fixed_undefined_direction(sa, sb, normal, depth):
    for t in (T(0, 0), T(-7.5, 3.25), T(2.0**30, -(2.0**30))):
        for c in (collide(sa, t, sb, t), collide(sb, t, sa, t)):
            assert c is not None and c.normal == normal and c.depth == depth


# --- containment: the full push-out -------------------------------------------------------------

@pytest.mark.parametrize("big, small, at, normal, depth", [
    # 2x2 box at (3, 0) in a 10x10 box: its left edge x = 2 must reach x = 5: 3 along +x (its
    # shadows overlap by 2 in x, which would be the wrong, partial answer).
    (AABB(10, 10), AABB(2, 2), (3.0, 0.0), (1.0, 0.0), 3.0),
    (AABB(10, 10), AABB(2, 2), (0.0, -3.5), (0.0, -1.0), 2.5),
    (Polygon.box(10, 10), AABB(2, 2), (3.0, 0.0), (1.0, 0.0), 3.0),
    # Circle r 1 at (3, 0) in a 10x10 box: the centre is 2 from the face x = 5, plus the radius.
    (AABB(10, 10), Circle(1), (3.0, 0.0), (1.0, 0.0), 3.0),
    # Circle r 1 at (1, 0) in a circle r 4: 4 - 1 + 1 = 4.
    (Circle(4), Circle(1), (1.0, 0.0), (1.0, 0.0), 4.0),
    # 2x2 box at (3, 0) in a circle r 10: the box leaves when its left edge x = 2 passes x = 10,
    # i.e. after 8 along +x (the rounded-box Minkowski sum's flat face x = 11).
    (Circle(10), AABB(2, 2), (3.0, 0.0), (1.0, 0.0), 8.0),
    (Circle(10), Polygon.box(2, 2), (0.0, 3.0), (0.0, 1.0), 8.0),
])
def test_containment_depth_is_the_full_push_out(big, small, at, normal, depth):
    ta, tb = T(0.5, -0.25), T(0.5 + at[0], -0.25 + at[1])
    c = both_orders(big, ta, small, tb)
    assert c is not None
    assert c.normal == pytest.approx(normal, abs=1e-15) and c.depth == pytest.approx(depth, abs=1e-12)
    # Moving B by normal * depth leaves them touching (None); a hair back, they overlap again.
    out = moved(tb, normal[0] * depth, normal[1] * depth)
    assert collide(big, ta, small, out) is None
    hair = moved(out, -normal[0] * 2.0**-20, -normal[1] * 2.0**-20)
    back = collide(big, ta, small, hair)
    assert back is not None and back.depth == pytest.approx(2.0**-20, rel=1e-9)


# --- the tie rule: a box landing on a corner is pushed up ---------------------------------------

@pytest.mark.parametrize("ground, faller", [
    (AABB(2, 2), AABB(2, 2)),
    (AABB(4, 2), AABB(1, 1)),
    (Polygon.box(2, 2), AABB(2, 2)),
    (AABB(2, 2), Polygon.box(2, 2)),
])
@pytest.mark.parametrize("side", [1.0, -1.0])
def test_box_on_a_corner_with_equal_overlaps_is_pushed_up(ground, faller, side):
    gw, gh = ground.points[2] if isinstance(ground, Polygon) else (ground.half_width, ground.half_height)
    fw, fh = faller.points[2] if isinstance(faller, Polygon) else (faller.half_width, faller.half_height)
    ov = 0.25  # equal overlap in x and y
    tb = T(side * (gw + fw - ov), gh + fh - ov)
    c = collide(ground, T(0, 0), faller, tb)
    assert c is not None and c.normal == (0.0, 1.0) and c.depth == ov
    s = collide(faller, tb, ground, T(0, 0))  # symmetric: the ground pushed down
    assert s is not None and s.normal == (0.0, -1.0) and s.depth == ov
    # Below the ground's corner: pushed down (the vertical one of the two equal choices).
    c = collide(ground, T(0, 0), faller, T(side * (gw + fw - ov), -(gh + fh - ov)))
    assert c is not None and c.normal == (0.0, -1.0)


def test_corner_tie_holds_under_rounding():
    # 0.1 and 0.3 are not dyadic: the two overlaps agree only to rounding, and the rule still
    # prefers vertical (rounding must not decide).
    ground, box = AABB(0.6, 0.6), AABB(0.2, 0.2)
    tb = T(0.3 + 0.1 - 0.07, 0.3 + 0.1 - 0.07)
    c = collide(ground, T(0, 0), box, tb)
    assert c is not None and c.normal == (0.0, 1.0)
    assert c.depth == pytest.approx(0.07, abs=1e-15)
    s = collide(box, tb, ground, T(0, 0))
    assert s is not None and s.normal == (0.0, -1.0)


# --- large coordinates, tiny and huge sizes -----------------------------------------------------

SCENES = [
    (AABB(2, 1), (0.0, 0.0, 0.0), Polygon([(0, 0), (2, 0.5), (0.5, 1.5)]), (0.75, 0.25, 0.0)),
    (Circle(1.5), (0.0, 0.0, 0.0), Polygon.box(1, 3), (1.25, 0.5, 0.0)),
    (Polygon.box(3, 1), (0.0, 0.0, 0.0), Circle(0.75), (0.5, 0.875, 0.0)),
    (Circle(1), (0.0, 0.0, 0.0), Circle(0.5), (1.0, 0.25, 0.0)),
    (AABB(4, 4), (0.0, 0.0, 0.0), AABB(1, 1), (1.0, 1.25, 0.0)),
]


@pytest.mark.parametrize("sa, pa, sb, pb", SCENES)
@pytest.mark.parametrize("shift", [(1e9, 0.0), (0.0, -1e9), (2.0**33, 2.0**33), (-(2.0**40), 123456.0)])
def test_far_from_the_origin_gives_the_same_answer(sa, pa, sb, pb, shift):
    # 1e9 + x is exact for these dyadic x, so the scene is exactly the same one, translated.
    here = collide(sa, pa, sb, pb)
    there = collide(sa, (pa[0] + shift[0], pa[1] + shift[1]), sb, (pb[0] + shift[0], pb[1] + shift[1]))
    assert here is not None and there is not None
    assert there.normal == here.normal and there.depth == here.depth
    assert there.point == pytest.approx((here.point[0] + shift[0], here.point[1] + shift[1]), abs=1e-6)


@pytest.mark.parametrize("sa, pa, sb, pb", SCENES)
@pytest.mark.parametrize("scale", [2.0**-30, 2.0**-100, 2.0**30, 2.0**100, 2.0**-1000, 2.0**1000])
def test_scaled_scenes_give_scaled_answers_exactly(sa, pa, sb, pb, scale):
    def sized(s):
        if isinstance(s, AABB):
            return AABB(s.width * scale, s.height * scale)
        if isinstance(s, Circle):
            return Circle(s.radius * scale)
        return Polygon([(x * scale, y * scale) for x, y in s.points])

    here = collide(sa, pa, sb, pb)
    there = collide(sized(sa), (pa[0] * scale, pa[1] * scale), sized(sb), (pb[0] * scale, pb[1] * scale))
    assert here is not None and there is not None
    assert there.normal == here.normal
    assert there.depth == here.depth * scale
    assert there.point == (here.point[0] * scale, here.point[1] * scale)


def test_tiny_and_huge_sizes():
    for s in (1e-9, 1e9, 1e-150, 1e150, 1e-300, 1e300):
        # Touching circles of radius s (centres 2s apart) are not a contact; at 1.5s they overlap
        # by 0.5s.
        assert collide(Circle(s), (0, 0), Circle(s), (2 * s, 0)) is None
        c = collide(Circle(s), (0, 0), Circle(s), (1.5 * s, 0))
        assert c is not None and c.depth == pytest.approx(0.5 * s, rel=1e-12) and c.normal == (1.0, 0.0)
        c = collide(AABB(s, s), (0, 0), AABB(s, s), (0.75 * s, 0.5 * s))
        assert c is not None and c.depth == pytest.approx(0.25 * s, rel=1e-12) and c.normal == (1.0, 0.0)
        c = collide(Polygon.box(s, s), (0, 0, 0.5), Circle(s), (s, 0))
        assert c is not None and c.depth > 0 and math.isfinite(c.depth)
    # A tiny circle deep inside a huge box, and a tiny box on a huge circle's rim.
    c = collide(AABB(1e9, 1e9), (0, 0), Circle(1e-9), (0, 5e8 - 1.0))
    assert c is not None and c.normal == (0.0, 1.0) and c.depth == pytest.approx(1.0 + 1e-9, rel=1e-12)
    c = collide(Circle(1e9), (0, 0), AABB(1e-9, 1e-9), (1e9, 0))
    assert c is not None and c.normal == (1.0, 0.0) and c.depth == pytest.approx(0.5e-9, rel=1e-6)


def test_extreme_magnitudes_never_give_nan_or_inf():
    big = 1.7e308
    cases = [
        (AABB(big, big), (0, 0), AABB(big, big), (big / 4, 0)),
        (Circle(big / 4), (-big, 0), Circle(big / 4), (-big + big / 8, 0)),
        (AABB(1, 1), (-big, 0), AABB(1, 1), (big, 0)),  # their offset overflows float64
        (Circle(1e-320), (0, 0), Circle(1e-320), (1e-320, 0)),
        (AABB(1e-300, 1e-300), (1e300, 0), AABB(1, 1), (1e300, 0)),
    ]
    for sa, ta, sb, tb in cases:
        for c in (collide(sa, ta, sb, tb), collide(sb, tb, sa, ta)):
            if c is not None:
                assert all(math.isfinite(v) for v in (*c.normal, c.depth, *c.point)) and c.depth > 0
    # Edges 1e-250 long: their products with coordinates of 1e-295 would underflow unless each
    # axis is rescaled; the depth is the sum of the half-heights, not the smallest float.
    thin, speck = AABB(1.0, 2.0**-830), AABB(2.0**-830, 2.0**-980)
    for c in (collide(thin, (0, 0), speck, (0, 0, 0.5)), collide(speck, (0, 0), thin, (0, 0))):
        assert c is not None and c.normal == (0.0, 1.0) and c.depth == 2.0**-831 + 2.0**-981
    c = collide(thin, (0, 0), Circle(2.0**-980), (0.25, 2.0**-831))  # centre on the top face
    assert c is not None and c.normal == (0.0, 1.0) and c.depth == pytest.approx(2.0**-980, rel=1e-9)
    # A contact whose depth is beyond float64 itself is refused, not returned as inf.
    with pytest.raises(ValueError, match="beyond float64"):
        collide(Circle(1.5e308), (0, 0), Circle(1.5e308), (0, 0))


# --- float32 and numpy inputs -------------------------------------------------------------------

def test_numpy_and_float32_inputs_compute_in_float64():
    f32 = np.float32
    a = AABB(f32(2.2), np.float64(1.1))
    b = Polygon(np.array([[0.0, 0.0], [1.3, 0.1], [0.4, 1.2]], dtype=np.float32))
    ta = T(f32(0.3), f32(-0.7), f32(0.2))
    tb = (np.float64(0.9), f32(-0.4), np.float64(0.1))
    c = collide(a, ta, b, tb)
    # The same values as Python floats (float32 values are exact in float64) give the same bits.
    plain = collide(
        AABB(float(f32(2.2)), 1.1),
        T(float(f32(0.3)), float(f32(-0.7))),
        Polygon([(0.0, 0.0), (float(f32(1.3)), float(f32(0.1))), (float(f32(0.4)), float(f32(1.2)))]),
        (0.9, float(f32(-0.4)), 0.1),
    )
    assert c is not None and c == plain
    assert all(type(v) is float for v in (*c.normal, c.depth, *c.point))


# --- contact point ------------------------------------------------------------------------------

def _shapely(shape, t: Transform | tuple):
    if isinstance(t, Transform):
        t = (t.x, t.y, t.rotation)
    x, y, r = t[0], t[1], (t[2] if len(t) > 2 else 0.0)
    if isinstance(shape, Circle):
        return Point(x, y), shape.radius
    if isinstance(shape, AABB):
        w, h = shape.half_width, shape.half_height
        return SPolygon([(x - w, y - h), (x + w, y - h), (x + w, y + h), (x - w, y + h)]), 0.0
    c, s = math.cos(r), math.sin(r)
    return SPolygon([(c * px - s * py + x, s * px + c * py + y) for px, py in shape.points]), 0.0


def in_closed(shape, t, point, tol: float) -> bool:
    geom, radius = _shapely(shape, t)
    return geom.distance(Point(*point)) <= radius + tol


SHAPES = [AABB(2, 1), Circle(0.75), Polygon([(0, 0), (2, 0.5), (0.5, 1.5)]), Polygon.box(1, 2)]


@pytest.mark.parametrize("sa", SHAPES)
@pytest.mark.parametrize("sb", SHAPES)
def test_contact_point_lies_in_the_closed_overlap(sa, sb):
    count = 0
    for i in range(-8, 9):
        for j in range(-8, 9):
            ta, tb = (0.1, -0.2, 0.3), (0.1 + i * 0.25, -0.2 + j * 0.25, -1.1 + 0.1 * i)
            c = collide(sa, ta, sb, tb)
            if c is None:
                continue
            count += 1
            assert in_closed(sa, ta, c.point, 1e-9) and in_closed(sb, tb, c.point, 1e-9), (i, j, c)
    assert count > 20


# --- rotation -----------------------------------------------------------------------------------

def test_polygon_rotates_about_its_hitbox_origin_not_its_centroid():
    # A 2x2 square whose centroid is (3, 1). Rotated by pi/2 about the origin, (x, y) -> (-y, x):
    # it covers x in [-2, 0], y in [2, 4] (centroid (-1, 3)). About its centroid it would stay put.
    square = Polygon([(2, 0), (4, 0), (4, 2), (2, 2)])
    probe = Circle(0.25)
    rot = T(0, 0, math.pi / 2)
    assert collide(square, rot, probe, T(-1, 3)) is not None
    assert collide(square, rot, probe, T(3, 1)) is None
    c = collide(square, rot, AABB(4, 0.5), T(-1, 4.125))  # overlapping its top face by 0.125
    assert c is not None and c.normal == pytest.approx((0.0, 1.0), abs=1e-12)
    assert c.depth == pytest.approx(0.125, abs=1e-12)
    # Rotating the transform by a full turn changes nothing (to rounding).
    a = collide(square, T(1, 1), probe, T(4, 2.125))
    b = collide(square, T(1, 1, 2 * math.pi), probe, T(4, 2.125))
    assert a is not None and b is not None and b.depth == pytest.approx(a.depth, abs=1e-12)


def test_aabb_ignores_rotation_but_polygon_box_rotates():
    probe = AABB(0.5, 0.5)
    for rot in (0.0, math.pi / 2, 1.0, -3.0):
        # AABB(4, 2) spans x in [-2, 2], y in [-1, 1] whatever the rotation.
        assert collide(AABB(4, 2), T(0, 0, rot), probe, T(1.75, 0)) is not None
        assert collide(AABB(4, 2), T(0, 0, rot), probe, T(0, 1.5)) is None
        unrotated = collide(AABB(4, 2), T(0, 0), probe, T(1, 0))
        assert collide(AABB(4, 2), T(0, 0, rot), probe, T(1, 0)) == unrotated
    # Polygon.box(4, 2) turned a quarter: spans x in [-1, 1], y in [-2, 2].
    turned = T(0, 0, math.pi / 2)
    assert collide(Polygon.box(4, 2), turned, probe, T(1.75, 0)) is None
    assert collide(Polygon.box(4, 2), turned, probe, T(0, 1.5)) is not None
    c = collide(Polygon.box(4, 2), T(0, 0, math.pi / 4), probe, T(0, 0))
    assert c is not None
    # Rotation of B matters too, and never for an AABB B.
    assert collide(probe, T(0, 0), Polygon.box(4, 2), T(0, 1.5, math.pi / 2)) is not None
    assert collide(probe, T(0, 0), AABB(4, 2), T(0, 1.5, math.pi / 2)) is None


def test_shapely_agrees_on_a_grid_of_rotated_pairs():
    a = Polygon([(-1, -0.5), (1.5, -0.25), (0.5, 1.25)])
    b = Polygon.box(1.5, 0.5)
    ga, _ = _shapely(a, (0.0, 0.0, 0.4))
    for i in range(-10, 11):
        for j in range(-10, 11):
            tb = (i * 0.2, j * 0.2, 0.1 * (i + j))
            gb, _ = _shapely(b, tb)
            inter = shapely.intersection(ga, gb).area
            c = collide(a, (0.0, 0.0, 0.4), b, tb)
            if inter > 1e-9:
                assert c is not None, (i, j)
            elif not ga.intersects(gb):
                assert c is None, (i, j)
