"""The scaled frame of one pair and the way back to the world, compiled: what the row kernels
(:mod:`.polygon_rows`, :mod:`.circle_rows`, :mod:`.box_pair_row`) share with the numpy kernels'
:func:`~framework.collision.batch_common.frame` and :func:`~framework.collision.batch_common.finish`,
and with :func:`~framework.collision.batch_common.pick`'s tie-break, one pair at a time, in the
same operations."""

from __future__ import annotations

import math

import numpy as np

from ..compiled import inner, leaf
from .exact import TINY
from .tiebreak import DEPTH_TOL, DIR_TOL

__all__ = ["BIG", "frame_row", "pick_row", "put_row", "world_row"]

#: "absent" in a min, in the scaled frames where values are about 1 (``batch_common.BIG``)
BIG = 1e300


@leaf
def frame_row(ax, ay, bx, by, reach):  # pragma: no cover - compiled
    """``batch_common.frame`` of one pair: ``(dx, dy, k)``, the offset of b from a scaled by
    ``2**-k`` so that it and ``reach`` are about 1 (``reach`` not NaN)."""
    hdx, hdy = 0.5 * bx - 0.5 * ax, 0.5 * by - 0.5 * ay
    m = abs(hdx) if abs(hdx) > abs(hdy) else abs(hdy)
    m = m if m > 0.5 * reach else 0.5 * reach
    k = math.frexp(m)[1]
    return math.ldexp(hdx, 1 - k), math.ldexp(hdy, 1 - k), k


@leaf
def world_row(depth, px, py, k, ax, ay):  # pragma: no cover - compiled
    """``batch_common.finish`` of one contact: ``(finite, depth, px, py)`` unscaled and moved to
    the world (the depth at least the smallest float); ``finite`` False where a value is beyond
    float64's range (the numpy kernel raises its error there)."""
    depth = math.ldexp(depth, k)
    depth = depth if depth > TINY else TINY
    px, py = ax + math.ldexp(px, k), ay + math.ldexp(py, k)
    return math.isfinite(depth) and math.isfinite(px) and math.isfinite(py), depth, px, py



@leaf
def put_row(i, nx_i, ny_i, depth_i, px_i, py_i, k, ax, ay, hit, nx, ny, depth, px, py, defer):
    # pragma: no cover - compiled
    """Row ``i``'s contact (scaled, frame ``k`` at ``(ax, ay)``) into the output columns as
    ``batch_common.finish`` writes it (normals with -0.0 made 0.0), or ``defer[i]`` where a value
    is beyond float64's range (the numpy kernel raises its error there)."""
    finite, d, x, y = world_row(depth_i, px_i, py_i, k, ax, ay)
    if not finite:
        defer[i] = True
        return
    hit[i] = True
    nx[i], ny[i], depth[i], px[i], py[i] = nx_i + 0.0, ny_i + 0.0, d, x, y

@inner
def pick_row(cd, cx, cy, size):  # pragma: no cover - compiled
    """``batch_common.pick`` of one pair's candidates ``(depth, nx, ny)`` (``depth`` >= 1e300 for
    absent ones); on the present ones alone, also ``tiebreak.pick``'s answer (the same steps)."""
    c = cd.size
    best = cd[0]
    for j in range(1, c):
        if cd[j] < best:
            best = cd[j]
    lim = best + DEPTH_TOL * size
    near = np.empty(c, dtype=np.bool_)
    top = 0.0
    for j in range(c):
        near[j] = cd[j] <= lim
        v = abs(cy[j]) * (1.0 if near[j] else 0.0)
        if j == 0 or v > top:
            top = v
    for j in range(c):
        near[j] = near[j] and abs(cy[j]) >= top - DIR_TOL
    top = 0.0
    for j in range(c):
        fold = cy[j] < -DIR_TOL or (abs(cy[j]) <= DIR_TOL and cx[j] < 0.0)
        fx = cx[j] * (1.0 - 2.0 * (1.0 if fold else 0.0))
        v = fx + ((1.0 if near[j] else 0.0) - 1.0) * 4.0
        if j == 0 or v > top:
            top = v
    shortest = 0.0
    for j in range(c):
        fold = cy[j] < -DIR_TOL or (abs(cy[j]) <= DIR_TOL and cx[j] < 0.0)
        fx = cx[j] * (1.0 - 2.0 * (1.0 if fold else 0.0))
        near[j] = near[j] and fx >= top - DIR_TOL
        v = cd[j] + (1.0 - (1.0 if near[j] else 0.0)) * BIG
        if j == 0 or v < shortest:
            shortest = v
    for key in range(2):
        any_keep = False
        for j in range(c):
            if near[j] and ((cy[j] if key == 0 else cx[j]) > DIR_TOL):
                any_keep = True
        if any_keep:
            for j in range(c):
                near[j] = near[j] and ((cy[j] if key == 0 else cx[j]) > DIR_TOL)
    low = 0.0
    for j in range(c):
        v = cd[j] + (1.0 - (1.0 if near[j] else 0.0)) * BIG
        if j == 0 or v < low:
            low = v
    i = 0
    for j in range(c):
        if near[j] and cd[j] == low:
            i = j
            break
    return shortest, cx[i], cy[i]
