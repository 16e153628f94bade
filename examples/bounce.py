"""Two squares that bounce when they touch: the classic first step.

    python -m examples.bounce                          # a window (F1 debug overlay, Esc quits)
    python -m examples.bounce --headless --frames 60   # no window: a one-line JSON summary

Two dynamic squares slide toward each other between two walls, with no gravity (a top-down view).
When they meet, the pipeline's response reflects their approaching speed with the pair's
restitution (1: elastic), and a collision handler counts the bounce. Nothing here is collision
code: the game only says what exists and what it wants to hear about.
"""

from __future__ import annotations

import argparse
import json

from framework import AABB, Hitbox, Scene, Transform, Velocity
from framework.components import Visual

__all__ = ["Square", "main", "make_scene"]

WIDTH, HEIGHT = 960, 540  # world units are screen pixels (the camera's default: zoom 1)


class Square:
    """Marks the two squares, so a handler can ask for square-square events only."""


def make_scene() -> tuple[Scene, list[int]]:
    scene = Scene()  # gravity (0, 0): nothing falls
    for x in (10, WIDTH - 10):  # a wall at each side: static bodies never move
        scene.spawn(Transform(x, HEIGHT / 2), Hitbox(AABB(20, HEIGHT), body="static"), Visual((90, 98, 128)))
    for x, vx, color in ((330, 200, 255), (630, -200, 0)):
        scene.spawn(Transform(x, HEIGHT / 2), Velocity(vx, 0), Hitbox(AABB(80, 80), restitution=1.0),
                    Visual((color, 140, 255 - color)), Square())
    bounces: list[int] = []

    def bounce(scene: Scene, event) -> None:  # called once, on the first step of each touch
        bounces.append(scene.frame + 1)  # scene.frame counts the steps finished before this one

    scene.on_collision(Square, Square, bounce, kinds=("started",))
    return scene, bounces


def main(argv: list[str] | None = None) -> int:
    prog = f"python -m {__package__ or 'examples'}.bounce"  # framework.examples.bounce when installed
    ap = argparse.ArgumentParser(prog=prog, description=__doc__.splitlines()[0])
    ap.add_argument("--headless", action="store_true", help="run without a window; print a JSON summary")
    ap.add_argument("--frames", type=int, default=None, metavar="N", help="stop after N steps (headless: 600)")
    args = ap.parse_args(argv)
    scene, bounces = make_scene()
    if args.headless:
        for _ in range(600 if args.frames is None else args.frames):
            scene.step(1 / 60)
    else:
        from framework.render import run

        run(scene, width=WIDTH, height=HEIGHT, title="bounce", max_frames=args.frames)
    velocities = [vel.x for _entity, (_square, vel) in scene.query(Square, Velocity)]
    print(json.dumps({"example": "bounce", "frames": scene.frame, "bounces": len(bounces),
                      "first_bounce_frame": bounces[0] if bounces else None,
                      "velocities": velocities}))
    scene.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
