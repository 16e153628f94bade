"""The solve's compiled passes (framework.systems.solve_columns, solve_rounds) give the bits of the numpy
they replaced, on random columns with ties, -0.0, infinities and NaN."""

from __future__ import annotations

import math

import numpy as np
import pytest

from framework.events import pair_keys, sorted_member
from framework.stable_sort import argsort_ints, stable_argsort
from framework.systems import gather
from framework.systems import solve_columns as sc
from framework.systems import solve_rounds as sr
from framework.systems import solver_loops as loops


def _same(a: np.ndarray, b: np.ndarray) -> None:
    assert a.dtype == b.dtype and a.shape == b.shape
    assert a.tobytes() == b.tobytes()


def _contacts(rng: np.random.Generator, n: int, c: int) -> tuple[np.ndarray, ...]:
    """``c`` contacts between ``n`` bodies, no body with itself, and their unit normals: ``(a, b, nx, ny)``."""
    a = rng.integers(0, n, c)
    b = (a + 1 + rng.integers(0, n - 1, c)) % n
    return (a, b, *_normals(rng, c))


def _normals(rng: np.random.Generator, c: int) -> tuple[np.ndarray, np.ndarray]:
    """``c`` unit normals at random angles: ``(nx, ny)``."""
    angle = rng.uniform(-np.pi, np.pi, c)
    return np.cos(angle), np.sin(angle)


def _floats(rng: np.random.Generator, n: int, specials: bool = True) -> np.ndarray:
    v = np.round(rng.normal(size=n), 1)  # (rounded: ties)
    if specials and n > 4:
        k = rng.integers(0, n, 4)
        v[k] = [np.nan, -0.0, 0.0, -np.inf]
    return v


@pytest.mark.parametrize("seed", range(8))
def test_stable_argsort_is_numpys_stable_argsort(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for n in (0, 1, 2, 7, 33, 200):
        key = _floats(rng, n)
        _same(stable_argsort(key), np.argsort(key, kind="stable").astype(np.int64))
        ints = rng.integers(-3, 4, n).astype(np.int64) << 40  # (the soft step's keys: integers, many ties)
        _same(stable_argsort(ints), np.argsort(ints, kind="stable").astype(np.int64))
        for runs in (1, 2, 3, 6):  # (a few runs in order, ties across them: NaN last in each)
            cut = np.sort(rng.integers(0, n + 1, runs - 1))
            for keys in (key, ints):
                joined = np.concatenate([np.sort(p, kind="stable") for p in np.split(keys, cut)])
                _same(stable_argsort(joined), np.argsort(joined, kind="stable").astype(np.int64))


@pytest.mark.parametrize("seed", range(8))
def test_argsort_ints_is_numpys_stable_argsort(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for n in (0, 1, 2, 3, 7, 33, 200, 3000):
        for keys in (rng.integers(-(2**62), 2**62, n), rng.integers(-3, 4, n).astype(np.int64) << 40,
                     rng.integers(0, 50, n).astype(np.int64) << 32 | rng.integers(0, 50, n)):  # (pair keys: ties)
            _same(argsort_ints(keys), np.argsort(keys, kind="stable").astype(np.int64))
            cut = np.sort(rng.integers(0, n + 1, 3))  # (four runs in order: merged)
            joined = np.concatenate([np.sort(p, kind="stable") for p in np.split(keys, cut)])
            _same(argsort_ints(joined), np.argsort(joined, kind="stable").astype(np.int64))


def _scene(rng: np.random.Generator, n_rows: int, c: int):
    rows = rng.permutation(n_rows)[: max(2, n_rows // 2)].astype(np.int64)
    a = rng.integers(0, rows.size, c)
    b = (a + 1 + rng.integers(0, rows.size - 1, c)) % rows.size
    return rows, a.astype(np.int64), b.astype(np.int64)


@pytest.mark.parametrize("seed", range(8))
def test_contact_columns_are_the_numpy_columns(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n_rows, c = 40, 30
    rows, a, b = _scene(rng, n_rows, c)
    ra, rb = rows[a], rows[b]
    hw = np.where(rng.random(n_rows) < 0.3, 0.0, rng.random(n_rows))
    hh, bound = rng.random(n_rows), rng.random(n_rows) + 0.5
    asleep = rng.random(n_rows) < 0.2
    inv_mass = np.where(rng.random(n_rows) < 0.3, 0.0, rng.random(n_rows) + 0.1)
    x, y = _floats(rng, n_rows), _floats(rng, n_rows)
    for statics, (gx, gy) in ((True, (0.0, -10.0)), (False, (3.0, -4.0)), (True, (0.0, 0.0))):
        g = math.hypot(gx, gy)
        with np.errstate(divide="ignore", invalid="ignore"):
            per_body, per_contact, got_immovable, got_order = sc.contact_columns(
                rows, ra, rb, hw, hh, bound, asleep, inv_mass, x, y, gx, gy, g)
            got = (per_body[0], per_body[0] if statics else per_body[1], *per_contact, got_immovable, got_order)
            half = np.where(hw[rows] > 0.0, np.minimum(hw[rows], hh[rows]), 0.5 * bound[rows])
            span = 0.5 * half
            reach = span if statics else np.full(rows.size, np.inf)
            wa = np.where(asleep[ra], 0.0, inv_mass[ra])
            wb = np.where(asleep[rb], 0.0, inv_mass[rb])
            w = 1.0 / (wa + wb)
            shares = (wa * w, wb * w)
            immovable = (wa == 0.0) | (wb == 0.0)
            if g == 0.0:
                order = np.arange(c)
            else:
                up_a = -(x[ra] * gx + y[ra] * gy) / g
                up_b = -(x[rb] * gx + y[rb] * gy) / g
                order = np.argsort(np.where(immovable, -np.inf, np.minimum(up_a, up_b)), kind="stable")
        wants = (span, reach, wa, wb, *shares, immovable, order.astype(np.int64))
        assert len(got) == len(wants)
        for have, want in zip(got, wants):
            _same(have, want)


def _lower_stays(b_on_a, a_on_b, share_a, share_b):
    return (np.where(b_on_a, 0.0, np.where(a_on_b, 1.0, share_a)),
            np.where(b_on_a, 1.0, np.where(a_on_b, 0.0, share_b)))


@pytest.mark.parametrize("seed", range(8))
def test_stays_are_the_numpy_shock_shares(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n, c = 12, 25
    a, b, nx, ny = _contacts(rng, n, c)
    share_a = np.where(rng.random(c) < 0.3, 0.0, rng.random(c))
    share_b = np.where(share_a == 0.0, 1.0, 1.0 - share_a)
    immovable = (share_a == 0.0) & (rng.random(c) < 0.7)
    rolling = rng.random(c) < 0.2
    order = rng.permutation(c)
    gx, gy = 1.0, -9.0
    g = math.hypot(gx, gy)
    up = -(nx * gx + ny * gy) / g
    held = loops.supported(order, a, b, up, share_a == 0.0, share_b == 0.0, n)
    rests = ~immovable & ~rolling
    b_on_a = rests & (up > 0.5) & held[a]
    a_on_b = rests & (up < -0.5) & held[b]
    got = sc.stays(order, a, b, nx, ny, gx, gy, g, share_a, share_b, immovable, rolling, n)
    for have, want in zip(got, (b_on_a, a_on_b, *_lower_stays(b_on_a, a_on_b, share_a, share_b))):
        _same(have, want)
    # the impulses' stays
    vx, vy = _floats(rng, n, specials=False), _floats(rng, n, specials=False)
    wa, wb = rng.random(c), rng.random(c)
    dt = 1.0 / 60.0
    resting_speed = 2.0 * np.abs(gx * nx + gy * ny) * dt
    va = b_on_a & (vx[a] * nx + vy[a] * ny <= resting_speed)
    vb = a_on_b & (-(vx[b] * nx + vy[b] * ny) <= resting_speed)
    hits = (vx[a] - vx[b]) * nx + (vy[a] - vy[b]) * ny > resting_speed
    va &= ~(hits & (wb < wa))
    vb &= ~(hits & (wa < wb))
    got = sc.velocity_stays(a, b, nx, ny, vx, vy, gx, gy, dt, b_on_a, a_on_b, wa, wb, share_a, share_b)
    for have, want in zip(got, (va, vb, *_lower_stays(va, vb, share_a, share_b))):
        _same(have, want)


@pytest.mark.parametrize("seed", range(8))
def test_rigid_shares_and_lever_arms_are_the_numpy_ones(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n, c = 12, 25
    a, b, nx, ny = _contacts(rng, n, c)
    rows = rng.permutation(40)[:n]
    ra, rb = rows[a], rows[b]
    # the shares, some bodies kept still, some contacts without mass or arm (1/0: inf and NaN)
    still_a, still_b = rng.random(c) < 0.3, rng.random(c) < 0.3
    wa, wb = np.where(rng.random(c) < 0.2, 0.0, rng.random(c)), np.where(rng.random(c) < 0.2, 0.0, rng.random(c))
    ia, ib = _floats(rng, c, specials=False) ** 2, _floats(rng, c, specials=False) ** 2
    rn_a, rn_b = _floats(rng, c), _floats(rng, c)
    w_a, w_b = np.where(still_a, 0.0, wa), np.where(still_b, 0.0, wb)
    i_a, i_b = np.where(still_a, 0.0, ia), np.where(still_b, 0.0, ib)
    with np.errstate(all="ignore"):
        inv = 1.0 / (w_a + w_b + i_a * rn_a * rn_a + i_b * rn_b * rn_b)
        want = (w_a * inv, w_b * inv, i_a * rn_a * inv, i_b * rn_b * inv)
    for have, expected in zip(sc.rigid_shares(still_a, still_b, wa, wb, ia, ib, rn_a, rn_b), want):
        _same(have, expected)
    # the lever arms, with a deep contact or two (arms 0, -0.0 kept) and arms that changed
    rax, ray, rbx, rby = (_floats(rng, c) for _ in range(4))
    depth = np.where(rng.random(c) < 0.2, 5.0, _floats(rng, c, specials=False))
    span = rng.random(n)
    asleep, inv_inertia = rng.random(40) < 0.2, np.where(rng.random(40) < 0.3, 0.0, rng.random(40))
    kind = rng.integers(0, 3, 40)
    k = c - 5  # (the contacts the arms were known for)
    old_a, old_b, dturn = _floats(rng, k), _floats(rng, k), _floats(rng, n, specials=False)
    flat = depth <= np.minimum(span[a], span[b])
    with np.errstate(all="ignore"):  # (0 times inf: NaN, as the pass gives)
        want_rn = (flat * (rax * ny - ray * nx), flat * (rbx * ny - rby * nx))
        want_rt = (flat * (rax * nx + ray * ny), flat * (rbx * nx + rby * ny))
    turning = ((kind[ra] == 2) & (inv_inertia[ra] > 0.0)) | ((kind[rb] == 2) & (inv_inertia[rb] > 0.0))
    for turned in (False, True):
        d = depth.copy()
        got = sc.lever_arms(ra, rb, rax, ray, rbx, rby, nx, ny, d, a, b, span, asleep, inv_inertia, kind, 2,
                            old_a if turned else np.zeros(0), old_b if turned else np.zeros(0),
                            dturn if turned else np.zeros(0), turned)
        want_depth = depth.copy()
        if turned:
            with np.errstate(all="ignore"):
                before = old_b * dturn[b[:k]] - old_a * dturn[a[:k]]
                want_depth[:k] += want_rn[1][:k] * dturn[b[:k]] - want_rn[0][:k] * dturn[a[:k]] - before
        want = (np.where(asleep[ra], 0.0, inv_inertia[ra]), np.where(asleep[rb], 0.0, inv_inertia[rb]), *want_rn,
                *want_rt, turning)
        for have, expected in zip(got, want):
            _same(have, expected)
        _same(d, want_depth)


@pytest.mark.parametrize("rigid", [False, True])
def test_separations_are_the_numpy_ones(rigid: bool) -> None:
    rng = np.random.default_rng(5)
    n, c = 12, 25
    a, b, nx, ny = _contacts(rng, n, c)
    dx, dy, depth = _floats(rng, n), _floats(rng, n), _floats(rng, c)
    rn_a, rn_b, dturn = (_floats(rng, c), _floats(rng, c), _floats(rng, n)) if rigid else (np.zeros(0),) * 3
    with np.errstate(all="ignore"):
        shift = (dx[b] - dx[a]) * nx + (dy[b] - dy[a]) * ny
        if rigid:
            shift += rn_b * dturn[b] - rn_a * dturn[a]
        want = shift - depth
    _same(sr.separations(a, b, nx, ny, dx, dy, rn_a, rn_b, dturn, depth), want)


def test_pair_friction_is_the_numpy_rule() -> None:
    from framework.store import _pair_friction

    friction = np.array([0.5, -1.0, 0.0, 0.25, np.nan, 2.0, -0.5])
    ra, rb = (np.array(p, dtype=np.int64) for p in zip(*[(i, j) for i in range(7) for j in range(7)]))
    fa, fb = friction[ra], friction[rb]
    with np.errstate(invalid="ignore"):
        given_a, given_b = fa >= 0.0, fb >= 0.0
        both = np.sqrt(np.maximum(fa, 0.0) * np.maximum(fb, 0.0))
    want = np.where(given_a & given_b, both, np.where(given_a, fa, np.where(given_b, fb, 0.0)))
    _same(_pair_friction(friction, ra, rb), want)


@pytest.mark.parametrize("seed", range(8))
def test_warm_pushes_are_the_numpy_warm_pushes(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n, c = 10, 20
    a, b, nx, ny = _contacts(rng, n, c)
    share_a = rng.random(c)
    share_b = 1.0 - share_a
    push0 = np.where(rng.random(c) < 0.3, 0.0, rng.random(c))
    span = 0.1 + 0.2 * rng.random(n)
    for reach in (span, np.full(n, np.inf), 1e-3 * span):
        cap = 2.0 * np.minimum(span[a], span[b])
        p = np.minimum(push0, cap)
        if np.isfinite(reach).all() and p.any():
            wx, wy = loops.warm_start(a, b, nx, ny, share_a, share_b, p, n)
            with np.errstate(over="ignore"):
                scale = np.minimum(1.0, reach / np.maximum(np.hypot(wx, wy), 1e-300))
            p = p * np.minimum(scale[a], scale[b])
        dx, dy = loops.warm_start(a, b, nx, ny, share_a, share_b, p, n)
        got = sc.warm_pushes(a, b, nx, ny, share_a, share_b, push0, span, reach)
        for have, want in zip(got, (p, dx, dy)):
            _same(have, want)


# --- the rounds' bookkeeping (framework.systems.solve_rounds) ---------------------------------


@pytest.mark.parametrize("seed", range(6))
def test_number_is_the_numpy_numbering(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = 30
    table, want_table = np.full(n, -1, dtype=np.int64), np.full(n, -1, dtype=np.int64)
    first = 0
    for _ in range(3):
        ra, rb = rng.integers(0, n, 8), rng.integers(0, n, 8)
        rows = np.concatenate([ra, rb])
        new = np.unique(rows[want_table[rows] < 0])
        want_table[new] = first + np.arange(new.size)
        got_new, got_local = sr.number(table, ra, rb, first)
        _same(got_new, new)
        _same(got_local, want_table[rows])
        _same(table, want_table)
        first += new.size


@pytest.mark.parametrize("seed", range(6))
def test_pair_picks_are_the_numpy_picks(seed: int) -> None:
    rng = np.random.default_rng(seed)
    ea, eb, ca, cb = (rng.integers(0, 50, 12) for _ in range(4))
    known = sr.known_keys(ea, eb, ca, cb)
    _same(known, np.sort(np.concatenate([pair_keys(ea, eb), pair_keys(ca, cb)])))
    # candidates not known, in the store, solid
    n = 40
    kind = rng.integers(-1, 3, n)
    sensor, asleep, one_way = (rng.random(n) < 0.1 for _ in range(3))
    inv_mass = np.where(rng.random(n) < 0.4, 0.0, 1.0)
    layer, mask = rng.integers(1, 4, n), rng.integers(1, 4, n)
    pa, pb = rng.integers(0, 45, 30), rng.integers(0, 45, 30)
    pea, peb = np.concatenate([ea[:5], rng.integers(0, 50, 25)]), np.concatenate([eb[:5], rng.integers(0, 50, 25)])
    cols = (kind, sensor, inv_mass, asleep, one_way, layer, mask, False)
    keep = ~sorted_member(pair_keys(pea, peb), known) & (pa < n) & (pb < n)
    ok = gather.solid_pairs_mask(pa[keep], pb[keep], *cols)
    want = tuple(v[keep][ok] for v in (pa, pb, pea, peb))
    for have, w in zip(sr.unknown_solid_pairs(pa, pb, pea, peb, known, n, *cols), want):
        _same(have, w)
    # the same pairs sorted by key, as the broad phase gives them: one walk along ``known``
    order = np.argsort(pair_keys(pea, peb), kind="stable")
    pa, pb, pea, peb = pa[order], pb[order], pea[order], peb[order]
    keep = ~sorted_member(pair_keys(pea, peb), known) & (pa < n) & (pb < n)
    ok = gather.solid_pairs_mask(pa[keep], pb[keep], *cols)
    want = tuple(v[keep][ok] for v in (pa, pb, pea, peb))
    for have, w in zip(sr.unknown_solid_pairs(pa, pb, pea, peb, known, n, *cols), want):
        _same(have, w)
    # the statics near the movable bodies, and their kept pairs
    x, y = _floats(rng, n, specials=False), _floats(rng, n, specials=False)
    cx, cy = np.where(rng.random(n) < 0.3, np.nan, x + 0.1), y - 0.05
    rows_all = rng.permutation(n)[:15]
    local = rng.permutation(15)[:10]
    reach = np.where(rng.random(15) < 0.2, np.inf, 0.1 + 0.1 * rng.random(15))
    rows, margin = rows_all[local], reach[local]
    ok = (inv_mass[rows] > 0.0) & ~asleep[rows] & np.isfinite(margin)
    r, m = rows[ok], margin[ok]
    far = ~(np.abs(x[r] - cx[r]) + np.abs(y[r] - cy[r]) <= m)
    for have, w in zip(sr.near_rows(local, rows_all, reach, inv_mass, asleep, x, y, cx, cy), (r, m, far)):
        _same(have, w)
    lut = np.where(rng.random(60) < 0.1, -1, rng.integers(0, n, 60))
    pair_row = rng.integers(0, n, 30)
    want_rows = np.zeros(n, dtype=bool)
    want_rows[r] = True
    sel = want_rows[pair_row]
    e1, e2 = pea[sel], peb[sel]
    keep = ~sorted_member(pair_keys(e1, e2), known)
    e1, e2 = e1[keep], e2[keep]
    r1, r2 = lut[e1], lut[e2]
    ok = gather.solid_pairs_mask(r1, r2, *cols)
    got = sr.kept_static_pairs(n, r, pair_row, pea, peb, known, lut, *cols)
    for have, w in zip(got, (r1[ok], r2[ok], e1[ok], e2[ok])):
        _same(have, w)


@pytest.mark.parametrize("rigid", [False, True])
def test_apply_measures_is_the_numpy_update(rigid: bool) -> None:
    rng = np.random.default_rng(int(rigid))
    n, c = 10, 24
    a, b = rng.integers(0, n, c), rng.integers(0, n, c)
    nx, ny = _normals(rng, c)
    depth = rng.normal(size=c) * 0.01
    dx, dy = rng.normal(size=n) * 0.01, rng.normal(size=n) * 0.01
    rn_a, rn_b, dturn = (rng.normal(size=c), rng.normal(size=c), rng.normal(size=n) * 0.01) if rigid else (
        np.zeros(0), np.zeros(0), np.zeros(0))
    check = np.sort(rng.permutation(c)[:12])
    hit = rng.random(12) < 0.5
    ra = rng.uniform(-np.pi, np.pi, 12)
    rnx, rny, rdepth = np.cos(ra), np.sin(ra), rng.normal(size=12) * 1e-8

    def shift(idx):
        s = (dx[b[idx]] - dx[a[idx]]) * nx[idx] + (dy[b[idx]] - dy[a[idx]]) * ny[idx]
        if rigid:
            s += rn_b[idx] * dturn[b[idx]] - rn_a[idx] * dturn[a[idx]]
        return s

    cols = [nx.copy(), ny.copy(), depth.copy()]
    dirty = np.zeros(c, dtype=bool)
    got = sr.apply_measures(check, hit, rnx, rny, rdepth, a, b, *cols, dx, dy, rn_a, rn_b, dturn, dirty, 1e-9)
    apart = check[~hit]
    depth[apart] = np.minimum(depth[apart], shift(apart))
    h = check[hit]
    nx[h], ny[h] = rnx[hit], rny[hit]
    depth[h] = rdepth[hit] + shift(h)
    for have, w in zip(cols, (nx, ny, depth)):
        _same(have, w)
    assert dirty.tobytes() == np.isin(np.arange(c), h).tobytes()
    assert got == (bool(hit.any()), bool((rdepth[hit] > 1e-9).any()))


@pytest.mark.parametrize("seed", range(6))
def test_measured_points_are_the_numpy_update(seed: int) -> None:
    """``Solve._measure_points``' pairs (np.unique of the keys) and its depths and flags, compiled
    (solve_rounds.pairs_of, points_measured), against the numpy they replaced: pairs measured with
    as many, fewer or no points, separations with ties, -0.0 and NaN."""
    rng = np.random.default_rng(seed)
    n, c = 8, 30
    a, b = rng.integers(0, n, c), rng.integers(0, n, c)
    ea, eb = rng.integers(1, 5, c).astype(np.int64), rng.integers(5, 9, c).astype(np.int64)  # (pairs repeat)
    nx, ny = _normals(rng, c)
    depth = _floats(rng, c) * 0.01
    dx, dy = rng.normal(size=n) * 0.01, rng.normal(size=n) * 0.01
    rn_a, rn_b, dturn = rng.normal(size=c), rng.normal(size=c), rng.normal(size=n) * 0.01
    slot = rng.integers(0, 3, c).astype(np.int64)
    bound = rng.uniform(0.5, 2.0, n).round(1)
    ra, rb = rng.integers(0, n, c), rng.integers(0, n, c)
    check = rng.permutation(c)[:18]
    keys = pair_keys(ea[check], eb[check])
    _u, first, pair = np.unique(keys, return_index=True, return_inverse=True)
    got_first, got_pair = sr.pairs_of(check, ea, eb)
    _same(got_first, first.astype(np.int64))
    _same(got_pair, pair.astype(np.int64))
    rows = first.size
    n_pts = rng.integers(0, 3, rows).astype(np.int64)
    sep = _floats(rng, 2 * rows).reshape(rows, 2) * 1e-6
    tol, slack_k = 1e-9, 1e-7
    dirty = rng.random(c) < 0.2
    want_dirty, want_depth = dirty.copy(), depth.copy()
    got_depth = depth.copy()
    over = sr.points_measured(check, pair, n_pts, sep, slot, a, b, nx, ny, dx, dy, rn_a, rn_b, dturn, got_depth, dirty,
                              tol, ra, rb, bound, slack_k)
    had = np.bincount(pair, minlength=rows)
    same = n_pts[pair] == had[pair]
    sl = np.minimum(slot[check], 1)
    deepest = np.where(n_pts > 1, sep.min(axis=1), sep[:, 0])
    now = np.where(same, sep[pair, sl], deepest[pair])
    apart = n_pts[pair] == 0
    shift = (dx[b[check]] - dx[a[check]]) * nx[check] + (dy[b[check]] - dy[a[check]]) * ny[check]
    shift += rn_b[check] * dturn[b[check]] - rn_a[check] * dturn[a[check]]
    with np.errstate(invalid="ignore"):  # (inf - inf: NaN, as the compiled pass makes it)
        new = np.where(apart, np.minimum(want_depth[check], shift), shift - now)
        want_dirty[check[np.abs(new - want_depth[check]) > tol]] = True
    want_depth[check] = new
    deep = (-now > slack_k * (1.0 + np.minimum(bound[ra], bound[rb]))[check]) & ~apart
    want_dirty[check[deep]] = True
    _same(got_depth, want_depth)
    _same(dirty, want_dirty)
    assert over == bool(deep.any())
    # (and the rounds' test of what is left overlapping: every contact's separation, numpy's way)
    immovable = rng.random(c) < 0.6
    for flags in (dirty, np.ones(c, dtype=bool), np.zeros(c, dtype=bool)):
        with np.errstate(invalid="ignore"):
            every = np.arange(c)
            sep = (dx[b] - dx[a]) * nx + (dy[b] - dy[a]) * ny
            sep += rn_b[every] * dturn[b] - rn_a[every] * dturn[a]
            sep -= got_depth
            want = bool(((sep < -(slack_k * (1.0 + np.minimum(bound[ra], bound[rb])))) & flags & immovable).any())
        assert sr.pending_points(a, b, nx, ny, dx, dy, rn_a, rn_b, dturn, got_depth, flags, immovable, ra, rb, bound,
                                 slack_k) == want


@pytest.mark.parametrize("seed", range(6))
def test_friction_columns_limits_and_clip_are_the_numpy_ones(seed: int) -> None:
    """Friction's columns (arms, k, shares, turns), limits and clip, compiled, against the numpy
    they replaced: circles and boxes, sleepers, given arms and inertias or the store's, shares
    that keep a lower body still, values beyond the bounds, -0.0 and NaN."""
    from framework.systems import friction as fr

    rng = np.random.default_rng(seed)
    n, c = 9, 25
    ra, rb = rng.integers(0, n, c), rng.integers(0, n, c)
    kind = rng.integers(0, 3, n).astype(np.int8)
    radius, inv_inertia = rng.uniform(0.2, 1.0, n).round(2), rng.uniform(0.0, 2.0, n).round(1)
    asleep = rng.random(n) < 0.2
    wa, wb = rng.uniform(0.0, 1.0, c).round(1), rng.uniform(0.0, 1.0, c).round(1)
    wb[wa == 0.0] += 0.5  # (no pair of two immovable bodies: k > 0)
    given_arms, given_inertia = (_floats(rng, c, False), _floats(rng, c, False)), (rng.uniform(0, 1, c),
                                                                                  rng.uniform(0, 1, c))
    for arms in (None, given_arms):
        for inertia in (None, given_inertia):
            for rotation in (False, True):
                cols, turns = fr._columns(ra, rb, wa, wb, kind, radius, asleep, inv_inertia,
                                          *(arms if arms is not None else (fr._NONE, fr._NONE)),
                                          *(inertia if inertia is not None else (fr._NONE, fr._NONE)),
                                          arms is not None, inertia is not None, rotation, 1)
                if arms is None:
                    arm_a = np.where(kind[ra] == 1, radius[ra], 0.0)
                    arm_b = np.where(kind[rb] == 1, -radius[rb], 0.0)
                else:
                    arm_a, arm_b = arms
                if inertia is not None:
                    ia, ib = inertia
                elif rotation:
                    ia, ib = np.where(asleep[ra], 0.0, inv_inertia[ra]), np.where(asleep[rb], 0.0, inv_inertia[rb])
                else:
                    ia = ib = np.zeros(c)
                k = wa + wb + ia * arm_a * arm_a + ib * arm_b * arm_b
                inv = 1.0 / k
                for got, want in zip(cols, (arm_a, arm_b, k, wa * inv, wb * inv, ia * arm_a * inv, ib * arm_b * inv)):
                    _same(got, want)
                assert turns == bool(ia.any() or ib.any())
    mu, k = rng.uniform(0.0, 1.0, c).round(1), rng.uniform(0.5, 2.0, c)
    share_a, share_b = np.where(rng.random(c) < 0.3, 0.0, wa), np.where(rng.random(c) < 0.3, 0.0, wb)
    for turning in (None, (rng.uniform(0, 1, c), rng.uniform(0, 1, c))):
        ka, kb = (wa, wb) if turning is None else (wa + turning[0], wb + turning[1])
        lower_a, lower_b = (share_a == 0.0) & (wa > 0.0), (share_b == 0.0) & (wb > 0.0)
        with np.errstate(divide="ignore"):  # (a lower body's partner immovable: inf, as numpy makes it)
            want = mu * (k / np.where(lower_a, kb, np.where(lower_b, ka, ka + kb)))
        got = fr._limits(share_a, share_b, wa, wb, *(turning if turning is not None else (fr._NONE, fr._NONE)),
                         turning is not None, mu, k)
        _same(got, want)
    value, normal, limits = _floats(rng, c) * 3.0, _floats(rng, c), _floats(rng, c)
    with np.errstate(invalid="ignore"):
        bound = limits * normal
        _same(fr._clip(value, normal, limits), np.clip(value, -bound, bound))


@pytest.mark.parametrize("seed", range(6))
def test_velocity_passes_are_the_numpy_velocity_start(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n_rows, c = 30, 20
    rows, a, b = _scene(rng, n_rows, c)
    ra, rb = rows[a], rows[b]
    nx, ny = _normals(rng, c)
    svx, svy = _floats(rng, n_rows, specials=False), _floats(rng, n_rows, specials=False)
    vx, vy, u = sc.closing_speeds(rows, a, b, nx, ny, svx, svy)
    want_vx, want_vy = svx[rows].copy(), svy[rows].copy()
    _same(vx, want_vx)
    _same(vy, want_vy)
    _same(u, (want_vx[b] - want_vx[a]) * nx + (want_vy[b] - want_vy[a]) * ny)
    if seed == 0:
        u[3] = np.nan
    warm = rng.random(c) < 0.6
    touching = warm | (rng.random(c) < 0.2)
    order = rng.permutation(c)
    impulse0 = rng.random(c)
    share_a = rng.random(c)
    share_b = 1.0 - share_a
    got_order, impulse, fastest = sc.warm_impulses(order, touching, warm, impulse0, a, b, nx, ny, share_a, share_b,
                                                   vx, vy, u)
    want_impulse = np.where(warm, impulse0, 0.0)
    wx, wy = loops.warm_start(a, b, nx, ny, share_a, share_b, want_impulse, rows.size)
    want_vx += wx
    want_vy += wy
    _same(got_order, order[touching[order]])
    _same(impulse, want_impulse)
    _same(vx, want_vx)
    _same(vy, want_vy)
    want_fastest = float(np.abs(u).max(initial=0.0))
    assert np.float64(fastest).tobytes() == np.float64(want_fastest).tobytes()
    # bounces
    restitution = np.where(rng.random(n_rows) < 0.5, 0.0, rng.random(n_rows))
    alive0 = rng.random(c) < 0.8
    gx, gy, dt = 0.0, -10.0, 1.0 / 60.0
    u = rng.normal(size=c)
    rest = np.maximum(restitution[ra], restitution[rb])
    g_n = gx * nx + gy * ny
    resting_speed = 2.0 * np.abs(g_n) * dt
    act = np.flatnonzero(warm)
    hits = np.zeros(c, dtype=bool)
    hits[act] = (rest[act] > 0.0) & (-u[act] > resting_speed[act]) & alive0[act]
    for have, want in zip(sc.bounce_hits(warm, u, ra, rb, restitution, nx, ny, gx, gy, dt, alive0), (hits, rest, g_n)):
        _same(have, want)


@pytest.mark.parametrize("rigid", [False, True])
def test_recorded_is_the_numpy_record(rigid: bool) -> None:
    rng = np.random.default_rng(7 + int(rigid))
    n, c = 10, 30
    a, b = rng.integers(0, n, c), rng.integers(0, n, c)
    ea, eb = rng.integers(0, 6, c), rng.integers(0, 6, c)  # (repeated pairs: a pair's points)
    nx, ny = _normals(rng, c)
    depth = rng.normal(size=c) * 0.01
    dx, dy, span = rng.normal(size=n) * 0.01, rng.normal(size=n) * 0.01, 0.01 * rng.random(n)
    rn_a, rn_b, dturn = (rng.normal(size=c), rng.normal(size=c), rng.normal(size=n) * 0.01) if rigid else (
        np.zeros(0), np.zeros(0), np.zeros(0))
    touching = rng.random(c) < 0.4
    push = np.where(rng.random(c) < 0.5, 0.0, 0.02 * rng.random(c))
    near = rng.random(c) < 0.3 if rigid else np.zeros(0, dtype=bool)
    impulse, tpush, timpulse = rng.random(c), rng.random(c), rng.random(c)
    ints, floats, applied = sr.recorded(touching, push, near, ea, eb, nx, ny, a, b, dx, dy, depth, rn_a, rn_b, dturn,
                                        span, impulse, tpush, timpulse)
    got = (*ints, *floats, applied)
    acted = touching | (push > 0.0)
    kept = acted | near if rigid else acted
    rows = np.flatnonzero(kept)
    keys = pair_keys(ea[rows], eb[rows])
    order = np.argsort(keys, kind="stable")
    rows, keys = rows[order], keys[order]
    sep = (dx[b] - dx[a]) * nx + (dy[b] - dy[a]) * ny
    if rigid:
        sep += rn_b * dturn[b] - rn_a * dturn[a]
    sep = sep - depth
    capped = np.minimum(push, 2.0 * np.minimum(span[a], span[b]))
    want = (rows, keys, ea[rows], eb[rows], nx[rows], ny[rows], np.maximum(sep[rows], 0.0), push[rows], capped[rows],
            impulse[rows], tpush[rows], timpulse[rows], acted[rows])
    assert len(got) == len(want)
    for have, w in zip(got, want):
        _same(have, w)


def test_place_and_far_bodies_are_the_numpy_ones() -> None:
    rng = np.random.default_rng(3)
    n_rows, n, c = 20, 8, 12
    rows = rng.permutation(n_rows)[:n]
    x0, y0 = rng.normal(size=n), rng.normal(size=n)
    dx = np.where(rng.random(n) < 0.4, 0.0, 0.1 * rng.normal(size=n))
    dy = np.where(rng.random(n) < 0.4, 0.0, 0.1 * rng.normal(size=n))
    sx, sy = rng.normal(size=n_rows), rng.normal(size=n_rows)
    want_x, want_y = sx.copy(), sy.copy()
    moved = np.flatnonzero((dx != 0.0) | (dy != 0.0))
    want_x[rows[moved]], want_y[rows[moved]] = x0[moved] + dx[moved], y0[moved] + dy[moved]
    seen_x, seen_y = np.where(rng.random(n) < 0.5, dx, 0.0), dy.copy()
    placed, *got = sr.place(rows, x0, y0, dx, dy, sx, sy, seen_x, seen_y)
    assert placed == moved.size
    _same(sx, want_x)
    _same(sy, want_y)
    for have, want in zip(got, ((dx != seen_x) | (dy != seen_y), dx, dy)):
        _same(have, want)
    fx, fy, limit = 0.05 * rng.normal(size=n), 0.05 * rng.normal(size=n), 0.1 * rng.random(n)
    far = np.hypot(dx - fx, dy - fy) > limit
    got_far, anyone = sr.far_bodies(dx, dy, fx, fy, limit, np.zeros(0, dtype=bool), np.zeros(0),
                                    np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64))
    _same(got_far, far)
    assert anyone == bool(far.any())
    a, b = rng.integers(0, n, c), rng.integers(0, n, c)
    immovable, push = rng.random(c) < 0.3, np.where(rng.random(c) < 0.3, 0.0, rng.random(c))
    both = ~immovable & (push > 0.0)
    pushed = np.zeros(n, dtype=bool)
    pushed[a[both]] = pushed[b[both]] = True
    pushed &= far
    got_far, anyone = sr.far_bodies(dx, dy, fx, fy, limit, immovable, push, a, b)
    _same(got_far, pushed)
    assert anyone == bool(pushed.any())


@pytest.mark.parametrize("immovable_only", [False, True])
def test_moved_candidates_are_the_numpy_ones(immovable_only: bool) -> None:
    rng = np.random.default_rng(11)
    n_rows, n, c = 30, 12, 25
    table = np.full(n_rows, -1, dtype=np.int64)
    table[rng.permutation(n_rows)[:n]] = np.arange(n)
    moved = rng.random(n) < 0.5
    ra, rb = rng.integers(0, n_rows, c), rng.integers(0, n_rows, c)
    inv_mass, asleep = np.where(rng.random(n_rows) < 0.3, 0.0, 1.0), rng.random(n_rows) < 0.2
    m = np.append(moved, False)
    near = m[table[ra]] | m[table[rb]]
    if immovable_only:
        movable = (inv_mass > 0.0) & ~asleep
        near &= ~(movable[ra] & movable[rb])
    look = np.flatnonzero(near)
    got = sr.moved_candidates(moved, table, ra, rb, immovable_only, inv_mass, asleep)
    for have, want in zip(got, (look, ra[look], rb[look])):
        _same(have, want)


@pytest.mark.parametrize("seed", range(6))
def test_places_of_keys_in_a_table_walked_or_searched(seed: int) -> None:
    """gather._places: each key's first place in the sorted table, or -1; keys in order by a walk,
    others by binary search (the same answers)."""
    rng = np.random.default_rng(seed)
    table = np.sort(rng.integers(0, 40, 30)).astype(np.int64)  # (ties: the first place)
    for keys in (np.sort(rng.integers(-5, 45, 25)), rng.integers(-5, 45, 25), np.zeros(0, dtype=np.int64)):
        keys = keys.astype(np.int64)
        out = np.empty(keys.size, dtype=np.int64)
        gather._places(keys, table, out)
        at = np.searchsorted(table, keys)
        there = (at < table.size) & (table[np.minimum(at, table.size - 1)] == keys)
        _same(out, np.where(there, at, -1).astype(np.int64))
    out = np.empty(3, dtype=np.int64)
    gather._places(np.array([1, 2, 3], dtype=np.int64), np.zeros(0, dtype=np.int64), out)
    _same(out, np.full(3, -1, dtype=np.int64))
