"""Terrain tiles to static collision pieces: solid cells and slopes, without ghost bumps at seams.

A tile game draws its ground cell by cell, but a body sliding over one static piece per cell can
catch the corner where two pieces meet (a "ghost bump"), most visibly where a slope's high side
meets the flat ground beside it. :func:`terrain_pieces` merges, within each row, the cells of a
slope run into the largest convex pieces it can, so the surface a body slides over has no seam
there. Plain solid cells that merge with no slope stay one ``AABB`` per cell, centred on the cell.

Cell kinds (strings; ``None`` or any other value is not terrain and is ignored, so one grid can
also hold a game's one-way platforms, spikes, ladders...):

| kind | surface, from the cell's left edge to its right edge (in tiles above its bottom) |
|---|---|
| ``"solid"`` | 1 to 1: the full cell |
| ``"slope_up"`` | 0 to 1: 45 degrees, rising left to right |
| ``"slope_down"`` | 1 to 0: 45 degrees, falling left to right |
| ``"slope_up_low"``, ``"slope_up_high"`` | 0 to 1/2, then 1/2 to 1: a gentle slope two cells long |
| ``"slope_down_high"``, ``"slope_down_low"`` | 1 to 1/2, then 1/2 to 0 |
| ``"step"`` | 1/4 to 1/4: a quarter-tile step (what a character's ``step_height`` walks up) |

The gentle slope rises one tile over two. Game makers often call it the "22.5 degree" slope; it is
atan(1/2) = 26.57 degrees.

Geometry: y is up; ``cells[row][col]`` has row 0 at the top, as drawn, so with ``H`` rows and
``origin = (ox, oy)`` the cell ``(col, row)`` spans x in ``[ox + col * tile, ox + (col + 1) * tile]``
and y in ``[oy + (H - row - 1) * tile, oy + (H - row) * tile]``. Pieces never span rows. With a
dyadic tile size (32, 1, 0.5...) and origin every vertex and position is exact.

Terrain drawn as lines in Tiled (polyline and polygon objects) becomes chains: :func:`tiled_chains`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from .shapes import AABB, Chain, Polygon
from .validation import InvalidValue, finite, positive, vector2

__all__ = [
    "HEIGHTS", "MIRRORED", "SLOPES", "SLOPE_DOWN", "SLOPE_DOWN_HIGH", "SLOPE_DOWN_LOW", "SLOPE_UP",
    "SLOPE_UP_HIGH", "SLOPE_UP_LOW", "SOLID", "STEP", "TERRAIN", "TerrainPiece", "terrain_pieces", "tiled_chains",
]

SOLID = "solid"
SLOPE_UP = "slope_up"
SLOPE_DOWN = "slope_down"
SLOPE_UP_LOW = "slope_up_low"
SLOPE_UP_HIGH = "slope_up_high"
SLOPE_DOWN_HIGH = "slope_down_high"
SLOPE_DOWN_LOW = "slope_down_low"
STEP = "step"

#: The slope kinds, in this order.
SLOPES = (SLOPE_UP, SLOPE_DOWN, SLOPE_UP_LOW, SLOPE_UP_HIGH, SLOPE_DOWN_HIGH, SLOPE_DOWN_LOW)
#: Every terrain kind: ``"solid"``, the slopes and the quarter-tile step.
TERRAIN = (SOLID, *SLOPES, STEP)

#: Each terrain kind's surface height at the cell's left and right edges, in tiles above its bottom.
HEIGHTS: dict[str, tuple[float, float]] = {
    SOLID: (1.0, 1.0),
    SLOPE_UP: (0.0, 1.0),
    SLOPE_DOWN: (1.0, 0.0),
    SLOPE_UP_LOW: (0.0, 0.5),
    SLOPE_UP_HIGH: (0.5, 1.0),
    SLOPE_DOWN_HIGH: (1.0, 0.5),
    SLOPE_DOWN_LOW: (0.5, 0.0),
    STEP: (0.25, 0.25),
}

#: Each terrain kind seen in a mirror (flipped left to right): a rising slope becomes a falling one.
MIRRORED: dict[str, str] = {
    SOLID: SOLID,
    SLOPE_UP: SLOPE_DOWN, SLOPE_DOWN: SLOPE_UP,
    SLOPE_UP_LOW: SLOPE_DOWN_LOW, SLOPE_DOWN_LOW: SLOPE_UP_LOW,
    SLOPE_UP_HIGH: SLOPE_DOWN_HIGH, SLOPE_DOWN_HIGH: SLOPE_UP_HIGH,
    STEP: STEP,
}


@dataclass(frozen=True)
class TerrainPiece:
    """One static collision piece of terrain.

    ``shape`` is an ``AABB(tile, tile)`` for a lone solid cell, else a convex ``Polygon`` in local
    coordinates; ``x, y`` is the world position of its hitbox origin (the centre of the piece's
    bounding box), ready for a ``Transform``. ``cells`` lists the ``(col, row)`` it covers, left
    to right (all in one row); ``top`` is the world y of its surface at its left and right ends.
    """

    shape: AABB | Polygon
    x: float
    y: float
    cells: tuple[tuple[int, int], ...]
    top: tuple[float, float]


def terrain_pieces(
    cells: Sequence[Sequence[object]], tile: float, *, origin: Sequence[float] = (0.0, 0.0),
) -> list[TerrainPiece]:
    """The static collision pieces of a grid of terrain cells, row by row from the top, left to right.

    Within a row, consecutive terrain cells are taken greedily left to right into the longest piece
    whose union is convex: each next cell's surface must start where the previous one's ends and
    must not be steeper upwards (its slope never increases, as over a hill: rise, flat, fall). A
    piece with a slope becomes one ``Polygon`` (its bottom edge along the row's bottom, its top the
    surface), so a slope and the flat ground beside its high side form one surface. A piece with
    no slope (a run of solid cells, e.g. at the foot of a slope) becomes one ``AABB`` per cell,
    exactly as a grid without slopes gives. Rows may differ in length (short ones end in empty
    cells). Raises ``InvalidValue`` (a ``ValueError``) for a tile size that is not finite and > 0, an
    origin that is not two finite numbers, or cells that are not a sequence of rows.
    """
    t = positive("terrain tile size", tile)
    if t * 0.25 == 0.0:
        raise InvalidValue(f"terrain tile size must be finite and > 0 with a quarter > 0, got {tile!r}")
    ox, oy = vector2("terrain origin", origin)
    if isinstance(cells, (str, bytes)):
        raise InvalidValue(f"terrain cells must be a sequence of rows of kinds, got {cells!r:.80}")
    try:
        rows = [[] if r is None else list(r) for r in cells]
    except TypeError:
        raise InvalidValue(f"terrain cells must be a sequence of rows of kinds, got {cells!r:.80}") from None
    height = len(rows)
    width = max((len(r) for r in rows), default=0)
    for edge_x, edge_y in ((ox + width * t, oy + height * t), (ox, oy)):
        if not (math.isfinite(edge_x) and math.isfinite(edge_y)):
            raise InvalidValue(
                f"terrain of {width} x {height} tiles of {tile!r} at {origin!r} does not fit in float64")
    out: list[TerrainPiece] = []
    for row, line in enumerate(rows):
        kinds = [k if isinstance(k, str) and k in HEIGHTS else None for k in line]
        bottom = oy + (height - row - 1) * t
        col = 0
        while col < len(kinds):
            if kinds[col] is None:
                col += 1
                continue
            end = col + 1
            while end < len(kinds) and _joins(kinds[end - 1], kinds[end]):
                end += 1
            run = kinds[col:end]
            if all(k == SOLID for k in run):
                for c in range(col, end):
                    top = bottom + t
                    out.append(TerrainPiece(AABB(t, t), ox + (c + 0.5) * t, oy + (height - row - 0.5) * t,
                                            ((c, row),), (top, top)))
            else:
                out.append(_polygon_piece(run, col, row, t, ox, bottom))
            col = end
    return out


def _joins(left: str | None, right: str | None) -> bool:
    """Whether cell ``right`` continues a convex piece that ends with cell ``left``."""
    if left is None or right is None:
        return False
    (a0, a1), (b0, b1) = HEIGHTS[left], HEIGHTS[right]
    return a1 == b0 and (b1 - b0) <= (a1 - a0)


def _polygon_piece(run: list[str | None], col: int, row: int, t: float, ox: float,
                   bottom: float) -> TerrainPiece:
    """One convex piece over the cells ``col .. col + len(run) - 1`` of ``row``.

    Local points are computed in tiles (multiples of 1/4, exact) relative to the bounding box's
    centre, then scaled by the tile size: one rounding at most, none for a dyadic tile.
    """
    n = len(run)
    heights = [HEIGHTS[k][0] for k in run] + [HEIGHTS[run[-1]][1]]  # type: ignore[index]
    peak = max(heights)
    half_w, half_h = n * 0.5, peak * 0.5
    outline = [(-half_w, -half_h), (half_w, -half_h)]
    outline += [(i - half_w, h - half_h) for i, h in reversed(list(enumerate(heights))) if h > 0.0]
    shape = Polygon([(x * t, y * t) for x, y in outline])
    return TerrainPiece(shape, ox + (col + half_w) * t, bottom + half_h * t,
                        tuple((c, row) for c in range(col, col + n)),
                        (bottom + heights[0] * t, bottom + heights[-1] * t))


# --- Tiled objects drawn as lines: chains -----------------------------------------------------------

def tiled_chains(objects: object, map_height: float, scale: float = 1.0) -> list[Chain]:
    """The polyline and polygon objects of a Tiled object layer as :class:`~framework.shapes.Chain`
    terrain (other objects are left to the caller): ``objects`` is the layer's ``"objects"`` list
    (or the layer itself, a dict with one) as Tiled's JSON gives it; ``map_height`` the map's height
    in Tiled's pixels (``height * tileheight``): Tiled's y runs down from the map's top, the
    chains' up from its bottom; every coordinate is then multiplied by ``scale`` (``1 / tile`` for
    a world in tiles).

    - A **polygon** is a closed loop of solid terrain: bodies meet it from outside, however it was
      drawn (its points are put in counter-clockwise order, y up).
    - A **polyline** is met from the side on the left of the way it was drawn, as it looks in
      Tiled: ground drawn left to right is met from above, a ceiling is drawn right to left.

    An object's ``x, y`` and ``rotation`` (degrees, clockwise as Tiled shows it, about ``x, y``)
    place its points. Bad values (a missing or non-finite coordinate, fewer points than a chain
    needs, two equal points in a row) raise :class:`ValueError` naming the object."""
    scale = positive("tiled_chains scale", scale)
    map_h = finite("tiled_chains map_height", map_height)
    if isinstance(objects, dict):
        objects = objects.get("objects", [])
    if not isinstance(objects, list):
        raise InvalidValue(f"tiled_chains needs a Tiled object layer or its 'objects' list, got {objects!r}")
    chains = []
    for i, obj in enumerate(objects):
        if not isinstance(obj, dict):
            raise InvalidValue(f"Tiled object {i} must be a JSON object, got {obj!r}")
        loop = "polygon" in obj
        raw = obj.get("polygon" if loop else "polyline")
        if raw is None:
            continue
        label = f"Tiled {'polygon' if loop else 'polyline'} object {obj.get('id', i)!r}"
        x, y = finite(f"{label} x", obj.get("x", 0.0)), finite(f"{label} y", obj.get("y", 0.0))
        angle = math.radians(finite(f"{label} rotation", obj.get("rotation", 0.0)))
        c, s = (1.0, 0.0) if angle == 0.0 else (math.cos(angle), math.sin(angle))
        if not isinstance(raw, list):
            raise InvalidValue(f"{label}: its points must be a list, got {raw!r}")
        pts = []
        for j, p in enumerate(raw):
            if not isinstance(p, dict):
                raise InvalidValue(f"{label}: point {j} must be an object with x and y, got {p!r}")
            px, py = finite(f"{label} point {j} x", p.get("x")), finite(f"{label} point {j} y", p.get("y"))
            # Tiled's frame (y down), turned about the object's position, then y up from the bottom.
            tx, ty = x + c * px - s * py, y + s * px + c * py
            pts.append((tx * scale, (map_h - ty) * scale))
        if loop:
            area2 = sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1]))
            if area2 < 0.0:
                pts.reverse()  # counter-clockwise: solid inside, met from outside
        else:
            pts.reverse()  # met on the left of the way it was drawn (a chain is met on its right)
        try:
            chains.append(Chain(pts, loop=loop))
        except InvalidValue as exc:
            raise InvalidValue(f"{label}: {exc}") from None
    return chains
