"""Continuous detection for the bodies that ask for it (``Hitbox(..., ccd=True)``).

After movement, each such body is swept from where it started the step to where it ended, against
every non-sensor body whose bounds meet the swept bounds (statics through the spatial hash, moving
bodies by one vectorised bounds test). If it hits something on the way, it is moved back to the
first moment of contact plus a hair of penetration, so the narrow phase sees the contact and the
response and events treat it like any other: a fast bullet never passes through a thin wall.
Other bodies are taken where they ended the step (exact for static walls). Bodies that do not opt
in pay nothing.
"""

from __future__ import annotations

import math

import numpy as np

from ..arrays import F64Array, IntpArray
from ..collision.sweep import time_of_impact
from ..frame import StepFrame
from ..geometry import Geometry
from ..store import STATIC, BodyStore
from .stage import Stage

__all__ = ["ContinuousDetection", "sweep_ccd_bodies"]


class ContinuousDetection(Stage):
    """Sweep the bodies that asked for it (``Hitbox(ccd=True)``) over the step's motion."""

    name = "ccd"
    needs = frozenset({"continuous", "movement"})
    solver = "exact"

    def run(self, frame: StepFrame) -> bool:
        rows = frame.ccd_rows
        bodies = self.bodies
        store = bodies.store
        if rows.size == 0 or rows.max() >= store.n:
            return False
        geom = bodies.ensure_geometry()
        frame.counters["rehashed"] += bodies.sync_static()
        stopped = sweep_ccd_bodies(store, geom, rows, *frame.ccd_start, bodies.static_rows_in_box, frame.counters)
        frame.counters["ccd_stopped"] = stopped
        x0, y0 = frame.ccd_start
        frame.swept_paths = list(zip(zip(x0.tolist(), y0.tolist()),
                                     zip(store.x[rows].tolist(), store.y[rows].tolist())))
        return True


def sweep_ccd_bodies(
    store: BodyStore, geom: Geometry, rows: IntpArray, start_x: F64Array, start_y: F64Array,
    static_candidates, counts: dict[str, int],
) -> int:
    """Sweep ``rows`` (which moved from ``start_x, start_y``); return how many were stopped early."""
    c = store.cols
    stopped = 0
    moving = np.flatnonzero((store.kind >= 0) & (store.body != STATIC))
    for i, r in enumerate(rows.tolist()):
        hb = store.hitboxes[r]
        if hb is None or hb._sensor:
            continue
        x0, y0 = float(start_x[i]), float(start_y[i])
        x1, y1 = float(c["x"][r]), float(c["y"][r])
        mx, my = x1 - x0, y1 - y0
        if mx == 0.0 and my == 0.0:
            continue
        # Swept bounds of the body over the step.
        dxs, dys = geom.hx[r] - x1, geom.hy[r] - y1  # hitbox offset, rotated
        ext_x = geom.maxx[r] - geom.hx[r]
        ext_y = geom.maxy[r] - geom.hy[r]
        low_x = geom.minx[r] - geom.hx[r]
        low_y = geom.miny[r] - geom.hy[r]
        bminx = min(x0, x1) + dxs + low_x
        bmaxx = max(x0, x1) + dxs + ext_x
        bminy = min(y0, y1) + dys + low_y
        bmaxy = max(y0, y1) + dys + ext_y
        cands = static_candidates(bminx, bminy, bmaxx, bmaxy).tolist()
        hitm = (
            (geom.minx[moving] < bmaxx) & (geom.maxx[moving] > bminx)
            & (geom.miny[moving] < bmaxy) & (geom.maxy[moving] > bminy)
        )
        cands.extend(moving[hitm].tolist())
        best = None
        rot = float(c["rot"][r])
        start = (x0 + dxs, y0 + dys, rot)
        for o in cands:
            if o == r:
                continue
            other = store.hitboxes[o]
            if other is None or other._sensor:
                continue
            if not (store.layer[r] & store.mask[o] and store.layer[o] & store.mask[r]):
                continue
            counts["swept"] = counts.get("swept", 0) + 1
            imp = time_of_impact(
                hb._shape, start, (mx, my), other._shape, (float(geom.hx[o]), float(geom.hy[o]), float(c["rot"][o]))
            )
            if imp is not None and other._one_way:
                # A one-way platform stops only a body coming down onto it (its local +y up).
                rot_o = float(c["rot"][o])
                ux, uy = -math.sin(rot_o), math.cos(rot_o)
                if imp.normal[0] * ux + imp.normal[1] * uy > -0.7071:
                    imp = None
            if imp is not None and imp.fraction > 0.0 and (best is None or imp.fraction < best[0]):
                best = (imp.fraction, imp.normal)
        if best is None:
            continue
        f, n = best
        # A hair past first contact, so the contact is seen: about 1e-6 of the body's size,
        # never past the end of the step.
        toward = mx * n[0] + my * n[1]
        slop = 1e-6 * float(store.bound[r])
        extra = slop / toward if toward > 0.0 else 0.0
        f = min(1.0, f + extra)
        store.place(r, x0 + mx * f, y0 + my * f)
        stopped += 1
    return stopped
