"""time_of_impact of shapes that touch exactly (issue 33, item 2): sliding along, moving away from,
or moving into a surface at gap 0.

The contract: the impact is the first moment the *interiors* overlap. Two shapes touching at the
start (gap exactly 0) whose relative motion has no component into the contact normal (a slide
along the surface, at any speed, past its end corner too, or a move away from it) never overlap:
``None``. A motion with any component into the surface overlaps at once: fraction 0, with the
surface's normal (from A toward B).

Every placement below is exact in binary (dyadic coordinates, radii 5/8 and sizes whose extents
land exactly on the surface; the slanted surfaces are faces of a 3-4-5 rotated square, whose unit
normals (0.6, 0.8) times 5/8 are dyadic), so every expectation is exact and written beside it. The
motions include non-dyadic-looking ones (1 ulp either side of every grid value, and the report's
0.1, 1/6, ...): their tangential motions are still exactly tangential on an axis-aligned face,
and on a slanted face the expectation is the exact sign of the motion against the normal.

The bug this guards (sweep.py before the fix): the rounded polygon (or rounded core hull) is a
union of face rectangles and vertex discs; a line along a face is tangent to the discs at both ends
of the face, rounding gave each tangent a sliver of an interval (one before the step, one after),
and taking the span from the earliest entry to the latest exit over all pieces made one interval
covering the whole step: a hit at fraction 0 with a normal from a far corner.
"""

from __future__ import annotations

import math
from fractions import Fraction

import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from framework import AABB, Capsule, Circle, Polygon, Transform
from framework.collision import Impact, Vec2, collide, time_of_impact

R = 0.625  # 5/8: the circle's and the capsules' radius
H = 0.5  # the capsules' half length (length 1)
CIRCLE = Circle(R)
CAPSULE = Capsule(R, 2 * H)
UP, SIDE = 0.0, math.pi / 2  # capsule rotations: upright, lying (its ends at x -+ H exactly: sin = 1.0)

# A square of side 10 turned by atan(3/4) (a rotated polygon with exact vertices): CCW
# (0, 0), (8, 6), (2, 14), (-6, 8). Its upper-left face runs (2, 14) -> (-6, 8), outward normal
# (-0.6, 0.8); its upper-right face (8, 6) -> (2, 14), outward normal (0.8, 0.6).
TURNED = Polygon([(0, 0), (8, 6), (2, 14), (-6, 8)])


class Surface:
    """A face of a static shape: ``foot`` a point strictly inside the face, ``normal`` its unit
    outward normal (exact floats: 0, +-1, +-0.6, +-0.8), ``along`` a dyadic vector along the face,
    ``half`` how many ``along`` from the foot to either end corner."""

    def __init__(self, name, shape, pose, foot, normal, along, half):
        self.name, self.shape, self.pose = name, shape, pose
        self.foot, self.normal, self.along, self.half = foot, normal, along, half

    def __repr__(self):
        return self.name


SURFACES = [
    # Floors: the top face y = 0, x in [-8, 8].
    Surface("aabb floor", AABB(16, 2), Transform(0, -1), (0.0, 0.0), (0.0, 1.0), (1.0, 0.0), 8),
    Surface("box floor", Polygon.box(16, 2), Transform(0, -1), (0.0, 0.0), (0.0, 1.0), (1.0, 0.0), 8),
    # A ceiling: the bottom face y = 0.
    Surface("aabb ceiling", AABB(16, 2), Transform(0, 1), (0.0, 0.0), (0.0, -1.0), (1.0, 0.0), 8),
    # Walls: the right face x = 0 of a wall on the left, the left face x = 0 of one on the right.
    Surface("aabb wall left", AABB(2, 16), Transform(-1, 0), (0.0, 0.0), (1.0, 0.0), (0.0, 1.0), 8),
    Surface("box wall right", Polygon.box(2, 16), Transform(1, 0), (0.0, 0.0), (-1.0, 0.0), (0.0, 1.0), 8),
    # The turned square's faces, foot at their midpoints, along a quarter of the face vector.
    Surface("turned upper-left", TURNED, Transform(0, 0), (-2.0, 11.0), (-0.6, 0.8), (2.0, 1.5), 2),
    Surface("turned upper-right", TURNED, Transform(0, 0), (5.0, 10.0), (0.8, 0.6), (-1.5, 2.0), 2),
    # The same, placed away from the origin (the offset is exact).
    Surface("turned, moved", TURNED, Transform(-32.5, 4.25), (-34.5, 15.25), (-0.6, 0.8), (2.0, 1.5), 2),
]


def resting(kind, surf):
    """``(shape, pose)`` of a circle or capsule resting on the surface at its foot, or None where
    the placement is not exact (a lying capsule is turned by pi/2, whose cosine is 6e-17, not 0:
    it only rests exactly end-on, against a wall)."""
    fx, fy = surf.foot
    nx, ny = surf.normal
    if kind == "circle":
        return CIRCLE, Transform(fx + R * nx, fy + R * ny)
    if kind == "upright capsule":
        # Its nearest point is on the end facing the surface (the whole flank, against a wall).
        lift = H if ny > 0 else -H if ny < 0 else 0.0
        return CAPSULE, Transform(fx + R * nx, fy + R * ny + lift, UP)
    assert kind == "lying capsule"
    if ny != 0:
        return None
    return CAPSULE, Transform(fx + (R + H) * nx, fy, SIDE)


KINDS = ["circle", "upright capsule", "lying capsule"]
CASES = [(k, s) for s in SURFACES for k in KINDS if resting(k, s) is not None]


def sweeps(shape, pose, motion, surf):
    """The three ways of asking: the mover as A moving, as B moving, and as A standing while the
    surface moves the other way; with the normal each should have, as a factor of the surface's
    outward normal (A toward B: -1 when the mover is A)."""
    mx, my = motion
    neg = (-mx, -my)
    return [
        (time_of_impact(shape, pose, motion, surf.shape, surf.pose), -1.0),
        (time_of_impact(surf.shape, surf.pose, (0, 0), shape, pose, motion), 1.0),
        (time_of_impact(shape, pose, (0, 0), surf.shape, surf.pose, neg), -1.0),
    ]


def into(motion, normal):
    """The exact sign of motion . normal (the normals' floats are exact multiples of 1/5 in
    exact arithmetic: 0.6 and 0.8 stand for 3/5 and 4/5)."""
    def exact(v):
        return Fraction(v).limit_denominator(5) if v in (0.6, -0.6, 0.8, -0.8) else Fraction(v)

    dot = Fraction(motion[0]) * exact(normal[0]) + Fraction(motion[1]) * exact(normal[1])
    return (dot > 0) - (dot < 0)


def expect(results, motion, surf):
    """Into the surface: fraction 0 with its normal (exactly); along it or away: None."""
    sign = into(motion, surf.normal)
    for imp, f in results:
        if sign < 0:
            assert imp == Impact(0.0, Vec2(f * surf.normal[0] + 0.0, f * surf.normal[1] + 0.0)), (motion, imp)
        else:
            assert imp is None, (motion, imp)


# Displacements: 200 dyadic values 1/16 .. 12.5 times the face's along vector, either way (from
# the middle of the face, so the larger ones slide past its end corner and beyond), and each one
# ulp either side.
GRID = [i / 16 for i in range(1, 201)]
GRID = GRID + [math.nextafter(d, math.inf) for d in GRID] + [math.nextafter(d, 0.0) for d in GRID]
REPORT = [0.05, 0.1, 1 / 6, 0.2, 1 / 15, 2 / 15, 0.15, 0.25, 0.23333333333333334, 0.23333333333333336]


@pytest.mark.parametrize("kind, surf", CASES, ids=[f"{k} on {s}" for k, s in CASES])
def test_sliding_along_a_face_never_hits(kind, surf):
    shape, pose = resting(kind, surf)
    # Touching, not overlapping, at the start.
    assert collide(shape, pose, surf.shape, surf.pose) is None
    ax, ay = surf.along
    for d in GRID + REPORT:
        for s in (d, -d):
            motion = (s * ax, s * ay)
            # Expectation: None when exactly along the face (always on an axis-aligned face, and for
            # dyadic d on a slanted one); a one-ulp d on a slanted face rounds s * 1.5 (or s * 0.75)
            # and may point into the face by a hair (fraction 0) or away (None): its exact sign.
            expect(sweeps(shape, pose, motion, surf), motion, surf)
            if surf.normal[0] * surf.normal[1] == 0.0 or d in GRID[:200]:
                assert into(motion, surf.normal) == 0


@pytest.mark.parametrize("kind, surf", CASES, ids=[f"{k} on {s}" for k, s in CASES])
def test_sliding_past_the_end_corner_never_hits(kind, surf):
    # Start a sixteenth of the along vector short of the end corner (either end) and slide over it
    # and well past it: the shape leaves the face over the corner, touching it, never entering.
    shape, pose = resting(kind, surf)
    ax, ay = surf.along
    for end in (1, -1):
        off = end * (surf.half - 1 / 16)
        start = Transform(pose.x + off * ax, pose.y + off * ay, pose.rotation)
        assert collide(shape, start, surf.shape, surf.pose) is None
        for d in (1 / 16, 1 / 8, 1 / 4, 1, 3, 7.5, 100, math.nextafter(1 / 8, 1), 0.1, 1 / 3):
            motion = (end * d * ax, end * d * ay)
            for imp, _ in sweeps(shape, start, motion, surf):
                if into(motion, surf.normal) == 0:
                    assert imp is None, (d, imp)
                else:  # (a rounded slanted motion) its sign decides
                    assert (imp is None) == (into(motion, surf.normal) > 0), (d, imp)


# Motions: a (dyadic) amount along the face plus one along the normal's dyadic multiple.
ALONG = [0.0, 1 / 8, -1 / 8, 1, -1, 3.5, -3.5, 12, -12, 0.1, -1 / 3]
ACROSS = [-4, -1, -1 / 8, -2.0**-30, 0.0, 2.0**-30, 1 / 8, 1, 4]


@pytest.mark.parametrize("kind, surf", CASES, ids=[f"{k} on {s}" for k, s in CASES])
def test_moving_into_hits_at_zero_moving_away_never(kind, surf):
    shape, pose = resting(kind, surf)
    ax, ay = surf.along
    nx, ny = surf.normal
    # A dyadic multiple of the normal (1.25 times it for the slanted ones: (-0.75, 1), (1, 0.75)).
    mx, my = (nx, ny) if nx * ny == 0.0 else (nx * 1.25, ny * 1.25)
    assert into((mx, my), surf.normal) == 1
    for a in ALONG:
        for b in ACROSS:
            motion = (a * ax + b * mx, a * ay + b * my)
            if motion == (0.0, 0.0):
                continue
            # b < 0: into the face, Impact(0.0, +-normal); b == 0: along; b > 0: away: None.
            # (For a = 0.1 or -1/3 on a slanted face the sum rounds: the exact sign decides.)
            expect(sweeps(shape, pose, motion, surf), motion, surf)
            if a in (0.0, 1 / 8, -1 / 8, 1, -1, 3.5, -3.5, 12, -12):
                assert into(motion, surf.normal) == (b > 0) - (b < 0)


# --- corners ---------------------------------------------------------------------------------------

FLOOR = AABB(16, 2), Transform(0, -1)  # top face y = 0 from the corner (-8, 0) to the corner (8, 0)


@pytest.mark.parametrize("shape, lift, rot", [(CIRCLE, 0.0, UP), (CAPSULE, H, UP)], ids=["circle", "capsule"])
def test_resting_on_a_corner(shape, lift, rot):
    floor, fpose = FLOOR
    # Straight above the corner (8, 0): sliding either way along the floor's line (back over the
    # face, or off it) never hits; down (even slanting off the floor at 45 degrees) hits at 0, up
    # normal (0, -1) from the mover; away (up, or off to the right and up) never.
    pose = Transform(8, R + lift, rot)
    assert collide(shape, pose, floor, fpose) is None
    for d in GRID[::7]:
        for motion in ((d, 0), (-d, 0)):
            assert time_of_impact(shape, pose, motion, floor, fpose) is None
            assert time_of_impact(floor, fpose, (0, 0), shape, pose, motion) is None
        for motion in ((0, -d), (d, -d), (-d, -d), (-d, -1 / 1024)):
            assert time_of_impact(shape, pose, motion, floor, fpose) == Impact(0.0, Vec2(0.0, -1.0))
            assert time_of_impact(floor, fpose, (0, 0), shape, pose, motion) == Impact(0.0, Vec2(0.0, 1.0))
        for motion in ((0, d), (d, d), (-d, d), (d, 1 / 1024)):
            assert time_of_impact(shape, pose, motion, floor, fpose) is None
    # Off the corner, touching it along the direction (0.6, 0.8) (the corner's own normal there;
    # 5/8 of it is (3/8, 1/2)): moving along the tangent (4, -3) or (-4, 3), at any speed, misses;
    # any motion with a component toward the corner hits at 0 with normal -(0.6, 0.8) from the
    # mover; away from it never.
    pose = Transform(8 + 0.375, 0.5 + lift, rot)
    assert collide(shape, pose, floor, fpose) is None
    for d in GRID[::7]:
        for motion in ((d, -0.75 * d), (-d, 0.75 * d)):
            # (0.75 d rounds for the one-ulp d: then the exact sign against (0.6, 0.8) decides.)
            sign = into(motion, (0.6, 0.8))
            assert sign == 0 or d not in GRID[:200]
            expected = None if sign >= 0 else Impact(0.0, Vec2(-0.6, -0.8))
            assert time_of_impact(shape, pose, motion, floor, fpose) == expected
            turned = None if expected is None else Impact(0.0, Vec2(0.6, 0.8))
            assert time_of_impact(floor, fpose, (0, 0), shape, pose, motion) == turned
        for motion in ((-d, -d), (-d, 0.5 * d), (0.5 * d, -d)):
            assert time_of_impact(shape, pose, motion, floor, fpose) == Impact(0.0, Vec2(-0.6, -0.8))
        for motion in ((d, d), (d, -0.5 * d), (-0.5 * d, d)):
            assert time_of_impact(shape, pose, motion, floor, fpose) is None


def test_capsule_flank_on_a_wall_corner():
    # An upright capsule against the wall x <= 0, y <= 0 (an AABB(2, 2) at (-1, -1)), its flank on
    # the wall's top corner (0, 0), its core (0.625, 0) .. (0.625, 1): up or down along the wall
    # misses (down: along the wall's face x = 0); into the wall (left) hits at 0, normal (-1, 0)
    # from the capsule: its lower cap, below y = 0, bulges past x = 0 at once.
    wall, wpose = AABB(2, 2), Transform(-1, -1)
    pose = Transform(R, H, UP)
    assert collide(CAPSULE, pose, wall, wpose) is None
    for d in GRID[::5]:
        for motion in ((0, d), (0, -d), (d, 0), (d, -d), (d, d)):
            assert time_of_impact(CAPSULE, pose, motion, wall, wpose) is None
        for motion in ((-d, 0), (-d, d), (-d, -d)):
            assert time_of_impact(CAPSULE, pose, motion, wall, wpose) == Impact(0.0, Vec2(-1.0, 0.0))


# --- the report's numbers -------------------------------------------------------------------------

@pytest.mark.parametrize("d", [0.05, 0.1, 1 / 6, 0.2, 1 / 15, 2 / 15, 0.15, 0.25])
def test_report_circle_on_floor(d):
    # Circle r = 5/16 at (-5, 5/16) resting on the top face y = 0 of the box x in [-14, 0]: sliding
    # by d either way misses (before the fix 0.05, 0.1, 1/6 and 0.2 hit at 0 with a normal from a
    # far corner's disc, e.g. (-0.9994, -0.0347)); 5 further on, the corner (0, 0) is slid past.
    floor, fpose = AABB(14, 1), Transform(-7, -0.5, 0)
    for x in (-5.0, -0.25):
        circle, pose = Circle(0.3125), Transform(x, 0.3125, 0)
        for m in ((d, 0), (-d, 0), (50 * d, 0), (-50 * d, 0)):
            assert time_of_impact(circle, pose, m, floor, fpose) is None
            assert time_of_impact(floor, fpose, (0, 0), circle, pose, m) is None
        # Into the floor by a little: fraction 0, normal (0, -1) from the circle.
        assert time_of_impact(circle, pose, (d, -d / 64), floor, fpose) == Impact(0.0, Vec2(0.0, -1.0))


@pytest.mark.parametrize("dy", [0.23333333333333334, 0.23333333333333336, 0.1, 1 / 3, -0.1, -1 / 3])
def test_report_capsule_beside_a_wall(dy):
    # Capsules r = 5/16, length 1/2, beside the unit box at the origin (x in [-1/2, 1/2]): upright,
    # its flank on the right face (x = 13/16), and lying (rot pi/2), its left end's cap on it
    # (x = 1/2 + 5/16 + 1/4): moving up or down along the face misses. Before the fix the upright
    # one at dy = 0.23333333333333336 hit at 0 with normal (-0.3846, -0.9231) (a corner's sliver),
    # at dy = 0.23333333333333334 it did not.
    box, bpose = AABB(1, 1), Transform(0, 0)
    cap = Capsule(0.3125, 0.5)
    for pose in (Transform(0.8125, 0, UP), Transform(1.0625, 0, SIDE), Transform(-0.8125, 0.25, UP),
                 Transform(-1.0625, 0.25, SIDE)):
        assert collide(cap, pose, box, bpose) is None
        assert time_of_impact(cap, pose, (0, dy), box, bpose) is None
        assert time_of_impact(box, bpose, (0, 0), cap, pose, (0, dy)) is None
        # Toward the box by 1/1024 as well: fraction 0, normal (-+1, 0) from the capsule.
        toward = -1.0 if pose.x > 0 else 1.0
        assert time_of_impact(cap, pose, (toward / 1024, dy), box, bpose) == Impact(0.0, Vec2(toward, 0.0))


# --- every pair of kinds --------------------------------------------------------------------------

def test_boxes_and_circles_sliding():
    # Box on box (and on a rotating box at rotation 0), circle on circle, circle on capsule, capsule
    # beside capsule (parallel: their cores' difference is a segment): every grid slide misses.
    cases = [
        (AABB(2, 2), Transform(0, 2), AABB(16, 2), Transform(0, 0), (1, 0)),
        (Polygon.box(2, 2), Transform(0.5, 2), AABB(16, 2), Transform(0, 0), (1, 0)),
        (TURNED, Transform(0, 0), Polygon([(0, 0), (8, 6), (8, 0)]), Transform(4, 3), (4, 3)),
        (Circle(0.375), Transform(0, 1), Circle(0.625), Transform(0, 0), (1, 0)),
        (Circle(0.375), Transform(1, 0), Capsule(0.625, 4), Transform(0, 0), (0, 1)),
        (Capsule(0.375, 1), Transform(1, 0), Capsule(0.625, 4), Transform(0, 0), (0, 1)),
        (Capsule(0.375, 1), Transform(1, 0), Circle(0.625), Transform(0, 0), (0, 1)),
        # The upright capsule's lower end (3.625, 3.5) 5/8 above-left of (4, 3) on the face y = 0.75 x.
        (CAPSULE, Transform(3.625, 4), Polygon([(0, 0), (8, 6), (8, 0)]), Transform(0, 0), (4, 3)),
    ]
    for a, ta, b, tb, (ux, uy) in cases:
        assert collide(a, ta, b, tb) is None
        for d in GRID[::3] + REPORT:
            for s in (d, -d):
                m = (s * ux, s * uy)
                if Fraction(m[0]) * uy != Fraction(m[1]) * ux:
                    continue  # (a rounded slanted motion: not a slide)
                assert time_of_impact(a, ta, m, b, tb) is None, (a, b, m)
                assert time_of_impact(b, tb, (0, 0), a, ta, m) is None, (a, b, m)


def test_turned_square_slides_on_its_twin():
    # The turned square's upper-left face (2, 14) -> (-6, 8) and the same square turned over and
    # laid on it: their faces coincide in part; sliding along (4, 3) misses, into it hits at 0.
    top = Polygon([(2, 14), (-6, 8), (-12, 16), (-4, 22)])  # the square reflected over that face
    assert collide(TURNED, Transform(0, 0), top, Transform(0, 0)) is None
    for d in GRID[::4]:
        for s in (d, -d):
            m = (s, 0.75 * s)
            # Along the face: None; a one-ulp s rounds 0.75 s: into by a hair (-3 mx + 4 my < 0):
            # fraction 0, normal (0.6, -0.8) from the top square; away by a hair: None.
            sign = into(m, (-0.6, 0.8))
            expected = Impact(0.0, Vec2(0.6, -0.8)) if sign < 0 else None
            assert time_of_impact(top, Transform(0, 0), m, TURNED, Transform(0, 0)) == expected
            if d in GRID[:200]:
                assert sign == 0
        assert time_of_impact(top, Transform(0, 0), (d, 0), TURNED, Transform(0, 0)) == Impact(0.0, Vec2(0.6, -0.8))
        assert time_of_impact(top, Transform(0, 0), (-d, 0), TURNED, Transform(0, 0)) is None


# --- property: random shapes placed exactly touching -------------------------------------------------

q = st.integers(1, 24).map(lambda i: i / 8)
pos = st.integers(-24, 24).map(lambda i: i / 8)


@st.composite
def convex_polygons(draw):
    # Triangles and quadrilaterals with dyadic corners, convex by construction: corners on a circle's
    # octants, scaled per axis.
    sx, sy = draw(q), draw(q)
    picks = draw(st.lists(st.integers(0, 7), min_size=3, max_size=5, unique=True))
    octant = [(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1)]
    pts = [(octant[i][0] * sx, octant[i][1] * sy) for i in sorted(picks)]
    try:
        return Polygon(pts)
    except ValueError:  # all on one line
        assume(False)


shapes = st.one_of(st.builds(AABB, q, q), st.builds(Circle, q), convex_polygons(), st.builds(Capsule, q, q))


def support(shape, axis, sign):
    """``(extent, lo, hi)``: how far the shape reaches from its origin along ``sign`` times the
    ``axis`` (0: x, 1: y), and the range of the other coordinate over the points that reach it."""
    if isinstance(shape, AABB):
        half = (shape.width / 2, shape.height / 2)
        return half[axis], -half[1 - axis], half[1 - axis]
    if isinstance(shape, Circle):
        return shape.radius, 0.0, 0.0
    if isinstance(shape, Capsule):  # upright
        if axis == 1:
            return shape.half_length + shape.radius, 0.0, 0.0
        return shape.radius, -shape.half_length, shape.half_length
    ext = max(sign * p[axis] for p in shape.points)
    other = [p[1 - axis] for p in shape.points if sign * p[axis] == ext]
    return ext, min(other), max(other)


@pytest.mark.slow
@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(shapes, shapes, st.integers(0, 3), pos, st.integers(-8, 8), st.integers(-64, 64),
       st.sampled_from([0, 1, -1]), st.booleans())
def test_touching_shapes_property(a, b, direction, ax_, slide_num, tangential, ulp, a_moves):
    # A at (ax_, 1/4); B placed on A's side ``direction`` (0: above, 1: below, 2: right, 3: left),
    # its extent landing exactly on A's, slid sideways so that the two contact sets overlap on a
    # piece of positive length or one lies strictly inside the other (else a corner meeting a corner
    # could slide off, and "into" would not be an overlap).
    axis, sign = (1, 1) if direction == 0 else (1, -1) if direction == 1 else (0, 1) if direction == 2 else (0, -1)
    ea, alo, ahi = support(a, axis, sign)
    eb, blo, bhi = support(b, axis, -sign)
    shift = slide_num / 8
    lo, hi = max(alo, blo + shift), min(ahi, bhi + shift)
    a_point, b_point = alo == ahi, blo == bhi
    # (Two polygon corners meeting tip to tip are excluded: moving "in" at a slant, one tip passes
    # beside the other. Where one of them is round, any motion with a component in overlaps at once.)
    round_ = isinstance(a, (Circle, Capsule)) or isinstance(b, (Circle, Capsule))
    proper = hi > lo or (lo == hi and ((a_point and blo + shift < alo < bhi + shift)
                                       or (b_point and alo < blo + shift < ahi)
                                       or (a_point and b_point and round_)))
    assume(proper)
    pa = [ax_, 0.25]
    pb = list(pa)
    pb[axis] = pa[axis] + sign * (ea + eb)
    pb[1 - axis] = pa[1 - axis] + shift
    ta, tb = Transform(*pa), Transform(*pb)
    assert collide(a, ta, b, tb) is None  # touching: no collision
    # The relative motion of B: ``tangential`` / 8 along the contact, ``across`` along its normal
    # (from A toward B), then nudged by an ulp (a tangential one stays tangential).
    n = [0.0, 0.0]
    n[axis] = float(sign)
    for across in (-1.0, -2.0**-20, 0.0, 2.0**-20, 0.5):
        v = [0.0, 0.0]
        v[1 - axis] = tangential / 8
        v[axis] = sign * across
        if ulp:
            v = [math.nextafter(c, ulp * math.inf) if c else c for c in v]
        if v == [0.0, 0.0]:
            continue
        if a_moves:
            imp = time_of_impact(a, ta, (-v[0], -v[1]), b, tb, (0, 0))
        else:
            imp = time_of_impact(a, ta, (0, 0), b, tb, tuple(v))
        # Exact: into (across < 0) -> Impact(0.0, n); along or away -> None.
        if across < 0:
            assert imp == Impact(0.0, Vec2(n[0], n[1])), (v, imp)
        else:
            assert imp is None, (v, imp)


# --- through the scene's shape casts (what the character controller casts) ------------------------

def test_shape_casts_along_a_tiled_floor_and_up_a_wall():
    # A floor of unit tiles (top y = 0, seams at every integer x) and a wall column of unit tiles
    # (right face x = -20). A circle and an upright capsule resting on the floor cast sideways:
    # no hit (before the fix a step of 0.1 or 1/6 hit at 0, which stopped a character spawned on
    # the floor); cast down-sideways: a hit at 0, the floor's normal (0, 1). The capsule against the
    # wall casting straight up (a wall jump from contact): no hit (before the fix: fraction 0 with a
    # corner's normal, pointing up enough to read as a floor).
    from framework import Hitbox, Scene

    s = Scene()
    try:
        for i in range(-20, 20):
            s.spawn(Transform(i + 0.5, -0.5), Hitbox(AABB(1, 1), body="static"))
        for j in range(0, 8):
            s.spawn(Transform(-20.5, j + 0.5), Hitbox(AABB(1, 1), body="static"))
        cap = Capsule(0.3125, 0.75)
        for shape, (x, y) in ((Circle(0.3125), (-5.0, 0.3125)), (cap, (-5.0, 0.6875)), (cap, (0.0, 0.6875))):
            for d in REPORT + [1 / 60 * v for v in (100.0, 128.0, 6.4)] + GRID[::10]:
                for m in (d, -d):
                    assert s.shape_cast(shape, (x, y), (x + m, y)) is None, (shape, x, m)
                hit = s.shape_cast(shape, (x, y), (x + d, y - d / 8))
                assert hit is not None and hit.fraction == 0.0 and hit.normal == Vec2(0.0, 1.0)
        # Beside the wall (x = -20 + 5/16), from just above the floor: up, and up and away, miss.
        for d in REPORT + GRID[::10]:
            for shape, y in ((cap, 1.5), (Circle(0.3125), 1.5)):
                start = (-20 + 0.3125, y)
                assert s.shape_cast(shape, start, (start[0], y + d)) is None, (shape, d)
                assert s.shape_cast(shape, start, (start[0] + d / 4, y + d)) is None, (shape, d)
                hit = s.shape_cast(shape, start, (start[0] - d / 4, y + d))
                assert hit is not None and hit.fraction == 0.0 and hit.normal == Vec2(1.0, 0.0)
    finally:
        s.close()
