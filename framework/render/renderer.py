"""The render system: entities with a :class:`~framework.components.Visual`, drawn through batches.

``scene.renderer = Renderer(...)`` attaches it; the scene then calls :meth:`Renderer.draw` as the
last stage of every step. That stage *brings the batches up to date* (camera, culling, shapes);
the GL draw calls happen when a frame is shown (:meth:`Renderer.render`, called by the window
runner's ``on_draw`` or by :meth:`Renderer.capture`). So a frame that ran two steps draws once, and
a frame that ran none shows the last state again.

The renderer reads the scene only through the read-only surface written down in
docs/rendering.md ("What the renderer reads"): ``scene.bodies`` (the store's columns, the current
geometry, the one entity -> row lookup, the static spatial hash), ``scene.step_frame`` (for the
overlay), ``scene.try_get``, ``scene.exists`` and ``scene.frame``.

Culling: the camera's view box picks the rows to draw. Static bodies come from the static spatial
hash while it is current (``bodies.static_rows_in_box`` over the view), moving bodies (and bodies
without a hitbox) from one vectorised test of their bounds; a sprite's reach beyond its hitbox is
added to the bounds. Only the visible entities are then visited in Python: their Visual is looked
up, their drawable made on first sight, moved only if their position changed since it was last
drawn (a vectorised comparison), shown if it was hidden. Drawables that leave the view are hidden,
not deleted, and deleted only after being out of view for a while (or when their entity goes).

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
from .offscreen import OffscreenTarget, offscreen_window, write_png
from .overlay import DebugOverlay

__all__ = ["Renderer"]

DELETE_HIDDEN_AFTER = 300  # a drawable out of view for this many draws is deleted (made again if it returns)
CHECK_HIDDEN_EVERY = 60  # draws between two looks for drawables to delete

_NO_ROWS = np.zeros(0, dtype=np.int64)


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
        self._z_groups: dict[int, Group] = {}
        self._drawables: dict[int, Drawable] = {}  # entity -> its drawable (shown or hidden)
        self._shown_entities: set[int] = set()  # entities whose drawable the last draw showed
        self._textures: dict[str, Any] = {}  # image path -> texture
        self._overlay: DebugOverlay | None = None
        self._target = OffscreenTarget()  # what capture() draws into
        self._draws = 0  # render stages run (a drawable's last_seen counts in these)
        self._store_version_seen = -1  # the store's version when despawned entities were last looked for
        self._scene_entities = 0
        self._forget_entities()

    def _forget_entities(self) -> None:
        """Empty the per-entity-id tables (grown as ids grow, by :meth:`_grow`)."""
        self._drawn_pose = np.full((0, 5), np.nan)  # hx, hy, x, y, rot when last placed
        self._sprite_reach = np.zeros(0)  # how far a sprite reaches beyond its entity's bounds
        self._looked_at = np.zeros(0, dtype=bool)  # whether the entity was looked at once

    # --- GL context ---------------------------------------------------------------------------

    def _make_current(self) -> Any:
        """Make the renderer's context current; return the one to restore afterwards."""
        if self.window is None:
            self.window = offscreen_window()
        previous = gl.current_context
        if previous is not self.window.context:
            self.window.switch_to()
        if self._batch is None:
            self._batch = Batch()
        return previous

    @staticmethod
    def _restore(previous: Any) -> None:
        if previous is not None and previous is not gl.current_context:
            previous.set_current()

    # --- the render stage -----------------------------------------------------------------

    def draw(self, scene: Any) -> None:
        """The render stage: follow the camera's target, cull, and bring the drawables (and the
        overlay, with ``debug``) up to date with the scene. No GL draw call happens here."""
        previous = self._make_current()
        t0 = time.perf_counter()
        try:
            self._draws += 1
            self.camera.update(scene, self.width, self.height)
            bodies = scene.bodies
            bodies.ensure_geometry()
            if bodies.store.version != self._store_version_seen:
                self._forget_despawned(bodies)
                self._store_version_seen = bodies.store.version
            self._look_at_new_entities(scene)
            rows = self.visible_rows(scene)
            self._sync(scene, rows)
            if self._draws % CHECK_HIDDEN_EVERY == 0:
                self._delete_long_hidden()
            if self.debug:
                if self._overlay is None:
                    self._overlay = DebugOverlay()
                self._overlay.build(scene, self, rows)
            self._scene_entities = bodies.store.n
        finally:
            self.draw_ms = (time.perf_counter() - t0) * 1e3
            self._restore(previous)

    def visible_rows(self, scene: Any) -> np.ndarray:
        """Sorted store rows whose bounds (grown by their sprite's reach) meet the camera's view box
        plus a pixel of margin.

        Statics come from the static spatial hash while it is current; everything else (and the
        statics when the hash is not current: a static changed since it was built, or it never
        was) from one vectorised test of the bounds."""
        bodies = scene.bodies
        store, geometry = bodies.store, bodies.ensure_geometry()
        if store.n == 0:
            return _NO_ROWS
        margin = 1.0 / self.camera.zoom  # a pixel
        x0, y0, x1, y1 = self.camera.view_box()
        x0, y0, x1, y1 = x0 - margin, y0 - margin, x1 + margin, y1 + margin
        entities = store.entity
        self._grow(int(entities.max()) + 1)
        reach = self._sprite_reach[entities]
        static = (store.kind >= 0) & (store.body == STATIC)
        if bodies.static_hash_current:
            r = float(reach[static].max()) if static.any() else 0.0
            near = bodies.static_rows_in_box(x0 - r, y0 - r, x1 + r, y1 + r)
            candidates = np.concatenate([near, np.flatnonzero(~static)])
        else:
            candidates = np.arange(store.n)
        x, y, r = store.x[candidates], store.y[candidates], reach[candidates]
        minx = np.minimum(geometry.minx[candidates], x - r)
        maxx = np.maximum(geometry.maxx[candidates], x + r)
        miny = np.minimum(geometry.miny[candidates], y - r)
        maxy = np.maximum(geometry.maxy[candidates], y + r)
        inside = (minx < x1) & (maxx > x0) & (miny < y1) & (maxy > y0)
        return np.sort(candidates[inside])

    # --- bookkeeping ------------------------------------------------------------------------

    def _look_at_new_entities(self, scene: Any) -> None:
        """Look once at each entity not seen before: a sprite's reach beyond the entity's bounds
        must be known before culling can keep a sprite that hangs into the view."""
        store = scene.bodies.store
        if store.n == 0:
            return
        entities = store.entity
        self._grow(int(entities.max()) + 1)
        new = entities[~self._looked_at[entities]]
        if new.size:
            for entity in new.tolist():
                visual = scene.try_get(entity, Visual)
                if visual is not None and visual.image is not None:
                    self._note_sprite_reach(entity, self._texture(visual.image, entity))
            self._looked_at[new] = True

    def _note_sprite_reach(self, entity: int, texture: Any) -> None:
        self._sprite_reach[entity] = 0.5 * math.hypot(texture.width, texture.height)

    def _grow(self, size: int) -> None:
        """Make the per-entity-id tables hold ids below ``size``."""
        have = self._sprite_reach.shape[0]
        if size <= have:
            return
        new = max(size, 2 * have, 64)
        drawn_pose = np.full((new, 5), np.nan)
        drawn_pose[:have] = self._drawn_pose
        sprite_reach = np.zeros(new)
        sprite_reach[:have] = self._sprite_reach
        looked_at = np.zeros(new, dtype=bool)
        looked_at[:have] = self._looked_at
        self._drawn_pose, self._sprite_reach, self._looked_at = drawn_pose, sprite_reach, looked_at

    def _forget_despawned(self, bodies: Any) -> None:
        """Delete the drawables of entities that left the scene (no row in the store)."""
        if not self._drawables:
            return
        entities = np.fromiter(self._drawables, dtype=np.int64, count=len(self._drawables))
        for entity in entities[bodies.rows_of(entities) < 0].tolist():
            self._drawables.pop(entity).delete()
            self._shown_entities.discard(entity)

    def _delete_long_hidden(self) -> None:
        """Delete drawables that have been out of view for a long time."""
        oldest = self._draws - DELETE_HIDDEN_AFTER
        long_hidden = [e for e, d in self._drawables.items() if not d.shown and d.last_seen < oldest]
        for entity in long_hidden:
            self._drawables.pop(entity).delete()
            self.stats["deleted"] = self.stats.get("deleted", 0) + 1

    def _z_group(self, z: int) -> Group:
        group = self._z_groups.get(z)
        if group is None:
            group = self._z_groups[z] = Group(order=z)
        return group

    def _texture(self, path: str, entity: int) -> Any:
        texture = self._textures.get(path)
        if texture is None:
            try:
                texture = load_image(path)
            except Exception as exc:  # a missing or unreadable file: say which entity and path
                raise ValueError(
                    f"entity {entity}: Visual image {path!r} could not be loaded: {exc}"
                ) from exc
            self._textures[path] = texture
        return texture

    # --- drawables ------------------------------------------------------------------------

    def _make(self, entity: int, visual: Visual, shape: Any, kind: int) -> Drawable | None:
        """A new drawable for ``entity``: its image as a sprite, else its hitbox ``shape`` filled
        (``None`` when it has neither)."""
        group = self._z_group(visual.z)
        color = tuple(visual.color)
        if visual.image is not None:
            texture = self._texture(visual.image, entity)
            sprite = pyglet.sprite.Sprite(texture, 0.0, 0.0, batch=self._batch, group=group)
            if color != (255, 255, 255, 255):
                sprite.color = color
            self._grow(entity + 1)
            self._note_sprite_reach(entity, texture)
            return Drawable(sprite, "sprite", shape, visual.image, visual.z, color, True)
        if shape is None:
            return None  # a Visual without an image needs a hitbox to take its shape from
        fill = ConvexFill(fill_triangles(shape, self.camera.zoom), 0.0, 0.0, 0.0, color,
                          batch=self._batch, group=group)
        return Drawable(fill, "fill", shape, None, visual.z, color, kind == KIND_POLYGON)

    def _remake(self, entity: int, visual: Visual, shape: Any, kind: int) -> Drawable | None:
        """Replace ``entity``'s drawable (if any) by a new one (``None``: nothing to draw)."""
        old = self._drawables.pop(entity, None)
        if old is not None:
            old.delete()
        drawable = self._make(entity, visual, shape, kind)
        if drawable is not None:
            self._drawables[entity] = drawable
        return drawable

    def _refresh(self, drawable: Drawable, visual: Visual) -> bool:
        """Take ``visual``'s z and colour; show the drawable if it was hidden. Return whether it
        was (it must then be placed: it has not followed its entity while hidden)."""
        if drawable.z != visual.z:
            drawable.set_group(visual.z, self._z_group(visual.z))
        if drawable.color != visual.color:
            drawable.set_color(tuple(visual.color))
        if drawable.shown:
            return False
        drawable.show()
        return True

    def _poses(self, bodies: Any, rows: np.ndarray, entities: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(poses, moved)``: each row's ``(hx, hy, x, y, rot)`` (hitbox origin, Transform,
        rotation) and whether it differs from the pose its entity was last drawn at (which
        becomes this one)."""
        store, geometry = bodies.store, bodies.ensure_geometry()
        if rows.size == 0:
            return np.zeros((0, 5)), np.zeros(0, dtype=bool)
        self._grow(int(entities.max()) + 1)
        poses = np.stack([geometry.hx[rows], geometry.hy[rows], store.x[rows], store.y[rows], store.rot[rows]],
                         axis=1)
        moved = (poses != self._drawn_pose[entities]).any(axis=1)
        self._drawn_pose[entities] = poses
        return poses, moved

    def _sync(self, scene: Any, rows: np.ndarray) -> None:
        """Bring the drawables of the visible ``rows`` up to date with their entities' Visual,
        hitbox and pose; hide the drawables of entities no longer visible."""
        store = scene.bodies.store
        entities = store.entity[rows]
        poses, moved = self._poses(scene.bodies, rows, entities)
        hitboxes, kinds = store.hitboxes, store.kind[rows].tolist()
        drawables, draws, try_get = self._drawables, self._draws, scene.try_get
        shown: set[int] = set()
        made = placed = 0
        for i, (entity, row, must_place) in enumerate(zip(entities.tolist(), rows.tolist(), moved.tolist())):
            visual = try_get(entity, Visual)
            if visual is None or not visual.visible:
                continue
            hitbox = hitboxes[row]
            shape = None if hitbox is None else hitbox.shape
            drawable = drawables.get(entity)
            if drawable is None or drawable.image != visual.image or (
                    visual.image is None and drawable.shape is not shape):
                drawable = self._remake(entity, visual, shape, kinds[i])
                if drawable is None:
                    continue
                made += 1
                must_place = True
            elif self._refresh(drawable, visual):
                must_place = True
            if must_place:
                hx, hy, x, y, rot = poses[i].tolist()
                drawable.place(hx, hy, x, y, rot)
                placed += 1
            drawable.last_seen = draws
            shown.add(entity)
        self._hide_all_but(shown)
        self.stats = {"visible_rows": int(rows.size), "drawn": len(shown), "made": made, "moved": placed,
                      "drawables": len(drawables)}

    def _hide_all_but(self, shown: set[int]) -> None:
        """Hide the drawables shown by the last draw whose entities are not in ``shown``."""
        for entity in self._shown_entities - shown:
            drawable = self._drawables.get(entity)
            if drawable is not None and drawable.shown:
                drawable.hide()
        self._shown_entities = shown

    # --- GL: showing a frame ------------------------------------------------------------------

    def render(self, window: Any = None) -> None:
        """Issue the GL draw calls of the last :meth:`draw` into the bound framebuffer, with the
        projection of a ``width`` x ``height`` viewport (the caller sets ``glViewport``).

        ``window``: whose ``projection`` / ``view`` (pyglet's WindowBlock) to set; default the
        renderer's own window."""
        previous = self._make_current()
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
            self._restore(previous)

    def capture(self, path: str | None = None) -> np.ndarray:
        """Render the last :meth:`draw` offscreen into an RGBA8 texture (pixel-exact) and return
        it as a ``(height, width, 4)`` uint8 array, top row first, alpha 255; also written as a
        PNG when ``path`` is given."""
        previous = self._make_current()
        try:
            pixels = self._target.capture(self.width, self.height, self.background, self.render)
        finally:
            self._restore(previous)
        if path is not None:
            write_png(path, pixels)
        return pixels

    # --- lifetime -----------------------------------------------------------------------------

    def reset(self) -> None:
        """Forget every drawable (e.g. before drawing another scene, whose entity ids differ)."""
        if self._drawables or self._overlay is not None:
            previous = self._make_current()
            try:
                for drawable in self._drawables.values():
                    drawable.delete()
            finally:
                self._restore(previous)
        self._drawables.clear()
        self._shown_entities = set()
        self._forget_entities()
        self._store_version_seen = -1

    def close(self) -> None:
        """Delete the renderer's GL objects (drawables, overlay buffers, offscreen target)."""
        if self.window is None:
            return
        self.reset()
        previous = self._make_current()
        try:
            if self._overlay is not None:
                self._overlay.delete()
                self._overlay = None
            self._target.delete()
            self._batch = None
        finally:
            self._restore(previous)

    @property
    def scene_entities(self) -> int:
        """Entities with a Transform in the scene at the last draw."""
        return self._scene_entities
