"""The ranges of sizes, masses and coordinates a scene takes, so that its arithmetic stays finite.

Shapes and queries (``collide``, ``raycast``...) take any finite size; a scene takes bodies only
where every stage's arithmetic is finite for them (issue 34: a circle of radius 1e-300 divided by
zero at spawn and killed the scene; one of 1e-160 turned another body's rotation into NaN 60
steps later; a polygon with coordinates near 1e300 overflowed a contact and left every row NaN;
``mass=1e-320`` has an infinite inverse). Refused with :class:`~framework.validation.InvalidValue`
at spawn, at ``add_component``, or (for a value written in place) by the next step before it
changes anything:

- a hitbox's size: the shape's bounding radius (its farthest point from the hitbox origin) within
  ``[MIN_SIZE, MAX_SIZE]``, its area at least ``MIN_SIZE**2`` (a segment, which has no area: its
  length at least ``MIN_SIZE``), its offset at most ``MAX_SIZE``;
- a dynamic body's mass (given, or density times area) within ``[MIN_MASS, MAX_MASS]`` (or
  ``math.inf``: a body nothing moves), and a finite moment of inertia (given, or mass times the
  shape's moment about its centroid) at least ``MIN_INERTIA``;
- a position within ``MAX_COORD`` of the origin, and a step that would carry a body beyond it
  (``|x| + |v| dt + |g| dt^2``): refused before it starts.

Why these numbers: a size of ``1e-6`` to ``1e9`` spans a micron to a million kilometres in metres,
or far beyond any screen in pixels; squares and products of coordinates up to ``1e15`` (``1e30``)
and of masses and inertias (``1e-40`` to ``1e38``, inverses likewise) stay far inside float64's
range, and none is subnormal, so no inverse is infinite and no product overflows.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .compiled import kernel
from .shapes import Shape
from .validation import InvalidValue

__all__ = ["MAX_COORD", "MAX_MASS", "MAX_SIZE", "MIN_INERTIA", "MIN_MASS", "MIN_SIZE", "check_hitbox_limits",
           "check_motion", "check_position", "check_shape_limits", "motion_within", "rows_sound"]

MIN_SIZE = 1e-6
MAX_SIZE = 1e9
MAX_COORD = 1e15
MIN_MASS = 1e-20
MAX_MASS = 1e20
MIN_INERTIA = 1e-40  # (the smallest mass times a small shape's second moment, 1e-33, with room)


def check_shape_limits(shape: Shape, what: str = "Hitbox shape") -> None:
    """Refuse a shape a scene cannot take (see the module docstring)."""
    size = shape.bounding_radius
    if not (MIN_SIZE <= size <= MAX_SIZE):
        raise InvalidValue(f"{what} {shape!r} reaches {size!r} from its origin: a scene takes shapes from "
                           f"{MIN_SIZE:g} to {MAX_SIZE:g} (see framework.limits)")
    if shape.kind == "segment":  # (no area: its length instead)
        length = shape.length  # type: ignore[attr-defined]
        if length < MIN_SIZE:
            raise InvalidValue(f"{what} {shape!r} is {length!r} long: a scene takes segments of length "
                               f"{MIN_SIZE:g} or more (see framework.limits)")
    elif shape.area < MIN_SIZE * MIN_SIZE:
        raise InvalidValue(f"{what} {shape!r} has an area of {shape.area!r}: a scene takes shapes of area "
                           f"{MIN_SIZE * MIN_SIZE:g} or more (see framework.limits)")


def check_hitbox_limits(hitbox: Any) -> None:
    """Refuse a :class:`~framework.components.Hitbox` a scene cannot take: its shape, offset, and for a
    dynamic body its mass and moment of inertia (see the module docstring)."""
    from .components import Body, check_body_shape  # (components imports this module's users)

    shape = hitbox.shape
    check_shape_limits(shape)
    check_body_shape(hitbox)
    ox, oy = hitbox.offset
    if max(abs(ox), abs(oy)) > MAX_SIZE:
        raise InvalidValue(f"Hitbox offset {hitbox.offset!r} is beyond {MAX_SIZE:g} (see framework.limits)")
    if hitbox.body is not Body.DYNAMIC:
        return
    mass = hitbox.effective_mass
    if math.isinf(mass):  # (an immovable body: nothing divides by it)
        return
    if not (MIN_MASS <= mass <= MAX_MASS):
        source = "mass" if hitbox.density is None else f"mass (density {hitbox.density!r} x area {shape.area!r})"
        raise InvalidValue(f"Hitbox {source} is {mass!r}: a scene takes masses from {MIN_MASS:g} to "
                           f"{MAX_MASS:g}, or math.inf (see framework.limits)")
    inertia = hitbox.inertia if hitbox.inertia is not None else mass * shape.central_moment  # (the least)
    if not math.isinf(inertia) and inertia < MIN_INERTIA:
        raise InvalidValue(f"Hitbox moment of inertia is {inertia!r}: a scene takes {MIN_INERTIA:g} or more, or "
                           "math.inf (see framework.limits)")


def check_position(x: float, y: float, what: str = "Transform") -> None:
    """Refuse a position farther than ``MAX_COORD`` from the origin along either axis."""
    if max(abs(x), abs(y)) > MAX_COORD:
        raise InvalidValue(f"{what} ({x!r}, {y!r}) is beyond {MAX_COORD:g} from the origin: a scene takes "
                           f"coordinates within {MAX_COORD:g} (see framework.limits)")


@kernel
def rows_sound(x, y, rot, vx, vy, w, rows, max_coord):
    """Whether the ``rows`` of the six pose and velocity columns are all finite, with positions
    within ``max_coord``: the common case of the step's checks, in one compiled pass (the checks
    look column by column, for the message, only when this says no)."""
    for k in range(rows.size):
        r = rows[k]
        if not (abs(x[r]) <= max_coord and abs(y[r]) <= max_coord):  # (NaN fails too)
            return False
        if not (math.isfinite(rot[r]) and math.isfinite(vx[r]) and math.isfinite(vy[r]) and math.isfinite(w[r])):
            return False
    return True


@kernel
def motion_within(x, y, vx, vy, rows, dt, gx, gy, max_coord):
    """The first of ``rows`` that a step of ``dt`` could carry beyond ``max_coord`` (see
    :func:`check_motion`), or -1."""
    ex, ey = abs(gx) * dt * dt, abs(gy) * dt * dt
    for k in range(rows.size):
        r = rows[k]
        if not (abs(x[r]) + abs(vx[r]) * dt + ex <= max_coord and abs(y[r]) + abs(vy[r]) * dt + ey <= max_coord):
            return k
    return -1


def check_motion(entities: np.ndarray, x: np.ndarray, y: np.ndarray, vx: np.ndarray, vy: np.ndarray,
                 dt: float, gravity: tuple[float, float]) -> None:
    """Refuse a step of ``dt`` that could carry one of these moving bodies beyond ``MAX_COORD``:
    ``|x| + |v| dt + |g| dt^2`` along each axis, a bound on where semi-implicit Euler takes it
    (the response moves a body by at most its size more)."""
    if x.size == 0:
        return
    gx, gy = abs(gravity[0]) * dt * dt, abs(gravity[1]) * dt * dt
    with np.errstate(over="ignore", invalid="ignore"):
        far_x = np.abs(x) + np.abs(vx) * dt + gx
        far_y = np.abs(y) + np.abs(vy) * dt + gy
        far = np.maximum(far_x, far_y)
    bad = ~(far <= MAX_COORD)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InvalidValue(f"a step of {dt!r} s could carry entity {int(entities[i])} (at ({float(x[i])!r}, "
                           f"{float(y[i])!r}), moving at ({float(vx[i])!r}, {float(vy[i])!r})) beyond {MAX_COORD:g} "
                           "from the origin, where a scene's arithmetic ends (see framework.limits); nothing "
                           "was changed")
