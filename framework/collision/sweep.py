"""Time of impact of two translating shapes (rotation is fixed during the step).

Only the relative motion ``v = motion_b - motion_a`` matters. B's hitbox origin, taken relative to
A's (the local origin), moves along ``delta + t v``, and the interiors overlap exactly while that
point is inside the Minkowski difference ``M = A - B`` (A's outline grown by B's turned round). So
a sweep is a ray cast of B's offset against ``M``, with the same grazing rules:

- box/polygon vs box/polygon: swept SAT over all face normals of both (unnormalised, exact for
  dyadic input); per axis the open time interval of strict overlap, intersected over the axes;
- circle vs circle: ``M`` is a disc of the radius sum;
- box/polygon vs circle: ``M`` is the polygon rounded by the radius, the union of one open
  rectangle per face (the face pushed out and in by the radius) and one open disc per vertex;
  the first entry into ``M`` is the first entry into any of those pieces;
- a capsule vs anything: ``M`` is the cores' Minkowski difference (the convex hull of the
  differences of their points: a polygon, or a segment where both cores are parallel segments or
  one is a point) rounded by the radii summed: the same pieces (for a segment, one rectangle and
  two discs, :func:`~framework.collision.ray.rounded_segment`).

Positions are scaled by one power of two and the motion by another (both exact); times are kept
in the scaled frame (``tau = t * 2**(j - k)``) and turned into a step fraction at the end. Swapping
A and B repeats the same arithmetic, so it gives the same fraction and the negated normal bit for
bit (except at fraction 0, where the normal is ``collide``'s).
"""

from __future__ import annotations

import math
from typing import cast

from ..shapes import AABB, Capsule, Circle, Polygon, Shape
from ..validation import vector2
from .capsule import capsule_first, core_points
from .collide import collide
from .kinds import CAPSULES, CIRCLES, PAIRS, POLYGON_CIRCLE, kind_of
from .placement import check_shape, pose
from .ray import (
    TIE,
    disc_interval,
    extent,
    local_exponent,
    relative,
    rounded_segment,
    scale_exponent,
    scaled_outline,
)
from .results import Impact, Vec2
from .tiebreak import pick

__all__ = ["time_of_impact"]

Pts = list[tuple[float, float]]
# (t_in, t_out, candidates (t, nx, ny) with unit normals from A toward B)
_Sweep = tuple[float, float, list[tuple[float, float, float]]]


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

    res = _sweep_pair(shape_a, (ax, ay, ar), shape_b, (bx, by, br), dx, dy, vx, vy, k)
    if res is None:
        return None
    t_in, t_out, cands = res
    if not (t_in < t_out and t_out > 0.0 and t_in < end):
        return None
    tol = TIE * max(1.0, abs(t_in))
    near = [(0.0, nx, ny) for t, nx, ny in cands if abs(t - t_in) <= tol]
    _, nx, ny = pick(near, 1.0)
    # t_in < end, so the fraction is < 1. A t_in <= 0 here means touching at the start and moving
    # in (or an overlap that collide's rounding missed): contact from the start.
    fraction = math.ldexp(t_in, k - j) if t_in > 0.0 else 0.0
    return Impact(fraction + 0.0, Vec2(nx + 0.0, ny + 0.0))


def _sweep_pair(
    shape_a: Shape, pose_a: tuple[float, float, float], shape_b: Shape, pose_b: tuple[float, float, float],
    dx: float, dy: float, vx: float, vy: float, k: int,
) -> _Sweep | None:
    """The sweep of the pair in the scaled local frame (B's offset (dx, dy), relative motion
    (vx, vy), sizes scaled by ``2**-k``), computed as :data:`~framework.collision.kinds.PAIRS` says."""
    (ax, ay, ar), (bx, by, br) = pose_a, pose_b
    rule = PAIRS[kind_of(shape_a), kind_of(shape_b)]
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
        return _circle_circle(dx, dy, math.ldexp(shape_a.radius, -k) + math.ldexp(shape_b.radius, -k),
                              vx, vy)
    if rule.family == POLYGON_CIRCLE and not rule.flip:
        assert isinstance(shape_b, Circle)
        return _polygon_circle(scaled_outline(_outlined(shape_a), 0.0, 0.0, ar, k), dx, dy,
                               math.ldexp(shape_b.radius, -k), vx, vy)
    if rule.family == POLYGON_CIRCLE:
        # A circle against B: in B's frame (as when B comes first, so that both orders do the same
        # arithmetic), cast A's centre at -delta, moving by -v; then turn the normals round.
        assert isinstance(shape_a, Circle)
        res = _polygon_circle(scaled_outline(_outlined(shape_b), 0.0, 0.0, br, k), -dx, -dy,
                              math.ldexp(shape_a.radius, -k), -vx, -vy)
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


def _turned_round(res: _Sweep | None) -> _Sweep | None:
    """A sweep worked with A and B swapped, its normals turned to point from A toward B again."""
    if res is None:
        return None
    return res[0], res[1], [(t, -nx, -ny) for t, nx, ny in res[2]]


def _outlined(shape: Shape) -> AABB | Polygon:
    """``shape`` as the box or polygon that the pair rule says it is here (no check made)."""
    return cast("AABB | Polygon", shape)


def _order_key(shape: Shape, x: float, y: float, rotation: float) -> tuple[object, ...]:
    """A total order on placed boxes and polygons (equal keys: the same outline at the same place)."""
    params = (shape.width, shape.height) if isinstance(shape, AABB) else cast(Polygon, shape).points
    return (x, y, rotation, kind_of(shape), params)


# --- pairs of kinds, in the scaled local frame --------------------------------------------------

def _unit(x: float, y: float) -> tuple[float, float]:
    ln = math.hypot(x, y)
    if ln == 0.0:
        return 0.0, 1.0  # undefined direction (only from rounding): up, as collide does
    return x / ln, y / ln


def _circle_circle(dx: float, dy: float, r: float, vx: float, vy: float) -> _Sweep | None:
    iv = disc_interval(dx, dy, r, vx, vy)
    if iv is None:
        return None
    t1, t2 = iv
    t = t1 if t1 > 0.0 else 0.0
    nx, ny = _unit(dx + t * vx, dy + t * vy)
    return t1, t2, [(t1, nx, ny)]


def _polygon_polygon(pa: Pts, pb: Pts, vx: float, vy: float) -> _Sweep | None:
    """Swept SAT: B (outline ``pb``) moves by ``tau * v`` against A (outline ``pa``)."""
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
            vp = ux * vx + uy * vy
            if vp == 0.0:
                if amax <= bmin or bmax <= amin:
                    return None  # separated (or touching) on this axis for the whole step
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
        return None
    return t_in, t_out, cands


def _polygon_circle(poly: Pts, cx: float, cy: float, r: float, vx: float, vy: float) -> _Sweep | None:
    """The circle's centre ``c + tau v`` against the polygon rounded by ``r`` (normals point from the
    polygon toward the circle). The rounded polygon's interior is the union of one open rectangle
    per face (the face swept out and in by ``r``) and one open disc per vertex; the line meets it in
    one interval whose ends are the earliest entry and latest exit among the pieces."""
    t_in, t_out = math.inf, -math.inf
    cands = []
    n = len(poly)
    for i in range(n):
        x0, y0 = poly[i]
        x1, y1 = poly[(i + 1) % n]
        ex, ey = x1 - x0, y1 - y0
        nx, ny = ey, -ex  # outward, unnormalised
        ln = math.sqrt(ex * ex + ey * ey)
        rl = r * ln
        qx, qy = cx - x0, cy - y0
        along = ex * qx + ey * qy
        across = nx * qx + ny * qy
        ev = ex * vx + ey * vy
        nv = nx * vx + ny * vy
        # Open rectangle 0 < e.(x - p0) < e.e, -r|e| < n.(x - p0) < r|e|, each as f0 + tau f1 < 0;
        # the tag says which side a ray enters through.
        rect = clip_constraints([
            (-along, -ev, "start"),
            (along - (ex * ex + ey * ey), ev, "end"),
            (across - rl, nv, "face"),
            (-across - rl, -nv, "inner"),
        ])
        if rect is not None:
            a, b, tags = rect
            t_in, t_out = min(t_in, a), max(t_out, b)
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
                cands.append((a, hx / hl, hy / hl))
            elif "inner" in tags and "face" not in tags:
                cands.append((a, -nx / ln, -ny / ln))
            else:
                cands.append((a, nx / ln, ny / ln))
        # Open disc around vertex p0.
        iv = disc_interval(qx, qy, r, vx, vy)
        if iv is not None:
            a, b = iv
            t_in, t_out = min(t_in, a), max(t_out, b)
            t = a if a > 0.0 else 0.0
            hx, hy = _unit(qx + t * vx, qy + t * vy)
            cands.append((a, hx, hy))
    if not t_in < t_out:
        return None
    return t_in, t_out, cands


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
                  k: int) -> _Sweep | None:
    """Capsule A at the origin, B's core at (dx, dy) moving by ``tau v``: B's offset against the cores'
    Minkowski difference rounded by the radii summed."""
    pa, ra = core_points(sa, rot_a, k)
    pb, rb = core_points(sb, rot_b, k)
    hull = _hull([(ax - bx, ay - by) for ax, ay in pa for bx, by in pb])
    if len(hull) >= 3:
        return _polygon_circle(hull, dx, dy, ra + rb, vx, vy)
    (s0x, s0y), (s1x, s1y) = hull if len(hull) == 2 else hull * 2
    found = rounded_segment(dx, dy, s0x, s0y, s1x, s1y, ra + rb, vx, vy)
    if found is None or not found[2]:
        return None
    return found


def clip_constraints(cons: list[tuple[float, float, str]]) -> tuple[float, float, set[str]] | None:
    """The open interval of ``tau`` where every ``f0 + tau f1 < 0`` holds, with the tags of the
    constraints that set its start (within :data:`TIE`), or ``None`` if it is empty."""
    t_in, t_out = -math.inf, math.inf
    enters = []
    for f0, f1, tag in cons:
        if f1 == 0.0:
            if f0 >= 0.0:
                return None
        elif f1 < 0.0:
            t = -f0 / f1
            enters.append((t, tag))
            if t > t_in:
                t_in = t
        else:
            t = -f0 / f1
            if t < t_out:
                t_out = t
    if not t_in < t_out or not enters:
        return None
    tol = TIE * max(1.0, abs(t_in))
    return t_in, t_out, {tag for t, tag in enters if t >= t_in - tol}
