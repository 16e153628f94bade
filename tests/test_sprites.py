"""Sprite sheets, animations, flips and the atlas: headless, pixel-exact, and bad input named.

Pixels are read from offscreen screenshots (see tests/test_render.py): ``img[H - 1 - sy, sx]`` is
screen pixel ``(sx, sy)`` counted from the bottom-left.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from framework import AABB, Hitbox, Scene, Transform, Velocity
from framework.components import Visual
from framework.sprites import Animation, Frame, SpriteSheet, image_size
from framework.validation import InvalidValue

BG = (0, 0, 40)
COLORS = [(255, 0, 0), (0, 255, 0), (0, 0, 255), (255, 255, 0)]


def write(path, rgba: np.ndarray) -> str:
    from framework.render.offscreen import write_png

    write_png(path, rgba)
    return str(path)


@pytest.fixture
def sheet(tmp_path):
    """4 frames of 4 x 2 pixels in a row, each one colour; frame 1's left column is white."""
    img = np.zeros((2, 16, 4), dtype=np.uint8)
    for k, c in enumerate(COLORS):
        img[:, 4 * k: 4 * k + 4] = (*c, 255)
    img[:, 4] = (255, 255, 255, 255)
    return SpriteSheet(write(tmp_path / "sheet.png", img), 4, 2)


def shot(render, scene, w=16, h=8):
    return render.screenshot(scene, width=w, height=h, background=BG)


def px(img, sx, sy):
    return tuple(int(v) for v in img[img.shape[0] - 1 - sy, sx, :3])


# --- data -------------------------------------------------------------------------------------------


def test_a_sheet_is_cut_row_by_row_from_the_top_left(tmp_path):
    path = write(tmp_path / "grid.png", np.zeros((10, 8, 4), dtype=np.uint8))  # 8 x 10
    s = SpriteSheet(path, 3, 4, margin=1, spacing=0)  # 2 x 2 frames inside a 1-pixel margin
    assert (s.columns, s.rows, len(s)) == (2, 2, 4)
    assert s[0] == Frame(path, 1, 1, 3, 4) and s[1] == Frame(path, 4, 1, 3, 4) and s[2] == Frame(path, 1, 5, 3, 4)
    assert image_size(path) == (8, 10)
    spaced = SpriteSheet(write(tmp_path / "sp.png", np.zeros((2, 11, 4), dtype=np.uint8)), 3, 2, spacing=1)
    assert [f.x for f in spaced.frames] == [0, 4, 8]


def test_an_animation_picks_its_frame_by_elapsed_time_looping_or_holding(sheet):
    a = sheet.animation([0, 1, 2], [0.25, 0.5, 0.25])
    assert [a.index_at(t) for t in (0.0, 0.24, 0.25, 0.74, 0.75, 0.99, 1.0, 1.25, 2.5)] == [0, 0, 1, 1, 2, 2, 0, 1, 1]
    once = sheet.animation([0, 1], 0.125, loop=False)
    assert [once.index_at(t) for t in (-1.0, 0.0, 0.125, 10.0)] == [0, 0, 1, 1]
    assert a.total == 1.0 and a == sheet.animation([0, 1, 2], [0.25, 0.5, 0.25]) and hash(a) == hash(
        sheet.animation([0, 1, 2], [0.25, 0.5, 0.25]))
    assert np.array_equal(a.indices_at(np.array([0.0, 0.3, 0.8])), [0, 1, 2])


def test_visual_frame_at_follows_the_scene_clock_from_spawn_and_play(sheet):
    run, jump = sheet.animation([0, 1, 2, 3], 0.25), sheet.animation([3], 1.0, loop=False)
    with Scene() as s:
        s.step(0.5)  # spawned at t = 0.5: the animation starts there
        e = s.spawn(Transform(0.0, 0.0), Visual(animation=run))
        vis = s.get(e, Visual)
        assert vis.started == 0.5 and vis.frame_at(s.time) == sheet[0]
        for _ in range(3):
            s.step(0.25)
        assert vis.frame_at(s.time) == sheet[3]
        vis.play(run, s.time)  # the animation already shown: nothing restarts
        assert vis.started == 0.5
        vis.play(jump, s.time)
        assert vis.started == s.time == 1.25 and vis.frame_at(s.time + 5.0) == sheet[3]
        vis.play(jump, 2.0, restart=True)
        assert vis.started == 2.0


def test_snapshot_restore_keeps_the_animation_clock(sheet):
    run = sheet.animation([0, 1, 2, 3], 0.25)
    with Scene() as s:
        e = s.spawn(Transform(0.0, 0.0), Visual(animation=run))
        s.step(0.25)
        snap = s.snapshot()
        s.step(0.25)
        s.step(0.25)
        s.restore(snap)
        assert s.get(e, Visual).frame_at(s.time) == sheet[1]


@pytest.mark.parametrize("bad, match", [
    (lambda sh: Animation([], 0.1), "at least one frame"),
    (lambda sh: sh.animation([0, 1], 0.0), "> 0"),
    (lambda sh: sh.animation([0, 1], -0.1), "> 0"),
    (lambda sh: sh.animation([0, 1], math.nan), "nan"),
    (lambda sh: sh.animation([0, 1], [0.1, math.inf]), "frame 1"),
    (lambda sh: sh.animation([0, 1], [0.1]), "2 frames but 1 durations"),
    (lambda sh: Animation(["x.png"], 0.1), "must be a Frame"),
    (lambda sh: sh[4], "no frame 4"),
    (lambda sh: Visual(animation="run"), "Animation"),
    (lambda sh: Visual(frame=(0, 0, 1, 1)), "Frame"),
    (lambda sh: Frame("a.png", 0, 0, 0, 2), "width"),
])
def test_bad_animations_and_frames_are_named(sheet, bad, match):
    with pytest.raises(InvalidValue, match=match):
        bad(sheet)


def test_a_grid_that_does_not_divide_the_image_or_a_missing_file_is_named(tmp_path):
    path = write(tmp_path / "odd.png", np.zeros((6, 10, 4), dtype=np.uint8))
    with pytest.raises(InvalidValue, match=r"odd\.png.*does not divide the image's 10 px wide"):
        SpriteSheet(path, 4, 6)
    with pytest.raises(InvalidValue, match=r"odd\.png.*does not divide the image's 6 px high"):
        SpriteSheet(path, 5, 4)
    with pytest.raises(InvalidValue, match=r"missing\.png.*cannot be read"):
        SpriteSheet(tmp_path / "missing.png", 4, 4)
    with pytest.raises(InvalidValue, match="not a PNG"):
        (tmp_path / "text.png").write_text("hello")
        SpriteSheet(tmp_path / "text.png", 1, 1)


def test_tiled_tileset_animations(tmp_path):
    write(tmp_path / "tiles.png", np.zeros((4, 8, 4), dtype=np.uint8))
    (tmp_path / "tiles.tsj").write_text(
        '{"image": "tiles.png", "tilewidth": 4, "tileheight": 4, "tiles": ['
        '{"id": 0, "animation": [{"tileid": 0, "duration": 250}, {"tileid": 1, "duration": 750}]}]}')
    s = SpriteSheet.from_tiled(tmp_path / "tiles.tsj")
    a = s.animations[0]
    assert a.frames == (s[0], s[1]) and a.durations == (0.25, 0.75) and a.loop
    (tmp_path / "bad.tsj").write_text('{"image": "tiles.png", "tilewidth": 4, "tileheight": 4, "tiles": ['
                                      '{"id": 0, "animation": [{"tileid": 9, "duration": 100}]}]}')
    with pytest.raises(InvalidValue, match=r"bad\.tsj.*tiles\[0\].*no frame 9"):
        SpriteSheet.from_tiled(tmp_path / "bad.tsj")
    (tmp_path / "zero.tsj").write_text('{"image": "tiles.png", "tilewidth": 4, "tileheight": 4, "tiles": ['
                                       '{"id": 0, "animation": [{"tileid": 1, "duration": 0}]}]}')
    with pytest.raises(InvalidValue, match=r"zero\.tsj.*> 0"):
        SpriteSheet.from_tiled(tmp_path / "zero.tsj")


# --- pixels -----------------------------------------------------------------------------------------


def test_animation_frames_at_given_steps_in_screenshots_and_an_attached_renderer(render, sheet):
    run = sheet.animation([0, 1, 2, 3], 0.25)
    with Scene() as s:
        renderer = render.Renderer(width=16, height=8, background=BG)
        s.renderer = renderer
        s.spawn(Transform(8.0, 4.0), Visual(animation=run))  # covers x 6..10, y 3..5
        seen = []
        for _ in range(8):
            s.step(0.125)
            img = renderer.capture()
            assert np.array_equal(img, shot(render, s))  # screenshot and attached renderer agree
            seen.append(px(img, 8, 4))
        # After step k the clock is k/8 s: frame floor(k/2) mod 4 (frame 1's left column is white).
        assert seen == [COLORS[0], COLORS[1], COLORS[1], COLORS[2], COLORS[2], COLORS[3], COLORS[3], COLORS[0]]
        assert px(renderer.capture(), 6, 4) == COLORS[0] and renderer.stats["animated"] == 1
        renderer.close()


def test_flip_x_mirrors_a_frame_and_tint_multiplies(render, sheet):
    with Scene() as s:
        e = s.spawn(Transform(8.0, 4.0), Visual(frame=sheet[1]))
        img = shot(render, s)
        assert px(img, 6, 4) == (255, 255, 255) and px(img, 9, 4) == COLORS[1]
        s.get(e, Visual).flip_x = True
        img = shot(render, s)
        assert px(img, 9, 4) == (255, 255, 255) and px(img, 6, 4) == COLORS[1]
        s.get(e, Visual).color = (255, 0, 0)
        assert px(shot(render, s), 9, 4) == (255, 0, 0)  # white tinted red


def test_atlas_packs_images_of_odd_sizes_and_draws_each_exactly(render, tmp_path):
    """Eleven images of odd sizes (one wider than the atlas starts, so it grows and packs again),
    each filled with its own colour and drawn at whole pixels: every one lands exactly."""
    rng = np.random.default_rng(3)
    with Scene() as s:
        boxes = []
        x = 2
        for k in range(11):
            w, h = int(rng.integers(1, 9)) * 2 + 1, int(rng.integers(1, 7)) * 2 + 1
            if k == 5:
                w = 301  # wider than the 256 px atlas it starts with
            color = (20 * k + 30, 255 - 20 * k, (37 * k) % 256)
            img = np.zeros((h, w, 4), dtype=np.uint8)
            img[...] = (*color, 255)
            path = write(tmp_path / f"i{k}.png", img)
            cx = x + w / 2
            s.spawn(Transform(cx, 16.0 + (h % 2) * 0.5), Visual(image=path))
            boxes.append((x, w, h, color))
            x += w + 2
        img = render.screenshot(s, width=x + 2, height=32, background=BG)
        for x0, w, h, color in boxes:
            y0 = 16 - h // 2
            region = img[32 - (y0 + h): 32 - y0, x0: x0 + w, :3]
            assert (region == color).all(), (x0, w, h)
            assert (img[32 - (y0 + h): 32 - y0, x0 - 1, :3] != color).any(axis=-1).all()  # nothing spills left


def test_a_visual_removed_or_changed_mid_animation(render, sheet):
    run = sheet.animation([0, 1, 2, 3], 0.25)
    with Scene() as s:
        renderer = render.Renderer(width=16, height=8, background=BG)
        s.renderer = renderer
        e = s.spawn(Transform(8.0, 4.0), Hitbox(AABB(2.0, 2.0), sensor=True), Visual(animation=run))
        s.step(0.25)
        assert px(renderer.capture(), 8, 4) == COLORS[1]
        s.get(e, Visual).animation = None  # no animation, no image: the hitbox, filled in its colour
        s.get(e, Visual).color = (9, 9, 9)
        s.step(0.25)
        img = renderer.capture()
        assert px(img, 7, 4) == (9, 9, 9) and px(img, 6, 4) == BG
        s.add_component(e, Visual(animation=run, started=0.0))  # replaced: the new one, from t = 0
        s.step(0.25)
        assert px(renderer.capture(), 7, 4) == COLORS[3]
        removed = s.remove_component(e, Visual)
        s.step(0.25)
        assert renderer.stats["drawables"] == 0 and px(renderer.capture(), 7, 4) == BG
        removed.color = (1, 2, 3)  # no longer the scene's: editing it changes nothing drawn
        s.step(0.25)
        assert px(renderer.capture(), 7, 4) == BG
        renderer.close()


def test_a_missing_or_broken_image_is_named_and_the_scene_stays_as_it_was(render, tmp_path):
    with pytest.raises(InvalidValue, match=r"Visual image .*gone\.png.*no such file"):
        Visual(image=str(tmp_path / "gone.png"))
    broken = tmp_path / "broken.png"
    broken.write_bytes(b"\x89PNG\r\n\x1a\n not really")
    with Scene() as s:
        e = s.spawn(Transform(8.0, 4.0), Velocity(1.0, 0.0), Visual((1, 2, 3)))
        with pytest.raises(InvalidValue, match="gone.png"):
            s.get(e, Visual).image = str(tmp_path / "gone.png")
        assert s.get(e, Visual).image is None
        s.get(e, Visual).image = str(broken)  # it exists: what is in it shows when it is drawn
        with pytest.raises(ValueError, match=rf"entity {e}: Visual image .*broken\.png.* could not be loaded"):
            shot(render, s)
        x = s.get(e, Transform).x
        s.step(1.0)  # no renderer attached: the simulation is not touched by the failed picture
        assert s.get(e, Transform).x == x + 1.0


def test_the_frame_of_many_moving_sprites_is_written_without_a_python_loop(render, sheet, monkeypatch):
    """Moving and animating sprites visits no entity in Python after the first frame: the per-entity
    path (a Visual look-up) runs only for entities whose Visual changed."""
    run = sheet.animation([0, 1, 2, 3], 0.25)
    with Scene(effects={"movement"}) as s:
        renderer = render.Renderer(width=64, height=48)
        s.renderer = renderer
        ents = [s.spawn(Transform(4.0 + i % 50, 4.0 + i // 50), Velocity(1.0, 1.0), Visual(animation=run))
                for i in range(2000)]
        s.step(0.1)
        looked = []
        try_get = s.try_get
        monkeypatch.setattr(s, "try_get", lambda e, c: looked.append(e) or try_get(e, c))
        for _ in range(3):
            s.step(0.1)
            renderer.capture()
        assert looked == [] and renderer.stats["moved"] > 1000
        s.get(ents[7], Visual).flip_x = True
        s.step(0.1)
        assert looked == [ents[7]]
        renderer.close()
