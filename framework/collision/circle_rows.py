"""The polygon / circle kernel over the pipeline's rows, compiled: :func:`polygon_circle_pairs`.

:func:`~framework.collision.batch_circle.polygon_circle` of pairs of rows (a box, polygon or
segment and a circle, either way round), one compiled pass that reads each outline where the
geometry keeps it, as :mod:`.polygon_rows` does for polygon pairs: a pile of circles in a pit of
boxes re-measures its circles against the walls a dozen times a step, and the numpy kernel's
calls cost far more than its arithmetic.

It is the numpy kernel row by row, in the same order of operations, so the same bits: the
polygon's scaled frame, the centre's distance outside each face, inside (out through the nearest
face, by the tie-break rule), nearest a face or nearest a vertex, and
:func:`~framework.collision.batch_common.finish`. Rows within rounding of touching, where
contacts must be exact, are decided and their contacts found exactly on the floats
(:mod:`.exact_sign`, the integers' bits); the rare rows that cannot be settled there (inputs
beyond 2**±200) and a contact beyond float64's range are left to the numpy kernel (``defer``),
which answers them as it always did; a row's answer does not depend on the others of its batch.
Each pass is built twice, as :mod:`.polygon_rows` is: the first marks the rows touching to
rounding ``pending``, its ``_settled`` twin decides them exactly (compiled when a scene first
has such a row).
"""

from __future__ import annotations

import math

import numpy as np

from ..compiled import kernel
from .exact import BAND, TINY
from .exact_sign import APART, SCRATCH_CIRCLE, UNSURE, circles_excess, polygon_circle_contact
from .polygon_rows import _edges, _extent, _norm, _outline, _radius
from .row_frame import BIG, frame_row, pick_row, put_row

__all__ = ["circle_pairs", "circle_pairs_settled", "polygon_circle_pairs", "polygon_circle_pairs_settled"]


def _polygon_circle_pairs(settle):
    """The polygon / circle row pass, built twice as
    :func:`~framework.collision.polygon_rows._polygon_pairs` is: ``settle`` false, rows touching to
    rounding where contacts must be exact are marked ``pending``; true, they are decided exactly."""

    @kernel
    def polygon_circle_pairs(poly, circ, flip, hx, hy, kind, hw, hh, radius, world_poly, poly_slot, count, k,
                             exact):
        # pragma: no cover - compiled
        """``polygon_circle`` of the polygon rows ``poly[i]`` and circle rows ``circ[i]`` (``flip[i]``:
        the circle is shape A of the pair, normals from it): the contact columns, ``defer`` and
        ``pending``, as ``(floats, flags)`` (as :func:`~framework.collision.polygon_rows.polygon_pairs`)."""
        n = poly.size
        # (the columns as the rows of two blocks: each array handed back costs the caller)
        floats, flags = np.zeros((5, n)), np.zeros((3, n), dtype=np.bool_)
        nx, ny, depth, px, py = floats[0], floats[1], floats[2], floats[3], floats[4]
        hit, defer, pending = flags[0], flags[1], flags[2]
        vx, vy, ex, ey = np.empty(k), np.empty(k), np.empty(k), np.empty(k)
        s, ln, cd, cnx, cny = np.empty(k), np.empty(k), np.empty(k), np.empty(k), np.empty(k)
        scratch = np.empty(SCRATCH_CIRCLE if settle else 0)  # (the exact decisions' working space, for every row)
        for i in range(n):
            a, b = poly[i], circ[i]
            c = _outline(a, kind, hw, hh, world_poly, poly_slot, count, vx, vy)
            f = -1.0 if flip[i] else 1.0
            ax, ay, bx, by, r = hx[a], hy[a], hx[b], hy[b], radius[b]
            # The polygon's frame (batch_common.frame).
            ext = _extent(vx, vy)
            reach = ext if ext > r else r
            cx, cy, e = frame_row(ax, ay, bx, by, reach)
            for j in range(k):
                vx[j], vy[j] = math.ldexp(vx[j], -e), math.ldexp(vy[j], -e)
            r = math.ldexp(r, -e)
            rp = _radius(vx, vy)
            size = rp + r
            tol = BAND * (abs(cx) + abs(cy) + rp + r)
            _edges(vx, ex)
            _edges(vy, ey)
            any_valid = any_out = False
            for j in range(k):
                s[j] = ey[j] * (cx - vx[j]) - ex[j] * (cy - vy[j])
                if s[j] > 0.0:
                    any_out = True
                if ex[j] != 0.0 or ey[j] != 0.0:
                    any_valid = True
            inside = not any_out and any_valid
            if c == 2 and inside:  # a segment: on its line is inside only between its ends
                t0, e0 = (cx - vx[0]) * ex[0] + (cy - vy[0]) * ey[0], ex[0] * ex[0] + ey[0] * ey[0]
                inside = t0 >= 0.0 and t0 <= e0
            low = 0.0
            for j in range(k):
                absent = 0.0 if (ex[j] != 0.0 or ey[j] != 0.0) else 1.0
                ln[j] = _norm(ex[j], ey[j]) + absent
                cd[j] = (r - s[j] / ln[j]) + absent * BIG
                if j == 0 or cd[j] < low:
                    low = cd[j]
            inside_clear = inside and low > tol
            # Outside: the first face whose region holds the centre, or else the nearest vertex.
            fi = -1
            vi = 0
            best = 0.0
            for j in range(k):
                wx, wy = cx - vx[j], cy - vy[j]
                if fi < 0 and s[j] > 0.0:
                    t = wx * ex[j] + wy * ey[j]
                    if t >= 0.0 and t <= ex[j] * ex[j] + ey[j] * ey[j]:
                        fi = j
                q = wx * wx + wy * wy
                if j == 0 or q < best:
                    best, vi = q, j
            has_face = fi >= 0
            f_i = fi if has_face else 0
            fex, fey = ex[f_i], ey[f_i]
            fln = np.sqrt(fex * fex + fey * fey) + (0.0 if has_face else 1.0)
            ddx, ddy = cx - vx[vi], cy - vy[vi]
            dist = s[f_i] / fln if has_face else _norm(ddx, ddy)
            out_hit = not inside and dist > 0.0 and dist <= r - tol
            unclear = (inside and not inside_clear) or (
                not inside and (dist == 0.0 or (dist > r - tol and dist < r + tol)))
            if unclear and exact:
                # Touching to rounding: the exact decision and contact, on the floats (exact_sign).
                if settle:
                    verdict, nxi, nyi, dep, pxi, pyi = polygon_circle_contact(vx, vy, c, ax, ay, bx, by, e, r, cx, cy,
                                                                              size, f, scratch)
                    if verdict == UNSURE:
                        defer[i] = True
                        continue
                    if verdict == APART:
                        continue
                else:  # (left to the settling variant)
                    pending[i] = True
                    continue
            elif not (inside_clear or out_hit):
                continue
            elif inside_clear:
                for j in range(k):
                    cnx[j] = f * ey[j] / ln[j]
                    cny[j] = -f * ex[j] / ln[j]
                dep, nxi, nyi = pick_row(cd, cnx, cny, size)
                pxi, pyi = cx, cy
            elif has_face:
                unx, uny = fey / fln, -fex / fln
                nxi, nyi = f * unx, f * uny
                dep = r - dist
                pxi, pyi = cx - unx * dist, cy - uny * dist
            else:
                nxi, nyi = f * ddx / dist, f * ddy / dist
                dep = r - dist
                pxi, pyi = vx[vi], vy[vi]
            put_row(i, nxi, nyi, dep, pxi, pyi, e, ax, ay, hit, nx, ny, depth, px, py, defer)
        return floats, flags

    return polygon_circle_pairs


#: Every row; rows touching to rounding where contacts must be exact are marked ``pending``.
polygon_circle_pairs = _polygon_circle_pairs(False)
#: The ``pending`` rows of :data:`polygon_circle_pairs`, decided exactly (compiled when first needed).
polygon_circle_pairs_settled = _polygon_circle_pairs(True)


def _circle_pairs(settle):
    """The circle row pass, built twice as :func:`_polygon_circle_pairs` is."""

    @kernel
    def circle_pairs(ra_rows, rb_rows, hx, hy, radius, exact):  # pragma: no cover - compiled
        """``circle_circle`` of the circle rows ``(ra_rows[i], rb_rows[i])``: the contact columns,
        ``defer``, the rows left to the numpy kernel (touching to rounding where the exact decision
        on floats, :func:`~framework.collision.exact_sign.circles_excess`, cannot be made; a contact
        beyond float64's range) and ``pending``, the rows left to the settling variant, as
        ``(floats, flags)`` (as :func:`~framework.collision.polygon_rows.polygon_pairs`)."""
        n = ra_rows.size
        # (the columns as the rows of two blocks: each array handed back costs the caller)
        floats, flags = np.zeros((5, n)), np.zeros((3, n), dtype=np.bool_)
        nx, ny, depth, px, py = floats[0], floats[1], floats[2], floats[3], floats[4]
        hit, defer, pending = flags[0], flags[1], flags[2]
        for i in range(n):
            a, b = ra_rows[i], rb_rows[i]
            ax, ay, bx, by, ar, br = hx[a], hy[a], hx[b], hy[b], radius[a], radius[b]
            dx, dy, e = frame_row(ax, ay, bx, by, ar if ar > br else br)
            ra, rb = math.ldexp(ar, -e), math.ldexp(br, -e)
            rsum = ra + rb
            d2, r2 = dx * dx + dy * dy, rsum * rsum
            band = BAND * (d2 + r2)
            near = exact and d2 > r2 - band and d2 < r2 + band
            num = 0.0
            if near:
                if settle:
                    verdict, num = circles_excess(ax, ay, bx, by, e, ra, rb)
                    if verdict == UNSURE:
                        defer[i] = True
                        continue
                    if verdict == APART:
                        continue
                else:  # (left to the settling variant)
                    pending[i] = True
                    continue
            elif not d2 <= r2 - band:
                continue
            dist = math.hypot(dx, dy)
            if near:  # (the exact (ra + rb)^2 - |d|^2 = depth * (ra + rb + |d|))
                dep = num / (rsum + dist)
                dep = dep if dep > TINY else TINY
            else:
                dep = rsum - dist
            if dist > 0.0:
                nxi, nyi = dx / dist, dy / dist
            else:  # (coincident centres: push up)
                nxi, nyi = 0.0, 1.0
            lo = dist - rb if dist - rb > -ra else -ra
            hi = dist + rb if dist + rb < ra else ra
            mid = 0.5 * (lo + hi)
            put_row(i, nxi, nyi, dep, nxi * mid, nyi * mid, e, ax, ay, hit, nx, ny, depth, px, py, defer)
        return floats, flags

    return circle_pairs


#: Every row; rows touching to rounding where contacts must be exact are marked ``pending``.
circle_pairs = _circle_pairs(False)
#: The ``pending`` rows of :data:`circle_pairs`, decided exactly (compiled when first needed).
circle_pairs_settled = _circle_pairs(True)
