"""``math.hypot`` as CPython computes it, compiled: :func:`hypot`.

The scalar Python code measures lengths with ``math.hypot``, which CPython 3.11 computes itself
(``vector_norm`` in ``Modules/mathmodule.c``: scaled, exact squares, a compensated sum and one
correction step); the C library's ``hypot``, which numba's ``math.hypot`` calls, differs from it
in the last bit for about one input in 500. Compiled code that must give the Python code's bits
(the batch queries, the character move, the exact polygon / circle contact) measures with this one.
"""

from __future__ import annotations

import math

from ..compiled import inner, kernel

__all__ = ["hypot"]


@inner
def _split(x):  # pragma: no cover - compiled
    t = x * 134217729.0  # Veltkamp: 2**27 + 1
    hi = t - (t - x)
    return hi, x - hi


@inner
def _mul(x, y):  # pragma: no cover - compiled
    """Dekker's exact product ``x * y == z + zz``."""
    xh, xl = _split(x)
    yh, yl = _split(y)
    p = xh * yh
    q = xh * yl + xl * yh
    z = p + q
    zz = p - z + q + xl * yl
    return z, zz


@inner
def _norm(x, y, m):  # pragma: no cover - compiled
    """CPython's ``vector_norm`` of ``(x, y)`` (both >= 0, ``m`` the larger, normal)."""
    e = math.frexp(m)[1]
    scale = math.ldexp(1.0, -e)
    csum, frac1, frac2 = 1.0, 0.0, 0.0
    for v in (x, y):
        v *= scale
        hi, lo = _mul(v, v)
        s = csum + hi
        frac2 += hi - (s - csum)
        csum = s
        frac1 += lo
    h = math.sqrt(csum - 1.0 + (frac1 + frac2))
    hi, lo = _mul(-h, h)
    s = csum + hi
    frac2 += hi - (s - csum)
    csum = s
    frac1 += lo
    v = csum - 1.0 + (frac1 + frac2)
    h += v / (2.0 * h)
    return h / scale


@kernel
def hypot(x, y):  # pragma: no cover - compiled
    """``math.hypot(x, y)`` as CPython 3.11 computes it (the same bits, subnormals included)."""
    x, y = abs(x), abs(y)
    if math.isinf(x) or math.isinf(y):
        return math.inf
    m = x if x > y else y
    if math.isnan(x) or math.isnan(y):
        return math.nan
    if m == 0.0:
        return m
    if math.frexp(m)[1] < -1023:  # subnormal: 2**-e would overflow; divided by the largest instead
        csum, frac = 1.0, 0.0
        for v in (x, y):
            v /= m
            v = v * v
            old = csum
            csum += v
            frac += (old - csum) + v
        return m * math.sqrt(csum - 1.0 + frac)
    return _norm(x, y, m)
