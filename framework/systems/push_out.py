"""The push-out solver: push overlapping bodies apart and remove (or reflect) their approaching velocity.

Vectorised over contacts, in a few passes:

- **Position.** A dynamic body touching immovable ones (static, kinematic, infinite mass) is
  pushed out of its *deepest* such contact only; its other contacts are measured again and
  resolved in the next pass only if they still overlap. That is what keeps a box sliding over a
  floor of tiles from snagging on a seam (the sliver of the next tile stops overlapping once the
  box stands on the floor) and a body pushed into a stacked wall from hanging on a seam. Two
  dynamic bodies share the push-out by inverse mass; a body in several such contacts takes the
  mean of their pushes (Jacobi), and further passes settle stacks.
- **Velocity.** Only the contacts actually resolved change velocities: the approaching normal
  velocity is removed (restitution 0, slide) or reflected (restitution e, bounce; a pair uses the
  larger e). A bounce off an immovable body first takes away the potential energy the push-out
  added against gravity, so an elastic ball never climbs higher than it started.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..store import BodyStore

__all__ = ["resolve"]

# (rows a, rows b) -> (hit, nx, ny, depth, rank): rank orders a body's immovable contacts (deepest
# first); it is the depth, except where the scene re-aimed a push (systems.internal_faces).
Recompute = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]]


def _complex(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``x + iy`` as one complex array (exactly: no arithmetic on the parts)."""
    z = np.empty(x.shape, dtype=np.complex128)
    z.real, z.imag = x, y
    return z


def _local_numbers(n: int, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(unique, local)``: the distinct rows (sorted) and each entry's number among them, like
    ``np.unique(rows, return_inverse=True)`` but by a lookup table over the ``n`` rows (no sort:
    faster even for a thousand rows among a hundred thousand)."""
    seen = np.zeros(n, dtype=bool)
    seen[rows] = True
    unique = np.flatnonzero(seen)
    table = np.empty(n, dtype=np.int64)
    table[unique] = np.arange(unique.size)
    return unique, table[rows]


def _first_per_group(groups: np.ndarray, keys: np.ndarray) -> np.ndarray:
    """Indices of the smallest key within each group (ties: the lowest index)."""
    order = np.lexsort((np.arange(groups.size), keys, groups))
    g = groups[order]
    first = np.ones(g.size, dtype=bool)
    first[1:] = g[1:] != g[:-1]
    return order[first]


def resolve(
    store: BodyStore,
    ra: np.ndarray,
    rb: np.ndarray,
    nx: np.ndarray,
    ny: np.ndarray,
    depth: np.ndarray,
    gravity: tuple[float, float],
    iterations: int,
    recompute: Recompute,
    alive0: np.ndarray | None = None,
    dt: float = 0.0,
    rank0: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Resolve the contacts ``(ra, rb)`` (normal from a to b).

    Returns ``(resolved, nx, ny, pushed)``: the mask of the contacts the response applied, the
    normal each was applied along and the total push-out along it.

    ``alive0`` marks the contacts overlapping now; the others are last step's contacts that no
    longer overlap (a resting stack's bodies fall by the same amount and merely touch). They keep
    the support chain whole and are resolved if a push below makes them overlap again.

    ``rank0`` orders each body's immovable contacts for the deepest-first push-out (default: the
    depth): a push re-aimed away from an internal tile face keeps the rank of its measured depth.
    """
    C = ra.size
    resolved = np.zeros(C, dtype=bool)
    if C == 0:
        return resolved, nx, ny, np.zeros(0)
    c = store.cols
    inv = c["inv_mass"]
    ia, ib = inv[ra].copy(), inv[rb].copy()
    # Per-body bookkeeping runs over the bodies in contact only (local numbers la, lb), not over
    # every row of the store: a level of 100,000 tiles costs nothing here.
    rows_u, local = _local_numbers(store.n, np.concatenate([ra, rb]))
    la, lb = local[:C], local[C:]
    L = rows_u.size
    ia0, ib0 = ia.copy(), ib.copy()  # the real inverse masses (the stack makes lower bodies 0)
    level = _shock_propagation(L, la, lb, nx, ny, ia, ib, gravity, c["vx"], c["vy"], ra, rb, dt)
    solid = (ia == 0.0) != (ib == 0.0)
    both = (ia > 0.0) & (ib > 0.0)
    applied_nx, applied_ny = nx.copy(), ny.copy()
    pushed = np.zeros(C)  # total push-out along the applied normal (for the energy correction)
    alive = np.ones(C, dtype=bool) if alive0 is None else alive0.copy()
    moved = np.zeros(L, dtype=bool)  # bodies moved since their contacts were last measured
    # A contact whose movable bodies are in no other contact is settled by its own push-out and
    # never needs measuring again (most contacts, in a sparse scene).
    per_row = np.bincount(local, minlength=L)
    lone = (per_row[la] == 1) & (per_row[lb] == 1)
    if solid.any():  # (a scene of dynamic bodies alone needs none of this)
        mobile = np.where(ib > 0.0, rb, ra)  # the dynamic body of a solid contact
        mobile_l = np.where(ib > 0.0, lb, la)
        sgn = np.where(ib > 0.0, 1.0, -1.0)  # it moves along +n if it is b, along -n if it is a
        cur_nx, cur_ny, cur_depth = nx.copy(), ny.copy(), depth.copy()
        cur_rank = depth.copy() if rank0 is None else rank0.copy()
        # Support level of each solid contact's mobile body: a stack is resolved from the ground
        # up, each level measured again after the one below it moved (inf: not resting on anything).
        mob_level = level[mobile_l]
        levels = np.unique(mob_level[solid & np.isfinite(mob_level)])
        lone = np.where(solid, per_row[mobile_l] == 1, lone)
    else:
        mobile = mobile_l = sgn = cur_nx = cur_ny = cur_depth = cur_rank = mob_level = None
        levels = np.zeros(0)

    # Where each row stood when the response began: contacts between two dynamic bodies are
    # re-measured along their normal from how far the bodies moved since (SAT depth is linear in
    # translation along a fixed axis, as in Box2D's solver); contacts with immovable bodies are
    # measured again from the geometry, because there the axis matters (tile seams).
    z0 = _complex(c["x"][rows_u], c["y"][rows_u])
    # The passes move the bodies in this local copy, positions as complex numbers x + iy (one
    # numpy call moves both coordinates; no scatter into the store per pass); the store is
    # written before a geometric re-measure reads it, and at the end.
    zl = z0.copy()
    dirty = [False]

    def flush() -> None:
        if dirty[0]:
            c["x"][rows_u], c["y"][rows_u] = zl.real, zl.imag
            dirty[0] = False

    def remeasure(idx: np.ndarray) -> None:
        """Measure the immovable contacts ``idx`` (indices) again."""
        if idx.size:
            flush()
            hit, rnx, rny, rdepth, rrank = recompute(ra[idx], rb[idx])
            alive[idx] = hit
            cur_nx[idx], cur_ny[idx], cur_depth[idx], cur_rank[idx] = rnx, rny, rdepth, rrank

    def push_out_deepest(s_idx: np.ndarray) -> None:
        """Push each mobile body fully out of its deepest immovable contact among ``s_idx``."""
        pick = s_idx[_first_per_group(mobile[s_idx], -cur_rank[s_idx])]
        m = mobile_l[pick]  # one contact per body: no repeats
        d = cur_depth[pick] * sgn[pick]
        zl[m] += _complex(cur_nx[pick] * d, cur_ny[pick] * d)
        dirty[0] = True
        moved[m] = True
        applied_nx[pick], applied_ny[pick] = cur_nx[pick], cur_ny[pick]
        pushed[pick] += cur_depth[pick]
        resolved[pick] = True
        alive[pick] = False  # touching now

    # The immovable contacts work on index sets: those of each support level, and those that may
    # need measuring again (not lone). The pairs of two dynamic bodies are columns (_DynamicPairs).
    sol_all = np.flatnonzero(solid)
    by_level = [sol_all[mob_level[sol_all] == lv] for lv in [*levels.tolist(), np.inf]] if sol_all.size else []
    sol_shared = sol_all[~lone[sol_all]]
    dyn = _DynamicPairs(np.flatnonzero(both), la, lb, nx, ny, depth, ia, ib, alive, lone, L)

    def moved_of(sel: np.ndarray) -> np.ndarray:
        return sel[moved[la[sel]] | moved[lb[sel]]]

    for it in range(max(1, iterations)):
        # Dynamic pairs: split by inverse mass, mean over each body's contacts.
        if dyn.push(zl, moved):
            dirty[0] = True
        # Immovable contacts: deepest one per dynamic body, level by level from the ground up,
        # each level measured again where the bodies under it moved.
        for at_level in by_level:
            remeasure(moved_of(at_level))
            s_idx = at_level[alive[at_level]]
            if s_idx.size == 0:
                continue
            push_out_deepest(s_idx)
        if it + 1 >= iterations:
            break
        stale = moved_of(sol_shared)
        if stale.size == 0 and not dyn.shared_moved(moved):
            break
        remeasure(stale)
        dyn.measure(zl - z0)
        moved[:] = False
        if not (dyn.any_alive() or alive[sol_all].any()):
            break
    dyn.store_results(pushed, resolved)

    # Clean-up: immovable contacts only, so no dynamic body is left inside static geometry by a
    # push from another dynamic body in the last pass.
    for _ in range(max(1, iterations) if sol_all.size else 0):
        remeasure(moved_of(sol_all))
        moved[:] = False
        s_idx = sol_all[alive[sol_all]]
        if s_idx.size == 0:
            break
        push_out_deepest(s_idx)

    flush()
    _velocities(store, ra, rb, ia0, ib0, solid, both, mobile_l, sgn, applied_nx, applied_ny, pushed,
                resolved, gravity, iterations, mob_level, lone, dt, la, lb, rows_u)
    return resolved, applied_nx, applied_ny, pushed


class _DynamicPairs:
    """The position passes over contacts between two dynamic bodies, as columns.

    Every pass pushes the overlapping pairs apart, each body moving by the mean of its pushes
    (Jacobi); the pairs are then measured again along their own normal: the depth of a fixed axis
    changes by exactly the relative displacement along it. Lone pairs (bodies in no other contact)
    are settled by the first pass and left alone. Masked arithmetic over all the pairs costs less
    than gathering the overlapping ones every pass; positions and normals are complex numbers, so
    one scatter moves both coordinates.
    """

    def __init__(self, idx, la, lb, nx, ny, depth, ia, ib, alive, lone, L) -> None:
        self.idx, self.L = idx, L
        cols = (la, lb, nx, ny, depth, ia, ib, alive, lone)
        if idx.size != la.size:  # (all contacts dynamic: the columns as they are)
            cols = tuple(col[idx] for col in cols)
        self.a, self.b, self.nx, self.ny, self.depth0, wa, wb, alive, self.lone = cols
        self.alive = alive.copy()  # (changed in place below: not the caller's)
        w = 1.0 / (wa + wb)
        fa, fb = wa * w, wb * w  # each body's share of a push
        self.move_a = _complex(-self.nx * fa, -self.ny * fa)  # a unit push, as a's and b's moves
        self.move_b = _complex(self.nx * fb, self.ny * fb)
        self.cur = self.depth0
        self.any_lone = bool(self.lone.any())
        self.pushed = np.zeros(idx.size)
        self.resolved = np.zeros(idx.size, dtype=bool)

    def push(self, zl, moved) -> bool:
        """One pass: push every overlapping pair apart (positions ``zl``, complex). Returns whether
        anything moved."""
        if not self.alive.any():
            return False
        a, b, L = self.a, self.b, self.L
        on = self.alive.astype(np.float64)
        p = self.cur * on
        count = np.zeros(L)
        np.add.at(count, a, on)
        np.add.at(count, b, on)
        sums = np.zeros(L, dtype=np.complex128)
        np.add.at(sums, a, p * self.move_a)
        np.add.at(sums, b, p * self.move_b)
        sums *= 1.0 / np.maximum(count, 1.0)
        zl += sums
        moved |= count > 0.0
        self.pushed += p
        self.resolved |= self.alive
        if self.any_lone:
            self.alive &= ~self.lone  # touching now, and nothing else moves them
        return True

    def shared_moved(self, moved) -> bool:
        return bool(moved[self.a].any() or moved[self.b].any())

    def measure(self, dz) -> None:
        """Depths after the bodies moved by ``dz`` (complex) since the start (lone pairs stay apart)."""
        d = dz[self.b] - dz[self.a]
        self.cur = self.depth0 - (d.real * self.nx + d.imag * self.ny)
        self.alive = self.cur > 0.0
        if self.any_lone:
            self.alive &= ~self.lone

    def any_alive(self) -> bool:
        return bool(self.alive.any())

    def store_results(self, pushed, resolved) -> None:
        """Write the total push and the resolved flag of every dynamic pair into the contact arrays."""
        pushed[self.idx] = self.pushed
        resolved[self.idx] = self.resolved


class _DynamicImpulses:
    """The velocity passes over resolved contacts between two dynamic bodies, as columns.

    Jacobi, made safe: a closing contact's impulse is divided by the larger number of closing
    contacts its two bodies are in. Each body's new velocity is then a convex combination of
    single-contact updates, none of which gains energy, so the pass gains none. (Full impulses
    summed let a box bouncing up into three bodies take three full bounces at once and shoot down
    through the floor: the 200-body soak found it.) A bounce applied whole is not looked at again;
    nor is a lone contact after the first pass. Velocities are complex numbers ``vx + i vy``.
    """

    def __init__(self, idx, la, lb, nx, ny, ia, ib, rest, resting_speed, lone, L) -> None:
        self.L = L
        cols = (la, lb, nx, ny, ia, ib, rest, resting_speed, lone)
        if idx.size != la.size:  # (all contacts dynamic: the columns as they are)
            cols = tuple(col[idx] for col in cols)
        self._take(*cols, np.zeros(idx.size, dtype=bool))

    def _take(self, a, b, nx, ny, wa, wb, rest, resting, lone, done) -> None:
        self.a, self.b, self.nx, self.ny, self.wa, self.wb = a, b, nx, ny, wa, wb
        self.rest, self.resting, self.lone, self.done = rest, resting, lone, done
        self.bouncy = bool(rest.any())
        self.skipping = bool(done.any())  # whether ``done`` masks anything
        inv = 1.0 / (wa + wb)
        # each body's share of the velocity change that stops the pair (see impulses)
        fa, fb = wa * inv, wb * inv
        self.dva = _complex(nx * fa, ny * fa)
        self.dvb = _complex(nx * fb, ny * fb)
        self.n = a.size
        self.v = self.mask = np.zeros(0)

    def closing(self, vz) -> bool:
        """Measure the normal speeds; whether any contact still to look at is closing."""
        if self.n == 0:
            return False
        d = vz[self.b] - vz[self.a]
        self.v = d.real * self.nx + d.imag * self.ny
        self.mask = self.v < 0.0
        if self.skipping:
            self.mask &= ~self.done
        return bool(self.mask.any())

    def impulses(self, vz) -> None:
        """Apply the impulses of the closing contacts (as last measured) to the velocities ``vz``.

        A contact closing at speed ``v < 0`` needs ``a`` to change by ``v * dva`` and ``b`` by
        ``-v * dvb`` to stop (``(1 + e)`` times that to bounce), shared out by ``w``."""
        if self.n == 0 or not self.mask.any():
            return
        m, a, b = self.mask, self.a, self.b
        on = m.astype(np.float64)
        count = np.zeros(self.L)
        np.add.at(count, a, on)
        np.add.at(count, b, on)
        w = 1.0 / np.maximum(np.maximum(count[a], count[b]), 1.0)
        j = self.v * w
        j *= on
        if self.bouncy:
            e = np.where(-self.v > self.resting, self.rest, 0.0)
            j *= 1.0 + e
            self.done |= m & (e > 0.0) & (w == 1.0)  # a shared bounce is looked at again next pass
            self.skipping = bool(self.done.any())
        np.add.at(vz, a, j * self.dva)
        np.subtract.at(vz, b, j * self.dvb)

    def drop_settled(self) -> None:
        """After the first pass: leave out the contacts settled (compacting the columns when that
        drops many of them, masking them otherwise)."""
        settled = self.done | self.lone
        keep = np.flatnonzero(~settled)
        if keep.size < 0.75 * self.n:
            self._take(*(col[keep] for col in (self.a, self.b, self.nx, self.ny, self.wa, self.wb, self.rest,
                                               self.resting, self.lone, self.done)))
        else:
            self.done = settled
            self.skipping = keep.size < self.n


def _shock_propagation(n, ra, rb, nx, ny, ia, ib, gravity, vx, vy, rows_a, rows_b, dt) -> np.ndarray:
    """Make a stack solid from the ground up (in place on ``ia``/``ib``).

    A dynamic body resting on something immovable has support level 1; one resting on a level-k
    body has level k + 1 ("resting on" = the contact normal within 60 degrees of straight up,
    against gravity). In a contact between two dynamic bodies at different levels, the lower one
    counts as immovable, so a pass pushes the upper one fully out instead of pressing the lower one
    into the floor: a stack settles in a few passes instead of sinking.

    Only a body *resting* on its support counts: one leaving it faster than gravity brings it back
    in a step (``vn > g dt``, e.g. a ball bouncing off the floor) supports nothing, so what it hits
    next meets a body of its real mass (momentum and energy kept) rather than a wall.
    """
    level = np.full(n, np.inf)
    gx, gy = gravity
    g = (gx * gx + gy * gy) ** 0.5
    if g == 0.0:
        return level
    ux, uy = -gx / g, -gy / g
    vn = (vx[rows_b] - vx[rows_a]) * nx + (vy[rows_b] - vy[rows_a]) * ny
    up = nx * ux + ny * uy  # > 0: b sits on a
    up = np.where(vn > g * dt, 0.0, up)  # separating: not resting
    solid = (ia == 0.0) != (ib == 0.0)
    on_ground = solid & (((ib > 0.0) & (up > 0.5)) | ((ia > 0.0) & (up < -0.5)))
    level[np.where(ib > 0.0, rb, ra)[on_ground]] = 1.0
    both = (ia > 0.0) & (ib > 0.0)
    b_on_a = both & (up > 0.5)
    a_on_b = both & (up < -0.5)
    lower = np.concatenate([ra[b_on_a], rb[a_on_b]])
    upper = np.concatenate([rb[b_on_a], ra[a_on_b]])
    if lower.size == 0:
        return level
    for _ in range(64):
        cand = level[lower] + 1.0
        new = level.copy()
        np.minimum.at(new, upper, cand)
        if np.array_equal(new, level):
            break
        level = new
    la, lb = level[ra], level[rb]
    ia[b_on_a & (la < lb)] = 0.0
    ib[a_on_b & (lb < la)] = 0.0
    return level


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
    of height per bounce (instead of a share of its energy proportional to dt). No real root: the
    push-out took more than the energy there was, so the body stops.
    """
    gp = np.maximum(g, 0.0)
    k = u * u - g * u * dt - 2.0 * g * d - 0.25 * gp * gp * dt * dt
    disc = g * g * dt * dt + 4.0 * k
    root = 0.5 * (g * dt + np.sqrt(np.maximum(disc, 0.0)))
    return np.where(disc >= 0.0, np.maximum(root, 0.0), 0.0)


def _velocities(store, ra, rb, ia, ib, solid, both, mobile_l, sgn, nx, ny, pushed, resolved, gravity,
                iterations, mob_level, lone, dt, la, lb, rows_u) -> None:
    """Velocity passes over the resolved contacts (``ia``/``ib``: the real inverse masses; ``la``,
    ``lb``, ``mobile_l``: local numbers of the bodies, rows ``rows_u`` of the store).

    The passes work on local copies of the bodies' velocities, written back once at the end.

    A contact ``solid`` only because its lower body is lower in a stack treats that body as
    immovable while it rests; once it moves into the upper one faster than a body at rest does
    (it bounced off its own support earlier in the pass), the two meet as the dynamic bodies
    they are: an immovable body moving up would hand the upper one a bounce off a moving wall
    and keep its own speed, making energy.
    """
    c = store.cols
    rest = np.maximum(c["restitution"][ra], c["restitution"][rb])
    gx, gy = gravity
    if gx or gy:
        # Restitution threshold: an approach no faster than gravity gives in two steps along the
        # normal is a body resting, not a bounce; without it a bouncy body on the floor hops by
        # e*g*dt every step forever and never sleeps.
        g_n = gx * nx + gy * ny
        resting_speed = 2.0 * np.abs(g_n) * dt
    else:
        g_n = resting_speed = np.zeros(ra.size)
    if mobile_l is not None:
        stacked = solid & (ia > 0.0) & (ib > 0.0)
        gn = -g_n * sgn  # gravity against the push-out direction of a solid contact's mobile body
    else:
        stacked = gn = None
    L = rows_u.size
    vz = _complex(c["vx"][rows_u], c["vy"][rows_u])
    _velocity_passes(vz, ia, ib, solid, both, mobile_l, sgn, nx, ny, pushed, resolved, iterations, mob_level,
                     lone, dt, la, lb, L, stacked, rest, gn, resting_speed)
    c["vx"][rows_u], c["vy"][rows_u] = vz.real, vz.imag


def _velocity_passes(vz, ia, ib, solid, both, mobile_l, sgn, nx, ny, pushed, resolved, iterations, mob_level,
                     lone, dt, la, lb, L, stacked, rest, gn, resting_speed) -> None:
    """The passes of ``_velocities`` on the local velocities ``vz = vx + i vy`` (changed in place)."""
    done = np.zeros(resolved.size, dtype=bool)  # bounces are applied once per contact
    act = np.flatnonzero(resolved & solid)  # the immovable contacts still to look at
    dyn = _DynamicImpulses(np.flatnonzero(resolved & both), la, lb, nx, ny, ia, ib, rest, resting_speed, lone, L)

    def closing_speed(idx: np.ndarray) -> np.ndarray:
        """Normal speed of b relative to a, now (< 0: closing)."""
        d = vz[lb[idx]] - vz[la[idx]]
        return d.real * nx[idx] + d.imag * ny[idx]

    def pair_impulses(idx: np.ndarray, v: np.ndarray) -> None:
        """Impulses between the dynamic bodies of the closing contacts ``idx`` (normal speeds ``v``),
        shared out as in :class:`_DynamicImpulses` (a stacked pair whose lower body came loose)."""
        a, b = la[idx], lb[idx]
        e = np.where(-v > resting_speed[idx], rest[idx], 0.0)
        per_body = np.bincount(np.concatenate([a, b]), minlength=L)
        w = 1.0 / np.maximum(per_body[a], per_body[b])
        wa, wb = ia[idx], ib[idx]
        j = -(1.0 + e) * v * w / (wa + wb)
        jz = _complex(j * nx[idx], j * ny[idx])
        np.add.at(vz, b, jz * wb)
        np.subtract.at(vz, a, jz * wa)
        done[idx] = (e > 0.0) & (w == 1.0)  # a shared bounce is looked at again next pass

    for it in range(max(1, iterations)):
        if act.size == 0 and dyn.n == 0:
            return
        vn = closing_speed(act)
        s_appr = vn < 0.0
        dyn_closing = dyn.closing(vz)
        if not (dyn_closing or s_appr.any()):
            return
        if s_appr.any():
            lvl = mob_level[act]
            lowest = lvl[s_appr].min()
            # Ground up: each level sees the velocities below it settled, so a level whose bodies
            # all fell together (not approaching at first) is looked at again once those below stop.
            for lv in np.unique(lvl[lvl >= lowest]).tolist():
                sel = np.flatnonzero((s_appr if lv == lowest else True) & (lvl == lv))
                s_idx = act[sel]
                if lv == lowest:
                    v_s = vn[sel]
                else:
                    v_s = closing_speed(s_idx)
                    keep = v_s < 0.0
                    s_idx, v_s = s_idx[keep], v_s[keep]
                if s_idx.size == 0:
                    continue
                first = _first_per_group(mobile_l[s_idx], v_s)
                pick, v = s_idx[first], v_s[first]
                if stacked[pick].any():
                    low = np.where(sgn[pick] > 0.0, la[pick], lb[pick])
                    v_low = sgn[pick] * (vz[low].real * nx[pick] + vz[low].imag * ny[pick])
                    loose = stacked[pick] & (v_low > resting_speed[pick])
                    if loose.any():
                        pair_impulses(pick[loose], v[loose])
                        pick, v = pick[~loose], v[~loose]
                        if pick.size == 0:
                            continue
                e = np.where(-v > resting_speed[pick], rest[pick], 0.0)
                target = e * _bounce_speed(v, gn[pick], pushed[pick], dt)
                dv = (target - v) * sgn[pick]
                m = mobile_l[pick]  # one contact per body: no repeats
                vz[m] += _complex(dv * nx[pick], dv * ny[pick])
                done[pick] = e > 0.0
            if dyn.n:
                dyn.closing(vz)  # the pass above changed velocities: measure after it
        dyn.impulses(vz)
        if it == 0:
            done |= lone  # a contact whose bodies touch nothing else is settled by one pass
            dyn.drop_settled()
        act = act[~done[act]]
