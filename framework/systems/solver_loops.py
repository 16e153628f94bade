"""The contact solver's inner loops: projected Gauss-Seidel over contacts, compiled with numba.

Two problems are solved over the same contacts, each as sequential impulses with accumulated,
clamped values (so a pass may take back part of an earlier push, never pull bodies together) and
warm started from the last step (so a resting pile is solved in its first pass):

- **positions** (:func:`solve_positions`): push-outs ``p_i >= 0`` (relative displacement along the
  contact normal) such that every contact's separation ``s_i = s0_i + (d_b - d_a) . n_i >= 0``,
  with ``p_i = 0`` wherever ``s_i > 0``. The separation along a fixed normal is exactly linear in
  the bodies' displacements (``s0`` is the separation where the bodies stand), as in Box2D's
  solver, so no geometry is measured inside the loop.
- **velocities** (:func:`solve_velocities`): velocity changes ``l_i >= 0`` along the normals such that
  every contact stops closing, ``u_i = (v_b - v_a) . n_i >= target_i`` (0 for a contact at rest,
  the bounce speed for one that bounces).

A push or an impulse is shared between the two bodies (``share_a + share_b = 1``; by inverse mass,
or 0 and 1 where one body keeps still), so a unit of ``p`` or ``l`` changes the relative
displacement or velocity along the normal by exactly one unit; an immovable body has share 0 and
the other share 1 (exactly: a body pushed out of the floor lands exactly on it). Bodies are
numbered locally (``a``, ``b`` index the per-body arrays). Contacts are visited in the order
``order`` (bottom of a pile first), which propagates a push up a stack in one pass.

Only contacts that may still change are visited: the first pass looks at the contacts marked
``dirty`` (all of them, at first), and later passes at the contacts of the bodies that moved (by
more than ``tolerance``) in the pass before or in this one. An isolated pair costs one pass; a
settled pile warm started from the last step costs one pass; work follows what moves.

One code path: these loops are the solver; numba compiles them on first use (``cache=True``: once
per installation). The two solvers' loops are written out each in full: with the visit test and the
per-body update as shared compiled functions (even inlined), both ran 2 to 3 times slower
(numba 0.68, measured 2026-11-25). Friction is the exception, the other way round: its velocity
update, written inside the loop, made the frictionless path 45% slower although it never ran, so
it is a function of its own (:func:`_stop_sliding`), called only where there is friction; inside
the position loop it costs nothing measurable. The ``*_rigid`` loops (contacts at points, bodies
that turn: :mod:`framework.systems.turning`) repeat the two loops with the angular terms added,
on purpose: a scene without turning bodies runs the translational loops as they were, bit for bit
and without the angular arithmetic (a 2x2 block solve of two-point manifolds as a helper called
from the rigid loop made it twice as slow, 2026-11-25).
"""

from __future__ import annotations

import numpy as np

from ..compiled import kernel, leaf

#: Passes of each run of the rigid position solve that follow friction (undo the slip); later passes
#: only keep each tangential push within its limit, so the normal pushes converge alone. Friction's
#: rows, coupled to the normal ones through the turns, are Gauss-Seidel's slow mode there (a run
#: captured in the physics toy: 600 passes to converge with them, 31 without): followed to the
#: pass limit, the toy made 5.4 runs a step of up to 64 passes, now 1.2 of about 18. The velocity
#: solve, which holds bodies by static friction, follows it to its limit (frozen there too, a stack
#: of 20 boxes that can tip crept sideways, 1e-3 in 500 steps).
FRICTION_PASSES = 16

__all__ = ["solve_positions", "solve_positions_rigid", "solve_velocities", "solve_velocities_rigid", "supported",
           "warm_start"]


@leaf
def _within(change, share, sign, ex, ey, nx, ny, reach):
    """``change`` limited so that a body now ``(ex, ey)`` from where the call began, moving by
    ``sign * share * change`` along ``(nx, ny)``, stays within ``reach`` of it."""
    if share == 0.0:
        return change
    en = ex * nx + ey * ny
    disc = en * en - (ex * ex + ey * ey) + reach * reach
    if disc < 0.0:
        return 0.0
    root = disc ** 0.5
    t = sign * share * change  # the move along n; allowed in [-en - root, -en + root]
    lo, hi = -en - root, -en + root
    if t > hi:
        t = hi
    elif t < lo:
        t = lo
    return t / (sign * share)


@leaf
def _kept_within(change, share, sign, ex, ey, nx, ny, reach):
    """:func:`_within`, returning ``change`` itself where it is not limited (with shares that are
    not 0, 1/2 or 1, ``t / (sign * share)`` rounds off ``change``, which read as held back)."""
    if share == 0.0:
        return change
    en = ex * nx + ey * ny
    disc = en * en - (ex * ex + ey * ey) + reach * reach
    if disc < 0.0:
        return 0.0
    root = disc ** 0.5
    t = sign * share * change
    if t > -en + root:
        return (-en + root) / (sign * share)
    if t < -en - root:
        return (-en - root) / (sign * share)
    return change


@kernel
def solve_positions(order, a, b, nx, ny, sep0, share_a, share_b, push, dx, dy, passes, tolerance, dirty, reach,
                    mu, tshare_a, tshare_b, turn_a, turn_b, arm_a, arm_b, tpush, mx, my, mturn, dturn):
    """Projected Gauss-Seidel on the separations. ``push`` (warm start on entry, the solution on
    exit) and the per-body displacements ``dx, dy`` (which must already hold the warm start's
    displacement) are updated in place. ``dirty``: the contacts to look at first; on return, those
    still to look at (none once converged). ``reach``: how far each body may move in this call
    (a push that would take it farther is held back).

    Friction (``mu``, per contact; empty for none): tangential pushes ``tpush`` (warm start in,
    solution out; along ``t = (-ny, nx)``), with ``|tpush| <= mu * push``, undo the bodies' slip
    along the contact over the step, so a body held by static friction does not creep. The slip
    at the contact point: the bodies' motion this step before the solve (``mx, my``, turns
    ``mturn``) plus the solve's (``dx, dy``, turns ``dturn``), a turn counting with the body's
    lever arm along the contact (``arm_a, arm_b``: ``r x t`` from its centre to the point). A unit
    of tangential push moves a body by ``tshare`` (by inverse mass: a box sliding on another
    drags it, whatever holds the lower one up) and turns it by ``turn`` (``1/I`` times its arm,
    over the pair's effective inverse mass); ``mu`` is the limit in those units (see
    ``Solve._friction_limits``). Returns ``(passes made, whether a push was held back)``."""
    friction = mu.size > 0
    moved = np.full(dx.size, -1, dtype=np.int64)  # the last pass in which each body moved
    x0, y0 = dx.copy(), dy.copy()
    held = False
    for it in range(passes):
        any_moved = False
        for k in range(order.size):
            i = order[k]
            ia, ib = a[i], b[i]
            if not (dirty[i] or moved[ia] >= it - 1 or moved[ib] >= it - 1):
                continue
            dirty[i] = False
            s = sep0[i] + (dx[ib] - dx[ia]) * nx[i] + (dy[ib] - dy[ia]) * ny[i]
            new = push[i] - s
            if new < 0.0:
                new = 0.0
            change = new - push[i]
            if change != 0.0:
                wanted = change
                change = _within(change, share_a[i], -1.0, dx[ia] - x0[ia], dy[ia] - y0[ia], nx[i], ny[i], reach[ia])
                change = _within(change, share_b[i], 1.0, dx[ib] - x0[ib], dy[ib] - y0[ib], nx[i], ny[i], reach[ib])
                if change != wanted:
                    held = True
                if change != 0.0:
                    push[i] += change
                    dx[ia] -= share_a[i] * change * nx[i]
                    dy[ia] -= share_a[i] * change * ny[i]
                    dx[ib] += share_b[i] * change * nx[i]
                    dy[ib] += share_b[i] * change * ny[i]
                    if abs(change) > tolerance:
                        moved[ia] = moved[ib] = it
                        any_moved = True
            if not friction:
                continue
            tx, ty = -ny[i], nx[i]
            slip = ((mx[ib] + dx[ib] - mx[ia] - dx[ia]) * tx + (my[ib] + dy[ib] - my[ia] - dy[ia]) * ty
                    + arm_b[i] * (mturn[ib] + dturn[ib]) - arm_a[i] * (mturn[ia] + dturn[ia]))
            limit = mu[i] * push[i]
            new = min(max(tpush[i] - slip, -limit), limit)
            change = new - tpush[i]
            if change == 0.0:
                continue
            wanted = change
            change = _within(change, tshare_a[i], -1.0, dx[ia] - x0[ia], dy[ia] - y0[ia], tx, ty, reach[ia])
            change = _within(change, tshare_b[i], 1.0, dx[ib] - x0[ib], dy[ib] - y0[ib], tx, ty, reach[ib])
            if change != wanted:
                held = True
                if change == 0.0:
                    continue
            tpush[i] += change
            dx[ia] -= tshare_a[i] * change * tx
            dy[ia] -= tshare_a[i] * change * ty
            dx[ib] += tshare_b[i] * change * tx
            dy[ib] += tshare_b[i] * change * ty
            dturn[ia] -= turn_a[i] * change
            dturn[ib] += turn_b[i] * change
            if abs(change) > tolerance:
                moved[ia] = moved[ib] = it
                any_moved = True
        if not any_moved:
            return it + 1, held
    _left(order, a, b, moved, passes - 1, dirty)
    return passes, held


@kernel
def solve_velocities(order, a, b, nx, ny, target, share_a, share_b, impulse, vx, vy, passes, tolerance, dirty,
                     mu, tshare_a, tshare_b, turn_a, turn_b, arm_a, arm_b, timpulse, w):
    """Projected Gauss-Seidel on the normal velocities: ``impulse`` (warm start on entry; the
    velocities ``vx, vy`` must already include it) and the velocities are updated in place;
    ``dirty`` as in :func:`solve_positions`. Friction (``mu``; empty for none): tangential
    impulses ``timpulse`` along ``t = (-ny, nx)``, ``|timpulse| <= mu * impulse``, stop the
    bodies sliding along the contact at its point (Coulomb: a contact that needs more slides,
    braked by the limit); they change the velocities by ``tshare`` and the angular velocities
    ``w`` by ``turn`` (as the pushes in :func:`solve_positions`). Returns the passes made."""
    friction = mu.size > 0
    moved = np.full(vx.size, -1, dtype=np.int64)
    for it in range(passes):
        any_moved = False
        for k in range(order.size):
            i = order[k]
            ia, ib = a[i], b[i]
            if not (dirty[i] or moved[ia] >= it - 1 or moved[ib] >= it - 1):
                continue
            dirty[i] = False
            u = (vx[ib] - vx[ia]) * nx[i] + (vy[ib] - vy[ia]) * ny[i]
            new = impulse[i] + (target[i] - u)
            if new < 0.0:
                new = 0.0
            change = new - impulse[i]
            if change != 0.0:
                impulse[i] = new
                vx[ia] -= share_a[i] * change * nx[i]
                vy[ia] -= share_a[i] * change * ny[i]
                vx[ib] += share_b[i] * change * nx[i]
                vy[ib] += share_b[i] * change * ny[i]
                if abs(change) > tolerance:
                    moved[ia] = moved[ib] = it
                    any_moved = True
            if friction and _stop_sliding(i, ia, ib, nx, ny, mu[i] * impulse[i], tshare_a, tshare_b, turn_a, turn_b,
                                          arm_a, arm_b, timpulse, vx, vy, w, tolerance):
                moved[ia] = moved[ib] = it
                any_moved = True
        if not any_moved:
            return it + 1
    _left(order, a, b, moved, passes - 1, dirty)
    return passes


@leaf
def _stop_sliding(i, ia, ib, nx, ny, limit, tshare_a, tshare_b, turn_a, turn_b, arm_a, arm_b, timpulse, vx, vy, w,
                  tolerance):
    """Friction's update of contact ``i`` in :func:`solve_velocities` (a function of its own, off
    the frictionless path: inside the loop it made that path 45% slower, numba 0.68). Whether it
    changed the velocities by more than ``tolerance``."""
    tx, ty = -ny[i], nx[i]
    ut = (vx[ib] - vx[ia]) * tx + (vy[ib] - vy[ia]) * ty + arm_b[i] * w[ib] - arm_a[i] * w[ia]
    new = min(max(timpulse[i] - ut, -limit), limit)
    change = new - timpulse[i]
    if change == 0.0:
        return False
    timpulse[i] = new
    vx[ia] -= tshare_a[i] * change * tx
    vy[ia] -= tshare_a[i] * change * ty
    vx[ib] += tshare_b[i] * change * tx
    vy[ib] += tshare_b[i] * change * ty
    w[ia] -= turn_a[i] * change
    w[ib] += turn_b[i] * change
    return abs(change) > tolerance


@leaf
def _left(order, a, b, moved, last, dirty):
    """After the last pass: the contacts of bodies that moved in it are still to look at."""
    for k in range(order.size):
        i = order[k]
        if moved[a[i]] >= last or moved[b[i]] >= last:
            dirty[i] = True


@kernel
def supported(order, a, b, up, fixed_a, fixed_b, n_bodies):
    """Which bodies rest on something immovable, directly or through a chain of bodies resting on
    each other: ``up[i] > 0.5`` says b rests on a, ``< -0.5`` a on b; ``fixed_*`` whether a
    contact's body is immovable. One pass in ``order`` (from the bottom up) follows the chains."""
    out = np.zeros(n_bodies, dtype=np.bool_)
    for k in range(order.size):
        i = order[k]
        if up[i] > 0.5:
            if fixed_a[i] or out[a[i]]:
                out[b[i]] = True
        elif up[i] < -0.5:
            if fixed_b[i] or out[b[i]]:
                out[a[i]] = True
    return out


@kernel
def warm_start(a, b, nx, ny, share_a, share_b, value, n_bodies):
    """Per-body ``(x, y)`` sums of the warm-start values (pushes or impulses) over the contacts."""
    ox, oy = np.zeros(n_bodies), np.zeros(n_bodies)
    for i in range(a.size):
        v = value[i]
        if v == 0.0:
            continue
        ox[a[i]] -= share_a[i] * v * nx[i]
        oy[a[i]] -= share_a[i] * v * ny[i]
        ox[b[i]] += share_b[i] * v * nx[i]
        oy[b[i]] += share_b[i] * v * ny[i]
    return ox, oy


@kernel
def solve_positions_rigid(order, a, b, nx, ny, sep0, share_a, share_b, nturn_a, nturn_b, rn_a, rn_b, push, dx, dy,
                          dturn, passes, tolerance, dirty, reach, mu, tshare_a, tshare_b, turn_a, turn_b, arm_a, arm_b,
                          tpush, mx, my, mturn, fturn):
    """:func:`solve_positions` for contacts at points off the bodies' centres (bodies that turn):
    a contact's separation also follows the turns ``dturn`` of its bodies by their lever arms
    ``rn = r x n``, and a unit of push turns each body by ``nturn`` besides moving it by
    ``share`` (see :mod:`framework.systems.turning`). ``fturn``: friction's turns, the same
    array as ``dturn`` (empty without friction). Friction is followed in the first
    :data:`FRICTION_PASSES` passes only, then kept within its limit."""
    friction = mu.size > 0
    moved = np.full(dx.size, -1, dtype=np.int64)
    x0, y0 = dx.copy(), dy.copy()
    held = False
    for it in range(passes):
        any_moved = False
        for k in range(order.size):
            i = order[k]
            ia, ib = a[i], b[i]
            if not (dirty[i] or moved[ia] >= it - 1 or moved[ib] >= it - 1):
                continue
            dirty[i] = False
            s = (sep0[i] + (dx[ib] - dx[ia]) * nx[i] + (dy[ib] - dy[ia]) * ny[i]
                 + rn_b[i] * dturn[ib] - rn_a[i] * dturn[ia])
            new = push[i] - s
            if new < 0.0:
                new = 0.0
            change = new - push[i]
            if change != 0.0:
                wanted = change
                change = _kept_within(change, share_a[i], -1.0, dx[ia] - x0[ia], dy[ia] - y0[ia], nx[i], ny[i],
                                      reach[ia])
                change = _kept_within(change, share_b[i], 1.0, dx[ib] - x0[ib], dy[ib] - y0[ib], nx[i], ny[i],
                                      reach[ib])
                if change != wanted:
                    held = True
                if change != 0.0:
                    push[i] += change
                    dx[ia] -= share_a[i] * change * nx[i]
                    dy[ia] -= share_a[i] * change * ny[i]
                    dx[ib] += share_b[i] * change * nx[i]
                    dy[ib] += share_b[i] * change * ny[i]
                    dturn[ia] -= nturn_a[i] * change
                    dturn[ib] += nturn_b[i] * change
                    if abs(change) > tolerance:
                        moved[ia] = moved[ib] = it
                        any_moved = True
            if not friction:
                continue
            tx, ty = -ny[i], nx[i]
            slip = 0.0  # (after FRICTION_PASSES passes of this run: kept within its limit only)
            if it < FRICTION_PASSES:
                slip = ((mx[ib] + dx[ib] - mx[ia] - dx[ia]) * tx + (my[ib] + dy[ib] - my[ia] - dy[ia]) * ty
                        + arm_b[i] * (mturn[ib] + dturn[ib]) - arm_a[i] * (mturn[ia] + dturn[ia]))
            limit = mu[i] * push[i]
            new = min(max(tpush[i] - slip, -limit), limit)
            change = new - tpush[i]
            if change == 0.0:
                continue
            wanted = change
            change = _kept_within(change, tshare_a[i], -1.0, dx[ia] - x0[ia], dy[ia] - y0[ia], tx, ty, reach[ia])
            change = _kept_within(change, tshare_b[i], 1.0, dx[ib] - x0[ib], dy[ib] - y0[ib], tx, ty, reach[ib])
            if change != wanted:
                held = True
                if change == 0.0:
                    continue
            tpush[i] += change
            dx[ia] -= tshare_a[i] * change * tx
            dy[ia] -= tshare_a[i] * change * ty
            dx[ib] += tshare_b[i] * change * tx
            dy[ib] += tshare_b[i] * change * ty
            dturn[ia] -= turn_a[i] * change
            dturn[ib] += turn_b[i] * change
            if abs(change) > tolerance:
                moved[ia] = moved[ib] = it
                any_moved = True
        if not any_moved:
            return it + 1, held
    _left(order, a, b, moved, passes - 1, dirty)
    return passes, held


@kernel
def solve_velocities_rigid(order, a, b, nx, ny, target, share_a, share_b, nturn_a, nturn_b, rn_a, rn_b, impulse, vx,
                           vy, w, passes, tolerance, dirty, mu, tshare_a, tshare_b, turn_a, turn_b, arm_a, arm_b,
                           timpulse, fw):
    """:func:`solve_velocities` for contacts at points off the bodies' centres: the closing speed
    at a point includes the bodies' angular velocities ``w`` by their lever arms ``rn``, and a
    unit of impulse changes them by ``nturn``. ``fw``: friction's angular velocities, the same
    array as ``w`` (empty without friction)."""
    friction = mu.size > 0
    moved = np.full(vx.size, -1, dtype=np.int64)
    for it in range(passes):
        any_moved = False
        for k in range(order.size):
            i = order[k]
            ia, ib = a[i], b[i]
            if not (dirty[i] or moved[ia] >= it - 1 or moved[ib] >= it - 1):
                continue
            dirty[i] = False
            u = (vx[ib] - vx[ia]) * nx[i] + (vy[ib] - vy[ia]) * ny[i] + rn_b[i] * w[ib] - rn_a[i] * w[ia]
            new = impulse[i] + (target[i] - u)
            if new < 0.0:
                new = 0.0
            change = new - impulse[i]
            if change != 0.0:
                impulse[i] = new
                vx[ia] -= share_a[i] * change * nx[i]
                vy[ia] -= share_a[i] * change * ny[i]
                vx[ib] += share_b[i] * change * nx[i]
                vy[ib] += share_b[i] * change * ny[i]
                w[ia] -= nturn_a[i] * change
                w[ib] += nturn_b[i] * change
                if abs(change) > tolerance:
                    moved[ia] = moved[ib] = it
                    any_moved = True
            if friction and _stop_sliding(i, ia, ib, nx, ny, mu[i] * impulse[i], tshare_a, tshare_b, turn_a, turn_b,
                                          arm_a, arm_b, timpulse, vx, vy, w, tolerance):
                moved[ia] = moved[ib] = it
                any_moved = True
        if not any_moved:
            return it + 1
    _left(order, a, b, moved, passes - 1, dirty)
    return passes
