"""Per-step geometry of the hitboxes, as columns: hitbox origins, bounds, polygon outlines and
capsules' half segments. A segment's outline (its two ends) is kept with the polygons'.

Derived from the store each step for the rows that can move; static rows are derived once and
cached until the static set changes.
"""

from __future__ import annotations

import numpy as np

from .arrays import F64Array, I64Array, IntpArray
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


def _down(v: float) -> float:
    """:func:`widen_down` of one float (the same arithmetic, so the same bits)."""
    return v - max(abs(v) * 2.0**-52, _TINY)


def _up(v: float) -> float:
    """:func:`widen_up` of one float."""
    return v + max(abs(v) * 2.0**-52, _TINY)


def widen_down(v: F64Array, out: F64Array | None = None) -> F64Array:
    """``v`` lowered by one or two ulps (at least to ``np.nextafter(v, -inf)``), by arithmetic:
    several times faster than ``nextafter``. The rounded difference ``v - step`` lies one or two
    ulps below ``v``; -inf stays -inf (and a lower bound is never +inf: it is at most the
    position)."""
    return np.subtract(v, _ulp_step(v), out=out)


def widen_up(v: F64Array, out: F64Array | None = None) -> F64Array:
    """``v`` raised by one or two ulps (see :func:`widen_down`)."""
    return np.add(v, _ulp_step(v), out=out)


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
        placements), bit for bit as :meth:`_compute` gives them, in scalars: a full update costs
        some thirty numpy calls however few rows moved. The geometry must have been current
        before the move."""
        x, y = float(store.cols["x"][row]), float(store.cols["y"][row])
        if self.has_offset:
            ox, oy = float(store.cols["ox"][row]), float(store.cols["oy"][row])
            if ox != 0.0 or oy != 0.0:
                co, so = float(self.cos[row]), float(self.sin[row])
                x += co * ox - so * oy
                y += so * ox + co * oy
            self.hx[row], self.hy[row] = x, y
        # (else hx, hy are the store's x, y columns: already moved)
        kind = int(store.cols["kind"][row])
        if kind == KIND_POLYGON or kind == KIND_SEGMENT:
            local = self.world_poly[self.poly_slot[row]]
            lo_x, hi_x = x + float(local[:, 0].min()), x + float(local[:, 0].max())
            lo_y, hi_y = y + float(local[:, 1].min()), y + float(local[:, 1].max())
        else:
            if kind == KIND_CAPSULE:
                r = float(store.cols["radius"][row])
                ex, ey = abs(float(self.cap_ux[row])) + r, abs(float(self.cap_uy[row])) + r
            else:
                ex, ey = float(store.cols["hw"][row]), float(store.cols["hh"][row])
            lo_x, hi_x, lo_y, hi_y = x - ex, x + ex, y - ey, y + ey
        self.minx[row], self.maxx[row] = _down(lo_x), _up(hi_x)
        self.miny[row], self.maxy[row] = _down(lo_y), _up(hi_y)

    def _compute(self, store: BodyStore, rows: IntpArray, full: bool, sel: slice | IntpArray | None = None) -> None:
        """Origins and bounds of ``rows`` (``sel``: the same rows as a slice, if they are one run)."""
        n = store.n
        if sel is None:
            sel = slice(0, n) if full else rows
        x, y, rot = store.x, store.y, store.rot
        ox, oy = store.ox, store.oy
        if full:
            self.cos, self.sin = np.ones(n), np.zeros(n)
            self.has_offset = bool(ox.any() or oy.any())
            self.minx, self.maxx, self.miny, self.maxy = (np.zeros(n) for _ in range(4))
            self.poly_slot = np.full(n, -1, dtype=np.int64)
            self.poly_slot[self.poly_rows] = np.arange(self.poly_rows.size)
            self.world_poly = np.zeros((self.poly_rows.size, self.K, 2))
            self.cap_ux, self.cap_uy = np.zeros(n), self.cap_half.copy()
            if self.has_offset:
                self.hx, self.hy = x.copy(), y.copy()
        offset = rows[(ox[sel] != 0.0) | (oy[sel] != 0.0)] if self.has_offset else rows[:0]
        if not self.poly_rows.size:
            polys = rows[:0]
        elif self.segments:
            polys = rows[(store.kind[sel] == KIND_POLYGON) | (store.kind[sel] == KIND_SEGMENT)]
        else:
            polys = rows[store.kind[sel] == KIND_POLYGON]
        caps = rows[store.kind[sel] == KIND_CAPSULE] if self.cap_rows.size else rows[:0]
        # Rotations matter only to polygons, capsules and offset hitboxes (AABBs and circles ignore
        # them).
        turned = np.union1d(polys, offset) if offset.size else polys
        if caps.size:
            turned = np.union1d(turned, caps)
        if turned.size:
            self.cos[turned], self.sin[turned] = np.cos(rot[turned]), np.sin(rot[turned])
        if self.has_offset:
            self.hx[sel], self.hy[sel] = x[sel], y[sel]
            if offset.size:
                co, so = self.cos[offset], self.sin[offset]
                self.hx[offset] += co * ox[offset] - so * oy[offset]
                self.hy[offset] += so * ox[offset] + co * oy[offset]
        else:
            self.hx, self.hy = x, y
        hx, hy = self.hx[sel], self.hy[sel]
        ex, ey = store.hw[sel], store.hh[sel]
        view = isinstance(sel, slice)  # write through views, no temporaries
        for lo, hi, h, e in ((self.minx, self.maxx, hx, ex), (self.miny, self.maxy, hy, ey)):
            if view:
                np.subtract(h, e, out=lo[sel])
                np.add(h, e, out=hi[sel])
            else:
                lo[sel], hi[sel] = h - e, h + e
        if polys.size:
            loc = self.local[polys]
            cc, ss = self.cos[polys, None], self.sin[polys, None]
            wx = cc * loc[:, :, 0] - ss * loc[:, :, 1]
            wy = ss * loc[:, :, 0] + cc * loc[:, :, 1]
            self.world_poly[self.poly_slot[polys]] = np.stack([wx, wy], axis=-1)  # about the hitbox origin
            self.minx[polys] = self.hx[polys] + wx.min(axis=1)
            self.maxx[polys] = self.hx[polys] + wx.max(axis=1)
            self.miny[polys] = self.hy[polys] + wy.min(axis=1)
            self.maxy[polys] = self.hy[polys] + wy.max(axis=1)
        if caps.size:
            # The half segment (0, h) turned; the bounds: its ends, pushed out by the radius.
            h, r = self.cap_half[caps], store.radius[caps]
            ux, uy = -(self.sin[caps] * h), self.cos[caps] * h
            self.cap_ux[caps], self.cap_uy[caps] = ux, uy
            ex, ey = np.abs(ux) + r, np.abs(uy) + r
            self.minx[caps], self.maxx[caps] = self.hx[caps] - ex, self.hx[caps] + ex
            self.miny[caps], self.maxy[caps] = self.hy[caps] - ey, self.hy[caps] + ey
        # Widen by an ulp or two: a bound is a rounded sum, so two shapes overlapping by less than
        # the rounding (boxes stacked at non-dyadic heights) could have strictly disjoint bounds
        # and never reach the (exact) narrow phase. The broad phase may now also pair shapes that
        # merely touch; the narrow phase drops those.
        with np.errstate(over="ignore", invalid="ignore"):  # inf stays inf, NaN stays NaN
            for lo, hi in ((self.minx, self.maxx), (self.miny, self.maxy)):
                if view:
                    widen_down(lo[sel], out=lo[sel])
                    widen_up(hi[sel], out=hi[sel])
                else:
                    lo[sel] = widen_down(lo[sel])
                    hi[sel] = widen_up(hi[sel])

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

