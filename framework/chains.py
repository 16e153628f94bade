"""Chains in a scene: terrain drawn as lines, one static body per segment.

A :class:`~framework.shapes.Chain` is a polyline or a loop of one-sided segments with ghost
vertices (:class:`~framework.shapes.ChainSegment`); :func:`spawn_chain` puts one body per segment
into a scene, each with a ``Transform`` at the chain's place and a ``Hitbox`` holding its segment,
so the broad phase sees each segment's own bounds (a chain of hundreds of segments costs a body
only where something is near it).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .components import Hitbox, Transform
from .shapes import Chain
from .validation import InvalidValue

if TYPE_CHECKING:
    from .scene import Scene

__all__ = ["spawn_chain"]


def spawn_chain(scene: Scene, chain: Chain, position: tuple[float, float] = (0.0, 0.0), rotation: float = 0.0,
                **hitbox: Any) -> list[int]:
    """Spawn one body per segment of ``chain`` (its points relative to ``position``, turned by
    ``rotation``) and return their entities, in the chain's order. ``hitbox``: the keyword
    arguments of every segment's :class:`~framework.components.Hitbox` (``layer``, ``mask``,
    ``friction``, ``restitution``...; ``body`` is ``"static"`` unless given: a chain has no area, so
    it is never dynamic)."""
    if not isinstance(chain, Chain):
        raise InvalidValue(f"spawn_chain needs a Chain, got {chain!r}")
    hitbox.setdefault("body", "static")
    x, y = position
    return [scene.spawn(Transform(x, y, rotation), Hitbox(seg, **hitbox)) for seg in chain.segments]
