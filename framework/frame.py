"""The frame: what one step (one pass of the pipeline) computed, handed from stage to stage.

Every stage reads what the stages before it wrote here (and the store), and writes its own results
here; nothing passes between stages any other way. A new frame starts each sub-step; the scene
keeps the last one, which is what ``scene.events``, ``scene.contacts``, ``scene.resolved``,
``scene.counters`` and the debug overlay read between steps.

Data flow (one way): movement -> ``start_x/start_y, ccd_rows, ccd_start`` -> continuous detection
-> ``swept_paths`` -> broad phase -> ``pairs, n_asleep`` -> narrow phase -> ``contacts,
contact_rows, started, ended`` -> response -> ``resolved, support`` -> sleeping -> render.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, TypeAlias

import numpy as np
from numpy.typing import NDArray

from .events import CollisionEvent, StepContacts, to_events

__all__ = ["NO_POINTS", "NO_RESOLVED", "NO_SUPPORT", "Points", "Resolved", "StepFrame", "Support", "add_counters",
           "new_counters"]

_I: TypeAlias = NDArray[np.int64]
_F: TypeAlias = NDArray[np.float64]
#: The contacts the response applied: entities a, b, normal x, y, push.
Resolved: TypeAlias = tuple[_I, _I, _F, _F, _F]
#: The pairs acted on, kept for the next step: a, b, nx, ny, push, impulse, gap, tangent push and impulse.
Support: TypeAlias = tuple[_I, _I, _F, _F, _F, _F, _F, _F, _F]
#: Contact points acted on: pair key, slot, push, impulse, tangent push and impulse, x, y.
Points: TypeAlias = tuple[_I, _I, _F, _F, _F, _F, _F, _F]

_INTS: _I = np.zeros(0, dtype=np.int64)
_FLOATS: _F = np.zeros(0)
NO_RESOLVED: Resolved = (_INTS, _INTS, _FLOATS, _FLOATS, _FLOATS)
NO_SUPPORT: Support = (*NO_RESOLVED, _FLOATS, _FLOATS, _FLOATS, _FLOATS)
NO_POINTS: Points = (_INTS, _INTS, _FLOATS, _FLOATS, _FLOATS, _FLOATS, _FLOATS, _FLOATS)


def new_counters() -> dict[str, Any]:
    """A sub-step's counters, before any stage ran (see ``Scene.counters``)."""
    return {"systems": [], "integrated": 0, "rehashed": 0, "candidate_pairs": 0, "narrow_tests": {}, "contacts": 0,
            "events": 0, "resolved": 0, "late_contacts": 0, "ccd_stopped": 0, "asleep": 0}


def add_counters(total: dict[str, Any], step: dict[str, Any]) -> None:
    """Sum one sub-step's counters into ``total`` (lists of systems: in order, once)."""
    for key, value in step.items():
        if isinstance(value, dict):
            add_counters(total.setdefault(key, {}), value)
        elif isinstance(value, list):
            seen = total.setdefault(key, [])
            seen.extend(v for v in value if v not in seen)
        else:
            total[key] = total.get(key, 0) + value


def _pairs() -> tuple[_I, _I, _I, _I]:
    return (_INTS, _INTS, _INTS, _INTS)


@dataclass(eq=False)
class StepFrame:
    """One sub-step's data. ``dt``: its length; ``render``: whether the render stage runs in it
    (the last sub-step of a step)."""

    dt: float = 0.0
    render: bool = False
    counters: dict[str, Any] = field(default_factory=new_counters)
    stage_ms: dict[str, float] = field(default_factory=dict)
    # movement: where every row started the step (rows spawned during it: none), the swept bodies
    start_x: _F = field(default_factory=lambda: _FLOATS)
    start_y: _F = field(default_factory=lambda: _FLOATS)
    ccd_rows: NDArray[np.intp] = field(default_factory=lambda: _INTS)
    ccd_start: tuple[_F, _F] = (_FLOATS, _FLOATS)
    # continuous detection: each swept body's path ((x0, y0), (x1, y1)), for the overlay
    swept_paths: list[tuple[tuple[float, float], tuple[float, float]]] = field(default_factory=list)
    # broad phase: candidate pairs (entities a < b, their rows) and how many bodies sleep
    pairs: tuple[_I, _I, _I, _I] = field(default_factory=_pairs)
    n_asleep: int = 0
    # narrow phase: the overlapping pairs, their rows, which started, which ended
    contacts: StepContacts = field(default_factory=StepContacts.empty)
    contact_rows: tuple[_I, _I] = (_INTS, _INTS)
    started: NDArray[np.bool_] = field(default_factory=lambda: np.zeros(0, dtype=bool))
    ended: StepContacts = field(default_factory=StepContacts.empty)
    # which shape of each body touched (the soft step, in a scene with compound bodies; else None:
    # every shape is part 0): (part a, part b) beside ``contacts`` and beside ``ended``
    parts: tuple[_I, _I] | None = None
    ended_parts: tuple[_I, _I] | None = None
    # response: the contacts applied (a, b, nx, ny, pushed) and the pairs acted on, kept for the next
    # step with their push, impulse, the gap they ended with and their friction's tangential push
    # and impulse (a, b, nx, ny, push, impulse, gap, tangent push, tangent impulse)
    resolved: Resolved = NO_RESOLVED
    support: Support = NO_SUPPORT
    # the soft step's joints: the rows of each joint's two bodies (joined bodies sleep and wake together)
    joined: tuple[_I, _I] = (_INTS, _INTS)
    # where bodies turn (see framework.systems.turning): each contact point acted on, by pair and
    # slot (pair key, slot, push, impulse, tangent push, tangent impulse, x, y), sorted by pair
    points: Points = NO_POINTS
    # queries during the step: (origin, end, first hit or None), for the overlay
    ray_log: list[tuple[tuple[float, float], tuple[float, float], Any]] = field(default_factory=list)
    _events: list[CollisionEvent] | None = None

    def next(self, dt: float, render: bool) -> StepFrame:
        """The frame of the next sub-step. Until its stages replace them, it shows this frame's
        contacts, events, resolved and resting pairs: what a game system that runs before the
        narrow phase (or the response) reads, and what the response starts from (last step's
        resting pairs)."""
        return StepFrame(dt=dt, render=render, pairs=self.pairs, contacts=self.contacts,
                         contact_rows=self.contact_rows, started=self.started, ended=self.ended,
                         parts=self.parts, ended_parts=self.ended_parts,
                         resolved=self.resolved, support=self.support, points=self.points,
                         _events=self._events)

    @property
    def events(self) -> list[CollisionEvent]:
        """The frame's collision events (made on first use), sorted by pair: ended, then started
        or ongoing."""
        if self._events is None:
            self._events = to_events(self.contacts, self.started, ~self.started, self.ended, self.parts,
                                     self.ended_parts)
        return self._events
