"""Numpy kernels of the broad phase: a uniform grid of cells and horizontal strips, no Python loop
over bodies.

Cells. ``cell_index(v) = floor(v / cell)``, clipped to ``+-CELL_LIMIT``, is the one function that
turns every coordinate into a cell, and it is monotone (division by a positive float is correctly
rounded, hence monotone, and so are ``floor`` and clipping). An interval ``[lo, hi]`` is entered in
cells ``cell_index(lo) .. max(cell_index(lo), cell_index(p))`` with ``p`` in ``[prev(hi), hi]``
(see :func:`cell_range`): a body ending exactly on a cell border does not enter the cell it only
touches. Two intervals that overlap strictly share a cell: ``lo_b < hi_a`` gives
``lo_b <= prev(hi_a) <= p_a``, so ``cell_index(lo_b) <= last_a`` by monotonicity, and the same the
other way round. Whether ``1.0 / 0.1`` rounds to 9.999... or to 10.0 never matters, only that every
caller sees the same answer (``1.0 // 0.1 == 9.0`` is a different function and is never used).

Reference cell. A pair sharing several cells is reported from one of them only: the cell
``(max(cx0_a, cx0_b), max(cy0_a, cy0_b))`` (``cx0``: first column of a body, ``cy0``: first row).
By the inequalities above it lies in both bodies' ranges. A shared cell is that one exactly when it
is in the first column of one of the two bodies and in the first row of one of them, so every cell
entry carries two flag bits (bit 1: first column of its body, bit 0: first row) and a pair is kept
iff ``flags_a | flags_b == 0b11``: no set of pairs, no ``np.unique`` over pairs. Strips (rows
alone) use the row bit alone.

Static bodies are entered in a :class:`CellIndex`: one int64 array of the packed
``(cell key, flag code, body)`` sorted by ``np.sort`` (2-3x faster than ``argsort``). Within a cell
the flag codes are ordered so that the partners of any query entry form one contiguous range, and
cells are found through a dense table (or ``searchsorted`` on a sparse grid).

Moving bodies are swept in strips (:class:`StripSweep`): entered in every row of cells they cover,
sorted by (row, minx), and each entry is paired with the following entries of its row whose minx is
below its maxx. That tests about 2.5 candidates per body against 6 for all pairs within each
cell (measured with boxes of 0.3-1.3 cells at one overlap per box).

Large bodies. A body covering more than :data:`LARGE_CELLS` cells, or with a NaN or infinite bound,
is not entered: it is kept in a short list and compared with everything directly, so one huge body
among small ones costs O(N), not a huge number of cells.
"""

from __future__ import annotations

from typing import TypeAlias

import numpy as np
from numpy.typing import NDArray

from ..compiled import kernel
from ..validation import InvalidValue

__all__ = [
    "Bounds",
    "CELL_LIMIT",
    "LARGE_CELLS",
    "CellIndex",
    "StripSweep",
    "as_bounds",
    "auto_cell_size",
    "cell_index",
    "cell_range",
    "expand_runs",
    "overlap_pairs",
    "strict_overlap",
    "subset",
]

#: Cell coordinates are clipped to +-CELL_LIMIT, so (column, row) keys always fit in an int64.
#: Clipping is monotone: it merges far cells but never loses a pair.
CELL_LIMIT = 1 << 29

#: A body covering more cells than this is compared with every other body directly instead.
LARGE_CELLS = 64

#: The bounds of N bodies: ``(minx, miny, maxx, maxy)``, four float64 arrays ``[N]``.
Bounds: TypeAlias = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]

_I64 = np.int64
_EMPTY_I = np.zeros(0, dtype=_I64)
# Upper bound on the elements of one dense block in overlap_pairs.
_BLOCK = 1 << 21


# --- small helpers --------------------------------------------------------------------------------


def as_bounds(minx: object, miny: object, maxx: object, maxy: object) -> Bounds:
    """The four bounds as 1-D float64 arrays of one length; inverted bounds raise InvalidValue.

    NaN passes through (a body with a NaN bound overlaps nothing, as in the brute-force test).
    """
    arrs = tuple(np.asarray(v, dtype=np.float64).reshape(-1) for v in (minx, miny, maxx, maxy))
    n = arrs[0].shape[0]
    if any(a.shape[0] != n for a in arrs):
        raise InvalidValue(
            f"minx, miny, maxx, maxy must have one length, got {[a.shape[0] for a in arrs]}"
        )
    lo_x, lo_y, hi_x, hi_y = arrs
    for axis, lo, hi in (("x", lo_x, hi_x), ("y", lo_y, hi_y)):
        bad = hi < lo
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise InvalidValue(f"body {i}: max{axis} {hi[i]!r} < min{axis} {lo[i]!r}")
    return lo_x, lo_y, hi_x, hi_y


def subset(bounds: Bounds, idx: NDArray[np.intp]) -> Bounds:
    """The bounds of the bodies ``idx``."""
    minx, miny, maxx, maxy = bounds
    return minx[idx], miny[idx], maxx[idx], maxy[idx]


def cell_index(v: NDArray[np.float64], cell: float, clip: bool = True) -> NDArray[np.int64]:
    """``floor(v / cell)`` clipped to +-CELL_LIMIT, as int64 (``v`` finite or +-inf, not NaN).

    ``clip=False`` skips the clipping when the caller knows every ``|v| / cell`` is below the limit.
    """
    return _floor_cells(v / cell, clip)


def _floor_cells(q: NDArray[np.float64], clip: bool) -> NDArray[np.int64]:
    np.floor(q, out=q)
    if clip:
        np.clip(q, -CELL_LIMIT, CELL_LIMIT, out=q)
    return q.astype(_I64)


def cell_range(
    lo: NDArray[np.float64], hi: NDArray[np.float64], cell: float, clip: bool = True,
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """First and last cell index that interval ``[lo, hi]`` needs, for strict overlaps.

    The last is ``cell_index(p)`` for a ``p`` between the float just below ``hi`` and ``hi``, so a
    body ending exactly on a cell border (a tile on a grid) is not entered in the cell beyond, which
    it only touches; and never below the first, so a zero-width interval keeps its one cell. Two
    intervals that overlap strictly still share a cell: ``lo_b < hi_a`` gives ``lo_b <= p_a``, so by
    monotonicity ``first_b <= last_a`` (and the reference cell lies in both ranges).

    ``p = hi - |hi| * 2**-53``: ``|hi| * 2**-53`` is below one ulp of ``hi`` (at most one ulp of the
    binade below for a power of two), so ``p`` rounds to ``hi`` or the float just below it.
    """
    first = cell_index(lo, cell, clip)
    p = np.abs(hi)
    p *= -(2.0**-53)
    p += hi
    p /= cell
    last = _floor_cells(p, clip)
    np.maximum(last, first, out=last)
    return first, last


def auto_cell_size(minx, miny, maxx, maxy) -> float | None:
    """About twice the median body extent, guarded; ``None`` when there is no finite body.

    Guards: an all-point scene falls back to the scene's spread over sqrt(N); the cell is never so
    small that a coordinate is more than 2**28 cells from the origin (a scene at 1e9 with tiny bodies
    gets cells of a few units, and cell indices stay unclipped).
    """
    with np.errstate(over="ignore", invalid="ignore"):
        fin = np.isfinite(minx + miny + maxx + maxy)
        if not fin.all():
            minx, miny, maxx, maxy = minx[fin], miny[fin], maxx[fin], maxy[fin]
        if minx.shape[0] == 0:
            return None
        return _auto_cell_size(minx, miny, maxx, maxy)


def _auto_cell_size(minx, miny, maxx, maxy) -> float:
    n = minx.shape[0]
    cell = 2.0 * float(np.median(np.maximum(maxx - minx, maxy - miny)))
    if not (np.isfinite(cell) and cell > 0.0):
        spread = max(float(maxx.max() - minx.min()), float(maxy.max() - miny.min()))
        cell = spread / np.sqrt(n) if np.isfinite(spread) and spread > 0.0 else 1.0
    mag = max(float(np.abs(v).max()) for v in (minx, miny, maxx, maxy))
    cell = max(cell, mag * 2.0**-28)
    return float(cell) if np.isfinite(cell) and cell > 0.0 else 1.0


def strict_overlap(ax0, ay0, ax1, ay1, bx0, by0, bx1, by1):
    """Elementwise: the bounds overlap on both axes, strictly (touching is no overlap)."""
    return (ax1 > bx0) & (bx1 > ax0) & (ay1 > by0) & (by1 > ay0)


def expand_runs(
    counts: NDArray[np.int64], starts: NDArray[np.int64] | None = None,
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """``(owner, value)``: for each ``k``, ``counts[k]`` entries with owner ``k`` and values
    ``starts[k], starts[k] + 1, ...`` (``0, 1, ...`` when ``starts`` is None)."""
    total = int(counts.sum())
    owner = np.repeat(np.arange(counts.shape[0], dtype=_I64), counts)
    value = np.arange(total, dtype=_I64) - np.repeat(np.cumsum(counts) - counts, counts)
    if starts is not None:
        value += np.repeat(starts, counts)
    return owner, value


def overlap_pairs(a: Bounds, b: Bounds, upper: bool = False) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """All ``(i, j)`` with bounds ``a[i]`` strictly overlapping ``b[j]``, in dense blocks (O(|a| |b|)).

    ``a`` and ``b`` are ``(minx, miny, maxx, maxy)`` tuples of arrays. With ``upper`` (``a`` is
    ``b``) only ``i < j``. Pairs come in row-major (lexicographic) order.
    """
    na, nb = a[0].shape[0], b[0].shape[0]
    if na == 0 or nb == 0:
        return _EMPTY_I, _EMPTY_I
    step = max(1, _BLOCK // nb)
    out_i, out_j = [], []
    for s in range(0, na, step):
        e = min(na, s + step)
        m = strict_overlap(*(v[s:e, None] for v in a), *(v[None, :] for v in b))
        if upper:
            m &= np.arange(s, e)[:, None] < np.arange(nb)[None, :]
        i, j = np.nonzero(m)
        out_i.append(i + s)
        out_j.append(j)
    return np.concatenate(out_i).astype(_I64), np.concatenate(out_j).astype(_I64)


class _Ranges:
    """Cell ranges of a set of bodies; ``small`` are the numbers of the bodies entered in cells,
    ``lo_x, hi_x``: the least minx and greatest maxx of the small bodies."""

    def __init__(self, bounds: Bounds, cell: float) -> None:
        with np.errstate(over="ignore"):  # huge coordinates over a tiny cell: clipped below
            self._compute(bounds, cell)

    def _compute(self, bounds: Bounds, cell: float) -> None:
        minx, miny, maxx, maxy = bounds
        n = minx.shape[0]
        if n == 0:
            self.cx0 = self.cx1 = self.cy0 = self.cy1 = self.nx = self.ny = self.small = self.large = _EMPTY_I
            self.lo_x = self.hi_x = 0.0
            return
        # bounds are validated (max >= min, or NaN), so these four reductions see any NaN or inf
        ext = (float(minx.min()), float(miny.min()), float(maxx.max()), float(maxy.max()))
        fin = None
        if not all(np.isfinite(ext)):
            fin = np.isfinite(minx + miny + maxx + maxy)  # an overflow to inf only makes a body large
            minx, miny, maxx, maxy = (np.where(fin, v, 0.0) for v in bounds)
            ext = (float(minx.min()), float(miny.min()), float(maxx.max()), float(maxy.max()))
        clip = max(abs(v) for v in ext) / cell >= CELL_LIMIT / 2
        self.cx0, self.cx1 = cell_range(minx, maxx, cell, clip)
        self.cy0, self.cy1 = cell_range(miny, maxy, cell, clip)
        self.nx = self.cx1 - self.cx0 + 1
        self.ny = self.cy1 - self.cy0 + 1
        ok = self.nx * self.ny <= LARGE_CELLS
        if fin is not None:
            ok &= fin
        if fin is None and ok.all():
            self.small = np.arange(n, dtype=_I64)
            self.large = _EMPTY_I
            self.lo_x, self.hi_x = ext[0], ext[2]
        else:
            self.small = np.flatnonzero(ok).astype(_I64)
            self.large = np.flatnonzero(~ok).astype(_I64)
            k = self.small.shape[0]
            self.lo_x = float(minx[self.small].min()) if k else 0.0
            self.hi_x = float(maxx[self.small].max()) if k else 0.0


def _offsets(span: NDArray[np.int64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """``(i, d)`` for every ``i`` and ``0 <= d < span[i]``, grouped by ``d`` when spans are short
    (each group keeps the order of ``i``)."""
    top = int(span.max()) if span.shape[0] else 0
    if top <= 4:
        ii, dd = [], []
        for d in range(top):
            i = np.arange(span.shape[0], dtype=_I64) if d == 0 else np.flatnonzero(span > d)
            ii.append(i)
            dd.append(np.full(i.shape[0], d, dtype=_I64))
        return np.concatenate(ii), np.concatenate(dd)
    return expand_runs(span)


# --- static bodies: cells -------------------------------------------------------------------------


class CellIndex:
    """A set of bodies entered in grid cells, as one sorted array (used for the static bodies).

    Attributes (read-only by convention):
      ``n``, ``bounds``: number of bodies and their (minx, miny, maxx, maxy) (a private copy);
      ``large``: sorted numbers of the bodies not entered in cells;
      ``x0, y0, wx, wy``: lowest cell and column/row span; cell ``(cx, cy)`` has the row-major key
      ``(cy - y0) * wx + (cx - x0)``;
      ``key, flags, body``: the entries sorted by key (flags: bit 1 first column, bit 0 first row);
      ``ukey``, ``bound``: the distinct keys, and where the code ranges of each one's run start.
    """

    def __init__(self, bounds: Bounds, cell: float, copy: bool = True) -> None:
        self.bounds: Bounds = (
            (np.array(bounds[0]), np.array(bounds[1]), np.array(bounds[2]), np.array(bounds[3])) if copy else bounds)
        self.n = self.bounds[0].shape[0]
        self.cell = cell
        r = _Ranges(self.bounds, cell)
        self.large = r.large
        sb = r.small
        if sb.shape[0] == 0:
            self.x0 = self.y0 = self.wx = self.wy = 0
            self.key = self.flags = self.body = self.ukey = _EMPTY_I
            self.bound = np.zeros((0, 5), dtype=_I64)
            self._dense = None
            self.ebounds = (np.zeros(0),) * 4
            return
        cx0, cy0, nx, ny = r.cx0[sb], r.cy0[sb], r.nx[sb], r.ny[sb]
        self.x0, self.y0 = x0, y0 = int(cx0.min()), int(cy0.min())
        self.wx = wx = int((r.cx1[sb]).max()) - x0 + 1
        self.wy = wy = int((r.cy1[sb]).max()) - y0 + 1
        base = (cy0 - y0) * wx + (cx0 - x0)
        i, d = _offsets(nx * ny)
        nxi = nx[i]
        dx, dy = d % nxi, d // nxi
        key = base[i] + dy * wx + dx
        flags = ((dx == 0).astype(_I64) << 1) | (dy == 0)
        body = sb[i]
        # Within a cell the entries are ordered by the code 0, 1, 3, 2 of their flags (the Gray code
        # flags ^ flags >> 1), so the partners a query entry with flags f needs (f | flags == 0b11)
        # are one contiguous range: f = 3 all, f = 2 codes 1-2, f = 1 codes 2-3, f = 0 code 2.
        code = flags ^ (flags >> 1)
        bbits = max(1, (self.n - 1).bit_length())
        kbits = max(1, (wx * wy - 1).bit_length())
        if kbits + 2 + bbits <= 63:
            packed = np.sort((key << (bbits + 2)) | (code << bbits) | body)
            self.body = packed & ((1 << bbits) - 1)
            code = (packed >> bbits) & 3
            self.key = packed >> (bbits + 2)
        else:  # cells spread over an astronomical span: sort (key, code) with lexsort
            order = np.lexsort((code, key))
            self.key, code, self.body = key[order], code[order], body[order]
        self.flags = code ^ (code >> 1)
        first = np.empty(self.key.shape[0], dtype=bool)
        first[0] = True
        np.not_equal(self.key[1:], self.key[:-1], out=first[1:])
        starts = np.flatnonzero(first)
        self.ukey = self.key[starts]
        # bound[u, c]: first entry of cell u with code >= c (bound[u, 4]: end of the cell);
        # keys use at most 61 bits, so (key, code) packs into an int64 that sorts like the entries
        kc, ukc = (self.key << 2) | code, self.ukey << 2
        bound = np.empty((starts.shape[0], 5), dtype=_I64)
        bound[:, 0] = starts
        for c in (1, 2, 3, 4):
            bound[:, c] = np.searchsorted(kc, ukc + c)
        self.bound = bound
        # a dense table cell key -> cell number when the grid is not much bigger than its entries
        self._dense = None
        if wx * wy <= max(1 << 16, 4 * self.key.shape[0]):
            self._dense = np.full(wx * wy + 1, -1, dtype=_I64)  # the extra last slot: "outside"
            self._dense[self.ukey] = np.arange(starts.shape[0], dtype=_I64)
        # the bounds in entry order, so the pair tests read neighbouring memory
        self.ebounds = subset(self.bounds, self.body)

    @property
    def entries(self) -> int:
        return self.key.shape[0]

    @property
    def dense(self) -> NDArray[np.int64]:
        """The table cell key -> number of the used cell (-1: empty), or an empty array where the
        grid is too sparse for one (the used cells' keys ``ukey`` are then searched)."""
        return _EMPTY_I if self._dense is None else self._dense

    # for query flags f = 0..3: the code range [_LO[f], _HI[f]) of the partners (see __init__)
    _LO = np.array([2, 2, 1, 0], dtype=_I64)
    _HI = np.array([3, 4, 3, 4], dtype=_I64)

    def lookup(
        self, cx: NDArray[np.int64], cy: NDArray[np.int64], f: NDArray[np.int64] | None = None,
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """``(lo, hi)``: the entries of cell ``(cx[k], cy[k])`` are ``lo[k]:hi[k]`` (empty if none);
        with query flags ``f``, only those an entry with flags ``f[k]`` is paired with in that cell
        (``f | flags == 0b11``). Fastest when the cells come in row-major order."""
        if self.entries == 0:
            z = np.zeros(cx.shape[0], dtype=_I64)
            return z, z
        valid = (cx >= self.x0) & (cx < self.x0 + self.wx) & (cy >= self.y0) & (cy < self.y0 + self.wy)
        if self._dense is not None:
            u = self._dense[np.where(valid, (cy - self.y0) * self.wx + (cx - self.x0), -1)]
            hit = u >= 0
        else:
            key = np.where(valid, (cy - self.y0) * self.wx + (cx - self.x0), -1)
            u = np.searchsorted(self.ukey, key)
            np.minimum(u, self.ukey.shape[0] - 1, out=u)
            hit = self.ukey[u] == key
        if f is None:
            lo, hi = self.bound[u, 0], self.bound[u, 4]
        else:
            lo, hi = self.bound[u, self._LO[f]], self.bound[u, self._HI[f]]
        return lo, np.where(hit, hi, lo)

    def bodies_in_cells(self, cx: NDArray[np.int64], cy: NDArray[np.int64]) -> NDArray[np.int64]:
        """Numbers of the bodies entered in any of the given cells (with repeats)."""
        if self.entries == 0 or cx.shape[0] == 0:
            return _EMPTY_I
        lo, hi = self.lookup(cx, cy)
        _, pos = expand_runs(hi - lo, lo)
        return self.body[pos]

    def used_cells(self) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """(column, row) of the cells holding something."""
        if self.entries == 0:
            return _EMPTY_I, _EMPTY_I
        row, col = np.divmod(self.ukey, self.wx)
        return col + self.x0, row + self.y0


# --- moving bodies: strips and sweep --------------------------------------------------------------


class StripSweep:
    """One step's moving bodies, entered in strips (rows of cells) and sorted by (row, minx).

    Order within a row. Rather than ranking the minx values (an ``argsort``), each entry's minx is
    quantised by a monotone ``q(x) = floor((x - lo) * scale)`` and packed with its row, first-row
    flag and body into one int64, sorted by ``np.sort``. Equal quanta may come in any order, so the
    sweep of entry ``p`` goes on while ``q(minx) <= q(maxx_p)``, a superset of ``minx < maxx_p``
    that still ends the sweep at the first entry past it, and pairs are then tested exactly. The
    sweep key ``row << qbits | q`` also ends every sweep at the end of its row.

    Attributes (read-only by convention): ``n``, ``large`` as in :class:`CellIndex`; per entry, in
    sorted order: ``row`` (relative to the lowest), ``first`` (1 in the body's first row), ``body``,
    the body's bounds ``ex0, ey0, ex1, ey1``, the sweep key ``skey`` and its limit ``slim``.
    """

    def __init__(self, bounds: Bounds, cell: float) -> None:
        minx, miny, maxx, maxy = bounds  # not kept: the caller may reuse its arrays
        self.n = minx.shape[0]
        self.cell = cell
        r = self._ranges = _Ranges(bounds, cell)
        self.large = r.large
        self._large_bounds = subset(bounds, r.large)
        self._bounds: Bounds | None = None
        sb = r.small
        k = sb.shape[0]
        if k == 0:
            self.row = self.first = self.body = self.skey = self.slim = _EMPTY_I
            self.ex0 = self.ey0 = self.ex1 = self.ey1 = np.zeros(0)
            return
        all_small = k == self.n
        cy0 = r.cy0 if all_small else r.cy0[sb]
        ny = r.ny if all_small else r.ny[sb]
        self._y0 = y0 = int(cy0.min())
        rbits = max(1, (int((cy0 + ny).max()) - y0).bit_length())
        self._bbits = bbits = max(1, (self.n - 1).bit_length())
        self._qbits = qbits = max(0, min(48, 62 - rbits - 1 - bbits))  # 2**48 - 1 is exact in float
        span = r.hi_x - r.lo_x
        top = float((1 << qbits) - 1)
        scale = top / span if np.isfinite(span) and span > 0.0 else 0.0
        self._q = (r.lo_x, scale, top)
        qmin = self.quantise(minx if all_small else minx[sb])
        i, dy = _offsets(ny)
        b = sb[i] if not all_small else i
        packed = np.sort((((((cy0[i] + dy - y0) << qbits) | qmin[i]) << 1 | (dy == 0)) << bbits) | b)
        self.body = body = packed & ((1 << bbits) - 1)
        self.first = (packed >> bbits) & 1
        skey = packed >> (bbits + 1)
        self.row = skey >> qbits
        self.ex0, self.ey0, self.ex1, self.ey1 = minx[body], miny[body], maxx[body], maxy[body]
        self.slim = (self.row << qbits) | self.quantise(self.ex1)
        # a sentinel past the last entry ends every sweep there
        self.skey = np.append(skey, np.iinfo(_I64).max)

    @property
    def bounds(self) -> Bounds:
        """The bodies' (minx, miny, maxx, maxy), rebuilt on demand from the entries (each small body
        once, from its first row) and the large bodies."""
        if self._bounds is None:
            out = (np.empty(self.n), np.empty(self.n), np.empty(self.n), np.empty(self.n))
            once = np.flatnonzero(self.first)
            entry = (self.ex0, self.ey0, self.ex1, self.ey1)
            for v, e, lg in zip(out, entry, self._large_bounds, strict=True):
                v[self.body[once]] = e[once]
                v[self.large] = lg
            self._bounds = out
        return self._bounds

    def quantise(self, x: NDArray[np.float64]) -> NDArray[np.int64]:
        """The monotone quantiser ``q`` of the sort order (see the class notes)."""
        lo, scale, top = self._q
        if scale == 0.0:  # one x for all, or a span that overflows: no order within rows at all
            return np.zeros(x.shape[0], dtype=_I64)
        q = np.floor((x - lo) * scale)
        np.clip(q, 0.0, top, out=q)
        return q.astype(_I64)

    @property
    def entries(self) -> int:
        return self.row.shape[0]

    def self_pairs(self) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """``(a, b)`` body numbers of the strictly overlapping pairs of small bodies, each once."""
        if self.entries < 2:
            return _EMPTY_I, _EMPTY_I
        pa, pb = sweep_pairs(self.skey, self.slim, self.ex0, self.ey0, self.ex1, self.ey1, self.first)
        return self.body[pa], self.body[pb]

    def cross_pairs(self, stat: CellIndex) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """``(m, s)``: small moving body ``m`` strictly overlapping small static body ``s``."""
        if self.entries == 0 or stat.entries == 0:
            return _EMPTY_I, _EMPTY_I
        r = self._ranges
        body = self.body
        # each strip entry looks up the cells of its row that its body covers; grouped by column
        # offset, the entries stay in (row, minx) order, so the lookups come in row-major order
        q, dx = _offsets(r.nx[body])
        f = ((dx == 0).astype(_I64) << 1) | self.first[q]
        lo, hi = stat.lookup(r.cx0[body[q]] + dx, self.row[q] + self._y0, f)
        own, ps = expand_runs(hi - lo, lo)
        q = q[own]
        ok = strict_overlap(*(v[q] for v in (self.ex0, self.ey0, self.ex1, self.ey1)),
                            *(v[ps] for v in stat.ebounds))
        return body[q[ok]], stat.body[ps[ok]]


@kernel
def sweep_pairs(skey, slim, x0, y0, x1, y1, first):
    """The sweep of :meth:`StripSweep.self_pairs` (compiled): entry ``p`` meets ``p + 1, p + 2, ...``
    while their sweep key is within its limit; a pair counts once (in the first row either of its
    bodies has) and only if the bounds strictly overlap. Returns entry numbers ``(a, b)``."""
    n = slim.shape[0]
    # Counted first, then filled: one sweep growing its output as it goes, or the test as a
    # function of its own, measured 2x and 8x slower (numba 0.68).
    count = 0
    for p in range(n):
        q = p + 1
        while skey[q] <= slim[p]:
            if (x1[q] > x0[p] and x1[p] > x0[q] and y1[q] > y0[p] and y1[p] > y0[q]
                    and (first[p] | first[q]) != 0):
                count += 1
            q += 1
    pa = np.empty(count, dtype=np.int64)
    pb = np.empty(count, dtype=np.int64)
    k = 0
    for p in range(n):
        q = p + 1
        while skey[q] <= slim[p]:
            if (x1[q] > x0[p] and x1[p] > x0[q] and y1[q] > y0[p] and y1[p] > y0[q]
                    and (first[p] | first[q]) != 0):
                pa[k] = p
                pb[k] = q
                k += 1
            q += 1
    return pa, pb
