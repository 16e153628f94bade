"""``gym.make`` with nothing imported but Gymnasium (the ``rl`` extra; skipped without gymnasium).

Gymnasium 1.0 removed the ``gymnasium.envs`` entry-point plugins, so installing a package can no
longer register its environments on Gymnasium's import; the id's ``module:`` prefix makes
``gym.make`` import the module that registers it. docs/headless.md shows that id: these tests run
exactly it in a fresh process whose script imports only Gymnasium, from the installed layout (the
wheel, unpacked, first on the path) and from the checkout (``examples.platformer.env``).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

pytest.importorskip("gymnasium", reason="the rl extra (gymnasium) is not installed: pip install -e '.[rl]'")

from test_packaging import wheel  # noqa: E402,F401  (the fixture: the wheel, built offline)

ROOT = Path(__file__).resolve().parents[1]
ENV_ID = "framework/Platformer-v0"


def _documented_id() -> str:
    """The id docs/headless.md's sample passes to ``gym.make``."""
    page = (ROOT / "docs" / "headless.md").read_text()
    (block,) = [b for b in re.findall(r"```python\n(.*?)```", page, flags=re.S) if "gym.make(" in b]
    assert [line for line in block.splitlines() if line.startswith(("import", "from"))] == ["import gymnasium as gym"]
    (made,) = re.findall(r"gym\.make\(\"([^\"]+)\"", block)
    return made


def _make_in_a_fresh_process(env_id: str, cwd: Path, path: Path) -> list[str]:
    """What a script that imports only Gymnasium prints after ``gym.make(env_id)`` and a reset."""
    script = ("import gymnasium as gym\n"
              f"env = gym.make({env_id!r}, level=0)\n"
              "obs, info = env.reset(seed=0)\n"
              "import sys\n"
              "module = type(env.unwrapped).__module__\n"
              "print(env.spec.id, info['level'], obs.shape, module)\n"
              "print(sys.modules[module].__file__)\n"
              "env.close()\n"
              f"print(gym.make({ENV_ID!r}).spec.id)  # the short id, once the module is imported\n")
    out = subprocess.run([sys.executable, "-c", script], cwd=cwd, env={**os.environ, "PYTHONPATH": str(path)},
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-4000:]
    return out.stdout.splitlines()


def test_the_documented_id_names_the_installed_module():
    assert _documented_id() == f"framework.examples.platformer.env:{ENV_ID}"


@pytest.mark.slow
def test_gym_make_from_the_installed_package_needs_no_other_import(wheel, tmp_path):  # noqa: F811
    site = tmp_path / "site"
    with zipfile.ZipFile(wheel) as z:
        z.extractall(site)
    printed = _make_in_a_fresh_process(_documented_id(), cwd=tmp_path, path=site)
    made, where, short = printed
    assert made == f"{ENV_ID} Meadow (54,) framework.examples.platformer.env" and short == ENV_ID
    assert Path(where).is_relative_to(site)  # the wheel's module, not a checkout's


@pytest.mark.slow
def test_gym_make_from_the_checkout_needs_no_other_import():
    checkout_id = _documented_id().replace("framework.examples.", "examples.")
    printed = _make_in_a_fresh_process(checkout_id, cwd=ROOT, path=ROOT)
    made, where, short = printed
    assert made == f"{ENV_ID} Meadow (54,) examples.platformer.env" and short == ENV_ID
    assert Path(where) == ROOT / "examples" / "platformer" / "env.py"
