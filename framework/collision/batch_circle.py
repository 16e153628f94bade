"""Batch kernels for pairs with a circle: circle / circle and polygon (or box) / circle.

Each step mirrors :mod:`framework.collision.collide` operation for operation (same scaled local
frame, same expressions in the same order, same band around touching); the rows inside the band
are decided exactly by :mod:`framework.collision.exact`.
"""

from __future__ import annotations

import math

import numpy as np

from .batch_common import (
    BIG,
    F64,
    ContactArrays,
    cols,
    columns,
    columns_of,
    edge_mask,
    edges,
    extent,
    finish,
    first,
    first_min,
    frame,
    norm,
    outline_rows,
    pick,
    take,
)
from .exact import BAND, TINY, Offset, circle_circle_exact, float_rounded, polygon_circle_exact, vertex_contact
from .tiebreak import pick as pick_one

__all__ = ["circle_circle", "polygon_circle"]


# --- circle / circle -------------------------------------------------------------------------

def circle_circle(ax, ay, ar, bx, by, br, exact: bool = True) -> ContactArrays:
    """Circles of radius ``ar`` at (ax, ay) (A) and ``br`` at (bx, by) (B), all ``[P]``.
    ``exact=False``: pairs within rounding of touching count as apart (for the response)."""
    ax, ay, ar, bx, by, br = columns(ax, ay, ar, bx, by, br)
    dx, dy, k = frame(ax, ay, bx, by, np.maximum(ar, br))
    ra, rb = np.ldexp(ar, -k), np.ldexp(br, -k)
    rsum = ra + rb
    d2, r2 = dx * dx + dy * dy, rsum * rsum
    band = BAND * (d2 + r2)
    hit = d2 <= r2 - band
    # Too close to touching for floats: decide on the exact |d|^2 < (ra + rb)^2.
    near = np.flatnonzero((d2 > r2 - band) & (d2 < r2 + band)) if exact else np.zeros(0, dtype=np.int64)
    num = np.zeros(near.size, dtype=F64)
    for j, i in enumerate(near):
        excess = circle_circle_exact((ax[i], ay[i], bx[i], by[i], int(k[i])), ra[i], rb[i])
        if excess is not None:
            hit[i] = True
            num[j] = float_rounded(*excess)
    exact_rows = np.zeros(hit.shape, dtype=bool)
    exact_rows[near] = True
    exact_num = np.zeros(hit.shape, dtype=F64)
    exact_num[near] = num
    dx, dy, ra, rb, rsum, k = dx[hit], dy[hit], ra[hit], rb[hit], rsum[hit], k[hit]
    exact_rows, exact_num = exact_rows[hit], exact_num[hit]
    dist = np.hypot(dx, dy)
    # Near touching, the depth comes from the exact (ra + rb)^2 - |d|^2 = depth * (ra + rb + |d|).
    depth = np.where(exact_rows, np.maximum(exact_num / (rsum + dist), TINY), rsum - dist)
    apart = dist > 0.0
    safe = np.where(apart, dist, 1.0)
    # Coincident centres: the direction is undefined, push up.
    nx = np.where(apart, dx / safe, 0.0)
    ny = np.where(apart, dy / safe, 1.0)
    # The overlap meets the centre line in [lo, hi] (distances from A's centre along n).
    mid = 0.5 * (np.maximum(-ra, dist - rb) + np.minimum(ra, dist + rb))
    return finish(hit, nx, ny, depth, nx * mid, ny * mid, k, ax[hit], ay[hit])


# --- polygon / circle ------------------------------------------------------------------------

def _polygon_circle(ax, ay, averts, acount, bx, by, br, flip, size, fallback: bool):
    vx, vy, count = outline_rows(averts, acount, "polygon vertices")
    p = vx.shape[1]
    ax, ay, bx, by, r = columns_of(p, ax, ay, bx, by, br)
    if p == 0:
        z = np.zeros(0)
        return finish(np.zeros(0, dtype=bool), z, z, z, z, z, np.zeros(0, dtype=int), ax, ay)
    f = np.where(np.broadcast_to(np.asarray(flip, dtype=bool), (p,)), -1.0, 1.0)  # per row
    # The polygon's frame, whichever shape of the pair it is.
    cx, cy, k = frame(ax, ay, bx, by, np.maximum(extent(vx, vy), r))
    vx, vy, r = np.ldexp(vx, -k), np.ldexp(vy, -k), np.ldexp(r, -k)
    rp = np.sqrt((vx * vx + vy * vy).max(axis=0))  # the polygon's radius (fine for tolerances)
    size = rp + r if size is None else np.ldexp(columns_of(p, size)[0], -k)
    tol = BAND * (np.abs(cx) + np.abs(cy) + rp + r)  # on distances
    ex, ey = edges(vx), edges(vy)
    valid = edge_mask(ex, ey)
    wx, wy = cx - vx, cy - vy  # centre relative to each vertex / edge start
    s = ey * wx - ex * wy  # unnormalised distance outside each face; 0 on padding edges
    out = s > 0.0
    inside = ~out.any(axis=0) & valid.any(axis=0)  # (a polygon shrunk to a point has no faces)
    if (count == 2).any():
        # A segment (an outline of two points): on its line is inside only between its ends.
        t0, e0 = wx[0] * ex[0] + wy[0] * ey[0], ex[0] * ex[0] + ey[0] * ey[0]
        inside &= (count != 2) | ((t0 >= 0.0) & (t0 <= e0))
    # Inside (or on the boundary): out through the nearest face, plus the radius.
    absent = (~valid).astype(F64)
    ln = norm(ex, ey) + absent  # 1 on padding edges
    cdepth = (r - s / ln) + absent * BIG
    inside_clear = inside & (cdepth.min(axis=0) > tol)
    # Outside: the closest point is on the first face whose region holds the centre, or else it
    # is the nearest vertex.
    e2 = ex * ex + ey * ey
    t = wx * ex + wy * ey
    face = out & (t >= 0.0) & (t <= e2)
    has_face = face.any(axis=0)
    fi = first(face)
    vi = first_min(wx * wx + wy * wy)
    fex, fey = take(ex, fi), take(ey, fi)
    fln = np.sqrt(fex * fex + fey * fey) + ~has_face  # 1 where there is no such face
    ddx, ddy = take(wx, vi), take(wy, vi)
    dist = np.where(has_face, take(s, fi) / fln, norm(ddx, ddy))
    out_hit = ~inside & (dist > 0.0) & (dist <= r - tol)
    exact = (inside & ~inside_clear) | (~inside & ((dist == 0.0) | ((dist > r - tol) & (dist < r + tol))))
    hit = inside_clear | out_hit
    results = {}
    for i in np.flatnonzero(exact) if fallback else ():
        n = int(count[i])
        poly = list(zip(vx[:n, i].tolist(), vy[:n, i].tolist(), strict=True))
        res = _polygon_circle_exact(
            poly, (ax[i], ay[i], bx[i], by[i], int(k[i])), r[i], cx[i], cy[i], size[i], float(f[i])
        )
        if res is not None:
            hit[i] = True
            results[i] = res
    nx, ny, depth, px, py = (np.zeros(p, dtype=F64) for _ in range(5))
    m = np.flatnonzero(inside_clear)
    if m.size:
        mex, mey, mln = cols(ex, m), cols(ey, m), cols(ln, m)
        depth[m], nx[m], ny[m] = pick(cols(cdepth, m), f[m] * mey / mln, -f[m] * mex / mln, size[m])
        px[m], py[m] = cx[m], cy[m]
    m = np.flatnonzero(out_hit & has_face)
    if m.size:
        d, ln_ = dist[m], fln[m]
        unx, uny = fey[m] / ln_, -fex[m] / ln_
        nx[m], ny[m] = f[m] * unx, f[m] * uny
        depth[m] = r[m] - d
        px[m], py[m] = cx[m] - unx * d, cy[m] - uny * d
    m = np.flatnonzero(out_hit & ~has_face)
    if m.size:
        d = dist[m]  # > 0 on these rows
        nx[m], ny[m] = f[m] * ddx[m] / d, f[m] * ddy[m] / d
        depth[m] = r[m] - d
        j = vi[m]
        px[m], py[m] = vx[j, m], vy[j, m]
    for i, res in results.items():
        nx[i], ny[i], depth[i], px[i], py[i] = res
    return finish(hit, nx[hit], ny[hit], depth[hit], px[hit], py[hit], k[hit], ax[hit], ay[hit])


def _polygon_circle_exact(
    poly: list[tuple[float, float]], offset: Offset, r: float, cx: float, cy: float, size: float, f: float
) -> tuple[float, float, float, float, float] | None:
    """One row of :func:`polygon_circle` decided on exact integers (a convex CCW outline at the
    origin, the circle at the exact offset, float (cx, cy)): ``(nx, ny, depth, px, py)`` with the
    normal times ``f``, or ``None``."""
    found = polygon_circle_exact(poly, offset, r)
    if found is None:
        return None
    n, e = len(poly), found.e
    if found.case == "inside":
        # An overlap (r > 0), depth r + distance to the nearest face.
        cands = []
        for i in range(n):
            (x0, y0), (x1, y1) = poly[i], poly[(i + 1) % n]
            ex, ey = x1 - x0, y1 - y0
            ln = math.hypot(ex, ey)
            if ln > 0.0:
                cands.append((r - float_rounded(found.seps[i], 2 * e) / ln, f * ey / ln, -f * ex / ln))
        depth, nx, ny = pick_one(cands, size)
        return nx, ny, max(depth, TINY), cx, cy
    if found.case == "face":
        # depth = (r^2 |e|^2 - s^2) / (|e| (r |e| + s)).
        i = found.index
        (fx0, fy0), (fx1, fy1) = poly[i], poly[(i + 1) % n]
        fex, fey = fx1 - fx0, fy1 - fy0
        ln = math.hypot(fex, fey)
        fs = float_rounded(found.seps[i], 2 * e)
        depth = max(float_rounded(found.num, 4 * e) / (ln * (r * ln + fs)), TINY)
        nx, ny = fey / ln, -fex / ln
        dist = fs / ln
        return f * nx, f * ny, depth, cx - nx * dist, cy - ny * dist
    return vertex_contact(found, poly, r, f, float_rounded)


def polygon_circle(ax, ay, averts, acount, bx, by, br, flip=False, size=None, exact: bool = True) -> ContactArrays:
    """Convex polygons (hitbox origins (ax, ay) ``[P]``, outlines ``averts [P, K, 2]`` with
    ``acount`` vertices, as :func:`~framework.collision.batch.outlines` gives them) against circles
    of radius ``br`` at (bx, by).

    Normals point from the polygon to the circle; with ``flip`` (a bool, or one per row) the circle
    is shape A of the pair (``collide(circle, ..., polygon, ...)``) and normals point from the
    circle to the polygon.
    ``size`` (optional ``[P]``): the pair's bounding radii summed, the scale of the tie-break
    tolerance; by default it is measured from the outlines. ``exact=False``: pairs within rounding
    of touching count as apart (the response re-measuring pairs it has just pushed apart).
    """
    return _polygon_circle(ax, ay, averts, acount, bx, by, br, flip, size, fallback=exact)
