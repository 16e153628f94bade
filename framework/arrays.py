"""Small numpy helpers shared by the per-step stages."""

from __future__ import annotations

from typing import TypeAlias, TypeVar

import numpy as np
from numpy.typing import NDArray

__all__ = ["BoolArray", "F64Array", "I64Array", "IntpArray", "distinct"]

_T = TypeVar("_T", bound=np.generic)

# Shorthands for the stages' annotations (numpy.typing): a column of floats, of row numbers (what
# ``np.flatnonzero`` and ``argsort`` give), of int64 (entity ids, pair keys, the store's rows) and a mask.
F64Array: TypeAlias = NDArray[np.float64]
IntpArray: TypeAlias = NDArray[np.intp]
I64Array: TypeAlias = NDArray[np.int64]
BoolArray: TypeAlias = NDArray[np.bool_]


def distinct(values: NDArray[_T]) -> NDArray[_T]:
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
