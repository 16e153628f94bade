"""Mass data (issue 38, part 1): a body's mass, centre of mass and inertia about that centre.

``Hitbox.mass_data`` as Box2D v3's ``b2MassData``: the centre in the entity's frame (the hitbox
offset plus the shape's centroid), the moment of inertia about the centre (the parallel-axis
theorem on the shape's moment about its origin). Exact where the arithmetic is (dyadic sizes,
divisions correctly rounded on both sides), else against the formulas to a few ulps; pymunk
(``moment_for_poly``, ``moment_for_circle``: moments about the body's origin), shapely (area,
centroid) and Box2D v3 (``pyb2d3``, in float32) as oracles.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from framework import AABB, Capsule, Circle, Hitbox, InvalidValue, MassData, Polygon, Scene, Transform, Velocity


def test_a_centred_box_a_circle_an_aabb_and_a_capsule_turn_about_their_origin():
    box = Hitbox(Polygon.box(2.0, 1.0), mass=3.0).mass_data
    assert box == MassData(3.0, (0.0, 0.0), 3.0 * (4.0 + 1.0) / 12.0)
    assert Hitbox(AABB(2.0, 1.0), mass=3.0).mass_data == box  # (an AABB never turns; its data is a box's)
    assert Hitbox(Circle(0.5), mass=2.0).mass_data == MassData(2.0, (0.0, 0.0), 2.0 * 0.25 / 2.0)
    cap = Capsule(0.25, 1.0)
    assert Hitbox(cap).mass_data == MassData(1.0, (0.0, 0.0), cap.second_moment)
    assert cap.centroid == (0.0, 0.0) and cap.central_moment == cap.second_moment


def test_box2d_v3s_shape_mass_cases():
    # Box2D v3's ShapeMassTest (test/test_shape.c), density 1: a circle of radius 1 centred at
    # (1, 0) has mass pi, centre (1, 0), rotational inertia pi / 2 (about its centre); the box of
    # half extents (1, 1) mass 4, centre (0, 0), inertia 8 / 3.
    circle = Hitbox(Circle(1.0), (1.0, 0.0), density=1.0).mass_data
    assert circle.mass == math.pi and circle.center == (1.0, 0.0) and circle.inertia == math.pi / 2
    box = Hitbox(Polygon.box(2.0, 2.0), density=1.0).mass_data
    assert box == MassData(4.0, (0.0, 0.0), pytest.approx(8.0 / 3.0, rel=1e-15))
    # its capsule, segment (-1, 0) to (1, 0) of radius 1 (ours is vertical: a quarter turn makes no
    # difference to the mass data): between the inscribed hull's and the enclosing box's
    cap = Hitbox(Capsule(1.0, 2.0), density=1.0).mass_data
    enclosing = Hitbox(Polygon.box(4.0, 2.0), density=1.0).mass_data
    n = 4
    hull = [(1.0 + math.cos(-math.pi / 2 + k * math.pi / (n - 1)), math.sin(-math.pi / 2 + k * math.pi / (n - 1)))
            for k in range(n)]
    hull += [(-px, -py) for px, py in hull]
    inscribed = Hitbox(Polygon(hull), density=1.0).mass_data
    assert inscribed.mass < cap.mass < enclosing.mass
    assert inscribed.inertia < cap.inertia < enclosing.inertia


def test_the_issues_offset_box():
    # A 1 x 1/2 box of density 1 (mass 1/2) whose centre is at (0.7, 0.4): about its centroid
    # m (w^2 + h^2) / 12 = 0.0520833, where the hitbox origin's moment is 0.3770833.
    pts = [(0.2, 0.15), (1.2, 0.15), (1.2, 0.65), (0.2, 0.65)]
    md = Hitbox(Polygon(pts), density=1.0).mass_data
    assert md.mass == pytest.approx(0.5, rel=1e-15)
    assert md.center == pytest.approx((0.7, 0.4), abs=1e-15)
    assert md.inertia == pytest.approx(0.5 * (1.0 + 0.25) / 12.0, rel=1e-14)
    assert round(md.inertia, 7) == 0.0520833
    about_origin = md.mass * Polygon(pts).second_moment
    assert round(about_origin, 7) == 0.3770833
    assert about_origin == pytest.approx(md.inertia + md.mass * (0.7 ** 2 + 0.4 ** 2), rel=1e-14)


def test_an_off_centre_polygon_exactly():
    # the box [0, 2] x [0, 1]: centroid (1, 1/2), (w^2 + h^2) / 12 about it; all dyadic but the 12
    md = Hitbox(Polygon([(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (0.0, 1.0)]), mass=3.0).mass_data
    assert md == MassData(3.0, (1.0, 0.5), 3.0 * (5.0 / 12.0))
    # the right triangle with legs 3: centroid (1, 1), (a^2 + b^2 + c^2) / 36 = 1 about it
    tri = Polygon([(0.0, 0.0), (3.0, 0.0), (0.0, 3.0)])
    assert tri.centroid == (1.0, 1.0) and tri.central_moment == 1.0 and tri.area == 4.5
    assert Hitbox(tri, density=2.0).mass_data == MassData(9.0, (1.0, 1.0), 9.0)
    # the moment about the origin is the parallel-axis theorem's
    assert tri.second_moment == 1.0 + 2.0


def test_an_offset_hitbox_moves_the_centre_not_the_inertia():
    md = Hitbox(Polygon.box(2.0, 1.0), (0.5, -0.25), mass=2.0).mass_data
    assert md == MassData(2.0, (0.5, -0.25), 2.0 * 5.0 / 12.0)
    md = Hitbox(Polygon([(0.0, 0.0), (3.0, 0.0), (0.0, 3.0)]), (-1.0, 0.5)).mass_data
    assert md == MassData(1.0, (0.0, 1.5), 1.0)  # offset plus centroid
    assert Hitbox(Circle(1.0), (3.0, 4.0), mass=2.0).mass_data == MassData(2.0, (3.0, 4.0), 1.0)


def test_a_given_inertia_is_about_the_centre_of_mass_and_inf_stays_inf():
    tri = Polygon([(0.0, 0.0), (3.0, 0.0), (0.0, 3.0)])
    assert Hitbox(tri, (1.0, 0.0), inertia=0.75).mass_data == MassData(1.0, (2.0, 1.0), 0.75)
    assert Hitbox(tri, inertia=math.inf).mass_data.inertia == math.inf
    assert Hitbox(tri, mass=math.inf).mass_data == MassData(math.inf, (1.0, 1.0), math.inf)


def test_a_symmetric_outline_computed_with_rounding_is_centred():
    hexagon = Polygon([(math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)) for k in range(6)])
    assert hexagon.centroid == (0.0, 0.0)
    assert hexagon.central_moment == hexagon.second_moment


def test_mass_data_follows_edits_and_is_read_only():
    hb = Hitbox(Polygon.box(2.0, 1.0))
    hb.offset = (1.0, 2.0)
    hb.mass = 4.0
    assert hb.mass_data == MassData(4.0, (1.0, 2.0), 4.0 * 5.0 / 12.0)
    with pytest.raises(AttributeError):
        hb.mass_data = MassData(1.0, (0.0, 0.0), 1.0)  # type: ignore[misc]
    with Scene() as s:
        e = s.spawn(Transform(), Velocity(), hb)
        s.get(e, Hitbox).density = None
        assert s.get(e, Hitbox).mass_data.center == (1.0, 2.0)
        with pytest.raises(InvalidValue):
            Hitbox(Polygon.box(2.0, 1.0), mass=2.0, density=1.0)


# --- oracles: shapely, pymunk, Box2D v3 ----------------------------------------------------------------

eighths = st.integers(-64, 64).map(lambda k: k / 8.0)


@st.composite
def convex_outlines(draw):
    """The convex hull of 3 to 12 points on a 1/8 grid, somewhere within 8 of the origin."""
    shapely = pytest.importorskip("shapely")
    pts = draw(st.lists(st.tuples(eighths, eighths), min_size=3, max_size=12, unique=True))
    hull = shapely.MultiPoint(pts).convex_hull
    assume(hull.geom_type == "Polygon" and hull.area > 0.25)
    try:
        return Polygon(list(hull.exterior.coords)[:-1]), hull
    except InvalidValue:
        assume(False)
        raise


@settings(max_examples=150, deadline=None)
@given(convex_outlines(), st.tuples(eighths, eighths), st.sampled_from([0.5, 1.0, 3.0]))
def test_a_polygons_mass_data_matches_shapely_and_pymunk(outline, offset, density):
    pymunk = pytest.importorskip("pymunk")
    poly, hull = outline
    md = Hitbox(poly, offset, density=density).mass_data
    assert md.mass == pytest.approx(density * hull.area, rel=1e-14)
    cx, cy = hull.centroid.x, hull.centroid.y
    assert md.center == pytest.approx((offset[0] + cx, offset[1] + cy), abs=1e-12)
    # pymunk: the moment of the outline about (0, 0) after moving it by ``offset``
    assert md.inertia == pytest.approx(pymunk.moment_for_poly(md.mass, poly.points, (-cx, -cy)), rel=1e-9)
    about_entity = pymunk.moment_for_poly(md.mass, poly.points, offset)
    assert md.inertia + md.mass * (md.center[0] ** 2 + md.center[1] ** 2) == pytest.approx(about_entity, rel=1e-9)


@settings(max_examples=100, deadline=None)
@given(st.integers(1, 64).map(lambda k: k / 8.0), st.tuples(eighths, eighths), st.sampled_from([0.5, 1.0, 3.0]))
def test_a_circles_mass_data_matches_pymunk(radius, offset, mass):
    pymunk = pytest.importorskip("pymunk")
    md = Hitbox(Circle(radius), offset, mass=mass).mass_data
    assert md == MassData(mass, offset, mass * radius * radius / 2.0)
    about_entity = pymunk.moment_for_circle(mass, 0.0, radius, offset)
    assert md.inertia + mass * (offset[0] ** 2 + offset[1] ** 2) == pytest.approx(about_entity, rel=1e-14)


@pytest.mark.parametrize("radius, length, offset", [(0.25, 1.0, (0.5, 0.0)), (1.0, 2.0, (0.0, 0.0)),
                                                     (0.125, 3.0, (-1.0, 2.0)), (2.0, 0.5, (0.25, 0.25))])
def test_a_capsules_mass_data_matches_box2d_v3(radius, length, offset):
    b2 = pytest.importorskip("pyb2d3")
    world = b2.World(gravity=(0.0, 0.0))
    body = world.create_dynamic_body(position=(0.0, 0.0))
    ox, oy = offset
    body.create_capsule_shape(b2.shape_def(density=1.0),
                              b2.capsule((ox, oy - length / 2), (ox, oy + length / 2), radius))
    md = Hitbox(Capsule(radius, length), offset, density=1.0).mass_data
    centre = body.local_center_of_mass()
    assert md.mass == pytest.approx(body.mass, rel=1e-6)  # (Box2D works in float32)
    assert md.center == pytest.approx((centre.x, centre.y), abs=1e-6 * (1.0 + abs(ox) + abs(oy)))
    assert md.inertia == pytest.approx(body.rotational_inertia(), rel=1e-5)
    world.destroy()


def test_a_capsules_inertia_is_the_limit_of_its_hull():
    cap = Capsule(0.5, 2.0)
    n = 2048
    half = [(0.5 * math.cos(math.pi * k / (n - 1)), 1.0 + 0.5 * math.sin(math.pi * k / (n - 1))) for k in range(n)]
    hull = Polygon(half + [(-px, -py) for px, py in half])
    assert hull.area == pytest.approx(cap.area, rel=1e-5) and hull.area < cap.area
    assert hull.central_moment == pytest.approx(cap.central_moment, rel=1e-5)
