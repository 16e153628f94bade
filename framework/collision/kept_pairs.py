"""Candidate pairs kept between steps, from fat bounds: :class:`KeptPairs`.

Every step the broad phase wants the pairs of hitboxes whose bounds strictly overlap, each with a
moving body in it. Where bodies barely move (a pile at rest, a stack) those pairs hardly change,
yet hashing a thousand movers afresh cost some 600 us a step. So, as Box2D keeps its proxies in
fat boxes, each mover is given fat bounds (its bounds grown by an eighth of its larger side) and
the pairs whose fat bounds overlap are found by the spatial hash once. A step then only checks
that every mover is still inside its fat bounds and keeps the candidates whose bounds overlap now
(compiled passes): a pair whose bounds overlap has fat bounds that overlap, so no pair is
missed, and the answer is the hash's pairs in the hash's order (sorted by entity pair). A mover
leaving its fat bounds, or any change to the rows, the statics or who sleeps, builds the
candidates again.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..compiled import kernel
from .grid import Bounds

__all__ = ["KeptPairs"]

#: A mover's fat bounds: its bounds grown on every side by this fraction of its larger side.
MARGIN = 0.125


@kernel
def _grown(moving, minx, miny, maxx, maxy, margin):  # pragma: no cover - compiled
    """The movers' fat bounds: each side moved out by ``margin`` times the larger side."""
    k = moving.size
    fx0, fy0, fx1, fy1 = np.empty(k), np.empty(k), np.empty(k), np.empty(k)
    for q in range(k):
        r = moving[q]
        w, h = maxx[r] - minx[r], maxy[r] - miny[r]
        m = margin * (w if w > h else h)
        fx0[q], fy0[q], fx1[q], fy1[q] = minx[r] - m, miny[r] - m, maxx[r] + m, maxy[r] + m
    return fx0, fy0, fx1, fy1


@kernel
def _inside(moving, minx, miny, maxx, maxy, fx0, fy0, fx1, fy1):  # pragma: no cover - compiled
    """Whether every mover's bounds lie within its fat bounds (``f*[k]``: mover ``k``'s)."""
    for k in range(moving.size):
        r = moving[k]
        if not (minx[r] >= fx0[k] and miny[r] >= fy0[k] and maxx[r] <= fx1[k] and maxy[r] <= fy1[k]):
            return False
    return True


@kernel
def _overlapping(ra, rb, minx, miny, maxx, maxy):  # pragma: no cover - compiled
    """Which candidates' bounds strictly overlap now."""
    keep = np.empty(ra.size, dtype=np.bool_)
    for k in range(ra.size):
        i, j = ra[k], rb[k]
        keep[k] = maxx[i] > minx[j] and maxx[j] > minx[i] and maxy[i] > miny[j] and maxy[j] > miny[i]
    return keep


class KeptPairs:
    """The broad phase's candidate pairs, kept while the rows, statics and sleepers stay as they
    were and every mover stays inside its fat bounds.

    Where bodies keep leaving their fat bounds (every body moving its own size a step), building
    the candidates each step costs more than hashing the bounds: after two builds in a row the
    stage hashes plainly for :data:`REST` steps before trying again."""

    #: steps of plain hashing after two builds in a row
    REST = 30

    def __init__(self) -> None:
        self._key: tuple[int, ...] | None = None
        self._moving = np.zeros(0, dtype=np.int64)
        self._keys = np.zeros(0, dtype=np.int64)
        self._ra = np.zeros(0, dtype=np.int64)
        self._rb = np.zeros(0, dtype=np.int64)
        self._fat: Bounds = (np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0))
        self._built_last = False  # the last step built the candidates
        self._plain = 0  # steps left of plain hashing
        #: how many times the candidates were built (for tests and the perf report)
        self.builds = 0

    def choose(self, key: tuple[int, ...], moving: NDArray[np.int64], bounds: Bounds,
               ) -> str:
        """This step's way: ``"kept"`` (the candidates hold: ``key``, the rows, statics and sleepers
        they were built for, unchanged, the same movers, each inside its fat bounds), ``"build"``
        (build them again) or ``"plain"`` (hash the bounds: see the class notes)."""
        if self._plain > 0:
            self._plain -= 1
            return "plain"
        minx, miny, maxx, maxy = bounds
        fx0, fy0, fx1, fy1 = self._fat
        if (key == self._key and moving.size == self._moving.size and bool((moving == self._moving).all())
                and _inside(moving, minx, miny, maxx, maxy, fx0, fy0, fx1, fy1)):
            self._built_last = False
            return "kept"
        self._key = None
        if self._built_last:  # two builds in a row: hash plainly for a while, then try again
            self._built_last = False
            self._plain = self.REST - 1
            return "plain"
        return "build"

    def fat(self, moving: NDArray[np.int64], bounds: Bounds,
            ) -> Bounds:
        """The movers' fat bounds (in the order of ``moving``), to build the candidates from."""
        minx, miny, maxx, maxy = bounds
        fx0, fy0, fx1, fy1 = _grown(moving, minx, miny, maxx, maxy, MARGIN)
        return fx0, fy0, fx1, fy1

    def keep(self, key: tuple[int, ...], moving: NDArray[np.int64], fat: Bounds,
             keys: NDArray[np.int64], ra: NDArray[np.int64], rb: NDArray[np.int64]) -> None:
        """Keep the candidates built from ``fat`` (sorted pair keys and their rows)."""
        self._key, self._moving, self._fat = key, moving.copy(), fat
        self._keys, self._ra, self._rb = keys, ra, rb
        self._built_last = True
        self.builds += 1

    def overlapping(self, bounds: Bounds,
                    ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
        """The kept candidates whose bounds strictly overlap now: ``(keys, ra, rb)``."""
        minx, miny, maxx, maxy = bounds
        keep = _overlapping(self._ra, self._rb, minx, miny, maxx, maxy)
        return self._keys[keep], self._ra[keep], self._rb[keep]
