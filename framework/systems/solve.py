"""One step's contact solve: push the solid contacts apart, then stop (or bounce) their approach.

:class:`Solve` works on the contacts the response stage gathered (:class:`Contacts`), on local
copies of their bodies' positions and velocities, with the compiled loops of
:mod:`framework.systems.solver_loops` (and the bookkeeping between them compiled too, in
:mod:`framework.systems.solve_columns` and :mod:`framework.systems.solve_rounds`):

1. **Positions**, in rounds. Each runs the position solver over every contact (warm started with
   last step's pushes); then the contacts with immovable bodies are measured again with the
   geometry (the axis of such a push matters: tile seams, corners), and the pairs the pushes made
   overlap are added (broad-phase pairs that were touching; bodies pushed far, asked again of a
   broad phase; statics they were shoved into). Rounds stop when nothing changes. In a pile, the
   lower body of a resting pair keeps still and the push lifts the upper one (shock propagation),
   so a stack is pushed out from the ground up, exactly.
2. **Velocities**: the contacts that were pushed stop closing (velocity solver, warm started with
   last step's impulses, shared as the pushes are); then those that hit faster than gravity
   brings in two steps bounce with the pair's restitution. A lone bounce off an immovable body
   gives up the potential energy its push-out added (:func:`bounce_speed`); several bounces at
   once never leave more kinetic energy than there was.

Where hitboxes give friction (and the scene has the ``friction`` effect), both halves also work
along each contact (:mod:`framework.systems.friction`): tangential pushes undo the step's slip,
tangential impulses stop the sliding, each within ``mu`` times its normal counterpart; with the
``rotation`` effect they turn the circles they act on. Without friction none of it runs.

Where a box or polygon that turns is in a contact (the ``rotation`` effect), the solve works on
points (:mod:`framework.systems.turning`): each such pair becomes its manifold points, pushes and
impulses turn bodies by their lever arms (the ``*_rigid`` loops), the points against immovable
bodies are measured again between rounds, and a contact with an immovable body that this step's
speeds would close is in the velocity solve too (speculative). A solve without such a body runs
exactly as before.
"""

from __future__ import annotations

import math
from typing import Any, TypeAlias

import numpy as np

from ..arrays import BoolArray, F64Array, I64Array, IntpArray, distinct
from ..collision import batch
from ..collision.broad_phase import SpatialHash
from ..collision.kinds import KIND_CIRCLE, KIND_POLYGON
from ..events import pair_keys, pair_parts, sorted_member
from ..frame import NO_POINTS, Points, StepFrame
from ..store import KINEMATIC
from . import solve_columns as columns
from . import solve_rounds as rounds
from . import solver_loops as solver
from .friction import NO_FRICTION_POSITIONS, NO_FRICTION_VELOCITIES, Friction
from .solve_rounds import apply_measures, known_keys, moved_immovable, number, pending_points, turning_pairs
from .turning import expand, turned_normals

__all__ = ["Contacts", "Pairs", "Solve", "bounce_speed"]

#: Pairs of bodies: rows a, rows b, entities a, entities b.
Pairs: TypeAlias = tuple[IntpArray, IntpArray, I64Array, I64Array]

# Solver passes at most per response iteration (Scene.response_iterations): passes stop once
# nothing changes (a pile warm started from the last step needs one or two, a fresh one dozens);
# a small solve may take up to MAX_PASSES, within PASS_BUDGET contact visits (nanoseconds each).
SOLVER_PASSES = 2
PASS_BUDGET = 8_000
MAX_PASSES = 16
# Passes stop once no push (impulse) changes by more than this much of the bodies' size (speed).
TOLERANCE = 1e-9
# ... and where bodies turn (Gauss-Seidel converges slowly on the coupled turns of a pile: a
# billionth cost a pyramid of 20 rows five rounds of the solver each step: 15 ms a step, against
# 11 ms at 1e-8, 4.7 ms at 1e-6 with the pyramid off by 2e-4 instead of 4e-6)
TOLERANCE_TURNING = 1e-8
# Where bodies turn, contact points this close (of the smaller body's size) are kept for the next step.
NEAR_GAP = 1e-3
# ... and a point measured again that overlaps by less than this (times 1 + the smaller body's size)
# is left to the next step (a round for each hundred-millionth cost a pyramid of 20 rows three
# rounds a step)
POINT_SLACK = 1e-7
# Rounds at most of pushing bodies out of static ones after the solver's rounds ran out (each moves
# a body at most its reach: a body sunk this many reaches deep is left partly inside).
MAX_CLEAR_ROUNDS = 1024
# A pair kept from last step stays in the solve while its gap is at most this fraction of the
# smaller body's size (farther apart, it is no longer a resting contact).
KEEP_GAP = 0.25

# (empty columns: a compiled pass's "none")
_NO_FLAGS = np.zeros(0, dtype=bool)
_NO_FLOATS = np.zeros(0)
_NO_IDS = np.zeros(0, dtype=np.int64)


class Contacts:
    """The contacts of one solve, as columns: rows and entities of the two bodies, normal (a to b),
    depth (> 0 overlap, <= 0 a kept pair's gap), whether each overlaps now (``alive0``), and the
    warm start (last step's push and impulse of the pair, and its friction's tangential push and
    impulse)."""

    ra: IntpArray
    rb: IntpArray
    ea: I64Array
    eb: I64Array
    nx: F64Array
    ny: F64Array
    depth: F64Array
    alive0: BoolArray
    push0: F64Array
    impulse0: F64Array
    tpush0: F64Array
    timpulse0: F64Array
    px: F64Array
    py: F64Array
    slot: I64Array

    def __init__(self, ra, rb, ea, eb, nx, ny, depth, alive0, push0, impulse0, tpush0, timpulse0, px, py,
                 slot=None, *, arms=None) -> None:
        self.ra, self.rb, self.ea, self.eb = ra, rb, ea, eb
        self.nx, self.ny, self.depth, self.alive0 = nx, ny, depth, alive0
        self.push0, self.impulse0, self.tpush0, self.timpulse0 = push0, impulse0, tpush0, timpulse0
        self.px, self.py = px, py  # a point of the contact (0 where not known: a kept pair's)
        # contacts at points (see framework.systems.turning): the point's slot in its pair's
        # manifold, and the lever arms (x, y) from a's and b's centres to it
        self.slot = np.zeros(ra.size, dtype=np.int64) if slot is None else slot
        self.arms = arms

    def columns(self) -> tuple[Any, ...]:  # (columns of several dtypes)
        return (self.ra, self.rb, self.ea, self.eb, self.nx, self.ny, self.depth, self.alive0, self.push0,
                self.impulse0, self.tpush0, self.timpulse0, self.px, self.py, self.slot)

    def take(self, idx: IntpArray) -> Contacts:
        arms = None if self.arms is None else tuple(v[idx] for v in self.arms)
        return Contacts(*(v[idx] for v in self.columns()), arms=arms)

    @property
    def size(self) -> int:
        return int(self.ra.size)


class Solve:
    """One step's solve over the solid contacts ``cs``, on local copies of the bodies' positions and
    velocities (written to the store when done)."""

    # Set by the methods that compute them (declared here: they are read before mypy sees them set).
    ia: F64Array
    ib: F64Array
    rn_a: F64Array
    rn_b: F64Array
    rt_a: F64Array
    rt_b: F64Array
    at_points: BoolArray
    rot0: F64Array
    dturn: F64Array
    b_on_a: BoolArray | None
    a_on_b: BoolArray | None
    position_mu: F64Array | None  # (set whenever ``fpos`` is)

    def __init__(self, stage: Any, frame: StepFrame, cs: Contacts,
                 points: Points = NO_POINTS) -> None:  # stage: the Response
        self.stage, self.frame = stage, frame
        self.store = store = stage.bodies.store
        gx, gy = stage.pipeline.active_gravity()
        self.gravity = (float(gx), float(gy))
        self.g = math.hypot(gx, gy)
        its = stage.pipeline.response_iterations
        self.iterations = max(SOLVER_PASSES * its, min(MAX_PASSES * its, PASS_BUDGET * its // cs.size))
        self.dt = frame.dt
        self.friction = "friction" in stage.pipeline.effects and self.store.has_friction()
        self.rotation = "rotation" in stage.pipeline.effects
        self.fr: Friction | None = None
        self.fpos: Friction | None = None
        overlapping = cs.alive0.copy()
        stage.redirect(cs.ra, cs.rb, cs.nx, cs.ny, cs.depth, cs.alive0)
        dropped = overlapping & ~cs.alive0  # the covering tile's own contact holds the body
        self.cs = cs = cs.take(np.flatnonzero(~dropped)) if dropped.any() else cs
        # Bodies that turn from contacts: the solve works on manifold points with lever arms.
        store = self.store
        self.rigid = self.rotation and bool(turning_pairs(cs.ra, cs.rb, store.kind, store.inv_inertia, KIND_POLYGON))
        if self.rigid:
            self.cs = cs = expand(cs, store, stage.bodies.ensure_geometry(), points, KEEP_GAP)
        # Bodies are numbered locally; ``table`` maps a store row to its number (-1: not in the solve).
        self.table = stage.numbering(store.n)
        self.rows, self.local = number(self.table, cs.ra, cs.rb, 0)
        self.tolerance = (TOLERANCE_TURNING if self.rigid else TOLERANCE) * float(store.bound[self.rows].max())
        self.dirty = np.ones(cs.size, dtype=bool)  # the contacts the position solver is to look at
        self._columns()

    def _columns(self) -> None:
        """Per-contact columns the solver reads, and how far a body may move in one run of the
        position solver (after the contact set changed)."""
        store, cs = self.store, self.cs
        C = cs.size
        self.a, self.b = self.local[:C], self.local[C:]
        # (one compiled pass, solve_columns.contact_columns; the spans: a move this long may bring a
        # body to bodies it was not paired with; the reaches: how far a body may move in one run of
        # the position solver, nothing to be pushed through without statics; a sleeper keeps still;
        # the order: see the note on self.order below)
        gx, gy = self.gravity
        statics = bool(self.stage.bodies.n_static)
        per_body, per_contact, self.immovable, self.order = columns.contact_columns(
            self.rows, cs.ra, cs.rb, store.hw, store.hh, store.bound, store.asleep, store.inv_mass, store.x, store.y,
            gx, gy, self.g)
        self.span, reach = per_body
        self.reach = self.span if statics else reach
        wa, wb, self.share_a, self.share_b = per_contact
        self.wa, self.wb = wa, wb
        arms = inertia = None
        self.turn_shares = None  # (contacts at points: how far a unit turns each body, shared by inverse mass)
        if self.rigid:
            self._arms()
            arms, inertia = (self.rt_a, self.rt_b), (self.ia, self.ib)
            still = np.zeros(C, dtype=bool)
            self.share_a, self.share_b, self.turn_shares = self._rigid_shares(still, still)
        self.fr = fr = Friction.of(store, cs.ra, cs.rb, wa, wb, self.rotation, arms, inertia) if self.friction else None
        # The position solve's friction (``fpos``) turns only circles, and only against immovable
        # bodies (rolling): with tangential pushes turning both bodies of a pair, a pyramid of 20
        # rows crept apart; turning a box by them coupled its turn to its slip, so a box landing
        # on a ledge slid 1e-8 before static friction caught the solver's residual turn.
        self.fpos = fr
        if self.rigid and fr is not None:
            imm = self.immovable
            roll_a = imm & (store.kind[cs.ra] == KIND_CIRCLE)
            roll_b = imm & (store.kind[cs.rb] == KIND_CIRCLE)
            self.fpos = Friction.of(store, cs.ra, cs.rb, wa, wb, self.rotation,
                                    (roll_a * self.rt_a, roll_b * self.rt_b), inertia)
        share_a, share_b, self.position_turns = self._shock_shares()
        self.position_shares = (share_a, share_b)
        fp = self.fpos
        self.position_mu = None if fp is None else fp.limits(*self.position_shares, self._angular())

    def _arms(self) -> None:
        """Contacts at points: each body's inverse inertia (a sleeper keeps still), and the lever
        arms across the normal (``rn = r x n``) and along the contact (``rt = r x t``, ``t = (-ny,
        nx)``) from each body's centre to the point, and which contacts have a turning polygon
        (their points are measured again by :meth:`_measure_points`)."""
        store, cs = self.store, self.cs
        # (one compiled pass, solve_columns.lever_arms. A deep overlap (a fast hit, a heap spawned on
        # one spot) moves its bodies without turning them: its points say little about where the
        # bodies met, a turn by its push would be far off the arc the linear separations follow,
        # and one point of a face that hit a face would set the body spinning. Arms that change
        # during the solve keep every contact's separation where it is: a contact's depth is
        # relative to where the solve began, through its arms.)
        turned = getattr(self, "dturn", None) is not None and getattr(self, "rn_a", None) is not None
        rax, ray, rbx, rby = cs.arms
        c = store.cols
        self.ia, self.ib, self.rn_a, self.rn_b, self.rt_a, self.rt_b, self.at_points = columns.lever_arms(
            cs.ra, cs.rb, rax, ray, rbx, rby, cs.nx, cs.ny, cs.depth, self.a, self.b, self.span, c["asleep"],
            c["inv_inertia"], c["kind"], KIND_POLYGON, self.rn_a if turned else _NO_FLOATS,
            self.rn_b if turned else _NO_FLOATS, self.dturn if turned else _NO_FLOATS, turned)

    def _rigid_shares(self, still_a: BoolArray, still_b: BoolArray) -> tuple[Any, ...]:
        """Contacts at points: how far a unit of push (impulse) moves and turns each body, the
        bodies ``still_*`` keeping still: ``(share_a, share_b, (turn_a, turn_b))``."""
        # (one compiled pass, solve_columns.rigid_shares)
        share_a, share_b, turn_a, turn_b = columns.rigid_shares(still_a, still_b, self.wa, self.wb, self.ia, self.ib,
                                                                self.rn_a, self.rn_b)
        return share_a, share_b, (turn_a, turn_b)

    def _angular(self) -> tuple[F64Array, F64Array] | None:
        """Contacts at points: each body's angular part of the normal effective inverse mass."""
        if not self.rigid:
            return None
        return self.ia * self.rn_a * self.rn_a, self.ib * self.rn_b * self.rn_b

    def _shock_shares(self) -> tuple[Any, ...]:
        """The shares of the position pushes (shock propagation). In a pair resting one on the other
        (normal within 60 degrees of the vertical) whose lower body rests on something immovable
        (the floor, or a body resting on it...), the lower body keeps still and the push lifts the
        upper one: a stack is pushed out from the ground up, each body exactly onto the one below
        (Gauss-Seidel alone converges on a stack only geometrically, and a body on top would press
        the one below into it). Elsewhere the push is shared by inverse mass, and so it is at a
        contact whose friction rolls a circle (:meth:`_rolling`). (Velocities: see
        :meth:`_velocity_shares`.) With the turns of contacts at points (None elsewhere):
        ``(share_a, share_b, turns)``."""
        gx, gy = self.gravity
        g = self.g
        if g == 0.0 or self.immovable.all():
            self.b_on_a = self.a_on_b = None
            return self.share_a, self.share_b, self.turn_shares
        cs = self.cs
        # (one compiled pass, solve_columns.stays: up = -n.g / |g| > 0.5, b rests on a; held: the
        # bodies resting on something immovable, as solver_loops.supported finds them)
        self.b_on_a, self.a_on_b, share_a, share_b = columns.stays(
            self.order, self.a, self.b, cs.nx, cs.ny, gx, gy, g, self.share_a, self.share_b, self.immovable,
            self._rolling(), self.rows.size)
        if self.rigid:
            return self._rigid_shares(self.b_on_a, self.a_on_b)
        return share_a, share_b, None

    def _rolling(self) -> BoolArray:
        """The contacts whose friction rolls a circle (one of its bodies is a circle that friction
        turns). These keep shares by inverse mass in both halves: a rolling circle is held still
        in a pile only by the friction of the bodies resting on it, pressed on it by their weight;
        kept still for the normal push and impulse of the body above, it carried its own weight
        alone, the friction that stops it rolling was bounded by that, and a pile of rolling
        circles flowed on for ever (issue 33 item 5a)."""
        fr = self.fr
        if fr is None or not fr.turns:
            return np.zeros(self.cs.size, dtype=bool)
        store, cs = self.store, self.cs
        circle_a, circle_b = store.kind[cs.ra] == KIND_CIRCLE, store.kind[cs.rb] == KIND_CIRCLE
        return (circle_a & (fr.turn_a != 0.0)) | (circle_b & (fr.turn_b != 0.0))

    # ``self.order`` (set by _columns): the contacts from the bottom of a pile up (contacts with
    # immovable bodies first, then by the lower body's height against gravity, ties in pair order):
    # a push then travels up a stack within one pass. Without gravity, in pair order.

    # --- positions ---------------------------------------------------------------------------

    def positions(self) -> None:
        """Push every solid contact out of overlap, in rounds: after each, the contacts with
        immovable bodies are measured again with the geometry, and the pairs the pushes made
        overlap are added (dynamic pairs the broad phase found touching, statics the pushed
        bodies were shoved into), until nothing changes (to the solver's tolerance, a billionth of
        the bodies' size), or the rounds run out (then :meth:`_clear_of_statics`)."""
        store, cs = self.store, self.cs
        self.x0, self.y0 = store.x[self.rows].copy(), store.y[self.rows].copy()
        self.push, self.dx, self.dy = self._warm_pushes(cs.push0)
        self.tpush = np.zeros(cs.size)
        n = self.rows.size
        if self.rigid:
            self.rot0, self.dturn = store.rot[self.rows].copy(), np.zeros(n)
            turn_a, turn_b = self.position_turns
            self.dturn += np.bincount(self.b, turn_b * self.push, n) - np.bincount(self.a, turn_a * self.push, n)
        fr = self.fpos
        if fr is not None:
            fr.start(self.frame, store, self.rows, self.x0, self.y0)
            if self.rigid:  # (one turn per body: the normal pushes' and friction's)
                fr.rot0, fr.dturn = self.rot0, self.dturn
            self.tpush = fr.clip(cs.tpush0, self.push, self.position_mu)  # type: ignore[arg-type]  # (fr: set)
            if self.tpush.any():
                tx, ty, turn = fr.spread(self.a, self.b, cs.nx, cs.ny, self.tpush, self.rows.size)
                self.dx += tx
                self.dy += ty
                fr.dturn += turn
        self.looked_x, self.looked_y = np.zeros(self.rows.size), np.zeros(self.rows.size)  # (see _far_candidates)
        # Candidates: the broad phase's pairs that were not contacts, and the statics within reach.
        self._set_candidates(self.stage.candidate_pairs(self.frame, cs))
        self._static_candidates(np.arange(self.rows.size))
        self.static_x, self.static_y = np.zeros(self.rows.size), np.zeros(self.rows.size)  # (see _late_contacts)
        rounds = 2 * max(2, self.stage.pipeline.response_iterations)
        self.seen_x, self.seen_y = np.zeros(self.rows.size), np.zeros(self.rows.size)  # (see _place)
        for _round in range(rounds):
            held_back = self._solve(self.order)  # (and self.moved: see _place)
            overlapping = self._measure_immovable()
            grew = self._far_candidates()
            grew = self._new_dynamic_contacts() or grew
            grew = self._late_contacts() or grew
            # (where bodies turn, points against immovable bodies measured again may be left
            # overlapping, to look at; overlaps between moving bodies wait for the next step)
            pending = self.rigid and self._pending()
            if not (held_back or overlapping or grew or pending):
                return
        self._clear_of_statics(rounds)

    def _pending(self) -> bool:
        """Contacts at points: whether one with an immovable body, to be looked at again, is left
        overlapping by more than its slack (``solve_rounds._slack``) where the bodies now stand. (One
        compiled pass, ``solve_rounds.pending_points``.)"""
        cs = self.cs
        return bool(pending_points(self.a, self.b, cs.nx, cs.ny, self.dx, self.dy, self.rn_a, self.rn_b, self.dturn,
                                   cs.depth, self.dirty, self.immovable, cs.ra, cs.rb, self.store.bound, POINT_SLACK))

    def _clear_of_statics(self, rounds: int) -> None:
        """After the rounds ran out with an overlap left (a heap spawned on one spot), rounds over
        the contacts with immovable bodies alone, while one still overlaps: each pushes its body
        exactly out, so no body ends the step inside static geometry; overlaps between dynamic
        bodies are left to the next step. A body moves at most its reach in a round, so there are
        as many rounds as the deepest overlap needs at that pace (a small body that fell into
        the floor faster than its size), and at least ``rounds``. (Where bodies turn, these pushes
        only move them, as the classic solve does: a push that turns a body wedged between statics
        may turn it into one as it pushes it out of another.)"""
        for _round in range(max(rounds, self._rounds_to_clear())):
            order = self.order[self.immovable[self.order]]
            if not (self._separations()[order] < 0.0).any():
                return
            self.dirty[order] = True
            self._solve(order, tolerance=0.0, translate=True)
            overlapping = self._measure_immovable()
            grew = self._new_dynamic_contacts(immovable_only=True)
            grew = self._late_contacts() or grew
            if not (overlapping or grew):
                return

    def _rounds_to_clear(self) -> int:
        """Rounds of :meth:`_clear_of_statics` that push every body out of the immovable ones at
        its reach per round (one more for the geometry to confirm), at most ``MAX_CLEAR_ROUNDS``."""
        imm = np.flatnonzero(self.immovable)
        deep = -self._separations()[imm]
        if imm.size == 0 or not (deep > 0.0).any():
            return 0
        mover = np.where(self.share_a[imm] > 0.0, self.a[imm], self.b[imm])
        need = float(np.max(np.ceil(np.maximum(deep, 0.0) / self.reach[mover])))
        return int(min(need + 1.0, MAX_CLEAR_ROUNDS))

    def _warm_pushes(self, push0: F64Array) -> tuple[F64Array, F64Array, F64Array]:
        """Last step's pushes as this step's first guess: none longer than its bodies' half-thickness
        (a body wedged between others that keep still may ask for more than any push can give, and
        its pushes must not grow from step to step: the 200-body soak shot a triangle 10 units
        through a wall that way), and scaled down where together they would move a body farther
        than its reach (see :meth:`_solve`) before the solver has looked at anything (a large
        reach over a tiny move: no scaling); with the moves they make, per body: ``(push, dx,
        dy)``. (One compiled pass: :func:`~framework.systems.solve_columns.warm_pushes`.)"""
        share_a, share_b = self.position_shares
        cs = self.cs
        push, dx, dy = columns.warm_pushes(self.a, self.b, cs.nx, cs.ny, share_a, share_b, push0, self.span, self.reach)
        return push, dx, dy

    def _solve(self, order: IntpArray, tolerance: float | None = None, translate: bool = False) -> bool:
        """One run of the position solver over the contacts ``order``; the bodies are then placed.
        Whether a push was held back.

        In a scene with static bodies, a body moves at most half its half-thickness in a run (bodies
        spawned on one spot push each other far): the geometry then sees every static it is pushed
        into while that static is still nearer the face it entered by, so the next round pushes it
        back out the way it came rather than on through."""
        cs = self.cs
        share_a, share_b = self.position_shares
        tol = self.tolerance if tolerance is None else tolerance
        if self.rigid:
            turn_a, turn_b = self.position_turns
            friction = self._friction_positions()
            if translate:  # (moves only: shares by inverse mass, no turns, no friction)
                inv = 1.0 / (self.wa + self.wb)
                share_a, share_b, turn_a, turn_b = self.wa * inv, self.wb * inv, 0.0 * turn_a, 0.0 * turn_b
                friction = NO_FRICTION_POSITIONS
            _passes, held = solver.solve_positions_rigid(
                order, self.a, self.b, cs.nx, cs.ny, -cs.depth, share_a, share_b, turn_a, turn_b, self.rn_a,
                self.rn_b, self.push, self.dx, self.dy, self.dturn, self.iterations, tol, self.dirty, self.reach,
                *friction)
        else:
            _passes, held = solver.solve_positions(order, self.a, self.b, cs.nx, cs.ny, -cs.depth, share_a, share_b,
                                                   self.push, self.dx, self.dy, self.iterations, tol, self.dirty,
                                                   self.reach, *self._friction_positions())
        self._place()
        return bool(held)

    def _friction_positions(self) -> tuple[F64Array, ...]:
        fr = self.fpos
        # (position_mu is set whenever fpos is)
        return NO_FRICTION_POSITIONS if fr is None else fr.positions_args(self.position_mu, self.tpush)  # type: ignore[arg-type]

    def _place(self) -> None:
        """Put the bodies where the solve has moved them (and turned them); ``self.moved``: the
        bodies the solve moved since the geometry was last looked at (the last round): only their
        contacts and candidates need looking at again. (Positions and moved: one compiled pass.)"""
        store = self.store
        placed, self.moved, self.seen_x, self.seen_y = rounds.place(
            self.rows, self.x0, self.y0, self.dx, self.dy, store.x, store.y, self.seen_x, self.seen_y)
        if placed:  # (as store.place)
            store.motion += 1
        if self.rigid:
            turned = np.flatnonzero(self.dturn != 0.0)
            if turned.size:
                self.store.rot[self.rows[turned]] = self.rot0[turned] + self.dturn[turned]
                self.store.motion += 1
        elif self.fpos is not None and self.fpos.turns:
            self.fpos.place_turns(self.store, self.rows)

    def _separations(self) -> F64Array:
        """Every contact's separation where the bodies now stand, along its normal (linear)."""
        cs = self.cs
        turns = (self.rn_a, self.rn_b, self.dturn) if self.rigid else (_NO_FLOATS,) * 3
        seps: F64Array = rounds.separations(self.a, self.b, cs.nx, cs.ny, self.dx, self.dy, *turns, cs.depth)
        return seps

    def _measure_immovable(self) -> bool:
        """Measure the pushed contacts with immovable bodies again; their depths (relative to where
        the solve began) follow the geometry. Whether one still overlaps."""
        cs = self.cs
        check, ra, rb, points = moved_immovable(self.immovable, self.moved, self.a, self.b,
                                                self.at_points if self.rigid else _NO_FLAGS, cs.ra, cs.rb)
        overlapping = False
        if self.rigid:
            overlapping = self._measure_points(points)
        if check.size == 0:
            return overlapping
        r = self.stage.remeasure(ra, rb)
        # (one compiled pass, solve_rounds.apply_measures: a pair apart, touching or a sliver within
        # rounding, is no longer pushed along; one that overlaps takes the new normal and depth)
        turns = (self.rn_a, self.rn_b, self.dturn) if self.rigid else (_NO_FLOATS,) * 3
        hit, deep = apply_measures(check, r.hit, r.nx, r.ny, r.depth, self.a, self.b, cs.nx, cs.ny, cs.depth, self.dx,
                                   self.dy, *turns, self.dirty, self.tolerance)
        if not hit:
            return False
        # Another round only for an overlap the solver would act on (not one within its tolerance).
        return bool(deep) or overlapping

    def _measure_points(self, check: IntpArray) -> bool:
        """Measure the contact points ``check`` (turning polygons against immovable bodies) again
        where the bodies now stand and are turned: a turn moves a point along an arc, which the
        solver's linear separations follow only to first order, and may turn the pair's normal
        (a box turning on a corner: the face it rests on changes), which the contact then takes,
        with its new points. A pair measured with as many points as it has keeps each point's new
        separation; otherwise all its points take its deepest. Whether one still overlaps."""
        if check.size == 0:
            return False
        cs, store = self.cs, self.store
        first, pair = rounds.pairs_of(check, cs.ea, cs.eb)  # (np.unique of the pair keys, compiled)
        rows = check[first]
        ra, rb = cs.ra[rows], cs.rb[rows]
        r = self.stage.remeasure(ra, rb)
        # (one compiled pass: the pairs that overlap along another normal now, and the normals)
        (nx, ny), turned, any_turned = turned_normals(rows, r.hit, r.nx, r.ny, cs.nx, cs.ny)
        n_pts, px, py, sep = self.stage.remeasure_points(ra, rb, nx, ny, KEEP_GAP)
        if any_turned:  # (the new normal, and where the points are now)
            had = np.bincount(pair, minlength=rows.size)
            same = n_pts[pair] == had[pair]
            slot = np.minimum(cs.slot[check], 1)
            t = check[turned[pair]]
            cs.nx[t], cs.ny[t] = nx[pair[turned[pair]]], ny[pair[turned[pair]]]
            ok = turned[pair] & same & (n_pts[pair] > 0)
            moved, k, q = check[ok], pair[ok], slot[ok]
            cs.px[moved], cs.py[moved] = px[k, q], py[k, q]
            rax, ray, rbx, rby = cs.arms
            ra, rb = cs.ra[moved], cs.rb[moved]
            rax[moved], ray[moved] = px[k, q] - store.x[ra], py[k, q] - store.y[ra]
            rbx[moved], rby[moved] = px[k, q] - store.x[rb], py[k, q] - store.y[rb]
            self._arms()
        # (the depths, where the bodies now stand and are turned, and which contacts to look at
        # again: one compiled pass, solve_rounds.points_measured; the slack: solve_rounds._slack)
        over = rounds.points_measured(check, pair, n_pts, sep, cs.slot, self.a, self.b, cs.nx, cs.ny, self.dx, self.dy,
                                      self.rn_a, self.rn_b, self.dturn, cs.depth, self.dirty, self.tolerance, cs.ra,
                                      cs.rb, store.bound, POINT_SLACK)
        if any_turned:
            self.dirty[check[turned[pair]]] = True
            self._recolumn()
        return bool(over)

    def _set_candidates(self, candidates: Pairs) -> None:
        self.candidates = candidates

    def _known_keys(self) -> I64Array:
        """The sorted pair keys of the solve's contacts and its candidates."""
        known: I64Array = known_keys(self.cs.ea, self.cs.eb, self.candidates[2], self.candidates[3])
        return known

    def _static_candidates(self, bodies: IntpArray) -> None:
        """Add the statics within reach of the movable ``bodies`` (local numbers) to the candidates."""
        if self.stage.bodies.n_static == 0:
            return
        near = self.stage.static_candidates(bodies, self.rows, self.reach, self._known_keys)
        if near[0].size:
            self._set_candidates(_joined(self.candidates, near))

    def _far_candidates(self) -> bool:
        """Pushes that moved a body farther than its span (a quarter of its half-thickness) since it
        was last looked at (a heap spawned on one spot) may bring it to bodies the broad phase did
        not pair it with: the pairs of those bodies where everything now stands become candidates.
        Whether any did."""
        far, anyone = rounds.far_bodies(self.dx, self.dy, self.looked_x, self.looked_y, self.span, _NO_FLAGS,
                                        _NO_FLOATS, _NO_IDS, _NO_IDS)
        if not anyone:
            return False
        self.looked_x[far], self.looked_y[far] = self.dx[far], self.dy[far]
        bodies = self.stage.bodies
        store, geom = bodies.store, bodies.ensure_geometry()
        rows = store.active()[2]
        rows = rows[store.kind[rows] >= 0]
        # The far bodies in a hash of their own, every moving body asked against it (only those
        # near a far one are swept).
        far_rows = self.rows[far]
        index = SpatialHash(bodies.hash.cell_size)
        base = int(store.entity.max()) + 1  # the far bodies' ids in the index: above every entity id
        index.set_static(geom.minx[far_rows], geom.miny[far_rows], geom.maxx[far_rows], geom.maxy[far_rows],
                         base + np.arange(far_rows.size))
        ea, eb = index.static_pairs(geom.minx[rows], geom.miny[rows], geom.maxx[rows], geom.maxy[rows],
                                    store.entity[rows])  # (entity, base + i)
        eb = store.entity[far_rows[eb - base]]
        keys = distinct(pair_keys(np.minimum(ea, eb), np.maximum(ea, eb))[ea != eb])  # (far-far pairs come twice)
        ea, eb = pair_parts(keys)
        known = self._known_keys()
        keep = ~sorted_member(keys, known)
        if not keep.any():
            return False
        ea, eb = ea[keep], eb[keep]
        new = self.stage.solid_pairs(bodies.rows_of(ea), bodies.rows_of(eb), ea, eb)
        self._set_candidates(_joined(self.candidates, new))
        return bool(new[0].size)

    def _new_dynamic_contacts(self, immovable_only: bool = False) -> bool:
        """Add the candidate pairs (touching or near when the step's contacts were found) that the
        pushes made overlap (``immovable_only``: only those with an immovable body). Whether there
        were any."""
        ra, rb, ea, eb = self.candidates
        if ra.size == 0:
            return False
        # (one compiled pass: the pairs with a body in the solve that moved)
        store = self.store
        look, ra_look, rb_look = rounds.moved_candidates(self.moved, self.table, ra, rb, immovable_only,
                                                         store.inv_mass, store.asleep)
        if look.size == 0:
            return False
        r = self.stage.remeasure(ra_look, rb_look)
        h = np.flatnonzero(r.hit & (r.depth > self.tolerance))  # (a sliver is left to the next step)
        if h.size == 0:
            return False
        new = look[h]
        keep = np.ones(ra.size, dtype=bool)
        keep[new] = False
        self._set_candidates((ra[keep], rb[keep], ea[keep], eb[keep]))
        self._add(ra[new], rb[new], ea[new], eb[new], batch.ContactArrays._make(v[h] for v in r))
        return True

    def _late_contacts(self) -> bool:
        """Add the contacts with statics that bodies pushed by dynamic bodies were shoved into (they
        were not touching them when the step's contacts were found). Whether there were any.

        The statics within a body's reach of where it stood when the solve began are candidates
        already (:meth:`_new_dynamic_contacts`); the static hash is asked again only about bodies
        pushed farther than their reach since it was last asked (a crowd spawned in a heap)."""
        cs = self.cs
        if self.stage.bodies.n_static == 0:
            return False
        # (the bodies of pushed contacts between movable bodies, farther than their reach from where
        # the static hash was last asked about them)
        pushed, anyone = rounds.far_bodies(self.dx, self.dy, self.static_x, self.static_y, self.reach, self.immovable,
                                           self.push, self.a, self.b)
        if not anyone:
            return False
        self.static_x[pushed], self.static_y[pushed] = self.dx[pushed], self.dy[pushed]
        extra = self.stage.new_static_contacts(self.rows[pushed], known_keys(cs.ea, cs.eb, _NO_IDS, _NO_IDS))
        if extra is None:
            return False
        ea, eb, ra, rb, r = extra
        self.frame.counters["late_contacts"] += int(ea.size)
        self._add(ra, rb, ea, eb, r)
        return True

    def _add(self, ra, rb, ea, eb, r) -> None:
        """Append contacts measured where the bodies stand now (their depths are made relative to
        where the solve began, like every other contact's); bodies new to the solve are numbered
        after the others. (Contacts at points: the new pairs' manifold points, measured now.)"""
        ones = np.ones(ra.size, dtype=bool)
        zeros = np.zeros(ra.size)
        new = Contacts(ra, rb, ea, eb, r.nx, r.ny, r.depth, ones, zeros, zeros, zeros, zeros, r.px, r.py)
        if self.rigid:
            new = expand(new, self.store, self.stage.bodies.ensure_geometry(), NO_POINTS, KEEP_GAP)
            ra, rb = new.ra, new.rb
        n_old = self.rows.size
        new_rows, local = number(self.table, ra, rb, n_old)
        new_a, new_b = local[: ra.size], local[ra.size:]
        k = new_rows.size
        rows = np.concatenate([self.rows, new_rows])
        dx, dy = np.concatenate([self.dx, np.zeros(k)]), np.concatenate([self.dy, np.zeros(k)])
        x0 = np.concatenate([self.x0, self.store.x[new_rows]])
        y0 = np.concatenate([self.y0, self.store.y[new_rows]])
        shift = (dx[new_b] - dx[new_a]) * new.nx + (dy[new_b] - dy[new_a]) * new.ny
        new.depth = new.depth + shift
        cs, cat = self.cs, np.concatenate
        if self.rigid:  # (the turns so far, by the new points' arms)
            self.rot0 = cat([self.rot0, self.store.rot[new_rows]])
            self.dturn = cat([self.dturn, np.zeros(k)])
            rax, ray, rbx, rby = new.arms
            new.depth += ((rbx * new.ny - rby * new.nx) * self.dturn[new_b]
                          - (rax * new.ny - ray * new.nx) * self.dturn[new_a])
        arms = None if cs.arms is None else tuple(cat([c, v]) for c, v in zip(cs.arms, new.arms))
        self.cs = Contacts(*(cat([c, v]) for c, v in zip(cs.columns(), new.columns())), arms=arms)
        zeros = np.zeros(new.size)
        self.rows, self.dx, self.dy, self.x0, self.y0 = rows, dx, dy, x0, y0
        self.looked_x, self.looked_y = cat([self.looked_x, np.zeros(k)]), cat([self.looked_y, np.zeros(k)])
        self.seen_x, self.seen_y = cat([self.seen_x, np.zeros(k)]), cat([self.seen_y, np.zeros(k)])
        self.moved = cat([self.moved, np.zeros(k, dtype=bool)])
        self.static_x, self.static_y = cat([self.static_x, np.zeros(k)]), cat([self.static_y, np.zeros(k)])
        self.local = cat([self.a, new_a, self.b, new_b])
        self.push = cat([self.push, zeros])
        self.tpush = cat([self.tpush, zeros])
        self.dirty = cat([self.dirty, np.ones(new.size, dtype=bool)])
        self._recolumn()
        self._static_candidates(np.arange(n_old, rows.size))  # (the new bodies')

    def _recolumn(self) -> None:
        """The per-contact columns again (contacts were added, or turned), friction's per-body
        columns and the turns made so far kept."""
        fr0 = self.fpos
        self._columns()
        if self.fpos is not None:
            self.fpos.start(self.frame, self.store, self.rows, self.x0, self.y0, fr0)
            if self.rigid:
                self.fpos.rot0, self.fpos.dturn = self.rot0, self.dturn

    # --- velocities --------------------------------------------------------------------------

    def velocities(self) -> None:
        """Stop the touching contacts closing, then bounce the ones that hit."""
        store, cs = self.store, self.cs
        self.touching = self.push > 0.0  # (a contact merely touching, never pushed, does not brake)
        if self.rigid:  # (but a point where the bodies touch does: a body pushed out at one point of
            # its two touches at the other, and braked at one point alone it would spin; and a body
            # that continuous detection stopped touching a static one, lifted a hair off it by a
            # turning body each step, kept a falling speed no push ever showed: the 40-body soak's
            # runaway. So, as Box2D's speculative contacts do, a contact a hair apart that this
            # step's speeds would close is in the solve too, allowed to close only its gap.)
            sep = self._separations()
            self.touching |= sep <= self.tolerance
        n = self.rows.size
        a, b = self.a, self.b
        vx, vy, u = columns.closing_speeds(self.rows, a, b, cs.nx, cs.ny, store.vx, store.vy)  # (u: before the solve)
        spin = None
        if self.rigid:
            spin = store.w[self.rows].copy()
            u += self.rn_b * spin[b] - self.rn_a * spin[a]
        target = np.zeros(cs.size)
        warm = self.touching
        if self.rigid:
            dt = self.dt
            speculative = ~self.touching & self.immovable & (u * dt + sep < 0.0)
            if speculative.any():
                self.touching = self.touching | speculative  # (not warm started: not in contact yet)
                target[speculative] = -sep[speculative] / dt
        share_a, share_b, turns = self._velocity_shares(vx, vy)
        # (one compiled pass: the touching contacts in order, the warm start of those touching
        # before the speculative ones joined, and max |u|)
        order, self.impulse, fastest = columns.warm_impulses(
            self.order, self.touching, warm, cs.impulse0, a, b, cs.nx, cs.ny, share_a, share_b, vx, vy, u)
        if spin is not None:
            spin += np.bincount(b, turns[1] * self.impulse, n) - np.bincount(a, turns[0] * self.impulse, n)
        self.timpulse = np.zeros(cs.size)
        fr = self.fr
        friction = NO_FRICTION_VELOCITIES
        if fr is not None:
            if spin is None:
                spin = store.w[self.rows].copy()
            limits = fr.limits(share_a, share_b, self._angular())
            self.timpulse = fr.clip(cs.timpulse0, self.impulse, limits)
            if self.timpulse.any():
                wx, wy, turn = fr.spread(a, b, cs.nx, cs.ny, self.timpulse, n)
                vx += wx
                vy += wy
                spin += turn
            friction = fr.velocities_args(limits, self.timpulse, spin)
        tol = TOLERANCE * (fastest + self.g * self.dt)
        self._solve_velocities(order, target, share_a, share_b, turns, vx, vy, spin, tol, friction)
        bounce = self._bounce_targets(u, warm)
        if bounce is not None:
            vx_in, vy_in = vx.copy(), vy.copy()
            w_in = None if spin is None else spin.copy()
            self._solve_velocities(order, bounce, share_a, share_b, turns, vx, vy, spin, tol, friction)
            if not self.solo[bounce > 0.0].all() or self.rigid:
                # (before the velocities are written: it reads the store's, those before the response)
                self._no_energy_made(bounce, store.movable(self.rows), vx_in, vy_in, vx, vy, w_in, spin)
        movable = store.movable(self.rows)
        rows = self.rows[movable]
        store.vx[rows], store.vy[rows] = vx[movable], vy[movable]
        if self.rigid or (fr is not None and fr.turns):
            store.w[rows] = spin[movable]  # type: ignore[index]  # (spin is set for both)

    def _solve_velocities(self, order, target, share_a, share_b, turns, vx, vy, spin, tol, friction) -> None:
        cs, a, b = self.cs, self.a, self.b
        dirty = np.ones(cs.size, dtype=bool)
        if self.rigid:
            solver.solve_velocities_rigid(order, a, b, cs.nx, cs.ny, target, share_a, share_b, turns[0], turns[1],
                                          self.rn_a, self.rn_b, self.impulse, vx, vy, spin, self.iterations, tol,
                                          dirty, *friction)
        else:
            solver.solve_velocities(order, a, b, cs.nx, cs.ny, target, share_a, share_b, self.impulse, vx, vy,
                                    self.iterations, tol, dirty, *friction)

    def _velocity_shares(self, vx: F64Array, vy: F64Array) -> tuple[Any, ...]:
        """Shares of the velocity impulses. As for the pushes, the lower body of a supported resting
        pair keeps still (a pile's weight goes straight down to the ground within one pass; a body
        high in a pile cannot keep a falling speed that only the pushes hide), except where the
        lower body moves into the upper one faster than a body at rest does (it bounced): an
        immovable body moving up would hand the upper one a bounce off a moving wall and keep its
        own speed, making energy; those pairs meet as the dynamic bodies they are. With the turns of
        contacts at points, as :meth:`_shock_shares`."""
        if self.b_on_a is None or self.a_on_b is None or not (self.b_on_a.any() or self.a_on_b.any()):  # (set together)
            return self.share_a, self.share_b, self.turn_shares
        cs, a, b = self.cs, self.a, self.b
        gx, gy = self.gravity
        # (one compiled pass, solve_columns.velocity_stays: resting_speed = 2 |g.n| dt; the lower
        # body's speed toward the upper one against it)
        # ... and where the upper body closes on the lower one faster than that (it hits, it does not
        # rest): an impulse against a lower body kept still goes to the upper body alone, so a heavy
        # ball thrown into a pyramid of boxes met the boxes under it as the ground and was turned
        # up off them (issue 33 item 5: to y = 19.9 at 19 units/s up, where pymunk and Box2D v3
        # reach 3.3 and 3.5; 2.5 with this).
        # Only a heavier body hitting a lighter one: bodies of like mass landing on each other (a
        # pyramid spawned with gaps between its rows settling) keep the lower body still, as
        # before; without it a 20-row pyramid of boxes that turn fell apart as its rows landed.
        # (b is the upper body: lighter inverse mass is heavier)
        b_on_a, a_on_b, share_a, share_b = columns.velocity_stays(
            a, b, cs.nx, cs.ny, vx, vy, gx, gy, self.dt, self.b_on_a, self.a_on_b, self.wa, self.wb, self.share_a,
            self.share_b)
        if self.rigid:
            return self._rigid_shares(b_on_a, a_on_b)
        return share_a, share_b, None

    def _no_energy_made(self, bounce, movable, vx_in, vy_in, vx, vy, w_in=None, w=None) -> None:
        """Bounces hand back (some of) the energy the stopping took, never more than the bodies had
        before the response: where they would end with more kinetic energy (bodies in several
        bounces at once; rounding), the bounces are scaled back until they do not. (Not called
        when every bounce is a lone bounce off an immovable body that does not turn: its speed is
        energy-exact by construction, see :func:`bounce_speed`.) Bounces off a moving kinematic
        body may add energy, as they should: then nothing is scaled. ``w_in, w``: angular
        velocities, for bodies that turn (their energy ``I w^2 / 2`` counts)."""
        store, cs = self.store, self.cs
        hit = bounce > 0.0
        kinematic = (store.body[cs.ra[hit]] == KINEMATIC) | (store.body[cs.rb[hit]] == KINEMATIC)
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
        if w is not None:
            inv_i = store.inv_inertia[self.rows]
            inertia = np.where(movable & (inv_i > 0.0), 1.0 / np.where(inv_i > 0.0, inv_i, 1.0), 0.0)
            w0, dw = store.w[self.rows], w - w_in
            before += float(np.sum(inertia * w0 * w0))
            c0 += float(np.sum(inertia * w_in * w_in))
            c1 += 2.0 * float(np.sum(inertia * w_in * dw))
            c2 += float(np.sum(inertia * dw * dw))
        if c0 + c1 + c2 <= before or c2 <= 0.0:
            return
        before -= 16.0 * np.finfo(float).eps * before  # (scaled: a margin for the rounding of any way of summing)
        disc = max(c1 * c1 - 4.0 * c2 * (c0 - before), 0.0)
        t = max(0.0, min(1.0, (-c1 + math.sqrt(disc)) / (2.0 * c2)))
        t = math.nextafter(t, 0.0)  # (rounding: stay on the safe side)
        vx[:], vy[:] = vx_in + t * dx, vy_in + t * dy
        if w is not None:
            w[:] = w_in + t * dw

    def _bounce_targets(self, u: F64Array, touching: BoolArray) -> F64Array | None:
        """The speed each touching contact must part at (0: no bounce), or None if none bounces.

        An approach no faster than gravity gives in two steps along the normal (``2 |g.n| dt``) is
        a body at rest, not a bounce: without that threshold a bouncy body on the floor would hop
        by ``e g dt`` every step forever. (``touching``: the contacts in the velocity solve; the
        hits, one compiled pass.)"""
        store, cs = self.store, self.cs
        gx, gy = self.gravity
        hits, rest, g_n = columns.bounce_hits(touching, u, cs.ra, cs.rb, store.restitution, cs.nx, cs.ny, gx, gy,
                                              self.dt, cs.alive0)
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
            target[solo] = rest[solo] * bounce_speed(u[solo], -g_n[solo] * sgn, self.push[solo], self.dt)
        return target

    # --- results -----------------------------------------------------------------------------

    def record(self, frame: StepFrame) -> None:
        """``frame.resolved`` (sorted by pair) and the pairs acted on, with their push and impulse
        (the next step's warm start); for contacts at points, each point's (``frame.points``), and
        the pair's the sums of its points'."""
        cs = self.cs
        near, turns = _NO_FLAGS, (_NO_FLOATS,) * 3
        if self.rigid:  # (and the points a hair apart: a turn in a pile opens such gaps, and a pair
            # not kept would be found again only by the pushes, a round of the solve later)
            store = self.store
            gap = NEAR_GAP * np.minimum(store.bound[cs.ra], store.bound[cs.rb])
            near = self.at_points & (self._separations() <= gap)
            turns = (self.rn_a, self.rn_b, self.dturn)
        # (one compiled pass: the contacts acted on (touching or pushed) and kept, sorted by pair;
        # their gaps where the bodies now stand, and their pushes capped as _warm_pushes caps them)
        ints, floats, applied = rounds.recorded(
            self.touching, self.push, near, cs.ea, cs.eb, cs.nx, cs.ny, self.a, self.b, self.dx, self.dy, cs.depth,
            *turns, self.span, self.impulse, self.tpush, self.timpulse)
        rows, keys, ea, eb = ints
        nx, ny, gap, pushed, push, impulse, tpush, timpulse = floats
        if self.fpos is None:
            tpush = np.zeros(rows.size)
        else:
            tpush = self.fpos.clip(tpush, push, self.position_mu[rows])  # type: ignore[index]  # (fpos: set)
        values: tuple[F64Array, ...] = (pushed, push, impulse, tpush, timpulse)
        if self.rigid:
            frame.points = (keys, cs.slot[rows], values[1], values[2], values[3], values[4], cs.px[rows], cs.py[rows])
            starts = np.empty(keys.size, dtype=bool)  # (each pair's first point)
            starts[:1] = True
            np.not_equal(keys[1:], keys[:-1], out=starts[1:])
            first = np.flatnonzero(starts)
            ea, eb, nx, ny = ea[first], eb[first], nx[first], ny[first]
            if first.size:
                gap = np.minimum.reduceat(gap, first)
                values = tuple(np.add.reduceat(v, first) for v in values)
                applied = np.maximum.reduceat(applied, first)
        pushed, push, impulse, tpush, timpulse = values
        frame.support = (ea, eb, nx, ny, push, impulse, gap, tpush, timpulse)
        frame.resolved = (ea, eb, nx, ny, pushed)
        if not applied.all():  # (pairs only kept, a hair apart: not applied)
            a = np.flatnonzero(applied)
            frame.resolved = (ea[a], eb[a], nx[a], ny[a], pushed[a])
        frame.counters["resolved"] = int(frame.resolved[0].size)


def _joined(a: Pairs, b: Pairs) -> Pairs:
    """The pairs of ``a`` followed by those of ``b``, column by column."""
    return (np.concatenate([a[0], b[0]]), np.concatenate([a[1], b[1]]), np.concatenate([a[2], b[2]]),
            np.concatenate([a[3], b[3]]))


def bounce_speed(u: F64Array, g: F64Array, d: F64Array, dt: float) -> F64Array:
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
