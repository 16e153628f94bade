"""Batch kernel for axis-aligned box pairs.

The scalar code treats two AABBs as two 4-vertex polygons. Their 8 separating axes collapse to
4 distinct tests, and their 16 push-out candidates to 4 directions with 2 depths each, so this
kernel evaluates exactly the scalar code's products on ``[P]`` arrays, with no ``[P, C, K]``
projections:

A's outline (at the origin) is ``(±hwa, ±hha)`` and B's is ``(dx ± hwb, dy ± hhb)``. A's bottom
and top edges give the axes ``(0, ∓Wa)`` with ``Wa = 2 hwa``; projecting on them multiplies the
y coordinates by ``Wa`` (the ``0 * x`` term adds a signed zero only), and rounding is monotonic,
so the scalar code's ``max(A.n) <= min(B.n)`` is ``Wa * hha <= -(Wa * yb1)`` and so on. B's edges
give the same with ``Wb = (dx + hwb) - (dx - hwb)`` (which rounding may make differ from
``2 hwb``, and may even make 0 far from the origin: then the scalar code calls the pair
separated, and so does this kernel).
"""

from __future__ import annotations

import numpy as np

from .batch_common import ContactArrays, columns, edges, scatter
from .batch_polygon import overlap_point
from .tiebreak import DEPTH_TOL

__all__ = ["aabb_aabb", "overlap_aabb_aabb"]


def _box_frame(ax, ay, ahw, ahh, bx, by, bhw, bhh):
    ax, ay, ahw, ahh, bx, by, bhw, bhh = columns(ax, ay, ahw, ahh, bx, by, bhw, bhh)
    dx, dy = bx - ax, by - ay
    # B's outline in A's frame, as the scalar code places it.
    xb0, xb1, yb0, yb1 = dx - bhw, dx + bhw, dy - bhh, dy + bhh
    return ax, ay, ahw, ahh, bhw, bhh, xb0, xb1, yb0, yb1


def _scales(ahw, ahh, xb0, xb1, yb0, yb1):
    """Lengths of the unnormalised axes: (A's y axis, B's y axis), (A's x axis, B's x axis)."""
    return (ahw + ahw, xb1 - xb0), (ahh + ahh, yb1 - yb0)


def _boxes_overlap(ahw, ahh, xb0, xb1, yb0, yb1) -> np.ndarray:
    (wa, wb), (ha, hb) = _scales(ahw, ahh, xb0, xb1, yb0, yb1)
    hit = np.ones(xb0.shape, dtype=bool)
    for c in (wa, wb):  # axes (0, ±c): B above A, or below it
        top = c * ahh
        hit &= (top > c * yb0) & (c * yb1 > -top)
    for c in (ha, hb):  # axes (±c, 0): B right of A, or left of it
        right = c * ahw
        hit &= (right > c * xb0) & (c * xb1 > -right)
    return hit


def overlap_aabb_aabb(ax, ay, ahw, ahh, bx, by, bhw, bhh) -> np.ndarray:
    """``hit`` of :func:`aabb_aabb` only."""
    _, _, ahw, ahh, _, _, xb0, xb1, yb0, yb1 = _box_frame(ax, ay, ahw, ahh, bx, by, bhw, bhh)
    return _boxes_overlap(ahw, ahh, xb0, xb1, yb0, yb1)


def aabb_aabb(ax, ay, ahw, ahh, bx, by, bhw, bhh) -> ContactArrays:
    """Axis-aligned boxes: centres (ax, ay), (bx, by) and half extents (``ahw``, ``ahh``),
    (``bhw``, ``bhh``), all ``[P]``; the contacts of ``collide(AABB, .., AABB, ..)``."""
    ax, ay, ahw, ahh, bhw, bhh, xb0, xb1, yb0, yb1 = _box_frame(ax, ay, ahw, ahh, bx, by, bhw, bhh)
    hit = _boxes_overlap(ahw, ahh, xb0, xb1, yb0, yb1)
    if not hit.any():
        return scatter(hit, 0.0, 0.0, 0.0, 0.0, 0.0)
    ax, ay, ahw, ahh, bhw, bhh = ax[hit], ay[hit], ahw[hit], ahh[hit], bhw[hit], bhh[hit]
    xb0, xb1, yb0, yb1 = xb0[hit], xb1[hit], yb0[hit], yb1[hit]
    (wa, wb), (ha, hb) = _scales(ahw, ahh, xb0, xb1, yb0, yb1)
    # The 16 candidates of the scalar code, as 4 directions with 2 depths each (one per axis
    # scale); the duplicates (A's bottom edge backward = its top edge forward, ...) are equal.
    up = np.minimum(*(((c * ahh) - c * yb0) / c for c in (wa, wb)))
    down = np.minimum(*(((c * ahh) + c * yb1) / c for c in (wa, wb)))
    right = np.minimum(*(((c * ahw) - c * xb0) / c for c in (ha, hb)))
    left = np.minimum(*(((c * ahw) + c * xb1) / c for c in (ha, hb)))
    # The tie-break rule: keep the near-shortest; prefer vertical; then up (or right).
    size = np.hypot(ahw, ahh) + np.hypot(bhw, bhh)
    lim = np.minimum(np.minimum(up, down), np.minimum(right, left)) + DEPTH_TOL * size
    vertical = (up <= lim) | (down <= lim)
    use_up, use_right = up <= lim, right <= lim
    depth = np.where(vertical, np.where(use_up, up, down), np.where(use_right, right, left))
    nx = np.where(vertical, 0.0, np.where(use_right, 1.0, -1.0))
    ny = np.where(vertical, np.where(use_up, 1.0, -1.0), 0.0)
    # Contact point: the scalar code's construction on the two 4-vertex outlines.
    n = ahw.shape[0]
    avx = np.stack((-ahw, ahw, ahw, -ahw), axis=1)
    avy = np.stack((-ahh, -ahh, ahh, ahh), axis=1)
    bvx = np.stack((xb0, xb1, xb1, xb0), axis=1)
    bvy = np.stack((yb0, yb0, yb1, yb1), axis=1)
    four = np.full(n, 4)
    px, py = overlap_point(
        avx, avy, edges(avx), edges(avy), four, bvx, bvy, edges(bvx), edges(bvy), four,
        nx, ny, depth, size,
    )
    return scatter(hit, nx, ny, depth, px + ax, py + ay)
