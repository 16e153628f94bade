"""Command line: ``python -m examples.sandbox [options]`` (installed: ``framework.examples.sandbox``).

Opens the sandbox in a window by default: press the left mouse button on a crate, a barrel, the
rope or the car and drag it; left / right arrows (A / D) drive the car; F1 shows the debug
overlay; Esc quits.

--headless         run without a window; print a one-line JSON summary as the last line
--demo             scripted input: drive the car up the slope, lift a crate with the mouse, drop it
--frames N         stop after N steps (also --steps N; headless default: 600, or 360 with --demo)
--screenshot PATH  after the run, write a PNG of the last frame (headless rendering)
--debug            start with the debug overlay (and draw it in the screenshot)

Without a display (and without --headless), it says so in one line on stderr, with how to run it
instead, and exits with status 1: it never runs an invisible window.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from typing import Any

from framework import Transform

from .controls import drag_to, drive_system, grab, joint_count, release
from .demo import DEMO_STEPS, DemoState, demo_step
from .world import DT, ZOOM, Sandbox, make_sandbox

__all__ = ["BACKGROUND", "camera", "main", "open_window", "parse_args", "run_headless", "run_window", "summary"]

WIDTH, HEIGHT = 1280, 540
BACKGROUND = (24, 26, 38)
CENTER = (5.0, 9.0)  # the world point at the centre of the view
ON_GROUND = 0.01  # a wheel this close to the ground (metres) touches it
TITLE = "Sandbox - drag bodies with the mouse, left / right drive the car, F1 overlay, Esc quits"


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(prog=f"python -m {__package__}", description="The physics sandbox.")
    ap.add_argument("--headless", action="store_true", help="run without a window and print a JSON summary")
    ap.add_argument("--demo", action="store_true", help="scripted input: drive up the slope, drag a crate")
    ap.add_argument("--frames", "--steps", type=int, default=None, metavar="N", dest="frames",
                    help="stop after N steps")
    ap.add_argument("--screenshot", default=None, metavar="PATH", help="write a PNG of the last frame")
    ap.add_argument("--debug", action="store_true", help="start with the debug overlay")
    args = ap.parse_args(argv)
    if args.frames is not None and args.frames < 0:
        ap.error(f"--frames must be >= 0, got {args.frames}")
    return args


def camera() -> Any:
    from framework.render import Camera

    return Camera(*CENTER, zoom=ZOOM)


def summary(sandbox: Sandbox) -> dict[str, Any]:
    """Where the car is (its chassis' centre and angle, in degrees), whether both wheels touch the
    ground (within 1 cm), and how many joints the scene holds."""
    t = sandbox.scene.get(sandbox.chassis, Transform)
    return {"car_x": round(t.x, 2), "car_y": round(t.y, 2), "car_angle": round(math.degrees(t.rotation), 1),
            "wheels_on_ground": max(sandbox.wheel_gaps()) < ON_GROUND, "joints": joint_count(sandbox)}


def run_headless(sandbox: Sandbox, args: argparse.Namespace) -> dict[str, Any]:
    limit = args.frames if args.frames is not None else (DEMO_STEPS if args.demo else 600)
    state = DemoState()
    t0 = time.perf_counter()
    for step in range(limit):
        if args.demo:
            demo_step(sandbox, step, state)
        sandbox.scene.step(DT)
    elapsed = time.perf_counter() - t0
    return {"frames": limit, "ms_per_frame": round(1e3 * elapsed / max(limit, 1), 4), **summary(sandbox),
            "drags": state.drags, "lifted": state.lifted}


def open_window(sandbox: Sandbox, args: argparse.Namespace) -> tuple[Any, list[int]]:
    """The sandbox's window (a :class:`~framework.render.Runner`, not yet running) and a list that
    counts the drags made in it. The mouse's presses, drags and releases go, as world points, to
    grab, drag_to and release; the keys to the scene's Input, which the drive system reads.
    :class:`~framework.render.NoDisplayError` where no window can be shown."""
    from pyglet.window import mouse

    from framework.render import Runner

    runner = Runner(sandbox.scene, width=WIDTH, height=HEIGHT, title=TITLE, fps=round(1.0 / DT), camera=camera(),
                    debug=args.debug, max_frames=args.frames, background=BACKGROUND)
    drags: list[int] = []

    def world(x: float, y: float) -> tuple[float, float]:
        return runner.renderer.camera.screen_to_world(x, y)

    def on_mouse_press(x: int, y: int, button: int, modifiers: int) -> None:
        if button == mouse.LEFT:
            joint = grab(sandbox, world(x, y))
            if joint is not None:
                drags.append(joint)

    def on_mouse_drag(x: int, y: int, dx: int, dy: int, buttons: int, modifiers: int) -> None:
        drag_to(sandbox, world(x, y))

    def on_mouse_release(x: int, y: int, button: int, modifiers: int) -> None:
        if button == mouse.LEFT:
            release(sandbox)

    runner.window.push_handlers(on_mouse_press=on_mouse_press, on_mouse_drag=on_mouse_drag,
                                on_mouse_release=on_mouse_release)
    return runner, drags


def run_window(sandbox: Sandbox, args: argparse.Namespace) -> dict[str, Any]:
    runner, drags = open_window(sandbox, args)
    t0 = time.perf_counter()
    runner.run()
    ms = 1e3 * (time.perf_counter() - t0) / max(sandbox.scene.frame, 1)
    return {"frames": sandbox.scene.frame, "ms_per_frame": round(ms, 4), **summary(sandbox), "drags": len(drags),
            "lifted": None}


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    if not args.headless:  # before building the scene: say at once that no window can be shown
        from framework.render.display import no_display_reason, no_window_line

        reason = no_display_reason()
        if reason is not None:
            print(no_window_line(reason, __package__), file=sys.stderr)
            return 1
    with make_sandbox() as sandbox:
        sandbox.scene.add_system(drive_system(sandbox), before="movement")
        if args.headless:
            result = run_headless(sandbox, args)
        else:
            from framework.render import NoDisplayError

            try:
                result = run_window(sandbox, args)
            except NoDisplayError as exc:  # the display is there but fails to open
                print(no_window_line(exc, __package__), file=sys.stderr)
                return 1
        if args.screenshot:
            from framework.render import screenshot

            screenshot(sandbox.scene, args.screenshot, width=WIDTH, height=HEIGHT, camera=camera(),
                       debug=args.debug, background=BACKGROUND)
            result["screenshot"] = args.screenshot
        if args.headless:
            print(json.dumps(result))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
