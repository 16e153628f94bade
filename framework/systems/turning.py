"""Contacts of bodies that turn: manifold points with lever arms.

With the ``rotation`` effect, a dynamic box or polygon (``Hitbox`` of finite inertia, centred on
its entity) turns when contacts push it off its centre. The solve then works on *points*, not
pairs: each pair with such a body becomes the points of its manifold
(:func:`~framework.collision.batch_manifold.pair_manifolds`: two where a face rests on a face,
one at a corner), each with its own separation and its lever arms ``r`` from each body's centre
(its entity's position) to the point. A unit of push or impulse at a point moves a body by its
inverse mass and turns it by its inverse inertia times ``r x n`` (``r x t`` along the contact),
both over the pair's effective inverse mass at that point, ``k = w_a + w_b + i_a (r_a x n)^2 +
i_b (r_b x n)^2``, so that a unit changes the point's separation (speed) by exactly one unit, as
in the translational solve. Pairs with no turning polygon keep one row with their narrow-phase
point (a circle's lever arm along the normal is 0; along the contact, its radius: it rolls).

Capsules never turn (their inverse inertia is 0, as an AABB's): a dynamic capsule is pushed like
an AABB. A pair of a turning polygon and a capsule keeps one row with its narrow-phase point, as a
pair with a circle does, whose lever arm turns the polygon.

Each point's push, impulse and friction's are kept for the next step by pair and slot (the
points are ordered along the contact's tangent), in ``frame.points``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..arrays import F64Array, I64Array, IntpArray
from ..collision.batch_manifold import pair_manifolds
from ..collision.box_rows import lower_bound
from ..collision.kinds import KIND_CAPSULE, KIND_CIRCLE, KIND_POLYGON
from ..compiled import inner, kernel
from ..frame import Points
from ..geometry import Geometry
from ..store import BodyStore
from .gather import _np_min
from .solve_columns import turning_pair

if TYPE_CHECKING:  # (solve imports this module)
    from .solve import Contacts

__all__ = ["expand", "manifold_points", "turned_normals"]


@kernel
def _margins(ra, rb, gap, bound, kind, circle, capsule):  # pragma: no cover - compiled
    """For :func:`manifold_points`: each pair's margin (``gap`` times the smaller body's size, as
    numpy's ``gap * np.minimum``), whether it has a round body (a circle or a capsule: no outline
    to clip), and whether any has."""
    margin = np.empty(ra.size)
    round_ = np.zeros(ra.size, dtype=np.bool_)
    anyone = False
    for i in range(ra.size):
        a, b = ra[i], rb[i]
        margin[i] = gap * _np_min(bound[a], bound[b])
        round_[i] = kind[a] == capsule or kind[b] == capsule or kind[a] == circle or kind[b] == circle
        anyone = anyone or round_[i]
    return margin, round_, anyone


@kernel
def turned_normals(rows, hit, rnx, rny, nx, ny):  # pragma: no cover - compiled
    """For the solve's points measured again: the contacts ``rows`` (normals ``nx[rows], ny[rows]``)
    whose pair, measured again (``hit``, ``rnx``, ``rny``, one per row), overlaps along another
    normal (turned past rounding): ``(normals, turned, any turned)``, the normals (new where turned)
    as the rows of one block."""
    m = rows.size
    normals = np.empty((2, m))
    turned = np.zeros(m, dtype=np.bool_)
    anyone = False
    for k in range(m):
        r = rows[k]
        turned[k] = hit[k] and rnx[k] * nx[r] + rny[k] * ny[r] < 1.0 - 1e-9
        if turned[k]:
            normals[0, k], normals[1, k] = rnx[k], rny[k]
            anyone = True
        else:
            normals[0, k], normals[1, k] = nx[r], ny[r]
    return normals, turned, anyone


def manifold_points(store: BodyStore, geom: Geometry, ra: IntpArray, rb: IntpArray, nx: F64Array, ny: F64Array,
                    gap: float) -> tuple[I64Array, F64Array, F64Array, F64Array]:
    """:func:`pair_manifolds` of the box and polygon pairs ``(ra, rb)`` along ``(nx, ny)``, from
    the step's geometry, keeping the points less than ``gap`` times the smaller body's size
    apart: ``(count, px, py, sep)``."""
    margin, round_, any_round = _margins(ra, rb, gap, store.bound, store.kind, KIND_CIRCLE, KIND_CAPSULE)
    if not any_round:
        return pair_manifolds(ra, rb, nx, ny, margin, store.kind, geom.hx, geom.hy, store.hw, store.hh,
                              geom.poly_slot, geom.world_poly, geom.count)
    # A pair with a circle or a capsule has no outline to clip: its one point is the narrow
    # phase's, where they overlap (none where they do not).
    caps = np.flatnonzero(round_)
    rest = np.flatnonzero(~round_)
    n_pts, px, py, sep = (np.zeros(ra.size, dtype=np.int64), np.zeros((ra.size, 2)), np.zeros((ra.size, 2)),
                          np.zeros((ra.size, 2)))
    if rest.size:
        got = pair_manifolds(ra[rest], rb[rest], nx[rest], ny[rest], margin[rest], store.kind, geom.hx, geom.hy,
                             store.hw, store.hh, geom.poly_slot, geom.world_poly, geom.count)
        n_pts[rest], px[rest], py[rest], sep[rest] = got
    from .narrow_phase import pair_contacts

    r = pair_contacts(store, geom, ra[caps], rb[caps], remeasure=True)
    n_pts[caps] = r.hit
    px[caps, 0], py[caps, 0], sep[caps, 0] = r.px, r.py, -r.depth
    return n_pts, px, py, sep


def expand(cs: Contacts, store: BodyStore, geom: Geometry, points: Points, margin: float) -> Contacts:
    """``cs`` (:class:`~framework.systems.solve.Contacts`) with every pair that has a turning
    polygon replaced by its manifold points (points within ``margin`` times the smaller body's
    size of touching), warm started from last step's ``points`` (``frame.points``), and every
    row's lever arms set (``cs.arms``). One compiled pass (which pairs are clipped, their
    manifolds, the rows, their points, the rims of round bodies, the warm starts and the arms)
    where numpy took some sixty calls: a pair with no manifold point keeps its own row if it
    overlaps; a kept pair with a circle or a capsule gets the point on its rim facing the other
    body; each point is warm started from last step's value of the same pair and slot, or (a pair
    that had another number of points) its pair's, shared evenly."""
    c = store.cols
    ints, floats, alive0 = _expanded(cs.ra, cs.rb, cs.ea, cs.eb, cs.nx, cs.ny, cs.depth, cs.alive0, cs.push0,
                                     cs.impulse0, cs.tpush0, cs.timpulse0, cs.px, cs.py, margin, c["kind"],
                                     c["inv_inertia"], c["bound"], c["x"], c["y"], c["radius"], c["hw"], c["hh"],
                                     geom.hx, geom.hy, geom.cap_ux, geom.cap_uy, geom.poly_slot, geom.world_poly,
                                     geom.count, *points[:6], KIND_POLYGON, KIND_CIRCLE, KIND_CAPSULE)
    ra, rb, ea, eb, slot = ints
    nx, ny, depth, push0, impulse0, tpush0, timpulse0, opx, opy, rax, ray, rbx, rby = floats
    return type(cs)(ra, rb, ea, eb, nx, ny, depth, alive0, push0, impulse0, tpush0, timpulse0, opx, opy, slot,
                    arms=(rax, ray, rbx, rby))


@inner
def _clipped(ra, rb, kind, inv_inertia, bound, margin, polygon, circle, capsule):  # pragma: no cover - compiled
    """The pairs with a turning polygon and no round body (circle or capsule), whose manifolds
    are clipped, and each one's gap: ``margin`` times the smaller body's bound."""
    clip = np.empty(ra.size, dtype=np.int64)
    m = 0
    for i in range(ra.size):
        a, b = ra[i], rb[i]
        turn = turning_pair(a, b, kind, inv_inertia, polygon)
        round_ = kind[a] == circle or kind[b] == circle or kind[a] == capsule or kind[b] == capsule
        if turn and not round_:
            clip[m] = i
            m += 1
    clip = clip[:m]
    gaps = np.empty(m)
    for q in range(m):
        a, b = ra[clip[q]], rb[clip[q]]
        gaps[q] = margin * (bound[b] if bound[b] < bound[a] else bound[a])
    return clip, gaps


@kernel
def _expanded(ra, rb, ea, eb, nx, ny, depth, alive0, push0, impulse0, tpush0, timpulse0, px, py, margin, kind,
              inv_inertia, bound, x, y, radius, hw, hh, hx, hy, cap_ux, cap_uy, poly_slot, world_poly, count, pk, pslot,
              lpush, limp, ltpush, ltimp, polygon, circle, capsule):  # pragma: no cover - compiled
    """The rows of :func:`expand` (see there), as ``(ints, floats, alive0)``: rows ``ra, rb, ea,
    eb, slot`` and ``nx, ny, depth, push0, impulse0, tpush0, timpulse0, px, py`` and the arms
    ``rax, ray, rbx, rby`` (two arrays and a mask: each array handed back to Python costs). The
    clipped pairs' manifolds (:func:`_clipped`, then
    :func:`~framework.collision.batch_manifold.pair_manifolds`) first."""
    clip, gaps = _clipped(ra, rb, kind, inv_inertia, bound, margin, polygon, circle, capsule)
    cra, crb, cnx, cny = np.empty(clip.size, dtype=np.int64), np.empty(clip.size, dtype=np.int64), \
        np.empty(clip.size), np.empty(clip.size)
    for q in range(clip.size):
        cra[q], crb[q], cnx[q], cny[q] = ra[clip[q]], rb[clip[q]], nx[clip[q]], ny[clip[q]]
    n_pts, mpx, mpy, msep = pair_manifolds(cra, crb, cnx, cny, gaps, kind, hx, hy, hw, hh, poly_slot, world_poly,
                                           count)
    C = ra.size
    at = np.full(C, -1, dtype=np.int64)  # each pair's place among the clipped ones
    for q in range(clip.size):
        at[clip[q]] = q
    count = np.ones(C, dtype=np.int64)
    total = 0
    for i in range(C):
        q = at[i]
        if q >= 0:
            count[i] = (1 if alive0[i] else 0) if n_pts[q] == 0 else n_pts[q]
        total += count[i]
    ints = np.empty((5, total), dtype=np.int64)
    floats = np.empty((13, total))
    alive = np.empty(total, dtype=np.bool_)
    o = 0
    for i in range(C):
        q = at[i]
        for s in range(count[i]):
            ints[0, o], ints[1, o], ints[2, o], ints[3, o], ints[4, o] = ra[i], rb[i], ea[i], eb[i], s
            alive[o] = alive0[i]
            floats[0, o], floats[1, o], floats[2, o] = nx[i], ny[i], depth[i]
            floats[3, o], floats[4, o], floats[5, o], floats[6, o] = push0[i], impulse0[i], tpush0[i], timpulse0[i]
            floats[7, o], floats[8, o] = px[i], py[i]
            has = q >= 0 and n_pts[q] > 0
            if has:  # the manifold's point
                floats[7, o], floats[8, o] = mpx[q, s], mpy[q, s]
                floats[2, o] = -msep[q, s]
            elif not alive[o]:  # a kept pair: the point on a round body's rim facing the other one
                a, b = ra[i], rb[i]
                ka, kb = kind[a], kind[b]
                if ka == circle or (ka == capsule and kb != circle):
                    r, sx, sy = a, 1.0 * nx[i], 1.0 * ny[i]
                else:
                    r, sx, sy = b, -1.0 * nx[i], -1.0 * ny[i]
                cx, cy = x[r], y[r]
                if kind[r] == capsule:  # the end of its segment farther along the normal (its middle if square on)
                    ux, uy = cap_ux[r], cap_uy[r]
                    along = np.sign(ux * sx + uy * sy)
                    cx, cy = hx[r] + along * ux, hy[r] + along * uy
                floats[7, o], floats[8, o] = cx + radius[r] * sx, cy + radius[r] * sy
            # the warm start: last step's same pair and slot, else the pair's shared evenly
            key = (ea[i] << 32) | eb[i]
            found = False
            w = 0
            if pk.size:
                w = lower_bound(pk, key) + s
                if w > pk.size - 1:
                    w = pk.size - 1
                found = pk[w] == key and pslot[w] == s
            if found:
                floats[3, o], floats[4, o], floats[5, o], floats[6, o] = lpush[w], limp[w], ltpush[w], ltimp[w]
            else:
                n = count[i]
                floats[3, o], floats[4, o] = floats[3, o] / n, floats[4, o] / n
                floats[5, o], floats[6, o] = floats[5, o] / n, floats[6, o] / n
            a, b = ra[i], rb[i]
            floats[9, o], floats[10, o] = floats[7, o] - x[a], floats[8, o] - y[a]
            floats[11, o], floats[12, o] = floats[7, o] - x[b], floats[8, o] - y[b]
            o += 1
    return ints, floats, alive
