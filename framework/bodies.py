"""The bodies: the columnar store and what every stage and query derives from it.

One object owns the store, the hitbox geometry derived from it (origins, bounds, outlines), the
spatial hash of the static bodies (and the one of the sleeping bodies, which the broad phase
fills) and keeps them current. Derived data is keyed on the store's counters (``version``,
``static_epoch``, ``motion``, ``writes``), which the store bumps itself whenever rows, statics or
positions change, so no mover has to remember to invalidate anything.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .collision.broad_phase import SpatialHash
from .collision.grid import auto_cell_size
from .geometry import Geometry
from .store import STATIC, BodyStore

__all__ = ["Bodies"]


class Bodies:
    """The store, its geometry and its static index. ``cell_size``: the spatial hash's cell
    (``None``: chosen from the hitbox sizes when the statics are first hashed)."""

    def __init__(self, cell_size: float | None = None) -> None:
        self.store = BodyStore()
        self.geometry = Geometry()
        self.hash = SpatialHash(cell_size)  # the static bodies (kept until the static set changes)
        self.sleep_hash = SpatialHash(cell_size)  # the sleeping bodies (the broad phase fills it)
        self.n_static = 0
        self._geometry_stamp: tuple[int, ...] | None = None

    def rows_of(self, entities: NDArray[np.int64] | list[int]) -> NDArray[np.int64]:
        """Rows of ``entities`` (-1 for ids without one)."""
        return self.store.rows_of(entities)

    def ensure_geometry(self) -> Geometry:
        """The geometry (hitbox origins and bounds), brought up to date if anything moved or changed
        since it was last computed; stages, queries and the renderer call this before reading it."""
        store = self.store
        stamp = (store.motion, store.writes, store.version, store.n)
        if stamp != self._geometry_stamp:
            self.geometry.update(store)
            self._geometry_stamp = stamp
        return self.geometry

    def place_row(self, row: int, x: float, y: float) -> None:
        """Put one moving row at ``(x, y)`` (it does not turn), keeping the geometry current if it
        was (:meth:`Geometry.move_row`: one row's bounds, not every moving row's)."""
        store = self.store
        current = self._geometry_stamp == (store.motion, store.writes, store.version, store.n)
        store.place(row, x, y)
        if current and store.cols["body"][row] != STATIC and store.cols["kind"][row] >= 0:
            self.geometry.move_row(store, row)
            self._geometry_stamp = (store.motion, store.writes, store.version, store.n)

    def placed_boxes(self) -> None:
        """Moving rows were placed by a compiled pass that kept their bounds as :meth:`place_row`
        does (the character stage's whole move), the geometry current before it: the move
        counted, the geometry still current."""
        store = self.store
        store.motion += 1
        self._geometry_stamp = (store.motion, store.writes, store.version, store.n)

    def sync_static(self) -> int:
        """Hash the static bodies again if the static set changed (waking the sleepers: the level
        changed under them); return how many were hashed (0: the hash was current)."""
        store, geom = self.store, self.geometry
        if not store.static_dirty:
            return 0
        if store.asleep.any():
            store.wake(np.flatnonzero(store.asleep))
        rows = np.flatnonzero((store.kind >= 0) & (store.body == STATIC))
        if self.hash.cell_size is None:
            self._choose_cell_size(rows)
        self.hash.set_static(geom.minx[rows], geom.miny[rows], geom.maxx[rows], geom.maxy[rows], store.entity[rows])
        self.n_static = int(rows.size)
        store.static_dirty = False
        return int(rows.size)

    def _choose_cell_size(self, static_rows: NDArray[np.intp]) -> None:
        """The automatic cell: about twice the median extent of the moving bodies or of the static
        ones, whichever is larger, so small tiles do not make every mover span dozens of cells
        and small movers do not cut large tiles into many."""
        store, geom = self.store, self.geometry
        moving = np.flatnonzero((store.kind >= 0) & (store.body != STATIC))
        sizes = []
        for rows in (moving, static_rows):
            if rows.size:
                c = auto_cell_size(geom.minx[rows], geom.miny[rows], geom.maxx[rows], geom.maxy[rows])
                if c is not None:
                    sizes.append(c)
        if sizes:
            self.hash.set_cell_size(max(sizes))
            self.sleep_hash.set_cell_size(max(sizes))

    def static_rows_in_box(self, minx: float, miny: float, maxx: float, maxy: float) -> NDArray[np.int64]:
        """Rows of the static bodies whose hashed cells meet the box (candidates, not overlaps)."""
        rows = self.rows_of(self.hash.query_box(minx, miny, maxx, maxy))
        rows = rows[rows >= 0]
        return rows[self.store.body[rows] == STATIC]

    def wake_near(self, row: int) -> None:
        """Wake the sleepers whose bounds come within a tenth of ``row``'s size of it (whatever slept
        on or against a body that goes)."""
        store = self.store
        r = 1.1 * float(store.bound[row])
        x, y = float(store.x[row]), float(store.y[row])
        g = self.ensure_geometry()
        near = (g.minx < x + r) & (g.maxx > x - r) & (g.miny < y + r) & (g.maxy > y - r)
        store.wake(np.flatnonzero(near & store.asleep))

    @property
    def static_hash_current(self) -> bool:
        """Whether :attr:`hash` holds the static bodies as they are now: it was built (it has a
        cell size) and no static body was added, moved, changed or removed since (the broad phase
        and the spatial queries build it again when one was). Read-only: the renderer culls the
        statics through the hash only while this holds."""
        return not self.store.static_dirty and self.hash.cell_size is not None
