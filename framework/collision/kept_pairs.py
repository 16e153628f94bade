"""Candidate pairs kept between steps, from fat bounds: :class:`KeptPairs`.

Every step the broad phase wants the pairs of hitboxes whose bounds strictly overlap, each with a
moving body in it. Where bodies barely move (a pile at rest, a stack) those pairs hardly change,
yet hashing a thousand movers afresh cost some 600 us a step. So, as Box2D keeps its proxies in
fat boxes, each mover is given fat bounds (its bounds grown by an eighth of its larger side) and
the pairs whose fat bounds overlap are found by the spatial hash once. A step then only checks
that every mover is still inside its fat bounds and keeps the candidates whose bounds overlap now
(compiled passes): a pair whose bounds overlap has fat bounds that overlap, so no pair is
missed, and the answer is the hash's pairs in the hash's order (sorted by entity pair). Movers
leaving their fat bounds (at most half of them in a step: a crowd drifting, where every step some
do) get new fat bounds, and only their candidates are found again: with every mover, through a
grid of all the movers' fat bounds made for the purpose (a counting sort by cell), and with the
statics and sleepers through their hashes. More movers leaving, or any change to the rows, the
statics or who sleeps, builds the candidates again.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from ..compiled import kernel, leaf
from .grid import Bounds

__all__ = ["KeptPairs"]

#: A mover's fat bounds: its bounds grown on every side by this fraction of its larger side.
MARGIN = 0.125
#: The most movers (a share of them) that may leave their fat bounds in a step for the candidates
#: to be brought up to date (:meth:`KeptPairs.update`) rather than built again.
UPDATE_SHARE = 0.5
#: The most grid cells a mover's fat bounds may cover for an update (more: build again).
MOST_CELLS = 64


@kernel
def _grown(moving, minx, miny, maxx, maxy, margin):  # pragma: no cover - compiled
    """The movers' fat bounds: each side moved out by ``margin`` times the larger side."""
    k = moving.size
    fx0, fy0, fx1, fy1 = np.empty(k), np.empty(k), np.empty(k), np.empty(k)
    for q in range(k):
        r = moving[q]
        w, h = maxx[r] - minx[r], maxy[r] - miny[r]
        m = margin * (w if w > h else h)
        fx0[q], fy0[q], fx1[q], fy1[q] = minx[r] - m, miny[r] - m, maxx[r] + m, maxy[r] + m
    return fx0, fy0, fx1, fy1


@kernel
def _escaped(moving, minx, miny, maxx, maxy, fx0, fy0, fx1, fy1):  # pragma: no cover - compiled
    """The movers (places in ``moving``) whose bounds no longer lie within their fat bounds
    (``f*[k]``: mover ``k``'s)."""
    out = np.empty(moving.size, dtype=np.int64)
    m = 0
    for k in range(moving.size):
        r = moving[k]
        if not (minx[r] >= fx0[k] and miny[r] >= fy0[k] and maxx[r] <= fx1[k] and maxy[r] <= fy1[k]):
            out[m] = k
            m += 1
    return out[:m]


@leaf
def _cell(v, inv):  # pragma: no cover - compiled
    """The grid cell along one axis of coordinate ``v`` (``inv``: one over the cell size)."""
    return np.int64(math.floor(v * inv))


@kernel
def _grid_candidates(left, moving, fx0, fy0, fx1, fy1, cell, entity, most_cells):  # pragma: no cover
    """The pair keys (``entity`` of the two rows, the lower first; not sorted) of each mover of
    ``left`` (places in ``moving``) with every mover whose fat bounds strictly overlap its own, each
    pair once; and whether it could tell (False where a mover's fat bounds span more than
    ``most_cells`` cells, or the movers are spread over many more cells than they fill: then build
    the candidates instead). Every mover is entered into the cells of side ``cell`` its fat bounds
    cover (a counting sort over the cells of the box around them all), and each of ``left`` looks
    in its own cells only; a pair is reported in the one cell holding the lower left corner of the
    two fat bounds' overlap, which both cover."""
    k = moving.size
    none = np.empty(0, dtype=np.int64)
    inv = 1.0 / cell
    lo = np.empty((2, k), dtype=np.int64)
    hi = np.empty((2, k), dtype=np.int64)
    reach = 2.0**40
    total = 0
    for i in range(k):
        a, b, c, d = fx0[i] * inv, fy0[i] * inv, fx1[i] * inv, fy1[i] * inv
        if not (abs(a) < reach and abs(b) < reach and abs(c) < reach and abs(d) < reach):
            return none, False
        lo[0, i], lo[1, i], hi[0, i], hi[1, i] = _cell(fx0[i], inv), _cell(fy0[i], inv), _cell(fx1[i], inv), _cell(
            fy1[i], inv)
        cells = (hi[0, i] - lo[0, i] + 1) * (hi[1, i] - lo[1, i] + 1)
        if cells > most_cells:
            return none, False
        total += cells
    x0, y0, x1, y1 = lo[0].min(), lo[1].min(), hi[0].max(), hi[1].max()
    wide, tall = x1 - x0 + 1, y1 - y0 + 1
    if wide * tall > max(8 * total, 1 << 16):
        return none, False
    start = np.zeros(wide * tall + 1, dtype=np.int64)
    for i in range(k):
        for cx in range(lo[0, i], hi[0, i] + 1):
            for cy in range(lo[1, i], hi[1, i] + 1):
                start[(cx - x0) * tall + (cy - y0) + 1] += 1
    for c in range(wide * tall):
        start[c + 1] += start[c]
    who = np.empty(total, dtype=np.int64)
    fill = start[:-1].copy()
    for i in range(k):
        for cx in range(lo[0, i], hi[0, i] + 1):
            for cy in range(lo[1, i], hi[1, i] + 1):
                c = (cx - x0) * tall + (cy - y0)
                who[fill[c]] = i
                fill[c] += 1
    gone = np.zeros(k, dtype=np.bool_)
    for q in range(left.size):
        gone[left[q]] = True
    out = np.empty(max(16, 4 * left.size), dtype=np.int64)
    n = 0
    for q in range(left.size):
        i = left[q]
        a0, b0, a1, b1 = fx0[i], fy0[i], fx1[i], fy1[i]
        for cx in range(lo[0, i], hi[0, i] + 1):
            for cy in range(lo[1, i], hi[1, i] + 1):
                c = (cx - x0) * tall + (cy - y0)
                for t in range(start[c], start[c + 1]):
                    j = who[t]
                    if j == i or (gone[j] and j < i):  # (two movers that both left: the pair once)
                        continue
                    if not (fx1[j] > a0 and a1 > fx0[j] and fy1[j] > b0 and b1 > fy0[j]):
                        continue
                    if _cell(max(a0, fx0[j]), inv) != cx or _cell(max(b0, fy0[j]), inv) != cy:
                        continue  # (reported in the cell of the overlap's lower left corner)
                    if n == out.size:
                        grown = np.empty(2 * out.size, dtype=np.int64)
                        for e in range(n):
                            grown[e] = out[e]
                        out = grown
                    ea, eb = entity[moving[i]], entity[moving[j]]
                    out[n] = (ea << 32) | eb if ea < eb else (eb << 32) | ea
                    n += 1
    return out[:n], True


@kernel
def _merged(keys, ra, rb, gone, more, lut):  # pragma: no cover - compiled
    """The candidates ``keys, ra, rb`` (sorted by key) of neither of whose rows ``gone`` is set,
    merged with the pair keys ``more`` (sorted, none of them among those): ``(keys, ra, rb)``, sorted
    by key, the rows of ``more``'s looked up in ``lut`` (entity -> row, ``BodyStore.row_table``)."""
    stay = np.empty(keys.size, dtype=np.bool_)
    m = 0
    for k in range(keys.size):
        stay[k] = not (gone[ra[k]] or gone[rb[k]])
        if stay[k]:
            m += 1
    t = m + more.size
    out = np.empty((3, t), dtype=np.int64)
    i = j = 0
    for o in range(t):
        while i < keys.size and not stay[i]:
            i += 1
        if j == more.size or (i < keys.size and keys[i] < more[j]):
            out[0, o], out[1, o], out[2, o] = keys[i], ra[i], rb[i]
            i += 1
        else:
            key = more[j]
            out[0, o], out[1, o], out[2, o] = key, lut[key >> 32], lut[key & 0xFFFFFFFF]
            j += 1
    return out


@kernel
def _overlapping(keys, ra, rb, minx, miny, maxx, maxy):  # pragma: no cover - compiled
    """The candidates whose bounds strictly overlap now, in their order: the rows of one block,
    ``(keys, ra, rb)``."""
    out = np.empty((3, ra.size), dtype=np.int64)
    m = 0
    for k in range(ra.size):
        i, j = ra[k], rb[k]
        if maxx[i] > minx[j] and maxx[j] > minx[i] and maxy[i] > miny[j] and maxy[j] > miny[i]:
            out[0, m], out[1, m], out[2, m] = keys[k], i, j
            m += 1
    return out[:, :m]


class KeptPairs:
    """The broad phase's candidate pairs, kept while the rows, statics and sleepers stay as they
    were and every mover stays inside its fat bounds.

    Where most bodies keep leaving their fat bounds (every body moving its own size a step),
    building the candidates each step costs more than hashing the bounds: after two builds in a
    row the stage hashes plainly for :data:`REST` steps before trying again."""

    #: steps of plain hashing after two builds in a row
    REST = 4
    # (class defaults too: a snapshot file saved before updates existed restores without them)
    updates = 0
    _left = np.zeros(0, dtype=np.int64)

    def __init__(self) -> None:
        self._key: tuple[int, ...] | None = None
        self._moving = np.zeros(0, dtype=np.int64)
        self._keys = np.zeros(0, dtype=np.int64)
        self._ra = np.zeros(0, dtype=np.int64)
        self._rb = np.zeros(0, dtype=np.int64)
        self._fat: Bounds = (np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0))
        self._built_last = False  # the last step built the candidates
        self._plain = 0  # steps left of plain hashing
        self._left = np.zeros(0, dtype=np.int64)  # the movers that left their fat bounds (choose: "update")
        #: how many times the candidates were built, and brought up to date (for tests and reports)
        self.builds = 0
        self.updates = 0

    def choose(self, key: tuple[int, ...], moving: NDArray[np.int64], bounds: Bounds,
               ) -> str:
        """This step's way: ``"kept"`` (the candidates hold: ``key``, the rows, statics and sleepers
        they were built for, unchanged, the same movers, each inside its fat bounds), ``"update"``
        (the same, but some movers, at most :data:`UPDATE_SHARE` of them, left their fat bounds:
        :meth:`update`), ``"build"`` (build them again) or ``"plain"`` (hash the bounds: see the
        class notes)."""
        if self._plain > 0:
            self._plain -= 1
            return "plain"
        minx, miny, maxx, maxy = bounds
        fx0, fy0, fx1, fy1 = self._fat
        if key == self._key and moving.size == self._moving.size and bool((moving == self._moving).all()):
            left = _escaped(moving, minx, miny, maxx, maxy, fx0, fy0, fx1, fy1)
            if left.size == 0:
                self._built_last = False
                return "kept"
            if left.size <= UPDATE_SHARE * moving.size:
                self._left = left
                return "update"
        self._key = None
        if self._built_last:  # two builds in a row: hash plainly for a while, then try again
            self._built_last = False
            self._plain = self.REST - 1
            return "plain"
        return "build"

    def fat(self, moving: NDArray[np.int64], bounds: Bounds,
            ) -> Bounds:
        """The movers' fat bounds (in the order of ``moving``), to build the candidates from."""
        minx, miny, maxx, maxy = bounds
        fx0, fy0, fx1, fy1 = _grown(moving, minx, miny, maxx, maxy, MARGIN)
        return fx0, fy0, fx1, fy1

    def keep(self, key: tuple[int, ...], moving: NDArray[np.int64], fat: Bounds,
             keys: NDArray[np.int64], ra: NDArray[np.int64], rb: NDArray[np.int64]) -> None:
        """Keep the candidates built from ``fat`` (sorted pair keys and their rows)."""
        self._key, self._moving, self._fat = key, moving.copy(), fat
        self._keys, self._ra, self._rb = keys, ra, rb
        self._built_last = True
        self.builds += 1

    def update(self, bounds: Bounds, entity: NDArray[np.int64], cell: float | None,
               others: Callable[[Bounds, NDArray[np.int64]], NDArray[np.int64]],
               lut: NDArray[np.int64]) -> bool:
        """Bring the candidates up to date where :meth:`choose` said ``"update"``: the movers that
        left their fat bounds get new ones where they are now, their old pairs go, and their pairs
        come with every mover whose fat bounds overlap theirs (:func:`_grid_candidates`, a grid of
        side ``cell``) and with the statics and sleepers (``others(their fat bounds, their
        entities)``: pair keys). Every pair of movers whose fat bounds overlap stays a candidate (it
        was found when the later of the two got its fat bounds), so no pair is missed, and what
        :meth:`overlapping` answers is what it answers after a build. ``entity``: the store's
        column; ``lut``: entity -> row (``BodyStore.row_table``). False, the candidates no longer
        usable, where the grid cannot take the movers (build them again)."""
        left, self._left = self._left, np.zeros(0, dtype=np.int64)
        if cell is None:
            self._key = None
            return False
        minx, miny, maxx, maxy = bounds
        fx0, fy0, fx1, fy1 = self._fat
        rows = self._moving[left]
        fx0[left], fy0[left], fx1[left], fy1[left] = _grown(rows, minx, miny, maxx, maxy, MARGIN)
        mine, ok = _grid_candidates(left, self._moving, fx0, fy0, fx1, fy1, cell, entity, MOST_CELLS)
        if not ok:
            self._key = None
            return False
        gone = np.zeros(entity.size, dtype=bool)
        gone[rows] = True
        more = others((fx0[left], fy0[left], fx1[left], fy1[left]), entity[rows])
        new = np.sort(np.concatenate([mine, more]))
        self._keys, self._ra, self._rb = _merged(self._keys, self._ra, self._rb, gone, new, lut)
        self._built_last = False
        self.updates += 1
        return True

    def overlapping(self, bounds: Bounds,
                    ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
        """The kept candidates whose bounds strictly overlap now: ``(keys, ra, rb)``."""
        minx, miny, maxx, maxy = bounds
        keys, ra, rb = _overlapping(self._keys, self._ra, self._rb, minx, miny, maxx, maxy)
        return keys, ra, rb
