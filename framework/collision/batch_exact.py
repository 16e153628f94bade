"""Exact decisions for the few batch rows that floats cannot decide.

The kernels decide every pair with floats, as the scalar code does, unless the float answer lies
within a thin band (``BAND`` relative to the magnitudes involved) around "touching". Those rows,
rare outside deliberately touching scenes, are decided here one by one on exact integers (every
float is an integer times a power of two): touching is never a collision and an overlap of one
ulp always is. The answer is the exact one, so it is the scalar code's whatever path it took.

Everything is in a kernel's scaled local frame: shapes in their own local coordinates times
``2**-k`` and the offset between the two hitbox origins ``(q - o) * 2**-k``, exact.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from .batch_common import TINY
from .tiebreak import pick

__all__ = ["BAND", "TINY", "circle_circle_exact", "polygon_circle_exact", "polygon_polygon_exact"]

# Half-width of the band, relative to the magnitudes involved, inside which a float decision is
# not trusted (float rounding is below 1e-15 of them). The scalar code uses the same band.
BAND = 1e-13

Pts = Sequence[tuple[float, float]]
Offset = tuple[float, float, float, float, int]  # ox, oy, qx, qy, k: the offset is (q - o) * 2**-k


def _ints(offset: Offset, values: Sequence[float]) -> tuple[int, int, list[int], int]:
    """The exact offset and ``values`` as integers over one power of two ``2**e``."""
    ox, oy, qx, qy, k = offset
    parts = []
    for v, shift in ((qx, -k), (ox, -k), (qy, -k), (oy, -k), *((v, 0) for v in values)):
        num, den = float(v).as_integer_ratio()  # den is a power of two
        parts.append((num, shift - den.bit_length() + 1))
    e = min(p[1] for p in parts)
    n = [num << (q - e) for num, q in parts]
    return n[0] - n[1], n[2] - n[3], n[4:], e


def _float(n: int, e: int) -> float:
    """``n * 2**e``, correctly rounded."""
    return float(n << e) if e >= 0 else n / (1 << -e)


def circle_circle_exact(offset: Offset, ra: float, rb: float) -> float | None:
    """``(ra + rb)^2 - |d|^2`` (> 0: overlap) as a float, or ``None`` if they do not overlap."""
    ex, ey, (era, erb), e = _ints(offset, (ra, rb))
    num = (era + erb) ** 2 - ex * ex - ey * ey
    return None if num <= 0 else _float(num, 2 * e)


def polygon_circle_exact(
    poly: Pts, offset: Offset, r: float, cx: float, cy: float, size: float, f: float
) -> tuple[float, float, float, float, float] | None:
    """Convex CCW polygon at the origin, circle of radius ``r`` at the exact offset (float
    (cx, cy)): ``(nx, ny, depth, px, py)`` with the normal times ``f``, or ``None``."""
    n = len(poly)
    ecx, ecy, rest, e = _ints(offset, [r, *(c for p in poly for c in p)])
    er, pts = rest[0], [(rest[1 + 2 * i], rest[2 + 2 * i]) for i in range(n)]
    seps = []
    for i in range(n):
        (x0, y0), (x1, y1) = pts[i], pts[(i + 1) % n]
        seps.append((y1 - y0) * (ecx - x0) - (x1 - x0) * (ecy - y0))
    if any(pts[i] != pts[(i + 1) % n] for i in range(n)) and all(s <= 0 for s in seps):
        # Inside or on the boundary: an overlap (r > 0), depth r + distance to the nearest face.
        cands = []
        for i in range(n):
            (x0, y0), (x1, y1) = poly[i], poly[(i + 1) % n]
            ex, ey = x1 - x0, y1 - y0
            ln = math.hypot(ex, ey)
            if ln > 0.0:
                cands.append((r - _float(seps[i], 2 * e) / ln, f * ey / ln, -f * ex / ln))
        depth, nx, ny = pick(cands, size)
        return nx, ny, max(depth, TINY), cx, cy
    for i in range(n):
        s = seps[i]
        if s <= 0:
            continue
        (x0, y0), (x1, y1) = pts[i], pts[(i + 1) % n]
        ex, ey = x1 - x0, y1 - y0
        e2 = ex * ex + ey * ey
        t = (ecx - x0) * ex + (ecy - y0) * ey
        if 0 <= t <= e2:
            # distance s / |e| < r  <=>  s^2 < r^2 |e|^2; depth = (r^2 |e|^2 - s^2) / (|e| (r |e| + s)).
            num = er * er * e2 - s * s
            if num <= 0:
                return None
            (fx0, fy0), (fx1, fy1) = poly[i], poly[(i + 1) % n]
            fex, fey = fx1 - fx0, fy1 - fy0
            ln = math.hypot(fex, fey)
            fs = _float(s, 2 * e)
            depth = max(_float(num, 4 * e) / (ln * (r * ln + fs)), TINY)
            nx, ny = fey / ln, -fex / ln
            dist = fs / ln
            return f * nx, f * ny, depth, cx - nx * dist, cy - ny * dist
    j = min(range(n), key=lambda i: (ecx - pts[i][0]) ** 2 + (ecy - pts[i][1]) ** 2)
    num = er * er - (ecx - pts[j][0]) ** 2 - (ecy - pts[j][1]) ** 2
    if num <= 0:
        return None
    ddx, ddy = _float(ecx - pts[j][0], e), _float(ecy - pts[j][1], e)
    dist = math.hypot(ddx, ddy)
    depth = max(_float(num, 2 * e) / (r + dist), TINY)
    nx, ny = (ddx / dist, ddy / dist) if dist > 0.0 else (0.0, f)  # (0, f): up once turned round
    return f * nx, f * ny, depth, poly[j][0], poly[j][1]


def _extent(pts: list[tuple[int, int]], ux: int, uy: int) -> tuple[int, int]:
    proj = [ux * x + uy * y for x, y in pts]
    return min(proj), max(proj)


def polygon_polygon_exact(pa: Pts, lb: Pts, offset: Offset) -> list[tuple[float, float]] | None:
    """Separating axes on exact integers: ``None`` if separated or touching, else per axis (A's
    then B's nonzero edges, in order) how far B must move forward and backward, times ``|u|``."""
    ex, ey, rest, e = _ints(offset, [c for p in (*pa, *lb) for c in p])
    pts = [(rest[2 * i], rest[2 * i + 1]) for i in range(len(rest) // 2)]
    ia, ib = pts[: len(pa)], pts[len(pa):]
    out = []
    for poly in (ia, ib):
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
            out.append((_float(fwd, 2 * e), _float(bwd, 2 * e)))
    return out
