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

from ..arrays import BoolArray, F64Array, I64Array, IntpArray
from ..collision.batch_manifold import pair_manifolds
from ..collision.kinds import KIND_CAPSULE, KIND_CIRCLE, KIND_POLYGON
from ..events import pair_keys
from ..frame import Points
from ..geometry import Geometry
from ..store import BodyStore

if TYPE_CHECKING:  # (solve imports this module)
    from .solve import Contacts

__all__ = ["expand", "manifold_points", "turning_polygons"]


def turning_polygons(store: BodyStore, rows: IntpArray) -> BoolArray:
    """Mask of ``rows`` that are boxes or polygons contacts turn."""
    return (store.kind[rows] == KIND_POLYGON) & (store.inv_inertia[rows] > 0.0)


def manifold_points(store: BodyStore, geom: Geometry, ra: IntpArray, rb: IntpArray, nx: F64Array, ny: F64Array,
                    gap: float) -> tuple[I64Array, F64Array, F64Array, F64Array]:
    """:func:`pair_manifolds` of the box and polygon pairs ``(ra, rb)`` along ``(nx, ny)``, from
    the step's geometry, keeping the points less than ``gap`` times the smaller body's size
    apart: ``(count, px, py, sep)``."""
    margin = gap * np.minimum(store.bound[ra], store.bound[rb])
    round_ = ((store.kind[ra] == KIND_CAPSULE) | (store.kind[rb] == KIND_CAPSULE) | (store.kind[ra] == KIND_CIRCLE)
              | (store.kind[rb] == KIND_CIRCLE))
    caps = np.flatnonzero(round_)
    if caps.size == 0:
        return pair_manifolds(ra, rb, nx, ny, margin, store.kind, geom.hx, geom.hy, store.hw, store.hh,
                              geom.poly_slot, geom.world_poly, geom.count)
    # A pair with a circle or a capsule has no outline to clip: its one point is the narrow
    # phase's, where they overlap (none where they do not).
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
    row's lever arms set (``cs.arms``)."""
    ra, rb = cs.ra, cs.rb
    turn = turning_polygons(store, ra) | turning_polygons(store, rb)
    round_ = ((store.kind[ra] == KIND_CIRCLE) | (store.kind[rb] == KIND_CIRCLE) | (store.kind[ra] == KIND_CAPSULE)
              | (store.kind[rb] == KIND_CAPSULE))
    clip = np.flatnonzero(turn & ~round_)
    n_pts, px, py, sep = manifold_points(store, geom, ra[clip], rb[clip], cs.nx[clip], cs.ny[clip], margin)
    # rows: every pair once (a pair with no manifold point keeps its own row if it overlaps), then
    # each clipped pair's second point
    count = np.ones(cs.size, dtype=np.int64)
    count[clip] = np.where(n_pts == 0, cs.alive0[clip].astype(np.int64), n_pts)
    src = np.repeat(np.arange(cs.size), count)
    slot = np.arange(src.size) - np.repeat(np.cumsum(count) - count, count)
    out = cs.take(src)
    out.slot = slot
    # the clipped pairs' points
    at = np.full(cs.size, -1, dtype=np.int64)
    at[clip] = np.arange(clip.size)
    c = at[src]
    has = c >= 0
    has[has] = n_pts[c[has]] > 0
    k, s = c[has], slot[has]
    out.px[has], out.py[has] = px[k, s], py[k, s]
    out.depth[has] = -sep[k, s]
    # kept pairs with a circle (or a capsule): the point on its rim facing the other body
    rim = ~out.alive0 & ~has
    if rim.any():
        ka, kb = store.kind[out.ra], store.kind[out.rb]
        ca = rim & ((ka == KIND_CIRCLE) | ((ka == KIND_CAPSULE) & (kb != KIND_CIRCLE)))
        cb = rim & ~ca
        for m, rows, sign in ((ca, out.ra, 1.0), (cb, out.rb, -1.0)):
            r = rows[m]
            nx, ny = sign * out.nx[m], sign * out.ny[m]
            cx, cy = store.x[r], store.y[r]
            cap = store.kind[r] == KIND_CAPSULE
            if cap.any():
                # the end of the capsule's segment farther along the normal (its middle if square on)
                ux, uy = geom.cap_ux[r], geom.cap_uy[r]
                along = np.sign(ux * nx + uy * ny)
                cx = np.where(cap, geom.hx[r] + along * ux, cx)
                cy = np.where(cap, geom.hy[r] + along * uy, cy)
            out.px[m] = cx + store.radius[r] * nx
            out.py[m] = cy + store.radius[r] * ny
    _warm_points(out, count[src], points)
    out.arms = (out.px - store.x[out.ra], out.py - store.y[out.ra], out.px - store.x[out.rb], out.py - store.y[out.rb])
    return out


def _warm_points(cs: Contacts, n_points: I64Array, points: Points) -> None:
    """Each point's warm start: last step's values of the same pair and slot, or (a pair that had
    another number of points) its pair's, shared evenly."""
    keys = pair_keys(cs.ea, cs.eb)
    pk, pslot, *values = points[:6]
    found = np.zeros(cs.size, dtype=bool)
    if pk.size:  # (sorted by pair, then slot: a pair's slots follow each other)
        at = np.minimum(np.searchsorted(pk, keys) + cs.slot, pk.size - 1)
        found = (pk[at] == keys) & (pslot[at] == cs.slot)
    split = ~found
    columns = (cs.push0, cs.impulse0, cs.tpush0, cs.timpulse0)
    for col, last in zip(columns, values):
        if found.any():
            col[found] = last[at[found]]
        col[split] = col[split] / n_points[split]
