"""Pairwise overlap tests with contact normal, depth and point, for every pair of shape kinds.

Depth is the penetration depth, i.e. the distance from the origin to the boundary of the Minkowski
difference A - B. Its faces are A's faces and B's faces turned around, so for boxes and polygons
the shortest push-out is found among those face normals: along an axis ``n`` B must move
``max(A.n) - min(B.n)`` forward, or ``max(B.n) - min(A.n)`` backward (the full push-out, also for a
shape contained in the other, not the overlap of the two shadows).

Numerics, in three layers:

1. **A local frame.** Each pair is worked relative to one shape's position (A's; the polygon's for
   a polygon-circle pair, whichever comes first), with shapes in their own local coordinates and
   B's offset kept apart: a projection is ``u . local + u . offset``. So a scene at x = 1e9 gives
   the answers of the scene at the origin, and swapping A and B gives bit-identical depths and
   exactly negated normals.
2. **A power-of-two scale.** The frame is scaled by ``2**-k`` so that the largest offset or
   bounding radius is about 1. Scaling by a power of two is exact, so ordinary scenes get the
   unscaled answers bit for bit, while radii of 1e-200 or 1e300 neither underflow nor overflow.
3. **Exact arithmetic near touching.** Floats decide wherever the answer is clear by far more than
   their rounding error. Inside a thin band around "touching" the decision is redone with exact
   integers (every float is an integer times a power of two; :mod:`~framework.collision.exact`,
   shared with the batch kernels), so touching is never a collision and an overlap of one ulp
   always is; the depth is then computed from the exact overlap, so it is > 0 whenever a contact
   is returned.
"""

from __future__ import annotations

import math
from typing import cast

from ..shapes import AABB, Capsule, ChainSegment, Circle, Polygon, Segment, Shape
from ..validation import InvalidValue
from .capsule import capsule_first, capsule_pair
from .exact import (
    BAND,
    TINY,
    Offset,
    circle_circle_exact,
    float_approx,
    polygon_circle_exact,
    polygon_polygon_exact,
    ratio_approx,
    vertex_contact,
)
from .kinds import CAPSULES, CIRCLES, PAIRS, POLYGON_CIRCLE, kind_of
from .placement import check_shape, local_outline, pose
from .results import Contact, Vec2
from .tiebreak import pick

__all__ = ["collide"]

Pts = list[tuple[float, float]]
# (nx, ny, depth, px, py) in the scaled local frame; the normal already points from A toward B.
Res = tuple[float, float, float, float, float]


def collide(shape_a: Shape, transform_a: object, shape_b: Shape, transform_b: object) -> Contact | None:
    """Contact of B against A, or ``None`` unless their interiors overlap (touching is no contact).

    The normal points from A toward B; moving B by ``normal * depth`` leaves them touching.
    Transforms may be :class:`~framework.components.Transform` objects or ``(x, y[, rotation])``
    tuples; bad shapes or non-finite transform fields raise ``ValueError`` naming the field.
    """
    check_shape("shape_a", shape_a)
    check_shape("shape_b", shape_b)
    ax, ay, ar = pose("transform_a", transform_a)
    bx, by, br = pose("transform_b", transform_b)
    if isinstance(shape_b, ChainSegment) and not isinstance(shape_a, ChainSegment):
        # A chain segment's contact is worked with the segment first, whichever comes first.
        c = collide(shape_b, (bx, by, br), shape_a, (ax, ay, ar))
        return None if c is None else Contact(Vec2(-c.normal.x + 0.0, -c.normal.y + 0.0), c.depth, c.point)
    rule = PAIRS[kind_of(shape_a), kind_of(shape_b)]
    flip = rule.flip
    if rule.family == CAPSULES and not flip and isinstance(shape_b, Capsule):
        # Two capsules: in the frame of the one placed first, whichever comes first.
        flip = not capsule_first(shape_a, (ax, ay, ar), shape_b, (bx, by, br))  # type: ignore[arg-type]
    if flip:
        # Polygon-circle pairs are worked in the polygon's frame whichever comes first (pairs
        # with a capsule in the capsule's).
        ox, oy = bx, by
        found = _pair(rule.family, shape_b, bx, by, br, shape_a, ax, ay, ar, flip=True)
    else:
        ox, oy = ax, ay
        found = _pair(rule.family, shape_a, ax, ay, ar, shape_b, bx, by, br)
    if found is None:
        return None
    (nx, ny, depth, px, py), k = found
    try:
        # An overlap below the smallest float (only between shapes 1e300 times smaller than the
        # scene) is still an overlap: depth > 0.
        depth = max(math.ldexp(depth, k), TINY)
        px, py = ox + math.ldexp(px, k), oy + math.ldexp(py, k)
    except OverflowError:
        px = math.inf
    if not (math.isfinite(depth) and math.isfinite(px) and math.isfinite(py)):
        raise InvalidValue(
            f"collide: the contact of {shape_a!r} at {(ax, ay)!r} and {shape_b!r} at {(bx, by)!r} "
            "is beyond float64's range"
        )
    if isinstance(shape_a, ChainSegment) and not isinstance(shape_b, Segment):
        # A chain segment keeps what its one side and its joints allow (framework.collision.chain).
        from .chain import one_contact

        kept = one_contact(shape_a, (ax, ay, ar), shape_b, (bx, by, br), nx, ny, depth, px, py)
        if kept is None:
            return None
        nx, ny, depth, px, py = kept
    # "+ 0.0" turns a -0.0 component into 0.0, so normals compare and print cleanly.
    return Contact(Vec2(nx + 0.0, ny + 0.0), depth, Vec2(px, py))


def _pair(
    family: int, sa: Shape, ox: float, oy: float, rot_a: float, sb: Shape, qx: float, qy: float,
    rot_b: float = 0.0, flip: bool = False,
) -> tuple[Res, int] | None:
    """``sa`` at (ox, oy) against ``sb`` at (qx, qy), computed by ``family``
    (:data:`~framework.collision.kinds.PAIRS`): the result in ``sa``'s frame scaled by 2**-k.

    With ``flip`` the caller's A is ``sb`` (a circle, or the shape paired with a capsule): normals
    are turned to point from it.
    """
    ra, rb = sa.bounding_radius, sb.bounding_radius
    # Halves first: 0.5 * q - 0.5 * o never overflows, and halving is exact above the subnormals.
    hx, hy = 0.5 * qx - 0.5 * ox, 0.5 * qy - 0.5 * oy
    k = math.frexp(max(abs(hx), abs(hy), 0.5 * ra, 0.5 * rb))[1]
    dx, dy = math.ldexp(hx, 1 - k), math.ldexp(hy, 1 - k)
    # The exact offset (q - o) * 2**-k, for the exact fallback.
    off = (ox, oy, qx, qy, k)
    size = math.ldexp(ra, -k) + math.ldexp(rb, -k)
    if family == CAPSULES:
        assert isinstance(sa, Capsule)
        res = capsule_pair(sa, rot_a, sb, rot_b, dx, dy, off, k, size, flip)
    elif family == CIRCLES:
        assert isinstance(sa, Circle) and isinstance(sb, Circle)
        res = circle_circle(math.ldexp(sa.radius, -k), math.ldexp(sb.radius, -k), dx, dy, off)
    elif family == POLYGON_CIRCLE:
        assert isinstance(sb, Circle)
        # (the pair rule puts the box or polygon first)
        res = polygon_circle(local_outline(cast("AABB | Polygon", sa), rot_a, k), dx, dy, math.ldexp(sb.radius, -k),
                             off, size, flip)
    else:  # BOXES or POLYGONS: boxes are polygons here, and a segment an outline of two points
        res = polygon_polygon(local_outline(cast("AABB | Polygon | Segment", sa), rot_a, k),
                              local_outline(cast("AABB | Polygon | Segment", sb), rot_b, k), dx, dy, off, size)
    return None if res is None else (res, k)


# --- circle / circle -------------------------------------------------------------------------

def circle_circle(
    ra: float, rb: float, dx: float, dy: float, off: Offset
) -> Res | None:
    """Circle A (radius ``ra``) at the origin, circle B (``rb``) at (dx, dy)."""
    rsum = ra + rb
    d2, r2 = dx * dx + dy * dy, rsum * rsum
    band = BAND * (d2 + r2)
    if d2 >= r2 + band:
        return None
    dist = math.hypot(dx, dy)
    if d2 > r2 - band:
        # Too close to touching for floats: decide on the exact |d|^2 < (ra + rb)^2, and take the
        # depth from the exact (ra + rb)^2 - |d|^2 = depth * (ra + rb + |d|).
        excess = circle_circle_exact(off, ra, rb)
        if excess is None:
            return None
        depth = max(float_approx(*excess) / (rsum + dist), TINY)
    else:
        depth = rsum - dist
    if dist > 0.0:
        nx, ny = dx / dist, dy / dist
    else:  # coincident centres: the direction is undefined, push up
        nx, ny = 0.0, 1.0
    # The overlap meets the centre line in [lo, hi] (distances from A's centre along n).
    lo = max(-ra, dist - rb)
    hi = min(ra, dist + rb)
    mid = 0.5 * (lo + hi)
    return nx, ny, depth, nx * mid, ny * mid


# --- polygon / circle ------------------------------------------------------------------------

def polygon_circle(
    poly: Pts, cx: float, cy: float, r: float, off: Offset, size: float,
    flip: bool = False,
) -> Res | None:
    """Convex CCW polygon A at the origin against circle B (radius ``r``) at (cx, cy).

    With ``flip`` the normal points from the circle to the polygon (the circle is the caller's A).
    """
    f = -1.0 if flip else 1.0
    rp = max(math.hypot(x, y) for x, y in poly)
    tol = BAND * (abs(cx) + abs(cy) + rp + r)  # on distances
    faces = _faces(poly)
    # Unnormalised signed distances of the centre outside each face (outward normal (ey, -ex)).
    seps = [ey * (cx - x0) - ex * (cy - y0) for x0, y0, ex, ey, _, _ in faces]
    if faces and all(s <= 0.0 for s in seps) and (len(poly) != 2 or _between(poly, cx, cy)):
        # Centre inside (or on the boundary): push out through the nearest face, plus the radius.
        cands = _inside_candidates(faces, seps, r, f)
        if min(c[0] for c in cands) > tol:
            depth, nx, ny = pick(cands, size)
            return nx, ny, depth, cx, cy
        return _polygon_circle_exact(poly, cx, cy, r, off, size, f)
    # Centre outside: the closest point of the polygon is on a face whose region holds the centre
    # (s > 0 and the projection falls within the edge), or else it is the nearest vertex.
    dist = None
    for (x0, y0, ex, ey, ln, k), s in zip(faces, seps, strict=True):
        # The centre's projection on the edge line lies within the edge (of length ln * 2**k).
        if s > 0.0 and 0.0 <= ((cx - x0) * ex + (cy - y0) * ey) / ln <= math.ldexp(ln, k):
            nx, ny = ey / ln, -ex / ln
            dist = s / ln
            px, py = cx - nx * dist, cy - ny * dist  # closest point on the face
            break
    if dist is None:
        # Distances in one frame (no per-vertex rescaling), so the nearest vertex wins.
        vx, vy = min(poly, key=lambda v: math.hypot(cx - v[0], cy - v[1]))
        ddx, ddy = cx - vx, cy - vy
        dist = math.hypot(ddx, ddy)
        if dist == 0.0:
            return _polygon_circle_exact(poly, cx, cy, r, off, size, f)
        nx, ny = ddx / dist, ddy / dist
        px, py = vx, vy
    if dist >= r + tol:
        return None
    if dist > r - tol:
        return _polygon_circle_exact(poly, cx, cy, r, off, size, f)
    return f * nx, f * ny, r - dist, px, py


def _between(seg: Pts, cx: float, cy: float) -> bool:
    """The projection of (cx, cy) on the segment (an outline of two points) lies between its ends
    (with the centre on its line, the centre is then on the segment: "inside" it)."""
    (x0, y0), (x1, y1) = seg
    ex, ey = x1 - x0, y1 - y0
    t = (cx - x0) * ex + (cy - y0) * ey
    return 0.0 <= t <= ex * ex + ey * ey


Face = tuple[float, float, float, float, float, int]


def _faces(poly: Pts) -> list[Face]:
    """``(x0, y0, ex, ey, |e|, k)`` of each edge of an outline, but those scaled away to nothing.

    ``(ex, ey)`` is the edge times ``2**-k`` (exact), which keeps products from underflowing.
    """
    n = len(poly)
    faces = []
    for i in range(n):
        x0, y0 = poly[i]
        x1, y1 = poly[(i + 1) % n]
        if (x0, y0) != (x1, y1):
            k = math.frexp(max(abs(x1 - x0), abs(y1 - y0)))[1]
            ex, ey = math.ldexp(x1 - x0, -k), math.ldexp(y1 - y0, -k)
            faces.append((x0, y0, ex, ey, math.hypot(ex, ey), k))
    return faces


def _inside_candidates(faces: list[Face], seps: list[float], r: float, f: float) -> list[tuple[float, float, float]]:
    """Push-outs through each face of a centre inside; ``seps`` are in the faces' edge units."""
    cands = [
        (r - s / ln, f * ey / ln, -f * ex / ln) for (_, _, ex, ey, ln, _), s in zip(faces, seps, strict=True)
    ]
    return cands or [(r, 0.0, 1.0)]  # a polygon shrunk to a point at the centre: undefined, up


def _polygon_circle_exact(
    poly: Pts, cx: float, cy: float, r: float, off: Offset, size: float, f: float
) -> Res | None:
    """:func:`polygon_circle` decided on exact integers (for centres within rounding of touching)."""
    found = polygon_circle_exact(poly, off, r)
    if found is None:
        return None
    n, e = len(poly), found.e
    if found.case == "inside":
        # Always an overlap (r > 0), depth r + distance to the face.
        faces = _faces(poly)  # the same edges: a float edge is zero exactly when the exact one is
        exact_seps = [s for i, s in enumerate(found.seps) if poly[i] != poly[(i + 1) % n]]
        seps = [float_approx(s, 2 * e - face[5]) for s, face in zip(exact_seps, faces, strict=True)]
        cands = _inside_candidates(faces, seps, r, f)
        depth, nx, ny = pick(cands, size)
        return nx, ny, max(depth, TINY), cx, cy
    if found.case == "face":
        # depth = r - dist, computed as (r^2 - dist^2) / (r + dist) with r^2 - dist^2 =
        # (r^2 |e|^2 - s^2) / |e|^2 exact.
        i = found.index
        (fx0, fy0), (fx1, fy1) = poly[i], poly[(i + 1) % n]
        k = math.frexp(max(abs(fx1 - fx0), abs(fy1 - fy0)))[1]
        fex, fey = math.ldexp(fx1 - fx0, -k), math.ldexp(fy1 - fy0, -k)
        ln = math.hypot(fex, fey)
        dist = float_approx(found.seps[i], 2 * e - k) / ln
        depth = max(ratio_approx(found.num, found.edge2, 2 * e) / (r + dist), TINY)
        nx, ny = fey / ln, -fex / ln
        return f * nx, f * ny, depth, cx - nx * dist, cy - ny * dist
    return vertex_contact(found, poly, r, f, float_approx)


# --- polygon / polygon (AABBs are polygons here) ----------------------------------------------

def _edge(poly: Pts, i: int) -> tuple[float, float]:
    """Outward normal (unnormalised: exact for dyadic input) of edge ``i`` of a CCW outline."""
    x0, y0 = poly[i]
    x1, y1 = poly[(i + 1) % len(poly)]
    return y1 - y0, x0 - x1


def _axes(pa: Pts, pb: Pts) -> list[tuple[int, int]]:
    """The edges ``(0 for A / 1 for B, index)`` whose normals are the SAT axes.

    An edge scaled away to nothing gives no axis; an axis equal or opposite to an earlier one
    (a box's opposite sides) adds nothing, since both directions of every axis are tried.
    """
    edges = []
    seen: set[tuple[float, float]] = set()
    for which, poly in enumerate((pa, pb)):
        for i in range(len(poly)):
            ux, uy = _edge(poly, i)
            if (ux == 0.0 and uy == 0.0) or (ux, uy) in seen or (-ux, -uy) in seen:
                continue
            seen.add((ux, uy))
            edges.append((which, i))
    return edges


def _extent(poly: Pts, ux: float, uy: float) -> tuple[float, float]:
    lo = hi = ux * poly[0][0] + uy * poly[0][1]
    for x, y in poly:
        p = ux * x + uy * y
        if p < lo:
            lo = p
        elif p > hi:
            hi = p
    return lo, hi


def polygon_polygon(
    pa: Pts, lb: Pts, dx: float, dy: float, off: Offset, size: float
) -> Res | None:
    """Convex CCW outline A at the origin and B (outline ``lb`` about its own origin) at (dx, dy).
    Two outlines of two points (segments) have no interior between them: never a contact."""
    if len(pa) == 2 and len(lb) == 2:
        return None
    edges = _axes(pa, lb)
    # Each axis times 2**-k (exact): its larger component in [0.5, 1), so that a very short edge's
    # products with small coordinates do not underflow. No decision or result bit changes.
    raw = [_edge(lb if which else pa, i) for which, i in edges]
    ks = [math.frexp(max(abs(ux), abs(uy)))[1] for ux, uy in raw]
    axes = [(math.ldexp(ux, -k), math.ldexp(uy, -k)) for (ux, uy), k in zip(raw, ks, strict=True)]
    mag = size + abs(dx) + abs(dy)
    overlaps = []  # per axis: how far B must move forward (+u) and backward (-u), times |u|
    borderline = False
    for ux, uy in axes:
        amin, amax = _extent(pa, ux, uy)
        bmin, bmax = _extent(lb, ux, uy)
        ud = ux * dx + uy * dy
        fwd, bwd = (amax - bmin) - ud, (bmax - amin) + ud
        least = min(fwd, bwd)
        tol = BAND * (abs(ux) + abs(uy)) * mag
        if least < -tol:
            return None  # a separating axis, clear of rounding
        if least <= tol:
            borderline = True
        overlaps.append((fwd, bwd))
    if not axes:
        return None  # both shapes vanish at this scale: two points apart
    if borderline:
        exact = _polygon_polygon_exact(pa, lb, off, edges, ks)
        if exact is None:
            return None  # a separating axis (touching counts as separated)
        overlaps = exact
    cands: list[tuple[float, float, float]] = []
    for (ux, uy), (fwd, bwd) in zip(axes, overlaps, strict=True):
        ln = math.hypot(ux, uy)
        nx, ny = ux / ln, uy / ln
        cands.append((max(fwd / ln, TINY), nx, ny))
        cands.append((max(bwd / ln, TINY), -nx, -ny))
    depth, nx, ny = pick(cands, size)
    pb = [(x + dx, y + dy) for x, y in lb]
    px, py = overlap_point(pa, pb, nx, ny, depth, size)
    return nx, ny, depth, px, py


def _polygon_polygon_exact(
    pa: Pts, lb: Pts, off: Offset, edges: list[tuple[int, int]], ks: list[int]
) -> list[tuple[float, float]] | None:
    """The SAT on exact integers: ``None`` if separated or touching, else the overlaps along the
    axes of ``edges``, in the units of those axes scaled by ``2**-ks``. Every edge is tested, also
    those whose float axis was dropped as a repeat (rounding can make nearly parallel edges look
    exactly parallel)."""
    exact = polygon_polygon_exact(pa, lb, off)
    if exact is None:
        return None
    found, u = exact
    return [(float_approx(found[edge][0], u - k), float_approx(found[edge][1], u - k))
            for edge, k in zip(edges, ks, strict=True)]


# Relative tolerance (times the pair's size) of the inside tests of the contact point: a vertex
# within rounding of the other outline counts as inside it.
POINT_TOL = 1e-12


def _inside(poly: Pts, x: float, y: float, tol: float) -> bool:
    """(x, y) in the closed convex CCW polygon, allowing ``tol`` (relative) of rounding. An outline
    of two points is a segment: on its line and between its ends."""
    n = len(poly)
    if n == 2:
        (x0, y0), (x1, y1) = poly
        ex, ey = x1 - x0, y1 - y0
        ln = math.hypot(ex, ey)
        along = ex * (x - x0) + ey * (y - y0)
        if not -tol * ln <= along <= ex * ex + ey * ey + tol * ln:
            return False
    for i in range(n):
        x0, y0 = poly[i]
        x1, y1 = poly[(i + 1) % n]
        ex, ey = x1 - x0, y1 - y0
        if ex * (y - y0) - ey * (x - x0) < -tol * math.hypot(ex, ey):
            return False
    return True


def overlap_point(pa: Pts, pb: Pts, nx: float, ny: float, depth: float, size: float) -> tuple[float, float]:
    """A point of the intersection of two overlapping convex polygons (or a polygon and a segment,
    an outline of two points).

    The vertices of A ∩ B are A's vertices inside B, B's vertices inside A and the crossings of
    their edges; their mean is a convex combination, so it lies in A ∩ B.
    """
    tol = POINT_TOL * size
    sx = sy = 0.0
    count = 0
    for x, y in pa:
        if _inside(pb, x, y, tol):
            sx += x
            sy += y
            count += 1
    for x, y in pb:
        if _inside(pa, x, y, tol):
            sx += x
            sy += y
            count += 1
    na, nb = len(pa), len(pb)
    for i in range(na):
        px, py = pa[i]
        rx, ry = pa[(i + 1) % na][0] - px, pa[(i + 1) % na][1] - py
        for j in range(nb):
            qx, qy = pb[j]
            sx_, sy_ = pb[(j + 1) % nb][0] - qx, pb[(j + 1) % nb][1] - qy
            den = rx * sy_ - ry * sx_
            if den == 0.0:
                continue
            wx, wy = qx - px, qy - py
            t = (wx * sy_ - wy * sx_) / den
            u = (wx * ry - wy * rx) / den
            if 0.0 <= t <= 1.0 and 0.0 <= u <= 1.0:
                sx += px + t * rx
                sy += py + t * ry
                count += 1
    if count:
        return sx / count, sy / count
    # Rounding hid every vertex (only possible in near-degenerate cases): take the middle of the
    # penetration segment from B's deepest vertex.
    bx, by = min(pb, key=lambda p: p[0] * nx + p[1] * ny)
    return bx + nx * depth * 0.5, by + ny * depth * 0.5
