"""The response stage: push overlapping bodies apart, then stop (or bounce) their approach.

Each step it gathers this step's contacts and the pairs it acted on last step (bodies resting on
each other fall by the same amount and merely touch: those pairs stay in the solve, with the gap
the step's motion opened), keeps the solid ones (not sensors, at least one movable body, one-way
platforms only when landed on) and re-aims pushes away from the internal faces of tiles. Then:

1. **Positions.** The solver (:mod:`framework.systems.contact_solver`) finds the push-outs that
   leave no contact overlapping, all contacts at once, warm started with last step's pushes: a
   resting pile is solved in its first pass and stays exactly where it is. Contacts with
   immovable bodies (static, kinematic, infinite mass, asleep) are then measured again with the
   geometry, and solved again while one still overlaps: the axis of such a push matters (tile
   seams, corners). Bodies pushed by dynamic bodies into static geometry they did not touch when
   the step's contacts were found get those contacts too (late contacts).
2. **Velocities.** The contacts left touching stop closing: the solver removes their approaching
   normal velocity, all at once and warm started with last step's impulses, so a pile's
   velocities settle as a whole. A contact that closed faster than gravity brings in two steps
   then bounces with the pair's restitution; a bounce off an immovable body first gives up the
   potential energy the push-out added against gravity, so an elastic ball never climbs higher
   than it started.

What was applied is ``frame.resolved``; the pairs acted on, with their pushes and impulses (the
next step's warm start), are ``frame.support``.
"""

from __future__ import annotations

import math

import numpy as np

from ..collision import batch
from ..collision.broad_phase import SpatialHash
from ..events import pair_keys, sorted_member
from ..frame import NO_RESOLVED, NO_SUPPORT, StepFrame
from . import contact_solver as solver
from .internal_faces import InternalFaces
from .narrow_phase import filter_layers, pair_contacts
from .stage import Stage

__all__ = ["Response"]

# Solver passes at most per response iteration (Scene.response_iterations): passes stop once
# nothing changes (a pile warm started from the last step needs one or two, a fresh one dozens);
# a small solve may take up to MAX_PASSES, within PASS_BUDGET contact visits (nanoseconds each).
SOLVER_PASSES = 4
PASS_BUDGET = 25_000
MAX_PASSES = 16
# Passes stop once no push (impulse) changes by more than this much of the bodies' size (speed).
TOLERANCE = 1e-9
# A body pushed farther than this fraction of its size within a step is looked at again with the
# static hash (late contacts); nearer statics are among the broad phase's pairs.
FAR = 0.01
# A pair kept from last step stays in the solve while its gap is at most this fraction of the
# smaller body's size (farther apart, it is no longer a resting contact).
KEEP_GAP = 0.25


class _Contacts:
    """The contacts of one solve, as columns: rows and entities of the two bodies, normal (a to b),
    depth (> 0 overlap, <= 0 a kept pair's gap), whether each overlaps now (``alive0``), and the
    warm start (last step's push and impulse of the pair)."""

    def __init__(self, ra, rb, ea, eb, nx, ny, depth, alive0, push0, impulse0) -> None:
        self.ra, self.rb, self.ea, self.eb = ra, rb, ea, eb
        self.nx, self.ny, self.depth, self.alive0 = nx, ny, depth, alive0
        self.push0, self.impulse0 = push0, impulse0

    def take(self, idx: np.ndarray) -> _Contacts:
        return _Contacts(*(v[idx] for v in (self.ra, self.rb, self.ea, self.eb, self.nx, self.ny, self.depth,
                                            self.alive0, self.push0, self.impulse0)))

    @property
    def size(self) -> int:
        return int(self.ra.size)


class Response(Stage):
    """Resolve the step's solid contacts; fill ``frame.resolved`` and ``frame.support``."""

    name = "response"
    needs = frozenset({"response"})

    def __init__(self, pipeline) -> None:
        super().__init__(pipeline)
        self.internal_faces = InternalFaces()

    def run(self, frame: StepFrame) -> bool:
        store = self.bodies.store
        cs = self._gather(frame)
        frame.support = NO_SUPPORT
        frame.resolved = NO_RESOLVED
        if cs.size and cs.ra.max() >= store.n:  # rows spawned mid-step are not in this step
            return False
        cs = cs.take(np.flatnonzero(self._solid(frame, cs)))
        if cs.size == 0:
            return True
        solve = _Solve(self, frame, cs)
        solve.positions()
        solve.velocities()
        solve.record(frame)
        return True

    # --- which contacts ----------------------------------------------------------------------

    def _gather(self, frame: StepFrame) -> _Contacts:
        """This step's contacts (with last step's push and impulse where the pair was acted on),
        plus last step's pairs that no longer overlap but are still close (both bodies still
        there, with hitboxes whose layers meet)."""
        store, bodies = self.bodies.store, self.bodies
        c = frame.contacts
        sa, sb, snx, sny, spush, simp, ssep = frame.support
        now_keys, kept_keys = pair_keys(c.a, c.b), pair_keys(sa, sb)
        push0, impulse0 = np.zeros(c.a.size), np.zeros(c.a.size)
        if kept_keys.size:  # the warm start of the pairs found again
            at = np.minimum(np.searchsorted(kept_keys, now_keys), kept_keys.size - 1)
            found = kept_keys[at] == now_keys
            push0[found], impulse0[found] = spush[at[found]], simp[at[found]]
        old = np.flatnonzero(~sorted_member(kept_keys, now_keys))
        sra, srb = bodies.rows_of(sa[old]), bodies.rows_of(sb[old])
        live = (sra >= 0) & (srb >= 0)
        ok = np.flatnonzero(live)
        live[ok] = (store.kind[sra[ok]] >= 0) & (store.kind[srb[ok]] >= 0) & filter_layers(store, sra[ok], srb[ok])
        old, sra, srb = old[live], sra[live], srb[live]
        gaps = self._support_gaps(frame, sra, srb, snx[old], sny[old]) - ssep[old]
        near = gaps >= -KEEP_GAP * np.minimum(store.bound[sra], store.bound[srb])
        old, sra, srb, gaps = old[near], sra[near], srb[near], gaps[near]
        cat = np.concatenate
        return _Contacts(
            cat([frame.contact_rows[0], sra]), cat([frame.contact_rows[1], srb]), cat([c.a, sa[old]]),
            cat([c.b, sb[old]]), cat([c.nx, snx[old]]), cat([c.ny, sny[old]]), cat([c.depth, gaps]),
            np.arange(c.a.size + old.size) < c.a.size, cat([push0, spush[old]]), cat([impulse0, simp[old]]))

    def _solid(self, frame: StepFrame, cs: _Contacts) -> np.ndarray:
        """Mask of the contacts the response acts on."""
        store = self.bodies.store
        ra, rb = cs.ra, cs.rb
        inv, asleep = store.inv_mass, store.asleep  # sleeping bodies keep still
        movable_a, movable_b = (inv[ra] > 0) & ~asleep[ra], (inv[rb] > 0) & ~asleep[rb]
        solid = ~(store.sensor[ra] | store.sensor[rb]) & (movable_a | movable_b)
        solid &= (store.kind[ra] >= 0) & (store.kind[rb] >= 0)  # a system may have removed a hitbox
        # A body a system spoiled (NaN) is left alone, so the step reports it as written and the
        # bad value spreads to no other body.
        solid &= np.isfinite(store.vx[ra] + store.vy[ra] + store.vx[rb] + store.vy[rb])
        one_way = store.one_way[ra] | store.one_way[rb]
        if one_way.any():
            solid &= ~one_way | self._lands_on_one_way(frame, cs)
        return solid

    def _support_gaps(self, frame: StepFrame, ra, rb, nx, ny) -> np.ndarray:
        """How far the step's movement took last step's pairs apart along their normal, as a depth
        (<= 0; the caller subtracts the gap they ended last step with): a pair that fell together
        stays where it was (and is pushed apart again if a push below makes them overlap), one
        flying apart starts this much farther from touching."""
        sx, sy, store = frame.start_x, frame.start_y, self.bodies.store
        if ra.size == 0 or sx.size <= max(int(ra.max()), int(rb.max())):
            return np.zeros(ra.size)
        gap = (((store.x[rb] - sx[rb]) - (store.x[ra] - sx[ra])) * nx
               + ((store.y[rb] - sy[rb]) - (store.y[ra] - sy[ra])) * ny)
        return np.minimum(-gap, 0.0)

    def _lands_on_one_way(self, frame: StepFrame, cs: _Contacts) -> np.ndarray:
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

    def candidate_pairs(self, frame: StepFrame, cs: _Contacts) -> tuple[np.ndarray, ...]:
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

    def solid_pairs(self, ra, rb, ea, eb) -> tuple[np.ndarray, ...]:
        """The pairs among ``(ra, rb, ea, eb)`` the response may act on: hitboxes whose layers
        meet, neither a sensor nor a one-way platform, at least one body movable."""
        store = self.bodies.store
        inv, asleep = store.inv_mass, store.asleep
        ok = (ra >= 0) & (rb >= 0)
        ra, rb, ea, eb = ra[ok], rb[ok], ea[ok], eb[ok]
        ok = (store.kind[ra] >= 0) & (store.kind[rb] >= 0) & ~(store.sensor[ra] | store.sensor[rb])
        ok &= ~(store.one_way[ra] | store.one_way[rb]) & filter_layers(store, ra, rb)
        ok &= ((inv[ra] > 0) & ~asleep[ra]) | ((inv[rb] > 0) & ~asleep[rb])
        return ra[ok], rb[ok], ea[ok], eb[ok]

    # --- geometry the solve asks for ---------------------------------------------------------

    def redirect(self, ra, rb, nx, ny, depth, hit) -> None:
        """Re-aim (in place) pushes that would leave a tile through a face another tile covers."""
        b = self.bodies
        if b.n_static == 0:
            return
        rank = depth.copy()
        self.internal_faces.redirect(b.store, b.geometry, b.hash, b.rows_of, ra, rb, nx, ny, depth, hit, rank)

    def remeasure(self, ra: np.ndarray, rb: np.ndarray) -> batch.ContactArrays:
        """The pairs ``(ra, rb)`` measured again where the bodies now are (pairs within rounding of
        touching count as apart), pushes re-aimed off internal faces. Only these rows' hitbox
        origins are brought up to date (a full update waits for the next reader)."""
        store, geom = self.bodies.store, self.bodies.geometry
        if geom.version != store.version:
            geom.update(store)
        elif geom.has_offset:
            geom.update_rows(store, np.concatenate([ra, rb]))
        else:  # origins are the positions
            geom.hx, geom.hy = store.x, store.y
        r = pair_contacts(store, geom, ra, rb, remeasure=True)
        self.redirect(ra, rb, r.nx, r.ny, r.depth, r.hit)
        return r

    def new_static_contacts(self, rows: np.ndarray, known: np.ndarray):
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
        return ea[h], eb[h], ra[h], rb[h], batch.ContactArrays(*(v[h] for v in r))


class _Solve:
    """One step's solve over the solid contacts ``cs``, on local copies of the bodies' positions and
    velocities (written to the store when done)."""

    def __init__(self, stage: Response, frame: StepFrame, cs: _Contacts) -> None:
        self.stage, self.frame = stage, frame
        self.store = store = stage.bodies.store
        self.gravity = stage.pipeline.active_gravity()
        its = stage.pipeline.response_iterations
        self.iterations = max(SOLVER_PASSES * its, min(MAX_PASSES * its, PASS_BUDGET * its // cs.size))
        self.dt = frame.dt
        overlapping = cs.alive0.copy()
        stage.redirect(cs.ra, cs.rb, cs.nx, cs.ny, cs.depth, cs.alive0)
        dropped = overlapping & ~cs.alive0  # the covering tile's own contact holds the body
        self.cs = cs = cs.take(np.flatnonzero(~dropped)) if dropped.any() else cs
        self.rows, self.local = _local_numbers(store.n, np.concatenate([cs.ra, cs.rb]))
        self.tolerance = TOLERANCE * float(store.bound[self.rows].max())
        self.dirty = np.ones(cs.size, dtype=bool)  # the contacts the position solver is to look at
        self._columns()

    def _columns(self) -> None:
        """Per-contact columns the solver reads, and how far a body may move in one run of the
        position solver (after the contact set changed)."""
        store, cs = self.store, self.cs
        rows = self.rows
        if self.stage.bodies.n_static:
            half = np.where(store.hw[rows] > 0.0, np.minimum(store.hw[rows], store.hh[rows]), 0.5 * store.bound[rows])
            self.reach = 0.5 * half
        else:  # (nothing to be pushed through)
            self.reach = np.full(rows.size, np.inf)
        C = cs.size
        self.a, self.b = self.local[:C], self.local[C:]
        wa = np.where(store.asleep[cs.ra], 0.0, store.inv_mass[cs.ra])  # a sleeper keeps still
        wb = np.where(store.asleep[cs.rb], 0.0, store.inv_mass[cs.rb])
        w = 1.0 / (wa + wb)
        self.share_a, self.share_b = wa * w, wb * w
        self.immovable = (wa == 0.0) | (wb == 0.0)
        self.order = self._order()
        self.position_shares = self._shock_shares()

    def _shock_shares(self) -> tuple[np.ndarray, np.ndarray]:
        """The shares of the position pushes (shock propagation). In a pair resting one on the other
        (normal within 60 degrees of the vertical) whose lower body rests on something immovable
        (the floor, or a body resting on it...), the lower body keeps still and the push lifts the
        upper one: a stack is pushed out from the ground up, each body exactly onto the one below
        (Gauss-Seidel alone converges on a stack only geometrically, and a body on top would press
        the one below into it). Elsewhere the push is shared by inverse mass. (Velocities: see
        :meth:`_velocity_shares`.)"""
        gx, gy = self.gravity
        g = math.hypot(gx, gy)
        both = ~self.immovable
        if g == 0.0 or not both.any():
            self.b_on_a = self.a_on_b = None
            return self.share_a, self.share_b
        cs = self.cs
        up = -(cs.nx * gx + cs.ny * gy) / g  # > 0.5: b rests on a
        fixed_a, fixed_b = self.share_a == 0.0, self.share_b == 0.0
        held = solver.supported(self.order, self.a, self.b, up, fixed_a, fixed_b, self.rows.size)
        self.b_on_a = b_on_a = both & (up > 0.5) & held[self.a]
        self.a_on_b = a_on_b = both & (up < -0.5) & held[self.b]
        return self._lower_stays(b_on_a, a_on_b)

    def _lower_stays(self, b_on_a: np.ndarray, a_on_b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Shares in which the lower body of the pairs ``b_on_a`` / ``a_on_b`` keeps still."""
        share_a = np.where(b_on_a, 0.0, np.where(a_on_b, 1.0, self.share_a))
        share_b = np.where(b_on_a, 1.0, np.where(a_on_b, 0.0, self.share_b))
        return share_a, share_b

    def _order(self) -> np.ndarray:
        """Contacts from the bottom of a pile up (contacts with immovable bodies first): a push
        then travels up a stack within one pass. Without gravity, in pair order."""
        gx, gy = self.gravity
        g = math.hypot(gx, gy)
        if g == 0.0:
            return np.arange(self.cs.size)
        store, cs = self.store, self.cs
        up_a = -(store.x[cs.ra] * gx + store.y[cs.ra] * gy) / g
        up_b = -(store.x[cs.rb] * gx + store.y[cs.rb] * gy) / g
        height = np.where(self.immovable, -np.inf, np.minimum(up_a, up_b))
        return np.argsort(height, kind="stable")

    # --- positions ---------------------------------------------------------------------------

    def positions(self) -> None:
        """Push every solid contact out of overlap, in rounds: after each, the contacts with
        immovable bodies are measured again with the geometry, and the pairs the pushes made
        overlap are added (dynamic pairs the broad phase found touching, statics the pushed
        bodies were shoved into), until nothing changes. If a contact with an immovable body still
        overlaps after them (a crowd spawned in a heap), rounds over those contacts alone, so no
        body ends the step inside static geometry (overlaps between dynamic bodies are left to the
        next step)."""
        store, cs = self.store, self.cs
        self.x0, self.y0 = store.x[self.rows].copy(), store.y[self.rows].copy()
        self.push = self._warm_pushes(cs.push0)
        share_a, share_b = self.position_shares
        self.dx, self.dy = solver.warm_start(self.a, self.b, cs.nx, cs.ny, share_a, share_b, self.push, self.rows.size)
        self.far_done = np.zeros(self.rows.size, dtype=bool)
        self.candidates = self.stage.candidate_pairs(self.frame, cs)
        rounds = 2 * max(2, self.stage.pipeline.response_iterations)
        for _round in range(rounds):
            held_back = self._solve(self.order)
            overlapping = self._measure_immovable()
            grew = self._far_candidates()
            grew = self._new_dynamic_contacts() or grew
            grew = self._late_contacts() or grew
            if not (held_back or overlapping or grew):
                return
        for _round in range(rounds):
            self._solve(self.order[self.immovable[self.order]])
            if not self._measure_immovable():
                return

    def _warm_pushes(self, push0: np.ndarray) -> np.ndarray:
        """Last step's pushes as this step's first guess, scaled down where they would move a body
        farther than its reach (see :meth:`_solve`) before the solver has looked at anything."""
        if np.isfinite(self.reach).all() and push0.any():
            share_a, share_b = self.position_shares
            cs = self.cs
            wx, wy = solver.warm_start(self.a, self.b, cs.nx, cs.ny, share_a, share_b, push0, self.rows.size)
            far = np.hypot(wx, wy)
            scale = np.minimum(1.0, self.reach / np.maximum(far, 1e-300))
            return push0 * np.minimum(scale[self.a], scale[self.b])
        return push0.copy()

    def _solve(self, order: np.ndarray) -> bool:
        """One run of the position solver over the contacts ``order``; the bodies are then placed.
        Whether a push was held back.

        In a scene with static bodies, a body moves at most half its half-thickness in a run (bodies
        spawned on one spot push each other far): the geometry then sees every static it is pushed
        into while that static is still nearer the face it entered by, so the next round pushes it
        back out the way it came rather than on through."""
        cs = self.cs
        share_a, share_b = self.position_shares
        _passes, held = solver.solve_positions(order, self.a, self.b, cs.nx, cs.ny, -cs.depth, share_a, share_b,
                                               self.push, self.dx, self.dy, self.iterations, self.tolerance,
                                               self.dirty, self.reach)
        self._place()
        return bool(held)

    def _place(self) -> None:
        moved = np.flatnonzero((self.dx != 0.0) | (self.dy != 0.0))
        if moved.size:
            self.store.place(self.rows[moved], self.x0[moved] + self.dx[moved], self.y0[moved] + self.dy[moved])

    def _shift(self, idx: np.ndarray) -> np.ndarray:
        """How far the solve has moved the bodies of contacts ``idx`` apart along their normals."""
        cs, a, b = self.cs, self.a[idx], self.b[idx]
        return (self.dx[b] - self.dx[a]) * cs.nx[idx] + (self.dy[b] - self.dy[a]) * cs.ny[idx]

    def _separations(self) -> np.ndarray:
        """Every contact's separation where the bodies now stand, along its normal (linear)."""
        return self._shift(np.arange(self.cs.size)) - self.cs.depth

    def _measure_immovable(self) -> bool:
        """Measure the pushed contacts with immovable bodies again; their depths (relative to where
        the solve began) follow the geometry. Whether one still overlaps."""
        cs = self.cs
        moved = (self.dx != 0.0) | (self.dy != 0.0)
        check = np.flatnonzero(self.immovable & (moved[self.a] | moved[self.b]))
        if check.size == 0:
            return False
        r = self.stage.remeasure(cs.ra[check], cs.rb[check])
        apart = check[~r.hit]  # touching, or a sliver within rounding: no longer pushed along
        cs.depth[apart] = np.minimum(cs.depth[apart], self._shift(apart))
        if not r.hit.any():
            return False
        hit = check[r.hit]
        cs.nx[hit], cs.ny[hit] = r.nx[r.hit], r.ny[r.hit]
        cs.depth[hit] = r.depth[r.hit] + self._shift(hit)
        self.dirty[hit] = True
        # Another round only for an overlap the solver would act on (not one within its tolerance).
        return bool((r.depth[r.hit] > self.tolerance).any())

    def _moved_rows(self) -> np.ndarray:
        """Store rows (sorted) the solve has moved."""
        return self.rows[(self.dx != 0.0) | (self.dy != 0.0)]

    def _far_candidates(self) -> bool:
        """Pushes that moved a body more than its solver reach (a heap spawned on one spot) may
        bring it to bodies the broad phase did not pair it with: the pairs of those bodies where
        everything now stands become candidates. Whether any did."""
        far = (np.hypot(self.dx, self.dy) > self.reach) & ~self.far_done
        if not far.any():
            return False
        self.far_done |= far
        bodies = self.stage.bodies
        store, geom = bodies.store, bodies.ensure_geometry()
        rows = store.active()[2]
        rows = rows[store.kind[rows] >= 0]
        ea, eb = SpatialHash(bodies.hash.cell_size).pairs(geom.minx[rows], geom.miny[rows], geom.maxx[rows],
                                                          geom.maxy[rows], store.entity[rows])
        far_ents = np.sort(store.entity[self.rows[far]])
        keep = sorted_member(ea, far_ents) | sorted_member(eb, far_ents)
        ca, cb = self.candidates[2], self.candidates[3]
        known = np.sort(np.concatenate([pair_keys(self.cs.ea, self.cs.eb), pair_keys(ca, cb)]))
        keep &= ~sorted_member(pair_keys(ea, eb), known)
        if not keep.any():
            return False
        ea, eb = ea[keep], eb[keep]
        new = self.stage.solid_pairs(bodies.rows_of(ea), bodies.rows_of(eb), ea, eb)
        self.candidates = tuple(np.concatenate([c, n]) for c, n in zip(self.candidates, new))
        return bool(new[0].size)

    def _new_dynamic_contacts(self) -> bool:
        """Add the candidate pairs (touching or near when the step's contacts were found) that the
        pushes made overlap. Whether there were any."""
        ra, rb, ea, eb = self.candidates
        if ra.size == 0:
            return False
        moved = self._moved_rows()
        look = np.flatnonzero(sorted_member(ra, moved) | sorted_member(rb, moved))
        if look.size == 0:
            return False
        r = self.stage.remeasure(ra[look], rb[look])
        h = np.flatnonzero(r.hit & (r.depth > self.tolerance))  # (a sliver is left to the next step)
        if h.size == 0:
            return False
        new = look[h]
        keep = np.ones(ra.size, dtype=bool)
        keep[new] = False
        self.candidates = (ra[keep], rb[keep], ea[keep], eb[keep])
        self._add(ra[new], rb[new], ea[new], eb[new], batch.ContactArrays(*(v[h] for v in r)))
        return True

    def _late_contacts(self) -> bool:
        """Add the contacts with statics that bodies pushed by dynamic bodies were shoved into (they
        were not touching them when the step's contacts were found). Whether there were any.

        Statics the broad phase found touching or near a body are candidates already (see
        :meth:`_new_dynamic_contacts`); the static hash is asked again only about bodies pushed
        farther than a hundredth of their size (a crowd spawned in a heap), which is what could
        reach a static that was not near. (A resting pile's bodies move by a step of gravity.)"""
        cs = self.cs
        both = ~self.immovable & (self.push > 0.0)
        pushed = np.zeros(self.rows.size, dtype=bool)
        pushed[self.a[both]] = pushed[self.b[both]] = True
        bound = self.store.bound[self.rows]
        pushed &= np.hypot(self.dx, self.dy) > FAR * bound
        if not pushed.any():
            return False
        extra = self.stage.new_static_contacts(self.rows[pushed], np.sort(pair_keys(cs.ea, cs.eb)))
        if extra is None:
            return False
        ea, eb, ra, rb, r = extra
        self.frame.counters["late_contacts"] += int(ea.size)
        self._add(ra, rb, ea, eb, r)
        return True

    def _add(self, ra, rb, ea, eb, r) -> None:
        """Append contacts measured where the bodies stand now (their depths are made relative to
        where the solve began, like every other contact's)."""
        old_rows = self.rows
        rows, local = _local_numbers(self.store.n, np.concatenate([old_rows, ra, rb]))
        remap = local[: old_rows.size]
        new_a, new_b = local[old_rows.size: old_rows.size + ra.size], local[old_rows.size + ra.size:]
        dx, dy = np.zeros(rows.size), np.zeros(rows.size)
        dx[remap], dy[remap] = self.dx, self.dy
        x0, y0 = self.store.x[rows].copy(), self.store.y[rows].copy()
        x0[remap], y0[remap] = self.x0, self.y0
        shift = (dx[new_b] - dx[new_a]) * r.nx + (dy[new_b] - dy[new_a]) * r.ny
        cs, cat, zeros = self.cs, np.concatenate, np.zeros(ra.size)
        self.cs = _Contacts(cat([cs.ra, ra]), cat([cs.rb, rb]), cat([cs.ea, ea]), cat([cs.eb, eb]),
                            cat([cs.nx, r.nx]), cat([cs.ny, r.ny]), cat([cs.depth, r.depth + shift]),
                            cat([cs.alive0, np.ones(ra.size, dtype=bool)]), cat([cs.push0, zeros]),
                            cat([cs.impulse0, zeros]))
        far_done = np.zeros(rows.size, dtype=bool)
        far_done[remap] = self.far_done
        self.rows, self.dx, self.dy, self.x0, self.y0, self.far_done = rows, dx, dy, x0, y0, far_done
        self.local = cat([remap[self.a], new_a, remap[self.b], new_b])
        self.push = cat([self.push, zeros])
        self.dirty = cat([self.dirty, np.ones(ra.size, dtype=bool)])
        self._columns()

    # --- velocities --------------------------------------------------------------------------

    def velocities(self) -> None:
        """Stop the touching contacts closing, then bounce the ones that hit."""
        store, cs = self.store, self.cs
        self.touching = self.push > 0.0  # (a contact merely touching, never pushed, does not brake)
        vx, vy = store.vx[self.rows].copy(), store.vy[self.rows].copy()
        a, b = self.a, self.b
        u = (vx[b] - vx[a]) * cs.nx + (vy[b] - vy[a]) * cs.ny  # closing speed before the solve
        act = np.flatnonzero(self.touching)
        order = self.order[self.touching[self.order]]
        share_a, share_b = self._velocity_shares(vx, vy)
        self.impulse = np.where(self.touching, cs.impulse0, 0.0)
        wx, wy = solver.warm_start(a, b, cs.nx, cs.ny, share_a, share_b, self.impulse, self.rows.size)
        vx += wx
        vy += wy
        target = np.zeros(cs.size)
        gx, gy = self.gravity
        tol = TOLERANCE * (float(np.abs(u).max(initial=0.0)) + math.hypot(gx, gy) * self.dt)
        solver.solve_velocities(order, a, b, cs.nx, cs.ny, target, share_a, share_b, self.impulse, vx, vy,
                                self.iterations, tol, np.ones(cs.size, dtype=bool))
        bounce = self._bounce_targets(u, act)
        movable = ~((store.inv_mass[self.rows] == 0.0) | store.asleep[self.rows])
        if bounce is not None:
            vx_in, vy_in = vx.copy(), vy.copy()
            solver.solve_velocities(order, a, b, cs.nx, cs.ny, bounce, share_a, share_b, self.impulse,
                                    vx, vy, self.iterations, tol, np.ones(cs.size, dtype=bool))
            if not self.solo[bounce > 0.0].all():
                self._no_energy_made(bounce, movable, vx_in, vy_in, vx, vy)
        rows = self.rows[movable]
        store.vx[rows], store.vy[rows] = vx[movable], vy[movable]

    def _velocity_shares(self, vx: np.ndarray, vy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Shares of the velocity impulses. As for the pushes, the lower body of a supported resting
        pair keeps still (a pile's weight goes straight down to the ground within one pass; a body
        high in a pile cannot keep a falling speed that only the pushes hide), except where the
        lower body moves into the upper one faster than a body at rest does (it bounced): an
        immovable body moving up would hand the upper one a bounce off a moving wall and keep its
        own speed, making energy; those pairs meet as the dynamic bodies they are."""
        if self.b_on_a is None or not (self.b_on_a.any() or self.a_on_b.any()):
            return self.share_a, self.share_b
        cs, a, b = self.cs, self.a, self.b
        gx, gy = self.gravity
        resting_speed = 2.0 * np.abs(gx * cs.nx + gy * cs.ny) * self.dt
        # the lower body's speed toward the upper one
        a_up = vx[a] * cs.nx + vy[a] * cs.ny
        b_down = -(vx[b] * cs.nx + vy[b] * cs.ny)
        b_on_a = self.b_on_a & (a_up <= resting_speed)
        a_on_b = self.a_on_b & (b_down <= resting_speed)
        return self._lower_stays(b_on_a, a_on_b)

    def _no_energy_made(self, bounce, movable, vx_in, vy_in, vx, vy) -> None:
        """Bounces hand back (some of) the energy the stopping took, never more than the bodies had
        before the response: where they would end with more kinetic energy (bodies in several
        bounces at once; rounding), the bounces are scaled back until they do not. (Not called
        when every bounce is a lone bounce off an immovable body: its speed is energy-exact by
        construction, see :func:`_bounce_speed`.) Bounces off a moving kinematic body may add
        energy, as they should: then nothing is scaled."""
        store, cs = self.store, self.cs
        hit = bounce > 0.0
        kinematic = (store.body[cs.ra[hit]] == 1) | (store.body[cs.rb[hit]] == 1)
        if kinematic.any():
            return
        mass = np.where(movable, 1.0 / np.where(movable, store.inv_mass[self.rows], 1.0), 0.0)
        v0x, v0y = store.vx[self.rows], store.vy[self.rows]
        before = float(np.sum(mass * (v0x * v0x + v0y * v0y)))
        # Kinetic energy (twice) along the blend v_in + t (v - v_in): c0 + c1 t + c2 t^2.
        dx, dy = vx - vx_in, vy - vy_in
        c0 = float(np.sum(mass * (vx_in * vx_in + vy_in * vy_in)))
        c1 = 2.0 * float(np.sum(mass * (vx_in * dx + vy_in * dy)))
        c2 = float(np.sum(mass * (dx * dx + dy * dy)))
        if c0 + c1 + c2 <= before or c2 <= 0.0:
            return
        before -= 16.0 * np.finfo(float).eps * before  # (scaled: a margin for the rounding of any way of summing)
        disc = max(c1 * c1 - 4.0 * c2 * (c0 - before), 0.0)
        t = max(0.0, min(1.0, (-c1 + math.sqrt(disc)) / (2.0 * c2)))
        t = math.nextafter(t, 0.0)  # (rounding: stay on the safe side)
        vx[:], vy[:] = vx_in + t * dx, vy_in + t * dy

    def _bounce_targets(self, u: np.ndarray, act: np.ndarray) -> np.ndarray | None:
        """The speed each touching contact must part at (0: no bounce), or None if none bounces.

        An approach no faster than gravity gives in two steps along the normal (``2 |g.n| dt``) is
        a body at rest, not a bounce: without that threshold a bouncy body on the floor would hop
        by ``e g dt`` every step forever."""
        store, cs = self.store, self.cs
        rest = np.maximum(store.restitution[cs.ra], store.restitution[cs.rb])
        gx, gy = self.gravity
        g_n = gx * cs.nx + gy * cs.ny
        resting_speed = 2.0 * np.abs(g_n) * self.dt
        hits = np.zeros(cs.size, dtype=bool)
        hits[act] = (rest[act] > 0.0) & (-u[act] > resting_speed[act]) & cs.alive0[act]
        self.solo = np.zeros(cs.size, dtype=bool)
        if not hits.any():
            return None
        target = np.zeros(cs.size)
        target[hits] = -rest[hits] * u[hits]
        # A lone bounce off an immovable body gives up the potential energy its push-out added.
        solo = hits & self.immovable & (np.bincount(self.a[hits], minlength=self.rows.size)[self.a]
                                        + np.bincount(self.b[hits], minlength=self.rows.size)[self.b] <= 2)
        self.solo = solo
        if solo.any():
            sgn = np.where(self.share_b[solo] > 0.0, 1.0, -1.0)  # the mobile body moves along sgn * n
            target[solo] = rest[solo] * _bounce_speed(u[solo], -g_n[solo] * sgn, self.push[solo], self.dt)
        return target

    # --- results -----------------------------------------------------------------------------

    def record(self, frame: StepFrame) -> None:
        """``frame.resolved`` (sorted by pair) and the pairs acted on, with their push and impulse
        (the next step's warm start)."""
        cs = self.cs
        acted = np.flatnonzero(self.touching | (self.push > 0.0))
        keys = pair_keys(cs.ea[acted], cs.eb[acted])
        order = np.argsort(keys, kind="stable")
        acted = acted[order]
        ea, eb, nx, ny = cs.ea[acted], cs.eb[acted], cs.nx[acted], cs.ny[acted]
        frame.resolved = (ea, eb, nx, ny, self.push[acted])
        gap = np.maximum(self._separations()[acted], 0.0)
        frame.support = (ea, eb, nx, ny, self.push[acted], self.impulse[acted], gap)
        frame.counters["resolved"] = int(acted.size)


def _local_numbers(n: int, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(unique, local)``: the distinct rows (sorted) and each entry's number among them, like
    ``np.unique(rows, return_inverse=True)`` but by a lookup table over the ``n`` rows."""
    seen = np.zeros(n, dtype=bool)
    seen[rows] = True
    unique = np.flatnonzero(seen)
    table = np.empty(n, dtype=np.int64)
    table[unique] = np.arange(unique.size)
    return unique, table[rows]


def _bounce_speed(u: np.ndarray, g: np.ndarray, d: np.ndarray, dt: float) -> np.ndarray:
    """Speed off an immovable surface that keeps the energy of an elastic bounce.

    Semi-implicit Euler under gravity ``g`` (its component against the push-out) conserves
    ``F = v^2/2 + g h - g v dt/2`` exactly in flight (v, h along the push-out; derivation: one
    step changes the three terms by ``-g dt (v0 + v1)/2``, ``g v1 dt`` and ``g^2 dt^2/2``, which
    sum to 0). The push-out raised the body by ``d``; solving ``F_after = F_before`` for the new
    speed, with ``u`` (< 0) the approach speed, gives the positive root of
    ``v^2 - g dt v - (u^2 - g u dt - 2 g d) = 0``. In flight the height at a discrete apex can
    still exceed ``F / g`` by up to ``g dt^2 / 8`` (the last upward step), so a bounce also gives
    up that much: an elastic ball never climbs higher than it started, and loses only that hair
    of height per bounce. No real root: the push-out took more than the energy there was, so the
    body stops.
    """
    gp = np.maximum(g, 0.0)
    k = u * u - g * u * dt - 2.0 * g * d - 0.25 * gp * gp * dt * dt
    disc = g * g * dt * dt + 4.0 * k
    root = 0.5 * (g * dt + np.sqrt(np.maximum(disc, 0.0)))
    return np.where(disc >= 0.0, np.maximum(root, 0.0), 0.0)
