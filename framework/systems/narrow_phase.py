"""Narrow phase: run the batch kernels on candidate pairs, grouped by shape-pair kind.

Pairs arrive as rows ``(ra, rb)`` of the store; results come back in the same order with the
normal pointing from ``ra``'s body toward ``rb``'s. Layers and masks are applied before any
geometry is computed.
"""

from __future__ import annotations

import numpy as np

from ..arrays import distinct
from ..collision import batch
from ..collision.kinds import BOXES, CIRCLES, KIND_POLYGON, PAIRS, POLYGON_CIRCLE, pair_code
from ..store import BodyStore
from .geometry import Geometry

__all__ = ["filter_layers", "pair_contacts"]

# The shape-pair table as columns indexed by pair code: counter name, kernel family, flipped.
_PAIR_NAME = [rule.name for rule in PAIRS.values()]
_PAIR_FAMILY = np.array([rule.family for rule in PAIRS.values()], dtype=np.int64)
_PAIR_FLIP = np.array([rule.flip for rule in PAIRS.values()])


def filter_layers(store: BodyStore, ra: np.ndarray, rb: np.ndarray) -> np.ndarray:
    """Mask of the pairs whose layers and masks let them meet."""
    if store.layers_all_meet():
        return np.ones(ra.size, dtype=bool)
    layer, mask = store.layer, store.mask
    return ((layer[ra] & mask[rb]) != 0) & ((layer[rb] & mask[ra]) != 0)


def pair_contacts(
    store: BodyStore, geom: Geometry, ra: np.ndarray, rb: np.ndarray, counts: dict[str, int] | None = None,
    *, remeasure: bool = False,
) -> batch.ContactArrays:
    """Contacts of B (rows ``rb``) against A (rows ``ra``), in input order.

    ``remeasure``: the response measuring pairs it has just pushed apart; pairs then count
    overlaps within rounding of touching as none, and box and polygon pairs skip their points."""
    P = ra.size
    if P == 0:
        return batch.ContactArrays(np.zeros(0, dtype=bool), *(np.zeros(0) for _ in range(5)))
    kinds = store.kinds_present()
    if len(kinds) == 1 and KIND_POLYGON not in kinds:  # boxes alone, or circles alone: one family
        k = next(iter(kinds))
        rule = PAIRS[k, k]
        if counts is not None:
            counts[rule.name] = counts.get(rule.name, 0) + P
        fams = [rule.family]
    else:
        code = pair_code(store.kind[ra].astype(np.int64), store.kind[rb].astype(np.int64))
        if counts is not None:
            n_of = np.bincount(code, minlength=len(PAIRS))
            for c in np.flatnonzero(n_of).tolist():
                name = _PAIR_NAME[c]
                counts[name] = counts.get(name, 0) + int(n_of[c])
        # One kernel call per family of pairs, not per ordered pair of kinds: a box is a polygon
        # to the polygon kernels, and a circle may be either shape of a polygon-circle pair (the
        # kernel flips the normal per row). Per-call overhead dominates the response's small batches.
        family = _PAIR_FAMILY[code]
        fams = [int(family[0])] if (family == family[0]).all() else distinct(family).tolist()
    hx, hy = geom.hx, geom.hy
    if len(fams) > 1:
        hit = np.zeros(P, dtype=bool)
        nx, ny, depth, px, py = (np.zeros(P) for _ in range(5))
    for f in fams:
        idx = np.flatnonzero(family == f) if len(fams) > 1 else None
        a, b = (ra[idx], rb[idx]) if idx is not None else (ra, rb)
        if f == BOXES:
            res = batch.aabb_aabb_fast(
                hx[a], hy[a], store.hw[a], store.hh[a], hx[b], hy[b], store.hw[b], store.hh[b],
                exact=not remeasure, points=not remeasure,
            )
        elif f == CIRCLES:
            res = batch.circle_circle(hx[a], hy[a], store.radius[a], hx[b], hy[b], store.radius[b],
                                       exact=not remeasure)
        elif f == POLYGON_CIRCLE:
            flip = _PAIR_FLIP[code if idx is None else code[idx]]  # the circle is A: normals from it
            poly, circ = np.where(flip, b, a), np.where(flip, a, b)
            vp, np_ = geom.outlines(store, poly)
            res = batch.polygon_circle(hx[poly], hy[poly], vp, np_, hx[circ], hy[circ], store.radius[circ],
                                      flip=flip, exact=not remeasure)
        else:
            va, na = geom.outlines(store, a)
            vb, nb = geom.outlines(store, b)
            res = batch.polygon_polygon(hx[a], hy[a], va, na, hx[b], hy[b], vb, nb,
                                        exact=not remeasure, points=not remeasure)
        if idx is None:  # one family: the kernel's rows are the pairs
            return res
        hit[idx], nx[idx], ny[idx], depth[idx], px[idx], py[idx] = res
    return batch.ContactArrays(hit, nx, ny, depth, px, py)
