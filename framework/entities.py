"""The rules for what an entity may hold, checked before a scene changes anything.

A Hitbox needs a Transform; a Velocity needs a Transform; a static body has no Velocity; a
component belongs to one entity; a Transform is given at spawn and never replaced.
"""

from __future__ import annotations

import types
from typing import Any

import esper

from .components import Body, Hitbox, Parts, Transform, Velocity, check_component
from .limits import check_hitbox_limits, check_position
from .shapes import ChainSegment, Shape
from .sprites import Animation, Frame
from .store import BodyStore
from .validation import InvalidValue

__all__ = ["MissingComponent", "check_added_component", "check_is_component", "check_parts", "spawn_components"]

# Modules whose types are values, not components: Python's built-in types (str, int, float, bool,
# bytes, tuple, list, dict, set, None, functions, modules, ...), the standard library's numbers and
# containers, numpy's scalars and arrays. A game's own classes (plain classes, dataclasses,
# namedtuples, subclasses of built-in types) are components.
_VALUE_MODULES = frozenset(("builtins", "numpy", "fractions", "decimal", "collections", "array", "functools"))
_FUNCTIONS = (types.FunctionType, types.BuiltinFunctionType, types.MethodType, types.BuiltinMethodType)


def _a(noun: str) -> str:
    return ("an " if noun[:1].lower() in "aeiou" else "a ") + noun


def _short(value: object, limit: int = 120) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 4] + " ..."


def is_value_type(cls: type) -> bool:
    """Whether instances of ``cls`` are plain values (built-in or library types), not components."""
    return str(getattr(cls, "__module__", "")).partition(".")[0] in _VALUE_MODULES


def check_is_component(call: str, value: object) -> None:
    """:class:`InvalidValue` if ``value`` cannot be a component of an entity, with what was meant.

    A component is an instance of a class the game (or the framework) defines. Refused: None,
    classes, tuples and lists (components are passed one by one), shapes (held by a Hitbox), a
    Body kind (a Hitbox field), a Frame or Animation (held by a Visual), functions, and the values
    of built-in and library types (str, int, float, bool, bytes, dict, set, numpy scalars, ...)."""
    shown = _short(value)
    if value is None:
        raise InvalidValue(f"{call} takes component instances, got None: None is not a component; leave it out")
    if isinstance(value, type):
        name = value.__name__
        raise InvalidValue(f"{call} takes component instances, got the class {name}: pass an instance ({name}())")
    if isinstance(value, Shape):
        name = type(value).__name__
        raise InvalidValue(f"{call} got {_a(name)}: a shape is not a component; wrap a shape in a Hitbox, "
                           f"e.g. Hitbox({shown})")
    if isinstance(value, Body):
        raise InvalidValue(f"{call} got {shown}: a body kind is not a component; give it to the Hitbox, "
                           f"e.g. Hitbox(shape, body=Body.{value.name})")
    if isinstance(value, (Frame, Animation)):
        field = "frame" if isinstance(value, Frame) else "animation"
        raise InvalidValue(f"{call} got {_a(type(value).__name__)}, {shown}: it is not a component; give it to "
                           f"a Visual, e.g. Visual({field}=...)")
    cls = type(value)
    if isinstance(value, (tuple, list)) and is_value_type(cls):
        kind = cls.__name__
        fix = ("pass the components themselves, one argument each: spawn(*components)" if call == "spawn"
               else "add the components one at a time")
        raise InvalidValue(f"{call} takes components, not a {kind}: got {shown}; {fix}")
    if isinstance(value, _FUNCTIONS) or (is_value_type(cls) and callable(value)):
        raise InvalidValue(f"{call} got the function {shown}: a function is not a component (a system is "
                           "added with scene.add_system, a collision handler with scene.on_collision)")
    if is_value_type(cls):
        kind = _a(cls.__name__)
        raise InvalidValue(f"{call} got {shown}, {kind}: {kind} is not a component; use an instance of a "
                           "component class (a class of your own holding the value, e.g. class Name: ...)")


class MissingComponent(KeyError):
    """``scene.get(entity, Type)`` for an entity without a ``Type`` component, or one that does not
    exist (despawned): a ``KeyError`` whose message names the entity and the type.

    ``entity`` and ``component_type`` are what was asked for."""

    def __init__(self, message: str, entity: Any, component_type: Any) -> None:
        super().__init__(message)
        self.entity = entity
        self.component_type = component_type

    def __str__(self) -> str:  # KeyError's own quotes the message as a repr
        return str(self.args[0])


def spawn_components(components: tuple[Any, ...]) -> tuple[Any, Any, Any]:
    """Check the components of a new entity; return its ``(Transform, Velocity, Hitbox)`` (each
    or None). ``ValueError`` naming the problem otherwise."""
    for comp in components:  # before anything is checked (or normalised) in place
        check_is_component("spawn", comp)
    kinds: dict[type, Any] = {}
    for comp in components:
        check_component(comp)
        if type(comp) in kinds:
            raise InvalidValue(f"spawn got two {type(comp).__name__} components: {components!r}")
        kinds[type(comp)] = comp
    t, v, h = kinds.get(Transform), kinds.get(Velocity), kinds.get(Hitbox)
    for comp in (t, v, h):
        if comp is not None and comp._store is not None:
            raise InvalidValue(f"{comp!r} already belongs to an entity; give each entity its own")
    if h is not None and t is None:
        raise InvalidValue("an entity with a Hitbox needs a Transform")
    if h is not None and h.body is Body.STATIC and v is not None:
        raise InvalidValue("a static body never moves: give it no Velocity (or make it kinematic)")
    if v is not None and t is None:
        raise InvalidValue("an entity with a Velocity needs a Transform")
    if t is not None:
        check_position(t.x, t.y)
    if h is not None:
        check_hitbox_limits(h)
    parts = kinds.get(Parts)
    if parts is not None:
        if h is None:
            raise InvalidValue("an entity with Parts needs a Hitbox (its part 0, that gives the body its kind)")
        check_parts(parts, h)
    return t, v, h


def check_parts(parts: Parts, hitbox: Hitbox | None) -> None:
    """Refuse a :class:`~framework.components.Parts` an entity whose Hitbox is ``hitbox`` cannot
    take: a part with a bad field, beyond the scene's limits, already another entity's, or whose
    body kind is not the Hitbox's. Normalises the parts' fields in place, as spawning a Hitbox does."""
    if parts._store is not None:
        raise InvalidValue(f"{parts!r} already belongs to an entity; give each entity its own")
    for i, part in enumerate(parts.hitboxes, start=1):
        try:
            check_component(part)
            check_hitbox_limits(part)
        except InvalidValue as exc:
            raise InvalidValue(f"Parts: part {i}: {exc}") from None
        if isinstance(part.shape, ChainSegment):
            raise InvalidValue(f"Parts: part {i} is a chain segment: a chain's segments are bodies of their own "
                               "(framework.chains.spawn_chain); a plain Segment may be a part")
        if part is hitbox or part._store is not None:
            raise InvalidValue(f"Parts: part {i} is a Hitbox that belongs to an entity already; give each its own")
        if hitbox is not None and part.body is not hitbox.body:
            raise InvalidValue(f"Parts: part {i} is body={part.body.value!r}, the entity's Hitbox "
                               f"body={hitbox.body.value!r}: the shapes of one body are of one kind")


def check_added_component(store: BodyStore, entity: int, component: Any) -> None:
    """Check ``component`` before it is added to ``entity`` (in the current esper world)."""
    check_is_component("add_component", component)
    if isinstance(component, Transform):
        raise InvalidValue("a Transform is given at spawn and edited in place; it cannot be replaced")
    try:
        check_component(component)
    except InvalidValue as exc:
        raise InvalidValue(f"entity {entity}: {exc}") from None
    if isinstance(component, Hitbox):
        try:
            check_hitbox_limits(component)
        except InvalidValue as exc:
            raise InvalidValue(f"entity {entity}: {exc}") from None
    if isinstance(component, Parts):
        hb = esper.try_component(entity, Hitbox)
        if entity not in store.row_of or hb is None:
            raise InvalidValue(f"entity {entity}: Parts need a Hitbox (and a Transform) on the entity first")
        try:
            check_parts(component, hb)
        except InvalidValue as exc:
            raise InvalidValue(f"entity {entity}: {exc}") from None
    if isinstance(component, (Velocity, Hitbox)):
        if entity not in store.row_of:
            raise InvalidValue(f"entity {entity} has no Transform")
        if component._store is not None:
            raise InvalidValue(f"{component!r} already belongs to an entity")
        hb = component if isinstance(component, Hitbox) else esper.try_component(entity, Hitbox)
        has_v = isinstance(component, Velocity) or esper.has_component(entity, Velocity)
        if hb is not None and hb.body is Body.STATIC and has_v:
            raise InvalidValue("a static body never moves: give it no Velocity")
