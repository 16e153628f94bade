"""A failing toolkit assertion points at the game's test, not at the framework's source.

A game's test file runs under pytest in another process (the plugin as installed, the framework
of this checkout first on the path); its failure reports must show the test's own line and the
message, and no frame of ``framework/testing/``: the toolkit's helpers hide their frames from
pytest's tracebacks for assertion failures (``__tracebackhide__``). An exception raised by the
game's own system during a step is not a test's failure, and keeps its whole path.
"""

from __future__ import annotations

from pathlib import Path

import pytest

pytest_plugins = ["pytester"]

ROOT = Path(__file__).resolve().parents[1]

GAME_TEST = '''
from framework import AABB, Hitbox, Scene, Transform, Velocity
from framework.testing import EventLog, assert_at_rest, assert_inside, check_golden, step_until


class Ball:
    pass


def falling_ball():
    scene = Scene(gravity=(0.0, -10.0))
    ball = scene.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(AABB(1.0, 1.0)), Ball())
    return scene, ball


def test_step_until_runs_out():
    scene, ball = falling_ball()
    step_until(scene, lambda s: s.get(ball, Transform).y > 1.0, within=5, what="the ball rising")


def test_assert_at_rest_fails():
    scene, ball = falling_ball()
    scene.step(1 / 60)
    assert_at_rest(scene, ball)


def test_assert_inside_fails_for_a_despawned_entity():
    scene, ball = falling_ball()
    scene.despawn(ball)
    assert_inside(scene, ball, (0.0, 0.0, 1.0, 1.0))


def test_event_log_fails():
    scene, ball = falling_ball()
    EventLog(scene).assert_started(Ball, Ball)


def test_golden_mismatch(tmp_path):
    scene, ball = falling_ball()
    check_golden(scene, tmp_path / "run.json", steps=3, update=True)
    scene, ball = falling_ball()
    scene.get(ball, Velocity).x = 1.0
    check_golden(scene, tmp_path / "run.json", steps=3)


def test_a_system_that_raises_keeps_its_path():
    scene, ball = falling_ball()

    def broken_system(scene, dt):
        raise RuntimeError("the game's own bug")

    scene.add_system(broken_system)
    step_until(scene, lambda s: False, within=5)
'''

FAILURES = {  # the test, the line of the test the report points at, the message
    "test_step_until_runs_out": ("step_until(scene, lambda s: s.get(ball, Transform).y > 1.0",
                                 "AssertionError: the ball rising did not happen within 5 steps"),
    "test_assert_at_rest_fails": ("assert_at_rest(scene, ball)", "AssertionError: entity 1 is not at rest at step 1"),
    "test_assert_inside_fails_for_a_despawned_entity": ("assert_inside(scene, ball,",
                                                        "AssertionError: entity 1 does not exist at step 0"),
    "test_event_log_fails": ("EventLog(scene).assert_started(Ball, Ball)",
                             "AssertionError: no 'started' event between Ball and Ball"),
    "test_golden_mismatch": ('check_golden(scene, tmp_path / "run.json", steps=3)',
                             "differs from the golden run: entity 1 x"),
}


def _sections(out: str) -> dict[str, str]:
    """Each failing test's section of pytest's report (``____ test_name ____`` headers)."""
    parts: dict[str, str] = {}
    name = None
    for line in out.splitlines():
        if line.startswith("_") and line.rstrip().endswith("_") and " test_" in line:
            name = line.strip("_ ").strip()
            parts[name] = ""
        elif line.startswith("=") and name is not None and "short test summary" in line:
            name = None
        elif name is not None:
            parts[name] += line + "\n"
    return parts


@pytest.mark.slow
def test_failing_toolkit_assertions_show_the_test_and_not_the_framework(pytester, monkeypatch):
    monkeypatch.setenv("PYTHONPATH", str(ROOT))  # this checkout's framework, whatever is installed
    pytester.makepyfile(test_game=GAME_TEST)
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", "--no-framework-pictures")
    out = result.stdout.str()
    assert result.parseoutcomes() == {"failed": len(FAILURES) + 1}, out[-4000:]
    sections = _sections(out)
    assert set(sections) == set(FAILURES) | {"test_a_system_that_raises_keeps_its_path"}, out[-4000:]
    for name, (line, message) in FAILURES.items():
        report = sections[name]
        assert "framework/testing/" not in report and "framework" + "\\testing" not in report, \
            f"{name} shows the toolkit's frames:\n{report}"
        assert f">       {line}" in report or f">   {line}" in report or f"> {line}" in report, \
            f"{name} does not point at the test's line:\n{report}"
        assert message in report, f"{name}: the message is missing:\n{report}"
    # Not a test's failure: the game's exception keeps the path through the step, toolkit included.
    raised = sections["test_a_system_that_raises_keeps_its_path"]
    assert "RuntimeError: the game's own bug" in raised
    assert "framework/testing/running.py" in raised and "framework/scene.py" in raised, raised
