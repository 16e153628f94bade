"""The contact point of two overlapping convex outlines, vectorised over pairs.

As ``collide.overlap_point``: the mean of the vertices of A ∩ B (an outline of two points is a
segment), i.e. A's vertices inside B, B's
vertices inside A (``[Ka, Kb, P]`` edge tests) and the crossings of every edge of A with every edge
of B (``[Ka, Kb, P]``), each included by the same closed tests. The mean is a convex combination of
points of A ∩ B, so it lies in the overlap.
"""

from __future__ import annotations

import numpy as np

from .batch_common import F64, cols, edges, first_min, norm, sum_leading, take, vertex_mask
from .collide import POINT_TOL

__all__ = ["overlap_point"]


def _inside(x, y, ox, oy, ex, ey, tol):
    """``[Kp, P]``: points (x, y) in the closed outlines (vertices ox, oy, edges ex, ey), with
    ``tol`` (absolute, ``[P]``) of rounding, as ``collide._inside``. Padding edges never exclude."""
    cross = ex[None] * (y[:, None] - oy[None])
    cross -= ey[None] * (x[:, None] - ox[None])
    return ~(cross < -tol * norm(ex, ey)[None]).any(axis=1)


def _within_segment(x, y, ox, oy, count, tol):
    """``[Kp, P]``: for the outlines of two points (segments, ``count`` 2), points (x, y) between the
    ends along the segment (their being on its line is :func:`_inside`'s test), as
    ``collide._inside``; true for the other outlines."""
    ex, ey = ox[1] - ox[0], oy[1] - oy[0]
    along = ex * (x - ox[0]) + ey * (y - oy[0])
    slack = tol * norm(ex, ey)
    return (count != 2) | ((along >= -slack) & (along <= ex * ex + ey * ey + slack))


def overlap_point(avx, avy, acount, bvx, bvy, bcount, nx, ny, depth, size):
    """Mean of the vertices of A ∩ B for overlapping outlines ``[K, P]`` (B at its offset)."""
    tol = POINT_TOL * size
    exa, eya, exb, eyb = edges(avx), edges(avy), edges(bvx), edges(bvy)
    ina = _inside(avx, avy, bvx, bvy, exb, eyb, tol) & vertex_mask(acount, avx.shape[0])
    inb = _inside(bvx, bvy, avx, avy, exa, eya, tol) & vertex_mask(bcount, bvx.shape[0])
    if (acount == 2).any() or (bcount == 2).any():
        ina &= _within_segment(avx, avy, bvx, bvy, bcount, tol)
        inb &= _within_segment(bvx, bvy, avx, avy, acount, tol)
    ina, inb = ina.astype(F64), inb.astype(F64)
    sx = sum_leading(avx * ina) + sum_leading(bvx * inb)
    sy = sum_leading(avy * ina) + sum_leading(bvy * inb)
    count = sum_leading(ina) + sum_leading(inb)
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
    sx += sum_leading((avx[:, None] + t * rx) * crossing)
    sy += sum_leading((avy[:, None] + t * ry) * crossing)
    count += sum_leading(crossing)
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
