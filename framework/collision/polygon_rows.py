"""The polygon kernel over the pipeline's rows, compiled: :func:`polygon_pairs`.

:func:`~framework.collision.batch_polygon.polygon_polygon` of pairs of rows (boxes and polygons in
any mix but AABB / AABB), one compiled pass that reads each row's outline where the geometry keeps
it (an AABB's from its half extents, a polygon's or segment's turned outline) instead of gathering
outlines into padded ``[K, P]`` arrays first. The narrow phase and the solve's re-measures call it
some ten times a step with a few dozen pairs each, where the numpy kernel's hundred-odd calls cost
far more than its arithmetic.

It is the numpy kernel row by row, in the same order of operations, so the same bits: the scaled
frame, the separating axes and their band around touching, the candidates of the tie-break rule
and :func:`~framework.collision.tiebreak.pick`'s steps, the contact point as
:func:`~framework.collision.batch_point.overlap_point` finds it (its sums in the same sequential
order), and :func:`~framework.collision.batch_common.finish`.

Rows it leaves to the numpy kernel (``defer``), which then answers them as it always did:

- two centred axis-aligned boxes of extreme magnitudes, or whose overlap rounding hid (the box
  kernels answer two centred boxes, :func:`~framework.collision.batch_box.aabb_aabb` compiled
  in :mod:`.box_pair_row` where contacts must be exact with their points);
- rows within rounding of touching on some axis where contacts must be exact and whose exact
  decision and depths (on the floats, :mod:`.exact_sign`, the integer fallback's of
  :mod:`~framework.collision.exact` bit for bit) cannot be settled there (inputs beyond about
  2**±300);
- a contact beyond float64's range (the numpy kernel raises the error).

A row's answer does not depend on the other rows of its batch (the numpy kernel's sums are
sequential per row for that reason), so answering a few rows apart gives the same bits. The pass
is built twice for that reason: :data:`polygon_pairs` marks the rows touching to rounding
(``pending``) and :data:`polygon_pairs_settled` decides them exactly. Most scenes never have such
a row, and a new installation then never compiles the exact functions (about 8 seconds of
numba's time with the polygon / circle and circle passes, which are built the same way).
"""

from __future__ import annotations

import math

import numpy as np

from ..compiled import kernel, leaf
from .batch_box import _aabb_row
from .box_pair_row import aabb_exact_row
from .collide import POINT_TOL
from .exact import BAND, TINY
from .exact_sign import APART, OVERLAP, SCRATCH, polygon_depths, polygons_apart
from .kinds import KIND_AABB
from .row_frame import BIG, frame_row, pick_row, put_row

__all__ = ["polygon_pairs", "polygon_pairs_settled"]



@leaf
def _outline(r, kind, hw, hh, world_poly, poly_slot, count, vx, vy):  # pragma: no cover - compiled
    """Row ``r``'s outline about its hitbox origin into ``vx, vy`` (``K`` slots, the padding
    repeating the last vertex, as ``batch_common.outline_rows`` writes it); returns its count."""
    k = vx.size
    if kind[r] == KIND_AABB:
        w, h = hw[r], hh[r]
        vx[0], vy[0] = -w, -h
        vx[1], vy[1] = w, -h
        vx[2], vy[2] = w, h
        for j in range(3, k):
            vx[j], vy[j] = -w, h
        return 4
    s, c = poly_slot[r], count[r]
    for j in range(k):
        m = j if j < c else c - 1
        vx[j], vy[j] = world_poly[s, m, 0], world_poly[s, m, 1]
    return c


@leaf
def _centred_box(vx, vy, c):  # pragma: no cover - compiled
    """``batch_polygon._centred_boxes`` of one outline."""
    if vx.size < 4:
        return False
    return (c == 4 and vx[1] > 0.0 and vy[2] > 0.0 and vx[0] == -vx[1] and vx[2] == vx[1] and vx[3] == vx[0]
            and vy[1] == vy[0] and vy[0] == -vy[2] and vy[3] == vy[2])


@leaf
def _norm(x, y):  # pragma: no cover - compiled
    """``batch_common.norm`` of one vector."""
    n = np.sqrt(x * x + y * y)
    return math.hypot(x, y) if n < 1e-150 else n


@leaf
def _edges(v, e):  # pragma: no cover - compiled
    """``batch_common.edges`` of one outline coordinate into ``e``."""
    k = v.size
    for j in range(k - 1):
        e[j] = v[j + 1] - v[j]
    e[k - 1] = v[0] - v[k - 1]


@leaf
def _extent(vx, vy):  # pragma: no cover - compiled
    """``batch_common.extent`` of one outline."""
    mx = abs(vx[0])
    my = abs(vy[0])
    for j in range(1, vx.size):
        if abs(vx[j]) > mx:
            mx = abs(vx[j])
        if abs(vy[j]) > my:
            my = abs(vy[j])
    return mx if mx > my else my


@leaf
def _radius(vx, vy):  # pragma: no cover - compiled
    """The root of the largest squared vertex length (``_frame``'s bounding radius)."""
    m = vx[0] * vx[0] + vy[0] * vy[0]
    for j in range(1, vx.size):
        q = vx[j] * vx[j] + vy[j] * vy[j]
        if q > m:
            m = q
    return np.sqrt(m)


@leaf
def _project(ux, uy, vx, vy):  # pragma: no cover - compiled
    """Min and max of an outline's vertices projected on axis ``u`` (``batch_polygon._extent``)."""
    lo = ux * vx[0] + uy * vy[0]
    hi = lo
    for j in range(1, vx.size):
        p = ux * vx[j] + uy * vy[j]
        if p < lo:
            lo = p
        if p > hi:
            hi = p
    return lo, hi


@leaf
def _inside(x, y, ox, oy, ex, ey, en, tol):  # pragma: no cover - compiled
    """``batch_point._inside`` of one point against one outline (vertices ``o``, edges ``e``,
    their lengths ``en``)."""
    for e in range(ox.size):
        cross = ex[e] * (y - oy[e])
        cross -= ey[e] * (x - ox[e])
        if cross < -tol * en[e]:
            return False
    return True


@leaf
def _within_segment(x, y, ox, oy, tol):  # pragma: no cover - compiled
    """``batch_point._within_segment`` of one point and a segment (an outline of two points)."""
    ex, ey = ox[1] - ox[0], oy[1] - oy[0]
    along = ex * (x - ox[0]) + ey * (y - oy[0])
    slack = tol * _norm(ex, ey)
    return along >= -slack and along <= ex * ex + ey * ey + slack


@leaf
def _overlap_point(avx, avy, ac, bvx, bvy, bc, nx, ny, depth, size, exa, eya, exb, eyb, na, nb):
    # pragma: no cover - compiled
    """``batch_point.overlap_point`` of one pair (B at its offset): the mean of the vertices of
    A ∩ B, its sums in the numpy kernel's order (A's vertices, B's, then the crossings)."""
    k = avx.size
    tol = POINT_TOL * size
    _edges(avx, exa)
    _edges(avy, eya)
    _edges(bvx, exb)
    _edges(bvy, eyb)
    for j in range(k):
        na[j] = _norm(exa[j], eya[j])
        nb[j] = _norm(exb[j], eyb[j])
    sxa = sya = ca = 0.0
    sxb = syb = cb = 0.0
    for j in range(k):
        ina = j < ac and _inside(avx[j], avy[j], bvx, bvy, exb, eyb, nb, tol)
        if ina and bc == 2:
            ina = _within_segment(avx[j], avy[j], bvx, bvy, tol)
        inb = j < bc and _inside(bvx[j], bvy[j], avx, avy, exa, eya, na, tol)
        if inb and ac == 2:
            inb = _within_segment(bvx[j], bvy[j], avx, avy, tol)
        fa, fb = 1.0 if ina else 0.0, 1.0 if inb else 0.0
        if j == 0:
            sxa, sya, ca = avx[j] * fa, avy[j] * fa, fa
            sxb, syb, cb = bvx[j] * fb, bvy[j] * fb, fb
        else:
            sxa += avx[j] * fa
            sya += avy[j] * fa
            ca += fa
            sxb += bvx[j] * fb
            syb += bvy[j] * fb
            cb += fb
    sx, sy, count = sxa + sxb, sya + syb, ca + cb
    tx = ty = tc = 0.0
    for i in range(k):
        rx, ry = exa[i], eya[i]
        for j in range(k):
            sx_, sy_ = exb[j], eyb[j]
            den = rx * sy_ - ry * sx_
            wx = bvx[j] - avx[i]
            wy = bvy[j] - avy[i]
            parallel = den == 0.0
            if parallel:
                den += 1.0
            t = (wx * sy_ - wy * sx_) / den
            u = (wx * ry - wy * rx) / den
            f = 1.0 if (t >= 0.0 and t <= 1.0 and u >= 0.0 and u <= 1.0 and not parallel) else 0.0
            t = 0.0 if t < 0.0 else t
            t = 1.0 if t > 1.0 else t
            vx_ = (avx[i] + t * rx) * f
            vy_ = (avy[i] + t * ry) * f
            if i == 0 and j == 0:
                tx, ty, tc = vx_, vy_, f
            else:
                tx += vx_
                ty += vy_
                tc += f
    sx += tx
    sy += ty
    count += tc
    if count > 0.0:
        return sx / count, sy / count
    # Rounding hid every vertex (near-degenerate only): the middle of the penetration segment from
    # B's deepest vertex.
    j = 0
    low = bvx[0] * nx + bvy[0] * ny
    for m in range(1, k):
        v = bvx[m] * nx + bvy[m] * ny
        if v < low:
            low, j = v, m
    half = depth * 0.5
    return bvx[j] + nx * half, bvy[j] + ny * half


def _polygon_pairs(settle):
    """The row pass, built twice (module docstring): ``settle`` false, rows touching to rounding
    where contacts must be exact are only marked ``pending``; ``settle`` true, they are decided
    exactly. (``settle`` is a constant of the closure: numba drops the branch not taken before
    typing, so the exact functions compile only with the settling variant.)"""

    @kernel
    def polygon_pairs(ra, rb, hx, hy, kind, hw, hh, world_poly, poly_slot, count, k, exact, points):
        # pragma: no cover - compiled
        """``polygon_polygon`` of the pairs of rows ``(ra[i], rb[i])`` (module docstring), as
        ``(floats, flags)``: the rows of ``floats`` the contact columns ``nx, ny, depth, px, py``,
        of ``flags`` ``hit``, ``defer`` (the rows left to the numpy kernel) and ``pending`` (the
        rows left to the settling variant)."""
        n = ra.size
        # (the columns as the rows of two blocks: each array handed back costs the caller)
        floats, flags = np.zeros((5, n)), np.zeros((3, n), dtype=np.bool_)
        nx, ny, depth, px, py = floats[0], floats[1], floats[2], floats[3], floats[4]
        hit, defer, pending = flags[0], flags[1], flags[2]
        extreme = np.zeros(n, dtype=np.bool_)
        avx, avy, bvx, bvy = np.empty(k), np.empty(k), np.empty(k), np.empty(k)
        ux, uy, fwd, bwd = np.empty(2 * k), np.empty(2 * k), np.empty(2 * k), np.empty(2 * k)
        need = np.zeros(2 * k, dtype=np.int64)
        cd, cx, cy = np.empty(4 * k), np.empty(4 * k), np.empty(4 * k)
        exa, eya, exb, eyb, na, nb = np.empty(k), np.empty(k), np.empty(k), np.empty(k), np.empty(k), np.empty(k)
        scratch = np.empty(SCRATCH if settle else 0)  # (the exact decisions' working space, for every row)
        for i in range(n):
            a, b = ra[i], rb[i]
            ac = _outline(a, kind, hw, hh, world_poly, poly_slot, count, avx, avy)
            bc = _outline(b, kind, hw, hh, world_poly, poly_slot, count, bvx, bvy)
            ax, ay, bx, by = hx[a], hy[a], hx[b], hy[b]
            if _centred_box(avx, avy, ac) and _centred_box(bvx, bvy, bc):
                if exact and points:
                    h, nxi, nyi, dep, pxi, pyi, found = aabb_exact_row(ax, ay, avx[1], avy[2], bx, by, bvx[1], bvy[2])
                    if not found:
                        defer[i] = True
                    elif h:
                        hit[i] = True
                        nx[i], ny[i], depth[i], px[i], py[i] = nxi, nyi, dep, pxi, pyi
                    continue
                hit[i], nx[i], ny[i], depth[i], px[i], py[i], extreme[i] = _aabb_row(ax, ay, avx[1], avy[2], bx, by,
                                                                                     bvx[1], bvy[2], exact, points)
                if exact and extreme[i]:
                    defer[i] = True
                continue
            # The scaled frame (batch_common.frame, batch_polygon._frame).
            ea, eb = _extent(avx, avy), _extent(bvx, bvy)
            reach = ea if ea > eb else eb  # (np.maximum: no NaN here)
            dx, dy, e = frame_row(ax, ay, bx, by, reach)
            for j in range(k):
                avx[j], avy[j] = math.ldexp(avx[j], -e), math.ldexp(avy[j], -e)
                bvx[j], bvy[j] = math.ldexp(bvx[j], -e), math.ldexp(bvy[j], -e)
            sz = _radius(avx, avy) + _radius(bvx, bvy)
            # Separating axes (batch_polygon._sat): unnormalised outward edge normals of A, then of B.
            _edges(avy, exa)
            _edges(avx, eya)
            _edges(bvy, exb)
            _edges(bvx, eyb)
            for j in range(k):
                ux[j], uy[j] = exa[j], -eya[j]
                ux[k + j], uy[k + j] = exb[j], -eyb[j]
            apart = ac == 2 and bc == 2
            border = any_valid = False
            reach2 = sz + abs(dx) + abs(dy)
            for c in range(2 * k):
                need[c] = 0
                if ux[c] == 0.0 and uy[c] == 0.0:
                    continue
                any_valid = True
                amin, amax = _project(ux[c], uy[c], avx, avy)
                bmin, bmax = _project(ux[c], uy[c], bvx, bvy)
                ud = ux[c] * dx + uy[c] * dy
                fwd[c] = (amax - bmin) - ud
                bwd[c] = (bmax - amin) + ud
                least = fwd[c] if fwd[c] < bwd[c] else bwd[c]
                tol = BAND * (abs(ux[c]) + abs(uy[c])) * reach2
                if least < -tol:
                    apart = True
                    break
                need[c] = (1 if fwd[c] <= tol else 0) + (2 if bwd[c] <= tol else 0)
                if least <= tol:
                    border = True
            if apart or not any_valid:
                continue
            if border:
                # Touching to rounding: apart unless exact, where the exact decision and depths are
                # found on the floats (exact_sign); only what that cannot settle is deferred.
                if not exact:
                    continue
                if settle:
                    verdict = polygons_apart(avx, avy, ac, bvx, bvy, bc, ax, ay, bx, by, e, need, scratch)
                    if verdict == APART:
                        continue
                    if not (verdict == OVERLAP and polygon_depths(avx, avy, ac, bvx, bvy, bc, ax, ay, bx, by, e, fwd,
                                                                  bwd, scratch)):
                        defer[i] = True
                        continue
                else:  # (left to the settling variant)
                    pending[i] = True
                    continue
                # (an overlap: every axis's exact overlaps, rounded, as the integers give them)
            # Candidates in the scalar code's order: per axis, forward then backward.
            for c in range(2 * k):
                if ux[c] == 0.0 and uy[c] == 0.0:  # (a padding edge: ln 1, the depth BIG, as the numpy)
                    cx[2 * c], cy[2 * c] = ux[c], uy[c]
                    cx[2 * c + 1], cy[2 * c + 1] = -ux[c], -uy[c]
                    cd[2 * c] = cd[2 * c + 1] = BIG
                    continue
                ln = _norm(ux[c], uy[c])
                cx[2 * c] = ux[c] / ln
                cy[2 * c] = uy[c] / ln
                cx[2 * c + 1] = -cx[2 * c]
                cy[2 * c + 1] = -cy[2 * c]
                d = fwd[c] / ln
                cd[2 * c] = (d if d > TINY else TINY) + 0.0
                d = bwd[c] / ln
                cd[2 * c + 1] = (d if d > TINY else TINY) + 0.0
            dep, nxi, nyi = pick_row(cd, cx, cy, sz)
            pxi = pyi = 0.0
            if points:
                for j in range(k):
                    bvx[j] += dx
                    bvy[j] += dy
                pxi, pyi = _overlap_point(avx, avy, ac, bvx, bvy, bc, nxi, nyi, dep, sz, exa, eya, exb, eyb, na, nb)
            put_row(i, nxi, nyi, dep, pxi, pyi, e, ax, ay, hit, nx, ny, depth, px, py, defer)
        return floats, flags

    return polygon_pairs


#: Every row; rows touching to rounding where contacts must be exact are marked ``pending``.
polygon_pairs = _polygon_pairs(False)
#: The ``pending`` rows of :data:`polygon_pairs`, decided exactly (compiled when a scene first has one).
polygon_pairs_settled = _polygon_pairs(True)
