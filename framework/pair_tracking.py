"""Which of a step's overlapping pairs are new and which of last step's are gone: the pair
tracker's (:class:`~framework.events.PairTracker`) merge of two sorted lists of pair keys, in one
compiled pass (numpy took a dozen calls a step: the keys, a stable sort of both lists, the twins).
"""

from __future__ import annotations

import numpy as np

from .compiled import kernel, leaf
from .stable_sort import argsort_ints

__all__ = ["track_pairs"]


@leaf
def _increasing(keys):  # pragma: no cover - compiled
    for i in range(1, keys.size):
        if not keys[i - 1] < keys[i]:
            return False
    return True


@kernel
def track_pairs(a, b, last):  # pragma: no cover - compiled
    """``(keys, was, gone)``: this step's pair keys (``a << 32 | b``, as
    :func:`~framework.events.pair_keys`), whether each was among ``last`` (last step's keys), and
    the places in ``last`` of the keys no longer there, ascending. Sorted distinct keys (the
    pipeline's) are merged in one walk; others are sorted first (stably, both lists together: a
    key in both sits next to its twin, the one from this step first)."""
    n, m = a.size, last.size
    keys = np.empty(n, dtype=np.int64)
    for i in range(n):
        keys[i] = (np.int64(a[i]) << 32) | np.int64(b[i])
    was = np.zeros(n, dtype=np.bool_)
    kept = np.zeros(m, dtype=np.bool_)
    if _increasing(keys) and _increasing(last):
        i = j = 0
        while i < n and j < m:
            if keys[i] < last[j]:
                i += 1
            elif last[j] < keys[i]:
                j += 1
            else:
                was[i] = kept[j] = True
                i += 1
                j += 1
    elif n and m:
        merged = np.empty(n + m, dtype=np.int64)
        for i in range(n):
            merged[i] = keys[i]
        for j in range(m):
            merged[n + j] = last[j]
        order = argsort_ints(merged)  # (stable; the project's sort: no second sort to compile)
        for t in range(n + m - 1):
            if merged[order[t + 1]] == merged[order[t]]:
                if order[t] < n:
                    was[order[t]] = True
                if order[t + 1] >= n:
                    kept[order[t + 1] - n] = True
    return keys, was, np.flatnonzero(~kept)
