"""The sandbox's controls as plain functions: the window's handlers call them with world points and
key names, and so do the demo script and the tests (no window needed).

- The mouse drags bodies: :func:`grab` at a point spawns a :class:`~framework.MouseJoint` on the
  dynamic body there (its pull at most :data:`DRAG_STRENGTH` times the body's weight), :func:`drag_to`
  moves its target, :func:`release` removes it.
- Keys drive the car: :func:`drive` sets both wheel motors from the keys held (right / D: forward,
  left / A: back, neither: the brake); :func:`drive_system` does it every step from the scene's
  :class:`~framework.Input`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from framework import Body, Hitbox, Input, MouseJoint, Scene, WheelJoint
from framework.joints import JOINT_TYPES

from .world import CAR, GRAVITY, Sandbox

__all__ = ["DRAG_STRENGTH", "drag_to", "drive", "drive_system", "grab", "joint_count", "release"]

DRAG_STRENGTH = 50.0  # a drag pulls with at most this many times the body's weight
FORWARD, BACK = ("right", "d"), ("left", "a")


def joint_count(sandbox: Sandbox) -> int:
    """How many joints the scene holds (of every kind)."""
    return sum(len(sandbox.scene.query(kind)) for kind in JOINT_TYPES)


def _draggable(sandbox: Sandbox, entity: int) -> bool:
    hitbox = sandbox.scene.try_get(entity, Hitbox)
    return hitbox is not None and hitbox.body is Body.DYNAMIC and hitbox.mass < float("inf") \
        and not hitbox.sensor


def grab(sandbox: Sandbox, point: tuple[float, float]) -> int | None:
    """Press at the world ``point``: drag the dynamic body there (the first, by entity id, if
    several overlap) by its point under ``point``; return the MouseJoint's entity, or ``None`` when
    no dynamic body is there (a static body is never dragged). A drag already held is released."""
    release(sandbox)
    scene = sandbox.scene
    bodies = [e for e in scene.query_point(point[0], point[1]) if _draggable(sandbox, e)]
    if not bodies:
        return None
    body = min(bodies)
    weight = scene.get(body, Hitbox).mass * GRAVITY
    sandbox.drag = scene.spawn(MouseJoint(body, point, max_force=DRAG_STRENGTH * weight, hertz=5.0, damping=0.7))
    return sandbox.drag


def drag_to(sandbox: Sandbox, point: tuple[float, float]) -> None:
    """Move the mouse to the world ``point``: the dragged body's point follows it (nothing is
    dragged: nothing happens)."""
    joint = _held(sandbox)
    if joint is not None:
        joint.target = point


def release(sandbox: Sandbox) -> None:
    """Let go: remove the drag's joint (if any)."""
    if _held(sandbox) is not None:
        assert sandbox.drag is not None
        sandbox.scene.despawn(sandbox.drag)
    sandbox.drag = None


def _held(sandbox: Sandbox) -> MouseJoint | None:
    """The drag's joint, or ``None`` (none, or gone: its body despawned, or it broke)."""
    if sandbox.drag is None or not sandbox.scene.exists(sandbox.drag):
        sandbox.drag = None
        return None
    joint: MouseJoint | None = sandbox.scene.try_get(sandbox.drag, MouseJoint)
    return joint


def drive(sandbox: Sandbox, held: Iterable[str]) -> int:
    """Set the car's wheel motors from the keys ``held``: forward (right, D) turns the wheels
    clockwise at ``CAR.speed`` with at most ``CAR.torque``, back (left, A) the other way, both or
    neither hold them at speed 0 with ``CAR.brake_torque`` (a parking brake). Return the direction
    (1, -1 or 0)."""
    keys = set(held)
    direction = int(any(k in keys for k in FORWARD)) - int(any(k in keys for k in BACK))
    for j in sandbox.motors:
        motor = sandbox.scene.get(j, WheelJoint)
        motor.motor_speed = -direction * CAR.speed  # clockwise (negative) rolls right
        motor.max_motor_torque = CAR.torque if direction else CAR.brake_torque
    return direction


def drive_system(sandbox: Sandbox) -> Callable[[Scene, float], None]:
    """A system (for ``scene.add_system(..., before="movement")``) that drives the car from the
    scene's :class:`~framework.Input` every step."""

    def system(scene: Scene, dt: float) -> None:
        drive(sandbox, scene.resources.setdefault(Input, Input()).held)

    return system
