"""Rendering: pixel-exact headless screenshots, the camera, culling, the overlay, the runner.

Every picture is rendered offscreen into an RGBA8 texture (EGL + Mesa's llvmpipe without a
display) and compared exactly. Shapes sit on whole pixel coordinates, so each edge falls between
pixel centres and the expected image is a plain rectangle fill. Pixel ``(sx, sy)`` counts from the
bottom-left (y up); arrays come top row first, so it is ``img[H - 1 - sy, sx]``.

Skipped, with the reason, only where no OpenGL library can make a context.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from framework import AABB, Circle, Hitbox, Polygon, Scene, Text, Transform, Velocity
from framework.components import Visual
from framework.effects import DEFAULT_EFFECTS
from framework.input import Input

RED, GREEN, BLUE, BG = (255, 0, 0), (0, 255, 0), (0, 0, 255), (0, 0, 40)


@pytest.fixture
def scene():
    s = Scene()
    yield s
    s.close()


def canvas(w: int, h: int, color=BG) -> np.ndarray:
    img = np.empty((h, w, 3), dtype=np.uint8)
    img[...] = color
    return img


def rect(img: np.ndarray, x0: int, y0: int, x1: int, y1: int, color) -> np.ndarray:
    """Fill screen pixels x0 <= sx < x1, y0 <= sy < y1 (y up) of a top-row-first image."""
    h = img.shape[0]
    img[h - y1: h - y0, x0:x1] = color
    return img


def px(img: np.ndarray, sx: int, sy: int) -> tuple[int, ...]:
    return tuple(int(v) for v in img[img.shape[0] - 1 - sy, sx, :3])


def count(img: np.ndarray, color) -> int:
    return int((img[..., :3] == np.array(color[:3], dtype=np.uint8)).all(axis=2).sum())


# --- pyglet stays out of the simulation -------------------------------------------------------------


def test_framework_and_a_scene_never_import_pyglet_gl():
    code = textwrap.dedent("""
        import sys
        import framework
        from framework import AABB, Circle, Hitbox, Scene, Transform, Velocity
        from framework.components import Visual
        s = Scene(gravity=(0.0, -10.0))
        s.spawn(Transform(0.0, 0.0), Hitbox(AABB(10.0, 1.0), body="static"), Visual((1, 2, 3)))
        s.spawn(Transform(0.0, 2.0), Velocity(0.0, 0.0), Hitbox(Circle(0.5)), Visual((4, 5, 6)))
        for _ in range(30):
            s.step(1 / 60)
        s.raycast((0.0, 5.0), (0.0, -1.0))
        bad = sorted(m for m in sys.modules
                     if m.split(".")[:2] in (["pyglet", "gl"], ["pyglet", "window"], ["pyglet", "graphics"])
                     or m.startswith("framework.render"))
        print(bad, s.counters["systems"])
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("[] "), out.stdout
    assert "render" not in out.stdout.split("] ", 1)[1]  # no render stage without a renderer


# --- pixels -----------------------------------------------------------------------------------------


def test_a_box_is_drawn_exactly_where_it_is_and_nothing_else(render, scene):
    scene.spawn(Transform(30.0, 20.0), Hitbox(AABB(20.0, 10.0)), Visual(RED))
    img = render.screenshot(scene, width=64, height=48, background=BG)
    assert img.shape == (48, 64, 4) and img.dtype == np.uint8
    assert np.array_equal(img[..., :3], rect(canvas(64, 48), 20, 15, 40, 25, RED))
    assert (img[..., 3] == 255).all()


def test_same_picture_before_and_after_a_step_and_a_static_body(render, scene):
    scene.spawn(Transform(30.0, 20.0), Hitbox(AABB(20.0, 10.0), body="static"), Visual(RED))
    before = render.screenshot(scene, width=64, height=48, background=BG)
    scene.step(1 / 60)  # now the statics come from the spatial hash
    after = render.screenshot(scene, width=64, height=48, background=BG)
    assert np.array_equal(before, after)
    assert np.array_equal(after[..., :3], rect(canvas(64, 48), 20, 15, 40, 25, RED))


def test_camera_offset_moves_the_picture_by_exact_pixels(render, scene):
    scene.spawn(Transform(30.0, 20.0), Hitbox(AABB(20.0, 10.0)), Visual(RED))
    # The camera 7 right of and 3 below the default centre (32, 24): the world shifts 7 left, 3 up.
    img = render.screenshot(scene, width=64, height=48, camera=render.Camera(32.0 + 7.0, 24.0 - 3.0),
                            background=BG)
    assert np.array_equal(img[..., :3], rect(canvas(64, 48), 13, 18, 33, 28, RED))


def test_zoom_scales_about_the_view(render, scene):
    scene.spawn(Transform(30.0, 20.0), Hitbox(AABB(20.0, 10.0)), Visual(RED))
    img = render.screenshot(scene, width=96, height=64, camera=render.Camera(zoom=2.0), background=BG)
    assert np.array_equal(img[..., :3], rect(canvas(96, 64), 40, 30, 80, 50, RED))  # origin stays put
    img = render.screenshot(scene, width=96, height=64, camera=render.Camera(30.0, 20.0, zoom=2.0),
                            background=BG)
    assert np.array_equal(img[..., :3], rect(canvas(96, 64), 28, 22, 68, 42, RED))  # centred on the box


def test_rotation_turns_a_polygon_box_counter_clockwise_and_never_an_aabb(render, scene):
    scene.spawn(Transform(32.0, 24.0, math.pi / 2), Hitbox(Polygon.box(30.0, 10.0)), Visual(RED))
    img = render.screenshot(scene, width=64, height=48, background=BG)
    assert np.array_equal(img[..., :3], rect(canvas(64, 48), 27, 9, 37, 39, RED))
    with Scene() as s2:
        s2.spawn(Transform(32.0, 24.0, math.pi / 2), Hitbox(AABB(30.0, 10.0)), Visual(RED))
        img = render.screenshot(s2, width=64, height=48, background=BG)
        assert np.array_equal(img[..., :3], rect(canvas(64, 48), 17, 19, 47, 29, RED))
    with Scene() as s3:
        # A right triangle along +x; a quarter turn counter-clockwise puts it along +y, left of x = 32.
        s3.spawn(Transform(32.0, 12.0, math.pi / 2), Hitbox(Polygon([(0, 0), (20, 0), (0, 10)])), Visual(RED))
        img = render.screenshot(s3, width=64, height=48, background=BG)
        assert px(img, 27, 14) == RED and px(img, 31, 30) == RED
        assert px(img, 36, 10) == BG and px(img, 36, 14) == BG and px(img, 27, 8) == BG


def test_a_circle_fills_its_disc(render, scene):
    scene.spawn(Transform(32.0, 24.0), Hitbox(Circle(10.0)), Visual(GREEN))
    img = render.screenshot(scene, width=64, height=48, background=BG)
    ys, xs = np.mgrid[0:48, 0:64]
    d = np.hypot(xs + 0.5 - 32.0, (47 - ys) + 0.5 - 24.0)
    green = (img[..., :3] == GREEN).all(axis=2)
    bg = (img[..., :3] == BG).all(axis=2)
    assert green[d <= 9.5].all() and bg[d >= 10.01].all() and (green | bg).all()


def test_higher_z_draws_on_top_whatever_the_spawn_order(render, scene):
    scene.spawn(Transform(24.0, 24.0), Hitbox(AABB(20.0, 20.0)), Visual(RED, z=1))
    scene.spawn(Transform(36.0, 24.0), Hitbox(AABB(20.0, 20.0)), Visual(BLUE, z=0))
    img = render.screenshot(scene, width=64, height=48, background=BG)
    assert px(img, 30, 24) == RED and px(img, 20, 24) == RED and px(img, 42, 24) == BLUE


def test_image_sprites_centre_on_the_entity_and_turn_with_it(render, scene, tmp_path):
    path = tmp_path / "block.png"
    image = np.zeros((4, 6, 4), dtype=np.uint8)
    image[...] = (10, 200, 30, 255)
    render.write_png(path, image)
    e = scene.spawn(Transform(32.0, 24.0), Visual(image=str(path)))  # no hitbox needed for a sprite
    img = render.screenshot(scene, width=64, height=48, background=BG)
    assert np.array_equal(img[..., :3], rect(canvas(64, 48), 29, 22, 35, 26, (10, 200, 30)))
    scene.get(e, Transform).rotation = math.pi / 2
    img = render.screenshot(scene, width=64, height=48, background=BG)
    assert np.array_equal(img[..., :3], rect(canvas(64, 48), 30, 21, 34, 27, (10, 200, 30)))
    # Mostly off screen (centre at x = -2): the sprite's reach keeps it in the view box.
    scene.get(e, Transform).rotation = 0.0
    scene.get(e, Transform).x = -2.0
    img = render.screenshot(scene, width=64, height=48, background=BG)
    assert np.array_equal(img[..., :3], rect(canvas(64, 48), 0, 22, 1, 26, (10, 200, 30)))


def test_invisible_and_visual_less_entities_are_not_drawn(render, scene):
    scene.spawn(Transform(20.0, 20.0), Hitbox(AABB(10.0, 10.0)))
    scene.spawn(Transform(40.0, 20.0), Hitbox(AABB(10.0, 10.0)), Visual(RED, visible=False))
    scene.spawn(Transform(40.0, 40.0), Visual(RED))  # neither a hitbox nor an image: nothing to draw
    img = render.screenshot(scene, width=64, height=48, background=BG)
    assert np.array_equal(img[..., :3], canvas(64, 48))


def test_screenshot_writes_a_png_of_the_returned_pixels(render, scene, tmp_path):
    import pyglet

    scene.spawn(Transform(30.0, 20.0), Hitbox(AABB(20.0, 10.0)), Visual((250, 120, 7)))
    path = tmp_path / "shot.png"
    img = render.screenshot(scene, path, width=64, height=48, background=BG)
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and int.from_bytes(data[16:20], "big") == 64
    decoded = pyglet.image.load(str(path)).get_image_data()
    rgba = np.frombuffer(decoded.get_data("RGBA", -64 * 4), dtype=np.uint8).reshape(48, 64, 4)
    assert np.array_equal(rgba, img)


# --- the render stage: kept drawables, culling ------------------------------------------------------


def test_attached_renderer_updates_its_drawables_in_place(render, scene):
    renderer = render.Renderer(width=64, height=48, background=BG)
    scene.renderer = renderer
    e = scene.spawn(Transform(20.0, 24.0), Velocity(64.0, 0.0), Hitbox(AABB(8.0, 8.0)), Visual(RED))
    scene.step(1 / 16)  # moves 4 px
    assert "render" in scene.counters["systems"]
    assert renderer.stats["made"] == 1
    first = renderer.capture()
    assert np.array_equal(first[..., :3], rect(canvas(64, 48), 20, 20, 28, 28, RED))
    scene.step(1 / 16)
    assert renderer.stats["made"] == 0 and renderer.stats["moved"] == 1
    second = renderer.capture()
    assert np.array_equal(second[..., :3], np.roll(first[..., :3], 4, axis=1))
    # Colour and z are read from the Visual every frame; the drawable is kept.
    scene.get(e, Visual).color = (0, 255, 0, 255)
    scene.get(e, Velocity).x = 0.0
    scene.step(1 / 16)
    assert renderer.stats["made"] == 0 and renderer.stats["moved"] == 0
    assert px(renderer.capture(), 30, 24) == GREEN
    # Gone with its entity.
    scene.despawn(e)
    scene.step(1 / 16)
    assert renderer.stats["drawables"] == 0
    assert np.array_equal(renderer.capture()[..., :3], canvas(64, 48))
    renderer.close()


def test_z_change_at_run_time_reorders(render, scene):
    renderer = render.Renderer(width=64, height=48, background=BG)
    scene.renderer = renderer
    a = scene.spawn(Transform(24.0, 24.0), Hitbox(AABB(20.0, 20.0), sensor=True), Visual(RED, z=1))
    scene.spawn(Transform(36.0, 24.0), Hitbox(AABB(20.0, 20.0), sensor=True), Visual(BLUE, z=0))
    scene.step(1 / 60)
    assert px(renderer.capture(), 30, 24) == RED
    scene.get(a, Visual).z = -1
    scene.step(1 / 60)
    assert renderer.stats["made"] == 0
    assert px(renderer.capture(), 30, 24) == BLUE
    renderer.close()


def test_culling_draws_only_what_the_view_meets(render, scene):
    for i in range(200):  # a long floor of static tiles, 16 units each
        scene.spawn(Transform(8.0 + 16.0 * i, 8.0), Hitbox(AABB(16.0, 16.0), body="static"), Visual(RED))
    for i in range(50):  # moving boxes along the floor
        scene.spawn(Transform(30.0 + 64.0 * i, 40.0), Velocity(0.0, 0.0), Hitbox(AABB(8.0, 8.0)),
                    Visual(BLUE))
    camera = render.Camera(32.0, 24.0)
    renderer = render.Renderer(width=64, height=48, camera=camera)
    scene.renderer = renderer
    calls = []
    static_hash = scene.bodies.hash
    query_box = static_hash.query_box
    static_hash.query_box = lambda *box: calls.append(box) or query_box(*box)
    scene.step(1 / 60)
    assert calls, "the statics are culled through the spatial hash"

    def expected() -> int:
        x0, y0, x1, y1 = camera.view_box()
        g = scene.bodies.ensure_geometry()
        on = (g.minx < x1 + 1) & (g.maxx > x0 - 1) & (g.miny < y1 + 1) & (g.maxy > y0 - 1)
        return int(on.sum())

    assert renderer.stats["drawn"] == expected() == 6  # tiles 0-4 (one pixel of margin) and a box
    assert renderer.stats["drawables"] == 6
    camera.x = 1000.0
    scene.step(1 / 60)
    assert renderer.stats["drawn"] == expected()
    assert renderer.stats["made"] == expected()  # new ones made; the old ones hidden, not deleted
    assert renderer.stats["drawables"] == 6 + expected()
    img = renderer.capture()
    assert px(img, 5, 5) == RED and px(img, 40, 30) == (0, 0, 0)
    renderer.close()


class _Only:
    """``target`` seen through the ``names`` given (and the ``replaced`` ones): reading anything else
    fails, naming what was read."""

    def __init__(self, target, names, **replaced):
        self._target, self._names, self._replaced = target, frozenset(names), replaced

    def __getattr__(self, name):
        if name in self._replaced:
            return self._replaced[name]
        if name not in self._names:
            raise AttributeError(f"read {name!r}, which is not in the renderer's surface (docs/rendering.md)")
        return getattr(self._target, name)


def test_the_renderer_reads_the_scene_only_through_its_surface(render, scene, tmp_path):
    """The names of docs/rendering.md's "What the renderer reads", and no others: the same pixels,
    overlay included, and the same bookkeeping as through the scene itself."""
    sprite = tmp_path / "sprite.png"
    render.write_png(sprite, np.full((4, 6, 4), 200, dtype=np.uint8))
    for i in range(8):
        scene.spawn(Transform(8.0 + 16.0 * i, 8.0), Hitbox(AABB(16.0, 16.0), body="static"), Visual(RED))
    scene.spawn(Transform(40.0, 40.0), Velocity(30.0, 0.0), Hitbox(Circle(6.0)), Visual(GREEN))
    gone = scene.spawn(Transform(80.0, 40.0, 0.3), Velocity(0.0, 0.0), Hitbox(Polygon.box(12.0, 8.0)), Visual(BLUE))
    scene.spawn(Transform(10.0, 70.0), Velocity(900.0, 0.0), Hitbox(Circle(2.0), ccd=True))
    scene.spawn(Transform(100.0, 70.0), Visual(image=str(sprite)))
    scene.spawn(Transform(60.0, 20.0), Text("world", size=8.0))
    scene.spawn(Text("hud", size=8.0, screen=True, corner="top_right", anchor_x="right", anchor_y="top"))
    scene.add_system(lambda s, dt: s.raycast((0.0, 60.0), (1.0, -0.5), 150.0), after="response")
    scene.step(1 / 30)
    assert scene.bodies.static_hash_current
    bodies = _Only(scene.bodies, {"store", "ensure_geometry", "rows_of", "static_hash_current", "static_rows_in_box",
                                  "hash"})
    view = _Only(scene, {"step_frame", "try_get", "exists", "frame", "renderer", "query"}, bodies=bodies)
    for debug in (False, True):
        expected = render.screenshot(scene, width=128, height=96, background=BG, debug=debug)
        seen = render.screenshot(view, width=128, height=96, background=BG, debug=debug)
        assert np.array_equal(seen, expected), debug
    renderer = render.Renderer(width=128, height=96)
    try:
        renderer.draw(view)
        assert renderer.stats["drawables"] == 11
        scene.despawn(gone)
        renderer.draw(view)  # the drawable of a despawned entity goes (found through bodies.rows_of)
        assert renderer.stats["drawables"] == 10 and renderer.scene_entities == 12  # (the world text's)
    finally:
        renderer.close()


def test_render_modules_import_one_way():
    """No module of framework.render imports one that imports it back (at the top or in a function)."""
    import ast
    from pathlib import Path

    package = Path(__file__).resolve().parents[1] / "framework" / "render"
    imports = {}
    for path in package.glob("*.py"):
        tree = ast.parse(path.read_text())
        imports[path.stem] = {node.module.split(".")[0] for node in ast.walk(tree)
                              if isinstance(node, ast.ImportFrom) and node.level == 1 and node.module}

    def reaches(start, goal, seen=()):
        return any(m == goal or (m not in seen and reaches(m, goal, (*seen, m))) for m in imports.get(start, ()))

    cycles = sorted(m for m in imports if m != "__init__" and reaches(m, m))
    assert cycles == [], f"import cycles through {cycles}"
    assert "headless" not in imports["renderer"] and "renderer" not in imports["offscreen"]


# --- camera -----------------------------------------------------------------------------------------


def test_camera_follows_its_target_within_the_level(render, scene):
    e = scene.spawn(Transform(100.0, 50.0))
    cam = render.Camera(target=e, bounds=(0.0, 0.0, 400.0, 200.0))
    cam.update(scene, 100, 60)
    assert cam.center == (100.0, 50.0)
    assert cam.view_box() == (50.0, 20.0, 150.0, 80.0)
    assert cam.world_to_screen(100.0, 50.0) == (50.0, 30.0)
    assert cam.screen_to_world(0.0, 0.0) == (50.0, 20.0)
    scene.get(e, Transform).x = 10.0  # near the left end: the view stops at the level's edge
    scene.get(e, Transform).y = 195.0
    cam.update(scene, 100, 60)
    assert cam.view_box() == (0.0, 140.0, 100.0, 200.0)
    cam.zoom = 2.0  # zoomed in, the view is 50 x 30 world units
    cam.update(scene, 100, 60)
    assert cam.view_box() == (0.0, 170.0, 50.0, 200.0)
    cam.bounds = (0.0, 0.0, 40.0, 400.0)  # narrower than the view: centred across
    cam.update(scene, 100, 60)
    assert cam.center[0] == 20.0
    scene.despawn(e)  # a vanished target: the camera stays
    cam.update(scene, 100, 60)
    assert cam.center[0] == 20.0
    with pytest.raises(ValueError):
        render.Camera(zoom=0.0)
    with pytest.raises(ValueError):
        render.Camera(bounds=(0.0, 0.0, -1.0, 1.0))


def test_camera_target_and_bounds_in_pixels(render, scene):
    # Level 0..200 x 0..100 in a 64 x 48 view; the player near the right end.
    scene.spawn(Transform(100.0, 50.0), Hitbox(AABB(200.0, 100.0), body="static"), Visual(BLUE, z=-1))
    p = scene.spawn(Transform(195.0, 50.0), Hitbox(AABB(4.0, 4.0)), Visual(RED))
    cam = render.Camera(target=p, bounds=(0.0, 0.0, 200.0, 100.0))
    img = render.screenshot(scene, width=64, height=48, camera=cam, background=BG)
    # The view's right edge is the level's (x = 200): the player (193..197) is 3 px from it.
    expect = rect(canvas(64, 48, BLUE), 64 - 7, 22, 64 - 3, 26, RED)
    assert np.array_equal(img[..., :3], expect)


# --- text ------------------------------------------------------------------------------------------

# Glyphs are antialiased: a text pixel is a blend of its colour and the background. The world texts
# below are green and the screen texts yellow, so on the blue background a pixel with green and no
# red is a world text's, one with red and green a screen text's.
WORLD_TEXT, SCREEN_TEXT = (0, 255, 0), (255, 255, 0)


def _inked(img: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Masks (top row first) of the world texts' pixels and the screen texts' pixels."""
    r, g = img[..., 0].astype(int), img[..., 1].astype(int)
    return (r == 0) & (g > 0), (r > 0) & (g > 0)


def _box(mask: np.ndarray) -> tuple[int, int, int, int]:
    """x0, y0, x1, y1 (screen pixels, y up, inclusive) of the lit pixels of a top-row-first mask."""
    ys, xs = np.nonzero(mask)
    h = mask.shape[0]
    return int(xs.min()), int(h - 1 - ys.max()), int(xs.max()), int(h - 1 - ys.min())


def _text_scene(s: Scene) -> tuple[int, int]:
    world = s.spawn(Transform(40.0, 60.0), Text("Hi there", size=10.0, color=WORLD_TEXT))
    hud = s.spawn(Text("coins 3", size=10.0, color=SCREEN_TEXT, screen=True, corner="top_left",
                       offset=(4.0, -4.0), anchor_y="top"))
    return world, hud


def test_text_is_drawn_where_its_label_is_and_nowhere_else(render, scene):
    _text_scene(scene)
    img = render.screenshot(scene, width=160, height=100, background=BG)
    world, hud = _inked(img)
    assert world.sum() > 30 and hud.sum() > 30
    x0, y0, x1, y1 = _box(world)  # its layout's bottom left at the entity (40, 60): ink just above
    assert 40 <= x0 <= 42 and 60 <= y0 <= 66 and 60 < x1 < 100 and 66 < y1 < 80, (x0, y0, x1, y1)
    x0, y0, x1, y1 = _box(hud)  # top left at (4, 100 - 4), below and right of it
    assert 4 <= x0 <= 6 and 86 <= y1 <= 96 and 30 < x1 < 70 and y0 > 70, (x0, y0, x1, y1)
    rest = ~(img[..., :3] == BG).all(axis=2) & ~world & ~hud
    assert not rest.any()  # nothing but the two texts on the background
    without = render.screenshot(Scene(), width=160, height=100, background=BG)
    assert (without[..., :3] == BG).all()


def test_a_screen_text_at_a_corner_hangs_inside_the_view_by_default(render, scene):
    # no anchors given: a top corner's text hangs below its point, a right corner's ends at it,
    # the same pixels as with the anchors spelt out (before, the default bottom-left anchor drew a
    # top-left HUD line above the view's top edge, clipped)
    defaults = [Text("coins 3", size=10.0, color=SCREEN_TEXT, screen=True, corner=c, offset=o)
                for c, o in (("top_left", (4.0, -4.0)), ("top_right", (-4.0, -4.0)), ("bottom_right", (-4.0, 4.0)))]
    assert [(t.anchor_x, t.anchor_y) for t in defaults] == [("left", "top"), ("right", "top"), ("right", "bottom")]
    assert (Text("x").anchor_x, Text("x").anchor_y) == ("left", "bottom")  # a world text's
    assert (Text("x", screen=True, corner="center").anchor_x, Text("x", screen=True, corner="center").anchor_y) == \
        ("center", "center")
    for t in defaults:
        scene.spawn(t)
    img = render.screenshot(scene, width=160, height=100, background=BG)
    spelt = Scene()
    for t in defaults:
        spelt.spawn(Text(t.text, size=10.0, color=SCREEN_TEXT, screen=True, corner=t.corner, offset=t.offset,
                         anchor_x=t.anchor_x, anchor_y=t.anchor_y))
    assert np.array_equal(img, render.screenshot(spelt, width=160, height=100, background=BG))
    _world, hud = _inked(img)
    rows = np.flatnonzero(hud.any(axis=1))  # (top first) every line fully inside, none at an edge
    cols = np.flatnonzero(hud.any(axis=0))
    assert rows.size and rows[0] >= 4 and rows[-1] <= 100 - 4 and cols[0] >= 4 and cols[-1] <= 160 - 4
    assert hud[:50].sum() > 30 and hud[50:].sum() > 30  # the top two and the bottom one all drawn


def test_a_world_text_moves_with_the_camera_and_a_screen_text_does_not(render, scene):
    _text_scene(scene)
    a = render.screenshot(scene, width=160, height=100, background=BG)
    # The camera 11 right of and 7 above the default centre (80, 50): the world shifts 11 left, 7 down.
    b = render.screenshot(scene, width=160, height=100, camera=render.Camera(80.0 + 11.0, 50.0 + 7.0),
                          background=BG)
    (world_a, hud_a), (world_b, hud_b) = _inked(a), _inked(b)
    assert np.array_equal(hud_a, hud_b)  # the HUD stays put, pixel for pixel
    assert np.array_equal(a[hud_a], b[hud_b])
    assert world_a.sum() == world_b.sum() > 30
    assert np.array_equal(world_b[7:, :-11], world_a[:-7, 11:])  # rows are top first: down is +7
    # Zoomed 2x, centred on (70, 60): the text's anchor (40, 60) lands at (80 - 2 x 30, 50) = (20, 50).
    zoomed = render.screenshot(scene, width=160, height=100, camera=render.Camera(70.0, 60.0, zoom=2.0),
                               background=BG)
    world_z, hud_z = _inked(zoomed)
    assert np.array_equal(hud_z, hud_a)  # zoom leaves the HUD alone
    assert world_z.sum() > 2 * world_a.sum()  # and scales the world's text (about 4 times the ink)
    x0, y0, x1, _y1 = _box(world_z)
    ax0, _ay0, ax1, _ay1 = _box(world_a)
    assert 20 <= x0 <= 24 and 50 <= y0 <= 62 and x1 - x0 >= 2 * (ax1 - ax0) - 2, (x0, y0, x1)


def test_text_changes_show_in_an_attached_renderer(render, scene):
    world, hud = _text_scene(scene)
    r = render.Renderer(width=160, height=100, background=BG)
    scene.renderer = r
    try:
        scene.step(1 / 60)
        first = r.capture()
        text = scene.get(hud, Text)
        text.text = "coins 3"  # the same: no change
        assert np.array_equal(r.capture(), first)
        text.text = "coins 12345"  # longer: more ink, further right, shown without a step
        longer = _inked(r.capture())[1]
        assert _box(longer)[2] > _box(_inked(first)[1])[2]
        scene.get(world, Transform).x += 20.0  # the world text follows its entity
        scene.step(1 / 60)
        moved = _inked(r.capture())[0]
        assert np.array_equal(moved[:, 20:], _inked(first)[0][:, :-20])
        scene.get(world, Text).visible = False
        text.text = ""
        img = r.capture()
        assert (img[..., :3] == BG).all()
        scene.despawn(hud)
        scene.get(world, Text).visible = True
        scene.step(1 / 60)
        world_ink, hud_ink = _inked(r.capture())
        assert world_ink.any() and not hud_ink.any()
    finally:
        r.close()


def test_a_world_text_without_a_transform_is_not_drawn(render, scene):
    scene.spawn(Text("lost", color=WORLD_TEXT))
    img = render.screenshot(scene, width=64, height=48, background=BG)
    assert (img[..., :3] == BG).all()


@pytest.mark.parametrize("field, value, says", [
    ("size", 0, "size must be finite and > 0"), ("size", -3.0, "size must be finite and > 0"),
    ("size", float("nan"), "size must be finite and > 0"), ("offset", (float("nan"), 0.0), "offset[0] must be finite"),
    ("offset", (1.0, float("inf")), "offset[1] must be finite"), ("offset", 3.0, "offset must be a pair"),
    ("color", (300, 0, 0), "color must be 3 or 4 ints"), ("color", (1.5, 0, 0), "color must be 3 or 4 ints"),
    ("color", 7, "color must be (r, g, b)"), ("corner", "middle", "corner must be one of"),
    ("anchor_x", "top", "anchor_x must be one of"), ("anchor_y", 3, "anchor_y must be one of"),
    ("text", 12, "text must be a str"), ("text", "two\nlines", "one line"), ("z", 1.0, "z must be an int"),
    ("z", True, "z must be an int"), ("screen", 1, "screen must be True or False"),
    ("visible", "no", "visible must be True or False"), ("font", "", "font must be a font family name"),
])
def test_bad_text_values_raise_value_error_naming_them(field, value, says):
    with pytest.raises(ValueError, match=re.escape(says)) as info:
        if field == "text":
            Text(value)
        else:
            Text("ok", **{field: value})
    assert str(info.value).startswith("Text ") and "got" in str(info.value)  # which field, what it got
    text = Text("ok")
    before = text.version
    with pytest.raises(ValueError, match=re.escape(says)):
        setattr(text, field, value)  # the same when set later; the text keeps its value
    assert text.version == before and text.text == "ok"


def test_text_is_light_data_and_round_trips_through_a_snapshot_file(tmp_path):
    import pickle

    from framework.snapshot_file import load_snapshot, save_snapshot

    code = "import sys, framework; framework.Text('a'); print(any(m.startswith('pyglet') for m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.stdout.strip() == "False", out.stderr
    with Scene() as s:
        e = s.spawn(Text("score 1", size=12.0, screen=True, corner="top_right", offset=(-4.0, -4.0)))
        path = tmp_path / "snap.npz"
        save_snapshot(s, path)
        s.get(e, Text).text = "score 2"
        load_snapshot(s, path)
        back = s.get(e, Text)
        assert (back.text, back.size, back.corner, back.offset) == ("score 1", 12.0, "top_right", (-4.0, -4.0))
    copy = pickle.loads(pickle.dumps(back))
    assert copy.text == "score 1" and copy.color == (255, 255, 255, 255)


# --- the debug overlay ------------------------------------------------------------------------------


def test_overlay_outlines_every_hitbox_in_its_colour(render):
    colors = render.OVERLAY_COLORS
    scene = Scene(cell_size=64.0)  # hash cell lines at multiples of 64, away from the pixels tested
    scene.spawn(Transform(30.0, 20.0), Hitbox(AABB(20.0, 10.0), body="static"))  # no Visual
    scene.spawn(Transform(80.0, 20.0), Velocity(0.0, 0.0), Hitbox(AABB(20.0, 10.0)), Visual(RED))
    scene.step(1 / 60)
    plain = render.screenshot(scene, width=128, height=96, background=BG)
    assert px(plain, 30, 15) == BG
    img = render.screenshot(scene, width=128, height=96, background=BG, debug=True)
    # Lines are drawn half a pixel in: an edge at x (or y) lights pixel column (row) x.
    assert px(img, 30, 15) == colors["static"][:3] and px(img, 30, 25) == colors["static"][:3]
    assert px(img, 20, 20) == colors["static"][:3] and px(img, 40, 20) == colors["static"][:3]
    assert px(img, 30, 20) == BG  # an outline, not a fill
    assert px(img, 80, 15) == colors["dynamic"][:3] and px(img, 80, 20) == RED
    scene.close()


def test_overlay_shows_contacts_sweeps_rays_cells_and_the_text_line(render, scene):
    colors = render.OVERLAY_COLORS
    scene.spawn(Transform(40.0, 20.0), Velocity(0.0, 0.0), Hitbox(AABB(20.0, 20.0)))
    scene.spawn(Transform(55.0, 20.0), Velocity(0.0, 0.0), Hitbox(AABB(20.0, 20.0)))
    scene.spawn(Transform(20.0, 60.0), Velocity(600.0, 0.0), Hitbox(Circle(2.0), ccd=True))
    scene.spawn(Transform(150.0, 20.0), Hitbox(AABB(20.0, 20.0), body="static"))
    scene.add_system(lambda s, dt: s.raycast((100.0, 80.0), (1.0, -1.0), 200.0), after="response")
    scene.step(1 / 30)
    assert len(scene.contacts.a) == 1 and scene.swept_paths and scene.ray_log
    img = render.screenshot(scene, width=200, height=120, background=BG, debug=True)
    for key in ("contact", "normal", "swept", "ray", "ray_rest", "cell"):
        assert count(img, colors[key]) > 0, key
    assert count(img[:36, :120], colors["text"]) > 20  # the text line, top left
    without = render.screenshot(scene, width=200, height=120, background=BG)
    assert count(without, colors["swept"]) == 0


@pytest.mark.parametrize("friction", [0.5, None])
def test_overlay_shows_the_friction_in_use(render, friction):
    colors = render.OVERLAY_COLORS
    with Scene(gravity=(0.0, -200.0), cell_size=256.0) as s:
        s.spawn(Transform(100.0, 10.0), Hitbox(AABB(200.0, 20.0), body="static"))
        s.spawn(Transform(40.0, 30.0), Velocity(100.0, 0.0), Hitbox(AABB(20.0, 20.0), friction=friction))
        for _ in range(3):
            s.step(1 / 60)
        img = render.screenshot(s, width=200, height=120, background=BG, debug=True)
        lit = count(img, colors["friction"])
        assert (lit > 0) == (friction is not None), lit  # sliding: a line along the floor, backwards


@pytest.mark.parametrize("turns", [True, False])
def test_overlay_marks_the_points_a_turning_box_rests_on(render, turns):
    """A box resting on its face: with the rotation effect the solver pushes at its two corners,
    and the overlay marks both (a diamond each, near the box's lower corners); without, none."""
    colors = render.OVERLAY_COLORS
    effects = None if turns else DEFAULT_EFFECTS - {"rotation"}
    with Scene(gravity=(0.0, -200.0), cell_size=256.0, effects=effects) as s:
        s.spawn(Transform(100.0, 10.0), Hitbox(AABB(200.0, 20.0), body="static"))
        s.spawn(Transform(100.0, 40.0), Velocity(), Hitbox(Polygon.box(40.0, 40.0)))
        for _ in range(4):
            s.step(1 / 60)
        img = render.screenshot(s, width=200, height=120, background=BG, debug=True)
        lit = np.argwhere(np.all(img[..., :3] == colors["point"][:3], axis=-1))
        if not turns:
            assert lit.size == 0
            return
        xs = lit[:, 1]
        assert (np.abs(xs - 80) <= 4).any() and (np.abs(xs - 120) <= 4).any(), sorted(set(xs.tolist()))


def test_overlay_draws_each_moving_body_s_velocity(render):
    """A line from the body's position to where its velocity takes it in VELOCITY_SECONDS; none for
    a body at rest."""
    from framework.render.overlay import VELOCITY_SECONDS

    colors = render.OVERLAY_COLORS
    with Scene(cell_size=256.0) as s:
        s.spawn(Transform(40.0, 40.0), Velocity(80.0, 0.0), Hitbox(AABB(4.0, 4.0), sensor=True))
        s.spawn(Transform(40.0, 80.0), Velocity(0.0, 0.0), Hitbox(AABB(4.0, 4.0), sensor=True))
        img = render.screenshot(s, width=128, height=96, background=BG, debug=True)
        reach = int(80.0 * VELOCITY_SECONDS)  # 20 px
        lit = np.argwhere(np.all(img[..., :3] == colors["velocity"][:3], axis=-1))
        assert sorted(set((96 - 1 - lit[:, 0]).tolist())) == [40]  # one row, y = 40
        assert sorted(lit[:, 1].tolist()) == list(range(40, 40 + reach))  # from x = 40, 20 px long


def _all_stages_scene(solver: str) -> Scene:
    """A scene whose step runs every stage its solver has (a character, a swept body, a pile)."""
    from framework import CharacterController

    s = Scene(gravity=(0.0, -200.0), solver=solver)
    s.spawn(Transform(400.0, 10.0), Hitbox(AABB(800.0, 20.0), body="static"), Visual((90, 70, 50)))
    for i in range(6):
        s.spawn(Transform(300.0 + 22.0 * i, 40.0), Velocity(), Hitbox(AABB(20.0, 20.0)), Visual(RED))
    s.spawn(Transform(100.0, 200.0), Velocity(300.0, 0.0), Hitbox(Circle(4.0), ccd=True), Visual(GREEN))
    if solver == "exact":
        s.spawn(Transform(600.0, 40.0), Velocity(), Hitbox(AABB(16.0, 30.0), body="kinematic"), CharacterController(),
                Visual(BLUE))
    return s


@pytest.mark.parametrize("solver", ["exact", "soft"])
def test_overlay_shows_every_stage_timing_within_an_800_pixel_window(render, solver):
    """Issue 36: the stage timings ran off the right edge of an 800 x 600 window. Each figure is
    shown whole, every line fits the width, and the screenshot has text on each line's row and
    none past the widest line."""
    from framework.render.overlay import HUD_LINE_PX

    text = render.OVERLAY_COLORS["text"][:3]
    with _all_stages_scene(solver) as s:
        r = render.Renderer(width=800, height=600, debug=True, background=BG)
        s.renderer = r
        for _ in range(3):
            s.step(1 / 60)
        stages = set(s.stage_ms)
        expected = {"soft_step", "sleeping", "render"} if solver == "soft" else {
            "movement", "ccd", "broad_phase", "narrow_phase", "response", "character", "sleeping", "render"}
        assert stages == expected
        for name in s.stage_ms:  # the widest figures a stage can plausibly show
            s.stage_ms[name] = 888.88
        r.fps = 888.0
        r.draw(s)  # the overlay's text is built by the render stage
        img = r.capture()
        overlay = r._overlay
        lines = overlay.lines(r.width, r.height)
        shown = "  ".join(lines)
        for name in stages:
            assert f"{name} 888.88" in shown, (name, lines)  # whole: the name and its figure together
        assert f"total {888.88 * len(stages):.2f}" in shown and "FPS 888" in shown
        widths = overlay.label_widths()
        assert len(widths) == len(lines) >= 2
        assert max(widths) <= 800 - 2 * 6, widths
        hud = np.all(img[:, :, :3] == text, axis=-1)
        cols = np.flatnonzero(hud.any(axis=0))
        assert cols.max() < 6 + max(widths) < 800 - 1, cols.max()  # nothing cut at the right edge
        for i in range(len(lines)):  # each line's row of text is drawn
            top = 4 + HUD_LINE_PX * i
            assert hud[top: top + HUD_LINE_PX].sum() > 20, i
        assert not hud[4 + HUD_LINE_PX * len(lines) + 4:].any()  # and nothing below the last
        if solver == "exact":
            assert len(lines) >= 3  # the stage line needed wrapping at this width
        r.close()


def test_wrap_figures_breaks_between_figures_only():
    from framework.render.overlay import wrap_figures

    def measure(t):
        return 10.0 * len(t)

    text = "head 1  two 2\nms/step: aaa 1.00  bbb 2.00  ccc 3.00"
    assert wrap_figures(text, 1000, measure) == ["head 1  two 2", "ms/step: aaa 1.00  bbb 2.00  ccc 3.00"]
    assert wrap_figures(text, 200, measure) == ["head 1  two 2", "ms/step: aaa 1.00", "  bbb 2.00  ccc 3.00"]
    assert wrap_figures("a-very-long-figure 1  b 2", 50, measure) == ["a-very-long-figure 1", "  b 2"]
    # At most two lines: each source line keeps one, its overflow running on past the width.
    assert wrap_figures(text, 200, measure, max_lines=2) == text.split("\n")
    assert wrap_figures(text, 200, measure, max_lines=0) == text.split("\n")  # never fewer than it has
    assert wrap_figures(text, 100, measure, max_lines=3) == [
        "head 1", "  two 2", "ms/step: aaa 1.00  bbb 2.00  ccc 3.00"]


def test_scene_effect_debug_overlay_turns_the_overlay_on(render):
    with Scene(effects=["movement", "detection", "debug_overlay"]) as s:
        r = render.Renderer(width=32, height=32)
        s.renderer = r
        assert r.debug
        r.close()


# --- the window runner ------------------------------------------------------------------------------


def test_key_names_are_lower_case_names(render):
    from pyglet.window import key

    names = [render.key_name(k) for k in (key.LEFT, key.SPACE, key.A, key.F1, key.ESCAPE, key._1, key.R)]
    assert names == ["left", "space", "a", "f1", "escape", "1", "r"]


def test_runner_feeds_keys_to_input_toggles_overlay_and_restarts(render, scene):
    from pyglet.window import key

    seen = []
    fresh = Scene()

    def on_key(s, name):
        seen.append(name)
        return fresh if name == "r" else None

    runner = render.Runner(scene, width=64, height=48, on_key=on_key)
    try:
        assert scene.renderer is runner.renderer
        runner.on_key_press(key.LEFT, 0)
        inp = scene.resources[Input]
        assert inp.held == {"left"} and inp.pressed == {"left"}
        assert runner.tick(runner.dt) == 1  # the step saw the press; the edge is then forgotten
        assert inp.pressed == set() and inp.held == {"left"}
        runner.on_key_release(key.LEFT, 0)
        assert inp.released == {"left"}
        assert not runner.renderer.debug
        runner.on_key_press(key.F1, 0)
        assert runner.renderer.debug
        runner.on_key_press(key.D, 0)  # held into the new scene
        runner.on_key_press(key.R, 0)
        assert runner.scene is fresh and fresh.renderer is runner.renderer and scene.renderer is None
        assert fresh.resources[Input].held == {"d", "f1", "r"}
        assert seen == ["left", "f1", "d", "r"]
        runner.frame()  # steps and draws one frame into the window
        assert runner.frames == 1
        runner.on_key_press(key.ESCAPE, 0)
        assert runner.window.context is None  # closed
    finally:
        runner.close()
        fresh.close()


def test_runner_fixed_timestep_accumulator(render, scene):
    runner = render.Runner(scene, width=32, height=32, fps=60)
    try:
        dt = runner.dt
        assert runner.tick(0.5 * dt) == 0
        assert runner.tick(0.5 * dt) == 1  # the two halves make a step
        assert runner.tick(3 * dt) == 3
        assert scene.frame == 4 and scene.time == pytest.approx(4 * dt)
        # A stall: at most MAX_STEPS_PER_FRAME steps, the rest of the time is dropped.
        assert runner.tick(10.0) == render.window.MAX_STEPS_PER_FRAME
        assert runner.accumulator <= dt
    finally:
        runner.close()


def test_run_twice_in_one_process_opens_a_window_each_time(render):
    # pyglet's app.run() leaves the window event queue off when it returns; a window made after
    # that handled its first resize before it could draw, so a second run() (a game's restart,
    # a menu's "play again") failed with AttributeError 'ubo'
    for k in range(2):
        s = Scene()
        render.run(s, width=48, height=32, max_frames=2)
        assert s.frame >= 1, k


def test_run_opens_steps_and_closes(render, scene, monkeypatch):
    e = scene.spawn(Transform(10.0, 10.0), Velocity(60.0, 0.0), Hitbox(AABB(4.0, 4.0)), Visual(RED))
    seen = []
    init = render.window.Runner.__init__

    def spy(self, *args, **kwargs):
        init(self, *args, **kwargs)
        seen.append(self.renderer.background)

    monkeypatch.setattr(render.window.Runner, "__init__", spy)
    render.run(scene, width=64, height=48, max_frames=3, debug=True, background=BG)
    assert seen == [tuple(BG)]
    assert scene.frame >= 1 and scene.renderer is None
    assert scene.get(e, Transform).x > 10.0
