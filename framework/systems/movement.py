"""Movement: integrate velocities (semi-implicit Euler), with optional gravity.

Only rows with a Velocity are touched; static and sleeping bodies never move. Gravity accelerates dynamic
bodies only (kinematic ones move exactly as game code tells them).
"""

from __future__ import annotations

import numpy as np

from ..store import DYNAMIC, STATIC, BodyStore

__all__ = ["integrate", "integrate_rows"]


def integrate(store: BodyStore, dt: float, gravity: tuple[float, float]) -> np.ndarray:
    """Advance every moving row by ``dt``; return the rows integrated."""
    rows = store.active()[0]
    _advance(store, rows, store.active_sel()[0], dt, gravity)  # a slice where the movers are one run
    return rows


def integrate_rows(store: BodyStore, rows: np.ndarray, dt: float, gravity: tuple[float, float]) -> None:
    """:func:`integrate` for some rows only (bodies woken after the movement stage, catching up on
    the step they slept through); rows without a Velocity, and static rows, stay put."""
    c = store.cols
    rows = rows[c["has_vel"][rows] & (c["body"][rows] != STATIC)]
    _advance(store, rows, rows, dt, gravity)


def _advance(store: BodyStore, rows: np.ndarray, sel: slice | np.ndarray, dt: float,
             gravity: tuple[float, float]) -> None:
    """Semi-implicit Euler on ``rows`` (``sel``: the same rows, as a slice where they are one run,
    so the column reads are views, not gathers)."""
    if rows.size == 0:
        return
    c = store.cols
    gx, gy = gravity
    if gx or gy:
        dyn = rows[store.body[rows] == DYNAMIC]
        if gx:
            c["vx"][dyn] += gx * dt
        if gy:
            c["vy"][dyn] += gy * dt
    c["x"][sel] += c["vx"][sel] * dt
    c["y"][sel] += c["vy"][sel] * dt
    w = c["w"][sel]
    spinning = w != 0.0
    if spinning.any():
        c["rot"][rows[spinning]] += w[spinning] * dt
