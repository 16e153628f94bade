"""Shapes and Transform: validation, normalisation of polygon outlines, messages naming bad values."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from framework import AABB, Circle, Polygon, Transform
from framework.collision import collide
from framework.validation import InvalidValue, finite, positive, vector2

NAN, INF = math.nan, math.inf


def short(value: object) -> str:
    """A test id: the value's repr, cut short (10**400 has 401 digits)."""
    text = repr(value)
    return text if len(text) <= 24 else text[:21] + "..."


def raises_naming(bad: object, fn, *args, **kwargs) -> ValueError:
    """``fn(*args)`` raises ValueError whose message holds ``repr(bad)``."""
    with pytest.raises(ValueError) as info:
        fn(*args, **kwargs)
    assert repr(bad) in str(info.value), f"{bad!r} not named in: {info.value}"
    return info.value


# --- sizes --------------------------------------------------------------------------------------

BAD_SIZES = [NAN, INF, -INF, 0.0, -0.0, -1.5, None, "2", b"2", True, False, [2.0], 1 + 2j,
             np.float64(NAN), np.float32(INF), np.float64(-2.0), 10**400, 5e-324]


@pytest.mark.parametrize("bad", BAD_SIZES, ids=short)
@pytest.mark.parametrize(
    "make",
    [
        lambda v: AABB(v, 1.0),
        lambda v: AABB(1.0, v),
        lambda v: Polygon.box(v, 1.0),
        lambda v: Polygon.box(1.0, v),
    ],
    ids=["AABB.width", "AABB.height", "box.width", "box.height"],
)
def test_bad_box_sizes_raise_naming_the_value(make, bad):
    err = raises_naming(bad, make, bad)
    assert isinstance(err, InvalidValue)


@pytest.mark.parametrize("bad", [b for b in BAD_SIZES if not (isinstance(b, float) and b == 5e-324)],
                         ids=short)
def test_bad_radius_raises_naming_the_value(bad):
    raises_naming(bad, Circle, bad)


def test_smallest_subnormal_radius_is_a_valid_circle():
    # A circle needs no half of its radius, so 5e-324 (> 0, finite) is accepted...
    assert Circle(5e-324).radius == 5e-324
    # ...while a box of width 5e-324 would have half-width 0 (no interior): refused above.


@pytest.mark.parametrize(
    "value", [1, 2.5, np.float32(0.1), np.float64(3.0), np.int64(4), Fraction(1, 3)], ids=short
)
def test_sizes_accept_real_numbers_and_store_float64(value):
    box, circle = AABB(value, value), Circle(value)
    for got in (box.width, box.height, circle.radius):
        assert type(got) is float
        assert got == float(value)


def test_shapes_are_immutable_and_hashable():
    box = AABB(2, 3)
    with pytest.raises(AttributeError):
        box.width = 5  # type: ignore[misc]
    assert {AABB(2, 3), AABB(2.0, 3.0), Circle(1), Circle(1.0)} == {AABB(2, 3), Circle(1)}
    assert box.half_width == 1.0 and box.half_height == 1.5
    assert box.bounding_radius == math.hypot(1.0, 1.5)
    assert Circle(2).bounding_radius == 2.0
    assert Polygon([(0, 0), (3, 0), (0, 4)]).bounding_radius == 4.0


# --- Transform ----------------------------------------------------------------------------------

BAD_COORDS = [NAN, INF, -INF, None, "1", True, np.float64(NAN), np.float32(-INF), 10**400, (1, 2)]


@pytest.mark.parametrize("bad", BAD_COORDS, ids=short)
@pytest.mark.parametrize("field", ["x", "y", "rotation"])
def test_transform_refuses_non_finite_and_wrong_types(field, bad):
    kwargs = {"x": 0.0, "y": 0.0, "rotation": 0.0, field: bad}
    err = raises_naming(bad, Transform, **kwargs)
    assert field in str(err)


def test_transform_stores_float64_and_is_mutable():
    t = Transform(np.float32(0.5), np.int64(3), np.float64(0.25))
    assert (t.x, t.y, t.rotation) == (0.5, 3.0, 0.25)
    assert all(type(v) is float for v in (t.x, t.y, t.rotation))
    t.x += 1
    assert t == Transform(1.5, 3, 0.25)
    assert Transform() == Transform(0.0, 0.0, 0.0)


@pytest.mark.parametrize("field", ["x", "y", "rotation"])
@pytest.mark.parametrize("bad", [NAN, INF, "oops", None], ids=short)
@pytest.mark.parametrize("side", ["a", "b"])
def test_collide_with_a_transform_mutated_to_a_bad_value_raises_naming_the_field(field, bad, side):
    ta, tb = Transform(0, 0), Transform(0.5, 0)
    setattr(ta if side == "a" else tb, field, bad)
    err = raises_naming(bad, collide, AABB(1, 1), ta, Polygon.box(1, 1), tb)
    assert f"transform_{side}.{field}" in str(err)


@pytest.mark.parametrize("bad", [None, "box", 3.0, (1, 1), Transform()], ids=short)
def test_collide_refuses_things_that_are_not_shapes(bad):
    raises_naming(bad, collide, bad, Transform(), AABB(1, 1), Transform())
    raises_naming(bad, collide, AABB(1, 1), Transform(), bad, Transform())


@pytest.mark.parametrize("bad", [None, "xy", (1,), (1, 2, 3, 4), 7, (NAN, 0)], ids=short)
def test_collide_refuses_bad_transform_tuples(bad):
    with pytest.raises(ValueError):
        collide(AABB(1, 1), bad, AABB(1, 1), (0, 0))


# --- validation helpers -------------------------------------------------------------------------

def test_validation_helpers():
    assert finite("v", np.float32(0.5)) == 0.5
    assert positive("v", 2) == 2.0
    assert vector2("v", np.array([1.0, 2.0])) == (1.0, 2.0)
    raises_naming(NAN, finite, "v", NAN)
    raises_naming(0.0, positive, "v", 0.0)
    for bad in ("ab", (1, 2, 3), None, (1, NAN)):
        with pytest.raises(ValueError):
            vector2("v", bad)
    # InvalidValue is also a TypeError, so either except clause catches a wrong type.
    with pytest.raises(TypeError):
        finite("v", None)


# --- polygons: normalisation --------------------------------------------------------------------

SQUARE_CCW = [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)]
PENTAGON = [(0.0, -2.0), (2.0, -0.5), (1.25, 2.0), (-1.25, 2.0), (-2.0, -0.5)]


def variants(pts: list[tuple[float, float]]):
    """The same outline: every rotation of the start, both windings, repeats, collinear extras."""
    n = len(pts)
    for w in (pts, pts[::-1]):
        for s in range(n):
            yield w[s:] + w[:s]
    yield pts + [pts[0]]  # closed explicitly
    yield [p for p in pts for _ in range(2)]  # every point doubled
    mid = ((pts[0][0] + pts[1][0]) / 2, (pts[0][1] + pts[1][1]) / 2)  # exact for these inputs
    yield [pts[0], mid, pts[1], *pts[2:]]  # a collinear point on an edge
    q1 = (pts[0][0] * 0.75 + pts[1][0] * 0.25, pts[0][1] * 0.75 + pts[1][1] * 0.25)
    yield [pts[0], q1, mid, mid, pts[1], *pts[2:]][::-1]  # several, reversed, with a repeat
    yield np.array(pts)
    yield tuple(tuple(p) for p in pts)
    yield iter(pts)
    yield [(np.float64(x), np.float32(y)) for x, y in pts]  # exact in float32 too


@pytest.mark.parametrize("pts", [SQUARE_CCW, PENTAGON, [(0, 0), (4, 0), (0, 3)]],
                         ids=["square", "pentagon", "tri"])
def test_every_spelling_of_one_outline_gives_the_identical_polygon(pts):
    reference = Polygon(pts)
    # Stored counter-clockwise from the lowest (then leftmost) vertex.
    first = min(reference.points, key=lambda p: (p[1], p[0]))
    assert reference.points[0] == first
    pts_ = reference.points
    area2 = sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(pts_, pts_[1:] + pts_[:1], strict=True))
    assert area2 > 0
    assert len(reference) == len(pts)
    probe_shapes = [AABB(1, 1), Circle(0.75), Polygon([(0, 0), (1, 0.25), (0.5, 1)])]
    probes = [(x * 0.5, y * 0.5, r) for x in range(-6, 7) for y in range(-6, 7) for r in (0.0, 0.7)]
    expected = [collide(reference, (0.25, 0.0, 0.3), s, p) for s in probe_shapes for p in probes]
    for v in variants(list(pts)):
        poly = Polygon(v)
        assert poly == reference and hash(poly) == hash(reference)
        assert poly.points == reference.points
        assert all(type(c) is float for p in poly.points for c in p)
        got = [collide(poly, (0.25, 0.0, 0.3), s, p) for s in probe_shapes for p in probes]
        assert got == expected  # bit for bit


def test_negative_zero_is_stored_as_zero():
    poly = Polygon([(-0.0, -0.0), (1.0, -0.0), (-0.0, 1.0)])
    assert all(math.copysign(1.0, c) == 1.0 for p in poly.points for c in p)
    assert poly == Polygon([(0, 0), (1, 0), (0, 1)])


def test_box_polygon_is_the_rotatable_box():
    assert Polygon.box(4, 2).points == ((-2.0, -1.0), (2.0, -1.0), (2.0, 1.0), (-2.0, 1.0))


def test_nearly_collinear_points_from_rounding_are_dropped_in_any_order():
    # The midpoint of an edge computed with rounding sits within an ulp or so of the edge.
    a, b = (0.1, 0.7), (2.3, 1.9)
    mid = (a[0] + (b[0] - a[0]) * 0.3, a[1] + (b[1] - a[1]) * 0.3)
    pts = [a, mid, b, (0.4, 3.1)]
    ref = Polygon([a, b, (0.4, 3.1)])
    for s in range(4):
        assert Polygon(pts[s:] + pts[:s]) == ref
        assert Polygon((pts[s:] + pts[:s])[::-1]) == ref


def test_thin_and_far_polygons_are_accepted_when_they_are_genuine():
    # A 1000 x 1e-6 sliver (thickness 1e-9 of its extent, far above the 1e-12 collinear tolerance).
    assert len(Polygon([(0, 0), (1000, 0), (1000, 1e-6), (0, 1e-6)])) == 4
    # Huge and tiny coordinates neither overflow nor underflow the checks.
    assert len(Polygon([(0, 0), (1e300, 0), (0, 1e300)])) == 3
    assert len(Polygon([(0, 0), (1e-300, 0), (0, 1e-300)])) == 3
    assert len(Polygon([(0, 0), (1e-320, 0), (0, 1e-320)])) == 3  # subnormal


# --- polygons: refusals -------------------------------------------------------------------------

BAD_OUTLINES = {
    "empty": [],
    "one point": [(0, 0)],
    "two points": [(0, 0), (1, 1)],
    "one point thrice": [(1, 1), (1, 1), (1, 1)],
    "collinear": [(0, 0), (1, 1), (2, 2)],
    "collinear, out of order": [(0, 0), (2, 0), (1, 0)],
    "collinear many": [(0, 0), (1, 2), (3, 6), (-1, -2), (2, 4)],
    "nearly collinear (sliver of 1e-15)": [(0, 0), (1, 0), (0.5, 1e-15)],
    "tuple of collinear points": ((0, 0), (1, 0), (2, 0)),
    "non-convex dart": [(0, 0), (2, 1), (0, 2), (1, 1)],
    "non-convex L": [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)],
    "dent of 1e-6": [(0, 0), (1, 0), (1, 1), (0.5, 1 - 1e-6), (0, 1)],
    "spike": [(0, 0), (2, 0), (3, 0), (2.5, 0), (2, 1)],
    "spike back to a vertex": [(0, 0), (2, 0), (2, 2), (2, 1), (0, 2)],
    "bow-tie": [(0, 0), (1, 0), (0, 1), (1, 1)],
    "bow-tie, wide": [(0, 0), (4, 0), (0, 1), (4, 1)],
    "pentagram": [(math.cos(math.pi / 2 + 4 * math.pi * i / 5), math.sin(math.pi / 2 + 4 * math.pi * i / 5))
                  for i in range(5)],
    "square wound twice": [(0, 0), (1, 0), (1, 1), (0, 1)] * 2,
    "revisits a point": [(0, 0), (2, 0), (2, 2), (0, 0), (0, 2)],
}


@pytest.mark.parametrize("pts", BAD_OUTLINES.values(), ids=BAD_OUTLINES.keys())
def test_degenerate_and_non_convex_outlines_raise_naming_the_outline(pts):
    raises_naming(pts, Polygon, pts)


def test_bow_tie_and_star_say_self_intersecting_not_collinear():
    for name in ("bow-tie", "bow-tie, wide", "pentagram"):
        msg = str(raises_naming(BAD_OUTLINES[name], Polygon, BAD_OUTLINES[name]))
        assert "crosses itself" in msg and "not convex" in msg and "collinear" not in msg
    msg = str(raises_naming(BAD_OUTLINES["spike"], Polygon, BAD_OUTLINES["spike"]))
    assert "spike" in msg
    msg = str(raises_naming(BAD_OUTLINES["non-convex dart"], Polygon, BAD_OUTLINES["non-convex dart"]))
    assert "not convex" in msg
    msg = str(raises_naming(BAD_OUTLINES["collinear"], Polygon, BAD_OUTLINES["collinear"]))
    assert "non-collinear" in msg


@pytest.mark.parametrize(
    "pts, bad",
    [
        ([(0, 0), (1, NAN), (0, 1)], NAN),
        ([(0, 0), (INF, 0), (0, 1)], INF),
        ([(0, 0), (1, 0), (None, 1)], None),
        ([(0, 0), (1, 0), ("0", 1)], "0"),
        ([(0, 0), (1, 0), (True, 1)], True),
        ([(0, 0), (1, 0), (np.float64(NAN), 1)], np.float64(NAN)),
        ([(0, 0), (1, 0), (0, 1, 2)], (0, 1, 2)),
        ([(0, 0), (1, 0), 5], 5),
        ([(0, 0), (1, 0), "xy"], "xy"),
        ([(0, 0), (1.5e308, 1.5e308), (0, 1)], (1.5e308, 1.5e308)),  # its distance overflows
        (None, None),
        (5, 5),
        ("abc", "abc"),
    ],
    ids=short,
)
def test_bad_points_raise_naming_the_value(pts, bad):
    raises_naming(bad, Polygon, pts)


def test_too_thin_polygon_box_names_its_sizes():
    err = raises_naming(1e15, Polygon.box, 1, 1e15)
    assert f"Polygon.box(1, {1e15!r})" in str(err) and "AABB" in str(err)
    assert len(Polygon.box(1, 1e12)) == 4  # a 1e12 aspect ratio is still a polygon
