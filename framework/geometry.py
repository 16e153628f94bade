"""Per-step geometry of the hitboxes, as columns: hitbox origins, bounds, polygon outlines and
capsules' half segments. A segment's outline (its two ends) is kept with the polygons'.

Derived from the store each step for the rows that can move; static rows are derived once and
cached until the static set changes.
"""

from __future__ import annotations

import numpy as np

from .arrays import F64Array, I64Array, IntpArray
from .compiled import kernel
from .shapes import Capsule, ChainSegment, Polygon, Segment
from .store import KIND_AABB, KIND_CAPSULE, KIND_POLYGON, KIND_SEGMENT, BodyStore

__all__ = ["Geometry", "widen_down", "widen_up"]

_TINY = 5e-324  # the smallest subnormal: the step away from 0


def _ulp_step(v: F64Array) -> F64Array:
    """``|v| * 2**-52`` (between one and two ulps of ``v``), at least the smallest subnormal (which
    moves 0 and subnormals). (Not the sum of the two: below about 1e-292 the product is itself
    subnormal, and rounded up it plus the smallest subnormal made three ulps.)"""
    step = np.abs(v)
    step *= 2.0**-52
    np.maximum(step, _TINY, out=step)
    return step


def widen_down(v: F64Array, out: F64Array | None = None) -> F64Array:
    """``v`` lowered by one or two ulps (at least to ``np.nextafter(v, -inf)``), by arithmetic:
    several times faster than ``nextafter``. The rounded difference ``v - step`` lies one or two
    ulps below ``v``; -inf stays -inf (and a lower bound is never +inf: it is at most the
    position)."""
    return np.subtract(v, _ulp_step(v), out=out)


def widen_up(v: F64Array, out: F64Array | None = None) -> F64Array:
    """``v`` raised by one or two ulps (see :func:`widen_down`)."""
    return np.add(v, _ulp_step(v), out=out)


@kernel
def _place(rows, x, y, ox, oy, kind, hw, hh, radius, cos, sin, local, slot, world_poly, cap_half, cap_ux, cap_uy, hx,
           hy, minx, maxx, miny, maxy, has_offset):  # pragma: no cover - compiled
    """Origins and bounds of ``rows`` from their poses, with ``cos``/``sin`` of their rotations
    already current: an offset hitbox's origin is its position plus the offset turned; a polygon's
    or segment's outline is turned into ``world_poly`` (about the hitbox origin, padded vertices
    included) and bounds it; a capsule's half segment ``(0, h)`` turned, grown by the radius;
    a box or circle is its origin -+ its half extents. Each bound is then widened by one or two
    ulps (:func:`widen_down`, :func:`widen_up`): the same arithmetic, so the same bits."""
    for i in range(rows.size):
        r = rows[i]
        px, py = x[r], y[r]
        if has_offset:
            if ox[r] != 0.0 or oy[r] != 0.0:
                co, so = cos[r], sin[r]
                px = px + (co * ox[r] - so * oy[r])
                py = py + (so * ox[r] + co * oy[r])
            hx[r], hy[r] = px, py
        k = kind[r]
        if k == KIND_POLYGON or k == KIND_SEGMENT:
            s = slot[r]
            cc, ss = cos[r], sin[r]
            lo_x = hi_x = lo_y = hi_y = 0.0
            for j in range(local.shape[1]):
                wx = cc * local[r, j, 0] - ss * local[r, j, 1]
                wy = ss * local[r, j, 0] + cc * local[r, j, 1]
                world_poly[s, j, 0], world_poly[s, j, 1] = wx, wy
                if j == 0 or wx < lo_x:
                    lo_x = wx
                if j == 0 or wx > hi_x:
                    hi_x = wx
                if j == 0 or wy < lo_y:
                    lo_y = wy
                if j == 0 or wy > hi_y:
                    hi_y = wy
            lx, hx_, ly, hy_ = px + lo_x, px + hi_x, py + lo_y, py + hi_y
        elif k == KIND_CAPSULE:
            h = cap_half[r]
            ux, uy = -(sin[r] * h), cos[r] * h
            cap_ux[r], cap_uy[r] = ux, uy
            ex, ey = abs(ux) + radius[r], abs(uy) + radius[r]
            lx, hx_, ly, hy_ = px - ex, px + ex, py - ey, py + ey
        else:
            lx, hx_, ly, hy_ = px - hw[r], px + hw[r], py - hh[r], py + hh[r]
        minx[r], maxx[r] = lx - _ulp(lx), hx_ + _ulp(hx_)
        miny[r], maxy[r] = ly - _ulp(ly), hy_ + _ulp(hy_)


@kernel
def _ulp(v):  # pragma: no cover - compiled
    """:func:`_ulp_step` of one float (NaN stays NaN, as ``np.maximum`` keeps it)."""
    step = abs(v) * 2.0**-52
    return _TINY if step < _TINY else step


class Geometry:
    """Hitbox origins ``hx, hy``, bounds and outlines of every row with a hitbox; for capsule rows
    the half segment ``cap_ux, cap_uy`` (its ends are the origin -+ it), turned as the transform."""

    def __init__(self) -> None:
        self.version = -1
        self.local = np.zeros((0, 4, 2))  # padded local outlines, one per row (polygon rows only)
        self.count = np.zeros(0, dtype=np.int64)
        self.poly_rows = np.zeros(0, dtype=np.int64)
        self.cap_rows = np.zeros(0, dtype=np.int64)
        self.cap_half = np.zeros(0)  # per row: a capsule's half length (0 elsewhere)
        self.K = 4
        self.segments = False  # whether some rows are segments (outlines of two points)
        self.chains = False  # whether some segments are chain segments (then the two below are filled)
        self.is_chain = np.zeros(0, dtype=bool)  # per row: a chain segment
        self.ghosts = np.zeros((0, 2, 2))  # per chain row: its ghost vertices, local (ghost1, ghost2)

    def rebuild_tables(self, store: BodyStore) -> None:
        """Re-read the polygon outlines after a structural change."""
        n = store.n
        self.segments = bool((store.kind == KIND_SEGMENT).any())
        # Segments are outlines of two points, kept with the polygons' (only where a scene has some).
        outlined = (store.kind == KIND_POLYGON) | (store.kind == KIND_SEGMENT) if self.segments else \
            store.kind == KIND_POLYGON
        self.poly_rows = np.flatnonzero(outlined)
        shapes: list[Polygon | Segment] = [store.shapes[r] for r in self.poly_rows.tolist()]  # as the columns know them
        K = max([4] + [len(s.points) for s in shapes if isinstance(s, Polygon)])
        local = np.zeros((n, K, 2))
        count = np.zeros(n, dtype=np.int64)
        self.is_chain = np.zeros(n, dtype=bool)
        if self.segments:
            chain_rows = [r for r, s in zip(self.poly_rows.tolist(), shapes) if isinstance(s, ChainSegment)]
            self.is_chain[chain_rows] = True
            self.ghosts = np.zeros((n, 2, 2))
            for r in chain_rows:
                self.ghosts[r] = (store.shapes[r].ghost1, store.shapes[r].ghost2)
        self.chains = bool(self.is_chain.any())
        for r, s in zip(self.poly_rows.tolist(), shapes):
            pts = np.asarray(s.points if isinstance(s, Polygon) else (s.a, s.b))
            m = len(pts)
            local[r, :m] = pts
            local[r, m:] = pts[-1]  # pad by repeating the last vertex
            count[r] = m
        self.local, self.count, self.K = local, count, K
        self.cap_rows = np.flatnonzero(store.kind[:n] == KIND_CAPSULE)
        self.cap_half = np.zeros(n)
        caps: list[Capsule] = [store.shapes[r] for r in self.cap_rows.tolist()]
        self.cap_half[self.cap_rows] = [c.half_length for c in caps]
        self.version = store.version

    def update(self, store: BodyStore) -> None:
        """Hitbox origins and bounds from the current transforms: every row after a structural or
        static change, otherwise only the rows that can move (static ones keep theirs)."""
        if self.version != store.version:
            self.rebuild_tables(store)
        key = (store.version, store.static_epoch, store.n)
        if key != getattr(self, "_full_key", None):
            self._compute(store, np.arange(store.n), full=True)
            self._full_key = key
        else:
            self._compute(store, store.active()[2], full=False, sel=store.active_sel()[2])

    def update_rows(self, store: BodyStore, rows: IntpArray) -> None:
        """Origins and bounds of ``rows`` only (bodies the response just moved); a full
        :meth:`update` if the structure changed since the last one."""
        if self.version != store.version or (store.version, store.static_epoch, store.n) != getattr(
                self, "_full_key", None):
            self.update(store)
        else:
            self._compute(store, rows, full=False)

    def move_row(self, store: BodyStore, row: int) -> None:
        """Origin and bounds of one row that moved without turning (the character stage's
        placements): :func:`_place` of that row alone (a full update costs some thirty numpy calls
        however few rows moved). The geometry must have been current before the move (its sines
        and cosines are the row's)."""
        c = store.cols
        if c["kind"][row] == KIND_AABB and not self.has_offset:  # (a box: its origin is its position)
            # :func:`_place`'s arithmetic on Python floats (the same IEEE doubles, so the same bits;
            # :func:`_ulp`'s own Python): a call of the compiled pass with its 23 arguments cost more
            ulp = _ulp.py_func
            x, y, hw, hh = float(c["x"][row]), float(c["y"][row]), float(c["hw"][row]), float(c["hh"][row])
            lx, hx, ly, hy = x - hw, x + hw, y - hh, y + hh
            self.minx[row], self.maxx[row] = lx - ulp(lx), hx + ulp(hx)
            self.miny[row], self.maxy[row] = ly - ulp(ly), hy + ulp(hy)
            return
        self._place_rows(store, np.array([row], dtype=np.int64))

    def _compute(self, store: BodyStore, rows: IntpArray, full: bool, sel: slice | IntpArray | None = None) -> None:
        """Origins and bounds of ``rows`` (``sel``: the same rows as a slice, if they are one run):
        the sines and cosines of the rows whose rotation matters by numpy, the rest in one
        compiled pass (:func:`_place`; a step's few moving rows took some thirty numpy calls)."""
        n, c = store.n, store.cols
        if sel is None:
            sel = slice(0, n) if full else rows
        if full:
            self.cos, self.sin = np.ones(n), np.zeros(n)
            self.has_offset = bool(store.ox.any() or store.oy.any())
            self.minx, self.maxx, self.miny, self.maxy = (np.zeros(n) for _ in range(4))
            self.poly_slot = np.full(n, -1, dtype=np.int64)
            self.poly_slot[self.poly_rows] = np.arange(self.poly_rows.size)
            self.world_poly = np.zeros((self.poly_rows.size, self.K, 2))
            self.cap_ux, self.cap_uy = np.zeros(n), self.cap_half.copy()
            if self.has_offset:
                self.hx, self.hy = store.x.copy(), store.y.copy()
            rows = np.arange(n)
        hx = getattr(self, "hx", None)
        if not self.has_offset and (hx is None or hx.base is not c["x"] or hx.size != n):
            self.hx, self.hy = store.x, store.y  # (the columns themselves: origins are positions)
        # Rotations matter only to polygons, capsules and offset hitboxes (AABBs and circles ignore
        # them).
        if self.poly_rows.size or self.cap_rows.size or self.has_offset:
            kind = c["kind"][sel]
            turned = (kind == KIND_POLYGON) | (kind == KIND_SEGMENT) | (kind == KIND_CAPSULE)
            if self.has_offset:
                turned |= (c["ox"][sel] != 0.0) | (c["oy"][sel] != 0.0)
            turned_rows = rows[turned]
            if turned_rows.size:
                rot = c["rot"][turned_rows]
                self.cos[turned_rows], self.sin[turned_rows] = np.cos(rot), np.sin(rot)
        self._place_rows(store, np.ascontiguousarray(rows, dtype=np.int64))

    def _place_rows(self, store: BodyStore, rows: I64Array) -> None:
        """:func:`_place` of ``rows`` (the columns whole: the pass reads only ``rows``, all below n)."""
        c = store.cols
        _place(rows, c["x"], c["y"], c["ox"], c["oy"], c["kind"], c["hw"], c["hh"], c["radius"], self.cos, self.sin,
               self.local, self.poly_slot, self.world_poly, self.cap_half, self.cap_ux, self.cap_uy, self.hx, self.hy,
               self.minx, self.maxx, self.miny, self.maxy, self.has_offset)

    def outlines(self, store: BodyStore, rows: IntpArray) -> tuple[F64Array, I64Array]:
        """Rotated outlines (relative to the hitbox origin) and vertex counts of AABB/polygon rows (a
        segment row: its two ends)."""
        K = self.K
        out = np.empty((rows.size, K, 2))
        count = np.empty(rows.size, dtype=np.int64)
        kind = store.kind[rows]
        box = kind == KIND_AABB
        if box.any():
            hw, hh = store.hw[rows[box]], store.hh[rows[box]]
            b = np.empty((hw.size, K, 2))
            b[:, 0, 0], b[:, 0, 1] = -hw, -hh
            b[:, 1, 0], b[:, 1, 1] = hw, -hh
            b[:, 2, 0], b[:, 2, 1] = hw, hh
            b[:, 3:, 0], b[:, 3:, 1] = -hw[:, None], hh[:, None]
            out[box] = b
            count[box] = 4
        poly = (kind == KIND_POLYGON) | (kind == KIND_SEGMENT) if self.segments else kind == KIND_POLYGON
        if poly.any():
            out[poly] = self.world_poly[self.poly_slot[rows[poly]]]
            count[poly] = self.count[rows[poly]]
        return out, count

