"""Per-step geometry of the hitboxes, as columns: hitbox origins, bounds and polygon outlines.

Derived from the store each step for the rows that can move; static rows are derived once and
cached until the static set changes.
"""

from __future__ import annotations

import numpy as np

from ..shapes import Polygon
from ..store import KIND_AABB, KIND_POLYGON, BodyStore

__all__ = ["Geometry"]


class Geometry:
    """Hitbox origins ``hx, hy``, bounds and outlines of every row with a hitbox."""

    def __init__(self) -> None:
        self.version = -1
        self.local = np.zeros((0, 4, 2))  # padded local outlines, one per row (polygon rows only)
        self.count = np.zeros(0, dtype=np.int64)
        self.poly_rows = np.zeros(0, dtype=np.int64)
        self.K = 4

    def rebuild_tables(self, store: BodyStore) -> None:
        """Re-read the polygon outlines after a structural change."""
        n = store.n
        self.poly_rows = np.flatnonzero(store.kind == KIND_POLYGON)
        shapes: list[Polygon] = [store.hitboxes[r]._shape for r in self.poly_rows]  # type: ignore[union-attr]
        K = max([4] + [len(s.points) for s in shapes])
        local = np.zeros((n, K, 2))
        count = np.zeros(n, dtype=np.int64)
        for r, s in zip(self.poly_rows.tolist(), shapes):
            pts = np.asarray(s.points)
            m = len(pts)
            local[r, :m] = pts
            local[r, m:] = pts[-1]  # pad by repeating the last vertex
            count[r] = m
        self.local, self.count, self.K = local, count, K
        self.version = store.version

    def update(self, store: BodyStore) -> None:
        """Hitbox origins and bounds of every row, from the current transforms."""
        if self.version != store.version:
            self.rebuild_tables(store)
        x, y, rot = store.x, store.y, store.rot
        ox, oy = store.ox, store.oy
        pr = self.poly_rows
        offset = np.flatnonzero((ox != 0.0) | (oy != 0.0))
        # Rotations matter only to polygons and to offset hitboxes (AABBs and circles ignore them).
        turned = np.union1d(pr, offset) if offset.size else pr
        c = np.ones(store.n)
        s = np.zeros(store.n)
        if turned.size:
            c[turned], s[turned] = np.cos(rot[turned]), np.sin(rot[turned])
        if offset.size:
            self.hx, self.hy = x.copy(), y.copy()
            co, so = c[offset], s[offset]
            self.hx[offset] += co * ox[offset] - so * oy[offset]
            self.hy[offset] += so * ox[offset] + co * oy[offset]
        else:
            self.hx, self.hy = x, y
        self.cos, self.sin = c, s
        ex, ey = store.hw, store.hh
        if pr.size:
            loc = self.local[pr]
            cc, ss = c[pr, None], s[pr, None]
            wx = cc * loc[:, :, 0] - ss * loc[:, :, 1]
            wy = ss * loc[:, :, 0] + cc * loc[:, :, 1]
            self.world_poly = np.stack([wx, wy], axis=-1)  # rotated, relative to the hitbox origin
            self.poly_slot = np.full(store.n, -1, dtype=np.int64)
            self.poly_slot[pr] = np.arange(pr.size)
            self.minx = self.hx - ex
            self.maxx = self.hx + ex
            self.miny = self.hy - ey
            self.maxy = self.hy + ey
            self.minx[pr] = self.hx[pr] + wx.min(axis=1)
            self.maxx[pr] = self.hx[pr] + wx.max(axis=1)
            self.miny[pr] = self.hy[pr] + wy.min(axis=1)
            self.maxy[pr] = self.hy[pr] + wy.max(axis=1)
        else:
            self.world_poly = np.zeros((0, self.K, 2))
            self.poly_slot = np.full(store.n, -1, dtype=np.int64)
            self.minx, self.maxx = self.hx - ex, self.hx + ex
            self.miny, self.maxy = self.hy - ey, self.hy + ey

    def outlines(self, store: BodyStore, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Rotated outlines (relative to the hitbox origin) and vertex counts of AABB/polygon rows."""
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
        poly = kind == KIND_POLYGON
        if poly.any():
            out[poly] = self.world_poly[self.poly_slot[rows[poly]]]
            count[poly] = self.count[rows[poly]]
        return out, count

