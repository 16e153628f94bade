"""Line of sight with ``scene.raycast``: a guard sees the runner only when no pillar is between.

    python -m examples.line_of_sight                          # a window (arrows steer the runner)
    python -m examples.line_of_sight --headless --frames 60   # no window: a one-line JSON summary

Each step a system casts one ray from the guard toward the runner. The first hitbox the ray
enters is the answer: the runner (seen: it turns red) or a pillar (hidden: green). The guard's
own hitbox is on a layer the ray's ``mask`` leaves out, or every ray would hit it at distance 0.
The debug overlay (on here) draws each ray up to its first hit and the hit's normal.
"""

from __future__ import annotations

import argparse
import json
import math
from typing import Any

from framework import AABB, Circle, Hitbox, Polygon, Scene, Transform, Velocity
from framework.components import Visual
from framework.input import Input

__all__ = ["main", "make_scene"]

WIDTH, HEIGHT, SPEED = 960, 540, 180.0
WORLD, GUARD = 1, 2  # collision layers: the ray looks at WORLD only
SEEN, HIDDEN = (240, 80, 70), (90, 210, 120)


def make_scene() -> tuple[Scene, dict[str, Any]]:
    scene = Scene()  # no gravity: seen from above
    guard = scene.spawn(Transform(120, HEIGHT / 2), Hitbox(Circle(16), body="static", layer=GUARD),
                        Visual((250, 230, 90)))
    grey = (90, 98, 128)
    for x, y in ((400, 120), (400, 420), (560, 270)):  # pillars: a box, a box and a round one
        shape = Circle(50) if y == 270 else AABB(70, 110)
        scene.spawn(Transform(x, y), Hitbox(shape, body="static"), Visual(grey))
    scene.spawn(Transform(300, 270), Hitbox(Polygon([(-20, -40), (20, -40), (0, 40)]), body="static"),
                Visual(grey))
    runner = scene.spawn(Transform(800, 40), Velocity(0, SPEED), Hitbox(AABB(30, 30)), Visual(HIDDEN))
    stats: dict[str, Any] = {"seen": 0, "hidden": 0, "first_seen": None}

    def steer(scene: Scene, dt: float) -> None:  # arrows steer; without keys it patrols up and down
        keys, vel, pos = scene.resources[Input], scene.get(runner, Velocity), scene.get(runner, Transform)
        if keys.held:
            vel.x = SPEED * (keys.is_held("right") - keys.is_held("left"))
            vel.y = SPEED * (keys.is_held("up") - keys.is_held("down"))
        elif (pos.y > HEIGHT - 40 and vel.y > 0) or (pos.y < 40 and vel.y < 0):
            vel.x, vel.y = 0.0, -vel.y

    def look(scene: Scene, dt: float) -> None:  # after the response: where everything ended up
        g, r = scene.get(guard, Transform), scene.get(runner, Transform)
        dx, dy = r.x - g.x, r.y - g.y  # toward the runner's centre, and no farther
        hit = scene.raycast((g.x, g.y), (dx, dy), max_distance=math.hypot(dx, dy), mask=WORLD)
        seen = hit is not None and hit.entity == runner
        scene.get(runner, Visual).color = (*(SEEN if seen else HIDDEN), 255)
        stats["seen" if seen else "hidden"] += 1
        if seen and stats["first_seen"] is None:
            stats["first_seen"] = scene.frame + 1

    scene.add_system(steer, before="movement")
    scene.add_system(look, after="response")
    return scene, stats


def main(argv: list[str] | None = None) -> int:
    prog = f"python -m {__package__ or 'examples'}.line_of_sight"  # framework.examples.line_of_sight when installed
    ap = argparse.ArgumentParser(prog=prog, description=__doc__.splitlines()[0])
    ap.add_argument("--headless", action="store_true", help="run without a window; print a JSON summary")
    ap.add_argument("--frames", type=int, default=None, metavar="N", help="stop after N steps (headless: 600)")
    args = ap.parse_args(argv)
    scene, stats = make_scene()
    if args.headless:
        for _ in range(600 if args.frames is None else args.frames):
            scene.step(1 / 60)
    else:
        from framework.render import run

        run(scene, width=WIDTH, height=HEIGHT, title="line of sight", debug=True, max_frames=args.frames)
    print(json.dumps({"example": "line_of_sight", "frames": scene.frame, "seen_frames": stats["seen"],
                      "hidden_frames": stats["hidden"], "first_seen_frame": stats["first_seen"]}))
    scene.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
