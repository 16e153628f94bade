"""How the tests run an example's command in a child process, under both of its module names
(tests/test_play_command.py, tests/test_sandbox.py).

`framework.examples` is the installed name of the checkout's examples/ (pyproject's package-dir).
An editable install elsewhere maps it onto that checkout, so the child maps it onto this one the
same way (the folder on the package's path) and runs the module as `python -m` would. The child
runs without a display and without ``PYGLET_HEADLESS`` and ``PYGLET_SHADOW_WINDOW`` (conftest sets
them for this process), unless ``extra`` says otherwise.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def commands(example: str) -> dict[str, list[str]]:
    """``{module name: argv}`` of the example (``"platformer"``) as ``examples.<example>`` in the
    checkout and as the installed ``framework.examples.<example>``."""
    installed = f"framework.examples.{example}"
    as_installed = ("import runpy, sys, framework\n"
                    f"framework.__path__.insert(0, {str(ROOT)!r})\n"
                    f"sys.argv[0] = {installed!r}\n"
                    f"runpy.run_module({installed!r}, run_name='__main__', alter_sys=True)\n")
    return {f"examples.{example}": [sys.executable, "-m", f"examples.{example}"],
            installed: [sys.executable, "-c", as_installed]}


def child_env(extra: dict[str, str]) -> dict[str, str]:
    """This process's environment less its display and pyglet settings, with the checkout on the
    path, plus ``extra``."""
    drop = {"DISPLAY", "WAYLAND_DISPLAY", "PYGLET_HEADLESS", "PYGLET_SHADOW_WINDOW"}
    env = {k: v for k, v in os.environ.items() if k not in drop}
    return {**env, "PYTHONPATH": str(ROOT), **extra}
