"""Placing shapes in the world, relative to a local origin.

Every query subtracts a local origin (the first shape's position) before any arithmetic, so a
scene at x = 1e9 gives the answers of the same scene at the origin, to float64 rounding.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import cast

from ..shapes import AABB, Capsule, Circle, Polygon, Segment, Shape
from ..validation import InvalidValue, finite

__all__ = ["pose", "local_outline", "check_shape"]


def check_shape(name: str, shape: object) -> Shape:
    if not isinstance(shape, (AABB, Capsule, Circle, Polygon, Segment)):
        raise InvalidValue(f"{name} must be an AABB, Capsule, Circle, Polygon or Segment, got {shape!r}")
    return shape


def pose(name: str, transform: object) -> tuple[float, float, float]:
    """``(x, y, rotation)`` of a Transform (or an ``(x, y[, rotation])`` sequence), checked finite."""
    if hasattr(transform, "x") and hasattr(transform, "y"):
        return (
            finite(f"{name}.x", transform.x),
            finite(f"{name}.y", transform.y),
            finite(f"{name}.rotation", getattr(transform, "rotation", 0.0)),
        )
    try:
        n = len(transform)  # type: ignore[arg-type]  # (any object: one without a length raises TypeError)
    except TypeError:
        n = -1
    if n not in (2, 3) or isinstance(transform, (str, bytes)):
        raise InvalidValue(f"{name} must be a Transform or an (x, y[, rotation]) tuple, got {transform!r}")
    seq = cast("Sequence[object]", transform)  # (a length of 2 or 3, not a string: a sequence)
    rot = seq[2] if n == 3 else 0.0
    return (finite(f"{name}[0]", seq[0]), finite(f"{name}[1]", seq[1]),
            finite(f"{name}[2]", rot))


def local_outline(shape: AABB | Polygon | Segment, rotation: float, k: int = 0) -> list[tuple[float, float]]:
    """Outline (counter-clockwise) of a box or polygon about its own hitbox origin, rotated, and
    scaled by ``2**-k`` (exact, bar underflow) before rotating so that nothing overflows; a
    segment's outline is its two ends, ``a`` then ``b`` (an outline of two points, whose two edges
    are the segment both ways).

    AABBs ignore ``rotation``. A query that scales its whole scene by the same power of two gets
    the answers of the unscaled scene bit for bit, without overflow or underflow at the extremes.
    """
    if isinstance(shape, AABB):
        hw, hh = math.ldexp(shape.width, -1 - k), math.ldexp(shape.height, -1 - k)
        return [(-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh)]
    src = (shape.a, shape.b) if isinstance(shape, Segment) else shape.points
    pts = [(math.ldexp(px, -k), math.ldexp(py, -k)) for px, py in src]
    if rotation == 0.0:
        return pts
    c, s = math.cos(rotation), math.sin(rotation)
    return [(c * px - s * py, s * px + c * py) for px, py in pts]
