"""Which rows' bounds meet a box: the candidates of the scene queries and the character
controller's casts, as compiled loops over the geometry's bound columns.

A query asks for a few dozen rows out of hundreds to thousands; numpy's masks and fancy indexing
cost a few microseconds a call each, and a character's move asks a dozen times a step. One
compiled pass over the columns answers in one call. The spatial hash answers instead where the
rows are too many for a pass (:data:`~framework.collision.broad_phase.DIRECT_QUERY`).
"""

from __future__ import annotations

import numpy as np

from ..compiled import kernel, leaf

__all__ = ["holds", "lower_bound", "rows_meeting", "rows_near", "rows_within"]


@kernel
def rows_meeting(kind, minx, miny, maxx, maxy, x0, y0, x1, y1):  # pragma: no cover - compiled
    """Rows with a hitbox (``kind >= 0``) whose bounds strictly overlap the box ``[x0, x1] x
    [y0, y1]`` (touching does not count), in row order."""
    out = np.empty(kind.size, dtype=np.intp)
    m = 0
    for r in range(kind.size):
        if kind[r] >= 0 and minx[r] < x1 and maxx[r] > x0 and miny[r] < y1 and maxy[r] > y0:
            out[m] = r
            m += 1
    return out[:m]


@leaf
def lower_bound(keys, key):  # pragma: no cover - compiled
    """The first place in the sorted ``keys`` whose key is not below ``key`` (``np.searchsorted``'s
    left side), by binary search."""
    lo, hi = 0, keys.size
    while lo < hi:
        mid = (lo + hi) >> 1
        if keys[mid] < key:
            lo = mid + 1
        else:
            hi = mid
    return lo


@leaf
def holds(keys, key):  # pragma: no cover - compiled
    """Whether the sorted ``keys`` hold ``key`` (the soft step's pair and joint filters use it too)."""
    i = lower_bound(keys, key)
    return i < keys.size and keys[i] == key


@kernel
def rows_within(rows, minx, miny, maxx, maxy, x0, y0, x1, y1, layer, sensor, mask, skip_rows, entity,
                skip_entities):  # pragma: no cover - compiled
    """The ``rows`` whose bounds meet the box (closed) that block a body of ``mask`` (their layer
    meets it, not sensors) and are neither in ``skip_rows`` nor of an entity in ``skip_entities``
    (both sorted), in their order. ``mask < 0``: no layer or sensor test (rows already filtered)."""
    out = np.empty(rows.size, dtype=np.intp)
    m = 0
    for i in range(rows.size):
        r = rows[i]
        if not (minx[r] <= x1 and maxx[r] >= x0 and miny[r] <= y1 and maxy[r] >= y0):
            continue
        if mask >= 0 and ((layer[r] & mask) == 0 or sensor[r]):
            continue
        if skip_rows.size and holds(skip_rows, r):
            continue
        if skip_entities.size and holds(skip_entities, entity[r]):
            continue
        out[m] = r
        m += 1
    return out[:m]


@kernel
def rows_near(kind, minx, miny, maxx, maxy, x0, y0, x1, y1, layer, sensor, mask, skip_rows, entity,
              skip_entities):  # pragma: no cover - compiled
    """:func:`rows_within` of :func:`rows_meeting`'s rows, in one call from Python: the rows with a
    hitbox whose bounds strictly overlap the box that block a body of ``mask`` and are skipped by
    neither list, in row order (the character controller's candidates, where the rows are few
    enough for a pass)."""
    return rows_within(rows_meeting(kind, minx, miny, maxx, maxy, x0, y0, x1, y1), minx, miny, maxx, maxy, x0, y0,
                       x1, y1, layer, sensor, mask, skip_rows, entity, skip_entities)
