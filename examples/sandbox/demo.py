"""The sandbox's scripted run (``--demo``): it drives the car up the slope and, meanwhile, lifts a
crate with the mouse and lets it drop, through the same functions the window's handlers call.
"""

from __future__ import annotations

from dataclasses import dataclass

from framework import Input, Transform

from .controls import drag_to, grab, release
from .world import Sandbox

__all__ = ["DEMO_STEPS", "DRIVE", "GRAB", "LIFT", "LIFT_HEIGHT", "RELEASE", "DemoState", "demo_step"]

DEMO_STEPS = 360  # the demo's length (6 s at 60 steps a second)
DRIVE = range(30, 210)  # steps with "right" held
GRAB, RELEASE = 30, 240  # the mouse goes down on the lone crate, and up
LIFT = 90  # steps over which the pointer rises by LIFT_HEIGHT (then holds still)
LIFT_HEIGHT = 4.0


@dataclass
class DemoState:
    """What the script noted: where it grabbed, how many drags it made, how high the crate was when
    let go."""

    start: tuple[float, float] | None = None
    drags: int = 0
    lifted: float | None = None


def demo_step(sandbox: Sandbox, step: int, state: DemoState) -> None:
    """Apply the script's input for ``step`` (0-based), before the scene steps."""
    scene = sandbox.scene
    scene.resources.setdefault(Input, Input()).set_held({"right"} if step in DRIVE else set())
    crate = sandbox.crates[2]  # the lone crate, left of the car
    if step == GRAB:
        t = scene.get(crate, Transform)
        state.start = (t.x, t.y)
        if grab(sandbox, state.start) is not None:
            state.drags += 1
    elif GRAB < step < RELEASE and state.start is not None:
        x, y = state.start
        f = min((step - GRAB) / LIFT, 1.0)
        drag_to(sandbox, (x, y + f * LIFT_HEIGHT))
    elif step == RELEASE:
        t = scene.get(crate, Transform)
        state.lifted = round(t.y, 2)
        release(sandbox)
