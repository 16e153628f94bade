"""Contact manifolds of many box and polygon pairs at once, compiled: the points a solver that turns
bodies pushes at.

:func:`~framework.collision.manifold` is the reference (one pair, the shapes given); this kernel
does the same clipping over the pairs of one step, from the outlines the step's geometry already
holds, and also for pairs a little apart (a box resting on another, both fallen by the same
amount, merely touches): given the pair's normal, the *reference* face is the face (of A, or of B
against the normal) whose outward normal lies closest to it, the *incident* face the other shape's
face most opposed to that; the incident face clipped to the reference face's side planes (its
neighbouring faces; a segment's: the planes through its ends) gives up to two points, kept where
they are less than ``margin`` above the reference face. Each point is
reported midway between the incident face and the reference face's plane, with its separation
along the pair's normal (< 0: overlapping), ordered along the tangent ``(-ny, nx)``. Where the
clipping leaves nothing (a deep overlap, the incident face beside the reference face), the point is
B's deepest vertex along the normal, with the overlap of the shapes' projections on it.
"""

from __future__ import annotations

import numpy as np

from ..compiled import kernel, leaf
from .kinds import KIND_AABB

__all__ = ["pair_manifolds"]


@leaf
def _outline(r, kind, hx, hy, hw, hh, slot, world_poly, count, out):
    """Row ``r``'s outline in world coordinates, counter-clockwise, into ``out``; its vertex count."""
    if kind[r] == KIND_AABB:
        x, y, w, h = hx[r], hy[r], hw[r], hh[r]
        out[0, 0], out[0, 1] = x - w, y - h
        out[1, 0], out[1, 1] = x + w, y - h
        out[2, 0], out[2, 1] = x + w, y + h
        out[3, 0], out[3, 1] = x - w, y + h
        return 4
    s = slot[r]
    m = count[r]
    for i in range(m):
        out[i, 0] = hx[r] + world_poly[s, i, 0]
        out[i, 1] = hy[r] + world_poly[s, i, 1]
    return m


@leaf
def _face_normal(p, m, i):
    j = i + 1 if i + 1 < m else 0
    ex, ey = p[j, 0] - p[i, 0], p[j, 1] - p[i, 1]
    length = (ex * ex + ey * ey) ** 0.5
    return ey / length, -ex / length


@leaf
def _clip(s0, s1, lo, hi):
    """The part ``[lo, hi]`` (fractions along the incident face, v0 to v1) left inside one side
    plane, ``s0`` and ``s1`` the heights of v0 and v1 inside it: ``(empty, lo, hi)``."""
    if s0 < 0.0 and s1 < 0.0:
        return True, lo, hi
    if s0 < 0.0:
        lo = max(lo, s0 / (s0 - s1))
    elif s1 < 0.0:
        hi = min(hi, s0 / (s0 - s1))
    return False, lo, hi


@leaf
def _facing(p, m, nx, ny):
    best, along = 0, -np.inf
    for i in range(m):
        fx, fy = _face_normal(p, m, i)
        d = fx * nx + fy * ny
        if d > along:
            best, along = i, d
    return best, along


@kernel
def pair_manifolds(ra, rb, nx, ny, margin, kind, hx, hy, hw, hh, slot, world_poly, count):
    """Per pair ``(ra[i], rb[i])`` (boxes or polygons) with normal ``(nx, ny)`` (A toward B): the
    number of points (0 to 2), their positions ``px, py`` and separations ``sep`` (``(P, 2)``)."""
    P = ra.size
    K = max(4, world_poly.shape[1])
    n_pts = np.zeros(P, dtype=np.int64)
    px, py, sep = np.zeros((P, 2)), np.zeros((P, 2)), np.zeros((P, 2))
    A, B = np.zeros((K, 2)), np.zeros((K, 2))
    for p in range(P):
        ma = _outline(ra[p], kind, hx, hy, hw, hh, slot, world_poly, count, A)
        mb = _outline(rb[p], kind, hx, hy, hw, hh, slot, world_poly, count, B)
        n_x, n_y = nx[p], ny[p]
        ia, along_a = _facing(A, ma, n_x, n_y)
        ib, along_b = _facing(B, mb, -n_x, -n_y)
        if along_a >= along_b:
            ref, mr, i, inc, mi, along = A, ma, ia, B, mb, along_a
        else:
            ref, mr, i, inc, mi, along = B, mb, ib, A, ma, along_b
        if along <= 0.0:
            continue
        fx, fy = _face_normal(ref, mr, i)
        j, _ = _facing(inc, mi, -fx, -fy)
        j1 = j + 1 if j + 1 < mi else 0
        v0x, v0y, v1x, v1y = inc[j, 0], inc[j, 1], inc[j1, 0], inc[j1, 1]
        lo, hi = 0.0, 1.0
        empty = False
        for k in range(mr):
            if k == i:
                continue
            if mr == 2:
                # A segment's side planes: through its ends, facing out along it.
                i1 = 1 - i
                ux, uy = ref[i1, 0] - ref[i, 0], ref[i1, 1] - ref[i, 1]
                ul = (ux * ux + uy * uy) ** 0.5
                ux, uy = ux / ul, uy / ul
                s0 = (ref[i, 0] - v0x) * -ux + (ref[i, 1] - v0y) * -uy
                s1 = (ref[i, 0] - v1x) * -ux + (ref[i, 1] - v1y) * -uy
                t0 = (ref[i1, 0] - v0x) * ux + (ref[i1, 1] - v0y) * uy
                t1 = (ref[i1, 0] - v1x) * ux + (ref[i1, 1] - v1y) * uy
                empty, lo, hi = _clip(s0, s1, lo, hi)
                if not empty:
                    empty, lo, hi = _clip(t0, t1, lo, hi)
            else:
                kx, ky = _face_normal(ref, mr, k)
                s0 = (ref[k, 0] - v0x) * kx + (ref[k, 1] - v0y) * ky  # >= 0: v0 inside face k
                s1 = (ref[k, 0] - v1x) * kx + (ref[k, 1] - v1y) * ky
                empty, lo, hi = _clip(s0, s1, lo, hi)
            if empty:
                break
        if empty or lo > hi:
            # (a deep overlap, the incident face beside the reference face: B's deepest vertex
            # along the normal, with the overlap of the two shapes' projections on it)
            top, low, k_low = -np.inf, np.inf, 0
            for k in range(ma):
                top = max(top, A[k, 0] * n_x + A[k, 1] * n_y)
            for k in range(mb):
                d = B[k, 0] * n_x + B[k, 1] * n_y
                if d < low:
                    low, k_low = d, k
            s = low - top
            if s < margin[p]:
                px[p, 0] = B[k_low, 0] - 0.5 * s * n_x
                py[p, 0] = B[k_low, 1] - 0.5 * s * n_y
                sep[p, 0] = s
                n_pts[p] = 1
            continue
        r0x, r0y = ref[i, 0], ref[i, 1]
        tx, ty = -n_y, n_x
        q = 0
        for t in (lo, hi):
            if q == 1 and hi <= lo:
                break
            qx, qy = v0x + (v1x - v0x) * t, v0y + (v1y - v0y) * t
            above = (qx - r0x) * fx + (qy - r0y) * fy  # along the reference face's normal
            s = above / along  # along the pair's normal
            if s >= margin[p]:
                continue
            px[p, q] = qx - 0.5 * above * fx
            py[p, q] = qy - 0.5 * above * fy
            sep[p, q] = s
            q += 1
        if q == 2 and px[p, 1] * tx + py[p, 1] * ty < px[p, 0] * tx + py[p, 0] * ty:
            px[p, 0], px[p, 1] = px[p, 1], px[p, 0]
            py[p, 0], py[p, 1] = py[p, 1], py[p, 0]
            sep[p, 0], sep[p, 1] = sep[p, 1], sep[p, 0]
        n_pts[p] = q
    return n_pts, px, py, sep
