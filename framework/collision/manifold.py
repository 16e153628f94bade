"""Contact manifolds: the points where two overlapping shapes touch, one or two.

:func:`~framework.collision.collide` reports one contact: the normal, the depth and one point of
the overlap. A box resting on a face touches along a segment, and a solver that turns bodies needs
that segment's ends (a box on one point would rock). :func:`manifold` clips, as Box2D's
``b2ClipPolygons`` does: the *reference* face is the face whose outward normal lies closest to the
contact normal (on A, or on B against it); the *incident* face of the other shape is its face
most opposed to that; the incident face, clipped to the reference face's extent, gives up to two
points, and those below the reference face are the manifold, each with its depth below it.
A segment is an outline of two points here (its two faces are its two sides); as a reference face
it clips the incident face to its own extent, the planes through its ends (as Box2D's
``b2ClipPolygons`` does with a reference edge's side planes). Circles touch at one point:
collide's. Points are in the overlap region (the contract's rule for
``Contact.point``), on the boundary of one of the shapes, deepest first.
"""

from __future__ import annotations

import math
from typing import cast

from ..shapes import AABB, Capsule, Circle, Polygon, Segment, Shape
from .collide import collide
from .placement import local_outline, pose
from .results import Manifold, ManifoldPoint, Vec2

__all__ = ["manifold"]

Pts = list[tuple[float, float]]


def manifold(shape_a: Shape, transform_a: object, shape_b: Shape, transform_b: object) -> Manifold | None:
    """The manifold of B against A, or ``None`` unless their interiors overlap (as ``collide``).

    Transforms as for :func:`~framework.collision.collide`. The normal is collide's; a circle or a
    capsule in the pair gives collide's point alone; two boxes or polygons give one point (a corner in a face)
    or two (a face on a face: the ends of the segment they share)."""
    c = collide(shape_a, transform_a, shape_b, transform_b)
    if c is None:
        return None
    single = Manifold(c.normal, (ManifoldPoint(c.point, c.depth),))
    if isinstance(shape_a, (Circle, Capsule)) or isinstance(shape_b, (Circle, Capsule)):
        return single  # (a round shape touches at one point)
    # (collide accepted them and neither is round: boxes, polygons or a segment)
    pa = _world(cast("AABB | Polygon | Segment", shape_a), *pose("transform_a", transform_a))
    pb = _world(cast("AABB | Polygon | Segment", shape_b), *pose("transform_b", transform_b))
    nx, ny = c.normal
    ia, along_a = _facing(pa, nx, ny)
    ib, along_b = _facing(pb, -nx, -ny)
    if along_a >= along_b:  # A's face is the reference: B's face rests on it
        points = _clip(pa, ia, pb)
    else:
        points = _clip(pb, ib, pa)
    if not points:  # (a sliver within rounding: collide's point stands)
        return single
    points.sort(key=lambda p: -p.depth)
    return Manifold(c.normal, tuple(points))


def _world(shape: AABB | Polygon | Segment, x: float, y: float, rotation: float) -> Pts:
    """The shape's outline in world coordinates, counter-clockwise."""
    return [(x + px, y + py) for px, py in local_outline(shape, rotation)]


def _normal(poly: Pts, i: int) -> tuple[float, float]:
    """The outward unit normal of face ``i`` (from vertex ``i`` to ``i + 1``, counter-clockwise)."""
    (x0, y0), (x1, y1) = poly[i], poly[(i + 1) % len(poly)]
    ex, ey = x1 - x0, y1 - y0
    length = math.hypot(ex, ey)
    return ey / length, -ex / length


def _facing(poly: Pts, nx: float, ny: float) -> tuple[int, float]:
    """The face of ``poly`` whose outward normal lies closest to ``(nx, ny)``, and their dot."""
    best, along = 0, -math.inf
    for i in range(len(poly)):
        fx, fy = _normal(poly, i)
        d = fx * nx + fy * ny
        if d > along:
            best, along = i, d
    return best, along


def _clip(ref: Pts, i: int, inc: Pts) -> list[ManifoldPoint]:
    """The points of ``inc``'s incident face inside ``ref`` and below its face ``i``: the face,
    clipped to ``ref``'s other faces (so every point lies in both shapes), keeps its ends that are
    below face ``i``, each with its depth below it."""
    fx, fy = _normal(ref, i)
    j, _ = _facing(inc, -fx, -fy)
    (v0x, v0y), (v1x, v1y) = inc[j], inc[(j + 1) % len(inc)]
    lo, hi = 0.0, 1.0
    if len(ref) == 2:
        # A segment: its extent is between the planes through its ends, facing out along it.
        (ax, ay), (bx, by) = ref[i], ref[1 - i]
        ln = math.hypot(bx - ax, by - ay)
        ux, uy = (bx - ax) / ln, (by - ay) / ln
        planes = [(ax, ay, -ux, -uy), (bx, by, ux, uy)]
    else:
        planes = [(*ref[k], *_normal(ref, k)) for k in range(len(ref)) if k != i]
    for rx, ry, kx, ky in planes:
        s0 = (rx - v0x) * kx + (ry - v0y) * ky  # >= 0: v0 inside face k
        s1 = (rx - v1x) * kx + (ry - v1y) * ky
        if s0 < 0.0 and s1 < 0.0:
            return []
        if s0 < 0.0:
            lo = max(lo, s0 / (s0 - s1))
        elif s1 < 0.0:
            hi = min(hi, s0 / (s0 - s1))
    if lo > hi:
        return []
    r0x, r0y = ref[i]
    out = []
    for t in ((lo, hi) if hi > lo else (lo,)):
        px, py = v0x + (v1x - v0x) * t, v0y + (v1y - v0y) * t
        below = (px - r0x) * fx + (py - r0y) * fy
        if below < 0.0:
            out.append(ManifoldPoint(Vec2(px, py), -below))
    return out
