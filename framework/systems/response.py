"""The response stage: which contacts the response acts on, and the geometry its solve asks for.

Each step it gathers this step's contacts and the pairs it acted on last step, with their pushes
and impulses (bodies resting on each other fall by the same amount and merely touch: those pairs
stay in the solve, with the gap the step's motion opened), keeps the solid ones (not sensors, at
least one movable body, not a body a system spoiled, one-way platforms only when landed on) and
hands them to the solve (:mod:`framework.systems.solve`), which pushes them apart and stops their
approach. The solve asks this stage to measure pairs again (with pushes re-aimed off the internal
faces of tiles), for the broad phase's candidate pairs and for statics near bodies it pushed far.

What was applied is ``frame.resolved``; the pairs acted on, with their pushes, impulses and the gap
they ended with (the next step's warm start), are ``frame.support``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..arrays import BoolArray, F64Array, I64Array, IntpArray
from ..collision import batch
from ..collision.kinds import KIND_AABB, KIND_CIRCLE
from ..events import pair_keys, sorted_member
from ..frame import NO_POINTS, NO_RESOLVED, NO_SUPPORT, StepFrame
from ..geometry import Geometry
from ..store import STATIC
from .gather import centres_inside, gather, solid_contacts, solid_pairs_mask, taking_part
from .internal_faces import InternalFaces
from .narrow_phase import filter_layers, pair_contacts
from .solve import KEEP_GAP, Contacts, Pairs, Solve
from .solve_rounds import kept_static_pairs, known_keys, near_rows, unknown_solid_pairs
from .stage import Stage
from .turning import manifold_points

__all__ = ["Response"]

_NO_IDS = np.zeros(0, dtype=np.int64)  # (no pairs; no keys)


class Response(Stage):
    """Resolve the step's solid contacts; fill ``frame.resolved`` and ``frame.support``."""

    name = "response"
    needs = frozenset({"response"})
    solver = "exact"

    def __init__(self, pipeline) -> None:
        super().__init__(pipeline)
        self.internal_faces = InternalFaces()
        self._near: _NearStatics | None = None
        # The solve's numbering, row -> local number (-1: not in the solve), kept between steps:
        # a solve sets the entries of its own rows and the next one resets just those (a table of
        # the store's size made afresh each step cost a level of 100,000 static tiles 50 us).
        self._numbering = np.zeros(0, dtype=np.int64)
        self._numbered = np.zeros(0, dtype=np.int64)  # the rows last numbered (-1 again: to reset)
        self._numbering_clean = True  # False from a solve's start to its end (a step that failed midway)

    def run(self, frame: StepFrame) -> bool:
        if frame.support[0].size == 0 and self._idle(frame):
            # Nothing to act on: no pair was acted on last step and no contact has a body the
            # response may move (everything touching is static, kinematic or asleep: a platformer's
            # kinematic characters, a pile asleep). What the full pass below would find, without
            # its sixty array operations.
            frame.support, frame.resolved, frame.points = NO_SUPPORT, NO_RESOLVED, NO_POINTS
            return True
        cs = self._gather(frame)
        frame.support = NO_SUPPORT
        frame.resolved = NO_RESOLVED
        points, frame.points = frame.points, NO_POINTS
        solid = self._solid(frame, cs)
        if not solid.all():  # (all solid: the gathered columns as they are, no copy of them)
            cs = cs.take(np.flatnonzero(solid))
        if cs.size == 0:
            return True
        solve = Solve(self, frame, cs, points)
        solve.positions()
        solve.velocities()
        solve.record(frame)
        self._numbered, self._numbering_clean = solve.rows, True
        return True

    def numbering(self, n: int) -> I64Array:
        """The solve's table row -> local number, every entry -1, for a store of ``n`` rows: the
        kept one with the last solve's rows reset (a new one where the store changed size or the
        last solve did not finish)."""
        table = self._numbering
        if table.size != n or not self._numbering_clean:
            table = self._numbering = np.full(n, -1, dtype=np.int64)
        else:
            table[self._numbered] = -1
        self._numbered, self._numbering_clean = _NO_IDS, False
        return table

    def _idle(self, frame: StepFrame) -> bool:
        """Whether no contact of this step has a body the response may move (a contact's row beyond
        the store's: not idle, the full pass says what is wrong)."""
        ra, rb = frame.contact_rows
        n = self.bodies.store.n
        if ra.size == 0:
            return True
        if ra.max() >= n or rb.max() >= n:
            return False
        return not self._takes_part(ra, rb).any()

    # --- which contacts ----------------------------------------------------------------------

    def _gather(self, frame: StepFrame) -> Contacts:
        """This step's contacts (with last step's push and impulse where the pair was acted on;
        two boxes along the axis they came together on), plus last step's pairs that no longer
        overlap but are still close (both bodies still there, with hitboxes whose layers meet,
        still facing each other): one compiled pass, :func:`~framework.systems.gather.gather`
        (its docstring says why each rule)."""
        store = self.bodies.store
        c = frame.contacts
        ra, rb = frame.contact_rows
        n = store.n
        if ra.size and (int(ra.max()) >= n or int(rb.max()) >= n):
            raise IndexError(f"a contact's row is beyond the store's {n} rows (a body removed during the step)")
        geom = self.bodies.ensure_geometry()
        col = store.cols
        i64, f64 = np.int64, np.float64
        sa, sb, snx, sny, spush, simp, ssep, stpush, stimp = (
            np.asarray(v, dtype=i64 if k < 2 else f64) for k, v in enumerate(frame.support))
        effects = self.pipeline.effects
        ints, floats, alive0 = gather(
            np.asarray(c.a, dtype=i64), np.asarray(c.b, dtype=i64), c.nx, c.ny, c.depth, c.px, c.py,
            np.asarray(ra, dtype=i64), np.asarray(rb, dtype=i64), sa, sb, snx, sny, spush, simp, ssep, stpush, stimp,
            store.row_table(), col["kind"], col["layer"], col["mask"], store.layers_all_meet(), col["bound"],
            col["radius"], col["inv_inertia"], col["friction"], col["hw"], col["hh"], col["x"], col["y"],
            frame.start_x, frame.start_y, geom.hx, geom.hy, geom.minx, geom.miny, geom.maxx, geom.maxy,
            "friction" in effects and "rotation" in effects, KEEP_GAP, KIND_AABB, KIND_CIRCLE)
        ra, rb, ea, eb = ints
        nx, ny, depth, push0, impulse0, tpush0, timpulse0, px, py = floats
        return Contacts(ra, rb, ea, eb, nx, ny, depth, alive0, push0, impulse0, tpush0, timpulse0, px, py)

    def _solid(self, frame: StepFrame, cs: Contacts) -> BoolArray:
        """Mask of the contacts the response acts on."""
        store = self.bodies.store
        ra, rb = cs.ra, cs.rb
        c = store.cols
        # (one compiled pass: the pairs taking part; a body a system spoiled (NaN) is left alone, so
        # the step reports it as written and the bad value spreads to no other body)
        solid, platforms = solid_contacts(ra, rb, c["kind"], c["sensor"], c["inv_mass"], c["asleep"], store.vx,
                                          store.vy, c["one_way"])
        if platforms:
            one_way = store.one_way[ra] | store.one_way[rb]
            solid &= ~one_way | self._lands_on_one_way(frame, cs)
        return solid

    def _moved(self, frame: StepFrame, rows: IntpArray) -> tuple[F64Array, F64Array] | None:
        """How far each of ``rows`` has moved since the step began, or None if one was spawned
        during the step (it has no start)."""
        sx, sy, store = frame.start_x, frame.start_y, self.bodies.store
        if rows.size and sx.size <= int(rows.max()):
            return None
        return store.x[rows] - sx[rows], store.y[rows] - sy[rows]

    def _lands_on_one_way(self, frame: StepFrame, cs: Contacts) -> BoolArray:
        """Mask of contacts a one-way platform takes: the other body comes from above (the
        normal within 45 degrees of the platform's up) and sank in only by this step's motion."""
        store = self.bodies.store
        ra, rb, nx, ny = cs.ra, cs.rb, cs.nx, cs.ny
        plat_is_a = store.one_way[ra]
        plat = np.where(plat_is_a, ra, rb)
        other = np.where(plat_is_a, rb, ra)
        rot = store.rot[plat]
        ux, uy = -np.sin(rot), np.cos(rot)
        toward_other = np.where(plat_is_a, 1.0, -1.0)
        from_above = (nx * ux + ny * uy) * toward_other > 0.7071
        # Where each body started the step (rows spawned during the step: where they are).
        x0, y0 = store.x.copy(), store.y.copy()
        n0 = frame.start_x.size
        x0[:n0], y0[:n0] = frame.start_x, frame.start_y
        dx = (store.x[other] - x0[other]) - (store.x[plat] - x0[plat])
        dy = (store.y[other] - y0[other]) - (store.y[plat] - y0[plat])
        sank = -(dx * ux + dy * uy)
        tol = 1e-9 * (1.0 + store.bound[other])
        came_down = cs.depth <= np.maximum(sank, 0.0) + tol
        return from_above & (came_down | ~cs.alive0)

    def candidate_pairs(self, frame: StepFrame, cs: Contacts) -> Pairs:
        """The broad phase's pairs that are not contacts of the solve (touching or near when the
        narrow phase measured them), where both bodies take part in the response and neither is a
        one-way platform: ``(rows a, rows b, entities a, entities b)``. Pushes may make them
        overlap within the step."""
        ea, eb, ra, rb = frame.pairs
        if ea.size == 0:
            return ra, rb, ea, eb
        store = self.bodies.store
        c = store.cols
        # (one compiled pass: the pairs not among the contacts' keys, rows in the store, solid)
        pairs: Pairs = unknown_solid_pairs(
            ra, rb, ea, eb, known_keys(cs.ea, cs.eb, _NO_IDS, _NO_IDS), store.n, c["kind"], c["sensor"],
            c["inv_mass"], c["asleep"], c["one_way"], c["layer"], c["mask"], store.layers_all_meet())
        return pairs

    def solid_pairs(self, ra: IntpArray, rb: IntpArray, ea: I64Array, eb: I64Array) -> Pairs:
        """The pairs among ``(ra, rb, ea, eb)`` the response may act on: hitboxes whose layers
        meet, neither a sensor nor a one-way platform, at least one body movable."""
        store = self.bodies.store
        c = store.cols
        ok = solid_pairs_mask(ra, rb, c["kind"], c["sensor"], c["inv_mass"], c["asleep"], c["one_way"], c["layer"],
                              c["mask"], store.layers_all_meet())
        return ra[ok], rb[ok], ea[ok], eb[ok]

    def _takes_part(self, ra: IntpArray, rb: IntpArray) -> BoolArray:
        """Mask of the pairs the response may act on by their bodies alone: both still have a
        hitbox (a system may have removed one), neither is a sensor, and at least one is movable
        (sleeping bodies keep still)."""
        c = self.bodies.store.cols
        taking: BoolArray = taking_part(ra, rb, c["kind"], c["sensor"], c["inv_mass"], c["asleep"])
        return taking

    # --- geometry the solve asks for ---------------------------------------------------------

    def redirect(
        self, ra: IntpArray, rb: IntpArray, nx: F64Array, ny: F64Array, depth: F64Array, hit: BoolArray,
    ) -> None:
        """Re-aim (in place) pushes of bodies deep inside a static box (:meth:`_deep_inside`),
        and pushes that would leave a tile through a face another tile covers."""
        b = self.bodies
        if b.n_static == 0:
            return
        store, geom = b.store, b.geometry  # (the callers' measures brought the origins up to date)
        c = store.cols
        # (one compiled pass: the contacts with one static box whose body's centre is inside it, and
        # whether a box met may have a covered face; both re-aim only pushes off static boxes)
        inside, covered = centres_inside(ra, rb, hit, c["body"], c["kind"], STATIC, KIND_AABB, geom.hx, geom.hy,
                                         geom.minx, geom.maxx, geom.miny, geom.maxy, self.internal_faces.table(store))
        if inside.size:
            self._deep_inside(ra, rb, nx, ny, depth, inside)
        if covered:
            rank = depth.copy()
            self.internal_faces.redirect(store, geom, b.hash, b.rows_of, ra, rb, nx, ny, depth, hit, rank)

    def _deep_inside(self, ra: IntpArray, rb: IntpArray, nx: F64Array, ny: F64Array, depth: F64Array,
                     pick: IntpArray) -> None:
        """Re-aim (in place) the pushes of the contacts ``pick``, of movable bodies whose centre lies
        inside a static AABB (``gather.centres_inside``).

        The least push out of a slab is through its nearer face: a box spawned or teleported into
        the middle of a floor one unit thick was pushed out of its bottom (the tie between top and
        bottom goes down by the contract's order) and fell forever (issue 34). So for such a body:
        if its centre was outside the box at the step's start, it came in this step and goes back
        out the side it came from; otherwise (spawned or teleported there) out of the face against
        gravity where that push is at most the body's own extent along gravity longer than the
        least (a box in a floor pops up on top; a ball in the middle of a tall wall still goes out
        of the near side), else the least. Each push is along the face's normal, exactly as far as
        takes the body's bounds clear of that face. (Faces other tiles cover: see
        :mod:`~framework.systems.internal_faces`, which runs after this.)"""
        store = self.bodies.store
        geom = self.bodies.geometry  # (the callers' measures brought the origins up to date)
        flip = (store.body[rb[pick]] == STATIC) & (store.kind[rb[pick]] == KIND_AABB)  # the box is b: push negated
        s = np.where(flip, rb[pick], ra[pick])
        m = np.where(flip, ra[pick], rb[pick])
        cx, cy = geom.hx[m], geom.hy[m]
        geom.update_rows(store, m)  # (their bounds: the solve may have moved them since they were computed)
        # the four pushes that take the body's bounds clear of each face: +x, -x, +y, -y
        pushes = np.stack([geom.maxx[s] - geom.minx[m], geom.maxx[m] - geom.minx[s],
                           geom.maxy[s] - geom.miny[m], geom.maxy[m] - geom.miny[s]])
        face_x = np.array([1.0, -1.0, 0.0, 0.0])
        face_y = np.array([0.0, 0.0, 1.0, -1.0])
        choice = np.argmin(pushes, axis=0)
        gx, gy = self.pipeline.active_gravity()
        if gx or gy:  # the face against gravity, if not much farther
            up = int(np.argmax(-(face_x * gx + face_y * gy)))
            extent = np.where(face_x[up] != 0.0, geom.maxx[m] - geom.minx[m], geom.maxy[m] - geom.miny[m])
            least = pushes[choice, np.arange(pick.size)]
            choice = np.where(pushes[up] <= least + extent, up, choice)
        moved = self._moved(self.pipeline.frame, m)
        if moved is not None:  # came in this step: back out the way it came
            x0, y0 = cx - moved[0], cy - moved[1]
            came = np.select([x0 >= geom.maxx[s], x0 <= geom.minx[s], y0 >= geom.maxy[s], y0 <= geom.miny[s]],
                             [0, 1, 2, 3], -1)
            choice = np.where(came >= 0, came, choice)
        sign = np.where(flip, -1.0, 1.0)
        nx[pick], ny[pick] = sign * face_x[choice], sign * face_y[choice]
        depth[pick] = pushes[choice, np.arange(pick.size)]

    def remeasure(self, ra: IntpArray, rb: IntpArray) -> batch.ContactArrays:
        """The pairs ``(ra, rb)`` measured again where the bodies now are (pairs within rounding of
        touching count as apart), pushes re-aimed off internal faces. Only these rows' hitbox
        origins are brought up to date (a full update waits for the next reader)."""
        store, geom = self.bodies.store, self._geometry_of(ra, rb, False)
        r = pair_contacts(store, geom, ra, rb, remeasure=True)
        self.redirect(ra, rb, r.nx, r.ny, r.depth, r.hit)
        return r

    def remeasure_points(self, ra: IntpArray, rb: IntpArray, nx: F64Array, ny: F64Array,
                         gap: float) -> tuple[I64Array, F64Array, F64Array, F64Array]:
        """The manifold points of the box and polygon pairs ``(ra, rb)`` along the normals ``(nx,
        ny)``, where the bodies (and their turns) now are (see :func:`manifold_points`)."""
        return manifold_points(self.bodies.store, self._geometry_of(ra, rb, True), ra, rb, nx, ny, gap)

    def _geometry_of(self, ra: IntpArray, rb: IntpArray, turned: bool) -> Geometry:
        """The geometry, with the hitboxes of these rows where their bodies now stand (``turned``:
        and as they are now turned; a full update waits for the next reader)."""
        store, geom = self.bodies.store, self.bodies.geometry
        if geom.version != store.version:
            geom.update(store)
        elif geom.has_offset or turned:
            geom.update_rows(store, np.concatenate([ra, rb]))
        else:  # origins are the positions
            geom.hx, geom.hy = store.x, store.y
        return geom

    def static_candidates(self, local: IntpArray, rows: IntpArray, reach: F64Array,
                          known: Callable[[], I64Array]) -> Pairs:
        """Pairs of the solve's bodies ``local`` (local numbers of its ``rows``, with their ``reach``) that
        the response may move, with the static bodies their bounds, grown by their reach, meet where
        they stand, other than the pairs whose keys are in ``known()`` (sorted; asked only where a
        body has statics near): ``(rows a, rows b, entities a, entities b)``, as
        :meth:`candidate_pairs`. Pushes within the reach can bring a body only to these statics.

        Kept from step to step: a body's statics are looked up (with twice the reach) again only
        once it has moved more than the reach since, or the statics changed; a resting pile asks
        the static hash nothing."""
        bodies = self.bodies
        store = bodies.store
        if bodies.n_static == 0:
            return _NO_IDS, _NO_IDS, _NO_IDS, _NO_IDS
        cache = self._static_cache()
        # (compiled passes: the movable bodies with a finite reach, which moved farther than it,
        # and their kept pairs not among the known keys that the response may act on)
        rows, margin, far = near_rows(local, rows, reach, store.inv_mass, store.asleep, store.x, store.y, cache.x,
                                      cache.y)
        if rows.size == 0:
            return _NO_IDS, _NO_IDS, _NO_IDS, _NO_IDS
        if far.any():
            cache.refresh(bodies, rows[far], 2.0 * margin[far])
        if cache.row.size == 0:  # (no body has a static near: bodies far from the level's tiles)
            return _NO_IDS, _NO_IDS, _NO_IDS, _NO_IDS
        c = store.cols
        pairs: Pairs = kept_static_pairs(store.n, rows, cache.row, cache.ea, cache.eb, known(), store.row_table(),
                                         c["kind"], c["sensor"], c["inv_mass"], c["asleep"], c["one_way"], c["layer"],
                                         c["mask"], store.layers_all_meet())
        return pairs

    def _static_cache(self) -> _NearStatics:
        store = self.bodies.store
        key = (store.version, store.static_epoch, store.n)
        if self._near is None or self._near.key != key:
            self._near = _NearStatics(key, store.n)
        return self._near

    def new_static_contacts(
        self, rows: IntpArray, known: I64Array,
    ) -> tuple[I64Array, I64Array, IntpArray, IntpArray, batch.ContactArrays] | None:
        """Overlaps of ``rows`` (dynamic, just moved) with static bodies, other than the pairs whose
        keys are in ``known`` (sorted): ``(ents_a, ents_b, rows_a, rows_b, contacts)`` or None."""
        bodies = self.bodies
        store, hsh = bodies.store, bodies.hash
        if rows.size == 0 or bodies.n_static == 0:
            return None
        geom = bodies.geometry
        # First a cheap look with bounds that hold the hitbox at any rotation (its bounding circle
        # about the body's position): most bodies have no static in their cells, and their exact
        # bounds are not needed; nor are any when all of them lie outside the statics' extent.
        reach = store.bound[rows] + np.hypot(store.ox[rows], store.oy[rows]) if geom.has_offset else store.bound[rows]
        x, y = store.x[rows], store.y[rows]
        box = (np.nextafter(x - reach, -np.inf), np.nextafter(y - reach, -np.inf),
               np.nextafter(x + reach, np.inf), np.nextafter(y + reach, np.inf))
        if hsh.outside_statics(*(f(v) for f, v in zip((np.min, np.min, np.max, np.max), box))):
            return None
        near = hsh.near_statics(*box) & (store.kind[rows] >= 0) & ~store.asleep[rows] & ~store.sensor[rows]
        rows = rows[near]
        if rows.size == 0:
            return None
        geom.update_rows(store, rows)
        ea, eb = hsh.static_pairs(geom.minx[rows], geom.miny[rows], geom.maxx[rows], geom.maxy[rows],
                                  store.entity[rows])
        if ea.size == 0:
            return None
        ra, rb = bodies.rows_of(ea), bodies.rows_of(eb)
        keep = filter_layers(store, ra, rb) & ~(store.sensor[ra] | store.sensor[rb])
        keep &= ~(store.one_way[ra] | store.one_way[rb])  # a platform is passed through from below
        keys = pair_keys(np.minimum(ea, eb), np.maximum(ea, eb))
        keep &= ~sorted_member(keys, known)
        if not keep.any():
            return None
        ea, eb, ra, rb = ea[keep], eb[keep], ra[keep], rb[keep]
        r = self.remeasure(ra, rb)
        if not r.hit.any():
            return None
        h = np.flatnonzero(r.hit)
        return ea[h], eb[h], ra[h], rb[h], batch.ContactArrays._make(v[h] for v in r)


class _NearStatics:
    """Per dynamic row, the static bodies near it (entity pairs), and where it stood when they were
    looked up; valid until rows or statics change (``key``)."""

    def __init__(self, key: tuple[int, ...], n: int) -> None:
        self.key = key
        self.x, self.y = np.full(n, np.nan), np.full(n, np.nan)
        self.row = np.zeros(0, dtype=np.int64)  # per pair: the dynamic body's row
        self.ea = self.eb = np.zeros(0, dtype=np.int64)

    def refresh(self, bodies, rows: IntpArray, margin: F64Array) -> None:
        """Look up the statics within ``margin`` of ``rows`` again."""
        store, geom, hsh = bodies.store, bodies.geometry, bodies.hash
        if self.row.size:  # (the pairs of other rows kept)
            stale = np.zeros(store.n, dtype=bool)
            stale[rows] = True
            keep = ~stale[self.row]
            self.row, self.ea, self.eb = self.row[keep], self.ea[keep], self.eb[keep]
        self.x[rows], self.y[rows] = store.x[rows], store.y[rows]
        box = (geom.minx[rows] - margin, geom.miny[rows] - margin, geom.maxx[rows] + margin, geom.maxy[rows] + margin)
        if hsh.outside_statics(*(f(v) for f, v in zip((np.min, np.min, np.max, np.max), box))):
            return
        ea, eb = hsh.static_pairs(*box, store.entity[rows])
        if ea.size:
            dyn = np.where(store.body[bodies.rows_of(ea)] == STATIC, eb, ea)
            self.row = np.concatenate([self.row, bodies.rows_of(dyn)])
            self.ea, self.eb = np.concatenate([self.ea, ea]), np.concatenate([self.eb, eb])

    def pairs_of(self, n: int, rows: IntpArray) -> tuple[I64Array, I64Array]:
        """The kept pairs of ``rows``."""
        want = np.zeros(n, dtype=bool)
        want[rows] = True
        sel = want[self.row]
        return self.ea[sel], self.eb[sel]
