"""Input checks shared by shapes, components and queries.

Bad input raises :class:`InvalidValue`, which is both a ``ValueError`` and a ``TypeError``: a
wrong type (``None``, a string) and a wrong value (NaN, a negative size) are the same mistake to a
game maker, and either ``except`` clause catches it. Every message names the bad value.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from numbers import Real

__all__ = ["InvalidValue", "finite", "positive", "vector2"]


class InvalidValue(ValueError, TypeError):
    """A value that the framework refuses: non-finite, out of range or of the wrong type."""


def _as_float(name: str, value: object) -> float:
    if type(value) is float:  # (the common case, without the numbers.Real check's cost)
        return value
    # bool is a Real in Python, but True as a coordinate is a bug, not a number.
    if isinstance(value, bool) or not isinstance(value, Real):
        # numpy scalars are registered as numbers.Real; anything else is refused.
        raise InvalidValue(f"{name} must be a real number, got {value!r}")
    try:
        return float(value)
    except (OverflowError, ValueError):
        # An int or Fraction beyond float64's range (e.g. 10**400): not a finite float.
        raise InvalidValue(f"{name} must be finite (within float64 range), got {value!r}") from None


def finite(name: str, value: object) -> float:
    """``value`` as a float64, or :class:`InvalidValue` if it is not a finite real number."""
    x = _as_float(name, value)
    if not math.isfinite(x):
        raise InvalidValue(f"{name} must be finite, got {value!r}")
    return x


def positive(name: str, value: object) -> float:
    """``value`` as a float64 that is finite and > 0, or :class:`InvalidValue`."""
    x = _as_float(name, value)
    if not (math.isfinite(x) and x > 0.0):
        raise InvalidValue(f"{name} must be finite and > 0, got {value!r}")
    return x


def vector2(name: str, value: object) -> tuple[float, float]:
    """A 2-vector (any sequence or array of two finite reals) as a tuple of float64."""
    try:
        n = len(value)  # type: ignore[arg-type]
    except TypeError:
        raise InvalidValue(f"{name} must be a pair of numbers, got {value!r}") from None
    if n != 2 or isinstance(value, (str, bytes)):
        raise InvalidValue(f"{name} must be a pair of numbers, got {value!r}")
    seq: Sequence[object] = value  # type: ignore[assignment]
    return (finite(f"{name}[0]", seq[0]), finite(f"{name}[1]", seq[1]))
