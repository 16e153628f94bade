"""What the joint tests share: a soft scene, a box that turns, a body's pose and a swing's period
measured from its zero crossings (tests/test_joints.py, tests/test_joint_springs.py)."""

from __future__ import annotations

from framework import Polygon, Scene, Transform
from framework.systems.soft_step import SOFT_SETTINGS

SLOP = SOFT_SETTINGS["slop"]
G = 8.0
DT = 1 / 64


def soft(gravity: float = G) -> Scene:
    return Scene(gravity=(0.0, -gravity), solver="soft")


def box(hw: float, hh: float) -> Polygon:
    """A box that turns (an AABB never does)."""
    return Polygon([(-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh)])


def pose(scene: Scene, e: int) -> tuple[float, float, float]:
    t = scene.get(e, Transform)
    return t.x, t.y, t.rotation


def crossings(ts: list[float], xs: list[float]) -> list[float]:
    """The times where ``xs`` changes sign, interpolated."""
    out = []
    for k in range(1, len(xs)):
        if xs[k - 1] < 0.0 <= xs[k] or xs[k - 1] >= 0.0 > xs[k]:
            f = xs[k - 1] / (xs[k - 1] - xs[k])
            out.append(ts[k - 1] + f * (ts[k] - ts[k - 1]))
    return out


def period(ts: list[float], xs: list[float]) -> float:
    c = crossings(ts, xs)
    assert len(c) >= 5
    return 2.0 * (c[-1] - c[0]) / (len(c) - 1)
