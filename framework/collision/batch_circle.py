"""Batch kernels for pairs with a circle: circle / circle and polygon (or box) / circle.

Each step mirrors :mod:`framework.collision.collide` operation for operation (same local origin,
same expressions in the same order), so the overlap decisions are the same bit for bit and the
normals, depths and points agree to rounding.
"""

from __future__ import annotations

import numpy as np

from .batch_common import (
    F64,
    ContactArrays,
    columns,
    columns_of,
    edge_mask,
    edges,
    outline_rows,
    pick,
    radii,
    scatter,
)

__all__ = ["circle_circle", "overlap_circle_circle", "overlap_polygon_circle", "polygon_circle"]


# --- circle / circle -------------------------------------------------------------------------

def _circles_overlap(dx: np.ndarray, dy: np.ndarray, rsum: np.ndarray) -> np.ndarray:
    # |d| < ra + rb on squares scaled by a power of two (exact), as in the scalar code.
    k = np.frexp(np.maximum(np.maximum(np.abs(dx), np.abs(dy)), rsum))[1]
    sx, sy, sr = np.ldexp(dx, -k), np.ldexp(dy, -k), np.ldexp(rsum, -k)
    return sx * sx + sy * sy < sr * sr


def overlap_circle_circle(ax, ay, ar, bx, by, br) -> np.ndarray:
    """``hit`` of :func:`circle_circle` only."""
    ax, ay, ar, bx, by, br = columns(ax, ay, ar, bx, by, br)
    return _circles_overlap(bx - ax, by - ay, ar + br)


def circle_circle(ax, ay, ar, bx, by, br) -> ContactArrays:
    """Circles of radius ``ar`` at (ax, ay) (A) and ``br`` at (bx, by) (B), all ``[P]``."""
    ax, ay, ar, bx, by, br = columns(ax, ay, ar, bx, by, br)
    dx, dy = bx - ax, by - ay
    rsum = ar + br
    hit = _circles_overlap(dx, dy, rsum)
    if not hit.any():
        return scatter(hit, 0.0, 0.0, 0.0, 0.0, 0.0)
    dx, dy, ar, br, rsum = dx[hit], dy[hit], ar[hit], br[hit], rsum[hit]
    dist = np.hypot(dx, dy)
    apart = dist > 0.0
    safe = np.where(apart, dist, 1.0)
    # Coincident centres: the direction is undefined, push up.
    nx = np.where(apart, dx / safe, 0.0)
    ny = np.where(apart, dy / safe, 1.0)
    depth = rsum - dist
    # The overlap meets the centre line in [lo, hi] (distances from A's centre along n).
    mid = 0.5 * (np.maximum(-ar, dist - br) + np.minimum(ar, dist + br))
    px = (0.0 + nx * mid) + ax[hit]
    py = (0.0 + ny * mid) + ay[hit]
    return scatter(hit, nx, ny, depth, px, py)


# --- polygon / circle ------------------------------------------------------------------------

def _polygon_circle_frame(ax, ay, averts, acount, bx, by, br, flip):
    """Polygon and circle in the local frame of shape A of the pair (the scalar code's frame)."""
    vx, vy, count = outline_rows(averts, acount, "polygon vertices")
    p = vx.shape[0]
    ax, ay, bx, by, r = columns_of(p, ax, ay, bx, by, br)
    if flip:
        # The circle is shape A: it is the origin, the polygon sits at its offset from it.
        ox, oy = bx, by
        vx = vx + (ax - bx)[:, None]
        vy = vy + (ay - by)[:, None]
        cx = np.zeros(p, dtype=F64)
        cy = np.zeros(p, dtype=F64)
    else:
        ox, oy = ax, ay
        vx = vx + 0.0
        vy = vy + 0.0
        cx, cy = bx - ax, by - ay
    return vx, vy, count, cx, cy, r, ox, oy


def _polygon_circle_decide(vx, vy, cx, cy, r):
    """The scalar code's branch structure, on every row at once.

    Returns the per-row arrays needed later and the decision: the centre is inside (every
    unnormalised face distance ``s <= 0``), or in the region of the first face with ``s > 0`` whose
    projection falls on the edge, or else nearest a vertex.
    """
    ex, ey = edges(vx), edges(vy)
    wx = cx[:, None] - vx  # centre relative to each vertex (= to each edge's start)
    wy = cy[:, None] - vy
    s = ey * wx - ex * wy  # outward normal (ey, -ex) of a CCW outline; 0 on padding edges
    out = s > 0.0
    inside = ~out.any(axis=1)
    e2 = ex * ex + ey * ey
    t = wx * ex + wy * ey
    face = out & (t >= 0.0) & (t <= e2)
    has_face = face.any(axis=1)
    rows = np.arange(vx.shape[0])
    fi = face.argmax(axis=1)  # the first such face, as the scalar loop returns on the first
    fs, fe2 = s[rows, fi], e2[rows, fi]
    # distance = s / |e|: s^2 < r^2 |e|^2 after an exact power-of-two scaling.
    k = np.frexp(np.maximum(fs, r * np.sqrt(fe2)))[1]
    ss, sr = np.ldexp(fs, -k), np.ldexp(r, -k)
    face_hit = ss * ss < sr * sr * fe2
    vi, vert_hit = _nearest_vertex(wx, wy, r)
    hit = inside | np.where(has_face, face_hit, vert_hit)
    return hit, inside, has_face, fi, vi, ex, ey, s, wx, wy


def _nearest_vertex(wx: np.ndarray, wy: np.ndarray, r: np.ndarray):
    """Index of the vertex the scalar code picks, and whether the circle reaches past it.

    Mirrors ``collide.polygon_circle``: each vertex's squares are scaled by its own power of two
    and the smallest scaled value wins (padding slots repeat the last vertex, so never win first).
    """
    k = np.frexp(np.maximum(np.maximum(np.abs(wx), np.abs(wy)), r[:, None]))[1]
    sx, sy = np.ldexp(wx, -k), np.ldexp(wy, -k)
    d2 = sx * sx + sy * sy
    vi = d2.argmin(axis=1)
    rows = np.arange(wx.shape[0])
    sr = np.ldexp(r, -k[rows, vi])
    return vi, d2[rows, vi] < sr * sr


def overlap_polygon_circle(ax, ay, averts, acount, bx, by, br, flip=False) -> np.ndarray:
    """``hit`` of :func:`polygon_circle` only."""
    vx, vy, _, cx, cy, r, _, _ = _polygon_circle_frame(ax, ay, averts, acount, bx, by, br, flip)
    return _polygon_circle_decide(vx, vy, cx, cy, r)[0]


def polygon_circle(ax, ay, averts, acount, bx, by, br, flip=False, size=None) -> ContactArrays:
    """Convex polygons (hitbox origins (ax, ay), outlines ``averts [P, K, 2]`` with ``acount``
    vertices, as :func:`~framework.collision.batch.outlines` gives them) against circles of
    radius ``br`` at (bx, by).

    Normals point from the polygon to the circle; with ``flip`` the circle is shape A of the pair
    (``collide(circle, ..., polygon, ...)``) and normals point from the circle to the polygon.
    ``size`` (optional ``[P]``): the pair's bounding radii summed, the scale of the tie-break
    tolerance; by default it is measured from the outlines.
    """
    vx, vy, count, cx, cy, r, ox, oy = _polygon_circle_frame(ax, ay, averts, acount, bx, by, br, flip)
    p = vx.shape[0]
    hit, inside, has_face, fi, vi, ex, ey, s, wx, wy = _polygon_circle_decide(vx, vy, cx, cy, r)
    f = -1.0 if flip else 1.0
    nx = np.zeros(p, dtype=F64)
    ny = np.zeros(p, dtype=F64)
    depth = np.zeros(p, dtype=F64)
    px = np.zeros(p, dtype=F64)
    py = np.zeros(p, dtype=F64)

    # Centre inside (or on the boundary): out through the nearest face, plus the radius.
    m = hit & inside
    if m.any():
        if size is None:
            sz = radii(vx[m], vy[m]) + r[m]
        else:
            sz = columns_of(p, size)[0][m]
        mex, mey = ex[m], ey[m]
        valid = edge_mask(count[m], vx.shape[1])
        ln = np.where(valid, np.hypot(mex, mey), 1.0)
        cd = np.where(valid, r[m][:, None] - s[m] / ln, np.inf)
        cnx = f * mey / ln
        cny = -f * mex / ln
        depth[m], nx[m], ny[m] = pick(cd, cnx, cny, sz)
        px[m], py[m] = cx[m], cy[m]

    # Centre in a face's region: the closest point is on that face.
    m = hit & ~inside & has_face
    if m.any():
        rows, i = np.flatnonzero(m), fi[m]
        fex, fey = ex[rows, i], ey[rows, i]
        ln = np.sqrt(fex * fex + fey * fey)
        unx, uny = fey / ln, -fex / ln
        dist = s[rows, i] / ln
        nx[m], ny[m] = f * unx, f * uny
        depth[m] = r[m] - dist
        px[m] = cx[m] - unx * dist
        py[m] = cy[m] - uny * dist

    # Otherwise the closest point is a vertex.
    m = hit & ~inside & ~has_face
    if m.any():
        rows, i = np.flatnonzero(m), vi[m]
        ddx, ddy = wx[rows, i], wy[rows, i]
        dist = np.hypot(ddx, ddy)
        safe = np.where(dist > 0.0, dist, 1.0)
        nx[m] = np.where(dist > 0.0, f * ddx / safe, 0.0)
        ny[m] = np.where(dist > 0.0, f * ddy / safe, f)
        depth[m] = r[m] - dist
        px[m], py[m] = vx[rows, i], vy[rows, i]

    return scatter(hit, nx[hit], ny[hit], depth[hit], px[hit] + ox[hit], py[hit] + oy[hit])
