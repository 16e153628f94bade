"""Ray casts: where a ray first enters a shape's interior.

The ray and the shape are brought into a local frame first: the ray origin is taken relative to
the shape's position (a scene at x = 1e9 gives the answers of the same scene at the origin), then
positions and sizes are scaled by one power of two (the shape about one unit across) and the
direction by another (both exact), so that neither huge nor tiny scenes overflow or underflow and
integer / dyadic input keeps its exact decisions.

A ray that only grazes the boundary (along an edge, exactly through a corner from outside, tangent
to a circle or to a capsule's side or cap) misses, on any float input, not only on round numbers:
floats decide wherever the answer is clear by far more than their rounding, and wherever a test is
within :data:`~framework.collision.exact.BAND` of touching it is decided again on exact integers,
as :func:`~framework.collision.collide.collide` decides touching.

- Boxes and polygons are clipped with Cyrus-Beck on *unnormalised* edge normals
  (:func:`clip_polygon`). Where the signs of ``n . (v - o)`` or ``n . d``, or the order of the
  entry and exit times (a ray through a corner) or their signs, are within rounding, the clip is
  redone on exact rationals.
- Circles use the discriminant written as ``|d|^2 r^2 - (m x d)^2`` and the numerically stable
  root (:func:`~framework.collision.pieces.disc_interval`, exact near tangency).
- A segment has no interior: a ray hits it where it crosses it (a closed segment: through an end
  counts, so a ray through the shared vertex of two segments of a chain hits), and a ray parallel
  to it (along it included) misses, as a graze. The crossing's three signs (the ray against the
  segment's line, and the crossing against either end) are decided exactly where rounding could
  flip them (:func:`_ray_segment`).
- A capsule is the union of an open rectangle (its segment pushed out both ways by the radius) and
  two open discs at the segment's ends (:func:`~framework.collision.pieces.rounded_segment`). Each
  piece's interval is kept on its own and the ray enters where it first enters one of them: a ray
  along a side is tangent to both discs, and taking the span over the pieces would turn the
  rounding slivers of two tangents into a hit.

The helpers below (local frames, clipping) are shared with :mod:`framework.collision.sweep`, which
casts the relative motion against a Minkowski difference; the pieces of rounded shapes are in
:mod:`framework.collision.pieces`.
"""

from __future__ import annotations

import math
from fractions import Fraction
from numbers import Real
from typing import cast

from ..compiled import kernel
from ..shapes import AABB, Capsule, ChainSegment, Circle, Polygon, Segment, Shape
from ..validation import InvalidValue, vector2
from .exact import BAND, TINY, ratio_approx
from .pieces import TIE, disc_interval, first_entry, ints, rounded_segment
from .placement import check_shape, pose
from .results import RayHit, Vec2
from .tiebreak import pick

__all__ = ["raycast"]

Pts = list[tuple[float, float]]


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
    elif isinstance(shape, Segment):
        from .chain import one_sided_ray
        from .placement import local_outline

        if isinstance(shape, ChainSegment) and not one_sided_ray(shape, rot, dx, dy):
            return None  # a chain segment is met from its front only
        (s0x, s0y), (s1x, s1y) = local_outline(shape, rot, k)
        res = _ray_segment(mx, my, s0x, s0y, s1x, s1y, ux, uy)
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
    iv = disc_interval(0.0, 0.0, mx, my, r, (r,), dx, dy)
    if iv is None:
        return None  # the line misses the open disc, or is tangent to it
    t1, t2 = iv
    if not t2 > 0.0:
        return None  # behind the origin (or the origin on the circle, heading out)
    if t1 < 0.0:
        return 0.0, None
    # t1 == 0: on the circle, heading inward (exact signs near there: disc_interval).
    hx, hy = mx + t1 * dx, my + t1 * dy
    ln = math.hypot(hx, hy)
    return t1, ((hx / ln, hy / ln) if ln > 0.0 else (0.0, 1.0))


def _ray_segment(mx: float, my: float, s0x: float, s0y: float, s1x: float, s1y: float, dx: float,
                 dy: float) -> _Res | None:
    """The ray ``m + tau d`` against the closed segment s0 s1: where it crosses it, with the
    segment's normal facing the ray; ``None`` if it is parallel to it (a graze) or passes by.

    With ``w = s0 - m`` and ``e = s1 - s0``, the crossing is at ``tau = (w x e) / (d x e)`` and
    ``s = (w x d) / (d x e)`` along the segment; it is a hit for ``tau >= 0`` and ``0 <= s <= 1``.
    Where ``d x e``, ``tau`` or ``s`` is within rounding of a boundary of those tests, the three
    cross products are worked again on exact integers."""
    ex, ey = s1x - s0x, s1y - s0y
    wx, wy = s0x - mx, s0y - my
    den = dx * ey - dy * ex
    num_t = wx * ey - wy * ex
    num_s = wx * dy - wy * dx
    band_den = BAND * (abs(dx * ey) + abs(dy * ex))
    band_t = BAND * (abs(wx * ey) + abs(wy * ex))
    band_s = BAND * (abs(wx * dy) + abs(wy * dx))
    if (abs(den) <= band_den or abs(num_t) <= band_t
            or abs(num_s) <= band_s or abs(num_s - den) <= band_s + band_den):
        (imx, imy, i0x, i0y, i1x, i1y, idx, idy), e = ints((mx, my, s0x, s0y, s1x, s1y, dx, dy))
        iex, iey, iwx, iwy = i1x - i0x, i1y - i0y, i0x - imx, i0y - imy
        iden = idx * iey - idy * iex
        if iden == 0:
            return None  # parallel: along the segment, or beside it
        inum_t = iwx * iey - iwy * iex
        inum_s = iwx * idy - iwy * idx
        if iden < 0:
            iden, inum_t, inum_s = -iden, -inum_t, -inum_s
        if inum_t < 0 or inum_s < 0 or inum_s > iden:
            return None
        tau = 0.0 if inum_t == 0 else ratio_approx(inum_t, iden, 0)
    else:
        if den < 0.0:
            den, num_t, num_s = -den, -num_t, -num_s
        if num_t < 0.0 or num_s < 0.0 or num_s > den:
            return None
        tau = num_t / den
    ln = math.hypot(ex, ey)
    nx, ny = ey / ln, -ex / ln
    if nx * dx + ny * dy > 0.0:
        nx, ny = -nx, -ny
    return tau, (nx, ny)


def _ray_capsule(mx: float, my: float, shape: Capsule, rot: float, k: int, dx: float, dy: float) -> _Res | None:
    from .capsule import segment

    sx, sy = segment(shape, rot, k)
    r = math.ldexp(shape.radius, -k)
    pieces = rounded_segment(mx, my, -sx, -sy, sx, sy, (r,), dx, dy)
    # Strictly inside the open capsule (the union of the pieces): inside one piece at tau = 0.
    if any(a < 0.0 < b for a, b, _ in pieces):
        return 0.0, None
    found = first_entry(pieces, math.inf)
    if found is None:
        return None  # no piece entered ahead of the origin: a miss, or a graze
    t_in, near = found
    _, nx, ny = pick([(0.0, nx, ny) for _, nx, ny in near], 1.0)
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


#: :func:`closest_on_segment` compiled: the capsule kernels' and the batch queries' own arithmetic
#: (one compiled copy for both).
closest_on_segment_compiled = kernel(closest_on_segment)


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
    if isinstance(shape, Segment):
        return max(abs(shape.a[0]), abs(shape.a[1]), abs(shape.b[0]), abs(shape.b[1]))
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


def scaled_outline(shape: AABB | Polygon | Segment, x: float, y: float, rotation: float, k: int) -> Pts:
    """World outline (counter-clockwise) of a box or polygon scaled by ``2**-k`` (exactly: scaled
    operands), its hitbox origin at the already scaled (x, y). AABBs ignore ``rotation``. A
    segment's outline is its two ends."""
    if isinstance(shape, AABB):
        hw, hh = math.ldexp(shape.width, -k - 1), math.ldexp(shape.height, -k - 1)
        return [(x - hw, y - hh), (x + hw, y - hh), (x + hw, y + hh), (x - hw, y + hh)]
    src = (shape.a, shape.b) if isinstance(shape, Segment) else shape.points
    pts = [(math.ldexp(px, -k), math.ldexp(py, -k)) for px, py in src]
    if rotation == 0.0:
        return [(px + x, py + y) for px, py in pts]
    c, s = math.cos(rotation), math.sin(rotation)
    return [(c * px - s * py + x, s * px + c * py + y) for px, py in pts]


def clip_polygon(
    pts: Pts, ox: float, oy: float, dx: float, dy: float
) -> tuple[float, float, list[tuple[float, float, float]]] | None:
    """Cyrus-Beck: the open interval ``(t_in, t_out)`` where ``o + t d`` is strictly inside the convex
    CCW outline, with the entering faces ``(t, nx, ny)`` (unnormalised outward normals), or
    ``None`` when the line never enters the interior (a graze along an edge or through a corner).

    Each face's time ``t = n.(v - o) / n.d`` is computed in floats with a bound on its rounding
    (:data:`~framework.collision.exact.BAND` relative to the magnitudes of the products summed).
    Where a decision is within those bounds (``n.d`` or, for a face parallel to the ray, ``n.(v - o)``
    within rounding of 0; ``t_in`` against ``t_out``, as at a corner; either against 0), the clip
    is redone on exact rationals (:func:`_clip_exact`)."""
    t_in, t_out = -math.inf, math.inf
    # Bounds on the exact t_in and t_out: each is in [lo, hi].
    in_lo = in_hi = -math.inf
    out_lo = out_hi = math.inf
    faces = []
    n = len(pts)
    for i in range(n):
        x0, y0 = pts[i]
        x1, y1 = pts[(i + 1) % n]
        nx, ny = y1 - y0, x0 - x1  # outward normal of a CCW outline, unnormalised
        ax, ay = nx * (x0 - ox), ny * (y0 - oy)
        bx, by = nx * dx, ny * dy
        num, den = ax + ay, bx + by
        mag = BAND * (abs(ax) + abs(ay))
        if abs(den) <= BAND * (abs(bx) + abs(by)) and (bx != 0.0 or by != 0.0):
            return _clip_exact(pts, ox, oy, dx, dy)  # within rounding of parallel
        if den == 0.0:  # parallel (exactly: each product is 0)
            if abs(num) <= mag:
                return _clip_exact(pts, ox, oy, dx, dy)  # within rounding of the face's line
            if num < 0.0:
                return None  # outside this face's line
            continue
        t = num / den
        err = (mag + abs(t) * BAND * (abs(bx) + abs(by))) / abs(den)
        if den < 0.0:
            faces.append((t, nx, ny))
            t_in = max(t_in, t)
            in_lo, in_hi = max(in_lo, t - err), max(in_hi, t + err)
        else:
            t_out = min(t_out, t)
            out_lo, out_hi = min(out_lo, t - err), min(out_hi, t + err)
    if in_lo < out_hi and out_lo <= in_hi:
        return _clip_exact(pts, ox, oy, dx, dy)  # t_in < t_out within rounding (a corner)
    if not t_in < t_out:
        return None
    if out_lo <= 0.0 < out_hi or in_lo <= 0.0 <= in_hi:
        return _clip_exact(pts, ox, oy, dx, dy)  # the origin within rounding of the boundary
    return t_in, t_out, faces


def _clip_exact(
    pts: Pts, ox: float, oy: float, dx: float, dy: float
) -> tuple[float, float, list[tuple[float, float, float]]] | None:
    """:func:`clip_polygon` on exact rationals: every float is an integer times a power of two, so
    ``n.(v - o)`` and ``n.d`` are exact integers over one power of two, and the times their
    exact ratios. Faces whose exact times tie get the same float time."""
    vals, _ = ints((ox, oy, dx, dy, *(c for p in pts for c in p)))
    iox, ioy, idx, idy = vals[:4]
    ipts = [(vals[4 + 2 * i], vals[5 + 2 * i]) for i in range(len(pts))]
    t_in: Fraction | None = None
    t_out: Fraction | None = None
    enter: list[tuple[Fraction, int]] = []
    n = len(ipts)
    for i in range(n):
        (x0, y0), (x1, y1) = ipts[i], ipts[(i + 1) % n]
        nx, ny = y1 - y0, x0 - x1
        num = nx * (x0 - iox) + ny * (y0 - ioy)
        den = nx * idx + ny * idy
        if den == 0:
            if num <= 0:
                return None  # parallel, on or outside this face's line
            continue
        t = Fraction(num, den)
        if den < 0:
            enter.append((t, i))
            if t_in is None or t > t_in:
                t_in = t
        elif t_out is None or t < t_out:
            t_out = t
    if t_in is None or (t_out is not None and not t_in < t_out):
        return None
    faces: list[tuple[float, float, float]] = []
    for t, i in enter:
        (fx0, fy0), (fx1, fy1) = pts[i], pts[(i + 1) % n]
        faces.append((_signed_float(t), fy1 - fy0, fx0 - fx1))  # the float normal, as clip_polygon's
    return _signed_float(t_in), math.inf if t_out is None else _signed_float(t_out), faces


def _signed_float(t: Fraction) -> float:
    """``t`` as a float, never rounded to 0 unless it is 0, and infinite beyond float's range (a face
    all but parallel to a ray whose direction has a subnormal component: 0.5 / 5e-324)."""
    try:
        f = float(t)
    except OverflowError:
        return math.inf if t > 0 else -math.inf
    if f == 0.0 and t != 0:
        return math.copysign(TINY, t)
    return f
