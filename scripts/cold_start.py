"""Cold and warm start of a scene's first step, in both solvers: what a new installation costs.

Each measurement is a fresh Python process. *Cold*: numba's cache is an empty directory
(``NUMBA_CACHE_DIR``), as on the first run after installing, so every kernel the scene uses is
compiled; *warm*: the same directory again, so they load from it. Reported per solver: the import of
``framework``, the first step, and the next step (the step's own cost). Run on a quiet machine: the
figures are single runs (the median of ``--runs`` when given).

    python scripts/cold_start.py [--runs 3]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

CHILD = r"""
import json, sys, time
t0 = time.perf_counter()
from framework import AABB, Circle, Hitbox, Polygon, Scene, Transform, Velocity
t1 = time.perf_counter()
s = Scene(solver=sys.argv[1], gravity=(0.0, -10.0))
s.spawn(Transform(0.0, -0.5), Hitbox(AABB(20.0, 1.0), body="static"))
for i in range(3):
    s.spawn(Transform(-2.0, 0.5 + i), Hitbox(AABB(1.0, 1.0)), Velocity(0.0, 0.0))
s.spawn(Transform(0.0, 0.5), Hitbox(Circle(0.5)), Velocity(0.0, 0.0))
s.spawn(Transform(2.0, 0.5), Hitbox(Polygon.box(1.0, 1.0)), Velocity(0.0, 0.0))
s.spawn(Transform(4.0, 2.0), Hitbox(Polygon.box(1.0, 0.5)), Velocity(1.0, 0.0))
t2 = time.perf_counter()
s.step(1 / 60)
t3 = time.perf_counter()
s.step(1 / 60)
t4 = time.perf_counter()
print(json.dumps({"import": t1 - t0, "first": t3 - t2, "next": t4 - t3}))
"""


def measure(solver: str, cache: str) -> dict[str, float]:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    out = subprocess.run([sys.executable, "-c", CHILD, solver], env=env, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=1, help="runs of each (the median is reported)")
    args = parser.parse_args()
    rows = []
    for solver in ("exact", "soft"):
        cold, warm = [], []
        for _ in range(args.runs):
            with tempfile.TemporaryDirectory() as cache:
                cold.append(measure(solver, cache))
                warm.append(measure(solver, cache))
        for name, runs in (("cold", cold), ("warm", warm)):
            med = {k: statistics.median(r[k] for r in runs) for k in runs[0]}
            rows.append((solver, name, med))
    print("| solver | start | import | first step | next step |")
    print("|---|---|---:|---:|---:|")
    for solver, name, m in rows:
        print(f"| {solver} | {name} | {m['import']:.2f} s | {m['first']:.2f} s | {m['next'] * 1e3:.2f} ms |")


if __name__ == "__main__":
    main()
