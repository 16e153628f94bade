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

import numpy as np

from ..arrays import BoolArray, F64Array, I64Array, IntpArray
from ..collision import batch
from ..collision.kinds import KIND_AABB, KIND_CIRCLE
from ..events import pair_keys, sorted_find, sorted_member
from ..frame import NO_POINTS, NO_RESOLVED, NO_SUPPORT, StepFrame
from ..geometry import Geometry
from ..store import STATIC
from .internal_faces import InternalFaces
from .narrow_phase import filter_layers, pair_contacts
from .solve import KEEP_GAP, Contacts, Pairs, Solve
from .stage import Stage
from .turning import manifold_points

__all__ = ["Response"]


class Response(Stage):
    """Resolve the step's solid contacts; fill ``frame.resolved`` and ``frame.support``."""

    name = "response"
    needs = frozenset({"response"})
    solver = "exact"

    def __init__(self, pipeline) -> None:
        super().__init__(pipeline)
        self.internal_faces = InternalFaces()
        self._near: _NearStatics | None = None

    def run(self, frame: StepFrame) -> bool:
        store = self.bodies.store
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
        if cs.size and cs.ra.max() >= store.n:  # rows spawned mid-step are not in this step
            return False
        cs = cs.take(np.flatnonzero(self._solid(frame, cs)))
        if cs.size == 0:
            return True
        solve = Solve(self, frame, cs, points)
        solve.positions()
        solve.velocities()
        solve.record(frame)
        return True

    def _idle(self, frame: StepFrame) -> bool:
        """Whether no contact of this step has a body the response may move (rows spawned during
        the step excepted: the full pass leaves the step to them)."""
        ra, rb = frame.contact_rows
        n = self.bodies.store.n
        if ra.size == 0:
            return True
        if ra.max() >= n or rb.max() >= n:
            return False
        return not self._takes_part(ra, rb).any()

    # --- which contacts ----------------------------------------------------------------------

    def _gather(self, frame: StepFrame) -> Contacts:
        """This step's contacts (with last step's push and impulse where the pair was acted on),
        plus last step's pairs that no longer overlap but are still close (both bodies still
        there, with hitboxes whose layers meet)."""
        store, bodies = self.bodies.store, self.bodies
        c = frame.contacts
        sa, sb, snx, sny, spush, simp, ssep, stpush, stimp = frame.support
        now_keys, kept_keys = pair_keys(c.a, c.b), pair_keys(sa, sb)
        push0, impulse0 = np.zeros(c.a.size), np.zeros(c.a.size)
        tpush0, timpulse0 = np.zeros(c.a.size), np.zeros(c.a.size)
        if kept_keys.size:  # the warm start of the pairs found again
            at, found = sorted_find(now_keys, kept_keys)
            push0[found], impulse0[found] = spush[at[found]], simp[at[found]]
            if stpush.any() or stimp.any():  # (friction acted last step)
                tpush0[found], timpulse0[found] = stpush[at[found]], stimp[at[found]]
        old = np.flatnonzero(~sorted_member(kept_keys, now_keys))
        sra, srb = bodies.rows_of(sa[old]), bodies.rows_of(sb[old])
        live = (sra >= 0) & (srb >= 0)
        ok = np.flatnonzero(live)
        live[ok] = (store.kind[sra[ok]] >= 0) & (store.kind[srb[ok]] >= 0) & filter_layers(store, sra[ok], srb[ok])
        old, sra, srb = old[live], sra[live], srb[live]
        snx, sny = snx.copy(), sny.copy()
        gaps = self._support_gaps(frame, sra, srb, snx[old], sny[old]) - ssep[old]
        self._rolling_gaps(sra, srb, old, snx, sny, gaps)
        margin = KEEP_GAP * np.minimum(store.bound[sra], store.bound[srb])
        near = (gaps >= -margin) & self._facing(sra, srb, snx[old], sny[old], margin)
        old, sra, srb, gaps = old[near], sra[near], srb[near], gaps[near]
        cat = np.concatenate
        nx, ny, depth = self._entry_axes(frame, frame.contact_rows[0], frame.contact_rows[1], c.nx, c.ny, c.depth)
        return Contacts(
            cat([frame.contact_rows[0], sra]), cat([frame.contact_rows[1], srb]), cat([c.a, sa[old]]),
            cat([c.b, sb[old]]), cat([nx, snx[old]]), cat([ny, sny[old]]), cat([depth, gaps]),
            np.arange(c.a.size + old.size) < c.a.size, cat([push0, spush[old]]), cat([impulse0, simp[old]]),
            cat([tpush0, stpush[old]]), cat([timpulse0, stimp[old]]), cat([c.px, np.zeros(old.size)]),
            cat([c.py, np.zeros(old.size)]))

    def _rolling_gaps(self, ra: IntpArray, rb: IntpArray, old: IntpArray, nx: F64Array, ny: F64Array,
                      gaps: F64Array) -> None:
        """Kept pairs of two circles of which friction rolls one: their normal (in ``nx, ny`` at
        ``old``) and gap (in ``gaps``, as a depth) where they stand now.

        Elsewhere a kept pair keeps last step's normal, and its gap is the step's motion along it.
        Between two circles that is a plane tangent to the lower one: a circle rolling over the
        top of another rode that plane at the height of the top, kept while their bounds still
        faced each other (a diameter of travel), and rolling on a level plane costs nothing: in a
        pile of 80 rolling circles (issue 33 item 5a) balls rolled on such planes at up to 0.5
        units/s, 0.12 clear of the circle under them. (Not yet for circles that do not turn: the
        frictionless half-boxes crowd of test_solver, seed 0, then rests at 34 s instead of
        within 30.)"""
        store = self.bodies.store
        if not ("friction" in self.pipeline.effects and "rotation" in self.pipeline.effects):
            return
        circles = (store.kind[ra] == KIND_CIRCLE) & (store.kind[rb] == KIND_CIRCLE)
        turns = (store.inv_inertia[ra] > 0.0) | (store.inv_inertia[rb] > 0.0)
        i = np.flatnonzero(circles & turns)
        if i.size == 0:
            return
        i = i[store.pair_friction(ra[i], rb[i]) > 0.0]
        geom = self.bodies.ensure_geometry()
        a, b = ra[i], rb[i]
        dx, dy = geom.hx[b] - geom.hx[a], geom.hy[b] - geom.hy[a]
        dist = np.hypot(dx, dy)
        ok = dist > 0.0
        i, a, b, dx, dy, dist = i[ok], a[ok], b[ok], dx[ok], dy[ok], dist[ok]
        nx[old[i]], ny[old[i]] = dx / dist, dy / dist
        gaps[i] = np.minimum(store.radius[a] + store.radius[b] - dist, 0.0)

    def _entry_axes(self, frame: StepFrame, ra: IntpArray, rb: IntpArray, nx: F64Array, ny: F64Array,
                    depth: F64Array) -> tuple[F64Array, F64Array, F64Array]:
        """The solve's normals and depths of this step's contacts between two AABBs: along the
        axis the pair came together on this step, where that is not the axis of least overlap.

        The least overlap (the contract's push-out) forgets how the boxes met. A box falling into a
        gap a hair narrower than itself overlaps its neighbours' top corners by the step's fall
        vertically and by the hair sideways: pushed out sideways, it wedged the row apart against
        the walls and sank into the gap, and a crowd came to rest with rows overlapping by 0.02
        (issue 33). So where, at the step's start, the two boxes overlapped along one axis and
        were apart or touching along the other (within a millionth of their size), the contact
        is along that other axis; apart along both (a corner approach), along the axis on which
        they met last; overlapping along both, the least overlap as before. The events keep the
        contract's normal; only the solve's changes."""
        store = self.bodies.store
        boxes = np.flatnonzero((store.kind[ra] == KIND_AABB) & (store.kind[rb] == KIND_AABB))
        a, b = ra[boxes], rb[boxes]
        ma, mb = self._moved(frame, a), self._moved(frame, b)
        if boxes.size == 0 or ma is None or mb is None:
            return nx, ny, depth
        geom = self.bodies.ensure_geometry()
        wx, wy = store.hw[a] + store.hw[b], store.hh[a] + store.hh[b]
        # centre offsets (b - a) now and at the step's start (the hitboxes moved with their bodies)
        cx, cy = geom.hx[b] - geom.hx[a], geom.hy[b] - geom.hy[a]
        cx0, cy0 = cx - (mb[0] - ma[0]), cy - (mb[1] - ma[1])
        ox, oy = wx - np.abs(cx), wy - np.abs(cy)  # overlaps now (> 0 along both: they overlap)
        ox0, oy0 = wx - np.abs(cx0), wy - np.abs(cy0)  # ... and at the start (<= 0: apart)
        hair = 1e-6 * np.minimum(wx, wy)
        apart_x, apart_y = ox0 <= hair, oy0 <= hair
        # apart along both: the axis whose gap closed later in the step (vertical on a tie)
        late_x = (-ox0) * np.maximum(oy - oy0, 0.0) > (-oy0) * np.maximum(ox - ox0, 0.0)
        along_x = np.where(apart_x & apart_y, late_x, apart_x & ~apart_y)
        along_y = np.where(apart_x & apart_y, ~late_x, apart_y & ~apart_x)
        was_x = np.abs(nx[boxes]) > np.abs(ny[boxes])
        to_x, to_y = along_x & ~was_x & (ox > 0.0), along_y & was_x & (oy > 0.0)
        if not (to_x.any() or to_y.any()):
            return nx, ny, depth
        nx, ny, depth = nx.copy(), ny.copy(), depth.copy()
        # (b's side of a: where it was at the start, else where it is)
        side_x = np.where(np.where(cx0 != 0.0, cx0, cx) < 0.0, -1.0, 1.0)
        side_y = np.where(np.where(cy0 != 0.0, cy0, cy) < 0.0, -1.0, 1.0)
        i = boxes[to_x]
        nx[i], ny[i], depth[i] = side_x[to_x], 0.0, ox[to_x]
        i = boxes[to_y]
        nx[i], ny[i], depth[i] = 0.0, side_y[to_y], oy[to_y]
        return nx, ny, depth

    def _solid(self, frame: StepFrame, cs: Contacts) -> BoolArray:
        """Mask of the contacts the response acts on."""
        store = self.bodies.store
        ra, rb = cs.ra, cs.rb
        solid = self._takes_part(ra, rb)
        # A body a system spoiled (NaN) is left alone, so the step reports it as written and the
        # bad value spreads to no other body.
        solid &= np.isfinite(store.vx[ra] + store.vy[ra] + store.vx[rb] + store.vy[rb])
        one_way = store.one_way[ra] | store.one_way[rb]
        if one_way.any():
            solid &= ~one_way | self._lands_on_one_way(frame, cs)
        return solid

    def _facing(self, ra: IntpArray, rb: IntpArray, nx: F64Array, ny: F64Array, margin: F64Array) -> BoolArray:
        """Mask of the kept pairs whose bodies still face each other across their contact: their
        bounds meet when grown by ``margin`` along the normal only (a box whose support slid away
        sideways is no longer held by it, however small the gap along the normal)."""
        geom = self.bodies.ensure_geometry()
        gx, gy = margin * np.abs(nx), margin * np.abs(ny)
        return ((geom.minx[ra] - gx < geom.maxx[rb]) & (geom.minx[rb] - gx < geom.maxx[ra])
                & (geom.miny[ra] - gy < geom.maxy[rb]) & (geom.miny[rb] - gy < geom.maxy[ra]))

    def _moved(self, frame: StepFrame, rows: IntpArray) -> tuple[F64Array, F64Array] | None:
        """How far each of ``rows`` has moved since the step began, or None if one was spawned
        during the step (it has no start)."""
        sx, sy, store = frame.start_x, frame.start_y, self.bodies.store
        if rows.size and sx.size <= int(rows.max()):
            return None
        return store.x[rows] - sx[rows], store.y[rows] - sy[rows]

    def _support_gaps(self, frame: StepFrame, ra: IntpArray, rb: IntpArray, nx: F64Array, ny: F64Array) -> F64Array:
        """How far the step's movement took last step's pairs apart along their normal, as a depth
        (<= 0; the caller subtracts the gap they ended last step with): a pair that fell together
        stays where it was (and is pushed apart again if a push below makes them overlap), one
        flying apart starts this much farther from touching."""
        ma, mb = self._moved(frame, ra), self._moved(frame, rb)
        if ra.size == 0 or ma is None or mb is None:
            return np.zeros(ra.size)
        gap = (mb[0] - ma[0]) * nx + (mb[1] - ma[1]) * ny
        return np.minimum(-gap, 0.0)

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
        known = np.sort(pair_keys(cs.ea, cs.eb))
        store = self.bodies.store
        keep = ~sorted_member(pair_keys(ea, eb), known) & (ra < store.n) & (rb < store.n)
        return self.solid_pairs(ra[keep], rb[keep], ea[keep], eb[keep])

    def solid_pairs(self, ra: IntpArray, rb: IntpArray, ea: I64Array, eb: I64Array) -> Pairs:
        """The pairs among ``(ra, rb, ea, eb)`` the response may act on: hitboxes whose layers
        meet, neither a sensor nor a one-way platform, at least one body movable."""
        store = self.bodies.store
        ok = (ra >= 0) & (rb >= 0)
        ra, rb, ea, eb = ra[ok], rb[ok], ea[ok], eb[ok]
        ok = self._takes_part(ra, rb) & ~(store.one_way[ra] | store.one_way[rb]) & filter_layers(store, ra, rb)
        return ra[ok], rb[ok], ea[ok], eb[ok]

    def _takes_part(self, ra: IntpArray, rb: IntpArray) -> BoolArray:
        """Mask of the pairs the response may act on by their bodies alone: both still have a
        hitbox (a system may have removed one), neither is a sensor, and at least one is movable
        (sleeping bodies keep still)."""
        store = self.bodies.store
        ok = (store.kind[ra] >= 0) & (store.kind[rb] >= 0) & ~(store.sensor[ra] | store.sensor[rb])
        return ok & (store.movable(ra) | store.movable(rb))

    # --- geometry the solve asks for ---------------------------------------------------------

    def redirect(
        self, ra: IntpArray, rb: IntpArray, nx: F64Array, ny: F64Array, depth: F64Array, hit: BoolArray,
    ) -> None:
        """Re-aim (in place) pushes of bodies deep inside a static box (:meth:`_deep_inside`),
        and pushes that would leave a tile through a face another tile covers."""
        b = self.bodies
        if b.n_static == 0:
            return
        self._deep_inside(ra, rb, nx, ny, depth, hit)
        rank = depth.copy()
        self.internal_faces.redirect(b.store, b.geometry, b.hash, b.rows_of, ra, rb, nx, ny, depth, hit, rank)

    def _deep_inside(self, ra: IntpArray, rb: IntpArray, nx: F64Array, ny: F64Array, depth: F64Array,
                     hit: BoolArray) -> None:
        """Re-aim (in place) the pushes of movable bodies whose centre lies inside a static AABB.

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
        static_a = (store.body[ra] == STATIC) & (store.kind[ra] == KIND_AABB)
        static_b = (store.body[rb] == STATIC) & (store.kind[rb] == KIND_AABB)
        pick = np.flatnonzero(hit & (static_a ^ static_b))
        if pick.size == 0:
            return
        flip = static_b[pick]  # the static box is b: the normal (a to b) is the push, negated
        s = np.where(flip, rb[pick], ra[pick])
        m = np.where(flip, ra[pick], rb[pick])
        geom = self.bodies.geometry  # (the callers' measures brought the origins up to date)
        cx, cy = geom.hx[m], geom.hy[m]
        inside = (geom.minx[s] < cx) & (cx < geom.maxx[s]) & (geom.miny[s] < cy) & (cy < geom.maxy[s])
        if not inside.any():
            return
        pick, flip, s, m, cx, cy = pick[inside], flip[inside], s[inside], m[inside], cx[inside], cy[inside]
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

    def static_candidates(self, rows: IntpArray, margin: F64Array, known: I64Array) -> Pairs:
        """Pairs of the bodies ``rows`` with the static bodies their bounds, grown by ``margin`` (per
        row), meet where they stand, other than the pairs whose keys are in ``known`` (sorted):
        ``(rows a, rows b, entities a, entities b)``, as :meth:`candidate_pairs`. Pushes within the
        margin can bring a body only to these statics.

        Kept from step to step: a body's statics are looked up (with twice the margin) again only
        once it has moved more than the margin since, or the statics changed; a resting pile asks
        the static hash nothing."""
        bodies = self.bodies
        store = bodies.store
        empty = np.zeros(0, dtype=np.int64)
        ok = np.isfinite(margin)
        rows, margin = rows[ok], margin[ok]
        if rows.size == 0 or bodies.n_static == 0:
            return empty, empty, empty, empty
        cache = self._static_cache()
        far = ~(np.abs(store.x[rows] - cache.x[rows]) + np.abs(store.y[rows] - cache.y[rows]) <= margin)
        if far.any():
            cache.refresh(bodies, rows[far], 2.0 * margin[far])
        ea, eb = cache.pairs_of(store.n, rows)
        keep = ~sorted_member(pair_keys(ea, eb), known)
        ea, eb = ea[keep], eb[keep]
        return self.solid_pairs(bodies.rows_of(ea), bodies.rows_of(eb), ea, eb)

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
