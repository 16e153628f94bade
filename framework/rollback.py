"""What a step may change, kept from before it, so that a step that fails changes nothing.

A step fails when its pipeline raises (a stage, or a game system or processor among them) or
leaves a bad value in a body (a game system wrote NaN, a motion overflowed). The scene then puts
back what the pipeline changes: every body's pose, velocity and sleep, the pairs the narrow phase
tracks and the last step's frame (contacts, events, the solver's warm start), the soft step's
candidate pairs and warm starts (kept by reference: its kernel never changes them in place), the
sleeping stage's links, the character controllers' state, the step counter and clock; entities
spawned during the step are removed and despawns it asked for are dropped. It costs a copy of eight
columns a step (about 30 us at 10,000 bodies, about 1% of such a step). What game code did outside
the scene (its own components' fields, resources, files) is the game's: the scene cannot take that
back.

If a system changed the scene's structure before the failure (added or removed a Hitbox or a
Velocity), the rows no longer line up with what was kept: the scene is then left as the failure
found it, and the exception says so.
"""

from __future__ import annotations

from typing import Any

import esper
import numpy as np
from numba import njit

from .character import CharacterController

__all__ = ["StepRollback"]

_COLUMNS = ("x", "y", "rot", "vx", "vy", "w", "still", "asleep")
_STRUCTURE = ("entity", "kind", "body", "has_vel")
# the character controller's state, written by each step (its settings are the game's)
_CONTROLLER_STATE = ("drop_through", "on_floor", "floor_normal", "floor_entity", "on_wall", "wall_normal",
                     "on_ceiling", "crushed")


_KEPT = _STRUCTURE + _COLUMNS


@njit(cache=True)
def _keep(entity, kind, body, has_vel, x, y, rot, vx, vy, w, still, asleep):
    """The columns (of one length, in :data:`_KEPT`'s order) as the rows of a new float array."""
    n = x.size
    out = np.empty((12, n))
    for r in range(n):
        out[0, r], out[1, r], out[2, r], out[3, r] = entity[r], kind[r], body[r], has_vel[r]
        out[4, r], out[5, r], out[6, r], out[7, r], out[8, r], out[9, r] = x[r], y[r], rot[r], vx[r], vy[r], w[r]
        out[10, r], out[11, r] = still[r], asleep[r]
    return out


class StepRollback:
    """The state of ``scene`` before a step (:meth:`restore` puts it back)."""

    def __init__(self, scene: Any) -> None:
        store = scene.bodies.store
        n = self.n = store.n
        # the rows' structure (which entity, shape kind, body kind, whether it has a Velocity) and
        # the columns a step changes, as the rows of one float array (every value of them is exact
        # in a float), copied in one compiled pass
        c = store.cols
        self.kept = _keep(*(c[name][:n] for name in _KEPT))
        self.frame = scene._pipeline.frame
        tracker = scene.tracker
        self.tracker = (tracker.active, tracker.keys)
        sleeping = scene._stages.get("sleeping")
        self.sleeping = None if sleeping is None else (sleeping.links, sleeping.wakes_seen)
        self.soft = scene._stages["soft_step"].state()
        self.controllers = [(c, {name: getattr(c, name) for name in _CONTROLLER_STATE}, set(c.dropping))
                            for _e, c in esper.get_component(CharacterController)]
        self.clock = (scene.frame, scene.time, scene._totals)
        self.next_entity = scene._next_entity()  # (ids from this one on are spawned during the step)

    def restore(self, scene: Any) -> bool:
        """Put the scene back as it was before the step; whether it could (False: a system changed
        the scene's structure before the failure, see the module docstring)."""
        scene._pending_despawn = []
        for e in [e for e in esper._entities if e >= self.next_entity]:
            scene._remove(e)  # spawned during the failed step
        store = scene.bodies.store
        n, kept = self.n, self.kept
        if store.n != n or not all(np.array_equal(store.cols[name][:n], kept[i]) for i, name in enumerate(_STRUCTURE)):
            return False
        for i, name in enumerate(_COLUMNS, len(_STRUCTURE)):
            store.cols[name][:n] = kept[i]
        store.motion += 1  # (caches keyed on motion look again)
        store.sleep_dirty = True
        store.written.clear()
        store.bad.clear()
        scene._pipeline.frame = self.frame
        tracker = scene.tracker
        tracker.active, tracker.keys = self.tracker
        scene._stages["soft_step"].restore(self.soft)
        sleeping = scene._stages.get("sleeping")
        if sleeping is not None and self.sleeping is not None:
            sleeping.links, sleeping.wakes_seen = self.sleeping
        for controller, state, dropping in self.controllers:
            for name, value in state.items():
                object.__setattr__(controller, name, value)
            controller.dropping.clear()
            controller.dropping.update(dropping)
        scene.frame, scene.time, scene._totals = self.clock
        return True
