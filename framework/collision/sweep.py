"""Time of impact of two translating shapes (rotation is fixed during the step).

Only the relative motion ``v = motion_b - motion_a`` matters. B's hitbox origin, taken relative to
A's (the local origin), moves along ``delta + t v``, and the interiors overlap exactly while that
point is inside the Minkowski difference ``M = A - B`` (A's outline grown by B's turned round). So
a sweep is a ray cast of B's offset against ``M``, with the same grazing rules:

- box/polygon vs box/polygon: swept SAT over all face normals of both (unnormalised, exact for
  dyadic input); per axis the open time interval of strict overlap, intersected over the axes;
- circle vs circle: ``M`` is a disc of the radius sum;
- box/polygon vs circle: ``M`` is the polygon rounded by the radius, whose interior near its
  boundary is the union of one open rectangle per face (the face pushed out and in by the radius)
  and one open disc per vertex;
- a capsule vs anything: ``M`` is the cores' Minkowski difference (the convex hull of the
  differences of their points: a polygon, or a segment where both cores are parallel segments or
  one is a point) rounded by the radii summed: the same pieces (for a segment, one rectangle and
  two discs, :func:`~framework.collision.pieces.rounded_segment`).

A sweep is a list of *pieces*, each the open interval of ``tau`` during which B's offset is inside
one piece of ``M`` (for the swept SAT, the one interval of the whole of ``M``). The impact is the
earliest moment of the step inside any piece: the earliest ``max(entry, 0)`` among the pieces whose
interval is non-empty and meets the step ``[0, T)``. It is not the span from the earliest entry to
the latest exit over all pieces: a line along a face of ``M`` (a shape sliding along a surface it
touches) is tangent to the discs at both ends of the face, and where rounding gives those tangents
a sliver of an interval each, the span of two slivers on either side of the step would cover it
(issue 33, item 2). Touching is also decided exactly: wherever a piece's float test is within
:data:`~framework.collision.exact.BAND` of touching (a disc's discriminant and the start's distance
from its centre, a rectangle's four sides), the sign is decided again on exact integers, so a
tangent line (a slide along a face or past a corner, at any speed) is always a miss, and a shape
touching at the start and moving away never hits.

Positions are scaled by one power of two and the motion by another (both exact); times are kept
in the scaled frame (``tau = t * 2**(j - k)``) and turned into a step fraction at the end. Swapping
A and B repeats the same arithmetic, so it gives the same fraction and the negated normal bit for
bit (except at fraction 0, where the normal is ``collide``'s).
"""

from __future__ import annotations

import math
from typing import cast

from ..shapes import AABB, Capsule, ChainSegment, Circle, Polygon, Segment, Shape
from ..validation import vector2
from .capsule import capsule_first, core_points
from .collide import collide
from .exact import BAND, float_approx
from .kinds import CAPSULES, CIRCLES, PAIRS, POLYGON_CIRCLE, kind_of
from .pieces import Piece, disc_interval, first_entry, ints, rect_interval, rounded_segment
from .placement import check_shape, pose
from .ray import extent, local_exponent, relative, scale_exponent, scaled_outline
from .results import Impact, Vec2
from .tiebreak import pick

__all__ = ["time_of_impact"]

Pts = list[tuple[float, float]]
# A sweep is a list of pieces (:data:`~framework.collision.pieces.Piece`): each the open interval of
# tau inside one piece of the Minkowski difference, with candidate normals from A toward B.


def time_of_impact(
    shape_a: Shape,
    transform_a: object,
    motion_a: object,
    shape_b: Shape,
    transform_b: object,
    motion_b: object = (0, 0),
) -> Impact | None:
    """First moment, as a fraction of the step in [0, 1], at which the interiors of A and B overlap
    while A moves by ``motion_a`` and B by ``motion_b``; ``None`` if they never do (grazing or
    sliding along at gap 0 is a miss, and so is a first contact at exactly fraction 1).

    Already overlapping gives fraction 0 with ``collide``'s normal. ``Impact.normal`` is the unit
    normal from A toward B at the moment of contact; ties (corner meets corner) follow
    :func:`framework.collision.tiebreak.pick`.
    """
    check_shape("shape_a", shape_a)
    check_shape("shape_b", shape_b)
    ax, ay, ar = pose("transform_a", transform_a)
    bx, by, br = pose("transform_b", transform_b)
    max_, may_ = vector2("motion_a", motion_a)
    mbx, mby = vector2("motion_b", motion_b)
    if isinstance(shape_b, ChainSegment) and not isinstance(shape_a, ChainSegment):
        # A chain segment's impact is worked with the segment first, whichever comes first.
        hit = time_of_impact(shape_b, (bx, by, br), (mbx, mby), shape_a, (ax, ay, ar), (max_, may_))
        return None if hit is None else Impact(hit.fraction, Vec2(-hit.normal.x + 0.0, -hit.normal.y + 0.0))

    contact = collide(shape_a, (ax, ay, ar), shape_b, (bx, by, br))
    if contact is not None:
        return Impact(0.0, contact.normal)
    vx, vy, ev = relative(mbx, mby, max_, may_)
    if vx == 0.0 and vy == 0.0:
        return None

    # Local frame: A's position is the origin; positions scaled by 2**-k, the motion by 2**-j.
    dx, dy, ed = relative(bx, by, ax, ay)
    k = local_exponent([extent(shape_a), extent(shape_b)], [(dx, ed), (dy, ed)])
    j = scale_exponent([(vx, ev), (vy, ev)])
    dx, dy = math.ldexp(dx, ed - k), math.ldexp(dy, ed - k)
    vx, vy = math.ldexp(vx, ev - j), math.ldexp(vy, ev - j)
    # With tau = t * 2**(j - k), B's offset is delta + tau * v; the step ends at tau = T.
    end = math.inf if j - k > 1023 else math.ldexp(1.0, j - k)

    pieces = _sweep_pair(shape_a, (ax, ay, ar), shape_b, (bx, by, br), dx, dy, vx, vy, k)
    found = first_entry(pieces, end)
    if found is None:
        return None
    t_in, near = found
    _, nx, ny = pick([(0.0, nx, ny) for _, nx, ny in near], 1.0)
    # t_in < end, so the fraction is < 1. A t_in == 0 here means touching at the start and moving
    # in (or an overlap that collide's rounding missed): contact from the start.
    fraction = math.ldexp(t_in, k - j) if t_in > 0.0 else 0.0
    if isinstance(shape_a, ChainSegment) and not isinstance(shape_b, Segment):
        # A chain segment keeps the touches its one side and its joints allow (framework.collision.chain),
        # judged where the two are at that moment.
        from .chain import one_impact

        at_a = (ax + max_ * fraction, ay + may_ * fraction, ar)
        at_b = (bx + mbx * fraction, by + mby * fraction, br)
        kept = one_impact(shape_a, at_a, shape_b, at_b, nx, ny)
        if kept is None:
            return None
        nx, ny = kept
    return Impact(fraction + 0.0, Vec2(nx + 0.0, ny + 0.0))


def _sweep_pair(
    shape_a: Shape, pose_a: tuple[float, float, float], shape_b: Shape, pose_b: tuple[float, float, float],
    dx: float, dy: float, vx: float, vy: float, k: int,
) -> list[Piece]:
    """The sweep of the pair in the scaled local frame (B's offset (dx, dy), relative motion
    (vx, vy), sizes scaled by ``2**-k``), computed as :data:`~framework.collision.kinds.PAIRS` says."""
    (ax, ay, ar), (bx, by, br) = pose_a, pose_b
    rule = PAIRS[kind_of(shape_a), kind_of(shape_b)]
    if isinstance(shape_a, Segment) and isinstance(shape_b, Segment):
        return []  # two segments: no interior to enter
    if rule.family == CAPSULES:
        # The capsule first (of two, the one placed first), as collide does; then turned round.
        # (of a capsule pair the rule does not flip, A is a capsule)
        flip = rule.flip or (isinstance(shape_b, Capsule)
                             and not capsule_first(cast(Capsule, shape_a), pose_a, shape_b, pose_b))
        if flip:
            return _turned_round(_capsule_pair(shape_b, br, shape_a, ar, -dx, -dy, -vx, -vy, k))
        return _capsule_pair(shape_a, ar, shape_b, br, dx, dy, vx, vy, k)
    if rule.family == CIRCLES:
        assert isinstance(shape_a, Circle) and isinstance(shape_b, Circle)
        radii = (math.ldexp(shape_a.radius, -k), math.ldexp(shape_b.radius, -k))
        return _circle_circle(dx, dy, radii, vx, vy)
    if rule.family == POLYGON_CIRCLE and not rule.flip:
        assert isinstance(shape_b, Circle)
        return _polygon_circle(scaled_outline(_outlined(shape_a), 0.0, 0.0, ar, k), dx, dy,
                               (math.ldexp(shape_b.radius, -k),), vx, vy)
    if rule.family == POLYGON_CIRCLE:
        # A circle against B: in B's frame (as when B comes first, so that both orders do the same
        # arithmetic), cast A's centre at -delta, moving by -v; then turn the normals round.
        assert isinstance(shape_a, Circle)
        res = _polygon_circle(scaled_outline(_outlined(shape_b), 0.0, 0.0, br, k), -dx, -dy,
                              (math.ldexp(shape_a.radius, -k),), -vx, -vy)
        return _turned_round(res)
    # BOXES or POLYGONS: the swept SAT.
    if _order_key(shape_b, bx, by, br) < _order_key(shape_a, ax, ay, ar):
        # Work in the frame of whichever shape sorts first, so that swapping A and B repeats the
        # very same arithmetic: the same fraction and the exactly negated normal. (Two circles'
        # numbers only change sign when swapped; a circle and a polygon work in the polygon's frame.)
        res = _polygon_polygon(scaled_outline(_outlined(shape_b), 0.0, 0.0, br, k),
                               scaled_outline(_outlined(shape_a), -dx, -dy, ar, k), -vx, -vy)
        return _turned_round(res)
    return _polygon_polygon(scaled_outline(_outlined(shape_a), 0.0, 0.0, ar, k),
                            scaled_outline(_outlined(shape_b), dx, dy, br, k), vx, vy)


def _turned_round(pieces: list[Piece]) -> list[Piece]:
    """A sweep worked with A and B swapped, its normals turned to point from A toward B again."""
    return [(a, b, [(t, -nx, -ny) for t, nx, ny in cands]) for a, b, cands in pieces]


def _outlined(shape: Shape) -> AABB | Polygon | Segment:
    """``shape`` as the box, polygon or segment that the pair rule says it is here (no check made)."""
    return cast("AABB | Polygon | Segment", shape)


def _order_key(shape: Shape, x: float, y: float, rotation: float) -> tuple[object, ...]:
    """A total order on placed boxes, polygons and segments (equal keys: the same outline at the
    same place)."""
    if isinstance(shape, AABB):
        params: tuple[object, ...] = (shape.width, shape.height)
    elif isinstance(shape, Segment):
        params = (shape.a, shape.b)
    else:
        params = cast(Polygon, shape).points
    return (x, y, rotation, kind_of(shape), params)


# --- pairs of kinds, in the scaled local frame --------------------------------------------------

def _unit(x: float, y: float) -> tuple[float, float]:
    ln = math.hypot(x, y)
    if ln == 0.0:
        return 0.0, 1.0  # undefined direction (only from rounding): up, as collide does
    return x / ln, y / ln


def _circle_circle(dx: float, dy: float, radii: tuple[float, float], vx: float, vy: float) -> list[Piece]:
    iv = disc_interval(0.0, 0.0, dx, dy, radii[0] + radii[1], radii, vx, vy)
    if iv is None:
        return []
    t1, t2 = iv
    t = t1 if t1 > 0.0 else 0.0
    nx, ny = _unit(dx + t * vx, dy + t * vy)
    return [(t1, t2, [(t1, nx, ny)])]


def _polygon_polygon(pa: Pts, pb: Pts, vx: float, vy: float) -> list[Piece]:
    """Swept SAT: B (outline ``pb``) moves by ``tau * v`` against A (outline ``pa``). The Minkowski
    difference is the intersection of the slabs of all the face normals, so its interval is the
    intersection of the per-axis intervals: one piece."""
    t_in, t_out = -math.inf, math.inf
    cands = []
    for poly in (pa, pb):
        n = len(poly)
        for i in range(n):
            x0, y0 = poly[i]
            x1, y1 = poly[(i + 1) % n]
            ux, uy = y1 - y0, x0 - x1  # unnormalised axis, as in collide
            amin = amax = ux * pa[0][0] + uy * pa[0][1]
            for x, y in pa:
                p = ux * x + uy * y
                if p < amin:
                    amin = p
                elif p > amax:
                    amax = p
            bmin = bmax = ux * pb[0][0] + uy * pb[0][1]
            for x, y in pb:
                p = ux * x + uy * y
                if p < bmin:
                    bmin = p
                elif p > bmax:
                    bmax = p
            pvx, pvy = ux * vx, uy * vy
            vp = pvx + pvy
            if abs(vp) <= BAND * (abs(pvx) + abs(pvy)) and (pvx != 0.0 or pvy != 0.0):
                # Motion within rounding of parallel to the axis: its sign decided exactly (a
                # slide along a face of touching shapes is no entry; moving in by a hair is one).
                (iux, iuy, ivx, ivy), e = ints((ux, uy, vx, vy))
                vp = float_approx(iux * ivx + iuy * ivy, 2 * e)
            if vp == 0.0:
                if amax <= bmin or bmax <= amin:
                    return []  # separated (or touching) on this axis for the whole step
                continue
            # B's shadow [bmin, bmax] + tau vp overlaps [amin, amax] strictly on (enter, leave).
            if vp > 0.0:
                enter, leave, sign = (amin - bmax) / vp, (amax - bmin) / vp, -1.0
            else:
                enter, leave, sign = (amax - bmin) / vp, (amin - bmax) / vp, 1.0
            ln = math.hypot(ux, uy)
            cands.append((enter, sign * ux / ln, sign * uy / ln))
            if enter > t_in:
                t_in = enter
            if leave < t_out:
                t_out = leave
    if not (t_in < t_out and cands):
        return []
    return [(t_in, t_out, cands)]


def _polygon_circle(poly: Pts, cx: float, cy: float, radii: tuple[float, ...], vx: float, vy: float) -> list[Piece]:
    """The circle's centre ``c + tau v`` against the polygon rounded by ``r`` (the sum of ``radii``;
    normals point from the polygon toward the circle): one piece per face (the open rectangle of the
    face swept out and in by ``r``) and one per vertex (the open disc around it). Near the rounded
    polygon's boundary its interior is the union of those pieces, so the first entry into it is the
    first entry into one of them (:func:`~framework.collision.pieces.first_entry`)."""
    r = radii[0] if len(radii) == 1 else radii[0] + radii[1]
    pieces: list[Piece] = []
    n = len(poly)
    for i in range(n):
        x0, y0 = poly[i]
        x1, y1 = poly[(i + 1) % n]
        ex, ey = x1 - x0, y1 - y0
        nx, ny = ey, -ex  # outward, unnormalised
        ln = math.sqrt(ex * ex + ey * ey)
        rect = rect_interval(x0, y0, x1, y1, cx, cy, r, radii, vx, vy)
        if rect is not None:
            a, b, tags = rect
            hx, hy = cx + a * vx, cy + a * vy
            if "start" in tags and "face" not in tags:
                hx, hy = hx - x0, hy - y0
            elif "end" in tags and "face" not in tags:
                hx, hy = hx - x1, hy - y1
            else:  # through the pushed-out face, or the pushed-in one
                hx = hy = 0.0
            # Through an end of the rectangle the entry is next to a vertex (whose disc is entered
            # no later): the normal points from that vertex. Through the pushed-in side (first only
            # when overlapping at the start, or when the polygon is flat to within rounding, as the
            # cores' hull of two nearly parallel capsules is) it is that side's outward normal, -n.
            hl = math.hypot(hx, hy)
            if hl > 0.0:
                pieces.append((a, b, [(a, hx / hl, hy / hl)]))
            elif "inner" in tags and "face" not in tags:
                pieces.append((a, b, [(a, -nx / ln, -ny / ln)]))
            else:
                pieces.append((a, b, [(a, nx / ln, ny / ln)]))
        # Open disc around vertex p0.
        iv = disc_interval(x0, y0, cx, cy, r, radii, vx, vy)
        if iv is not None:
            a, b = iv
            t = a if a > 0.0 else 0.0
            hx, hy = _unit(cx - x0 + t * vx, cy - y0 + t * vy)
            pieces.append((a, b, [(a, hx, hy)]))
    return pieces


def _hull(pts: Pts) -> Pts:
    """Convex hull, counter-clockwise, without collinear points (monotone chain)."""
    pts = sorted(set(pts))
    if len(pts) <= 2:
        return pts

    def half(seq: Pts) -> Pts:
        out: Pts = []
        for p in seq:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (p[1] - out[-2][1])
                                     - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])) <= 0.0:
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(pts[::-1])
    return lower[:-1] + upper[:-1]


def _capsule_pair(sa: Shape, rot_a: float, sb: Shape, rot_b: float, dx: float, dy: float, vx: float, vy: float,
                  k: int) -> list[Piece]:
    """Capsule A at the origin, B's core at (dx, dy) moving by ``tau v``: B's offset against the cores'
    Minkowski difference rounded by the radii summed."""
    pa, ra = core_points(sa, rot_a, k)
    pb, rb = core_points(sb, rot_b, k)
    hull = _hull([(ax - bx, ay - by) for ax, ay in pa for bx, by in pb])
    if len(hull) >= 3:
        return _polygon_circle(hull, dx, dy, (ra, rb), vx, vy)
    (s0x, s0y), (s1x, s1y) = hull if len(hull) == 2 else hull * 2
    return rounded_segment(dx, dy, s0x, s0y, s1x, s1y, (ra, rb), vx, vy)
