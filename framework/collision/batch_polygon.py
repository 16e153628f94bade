"""Batch kernel for convex polygon / convex polygon pairs (boxes paired with polygons included).

Separating axes, vectorised over pairs: the axes are the unnormalised outward edge normals of A
and of B, ``[P, C]`` with ``C = Ka + Kb``; every vertex of both outlines is projected on every
axis at once (``[P, C, K]``), so the decision uses exactly the scalar code's products and
comparisons. Only the pairs that overlap go on to normalise their axes, build the ``2 C``
push-out candidates and apply the tie-break rule.

Contact point: the mean of the vertices of A ∩ B, built as the scalar code builds it: A's vertices
inside B and B's vertices inside A (``[P, Ka, Kb]`` edge tests) and the crossings of every edge
of A with every edge of B (``[P, Ka, Kb]``), each included with the same closed tests. The mean
is a convex combination of points of A ∩ B, so it lies in the overlap.
"""

from __future__ import annotations

import numpy as np

from .batch_common import (
    ContactArrays,
    columns_of,
    edge_mask,
    edges,
    outline_rows,
    pick,
    radii,
    scatter,
    vertex_mask,
)

__all__ = ["overlap_polygon_polygon", "polygon_polygon"]

# Relative tolerance of the inside test of the contact point (times the pair's size), as in
# ``collide.overlap_point``.
POINT_TOL = 1e-12


def _frame(ax, ay, averts, acount, bx, by, bverts, bcount):
    """Both outlines in A's local frame (A's hitbox origin at 0), as the scalar code places them."""
    avx, avy, acount = outline_rows(averts, acount, "averts")
    bvx, bvy, bcount = outline_rows(bverts, bcount, "bverts")
    p = avx.shape[0]
    if bvx.shape[0] != p:
        raise ValueError(f"averts has {p} rows but bverts has {bvx.shape[0]}")
    ax, ay, bx, by = columns_of(p, ax, ay, bx, by)
    dx, dy = bx - ax, by - ay
    # B's vertices are its outline plus its offset from A, the one large-magnitude subtraction.
    return (avx + 0.0, avy + 0.0, acount, bvx, bvy, dx, dy, bcount, ax, ay)


def _project(ux: np.ndarray, uy: np.ndarray, vx: np.ndarray, vy: np.ndarray):
    """Min and max of every vertex projected on every axis: ``[P, C]`` each."""
    proj = ux[:, :, None] * vx[:, None, :]
    proj += uy[:, :, None] * vy[:, None, :]
    return proj.min(axis=2), proj.max(axis=2)


def _sat(avx, avy, acount, bvx, bvy, bcount):
    exa, eya, exb, eyb = edges(avx), edges(avy), edges(bvx), edges(bvy)
    # Unnormalised outward normal (ey, -ex) of each edge of a CCW outline; exact for dyadic input.
    ux = np.concatenate((eya, eyb), axis=1)
    uy = -np.concatenate((exa, exb), axis=1)
    valid = np.concatenate(
        (edge_mask(acount, avx.shape[1]), edge_mask(bcount, bvx.shape[1])), axis=1
    )
    amin, amax = _project(ux, uy, avx, avy)
    bmin, bmax = _project(ux, uy, bvx, bvy)
    # A separating axis (touching counts as separated) on any real edge.
    hit = ~(((amax <= bmin) | (bmax <= amin)) & valid).any(axis=1)
    return hit, (ux, uy, valid, amin, amax, bmin, bmax), (exa, eya, exb, eyb)


def overlap_polygon_polygon(ax, ay, averts, acount, bx, by, bverts, bcount) -> np.ndarray:
    """``hit`` of :func:`polygon_polygon` only."""
    avx, avy, acount, bvx, bvy, dx, dy, bcount, _, _ = _frame(
        ax, ay, averts, acount, bx, by, bverts, bcount
    )
    if avx.shape[0] == 0:
        return np.zeros(0, dtype=bool)
    return _sat(avx, avy, acount, bvx + dx[:, None], bvy + dy[:, None], bcount)[0]


def polygon_polygon(ax, ay, averts, acount, bx, by, bverts, bcount, size=None) -> ContactArrays:
    """Convex polygons A and B: hitbox origins (ax, ay), (bx, by) ``[P]`` and outlines relative
    to them, ``averts [P, Ka, 2]`` / ``bverts [P, Kb, 2]`` with ``acount`` / ``bcount`` vertices,
    as :func:`~framework.collision.batch.outlines` gives them (gathered per pair).

    ``size`` (optional ``[P]``): the pair's bounding radii summed, the scale of the tie-break and
    point tolerances; by default it is measured from the outlines.
    """
    avx, avy, acount, brx, bry, dx, dy, bcount, ax, ay = _frame(
        ax, ay, averts, acount, bx, by, bverts, bcount
    )
    p = avx.shape[0]
    if p == 0:
        return scatter(np.zeros(0, dtype=bool), 0.0, 0.0, 0.0, 0.0, 0.0)
    bvx, bvy = brx + dx[:, None], bry + dy[:, None]
    hit, axes, edge_vecs = _sat(avx, avy, acount, bvx, bvy, bcount)
    if not hit.any():
        return scatter(hit, 0.0, 0.0, 0.0, 0.0, 0.0)
    ux, uy, valid, amin, amax, bmin, bmax = (a[hit] for a in axes)
    avx, avy, acount, bvx, bvy, bcount = avx[hit], avy[hit], acount[hit], bvx[hit], bvy[hit], bcount[hit]
    if size is None:
        size = radii(avx, avy) + radii(brx[hit], bry[hit])
    else:
        size = columns_of(p, size)[0][hit]
    ln = np.where(valid, np.hypot(ux, uy), 1.0)
    nx, ny = ux / ln, uy / ln
    # Along n, B moves max(A.n) - min(B.n) forward, or max(B.n) - min(A.n) backward.
    fwd = np.where(valid, (amax - bmin) / ln, np.inf)
    back = np.where(valid, (bmax - amin) / ln, np.inf)
    n = fwd.shape[0]
    cd = np.stack((fwd, back), axis=2).reshape(n, -1)
    cnx = np.stack((nx, -nx), axis=2).reshape(n, -1)
    cny = np.stack((ny, -ny), axis=2).reshape(n, -1)
    depth, nx, ny = pick(cd, cnx, cny, size)
    exa, eya, exb, eyb = (e[hit] for e in edge_vecs)
    px, py = overlap_point(avx, avy, exa, eya, acount, bvx, bvy, exb, eyb, bcount, nx, ny, depth, size)
    return scatter(hit, nx, ny, depth, px + ax[hit], py + ay[hit])


def _inside(x, y, ox, oy, ex, ey, tol):
    """``[P, Kp]``: points (x, y) in the closed outlines (ox, oy, edges ex, ey), with ``tol``
    (absolute, ``[P]``) of rounding, as ``collide._inside``. Padding edges never exclude."""
    cross = ex[:, None, :] * (y[:, :, None] - oy[:, None, :])
    cross -= ey[:, None, :] * (x[:, :, None] - ox[:, None, :])
    return ~(cross < (-tol[:, None, None] * np.hypot(ex, ey)[:, None, :])).any(axis=2)


def overlap_point(avx, avy, exa, eya, acount, bvx, bvy, exb, eyb, bcount, nx, ny, depth, size):
    """Mean of the vertices of A ∩ B for overlapping outlines (all arrays of hit rows)."""
    tol = POINT_TOL * size
    ina = _inside(avx, avy, bvx, bvy, exb, eyb, tol) & vertex_mask(acount, avx.shape[1])
    inb = _inside(bvx, bvy, avx, avy, exa, eya, tol) & vertex_mask(bcount, bvx.shape[1])
    sx = np.where(ina, avx, 0.0).sum(axis=1) + np.where(inb, bvx, 0.0).sum(axis=1)
    sy = np.where(ina, avy, 0.0).sum(axis=1) + np.where(inb, bvy, 0.0).sum(axis=1)
    count = ina.sum(axis=1) + inb.sum(axis=1)
    # Crossings of A's edge i (p + t r) with B's edge j (q + u s), t and u in [0, 1]. Parallel
    # and padding (zero) edges have den == 0 exactly and are skipped, as in the scalar code.
    rx, ry = exa[:, :, None], eya[:, :, None]
    sx_, sy_ = exb[:, None, :], eyb[:, None, :]
    den = rx * sy_ - ry * sx_
    wx = bvx[:, None, :] - avx[:, :, None]
    wy = bvy[:, None, :] - avy[:, :, None]
    crossing = den != 0.0
    den = np.where(crossing, den, 1.0)
    t = (wx * sy_ - wy * sx_) / den
    u = (wx * ry - wy * rx) / den
    crossing &= (t >= 0.0) & (t <= 1.0) & (u >= 0.0) & (u <= 1.0)
    sx += np.where(crossing, avx[:, :, None] + t * rx, 0.0).sum(axis=(1, 2))
    sy += np.where(crossing, avy[:, :, None] + t * ry, 0.0).sum(axis=(1, 2))
    count += crossing.sum(axis=(1, 2))
    found = count > 0
    c = np.where(found, count, 1)
    px, py = sx / c, sy / c
    if not found.all():
        # Rounding hid every vertex (near-degenerate only): the middle of the penetration segment
        # from B's deepest vertex.
        m = ~found
        rows = np.flatnonzero(m)
        j = (bvx[m] * nx[m][:, None] + bvy[m] * ny[m][:, None]).argmin(axis=1)
        half = depth[m] * 0.5
        px[m] = bvx[rows, j] + nx[m] * half
        py[m] = bvy[rows, j] + ny[m] * half
    return px, py
