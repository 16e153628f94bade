"""Circles and polygons colliding, with the debug overlay on.

    python -m examples.shapes_overlay                     # a window, overlay on (F1 toggles it)
    python -m examples.shapes_overlay --headless --frames 60 --screenshot shapes.png

Balls, crates (``Polygon.box``: a box that turns) and odd convex polygons rain onto two tilted
bars, a triangular bump and a floor between two walls. The overlay draws every hitbox outline
(green dynamic, grey static, blue asleep), each contact point with its normal from A toward B,
the spatial hash's cells in use and the milliseconds of each pipeline stage. ``--screenshot
PATH`` writes the last frame, overlay included, as a PNG (headless; no display needed).
"""

from __future__ import annotations

import argparse
import json
import math
import random

from framework import AABB, Circle, Hitbox, Polygon, Scene, Transform, Velocity
from framework.components import Visual
from framework.scene import DEFAULT_EFFECTS

__all__ = ["SHAPES", "main", "make_scene"]

WIDTH, HEIGHT = 960, 540
SHAPES = [Circle(14), Circle(9), Polygon.box(30, 20), Polygon([(-16, -12), (18, -10), (0, 16)]),
          Polygon([(math.cos(k * math.pi / 3) * 15, math.sin(k * math.pi / 3) * 15) for k in range(6)])]


def make_scene(seed: int = 7) -> tuple[Scene, dict]:
    # The default effects plus debug_overlay: the overlay is on whenever a renderer is attached.
    scene = Scene(gravity=(0.0, -500.0), effects=DEFAULT_EFFECTS | {"debug_overlay"})
    grey = (80, 84, 100)
    scene.spawn(Transform(WIDTH / 2, 10), Hitbox(AABB(WIDTH, 20), body="static"), Visual(grey))
    for x in (10, WIDTH - 10):  # two walls
        scene.spawn(Transform(x, HEIGHT / 2), Hitbox(AABB(20, HEIGHT), body="static"), Visual(grey))
    scene.spawn(Transform(WIDTH / 2, 20), Hitbox(Polygon([(-90, 0), (90, 0), (0, 60)]), body="static"),
                Visual(grey))  # a bump in the middle: a static triangle
    scene.spawn(Transform(300, 200, 0.3), Hitbox(Polygon.box(160, 16), body="static"), Visual(grey))
    scene.spawn(Transform(660, 240, -0.3), Hitbox(Polygon.box(160, 16), body="static"), Visual(grey))
    rng = random.Random(seed)
    for i in range(24):  # a rain of shapes, each a little higher than the last
        shape = SHAPES[i % len(SHAPES)]
        color = (rng.randrange(120, 256), rng.randrange(80, 220), rng.randrange(80, 256))
        scene.spawn(Transform(rng.uniform(260, 700), 260 + 22 * i, rng.uniform(0, math.pi)),
                    Velocity(rng.uniform(-60, 60), 0), Hitbox(shape, restitution=0.3), Visual(color, z=1))
    stats: dict = {"peak_contacts": 0, "narrow_tests": {}}

    def count(scene: Scene, dt: float) -> None:  # what the narrow phase just did, by shape pair
        stats["peak_contacts"] = max(stats["peak_contacts"], scene.counters["contacts"])
        for kind, n in scene.counters["narrow_tests"].items():
            stats["narrow_tests"][kind] = stats["narrow_tests"].get(kind, 0) + n

    scene.add_system(count, after="narrow_phase")
    return scene, stats


def main(argv: list[str] | None = None) -> int:
    prog = f"python -m {__package__ or 'examples'}.shapes_overlay"  # framework.examples.shapes_overlay when installed
    ap = argparse.ArgumentParser(prog=prog, description=__doc__.splitlines()[0])
    ap.add_argument("--headless", action="store_true", help="run without a window; print a JSON summary")
    ap.add_argument("--frames", type=int, default=None, metavar="N", help="stop after N steps (headless: 300)")
    ap.add_argument("--screenshot", default=None, metavar="PATH", help="write a PNG of the last frame")
    args = ap.parse_args(argv)
    scene, stats = make_scene()
    if args.headless:
        for _ in range(300 if args.frames is None else args.frames):
            scene.step(1 / 60)
    else:
        from framework.render import run

        run(scene, width=WIDTH, height=HEIGHT, title="shapes and the debug overlay", max_frames=args.frames)
    if args.screenshot:
        from framework.render import screenshot

        screenshot(scene, args.screenshot, width=WIDTH, height=HEIGHT, debug=True, background=(24, 26, 34))
    tests = dict(sorted(stats["narrow_tests"].items()))
    print(json.dumps({"example": "shapes_overlay", "frames": scene.frame, "bodies": len(scene.entities),
                      "peak_contacts": stats["peak_contacts"], "narrow_tests": tests, "screenshot": args.screenshot}))
    scene.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
