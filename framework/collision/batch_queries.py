"""Many scene queries at once: which hitboxes hold each of many points, which is nearest each, where
each of many rays first enters one, as one compiled pass per batch.

The kernels redo, query by query and row by row, the float arithmetic of the single queries
(:func:`~framework.collision.distance.point_distance`, :func:`~framework.collision.ray.raycast`
and the containment test of ``Scene.query_point``) in the same order of operations, so that
their answers are the same floats, bit for bit, not only close:

- ``math.hypot`` is CPython's own algorithm (:func:`~framework.collision.py_hypot.hypot`, a port
  of ``vector_norm`` in ``Modules/mathmodule.c``), not the C library's, which differs from it in
  the last bit for about 1 input in 500;
- ``x ** 2`` is ``math.pow(x, two)`` with ``two`` a run-time argument (CPython calls the C
  library's ``pow``; a literal exponent would be folded into ``x * x``, which rounds differently
  for about 1 input in 1,000);
- ``math.cos``, ``math.sin``, ``math.frexp``, ``math.ldexp`` and ``math.sqrt`` are the C library's
  in both.

Where the single ray cast decides on exact rationals (a test within
:data:`~framework.collision.exact.BAND` of touching: a graze, a corner, a tangent, an origin on a
boundary), the kernel does not guess: it reports the (ray, row) pair as *unresolved* and the caller
answers it with :func:`~framework.collision.ray.raycast` itself. Capsules' rays are always
answered that way (their pieces, :func:`~framework.collision.pieces.rounded_segment`, are not
compiled); points against capsules are compiled.

Candidate rows are found as the single queries find them in scenes of up to
:data:`~framework.collision.broad_phase.DIRECT_QUERY` rows: each row's bounds against the query's
box (strictly, widened by ``1e-9``), then the layer mask. Rows that cannot change the answer are
skipped on conservative tests (a ray that misses a row's bounds widened by a margin far above
rounding; a row whose bounds are farther than the best distance found, plus that margin).
"""

from __future__ import annotations

import math

import numpy as np

from ..compiled import kernel
from .exact import BAND
from .pieces import TIE
from .py_hypot import hypot
from .ray import closest_on_segment_compiled as _closest_on_segment
from .tiebreak import DIR_TOL

__all__ = ["hypot", "nearest_points", "points_inside", "rays_first", "ray_rows"]

# Kind codes of the rows (as framework.collision.kinds; repeated for the compiled code).
_AABB, _CIRCLE, _POLYGON, _CAPSULE, _SEGMENT = 0, 1, 2, 3, 4
_FAR = 500  # framework.collision.ray.FAR
_NEAR = 1e-9  # the widening of the single queries' candidate boxes
_SLACK = 1e-9  # relative margin of the skipping tests (rounding is below 1e-15 of the magnitudes)


@kernel
def _grow(a, m):  # pragma: no cover - compiled
    b = np.empty(max(2 * a.size, m + 1), dtype=a.dtype)
    b[: a.size] = a
    return b


# --- points inside hitboxes (Scene.query_point) -----------------------------------------------


@kernel
def _contains(r, skind, kind, hx, hy, radius, cap_ux, cap_uy, hw, hh, world_poly, poly_slot, count, px, py,
              two):  # pragma: no cover - compiled
    """SpatialQueries._contains: closed containment of (px, py) in row r."""
    dx, dy = px - hx[r], py - hy[r]
    k = skind[r]
    if k == _CIRCLE:
        return dx * dx + dy * dy <= radius[r] * radius[r]
    if k == _CAPSULE:
        ux, uy = cap_ux[r], cap_uy[r]
        cx, cy = _closest_on_segment(dx, dy, -ux, -uy, ux, uy)
        return math.pow(dx - cx, two) + math.pow(dy - cy, two) <= radius[r] * radius[r]
    if kind[r] == _AABB:
        w, h = hw[r], hh[r]
        xs = (-w, w, w, -w)
        ys = (-h, -h, h, h)
        for i in range(4):
            x0, y0 = xs[i], ys[i]
            x1, y1 = xs[(i + 1) % 4], ys[(i + 1) % 4]
            if (x1 - x0) * (dy - y0) - (y1 - y0) * (dx - x0) < 0.0:
                return False
        return True
    if k == _SEGMENT:  # the point on it, between its ends (then on both of its sides' lines)
        pts = world_poly[poly_slot[r]]
        x0, y0, x1, y1 = pts[0, 0], pts[0, 1], pts[1, 0], pts[1, 1]
        along = (x1 - x0) * (dx - x0) + (y1 - y0) * (dy - y0)
        if not (0.0 <= along <= math.pow(x1 - x0, two) + math.pow(y1 - y0, two)):
            return False
        return not ((x1 - x0) * (dy - y0) - (y1 - y0) * (dx - x0) < 0.0
                    or (x0 - x1) * (dy - y1) - (y0 - y1) * (dx - x1) < 0.0)
    if kind[r] == _POLYGON:
        pts = world_poly[poly_slot[r]]
        n = count[r]
        for i in range(n):
            x0, y0 = pts[i, 0], pts[i, 1]
            j = (i + 1) % n
            x1, y1 = pts[j, 0], pts[j, 1]
            if (x1 - x0) * (dy - y0) - (y1 - y0) * (dx - x0) < 0.0:
                return False
        return True
    return False  # (a live shape of another kind than its row's: not reached between steps)


@kernel
def points_inside(px, py, kind, skind, layer, entity, minx, miny, maxx, maxy, hx, hy, radius, cap_ux, cap_uy,
                  hw, hh, world_poly, poly_slot, count, mask, two):  # pragma: no cover - compiled
    """For each point, the entities whose hitbox contains it (closed), sorted: ``(offsets,
    entities)``, point ``i``'s entities being ``entities[offsets[i]:offsets[i + 1]]``."""
    n = px.size
    offsets = np.zeros(n + 1, dtype=np.int64)
    out = np.empty(max(16, n), dtype=np.int64)
    m = 0
    for i in range(n):
        x, y = px[i], py[i]
        x0, y0, x1, y1 = x - _NEAR, y - _NEAR, x + _NEAR, y + _NEAR
        start = m
        for r in range(kind.size):
            if not (kind[r] >= 0 and minx[r] < x1 and maxx[r] > x0 and miny[r] < y1 and maxy[r] > y0):
                continue
            if (layer[r] & mask) == 0:
                continue
            if not _contains(r, skind, kind, hx, hy, radius, cap_ux, cap_uy, hw, hh, world_poly, poly_slot, count,
                             x, y, two):
                continue
            if m >= out.size:
                out = _grow(out, m)
            e = entity[r]
            j = m  # insertion sort: a point is in few hitboxes
            while j > start and out[j - 1] > e:
                out[j] = out[j - 1]
                j -= 1
            out[j] = e
            m += 1
        offsets[i + 1] = m
    return offsets, out[:m].copy()


# --- the nearest hitbox (Scene.nearest) -------------------------------------------------------


@kernel
def _point_distance(k, sa, sb, local, cnt, x, y, rot, px, py):  # pragma: no cover - compiled
    """framework.collision.distance.point_distance of the shape of kind ``k`` (``sa, sb``: half
    width and height of an AABB, radius of a circle, radius and length of a capsule; ``local``,
    ``cnt``: a polygon's points) at (x, y, rot): ``(d, bx, by)``."""
    c, s = math.cos(rot), math.sin(rot)
    cx = np.empty(max(4, cnt))
    cy = np.empty(max(4, cnt))
    r = 0.0
    if k == _CIRCLE:
        n = 1
        cx[0], cy[0] = x, y
        r = sa
    elif k == _CAPSULE:
        n = 2
        h = 0.5 * sb
        cx[0], cy[0] = x + s * h, y - c * h
        cx[1], cy[1] = x - s * h, y + c * h
        r = sa
    elif k == _AABB:
        n = 4
        hw, hh = sa, sb
        cx[0], cy[0] = x - hw, y - hh
        cx[1], cy[1] = x + hw, y - hh
        cx[2], cy[2] = x + hw, y + hh
        cx[3], cy[3] = x - hw, y + hh
    else:
        n = cnt
        for i in range(n):
            qx, qy = local[i, 0], local[i, 1]
            cx[i] = x + c * qx - s * qy
            cy[i] = y + s * qx + c * qy
    if n >= 3:
        inside = True
        for i in range(n):
            j = (i + 1) % n
            if (cx[j] - cx[i]) * (py - cy[i]) - (cy[j] - cy[i]) * (px - cx[i]) < 0.0:
                inside = False
                break
        if inside:
            return 0.0, px, py
    best, bx, by = math.inf, px, py
    edges = 1 if n <= 2 else n
    for i in range(edges):
        j = 0 if n == 1 else (1 if n == 2 else (i + 1) % n)
        qx, qy = _closest_on_segment(px, py, cx[i], cy[i], cx[j], cy[j])
        d = hypot(px - qx, py - qy)
        if d < best:
            best, bx, by = d, qx, qy
    if best <= r:
        return 0.0, px, py
    return best - r, bx + r * (px - bx) / best, by + r * (py - by) / best


@kernel
def nearest_points(px, py, max_distance, kind, skind, sa, sb, local, cnt, layer, entity, minx, miny, maxx, maxy,
                   hx, hy, rot, mask):  # pragma: no cover - compiled
    """For each point, the row nearest it within ``max_distance`` (as ``Scene.nearest``; ties to the
    lower entity): ``(entity, distance, x, y)``, entity -1 (distance inf, point the query's) where
    none is."""
    n = px.size
    ent = np.full(n, -1, dtype=np.int64)
    dist = np.full(n, math.inf)
    bxs, bys = px.copy(), py.copy()
    md = max_distance
    bounded = math.isfinite(md)
    for i in range(n):
        x, y = px[i], py[i]
        x0, y0, x1, y1 = x - md - _NEAR, y - md - _NEAR, x + md + _NEAR, y + md + _NEAR
        best_d, best_e, best_x, best_y = math.inf, -1, x, y
        slack = _SLACK * (1.0 + abs(x) + abs(y))
        for r in range(kind.size):
            if kind[r] < 0:
                continue
            if bounded and not (minx[r] < x1 and maxx[r] > x0 and miny[r] < y1 and maxy[r] > y0):
                continue
            if (layer[r] & mask) == 0:
                continue
            if best_e >= 0:  # the row's bounds farther than the best: it cannot win (nor tie)
                gx = max(minx[r] - x, x - maxx[r], 0.0)
                gy = max(miny[r] - y, y - maxy[r], 0.0)
                if math.sqrt(gx * gx + gy * gy) > best_d + slack * (1.0 + abs(minx[r]) + abs(maxy[r])):
                    continue
            d, qx, qy = _point_distance(skind[r], sa[r], sb[r], local[r], cnt[r], hx[r], hy[r], rot[r], x, y)
            e = entity[r]
            if d <= md and (best_e < 0 or d < best_d or (d == best_d and e < best_e)):
                best_d, best_e, best_x, best_y = d, e, qx, qy
        if best_e >= 0:
            ent[i], dist[i], bxs[i], bys[i] = best_e, best_d, best_x, best_y
    return ent, dist, bxs, bys


# --- rays (Scene.raycast) ---------------------------------------------------------------------


@kernel
def _pick(nxs, nys, m):  # pragma: no cover - compiled
    """framework.collision.tiebreak.pick of ``m`` candidates of equal depth: the index of the winner."""
    if m == 1:
        return 0
    keep = np.ones(m, dtype=np.bool_)
    top = -math.inf
    for i in range(m):
        top = max(top, abs(nys[i]))
    left = 0
    for i in range(m):
        keep[i] = abs(nys[i]) >= top - DIR_TOL
        left += keep[i]
    if left == 1:
        for i in range(m):
            if keep[i]:
                return i
    fx = -math.inf
    fold = np.empty(m)
    for i in range(m):
        ny = nys[i]
        fold[i] = -nxs[i] if (ny < -DIR_TOL or (abs(ny) <= DIR_TOL and nxs[i] < 0.0)) else nxs[i]
        if keep[i]:
            fx = max(fx, fold[i])
    left = 0
    for i in range(m):
        keep[i] = keep[i] and fold[i] >= fx - DIR_TOL
        left += keep[i]
    if left == 1:
        for i in range(m):
            if keep[i]:
                return i
    # max by (ny > DIR_TOL, nx > DIR_TOL): the first such
    best, key = -1, -1
    for i in range(m):
        if keep[i]:
            kk = 2 * (nys[i] > DIR_TOL) + (nxs[i] > DIR_TOL)
            if kk > key:
                best, key = i, kk
    return best


@kernel
def _ray_polygon(qx, qy, n, ox, oy, dx, dy, dlen):  # pragma: no cover - compiled
    """framework.collision.ray._ray_polygon with clip_polygon's float path on the scaled outline
    ``qx, qy`` (``n`` vertices, counter-clockwise): ``(status, tau, nx, ny)``, status 0 a miss,
    1 a hit, 2 the origin strictly inside, -1 unresolved (clip_polygon would decide exactly)."""
    t_in, t_out = -math.inf, math.inf
    in_lo = in_hi = -math.inf
    out_lo = out_hi = math.inf
    ft = np.empty(n)
    fnx = np.empty(n)
    fny = np.empty(n)
    nf = 0
    for i in range(n):
        x0, y0 = qx[i], qy[i]
        j = (i + 1) % n
        x1, y1 = qx[j], qy[j]
        nx, ny = y1 - y0, x0 - x1
        ax, ay = nx * (x0 - ox), ny * (y0 - oy)
        bx, by = nx * dx, ny * dy
        num, den = ax + ay, bx + by
        mag = BAND * (abs(ax) + abs(ay))
        if abs(den) <= BAND * (abs(bx) + abs(by)) and (bx != 0.0 or by != 0.0):
            return -1, 0.0, 0.0, 0.0
        if den == 0.0:
            if abs(num) <= mag:
                return -1, 0.0, 0.0, 0.0
            if num < 0.0:
                return 0, 0.0, 0.0, 0.0
            continue
        t = num / den
        err = (mag + abs(t) * BAND * (abs(bx) + abs(by))) / abs(den)
        if den < 0.0:
            ft[nf], fnx[nf], fny[nf] = t, nx, ny
            nf += 1
            t_in = max(t_in, t)
            in_lo, in_hi = max(in_lo, t - err), max(in_hi, t + err)
        else:
            t_out = min(t_out, t)
            out_lo, out_hi = min(out_lo, t - err), min(out_hi, t + err)
    if in_lo < out_hi and out_lo <= in_hi:
        return -1, 0.0, 0.0, 0.0
    if not t_in < t_out:
        return 0, 0.0, 0.0, 0.0
    if (out_lo <= 0.0 < out_hi) or (in_lo <= 0.0 <= in_hi):
        return -1, 0.0, 0.0, 0.0
    # _ray_polygon
    if not t_out > 0.0:
        return 0, 0.0, 0.0, 0.0
    if t_in < 0.0:
        return 2, 0.0, 0.0, 0.0
    tol = TIE * max(1.0, t_in)
    cs = np.empty(nf)
    ux = np.empty(nf)
    uy = np.empty(nf)
    m = 0
    best = math.inf
    for i in range(nf):
        if ft[i] >= t_in - tol:
            ln = hypot(fnx[i], fny[i])
            cs[m] = (fnx[i] * dx + fny[i] * dy) / (ln * dlen)
            ux[m], uy[m] = fnx[i] / ln, fny[i] / ln
            best = min(best, cs[m])
            m += 1
    k = 0
    for i in range(m):
        if cs[i] <= best + TIE:
            ux[k], uy[k] = ux[i], uy[i]
            k += 1
    w = _pick(ux, uy, k)
    return 1, t_in, ux[w], uy[w]


@kernel
def _ray_circle(mx, my, r, vx, vy):  # pragma: no cover - compiled
    """framework.collision.ray._ray_circle with disc_interval's float path: as _ray_polygon."""
    a = vx * vx + vy * vy
    cross = mx * vy - my * vx
    rr = r * r
    disc = a * rr - cross * cross
    mm = mx * mx + my * my
    c = mm - rr
    b = mx * vx + my * vy
    if (abs(disc) <= BAND * (a * rr + abs(cross) * (abs(mx * vy) + abs(my * vx)))
            or abs(c) <= BAND * (mm + rr)):
        return -1, 0.0, 0.0, 0.0
    if not disc > 0.0:
        return 0, 0.0, 0.0, 0.0
    sq = math.sqrt(disc)
    if b < 0.0:
        q = sq - b
        t1, t2 = c / q, q / a
    else:
        q = -b - sq
        t1, t2 = q / a, c / q
    ahead = t2 > 0.0 if t1 < t2 else t1 >= 0.0  # (t2 = nextafter(t1, inf) there)
    if not ahead:
        return 0, 0.0, 0.0, 0.0
    if t1 < 0.0:
        return 2, 0.0, 0.0, 0.0
    hx, hy = mx + t1 * vx, my + t1 * vy
    ln = hypot(hx, hy)
    if ln > 0.0:
        return 1, t1, hx / ln, hy / ln
    return 1, t1, 0.0, 1.0


@kernel
def _exponent(v):  # pragma: no cover - compiled
    return math.frexp(abs(v))[1]


@kernel
def _ray_row(k, sa, sb, ext, local, cnt, px, py, rot, ox, oy, dx, dy, limit):  # pragma: no cover - compiled
    """framework.collision.ray.raycast of one row: ``(status, distance, hit x, hit y, nx, ny)``,
    status 0 a miss, 1 a hit, -1 unresolved (answer it with raycast itself)."""
    j = _exponent(max(abs(dx), abs(dy)))
    ux, uy = math.ldexp(dx, -j), math.ldexp(dy, -j)
    ulen = hypot(ux, uy)
    rx, ry, e = ox - px, oy - py, 0
    if not (math.isfinite(rx) and math.isfinite(ry)):
        rx = math.ldexp(ox, -1) - math.ldexp(px, -1)
        ry = math.ldexp(oy, -1) - math.ldexp(py, -1)
        e = 1
    kk = _exponent(ext)
    if rx != 0.0 or ry != 0.0:
        far = -100000
        if rx != 0.0:
            far = _exponent(rx) + e
        if ry != 0.0:
            far = max(far, _exponent(ry) + e)
        kk = max(kk, far - _FAR)
    mx, my = math.ldexp(rx, e - kk), math.ldexp(ry, e - kk)
    if k == _CIRCLE:
        status, tau, nx, ny = _ray_circle(mx, my, math.ldexp(sa, -kk), ux, uy)
    elif k == _CAPSULE or k == _SEGMENT:  # (a segment: an exact crossing, and a chain's one side)
        return -1, 0.0, 0.0, 0.0, 0.0, 0.0
    else:
        qx = np.empty(max(4, cnt))
        qy = np.empty(max(4, cnt))
        if k == _AABB:
            n = 4
            hw, hh = math.ldexp(sa, -kk), math.ldexp(sb, -kk)  # (sa, sb: the half sizes, exactly)
            qx[0], qy[0] = 0.0 - hw, 0.0 - hh
            qx[1], qy[1] = 0.0 + hw, 0.0 - hh
            qx[2], qy[2] = 0.0 + hw, 0.0 + hh
            qx[3], qy[3] = 0.0 - hw, 0.0 + hh
        else:
            n = cnt
            if rot == 0.0:
                for i in range(n):
                    qx[i] = math.ldexp(local[i, 0], -kk) + 0.0
                    qy[i] = math.ldexp(local[i, 1], -kk) + 0.0
            else:
                c, s = math.cos(rot), math.sin(rot)
                for i in range(n):
                    lx, ly = math.ldexp(local[i, 0], -kk), math.ldexp(local[i, 1], -kk)
                    qx[i] = c * lx - s * ly + 0.0
                    qy[i] = s * lx + c * ly + 0.0
        status, tau, nx, ny = _ray_polygon(qx, qy, n, mx, my, ux, uy, ulen)
    if status <= 0:
        return status, 0.0, 0.0, 0.0, 0.0, 0.0
    if status == 2:  # strictly inside
        return 1, 0.0, ox + 0.0, oy + 0.0, -ux / ulen + 0.0, -uy / ulen + 0.0
    if tau <= 0.0:
        return 1, 0.0, ox + 0.0, oy + 0.0, nx + 0.0, ny + 0.0
    distance = math.ldexp(tau * ulen, kk)
    if not (distance <= limit and math.isfinite(distance)):
        return 0, 0.0, 0.0, 0.0, 0.0, 0.0
    hx = px + math.ldexp(mx + tau * ux, kk)
    hy = py + math.ldexp(my + tau * uy, kk)
    if not (math.isfinite(hx) and math.isfinite(hy)):
        return 0, 0.0, 0.0, 0.0, 0.0, 0.0
    return 1, distance + 0.0, hx + 0.0, hy + 0.0, nx + 0.0, ny + 0.0


@kernel
def ray_rows(rows, at, ox, oy, dx, dy, max_distance, skind, sa, sb, ext, local, cnt, hx, hy,
             rot):  # pragma: no cover - compiled
    """One ray against each of ``rows`` (as ``Scene.raycast_all`` asks; their shapes at ``at`` in
    the shape columns): per row ``(status, distance, x, y, nx, ny)`` of
    :func:`~framework.collision.ray.raycast`, status 0 a miss, 1 a hit, -1 unresolved (answer it
    with ``raycast`` itself)."""
    out = np.zeros((rows.size, 6))
    for i in range(rows.size):
        r, q = rows[i], at[i]
        status, d, qx, qy, nx, ny = _ray_row(skind[q], sa[q], sb[q], ext[q], local[q], cnt[q], hx[r], hy[r], rot[r],
                                             ox, oy, dx, dy, max_distance)
        out[i, 0], out[i, 1], out[i, 2], out[i, 3], out[i, 4], out[i, 5] = status, d, qx, qy, nx, ny
    return out


@kernel
def rays_first(ox, oy, dx, dy, max_distance, reach, kind, skind, sa, sb, ext, local, cnt, layer, entity, minx,
               miny, maxx, maxy, hx, hy, rot, mask):  # pragma: no cover - compiled
    """For each ray, the first row it enters (as ``Scene.raycast``: nearest, ties to the lower
    entity): ``(entity, distance, x, y, nx, ny, row, pending)``, entity and row -1 where none is, and
    ``pending``: the unresolved (ray, row) pairs, ``[P, 2]``, which may still be nearer."""
    n = ox.size
    ent = np.full(n, -1, dtype=np.int64)
    dist = np.full(n, math.inf)
    hxs = np.zeros(n)
    hys = np.zeros(n)
    nxs = np.zeros(n)
    nys = np.zeros(n)
    rows = np.full(n, -1, dtype=np.int64)
    pending = np.empty((16, 2), dtype=np.int64)
    npend = 0
    md = max_distance
    for i in range(n):
        x, y, vx, vy = ox[i], oy[i], dx[i], dy[i]
        ln = hypot(vx, vy)
        ex, ey = x + vx / ln * reach[i], y + vy / ln * reach[i]
        x0, y0 = min(x, ex) - _NEAR, min(y, ey) - _NEAR
        x1, y1 = max(x, ex) + _NEAR, max(y, ey) + _NEAR
        wx, wy = vx / ln, vy / ln
        best_d, best_e = math.inf, -1
        for r in range(kind.size):  # (in row order: of two equal hits, the first row's, as the stable sort)
            if not (kind[r] >= 0 and minx[r] < x1 and maxx[r] > x0 and miny[r] < y1 and maxy[r] > y0):
                continue
            if (layer[r] & mask) == 0:
                continue
            # Slab test against the row's bounds widened by far more than rounding: a ray that
            # misses them misses the hitbox, and one entering them beyond the best cannot win.
            slack = _SLACK * (1.0 + abs(x) + abs(y) + abs(minx[r]) + abs(maxx[r]) + abs(miny[r]) + abs(maxy[r]))
            lo, hi = 0.0, math.inf
            for a0, a1, o, w in ((minx[r], maxx[r], x, wx), (miny[r], maxy[r], y, wy)):
                a0, a1 = a0 - slack, a1 + slack
                if w == 0.0:
                    if o < a0 or o > a1:
                        lo, hi = 1.0, 0.0
                else:
                    t0, t1 = (a0 - o) / w, (a1 - o) / w
                    if t0 > t1:
                        t0, t1 = t1, t0
                    lo, hi = max(lo, t0), min(hi, t1)
            if lo > hi or lo > best_d + slack or lo > md + slack:
                continue
            status, d, qx, qy, nx, ny = _ray_row(skind[r], sa[r], sb[r], ext[r], local[r], cnt[r], hx[r], hy[r],
                                                 rot[r], x, y, vx, vy, md)
            if status < 0:
                if npend >= pending.shape[0]:
                    more = np.empty((2 * pending.shape[0], 2), dtype=np.int64)
                    more[:npend] = pending[:npend]
                    pending = more
                pending[npend, 0], pending[npend, 1] = i, r
                npend += 1
                continue
            if status == 0:
                continue
            e = entity[r]
            if best_e < 0 or d < best_d or (d == best_d and e < best_e):
                best_d, best_e = d, e
                ent[i], dist[i], hxs[i], hys[i], nxs[i], nys[i], rows[i] = e, d, qx, qy, nx, ny, r
    return ent, dist, hxs, hys, nxs, nys, rows, pending[:npend].copy()
