"""The compiled expansion of contacts into manifold points (``framework.systems.turning.expand``)
against the numpy code it replaced, kept here as the reference: every expansion made while
stepping scenes where bodies turn (boxes on boxes, a ball and a barrel among them, capsules and
circles in kept pairs) gives the same rows, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

import framework.systems.solve as solve_module
from framework import AABB, Capsule, Circle, Hitbox, Polygon, Scene, Transform, Velocity
from framework.bench import regimes
from framework.collision.kinds import KIND_CAPSULE, KIND_CIRCLE, KIND_POLYGON
from framework.events import pair_keys
from framework.systems import turning
from framework.systems.turning import manifold_points


def turning_polygons(store, rows):
    """Mask of ``rows`` that are boxes or polygons contacts turn (the numpy rule the compiled
    ``solve_columns.turning_pair`` replaced)."""
    return (store.kind[rows] == KIND_POLYGON) & (store.inv_inertia[rows] > 0.0)


def _expand_numpy(cs, store, geom, points, margin):
    """The numpy ``expand`` of 2026-11-27 (before it was compiled)."""
    ra, rb = cs.ra, cs.rb
    turn = turning_polygons(store, ra) | turning_polygons(store, rb)
    round_ = ((store.kind[ra] == KIND_CIRCLE) | (store.kind[rb] == KIND_CIRCLE) | (store.kind[ra] == KIND_CAPSULE)
              | (store.kind[rb] == KIND_CAPSULE))
    clip = np.flatnonzero(turn & ~round_)
    n_pts, px, py, sep = manifold_points(store, geom, ra[clip], rb[clip], cs.nx[clip], cs.ny[clip], margin)
    count = np.ones(cs.size, dtype=np.int64)
    count[clip] = np.where(n_pts == 0, cs.alive0[clip].astype(np.int64), n_pts)
    src = np.repeat(np.arange(cs.size), count)
    slot = np.arange(src.size) - np.repeat(np.cumsum(count) - count, count)
    out = cs.take(src)
    out.slot = slot
    at = np.full(cs.size, -1, dtype=np.int64)
    at[clip] = np.arange(clip.size)
    c = at[src]
    has = c >= 0
    has[has] = n_pts[c[has]] > 0
    k, s = c[has], slot[has]
    out.px[has], out.py[has] = px[k, s], py[k, s]
    out.depth[has] = -sep[k, s]
    rim = ~out.alive0 & ~has
    if rim.any():
        ka, kb = store.kind[out.ra], store.kind[out.rb]
        ca = rim & ((ka == KIND_CIRCLE) | ((ka == KIND_CAPSULE) & (kb != KIND_CIRCLE)))
        cb = rim & ~ca
        for m, rows, sign in ((ca, out.ra, 1.0), (cb, out.rb, -1.0)):
            r = rows[m]
            nx, ny = sign * out.nx[m], sign * out.ny[m]
            cx, cy = store.x[r], store.y[r]
            cap = store.kind[r] == KIND_CAPSULE
            if cap.any():
                ux, uy = geom.cap_ux[r], geom.cap_uy[r]
                along = np.sign(ux * nx + uy * ny)
                cx = np.where(cap, geom.hx[r] + along * ux, cx)
                cy = np.where(cap, geom.hy[r] + along * uy, cy)
            out.px[m] = cx + store.radius[r] * nx
            out.py[m] = cy + store.radius[r] * ny
    n_points = count[src]
    keys = pair_keys(out.ea, out.eb)
    pk, pslot, *values = points[:6]
    found = np.zeros(out.size, dtype=bool)
    if pk.size:
        w = np.minimum(np.searchsorted(pk, keys) + out.slot, pk.size - 1)
        found = (pk[w] == keys) & (pslot[w] == out.slot)
    split = ~found
    for col, last in zip((out.push0, out.impulse0, out.tpush0, out.timpulse0), values):
        if found.any():
            col[found] = last[w[found]]
        col[split] = col[split] / n_points[split]
    out.arms = (out.px - store.x[out.ra], out.py - store.y[out.ra], out.px - store.x[out.rb],
                out.py - store.y[out.rb])
    return out


def _same(a, b) -> None:
    ca, cb = a.columns() + a.arms, b.columns() + b.arms
    for i, (u, v) in enumerate(zip(ca, cb)):
        assert u.dtype == v.dtype and u.shape == v.shape, i
        assert u.tobytes() == v.tobytes(), i


def _mixed() -> Scene:
    """Boxes and polygons that turn beside circles and capsules, falling into a pit and bumping."""
    s = Scene(gravity=(0.0, -10.0))
    s.spawn(Transform(0.0, -0.5), Hitbox(AABB(30.0, 1.0), body="static", friction=0.5))
    s.spawn(Transform(-8.0, 3.0), Hitbox(AABB(1.0, 6.0), body="static"))
    s.spawn(Transform(8.0, 3.0), Hitbox(AABB(1.0, 6.0), body="static"))
    tri = Polygon([(-0.5, -0.4), (0.5, -0.4), (0.0, 0.5)])
    box = Polygon([(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)])
    shapes = [box, Circle(0.4), tri, Capsule(0.3, 0.8), box, AABB(0.8, 0.8)]
    for k in range(24):
        x, y = -6.0 + (k % 8) * 1.6, 1.0 + (k // 8) * 1.3
        s.spawn(Transform(x, y, 0.1 * k), Velocity(0.5 * ((k % 3) - 1), 0.0),
                Hitbox(shapes[k % len(shapes)], friction=0.4))
    return s


@pytest.mark.parametrize("build", ["tumbling", "toy", "mixed"])
def test_expand_is_the_numpy_expansion(build, monkeypatch):
    seen = []
    compiled = turning.expand

    def both(cs, store, geom, points, margin):
        want = _expand_numpy(cs.take(np.arange(cs.size)), store, geom, points, margin)
        got = compiled(cs, store, geom, points, margin)
        _same(got, want)
        seen.append(got.size)
        return got

    monkeypatch.setattr(solve_module, "expand", both)
    if build == "mixed":
        s, step = _mixed(), None
    else:
        engine = regimes.Ours(regimes.stack_tumbling(12) if build == "tumbling" else regimes.physics_toy())
        s, step = engine.scene, engine.step
    for _ in range(240):
        step() if step is not None else s.step(1 / 60)
    assert len(seen) > 100 and max(seen) > 0
