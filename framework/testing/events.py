"""Event capture: which collision events happened between which entities, in which steps, with
assertions that say what did happen when they fail.

::

    log = EventLog(scene)           # records from now on (every sub-step)
    run(scene, 120)
    log.assert_started(Player, Coin, within=60)     # types match any entity that has them
    log.assert_never(Player, Hazard)
"""

from __future__ import annotations

from typing import Any, NamedTuple

import esper

from ..validation import InvalidValue
from .tracebacks import hide_on_failure

__all__ = ["EventLog", "Recorded"]


class Recorded(NamedTuple):
    """One event as the log saw it: the scene's ``frame`` (the step it happened in; 1 = the first
    step), its ``kind``, the entities ``a`` and ``b`` and their component types then."""

    frame: int
    kind: str
    a: int
    b: int
    types_a: frozenset[type]
    types_b: frozenset[type]

    def __str__(self) -> str:
        def who(e: int, types: frozenset[type]) -> str:
            names = sorted(t.__name__ for t in types if t.__module__.split(".")[0] != "framework")
            return f"{e}" + (f" ({', '.join(names)})" if names else "")

        return f"step {self.frame}: {self.kind} {who(self.a, self.types_a)} - {who(self.b, self.types_b)}"


Who = int | type


class EventLog:
    """Records a scene's collision events (``started``, ``ongoing``, ``ended``) from its creation
    on: a processor after the pipeline's last stage reads each sub-step's events."""

    def __init__(self, scene: Any) -> None:
        self.scene = scene
        self.records: list[Recorded] = []
        self._start = scene.frame
        scene.add_system(self._record, after="sleeping")

    def _record(self, scene: Any, dt: float) -> None:
        frame = scene.frame + 1  # the step under way
        for ev in scene.step_frame.events:
            self.records.append(Recorded(frame, ev.kind, ev.a, ev.b, _types(ev.a), _types(ev.b)))

    def between(self, a: Who, b: Who, kind: str | None = None) -> list[Recorded]:
        """The recorded events between ``a`` and ``b`` (each an entity id or a component type, in
        either order), of ``kind`` if given."""
        _check_kind(kind)
        return [r for r in self.records if (kind is None or r.kind == kind) and _pair(r, a, b)]

    def assert_started(self, a: Who, b: Who, *, within: int | None = None) -> Recorded:
        """A ``started`` event between ``a`` and ``b`` happened (within the first ``within`` steps
        since the log began); return the first."""
        __tracebackhide__ = hide_on_failure
        hits = self.between(a, b, "started")
        if within is not None:
            hits = [r for r in hits if r.frame - self._start <= within]
        if not hits:
            bound = f" within {within} steps" if within is not None else ""
            raise AssertionError(f"no 'started' event between {_name(a)} and {_name(b)}{bound}; "
                                 f"{self._summary()}")
        return hits[0]

    def assert_never(self, a: Who, b: Who, kind: str = "started") -> None:
        """No ``kind`` event between ``a`` and ``b`` was recorded."""
        __tracebackhide__ = hide_on_failure
        hits = self.between(a, b, kind)
        if hits:
            raise AssertionError(f"{len(hits)} '{kind}' event(s) between {_name(a)} and {_name(b)}, the first at "
                                 f"{hits[0]}")

    def _summary(self, limit: int = 8) -> str:
        if not self.records:
            return f"no events at all in {self.scene.frame - self._start} steps"
        shown = "; ".join(str(r) for r in self.records[:limit])
        more = f" (and {len(self.records) - limit} more)" if len(self.records) > limit else ""
        return f"what happened: {shown}{more}"


def _types(entity: int) -> frozenset[type]:
    try:
        comps: tuple[Any, ...] = esper.components_for_entity(entity)
        return frozenset(type(c) for c in comps)
    except KeyError:
        return frozenset()


def _matches(entity: int, types: frozenset[type], who: Who) -> bool:
    if isinstance(who, type):
        return who in types
    if isinstance(who, bool) or not isinstance(who, int):
        raise InvalidValue(f"an event side must be an entity id or a component type, got {who!r}")
    return entity == who


def _pair(r: Recorded, a: Who, b: Who) -> bool:
    return (_matches(r.a, r.types_a, a) and _matches(r.b, r.types_b, b)) or \
        (_matches(r.a, r.types_a, b) and _matches(r.b, r.types_b, a))


def _name(who: Who) -> str:
    return who.__name__ if isinstance(who, type) else f"entity {who}"


def _check_kind(kind: str | None) -> None:
    if kind not in (None, "started", "ongoing", "ended"):
        raise InvalidValue(f"kind must be 'started', 'ongoing' or 'ended', got {kind!r}")
