"""The scaled frame of one pair and the way back to the world, compiled: what the row kernels
(:mod:`.polygon_rows`, :mod:`.circle_rows`, :mod:`.box_pair_row`) share with the numpy kernels'
:func:`~framework.collision.batch_common.frame` and :func:`~framework.collision.batch_common.finish`,
one pair at a time, in the same operations."""

from __future__ import annotations

import math

from ..compiled import inner
from .exact import TINY

__all__ = ["frame_row", "world_row"]


@inner
def frame_row(ax, ay, bx, by, reach):  # pragma: no cover - compiled
    """``batch_common.frame`` of one pair: ``(dx, dy, k)``, the offset of b from a scaled by
    ``2**-k`` so that it and ``reach`` are about 1 (``reach`` not NaN)."""
    hdx, hdy = 0.5 * bx - 0.5 * ax, 0.5 * by - 0.5 * ay
    m = abs(hdx) if abs(hdx) > abs(hdy) else abs(hdy)
    m = m if m > 0.5 * reach else 0.5 * reach
    k = math.frexp(m)[1]
    return math.ldexp(hdx, 1 - k), math.ldexp(hdy, 1 - k), k


@inner
def world_row(depth, px, py, k, ax, ay):  # pragma: no cover - compiled
    """``batch_common.finish`` of one contact: ``(finite, depth, px, py)`` unscaled and moved to
    the world (the depth at least the smallest float); ``finite`` False where a value is beyond
    float64's range (the numpy kernel raises its error there)."""
    depth = math.ldexp(depth, k)
    depth = depth if depth > TINY else TINY
    px, py = ax + math.ldexp(px, k), ay + math.ldexp(py, k)
    return math.isfinite(depth) and math.isfinite(px) and math.isfinite(py), depth, px, py
