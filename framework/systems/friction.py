"""Friction's part of one solve: per-contact coefficients and lever arms, per-body slip and turn.

Coulomb friction at a contact resists the two bodies sliding along it at its point, up to ``mu``
times what presses them together (see docs/physics.md). The solver loops
(:mod:`framework.systems.solver_loops`) do the work, in the same units as the normal pushes and
impulses: a unit of tangential push (impulse) changes the bodies' relative slip (slip speed) at the
contact point by exactly one unit. This module prepares what they read:

- ``mu``: the pair's coefficient (:meth:`BodyStore.pair_friction`), and, per normal share, the
  limit in the loops' units (:meth:`Friction.limits`);
- ``tshare``, ``turn``: how far a unit moves and turns each body. A body moves by its inverse
  mass and turns by its inverse inertia times its lever arm ``r x t`` (the arm from its centre to
  the contact point, across the tangent), both over the pair's effective inverse mass along the
  tangent, ``k = w_a + w_b + i_a arm_a^2 + i_b arm_b^2``;
- per body, its motion this step before the solve (``mx, my``, turn ``mturn``): the slip the
  position solve undoes, so static friction holds a body without creep.

Which bodies turn: dynamic bodies centred on their entity with a finite inertia (``inv_inertia >
0`` in the store), and only with the ``rotation`` effect. A circle's arm is its radius (the point is
on its rim, along the normal), so friction rolls it; where a box or polygon turns, every contact of
the solve is at a manifold point with arms from both centres (:mod:`framework.systems.turning`).
"""

from __future__ import annotations

import numpy as np

from ..arrays import F64Array, IntpArray
from ..collision.kinds import KIND_CIRCLE
from ..frame import StepFrame
from ..store import STATIC, BodyStore
from .solver_loops import warm_start

__all__ = ["NO_FRICTION_POSITIONS", "NO_FRICTION_VELOCITIES", "Friction"]

_NONE = np.zeros(0)
# the loops' friction arguments in a solve without friction
NO_FRICTION_POSITIONS: tuple[F64Array, ...] = (_NONE,) * 12
NO_FRICTION_VELOCITIES: tuple[F64Array, ...] = (_NONE,) * 9


class Friction:
    """The friction columns of one solve's contacts ``(ra, rb)`` (local bodies ``a``, ``b``, shares
    of inverse mass ``wa``, ``wb``; sleepers count as immovable)."""

    def __init__(self, store: BodyStore, ra: IntpArray, rb: IntpArray, wa: F64Array, wb: F64Array, mu: F64Array,
                 rotation: bool, arms: tuple[F64Array, F64Array] | None = None,
                 inertia: tuple[F64Array, F64Array] | None = None) -> None:
        self.mu = mu
        self.wa, self.wb = wa, wb
        if arms is None:
            self.arm_a = np.where(store.kind[ra] == KIND_CIRCLE, store.radius[ra], 0.0)
            self.arm_b = np.where(store.kind[rb] == KIND_CIRCLE, -store.radius[rb], 0.0)
        else:  # (contacts at points: see framework.systems.turning)
            self.arm_a, self.arm_b = arms
        if inertia is not None:
            ia, ib = inertia
        elif rotation:
            ia = np.where(store.asleep[ra], 0.0, store.inv_inertia[ra])
            ib = np.where(store.asleep[rb], 0.0, store.inv_inertia[rb])
        else:
            ia = ib = np.zeros(ra.size)
        self.k = wa + wb + ia * self.arm_a * self.arm_a + ib * self.arm_b * self.arm_b
        inv = 1.0 / self.k
        self.tshare_a, self.tshare_b = wa * inv, wb * inv
        self.turn_a, self.turn_b = ia * self.arm_a * inv, ib * self.arm_b * inv
        self.turns = bool(ia.any() or ib.any())

    @classmethod
    def of(cls, store: BodyStore, ra: IntpArray, rb: IntpArray, wa: F64Array, wb: F64Array,
           rotation: bool, arms: tuple[F64Array, F64Array] | None = None,
           inertia: tuple[F64Array, F64Array] | None = None) -> Friction | None:
        """The columns, or None when no pair has friction. ``arms``, ``inertia``: each contact's
        lever arms along it and its bodies' inverse inertias, for contacts at points (default:
        circles' radii; the store's inertias with ``rotation``)."""
        mu = store.pair_friction(ra, rb)
        return cls(store, ra, rb, wa, wb, mu, rotation, arms, inertia) if mu.any() else None

    def limits(self, share_a: F64Array, share_b: F64Array,
               turning: tuple[F64Array, F64Array] | None = None) -> F64Array:
        """Per contact, the largest tangential push (impulse) per unit of normal push (impulse),
        in the loops' units, for normal pushes shared by ``share_a, share_b``: ``mu`` times the
        tangential effective inverse mass over the normal one. Where shock propagation keeps a
        pair's lower body still for the normal push, a unit of it is the upper body's mass worth of
        impulse, not the pair's, and the limit grows by the ratio (two equal boxes: twice).

        ``turning``: for contacts at points, each body's angular part of the normal effective
        inverse mass (``i_a rn_a^2``, ``i_b rn_b^2``). A unit of normal push at a point that turns
        the bodies is ``1 / k_normal`` of impulse with ``k_normal = w_a + w_b + i_a rn_a^2 + i_b
        rn_b^2``; leaving the angular part out made the bound on a turning box ``1 + m (w/2)^2 / I``
        times too strong (2.5 times for a square)."""
        wa, wb = self.wa, self.wb
        lower_a = (share_a == 0.0) & (wa > 0.0)  # a keeps still although it could move
        lower_b = (share_b == 0.0) & (wb > 0.0)
        ka, kb = wa, wb
        if turning is not None:
            ka, kb = wa + turning[0], wb + turning[1]
        k_normal = np.where(lower_a, kb, np.where(lower_b, ka, ka + kb))
        return self.mu * (self.k / k_normal)

    def start(self, frame: StepFrame, store: BodyStore, rows: IntpArray, x: F64Array, y: F64Array,
              before: Friction | None = None) -> None:
        """Per body (``rows``, standing at ``x, y`` when the solve began): its motion this step
        before the solve, and its turn by the solve so far (the bodies ``before`` knew keep theirs;
        contacts were added during the solve)."""
        fx, fy = frame.start_x, frame.start_y
        n = rows.size
        self.mx, self.my, self.mturn = np.zeros(n), np.zeros(n), np.zeros(n)
        known = rows < fx.size  # (rows spawned during the step did not move before it)
        self.mx[known], self.my[known] = x[known] - fx[rows[known]], y[known] - fy[rows[known]]
        moving = known & store.has_vel[rows] & ~store.asleep[rows] & (store.body[rows] != STATIC)
        self.mturn[moving] = store.w[rows[moving]] * frame.dt
        self.rot0 = store.rot[rows].copy()
        self.dturn = np.zeros(n)
        if before is not None:
            k = before.dturn.size
            self.rot0[:k], self.dturn[:k] = before.rot0, before.dturn

    def clip(self, value: F64Array, normal: F64Array, limits: F64Array) -> F64Array:
        """Tangential values (last step's, as a warm start) within the limits of the normal ones."""
        bound = limits * normal
        return np.clip(value, -bound, bound)

    def spread(self, a: IntpArray, b: IntpArray, nx: F64Array, ny: F64Array, value: F64Array,
               n_bodies: int) -> tuple[F64Array, F64Array, F64Array]:
        """Per body, the ``(x, y, turn)`` changes the tangential ``value`` of every contact makes
        (a warm start)."""
        ox, oy = warm_start(a, b, -ny, nx, self.tshare_a, self.tshare_b, value, n_bodies)
        turn = np.bincount(b, self.turn_b * value, n_bodies) - np.bincount(a, self.turn_a * value, n_bodies)
        # (bincount with weights gives float64; numpy's stub says an integer array whatever the weights)
        return ox, oy, turn  # type: ignore[return-value]

    def positions_args(self, limits: F64Array, tpush: F64Array) -> tuple[F64Array, ...]:
        """:func:`solve_positions`' friction arguments."""
        return (limits, self.tshare_a, self.tshare_b, self.turn_a, self.turn_b, self.arm_a, self.arm_b, tpush,
                self.mx, self.my, self.mturn, self.dturn)

    def velocities_args(self, limits: F64Array, timpulse: F64Array, w: F64Array) -> tuple[F64Array, ...]:
        """:func:`solve_velocities`' friction arguments."""
        return (limits, self.tshare_a, self.tshare_b, self.turn_a, self.turn_b, self.arm_a, self.arm_b, timpulse, w)

    def place_turns(self, store: BodyStore, rows: IntpArray) -> None:
        """Turn the bodies the position solve turned."""
        turned = np.flatnonzero(self.dturn != 0.0)
        if turned.size:
            store.rot[rows[turned]] = self.rot0[turned] + self.dturn[turned]
