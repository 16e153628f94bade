"""The exact pipeline's shortcuts change nothing: the response's idle path (nothing it may move
touches anything) steps bit for bit as its full pass does; the compiled bounds of the moving rows
are the numpy formulas' bits; the compiled integration keeps -0.0 where nothing is added."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from examples.platformer import Game, builtin_levels, load_level
from examples.platformer.demo import Autoplay, level1
from framework import AABB, Capsule, Circle, Hitbox, Polygon, Scene, Transform, Velocity
from framework.geometry import Geometry
from framework.systems.response import Response


def _state(scene: Scene) -> tuple[bytes, list[tuple[object, ...]]]:
    store = scene.bodies.store
    n = store.n
    cols = b"".join(store.cols[name][:n].tobytes() for name in ("x", "y", "rot", "vx", "vy", "w", "asleep"))
    events = [(e.kind, e.a, e.b, e.normal, e.depth, e.point) for e in scene.events]
    return cols, events


def _full_pass(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(Response, "_idle", lambda self, frame: False)


def _counting(monkeypatch: pytest.MonkeyPatch) -> list[bool]:
    """Record what the idle test answers (so a test knows both paths were taken)."""
    answers: list[bool] = []
    idle = Response._idle

    def spy(self: Response, frame: object) -> bool:
        answers.append(idle(self, frame))
        return answers[-1]

    monkeypatch.setattr(Response, "_idle", spy)
    return answers


def _platformer_run(steps: int) -> list[tuple[bytes, list[tuple[object, ...]]]]:
    game = Game([load_level(builtin_levels()[0])], autoplay=Autoplay(level1))
    out = []
    for _ in range(steps):
        game.step()
        out.append(_state(game.scene))
    return out


def test_the_platformer_steps_the_same_with_and_without_the_idle_path(monkeypatch):
    """Its bodies are kinematic (player, walkers, platform): the idle path answers every step."""
    answers = _counting(monkeypatch)
    quick = _platformer_run(400)
    assert answers and all(answers)
    _full_pass(monkeypatch)
    assert _platformer_run(400) == quick


def _pile(steps: int, push_at: int) -> list[tuple[bytes, list[tuple[object, ...]]]]:
    """Boxes falling asleep on a floor, a kinematic paddle sliding into them later (it wakes them:
    the full pass takes over), and a ball dropped on the pile."""
    s = Scene(gravity=(0.0, -10.0))
    s.spawn(Transform(0.0, -0.5), Hitbox(AABB(40.0, 1.0), body="static"))
    for i in range(6):
        s.spawn(Transform(0.75 * (i % 2), 0.5 + i), Hitbox(AABB(1.0, 1.0)), Velocity())
    paddle = s.spawn(Transform(-6.0, 0.5), Hitbox(AABB(1.0, 1.0), body="kinematic"), Velocity())
    out = []
    for k in range(steps):
        if k == push_at:
            s.get(paddle, Velocity).x = 2.0
        if k == push_at + 200:
            s.spawn(Transform(0.25, 9.0), Hitbox(Circle(0.5)), Velocity())
        s.step(1 / 60)
        out.append(_state(s))
    return out


def test_a_pile_that_sleeps_and_is_woken_steps_the_same_with_and_without_the_idle_path(monkeypatch):
    answers = _counting(monkeypatch)
    quick = _pile(700, 300)
    assert quick[299][0][-8:] != bytes(8)  # (the last column, asleep, of the 8 rows: the pile slept)
    assert any(answers[:300]) and not all(answers[300:])  # (idle while it slept, the full pass once woken)
    _full_pass(monkeypatch)
    assert _pile(700, 300) == quick


# --- the compiled bounds: the numpy formulas' bits ------------------------------------------------


def _widen(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    def step(v: np.ndarray) -> np.ndarray:
        return np.maximum(np.abs(v) * 2.0**-52, 5e-324)

    return lo - step(lo), hi + step(hi)


def _reference(shape, x: float, y: float, rot: float, offset: tuple[float, float]) -> tuple[float, ...]:
    """Origin and bounds of one hitbox by the numpy formulas the compiled pass replaced."""
    c, s = np.cos(np.array([rot])), np.sin(np.array([rot]))
    ox, oy = offset
    turned = isinstance(shape, (Polygon, Capsule)) or ox != 0.0 or oy != 0.0
    if not turned:
        c, s = np.ones(1), np.zeros(1)
    hx, hy = np.array([x]), np.array([y])
    if ox != 0.0 or oy != 0.0:
        hx = hx + (c * ox - s * oy)
        hy = hy + (s * ox + c * oy)
    if isinstance(shape, Polygon):
        loc = np.array(shape.points)[None]
        wx = c[:, None] * loc[:, :, 0] - s[:, None] * loc[:, :, 1]
        wy = s[:, None] * loc[:, :, 0] + c[:, None] * loc[:, :, 1]
        lo_x, hi_x, lo_y, hi_y = hx + wx.min(axis=1), hx + wx.max(axis=1), hy + wy.min(axis=1), hy + wy.max(axis=1)
    elif isinstance(shape, Capsule):
        h, r = shape.half_length, shape.radius
        ux, uy = -(s * h), c * h
        ex, ey = np.abs(ux) + r, np.abs(uy) + r
        lo_x, hi_x, lo_y, hi_y = hx - ex, hx + ex, hy - ey, hy + ey
    else:
        ex = np.array([shape.width * 0.5 if isinstance(shape, AABB) else shape.radius])
        ey = np.array([shape.height * 0.5 if isinstance(shape, AABB) else shape.radius])
        lo_x, hi_x, lo_y, hi_y = hx - ex, hx + ex, hy - ey, hy + ey
    (lo_x, hi_x), (lo_y, hi_y) = _widen(lo_x, hi_x), _widen(lo_y, hi_y)
    return float(hx[0]), float(hy[0]), float(lo_x[0]), float(hi_x[0]), float(lo_y[0]), float(hi_y[0])


_coord = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False)
_size = st.floats(1e-3, 1e3, allow_nan=False)
_shape = st.one_of(
    st.builds(AABB, _size, _size),
    st.builds(Circle, _size),
    st.builds(Capsule, _size, _size),
    st.builds(lambda w, h, k: Polygon([(-w, -h), (w * k, -h * 0.5), (w * 0.25, h)]), _size, _size,
              st.floats(0.5, 2.0)),
)


@settings(max_examples=200, deadline=None)
@given(shapes=st.lists(st.tuples(_shape, _coord, _coord, st.floats(-10.0, 10.0),
                                 st.sampled_from([(0.0, 0.0), (0.25, -0.125), (3.0, 7.5)])), min_size=1, max_size=5),
       moved=st.tuples(_coord, _coord, st.floats(-10.0, 10.0)))
def test_compiled_bounds_are_the_numpy_formulas_bits(shapes, moved):
    s = Scene()
    rows = []
    for shape, x, y, rot, offset in shapes:
        e = s.spawn(Transform(x, y, rot), Velocity(), Hitbox(shape, body="kinematic", offset=offset))
        rows.append((s.bodies.store.row_of[e], shape, offset))
    store = s.bodies.store
    geom = Geometry()
    geom.update(store)  # (a full pass: every row)
    for step in range(2):
        for row, shape, offset in rows:
            got = tuple(float(getattr(geom, k)[row]) for k in ("hx", "hy", "minx", "maxx", "miny", "maxy"))
            want = _reference(shape, float(store.x[row]), float(store.y[row]), float(store.rot[row]), offset)
            assert got == want, (shape, offset, step)
        if step == 0:  # move every row and measure only the moving ones
            mx, my, mr = moved
            for row, *_ in rows:
                store.cols["x"][row] += mx
                store.cols["y"][row] += my
                store.cols["rot"][row] += mr
            store.motion += 1
            geom.update(store)


# --- the compiled integration ------------------------------------------------------------------------


def test_integration_adds_what_numpy_added_and_keeps_negative_zero():
    s = Scene(gravity=(0.0, -9.75))
    drop = s.spawn(Transform(0.0, 1.0, -0.0), Velocity(-0.0, 0.0, 0.0), Hitbox(Polygon.box(1.0, 1.0)))
    spin = s.spawn(Transform(5.0, 1.0, 0.5), Velocity(0.375, -0.0, 1.5), Hitbox(Polygon.box(1.0, 1.0)))
    s.step(0.125)
    t_drop, v_drop = s.get(drop, Transform), s.get(drop, Velocity)
    t_spin, v_spin = s.get(spin, Transform), s.get(spin, Velocity)
    assert math.copysign(1.0, v_drop.x) == -1.0  # no gravity along x: nothing added to -0.0
    assert math.copysign(1.0, t_drop.rotation) == -1.0  # no spin: the rotation untouched
    assert t_drop.x == 0.0 and v_drop.y == -9.75 * 0.125 and t_drop.y == 1.0 + (-9.75 * 0.125) * 0.125
    assert v_spin.y == -0.0 + -9.75 * 0.125
    assert t_spin.x == 5.0 + 0.375 * 0.125
    assert t_spin.rotation == 0.5 + 1.5 * 0.125
