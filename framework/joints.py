"""Joints: components that hold two bodies together (Box2D v3's joints, in the soft step).

A joint is a component on an entity of its own (``scene.spawn(DistanceJoint(a, b))``) naming two
bodies by entity id: ``a`` and ``b`` (``b=None``: the world, a fixed point). Both must have a
Hitbox; either may be static. It is read, changed (``joint.motor_speed = 2.0``, ``mouse.target =
(x, y)``) and removed like any component; despawning one of its bodies removes it (and its entity,
if the joint was all the entity held). The bodies of a joint do not collide with each other unless
``collide_connected=True``.

- :class:`DistanceJoint`: keeps two anchors at a distance: a rod (rigid), a rope (``min_length=0``
  and a ``max_length``: only a most) or a spring (``hertz > 0``);
- :class:`RevoluteJoint`: a hinge at a point both bodies share, with angle limits, a motor and a
  spring (``hertz > 0``) toward the angle it was made at;
- :class:`PrismaticJoint`: a slider along an axis, with limits, a motor and a spring toward where
  it was made;
- :class:`WheelJoint`: a wheel on a chassis: a slider on a suspension spring that turns freely;
- :class:`WeldJoint`: glues two bodies in their relative pose (stiff, or springy with ``hertz``);
- :class:`MouseJoint`: drags a point of a body toward a target with a limited force;
- :class:`MotorJoint`: drives a body toward a position and an angle relative to another body (or
  the world) with a limited force and torque: a moving platform, a crane's hook, a body steered
  along a path.

What a joint measures when it is spawned (a :class:`DistanceJoint`'s ``length`` if not given, a
revolute or weld joint's anchor in each body's frame and the bodies' relative angle, where a
spring rests; a :class:`MotorJoint`'s offsets if not given) is fixed then: the anchors are each
body's own points, they turn with the body. Only ``Scene(solver="soft")`` solves joints; stepping
an exact-solver scene that holds one raises :class:`InvalidValue`. The solver is
:mod:`framework.systems.soft_joints`; see docs/physics.md ("Joints").
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from numbers import Integral
from typing import ClassVar, NamedTuple

import esper

from .collision.results import Vec2
from .store import KIND_NONE, BodyStore
from .validation import InvalidValue, finite, positive, vector2

__all__ = ["DistanceJoint", "Joint", "JointBroken", "JointReaction", "MotorJoint", "MouseJoint", "PrismaticJoint",
           "RevoluteJoint", "WeldJoint", "WheelJoint"]

class JointReaction(NamedTuple):
    """What a joint did to its body ``a`` in the last step (``Scene.joint_reaction``): the force
    (world units of force: mass times length per second squared) and the torque of its angular
    part (a motor's, a limit's, a weld's; not the moment of the force)."""

    force: Vec2
    torque: float


class JointBroken(NamedTuple):
    """A joint that broke at the end of a step (``scene.broken_joints``): its entity, its bodies,
    the joint itself (removed from the entity) and the force and torque that broke it."""

    entity: int
    a: int
    b: int | None
    joint: Joint
    force: Vec2
    torque: float


# The kernel's joint kinds (framework.systems.soft_joints reads them by number).
DISTANCE, REVOLUTE, WELD, MOUSE, PRISMATIC, WHEEL, MOTOR = 0, 1, 2, 3, 4, 5, 6


def _entity(name: str, value: object, optional: bool) -> int | None:
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, Integral):
        what = "an entity id (an int) or None (the world)" if optional else "an entity id (an int)"
        raise InvalidValue(f"{name} must be {what}, got {value!r}")
    return int(value)


def _at_least_zero(name: str, value: object) -> float:
    v = finite(name, value)
    if v < 0.0:
        raise InvalidValue(f"{name} must be >= 0, got {value!r}")
    return v


def _optional(name: str, value: object) -> float | None:
    return None if value is None else _at_least_zero(name, value)


def _pose(store: BodyStore, entity: int) -> tuple[float, float, float]:
    """A body's (x, y, rotation) now."""
    row = store.row_of[entity]
    c = store.cols
    return float(c["x"][row]), float(c["y"][row]), float(c["rot"][row])


def _to_local(pose: tuple[float, float, float], px: float, py: float) -> tuple[float, float]:
    """The world point ``(px, py)`` in the frame of a body at ``pose`` (about its Transform origin)."""
    x, y, r = pose
    c, s = math.cos(r), math.sin(r)
    dx, dy = px - x, py - y
    return c * dx + s * dy, -s * dx + c * dy


def _to_world(pose: tuple[float, float, float], lx: float, ly: float) -> tuple[float, float]:
    x, y, r = pose
    c, s = math.cos(r), math.sin(r)
    return x + c * lx - s * ly, y + s * lx + c * ly


class Joint(ABC):
    """What every joint has: its bodies ``a`` and ``b`` (``None``: the world) and whether they
    collide with each other. Subclasses add their parameters and :meth:`check` them."""

    kind: ClassVar[int]
    a: int
    b: int | None
    collide_connected: bool
    #: the joint breaks (is removed at the end of a step, and listed in ``scene.broken_joints``)
    #: when the force or the torque it applied in the step is above these (> 0; inf: never)
    break_force: float = math.inf
    break_torque: float = math.inf

    def __setattr__(self, name: str, value: object) -> None:
        # A parameter written (by the game, or normalised by check) makes the joint unchecked and
        # its packed tables stale: check_joints checks it again, the soft step packs it again.
        object.__setattr__(self, name, value)
        if not name.startswith("_"):
            self.__dict__["_checked"] = None
            _WRITES[0] += 1

    def check_breaking(self) -> None:
        """:class:`InvalidValue` unless ``break_force`` and ``break_torque`` are > 0 (inf: never)."""
        name = type(self).__name__
        for field in ("break_force", "break_torque"):
            value = getattr(self, field)
            v = float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else math.nan
            if not v > 0.0:
                raise InvalidValue(f"{name} {field} must be > 0 (math.inf: never breaks), got {value!r}")
            setattr(self, field, v)

    def _init_bodies(self, a: object, b: object, collide_connected: object) -> None:
        name = type(self).__name__
        self.a = _entity(f"{name} a", a, optional=False)  # type: ignore[assignment]  # (never None)
        self.b = _entity(f"{name} b", b, optional=True)
        if self.a == self.b:
            raise InvalidValue(f"{name} joins body {self.a} to itself: a and b must be two bodies")
        if not isinstance(collide_connected, bool):
            raise InvalidValue(f"{name} collide_connected must be True or False, got {collide_connected!r}")
        self.collide_connected = collide_connected
        # each body's anchor in its own frame (b None: a world point) and their relative angle at
        # creation; fixed by attach()
        self._frame: tuple[float, float, float, float, float] | None = None

    def bodies(self) -> tuple[int, ...]:
        """The entity ids of the joint's bodies (one for a joint to the world)."""
        return (self.a,) if self.b is None else (self.a, self.b)

    @abstractmethod
    def check(self) -> None:
        """:class:`InvalidValue` naming the field if a parameter is bad (as the constructor checks;
        a value written later is checked again at each step)."""

    def check_bodies(self, store: BodyStore) -> None:
        """:class:`InvalidValue` unless the joint's bodies are bodies of the scene with a Hitbox."""
        name = type(self).__name__
        if self.a == self.b:
            raise InvalidValue(f"{name} joins body {self.a} to itself: a and b must be two bodies")
        for label, e in (("a", self.a), ("b", self.b)):
            if e is None and label == "b":
                continue
            row = store.row_of.get(e) if isinstance(e, int) and not isinstance(e, bool) else None
            if row is None:
                raise InvalidValue(f"{name} {label} = {e!r} is not a body of this scene (no such entity, despawned, "
                                   "or without a Transform)")
            if store.kind[row] == KIND_NONE:
                raise InvalidValue(f"{name} {label} = {e!r} has no Hitbox: a joint holds bodies with a Hitbox")

    def attach(self, store: BodyStore) -> None:
        """Check the joint against the scene's bodies and fix what it measures at creation (changes
        nothing on error)."""
        self.check()
        self.check_bodies(store)
        self._measure(store)

    @abstractmethod
    def _measure(self, store: BodyStore) -> None:
        """Fix what the joint measures when it is made (``_frame``; a distance joint's length)."""

    def _anchors_at(self, store: BodyStore, point: tuple[float, float]) -> None:
        """Fix the anchor frame from one world point both bodies share (revolute, weld)."""
        pa = _pose(store, self.a)
        ax, ay = _to_local(pa, *point)
        if self.b is None:
            bx, by, rb = point[0], point[1], 0.0
        else:
            pb = _pose(store, self.b)
            (bx, by), rb = _to_local(pb, *point), pb[2]
        self._frame = (ax, ay, bx, by, rb - pa[2])


class DistanceJoint(Joint):
    """Keeps ``anchor_a`` (a point of body ``a``, in its frame) and ``anchor_b`` (of ``b``; with
    ``b=None`` a world point) ``length`` apart (``None``: their distance when spawned).

    ``hertz == 0``: rigid between ``min_length`` and ``max_length`` (both default to ``length``: a
    rod; ``min_length=0`` and a ``max_length``: a rope, which goes slack). ``hertz > 0``: a spring
    of that frequency and damping ratio ``damping`` toward ``length``, free to stretch unless
    ``min_length`` or ``max_length`` say otherwise."""

    kind = DISTANCE

    def __init__(self, a: int, b: int | None, anchor_a: tuple[float, float] = (0.0, 0.0),
                 anchor_b: tuple[float, float] = (0.0, 0.0), length: float | None = None,
                 min_length: float | None = None, max_length: float | None = None, hertz: float = 0.0,
                 damping: float = 0.0, collide_connected: bool = False, break_force: float = math.inf,
                 break_torque: float = math.inf) -> None:
        self._init_bodies(a, b, collide_connected)
        self.break_force, self.break_torque = break_force, break_torque
        self.anchor_a = anchor_a
        self.anchor_b = anchor_b
        self.length = length
        self.min_length = min_length
        self.max_length = max_length
        self.hertz = hertz
        self.damping = damping
        self.check()

    def limits(self) -> tuple[float, float | None]:
        """The least and the most length allowed (``None``: no most), defaults resolved."""
        return _limits(self.hertz, self.length or 0.0, self.min_length, self.max_length)

    def check(self) -> None:
        self.check_breaking()
        self.anchor_a = vector2("DistanceJoint anchor_a", self.anchor_a)
        self.anchor_b = vector2("DistanceJoint anchor_b", self.anchor_b)
        self.length = _optional("DistanceJoint length", self.length)
        self.min_length = _optional("DistanceJoint min_length", self.min_length)
        self.max_length = _optional("DistanceJoint max_length", self.max_length)
        self.hertz = _at_least_zero("DistanceJoint hertz", self.hertz)
        self.damping = _at_least_zero("DistanceJoint damping", self.damping)
        if self.min_length is not None and self.max_length is not None and self.min_length > self.max_length:
            raise InvalidValue(f"DistanceJoint min_length ({self.min_length}) is more than max_length "
                               f"({self.max_length})")

    def _measure(self, store: BodyStore) -> None:
        pa = _pose(store, self.a)
        wa = _to_world(pa, *self.anchor_a)
        wb = self.anchor_b if self.b is None else _to_world(_pose(store, self.b), *self.anchor_b)
        length = math.hypot(wb[0] - wa[0], wb[1] - wa[1]) if self.length is None else self.length
        lo, hi = _limits(self.hertz, length, self.min_length, self.max_length)
        if hi is not None and lo > hi:
            raise InvalidValue(f"DistanceJoint length {length} with min_length {self.min_length} and max_length "
                               f"{self.max_length}: the least length allowed ({lo}) is more than the most ({hi})")
        self.length = length
        self._frame = (*self.anchor_a, *self.anchor_b, 0.0)


def _limits(hertz: float, length: float, lo: float | None, hi: float | None) -> tuple[float, float | None]:
    """A distance joint's least and most length: as given, else a rod's (``length``, with ``hertz``
    0) or a spring's (0 and none)."""
    rigid = hertz == 0.0
    least = lo if lo is not None else (length if rigid else 0.0)
    return least, (hi if hi is not None else (length if rigid else None))


class RevoluteJoint(Joint):
    """A hinge: bodies ``a`` and ``b`` share the world point ``anchor`` (where it is when spawned;
    each body's point there turns with it) and turn freely about it, within ``lower`` and
    ``upper`` (radians of ``a``'s turn relative to ``b`` since the joint was made, counter-clockwise;
    with ``b=None``, ``a``'s own turn; ``None``: no limit). A motor (``max_motor_torque > 0``)
    drives that turn at ``motor_speed`` radians a second with at most that torque. A spring
    (``hertz > 0``, damping ratio ``damping``; Box2D's ``enableSpring``) pulls the turn toward 0,
    the angle it was made at: its stiffness is ``I (2 pi hertz)^2`` for the moment of inertia ``I``
    it turns (``hertz`` 0: no spring)."""

    kind = REVOLUTE

    def __init__(self, a: int, b: int | None, anchor: tuple[float, float], lower: float | None = None,
                 upper: float | None = None, motor_speed: float = 0.0, max_motor_torque: float = 0.0,
                 hertz: float = 0.0, damping: float = 0.0, collide_connected: bool = False,
                 break_force: float = math.inf, break_torque: float = math.inf) -> None:
        self._init_bodies(a, b, collide_connected)
        self.break_force, self.break_torque = break_force, break_torque
        self.anchor = anchor
        self.lower = lower
        self.upper = upper
        self.motor_speed = motor_speed
        self.max_motor_torque = max_motor_torque
        self.hertz = hertz
        self.damping = damping
        self.check()

    def check(self) -> None:
        self.check_breaking()
        self.anchor = vector2("RevoluteJoint anchor", self.anchor)
        self.lower = None if self.lower is None else finite("RevoluteJoint lower", self.lower)
        self.upper = None if self.upper is None else finite("RevoluteJoint upper", self.upper)
        self.motor_speed = finite("RevoluteJoint motor_speed", self.motor_speed)
        self.max_motor_torque = _at_least_zero("RevoluteJoint max_motor_torque", self.max_motor_torque)
        self.hertz = _at_least_zero("RevoluteJoint hertz", self.hertz)
        self.damping = _at_least_zero("RevoluteJoint damping", self.damping)
        if self.lower is not None and self.upper is not None and self.lower > self.upper:
            raise InvalidValue(f"RevoluteJoint lower ({self.lower}) is more than upper ({self.upper})")

    def _measure(self, store: BodyStore) -> None:
        self._anchors_at(store, self.anchor)


class WeldJoint(Joint):
    """Glues bodies ``a`` and ``b`` in their relative pose when spawned, about the world point
    ``anchor``: rigid with ``hertz == 0``, else a spring of that frequency and damping ratio
    ``damping`` (in both the offset and the angle)."""

    kind = WELD

    def __init__(self, a: int, b: int | None, anchor: tuple[float, float], hertz: float = 0.0,
                 damping: float = 0.0, collide_connected: bool = False, break_force: float = math.inf,
                 break_torque: float = math.inf) -> None:
        self._init_bodies(a, b, collide_connected)
        self.break_force, self.break_torque = break_force, break_torque
        self.anchor = anchor
        self.hertz = hertz
        self.damping = damping
        self.check()

    def check(self) -> None:
        self.check_breaking()
        self.anchor = vector2("WeldJoint anchor", self.anchor)
        self.hertz = _at_least_zero("WeldJoint hertz", self.hertz)
        self.damping = _at_least_zero("WeldJoint damping", self.damping)

    def _measure(self, store: BodyStore) -> None:
        self._anchors_at(store, self.anchor)


class MouseJoint(Joint):
    """Drags ``body`` toward the world point ``target`` (change it at will: ``joint.target = (x,
    y)``) as a spring of ``hertz`` and damping ratio ``damping``, with at most ``max_force``. The
    point of the body dragged is the one under ``target`` when the joint is spawned (where the
    mouse grabbed it); its turning is damped a little (Box2D's mouse joint)."""

    kind = MOUSE

    def __init__(self, body: int, target: tuple[float, float], max_force: float, hertz: float = 5.0,
                 damping: float = 0.7, break_force: float = math.inf, break_torque: float = math.inf) -> None:
        self._init_bodies(body, None, False)
        self.break_force, self.break_torque = break_force, break_torque
        self.target = target
        self.max_force = max_force
        self.hertz = hertz
        self.damping = damping
        self.check()

    @property
    def body(self) -> int:
        """The body dragged (``a``)."""
        return self.a

    def check(self) -> None:
        self.check_breaking()
        self.target = vector2("MouseJoint target", self.target)
        force = finite("MouseJoint max_force", self.max_force)
        if force <= 0.0:
            raise InvalidValue(f"MouseJoint max_force must be > 0, got {self.max_force!r}")
        self.max_force = force
        self.hertz = positive("MouseJoint hertz", self.hertz)
        self.damping = _at_least_zero("MouseJoint damping", self.damping)

    def _measure(self, store: BodyStore) -> None:
        lx, ly = _to_local(_pose(store, self.a), *self.target)
        self._frame = (lx, ly, 0.0, 0.0, 0.0)


class _SlidingJoint(Joint):
    """What a slider and a wheel share: ``a`` slides along ``axis`` on ``b`` (a world direction when
    spawned, kept in ``b``'s frame after), within ``lower`` and ``upper``."""

    anchor: tuple[float, float]
    axis: tuple[float, float]
    lower: float | None
    upper: float | None
    _axis_local: tuple[float, float]

    def _check_slide(self) -> None:
        """Check (and normalise) the anchor, the axis and the limits of the slide."""
        name = type(self).__name__
        self.anchor = vector2(f"{name} anchor", self.anchor)
        ax, ay = vector2(f"{name} axis", self.axis)
        length = math.hypot(ax, ay)
        if not length > 0.0 or not math.isfinite(length):
            raise InvalidValue(f"{name} axis must be a direction (not zero), got {self.axis!r}")
        self.axis = (ax / length, ay / length)
        self.lower = None if self.lower is None else finite(f"{name} lower", self.lower)
        self.upper = None if self.upper is None else finite(f"{name} upper", self.upper)
        if self.lower is not None and self.upper is not None and self.lower > self.upper:
            raise InvalidValue(f"{name} lower ({self.lower}) is more than upper ({self.upper})")

    def _measure(self, store: BodyStore) -> None:
        self._anchors_at(store, self.anchor)
        rot = 0.0 if self.b is None else _pose(store, self.b)[2]
        c, s = math.cos(rot), math.sin(rot)
        self._axis_local = (c * self.axis[0] + s * self.axis[1], -s * self.axis[0] + c * self.axis[1])


class PrismaticJoint(_SlidingJoint):
    """A slider: body ``a`` slides along ``axis`` on ``b`` (the world with ``b=None``): they keep
    their relative angle, and ``a``'s point ``anchor`` stays on the line along ``axis`` through
    ``b``'s (``axis``: a world direction when spawned, turning with ``b`` after). ``lower`` and
    ``upper`` limit ``a``'s slide (world units along the axis from where it was when spawned;
    ``None``: no limit); a motor (``max_motor_force > 0``) drives it at ``motor_speed`` units a
    second with at most that force. A spring (``hertz > 0``, damping ratio ``damping``; Box2D's
    ``enableSpring``) pulls the slide toward 0, where it was made: its stiffness is ``m (2 pi
    hertz)^2`` for the mass ``m`` it moves (``hertz`` 0: no spring)."""

    kind = PRISMATIC

    def __init__(self, a: int, b: int | None, anchor: tuple[float, float], axis: tuple[float, float] = (1.0, 0.0),
                 lower: float | None = None, upper: float | None = None, motor_speed: float = 0.0,
                 max_motor_force: float = 0.0, hertz: float = 0.0, damping: float = 0.0,
                 collide_connected: bool = False, break_force: float = math.inf,
                 break_torque: float = math.inf) -> None:
        self._init_bodies(a, b, collide_connected)
        self.break_force, self.break_torque = break_force, break_torque
        self.anchor = anchor
        self.axis = axis
        self.lower = lower
        self.upper = upper
        self.motor_speed = motor_speed
        self.max_motor_force = max_motor_force
        self.hertz = hertz
        self.damping = damping
        self._axis_local: tuple[float, float] = (1.0, 0.0)
        self.check()

    def check(self) -> None:
        self.check_breaking()
        self._check_slide()
        self.motor_speed = finite("PrismaticJoint motor_speed", self.motor_speed)
        self.max_motor_force = _at_least_zero("PrismaticJoint max_motor_force", self.max_motor_force)
        self.hertz = _at_least_zero("PrismaticJoint hertz", self.hertz)
        self.damping = _at_least_zero("PrismaticJoint damping", self.damping)


class WheelJoint(_SlidingJoint):
    """A wheel on a chassis: body ``a`` (the wheel) turns freely about its point ``anchor`` and
    slides along ``axis`` on ``b`` (the chassis; the world with ``b=None``), held by a suspension
    spring of ``hertz`` and damping ratio ``damping`` toward where it was spawned (``hertz`` 0: no
    spring; ``axis``: a world direction when spawned, turning with ``b``); ``lower``, ``upper``
    limit the slide; a motor (``max_motor_torque > 0``) turns the wheel relative to the chassis at
    ``motor_speed`` radians a second with at most that torque (Box2D's wheel joint)."""

    kind = WHEEL

    def __init__(self, a: int, b: int | None, anchor: tuple[float, float], axis: tuple[float, float] = (0.0, 1.0),
                 hertz: float = 1.0, damping: float = 0.7, lower: float | None = None, upper: float | None = None,
                 motor_speed: float = 0.0, max_motor_torque: float = 0.0, collide_connected: bool = False,
                 break_force: float = math.inf, break_torque: float = math.inf) -> None:
        self._init_bodies(a, b, collide_connected)
        self.break_force, self.break_torque = break_force, break_torque
        self.anchor = anchor
        self.axis = axis
        self.hertz = hertz
        self.damping = damping
        self.lower = lower
        self.upper = upper
        self.motor_speed = motor_speed
        self.max_motor_torque = max_motor_torque
        self._axis_local: tuple[float, float] = (0.0, 1.0)
        self.check()

    def check(self) -> None:
        self.check_breaking()
        self._check_slide()
        self.hertz = _at_least_zero("WheelJoint hertz", self.hertz)
        self.damping = _at_least_zero("WheelJoint damping", self.damping)
        self.motor_speed = finite("WheelJoint motor_speed", self.motor_speed)
        self.max_motor_torque = _at_least_zero("WheelJoint max_motor_torque", self.max_motor_torque)


class MotorJoint(Joint):
    """Drives body ``a`` toward a pose relative to body ``b`` (the world with ``b=None``; Box2D's
    motor joint): its origin (its Transform's position) toward the point ``linear_offset`` of ``b``'s
    frame (a world point with ``b=None``) and its turn relative to ``b`` toward ``angular_offset``
    radians, with at most ``max_force`` and ``max_torque`` (0: that part is free). Each sub-step it
    asks for the velocity that would close ``correction_factor`` (0 to 1) of what is left; the force
    and torque limits decide how much of that it gets. ``linear_offset`` or ``angular_offset``
    ``None``: where ``a`` is when spawned (it holds it there). Change them at will (every frame, to
    move a platform along a path) like any field."""

    kind = MOTOR

    def __init__(self, a: int, b: int | None, linear_offset: tuple[float, float] | None = None,
                 angular_offset: float | None = None, max_force: float = 1.0, max_torque: float = 1.0,
                 correction_factor: float = 0.3, collide_connected: bool = False, break_force: float = math.inf,
                 break_torque: float = math.inf) -> None:
        self._init_bodies(a, b, collide_connected)
        self.break_force, self.break_torque = break_force, break_torque
        self.linear_offset = linear_offset
        self.angular_offset = angular_offset
        self.max_force = max_force
        self.max_torque = max_torque
        self.correction_factor = correction_factor
        self.check()

    def check(self) -> None:
        self.check_breaking()
        if self.linear_offset is not None:
            self.linear_offset = vector2("MotorJoint linear_offset", self.linear_offset)
        if self.angular_offset is not None:
            self.angular_offset = finite("MotorJoint angular_offset", self.angular_offset)
        self.max_force = _at_least_zero("MotorJoint max_force", self.max_force)
        self.max_torque = _at_least_zero("MotorJoint max_torque", self.max_torque)
        factor = finite("MotorJoint correction_factor", self.correction_factor)
        if not 0.0 <= factor <= 1.0:
            raise InvalidValue(f"MotorJoint correction_factor must be between 0 and 1, got {self.correction_factor!r}")
        self.correction_factor = factor

    def _measure(self, store: BodyStore) -> None:
        pa = _pose(store, self.a)
        pb = (0.0, 0.0, 0.0) if self.b is None else _pose(store, self.b)
        if self.linear_offset is None:
            self.linear_offset = _to_local(pb, pa[0], pa[1])
        if self.angular_offset is None:
            self.angular_offset = pa[2] - pb[2]
        self._frame = (0.0, 0.0, 0.0, 0.0, 0.0)


JOINT_TYPES: tuple[type[Joint], ...] = (DistanceJoint, RevoluteJoint, WeldJoint, MouseJoint, PrismaticJoint,
                                        WheelJoint, MotorJoint)
_JOINT_SET = frozenset(JOINT_TYPES)


_WRITES = [0]  # joint parameters written, ever (see joint_writes)


def joint_components() -> list[tuple[int, Joint]]:
    """Every joint of the current esper world as ``(entity, joint)``, by entity then kind (a list
    the caller must not change). A world without joints answers from esper's table of component
    types (which drops a type when its last component goes): four set look-ups, a fraction of a
    microsecond a step. Otherwise the answer is sorted again only when esper's lists of the joint
    types are new ones (esper makes new lists after any component is added or removed): a step
    asks three times, and sorting a hundred joints each time was a fifth of a chain's step."""
    if esper._components.keys().isdisjoint(_JOINT_SET):
        return []
    lists = tuple(esper.get_component(cls) for cls in JOINT_TYPES)
    seen, answer = _LISTED
    if seen is not None and all(a is b for a, b in zip(lists, seen)):
        return answer
    out: list[tuple[int, Joint]] = []
    for found in lists:
        out.extend(found)
    if len(out) > 1:
        out.sort(key=lambda ej: (ej[0], ej[1].kind))
    _LISTED[:] = [lists, out]  # (holding esper's lists: their identities cannot be reused)
    return out


_LISTED: list = [None, []]  # esper's lists joint_components last read, and its answer
_CLEAN: list = [None]  # what check_joints last passed: (joints, store, version, writes, solver)


def check_joints(joints: list[tuple[int, Joint]], store: BodyStore, solver: str) -> None:
    """:class:`InvalidValue` naming the joint's entity if a joint is bad (a parameter written since,
    a body gone or without a Hitbox), or if the scene's solver cannot solve joints. The same list
    of joints against the same bodies with nothing written since it passed passes at once."""
    last = _CLEAN[0]
    if (last is not None and last[0] is joints and last[1] is store and last[2] == store.version
            and last[3] == _WRITES[0] and last[4] == solver):
        return
    if joints and solver != "soft":
        e, j = joints[0]
        raise InvalidValue(f"entity {e} holds a {type(j).__name__}: joints need Scene(solver=\"soft\"); the exact "
                           "solver does not solve joints yet")
    stamp = (id(store), store.version)  # (a body gone or its Hitbox removed changes the version)
    for e, j in joints:
        if j.__dict__.get("_checked") == stamp:
            continue  # (nothing written since it was checked against these bodies)
        try:
            j.check()
            j.check_bodies(store)
        except InvalidValue as exc:
            raise InvalidValue(f"entity {e}: {exc}") from None
        j.__dict__["_checked"] = stamp
    _CLEAN[0] = (joints, store, store.version, _WRITES[0], solver)


def breakable(joints: list[tuple[int, Joint]]) -> list[tuple[int, Joint]]:
    """The joints that may break (a finite ``break_force`` or ``break_torque``), found again only
    when the list or a joint's parameters changed."""
    last, answer = _BREAKABLE
    if last is not None and last[0] is joints and last[1] == _WRITES[0]:
        return answer
    answer = [(e, j) for e, j in joints if j.break_force != math.inf or j.break_torque != math.inf]
    _BREAKABLE[:] = [(joints, _WRITES[0]), answer]
    return answer


_BREAKABLE: list = [None, []]  # (the list and the writes breakable last read, its answer)


def joint_writes() -> int:
    """How many times a joint parameter was written in this process: the soft step packs its joint
    tables again only when this, its joints or the scene's structure changed."""
    return _WRITES[0]


def remove_joints_of(entity: int) -> list[int]:
    """Remove the joints holding body ``entity`` (from the current esper world); return the joint
    entities left with no component at all (for the caller to delete)."""
    empty = []
    for e, j in joint_components():
        if entity == j.a or entity == j.b:
            esper.remove_component(e, type(j))
            if not esper.components_for_entity(e):
                empty.append(e)
    return empty
