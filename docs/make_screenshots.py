"""Make the images of docs/rendering.md from the code itself (headless; no display needed).

    python docs/make_screenshots.py          # writes docs/images/rendering.png and rendering_debug.png

A small level (static tiles, a one-way ledge, a slope), a stack of boxes falling onto it, a
rotating polygon, a ball, a fast continuous-detection bullet and a ray, stepped a few times and
then rendered twice: as the game shows it, and with the debug overlay.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from framework import AABB, Circle, Hitbox, Polygon, Scene, Transform, Velocity  # noqa: E402
from framework.components import Visual  # noqa: E402
from framework.render import Camera, screenshot  # noqa: E402

OUT = ROOT / "docs" / "images"
TILE = 16.0


def build_scene() -> Scene:
    """The demo scene, stepped to an interesting moment. World units are pixels at zoom 1."""
    scene = Scene(gravity=(0.0, -600.0), cell_size=32.0)
    ground, ledge, wall = (90, 70, 50), (150, 120, 80), (70, 80, 95)
    for i in range(45):  # the floor: a row of static tiles
        scene.spawn(Transform(i * TILE + TILE / 2, TILE / 2), Hitbox(AABB(TILE, TILE), body="static"),
                    Visual(ground, z=0))
    for j in range(1, 12):  # a wall on the right
        scene.spawn(Transform(44 * TILE + TILE / 2, j * TILE + TILE / 2),
                    Hitbox(AABB(TILE, TILE), body="static"), Visual(wall, z=0))
    scene.spawn(Transform(120.0, 90.0), Hitbox(AABB(96.0, 8.0), body="static", one_way=True), Visual(ledge))
    scene.spawn(Transform(300.0, 40.0), Hitbox(Polygon([(-60, -24), (60, -24), (60, 24)]), body="static"),
                Visual(ground))
    colors = [(230, 80, 70), (240, 170, 60), (90, 200, 110), (80, 150, 230)]
    for k in range(4):  # a stack of boxes dropping onto the floor
        scene.spawn(Transform(500.0 + 3 * k, 40.0 + 26.0 * k), Velocity(0.0, 0.0), Hitbox(AABB(24.0, 24.0)),
                    Visual(colors[k], z=1))
    scene.spawn(Transform(200.0, 150.0, 0.4), Velocity(40.0, 0.0, 1.5),
                Hitbox(Polygon([(-18, -10), (16, -14), (22, 8), (-4, 18)])), Visual((200, 110, 220), z=1))
    scene.spawn(Transform(60.0, 140.0), Velocity(60.0, 20.0), Hitbox(Circle(12.0), restitution=0.6),
                Visual((250, 230, 90), z=1))
    scene.spawn(Transform(-300.0, 60.0), Velocity(2400.0, 0.0), Hitbox(Circle(3.0), ccd=True, mass=0.1),
                Visual((255, 255, 255), z=2))
    scene.spawn(Transform(620.0, 160.0), Hitbox(AABB(40.0, 40.0), sensor=True, body="static"))  # a trigger

    def probe(s: Scene, dt: float) -> None:  # a game system casting a ray each step
        s.raycast((20.0, 120.0), (math.cos(-0.35), math.sin(-0.35)), 400.0)

    scene.add_system(probe, before="response")
    for _ in range(14):
        scene.step(1.0 / 60.0)
    return scene


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    scene = build_scene()
    camera = Camera(360.0, 110.0, zoom=1.0, bounds=(0.0, 0.0, 720.0, 400.0))
    screenshot(scene, OUT / "rendering.png", width=720, height=220, camera=camera, background=(24, 26, 34))
    screenshot(scene, OUT / "rendering_debug.png", width=720, height=220, camera=camera, debug=True,
               background=(24, 26, 34))
    print(f"wrote {OUT / 'rendering.png'} and {OUT / 'rendering_debug.png'}")


if __name__ == "__main__":
    main()
