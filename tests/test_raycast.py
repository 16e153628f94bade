"""raycast: the contract in CONTRACT.md, with exact expectations on dyadic input.

Every expected value below is derived in a comment; with integer / dyadic coordinates the answers
are exact, so most checks use ``==``. Rotated shapes go through cos/sin and use a tolerance.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from shapely.geometry import LineString, Point
from shapely.geometry import Polygon as SPolygon

from framework import AABB, Circle, Polygon, Transform
from framework.collision import RayHit, Vec2, raycast
from framework.validation import InvalidValue

BOX = AABB(4, 2)  # at (1, 2): x in [-1, 3], y in [1, 3]
AT = Transform(1, 2)


# --- boxes: each face ------------------------------------------------------------------------

@pytest.mark.parametrize(
    "origin, direction, distance, point, normal",
    [
        # From the left at y = 2.5: the left face x = -1 is 4 away.
        ((-5, 2.5), (1, 0), 4.0, (-1, 2.5), (-1, 0)),
        # From the right at y = 1.5: the right face x = 3 is 4 away.
        ((7, 1.5), (-1, 0), 4.0, (3, 1.5), (1, 0)),
        # From below at x = 0.5: the bottom face y = 1 is 4 away.
        ((0.5, -3), (0, 1), 4.0, (0.5, 1), (0, -1)),
        # From above at x = 2.25: the top face y = 3 is 7 away.
        ((2.25, 10), (0, -1), 7.0, (2.25, 3), (0, 1)),
        # Slanted 3-4-5 ray from (-4, -2): x = -1 at s = 1 (y = 2, inside the face), while y = 1
        # comes earlier at s = 0.75 but there x = -1.75 is outside: the left face, 5 away.
        ((-4, -2), (3, 4), 5.0, (-1, 2), (-1, 0)),
        # Non-unit direction: the distance is in world units along it, not in multiples of it.
        ((-5, 2.5), (0.25, 0), 4.0, (-1, 2.5), (-1, 0)),
        ((-5, 2.5), (1024, 0), 4.0, (-1, 2.5), (-1, 0)),
    ],
)
@pytest.mark.parametrize("shape", [BOX, Polygon.box(4, 2)], ids=["aabb", "polygon_box"])
def test_box_faces_exact(shape, origin, direction, distance, point, normal):
    hit = raycast(shape, AT, origin, direction)
    assert hit == RayHit(distance, Vec2(*point), Vec2(*normal))
    assert isinstance(hit.distance, float) and isinstance(hit.point, Vec2) and isinstance(hit.normal, Vec2)


def test_aabb_ignores_rotation():
    # An AABB never rotates: the same answers whatever the transform's rotation.
    assert raycast(BOX, Transform(1, 2, 0.7), (-5, 2.5), (1, 0)) == raycast(BOX, AT, (-5, 2.5), (1, 0))


def test_rotated_polygon_box():
    # Polygon.box(4, 2) turned a quarter turn at the origin is 2 wide and 4 tall: the ray along
    # y = 1.5 (which would miss the unrotated box, 1 tall) meets x = -1 after 4 units.
    hit = raycast(Polygon.box(4, 2), Transform(0, 0, math.pi / 2), (-5, 1.5), (1, 0))
    assert hit.distance == pytest.approx(4.0, abs=1e-12)
    assert hit.point == pytest.approx((-1.0, 1.5), abs=1e-12)
    assert hit.normal == pytest.approx((-1.0, 0.0), abs=1e-12)
    assert raycast(Polygon.box(4, 2), Transform(0, 0), (-5, 1.5), (1, 0)) is None
    # A 2 x 2 box turned by 45 degrees is the diamond |x| + |y| < sqrt(2): along y = 0.5 it is
    # entered at x = 0.5 - sqrt(2), on the upper-left face, normal (-1, 1) / sqrt(2).
    hit = raycast(Polygon.box(2, 2), Transform(0, 0, math.pi / 4), (-5, 0.5), (1, 0))
    assert hit.distance == pytest.approx(5.5 - math.sqrt(2), abs=1e-12)
    assert hit.point == pytest.approx((0.5 - math.sqrt(2), 0.5), abs=1e-12)
    assert hit.normal == pytest.approx((-math.sqrt(0.5), math.sqrt(0.5)), abs=1e-12)


def test_polygon_slanted_face():
    # Triangle (0,0) (4,0) (0,4): from (4, 4) straight at the origin the ray meets the hypotenuse
    # x + y = 4 at (2, 2), 2*sqrt(2) away; the face's outward normal is (1, 1) / sqrt(2).
    tri = Polygon([(0, 0), (4, 0), (0, 4)])
    hit = raycast(tri, (0, 0), (4, 4), (-1, -1))
    assert hit.distance == pytest.approx(2 * math.sqrt(2), rel=1e-15)
    assert hit.point == (2.0, 2.0)
    assert hit.normal == pytest.approx((math.sqrt(0.5), math.sqrt(0.5)), rel=1e-15)
    # Either winding, any starting vertex: the same answer bit for bit.
    assert raycast(Polygon([(0, 4), (4, 0), (0, 0)]), (0, 0), (4, 4), (-1, -1)) == hit


# --- circles ---------------------------------------------------------------------------------

@pytest.mark.parametrize(
    "origin, direction, distance, point, normal",
    [
        # Circle r = 2 at (1, 1). From (-5, 1) to the right: x = -1 is 4 away.
        ((-5, 1), (1, 0), 4.0, (-1, 1), (-1, 0)),
        # From (1, 10) down, with a direction of length 2: y = 3 is 7 away.
        ((1, 10), (0, -2), 7.0, (1, 3), (0, 1)),
    ],
)
def test_circle_exact(origin, direction, distance, point, normal):
    assert raycast(Circle(2), (1, 1), origin, direction) == RayHit(distance, Vec2(*point), Vec2(*normal))


def test_circle_pythagorean():
    # r = 5 at the origin, ray along y = 3: enters at x = -4 (16 + 9 = 25), 6 away from x = -10;
    # the outward normal there is (-4, 3) / 5.
    assert raycast(Circle(5), (0, 0), (-10, 3), (1, 0)) == RayHit(6.0, Vec2(-4, 3), Vec2(-0.8, 0.6))


def test_circle_tangent_misses():
    # y = 1 touches the unit circle at (0, 1) only: a graze.
    assert raycast(Circle(1), (0, 0), (-5, 1), (1, 0)) is None
    assert raycast(Circle(1), (0, 0), (-5, -1), (3, 0)) is None
    # 3-4-5 tangent: the line through (-5, 0) with direction (4, 3) is 3 away from the origin.
    assert raycast(Circle(3), (0, 0), (-5, 0), (4, 3)) is None
    assert raycast(Circle(3), (0, 0), (-5, 0), (4, 2.9990234375)) is not None


@pytest.mark.parametrize("e", [-600, -60, 0, 60, 600])
def test_circle_huge_and_tiny_scales(e):
    # The same picture scaled by 2**e: exact distance, exact tangent miss, no overflow.
    s = 2.0 ** e
    c = Circle(5 * s)
    assert raycast(c, (0, 0), (-10 * s, 3 * s), (1, 0)) == RayHit(6 * s, Vec2(-4 * s, 3 * s), Vec2(-0.8, 0.6))
    assert raycast(c, (0, 0), (-10 * s, 5 * s), (1, 0)) is None


@pytest.mark.parametrize("e", [-600, -60, 0, 60, 600])
def test_box_huge_and_tiny_scales(e):
    s = 2.0 ** e
    box = AABB(4 * s, 2 * s)
    expect = RayHit(4 * s, Vec2(-s, 2.5 * s), Vec2(-1, 0))
    assert raycast(box, (s, 2 * s), (-5 * s, 2.5 * s), (1, 0)) == expect
    assert raycast(box, (s, 2 * s), (-5 * s, 3 * s), (1, 0)) is None


# --- grazing ---------------------------------------------------------------------------------

@pytest.mark.parametrize("shape", [BOX, Polygon.box(4, 2)], ids=["aabb", "polygon_box"])
@pytest.mark.parametrize(
    "origin, direction",
    [
        ((-5, 3), (1, 0)),  # along the top edge's line
        ((-5, 1), (2, 0)),  # along the bottom edge's line
        ((3, -5), (0, 1)),  # along the right edge's line
        ((-1, 10), (0, -1)),  # along the left edge's line, from above
        ((-1, 1.5), (0, 1)),  # starting on the left edge, running along it
        ((-3, 3), (1, -1)),  # exactly through the corner (-1, 1) and out: x + y = 0 meets only it
        ((5, 1), (-1, 1)),  # exactly through the corner (3, 3): x + y = 6
        ((-2, 2), (-1, 1)),  # the line through (-1, 1) again, heading away from it
    ],
)
def test_grazes_miss(shape, origin, direction):
    assert raycast(shape, AT, origin, direction) is None


def test_triangle_corner_graze():
    # The line y = 4 touches the triangle only at its apex (0, 4).
    tri = Polygon([(0, 0), (4, 0), (0, 4)])
    assert raycast(tri, (0, 0), (-3, 4), (1, 0)) is None
    # Through the apex (0, 4) and the vertex (4, 0): along the hypotenuse, a graze.
    assert raycast(tri, (0, 0), (-2, 6), (1, -1)) is None
    # The line y = x - 4 meets the triangle (x, y >= 0, x + y <= 4) only at its corner (4, 0).
    assert raycast(tri, (0, 0), (6, 2), (-1, -1)) is None


def test_ray_behind_misses():
    assert raycast(BOX, AT, (-5, 2.5), (-1, 0)) is None
    assert raycast(Circle(2), (1, 1), (-5, 1), (-1, 0)) is None


# --- starting inside or on the boundary --------------------------------------------------------

@pytest.mark.parametrize(
    "shape, transform",
    [(BOX, AT), (Polygon.box(4, 2), AT), (Circle(2), (1, 2)), (Polygon.box(4, 2), Transform(1, 2, 0.3))],
)
@pytest.mark.parametrize("max_distance", [math.inf, 1.0, 0.0])
def test_start_inside(shape, transform, max_distance):
    # Strictly inside: distance 0 at the origin, normal = -unit(direction) = -(3, 4) / 5.
    hit = raycast(shape, transform, (1.25, 2.5), (3, 4), max_distance)
    assert hit == RayHit(0.0, Vec2(1.25, 2.5), Vec2(-0.6, -0.8))


@pytest.mark.parametrize("shape", [BOX, Polygon.box(4, 2)], ids=["aabb", "polygon_box"])
def test_start_on_boundary(shape):
    # On the left face (x = -1) heading in (and up): distance 0, that face's normal (-1, 0).
    assert raycast(shape, AT, (-1, 2.5), (1, 0.5)) == RayHit(0.0, Vec2(-1, 2.5), Vec2(-1, 0))
    assert raycast(shape, AT, (-1, 2.5), (1, 0.5), 0.0) == RayHit(0.0, Vec2(-1, 2.5), Vec2(-1, 0))
    # On the top face heading in.
    assert raycast(shape, AT, (2, 3), (-1, -1)) == RayHit(0.0, Vec2(2, 3), Vec2(0, 1))
    # Heading out, or along the face: a miss.
    assert raycast(shape, AT, (-1, 2.5), (-1, 0)) is None
    assert raycast(shape, AT, (-1, 2.5), (-1, 5)) is None
    assert raycast(shape, AT, (-1, 2.5), (0, -1)) is None


@pytest.mark.parametrize("shape", [BOX, Polygon.box(4, 2)], ids=["aabb", "polygon_box"])
def test_start_on_vertex(shape):
    # At the corner (3, 3), both the right face (1, 0) and the top face (0, 1) start there.
    # The face most opposed to the ray wins: (-1, -0.5) opposes (1, 0) more -> right face.
    assert raycast(shape, AT, (3, 3), (-1, -0.5)).normal == (1, 0)
    assert raycast(shape, AT, (3, 3), (-0.5, -1)).normal == (0, 1)
    # Equally opposed (the diagonal): tiebreak.pick's rule, closest to vertical -> (0, 1).
    assert raycast(shape, AT, (3, 3), (-1, -1)) == RayHit(0.0, Vec2(3, 3), Vec2(0, 1))
    # From the corner (-1, 1) along the diagonal inward: bottom face (0, -1) wins the tie.
    assert raycast(shape, AT, (-1, 1), (1, 1)) == RayHit(0.0, Vec2(-1, 1), Vec2(0, -1))
    # From a corner outward or along an edge: a miss.
    assert raycast(shape, AT, (3, 3), (1, 1)) is None
    assert raycast(shape, AT, (3, 3), (-1, 0)) is None
    assert raycast(shape, AT, (3, 3), (1, -1)) is None


def test_corner_entry_from_outside_ties():
    # From (-3, -1) along (1, 1) the ray reaches the corner (-1, 1) at s = 2 and goes on inside
    # (the line y = x + 2 crosses the box). Both the left and the bottom face are entered at s = 2,
    # equally opposed to the ray: tiebreak.pick's rule, closest to vertical -> (0, -1).
    hit = raycast(BOX, AT, (-3, -1), (1, 1))
    assert hit.distance == pytest.approx(2 * math.sqrt(2), rel=1e-15)
    assert hit.point == (-1.0, 1.0)
    assert hit.normal == (0.0, -1.0)
    # Steeper ray through the same corner: (1, 2) opposes the bottom face more.
    assert raycast(BOX, AT, (-2, -1), (1, 2)).normal == (0.0, -1.0)
    # Flatter ray through it: (2, 1) opposes the left face more.
    assert raycast(BOX, AT, (-5, -1), (2, 1)).normal == (-1.0, 0.0)


def test_circle_start_on_boundary():
    # On the circle r = 2 at (1, 1), at (-1, 1): heading in -> distance 0, outward normal (-1, 0).
    assert raycast(Circle(2), (1, 1), (-1, 1), (1, 1)) == RayHit(0.0, Vec2(-1, 1), Vec2(-1, 0))
    assert raycast(Circle(2), (1, 1), (-1, 1), (1, 1), 0.0) == RayHit(0.0, Vec2(-1, 1), Vec2(-1, 0))
    # Heading out, or along the tangent: a miss.
    assert raycast(Circle(2), (1, 1), (-1, 1), (-1, 3)) is None
    assert raycast(Circle(2), (1, 1), (-1, 1), (0, 1)) is None
    assert raycast(Circle(2), (1, 1), (-1, 1), (0, -1)) is None


# --- max_distance ----------------------------------------------------------------------------

@pytest.mark.parametrize("shape", [BOX, Polygon.box(4, 2)], ids=["aabb", "polygon_box"])
def test_max_distance_box(shape):
    # The hit is 4 away along the unit direction, even for direction (0.25, 0).
    for d in [(1, 0), (0.25, 0), (3, 0)]:
        assert raycast(shape, AT, (-5, 2.5), d, 4.0) == RayHit(4.0, Vec2(-1, 2.5), Vec2(-1, 0))
        assert raycast(shape, AT, (-5, 2.5), d, math.nextafter(4.0, 0.0)) is None
        assert raycast(shape, AT, (-5, 2.5), d, 0.0) is None
    # 3-4-5 direction: the hit 5 away counts at max_distance 5 exactly.
    assert raycast(shape, AT, (-4, -2), (3, 4), 5.0) == RayHit(5.0, Vec2(-1, 2), Vec2(-1, 0))
    assert raycast(shape, AT, (-4, -2), (3, 4), 4.999999) is None


def test_max_distance_circle():
    assert raycast(Circle(5), (0, 0), (-10, 3), (2, 0), 6.0) == RayHit(6.0, Vec2(-4, 3), Vec2(-0.8, 0.6))
    assert raycast(Circle(5), (0, 0), (-10, 3), (2, 0), math.nextafter(6.0, 0.0)) is None


# --- far from the origin ---------------------------------------------------------------------

@pytest.mark.parametrize(
    "shape, rotation",
    [(BOX, 0.0), (Polygon.box(4, 2), 0.0), (Polygon.box(4, 2), 0.3), (Circle(2), 0.0),
     (Polygon([(0, 0), (4, 0), (0, 4)]), 1.0)],
)
@pytest.mark.parametrize("origin, direction", [((-5, 2.5), (1, 0)), ((-4, -2), (3, 4)), ((1.25, 2.5), (1, 1)),
                                               ((7.5, 12), (-1, -1.5))])
def test_far_scene_same_answers(shape, rotation, origin, direction):
    # Shift the whole scene by 1e9 (a dyadic amount: the shifted inputs are exact): the same
    # distance and normal bit for bit, and the point shifted by exactly 1e9.
    near = raycast(shape, Transform(1, 2, rotation), origin, direction)
    far = raycast(shape, Transform(1e9 + 1, 2, rotation), (origin[0] + 1e9, origin[1]), direction)
    assert near is not None
    assert far.distance == near.distance
    assert far.normal == near.normal
    assert far.point.x - 1e9 == pytest.approx(near.point.x, abs=1e-6)
    assert far.point.y == near.point.y


# --- input types and bad input ---------------------------------------------------------------

def test_numpy_inputs():
    expect = RayHit(4.0, Vec2(-1, 2.5), Vec2(-1, 0))
    for f in (float, np.float64, np.float32):
        hit = raycast(BOX, Transform(f(1), f(2)), (f(-5), f(2.5)), (f(1), f(0)), f(4.0))
        assert hit == expect
        assert all(type(v) is float for v in (hit.distance, *hit.point, *hit.normal))
    assert raycast(BOX, (1, 2), np.array([-5.0, 2.5]), np.array([1.0, 0.0]), np.float32(4)) == expect
    # float32 values are taken as the float64 they are exactly: 2.1f is not 2.1.
    y = np.float32(2.1)
    hit = raycast(BOX, AT, (np.float32(-5), y), (1, 0))
    assert hit.point.y == float(y) != 2.1


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(direction=(0, 0)), ["direction", "(0, 0)"]),
        (dict(direction=(0.0, -0.0)), ["direction"]),
        (dict(max_distance=math.nan), ["max_distance", "nan"]),
        (dict(max_distance=-1.0), ["max_distance", "-1.0"]),
        (dict(max_distance=-math.inf), ["max_distance", "-inf"]),
        (dict(max_distance="far"), ["max_distance", "far"]),
        (dict(max_distance=None), ["max_distance", "None"]),
        (dict(origin=(math.nan, 0)), ["origin", "nan"]),
        (dict(origin=(0, math.inf)), ["origin", "inf"]),
        (dict(origin=(1, 2, 3)), ["origin"]),
        (dict(direction=(math.nan, 1)), ["direction", "nan"]),
        (dict(direction="ab"), ["direction"]),
        (dict(transform=(math.nan, 0)), ["transform", "nan"]),
        (dict(shape="box"), ["shape", "box"]),
    ],
)
def test_bad_input(kwargs, words):
    args = dict(shape=BOX, transform=AT, origin=(-5, 2.5), direction=(1, 0))
    args.update(kwargs)
    with pytest.raises(ValueError) as err:
        raycast(**args)
    assert isinstance(err.value, InvalidValue)
    for w in words:
        assert w in str(err.value)


def test_far_origin():
    # From x = -2**40 the left face x = -1 is 2**40 - 1 away (exactly representable); max_distance
    # defaults to infinity.
    expect = RayHit(2.0**40 - 1, Vec2(-1, 2.5), Vec2(-1, 0))
    assert raycast(BOX, AT, (-(2.0**40), 2.5), (1, 0)) == expect
    assert raycast(BOX, AT, (-(2.0**40), 2.5), (1, 0), math.inf) == expect
    assert raycast(BOX, AT, (-(2.0**40), 2.5), (1, 0), 2.0**40 - 2) is None
    # A circle 2**40 radii away, hit along the Pythagorean chord of the r = 5 picture.
    assert raycast(Circle(5), (2.0**40, 0), (-10, 3), (1, 0)) == RayHit(
        2.0**40 + 6, Vec2(2.0**40 - 4, 3), Vec2(-0.8, 0.6)
    )


def test_extreme_values_never_nan():
    # Origin and shape at opposite ends of the float range: the offset overflows float64.
    # The circle is entered at x = -0.5e308, 2.2e308 away: beyond the float range, so no hit.
    assert raycast(Circle(1e308), (-1.5e308, 0), (1.7e308, 0), (-1, 0)) is None
    # The offset overflows again, but a bigger circle is entered at x = (sqrt(1.5**2 - 0.1**2) - 1)e308,
    # a representable distance away.
    hit = raycast(Circle(1.5e308), (-1e308, 0), (1e308, 1e307), (-1, 0))
    entry = (math.sqrt(1.5**2 - 0.1**2) - 1) * 1e308
    assert hit.distance == pytest.approx(1e308 - entry, rel=1e-12)
    assert hit.point == pytest.approx((entry, 1e307), rel=1e-12)
    assert hit.normal == pytest.approx((math.sqrt(1.5**2 - 0.1**2) / 1.5, 0.1 / 1.5), rel=1e-12)
    hit = raycast(AABB(1.7e308, 1.7e308), (0, 0), (1.7e308, 0), (-1, 0))
    assert hit.distance == pytest.approx(1.7e308 - 0.85e308, rel=1e-15)
    assert hit.normal == (1.0, 0.0)
    # A tiny direction and a huge one.
    assert raycast(BOX, AT, (-5, 2.5), (5e-324, 0)) == RayHit(4.0, Vec2(-1, 2.5), Vec2(-1, 0))
    assert raycast(BOX, AT, (-5, 2.5), (1.7e308, 1e-300)).normal == (-1.0, 0.0)


# --- properties ------------------------------------------------------------------------------

coord = st.integers(-64, 64).map(lambda i: i / 4)


@st.composite
def convex_polygons(draw):
    pts = draw(st.lists(st.tuples(coord, coord), min_size=3, max_size=8, unique=True))
    hull = SPolygon(pts).convex_hull
    assume(hull.geom_type == "Polygon" and hull.area > 1.0)
    return Polygon(list(hull.exterior.coords)[:-1])


def _world(shape, x, y, rot):
    if isinstance(shape, AABB):
        hw, hh = shape.width / 2, shape.height / 2
        return [(x - hw, y - hh), (x + hw, y - hh), (x + hw, y + hh), (x - hw, y + hh)]
    c, s = math.cos(rot), math.sin(rot)
    return [(c * px - s * py + x, s * px + c * py + y) for px, py in shape.points]


shapes_poly = st.one_of(
    convex_polygons(),
    st.builds(AABB, st.integers(1, 40).map(lambda i: i / 4), st.integers(1, 40).map(lambda i: i / 4)),
)
angles = st.one_of(st.just(0.0), st.floats(-4, 4))


# Most rays are aimed at a point near the shape's hitbox origin, so that most of them hit.
aims = st.one_of(st.none(), st.tuples(st.floats(-4, 4), st.floats(-4, 4)),
                 st.tuples(st.integers(-8, 8), st.integers(-8, 8)).map(lambda p: (p[0] / 2, p[1] / 2)))


@pytest.mark.slow
@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(shapes_poly, coord, coord, angles, st.tuples(coord, coord), st.tuples(coord, coord), aims,
       st.one_of(st.just(math.inf), st.floats(0, 60)))
def test_polygon_agrees_with_shapely(shape, x, y, rot, origin, direction, aim, max_distance):
    if aim is not None:
        direction = (x + aim[0] - origin[0], y + aim[1] - origin[1])
    assume(direction != (0, 0))
    poly = SPolygon(_world(shape, x, y, rot))
    dl = math.hypot(*direction)
    ux, uy = direction[0] / dl, direction[1] / dl
    far = 200.0
    line = LineString([origin, (origin[0] + far * ux, origin[1] + far * uy)])
    o = Point(origin)
    # Keep away from the ambiguous cases: origin (nearly) on the boundary, a (near-)graze.
    assume(poly.exterior.distance(o) > 1e-6)
    inter = poly.intersection(line)
    if inter.length > 0:
        assume(inter.length > 1e-6)
        # A ray along an edge meets the polygon's boundary only: a graze (the contract: a miss),
        # which shapely counts as an intersection. Keep rays that enter the interior.
        assume(line.intersection(poly.buffer(-1e-7)).length > 1e-6)
    else:
        assume(poly.distance(line) > 1e-6)
    hit = raycast(shape, (x, y, rot), origin, direction, max_distance)
    if inter.length == 0:
        assert hit is None
        return
    expect = o.distance(inter)  # 0 inside, else the distance to the entry point
    if expect > max_distance * (1 + 1e-9):
        assert hit is None
        return
    if expect < max_distance * (1 - 1e-9):
        assert hit is not None
    if hit is None:
        return
    assert hit.distance == pytest.approx(expect, rel=1e-9, abs=1e-9)
    assert math.hypot(*hit.normal) == pytest.approx(1.0, abs=1e-12)
    if expect == 0.0:
        assert hit.point == tuple(origin)
        assert hit.normal == pytest.approx((-ux, -uy), abs=1e-12)
    else:
        assert poly.exterior.distance(Point(hit.point)) < 1e-9
        assert hit.point == pytest.approx((origin[0] + expect * ux, origin[1] + expect * uy), abs=1e-9)
        # The normal faces the ray and is the outward normal of the face through the point.
        assert hit.normal.x * ux + hit.normal.y * uy < 0
        px, py = hit.point
        nx, ny = hit.normal
        assert not poly.contains(Point(px + 1e-6 * nx, py + 1e-6 * ny))


@settings(max_examples=400, deadline=None)
@given(st.integers(1, 40).map(lambda i: i / 4), coord, coord, st.tuples(coord, coord),
       st.tuples(coord, coord), aims, st.floats(-100, 100))
def test_circle_analytic(r, x, y, origin, direction, aim, shift):
    # Independent check with the textbook formula on a unit direction: |m + s u|^2 = r^2.
    if aim is not None:
        direction = (x + aim[0] - origin[0], y + aim[1] - origin[1])
    assume(direction != (0, 0))
    dl = math.hypot(*direction)
    ux, uy = direction[0] / dl, direction[1] / dl
    mx, my = origin[0] - x, origin[1] - y
    b = mx * ux + my * uy
    c = mx * mx + my * my - r * r
    disc = b * b - c
    assume(abs(c) > 1e-6 and abs(disc) > 1e-6)
    hit = raycast(Circle(r), (x + shift, y), (origin[0] + shift, origin[1]), direction)
    if c < 0:
        assert hit == RayHit(0.0, Vec2(origin[0] + shift, origin[1]), Vec2(-ux + 0.0, -uy + 0.0))
        return
    if disc < 0 or b >= 0:
        assert hit is None
        return
    s = -b - math.sqrt(disc)
    assert hit.distance == pytest.approx(s, rel=1e-9, abs=1e-9)
    px, py = hit.point
    assert math.hypot(px - shift - x, py - y) == pytest.approx(r, rel=1e-9)
    assert hit.normal == pytest.approx(((px - shift - x) / r, (py - y) / r), abs=1e-9)
    assert hit.normal.x * ux + hit.normal.y * uy < 0
