"""The exact box kernel of one pair, compiled: :func:`aabb_exact_row`.

:func:`~framework.collision.batch_box.aabb_aabb` (the contacts of ``collide(AABB, .., AABB, ..)``,
its point the mean of the overlap's corners and crossings) for one pair, in the same order of
operations, so the same bits. The polygon kernel over rows (:mod:`.polygon_rows`) answers two
centred boxes with it where the narrow phase wants exact contacts with their points: resting
boxes that can turn but have not (a pyramid of polygons at rest) are such pairs every step.
"""

from __future__ import annotations

import math

from ..compiled import inner, kernel
from .batch_box import _less_1, _two_sum_1
from .collide import POINT_TOL
from .exact import BAND, TINY
from .row_frame import frame_row, world_row
from .tiebreak import DEPTH_TOL

__all__ = ["aabb_exact_row"]


@inner
def _crossing(t, u, gone):  # pragma: no cover - compiled
    """``batch_box._crossing`` of one edge pair, as a float."""
    return 1.0 if (t >= 0.0 and t <= 1.0 and u >= 0.0 and u <= 1.0 and not gone) else 0.0


@inner
def _clip(t):  # pragma: no cover - compiled
    """``np.minimum(np.maximum(t, 0.0), 1.0)``."""
    t = t if t >= 0.0 else 0.0
    return t if t <= 1.0 else 1.0


@inner
def _box_point(hwa, hha, hwb, hhb, dx, dy, size):  # pragma: no cover - compiled
    """``batch_box._box_point`` of one pair (B at its offset ``d``, all in the scaled frame)."""
    xb0, xb1, yb0, yb1 = -hwb + dx, hwb + dx, -hhb + dy, hhb + dy
    tol = POINT_TOL * size
    wa, ha = hwa + hwa, hha + hha
    wb, hb = xb1 - xb0, yb1 - yb0
    # batch_box._corners_inside: A's corners in B, then B's in A.
    sx = sy = count = 0.0
    for group in range(2):
        if group == 0:
            x0, x1, y0, y1 = -hwa, hwa, -hha, hha
            mx0 = not ((-(hb * (x0 - xb1)) < -tol * hb) or ((hb * (x0 - xb0)) < -tol * hb))
            mx1 = not ((-(hb * (x1 - xb1)) < -tol * hb) or ((hb * (x1 - xb0)) < -tol * hb))
            my0 = not ((wb * (y0 - yb0) < -tol * wb) or ((-wb) * (y0 - yb1) < -tol * wb))
            my1 = not ((wb * (y1 - yb0) < -tol * wb) or ((-wb) * (y1 - yb1) < -tol * wb))
        else:
            x0, x1, y0, y1 = xb0, xb1, yb0, yb1
            mx0 = not ((-(ha * (x0 - hwa)) < -tol * ha) or ((ha * (x0 - (-hwa))) < -tol * ha))
            mx1 = not ((-(ha * (x1 - hwa)) < -tol * ha) or ((ha * (x1 - (-hwa))) < -tol * ha))
            my0 = not ((wa * (y0 - (-hha)) < -tol * wa) or ((-wa) * (y0 - hha) < -tol * wa))
            my1 = not ((wa * (y1 - (-hha)) < -tol * wa) or ((-wa) * (y1 - hha) < -tol * wa))
        fx0, fx1 = 1.0 if mx0 else 0.0, 1.0 if mx1 else 0.0
        fy0, fy1 = 1.0 if my0 else 0.0, 1.0 if my1 else 0.0
        nxin, nyin = fx0 + fx1, fy0 + fy1
        sx += (x0 * fx0 + x1 * fx1) * nyin
        sy += (y0 * fy0 + y1 * fy1) * nxin
        count += nxin * nyin
    # batch_box._edge_crossings: A's bottom / top edges with B's right / left ones, then A's
    # right / left edges with B's bottom / top ones; each family's four sums in order.
    hsx = hsy = hsc = vsx = vsy = vsc = 0.0
    for m in range(4):
        p_x = -hwa if m < 2 else hwa
        p_y = -hha if m < 2 else hha
        r = wa if m < 2 else -wa
        q_x = xb1 if m % 2 == 0 else xb0
        q_y = yb0 if m % 2 == 0 else yb1
        s_ = hb if m % 2 == 0 else -hb
        den = r * s_
        gone = den == 0.0
        if gone:
            den += 1.0
        t = ((q_x - p_x) * s_) / den
        u = (-((q_y - p_y) * r)) / den
        c = _crossing(t, u, gone)
        hx_, hy_ = (p_x + _clip(t) * r) * c, p_y * c
        if m == 0:
            hsx, hsy, hsc = hx_, hy_, c
        else:
            hsx += hx_
            hsy += hy_
            hsc += c
    for m in range(4):
        p_x = hwa if m < 2 else -hwa
        p_y = -hha if m < 2 else hha
        r = ha if m < 2 else -ha
        q_x = xb0 if m % 2 == 0 else xb1
        q_y = yb0 if m % 2 == 0 else yb1
        s_ = wb if m % 2 == 0 else -wb
        den = -(r * s_)
        gone = den == 0.0
        if gone:
            den += 1.0
        t = (-((q_y - p_y) * s_)) / den
        u = ((q_x - p_x) * r) / den
        c = _crossing(t, u, gone)
        vx_, vy_ = p_x * c, (p_y + _clip(t) * r) * c
        if m == 0:
            vsx, vsy, vsc = vx_, vy_, c
        else:
            vsx += vx_
            vsy += vy_
            vsc += c
    sx += hsx + vsx
    sy += hsy + vsy
    count += hsc + vsc
    if count > 0.0:
        return sx / count, sy / count, True
    return 0.0, 0.0, False  # (rounding hid every vertex: the caller's generic fallback)


@kernel
def aabb_exact_row(ax, ay, ahw, ahh, bx, by, bhw, bhh):  # pragma: no cover - compiled
    """``aabb_aabb`` of one pair: ``(hit, nx, ny, depth, px, py, found)``; ``found`` False where
    rounding hid every vertex of the overlap or a value is beyond float64's range (the caller
    answers that rare pair otherwise)."""
    dxh, dxl = _two_sum_1(bx, -ax)
    rxh, rxl = _two_sum_1(ahw, bhw)
    dyh, dyl = _two_sum_1(by, -ay)
    ryh, ryl = _two_sum_1(ahh, bhh)
    if not (_less_1(dxh, dxl, rxh, rxl) and _less_1(dyh, dyl, ryh, ryl)):
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, True
    ra, rb = math.hypot(ahw, ahh), math.hypot(bhw, bhh)
    # batch_common.frame
    reach = ra if ra > rb else rb
    dx, dy, k = frame_row(ax, ay, bx, by, reach)
    hwa, hha, hwb, hhb = math.ldexp(ahw, -k), math.ldexp(ahh, -k), math.ldexp(bhw, -k), math.ldexp(bhh, -k)
    size = math.ldexp(ra + rb, -k)
    wa, wb, ha, hb = hwa + hwa, hwb + hwb, hha + hha, hhb + hhb
    # batch_box._overlaps, then the depths of the four directions.
    both = wa * hha + wa * hhb
    up0, down0 = both - wa * dy, both + wa * dy
    both = wb * hha + wb * hhb
    up1, down1 = both - wb * dy, both + wb * dy
    both = ha * hwa + ha * hwb
    right0, left0 = both - ha * dx, both + ha * dx
    both = hb * hwa + hb * hwb
    right1, left1 = both - hb * dx, both + hb * dx
    up = min(max(up0 / wa, TINY), max(up1 / wb, TINY))
    down = min(max(down0 / wa, TINY), max(down1 / wb, TINY))
    right = min(max(right0 / ha, TINY), max(right1 / hb, TINY))
    left = min(max(left0 / ha, TINY), max(left1 / hb, TINY))
    # Within the band around touching, depths from the exact overlaps: reach -/+ offset.
    mag = size + abs(dx) + abs(dy)
    if min(min(up, down), min(right, left)) <= 2.0 * BAND * mag:
        right = max(math.ldexp((rxh - dxh) + (rxl - dxl), -k), TINY)
        left = max(math.ldexp((rxh + dxh) + (rxl + dxl), -k), TINY)
        up = max(math.ldexp((ryh - dyh) + (ryl - dyl), -k), TINY)
        down = max(math.ldexp((ryh + dyh) + (ryl + dyl), -k), TINY)
    # The tie-break rule: keep the near-shortest; prefer vertical; then up (or right).
    lim = min(min(up, down), min(right, left)) + DEPTH_TOL * size
    if up <= lim or down <= lim:
        nx, ny, depth = 0.0, (1.0 if up <= lim else -1.0), (up if up <= lim else down)
    else:
        nx, ny, depth = (1.0 if right <= lim else -1.0), 0.0, (right if right <= lim else left)
    px, py, found = _box_point(hwa, hha, hwb, hhb, dx, dy, size)
    finite, depth, px, py = world_row(depth, px, py, k, ax, ay)
    return True, nx + 0.0, ny + 0.0, depth, px, py, found and finite

