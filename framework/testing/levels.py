"""Scenes from inline text: a tile map written in a test, one character per cell.

::

    level = text_scene('''
        #..........#
        #.P...C...G#
        ############
    ''', legend={"P": spawn_player, "C": spawn_coin, "G": spawn_goal}, tile=32.0)

Rows are top to bottom, as drawn (y is up in the world: the last row is at y 0 .. tile); leading
indentation common to every row is ignored and short rows are padded with empty cells. Built-in
characters: ``#`` solid, ``-`` one-way platform (a slab on the top quarter of the cell), ``/`` and
``\\`` 45-degree slopes, ``r R`` and ``F f`` the 2:1 slopes, ``_`` a quarter-tile step, ``.`` and a
space empty. Terrain becomes static hitboxes through :func:`framework.tiles.terrain_pieces` (slopes
merged with the ground beside them). A ``legend`` maps other characters (or overrides these) to a
terrain kind or to a function ``spawn(scene, x, y, tile) -> entity or None`` called with the cell's
centre. A character neither built in nor in the legend is an error naming it, its line and column.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from ..components import Hitbox, Transform
from ..shapes import AABB
from ..tiles import HEIGHTS, terrain_pieces
from ..validation import InvalidValue, positive

__all__ = ["BUILTIN", "ONE_WAY", "TextLevel", "text_scene"]

ONE_WAY = "oneway"
BUILTIN: dict[str, str | None] = {
    "#": "solid", "-": ONE_WAY, "/": "slope_up", "\\": "slope_down", "r": "slope_up_low",
    "R": "slope_up_high", "F": "slope_down_high", "f": "slope_down_low", "_": "step", ".": None, " ": None,
}

Spawn = Callable[[Any, float, float, float], Any]


@dataclass
class TextLevel:
    """What :func:`text_scene` built: the ``scene``, its grid (``width`` x ``height`` cells of
    ``tile``), the ``terrain`` entities, and per legend character the entities its function
    spawned, in reading order (``entities["C"]``)."""

    scene: Any
    tile: float
    width: int
    height: int
    terrain: list[int] = field(default_factory=list)
    entities: dict[str, list[int]] = field(default_factory=dict)
    cells: dict[str, list[tuple[int, int]]] = field(default_factory=dict)

    def cell_center(self, col: int, row: int) -> tuple[float, float]:
        """The world centre of cell ``(col, row)`` (row 0 at the top)."""
        return (col + 0.5) * self.tile, (self.height - row - 0.5) * self.tile

    def where(self, char: str) -> list[tuple[float, float]]:
        """The centres of the cells holding ``char``, in reading order."""
        return [self.cell_center(c, r) for c, r in self.cells.get(char, [])]

    def first(self, char: str) -> int:
        """The first entity spawned for ``char``."""
        found = self.entities.get(char) or []
        if not found:
            raise InvalidValue(f"the level has no entity spawned for {char!r}")
        return found[0]


def _rows(text: str) -> list[str]:
    lines = [ln.rstrip() for ln in text.splitlines()]
    while lines and not lines[0].strip():
        lines.pop(0)
    while lines and not lines[-1].strip():
        lines.pop()
    if not lines:
        raise InvalidValue("the text level is empty")
    indent = min(len(ln) - len(ln.lstrip(" ")) for ln in lines if ln.strip())
    lines = [ln[indent:] for ln in lines]
    width = max(len(ln) for ln in lines)
    return [ln.ljust(width) for ln in lines]


def text_scene(text: str, legend: Mapping[str, str | Spawn | None] | None = None, *, tile: float = 1.0,
               scene: Any = None, terrain_layer: int = 1, gravity: tuple[float, float] | None = None) -> TextLevel:
    """Build a scene (or fill ``scene``) from a text map; see the module docstring.

    ``terrain_layer``: the collision layer of the terrain's hitboxes. ``gravity``: the new scene's
    gravity (default ``(0, -20 * tile)``: about a game's, in tiles)."""
    t = positive("text level tile", tile)
    table: dict[str, str | Spawn | None] = {**BUILTIN, **(legend or {})}
    for ch, meaning in table.items():
        if not (meaning is None or callable(meaning) or meaning in HEIGHTS or meaning == ONE_WAY):
            raise InvalidValue(f"legend {ch!r}: {meaning!r} is neither a terrain kind "
                               f"({', '.join([*HEIGHTS, ONE_WAY])}) nor a function spawn(scene, x, y, tile)")
    rows = _rows(text)
    for r, line in enumerate(rows):
        for c, ch in enumerate(line):
            if ch not in table:
                known = "".join(sorted(k for k in table if k != " "))
                raise InvalidValue(f"unknown character {ch!r} at line {r + 1}, column {c + 1} of the text level "
                                   f"(known: {known!r}; add it to the legend)")
    if scene is None:
        from ..scene import Scene

        scene = Scene(gravity=gravity if gravity is not None else (0.0, -20.0 * t))
    level = TextLevel(scene, t, len(rows[0]), len(rows))
    kinds = [[table[ch] if isinstance(table[ch], str) else None for ch in line] for line in rows]
    for pc in terrain_pieces(kinds, t):
        level.terrain.append(scene.spawn(Transform(pc.x, pc.y), Hitbox(pc.shape, body="static", layer=terrain_layer)))
    for r, line in enumerate(rows):
        for c, ch in enumerate(line):
            meaning = table[ch]
            if meaning is None:
                continue
            level.cells.setdefault(ch, []).append((c, r))
            x, y = level.cell_center(c, r)
            if meaning == ONE_WAY:
                level.terrain.append(scene.spawn(Transform(x, y + 0.375 * t), Hitbox(
                    AABB(t, 0.25 * t), body="static", layer=terrain_layer, one_way=True)))
            elif callable(meaning):
                entity = meaning(scene, x, y, t)
                if entity is not None:
                    level.entities.setdefault(ch, []).append(entity)
    return level
