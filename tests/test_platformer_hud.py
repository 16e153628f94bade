"""The platformer's on-screen HUD (issue 36: score, lives and messages were only in the window
title): coins, deaths and the level as screen texts, kept up to date, drawn in the view's top
corners and nowhere else."""

from __future__ import annotations

import numpy as np
import pytest

from examples.platformer import Game, builtin_levels
from examples.platformer.__main__ import BACKGROUND, HEIGHT, WIDTH, camera_for
from examples.platformer.hud import hud_texts, install_hud
from framework import Text


@pytest.fixture
def game():
    g = Game([builtin_levels()[0]], view=(WIDTH, HEIGHT))
    yield g
    g.close()


def _said(game, entities):
    return {name: game.scene.get(e, Text).text for name, e in entities.items()}


def test_the_hud_says_coins_deaths_and_level_and_keeps_up(game):
    entities = install_hud(game)
    st = game.state
    said = _said(game, entities)  # before any step
    assert said == {"coins": f"coins 0/{st.coin_total_in_level}", "deaths": "deaths 0",
                    "level": f"level 1/1: {st.level_name}", "message": ""}
    assert st.coin_total_in_level > 0 and st.level_name
    st.coins_in_level, st.deaths = 2, 3  # as the handlers count them
    game.step()
    said = _said(game, entities)
    assert said["coins"] == f"coins 2/{st.coin_total_in_level}" and said["deaths"] == "deaths 3"
    st.level_done = True
    game.step()
    assert _said(game, entities)["message"] == "Level complete!"
    assert all(game.scene.get(e, Text).screen for e in entities.values())


def test_hud_texts_for_the_end_of_the_game():
    from examples.platformer import GameState

    st = GameState(level_index=2, level_name="Caves", coins_in_level=5, coin_total_in_level=9, deaths=1,
                   level_done=True, finished=True)
    assert hud_texts(st, 3) == {"coins": "coins 5/9", "deaths": "deaths 1", "level": "level 3/3: Caves",
                                "message": "All levels done! R replays the last one"}


def test_the_hud_is_drawn_in_the_top_corners_and_nowhere_else(game):
    try:
        import framework.render as render

        render.offscreen_window()
    except Exception as exc:  # no GL library, no EGL device: not a failure of the game
        pytest.skip(f"no OpenGL context available here ({type(exc).__name__}: {exc})")
    entities = install_hud(game)
    for _ in range(3):
        game.step()

    def shot():
        return render.screenshot(game.scene, width=WIDTH, height=HEIGHT, camera=camera_for(game, 1.0),
                                 background=BACKGROUND)[..., :3].astype(int)

    with_hud = shot()
    for e in entities.values():
        game.scene.get(e, Text).visible = False
    without = shot()
    changed = (with_hud != without).any(axis=2)
    ys, xs = np.nonzero(changed)
    assert changed.sum() > 300
    assert ys.max() < 60  # only the top of the view: two lines on the left, one on the right
    left, right = xs[xs < WIDTH // 2], xs[xs >= WIDTH // 2]
    assert left.size > 100 and right.size > 100
    assert left.min() >= 12 and right.max() <= WIDTH - 12  # inside the margins
    assert changed[:, 200:WIDTH - 300].sum() == 0  # nothing between the corners
    # Two lines on the left (coins, then deaths below), one on the right, a gap between the lines.
    rows_left, rows_right = set(ys[xs < WIDTH // 2].tolist()), set(ys[xs >= WIDTH // 2].tolist())
    first = {y for y in rows_left if y < min(rows_left) + 20}
    assert rows_right <= first and rows_left - first and min(rows_left - first) > max(first) + 1
