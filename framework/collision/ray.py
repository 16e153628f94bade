"""Ray casts: where a ray first enters a shape's interior.

The ray and the shape are brought into a local frame first: the ray origin is taken relative to
the shape's position (a scene at x = 1e9 gives the answers of the same scene at the origin), then
positions and sizes are scaled by one power of two (the shape about one unit across) and the
direction by another (both exact), so that neither huge nor tiny scenes overflow or underflow and
integer / dyadic input keeps its exact decisions.

Boxes and polygons are clipped with Cyrus-Beck on *unnormalised* edge normals: the sign tests
``n . (v - o)`` and ``n . d`` are exact for dyadic input, so a ray along an edge line or exactly
through a corner is a graze, hence a miss. Circles use the discriminant written as
``|d|^2 r^2 - (m x d)^2`` (no cancellation) and the numerically stable root ``c / q``. A capsule
is the union of an open rectangle (its segment pushed out both ways by the radius) and two open
discs at the segment's ends: the ray enters it where it first enters one of those
(:func:`rounded_segment`).

The helpers below (local frames, clipping, disc intervals, normal tie-breaks) are shared with
:mod:`framework.collision.sweep`, which casts the relative motion against a Minkowski difference.
"""

from __future__ import annotations

import math
from numbers import Real
from typing import cast

from ..shapes import AABB, Capsule, Circle, Polygon, Shape
from ..validation import InvalidValue, vector2
from .placement import check_shape, pose
from .results import RayHit, Vec2
from .tiebreak import pick

__all__ = ["raycast"]

Pts = list[tuple[float, float]]

# Entry times (in the scaled local frame, where the shapes are about 1 unit across) closer than
# this (relative to the time, when above 1) count as a tie, broken by a fixed rule, not rounding.
TIE = 1e-12


def raycast(
    shape: Shape,
    transform: object,
    origin: object,
    direction: object,
    max_distance: float = math.inf,
) -> RayHit | None:
    """Where the ray ``origin + s * unit(direction)``, ``0 <= s <= max_distance``, enters ``shape``.

    ``direction`` need not be unit length; ``RayHit.distance`` is in world units along it. A ray that
    only grazes the boundary misses. A ray starting inside hits at distance 0 at its origin with the
    negated unit direction as normal; one starting on the boundary and heading inward hits at
    distance 0 with that edge's outward normal. A hit at exactly ``max_distance`` counts.
    """
    check_shape("shape", shape)
    px, py, rot = pose("transform", transform)
    ox, oy = vector2("origin", origin)
    dx, dy = vector2("direction", direction)
    if dx == 0.0 and dy == 0.0:
        raise InvalidValue(f"direction must be non-zero, got {direction!r}")
    limit = _max_distance(max_distance)

    # Direction scaled (exactly) so that its larger component lies in [0.5, 1).
    j = math.frexp(max(abs(dx), abs(dy)))[1]
    ux, uy = math.ldexp(dx, -j), math.ldexp(dy, -j)
    ulen = math.hypot(ux, uy)

    # Ray origin relative to the shape, everything scaled by 2**-k (exact).
    rx, ry, e = relative(ox, oy, px, py)
    k = local_exponent([extent(shape)], [(rx, e), (ry, e)])
    mx, my = math.ldexp(rx, e - k), math.ldexp(ry, e - k)
    if isinstance(shape, Circle):
        res = _ray_circle(mx, my, math.ldexp(shape.radius, -k), ux, uy)
    elif isinstance(shape, Capsule):
        res = _ray_capsule(mx, my, shape, rot, k, ux, uy)
    else:
        # (not a circle or a capsule: check_shape let only a box or a polygon through)
        res = _ray_polygon(scaled_outline(cast("AABB | Polygon", shape), 0.0, 0.0, rot, k), mx, my, ux, uy, ulen)
    if res is None:
        return None
    tau, normal = res
    if normal is None:  # the origin is strictly inside
        return RayHit(0.0, Vec2(ox + 0.0, oy + 0.0), Vec2(-ux / ulen + 0.0, -uy / ulen + 0.0))
    nx, ny = normal
    if tau <= 0.0:  # on the boundary, heading inward
        return RayHit(0.0, Vec2(ox + 0.0, oy + 0.0), Vec2(nx + 0.0, ny + 0.0))
    distance = safe_ldexp(tau * ulen, k)
    if not (distance <= limit and math.isfinite(distance)):
        return None  # beyond max_distance, or beyond the float range
    hx = px + safe_ldexp(mx + tau * ux, k)
    hy = py + safe_ldexp(my + tau * uy, k)
    if not (math.isfinite(hx) and math.isfinite(hy)):
        return None  # the entry point lies beyond the float range
    return RayHit(distance + 0.0, Vec2(hx + 0.0, hy + 0.0), Vec2(nx + 0.0, ny + 0.0))


def _max_distance(value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, Real):
        raise InvalidValue(f"max_distance must be a real number, got {value!r}")
    x = float(value)
    if math.isnan(x) or x < 0.0:
        raise InvalidValue(f"max_distance must be >= 0 (math.inf allowed), got {value!r}")
    return x


# --- shape kinds -----------------------------------------------------------------------------

# (tau, normal): normal None means "origin strictly inside".
_Res = tuple[float, tuple[float, float] | None]


def _ray_polygon(pts: Pts, ox: float, oy: float, dx: float, dy: float, dlen: float) -> _Res | None:
    clip = clip_polygon(pts, ox, oy, dx, dy)
    if clip is None:
        return None
    t_in, t_out, faces = clip
    if not t_out > 0.0:
        return None  # the chord lies behind the origin (or the origin is on an exit face)
    if t_in < 0.0:
        return 0.0, None
    # The entry face; where faces tie (a vertex), the one most opposed to the ray, then pick's rule.
    near = []
    tol = TIE * max(1.0, t_in)
    for t, nx, ny in faces:
        if t >= t_in - tol:
            ln = math.hypot(nx, ny)
            near.append(((nx * dx + ny * dy) / (ln * dlen), nx / ln, ny / ln))
    best = min(c[0] for c in near)
    near = [(0.0, nx, ny) for c, nx, ny in near if c <= best + TIE]
    _, nx, ny = pick(near, 1.0)
    return t_in, (nx, ny)


def _ray_circle(mx: float, my: float, r: float, dx: float, dy: float) -> _Res | None:
    mm = mx * mx + my * my
    rr = r * r
    if mm < rr:
        return 0.0, None
    if mx * dx + my * dy >= 0.0:
        return None  # heading away, tangent, or on the circle heading out
    if mm == rr:  # on the circle, heading inward
        ln = math.hypot(mx, my)
        return 0.0, (mx / ln, my / ln)
    iv = disc_interval(mx, my, r, dx, dy)
    if iv is None:
        return None
    t = iv[0]
    hx, hy = mx + t * dx, my + t * dy
    ln = math.hypot(hx, hy)
    return t, (hx / ln, hy / ln)


def _ray_capsule(mx: float, my: float, shape: Capsule, rot: float, k: int, dx: float, dy: float) -> _Res | None:
    from .capsule import segment

    sx, sy = segment(shape, rot, k)
    r = math.ldexp(shape.radius, -k)
    # Strictly inside: nearer the segment than r.
    cx, cy = closest_on_segment(mx, my, -sx, -sy, sx, sy)
    if (mx - cx) ** 2 + (my - cy) ** 2 < r * r:
        return 0.0, None
    found = rounded_segment(mx, my, -sx, -sy, sx, sy, r, dx, dy)
    if found is None:
        return None
    t_in, t_out, cands = found
    if not t_out > 0.0:
        return None
    t_in = max(t_in, 0.0)  # (< 0 only by rounding: on the boundary, heading in)
    tol = TIE * max(1.0, t_in)
    _, nx, ny = pick([(0.0, nx, ny) for t, nx, ny in cands if t <= t_in + tol or t <= 0.0], 1.0)
    return t_in, (nx, ny)


# --- shared helpers (also used by sweep.py) ---------------------------------------------------

def closest_on_segment(px: float, py: float, s0x: float, s0y: float, s1x: float, s1y: float) -> tuple[float, float]:
    """The point of the segment s0 s1 closest to p."""
    ex, ey = s1x - s0x, s1y - s0y
    e2 = ex * ex + ey * ey
    if e2 == 0.0:
        return s0x, s0y
    t = ((px - s0x) * ex + (py - s0y) * ey) / e2
    if t <= 0.0:
        return s0x, s0y
    if t >= 1.0:
        return s1x, s1y
    return s0x + t * ex, s0y + t * ey


def rounded_segment(
    cx: float, cy: float, s0x: float, s0y: float, s1x: float, s1y: float, r: float, vx: float, vy: float
) -> tuple[float, float, list[tuple[float, float, float]]] | None:
    """The open interval ``(t_in, t_out)`` where ``c + t v`` is strictly inside the segment s0 s1
    rounded by ``r`` (an open rectangle and two open discs), with the entry normals ``(t, nx, ny)``
    of the pieces entered (unit, outward), or ``None`` if it never is (a graze). ``v`` non-zero."""
    t_in, t_out = math.inf, -math.inf
    cands: list[tuple[float, float, float]] = []
    ex, ey = s1x - s0x, s1y - s0y
    e2 = ex * ex + ey * ey
    if e2 > 0.0:
        nx, ny = ey, -ex
        ln = math.sqrt(e2)
        rl = r * ln
        qx, qy = cx - s0x, cy - s0y
        along, across = ex * qx + ey * qy, nx * qx + ny * qy
        ev, nv = ex * vx + ey * vy, nx * vx + ny * vy
        # 0 < e.(x - s0) < e.e and -r|e| < n.(x - s0) < r|e|, each as f0 + t f1 < 0.
        from .sweep import clip_constraints

        rect = clip_constraints([(-along, -ev, "start"), (along - e2, ev, "end"), (across - rl, nv, "pos"),
                                 (-across - rl, -nv, "neg")])
        if rect is not None:
            a, b, tags = rect
            t_in, t_out = min(t_in, a), max(t_out, b)
            if "pos" in tags:
                cands.append((a, nx / ln, ny / ln))
            elif "neg" in tags:
                cands.append((a, -nx / ln, -ny / ln))
            # (entered through an end only: next to a disc, entered no later, which gives the normal)
    for px, py in ((s0x, s0y), (s1x, s1y)):
        iv = disc_interval(cx - px, cy - py, r, vx, vy)
        if iv is not None:
            a, b = iv
            t_in, t_out = min(t_in, a), max(t_out, b)
            t = a if a > 0.0 else 0.0
            hx, hy = cx - px + t * vx, cy - py + t * vy
            hl = math.hypot(hx, hy)
            cands.append((a, hx / hl, hy / hl) if hl > 0.0 else (a, 0.0, 1.0))
    if not t_in < t_out:
        return None
    return t_in, t_out, cands


def safe_ldexp(x: float, e: int) -> float:
    """``x * 2**e``, or a signed inf on overflow (math.ldexp raises instead)."""
    try:
        return math.ldexp(x, e)
    except OverflowError:
        return math.copysign(math.inf, x)


def relative(ax: float, ay: float, bx: float, by: float) -> tuple[float, float, int]:
    """``(x, y, e)`` with ``(ax - bx, ay - by) == (x, y) * 2**e`` (rounded), never overflowing."""
    x, y = ax - bx, ay - by
    if math.isfinite(x) and math.isfinite(y):
        return x, y, 0
    return math.ldexp(ax, -1) - math.ldexp(bx, -1), math.ldexp(ay, -1) - math.ldexp(by, -1), 1


def extent(shape: Shape) -> float:
    """A size of the shape in its own frame, to choose the local scale (any factor of 2 will do)."""
    if isinstance(shape, Circle):
        return shape.radius
    if isinstance(shape, Capsule):
        return shape.bounding_radius
    if isinstance(shape, AABB):
        return max(shape.width, shape.height)
    assert isinstance(shape, Polygon)
    return max(max(abs(x), abs(y)) for x, y in shape.points)


def scale_exponent(values: list[tuple[float, int]]) -> int:
    """The exponent ``k`` with the largest ``|v| * 2**e`` in ``[2**(k-1), 2**k)``."""
    return max(math.frexp(abs(v))[1] + e for v, e in values if v != 0.0)


# Offsets may be up to 2**FAR times the shapes' size in the local frame: their squares and
# products with sizes stay far from overflow, and the shapes' own products far from underflow.
FAR = 500


def local_exponent(sizes: list[float], offsets: list[tuple[float, int]]) -> int:
    """The exponent ``k`` of the local frame (coordinates scaled by ``2**-k``): the shapes are about
    one unit across, unless an offset is more than ``2**FAR`` times farther (then it is ``2**FAR``)."""
    k = scale_exponent([(s, 0) for s in sizes])
    if any(v != 0.0 for v, _ in offsets):
        k = max(k, scale_exponent(offsets) - FAR)
    return k


def scaled_outline(shape: AABB | Polygon, x: float, y: float, rotation: float, k: int) -> Pts:
    """World outline (counter-clockwise) of a box or polygon scaled by ``2**-k`` (exactly: scaled
    operands), its hitbox origin at the already scaled (x, y). AABBs ignore ``rotation``."""
    if isinstance(shape, AABB):
        hw, hh = math.ldexp(shape.width, -k - 1), math.ldexp(shape.height, -k - 1)
        return [(x - hw, y - hh), (x + hw, y - hh), (x + hw, y + hh), (x - hw, y + hh)]
    pts = [(math.ldexp(px, -k), math.ldexp(py, -k)) for px, py in shape.points]
    if rotation == 0.0:
        return [(px + x, py + y) for px, py in pts]
    c, s = math.cos(rotation), math.sin(rotation)
    return [(c * px - s * py + x, s * px + c * py + y) for px, py in pts]


def clip_polygon(
    pts: Pts, ox: float, oy: float, dx: float, dy: float
) -> tuple[float, float, list[tuple[float, float, float]]] | None:
    """Cyrus-Beck: the open interval ``(t_in, t_out)`` where ``o + t d`` is strictly inside the convex
    CCW outline, with the entering faces ``(t, nx, ny)`` (unnormalised outward normals), or
    ``None`` when the line never enters the interior (a graze along an edge or through a corner)."""
    t_in, t_out = -math.inf, math.inf
    faces = []
    n = len(pts)
    for i in range(n):
        x0, y0 = pts[i]
        x1, y1 = pts[(i + 1) % n]
        nx, ny = y1 - y0, x0 - x1  # outward normal of a CCW outline, unnormalised
        num = nx * (x0 - ox) + ny * (y0 - oy)
        den = nx * dx + ny * dy
        if den == 0.0:
            if num <= 0.0:
                return None  # parallel, on or outside this face's line
        elif den < 0.0:
            t = num / den
            faces.append((t, nx, ny))
            if t > t_in:
                t_in = t
        else:
            t = num / den
            if t < t_out:
                t_out = t
    if not t_in < t_out:
        return None
    return t_in, t_out, faces


def disc_interval(mx: float, my: float, r: float, dx: float, dy: float) -> tuple[float, float] | None:
    """The open interval ``(t1, t2)`` where ``|m + t d| < r``, or ``None`` if empty (tangent lines
    touch at one point only: a graze). ``d`` must be non-zero."""
    a = dx * dx + dy * dy
    cross = mx * dy - my * dx
    # Discriminant b^2 - a c rewritten (Lagrange) as a r^2 - cross^2: no cancellation, and exact
    # on dyadic input, so a tangent ray is decided exactly.
    disc = a * (r * r) - cross * cross
    if not disc > 0.0:
        return None
    b = mx * dx + my * dy
    c = (mx * mx + my * my) - r * r
    sq = math.sqrt(disc)
    if b < 0.0:
        q = sq - b  # > 0, no cancellation
        t1, t2 = c / q, q / a
    else:
        q = -b - sq  # < 0, no cancellation
        t1, t2 = q / a, c / q
    if not t1 < t2:
        return None
    return t1, t2
