"""Collision shapes: plain, validated, immutable data in local coordinates.

A shape knows nothing of where it is; a :class:`~framework.components.Transform` places it. The
hitbox origin is local (0, 0): AABBs and circles are centred on it, polygons rotate about it.

- :class:`AABB` is an axis-aligned box that never rotates, whatever the transform's rotation.
- :class:`Circle` is centred on the origin.
- :class:`Polygon` is a convex outline, either winding; it is stored counter-clockwise, starting at
  its lowest (then leftmost) vertex, so equal outlines given in any order compare equal and give
  the same answers bit for bit.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import ClassVar

from .validation import InvalidValue, finite, positive

__all__ = ["AABB", "Circle", "Polygon", "Shape"]

# Relative size below which the turn at a vertex counts as no turn at all (|cross| <= this times
# the product of the two edge lengths, i.e. |sin(angle)| <= 1e-12). Such a vertex is dropped if
# the outline runs straight on, and makes the polygon a spike if the outline doubles back.
_COLLINEAR_SIN = 1e-12


class Shape:
    """Base of the collision shapes. ``kind`` names the shape for dispatch tables."""

    kind: ClassVar[str] = "shape"
    __slots__ = ()

    @property
    def bounding_radius(self) -> float:
        """Radius of the smallest origin-centred circle that holds the shape at any rotation."""
        raise NotImplementedError


@dataclass(frozen=True, slots=True)
class AABB(Shape):
    """Axis-aligned box ``width`` x ``height`` centred on the hitbox origin; never rotates."""

    width: float
    height: float
    kind: ClassVar[str] = "aabb"

    def __post_init__(self) -> None:
        object.__setattr__(self, "width", positive("AABB width", self.width))
        object.__setattr__(self, "height", positive("AABB height", self.height))

    @property
    def half_width(self) -> float:
        return self.width * 0.5

    @property
    def half_height(self) -> float:
        return self.height * 0.5

    @property
    def bounding_radius(self) -> float:
        return math.hypot(self.width * 0.5, self.height * 0.5)


@dataclass(frozen=True, slots=True)
class Circle(Shape):
    """Circle of ``radius`` centred on the hitbox origin."""

    radius: float
    kind: ClassVar[str] = "circle"

    def __post_init__(self) -> None:
        object.__setattr__(self, "radius", positive("Circle radius", self.radius))

    @property
    def bounding_radius(self) -> float:
        return self.radius


@dataclass(frozen=True, slots=True)
class Polygon(Shape):
    """Convex polygon in local coordinates; rotates with its transform about local (0, 0).

    ``points`` may wind either way. Duplicate points and points on a straight run are dropped.
    Fewer than 3 non-collinear points, a non-convex outline, a spike (the outline doubling back on
    itself) or an outline that winds more than once raise :class:`ValueError`.
    """

    points: tuple[tuple[float, float], ...]
    kind: ClassVar[str] = "polygon"
    _radius: float = field(init=False, repr=False, compare=False)

    def __init__(self, points: Iterable[Sequence[float]]) -> None:
        object.__setattr__(self, "points", _normalise_outline(points))
        object.__setattr__(
            self, "_radius", max(math.hypot(x, y) for x, y in self.points)
        )

    @classmethod
    def box(cls, width: float, height: float) -> Polygon:
        """A ``width`` x ``height`` box centred on the origin that rotates with its transform."""
        hw = positive("Polygon.box width", width) * 0.5
        hh = positive("Polygon.box height", height) * 0.5
        return cls([(-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh)])

    @property
    def bounding_radius(self) -> float:
        return self._radius

    def __len__(self) -> int:
        return len(self.points)


def _normalise_outline(points: Iterable[Sequence[float]]) -> tuple[tuple[float, float], ...]:
    """Validate a convex outline; return it counter-clockwise from its lowest-leftmost vertex."""
    try:
        raw = list(points)
    except TypeError:
        raise InvalidValue(f"Polygon points must be a sequence of (x, y) pairs, got {points!r}") from None
    pts: list[tuple[float, float]] = []
    for i, p in enumerate(raw):
        try:
            n = len(p)
        except TypeError:
            raise InvalidValue(f"Polygon point {i} must be an (x, y) pair, got {p!r}") from None
        if n != 2 or isinstance(p, (str, bytes)):
            raise InvalidValue(f"Polygon point {i} must be an (x, y) pair, got {p!r}")
        pts.append((finite(f"Polygon point {i} x", p[0]), finite(f"Polygon point {i} y", p[1])))

    # Drop repeated points (consecutive ones, including the closing repeat of the first point).
    out: list[tuple[float, float]] = []
    for p in pts:
        if not out or p != out[-1]:
            out.append(p)
    while len(out) > 1 and out[0] == out[-1]:
        out.pop()
    if len(set(out)) != len(out):
        raise InvalidValue(f"Polygon outline visits a point twice, so it is not convex: {raw!r}")

    if len(out) >= 3:
        x0, y0 = out[0]
        ext = max(math.hypot(x - x0, y - y0) for x, y in out)
        area2 = abs(sum(
            (out[i][0] - x0) * (out[i + 1][1] - y0) - (out[i][1] - y0) * (out[i + 1][0] - x0)
            for i in range(1, len(out) - 1)
        ))
        if area2 <= _COLLINEAR_SIN * ext * ext:
            raise InvalidValue(f"Polygon needs at least 3 non-collinear points, got {raw!r}")

    # Drop vertices where the outline runs straight on; a vertex where it doubles back is a spike.
    changed = True
    while changed and len(out) >= 3:
        changed = False
        for i in range(len(out)):
            ax, ay = out[i - 1]
            bx, by = out[i]
            cx, cy = out[(i + 1) % len(out)]
            e1x, e1y, e2x, e2y = bx - ax, by - ay, cx - bx, cy - by
            cross = e1x * e2y - e1y * e2x
            if abs(cross) <= _COLLINEAR_SIN * math.hypot(e1x, e1y) * math.hypot(e2x, e2y):
                if e1x * e2x + e1y * e2y < 0.0:
                    raise InvalidValue(
                        f"Polygon outline doubles back on itself at point {out[i]!r} "
                        f"(a spike is not convex): {raw!r}"
                    )
                del out[i]
                changed = True
                break
    if len(out) < 3:
        raise InvalidValue(f"Polygon needs at least 3 non-collinear points, got {raw!r}")

    # Convex: every turn has the same sign, and the outline turns once around (not a star).
    turns = []
    for i in range(len(out)):
        ax, ay = out[i - 1]
        bx, by = out[i]
        cx, cy = out[(i + 1) % len(out)]
        e1x, e1y, e2x, e2y = bx - ax, by - ay, cx - bx, cy - by
        turns.append(math.atan2(e1x * e2y - e1y * e2x, e1x * e2x + e1y * e2y))
    if not (all(t > 0 for t in turns) or all(t < 0 for t in turns)):
        bad = next(
            out[i] for i, t in enumerate(turns) if (t > 0) != (turns[0] > 0)
        )
        raise InvalidValue(f"Polygon is not convex (the outline turns the other way at {bad!r}): {raw!r}")
    if abs(abs(sum(turns)) - 2.0 * math.pi) > 1e-6:
        raise InvalidValue(f"Polygon outline winds around more than once, so it is not convex: {raw!r}")
    if turns[0] < 0:
        out.reverse()
    start = min(range(len(out)), key=lambda i: (out[i][1], out[i][0]))
    return tuple(out[start:] + out[:start])
