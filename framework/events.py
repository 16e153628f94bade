"""Collision events: ``started``, ``ongoing`` and ``ended``, one record per pair and step.

A pair is named by its two entities, smaller id first (``a < b``); the normal points from ``a``
toward ``b``. ``started`` is the first step of an overlap, ``ongoing`` every later step of it,
``ended`` the first step without it (also when either entity was despawned); an ``ended`` event
carries the contact of the last step the pair overlapped.

The tracker keeps the active pairs as a sorted array of int64 keys ``a << 32 | b`` so a step's
bookkeeping is a couple of vectorised set operations, whatever the number of pairs.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable, Iterable
from typing import Any, Literal, NamedTuple

import esper
import numpy as np
from numpy.typing import NDArray

from .collision.results import Vec2
from .entities import is_value_type
from .pair_tracking import track_pairs
from .shapes import Shape
from .validation import InvalidValue

__all__ = ["CollisionEvent", "CollisionHandlers", "PartEvent", "PairTracker", "STARTED", "ONGOING", "ENDED",
           "sorted_find", "sorted_member"]

STARTED: Literal["started"] = "started"
ONGOING: Literal["ongoing"] = "ongoing"
ENDED: Literal["ended"] = "ended"


class CollisionEvent(NamedTuple):
    """One pair's collision state change in one step."""

    kind: Literal["started", "ongoing", "ended"]
    a: int
    b: int
    normal: Vec2  # unit, from a toward b
    depth: float
    point: Vec2

    # Which shape of each body touched: 0 its Hitbox, i the i-th of its Parts (a body of several
    # shapes). Not fields: an event stays a tuple of six; a compound body's events are PartEvents.
    @property
    def part_a(self) -> int:
        """Which shape of ``a`` touched: 0, its Hitbox (a :class:`PartEvent` names its Parts)."""
        return 0

    @property
    def part_b(self) -> int:
        """Which shape of ``b`` touched: 0, its Hitbox (a :class:`PartEvent` names its Parts)."""
        return 0

    def flipped(self) -> CollisionEvent:
        """The same event seen from ``b``: entities (and parts) swapped, normal negated."""
        normal = Vec2(-self.normal.x + 0.0, -self.normal.y + 0.0)
        if self.part_a or self.part_b:
            return PartEvent(self.kind, self.b, self.a, normal, self.depth, self.point, self.part_b, self.part_a)
        return CollisionEvent(self.kind, self.b, self.a, normal, self.depth, self.point)


class PartEvent(CollisionEvent):
    """A :class:`CollisionEvent` where a body of several shapes (:class:`~framework.components.Parts`)
    touched with one of its other shapes: the same six fields, and ``part_a``, ``part_b``, which
    shape of ``a`` and of ``b`` (0: the entity's Hitbox; i: the i-th of its Parts). Equal to another
    event when the six fields and the parts are."""

    _parts: tuple[int, int]

    def __new__(cls, kind: Literal["started", "ongoing", "ended"], a: int, b: int, normal: Vec2, depth: float,
                point: Vec2, part_a: int = 0, part_b: int = 0) -> PartEvent:
        self = super().__new__(cls, kind, a, b, normal, depth, point)
        self._parts = (part_a, part_b)
        return self

    @property
    def part_a(self) -> int:
        """Which shape of ``a`` touched: 0 its Hitbox, i the i-th of its Parts."""
        return self._parts[0]

    @property
    def part_b(self) -> int:
        """Which shape of ``b`` touched: 0 its Hitbox, i the i-th of its Parts."""
        return self._parts[1]

    def __eq__(self, other: object) -> bool:
        return tuple.__eq__(self, other) is True and (
            getattr(other, "part_a", 0), getattr(other, "part_b", 0)) == (self.part_a, self.part_b)

    def __ne__(self, other: object) -> bool:
        return not self == other

    __hash__ = tuple.__hash__

    def __repr__(self) -> str:
        return (f"PartEvent(kind={self.kind!r}, a={self.a!r}, b={self.b!r}, normal={self.normal!r}, "
                f"depth={self.depth!r}, point={self.point!r}, part_a={self.part_a!r}, part_b={self.part_b!r})")


class StepContacts(NamedTuple):
    """This step's overlapping pairs as arrays (entity ids, a < b), sorted by (a, b)."""

    a: NDArray[np.int64]
    b: NDArray[np.int64]
    nx: NDArray[np.float64]
    ny: NDArray[np.float64]
    depth: NDArray[np.float64]
    px: NDArray[np.float64]
    py: NDArray[np.float64]

    @classmethod
    def empty(cls) -> StepContacts:
        z = np.zeros(0)
        i = np.zeros(0, dtype=np.int64)
        return cls(i, i, z, z, z, z, z)

    def take(self, idx: NDArray[np.intp]) -> StepContacts:
        return StepContacts(self.a[idx], self.b[idx], self.nx[idx], self.ny[idx], self.depth[idx], self.px[idx],
                            self.py[idx])


def pair_keys(a: NDArray[np.int64], b: NDArray[np.int64]) -> NDArray[np.int64]:
    """One int64 per pair of entity ids (each below 2**32), ordered as ``(a, b)`` is."""
    return (a.astype(np.int64) << 32) | b.astype(np.int64)


def pair_parts(keys: NDArray[np.int64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The ``(a, b)`` of :func:`pair_keys`."""
    return keys >> 32, keys & 0xFFFFFFFF


def sorted_find(
    keys: NDArray[np.int64], table: NDArray[np.int64],
) -> tuple[NDArray[np.intp], NDArray[np.bool_]]:
    """Where each of ``keys`` is in the sorted ``table`` (one binary search per key), and whether
    it is there at all (where not, the position is meaningless)."""
    if table.size == 0:
        return np.zeros(keys.size, dtype=np.int64), np.zeros(keys.size, dtype=bool)
    pos = np.minimum(np.searchsorted(table, keys), table.size - 1)
    return pos, table[pos] == keys


def sorted_member(keys: NDArray[np.int64], table: NDArray[np.int64]) -> NDArray[np.bool_]:
    """``np.isin(keys, table)`` for a sorted ``table``."""
    return sorted_find(keys, table)[1]


class PairTracker:
    """Turns each step's overlapping pairs into started / ongoing / ended events."""

    def __init__(self) -> None:
        self.active = StepContacts.empty()
        self.keys = np.zeros(0, dtype=np.int64)

    def update(self, now: StepContacts) -> tuple[NDArray[np.bool_], NDArray[np.bool_], StepContacts]:
        """Record this step's pairs; return (started mask over ``now``, ongoing mask, ended pairs)."""
        if now.a.size == 0 and self.keys.size == 0:  # (nothing touches, nor did: no merge to make)
            self.active = now  # (the keys: still none)
            return np.zeros(0, dtype=bool), np.zeros(0, dtype=bool), StepContacts.empty()
        keys, was, gone = track_pairs(now.a, now.b, self.keys)  # (one compiled merge)
        ended = self.active.take(gone) if gone.size else StepContacts.empty()
        self.active, self.keys = now, keys
        return ~was, was, ended


def to_events(
    contacts: StepContacts, started: NDArray[np.bool_], ongoing: NDArray[np.bool_], ended: StepContacts,
    parts: tuple[NDArray[np.int64], NDArray[np.int64]] | None = None,
    ended_parts: tuple[NDArray[np.int64], NDArray[np.int64]] | None = None,
) -> list[CollisionEvent]:
    """Event records, sorted by pair (a, b), then ended before started before ongoing (``parts``,
    ``ended_parts``: which shape of each body touched, beside ``contacts`` and ``ended``; None:
    part 0 of each)."""
    out: list[tuple[int, int, int, CollisionEvent]] = []
    for group, kind, order, shapes in ((ended, ENDED, 0, ended_parts), (contacts, None, 1, parts)):
        if len(group.a) == 0:
            continue
        cols = [arr.tolist() for arr in group]
        st = started.tolist() if kind is None else None
        if shapes is None:
            for i, (a, b, nx, ny, depth, px, py) in enumerate(zip(*cols)):
                k = kind if kind is not None else (STARTED if st[i] else ONGOING)  # type: ignore[index]
                out.append((a, b, order, CollisionEvent(k, a, b, Vec2(nx, ny), depth, Vec2(px, py))))
        else:
            pa, pb = shapes[0].tolist(), shapes[1].tolist()
            for i, (a, b, nx, ny, depth, px, py) in enumerate(zip(*cols)):
                k = kind if kind is not None else (STARTED if st[i] else ONGOING)  # type: ignore[index]
                ev = (PartEvent(k, a, b, Vec2(nx, ny), depth, Vec2(px, py), pa[i], pb[i]) if pa[i] or pb[i] else
                      CollisionEvent(k, a, b, Vec2(nx, ny), depth, Vec2(px, py)))
                out.append((a, b, order, ev))
    out.sort(key=lambda t: (t[0], t[1], t[2]))
    return [t[3] for t in out]


Handler = Callable[[Any, CollisionEvent], Any]


def _takes_one_argument(fn: Callable[..., Any]) -> bool:
    try:
        params = inspect.signature(fn).parameters.values()
    except (TypeError, ValueError):
        return False
    if any(p.kind == p.VAR_POSITIONAL for p in params):
        return False
    return sum(p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD) for p in params) == 1


def _event_only(one: Callable[[CollisionEvent], Any]) -> Handler:
    """A handler that takes only the event, called as ``handler(scene, event)``."""

    @functools.wraps(one)  # keeps its name (``__wrapped__``) for error messages
    def handler(scene: Any, event: CollisionEvent) -> Any:
        return one(event)

    return handler


def _handler_name(handler: Callable[..., Any]) -> str:
    """How an error names a handler: its qualified name (``Game.on_hit``, ``<lambda>``), with its
    module, or the repr of a callable object that has none."""
    fn = getattr(handler, "__wrapped__", handler)
    name = getattr(fn, "__qualname__", None)
    if not isinstance(name, str):
        return repr(fn)
    module = getattr(fn, "__module__", None)
    return f"{module}.{name}" if isinstance(module, str) else name


def _type_name(t: type) -> str:
    return getattr(t, "__name__", repr(t))


def _component_class(role: str, value: object) -> type:
    """``value`` if it is a class whose instances may be components, else :class:`InvalidValue`
    naming what was passed."""
    if isinstance(value, type):
        if issubclass(value, Shape):
            raise InvalidValue(f"on_collision got the shape class {value.__name__} as {role}: a shape is held by a "
                               "Hitbox, never a component of its own; pass Hitbox (or a class of your own)")
        if is_value_type(value):
            raise InvalidValue(f"on_collision got the class {value.__name__} as {role}: {value.__name__} is not a "
                               "component class (spawn refuses its instances); pass a class of your own")
        return value
    if isinstance(value, str):
        hint = f"pass the class itself ({value}), not its name"
    elif value is None:
        hint = "pass a component class"
    else:
        cls = type(value).__name__
        hint = f"pass the class {cls} itself, not an instance of it ({cls}())"
    raise InvalidValue(f"on_collision takes component classes, got {value!r} as {role}: {hint}")


class CollisionHandlers:
    """The scene's collision handlers (``scene.on_collision``) and their dispatch after each sub-step.

    ``rows_of``: entity ids -> store rows (for :meth:`wanted`). Entities despawned during a step
    are remembered by their component types until the dispatch, so their ``ended`` events still
    reach the handlers of those types."""

    def __init__(self, rows_of: Callable[[NDArray[np.int64]], NDArray[np.int64]]) -> None:
        self._rows_of = rows_of
        self._handlers: list[tuple[type, type, Handler, frozenset[str]]] = []
        self._ghosts: dict[int, set[type]] = {}

    def add(self, type_a: type, type_b: type, handler: Callable[..., Any], kinds: Iterable[str] | str) -> None:
        """Register ``handler`` (see ``Scene.on_collision``); :class:`InvalidValue` for a type that
        is not a class (an instance, a string), a handler that is not callable, unknown kinds."""
        type_a = _component_class("type_a", type_a)
        type_b = _component_class("type_b", type_b)
        ks = frozenset([kinds] if isinstance(kinds, str) else kinds)
        if not ks <= {STARTED, ONGOING, ENDED}:
            raise InvalidValue(f"kinds must be among 'started', 'ongoing', 'ended', got {sorted(ks)!r}")
        if not callable(handler):
            raise InvalidValue(f"handler must be callable, got {handler!r}")
        if _takes_one_argument(handler):
            handler = _event_only(handler)
        self._handlers.append((type_a, type_b, handler, ks))

    def remember(self, entity: int, types: set[type]) -> None:
        """``entity`` is being despawned: keep its component types for this step's dispatch."""
        self._ghosts[entity] = types

    def wanted(self, ra: NDArray[np.int64], rb: NDArray[np.int64]) -> NDArray[np.bool_]:
        """Mask of the pairs (rows) that some handler's two component types could match."""
        need = np.zeros(ra.size, dtype=bool)
        for ta, tb, _handler, _kinds in self._handlers:
            has_a, has_b = self._has_type(ta, ra, rb), self._has_type(tb, ra, rb)
            need |= (has_a[ra] & has_b[rb]) | (has_a[rb] & has_b[ra])
        return need

    def _has_type(self, component_type: type, ra: NDArray[np.int64], rb: NDArray[np.int64]) -> NDArray[np.bool_]:
        """Per row: whether the entity has a ``component_type`` component (current esper world)."""
        size = int(max(ra.max(), rb.max())) + 1 if ra.size else 0
        mask = np.zeros(size, dtype=bool)
        ents = [e for e, _ in esper.get_component(component_type)]
        if ents:
            rows = self._rows_of(np.array(ents, dtype=np.int64))
            rows = rows[(rows >= 0) & (rows < size)]
            mask[rows] = True
        return mask

    def dispatch(self, scene: Any, events: Callable[[], list[CollisionEvent]], errors: list[Exception],
                 where: str = "") -> None:
        """Call the handlers for ``events()`` (made only if some handler is registered), each event
        turned so that ``event.a`` has the handler's first type; then forget the despawned.

        A handler that raises does not stop the others: its exception gets a note naming the
        handler, the event and ``where`` (the step), and is appended to ``errors``, for the scene
        to raise once the step is complete."""
        ghosts = self._ghosts
        self._ghosts = {}
        if not self._handlers:
            return

        def has(e: int, t: type) -> bool:
            if e in ghosts:
                return t in ghosts[e]
            return esper.has_component(e, t)

        for ev in events():
            for ta, tb, handler, ks in self._handlers:
                if ev.kind not in ks:
                    continue
                if has(ev.a, ta) and has(ev.b, tb):
                    turned = ev
                elif has(ev.b, ta) and has(ev.a, tb):
                    turned = ev.flipped()
                else:
                    continue
                try:
                    handler(scene, turned)
                except Exception as exc:
                    exc.add_note(f"raised by the collision handler {_handler_name(handler)} "
                                 f"(on_collision({_type_name(ta)}, {_type_name(tb)})) for the {turned.kind!r} event "
                                 f"of entity {turned.a} ({_type_name(ta)}) and entity {turned.b} ({_type_name(tb)})"
                                 f"{where}")
                    errors.append(exc)
