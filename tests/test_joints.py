"""Joints in the soft step (framework.joints, framework.systems.soft_joints).

Analytic where the physics gives an answer (a pendulum's period, a spring's frequency, a motor's
torque, the angular acceleration of a hinged bar), bounded by the solver's tolerance (the linear
slop) where a constraint holds a length or an angle; dyadic values throughout.
"""

from __future__ import annotations

import math

import esper
import numpy as np
import pytest
from joint_helpers import DT, SLOP, G, box, period, pose, soft

from framework import (
    AABB,
    Circle,
    DistanceJoint,
    Hitbox,
    InvalidValue,
    MouseJoint,
    PrismaticJoint,
    RevoluteJoint,
    Scene,
    Transform,
    Velocity,
    WeldJoint,
    WheelJoint,
)
from framework.snapshot_file import load_snapshot, save_snapshot

# --- distance joints: rod, rope, spring ----------------------------------------------------------


@pytest.mark.parametrize("to_world", [False, True])
def test_a_pendulum_keeps_its_length_swings_at_its_period_and_gains_no_energy(to_world):
    s = soft()
    L, th0 = 2.0, 0.125
    pivot = None if to_world else s.spawn(Transform(0.0, 0.0), Hitbox(AABB(0.25, 0.25), body="static"))
    ball = s.spawn(Transform(L * math.sin(th0), -L * math.cos(th0)), Velocity(), Hitbox(Circle(0.0625)))
    joint = s.spawn(DistanceJoint(ball, pivot))
    assert s.get(joint, DistanceJoint).length == pytest.approx(L, abs=1e-15)
    ts, xs, angles, lengths = [], [], [], []
    for k in range(64 * 12):
        s.step(DT)
        x, y, _r = pose(s, ball)
        ts.append((k + 1) * DT)
        xs.append(x)
        angles.append(abs(math.atan2(x, -y)))
        lengths.append(math.hypot(x, y))
    assert max(abs(d - L) for d in lengths) < SLOP
    # small-angle period 2 pi sqrt(L / g), lengthened by (1 + th0^2 / 16) at this amplitude
    assert period(ts, xs) == pytest.approx(2 * math.pi * math.sqrt(L / G) * (1 + th0 * th0 / 16), rel=0.01)
    assert max(angles) <= th0 * (1 + 1e-5)  # (sampled once a step: no swing higher than the start)


def test_a_rope_lets_its_body_come_closer_but_never_farther():
    s = soft()
    anchor = s.spawn(Transform(0.0, 0.0), Hitbox(AABB(0.25, 0.25), body="static"))
    ball = s.spawn(Transform(0.0, -2.0), Velocity(1.0, 6.0), Hitbox(Circle(0.125)))
    s.spawn(DistanceJoint(ball, anchor, min_length=0.0, max_length=2.0))
    ds = []
    for _ in range(64 * 4):
        s.step(DT)
        x, y, _r = pose(s, ball)
        ds.append(math.hypot(x, y))
    assert min(ds) < 1.0  # thrown up: slack
    assert max(ds) <= 2.0 + SLOP  # caught at its length, never past it


@pytest.mark.parametrize("hertz", [0.5, 1.0])
def test_a_spring_oscillates_at_its_frequency(hertz):
    s = soft()
    ball = s.spawn(Transform(0.0, -1.0), Velocity(), Hitbox(Circle(0.125)))
    s.spawn(DistanceJoint(ball, None, length=1.0, hertz=hertz))
    # equilibrium: stretched by g / omega^2 below the rest length
    rest = -1.0 - G / (2 * math.pi * hertz) ** 2
    ts, ys = [], []
    for k in range(int(64 * 6 / hertz)):
        s.step(DT)
        ts.append((k + 1) * DT)
        ys.append(pose(s, ball)[1] - rest)
    assert period(ts, ys) == pytest.approx(1.0 / hertz, rel=0.03)


def test_a_damped_spring_settles_at_its_equilibrium():
    s = soft()
    ball = s.spawn(Transform(0.0, -1.0), Velocity(), Hitbox(Circle(0.125)))
    s.spawn(DistanceJoint(ball, None, length=1.0, hertz=1.0, damping=1.0))
    for _ in range(64 * 8):
        s.step(DT)
    assert pose(s, ball)[1] == pytest.approx(-1.0 - G / (2 * math.pi) ** 2, abs=1e-3)


def test_a_chain_of_twenty_links_between_two_statics_stays_within_its_length():
    s = soft()
    left = s.spawn(Transform(-2.0, 0.0), Hitbox(AABB(0.25, 0.25), body="static"))
    right = s.spawn(Transform(2.0, 0.0), Hitbox(AABB(0.25, 0.25), body="static"))
    link = 0.25  # 20 links of 0.25 and one more to the right: 5.25 across a gap of 4
    links = [s.spawn(Transform(-2.0 + 0.1875 * (i + 1), 0.0), Velocity(), Hitbox(Circle(0.0625))) for i in range(20)]
    ends = [left, *links, right]
    for a, b in zip(ends, ends[1:]):
        s.spawn(DistanceJoint(a, b, length=link))
    for k in range(64 * 6):
        s.step(DT)
        xy = [pose(s, e)[:2] for e in ends]
        gaps = [math.dist(p, q) for p, q in zip(xy, xy[1:])]
        # soft joints give a little while the chain falls and swings (as Box2D's do), hardly once it hangs
        assert max(gaps) <= link * (1 + 1 / 16) and sum(gaps) <= 21 * link * (1 + 1 / 32)
        if k >= 64 * 5:
            assert max(gaps) <= link + SLOP
    assert min(y for _x, y in xy) < -1.0  # it hangs (a taut chain would be at y 0)


# --- revolute joints: hinge, limits, motor --------------------------------------------------------


def hinged_bar(s: Scene, **kw) -> tuple[int, int]:
    """A bar 2 long (mass 1, inertia 1/4 about its middle) hinged to the world at its left end,
    level to start: gravity's torque about the hinge is -m g L/2 = -8, its inertia there 5/4."""
    bar = s.spawn(Transform(1.0, 0.0), Velocity(), Hitbox(box(1.0, 0.125), inertia=0.25))
    return bar, s.spawn(RevoluteJoint(bar, None, (0.0, 0.0), **kw))


def test_a_hinged_bar_turns_about_its_hinge():
    s = soft()
    bar, _j = hinged_bar(s)
    lowest = 0.0
    for _ in range(64 * 3):
        s.step(DT)
        x, y, r = pose(s, bar)
        assert math.hypot(x - math.cos(r), y - math.sin(r)) < SLOP  # its left end stays at the hinge
        lowest = min(lowest, r)
    assert lowest == pytest.approx(-math.pi, abs=0.01)  # it swings down and up to level on the other side


def test_a_revolute_limit_holds_under_load():
    s = soft()
    bar, _j = hinged_bar(s, lower=-0.25, upper=0.25)
    rs = []
    for _ in range(64 * 3):
        s.step(DT)
        rs.append(pose(s, bar)[2])
    assert min(rs) >= -0.25 - 0.01
    assert rs[-1] == pytest.approx(-0.25, abs=0.01)  # it rests on the lower limit


def test_a_motor_reaches_its_speed_against_a_load_it_can_carry():
    s = soft()
    bar, _j = hinged_bar(s, motor_speed=1.0, max_motor_torque=16.0)
    for _ in range(32):
        s.step(DT)
    assert s.get(bar, Velocity).angular == pytest.approx(1.0, abs=1e-3)


def test_a_motor_applies_no_more_than_its_torque():
    s = soft()
    bar, _j = hinged_bar(s, motor_speed=1.0, max_motor_torque=4.0)
    for _ in range(16):
        s.step(DT)
    # the motor's 4 against gravity's -8 about the hinge: alpha = -4 / (5/4)
    assert s.get(bar, Velocity).angular / (16 * DT) == pytest.approx(-3.2, rel=0.02)


def test_a_motor_too_weak_for_its_load_holds_nothing():
    s = soft()
    bar, j = hinged_bar(s, motor_speed=0.0, max_motor_torque=12.0)  # more than gravity's 8: held still
    for _ in range(64):
        s.step(DT)
    assert abs(pose(s, bar)[2]) < 1e-3
    s.get(j, RevoluteJoint).max_motor_torque = 4.0  # now too weak: it falls
    for _ in range(16):
        s.step(DT)
    assert pose(s, bar)[2] < -0.05


def test_changing_the_motor_speed_takes_effect():
    s = soft(gravity=0.0)
    wheel = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(Circle(0.5)))
    j = s.spawn(RevoluteJoint(wheel, None, (0.0, 0.0), motor_speed=2.0, max_motor_torque=64.0))
    for _ in range(8):
        s.step(DT)
    assert s.get(wheel, Velocity).angular == pytest.approx(2.0, abs=1e-6)
    s.get(j, RevoluteJoint).motor_speed = -1.0
    for _ in range(8):
        s.step(DT)
    assert s.get(wheel, Velocity).angular == pytest.approx(-1.0, abs=1e-6)
    assert math.hypot(*pose(s, wheel)[:2]) < 1e-9  # turning about its centre


# --- weld and mouse joints ------------------------------------------------------------------------


def relative(s: Scene, a: int, b: int) -> tuple[float, float, float]:
    """b's pose in a's frame."""
    xa, ya, ra = pose(s, a)
    xb, yb, rb = pose(s, b)
    c, sn = math.cos(ra), math.sin(ra)
    return c * (xb - xa) + sn * (yb - ya), -sn * (xb - xa) + c * (yb - ya), rb - ra


def test_a_weld_of_two_boxes_falls_and_lands_as_one():
    s = soft()
    s.spawn(Transform(0.0, -0.5), Hitbox(AABB(20.0, 1.0), body="static"))
    a = s.spawn(Transform(0.0, 2.0, 0.25), Velocity(0.0, 0.0, 1.0), Hitbox(box(0.5, 0.25)))
    b = s.spawn(Transform(0.0, 2.0, 0.25), Velocity(0.0, 0.0, 1.0), Hitbox(box(0.5, 0.25)))
    x, y, r = pose(s, a)
    t = s.get(b, Transform)
    t.x, t.y = x + math.cos(r), y + math.sin(r)  # b one to a's right, in a's frame
    s.spawn(WeldJoint(a, b, (x + 0.5 * math.cos(r), y + 0.5 * math.sin(r))))
    start = relative(s, a, b)
    for _ in range(64 * 3):
        s.step(DT)
        now = relative(s, a, b)
        # (the corner's impact on landing strains the weld for a step or two)
        assert math.dist(now[:2], start[:2]) < 2 * SLOP and abs(now[2] - start[2]) < 0.01
    assert math.dist(now[:2], start[:2]) < 1e-3 and abs(now[2] - start[2]) < 1e-3
    for e in (a, b):  # landed flat, side by side
        assert pose(s, e)[1] == pytest.approx(0.25, abs=SLOP) and abs(pose(s, e)[2]) < 1e-3


def test_a_mouse_joint_brings_a_body_to_its_target():
    s = soft(gravity=0.0)
    body = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(box(0.25, 0.25)))
    j = s.spawn(MouseJoint(body, (0.0, 0.0), max_force=64.0, hertz=4.0, damping=1.0))
    s.get(j, MouseJoint).target = (3.0, 1.0)
    for _ in range(64 * 3):
        s.step(DT)
    assert math.dist(pose(s, body)[:2], (3.0, 1.0)) < 1e-3


def test_a_mouse_joint_pulls_with_at_most_its_force():
    s = soft(gravity=0.0)
    body = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(Circle(0.25)))
    s.spawn(MouseJoint(body, (0.0, 0.0), max_force=2.0, hertz=4.0))
    s.get(esper.get_component(MouseJoint)[0][0], MouseJoint).target = (100.0, 0.0)
    for _ in range(16):
        s.step(DT)
    # a force of 2 on a mass of 1 for 1/4 s: a speed of 1/2 at most
    assert s.get(body, Velocity).x == pytest.approx(0.5, rel=1e-6)


@pytest.mark.parametrize("let_go", ["despawn", "remove_component"])
def test_a_body_a_mouse_joint_held_still_until_it_slept_falls_when_let_go(let_go):
    # held up still, the box falls asleep in the joint's grip; removing the joint wakes it (a
    # sleeper nobody touches would otherwise hang in the air), and it falls at g
    s = soft()
    body = s.spawn(Transform(0.0, 2.0), Velocity(), Hitbox(box(0.25, 0.25)))
    j = s.spawn(MouseJoint(body, (0.0, 2.0), max_force=64.0, hertz=4.0, damping=1.0))
    for _ in range(128):
        s.step(DT)
    assert s.store.asleep[s.store.row_of[body]]
    y0 = pose(s, body)[1]
    if let_go == "despawn":
        s.despawn(j)
    else:
        s.remove_component(j, MouseJoint)
    assert not s.store.asleep[s.store.row_of[body]]
    for _ in range(16):
        s.step(DT)
    assert s.get(body, Velocity).y == pytest.approx(-G * 16 * DT, rel=1e-6)
    assert pose(s, body)[1] < y0 - 0.5 * G * 0.25 ** 2 * 0.9


# --- ECS: validation, removal, collisions ---------------------------------------------------------


def bodies(s: Scene) -> tuple[int, int, int]:
    """Two bodies, an entity without a Hitbox, and entity 4 despawned."""
    a = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(Circle(0.25)))
    b = s.spawn(Transform(1.0, 0.0), Velocity(), Hitbox(Circle(0.25)))
    plain = s.spawn(Transform(3.0, 0.0))
    s.despawn(s.spawn(Transform(4.0, 0.0), Velocity(), Hitbox(Circle(0.25))))
    return a, b, plain


@pytest.mark.parametrize("make", [
    lambda a, b, p: DistanceJoint(a, 999),
    lambda a, b, p: DistanceJoint(a, 4),  # despawned
    lambda a, b, p: DistanceJoint(a, p),
    lambda a, b, p: RevoluteJoint(999, b, (0.0, 0.0)),
    lambda a, b, p: WeldJoint(a, a, (0.0, 0.0)),
    lambda a, b, p: DistanceJoint(a, b, length=math.nan),
    lambda a, b, p: DistanceJoint(a, b, anchor_a=(math.inf, 0.0)),
    lambda a, b, p: DistanceJoint(a, b, length=-1.0),
    lambda a, b, p: DistanceJoint(a, b, hertz=-1.0),
    lambda a, b, p: DistanceJoint(a, b, min_length=2.0, max_length=1.0),
    lambda a, b, p: DistanceJoint(a, b, min_length=2.0),  # more than the length measured, 1
    lambda a, b, p: RevoluteJoint(a, b, (0.5, 0.0), lower=0.5, upper=-0.5),
    lambda a, b, p: RevoluteJoint(a, b, (0.5, 0.0), max_motor_torque=-1.0),
    lambda a, b, p: MouseJoint(a, (0.0, 0.0), max_force=0.0),
    lambda a, b, p: MouseJoint(a, (0.0, math.nan), max_force=1.0),
    lambda a, b, p: DistanceJoint(True, b),
])
def test_a_bad_joint_is_refused_and_the_scene_is_unchanged(make):
    s = soft()
    a, b, plain = bodies(s)
    before = s.entities
    with pytest.raises(InvalidValue):
        s.spawn(make(a, b, plain))
    assert s.entities == before
    with pytest.raises(InvalidValue):
        s.add_component(plain, make(a, b, plain))
    assert esper.components_for_entity(plain) == (s.get(plain, Transform),)


def test_a_bad_value_written_later_is_refused_before_the_step_changes_anything():
    s = soft()
    a, b, _p = bodies(s)
    j = s.spawn(RevoluteJoint(a, b, (0.5, 0.0)))
    s.get(j, RevoluteJoint).motor_speed = math.nan
    with pytest.raises(InvalidValue, match=f"entity {j}.*motor_speed"):
        s.step(DT)
    assert s.frame == 0 and pose(s, a) == (0.0, 0.0, 0.0)


def test_a_joint_checked_by_earlier_steps_is_checked_again_when_written_or_its_body_changes():
    # a joint is checked (and packed) again only when something changed since: these changes must
    # each be seen, however many steps ran before them
    s = soft(gravity=0.0)
    a, b, _p = bodies(s)
    j = s.spawn(RevoluteJoint(a, b, (0.5, 0.0), motor_speed=0.0, max_motor_torque=10.0))
    for _ in range(3):
        s.step(DT)
    s.get(j, RevoluteJoint).motor_speed = 2.0  # a good value: packed again, the motor turns b
    for _ in range(8):
        s.step(DT)
    assert s.get(a, Velocity).angular - s.get(b, Velocity).angular == pytest.approx(2.0, abs=0.01)  # a's turn on b
    s.get(j, RevoluteJoint).lower = math.nan
    with pytest.raises(InvalidValue, match=f"entity {j}.*lower"):
        s.step(DT)
    s.get(j, RevoluteJoint).lower = None
    s.step(DT)
    before = (s.frame, pose(s, a), pose(s, b))
    s.remove_component(b, Hitbox)  # its body is no body any more
    with pytest.raises(InvalidValue, match=f"entity {j}.*has no Hitbox"):
        s.step(DT)
    assert (s.frame, pose(s, a), pose(s, b)) == before


def test_despawning_a_body_removes_its_joints():
    s = soft()
    a, b, _p = bodies(s)
    c = s.spawn(Transform(2.0, 0.0), Velocity(), Hitbox(Circle(0.25)))
    ab = s.spawn(DistanceJoint(a, b))
    bc = s.spawn(DistanceJoint(b, c))
    tagged = s.spawn(RevoluteJoint(a, None, (0.0, 0.0)), Tag())  # an entity holding more than the joint stays
    s.despawn(b)
    assert not s.exists(ab) and not s.exists(bc)
    assert s.exists(tagged) and s.try_get(tagged, RevoluteJoint) is not None
    s.despawn(a)
    assert s.exists(tagged) and s.try_get(tagged, RevoluteJoint) is None
    s.step(DT)


class Tag:
    """A game's own component."""


def test_collide_connected_is_off_by_default():
    def scene(collide: bool) -> Scene:
        s = soft(gravity=0.0)
        a = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(Circle(0.5)))
        b = s.spawn(Transform(0.75, 0.0), Velocity(), Hitbox(Circle(0.5)))  # overlapping
        s.spawn(DistanceJoint(a, b, collide_connected=collide))
        s.step(DT)
        return s

    assert len(scene(False).events) == 0
    assert len(scene(True).events) == 1


# --- snapshots, rollback, the exact solver --------------------------------------------------------


def machine() -> tuple[Scene, list[int]]:
    s = soft()
    s.spawn(Transform(0.0, -3.0), Hitbox(AABB(20.0, 1.0), body="static"))
    bar, _j = hinged_bar(s, lower=-1.0, upper=0.5, motor_speed=0.5, max_motor_torque=2.0)
    ball = s.spawn(Transform(2.0, -1.0), Velocity(), Hitbox(Circle(0.125)))
    s.spawn(DistanceJoint(bar, ball, anchor_a=(1.0, 0.0), hertz=2.0, damping=0.25))
    return s, [bar, ball]


def state(s: Scene, es: list[int]) -> bytes:
    return np.array([v for e in es for v in (*pose(s, e), *s.get(e, Velocity)._values())]).tobytes()


def test_a_restored_snapshot_continues_bit_for_bit():
    s, es = machine()
    for _ in range(40):
        s.step(DT)
    snap = s.snapshot()
    for _ in range(40):
        s.step(DT)
    expected = state(s, es)
    s.restore(snap)
    for _ in range(40):
        s.step(DT)
    assert state(s, es) == expected


def test_a_snapshot_file_continues_bit_for_bit(tmp_path):
    s, es = machine()
    for _ in range(40):
        s.step(DT)
    save_snapshot(s, tmp_path / "machine.snap")
    for _ in range(40):
        s.step(DT)
    expected = state(s, es)
    load_snapshot(s, tmp_path / "machine.snap")
    for _ in range(40):
        s.step(DT)
    assert state(s, es) == expected


def test_a_failed_step_leaves_the_joints_as_they_were():
    s, es = machine()
    twin, _ = machine()
    for _ in range(20):
        s.step(DT)
        twin.step(DT)

    def fail(scene, dt):
        raise RuntimeError("boom")

    s.add_system(fail, after="response")
    with pytest.raises(RuntimeError):
        s.step(DT)
    s.remove_system(fail)
    for _ in range(20):
        s.step(DT)
        twin.step(DT)
    assert state(s, es) == state(twin, es)


def test_the_exact_solver_refuses_joints():
    s = Scene(gravity=(0.0, -G))
    a, b, _p = bodies(s)
    s.spawn(DistanceJoint(a, b))
    with pytest.raises(InvalidValue, match='joints need Scene\\(solver="soft"\\)'):
        s.step(DT)
    assert s.frame == 0 and pose(s, a) == (0.0, 0.0, 0.0)


def test_a_sleeping_body_wakes_when_its_joint_changes():
    s = soft()
    wheel = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(Circle(0.5)))
    axle = s.spawn(RevoluteJoint(wheel, None, (0.0, 0.0), max_motor_torque=64.0))
    grabbed = s.spawn(Transform(4.0, 0.0), Velocity(), Hitbox(box(0.25, 0.25)))
    mouse = s.spawn(MouseJoint(grabbed, (4.0, 0.0), max_force=64.0))
    for _ in range(128):
        s.step(DT)
    assert s.store.asleep[s.store.row_of[wheel]] and s.store.asleep[s.store.row_of[grabbed]]
    s.get(axle, RevoluteJoint).motor_speed = 2.0
    s.get(mouse, MouseJoint).target = (4.0, 1.0)
    for _ in range(128):
        s.step(DT)
    assert s.get(wheel, Velocity).angular == pytest.approx(2.0, abs=1e-6)
    assert math.dist(pose(s, grabbed)[:2], (4.0, 1.0)) < 0.01


def test_a_body_asleep_wakes_when_the_other_body_of_its_joint_moves():
    s = soft()
    hook = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(Circle(0.125), body="kinematic"))
    ball = s.spawn(Transform(0.0, -1.0), Velocity(), Hitbox(Circle(0.125)))
    s.spawn(DistanceJoint(ball, hook))
    for _ in range(128):
        s.step(DT)
    assert s.store.asleep[s.store.row_of[ball]]
    s.get(hook, Velocity).x = 1.0  # the hook moves off: the ball follows
    for _ in range(64):
        s.step(DT)
    assert pose(s, ball)[0] > 0.5
    assert math.dist(pose(s, ball)[:2], pose(s, hook)[:2]) == pytest.approx(1.0, abs=SLOP)


# --- reactions: what a joint does to its body ---------------------------------------------------


def test_a_hanging_ball_is_held_by_its_weight():
    # a ball of mass 2 hanging at rest 1 below a fixed point: the rod pulls it up with m g = 16
    s = soft()
    ball = s.spawn(Transform(0.0, -1.0), Velocity(), Hitbox(Circle(0.125), mass=2.0))
    j = s.spawn(DistanceJoint(ball, None, anchor_b=(0.0, 0.0)))
    assert s.joint_reaction(j) == ((0.0, 0.0), 0.0)  # not solved yet
    for _ in range(64):
        s.step(DT)
    force, torque = s.joint_reaction(j)
    assert force == pytest.approx((0.0, 2.0 * G), abs=1e-6)
    assert torque == 0.0


def test_a_motor_holding_a_bar_level_gives_the_torque_gravity_takes():
    # the hinged bar (mass 1, 2 long) held level by a motor at speed 0: the hinge holds its weight
    # (force (0, 8) on the bar) and the motor gravity's moment about the hinge (m g L/2 = 8, turning
    # the bar up: counter-clockwise)
    s = soft()
    bar, j = hinged_bar(s, motor_speed=0.0, max_motor_torque=100.0)
    for _ in range(64):
        s.step(DT)
    assert abs(pose(s, bar)[2]) < 0.01
    force, torque = s.joint_reaction(j)
    assert force == pytest.approx((0.0, G), rel=1e-3)
    assert torque == pytest.approx(G * 1.0, rel=1e-3)


def test_a_welded_cantilever_carries_its_weight_and_moment():
    # a box 1 x 1/4 (mass 1) welded to the world at its left end: force (0, 8), torque 8 * 1/2
    s = soft()
    plank = s.spawn(Transform(0.5, 0.0), Velocity(), Hitbox(box(0.5, 0.125)))
    j = s.spawn(WeldJoint(plank, None, (0.0, 0.0)))
    for _ in range(64):
        s.step(DT)
    force, torque = s.joint_reaction(j)
    assert force == pytest.approx((0.0, G), rel=1e-3)
    assert torque == pytest.approx(G * 0.5, rel=1e-3)


def test_a_mouse_joint_holding_a_body_against_gravity_pulls_up_with_its_weight():
    s = soft()
    body = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(Circle(0.25), mass=0.5))
    j = s.spawn(MouseJoint(body, (0.0, 0.0), max_force=64.0, hertz=4.0, damping=1.0))
    for _ in range(64 * 4):
        s.step(DT)
    force, _torque = s.joint_reaction(j)
    assert force == pytest.approx((0.0, 0.5 * G), rel=1e-3)


def test_the_reaction_of_something_that_is_no_joint_is_refused():
    s = soft()
    ball = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(Circle(0.25)))
    for bad in (ball, 999, "joint", True):
        with pytest.raises(InvalidValue, match="joint"):
            s.joint_reaction(bad)


# --- breaking -------------------------------------------------------------------------------------


@pytest.mark.parametrize("mass, breaks", [(2.0, False), (3.0, True)])
def test_a_rope_breaks_above_its_force(mass, breaks):
    # a ball hanging from a rod that breaks above a force of 20: its weight m g is 16 or 24
    s = soft()
    ball = s.spawn(Transform(0.0, -1.0), Velocity(), Hitbox(Circle(0.125), mass=mass))
    rod = s.spawn(DistanceJoint(ball, None, anchor_b=(0.0, 0.0), break_force=20.0))
    s.step(DT)
    if breaks:
        (b,) = s.broken_joints
        assert (b.entity, b.a, b.b, type(b.joint)) == (rod, ball, None, DistanceJoint)
        assert b.force == pytest.approx((0.0, mass * G), rel=1e-3)
        assert not s.exists(rod)  # the joint was all its entity held
        for _ in range(31):
            s.step(DT)
        assert s.broken_joints == []
        assert s.get(ball, Velocity).y == pytest.approx(-G * 31 * DT, rel=1e-6)  # falling freely since
    else:
        for _ in range(63):
            s.step(DT)
            assert s.broken_joints == []
        assert pose(s, ball)[1] == pytest.approx(-1.0, abs=SLOP)


@pytest.mark.parametrize("limit, breaks", [(6.0, True), (16.0, False)])
def test_a_motor_hinge_breaks_above_its_torque(limit, breaks):
    # the motor holding the bar level gives a torque of 8 (up to 11 in the first steps, as the bar settles)
    s = soft()
    bar, j = hinged_bar(s, motor_speed=0.0, max_motor_torque=100.0)
    s.get(j, RevoluteJoint).break_torque = limit
    broke = []
    for _ in range(32):
        s.step(DT)
        broke += s.broken_joints
    assert bool(broke) == breaks
    if breaks:
        assert broke[0].torque > limit and not s.exists(j)


def test_a_joint_on_an_entity_with_other_components_leaves_the_entity():
    s = soft()
    ball = s.spawn(Transform(0.0, -1.0), Velocity(), Hitbox(Circle(0.125), mass=4.0))
    class Label:  # a game's own component on the joint's entity
        pass

    holder = s.spawn(DistanceJoint(ball, None, anchor_b=(0.0, 0.0), break_force=1.0), Label())
    s.step(DT)
    assert s.exists(holder) and s.try_get(holder, DistanceJoint) is None


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, "strong", True, None])
def test_a_bad_break_force_or_torque_is_refused(bad):
    s = soft()
    ball = s.spawn(Transform(0.0, -1.0), Velocity(), Hitbox(Circle(0.125)))
    with pytest.raises(InvalidValue, match="break_force"):
        DistanceJoint(ball, None, break_force=bad)
    with pytest.raises(InvalidValue, match="break_torque"):
        RevoluteJoint(ball, None, (0.0, 0.0), break_torque=bad)
    j = s.spawn(WeldJoint(ball, None, (0.0, 0.0)))
    s.get(j, WeldJoint).break_force = bad
    before = pose(s, ball)
    with pytest.raises(InvalidValue, match="break_force"):
        s.step(DT)
    assert pose(s, ball) == before


# --- prismatic: a slider ------------------------------------------------------------------------------


def slider(s: Scene, axis=(1.0, 1.0), **kw) -> tuple[int, int]:
    """A box (mass 1, turns) on a slider to the world through its centre at the origin."""
    body = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(box(0.25, 0.25)))
    return body, s.spawn(PrismaticJoint(body, None, (0.0, 0.0), axis=axis, **kw))


def test_a_slider_slides_along_its_axis_as_gravity_along_it_says():
    # a 45-degree axis: gravity along it is -8 / sqrt 2; the box keeps to the line and its angle
    s = soft()
    body, _j = slider(s)
    for _ in range(64):
        s.step(DT)
        x, y, r = pose(s, body)
        assert abs(x - y) / math.sqrt(2.0) < SLOP and abs(r) < 1e-3
    along = (x + y) / math.sqrt(2.0)
    assert along == pytest.approx(-0.5 * G / math.sqrt(2.0) * 1.0 ** 2, rel=0.02)


def test_a_slider_stops_at_its_limits():
    s = soft()
    body, _j = slider(s, axis=(0.0, 1.0), lower=-0.5, upper=2.0)
    for _ in range(64 * 2):
        s.step(DT)
        assert pose(s, body)[1] > -0.5 - 0.01
    assert pose(s, body)[1] == pytest.approx(-0.5, abs=0.01)
    s.get(body, Velocity).y = 20.0  # thrown up: stops at the upper limit
    for _ in range(16):
        s.step(DT)
        assert pose(s, body)[1] < 2.0 + 0.01


def test_a_slider_motor_reaches_its_speed_and_pushes_no_harder_than_its_force():
    s = soft(gravity=0.0)
    body, _j = slider(s, axis=(1.0, 0.0), motor_speed=2.0, max_motor_force=100.0)
    for _ in range(16):
        s.step(DT)
    assert s.get(body, Velocity).x == pytest.approx(2.0, abs=1e-3)
    # up a vertical slider against gravity's 8 with a force of 4: it falls at 4
    s = soft()
    body, _j = slider(s, axis=(0.0, 1.0), motor_speed=1.0, max_motor_force=4.0)
    for _ in range(16):
        s.step(DT)
    assert s.get(body, Velocity).y / (16 * DT) == pytest.approx(-4.0, rel=0.02)


def test_a_slider_motor_holding_a_body_carries_its_weight():
    s = soft()
    body, j = slider(s, axis=(0.0, 1.0), motor_speed=0.0, max_motor_force=100.0)
    for _ in range(64):
        s.step(DT)
    assert abs(pose(s, body)[1]) < 0.01
    force, torque = s.joint_reaction(j)
    assert force == pytest.approx((0.0, G), rel=1e-3, abs=1e-6)
    assert torque == pytest.approx(0.0, abs=1e-6)


def test_a_slider_between_two_bodies_keeps_them_on_its_line():
    # a box sliding on a turning beam pinned at its middle: it stays on the beam's axis as the beam turns
    s = soft()
    beam = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(box(2.0, 0.0625), inertia=1.0))
    s.spawn(RevoluteJoint(beam, None, (0.0, 0.0)))
    bead = s.spawn(Transform(1.0, 0.5), Velocity(), Hitbox(Circle(0.125)))
    s.spawn(PrismaticJoint(bead, beam, (1.0, 0.5), axis=(1.0, 0.0), lower=-3.0, upper=1.0))
    for _ in range(64 * 2):
        s.step(DT)
        bx, by, br = pose(s, beam)
        x, y, _r = pose(s, bead)
        # the bead's offset from the beam's line through (1, 0.5) when made: 0.5 across the beam
        across = -(x - bx) * math.sin(br) + (y - by) * math.cos(br)
        assert across == pytest.approx(0.5, abs=2 * SLOP)


@pytest.mark.parametrize("kw, field", [({"axis": (0.0, 0.0)}, "axis"), ({"lower": 1.0, "upper": 0.0}, "lower"),
                                       ({"max_motor_force": -1.0}, "max_motor_force"),
                                       ({"motor_speed": math.nan}, "motor_speed")])
def test_a_bad_slider_is_refused(kw, field):
    s = soft()
    body = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(box(0.25, 0.25)))
    with pytest.raises(InvalidValue, match=field):
        PrismaticJoint(body, None, (0.0, 0.0), **kw)


# --- wheel: a suspension and a motor ------------------------------------------------------------------


def test_a_wheel_hangs_on_its_suspension_and_bounces_at_its_frequency():
    # a wheel (mass 1) on a vertical spring of 2 hertz to the world: it settles where the spring
    # carries its weight, m g / k below, k = m (2 pi f)^2, and bounces about there at 2 hertz
    s = soft()
    wheel = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(Circle(0.25)))
    s.spawn(WheelJoint(wheel, None, (0.0, 0.0), axis=(0.0, 1.0), hertz=2.0, damping=0.0))
    ts, ys = [], []
    for k in range(64 * 4):
        s.step(DT)
        x, y, _r = pose(s, wheel)
        assert abs(x) < SLOP
        ts.append((k + 1) * DT)
        ys.append(y)
    sag = G / (2.0 * math.pi * 2.0) ** 2
    assert sum(ys) / len(ys) == pytest.approx(-sag, rel=0.05)
    assert period(ts, [y + sag for y in ys]) == pytest.approx(0.5, rel=0.03)


def test_a_wheel_motor_turns_the_wheel_at_its_speed():
    s = soft(gravity=0.0)
    wheel = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(Circle(0.25)))
    s.spawn(WheelJoint(wheel, None, (0.0, 0.0), motor_speed=-5.0, max_motor_torque=10.0))
    for _ in range(32):
        s.step(DT)
    assert s.get(wheel, Velocity).angular == pytest.approx(-5.0, abs=1e-3)


def test_a_car_drives_on_its_wheels():
    # a chassis on two wheels (radius 1/4) with motors at -8 rad/s, on a floor with friction: it
    # drives right at about 8 * 1/4 = 2 (the wheels roll), level, on its suspension
    s = soft()
    s.spawn(Transform(20.0, -0.5), Hitbox(AABB(60.0, 1.0), body="static", friction=0.9))
    chassis = s.spawn(Transform(0.0, 0.75), Velocity(), Hitbox(box(0.75, 0.125), mass=2.0, friction=0.9))
    wheels = []
    for x in (-0.5, 0.5):
        w = s.spawn(Transform(x, 0.25), Velocity(), Hitbox(Circle(0.25), mass=0.5, friction=0.9))
        s.spawn(WheelJoint(w, chassis, (x, 0.25), axis=(0.0, 1.0), hertz=4.0, damping=0.7, motor_speed=-8.0,
                           max_motor_torque=20.0))
        wheels.append(w)
    for _ in range(64 * 3):
        s.step(DT)
    v = s.get(chassis, Velocity)
    assert v.x == pytest.approx(2.0, rel=0.05)
    assert abs(pose(s, chassis)[2]) < 0.05
    for w in wheels:
        assert s.get(w, Velocity).angular == pytest.approx(-8.0, rel=0.02)
        assert pose(s, w)[1] == pytest.approx(0.25, abs=4 * SLOP)  # on the ground


def test_a_wheel_motor_holding_still_reports_its_torque():
    # the hinged-bar load on a wheel joint (no spring slide: limits at 0): the motor at speed 0
    # holds the bar level with torque m g L/2 = 8 (joint_reaction, on the bar)
    s = soft()
    bar = s.spawn(Transform(1.0, 0.0), Velocity(), Hitbox(box(1.0, 0.125), inertia=0.25))
    j = s.spawn(WheelJoint(bar, None, (0.0, 0.0), axis=(0.0, 1.0), hertz=0.0, lower=0.0, upper=0.0,
                           motor_speed=0.0, max_motor_torque=100.0))
    for _ in range(64):
        s.step(DT)
    assert abs(pose(s, bar)[2]) < 0.01
    force, torque = s.joint_reaction(j)
    assert force == pytest.approx((0.0, G), rel=1e-2, abs=1e-3)
    assert torque == pytest.approx(G, rel=1e-2)


@pytest.mark.parametrize("kw, field", [({"axis": (0.0, 0.0)}, "axis"), ({"hertz": -1.0}, "hertz"),
                                       ({"lower": 1.0, "upper": 0.0}, "lower"),
                                       ({"max_motor_torque": math.inf}, "max_motor_torque")])
def test_a_bad_wheel_is_refused(kw, field):
    s = soft()
    wheel = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(Circle(0.25)))
    with pytest.raises(InvalidValue, match=field):
        WheelJoint(wheel, None, (0.0, 0.0), **kw)
