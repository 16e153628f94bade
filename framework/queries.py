"""Spatial queries over a scene's hitboxes: rays, shape casts, boxes, points and shapes.

Candidates come from one compiled pass over the hitboxes' bounds (the static hash and a vectorised
bounds test in scenes of more than :data:`~framework.collision.broad_phase.DIRECT_QUERY` rows);
the exact answer from the collision functions of :mod:`framework.collision`. Rays
cast during a step are logged in the step's frame for the debug overlay.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from .casting import ShapeHit, cast_rows, shape_bounds, touch_point
from .collision import batch, collide
from .collision.box_rows import rows_meeting
from .collision.broad_phase import DIRECT_QUERY
from .collision.distance import Distance, point_distance
from .collision.distance import distance as shape_distance
from .collision.placement import check_shape
from .collision.ray import closest_on_segment
from .collision.ray import raycast as _raycast
from .collision.results import Vec2
from .shapes import AABB, Capsule, Circle
from .store import STATIC
from .systems.stage import Pipeline
from .validation import InvalidValue, finite, vector2

__all__ = ["ALL_LAYERS", "Nearest", "SceneHit", "ShapeHit", "SpatialQueries"]

ALL_LAYERS = 0xFFFFFFFF


class SceneHit(NamedTuple):
    """A scene raycast hit: the entity, and where and how the ray entered its hitbox."""

    entity: int
    distance: float
    point: Vec2
    normal: Vec2


class Nearest(NamedTuple):
    """The hitbox nearest a point: its entity, how far it is (0: the point is inside or on it) and
    its point nearest the given one."""

    entity: int
    distance: float
    point: Vec2


class SpatialQueries:
    """The queries of one scene (``Scene.raycast``, ``query_box``...), over its pipeline's bodies."""

    def __init__(self, pipeline: Pipeline) -> None:
        self.pipeline = pipeline
        self.bodies = pipeline.bodies

    def _candidate_rows(self, minx: float, miny: float, maxx: float, maxy: float) -> NDArray[np.intp]:
        """Rows whose current bounds strictly meet the box: one compiled pass over the bounds, or,
        in scenes of more rows than :data:`DIRECT_QUERY`, statics via the hash and moving bodies
        by one vectorised test over their current bounds."""
        bodies = self.bodies
        store = bodies.store
        geom = bodies.ensure_geometry()
        self.pipeline.frame.counters["rehashed"] = (self.pipeline.frame.counters.get("rehashed", 0)
                                                    + bodies.sync_static())
        if store.n <= DIRECT_QUERY:  # one compiled pass over every row's bounds (the same rows)
            found: NDArray[np.intp] = rows_meeting(store.kind, geom.minx, geom.miny, geom.maxx, geom.maxy, float(minx),
                                                   float(miny), float(maxx), float(maxy))
            return found
        st = bodies.static_rows_in_box(minx, miny, maxx, maxy)
        mv = np.flatnonzero((store.kind >= 0) & (store.body != STATIC))
        hit = (geom.minx[mv] < maxx) & (geom.maxx[mv] > minx) & (geom.miny[mv] < maxy) & (geom.maxy[mv] > miny)
        return np.concatenate([st, mv[hit]])

    def _mask_ok(self, rows: NDArray[np.intp], mask: int) -> NDArray[np.intp]:
        keep: NDArray[np.bool_] = (self.bodies.store.layer[rows] & mask) != 0  # (numpy types `!=` as Any)
        return rows[keep]

    def raycast_all(self, origin: tuple[float, float], direction: tuple[float, float],
                    max_distance: float = math.inf, mask: int = ALL_LAYERS) -> list[SceneHit]:
        """Every hitbox the ray enters within ``max_distance``, nearest first (ties by entity)."""
        ox, oy = vector2("origin", origin)
        dx, dy = vector2("direction", direction)
        if dx == 0.0 and dy == 0.0:
            raise InvalidValue(f"direction must not be zero, got {direction!r}")
        md = float(max_distance) if not isinstance(max_distance, bool) else math.nan
        if not md >= 0.0:
            raise InvalidValue(f"max_distance must be >= 0, got {max_distance!r}")
        ln = math.hypot(dx, dy)
        reach = md if math.isfinite(md) else self._world_extent(ox, oy)
        ex, ey = ox + dx / ln * reach, oy + dy / ln * reach
        rows = self._candidate_rows(min(ox, ex) - 1e-9, min(oy, ey) - 1e-9, max(ox, ex) + 1e-9,
                                    max(oy, ey) + 1e-9)
        rows = self._mask_ok(rows, mask)
        hits = []
        geom, store = self.bodies.geometry, self.bodies.store
        for r in rows.tolist():
            hb = store.hitboxes[r]
            hit = _raycast(hb.shape, (float(geom.hx[r]), float(geom.hy[r]), float(store.rot[r])),
                           (ox, oy), (dx, dy), md)
            if hit is not None:
                hits.append(SceneHit(int(store.entity[r]), *hit))
        hits.sort(key=lambda h: (h.distance, h.entity))
        self.pipeline.frame.ray_log.append(((ox, oy), (ex, ey), hits[0] if hits else None))
        return hits

    def shape_cast(self, shape: Any, start: tuple[float, float], end: tuple[float, float], rotation: float = 0.0,
                   mask: int = ALL_LAYERS, ignore: Iterable[int] = ()) -> ShapeHit | None:
        """The first hitbox ``shape`` would enter moving (without turning) from ``start`` to
        ``end`` (its hitbox origin's positions), or ``None``; sensors and the ``ignore``-d
        entities are passed through (see :mod:`framework.casting`)."""
        check_shape("shape", shape)
        x0, y0 = vector2("start", start)
        x1, y1 = vector2("end", end)
        rot = finite("rotation", rotation)
        skip_entities = np.array(sorted({int(e) for e in ignore}), dtype=np.int64)
        mx, my = x1 - x0, y1 - y0
        if not (math.isfinite(mx) and math.isfinite(my)):
            raise InvalidValue(f"the motion from {start!r} to {end!r} is too long for floats")
        store = self.bodies.store

        def skip(rows: NDArray[np.intp]) -> NDArray[np.bool_]:
            return ~np.isin(store.entity[rows], skip_entities)

        hit = cast_rows(self, shape, x0, y0, rot, mx, my, mask=mask, skip=skip if skip_entities.size else None)
        if hit is None:
            return None
        r, fraction, nx, ny = hit
        geom = self.bodies.geometry
        pose_b = (float(geom.hx[r]), float(geom.hy[r]), float(store.rot[r]))
        entity = int(store.entity[r])
        if fraction == 0.0:
            # (a row hit has a hitbox)
            contact = collide(shape, (x0, y0, rot), store.hitboxes[r].shape, pose_b)  # type: ignore[union-attr]
            if contact is not None:
                return ShapeHit(entity, 0.0, contact.point, Vec2(nx, ny))
        at = (x0 + mx * fraction, y0 + my * fraction, rot)
        other = store.hitboxes[r].shape  # type: ignore[union-attr]  # (a row hit has a hitbox)
        return ShapeHit(entity, fraction, touch_point(shape, at, other, pose_b, -nx, -ny), Vec2(nx, ny))

    def _world_extent(self, ox: float, oy: float) -> float:
        g = self.bodies.ensure_geometry()
        if self.bodies.store.n == 0:
            return 1.0
        far = max(abs(float(g.minx.min()) - ox), abs(float(g.maxx.max()) - ox),
                  abs(float(g.miny.min()) - oy), abs(float(g.maxy.max()) - oy))
        return 2.0 * far + 1.0

    def query_box(self, minx: float, miny: float, maxx: float, maxy: float, mask: int = ALL_LAYERS) -> list[int]:
        """Entities whose hitbox interiors overlap the box's interior, sorted."""
        x0, y0, x1, y1 = (finite(n, v) for n, v in zip(("minx", "miny", "maxx", "maxy"), (minx, miny, maxx, maxy)))
        if not (x1 > x0 and y1 > y0):
            raise InvalidValue(f"query_box needs maxx > minx and maxy > miny, got {(minx, miny, maxx, maxy)!r}")
        box = AABB(x1 - x0, y1 - y0)
        return self._overlapping(box, ((x0 + x1) * 0.5, (y0 + y1) * 0.5), mask, (x0, y0, x1, y1))

    def query_point(self, x: float, y: float, mask: int = ALL_LAYERS) -> list[int]:
        """Entities whose hitbox contains the point (closed: a point on the boundary counts)."""
        px, py = finite("x", x), finite("y", y)
        rows = self._mask_ok(self._candidate_rows(px - 1e-9, py - 1e-9, px + 1e-9, py + 1e-9), mask)
        return sorted(int(self.bodies.store.entity[r]) for r in rows.tolist() if self._contains(r, px, py))

    def query_shape(self, shape: Any, position: tuple[float, float], rotation: float = 0.0,
                    mask: int = ALL_LAYERS) -> list[int]:
        """Entities whose hitbox interiors overlap ``shape``'s at ``position`` (its hitbox origin),
        turned by ``rotation``, sorted (touching does not count, as in the collision contract)."""
        check_shape("shape", shape)
        x, y = vector2("position", position)
        rot = finite("rotation", rotation)
        return self._overlapping(shape, (x, y, rot), mask, shape_bounds(shape, x, y, rot))

    def nearest(self, point: tuple[float, float], max_distance: float = math.inf,
                mask: int = ALL_LAYERS) -> Nearest | None:
        """The hitbox nearest ``point`` within ``max_distance`` (0 if the point is inside one), or
        None; ties go to the lower entity id."""
        px, py = vector2("point", point)
        md = float(max_distance) if not isinstance(max_distance, bool) else math.nan
        if not md >= 0.0:
            raise InvalidValue(f"max_distance must be >= 0, got {max_distance!r}")
        store = self.bodies.store
        geom = self.bodies.ensure_geometry()
        if math.isfinite(md):
            rows = self._candidate_rows(px - md - 1e-9, py - md - 1e-9, px + md + 1e-9, py + md + 1e-9)
        else:
            self.bodies.sync_static()
            rows = np.flatnonzero(store.kind >= 0)
        best: Nearest | None = None
        for r in self._mask_ok(rows, mask).tolist():
            hb = store.hitboxes[r]
            assert hb is not None  # (rows with a kind have a hitbox)
            d, at = point_distance(hb.shape, float(geom.hx[r]), float(geom.hy[r]), float(store.rot[r]), px, py)
            e = int(store.entity[r])
            if d <= md and (best is None or (d, e) < (best.distance, best.entity)):
                best = Nearest(e, d, at)
        return best

    def distance(self, entity_a: int, entity_b: int) -> Distance:
        """How far entity B's hitbox is from entity A's, and their closest points
        (:func:`~framework.collision.distance.distance`)."""
        store = self.bodies.store
        geom = self.bodies.ensure_geometry()
        poses = []
        for name, e in (("entity_a", entity_a), ("entity_b", entity_b)):
            r = store.row_of.get(e) if isinstance(e, int) and not isinstance(e, bool) else None
            hb = store.hitboxes[r] if r is not None else None
            if hb is None:
                raise InvalidValue(f"{name} must be an entity with a Hitbox, got {e!r}")
            poses.append((hb.shape, (float(geom.hx[r]), float(geom.hy[r]), float(store.rot[r]))))
        (sa, pa), (sb, pb) = poses
        return shape_distance(sa, pa, sb, pb)

    def _contains(self, r: int, px: float, py: float) -> bool:
        store, geom = self.bodies.store, self.bodies.geometry
        hb = store.hitboxes[r]
        assert hb is not None  # (candidates have hitboxes)
        dx, dy = px - float(geom.hx[r]), py - float(geom.hy[r])
        shape = hb.shape
        if isinstance(shape, Circle):
            return dx * dx + dy * dy <= shape.radius * shape.radius
        if isinstance(shape, Capsule):  # within the radius of its segment
            ux, uy = float(geom.cap_ux[r]), float(geom.cap_uy[r])
            cx, cy = closest_on_segment(dx, dy, -ux, -uy, ux, uy)
            return (dx - cx) ** 2 + (dy - cy) ** 2 <= shape.radius * shape.radius
        verts, count = geom.outlines(store, np.array([r]))
        pts = verts[0, : int(count[0])]
        if len(pts) == 2:  # a segment: the point on it, between its ends
            (x0, y0), (x1, y1) = pts
            along = (x1 - x0) * (dx - x0) + (y1 - y0) * (dy - y0)
            if not 0.0 <= along <= (x1 - x0) ** 2 + (y1 - y0) ** 2:
                return False
        for i in range(len(pts)):
            x0, y0 = pts[i]
            x1, y1 = pts[(i + 1) % len(pts)]
            if (x1 - x0) * (dy - y0) - (y1 - y0) * (dx - x0) < 0.0:
                return False
        return True

    def _overlapping(self, shape: Any, center: tuple[float, float] | tuple[float, float, float], mask: int,
                     box: tuple[float, float, float, float]) -> list[int]:
        rows = self._mask_ok(self._candidate_rows(*box), mask)
        store, geom = self.bodies.store, self.bodies.geometry
        check_shape("shape", shape)
        if rows.size == 0:
            return []
        shapes_b = [store.hitboxes[r].shape for r in rows.tolist()]
        poses_b = list(zip(geom.hx[rows].tolist(), geom.hy[rows].tolist(), store.rot[rows].tolist()))
        res = batch.collide_many([shape] * rows.size, [center] * rows.size, shapes_b, poses_b)
        return sorted(int(e) for e in store.entity[rows[res.hit]])
