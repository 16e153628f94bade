"""The framework's pytest plugin (registered through the ``pytest11`` entry point: active wherever
the package is installed, no conftest needed).

- a ``scene`` fixture: a new :class:`~framework.scene.Scene`, closed after the test;
- failure pictures: when a test fails, every scene it made (the fixture's, a game's, any) is
  rendered headless with the debug overlay at the step it failed on, into ``--framework-pictures``
  (default ``.framework-failures/``), and the picture's path is printed in the failure report;
  ``--no-framework-pictures`` turns it off; where no OpenGL is available the report says why there
  is no picture. Scenes a test made are closed after it.
- a ``golden_dir`` fixture: the folder ``golden/`` next to the test's file (a :class:`~pathlib.Path`,
  not created until a golden run records into it), where a test keeps its golden files;
- ``--update-golden``: golden runs (:mod:`framework.testing.golden`) record instead of comparing
  (for the session: it sets ``FRAMEWORK_UPDATE_GOLDEN``, put back as it was at the end).
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

# pytest's hooks and the fixtures
__all__ = ["SECTION", "UPDATE_GOLDEN", "golden_dir", "pytest_addoption", "pytest_configure", "pytest_runtest_call",
           "pytest_runtest_makereport", "pytest_runtest_setup", "pytest_runtest_teardown", "pytest_unconfigure",
           "scene"]

SECTION = "framework picture"
UPDATE_GOLDEN = "FRAMEWORK_UPDATE_GOLDEN"


def pytest_addoption(parser: Any) -> None:
    group = parser.getgroup("framework", "the framework's test toolkit")
    group.addoption("--framework-pictures", default=".framework-failures", metavar="DIR",
                    help="where pictures of the scenes of failing tests go (default .framework-failures)")
    group.addoption("--no-framework-pictures", action="store_true", help="no pictures of failing tests' scenes")
    group.addoption("--update-golden", action="store_true", help="golden runs record their files anew")


def pytest_configure(config: Any) -> None:
    if config.getoption("update_golden", default=False):
        config._framework_update_golden_was = os.environ.get(UPDATE_GOLDEN)
        os.environ[UPDATE_GOLDEN] = "1"


def pytest_unconfigure(config: Any) -> None:
    if not hasattr(config, "_framework_update_golden_was"):
        return
    was = config._framework_update_golden_was
    if was is None:
        os.environ.pop(UPDATE_GOLDEN, None)
    else:
        os.environ[UPDATE_GOLDEN] = was


@pytest.fixture
def scene() -> Iterator[Any]:
    """A new scene (no gravity, the default effects), closed after the test."""
    from framework.scene import Scene

    s = Scene()
    yield s
    s.close()


@pytest.fixture
def golden_dir(request: Any) -> Path:
    """The folder ``golden/`` next to the test's file, for its golden files (check them in):
    ``check_golden(scene, golden_dir / "jump.json", steps=120)``. Not created here: a run that
    records (``--update-golden``) creates it."""
    return Path(request.path).parent / "golden"


class _Made:
    """The scenes made while one test runs: its fixtures' (setup) and its own (call)."""

    def __init__(self) -> None:
        self.phase = "setup"
        self.scenes: list[tuple[Any, str]] = []

    def __call__(self, scene: Any) -> None:
        self.scenes.append((scene, self.phase))


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_setup(item: Any) -> Iterator[None]:
    from framework.scene import SCENE_CREATED

    made = item._framework_made = _Made()
    SCENE_CREATED.append(made)
    yield


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_call(item: Any) -> Iterator[None]:
    made = getattr(item, "_framework_made", None)
    if made is not None:
        made.phase = "call"
    yield


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_teardown(item: Any) -> Iterator[None]:
    """After the test's own teardown: close the scenes it made itself (a fixture's scenes are the
    fixture's to close: one shared by several tests must live on)."""
    from framework.scene import SCENE_CREATED

    yield
    made = getattr(item, "_framework_made", None)
    if made is None:
        return
    if made in SCENE_CREATED:
        SCENE_CREATED.remove(made)
    for scene, phase in made.scenes:
        if phase == "call" and not scene.closed:
            scene.close()


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item: Any, call: Any) -> Iterator[None]:
    outcome: Any = yield
    report = outcome.get_result()
    if report.when != "call" or not report.failed:
        return
    made = getattr(item, "_framework_made", None)
    scenes = [s for s, _phase in (made.scenes if made is not None else []) if not s.closed]
    if not scenes or item.config.getoption("no_framework_pictures", default=False):
        return
    folder = Path(item.config.getoption("framework_pictures", default=".framework-failures"))
    if not folder.is_absolute():
        folder = Path(item.config.rootpath) / folder
    name = re.sub(r"[^A-Za-z0-9_.-]+", "_", item.nodeid).strip("_")
    from .pictures import picture

    lines = []
    for i, s in enumerate(scenes):
        path = folder / (f"{name}.png" if len(scenes) == 1 else f"{name}-{i + 1}.png")
        try:
            picture(s, path)
        except Exception as exc:  # no GL here, most likely: say why there is no picture
            lines.append(f"no picture of scene {i + 1} (step {s.frame}): {type(exc).__name__}: {exc}")
            continue
        lines.append(f"the scene at step {s.frame}, with hitboxes, contacts and velocities: {path}")
    report.sections.append((SECTION, "\n".join(lines)))
