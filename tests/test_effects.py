"""A scene pays only for the effects it declares: the per-step counters prove work not called for
is not done, and that declaring an effect turns the work on."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

from framework import AABB, Circle, Hitbox, Scene, Transform, Velocity
from framework.scene import DEFAULT_EFFECTS, SLEEP_STEPS, resolve_effects

DT = 1.0 / 64.0


def test_effects_pull_in_what_they_need_and_unknown_ones_are_refused():
    assert resolve_effects(["response"]) == {"response", "detection"}
    assert resolve_effects(["continuous"]) == {"continuous", "movement", "detection"}
    assert resolve_effects(["debug_overlay"]) == {"debug_overlay", "rendering"}
    assert resolve_effects(None) == DEFAULT_EFFECTS
    with pytest.raises(ValueError, match="'teleport'"):
        Scene(effects=["movement", "teleport"])
    with pytest.raises(ValueError, match="collection"):
        Scene(effects="movement")


def test_a_scene_without_response_runs_no_response_system():
    with Scene(effects=["movement", "detection", "events"]) as s:
        s.spawn(Transform(0, 0), Hitbox(AABB(2, 2), body="static"))
        d = s.spawn(Transform(0, 1.5), Velocity(0, -1), Hitbox(AABB(1, 1)))
        s.step(DT)
        assert s.counters["systems"] == ["movement", "broad_phase", "narrow_phase"]
        assert [e.kind for e in s.events] == ["started"]
        assert s.get(d, Transform).y == 1.5 - DT  # nobody pushed it out


def test_a_puzzle_scene_without_physics_does_no_collision_work():
    with Scene(effects=["movement"]) as s:
        for i in range(50):
            s.spawn(Transform(i * 0.5, 0), Velocity(1, 0), Hitbox(AABB(1, 1)))
        s.step(DT)
        c = s.counters
        assert c["systems"] == ["movement"] and c["integrated"] == 50
        assert c["candidate_pairs"] == 0 and c["narrow_tests"] == {} and c["rehashed"] == 0
        assert s.events == []


def test_enabling_an_effect_turns_the_work_on():
    def run(effects):
        with Scene(effects=effects, gravity=(0, -10)) as s:
            s.spawn(Transform(0, 0), Hitbox(AABB(4, 1), body="static"))
            b = s.spawn(Transform(0, 1.0), Velocity(), Hitbox(AABB(1, 1)))
            for _ in range(10):
                s.step(DT)
            return s.counters, s.get(b, Transform).y

    c, y = run(["movement"])
    assert c["systems"] == ["movement"] and y == 1.0  # no gravity declared: it floats
    c, y = run(["gravity"])
    assert y < 1.0 and c["candidate_pairs"] == 0  # falls into the floor: no detection
    c, y = run(["gravity", "response"])
    assert "response" in c["systems"] and c["resolved"] == 1 and y == pytest.approx(1.0, abs=1e-9)


@pytest.mark.slow
def test_100k_static_tiles_add_no_per_step_rehashing():
    with Scene(cell_size=4.0) as s:
        side = 317
        xs, ys = np.meshgrid(np.arange(side, dtype=float), np.arange(side, dtype=float))
        for x, y in zip(xs.ravel()[:100_000].tolist(), ys.ravel()[:100_000].tolist()):
            s.spawn(Transform(x, -y - 10.0), Hitbox(AABB(1, 1), body="static"))
        rng = np.random.default_rng(1)
        for _ in range(100):
            s.spawn(Transform(float(rng.uniform(0, 300)), float(rng.uniform(0, 20))),
                    Velocity(float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1))), Hitbox(Circle(0.5)))
        s.step(DT)
        assert s.counters["rehashed"] == 100_000 + 100  # the level is hashed once, at the first step
        for _ in range(5):
            s.step(DT)
            assert s.counters["rehashed"] == 100  # then only the moving bodies
            assert s.counters["integrated"] == 100


def test_sleeping_bodies_cost_nothing_until_woken():
    with Scene(gravity=(0.0, -10.0)) as s:
        s.spawn(Transform(0, 0), Hitbox(AABB(40, 1), body="static"))
        boxes = [s.spawn(Transform(-15.0 + 3 * i, 1.0), Velocity(), Hitbox(AABB(1, 1))) for i in range(10)]
        for _ in range(SLEEP_STEPS + 5):
            s.step(1 / 60)
        c = s.counters
        assert c["asleep"] == 10
        assert c["integrated"] == 0 and c["candidate_pairs"] == 0 and c["narrow_tests"] == {}
        assert c["rehashed"] == 0
        # They still rest on the floor: the resting contacts stay "ongoing".
        assert [e.kind for e in s.events] == ["ongoing"] * 10
        y_rest = s.get(boxes[0], Transform).y
        assert y_rest == pytest.approx(1.0, abs=1e-9)
        # Game code moving one wakes it (and only it).
        s.get(boxes[0], Velocity).y = 3.0
        s.step(1 / 60)
        assert s.counters["asleep"] == 9 and s.counters["integrated"] == 1
        assert s.get(boxes[0], Transform).y > y_rest


def test_an_awake_body_landing_on_a_sleeper_wakes_it():
    with Scene(gravity=(0.0, -10.0)) as s:
        s.spawn(Transform(0, 0), Hitbox(AABB(10, 1), body="static"))
        low = s.spawn(Transform(0, 1.0), Velocity(), Hitbox(AABB(1, 1)))
        for _ in range(SLEEP_STEPS + 2):
            s.step(1 / 60)
        assert s.store.asleep[s.store.row_of[low]]
        top = s.spawn(Transform(0, 3.0), Velocity(), Hitbox(AABB(1, 1)))
        for _ in range(60):
            s.step(1 / 60)
        # The dropped box ends resting on the (woken) lower one, both in place.
        assert s.get(top, Transform).y == pytest.approx(2.0, abs=1e-6)
        assert s.get(low, Transform).y == pytest.approx(1.0, abs=1e-6)


def test_without_the_events_effect_only_listened_pairs_are_tested():
    class Coin:
        pass

    class Player:
        pass

    got = []
    with Scene(effects=["movement", "response"]) as s:
        s.on_collision(Player, Coin, lambda sc, ev: got.append(ev.kind))
        s.spawn(Transform(0, 0), Hitbox(Circle(0.5), sensor=True, body="static"), Coin())
        s.spawn(Transform(5, 0), Hitbox(Circle(0.5), sensor=True, body="static"))  # nobody listens
        s.spawn(Transform(0.5, 0), Velocity(), Hitbox(AABB(1, 1)), Player())
        s.spawn(Transform(5.5, 0), Velocity(), Hitbox(AABB(1, 1)))
        s.step(DT)
        assert got == ["started"]
        assert s.counters["candidate_pairs"] == 1 and s.counters["contacts"] == 1


def test_headless_scene_never_imports_pyglet_gl():
    code = textwrap.dedent("""
        import sys
        from framework import AABB, Hitbox, Scene, Transform, Velocity
        s = Scene(gravity=(0, -10))
        s.spawn(Transform(0, 0), Hitbox(AABB(4, 1), body="static"))
        s.spawn(Transform(0, 2), Velocity(), Hitbox(AABB(1, 1)))
        for _ in range(10):
            s.step(1 / 60)
        bad = [m for m in sys.modules if m.startswith(("pyglet.gl", "pyglet.window", "pyglet.graphics"))]
        print(bad)
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_a_stack_falls_asleep_as_one_and_stays_exact():
    with Scene(gravity=(0.0, -10.0)) as s:
        s.spawn(Transform(0, 0), Hitbox(AABB(4, 1), body="static"))
        boxes = [s.spawn(Transform(0.0, 1.0 + k), Velocity(), Hitbox(AABB(1, 1))) for k in range(8)]
        for i in range(200):
            s.step(1 / 60)
            ys = [s.get(b, Transform).y for b in boxes]
            if i >= 10:  # once the stack has come to rest (it starts exactly touching, in free fall)
                assert max(abs(y - (1.0 + k)) for k, y in enumerate(ys)) < 1e-9
        assert s.counters["asleep"] == 8 and s.counters["integrated"] == 0


def test_a_body_bumped_awake_has_real_contacts_and_keeps_its_floor_contact():
    """A sleeper woken by a touch slept through the movement stage; it catches up (sinks into the
    floor by gravity's step like any resting body) and its contacts are measured again, so the
    narrow phase reports exactly what the geometry says and the floor pair stays ``ongoing``.
    (Found by the state machine: the woken body's kept contact was the one measured before the
    response of the step it fell asleep in.)"""
    from framework.collision.collide import collide

    s = Scene(gravity=(0.0, -10.0))
    floor = s.spawn(Transform(0.0, -0.5), Hitbox(AABB(20.0, 1.0), body="static"))
    box = s.spawn(Transform(0.0, 0.5), Velocity(), Hitbox(AABB(1.0, 1.0)))
    for _ in range(SLEEP_STEPS + 30):
        s.step(1 / 64)
    row = s.store.row_of[box]
    assert s.store.asleep[row]
    seen = []

    def check(scene, dt):  # right after the narrow phase: contacts against the components
        c = scene.contacts
        for k in range(c.a.size):
            a, b = int(c.a[k]), int(c.b[k])
            ref = collide(scene.get(a, Hitbox).shape, scene.get(a, Transform),
                          scene.get(b, Hitbox).shape, scene.get(b, Transform))
            awake = [e for e in (a, b) if scene.get(e, Hitbox).body.value == "dynamic"
                     and not scene.store.asleep[scene.store.row_of[e]]]
            if awake:
                assert ref is not None and ref.depth == pytest.approx(float(c.depth[k]), abs=1e-12), (a, b)
        seen.append(scene.store.asleep[row])

    s.add_system(check, after="narrow_phase")
    s.spawn(Transform(-0.76, 0.5), Velocity(1.0, 0.0), Hitbox(AABB(0.5, 0.5)))  # touches it next step
    kinds = []
    for _ in range(4):
        s.step(1 / 64)
        kinds += [ev.kind for ev in s.events if (ev.a, ev.b) == (floor, box)]
    assert seen[0] == np.False_  # woken in the first step
    assert kinds == ["ongoing"] * 4
    assert s.get(box, Transform).y == pytest.approx(0.5, abs=1e-9)  # pushed back out, no hop


def test_a_sleeper_whose_support_is_moved_away_falls():
    # A body asleep on another merely touches it (they fell together): when the game shoves the
    # lower one away, no contact ends; the two fell asleep linked, so the upper one wakes with the
    # lower one and falls (found 2026-11-25: it hung where it slept).
    with Scene(gravity=(0.0, -10.0)) as s:
        s.spawn(Transform(0.0, -0.5), Hitbox(AABB(100.0, 1.0), body="static"))
        low = s.spawn(Transform(0.0, 0.5), Velocity(), Hitbox(AABB(1.0, 1.0)))
        top = s.spawn(Transform(0.0, 1.25), Velocity(), Hitbox(AABB(0.5, 0.5)))
        for _ in range(120):
            s.step(1 / 60)
        assert s.counters["asleep"] == 2
        s.get(low, Velocity).x = 3.0  # the game shoves the lower box out from under the upper one
        for _ in range(60):
            s.step(1 / 60)
        assert s.get(top, Transform).y == pytest.approx(0.25, abs=1e-9)  # fallen to the floor
        assert s.counters["asleep"] == 0 or s.get(top, Velocity).y == 0.0
