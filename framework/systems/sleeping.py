"""Sleeping: bodies at rest stop costing anything until something wakes them.

A dynamic body sleeps after :data:`SLEEP_STEPS` steps at rest: moving less than
:data:`SLEEP_SPEED` (relative to 1 + its size, per second) with a speed below that. A stack sleeps
as one: a body touching an awake, restless dynamic body stays awake, and so, in turn, does
whatever touches it (the two bodies of a joint count as touching). Game code writing its Transform
or Velocity, a contact with an awake body, a change to the static level or a despawn nearby wake
it.

And a stack wakes as one: the bodies that fell asleep touching each other (contacts and resting
pairs, as the response saw them then) are linked, and when one of them wakes, for whatever reason,
the others it is linked to wake at the end of that step, and in turn theirs (a box asleep on a
crate the game shoves away falls, rather than hanging where it slept).
"""

from __future__ import annotations

import numpy as np

from ..arrays import I64Array, IntpArray, distinct
from ..compiled import kernel
from ..events import pair_keys, pair_parts
from ..frame import StepFrame
from ..store import DYNAMIC
from .stage import Stage

__all__ = ["SLEEP_SPEED", "SLEEP_STEPS", "Sleeping"]

SLEEP_STEPS = 30
# World units per second, per unit of (1 + size): about Box2D's 5 cm/s sleep threshold for a body a
# metre across. Slower than this, a body counts as at rest (without friction, a box creeping along
# a flat top would otherwise never sleep).
SLEEP_SPEED = 0.03


@kernel
def count_rest(body, kind, asleep, bound, x, y, start_x, start_y, vx, vy, w, still, n, dt, speed_k,
               steps):  # pragma: no cover - compiled
    """Count, for the first ``n`` rows' awake dynamic bodies, the steps they have been at rest
    (``still``, updated: moved less than ``tol dt`` this step and slower than ``tol``, ``tol =
    speed_k (1 + bound)``; else 0); return the rows at rest for ``steps`` steps or more. One
    compiled pass: the same arithmetic, in the same order, as the numpy it replaced."""
    out = np.empty(n, dtype=np.intp)
    m = 0
    for r in range(n):
        if body[r] != DYNAMIC or kind[r] < 0 or asleep[r]:
            continue
        tol = speed_k * (1.0 + bound[r])
        moved = abs(x[r] - start_x[r]) + abs(y[r] - start_y[r])
        speed = abs(vx[r]) + abs(vy[r]) + abs(w[r]) * bound[r]
        if moved <= tol * dt and speed <= tol:
            still[r] += 1
        else:
            still[r] = 0
        if still[r] >= steps:
            out[m] = r
            m += 1
    return out[:m]


class Sleeping(Stage):
    """Count the steps each awake dynamic body has been at rest; put the restful to sleep; wake
    the sleepers linked to a body that woke."""

    name = "sleeping"
    needs = frozenset({"sleeping"})

    def __init__(self, pipeline) -> None:
        super().__init__(pipeline)
        # The sleepers' links: sorted pair keys of the entities that fell asleep touching each other.
        self.links = np.zeros(0, dtype=np.int64)
        self.wakes_seen = -1

    def run(self, frame: StepFrame) -> bool:
        store = self.bodies.store
        if self.links.size and store.wakes != self.wakes_seen:
            self._wake_linked()
        self.wakes_seen = store.wakes
        n0 = frame.start_x.size
        if n0 == 0:  # (nothing moved this step: the movement stage did not run)
            return False
        c = store.cols
        sleepy = count_rest(c["body"], c["kind"], c["asleep"], c["bound"], c["x"], c["y"], frame.start_x,
                            frame.start_y, c["vx"], c["vy"], c["w"], c["still"], n0, frame.dt, SLEEP_SPEED,
                            SLEEP_STEPS)
        if sleepy.size == 0:
            return True
        ta, tb = self._touching(frame)
        sleepy = self._whole_islands(ta, tb, sleepy)
        if sleepy.size:
            c["asleep"][sleepy] = True
            c["vx"][sleepy] = c["vy"][sleepy] = c["w"][sleepy] = 0.0
            store.sleep_dirty = True
            self._link(ta, tb)
        return True

    def _touching(self, frame: StepFrame) -> tuple[I64Array, I64Array]:
        """The rows of the pairs touching this step: its contacts, the response's resting pairs
        (bodies that fell together merely touch) and the bodies of joints, all still in the store."""
        store = self.bodies.store
        sa, sb = self.bodies.rows_of(frame.support[0]), self.bodies.rows_of(frame.support[1])
        ja, jb = frame.joined
        ra = np.concatenate([frame.contact_rows[0], sa, ja])
        rb = np.concatenate([frame.contact_rows[1], sb, jb])
        ok = (ra >= 0) & (rb >= 0) & (ra < store.n) & (rb < store.n)
        return ra[ok], rb[ok]

    def _link(self, ra: IntpArray, rb: IntpArray) -> None:
        """Remember which bodies now asleep touch each other (of the touching rows ``ra, rb``, the
        pairs of two dynamic sleepers)."""
        store = self.bodies.store
        both = store.asleep[ra] & store.asleep[rb] & (store.body[ra] == DYNAMIC) & (store.body[rb] == DYNAMIC)
        if both.any():
            ea, eb = store.entity[ra[both]], store.entity[rb[both]]
            keys = pair_keys(np.minimum(ea, eb), np.maximum(ea, eb))
            self.links = distinct(np.concatenate([self.links, keys]))

    def _wake_linked(self) -> None:
        """Wake, in turn, every sleeper linked to a body that is no longer asleep (woken, or gone);
        forget the links of bodies awake again."""
        store, bodies = self.bodies.store, self.bodies
        ea, eb = pair_parts(self.links)
        while True:
            ra, rb = bodies.rows_of(ea), bodies.rows_of(eb)
            sleeps_a = (ra >= 0) & store.asleep[np.maximum(ra, 0)]
            sleeps_b = (rb >= 0) & store.asleep[np.maximum(rb, 0)]
            wake = np.concatenate([ra[sleeps_a & ~sleeps_b], rb[sleeps_b & ~sleeps_a]])
            if wake.size == 0:
                break
            store.wake(distinct(wake))
        keep = sleeps_a & sleeps_b
        self.links = self.links[keep]

    def _whole_islands(self, ea: IntpArray, eb: IntpArray, ready_rows: IntpArray) -> IntpArray:
        """The ready rows whose whole group of touching dynamic bodies (the touching rows ``ea,
        eb``) is ready (or asleep)."""
        store = self.bodies.store
        ready = np.zeros(store.n, dtype=bool)
        ready[ready_rows] = True
        restless = (store.body == 0) & ~store.asleep
        for _ in range(store.n):
            blocked_a = ready[ea] & restless[eb] & ~ready[eb]
            blocked_b = ready[eb] & restless[ea] & ~ready[ea]
            if not (blocked_a.any() or blocked_b.any()):
                break
            ready[ea[blocked_a]] = False
            ready[eb[blocked_b]] = False
        return ready_rows[ready[ready_rows]]
