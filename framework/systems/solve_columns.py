"""The solve's per-contact columns and shares, in compiled passes (see :mod:`framework.systems.solve`).

A small scene's solve (a stack of 20 boxes: a few dozen contacts) was mostly numpy glue: rounds of
small array operations, each costing more to call than to run. These passes are that glue, one
compiled loop per round:

- :func:`contact_columns`: each body's span and reach, each contact's shares of a push by inverse
  mass, which contacts have an immovable body, and the order of the contacts from the bottom of
  a pile up;
- :func:`stays`: shock propagation, which pairs rest one on the other with the lower body held
  still (:meth:`Solve._shock_shares`), and the shares with the lower body kept still;
- :func:`velocity_stays`: the same for the impulses (:meth:`Solve._velocity_shares`);
- :func:`warm_pushes`: last step's pushes, capped and scaled within reach, and the moves they make
  (:meth:`Solve._warm_pushes`);
- :func:`closing_speeds`, :func:`warm_impulses`, :func:`bounce_hits`: the velocity half's start
  (the bodies' velocities, the contacts' closing speeds, the warm start) and its bounces.

Each is the numpy it replaced, element by element, in the same order of operations (``np.minimum``
and ``np.maximum`` as :func:`~framework.systems.gather._np_min` and ``_np_max``, which keep numpy's
answers for -0.0 and NaN; ``np.argsort(kind="stable")`` as a merge sort that, like numpy's, puts
NaN last), so the same bits. Divisions follow numpy's rules (``error_model="numpy"``: ``1/0`` is
``inf``, not an exception).

A fresh install compiles each of these on its first call, a few tenths of a second each whatever
its size (cached after): so there are few of them, and the only helpers are rules two passes
share (:func:`push_cap`, :func:`_kept_still`, :func:`turning_pair`).
"""

from __future__ import annotations

import math

import numpy as np

from ..compiled import inner, leaf, numpy_kernel
from ..stable_sort import stable_argsort
from .gather import _np_max, _np_min
from .solver_loops import warm_start

__all__ = ["bounce_hits", "closing_speeds", "contact_columns", "lever_arms", "push_cap", "rigid_shares", "stays",
           "turning_pair", "velocity_stays", "warm_impulses", "warm_pushes"]

# (numpy's error model: a division by zero gives inf or NaN as numpy does)
_compiled = numpy_kernel


@leaf
def push_cap(push, span_a, span_b):  # pragma: no cover - compiled
    """A push as far as it is worth remembering for the next step: at most the smaller half-thickness
    of its two bodies (twice their smaller ``span``; a push that long in one step is a body being
    pushed out of a heap, not resting)."""
    return _np_min(push, 2.0 * _np_min(span_a, span_b))


@leaf
def turning_pair(p, q, kind, inv_inertia, polygon):  # pragma: no cover - compiled
    """Whether row ``p`` or row ``q`` is of kind ``polygon`` (a box or a polygon that contacts turn)
    and turns (``inv_inertia > 0``)."""
    return (kind[p] == polygon and inv_inertia[p] > 0.0) or (kind[q] == polygon and inv_inertia[q] > 0.0)


@inner
def _kept_still(b_on_a, a_on_b, share_a, share_b):  # pragma: no cover - compiled
    """The shares with the lower body of the pairs ``b_on_a`` / ``a_on_b`` kept still (its share 0,
    the upper body's 1), the others' as they are: ``(share_a, share_b)``."""
    sa, sb = share_a.copy(), share_b.copy()
    for i in range(sa.size):
        if b_on_a[i]:
            sa[i], sb[i] = 0.0, 1.0
        elif a_on_b[i]:
            sa[i], sb[i] = 1.0, 0.0
    return sa, sb


@_compiled
def contact_columns(rows, ra, rb, hw, hh, bound, asleep, inv_mass, x, y, gx, gy, g):  # pragma: no cover
    """The columns of :meth:`Solve._columns` (and its ``order``), as ``(per_body, per_contact,
    immovable, order)``: per body (``rows``, the rows of ``per_body``) its ``span`` (half its
    half-thickness) and an infinite ``reach`` (with statics the reach is the span: the caller's to
    take); per contact ``(ra, rb)`` (the rows of ``per_contact``) its bodies' inverse masses ``wa,
    wb`` (a sleeper's 0) and the shares of a push by them; whether a body is immovable, and the
    contacts' order from the bottom of a pile up (immovable first; along gravity ``(gx, gy)`` of
    length ``g``; in pair order without)."""
    n = rows.size
    # (the float columns as the rows of two blocks, per body and per contact: each array handed
    # back costs the caller; the reach with statics is the span itself, the caller's to take)
    per_body = np.full((2, n), np.inf)
    span = per_body[0]
    for k in range(n):
        r = rows[k]
        half = _np_min(hw[r], hh[r]) if hw[r] > 0.0 else 0.5 * bound[r]
        span[k] = 0.5 * half
    c = ra.size
    per_contact = np.empty((4, c))
    wa, wb, share_a, share_b = per_contact[0], per_contact[1], per_contact[2], per_contact[3]
    immovable = np.empty(c, dtype=np.bool_)
    height = np.empty(c)
    for i in range(c):
        p, q = ra[i], rb[i]
        u = 0.0 if asleep[p] else inv_mass[p]
        v = 0.0 if asleep[q] else inv_mass[q]
        w = 1.0 / (u + v)
        wa[i], wb[i] = u, v
        share_a[i], share_b[i] = u * w, v * w
        immovable[i] = (u == 0.0) | (v == 0.0)
        if g != 0.0:
            if immovable[i]:
                height[i] = -np.inf
            else:
                height[i] = _np_min(-(x[p] * gx + y[p] * gy) / g, -(x[q] * gx + y[q] * gy) / g)
    order = stable_argsort(height) if g != 0.0 else np.arange(c)
    return per_body, per_contact, immovable, order


@_compiled
def stays(order, a, b, nx, ny, gx, gy, g, share_a, share_b, immovable, rolling, n_bodies):  # pragma: no cover
    """Shock propagation (:meth:`Solve._shock_shares`): which pairs rest one on the other, ``b_on_a``
    (normal within 60 degrees of up) or ``a_on_b``, with the lower body held up by something
    immovable (one pass in ``order`` follows the chains, as ``solver_loops.supported``), neither
    body immovable nor the contact ``rolling``; and the shares with those lower bodies kept still
    (for contacts not at points): ``(b_on_a, a_on_b, share_a, share_b)``."""
    c = a.size
    up = np.empty(c)
    for i in range(c):
        up[i] = -(nx[i] * gx + ny[i] * gy) / g
    held = np.zeros(n_bodies, dtype=np.bool_)
    for k in range(order.size):
        i = order[k]
        if up[i] > 0.5:
            if share_a[i] == 0.0 or held[a[i]]:
                held[b[i]] = True
        elif up[i] < -0.5:
            if share_b[i] == 0.0 or held[b[i]]:
                held[a[i]] = True
    b_on_a = np.empty(c, dtype=np.bool_)
    a_on_b = np.empty(c, dtype=np.bool_)
    for i in range(c):
        rests = not immovable[i] and not rolling[i]
        b_on_a[i] = rests and up[i] > 0.5 and held[a[i]]
        a_on_b[i] = rests and up[i] < -0.5 and held[b[i]]
    sa, sb = _kept_still(b_on_a, a_on_b, share_a, share_b)
    return b_on_a, a_on_b, sa, sb


@_compiled
def velocity_stays(a, b, nx, ny, vx, vy, gx, gy, dt, b_on_a0, a_on_b0, wa, wb, share_a,
                   share_b):  # pragma: no cover - compiled
    """The pairs of ``b_on_a0`` / ``a_on_b0`` whose lower body keeps still for the impulses
    (:meth:`Solve._velocity_shares`): not where the lower body moves up into the upper one faster
    than a body at rest does, nor where a heavier upper body hits the lower one; and the shares
    with those lower bodies kept still: ``(b_on_a, a_on_b, share_a, share_b)``."""
    c = a.size
    b_on_a = np.empty(c, dtype=np.bool_)
    a_on_b = np.empty(c, dtype=np.bool_)
    for i in range(c):
        p, q = a[i], b[i]
        resting_speed = 2.0 * abs(gx * nx[i] + gy * ny[i]) * dt
        a_up = vx[p] * nx[i] + vy[p] * ny[i]
        b_down = -(vx[q] * nx[i] + vy[q] * ny[i])
        closing = (vx[p] - vx[q]) * nx[i] + (vy[p] - vy[q]) * ny[i]
        hits = closing > resting_speed
        b_on_a[i] = b_on_a0[i] and a_up <= resting_speed and not (hits and wb[i] < wa[i])
        a_on_b[i] = a_on_b0[i] and b_down <= resting_speed and not (hits and wa[i] < wb[i])
    sa, sb = _kept_still(b_on_a, a_on_b, share_a, share_b)
    return b_on_a, a_on_b, sa, sb


@_compiled
def warm_pushes(a, b, nx, ny, share_a, share_b, push0, span, reach):  # pragma: no cover - compiled
    """:meth:`Solve._warm_pushes`: last step's pushes ``push0``, each at most twice the smaller span
    of its bodies, scaled down where together they would move a body farther than its ``reach``
    (all reaches finite); and the moves ``(dx, dy)`` per body the pushes make (the solve's warm
    start): ``(push, dx, dy)``."""
    c, n = a.size, span.size
    push = np.empty(c)
    any_push = False
    for i in range(c):
        push[i] = push_cap(push0[i], span[a[i]], span[b[i]])
        any_push = any_push or push[i] != 0.0
    finite = True
    for k in range(n):
        finite = finite and math.isfinite(reach[k])
    if finite and any_push:
        wx, wy = warm_start(a, b, nx, ny, share_a, share_b, push, n)
        scale = np.empty(n)
        for k in range(n):
            scale[k] = _np_min(1.0, reach[k] / _np_max(math.hypot(wx[k], wy[k]), 1e-300))
        for i in range(c):
            push[i] = push[i] * _np_min(scale[a[i]], scale[b[i]])
    dx, dy = warm_start(a, b, nx, ny, share_a, share_b, push, n)
    return push, dx, dy


@_compiled
def closing_speeds(rows, a, b, nx, ny, svx, svy):  # pragma: no cover - compiled
    """The velocities of the solve's bodies (``rows`` of the store's ``svx, svy``, copied) and each
    contact's closing speed along its normal before the solve: ``(vx, vy, u)``."""
    n, c = rows.size, a.size
    vx, vy = np.empty(n), np.empty(n)
    for k in range(n):
        vx[k], vy[k] = svx[rows[k]], svy[rows[k]]
    u = np.empty(c)
    for i in range(c):
        p, q = a[i], b[i]
        u[i] = (vx[q] - vx[p]) * nx[i] + (vy[q] - vy[p]) * ny[i]
    return vx, vy, u


@_compiled
def warm_impulses(order, touching, warm, impulse0, a, b, nx, ny, share_a, share_b, vx, vy,
                  u):  # pragma: no cover - compiled
    """The velocity solve's start: the ``touching`` contacts in ``order``, last step's impulses of
    the ``warm`` ones (0 elsewhere) and the velocities they make, added to ``vx, vy`` in place, and
    the fastest closing or parting speed ``max |u|`` (0 with no contact; NaN if one is NaN):
    ``(order, impulse, max |u|)``."""
    picked = np.zeros(order.size, dtype=np.bool_)
    for k in range(order.size):
        picked[k] = touching[order[k]]
    c = a.size
    impulse = np.empty(c)
    fastest = 0.0
    for i in range(c):
        impulse[i] = impulse0[i] if warm[i] else 0.0
        s = abs(u[i])
        fastest = _np_max(fastest, s)
    wx, wy = warm_start(a, b, nx, ny, share_a, share_b, impulse, vx.size)
    for k in range(vx.size):
        vx[k] += wx[k]
        vy[k] += wy[k]
    return order[picked], impulse, fastest


@_compiled
def bounce_hits(warm, u, ra, rb, restitution, nx, ny, gx, gy, dt, alive0):  # pragma: no cover - compiled
    """:meth:`Solve._bounce_targets`' hits: the ``warm`` (touching) contacts that overlapped (``alive0``)
    with a restitution (the larger of the pair's) and approached faster than gravity brings in two
    steps along the normal; with each contact's restitution and gravity along its normal:
    ``(hits, rest, g_n)``."""
    c = ra.size
    hits = np.zeros(c, dtype=np.bool_)
    rest, g_n = np.empty(c), np.empty(c)
    for i in range(c):
        rest[i] = _np_max(restitution[ra[i]], restitution[rb[i]])
        g_n[i] = gx * nx[i] + gy * ny[i]
        if warm[i]:
            resting_speed = 2.0 * abs(g_n[i]) * dt
            hits[i] = rest[i] > 0.0 and -u[i] > resting_speed and alive0[i]
    return hits, rest, g_n


@_compiled
def rigid_shares(still_a, still_b, wa, wb, ia, ib, rn_a, rn_b):  # pragma: no cover - compiled
    """:meth:`Solve._rigid_shares`: contacts at points, how far a unit of push (impulse) moves and
    turns each body, the bodies ``still_*`` keeping still (their inverse mass ``w`` and inertia
    ``i`` taken as 0): ``(share_a, share_b, turn_a, turn_b)``."""
    c = wa.size
    share_a, share_b, turn_a, turn_b = np.empty(c), np.empty(c), np.empty(c), np.empty(c)
    for i in range(c):
        wa_i, ia_i = (0.0, 0.0) if still_a[i] else (wa[i], ia[i])
        wb_i, ib_i = (0.0, 0.0) if still_b[i] else (wb[i], ib[i])
        inv = 1.0 / (wa_i + wb_i + ia_i * rn_a[i] * rn_a[i] + ib_i * rn_b[i] * rn_b[i])
        share_a[i], share_b[i] = wa_i * inv, wb_i * inv
        turn_a[i], turn_b[i] = ia_i * rn_a[i] * inv, ib_i * rn_b[i] * inv
    return share_a, share_b, turn_a, turn_b


@_compiled
def lever_arms(ra, rb, rax, ray, rbx, rby, nx, ny, depth, a, b, span, asleep, inv_inertia, kind, polygon, rn_a0,
               rn_b0, dturn, turned):  # pragma: no cover - compiled
    """:meth:`Solve._arms`: each contact's bodies' inverse inertias (a sleeper's 0), lever arms
    across the normal (``rn = r x n``) and along the contact (``rt``), 0 for a deep overlap (depth
    over the smaller span), and whether a body is a turning polygon: ``(ia, ib, rn_a, rn_b, rt_a,
    rt_b, at_points)``. ``turned``: the arms changed during the solve (the old ones ``rn_*0``,
    turns ``dturn``); each such contact's depth is moved in place by what the turns make of the
    change, so its separation stays where it is."""
    c = ra.size
    ia, ib = np.empty(c), np.empty(c)
    rn_a, rn_b, rt_a, rt_b = np.empty(c), np.empty(c), np.empty(c), np.empty(c)
    at_points = np.empty(c, dtype=np.bool_)
    for i in range(c):
        p, q = ra[i], rb[i]
        ia[i] = 0.0 if asleep[p] else inv_inertia[p]
        ib[i] = 0.0 if asleep[q] else inv_inertia[q]
        flat = 1.0 if depth[i] <= _np_min(span[a[i]], span[b[i]]) else 0.0
        rn_a[i], rn_b[i] = flat * (rax[i] * ny[i] - ray[i] * nx[i]), flat * (rbx[i] * ny[i] - rby[i] * nx[i])
        rt_a[i], rt_b[i] = flat * (rax[i] * nx[i] + ray[i] * ny[i]), flat * (rbx[i] * nx[i] + rby[i] * ny[i])
        at_points[i] = turning_pair(p, q, kind, inv_inertia, polygon)
    if turned:
        for i in range(rn_a0.size):
            before = rn_b0[i] * dturn[b[i]] - rn_a0[i] * dturn[a[i]]
            depth[i] += rn_b[i] * dturn[b[i]] - rn_a[i] * dturn[a[i]] - before
    return ia, ib, rn_a, rn_b, rt_a, rt_b, at_points
