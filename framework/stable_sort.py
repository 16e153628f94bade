"""Compiled sorts: :func:`stable_argsort`, shared by the exact solve's rounds, the broad phase's
direct pairs and the soft step's kernel; for integer keys, :func:`argsort_ints` (pair keys: a few
sorted runs are merged, others sorted by radix).

Natural merge sorts: ``np.argsort(key, kind="stable")``'s answer (a stable sort's order is the
only one), for floats (NaN last, as numpy) and integers alike, at a tenth of the compile time of
numba's own ``argsort(kind="mergesort")``.
"""

from __future__ import annotations

import numpy as np

from .compiled import kernel, leaf

__all__ = ["argsort_ints", "stable_argsort"]


@leaf
def _before(x, y):  # pragma: no cover - compiled
    """Whether ``x`` sorts strictly before ``y`` (NaN last, as numpy)."""
    return x < y or (y != y and x == x)


@kernel
def stable_argsort(key):  # pragma: no cover - compiled
    """``np.argsort(key, kind="stable")`` of a float or integer array: a natural merge sort (the runs
    already in order are found first, then merged pairwise; ties keep their order, NaN sorts last).
    Keys made of a few sorted runs (pairs listed by kind, each kind in order) cost a pass per
    doubling of runs."""
    n = key.size
    idx = np.arange(n)
    starts = np.empty(n + 1, dtype=np.int64)  # where each run in order begins, then n
    m = 0
    for i in range(n):
        if i == 0 or _before(key[i], key[i - 1]):
            starts[m] = i
            m += 1
    starts[m] = n
    tmp = np.empty(n, dtype=np.int64)
    while m > 1:
        half = 0
        for r in range(0, m, 2):
            lo, mid = starts[r], starts[r + 1]
            hi = starts[r + 2] if r + 2 <= m else mid
            i, j, k = lo, mid, lo
            while i < mid and j < hi:
                if _before(key[idx[j]], key[idx[i]]):
                    tmp[k] = idx[j]
                    j += 1
                else:
                    tmp[k] = idx[i]
                    i += 1
                k += 1
            while i < mid:
                tmp[k] = idx[i]
                i += 1
                k += 1
            while j < hi:
                tmp[k] = idx[j]
                j += 1
                k += 1
            starts[half] = lo
            half += 1
        starts[half] = n
        m = half
        idx, tmp = tmp, idx
    return idx


#: :func:`argsort_ints` merges the runs in order where there are at most this many, else sorts by
#: radix (a pass over the keys per byte in which they differ: pair keys of a scene's entity ids,
#: four or so, where merging single keys took a pass per doubling).
MERGE_RUNS = 8


@kernel
def argsort_ints(keys):  # pragma: no cover - compiled
    """``np.argsort(keys, kind="stable")`` of integers (int64): :func:`stable_argsort`'s natural
    merge where the keys are at most :data:`MERGE_RUNS` runs in order, else a least-significant-byte-
    first radix sort carrying each key's place (stable by construction; a pass per byte in which
    the keys differ). Merging single keys of random order read them out of order, a pass per
    doubling: 4,000 pair keys 345 us by merging, about a fifth of that by radix."""
    n = keys.size
    runs = 0
    for i in range(n):
        if i == 0 or keys[i] < keys[i - 1]:
            runs += 1
            if runs > MERGE_RUNS:
                return _radix_argsort(keys)
    return stable_argsort(keys)


@kernel
def _radix_argsort(keys):  # pragma: no cover - compiled
    """:func:`argsort_ints` by a least-significant-byte-first radix sort: a counting pass and a
    placing pass per byte in which the keys differ (the top byte's sign bit flipped, so that
    negative keys come first), the keys and their places moved together."""
    n = keys.size
    differ = np.int64(0)
    for i in range(n):
        differ |= keys[i] ^ keys[0]
    src_k, dst_k = keys.copy(), np.empty(n, dtype=np.int64)
    src_i, dst_i = np.arange(n), np.empty(n, dtype=np.int64)
    count = np.empty(256, dtype=np.int64)
    for shift in range(0, 64, 8):
        if (differ >> shift) & 0xFF == 0:
            continue
        flip = 0x80 if shift == 56 else 0
        for d in range(256):
            count[d] = 0
        for i in range(n):
            count[((src_k[i] >> shift) & 0xFF) ^ flip] += 1
        total = 0
        for d in range(256):
            c = count[d]
            count[d] = total
            total += c
        for i in range(n):
            d = ((src_k[i] >> shift) & 0xFF) ^ flip
            dst_k[count[d]], dst_i[count[d]] = src_k[i], src_i[i]
            count[d] += 1
        src_k, dst_k = dst_k, src_k
        src_i, dst_i = dst_i, src_i
    return src_i
