"""The debug overlay: what the collision pipeline saw this step, drawn over the scene.

- every hitbox's outline in view (with a Visual or not), coloured by body type
  (:data:`OVERLAY_COLORS`), a circle with a radius showing its rotation;
- this step's contacts (``scene.contacts``): a cross at each point and the normal (A toward B);
- the swept paths of continuous-detection bodies (``scene.swept_paths``);
- the spatial-hash cells in use (``scene.hash.cells_in_use()``);
- this step's rays (``scene.ray_log``): to the hit, the rest of the ray dimmer, the hit normal;
- a text line with FPS, entity count and milliseconds per pipeline stage (``scene.stage_ms``).

All lines go into one vertex buffer, rebuilt from numpy arrays each step and drawn with one
``GL_LINES`` call; marks whose size is in pixels (crosses, normals) keep it at any zoom. Lines
are drawn half a pixel in, so an edge on a whole pixel coordinate lights exactly one pixel row.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pyglet
from pyglet import gl
from pyglet.graphics import Batch, Group

from ..store import KIND_AABB, KIND_CIRCLE, KIND_POLYGON

__all__ = ["OVERLAY_COLORS", "DebugOverlay"]

#: RGBA colours of the overlay's marks.
OVERLAY_COLORS: dict[str, tuple[int, int, int, int]] = {
    "dynamic": (0, 255, 0, 255),
    "kinematic": (255, 160, 0, 255),
    "static": (160, 160, 160, 255),
    "sensor": (0, 220, 255, 255),
    "asleep": (60, 120, 255, 255),
    "contact": (255, 40, 40, 255),
    "normal": (255, 255, 0, 255),
    "swept": (255, 0, 255, 255),
    "cell": (50, 50, 100, 255),
    "ray": (255, 255, 255, 255),
    "ray_rest": (110, 110, 110, 255),
    "ray_normal": (255, 190, 120, 255),
    "text": (255, 255, 255, 255),
}

CIRCLE_SEGMENTS = 24
CROSS_PX = 4.0    # half size of a contact cross, in screen pixels
NORMAL_PX = 16.0  # length of a drawn normal, in screen pixels

_VERTEX = """#version 150 core
in vec2 position;
in vec4 colors;
out vec4 vertex_colors;
uniform vec2 shift;
uniform WindowBlock
{
    mat4 projection;
    mat4 view;
} window;
void main()
{
    gl_Position = window.projection * (window.view * vec4(position, 0.0, 1.0) + vec4(shift, 0.0, 0.0));
    vertex_colors = colors;
}
"""
_FRAGMENT = """#version 150 core
in vec4 vertex_colors;
out vec4 final_color;
void main()
{
    final_color = vertex_colors;
}
"""
_VERTEX_DTYPE = np.dtype([("p", "<f4", (2,)), ("c", "u1", (4,))])


def _segs(a: np.ndarray, color: tuple[int, ...] | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(m, 4)`` segments x0, y0, x1, y1 and their ``(m, 4)`` uint8 colours."""
    a = np.asarray(a, dtype=np.float64).reshape(-1, 4)
    c = np.asarray(color, dtype=np.uint8)
    if c.ndim == 1:
        c = np.broadcast_to(c, (a.shape[0], 4))
    return a, c


def _outline_segments(store: Any, geom: Any, rows: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """The outlines of the hitboxes of ``rows``, coloured by body type."""
    out: list[tuple[np.ndarray, np.ndarray]] = []
    if rows.size == 0:
        return out
    palette = np.array([OVERLAY_COLORS[k] for k in ("dynamic", "kinematic", "static", "sensor", "asleep")],
                       dtype=np.uint8)
    which = store.body[rows].astype(np.int64)  # 0 dynamic, 1 kinematic, 2 static
    which = np.where(store.sensor[rows], 3, which)
    which = np.where(store.asleep[rows], 4, which)
    colors = palette[which]
    kind = store.kind[rows]
    hx, hy = geom.hx[rows], geom.hy[rows]
    pa = np.flatnonzero((kind == KIND_AABB) | (kind == KIND_POLYGON))
    if pa.size:
        verts, _count = geom.outlines(store, rows[pa])  # padded by repeating the last vertex
        world = verts + np.stack([hx[pa], hy[pa]], axis=1)[:, None, :]
        nxt = np.roll(world, -1, axis=1)
        seg = np.concatenate([world, nxt], axis=2)  # (R, K, 4)
        col = np.broadcast_to(colors[pa][:, None, :], seg.shape[:2] + (4,))
        keep = (seg[..., 0] != seg[..., 2]) | (seg[..., 1] != seg[..., 3])  # padding repeats
        out.append((seg[keep], col[keep]))
    ci = np.flatnonzero(kind == KIND_CIRCLE)
    if ci.size:
        r = store.radius[rows[ci]][:, None]
        ang = np.linspace(0.0, 2.0 * math.pi, CIRCLE_SEGMENTS + 1)[None, :]
        px = hx[ci][:, None] + r * np.cos(ang)
        py = hy[ci][:, None] + r * np.sin(ang)
        seg = np.stack([px[:, :-1], py[:, :-1], px[:, 1:], py[:, 1:]], axis=2)
        col = np.broadcast_to(colors[ci][:, None, :], seg.shape[:2] + (4,))
        out.append((seg.reshape(-1, 4), col.reshape(-1, 4)))
        rot = store.rot[rows[ci]]
        rim = r[:, 0]
        spoke = np.stack([hx[ci], hy[ci], hx[ci] + rim * np.cos(rot), hy[ci] + rim * np.sin(rot)], axis=1)
        out.append((spoke, colors[ci]))
    return out


class DebugOverlay:
    """Builds the overlay's lines from a scene (:meth:`build`) and draws them (:meth:`draw_world`,
    :meth:`draw_hud`). Needs a current GL context."""

    def __init__(self) -> None:
        ctx = gl.current_context
        self._program = ctx.create_program((_VERTEX, "vertex"), (_FRAGMENT, "fragment"))
        self._vao = pyglet.graphics.vertexarray.VertexArray()
        self._vbo = pyglet.graphics.vertexbuffer.BufferObject(_VERTEX_DTYPE.itemsize * 64,
                                                              gl.GL_STREAM_DRAW)
        attrs = self._program.attributes
        with self._vao:
            self._vbo.bind()
            stride = _VERTEX_DTYPE.itemsize
            loc = attrs["position"]["location"]
            gl.glEnableVertexAttribArray(loc)
            gl.glVertexAttribPointer(loc, 2, gl.GL_FLOAT, gl.GL_FALSE, stride, 0)
            loc = attrs["colors"]["location"]
            gl.glEnableVertexAttribArray(loc)
            gl.glVertexAttribPointer(loc, 4, gl.GL_UNSIGNED_BYTE, gl.GL_TRUE, stride, 8)
        self.count = 0  # vertices in the buffer (two per line)
        self.text = ""
        self._hud_batch = Batch()
        self._hud_back = pyglet.shapes.Rectangle(0, 0, 1, 1, color=(0, 0, 0, 160), batch=self._hud_batch,
                                                 group=Group(order=0))
        self._labels = [
            pyglet.text.Label("", x=6, y=0, anchor_y="top", font_size=10, color=OVERLAY_COLORS["text"],
                              batch=self._hud_batch, group=Group(order=1))
            for _ in range(2)
        ]

    # --- building ---------------------------------------------------------------------------

    def build(self, scene: Any, renderer: Any, rows: np.ndarray) -> None:
        """Collect this step's overlay lines (in world coordinates) and the text line."""
        store, geom = scene.store, scene.geometry
        zoom = renderer.camera.zoom
        parts: list[tuple[np.ndarray, np.ndarray]] = []
        parts += self._cells(scene, renderer.camera.view_box())
        parts += _outline_segments(store, geom, rows[store.kind[rows] >= 0])
        if scene.swept_paths:
            paths = np.array([(a[0], a[1], b[0], b[1]) for a, b in scene.swept_paths], dtype=np.float64)
            parts.append(_segs(paths, OVERLAY_COLORS["swept"]))
        parts += self._rays(scene.ray_log, NORMAL_PX / zoom)
        parts += self._contacts(scene.contacts, CROSS_PX / zoom, NORMAL_PX / zoom)
        parts = [p for p in parts if p[0].shape[0]]
        if parts:
            seg = np.concatenate([p[0] for p in parts])
            col = np.concatenate([p[1] for p in parts])
            ok = np.isfinite(seg).all(axis=1)
            seg, col = seg[ok], col[ok]
        else:
            seg, col = np.zeros((0, 4)), np.zeros((0, 4), dtype=np.uint8)
        self._upload(seg, col)
        self.text = self._hud_lines(scene, renderer)

    @staticmethod
    def _cells(scene: Any, box: tuple[float, float, float, float]) -> list[tuple[np.ndarray, np.ndarray]]:
        hsh = scene.hash
        size = getattr(hsh, "cell_size", None)
        if not size or not hasattr(hsh, "cells_in_use"):
            return []
        cells = np.asarray(hsh.cells_in_use(), dtype=np.float64).reshape(-1, 2) * size
        if cells.shape[0] == 0:
            return []
        x0, y0 = cells[:, 0], cells[:, 1]
        x1, y1 = x0 + size, y0 + size
        on = (x0 < box[2]) & (x1 > box[0]) & (y0 < box[3]) & (y1 > box[1])
        x0, y0, x1, y1 = x0[on], y0[on], x1[on], y1[on]
        seg = np.stack([
            np.stack([x0, y0, x1, y0], axis=1), np.stack([x1, y0, x1, y1], axis=1),
            np.stack([x1, y1, x0, y1], axis=1), np.stack([x0, y1, x0, y0], axis=1),
        ], axis=1).reshape(-1, 4)
        return [_segs(seg, OVERLAY_COLORS["cell"])]

    @staticmethod
    def _rays(log: list, normal_len: float) -> list[tuple[np.ndarray, np.ndarray]]:
        if not log:
            return []
        hit_seg, rest_seg, normals = [], [], []
        for (ox, oy), (ex, ey), hit in log:
            if hit is None:
                rest_seg.append((ox, oy, ex, ey))
            else:
                hx, hy = hit.point
                hit_seg.append((ox, oy, hx, hy))
                rest_seg.append((hx, hy, ex, ey))
                normals.append((hx, hy, hx + hit.normal[0] * normal_len, hy + hit.normal[1] * normal_len))
        out = []
        for segs, key in ((rest_seg, "ray_rest"), (hit_seg, "ray"), (normals, "ray_normal")):
            if segs:
                out.append(_segs(np.array(segs, dtype=np.float64), OVERLAY_COLORS[key]))
        return out

    @staticmethod
    def _contacts(c: Any, cross: float, normal_len: float) -> list[tuple[np.ndarray, np.ndarray]]:
        if len(c.a) == 0:
            return []
        px, py = np.asarray(c.px, dtype=np.float64), np.asarray(c.py, dtype=np.float64)
        nx, ny = np.asarray(c.nx, dtype=np.float64), np.asarray(c.ny, dtype=np.float64)
        normals = np.stack([px, py, px + nx * normal_len, py + ny * normal_len], axis=1)
        crosses = np.concatenate([
            np.stack([px - cross, py - cross, px + cross, py + cross], axis=1),
            np.stack([px - cross, py + cross, px + cross, py - cross], axis=1),
        ])
        return [_segs(normals, OVERLAY_COLORS["normal"]), _segs(crosses, OVERLAY_COLORS["contact"])]

    @staticmethod
    def _hud_lines(scene: Any, renderer: Any) -> str:
        fps = f"{renderer.fps:.0f}" if renderer.fps > 0 else "-"
        stats = renderer.stats
        head = (f"FPS {fps}  entities {len(scene.store.row_of)}  drawn {stats.get('drawn', 0)}  "
                f"contacts {len(scene.contacts.a)}  frame {scene.frame}")
        ms = dict(scene.stage_ms)
        if ms and "render" not in ms and renderer.draw_ms > 0:  # this stage is running: the last one's time
            ms["render"] = renderer.draw_ms
        stages = "  ".join(f"{k} {v:.2f}" for k, v in ms.items())
        total = sum(ms.values())
        if not ms:
            return f"{head}\nms/step: (not stepped yet)"
        return f"{head}\nms/step: {stages}  total {total:.2f}"

    def _upload(self, seg: np.ndarray, col: np.ndarray) -> None:
        m = seg.shape[0]
        data = np.empty(2 * m, dtype=_VERTEX_DTYPE)
        data["p"] = seg.reshape(2 * m, 2)
        data["c"] = np.repeat(col, 2, axis=0)
        self.count = 2 * m
        if m:
            self._vbo.size = data.nbytes
            self._vbo.set_data(data.ctypes.data)

    # --- drawing ----------------------------------------------------------------------------

    def draw_world(self) -> None:
        """Draw the lines (the world view must be set)."""
        if not self.count:
            return
        self._program.use()
        self._program["shift"] = (0.5, 0.5)
        gl.glEnable(gl.GL_BLEND)
        gl.glBlendFunc(gl.GL_SRC_ALPHA, gl.GL_ONE_MINUS_SRC_ALPHA)
        with self._vao:
            gl.glDrawArrays(gl.GL_LINES, 0, self.count)
        gl.glDisable(gl.GL_BLEND)
        self._program.stop()

    def draw_hud(self, renderer: Any) -> None:
        """Draw the text line at the top left (the identity view must be set)."""
        lines = self.text.split("\n")
        top = renderer.height - 4
        width = 0.0
        for i, label in enumerate(self._labels):
            text = lines[i] if i < len(lines) else ""
            if label.text != text:
                label.text = text
            label.y = top - 16 * i
            width = max(width, label.content_width)
        self._hud_back.position = (0, top - 16 * len(self._labels) - 2)
        self._hud_back.width, self._hud_back.height = width + 12, 16 * len(self._labels) + 6
        self._hud_batch.draw()

    def delete(self) -> None:
        self._vbo.delete()
        self._vao.delete()
        for label in self._labels:
            label.delete()
        self._hud_back.delete()
