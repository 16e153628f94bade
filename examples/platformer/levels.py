"""Level files: Tiled JSON maps (``.tmj``) and a plain-text format for tests and quick sketches.

Both load into the same :class:`Level`: a grid of tile kinds (rows top to bottom, as drawn) and a
list of :class:`LevelObject` in world coordinates (y up, units of the map's pixels). The game
(:mod:`.game`) turns a Level into entities; nothing here knows about the scene.

**Text maps**, one character per tile, rows top to bottom::

    #  solid tile          -  one-way platform     ^  spikes
    /  slope up (45)       \\  slope down (45)
    rR gentle slope up (2:1, two cells: low half, high half)
    Ff gentle slope down (2:1, two cells: high half, low half)
    _  a quarter-tile step (a slab on the bottom quarter of the cell)
    P  player start        C  coin                 E  enemy
    K  checkpoint          G  goal                 .  empty (so is a space)
    B  crate (pushable)    O  barrel (rolls)
    M  moving platform (a run of M is one platform, half a tile thick, one-way)
    ~  the cells a moving platform sweeps: to its right, left, above or below (one side)
    S  swing: a run of S (an odd number of cells) is its board at rest, half a tile thick, one-way
    o  a swing's pivot, straight above the middle of its board (only empty cells or objects between)
    =  rope bridge: a run of = (2 cells or more) is hung between its ends, the deck's top at the
       run's top at both ends, sagging to the run's bottom in the middle (one tile), a plank a cell

Lines starting with ``;`` are comments; short rows are padded with empty cells.

**Tiled maps** (orthogonal, finite, Tiled's JSON export): tile layers give tile kinds, either
for the whole layer (a ``kind`` property, or the layer named after a kind: ``solid``, ``oneway``,
``spikes`` or a slope) or per tile from the tileset (each tile's ``type``/``class`` or ``kind``
property). The slope kinds are those of :mod:`framework.tiles`: ``slope_up``, ``slope_down``,
``slope_up_low``, ``slope_up_high``, ``slope_down_high``, ``slope_down_low``. A slope tile flipped
horizontally (Tiled's flip flag) is the mirrored slope (``slope_up`` <-> ``slope_down``,
``slope_up_low`` <-> ``slope_down_low``, ``slope_up_high`` <-> ``slope_down_high``); a slope
flipped vertically or rotated is an error (upside-down slopes are not supported); flips of other
tiles are ignored. Layers named ``background`` or ``decoration`` (or ``kind`` = ``decoration``) are
ignored. Layer ``data`` may
be a plain array or base64 (uncompressed, zlib or gzip). One object layer (or more) holds
objects whose ``type``/``class`` (or ``name``) is ``player``, ``coin``, ``enemy``, ``goal``,
``checkpoint``, ``platform``, ``swing``, ``bridge``, ``spikes``, ``crate`` or ``barrel``; points and
rectangles both work. Properties:
``platform``: ``dx``, ``dy`` (travel in tiles, y up), ``speed`` (tiles/s), ``one_way`` (bool);
``swing`` (a rectangle: its board at rest, hanging straight below the pivot): ``length`` (tiles
from the pivot down to the board's centre, > 0; required), ``angle`` (the largest swing, degrees,
0 < angle < 90; default 30), ``period`` (s, > 0; default the pendulum's, 2 pi sqrt(length /
gravity), gravity in tiles/s^2 from the game's ``Tuning``), ``phase`` (degrees; default 0: the
swing starts at rest position going right), ``one_way`` (bool, default true);
``bridge`` (a rectangle: its left and right edges are the anchors, its top the deck's top there,
its bottom the deck's top in the middle at rest: the height is the sag): ``planks`` (an integer >=
2; default one a tile of width), ``thickness`` (tiles, > 0, less than a plank's length; default
0.25), ``mass`` (each plank's, > 0; default the game's ``Tuning.plank_mass``);
``enemy``: ``speed`` (tiles/s), ``direction`` (-1 left, 1 right).

**Terrain drawn as lines** (:class:`TerrainLine`): a Tiled **polyline** object (its type empty or
``terrain``) is the surface of the ground: everything below it, down to the map's bottom, is solid
and drawn as ground, whichever way it was drawn. It must run one way across the map (its x never
turning back: steep and vertical drops are fine), so draw an overhang, a ceiling or a floating block
as a **polygon** object, which is a solid block of any outline (not crossing itself). Both become
chains (:func:`framework.tiles.tiled_chains`, :class:`framework.shapes.Chain`): one-sided segments
met from outside the solid, without catching at joints. Tiled's object ``rotation`` is honoured.

The map's ``solver`` property (``exact`` or ``soft``) is the contact solver the game runs the level
with (``Level.solver``); without it, ``soft`` if the level has a bridge (its hinges are joints,
which only the soft solver solves), else none asked for (the game's own). A bridge in a level that
asks for ``exact`` is an error.

A malformed file raises :class:`LevelError`, a ``ValueError`` whose message starts with the
file's name and says what is wrong.
"""

from __future__ import annotations

import base64
import json
import math
import zlib
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NoReturn

from framework import tiles as terrain
from framework.shapes import Chain

__all__ = [
    "DEFAULT_LIMITS", "LEVEL_DIR", "Level", "LevelError", "LevelLimits", "LevelObject", "TerrainLine", "builtin_levels",
    "load_level", "parse_text", "parse_tmj", "to_tmj", "dump_tmj",
]

LEVEL_DIR = Path(__file__).with_name("levels")
# The order gives the tile ids of the tileset ``to_tmj`` writes: new kinds go at the end.
TILE_KINDS = ("solid", "oneway", "spikes", *terrain.SLOPES, terrain.STEP)
OBJECT_KINDS = ("player", "coin", "enemy", "goal", "checkpoint", "platform", "spikes", "crate", "barrel", "swing",
                "bridge")
SOLVERS = ("exact", "soft")  # what a level may ask for (framework.scene.SOLVERS)
DECORATION = ("background", "decoration")
DEFAULT_TILE = 32.0

_TEXT_TILES = {"#": "solid", "-": "oneway", "^": "spikes", "_": terrain.STEP, "/": terrain.SLOPE_UP,
               "\\": terrain.SLOPE_DOWN, "r": terrain.SLOPE_UP_LOW, "R": terrain.SLOPE_UP_HIGH,
               "F": terrain.SLOPE_DOWN_HIGH, "f": terrain.SLOPE_DOWN_LOW}
_TEXT_OBJECTS = {"P": "player", "C": "coin", "E": "enemy", "G": "goal", "K": "checkpoint", "B": "crate",
                 "O": "barrel"}
_TEXT_EMPTY = ". "
_FLIP_BITS = 0xF0000000  # Tiled's flip / rotate flags in the high bits of a gid
_FLIP_H = 0x80000000  # flipped horizontally
_FLIP_V_OR_D = 0x60000000  # flipped vertically, or diagonally (a rotation by 90 degrees)

Fail = Callable[[str], NoReturn]  # raises a LevelError naming the source


class LevelError(ValueError):
    """A level file that cannot be loaded; the message names the file and the problem."""


@dataclass(frozen=True)
class LevelLimits:
    """What a level file may declare, checked before anything is allocated for it (a file from a
    stranger can declare a 100,000 x 100,000 map in a few bytes). Raise them for a bigger game:
    ``load_level(path, limits=LevelLimits(max_tiles=20_000_000))``."""

    max_bytes: int = 16 * 1024 * 1024   # the file's size
    max_tiles: int = 4_000_000          # width x height (2,000 x 2,000)
    max_objects: int = 100_000
    max_layers: int = 1_000
    max_points: int = 100_000           # the points of every terrain line (polyline, polygon) together
    max_polygon_points: int = 1_000     # one polygon's (drawing it takes time quadratic in them)


DEFAULT_LIMITS = LevelLimits()


@dataclass(frozen=True)
class LevelObject:
    """A thing placed in a level: ``kind``, its rectangle in world coordinates (centre ``x, y``,
    y up; ``width`` and ``height`` are 0 for a point) and its properties."""

    kind: str
    x: float
    y: float
    width: float = 0.0
    height: float = 0.0
    props: dict[str, Any] = field(default_factory=dict)

    @property
    def bottom(self) -> float:
        return self.y - self.height * 0.5


@dataclass(frozen=True)
class TerrainLine:
    """Terrain drawn as a line (a Tiled polyline or polygon object), in world coordinates (y up).

    - ``loop`` false (a polyline): ``points`` is the ground's surface, left to right (x never
      decreasing); the ground is everything below it down to the map's bottom (y = 0).
    - ``loop`` true (a polygon): ``points`` is the outline of a solid block (the loader gives it
      counter-clockwise; either winding is the same block).

    :meth:`outline` is the solid's outline either way, :meth:`chain` its collision chain."""

    points: tuple[tuple[float, float], ...]
    loop: bool = False
    #: where it came from, for messages (e.g. ``"polyline object 7"``)
    label: str = field(default="", compare=False)

    def outline(self) -> list[tuple[float, float]]:
        """The solid's outline, counter-clockwise (y up): a polygon's points; a polyline's surface
        closed down to the map's bottom (its ends' feet, unless an end is on the bottom already)."""
        if self.loop:
            pts = list(self.points)
            area2 = sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1]))
            return pts if area2 >= 0.0 else pts[::-1]
        pts = list(self.points)
        (x0, y0), (x1, y1) = pts[0], pts[-1]
        feet = [(x1, 0.0)] * (y1 != 0.0) + [(x0, 0.0)] * (y0 != 0.0)
        return [*reversed(pts), *reversed(feet)]  # right to left along the top, then the feet left to right

    def chain(self) -> Chain:
        """The collision chain: a loop round :meth:`outline`, met from outside."""
        return Chain(self.outline(), loop=True)


@dataclass
class Level:
    """A loaded level: ``tiles[row][col]`` is a kind from ``TILE_KINDS`` or ``None``, row 0 at the
    top; the world's origin is the map's bottom-left corner, one tile is ``tile`` units."""

    name: str
    source: str
    tile: float
    width: int
    height: int
    tiles: list[list[str | None]]
    objects: list[LevelObject]
    #: the contact solver the level is played with (``"exact"`` or ``"soft"``); ``None``: the game's
    solver: str | None = None
    #: terrain drawn as lines (Tiled polylines and polygons), beside the tiles
    terrain: list[TerrainLine] = field(default_factory=list)

    @property
    def size(self) -> tuple[float, float]:
        """World width and height of the map."""
        return self.width * self.tile, self.height * self.tile

    def cell_center(self, col: int, row: int) -> tuple[float, float]:
        return (col + 0.5) * self.tile, (self.height - row - 0.5) * self.tile

    def of_kind(self, kind: str) -> list[LevelObject]:
        return [o for o in self.objects if o.kind == kind]

    @property
    def player(self) -> LevelObject:
        return self.of_kind("player")[0]

    def validate(self) -> Level:
        """Check what every level needs; raise :class:`LevelError` naming the source."""
        def fail(msg: str) -> NoReturn:
            raise LevelError(f"{self.source}: {msg}")

        if not (math.isfinite(self.tile) and self.tile > 0):
            fail(f"tile size must be a positive number, got {self.tile!r}")
        if self.width < 1 or self.height < 1:
            fail(f"the map is empty ({self.width} x {self.height} tiles)")
        players = self.of_kind("player")
        if len(players) != 1:
            fail(f"needs exactly one player start, found {len(players)}")
        w, h = self.size
        for o in self.objects:
            if o.kind not in OBJECT_KINDS:
                fail(f"unknown object kind {o.kind!r} (known: {', '.join(OBJECT_KINDS)})")
            if not all(math.isfinite(v) for v in (o.x, o.y, o.width, o.height)):
                fail(f"{o.kind} at ({o.x}, {o.y}) has a non-finite position or size")
            if not (0 <= o.x <= w and 0 <= o.y <= h):
                fail(f"{o.kind} at ({o.x:g}, {o.y:g}) lies outside the map (0..{w:g}, 0..{h:g})")
            if o.kind == "platform":
                if o.width <= 0 or o.height <= 0:
                    fail(f"platform at ({o.x:g}, {o.y:g}) needs a rectangle (width and height > 0)")
                for key in ("dx", "dy", "speed"):
                    if not _is_number(o.props.get(key, 0.0)):
                        fail(f"platform at ({o.x:g}, {o.y:g}): {key} must be a number, "
                             f"got {_show(o.props[key])}")
                if o.props.get("dx", 0) == 0 and o.props.get("dy", 0) == 0:
                    fail(f"platform at ({o.x:g}, {o.y:g}) does not move: give it dx or dy")
                if not float(o.props.get("speed", 2.0)) > 0:
                    fail(f"platform at ({o.x:g}, {o.y:g}): speed must be > 0")
            if o.kind == "swing":
                _check_swing(o, fail)
            if o.kind == "bridge":
                _check_bridge(o, self.tile, fail)
            if o.kind == "enemy":
                if not _is_number(o.props.get("speed", 2.0)) or not float(o.props.get("speed", 2.0)) >= 0:
                    fail(f"enemy at ({o.x:g}, {o.y:g}): speed must be a number >= 0")
                if o.props.get("direction", -1) not in (-1, 1):
                    fail(f"enemy at ({o.x:g}, {o.y:g}): direction must be -1 or 1, "
                         f"got {_show(o.props.get('direction'))}")
        for i, line in enumerate(self.terrain):
            _check_terrain(line, i, w, h, self.tile, fail)
        start = players[0]
        for line in self.terrain:
            if _inside(line.outline(), start.x, start.bottom + 0.5 * self.tile):
                fail(f"the player start at ({start.x:g}, {start.bottom:g}) is inside the ground of "
                     f"{line.label or 'a terrain line'}: put it above the surface")
        if self.solver is not None and (not isinstance(self.solver, str) or self.solver not in SOLVERS):
            fail(f"solver must be one of {', '.join(SOLVERS)}, got {_show(self.solver)}")
        if self.of_kind("bridge"):
            if self.solver == "exact":
                fail("the level has a bridge, whose hinges are joints, which only the soft solver solves: "
                     "solver must be soft (or not given), got 'exact'")
            self.solver = "soft"
        return self


def _check_terrain(line: TerrainLine, i: int, w: float, h: float, tile: float, fail: Fail) -> None:
    """A terrain line: inside the map, a chain (no two equal points in a row...), and a polyline
    running left to right, never turning back."""
    if not isinstance(line, TerrainLine):
        fail(f"terrain {i + 1} must be a TerrainLine, got {_show(line)}")
    what = line.label or f"terrain {'polygon' if line.loop else 'polyline'} {i + 1}"
    eps = 1e-9 * tile
    for x, y in line.points:
        if not (-eps <= x <= w + eps and -eps <= y <= h + eps):
            fail(f"{what}: point ({x:g}, {y:g}) lies outside the map (0..{w:g}, 0..{h:g})")
    if not line.loop:
        xs = [p[0] for p in line.points]
        back = next((j for j in range(1, len(xs)) if xs[j] < xs[j - 1] - eps), None)
        if back is not None or not xs[-1] > xs[0]:
            where = f"turns back at point {back}" if back is not None else "does not run across the map"
            fail(f"{what} {where}: a polyline is the surface of the ground below it and must run one way "
                 "across the map (steep and vertical drops are fine); draw an overhang, a ceiling or a "
                 "floating block as a polygon")
    try:
        line.chain()
        if line.loop:
            from .terrain import triangulate

            triangulate(line.outline())  # (what draws it: a polygon must not cross itself)
    except ValueError as exc:
        fail(f"{what}: {exc}")


def _inside(outline: list[tuple[float, float]], x: float, y: float) -> bool:
    """Whether ``(x, y)`` is inside the polygon ``outline`` (even-odd rule)."""
    inside = False
    for (x0, y0), (x1, y1) in zip(outline, outline[1:] + outline[:1]):
        if (y0 > y) != (y1 > y) and x < x0 + (y - y0) * (x1 - x0) / (y1 - y0):
            inside = not inside
    return inside


def _check_swing(o: LevelObject, fail: Fail) -> None:
    """A swing: a board (a rectangle) ``length`` tiles below its pivot; ``angle`` (degrees, the
    largest swing), ``period`` (s), ``phase`` (degrees) and ``one_way`` (bool), all optional."""
    where = f"swing at ({o.x:g}, {o.y:g})"
    if o.width <= 0 or o.height <= 0:
        fail(f"{where} needs a rectangle, the board (width and height > 0)")
    if "length" not in o.props:
        fail(f"{where} has no length: give it 'length', tiles from the pivot down to the board's centre")
    for key in ("length", "angle", "period", "phase"):
        if key in o.props and not _is_number(o.props[key]):
            fail(f"{where}: {key} must be a number, got {_show(o.props[key])}")
    if not float(o.props["length"]) > 0:
        fail(f"{where}: length must be > 0 (tiles from the pivot to the board), got {_show(o.props['length'])}")
    if not 0 < float(o.props.get("angle", 30.0)) < 90:
        fail(f"{where}: angle must be between 0 and 90 degrees (the largest swing), "
             f"got {_show(o.props['angle'])}")
    if "period" in o.props and not float(o.props["period"]) > 0:
        fail(f"{where}: period must be > 0 seconds, got {_show(o.props['period'])}")
    if not isinstance(o.props.get("one_way", True), bool):
        fail(f"{where}: one_way must be true or false, got {_show(o.props['one_way'])}")


def _check_bridge(o: LevelObject, tile: float, fail: Fail) -> None:
    """A bridge: a rectangle (anchors at its left and right edges, the deck's top at its top there;
    its height the sag); ``planks`` (an int >= 2), ``thickness`` (tiles) and ``mass`` (each
    plank's), all optional. The planks must be longer than thick."""
    from .bridge import plank_length

    where = f"bridge at ({o.x:g}, {o.y:g})"
    if o.width <= 0 or o.height <= 0:
        fail(f"{where} needs a rectangle: its width the span between the anchors, its height the sag "
             f"(width and height > 0), got {o.width:g} x {o.height:g}")
    planks = o.props.get("planks", bridge_planks(o, tile))
    if isinstance(planks, bool) or not isinstance(planks, int) or planks < 2:
        fail(f"{where}: planks must be an integer >= 2, got {_show(planks)}")
    for key in ("thickness", "mass"):
        if key in o.props and not _is_number(o.props[key]):
            fail(f"{where}: {key} must be a number, got {_show(o.props[key])}")
        if key in o.props and not float(o.props[key]) > 0:
            fail(f"{where}: {key} must be > 0, got {_show(o.props[key])}")
    thickness = float(o.props.get("thickness", 0.25)) * tile
    length = plank_length(o.width, o.height, planks)
    if not thickness < length:
        fail(f"{where}: thickness must be less than a plank's length ({length / tile:.4g} tiles for {planks} "
             f"planks), got {_show(o.props.get('thickness', 0.25))}")


def bridge_planks(o: LevelObject, tile: float) -> int:
    """A bridge's plank count: its ``planks`` property, else one a tile of its width (at least 2)."""
    planks = o.props.get("planks")
    return planks if isinstance(planks, int) and not isinstance(planks, bool) else max(2, round(o.width / tile))


def _is_number(v: object) -> bool:
    """A finite number that float64 holds (an int beyond it, ``10**400``, is not: False, no
    ``OverflowError``)."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return False
    try:
        return math.isfinite(v)
    except OverflowError:
        return False


def _show(v: object) -> str:
    """``repr`` of a value a file gave, for a message: cut to 80 characters, and never raising
    (an int of more than 4,300 digits cannot be printed, a list nested near the recursion limit
    cannot be repr'd from a deeper frame than the one that parsed it)."""
    try:
        text = repr(v)
    except (ValueError, RecursionError):
        return f"a {type(v).__name__} too long or too deeply nested to show"
    return text if len(text) <= 80 else f"{text[:60]}... ({len(text)} characters)"


def _text(v: object) -> str:
    """A name a file gave (a layer's, an object's type), as text: itself if it is text, else :func:`_show`."""
    return v if isinstance(v, str) else _show(v)


# --- text maps -------------------------------------------------------------------------------------


def parse_text(
    text: str, source: str = "<text>", *, tile: float = DEFAULT_TILE, name: str | None = None,
    limits: LevelLimits = DEFAULT_LIMITS,
) -> Level:
    """A :class:`Level` from a text map (see the module docstring for the characters)."""
    def fail(msg: str) -> NoReturn:
        raise LevelError(f"{source}: {msg}")

    if not isinstance(text, str):
        fail(f"a text map must be text, got {type(text).__name__}")
    if len(text) > limits.max_bytes:
        fail(f"the map is {len(text)} characters long, more than the limit of {limits.max_bytes} "
             "(LevelLimits.max_bytes)")

    lines = [ln.rstrip("\r\n").rstrip() for ln in text.splitlines()]
    lines = [ln for ln in lines if not ln.lstrip().startswith(";")]
    while lines and not lines[0].strip():
        lines.pop(0)
    while lines and not lines[-1].strip():
        lines.pop()
    if not lines:
        fail("the map is empty")
    width = max(len(ln) for ln in lines)
    if width * len(lines) > limits.max_tiles:
        fail(f"the map is {width} x {len(lines)} tiles, more than the limit of {limits.max_tiles} "
             "(LevelLimits.max_tiles)")
    grid = [ln.ljust(width, ".") for ln in lines]
    height = len(grid)
    tiles: list[list[str | None]] = [[None] * width for _ in range(height)]
    objects: list[LevelObject] = []
    known = set(_TEXT_TILES) | set(_TEXT_OBJECTS) | set(_TEXT_EMPTY) | {"M", "~", "S", "o", "="}

    def center(col: int, row: int) -> tuple[float, float]:
        return (col + 0.5) * tile, (height - row - 0.5) * tile

    for row, line in enumerate(grid):
        for col, ch in enumerate(line):
            if ch not in known:
                fail(f"unknown character {ch!r} at line {row + 1}, column {col + 1} "
                     f"(known: {''.join(sorted(known - {' '}))})")
            if ch in _TEXT_TILES:
                tiles[row][col] = _TEXT_TILES[ch]
            elif ch in _TEXT_OBJECTS:
                x, y = center(col, row)
                objects.append(LevelObject(_TEXT_OBJECTS[ch], x, y, tile, tile))
    objects.extend(_text_platforms(grid, tile, fail))
    objects.extend(_text_swings(grid, tile, fail))
    objects.extend(_text_bridges(grid, tile, fail))
    return Level(name or Path(source).stem, source, float(tile), width, height, tiles, objects).validate()


def _runs(grid: list[str], ch: str) -> Iterator[tuple[int, int, int]]:
    """``(row, start, end)`` of every run of ``ch`` in a row of the text map (columns start to
    end - 1), top to bottom, left to right."""
    for row, line in enumerate(grid):
        col = 0
        while col < len(line):
            if line[col] != ch:
                col += 1
                continue
            start = col
            while col < len(line) and line[col] == ch:
                col += 1
            yield row, start, col


def _cells(grid: list[str], ch: str) -> Iterator[tuple[int, int]]:
    """``(row, col)`` of every ``ch`` in the text map."""
    for row, line in enumerate(grid):
        for col, c in enumerate(line):
            if c == ch:
                yield row, col


def _text_platforms(grid: list[str], tile: float, fail: Fail) -> list[LevelObject]:
    height, width = len(grid), len(grid[0])
    out = []
    used = set()
    for row, start, col in _runs(grid, "M"):
        run = col - start

        def count(cells: Iterable[tuple[int, int]]) -> int:
            n = 0
            for r, c in cells:
                if not (0 <= r < height and 0 <= c < width) or grid[r][c] != "~":
                    break
                used.add((r, c))
                n += 1
            return n

        right = count((row, c) for c in range(col, width))
        left = count((row, c) for c in range(start - 1, -1, -1))
        up = count((r, start) for r in range(row - 1, -1, -1))
        down = count((r, start) for r in range(row + 1, height))
        sides = [(d, n) for d, n in (("right", right), ("left", left), ("up", up), ("down", down)) if n]
        where = f"moving platform at line {row + 1}, column {start + 1}"
        if not sides:
            fail(f"{where} has no path: mark the cells it sweeps with '~' on one side")
        if len(sides) > 1:
            fail(f"{where} has '~' paths on several sides ({', '.join(d for d, _ in sides)}); use one")
        side, n = sides[0]
        dx = {"right": n, "left": -n}.get(side, 0)
        dy = {"up": n, "down": -n}.get(side, 0)
        x = (start + run * 0.5) * tile
        y = (height - row) * tile - tile * 0.25
        out.append(LevelObject("platform", x, y, run * tile, tile * 0.5,
                               {"dx": float(dx), "dy": float(dy), "speed": 2.0, "one_way": True}))
    for row, col in _cells(grid, "~"):
        if (row, col) not in used:
            fail(f"'~' at line {row + 1}, column {col + 1} is not next to a moving platform's path")
    return out


def _text_swings(grid: list[str], tile: float, fail: Fail) -> list[LevelObject]:
    """Swings: a run of ``S`` (an odd number of cells) is the board at rest, half a tile thick on
    the top of its cells; the ``o`` straight above its middle cell (only empty cells or objects
    between) is the pivot, at that cell's centre."""
    height = len(grid)
    out = []
    pivots = set()
    for row, start, col in _runs(grid, "S"):
        where = f"swing at line {row + 1}, column {start + 1}"
        if (col - start) % 2 == 0:
            fail(f"{where}: its board is {col - start} cells long; make it an odd number, so that "
                 "its pivot 'o' can stand above its middle cell")
        mid = (start + col) // 2
        r = row - 1
        while r >= 0 and (grid[r][mid] in _TEXT_EMPTY or grid[r][mid] in _TEXT_OBJECTS):
            r -= 1
        if r < 0 or grid[r][mid] != "o":
            fail(f"{where} has no pivot: put an 'o' above the middle of its board (column {mid + 1}), "
                 "with only empty cells (or objects) between")
        pivots.add((r, mid))
        y = (height - row) * tile - tile * 0.25
        length = ((height - r - 0.5) * tile - y) / tile
        out.append(LevelObject("swing", (mid + 0.5) * tile, y, (col - start) * tile, tile * 0.5,
                               {"length": length, "one_way": True}))
    for row, col in _cells(grid, "o"):
        if (row, col) not in pivots:
            fail(f"'o' at line {row + 1}, column {col + 1} is not the pivot of a swing "
                 "(a run of 'S' straight below it)")
    return out


def _text_bridges(grid: list[str], tile: float, fail: Fail) -> list[LevelObject]:
    """Bridges: a run of ``=`` (2 cells or more) is hung between the run's outer edges, the deck's
    top at the run's top at both ends and sagging to the run's bottom in the middle: the rectangle
    of its cells. One plank a cell."""
    height = len(grid)
    out = []
    for row, start, col in _runs(grid, "="):
        if col - start < 2:
            fail(f"bridge at line {row + 1}, column {start + 1} is one cell long: a bridge needs 2 or more '='")
        out.append(LevelObject("bridge", (start + col) * 0.5 * tile, (height - row - 0.5) * tile, (col - start) * tile,
                               tile))
    return out


# --- Tiled maps ------------------------------------------------------------------------------------


def parse_tmj(data: Any, source: str = "<tmj>", *, name: str | None = None,
              limits: LevelLimits = DEFAULT_LIMITS) -> Level:
    """A :class:`Level` from a decoded Tiled JSON map. What it declares is checked against
    ``limits`` and against what it holds before anything is allocated for it."""
    def fail(msg: str) -> NoReturn:
        raise LevelError(f"{source}: {msg}")

    if not isinstance(data, dict):
        fail(f"a Tiled map must be a JSON object, got {type(data).__name__}")
    if data.get("type", "map") != "map":
        fail(f"not a Tiled map (type is {_show(data.get('type'))})")
    if data.get("orientation", "orthogonal") != "orthogonal":
        fail(f"only orthogonal maps are supported, got {_show(data.get('orientation'))}")
    if data.get("infinite"):
        fail("infinite maps are not supported; save the map as finite (Map > Map Properties)")
    for key in ("width", "height", "tilewidth", "tileheight", "layers"):
        if key not in data:
            fail(f"missing {key!r}")
    width, height, tw, th = data["width"], data["height"], data["tilewidth"], data["tileheight"]
    for key, v in (("width", width), ("height", height), ("tilewidth", tw), ("tileheight", th)):
        if isinstance(v, bool) or not isinstance(v, int) or v < 1:
            fail(f"{_show(key)} must be a positive integer, got {_show(v)}")
    if tw != th:
        fail(f"tiles must be square, got tilewidth {_show(tw)} and tileheight {_show(th)}")
    if not isinstance(data["layers"], list):
        fail("'layers' must be a list")
    if width * height > limits.max_tiles:
        fail(f"the map declares {_show(width)} x {_show(height)} = {_show(width * height)} tiles, more than the "
             f"limit of "
             f"{limits.max_tiles} (LevelLimits.max_tiles)")
    if not (_is_number(width * tw) and _is_number(height * th)):  # 10**400: beyond float64
        fail(f"the map is {_show(width)} x {_show(height)} tiles of {_show(tw)} pixels: its size in pixels is "
             "too large for a float64")
    layers = _flat_layers(data["layers"], fail, limits)
    for layer in layers:  # what each tile layer holds must match the size declared, before any grid exists
        held = layer.get("data")
        if layer.get("type") == "tilelayer" and isinstance(held, list) and len(held) != width * height:
            fail(f"layer {_show(layer.get('name', ''))} has {len(held)} tiles, expected width x height = "
                 f"{width} x {height} = {width * height}")
    gid_kinds = _tileset_kinds(data.get("tilesets", []), fail)
    tiles: list[list[str | None]] = [[None] * width for _ in range(height)]
    objects: list[LevelObject] = []
    lines: list[TerrainLine] = []
    points = 0
    map_h = float(height * th)
    for layer in layers:
        lname = _text(layer.get("name", ""))
        ltype = layer.get("type")
        where = f"layer {_show(lname)}"
        if ltype == "tilelayer":
            kind = _props(layer, fail, where).get("kind", lname.lower())
            if kind in DECORATION or lname.lower() in DECORATION:
                continue
            if kind not in TILE_KINDS:
                kind = None  # per-tile kinds from the tileset
            gids = _layer_data(layer, width, height, fail, where)
            for i, raw in enumerate(gids):
                gid = raw & ~_FLIP_BITS
                if gid == 0:
                    continue
                row, col = divmod(i, width)
                k = kind or gid_kinds.get(gid)
                if k is None:
                    fail(f"{where}: tile {gid} at column {col}, row {row} has no kind: name the layer "
                         f"{'/'.join(TILE_KINDS)}, give it a 'kind' property, or give the tile a type")
                if k in terrain.SLOPES:
                    if raw & _FLIP_V_OR_D:
                        fail(f"{where}: {k} tile {gid} at column {col}, row {row} is flipped vertically "
                             "or rotated; upside-down slopes are not supported (flip slopes horizontally "
                             "only)")
                    if raw & _FLIP_H:
                        k = terrain.MIRRORED[k]
                tiles[row][col] = k
        elif ltype == "objectgroup":
            objs = layer.get("objects", [])
            if not isinstance(objs, list):
                fail(f"{where}: 'objects' must be a list")
            if len(objects) + len(objs) > limits.max_objects:
                fail(f"{where}: more than {limits.max_objects} objects (LevelLimits.max_objects)")
            for obj in objs:
                if isinstance(obj, dict) and ("polyline" in obj or "polygon" in obj):
                    drawn = obj.get("polygon", obj.get("polyline"))
                    points += len(drawn) if isinstance(drawn, list) else 0
                    if points > limits.max_points:
                        fail(f"{where}: more than {limits.max_points} points of polylines and polygons "
                             "(LevelLimits.max_points)")
                    if "polygon" in obj and isinstance(drawn, list) and len(drawn) > limits.max_polygon_points:
                        fail(f"{where}: polygon object {_text(obj.get('id', '?'))} has {len(drawn)} points, more than "
                             f"{limits.max_polygon_points} (LevelLimits.max_polygon_points)")
                    lines.append(_tmj_line(obj, map_h, fail, where))
                else:
                    objects.append(_tmj_object(obj, map_h, fail, where))
        elif ltype in ("imagelayer",):
            continue
        else:
            fail(f"{where}: unknown layer type {_show(ltype)}")
    map_props = _props(data, fail, "map")
    title = map_props.get("title") or name or Path(source).stem
    return Level(_text(title), source, float(tw), width, height, tiles, objects, map_props.get("solver"),
                 lines).validate()


def _flat_layers(layers: list, fail: Fail, limits: LevelLimits) -> list[dict]:
    """The layers, groups opened (without recursion: a hostile file may nest them deeply)."""
    out: list[dict] = []
    todo = [iter(layers)]
    while todo:
        layer = next(todo[-1], None)
        if layer is None:
            todo.pop()
            continue
        if not isinstance(layer, dict):
            fail(f"a layer must be a JSON object, got {_show(layer)}")
        if layer.get("type") == "group":
            inner = layer.get("layers", [])
            if not isinstance(inner, list):
                fail(f"group layer {_show(layer.get('name', ''))}: 'layers' must be a list")
            todo.append(iter(inner))
        else:
            out.append(layer)
        if len(out) + len(todo) > limits.max_layers:
            fail(f"more than {limits.max_layers} layers (LevelLimits.max_layers)")
    return out


def _props(thing: dict, fail: Fail, where: str) -> dict[str, Any]:
    """Tiled's ``properties`` (a list of ``{name, type, value}``; an old-style dict also works)."""
    raw = thing.get("properties", [])
    if isinstance(raw, dict):
        return dict(raw)
    if not isinstance(raw, list):
        fail(f"{where}: 'properties' must be a list")
    out = {}
    for p in raw:
        if not isinstance(p, dict) or not isinstance(p.get("name"), str) or "value" not in p:
            fail(f"{where}: a property needs a 'name' (text) and a 'value', got {_show(p)}")
        out[p["name"]] = p["value"]
    return out


def _tileset_kinds(tilesets: Any, fail: Fail) -> dict[int, str]:
    if not isinstance(tilesets, list):
        fail("'tilesets' must be a list")
    kinds: dict[int, str] = {}
    for ts in tilesets:
        if not isinstance(ts, dict) or "firstgid" not in ts:
            fail(f"a tileset needs 'firstgid', got {_show(ts)}")
        if "source" in ts:
            fail(f"external tileset {_show(ts['source'])} is not supported: embed the tileset in the map")
        first = ts["firstgid"]
        if isinstance(first, bool) or not isinstance(first, int) or first < 1:
            fail(f"tileset {_show(ts.get('name'))}: 'firstgid' must be a positive integer, got {_show(first)}")
        tiles = ts.get("tiles", [])
        if not isinstance(tiles, list):
            fail(f"tileset {_show(ts.get('name'))}: 'tiles' must be a list")
        for tile in tiles:
            if not isinstance(tile, dict):
                fail(f"tileset {_show(ts.get('name'))}: a tile must be a JSON object, got {_show(tile)}")
            kind = _props(tile, fail, f"tileset {_show(ts.get('name'))}").get(
                "kind", tile.get("type") or tile.get("class"))
            if not isinstance(kind, str | None):
                fail(f"tileset {_show(ts.get('name'))}: tile {_show(tile.get('id'))} has a kind that is not text: "
                     f"{_show(kind)}")
            if kind in DECORATION:
                continue
            if kind is not None:
                if kind not in TILE_KINDS:
                    fail(f"tileset {_show(ts.get('name'))}: tile {_show(tile.get('id'))} has unknown kind "
                         f"{_show(kind)} "
                         f"(known: {', '.join(TILE_KINDS)})")
                tid = tile.get("id")
                if isinstance(tid, bool) or not isinstance(tid, int) or tid < 0:
                    fail(f"tileset {_show(ts.get('name'))}: a tile's 'id' must be an integer >= 0, got {_show(tid)}")
                kinds[first + tid] = kind
    return kinds


def _layer_data(layer: dict, width: int, height: int, fail: Fail, where: str) -> list[int]:
    if layer.get("width", width) != width or layer.get("height", height) != height:
        fail(f"{where} is {layer.get('width')} x {layer.get('height')} tiles, the map {width} x {height}")
    data = layer.get("data")
    if data is None:
        fail(f"{where} has no 'data' (chunks of infinite maps are not supported)")
    if layer.get("encoding") == "base64":
        want = 4 * width * height  # bytes of the gids the map declares: never inflate more than that
        if not isinstance(data, str):
            fail(f"{where}: base64 tile data must be text, got {type(data).__name__}")
        try:
            raw = base64.b64decode(data, validate=True)
            comp = layer.get("compression", "")
            if comp in ("zlib", "gzip"):
                inflate = zlib.decompressobj(zlib.MAX_WBITS | (16 if comp == "gzip" else 0))
                raw = inflate.decompress(raw, want + 1)
                if len(raw) > want:
                    fail(f"{where}: the compressed tile data holds more than the {want} bytes the map's "
                         f"{width} x {height} tiles need")
            elif comp:
                fail(f"{where}: unsupported compression {_show(comp)} (use none, zlib or gzip)")
        except (ValueError, zlib.error, OSError) as exc:
            fail(f"{where}: bad base64 tile data ({exc})")
        if len(raw) % 4:
            fail(f"{where}: base64 tile data is not a whole number of 32-bit gids")
        gids = [int.from_bytes(raw[i:i + 4], "little") for i in range(0, len(raw), 4)]
    else:
        if not isinstance(data, list) or not all(
                isinstance(g, int) and not isinstance(g, bool) and g >= 0 for g in data):
            fail(f"{where}: 'data' must be a list of tile ids (non-negative integers)")
        gids = data
    if len(gids) != width * height:
        fail(f"{where} has {len(gids)} tiles, expected width x height = "
             f"{width} x {height} = {width * height}")
    return gids


def _tmj_object(obj: Any, map_h: float, fail: Fail, where: str) -> LevelObject:
    if not isinstance(obj, dict):
        fail(f"{where}: an object must be a JSON object, got {_show(obj)}")
    kind = _text(obj.get("type") or obj.get("class") or obj.get("name") or "").lower()
    label = f"{where}: object {_text(obj.get('id', '?'))} ({kind or 'no type'})"
    if kind not in OBJECT_KINDS:
        fail(f"{label}: unknown object type {_show(kind)} (known: {', '.join(OBJECT_KINDS)})")
    vals = []
    for key in ("x", "y", "width", "height"):
        v = obj.get(key, 0.0)
        if not _is_number(v):
            fail(f"{label}: {_show(key)} must be a finite number, got {_show(v)}")
        vals.append(float(v))
    x, y, w, h = vals
    if w < 0 or h < 0:
        fail(f"{label}: negative size {w} x {h}")
    if obj.get("rotation", 0):
        fail(f"{label}: rotated objects are not supported")
    cx = x + w * 0.5
    # Tiled is y down from the map's top; rectangles hang from (x, y), tile objects stand on it.
    cy = map_h - (y - h * 0.5 if obj.get("gid") else y + h * 0.5)
    return LevelObject(kind, cx, cy, w, h, _props(obj, fail, label))


def _tmj_line(obj: dict, map_h: float, fail: Fail, where: str) -> TerrainLine:
    """A polyline or polygon object as a :class:`TerrainLine` (a polyline put left to right)."""
    loop = "polygon" in obj
    label = f"{'polygon' if loop else 'polyline'} object {_text(obj.get('id', '?'))}"
    kind = _text(obj.get("type") or obj.get("class") or "").lower()
    if kind not in ("", "terrain"):
        fail(f"{where}: {label}: polylines and polygons are terrain; its type must be empty or 'terrain', "
             f"got {_show(kind)}")
    if not isinstance(obj.get("polygon" if loop else "polyline"), list):
        fail(f"{where}: {label}: its points must be a list, got {_show(obj.get('polygon' if loop else 'polyline'))}")
    try:
        (chain,) = terrain.tiled_chains([obj], map_h)
    except ValueError as exc:
        fail(f"{where}: {exc}")
    pts = chain.points
    if not loop and pts[-1][0] < pts[0][0]:
        pts = pts[::-1]  # left to right, whichever way it was drawn
    return TerrainLine(tuple(pts), loop, label)


# --- loading and writing ---------------------------------------------------------------------------


def load_level(path: str | Path, *, limits: LevelLimits = DEFAULT_LIMITS) -> Level:
    """Load a ``.tmj`` (or ``.json``) Tiled map or a ``.txt`` text map; :class:`LevelError` if bad
    (whatever the file holds: see :class:`LevelLimits` for what a file may declare)."""
    p = Path(path)
    try:
        size = p.stat().st_size
        if size > limits.max_bytes:
            raise LevelError(f"{p}: the file is {size} bytes, more than the limit of {limits.max_bytes} "
                             "(LevelLimits.max_bytes)")
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise LevelError(f"{p}: no such level file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise LevelError(f"{p}: cannot read the level file ({exc})") from None
    suffix = p.suffix.lower()
    if suffix in (".tmj", ".json"):
        try:
            data = json.loads(text)
        except ValueError as exc:  # JSONDecodeError, or an int of more than 4,300 digits (int max str digits)
            raise LevelError(f"{p}: not valid JSON ({exc})") from None
        except RecursionError:
            raise LevelError(f"{p}: the JSON is nested too deeply to be a level") from None
        return parse_tmj(data, str(p), limits=limits)
    if suffix == ".txt":
        return parse_text(text, str(p), limits=limits)
    raise LevelError(f"{p}: unknown level format {suffix!r} (use .tmj or .txt)")


def builtin_levels() -> list[Path]:
    """The shipped levels, in play order."""
    return sorted(LEVEL_DIR.glob("*.tmj"))


# levels/tiles.png (art.py draws it): three tiles a row, in the order of TILE_KINDS (solid, one-way,
# spikes, then the slopes); its first row is the original three-tile tileset, so old ids keep their
# meaning. A level without slopes is written with that original tileset (the first row only), so its
# file is unchanged; a level with slopes gets every tile.
_TILESET_COLUMNS = 3
_BASIC_KINDS = 3  # solid, oneway, spikes


def _tileset(tile: float, kinds: int) -> dict[str, Any]:
    """The embedded tileset of ``to_tmj``: the first ``kinds`` of TILE_KINDS, typed, ``tile`` wide."""
    t = int(tile)
    rows = -(-kinds // _TILESET_COLUMNS)
    return {
        "firstgid": 1, "name": "platformer", "tilewidth": t, "tileheight": t, "tilecount": kinds,
        "columns": min(kinds, _TILESET_COLUMNS), "margin": 0, "spacing": 0, "image": "tiles.png",
        "imagewidth": int(_TILESET_COLUMNS * tile), "imageheight": int(rows * tile),
        "tiles": [{"id": i, "type": k} for i, k in enumerate(TILE_KINDS[:kinds])],
    }


def to_tmj(level: Level, title: str | None = None) -> dict[str, Any]:
    """The Tiled JSON map of ``level`` (what the shipped ``.tmj`` files were written from)."""
    t = level.tile
    gid = {k: i + 1 for i, k in enumerate(TILE_KINDS)}
    data = [gid[k] if k else 0 for row in level.tiles for k in row]
    map_h = level.height * t
    objs = []
    for i, o in enumerate(level.objects, start=1):
        entry: dict[str, Any] = {"id": i, "name": "", "type": o.kind, "rotation": 0, "visible": True}
        if o.kind in ("player", "enemy"):
            # A point at the feet: bottom-centre of the cell it was drawn in.
            entry.update(x=o.x, y=map_h - o.bottom, width=0, height=0, point=True)
        elif o.kind == "coin":
            entry.update(x=o.x, y=map_h - o.y, width=0, height=0, point=True)
        else:
            entry.update(x=o.x - o.width * 0.5, y=map_h - (o.y + o.height * 0.5),
                         width=o.width, height=o.height)
        if o.props:
            entry["properties"] = [
                {"name": k, "type": "bool" if isinstance(v, bool) else "float" if isinstance(v, float)
                 else "int" if isinstance(v, int) else "string", "value": v}
                for k, v in sorted(o.props.items())
            ]
        objs.append(entry)
    for line in level.terrain:  # at the object layer's origin, the points in Tiled's frame (y down)
        points = [{"x": x, "y": map_h - y} for x, y in line.points]
        objs.append({"id": len(objs) + 1, "name": "", "type": "terrain", "rotation": 0, "visible": True, "x": 0,
                     "y": 0, "polygon" if line.loop else "polyline": points})
    sloped = any(k in terrain.SLOPES or k == terrain.STEP for row in level.tiles for k in row)
    tileset = _tileset(t, len(TILE_KINDS) if sloped else _BASIC_KINDS)
    return {
        "type": "map", "version": "1.10", "tiledversion": "1.10.2", "orientation": "orthogonal",
        "renderorder": "right-down", "infinite": False, "compressionlevel": -1,
        "width": level.width, "height": level.height, "tilewidth": int(t), "tileheight": int(t),
        "nextlayerid": 3, "nextobjectid": len(objs) + 1,
        "properties": [{"name": "title", "type": "string", "value": title or level.name},
                       *([{"name": "solver", "type": "string", "value": level.solver}] if level.solver else [])],
        "tilesets": [tileset],
        "layers": [
            {"type": "tilelayer", "id": 1, "name": "tiles", "x": 0, "y": 0, "width": level.width,
             "height": level.height, "opacity": 1, "visible": True, "data": data},
            {"type": "objectgroup", "id": 2, "name": "objects", "x": 0, "y": 0, "opacity": 1,
             "visible": True, "draworder": "topdown", "objects": objs},
        ],
    }


def dump_tmj(tmj: dict[str, Any]) -> str:
    """JSON text of a map with one tile row per line (readable diffs)."""
    layers = []
    for layer in tmj["layers"]:
        if layer["type"] == "tilelayer":
            w = layer["width"]
            data = layer["data"]
            rows = [", ".join(str(g) for g in data[i:i + w]) for i in range(0, len(data), w)]
            body = {k: v for k, v in layer.items() if k != "data"}
            text = json.dumps(body)[:-1] + ', "data": [\n        ' + ",\n        ".join(rows) + "\n      ]}"
        else:
            objs = ",\n        ".join(json.dumps(o) for o in layer["objects"])
            body = {k: v for k, v in layer.items() if k != "objects"}
            text = json.dumps(body)[:-1] + ', "objects": [\n        ' + objs + "\n      ]}"
        layers.append(text)
    head = {k: v for k, v in tmj.items() if k != "layers"}
    joined = ",\n      ".join(layers)
    return json.dumps(head, indent=2)[:-2] + ',\n  "layers": [\n      ' + joined + "\n  ]\n}\n"
