"""framework.testing: the toolkit a game's headless tests use, and its pytest plugin."""

from __future__ import annotations

import json
import math
import os

import pytest
from hypothesis import given, settings

from framework import AABB, Circle, Hitbox, InvalidValue, Scene, Transform, Velocity
from framework.character import CharacterController
from framework.input import Input
from framework.testing import (
    EventLog,
    GoldenMismatch,
    KeyScript,
    assert_at_rest,
    assert_inside,
    assert_no_overlap,
    assert_on_floor,
    bounds,
    check_golden,
    feet,
    run,
    step_until,
    text_scene,
)
from framework.testing.strategies import shapes, small_scenes, transforms

pytest_plugins = ["pytester"]


class Coin:
    pass


class Player:
    pass


def spawn_coin(scene, x, y, tile):
    return scene.spawn(Transform(x, y), Hitbox(Circle(0.25 * tile), body="static", sensor=True), Coin())


def spawn_ball(scene, x, y, tile):
    return scene.spawn(Transform(x, y), Velocity(), Hitbox(Circle(0.5 * tile)), Player())


LEVEL = """
    #........#
    #.O..C...#
    ##########
"""


# --- running ---------------------------------------------------------------------------------------


def test_run_steps_and_seconds():
    s = Scene()
    assert run(s, 10) == 10 and run(s, seconds=0.5) == 40 and run(s, 0) == 40
    for bad, match in (({"steps": None}, "needs a bound"), ({"steps": -1}, "steps must be"),
                       ({"steps": 3, "seconds": 1.0}, "not both"), ({"seconds": float("nan")}, "seconds")):
        with pytest.raises(InvalidValue, match=match):
            run(s, **bad)
    s.close()


def test_step_until_returns_the_step_and_says_what_it_last_saw():
    level = text_scene(LEVEL, {"O": spawn_ball, "C": spawn_coin})
    s, ball = level.scene, level.first("O")
    s.get(ball, Velocity).x = 3.0
    took = step_until(s, lambda sc: sc.get(ball, Transform).x > 5.0, within=120)
    assert 0 < took <= 120 and s.get(ball, Transform).x > 5.0
    assert step_until(s, lambda sc: True, within=5) == 0
    with pytest.raises(AssertionError, match=r"ball_reaches_the_moon did not happen within 30 steps .*last seen: "
                                             r"frame \d+; bodies: \d+ at \("):
        def ball_reaches_the_moon(sc):
            return sc.get(ball, Transform).y > 1e6

        step_until(s, ball_reaches_the_moon, within=30)
    with pytest.raises(InvalidValue, match="step_until needs a bound"):
        step_until(s, lambda sc: False)
    s.close()


def test_key_scripts_hold_and_press_through_input():
    script = KeyScript().hold("right", 0, 5).press("space", 2).press("down", 3, frames=3)
    assert [sorted(script.keys_at(f)) for f in range(7)] == [
        ["right"], ["right"], ["right", "space"], ["down", "right"], ["down", "right"], ["down"], []]
    s = Scene()
    seen = []
    s.add_system(lambda sc, dt: seen.append(sorted(sc.resources[Input].held)), before="movement")
    run(s, 7, keys=script)
    assert seen == [sorted(script.keys_at(f)) for f in range(7)]
    run(s, 2, keys={"left"})
    assert seen[-2:] == [["left"], ["left"]]
    for bad in (lambda: KeyScript().hold("x", 5, 2), lambda: KeyScript().press("x", -1),
                lambda: KeyScript().press("x", 0, frames=0), lambda: KeyScript().hold("", 0)):
        with pytest.raises(InvalidValue):
            bad()
    s.close()


# --- text levels ------------------------------------------------------------------------------------


def test_text_scenes_spawn_terrain_and_legend_things():
    level = text_scene("""
        #.........#
        #..C..O...#
        #..../##\\.#
        ###########
    """, {"C": spawn_coin, "O": spawn_ball}, tile=2.0)
    assert (level.width, level.height, level.tile) == (11, 4, 2.0)
    assert level.where("C") == [(7.0, 5.0)] and len(level.entities["O"]) == 1
    assert len(level.terrain) > 0 and level.scene.gravity == (0.0, -40.0)
    run(level.scene, 120)
    assert_no_overlap(level.scene, deeper_than=1e-6)
    level.scene.close()


def test_an_unknown_symbol_is_named_with_its_place():
    with pytest.raises(InvalidValue, match=r"unknown character 'Z' at line 2, column 3 .*add it to the legend"):
        text_scene("#..#\n#.Z#\n####")
    with pytest.raises(InvalidValue, match="neither a terrain kind"):
        text_scene("#", {"#": "lava"})
    with pytest.raises(InvalidValue, match="empty"):
        text_scene("\n\n")


# --- events ------------------------------------------------------------------------------------------


def test_event_log_sees_a_coin_pickup_and_says_what_happened_when_an_assertion_fails():
    level = text_scene(LEVEL, {"O": spawn_ball, "C": spawn_coin})
    s = level.scene
    log = EventLog(s)
    s.get(level.first("O"), Velocity).x = 4.0
    run(s, 90)
    first = log.assert_started(Player, Coin, within=90)
    assert first.a in (level.first("O"), level.first("C")) and 1 <= first.frame <= 90
    assert log.between(level.first("O"), Coin, "ended")
    log.assert_never(Coin, Coin)
    with pytest.raises(AssertionError, match=r"'started' event\(s\) between Player and Coin, the first at step \d+"):
        log.assert_never(Player, Coin)
    with pytest.raises(AssertionError, match=r"no 'started' event between Coin and entity 1 within 1 steps; "
                                             r"what happened: step \d+: started"):
        log.assert_started(Coin, 1, within=1)
    s.close()


# --- physics assertions ----------------------------------------------------------------------------


def test_physics_assertions_pass_and_fail_readably():
    level = text_scene(LEVEL, {"O": spawn_ball, "C": spawn_coin})
    s, ball = level.scene, level.first("O")
    run(s, 120)
    assert_at_rest(s, ball, speed=1e-6)
    assert_on_floor(s, ball)
    assert_inside(s, ball, (1.0, 0.5, 9.0, 3.0))
    assert_no_overlap(s, deeper_than=1e-6)
    s.get(ball, Velocity).x = 2.5
    with pytest.raises(AssertionError, match=rf"entity {ball} is not at rest at step 120: velocity \(2.5, 0\)"):
        assert_at_rest(s, ball)
    with pytest.raises(AssertionError, match=rf"entity {ball} is not inside .* it spans \(2, 1\)"):
        assert_inside(s, ball, (2.25, 0.0, 9.0, 3.0))
    s.get(ball, Transform).y = 5.0
    with pytest.raises(AssertionError, match=rf"entity {ball} is not on a floor at step 120: at \(2.5, 5\), nothing"):
        assert_on_floor(s, ball)
    s.get(ball, Transform).y = 1.25  # half a unit into the ground
    with pytest.raises(AssertionError, match=r"1 pair\(s\) overlap deeper than 0 at step 120; the deepest: entities "):
        assert_no_overlap(s)
    s.close()


def test_bounds_and_feet_measure_where_an_entity_is():
    level = text_scene(LEVEL, {"O": spawn_ball, "C": spawn_coin})
    s, ball = level.scene, level.first("O")
    assert bounds(s, ball) == (2.0, 1.0, 3.0, 2.0) and feet(s, ball) == 1.0  # a circle of radius 1/2 at (2.5, 1.5)
    box = s.spawn(Transform(6.0, 2.5, 0.5), Velocity(0.0, 1.0), Hitbox(AABB(1.0, 0.5), offset=(0.0, 0.25)))
    s.step(1 / 64)
    # Exact, as the shape and the pose give it: the box's bottom is y - 1/4 to the bit (its offset
    # turns with it: by 0.5 rad the box's centre moves (-0.25 sin 0.5, 0.25 cos 0.5) off its position).
    t = s.get(box, Transform)
    hx, hy = t.x - 0.25 * math.sin(0.5), t.y + 0.25 * math.cos(0.5)
    assert bounds(s, box) == (hx - 0.5, hy - 0.25, hx + 0.5, hy + 0.25) and feet(s, box) == hy - 0.25
    s.get(ball, Transform).x = 4.25  # moved by hand: measured where it is now
    assert bounds(s, ball)[:3] == (3.75, 1.0, 4.75)
    point = s.spawn(Transform(2.5, 3.0))
    assert bounds(s, point) == (2.5, 3.0, 2.5, 3.0) and feet(s, point) == 3.0
    with pytest.raises(AssertionError, match="does not exist"):
        s.despawn(point)
        s.step(1 / 60)
        feet(s, point)
    s.close()


def test_on_floor_reads_a_character_controller():
    s = Scene(gravity=(0.0, -20.0))
    s.spawn(Transform(0.0, -0.5), Hitbox(AABB(10.0, 1.0), body="static"))
    e = s.spawn(Transform(0.0, 0.6), Velocity(), Hitbox(AABB(0.5, 1.0), body="kinematic"), CharacterController())
    run(s, 10)
    assert_on_floor(s, e)
    s.get(e, Velocity).y = 8.0
    run(s, 3)
    with pytest.raises(AssertionError, match=rf"entity {e} is not on a floor .* on a wall: False"):
        assert_on_floor(s, e)
    s.close()


# --- golden runs -----------------------------------------------------------------------------------


def _golden_scene(speed: float = 3.0) -> Scene:
    level = text_scene(LEVEL, {"O": spawn_ball, "C": spawn_coin})
    level.scene.get(level.first("O"), Velocity).x = speed
    return level.scene


@pytest.mark.slow
def test_golden_runs_record_then_compare_and_name_the_first_difference(tmp_path, monkeypatch):
    monkeypatch.delenv("FRAMEWORK_UPDATE_GOLDEN", raising=False)
    path = tmp_path / "golden" / "roll.json"
    with pytest.raises(AssertionError, match="no golden file .*update=True"):
        check_golden(_golden_scene(), path, 60)
    check_golden(_golden_scene(), path, 60, update=True)
    check_golden(_golden_scene(), path, 60)  # the same run: passes, bit for bit
    changed = _golden_scene(3.0 + 2.0**-20)
    with pytest.raises(GoldenMismatch, match=r"step 1 of 60 \(frame 1\) differs from the golden run: entity \d+ x: "
                                             r"golden .*, now ") as info:
        check_golden(changed, path, 60)
    assert info.value.step == 1 and info.value.snapshot.frame == 0
    check_golden(_golden_scene(3.0 + 2.0**-20), path, 60, atol=1e-4)  # within a tolerance
    monkeypatch.setenv("FRAMEWORK_UPDATE_GOLDEN", "1")
    check_golden(changed, path, 60)  # records the new behaviour
    monkeypatch.delenv("FRAMEWORK_UPDATE_GOLDEN")
    data = json.loads(path.read_text())
    data["framework"] = "0.0.1"
    path.write_text(json.dumps(data))
    with pytest.raises(InvalidValue, match="from another version .*rerun with update"):
        check_golden(_golden_scene(), path, 60)
    path.write_text("{not json")
    with pytest.raises(InvalidValue, match="not a golden trace"):
        check_golden(_golden_scene(), path, 60)


# --- strategies ----------------------------------------------------------------------------------


@pytest.mark.slow
@settings(max_examples=10, deadline=None)
@given(small_scenes(max_bodies=6))
def test_small_scenes_settle_without_sinking(scene):
    run(scene, 180)
    assert_no_overlap(scene, deeper_than=0.02)
    scene.close()


@settings(max_examples=30, deadline=None)
@given(shapes(), transforms())
def test_shapes_and_transforms_are_dyadic(shape, t):
    assert t.x * 8 == int(t.x * 8) and t.y * 8 == int(t.y * 8)
    assert shape.bounding_radius > 0


# --- the pytest plugin ---------------------------------------------------------------------------


GAME_TEST = """
from framework import AABB, Hitbox, Transform, Velocity
from framework.testing import run

def test_falls_through(scene):
    scene.gravity = (0.0, -10.0)
    scene.spawn(Transform(0.0, -0.5), Hitbox(AABB(10.0, 1.0), body="static"))
    box = scene.spawn(Transform(0.0, 3.0), Velocity(), Hitbox(AABB(1.0, 1.0)))
    run(scene, 60)
    assert scene.get(box, Transform).y < 0.0, "the box should have fallen through"

def test_passes(scene):
    run(scene, 2)
"""


@pytest.mark.slow
def test_the_plugin_pictures_a_failing_tests_scene(pytester):
    pytester.makepyfile(test_game=GAME_TEST)
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", "--framework-pictures", "pics")
    result.assert_outcomes(passed=1, failed=1)
    out = result.stdout.str()
    assert "framework picture" in out
    pictures = list((pytester.path / "pics").glob("*.png"))
    if pictures:
        assert len(pictures) == 1 and "test_falls_through" in pictures[0].name
        assert f"the scene at step 60, with hitboxes, contacts and velocities: {pictures[0]}" in out
        assert pictures[0].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    else:  # no GL on this machine: the report says why
        assert "no picture of scene 1 (step 60)" in out


@pytest.mark.slow
def test_the_plugin_can_be_told_not_to_picture(pytester):
    pytester.makepyfile(test_game=GAME_TEST)
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", "--no-framework-pictures",
                                           "--framework-pictures", "pics")
    result.assert_outcomes(passed=1, failed=1)
    assert "framework picture" not in result.stdout.str() and not (pytester.path / "pics").exists()


def test_scenes_a_test_makes_are_closed_after_it(pytester):
    pytester.makepyfile(test_made="""
from framework import Scene
made = []

def test_makes_one():
    made.append(Scene())

def test_it_was_closed():
    assert made[0].closed
""")
    pytester.runpytest("-p", "no:cacheprovider").assert_outcomes(passed=2)


def test_without_gl_the_report_says_why_there_is_no_picture(pytester, monkeypatch):
    import framework.testing.pictures

    def no_gl(scene, path, *args, **kwargs):  # what rendering does where no OpenGL context can be made
        raise RuntimeError("no EGL device (made up by this test)")

    monkeypatch.setattr(framework.testing.pictures, "picture", no_gl)
    pytester.makepyfile(test_game=GAME_TEST)
    result = pytester.runpytest("-p", "no:cacheprovider", "--framework-pictures", "pics")
    result.assert_outcomes(passed=1, failed=1)
    out = result.stdout.str()
    assert "framework picture" in out
    assert "no picture of scene 1 (step 60): RuntimeError: no EGL device (made up by this test)" in out
    assert "with hitboxes, contacts and velocities" not in out and not (pytester.path / "pics").exists()


GOLDEN_TEST = """
from framework import Circle, Hitbox, Transform, Velocity
from framework.testing import check_golden, text_scene

def spawn_ball(scene, x, y, tile):
    return scene.spawn(Transform(x, y), Velocity(SPEED, 0.0), Hitbox(Circle(0.4), restitution=0.5))

def test_roll(golden_dir):
    level = text_scene("#......#\\n#.O....#\\n########", {"O": spawn_ball})
    check_golden(level.scene, golden_dir / "roll.json", steps=90)
"""


@pytest.mark.slow
def test_the_update_golden_option_records_and_golden_dir_is_next_to_the_test(pytester, monkeypatch):
    monkeypatch.delenv("FRAMEWORK_UPDATE_GOLDEN", raising=False)

    def pytest_run(*args):  # in this process: no pictures (their GL objects would outlive the inner session)
        return pytester.runpytest("-p", "no:cacheprovider", "--no-framework-pictures", "tests", *args)

    pytester.mkdir("tests")
    test_file = pytester.path / "tests" / "test_ball.py"
    test_file.write_text("SPEED = 3.0\n" + GOLDEN_TEST)
    golden = pytester.path / "tests" / "golden" / "roll.json"
    first = pytest_run()
    first.assert_outcomes(failed=1)  # nothing recorded yet: a failure saying how to record it
    assert f"no golden file {golden}" in first.stdout.str() and "pytest --update-golden" in first.stdout.str()
    assert not golden.parent.exists()
    pytest_run("--update-golden").assert_outcomes(passed=1)
    assert golden.exists() and json.loads(golden.read_text())["steps"] == 90
    assert "FRAMEWORK_UPDATE_GOLDEN" not in os.environ  # the option lasts for its session only
    pytest_run().assert_outcomes(passed=1)  # compares: the same run passes
    test_file.write_text("SPEED = 3.25\n" + GOLDEN_TEST)
    changed = pytest_run()
    changed.assert_outcomes(failed=1)
    assert "step 1 of 90 (frame 1) differs from the golden run" in changed.stdout.str()
    pytest_run("--update-golden").assert_outcomes(passed=1)
    pytest_run().assert_outcomes(passed=1)  # the new behaviour, accepted
