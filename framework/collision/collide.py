"""Pairwise overlap tests with contact normal, depth and point, for every pair of shape kinds.

The overlap decision is made on exact-as-possible quantities (unnormalised edge normals, squared
distances scaled by powers of two), so "touching is not a collision" holds exactly on integer and
dyadic coordinates; only the winning axis is normalised afterwards.

Depth is the penetration depth, i.e. the distance from the origin to the boundary of the Minkowski
difference A - B. Its faces are A's faces and B's faces turned around, so for boxes and polygons
the shortest push-out is found among those face normals: along an axis ``n`` B must move
``max(A.n) - min(B.n)`` forward, or ``max(B.n) - min(A.n)`` backward (the full push-out, also for a
shape contained in the other, not the overlap of the two shadows).
"""

from __future__ import annotations

import math

from ..shapes import AABB, Circle, Polygon, Shape
from .placement import check_shape, outline, pose
from .results import Contact, Vec2
from .tiebreak import pick

__all__ = ["collide"]

Pts = list[tuple[float, float]]


def collide(shape_a: Shape, transform_a: object, shape_b: Shape, transform_b: object) -> Contact | None:
    """Contact of B against A, or ``None`` unless their interiors overlap (touching is no contact).

    The normal points from A toward B; moving B by ``normal * depth`` leaves them touching.
    """
    check_shape("shape_a", shape_a)
    check_shape("shape_b", shape_b)
    ax, ay, ar = pose("transform_a", transform_a)
    bx, by, br = pose("transform_b", transform_b)
    # Work relative to A's position: B's offset is the only large-magnitude subtraction.
    dx, dy = bx - ax, by - ay
    size = shape_a.bounding_radius + shape_b.bounding_radius
    if isinstance(shape_a, Circle):
        if isinstance(shape_b, Circle):
            res = circle_circle(0.0, 0.0, shape_a.radius, dx, dy, shape_b.radius)
        else:
            # Computed as B against A, with the normal turned around to point from A to B.
            res = polygon_circle(
                outline(shape_b, dx, dy, br), 0.0, 0.0, shape_a.radius, size, flip=True
            )
    elif isinstance(shape_b, Circle):
        res = polygon_circle(outline(shape_a, 0.0, 0.0, ar), dx, dy, shape_b.radius, size)
    else:
        res = polygon_polygon(outline(shape_a, 0.0, 0.0, ar), outline(shape_b, dx, dy, br), size)
    if res is None:
        return None
    nx, ny, depth, px, py = res
    # "+ 0.0" turns a -0.0 component into 0.0, so normals compare and print cleanly.
    return Contact(Vec2(nx + 0.0, ny + 0.0), depth, Vec2(px + ax, py + ay))


# --- circle / circle -------------------------------------------------------------------------

def circle_circle(
    ax: float, ay: float, ra: float, bx: float, by: float, rb: float
) -> tuple[float, float, float, float, float] | None:
    """Circles at (ax, ay) and (bx, by): ``(nx, ny, depth, px, py)`` or ``None``."""
    dx, dy = bx - ax, by - ay
    rsum = ra + rb
    # Compare squared lengths after scaling by a power of two (exact), so that neither huge nor
    # tiny radii overflow or underflow, and integer touching stays exactly touching.
    k = math.frexp(max(abs(dx), abs(dy), rsum))[1]
    sx, sy, sr = math.ldexp(dx, -k), math.ldexp(dy, -k), math.ldexp(rsum, -k)
    if sx * sx + sy * sy >= sr * sr:
        return None
    dist = math.hypot(dx, dy)
    if dist > 0.0:
        nx, ny = dx / dist, dy / dist
    else:  # coincident centres: the direction is undefined, push up
        nx, ny = 0.0, 1.0
    depth = rsum - dist
    # The overlap meets the centre line in [lo, hi] (distances from A's centre along n).
    lo = max(-ra, dist - rb)
    hi = min(ra, dist + rb)
    mid = 0.5 * (lo + hi)
    return nx, ny, depth, ax + nx * mid, ay + ny * mid


# --- polygon / circle ------------------------------------------------------------------------

def polygon_circle(
    poly: Pts, cx: float, cy: float, r: float, size: float, flip: bool = False
) -> tuple[float, float, float, float, float] | None:
    """Convex CCW polygon A against circle B at (cx, cy): ``(nx, ny, depth, px, py)`` or ``None``.

    With ``flip`` the normal points from the circle to the polygon (the circle is shape A).
    """
    f = -1.0 if flip else 1.0
    n = len(poly)
    seps = []  # unnormalised signed distances of the centre outside each face
    inside = True
    for i in range(n):
        x0, y0 = poly[i]
        x1, y1 = poly[(i + 1) % n]
        ex, ey = x1 - x0, y1 - y0
        s = ey * (cx - x0) - ex * (cy - y0)  # outward normal (ey, -ex) of a CCW outline
        seps.append(s)
        if s > 0.0:
            inside = False
    if inside:
        # Centre inside (or on the boundary): push out through the nearest face, plus the radius.
        cands = []
        for i in range(n):
            x0, y0 = poly[i]
            x1, y1 = poly[(i + 1) % n]
            ex, ey = x1 - x0, y1 - y0
            ln = math.hypot(ex, ey)
            cands.append((r - seps[i] / ln, f * ey / ln, -f * ex / ln))
        depth, nx, ny = pick(cands, size)
        return nx, ny, depth, cx, cy
    # Centre outside: the closest point of the polygon is on a face whose region holds the
    # centre (s > 0 and the projection falls within the edge), or else it is a vertex.
    for i in range(n):
        s = seps[i]
        if s <= 0.0:
            continue
        x0, y0 = poly[i]
        x1, y1 = poly[(i + 1) % n]
        ex, ey = x1 - x0, y1 - y0
        e2 = ex * ex + ey * ey
        t = (cx - x0) * ex + (cy - y0) * ey
        if 0.0 <= t <= e2:
            # distance = s / |e|; compare s^2 < r^2 |e|^2 after an exact power-of-two scaling.
            k = math.frexp(max(s, r * math.sqrt(e2)))[1]
            ss, sr = math.ldexp(s, -k), math.ldexp(r, -k)
            if ss * ss >= sr * sr * e2:
                return None
            ln = math.sqrt(e2)
            nx, ny = ey / ln, -ex / ln
            dist = s / ln
            # Closest point on the face, found from the centre (no division by e2 needed).
            return f * nx, f * ny, r - dist, cx - nx * dist, cy - ny * dist
    best = None
    for vx, vy in poly:
        ddx, ddy = cx - vx, cy - vy
        k = math.frexp(max(abs(ddx), abs(ddy), r))[1]
        sx, sy, sr = math.ldexp(ddx, -k), math.ldexp(ddy, -k), math.ldexp(r, -k)
        d2 = sx * sx + sy * sy
        if best is None or d2 < best[0]:
            best = (d2, sr * sr, vx, vy, ddx, ddy)
    assert best is not None
    d2, r2, vx, vy, ddx, ddy = best
    if d2 >= r2:
        return None
    dist = math.hypot(ddx, ddy)
    return f * ddx / dist, f * ddy / dist, r - dist, vx, vy


# --- polygon / polygon (AABBs are polygons here) ----------------------------------------------

def polygon_polygon(pa: Pts, pb: Pts, size: float) -> tuple[float, float, float, float, float] | None:
    """Convex CCW outlines A and B (same local frame): ``(nx, ny, depth, px, py)`` or ``None``."""
    cands: list[tuple[float, float, float]] = []
    for poly in (pa, pb):
        n = len(poly)
        for i in range(n):
            x0, y0 = poly[i]
            x1, y1 = poly[(i + 1) % n]
            # Unnormalised axis (outward normal of this edge); exact for dyadic input.
            ux, uy = y1 - y0, x0 - x1
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
            if amax <= bmin or bmax <= amin:
                return None  # a separating axis (touching counts as separated)
            ln = math.hypot(ux, uy)
            nx, ny = ux / ln, uy / ln
            cands.append(((amax - bmin) / ln, nx, ny))
            cands.append(((bmax - amin) / ln, -nx, -ny))
    depth, nx, ny = pick(cands, size)
    px, py = overlap_point(pa, pb, nx, ny, depth, size)
    return nx, ny, depth, px, py


def _inside(poly: Pts, x: float, y: float, tol: float) -> bool:
    """(x, y) in the closed convex CCW polygon, allowing ``tol`` (relative) of rounding."""
    n = len(poly)
    for i in range(n):
        x0, y0 = poly[i]
        x1, y1 = poly[(i + 1) % n]
        ex, ey = x1 - x0, y1 - y0
        if ex * (y - y0) - ey * (x - x0) < -tol * math.hypot(ex, ey):
            return False
    return True


def overlap_point(pa: Pts, pb: Pts, nx: float, ny: float, depth: float, size: float) -> tuple[float, float]:
    """A point of the intersection of two overlapping convex polygons.

    The vertices of A ∩ B are A's vertices inside B, B's vertices inside A and the crossings of
    their edges; their mean is a convex combination, so it lies in A ∩ B.
    """
    tol = 1e-12 * size
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
