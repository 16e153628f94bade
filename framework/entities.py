"""The rules for what an entity may hold, checked before a scene changes anything.

A Hitbox needs a Transform; a Velocity needs a Transform; a static body has no Velocity; a
component belongs to one entity; a Transform is given at spawn and never replaced.
"""

from __future__ import annotations

from typing import Any

import esper

from .components import Body, Hitbox, Transform, Velocity, check_component
from .store import BodyStore
from .validation import InvalidValue

__all__ = ["MissingComponent", "check_added_component", "spawn_components"]


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
    kinds: dict[type, Any] = {}
    for comp in components:
        if comp is None or isinstance(comp, type):
            raise InvalidValue(f"spawn takes component instances, got {comp!r}")
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
    return t, v, h


def check_added_component(store: BodyStore, entity: int, component: Any) -> None:
    """Check ``component`` before it is added to ``entity`` (in the current esper world)."""
    if isinstance(component, Transform):
        raise InvalidValue("a Transform is given at spawn and edited in place; it cannot be replaced")
    try:
        check_component(component)
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
