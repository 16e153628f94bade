"""The physics sandbox (examples/sandbox): its car climbs the slope, the mouse drags bodies, and
the command runs headless and refuses to run an invisible window.

The controls are plain functions on world points and key names, so these tests drive them as the
window's handlers do, without a window: ``grab`` / ``drag_to`` / ``release`` for the mouse, the
scene's ``Input`` (read by ``drive_system``) for the keys.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys

import pytest
from example_commands import ROOT, child_env, commands

from examples.sandbox import (
    CAR,
    DRAG_STRENGTH,
    GRAVITY,
    SLOPE,
    drag_to,
    drive,
    drive_system,
    grab,
    joint_count,
    make_sandbox,
    release,
    slope_height,
)
from examples.sandbox.world import DT
from framework import Hitbox, Input, MouseJoint, Transform, Velocity, WheelJoint

JOINTS = 9 + 2  # the rope's nine hinges (eight links and the weight) and the car's two wheels


@pytest.fixture
def sandbox():
    with make_sandbox() as sb:
        sb.scene.add_system(drive_system(sb), before="movement")
        yield sb


def steps(sb, n: int) -> None:
    for _ in range(n):
        sb.scene.step(DT)


def world_point(t: Transform, local: tuple[float, float]) -> tuple[float, float]:
    c, s = math.cos(t.rotation), math.sin(t.rotation)
    return t.x + c * local[0] - s * local[1], t.y + s * local[0] + c * local[1]


# --- the car ----------------------------------------------------------------------------------------


def test_the_car_driven_right_climbs_the_slope_on_its_wheels_upright(sandbox):
    scene = sandbox.scene
    steps(sandbox, 30)  # settle on the suspension
    x0 = scene.get(sandbox.chassis, Transform).x
    assert x0 < SLOPE.x0 - CAR.width  # it starts on the flat, short of the slope
    scene.resources[Input].set_held({"right"})
    seconds = 2.5
    worst_gap, worst_tilt = 0.0, 0.0
    for _ in range(round(seconds / DT)):
        scene.step(DT)
        worst_gap = max(worst_gap, *sandbox.wheel_gaps())
        worst_tilt = max(worst_tilt, abs(scene.get(sandbox.chassis, Transform).rotation))
    t = scene.get(sandbox.chassis, Transform)
    # The wheels roll at the motor's speed omega, so the car goes at most omega r along the ground.
    # Torque-limited, it reaches that speed no later than at the slope's least acceleration a
    # (the two motors' push less the weight's pull down the slope, over the car's mass and its
    # wheels' inertia, m + 2 I / r^2): it loses at most v^2 / 2a of the distance; 90% of the rest,
    # along the slope's cosine, is the margin (the suspension's bounce when it meets the slope).
    r, omega, theta = CAR.wheel_radius, CAR.speed, SLOPE.angle
    mass = CAR.chassis_mass + 2 * CAR.wheel_mass
    v = omega * r
    a = (2 * CAR.torque / r - mass * GRAVITY * math.sin(theta)) / (mass + 2 * 0.5 * CAR.wheel_mass)
    least = 0.9 * math.cos(theta) * (v * seconds - v * v / (2 * a))
    assert least < t.x - x0 <= v * seconds
    assert SLOPE.x0 < t.x < SLOPE.x1  # on the ramp, up it
    assert t.y - slope_height(t.x) == pytest.approx(0.875, abs=0.05)  # riding on its wheels, not dragged
    assert t.y > 1.0 + SLOPE.height * 0.25
    assert worst_gap < 0.01  # both wheels on the ground the whole way (no wheelie, no hop)
    assert worst_tilt < theta + math.radians(3)  # never pitched more than 3 degrees past the slope
    assert abs(t.rotation - theta) < math.radians(2)  # along the slope
    for w in sandbox.wheels:
        assert scene.get(w, Velocity).angular == pytest.approx(-omega, rel=0.05)


def test_the_car_parks_on_the_slope_when_no_key_is_held(sandbox):
    scene = sandbox.scene
    scene.resources[Input].set_held({"right"})
    steps(sandbox, 120)
    scene.resources[Input].set_held(())
    steps(sandbox, 60)  # braking to a stop
    x = scene.get(sandbox.chassis, Transform).x
    assert SLOPE.x0 < x < SLOPE.x1
    steps(sandbox, 120)
    assert scene.get(sandbox.chassis, Transform).x == pytest.approx(x, abs=0.01)  # the brake holds it


def test_the_keys_set_both_motors():
    with make_sandbox() as sb:
        motors = [sb.scene.get(j, WheelJoint) for j in sb.motors]
        for held, direction in ((["right"], 1), (["d"], 1), (["left"], -1), (["a"], -1), ([], 0),
                                (["left", "right"], 0), (["space"], 0)):
            assert drive(sb, held) == direction
            for m in motors:
                assert m.motor_speed == -direction * CAR.speed  # clockwise rolls right
                assert m.max_motor_torque == (CAR.torque if direction else CAR.brake_torque)


# --- the mouse --------------------------------------------------------------------------------------


def test_a_drag_brings_the_grabbed_point_of_a_crate_to_the_cursor_and_letting_go_drops_it(sandbox):
    scene = sandbox.scene
    crate = sandbox.crates[2]  # the lone one
    steps(sandbox, 30)  # (asleep by now: the grab must wake it)
    before = joint_count(sandbox)
    assert before == JOINTS
    t = scene.get(crate, Transform)
    local = (0.25, 0.25)  # off its centre (the crate swings about it: the point stays put)
    start = world_point(t, local)
    joint = grab(sandbox, start)
    assert joint is not None and sandbox.drag == joint and joint_count(sandbox) == before + 1
    mouse = scene.get(joint, MouseJoint)
    assert mouse.body == crate
    assert mouse.max_force == pytest.approx(DRAG_STRENGTH * scene.get(crate, Hitbox).mass * GRAVITY)
    target = (start[0] + 1.0, start[1] + 3.0)
    for k in range(1, 121):  # the cursor moves up and right over a second, then holds still
        f = min(k / 60, 1.0)
        drag_to(sandbox, (start[0] + f * (target[0] - start[0]), start[1] + f * (target[1] - start[1])))
        scene.step(DT)
    assert mouse.target == target
    # At rest, the spring (hertz f: stiffness m (2 pi f)^2) carries the crate's weight m g, the
    # point sagging g / (2 pi f)^2 below the cursor.
    sag = GRAVITY / (2 * math.pi * mouse.hertz) ** 2
    px, py = world_point(scene.get(crate, Transform), local)
    assert px == pytest.approx(target[0], abs=1e-3)
    assert py == pytest.approx(target[1] - sag, abs=1e-3)
    release(sandbox)
    assert sandbox.drag is None and not scene.exists(joint)
    assert joint_count(sandbox) == before
    steps(sandbox, 90)  # it falls back to the ground (once let go, even if it slept in the grip)
    assert scene.get(crate, Transform).y == pytest.approx(0.5, abs=0.02)
    release(sandbox)  # again: nothing to let go of
    assert joint_count(sandbox) == before


@pytest.mark.parametrize("where", ["ground", "slope", "wall", "hook", "air"])
def test_pressing_on_a_static_body_or_nothing_drags_nothing(sandbox, where):
    scene = sandbox.scene
    point = {"ground": (-6.0, -0.5), "slope": (SLOPE.x1 - 0.5, 1.0), "wall": (-18.5, 5.0), "hook": (-8.1, 8.1),
             "air": (0.0, 15.0)}[where]
    before = joint_count(sandbox)
    poses = {e: (scene.get(e, Transform).x, scene.get(e, Transform).y) for e in sandbox.ground + sandbox.statics}
    assert grab(sandbox, point) is None
    assert sandbox.drag is None and joint_count(sandbox) == before
    drag_to(sandbox, (point[0] + 5.0, point[1] + 5.0))  # moving and letting go do nothing either
    steps(sandbox, 10)
    release(sandbox)
    assert joint_count(sandbox) == before
    assert poses == {e: (scene.get(e, Transform).x, scene.get(e, Transform).y) for e in poses}


def test_grabbing_again_lets_go_of_the_first_body(sandbox):
    first = grab(sandbox, (-12.5, 0.5))
    second = grab(sandbox, (-10.0, 0.45))  # a barrel
    assert first is not None and second is not None
    assert not sandbox.scene.exists(first) and sandbox.drag == second
    assert sandbox.scene.get(second, MouseJoint).body == sandbox.barrels[0]
    assert joint_count(sandbox) == JOINTS + 1


def test_the_windows_mouse_handlers_drag_what_is_under_the_cursor(render):
    # The window's own events (pyglet's, in screen pixels) through the handlers the command
    # installs: a press over the lone crate grabs it, a drag moves the target to the world point
    # under the cursor, the release lets go; a press over the ground grabs nothing.
    from pyglet.window import mouse

    from examples.sandbox.__main__ import open_window, parse_args

    with make_sandbox() as sb:
        runner, drags = open_window(sb, parse_args([]))
        try:
            camera = runner.renderer.camera

            def event(*args) -> None:  # queued by the window, handled as its event loop does
                runner.window.dispatch_event(*args)
                runner.window.dispatch_events()

            t = sb.scene.get(sb.crates[2], Transform)
            x, y = camera.world_to_screen(t.x, t.y)
            event("on_mouse_press", x, y, mouse.LEFT, 0)
            assert drags == [sb.drag] and sb.scene.get(sb.drag, MouseJoint).body == sb.crates[2]
            event("on_mouse_drag", x + 50, y + 100, 50, 100, mouse.LEFT, 0)
            assert sb.scene.get(sb.drag, MouseJoint).target == pytest.approx(camera.screen_to_world(x + 50, y + 100))
            assert sb.scene.get(sb.drag, MouseJoint).target == pytest.approx((t.x + 50 / camera.zoom,
                                                                              t.y + 100 / camera.zoom), abs=0.05)
            event("on_mouse_release", x + 50, y + 100, mouse.LEFT, 0)
            assert sb.drag is None and joint_count(sb) == JOINTS
            event("on_mouse_press", *camera.world_to_screen(-6.0, -0.5), mouse.LEFT, 0)
            assert sb.drag is None and len(drags) == 1
        finally:
            runner.close()


# --- the command ------------------------------------------------------------------------------------

COMMANDS = commands("sandbox")


def test_the_headless_demo_drives_drags_and_prints_its_summary():
    out = subprocess.run([*COMMANDS["examples.sandbox"], "--headless", "--demo"], cwd=ROOT, env=child_env({}),
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    summary = json.loads(out.stdout.strip().splitlines()[-1])
    assert summary["frames"] == 360 and summary["drags"] == 1
    assert summary["joints"] == JOINTS  # the drag's joint is gone again
    assert SLOPE.x0 < summary["car_x"] < SLOPE.x1 and summary["wheels_on_ground"] is True  # parked on the slope
    assert abs(summary["car_angle"] - math.degrees(SLOPE.angle)) < 2.0
    assert summary["lifted"] == pytest.approx(0.5 + 4.0 - GRAVITY / (2 * math.pi * 5.0) ** 2, abs=0.01)


@pytest.mark.parametrize("module", list(COMMANDS))
def test_the_headless_steps_option(module):
    out = subprocess.run([*COMMANDS[module], "--headless", "--steps", "3"], cwd=ROOT, env=child_env({}),
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    summary = json.loads(out.stdout.strip().splitlines()[-1])
    assert summary["frames"] == 3 and summary["drags"] == 0 and summary["lifted"] is None
    assert summary["joints"] == JOINTS and summary["car_x"] == CAR.x


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="DISPLAY / WAYLAND_DISPLAY are Linux's")
@pytest.mark.parametrize("display", [{}, {"DISPLAY": ":987"}], ids=["no display", "a display that fails to open"])
@pytest.mark.parametrize("module", list(COMMANDS))
def test_without_a_display_it_says_so_in_one_line_and_exits_1(module, display):
    out = subprocess.run(COMMANDS[module], cwd=ROOT, env=child_env(display), capture_output=True, text=True, timeout=60)
    assert out.returncode == 1, (out.returncode, out.stdout, out.stderr)
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1, out.stderr  # one line, no traceback
    (line,) = lines
    assert line.startswith("error: ") and "display" in line, line
    assert f"python -m {module} --headless --demo" in line and "set DISPLAY" in line, line
    assert ("neither DISPLAY nor WAYLAND_DISPLAY is set" if not display else "':987'") in line, line
    assert out.stdout == ""
