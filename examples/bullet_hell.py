"""A bullet-hell stress scene: thousands of bullets, and what each pipeline stage costs.

    python -m examples.bullet_hell                          # a window: the title shows the numbers
    python -m examples.bullet_hell --headless --frames 60   # no window: a one-line JSON summary

Three emitters spray spirals of bullets at a ship (arrows steer it). Bullets are sensors whose mask sees only the
ship, so no two are ever paired; the scene declares only the effects it uses. A system sums ``scene.stage_ms``."""

import argparse
import json
import math
from collections import deque

from framework import AABB, Circle, Hitbox, Scene, Transform, Velocity
from framework.components import Visual
from framework.input import Input

__all__ = ["Bullet", "Ship", "main", "make_scene"]
WIDTH, HEIGHT, DT = 960, 540, 1 / 60
SHIP, BULLET = 1, 2  # collision layers
PER_EMITTER, SPEED, LIFETIME = 4, 160.0, 180  # bullets per emitter per step; their speed; steps they live


class Ship:
    """The player's ship."""


class Bullet:
    """A bullet (the hit handler asks for ship-bullet events)."""


def make_scene() -> tuple[Scene, dict]:
    scene = Scene(effects={"movement", "detection"})
    ship = scene.spawn(Transform(WIDTH / 2, 60), Velocity(), Visual((120, 200, 255), z=1), Ship(),
                       Hitbox(AABB(24, 24), body="kinematic", layer=SHIP, mask=BULLET))
    alive: deque[tuple[int, int]] = deque()  # (frame fired, bullet), oldest first
    stats: dict = {"hits": 0, "stage_ms": {}}

    def fire(scene: Scene, dt: float) -> None:
        f = scene.frame
        for k, ex in enumerate((WIDTH * 0.2, WIDTH * 0.5, WIDTH * 0.8)):
            for j in range(PER_EMITTER):
                a = 0.07 * f * (1 if k % 2 else -1) + j * 2 * math.pi / PER_EMITTER
                alive.append((f, scene.spawn(
                    Transform(ex, HEIGHT - 80), Velocity(SPEED * math.cos(a), SPEED * math.sin(a)), Bullet(),
                    Hitbox(Circle(4), sensor=True, layer=BULLET, mask=SHIP), Visual((255, 120 + 40 * k, 90)))))
        while alive and alive[0][0] < f - LIFETIME:  # old bullets go (unless a hit took them already)
            if scene.exists(bullet := alive.popleft()[1]):
                scene.despawn(bullet)

    def steer(scene: Scene, dt: float) -> None:  # arrows in a window; otherwise it weaves by itself
        keys, vel, x = scene.resources[Input], scene.get(ship, Velocity), scene.get(ship, Transform).x
        auto = 240.0 * math.sin(scene.frame * DT * 1.7)
        vel.x = 300.0 * (keys.is_held("right") - keys.is_held("left")) if keys.held else auto
        if (x < 20 and vel.x < 0) or (x > WIDTH - 20 and vel.x > 0):  # stay on screen
            vel.x = 0.0

    def hit(scene: Scene, event) -> None:  # event.a is the ship, event.b the bullet
        if scene.exists(event.b):  # not expired earlier in this step
            stats["hits"] += 1
            scene.despawn(event.b)

    def measure(scene: Scene, dt: float) -> None:  # after the last stage: this step's stage_ms is complete
        for stage, ms in scene.stage_ms.items():
            stats["stage_ms"][stage] = stats["stage_ms"].get(stage, 0.0) + ms
        if getattr(scene.renderer, "window", None) is not None:  # in a window, the title is the HUD
            stages = "  ".join(f"{s} {ms:.2f}" for s, ms in scene.stage_ms.items())
            scene.renderer.window.set_caption(f"{len(alive) + 1} bodies - ms: {stages} - hits {stats['hits']}")

    scene.add_system(fire, before="movement")
    scene.add_system(steer, before="movement")
    scene.add_system(measure, after="render")
    scene.on_collision(Ship, Bullet, hit)
    return scene, stats


def main(argv: list[str] | None = None) -> int:
    prog = f"python -m {__package__ or 'examples'}.bullet_hell"  # framework.examples.bullet_hell when installed
    ap = argparse.ArgumentParser(prog=prog, description=__doc__.splitlines()[0])
    ap.add_argument("--headless", action="store_true", help="run without a window; print a JSON summary")
    ap.add_argument("--frames", type=int, default=None, metavar="N", help="stop after N steps (headless: 600)")
    args = ap.parse_args(argv)
    scene, stats = make_scene()
    if args.headless:
        for _ in range(600 if args.frames is None else args.frames):
            scene.step(DT)
    else:
        from framework.render import run

        run(scene, width=WIDTH, height=HEIGHT, title="bullet hell", max_frames=args.frames)
    mean_ms = {s: round(ms / max(scene.frame, 1), 3) for s, ms in stats["stage_ms"].items()}
    print(json.dumps({"example": "bullet_hell", "frames": scene.frame, "bodies": len(scene.entities),
                      "hits": stats["hits"], "stage_ms": mean_ms}))
    scene.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
