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

A contact whose normal already is ``n1`` is kept as it is.

The rule is stated once, in :func:`chain_verdict`, a compiled leaf function
(:data:`framework.compiled.leaf`) that every path calls: the scalar queries (:func:`one_contact`,
:func:`one_impact`), the exact solver's narrow phase (:func:`chain_rule`, row by row) and the soft
step's manifolds (:func:`framework.collision.soft_manifold.chain_segment`). What each does with
the verdict (a contact's depth and point, a manifold's points) stays with it.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..compiled import leaf
from ..shapes import AABB, Capsule, ChainSegment, Circle, Polygon, Shape

__all__ = ["CONVEX_TOL", "KEEP", "PASS", "SIN_TOL", "SKIP", "SNAP", "chain_rule", "chain_verdict", "chain_world",
           "classify", "core_world", "deepest_below", "one_contact", "one_impact", "one_sided_ray"]

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


# What the rule leaves of a contact (:func:`chain_verdict`).
KEEP, PASS, SKIP, SNAP = 0, 1, 2, 3


@leaf
def chain_verdict(p1x, p1y, p2x, p2y, u0x, u0y, u1x, u1y, u2x, u2y, cx, cy, nx, ny):
    """The chain's rule (module docstring), once for every solver and query: the segment
    ``p1 -> p2``, the unit directions ``u0`` (ghost 1 -> ``p1``), ``u1`` (``p1 -> p2``) and ``u2``
    (``p2`` -> ghost 2), the body's centre ``(cx, cy)`` and the two-sided contact's normal
    ``(nx, ny)`` from the segment toward the body. Returns ``(verdict, convex1, convex2)``: the
    verdict is :data:`PASS` (the body is behind: no contact), :data:`SKIP` (the neighbour owns the
    normal), :data:`SNAP` (push out along the segment's normal ``(u1y, -u1x)`` instead) or
    :data:`KEEP`; ``convex1``, ``convex2``: whether the joints at ``p1`` and ``p2`` turn outward.

    Each caller measures the directions its own way (the exact path with ``hypot``, as numpy's
    ``np.hypot``; the soft step with ``sqrt(x * x + y * y)``, as Box2D's ``b2Normalize``), so
    neither's answers changed when the two statements of the rule became this one."""
    n1x, n1y = u1y, -u1x
    n0x, n0y = u0y, -u0x
    n2x, n2y = u2y, -u2x
    convex1 = u0x * u1y - u0y * u1x >= CONVEX_TOL
    convex2 = u1x * u2y - u1y * u2x >= CONVEX_TOL
    behind1 = n1x * (cx - p1x) + n1y * (cy - p1y) < 0.0
    behind0 = (not convex1) or n0x * (cx - p1x) + n0y * (cy - p1y) < 0.0
    behind2 = (not convex2) or n2x * (cx - p2x) + n2y * (cy - p2y) < 0.0
    if behind1 and behind0 and behind2:
        return PASS, convex1, convex2  # one-sided: the body comes from behind
    if abs(nx - n1x) <= SAME_NORMAL and abs(ny - n1y) <= SAME_NORMAL:
        return KEEP, convex1, convex2  # already the segment's normal
    if nx * u1x + ny * u1y <= 0.0:  # toward p1
        if not convex1:
            return SNAP, convex1, convex2
        return (SKIP if nx * n0y - ny * n0x > SIN_TOL else KEEP), convex1, convex2
    if not convex2:
        return SNAP, convex1, convex2
    return (SKIP if n2x * ny - n2y * nx > SIN_TOL else KEEP), convex1, convex2


@leaf
def _unit(x, y):
    # (numba's math.hypot is the C library's, as numpy's np.hypot: the same bits)
    ln = math.hypot(x, y)
    return x / ln, y / ln


@leaf
def classify(p1x, p1y, p2x, p2y, g1x, g1y, g2x, g2y, cx, cy, nx, ny):
    """:func:`chain_verdict` of a contact of the segment ``p1 -> p2`` with ghosts ``g1``, ``g2``
    (world coordinates), the body's centre ``(cx, cy)`` and the normal ``(nx, ny)`` from the
    segment toward the body: ``(verdict, n1x, n1y)``, ``n1`` the segment's unit normal."""
    u1x, u1y = _unit(p2x - p1x, p2y - p1y)
    u0x, u0y = _unit(p1x - g1x, p1y - g1y)
    u2x, u2y = _unit(g2x - p2x, g2y - p2y)
    verdict, _, _ = chain_verdict(p1x, p1y, p2x, p2y, u0x, u0y, u1x, u1y, u2x, u2y, cx, cy, nx, ny)
    return verdict, u1y, -u1x


@leaf
def _chain_rows(p1x, p1y, p2x, p2y, g1x, g1y, g2x, g2y, cx, cy, nx, ny, depth, px, py, low, sx, sy,
                keep, onx, ony, odepth, opx, opy):
    """:func:`chain_rule`, row by row, into ``keep, onx, ony, odepth, opx, opy``."""
    for i in range(p1x.shape[0]):
        verdict, n1x, n1y = classify(p1x[i], p1y[i], p2x[i], p2y[i], g1x[i], g1y[i], g2x[i], g2y[i], cx[i], cy[i],
                                     nx[i], ny[i])
        if verdict == SNAP:  # out along the segment's normal, by the body's depth below its line
            d = -low[i]
            keep[i] = d > 0.0
            onx[i], ony[i], odepth[i] = n1x + 0.0, n1y + 0.0, d
            opx[i], opy[i] = sx[i] + 0.5 * d * n1x, sy[i] + 0.5 * d * n1y
        else:
            keep[i] = verdict == KEEP
            onx[i], ony[i], odepth[i], opx[i], opy[i] = nx[i] + 0.0, ny[i] + 0.0, depth[i], px[i], py[i]


def chain_rule(p1x: F, p1y: F, p2x: F, p2y: F, g1x: F, g1y: F, g2x: F, g2y: F, cx: F, cy: F, nx: F, ny: F,
               depth: F, px: F, py: F, low: F, sx: F, sy: F) -> tuple[NDArray[np.bool_], F, F, F, F, F]:
    """The contacts of chain segments (module docstring; :func:`chain_verdict` per row): per row,
    the segment ``p1 -> p2`` and its ghosts, the body's centre ``(cx, cy)``, the two-sided contact
    (normal ``(nx, ny)`` from the segment toward the body, ``depth``, point) and the body's least
    height above the segment's line with its point there (:func:`deepest_below`). Returns
    ``(keep, nx, ny, depth, px, py)``."""
    n = p1x.shape[0]
    keep = np.empty(n, dtype=np.bool_)
    onx, ony, odepth, opx, opy = (np.empty(n) for _ in range(5))
    rows = [np.ascontiguousarray(a, dtype=np.float64) for a in
            (p1x, p1y, p2x, p2y, g1x, g1y, g2x, g2y, cx, cy, nx, ny, depth, px, py, low, sx, sy)]
    _chain_rows(*rows, keep, onx, ony, odepth, opx, opy)
    return keep, onx, ony, odepth, opx, opy


def one_contact(seg: ChainSegment, pose_s: tuple[float, float, float], other: Shape,
                pose_o: tuple[float, float, float], nx: float, ny: float, depth: float, px: float,
                py: float) -> tuple[float, float, float, float, float] | None:
    """:func:`chain_rule` of one contact: the chain segment at ``pose_s``, the other shape at
    ``pose_o``, the two-sided contact's normal from the segment toward the other shape."""
    seg_w = chain_world(seg, *pose_s)
    pts, r, (cx, cy) = core_world(other, *pose_o)
    p1x, p1y, p2x, p2y = seg_w[:4]
    u1x, u1y = _unit(p2x - p1x, p2y - p1y)
    low, sx, sy = deepest_below(np.array([[p[0] for p in pts]]), np.array([[p[1] for p in pts]]),
                                np.array([len(pts)]), np.array([r]), np.array([p1x]), np.array([p1y]),
                                np.array([u1y]), np.array([-u1x]))
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
    verdict, n1x, n1y = classify(*seg_w, cx, cy, nx, ny)
    if verdict == PASS or verdict == SKIP:
        return None
    if verdict == SNAP:
        return n1x + 0.0, n1y + 0.0
    return nx, ny
