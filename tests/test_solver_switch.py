"""Switching a scene's solver between steps (``scene.solver = "soft"``), and ``scene.after_step``.

What a switch promises: the scene then steps as a new scene of that solver holding the same bodies
would (the other solver's state dropped, every body awake), bit for bit; a switch asked for during
a step is refused and changes nothing; the same inputs and switches give the same bytes.
"""

from __future__ import annotations

import hashlib

import numpy as np
import pytest

from framework import AABB, Circle, DistanceJoint, Hitbox, Polygon, Scene, Transform, Velocity
from framework.snapshot import scene_shape
from framework.validation import InvalidValue

DT = 1.0 / 60.0
G = (0.0, -10.0)


def bodies(scene: Scene, poses=None) -> list[int]:
    """A floor, a wall and five dynamic bodies thrown at each other (``poses``: each dynamic body's
    (x, y, rotation, vx, vy, angular), default the thrown start)."""
    scene.spawn(Transform(0.0, -0.5), Hitbox(AABB(20.0, 1.0), body="static", friction=0.5))
    scene.spawn(Transform(5.5, 2.0), Hitbox(AABB(1.0, 4.0), body="static"))
    shapes = [AABB(0.8, 0.8), Circle(0.4), Polygon.box(1.0, 0.5), AABB(0.6, 0.6), Circle(0.3)]
    start = [(-3.0, 1.0, 0.0, 4.0, 0.0, 0.0), (-1.0, 2.5, 0.0, 2.0, 1.0, 0.0), (1.0, 0.6, 0.3, -1.0, 3.0, 1.0),
             (3.0, 3.0, 0.0, 0.0, 0.0, 0.0), (4.5, 0.5, 0.0, 3.0, 0.0, 0.0)]
    out = []
    for shape, (x, y, rot, vx, vy, w) in zip(shapes, poses or start, strict=True):
        out.append(scene.spawn(Transform(x, y, rot), Velocity(vx, vy, w), Hitbox(shape, friction=0.5)))
    return out


def state(scene: Scene, movers: list[int]) -> list[tuple[float, ...]]:
    out = []
    for e in movers:
        t, v = scene.get(e, Transform), scene.get(e, Velocity)
        out.append((t.x, t.y, t.rotation, v.x, v.y, v.angular))
    return out


def run(scene: Scene, movers: list[int], steps: int, h=None) -> str:
    """Step ``steps`` times, hashing every step's poses, velocities and events."""
    h = h or hashlib.sha256()
    for _ in range(steps):
        scene.step(DT)
        h.update(np.array(state(scene, movers), dtype=np.float64).tobytes())
        h.update(repr([tuple(ev) for ev in scene.events]).encode())
    return h.hexdigest()


@pytest.mark.parametrize(("built", "switched"), [("exact", "soft"), ("soft", "exact")])
def test_a_switch_before_the_first_step_steps_as_a_scene_built_with_that_solver(built, switched):
    a = Scene(gravity=G, solver=built)
    b = Scene(gravity=G, solver=switched)
    ma, mb = bodies(a), bodies(b)
    a.solver = switched
    assert a.solver == switched
    assert scene_shape(a) == scene_shape(b)  # the same stages, in the same order
    assert run(a, ma, 120) == run(b, mb, 120)


@pytest.mark.parametrize("built", ["exact", "soft"])
def test_each_switch_midway_steps_as_a_new_scene_of_that_solver_with_the_same_bodies(built):
    # 30 steps in one solver (bodies landing, sliding, in contact), then the other, and back, and
    # again: after each switch, the same bytes as a new scene of that solver holding the bodies
    # where they were, moving as they were (so nothing of the solver's last turn is left over).
    other = {"exact": "soft", "soft": "exact"}
    a = Scene(gravity=G, solver=built)
    ma = bodies(a)
    run(a, ma, 30)
    solver = built
    for _ in range(3):
        assert a.contacts.a.size > 0  # (things touch at the switch)
        solver = other[solver]
        a.solver = solver
        assert a.events == [] and a.contacts.a.size == 0  # the last step's frame is forgotten
        b = Scene(gravity=G, solver=solver)
        mb = bodies(b, state(a, ma))
        assert mb == ma
        assert run(a, ma, 30) == run(b, mb, 30)
        b.close()


def test_a_switch_wakes_the_sleepers():
    s = Scene(gravity=G)
    box = s.spawn(Transform(0.0, 0.5), Velocity(), Hitbox(AABB(1.0, 1.0)))
    s.spawn(Transform(0.0, -0.5), Hitbox(AABB(10.0, 1.0), body="static"))
    for _ in range(200):
        s.step(DT)
    row = s.store.row_of[box]
    assert s.store.asleep[row]
    s.solver = "soft"
    assert not s.store.asleep[row] and s.store.cols["still"][row] == 0


def test_the_same_steps_and_switches_give_the_same_bytes():
    def play() -> str:
        s = Scene(gravity=G)
        m = bodies(s)
        h = hashlib.sha256()
        for solver, steps in (("exact", 20), ("soft", 30), ("exact", 25), ("soft", 25)):
            s.solver = solver
            run(s, m, steps, h)
        return h.hexdigest()

    assert play() == play()


def test_setting_the_solver_it_has_changes_nothing():
    s = Scene(gravity=G, solver="soft")
    m = bodies(s)
    run(s, m, 30)
    soft = s._stages["soft_step"]
    pairs = soft.pairs
    events = s.events
    s.solver = "soft"
    assert s._stages["soft_step"] is soft and soft.pairs is pairs and s.events == events


# --- refusals -------------------------------------------------------------------------------------------


@pytest.mark.parametrize("bad", ["fast", "Soft", None, 1])
def test_an_unknown_solver_is_refused_naming_it(bad):
    s = Scene(gravity=G)
    m = bodies(s)
    run(s, m, 10)
    shape, before = scene_shape(s), state(s, m)
    with pytest.raises(InvalidValue, match=f"Scene solver must be one of .*got {bad!r}"):
        s.solver = bad
    assert s.solver == "exact" and scene_shape(s) == shape and state(s, m) == before


def test_a_switch_during_a_step_is_refused_and_the_step_undone():
    s = Scene(gravity=G)
    m = bodies(s)
    run(s, m, 10)
    calls = []

    def switch(scene: Scene, dt: float) -> None:
        calls.append(scene.frame)
        if len(calls) == 2:
            scene.solver = "soft"

    s.add_system(switch, before="movement")
    s.step(DT)  # (the first call asks for nothing)
    shape, before, frame, events = scene_shape(s), state(s, m), s.frame, s.events
    with pytest.raises(InvalidValue, match="cannot change during a step") as info:
        s.step(DT)
    assert "undone" in "".join(getattr(info.value, "__notes__", []))
    assert s.solver == "exact" and scene_shape(s) == shape and s.frame == frame
    assert state(s, m) == before and s.events == events
    # and the scene goes on stepping as before
    s.remove_system(switch)
    s.step(DT)
    assert s.frame == frame + 1


def test_after_step_switches_when_the_step_ends():
    s = Scene(gravity=G)
    m = bodies(s)
    seen = []

    def ask(scene: Scene, dt: float) -> None:
        seen.append((scene.frame, scene.solver))
        if scene.frame == 5:
            scene.after_step(lambda sc: setattr(sc, "solver", "soft"))
            assert scene.solver == "exact"  # (not yet)

    ran = []
    s.add_system(ask, before="movement")
    s.add_system(lambda scene, dt: ran.append(list(scene.step_frame.counters["systems"])), after="response")
    run(s, m, 6)
    assert s.solver == "soft" and seen[-1] == (5, "exact")
    assert "response" in ran[-1] and "soft_step" not in ran[-1]  # the step that asked ran the exact solver
    run(s, m, 1)
    assert seen[-1] == (6, "soft") and "soft_step" in ran[-1] and "response" not in ran[-1]


def test_after_step_outside_a_step_calls_now_and_a_failed_step_drops_its_calls():
    s = Scene(gravity=G)
    bodies(s)
    calls = []
    s.after_step(lambda sc: calls.append("now"))
    assert calls == ["now"]

    def ask_then_fail(scene: Scene, dt: float) -> None:
        scene.after_step(lambda sc: calls.append("after"))
        raise RuntimeError("boom")

    s.add_system(ask_then_fail)
    with pytest.raises(RuntimeError, match="boom"):
        s.step(DT)
    assert calls == ["now"]  # the step was undone: nothing called
    s.remove_system(ask_then_fail)
    s.step(DT)
    assert calls == ["now"]
    with pytest.raises(InvalidValue, match="after_step takes a callable"):
        s.after_step("soft")  # type: ignore[arg-type]


def test_an_after_step_call_that_raises_comes_out_of_the_complete_step():
    s = Scene(gravity=G)
    bodies(s)

    def ask(scene: Scene, dt: float) -> None:
        scene.after_step(lambda sc: setattr(sc, "solver", "quick"))

    s.add_system(ask)
    with pytest.raises(InvalidValue, match="got 'quick'") as info:
        s.step(DT)
    assert "called by scene.after_step at the end of step 1" in "".join(info.value.__notes__)
    assert s.frame == 1 and s.solver == "exact"  # the step is complete


# --- joints and snapshots ------------------------------------------------------------------------------


def test_joints_step_after_switching_to_soft_and_are_refused_again_after_switching_back():
    s = Scene(gravity=G)
    ball = s.spawn(Transform(1.0, 0.0), Velocity(), Hitbox(Circle(0.2)))
    s.spawn(DistanceJoint(ball, None, anchor_b=(0.0, 0.0)))
    with pytest.raises(InvalidValue, match="joints need"):
        s.step(DT)
    s.solver = "soft"
    for _ in range(30):
        s.step(DT)
    t = s.get(ball, Transform)
    assert t.y < -0.5 and np.hypot(t.x, t.y) == pytest.approx(1.0, abs=1e-3)  # swinging on its rod
    s.solver = "exact"
    with pytest.raises(InvalidValue, match="joints need"):
        s.step(DT)


def test_snapshots_follow_the_solver_the_scene_has():
    a = Scene(gravity=G)
    ma = bodies(a)
    run(a, ma, 20)
    exact_snap = a.snapshot()
    a.solver = "soft"
    run(a, ma, 20)
    soft_snap = a.snapshot()
    with pytest.raises(InvalidValue, match="another shape"):
        a.restore(exact_snap)  # (from the scene when it ran the exact solver)
    b = Scene(gravity=G, solver="soft")
    mb = bodies(b)
    b.restore(soft_snap)  # a scene built soft takes the switched scene's snapshot
    assert run(a, ma, 30) == run(b, mb, 30)
