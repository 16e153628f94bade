"""The play command where no window can be shown: one line saying so and how to play, a non-zero
exit, at once; never an invisible window running on (issue 36, item 1).

The child runs without ``PYGLET_HEADLESS`` and ``PYGLET_SHADOW_WINDOW`` (conftest sets them for
this process): headless rendering was not asked for, so there is no window to be had.
"""

from __future__ import annotations

import subprocess
import sys
import time

import pytest
from example_commands import ROOT, child_env, commands

HINT = "--headless --demo"

COMMANDS = commands("platformer")
DISPLAYS = {  # no display at all; one named that cannot be opened (nothing listens on :987)
    "no display": {},
    "a display that fails to open": {"DISPLAY": ":987"},
}


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="DISPLAY / WAYLAND_DISPLAY are Linux's")
@pytest.mark.parametrize("display", list(DISPLAYS))
@pytest.mark.parametrize("module", list(COMMANDS))
def test_the_play_command_without_a_display_says_so_and_exits(module, display):
    t0 = time.perf_counter()
    try:
        out = subprocess.run(COMMANDS[module], cwd=ROOT, env=child_env(DISPLAYS[display]), capture_output=True,
                             text=True, timeout=60)
    except subprocess.TimeoutExpired:
        pytest.fail(f"`python -m {module}` without a display still ran after 60 s (an invisible window?)")
    elapsed = time.perf_counter() - t0
    assert out.returncode == 1, (out.returncode, out.stdout, out.stderr)
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1, out.stderr  # one line, no traceback
    line = lines[0]
    assert line.startswith("error: ") and "display" in line, line
    assert f"python -m {module} {HINT}" in line and "set DISPLAY" in line, line
    if display == "no display":
        assert "neither DISPLAY nor WAYLAND_DISPLAY is set" in line, line
    else:
        assert "':987'" in line, line
    assert out.stdout == ""
    assert elapsed < 20.0, f"took {elapsed:.1f} s to give up"  # at once: no level loaded and played


def test_headless_asked_for_still_plays_without_a_display():
    out = subprocess.run([sys.executable, "-m", "examples.platformer", "--headless", "--frames", "3"], cwd=ROOT,
                         env=child_env({}), capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert '"frames": 3' in out.stdout.strip().splitlines()[-1]
