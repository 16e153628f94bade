"""The render system: entities with a :class:`~framework.components.Visual`, drawn through batches.

``scene.renderer = Renderer(...)`` attaches it; the scene then calls :meth:`Renderer.draw` as the
last stage of every step. That stage *brings the batches up to date* (camera, culling, shapes);
the GL draw calls happen when a frame is shown (:meth:`Renderer.render`, called by the window
runner's ``on_draw`` or by :meth:`Renderer.capture`). So a frame that ran two steps draws once, and
a frame that ran none shows the last state again.

Culling: the camera's view box picks the rows to draw. Static bodies come from the scene's spatial
hash (``scene.hash.query_box`` over the view), moving bodies (and bodies without a hitbox) from
one vectorised test of their bounds; a sprite's reach beyond its hitbox is added to the bounds.
Only the visible entities are then visited in Python: their Visual is looked up, their drawable
made on first sight, moved only if their position changed since it was last drawn (a vectorised
comparison), shown if it was hidden. Drawables that leave the view are hidden, not deleted, and
deleted only after being out of view for a while (or when their entity goes).

Batching: every drawable lives in one :class:`pyglet.graphics.Batch`, under a
:class:`pyglet.graphics.Group` per ``Visual.z`` (lower z first). pyglet draws a batch with one
multi-draw call per group and state, whatever the number of entities.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np
import pyglet
from pyglet import gl
from pyglet.graphics import Batch, Group
from pyglet.math import Mat4

from ..components import Visual
from ..store import KIND_POLYGON, STATIC
from .camera import Camera
from .drawables import ConvexFill, Drawable, fill_triangles, load_image
from .overlay import DebugOverlay

__all__ = ["Renderer"]

_HIDDEN_FRAMES = 300  # a drawable out of view this many frames is deleted (made again if it returns)
_SWEEP_EVERY = 60


class Renderer:
    """Draws a scene's entities (and, with ``debug``, the collision overlay) with pyglet.

    ``width, height``: the viewport in screen pixels (the window runner keeps them in step with
    the window). ``camera``: a :class:`~framework.render.camera.Camera` (default: world
    coordinates are screen pixels). ``debug``: draw the debug overlay. ``background``: clear
    colour of :meth:`capture` and the window runner.

    ``window``: the pyglet window whose GL context holds the renderer's GL objects; ``None`` until
    first used, then the window runner's window or, without one, a hidden offscreen window.
    """

    def __init__(
        self,
        *,
        width: int = 960,
        height: int = 540,
        camera: Camera | None = None,
        debug: bool = False,
        background: tuple[int, int, int] = (0, 0, 0),
        window: Any = None,
    ) -> None:
        self.width, self.height = int(width), int(height)
        if self.width <= 0 or self.height <= 0:
            raise ValueError(f"Renderer size must be positive, got {width!r} x {height!r}")
        self.camera = camera if camera is not None else Camera()
        self.debug = bool(debug)
        self.background = tuple(background)
        self.window = window
        self.fps = 0.0  # frames shown per second, measured by the window runner
        self.draw_ms = 0.0  # how long the last draw (the render stage) took
        #: what the last draw did: visible rows, drawables shown, made, moved, deleted
        self.stats: dict[str, int] = {}
        self._batch: Batch | None = None
        self._groups: dict[int, Group] = {}
        self._records: dict[int, Drawable] = {}
        self._shown: set[int] = set()
        self._images: dict[str, Any] = {}
        self._overlay: DebugOverlay | None = None
        self._frame = 0
        self._store_version = -1
        self._gone_version = -1
        self._lut = np.zeros(1, dtype=np.int64)
        # Per entity id: the last drawn (hx, hy, x, y, rot); the extra reach of its sprite beyond
        # its bounds; whether it has been looked at once.
        self._last = np.full((0, 5), np.nan)
        self._pad = np.zeros(0)
        self._seen = np.zeros(0, dtype=bool)
        self._fbo: tuple[Any, Any, int, int] | None = None
        self._scene_entities = 0

    # --- GL context ---------------------------------------------------------------------------

    def _enter(self) -> Any:
        """Make the renderer's context current; return the one to restore afterwards."""
        if self.window is None:
            from .headless import offscreen_window

            self.window = offscreen_window()
        prev = gl.current_context
        if prev is not self.window.context:
            self.window.switch_to()
        if self._batch is None:
            self._batch = Batch()
        return prev

    def _leave(self, prev: Any) -> None:
        if prev is not None and prev is not gl.current_context:
            prev.set_current()

    # --- the render stage -----------------------------------------------------------------

    def draw(self, scene: Any) -> None:
        """The render stage: follow the camera's target, cull, and bring the drawables (and the
        overlay, with ``debug``) up to date with the scene. No GL draw call happens here."""
        prev = self._enter()
        t0 = time.perf_counter()
        try:
            self._frame += 1
            self.camera.update(scene, self.width, self.height)
            store = scene.store
            scene.ensure_geometry()
            if store.version != self._gone_version:
                self._forget_gone(store)
                self._gone_version = store.version
            self._first_sight(scene)
            rows = self.visible_rows(scene)
            self._sync(scene, rows)
            if self._frame % _SWEEP_EVERY == 0:
                self._sweep()
            if self.debug:
                if self._overlay is None:
                    self._overlay = DebugOverlay()
                self._overlay.build(scene, self, rows)
            self._scene_entities = len(store.row_of)
        finally:
            self.draw_ms = (time.perf_counter() - t0) * 1e3
            self._leave(prev)

    def visible_rows(self, scene: Any) -> np.ndarray:
        """Store rows whose bounds (grown by their sprite's reach) meet the camera's view box.

        Statics come from the spatial hash when it is current; everything else (and the statics
        when the hash is stale: a static changed since the last step, or detection is off) from
        one vectorised test of the bounds. Call after ``scene.geometry.update``."""
        store, geom = scene.store, scene.geometry
        n = store.n
        if n == 0:
            return np.zeros(0, dtype=np.int64)
        x0, y0, x1, y1 = self.camera.view_box()
        m = 1.0 / self.camera.zoom  # a pixel of margin
        x0, y0, x1, y1 = x0 - m, y0 - m, x1 + m, y1 + m
        ents = store.entity
        self._grow(int(ents.max()) + 1)
        pad = self._pad[ents]
        static = (store.kind >= 0) & (store.body == STATIC)
        hsh = scene.hash
        if "detection" in scene.effects and not store.static_dirty and hsh.cell_size is not None:
            reach = float(pad[static].max()) if static.any() else 0.0
            ids = hsh.query_box(x0 - reach, y0 - reach, x1 + reach, y1 + reach)
            srows = self._rows_of(store, ids)
            srows = srows[srows >= 0]
            cand = np.concatenate([srows[static[srows]], np.flatnonzero(~static)])
        else:
            cand = np.arange(n)
        x, y, p = store.x[cand], store.y[cand], pad[cand]
        minx = np.minimum(geom.minx[cand], x - p)
        maxx = np.maximum(geom.maxx[cand], x + p)
        miny = np.minimum(geom.miny[cand], y - p)
        maxy = np.maximum(geom.maxy[cand], y + p)
        inside = (minx < x1) & (maxx > x0) & (miny < y1) & (maxy > y0)
        return np.sort(cand[inside])

    # --- bookkeeping ------------------------------------------------------------------------

    def _first_sight(self, scene: Any) -> None:
        """Look once at each entity not seen before: a sprite's reach beyond the entity's bounds
        must be known before culling can keep a sprite that hangs into the view."""
        store = scene.store
        if store.n == 0:
            return
        ents = store.entity
        self._grow(int(ents.max()) + 1)
        new = ents[~self._seen[ents]]
        if new.size:
            for e in new.tolist():
                vis = scene.try_get(e, Visual)
                if vis is not None and vis.image is not None:
                    tex = self._image(vis.image, e)
                    self._pad[e] = 0.5 * math.hypot(tex.width, tex.height)
            self._seen[new] = True

    def _grow(self, size: int) -> None:
        have = self._pad.shape[0]
        if size <= have:
            return
        new = max(size, 2 * have, 64)
        last = np.full((new, 5), np.nan)
        last[:have] = self._last
        pad = np.zeros(new)
        pad[:have] = self._pad
        seen = np.zeros(new, dtype=bool)
        seen[:have] = self._seen
        self._last, self._pad, self._seen = last, pad, seen

    def _rows_of(self, store: Any, ids: np.ndarray) -> np.ndarray:
        if self._lut.shape[0] <= (int(store.entity.max()) if store.n else 0) or \
                self._store_version != store.version:
            lut = np.full((int(store.entity.max()) + 1) if store.n else 1, -1, dtype=np.int64)
            lut[store.entity] = np.arange(store.n)
            self._lut = lut
            self._store_version = store.version
        ids = np.asarray(ids, dtype=np.int64)
        out = np.full(ids.shape[0], -1, dtype=np.int64)
        ok = ids < self._lut.shape[0]
        out[ok] = self._lut[ids[ok]]
        return out

    def _forget_gone(self, store: Any) -> None:
        """Delete the drawables of entities that left the scene."""
        row_of = store.row_of
        for e in [e for e in self._records if e not in row_of]:
            self._records.pop(e).delete()
            self._shown.discard(e)

    def _sweep(self) -> None:
        """Delete drawables that have been out of view for a long time."""
        old = self._frame - _HIDDEN_FRAMES
        for e in [e for e, r in self._records.items() if not r.shown and r.last_seen < old]:
            self._records.pop(e).delete()
            self.stats["deleted"] = self.stats.get("deleted", 0) + 1

    def _group(self, z: int) -> Group:
        g = self._groups.get(z)
        if g is None:
            g = self._groups[z] = Group(order=z)
        return g

    def _image(self, path: str, entity: int) -> Any:
        tex = self._images.get(path)
        if tex is None:
            try:
                tex = load_image(path)
            except Exception as exc:  # a missing or unreadable file: say which entity and path
                raise ValueError(
                    f"entity {entity}: Visual image {path!r} could not be loaded: {exc}"
                ) from exc
            self._images[path] = tex
        return tex

    # --- drawables ------------------------------------------------------------------------

    def _make(self, entity: int, vis: Visual, shape: Any, kind: int) -> Drawable | None:
        group = self._group(vis.z)
        color = tuple(vis.color)
        if vis.image is not None:
            tex = self._image(vis.image, entity)
            sprite = pyglet.sprite.Sprite(tex, 0.0, 0.0, batch=self._batch, group=group)
            if color != (255, 255, 255, 255):
                sprite.color = color
            self._grow(entity + 1)
            self._pad[entity] = 0.5 * math.hypot(tex.width, tex.height)
            return Drawable(sprite, "sprite", shape, vis.image, vis.z, color, True)
        if shape is None:
            return None  # a Visual without an image needs a hitbox to take its shape from
        fill = ConvexFill(fill_triangles(shape, self.camera.zoom), 0.0, 0.0, 0.0, color,
                          batch=self._batch, group=group)
        return Drawable(fill, "fill", shape, None, vis.z, color, kind == KIND_POLYGON)

    def _sync(self, scene: Any, rows: np.ndarray) -> None:
        store, geom = scene.store, scene.geometry
        ents = store.entity[rows]
        made = moved_n = 0
        if rows.size:
            self._grow(int(ents.max()) + 1)
        cur = np.stack([geom.hx[rows], geom.hy[rows], store.x[rows], store.y[rows], store.rot[rows]], axis=1)
        moved = (cur != self._last[ents]).any(axis=1) if rows.size else np.zeros(0, dtype=bool)
        self._last[ents] = cur
        records, frame = self._records, self._frame
        hitboxes = store.hitboxes
        kinds = store.kind[rows].tolist()
        shown: set[int] = set()
        try_get = scene.try_get
        for i, (e, r, mv) in enumerate(zip(ents.tolist(), rows.tolist(), moved.tolist())):
            vis = try_get(e, Visual)
            rec = records.get(e)
            if vis is None or not vis.visible:
                continue
            hb = hitboxes[r]
            shape = None if hb is None else hb.shape
            if rec is None or rec.image != vis.image or (vis.image is None and rec.shape is not shape):
                if rec is not None:
                    records.pop(e).delete()
                rec = self._make(e, vis, shape, kinds[i])
                if rec is None:
                    continue
                records[e] = rec
                made += 1
                mv = True
            else:
                if rec.z != vis.z:
                    rec.set_group(vis.z, self._group(vis.z))
                if rec.color != vis.color:
                    rec.set_color(tuple(vis.color))
                if not rec.shown:
                    rec.show()
                    mv = True
            if mv:
                c = cur[i]
                rec.place(float(c[0]), float(c[1]), float(c[2]), float(c[3]), float(c[4]))
                moved_n += 1
            rec.last_seen = frame
            shown.add(e)
        for e in self._shown - shown:
            rec = records.get(e)
            if rec is not None and rec.shown:
                rec.hide()
        self._shown = shown
        self.stats = {"visible_rows": int(rows.size), "drawn": len(shown), "made": made, "moved": moved_n,
                      "drawables": len(records)}

    # --- GL: showing a frame ------------------------------------------------------------------

    def render(self, window: Any = None) -> None:
        """Issue the GL draw calls of the last :meth:`draw` into the bound framebuffer, with the
        projection of a ``width`` x ``height`` viewport (the caller sets ``glViewport``).

        ``window``: whose ``projection`` / ``view`` (pyglet's WindowBlock) to set; default the
        renderer's own window."""
        prev = self._enter()
        win = window if window is not None else self.window
        try:
            win.projection = Mat4.orthogonal_projection(0.0, float(self.width), 0.0, float(self.height),
                                                        -8192.0, 8192.0)
            win.view = Mat4(*self.camera.matrix())
            assert self._batch is not None
            self._batch.draw()
            if self.debug and self._overlay is not None:
                self._overlay.draw_world()
                win.view = Mat4()
                self._overlay.draw_hud(self)
            win.view = Mat4()
        finally:
            self._leave(prev)

    def capture(self, path: str | None = None) -> np.ndarray:
        """Render the last :meth:`draw` offscreen into an RGBA8 texture (pixel-exact) and return
        it as a ``(height, width, 4)`` uint8 array, top row first, alpha 255; also written as a
        PNG when ``path`` is given."""
        from .headless import read_pixels, write_png

        prev = self._enter()
        try:
            w, h = self.width, self.height
            if self._fbo is None or self._fbo[2:] != (w, h):
                tex = pyglet.image.Texture.create(w, h, internalformat=gl.GL_RGBA8)
                fbo = pyglet.image.Framebuffer()
                fbo.attach_texture(tex)
                self._fbo = (fbo, tex, w, h)
            fbo = self._fbo[0]
            fbo.bind()
            try:
                if not fbo.is_complete:
                    raise RuntimeError(f"offscreen framebuffer incomplete: {fbo.get_status()}")
                gl.glViewport(0, 0, w, h)
                r, g, b = (c / 255.0 for c in self.background[:3])
                gl.glClearColor(r, g, b, 1.0)
                gl.glClear(gl.GL_COLOR_BUFFER_BIT | gl.GL_DEPTH_BUFFER_BIT)
                self.render()
                pixels = read_pixels(w, h)
            finally:
                fbo.unbind()
        finally:
            self._leave(prev)
        if path is not None:
            write_png(path, pixels)
        return pixels

    # --- lifetime -----------------------------------------------------------------------------

    def reset(self) -> None:
        """Forget every drawable (e.g. before drawing another scene, whose entity ids differ)."""
        if self._records or self._overlay is not None:
            prev = self._enter()
            try:
                for rec in self._records.values():
                    rec.delete()
            finally:
                self._leave(prev)
        self._records.clear()
        self._shown = set()
        self._last = np.full((0, 5), np.nan)
        self._pad = np.zeros(0)
        self._seen = np.zeros(0, dtype=bool)
        self._store_version = -1
        self._gone_version = -1
        self._lut = np.zeros(1, dtype=np.int64)

    def close(self) -> None:
        """Delete the renderer's GL objects (drawables, overlay buffers, offscreen target)."""
        if self.window is None:
            return
        self.reset()
        prev = self._enter()
        try:
            if self._overlay is not None:
                self._overlay.delete()
                self._overlay = None
            if self._fbo is not None:
                self._fbo[0].delete()
                self._fbo[1].delete()
                self._fbo = None
            self._batch = None
        finally:
            self._leave(prev)

    @property
    def scene_entities(self) -> int:
        """Entities with a Transform in the scene at the last draw."""
        return self._scene_entities
