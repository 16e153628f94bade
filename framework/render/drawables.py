"""The drawables of the render system: one pyglet object per entity, kept and updated in place.

A filled hitbox is a :class:`ConvexFill`: its outline in local coordinates (relative to the hitbox
origin), triangulated once, then moved by writing only its translation and rotation attributes.
It uses pyglet's default shape shader, so it batches with pyglet's own shapes. Images are pyglet
sprites. Both live in the renderer's batch, under a :class:`pyglet.graphics.Group` per ``z``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import pyglet
from pyglet.graphics import Batch, Group
from pyglet.shapes import ShapeBase

from ..shapes import AABB, Capsule, Circle, Polygon

__all__ = ["ConvexFill", "Drawable", "circle_segments", "fill_triangles", "load_image"]


class ConvexFill(ShapeBase):
    """A filled convex outline: ``triangles`` (flat x, y, ... in local coordinates, three points a
    triangle) placed at ``(x, y)`` and turned by ``rotation`` (pyglet's: degrees, clockwise)."""

    def __init__(
        self, triangles: Sequence[float], x: float, y: float, rotation: float,
        color: tuple[int, int, int, int], batch: Batch | None = None, group: Group | None = None,
    ) -> None:
        self._tri = tuple(float(v) for v in triangles)
        self._x, self._y = float(x), float(y)
        self._rotation = float(rotation)
        self._rgba = tuple(color)
        super().__init__(len(self._tri) // 2, batch=batch, group=group)

    def _create_vertex_list(self) -> None:
        n = self._num_verts
        self._vertex_list = self._program.vertex_list(
            n, self._draw_mode, self._batch, self._group,
            position=("f", self._get_vertices()),
            colors=("Bn", self._rgba * n),
            translation=("f", (self._x, self._y) * n),
            rotation=("f", (self._rotation,) * n),
        )

    def _get_vertices(self) -> Sequence[float]:
        return self._tri if self._visible else (0.0,) * len(self._tri)

    def _update_vertices(self) -> None:
        self._vertex_list.position[:] = self._get_vertices()

    def place(self, x: float, y: float, rotation: float) -> None:
        """Move to ``(x, y)`` and turn to ``rotation`` (degrees, clockwise) in one write each."""
        n = self._num_verts
        if x != self._x or y != self._y:
            self._x, self._y = x, y
            self._vertex_list.translation[:] = (x, y) * n
        if rotation != self._rotation:
            self._rotation = rotation
            self._vertex_list.rotation[:] = (rotation,) * n


def circle_segments(radius_px: float) -> int:
    """Segments of a circle of ``radius_px`` screen pixels: smooth enough, never wasteful."""
    return int(min(128, max(16, math.ceil(radius_px * 0.75))))


def _fan(points: Sequence[tuple[float, float]]) -> list[float]:
    out: list[float] = []
    x0, y0 = points[0]
    for i in range(1, len(points) - 1):
        (x1, y1), (x2, y2) = points[i], points[i + 1]
        out += (x0, y0, x1, y1, x2, y2)
    return out


def capsule_outline(shape: Capsule, zoom: float = 1.0) -> list[tuple[float, float]]:
    """A capsule's outline (upright, local coordinates, counter-clockwise) as a convex polygon: each
    round end a half circle of as many chords as half a circle of its radius on screen."""
    r, h = shape.radius, shape.half_length
    n = max(8, circle_segments(r * zoom) // 2)
    top = [(r * math.cos(math.pi * i / n), h + r * math.sin(math.pi * i / n)) for i in range(n + 1)]
    return top + [(-x, -y) for x, y in top]


def fill_triangles(shape: Any, zoom: float = 1.0) -> list[float]:
    """The triangles (flat, local coordinates) filling a hitbox shape."""
    if isinstance(shape, AABB):
        hw, hh = shape.width * 0.5, shape.height * 0.5
        return _fan([(-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh)])
    if isinstance(shape, Circle):
        r = shape.radius
        n = circle_segments(r * zoom)
        pts = [(r * math.cos(2.0 * math.pi * i / n), r * math.sin(2.0 * math.pi * i / n)) for i in range(n)]
        return _fan(pts)
    if isinstance(shape, Capsule):
        return _fan(capsule_outline(shape, zoom))
    if isinstance(shape, Polygon):
        return _fan(shape.points)
    raise TypeError(f"cannot fill a {type(shape).__name__}")


class Drawable:
    """What the renderer keeps for one entity: its pyglet object and what it was made from."""

    __slots__ = ("obj", "kind", "shape", "image", "z", "color", "shown", "last_seen", "rotates")

    def __init__(self, obj: Any, kind: str, shape: Any, image: str | None, z: int,
                 color: tuple[int, int, int, int], rotates: bool) -> None:
        self.obj = obj
        self.kind = kind  # "fill" or "sprite"
        self.shape = shape
        self.image = image
        self.z = z
        self.color = color
        self.shown = True
        self.last_seen = 0
        # (a capsule's fill turns with its transform, as a polygon's)
        self.rotates = rotates or (kind == "fill" and isinstance(shape, Capsule))

    def place(self, hx: float, hy: float, x: float, y: float, rot: float) -> None:
        """Put the drawable where the entity is: a fill at its hitbox origin, a sprite at its
        Transform; ``rot`` in radians counter-clockwise (pyglet turns clockwise in degrees)."""
        deg = -math.degrees(rot) if self.rotates else 0.0
        if self.kind == "fill":
            self.obj.place(hx, hy, deg)
        else:
            self.obj.update(x=x, y=y, rotation=deg)

    def set_color(self, color: tuple[int, int, int, int]) -> None:
        self.obj.color = color
        self.color = color

    def set_group(self, z: int, group: Group) -> None:
        self.obj.group = group
        self.z = z

    def show(self) -> None:
        self.obj.visible = True
        self.shown = True

    def hide(self) -> None:
        self.obj.visible = False
        self.shown = False

    def delete(self) -> None:
        self.obj.delete()


def load_image(path: str) -> Any:
    """A texture of the image file, anchored at its centre, sampled nearest (crisp pixels)."""
    from pyglet import gl

    tex = pyglet.image.load(path).get_texture()
    tex.anchor_x, tex.anchor_y = tex.width / 2.0, tex.height / 2.0
    gl.glBindTexture(tex.target, tex.id)
    gl.glTexParameteri(tex.target, gl.GL_TEXTURE_MIN_FILTER, gl.GL_NEAREST)
    gl.glTexParameteri(tex.target, gl.GL_TEXTURE_MAG_FILTER, gl.GL_NEAREST)
    gl.glBindTexture(tex.target, 0)
    return tex
