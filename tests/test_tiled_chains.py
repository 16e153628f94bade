"""Tiled polyline and polygon objects as chains (framework.tiles.tiled_chains): where their points
land (Tiled's y runs down from the map's top), which side bodies meet, and a scene built from a
Tiled object layer that a body slides along."""

from __future__ import annotations

import json
import math

import pytest

from framework import AABB, Chain, Circle, Hitbox, Scene, Transform, Velocity
from framework.chains import spawn_chain
from framework.tiles import tiled_chains

MAP_H = 320.0  # 10 rows of 32 pixels


def polyline(points, x=0.0, y=0.0, **extra):
    return {"id": 7, "x": x, "y": y, "polyline": [{"x": px, "y": py} for px, py in points], **extra}


def polygon(points, x=0.0, y=0.0, **extra):
    return {"id": 8, "x": x, "y": y, "polygon": [{"x": px, "y": py} for px, py in points], **extra}


def test_a_polyline_drawn_left_to_right_is_ground_met_from_above() -> None:
    (chain,) = tiled_chains([polyline([(0, 0), (64, 0), (128, -32)], x=32, y=288)], MAP_H, scale=1 / 32)
    # y flipped from the map's bottom, scaled to tiles; reversed so that its right side is up
    assert chain == Chain([(5.0, 2.0), (3.0, 1.0), (1.0, 1.0)])
    assert [s.normal[1] > 0 for s in chain.segments] == [True, True]
    (ceiling,) = tiled_chains([polyline([(128, 0), (0, 0)], y=32)], MAP_H, scale=1 / 32)
    assert ceiling.segments[0].normal == (0.0, -1.0)  # drawn right to left: met from below


@pytest.mark.parametrize("winding", [1, -1])
def test_a_polygon_is_solid_inside_whichever_way_it_was_drawn(winding) -> None:
    square = [(0, 0), (64, 0), (64, 64), (0, 64)][::winding]
    (chain,) = tiled_chains({"type": "objectgroup", "objects": [polygon(square, x=64, y=128)]}, MAP_H, 1 / 32)
    assert chain.loop and len(chain) == 4
    # counter-clockwise, y up: every normal points out of the square (x 2..4, y 4..6 in tiles)
    for seg in chain.segments:
        mx, my = (seg.a[0] + seg.b[0]) / 2, (seg.a[1] + seg.b[1]) / 2
        assert (mx - 3) * seg.normal[0] + (my - 5) * seg.normal[1] > 0
    assert sorted(chain.points) == [(2.0, 4.0), (2.0, 6.0), (4.0, 4.0), (4.0, 6.0)]


def test_rotation_other_objects_and_errors() -> None:
    (turned,) = tiled_chains([polyline([(0, 0), (32, 0)], x=0, y=160, rotation=90)], MAP_H, 1 / 32)
    # 90 degrees clockwise as Tiled shows it: the line now runs down the screen from (0, 160)
    assert [tuple(round(c, 12) + 0.0 for c in p) for p in turned.points] == [(0.0, 4.0), (0.0, 5.0)]
    others = [{"id": 1, "x": 3, "y": 4, "width": 10, "height": 10}, {"id": 2, "x": 1, "y": 1, "point": True}]
    assert tiled_chains(others, MAP_H) == []
    for bad, word in [([polyline([(0, 0)])], "at least 2"), ([polygon([(0, 0), (1, 0)])], "at least 3"),
                      ([polyline([(0, 0), (0, 0), (5, 5)])], "equal"), ([polyline([(0, 0), (1, math.nan)])], "nan"),
                      ([{"id": 3, "x": "a", "polyline": []}], "x must be a real number"),
                      ([polyline([(0, 0), (1, 1)], rotation=math.inf)], "rotation"),
                      ("layer", "object layer"), ([5], "must be a JSON object")]:
        with pytest.raises(ValueError, match=word):
            tiled_chains(bad, MAP_H)
    with pytest.raises(ValueError, match="polyline object 7"):
        tiled_chains([polyline([(0, 0)])], MAP_H)


@pytest.mark.parametrize("solver", ["exact", "soft"])
def test_a_tiled_map_of_lines_is_terrain_a_body_slides_along(solver) -> None:
    # Ground drawn left to right in Tiled as 400 points of a gentle wave (y down, pixels), a block
    # drawn as a polygon resting above the ground; saved and read back as JSON.
    wave = [(8.0 * i, 200.0 - 6.0 * math.sin(i / 20.0)) for i in range(400)]
    layer = {"type": "objectgroup", "name": "terrain",
             "objects": [polyline(wave), polygon([(0, 0), (64, 0), (64, 32), (0, 32)], x=1600, y=120)]}
    ground, block = tiled_chains(json.loads(json.dumps(layer)), MAP_H, 1 / 32)
    assert len(ground) == 399 and len(block) == 4
    s = Scene(solver="soft") if solver == "soft" else Scene()
    s.gravity = (0, -10)
    spawn_chain(s, ground)
    spawn_chain(s, block)
    crate = s.spawn(Transform(2.0, 4.0), Velocity(3.0, 0.0), Hitbox(AABB(0.5, 0.5), inertia=math.inf))
    ball = s.spawn(Transform(51.0, 9.0), Velocity(0.0, 0.0), Hitbox(Circle(0.25)))
    energy = None
    for _ in range(400):
        s.step(1 / 60)
        t, v = s.get(crate, Transform), s.get(crate, Velocity)
        e = 0.5 * (v.x * v.x + v.y * v.y) + 10.0 * t.y
        if t.y < 4.0 and energy is None:
            energy = e  # landed
        elif energy is not None:
            # frictionless, over joints of a curve: it keeps its energy (less what the bends take)
            assert e == pytest.approx(energy, rel=0.02)
    assert s.get(crate, Transform).x > 20.0
    # the ball came down on the block's top (y = 10 - 120/32 = 6.25), not through it
    assert s.get(ball, Transform).y == pytest.approx(6.25 + 0.25, abs=1e-2)
