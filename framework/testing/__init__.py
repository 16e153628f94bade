"""Headless tests of games built on the framework: what a game's test needs, small.

- :mod:`.running`: :func:`run` a scene for steps or seconds, :func:`step_until` something holds,
  scripted input over time (:class:`KeyScript`);
- :mod:`.levels`: scenes from inline text maps (:func:`text_scene`);
- :mod:`.events`: :class:`EventLog`, which collision events happened, with assertions;
- :mod:`.asserts`: physics assertions with readable messages (at rest, no overlap, inside a
  region, on the floor), and :func:`bounds` / :func:`feet` (where an entity's hitbox is);
- :mod:`.golden`: golden runs (:func:`check_golden`);
- :mod:`.strategies`: hypothesis strategies for shapes, transforms and small scenes (import it
  yourself: it needs hypothesis);
- :mod:`.tracebacks`: the helpers' frames are left out of pytest's tracebacks when they fail a
  test, so a failure points at the test's line;
- :mod:`.plugin`: the pytest plugin (a ``scene`` fixture, a ``golden_dir`` fixture, pictures of
  failing tests' scenes, ``--update-golden``), active wherever the framework is installed.

See docs/testing.md.
"""

from .asserts import assert_at_rest, assert_inside, assert_no_overlap, assert_on_floor, bounds, feet, overlaps
from .events import EventLog, Recorded
from .golden import GoldenMismatch, check_golden
from .levels import TextLevel, text_scene
from .running import DT, KeyScript, describe, run, step_until

__all__ = [
    "DT", "EventLog", "GoldenMismatch", "KeyScript", "Recorded", "TextLevel", "assert_at_rest", "assert_inside",
    "assert_no_overlap", "assert_on_floor", "bounds", "check_golden", "describe", "feet", "overlaps", "run",
    "step_until", "text_scene",
]
