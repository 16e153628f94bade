"""The distance between two shapes and their closest points (aiming, AI, "how far is the wall").

Every shape is a *rounded convex core*: an AABB or polygon its corners (radius 0), a circle its
centre (radius r), a capsule its segment (radius r), a segment its two ends
(radius 0). Two shapes that overlap or touch are at
distance 0 (:func:`~framework.collision.collide` decides overlap exactly; a touching pair's
feature distance rounds to 0). Apart, the distance is the least distance between the cores' features
(a vertex of one against an edge or vertex of the other) less the two radii, and the closest
points lie on the surfaces along the line between the cores' closest points. Two segments that
cross (or touch) are at distance 0, with their crossing as both points. Floats: the distance
is within a few ulps of the exact one.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from ..shapes import AABB, Capsule, Circle, Polygon, Segment, Shape
from .collide import collide
from .placement import check_shape, pose
from .ray import closest_on_segment
from .results import Vec2

__all__ = ["Distance", "distance", "point_distance", "shape_core"]


class Distance(NamedTuple):
    """How far shape B is from shape A: ``distance`` (0 where they overlap or touch), the point of
    A nearest B (``point_a``) and of B nearest A (``point_b``); where they overlap, both are the
    contact point of :func:`~framework.collision.collide`."""

    distance: float
    point_a: Vec2
    point_b: Vec2


def shape_core(shape: Shape, x: float, y: float, rotation: float) -> tuple[list[tuple[float, float]], float]:
    """The shape at ``(x, y, rotation)`` as a convex core in world coordinates (its vertices, counter-
    clockwise; one for a circle, two for a capsule) and the radius rounding it."""
    c, s = math.cos(rotation), math.sin(rotation)
    if isinstance(shape, Circle):
        return [(x, y)], shape.radius
    if isinstance(shape, Capsule):
        h = 0.5 * shape.length
        return [(x + s * h, y - c * h), (x - s * h, y + c * h)], shape.radius
    if isinstance(shape, Segment):
        (ax, ay), (bx, by) = shape.a, shape.b
        return [(x + c * ax - s * ay, y + s * ax + c * ay), (x + c * bx - s * by, y + s * bx + c * by)], 0.0
    if isinstance(shape, AABB):  # never turns
        hw, hh = shape.half_width, shape.half_height
        return [(x - hw, y - hh), (x + hw, y - hh), (x + hw, y + hh), (x - hw, y + hh)], 0.0
    assert isinstance(shape, Polygon)
    return [(x + c * px - s * py, y + s * px + c * py) for px, py in shape.points], 0.0


def _edges(core: list[tuple[float, float]]) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    n = len(core)
    if n == 1:
        return [(core[0], core[0])]
    if n == 2:
        return [(core[0], core[1])]
    return [(core[i], core[(i + 1) % n]) for i in range(n)]


def _closest_cores(a: list[tuple[float, float]], b: list[tuple[float, float]]):
    """The least distance between two disjoint convex cores and its two points (a's, b's)."""
    best = (math.inf, a[0], b[0])
    for (p, q, flip) in ((a, b, False), (b, a, True)):
        for vx, vy in p:
            for (s0, s1) in _edges(q):
                cx, cy = closest_on_segment(vx, vy, s0[0], s0[1], s1[0], s1[1])
                d = math.hypot(cx - vx, cy - vy)
                if d < best[0]:
                    best = (d, (cx, cy), (vx, vy)) if flip else (d, (vx, vy), (cx, cy))
    return best


def _crossing(a: list[tuple[float, float]], b: list[tuple[float, float]]) -> tuple[float, float] | None:
    """A point where two segments meet (crossing, or touching at an end), or ``None``."""
    (p0x, p0y), (p1x, p1y) = a
    (q0x, q0y), (q1x, q1y) = b
    rx, ry, sx, sy = p1x - p0x, p1y - p0y, q1x - q0x, q1y - q0y
    den = rx * sy - ry * sx
    if den == 0.0:
        return None  # parallel: the closest features give the distance (0 if they overlap)
    wx, wy = q0x - p0x, q0y - p0y
    t, u = (wx * sy - wy * sx) / den, (wx * ry - wy * rx) / den
    if 0.0 <= t <= 1.0 and 0.0 <= u <= 1.0:
        return p0x + t * rx, p0y + t * ry
    return None


def distance(shape_a: Shape, transform_a: object, shape_b: Shape, transform_b: object) -> Distance:
    """The distance from shape A to shape B and their closest points (see the module docstring).
    Transforms as :func:`~framework.collision.collide` takes them; bad shapes or non-finite
    transforms raise ``ValueError`` naming the field."""
    check_shape("shape_a", shape_a)
    check_shape("shape_b", shape_b)
    pa, pb = pose("transform_a", transform_a), pose("transform_b", transform_b)
    contact = collide(shape_a, pa, shape_b, pb)
    if contact is not None:
        return Distance(0.0, contact.point, contact.point)
    core_a, ra = shape_core(shape_a, *pa)
    core_b, rb = shape_core(shape_b, *pb)
    if isinstance(shape_a, Segment) and isinstance(shape_b, Segment):
        cross = _crossing(core_a, core_b)
        if cross is not None:  # (collide never calls two segments a contact: no interior)
            return Distance(0.0, Vec2(*cross), Vec2(*cross))
    d, (ax, ay), (bx, by) = _closest_cores(core_a, core_b)
    gap = d - ra - rb
    if d > 0.0:
        ux, uy = (bx - ax) / d, (by - ay) / d
        ax, ay, bx, by = ax + ra * ux, ay + ra * uy, bx - rb * ux, by - rb * uy
    if gap <= 0.0:  # touching (collide found no overlap): one point
        mx, my = 0.5 * (ax + bx), 0.5 * (ay + by)
        return Distance(0.0, Vec2(mx, my), Vec2(mx, my))
    return Distance(gap, Vec2(ax, ay), Vec2(bx, by))


def point_distance(shape: Shape, x: float, y: float, rotation: float, px: float, py: float) -> tuple[float, Vec2]:
    """How far the point ``(px, py)`` is from the shape at ``(x, y, rotation)`` (0 inside or on it),
    and the point of the shape nearest it (the point itself when inside)."""
    core, r = shape_core(shape, x, y, rotation)
    if len(core) >= 3 and all((q[0] - p[0]) * (py - p[1]) - (q[1] - p[1]) * (px - p[0]) >= 0.0
                              for p, q in _edges(core)):
        return 0.0, Vec2(px, py)
    best, bx, by = math.inf, px, py
    for s0, s1 in _edges(core):
        cx, cy = closest_on_segment(px, py, s0[0], s0[1], s1[0], s1[1])
        d = math.hypot(px - cx, py - cy)
        if d < best:
            best, bx, by = d, cx, cy
    if best <= r:
        return 0.0, Vec2(px, py)
    return best - r, Vec2(bx + r * (px - bx) / best, by + r * (py - by) / best)
