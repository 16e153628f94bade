"""Narrow phase: run the batch kernels on candidate pairs, grouped by shape-pair kind.

Pairs arrive as rows ``(ra, rb)`` of the store; results come back in the same order with the
normal pointing from ``ra``'s body toward ``rb``'s. Layers and masks are applied before any
geometry is computed.
"""

from __future__ import annotations

import numpy as np

from ..arrays import distinct
from ..collision import batch
from ..store import KIND_AABB, KIND_CIRCLE, KIND_POLYGON, BodyStore
from .geometry import Geometry

__all__ = ["filter_layers", "pair_contacts", "KIND_PAIR_NAMES"]

KIND_PAIR_NAMES = {
    (0, 0): "aabb-aabb", (0, 1): "aabb-circle", (0, 2): "aabb-polygon",
    (1, 0): "circle-aabb", (1, 1): "circle-circle", (1, 2): "circle-polygon",
    (2, 0): "polygon-aabb", (2, 1): "polygon-circle", (2, 2): "polygon-polygon",
}


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
        if counts is not None:
            name = KIND_PAIR_NAMES[(k, k)]
            counts[name] = counts.get(name, 0) + P
        fams, ca = [0 if k == KIND_AABB else 1], None
    else:
        ka = store.kind[ra].astype(np.int64)
        kb = store.kind[rb].astype(np.int64)
        if counts is not None:
            n_of = np.bincount(ka * 3 + kb, minlength=9)
            for c in np.flatnonzero(n_of).tolist():
                name = KIND_PAIR_NAMES[divmod(c, 3)]
                counts[name] = counts.get(name, 0) + int(n_of[c])
        # One kernel call per family of pairs, not per ordered pair of kinds: a box is a polygon
        # to the polygon kernels, and a circle may be either shape of a polygon-circle pair (the
        # kernel flips the normal per row). Per-call overhead dominates the response's small batches.
        ca, cb = ka == KIND_CIRCLE, kb == KIND_CIRCLE
        family = np.where(ca & cb, 1, np.where(ca | cb, 2, np.where((ka == KIND_AABB) & (kb == KIND_AABB), 0, 3)))
        fams = [int(family[0])] if (family == family[0]).all() else distinct(family).tolist()
    hx, hy = geom.hx, geom.hy
    if len(fams) > 1:
        hit = np.zeros(P, dtype=bool)
        nx, ny, depth, px, py = (np.zeros(P) for _ in range(5))
    for f in fams:
        idx = np.flatnonzero(family == f) if len(fams) > 1 else None
        a, b = (ra[idx], rb[idx]) if idx is not None else (ra, rb)
        if f == 0:
            res = batch.aabb_aabb_fast(
                hx[a], hy[a], store.hw[a], store.hh[a], hx[b], hy[b], store.hw[b], store.hh[b],
                exact=not remeasure, points=not remeasure,
            )
        elif f == 1:
            res = batch.circle_circle(hx[a], hy[a], store.radius[a], hx[b], hy[b], store.radius[b],
                                       exact=not remeasure)
        elif f == 2:
            flip = ca if idx is None else ca[idx]  # the circle is shape A: normals from it to the polygon
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
