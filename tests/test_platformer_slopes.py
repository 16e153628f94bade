"""The platformer on slopes: its player and walkers move with the framework's character controller."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from examples.platformer import Game, builtin_levels, parse_text
from examples.platformer.components import Enemy, LevelPiece, Tuning
from examples.platformer.demo import Autoplay, level3
from framework import Hitbox, Polygon, Transform
from framework.testing import assert_inside, assert_on_floor, bounds, feet, run, step_until

T = 32.0
TU = Tuning()

def test_the_hills_level_has_slopes_a_step_a_v_and_a_lift_over_a_pit():
    g = Game([builtin_levels()[2]])
    kinds = {k for row in g.level.tiles for k in row}
    assert {"slope_up", "slope_down", "slope_up_low", "slope_up_high", "slope_down_high", "slope_down_low",
            "step"} <= kinds
    assert any(a == "slope_down" and b == "slope_up" for row in g.level.tiles for a, b in zip(row, row[1:]))  # a V
    assert len(g.level.of_kind("platform")) == 1
    slopes = [e for e, (lp, hb) in g.scene.query(LevelPiece, Hitbox) if lp.kind == "slope"]
    assert slopes and all(isinstance(g.scene.get(e, Hitbox).shape, Polygon) for e in slopes)


@pytest.mark.slow
def test_demo_plays_the_hills_to_the_goal():
    g = Game([builtin_levels()[2]], autoplay=Autoplay(level3))
    step_until(g.scene, lambda s: g.state.reached_goal, within=2000, what="the goal")
    assert g.state.reached_goal and g.state.deaths == 0 and g.state.stomps == 1


HILL = """
#..............................#
#..............................#
#.........../###\\..............#
#.P.....rR######################
################################
"""


def test_player_runs_up_and_over_the_hill_with_its_feet_on_the_ground():
    g = Game([parse_text(HILL, "hill.txt")])
    run(g.scene, 20, keys=set())

    def ground(x: float) -> float:
        c = x / T
        if c < 8:
            return T
        if c < 10:
            return T + (c - 8) * T / 2
        if c < 12:
            return 2 * T
        if c < 13:
            return 2 * T + (c - 12) * T
        if c < 16:
            return 3 * T
        if c < 17:
            return 3 * T - (c - 16) * T
        return 2 * T

    half_w = TU.player_size[0] * T / 2
    for _ in range(150):
        g.step({"right"})
        x = g.player_transform.x
        under = max(ground(x - half_w), ground(x + half_w))
        assert_on_floor(g.scene, g.player)
        assert g.player_state.grounded
        assert 0.0 <= feet(g.scene, g.player) - under <= 1e-9, (x / T, feet(g.scene, g.player) - under)
    assert g.player_transform.x > 18 * T  # 150 steps at up to 7 tiles/s, never held up


@pytest.mark.slow
def test_walker_walks_up_and_down_slopes_and_turns_at_walls():
    g = Game([parse_text("""
#...............................#
#P..............................#
###.............................#
#.....................E.........#
#......./##\\..............rR####
#################################
""", "walker.txt")])
    xs = []
    for _ in range(1800):
        g.step(set())
        ((e, (_en, t)),) = g.scene.query(Enemy, Transform)
        xs.append(t.x / T)
        if g.scene.frame >= 30:
            assert_on_floor(g.scene, e)
    assert min(xs) < 1.5 and max(xs) > 31.5  # over the hill to the left wall, up the 2:1 slope to the right wall
    assert g.state.deaths == 0


@pytest.mark.slow
def test_random_input_on_the_hills_for_10000_frames_never_enters_terrain_or_leaves_the_level():
    g = Game([builtin_levels()[2]])
    scene = g.scene
    terrain = {e for e, lp in scene.query(LevelPiece) if lp.kind in ("solid", "slope")}
    width, height = g.level.size
    rng = random.Random(20)
    keys: set[str] = set()
    reached = 0.0
    for k in range(10_000):
        if k % 12 == 0:
            keys = set(rng.choices(["right", "left", "space", "down", "up"], weights=[5, 2, 3, 1, 1],
                                   k=rng.randint(0, 2)))
        g.step(keys)
        p, t = g.player, g.player_transform
        assert 0.0 < t.x < width and t.y < height
        assert_inside(scene, p, (0.0, -math.inf, width, height))  # all of it, not only its centre
        c = scene.contacts
        for i in np.flatnonzero((c.a == p) | (c.b == p)).tolist():
            other = int(c.b[i]) if int(c.a[i]) == p else int(c.a[i])
            assert other not in terrain, (k, t.x, t.y, float(c.depth[i]))  # never inside ground or slope
        reached = max(reached, t.x / T)
    assert reached > 40.0  # it got over the hill and the V to the pit


def test_a_lift_that_carries_the_player_into_a_ceiling_kills_it():
    g = Game([parse_text("""
#########
#..~....#
#..~....#
#..~P...#
#..MMM..#
#.......#
#.....G.#
#########
""", "crush.txt")])
    ceiling = 7 * T

    def crushed(scene) -> bool:  # ... and never through the ceiling on the way
        assert bounds(scene, g.player)[3] <= ceiling + 1e-9
        return g.state.deaths > 0

    step_until(g.scene, crushed, within=300, keys=set())
    assert g.state.deaths == 1
