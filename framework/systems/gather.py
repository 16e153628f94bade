"""The response's contacts for its solve, gathered in one compiled pass (:func:`gather`).

What it gathers, and why:

- **This step's contacts**, each with last step's push and impulse where the response acted on
  that pair last step (the warm start).
- **Two boxes along their entry axis.** The least overlap (the contract's push-out) forgets how
  the boxes met. A box falling into a gap a hair narrower than itself overlaps its neighbours' top
  corners by the step's fall vertically and by the hair sideways: pushed out sideways, it wedged
  the row apart against the walls and sank into the gap, and a crowd came to rest with rows
  overlapping by 0.02 (issue 33). So where, at the step's start, the two boxes overlapped along
  one axis and were apart or touching along the other (within a millionth of their size), the
  solve's contact is along that other axis; apart along both (a corner approach), along the axis
  on which they met last (vertical on a tie); overlapping along both, the least overlap as
  before. The events keep the contract's normal; only the solve's changes.
- **Last step's pairs that no longer overlap but are still close**: both bodies still there, with
  hitboxes whose layers meet. Bodies resting on each other fall by the same amount and merely
  touch: those pairs stay in the solve, with the gap the step's motion opened along the kept
  normal (a pair that fell together stays where it was; one flying apart starts that much farther
  from touching), less the gap they ended last step with; kept within a quarter of the smaller
  body's size, and while their bounds meet when grown by that margin along the normal only (a box
  whose support slid away sideways is no longer held by it, however small the gap).
- **Two circles of which friction rolls one**: their normal and gap where they stand now.
  Elsewhere a kept pair keeps last step's normal; between two circles that is a plane tangent to
  the lower one: a circle rolling over the top of another rode that plane at the height of the
  top, and in a pile of 80 rolling circles (issue 33 item 5a) balls rolled on such planes at up to
  0.5 units/s, 0.12 clear of the circle under them. (Not yet for circles that do not turn: the
  frictionless half-boxes crowd of test_solver, seed 0, then rests at 34 s instead of within 30.)

It is the numpy it replaced, row by row, in the same order of operations (``np.minimum`` and
``np.maximum`` as :func:`_np_min` and :func:`_np_max`, which keep their answers for -0.0 and NaN),
so the same bits: about fifty numpy calls a step were a sixth of a stack's step.
"""

from __future__ import annotations

import math

import numpy as np

from ..collision.box_rows import lower_bound
from ..compiled import kernel, leaf

__all__ = ["centres_inside", "gather", "solid_contacts", "solid_pair", "solid_pairs_mask", "taking_part"]


@leaf
def _np_min(a, b):  # pragma: no cover - compiled
    """``np.minimum(a, b)`` of two floats: ``a`` if it is less or NaN, else ``b`` (so -0.0 and
    0.0 give ``b``, as numpy does)."""
    return a if (a < b or a != a) else b


@leaf
def _np_max(a, b):  # pragma: no cover - compiled
    """``np.maximum(a, b)`` of two floats (see :func:`_np_min`)."""
    return a if (a > b or a != a) else b


@leaf
def _find(table, key):  # pragma: no cover - compiled
    """Where ``key`` is in the sorted ``table``, or -1 (as ``events.sorted_find``)."""
    i = lower_bound(table, key)
    return i if i < table.size and table[i] == key else -1


@leaf
def _places(keys, table, out):  # pragma: no cover - compiled
    """``out[i]``: where ``keys[i]`` is in the sorted ``table`` (-1: not there), as :func:`_find`
    of each; keys in order (a step's contacts, last step's pairs) by one walk along the table."""
    ascending = True
    for i in range(1, keys.size):
        if keys[i] < keys[i - 1]:
            ascending = False
            break
    j = 0
    for i in range(keys.size):
        if not ascending:
            out[i] = _find(table, keys[i])
            continue
        while j < table.size and table[j] < keys[i]:
            j += 1
        out[i] = j if j < table.size and table[j] == keys[i] else -1


@leaf
def _row(lut, entity):  # pragma: no cover - compiled
    """The row of ``entity`` (-1: none), as ``BodyStore.rows_of``."""
    return lut[entity] if entity < lut.size else -1


@kernel
def gather(ca, cb, cnx, cny, cdepth, cpx, cpy, cra, crb, sa, sb, snx, sny, spush, simp, ssep, stpush, stimp, lut,
           kind, layer, mask, layers_open, bound, radius, inv_inertia, friction, hw, hh, x, y, sx, sy, hx, hy, minx,
           miny, maxx, maxy, rolling, keep_gap, box_kind, circle_kind):  # pragma: no cover - compiled
    """The contacts of the solve: ``(ints, floats, alive0)``, the rows of ``ints`` ``ra, rb, ea, eb``,
    of ``floats`` ``nx, ny, depth, push0, impulse0, tpush0, timpulse0, px, py``; this step's
    contacts (``c*``: entities, normal, depth, point, rows) first, then last step's pairs kept
    (``s*``: the frame's support). ``lut``: entity -> row; ``sx, sy``: where the rows started the
    step (rows spawned since have none); ``rolling``: friction turns circles (the friction and
    rotation effects)."""
    m, k = ca.size, sa.size
    now_keys = np.empty(m, dtype=np.int64)
    for i in range(m):
        now_keys[i] = (ca[i] << 32) | cb[i]
    kept_keys = np.empty(k, dtype=np.int64)
    for j in range(k):
        kept_keys[j] = (sa[j] << 32) | sb[j]
    # this step's contacts: the warm start of the pairs found again
    push0, impulse0, tpush0, timpulse0 = np.zeros(m), np.zeros(m), np.zeros(m), np.zeros(m)
    tangent = False
    for j in range(k):
        if stpush[j] != 0.0 or stimp[j] != 0.0:
            tangent = True  # (friction acted last step)
            break
    at_kept = np.empty(m, dtype=np.int64)
    at_now = np.empty(k, dtype=np.int64)
    _places(now_keys, kept_keys, at_kept)
    _places(kept_keys, now_keys, at_now)
    if k:
        for i in range(m):
            at = at_kept[i]
            if at >= 0:
                push0[i], impulse0[i] = spush[at], simp[at]
                if tangent:
                    tpush0[i], timpulse0[i] = stpush[at], stimp[at]
    # last step's pairs not found again, whose bodies are still there and may meet
    old = np.empty(k, dtype=np.int64)
    ora, orb = np.empty(k, dtype=np.int64), np.empty(k, dtype=np.int64)
    n_old = 0
    for j in range(k):
        if at_now[j] >= 0:
            continue
        a, b = _row(lut, sa[j]), _row(lut, sb[j])
        if a < 0 or b < 0 or kind[a] < 0 or kind[b] < 0:
            continue
        if not layers_open and ((layer[a] & mask[b]) == 0 or (layer[b] & mask[a]) == 0):
            continue
        old[n_old], ora[n_old], orb[n_old] = j, a, b
        n_old += 1
    # their gaps: how far the step's motion took them apart along the kept normal (rows spawned
    # during the step have no start: then none), less the gap they ended last step with
    started = n_old > 0
    for q in range(n_old):
        if ora[q] >= sx.size or orb[q] >= sx.size:
            started = False
    knx, kny = snx.copy(), sny.copy()
    gaps = np.empty(n_old)
    for q in range(n_old):
        j, a, b = old[q], ora[q], orb[q]
        g = 0.0
        if started:
            mx = (x[b] - sx[b]) - (x[a] - sx[a])
            my = (y[b] - sy[b]) - (y[a] - sy[a])
            g = _np_min(-(mx * knx[j] + my * kny[j]), 0.0)
        gaps[q] = g - ssep[j]
    if rolling:  # two circles one of which friction rolls: their normal and gap where they stand now
        for q in range(n_old):
            a, b = ora[q], orb[q]
            if not (kind[a] == circle_kind and kind[b] == circle_kind):
                continue
            if not (inv_inertia[a] > 0.0 or inv_inertia[b] > 0.0):
                continue
            fa, fb = friction[a], friction[b]
            if fa >= 0.0 and fb >= 0.0:
                mu = math.sqrt(_np_max(fa, 0.0) * _np_max(fb, 0.0))
            elif fa >= 0.0:
                mu = fa
            elif fb >= 0.0:
                mu = fb
            else:
                mu = 0.0
            if not mu > 0.0:
                continue
            dx, dy = hx[b] - hx[a], hy[b] - hy[a]
            dist = math.hypot(dx, dy)
            if not dist > 0.0:
                continue
            knx[old[q]], kny[old[q]] = dx / dist, dy / dist
            gaps[q] = _np_min(radius[a] + radius[b] - dist, 0.0)
    # kept: still close, and facing each other across the normal
    keep = np.zeros(n_old, dtype=np.bool_)
    n_keep = 0
    for q in range(n_old):
        j, a, b = old[q], ora[q], orb[q]
        margin = keep_gap * _np_min(bound[a], bound[b])
        gx, gy = margin * abs(knx[j]), margin * abs(kny[j])
        if (gaps[q] >= -margin and minx[a] - gx < maxx[b] and minx[b] - gx < maxx[a] and miny[a] - gy < maxy[b]
                and miny[b] - gy < maxy[a]):
            keep[q] = True
            n_keep += 1
    # the solve's normals and depths of this step's contacts: two boxes along their entry axis
    nx, ny, depth = cnx.copy(), cny.copy(), cdepth.copy()
    boxes = 0
    started = True
    for i in range(m):
        a, b = cra[i], crb[i]
        if kind[a] == box_kind and kind[b] == box_kind:
            boxes += 1
            if a >= sx.size or b >= sx.size:
                started = False
    if boxes and started:
        for i in range(m):
            a, b = cra[i], crb[i]
            if not (kind[a] == box_kind and kind[b] == box_kind):
                continue
            wx, wy = hw[a] + hw[b], hh[a] + hh[b]
            cx, cy = hx[b] - hx[a], hy[b] - hy[a]
            cx0 = cx - ((x[b] - sx[b]) - (x[a] - sx[a]))
            cy0 = cy - ((y[b] - sy[b]) - (y[a] - sy[a]))
            ox, oy = wx - abs(cx), wy - abs(cy)
            ox0, oy0 = wx - abs(cx0), wy - abs(cy0)
            hair = 1e-6 * _np_min(wx, wy)
            apart_x, apart_y = ox0 <= hair, oy0 <= hair
            late_x = (-ox0) * _np_max(oy - oy0, 0.0) > (-oy0) * _np_max(ox - ox0, 0.0)
            if apart_x and apart_y:
                along_x, along_y = late_x, not late_x
            else:
                along_x, along_y = apart_x and not apart_y, apart_y and not apart_x
            was_x = abs(cnx[i]) > abs(cny[i])
            if along_x and not was_x and ox > 0.0:
                nx[i], ny[i], depth[i] = (-1.0 if (cx0 if cx0 != 0.0 else cx) < 0.0 else 1.0), 0.0, ox
            elif along_y and was_x and oy > 0.0:
                nx[i], ny[i], depth[i] = 0.0, (-1.0 if (cy0 if cy0 != 0.0 else cy) < 0.0 else 1.0), oy
    # this step's contacts, then the pairs kept
    # (as two blocks, the rows of which are the columns: each array handed back costs the caller)
    t = m + n_keep
    ints, floats = np.empty((4, t), dtype=np.int64), np.zeros((9, t))  # (a kept pair's point: 0)
    ra, rb, ea, eb = ints[0], ints[1], ints[2], ints[3]
    onx, ony, odepth, opush, oimp, otpush, otimp, opx, opy = (floats[0], floats[1], floats[2], floats[3], floats[4],
                                                              floats[5], floats[6], floats[7], floats[8])
    alive0 = np.zeros(t, dtype=np.bool_)
    for i in range(m):
        ra[i], rb[i], ea[i], eb[i] = cra[i], crb[i], ca[i], cb[i]
        onx[i], ony[i], odepth[i], alive0[i] = nx[i], ny[i], depth[i], True
        opush[i], oimp[i], otpush[i], otimp[i] = push0[i], impulse0[i], tpush0[i], timpulse0[i]
        opx[i], opy[i] = cpx[i], cpy[i]
    o = m
    for q in range(n_old):
        if not keep[q]:
            continue
        j = old[q]
        ra[o], rb[o], ea[o], eb[o] = ora[q], orb[q], sa[j], sb[j]
        onx[o], ony[o], odepth[o] = knx[j], kny[j], gaps[q]
        opush[o], oimp[o], otpush[o], otimp[o] = spush[j], simp[j], stpush[j], stimp[j]
        o += 1
    return ints, floats, alive0


@leaf
def _takes(a, b, kind, sensor, inv_mass, asleep):  # pragma: no cover - compiled
    """Whether the response may act on the pair of rows ``a, b`` by their bodies alone: both have
    a hitbox, neither is a sensor, at least one is movable (a finite mass, awake)."""
    if kind[a] < 0 or kind[b] < 0 or sensor[a] or sensor[b]:
        return False
    return (inv_mass[a] > 0.0 and not asleep[a]) or (inv_mass[b] > 0.0 and not asleep[b])


@kernel
def taking_part(ra, rb, kind, sensor, inv_mass, asleep):  # pragma: no cover - compiled
    """:func:`_takes` of each pair ``(ra[i], rb[i])`` (rows of the store, below its ``n``)."""
    out = np.zeros(ra.size, dtype=np.bool_)
    for i in range(ra.size):
        out[i] = _takes(ra[i], rb[i], kind, sensor, inv_mass, asleep)
    return out


@kernel
def solid_contacts(ra, rb, kind, sensor, inv_mass, asleep, vx, vy, one_way):  # pragma: no cover - compiled
    """``Response._solid`` before its one-way platforms: each contact :func:`_takes` whose bodies'
    velocities are finite (a body a system spoiled with NaN is left alone); and whether a contact
    has a one-way platform (those are then looked at): ``(mask, any one-way)``."""
    out = np.zeros(ra.size, dtype=np.bool_)
    one = False
    for i in range(ra.size):
        a, b = ra[i], rb[i]
        out[i] = _takes(a, b, kind, sensor, inv_mass, asleep) and math.isfinite(vx[a] + vy[a] + vx[b] + vy[b])
        one = one or one_way[a] or one_way[b]
    return out, one


@kernel
def solid_pairs_mask(ra, rb, kind, sensor, inv_mass, asleep, one_way, layer, mask,
                     layers_open):  # pragma: no cover - compiled
    """The pairs of rows the response may act on: both rows real (>= 0), taking part
    (:func:`_takes`), neither a one-way platform, their layers and masks meeting."""
    out = np.zeros(ra.size, dtype=np.bool_)
    for i in range(ra.size):
        out[i] = solid_pair(ra[i], rb[i], kind, sensor, inv_mass, asleep, one_way, layer, mask, layers_open)
    return out


@leaf
def solid_pair(a, b, kind, sensor, inv_mass, asleep, one_way, layer, mask, layers_open):  # pragma: no cover
    """:func:`solid_pairs_mask` of one pair of rows ``a, b``."""
    if a < 0 or b < 0 or one_way[a] or one_way[b] or not _takes(a, b, kind, sensor, inv_mass, asleep):
        return False
    return layers_open or ((layer[a] & mask[b]) != 0 and (layer[b] & mask[a]) != 0)


@kernel
def centres_inside(ra, rb, hit, body, kind, static, box, hx, hy, minx, maxx, miny, maxy, faces):
    # pragma: no cover - compiled
    """The contacts (``hit``) between one static box and a body of another kind of row whose
    hitbox origin lies strictly inside the box's bounds: their indices, in order (the candidates of
    ``Response._deep_inside``); and whether some contact between a static box and a body that is
    not static has a box whose face bits in ``faces`` are not 0, or not known yet (one may leave it
    through a covered face: ``InternalFaces.redirect`` has work)."""
    out = np.empty(ra.size, dtype=np.int64)
    n = 0
    covered = False
    for i in range(ra.size):
        if not hit[i]:
            continue
        a, b = ra[i], rb[i]
        static_a = body[a] == static and kind[a] == box
        static_b = body[b] == static and kind[b] == box
        if static_a == static_b:
            continue
        s, m = (b, a) if static_b else (a, b)
        if body[m] != static and faces[s] != 0:  # (not known yet: not 0 either)
            covered = True
        cx, cy = hx[m], hy[m]
        if minx[s] < cx and cx < maxx[s] and miny[s] < cy and cy < maxy[s]:
            out[n] = i
            n += 1
    return out[:n], covered
