"""Terrain tiles (framework/tiles.py) and slopes in the platformer's level files.

Grids are written as strings in the platformer's text-map characters (``#`` solid, ``/`` and ``\\``
45-degree slopes, ``r R`` and ``F f`` the 2:1 slope pairs, ``.`` empty), row 0 at the top. With
a tile of 32 the bottom row spans y 0..32. Shapely is the oracle for areas and unions.
"""

from __future__ import annotations

import json
import math
import random
import re
import struct

import pytest
from shapely.geometry import Polygon as ShapelyPolygon
from shapely.geometry import box as shapely_box
from shapely.ops import unary_union

from examples.platformer.levels import (
    LEVEL_DIR,
    TILE_KINDS,
    LevelError,
    dump_tmj,
    load_level,
    parse_text,
    parse_tmj,
    to_tmj,
)
from framework import AABB, Polygon, Transform
from framework.collision import collide
from framework.tiles import (
    HEIGHTS,
    MIRRORED,
    SLOPE_DOWN,
    SLOPE_DOWN_HIGH,
    SLOPE_DOWN_LOW,
    SLOPE_UP,
    SLOPE_UP_HIGH,
    SLOPE_UP_LOW,
    SLOPES,
    SOLID,
    TERRAIN,
    TerrainPiece,
    terrain_pieces,
)
from framework.validation import InvalidValue

CHARS = {"#": SOLID, "/": SLOPE_UP, "\\": SLOPE_DOWN, "r": SLOPE_UP_LOW, "R": SLOPE_UP_HIGH,
         "F": SLOPE_DOWN_HIGH, "f": SLOPE_DOWN_LOW, "-": "oneway", "^": "spikes"}
T = 32.0


def grid(text: str) -> list[list[str | None]]:
    return [[CHARS.get(ch) for ch in line] for line in text.strip("\n").split("\n")]


def pieces(text: str, tile: float = T, **kw) -> list[TerrainPiece]:
    return terrain_pieces(grid(text), tile, **kw)


def poly(*world_points, at=(0.0, 0.0)) -> Polygon:
    """The Polygon with these world vertices, in local coordinates about ``at``."""
    return Polygon([(x - at[0], y - at[1]) for x, y in world_points])


def world(p: TerrainPiece):
    """The piece's region as a shapely polygon, in world coordinates."""
    if isinstance(p.shape, AABB):
        hw, hh = p.shape.half_width, p.shape.half_height
        return shapely_box(p.x - hw, p.y - hh, p.x + hw, p.y + hh)
    return ShapelyPolygon([(p.x + x, p.y + y) for x, y in p.shape.points])


def cell_region(kind: str, col: int, row: int, rows: int, tile: float, origin=(0.0, 0.0)):
    x0, x1 = origin[0] + col * tile, origin[0] + (col + 1) * tile
    y0 = origin[1] + (rows - row - 1) * tile
    left, right = HEIGHTS[kind]
    pts = [(x0, y0), (x1, y0), (x1, y0 + right * tile), (x0, y0 + left * tile)]
    pts = [p for i, p in enumerate(pts) if p != pts[i - 1]]
    return ShapelyPolygon(pts)


# --- kinds ------------------------------------------------------------------------------------------


def test_kind_names_and_profiles():
    assert SLOPES == ("slope_up", "slope_down", "slope_up_low", "slope_up_high", "slope_down_high",
                      "slope_down_low")
    assert TERRAIN == ("solid", *SLOPES, "step") and set(HEIGHTS) == set(TERRAIN)
    assert HEIGHTS["step"] == (0.25, 0.25)
    assert HEIGHTS[SLOPE_UP_LOW][1] == HEIGHTS[SLOPE_UP_HIGH][0] == 0.5
    for kind in TERRAIN:
        assert MIRRORED[MIRRORED[kind]] == kind
        assert HEIGHTS[MIRRORED[kind]] == HEIGHTS[kind][::-1]


# --- exact outlines ---------------------------------------------------------------------------------


def test_a_lone_45_degree_slope_is_one_triangle():
    (up,) = pieces("/")
    assert (up.x, up.y, up.cells, up.top) == (16.0, 16.0, ((0, 0),), (0.0, 32.0))
    assert up.shape == poly((0, 0), (32, 0), (32, 32), at=(16, 16))
    assert up.shape.points == ((-16.0, -16.0), (16.0, -16.0), (16.0, 16.0))
    (down,) = pieces("\\")
    assert down.top == (32.0, 0.0)
    assert down.shape.points == ((-16.0, -16.0), (16.0, -16.0), (-16.0, 16.0))


def test_slope_up_flat_and_slope_down_make_one_hill_with_exact_vertices():
    (hill,) = pieces("/##\\")
    assert hill.cells == ((0, 0), (1, 0), (2, 0), (3, 0))
    assert (hill.x, hill.y, hill.top) == (64.0, 16.0, (0.0, 0.0))
    assert hill.shape.points == ((-64.0, -16.0), (64.0, -16.0), (32.0, 16.0), (-32.0, 16.0))
    (peak,) = pieces("/\\")
    assert peak.shape.points == ((-32.0, -16.0), (32.0, -16.0), (0.0, 16.0))


def test_a_slope_merges_with_the_flat_beside_its_high_side_only():
    # Flat then a rising slope is a valley: the solid stays a box, the slope joins the flat after it.
    box, ramp = pieces("#/#")
    assert box.shape == AABB(T, T) and (box.x, box.y, box.cells) == (16.0, 16.0, ((0, 0),))
    assert ramp.cells == ((1, 0), (2, 0)) and (ramp.x, ramp.y, ramp.top) == (64.0, 16.0, (0.0, 32.0))
    assert ramp.shape == poly((32, 0), (96, 0), (96, 32), (64, 32), at=(64, 16))
    ramp, box = pieces("#\\#")  # falling: the flat before the slope joins it, the one after does not
    assert ramp.cells == ((0, 0), (1, 0)) and ramp.top == (32.0, 0.0)
    assert box.shape == AABB(T, T) and box.cells == ((2, 0),)


def test_a_v_of_two_slopes_is_two_triangles():
    down, up = pieces("\\/")
    assert down.shape == poly((0, 0), (32, 0), (0, 32), at=(16, 16)) and down.cells == ((0, 0),)
    assert up.shape == poly((32, 0), (64, 0), (64, 32), at=(48, 16)) and up.cells == ((1, 0),)
    assert (down.x, up.x) == (16.0, 48.0)


def test_gentle_slope_pairs():
    (rise,) = pieces("rR")  # one straight slope, its middle vertex dropped as collinear
    assert (rise.x, rise.y, rise.top) == (32.0, 16.0, (0.0, 32.0))
    assert rise.shape.points == ((-32.0, -16.0), (32.0, -16.0), (32.0, 16.0))
    (fall,) = pieces("Ff")
    assert fall.shape.points == ((-32.0, -16.0), (32.0, -16.0), (-32.0, 16.0))
    (low,) = pieces("r")  # half a cell high: the bounding box's centre is a quarter up
    assert (low.x, low.y, low.top) == (16.0, 8.0, (0.0, 16.0))
    assert low.shape.points == ((-16.0, -8.0), (16.0, -8.0), (16.0, 8.0))
    (high,) = pieces("R")
    assert high.shape == poly((0, 0), (32, 0), (32, 32), (0, 16), at=(16, 16))
    (mesa,) = pieces("rR#Ff")
    assert mesa.cells == tuple((c, 0) for c in range(5)) and mesa.top == (0.0, 0.0)
    assert mesa.shape == poly((0, 0), (160, 0), (96, 32), (64, 32), at=(80, 16))
    (mixed,) = pieces("/F")  # steep, then gentle: still convex
    assert mixed.shape == poly((0, 0), (64, 0), (64, 16), (32, 32), at=(32, 16))
    a, b = pieces("r/")  # the 45 slope after the gentle one starts lower: a step, two pieces
    assert a.cells == ((0, 0),) and b.cells == ((1, 0),)
    a, b = pieces("rR/")  # continuous but steeper up: a valley
    assert a.cells == ((0, 0), (1, 0)) and b.cells == ((2, 0),)


def test_solid_only_grids_give_the_per_cell_boxes_at_the_exact_centres():
    text = "#..#\n####\n.##."
    got = pieces(text)
    level = parse_text("P...\n" + text, "x.txt")
    want = [(col, row) for row, line in enumerate(level.tiles) for col, k in enumerate(line) if k == "solid"]
    assert [p.cells for p in got] == [((c, r - 1),) for c, r in want]  # the level has a "P" row on top
    for p, (col, row) in zip(terrain_pieces(level.tiles, level.tile), want):
        assert p.shape == AABB(T, T) and p.cells == ((col, row),)
        assert (p.x, p.y) == level.cell_center(col, row)  # where the game spawns its tile boxes
        assert p.top == (p.y + 16.0, p.y + 16.0)


def test_slopes_on_different_rows_and_around_solids():
    got = pieces(
        "...rR\n"
        "../##F\n"
        "/####/#")
    assert [p.cells for p in got] == [
        ((3, 0), (4, 0)),
        ((2, 1), (3, 1), (4, 1), (5, 1)),
        ((0, 2), (1, 2), (2, 2), (3, 2), (4, 2)), ((5, 2), (6, 2)),
    ]
    assert got[0].shape == poly((96, 64), (160, 64), (160, 96), at=(128, 80))
    assert got[1].shape == poly((64, 32), (192, 32), (192, 48), (160, 64), (96, 64), at=(128, 48))
    assert got[2].shape == poly((0, 0), (160, 0), (160, 32), (32, 32), at=(80, 16))
    assert got[3].top == (0.0, 32.0)


def test_other_kinds_are_not_terrain_and_short_rows_are_padded():
    got = terrain_pieces([["oneway", "solid", None, "spikes"], [], ["ladder", SLOPE_UP, 7, SOLID]], 1.0)
    assert [p.cells for p in got] == [((1, 0),), ((1, 2),), ((3, 2),)]
    assert got[0].y == 2.5  # 3 rows, the empty middle one included
    assert terrain_pieces([], 32) == [] and terrain_pieces([[None, "oneway"]], 32) == []


@pytest.mark.parametrize("tile", [32.0, 1.0, 0.5, 1 / 1024])
def test_dyadic_tiles_and_origins_give_exact_vertices(tile):
    origin = (-3 * tile, 5.25 * tile)
    (hill,) = pieces("rR#\\", tile, origin=origin)
    assert (hill.x, hill.y) == (origin[0] + 2 * tile, origin[1] + 0.5 * tile)
    assert hill.top == (origin[1], origin[1])
    assert hill.shape.points == tuple((x * tile, y * tile) for x, y in
                                      ((-2.0, -0.5), (2.0, -0.5), (1.0, 0.5), (0.0, 0.5)))


@pytest.mark.parametrize("tile", [0, -32, math.nan, math.inf, "32", None, True, 5e-324])
def test_a_bad_tile_size_is_an_invalid_value_naming_it(tile):
    with pytest.raises(ValueError, match=re.escape(repr(tile))):
        terrain_pieces([["solid"]], tile)


@pytest.mark.parametrize("cells", [None, 5, "##", [3]])
def test_cells_that_are_not_rows_are_an_invalid_value(cells):
    with pytest.raises(InvalidValue, match="terrain cells"):
        terrain_pieces(cells, 32)


def test_a_bad_origin_is_an_invalid_value():
    with pytest.raises(InvalidValue, match="origin"):
        terrain_pieces([["solid"]], 32, origin=(0, math.nan))
    with pytest.raises(InvalidValue, match="does not fit"):
        terrain_pieces([["solid"] * 4], 1e308)


# --- properties on random grids --------------------------------------------------------------------

KINDS = [None, None, None, "oneway", *TERRAIN, SOLID, SOLID, SLOPE_UP, SLOPE_DOWN]


@pytest.mark.parametrize("seed", range(40))
def test_random_grids_give_convex_pieces_that_tile_the_cells_exactly(seed):
    rng = random.Random(seed)
    tile = rng.choice([32.0, 1.0, 0.5])
    origin = rng.choice([(0.0, 0.0), (-64.0, 16.0), (0.25, -2.0)])
    rows = [[rng.choice(KINDS) for _ in range(rng.randint(0, 9))] for _ in range(rng.randint(1, 5))]
    got = terrain_pieces(rows, tile, origin=origin)
    regions = {(c, r): cell_region(k, c, r, len(rows), tile, origin)
               for r, line in enumerate(rows) for c, k in enumerate(line) if k in TERRAIN}
    assert sorted(cell for p in got for cell in p.cells) == sorted(regions)  # each cell in one piece
    for p in got:
        shape = world(p)
        assert shape.is_valid and shape.convex_hull.area == shape.area  # convex
        cols = [c for c, _ in p.cells]
        assert len({r for _, r in p.cells}) == 1 and cols == list(range(cols[0], cols[0] + len(cols)))
        own = unary_union([regions[c] for c in p.cells])
        assert shape.symmetric_difference(own).area == 0.0  # exactly its cells' union
        assert p.shape.area == math.fsum(regions[c].area for c in p.cells)
        if isinstance(p.shape, AABB):
            assert all(rows[r][c] == SOLID for c, r in p.cells)
        else:
            assert any(rows[r][c] != SOLID for c, r in p.cells)  # a slope or a step
    union = unary_union([world(p) for p in got])
    cells = unary_union(list(regions.values()))
    assert union.symmetric_difference(cells).area == 0.0
    assert math.fsum(p.shape.area for p in got) == math.fsum(r.area for r in regions.values())
    # Maximal: a piece that ends next to another one could not take its first cell and stay convex
    # (two boxes of a solid run excepted: those stay one per cell on purpose).
    by_start = {p.cells[0]: p for p in got}
    for p in got:
        c, r = p.cells[-1]
        nxt = by_start.get((c + 1, r))
        if nxt is None or (isinstance(p.shape, AABB) and isinstance(nxt.shape, AABB)):
            continue
        joined = unary_union([world(p), regions[(c + 1, r)]])
        assert joined.convex_hull.area > joined.area, (p.cells, nxt.cells)


# --- why: no ghost bumps -----------------------------------------------------------------------------


def test_a_box_crossing_from_the_flat_onto_the_slope_is_not_pushed_back_by_a_seam():
    # A box sliding left over the flat top of "/#", sunk 0.5 into it, its left edge 0.1 past the
    # top of the slope. Cell by cell, the slope's vertical right face is 0.1 deep: a sideways shove
    # (a ghost bump). The merged piece has no face there; every push has an upward part.
    box, where = AABB(16, 16), Transform(31.9 + 8, 31.5 + 8)
    separate = [TerrainPiece(Polygon([(-16, -16), (16, -16), (16, 16)]), 16, 16, ((0, 0),), (0, 32)),
                TerrainPiece(AABB(32, 32), 48, 16, ((1, 0),), (32, 32))]
    normals = [collide(p.shape, Transform(p.x, p.y), box, where).normal for p in separate]
    assert any(n[0] == 1.0 and n[1] == 0.0 for n in normals)  # the ghost
    (merged,) = pieces("/#")
    contact = collide(merged.shape, Transform(merged.x, merged.y), box, where)
    assert contact is not None and contact.normal[1] > 0.5


# --- level files ------------------------------------------------------------------------------------


def test_text_maps_have_a_character_for_each_slope():
    level = parse_text("P.......\n/\\rRFf#-\n########", "slopes.txt")
    assert level.tiles[1] == [SLOPE_UP, SLOPE_DOWN, SLOPE_UP_LOW, SLOPE_UP_HIGH, SLOPE_DOWN_HIGH,
                              SLOPE_DOWN_LOW, "solid", "oneway"]
    assert set(SLOPES) <= set(TILE_KINDS) and TILE_KINDS[:3] == ("solid", "oneway", "spikes")


SLOPED = "P.......G\n..rR#Ff..\n./#####\\.\n#########"


def _map(data: list[int], tiles: list[dict] | None = None, **layer) -> dict:
    """A 3 x 2 Tiled map: a player, one tile layer of ``data``, a tileset with ``tiles``."""
    tmj = to_tmj(parse_text("P..\n...", "m.txt"))
    tmj["tilesets"][0]["tiles"] = tiles if tiles is not None else []
    tmj["layers"][0].update(layer, data=data)
    return tmj


def test_tiled_slopes_by_tileset_type_class_and_kind_property():
    tiles = [{"id": 0, "type": "solid"}, {"id": 4, "type": "slope_up"}, {"id": 5, "class": "slope_down_low"},
             {"id": 7, "properties": [{"name": "kind", "type": "string", "value": "slope_up_high"}]}]
    level = parse_tmj(_map([5, 6, 8, 1, 0, 0], tiles), "types.tmj")
    assert level.tiles == [[SLOPE_UP, SLOPE_DOWN_LOW, SLOPE_UP_HIGH], ["solid", None, None]]


@pytest.mark.parametrize("kind", SLOPES)
def test_tiled_slopes_by_layer_kind_and_layer_name(kind):
    by_prop = parse_tmj(_map([0, 3, 3, 0, 0, 3], properties=[{"name": "kind", "type": "string", "value": kind}]),
                        "prop.tmj")
    by_name = parse_tmj(_map([0, 3, 3, 0, 0, 3], name=kind), "name.tmj")
    assert by_prop.tiles == by_name.tiles == [[None, kind, kind], [None, None, kind]]


FLIP_H, FLIP_V, FLIP_D = 0x80000000, 0x40000000, 0x20000000


def test_a_horizontally_flipped_slope_tile_is_the_mirrored_slope():
    tiles = [{"id": i, "type": k} for i, k in enumerate(TILE_KINDS)]
    gid = {k: i + 1 for i, k in enumerate(TILE_KINDS)}
    for kind in SLOPES:
        level = parse_tmj(_map([gid[kind] | FLIP_H, gid[kind], gid["solid"] | FLIP_H | FLIP_V, 0, 0, 0], tiles),
                          "flip.tmj")
        assert level.tiles[0] == [MIRRORED[kind], kind, "solid"]  # flips of other tiles are ignored
    assert MIRRORED[SLOPE_UP] == SLOPE_DOWN and MIRRORED[SLOPE_UP_LOW] == SLOPE_DOWN_LOW
    assert MIRRORED[SLOPE_UP_HIGH] == SLOPE_DOWN_HIGH
    layer_wide = parse_tmj(_map([0, 0, 0, 9 | FLIP_H, 0, 0],
                                properties=[{"name": "kind", "type": "string", "value": "slope_up"}]), "l.tmj")
    assert layer_wide.tiles[1][0] == SLOPE_DOWN


@pytest.mark.parametrize("flags", [FLIP_V, FLIP_D, FLIP_H | FLIP_V, FLIP_H | FLIP_D, FLIP_V | FLIP_D])
def test_a_slope_flipped_vertically_or_rotated_is_a_level_error_naming_the_cell(flags, tmp_path):
    path = tmp_path / "upside.tmj"
    tiles = [{"id": 3, "type": "slope_up"}]
    path.write_text(json.dumps(_map([0, 0, 0, 0, 4 | flags, 0], tiles, name="ground")))
    with pytest.raises(LevelError) as info:
        load_level(path)
    msg = str(info.value)
    assert msg.startswith(str(path)) and "layer 'ground'" in msg and "column 1, row 1" in msg
    assert "slope" in msg and "upside-down" in msg


def test_slopes_round_trip_text_to_level_to_tiled_and_back(tmp_path):
    level = parse_text(SLOPED, "sloped.txt")
    assert {k for row in level.tiles for k in row} == {None, "solid", *SLOPES}
    tmj = to_tmj(level)
    (ts,) = tmj["tilesets"]
    assert [t["type"] for t in ts["tiles"]] == list(TILE_KINDS) and ts["tilecount"] == len(TILE_KINDS)
    path = tmp_path / "sloped.tmj"
    path.write_text(dump_tmj(tmj))
    again = load_level(path)
    assert again.tiles == level.tiles
    assert [(o.kind, o.x, o.bottom) for o in again.objects] == [(o.kind, o.x, o.bottom) for o in level.objects]
    assert [p.cells for p in terrain_pieces(again.tiles, again.tile)] == \
        [p.cells for p in terrain_pieces(level.tiles, level.tile)]


def test_levels_without_slopes_keep_the_three_tile_tileset_and_shipped_tilesets_are_regenerated():
    (ts,) = to_tmj(parse_text("P.\n##", "flat.txt"))["tilesets"]
    assert ts["tilecount"] == 3 and [t["type"] for t in ts["tiles"]] == ["solid", "oneway", "spikes"]
    assert (ts["imagewidth"], ts["imageheight"]) == (96, 32)
    for path in sorted(LEVEL_DIR.glob("*.tmj")):
        shipped = json.loads(path.read_text())["tilesets"]
        assert to_tmj(load_level(path))["tilesets"] == shipped


def test_the_tileset_image_holds_every_tile_kind():
    png = (LEVEL_DIR / "tiles.png").read_bytes()
    width, height = struct.unpack(">II", png[16:24])
    (ts,) = to_tmj(parse_text("P/\n##", "s.txt"))["tilesets"]
    assert (width, height) == (ts["imagewidth"], ts["imageheight"]) == (96, 128)
    assert ts["tilecount"] <= (width // 32) * (height // 32)


def test_a_quarter_tile_step_is_a_slab_on_the_bottom_of_its_cell():
    (piece,) = terrain_pieces([[None, "step", None], ["solid"] * 0], 32.0)
    assert piece.cells == ((1, 0),) and piece.top == (40.0, 40.0)  # the row's bottom is 32: one row above it
    assert sorted(piece.shape.points) == sorted([(-16.0, -4.0), (16.0, -4.0), (16.0, 4.0), (-16.0, 4.0)])
    assert (piece.x, piece.y) == (48.0, 36.0)
    level = parse_text("#P_.G#\n######", "step.txt")
    assert level.tiles[0][2] == "step"
