"""The wheel: what `pip install framework` (not editable) puts in site-packages.

The examples are ``examples`` in the checkout and ``framework.examples`` once installed
(pyproject.toml maps the one onto the other), so the wheel has a single top-level package and
carries the platformer's levels and images. The wheel is built offline from a clean copy of the
package sources (a checkout's stale ``build/lib`` would leak into a wheel built in place), with the
setuptools of the running environment; `.ci/run` builds it the ordinary way and installs it.
"""

from __future__ import annotations

import importlib.metadata
import importlib.util
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SOURCES = ("pyproject.toml", "README.md", "framework", "examples")  # what the build reads
JUNK = shutil.ignore_patterns("__pycache__", "*.pyc", "*.egg-info", "build", "dist")


def _offline_build_possible() -> str | None:
    """Why the wheel cannot be built here without an index, or None if it can."""
    if importlib.util.find_spec("pip") is None:
        return "pip is not installed in this environment"
    try:  # the version from the metadata: importing setuptools here would patch distutils for the session
        version = importlib.metadata.version("setuptools")
    except importlib.metadata.PackageNotFoundError:
        return "setuptools is not installed (pip install -e '.[dev]' brings it)"
    major, minor = (int(p) for p in version.split(".")[:2])
    # bdist_wheel is part of setuptools from 70.1; before that it needs the `wheel` package.
    if (major, minor) < (70, 1) and importlib.util.find_spec("wheel") is None:
        return f"setuptools {version} without `wheel` cannot build wheels (pip install -e '.[dev]' upgrades it)"
    return None


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    reason = _offline_build_possible()
    if reason:
        pytest.skip(f"cannot build the wheel offline: {reason}")
    tmp = tmp_path_factory.mktemp("wheel")
    src = tmp / "src"
    src.mkdir()
    for name in SOURCES:
        path = ROOT / name
        if path.is_dir():
            shutil.copytree(path, src / name, ignore=JUNK)
        else:
            shutil.copy2(path, src / name)
    out = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "--no-index", "-q",
         "-w", str(tmp / "dist"), str(src)],
        capture_output=True, text=True, timeout=120,
    )
    assert out.returncode == 0, out.stdout + out.stderr
    (whl,) = (tmp / "dist").glob("framework-*.whl")
    return whl


@pytest.fixture(scope="module")
def names(wheel) -> set[str]:
    with zipfile.ZipFile(wheel) as z:
        return set(z.namelist())


def _files(folder: Path) -> list[Path]:
    return sorted(p.relative_to(folder) for p in folder.rglob("*")
                  if p.is_file() and "__pycache__" not in p.parts and p.suffix != ".pyc")


def test_the_wheel_has_one_top_level_package_and_no_examples(wheel, names):
    tops = {n.split("/")[0] for n in names if not n.split("/")[0].endswith(".dist-info")}
    assert tops == {"framework"}
    assert not any(n.startswith("examples/") for n in names)
    with zipfile.ZipFile(wheel) as z:
        (top_level,) = [n for n in names if n.endswith(".dist-info/top_level.txt")]
        assert z.read(top_level).decode().split() == ["framework"]


def test_the_wheel_marks_the_package_as_typed(names):
    assert "framework/py.typed" in names  # PEP 561: users' type checkers read the package's hints


def test_every_module_of_the_framework_is_in_the_wheel(names):
    # pyproject.toml lists the packages by hand: a new subpackage of framework/ must be added there.
    missing = [str(p) for p in _files(ROOT / "framework") if f"framework/{p.as_posix()}" not in names]
    assert not missing, f"not in the wheel (add the package to [tool.setuptools] packages): {missing}"


def test_the_examples_ship_as_framework_examples_with_levels_and_images(names):
    shipped = {f"framework/examples/{p.as_posix()}" for p in _files(ROOT / "examples")}
    assert shipped - names == set()
    levels = {n for n in names if n.startswith("framework/examples/platformer/levels/")}
    images = {n for n in names if n.startswith("framework/examples/platformer/images/")}
    assert any(n.endswith(".tmj") for n in levels) and any(n.endswith(".png") for n in levels)
    assert len(images) >= 9 and all(n.endswith(".png") for n in images)


@pytest.mark.slow
def test_the_platformer_plays_from_the_unpacked_wheel(wheel, tmp_path):
    # What a non-editable install runs: the unpacked wheel first on the path, run from elsewhere.
    site = tmp_path / "site"
    with zipfile.ZipFile(wheel) as z:
        z.extractall(site)
    code = ("import framework\n"
            "from framework.examples.platformer.__main__ import main\n"
            "code = main(['--headless', '--demo'])\n"
            "print(framework.__file__)\n"
            "raise SystemExit(code)\n")
    env = {**os.environ, "PYTHONPATH": str(site)}
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stdout + out.stderr
    *_, summary, where = out.stdout.strip().splitlines()
    assert Path(where).is_relative_to(site)
    assert '"reached_goal": true' in summary
