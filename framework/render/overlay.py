"""The debug overlay: what the collision pipeline saw this step, drawn over the scene.

- every hitbox's outline in view (with a Visual or not), coloured by body type
  (:data:`OVERLAY_COLORS`), a circle with a radius showing its rotation;
- this step's contacts (``scene.step_frame.contacts``): a cross at each point and the normal (A
  toward B);
- where boxes and polygons turn, the points the solver pushed at (``scene.step_frame.points``: two
  where a face rests on a face), a diamond at each;
- the friction in use at them (``scene.step_frame.support``): a line along the contact, the way
  friction pushes B, as long as a normal where friction is at its limit (the bodies slide) and
  shorter in proportion where it holds them (static friction);
- each moving body's velocity: a line from its position to where it would be
  :data:`VELOCITY_SECONDS` later;
- the swept paths of continuous-detection bodies (``scene.step_frame.swept_paths``);
- the spatial hash's cells in use, by the static bodies and the last step's moving ones
  (``scene.bodies.hash.cells_in_use()``);
- this step's rays (``scene.step_frame.ray_log``): to the hit, the rest of the ray dimmer, the hit
  normal;
- text lines with FPS, entity count and milliseconds per pipeline stage
  (``scene.step_frame.stage_ms``), wrapped between figures to the view's width, so every figure is
  seen in a narrow window (an 800 x 600 one shows every stage of a scene with all of them), onto at
  most a quarter of the view's height (two lines at least: a tiny view shows the start of each).

All lines go into one vertex buffer, rebuilt from numpy arrays each step and drawn with one
``GL_LINES`` call; marks whose size is in pixels (crosses, normals) keep it at any zoom. Lines
are drawn half a pixel in, so an edge on a whole pixel coordinate lights exactly one pixel row.
"""

from __future__ import annotations

import ctypes
import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pyglet
from pyglet import gl
from pyglet.graphics import Batch, Group

from ..components import Body
from ..events import pair_keys, sorted_find
from ..shapes import AABB
from ..store import KIND_AABB, KIND_CAPSULE, KIND_CIRCLE, KIND_POLYGON, KIND_SEGMENT

__all__ = ["HUD_FONT_SIZE", "HUD_LINE_PX", "OVERLAY_COLORS", "DebugOverlay", "wrap_figures"]

#: RGBA colours of the overlay's marks.
OVERLAY_COLORS: dict[str, tuple[int, int, int, int]] = {
    "dynamic": (0, 255, 0, 255),
    "kinematic": (255, 160, 0, 255),
    "static": (160, 160, 160, 255),
    "sensor": (0, 220, 255, 255),
    "asleep": (60, 120, 255, 255),
    "contact": (255, 40, 40, 255),
    "normal": (255, 255, 0, 255),
    "friction": (255, 110, 200, 255),
    "point": (255, 140, 0, 255),
    "swept": (255, 0, 255, 255),
    "velocity": (150, 110, 255, 255),
    "cell": (50, 50, 100, 255),
    "ray": (255, 255, 255, 255),
    "ray_rest": (110, 110, 110, 255),
    "ray_normal": (255, 190, 120, 255),
    "text": (255, 255, 255, 255),
}

CIRCLE_SEGMENTS = 24
CROSS_PX = 4.0    # half size of a contact cross, in screen pixels
NORMAL_PX = 16.0  # length of a drawn normal, in screen pixels
VELOCITY_SECONDS = 0.25  # a velocity is drawn as the way its body would go in this time
HUD_FONT_SIZE = 10  # the text's size in points
HUD_LINE_PX = 16  # from one text line to the next, in pixels
HUD_MARGIN_PX = 6  # the text's distance from the view's left and right edges
HUD_MAX_SHARE = 0.25  # the text wraps onto at most this share of the view's height (two lines at least)

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


Segments = tuple[np.ndarray, np.ndarray]  # (m, 4) float x0, y0, x1, y1 and their (m, 4) uint8 colours


def _segments(ends: Any, color: tuple[int, ...] | np.ndarray) -> Segments:
    """``(m, 4)`` segments x0, y0, x1, y1 and their ``(m, 4)`` uint8 colours (one colour for all,
    or one per segment)."""
    ends = np.asarray(ends, dtype=np.float64).reshape(-1, 4)
    colors = np.asarray(color, dtype=np.uint8)
    if colors.ndim == 1:
        colors = np.broadcast_to(colors, (ends.shape[0], 4))
    return ends, colors


def _body_colors(store: Any, rows: np.ndarray) -> np.ndarray:
    """``(len(rows), 4)`` uint8: each row's overlay colour (asleep, else sensor, else its body type)."""
    palette = np.array([OVERLAY_COLORS[k] for k in ("dynamic", "kinematic", "static", "sensor", "asleep")],
                       dtype=np.uint8)
    which = store.body[rows].astype(np.int64)  # 0 dynamic, 1 kinematic, 2 static
    which = np.where(store.sensor[rows], 3, which)
    which = np.where(store.asleep[rows], 4, which)
    return palette[which]


def _outline_segments(store: Any, geometry: Any, rows: np.ndarray) -> list[Segments]:
    """The outlines of the hitboxes of ``rows`` (rows with a hitbox), coloured by body type: boxes
    and polygons edge by edge (a segment: its line), circles as :data:`CIRCLE_SEGMENTS` chords and a radius showing
    their rotation, capsules as two half circles of as many chords joined by their sides."""
    out: list[Segments] = []
    if rows.size == 0:
        return out
    colors = _body_colors(store, rows)
    kind = store.kind[rows]
    hx, hy = geometry.hx[rows], geometry.hy[rows]
    polygons = np.flatnonzero((kind == KIND_AABB) | (kind == KIND_POLYGON) | (kind == KIND_SEGMENT))
    if polygons.size:
        local, _count = geometry.outlines(store, rows[polygons])  # padded by repeating the last vertex
        corners = local + np.stack([hx[polygons], hy[polygons]], axis=1)[:, None, :]
        edges = np.concatenate([corners, np.roll(corners, -1, axis=1)], axis=2)  # (R, K, 4)
        edge_colors = np.broadcast_to(colors[polygons][:, None, :], edges.shape[:2] + (4,))
        real = (edges[..., 0] != edges[..., 2]) | (edges[..., 1] != edges[..., 3])  # not padding
        out.append((edges[real], edge_colors[real]))
    circles = np.flatnonzero(kind == KIND_CIRCLE)
    if circles.size:
        cx, cy = hx[circles], hy[circles]
        radius = store.radius[rows[circles]]
        angles = np.linspace(0.0, 2.0 * math.pi, CIRCLE_SEGMENTS + 1)[None, :]
        rim_x = cx[:, None] + radius[:, None] * np.cos(angles)
        rim_y = cy[:, None] + radius[:, None] * np.sin(angles)
        chords = np.stack([rim_x[:, :-1], rim_y[:, :-1], rim_x[:, 1:], rim_y[:, 1:]], axis=2)
        chord_colors = np.broadcast_to(colors[circles][:, None, :], chords.shape[:2] + (4,))
        out.append((chords.reshape(-1, 4), chord_colors.reshape(-1, 4)))
        rot = store.rot[rows[circles]]
        spokes = np.stack([cx, cy, cx + radius * np.cos(rot), cy + radius * np.sin(rot)], axis=1)
        out.append((spokes, colors[circles]))
    capsules = np.flatnonzero(kind == KIND_CAPSULE)
    if capsules.size:
        # Half a circle about each end of the segment (the far side first), joined by the sides.
        cx, cy = hx[capsules], hy[capsules]
        r = store.radius[rows[capsules]][:, None]
        ux, uy = geometry.cap_ux[rows[capsules]], geometry.cap_uy[rows[capsules]]
        theta = np.arctan2(uy, ux)[:, None]
        half = np.linspace(-0.5 * math.pi, 0.5 * math.pi, CIRCLE_SEGMENTS // 2 + 1)[None, :]
        ends = []
        for sign in (1.0, -1.0):
            ang = theta + half + (0.0 if sign > 0 else math.pi)
            ends.append((cx[:, None] + sign * ux[:, None] + r * np.cos(ang),
                         cy[:, None] + sign * uy[:, None] + r * np.sin(ang)))
        loop_x = np.concatenate([ends[0][0], ends[1][0], ends[0][0][:, :1]], axis=1)
        loop_y = np.concatenate([ends[0][1], ends[1][1], ends[0][1][:, :1]], axis=1)
        segs = np.stack([loop_x[:, :-1], loop_y[:, :-1], loop_x[:, 1:], loop_y[:, 1:]], axis=2)
        seg_colors = np.broadcast_to(colors[capsules][:, None, :], segs.shape[:2] + (4,))
        out.append((segs.reshape(-1, 4), seg_colors.reshape(-1, 4)))
    return out


def _part_segments(store: Any) -> list[Segments]:
    """The outlines of the other shapes of compound bodies (:class:`~framework.components.Parts`),
    each posed by its entity's transform (its offset turning with it; an AABB's box never turns) and
    coloured as its body (a sensor part as a sensor). Every compound body's, seen or not: they are
    few, and a part may reach into view from a body that is not."""
    if not store.parts:
        return []
    from .drawables import fill_outline

    names = {Body.DYNAMIC: "dynamic", Body.KINEMATIC: "kinematic", Body.STATIC: "static"}
    ends: list[tuple[float, float, float, float]] = []
    colors: list[tuple[int, ...]] = []
    for e, parts in sorted(store.parts.items()):
        row = store.row_of[e]
        x, y, rot = float(store.x[row]), float(store.y[row]), float(store.rot[row])
        c, s = math.cos(rot), math.sin(rot)
        for hb in parts.hitboxes:
            ox, oy = hb.offset
            hx, hy = x + c * ox - s * oy, y + s * ox + c * oy
            turn = (1.0, 0.0) if isinstance(hb.shape, AABB) else (c, s)
            pts = [(hx + turn[0] * px - turn[1] * py, hy + turn[1] * px + turn[0] * py)
                   for px, py in fill_outline(hb.shape)]
            color = OVERLAY_COLORS["asleep" if store.asleep[row] else "sensor" if hb.sensor else names[hb.body]]
            closed = len(pts) > 2
            for i in range(len(pts) if closed else 1):
                (ax, ay), (bx, by) = pts[i], pts[(i + 1) % len(pts)]
                ends.append((ax, ay, bx, by))
                colors.append(tuple(color))
    return [_segments(ends, np.array(colors, dtype=np.uint8).reshape(-1, 4))]


def _velocity_segments(store: Any, rows: np.ndarray) -> list[Segments]:
    """For each of ``rows`` with a non-zero Velocity: its entity's position to where the velocity
    takes it in :data:`VELOCITY_SECONDS`."""
    if rows.size == 0:
        return []
    vx, vy = store.vx[rows], store.vy[rows]
    moving = store.has_vel[rows] & ((vx != 0.0) | (vy != 0.0))
    if not moving.any():
        return []
    x, y = store.x[rows][moving], store.y[rows][moving]
    ends = np.stack([x, y, x + vx[moving] * VELOCITY_SECONDS, y + vy[moving] * VELOCITY_SECONDS], axis=1)
    return [_segments(ends, OVERLAY_COLORS["velocity"])]


def _cell_segments(static_hash: Any, box: tuple[float, float, float, float]) -> list[Segments]:
    """The borders of the hash cells in use that meet ``box``."""
    size = static_hash.cell_size
    if not size:
        return []
    cells = np.asarray(static_hash.cells_in_use(), dtype=np.float64).reshape(-1, 2) * size
    if cells.shape[0] == 0:
        return []
    x0, y0 = cells[:, 0], cells[:, 1]
    x1, y1 = x0 + size, y0 + size
    on = (x0 < box[2]) & (x1 > box[0]) & (y0 < box[3]) & (y1 > box[1])
    x0, y0, x1, y1 = x0[on], y0[on], x1[on], y1[on]
    borders = np.stack([
        np.stack([x0, y0, x1, y0], axis=1), np.stack([x1, y0, x1, y1], axis=1),
        np.stack([x1, y1, x0, y1], axis=1), np.stack([x0, y1, x0, y0], axis=1),
    ], axis=1).reshape(-1, 4)
    return [_segments(borders, OVERLAY_COLORS["cell"])]


def _swept_path_segments(paths: list) -> list[Segments]:
    """The swept paths ``((x0, y0), (x1, y1))`` of continuous-detection bodies."""
    if not paths:
        return []
    ends = np.array([(a[0], a[1], b[0], b[1]) for a, b in paths], dtype=np.float64)
    return [_segments(ends, OVERLAY_COLORS["swept"])]


def _ray_segments(ray_log: list, normal_len: float) -> list[Segments]:
    """Each ray ``(origin, end, first hit or None)``: to its hit, the rest, the hit's normal."""
    if not ray_log:
        return []
    to_hit, rest, normals = [], [], []
    for (ox, oy), (ex, ey), hit in ray_log:
        if hit is None:
            rest.append((ox, oy, ex, ey))
        else:
            hx, hy = hit.point
            to_hit.append((ox, oy, hx, hy))
            rest.append((hx, hy, ex, ey))
            normals.append((hx, hy, hx + hit.normal[0] * normal_len, hy + hit.normal[1] * normal_len))
    out = []
    for ends, key in ((rest, "ray_rest"), (to_hit, "ray"), (normals, "ray_normal")):
        if ends:
            out.append(_segments(np.array(ends, dtype=np.float64), OVERLAY_COLORS[key]))
    return out


def _contact_segments(contacts: Any, cross: float, normal_len: float) -> list[Segments]:
    """A cross of half size ``cross`` at each contact point, and its normal (A toward B)."""
    if len(contacts.a) == 0:
        return []
    px, py = np.asarray(contacts.px, dtype=np.float64), np.asarray(contacts.py, dtype=np.float64)
    nx, ny = np.asarray(contacts.nx, dtype=np.float64), np.asarray(contacts.ny, dtype=np.float64)
    normals = np.stack([px, py, px + nx * normal_len, py + ny * normal_len], axis=1)
    crosses = np.concatenate([
        np.stack([px - cross, py - cross, px + cross, py + cross], axis=1),
        np.stack([px - cross, py + cross, px + cross, py - cross], axis=1),
    ])
    return [_segments(normals, OVERLAY_COLORS["normal"]), _segments(crosses, OVERLAY_COLORS["contact"])]


def _point_segments(points: tuple, size: float) -> list[Segments]:
    """A diamond of half size ``size`` at each contact point the solver pushed at (``frame.points``:
    pair key, slot, push, impulse, tangent push, tangent impulse, x, y)."""
    if len(points[0]) == 0:
        return []
    px, py = np.asarray(points[6], dtype=np.float64), np.asarray(points[7], dtype=np.float64)
    corners = [(px + size, py), (px, py + size), (px - size, py), (px, py - size)]
    sides = [np.stack([*corners[k], *corners[(k + 1) % 4]], axis=1) for k in range(4)]
    return [_segments(np.concatenate(sides), OVERLAY_COLORS["point"])]


def _friction_segments(store: Any, rows_of: Any, contacts: Any, support: tuple, length: float) -> list[Segments]:
    """At each contact where friction acted this step, a line along the contact (the way it
    pushes B), ``length`` long at the friction limit and in proportion below it."""
    sa, sb, snx, sny, _push, impulse, _gap, _tpush, timpulse = support
    acting = np.flatnonzero(timpulse != 0.0)
    if acting.size == 0 or len(contacts.a) == 0:
        return []
    keys = pair_keys(np.asarray(contacts.a), np.asarray(contacts.b))
    order = np.argsort(keys)
    at, found = sorted_find(pair_keys(sa[acting], sb[acting]), keys[order])
    acting, at = acting[found], order[at[found]]
    if acting.size == 0:
        return []
    px, py = np.asarray(contacts.px, dtype=np.float64)[at], np.asarray(contacts.py, dtype=np.float64)[at]
    limit = store.pair_friction(rows_of(sa[acting]), rows_of(sb[acting])) * impulse[acting]
    t = timpulse[acting]
    share = np.clip(np.abs(t) / np.where(limit > 0.0, limit, np.abs(t)), 0.0, 1.0) * np.sign(t) * length
    ends = np.stack([px, py, px - sny[acting] * share, py + snx[acting] * share], axis=1)
    return [_segments(ends, OVERLAY_COLORS["friction"])]


def _hud_text(scene: Any, renderer: Any) -> str:
    """The overlay's text: FPS, entities, drawn, contacts, frame; then ms per stage and their total.
    Figures are separated by two spaces, each name and its figure by one (see :func:`wrap_figures`)."""
    frame = scene.step_frame
    fps = f"{renderer.fps:.0f}" if renderer.fps > 0 else "-"
    head = (f"FPS {fps}  entities {scene.bodies.store.n}  drawn {renderer.stats.get('drawn', 0)}  "
            f"contacts {len(frame.contacts.a)}  frame {scene.frame}")
    ms = dict(frame.stage_ms)
    if not ms:
        return f"{head}\nms/step: (not stepped yet)"
    if "render" not in ms and renderer.draw_ms > 0:  # this stage is running: the last one's time
        ms["render"] = renderer.draw_ms
    stages = "  ".join(f"{k} {v:.2f}" for k, v in ms.items())
    return f"{head}\nms/step: {stages}  total {sum(ms.values()):.2f}"


def _wrap_line(line: str, max_width: float, measure: Callable[[str], float]) -> list[str]:
    out: list[str] = []
    current = ""
    for figure in line.split("  "):
        joined = f"{current}  {figure}" if current else figure
        if current and measure(joined) > max_width:
            out.append(current)
            joined = f"  {figure}"
        current = joined
    out.append(current)
    return out


def wrap_figures(text: str, max_width: float, measure: Callable[[str], float],
                 max_lines: int | None = None) -> list[str]:
    """``text``'s lines, each broken into as few lines as keep every one within ``max_width`` (as
    ``measure`` gives a string's width): breaks fall only between figures (the two-space gaps),
    never between a name and its figure. A continued line is indented by two spaces; a figure
    wider than ``max_width`` on its own stays whole.

    ``max_lines``: at most this many lines (never fewer than ``text`` has): each of ``text``'s
    lines keeps at least one, and what does not fit stays on a line's last one, running past
    ``max_width`` (a view too small to show it all shows the start of each line)."""
    source = text.split("\n")
    limit = None if max_lines is None else max(max_lines, len(source))
    out: list[str] = []
    for i, line in enumerate(source):
        wrapped = _wrap_line(line, max_width, measure)
        if limit is not None:
            room = limit - len(out) - (len(source) - 1 - i)
            if len(wrapped) > room:  # continuations start with their gap: joining them restores it
                wrapped = [*wrapped[:room - 1], "".join(wrapped[room - 1:])]
        out += wrapped
    return out


class DebugOverlay:
    """Builds the overlay's lines from a scene (:meth:`build`) and draws them (:meth:`draw_world`,
    :meth:`draw_hud`). Needs a current GL context."""

    def __init__(self) -> None:
        ctx = gl.current_context
        if ctx is None:
            raise RuntimeError("the debug overlay needs a current GL context")
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
        self._text_group = Group(order=1)
        self._labels: list[Any] = []  # one per text line shown, made as lines are needed
        self._font: Any = None

    # --- building ---------------------------------------------------------------------------

    def build(self, scene: Any, renderer: Any, rows: np.ndarray) -> None:
        """Collect this step's overlay lines (in world coordinates) for the visible ``rows`` and
        the text line. Reads ``scene.bodies`` and ``scene.step_frame`` (see docs/rendering.md)."""
        bodies, frame = scene.bodies, scene.step_frame
        store, geometry = bodies.store, bodies.ensure_geometry()
        zoom = renderer.camera.zoom
        parts: list[Segments] = []
        parts += _cell_segments(bodies.hash, renderer.camera.view_box())
        parts += _outline_segments(store, geometry, rows[store.kind[rows] >= 0])
        parts += _part_segments(store)
        parts += _velocity_segments(store, rows)
        parts += _swept_path_segments(frame.swept_paths)
        parts += _ray_segments(frame.ray_log, NORMAL_PX / zoom)
        parts += _contact_segments(frame.contacts, CROSS_PX / zoom, NORMAL_PX / zoom)
        parts += _point_segments(frame.points, CROSS_PX / zoom)
        parts += _friction_segments(store, bodies.rows_of, frame.contacts, frame.support, NORMAL_PX / zoom)
        parts = [p for p in parts if p[0].shape[0]]
        if parts:
            ends = np.concatenate([p[0] for p in parts])
            colors = np.concatenate([p[1] for p in parts])
            finite = np.isfinite(ends).all(axis=1)
            ends, colors = ends[finite], colors[finite]
        else:
            ends, colors = np.zeros((0, 4)), np.zeros((0, 4), dtype=np.uint8)
        self._upload(ends, colors)
        self.text = _hud_text(scene, renderer)

    def _upload(self, ends: np.ndarray, colors: np.ndarray) -> None:
        """Write the segments into the vertex buffer, two vertices each."""
        m = ends.shape[0]
        data = np.empty(2 * m, dtype=_VERTEX_DTYPE)
        data["p"] = ends.reshape(2 * m, 2)
        data["c"] = np.repeat(colors, 2, axis=0)
        self.count = 2 * m
        if m:
            self._vbo.size = data.nbytes
            self._vbo.set_data(data.ctypes.data_as(ctypes.POINTER(ctypes.c_ubyte)))

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

    def lines(self, width: int, height: int) -> list[str]:
        """The text as shown in a ``width`` x ``height`` view: wrapped between figures so that every
        line fits the width (:func:`wrap_figures`, measured in the overlay's font), onto at most
        :data:`HUD_MAX_SHARE` of the height, so that the text never hides most of a small view."""
        if self._font is None:
            self._font = pyglet.font.load(None, HUD_FONT_SIZE)
        font = self._font

        def measure(text: str) -> float:
            return float(sum(glyph.advance for glyph in font.get_glyphs(text)[0]))

        max_lines = int(height * HUD_MAX_SHARE) // HUD_LINE_PX
        return wrap_figures(self.text, width - 2 * HUD_MARGIN_PX, measure, max_lines=max_lines)

    def draw_hud(self, renderer: Any) -> None:
        """Draw the text at the top left, wrapped to the view's width (the identity view must be set)."""
        lines = self.lines(renderer.width, renderer.height)
        while len(self._labels) < len(lines):
            self._labels.append(pyglet.text.Label(
                "", x=HUD_MARGIN_PX, y=0, anchor_y="top", font_size=HUD_FONT_SIZE, color=OVERLAY_COLORS["text"],
                batch=self._hud_batch, group=self._text_group))
        top = renderer.height - 4
        width = 0.0
        for i, label in enumerate(self._labels):
            text = lines[i] if i < len(lines) else ""
            if label.text != text:
                label.text = text
            label.y = top - HUD_LINE_PX * i
            width = max(width, label.content_width)
        self._hud_back.position = (0, top - HUD_LINE_PX * len(lines) - 2)
        self._hud_back.width, self._hud_back.height = width + 2 * HUD_MARGIN_PX, HUD_LINE_PX * len(lines) + 6
        self._hud_batch.draw()

    def label_widths(self) -> list[int]:
        """The laid-out width in pixels of each text line the last :meth:`draw_hud` showed."""
        return [label.content_width for label in self._labels if label.text]

    def delete(self) -> None:
        self._vbo.delete()
        self._vao.delete()
        for label in self._labels:
            label.delete()
        self._hud_back.delete()
