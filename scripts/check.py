"""Every check a contributor runs before pushing, in one command, in the current environment.

``python scripts/check.py`` runs, in order: ruff, mypy (configured in pyproject.toml), the tests,
the compiled kernels' index bounds (:data:`BOUNDS_TESTS` again with ``NUMBA_BOUNDSCHECK=1``: a
kernel that reads past an array's end reads memory that differs from run to run, so its scene does
not replay bit for bit), the strict docs build (``mkdocs build --strict``, into a temporary
directory) and each benchmark's ``--quick`` run (the list is read from ``python -m framework.bench``,
so a new benchmark is checked without touching this file). Every check runs even when an earlier
one failed; a summary with each check's time comes last, and the exit status is 1 if any check
failed.

Nothing is installed and no virtual environment is made: it uses the Python that runs it (the
project's ``.venv``), so it works offline. It needs the ``dev`` extra, and the ``docs`` extra for
the docs build (``pip install -e ".[dev,docs]"``); the ``bench`` extra (pymunk, pyb2d3, matplotlib)
is optional: without it the benchmarks leave the peers' columns empty.

Options: ``--skip-tests`` (CI has just run the test suite), ``--skip NAME`` and ``--only NAME``
(repeatable; names as ``--list`` prints them: ``ruff``, ``mypy``, ``tests``, ``bounds``,
``docs``, ``bench-perf`` ...), ``--list``. The benchmarks write no report files (``--no-save``).
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


# The tests that drive every compiled stage (movement, detection, both solvers, the character
# controller, sleeping, joints, queries, snapshots and the platformer): the bounds check runs them
# with numba's index checks on, compiled into a cache of their own (a checked kernel is slower, and
# must never be the one a normal run loads). About 6 minutes on 2 cores, compiling included.
BOUNDS_TESTS = (
    "test_character", "test_character_edges", "test_character_kernel", "test_snapshot", "test_platformer",
    "test_platformer_slopes", "test_platformer_swing", "test_platformer_bridge", "test_determinism",
    "test_soft_step", "test_solver", "test_tumbling", "test_friction", "test_crowds", "test_tiles",
    "test_internal_faces", "test_batch_queries", "test_raycast", "test_shape_cast", "test_sleeping_contacts",
    "test_compound", "test_joints", "test_deep_push_out", "test_step_fast_paths", "test_broad_phase",
    "test_manifold", "test_geometry_rows", "test_turning_rows", "test_solve_columns", "test_segment_scenes",
    "test_tiled_chains", "test_soft_manifold", "test_rolling_impacts", "test_polygon_rows", "test_capsule",
)


@dataclass
class Check:
    name: str
    command: list[str]
    needs: str | None = None  # a module that must be importable (else: what to install)
    hint: str = ""
    env: dict[str, str] | None = None  # set for this check only


def bench_names() -> list[str]:
    """The benchmarks ``python -m framework.bench`` offers (its sub-commands), in its order."""
    sys.path.insert(0, str(ROOT))
    try:
        from framework.bench.__main__ import _parser
    finally:
        sys.path.pop(0)
    for action in _parser()._actions:
        if isinstance(action, argparse._SubParsersAction):
            return list(action.choices)
    raise RuntimeError("python -m framework.bench has no sub-commands")


def checks(site_dir: str, bounds_cache: str) -> list[Check]:
    py = sys.executable
    out = [
        Check("ruff", [py, "-m", "ruff", "check", "."], "ruff", 'pip install -e ".[dev]"'),
        Check("mypy", [py, "-m", "mypy"], "mypy", 'pip install -e ".[dev]"'),
        Check("tests", [py, "-m", "pytest"], "pytest", 'pip install -e ".[dev]"'),
        Check("bounds", [py, "-m", "pytest", "-q", *(f"tests/{t}.py" for t in BOUNDS_TESTS)], "pytest",
              'pip install -e ".[dev]"', {"NUMBA_BOUNDSCHECK": "1", "NUMBA_CACHE_DIR": bounds_cache}),
        Check("docs", [py, "-m", "mkdocs", "build", "--strict", "--site-dir", site_dir], "mkdocstrings",
              'pip install -e ".[docs]"'),
    ]
    for name in bench_names():
        out.append(Check(f"bench-{name}", [py, "-m", "framework.bench", name, "--quick", "--no-save",
                                           "--no-progress"]))
    return out


def run(check: Check) -> tuple[bool, float, str]:
    """Run one check with its output shown as it comes; ``(passed, seconds, note)``."""
    if check.needs is not None and importlib.util.find_spec(check.needs) is None:
        return False, 0.0, f"{check.needs} is not installed: {check.hint}"
    print(f"\n=== {check.name}: {' '.join(Path(c).name if i == 0 else c for i, c in enumerate(check.command))}",
          flush=True)
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1", **(check.env or {})}
    t0 = time.perf_counter()
    code = subprocess.call(check.command, cwd=ROOT, env=env)
    seconds = time.perf_counter() - t0
    return code == 0, seconds, "" if code == 0 else f"exit status {code}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python scripts/check.py", description=__doc__.split("\n\n")[0])
    parser.add_argument("--skip-tests", action="store_true", help="leave out the test suite (CI ran it already)")
    parser.add_argument("--skip", action="append", default=[], metavar="NAME", help="leave out this check")
    parser.add_argument("--only", action="append", default=[], metavar="NAME", help="run only these checks")
    parser.add_argument("--list", action="store_true", help="print the checks' names and commands, run nothing")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="check-site-") as site, \
            tempfile.TemporaryDirectory(prefix="check-bounds-cache-") as bounds_cache:
        todo = checks(site, bounds_cache)
        names = [c.name for c in todo]
        unknown = sorted(set(args.skip + args.only) - set(names))
        if unknown:
            parser.error(f"unknown check(s) {', '.join(unknown)}; known: {', '.join(names)}")
        skip = set(args.skip) | ({"tests"} if args.skip_tests else set())
        todo = [c for c in todo if c.name not in skip and (not args.only or c.name in args.only)]
        if args.list:
            for c in todo:
                print(f"{c.name:14} {' '.join(c.command[1:])}")
            return 0
        results = [(c, *run(c)) for c in todo]
    print("\n=== summary")
    for c, ok, seconds, note in results:
        print(f"{'pass' if ok else 'FAIL':4}  {c.name:14} {seconds:7.1f} s  {note}")
    total = sum(seconds for _c, _ok, seconds, _n in results)
    failed = [c.name for c, ok, _s, _n in results if not ok]
    print(f"{len(results) - len(failed)} of {len(results)} checks passed in {total:.0f} s"
          + (f"; failed: {', '.join(failed)}" if failed else ""))
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
