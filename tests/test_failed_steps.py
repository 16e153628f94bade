"""A refused call or a failed step changes nothing (issue 34, item 1).

Values a scene's arithmetic cannot take are refused at spawn (or by the next step, for a value
written in place) with ``InvalidValue`` naming them (:mod:`framework.limits`); a step that fails
(a stage, system or processor raises, one writes NaN into a body, a motion would overflow) is
undone: the scene's state hash before and after is the same, and the scene steps on exactly as a
twin that never tried the failed step.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_snapshot import state_hash  # (tests/ is on sys.path)

from framework import AABB, Capsule, Circle, Hitbox, Polygon, Scene, Transform, Velocity
from framework.limits import MAX_COORD, MAX_MASS, MAX_SIZE, MIN_MASS, MIN_SIZE
from framework.validation import InvalidValue

DT = 1.0 / 64.0


def _busy(seed: int = 3) -> Scene:
    """A floor, walls and a heap of every shape falling, with friction on some (a scene with
    contacts, events, warm starts and sleepers to put back)."""
    rng = np.random.default_rng(seed)
    s = Scene(gravity=(0.0, -10.0))
    s.spawn(Transform(0.0, -0.5), Hitbox(AABB(20.0, 1.0), body="static"))
    for x in (-6.0, 6.0):
        s.spawn(Transform(x, 5.0), Hitbox(AABB(1.0, 10.0), body="static"))
    shapes = [AABB(0.8, 0.6), Circle(0.4), Polygon.box(0.7, 0.5), Capsule(0.25, 0.5),
              Polygon([(-0.4, -0.3), (0.4, -0.3), (0.0, 0.4)])]
    for k in range(15):
        s.spawn(Transform(-4.0 + (k % 5) * 2.0, 1.0 + (k // 5) * 1.2, float(rng.uniform(0, 1))),
                Velocity(float(rng.uniform(-2, 2)), 0.0), Hitbox(shapes[k % 5], friction=0.5 if k % 2 else None))
    return s


def _hashes(s: Scene, steps: int) -> list[str]:
    out = []
    for _ in range(steps):
        s.step(DT)
        out.append(state_hash(s))
    return out


@pytest.mark.slow
@pytest.mark.parametrize("stage", ["movement", "broad_phase", "narrow_phase", "response", "sleeping"])
def test_a_system_that_raises_mid_step_leaves_the_scene_as_it_was(stage):
    s, twin = _busy(), _busy()
    try:
        _hashes(s, 40)
        _hashes(twin, 40)
        before = state_hash(s)
        counters = dict(s.counters)

        def boom(scene, dt):
            raise RuntimeError("game bug")

        s.add_system(boom, after=stage)
        with pytest.raises(RuntimeError, match="game bug") as info:
            s.step(DT)
        assert "undone" in info.value.__notes__[-1]
        assert state_hash(s) == before and s.counters == counters
        s.remove_system(boom)
        assert _hashes(s, 40) == _hashes(twin, 40)  # and on exactly as a scene that never tried it
    finally:
        s.close()
        twin.close()


def test_a_system_that_writes_nan_fails_the_step_and_nothing_changes():
    s = _busy()
    with s:
        _hashes(s, 20)
        before = state_hash(s)
        ball = 5

        def spoil(scene, dt):
            scene.get(ball, Velocity).x = math.nan

        s.add_system(spoil, after="response")
        with pytest.raises(InvalidValue, match=f"entity {ball}: Velocity.x .*during step 21"):
            s.step(DT)
        assert state_hash(s) == before and math.isfinite(s.get(ball, Velocity).x)
        s.remove_system(spoil)
        s.step(DT)
        assert s.frame == 21


def test_a_failed_step_removes_what_it_spawned_and_drops_the_despawns_it_asked_for():
    s = _busy()
    with s:
        _hashes(s, 10)
        before, entities = state_hash(s), sorted(s.entities)

        def churn(scene, dt):
            scene.spawn(Transform(0.0, 8.0), Velocity(), Hitbox(Circle(0.5)))
            scene.despawn(4)
            raise RuntimeError("after churning")

        s.add_system(churn, after="narrow_phase")
        with pytest.raises(RuntimeError):
            s.step(DT)
        assert state_hash(s) == before and sorted(s.entities) == entities and s.exists(4)


def test_a_failed_step_puts_back_the_static_bodies_a_system_moved():
    """The rollback keeps the rows that are not static whole and saves a static row only on its
    first change during the step: a system that moves a wall (twice) and a static floor, then
    fails, leaves them where they were, and the scene goes on as one that never tried."""
    s, twin = _busy(), _busy()
    try:
        _hashes(s, 12)
        _hashes(twin, 12)
        before = state_hash(s)
        wall, floor = 2, 1  # (a wall and the floor: static)
        x0 = s.get(wall, Transform).x

        def shove(scene, dt):
            t = scene.get(wall, Transform)
            t.x += 0.5
            t.x += 0.25  # (a second write of the same row: the first saved value stands)
            scene.get(floor, Transform).rotation = 0.125
            raise RuntimeError("after shoving")

        s.add_system(shove, after="movement")
        with pytest.raises(RuntimeError, match="after shoving") as info:
            s.step(DT)
        assert "undone" in info.value.__notes__[-1]
        assert state_hash(s) == before
        assert s.get(wall, Transform).x == x0 and s.get(floor, Transform).rotation == 0.0
        s.remove_system(shove)
        assert _hashes(s, 20) == _hashes(twin, 20)
    finally:
        s.close()
        twin.close()


def test_a_static_body_changed_by_a_step_that_stands_is_not_put_back_later():
    """A static body moved by a system in a step that succeeds stays moved, also when a later
    step fails (it is saved again from where it is then)."""
    s = _busy()
    with s:
        wall = 2
        x0 = s.get(wall, Transform).x

        def nudge(scene, dt):
            scene.get(wall, Transform).x += 0.5

        s.add_system(nudge, after="movement")
        s.step(DT)
        s.remove_system(nudge)
        assert s.get(wall, Transform).x == x0 + 0.5
        before = state_hash(s)

        def nudge_and_fail(scene, dt):
            scene.get(wall, Transform).x += 1.0
            raise RuntimeError("no")

        s.add_system(nudge_and_fail, after="movement")
        with pytest.raises(RuntimeError):
            s.step(DT)
        assert s.get(wall, Transform).x == x0 + 0.5 and state_hash(s) == before


def test_a_failed_step_that_took_a_static_body_s_hitbox_is_left_as_it_found_it():
    """A structural change of a static row during a failed step (its Hitbox removed) cannot be
    put back: the scene says so, as for a moving body's."""
    s = _busy()
    with s:
        _hashes(s, 5)
        wall = 2

        def strip(scene, dt):
            scene.remove_component(wall, Hitbox)
            raise RuntimeError("stripped")

        s.add_system(strip, after="movement")
        with pytest.raises(RuntimeError, match="stripped") as info:
            s.step(DT)
        assert "left as the failure found it" in info.value.__notes__[-1]


def test_a_failed_sub_step_undoes_the_whole_step():
    s = _busy()
    s.substeps = 4
    with s:
        _hashes(s, 10)
        before = state_hash(s)
        calls = []

        def third(scene, dt):
            calls.append(dt)
            if len(calls) == 3:
                raise RuntimeError("sub-step 3")

        s.add_system(third, after="response")
        with pytest.raises(RuntimeError, match="sub-step 3"):
            s.step(DT)
        assert state_hash(s) == before


def test_a_step_that_could_carry_a_body_beyond_the_scene_is_refused_before_it_starts():
    s = _busy()
    with s:
        _hashes(s, 5)
        before, counters = state_hash(s), dict(s.counters)
        with pytest.raises(InvalidValue, match="could carry entity .* beyond 1e\\+15"):
            s.step(1e300)
        assert state_hash(s) == before and s.counters == counters
        e = s.spawn(Transform(MAX_COORD - 1.0, 100.0), Velocity(2.0 / DT, 0.0), Hitbox(AABB(1.0, 1.0)))
        with pytest.raises(InvalidValue, match=f"could carry entity {e}"):
            s.step(DT)  # 2 units on: beyond
        s.get(e, Velocity).x = 0.5 / DT
        s.step(DT)  # half a unit on: within
        assert s.get(e, Transform).x == MAX_COORD - 0.5


def test_a_refused_step_keeps_the_counters():
    # (the issue: a step refused for a density written onto a hitbox that has a mass reset them)
    s = _busy()
    with s:
        _hashes(s, 5)
        counters, before = dict(s.counters), state_hash(s)
        hb = s.get(6, Hitbox)
        hb.mass = 2.0
        s.step(DT)
        counters, before = dict(s.counters), state_hash(s)
        hb.density = 2.0
        with pytest.raises(InvalidValue, match="entity 6: .*mass and density"):
            s.step(DT)
        assert s.counters == counters and state_hash(s) == before
        hb.density = None
        s.step(DT)


@pytest.mark.parametrize("make", [
    lambda: Hitbox(Circle(1e-300)), lambda: Hitbox(Circle(1e-160)), lambda: Hitbox(Polygon.box(1e-300, 1e-300)),
    lambda: Hitbox(Polygon([(1e-150, 0.0), (2e-150, 0.0), (1e-150, 1e-150)])),
    lambda: Hitbox(Polygon([(1e300, 0.0), (1.0000001e300, 0.0), (1e300, 1e293)])),
    lambda: Hitbox(AABB(1.0, 1.0), mass=1e-320), lambda: Hitbox(AABB(1.0, 1.0), mass=1e300),
    lambda: Hitbox(Circle(1e8), density=1e6), lambda: Hitbox(AABB(4e9, 1.0)),
    lambda: Hitbox(AABB(1.0, 1.0), offset=(2e9, 0.0)), lambda: Hitbox(AABB(1e-10, 1e-3)),
    lambda: Hitbox(Circle(1.0), inertia=1e-300),
], ids=["circle-1e-300", "circle-1e-160", "box-1e-300", "polygon-near-1e-150", "polygon-near-1e300",
        "mass-1e-320", "mass-1e300", "density-huge", "aabb-4e9", "offset-2e9", "sliver-area", "inertia-1e-300"])
def test_hitboxes_beyond_the_scene_s_range_are_refused_at_spawn_and_nothing_changes(make):
    s = _busy()
    with s:
        s.step(DT)
        before, entities = state_hash(s), sorted(s.entities)
        with pytest.raises(InvalidValue, match="framework.limits"):
            s.spawn(Transform(0.0, 3.0), Velocity(), make())
        with pytest.raises(InvalidValue, match="framework.limits"):
            s.add_component(5, make())
        assert state_hash(s) == before and sorted(s.entities) == entities
        s.step(DT)


def test_positions_beyond_the_scene_s_range_are_refused():
    s = _busy()
    with s:
        with pytest.raises(InvalidValue, match="beyond 1e\\+15"):
            s.spawn(Transform(1.7e308, 0.0), Velocity(1e308, 0.0), Hitbox(AABB(1.0, 1.0)))
        s.step(DT)
        before = state_hash(s)
        s.get(5, Transform).x = 2e15  # written in place: the next step refuses, naming it
        with pytest.raises(InvalidValue, match="entity 5: Transform .*beyond 1e\\+15"):
            s.step(DT)
        s.get(5, Transform).x = 0.0
        s.step(DT)
        assert state_hash(s) != before  # it steps on


def test_a_hitbox_edited_beyond_the_range_is_refused_by_the_next_step_before_anything_changes():
    s = _busy()
    with s:
        s.step(DT)
        before = state_hash(s)
        hb = s.get(5, Hitbox)
        old = hb.shape
        hb.shape = Circle(1e-200)
        with pytest.raises(InvalidValue, match="entity 5: Hitbox shape Circle.*framework.limits"):
            s.step(DT)
        assert state_hash(s) == before
        hb.shape = old
        s.step(DT)


# --- the range's edges: every shape pair, every stage, nothing non-finite ----------------------------

EDGE_SIZES = [2 * MIN_SIZE, 1e-3, 1.0, 1e4, MAX_SIZE / 2]


def _shape(kind: str, size: float):
    """A shape of about ``size`` whose bounding radius and area are within the range for every
    size above."""
    if kind == "aabb":
        return AABB(size, size)
    if kind == "circle":
        return Circle(size)
    if kind == "polygon":
        return Polygon.box(size, size / 2)
    return Capsule(size / 4, size / 2)


@pytest.mark.slow
@settings(max_examples=60, deadline=None, derandomize=True)
@given(ka=st.sampled_from(["aabb", "circle", "polygon", "capsule"]),
       kb=st.sampled_from(["aabb", "circle", "polygon", "capsule"]),
       sa=st.sampled_from(EDGE_SIZES), sb=st.sampled_from(EDGE_SIZES),
       mass=st.sampled_from([MIN_MASS, 1.0, MAX_MASS]), where=st.sampled_from([0.0, 1e9, -1e12]),
       overlap=st.sampled_from([0.0, 0.25, 0.9]))
def test_bodies_at_the_edges_of_the_range_step_without_nan_or_errors(ka, kb, sa, sb, mass, where, overlap):
    # Two bodies of the extreme sizes and masses, one resting on (or sunk into) the other, over a
    # static floor of the largest size, with gravity, friction and restitution: 20 steps through
    # every stage give finite poses and velocities and no exception.
    s = Scene(gravity=(0.0, -10.0))
    with s:
        s.spawn(Transform(where, where - MAX_SIZE / 4), Hitbox(AABB(MAX_SIZE, MAX_SIZE / 2), body="static"))
        a = s.spawn(Transform(where, where + sa), Velocity(1.0, 0.0),
                    Hitbox(_shape(ka, sa), mass=mass, friction=0.5, restitution=0.5))
        s.spawn(Transform(where + 0.1 * sa, where + 2 * sa + sb * (1 - 2 * overlap)), Velocity(0.0, -1.0),
                Hitbox(_shape(kb, sb), friction=0.5, ccd=True))
        for _ in range(20):
            s.step(1.0 / 60.0)
        store = s.store
        for col in ("x", "y", "rot", "vx", "vy", "w"):
            assert np.isfinite(store.cols[col][: store.n]).all(), col
        assert math.isfinite(s.get(a, Transform).y)
        for ev in s.events:
            assert all(math.isfinite(v) for v in (*ev.normal, ev.depth, *ev.point))


def test_a_step_that_fails_inside_the_solve_steps_on_as_a_twin_that_never_tried_it(monkeypatch):
    """The solve's numbering (row -> local number) is kept between steps and reset row by row; a
    solve that raises after numbering its bodies leaves it dirty, and the next one starts afresh."""
    from framework.systems import solve as solve_module

    s, twin = _busy(), _busy()
    try:
        assert _hashes(s, 30) == _hashes(twin, 30)
        before = state_hash(s)
        real = solve_module.Solve.velocities

        def boom(self):
            raise RuntimeError("failed inside the solve")

        monkeypatch.setattr(solve_module.Solve, "velocities", boom)
        with pytest.raises(RuntimeError, match="inside the solve"):
            s.step(DT)
        assert state_hash(s) == before
        monkeypatch.setattr(solve_module.Solve, "velocities", real)
        assert _hashes(s, 40) == _hashes(twin, 40)
    finally:
        s.close()
        twin.close()
