"""Broad phase: the candidate pairs of the step, from the spatial hash (a few movers: directly).

Where the moving bodies times the rows are at most
:data:`~framework.collision.broad_phase.DIRECT_PAIRS`, the movers are paired with every hitbox in
one compiled pass (:func:`~framework.collision.broad_phase.direct_pairs`); more movers keep their
candidate pairs between steps, found from fat bounds and built again only when a mover leaves its
fat bounds or the rows, statics or sleepers change (:mod:`~framework.collision.kept_pairs`). Both
give the spatial hash's pairs in its order. The hash still takes each step's movers, and the
sleepers when one falls asleep or wakes, for the scene's queries and the debug overlay. Pairs whose layers and
masks do not meet are dropped here, and, in a scene without the events effect, pairs nobody reads
(neither the response nor a collision handler).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..arrays import BoolArray, I64Array, IntpArray
from ..collision.broad_phase import DIRECT_PAIRS, direct_pairs
from ..collision.grid import Bounds
from ..collision.kept_pairs import KeptPairs
from ..events import pair_keys, pair_parts
from ..frame import StepFrame
from ..store import STATIC
from .narrow_phase import filter_layers
from .stage import Stage

__all__ = ["BroadPhase"]

_NO_KEYS = np.zeros(0, dtype=np.int64)


class BroadPhase(Stage):
    """Fill ``frame.pairs`` (entities a < b and their rows) and ``frame.n_asleep``."""

    name = "broad_phase"
    needs = frozenset({"detection"})
    solver = "exact"

    def __init__(self, pipeline: Any) -> None:
        super().__init__(pipeline)
        self.kept = KeptPairs()  # the candidates of many movers, kept between steps

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
        counters["rehashed"] += int(movers.size)
        if store.sleep_dirty:
            sleepers = np.flatnonzero(store.asleep)
            bodies.sleep_hash.set_static(geom.minx[sleepers], geom.miny[sleepers], geom.maxx[sleepers],
                                         geom.maxy[sleepers], store.entity[sleepers])
            counters["rehashed"] += int(sleepers.size)
            store.sleep_dirty = False
        counters["asleep"] = frame.n_asleep = int(np.count_nonzero(store.asleep[store.active_sel()[2]]))
        all_bounds = (geom.minx, geom.miny, geom.maxx, geom.maxy)
        open_layers = store.layers_all_meet()
        kept = self.kept
        way = "direct" if direct else kept.choose((store.version, store.static_epoch, store.sleep_epoch, store.n),
                                                  movers, all_bounds)
        if way == "direct":
            c, n = store.cols, store.n
            ea, eb, ra, rb = direct_pairs(movers, c["kind"][:n], c["body"][:n], c["asleep"][:n], c["entity"][:n],
                                          *all_bounds, STATIC, store.row_table(), c["layer"], c["mask"], open_layers)
            bodies.hash.enter_few(*bounds, store.entity[moving])  # (for the queries and the overlay)
        elif way == "plain":
            keys = self._hashed(bounds, store.entity[moving], frame.n_asleep)
            ea, eb = pair_parts(keys)
            ra, rb = bodies.rows_of(ea), bodies.rows_of(eb)
        else:
            if way == "update":
                asleep = frame.n_asleep
                if not kept.update(all_bounds, store.cols["entity"], bodies.hash.cell_size,
                                   lambda fat, ids: self._still_pairs(fat, ids, asleep), store.row_table()):
                    way = "build"
            if way == "build":
                fat = kept.fat(movers, all_bounds)
                keys = self._hashed(fat, store.entity[moving], frame.n_asleep)
                kept.keep((store.version, store.static_epoch, store.sleep_epoch, store.n), movers, fat, keys,
                          bodies.rows_of(keys >> 32), bodies.rows_of(keys & 0xFFFFFFFF))
            keys, ra, rb = kept.overlapping(all_bounds)
            ea, eb = pair_parts(keys)
            bodies.hash.enter_few(*bounds, store.entity[moving])  # (the movers as they are, not fat)
        keep = None if open_layers or way == "direct" else filter_layers(store, ra, rb)  # (direct: filtered)
        if "events" not in self.pipeline.effects:
            need = self._someone_reads(ra, rb)
            keep = need if keep is None else keep & need
        frame.pairs = (ea, eb, ra, rb) if keep is None else (ea[keep], eb[keep], ra[keep], rb[keep])
        counters["candidate_pairs"] = int(frame.pairs[0].size)
        return True

    def _hashed(self, bounds: Bounds, ids: I64Array, asleep: int) -> I64Array:
        """The sorted pair keys of the movers' ``bounds`` (``ids`` their entities) with each other,
        the statics and (``asleep``: there are some) the sleepers, by the spatial hashes."""
        bodies = self.bodies
        ea, eb = bodies.hash.pairs(*bounds, ids)
        keys = pair_keys(ea, eb)
        if asleep:
            sa, sb = bodies.sleep_hash.pairs(*bounds, ids, moving_pairs=False)
            if sa.size:
                keys = np.concatenate([keys, pair_keys(sa, sb)])
                keys.sort()
        return keys

    def _still_pairs(self, bounds: Bounds, ids: I64Array, asleep: int) -> I64Array:
        """The pair keys of the bodies ``bounds`` (``ids`` their entities) with the statics and
        (``asleep``: there are some) the sleepers, by the spatial hashes (not sorted)."""
        bodies = self.bodies
        keys = pair_keys(*bodies.hash.static_pairs(*bounds, ids)) if bodies.n_static else _NO_KEYS
        if asleep:
            keys = np.concatenate([keys, pair_keys(*bodies.sleep_hash.static_pairs(*bounds, ids))])
        return keys

    def _someone_reads(self, ra: IntpArray, rb: IntpArray) -> BoolArray:
        """Without the events effect, only pairs the response or a handler reads are tested."""
        store = self.bodies.store
        need = np.zeros(ra.size, dtype=bool)
        if "response" in self.pipeline.effects:
            need |= ~(store.sensor[ra] | store.sensor[rb]) & ((store.inv_mass[ra] > 0) | (store.inv_mass[rb] > 0))
        if self.pipeline.wanted_pairs is not None:
            need |= self.pipeline.wanted_pairs(ra, rb)
        return need
