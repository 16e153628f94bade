"""The soft step: movement, detection and response as one compiled call (``Scene(solver="soft")``).

Box2D v3's "soft step" (sub-steps, soft contacts, relax, restitution, warm starting) over every
body in one call of :func:`~framework.systems.soft_kernel.soft_step`, in place of the exact
pipeline's movement, continuous detection, broad phase, narrow phase and response stages. It is
the accuracy knob for speed: bodies at rest sit within a small fraction of the linear slop of their
exact height instead of on it, and contacts are measured in floats (a pair counts as touching from
the first overlap until it is more than the slop apart), where the exact pipeline decides touching
exactly. See docs/physics.md.

What stays outside the call, in Python: the shape tables (rebuilt only after a structural change),
the pair tracking handed to the frame (started, ongoing and ended pairs as arrays; event objects
are made only when asked for), waking the sleepers an awake body touched. The stage runs where the
response does: a game processor placed between the exact pipeline's physics stages runs before it.
"""

from __future__ import annotations

import math
import sys
import threading
from typing import Any

import esper
import numpy as np

from ..character import CharacterController
from ..events import StepContacts
from ..frame import StepFrame
from ..store import KIND_AABB, KIND_CAPSULE, KIND_CIRCLE, KIND_POLYGON
from .soft_kernel import PARAMS, SLOT, soft_step
from .stage import PRIORITY, Stage

__all__ = ["COMPILE_NOTICE", "SOFT_SETTINGS", "SoftStep", "shape_tables"]

#: Box2D v3's defaults, in metres (scaled by ``Scene(length_unit=...)``): linear slop, contact
#: stiffness (hertz) and damping ratio, the fastest push out of an overlap, the slowest approach
#: that bounces, sub-steps per step, and how far a moving body's fat bounds reach beyond it (its
#: candidate pairs are found again only when it leaves them).
SOFT_SETTINGS = {"slop": 0.005, "hertz": 30.0, "damping": 10.0, "push_speed": 3.0, "restitution_threshold": 1.0,
                 "substeps": 4, "fat_margin": 0.1}
# the store's columns the kernel reads (and writes: the pose and velocity), in its argument order
_KERNEL_COLUMNS = ("x", "y", "rot", "vx", "vy", "w", "body", "kind", "inv_mass", "inv_inertia", "friction",
                   "restitution", "layer", "mask", "sensor", "one_way", "asleep", "has_vel", "entity", "bound")


def shape_tables(store) -> tuple[np.ndarray, ...]:
    """Every row's hitbox as a rounded polygon about its hitbox origin: ``(offset, vertices,
    normals, count, radius, spins)``; count 0 for a row without a hitbox. AABBs do not turn with
    the transform (their offset does); circles are one vertex, capsules their segment."""
    n = store.n
    polys = [store.shapes[r] for r in range(n)]
    K = max([4] + [len(s.points) for s, k in zip(polys, store.kind[:n].tolist()) if k == KIND_POLYGON])
    off = np.zeros((n, 2))
    off[:, 0], off[:, 1] = store.ox, store.oy
    lv = np.zeros((n, K, 2))
    ln = np.zeros((n, K, 2))
    cnt = np.zeros(n, dtype=np.int64)
    rr = np.zeros(n)
    spin = np.ones(n, dtype=np.bool_)
    box_n = ((0.0, -1.0), (1.0, 0.0), (0.0, 1.0), (-1.0, 0.0))
    for r, k in enumerate(store.kind[:n].tolist()):
        if k == KIND_AABB:
            hw, hh = float(store.hw[r]), float(store.hh[r])
            lv[r, :4] = ((-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh))
            ln[r, :4] = box_n
            cnt[r], spin[r] = 4, False
        elif k == KIND_CIRCLE:
            cnt[r], rr[r] = 1, float(store.radius[r])
        elif k == KIND_CAPSULE:
            h = polys[r].half_length
            lv[r, :2] = ((0.0, -h), (0.0, h))
            ln[r, :2] = ((1.0, 0.0), (-1.0, 0.0))
            cnt[r], rr[r] = 2, float(store.radius[r])
        elif k == KIND_POLYGON:
            pts = polys[r].points
            m = len(pts)
            for i in range(m):
                (x1, y1), (x2, y2) = pts[i], pts[(i + 1) % m]
                ex, ey = x2 - x1, y2 - y1
                d = math.hypot(ex, ey)
                lv[r, i] = (x1, y1)
                ln[r, i] = (ey / d, -ex / d)
            cnt[r] = m
    return off, lv, ln, cnt, rr, spin


_COMPILED = False
COMPILE_NOTICE = ("framework: compiling the soft step (once per installation, about half a minute; later runs load "
                  "it from numba's cache)")


def _first_call(args: tuple[Any, ...]) -> tuple[Any, ...]:
    """The kernel's first call in this process: if it has not returned within a second (numba is
    compiling it, not loading it from its cache), say so on stderr, once."""
    global _COMPILED
    timer = threading.Timer(1.0, lambda: print(COMPILE_NOTICE, file=sys.stderr, flush=True))
    timer.start()
    try:
        return soft_step(*args)
    finally:
        timer.cancel()
        _COMPILED = True


class SoftStep(Stage):
    """Movement, detection and response in one compiled call, for ``Scene(solver="soft")``."""

    name = "soft_step"
    needs = frozenset()
    solver = "soft"

    def __init__(self, pipeline) -> None:
        super().__init__(pipeline)
        self.priority = PRIORITY["response"] + 1  # where the response runs (see the module docstring)
        self._tables_key: tuple[int, int] | None = None
        self._tables: tuple[np.ndarray, ...] = ()
        self._params = np.zeros(len(PARAMS))
        self._settings_key: tuple[Any, ...] | None = None
        self._columns_key: tuple[int, int] | None = None
        self._cols: tuple[np.ndarray, ...] = ()
        self._no_driven = np.zeros(0, dtype=np.bool_)
        self.reset()

    def reset(self) -> None:
        """Forget the candidate pairs and their contacts (warm starts and touching pairs)."""
        self.pairs = np.zeros((0, 3), dtype=np.int64)  # rows a, b and key (entity a << 32 | entity b)
        self.slots = np.zeros((0, len(SLOT)))
        self.fat = np.zeros((0, 4))
        self._pairs_key: tuple[int, int, bool] | None = None

    def state(self) -> tuple[Any, ...]:
        """What the next step starts from (the kernel never modifies these arrays in place: a
        step replaces them, so keeping the references keeps the state)."""
        return self.fat, self.pairs, self.slots, self._pairs_key

    def restore(self, state: tuple[Any, ...]) -> None:
        """Start the next step from ``state`` (of :meth:`state`)."""
        self.fat, self.pairs, self.slots, self._pairs_key = state

    def wanted(self) -> bool:
        effects = self.pipeline.effects
        return self.pipeline.solver == "soft" and bool(effects & {"movement", "detection"})

    def _shape_tables(self) -> tuple[np.ndarray, ...]:
        store = self.bodies.store
        key = (store.version, store.n)
        if key != self._tables_key:
            self._tables = shape_tables(store)
            self._tables_key = key
        return self._tables

    def _columns(self) -> tuple[np.ndarray, ...]:
        """The store's columns as the kernel takes them (views of the live rows), kept until the rows
        or the columns' storage change."""
        store = self.bodies.store
        c = store.cols
        key = (store.version, store.n)
        # (views of these very columns: a restored scene's copies are views of nothing, and an
        # unpickled copy of a column is not the column)
        if key != self._columns_key or not self._cols or self._cols[0].base is not c["x"]:
            n = store.n
            self._cols = tuple(c[name][:n] for name in _KERNEL_COLUMNS)
            self._columns_key = key
        return self._cols

    def _driven(self, frame: StepFrame) -> np.ndarray:
        """Rows the character stage moved this step (the soft step moves them no further)."""
        n = self.bodies.store.n
        if self._no_driven.size != n:
            self._no_driven = np.zeros(n, dtype=np.bool_)
        if not frame.counters.get("characters"):
            return self._no_driven
        rows = self.bodies.rows_of([e for e, _c in esper.get_component(CharacterController)])
        driven = np.zeros(n, dtype=np.bool_)
        driven[rows[rows >= 0]] = True
        return driven

    def _settings(self, frame: StepFrame) -> np.ndarray:
        """The kernel's ``params`` for this step (rebuilt only when a setting changed)."""
        pipe, store = self.pipeline, self.bodies.store
        effects = pipe.effects
        key = (frame.dt, effects, pipe.gravity, pipe.length_unit, store.layers_all_meet())
        if key != self._settings_key:
            unit, s = pipe.length_unit, SOFT_SETTINGS
            gx, gy = pipe.active_gravity()
            moves = "movement" in effects
            self._params[:] = (frame.dt if moves else 0.0, s["substeps"] if moves else 0, gx, gy, s["slop"] * unit,
                               4.0 * s["slop"] * unit, s["hertz"], s["damping"], s["push_speed"] * unit,
                               s["restitution_threshold"] * unit, float(key[-1]), float("response" in effects),
                               float("rotation" in effects), float("friction" in effects), s["fat_margin"] * unit)
            self._settings_key = key
        return self._params

    def run(self, frame: StepFrame) -> bool:
        store = self.bodies.store
        effects = self.pipeline.effects
        if "sleeping" in effects:  # (where the step began: what the sleeping stage measures rest by)
            c, n = store.cols, store.n
            frame.start_x, frame.start_y = c["x"][:n].copy(), c["y"][:n].copy()
        off, lv, ln, cnt, rr, spin = self._shape_tables()
        if "detection" not in effects:
            cnt = np.zeros(store.n, dtype=np.int64)
        key = (store.version, store.n, "detection" in effects)
        rebuild = key != self._pairs_key
        if rebuild:
            self.fat = np.zeros((store.n, 4))
            self._pairs_key = key
        args = (self._settings(frame), *self._columns(), off, lv, ln, cnt, rr, spin, self._driven(frame), self.fat,
                self.pairs, self.slots, rebuild)
        out = soft_step(*args) if _COMPILED else _first_call(args)
        self.fat, self.pairs, self.slots, touch_i, touch_f, end_i, end_f, info = out
        if "movement" in effects:
            store.motion += 1
        ra, rb, ea, eb, started = touch_i
        frame.contacts = StepContacts(ea, eb, *touch_f)
        frame.contact_rows, frame.started = (ra, rb), started.astype(bool)
        frame.ended = StepContacts(end_i[0], end_i[1], *end_f)
        frame._events = None
        if info.size > 3:
            store.wake(info[3:])
        counters = frame.counters
        counters["integrated"] = int(store.active()[0].size)
        counters["candidate_pairs"] = int(self.pairs.shape[0])
        counters["rehashed"] = int(info[0])
        counters["contacts"] = int(ea.size)
        counters["events"] = int(ea.size + end_i.shape[1])
        counters["resolved"] = int(info[1])
        counters["asleep"] = frame.n_asleep = int(info[2])
        return True
