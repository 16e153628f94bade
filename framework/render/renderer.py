"""The render system: entities with a :class:`~framework.components.Visual`, drawn column-wise.

``scene.renderer = Renderer(...)`` attaches it; the scene then calls :meth:`Renderer.draw` as the
last stage of every step. That stage *brings the drawing up to date* (camera, culling, poses);
the GL draw calls happen when a frame is shown (:meth:`Renderer.render`, called by the window
runner's ``on_draw`` or by :meth:`Renderer.capture`). So a frame that ran two steps draws once, and
a frame that ran none shows the last state again.

The renderer reads the scene only through the read-only surface written down in
docs/rendering.md ("What the renderer reads").

Column-wise: each drawable (one per drawn entity) is a vertex list that does not change while it
moves, and a row (*slot*) of one float table on the GPU holding its pose, the atlas rectangle it
shows and its size (:mod:`.instances`). A frame computes those rows for every visible drawable
with numpy, from the store's columns, and uploads the table once: no Python loop over entities.
Only *structural* changes take a per-entity path: an entity seen for the first time, one whose
``Visual`` was added, edited or removed or whose hitbox shape changed (the store stamps its row's
``look`` column; the renderer compares stamps, vectorised), and drawables made or deleted.

Culling: the camera's view box picks the rows to draw. Static bodies come from the static spatial
hash while it is current (``bodies.static_rows_in_box`` over the view), moving bodies (and bodies
without a hitbox) from one vectorised test of their bounds; a sprite's reach beyond its hitbox is
added to the bounds. Drawables that leave the view are hidden (their slot says so), not deleted,
and deleted only after being out of view for a while (or when their entity goes).

Batching: every image is packed into one texture atlas (:mod:`.atlas`), and fills and sprites share
one shader, so each ``Visual.z`` layer is one :class:`pyglet.graphics.Group` drawn with one
multi-draw call, whatever the number of entities, images and animations.

Animations: a sprite's frame is chosen when the frame is shown (:meth:`render`), from the scene's
clock then (``scene.time``), so what is drawn is what ``Visual.frame_at(scene.time)`` says.

Text: entities' :class:`~framework.text.Text` components are pyglet labels (:mod:`.texts`), brought
up to date when the frame is shown: world texts over the sprites with the camera's view, screen
texts (a HUD) over everything but the debug overlay's text.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from pyglet import gl
from pyglet.graphics import Batch
from pyglet.math import Mat4

from ..components import Visual
from ..shapes import Circle
from ..sprites import Animation, Frame
from ..store import KIND_CAPSULE, KIND_POLYGON, STATIC
from ..text import Text
from .atlas import Atlas
from .camera import Camera
from .drawables import fill_outline
from .instances import DISC, DISC_QUAD, FILL, SPRITE, SPRITE_QUAD, InstanceTable, LayerGroup, vertex_list
from .offscreen import OffscreenTarget, offscreen_window, write_png
from .overlay import DebugOverlay
from .texts import TextLabels

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
        #: what the last draw did: visible rows, drawables shown, made, moved; drawables kept
        self.stats: dict[str, int] = {}
        self._batch: Batch | None = None
        self._groups: dict[int, LayerGroup] = {}
        self._atlas = Atlas()
        self._table = InstanceTable()
        self._overlay: DebugOverlay | None = None
        self._texts: TextLabels | None = None  # the labels of the scene's Text components, made on first use
        self._target = OffscreenTarget()  # what capture() draws into
        self._draws = 0  # render stages run (a drawable's last_seen counts in these)
        self._store_version_seen = -1  # the store's version when despawned entities were last looked for
        self._scene_entities = 0
        self._scene: Any = None  # the scene last drawn (its clock picks animation frames)
        self._animations: dict[Animation, int] = {}
        self._animation_list: list[tuple[Animation, np.ndarray]] = []  # (animation, its frames' atlas ids)
        self._forget_entities()

    def _forget_entities(self) -> None:
        """Empty the per-entity and per-slot tables (grown as ids and slots grow)."""
        # Per entity id (grown by _grow_entities):
        self._slot_of = np.full(0, -1, dtype=np.int64)  # its slot, -1 for none
        self._look = np.full(0, -1, dtype=np.int64)  # the store's look stamp when it was last visited
        self._drawable = np.zeros(0, dtype=bool)  # its Visual is visible and has something to draw
        self._sprite_reach = np.zeros(0)  # how far a sprite reaches beyond its entity's bounds
        # Per slot (grown by _grow_slots); the Python lists are touched on structural changes only:
        self._s_entity = np.full(0, -1, dtype=np.int64)
        self._s_fill = np.zeros(0, dtype=bool)  # a filled hitbox (else a sprite)
        self._s_rotates = np.zeros(0, dtype=bool)
        self._s_enabled = np.zeros(0, dtype=bool)  # Visual.visible
        self._s_shown = np.zeros(0, dtype=bool)  # shown by the last draw
        self._s_last_seen = np.zeros(0, dtype=np.int64)
        self._s_frame = np.full(0, -1, dtype=np.int64)  # atlas frame of a still sprite
        self._s_anim = np.full(0, -1, dtype=np.int64)  # animation of an animated sprite
        self._s_started = np.zeros(0)
        self._s_flip = np.zeros(0, dtype=bool)
        self._s_pose = np.full((0, 5), np.nan)  # hx, hy, x, y, rot when last placed
        self._s_redo = np.zeros(0, dtype=bool)  # its table row must be written again (frame, flip, ...)
        self._s_vlist: list[Any] = []
        self._s_shape: list[Any] = []  # the hitbox shape a fill was made from
        self._s_key: list[Any] = []  # (z, colour) the vertex list holds
        self._free: list[int] = []
        self._slots_used = 0  # slots below this have been handed out
        self._atlas_version = self._atlas.version
        self._table = InstanceTable()
        self._animated = _NO_ROWS  # the animated slots the last draw showed
        self._made = 0  # drawables made by this draw

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

    def atlas_texture(self) -> int:
        """The GL texture of the image atlas (uploaded again first if images were added)."""
        return self._atlas.texture_id()

    def table_texture(self) -> int:
        """The GL texture of the slot table (the rows in use uploaded first if they changed)."""
        return self._table.texture_id()

    # --- the render stage -----------------------------------------------------------------

    def draw(self, scene: Any) -> None:
        """The render stage: follow the camera's target, cull, and bring the drawables (and the
        overlay, with ``debug``) up to date with the scene. No GL draw call happens here."""
        previous = self._make_current()
        t0 = time.perf_counter()
        try:
            self._draws += 1
            self._made = 0
            self._scene = scene
            self.camera.update(scene, self.width, self.height)
            bodies = scene.bodies
            bodies.ensure_geometry()
            if bodies.store.version != self._store_version_seen:
                self._forget_despawned(bodies)
                self._store_version_seen = bodies.store.version
            self._visit_changed(scene)
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
        self._grow_entities(int(entities.max()) + 1)
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

    # --- per-entity and per-slot tables -----------------------------------------------------

    def _grow_entities(self, size: int) -> None:
        """Make the per-entity-id tables hold ids below ``size``."""
        have = self._slot_of.shape[0]
        if size <= have:
            return
        new = max(size, 2 * have, 64)
        self._slot_of = _grown(self._slot_of, new, -1)
        self._look = _grown(self._look, new, -1)
        self._drawable = _grown(self._drawable, new, False)
        self._sprite_reach = _grown(self._sprite_reach, new, 0.0)

    def _grow_slots(self, size: int) -> None:
        have = self._s_entity.shape[0]
        if size <= have:
            return
        new = max(size, 2 * have, 64)
        self._s_entity = _grown(self._s_entity, new, -1)
        self._s_fill = _grown(self._s_fill, new, False)
        self._s_rotates = _grown(self._s_rotates, new, False)
        self._s_enabled = _grown(self._s_enabled, new, False)
        self._s_shown = _grown(self._s_shown, new, False)
        self._s_last_seen = _grown(self._s_last_seen, new, 0)
        self._s_frame = _grown(self._s_frame, new, -1)
        self._s_anim = _grown(self._s_anim, new, -1)
        self._s_started = _grown(self._s_started, new, 0.0)
        self._s_flip = _grown(self._s_flip, new, False)
        self._s_pose = _grown(self._s_pose, new, np.nan)
        self._s_redo = _grown(self._s_redo, new, False)
        grow_by = new - len(self._s_vlist)
        self._s_vlist += [None] * grow_by
        self._s_shape += [None] * grow_by
        self._s_key += [None] * grow_by
        self._table.grow(new)

    # --- structural changes: the per-entity path ----------------------------------------------

    def _visit_changed(self, scene: Any) -> None:
        """Visit the entities whose row the store stamped since this renderer last looked (new
        rows, Visuals added, edited or removed, hitbox shapes changed): note whether they have
        something to draw and how far a sprite reaches; bring an existing drawable up to date."""
        store = scene.bodies.store
        if store.n == 0:
            return
        entities = store.entity
        self._grow_entities(int(entities.max()) + 1)
        looks = store.look
        stale = np.flatnonzero(looks != self._look[entities])
        if stale.size == 0:
            return
        hitboxes, kinds = store.hitboxes, store.kind
        for row in stale.tolist():
            entity = int(entities[row])
            visual = scene.try_get(entity, Visual)
            hitbox = hitboxes[row]
            shape = None if hitbox is None else hitbox.shape
            frame = None if visual is None else self._still_frame(entity, visual)
            sprite = visual is not None and (visual.animation is not None or frame is not None)
            drawable = visual is not None and (sprite or shape is not None)
            self._drawable[entity] = drawable and visual.visible  # a hidden Visual gets no new drawable
            if sprite:
                self._note_sprite_reach(entity, visual, frame)
            else:
                self._sprite_reach[entity] = 0.0
            slot = int(self._slot_of[entity])
            if slot >= 0:
                if not drawable:
                    self._free_slot(slot)
                else:
                    self._update_slot(slot, entity, visual, shape, int(kinds[row]), frame)
            self._look[entity] = looks[row]

    def _still_frame(self, entity: int, visual: Visual) -> Frame | None:
        """The frame a Visual shows when it is not animated: its ``frame``, or its whole ``image``."""
        if visual.frame is not None:
            return visual.frame
        if visual.image is None:
            return None
        try:
            return self._atlas.whole(visual.image)
        except ValueError as exc:  # a missing or unreadable image: say which entity and file
            raise ValueError(f"entity {entity}: Visual {exc}") from exc

    def _note_sprite_reach(self, entity: int, visual: Visual, frame: Frame | None) -> None:
        """Half the diagonal of the largest frame the sprite can show: how far beyond its entity's
        bounds it may reach (checked once per change of its Visual)."""
        frames = visual.animation.frames if visual.animation is not None else (frame,)
        try:
            ids = [self._atlas.frame_id(f) for f in frames if f is not None]
        except ValueError as exc:  # a missing or unreadable image, a frame outside its image
            raise ValueError(f"entity {entity}: Visual {exc}") from exc
        sizes = self._atlas.size[ids]
        self._sprite_reach[entity] = 0.5 * float(np.hypot(sizes[:, 0], sizes[:, 1]).max())

    def _animation_id(self, animation: Animation) -> int:
        aid = self._animations.get(animation)
        if aid is None:
            aid = self._animations[animation] = len(self._animation_list)
            ids = np.array([self._atlas.frame_id(f) for f in animation.frames], dtype=np.int64)
            self._animation_list.append((animation, ids))
        return aid

    def _group(self, z: int) -> LayerGroup:
        group = self._groups.get(z)
        if group is None:
            group = self._groups[z] = LayerGroup(z, self)
        return group

    def _new_slot(self) -> int:
        if self._free:
            return self._free.pop()
        slot = self._slots_used
        self._slots_used += 1
        self._grow_slots(self._slots_used)
        self._table.used = self._slots_used
        return slot

    def _make_slot(self, entity: int, visual: Visual, shape: Any, kind: int) -> bool:
        """A new drawable for ``entity`` (``False`` when it has nothing to draw)."""
        frame = self._still_frame(entity, visual)
        if visual.animation is None and frame is None and shape is None:
            return False
        slot = self._new_slot()
        self._s_entity[slot] = entity
        self._s_shown[slot] = False
        self._slot_of[entity] = slot
        self._update_slot(slot, entity, visual, shape, kind, frame, new=True)
        return True

    def _update_slot(self, slot: int, entity: int, visual: Visual, shape: Any, kind: int, frame: Frame | None,
                     new: bool = False) -> None:
        """Bring ``slot`` in line with ``visual`` (and the hitbox ``shape``): its vertex list made
        again only when it changes between fill and sprite or its shape changes; moved to another
        layer, recoloured, or given another frame or animation in place."""
        sprite = visual.animation is not None or frame is not None
        color = visual.color
        group = self._group(visual.z)
        vlist = self._s_vlist[slot]
        remake = new or vlist is None or bool(self._s_fill[slot]) == sprite or (
            not sprite and self._s_shape[slot] is not shape)
        if remake:
            if vlist is not None:
                vlist.delete()
            if sprite:
                local, mode = SPRITE_QUAD, SPRITE
            elif isinstance(shape, Circle):
                local, mode = DISC_QUAD, DISC
                self._table.rows[slot, 2, :2] = shape.radius
            else:
                local, mode = np.asarray(fill_outline(shape, self.camera.zoom), dtype=np.float64).ravel(), FILL
            self._s_vlist[slot] = vertex_list(self._batch, group, local, color, slot, mode)
            self._s_key[slot] = (visual.z, color)
            self._s_pose[slot] = np.nan  # placed again by the next sync
            self._made += 1
        else:
            z, old_color = self._s_key[slot]
            if z != visual.z:
                batch = self._batch
                assert batch is not None  # made by _make_current before any draw
                batch.migrate(vlist, gl.GL_TRIANGLES, group, batch)
            if old_color != color:
                vlist.colors[:] = color * vlist.count
            self._s_key[slot] = (visual.z, color)
        self._s_fill[slot] = not sprite
        self._s_shape[slot] = None if sprite else shape
        self._s_rotates[slot] = sprite or kind in (KIND_POLYGON, KIND_CAPSULE)
        self._s_enabled[slot] = visual.visible
        self._s_flip[slot] = visual.flip_x
        if visual.animation is not None:
            try:
                self._s_anim[slot] = self._animation_id(visual.animation)
            except ValueError as exc:
                raise ValueError(f"entity {entity}: Visual {exc}") from exc
            self._s_started[slot] = visual.started if visual.started is not None else 0.0
            self._s_frame[slot] = -1
        elif frame is not None:
            self._s_anim[slot] = -1
            try:
                self._s_frame[slot] = self._atlas.frame_id(frame)
            except ValueError as exc:
                raise ValueError(f"entity {entity}: Visual {exc}") from exc
        else:
            self._s_anim[slot] = self._s_frame[slot] = -1
        self._s_redo[slot] = True  # its row written again by the next sync (frame, flip, size)

    def _free_slot(self, slot: int) -> None:
        vlist = self._s_vlist[slot]
        if vlist is not None:
            vlist.delete()
        entity = int(self._s_entity[slot])
        if entity >= 0 and entity < self._slot_of.shape[0]:
            self._slot_of[entity] = -1
        self._s_vlist[slot] = self._s_shape[slot] = self._s_key[slot] = None
        self._s_entity[slot] = -1
        self._s_shown[slot] = self._s_enabled[slot] = False
        self._s_anim[slot] = self._s_frame[slot] = -1
        self._table.rows[slot, 2, 2] = 0.0
        self._table.dirty = True
        self._free.append(slot)

    def _forget_despawned(self, bodies: Any) -> None:
        """Delete the drawables of entities that left the scene (no row in the store)."""
        used = np.flatnonzero(self._s_entity[: self._slots_used] >= 0)
        if used.size == 0:
            return
        gone = used[bodies.rows_of(self._s_entity[used]) < 0]
        for slot in gone.tolist():
            entity = int(self._s_entity[slot])
            self._free_slot(slot)
            self._look[entity] = -1  # an id used again is a new entity

    def _delete_long_hidden(self) -> None:
        """Delete drawables that have been out of view for a long time."""
        n = self._slots_used
        oldest = self._draws - DELETE_HIDDEN_AFTER
        old = np.flatnonzero((self._s_entity[:n] >= 0) & ~self._s_shown[:n] & (self._s_last_seen[:n] < oldest))
        for slot in old.tolist():
            self._free_slot(slot)
        self.stats["deleted"] = self.stats.get("deleted", 0) + int(old.size)

    # --- every frame: columns ---------------------------------------------------------------

    def _sync(self, scene: Any, rows: np.ndarray) -> None:
        """Make drawables for visible entities that have none; write the table rows of every
        visible drawable (pose, frame, size) from the store's columns; hide the rest."""
        store = scene.bodies.store
        entities = store.entity[rows]
        slots = self._slot_of[entities]
        need = np.flatnonzero((slots < 0) & self._drawable[entities])
        if need.size:
            hitboxes, kinds = store.hitboxes, store.kind
            for i in need.tolist():
                row, entity = int(rows[i]), int(entities[i])
                visual = scene.try_get(entity, Visual)
                hitbox = hitboxes[row]
                if visual is not None and self._make_slot(entity, visual, None if hitbox is None else hitbox.shape,
                                                          int(kinds[row])):
                    slots[i] = self._slot_of[entity]
        made = self._made
        n = self._slots_used
        self._grow_slots(n)
        has = slots >= 0
        show = has.copy()
        show[has] = self._s_enabled[slots[has]]
        vis_rows, vis = rows[show], slots[show]
        now_shown = np.zeros(n, dtype=bool)
        now_shown[vis] = True
        table = self._table.rows
        hide = np.flatnonzero(self._s_shown[:n] & ~now_shown)
        if hide.size:
            table[hide, 2, 2] = 0.0
        was_shown = self._s_shown[vis]
        self._s_shown[:n] = now_shown
        self._s_last_seen[vis] = self._draws
        geometry = scene.bodies.ensure_geometry()
        poses = np.stack([geometry.hx[vis_rows], geometry.hy[vis_rows], store.x[vis_rows], store.y[vis_rows],
                          store.rot[vis_rows]], axis=1)
        moved = ~(poses == self._s_pose[vis]).all(axis=1) | ~was_shown
        self._s_pose[vis] = poses
        write = moved | self._s_redo[vis]
        self._s_redo[vis] = False
        if self._atlas.version != self._atlas_version:  # a re-pack moved every frame in the atlas
            write[:] = True
            self._atlas_version = self._atlas.version
        if write.any():
            m, ms = poses[write], vis[write]
            fill = self._s_fill[ms]
            rot = np.where(self._s_rotates[ms], m[:, 4], 0.0)
            table[ms, 0, 0] = np.where(fill, m[:, 0], m[:, 2])
            table[ms, 0, 1] = np.where(fill, m[:, 1], m[:, 3])
            table[ms, 0, 2] = np.cos(rot)
            table[ms, 0, 3] = np.sin(rot)
            table[ms, 2, 2] = 1.0
            still = ms[~fill & (self._s_frame[ms] >= 0)]
            if still.size:
                self._write_frames(still, self._s_frame[still])
            self._table.dirty = True
        self._animated = vis[self._s_anim[vis] >= 0]
        self.stats = {"visible_rows": int(rows.size), "drawn": int(vis.size), "made": made,
                      "moved": int(moved.sum()), "drawables": int((self._s_entity[:n] >= 0).sum()),
                      "animated": int(self._animated.size)}

    def _write_frames(self, slots: np.ndarray, frames: np.ndarray) -> None:
        """Write the atlas rectangle (mirrored where flipped) and size of ``frames`` into ``slots``' rows."""
        table = self._table.rows
        uv = self._atlas.uv[frames]
        flip = self._s_flip[slots]
        if flip.any():
            uv[flip] = uv[flip][:, [2, 1, 0, 3]]
        table[slots, 1] = uv
        table[slots, 2, :2] = self._atlas.size[frames]
        self._table.dirty = True

    def _animate(self) -> None:
        """Pick each shown animated sprite's frame at the scene's clock (``scene.time``)."""
        slots = self._animated
        if slots.size == 0 or self._scene is None:
            return
        elapsed = float(self._scene.time) - self._s_started[slots]
        anims = self._s_anim[slots]
        frames = np.empty(slots.size, dtype=np.int64)
        for aid in np.unique(anims).tolist():
            pick = anims == aid
            animation, ids = self._animation_list[aid]
            frames[pick] = ids[animation.indices_at(elapsed[pick])]
        self._write_frames(slots, frames)

    # --- GL: showing a frame ------------------------------------------------------------------

    def render(self, window: Any = None) -> None:
        """Issue the GL draw calls of the last :meth:`draw` into the bound framebuffer, with the
        projection of a ``width`` x ``height`` viewport (the caller sets ``glViewport``).

        ``window``: whose ``projection`` / ``view`` (pyglet's WindowBlock) to set; default the
        renderer's own window."""
        previous = self._make_current()
        win = window if window is not None else self.window
        try:
            self._animate()
            win.projection = Mat4.orthogonal_projection(0.0, float(self.width), 0.0, float(self.height),
                                                        -8192.0, 8192.0)
            win.view = Mat4(*self.camera.matrix())
            assert self._batch is not None
            self._batch.draw()
            texts = self._sync_texts()
            if texts is not None:
                texts.draw_world()
            if self.debug and self._overlay is not None:
                self._overlay.draw_world()
            win.view = Mat4()
            if texts is not None:
                texts.draw_screen()
            if self.debug and self._overlay is not None:
                self._overlay.draw_hud(self)
        finally:
            self._restore(previous)

    def _sync_texts(self) -> TextLabels | None:
        """The labels of the last drawn scene's Text components, brought up to date now (what a
        game wrote since the last step shows too); ``None`` while the scene has none."""
        scene = self._scene
        if scene is None:
            return self._texts
        if self._texts is None:
            if not scene.query(Text):
                return None
            self._texts = TextLabels()
        self._texts.sync(scene, self.width, self.height)
        return self._texts

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
        if self._slots_used or self._overlay is not None or self._texts is not None:
            previous = self._make_current()
            try:
                for vlist in self._s_vlist:
                    if vlist is not None:
                        vlist.delete()
                self._table.delete()
                if self._texts is not None:
                    self._texts.delete()
            finally:
                self._restore(previous)
        self._forget_entities()
        self._store_version_seen = -1

    def close(self) -> None:
        """Delete the renderer's GL objects (drawables, atlas, overlay buffers, offscreen target)."""
        if self.window is None:
            return
        self.reset()
        previous = self._make_current()
        try:
            if self._overlay is not None:
                self._overlay.delete()
                self._overlay = None
            self._atlas.delete()
            self._target.delete()
            self._batch = None
        finally:
            self._restore(previous)

    @property
    def scene_entities(self) -> int:
        """Entities with a Transform in the scene at the last draw."""
        return self._scene_entities


def _grown(array: np.ndarray, size: int, fill: Any) -> np.ndarray:
    """``array`` grown along its first axis to ``size``, new entries ``fill``."""
    out = np.full((size, *array.shape[1:]), fill, dtype=array.dtype)
    out[: array.shape[0]] = array
    return out
