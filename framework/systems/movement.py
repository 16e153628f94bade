"""Movement: integrate velocities (semi-implicit Euler), with optional gravity.

Only rows with a Velocity are touched; static and sleeping bodies never move. Gravity accelerates dynamic
bodies only (kinematic ones move exactly as game code tells them). The stage also records where
every row started the step (for one-way platforms and sleeping) and which bodies continuous
detection will sweep.
"""

from __future__ import annotations

import numpy as np

from ..arrays import IntpArray
from ..compiled import kernel
from ..frame import StepFrame
from ..store import DYNAMIC, STATIC, BodyStore
from .stage import Stage

__all__ = ["Movement", "integrate", "integrate_rows"]


@kernel
def _fall(rows, body, vx, vy, gx_dt, gy_dt, along_x, along_y, dynamic):  # pragma: no cover - compiled
    """Gravity's step on the dynamic ``rows``' velocities (an axis without gravity untouched:
    adding 0 would turn a velocity of -0.0 into 0.0)."""
    for i in range(rows.size):
        r = rows[i]
        if body[r] == dynamic:
            if along_x:
                vx[r] += gx_dt
            if along_y:
                vy[r] += gy_dt


def integrate(store: BodyStore, dt: float, gravity: tuple[float, float]) -> IntpArray:
    """Advance every moving row by ``dt``; return the rows integrated."""
    rows = store.active()[0]
    _advance(store, rows, store.active_sel()[0], dt, gravity)  # a slice where the movers are one run
    return rows


def integrate_rows(store: BodyStore, rows: IntpArray, dt: float, gravity: tuple[float, float]) -> None:
    """:func:`integrate` for some rows only (bodies woken after the movement stage, catching up on
    the step they slept through); rows without a Velocity, and static rows, stay put."""
    c = store.cols
    rows = rows[c["has_vel"][rows] & (c["body"][rows] != STATIC)]
    _advance(store, rows, rows, dt, gravity)


def _advance(store: BodyStore, rows: IntpArray, sel: slice | IntpArray, dt: float,
             gravity: tuple[float, float]) -> None:
    """Semi-implicit Euler on ``rows`` (``sel``: the same rows, as a slice where they are one run)."""
    if rows.size == 0:
        return
    c = store.cols
    gx, gy = gravity
    if gx or gy:
        _fall(rows, c["body"], c["vx"], c["vy"], gx * dt, gy * dt, gx != 0.0, gy != 0.0, DYNAMIC)
    store.move_by_velocity(rows, sel, dt)


class Movement(Stage):
    """Integrate the moving bodies; record the step's start positions and the bodies to sweep."""

    name = "movement"
    needs = frozenset({"movement"})
    solver = "exact"

    def __init__(self, pipeline) -> None:
        super().__init__(pipeline)
        self._start_key: tuple[int, ...] | None = None
        self._start_buf = (np.zeros(0), np.zeros(0))

    def run(self, frame: StepFrame) -> bool:
        store = self.bodies.store
        # Where every row starts the step (for one-way platforms and sleeping); static rows are
        # copied again only when the static set changed.
        key = (store.version, store.static_epoch, store.n)
        if key != self._start_key:
            self._start_buf = (store.x.copy(), store.y.copy())
            self._start_key = key
        else:
            sel = store.active_sel()[2]
            self._start_buf[0][sel], self._start_buf[1][sel] = store.x[sel], store.y[sel]
        frame.start_x, frame.start_y = self._start_buf
        movers = store.active()[0]
        ccd = movers[store.ccd[store.active_sel()[0]]]
        frame.ccd_rows = ccd
        frame.ccd_start = (store.x[ccd].copy(), store.y[ccd].copy())
        rows = integrate(store, frame.dt, self.pipeline.active_gravity())
        frame.counters["integrated"] = int(rows.size)
        return True
