"""time_of_impact: the contract in CONTRACT.md, with exact expectations on dyadic input.

Fractions below are derived in comments: gap / closing speed along the contact normal. With
integer / dyadic coordinates the answers are exact, so most checks use ``==``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from shapely.geometry import Polygon as SPolygon

from framework import AABB, Capsule, Circle, Polygon, Transform
from framework.collision import Impact, Vec2, collide, time_of_impact
from framework.validation import InvalidValue

BOX = AABB(2, 2)  # at the origin: x, y in [-1, 1]
ORIGIN = Transform(0, 0)
TRI = Polygon([(0, 0), (4, 0), (0, 4)])
DIAMOND = Polygon([(0, -1), (1, 0), (0, 1), (-1, 0)])
R2 = math.sqrt(0.5)


def both_orders(shape_a, ta, ma, shape_b, tb, mb, fraction, normal, exact=True):
    """Check A against B and B against A: the same fraction, the normal negated."""
    for imp, n in (
        (time_of_impact(shape_a, ta, ma, shape_b, tb, mb), normal),
        (time_of_impact(shape_b, tb, mb, shape_a, ta, ma), (-normal[0] + 0.0, -normal[1] + 0.0)),
    ):
        assert imp is not None
        assert type(imp.fraction) is float and isinstance(imp.normal, Vec2)
        if exact:
            assert imp == Impact(fraction, Vec2(*n))
        else:
            assert imp.fraction == pytest.approx(fraction, abs=1e-12)
            assert imp.normal == pytest.approx(n, abs=1e-12)


def no_impact_either_order(shape_a, ta, ma, shape_b, tb, mb):
    assert time_of_impact(shape_a, ta, ma, shape_b, tb, mb) is None
    assert time_of_impact(shape_b, tb, mb, shape_a, ta, ma) is None


# --- exact fractions ---------------------------------------------------------------------------

def test_box_box():
    # B's left face x = 4 meets A's right face x = 1 after 3 of its 4 units: 0.75, normal +x.
    both_orders(BOX, ORIGIN, (0, 0), BOX, Transform(5, 0), (-4, 0), 0.75, (1, 0))
    # The same relative motion made by A instead of B.
    both_orders(BOX, ORIGIN, (4, 0), BOX, Transform(5, 0), (0, 0), 0.75, (1, 0))
    # Falling: B (4 x 2 at y = 10, bottom y = 9) onto A's top y = 1: 8 of 16 units -> 0.5, +y.
    both_orders(BOX, ORIGIN, (0, 0), AABB(4, 2), Transform(1, 10), (0, -16), 0.5, (0, 1))
    # A Polygon.box behaves as the AABB when unrotated.
    both_orders(Polygon.box(2, 2), ORIGIN, (0, 0), BOX, Transform(5, 0), (-4, 0), 0.75, (1, 0))


def test_both_moving():
    # A moves +2, B (at x = 6) moves -6: the gap 4 between x = 1 and x = 5 closes at 8 per step.
    both_orders(BOX, ORIGIN, (2, 0), BOX, Transform(6, 0), (-6, 0), 0.5, (1, 0))
    # Diagonal, both moving: relative motion (-4, -8) of B at (3, 9); the y gap from A's top y = 1
    # to B's bottom y = 8 is 7, closing at 8 -> 0.875, when B's x is 3 - 0.875 * 4 = -0.5, well
    # over A (the x shadows overlap from 0.25 on): the top face, normal +y.
    both_orders(BOX, ORIGIN, (1, 2), BOX, Transform(3, 9), (-3, -6), 0.875, (0, 1))


def test_circle_circle():
    # Radii 1 + 2 = 3; centres 8 apart closing 10 per step: contact after 5 -> 0.5, normal +y.
    both_orders(Circle(1), ORIGIN, (0, 0), Circle(2), Transform(0, 8), (0, -10), 0.5, (0, 1))
    # 3-4-5: radii 1 + 4 = 5, centres (6, 8) apart (10) moving straight in: 0.5, normal (0.6, 0.8).
    both_orders(Circle(1), ORIGIN, (0, 0), Circle(4), Transform(6, 8), (-6, -8), 0.5, (0.6, 0.8))


def test_box_circle():
    # Circle r = 1 at y = 5 falling 4: its bottom y = 4 meets A's top y = 1 after 3 -> 0.75, +y.
    both_orders(BOX, ORIGIN, (0, 0), Circle(1), Transform(0, 5), (0, -4), 0.75, (0, 1))
    # Off-centre but over the face (x = 0.5): y = 2 reached after 3 of 8 -> 0.375, +y.
    both_orders(BOX, ORIGIN, (0, 0), Circle(1), Transform(0.5, 5), (0, -8), 0.375, (0, 1))
    # Onto the corner (1, 1): r = 5 from (7, 9) along -(3, 4); the centre is 5 from the corner at
    # (4, 5), in the corner's region (x > 1, y > 1): after 5 of 10 -> 0.5, normal (0.6, 0.8).
    both_orders(BOX, ORIGIN, (0, 0), Circle(5), Transform(7, 9), (-6, -8), 0.5, (0.6, 0.8))
    # From the side, circle moving and box moving: relative (-8, 0), gap 6 - 1 - 2 = 3 -> 0.375.
    both_orders(BOX, ORIGIN, (2, 0), Circle(2), Transform(6, 0.5), (-6, 0), 0.375, (1, 0))


def test_polygon_polygon():
    # Diamond (vertex down) at y = 5 falling 4 onto the box: its lowest vertex y = 4 meets y = 1
    # after 3 -> 0.75, normal +y (the diamond's own faces would be entered earlier, at 0.5).
    both_orders(BOX, ORIGIN, (0, 0), DIAMOND, Transform(0, 5), (0, -4), 0.75, (0, 1))
    # Triangle (0,0) (4,0) (0,4) and a 2 x 2 box at (5, 5) moving (-4, -4): the box's corner (4, 4)
    # meets the hypotenuse x + y = 4 at (2, 2) halfway -> 0.5, normal (1, 1) / sqrt(2).
    both_orders(TRI, ORIGIN, (0, 0), BOX, Transform(5, 5), (-4, -4), 0.5, (R2, R2), exact=False)
    # The triangle falling onto the box's top face, tip first from y = 9: 8 of 16 -> 0.5.
    tip_down = Polygon([(0, 0), (-2, 2), (2, 2)])
    both_orders(BOX, ORIGIN, (0, 0), tip_down, Transform(0, 9), (0, -16), 0.5, (0, 1))


def test_rotated_shapes():
    # A 2 x 2 box turned 45 degrees is the diamond |x| + |y| < sqrt(2): falling from y = 5 its tip
    # reaches y = 1 after 4 - sqrt(2) of 4.
    both_orders(BOX, ORIGIN, (0, 0), Polygon.box(2, 2), Transform(0, 5, math.pi / 4), (0, -4),
                (4 - math.sqrt(2)) / 4, (0, 1), exact=False)
    # A circle r = 1 coming down the diagonal onto the face x + y = 2 of the diamond |x| + |y| < 2:
    # contact when (x + y - 2) / sqrt(2) = 1, i.e. the centre (c, c) with c = 1 + sqrt(0.5).
    big = Polygon([(0, -2), (2, 0), (0, 2), (-2, 0)])
    both_orders(big, ORIGIN, (0, 0), Circle(1), Transform(5, 5), (-4, -4), (4 - R2) / 4, (R2, R2),
                exact=False)


# --- ties ----------------------------------------------------------------------------------------

def test_corner_meets_corner_prefers_vertical():
    # B's corner (2, 2) runs along the diagonal into A's corner (1, 1): both axes are entered at
    # 0.5. tiebreak.pick prefers the direction closest to vertical: (0, 1); swapped, (0, -1).
    both_orders(BOX, ORIGIN, (0, 0), BOX, Transform(3, 3), (-2, -2), 0.5, (0, 1))
    both_orders(BOX, ORIGIN, (0, 0), BOX, Transform(-3, 3), (2, -2), 0.5, (0, 1))
    both_orders(BOX, ORIGIN, (0, 0), BOX, Transform(3, -3), (-2, 2), 0.5, (0, -1))


@pytest.mark.parametrize("turn", [0.0, 6.100261378556396e-19, -1e-12, 1e-15])
def test_nearly_parallel_capsules_side_by_side(turn):
    # Two upright capsules (radius 1/4, core 1/4) a unit apart, B (turned by almost nothing) closing
    # at 3/4: the gap of 1/4 closes after a third of the step, flat side on flat side. The cores'
    # hull is then a sliver: the face rectangle on its far side reaches the near side too; its
    # normal must not be taken for the near one's (found by the swap-symmetry property).
    a, b = Capsule(0.25, 0.25), Capsule(0.25, 0.25)
    ab = time_of_impact(a, (0, 0, 0), (0, 0), b, (0.75, 0, turn), (-0.75, 0))
    ba = time_of_impact(b, (0.75, 0, turn), (-0.75, 0), a, (0, 0, 0), (0, 0))
    assert ab.fraction == ba.fraction == pytest.approx(1 / 3, abs=1e-12)
    assert ab.normal == pytest.approx((1.0, 0.0), abs=1e-12)
    assert ba.normal == (-ab.normal.x + 0.0, -ab.normal.y + 0.0)


# --- grazes and touches ----------------------------------------------------------------------------

def test_sliding_along_a_face_misses():
    # B's bottom y = 1 runs along A's top y = 1: gap 0 throughout, never overlapping.
    no_impact_either_order(BOX, ORIGIN, (0, 0), BOX, Transform(-5, 2), (10, 0))
    no_impact_either_order(BOX, ORIGIN, (0, 0), Polygon.box(2, 2), Transform(-5, 2), (10, 0))
    # A circle sliding along the top face, and along the side face.
    no_impact_either_order(BOX, ORIGIN, (0, 0), Circle(1), Transform(-5, 2), (10, 0))
    no_impact_either_order(BOX, ORIGIN, (0, 0), Circle(0.5), Transform(1.5, -5), (0, 10))
    # Two circles passing at exactly the radius sum: tangent at x = 0.
    no_impact_either_order(Circle(1), ORIGIN, (0, 0), Circle(1), Transform(-5, 2), (10, 0))


def test_grazing_a_corner_misses():
    # B's corner (-2, 0) runs along the diagonal through A's corner (-1, 1) and on to (0, 2):
    # B (x < corner.x, y > corner.y) only ever touches A at that corner.
    no_impact_either_order(BOX, ORIGIN, (0, 0), BOX, Transform(-3, 1), (2, 2))
    # A circle r = 5 whose centre passes (-5, 4), exactly 5 from A's corner (-1, 1), moving along
    # (3, 4), i.e. perpendicular to (-4, 3): every point of A has 4x - 3y >= -7, so the centre's
    # line 4x - 3y = -32 stays >= 5 away, touching only at that instant.
    no_impact_either_order(BOX, ORIGIN, (0, 0), Circle(5), Transform(-11, -4), (12, 16))
    # Triangle tip grazing: the box's corner (-1, 1) slides past the triangle's apex (0, 4)? The
    # box at (-1, 5) moving (2, 0) has its bottom y = 4 level with the apex: a touch, then apart.
    no_impact_either_order(TRI, ORIGIN, (0, 0), BOX, Transform(-2, 5), (4, 0))


def test_contact_exactly_at_the_end_is_a_touch():
    # Gap 3, motion 3: touching exactly at fraction 1, so no impact.
    no_impact_either_order(BOX, ORIGIN, (0, 0), BOX, Transform(5, 0), (-3, 0))
    no_impact_either_order(Circle(1), ORIGIN, (0, 0), Circle(1), Transform(4, 0), (-2, 0))
    no_impact_either_order(BOX, ORIGIN, (0, 0), Circle(1), Transform(0, 5), (0, -3))
    no_impact_either_order(BOX, ORIGIN, (0, 0), DIAMOND, Transform(0, 5), (0, -3))
    # A hair more motion: an impact just before the end.
    imp = time_of_impact(BOX, ORIGIN, (0, 0), BOX, Transform(5, 0), (-3 - 2.0**-20, 0))
    assert imp.fraction == 3 / (3 + 2.0**-20) < 1.0
    assert imp.normal == (1, 0)


def test_touching_at_start():
    # Touching (gap 0) at the start: moving in -> fraction 0 with the contact normal; moving
    # apart or sliding -> no impact.
    both_orders(BOX, ORIGIN, (0, 0), BOX, Transform(0, 2), (0.5, -1), 0.0, (0, 1))
    both_orders(BOX, ORIGIN, (0, 0), Circle(1), Transform(2, 0.5), (-1, 0), 0.0, (1, 0))
    both_orders(Circle(1), ORIGIN, (0, 0), Circle(1), Transform(0, 2), (0, -1), 0.0, (0, 1))
    no_impact_either_order(BOX, ORIGIN, (0, 0), BOX, Transform(0, 2), (0, 1))
    no_impact_either_order(BOX, ORIGIN, (0, 0), BOX, Transform(0, 2), (1, 0))
    no_impact_either_order(Circle(1), ORIGIN, (0, 0), Circle(1), Transform(0, 2), (1, 0))


def test_already_overlapping_gives_collide_normal():
    cases = [
        (BOX, ORIGIN, BOX, Transform(1.5, 0.5)),
        (BOX, ORIGIN, Circle(1), Transform(0.25, 1.5)),
        (Circle(1), ORIGIN, Circle(2), Transform(1, 1)),
        (Circle(1), ORIGIN, Circle(1), ORIGIN),  # coincident centres: collide says (0, 1)
        (TRI, ORIGIN, DIAMOND, Transform(1, 1)),
    ]
    for a, ta, b, tb in cases:
        for ma, mb in [((0, 0), (0, 0)), ((3, -1), (0, 0)), ((0, 0), (-5, 7))]:
            c = collide(a, ta, b, tb)
            assert c is not None
            assert time_of_impact(a, ta, ma, b, tb, mb) == Impact(0.0, c.normal)


def test_zero_relative_motion():
    # Apart and not moving, or moving together: never an impact.
    assert time_of_impact(BOX, ORIGIN, (0, 0), BOX, Transform(5, 0)) is None
    assert time_of_impact(BOX, ORIGIN, (0, 0), BOX, Transform(5, 0), (0, 0)) is None
    assert time_of_impact(BOX, ORIGIN, (3, 1), BOX, Transform(5, 0), (3, 1)) is None
    assert time_of_impact(Circle(1), ORIGIN, (-7, 2), Circle(1), Transform(3, 0), (-7, 2)) is None
    assert time_of_impact(BOX, ORIGIN, (0, 0), Circle(1), Transform(2, 0), (0, 0)) is None  # touching


def test_moving_apart():
    assert time_of_impact(BOX, ORIGIN, (0, 0), BOX, Transform(5, 0), (4, 0)) is None
    assert time_of_impact(BOX, ORIGIN, (0, 0), Circle(1), Transform(0, 5), (3, 4)) is None
    assert time_of_impact(Circle(1), ORIGIN, (0, 0), Circle(1), Transform(0, 5), (0, 100)) is None


# --- no tunnelling -------------------------------------------------------------------------------

@pytest.mark.parametrize(
    "bullet", [AABB(0.125, 0.125), Circle(0.0625), Polygon([(0, 0), (0.125, 0), (0, 0.125)])]
)
def test_fast_bullet_hits_thin_wall(bullet):
    wall = AABB(0.25, 10)  # x in [-0.125, 0.125]
    start, motion = Transform(-100, 0.5), (1000, 1)
    # Before and after the step the bullet is clear of the wall: a discrete test would miss it.
    assert collide(bullet, start, wall, ORIGIN) is None
    assert collide(bullet, Transform(900, 1.5), wall, ORIGIN) is None
    imp = time_of_impact(bullet, start, motion, wall, ORIGIN)
    assert imp is not None and 0.0997 < imp.fraction < 0.1
    assert imp.normal == (1.0, 0.0)
    # The wall as A and the bullet as B: same fraction, normal negated.
    imp2 = time_of_impact(wall, ORIGIN, (0, 0), bullet, start, motion)
    assert imp2.fraction == pytest.approx(imp.fraction, abs=1e-15)
    assert imp2.normal == (-1.0, 0.0)
    # At the impact the bullet's leading edge is at the wall's face x = -0.125.
    c = collide(bullet, (-100 + 1000 * imp.fraction + 1e-9, 0.5 + imp.fraction), wall, ORIGIN)
    assert c is not None and c.depth < 1e-8


def test_bullet_exact():
    # 1/8 box bullet at x = -100, right face -99.9375, moving 1000: reaches x = -0.125 after
    # 99.8125 units -> 0.0998125; the circle (r = 1/16, same front) likewise.
    imp = time_of_impact(AABB(0.125, 0.125), Transform(-100, 0), (1000, 0), AABB(0.25, 10), ORIGIN)
    assert imp.fraction == pytest.approx(0.0998125, rel=1e-15)
    imp = time_of_impact(Circle(0.0625), Transform(-100, 0), (1000, 0), AABB(0.25, 10), ORIGIN)
    assert imp.fraction == pytest.approx(0.0998125, rel=1e-15)


# --- far from the origin, input types, bad input ---------------------------------------------------

@pytest.mark.parametrize("shift", [1e9, 2.0**40, -1e9])
def test_far_scene_same_answers(shift):
    cases = [
        (BOX, (0, 0), (0, 0), BOX, (5, 0), (-4, 0)),
        (BOX, (0, 0), (0, 0), Circle(5), (7, 9), (-6, -8)),
        (Circle(1), (0.5, 0), (1, 2), Circle(4), (6, 8), (-6, -8)),
        (TRI, (0, 0), (0, 0), BOX, (5, 5), (-4, -4)),
        (Polygon.box(2, 3), (1, 0), (0, 0), DIAMOND, (4, 4), (-4, -4)),
    ]
    for a, pa, ma, b, pb, mb in cases:
        for rot in (0.0, 0.4):
            near = time_of_impact(a, (*pa, rot), ma, b, (*pb, rot), mb)
            far = time_of_impact(a, (pa[0] + shift, pa[1], rot), ma, b, (pb[0] + shift, pb[1], rot), mb)
            assert near is not None and far == near


def test_numpy_inputs():
    expect = Impact(0.75, Vec2(1, 0))
    for f in (float, np.float64, np.float32):
        imp = time_of_impact(
            BOX, Transform(f(0), f(0)), (f(0), f(0)), BOX, Transform(f(5), f(0)), (f(-4), f(0))
        )
        assert imp == expect
        assert all(type(v) is float for v in (imp.fraction, *imp.normal))
    assert time_of_impact(BOX, (0, 0), np.zeros(2), BOX, (5, 0), np.array([-4.0, 0.0])) == expect
    motion = np.array([-4, 0], np.float32)
    assert time_of_impact(BOX, (0, 0), np.zeros(2, np.float32), BOX, (5, 0), motion) == expect


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(motion_a=(math.nan, 0)), ["motion_a", "nan"]),
        (dict(motion_b=(0, math.inf)), ["motion_b", "inf"]),
        (dict(motion_b="up"), ["motion_b", "up"]),
        (dict(motion_a=(1, 2, 3)), ["motion_a"]),
        (dict(motion_a=None), ["motion_a", "None"]),
        (dict(transform_a=(0, math.nan)), ["transform_a", "nan"]),
        (dict(shape_b=3), ["shape_b", "3"]),
    ],
)
def test_bad_input(kwargs, words):
    args = dict(
        shape_a=BOX, transform_a=ORIGIN, motion_a=(0, 0), shape_b=BOX, transform_b=(5, 0), motion_b=(-4, 0)
    )
    args.update(kwargs)
    with pytest.raises(ValueError) as err:
        time_of_impact(**args)
    assert isinstance(err.value, InvalidValue)
    for w in words:
        assert w in str(err.value)


def test_extreme_scales_never_nan():
    for e in (-600, -60, 60, 600):
        s = 2.0**e
        # The 3-4-5 circle pair and the box pair, scaled: the same fractions exactly.
        imp = time_of_impact(Circle(s), ORIGIN, (0, 0), Circle(4 * s), (6 * s, 8 * s), (-6 * s, -8 * s))
        assert imp == Impact(0.5, Vec2(0.6, 0.8))
        imp = time_of_impact(AABB(2 * s, 2 * s), ORIGIN, (0, 0), AABB(2 * s, 2 * s), (5 * s, 0), (-4 * s, 0))
        assert imp == Impact(0.75, Vec2(1, 0))
    # Huge motion against a small scene and tiny motion against a big one.
    imp = time_of_impact(BOX, ORIGIN, (0, 0), BOX, (5, 0), (-1e300, 0))
    assert imp.fraction == pytest.approx(3e-300, rel=1e-12) and imp.normal == (1, 0)
    assert time_of_impact(BOX, ORIGIN, (0, 0), BOX, (5, 0), (-1e-300, 0)) is None
    # Positions at opposite ends of the float range: their offset (2e308) and the relative motion
    # (-2e308) overflow float64. The gap 1e308 closes halfway through.
    big = AABB(1e308, 1e308)
    imp = time_of_impact(big, (-1e308, 0), (0.5e308, 0), big, (1e308, 0), (-1.5e308, 0))
    assert imp.fraction == pytest.approx(0.5, rel=1e-12) and imp.normal == (1, 0)
    big = Circle(0.5e308)
    imp = time_of_impact(big, (-1e308, 0), (0.5e308, 0), big, (1e308, 0), (-1.5e308, 0))
    assert imp.fraction == pytest.approx(0.5, rel=1e-12) and imp.normal == (1, 0)


# --- properties ------------------------------------------------------------------------------------

coord = st.integers(-40, 40).map(lambda i: i / 4)
size = st.integers(1, 24).map(lambda i: i / 4)


@st.composite
def convex_polygons(draw):
    small = st.integers(-12, 12).map(lambda i: i / 4)
    pts = draw(st.lists(st.tuples(small, small), min_size=3, max_size=7, unique=True))
    hull = SPolygon(pts).convex_hull
    assume(hull.geom_type == "Polygon" and hull.area > 0.5)
    return Polygon(list(hull.exterior.coords)[:-1])


shapes = st.one_of(st.builds(AABB, size, size), st.builds(Circle, size), convex_polygons(),
                   st.builds(Capsule, size, size))
angles = st.one_of(st.just(0.0), st.floats(-4, 4))
motions = st.tuples(st.integers(-80, 80).map(lambda i: i / 4), st.integers(-80, 80).map(lambda i: i / 4))


def _at(x, y, rot, motion, t):
    return (x + t * motion[0], y + t * motion[1], rot)


def _overlap_end(a, ta, ma, b, tb, mb):
    """When the overlap that starts at the impact ends: the reversed sweep from the step's end."""
    end_a = (ta[0] + ma[0], ta[1] + ma[1], ta[2])
    end_b = (tb[0] + mb[0], tb[1] + mb[1], tb[2])
    if collide(a, end_a, b, end_b) is not None:
        return 1.0
    back = time_of_impact(a, end_a, (-ma[0], -ma[1]), b, end_b, (-mb[0], -mb[1]))
    return None if back is None else 1.0 - back.fraction


# Aimed motions: B heads for a point near A's start, at 1 to 2 times the distance, so that most
# sweeps hit.
aims = st.one_of(
    st.none(),
    st.tuples(st.integers(-8, 8).map(lambda i: i / 4), st.integers(-8, 8).map(lambda i: i / 4),
              st.sampled_from([1.0, 1.5, 2.0])),
)


def _aimed(xa, ya, xb, yb, ma, mb, aim):
    if aim is None:
        return mb
    return (ma[0] + (xa + aim[0] - xb) * aim[2], ma[1] + (ya + aim[1] - yb) * aim[2])


@pytest.mark.slow
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(shapes, coord, coord, angles, motions, shapes, coord, coord, angles, motions, aims)
def test_consistent_with_collide(a, xa, ya, ra, ma, b, xb, yb, rb, mb, aim):
    mb = _aimed(xa, ya, xb, yb, ma, mb, aim)
    ta, tb = (xa, ya, ra), (xb, yb, rb)
    imp = time_of_impact(a, ta, ma, b, tb, mb)
    vx, vy = mb[0] - ma[0], mb[1] - ma[1]
    if imp is None:
        # No tunnelling: nowhere during the step do the interiors overlap (beyond rounding).
        for i in range(65):
            t = i / 64
            c = collide(a, _at(xa, ya, ra, ma, t), b, _at(xb, yb, rb, mb, t))
            assert c is None or c.depth < 1e-9
        return
    f = imp.fraction
    assert 0.0 <= f < 1.0
    assert math.hypot(*imp.normal) == pytest.approx(1.0, abs=1e-12)
    start = collide(a, ta, b, tb)
    if start is not None:
        assert imp == Impact(0.0, start.normal)
        return
    # At the impact B is closing on A along the normal.
    assert imp.normal.x * vx + imp.normal.y * vy < 1e-12 * math.hypot(vx, vy)
    # Just before the impact: apart (or touching, within rounding).
    if f > 1e-6:
        c = collide(a, _at(xa, ya, ra, ma, f - 1e-6), b, _at(xb, yb, rb, mb, f - 1e-6))
        assert c is None or c.depth < 1e-9
    # Between the impact and the end of the overlap (or of the step): overlapping.
    end = _overlap_end(a, ta, ma, b, tb, mb)
    assert end is not None and end >= f - 1e-9
    assume(end - f > 1e-6)  # not a near-graze
    mid = (f + end) / 2
    c = collide(a, _at(xa, ya, ra, ma, mid), b, _at(xb, yb, rb, mb, mid))
    assert c is not None
    # Right after the impact the overlap is shallow, and (for circles) along the impact normal.
    if end - f > 2e-6:
        t = f + 1e-6
        c = collide(a, _at(xa, ya, ra, ma, t), b, _at(xb, yb, rb, mb, t))
        assert c is not None and c.depth <= 1e-6 * math.hypot(vx, vy) + 1e-9
        if isinstance(a, Circle) and isinstance(b, Circle):
            assert tuple(c.normal) == pytest.approx(tuple(imp.normal), abs=1e-4)


@pytest.mark.slow
@settings(max_examples=300, deadline=None)
@given(shapes, coord, coord, angles, motions, shapes, coord, coord, angles, motions, aims)
def test_swap_symmetry(a, xa, ya, ra, ma, b, xb, yb, rb, mb, aim):
    mb = _aimed(xa, ya, xb, yb, ma, mb, aim)
    ta, tb = (xa, ya, ra), (xb, yb, rb)
    ab = time_of_impact(a, ta, ma, b, tb, mb)
    ba = time_of_impact(b, tb, mb, a, ta, ma)
    assert (ab is None) == (ba is None)
    if ab is None:
        return
    start = collide(a, ta, b, tb)
    if start is not None:  # collide's normal (its own symmetry rule, e.g. coincident circles)
        assert ab == Impact(0.0, start.normal)
        assert ba == Impact(0.0, collide(b, tb, a, ta).normal)
        return
    # Bit for bit, whatever the input: both orders do the same arithmetic (up to exact negations).
    assert ab.fraction == ba.fraction
    assert ab.normal == (-ba.normal.x + 0.0, -ba.normal.y + 0.0)


@settings(max_examples=150, deadline=None)
@given(shapes, coord, coord, motions, shapes, coord, coord, motions, aims)
def test_translation_invariance(a, xa, ya, ma, b, xb, yb, mb, aim):
    mb = _aimed(xa, ya, xb, yb, ma, mb, aim)
    near = time_of_impact(a, (xa, ya), ma, b, (xb, yb), mb)
    far = time_of_impact(a, (xa + 1e9, ya - 1e9), ma, b, (xb + 1e9, yb - 1e9), mb)
    assert near == far
