"""Pairs of boxes, polygons and circles measured in one compiled call: :func:`measure_rows`.

The narrow phase sorts its pairs into families of kernels (box pairs, circle pairs,
polygon-circle pairs, polygon pairs) and calls one kernel per family, gathering each family's rows
first and scattering its answers after: some fifteen Python calls and their arrays a time. The
exact solve measures its pushed pairs again a dozen times a step, a few dozen pairs each, so that
glue was most of a re-measure (about 30 us a time, the kernels a third of it). Here the pairs are
sorted, each family's kernel called and the answers put in place in one compiled pass, the
kernels being the very ones the narrow phase calls (:func:`~.batch_box._aabb_pairs`,
:func:`~.circle_rows.circle_pairs`, :func:`~.circle_rows.polygon_circle_pairs`,
:func:`~.polygon_rows.polygon_pairs`), so each row's answer is the same bits.
"""

from __future__ import annotations

import numpy as np

from ..compiled import kernel
from .batch_box import _aabb_pairs
from .circle_rows import circle_pairs, polygon_circle_pairs
from .kinds import BOXES, CIRCLES, POLYGON_CIRCLE, POLYGONS
from .polygon_rows import polygon_pairs

__all__ = ["measure_rows"]


@kernel
def measure_rows(ra, rb, kind, n_kinds, family_of_code, flip_of_code, hx, hy, hw, hh, radius, world_poly, poly_slot,
                 count, k, exact, points):  # pragma: no cover - compiled
    """The contacts of the pairs of rows ``(ra[i], rb[i])`` (the narrow phase's columns; pair codes
    ``kind_a * n_kinds + kind_b``, their families and flips as the tables give them), as
    ``(floats, flags, ok)``: the rows of ``floats`` the contact columns ``nx, ny, depth, px, py``,
    of ``flags`` ``hit`` and ``left`` (rows the kernels leave to their numpy or settling variants:
    the caller answers them so); ``ok`` false, and nothing measured, where a pair is of another
    family (a capsule) or a row has no hitbox."""
    n = ra.size
    floats, flags = np.zeros((5, n)), np.zeros((2, n), dtype=np.bool_)
    family = np.empty(n, dtype=np.int64)
    flipped = np.empty(n, dtype=np.bool_)  # (a polygon-circle pair whose circle is A: normals from it)
    sizes = np.zeros(4, dtype=np.int64)
    for i in range(n):
        ka, kb = np.int64(kind[ra[i]]), np.int64(kind[rb[i]])
        if ka < 0 or kb < 0 or ka >= n_kinds or kb >= n_kinds:
            return floats, flags, False
        f = family_of_code[ka * n_kinds + kb]
        if f > POLYGONS:
            return floats, flags, False
        family[i], flipped[i] = f, flip_of_code[ka * n_kinds + kb]
        sizes[f] += 1
    for f in range(4):
        m = sizes[f]
        if m == 0:
            continue
        at, a, b = np.empty(m, dtype=np.int64), np.empty(m, dtype=np.int64), np.empty(m, dtype=np.int64)
        flip = np.zeros(m, dtype=np.bool_)
        j = 0
        for i in range(n):
            if family[i] == f:
                at[j], a[j], b[j] = i, ra[i], rb[i]
                if f == POLYGON_CIRCLE:  # (the polygon first)
                    flip[j] = flipped[i]
                    if flip[j]:
                        a[j], b[j] = rb[i], ra[i]
                j += 1
        if f == BOXES:
            got, cols, _extremes = _aabb_pairs(a, b, hx, hy, hw, hh, exact, points)
            left = np.zeros(m, dtype=np.bool_)  # (extreme rows: the kernel's own answer unless exact)
            if exact:
                left = got[1]
        elif f == CIRCLES:
            cols, got = circle_pairs(a, b, hx, hy, radius, exact)
            left = got[1] | got[2]
        elif f == POLYGON_CIRCLE:
            cols, got = polygon_circle_pairs(a, b, flip, hx, hy, kind, hw, hh, radius, world_poly, poly_slot, count,
                                             k, exact)
            left = got[1] | got[2]
        else:
            cols, got = polygon_pairs(a, b, hx, hy, kind, hw, hh, world_poly, poly_slot, count, k, exact, points)
            left = got[1] | got[2]
        for j in range(m):
            i = at[j]
            flags[0, i], flags[1, i] = got[0, j], left[j]
            for c in range(5):
                floats[c, i] = cols[c, j]
    return floats, flags, True
