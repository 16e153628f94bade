"""Narrow phase: run the batch kernels on candidate pairs, grouped by shape-pair kind.

Pairs arrive as rows ``(ra, rb)`` of the store; results come back in the same order with the
normal pointing from ``ra``'s body toward ``rb``'s. Layers and masks are applied before any
geometry is computed.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..arrays import BoolArray, I64Array, IntpArray, distinct
from ..collision import batch
from ..collision.batch_box import aabb_pairs_fast
from ..collision.chain import chain_rule, deepest_below
from ..collision.circle_rows import (
    circle_pairs,
    circle_pairs_settled,
    polygon_circle_pairs,
    polygon_circle_pairs_settled,
)
from ..collision.kinds import (
    BOXES,
    CAPSULES,
    CIRCLES,
    KIND_AABB,
    KIND_CAPSULE,
    KIND_CIRCLE,
    KIND_POLYGON,
    KIND_SEGMENT,
    KINDS,
    PAIRS,
    POLYGON_CIRCLE,
    POLYGONS,
    pair_code,
)
from ..collision.measure_rows import measure_rows
from ..collision.pair_classes import FAMILY_OF_CODE, classify_pairs
from ..collision.polygon_rows import polygon_pairs, polygon_pairs_settled
from ..events import PairTracker, StepContacts
from ..frame import StepFrame
from ..geometry import Geometry
from ..store import STATIC, BodyStore
from .movement import integrate_rows
from .sleeping_contacts import kept_contacts
from .stage import Stage

__all__ = ["NarrowPhase", "filter_layers", "pair_contacts"]

# The shape-pair table as columns indexed by pair code: counter name, kernel family, flipped.
_PAIR_NAME = [rule.name for rule in PAIRS.values()]
_PAIR_FAMILY = FAMILY_OF_CODE
_PAIR_FLIP = np.array([rule.flip for rule in PAIRS.values()])
_N_KINDS = np.int64(len(KINDS))
_BOXES_ALONE = frozenset({KIND_AABB})
_FAMILIES = (BOXES, CIRCLES, POLYGON_CIRCLE, POLYGONS, CAPSULES)


def filter_layers(store: BodyStore, ra: IntpArray, rb: IntpArray) -> BoolArray:
    """Mask of the pairs whose layers and masks let them meet."""
    if store.layers_all_meet():
        return np.ones(ra.size, dtype=bool)
    layer, mask = store.layer, store.mask
    return ((layer[ra] & mask[rb]) != 0) & ((layer[rb] & mask[ra]) != 0)


def pair_contacts(
    store: BodyStore, geom: Geometry, ra: IntpArray, rb: IntpArray, counts: dict[str, int] | None = None,
    *, remeasure: bool = False,
) -> batch.ContactArrays:
    """Contacts of B (rows ``rb``) against A (rows ``ra``), in input order.

    ``remeasure``: the response measuring pairs it has just pushed apart; pairs then count
    overlaps within rounding of touching as none, and box and polygon pairs skip their points.
    A pair with a chain segment keeps what the chain's rules allow (:func:`chain_contacts`)."""
    res = _pair_contacts(store, geom, ra, rb, counts, remeasure=remeasure)
    if geom.chains:
        res = chain_contacts(store, geom, ra, rb, res)
    return res


def chain_contacts(store: BodyStore, geom: Geometry, ra: IntpArray, rb: IntpArray,
                   res: batch.ContactArrays) -> batch.ContactArrays:
    """The contacts ``res`` of pairs ``(ra, rb)``, those with a chain segment passed through
    :func:`framework.collision.chain.chain_rule` (one-sided; ghost vertices at the joints)."""
    ca, cb = geom.is_chain[ra], geom.is_chain[rb]
    m = np.flatnonzero(res.hit & (ca | cb))
    if m.size == 0:
        return res
    first = ca[m]
    seg, oth = np.where(first, ra[m], rb[m]), np.where(first, rb[m], ra[m])
    sign = np.where(first, 1.0, -1.0)  # the kernel's normal from A toward B, times this: from the segment
    hx, hy, cos, sin = geom.hx, geom.hy, geom.cos, geom.sin
    ends = geom.world_poly[geom.poly_slot[seg]]
    p1x, p1y = hx[seg] + ends[:, 0, 0], hy[seg] + ends[:, 0, 1]
    p2x, p2y = hx[seg] + ends[:, 1, 0], hy[seg] + ends[:, 1, 1]
    gl = geom.ghosts[seg]
    c, s = cos[seg][:, None], sin[seg][:, None]
    gx = hx[seg][:, None] + c * gl[:, :, 0] - s * gl[:, :, 1]
    gy = hy[seg][:, None] + s * gl[:, :, 0] + c * gl[:, :, 1]
    # The other body: its core (outline, centre or a capsule's ends) and radius, and its centre.
    kind = store.kind[oth]
    k = max(geom.K, 2)
    vx, vy = np.zeros((m.size, k)), np.zeros((m.size, k))
    count = np.ones(m.size, dtype=np.int64)
    outl = np.flatnonzero((kind == KIND_AABB) | (kind == KIND_POLYGON) | (kind == KIND_SEGMENT))
    if outl.size:
        v, n = geom.outlines(store, oth[outl])
        vx[outl, : v.shape[1]] = v[:, :, 0]
        vy[outl, : v.shape[1]] = v[:, :, 1]
        count[outl] = n
    caps = np.flatnonzero(kind == KIND_CAPSULE)
    if caps.size:
        ux, uy = geom.cap_ux[oth[caps]], geom.cap_uy[oth[caps]]
        vx[caps, 0], vy[caps, 0], vx[caps, 1], vy[caps, 1] = -ux, -uy, ux, uy
        count[caps] = 2
    vx += hx[oth][:, None]
    vy += hy[oth][:, None]
    radius = np.where((kind == KIND_CIRCLE) | (kind == KIND_CAPSULE), store.radius[oth], 0.0)
    cx, cy = hx[oth], hy[oth]  # (its centre for the one-sided test: its hitbox origin)
    ex, ey = p2x - p1x, p2y - p1y
    ln = np.hypot(ex, ey)
    low, sx, sy = deepest_below(vx, vy, count, radius, p1x, p1y, ey / ln, -ex / ln)
    keep, nx, ny, depth, px, py = chain_rule(p1x, p1y, p2x, p2y, gx[:, 0], gy[:, 0], gx[:, 1], gy[:, 1], cx, cy,
                                             sign * res.nx[m], sign * res.ny[m], res.depth[m], res.px[m],
                                             res.py[m], low, sx, sy)
    hit = res.hit.copy()
    onx, ony, odepth, opx, opy = res.nx.copy(), res.ny.copy(), res.depth.copy(), res.px.copy(), res.py.copy()
    hit[m] = keep
    onx[m], ony[m] = np.where(keep, sign * nx, 0.0), np.where(keep, sign * ny, 0.0)
    odepth[m], opx[m], opy[m] = np.where(keep, depth, 0.0), np.where(keep, px, 0.0), np.where(keep, py, 0.0)
    return batch.ContactArrays(hit, onx, ony, odepth, opx, opy)


def _pair_contacts(
    store: BodyStore, geom: Geometry, ra: IntpArray, rb: IntpArray, counts: dict[str, int] | None = None,
    *, remeasure: bool = False,
) -> batch.ContactArrays:
    """:func:`pair_contacts` of two-sided shapes (a chain segment is its segment here)."""
    P = ra.size
    if P == 0:
        return batch.ContactArrays(np.zeros(0, dtype=bool), *(np.zeros(0) for _ in range(5)))
    if remeasure and counts is None and store.kinds_present() != _BOXES_ALONE:
        # (the solve's re-measures: every family in one compiled call; boxes alone are one lean
        # kernel call already)
        res = _measured_at_once(store, geom, ra, rb)
        if res is not None:
            return res
    return _by_families(store, geom, ra, rb, counts, remeasure)


def _measured_at_once(store: BodyStore, geom: Geometry, ra: IntpArray, rb: IntpArray) -> batch.ContactArrays | None:
    """The pairs ``(ra, rb)`` of boxes, polygons and circles measured again (``remeasure``) in one
    compiled call (:func:`~framework.collision.measure_rows.measure_rows`, the families' own
    kernels), the rows those leave to their numpy or settling variants answered as
    :func:`_by_families` answers them (a row's answer does not depend on its batch); None where a
    pair has another shape (a capsule) or a row no hitbox."""
    a, b = np.ascontiguousarray(ra, dtype=np.int64), np.ascontiguousarray(rb, dtype=np.int64)
    floats, flags, ok = measure_rows(a, b, store.kind, _N_KINDS, _PAIR_FAMILY, _PAIR_FLIP, geom.hx, geom.hy, store.hw,
                                     store.hh, store.radius, geom.world_poly, geom.poly_slot, geom.count, geom.K,
                                     False, False)
    if not ok:
        return None
    hit, left = flags
    nx, ny, depth, px, py = floats
    if left.any():
        d = np.flatnonzero(left)
        hit[d], nx[d], ny[d], depth[d], px[d], py[d] = _by_families(store, geom, a[d], b[d], None, True)
    return batch.ContactArrays(hit, nx, ny, depth, px, py)


def _by_families(store: BodyStore, geom: Geometry, ra: IntpArray, rb: IntpArray, counts: dict[str, int] | None,
                 remeasure: bool) -> batch.ContactArrays:
    """:func:`_pair_contacts` family by family: one kernel call per family of pairs present."""
    P = ra.size
    kinds = store.kinds_present()
    if len(kinds) == 1 and not kinds & {KIND_POLYGON, KIND_CAPSULE, KIND_SEGMENT}:  # boxes alone, or circles alone
        k = next(iter(kinds))
        rule = PAIRS[k, k]
        if counts is not None:
            counts[rule.name] = counts.get(rule.name, 0) + P
        fams, family = [rule.family], None
    else:
        # One kernel call per family of pairs, not per ordered pair of kinds: a box is a polygon
        # to the polygon kernels, and a circle may be either shape of a polygon-circle pair (the
        # kernel flips the normal per row). Per-call overhead dominates the response's small batches.
        # (The codes, their counts and the families: one compiled pass, classify_pairs.)
        code, n_of, present = classify_pairs(store.kind, ra, rb)
        if present >= 0:
            fams = [f for f in _FAMILIES if present >> f & 1]
            family = _PAIR_FAMILY[code] if len(fams) > 1 else None
        else:  # (a row without a hitbox: numpy's arithmetic, as before, says what happens)
            code = pair_code(store.kind[ra].astype(np.int64), store.kind[rb].astype(np.int64))
            n_of = np.bincount(code, minlength=len(PAIRS)) if counts is not None else n_of
            family = _PAIR_FAMILY[code]
            fams = [int(family[0])] if (family == family[0]).all() else distinct(family).tolist()
            family = family if len(fams) > 1 else None
        if counts is not None:
            for c, k in enumerate(n_of.tolist()):
                if k:
                    name = _PAIR_NAME[c]
                    counts[name] = counts.get(name, 0) + k
    hx, hy = geom.hx, geom.hy
    if len(fams) > 1:
        hit = np.zeros(P, dtype=bool)
        nx, ny, depth, px, py = (np.zeros(P) for _ in range(5))
    for f in fams:
        idx = np.flatnonzero(family == f) if family is not None else None
        a, b = (ra[idx], rb[idx]) if idx is not None else (ra, rb)
        if f == BOXES:  # (the rows' columns read in the compiled pass)
            res = aabb_pairs_fast(a, b, hx, hy, store.cols["hw"], store.cols["hh"], exact=not remeasure,
                                  points=not remeasure)
        elif f == CIRCLES:
            res = _circle_pairs(store, geom, a, b, exact=not remeasure)
        elif f == POLYGON_CIRCLE:
            flip = _PAIR_FLIP[code if idx is None else code[idx]]  # the circle is A: normals from it
            poly, circ = np.where(flip, b, a), np.where(flip, a, b)
            res = _polygon_circle_pairs(store, geom, poly, circ, flip, exact=not remeasure)
        elif f == CAPSULES:
            res = _capsule_pairs(store, geom, a, b, code if idx is None else code[idx], remeasure)
        else:
            res = _polygon_pairs(store, geom, a, b, exact=not remeasure, points=not remeasure)
        if idx is None:  # one family: the kernel's rows are the pairs
            return res
        hit[idx], nx[idx], ny[idx], depth[idx], px[idx], py[idx] = res
    return batch.ContactArrays(hit, nx, ny, depth, px, py)


def _with_deferred(cols: tuple[Any, ...], settle: Callable[[IntpArray], tuple[Any, ...]],
                   answer: Callable[[IntpArray], batch.ContactArrays]) -> batch.ContactArrays:
    """A compiled row pass's contact columns: its rows marked ``pending`` (touching to rounding,
    where contacts must be exact) answered by ``settle(rows)``, the pass's settling variant (whose
    exact functions compile only when a scene first has such a row), then its rows marked ``defer``
    by ``answer(rows)``, the numpy kernel (a row's answer does not depend on its batch)."""
    (nx, ny, depth, px, py), (hit, defer, pending) = cols
    if pending.any():
        p = np.flatnonzero(pending)
        (nx[p], ny[p], depth[p], px[p], py[p]), (hit[p], defer[p], _) = settle(p)
    if defer.any():
        d = np.flatnonzero(defer)
        hit[d], nx[d], ny[d], depth[d], px[d], py[d] = answer(d)
    return batch.ContactArrays(hit, nx, ny, depth, px, py)


def _polygon_pairs(store: BodyStore, geom: Geometry, a: IntpArray, b: IntpArray, *, exact: bool,
                   points: bool) -> batch.ContactArrays:
    """:func:`~framework.collision.batch.polygon_polygon` of pairs of box and polygon rows: the
    compiled pass over the rows (:mod:`~framework.collision.polygon_rows`), and the numpy kernel on
    the outlines of the rare rows that pass leaves to it (inputs beyond the range where the exact
    decisions on floats hold, a contact beyond float64's range)."""
    a, b = np.ascontiguousarray(a, dtype=np.int64), np.ascontiguousarray(b, dtype=np.int64)
    hx, hy = geom.hx, geom.hy

    def numpy(d: IntpArray) -> batch.ContactArrays:
        (va, na), (vb, nb) = geom.outlines(store, a[d]), geom.outlines(store, b[d])
        return batch.polygon_polygon(hx[a[d]], hy[a[d]], va, na, hx[b[d]], hy[b[d]], vb, nb, exact=exact,
                                     points=points)

    def rows(kernel: Callable[..., tuple[Any, ...]], a: IntpArray, b: IntpArray) -> tuple[Any, ...]:
        return kernel(a, b, hx, hy, store.kind, store.hw, store.hh, geom.world_poly, geom.poly_slot, geom.count,
                      geom.K, exact, points)

    return _with_deferred(rows(polygon_pairs, a, b), lambda p: rows(polygon_pairs_settled, a[p], b[p]), numpy)


def _circle_pairs(store: BodyStore, geom: Geometry, a: IntpArray, b: IntpArray, *, exact: bool,
                  ) -> batch.ContactArrays:
    """:func:`~framework.collision.batch.circle_circle` of pairs of circle rows: the compiled pass
    (:func:`~framework.collision.circle_rows.circle_pairs`), and the numpy kernel on the rare rows
    it leaves to it (the same reasons)."""
    a, b = np.ascontiguousarray(a, dtype=np.int64), np.ascontiguousarray(b, dtype=np.int64)
    hx, hy, radius = geom.hx, geom.hy, store.radius

    def numpy(d: IntpArray) -> batch.ContactArrays:
        return batch.circle_circle(hx[a[d]], hy[a[d]], radius[a[d]], hx[b[d]], hy[b[d]], radius[b[d]], exact=exact)

    return _with_deferred(circle_pairs(a, b, hx, hy, radius, exact),
                          lambda p: circle_pairs_settled(a[p], b[p], hx, hy, radius, exact), numpy)


def _polygon_circle_pairs(store: BodyStore, geom: Geometry, poly: IntpArray, circ: IntpArray, flip: BoolArray, *,
                          exact: bool) -> batch.ContactArrays:
    """:func:`~framework.collision.batch.polygon_circle` of pairs of polygon (box, segment) and
    circle rows: the compiled pass over the rows (:mod:`~framework.collision.circle_rows`), and
    the numpy kernel on the outlines of the rare rows it leaves to it (the same reasons)."""
    poly, circ = np.ascontiguousarray(poly, dtype=np.int64), np.ascontiguousarray(circ, dtype=np.int64)
    flip = np.ascontiguousarray(flip, dtype=np.bool_)
    hx, hy, radius = geom.hx, geom.hy, store.radius

    def numpy(d: IntpArray) -> batch.ContactArrays:
        vp, np_ = geom.outlines(store, poly[d])
        return batch.polygon_circle(hx[poly[d]], hy[poly[d]], vp, np_, hx[circ[d]], hy[circ[d]], radius[circ[d]],
                                    flip=flip[d], exact=exact)

    def rows(kernel: Callable[..., tuple[Any, ...]], poly: IntpArray, circ: IntpArray, flip: BoolArray,
             ) -> tuple[Any, ...]:
        return kernel(poly, circ, flip, hx, hy, store.kind, store.hw, store.hh, radius, geom.world_poly,
                      geom.poly_slot, geom.count, geom.K, exact)

    return _with_deferred(rows(polygon_circle_pairs, poly, circ, flip),
                          lambda p: rows(polygon_circle_pairs_settled, poly[p], circ[p], flip[p]), numpy)


def _capsule_pairs(store: BodyStore, geom: Geometry, a: IntpArray, b: IntpArray, code: IntpArray,
                   remeasure: bool) -> batch.ContactArrays:
    """:func:`~framework.collision.capsule.capsule_many` of pairs with a capsule: the capsule
    first (the pair rule's flip; of two capsules, the one placed first, as ``collide``), the other
    shape as its core (a circle's centre, a capsule's ends, a box's or polygon's outline)."""
    kind = store.kind
    flip = _PAIR_FLIP[code].copy()
    two = np.flatnonzero((kind[a] == KIND_CAPSULE) & (kind[b] == KIND_CAPSULE))
    if two.size:
        hx, hy, rot, radius, half = geom.hx, geom.hy, store.rot, store.radius, geom.cap_half
        ka = [v[a[two]] for v in (hx, hy, rot, radius, half)]
        kb = [v[b[two]] for v in (hx, hy, rot, radius, half)]
        # A's key (x, y, rotation, radius, length) after B's, lexicographically: B is placed first
        later = np.zeros(two.size, dtype=bool)
        tied = np.ones(two.size, dtype=bool)
        for va, vb in zip(ka, kb, strict=True):
            later |= tied & (va > vb)
            tied &= va == vb
        flip[two] = later
    cap, oth = np.where(flip, b, a), np.where(flip, a, b)
    ko = kind[oth]
    k = max(geom.K, 2)
    verts = np.zeros((oth.size, k, 2))
    counts = np.ones(oth.size, dtype=np.int64)
    outl = np.flatnonzero((ko == KIND_AABB) | (ko == KIND_POLYGON) | (ko == KIND_SEGMENT))
    if outl.size:
        v, n = geom.outlines(store, oth[outl])
        verts[outl, : v.shape[1]] = v
        counts[outl] = n
    caps = np.flatnonzero(ko == KIND_CAPSULE)
    if caps.size:
        ux, uy = geom.cap_ux[oth[caps]], geom.cap_uy[oth[caps]]
        verts[caps, 0, 0], verts[caps, 0, 1] = -ux, -uy
        verts[caps, 1:, 0], verts[caps, 1:, 1] = ux[:, None], uy[:, None]
        counts[caps] = 2
    radius = np.where((ko == KIND_CIRCLE) | (ko == KIND_CAPSULE), store.radius[oth], 0.0)
    return batch.capsule_many(geom.hx[cap], geom.hy[cap], geom.cap_ux[cap], geom.cap_uy[cap], store.radius[cap],
                              store.bound[cap], geom.hx[oth], geom.hy[oth], verts, counts, radius, store.bound[oth],
                              flip, exact=not remeasure)


class NarrowPhase(Stage):
    """Measure the candidate pairs; fill ``frame.contacts`` (entities a < b, normal from a to b),
    ``frame.contact_rows`` and, through the pair tracker, ``frame.started`` and ``frame.ended``.

    Pairs of sleeping (or sleeping and static) bodies are not measured: they keep last step's
    contact, so their events stay ``ongoing`` while they sleep. A touch by an awake solid body wakes
    a sleeper, which then catches up on the step it slept through (see :meth:`_catch_up_woken`)."""

    name = "narrow_phase"
    needs = frozenset({"detection"})
    solver = "exact"

    def __init__(self, pipeline) -> None:
        super().__init__(pipeline)
        self.tracker = PairTracker()

    def run(self, frame: StepFrame) -> bool:
        bodies = self.bodies
        store, geom = bodies.store, bodies.geometry
        ea, eb, ra, rb = frame.pairs
        if geom.version != store.version:
            # A system changed hitboxes after the broad phase: measure the pairs as they are now.
            live = (store.kind[ra] >= 0) & (store.kind[rb] >= 0)
            ea, eb, ra, rb = ea[live], eb[live], ra[live], rb[live]
            geom.update(store)
        if ra.size == 0:  # (no candidates: nothing to measure)
            h, contacts, rows = ra, StepContacts.empty(), (ra, rb)
        else:
            res = pair_contacts(store, geom, ra, rb, frame.counters["narrow_tests"])
            h = np.flatnonzero(res.hit)
            contacts = StepContacts(ea[h], eb[h], res.nx[h], res.ny[h], res.depth[h], res.px[h], res.py[h])
            rows = (ra[h], rb[h])
        if frame.n_asleep:
            contacts, rows = self._keep_sleepers(frame, contacts, rows)
        frame.contacts, frame.contact_rows = contacts, rows
        frame.started, _ongoing, frame.ended = self.tracker.update(contacts)
        frame._events = None
        frame.counters["contacts"] = int(contacts.a.size)
        frame.counters["events"] = int(h.size + frame.ended.a.size)
        return True

    def _keep_sleepers(
        self, frame: StepFrame, contacts: StepContacts, rows: tuple[I64Array, I64Array],
    ) -> tuple[StepContacts, tuple[I64Array, I64Array]]:
        """Add last step's contacts between idle bodies (asleep or static); wake sleepers touched by
        an awake solid body, and bring them up to date."""
        store = self.bodies.store
        prev = self.tracker.active
        # (one compiled pass, sleeping_contacts.kept_contacts: the contacts kept, merged by pair,
        # and the sleepers to wake)
        merged, ints, floats, woken = kept_contacts(*contacts, *rows, *prev, store.row_table(), store.asleep,
                                                   store.body, store.sensor, STATIC)
        if merged:
            contacts = StepContacts(ints[0], ints[1], *floats)
            rows = (ints[2], ints[3])
        if woken.size:
            store.wake(woken)
            contacts, rows = self._catch_up_woken(woken, frame.dt, contacts, rows)
        return contacts, rows

    def _catch_up_woken(
        self, woken: I64Array, dt: float, contacts: StepContacts,
        rows: tuple[I64Array, I64Array],
    ) -> tuple[StepContacts, tuple[I64Array, I64Array]]:
        """Bodies woken by a touch in this narrow phase slept through the movement stage: move them
        now as it would have (a body resting on the floor sinks into it by gravity's step, as an
        awake one does, and the response pushes it out), then measure their contacts again: those
        kept from last step are as the narrow phase found them before that step's response moved
        the body. A contact now apart is dropped. So a woken body's contacts are real ones, and a
        resting body bumped awake keeps its floor contact (``ongoing``) rather than ending it."""
        store, geom = self.bodies.store, self.bodies.geometry
        if "movement" in self.pipeline.effects:
            integrate_rows(store, woken, dt, self.pipeline.active_gravity())
            geom.update_rows(store, woken)
        flag = np.zeros(store.n, dtype=bool)
        flag[woken] = True
        stale = np.flatnonzero(flag[rows[0]] | flag[rows[1]])
        if stale.size == 0:
            return contacts, rows
        r = pair_contacts(store, geom, rows[0][stale], rows[1][stale])
        cols = [c.copy() for c in contacts]
        for col, new in zip(cols[2:], (r.nx, r.ny, r.depth, r.px, r.py)):
            col[stale] = new
        keep = np.ones(contacts.a.size, dtype=bool)
        keep[stale[~r.hit]] = False
        return StepContacts._make(c[keep] for c in cols), (rows[0][keep], rows[1][keep])
