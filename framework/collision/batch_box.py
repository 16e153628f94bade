"""Batch kernel for axis-aligned box pairs.

The overlap decision is exact and fully vectorised: the boxes' interiors overlap iff
``|qx - ox| < hwa + hwb`` and the same in y, on the exact reals. Each side is a float plus an exact
rounding error (Knuth's TwoSum), and two such double-doubles compare exactly: rounding is
monotonic, so unequal leading parts decide, and equal ones leave it to the tails. This is the
scalar code's decision, which is exact too (floats where clear, integers near touching), without
its per-pair integer fallback: exactly touching boxes, common in tile worlds, cost nothing extra.

Depths and normals follow the scalar code, which treats two AABBs as two 4-vertex polygons. Their
8 separating axes collapse to two scales per direction, and their 16 push-out candidates to 4
directions with 2 depths each. In the scaled frame, A's outline is ``(±hwa, ±hha)`` and B's
``(±hwb, ±hhb)`` about its own origin, at offset d. A's bottom and top edges give the axes
``(0, ∓c)`` with ``c = 2 hwa`` (the ``0 * x`` terms add signed zeros only), along which B must move
up by ``(c hha + c hhb) - c dy`` or down by ``(c hha + c hhb) + c dy``, times ``|u| = c``; B's edges
give the same with ``c = 2 hwb``; the side edges the same in x. Within the band around touching,
where the scalar code takes its depths from exact overlaps, so does this kernel (double-double).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..compiled import kernel, leaf
from .batch_common import F64, ContactArrays, columns, finish, frame, sum_leading
from .batch_point import overlap_point
from .collide import POINT_TOL
from .exact import BAND, TINY
from .tiebreak import DEPTH_TOL

__all__ = ["aabb_aabb", "aabb_aabb_fast", "aabb_pairs_fast"]


def _two_sum(a: NDArray[np.float64], b: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(s, e)``: ``s = fl(a + b)`` and ``s + e == a + b`` exactly (Knuth; no overflow)."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


def _reach(o, q, ha, hb):
    """Offset ``q - o`` and reach ``ha + hb`` on one axis, each as an exact double-double."""
    return (*_two_sum(q, -o), *_two_sum(ha, hb))


def _dd_overlap(dh, dl, rh, rl) -> NDArray[np.float64]:
    """``(rh + rl) - |dh + dl|`` (reach less distance), to about double-double accuracy."""
    sgn = np.where(dh < 0.0, -1.0, 1.0)
    return (rh - np.abs(dh)) + (rl - sgn * dl)


def _less(dh, dl, rh, rl) -> NDArray[np.bool_]:
    """``|dh + dl| < rh + rl`` exactly (``dh``, ``rh`` the rounded leading parts, ``rh >= 0``)."""
    adh = np.abs(dh)
    return (adh < rh) | ((adh == rh) & (np.sign(dh) * dl < rl))


def _overlaps(hwa, hha, hwb, hhb, dx, dy):
    """Per axis scale (A's, B's): B's move up, down, right and left, times the scale."""
    up, down, right, left = [], [], [], []
    for c in (hwa + hwa, hwb + hwb):
        both = c * hha + c * hhb
        up.append(both - c * dy)
        down.append(both + c * dy)
    for c in (hha + hha, hhb + hhb):
        both = c * hwa + c * hwb
        right.append(both - c * dx)
        left.append(both + c * dx)
    return up, down, right, left


def aabb_aabb(ax, ay, ahw, ahh, bx, by, bhw, bhh) -> ContactArrays:
    """Axis-aligned boxes: centres (ax, ay), (bx, by) and half extents (``ahw``, ``ahh``),
    (``bhw``, ``bhh``), all ``[P]``; the contacts of ``collide(AABB, .., AABB, ..)``."""
    ax, ay, ahw, ahh, bx, by, bhw, bhh = columns(ax, ay, ahw, ahh, bx, by, bhw, bhh)
    rx, ry = _reach(ax, bx, ahw, bhw), _reach(ay, by, ahh, bhh)
    hit = _less(*rx) & _less(*ry)
    h = np.flatnonzero(hit)
    ax, ay, ahw, ahh, bx, by, bhw, bhh = (v[h] for v in (ax, ay, ahw, ahh, bx, by, bhw, bhh))
    rx, ry = (tuple(v[h] for v in r) for r in (rx, ry))
    ra, rb = np.hypot(ahw, ahh), np.hypot(bhw, bhh)
    dx, dy, k = frame(ax, ay, bx, by, np.maximum(ra, rb))
    hwa, hha, hwb, hhb = (np.ldexp(v, -k) for v in (ahw, ahh, bhw, bhh))
    size = np.ldexp(ra + rb, -k)
    scales = (hwa + hwa, hwb + hwb, hha + hha, hhb + hhb)
    up, down, right, left = _overlaps(hwa, hha, hwb, hhb, dx, dy)
    # Depths: the 16 candidates of the scalar code are 4 directions with 2 depths each (one per
    # axis scale); the duplicates (A's bottom edge backward = its top edge forward, ...) are equal.
    wa, wb, ha, hb = scales
    up = np.minimum(np.maximum(up[0] / wa, TINY), np.maximum(up[1] / wb, TINY))
    down = np.minimum(np.maximum(down[0] / wa, TINY), np.maximum(down[1] / wb, TINY))
    right = np.minimum(np.maximum(right[0] / ha, TINY), np.maximum(right[1] / hb, TINY))
    left = np.minimum(np.maximum(left[0] / ha, TINY), np.maximum(left[1] / hb, TINY))
    # Within the band around touching, depths from the exact overlaps: reach -/+ offset.
    mag = size + np.abs(dx) + np.abs(dy)
    near = (np.minimum(np.minimum(up, down), np.minimum(right, left)) <= 2.0 * BAND * mag)
    if near.any():
        for (dh, dl, rh, rl), plus, minus in ((rx, right, left), (ry, up, down)):
            fwd = np.ldexp((rh - dh) + (rl - dl), -k)
            bwd = np.ldexp((rh + dh) + (rl + dl), -k)
            plus[near] = np.maximum(fwd, TINY)[near]
            minus[near] = np.maximum(bwd, TINY)[near]
    # The tie-break rule: keep the near-shortest; prefer vertical; then up (or right).
    lim = np.minimum(np.minimum(up, down), np.minimum(right, left)) + DEPTH_TOL * size
    vertical = (up <= lim) | (down <= lim)
    use_up, use_right = up <= lim, right <= lim
    depth = np.where(vertical, np.where(use_up, up, down), np.where(use_right, right, left))
    nx = np.where(vertical, 0.0, np.where(use_right, 1.0, -1.0))
    ny = np.where(vertical, np.where(use_up, 1.0, -1.0), 0.0)
    px, py = _box_point(hwa, hha, hwb, hhb, dx, dy, nx, ny, depth, size)
    return finish(hit, nx, ny, depth, px, py, k, ax, ay)


def _crossing(t: NDArray[np.float64], u: NDArray[np.float64], gone: NDArray[np.bool_]) -> NDArray[np.float64]:
    """1.0 where two edges cross (``t`` and ``u`` in [0, 1]; a vanished edge never crosses)."""
    return ((t >= 0.0) & (t <= 1.0) & (u >= 0.0) & (u <= 1.0) & ~gone).astype(F64)


def _corners_inside(hwa, hha, xb0, xb1, yb0, yb1, tol):
    """Sums of the x and y of A's corners inside B and B's corners inside A (B's outline
    ``[xb0, xb1] x [yb0, yb1]`` at its offset, A's ``(±hwa, ±hha)``), and their number."""
    wa, ha = hwa + hwa, hha + hha  # A's edge lengths; B's as the scalar code gets them:
    wb, hb = xb1 - xb0, yb1 - yb0

    def a_in_b_x(x):  # B's right edge (origin (xb1, yb0)) and left edge (origin (xb0, yb1))
        return ~((-(hb * (x - xb1)) < -tol * hb) | ((hb * (x - xb0)) < -tol * hb))

    def a_in_b_y(y):  # B's bottom edge (origin (xb0, yb0)) and top edge (origin (xb1, yb1))
        return ~((wb * (y - yb0) < -tol * wb) | ((-wb) * (y - yb1) < -tol * wb))

    def b_in_a_x(x):
        return ~((-(ha * (x - hwa)) < -tol * ha) | ((ha * (x - (-hwa))) < -tol * ha))

    def b_in_a_y(y):
        return ~((wa * (y - (-hha)) < -tol * wa) | ((-wa) * (y - hha) < -tol * wa))

    sx = np.zeros(hwa.shape, dtype=F64)
    sy = np.zeros(hwa.shape, dtype=F64)
    count = np.zeros(hwa.shape, dtype=F64)
    for xs, ys, in_x, in_y in (((-hwa, hwa), (-hha, hha), a_in_b_x, a_in_b_y),
                               ((xb0, xb1), (yb0, yb1), b_in_a_x, b_in_a_y)):
        mx = [in_x(x).astype(F64) for x in xs]
        my = [in_y(y).astype(F64) for y in ys]
        nxin, nyin = mx[0] + mx[1], my[0] + my[1]
        sx += (xs[0] * mx[0] + xs[1] * mx[1]) * nyin
        sy += (ys[0] * my[0] + ys[1] * my[1]) * nxin
        count += nxin * nyin
    return sx, sy, count


def _edge_crossings(hwa, hha, xb0, xb1, yb0, yb1):
    """Sums of the x and y of the crossings of A's edges with B's, and their number.

    A's bottom / top edges cross B's right / left ones, and A's right / left edges B's bottom /
    top ones. With the zero components of the edge vectors written out, the scalar code's
    den = rx sy - ry sx, t = (wx sy - wy sx) / den and u = (wx ry - wy rx) / den lose terms that
    are signed zeros (changing no comparison and no sum).
    """
    wa, ha = hwa + hwa, hha + hha
    wb, hb = xb1 - xb0, yb1 - yb0

    def stack(*v):
        return np.stack(v)

    # A horizontal (origin p, vector (r, 0)) x B vertical (origin q, vector (0, s)).
    p_x, p_y, r = stack(-hwa, -hwa, hwa, hwa), stack(-hha, -hha, hha, hha), stack(wa, wa, -wa, -wa)
    q_x, q_y, s_ = stack(xb1, xb0, xb1, xb0), stack(yb0, yb1, yb0, yb1), stack(hb, -hb, hb, -hb)
    den = r * s_
    gone = den == 0.0  # a box edge has vanished (extreme size ratios): no crossing
    den += gone
    t = ((q_x - p_x) * s_) / den
    u = (-((q_y - p_y) * r)) / den
    hx, hy, hcross = p_x + np.minimum(np.maximum(t, 0.0), 1.0) * r, p_y, _crossing(t, u, gone)
    # A vertical (origin p, vector (0, r)) x B horizontal (origin q, vector (s, 0)).
    p_x, p_y, r = stack(hwa, hwa, -hwa, -hwa), stack(-hha, -hha, hha, hha), stack(ha, ha, -ha, -ha)
    q_x, q_y, s_ = stack(xb0, xb1, xb0, xb1), stack(yb0, yb1, yb0, yb1), stack(wb, -wb, wb, -wb)
    den = -(r * s_)
    gone = den == 0.0
    den += gone
    t = (-((q_y - p_y) * s_)) / den
    u = ((q_x - p_x) * r) / den
    vx, vy, vcross = p_x, p_y + np.minimum(np.maximum(t, 0.0), 1.0) * r, _crossing(t, u, gone)
    return (sum_leading(hx * hcross) + sum_leading(vx * vcross),
            sum_leading(hy * hcross) + sum_leading(vy * vcross),
            sum_leading(hcross) + sum_leading(vcross))


def _box_point(hwa, hha, hwb, hhb, dx, dy, nx, ny, depth, size):
    """``collide.overlap_point`` of two boxes, with B at its offset: the mean of A's corners in B,
    B's corners in A and the crossings of their edges, each counted by the scalar code's tests.

    For boxes those tests separate: an edge's cross product ``ex (y - y0) - ey (x - x0)`` has one
    term ``0 * (...)``, a signed zero that changes no comparison, so a corner is inside when its x
    passes the two side edges and its y the bottom and top edges; and only the 8 perpendicular
    edge pairs can cross (parallel ones have ``den == 0`` exactly and are skipped).
    """
    xb0, xb1, yb0, yb1 = -hwb + dx, hwb + dx, -hhb + dy, hhb + dy
    sx, sy, count = _corners_inside(hwa, hha, xb0, xb1, yb0, yb1, POINT_TOL * size)
    cross_x, cross_y, crossings = _edge_crossings(hwa, hha, xb0, xb1, yb0, yb1)
    sx += cross_x
    sy += cross_y
    count += crossings
    found = count > 0
    c = np.maximum(count, 1.0)
    px, py = sx / c, sy / c
    if not found.all():
        # Rounding hid every vertex (near-degenerate only): the generic fallback.
        m = np.flatnonzero(~found)
        four = np.full(m.size, 4)
        avx = np.stack((-hwa[m], hwa[m], hwa[m], -hwa[m]))
        avy = np.stack((-hha[m], -hha[m], hha[m], hha[m]))
        bvx = np.stack((xb0[m], xb1[m], xb1[m], xb0[m]))
        bvy = np.stack((yb0[m], yb0[m], yb1[m], yb1[m]))
        px[m], py[m] = overlap_point(avx, avy, four, bvx, bvy, four, nx[m], ny[m], depth[m], size[m])
    return px, py


def aabb_aabb_fast(ax, ay, ahw, ahh, bx, by, bhw, bhh, *, exact: bool = True, points: bool = True) -> ContactArrays:
    """:func:`aabb_aabb` for the pipeline's hot path: the same overlap decisions, normals and
    depths (to rounding), but the contact point is the centre of the overlap rectangle.

    That centre is the mean of the rectangle's corners, which is what :func:`aabb_aabb` (and
    ``collide``) average except where corners coincide; it lies in the overlap region either way.
    Rows are decided with plain floats where the answer is clear; those within the rounding band
    around touching (boxes just pushed apart, common) are decided exactly on double-doubles, as
    :func:`aabb_aabb` decides them, with double-double push-outs; extreme magnitudes go through
    :func:`aabb_aabb`. With ``exact=False`` rows within about 1e-12 of the sizes of touching count
    as not overlapping (the response re-measuring pairs it has just pushed apart: such an overlap
    is not worth resolving), and with ``points=False`` the points are left at 0.
    """
    ax, ay, ahw, ahh, bx, by, bhw, bhh = columns(ax, ay, ahw, ahh, bx, by, bhw, bhh)
    hit, nx, ny, depth, px, py, extreme = _aabb_rows(ax, ay, ahw, ahh, bx, by, bhw, bhh, exact, points)
    return _with_extremes(ContactArrays(hit, nx, ny, depth, px, py), extreme, exact, ax, ay, ahw, ahh, bx, by, bhw, bhh)


def aabb_pairs_fast(ra, rb, hx, hy, hw, hh, *, exact: bool = True, points: bool = True) -> ContactArrays:
    """:func:`aabb_aabb_fast` of the pairs of rows ``(ra, rb)`` of the columns (hitbox origins
    ``hx, hy``, half sizes ``hw, hh``): the pipeline's narrow phase, which gathers nothing first."""
    ra, rb = np.ascontiguousarray(ra, dtype=np.int64), np.ascontiguousarray(rb, dtype=np.int64)
    flags, cols, extremes = _aabb_pairs(ra, rb, hx, hy, hw, hh, exact, points)
    hit, extreme = flags
    res = ContactArrays(hit, *cols)
    if not (exact and extremes):
        return res
    return _with_extremes(res, extreme, exact, hx[ra], hy[ra], hw[ra], hh[ra], hx[rb], hy[rb], hw[rb], hh[rb])


def _with_extremes(res: ContactArrays, extreme, exact, ax, ay, ahw, ahh, bx, by, bhw, bhh) -> ContactArrays:
    """``res`` with its rows of extreme magnitudes (``extreme``) answered by the scaled exact
    kernel (:func:`aabb_aabb`), where ``exact``."""
    e = np.flatnonzero(extreme) if exact else np.zeros(0, dtype=np.intp)
    if e.size:
        hit, nx, ny, depth, px, py = res
        ref = aabb_aabb(ax[e], ay[e], ahw[e], ahh[e], bx[e], by[e], bhw[e], bhh[e])
        hit[e] = ref.hit
        nx[e], ny[e], depth[e], px[e], py[e] = ref.nx, ref.ny, ref.depth, ref.px, ref.py
    return res



@leaf
def _two_sum_1(a, b):  # pragma: no cover - compiled
    """:func:`_two_sum` of two floats."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


@leaf
def _less_1(dh, dl, rh, rl):  # pragma: no cover - compiled
    """:func:`_less` of one row (``np.sign``'s 0 at 0 kept)."""
    adh = abs(dh)
    sign = 1.0 if dh > 0.0 else (-1.0 if dh < 0.0 else 0.0)
    return adh < rh or (adh == rh and sign * dl < rl)


@leaf
def _dd_overlap_1(dh, dl, rh, rl):  # pragma: no cover - compiled
    """:func:`_dd_overlap` of one row."""
    sgn = -1.0 if dh < 0.0 else 1.0
    return (rh - abs(dh)) + (rl - sgn * dl)


@leaf
def _aabb_row(ax, ay, ahw, ahh, bx, by, bhw, bhh, exact, points):  # pragma: no cover - compiled
    """One row of :func:`aabb_aabb_fast` but for extreme magnitudes (flagged, for the scaled exact
    kernel): ``(hit, nx, ny, depth, px, py, extreme)``, zeros where there is no hit; the same
    arithmetic in the same order as the numpy it replaced (so the same bits). (Scalars in and out:
    passing the seven output columns to it cost more than its arithmetic.)"""
    dx, dy = bx - ax, by - ay
    adx, ady = abs(dx), abs(dy)
    sx, sy = ahw + bhw, ahh + bhh
    ox, oy = sx - adx, sy - ady
    mag = sx + sy + adx + ady
    band = (2.0**-48 if exact else 8.0 * BAND) * mag
    unclear = (abs(ox) <= band and oy >= -band) or (abs(oy) <= band and ox >= -band)
    ext = not (mag <= 1e150) or mag < 1e-150
    h = ox > 0.0 and oy > 0.0 and not unclear and not ext
    if exact and unclear and not ext:
        dxh, dxl = _two_sum_1(bx, -ax)
        rxh, rxl = _two_sum_1(ahw, bhw)
        dyh, dyl = _two_sum_1(by, -ay)
        ryh, ryl = _two_sum_1(ahh, bhh)
        h = _less_1(dxh, dxl, rxh, rxl) and _less_1(dyh, dyl, ryh, ryl)
        ox, oy = _dd_overlap_1(dxh, dxl, rxh, rxl), _dd_overlap_1(dyh, dyl, ryh, ryl)
    if not h:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, ext
    nx = ny = depth = px = py = 0.0
    size = np.sqrt(ahw * ahw + ahh * ahh) + np.sqrt(bhw * bhw + bhh * bhh)
    lim = (ox if ox < oy else oy) + DEPTH_TOL * size
    if oy <= lim:
        depth = oy
        ny = 1.0 if sy - dy <= lim else -1.0
    else:
        depth = ox
        nx = 1.0 if sx - dx <= lim else -1.0
    if points:
        lo_x, hi_x = max(ax - ahw, bx - bhw), min(ax + ahw, bx + bhw)
        lo_y, hi_y = max(ay - ahh, by - bhh), min(ay + ahh, by + bhh)
        px, py = 0.5 * (lo_x + hi_x), 0.5 * (lo_y + hi_y)
    return True, nx, ny, depth, px, py, ext


@kernel
def _aabb_out(n):  # pragma: no cover - compiled
    """The output columns of :func:`_aabb_row` for ``n`` rows, zeros."""
    return (np.zeros(n, dtype=np.bool_), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
            np.zeros(n, dtype=np.bool_))


@kernel
def _aabb_rows(ax, ay, ahw, ahh, bx, by, bhw, bhh, exact, points):  # pragma: no cover - compiled
    """:func:`_aabb_row` of every row of the gathered columns."""
    n = ax.size
    hit, nx, ny, depth, px, py, extreme = _aabb_out(n)
    for i in range(n):
        hit[i], nx[i], ny[i], depth[i], px[i], py[i], extreme[i] = _aabb_row(ax[i], ay[i], ahw[i], ahh[i], bx[i], by[i],
                                                                             bhw[i], bhh[i], exact, points)
    return hit, nx, ny, depth, px, py, extreme


@kernel
def _aabb_pairs(ra, rb, hx, hy, hw, hh, exact, points):  # pragma: no cover - compiled
    """:func:`_aabb_row` of every pair of rows ``(ra[i], rb[i])`` of the columns (origins ``hx,
    hy``, half sizes ``hw, hh``), gathered in the pass: ``(flags, cols, extremes)``, the rows
    ``hit, extreme`` and ``nx, ny, depth, px, py`` of two arrays (each array handed back to Python
    costs a third of a microsecond), and whether a row is extreme."""
    n = ra.size
    flags = np.zeros((2, n), dtype=np.bool_)
    cols = np.zeros((5, n))
    extremes = False
    for i in range(n):
        a, b = ra[i], rb[i]
        h, nx, ny, depth, px, py, e = _aabb_row(hx[a], hy[a], hw[a], hh[a], hx[b], hy[b], hw[b], hh[b], exact, points)
        flags[0, i], flags[1, i] = h, e
        cols[0, i], cols[1, i], cols[2, i], cols[3, i], cols[4, i] = nx, ny, depth, px, py
        extremes = extremes or e
    return flags, cols, extremes
