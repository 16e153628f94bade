"""Contact manifolds in Box2D v3's form, compiled: up to two points with separations and feature ids.

Used by the soft step (:mod:`framework.systems.soft_kernel`). Every shape is a *rounded polygon*
in world coordinates: ``count`` vertices (counter-clockwise), their outward edge normals and a
rounding radius. A box or polygon has radius 0; a circle is one vertex with its radius; a capsule
is two vertices (its segment) with its radius, as Box2D's ``b2MakeCapsule``. So three functions
cover every pair: circle-circle, polygon-circle and polygon-polygon (Box2D's ``manifold.c``:
``b2CollideCircles``, ``b2CollidePolygonAndCircle``, ``b2CollidePolygons`` with ``b2ClipPolygons``).

Invariants: the normal points from A to B; a point's separation is negative where the shapes
overlap; a manifold is reported up to ``speculative`` apart (its points may be apart: the solver
lets them close, no further). Polygons are given as rows of the world vertex and normal tables
``V[row, i]``, ``N[row, i]`` (indexing, not views: a view per call cost more than the arithmetic).
Each function writes into ``out`` (rows: point 0, point 1; columns: x, y, separation, id) and
returns ``(count, nx, ny)``. Floats only: these are the soft step's measurements, not the
contract's exact decisions.

**Internal faces.** A static box's face that another static box covers (a floor of tiles, a wall of
tiles) is *internal*: nothing can be outside it. The ``faces`` bits of such a box (``LEFT``,
``RIGHT``, ``DOWN``, ``UP``: the direction a body leaves the box through the face) keep the
manifolds from pushing a body out through one: such an axis is not chosen as the contact's normal,
and a corner where an internal face meets an open one is part of the open face (a body sliding
or rolling over the seam between two tiles meets a flat floor, as on Box2D's chain shapes). Where
the least overlap leaves through an internal face, the next open way out is taken only if it is
within the pair's speculative distance (the body came that way this step); deeper, the contact
belongs to the neighbour that covers the face (a box in the corner of a tiled floor and a wall is
held by the floor and the wall, not lifted by the tile under the wall), and none is reported. A
separation along a banned axis still proves the shapes apart.

**Chain segments** (one-sided, with ghost vertices: :mod:`framework.collision.chain`) are a segment
first (a polygon of two points, radius 0); :func:`chain_segment` then keeps what the chain's rules
allow of that manifold: nothing where the body comes from behind or the neighbour owns the
direction, and a manifold along the segment's own normal (the body's incident edge clipped to the
segment, Box2D's ``b2ClipSegments``) where the normal points out of a straight or inward joint.
"""

from __future__ import annotations

import math

from ..compiled import leaf
from .chain import KEEP, PASS, SKIP, chain_verdict

__all__ = ["DOWN", "LEFT", "RIGHT", "UP", "box_box", "capsule_capsule", "chain_segment", "circle_circle", "face_bit",
           "polygon_circle", "polygon_polygon"]

_EPS = 1.1920929e-07  # Box2D's FLT_EPSILON, the scale of "safely outside"
LEFT, RIGHT, DOWN, UP = 1, 2, 4, 8  # a static box's faces, by the direction a body leaves it through them


@leaf
def face_bit(vx, vy):
    """The face of a box that the direction ``(vx, vy)`` leaves it through (its dominant axis)."""
    if abs(vx) >= abs(vy):
        return RIGHT if vx > 0.0 else LEFT
    return UP if vy > 0.0 else DOWN


@leaf
def circle_circle(ax, ay, ra, bx, by, rb, speculative, out):
    """Two circles (centres, radii)."""
    dx, dy = bx - ax, by - ay
    dist = math.sqrt(dx * dx + dy * dy)
    sep = dist - ra - rb
    if sep > speculative:
        return 0, 0.0, 0.0
    if dist > 0.0:
        nx, ny = dx / dist, dy / dist
    else:  # concentric: any direction is as good; up, as the contract's tie-break
        nx, ny = 0.0, 1.0
    # the point halfway between the two surfaces
    cax, cay = ax + ra * nx, ay + ra * ny
    cbx, cby = bx - rb * nx, by - rb * ny
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = 0.5 * (cax + cbx), 0.5 * (cay + cby), sep, 0.0
    return 1, nx, ny


@leaf
def box_box(ax, ay, aw, ah, bx, by, bw, bh, speculative, out, fa=0, fb=0):
    """Two axis-aligned boxes (centres, half extents; internal ``faces`` bits ``fa``, ``fb``): what
    :func:`polygon_polygon` gives them, in a few operations (the common case of boxes that never
    turn). The axis of least overlap (y on a tie: a resting stack's normal is vertical) unless it
    leaves a box through an internal face; two points at the ends of the faces' common run, one
    where the runs do not meet (boxes apart across a corner). Ids: 0, 1 along y, 2, 3 along x."""
    dx, dy = bx - ax, by - ay
    sx = abs(dx) - (aw + bw)
    sy = abs(dy) - (ah + bh)
    if sx > speculative or sy > speculative:
        return 0, 0.0, 0.0
    along_x = sx > sy
    if fa | fb:  # B leaves A along the normal, A leaves B against it
        gx = 1.0 if dx >= 0.0 else -1.0
        gy = 1.0 if dy >= 0.0 else -1.0
        x_ok = (fa & face_bit(gx, 0.0)) == 0 and (fb & face_bit(-gx, 0.0)) == 0
        y_ok = (fa & face_bit(0.0, gy)) == 0 and (fb & face_bit(0.0, -gy)) == 0
        if x_ok != y_ok and along_x != x_ok:  # the least overlap leaves through an internal face
            if (sy if along_x else sx) < -speculative:
                return 0, 0.0, 0.0
            along_x = x_ok
    if along_x:  # normal along x; the run is along y
        sgn = 1.0 if dx >= 0.0 else -1.0
        lo, hi = max(ay - ah, by - bh), min(ay + ah, by + bh)
        face = 0.5 * (ax + sgn * aw + bx - sgn * bw)
        if lo > hi:
            out[0, 0], out[0, 1], out[0, 2], out[0, 3] = face, 0.5 * (lo + hi), sx, 2.0
            return 1, sgn, 0.0
        out[0, 0], out[0, 1], out[0, 2], out[0, 3] = face, lo, sx, 2.0
        out[1, 0], out[1, 1], out[1, 2], out[1, 3] = face, hi, sx, 3.0
        return 2, sgn, 0.0
    sgn = 1.0 if dy >= 0.0 else -1.0
    lo, hi = max(ax - aw, bx - bw), min(ax + aw, bx + bw)
    face = 0.5 * (ay + sgn * ah + by - sgn * bh)
    if lo > hi:
        out[0, 0], out[0, 1], out[0, 2], out[0, 3] = 0.5 * (lo + hi), face, sy, 0.0
        return 1, 0.0, sgn
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = lo, face, sy, 0.0
    out[1, 0], out[1, 1], out[1, 2], out[1, 3] = hi, face, sy, 1.0
    return 2, 0.0, sgn


@leaf
def polygon_circle(V, N, a, count, ra, cx, cy, rb, speculative, out, fa=0):
    """Polygon A (world vertices ``V[a, :count]``, normals ``N[a]``, rounding ``ra``, internal
    ``faces`` bits ``fa``) and circle B."""
    sep, sep_all = -1e300, -1e300
    best = -1
    for i in range(count):
        s = N[a, i, 0] * (cx - V[a, i, 0]) + N[a, i, 1] * (cy - V[a, i, 1])
        sep_all = max(sep_all, s)
        if s > sep and (fa & face_bit(N[a, i, 0], N[a, i, 1])) == 0:
            sep, best = s, i
    radius = ra + rb
    if sep_all - radius > speculative:
        return 0, 0.0, 0.0
    if best < 0:  # every face internal: the deepest way out after all
        for i in range(count):
            s = N[a, i, 0] * (cx - V[a, i, 0]) + N[a, i, 1] * (cy - V[a, i, 1])
            if s > sep:
                sep, best = s, i
    elif sep < sep_all and sep - radius < -speculative:  # the way out is through a neighbour
        return 0, 0.0, 0.0
    i1 = best
    i2 = i1 + 1 if i1 + 1 < count else 0
    v1x, v1y, v2x, v2y = V[a, i1, 0], V[a, i1, 1], V[a, i2, 0], V[a, i2, 1]
    u1 = (cx - v1x) * (v2x - v1x) + (cy - v1y) * (v2y - v1y)
    u2 = (cx - v2x) * (v1x - v2x) + (cy - v2y) * (v1y - v2y)
    if fa:  # a corner where an internal face meets this one belongs to this face
        i0 = i1 - 1 if i1 > 0 else count - 1
        if u1 < 0.0 and (fa & face_bit(N[a, i0, 0], N[a, i0, 1])) != 0:
            u1 = 0.0
        if u2 < 0.0 and (fa & face_bit(N[a, i2, 0], N[a, i2, 1])) != 0:
            u2 = 0.0
    if (u1 < 0.0 or u2 < 0.0) and sep > _EPS:
        # the centre is nearest a vertex, safely outside: the normal runs from the vertex
        px, py = (v1x, v1y) if u1 < 0.0 else (v2x, v2y)
        dx, dy = cx - px, cy - py
        d = math.sqrt(dx * dx + dy * dy)
        if d - radius > speculative:
            return 0, 0.0, 0.0
        nx, ny = dx / d, dy / d
        cax, cay = px + ra * nx, py + ra * ny
        cbx, cby = cx - rb * nx, cy - rb * ny
        out[0, 0], out[0, 1] = 0.5 * (cax + cbx), 0.5 * (cay + cby)
        out[0, 2], out[0, 3] = (cbx - cax) * nx + (cby - cay) * ny, 0.0
        return 1, nx, ny
    nx, ny = N[a, best, 0], N[a, best, 1]
    # cA: the centre projected onto the (rounded) reference face; cB: the circle's deepest point
    proj = ra - ((cx - v1x) * nx + (cy - v1y) * ny)
    cax, cay = cx + proj * nx, cy + proj * ny
    cbx, cby = cx - rb * nx, cy - rb * ny
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = 0.5 * (cax + cbx), 0.5 * (cay + cby), sep - radius, 0.0
    return 1, nx, ny


@leaf
def _max_separation(V, N, p1, c1, p2, c2, f1, f2):
    """The edge of polygon 1 whose normal separates the two the most and that separation, among the
    edges that leave no box through an internal face (``f1``, ``f2``: the polygons' ``faces`` bits;
    -1 and -1e300 if none does); then the most separating of all edges' separations."""
    best, best_sep, sep_all = -1, -1e300, -1e300
    for i in range(c1):
        si = 1e300
        for j in range(c2):
            s = N[p1, i, 0] * (V[p2, j, 0] - V[p1, i, 0]) + N[p1, i, 1] * (V[p2, j, 1] - V[p1, i, 1])
            if s < si:
                si = s
        sep_all = max(sep_all, si)
        if si > best_sep and ((f1 | f2) == 0 or ((f1 & face_bit(N[p1, i, 0], N[p1, i, 1])) == 0
                                                 and (f2 & face_bit(-N[p1, i, 0], -N[p1, i, 1])) == 0)):
            best_sep, best = si, i
    return best, best_sep, sep_all


@leaf
def _internal_corner(N, p, c, i, f):
    """Whether vertex ``i`` of polygon ``p`` (``c`` vertices, ``faces`` bits ``f``) ends an internal face."""
    if f == 0:
        return False
    i0 = i - 1 if i > 0 else c - 1
    return (f & face_bit(N[p, i0, 0], N[p, i0, 1])) != 0 or (f & face_bit(N[p, i, 0], N[p, i, 1])) != 0


@leaf
def _incident_edge(nx, ny, N, p2, c2):
    """The edge of polygon 2 most anti-parallel to the reference normal."""
    best, low = 0, 1e300
    for i in range(c2):
        d = nx * N[p2, i, 0] + ny * N[p2, i, 1]
        if d < low:
            low, best = d, i
    return best


@leaf
def _segment_fractions(p1x, p1y, q1x, q1y, p2x, p2y, q2x, q2y):
    """Box2D's ``b2SegmentDistance``: the fractions along segments 1 and 2 of their closest points."""
    d1x, d1y, d2x, d2y = q1x - p1x, q1y - p1y, q2x - p2x, q2y - p2y
    rx, ry = p1x - p2x, p1y - p2y
    dd1 = d1x * d1x + d1y * d1y
    dd2 = d2x * d2x + d2y * d2y
    rd1 = rx * d1x + ry * d1y
    rd2 = rx * d2x + ry * d2y
    eps2 = _EPS * _EPS
    if dd1 < eps2 or dd2 < eps2:
        if dd1 >= eps2:
            return min(max(-rd1 / dd1, 0.0), 1.0), 0.0
        if dd2 >= eps2:
            return 0.0, min(max(rd2 / dd2, 0.0), 1.0)
        return 0.0, 0.0
    d12 = d1x * d2x + d1y * d2y
    denom = dd1 * dd2 - d12 * d12
    f1 = 0.0
    if denom != 0.0:
        f1 = min(max((d12 * rd2 - rd1 * dd2) / denom, 0.0), 1.0)
    f2 = (d12 * f1 + rd2) / dd2
    if f2 < 0.0:
        f2 = 0.0
        f1 = min(max(-rd1 / dd1, 0.0), 1.0)
    elif f2 > 1.0:
        f2 = 1.0
        f1 = min(max((d12 - rd1) / dd1, 0.0), 1.0)
    return f1, f2


@leaf
def _clip(V, N, p1, c1, r1, e1, p2, c2, r2, e2, flip, out):
    """Box2D's ``b2ClipPolygons``: reference edge ``e1`` of polygon 1, incident edge ``e2`` of
    polygon 2; ``flip``: polygon 1 is B (the normal is turned to point from A to B)."""
    i11, i12 = e1, (e1 + 1 if e1 + 1 < c1 else 0)
    i21, i22 = e2, (e2 + 1 if e2 + 1 < c2 else 0)
    nx, ny = N[p1, i11, 0], N[p1, i11, 1]
    v11x, v11y, v12x, v12y = V[p1, i11, 0], V[p1, i11, 1], V[p1, i12, 0], V[p1, i12, 1]
    v21x, v21y, v22x, v22y = V[p2, i21, 0], V[p2, i21, 1], V[p2, i22, 0], V[p2, i22, 1]
    tx, ty = -ny, nx  # cross(1, normal)
    lower1 = 0.0
    upper1 = (v12x - v11x) * tx + (v12y - v11y) * ty
    upper2 = (v21x - v11x) * tx + (v21y - v11y) * ty  # the incident edge runs against the tangent
    lower2 = (v22x - v11x) * tx + (v22y - v11y) * ty
    if upper2 < lower1 or upper1 < lower2:
        return 0, 0.0, 0.0
    span = upper2 - lower2
    if lower2 < lower1 and span > _EPS:
        t = (lower1 - lower2) / span
        lox, loy = v22x + t * (v21x - v22x), v22y + t * (v21y - v22y)
    else:
        lox, loy = v22x, v22y
    if upper2 > upper1 and span > _EPS:
        t = (upper1 - lower2) / span
        upx, upy = v22x + t * (v21x - v22x), v22y + t * (v21y - v22y)
    else:
        upx, upy = v21x, v21y
    slo = (lox - v11x) * nx + (loy - v11y) * ny
    sup = (upx - v11x) * nx + (upy - v11y) * ny
    # points halfway between the rounded surfaces
    lox, loy = lox + 0.5 * (r1 - r2 - slo) * nx, loy + 0.5 * (r1 - r2 - slo) * ny
    upx, upy = upx + 0.5 * (r1 - r2 - sup) * nx, upy + 0.5 * (r1 - r2 - sup) * ny
    radius = r1 + r2
    if not flip:
        out[0, 0], out[0, 1], out[0, 2], out[0, 3] = lox, loy, slo - radius, float((i11 << 8) | i22)
        out[1, 0], out[1, 1], out[1, 2], out[1, 3] = upx, upy, sup - radius, float((i12 << 8) | i21)
        return 2, nx, ny
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = upx, upy, sup - radius, float((i21 << 8) | i12)
    out[1, 0], out[1, 1], out[1, 2], out[1, 3] = lox, loy, slo - radius, float((i22 << 8) | i11)
    return 2, -nx, -ny


@leaf
def _segments_cross(V, a, b):
    """Whether the segments of rows ``a`` and ``b`` cross (each one's ends on either side of the
    other's line, by the signs of the orientations: closest points then lie at no distance, up
    to rounding)."""
    px, py, qx, qy = V[a, 0, 0], V[a, 0, 1], V[a, 1, 0], V[a, 1, 1]
    rx, ry, sx, sy = V[b, 0, 0], V[b, 0, 1], V[b, 1, 0], V[b, 1, 1]
    o1 = (qx - px) * (ry - py) - (qy - py) * (rx - px)
    o2 = (qx - px) * (sy - py) - (qy - py) * (sx - px)
    o3 = (sx - rx) * (py - ry) - (sy - ry) * (px - rx)
    o4 = (sx - rx) * (qy - ry) - (sy - ry) * (qx - rx)
    return o1 * o2 < 0.0 and o3 * o4 < 0.0


@leaf
def capsule_capsule(V, a, ra, b, rb, speculative, out):
    """Two capsules (rows ``a``, ``b`` of ``V``: their segments' ends; radii): one point, between
    the closest points of the two segments (as Box2D's ``b2CollideCapsules`` where the segments are
    not parallel; our capsules never turn, so one point holds them). Two capsules end to end are
    not a face against a face: the polygon clipper finds nothing there. Where the segments cross
    (closest points at no distance), returns a count of -1: the separating-axis measure of
    :func:`polygon_polygon` is the one that knows how deep they are then."""
    f1, f2 = _segment_fractions(V[a, 0, 0], V[a, 0, 1], V[a, 1, 0], V[a, 1, 1],
                                V[b, 0, 0], V[b, 0, 1], V[b, 1, 0], V[b, 1, 1])
    c1x = V[a, 0, 0] + f1 * (V[a, 1, 0] - V[a, 0, 0])
    c1y = V[a, 0, 1] + f1 * (V[a, 1, 1] - V[a, 0, 1])
    c2x = V[b, 0, 0] + f2 * (V[b, 1, 0] - V[b, 0, 0])
    c2y = V[b, 0, 1] + f2 * (V[b, 1, 1] - V[b, 0, 1])
    dx, dy = c2x - c1x, c2y - c1y
    d = math.sqrt(dx * dx + dy * dy)
    if d - ra - rb > speculative:
        return 0, 0.0, 0.0
    if d == 0.0 or _segments_cross(V, a, b):  # the caller measures them as rounded polygons instead
        return -1, 0.0, 0.0
    nx, ny = dx / d, dy / d
    cax, cay = c1x + ra * nx, c1y + ra * ny
    cbx, cby = c2x - rb * nx, c2y - rb * ny
    out[0, 0], out[0, 1] = 0.5 * (cax + cbx), 0.5 * (cay + cby)
    out[0, 2], out[0, 3] = d - ra - rb, 0.0
    return 1, nx, ny


@leaf
def polygon_polygon(V, N, a, ca, ra, b, cb, rb, slop, speculative, out, fa=0, fb=0):
    """Two rounded polygons (world vertices, normals, counts, radii, internal ``faces`` bits),
    ``slop``: Box2D's linear slop. Returns ``(count, nx, ny)``; points beyond ``speculative`` apart
    are dropped."""
    ea, sa, all_a = _max_separation(V, N, a, ca, b, cb, fa, fb)
    eb, sb, all_b = _max_separation(V, N, b, cb, a, ca, fb, fa)
    radius = ra + rb
    if all_a > speculative + radius or all_b > speculative + radius:
        return 0, 0.0, 0.0
    if ea < 0 and eb < 0:  # every axis leaves through an internal face: the least deep after all
        ea, sa, _ = _max_separation(V, N, a, ca, b, cb, 0, 0)
        eb, sb, _ = _max_separation(V, N, b, cb, a, ca, 0, 0)
    elif max(sa, sb) < max(all_a, all_b) and max(sa, sb) - radius < -speculative:  # through a neighbour
        return 0, 0.0, 0.0
    flip = not (sa >= sb)
    if flip:
        ea = _incident_edge(N[b, eb, 0], N[b, eb, 1], N, a, ca)
    else:
        eb = _incident_edge(N[a, ea, 0], N[a, ea, 1], N, b, cb)
    if sa > 0.1 * slop or sb > 0.1 * slop:
        # Apart: if the nearest features are two vertices, one point along the line between them.
        i11, i12 = ea, (ea + 1 if ea + 1 < ca else 0)
        i21, i22 = eb, (eb + 1 if eb + 1 < cb else 0)
        f1, f2 = _segment_fractions(V[a, i11, 0], V[a, i11, 1], V[a, i12, 0], V[a, i12, 1],
                                    V[b, i21, 0], V[b, i21, 1], V[b, i22, 0], V[b, i22, 1])
        ia = i11 if f1 == 0.0 else i12
        ib = i21 if f2 == 0.0 else i22
        if ((f1 == 0.0 or f1 == 1.0) and (f2 == 0.0 or f2 == 1.0) and not _internal_corner(N, a, ca, ia, fa)
                and not _internal_corner(N, b, cb, ib, fb)):
            dx, dy = V[b, ib, 0] - V[a, ia, 0], V[b, ib, 1] - V[a, ia, 1]
            d = math.sqrt(dx * dx + dy * dy)
            if d - radius > speculative:
                return 0, 0.0, 0.0
            if d > 0.0:
                nx, ny = dx / d, dy / d
                cax, cay = V[a, ia, 0] + ra * nx, V[a, ia, 1] + ra * ny
                cbx, cby = V[b, ib, 0] - rb * nx, V[b, ib, 1] - rb * ny
                out[0, 0], out[0, 1] = 0.5 * (cax + cbx), 0.5 * (cay + cby)
                out[0, 2], out[0, 3] = d - radius, float((ia << 8) | ib)
                return 1, nx, ny
    # one call site (a literal flip would compile the clip twice)
    p1, c1, r1, e1, p2, c2, r2, e2 = (b, cb, rb, eb, a, ca, ra, ea) if flip else (a, ca, ra, ea, b, cb, rb, eb)
    k, nx, ny = _clip(V, N, p1, c1, r1, e1, p2, c2, r2, e2, flip, out)
    if k == 2:  # drop a point beyond the speculative distance (keep the order of the rest)
        keep0 = out[0, 2] <= speculative
        keep1 = out[1, 2] <= speculative
        if not keep0 and not keep1:
            return 0, 0.0, 0.0
        if not keep0:
            out[0, 0], out[0, 1], out[0, 2], out[0, 3] = out[1, 0], out[1, 1], out[1, 2], out[1, 3]
            return 1, nx, ny
        if not keep1:
            return 1, nx, ny
    return k, nx, ny


@leaf
def _unit2(x, y):
    ln = math.sqrt(x * x + y * y)
    return x / ln, y / ln


@leaf
def chain_segment(V, N, L, g, o, count, ro, cx, cy, k, nx, ny, speculative, out):
    """What chain segment ``g`` (world ends ``V[g, 0:2]``; local ends and ghosts ``L[g, 0:4]``) keeps of
    its manifold with body ``o`` (``count`` world vertices ``V[o]``, normals ``N[o]``, radius ``ro``,
    hitbox origin ``(cx, cy)``): ``k`` points in ``out`` and the normal ``(nx, ny)`` from ``g`` toward
    ``o``. Returns ``(count, nx, ny)``, the normal from ``g`` toward ``o``. The rule is
    :func:`framework.collision.chain.chain_verdict` (its directions measured here as Box2D does,
    ``sqrt(x * x + y * y)``); what a kept or snapped manifold's points are is this function's."""
    if k <= 0:
        return k, nx, ny
    p1x, p1y, p2x, p2y = V[g, 0, 0], V[g, 0, 1], V[g, 1, 0], V[g, 1, 1]
    # The ghosts in the world: the turn taking the local segment to the world one.
    lex, ley = L[g, 1, 0] - L[g, 0, 0], L[g, 1, 1] - L[g, 0, 1]
    wex, wey = p2x - p1x, p2y - p1y
    l2 = lex * lex + ley * ley
    c, s = (lex * wex + ley * wey) / l2, (lex * wey - ley * wex) / l2
    d1x, d1y = L[g, 2, 0] - L[g, 0, 0], L[g, 2, 1] - L[g, 0, 1]
    d2x, d2y = L[g, 3, 0] - L[g, 0, 0], L[g, 3, 1] - L[g, 0, 1]
    g1x, g1y = p1x + c * d1x - s * d1y, p1y + s * d1x + c * d1y
    g2x, g2y = p1x + c * d2x - s * d2y, p1y + s * d2x + c * d2y
    u1x, u1y = _unit2(wex, wey)
    n1x, n1y = u1y, -u1x
    u0x, u0y = _unit2(p1x - g1x, p1y - g1y)
    u2x, u2y = _unit2(g2x - p2x, g2y - p2y)
    verdict, convex1, convex2 = chain_verdict(p1x, p1y, p2x, p2y, u0x, u0y, u1x, u1y, u2x, u2y, cx, cy, nx, ny)
    if verdict == PASS or verdict == SKIP:
        return 0, 0.0, 0.0  # the body comes from behind, or the neighbour owns the normal
    length = math.sqrt(wex * wex + wey * wey)
    if verdict == KEEP:
        return _own_points(out, k, p1x, p1y, u1x, u1y, length, convex1, convex2, nx, ny)
    # Snapped: along the segment's normal, the body's incident edge clipped to the segment.
    if count == 1:
        qx, qy = V[o, 0, 0], V[o, 0, 1]
        t = (qx - p1x) * u1x + (qy - p1y) * u1y
        if t < 0.0 or t > length:
            return 0, 0.0, 0.0  # beside the segment: the neighbour's
        h = (qx - p1x) * n1x + (qy - p1y) * n1y
        if h - ro > speculative:
            return 0, 0.0, 0.0
        out[0, 0], out[0, 1] = qx - n1x * 0.5 * (h + ro), qy - n1y * 0.5 * (h + ro)
        out[0, 2], out[0, 3] = h - ro, 0.0
        return _own_points(out, 1, p1x, p1y, u1x, u1y, length, convex1, convex2, n1x, n1y)
    deep, low = 0, 1e300
    for i in range(count):
        h = (V[o, i, 0] - p1x) * n1x + (V[o, i, 1] - p1y) * n1y
        if h < low:
            deep, low = i, h
    before = deep - 1 if deep > 0 else count - 1
    e = before if N[o, before, 0] * n1x + N[o, before, 1] * n1y < N[o, deep, 0] * n1x + N[o, deep, 1] * n1y else deep
    e1 = e + 1 if e + 1 < count else 0
    ax, ay, bx, by = V[o, e, 0], V[o, e, 1], V[o, e1, 0], V[o, e1, 1]
    ta, tb = (ax - p1x) * u1x + (ay - p1y) * u1y, (bx - p1x) * u1x + (by - p1y) * u1y
    if max(ta, tb) < 0.0 or min(ta, tb) > length:
        return 0, 0.0, 0.0
    m = 0
    # (an edge that meets the segment at one point, an end, gives that point once)
    single = min(max(ta, tb), length) - max(min(ta, tb), 0.0) <= 1e-9 * length
    for j in range(1 if single else 2):
        t_end = ta if j == 0 else tb
        qx, qy = (ax, ay) if j == 0 else (bx, by)
        if (t_end < 0.0 or t_end > length) and ta != tb:
            bound = 0.0 if t_end < 0.0 else length
            f = (bound - ta) / (tb - ta)
            qx, qy = ax + f * (bx - ax), ay + f * (by - ay)
        h = (qx - p1x) * n1x + (qy - p1y) * n1y
        if h - ro > speculative:
            continue
        out[m, 0], out[m, 1] = qx - n1x * 0.5 * (h + ro), qy - n1y * 0.5 * (h + ro)
        out[m, 2], out[m, 3] = h - ro, float(j)
        m += 1
    return _own_points(out, m, p1x, p1y, u1x, u1y, length, convex1, convex2, n1x, n1y)


@leaf
def _own_points(out, k, p1x, p1y, u1x, u1y, length, convex1, convex2, nx, ny):
    """The manifold's points that this segment owns: a point at or beyond a joint where the chain
    runs on straight or bends inward is the neighbour's (at the joint itself, the segment that ends
    there keeps it, the one that starts there leaves it), so a face resting across a joint is held
    at its two ends, not at three points, two of them one. Returns ``(count, nx, ny)``."""
    m = 0
    for i in range(k):
        t = (out[i, 0] - p1x) * u1x + (out[i, 1] - p1y) * u1y
        if (not convex1 and t <= 1e-9 * length) or (not convex2 and t > length * (1.0 + 1e-9)):
            continue
        if m != i:
            out[m, 0], out[m, 1], out[m, 2], out[m, 3] = out[i, 0], out[i, 1], out[i, 2], out[i, 3]
        m += 1
    if m == 0:
        return 0, 0.0, 0.0
    return m, nx, ny
