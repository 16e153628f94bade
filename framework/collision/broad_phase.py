"""Broad phase: every pair of bodies whose axis-aligned bounds overlap, found with a spatial hash.

Pure numpy, no ECS. The pair set is exactly that of :func:`brute_force_pairs`: bounds overlapping
*strictly* on both axes (``maxx_a > minx_b and maxx_b > minx_a``, the same for y: touching bounds
are not a pair, as touching shapes are not a collision), never two static bodies. Pairs come as
two int64 arrays ``(a, b)`` with ``a < b``, sorted lexicographically, so the output depends only on
the input values (no hash seeds, no set order).

How (the invariants and their proofs are in :mod:`framework.collision.grid`):

- one uniform grid of square cells. A body is entered in the cells its bounds need for strict
  overlaps, computed with one monotone ``floor(v / cell)``, so two overlapping bodies always share
  a cell whatever the rounding (``1.0 // 0.1 == 9.0`` cannot lose a pair), and a pair sharing
  several cells is reported from one of them only (its *reference cell*; no dedup pass);
- static bodies: :meth:`SpatialHash.set_static` enters them once in a sorted cell array. Each
  :meth:`SpatialHash.pairs` call looks up only the cells the moving bodies cover, so a
  100,000-tile level adds the cost of the tiles next to movers, not of the level;
- moving bodies: entered in horizontal strips (rows of cells), sorted by (row, minx), and swept:
  each entry meets the following entries of its row whose minx is below its maxx;
- candidates are tested exactly on the float bounds; no Python loop runs over bodies;
- bodies covering more than ``grid.LARGE_CELLS`` cells (one huge body among small ones), and bodies
  with NaN or infinite bounds, are kept aside and compared with every other body directly.
"""

from __future__ import annotations

import math
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..arrays import distinct
from ..compiled import kernel, leaf
from ..stable_sort import argsort_ints, stable_argsort
from ..validation import InvalidValue, finite, positive
from . import grid
from .box_rows import lower_bound
from .grid import Bounds, CellIndex, StripSweep, as_bounds, overlap_pairs, strict_overlap, subset
from .static_cells import static_cross

__all__ = ["SpatialHash", "brute_force_pairs"]

_I64 = np.int64
_EMPTY_I = np.zeros(0, dtype=_I64)
_EMPTY_BOUNDS: Bounds = (np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0))
# At most this many moving bodies are paired directly, every two of them (see SpatialHash.pairs).
SMALL = 48
# A box query tests the bounds of up to this many bodies directly, without the cell index: a look-up
# there cost 75-145 us of numpy calls, a bounds test 35-50 us up to 32,768 bodies (120 us at 65,536;
# measured 2026-11-26: a scene of n static unit tiles, a 4 x 4 box). The answer is the same
# either way: the index only narrows the candidates the bounds test decides. (The platformer's
# character stage: 916 -> 611 us a step, its controller's look-ups being most of it.)
DIRECT_QUERY = 16384


class _FewBodies:
    """The moving bodies of a :meth:`SpatialHash.pairs` call that paired them directly: what the
    queries read of them (their bounds; none is large)."""

    def __init__(self, bounds: Bounds) -> None:
        self.bounds = bounds
        self.n = bounds[0].shape[0]
        self.large = _EMPTY_I


_UPPER: dict[int, tuple[NDArray[np.int64], NDArray[np.int64]]] = {}


def _upper_pairs(n: int) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """``(i, j)``, every ``i < j < n`` (cached per ``n``)."""
    if n not in _UPPER:
        i, j = np.triu_indices(n, 1)
        _UPPER[n] = (i.astype(_I64), j.astype(_I64))
    return _UPPER[n]


def brute_force_pairs(
    minx: ArrayLike, miny: ArrayLike, maxx: ArrayLike, maxy: ArrayLike, static: ArrayLike | None = None,
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Reference answer by testing all N^2 pairs (numpy, in row blocks): ``(i, j)``, ``i < j``.

    Index pairs of strictly overlapping bounds, excluding static-static pairs, lexicographically
    sorted. For tests and benchmarks; O(N^2) time.
    """
    b = as_bounds(minx, miny, maxx, maxy)
    n = b[0].shape[0]
    st = np.zeros(n, dtype=bool) if static is None else np.asarray(static, dtype=bool).reshape(-1)
    if st.shape[0] != n:
        raise InvalidValue(f"static must have {n} entries, got {st.shape[0]}")
    i, j = overlap_pairs(b, b, upper=True)
    keep = ~(st[i] & st[j])
    return i[keep], j[keep]


def _as_ids(ids: ArrayLike, n: int) -> NDArray[np.int64]:
    a = np.asarray(ids).reshape(-1)
    if a.shape[0] != n:
        raise InvalidValue(f"ids must have {n} entries (one per body), got {a.shape[0]}")
    if a.dtype.kind not in "iu":
        if a.shape[0] == 0:
            return _EMPTY_I
        raise InvalidValue(f"ids must be integers, got dtype {a.dtype}")
    return a.astype(_I64, copy=False)


def _sorted_id_pairs(
    ia: NDArray[np.int64], ib: NDArray[np.int64],
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """``(lo, hi)`` of id pairs, ``lo < hi``, sorted lexicographically."""
    lo = np.minimum(ia, ib)
    hi = np.maximum(ia, ib)
    if lo.shape[0] == 0:
        return _EMPTY_I, _EMPTY_I
    if (lo == hi).any():
        k = int(lo[np.flatnonzero(lo == hi)[0]])
        raise InvalidValue(f"id {k} is given to two bodies; ids must be unique over static and moving")
    base = int(lo.min())
    span = int(hi.max()) - base
    if span < (1 << 31):
        packed = np.sort(((lo - base) << 32) | (hi - base))
        return (packed >> 32) + base, (packed & 0xFFFFFFFF) + base
    order = np.lexsort((hi, lo))
    return lo[order], hi[order]


class SpatialHash:
    """A uniform-grid broad phase for static bodies (entered once) and moving bodies (each step).

    ``cell_size``: the grid's cell side in world units; ``None`` picks about twice the median body
    extent at the first non-empty :meth:`set_static` or :meth:`pairs` call, then keeps it.

    Ids are the caller's integers (e.g. row numbers in its tables); they must be unique over the
    static and the moving bodies together. Nothing keeps a reference to the caller's arrays, so it
    may reuse and overwrite them between calls.
    """

    def __init__(self, cell_size: float | None = None) -> None:
        self._cell = None if cell_size is None else positive("cell_size", cell_size)
        self._static = CellIndex(_EMPTY_BOUNDS, 1.0)
        self._static_ids = _EMPTY_I
        self._static_extent: tuple[float, float, float, float] | None = None
        self._moving: StripSweep | _FewBodies = StripSweep(_EMPTY_BOUNDS, 1.0)
        self._moving_ids = _EMPTY_I
        self._moving_cells: CellIndex | None = None
        self._queries = 0
        #: how many bodies the last set_static / pairs call entered in the grid (or set aside as large)
        self.rehashed_last = 0

    @property
    def cell_size(self) -> float | None:
        """The cell side; ``None`` only while automatic and nothing has been built yet."""
        return self._cell

    def set_cell_size(self, cell_size: float) -> None:
        """Fix the cell side before anything is built (a caller that knows the scene better than
        the first build's bodies, e.g. both the movers and the tiles)."""
        if self._static.entries or self._moving.n:
            raise InvalidValue("set_cell_size must come before the first set_static or pairs call")
        self._cell = positive("cell_size", cell_size)

    def _choose_cell(self, bounds: Bounds) -> float:
        if self._cell is None:
            self._cell = grid.auto_cell_size(*bounds)
        return self._cell if self._cell is not None else 1.0

    # --- building ---------------------------------------------------------------------------------

    def set_static(self, minx: ArrayLike, miny: ArrayLike, maxx: ArrayLike, maxy: ArrayLike, ids: ArrayLike) -> None:
        """Enter the static bodies (replacing any earlier ones). Call again only when they change."""
        b = as_bounds(minx, miny, maxx, maxy)
        sids = _as_ids(ids, b[0].shape[0])
        self._static = CellIndex(b, self._choose_cell(b))
        self._static_ids = sids.copy()
        # The box around every static (None if some static is not finite, or there is none).
        with np.errstate(over="ignore"):  # a huge sum only makes the extent unknown
            fin = np.isfinite(b[0] + b[1] + b[2] + b[3])
        self._static_extent = (float(b[0].min()), float(b[1].min()), float(b[2].max()),
                               float(b[3].max())) if fin.size and fin.all() else None
        self.rehashed_last = b[0].shape[0]

    def pairs(
        self, minx: ArrayLike, miny: ArrayLike, maxx: ArrayLike, maxy: ArrayLike, ids: ArrayLike, *,
        moving_pairs: bool = True,
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """All moving-moving and moving-static pairs of strictly overlapping bounds.

        The arguments are this step's moving bodies. Returns ``(id_a, id_b)`` int64 arrays with
        ``id_a < id_b``, sorted lexicographically. The static bodies are not re-entered.
        ``moving_pairs=False`` gives only the moving-static pairs (e.g. awake bodies against a
        second hash holding the sleeping ones).
        """
        b = as_bounds(minx, miny, maxx, maxy)
        n = b[0].shape[0]
        # Up to SMALL bodies are paired directly, every two of them (cheaper than sorting them into
        # strips), the statics through the bodies near one: the same pairs as the strips give.
        few = n <= SMALL
        self._enter(b, ids, None if few else StripSweep(b, self._choose_cell(b)))
        mov, ids = self._moving, self._moving_ids

        out_a: list[NDArray[np.int64]] = []
        out_b: list[NDArray[np.int64]] = []
        if isinstance(mov, _FewBodies):  # (n <= SMALL)
            if moving_pairs and n > 1:
                i, j = _upper_pairs(n)
                ok = strict_overlap(*(v[i] for v in b), *(v[j] for v in b))
                out_a.append(ids[i[ok]])
                out_b.append(ids[j[ok]])
            self._near_static_pairs(b, ids, out_a, out_b)
        else:
            if moving_pairs:
                if mov.entries:
                    a, c = mov.self_pairs()
                    out_a.append(ids[a])
                    out_b.append(ids[c])
                if mov.large.shape[0]:
                    # large movers against every mover (each large-large pair once)
                    lg = mov.large
                    i, j = overlap_pairs(subset(b, lg), b)
                    i = lg[i]
                    is_large = np.zeros(mov.n, dtype=bool)
                    is_large[lg] = True
                    keep = ~is_large[j] | (i < j)
                    out_a.append(ids[i[keep]])
                    out_b.append(ids[j[keep]])
            if n and not self.outside_statics(float(b[0].min()), float(b[1].min()), float(b[2].max()),
                                              float(b[3].max())):  # (bodies all far from the level's tiles: none)
                self._cross_static(mov, b, ids, out_a, out_b)
        if not out_a:
            return _EMPTY_I, _EMPTY_I
        return _sorted_id_pairs(np.concatenate(out_a), np.concatenate(out_b))

    def enter_few(self, minx: ArrayLike, miny: ArrayLike, maxx: ArrayLike, maxy: ArrayLike, ids: ArrayLike) -> None:
        """Take the moving bodies as a :meth:`pairs` call does (for the queries and the overlay's
        cells), without pairing them: the caller paired them itself
        (:func:`direct_pairs`), from the geometry's bounds (float64 columns, never inverted: not
        checked again here, a step's broad phase calls this every step)."""
        b = np.array((minx, miny, maxx, maxy), dtype=np.float64)  # (the four copied at once, kept as they are)
        if self._cell is None or not isinstance(ids, np.ndarray) or ids.dtype != _I64 or ids.shape != b[0].shape:
            self._enter((b[0], b[1], b[2], b[3]), ids, None, copied=True)
            return
        # (the step's own call: int64 ids, one per body, a cell size chosen: _enter without its checks)
        self._take_moving(_FewBodies((b[0], b[1], b[2], b[3])), ids)

    def _enter(self, b: Bounds, ids: ArrayLike, strips: StripSweep | None, copied: bool = False) -> None:
        """Take the moving bodies of a step: swept into ``strips``, or (None) kept as they are,
        a few paired directly (``copied``: ``b`` is the caller's copy, kept); the cell size chosen
        from them if none was yet."""
        mids = _as_ids(ids, b[0].shape[0])
        self._choose_cell(b)
        self._take_moving(strips if strips is not None else _FewBodies(b if copied else (b[0].copy(), b[1].copy(),
                                                                                         b[2].copy(), b[3].copy())),
                          mids)

    def _take_moving(self, moving: StripSweep | _FewBodies, ids: NDArray[np.int64]) -> None:
        """The step's moving bodies ``moving`` (a copy of ``ids`` their ids) in place of the last
        step's, with nothing indexed for queries yet."""
        self._moving = moving
        self._moving_cells = None
        self._queries = 0
        self._moving_ids = ids.copy()
        self.rehashed_last = moving.n

    def static_pairs(
        self, minx: ArrayLike, miny: ArrayLike, maxx: ArrayLike, maxy: ArrayLike, ids: ArrayLike,
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """The pairs of the given bodies with the static ones, like ``pairs(..., moving_pairs=False)``
        but leaving the last :meth:`pairs` call's moving bodies (and queries on them) as they were."""
        b = as_bounds(minx, miny, maxx, maxy)
        out_a: list[NDArray[np.int64]] = []
        out_b: list[NDArray[np.int64]] = []
        self._near_static_pairs(b, _as_ids(ids, b[0].shape[0]), out_a, out_b)
        if not out_a:
            return _EMPTY_I, _EMPTY_I
        return _sorted_id_pairs(np.concatenate(out_a), np.concatenate(out_b))

    def _near_static_pairs(
        self, b: Bounds, ids: NDArray[np.int64], out_a: list[NDArray[np.int64]], out_b: list[NDArray[np.int64]],
    ) -> None:
        """Append the pairs of the bodies ``b`` (ids ``ids``) with the statics: each body looks in
        the statics' cells it covers (one compiled pass, :func:`~.static_cells.static_cross`)."""
        stat = self._static
        if b[0].shape[0] == 0 or stat.n == 0:
            return
        # (one compiled pass over the statics' cells: static_cells.static_cross)
        i, s = static_cross(*(np.ascontiguousarray(v) for v in b), stat.cell, stat.x0, stat.y0, stat.wx, stat.wy,
                            stat.ukey, stat.bound, stat.dense, stat.body, *stat.ebounds, stat.large, *stat.bounds)
        if i.size:
            out_a.append(ids[i])
            out_b.append(self._static_ids[s])

    def outside_statics(self, minx: float, miny: float, maxx: float, maxy: float) -> bool:
        """Whether the box surely meets no static body: it lies outside the box around every static
        (touching it counts as outside), or there are none. ``False`` when not sure."""
        ext = self._static_extent
        if self._static.n == 0:
            return True
        if ext is None or not all(math.isfinite(v) for v in (minx, miny, maxx, maxy)):
            return False
        return not (maxx > ext[0] and minx < ext[2] and maxy > ext[1] and miny < ext[3])

    def near_statics(self, minx: ArrayLike, miny: ArrayLike, maxx: ArrayLike, maxy: ArrayLike) -> NDArray[np.bool_]:
        """Mask of the boxes that may strictly overlap a static body (a cheap superset test)."""
        b = as_bounds(minx, miny, maxx, maxy)
        return self._near_statics(b)

    def _near_statics(self, b: Bounds) -> NDArray[np.bool_]:
        """Mask of the boxes that may meet a static body: one shares a cell they need (no false
        negatives: strictly overlapping bounds always share a cell), a large static overlaps them,
        or they span many cells or are not finite (not looked at closely). Boxes outside the box
        around every static are dismissed first."""
        stat, ext = self._static, self._static_extent
        with np.errstate(over="ignore"):  # a huge sum only makes a box "not looked at closely"
            keep = ~np.isfinite(b[0] + b[1] + b[2] + b[3])
        if stat.n == 0:
            return keep
        ok = ~keep
        if ext is not None:
            ok &= (b[2] > ext[0]) & (b[0] < ext[2]) & (b[3] > ext[1]) & (b[1] < ext[3])
        cand = np.flatnonzero(ok)
        if cand.size == 0:
            return keep
        cb = subset(b, cand)
        near = np.zeros(cand.size, dtype=bool)
        if stat.large.shape[0]:
            i, _ = overlap_pairs(cb, subset(stat.bounds, stat.large))
            near[i] = True
        if stat.entries:
            with np.errstate(over="ignore"):
                cx0, cx1 = grid.cell_range(cb[0], cb[2], stat.cell)
                cy0, cy1 = grid.cell_range(cb[1], cb[3], stat.cell)
            near |= (cx1 - cx0 > 1) | (cy1 - cy0 > 1)
            inside = np.flatnonzero(~near & (cx1 >= stat.x0) & (cx0 < stat.x0 + stat.wx)
                                    & (cy1 >= stat.y0) & (cy0 < stat.y0 + stat.wy))  # the statics' grid
            if inside.size:
                cx0, cx1, cy0, cy1 = cx0[inside], cx1[inside], cy0[inside], cy1[inside]
                for cx, cy in ((cx0, cy0), (cx1, cy0), (cx0, cy1), (cx1, cy1)):  # all their cells (<= 2 x 2)
                    lo, hi = stat.lookup(cx, cy)
                    near[inside[hi > lo]] = True
        keep[cand[near]] = True
        return keep

    def _cross_static(
        self, mov: StripSweep, b: Bounds, ids: NDArray[np.int64], out_a: list[NDArray[np.int64]],
        out_b: list[NDArray[np.int64]],
    ) -> None:
        """Append the pairs of the swept bodies ``mov`` (bounds ``b``, ids ``ids``) with the statics."""
        stat, sids = self._static, self._static_ids
        if mov.entries and stat.entries:
            m, s = mov.cross_pairs(stat)
            out_a.append(ids[m])
            out_b.append(sids[s])
        if mov.large.shape[0]:
            # large movers against every static
            lg = mov.large
            i, s = overlap_pairs(subset(b, lg), stat.bounds)
            out_a.append(ids[lg[i]])
            out_b.append(sids[s])
        if stat.large.shape[0] and mov.n:
            # large statics against the small movers (large movers were done above)
            small = np.ones(mov.n, dtype=bool)
            small[mov.large] = False
            sm = np.flatnonzero(small)
            s, m = overlap_pairs(subset(stat.bounds, stat.large), subset(b, sm))
            out_a.append(sids[stat.large[s]])
            out_b.append(ids[sm[m]])

    # --- queries ----------------------------------------------------------------------------------

    def _moving_index(self, for_query: bool = True) -> CellIndex | None:
        """The moving bodies in cells, built on demand: a query's first few calls after a step test
        all moving bodies directly (cheaper than building cells for one query)."""
        if self._moving_cells is None:
            self._queries += for_query
            if for_query and (self._queries <= 3 or self._moving.n < 1024):
                return None
            self._moving_cells = CellIndex(self._moving.bounds, self._cell or 1.0, copy=False)
        return self._moving_cells

    def _sets(self) -> tuple[tuple[CellIndex | None, Bounds, NDArray[np.int64]], ...]:
        """``(index or None, bounds, ids)`` of the static and the moving bodies."""
        return (
            (self._static, self._static.bounds, self._static_ids),
            (self._moving_index(), self._moving.bounds, self._moving_ids),
        )

    def query_box(self, minx: float, miny: float, maxx: float, maxy: float) -> NDArray[np.int64]:
        """Sorted ids of the static bodies and of the last :meth:`pairs` call's moving bodies whose
        bounds strictly overlap the box ``[minx, maxx] x [miny, maxy]`` (touching does not count)."""
        x0, y0 = finite("minx", minx), finite("miny", miny)
        x1, y1 = finite("maxx", maxx), finite("maxy", maxy)
        if x1 < x0 or y1 < y0:
            raise InvalidValue(f"box max ({x1!r}, {y1!r}) is below its min ({x0!r}, {y0!r})")
        box = (x0, y0, x1, y1)
        found = []
        for index, bounds, ids in self._sets():
            if bounds[0].shape[0] == 0:
                continue
            c = None if index is None or bounds[0].shape[0] <= DIRECT_QUERY else self._box_candidates(index, box)
            if c is None:
                ok = strict_overlap(*bounds, *box)
                found.append(ids[ok])
            else:
                ok = strict_overlap(*subset(bounds, c), *box)
                found.append(ids[c[ok]])
        return distinct(np.concatenate(found)) if found else _EMPTY_I

    def _box_candidates(self, index: CellIndex, box: tuple[float, float, float, float]) -> NDArray[np.int64] | None:
        """Sorted numbers of the bodies in the cells under the box and of the large bodies; ``None``
        when the box covers more cells than the index has entries (then test every body)."""
        cell = cast(float, self._cell)  # (bodies were entered in the index: a cell size was chosen)
        cx0, cx1 = (int(v) for v in grid.cell_index(np.array([box[0], box[2]]), cell))
        cy0, cy1 = (int(v) for v in grid.cell_index(np.array([box[1], box[3]]), cell))
        gx0, gx1 = max(cx0, index.x0), min(cx1, index.x0 + index.wx - 1)
        gy0, gy1 = max(cy0, index.y0), min(cy1, index.y0 + index.wy - 1)
        nx, ny = max(0, gx1 - gx0 + 1), max(0, gy1 - gy0 + 1)
        if nx * ny > index.entries:
            return None
        cy = np.repeat(np.arange(gy0, gy0 + ny, dtype=_I64), nx)  # row-major order
        cx = np.tile(np.arange(gx0, gx0 + nx, dtype=_I64), ny)
        return distinct(np.concatenate([index.large, index.bodies_in_cells(cx, cy)]))

    def cells_in_use(self) -> NDArray[np.int64]:
        """``(M, 2)`` int64 (column, row) of the cells holding a static body or a moving body of the
        last :meth:`pairs` call, sorted; cell ``(c, r)`` spans ``[c, c+1] x [r, r+1]`` times
        :attr:`cell_size`. Large bodies (see the module notes) occupy no cell."""
        cols, rows = [], []
        # (not for a query, the moving bodies' index is always built)
        for index in (self._static, cast(CellIndex, self._moving_index(for_query=False))):
            c, r = index.used_cells()
            cols.append(c)
            rows.append(r)
        cells = np.stack([np.concatenate(cols), np.concatenate(rows)], axis=1)
        return np.unique(cells, axis=0) if cells.shape[0] else cells.reshape(0, 2)



#: A step pairs its moving bodies with every other hitbox directly (one compiled pass, no hash)
#: when that is this many tests or fewer (moving x rows): a platformer's dozen movers among a few
#: hundred tiles, a pyramid of 210 boxes. The hash's answer is the same pairs. (Measured
#: 2026-11-27, the broad phase stage a step, hash -> direct: the physics toy's 62 bodies 286 -> 92
#: us, a pile of 100 boxes 268 -> 80, a pyramid of 210 334 -> 180; about 2 ns a test. Since, many
#: movers are swept rather than tested in pairs: :data:`SWEEP_FROM`.)
DIRECT_PAIRS = 1 << 16


#: Above this many tests (moving x rows), :func:`direct_pairs` sweeps the bodies in order of their
#: left edges instead of testing every mover against every row: a pyramid of 210 boxes 44,000 tests
#: to about 6,000. (Below it, sorting the rows costs more than the tests it saves.)
SWEEP_FROM = 1 << 12


@kernel
def direct_pairs(moving, kind, body, asleep, entity, minx, miny, maxx, maxy, static_kind, lut, layer, mask,
                 layers_open):  # pragma: no cover
    """The pairs of every moving row (``moving``, sorted rows) with every other hitbox row whose
    bounds strictly overlap its own (touching is no overlap): the static ones, the sleeping ones and
    the moving ones (each moving pair once, found from its lower row: the higher one must have a
    hitbox), whose layers and masks let them meet (unless ``layers_open``: every pair does). As
    the rows of one int64 block, ``(entities a, entities b, rows a, rows b)``, a < b, sorted by
    pair key (``entity a << 32 | entity b``), the rows looked up in ``lut`` (entity -> row,
    ``BodyStore.row_table``).

    Few tests (:data:`SWEEP_FROM`): every mover against every such row. More: the movers sorted by
    their left edges are swept against each other (each one meets those whose left edge lies before
    its right edge), and each mover looks among the other rows, sorted by left edge too, only at
    those whose left edge lies within the widest of them to its left. Either way the rows' bounds
    are first laid side by side, in the order they are met, so that the inner loops read them in
    turn; the keys are sorted at the end."""
    n = kind.size
    rank = np.full(n, -1, dtype=np.int64)  # a mover's place in ``moving``; -1 for the others
    for k in range(moving.size):
        rank[moving[k]] = k
    rows = np.empty(n, dtype=np.int64)  # the rows a mover may pair with that do not move
    c = np.int64(0)  # (not a literal 0: _pairs_from would compile twice)
    for r in range(n):
        if kind[r] >= 0 and rank[r] < 0 and (body[r] == static_kind or asleep[r]):
            rows[c] = r
            c += 1
    mv = moving.size
    swept = mv * (mv + c) > SWEEP_FROM
    # the movers' bounds side by side (by left edge when swept), then the still rows' (likewise)
    at = np.empty(mv + c, dtype=np.int64)
    widest = 0.0
    if swept:
        left = np.empty(mv)
        for k in range(mv):
            left[k] = minx[moving[k]]
        order = stable_argsort(left)
        for k in range(mv):
            at[k] = moving[order[k]]
        left = np.empty(c)
        for q in range(c):
            left[q] = minx[rows[q]]
            widest = max(widest, maxx[rows[q]] - minx[rows[q]])
        order = stable_argsort(left)
        for q in range(c):
            at[mv + q] = rows[order[q]]
    else:
        for k in range(mv + c):
            at[k] = moving[k] if k < mv else rows[k - mv]
    bx0, by0, bx1, by1 = np.empty(mv + c), np.empty(mv + c), np.empty(mv + c), np.empty(mv + c)
    for k in range(mv + c):
        r = at[k]
        bx0[k], by0[k], bx1[k], by1[k] = minx[r], miny[r], maxx[r], maxy[r]
    out = np.empty(max(16, 2 * mv), dtype=np.int64)
    k, m = np.int64(0), np.int64(0)  # (np.int64: literal 0s would compile _pairs_from twice)
    while True:
        k, m = _pairs_from(k, mv, c, swept, widest, at, bx0, by0, bx1, by1, kind, entity, out, m, layer, mask,
                           layers_open)
        if k == mv:
            break
        grown = np.empty(2 * out.size, dtype=np.int64)
        for q in range(m):  # (a loop: a slice assignment compiles numba's shape checks, seconds)
            grown[q] = out[q]
        out = grown
    order = argsort_ints(out[:m])
    pairs = np.empty((4, m), dtype=np.int64)  # (one block, its rows the columns: one array handed back)
    for q in range(m):
        key = out[order[q]]
        a, b = key >> 32, key & 0xFFFFFFFF
        pairs[0, q], pairs[1, q], pairs[2, q], pairs[3, q] = a, b, lut[a], lut[b]
    return pairs


@leaf
def _pairs_from(k, mv, c, swept, widest, at, bx0, by0, bx1, by1, kind, entity, out, m, layer, mask,
                layers_open):  # pragma: no cover
    """:func:`direct_pairs`' keys of the movers from the ``k``-th on, written to ``out`` from ``m``
    on: ``(mv, the keys' end)``, or where ``out`` was too small for a mover's keys, ``(that mover,
    the keys' end before it)``. (Apart, without reference counting: numba counted the growing key
    array's references in every test, five times the tests' own cost.)"""
    while k < mv:
        i = at[k]
        ax0, ay0, ax1, ay1 = bx0[k], by0[k], bx1[k], by1[k]
        # the movers after this one (in row order, or by left edge: then up to the first whose
        # left edge is past this one's right edge), then the still rows (all, or those whose left
        # edge lies between this one's left edge less the widest of them and its right edge; the
        # margin covers the rounding of ``widest`` and of the difference)
        first = mv
        if swept:
            reach = ax0 - widest
            first = mv + lower_bound(bx0[mv:], reach - (abs(reach) + widest) * 1e-12)
        j = m
        for part in range(2):
            lo, hi = (k + 1, mv) if part == 0 else (first, mv + c)
            for q in range(lo, hi):
                if swept and bx0[q] >= ax1:
                    break
                if ax1 > bx0[q] and bx1[q] > ax0 and ay1 > by0[q] and by1[q] > ay0:
                    r = at[q]
                    if q < mv and kind[max(i, r)] < 0:
                        continue
                    if not layers_open and ((layer[i] & mask[r]) == 0 or (layer[r] & mask[i]) == 0):
                        continue
                    if j == out.size:
                        return k, m
                    out[j] = (min(entity[i], entity[r]) << 32) | max(entity[i], entity[r])
                    j += 1
        m = j
        k += 1
    return k, m
