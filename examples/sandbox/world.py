"""The sandbox's scene: ground, a slope, crates, barrels, a rope with a weight, and a car.

World units are metres (``Scene(length_unit=1)``), y up, gravity 10 m/s^2 down; the camera shows
them at :data:`ZOOM` pixels a metre. The car is a chassis box on two wheels, each held by a
:class:`~framework.WheelJoint` (a suspension spring along the chassis' up axis and a motor that
turns the wheel); the rope is a chain of links on :class:`~framework.RevoluteJoint` hinges hanging
from a static hook, with a heavy ball at its end.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from framework import AABB, Circle, Hitbox, Polygon, RevoluteJoint, Scene, Transform, Velocity, WheelJoint
from framework.components import Visual

__all__ = ["CAR", "DT", "GRAVITY", "SLOPE", "ZOOM", "CarSpec", "Sandbox", "SlopeSpec", "make_sandbox", "slope_height"]

GRAVITY = 10.0  # m/s^2, down
ZOOM = 25.0  # screen pixels a metre
DT = 1.0 / 60.0

# The slope: a ramp from (SLOPE.x0, 0) up to (SLOPE.x1, SLOPE.height), a flat top to SLOPE.x2, and a
# ramp down to (SLOPE.x3, 0).


@dataclass(frozen=True)
class SlopeSpec:
    x0: float = 0.0
    x1: float = 12.0
    x2: float = 16.0
    x3: float = 22.0
    height: float = 3.0

    @property
    def angle(self) -> float:
        """The ramp's angle, radians (atan(3 / 12): about 14 degrees)."""
        return math.atan2(self.height, self.x1 - self.x0)


@dataclass(frozen=True)
class CarSpec:
    x: float = -4.0  # where the chassis' centre starts
    width: float = 2.0
    height: float = 0.4
    chassis_mass: float = 4.0
    wheel_radius: float = 0.4
    wheel_mass: float = 1.0
    wheelbase: float = 1.4  # between the wheels' centres
    ride: float = 0.5  # the wheels' centres below the chassis' centre
    hertz: float = 6.0  # the suspension: stiff enough that the car does not pitch much as it drives off
    damping: float = 1.0
    speed: float = 10.0  # the motor's speed, rad/s (about 4 m/s on the flat)
    torque: float = 10.0  # the motor's most torque while driving (more lifts the front wheel off: a wheelie)
    brake_torque: float = 10.0  # held at speed 0 when no key is down: the car parks on the slope
    friction: float = 0.9


SLOPE = SlopeSpec()
CAR = CarSpec()


def slope_height(x: float) -> float:
    """The ground's height (top surface) at ``x``."""
    s = SLOPE
    if x <= s.x0 or x >= s.x3:
        return 0.0
    if x <= s.x1:
        return s.height * (x - s.x0) / (s.x1 - s.x0)
    if x <= s.x2:
        return s.height
    return s.height * (s.x3 - x) / (s.x3 - s.x2)


@dataclass
class Sandbox:
    """The scene and the entities the controls and the tests refer to."""

    scene: Scene
    chassis: int
    wheels: tuple[int, int]
    motors: tuple[int, int]  # the WheelJoints' entities (rear, front)
    ground: list[int]  # the floor, the ramp up, the flat top, the ramp down (static)
    crates: list[int] = field(default_factory=list)
    barrels: list[int] = field(default_factory=list)
    rope: list[int] = field(default_factory=list)  # the links, from the hook down, then the weight
    statics: list[int] = field(default_factory=list)  # the other static bodies: two walls, the rope's hook
    drag: int | None = None  # the MouseJoint's entity while the mouse holds a body

    def wheel_gaps(self) -> tuple[float, float]:
        """How far each wheel (rear, front) is from the ground: 0 where it touches (or sinks in)."""
        rear, front = (min(self.scene.distance(w, g).distance for g in self.ground) for w in self.wheels)
        return rear, front

    def close(self) -> None:
        self.scene.close()

    def __enter__(self) -> Sandbox:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _box(w: float, h: float) -> Polygon:
    return Polygon.box(w, h)


def make_sandbox() -> Sandbox:
    scene = Scene(gravity=(0.0, -GRAVITY), solver="soft")
    ground_color, wood, steel = (70, 78, 96), (176, 128, 72), (120, 132, 150)
    s = SLOPE
    ground = [
        scene.spawn(Transform(5.0, -0.5), Hitbox(AABB(50.0, 1.0), body="static", friction=0.9),
                    Visual(ground_color)),
        scene.spawn(Transform(0.0, 0.0), Hitbox(Polygon([(s.x0, 0.0), (s.x1, 0.0), (s.x1, s.height)]),
                                                body="static", friction=0.9), Visual(ground_color)),
        scene.spawn(Transform((s.x1 + s.x2) / 2, s.height / 2), Hitbox(AABB(s.x2 - s.x1, s.height), body="static",
                                                                       friction=0.9), Visual(ground_color)),
        scene.spawn(Transform(0.0, 0.0), Hitbox(Polygon([(s.x2, 0.0), (s.x3, 0.0), (s.x2, s.height)]),
                                                body="static", friction=0.9), Visual(ground_color)),
    ]
    statics = [
        scene.spawn(Transform(-18.5, 5.0), Hitbox(AABB(1.0, 10.0), body="static"), Visual(ground_color)),
        scene.spawn(Transform(28.5, 5.0), Hitbox(AABB(1.0, 10.0), body="static"), Visual(ground_color)),
    ]
    crates = [scene.spawn(Transform(x, 0.5 + 1.0 * k), Velocity(), Hitbox(_box(1.0, 1.0), mass=2.0, friction=0.6),
                          Visual(wood))
              for x, k in ((-14.0, 0), (-14.0, 1), (-12.5, 0), (25.0, 0))]
    barrels = [scene.spawn(Transform(x, 0.45), Velocity(), Hitbox(Circle(0.45), mass=1.5, friction=0.6),
                           Visual(steel))
               for x in (-10.0, 27.0)]
    # The rope: a hook, 8 links of 0.5 m hinged end to end, a ball of 4 kg at the end; it hangs
    # straight down, clear of the ground.
    hook_x, hook_y, link = -8.0, 8.0, 0.5
    hook = scene.spawn(Transform(hook_x, hook_y), Hitbox(AABB(0.3, 0.3), body="static"), Visual(ground_color))
    statics.append(hook)
    rope: list[int] = []
    above, top = hook, hook_y
    for _ in range(8):
        e = scene.spawn(Transform(hook_x, top - link / 2), Velocity(),
                        Hitbox(_box(0.12, link), mass=0.25, friction=0.3), Visual((200, 180, 140)))
        scene.spawn(RevoluteJoint(e, above, (hook_x, top)))
        rope.append(e)
        above, top = e, top - link
    weight = scene.spawn(Transform(hook_x, top - 0.35), Velocity(), Hitbox(Circle(0.35), mass=4.0, friction=0.5),
                         Visual((200, 70, 60)))
    scene.spawn(RevoluteJoint(weight, above, (hook_x, top)))
    rope.append(weight)
    chassis, wheels, motors = _car(scene, CAR)
    return Sandbox(scene, chassis, wheels, motors, ground, crates, barrels, rope, statics)


def _car(scene: Scene, c: CarSpec) -> tuple[int, tuple[int, int], tuple[int, int]]:
    """A chassis on two wheels at rest on the flat ground at ``c.x``; the wheels' joints (rear, front)."""
    wheel_y = c.wheel_radius
    chassis_y = wheel_y + c.ride
    chassis = scene.spawn(Transform(c.x, chassis_y), Velocity(),
                          Hitbox(_box(c.width, c.height), mass=c.chassis_mass, friction=c.friction),
                          Visual((220, 90, 60), z=1))
    wheels, motors = [], []
    for dx in (-c.wheelbase / 2, c.wheelbase / 2):
        x = c.x + dx
        w = scene.spawn(Transform(x, wheel_y), Velocity(),
                        Hitbox(Circle(c.wheel_radius), mass=c.wheel_mass, friction=c.friction),
                        Visual((40, 40, 46), z=2))
        j = scene.spawn(WheelJoint(w, chassis, (x, wheel_y), axis=(0.0, 1.0), hertz=c.hertz, damping=c.damping,
                                   motor_speed=0.0, max_motor_torque=c.brake_torque))
        wheels.append(w)
        motors.append(j)
    return chassis, (wheels[0], wheels[1]), (motors[0], motors[1])
