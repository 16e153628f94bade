"""Compiled sorts: :func:`stable_argsort`, shared by the exact solve's rounds, the broad phase's
direct pairs and the soft step's kernel; :func:`sorted_ints`, integer keys made of a few sorted runs
(the solve's known pair keys).

Natural merge sorts: ``np.argsort(key, kind="stable")``'s answer (a stable sort's order is the
only one), for floats (NaN last, as numpy) and integers alike, at a tenth of the compile time of
numba's own ``argsort(kind="mergesort")``.
"""

from __future__ import annotations

import numpy as np

from .compiled import kernel, leaf

__all__ = ["sorted_ints", "stable_argsort"]


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


@kernel
def sorted_ints(keys):  # pragma: no cover - compiled
    """The integers ``keys`` in ascending order (``np.sort(keys)``; integers: any sort's answer), by
    a natural merge sort: the runs already in order are found first and merged pairwise, so keys made
    of a few sorted runs (contacts listed by kind, then candidates) cost a pass per doubling of runs,
    and keys in order cost one pass and no copy."""
    n = keys.size
    starts = np.empty(n + 1, dtype=np.int64)  # where each run in order begins, then n
    m = 0
    for i in range(n):
        if i == 0 or keys[i] < keys[i - 1]:
            starts[m] = i
            m += 1
    if m <= 1:
        return keys
    starts[m] = n
    src = keys.copy()
    dst = np.empty(n, dtype=keys.dtype)
    while m > 1:
        half = 0
        for r in range(0, m, 2):
            lo, mid = starts[r], starts[r + 1]
            hi = starts[r + 2] if r + 2 <= m else mid
            i, j, k = lo, mid, lo
            while i < mid and j < hi:
                if src[j] < src[i]:
                    dst[k] = src[j]
                    j += 1
                else:
                    dst[k] = src[i]
                    i += 1
                k += 1
            while i < mid:
                dst[k] = src[i]
                i += 1
                k += 1
            while j < hi:
                dst[k] = src[j]
                j += 1
                k += 1
            starts[half] = lo
            half += 1
        starts[half] = n
        m = half
        src, dst = dst, src
    return src
