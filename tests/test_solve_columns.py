"""The solve's compiled column passes (framework.systems.solve_columns) give the bits of the numpy they
replaced, on random columns with ties, -0.0, infinities and NaN."""

from __future__ import annotations

import math

import numpy as np
import pytest

from framework.systems import solve_columns as sc
from framework.systems import solver_loops as loops


def _same(a: np.ndarray, b: np.ndarray) -> None:
    assert a.dtype == b.dtype and a.shape == b.shape
    assert a.tobytes() == b.tobytes()


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
        _same(sc.stable_argsort(key), np.argsort(key, kind="stable").astype(np.int64))


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
            got = sc.contact_columns(rows, ra, rb, hw, hh, bound, asleep, inv_mass, x, y, statics, gx, gy, g)
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
        for have, want in zip(got, (span, reach, wa, wb, *shares, immovable, order.astype(np.int64))):
            _same(have, want)


def _lower_stays(b_on_a, a_on_b, share_a, share_b):
    return (np.where(b_on_a, 0.0, np.where(a_on_b, 1.0, share_a)),
            np.where(b_on_a, 1.0, np.where(a_on_b, 0.0, share_b)))


@pytest.mark.parametrize("seed", range(8))
def test_stays_are_the_numpy_shock_shares(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n, c = 12, 25
    a = rng.integers(0, n, c)
    b = (a + 1 + rng.integers(0, n - 1, c)) % n
    angle = rng.uniform(-np.pi, np.pi, c)
    nx, ny = np.cos(angle), np.sin(angle)
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
def test_warm_pushes_are_the_numpy_warm_pushes(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n, c = 10, 20
    a = rng.integers(0, n, c)
    b = (a + 1 + rng.integers(0, n - 1, c)) % n
    angle = rng.uniform(-np.pi, np.pi, c)
    nx, ny = np.cos(angle), np.sin(angle)
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
