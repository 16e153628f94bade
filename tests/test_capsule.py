"""Capsules: the shape, and its exact answers with every other shape (collide, the batch kernel).

Coordinates are dyadic and capsules upright (rotation 0), so the touching cases are exact: a gap
of exactly 0 is no collision, an overlap of one ulp is one.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import framework
from framework import AABB, Capsule, Circle, Polygon
from framework.collision import collide
from framework.collision.batch import collide_many
from framework.collision.kinds import KIND_CAPSULE, KIND_NAMES, PAIRS, kind_of

below = math.nextafter  # below(x, -inf): one ulp below x


# --- the shape ---------------------------------------------------------------------------------

def test_capsule_is_exported_and_is_a_frozen_slotted_shape() -> None:
    assert framework.Capsule is Capsule and framework.shapes.Capsule is Capsule
    assert "Capsule" in framework.__all__ and "Capsule" in framework.shapes.__all__
    c = Capsule(1, 2)
    assert c == Capsule(1.0, 2.0) and hash(c) == hash(Capsule(1.0, 2.0))
    assert c.kind == "capsule" and KIND_NAMES[kind_of(c)] == "capsule" and kind_of(c) == KIND_CAPSULE
    with pytest.raises(AttributeError):
        c.radius = 2.0  # type: ignore[misc]
    assert not hasattr(c, "__dict__")
    assert isinstance(c.radius, float) and isinstance(c.length, float)


@pytest.mark.parametrize(("args", "bad"), [
    ((0, 1), "0"), ((-1, 1), "-1"), ((math.nan, 1), "nan"), ((math.inf, 1), "inf"), (("1", 1), "'1'"),
    ((None, 1), "None"), ((True, 1), "True"),
    ((1, 0), "0"), ((1, -2.5), "-2.5"), ((1, math.nan), "nan"), ((1, -math.inf), "-inf"), ((1, 5e-324), "5e-324"),
])
def test_bad_sizes_raise_value_errors_naming_the_value(args, bad) -> None:
    with pytest.raises(ValueError, match="Capsule") as err:
        Capsule(*args)
    assert bad in str(err.value)


def test_a_capsule_whose_half_height_overflows_is_refused() -> None:
    with pytest.raises(ValueError, match="too large"):
        Capsule(1.7e308, 1.7e308)


def test_sizes_area_and_bounding_radius() -> None:
    c = Capsule(0.5, 3)
    assert (c.half_length, c.height, c.width, c.bounding_radius) == (1.5, 4.0, 1.0, 2.0)
    assert c.area == 3.0 + math.pi * 0.25
    # A capsule of length -> 0 is a circle; of radius -> 0 a thin rectangle.
    assert Capsule(2, 1e-300).area == pytest.approx(Circle(2).area, rel=1e-15)
    assert Capsule(1e-9, 4).area == pytest.approx(8e-9, rel=1e-8)


def _simpson(f, a: float, b: float, n: int = 4000) -> float:
    xs = np.linspace(a, b, n + 1)
    w = np.ones(n + 1)
    w[1:-1:2], w[2:-1:2] = 4.0, 2.0
    return float((f(xs) * w).sum() * (b - a) / (3 * n))


def _numeric_second_moment(r: float, length: float) -> float:
    """The integrals of 1 and x^2 + y^2 over the capsule by horizontal slices (half width w at
    height y: the slice gives 2 w and 2 (w^3 / 3 + y^2 w)), by Simpson's rule: over the rectangle
    in y, over each cap in the angle t (y = L/2 + r sin t, w = r cos t), where the integrand is
    smooth."""
    hl = length / 2

    def slab(y, w):
        return 2.0 * (w**3 / 3.0 + y * y * w)

    rect_m = _simpson(lambda y: slab(y, np.full_like(y, r)), -hl, hl)
    cap_m = _simpson(lambda t: slab(hl + r * np.sin(t), r * np.cos(t)) * r * np.cos(t), 0.0, math.pi / 2)
    cap_a = _simpson(lambda t: 2.0 * r * np.cos(t) * r * np.cos(t), 0.0, math.pi / 2)
    return (rect_m + 2 * cap_m) / (2 * r * length + 2 * cap_a)


@pytest.mark.parametrize(("r", "length"), [(1, 2), (0.5, 3), (2, 0.25), (1e-3, 1), (3, 1e-6), (1e6, 2e6)])
def test_second_moment_matches_a_numeric_integration(r, length) -> None:
    c = Capsule(r, length)
    assert c.second_moment == pytest.approx(_numeric_second_moment(r, length), rel=1e-6)


def test_second_moment_limits() -> None:
    assert Capsule(2, 1e-12).second_moment == pytest.approx(Circle(2).second_moment, rel=1e-9)
    # A thin rod of length L about its middle: L^2 / 12.
    assert Capsule(1e-9, 6).second_moment == pytest.approx(36 / 12, rel=1e-6)
    assert math.isfinite(Capsule(1e300, 1e300).bounding_radius)


# --- collide: exact answers ----------------------------------------------------------------------

CAP = Capsule(0.5, 2)  # core from (0, -1) to (0, 1); reaches y = +-1.5 and x = +-0.5 upright


def both_orders(a, ta, b, tb):
    """collide both ways; asserts the symmetry (same depth bit for bit, negated normal)."""
    c, s = collide(a, ta, b, tb), collide(b, tb, a, ta)
    assert (c is None) == (s is None)
    if c is not None:
        assert s.depth == c.depth
        assert (s.normal.x, s.normal.y) == (-c.normal.x + 0.0, -c.normal.y + 0.0)
    return c


@pytest.mark.slow
@pytest.mark.parametrize("other", [Circle(0.25), AABB(1, 0.5), Polygon.box(1, 0.5), CAP, Capsule(0.25, 1),
                                   Polygon([(-0.5, -0.25), (0.5, -0.25), (0, 0.25)])])
def test_touching_is_not_a_collision_and_one_ulp_of_overlap_is(other) -> None:
    # B below the capsule: its top at y = -1.5 exactly.
    if isinstance(other, Circle):
        top = other.radius
    elif isinstance(other, Capsule):
        top = other.half_length + other.radius
    elif isinstance(other, AABB):
        top = other.height / 2
    else:
        top = max(p[1] for p in other.points)
    y = -1.5 - top
    assert both_orders(CAP, (0, 0), other, (0, y)) is None
    c = both_orders(CAP, (0, 0), other, (0, below(y, math.inf)))
    assert c is not None and 0 < c.depth < 1e-15 and c.normal == (0, -1)
    # Beside it: B's left side at x = +0.5 exactly (upright shapes: the half widths are exact).
    if isinstance(other, (Circle, Capsule)):
        half = other.radius
    elif isinstance(other, AABB):
        half = other.width / 2
    else:
        half = max(p[0] for p in other.points)
    x = 0.5 + half
    assert both_orders(CAP, (0, 0), other, (x, 0.125)) is None
    c = both_orders(CAP, (0, 0), other, (below(x, -math.inf), 0.125))
    assert c is not None and 0 < c.depth < 1e-15 and c.normal == (1, 0)
    # At a large offset the same (the local frame)
    assert both_orders(CAP, (2.0**30, -(2.0**30)), other, (2.0**30 + x, 0.125 - 2.0**30)) is None


def test_end_caps_touch_diagonally_exactly() -> None:
    # A dyadic Pythagorean triple: (3/4, 1) from the core's end (0, 1), distance 5/4.
    r = 1.25 - 0.5
    assert both_orders(CAP, (0, 0), Circle(r), (0.75, 2.0)) is None
    c = both_orders(CAP, (0, 0), Circle(below(r, math.inf) + 2**-50), (0.75, 2.0))
    assert c is not None and c.normal == pytest.approx((0.6, 0.8), abs=1e-15)
    # Two capsules end to end along a diagonal: cores' ends (0, 1) and (0.75, 2) apart 5/4 = rsum.
    assert both_orders(CAP, (0, 0), Capsule(0.75, 2), (0.75, 3.0)) is None
    c = both_orders(CAP, (0, 0), Capsule(0.75, 2), (0.75, below(3.0, -math.inf)))
    assert c is not None and c.depth > 0


def test_capsule_and_circle_depths_and_normals() -> None:
    # beside the core: depth rsum - d, normal across
    c = both_orders(CAP, (1, 1), Circle(0.25), (1.5, 1.5))
    assert c.normal == (1, 0) and c.depth == 0.25
    assert c.point == pytest.approx((1.375, 1.5))
    # beyond the top end: along the axis
    c = both_orders(CAP, (0, 0), Circle(0.25), (0, 2.5))
    assert c is None
    c = both_orders(CAP, (0, 0), Circle(0.25), (0, 1.5))
    assert c.normal == (0, 1) and c.depth == 0.25
    # a circle inside the capsule, off the core: pushed out sideways, all the way
    big = Capsule(2, 4)
    c = both_orders(big, (0, 0), Circle(0.5), (0.5, 0.25))
    assert c.normal == (1, 0) and c.depth == 2.0
    # centre on the core: the direction is undefined between left and right: right, either order
    c, s = collide(big, (0, 0), Circle(0.5), (0, 0.25)), collide(Circle(0.5), (0, 0.25), big, (0, 0))
    assert c.depth == s.depth == 2.5 and c.normal == s.normal == (1, 0)
    # centre at the core's end: up (the closest to vertical of the equally short push-outs)
    c, s = collide(big, (0, 0), Circle(0.5), (0, 2)), collide(Circle(0.5), (0, 2), big, (0, 0))
    assert c.depth == 2.5 and c.normal == (0, 1)
    assert s.depth == 2.5 and s.normal == (0, -1)


def test_capsule_on_a_box_and_inside_a_box() -> None:
    # resting on a box, overlapping by 1/8: pushed straight up
    c = both_orders(AABB(4, 1), (0, 0), CAP, (1, 0.5 + 1.5 - 0.125))
    assert c.normal == (0, 1) and c.depth == 0.125 and c.point == (1, 0.5)  # on the box, in the capsule
    # the round end over the box's corner (2, 0.5), 3/4 and 1 from it, radius 1/2: apart by 3/4;
    # closer along the diagonal (3/5, 4/5): depth exactly as the circle's
    c = collide(AABB(4, 1), (0, 0), Capsule(1.5, 2), (2.75, 2.5))
    assert c.normal == pytest.approx((0.6, 0.8), abs=1e-15) and c.depth == pytest.approx(0.25, abs=1e-15)
    # containment: the full push-out, not the overlap of the shadows
    # (centred: left and right tie, an undefined direction: rightward, whichever comes first)
    c, s = collide(AABB(10, 10), (0, 0), CAP, (0, 0)), collide(CAP, (0, 0), AABB(10, 10), (0, 0))
    assert c.depth == s.depth == 5.5 and c.normal == s.normal == (1, 0)
    c = both_orders(AABB(10, 10), (0, 0), CAP, (1, 3))
    assert c.depth == 3.5 and c.normal == (0, 1)  # up: 5 - 3 + 1.5
    c, s = collide(CAP, (0, 0), AABB(0.25, 0.25), (0, 0.5)), collide(AABB(0.25, 0.25), (0, 0.5), CAP, (0, 0))
    assert c.depth == s.depth == 0.5 + 0.125 and c.normal == s.normal == (1, 0)


def test_capsule_and_polygon() -> None:
    tri = Polygon([(-1, 0), (1, 0), (0, 1)])
    # a capsule standing on the triangle's flat bottom from below: touching, then an ulp in
    assert both_orders(tri, (0, 0), CAP, (0, -1.5)) is None
    c = both_orders(tri, (0, 0), CAP, (0, below(-1.5, math.inf)))
    assert c.normal == (0, -1) and c.depth > 0
    # a capsule through the triangle's apex: the shortest push-out
    c = both_orders(tri, (0, 0), CAP, (0, 2.25))
    assert c.normal == (0, 1) and c.depth == pytest.approx(0.25)
    # a lying capsule on a slope: the slope's normal
    slope = Polygon([(-4, -4), (4, -4), (4, 4)])  # the face y = x, outward normal (-1, 1) / sqrt 2
    # lying along the face (its core on the line y = x, 1/4 outside it): depth 1/2 - 1/4
    c = both_orders(slope, (0, 0), Capsule(0.5, 2), (-0.125, 0.125, -math.pi / 4))
    assert c.normal == pytest.approx((-math.sqrt(0.5), math.sqrt(0.5)), abs=1e-14)
    assert c.depth == pytest.approx(0.5 - math.sqrt(2) / 8, abs=1e-15)
    moved = collide(slope, (0, 0), Capsule(0.5, 2), (-0.125 + c.normal.x * c.depth, 0.125 + c.normal.y * c.depth,
                                                     -math.pi / 4))
    assert moved is None or moved.depth < 1e-12


def test_capsule_and_capsule() -> None:
    # side by side, overlapping by 1/4
    c = both_orders(CAP, (0, 0), CAP, (0.75, 0.5))
    assert c.normal == (1, 0) and c.depth == 0.25 and c.point == (0.375, 1.0)  # in both
    # end to end
    c = both_orders(CAP, (0, 0), CAP, (0, 2.75))
    assert c.normal == (0, 1) and c.depth == 0.25
    # crossed at one place: the cores cross; push out across the wider shadow's shortest way
    # (the four ways out tie: up, whichever comes first)
    c, s = collide(CAP, (0, 0), CAP, (0, 0, math.pi / 2)), collide(CAP, (0, 0, math.pi / 2), CAP, (0, 0))
    assert c.depth == s.depth == pytest.approx(2.0) and c.normal == s.normal == (0, 1)
    # identical capsules at one place: out sideways (left and right tie: rightward)
    c = collide(CAP, (3, 3), CAP, (3, 3))
    assert c.depth == 1.0 and c.normal == (1, 0)
    # parallel, overlapping cores side by side (a tie across the long sides): across
    c = both_orders(CAP, (0, 0), CAP, (0.5, 0))
    assert c.normal == (1, 0) and c.depth == 0.5


def test_huge_and_far_scenes_give_the_same_answers() -> None:
    for shift in (0.0, 1e9, -(2.0**40)):
        c = collide(CAP, (shift, shift), CAP, (shift + 0.75, shift + 0.5))
        assert c.normal == (1, 0) and c.depth == 0.25
    # scale invariance by powers of two
    for k in (-500, -40, 40, 500):
        s = 2.0**k
        c = collide(Capsule(0.5 * s, 2 * s), (0, 0), Capsule(0.5 * s, 2 * s), (0.75 * s, 0.5 * s))
        assert c.normal == (1, 0) and c.depth == 0.25 * s
        assert collide(Capsule(0.5 * s, 2 * s), (0, 0), Circle(0.5 * s), (s, 0)) is None
        assert collide(Capsule(0.5 * s, 2 * s), (0, 0), Circle(0.5 * s), (below(s, 0.0), 0)) is not None


def test_collide_validates_and_lists_capsules_in_its_messages() -> None:
    with pytest.raises(ValueError, match="Capsule"):
        collide("capsule", (0, 0), CAP, (0, 0))  # type: ignore[arg-type]
    with pytest.raises(ValueError):
        collide(CAP, (0, math.nan), CAP, (0, 0))


def test_pair_table_has_every_capsule_pair() -> None:
    for k in (0, 1, 2, 3):
        assert (KIND_CAPSULE, k) in PAIRS and (k, KIND_CAPSULE) in PAIRS
    assert PAIRS[KIND_CAPSULE, KIND_CAPSULE].name == "capsule-capsule"


# --- the batch kernel gives collide's answers bit for bit -------------------------------------------

def _random_pairs(rng, n):
    def shape():
        k = rng.integers(5)
        if k == 0:
            return AABB(*rng.uniform(0.25, 3, 2))
        if k == 1:
            return Circle(rng.uniform(0.25, 2))
        if k == 2:
            return Polygon.box(*rng.uniform(0.25, 3, 2))
        if k == 3:
            return Polygon([(0, 0), (2, 0.5), (1, 2), (-0.5, 1)])
        return Capsule(rng.uniform(0.125, 1.5), rng.uniform(0.125, 3))

    sa, ta, sb, tb = [], [], [], []
    for _ in range(n):
        a, b = shape(), shape()
        if not isinstance(a, Capsule) and not isinstance(b, Capsule):
            b = Capsule(0.5, 1)
        sa.append(a)
        sb.append(b)
        # dyadic positions now and then (exact touching), random rotations or none
        ta.append((float(rng.integers(-16, 16)) / 8 if rng.random() < 0.3 else rng.uniform(-2, 2),
                   rng.uniform(-2, 2), float(rng.choice([0.0, rng.uniform(-4, 4)]))))
        tb.append((rng.uniform(-2, 2), float(rng.integers(-16, 16)) / 8 if rng.random() < 0.3 else rng.uniform(-2, 2),
                   float(rng.choice([0.0, rng.uniform(-4, 4)]))))
    return sa, ta, sb, tb


def test_collide_many_equals_collide_bit_for_bit() -> None:
    sa, ta, sb, tb = _random_pairs(np.random.default_rng(7), 1500)
    res = collide_many(sa, ta, sb, tb)
    hits = 0
    for i in range(len(sa)):
        c = collide(sa[i], ta[i], sb[i], tb[i])
        assert (c is not None) == bool(res.hit[i]), i
        if c is not None:
            hits += 1
            assert (c.normal.x, c.normal.y, c.depth, c.point.x, c.point.y) == (
                res.nx[i], res.ny[i], res.depth[i], res.px[i], res.py[i]), i
    assert 300 < hits < 1400


def test_collide_many_decides_touching_exactly() -> None:
    others = [Circle(0.25), AABB(1, 0.5), Polygon.box(1, 0.5), CAP]
    tops = [0.25, 0.25, 0.25, 1.5]
    sa, ta, sb, tb = [], [], [], []
    for o, top in zip(others, tops, strict=True):
        for y in (-1.5 - top, below(-1.5 - top, math.inf)):
            sa += [CAP, o]
            ta += [(0, 0), (0, y)]
            sb += [o, CAP]
            tb += [(0, y), (0, 0)]
    res = collide_many(sa, ta, sb, tb)
    assert res.hit.tolist() == [False, False, True, True] * 4
    assert (res.depth[res.hit] > 0).all()


# --- raycast -----------------------------------------------------------------------------------------

from framework.collision import raycast, time_of_impact  # noqa: E402


def test_raycast_hits_the_sides_and_the_caps_exactly() -> None:
    hit = raycast(CAP, (1, 1), (-4, 1.5), (1, 0))
    assert hit.distance == 4.5 and hit.point == (0.5, 1.5) and hit.normal == (-1, 0)
    hit = raycast(CAP, (0, 0), (0, -5), (0, 2))  # direction not unit: world units
    assert hit.distance == 3.5 and hit.point == (0, -1.5) and hit.normal == (0, -1)
    # the cap: from (3/8, -5) up, entering the bottom disc of radius 1/2 about (0, -1) at y = -1.3 ...
    hit = raycast(CAP, (0, 0), (0.375, -5), (0, 1))
    assert hit.distance == pytest.approx(5 - 1 - math.sqrt(0.25 - 0.375**2))
    assert hit.normal == pytest.approx((0.75, -math.sqrt(1 - 0.75**2)))


def test_raycast_grazing_misses_and_max_distance_counts() -> None:
    assert raycast(CAP, (0, 0), (-0.5, -5), (0, 1)) is None  # along the left side
    assert raycast(CAP, (0, 0), (-5, 1.5), (1, 0)) is None  # tangent to the top cap
    assert raycast(CAP, (0, 0), (-5, -1.5), (1, 0)) is None  # tangent to the bottom cap
    assert raycast(CAP, (0, 0), (0, -5), (0, 1), 3.5).distance == 3.5
    assert raycast(CAP, (0, 0), (0, -5), (0, 1), below(3.5, 0.0)) is None
    assert raycast(CAP, (0, 0), (0, -5), (0, -1)) is None  # away


def test_raycast_from_inside_and_from_the_boundary() -> None:
    hit = raycast(CAP, (0, 0), (0.25, 1.25), (3, 4), 0.0)
    assert hit.distance == 0 and hit.point == (0.25, 1.25) and hit.normal == pytest.approx((-0.6, -0.8))
    hit = raycast(CAP, (0, 0), (0.5, 0), (-1, 0))  # on the side, heading in
    assert hit.distance == 0 and hit.normal == (1, 0)
    hit = raycast(CAP, (0, 0), (0, 1.5), (0, -1))  # on the top, heading in
    assert hit.distance == 0 and hit.normal == (0, 1)
    assert raycast(CAP, (0, 0), (0.5, 0), (1, 0)) is None  # on the side, heading out


def test_raycast_on_a_turned_and_far_capsule() -> None:
    # lying (a quarter turn): its core from (1, 0) to (-1, 0) about the origin
    hit = raycast(CAP, (1e9, 5, math.pi / 2), (1e9 - 3, 5), (1, 0))
    assert hit.distance == pytest.approx(1.5, abs=1e-6) and hit.normal == pytest.approx((-1, 0))
    hit = raycast(CAP, (0, 0, math.pi / 2), (0.25, 3), (0, -1))
    assert hit.distance == pytest.approx(2.5) and hit.normal == pytest.approx((0, 1))


# --- time of impact ------------------------------------------------------------------------------

@pytest.mark.parametrize("other", [Circle(0.5), AABB(1, 1), Polygon.box(1, 1), CAP,
                                   Polygon([(-0.5, -0.5), (0.5, -0.5), (0, 0.5)])])
def test_time_of_impact_exact_fractions_and_grazing(other) -> None:
    # B (half width 1/2 upright) 3 to the right, moving left by 4: contact at gap 2 -> 1/2
    imp = time_of_impact(CAP, (0, 0), (0, 0), other, (3, 0.25), (-4, 0))
    assert imp.fraction == 0.5 and imp.normal == (1, 0)
    swapped = time_of_impact(other, (3, 0.25), (-4, 0), CAP, (0, 0), (0, 0))
    assert swapped.fraction == 0.5 and swapped.normal == (-1, 0)
    # the same motion split between the two
    imp = time_of_impact(CAP, (0, 0), (2, 0), other, (3, 0.25), (-2, 0))
    assert imp.fraction == 0.5 and imp.normal == (1, 0)
    # first touch at exactly the end of the step: None
    assert time_of_impact(CAP, (0, 0), (0, 0), other, (3, 0.25), (-2, 0)) is None
    # sliding along at gap 0: a graze
    assert time_of_impact(CAP, (0, 0), (0, 0), other, (1, -4), (0, 8)) is None
    # already overlapping: fraction 0 with collide's normal
    imp = time_of_impact(CAP, (0, 0), (0, 0), other, (0.75, 0), (5, 5))
    assert imp.fraction == 0.0 and imp.normal == collide(CAP, (0, 0), other, (0.75, 0)).normal
    # no relative motion
    assert time_of_impact(CAP, (0, 0), (1, 1), other, (3, 0.25), (1, 1)) is None


def test_time_of_impact_end_to_end_and_through_a_corner() -> None:
    # falling onto a box: the bottom cap meets the top face
    imp = time_of_impact(CAP, (0, 4), (0, -8), AABB(4, 1), (0, 0))
    assert imp.fraction == 0.25 and imp.normal == (0, -1)  # from A (above) toward B
    # a capsule falling past a box's corner, its side 0 away: a graze
    assert time_of_impact(CAP, (2.5, 4), (0, -8), AABB(4, 1), (0, 0)) is None
    # two capsules, one lying, the other falling onto its middle
    imp = time_of_impact(CAP, (0, 4), (0, -8), CAP, (0, 0, math.pi / 2))
    assert imp.fraction == pytest.approx(0.25) and imp.normal == pytest.approx((0, -1))


def _collides_at(sa, ta, ma, sb, tb, mb, f):
    return collide(sa, (ta[0] + ma[0] * f, ta[1] + ma[1] * f, ta[2]), sb, (tb[0] + mb[0] * f, tb[1] + mb[1] * f, tb[2]))


def test_time_of_impact_agrees_with_collide_along_the_way() -> None:
    rng = np.random.default_rng(11)
    sa, ta, sb, tb = _random_pairs(rng, 400)
    seen = 0
    for a, pa, b, pb in zip(sa, ta, sb, tb, strict=True):
        pa = (pa[0] * 3, pa[1] * 3, pa[2])
        ma = tuple(rng.uniform(-6, 6, 2))
        imp = time_of_impact(a, pa, ma, b, pb, (0, 0))
        if imp is None:
            # never overlapping at a sample of the step
            assert not any(_collides_at(a, pa, ma, b, pb, (0, 0), f) for f in np.linspace(0, 1, 41)[1:-1])
            continue
        seen += 1
        f = imp.fraction
        assert 0.0 <= f < 1.0
        if f > 1e-6:
            assert _collides_at(a, pa, ma, b, pb, (0, 0), f * (1 - 1e-9)) is None
            c = _collides_at(a, pa, ma, b, pb, (0, 0), min(f + 1e-7, 1.0))
            assert c is not None
            assert imp.normal == pytest.approx(tuple(c.normal), abs=1e-3)
    assert seen > 50


# --- the pipeline --------------------------------------------------------------------------------

from framework import Hitbox, Scene, Transform, Velocity  # noqa: E402


def tiles(scene, n, x0=-3.5):
    """A row of unit static tiles centred at y = 0: the floor's top is y = 0.5."""
    return [scene.spawn(Transform(x0 + i, 0.0), Hitbox(AABB(1, 1), body="static")) for i in range(n)]


def test_a_capsule_falls_onto_tiles_rests_at_its_height_and_sleeps() -> None:
    with Scene(gravity=(0.0, -10.0)) as s:
        tiles(s, 8)
        cap = s.spawn(Transform(0.5, 3.0), Velocity(), Hitbox(Capsule(0.25, 1.0)))  # on a seam
        lying = s.spawn(Transform(2.0, 3.0, math.pi / 2), Velocity(), Hitbox(Capsule(0.25, 1.0)))
        started = []
        for _ in range(400):
            s.step(1 / 60)
            started += [e for e in s.events if e.kind == "started"]
        assert {frozenset((e.a, e.b)) & {cap, lying} for e in started} >= {frozenset({cap}), frozenset({lying})}
        # resting: the round end on the floor's top (0.5 + 0.25 + 0.5), the lying one on its side
        assert s.get(cap, Transform).y == pytest.approx(1.25, abs=10 / 60**2 + 1e-9)
        assert s.get(cap, Transform).x == 0.5 and s.get(cap, Transform).rotation == 0.0
        assert s.get(lying, Transform).y == pytest.approx(0.75, abs=10 / 60**2 + 1e-9)
        assert s.get(lying, Transform).rotation == math.pi / 2  # capsules never turn from contacts
        assert s.get(cap, Velocity).y == 0.0
        assert s.counters["asleep"] == 2
        ys = s.get(cap, Transform).y
        for _ in range(100):
            s.step(1 / 60)
        assert s.get(cap, Transform).y == ys


def test_two_capsules_stack() -> None:
    with Scene(gravity=(0.0, -10.0)) as s:
        tiles(s, 5, x0=-2.0)
        low = s.spawn(Transform(0.0, 2.0), Velocity(), Hitbox(Capsule(0.25, 1.0)))
        high = s.spawn(Transform(0.0, 4.0), Velocity(), Hitbox(Capsule(0.25, 1.0)))
        for _ in range(600):
            s.step(1 / 60)
        assert s.get(low, Transform).y == pytest.approx(1.25, abs=1e-2)
        assert s.get(high, Transform).y == pytest.approx(2.75, abs=1e-2)
        assert s.get(high, Transform).x == pytest.approx(0.0, abs=1e-9)


def test_capsules_collide_with_circles_boxes_and_polygons_in_a_scene() -> None:
    with Scene(gravity=(0.0, -10.0)) as s:
        tiles(s, 12, x0=-5.5)
        cap = s.spawn(Transform(0.0, 1.25), Velocity(), Hitbox(Capsule(0.25, 1.0)))
        others = [s.spawn(Transform(0.0, 2.5), Velocity(), Hitbox(Circle(0.5))),
                  s.spawn(Transform(3.0, 1.25), Hitbox(Capsule(0.25, 1.0), body="static")),
                  s.spawn(Transform(3.0, 3.0), Velocity(), Hitbox(Polygon.box(1, 1))),
                  s.spawn(Transform(-3.0, 3.0), Velocity(), Hitbox(AABB(1, 1)))]
        for _ in range(300):
            s.step(1 / 60)
        # the ball rests on the capsule's round top, the box on the static capsule
        assert s.get(others[0], Transform).y == pytest.approx(1.25 + 0.75 + 0.5, abs=1e-2)
        assert s.get(others[2], Transform).y == pytest.approx(2.0 + 0.5, abs=1e-2)
        assert s.get(cap, Transform).y == pytest.approx(1.25, abs=1e-2)


def test_a_fast_capsule_with_ccd_does_not_tunnel() -> None:
    with Scene() as s:
        wall = s.spawn(Transform(10.0, 0.0), Hitbox(AABB(0.25, 4), body="static"))
        fast = s.spawn(Transform(0.0, 0.0), Velocity(600.0, 0.0), Hitbox(Capsule(0.25, 1.0), ccd=True))
        hits = []
        for _ in range(10):
            s.step(1 / 60)
            hits += [e for e in s.events if e.kind == "started"]
        assert s.get(fast, Transform).x <= 10.0 - 0.125 - 0.25 + 1e-9
        assert any({e.a, e.b} == {wall, fast} for e in hits)


def test_scene_queries_see_capsules() -> None:
    with Scene() as s:
        cap = s.spawn(Transform(0.0, 0.0, math.pi / 2), Hitbox(Capsule(0.5, 2.0), body="static"))
        up = s.spawn(Transform(5.0, 0.0), Hitbox(Capsule(0.5, 2.0)))
        hit = s.raycast((0.0, 5.0), (0.0, -1.0))
        assert hit.entity == cap and hit.distance == pytest.approx(4.5)
        hit = s.raycast((5.0, -5.0), (0.0, 1.0))
        assert hit.entity == up and hit.distance == 3.5 and hit.normal == (0, -1)
        assert s.query_point(1.25, 0.25) == [cap]  # in the lying capsule's round end
        assert s.query_point(1.5, 0.5) == []  # beside its corner, outside the cap
        assert s.query_point(5.0, 1.5) == [up] and s.query_point(5.0, 1.5 + 1e-9) == []
        assert s.query_box(4.0, 1.4, 4.6, 1.6) == []  # where a box would have its square corner
        assert s.query_box(4.75, 1.0, 5.25, 1.4) == [up]
        assert s.query_box(-10.0, -10.0, 10.0, 10.0) == sorted([cap, up])


# --- rendering -----------------------------------------------------------------------------------

def test_fill_triangles_and_the_overlay_outline_of_a_capsule() -> None:
    from framework.render.drawables import capsule_outline, fill_triangles

    shape = Capsule(10.0, 20.0)
    pts = capsule_outline(shape, 1.0)
    assert all(abs(math.hypot(x, abs(y) - 10.0) - 10.0) < 1e-9 for x, y in pts)
    assert max(y for _, y in pts) == 20.0 and min(y for _, y in pts) == -20.0
    tris = np.array(fill_triangles(shape)).reshape(-1, 3, 2)
    e1, e2 = tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum()
    assert area == pytest.approx(shape.area, rel=2e-2) and area < shape.area


def test_a_capsule_is_drawn_where_it_is_and_turns() -> None:
    try:
        import framework.render as render
        render.offscreen_window()
    except Exception as exc:  # no GL library, no EGL device: not a failure of the code under test
        pytest.skip(f"no OpenGL context available here ({type(exc).__name__}: {exc})")
    from framework.components import Visual

    red, bg = (255, 0, 0), (0, 0, 40)
    with Scene() as s:
        s.spawn(Transform(32.0, 24.0, math.pi / 2), Hitbox(Capsule(6.0, 24.0)), Visual(red))
        img = render.screenshot(s, width=64, height=48, background=bg)

        def at(sx, sy):
            return tuple(int(v) for v in img[47 - sy, sx, :3])

        # lying: from x = 32 - 18 to 32 + 18, 6 either side of y = 24
        assert at(32, 24) == red and at(15, 24) == red and at(48, 24) == red and at(32, 19) == red
        assert at(32, 31) == bg and at(12, 24) == bg and at(52, 24) == bg
        assert at(15, 29) == bg  # the rounded corner
        img = render.screenshot(s, width=64, height=48, background=bg, debug=True)
        # the outline (green: a dynamic body) along the top side and around the round ends
        assert at(32, 30)[1] > 0 and at(32, 30)[2] == 0 and at(32, 36)[1] == 0
        assert at(14, 26)[1] > 0 and at(50, 26)[1] > 0  # (lower down, the overlay text line)


def test_manifold_of_a_pair_with_a_capsule_is_collides_point() -> None:
    from framework.collision import manifold

    for other in (AABB(4, 1), Polygon.box(4, 1), Circle(0.5), CAP):
        c = collide(other, (0, 0), CAP, (0.25, 1.75))
        m = manifold(other, (0, 0), CAP, (0.25, 1.75))
        assert m.normal == c.normal and len(m.points) == 1
        assert m.points[0].point == c.point and m.points[0].depth == c.depth


@pytest.mark.slow
def test_a_capsule_slides_over_tile_seams_without_snagging() -> None:
    with Scene(gravity=(0.0, -10.0)) as s:
        tiles(s, 40, x0=0.0)
        cap = s.spawn(Transform(2.0, 1.25), Velocity(4.0, 0.0), Hitbox(Capsule(0.25, 1.0)))
        for _ in range(300):
            s.step(1 / 60)
            assert s.get(cap, Velocity).x == 4.0  # no push from a seam, ever
        assert s.get(cap, Transform).x == pytest.approx(2.0 + 4.0 * 300 / 60)
        assert s.get(cap, Transform).y == pytest.approx(1.25, abs=10 / 60**2 + 1e-9)
