"""Small numpy helpers shared by the per-step stages."""

from __future__ import annotations

import numpy as np

__all__ = ["distinct"]


def distinct(values: np.ndarray) -> np.ndarray:
    """The sorted distinct values of an integer array: ``np.unique(values)`` by one sort.

    numpy 2's ``np.unique`` takes a hash-table path for integers that costs about seven times a
    sort on the few thousand row numbers a step handles (measured with numpy 2.4)."""
    s = np.sort(values, axis=None)
    if s.size < 2:
        return s
    keep = np.empty(s.size, dtype=bool)
    keep[0] = True
    np.not_equal(s[1:], s[:-1], out=keep[1:])
    return s[keep]
