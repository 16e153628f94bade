"""``math.hypot`` as CPython computes it, compiled: :func:`hypot`.

The scalar Python code measures lengths with ``math.hypot``, which CPython 3.11 computes itself
(its ``vector_norm``: exact squares, a compensated sum and one correction); the C library's
``hypot``, which numba's ``math.hypot`` calls, differs from it in the last bit for about one pair
in 500. Compiled code that must give the Python code's bits (the character move, the exact
polygon / circle contact) measures with this one.
"""

from __future__ import annotations

import math

from numba import njit

from ..compiled import inner

__all__ = ["hypot"]


@inner
def _two_product(x, y):  # pragma: no cover - compiled
    """``x * y`` exactly, as ``(hi, lo)`` (Dekker's product by Veltkamp's split)."""
    t = x * 134217729.0
    xh = t - (t - x)
    xl = x - xh
    t = y * 134217729.0
    yh = t - (t - y)
    yl = y - yh
    p = xh * yh
    q = xh * yl + xl * yh
    z = p + q
    return z, p - z + q + xl * yl


@inner
def _norm(a, b, top):  # pragma: no cover - compiled
    """CPython's ``vector_norm`` of ``(a, b)`` (both >= 0, ``top`` the larger, normal)."""
    scale = math.ldexp(1.0, -math.frexp(top)[1])
    csum, frac1, frac2 = 1.0, 0.0, 0.0
    for k in range(2):
        x = (a if k == 0 else b) * scale
        hi, lo = _two_product(x, x)
        s = csum + hi
        frac2 += (csum - s) + hi
        csum = s
        frac1 += lo
    h = math.sqrt(csum - 1.0 + (frac1 + frac2))
    hi, lo = _two_product(-h, h)
    s = csum + hi
    frac2 += (csum - s) + hi
    csum = s
    frac1 += lo
    x = csum - 1.0 + (frac1 + frac2)
    h += x / (2.0 * h)
    return h / scale


@njit(cache=True)
def hypot(a, b):  # pragma: no cover - compiled
    """``math.hypot(a, b)`` as CPython 3.11 computes it (``vector_norm``: exact squares, a
    compensated sum and one correction), which the C library's ``hypot`` numba calls is not: they
    differ in the last bit for about one pair in 500."""
    a, b = abs(a), abs(b)
    if math.isinf(a) or math.isinf(b):
        return math.inf
    if math.isnan(a) or math.isnan(b):
        return math.nan
    top = b if b > a else a
    if top == 0.0:
        return top
    if math.frexp(top)[1] < -1023:  # (deep below the normals: scaled up first, as CPython does)
        tiny = 2.2250738585072014e-308
        return tiny * _norm(a / tiny, b / tiny, top / tiny)
    return _norm(a, b, top)
