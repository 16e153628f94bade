"""The triangles of a filled hitbox, in local coordinates (about the hitbox origin).

The render system triangulates each filled hitbox once, when its drawable is made; moving or
turning it afterwards changes only its row of the slot table (:mod:`.instances`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from ..shapes import AABB, Capsule, Circle, Polygon, Segment

__all__ = ["capsule_outline", "circle_segments", "fan_indices", "fill_outline", "fill_triangles"]


def circle_segments(radius_px: float) -> int:
    """Segments of a circle of ``radius_px`` screen pixels: smooth enough, never wasteful."""
    return int(min(128, max(16, math.ceil(radius_px * 0.75))))


def _fan(points: Sequence[tuple[float, float]]) -> list[float]:
    out: list[float] = []
    x0, y0 = points[0]
    for i in range(1, len(points) - 1):
        (x1, y1), (x2, y2) = points[i], points[i + 1]
        out += (x0, y0, x1, y1, x2, y2)
    return out


def capsule_outline(shape: Capsule, zoom: float = 1.0) -> list[tuple[float, float]]:
    """A capsule's outline (upright, local coordinates, counter-clockwise) as a convex polygon: each
    round end a half circle of as many chords as half a circle of its radius on screen."""
    r, h = shape.radius, shape.half_length
    n = max(8, circle_segments(r * zoom) // 2)
    top = [(r * math.cos(math.pi * i / n), h + r * math.sin(math.pi * i / n)) for i in range(n + 1)]
    return top + [(-x, -y) for x, y in top]


def fill_outline(shape: Any, zoom: float = 1.0) -> list[tuple[float, float]]:
    """The convex outline (local coordinates, in order) of a hitbox shape; a circle's and a
    capsule's round parts as chords fine enough at ``zoom``."""
    if isinstance(shape, AABB):
        hw, hh = shape.width * 0.5, shape.height * 0.5
        return [(-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh)]
    if isinstance(shape, Circle):
        r = shape.radius
        n = circle_segments(r * zoom)
        return [(r * math.cos(2.0 * math.pi * i / n), r * math.sin(2.0 * math.pi * i / n)) for i in range(n)]
    if isinstance(shape, Capsule):
        return capsule_outline(shape, zoom)
    if isinstance(shape, Polygon):
        return list(shape.points)
    if isinstance(shape, Segment):  # no area: its two ends (a fan of them fills nothing)
        return [shape.a, shape.b]
    raise TypeError(f"cannot fill a {type(shape).__name__}")


def fill_triangles(shape: Any, zoom: float = 1.0) -> list[float]:
    """The triangles (flat, local coordinates) filling a hitbox shape: a fan over its outline."""
    return _fan(fill_outline(shape, zoom))


def fan_indices(n: int) -> list[int]:
    """The indices of a fan of triangles over ``n`` outline points (``0, i, i + 1``)."""
    return [k for i in range(1, n - 1) for k in (0, i, i + 1)]
