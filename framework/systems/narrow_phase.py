"""Narrow phase: run the batch kernels on candidate pairs, grouped by shape-pair kind.

Pairs arrive as rows ``(ra, rb)`` of the store; results come back in the same order with the
normal pointing from ``ra``'s body toward ``rb``'s. Layers and masks are applied before any
geometry is computed.
"""

from __future__ import annotations

import numpy as np

from ..collision import batch
from ..store import KIND_AABB, KIND_CIRCLE, BodyStore
from .geometry import Geometry

__all__ = ["filter_layers", "pair_contacts", "KIND_PAIR_NAMES"]

KIND_PAIR_NAMES = {
    (0, 0): "aabb-aabb", (0, 1): "aabb-circle", (0, 2): "aabb-polygon",
    (1, 0): "circle-aabb", (1, 1): "circle-circle", (1, 2): "circle-polygon",
    (2, 0): "polygon-aabb", (2, 1): "polygon-circle", (2, 2): "polygon-polygon",
}


def filter_layers(store: BodyStore, ra: np.ndarray, rb: np.ndarray) -> np.ndarray:
    """Mask of the pairs whose layers and masks let them meet."""
    layer, mask = store.layer, store.mask
    return ((layer[ra] & mask[rb]) != 0) & ((layer[rb] & mask[ra]) != 0)


def pair_contacts(
    store: BodyStore, geom: Geometry, ra: np.ndarray, rb: np.ndarray, counts: dict[str, int] | None = None,
    *, remeasure: bool = False,
) -> batch.ContactArrays:
    """Contacts of B (rows ``rb``) against A (rows ``ra``), in input order.

    ``remeasure``: the response measuring pairs it has just pushed apart; box pairs then skip
    their points and count overlaps within rounding of touching as none."""
    P = ra.size
    hit = np.zeros(P, dtype=bool)
    nx, ny, depth, px, py = (np.zeros(P) for _ in range(5))
    if P == 0:
        return batch.ContactArrays(hit, nx, ny, depth, px, py)
    ka = store.kind[ra].astype(np.int64)
    kb = store.kind[rb].astype(np.int64)
    code = ka * 3 + kb
    hx, hy = geom.hx, geom.hy
    kinds = [int(code[0])] if (code == code[0]).all() else np.unique(code).tolist()
    for c in kinds:
        idx = np.flatnonzero(code == c) if len(kinds) > 1 else np.arange(P)
        a, b = ra[idx], rb[idx]
        kind_a, kind_b = divmod(c, 3)
        if counts is not None:
            name = KIND_PAIR_NAMES[(kind_a, kind_b)]
            counts[name] = counts.get(name, 0) + idx.size
        if kind_a == KIND_AABB and kind_b == KIND_AABB:
            res = batch.aabb_aabb_fast(
                hx[a], hy[a], store.hw[a], store.hh[a], hx[b], hy[b], store.hw[b], store.hh[b],
                exact=not remeasure, points=not remeasure,
            )
        elif kind_a == KIND_CIRCLE and kind_b == KIND_CIRCLE:
            res = batch.circle_circle(hx[a], hy[a], store.radius[a], hx[b], hy[b], store.radius[b])
        elif kind_b == KIND_CIRCLE:
            va, na = geom.outlines(store, a)
            res = batch.polygon_circle(hx[a], hy[a], va, na, hx[b], hy[b], store.radius[b])
        elif kind_a == KIND_CIRCLE:
            vb, nb = geom.outlines(store, b)
            res = batch.polygon_circle(hx[b], hy[b], vb, nb, hx[a], hy[a], store.radius[a], flip=True)
        else:
            va, na = geom.outlines(store, a)
            vb, nb = geom.outlines(store, b)
            res = batch.polygon_polygon(hx[a], hy[a], va, na, hx[b], hy[b], vb, nb)
        hit[idx], nx[idx], ny[idx], depth[idx], px[idx], py[idx] = res
    return batch.ContactArrays(hit, nx, ny, depth, px, py)
