"""The platformer's terrain drawn as lines: Tiled polylines (the surface of the ground below them)
and polygons (solid blocks) load as chains (examples/platformer/levels.py ``TerrainLine``), are drawn
as ground (examples/platformer/terrain.py), and the player walks, jumps and lands on them.

The map ``tests/levels/lines.tmj`` (40 x 12 tiles of 32): a tile floor at y = 64 on the left, then a
polyline hill from the floor's height up slopes of 26.6 and 36.9 degrees (the controller's
``max_floor_angle`` is 50), a flat top at 160, down the same slopes back to 64 and on to the map's
right edge; a polygon rock floating over it (x 832..960, y 128..176, its top a roof)."""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import pytest

from examples.platformer import Game
from examples.platformer.components import Enemy, LevelPiece
from examples.platformer.levels import LevelError, TerrainLine, load_level, parse_tmj, to_tmj
from examples.platformer.terrain import fill_pieces, grass_strips, triangulate
from framework import Hitbox, Transform, Velocity
from framework.shapes import ChainSegment
from framework.testing import assert_on_floor, feet

T = 32.0
MAP = Path(__file__).with_name("levels") / "lines.tmj"
HILL = ((256, 64), (320, 64), (384, 96), (448, 144), (512, 160), (576, 160), (640, 128), (704, 80), (768, 64),
        (1280, 64))
ROCK = ((832, 128), (960, 128), (960, 160), (896, 176), (832, 160))
HALF_W = 0.75 * T / 2  # the player's half width (Tuning.player_size)


def _tmj() -> dict:
    return json.loads(MAP.read_text())


def _objects(d: dict) -> list:
    return next(layer for layer in d["layers"] if layer["type"] == "objectgroup")["objects"]


def _surface(x: float) -> float:
    """The ground's height at ``x``: the tile floor (64) left of the hill, the polyline over it."""
    for (x0, y0), (x1, y1) in zip(HILL, HILL[1:]):
        if x0 <= x <= x1:
            return y0 + (y1 - y0) * (x - x0) / (x1 - x0)
    return 64.0


def _under(x: float) -> float:
    """The highest ground under the player's feet (its bottom spans x +- HALF_W)."""
    xs = [x - HALF_W, x + HALF_W, *(px for px, _ in HILL if x - HALF_W < px < x + HALF_W)]
    return max(_surface(v) for v in xs)


def _distance_to_hill(px: float, py: float) -> float:
    """The distance from ``(px, py)`` to the nearest point of the hill's polyline."""
    best = math.inf
    for (x0, y0), (x1, y1) in zip(HILL, HILL[1:]):
        dx, dy = x1 - x0, y1 - y0
        t = max(0.0, min(1.0, ((px - x0) * dx + (py - y0) * dy) / (dx * dx + dy * dy)))
        best = min(best, math.hypot(px - x0 - t * dx, py - y0 - t * dy))
    return best


# --- loading -----------------------------------------------------------------------------------------

def test_polylines_and_polygons_load_as_terrain_lines_and_write_back() -> None:
    level = load_level(MAP)
    hill, rock = level.terrain
    assert hill == TerrainLine(tuple((float(x), float(y)) for x, y in HILL))  # left to right, y up
    assert rock == TerrainLine(tuple((float(x), float(y)) for x, y in ROCK), loop=True)  # counter-clockwise
    assert (hill.label, rock.label) == ("polyline object 7", "polygon object 8")
    # the polyline's solid: the ground below it, closed down the ends to the map's bottom
    assert hill.outline() == [*reversed(hill.points), (256.0, 0.0), (1280.0, 0.0)]
    assert len(hill.chain().segments) == len(HILL) + 2 and hill.chain().loop
    assert parse_tmj(to_tmj(level), "again.tmj").terrain == level.terrain
    assert TerrainLine(rock.points[::-1], loop=True).outline() == rock.outline()  # either winding


def test_a_polyline_is_the_same_ground_whichever_way_it_was_drawn() -> None:
    # Drawn right to left, its points relative to the object's position (as Tiled saves them).
    d = _tmj()
    line = next(o for o in _objects(d) if "polyline" in o)
    pts = [(p["x"], p["y"]) for p in line["polyline"]][::-1]
    line.update(x=100.0, y=50.0, type="", polyline=[{"x": x - 100.0, "y": y - 50.0} for x, y in pts])
    assert parse_tmj(d, "backwards.tmj").terrain == load_level(MAP).terrain


@pytest.mark.parametrize(("change", "problem"), [
    (lambda o: o["polyline"].insert(3, {"x": 300.0, "y": 280.0}), "polyline object 7 turns back at point 3"),
    (lambda o: o.update(polyline=[{"x": 256.0, "y": 320.0}, {"x": 256.0, "y": 200.0}]),
     "polyline object 7 does not run across the map"),
    (lambda o: o["polyline"].append({"x": 1400.0, "y": 320.0}), "lies outside the map"),
    (lambda o: o.update(type="platform"), "its type must be empty or 'terrain', got 'platform'"),
    (lambda o: o.update(polyline=[{"x": 256.0, "y": 320.0}]), "at least 2"),
    (lambda o: o.update(polyline="up"), "its points must be a list"),
], ids=["turns-back", "vertical", "outside", "typed", "one-point", "not-a-list"])
def test_a_bad_polyline_is_a_level_error_naming_it(change, problem) -> None:
    d = _tmj()
    change(next(o for o in _objects(d) if "polyline" in o))
    with pytest.raises(LevelError, match="bad.tmj: ") as info:
        parse_tmj(d, "bad.tmj")
    assert problem in str(info.value), info.value


def test_a_polygon_that_crosses_itself_or_a_player_inside_the_ground_is_an_error() -> None:
    d = _tmj()
    rock = next(o for o in _objects(d) if "polygon" in o)
    rock["polygon"] = [{"x": 832, "y": 256}, {"x": 960, "y": 224}, {"x": 960, "y": 256}, {"x": 832, "y": 224}]
    with pytest.raises(LevelError, match="polygon object 8: its outline crosses itself"):
        parse_tmj(d, "bowtie.tmj")
    d = _tmj()
    next(o for o in _objects(d) if o.get("type") == "player").update(x=480.0)  # under the hill's top
    with pytest.raises(LevelError, match="player start at .* is inside the ground of polyline object 7"):
        parse_tmj(d, "buried.tmj")
    d = _tmj()
    next(o for o in _objects(d) if "polygon" in o)["polygon"] *= 400
    with pytest.raises(LevelError, match="more than 1000 .LevelLimits.max_polygon_points"):
        parse_tmj(d, "huge.tmj")


# --- drawing -----------------------------------------------------------------------------------------

def _area(pts) -> float:
    return 0.5 * sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(pts, [*pts[1:], pts[0]]))


def test_the_pieces_fill_the_ground_exactly_and_grass_lines_the_top() -> None:
    hill, rock = load_level(MAP).terrain
    for line in (hill, rock):
        pieces = fill_pieces(line)
        assert all(_area(p) > 0 for p in pieces)  # counter-clockwise, convex (quads and triangles)
        assert sum(_area(p) for p in pieces) == _area(line.outline())  # (dyadic: exact)
    # grass under the edges that face up: the hill's nine, the rock's roof (two); not walls or bottoms
    assert len(grass_strips(hill, 0.0, 6.0)) == len(HILL) - 1
    assert sorted(s[2] for s in grass_strips(rock, 0.0, 6.0)) == [(896.0, 176.0), (960.0, 160.0)]  # (right ends)
    # an L-shaped block: non-convex, its triangles cover it
    ell = [(0.0, 0.0), (4.0, 0.0), (4.0, 1.0), (1.0, 1.0), (1.0, 3.0), (0.0, 3.0)]
    assert sum(_area(t) for t in triangulate(ell)) == _area(ell) == 6.0


def test_the_level_spawns_chains_that_collide_and_pieces_that_only_draw() -> None:
    g = Game([load_level(MAP)])
    kinds: dict[str, list[int]] = {}
    for e, lp in g.scene.query(LevelPiece):
        kinds.setdefault(lp.kind, []).append(e)
    chains = [g.scene.get(e, Hitbox) for e in kinds["chain"]]
    assert len(chains) == (len(HILL) + 2) + len(ROCK)
    assert all(isinstance(h.shape, ChainSegment) and h.body.value == "static" and h.layer for h in chains)
    drawn = [g.scene.get(e, Hitbox) for e in kinds["terrain"]]
    assert drawn and all(h.sensor and h.layer == 0 and h.mask == 0 for h in drawn)


def test_a_screenshot_shows_ground_under_the_line_and_sky_over_it() -> None:
    try:
        from framework.render import Camera, screenshot

        g = Game([load_level(MAP)])
        img = screenshot(g.scene, width=160, height=120, camera=Camera(544.0, 120.0), background=(0, 0, 0))
    except Exception as exc:  # no GL context here
        pytest.skip(f"no OpenGL context available here ({type(exc).__name__}: {exc})")
    from examples.platformer.art import GRASS, GROUND

    def pixel(x: float, y: float) -> tuple[int, ...]:  # world (x, y) to the image's row and column
        return tuple(int(v) for v in img[int(60 - (y - 120.0)), int(80 + (x - 544.0)), :3])

    assert pixel(544, 100) == GROUND  # under the hill's flat top (y 160)
    assert pixel(544, 157) == GRASS
    assert pixel(544, 170) == (0, 0, 0)


# --- playing -----------------------------------------------------------------------------------------

def test_the_player_walks_over_the_polyline_hill_and_back_with_its_feet_on_it() -> None:
    g = Game([load_level(MAP)])
    for _ in range(10):
        g.step(set())
    for keys, steps in (({"right"}, 250), ({"left"}, 250)):
        speed = []
        for _ in range(steps):
            x0 = g.player_transform.x
            g.step(keys)
            x = g.player_transform.x
            speed.append(abs(x - x0))
            assert_on_floor(g.scene, g.player)
            assert g.player_state.grounded
            # from the tiles onto the chain, up and down every joint: on the surface, to rounding
            assert 0.0 <= feet(g.scene, g.player) - _under(x) <= 1e-9, (x / T, feet(g.scene, g.player) - _under(x))
        # never held up at a joint: full running speed (7 tiles/s) once it has turned and sped up
        assert min(speed[12:]) == pytest.approx(7.0 * T / 60.0, rel=1e-9)
    assert g.state.deaths == 0


def test_the_player_jumps_onto_the_slope_and_onto_the_rock() -> None:
    g = Game([load_level(MAP)])
    for _ in range(10):
        g.step(set())
    # a running jump from the tiles lands on the hill's first slope and runs on up it
    for _ in range(36):
        g.step({"right"})
    assert g.player_transform.x < 256 - HALF_W  # still on the tiles
    landed = None
    for k in range(60):
        g.step({"right", "space"})
        if k > 0 and g.player_state.grounded:
            landed = landed or g.player_transform.x
            assert 0.0 <= feet(g.scene, g.player) - _under(g.player_transform.x) <= 1e-9
    assert landed is not None and 320 < landed < 384 + HALF_W  # on the slope (26.6 degrees) up from 320
    # onto the rock: put the player on the ground left of it, run and jump onto its roof
    t = g.player_transform
    t.x, t.y = 800.0, 64.0 + 0.875 * T / 2
    g.scene.get(g.player, Velocity).x = 0.0
    for _ in range(5):
        g.step(set())
    for k in range(60):
        g.step({"right", "space"} if k < 25 else set())
    x = g.player_transform.x
    roof = 160.0 + 16.0 * (1.0 - abs(x - 896.0) / 64.0)  # the roof at the player's centre...
    assert g.player_state.grounded and 832 < x < 960
    assert feet(g.scene, g.player) >= roof - 1e-9 and feet(g.scene, g.player) < 176.0 + 1e-9  # ... on it


def test_a_walker_walks_over_the_hill_onto_the_tiles_and_turns_at_the_ledge() -> None:
    d = _tmj()
    _objects(d).append({"id": 30, "type": "enemy", "x": 720.0, "y": 300.0, "width": 0, "height": 0, "point": True,
                        "properties": [{"name": "direction", "type": "int", "value": -1}]})
    g = Game([parse_tmj(d, "walker.tmj")])
    xs = []
    for k in range(780):
        g.step(set())
        ((e, (en, t)),) = g.scene.query(Enemy, Transform)
        xs.append(t.x)
        if k >= 30:  # (it starts in the air)
            assert_on_floor(g.scene, e)
            if t.x > 256:
                assert 0.0 <= feet(g.scene, e) - _under(t.x) <= 1e-9  # (as wide as the player)
    assert min(xs) < 32 and en.direction == 1 and xs[-1] > min(xs) + 2 * T  # up, over, down, back


@pytest.mark.parametrize("solver", ["exact", "soft"])
def test_both_solvers_play_lines_a_barrel_rolls_down_the_hill_a_crate_rests_on_the_rock(solver) -> None:
    d = _tmj()
    d["properties"].append({"name": "solver", "type": "string", "value": solver})
    objs = _objects(d)
    objs.append({"id": 20, "type": "barrel", "x": 600.0, "y": 200.0, "width": 0, "height": 0, "point": True})
    objs.append({"id": 21, "type": "crate", "x": 864.0, "y": 120.0, "width": 0, "height": 0, "point": True})
    g = Game([parse_tmj(copy.deepcopy(d), "solver.tmj")])
    assert g.scene.solver == solver
    piece = {lp.kind: e for e, lp in g.scene.query(LevelPiece) if lp.kind in ("barrel", "crate")}
    r = 0.375 * T  # Tuning.barrel_radius
    # how far into the ground it may sink: the exact solver none; the soft one a little at impacts
    sink = 1e-9 if solver == "exact" else 0.1 * T
    for _ in range(100):
        g.step(set())
        b = g.scene.get(piece["barrel"], Transform)
        assert _distance_to_hill(b.x, b.y) >= r - sink  # never into the hill
    assert 768 < g.scene.get(piece["barrel"], Transform).x < 1280  # rolled down the hill, on along the flat
    c, v = g.scene.get(piece["crate"], Transform), g.scene.get(piece["crate"], Velocity)
    # a box never turns: it rests on its lower right corner on the roof's left slope (up to the right)
    half = 0.875 * T / 2  # Tuning.crate_size
    assert 832 < c.x - half and c.x + half < 896 and math.hypot(v.x, v.y) < 1e-6
    assert c.y - half == pytest.approx(160.0 + 16.0 * (c.x + half - 832.0) / 64.0, abs=0.01 * T)
