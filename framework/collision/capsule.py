"""Pairs with a capsule: a capsule against a circle, a box, a polygon or another capsule.

Every shape of such a pair is a *core* rounded by a radius: a capsule is its segment rounded by its
radius, a circle its centre rounded by its radius, a box or polygon its outline rounded by 0. Two
rounded cores overlap exactly when the distance between the cores is less than the sum of the radii
``R``, and their Minkowski difference is the cores' Minkowski difference ``Q`` (a convex polygon,
a parallelogram or a segment) rounded by ``R``. So, with A's core at the origin and B's at the offset:

- **Cores that meet** (the origin is in ``Q``): the shortest push-out leaves ``Q`` through a face and
  then goes ``R`` further. ``Q``'s faces are the faces of the two cores (a segment's two sides), so
  the separating-axis projections on those axes give the candidates ``overlap / |u| + R``. The
  segment's own direction and the vertical are added as axes: an axis that is no face of ``Q``
  gives a push-out that is never too short (the support function bounds the exit), so it only wins
  where it is a shortest one too (the vertical one where a segment's end meets a core: the tie-break
  rule's "closest to vertical" among a half-circle of equal push-outs).
- **Cores apart** (some axis separates them): the closest points of the cores are a vertex of one and
  a point of an edge of the other; if they are ``d < R`` apart, the push-out is ``R - d`` along the
  line from A's closest point to B's.

Numerics as in :mod:`~framework.collision.collide`: the pair is worked in a local frame scaled by a
power of two (the capsule's, whichever shape comes first; for two capsules, the one whose placement
sorts first, so swapping A and B repeats the same arithmetic and gives the same depth bit for bit
and the exactly negated normal), floats decide wherever they are clear of rounding, and a thin band
around touching is decided on exact integers (:func:`~framework.collision.exact.rounded_exact`), so
touching is never a collision and an overlap of one ulp always is.

The float core is compiled (numba) and is the same function for :func:`~framework.collision.collide`
and for the batch kernel :func:`capsule_many` (one call per pair inside one compiled loop), so the two
give the same bits.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..compiled import kernel, leaf
from ..shapes import AABB, Capsule, Circle, Polygon, Segment, Shape
from .exact import BAND, TINY, Offset, float_approx, ratio_approx, rounded_exact
from .ray import closest_on_segment_compiled as _on_segment  # (ray.py's, compiled for the kernels here)
from .tiebreak import DEPTH_TOL, DIR_TOL

if TYPE_CHECKING:
    from .batch_common import ContactArrays

__all__ = ["capsule_first", "capsule_many", "capsule_pair", "core_points", "half_segments", "segment"]

Res = tuple[float, float, float, float, float]

APART, HIT, EXACT = 0, 1, 2


# --- cores -----------------------------------------------------------------------------------------

def segment(shape: Capsule, rotation: float, k: int = 0) -> tuple[float, float]:
    """The half segment ``(ux, uy)`` of a capsule (its ends are ``-u`` and ``+u``), rotated, scaled
    by ``2**-k`` (exact) before rotating, as :func:`~framework.collision.placement.local_outline`."""
    h = math.ldexp(shape.half_length, -k)
    if rotation == 0.0:
        return 0.0, h
    c, s = math.cos(rotation), math.sin(rotation)
    return -(s * h), c * h


def half_segments(half_length: ArrayLike, rotation: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`segment` of many capsules (unscaled), ``[N]`` each: ``math.cos`` and ``math.sin`` as
    the scalar code (numpy's may differ in the last bit), ``(0, h)`` at rotation 0."""
    hl = np.asarray(half_length, dtype=np.float64)
    rot = np.broadcast_to(np.asarray(rotation, dtype=np.float64), hl.shape)
    ux, uy = np.zeros(hl.shape), hl.copy()
    turned = np.flatnonzero(rot != 0.0)
    if turned.size:
        r = rot[turned].tolist()
        c = np.fromiter(map(math.cos, r), dtype=np.float64, count=len(r))
        s = np.fromiter(map(math.sin, r), dtype=np.float64, count=len(r))
        ux[turned] = -(s * hl[turned])
        uy[turned] = c * hl[turned]
    return ux, uy


def core_points(shape: Shape, rotation: float, k: int = 0) -> tuple[list[tuple[float, float]], float]:
    """The core of a shape about its hitbox origin, scaled by ``2**-k``, and its radius: a circle's
    centre, a capsule's two segment ends (``-u``, ``+u``), a box's or polygon's outline, a segment's
    two ends (radius 0)."""
    from .placement import local_outline

    if isinstance(shape, Segment):
        return local_outline(shape, rotation, k), 0.0
    if isinstance(shape, Circle):
        return [(0.0, 0.0)], math.ldexp(shape.radius, -k)
    if isinstance(shape, Capsule):
        ux, uy = segment(shape, rotation, k)
        return [(-ux, -uy), (ux, uy)], math.ldexp(shape.radius, -k)
    assert isinstance(shape, (AABB, Polygon))
    return local_outline(shape, rotation, k), 0.0


def capsule_first(a: Capsule, pose_a: tuple[float, float, float], b: Capsule,
                  pose_b: tuple[float, float, float]) -> bool:
    """Whether a pair of capsules is worked in A's frame (else in B's, turned round): the placement
    ``(x, y, rotation, radius, length)`` that sorts first. The batch kernels order by the same key."""
    return (pose_a[0], pose_a[1], pose_a[2], a.radius, a.length) <= (pose_b[0], pose_b[1], pose_b[2], b.radius,
                                                                      b.length)


# --- the compiled core -----------------------------------------------------------------------------

@leaf
def _folded_x(nx, ny):
    if ny < -DIR_TOL or (abs(ny) <= DIR_TOL and nx < 0.0):
        return -nx
    return nx


@kernel
def _pick(cd, cx, cy, m, size):
    """:func:`framework.collision.tiebreak.pick` over the first ``m`` candidates."""
    best = np.inf
    for i in range(m):
        if cd[i] < best:
            best = cd[i]
    tol = DEPTH_TOL * size
    near = np.zeros(m, dtype=np.bool_)
    top = -1.0
    for i in range(m):
        if cd[i] <= best + tol:
            near[i] = True
            if abs(cy[i]) > top:
                top = abs(cy[i])
    fx = -np.inf
    for i in range(m):
        if near[i]:
            if abs(cy[i]) >= top - DIR_TOL:
                f = _folded_x(cx[i], cy[i])
                if f > fx:
                    fx = f
            else:
                near[i] = False
    shortest = np.inf
    for i in range(m):
        if near[i]:
            if _folded_x(cx[i], cy[i]) >= fx - DIR_TOL:
                if cd[i] < shortest:
                    shortest = cd[i]
            else:
                near[i] = False
    # The first maximum of the key (ny > tol, nx > tol, -depth), as Python's max.
    w = -1
    for i in range(m):
        if near[i]:
            if w < 0:
                w = i
                continue
            ki = (cy[i] > DIR_TOL, cx[i] > DIR_TOL, -cd[i])
            kw = (cy[w] > DIR_TOL, cx[w] > DIR_TOL, -cd[w])
            if ki > kw:
                w = i
    return shortest, cx[w], cy[w]


@leaf
def _n_edges(nb):
    return nb if nb >= 3 else 1


@leaf
def _pair_points(i, a0x, a0y, a1x, a1y, qx, qy, nb):
    """Closest points ``(pa, pb)`` of pair ``i``: ``i < 2 E``: A's end ``i // E`` and B's edge
    ``i % E`` (E edges: a point's one "edge" is the point, a segment's is the segment); then B's
    vertex ``i - 2 E`` and A's segment. The numbering of :func:`~framework.collision.exact.rounded_exact`."""
    ne = _n_edges(nb)
    if i < 2 * ne:
        px, py = (a0x, a0y) if i < ne else (a1x, a1y)
        j = i % ne
        j1 = j + 1 if j + 1 < nb else 0
        cx, cy = _on_segment(px, py, qx[j], qy[j], qx[j1], qy[j1])
        return px, py, cx, cy
    j = i - 2 * ne
    cx, cy = _on_segment(qx[j], qy[j], a0x, a0y, a1x, a1y)
    return cx, cy, qx[j], qy[j]


@leaf
def _closest(a0x, a0y, a1x, a1y, qx, qy, nb):
    """The pair of closest points of the cores (first of the nearest): ``(i, distance)``."""
    best, bi = np.inf, 0
    for i in range(2 * _n_edges(nb) + nb):
        pax, pay, pbx, pby = _pair_points(i, a0x, a0y, a1x, a1y, qx, qy, nb)
        d = math.hypot(pbx - pax, pby - pay)
        if d < best:
            best, bi = d, i
    return bi, best


@leaf
def _axes(a0x, a0y, a1x, a1y, bx, by, nb, dx, dy, rsum, f, cd, cx, cy):
    """The separating axes of the cores (A's segment's normal and direction, the vertical, B's
    faces): fills the push-out candidates ``(overlap / |u| + R, f u / |u|)`` both ways; returns
    ``(count, least overlap / |u|)`` (< 0: an axis separates the cores; inf: no axis at all)."""
    ex, ey = a1x - a0x, a1y - a0y
    nax = 3 + (2 if nb == 2 else (nb if nb >= 3 else 0))
    m = 0
    sat = np.inf
    for t in range(nax):
        if t == 0:
            ux, uy = ey, -ex
        elif t == 1:
            ux, uy = ex, ey
        elif t == 2:
            ux, uy = 0.0, 1.0
        elif nb == 2:
            fx, fy = bx[1] - bx[0], by[1] - by[0]
            ux, uy = (fy, -fx) if t == 3 else (fx, fy)
        else:
            j = t - 3
            j1 = j + 1 if j + 1 < nb else 0
            ux, uy = by[j1] - by[j], bx[j] - bx[j1]
        if ux == 0.0 and uy == 0.0:
            continue
        p0, p1 = ux * a0x + uy * a0y, ux * a1x + uy * a1y
        amin, amax = min(p0, p1), max(p0, p1)
        bmin = bmax = ux * bx[0] + uy * by[0]
        for j in range(1, nb):
            p = ux * bx[j] + uy * by[j]
            if p < bmin:
                bmin = p
            elif p > bmax:
                bmax = p
        ud = ux * dx + uy * dy
        fwd, bwd = (amax - bmin) - ud, (bmax - amin) + ud
        ln = math.hypot(ux, uy)
        fw, bw = fwd / ln, bwd / ln
        sat = min(sat, fw, bw)
        cd[m], cx[m], cy[m] = fw + rsum, f * ux / ln, f * uy / ln
        cd[m + 1], cx[m + 1], cy[m + 1] = bw + rsum, -f * ux / ln, -f * uy / ln
        m += 2
    return m, sat


@leaf
def _inside_point(a0x, a0y, a1x, a1y, qx, qy, nb):
    """A point of both cores, which meet (up to rounding)."""
    if nb == 1:
        return qx[0], qy[0]
    ex, ey = a1x - a0x, a1y - a0y
    if nb == 2:
        fx, fy = qx[1] - qx[0], qy[1] - qy[0]
        den = ex * fy - ey * fx
        if den != 0.0:
            wx, wy = qx[0] - a0x, qy[0] - a0y
            t = (wx * fy - wy * fx) / den
            u = (wx * ey - wy * ex) / den
            if 0.0 <= t <= 1.0 and 0.0 <= u <= 1.0:
                return a0x + t * ex, a0y + t * ey
    else:
        # A's segment clipped to the polygon (Cyrus-Beck, closed half-planes).
        t0, t1 = 0.0, 1.0
        for j in range(nb):
            j1 = j + 1 if j + 1 < nb else 0
            nx, ny = qy[j1] - qy[j], qx[j] - qx[j1]
            num = nx * (qx[j] - a0x) + ny * (qy[j] - a0y)
            den = nx * ex + ny * ey
            if den == 0.0:
                if num < 0.0:
                    t0, t1 = 1.0, 0.0
            elif den < 0.0:
                t0 = max(t0, num / den)
            else:
                t1 = min(t1, num / den)
        if t0 <= t1:
            t = 0.5 * (t0 + t1)
            return a0x + t * ex, a0y + t * ey
    # Cores that only touch, or parallel segments: the middle of the closest points.
    i, _ = _closest(a0x, a0y, a1x, a1y, qx, qy, nb)
    pax, pay, pbx, pby = _pair_points(i, a0x, a0y, a1x, a1y, qx, qy, nb)
    return 0.5 * (pax + pbx), 0.5 * (pay + pby)


@leaf
def _apart_contact(i, dist, depth, a0x, a0y, a1x, a1y, qx, qy, nb, ra, rb, f, out):
    """The contact of cores apart whose closest points are pair ``i``, ``dist`` > 0 apart (the
    normal times ``f``)."""
    pax, pay, pbx, pby = _pair_points(i, a0x, a0y, a1x, a1y, qx, qy, nb)
    nx, ny = (pbx - pax) / dist, (pby - pay) / dist
    # The overlap meets the line through the closest points in [lo, hi] (distances from pa).
    mid = 0.5 * (max(-ra, dist - rb) + min(ra, dist + rb))
    out[0], out[1], out[2] = f * nx, f * ny, depth
    out[3], out[4] = pax + nx * mid, pay + ny * mid


@kernel
def _inside_contact(a0x, a0y, a1x, a1y, bx, by, qx, qy, nb, dx, dy, ra, rb, size, f, out):
    """The contact of cores that meet (or are within rounding of meeting): the shortest push-out
    over the axes, plus the radii."""
    cd, cx, cy = np.empty(2 * (nb + 5)), np.empty(2 * (nb + 5)), np.empty(2 * (nb + 5))
    m, _ = _axes(a0x, a0y, a1x, a1y, bx, by, nb, dx, dy, ra + rb, f, cd, cx, cy)
    depth, nx, ny = _pick(cd, cx, cy, m, size)
    px, py = _inside_point(a0x, a0y, a1x, a1y, qx, qy, nb)
    out[0], out[1], out[2], out[3], out[4] = nx, ny, max(depth, TINY), px, py


@kernel
def core(a0x, a0y, a1x, a1y, ra, bx, by, nb, dx, dy, rb, size, f, out):
    """Capsule A (segment a0 a1, radius ra, about A's origin) against B's core (``bx, by``, ``nb``
    points about B's origin: 1 a point, 2 a segment, 3+ a convex CCW outline) rounded by ``rb`` at
    the offset (dx, dy), in a scaled local frame. Returns APART, HIT (``out``: nx, ny, depth, px, py,
    the normal from A toward B, times ``f``: -1 where the caller's A is B) or EXACT (within rounding
    of touching: decide on integers). The candidates are turned round before the tie-break, so a
    direction that is undefined (a candidate and its negation tie) is the upward (rightward) one
    whichever shape comes first."""
    rsum = ra + rb
    qx, qy = np.empty(nb), np.empty(nb)
    for j in range(nb):
        qx[j], qy[j] = bx[j] + dx, by[j] + dy
    tol = BAND * (size + abs(dx) + abs(dy))
    cd, cx, cy = np.empty(2 * (nb + 5)), np.empty(2 * (nb + 5)), np.empty(2 * (nb + 5))
    m, sat = _axes(a0x, a0y, a1x, a1y, bx, by, nb, dx, dy, rsum, f, cd, cx, cy)
    if m > 0 and sat >= -tol:
        # The cores meet, or nearly: an overlap unless the radii are within rounding of nothing.
        if rsum <= 4.0 * tol:
            return EXACT
        _inside_contact(a0x, a0y, a1x, a1y, bx, by, qx, qy, nb, dx, dy, ra, rb, size, f, out)
        return HIT
    i, dist = _closest(a0x, a0y, a1x, a1y, qx, qy, nb)
    if dist >= rsum + tol:
        return APART
    if dist <= rsum - tol and dist > 0.0:
        _apart_contact(i, dist, rsum - dist, a0x, a0y, a1x, a1y, qx, qy, nb, ra, rb, f, out)
        return HIT
    return EXACT


@kernel
def exact_contact(found, index, excess, a0x, a0y, a1x, a1y, ra, bx, by, nb, dx, dy, rb, size, f, out):
    """The contact of a pair decided on integers: ``found`` 1 the cores meet, 2 they are apart with
    closest points ``index`` and ``R^2 - d^2 = excess`` (> 0)."""
    qx, qy = np.empty(nb), np.empty(nb)
    for j in range(nb):
        qx[j], qy[j] = bx[j] + dx, by[j] + dy
    if found == 2:
        pax, pay, pbx, pby = _pair_points(index, a0x, a0y, a1x, a1y, qx, qy, nb)
        dist = math.hypot(pbx - pax, pby - pay)
        if dist > 0.0:
            # R - d from the exact R^2 - d^2 = (R - d)(R + d): > 0, and accurate near touching.
            _apart_contact(index, dist, max(excess / (ra + rb + dist), TINY), a0x, a0y, a1x, a1y, qx, qy, nb,
                           ra, rb, f, out)
            return
    _inside_contact(a0x, a0y, a1x, a1y, bx, by, qx, qy, nb, dx, dy, ra, rb, size, f, out)


@kernel
def _core_many(a0x, a0y, a1x, a1y, ra, bvx, bvy, bn, dx, dy, rb, size, f, status, out):
    for p in range(a0x.shape[0]):
        status[p] = core(a0x[p], a0y[p], a1x[p], a1y[p], ra[p], bvx[p], bvy[p], bn[p], dx[p], dy[p], rb[p],
                         size[p], f[p], out[p])


# --- one pair ----------------------------------------------------------------------------------

def _decide_exactly(a0: tuple[float, float], a1: tuple[float, float], ra: float, bpts: list[tuple[float, float]],
                    rb: float, off: Offset, to_float) -> tuple[int, int, float]:
    """``(found, index, excess)`` for :func:`exact_contact` (found 0: apart or touching)."""
    got = rounded_exact([a0, a1], bpts, off, ra, rb)
    if got is None:
        return 0, 0, 0.0
    if got[0] == "meet":
        return 1, 0, 0.0
    _, index, num, den, u = got
    return 2, index, to_float(num, den, u)


def _ratio(num: int, den: int, u: int) -> float:
    return ratio_approx(num, den, u) if den != 1 else float_approx(num, u)


def capsule_pair(sa: Capsule, rot_a: float, sb: Shape, rot_b: float, dx: float, dy: float, off: Offset, k: int,
                 size: float, flip: bool = False) -> Res | None:
    """Capsule ``sa`` at the origin of the scaled local frame against ``sb`` at (dx, dy): the
    contact ``(nx, ny, depth, px, py)`` in that frame, or ``None``. With ``flip`` the caller's A is
    ``sb``: the normal is turned round."""
    ux, uy = segment(sa, rot_a, k)
    ra = math.ldexp(sa.radius, -k)
    pts, rb = core_points(sb, rot_b, k)
    bx = np.array([p[0] for p in pts])
    by = np.array([p[1] for p in pts])
    out = np.zeros(5)
    f = -1.0 if flip else 1.0
    status = core(-ux, -uy, ux, uy, ra, bx, by, len(pts), dx, dy, rb, size, f, out)
    if status == APART:
        return None
    if status == EXACT:
        found, index, excess = _decide_exactly((-ux, -uy), (ux, uy), ra, pts, rb, off, _ratio)
        if found == 0:
            return None
        exact_contact(found, index, excess, -ux, -uy, ux, uy, ra, bx, by, len(pts), dx, dy, rb, size, f, out)
    nx, ny, depth, px, py = (float(v) for v in out)
    return nx, ny, depth, px, py


# --- many pairs (the batch kernel) ------------------------------------------------------------------

def capsule_many(ax, ay, aux, auy, ar, abound, bx, by, bverts, bcount, br, bbound, flip=False,
                 exact: bool = True) -> ContactArrays:
    """Capsules A (hitbox origins (ax, ay), half segments (aux, auy) already rotated, radii ``ar``,
    bounding radii ``abound``, all ``[P]``) against cores B: origins (bx, by), core points about
    them ``bverts [P, K, 2]`` with ``bcount`` of them (1: a circle's centre; 2: a capsule's ends,
    ``-u`` then ``+u``; 3+: a box's or polygon's outline, as
    :func:`~framework.collision.batch.outlines` gives it), radii ``br`` (0 for outlines) and
    bounding radii ``bbound``. Normals point from A toward B, or, where ``flip`` (a bool or one per
    row), from B toward A (the capsule is the caller's shape B). Rows of two capsules must come in
    the order :func:`capsule_first` gives. ``exact=False``: pairs within rounding of touching count
    as apart. Returns :class:`~framework.collision.batch_common.ContactArrays`."""
    from .batch_common import columns_of, finish, frame

    bv = np.asarray(bverts, dtype=np.float64)
    p = bv.shape[0]
    ax, ay, aux, auy, ar, abound, bx, by, br, bbound = columns_of(p, ax, ay, aux, auy, ar, abound, bx, by, br, bbound)
    bn = np.broadcast_to(np.asarray(bcount, dtype=np.int64), (p,))
    f = np.where(np.broadcast_to(np.asarray(flip, dtype=bool), (p,)), -1.0, 1.0)
    dx, dy, k = frame(ax, ay, bx, by, np.maximum(abound, bbound))
    ux, uy = np.ldexp(aux, -k), np.ldexp(auy, -k)
    ra, rb = np.ldexp(ar, -k), np.ldexp(br, -k)
    size = np.ldexp(abound, -k) + np.ldexp(bbound, -k)
    bvx = np.ascontiguousarray(np.ldexp(bv[:, :, 0], -k[:, None]))
    bvy = np.ascontiguousarray(np.ldexp(bv[:, :, 1], -k[:, None]))
    status = np.zeros(p, dtype=np.int64)
    out = np.zeros((p, 5))
    if p:
        _core_many(-ux, -uy, ux, uy, ra, bvx, bvy, np.ascontiguousarray(bn), dx, dy, rb, size, f, status, out)
    hit = status == HIT
    for i in np.flatnonzero(status == EXACT) if exact else ():
        n = int(bn[i])
        pts = list(zip(bvx[i, :n].tolist(), bvy[i, :n].tolist(), strict=True))
        a0, a1 = (-float(ux[i]), -float(uy[i])), (float(ux[i]), float(uy[i]))
        found, index, excess = _decide_exactly(a0, a1, float(ra[i]), pts, float(rb[i]),
                                               (float(ax[i]), float(ay[i]), float(bx[i]), float(by[i]), int(k[i])),
                                               _ratio)
        if found:
            exact_contact(found, index, excess, a0[0], a0[1], a1[0], a1[1], ra[i], bvx[i], bvy[i], n, dx[i], dy[i],
                          rb[i], size[i], f[i], out[i])
            hit[i] = True
    return finish(hit, out[hit, 0], out[hit, 1], out[hit, 2], out[hit, 3], out[hit, 4], k[hit], ax[hit], ay[hit])
