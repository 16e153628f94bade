"""What a step may change, kept from before it, so that a step that fails changes nothing.

A step fails when its pipeline raises (a stage, or a game system or processor among them) or
leaves a bad value in a body (a game system wrote NaN, a motion overflowed). The scene then puts
back what the pipeline changes: every body's pose, velocity and sleep, the pairs the narrow phase
tracks and the last step's frame (contacts, events, the solver's warm start), the soft step's
candidate pairs and warm starts (kept by reference: its kernel never changes them in place), the
sleeping stage's links, the character controllers' state, the step counter and clock; entities
spawned during the step are removed and despawns it asked for are dropped. It costs a copy of the
rows that are not static a step (about 30 us at 10,000 bodies, about 1% of such a step); a static
row is saved only if it changes during the step (game code writes it, or a structural change), since
the pipeline never moves one, so a level of 100,000 tiles adds nothing. What game code did outside
the scene (its own components' fields, resources, files) is the game's: the scene cannot take that
back.

If a system changed the scene's structure before the failure (added or removed a Hitbox or a
Velocity), the rows no longer line up with what was kept: the scene is then left as the failure
found it, and the exception says so.
"""

from __future__ import annotations

from operator import itemgetter
from typing import Any

import esper
import numpy as np

from .character import CharacterController
from .compiled import kernel
from .store import ROW_STATE, ROW_STRUCTURE

__all__ = ["StepRollback"]

# the character controller's state, written by each step (its settings are the game's)
_CONTROLLER_STATE = ("drop_through", "on_floor", "floor_normal", "floor_entity", "on_wall", "wall_normal",
                     "on_ceiling", "crushed")


# the columns of ROW_STATE, out of the store's table in one call
_STATE_COLUMNS = itemgetter(*ROW_STATE)


@kernel
def _keep(rows, entity, kind, body, has_vel, x, y, rot, vx, vy, w, still, asleep):
    """The ``rows`` of the columns (in :data:`~framework.store.ROW_STATE`'s order) as the rows of a
    new float array, one column per row kept."""
    out = np.empty((12, rows.size))
    for k in range(rows.size):
        r = rows[k]
        out[0, k], out[1, k], out[2, k], out[3, k] = entity[r], kind[r], body[r], has_vel[r]
        out[4, k], out[5, k], out[6, k], out[7, k], out[8, k], out[9, k] = x[r], y[r], rot[r], vx[r], vy[r], w[r]
        out[10, k], out[11, k] = still[r], asleep[r]
    return out


class StepRollback:
    """The state of ``scene`` before a step (:meth:`restore` puts it back)."""

    def __init__(self, scene: Any) -> None:
        store = scene.bodies.store
        self.n = store.n
        # every row that is not static, whole (structure and the columns a step changes), copied in
        # one compiled pass; the static rows are saved by the store before their first change
        # (BodyStore.begin_undo): the pipeline never moves them, so a level's tiles cost nothing
        c = store.cols
        self.rows = store.active()[2]
        self.kept = _keep(self.rows, *_STATE_COLUMNS(c))
        store.begin_undo()
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
        saved = store.end_undo()
        c, rows, kept = store.cols, self.rows, self.kept
        if store.n != self.n or not all(np.array_equal(c[name][rows], kept[i]) for i, name in enumerate(ROW_STRUCTURE)):
            return False
        for r, values in saved.items():
            if any(c[name][r] != values[i] for i, name in enumerate(ROW_STRUCTURE)):
                return False
        for i, name in enumerate(ROW_STATE[len(ROW_STRUCTURE):], len(ROW_STRUCTURE)):
            c[name][rows] = kept[i]
            for r, values in saved.items():
                c[name][r] = values[i]
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
