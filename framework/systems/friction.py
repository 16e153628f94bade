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
from ..compiled import kernel, numpy_kernel
from ..frame import StepFrame
from ..store import STATIC, BodyStore
from .gather import _np_max, _np_min
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
        # (one compiled pass, _columns: the arms (a circle's radius where none are given: contacts
        # at points bring theirs, see framework.systems.turning), each body's inverse inertia (a
        # sleeper's 0; none without rotation), k, the shares and the turns)
        c = store.cols
        cols, turns = _columns(ra, rb, wa, wb, c["kind"], c["radius"], c["asleep"], c["inv_inertia"],
                               _NONE if arms is None else arms[0], _NONE if arms is None else arms[1],
                               _NONE if inertia is None else inertia[0], _NONE if inertia is None else inertia[1],
                               arms is not None, inertia is not None, rotation, KIND_CIRCLE)
        self.arm_a, self.arm_b, self.k, self.tshare_a, self.tshare_b, self.turn_a, self.turn_b = cols
        self.turns = bool(turns)

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
        limits: F64Array = _limits(share_a, share_b, self.wa, self.wb, _NONE if turning is None else turning[0],
                                   _NONE if turning is None else turning[1], turning is not None, self.mu, self.k)
        return limits

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
        clipped: F64Array = _clip(value, normal, limits)
        return clipped

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


@numpy_kernel
def _columns(ra, rb, wa, wb, kind, radius, asleep, inv_inertia, arms_a, arms_b, inertia_a, inertia_b, has_arms,
             has_inertia, rotation, circle):  # pragma: no cover - compiled
    """:class:`Friction`'s columns ``(arm_a, arm_b, k, tshare_a, tshare_b, turn_a, turn_b)`` as the
    rows of one array, and whether a body turns: numpy's arithmetic, in its order."""
    out = np.empty((7, ra.size))
    turns = False
    for i in range(ra.size):
        a, b = ra[i], rb[i]
        if has_arms:
            arm_a, arm_b = arms_a[i], arms_b[i]
        else:
            arm_a = radius[a] if kind[a] == circle else 0.0
            arm_b = -radius[b] if kind[b] == circle else 0.0
        if has_inertia:
            ia, ib = inertia_a[i], inertia_b[i]
        elif rotation:
            ia = 0.0 if asleep[a] else inv_inertia[a]
            ib = 0.0 if asleep[b] else inv_inertia[b]
        else:
            ia = ib = 0.0
        k = wa[i] + wb[i] + ia * arm_a * arm_a + ib * arm_b * arm_b
        inv = 1.0 / k
        out[0, i], out[1, i], out[2, i] = arm_a, arm_b, k
        out[3, i], out[4, i] = wa[i] * inv, wb[i] * inv
        out[5, i], out[6, i] = ia * arm_a * inv, ib * arm_b * inv
        turns = turns or ia != 0.0 or ib != 0.0
    return out, turns


@numpy_kernel
def _limits(share_a, share_b, wa, wb, turning_a, turning_b, turning, mu, k):  # pragma: no cover - compiled
    """:meth:`Friction.limits` (see there): numpy's arithmetic, in its order."""
    out = np.empty(mu.size)
    for i in range(mu.size):
        ka, kb = wa[i], wb[i]
        if turning:
            ka, kb = wa[i] + turning_a[i], wb[i] + turning_b[i]
        if share_a[i] == 0.0 and wa[i] > 0.0:  # a keeps still although it could move
            k_normal = kb
        elif share_b[i] == 0.0 and wb[i] > 0.0:
            k_normal = ka
        else:
            k_normal = ka + kb
        out[i] = mu[i] * (k[i] / k_normal)
    return out


@kernel
def _clip(value, normal, limits):  # pragma: no cover - compiled
    """``np.clip(value, -bound, bound)`` with ``bound = limits * normal`` (numpy's clip: the max,
    then the min, NaN kept)."""
    out = np.empty(value.size)
    for i in range(value.size):
        bound = limits[i] * normal[i]
        out[i] = _np_min(_np_max(value[i], -bound), bound)
    return out
