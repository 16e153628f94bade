"""Exact decisions on floats, compiled: whether two outlines touching to rounding are apart.

:func:`~framework.collision.exact.polygon_polygon_exact` decides the pairs within rounding of
touching on Python integers, some hundred microseconds a pair; a pile at rest holds hundreds of
such pairs every step (the exact solver leaves them touching exactly). Most of them are touching
or apart, and then no number is needed but the decision. :func:`polygons_apart` makes that
decision on the same floats without integers: each quantity of the separating-axis test is a sum
of products of floats, kept exactly as a floating-point expansion (a sum of non-overlapping
doubles, Shewchuk's arithmetic: ``two_sum`` and ``two_product`` lose nothing), whose sign is the
sign of its largest part. Where the outlines overlap, the caller asks the integers for the depths.

Exact only while no product underflows or overflows: every float involved is 0 or of magnitude in
``[2**-300, 2**300]`` (the scaled frames put them near 1), else the answer is "not sure" and the
integers decide, as before.
"""

from __future__ import annotations

import math

import numpy as np

from ..compiled import kernel, leaf
from .batch_box import _two_sum_1 as _two_sum
from .exact import TINY
from .py_hypot import hypot
from .row_frame import pick_row

__all__ = ["APART", "OVERLAP", "SCRATCH", "SCRATCH_CIRCLE", "UNSURE", "polygon_circle_contact", "polygon_depths",
           "polygons_apart"]

APART, OVERLAP, UNSURE = 0, 1, 2

#: Doubles of scratch :func:`polygons_apart` and :func:`polygon_depths` work in (expansions of up
#: to 64 parts, their sums of up to 256).
SCRATCH = 1024
#: ... and :func:`polygon_circle_contact` (expansions of up to 32, 128, 512 and 1,024 parts).
SCRATCH_CIRCLE = 3208

_LO, _HI = 2.0**-300, 2.0**300
_SPLIT = 134217729.0  # 2**27 + 1 (Dekker's split of a double into two 26-bit halves)


@leaf
def _two_product(a, b):  # pragma: no cover - compiled
    p = a * b
    c = _SPLIT * a
    ah = c - (c - a)
    al = a - ah
    c = _SPLIT * b
    bh = c - (c - b)
    bl = b - bh
    return p, al * bl - (((p - ah * bh) - al * bh) - ah * bl)


@leaf
def _grow(e, m, b):  # pragma: no cover - compiled
    """Add the double ``b`` to the expansion ``e[:m]`` (non-overlapping, increasing magnitude),
    exactly, in place (zeros dropped); returns the new length."""
    q = b
    j = 0
    for i in range(m):
        q, h = _two_sum(q, e[i])
        if h != 0.0:
            e[j] = h
            j += 1
    if q != 0.0:
        e[j] = q
        j += 1
    return j


@leaf
def _add_product(e, m, a_hi, a_lo, b_hi, b_lo, sign):  # pragma: no cover - compiled
    """``e += sign * (a_hi + a_lo) * (b_hi + b_lo)`` exactly; returns the new length."""
    for x in (a_hi, a_lo):
        if x == 0.0:
            continue
        for y in (b_hi, b_lo):
            if y == 0.0:
                continue
            p, err = _two_product(x, y)
            m = _grow(e, m, sign * p)
            m = _grow(e, m, sign * err)
    return m


@leaf
def _sign(e, m):  # pragma: no cover - compiled
    """The sign of the expansion's sum: its largest part's."""
    if m == 0:
        return 0
    return 1 if e[m - 1] > 0.0 else -1


@leaf
def _project(e, ux_h, ux_l, uy_h, uy_l, x, y):  # pragma: no cover - compiled
    """``e = u . (x, y)`` exactly (``u`` two two-term sums); returns its length."""
    m = _add_product(e, 0, ux_h, ux_l, x, 0.0, 1.0)
    return _add_product(e, m, uy_h, uy_l, y, 0.0, 1.0)


@leaf
def _copy_add(dst, src, m, other, n, sign):  # pragma: no cover - compiled
    """``dst = src[:m] + sign * other[:n]`` exactly; returns its length."""
    for i in range(m):
        dst[i] = src[i]
    for i in range(n):
        m = _grow(dst, m, sign * other[i])
    return m


@leaf
def _extreme(vx, vy, c, ux_h, ux_l, uy_h, uy_l, want, best, cur, tmp):  # pragma: no cover - compiled
    """The exact max (``want`` 1) or min (-1) over the first ``c`` vertices of their projections on
    ``u``, into ``best``; returns its length. Only the vertices whose float projection is within a
    generous bound of the float extreme are compared exactly (the bound, 2**-40 of the magnitudes,
    is far above the floats' error, some 2**-51)."""
    top = 0.0
    reach = 0.0
    for j in range(c):
        p = (ux_h * vx[j] + uy_h * vy[j]) * want
        if j == 0 or p > top:
            top = p
        r = abs(vx[j]) + abs(vy[j])
        if r > reach:
            reach = r
    slack = 2.0**-40 * (abs(ux_h) + abs(uy_h)) * reach
    nb = -1
    for j in range(c):
        if (ux_h * vx[j] + uy_h * vy[j]) * want < top - slack:
            continue
        nc = _project(cur, ux_h, ux_l, uy_h, uy_l, vx[j], vy[j])
        if nb < 0:
            for i in range(nc):
                best[i] = cur[i]
            nb = nc
            continue
        nt = _copy_add(tmp, cur, nc, best, nb, -1.0)
        if _sign(tmp, nt) * want > 0:
            for i in range(nc):
                best[i] = cur[i]
            nb = nc
    return nb


@leaf
def _fits(v):  # pragma: no cover - compiled
    a = abs(v)
    return a == 0.0 or (a >= _LO and a <= _HI)


@leaf
def _offset(ox, oy, qx, qy, k):  # pragma: no cover - compiled
    """The exact offset ``(q - o) * 2**-k`` as two two-part sums ``(x_hi, x_lo, y_hi, y_lo)``,
    after whether it is exact: False where a scaled coordinate lost bits below the smallest float
    (the integers take those pairs)."""
    sx, sy = math.ldexp(qx, -k), math.ldexp(qy, -k)
    tx, ty = math.ldexp(ox, -k), math.ldexp(oy, -k)
    exact = (math.ldexp(sx, k) == qx and math.ldexp(sy, k) == qy and math.ldexp(tx, k) == ox
             and math.ldexp(ty, k) == oy)
    x_hi, x_lo = _two_sum(sx, -tx)
    y_hi, y_lo = _two_sum(sy, -ty)
    return exact, x_hi, x_lo, y_hi, y_lo


@leaf
def _polygons_fit(ex_h, ex_l, ey_h, ey_l, avx, avy, bvx, bvy):  # pragma: no cover - compiled
    """Whether the offset's parts and both outlines' slots are all in :func:`_fits`'s range."""
    if not (_fits(ex_h) and _fits(ex_l) and _fits(ey_h) and _fits(ey_l)):
        return False
    for j in range(avx.size):
        if not (_fits(avx[j]) and _fits(avy[j]) and _fits(bvx[j]) and _fits(bvy[j])):
            return False
    return True


@leaf
def polygons_apart(avx, avy, ac, bvx, bvy, bc, ox, oy, qx, qy, k, need, w):  # pragma: no cover - compiled
    """:func:`~framework.collision.exact.polygon_polygon_exact`'s decision on floats: outlines A
    (``ac`` vertices ``avx, avy``, scaled, about the origin, padded to ``K`` slots as the batch
    kernels pad them) and B (about its own origin, at the exact offset ``(q - o) * 2**-k``):
    :data:`APART` (separated or touching: the integers' None), :data:`OVERLAP`, or
    :data:`UNSURE` (a float outside the range where products are exact).

    ``need [2 K]``: per axis slot (A's edges, then B's), which overlaps the floats left in doubt
    (1 forward, 2 backward, 3 both); the others are positive beyond the floats' error, and only a
    separation or touch (an overlap <= 0) on some axis makes the pair apart. ``w``: :data:`SCRATCH`
    doubles to work in (a row pass makes them once for all its rows)."""
    exact, ex_h, ex_l, ey_h, ey_l = _offset(ox, oy, qx, qy, k)
    if not (exact and _polygons_fit(ex_h, ex_l, ey_h, ey_l, avx, avy, bvx, bvy)):
        return UNSURE
    cur, tmp, lo, hi, ud = w[0:64], w[64:128], w[128:192], w[192:256], w[256:320]
    out = w[320:576]
    kk = avx.size
    for c in range(2 * kk):
        if need[c] == 0:
            continue
        vx, vy = (avx, avy) if c < kk else (bvx, bvy)
        j = c % kk
        x0, y0 = vx[j], vy[j]
        x1, y1 = (vx[j + 1], vy[j + 1]) if j + 1 < kk else (vx[0], vy[0])
        if x0 == x1 and y0 == y1:
            continue  # (a padding slot, or an edge of no length: no axis)
        ux_h, ux_l = _two_sum(y1, -y0)  # the axis (ey, -ex), exactly
        uy_h, uy_l = _two_sum(x0, -x1)
        if not (_fits(ux_h) and _fits(ux_l) and _fits(uy_h) and _fits(uy_l)):
            return UNSURE
        nd = _add_product(ud, 0, ux_h, ux_l, ex_h, ex_l, 1.0)
        nd = _add_product(ud, nd, uy_h, uy_l, ey_h, ey_l, 1.0)
        if need[c] & 1:  # forward: (max over A - min over B) - u . d
            na = _extreme(avx, avy, ac, ux_h, ux_l, uy_h, uy_l, 1, hi, cur, tmp)
            nb = _extreme(bvx, bvy, bc, ux_h, ux_l, uy_h, uy_l, -1, lo, cur, tmp)
            m = _copy_add(out, hi, na, lo, nb, -1.0)
            for i in range(nd):
                m = _grow(out, m, -ud[i])
            if _sign(out, m) <= 0:
                return APART
        if need[c] & 2:  # backward: (max over B - min over A) + u . d
            na = _extreme(avx, avy, ac, ux_h, ux_l, uy_h, uy_l, -1, lo, cur, tmp)
            nb = _extreme(bvx, bvy, bc, ux_h, ux_l, uy_h, uy_l, 1, hi, cur, tmp)
            m = _copy_add(out, hi, nb, lo, na, -1.0)
            for i in range(nd):
                m = _grow(out, m, ud[i])
            if _sign(out, m) <= 0:
                return APART
    return OVERLAP


# --- polygon / circle -----------------------------------------------------------------------------
# Quantities of degree up to four in the inputs: exact while every input is 0 or of magnitude in
# [2**-200, 2**200] (a part's lowest bit then stays above 2**-1022 through four products).
_LO4, _HI4 = 2.0**-200, 2.0**200


@leaf
def _fits4(v):  # pragma: no cover - compiled
    a = abs(v)
    return a == 0.0 or (a >= _LO4 and a <= _HI4)


@leaf
def _mul(dst, m, a, na, b, nb, sign):  # pragma: no cover - compiled
    """``dst[:m] += sign * a[:na] * b[:nb]`` exactly; returns the new length."""
    for i in range(na):
        for j in range(nb):
            p, err = _two_product(a[i], b[j])
            m = _grow(dst, m, sign * p)
            m = _grow(dst, m, sign * err)
    return m


@leaf
def _diff(dst, a, na, b):  # pragma: no cover - compiled
    """``dst = a[:na] - b`` (``b`` a double) exactly; returns its length."""
    for i in range(na):
        dst[i] = a[i]
    return _grow(dst, na, -b)


@leaf
def _seps(vx, vy, c, cx, ncx, cy, ncy, i, wx, wy, ex, ey, s):  # pragma: no cover - compiled
    """Edge ``i``'s exact ``(ey (cx - x0) - ex (cy - y0))`` into ``s`` (the centre's distance
    outside its line, times its length), its parts into ``wx, wy, ex, ey``: their lengths."""
    x0, y0 = vx[i], vy[i]
    x1, y1 = vx[(i + 1) % c], vy[(i + 1) % c]
    nwx, nwy = _diff(wx, cx, ncx, x0), _diff(wy, cy, ncy, y0)
    nex = _grow(ex, _grow(ex, 0, x1), -x0)
    ney = _grow(ey, _grow(ey, 0, y1), -y0)
    ns = _mul(s, 0, ey, ney, wx, nwx, 1.0)
    ns = _mul(s, ns, ex, nex, wy, nwy, -1.0)
    return nwx, nwy, nex, ney, ns


@kernel
def polygon_circle_contact(vx, vy, c, ox, oy, qx, qy, k, r, cx0, cy0, size, f, w):  # pragma: no cover - compiled
    """:func:`~framework.collision.batch_circle._polygon_circle_exact` on floats: the outline
    (``c`` vertices ``vx, vy``, scaled, about the origin) and the circle of radius ``r`` (scaled)
    at the exact offset ``(q - o) * 2**-k`` (``cx0, cy0``: that offset in floats, ``size`` the
    tie-break's scale, ``f`` -1 where the circle is shape A): ``(verdict, nx, ny, depth, px, py)``,
    the contact (in the scaled frame) where :data:`OVERLAP`, as the integers give it bit for bit;
    else :data:`APART` or :data:`UNSURE` (a float outside the range where these products are exact,
    or a rounding not settled). ``w``: :data:`SCRATCH_CIRCLE` doubles to work in (a row pass makes
    them once for all its rows)."""
    cx, cy, rr = w[0:2], w[2:4], w[4:6]
    wx, wy, ex, ey = w[8:40], w[40:72], w[72:104], w[104:136]
    s, t, e2, best = w[136:264], w[264:392], w[392:520], w[520:648]
    num, tmp, tmp2 = w[648:1160], w[1160:2184], w[2184:3208]
    exact, cx[1], cx[0], cy[1], cy[0] = _offset(ox, oy, qx, qy, k)  # (expansions: smaller part first)
    if not exact or not (_fits4(cx[0]) and _fits4(cx[1]) and _fits4(cy[0]) and _fits4(cy[1]) and _fits4(r)):
        return UNSURE, 0.0, 0.0, 0.0, 0.0, 0.0
    for j in range(c):
        if not (_fits4(vx[j]) and _fits4(vy[j])):
            return UNSURE, 0.0, 0.0, 0.0, 0.0, 0.0
    ncx = _grow(cx, 0, cx[0]) if cx[1] == 0.0 else 2  # (drop a zero part)
    ncy = _grow(cy, 0, cy[0]) if cy[1] == 0.0 else 2
    rr[1], rr[0] = _two_product(r, r)
    nrr = 2
    # Inside (or on the boundary): every edge's line has the centre on its inner side.
    inside = True
    distinct = False
    for i in range(c):
        if vx[i] != vx[(i + 1) % c] or vy[i] != vy[(i + 1) % c]:
            distinct = True
        ns = _seps(vx, vy, c, cx, ncx, cy, ncy, i, wx, wy, ex, ey, s)[4]
        if _sign(s, ns) > 0:
            inside = False
    if c == 2 and inside:  # a segment: the centre on it only between its ends
        nwx, nwy = _diff(wx, cx, ncx, vx[0]), _diff(wy, cy, ncy, vy[0])
        nex = _grow(ex, _grow(ex, 0, vx[1]), -vx[0])
        ney = _grow(ey, _grow(ey, 0, vy[1]), -vy[0])
        nt = _mul(t, 0, wx, nwx, ex, nex, 1.0)
        nt = _mul(t, nt, wy, nwy, ey, ney, 1.0)
        n2 = _mul(e2, 0, ex, nex, ex, nex, 1.0)
        n2 = _mul(e2, n2, ey, ney, ey, ney, 1.0)
        for q in range(nt):
            n2 = _grow(e2, n2, -t[q])
        inside = _sign(t, nt) >= 0 and _sign(e2, n2) >= 0
    if inside and distinct:
        # Out through the nearest face, plus the radius: the tie-break among the faces.
        cd, cnx, cny = np.empty(c), np.empty(c), np.empty(c)
        m = 0
        for i in range(c):
            fex, fey = vx[(i + 1) % c] - vx[i], vy[(i + 1) % c] - vy[i]
            ln = hypot(fex, fey)
            if not ln > 0.0:
                continue
            ns = _seps(vx, vy, c, cx, ncx, cy, ncy, i, wx, wy, ex, ey, s)[4]
            fs, ok = _rounded(s, ns, tmp, tmp2)
            if not ok:
                return UNSURE, 0.0, 0.0, 0.0, 0.0, 0.0
            cd[m], cnx[m], cny[m] = r - fs / ln, f * fey / ln, -f * fex / ln
            m += 1
        depth, nx, ny = pick_row(cd[:m], cnx[:m], cny[:m], size)
        return OVERLAP, nx, ny, (depth if depth > TINY else TINY), cx0, cy0
    # Outside: the first face whose region holds the centre decides, else the nearest vertex.
    for i in range(c):
        nwx, nwy, nex, ney, ns = _seps(vx, vy, c, cx, ncx, cy, ncy, i, wx, wy, ex, ey, s)
        if _sign(s, ns) <= 0:
            continue
        nt = _mul(t, 0, wx, nwx, ex, nex, 1.0)
        nt = _mul(t, nt, wy, nwy, ey, ney, 1.0)
        n2 = _mul(e2, 0, ex, nex, ex, nex, 1.0)
        n2 = _mul(e2, n2, ey, ney, ey, ney, 1.0)
        if _sign(t, nt) < 0:
            continue
        nd = _copy_add(num, e2, n2, t, nt, -1.0)  # edge2 - t
        if _sign(num, nd) < 0:
            continue
        # distance s / |e| < r  <=>  r^2 |e|^2 - s^2 > 0
        nn = _mul(num, 0, rr, nrr, e2, n2, 1.0)
        nn = _mul(num, nn, s, ns, s, ns, -1.0)
        if _sign(num, nn) <= 0:
            return APART, 0.0, 0.0, 0.0, 0.0, 0.0
        fs, ok = _rounded(s, ns, tmp, tmp2)
        numr, ok2 = _rounded(num, nn, tmp, tmp2)
        if not (ok and ok2):
            return UNSURE, 0.0, 0.0, 0.0, 0.0, 0.0
        fex, fey = vx[(i + 1) % c] - vx[i], vy[(i + 1) % c] - vy[i]
        ln = hypot(fex, fey)
        depth = numr / (ln * (r * ln + fs))
        nx, ny = fey / ln, -fex / ln
        dist = fs / ln
        return OVERLAP, f * nx, f * ny, (depth if depth > TINY else TINY), cx0 - nx * dist, cy0 - ny * dist
    # The nearest vertex (the first of equals), exactly.
    nb = 0
    jb = -1
    for j in range(c):
        nwx, nwy = _diff(wx, cx, ncx, vx[j]), _diff(wy, cy, ncy, vy[j])
        nq = _mul(t, 0, wx, nwx, wx, nwx, 1.0)
        nq = _mul(t, nq, wy, nwy, wy, nwy, 1.0)
        if jb >= 0:
            nd = _copy_add(num, t, nq, best, nb, -1.0)
            if _sign(num, nd) >= 0:
                continue
        for q in range(nq):
            best[q] = t[q]
        nb, jb = nq, j
    nn = _copy_add(num, rr, nrr, best, nb, -1.0)  # r^2 - |d|^2
    if _sign(num, nn) <= 0:
        return APART, 0.0, 0.0, 0.0, 0.0, 0.0
    nwx, nwy = _diff(wx, cx, ncx, vx[jb]), _diff(wy, cy, ncy, vy[jb])
    ddx, ok = _rounded(wx, nwx, tmp, tmp2)
    ddy, ok2 = _rounded(wy, nwy, tmp, tmp2)
    numr, ok3 = _rounded(num, nn, tmp, tmp2)
    if not (ok and ok2 and ok3):
        return UNSURE, 0.0, 0.0, 0.0, 0.0, 0.0
    dist = hypot(ddx, ddy)
    depth = numr / (r + dist)
    nx, ny = (ddx / dist, ddy / dist) if dist > 0.0 else (0.0, f)
    return OVERLAP, f * nx, f * ny, (depth if depth > TINY else TINY), vx[jb], vy[jb]


# --- exact depths of overlapping polygons ---------------------------------------------------------

@leaf
def _steps(hi):  # pragma: no cover - compiled
    """The gaps from ``hi`` (normal, nonzero) to the next double up and down."""
    m, ex = math.frexp(abs(hi))
    gap = math.ldexp(1.0, ex - 53)  # the spacing in hi's binade
    toward = gap * 0.5 if m == 0.5 else gap  # (below a power of two the spacing halves)
    return (gap, toward) if hi > 0.0 else (toward, gap)


@leaf
def _even(v):  # pragma: no cover - compiled
    m, _ex = math.frexp(abs(v))
    return int(m * 9007199254740992.0) % 2 == 0  # (the 53-bit significand's last bit)


@leaf
def _rounded(e, m, tmp, tmp2):  # pragma: no cover - compiled
    """The expansion's sum correctly rounded (to nearest, ties to even), as Python's int division
    rounds it, and whether that was found (False far from 1, where the gaps below are not exact)."""
    if m == 0:
        return 0.0, True
    hi = 0.0
    for i in range(m):
        hi += e[i]
    for _ in range(6):
        if not (abs(hi) > 2.0**-900 and abs(hi) < 2.0**1000):
            return 0.0, False
        up, down = _steps(hi)
        nr = _copy_add(tmp, e, m, e, 0, 1.0)
        nr = _grow(tmp, nr, -hi)  # the remainder V - hi, exactly
        n2 = _copy_add(tmp2, tmp, nr, tmp, 0, 1.0)
        above = _sign(tmp2, _grow(tmp2, n2, -0.5 * up))  # V against the midpoint above hi
        if above > 0:
            hi += up
            continue
        if above == 0:
            return (hi if _even(hi) else hi + up), True
        n2 = _copy_add(tmp2, tmp, nr, tmp, 0, 1.0)
        below = _sign(tmp2, _grow(tmp2, n2, 0.5 * down))  # and the midpoint below
        if below < 0:
            hi -= down
            continue
        if below == 0:
            return (hi if _even(hi) else hi - down), True
        return hi, True
    return 0.0, False


@leaf
def polygon_depths(avx, avy, ac, bvx, bvy, bc, ox, oy, qx, qy, k, fwd, bwd, w):  # pragma: no cover - compiled
    """For overlapping outlines (as :func:`polygons_apart` takes them): every axis slot's exact
    forward and backward overlaps, correctly rounded, into ``fwd`` and ``bwd`` (padding slots are
    left alone), as :mod:`~framework.collision.batch_polygon` writes the integers' ones; False
    where an input is outside the exact range or a rounding could not be settled. ``w``:
    :data:`SCRATCH` doubles to work in."""
    exact, ex_h, ex_l, ey_h, ey_l = _offset(ox, oy, qx, qy, k)
    if not (exact and _polygons_fit(ex_h, ex_l, ey_h, ey_l, avx, avy, bvx, bvy)):
        return False
    cur, lo, hi, ud = w[0:64], w[64:128], w[128:192], w[192:256]
    tmp, tmp2, out = w[256:512], w[512:768], w[768:1024]
    kk = avx.size
    for c in range(2 * kk):
        vx, vy = (avx, avy) if c < kk else (bvx, bvy)
        j = c % kk
        x0, y0 = vx[j], vy[j]
        x1, y1 = (vx[j + 1], vy[j + 1]) if j + 1 < kk else (vx[0], vy[0])
        if x0 == x1 and y0 == y1:
            continue
        ux_h, ux_l = _two_sum(y1, -y0)
        uy_h, uy_l = _two_sum(x0, -x1)
        if not (_fits(ux_h) and _fits(ux_l) and _fits(uy_h) and _fits(uy_l)):
            return False
        nd = _add_product(ud, 0, ux_h, ux_l, ex_h, ex_l, 1.0)
        nd = _add_product(ud, nd, uy_h, uy_l, ey_h, ey_l, 1.0)
        na = _extreme(avx, avy, ac, ux_h, ux_l, uy_h, uy_l, 1, hi, cur, tmp)
        nb = _extreme(bvx, bvy, bc, ux_h, ux_l, uy_h, uy_l, -1, lo, cur, tmp)
        m = _copy_add(out, hi, na, lo, nb, -1.0)
        for i in range(nd):
            m = _grow(out, m, -ud[i])
        value, ok = _rounded(out, m, tmp, tmp2)
        if not ok:
            return False
        fwd[c] = value
        na = _extreme(avx, avy, ac, ux_h, ux_l, uy_h, uy_l, -1, lo, cur, tmp)
        nb = _extreme(bvx, bvy, bc, ux_h, ux_l, uy_h, uy_l, 1, hi, cur, tmp)
        m = _copy_add(out, hi, nb, lo, na, -1.0)
        for i in range(nd):
            m = _grow(out, m, ud[i])
        value, ok = _rounded(out, m, tmp, tmp2)
        if not ok:
            return False
        bwd[c] = value
    return True


@kernel
def exact_sum(parts):  # pragma: no cover - compiled
    """The sum of the doubles ``parts``, exact, then correctly rounded (``math.fsum``'s answer);
    NaN where the rounding is not settled here (a sum beyond about 2**±900). The expansions'
    arithmetic and rounding as the kernels use them, callable from Python (the tests')."""
    e = np.empty(parts.size + 1)
    m = 0
    for i in range(parts.size):
        m = _grow(e, m, parts[i])
    value, ok = _rounded(e, m, np.empty(4 * parts.size + 8), np.empty(4 * parts.size + 8))
    return value if ok else np.nan


# --- circle / circle --------------------------------------------------------------------------------

@kernel
def circles_excess(ox, oy, qx, qy, k, ra, rb):  # pragma: no cover - compiled
    """:func:`~framework.collision.exact.circle_circle_exact` on floats: circles of radius ``ra``
    at the origin and ``rb`` at the exact offset ``(q - o) * 2**-k`` (radii scaled):
    ``(verdict, excess)``, the excess ``(ra + rb)^2 - |d|^2`` correctly rounded where they
    overlap (:data:`OVERLAP`), else :data:`APART` or :data:`UNSURE`."""
    d = np.empty(2)
    e = np.empty(2)
    s = np.empty(2)
    exact, d[1], d[0], e[1], e[0] = _offset(ox, oy, qx, qy, k)
    if not exact:
        return UNSURE, 0.0
    s[1], s[0] = _two_sum(ra, rb)
    for v in (d[0], d[1], e[0], e[1], s[0], s[1]):
        if not _fits(v):
            return UNSURE, 0.0
    out = np.empty(64)
    m = _mul(out, 0, s, 2, s, 2, 1.0)
    m = _mul(out, m, d, 2, d, 2, -1.0)
    m = _mul(out, m, e, 2, e, 2, -1.0)
    if _sign(out, m) <= 0:
        return APART, 0.0
    value, ok = _rounded(out, m, np.empty(256), np.empty(256))
    return (OVERLAP, value) if ok else (UNSURE, 0.0)
