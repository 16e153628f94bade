"""Springs on revolute and prismatic joints, and the motor joint (issue 37; framework.joints,
framework.systems.soft_joints).

Analytic where the physics gives an answer: a spring of f hertz oscillates at f and sags m g / k;
a damping ratio of 1 returns without overshoot; a motor joint holds its body at its target with the
body's weight, and never pulls harder than its ``max_force``. The sub-step is the unit of the
solver's error: at 1/64 s a step and 4 sub-steps, h = 1/256 s.
"""

from __future__ import annotations

import math

import esper
import pytest
from joint_helpers import DT, SLOP, G, box, period, pose, soft

from framework import (
    AABB,
    Circle,
    DistanceJoint,
    Hitbox,
    InvalidValue,
    MotorJoint,
    PrismaticJoint,
    RevoluteJoint,
    Scene,
    Transform,
    Velocity,
)
from framework.snapshot_file import load_snapshot, save_snapshot
from framework.systems.soft_step import SOFT_SETTINGS

H = DT / SOFT_SETTINGS["substeps"]  # the sub-step


def period_tolerance(hertz: float) -> float:
    """The relative error allowed on a spring's period: the soft step solves a spring implicitly
    over each sub-step h (Box2D's soft constraint), and an implicit step's frequency is off by a
    term of order (omega h)^2 (backward Euler's turns by atan(omega h) a step instead of omega h:
    (omega h)^2 / 3 slow); measured, about (omega h)^2 / 2.2 here. The zero crossings are
    interpolated linearly between steps 1/64 s apart, which errs far less (their errors cancel
    over whole periods)."""
    return (2.0 * math.pi * hertz * H) ** 2


# --- the revolute spring ----------------------------------------------------------------------


def sprung_bar(s: Scene, turn: float = 0.125, **kw) -> tuple[int, int]:
    """A bar (moment of inertia 1/4) hinged to the world at its centre on a spring, made level,
    then turned by ``turn``: the spring pulls it back toward level, the angle it was made at."""
    bar = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(box(1.0, 0.125), inertia=0.25))
    j = s.spawn(RevoluteJoint(bar, None, (0.0, 0.0), **kw))
    s.get(bar, Transform).rotation = turn
    return bar, j


@pytest.mark.parametrize("hertz", [1.0, 4.0])
def test_a_bar_on_a_revolute_spring_oscillates_at_its_frequency(hertz):
    # no gravity, no damping: theta = 0.125 cos(2 pi f t), with no energy gained
    s = soft(gravity=0.0)
    bar, j = sprung_bar(s, hertz=hertz)
    ts, rs = [], []
    for k in range(int(64 * 6 / hertz)):
        s.step(DT)
        x, y, r = pose(s, bar)
        assert math.hypot(x, y) < 1e-9  # turning about its centre
        ts.append((k + 1) * DT)
        rs.append(r)
    assert period(ts, rs) == pytest.approx(1.0 / hertz, rel=period_tolerance(hertz))
    assert max(abs(r) for r in rs) <= 0.125
    # its torque: the spring's, -I omega^2 theta (I = 1/4), the last sub-step's
    torque = s.joint_reaction(j).torque
    assert torque == pytest.approx(-0.25 * (2.0 * math.pi * hertz) ** 2 * rs[-1], rel=0.05, abs=1e-3)


@pytest.mark.parametrize("damping, overshoots", [(0.25, True), (1.0, False), (2.0, False)])
def test_a_damped_revolute_spring_overshoots_only_below_a_damping_ratio_of_one(damping, overshoots):
    # critically damped (1) or more: theta returns to 0 without crossing it; less: it swings past
    s = soft(gravity=0.0)
    bar, _j = sprung_bar(s, hertz=2.0, damping=damping)
    rs = []
    for _ in range(64 * 3):
        s.step(DT)
        rs.append(pose(s, bar)[2])
    if overshoots:
        assert min(rs) < -0.01
    else:
        assert min(rs) >= -1e-9
        assert all(b <= a + 1e-12 for a, b in zip(rs, rs[1:]))  # straight back, never turning round
    # settled within 3 s (6 periods): asleep, which stops an overdamped bar creeping back a few
    # milliradians short (it sleeps once slower than the sleep threshold)
    assert abs(rs[-1]) < 0.125 * 0.05 and s.store.asleep[s.store.row_of[bar]]


def test_a_spring_taken_off_leaves_a_free_hinge_and_put_back_starts_afresh():
    s = soft(gravity=0.0)
    bar, j = sprung_bar(s, hertz=2.0)
    for _ in range(8):
        s.step(DT)
    s.get(j, RevoluteJoint).hertz = 0.0  # off: the bar turns on freely, at the speed it had
    s.step(DT)
    w = s.get(bar, Velocity).angular
    assert w < -0.5 and s.joint_reaction(j).torque == 0.0
    for _ in range(8):
        s.step(DT)
        assert s.get(bar, Velocity).angular == pytest.approx(w, abs=1e-12)
    assert s._stages["soft_step"].joints[1][0, 5] == 0.0  # its impulse forgotten (JOINT_IMP "spring")
    s.get(j, RevoluteJoint).hertz = 2.0  # back on: swinging about 0 again (free, it would turn 1.5 a second)
    rs = []
    for _ in range(64):
        s.step(DT)
        rs.append(pose(s, bar)[2])
    assert min(rs) < 0.0 < max(rs) and max(abs(r) for r in rs) < 0.3


def test_a_revolute_spring_and_its_limits_and_motor_work_together():
    # a spring stiff enough to hold a bar hinged at its end against gravity (torque m g L/2 = 8
    # at level): it sags to where the spring's torque k theta carries it, as long as a limit does
    # not stop it first
    s = soft()
    bar = s.spawn(Transform(1.0, 0.0), Velocity(), Hitbox(box(1.0, 0.125), inertia=0.25))
    s.spawn(RevoluteJoint(bar, None, (0.0, 0.0), hertz=4.0, damping=1.0, lower=-0.1))
    for _ in range(64 * 2):
        s.step(DT)
    # k = I (2 pi f)^2 with I the bar's own 1/4 (the spring's angular mass): theta = 8 cos / k
    k = 0.25 * (2.0 * math.pi * 4.0) ** 2
    free = -8.0 / k  # (about -0.05: cos theta ~ 1)
    assert -0.1 < free
    assert pose(s, bar)[2] == pytest.approx(free * math.cos(free), rel=0.01)
    s2 = soft()
    bar2 = s2.spawn(Transform(1.0, 0.0), Velocity(), Hitbox(box(1.0, 0.125), inertia=0.25))
    s2.spawn(RevoluteJoint(bar2, None, (0.0, 0.0), hertz=4.0, damping=1.0, lower=-0.02))
    for _ in range(64 * 2):
        s2.step(DT)
    assert pose(s2, bar2)[2] == pytest.approx(-0.02, abs=0.002)  # the limit holds it first


# --- the prismatic spring ---------------------------------------------------------------------


@pytest.mark.parametrize("hertz", [1.0, 2.0])
def test_a_mass_on_a_prismatic_spring_sags_its_weight_over_k_and_oscillates_at_its_frequency(hertz):
    # a box of mass 2 on a vertical slider with a spring of f hertz (k = m (2 pi f)^2), let go
    # where the spring is slack: it oscillates at f about m g / k = g / (2 pi f)^2 below, keeping
    # to the axis and its angle
    s = soft()
    body = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(box(0.25, 0.25), mass=2.0))
    j = s.spawn(PrismaticJoint(body, None, (0.0, 0.0), axis=(0.0, 1.0), hertz=hertz))
    sag = G / (2.0 * math.pi * hertz) ** 2
    ts, ys = [], []
    for k in range(64 * 6):
        s.step(DT)
        x, y, r = pose(s, body)
        assert abs(x) < SLOP and abs(r) < 1e-6
        ts.append((k + 1) * DT)
        ys.append(y)
    assert period(ts, [y + sag for y in ys]) == pytest.approx(1.0 / hertz, rel=period_tolerance(hertz))
    assert min(ys) >= -2.0 * sag - 1e-9  # no energy gained: never below twice the sag
    # at rest (damped), the spring carries the weight m g = k sag (the soft constraint's fixed
    # point is exact: its impulse a sub-step is m h omega^2 times the stretch), joint_reaction m g up
    s.get(j, PrismaticJoint).damping = 1.0
    for _ in range(64 * 4):
        s.step(DT)
    assert pose(s, body)[1] == pytest.approx(-sag, rel=0.01)
    force, torque = s.joint_reaction(j)
    assert force == pytest.approx((0.0, 2.0 * G), rel=0.01, abs=1e-6)


def test_a_prismatic_spring_between_two_bodies_pulls_them_back_to_their_offset():
    # no gravity: two boxes of mass 1 on a horizontal slider with a spring, pulled 0.25 apart
    # beyond where they were made: they oscillate about it at f, the centre of mass still
    s = soft(gravity=0.0)
    a = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(box(0.25, 0.25)))
    b = s.spawn(Transform(1.0, 0.0), Velocity(), Hitbox(box(0.25, 0.25)))
    s.spawn(PrismaticJoint(a, b, (0.0, 0.0), axis=(1.0, 0.0), hertz=1.0))
    s.get(a, Transform).x = -0.25
    ts, gaps = [], []
    for k in range(64 * 4):
        s.step(DT)
        ts.append((k + 1) * DT)
        gaps.append(pose(s, b)[0] - pose(s, a)[0] - 1.0)
        assert abs(pose(s, a)[0] + pose(s, b)[0] - 0.75) < 1e-9  # the centre of mass stays
    # the spring's mass is the slider's axial mass: 1 / (1/m_a + 1/m_b) = 1/2, so it runs at f
    assert period(ts, gaps) == pytest.approx(1.0, rel=period_tolerance(1.0))


# --- the motor joint --------------------------------------------------------------------------


def test_a_motor_joint_drags_a_box_to_its_offset_and_holds_it_there():
    # no gravity: a box of mass 2 driven from the origin to (3, 1) and a turn of 1, with at most
    # a force of 200 and a torque of 10: it gets there (past it first: the joint asks for the
    # velocity that closes 0.3 of the gap a sub-step, and brakes only as it nears it), settles,
    # stays, and never pulls harder than its most
    s = soft(gravity=0.0)
    body = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(box(0.5, 0.5), mass=2.0))
    j = s.spawn(MotorJoint(body, None, linear_offset=(3.0, 1.0), angular_offset=1.0, max_force=200.0,
                           max_torque=10.0))
    for _ in range(64 * 4):
        s.step(DT)
        force, torque = s.joint_reaction(j)
        assert math.hypot(*force) <= 200.0 * (1 + 1e-12) and abs(torque) <= 10.0 * (1 + 1e-12)
    x, y, r = pose(s, body)
    assert (x, y, r) == pytest.approx((3.0, 1.0, 1.0), abs=1e-9)
    v = s.get(body, Velocity)
    assert (v.x, v.y, v.angular) == pytest.approx((0.0, 0.0, 0.0), abs=1e-9)


@pytest.mark.parametrize("weights, lifts", [(1.25, True), (0.75, False)])
def test_a_motor_joint_lifts_a_box_only_with_more_force_than_its_weight(weights, lifts):
    # a box of mass 2 (weight 16) on the ground, driven 1 up: a most force above its weight lifts
    # it to the target and holds it there with its weight; below, it stays on the ground, the
    # joint pulling with all it has
    s = soft()
    s.spawn(Transform(0.0, -0.75), Hitbox(AABB(20.0, 0.5), body="static"))  # (its top at -0.5)
    body = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(box(0.5, 0.5), mass=2.0))
    j = s.spawn(MotorJoint(body, None, linear_offset=(0.0, 1.0), max_force=weights * 2.0 * G, max_torque=10.0))
    ys = []
    for _ in range(64 * 6):
        s.step(DT)
        ys.append(pose(s, body)[1])
        assert math.hypot(*s.joint_reaction(j).force) <= weights * 2.0 * G * (1 + 1e-12)
    force = s.joint_reaction(j).force
    if lifts:
        assert max(ys) > 1.0
        assert ys[-1] == pytest.approx(1.0, abs=1e-6)
        assert force == pytest.approx((0.0, 2.0 * G), rel=1e-6, abs=1e-9)
    else:
        assert max(ys) < SLOP and ys[-1] == pytest.approx(0.0, abs=SLOP)  # on the ground
        assert force == pytest.approx((0.0, weights * 2.0 * G), rel=1e-9, abs=1e-9)


@pytest.mark.parametrize("most", [200.0, 20000.0])
def test_a_motor_joints_offset_is_in_its_b_frame_and_follows_a_path(most):
    # a platform of mass 4 driven relative to a static post turned a quarter turn: linear_offset
    # (2, 0) of the post's frame is 2 above it, angular_offset -pi/2 keeps it level; then the
    # offset moved a little every step, along a circle, and the platform follows it
    s = soft()
    post = s.spawn(Transform(1.0, 1.0, math.pi / 2), Hitbox(AABB(0.25, 0.25), body="static"))
    platform = s.spawn(Transform(1.0, 2.0), Velocity(), Hitbox(box(1.0, 0.125), mass=4.0))
    j = s.spawn(MotorJoint(platform, post, linear_offset=(2.0, 0.0), angular_offset=-math.pi / 2, max_force=most,
                           max_torque=50.0))
    for _ in range(64 * 2):  # (it gets there in about a second, swinging past it twice at 200)
        s.step(DT)
    x, y, r = pose(s, platform)
    assert (x, y, r) == pytest.approx((1.0, 3.0, 0.0), abs=1e-6)  # 2 along the post's x: up
    motor = s.get(j, MotorJoint)
    lags = []
    for k in range(1, 64 * 4 + 1):  # the offset along a circle of 1 about (2, 1), once in 2 s
        a = math.pi * k * DT
        motor.linear_offset = (2.0 + math.sin(a), 1.0 - math.cos(a))
        s.step(DT)
        ox, oy = motor.linear_offset
        x, y, _r = pose(s, platform)
        lags.append(math.hypot(x - (1.0 - oy), y - (1.0 + ox)))  # from the target, in the world
        assert math.hypot(*s.joint_reaction(j).force) <= most * (1 + 1e-12)
    assert abs(pose(s, platform)[2]) < 1e-6
    step = math.pi * DT  # how far the target moves a step
    if most > 1000.0:
        # not held back by its force: each sub-step closes 0.3 of the gap (correction_factor), so
        # on the second lap the gap g after a step is 0.7^4 (g + step): g = step 0.7^4 / (1 - 0.7^4)
        steady = step * 0.7 ** 4 / (1.0 - 0.7 ** 4)
        assert min(lags[64 * 2:]) == pytest.approx(steady, rel=0.01)
        assert max(lags[64 * 2:]) == pytest.approx(steady, rel=0.01)
    else:  # at 200 it cannot close that much each step (it pulls with all it has): it falls behind
        assert step * 0.7 ** 4 / (1.0 - 0.7 ** 4) < max(lags[64 * 2:]) < step


def test_a_motor_joint_between_two_bodies_pushes_both_and_keeps_their_centre_of_mass():
    # no gravity: a (mass 1) driven to 2 right of b (mass 3), 3 apart at first: they close in on
    # each other, a three times as far (0.75 and 0.25), and the centre of mass stays where it was
    s = soft(gravity=0.0)
    a = s.spawn(Transform(3.0, 0.0), Velocity(), Hitbox(box(0.25, 0.25), mass=1.0))
    b = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(box(0.25, 0.25), mass=3.0))
    s.spawn(MotorJoint(a, b, linear_offset=(2.0, 0.0), angular_offset=0.0, max_force=500.0, max_torque=50.0))
    for _ in range(64 * 2):
        s.step(DT)
        assert (pose(s, a)[0] + 3.0 * pose(s, b)[0]) / 4.0 == pytest.approx(0.75, abs=1e-9)
    assert pose(s, a) == pytest.approx((2.25, 0.0, 0.0), abs=1e-6)  # (a - b = 2, a + 3 b = 3)
    assert pose(s, b) == pytest.approx((0.25, 0.0, 0.0), abs=1e-6)


def test_a_motor_joint_turns_the_short_way():
    # angular_offset 2 pi is the turn it already has: nothing turns; 2 pi - 0.25 turns it by -0.25
    s = soft(gravity=0.0)
    body = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(box(0.5, 0.5)))
    j = s.spawn(MotorJoint(body, None, angular_offset=2.0 * math.pi, max_force=10.0, max_torque=10.0))
    assert s.get(j, MotorJoint).linear_offset == (0.0, 0.0)  # measured: where it is
    for _ in range(16):
        s.step(DT)
    assert pose(s, body) == (0.0, 0.0, 0.0)
    s.get(j, MotorJoint).angular_offset = 2.0 * math.pi - 0.25
    for _ in range(64 * 2):
        s.step(DT)
    assert pose(s, body)[2] == pytest.approx(-0.25, abs=1e-9)


def test_a_motor_joint_measures_what_is_not_given():
    s = soft(gravity=0.0)
    base = s.spawn(Transform(1.0, 0.0, math.pi / 2), Velocity(), Hitbox(box(0.5, 0.5)))
    body = s.spawn(Transform(1.0, 2.0, 0.5), Velocity(), Hitbox(box(0.5, 0.5)))
    j = s.get(s.spawn(MotorJoint(body, base)), MotorJoint)
    assert j.linear_offset == pytest.approx((2.0, 0.0), abs=1e-15)  # 2 up: along the base's x
    assert j.angular_offset == pytest.approx(0.5 - math.pi / 2, abs=1e-15)
    for _ in range(32):
        s.step(DT)
    assert pose(s, body) == pytest.approx((1.0, 2.0, 0.5), abs=1e-12)  # held where it was


@pytest.mark.parametrize("limit, breaks", [(1.5, True), (3.0, False)])
def test_a_motor_joint_breaks_above_its_force(limit, breaks):
    # lifting a box of weight 16 with at most twice its weight: it pulls with 32 at first
    s = soft()
    body = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(box(0.5, 0.5), mass=2.0))
    j = s.spawn(MotorJoint(body, None, linear_offset=(0.0, 2.0), max_force=2 * 16.0, break_force=limit * 16.0))
    broke = []
    for _ in range(32):
        s.step(DT)
        broke += s.broken_joints
    assert bool(broke) == breaks
    if breaks:
        (b,) = broke
        assert (b.entity, b.a, b.b, type(b.joint)) == (j, body, None, MotorJoint)
        assert math.hypot(*b.force) == pytest.approx(32.0, rel=1e-9) and not s.exists(j)


def test_a_sleeping_body_wakes_when_its_motor_joints_target_moves():
    s = soft()
    s.spawn(Transform(0.0, -0.75), Hitbox(AABB(20.0, 0.5), body="static"))
    body = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(box(0.5, 0.5), mass=2.0))
    j = s.spawn(MotorJoint(body, None, max_force=100.0, max_torque=10.0))  # holds it where it is
    for _ in range(64 * 3):
        s.step(DT)
    assert s.store.asleep[s.store.row_of[body]]
    s.get(j, MotorJoint).linear_offset = (0.0, 1.0)
    for _ in range(64 * 2):
        s.step(DT)
    assert pose(s, body)[1] == pytest.approx(1.0, abs=1e-6)


# --- validation -------------------------------------------------------------------------------


@pytest.mark.parametrize("make, field", [
    (lambda a, b: RevoluteJoint(a, b, (0.5, 0.0), hertz=-1.0), "hertz"),
    (lambda a, b: RevoluteJoint(a, b, (0.5, 0.0), hertz=math.nan), "hertz"),
    (lambda a, b: RevoluteJoint(a, b, (0.5, 0.0), hertz=math.inf), "hertz"),
    (lambda a, b: RevoluteJoint(a, b, (0.5, 0.0), hertz=1.0, damping=-0.5), "damping"),
    (lambda a, b: RevoluteJoint(a, b, (0.5, 0.0), hertz=1.0, damping="some"), "damping"),
    (lambda a, b: PrismaticJoint(a, b, (0.5, 0.0), hertz=-1.0), "hertz"),
    (lambda a, b: PrismaticJoint(a, b, (0.5, 0.0), hertz=True), "hertz"),
    (lambda a, b: PrismaticJoint(a, b, (0.5, 0.0), damping=math.inf), "damping"),
    (lambda a, b: MotorJoint(a, b, max_force=-1.0), "max_force"),
    (lambda a, b: MotorJoint(a, b, max_force=math.nan), "max_force"),
    (lambda a, b: MotorJoint(a, b, max_torque=-1.0), "max_torque"),
    (lambda a, b: MotorJoint(a, b, correction_factor=1.5), "correction_factor"),
    (lambda a, b: MotorJoint(a, b, correction_factor=-0.1), "correction_factor"),
    (lambda a, b: MotorJoint(a, b, correction_factor=math.nan), "correction_factor"),
    (lambda a, b: MotorJoint(a, b, linear_offset=(math.nan, 0.0)), "linear_offset"),
    (lambda a, b: MotorJoint(a, b, linear_offset=3.0), "linear_offset"),
    (lambda a, b: MotorJoint(a, b, angular_offset=math.inf), "angular_offset"),
    (lambda a, b: MotorJoint(a, a), "itself"),
    (lambda a, b: MotorJoint(a, 999), "999"),
])
def test_a_bad_spring_or_motor_joint_is_refused_and_the_scene_is_unchanged(make, field):
    s = soft()
    a = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(Circle(0.25)))
    b = s.spawn(Transform(1.0, 0.0), Velocity(), Hitbox(Circle(0.25)))
    before = s.entities
    with pytest.raises(InvalidValue, match=field):
        s.spawn(make(a, b))
    assert s.entities == before
    assert esper.get_component(RevoluteJoint) == [] and esper.get_component(MotorJoint) == []


@pytest.mark.parametrize("cls, field, bad", [
    (RevoluteJoint, "hertz", -2.0), (RevoluteJoint, "damping", math.nan), (PrismaticJoint, "hertz", math.inf),
    (PrismaticJoint, "damping", -1.0), (MotorJoint, "max_force", -3.0), (MotorJoint, "correction_factor", 2.0),
    (MotorJoint, "linear_offset", (0.0, math.nan)), (MotorJoint, "angular_offset", math.nan),
])
def test_a_bad_value_written_later_is_refused_before_the_step_changes_anything(cls, field, bad):
    s = soft()
    a = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(box(0.25, 0.25)))
    j = s.spawn(MotorJoint(a, None, max_force=100.0) if cls is MotorJoint else cls(a, None, (0.0, 0.0), hertz=1.0))
    s.step(DT)
    before = (s.frame, pose(s, a))
    setattr(s.get(j, cls), field, bad)
    with pytest.raises(InvalidValue, match=f"entity {j}.*{field}"):
        s.step(DT)
    assert (s.frame, pose(s, a)) == before


# --- snapshots ----------------------------------------------------------------------------------


def machine() -> tuple[Scene, list[int]]:
    """A sprung bar, a sprung slider carrying a ball on a rope, and a box a motor joint drives."""
    s = soft()
    bar, _j = sprung_bar(s, hertz=2.0, damping=0.1)
    slider = s.spawn(Transform(3.0, 0.0), Velocity(), Hitbox(box(0.25, 0.25)))
    s.spawn(PrismaticJoint(slider, None, (3.0, 0.0), axis=(1.0, 1.0), hertz=1.5, damping=0.05, lower=-1.0))
    ball = s.spawn(Transform(3.0, -1.0), Velocity(), Hitbox(Circle(0.125)))
    s.spawn(DistanceJoint(ball, slider))
    crate = s.spawn(Transform(-3.0, 0.0), Velocity(), Hitbox(box(0.5, 0.5), mass=2.0))
    s.spawn(MotorJoint(crate, bar, linear_offset=(-2.0, 1.0), angular_offset=0.5, max_force=30.0, max_torque=5.0))
    return s, [bar, slider, ball, crate]


def state(s: Scene, es: list[int]) -> tuple[float, ...]:
    return tuple(v for e in es for v in (*pose(s, e), *s.get(e, Velocity)._values()))


def test_springs_and_motor_joints_survive_a_snapshot_bit_for_bit(tmp_path):
    s, es = machine()
    for _ in range(40):
        s.step(DT)
    snap = s.snapshot()
    save_snapshot(s, tmp_path / "machine.snap")
    for _ in range(40):
        s.step(DT)
    expected = state(s, es)
    assert len(set(expected)) > 10  # (things moved)
    s.restore(snap)
    for _ in range(40):
        s.step(DT)
    assert state(s, es) == expected
    load_snapshot(s, tmp_path / "machine.snap")
    for _ in range(40):
        s.step(DT)
    assert state(s, es) == expected
