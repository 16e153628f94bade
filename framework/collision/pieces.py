"""A line against a rounded shape, piece by piece, with touching decided exactly.

:func:`~framework.collision.ray.raycast` and :func:`~framework.collision.sweep.time_of_impact` both
follow a point ``c + tau v`` against a convex shape rounded by a radius (a circle, a capsule, or
the Minkowski difference of two shapes one of which is round). Near its boundary the interior of
such a shape is the union of *pieces*: one open rectangle per face (the face pushed out and in by
the radius) and one open disc per vertex. Each piece gives an open interval of ``tau`` (a
:data:`Piece`), kept on its own: the first entry into the shape is the first entry into one of the
pieces (:func:`first_entry`), never the span from the earliest entry to the latest exit over all
of them (a line along a face is tangent to the discs at both its ends, and where rounding gives
each tangent a sliver of an interval, the span of two slivers would cover the whole line).

Touching is decided exactly: wherever a piece's float test is within
:data:`~framework.collision.exact.BAND` of touching (a disc's discriminant and the start's distance
from its centre, a rectangle's four sides), its sign is decided again on exact integers (every
float is an integer times a power of two), so a tangent line is always a miss and a line that goes
in by a hair always a hit.
"""

from __future__ import annotations

import math

from .exact import BAND, float_approx

__all__ = [
    "TIE", "Cands", "Piece", "clip_constraints", "disc_interval", "first_entry", "ints", "minus_root",
    "rect_interval", "rounded_segment",
]

# Entry times (in the scaled local frame, where the shapes are about 1 unit across) closer than
# this (relative to the time, when above 1) count as a tie, broken by a fixed rule, not rounding.
TIE = 1e-12

Cands = list[tuple[float, float, float]]
# One piece: (t_in, t_out, candidates (t, nx, ny) with unit normals): the open interval of tau
# during which the point is inside that piece.
Piece = tuple[float, float, Cands]


def ints(values: tuple[float, ...]) -> tuple[list[int], int]:
    """``(ints, e)``: ``values`` as integers over one common power of two, each ``n * 2**e``."""
    parts = [float(v).as_integer_ratio() for v in values]  # each denominator a power of two
    top = max(den.bit_length() for _, den in parts)
    return [num << (top - den.bit_length()) for num, den in parts], 1 - top


def minus_root(s: int, root: int, e: int) -> float:
    """``(s - sqrt(root)) * 2**e`` with its exact sign (``root`` in units of ``2**(2e)``), as a
    float: ``(s^2 - root) / (s + sqrt(root))`` where they nearly cancel."""
    if s > 0:
        return float_approx(s * s - root, 2 * e) / (float_approx(s, e) + math.sqrt(float_approx(root, 2 * e)))
    return -(float_approx(-s, e) + math.sqrt(float_approx(root, 2 * e)))


def clip_constraints(cons: list[tuple[float, float, str]]) -> tuple[float, float, set[str]] | None:
    """The open interval of ``tau`` where every ``f0 + tau f1 < 0`` holds, with the tags of the
    constraints that set its start (within :data:`TIE`), or ``None`` if it is empty."""
    t_in, t_out = -math.inf, math.inf
    enters = []
    for f0, f1, tag in cons:
        if f1 == 0.0:
            if f0 >= 0.0:
                return None
        elif f1 < 0.0:
            t = -f0 / f1
            enters.append((t, tag))
            if t > t_in:
                t_in = t
        else:
            t = -f0 / f1
            if t < t_out:
                t_out = t
    if not t_in < t_out or not enters:
        return None
    tol = TIE * max(1.0, abs(t_in))
    return t_in, t_out, {tag for t, tag in enters if t >= t_in - tol}


def rect_interval(x0: float, y0: float, x1: float, y1: float, cx: float, cy: float, r: float,
                  radii: tuple[float, ...], vx: float, vy: float) -> tuple[float, float, set[str]] | None:
    """:func:`clip_constraints` of the open rectangle of the edge p0 p1 pushed out and in by ``r``
    (the sum of ``radii``), ``0 < e.(x - p0) < e.e``, ``-r|e| < n.(x - p0) < r|e|``, for
    ``c + tau v``; tags ``start``, ``end``, ``face`` (the side pushed out along ``n = (ey, -ex)``),
    ``inner``. Where the start is within rounding of a side, the constraints are worked again
    from exact integers (the start's offsets from the sides and the motion across them, each
    with its exact sign): touching and sliding along, or moving away, is then never an entry, and
    moving in by a hair always is."""
    ex, ey = x1 - x0, y1 - y0
    nx, ny = ey, -ex
    e2 = ex * ex + ey * ey
    rl = r * math.sqrt(e2)
    qx, qy = cx - x0, cy - y0
    along = ex * qx + ey * qy
    across = nx * qx + ny * qy
    ev = ex * vx + ey * vy
    nv = nx * vx + ny * vy
    f_start, f_end, f_face, f_inner = -along, along - e2, across - rl, -across - rl
    if (min(abs(f_start), abs(f_end)) <= BAND * (abs(ex * qx) + abs(ey * qy) + e2)
            or min(abs(f_face), abs(f_inner)) <= BAND * (abs(nx * qx) + abs(ny * qy) + rl)):
        (ix0, iy0, ix1, iy1, icx, icy, ivx, ivy, *irs), e = ints((x0, y0, x1, y1, cx, cy, vx, vy, *radii))
        iex, iey, iqx, iqy, ir = ix1 - ix0, iy1 - iy0, icx - ix0, icy - iy0, sum(irs)
        ialong = iex * iqx + iey * iqy
        iacross = iey * iqx - iex * iqy
        ie2 = iex * iex + iey * iey
        f_start = float_approx(-ialong, 2 * e)
        f_end = float_approx(ialong - ie2, 2 * e)
        f_face = minus_root(iacross, ir * ir * ie2, 2 * e)
        f_inner = minus_root(-iacross, ir * ir * ie2, 2 * e)
        ev = float_approx(iex * ivx + iey * ivy, 2 * e)
        nv = float_approx(iey * ivx - iex * ivy, 2 * e)
    return clip_constraints([(f_start, -ev, "start"), (f_end, ev, "end"), (f_face, nv, "face"),
                             (f_inner, -nv, "inner")])


def disc_interval(px: float, py: float, cx: float, cy: float, r: float, radii: tuple[float, ...],
                  vx: float, vy: float) -> tuple[float, float] | None:
    """The open interval ``(t1, t2)`` where ``|c + t v - p| < r`` (``r`` the sum of ``radii``), or
    ``None`` if it is empty: a tangent line touches at one point only, a graze. The discriminant is
    written as ``|v|^2 r^2 - (m x v)^2`` (no cancellation of large terms) and the root is the
    stable one; where the discriminant or ``|m|^2 - r^2`` (the start against the circle) is within
    rounding of 0, their signs are decided exactly (``v`` non-zero). The discriminant's band also
    counts the rounding of ``m x v`` itself, whose terms are large where ``c`` is far from ``p``
    (a ray cast from far away)."""
    mx, my = cx - px, cy - py
    a = vx * vx + vy * vy
    cross = mx * vy - my * vx
    rr = r * r
    disc = a * rr - cross * cross
    mm = mx * mx + my * my
    c = mm - rr
    b = mx * vx + my * vy
    if (abs(disc) <= BAND * (a * rr + abs(cross) * (abs(mx * vy) + abs(my * vx)))
            or abs(c) <= BAND * (mm + rr)):
        (ipx, ipy, icx, icy, ivx, ivy, *irs), e = ints((px, py, cx, cy, vx, vy, *radii))
        imx, imy, ir = icx - ipx, icy - ipy, sum(irs)
        icross = imx * ivy - imy * ivx
        idisc = (ivx * ivx + ivy * ivy) * ir * ir - icross * icross
        if idisc <= 0:
            return None  # tangent (or apart)
        disc = float_approx(idisc, 4 * e)
        c = float_approx(imx * imx + imy * imy - ir * ir, 2 * e)
        b = float_approx(imx * ivx + imy * ivy, 2 * e)  # (touching at the start: in or out)
    if not disc > 0.0:
        return None
    sq = math.sqrt(disc)
    if b < 0.0:
        q = sq - b  # > 0, no cancellation
        t1, t2 = c / q, q / a
    else:
        q = -b - sq  # < 0, no cancellation
        t1, t2 = q / a, c / q
    if not t1 < t2:
        # The line does enter the disc (the discriminant is > 0, exactly or by far more than its
        # rounding), but by less than the times' resolution (a hair, or from very far away).
        t2 = math.nextafter(t1, math.inf)
    return t1, t2


def rounded_segment(cx: float, cy: float, s0x: float, s0y: float, s1x: float, s1y: float,
                    radii: tuple[float, ...], vx: float, vy: float) -> list[Piece]:
    """``c + tau v`` against the segment s0 s1 rounded by the sum of ``radii`` (one radius, or two
    summed exactly): an open rectangle and two open discs, with their entry normals (unit, outward:
    the side's through a side, from the disc's centre through a disc; a rectangle entered through
    an end only has none: the disc there, entered no later, gives it)."""
    r = radii[0] if len(radii) == 1 else radii[0] + radii[1]
    pieces: list[Piece] = []
    ex, ey = s1x - s0x, s1y - s0y
    e2 = ex * ex + ey * ey
    if e2 > 0.0:
        nx, ny = ey, -ex
        ln = math.sqrt(e2)
        rect = rect_interval(s0x, s0y, s1x, s1y, cx, cy, r, radii, vx, vy)
        if rect is not None:
            a, b, tags = rect
            if "face" in tags:
                pieces.append((a, b, [(a, nx / ln, ny / ln)]))
            elif "inner" in tags:
                pieces.append((a, b, [(a, -nx / ln, -ny / ln)]))
            else:
                pieces.append((a, b, []))
    for px, py in ((s0x, s0y), (s1x, s1y)):
        iv = disc_interval(px, py, cx, cy, r, radii, vx, vy)
        if iv is not None:
            a, b = iv
            t = a if a > 0.0 else 0.0
            hx, hy = cx - px + t * vx, cy - py + t * vy
            hl = math.hypot(hx, hy)
            pieces.append((a, b, [(a, hx / hl, hy / hl) if hl > 0.0 else (a, 0.0, 1.0)]))
    return pieces


def first_entry(pieces: list[Piece], end: float) -> tuple[float, Cands] | None:
    """The first moment of ``[0, end)`` inside one of the pieces, and the candidate normals of the
    pieces entered then (within :data:`TIE`), or ``None`` if no piece's open interval meets
    ``[0, end)``. Pieces that only touch (an empty interval: a tangent or a slide along a side) and
    pieces wholly before 0 or at or after the end do not count, whatever the others span."""
    valid = [(max(a, 0.0), a, cands) for a, b, cands in pieces if a < b and b > 0.0 and a < end]
    if not valid:
        return None
    first = min(v[0] for v in valid)
    tol = TIE * max(1.0, first)
    near = []
    for entry, a, cands in valid:
        if entry <= first + tol:
            ta = TIE * max(1.0, abs(a))
            near += [c for c in cands if abs(c[0] - a) <= ta]
    if not near:
        # Entered through an end of a rounded segment's rectangle only: the disc there is entered
        # no later in exact arithmetic (by a hair later in rounding), and gives the normal.
        later = sorted((v for v in valid if v[2]), key=lambda v: v[0])
        if not later:
            return None
        _, a, cands = later[0]
        ta = TIE * max(1.0, abs(a))
        near = [c for c in cands if abs(c[0] - a) <= ta]
    return first, near
