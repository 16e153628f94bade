"""Spatial queries over a scene's hitboxes: rays, shape casts, boxes, points and shapes.

Candidates come from one compiled pass over the hitboxes' bounds (the static hash and a vectorised
bounds test in scenes of more than :data:`~framework.collision.broad_phase.DIRECT_QUERY` rows);
the exact answer from the collision functions of :mod:`framework.collision`. Rays
cast during a step are logged in the step's frame for the debug overlay.

The batch forms (:meth:`SpatialQueries.query_points`, :meth:`~SpatialQueries.nearest_many`,
:meth:`~SpatialQueries.raycast_many`) answer many points or rays in one compiled pass
(:mod:`framework.collision.batch_queries`) with the same answers, float for float, as the single
queries asked one by one; batched rays are not logged for the overlay.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from .casting import ShapeHit, cast_rows, shape_bounds, touch_point
from .collision import batch, collide, time_of_impact
from .collision import batch_queries as bq
from .collision.box_rows import rows_meeting, rows_near, rows_within
from .collision.broad_phase import DIRECT_QUERY
from .collision.distance import Distance, point_distance
from .collision.distance import distance as shape_distance
from .collision.placement import check_shape
from .collision.ray import closest_on_segment
from .collision.ray import raycast as _raycast
from .collision.results import Vec2
from .geometry import Geometry
from .shapes import AABB, Capsule, Circle, Polygon, Segment
from .store import STATIC, BodyStore
from .systems.stage import Pipeline
from .validation import InvalidValue, finite, vector2

__all__ = ["ALL_LAYERS", "Nearest", "NearestMany", "PointHits", "RayHits", "SceneHit", "ShapeHit", "SpatialQueries"]

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


class PointHits(NamedTuple):
    """Which entities hold each of ``n`` points (:meth:`SpatialQueries.query_points`), as two
    arrays: point ``i``'s entities, sorted, are ``entities[offsets[i]:offsets[i + 1]]``
    (``offsets`` has ``n + 1`` entries, the first 0). ``counts`` and :meth:`of` read them."""

    offsets: NDArray[np.int64]
    entities: NDArray[np.int64]

    @property
    def counts(self) -> NDArray[np.int64]:
        """How many entities hold each point, ``(n,)``."""
        return np.diff(self.offsets)

    def of(self, i: int) -> list[int]:
        """The entities holding point ``i``, sorted: ``query_point`` of that point."""
        found: list[int] = self.entities[self.offsets[i]:self.offsets[i + 1]].tolist()
        return found


class NearestMany(NamedTuple):
    """The hitbox nearest each of ``n`` points (:meth:`SpatialQueries.nearest_many`): ``entity``
    ``(n,)`` (-1 where none is within ``max_distance``), ``distance`` ``(n,)`` (0 inside; -1
    where none is: the contract's queries never answer inf) and ``point`` ``(n, 2)``, the
    hitbox's point nearest (the query point itself where none is). Row ``i`` is
    ``nearest(points[i])``, float for float."""

    entity: NDArray[np.int64]
    distance: NDArray[np.float64]
    point: NDArray[np.float64]


class RayHits(NamedTuple):
    """Where each of ``n`` rays first enters a hitbox (:meth:`SpatialQueries.raycast_many`):
    ``entity`` ``(n,)`` (-1 for a miss), ``distance`` ``(n,)`` (-1 for a miss), ``point`` and
    ``normal`` ``(n, 2)`` (zeros for a miss). Row ``i`` is ``raycast(origins[i], directions[i])``,
    float for float."""

    entity: NDArray[np.int64]
    distance: NDArray[np.float64]
    point: NDArray[np.float64]
    normal: NDArray[np.float64]


def _xy_rows(name: str, value: object) -> NDArray[np.float64]:
    """``value`` as an ``(n, 2)`` float64 array of finite values (a copy), or :class:`InvalidValue`
    naming the bad row."""
    try:
        a = np.asarray(value)
    except (TypeError, ValueError):
        raise InvalidValue(f"{name} must be an (n, 2) array of numbers, got {value!r}") from None
    if a.size == 0 and a.ndim <= 2 and (a.ndim < 2 or a.shape[1] in (0, 2)):
        return np.zeros((0, 2))
    if a.dtype.kind not in "iuf":
        raise InvalidValue(f"{name} must be an (n, 2) array of real numbers, got dtype {a.dtype} ({value!r:.80})")
    if a.ndim != 2 or a.shape[1] != 2:
        raise InvalidValue(f"{name} must be an (n, 2) array of x, y rows, got shape {a.shape}")
    out = a.astype(np.float64)
    bad = np.flatnonzero(~np.isfinite(out).all(axis=1))
    if bad.size:
        i = int(bad[0])
        raise InvalidValue(f"{name}[{i}] must be finite, got {tuple(a[i].tolist())!r}")
    return out


def _mask_value(mask: object) -> np.int64:
    if isinstance(mask, bool) or not isinstance(mask, (int, np.integer)) or not -2**63 <= int(mask) < 2**63:
        raise InvalidValue(f"mask must be an int of 64 bits, got {mask!r}")
    return np.int64(mask)


def _max_distance(max_distance: object) -> float:
    """As the single queries take it: a real >= 0 (inf allowed), else :class:`InvalidValue`."""
    md = float(max_distance) if isinstance(max_distance, (int, float, np.floating, np.integer)) and not isinstance(
        max_distance, bool) else math.nan
    if not md >= 0.0:
        raise InvalidValue(f"max_distance must be >= 0, got {max_distance!r}")
    return md


class _Shapes(NamedTuple):
    """The hitboxes' shapes as columns for the batch kernels (framework.collision.batch_queries):
    the kind of each row's live shape (-1: none), ``sa, sb`` (an AABB's half width and height, a
    circle's radius, a capsule's radius and length), ``ext`` (the ray cast's local scale,
    :func:`~framework.collision.ray.extent`), a polygon's points (``local``, ``cnt``)."""

    kind: NDArray[np.int8]
    sa: NDArray[np.float64]
    sb: NDArray[np.float64]
    ext: NDArray[np.float64]
    local: NDArray[np.float64]
    cnt: NDArray[np.int64]


def _shape_table(shapes: list[Any]) -> _Shapes:
    """Shapes (None: a row without a hitbox) as the batch kernels' columns: kind (0 box, 1 circle,
    2 polygon, 3 capsule, 4 segment, -1 none), the box's half sizes, a circle's or capsule's radius
    (and a capsule's length), the extent, and a polygon's or segment's points."""
    table = _empty_table(len(shapes), max([4] + [len(s.points) for s in shapes if isinstance(s, Polygon)]))
    for r, shape in enumerate(shapes):
        _fill_row(table, r, shape)
    return table


def _empty_table(n: int, k: int) -> _Shapes:
    """A table of ``n`` rows without shapes, room for ``k`` points a row."""
    return _Shapes(np.full(n, -1, dtype=np.int8), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros((n, k, 2)),
                   np.zeros(n, dtype=np.int64))


def _fill_row(table: _Shapes, r: int, shape: Any) -> None:
    """Row ``r`` of ``table``: ``shape``'s columns (see :func:`_shape_table`; None leaves it empty)."""
    kind, sa, sb, ext, local, cnt = table
    if isinstance(shape, AABB):
        kind[r], sa[r], sb[r], ext[r] = 0, shape.half_width, shape.half_height, max(shape.width, shape.height)
    elif isinstance(shape, Circle):
        kind[r], sa[r], ext[r] = 1, shape.radius, shape.radius
    elif isinstance(shape, Capsule):
        kind[r], sa[r], sb[r], ext[r] = 3, shape.radius, shape.length, shape.bounding_radius
    elif isinstance(shape, Polygon):
        kind[r], cnt[r] = 2, len(shape.points)
        local[r, : cnt[r]] = shape.points
        ext[r] = max(max(abs(x), abs(y)) for x, y in shape.points)
    elif isinstance(shape, Segment):  # (its two ends; a chain segment's one side: rays ask raycast)
        kind[r], cnt[r] = 4, 2
        local[r, :2] = (shape.a, shape.b)
        ext[r] = max(abs(shape.a[0]), abs(shape.a[1]), abs(shape.b[0]), abs(shape.b[1]))


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
        geom = self._synced_geometry()
        if store.n <= DIRECT_QUERY:  # one compiled pass over every row's bounds (the same rows)
            found: NDArray[np.intp] = rows_meeting(store.kind, geom.minx, geom.miny, geom.maxx, geom.maxy, float(minx),
                                                   float(miny), float(maxx), float(maxy))
            return found
        st = bodies.static_rows_in_box(minx, miny, maxx, maxy)
        mv = np.flatnonzero((store.kind >= 0) & (store.body != STATIC))
        hit = (geom.minx[mv] < maxx) & (geom.maxx[mv] > minx) & (geom.miny[mv] < maxy) & (geom.maxy[mv] > miny)
        return np.concatenate([st, mv[hit]])

    def _blocking_rows(self, box: tuple[float, float, float, float], mask: int, skip_rows: NDArray[np.int64],
                       skip_entities: NDArray[np.int64]) -> NDArray[np.intp]:
        """:meth:`_candidate_rows` of ``box`` that block a body of ``mask`` (their layer meets it, not
        sensors; ``mask < 0``: no such test) and are in neither sorted list, in their order (the
        character controller's candidates): where the rows are few enough for a pass, the look-up
        and the filter in one (:func:`~framework.collision.box_rows.rows_near`)."""
        store = self.bodies.store
        c = store.cols
        if store.n <= DIRECT_QUERY and mask >= 0:
            geom = self._synced_geometry()
            near: NDArray[np.intp] = rows_near(store.kind, geom.minx, geom.miny, geom.maxx, geom.maxy, float(box[0]),
                                               float(box[1]), float(box[2]), float(box[3]), c["layer"], c["sensor"],
                                               mask, skip_rows, c["entity"], skip_entities)
            return near
        rows = self._candidate_rows(*box)
        geom = self.bodies.geometry
        found: NDArray[np.intp] = rows_within(rows, geom.minx, geom.miny, geom.maxx, geom.maxy, *box, c["layer"],
                                              c["sensor"], mask, skip_rows, c["entity"], skip_entities)
        return found

    def _synced_geometry(self) -> Geometry:
        """The geometry, current, with the static hash brought up to date (counted in the frame's
        ``rehashed``): what every look-up of candidate rows starts from."""
        bodies = self.bodies
        geom = bodies.ensure_geometry()
        counters = self.pipeline.frame.counters
        counters["rehashed"] = counters.get("rehashed", 0) + bodies.sync_static()
        return geom

    def _parts(self, mask: int) -> list[tuple[int, Any, tuple[float, float, float]]]:
        """The other shapes of the compound bodies (:class:`~framework.components.Parts`) whose
        layer meets ``mask``: ``(entity, part hitbox, its pose (x, y, rotation))``, by entity then
        part. A query answers a body's parts as its Hitbox, by its entity; compound bodies are few,
        so their parts are tested one by one, without the broad phase."""
        store = self.bodies.store
        out = []
        for e, parts in sorted(store.parts.items()):
            r = store.row_of[e]
            if store.hitboxes[r] is None:  # (refused by the step: not a body)
                continue
            x, y, rot = float(store.x[r]), float(store.y[r]), float(store.rot[r])
            c, s = math.cos(rot), math.sin(rot)
            for hb in parts.hitboxes:
                if hb.layer & mask:
                    ox, oy = hb.offset
                    out.append((e, hb, (x + c * ox - s * oy, y + s * ox + c * oy, rot)))
        return out

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
        if rows.size:  # one compiled pass (the float path of raycast, the same bits); raycast itself
            # for what it leaves to exact arithmetic (a graze, a corner) and for capsules
            cols, at = self._shapes_of(rows)
            found = bq.ray_rows(np.ascontiguousarray(rows, dtype=np.int64), at, ox, oy, dx, dy, md, cols.kind, cols.sa,
                                cols.sb, cols.ext, cols.local, cols.cnt, geom.hx, geom.hy, store.rot)
            for r, (status, dist, px, py, nx, ny) in zip(rows.tolist(), found.tolist()):
                if status > 0.0:
                    hits.append(SceneHit(int(store.entity[r]), dist, Vec2(px, py), Vec2(nx, ny)))
                elif status < 0.0:
                    hb = store.hitboxes[r]
                    hit = _raycast(hb.shape, (float(geom.hx[r]), float(geom.hy[r]), float(store.rot[r])),
                                   (ox, oy), (dx, dy), md)
                    if hit is not None:
                        hits.append(SceneHit(int(store.entity[r]), *hit))
        if store.parts:  # a compound body: where the ray first enters any of its shapes
            for e, part, pose in self._parts(int(mask)):
                hit = _raycast(part.shape, pose, (ox, oy), (dx, dy), md)
                if hit is not None:
                    hits.append(SceneHit(e, *hit))
            first: dict[int, SceneHit] = {}
            for h in sorted(hits, key=lambda h: h.distance):
                first.setdefault(h.entity, h)
            hits = list(first.values())
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
        if store.parts:
            part_hit = self._cast_parts(shape, x0, y0, rot, mx, my, int(mask), set(skip_entities.tolist()))
            if part_hit is not None and (hit is None or (part_hit.fraction, part_hit.entity)
                                         < (hit[1], int(store.entity[hit[0]]))):
                return part_hit
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

    def _cast_parts(self, shape: Any, x0: float, y0: float, rot: float, mx: float, my: float, mask: int,
                    skip: set[int]) -> ShapeHit | None:
        """The first part of a compound body ``shape`` would enter (sensors and ``skip``-ped
        entities passed through), as :meth:`shape_cast` answers; by time of impact, then entity."""
        best: ShapeHit | None = None
        for e, part, pose in self._parts(mask):
            if part.sensor or e in skip:
                continue
            impact = time_of_impact(shape, (x0, y0, rot), (mx, my), part.shape, pose)
            if impact is None or (best is not None and (impact.fraction, e) >= (best.fraction, best.entity)):
                continue
            nx, ny = -impact.normal.x + 0.0, -impact.normal.y + 0.0  # (facing the cast shape)
            if impact.fraction == 0.0:
                contact = collide(shape, (x0, y0, rot), part.shape, pose)
                if contact is not None:
                    best = ShapeHit(e, 0.0, contact.point, Vec2(nx, ny))
                    continue
            at = (x0 + mx * impact.fraction, y0 + my * impact.fraction, rot)
            best = ShapeHit(e, impact.fraction, touch_point(shape, at, part.shape, pose, -nx, -ny), Vec2(nx, ny))
        return best

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
        found = {int(self.bodies.store.entity[r]) for r in rows.tolist() if self._contains(r, px, py)}
        if self.bodies.store.parts:
            found |= {e for e, part, pose in self._parts(int(mask))
                      if point_distance(part.shape, *pose, px, py)[0] == 0.0}
        return sorted(found)

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
        for e, part, pose in self._parts(int(mask)) if store.parts else ():
            d, at = point_distance(part.shape, *pose, px, py)
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
        if not store.parts or not ({entity_a, entity_b} & store.parts.keys()):
            return shape_distance(sa, pa, sb, pb)
        # a compound body: the nearest of its shapes (the first of equals, Hitbox first)
        shapes = self._parts(ALL_LAYERS)
        of_a = [(sa, pa)] + [(p.shape, pose) for e, p, pose in shapes if e == entity_a]
        of_b = [(sb, pb)] + [(p.shape, pose) for e, p, pose in shapes if e == entity_b]
        best: Distance | None = None
        for shape_a, pose_a in of_a:
            for shape_b, pose_b in of_b:
                d = shape_distance(shape_a, pose_a, shape_b, pose_b)
                if best is None or d.distance < best.distance:
                    best = d
        assert best is not None
        return best

    # --- many at once (framework.collision.batch_queries) -------------------------------------

    def _shapes(self) -> _Shapes:
        """The live shapes as columns, cached until a structural change (rebuilt while a hitbox
        edit waits for the next step, as the single queries read the edited shape at once)."""
        cols = self._cached_shapes()
        if cols is None:
            store = self.bodies.store
            cols = _shape_table([None if hb is None else hb.shape for hb in store.hitboxes[: store.n]])
            self._shape_cols = (store, store.version, cols)
        return cols

    def _shapes_of(self, rows: NDArray[np.intp]) -> tuple[_Shapes, NDArray[np.int64]]:
        """The live shapes of ``rows`` as columns, and where each row is in them: the scene's table
        when it is current; else, with no hitbox edit waiting, a table of the scene's rows kept until
        its next structural change and filled row by row as queries ask for rows (a game's rays each
        step: a table of their few rows made afresh for each ray cost more than the cast); with an
        edit waiting, a table of these rows alone (a query after a spawn or a hitbox edit does not
        measure every hitbox of the scene again)."""
        cols = self._cached_shapes()
        at = np.ascontiguousarray(rows, dtype=np.int64)
        if cols is not None:
            return cols, at
        store = self.bodies.store
        hitboxes = store.hitboxes
        if store.dirty_hitboxes:
            return _shape_table([hitboxes[r].shape for r in rows.tolist()]), np.arange(rows.size)
        k = self.bodies.ensure_geometry().K  # (the most points of a polygon in the scene, at least 4)
        kept: tuple[BodyStore, int, _Shapes, NDArray[np.bool_]] | None = getattr(self, "_row_shapes", None)
        if (kept is None or kept[0] is not store or kept[1] != store.version or kept[2].kind.size != store.n
                or kept[2].local.shape[1] != k):
            kept = self._row_shapes = (store, store.version, _empty_table(store.n, k), np.zeros(store.n, dtype=bool))
        _store, _version, table, filled = kept
        for r in at[~filled[at]].tolist():
            _fill_row(table, r, hitboxes[r].shape)
            filled[r] = True
        return table, at

    def _cached_shapes(self) -> _Shapes | None:
        """The scene's shape table if it is current (no structural change, no hitbox edit waiting).
        A table belongs to one store: a restored snapshot is another, whatever its count of changes
        (two timelines from one snapshot reach the same count with other rows)."""
        store = self.bodies.store
        cached: tuple[BodyStore, int, _Shapes] | None = getattr(self, "_shape_cols", None)
        if cached is not None and cached[0] is store and cached[1] == store.version and not store.dirty_hitboxes:
            return cached[2]
        return None

    def _prepare(self) -> Geometry:
        """The geometry, current, as the single queries' candidate search leaves it."""
        geom = self.bodies.ensure_geometry()
        self.pipeline.frame.counters["rehashed"] = (self.pipeline.frame.counters.get("rehashed", 0)
                                                    + self.bodies.sync_static())
        return geom

    def query_points(self, points: object, mask: int = ALL_LAYERS) -> PointHits:
        """:meth:`query_point` of each row of ``points`` (``(n, 2)``), in one compiled pass: a
        :class:`PointHits` (``offsets``, ``entities``; point ``i``'s sorted entities are
        ``entities[offsets[i]:offsets[i + 1]]``)."""
        pts = _xy_rows("points", points)
        m = _mask_value(mask)
        geom = self._prepare()
        store, cols = self.bodies.store, self._shapes()
        if store.parts:  # (compound bodies: the single queries, point by point)
            found = [self.query_point(float(px), float(py), int(m)) for px, py in pts.tolist()]
            offsets = np.concatenate([[0], np.cumsum([len(f) for f in found])]).astype(np.int64)
            return PointHits(offsets, np.array([e for f in found for e in f], dtype=np.int64))
        offsets, entities = bq.points_inside(
            np.ascontiguousarray(pts[:, 0]), np.ascontiguousarray(pts[:, 1]), store.kind, cols.kind, store.layer,
            store.entity, geom.minx, geom.miny, geom.maxx, geom.maxy, geom.hx, geom.hy, cols.sa, geom.cap_ux,
            geom.cap_uy, store.hw, store.hh, geom.world_poly, geom.poly_slot, geom.count, m, 2.0)
        return PointHits(offsets, entities)

    def nearest_many(self, points: object, max_distance: float = math.inf, mask: int = ALL_LAYERS) -> NearestMany:
        """:meth:`nearest` of each row of ``points`` (``(n, 2)``), in one compiled pass: a
        :class:`NearestMany` (entity -1 and distance -1 where no hitbox is within
        ``max_distance``)."""
        pts = _xy_rows("points", points)
        md = _max_distance(max_distance)
        m = _mask_value(mask)
        geom = self._prepare()
        store, cols = self.bodies.store, self._shapes()
        if store.parts:  # (compound bodies: the single queries, point by point)
            near = [self.nearest((float(px), float(py)), md, int(m)) for px, py in pts.tolist()]
            return NearestMany(np.array([-1 if h is None else h.entity for h in near], dtype=np.int64),
                               np.array([-1.0 if h is None else h.distance for h in near]),
                               np.array([(px, py) if h is None else tuple(h.point) for h, (px, py) in
                                         zip(near, pts.tolist())], dtype=np.float64).reshape(-1, 2))
        ent, dist, bx, by = bq.nearest_points(
            np.ascontiguousarray(pts[:, 0]), np.ascontiguousarray(pts[:, 1]), md, store.kind, cols.kind, cols.sa,
            cols.sb, cols.local, cols.cnt, store.layer, store.entity, geom.minx, geom.miny, geom.maxx, geom.maxy,
            geom.hx, geom.hy, store.rot, m)
        dist[ent < 0] = -1.0  # (a miss: never inf)
        return NearestMany(ent, dist, np.stack([bx, by], axis=1))

    def raycast_many(self, origins: object, directions: object, max_distance: float = math.inf,
                     mask: int = ALL_LAYERS) -> RayHits:
        """:meth:`raycast` of each ray ``origins[i]``, ``directions[i]`` (``(n, 2)`` each), in one
        compiled pass: a :class:`RayHits` (entity -1 and distance -1 for a miss). (ray, row)
        pairs the compiled float path leaves to exact arithmetic, and rays against capsules, are
        answered by :func:`~framework.collision.ray.raycast` itself."""
        o = _xy_rows("origins", origins)
        d = _xy_rows("directions", directions)
        if o.shape != d.shape:
            raise InvalidValue(f"origins and directions must have the same shape, got {o.shape} and {d.shape}")
        zero = np.flatnonzero((d[:, 0] == 0.0) & (d[:, 1] == 0.0))
        if zero.size:
            raise InvalidValue(f"directions[{int(zero[0])}] must not be zero, got {tuple(d[zero[0]].tolist())!r}")
        md = _max_distance(max_distance)
        m = _mask_value(mask)
        geom = self._prepare()
        store, cols = self.bodies.store, self._shapes()
        if store.parts:  # (compound bodies: the single queries, ray by ray; not logged for the overlay)
            log = self.pipeline.frame.ray_log
            logged = len(log)
            first = [self.raycast_all((a, b), (c, d_), md, int(m)) for (a, b), (c, d_) in zip(o.tolist(), d.tolist())]
            del log[logged:]
            hits = [f[0] if f else None for f in first]
            return RayHits(np.array([-1 if h is None else h.entity for h in hits], dtype=np.int64),
                           np.array([-1.0 if h is None else h.distance for h in hits]),
                           np.array([(0.0, 0.0) if h is None else tuple(h.point) for h in hits]).reshape(-1, 2),
                           np.array([(0.0, 0.0) if h is None else tuple(h.normal) for h in hits]).reshape(-1, 2))
        ox, oy = np.ascontiguousarray(o[:, 0]), np.ascontiguousarray(o[:, 1])
        if math.isfinite(md):
            reach = np.full(ox.size, md)
        elif store.n == 0:
            reach = np.ones(ox.size)
        else:  # _world_extent of each origin (the same float operations)
            far = np.maximum.reduce([np.abs(float(geom.minx.min()) - ox), np.abs(float(geom.maxx.max()) - ox),
                                     np.abs(float(geom.miny.min()) - oy), np.abs(float(geom.maxy.max()) - oy)])
            reach = 2.0 * far + 1.0
        ent, dist, hx, hy, nx, ny, rows, pending = bq.rays_first(
            ox, oy, np.ascontiguousarray(d[:, 0]), np.ascontiguousarray(d[:, 1]), md, reach, store.kind, cols.kind,
            cols.sa, cols.sb, cols.ext, cols.local, cols.cnt, store.layer, store.entity, geom.minx, geom.miny,
            geom.maxx, geom.maxy, geom.hx, geom.hy, store.rot, m)
        for i, r in pending.tolist():
            hb = store.hitboxes[r]
            assert hb is not None  # (rows with a kind have a hitbox)
            hit = _raycast(hb.shape, (float(geom.hx[r]), float(geom.hy[r]), float(store.rot[r])),
                           (float(ox[i]), float(oy[i])), (float(d[i, 0]), float(d[i, 1])), md)
            if hit is None:
                continue
            e = int(store.entity[r])
            if ent[i] < 0 or (hit.distance, e, r) < (float(dist[i]), int(ent[i]), int(rows[i])):
                ent[i], dist[i], rows[i] = e, hit.distance, r
                hx[i], hy[i] = hit.point
                nx[i], ny[i] = hit.normal
        dist[ent < 0] = -1.0  # (a miss: never inf)
        return RayHits(ent, dist, np.stack([hx, hy], axis=1), np.stack([nx, ny], axis=1))

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
        found: set[int] = self._overlapping_parts(shape, center, int(mask)) if store.parts else set()
        if rows.size == 0:
            return sorted(found)
        shapes_b = [store.hitboxes[r].shape for r in rows.tolist()]
        poses_b = list(zip(geom.hx[rows].tolist(), geom.hy[rows].tolist(), store.rot[rows].tolist()))
        res = batch.collide_many([shape] * rows.size, [center] * rows.size, shapes_b, poses_b)
        return sorted(found | {int(e) for e in store.entity[rows[res.hit]]})

    def _overlapping_parts(self, shape: Any, center: tuple[float, float] | tuple[float, float, float],
                           mask: int) -> set[int]:
        """The compound bodies one of whose parts overlaps ``shape`` at ``center``."""
        return {e for e, part, pose in self._parts(mask) if collide(shape, center, part.shape, pose) is not None}
