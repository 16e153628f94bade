"""The soft step as one compiled call: broad phase, manifolds and Box2D v3's soft-step solver.

Read top to bottom, one step is:

1. **shapes**: every hitbox as a rounded polygon in world coordinates, and its bounds swept by
   this step's motion (:func:`_world_shapes`);
2. **broad phase**: candidate pairs kept between steps on fat bounds (a moving body's bounds, a
   margin wider): a body that leaves its fat bounds gets new ones and only its pairs change
   (:func:`_moved_pairs`); after a structural change, or when many bodies left theirs, all of them
   again by sort and sweep (:func:`_candidate_pairs`). Never two idle bodies (static, or without a
   velocity); never layers that do not meet;
3. **narrow phase**: a manifold per pair (:mod:`framework.collision.soft_manifold`), reported up
   to a speculative distance that grows with the pair's motion this step, so a fast body meets a
   wall it would otherwise pass in one step (no tunnelling, without a separate sweep);
4. **prepare**: anchors relative to each body's origin (a body turning about a centre of mass off
   its entity's origin has its position moved to that centre for the step, and back after:
   :func:`_to_centres`, :func:`_from_centres`), effective masses, the impulses of last
   step's matching points (by pair slot and feature id) to warm start with; where nothing turns, a
   face's two points are one row; the joints prepared likewise (:mod:`.soft_joints`), and the
   pairs of a joint's bodies never touch (unless it says they collide);
5. **sub-steps** (Box2D's ``b2SolverStage``): integrate velocities (gravity), warm start, solve
   with soft constraints (the bias pushes overlap out at most ``push_speed``), integrate
   positions, relax (solve again without the bias); joints before contacts in each;
6. **restitution**, then **store** the impulses in the pairs' slots and report the pairs in
   contact sorted by entity ids (started ones flagged), the ones no longer in contact, and the
   sleepers an awake body touched (to wake).

The separation of a point during the sub-steps is measured from the anchors and the bodies'
motion since the step began (Box2D's ``contact_solver.c`` derivation), so nothing is re-measured
geometrically inside the solve. Sequential impulses over contacts in a fixed order: bit-identical
results for identical inputs.

Numba's cache of this module does not see through the functions it calls from
:mod:`framework.collision.soft_manifold`, :mod:`.soft_joints` and :mod:`.softness`: after editing
one of them, delete the ``soft_kernel*``
cache files in ``__pycache__`` (an installed release replaces both files at once).
"""

from __future__ import annotations

import math

import numpy as np

from ..collision.box_rows import holds
from ..collision.soft_manifold import (
    DOWN,
    LEFT,
    RIGHT,
    UP,
    box_box,
    capsule_capsule,
    chain_segment,
    circle_circle,
    polygon_circle,
    polygon_polygon,
)
from ..compiled import kernel, leaf
from ..stable_sort import argsort_ints
from .soft_joints import prepare_joints, solve_joints, warm_start_joints
from .softness import soft as _soft

__all__ = ["CHAIN_KIND", "PARAMS", "SLOT", "internal_faces", "soft_step"]

# The layout of the ``params`` float array (one argument instead of fourteen scalars).
PARAMS = ("dt", "substeps", "gx", "gy", "slop", "speculative", "hertz", "damping", "push_speed",
          "restitution_threshold", "layers_open", "response", "rotation", "friction", "fat_margin", "joint_hertz",
          "joint_damping")
(_DT, _SUB, _GX, _GY, _SLOP, _SPEC, _HZ, _ZETA, _PUSH, _REST, _LAYERS, _RESPONSE, _ROT, _FRIC, _FAT, _JHZ,
 _JZETA) = range(len(PARAMS))

_DYNAMIC, _STATIC = 0, 2
_AABB, _CIRCLE, _CAPSULE = 0, 1, 3
CHAIN_KIND = _CHAIN = 5  # a chain segment (kernel_tables' code: the store's kind is a segment's)


@kernel
def internal_faces(x, y, rot, off, half, cnt, eligible, layer, mask):
    """Each row's internal faces (bits :data:`~framework.collision.soft_manifold.LEFT`, ``RIGHT``,
    ``DOWN``, ``UP``; 0 for rows not ``eligible``: static boxes that take part in the response). A
    face of box ``T`` is internal when another eligible box of the same layer and mask spans the
    whole face and reaches past it, to within the rounding of the coordinates: a floor or a wall of
    tiles. ``half``: each row's half extents. One sort and sweep along x, when the statics change."""
    n = x.size
    faces = np.zeros(n, dtype=np.int64)
    rows = np.empty(n, dtype=np.int64)
    m = 0
    for r in range(n):
        if eligible[r] and cnt[r] > 0:
            rows[m] = r
            m += 1
    box = np.empty((n, 4))  # xmin, ymin, xmax, ymax
    tol = np.empty(n)
    xs = np.empty(m)
    for k in range(m):
        r = rows[k]
        c, s = math.cos(rot[r]), math.sin(rot[r])
        hx, hy = x[r] + c * off[r, 0] - s * off[r, 1], y[r] + s * off[r, 0] + c * off[r, 1]
        box[r, 0], box[r, 1], box[r, 2], box[r, 3] = hx - half[r, 0], hy - half[r, 1], hx + half[r, 0], hy + half[r, 1]
        tol[r] = 1e-9 * (1.0 + abs(hx) + abs(hy) + half[r, 0] + half[r, 1])
        xs[k] = box[r, 0]
    order = argsort_ints(_float_keys(xs))
    for ii in range(m):
        i = rows[order[ii]]
        for jj in range(ii + 1, m):
            j = rows[order[jj]]
            t = max(tol[i], tol[j])
            if box[j, 0] > box[i, 2] + t:
                break
            if box[j, 1] > box[i, 3] + t or box[i, 1] > box[j, 3] + t:
                continue
            if layer[i] != layer[j] or mask[i] != mask[j]:
                continue
            for q in range(2):
                T, M = (i, j) if q == 0 else (j, i)  # does M cover a face of T?
                spans_y = box[M, 1] <= box[T, 1] + t and box[M, 3] >= box[T, 3] - t
                spans_x = box[M, 0] <= box[T, 0] + t and box[M, 2] >= box[T, 2] - t
                if spans_y and box[M, 0] <= box[T, 2] + t and box[M, 2] > box[T, 2] + t:
                    faces[T] |= RIGHT
                if spans_y and box[M, 2] >= box[T, 0] - t and box[M, 0] < box[T, 0] - t:
                    faces[T] |= LEFT
                if spans_x and box[M, 1] <= box[T, 3] + t and box[M, 3] > box[T, 3] + t:
                    faces[T] |= UP
                if spans_x and box[M, 3] >= box[T, 1] - t and box[M, 1] < box[T, 1] - t:
                    faces[T] |= DOWN
    return faces


@leaf
def _world_shapes(x, y, rot, vx, vy, w, moving, driven, off, lv, ln, cnt, rr, spin, bound, dt, gx, gy, margin0,
                  wc, wv, wn, lo, hi, reach, owner):
    """World centres, vertices and normals of every hitbox (``cnt == 0``: none) and its bounds, widened by
    ``margin0`` and swept by the body's motion this step; ``reach``: how far the body may move. The
    shape rows are posed by their ``owner`` body rows (a row of its own but for a compound body's parts)."""
    g = (abs(gx) + abs(gy)) * dt * dt
    for q in range(cnt.size):
        k = cnt[q]
        if k == 0:
            continue
        r = owner[q]
        c, s = math.cos(rot[r]), math.sin(rot[r])
        ox, oy = off[q, 0], off[q, 1]
        hx, hy = x[r] + c * ox - s * oy, y[r] + s * ox + c * oy
        wc[q, 0], wc[q, 1] = hx, hy
        if not spin[q]:
            c, s = 1.0, 0.0
        mnx, mny, mxx, mxy = 1e300, 1e300, -1e300, -1e300
        for i in range(k):
            px, py = lv[q, i, 0], lv[q, i, 1]
            qx, qy = hx + c * px - s * py, hy + s * px + c * py
            wv[q, i, 0], wv[q, i, 1] = qx, qy
            wn[q, i, 0] = c * ln[q, i, 0] - s * ln[q, i, 1]
            wn[q, i, 1] = s * ln[q, i, 0] + c * ln[q, i, 1]
            mnx, mxx = min(mnx, qx), max(mxx, qx)
            mny, mxy = min(mny, qy), max(mxy, qy)
        rad = rr[q] + margin0
        mnx, mny, mxx, mxy = mnx - rad, mny - rad, mxx + rad, mxy + rad
        m = 0.0
        if moving[r] and not driven[r]:
            ex, ey = vx[r] * dt, vy[r] * dt
            m = abs(ex) + abs(ey) + abs(w[r]) * bound[q] * dt + g
            turn = abs(w[r]) * bound[q] * dt + g
            mnx += min(ex, 0.0) - turn
            mxx += max(ex, 0.0) + turn
            mny += min(ey, 0.0) - turn
            mxy += max(ey, 0.0) + turn
        lo[q, 0], lo[q, 1], hi[q, 0], hi[q, 1] = mnx, mny, mxx, mxy
        reach[q] = m


@kernel
def _float_keys(v):
    """Integers in the order of the floats ``v`` (their bits, the negatives' flipped): one sort
    (:func:`~framework.stable_sort.argsort_ints`) serves both."""
    k = (v + 0.0).view(np.int64)  # (+ 0.0: -0.0 becomes 0.0, its equal)
    for i in range(k.size):
        if k[i] < 0:
            k[i] ^= 0x7FFFFFFFFFFFFFFF
    return k


@kernel
def _candidate_pairs(fat, cnt, fixed, layer, mask, layers_open, entity, owner):
    """Sort-and-sweep along x over the fat bounds: the pairs of rows whose fat bounds overlap
    (never two fixed ones, never two shapes of one ``owner`` body; layers that meet), as rows
    ``(a, b, key)`` with ``entity[a] < entity[b]`` and ``key = entity[a] << 32 | entity[b]``, sorted
    by key (``entity``: the shape rows' key ids, a body's entity for its own row)."""
    n = fat.shape[0]
    xs = np.empty(n)
    for i in range(n):
        xs[i] = fat[i, 0]
    order = argsort_ints(_float_keys(xs))
    cap = 4 * n + 16
    pa = np.empty(cap, dtype=np.int64)
    pb = np.empty(cap, dtype=np.int64)
    start, m = 0, 0
    while True:
        start, m = _swept_pairs(start, order, fat, cnt, fixed, layer, mask, layers_open, entity, owner, pa, pb, m)
        if start == n:
            break
        cap *= 2
        na = np.empty(cap, dtype=np.int64)
        nb = np.empty(cap, dtype=np.int64)
        for q in range(m):
            na[q], nb[q] = pa[q], pb[q]
        pa, pb = na, nb
    keys = np.empty(m, dtype=np.int64)
    for k in range(m):
        keys[k] = (entity[pa[k]] << 32) | entity[pb[k]]
    srt = argsort_ints(keys)
    pairs = np.empty((m, 3), dtype=np.int64)
    for k in range(m):
        pairs[k, 0], pairs[k, 1], pairs[k, 2] = pa[srt[k]], pb[srt[k]], keys[srt[k]]
    return pairs


@leaf
def _swept_pairs(start, order, fat, cnt, fixed, layer, mask, layers_open, entity, owner, pa, pb,
                 m):  # pragma: no cover - compiled
    """:func:`_candidate_pairs`' sweep from the ``start``-th row in x order on, its pairs written to
    ``pa, pb`` from ``m`` on: ``(n, the pairs' end)``, or where they were too small for a row's
    pairs, ``(that row's place, the pairs' end before it)``. (Apart, without reference counting:
    numba counted the growing arrays' references in every test.)"""
    n = order.size
    for ii in range(start, n):
        i = order[ii]
        if cnt[i] == 0:
            continue
        xmax = fat[i, 2]
        j0 = m
        for jj in range(ii + 1, n):
            j = order[jj]
            if fat[j, 0] > xmax:
                break
            if cnt[j] == 0 or (fixed[i] and fixed[j]) or owner[i] == owner[j]:
                continue
            if fat[j, 1] > fat[i, 3] or fat[i, 1] > fat[j, 3]:
                continue
            if not layers_open and ((layer[i] & mask[j]) == 0 or (layer[j] & mask[i]) == 0):
                continue
            if j0 == pa.size:
                return ii, m
            if entity[j] < entity[i]:
                pa[j0], pb[j0] = j, i
            else:
                pa[j0], pb[j0] = i, j
            j0 += 1
        m = j0
    return n, m


@leaf
def _fat_overlap(fat, i, j):
    return not (fat[j, 0] > fat[i, 2] or fat[i, 0] > fat[j, 2] or fat[j, 1] > fat[i, 3] or fat[i, 1] > fat[j, 3])


@kernel
def _moved_pairs(fat, moved, cnt, fixed, layer, mask, layers_open, entity, pairs, owner):
    """The candidate pairs after the ``moved`` rows took new fat bounds: exactly what
    :func:`_candidate_pairs` would find (pairs of unmoved rows keep their overlap), at the cost of a
    pass over the pairs and one over the rows per moved row."""
    n = fat.shape[0]
    m = pairs.shape[0]
    keep = np.empty(m, dtype=np.bool_)
    n_keep = 0
    for p in range(m):
        a, b = pairs[p, 0], pairs[p, 1]
        keep[p] = not (moved[a] or moved[b]) or _fat_overlap(fat, a, b)
        if keep[p]:
            n_keep += 1
    old_keys = pairs[:, 2].copy()  # (contiguous: the one holds the joints use too)
    cap = 16
    add = np.empty((cap, 3), dtype=np.int64)
    n_add = 0
    for e in range(n):
        if not moved[e] or cnt[e] == 0:
            continue
        for j in range(n):
            if owner[j] == owner[e] or cnt[j] == 0 or (moved[j] and j < e) or (fixed[e] and fixed[j]):
                continue
            if not _fat_overlap(fat, e, j):
                continue
            if not layers_open and ((layer[e] & mask[j]) == 0 or (layer[j] & mask[e]) == 0):
                continue
            a, b = (e, j) if entity[e] < entity[j] else (j, e)
            key = (entity[a] << 32) | entity[b]
            if holds(old_keys, key):  # already a candidate (and kept: it still overlaps)
                continue
            if n_add == cap:
                cap *= 2
                grown = np.empty((cap, 3), dtype=np.int64)
                for q in range(n_add):
                    grown[q, 0], grown[q, 1], grown[q, 2] = add[q, 0], add[q, 1], add[q, 2]
                add = grown
            add[n_add, 0], add[n_add, 1], add[n_add, 2] = a, b, key
            n_add += 1
    add_keys = np.empty(n_add, dtype=np.int64)
    for q in range(n_add):
        add_keys[q] = add[q, 2]
    order = argsort_ints(add_keys)
    out = np.empty((n_keep + n_add, 3), dtype=np.int64)
    i, k, o = 0, 0, 0
    while i < m or k < n_add:
        if i < m and not keep[i]:
            i += 1
            continue
        if k < n_add and (i >= m or add[order[k], 2] < pairs[i, 2]):
            q = order[k]
            out[o, 0], out[o, 1], out[o, 2] = add[q, 0], add[q, 1], add[q, 2]
            k += 1
        else:
            out[o, 0], out[o, 1], out[o, 2] = pairs[i, 0], pairs[i, 1], pairs[i, 2]
            i += 1
        o += 1
    return out


# Columns of a candidate pair's slot (kept between steps): the feature ids and accumulated normal and
# tangent impulses of its two points, how many points it had, whether it touched, and the contact it
# reported (normal, depth, deepest point).
SLOT = ("id0", "id1", "ni0", "ni1", "ti0", "ti1", "points", "touching", "nx", "ny", "depth", "px", "py")
_ID, _NI, _TI, _NP, _TOUCH, _NX, _NY, _DEPTH, _PX, _PY = 0, 2, 4, 6, 7, 8, 9, 10, 11, 12
# Columns of a contact point in the solve.
_RAX, _RAY, _RBX, _RBY, _BASE, _NMASS, _TMASS, _PNI, _PTI, _TOTAL, _RELV, _PID, _PEAK = range(13)


@kernel
def _merge_slots(old_keys, old_slots, new_keys, ended_keys, ended_f):
    """The slots of the new (sorted) candidate pairs, carried over from the old ones by key; the
    old pairs that touched and are no longer candidates are written to ``ended_*`` (how many)."""
    slots = np.zeros((new_keys.size, len(SLOT)))
    k, n_end = 0, 0
    for i in range(old_keys.size):
        while k < new_keys.size and new_keys[k] < old_keys[i]:
            k += 1
        if k < new_keys.size and new_keys[k] == old_keys[i]:
            for q in range(old_slots.shape[1]):
                slots[k, q] = old_slots[i, q]
        elif old_slots[i, _TOUCH] != 0.0:
            ended_keys[n_end] = old_keys[i]
            for q in range(5):
                ended_f[n_end, q] = old_slots[i, _NX + q]
            n_end += 1
    return slots, n_end


@kernel
def _narrow_phase(pairs, slots, moving, reach, spec, slop, response, rotation, use_friction, kind, cnt, rr, sensor,
                  one_way, friction, restitution, faces, wc, lv, wv, wn, x, y, vx, vy, w, im, ii, apart, owner, entity,
                  rare):
    """The manifold of every candidate pair, and the contacts the solver uses, prepared (anchors, effective
    masses, warm starts from the pair's slot by feature id): ``(nc, ci, cf, cp, tnow, evd)``, see
    :func:`soft_step`; a pair whose bodies both rest keeps its state (``tnow`` -1); a pair whose key is
    in ``apart`` (sorted: the bodies of a joint) never touches. The pairs are of shape rows; the
    solver's bodies are their ``owner`` rows (``ci`` columns 2, 3). ``rare``: None where no row is a
    capsule or a chain segment (numba then drops their manifolds: see :func:`soft_step`)."""
    m = pairs.shape[0]
    compound = owner.size != moving.size  # (shape rows beyond the body rows: parts of compound bodies)
    ci = np.empty((m, 4), dtype=np.int64)  # the contact's pair slot, points the solver uses, its two bodies
    cf = np.empty((m, 5))  # nx, ny, friction, restitution, stiff (against an idle body)
    cp = np.empty((m, 2, 13))
    tnow = np.zeros(m, dtype=np.int8)  # in contact now: 1 yes, 0 no, -1 not measured (keeps its state)
    evd = np.empty((m, 5))  # the contact measured now: nx, ny, depth, px, py
    out = np.empty((2, 4))
    nc = np.int64(0)  # (not the literal 0: the solver's functions would compile twice, for it and for int64)
    for p in range(m):
        a, b = pairs[p, 0], pairs[p, 1]  # shape rows
        ba, bb = owner[a], owner[b]  # their bodies' rows
        was = slots[p, _TOUCH] != 0.0
        if not moving[ba] and not moving[bb]:  # asleep (or still): keeps what it had
            tnow[p] = -1
            slots[p, _NP] = 0.0
            continue
        if apart.size:  # joined, not colliding (``apart``: keys of entities)
            key = pairs[p, 2]
            if compound:
                ea, eb = min(entity[a], entity[b]), max(entity[a], entity[b])
                key = (ea << 32) | eb
            if holds(apart, key):
                tnow[p] = 0
                slots[p, _NP] = 0.0
                continue
        s_pair = spec + reach[a] + reach[b] if response else 0.0
        if kind[a] == _AABB and kind[b] == _AABB:  # the common case, inline (an AABB's corner 2: its half extents)
            k, nx, ny = box_box(wc[a, 0], wc[a, 1], lv[a, 2, 0], lv[a, 2, 1], wc[b, 0], wc[b, 1], lv[b, 2, 0],
                                lv[b, 2, 1], s_pair, out, faces[a], faces[b])
        elif kind[a] == _CIRCLE and kind[b] == _CIRCLE:
            k, nx, ny = circle_circle(wv[a, 0, 0], wv[a, 0, 1], rr[a], wv[b, 0, 0], wv[b, 0, 1], rr[b], s_pair, out)
        elif kind[a] == _CIRCLE or kind[b] == _CIRCLE:  # a polygon (box, capsule) and a circle
            g, o = (b, a) if kind[a] == _CIRCLE else (a, b)
            k, nx, ny = polygon_circle(wv, wn, g, cnt[g], rr[g], wv[o, 0, 0], wv[o, 0, 1], rr[o], s_pair, out,
                                       faces[g])
            if g == b:
                nx, ny = -nx, -ny
        else:
            k, nx, ny = -1, 0.0, 0.0
            if rare is not None:
                if kind[a] == _CAPSULE and kind[b] == _CAPSULE:
                    k, nx, ny = capsule_capsule(wv, a, rr[a], b, rr[b], s_pair, out)
            if k < 0:
                k, nx, ny = polygon_polygon(wv, wn, a, cnt[a], rr[a], b, cnt[b], rr[b], slop, s_pair, out, faces[a],
                                            faces[b])
        if rare is not None:
            if kind[a] == _CHAIN or kind[b] == _CHAIN:  # one-sided, ghost vertices: what the chain keeps
                g, o = (a, b) if kind[a] == _CHAIN else (b, a)
                f = 1.0 if g == a else -1.0
                k, nx, ny = chain_segment(wv, wn, lv, g, o, cnt[o], rr[o], wc[o, 0], wc[o, 1], k, f * nx, f * ny,
                                          s_pair, out)
                nx, ny = f * nx, f * ny
        low = 0.0
        if k > 0:
            low = out[0, 2]
            deep = 0
            if k == 2 and out[1, 2] < low:
                low, deep = out[1, 2], 1
            evd[p, 0], evd[p, 1], evd[p, 2] = nx, ny, max(-low, 0.0)
            evd[p, 3], evd[p, 4] = out[deep, 0], out[deep, 1]
        # In contact: overlapping, or in contact last step and still within the slop (and, after
        # the solve, any pair a solve pushed apart: a speculative contact that stopped a fast body).
        tnow[p] = 1 if k > 0 and (low < 0.0 or (was and low < slop)) else 0
        use = response and k > 0 and not (sensor[a] or sensor[b])
        if use and (one_way[a] or one_way[b]):
            up = ny if one_way[a] else -ny  # the normal from the platform to the other body
            use = up > 0.5 and low > -4.0 * slop
        if use and im[ba] == 0.0 and im[bb] == 0.0 and ii[ba] == 0.0 and ii[bb] == 0.0:
            use = False
        if not use:
            slots[p, _NP] = 0.0
            continue
        # prepare the contact: anchors, effective masses, warm starts from the slot by feature id
        if k == 2 and not rotation:
            # Where nothing turns, a contact's two points have one Jacobian (the normal, no lever
            # arms): solved one after the other they act as one row held by the deeper point. So
            # solve one row (id -1: a translation row, not warm started by a point of a turning
            # step): half the work of a face resting on a face.
            # Its spring stands for the two points' springs side by side: twice as stiff and as
            # damped (hertz and damping ratio times sqrt 2), so it gives under load as they did.
            if out[1, 2] < out[0, 2]:
                out[0, 0], out[0, 1], out[0, 2] = out[1, 0], out[1, 1], out[1, 2]
            out[0, 3] = -1.0
            k = 1
            paired = 2.0
        else:
            paired = 0.0
        ci[nc, 0], ci[nc, 1], ci[nc, 2], ci[nc, 3] = p, k, ba, bb
        fa, fb = friction[a], friction[b]
        mu = 0.0
        if use_friction:
            if fa >= 0.0 and fb >= 0.0:
                mu = math.sqrt(fa * fb)
            elif fa >= 0.0:
                mu = fa
            elif fb >= 0.0:
                mu = fb
        cf[nc, 0], cf[nc, 1], cf[nc, 2] = nx, ny, mu
        cf[nc, 3] = max(restitution[a], restitution[b])
        # the softness to use: 0 between moving bodies, 1 against an idle one (stiffer), + 2 for a
        # row standing for two points
        cf[nc, 4] = (1.0 if (not moving[ba] or not moving[bb]) else 0.0) + paired
        tx, ty = ny, -nx  # Box2D's right perp
        old_np = int(slots[p, _NP])
        a, b = ba, bb  # (from here on, the bodies)
        for j in range(k):
            px, py = out[j, 0], out[j, 1]
            ax_, ay_ = px - x[a], py - y[a]
            bx_, by_ = px - x[b], py - y[b]
            cp[nc, j, _RAX], cp[nc, j, _RAY], cp[nc, j, _RBX], cp[nc, j, _RBY] = ax_, ay_, bx_, by_
            cp[nc, j, _BASE] = out[j, 2] - ((bx_ - ax_) * nx + (by_ - ay_) * ny)
            rna = ax_ * ny - ay_ * nx
            rnb = bx_ * ny - by_ * nx
            kn = im[a] + im[b] + ii[a] * rna * rna + ii[b] * rnb * rnb
            cp[nc, j, _NMASS] = 1.0 / kn if kn > 0.0 else 0.0
            rta = ax_ * ty - ay_ * tx
            rtb = bx_ * ty - by_ * tx
            kt = im[a] + im[b] + ii[a] * rta * rta + ii[b] * rtb * rtb
            cp[nc, j, _TMASS] = 1.0 / kt if kt > 0.0 else 0.0
            cp[nc, j, _RELV] = (nx * (vx[b] - w[b] * by_ - vx[a] + w[a] * ay_)
                                + ny * (vy[b] + w[b] * bx_ - vy[a] - w[a] * ax_))
            cp[nc, j, _PID] = out[j, 3]
            cp[nc, j, _PNI], cp[nc, j, _PTI], cp[nc, j, _TOTAL], cp[nc, j, _PEAK] = 0.0, 0.0, 0.0, 0.0
            for o in range(old_np):
                if slots[p, _ID + o] == out[j, 3]:
                    cp[nc, j, _PNI], cp[nc, j, _PTI] = slots[p, _NI + o], slots[p, _TI + o]
        nc += 1

    return nc, ci, cf, cp, tnow, evd


@kernel
def _report(nc, ci, cp, pairs, slots, tnow, evd, entity, sensor, asleep, moving, ended_keys, ended_f, n_end,
            rebuilt, sleepers, owner, part):
    """Store the impulses in the pairs' slots and report which pairs are in contact: ``(touch_i,
    touch_f, end_i, end_f, info)``, see :func:`soft_step`."""
    m = pairs.shape[0]
    n = moving.size
    wake = np.zeros(n, dtype=np.bool_)
    for c in range(nc):
        p = ci[c, 0]
        k = ci[c, 1]
        slots[p, _NP] = k
        for j in range(k):
            slots[p, _ID + j], slots[p, _NI + j], slots[p, _TI + j] = cp[c, j, _PID], cp[c, j, _PNI], cp[c, j, _PTI]
            if cp[c, j, _PEAK] > 0.0:  # a solve pushed the bodies apart: they met this step
                tnow[p] = 1
    touching_idx = np.empty(m, dtype=np.int64)
    started = np.empty(m, dtype=np.bool_)
    n_touch = 0
    for p in range(m):
        was = slots[p, _TOUCH] != 0.0
        touching = was if tnow[p] < 0 else tnow[p] == 1
        if touching:
            touching_idx[n_touch] = p
            started[n_touch] = not was
            n_touch += 1
            if tnow[p] > 0:
                for q in range(5):
                    slots[p, _NX + q] = evd[p, q]
                a, b = pairs[p, 0], pairs[p, 1]
                if not (sensor[a] or sensor[b]):  # a sleeper an awake body touches wakes
                    a, b = owner[a], owner[b]
                    if asleep[a] and moving[b]:
                        wake[a] = True
                    if asleep[b] and moving[a]:
                        wake[b] = True
        elif was:
            ended_keys[n_end] = pairs[p, 2]
            for q in range(5):
                ended_f[n_end, q] = slots[p, _NX + q]
            n_end += 1
        slots[p, _TOUCH] = 1.0 if touching else 0.0
    # the touching pairs, as the frame's contact columns
    touch_i = np.empty((7, n_touch), dtype=np.int64)
    touch_f = np.empty((5, n_touch))
    for i in range(n_touch):
        p = touching_idx[i]
        a, b = pairs[p, 0], pairs[p, 1]
        touch_i[0, i], touch_i[1, i], touch_i[2, i], touch_i[3, i] = owner[a], owner[b], entity[a], entity[b]
        touch_i[4, i] = 1 if started[i] else 0
        touch_i[5, i], touch_i[6, i] = part[a], part[b]
        for q in range(5):
            touch_f[q, i] = slots[p, _NX + q]
    end_i = np.empty((2, n_end), dtype=np.int64)
    end_f = np.empty((5, n_end))
    for i in range(n_end):
        end_i[0, i], end_i[1, i] = ended_keys[i] >> 32, ended_keys[i] & 0xFFFFFFFF
        for q in range(5):
            end_f[q, i] = ended_f[i, q]
    n_wake = 0
    for r in range(n):
        if wake[r]:
            n_wake += 1
    info = np.empty(3 + n_wake, dtype=np.int64)
    info[0], info[1], info[2] = 1 if rebuilt else 0, nc, sleepers
    n_wake = 3
    for r in range(n):
        if wake[r]:
            info[n_wake] = r
            n_wake += 1
    return touch_i, touch_f, end_i, end_f, info


@kernel
def soft_step(params, x, y, rot, vx, vy, w, asleep, fprops, iprops, off, verts, faces, driven, fat, pairs, slots,
              rebuild, jint, jf, jimp, apart, rare):
    """One step of ``params[_DT]`` over the rows (the pose and velocity columns modified in place).

    What changes only with the rows comes packed, as rows of three tables (see
    :func:`framework.systems.soft_step.kernel_tables`; an array argument costs about 0.3 us to pass):
    ``fprops`` (inverse mass, inverse inertia, friction, restitution, bounding radius, rounding
    radius), ``iprops`` (body kind, shape kind, layer, mask, entity, sensor, one-way, has a
    velocity, vertex count, turns with the body, then the owner, key id and part number of each
    shape row), ``off`` (hitbox offsets) and ``verts`` (each row's local vertices, then normals);
    ``faces``: each row's internal faces (:func:`internal_faces`). The pose and velocity columns
    are the bodies'; the tables may hold more rows than they, the shape rows of compound bodies'
    other parts, each posed by its owner body row and acting on it (its contacts' impulses go to
    the owner; two shapes of one owner never pair); without compound bodies each row is its own
    owner and the step is what it was before they existed, bit for bit.
    ``driven``: rows a character controller moved this step (they are not moved again, and take
    no impulse); ``fat``: each row's fat bounds; ``pairs, slots``: the candidate pairs kept from the last step
    (rows a, b and key) and their slots (``rebuild``: the rows changed, find them again); these are
    not modified: new ones are returned. ``jint, jf, jimp``: the joints, their parameters and their
    impulses from the last step (:mod:`framework.systems.soft_joints`; new impulses are returned),
    or three Nones for a scene without joints (then the joints' code is not compiled for it);
    ``apart``: the sorted keys of the pairs that do not collide (a joint's bodies); ``rare``: None
    for a scene with no capsule and no chain segment (then their manifolds are not compiled for it:
    about 4 of the 24 seconds a new installation's first soft step compiles), else any integer.
    See the module docstring for the stages.

    Returns ``(fat, pairs, slots, touch_i, touch_f, end_i, end_f, info, jimp)`` (few objects: each
    array returned to Python costs about a microsecond): the fat bounds, candidate pairs and their
    slots for the next step; the pairs touching now (``touch_i`` rows: body row a, body row b,
    entity a, entity b, started, part a, part b; ``touch_f`` rows: nx, ny, depth, px, py), the pairs
    that stopped touching (``end_i`` rows: key id a, key id b, the entities but for parts, see
    ``soft_step.part_ids``; ``end_f``: their last contact); ``info``: whether the pairs
    were found again, how many contacts the solver used, how many bodies sleep (before this step's
    wakes), then the rows of the sleepers to wake; the joints' impulses."""
    inv_mass, inv_inertia, friction, restitution, bound, rr = fprops[0], fprops[1], fprops[2], fprops[3], fprops[4], \
        fprops[5]
    body, kind, layer, mask, entity = iprops[0], iprops[1], iprops[2], iprops[3], iprops[4]
    sensor, one_way, has_vel, cnt, spin = iprops[5], iprops[6], iprops[7], iprops[8], iprops[9]
    owner, sid, part = iprops[10], iprops[11], iprops[12]
    lv, ln = verts[:, :, 0:2], verts[:, :, 2:4]
    dt = params[_DT]
    nsub = int(params[_SUB])
    gx, gy = params[_GX], params[_GY]
    slop, spec = params[_SLOP], params[_SPEC]
    response, rotation, use_friction = params[_RESPONSE] != 0.0, params[_ROT] != 0.0, params[_FRIC] != 0.0
    n = x.size  # the bodies' rows; then, in compound scenes, the shape rows of their other parts
    ns = cnt.size
    K = lv.shape[1]

    # --- bodies: who moves, who takes impulses ----------------------------------------------
    moving = np.zeros(n, dtype=np.bool_)
    fixed = np.zeros(n, dtype=np.bool_)  # never moves by itself: static, or without a velocity
    im = np.zeros(n)
    ii = np.zeros(n)
    sleepers = np.int64(0)  # (np.int64: a literal 0 would compile _report twice)
    for r in range(n):
        fixed[r] = body[r] == _STATIC or not has_vel[r]
        moving[r] = not fixed[r] and not asleep[r]
        if asleep[r] and body[r] != _STATIC:
            sleepers += 1
        if moving[r] and body[r] == _DYNAMIC and response:
            im[r] = inv_mass[r]
            if rotation:
                ii[r] = inv_inertia[r]
    # A scene where nothing turns runs the translation-only solve (no angular terms).
    turns = False
    for r in range(n):
        if ii[r] > 0.0 or (moving[r] and w[r] != 0.0):
            turns = True
            break
    rotation = rotation and turns
    turning = np.zeros(n, dtype=np.bool_)
    for r in range(n):
        turning[r] = moving[r] and (ii[r] > 0.0 or w[r] != 0.0)

    # --- bodies that turn about a centre of mass off their origin ------------------------------
    # (Box2D's local centre.) Such a body is stepped as if its origin were its centre of mass: its
    # position is moved there, its hitbox offset and joint anchors are measured from there, and it
    # is moved back at the end. Rows whose centre is their origin are not touched: not a bit of
    # them changes, and a scene without such a body pays one pass over the rows.
    conv = np.zeros(n, dtype=np.bool_)
    shifted = False
    x_origin, y_origin, centre0 = x, y, np.zeros((0, 2))
    for r in range(n):
        if turning[r] and not driven[r] and body[r] == _DYNAMIC and (off[r, 2] != 0.0 or off[r, 3] != 0.0):
            conv[r] = True
            shifted = True
    if shifted:
        x_origin, y_origin = x.copy(), y.copy()
        off, bound, centre0 = _to_centres(x, y, rot, off, bound, conv, owner)
        if jint is not None:
            jf = _anchors_from_centres(jint, jf, off, conv)

    # --- shapes, fat bounds and the broad phase ----------------------------------------------------
    wc = np.empty((ns, 2))
    wv = np.empty((ns, K, 2))
    wn = np.empty((ns, K, 2))
    lo = np.empty((ns, 2))
    hi = np.empty((ns, 2))
    reach = np.zeros(ns)
    margin0 = 0.5 * spec if response else 0.0
    _world_shapes(x, y, rot, vx, vy, w, moving, driven, off, lv, ln, cnt, rr, spin, bound, dt, gx, gy, margin0,
                  wc, wv, wn, lo, hi, reach, owner)
    fixed_s = fixed  # each shape row's body is fixed
    if ns != n:
        fixed_s = np.empty(ns, dtype=np.bool_)
        for q in range(ns):
            fixed_s[q] = fixed[owner[q]]
    fat_margin = params[_FAT]
    fat = fat.copy()  # (the step's inputs stay as they were: a failed step is undone by keeping them)
    slots = slots.copy()
    moved = np.zeros(ns, dtype=np.bool_)  # left its fat bounds (or the rows changed): new fat bounds
    n_moved = 0
    for r in range(ns):
        if cnt[r] == 0:
            continue
        inside = (lo[r, 0] >= fat[r, 0] and lo[r, 1] >= fat[r, 1] and hi[r, 0] <= fat[r, 2]
                  and hi[r, 1] <= fat[r, 3])
        if rebuild or not inside:
            e = 0.0 if fixed_s[r] else fat_margin
            fat[r, 0], fat[r, 1], fat[r, 2], fat[r, 3] = lo[r, 0] - e, lo[r, 1] - e, hi[r, 0] + e, hi[r, 1] + e
            moved[r] = True
            n_moved += 1
    n_end = np.int64(0)
    ended_keys = np.empty(pairs.shape[0], dtype=np.int64)
    ended_f = np.empty((pairs.shape[0], 5))
    rebuilt = rebuild or 8 * n_moved > ns
    if rebuilt or n_moved:
        if rebuilt:  # everything again: sort and sweep
            new = _candidate_pairs(fat, cnt, fixed_s, layer, mask, params[_LAYERS] != 0.0, sid, owner)
        else:  # a few bodies left their fat bounds: only their pairs change
            new = _moved_pairs(fat, moved, cnt, fixed_s, layer, mask, params[_LAYERS] != 0.0, sid, pairs, owner)
        slots, n_end = _merge_slots(pairs[:, 2], slots, new[:, 2], ended_keys, ended_f)
        pairs = new

    # --- narrow phase: manifolds -> contacts, prepared ---------------------------------------------
    nc, ci, cf, cp, tnow, evd = _narrow_phase(pairs, slots, moving, reach, spec, slop, response, rotation, use_friction,
                                              kind, cnt, rr, sensor, one_way, friction, restitution, faces, wc, lv,
                                              wv, wn, x, y, vx, vy, w, im, ii, apart, owner, entity, rare)

    # --- sub-steps ------------------------------------------------------------------------------
    h = dt / nsub if nsub > 0 else 0.0
    inv_h = 1.0 / h if h > 0.0 else 0.0
    hertz = min(params[_HZ], 0.125 * inv_h)
    zeta = params[_ZETA]
    r2 = math.sqrt(2.0)
    softness = np.empty((4, 3))  # rows: between moving bodies, against an idle one; then each for a paired row
    for q in range(4):
        scale = r2 if q >= 2 else 1.0
        softness[q, 0], softness[q, 1], softness[q, 2] = _soft((2.0 if q & 1 else 1.0) * scale * hertz,
                                                               scale * zeta, h)
    push = params[_PUSH]
    # (a scene without joints passes None: numba drops these branches, and compiles none of the
    # joints' code for it)
    if jint is not None:
        jp = prepare_joints(jint, jf, x, y, rot, moving, im, ii, h)
        jimp = jimp.copy()
        jsoft = np.empty(3)  # the joints' stiffness (Box2D's b2PrepareJoint: at most a quarter of the sub-step rate)
        jsoft[0], jsoft[1], jsoft[2] = _soft(min(params[_JHZ], 0.25 * inv_h), params[_JZETA], h)
    x0 = x.copy()
    y0 = y.copy()
    qc = np.ones(n)
    qs = np.zeros(n)
    for _sub in range(nsub):
        for r in range(n):  # integrate velocities
            if moving[r] and body[r] == _DYNAMIC and not driven[r]:
                vx[r] += h * gx
                vy[r] += h * gy
        if jint is not None:
            warm_start_joints(jint, jf, jp, jimp, x, y, x0, y0, qc, qs, rot, vx, vy, w)
        _warm_start(nc, ci, cf, cp, pairs, vx, vy, w, im, ii)
        for relax in range(2):  # solve (with the soft push), integrate positions, relax (without)
            if relax:
                for r in range(n):
                    if moving[r] and not driven[r]:
                        x[r] += h * vx[r]
                        y[r] += h * vy[r]
                        if turning[r]:
                            # the turn since the step began, as Box2D's b2IntegrateRotation: (c, s)
                            # advanced along its tangent and normalised (no cos or sin)
                            hw = h * w[r]
                            rot[r] += hw
                            c2, s2 = qc[r] - hw * qs[r], qs[r] + hw * qc[r]
                            mag = 1.0 / math.sqrt(c2 * c2 + s2 * s2)
                            qc[r], qs[r] = c2 * mag, s2 * mag
            if jint is not None:
                solve_joints(jint, jf, jp, jimp, x, y, x0, y0, qc, qs, rot, vx, vy, w, relax == 0, jsoft, h, inv_h)
            _solve(nc, ci, cf, cp, pairs, x, y, x0, y0, qc, qs, vx, vy, w, im, ii, relax == 0, rotation, softness,
                   inv_h, push)
    _restitution(nc, ci, cf, cp, pairs, vx, vy, w, im, ii, params[_REST])
    if shifted:
        _from_centres(x, y, rot, off, conv, x_origin, y_origin, x0, y0, centre0)

    # --- store the impulses in the slots; which pairs are in contact ----------------------------
    touch_i, touch_f, end_i, end_f, info = _report(nc, ci, cp, pairs, slots, tnow, evd, entity, sensor, asleep, moving,
                                                   ended_keys, ended_f, n_end, rebuilt, sleepers, owner, part)
    return fat, pairs, slots, touch_i, touch_f, end_i, end_f, info, jimp


@kernel
def _to_centres(x, y, rot, off, bound, conv, owner):
    """Move the ``conv`` rows' positions from their origins to their centres of mass (``off``
    columns 2, 3, in the body's frame): returns copies of ``off`` and ``bound`` for the step, the
    hitbox offsets measured from the centres and the reach of each hitbox about them, and each
    centre turned into the world at the step's start (``R(rot) c``). The shape rows of a compound
    body's other parts (after the body rows, posed by their ``owner``) have their offsets measured
    from their body's centre too (their reach already holds it: see ``kernel_tables``)."""
    n = x.size
    off = off.copy()
    bound = bound.copy()
    centre0 = np.zeros((n, 2))
    for r in range(n):
        if not conv[r]:
            continue
        cx, cy = off[r, 2], off[r, 3]
        c, s = math.cos(rot[r]), math.sin(rot[r])
        centre0[r, 0], centre0[r, 1] = c * cx - s * cy, s * cx + c * cy
        x[r] += centre0[r, 0]
        y[r] += centre0[r, 1]
        off[r, 0] -= cx
        off[r, 1] -= cy
        bound[r] += math.sqrt(off[r, 0] * off[r, 0] + off[r, 1] * off[r, 1])
    for q in range(n, owner.size):
        r = owner[q]
        if conv[r]:
            off[q, 0] -= off[r, 2]
            off[q, 1] -= off[r, 3]
    return off, bound, centre0


@kernel
def _anchors_from_centres(jint, jf, off, conv):
    """A copy of the joints' parameters with the anchors on the ``conv`` rows measured from their
    centres of mass (a world anchor, row -1, stays)."""
    jf = jf.copy()
    for j in range(jint.shape[0]):
        a, b = jint[j, 1], jint[j, 2]
        if a >= 0 and conv[a]:
            jf[j, 0] -= off[a, 2]
            jf[j, 1] -= off[a, 3]
        if b >= 0 and conv[b]:
            jf[j, 2] -= off[b, 2]
            jf[j, 3] -= off[b, 3]
    return jf


@leaf
def _from_centres(x, y, rot, off, conv, x_origin, y_origin, x0, y0, centre0):
    """Move the ``conv`` rows back from their centres of mass to their origins: the origin at the
    step's start plus the centre's motion since, less the centre's turn since (``R(rot) c`` now less
    at the start), so a body that did not move is back on its origin's very bits."""
    for r in range(x.size):
        if not conv[r]:
            continue
        cx, cy = off[r, 2], off[r, 3]
        c, s = math.cos(rot[r]), math.sin(rot[r])
        ex, ey = c * cx - s * cy, s * cx + c * cy
        x[r] = x_origin[r] + ((x[r] - x0[r]) - (ex - centre0[r, 0]))
        y[r] = y_origin[r] + ((y[r] - y0[r]) - (ey - centre0[r, 1]))


@leaf
def _push(px, py, ma, ia, mb, ib, ax, ay, bx, by, vax, vay, wa, vbx, vby, wb, turning):
    """The velocities of A and B after the impulse ``(px, py)`` at their anchors (B takes it, A
    its opposite); ``turning``: the angular parts too."""
    vax -= ma * px
    vay -= ma * py
    vbx += mb * px
    vby += mb * py
    if turning:
        wa -= ia * (ax * py - ay * px)
        wb += ib * (bx * py - by * px)
    return vax, vay, wa, vbx, vby, wb


@leaf
def _warm_start(nc, ci, cf, cp, pairs, vx, vy, w, im, ii):
    """Apply each point's accumulated impulses (Box2D's ``b2WarmStartContacts``)."""
    for c in range(nc):
        a, b = ci[c, 2], ci[c, 3]
        nx, ny = cf[c, 0], cf[c, 1]
        tx, ty = ny, -nx
        vax, vay, wa, vbx, vby, wb = vx[a], vy[a], w[a], vx[b], vy[b], w[b]
        for j in range(ci[c, 1]):
            Px = cp[c, j, _PNI] * nx + cp[c, j, _PTI] * tx
            Py = cp[c, j, _PNI] * ny + cp[c, j, _PTI] * ty
            cp[c, j, _TOTAL] += cp[c, j, _PNI]
            vax, vay, wa, vbx, vby, wb = _push(Px, Py, im[a], ii[a], im[b], ii[b], cp[c, j, _RAX], cp[c, j, _RAY],
                                               cp[c, j, _RBX], cp[c, j, _RBY], vax, vay, wa, vbx, vby, wb, True)
        vx[a], vy[a], w[a], vx[b], vy[b], w[b] = vax, vay, wa, vbx, vby, wb


@leaf
def _solve(nc, ci, cf, cp, pairs, x, y, x0, y0, qc, qs, vx, vy, w, im, ii, use_bias, rotation, softness,
           inv_h, push):
    """One pass over the contacts (Box2D's ``b2SolveContact``): the normal impulses with soft
    constraints (``use_bias``) or rigid ones without bias (the relax), then friction."""
    for c in range(nc):
        k = ci[c, 1]
        a, b = ci[c, 2], ci[c, 3]
        mA, iA, mB, iB = im[a], ii[a], im[b], ii[b]
        vax, vay, wa = vx[a], vy[a], w[a]
        vbx, vby, wb = vx[b], vy[b], w[b]
        dpx = (x[b] - x0[b]) - (x[a] - x0[a])
        dpy = (y[b] - y0[b]) - (y[a] - y0[a])
        nx, ny = cf[c, 0], cf[c, 1]
        sc = int(cf[c, 4])
        bias_rate, mass_scale, imp_scale = softness[sc, 0], softness[sc, 1], softness[sc, 2]
        for j in range(k):
            ax_, ay_, bx_, by_ = cp[c, j, _RAX], cp[c, j, _RAY], cp[c, j, _RBX], cp[c, j, _RBY]
            if rotation:  # the anchors turned by each body's rotation since the step began
                pax, pay = qc[a] * ax_ - qs[a] * ay_, qs[a] * ax_ + qc[a] * ay_
                pbx, pby = qc[b] * bx_ - qs[b] * by_, qs[b] * bx_ + qc[b] * by_
                s = cp[c, j, _BASE] + (dpx + pbx - pax) * nx + (dpy + pby - pay) * ny
                vn = (vbx - wb * by_ - vax + wa * ay_) * nx + (vby + wb * bx_ - vay - wa * ax_) * ny
            else:
                s = cp[c, j, _BASE] + (dpx + bx_ - ax_) * nx + (dpy + by_ - ay_) * ny
                vn = (vbx - vax) * nx + (vby - vay) * ny
            vbias, ms, isc = 0.0, 1.0, 0.0
            if s > 0.0:
                vbias = s * inv_h  # speculative: close the gap, no further
            elif use_bias:
                vbias = max(bias_rate * s, -push)
                ms, isc = mass_scale, imp_scale
            old = cp[c, j, _PNI]
            new = max(old - cp[c, j, _NMASS] * (ms * vn + vbias) - isc * old, 0.0)
            imp = new - old
            cp[c, j, _PNI] = new
            cp[c, j, _TOTAL] += imp
            if new > cp[c, j, _PEAK]:  # (the largest impulse a solve left: did the bodies meet?)
                cp[c, j, _PEAK] = new
            vax, vay, wa, vbx, vby, wb = _push(imp * nx, imp * ny, mA, iA, mB, iB, ax_, ay_, bx_, by_,
                                               vax, vay, wa, vbx, vby, wb, rotation)
        f = cf[c, 2]
        if f > 0.0:
            tx, ty = ny, -nx
            for j in range(k):
                ax_, ay_, bx_, by_ = cp[c, j, _RAX], cp[c, j, _RAY], cp[c, j, _RBX], cp[c, j, _RBY]
                if rotation:
                    vt = (vbx - wb * by_ - vax + wa * ay_) * tx + (vby + wb * bx_ - vay - wa * ax_) * ty
                else:
                    vt = (vbx - vax) * tx + (vby - vay) * ty
                old = cp[c, j, _PTI]
                lim = f * cp[c, j, _PNI]
                new = min(max(old - cp[c, j, _TMASS] * vt, -lim), lim)
                imp = new - old
                cp[c, j, _PTI] = new
                vax, vay, wa, vbx, vby, wb = _push(imp * tx, imp * ty, mA, iA, mB, iB, ax_, ay_, bx_, by_,
                                                   vax, vay, wa, vbx, vby, wb, rotation)
        if mA > 0.0 or iA > 0.0:
            vx[a], vy[a], w[a] = vax, vay, wa
        if mB > 0.0 or iB > 0.0:
            vx[b], vy[b], w[b] = vbx, vby, wb


@leaf
def _restitution(nc, ci, cf, cp, pairs, vx, vy, w, im, ii, threshold):
    """Bounce the points that approached faster than ``threshold`` and took an impulse (Box2D's
    ``b2ApplyRestitution``): the relative normal velocity becomes ``-e`` times the approach."""
    for c in range(nc):
        e = cf[c, 3]
        if e == 0.0:
            continue
        a, b = ci[c, 2], ci[c, 3]
        nx, ny = cf[c, 0], cf[c, 1]
        vax, vay, wa, vbx, vby, wb = vx[a], vy[a], w[a], vx[b], vy[b], w[b]
        for j in range(ci[c, 1]):
            if cp[c, j, _RELV] > -threshold or cp[c, j, _TOTAL] == 0.0:
                continue
            ax_, ay_, bx_, by_ = cp[c, j, _RAX], cp[c, j, _RAY], cp[c, j, _RBX], cp[c, j, _RBY]
            vn = (vbx - wb * by_ - vax + wa * ay_) * nx + (vby + wb * bx_ - vay - wa * ax_) * ny
            old = cp[c, j, _PNI]
            new = max(old - cp[c, j, _NMASS] * (vn + e * cp[c, j, _RELV]), 0.0)
            imp = new - old
            cp[c, j, _PNI] = new
            vax, vay, wa, vbx, vby, wb = _push(imp * nx, imp * ny, im[a], ii[a], im[b], ii[b], ax_, ay_, bx_, by_,
                                               vax, vay, wa, vbx, vby, wb, True)
        vx[a], vy[a], w[a], vx[b], vy[b], w[b] = vax, vay, wa, vbx, vby, wb
