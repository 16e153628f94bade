"""The static bodies a set of boxes meets, looked up in the statics' cells in one compiled pass:
:func:`static_cross`.

A box looks in each cell of the statics' grid (:class:`~framework.collision.grid.CellIndex`) its
bounds cover and tests the entries there whose pair it reports by the reference-cell rule of
:mod:`~framework.collision.grid` (one cell of the two bodies' shared ones, so each pair once); a
box over more than :data:`~framework.collision.grid.LARGE_CELLS` cells, or not finite, is tested
against every static instead, and every box against the statics kept out of the cells (large).
Its cells are found as :func:`~framework.collision.grid.cell_range` finds them (the same
arithmetic, so the same cells as the statics' own).

Where the numpy path (the boxes swept into strips, then looked up cell by cell) took some three
hundred Python calls for a handful of boxes (a solve asking which statics its pushed bodies may
reach: half a millisecond a time), this is one call. The pairs are the same set: every box and
static whose bounds strictly overlap.
"""

from __future__ import annotations

import numpy as np

from ..compiled import inner, kernel, leaf
from .box_rows import lower_bound
from .grid import CELL_LIMIT, LARGE_CELLS

__all__ = ["static_cross"]

# For a box's flags f in a cell (bit 1: its first column, bit 0: its first row), the codes of the
# entries it is paired with there run from _LO[f] to _HI[f] (CellIndex's Gray-coded order).
_LO = (2, 2, 1, 0)
_HI = (3, 4, 3, 4)


@leaf
def _cell(q):  # pragma: no cover - compiled
    """``floor(q)`` clipped to +-CELL_LIMIT, as :func:`~framework.collision.grid.cell_index`."""
    c = np.floor(q)
    if c < -CELL_LIMIT:
        c = -CELL_LIMIT
    elif c > CELL_LIMIT:
        c = CELL_LIMIT
    return np.int64(c)


@leaf
def _last_cell(hi, cell, first):  # pragma: no cover - compiled
    """The last cell an interval ending at ``hi`` needs (:func:`~framework.collision.grid.cell_range`)."""
    last = _cell((hi + abs(hi) * -(2.0**-53)) / cell)
    return last if last > first else first


@leaf
def _unique_cell(ukey, dense, key):  # pragma: no cover - compiled
    """The number of the cell ``key`` among the used cells (-1: none there)."""
    if dense.size:
        return dense[key]
    u = lower_bound(ukey, key)
    return u if u < ukey.size and ukey[u] == key else -1


@inner
def _put(out, m, i, s):  # pragma: no cover - compiled
    """``out`` with the pair ``(i, s)`` in its column ``m`` (a larger copy when full)."""
    if m == out.shape[1]:
        grown = np.empty((2, 2 * m), dtype=np.int64)
        for k in range(m):  # (a loop: a slice assignment compiles numba's shape checks, seconds)
            grown[0, k], grown[1, k] = out[0, k], out[1, k]
        out = grown
    out[0, m], out[1, m] = i, s
    return out


@kernel
def static_cross(minx, miny, maxx, maxy, cell, x0, y0, wx, wy, ukey, bound, dense, body, ex0, ey0, ex1, ey1,
                 large, sx0, sy0, sx1, sy1):  # pragma: no cover - compiled
    """``(i, s)`` as the rows of one int64 block: box ``i`` (bounds ``minx .. maxy``) and static
    ``s`` strictly overlap, each pair once, in no particular order. The statics: the grid (``cell``,
    lowest cell ``x0, y0``, ``wx`` columns, ``wy`` rows), the used cells' keys ``ukey``, each one's
    code ranges ``bound`` and the ``dense`` table (empty: none), the entries' ``body`` and bounds
    ``ex0 .. ey1``; the ``large`` ones; every static's bounds ``sx0 .. sy1``."""
    out = np.empty((2, 16), dtype=np.int64)
    m = 0
    for i in range(minx.size):
        a0, b0, a1, b1 = minx[i], miny[i], maxx[i], maxy[i]
        every = not np.isfinite(a0 + b0 + a1 + b1)
        cx0 = cx1 = cy0 = cy1 = np.int64(0)
        if not every:
            cx0 = _cell(a0 / cell)
            cx1 = _last_cell(a1, cell, cx0)
            cy0 = _cell(b0 / cell)
            cy1 = _last_cell(b1, cell, cy0)
            every = (cx1 - cx0 + 1) * (cy1 - cy0 + 1) > LARGE_CELLS
        if every:  # (not looked up in cells: tested against every static)
            for s in range(sx0.size):
                if sx1[s] > a0 and a1 > sx0[s] and sy1[s] > b0 and b1 > sy0[s]:
                    out = _put(out, m, i, s)
                    m += 1
            continue
        for cy in range(max(cy0, y0), min(cy1, y0 + wy - 1) + 1):
            for cx in range(max(cx0, x0), min(cx1, x0 + wx - 1) + 1):
                u = _unique_cell(ukey, dense, (cy - y0) * wx + (cx - x0))
                if u < 0:
                    continue
                f = (2 if cx == cx0 else 0) | (1 if cy == cy0 else 0)
                for e in range(bound[u, _LO[f]], bound[u, _HI[f]]):
                    if ex1[e] > a0 and a1 > ex0[e] and ey1[e] > b0 and b1 > ey0[e]:
                        out = _put(out, m, i, body[e])
                        m += 1
        for k in range(large.size):
            s = large[k]
            if sx1[s] > a0 and a1 > sx0[s] and sy1[s] > b0 and b1 > sy0[s]:
                out = _put(out, m, i, s)
                m += 1
    pairs = np.empty((2, m), dtype=np.int64)
    for k in range(m):
        pairs[0, k], pairs[1, k] = out[0, k], out[1, k]
    return pairs
