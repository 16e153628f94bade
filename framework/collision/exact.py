"""Exact decisions near touching: the one numeric core of the scalar queries and the batch kernels.

Floats decide every pair whose answer is clear by far more than their rounding error. Inside a thin
band around "touching" (``BAND`` relative to the magnitudes involved) the decision is redone here
on exact integers: every float is an integer times a power of two, so the offset between the two
shapes and their sizes become integers over one common power of two ``2**e``, and sums, products
and comparisons of them are exact. Touching is then never a collision and an overlap of one ulp
always is, whichever code path the floats took.

Everything is in a query's scaled local frame: shapes in their own local coordinates times
``2**-k``, and the offset between the two hitbox origins ``(q - o) * 2**-k``, passed as an
:data:`Offset` ``(ox, oy, qx, qy, k)`` so that it stays exact.

The functions below decide and return integers; each caller turns them into the float depth,
normal and point of its own arithmetic: :mod:`~framework.collision.collide` with
:func:`float_approx` and :func:`ratio_approx`, the batch kernels with :func:`float_rounded`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Literal, NamedTuple

__all__ = [
    "BAND", "TINY", "Offset", "PolygonCircleExact", "circle_circle_exact", "exact_ints", "float_approx",
    "float_rounded", "polygon_circle_exact", "polygon_polygon_exact", "ratio_approx", "rounded_exact",
    "vertex_contact",
]

# Half-width of the band, relative to the magnitudes involved, inside which a float decision is not
# trusted and the overlap is decided exactly. Float rounding is below 1e-15 of those magnitudes; the
# band only has to be wider than that, and narrow enough to be rare.
BAND = 1e-13
# Smallest positive float: the floor of every depth, so "depth > 0" holds even in cases (an overlap
# far below the scene's resolution) where the division underflows.
TINY = 5e-324

Offset = tuple[float, float, float, float, int]  # ox, oy, qx, qy, k: the offset is (q - o) * 2**-k
Pts = Sequence[tuple[float, float]]


# --- integers and back --------------------------------------------------------------------------

def exact_ints(offset: Offset, values: Sequence[float]) -> tuple[int, int, list[int], int]:
    """``(ex, ey, ints, e)``: the exact offset and ``values`` as integers over one power of two,
    each standing for ``n * 2**e``."""
    ox, oy, qx, qy, k = offset
    parts = []
    for v, shift in ((qx, -k), (ox, -k), (qy, -k), (oy, -k), *((v, 0) for v in values)):
        num, den = float(v).as_integer_ratio()  # den is a power of two
        parts.append((num, shift - den.bit_length() + 1))
    e = min(p[1] for p in parts)
    n = [num << (q - e) for num, q in parts]
    return n[0] - n[1], n[2] - n[3], n[4:], e


def float_rounded(n: int, e: int) -> float:
    """``n * 2**e``, correctly rounded (the batch kernels' conversion)."""
    return float(n << e) if e >= 0 else n / (1 << -e)


def float_approx(n: int, e: int) -> float:
    """``n * 2**e`` from the leading 64 bits of ``n``: to within 2**-63 relative, and nonzero stays
    nonzero (bar underflow) (the scalar queries' conversion)."""
    s = max(0, n.bit_length() - 64)
    m = float(n >> s) if n >= 0 else -float((-n) >> s)
    return math.ldexp(m, e + s)


def ratio_approx(num: int, den: int, e: int) -> float:
    """``num / den * 2**e`` (``den > 0``) as a float, to within 2**-60 relative."""
    shift = 64 - (num.bit_length() - den.bit_length())
    q = (num << shift) // den if shift >= 0 else num // (den << -shift)
    return float_approx(q, e - shift)


# --- the decisions ------------------------------------------------------------------------------

def circle_circle_exact(offset: Offset, ra: float, rb: float) -> tuple[int, int] | None:
    """Circles of radius ``ra`` at the origin and ``rb`` at the offset: ``(num, u)`` with
    ``num * 2**u = (ra + rb)^2 - |d|^2 > 0`` where they overlap, else ``None``."""
    ex, ey, (era, erb), e = exact_ints(offset, (ra, rb))
    num = (era + erb) ** 2 - ex * ex - ey * ey
    return None if num <= 0 else (num, 2 * e)


class PolygonCircleExact(NamedTuple):
    """An exact polygon / circle overlap: where the circle's centre lies and the integers its
    contact is made of, each standing for ``n * 2**u`` with the unit ``u`` given (``e`` below)."""

    case: str  # "inside" (or on the boundary), "face" (nearest a face) or "vertex" (nearest a vertex)
    # (The field shadows tuple.index, which nothing calls on this record: mypy flags the override.)
    index: int  # type: ignore[assignment]  # "face": the edge from vertex ``index`` to the next; "vertex": the vertex
    seps: list[int]  # per edge: the centre's distance outside its line, times the edge's length (2e)
    num: int  # "face": r^2 |edge|^2 - seps[index]^2 (4e); "vertex": r^2 - |centre - vertex|^2 (2e)
    edge2: int  # "face": |edge|^2 (2e)
    dx: int  # "vertex": centre - vertex (e)
    dy: int
    e: int


def polygon_circle_exact(poly: Pts, offset: Offset, r: float) -> PolygonCircleExact | None:
    """Convex CCW outline at the origin against the circle of radius ``r`` at the offset, on exact
    integers: ``None`` if they do not overlap (touching is no overlap). An outline of two points is
    a segment: its centre is "inside" only on the segment itself."""
    n = len(poly)
    ecx, ecy, rest, e = exact_ints(offset, [r, *(c for p in poly for c in p)])
    er, pts = rest[0], [(rest[1 + 2 * i], rest[2 + 2 * i]) for i in range(n)]
    seps = []
    for i in range(n):
        (x0, y0), (x1, y1) = pts[i], pts[(i + 1) % n]
        seps.append((y1 - y0) * (ecx - x0) - (x1 - x0) * (ecy - y0))
    on_segment = n != 2 or 0 <= (ecx - pts[0][0]) * (pts[1][0] - pts[0][0]) + (ecy - pts[0][1]) * (
        pts[1][1] - pts[0][1]) <= (pts[1][0] - pts[0][0]) ** 2 + (pts[1][1] - pts[0][1]) ** 2
    if any(pts[i] != pts[(i + 1) % n] for i in range(n)) and all(s <= 0 for s in seps) and on_segment:
        # Inside or on the boundary: always an overlap (r > 0).
        return PolygonCircleExact("inside", -1, seps, 0, 0, 0, 0, e)
    # Outside: the nearest point is on the first face whose region holds the centre, or a vertex.
    for i in range(n):
        s = seps[i]
        if s <= 0:
            continue  # (also every edge of length zero)
        (x0, y0), (x1, y1) = pts[i], pts[(i + 1) % n]
        ex, ey = x1 - x0, y1 - y0
        edge2 = ex * ex + ey * ey
        if 0 <= (ecx - x0) * ex + (ecy - y0) * ey <= edge2:
            # distance s / |e| < r  <=>  s^2 < r^2 |e|^2
            num = er * er * edge2 - s * s
            return None if num <= 0 else PolygonCircleExact("face", i, seps, num, edge2, 0, 0, e)
    j = min(range(n), key=lambda i: (ecx - pts[i][0]) ** 2 + (ecy - pts[i][1]) ** 2)
    dx, dy = ecx - pts[j][0], ecy - pts[j][1]
    num = er * er - dx**2 - dy**2
    return None if num <= 0 else PolygonCircleExact("vertex", j, seps, num, 0, dx, dy, e)


def vertex_contact(found: PolygonCircleExact, poly: Pts, r: float, f: float,
                   to_float: Callable[[int, int], float]) -> tuple[float, float, float, float, float]:
    """The contact of a ``"vertex"`` overlap: ``(nx, ny, depth, px, py)``, the normal from the
    vertex toward the circle's centre (``(0, f)`` if the centre is on it) times ``f`` (-1: the
    circle is shape A), the depth ``r - |d|`` as ``(r^2 - |d|^2) / (r + |d|)``, the point the
    vertex. ``to_float``: the caller's conversion of ``n * 2**e`` (:func:`float_rounded` for the
    batch kernels, :func:`float_approx` for the scalar queries)."""
    e, j = found.e, found.index
    ddx, ddy = to_float(found.dx, e), to_float(found.dy, e)
    dist = math.hypot(ddx, ddy)
    depth = max(to_float(found.num, 2 * e) / (r + dist), TINY)
    nx, ny = (ddx / dist, ddy / dist) if dist > 0.0 else (0.0, f)  # (0, f): up once turned round
    return f * nx, f * ny, depth, poly[j][0], poly[j][1]


def _extent(pts: list[tuple[int, int]], ux: int, uy: int) -> tuple[int, int]:
    proj = [ux * x + uy * y for x, y in pts]
    return min(proj), max(proj)


def polygon_polygon_exact(
    pa: Pts, lb: Pts, offset: Offset
) -> tuple[dict[tuple[int, int], tuple[int, int]], int] | None:
    """Separating axes on exact integers for convex CCW outlines A at the origin and B (``lb``,
    about its own origin) at the offset: ``None`` if separated or touching, else ``(found, u)``:
    per axis, keyed ``(0 for A / 1 for B, edge index)`` for every edge of nonzero length in order,
    how far B must move forward (+axis) and backward, times the axis's length, in units of ``2**u``.
    The axes are the unnormalised outward edge normals ``(ey, -ex)``."""
    ex, ey, rest, e = exact_ints(offset, [c for p in (*pa, *lb) for c in p])
    pts = [(rest[2 * i], rest[2 * i + 1]) for i in range(len(rest) // 2)]
    ia, ib = pts[: len(pa)], pts[len(pa):]
    found = {}
    for which, poly in enumerate((ia, ib)):
        n = len(poly)
        for i in range(n):
            (x0, y0), (x1, y1) = poly[i], poly[(i + 1) % n]
            if (x0, y0) == (x1, y1):
                continue
            ux, uy = y1 - y0, x0 - x1
            amin, amax = _extent(ia, ux, uy)
            bmin, bmax = _extent(ib, ux, uy)
            ud = ux * ex + uy * ey
            fwd, bwd = (amax - bmin) - ud, (bmax - amin) + ud
            if fwd <= 0 or bwd <= 0:
                return None
            found[which, i] = (fwd, bwd)
    return found, 2 * e


# --- rounded cores (pairs with a capsule) ---------------------------------------------------------

def _point_segment_excess(px: int, py: int, s0: tuple[int, int], s1: tuple[int, int], r2: int) -> tuple[int, int]:
    """``(num, den)`` with ``num / den = R^2 - d^2``, ``d`` the distance from p to the segment
    s0 s1 (a point if s0 == s1), ``r2 = R^2``."""
    ex, ey = s1[0] - s0[0], s1[1] - s0[1]
    e2 = ex * ex + ey * ey
    wx, wy = px - s0[0], py - s0[1]
    t = wx * ex + wy * ey
    if e2 == 0 or t <= 0:
        return r2 - wx * wx - wy * wy, 1
    if t >= e2:
        vx, vy = px - s1[0], py - s1[1]
        return r2 - vx * vx - vy * vy, 1
    cross = ex * wy - ey * wx
    return r2 * e2 - cross * cross, e2


def rounded_exact(
    pa: Pts, lb: Pts, offset: Offset, ra: float, rb: float
) -> tuple[Literal["meet"]] | tuple[Literal["apart"], int, int, int, int] | None:
    """A segment (``pa``: its two ends, about the origin) rounded by ``ra`` against B's core
    (``lb`` about B's own origin, at the offset: one point, a segment's two ends, or a convex CCW
    outline) rounded by ``rb``, on exact integers: ``None`` if they do not overlap (the cores are
    ``R = ra + rb`` or more apart: touching is no overlap), ``("meet",)`` if the cores meet, else
    ``("apart", i, num, den, u)``: the closest points are pair ``i`` (numbered as
    :func:`framework.collision.capsule._pair_points` numbers them: each end of the segment against
    each edge of B, then each vertex of B against the segment) and ``R^2 - d^2 = num / den * 2**u > 0``.
    """
    nb = len(lb)
    ox, oy, rest, e = exact_ints(offset, [ra, rb, *(c for p in (*pa, *lb) for c in p)])
    r = rest[0] + rest[1]
    a = [(rest[2], rest[3]), (rest[4], rest[5])]
    b = [(rest[6 + 2 * j] + ox, rest[7 + 2 * j] + oy) for j in range(nb)]
    # Separating axes of the cores (complete for two convex sets, degenerate ones included: a
    # segment's normal and direction).
    ex, ey = a[1][0] - a[0][0], a[1][1] - a[0][1]
    axes = [(ey, -ex), (ex, ey)]
    if nb == 2:
        fx, fy = b[1][0] - b[0][0], b[1][1] - b[0][1]
        axes += [(fy, -fx), (fx, fy)]
    elif nb >= 3:
        axes += [(b[(j + 1) % nb][1] - b[j][1], b[j][0] - b[(j + 1) % nb][0]) for j in range(nb)]
    axes = [u for u in axes if u != (0, 0)]
    if axes:
        meet = True
        for ux, uy in axes:
            amin, amax = _extent(a, ux, uy)
            bmin, bmax = _extent(b, ux, uy)
            if amax < bmin or bmax < amin:
                meet = False
                break
    else:  # both cores scaled away to points
        meet = a[0] == b[0]
    if meet:
        return ("meet",)
    r2 = r * r
    ne = nb if nb >= 3 else 1
    pairs = []
    for k in range(2):
        for j in range(ne):
            pairs.append(_point_segment_excess(a[k][0], a[k][1], b[j], b[(j + 1) % nb], r2))
    for j in range(nb):
        pairs.append(_point_segment_excess(b[j][0], b[j][1], a[0], a[1], r2))
    best = 0
    for i in range(1, len(pairs)):
        num, den = pairs[i]
        bnum, bden = pairs[best]
        if num * bden > bnum * den:
            best = i
    num, den = pairs[best]
    if num <= 0:
        return None
    return "apart", best, num, den, 2 * e
