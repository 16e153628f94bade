"""Movement: integrate velocities (semi-implicit Euler), with optional gravity.

Only rows with a Velocity are touched; static and sleeping bodies never move. Gravity accelerates dynamic
bodies only (kinematic ones move exactly as game code tells them).
"""

from __future__ import annotations

import numpy as np

from ..store import DYNAMIC, BodyStore

__all__ = ["integrate"]


def integrate(store: BodyStore, dt: float, gravity: tuple[float, float]) -> np.ndarray:
    """Advance every moving row by ``dt``; return the rows integrated."""
    rows = store.active()[0]
    if rows.size == 0:
        return rows
    c = store.cols
    gx, gy = gravity
    if gx or gy:
        dyn = rows[store.body[rows] == DYNAMIC]
        if gx:
            c["vx"][dyn] += gx * dt
        if gy:
            c["vy"][dyn] += gy * dt
    c["x"][rows] += c["vx"][rows] * dt
    c["y"][rows] += c["vy"][rows] * dt
    w = c["w"][rows]
    spinning = w != 0.0
    if spinning.any():
        c["rot"][rows[spinning]] += w[spinning] * dt
    return rows
