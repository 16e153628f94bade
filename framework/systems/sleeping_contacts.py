"""The narrow phase's contacts between idle bodies, kept while they sleep, in one compiled pass.

Pairs of sleeping (or sleeping and static) bodies are not measured: they keep last step's contact,
so their events stay ``ongoing`` while they sleep. :func:`kept_contacts` merges those contacts into
the step's measured ones, sorted by pair, and names the sleepers an awake solid body touches (the
narrow phase wakes them). It is the numpy it replaced (about twenty calls a step, most of the
narrow phase of a scene at rest) element by element: the merge is a stable sort by pair key, as
``np.lexsort((b, a))`` was, for entity ids below 2**31.
"""

from __future__ import annotations

import numpy as np

from ..compiled import kernel
from ..stable_sort import argsort_ints
from .solve_rounds import _where

__all__ = ["kept_contacts"]


@kernel
def kept_contacts(ca, cb, cnx, cny, cdepth, cpx, cpy, cra, crb, pa, pb, pnx, pny, pdepth, ppx, ppy, lut, asleep, body,
                  sensor, static):  # pragma: no cover - compiled
    """This step's contacts (``c*``: entities, normal, depth, point, rows) with last step's (``p*``)
    whose bodies are both idle (asleep or ``static``; rows looked up in ``lut``, entity -> row),
    sorted by pair (this step's first among equals): ``(merged, ints, floats, woken)``, ``merged``
    False where none was kept (then the step's contacts stand as they are and ``ints``, ``floats``
    are empty); ``ints``: rows of entities a, b and rows a, b; ``floats``: rows of nx, ny, depth,
    px, py; ``woken``: the sorted rows of the sleepers touched by an awake solid body that is not
    static."""
    m, k = ca.size, pa.size
    ra_p, rb_p = np.empty(k, dtype=np.int64), np.empty(k, dtype=np.int64)
    frozen = np.zeros(k, dtype=np.bool_)
    n_frozen = 0
    for j in range(k):
        p = lut[pa[j]] if pa[j] < lut.size else -1
        q = lut[pb[j]] if pb[j] < lut.size else -1
        ra_p[j], rb_p[j] = p, q
        if p >= 0 and q >= 0 and (asleep[p] or body[p] == static) and (asleep[q] or body[q] == static):
            frozen[j] = True
            n_frozen += 1
    total = m + n_frozen
    ints = np.empty((4, total if n_frozen else 0), dtype=np.int64)
    floats = np.empty((5, total if n_frozen else 0))
    if n_frozen:
        keys = np.empty(total, dtype=np.int64)
        src = np.empty(total, dtype=np.int64)  # a step's contact i, or -1 - j for last step's j
        for i in range(m):
            keys[i], src[i] = (np.int64(ca[i]) << 32) | np.int64(cb[i]), i
        t = m
        for j in range(k):
            if frozen[j]:
                keys[t], src[t] = (np.int64(pa[j]) << 32) | np.int64(pb[j]), -1 - j
                t += 1
        order = argsort_ints(keys)
        for o in range(total):
            s = src[order[o]]
            if s >= 0:
                ints[0, o], ints[1, o], ints[2, o], ints[3, o] = ca[s], cb[s], cra[s], crb[s]
                floats[0, o], floats[1, o], floats[2, o] = cnx[s], cny[s], cdepth[s]
                floats[3, o], floats[4, o] = cpx[s], cpy[s]
            else:
                j = -1 - s
                ints[0, o], ints[1, o], ints[2, o], ints[3, o] = pa[j], pb[j], ra_p[j], rb_p[j]
                floats[0, o], floats[1, o], floats[2, o] = pnx[j], pny[j], pdepth[j]
                floats[3, o], floats[4, o] = ppx[j], ppy[j]
    # the sleepers an awake solid body that is not static touches
    wake = np.zeros(asleep.size, dtype=np.bool_)
    for o in range(total):
        a = ints[2, o] if n_frozen else cra[o]
        b = ints[3, o] if n_frozen else crb[o]
        if sensor[a] or sensor[b]:
            continue
        if asleep[a] and not asleep[b] and body[b] != static:  # (a woken by b)
            wake[a] = True
        if asleep[b] and not asleep[a] and body[a] != static:
            wake[b] = True
    return n_frozen > 0, ints, floats, _where(wake)
