"""Shape casts: sweep a shape through a scene and find the first hitbox it would enter.

A cast is :func:`~framework.collision.time_of_impact` of the moving shape against every hitbox
whose bounds meet the swept box (one compiled pass over the bounds, :mod:`~framework.collision.box_rows`;
the static hash in very large scenes), the earliest impact winning (ties: the lowest entity).
The scene's ``shape_cast`` query and the character controller (:mod:`framework.character`) both
cast through :func:`cast_rows`.

Conventions follow the ray queries: the hit's ``normal`` is the unit normal of the surface that
was hit, facing the cast shape (so a shape cast down onto a floor gets ``(0, 1)``); grazing a
surface (moving along it at gap 0) is a miss; a shape that already overlaps a hitbox at the start
hits it at fraction 0 with the push-out normal of :func:`~framework.collision.collide`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numpy.typing import NDArray

from .collision import collide, time_of_impact
from .collision.box_rows import rows_within
from .collision.results import Vec2
from .shapes import AABB, Circle, Polygon, Segment, Shape

if TYPE_CHECKING:
    from .queries import SpatialQueries

__all__ = ["ShapeHit", "candidate_rows", "cast_rows", "overlapping_rows", "shape_bounds", "touch_point"]

_NONE = np.zeros(0, dtype=np.int64)


class ShapeHit(NamedTuple):
    """A shape cast's first hit: the ``entity`` hit, the ``fraction`` of the motion travelled
    before the interiors would overlap (time of impact, in [0, 1)), the ``point`` where the two
    touch and the unit ``normal`` of the hit surface there, facing the cast shape."""

    entity: int
    fraction: float
    point: Vec2
    normal: Vec2


def shape_bounds(shape: Shape, x: float, y: float, rotation: float) -> tuple[float, float, float, float]:
    """``(minx, miny, maxx, maxy)`` of ``shape`` with its hitbox origin at ``(x, y)``, turned by
    ``rotation`` (AABBs never turn)."""
    if isinstance(shape, AABB):
        hw, hh = shape.width * 0.5, shape.height * 0.5
        return x - hw, y - hh, x + hw, y + hh
    if isinstance(shape, (Polygon, Segment)):
        c, s = math.cos(rotation), math.sin(rotation)
        src = shape.points if isinstance(shape, Polygon) else (shape.a, shape.b)
        xs = [x + px * c - py * s for px, py in src]
        ys = [y + px * s + py * c for px, py in src]
        return min(xs), min(ys), max(xs), max(ys)
    if shape.kind == "capsule":  # its segment's ends, grown by the radius
        # (kind "capsule": a Capsule, without importing it here)
        h, r = shape.length * 0.5, shape.radius  # type: ignore[attr-defined]
        ex, ey = abs(h * math.sin(rotation)), abs(h * math.cos(rotation))
        return x - ex - r, y - ey - r, x + ex + r, y + ey + r
    r = shape.bounding_radius
    return x - r, y - r, x + r, y + r


def _support(shape: Shape, x: float, y: float, rotation: float, nx: float, ny: float) -> list[tuple[float, float]]:
    """The points of ``shape`` furthest along ``(nx, ny)`` (one, or the two ends of a face)."""
    if isinstance(shape, Circle):
        return [(x + nx * shape.radius, y + ny * shape.radius)]
    if isinstance(shape, AABB):
        hw, hh = shape.width * 0.5, shape.height * 0.5
        pts = [(x - hw, y - hh), (x + hw, y - hh), (x + hw, y + hh), (x - hw, y + hh)]
    elif isinstance(shape, (Polygon, Segment)):
        c, s = math.cos(rotation), math.sin(rotation)
        src = shape.points if isinstance(shape, Polygon) else (shape.a, shape.b)
        pts = [(x + px * c - py * s, y + px * s + py * c) for px, py in src]
    else:  # a rounded segment (a capsule): its segment's ends pushed out by the radius
        c, s = math.cos(rotation), math.sin(rotation)
        # (the shapes left are capsules)
        h = shape.length * 0.5  # type: ignore[attr-defined]
        r = shape.radius  # type: ignore[attr-defined]
        pts = [(x + h * s + nx * r, y - h * c + ny * r), (x - h * s + nx * r, y + h * c + ny * r)]
    proj = [px * nx + py * ny for px, py in pts]
    top = max(proj)
    tol = 1e-9 * (max(abs(v) for v in proj) + shape.bounding_radius)
    return [p for p, v in zip(pts, proj) if v >= top - tol]


def touch_point(shape_a: Shape, pose_a: tuple[float, float, float], shape_b: Shape,
                pose_b: tuple[float, float, float], nx: float, ny: float) -> Vec2:
    """Where A and B touch, given the unit normal ``(nx, ny)`` from A toward B: the middle of the
    common part of A's support toward B and B's support toward A (a point, or the shared stretch
    of two faces lying on each other)."""
    sa = _support(shape_a, *pose_a, nx, ny)
    sb = _support(shape_b, *pose_b, -nx, -ny)
    tx, ty = -ny, nx
    ta = [px * tx + py * ty for px, py in sa]
    tb = [px * tx + py * ty for px, py in sb]
    lo, hi = max(min(ta), min(tb)), min(max(ta), max(tb))
    if lo > hi:  # rounding: the supports just miss each other; take the nearer ends
        lo = hi = (lo + hi) * 0.5
    mid = (lo + hi) * 0.5
    # Along the normal: halfway between the two supports (equal when touching exactly).
    da = sum(px * nx + py * ny for px, py in sa) / len(sa)
    db = sum(px * nx + py * ny for px, py in sb) / len(sb)
    d = (da + db) * 0.5
    return Vec2(d * nx + mid * tx + 0.0, d * ny + mid * ty + 0.0)


def _in_box(
    queries: SpatialQueries, rows: NDArray[np.intp], x0: float, y0: float, x1: float, y1: float,
) -> NDArray[np.intp]:
    """The ``rows`` whose current bounds meet the box (closed): the candidates worth an exact test."""
    g, store = queries.bodies.geometry, queries.bodies.store
    c = store.cols
    return rows_within(rows, g.minx, g.miny, g.maxx, g.maxy, x0, y0, x1, y1, c["layer"], c["sensor"], -1, _NONE,
                       c["entity"], _NONE)


def candidate_rows(queries: SpatialQueries, x0: float, y0: float, x1: float, y1: float, mask: int,
                   skip: Callable[[NDArray[np.intp]], NDArray[np.bool_]] | None = None) -> NDArray[np.intp]:
    """Rows with a hitbox in ``mask`` (sensors never block), minus those ``skip`` (rows -> keep
    mask) removes, whose bounds meet the box ``(x0, y0, x1, y1)``."""
    store = queries.bodies.store
    rows = queries._candidate_rows(x0, y0, x1, y1)
    rows = rows[((store.cols["layer"][rows] & mask) != 0) & ~store.cols["sensor"][rows]]
    if skip is not None and rows.size:
        rows = rows[skip(rows)]
    return _in_box(queries, rows, x0, y0, x1, y1)


def _box_sweep(ax: float, ay: float, ahw: float, ahh: float, bx: float, by: float, bhw: float, bhh: float,
               mx: float, my: float) -> tuple[float, float, float] | None | bool:
    """Box A moving by ``(mx, my)`` against box B (both axis-aligned), by slabs: ``(fraction,
    nx, ny)`` with the normal of B's face, facing A; None for a miss; False where the answer is
    at the very start (touching or overlapping) and :func:`time_of_impact` must decide it."""
    t_in, t_out, axis = -math.inf, math.inf, -1
    for k, (d, m, e) in enumerate(((bx - ax, mx, ahw + bhw), (by - ay, my, ahh + bhh))):
        if m == 0.0:
            if not abs(d) < e:
                return None  # apart (or touching) on this axis all the way
            continue
        lo, hi = (d - e) / m, (d + e) / m
        if lo > hi:
            lo, hi = hi, lo
        if lo > t_in or (lo == t_in and k == 1):  # a corner: the vertical face wins (the contract's tie rule)
            t_in, axis = lo, k
        t_out = min(t_out, hi)
    if not (t_in < t_out and t_out > 0.0 and t_in < 1.0):
        return None
    if t_in < 0.0 or axis < 0:
        return False  # overlapping at the start: collide's push-out normal decides
    # (t_in == 0: touching at the start and moving in: a hit at fraction 0 on the face met)
    if axis == 0:
        return t_in, (-1.0 if bx > ax else 1.0), 0.0
    return t_in, 0.0, (-1.0 if by > ay else 1.0)


def cast_rows(
    queries: SpatialQueries, shape: Shape, x: float, y: float, rotation: float, mx: float, my: float,
    accept: Callable[[int, float, float, float], bool] | None = None, *, mask: int = 0xFFFFFFFF,
    skip: Callable[[NDArray[np.intp]], NDArray[np.bool_]] | None = None, rows: NDArray[np.intp] | None = None,
    exact: bool = True,
) -> tuple[int, float, float, float] | None:
    """The first hit of ``shape`` (hitbox origin at ``(x, y)``, turned by ``rotation``) moving by
    ``(mx, my)``: ``(row, fraction, nx, ny)`` with the surface normal facing the shape, or None.

    Candidates are the rows :func:`candidate_rows` gives for the swept box (or those of ``rows``,
    already filtered by mask and ``skip``, whose bounds meet it); ``accept(row, fraction, nx, ny)``
    may refuse a hit (a one-way platform hit from below), and the next earliest counts instead.
    ``exact=False``: a box against boxes is swept by slabs (the fraction to rounding, not bit for
    bit :func:`time_of_impact`'s; several times faster), the character controller's casts."""
    store = queries.bodies.store
    x0, y0, x1, y1 = shape_bounds(shape, x, y, rotation)
    pad = 1e-9 * (abs(x) + abs(y) + shape.bounding_radius + abs(mx) + abs(my))
    box = (min(x0, x0 + mx) - pad, min(y0, y0 + my) - pad, max(x1, x1 + mx) + pad, max(y1, y1 + my) + pad)
    if rows is None:
        rows = candidate_rows(queries, *box, mask, skip)
    else:
        rows = _in_box(queries, rows, *box)
    if rows.size == 0:
        return None
    geom = queries.bodies.geometry
    found = []
    slabs = not exact and isinstance(shape, AABB)
    hw, hh = (shape.width * 0.5, shape.height * 0.5) if isinstance(shape, AABB) else (0.0, 0.0)
    for r in rows.tolist():
        other = store.hitboxes[r].shape  # (candidates have hitboxes)
        if slabs and isinstance(other, AABB):
            quick = _box_sweep(x, y, hw, hh, float(geom.hx[r]), float(geom.hy[r]), other.width * 0.5,
                               other.height * 0.5, mx, my)
            if quick is None:
                continue
            if isinstance(quick, tuple):
                found.append((quick[0], int(store.cols["entity"][r]), r, quick[1], quick[2]))
                continue
        pose_b = (float(geom.hx[r]), float(geom.hy[r]), float(store.cols["rot"][r]))
        hit = time_of_impact(shape, (x, y, rotation), (mx, my), other, pose_b)
        if hit is not None:
            found.append((hit.fraction, int(store.cols["entity"][r]), r, -hit.normal.x + 0.0, -hit.normal.y + 0.0))
    found.sort()
    for fraction, _e, r, nx, ny in found:
        if accept is None or accept(r, fraction, nx, ny):
            return r, fraction, nx, ny
    return None


def overlapping_rows(queries: SpatialQueries, shape: Shape, x: float, y: float, rotation: float,
                     mask: int, skip: Callable[[NDArray[np.intp]], NDArray[np.bool_]] | None = None,
                     rows: NDArray[np.intp] | None = None, apart: float | None = None,
                     ) -> list[tuple[int, float, float, float]]:
    """Rows (in ``mask``, not sensors, not ``skip``-ped; or those of ``rows``) whose hitboxes
    ``shape`` overlaps at ``(x, y)``: ``(row, nx, ny, depth)``, the normal pointing from the row's
    hitbox toward the shape (the way out). Rows whose bounds are more than ``apart`` from the
    shape's (default: rounding) are passed over without an exact test."""
    store = queries.bodies.store
    box = shape_bounds(shape, x, y, rotation)
    rows = candidate_rows(queries, *box, mask, skip) if rows is None else _in_box(queries, rows, *box)
    geom = queries.bodies.geometry
    out = []
    x0, y0, x1, y1 = box
    tol = 1e-12 * (abs(x) + abs(y) + x1 - x0 + y1 - y0) if apart is None else apart
    box_shape = isinstance(shape, AABB)
    for r in rows.tolist():
        # Bounds apart by more than rounding: no overlap, no exact test needed.
        if geom.minx[r] >= x1 + tol or geom.maxx[r] <= x0 - tol or geom.miny[r] >= y1 + tol or geom.maxy[r] <= y0 - tol:
            continue
        other = store.hitboxes[r].shape  # (candidates have hitboxes)
        # (box_shape: the shape is an AABB too)
        if box_shape and isinstance(other, AABB) and not (
                abs(float(geom.hx[r]) - x) < (shape.width + other.width) * 0.5  # type: ignore[attr-defined]
                and abs(float(geom.hy[r]) - y) < (shape.height + other.height) * 0.5):  # type: ignore[attr-defined]
            continue  # two boxes touching (or apart): not overlapping, to rounding
        c = collide(store.hitboxes[r].shape, (float(geom.hx[r]), float(geom.hy[r]), float(store.cols["rot"][r])),
                    shape, (x, y, rotation))
        if c is not None:
            out.append((r, c.normal.x, c.normal.y, c.depth))
    return out
