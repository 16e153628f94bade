"""Batch kernel for convex polygon / convex polygon pairs (boxes paired with polygons included).

Separating axes, vectorised over pairs: the axes are the unnormalised outward edge normals of A
and of B, ``[C, P]`` with ``C = Ka + Kb``; every vertex of both outlines is projected on every
axis at once (``[C, K, P]``), with B about its own origin and ``u . d`` added, exactly the scalar
code's products and comparisons. Rows within the band of touching on some axis are decided
exactly (:mod:`framework.collision.batch_exact`). Only the overlapping rows go on to normalise
their axes, build the ``2 C`` push-out candidates and apply the tie-break rule.

Contact point: the mean of the vertices of A ∩ B, built as the scalar code builds it: A's vertices
inside B and B's vertices inside A (``[Ka, Kb, P]`` edge tests) and the crossings of every edge
of A with every edge of B (``[Ka, Kb, P]``), each included by the same closed tests. The mean
is a convex combination of points of A ∩ B, so it lies in the overlap.
"""

from __future__ import annotations

import numpy as np

from ..validation import InvalidValue
from .batch_common import (
    BIG,
    F64,
    ContactArrays,
    cols,
    columns_of,
    edge_mask,
    edges,
    extent,
    finish,
    first_min,
    frame,
    norm,
    outline_rows,
    pick,
    take,
    vertex_mask,
)
from .batch_exact import BAND, TINY, polygon_polygon_exact

__all__ = ["overlap_polygon_polygon", "polygon_polygon"]

# Relative tolerance of the inside test of the contact point (times the pair's size), as in
# ``collide.overlap_point``.
POINT_TOL = 1e-12


def _frame(ax, ay, averts, acount, bx, by, bverts, bcount):
    """Both outlines ``[K, P]`` about their own origins and B's offset, in A's scaled frame."""
    avx, avy, acount = outline_rows(averts, acount, "averts")
    bvx, bvy, bcount = outline_rows(bverts, bcount, "bverts")
    p = avx.shape[1]
    if bvx.shape[1] != p:
        raise InvalidValue(f"averts has {p} rows but bverts has {bvx.shape[1]}")
    ax, ay, bx, by = columns_of(p, ax, ay, bx, by)
    if p == 0:
        z = np.zeros(0)
        return avx, avy, acount, bvx, bvy, bcount, ax, ay, bx, by, z, z, np.zeros(0, dtype=np.intp), z
    dx, dy, k = frame(ax, ay, bx, by, np.maximum(extent(avx, avy), extent(bvx, bvy)))
    avx, avy, bvx, bvy = (np.ldexp(v, -k) for v in (avx, avy, bvx, bvy))
    # The bounding radii summed (fine for tolerances), in the scaled frame.
    size = np.sqrt((avx * avx + avy * avy).max(axis=0)) + np.sqrt((bvx * bvx + bvy * bvy).max(axis=0))
    return avx, avy, acount, bvx, bvy, bcount, ax, ay, bx, by, dx, dy, k, size


def _extent(ux: np.ndarray, uy: np.ndarray, vx: np.ndarray, vy: np.ndarray):
    """Min and max of every vertex ``[K, P]`` projected on every axis ``[C, P]``: ``[C, P]``."""
    # A loop over the few vertices keeps the temporaries small (3x faster than [C, K, P]).
    lo = ux * vx[0]
    lo += uy * vy[0]
    hi = lo.copy()
    for j in range(1, vx.shape[0]):
        proj = ux * vx[j]
        proj += uy * vy[j]
        np.minimum(lo, proj, out=lo)
        np.maximum(hi, proj, out=hi)
    return lo, hi


def _sat(avx, avy, acount, bvx, bvy, bcount, ax, ay, bx, by, dx, dy, k, size):
    """The separating-axis decision of every row, and the per-axis overlaps ``[C, P]``.

    A projection is ``u . local + u . offset``: B is projected about its own origin and
    ``ud = u . d`` added, as in the scalar code. Rows within the band of touching on some axis
    are decided exactly; their overlaps are then the exact ones.
    """
    # Unnormalised outward normal (ey, -ex) of each edge of a CCW outline; exact for dyadic input.
    ux = np.concatenate((edges(avy), edges(bvy)))
    uy = -np.concatenate((edges(avx), edges(bvx)))
    valid = edge_mask(ux, uy)
    amin, amax = _extent(ux, uy, avx, avy)
    bmin, bmax = _extent(ux, uy, bvx, bvy)
    ud = ux * dx + uy * dy
    # How far B must move forward (+u) and backward (-u), times |u|.
    fwd = (amax - bmin) - ud
    bwd = (bmax - amin) + ud
    least = np.minimum(fwd, bwd)
    tol = BAND * (np.abs(ux) + np.abs(uy)) * (size + np.abs(dx) + np.abs(dy))
    apart = ((least < -tol) & valid).any(axis=0) | ~valid.any(axis=0)
    border = ((least <= tol) & valid).any(axis=0) & ~apart
    hit = ~apart & ~border
    for i in np.flatnonzero(border):
        pa = list(zip(avx[: acount[i], i].tolist(), avy[: acount[i], i].tolist(), strict=True))
        lb = list(zip(bvx[: bcount[i], i].tolist(), bvy[: bcount[i], i].tolist(), strict=True))
        exact = polygon_polygon_exact(pa, lb, (ax[i], ay[i], bx[i], by[i], int(k[i])))
        if exact is not None:
            hit[i] = True
            slots = np.flatnonzero(valid[:, i])
            fwd[slots, i], bwd[slots, i] = np.array(exact).T
    return hit, (ux, uy, valid, fwd, bwd)


def overlap_polygon_polygon(ax, ay, averts, acount, bx, by, bverts, bcount) -> np.ndarray:
    """``hit`` of :func:`polygon_polygon` only."""
    fr = _frame(ax, ay, averts, acount, bx, by, bverts, bcount)
    if fr[6].shape[0] == 0:
        return np.zeros(0, dtype=bool)
    return _sat(*fr)[0]


def polygon_polygon(ax, ay, averts, acount, bx, by, bverts, bcount, size=None) -> ContactArrays:
    """Convex polygons A and B: hitbox origins (ax, ay), (bx, by) ``[P]`` and outlines relative
    to them, ``averts [P, Ka, 2]`` / ``bverts [P, Kb, 2]`` with ``acount`` / ``bcount`` vertices,
    as :func:`~framework.collision.batch.outlines` gives them (gathered per pair).

    ``size`` (optional ``[P]``): the pair's bounding radii summed (the scale of the tie-break and
    contact-point tolerances); by default it is measured from the outlines.
    """
    fr = _frame(ax, ay, averts, acount, bx, by, bverts, bcount)
    avx, avy, acount, bvx, bvy, bcount, ax, ay, bx, by, dx, dy, k, sz = fr
    p = ax.shape[0]
    if p == 0:
        return finish(np.zeros(0, dtype=bool), *([np.zeros(0)] * 5), k, ax, ay)
    if size is not None:
        sz = np.ldexp(columns_of(p, size)[0], -k)
    hit, axes = _sat(*fr[:-1], sz)
    h = np.flatnonzero(hit)
    ux, uy, valid, fwd, bwd, avx, avy, bvx, bvy = (cols(a, h) for a in (*axes, avx, avy, bvx, bvy))
    acount, bcount = acount[h], bcount[h]
    dx, dy, sz = dx[h], dy[h], sz[h]
    absent = (~valid).astype(F64)
    ln = norm(ux, uy) + absent  # 1 on padding axes
    # Candidates in the scalar code's order: per axis, forward then backward ([C, 2, H]).
    c, n = ux.shape
    cdepth, cnx, cny = np.empty((c, 2, n)), np.empty((c, 2, n)), np.empty((c, 2, n))
    np.divide(ux, ln, out=cnx[:, 0])
    np.divide(uy, ln, out=cny[:, 0])
    np.negative(cnx[:, 0], out=cnx[:, 1])
    np.negative(cny[:, 0], out=cny[:, 1])
    absent *= BIG
    for j, over in enumerate((fwd, bwd)):
        d = cdepth[:, j]
        np.divide(over, ln, out=d)
        np.maximum(d, TINY, out=d)
        d += absent
    depth, nx, ny = pick(*(a.reshape(2 * c, n) for a in (cdepth, cnx, cny)), sz)
    # The point is found with B at its offset.
    bvx, bvy = bvx + dx, bvy + dy
    px, py = overlap_point(avx, avy, acount, bvx, bvy, bcount, nx, ny, depth, sz)
    return finish(hit, nx, ny, depth, px, py, k[h], ax[h], ay[h])


def _inside(x, y, ox, oy, ex, ey, tol):
    """``[Kp, P]``: points (x, y) in the closed outlines (vertices ox, oy, edges ex, ey), with
    ``tol`` (absolute, ``[P]``) of rounding, as ``collide._inside``. Padding edges never exclude."""
    cross = ex[None] * (y[:, None] - oy[None])
    cross -= ey[None] * (x[:, None] - ox[None])
    return ~(cross < -tol * norm(ex, ey)[None]).any(axis=1)


def overlap_point(avx, avy, acount, bvx, bvy, bcount, nx, ny, depth, size):
    """Mean of the vertices of A ∩ B for overlapping outlines ``[K, P]`` (B at its offset)."""
    tol = POINT_TOL * size
    exa, eya, exb, eyb = edges(avx), edges(avy), edges(bvx), edges(bvy)
    ina = _inside(avx, avy, bvx, bvy, exb, eyb, tol) & vertex_mask(acount, avx.shape[0])
    inb = _inside(bvx, bvy, avx, avy, exa, eya, tol) & vertex_mask(bcount, bvx.shape[0])
    ina, inb = ina.astype(F64), inb.astype(F64)
    sx = (avx * ina).sum(axis=0) + (bvx * inb).sum(axis=0)
    sy = (avy * ina).sum(axis=0) + (bvy * inb).sum(axis=0)
    count = ina.sum(axis=0) + inb.sum(axis=0)
    # Crossings of A's edge i (p + t r) with B's edge j (q + u s), t and u in [0, 1]: [Ka, Kb, P].
    # Parallel and padding (zero) edges have den == 0 exactly and are skipped, as in the scalar code.
    rx, ry = exa[:, None], eya[:, None]
    sx_, sy_ = exb[None], eyb[None]
    den = rx * sy_ - ry * sx_
    wx = bvx[None] - avx[:, None]
    wy = bvy[None] - avy[:, None]
    parallel = den == 0.0
    den += parallel  # 1 where 0: those are skipped
    t = (wx * sy_ - wy * sx_) / den
    u = (wx * ry - wy * rx) / den
    crossing = ((t >= 0.0) & (t <= 1.0) & (u >= 0.0) & (u <= 1.0) & ~parallel).astype(F64)
    t = np.minimum(np.maximum(t, 0.0), 1.0)  # unchanged where crossing; finite elsewhere
    sx += ((avx[:, None] + t * rx) * crossing).sum(axis=(0, 1))
    sy += ((avy[:, None] + t * ry) * crossing).sum(axis=(0, 1))
    count += crossing.sum(axis=(0, 1))
    found = count > 0
    c = np.maximum(count, 1.0)
    px, py = sx / c, sy / c
    if not found.all():
        # Rounding hid every vertex (near-degenerate only): the middle of the penetration segment
        # from B's deepest vertex.
        m = np.flatnonzero(~found)
        mx, my = cols(bvx, m), cols(bvy, m)
        j = first_min(mx * nx[m] + my * ny[m])
        half = depth[m] * 0.5
        px[m] = take(mx, j) + nx[m] * half
        py[m] = take(my, j) + ny[m] * half
    return px, py
