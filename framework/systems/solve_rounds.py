"""The bookkeeping of the solve's rounds, in compiled passes (see :mod:`framework.systems.solve`).

Between runs of the position solver, the solve numbers the bodies it meets, keeps sorted keys of
the pairs it knows, picks the candidate pairs the broad phase and the static cache offer, and
measures the contacts with immovable bodies again. Each of those was a handful of small numpy
calls on a few dozen rows; here each is one loop:

- :func:`number`: the local numbering of new bodies;
- :func:`turning_pairs`: whether a contact has a box or polygon that turns;
- :func:`known_keys`: the sorted pair keys of two lists of pairs;
- :func:`unknown_solid_pairs`: the pairs not among known keys that the response may act on;
- :func:`near_rows`, :func:`kept_static_pairs`: the static candidates;
- :func:`moved_immovable`, :func:`apply_measures`: the contacts with immovable bodies measured
  again, before and after the geometry's measure; :func:`moved_candidates`: the candidate pairs
  to measure again;
- :func:`place`, :func:`far_bodies`: the bodies placed after a run of the solver and which of
  them moved since the last round, and which moved far (past their span or reach);
- :func:`recorded`: what the solve records of its contacts, sorted by pair.

Each is the numpy it replaced, element by element, in the same order of operations (``np.minimum``
as :func:`~framework.systems.gather._np_min`), so the same bits; sorts are of integers (any sort
gives the same answer; a stable one where ties are kept in order) and set membership is exact.
(Few functions, for a fresh install's compile: see :mod:`framework.systems.solve_columns`.)
"""

from __future__ import annotations

import math

import numpy as np

from ..compiled import kernel, leaf
from ..stable_sort import argsort_ints
from .gather import _find, _np_max, _np_min, _places, _row, solid_pair
from .solve_columns import push_cap, turning_pair

__all__ = ["apply_measures", "far_bodies", "kept_static_pairs", "known_keys", "moved_candidates", "moved_immovable",
           "near_rows", "number", "place", "recorded", "separations", "turning_pairs", "unknown_solid_pairs"]


@kernel
def _where(mask):  # pragma: no cover - compiled
    """``np.flatnonzero(mask)`` (int64), by two loops (numba compiles these faster than numpy's)."""
    n = 0
    for k in range(mask.size):
        n += 1 if mask[k] else 0
    out = np.empty(n, dtype=np.int64)
    n = 0
    for k in range(mask.size):
        if mask[k]:
            out[n] = k
            n += 1
    return out


@kernel
def _at(values, idx):  # pragma: no cover - compiled
    """``values[idx]`` for an index array ``idx``, by a loop."""
    out = np.empty(idx.size, dtype=values.dtype)
    for k in range(idx.size):
        out[k] = values[idx[k]]
    return out


@kernel
def number(table, ra, rb, first):  # pragma: no cover - compiled
    """Number the rows of ``ra`` and ``rb`` that ``table`` (row -> number, -1: none) does not know
    yet, from ``first`` on in row order, entering them in the table: ``(the new rows, every
    entry's number, ra's then rb's)``. (The new rows are marked -2 in the table, then numbered in
    one sweep over the rows between the least and the greatest: no sort.)"""
    c = ra.size
    fresh, lo, hi = 0, table.size, -1
    for k in range(2 * c):
        r = ra[k] if k < c else rb[k - c]
        if table[r] == -1:
            table[r] = -2
            fresh += 1
            lo, hi = min(lo, r), max(hi, r)
    new = np.empty(fresh, dtype=np.int64)
    j = 0
    for r in range(lo, hi + 1):
        if table[r] == -2:
            table[r] = first + j
            new[j] = r
            j += 1
    local = np.empty(2 * c, dtype=np.int64)
    for k in range(2 * c):
        local[k] = table[ra[k] if k < c else rb[k - c]]
    return new, local


@leaf
def turning_pairs(ra, rb, kind, inv_inertia, polygon):  # pragma: no cover - compiled
    """Whether a pair ``(ra, rb)`` has a body of kind ``polygon`` that turns (:func:`turning_pair`)."""
    for i in range(ra.size):
        if turning_pair(ra[i], rb[i], kind, inv_inertia, polygon):
            return True
    return False


@kernel
def known_keys(ea, eb, ca, cb):  # pragma: no cover - compiled
    """The sorted pair keys (``events.pair_keys``) of the pairs ``(ea, eb)`` and ``(ca, cb)``."""
    keys = np.empty(ea.size + ca.size, dtype=np.int64)
    for i in range(ea.size):
        keys[i] = (np.int64(ea[i]) << 32) | np.int64(eb[i])
    for i in range(ca.size):
        keys[ea.size + i] = (np.int64(ca[i]) << 32) | np.int64(cb[i])
    return _at(keys, argsort_ints(keys))  # (the contacts come as a few sorted runs, the candidates as one)


@kernel
def unknown_solid_pairs(ra, rb, ea, eb, known, n, kind, sensor, inv_mass, asleep, one_way, layer, mask,
                        layers_open):  # pragma: no cover - compiled
    """The pairs ``(ra, rb, ea, eb)`` whose key is not in the sorted ``known``, both rows in the
    store's ``n``, that the response may act on (``gather.solid_pair``)."""
    keys = np.empty(ra.size, dtype=np.int64)
    for i in range(ra.size):
        keys[i] = (np.int64(ea[i]) << 32) | np.int64(eb[i])
    at = np.empty(ra.size, dtype=np.int64)
    _places(keys, known, at)  # (the broad phase's pairs come sorted by key: one walk along ``known``)
    ok = np.zeros(ra.size, dtype=np.bool_)
    for i in range(ra.size):
        ok[i] = (ra[i] < n and rb[i] < n and at[i] < 0
                 and solid_pair(ra[i], rb[i], kind, sensor, inv_mass, asleep, one_way, layer, mask, layers_open))
    idx = _where(ok)
    return _at(ra, idx), _at(rb, idx), _at(ea, idx), _at(eb, idx)


@kernel
def near_rows(bodies, rows, reach, inv_mass, asleep, x, y, cx, cy):  # pragma: no cover - compiled
    """Of the local ``bodies`` (store ``rows``, ``reach``), those the response may move (``inv_mass >
    0``, awake) with a finite reach, their rows and reaches, and which of them stand more than their
    reach (``|dx| + |dy|``) from where their statics were looked up ``(cx, cy)`` (or were never
    looked up: NaN): ``(rows, margin, far)``."""
    ok = np.zeros(bodies.size, dtype=np.bool_)
    for k in range(bodies.size):
        r = rows[bodies[k]]
        ok[k] = inv_mass[r] > 0.0 and not asleep[r] and math.isfinite(reach[bodies[k]])
    picked = _at(bodies, _where(ok))
    rows, margin = _at(rows, picked), _at(reach, picked)
    far = np.empty(rows.size, dtype=np.bool_)
    for k in range(rows.size):
        r = rows[k]
        far[k] = not (abs(x[r] - cx[r]) + abs(y[r] - cy[r]) <= margin[k])
    return rows, margin, far


@kernel
def kept_static_pairs(n, rows, pair_row, pea, peb, known, lut, kind, sensor, inv_mass, asleep, one_way, layer, mask,
                      layers_open):  # pragma: no cover - compiled
    """The kept static pairs ``(pea, peb)`` of ``rows`` (each pair's dynamic row: ``pair_row``)
    whose key is not in the sorted ``known``, that the response may act on: ``(rows a, rows b,
    entities a, entities b)``, rows looked up in ``lut`` (-1: none)."""
    want = np.zeros(n, dtype=np.bool_)
    for k in range(rows.size):
        want[rows[k]] = True
    m = pair_row.size
    ok = np.zeros(m, dtype=np.bool_)
    ra, rb = np.empty(m, dtype=np.int64), np.empty(m, dtype=np.int64)
    for j in range(m):
        ra[j], rb[j] = _row(lut, pea[j]), _row(lut, peb[j])
        ok[j] = (want[pair_row[j]] and _find(known, (np.int64(pea[j]) << 32) | np.int64(peb[j])) < 0
                 and solid_pair(ra[j], rb[j], kind, sensor, inv_mass, asleep, one_way, layer, mask, layers_open))
    idx = _where(ok)
    return _at(ra, idx), _at(rb, idx), _at(pea, idx), _at(peb, idx)


@kernel
def moved_immovable(immovable, moved, a, b, at_points, ra, rb):  # pragma: no cover - compiled
    """The contacts with an immovable body one of whose bodies moved: those not at points (with
    their rows ``ra``, ``rb``) and those at points (``at_points``; empty: none are):
    ``(check, rows a, rows b, points)``."""
    c = a.size
    sel = np.zeros(c, dtype=np.bool_)
    pts = np.zeros(c, dtype=np.bool_)
    for i in range(c):
        if immovable[i] and (moved[a[i]] or moved[b[i]]):
            if at_points.size > 0 and at_points[i]:
                pts[i] = True
            else:
                sel[i] = True
    check = _where(sel)
    return check, _at(ra, check), _at(rb, check), _where(pts)


@leaf
def _shift(i, p, q, dx, dy, nx, ny, rn_a, rn_b, dturn):  # pragma: no cover - compiled
    """``Solve._shift`` of contact ``i`` (bodies ``p``, ``q``): how far the solve has moved them apart
    along its normal (and, for contacts at points, turned them: ``rn_a`` not empty)."""
    shift = (dx[q] - dx[p]) * nx[i] + (dy[q] - dy[p]) * ny[i]
    if rn_a.size > 0:
        shift += rn_b[i] * dturn[q] - rn_a[i] * dturn[p]
    return shift


@kernel
def separations(a, b, nx, ny, dx, dy, rn_a, rn_b, dturn, depth):  # pragma: no cover - compiled
    """``Solve._separations``: every contact's separation where the bodies now stand, along its
    normal (its shift less its depth; turns count for contacts at points: ``rn_a`` not empty)."""
    out = np.empty(depth.size)
    for i in range(depth.size):
        out[i] = _shift(i, a[i], b[i], dx, dy, nx, ny, rn_a, rn_b, dturn) - depth[i]
    return out


@leaf
def apply_measures(check, hit, rnx, rny, rdepth, a, b, nx, ny, depth, dx, dy, rn_a, rn_b, dturn, dirty,
                   tolerance):  # pragma: no cover - compiled
    """The contacts ``check`` measured again (``hit``, normals, depths where the bodies now stand),
    written into the solve's columns in place (depths relative to where the solve began): one
    apart keeps its depth or the gap its shift opened, whichever is less; one that overlaps takes
    the new normal and depth and is looked at again. Returns ``(any hit, any hit deeper than
    tolerance)``."""
    any_hit = over = False
    for j in range(check.size):
        i = check[j]
        if hit[j]:
            nx[i], ny[i] = rnx[j], rny[j]
        shift = _shift(i, a[i], b[i], dx, dy, nx, ny, rn_a, rn_b, dturn)  # (along the normal now)
        if hit[j]:
            depth[i] = rdepth[j] + shift
            dirty[i] = True
            any_hit = True
            over = over or rdepth[j] > tolerance
        else:  # touching, or a sliver within rounding: no longer pushed along
            depth[i] = _np_min(depth[i], shift)
    return any_hit, over


@leaf
def _slack(i, ra, rb, bound, point_slack):  # pragma: no cover - compiled
    """Contacts at points: the overlap of contact ``i``'s point measured again that is left to the
    next step rather than given another round (second order: what a turn's arc adds),
    ``point_slack`` times one plus the smaller body's size."""
    return point_slack * (1.0 + _np_min(bound[ra[i]], bound[rb[i]]))


@kernel
def pairs_of(check, ea, eb):  # pragma: no cover - compiled
    """The pairs of contacts ``check`` (a pair's points are contacts of one pair of entities):
    ``np.unique(keys, return_index=True, return_inverse=True)``'s index and inverse of their pair
    keys, the first of each pair in key order and each contact's pair."""
    m = check.size
    keys = np.empty(m, dtype=np.int64)
    for i in range(m):
        keys[i] = (ea[check[i]] << 32) | eb[check[i]]
    order = argsort_ints(keys)  # (stable: the first of equal keys first, as np.unique's)
    first = np.empty(m, dtype=np.int64)
    pair = np.empty(m, dtype=np.int64)
    u = -1
    for t in range(m):
        i = order[t]
        if t == 0 or keys[i] != keys[order[t - 1]]:
            u += 1
            first[u] = i
        pair[i] = u
    return first[: u + 1], pair


@kernel
def points_measured(check, pair, n_pts, sep, slot, a, b, nx, ny, dx, dy, rn_a, rn_b, dturn, depth, dirty, tolerance,
                    ra, rb, bound, point_slack):  # pragma: no cover - compiled
    """``Solve._measure_points``' depths of the contacts at points ``check`` measured again
    (``n_pts, sep``: each pair's points and their separations, ``pair``: each contact's pair),
    written in place (relative to where the solve began): a pair measured with as many points as
    it has keeps each point's separation, otherwise all take its deepest; a pair with no point
    within the margin keeps its depth or the gap its shift opened, whichever is less. A contact
    whose depth changed by more than ``tolerance``, or left deeper than the slack, is looked at
    again (``dirty``). Whether one was left deeper than the slack."""
    had = np.zeros(n_pts.size, dtype=np.int64)
    for j in range(check.size):
        had[pair[j]] += 1
    over = False
    for j in range(check.size):
        i, p = check[j], pair[j]
        s = slot[i] if slot[i] < 1 else 1
        if n_pts[p] == had[p]:
            now = sep[p, s]
        else:
            now = _np_min(sep[p, 0], sep[p, 1]) if n_pts[p] > 1 else sep[p, 0]
        apart = n_pts[p] == 0
        shift = _shift(i, a[i], b[i], dx, dy, nx, ny, rn_a, rn_b, dturn)
        d = _np_min(depth[i], shift) if apart else shift - now
        if abs(d - depth[i]) > tolerance:
            dirty[i] = True
        depth[i] = d
        if -now > _slack(i, ra, rb, bound, point_slack) and not apart:
            dirty[i] = True
            over = True
    return over


@kernel
def pending_points(a, b, nx, ny, dx, dy, rn_a, rn_b, dturn, depth, dirty, immovable, ra, rb, bound,
                   point_slack):  # pragma: no cover - compiled
    """Whether a contact with an immovable body that is to be looked at again (``dirty``) is left
    overlapping by more than its slack (:func:`_slack`) where the bodies now stand:
    ``((Solve._separations() < -slack) & dirty & immovable).any()`` in one pass."""
    for i in range(a.size):
        if dirty[i] and immovable[i]:
            sep = _shift(i, a[i], b[i], dx, dy, nx, ny, rn_a, rn_b, dturn) - depth[i]
            if sep < -_slack(i, ra, rb, bound, point_slack):
                return True
    return False


@kernel
def recorded(touching, push, near, ea, eb, nx, ny, a, b, dx, dy, depth, rn_a, rn_b, dturn, span, impulse, tpush,
             timpulse):  # pragma: no cover - compiled
    """What :meth:`Solve.record` keeps, sorted by pair key (stably: a pair's points in order): the
    contacts acted on (``touching`` or pushed) or ``near`` (empty: none), as ``(ints, floats,
    applied)``: the rows of ``ints`` ``rows, keys, ea, eb``, of ``floats`` ``nx, ny, gap, push,
    capped push, impulse, tpush, timpulse``: the gap where the bodies now stand (0 if they
    overlap), the push capped as :func:`~framework.systems.solve_columns.push_cap` says; and
    whether the contact was acted on."""
    c = ea.size
    kept = np.zeros(c, dtype=np.bool_)
    for i in range(c):
        kept[i] = touching[i] or push[i] > 0.0 or (near.size > 0 and near[i])
    rows = _where(kept)
    keys = np.empty(rows.size, dtype=np.int64)
    for k in range(rows.size):
        keys[k] = (np.int64(ea[rows[k]]) << 32) | np.int64(eb[rows[k]])
    order = argsort_ints(keys)
    rows, keys = _at(rows, order), _at(keys, order)
    m = rows.size
    # (as two blocks, the rows of which are the columns: each array handed back costs the caller)
    ints, floats = np.empty((4, m), dtype=np.int64), np.empty((8, m))
    applied = np.empty(m, dtype=np.bool_)
    for k in range(m):
        i = rows[k]
        ints[0, k], ints[1, k], ints[2, k], ints[3, k] = i, keys[k], ea[i], eb[i]
        shift = _shift(i, a[i], b[i], dx, dy, nx, ny, rn_a, rn_b, dturn)
        floats[0, k], floats[1, k] = nx[i], ny[i]
        floats[2, k] = _np_max(shift - depth[i], 0.0)
        floats[3, k] = push[i]
        floats[4, k] = push_cap(push[i], span[a[i]], span[b[i]])
        floats[5, k], floats[6, k], floats[7, k] = impulse[i], tpush[i], timpulse[i]
        applied[k] = touching[i] or push[i] > 0.0
    return ints, floats, applied


@kernel
def place(rows, x0, y0, dx, dy, sx, sy, seen_x, seen_y):  # pragma: no cover - compiled
    """Put the solve's bodies it moved (``dx, dy`` not both 0) at ``(x0 + dx, y0 + dy)`` in the
    store's ``sx, sy`` (as ``BodyStore.place``, whose ``motion`` the caller bumps); and say which
    bodies moved since they were ``(seen_x, seen_y)``, with copies of where they are now (to be
    seen next): ``(how many placed, moved, dx, dy)``."""
    placed = 0
    for k in range(rows.size):
        if dx[k] != 0.0 or dy[k] != 0.0:
            sx[rows[k]] = x0[k] + dx[k]
            sy[rows[k]] = y0[k] + dy[k]
            placed += 1
    n = seen_x.size
    moved = np.empty(n, dtype=np.bool_)
    for k in range(n):
        moved[k] = dx[k] != seen_x[k] or dy[k] != seen_y[k]
    return placed, moved, dx.copy(), dy.copy()


@kernel
def far_bodies(dx, dy, fx, fy, limit, immovable, push, a, b):  # pragma: no cover - compiled
    """The bodies that moved (``dx, dy``) farther than their ``limit`` from ``(fx, fy)``; with
    contacts (``immovable`` not empty), only the bodies of the pushed contacts (``push > 0``)
    between two movable bodies. Returns the mask and whether any is set."""
    n = dx.size
    among = np.ones(n, dtype=np.bool_)
    if immovable.size > 0:
        among[:] = False
        for i in range(immovable.size):
            if not immovable[i] and push[i] > 0.0:
                among[a[i]] = True
                among[b[i]] = True
    far = np.zeros(n, dtype=np.bool_)
    anyone = False
    for k in range(n):
        far[k] = among[k] and math.hypot(dx[k] - fx[k], dy[k] - fy[k]) > limit[k]
        anyone = anyone or far[k]
    return far, anyone


@kernel
def moved_candidates(moved, table, ra, rb, immovable_only, inv_mass, asleep):  # pragma: no cover - compiled
    """The candidate pairs ``(ra, rb)`` (store rows) one of whose bodies is in the solve (``table``:
    row -> local number, -1: not) and ``moved``; ``immovable_only``: only those with a body the
    response may not move (no finite mass, or asleep): ``(indices, rows a, rows b)``."""
    near = np.zeros(ra.size, dtype=np.bool_)
    for i in range(ra.size):
        p, q = ra[i], rb[i]
        ta, tb = table[p], table[q]
        near[i] = (ta >= 0 and moved[ta]) or (tb >= 0 and moved[tb])
        if immovable_only and near[i]:
            near[i] = not ((inv_mass[p] > 0.0 and not asleep[p]) and (inv_mass[q] > 0.0 and not asleep[q]))
    look = _where(near)
    return look, _at(ra, look), _at(rb, look)
