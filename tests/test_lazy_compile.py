"""A scene compiles only the kernels it uses (issue 35, the cold start): the exact decisions of pairs
touching to rounding (``exact_sign``) are reached only through the row passes' ``_settled``
variants, which a scene that never has such a pair never calls, so a new installation never
compiles them for it (about 8 of the 36 seconds the scene below used to take); the soft kernel
likewise leaves out the capsule and chain manifolds where a scene has neither."""

from __future__ import annotations

import json
import subprocess
import sys

CHILD = r"""
import json
from framework import AABB, Circle, Hitbox, Polygon, Scene, Transform, Velocity
from framework.collision import circle_rows, exact_sign, polygon_rows
s = Scene(gravity=(0.0, -10.0))
s.spawn(Transform(0.0, -0.5), Hitbox(AABB(20.0, 1.0), body="static"))
for i in range(3):
    s.spawn(Transform(-2.0, 0.5 + i), Hitbox(AABB(1.0, 1.0)), Velocity(0.0, 0.0))
s.spawn(Transform(0.0, 0.5), Hitbox(Circle(0.5)), Velocity(0.0, 0.0))
s.spawn(Transform(2.0, 0.5), Hitbox(Polygon.box(1.0, 1.0)), Velocity(0.0, 0.0))
s.spawn(Transform(4.0, 2.0), Hitbox(Polygon.box(1.0, 0.5)), Velocity(1.0, 0.0))
for _ in range(30):
    s.step(1 / 60)
fast = [polygon_rows.polygon_pairs, circle_rows.polygon_circle_pairs]
slow = [polygon_rows.polygon_pairs_settled, circle_rows.polygon_circle_pairs_settled,
        circle_rows.circle_pairs_settled, exact_sign.polygons_apart, exact_sign.polygon_depths,
        exact_sign.polygon_circle_contact]
print(json.dumps({"fast": [len(f.signatures) for f in fast], "slow": [len(f.signatures) for f in slow]}))
"""


def test_a_scene_without_pairs_touching_to_rounding_never_compiles_the_exact_decisions():
    out = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, check=True)
    got = json.loads(out.stdout.strip().splitlines()[-1])
    assert got["fast"] == [1, 1]  # (the passes ran: boxes on the floor, the circle beside them)
    assert got["slow"] == [0, 0, 0, 0, 0, 0]


SOFT_CHILD = r"""
import json, sys
from framework import AABB, Capsule, Circle, Hitbox, Polygon, Scene, Transform, Velocity
from framework.systems.soft_kernel import soft_step
s = Scene(solver="soft", gravity=(0.0, -10.0))
s.spawn(Transform(0.0, -0.5), Hitbox(AABB(20.0, 1.0), body="static"))
s.spawn(Transform(-2.0, 0.5), Hitbox(AABB(1.0, 1.0)), Velocity(0.0, 0.0))
s.spawn(Transform(0.0, 0.5), Hitbox(Circle(0.5)), Velocity(0.0, 0.0))
s.spawn(Transform(2.0, 0.5), Hitbox(Polygon.box(1.0, 1.0)), Velocity(0.0, 0.0))
if sys.argv[1] == "capsules":
    s.spawn(Transform(4.0, 0.5), Hitbox(Capsule(0.25, 0.5)), Velocity(0.0, 0.0))
    s.spawn(Transform(4.0, 1.5), Hitbox(Capsule(0.25, 0.5)), Velocity(0.0, 0.0))
for _ in range(5):
    s.step(1 / 60)
print(json.dumps([str(sig[-1]) for sig in soft_step.signatures]))  # (its last argument: ``rare``)
"""


def test_a_soft_scene_without_capsules_or_chains_runs_the_kernel_without_their_manifolds():
    """The soft kernel's ``rare`` is None (numba then drops the capsule and chain manifolds before
    typing them: 4 of its 24 seconds of compiling) unless the scene has a capsule or a chain."""
    got = {}
    for scene in ("plain", "capsules"):
        out = subprocess.run([sys.executable, "-c", SOFT_CHILD, scene], capture_output=True, text=True, check=True)
        got[scene] = json.loads(out.stdout.strip().splitlines()[-1])
    assert got == {"plain": ["none"], "capsules": ["int64"]}
