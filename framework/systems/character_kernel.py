"""The character stage's compiled move: one call moves a box among boxes, bit for bit as the
Python controller (:mod:`framework.systems.character`) does.

A character's move is a few dozen small steps (ride, depenetrate, slide with step-up, land,
velocity) each asking a shape cast over one or two candidate rows; in Python the glue of those
steps, not the geometry, was the cost (about 85 us a character). Here the whole move after the
candidates are gathered is one compiled call, for the common case: an axis-aligned box character
whose every gathered candidate is an axis-aligned box. It repeats the Python code's arithmetic in
the same order (casts by slabs, :func:`~framework.casting._box_sweep`; hits taken in the order of
``(fraction, entity)``; ``math.hypot`` as CPython computes it), so the bits are the same.

:func:`move_character` is the stage's whole move in that call (its candidates looked up in the
call too, the body placed); :func:`move_box` the move from the candidates the stage gathered.

What it does not decide it hands back (a reason, :data:`REASONS`), and the Python move runs instead,
unchanged: a candidate that is not a box, a cast or overlap test reaching beyond the gathered
region, a cast starting inside a candidate or touching a one-way platform (``time_of_impact`` and
``collide`` decide those), a body overlapping something at the start (depenetration), too many
surfaces met, a floor that turns under the body (:func:`move_character`).

Compiling it costs about 7 to 10 seconds once per installation (measured on a busy two-core
machine; numba's cache keeps it); the stage imports this module only when a scene first has a box
character to move.
"""

from __future__ import annotations

import math

import numpy as np

from ..arrays import F64Array, I64Array, IntpArray
from ..collision.box_rows import rows_near
from ..collision.kinds import KIND_AABB
from ..collision.py_hypot import hypot
from ..compiled import inner, kernel
from ..geometry import _ulp
from ..store import DYNAMIC, STATIC

__all__ = ["REASONS", "move_box", "move_character", "outputs"]

#: ``move_box``'s status when the Python move must decide instead: its first reason (0: moved).
REGION, STARTS_INSIDE, ONE_WAY_TOUCH, OVERLAP, FULL, NOT_A_BOX, TURNING_FLOOR = range(1, 8)
#: The reasons' names, by status (the stage counts its hand-backs by them).
REASONS = ("", "beyond the gathered region", "a cast starting inside a box", "touching a one-way platform",
           "overlapping a box", "too many surfaces", "a candidate not a box", "standing on a turning floor")

# The body's settings (``me``): half extents, skin, cos(max floor angle), bounding radius, the
# gathered region's box.
HW, HH, SKIN, COSF, RAD, GB0, GB1, GB2, GB3 = range(9)
# The move's state (``st``, floats): position, the floor's and the wall's normals.
X, Y, FNX, FNY, WNX, WNY = range(6)
# The move's state (``si``, ints): floor and wall rows (-1: none), ceiling met, hits and pushed
# surfaces recorded, rows ignored, bail.
FLOOR, WALL, CEIL, NHITS, NPUSH, NIGN, BAILED = range(7)

# (The helpers are ``inner``: compiled into the move, never called from Python, so no wrapper to
# call them by is built: a third less compiling.)

_HITS = 64  # surfaces a move records at most (more: bail)
_IGNORED = 8  # rows ignored at once at most


@inner
def _first_min(a, b):  # pragma: no cover - compiled
    """Python's ``min(a, b)``: ``a`` unless ``b`` is smaller."""
    return b if b < a else a


@inner
def _first_max(a, b):  # pragma: no cover - compiled
    """Python's ``max(a, b)``: ``a`` unless ``b`` is larger."""
    return b if b > a else a


# --- looking up and casting --------------------------------------------------------------------


@inner
def _bail(si, reason):  # pragma: no cover - compiled
    """Hand the move back to the Python code (the first reason is kept)."""
    if si[BAILED] == 0:
        si[BAILED] = reason


@inner
def _ignored(si, ign, r):  # pragma: no cover - compiled
    for k in range(si[NIGN]):
        if ign[k] == r:
            return True
    return False


@inner
def _ignore(si, ign, r):  # pragma: no cover - compiled
    """``mv.ignore.add(r)``."""
    if _ignored(si, ign, r):
        return
    if si[NIGN] == ign.size:
        _bail(si, FULL)
        return
    ign[si[NIGN]] = r
    si[NIGN] += 1


@inner
def _unignore(si, ign, r):  # pragma: no cover - compiled
    """``mv.ignore.discard(r)``."""
    n = si[NIGN]
    for k in range(n):
        if ign[k] == r:
            ign[k] = ign[n - 1]
            si[NIGN] = n - 1
            return


@inner
def _box_sweep(ax, ay, ahw, ahh, bx, by, bhw, bhh, mx, my):  # pragma: no cover - compiled
    """:func:`framework.casting._box_sweep`: ``(code, fraction, nx, ny)``, code 0 a miss, 1 a
    hit, 2 the answer at the very start (``time_of_impact`` decides: bail)."""
    t_in, t_out, axis = -math.inf, math.inf, -1
    for k in range(2):
        if k == 0:
            d, m, e = bx - ax, mx, ahw + bhw
        else:
            d, m, e = by - ay, my, ahh + bhh
        if m == 0.0:
            if not abs(d) < e:
                return 0, 0.0, 0.0, 0.0
            continue
        lo, hi = (d - e) / m, (d + e) / m
        if lo > hi:
            lo, hi = hi, lo
        if lo > t_in or (lo == t_in and k == 1):
            t_in, axis = lo, k
        t_out = _first_min(t_out, hi)
    if not (t_in < t_out and t_out > 0.0 and t_in < 1.0):
        return 0, 0.0, 0.0, 0.0
    if t_in < 0.0 or axis < 0:
        return 2, 0.0, 0.0, 0.0
    if axis == 0:
        return 1, t_in, (-1.0 if bx > ax else 1.0), 0.0
    return 1, t_in, 0.0, (-1.0 if by > ay else 1.0)


@inner
def _cast(world, me, st, si, ign, scratch, rows_found, mx, my):  # pragma: no cover - compiled
    """The stage's ``_cast`` (``_near``, then ``cast_rows`` by slabs, one-way platforms refusing
    hits from below): ``(row, fraction, nx, ny)``, row -1 for none. ``scratch`` (n x 3) and
    ``rows_found`` (n): room for a hit per gathered row."""
    cand, minx, miny, maxx, maxy = world[0], world[1], world[2], world[3], world[4]
    hx, hy, hw, hh, one_way, entity = world[5], world[6], world[7], world[8], world[9], world[11]
    x, y, ahw, ahh = st[X], st[Y], me[HW], me[HH]
    x0, y0, x1, y1 = x - ahw, y - ahh, x + ahw, y + ahh
    # _near's box (it must lie in the gathered region) ...
    pad = 1e-6 * (abs(x0) + abs(y0) + abs(mx) + abs(my) + x1 - x0 + y1 - y0)
    n0, n1 = _first_min(x0, x0 + mx) - pad, _first_min(y0, y0 + my) - pad
    n2, n3 = _first_max(x1, x1 + mx) + pad, _first_max(y1, y1 + my) + pad
    if not (me[GB0] <= n0 and me[GB1] <= n1 and n2 <= me[GB2] and n3 <= me[GB3]):
        _bail(si, REGION)
        return -1, 0.0, 0.0, 0.0
    # ... and cast_rows' own (narrower) box
    pad = 1e-9 * (abs(x) + abs(y) + me[RAD] + abs(mx) + abs(my))
    b0, b1 = _first_min(x0, x0 + mx) - pad, _first_min(y0, y0 + my) - pad
    b2, b3 = _first_max(x1, x1 + mx) + pad, _first_max(y1, y1 + my) + pad
    m = 0
    for i in range(cand.size):
        r = cand[i]
        if not (minx[r] <= n2 and maxx[r] >= n0 and miny[r] <= n3 and maxy[r] >= n1):
            continue
        if _ignored(si, ign, r):
            continue
        if not (minx[r] <= b2 and maxx[r] >= b0 and miny[r] <= b3 and maxy[r] >= b1):
            continue
        code, f, nx, ny = _box_sweep(x, y, ahw, ahh, hx[r], hy[r], hw[r], hh[r], mx, my)
        if code == 0:
            continue
        if code == 2:
            _bail(si, STARTS_INSIDE)
            return -1, 0.0, 0.0, 0.0
        scratch[m, 0], scratch[m, 1], scratch[m, 2], rows_found[m] = f, nx, ny, r
        m += 1
    # The hits in the order of (fraction, entity) (a row's entity is its own), the first accepted.
    for _ in range(m):
        k = -1
        for j in range(m):
            if rows_found[j] < 0:
                continue
            if k < 0 or scratch[j, 0] < scratch[k, 0] or (
                    scratch[j, 0] == scratch[k, 0] and entity[rows_found[j]] < entity[rows_found[k]]):
                k = j
        r, f, nx, ny = rows_found[k], scratch[k, 0], scratch[k, 1], scratch[k, 2]
        rows_found[k] = -1
        if not one_way[r]:
            return r, f, nx, ny
        if ny < me[COSF] or (my > 0.0 and f == 0.0):
            continue  # a one-way platform blocks only a body coming down onto its top
        if f == 0.0:  # touching it: collide decides
            _bail(si, ONE_WAY_TOUCH)
            return -1, 0.0, 0.0, 0.0
        return r, f, nx, ny
    return -1, 0.0, 0.0, 0.0


@inner
def _advance(me, st, mx, my, f, nx, ny):  # pragma: no cover - compiled
    """The stage's ``_advance``: by ``f`` of the move, then back until ``skin`` clear."""
    length = hypot(mx, my)
    if length == 0.0:
        return
    go = f * length
    into = -(mx * nx + my * ny) / length
    back = _first_min(go, me[SKIN] / into) if into > 0.0 else 0.0
    t = (go - back) / length
    st[X] += mx * t
    st[Y] += my * t


@inner
def _record(si, rows, normals, count, r, nx, ny):  # pragma: no cover - compiled
    """Append ``(r, nx, ny)`` to a list of surfaces (``count`` indexes ``si``)."""
    k = si[count]
    if k == rows.size:
        _bail(si, FULL)
        return
    rows[k] = r
    normals[k, 0] = nx
    normals[k, 1] = ny
    si[count] = k + 1


# --- moving --------------------------------------------------------------------------------------


@inner
def _contact_height(world, me, st, r, nx, ny):  # pragma: no cover - compiled
    """The stage's ``_contact_height``: ``touch_point`` of the body and box ``r`` (met at normal
    ``n``), its y; both supports of a box."""
    hx, hy, hw, hh, bound = world[5], world[6], world[7], world[8], world[12]
    tnx, tny = -nx, -ny
    tx, ty = -tny, tnx
    # (0: the body's support toward the row; 1: the row's toward the body)
    tmin = np.empty(2)
    tmax = np.empty(2)
    along = np.empty(2)
    for side in range(2):
        if side == 0:
            cx, cy, ehw, ehh, rad, dx, dy = st[X], st[Y], me[HW], me[HH], me[RAD], tnx, tny
        else:
            cx, cy, ehw, ehh, rad, dx, dy = hx[r], hy[r], hw[r], hh[r], bound[r], -tnx, -tny
        px = (cx - ehw, cx + ehw, cx + ehw, cx - ehw)
        py = (cy - ehh, cy - ehh, cy + ehh, cy + ehh)
        proj = np.empty(4)
        top = 0.0
        big = 0.0
        for k in range(4):
            proj[k] = px[k] * dx + py[k] * dy
            if k == 0 or proj[k] > top:
                top = proj[k]
            if k == 0 or abs(proj[k]) > big:
                big = abs(proj[k])
        tol = 1e-9 * (big + rad)
        lo, hi, s, count = 0.0, 0.0, 0.0, 0
        for k in range(4):
            if proj[k] >= top - tol:
                t = px[k] * tx + py[k] * ty
                if count == 0 or t < lo:
                    lo = t
                if count == 0 or t > hi:
                    hi = t
                s = s + (px[k] * tnx + py[k] * tny)
                count += 1
        tmin[side], tmax[side], along[side] = lo, hi, s / count
    lo, hi = _first_max(tmin[0], tmin[1]), _first_min(tmax[0], tmax[1])
    if lo > hi:
        lo = hi = (lo + hi) * 0.5
    mid = (lo + hi) * 0.5
    d = (along[0] + along[1]) * 0.5
    return d * tny + mid * ty + 0.0


@inner
def _step_up(world, me, st, si, ign, scratch, rows_found, hits_r, hits_n, rx,
             step):  # pragma: no cover - compiled
    """The stage's ``_step_up`` for a box (no round bottom to carry further)."""
    x0, y0, cos_f, skin = st[X], st[Y], me[COSF], me[SKIN]
    bottom = st[Y] - me[HH]
    ur, uf, _unx, _uny = _cast(world, me, st, si, ign, scratch, rows_found, 0.0, step)
    rise = step
    if ur >= 0:
        v = step * uf - skin
        rise = v if v > 0.0 else 0.0
    if rise <= skin:
        return False
    top = y0 + rise
    go = rx
    nudged = False
    for _ in range(3):
        st[X], st[Y] = x0, top
        ar, af, anx, any_ = _cast(world, me, st, si, ign, scratch, rows_found, go, 0.0)
        if ar >= 0:
            _advance(me, st, go, 0.0, af, anx, any_)
        else:
            st[X] += go
        if abs(st[X] - x0) <= skin:
            if not nudged and ar < 0:
                go, nudged = go + math.copysign(4.0 * skin, rx), True
                continue
            break
        dr, fd, nx, ny = _cast(world, me, st, si, ign, scratch, rows_found, 0.0, -rise)
        if dr < 0:
            break
        if ny >= cos_f:
            _advance(me, st, 0.0, -rise, fd, nx, ny)
            if _contact_height(world, me, st, dr, nx, ny) > bottom + step + 4.0 * skin:
                break
            si[FLOOR], st[FNX], st[FNY] = dr, nx, ny
            if ar >= 0:
                si[WALL], st[WNX], st[WNY] = ar, anx, any_
                _record(si, hits_r, hits_n, NHITS, ar, anx, any_)
            return True
        break  # (a box's bottom is flat: never carried further to stand on an edge)
    st[X], st[Y] = x0, y0
    return False


@inner
def _slide(world, me, st, si, ign, scratch, rows_found, hits_r, hits_n, push_r, push_n, mx, my, on_floor, step,
           max_slides):  # pragma: no cover - compiled
    """The stage's ``_slide``: move, sliding along what it hits."""
    body = world[10]
    cos_f = me[COSF]
    scale = me[SKIN] * 1e-6
    planes = np.empty((max_slides, 2))
    n_planes = 0
    for _ in range(max_slides):
        if si[BAILED]:
            return
        if abs(mx) <= scale and abs(my) <= scale:
            return
        r, f, nx, ny = _cast(world, me, st, si, ign, scratch, rows_found, mx, my)
        if r < 0:
            st[X] += mx
            st[Y] += my
            return
        _advance(me, st, mx, my, f, nx, ny)
        rx, ry = mx * (1.0 - f), my * (1.0 - f)
        if ny >= cos_f:  # a floor
            si[FLOOR], st[FNX], st[FNY] = r, nx, ny
            _record(si, hits_r, hits_n, NHITS, r, nx, ny)
            on_floor = True
            mx, my = rx, -rx * nx / ny
        elif ny <= -cos_f:  # a ceiling
            si[CEIL] = 1
            _record(si, hits_r, hits_n, NHITS, r, nx, ny)
            d = rx * nx + ry * ny
            if d < 0.0:
                mx, my = rx - d * nx, ry - d * ny
            else:
                mx, my = rx, ry
        else:  # a wall
            if body[r] == DYNAMIC:
                _record(si, push_r, push_n, NPUSH, r, nx, ny)
            if on_floor and step > 0.0 and rx != 0.0 and abs(ny) < cos_f and _step_up(
                    world, me, st, si, ign, scratch, rows_found, hits_r, hits_n, rx, step):
                return
            si[WALL], st[WNX], st[WNY] = r, nx, ny
            _record(si, hits_r, hits_n, NHITS, r, nx, ny)
            d = rx * nx + ry * ny
            if d < 0.0:
                mx, my = rx - d * nx, ry - d * ny
            else:
                mx, my = rx, ry
            if on_floor and my > 0.0:
                mx = my = 0.0
        for k in range(n_planes):
            if mx * planes[k, 0] + my * planes[k, 1] < -scale:
                mx = my = 0.0
        planes[n_planes, 0] = nx
        planes[n_planes, 1] = ny
        n_planes += 1


@inner
def _ride(world, me, st, si, ign, scratch, rows_found, hits_r, hits_n, push_r, push_n, floor_row, cx, cy,
          ride_slides):  # pragma: no cover - compiled
    """The stage's ``_ride``: carried by the floor (not in the way); nothing met is kept.
    (``ride_slides`` and the False made of it come typed as the walk's: one compiled ``_slide``
    serves both, where literal ``False, 4`` compiled a second one.)"""
    _ignore(si, ign, floor_row)
    _slide(world, me, st, si, ign, scratch, rows_found, hits_r, hits_n, push_r, push_n, cx, cy, ride_slides < 0, 0.0,
           ride_slides)
    _unignore(si, ign, floor_row)
    si[FLOOR] = si[WALL] = -1
    si[CEIL] = 0
    si[NHITS] = 0


@inner
def _land(world, me, st, si, ign, scratch, rows_found, reach):  # pragma: no cover - compiled
    """The stage's ``_land``: cast down by ``reach``, onto a floor (the row, -1 for none, and
    its normal; the body moved onto it)."""
    cos_f = me[COSF]
    hr, hf, hnx, hny = _cast(world, me, st, si, ign, scratch, rows_found, 0.0, -reach)
    fr, ff, fnx, fny = hr, hf, hnx, hny
    ignored = np.empty(3, dtype=np.intp)
    n_ignored = 0
    found = -1
    for _ in range(3):
        if hr < 0 or fr < 0:
            break
        if hny >= cos_f:
            if (hf - ff) * reach <= 4.0 * me[SKIN]:
                found = 1
            break
        ignored[n_ignored] = hr
        n_ignored += 1
        _ignore(si, ign, hr)
        hr, hf, hnx, hny = _cast(world, me, st, si, ign, scratch, rows_found, 0.0, -reach)
    for k in range(n_ignored):
        _unignore(si, ign, ignored[k])
    if found < 0 or fr < 0:
        return -1, 0.0, 0.0
    _advance(me, st, 0.0, -reach, ff, fnx, fny)
    return hr, hnx, hny


@inner
def _overlaps(world, me, st, si, ign):  # pragma: no cover - compiled
    """Bail if the body may overlap a candidate (``overlapping_rows``' tests before ``collide``):
    the Python move depenetrates it."""
    minx, miny, maxx, maxy, hx, hy, hw, hh = world[1], world[2], world[3], world[4], world[5], world[6], world[7], \
        world[8]
    cand = world[0]
    x, y = st[X], st[Y]
    x0, y0, x1, y1 = x - me[HW], y - me[HH], x + me[HW], y + me[HH]
    if not (me[GB0] <= x0 and me[GB1] <= y0 and x1 <= me[GB2] and y1 <= me[GB3]):
        _bail(si, REGION)  # (the Python move looks up afresh)
        return
    tol = 0.5 * me[SKIN]
    for i in range(cand.size):
        r = cand[i]
        if not (minx[r] <= x1 and maxx[r] >= x0 and miny[r] <= y1 and maxy[r] >= y0):
            continue  # (_near's test, then overlapping_rows')
        if _ignored(si, ign, r):
            continue
        if minx[r] >= x1 + tol or maxx[r] <= x0 - tol or miny[r] >= y1 + tol or maxy[r] <= y0 - tol:
            continue
        if not (abs(hx[r] - x) < me[HW] + hw[r] and abs(hy[r] - y) < me[HH] + hh[r]):
            continue
        _bail(si, OVERLAP)
        return


@inner
def _unblocked(world, me, st, si, hits_r, hits_n, vx, vy):  # pragma: no cover - compiled
    """The stage's ``_unblocked``: the velocity without its part into the surfaces met."""
    body = world[10]
    n = 0
    pn = np.empty((si[NHITS], 2))
    for k in range(si[NHITS]):
        if body[hits_r[k]] != DYNAMIC:
            pn[n, 0], pn[n, 1] = hits_n[k, 0], hits_n[k, 1]
            n += 1
    if n == 0:
        return vx, vy
    if si[FLOOR] >= 0:
        tx, ty = 1.0, -st[FNX] / st[FNY]
        for k in range(n):
            nx, ny = pn[k, 0], pn[k, 1]
            if ny < me[COSF] and vx * (tx * nx + ty * ny) < 0.0:
                vx = 0.0
                break
        return vx, vy
    tol = 1e-12 * hypot(vx, vy)
    for _ in range(3):
        into = False
        for k in range(n):
            nx, ny = pn[k, 0], pn[k, 1]
            d = vx * nx + vy * ny
            if d < -tol:
                vx, vy = vx - d * nx, vy - d * ny
                into = True
        if not into:
            return vx, vy
    for k in range(n):
        if vx * pn[k, 0] + vy * pn[k, 1] < -tol:
            return 0.0, 0.0
    return vx, vy


def outputs() -> tuple[F64Array, I64Array, IntpArray, F64Array]:
    """The arrays :func:`move_box` writes its outcome to (a stage keeps one set: returning
    arrays from a compiled call costs more than the move's arithmetic)."""
    return np.zeros(10), np.zeros(7, dtype=np.int64), np.zeros(_HITS, dtype=np.intp), np.zeros((_HITS, 2))


@kernel
def move_box(world, me, go, floor_row, was_on_floor, ride_after, max_slides, ride_slides, st, si, push_r,
             push_n):  # pragma: no cover - compiled
    """The stage's ``_move`` from its ride on, the candidates gathered by the stage (:func:`_move`;
    :func:`move_character` gathers them itself): 0, or the reason it hands the move back."""
    return _move(world, me, go, floor_row, was_on_floor, ride_after, max_slides, ride_slides, st, si, push_r, push_n)


@inner
def _move(world, me, go, floor_row, was_on_floor, ride_after, max_slides, ride_slides, st, si, push_r,
          push_n):  # pragma: no cover - compiled
    """The stage's ``_move`` from its ride on (the candidates gathered): 0, or the reason it hands
    the move back (``REGION`` ...).
    ``world``: the gathered rows, then the geometry's bounds and origins and the store's columns
    by row (``minx, miny, maxx, maxy, hx, hy, hw, hh, one_way, body, entity, bound, kind``);
    ``me``: the body's settings (``HW`` ...); ``go``: ``x, y, carried x, carried y, vx, vy, dt,
    gx, gy, gravity scale, step height, snap, tan(max floor angle), floor normal x, y``;
    ``ride_slides``: the casts of a ride (the stage's ``_slide`` default, 4). The
    outcome (arrays from :func:`outputs`): ``st``: ``x, y, floor normal, wall normal, vx, vy, the
    own move``; ``si``: floor and wall rows, ceiling, hits, pushed dynamic rows (``push_r``,
    normals ``push_n``), ..."""
    cand, kind = world[0], world[13]
    st[:] = 0.0
    si[:] = 0
    si[FLOOR] = si[WALL] = -1
    ign = np.empty(_IGNORED, dtype=np.intp)
    hits_r = np.empty(_HITS, dtype=np.intp)
    hits_n = np.empty((_HITS, 2))
    scratch = np.empty((cand.size, 3))
    rows_found = np.empty(cand.size, dtype=np.intp)
    for i in range(cand.size):
        if kind[cand[i]] != KIND_AABB:
            return NOT_A_BOX
    st[X], st[Y] = go[0], go[1]
    cx, cy, vx, vy, dt = go[2], go[3], go[4], go[5], go[6]
    carried = not (cx == 0.0 and cy == 0.0)
    if carried and floor_row >= 0 and not ride_after:
        _ride(world, me, st, si, ign, scratch, rows_found, hits_r, hits_n, push_r, push_n, floor_row, cx, cy,
              ride_slides)
    if si[BAILED] == 0:
        _overlaps(world, me, st, si, ign)
    if si[BAILED]:
        return si[BAILED]
    cos_f = me[COSF]
    jumping = vy > 0.0
    if was_on_floor and jumping and floor_row >= 0 and dt > 0.0:
        vx += cx / dt
        vy += cy / dt
    if was_on_floor and not jumping:
        vy = 0.0
        nx, ny = go[13], go[14]
        if ny < cos_f:
            nx, ny = 0.0, 1.0
        mx, my = vx * dt, vx * dt * (nx / ny) * -1.0
    else:
        vx += go[7] * go[9] * dt
        vy += go[8] * go[9] * dt
        mx, my = vx * dt, vy * dt
    on_floor_now = was_on_floor and not jumping
    px = st[X]
    st[8], st[9] = mx, my
    _slide(world, me, st, si, ign, scratch, rows_found, hits_r, hits_n, push_r, push_n, mx, my, on_floor_now, go[10],
           max_slides)
    if on_floor_now or (si[FLOOR] >= 0 and not jumping):
        reach = go[11] + abs(st[X] - px) * go[12] + 2.0 * me[SKIN]
        si[FLOOR], st[FNX], st[FNY] = _land(world, me, st, si, ign, scratch, rows_found, reach)
    elif si[FLOOR] >= 0:
        si[FLOOR], st[FNX], st[FNY] = _land(world, me, st, si, ign, scratch, rows_found, 4.0 * me[SKIN])
    if ride_after and carried and floor_row >= 0:
        kept_i = si.copy()
        kept_f = st.copy()
        _ride(world, me, st, si, ign, scratch, rows_found, hits_r, hits_n, push_r, push_n, floor_row, cx, cy,
              ride_slides)
        si[FLOOR], si[WALL], si[CEIL], si[NHITS] = kept_i[FLOOR], kept_i[WALL], kept_i[CEIL], kept_i[NHITS]
        st[FNX], st[FNY], st[WNX], st[WNY] = kept_f[FNX], kept_f[FNY], kept_f[WNX], kept_f[WNY]
    if si[FLOOR] >= 0:
        vy = 0.0
    if si[CEIL] and vy > 0.0:
        vy = 0.0
    vx, vy = _unblocked(world, me, st, si, hits_r, hits_n, vx, vy)
    st[6], st[7] = vx, vy
    return si[BAILED]


# The settings :func:`move_character` reads (``cfg``): the controller's skin (NaN: the default one),
# cos(max floor angle), gravity scale, step height, snap length, tan(max floor angle), the floor
# normal it stood on; the step's dt and gravity.
C_SKIN, C_COSF, C_GSCALE, C_STEP, C_SNAP, C_TAN, C_FNX, C_FNY, C_DT, C_GX, C_GY = range(11)


@inner
def _place_box(row, px, py, x, y, hw, hh, minx, miny, maxx, maxy):  # pragma: no cover - compiled
    """``Bodies.place_row`` of a box without offset: its position, and its bounds as
    :func:`framework.geometry._place` computes them (the same arithmetic, so the same bits)."""
    x[row], y[row] = px, py
    lx, ux, ly, uy = px - hw[row], px + hw[row], py - hh[row], py + hh[row]
    minx[row], maxx[row] = lx - _ulp(lx), ux + _ulp(ux)
    miny[row], maxy[row] = ly - _ulp(ly), uy + _ulp(uy)


@kernel
def move_character(row, undo, moved, soft, cfg, mask, floor_row, was_on_floor, max_slides, ride_slides, start_x,
                   start_y, x, y, vx, vy, w, has_vel, body, asleep, kind, minx, miny, maxx, maxy, hw, hh, one_way,
                   entity, bound, layer, sensor, st, si, push_r, push_n):  # pragma: no cover - compiled
    """The stage's whole ``_move`` of a box character without offset in a scene of few enough rows
    for a pass (``DIRECT_QUERY``), neither dropping through a platform nor asked to: put back
    where the movement stage found it (``undo``), its skin, what its floor carries, its candidates
    (:func:`~framework.collision.box_rows.rows_near` of the reach ``_gather`` computes), the move
    (:func:`_move`) and, if that decided it, the body placed where it ends. 0, or the reason it
    hands the move back to the Python code (then only the ``undo`` was done). The stage's Python
    arithmetic, in its order: the same bits. The geometry must be current (``hx`` is ``x``), and
    ``kind`` the live rows only (``store.kind``, as long as the geometry's bounds): the candidates
    come from a pass over it, and a column's rows past the live ones (kept from despawned bodies)
    would read bounds past the geometry's end (memory that differs from run to run)."""
    if undo:
        _place_box(row, start_x[row], start_y[row], x, y, hw, hh, minx, miny, maxx, maxy)
    x0, y0, ahw, ahh = x[row], y[row], hw[row], hh[row]
    ew, eh = (0.0 + ahw) - (0.0 - ahw), (0.0 + ahh) - (0.0 - ahh)  # (_extent: shape_bounds at the origin)
    size = eh if eh < ew else ew
    skin = cfg[C_SKIN]
    if skin != skin:  # (default_skin; Python's max)
        a, b = size * 2.0**-40, (abs(x0) + abs(y0)) * 2.0**-44
        skin = b if b > a else a
    dt = cfg[C_DT]
    cx = cy = 0.0
    ride_after = False
    if was_on_floor and floor_row >= 0:
        f = floor_row
        going = has_vel[f] and body[f] != STATIC and not asleep[f]
        pivot = False
        if moved and f < start_x.size:
            cx, cy, pivot = x[f] - start_x[f], y[f] - start_y[f], True
        elif going and soft:
            cx, cy, pivot, ride_after = vx[f] * dt, vy[f] * dt, True, True
        if going and pivot and w[f] * dt != 0.0:
            return TURNING_FLOOR
    # _gather: the reach of every cast this step
    vx0, vy0, gx, gy, gscale = vx[row], vy[row], cfg[C_GX], cfg[C_GY], cfg[C_GSCALE]
    own = (abs(vx0) + abs(vy0) + (abs(gx) + abs(gy)) * abs(gscale) * dt) * dt
    carry = abs(cx) + abs(cy)
    reach = (2.0 * carry + own * (1.0 + cfg[C_TAN]) + 2.0 * cfg[C_STEP] + cfg[C_SNAP] + 0.5 * size + 8.0 * skin)
    b0, b1, b2, b3 = x0 - ahw - reach, y0 - ahh - reach, x0 + ahw + reach, y0 + ahh + reach
    own_row = np.full(1, row, dtype=np.int64)
    cand = rows_near(kind, minx, miny, maxx, maxy, b0, b1, b2, b3, layer, sensor, mask, own_row, entity,
                     own_row[:0])
    me = np.empty(9)
    me[HW], me[HH], me[SKIN], me[COSF], me[RAD] = ahw, ahh, skin, cfg[C_COSF], bound[row]
    me[GB0], me[GB1], me[GB2], me[GB3] = b0, b1, b2, b3
    go = np.empty(15)
    go[0], go[1], go[2], go[3], go[4], go[5], go[6] = x0, y0, cx, cy, vx0, vy0, dt
    go[7], go[8], go[9], go[10], go[11], go[12] = gx, gy, gscale, cfg[C_STEP], cfg[C_SNAP], cfg[C_TAN]
    go[13], go[14] = cfg[C_FNX], cfg[C_FNY]
    world = (cand, minx, miny, maxx, maxy, x, y, hw, hh, one_way, body, entity, bound, kind)
    status = _move(world, me, go, floor_row, was_on_floor, ride_after, max_slides, ride_slides, st, si, push_r, push_n)
    if status == 0:
        _place_box(row, st[X], st[Y], x, y, hw, hh, minx, miny, maxx, maxy)
    return status
