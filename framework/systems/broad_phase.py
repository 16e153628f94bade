"""Broad phase: the candidate pairs of the step, from the spatial hash (a few movers: directly).

Moving bodies are hashed every step against the static hash (kept until the static set changes)
and against each other; sleeping bodies are kept in a hash of their own, entered only when one
falls asleep or wakes. Where the moving bodies times the rows are at most
:data:`~framework.collision.broad_phase.DIRECT_PAIRS`, the movers are paired with every hitbox in
one compiled pass instead (the same pairs, in the same order;
:func:`~framework.collision.broad_phase.direct_pairs`). Pairs whose layers and
masks do not meet are dropped here, and, in a scene without the events effect, pairs nobody reads
(neither the response nor a collision handler).
"""

from __future__ import annotations

import numpy as np

from ..arrays import BoolArray, IntpArray
from ..collision.broad_phase import DIRECT_PAIRS, direct_pairs
from ..events import pair_keys, pair_parts
from ..frame import StepFrame
from ..store import STATIC
from .narrow_phase import filter_layers
from .stage import Stage

__all__ = ["BroadPhase"]


class BroadPhase(Stage):
    """Fill ``frame.pairs`` (entities a < b and their rows) and ``frame.n_asleep``."""

    name = "broad_phase"
    needs = frozenset({"detection"})
    solver = "exact"

    def run(self, frame: StepFrame) -> bool:
        bodies = self.bodies
        store = bodies.store
        geom = bodies.ensure_geometry()
        counters = frame.counters
        counters["rehashed"] += bodies.sync_static()
        moving = store.active_sel()[1]  # a slice where the bodies are one run of rows: views, no gathers
        bounds = (geom.minx[moving], geom.miny[moving], geom.maxx[moving], geom.maxy[moving])
        movers = store.active()[1]
        # Few enough tests (movers x rows): every mover paired with every hitbox directly, in one
        # compiled pass (the hash's pairs, without its numpy calls); else through the hashes.
        direct = movers.size * store.n <= DIRECT_PAIRS
        if direct:
            bodies.hash.enter_few(*bounds, store.entity[moving])
        else:
            ea, eb = bodies.hash.pairs(*bounds, store.entity[moving])
        counters["rehashed"] += int(movers.size)
        if store.sleep_dirty:
            sleepers = np.flatnonzero(store.asleep)
            bodies.sleep_hash.set_static(geom.minx[sleepers], geom.miny[sleepers], geom.maxx[sleepers],
                                         geom.maxy[sleepers], store.entity[sleepers])
            counters["rehashed"] += int(sleepers.size)
            store.sleep_dirty = False
        counters["asleep"] = frame.n_asleep = int(np.count_nonzero(store.asleep[store.active_sel()[2]]))
        if direct:
            c, n = store.cols, store.n
            ea, eb = pair_parts(direct_pairs(movers, c["kind"][:n], c["body"][:n], c["asleep"][:n], c["entity"][:n],
                                             geom.minx, geom.miny, geom.maxx, geom.maxy, STATIC))
        elif frame.n_asleep:
            sa, sb = bodies.sleep_hash.pairs(*bounds, store.entity[moving], moving_pairs=False)
            if sa.size:
                keys = np.concatenate([pair_keys(ea, eb), pair_keys(sa, sb)])
                keys.sort()
                ea, eb = pair_parts(keys)
        ra, rb = bodies.rows_of(ea), bodies.rows_of(eb)
        keep = filter_layers(store, ra, rb)
        if "events" not in self.pipeline.effects:
            keep &= self._someone_reads(ra, rb)
        frame.pairs = (ea[keep], eb[keep], ra[keep], rb[keep])
        counters["candidate_pairs"] = int(keep.sum())
        return True

    def _someone_reads(self, ra: IntpArray, rb: IntpArray) -> BoolArray:
        """Without the events effect, only pairs the response or a handler reads are tested."""
        store = self.bodies.store
        need = np.zeros(ra.size, dtype=bool)
        if "response" in self.pipeline.effects:
            need |= ~(store.sensor[ra] | store.sensor[rb]) & ((store.inv_mass[ra] > 0) | (store.inv_mass[rb] > 0))
        if self.pipeline.wanted_pairs is not None:
            need |= self.pipeline.wanted_pairs(ra, rb)
        return need
