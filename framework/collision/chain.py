"""One-sided segments with ghost vertices (chains): which contacts of a two-sided segment a chain
segment keeps, and along which normal.

A :class:`~framework.shapes.ChainSegment` is first met as the two-sided segment it lies on (the
segment pairs of :mod:`~framework.collision.collide` and the batch kernels); these rules then
decide, from the segment ``p1 -> p2``, its ghost vertices ``g1`` (before ``p1``) and ``g2`` (after
``p2``), the body's centre and its deepest point below the segment's line, what is left of that
contact (Box2D v3's ``b2CollideChainSegmentAndPolygon``, and its Gauss-map classification
``b2ClassifyNormal``; see https://box2d.org/posts/2020/06/ghost-collisions/):

- **One-sided.** The segment's normal ``n1`` is on its right. A body whose centre (its hitbox
  origin: the centre of every shape but a polygon drawn off its origin) is behind the segment's line
  (and behind the line of each neighbour that turns outward at a joint) passes.
- **Joints.** A joint is *convex* where the chain turns outward (toward ``n1``) by more than
  :data:`CONVEX_TOL` (a sine). A contact normal that points toward the joint at ``p1`` (its part
  along ``p1 -> p2`` <= 0; toward ``p2`` otherwise):

  - at a convex joint, is kept while it lies between ``n1`` and the neighbour's normal, and is
    *skipped* beyond it (the neighbour segment owns those directions: its own contact stands);
  - at a joint where the chain runs on straight or bends inward, is *snapped* to ``n1``: the body is
    pushed out along the segment's normal by its depth below the segment's line, never sideways
    out of the joint. This is what keeps a box sliding along a chain from catching on a joint.

A contact whose normal already is ``n1`` is kept as it is. Every function works on numpy arrays,
one value per contact (the scalar queries pass arrays of one), so the scalar queries and the
scenes' kernels give the same answers.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..shapes import AABB, Capsule, ChainSegment, Circle, Polygon, Shape

__all__ = ["CONVEX_TOL", "SIN_TOL", "chain_rule", "chain_world", "classify", "core_world", "deepest_below",
           "one_contact", "one_impact", "one_sided_ray"]

F = NDArray[np.float64]

# The sine of the least outward turn that makes a joint convex, and the tolerance of the Gauss-map
# test (Box2D's convexTol and sinTol).
CONVEX_TOL = 0.01
SIN_TOL = 0.01
# A contact normal within this of the segment's normal (its components) is the segment's normal.
SAME_NORMAL = 1e-12


def chain_world(seg: ChainSegment, x: float, y: float, rotation: float) -> tuple[float, ...]:
    """``(p1x, p1y, p2x, p2y, g1x, g1y, g2x, g2y)``: the segment and its ghosts in world
    coordinates, the segment at ``(x, y)`` turned by ``rotation``."""
    c, s = math.cos(rotation), math.sin(rotation)
    out: list[float] = []
    for px, py in (seg.a, seg.b, seg.ghost1, seg.ghost2):
        if rotation == 0.0:
            out += [x + px, y + py]
        else:
            out += [x + (c * px - s * py), y + (s * px + c * py)]
    return tuple(out)


def core_world(shape: Shape, x: float, y: float, rotation: float) -> tuple[list[tuple[float, float]], float,
                                                                            tuple[float, float]]:
    """The shape at ``(x, y, rotation)`` as its core points in world coordinates (a circle's centre,
    a capsule's segment ends, a box's or polygon's outline), its radius, and its centre for the
    one-sided test: its hitbox origin (every solver reads the same point)."""
    c, s = math.cos(rotation), math.sin(rotation)
    if isinstance(shape, Circle):
        return [(x, y)], shape.radius, (x, y)
    if isinstance(shape, Capsule):
        h = shape.half_length
        return [(x + s * h, y - c * h), (x - s * h, y + c * h)], shape.radius, (x, y)
    if isinstance(shape, AABB):
        hw, hh = shape.half_width, shape.half_height
        return [(x - hw, y - hh), (x + hw, y - hh), (x + hw, y + hh), (x - hw, y + hh)], 0.0, (x, y)
    assert isinstance(shape, Polygon)
    return [(x + c * px - s * py, y + s * px + c * py) for px, py in shape.points], 0.0, (x, y)


def deepest_below(vx: F, vy: F, count: NDArray[np.int64], radius: F, p1x: F, p1y: F, n1x: F,
                  n1y: F) -> tuple[F, F, F]:
    """Per row, the body's least height above the segment's line (its core points ``vx, vy``
    ``[P, K]``, the first ``count`` real, rounded by ``radius``), and its point there:
    ``(low, sx, sy)``; ``low < 0``: the body reaches ``-low`` below the line."""
    k = vx.shape[1]
    h = (vx - p1x[:, None]) * n1x[:, None] + (vy - p1y[:, None]) * n1y[:, None]
    h = np.where(np.arange(k)[None, :] < count[:, None], h, np.inf)
    j = np.argmin(h, axis=1)
    rows = np.arange(vx.shape[0])
    low = h[rows, j] - radius
    return low, vx[rows, j] - n1x * radius, vy[rows, j] - n1y * radius


def _unit(x: F, y: F) -> tuple[F, F]:
    ln = np.hypot(x, y)
    return x / ln, y / ln


def chain_rule(p1x: F, p1y: F, p2x: F, p2y: F, g1x: F, g1y: F, g2x: F, g2y: F, cx: F, cy: F, nx: F, ny: F,
               depth: F, px: F, py: F, low: F, sx: F, sy: F) -> tuple[NDArray[np.bool_], F, F, F, F, F]:
    """The contacts of chain segments (module docstring): per row, the segment ``p1 -> p2`` and its
    ghosts, the body's centre ``(cx, cy)``, the two-sided contact (normal ``(nx, ny)`` from the
    segment toward the body, ``depth``, point) and the body's least height above the segment's line
    with its point there (:func:`deepest_below`). Returns ``(keep, nx, ny, depth, px, py)``."""
    passes, skip, snap, n1x, n1y = classify(p1x, p1y, p2x, p2y, g1x, g1y, g2x, g2y, cx, cy, nx, ny)
    snap_depth = -low
    keep = ~passes & ~skip & (~snap | (snap_depth > 0.0))
    nx, ny = np.where(snap, n1x, nx), np.where(snap, n1y, ny)
    depth = np.where(snap, snap_depth, depth)
    px = np.where(snap, sx + 0.5 * snap_depth * n1x, px)
    py = np.where(snap, sy + 0.5 * snap_depth * n1y, py)
    return keep, nx + 0.0, ny + 0.0, depth, px, py


def classify(p1x: F, p1y: F, p2x: F, p2y: F, g1x: F, g1y: F, g2x: F, g2y: F, cx: F, cy: F, nx: F,
             ny: F) -> tuple[NDArray[np.bool_], NDArray[np.bool_], NDArray[np.bool_], F, F]:
    """Per contact of a chain segment (normal ``(nx, ny)`` from it toward the body, whose centre is
    ``(cx, cy)``): ``(passes, skip, snap, n1x, n1y)``: the body passes (it is behind), the normal is
    the neighbour's, the normal is to be snapped to the segment's normal ``n1`` (module
    docstring)."""
    u1x, u1y = _unit(p2x - p1x, p2y - p1y)
    n1x, n1y = u1y, -u1x
    u0x, u0y = _unit(p1x - g1x, p1y - g1y)
    u2x, u2y = _unit(g2x - p2x, g2y - p2y)
    n0x, n0y = u0y, -u0x
    n2x, n2y = u2y, -u2x
    convex1 = u0x * u1y - u0y * u1x >= CONVEX_TOL
    convex2 = u1x * u2y - u1y * u2x >= CONVEX_TOL
    behind1 = n1x * (cx - p1x) + n1y * (cy - p1y) < 0.0
    behind0 = ~convex1 | (n0x * (cx - p1x) + n0y * (cy - p1y) < 0.0)
    behind2 = ~convex2 | (n2x * (cx - p2x) + n2y * (cy - p2y) < 0.0)
    passes = behind1 & behind0 & behind2
    same = (np.abs(nx - n1x) <= SAME_NORMAL) & (np.abs(ny - n1y) <= SAME_NORMAL)
    tail = nx * u1x + ny * u1y <= 0.0
    skip = np.where(tail, convex1 & (nx * n0y - ny * n0x > SIN_TOL), convex2 & (n2x * ny - n2y * nx > SIN_TOL))
    snap = ~same & np.where(tail, ~convex1, ~convex2)
    skip &= ~same
    return passes, skip, snap, n1x, n1y


def one_contact(seg: ChainSegment, pose_s: tuple[float, float, float], other: Shape,
                pose_o: tuple[float, float, float], nx: float, ny: float, depth: float, px: float,
                py: float) -> tuple[float, float, float, float, float] | None:
    """:func:`chain_rule` of one contact: the chain segment at ``pose_s``, the other shape at
    ``pose_o``, the two-sided contact's normal from the segment toward the other shape."""
    seg_w = chain_world(seg, *pose_s)
    pts, r, (cx, cy) = core_world(other, *pose_o)
    p1x, p1y, p2x, p2y = seg_w[:4]
    u1x, u1y = _unit(np.array([p2x - p1x]), np.array([p2y - p1y]))
    low, sx, sy = deepest_below(np.array([[p[0] for p in pts]]), np.array([[p[1] for p in pts]]),
                                np.array([len(pts)]), np.array([r]), np.array([p1x]), np.array([p1y]), u1y, -u1x)
    a = [np.array([v]) for v in (*seg_w, cx, cy, nx, ny, depth, px, py)]
    keep, nx_, ny_, d_, px_, py_ = chain_rule(a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7], a[8], a[9], a[10],
                                              a[11], a[12], a[13], a[14], low, sx, sy)
    if not keep[0]:
        return None
    return float(nx_[0]), float(ny_[0]), float(d_[0]), float(px_[0]), float(py_[0])


def one_sided_ray(seg: ChainSegment, rotation: float, dx: float, dy: float) -> bool:
    """Whether a ray of direction ``(dx, dy)`` can hit the chain segment (turned by ``rotation``):
    only from its front, against its normal (Box2D's one-sided ray cast)."""
    (ax, ay), (bx, by) = seg.a, seg.b
    ex, ey = bx - ax, by - ay
    if rotation != 0.0:
        c, s = math.cos(rotation), math.sin(rotation)
        ex, ey = c * ex - s * ey, s * ex + c * ey
    return ey * dx - ex * dy < 0.0  # the normal (ey, -ex) against the direction


def one_impact(seg: ChainSegment, pose_s: tuple[float, float, float], other: Shape,
               pose_o: tuple[float, float, float], nx: float, ny: float) -> tuple[float, float] | None:
    """The normal of a chain segment's first touch of another shape (the segment and the shape at
    their poses then; ``(nx, ny)`` the two-sided sweep's normal from the segment toward the
    shape), or ``None`` where the chain's rules give that touch away (the shape comes from behind,
    or the neighbour owns the direction); a direction out of a straight or inward joint becomes the
    segment's normal."""
    seg_w = chain_world(seg, *pose_s)
    _, _, (cx, cy) = core_world(other, *pose_o)
    a = [np.array([v]) for v in (*seg_w, cx, cy, nx, ny)]
    passes, skip, snap, n1x, n1y = classify(*a)
    if passes[0] or skip[0]:
        return None
    if snap[0]:
        return float(n1x[0]) + 0.0, float(n1y[0]) + 0.0
    return nx, ny
