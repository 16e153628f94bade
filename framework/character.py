"""The character controller component: kinematic bodies that walk, climb slopes and steps, ride platforms.

A :class:`CharacterController` on an entity with ``Transform``, ``Velocity`` and a kinematic
``Hitbox`` hands that body to the pipeline's character stage (right after movement, so moving
platforms have already moved). The game sets the velocity it wants (``Velocity``, like Godot's
``CharacterBody2D.velocity``); each step the stage moves the body by it with swept shape casts
(:mod:`framework.casting`), so it never tunnels, and slides along what it hits:

- **floors** (a surface whose normal is within ``max_floor_angle`` of straight up): standing on
  one, gravity does not pull the body down the slope and the horizontal velocity walks along the
  surface, the x advance per step exactly ``Velocity.x * dt`` (feet on the surface every step,
  up or down); landing keeps the horizontal part of the motion;
- **walls**: in the air the motion slides along them (jumping into a wall never sticks); on the
  floor a wall (or a slope too steep to walk) stops the walk, unless it is a step no higher than
  ``step_height``, which the body steps up at any walking speed (a round bottom goes across as
  far as it must to rest on the step's edge at a standing angle);
- **ceilings**: the motion slides along them and an upward velocity is cut;
- **snap**: walking down a slope, over a crest or down a small step, the body stays on the floor
  (it is pulled down by up to ``snap_length`` plus what the floor angle allows for the step's
  horizontal move) unless it is moving up (a jump);
- **moving platforms**: the body is carried by the displacement of the point under its feet of
  the body it stands on this step (any kinematic or dynamic body; a platform that turns carries it
  round with it), so it rides without jitter, also when the platform turns back; a platform
  that would carry it into a ceiling leaves it under the ceiling and marks it ``crushed`` (it
  never escapes through);
- **one-way platforms** (``Hitbox(one_way=True)``): stood on from above, passed from below and
  the sides; ``drop_through = True`` lets the body fall through the one it stands on.

The body is kept ``skin`` away from what it touches (by default a gap of 2**-40 of its size, and
at least 256 units of rounding of its coordinates), so floating-point rounding never leaves it
inside a surface and sliding along a row of tiles meets no seams. Its state after each step:
``on_floor``, ``floor_normal``, ``floor_entity`` (where it ends the step: a floor within the skin
under its feet; one met on the way and left again is not kept), ``on_wall``, ``wall_normal``,
``on_ceiling``, ``crushed``. The velocity loses its part into every surface the move met, the
same step (on a floor: no vertical velocity, and a walk into a wall or ceiling met stops; in the
air: it slides along them; a dynamic body pushed keeps the walk's velocity). Gravity (the
scene's, times ``gravity_scale``) accelerates it while it is not on a floor. Velocity is
relative to the floor it stands on; leaving a moving platform adds the platform's velocity.

What blocks it: hitboxes in ``solid_mask`` (default: its own hitbox's mask) that are not sensors.
Other overlaps (coins, enemies, hazards) are left to the pipeline's events, as for any body.
The stage that moves it: :mod:`framework.systems.character`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .validation import InvalidValue

__all__ = ["CharacterController"]

_SETTINGS = ("max_floor_angle", "step_height", "snap_length", "skin", "max_slides", "gravity_scale",
             "solid_mask", "push_mass")


def _check(name: str, value: Any) -> Any:
    """A setting's value if it is valid, else :class:`InvalidValue` naming it."""
    if name == "max_slides":
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise InvalidValue(f"CharacterController max_slides must be an int >= 1, got {value!r}")
        return value
    if name == "solid_mask":
        if value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 0 <= value <= 0xFFFFFFFF:
            raise InvalidValue(f"CharacterController solid_mask must be a 32-bit int or None, got {value!r}")
        return int(value)
    if value is None and name in ("snap_length", "skin"):
        return None
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if isinstance(value, bool) or not math.isfinite(number):
        raise InvalidValue(f"CharacterController {name} must be a finite number, got {value!r}")
    if name == "max_floor_angle" and not 0.0 < number < 90.0:
        raise InvalidValue(f"CharacterController max_floor_angle must be between 0 and 90 degrees "
                           f"(exclusive), got {value!r}")
    if name in ("step_height", "snap_length", "push_mass") and number < 0.0:
        raise InvalidValue(f"CharacterController {name} must be >= 0, got {value!r}")
    if name == "skin" and number <= 0.0:
        raise InvalidValue(f"CharacterController skin must be > 0, got {value!r}")
    return number


@dataclass(eq=False)
class CharacterController:
    """Move-and-slide control of a kinematic body (see the module docstring).

    Settings (checked when set: a bad value raises :class:`~framework.validation.InvalidValue`
    naming it, and its entity once in a scene, and nothing changes):

    - ``max_floor_angle``: steepest walkable surface, degrees in (0, 90); default 50.
    - ``step_height``: highest step walked up without a jump (world units, >= 0; default 0).
    - ``snap_length``: how far the body is pulled down to stay on the floor beyond what the floor
      angle needs (>= 0; default: ``step_height``, so it walks down the steps it walks up).
    - ``skin``: the gap kept to what it touches (> 0; default None: 2**-40 of its hitbox's smaller
      size, at least 256 units of rounding of its position).
    - ``max_slides``: casts per move (>= 1; default 4).
    - ``gravity_scale``: times the scene's gravity while not on a floor (default 1).
    - ``solid_mask``: layers that block it (default None: its hitbox's mask).
    - ``push_mass``: the mass with which it pushes dynamic bodies it walks into (>= 0; 0: it
      stops at them like at a wall; default 1).

    Request: ``drop_through = True`` makes it fall through the one-way platform it stands on (the
    request is consumed by the next step). State, written by each step: ``on_floor``,
    ``floor_normal``, ``floor_entity``, ``on_wall``, ``wall_normal``, ``on_ceiling``,
    ``crushed``.
    """

    max_floor_angle: float = 50.0
    step_height: float = 0.0
    snap_length: float | None = None
    skin: float | None = None
    max_slides: int = 4
    gravity_scale: float = 1.0
    solid_mask: int | None = None
    push_mass: float = 1.0
    drop_through: bool = False
    on_floor: bool = False
    floor_normal: tuple[float, float] = (0.0, 0.0)
    floor_entity: int | None = None
    on_wall: bool = False
    wall_normal: tuple[float, float] = (0.0, 0.0)
    on_ceiling: bool = False
    crushed: bool = False
    dropping: set[int] = field(default_factory=set)  # one-way platforms being dropped through

    def __setattr__(self, name: str, value: Any) -> None:
        if name in _SETTINGS:
            try:
                value = _check(name, value)
            except InvalidValue as exc:
                entity = self.__dict__.get("_entity")
                raise (InvalidValue(f"entity {entity}: {exc}") if entity is not None else exc) from None
        object.__setattr__(self, name, value)

    def bind(self, entity: int) -> None:
        """Remember the entity this controller moves (the scene calls it), so that a bad setting
        names it."""
        object.__setattr__(self, "_entity", entity)

    @property
    def floor_cos(self) -> float:
        """cos(max_floor_angle): a surface normal with a y at least this is a floor."""
        return math.cos(math.radians(self.max_floor_angle))
