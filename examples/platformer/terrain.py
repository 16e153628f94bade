"""Terrain drawn as lines (:class:`.levels.TerrainLine`): the convex pieces that draw it.

A chain's segments have no area, so the ground a line stands for is drawn with pieces of its own,
filled polygons the renderer draws as it draws any hitbox (drawn only: no layer, no mask, they
meet nothing):

- the ground: a polyline's as one quad per segment, from the segment down to the map's bottom
  (a polyline runs one way across the map, so the quads tile the ground below it exactly); a
  polygon's as the triangles of its outline (ear clipping);
- grass along every edge of the outline that faces up (its outward normal points up): a strip
  hanging :data:`GRASS_DEPTH` tiles below the edge (a light line on top, a dark one at the
  bottom), cut vertically at its ends so that the strips of two edges meet without a gap, in the
  colours of the ground tiles' grass (``art.py``).
"""

from __future__ import annotations

from .levels import TerrainLine

__all__ = ["DARK_DEPTH", "GRASS_DEPTH", "LIGHT_DEPTH", "fill_pieces", "grass_strips", "triangulate"]

Point = tuple[float, float]

GRASS_DEPTH = 6.0 / 32.0  # tiles: the grass of a ground tile is 5 to 7 of its 32 pixels deep
LIGHT_DEPTH = 1.0 / 32.0  # tiles: the light line along the grass's top
DARK_DEPTH = 1.0 / 32.0  # tiles: the dark line along its bottom


def fill_pieces(line: TerrainLine) -> list[list[Point]]:
    """The convex pieces (counter-clockwise outlines) filling the ground of ``line``."""
    if line.loop:
        return [list(t) for t in triangulate(line.outline())]
    out = []
    for (x0, y0), (x1, y1) in zip(line.points, line.points[1:]):
        if x1 <= x0:
            continue  # a vertical drop: its neighbours' quads meet there
        quad = [(x0, 0.0), (x1, 0.0), (x1, y1), (x0, y0)]
        out.append([p for i, p in enumerate(quad) if p != quad[i - 1]])  # (a corner on the bottom: a triangle)
    return [q for q in out if len(q) >= 3 and _cross(q[0], q[1], q[2]) > 0.0]


def grass_strips(line: TerrainLine, top: float, bottom: float) -> list[list[Point]]:
    """The strips from ``top`` to ``bottom`` (world units below the surface, ``top < bottom``)
    under every edge of the outline that faces up, counter-clockwise."""
    outline = line.outline()
    out = []
    for (x0, y0), (x1, y1) in zip(outline, outline[1:] + outline[:1]):
        if x1 < x0:  # counter-clockwise: an edge running right to left has the outside above it
            out.append([(x1, y1 - bottom), (x0, y0 - bottom), (x0, y0 - top), (x1, y1 - top)])
    return out


def _cross(a: Point, b: Point, c: Point) -> float:
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def _in_triangle(p: Point, a: Point, b: Point, c: Point) -> bool:
    """Whether ``p`` is in the closed counter-clockwise triangle ``a, b, c``."""
    return _cross(a, b, p) >= 0.0 and _cross(b, c, p) >= 0.0 and _cross(c, a, p) >= 0.0


def _crosses(outline: list[Point]) -> bool:
    """Whether two edges of the closed outline that are not neighbours meet (or two neighbours
    fold onto each other)."""
    n = len(outline)
    edges = [(outline[i], outline[(i + 1) % n]) for i in range(n)]
    for i in range(n):
        a, b = edges[i]
        for j in range(i + 1, n):
            c, d = edges[j]
            if j == i + 1 or (i == 0 and j == n - 1):  # neighbours: they share a corner, fold back only
                shared, far = (b, d) if j == i + 1 else (a, c)
                other = a if j == i + 1 else b
                if _cross(other, shared, far) == 0.0 and (far[0] - shared[0]) * (other[0] - shared[0]) + (
                        far[1] - shared[1]) * (other[1] - shared[1]) > 0.0:
                    return True
                continue
            d1, d2 = _cross(a, b, c), _cross(a, b, d)
            d3, d4 = _cross(c, d, a), _cross(c, d, b)
            if ((d1 > 0.0) != (d2 > 0.0) or d1 == 0.0 or d2 == 0.0) and (
                    (d3 > 0.0) != (d4 > 0.0) or d3 == 0.0 or d4 == 0.0) and _boxes_meet(a, b, c, d):
                return True
    return False


def _boxes_meet(a: Point, b: Point, c: Point, d: Point) -> bool:
    return (min(a[0], b[0]) <= max(c[0], d[0]) and min(c[0], d[0]) <= max(a[0], b[0])
            and min(a[1], b[1]) <= max(c[1], d[1]) and min(c[1], d[1]) <= max(a[1], b[1]))


def triangulate(outline: list[Point]) -> list[tuple[Point, Point, Point]]:
    """The triangles of a simple polygon (``outline`` counter-clockwise) by ear clipping: cut off a
    corner that turns left and holds no other vertex, again and again. A corner that does not turn
    (three points in a line) is dropped. ``ValueError`` if the outline crosses or touches itself.
    (Quadratic in the points, and worse for outlines of many reflex corners: the loader limits a
    polygon's points, ``LevelLimits.max_polygon_points``.)"""
    if _crosses(outline):
        raise ValueError("its outline crosses itself")
    idx = list(range(len(outline)))
    out = []
    while len(idx) > 3:
        n = len(idx)
        for k in range(n):
            a, b, c = outline[idx[k - 1]], outline[idx[k]], outline[idx[(k + 1) % n]]
            turn = _cross(a, b, c)
            if turn == 0.0:
                del idx[k]  # no area at this corner
                break
            if turn < 0.0:
                continue
            if any(_in_triangle(outline[j], a, b, c) and outline[j] not in (a, b, c) for j in idx):
                continue
            out.append((a, b, c))
            del idx[k]
            break
        else:
            raise ValueError("its outline crosses itself")
    if len(idx) == 3:
        a, b, c = (outline[i] for i in idx)
        if _cross(a, b, c) > 0.0:
            out.append((a, b, c))
    return out
