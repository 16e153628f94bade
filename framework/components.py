"""Components: small, validated data that systems process.

Constructors refuse NaN, inf and wrong types at once. Attributes stay plain and mutable
(``t.x += 1`` in game code), so a bad value written later is caught when the scene next steps.
"""

from __future__ import annotations

from .validation import finite

__all__ = ["Transform"]


class Transform:
    """Where an entity is: position ``(x, y)`` in world units (y up) and ``rotation`` in radians,
    counter-clockwise. A hitbox's shape rotates about its hitbox origin."""

    __slots__ = ("x", "y", "rotation")

    def __init__(self, x: float = 0.0, y: float = 0.0, rotation: float = 0.0) -> None:
        self.x = finite("Transform x", x)
        self.y = finite("Transform y", y)
        self.rotation = finite("Transform rotation", rotation)

    def __repr__(self) -> str:
        return f"Transform(x={self.x!r}, y={self.y!r}, rotation={self.rotation!r})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Transform):
            return NotImplemented
        return (self.x, self.y, self.rotation) == (other.x, other.y, other.rotation)

    __hash__ = None  # type: ignore[assignment]  # mutable
