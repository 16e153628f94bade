"""The soft step (``Scene(solver="soft")``): Box2D v3's soft-step solver as one compiled call.

Expectations are analytic where the sub-stepped integration gives an exact answer (dyadic values),
else bounded by the solver's documented tolerance (the linear slop, 0.005 per metre); Box2D v3
(pyb2d3) is the oracle for a pile's rest where it is installed.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from framework import AABB, Capsule, Circle, Hitbox, InvalidValue, Polygon, Scene, Transform, Velocity
from framework.scene import DEFAULT_EFFECTS
from framework.systems.soft_step import SOFT_SETTINGS

SLOP = SOFT_SETTINGS["slop"]


def soft(**kw) -> Scene:
    kw.setdefault("gravity", (0.0, -10.0))
    return Scene(solver="soft", **kw)


def floor(scene: Scene, width: float = 100.0, **kw) -> int:
    return scene.spawn(Transform(0.0, -0.5), Hitbox(AABB(width, 1.0), body="static", **kw))


def hexagon(r: float) -> Polygon:
    return Polygon([(r * math.cos(k * math.pi / 3), r * math.sin(k * math.pi / 3)) for k in range(6)])


# --- settings ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("bad", ["fast", "", None, 1])
def test_unknown_solver_is_refused(bad):
    with pytest.raises(InvalidValue, match="solver"):
        Scene(solver=bad)


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, math.inf])
def test_length_unit_must_be_positive_and_finite(bad):
    with pytest.raises(ValueError, match="length_unit"):
        Scene(solver="soft", length_unit=bad)


def test_the_default_solver_is_exact():
    assert Scene().solver == "exact"
    assert soft().solver == "soft"


def test_the_soft_step_replaces_the_exact_stages():
    s = soft()
    floor(s)
    s.spawn(Transform(0.0, 2.0), Velocity(), Hitbox(AABB(1.0, 1.0)))
    s.step(1 / 60)
    assert "soft_step" in s.counters["systems"]
    assert not {"movement", "broad_phase", "narrow_phase", "response"} & set(s.counters["systems"])


# --- integration: Box2D's sub-stepped semi-implicit Euler, exact in dyadic numbers -----------------


def test_free_fall_is_sub_stepped_semi_implicit_euler():
    s = soft(gravity=(0.0, -8.0))
    e = s.spawn(Transform(0.0, 0.0), Velocity(0.0, 0.0), Hitbox(Circle(0.5)))
    s.step(1 / 64)
    # four sub-steps of h = 1/256: v_k = -8 k h, y = sum h v_k = -8 h^2 (1 + 2 + 3 + 4)
    assert s.get(e, Velocity).y == -8.0 / 64
    assert s.get(e, Transform).y == -80.0 / 65536


def test_kinematic_bodies_move_without_gravity_and_are_not_pushed():
    s = soft()
    k = s.spawn(Transform(0.0, 0.0), Velocity(1.0, 0.0), Hitbox(AABB(2.0, 0.5), body="kinematic"))
    box = s.spawn(Transform(-3.0, 0.0), Velocity(8.0, 0.0), Hitbox(AABB(1.0, 1.0)))
    for _ in range(64):
        s.step(1 / 64)
    assert s.get(k, Transform).x == 1.0 and s.get(k, Transform).y == 0.0
    assert s.get(k, Velocity).x == 1.0
    assert s.get(box, Transform).x < s.get(k, Transform).x - 1.5 + SLOP  # stopped at the platform's face


# --- resting: within the slop, no jitter ----------------------------------------------------------------


@pytest.mark.parametrize("shape,height", [(AABB(1.0, 1.0), 0.5), (Circle(0.25), 0.25), (Capsule(0.25, 1.0), 0.75),
                                          (hexagon(0.5), math.sqrt(3) / 4), (Polygon.box(1.0, 0.5), 0.25)])
def test_a_body_rests_on_the_floor_within_the_slop(shape, height):
    s = soft()
    floor(s)
    e = s.spawn(Transform(0.0, height + 0.25), Velocity(), Hitbox(shape, inertia=None if isinstance(shape, Polygon)
                                                                   else math.inf))
    ys = []
    for _ in range(240):
        s.step(1 / 60)
        ys.append(s.get(e, Transform).y)
    assert abs(ys[-1] - height) < 0.05 * SLOP
    assert max(ys[-60:]) - min(ys[-60:]) < 1e-9  # no jitter once at rest
    # (the two points of a flat landing are solved one after the other, as Box2D's are: a wide box
    # lands turned by about 1e-4 radians, 0.007 degrees)
    assert abs(s.get(e, Transform).rotation) < 2e-4


def test_a_stack_of_twenty_rests_and_sinks_as_little_as_box2d():
    s = soft()
    floor(s, 8.0)
    boxes = [s.spawn(Transform(0.0, i + 0.5 + (i + 1) / 16), Velocity(), Hitbox(AABB(1.0, 1.0))) for i in range(20)]
    for _ in range(600):
        s.step(1 / 60)
    y = np.array([s.get(b, Transform).y for b in boxes])
    exact = np.arange(20) + 0.5
    assert np.all(y <= exact + 1e-9)
    assert (exact[-1] - y[-1]) / 20 < 0.003  # Box2D v3: 0.0027 of the height (docs/performance.md)
    # a soft contact gives under load like a stiff spring: the lowest, under 19 boxes, by about the slop
    assert np.all(np.diff(y) > 1.0 - 2 * SLOP)
    assert all(abs(s.get(b, Velocity).y) < 1e-6 for b in boxes)


def test_a_pile_rests_as_box2d_does():
    b2 = pytest.importorskip("pyb2d3")
    del b2
    from framework.bench import regimes as R

    regime = R.box_pile(10, 10)
    ours, peer = R.Ours(R.replace(regime)), R.Box2DEngine(regime, R.peer_modules()["box2d"])
    ours.scene.close()
    scene = Scene(gravity=regime.gravity, solver="soft", effects=DEFAULT_EFFECTS - {"sleeping"})
    ents = [scene.spawn(Transform(p.x, p.y), Hitbox(p.shape, body="static")) if p.kind == "static" else
            scene.spawn(Transform(p.x, p.y), Velocity(p.vx, p.vy), Hitbox(p.shape)) for p in regime.pieces]
    for _ in range(300):
        scene.step(regime.dt)
        peer.step()
    _, py, *_ = peer.state()
    oy = np.array([scene.get(e, Transform).y for e in ents])
    top = regime.top
    assert abs(oy[top].min() - py[top].min()) < 0.01  # the same sink as Box2D, to a hundredth of a box
    assert regime.exact_top - oy[top].min() < 0.01 * regime.height
    peer.close()


# --- friction, restitution, momentum ------------------------------------------------------------------


@pytest.mark.parametrize("turns", [False, True])
def test_a_sliding_box_stops_where_coulomb_says(turns):
    s = soft()
    floor(s, friction=0.5)
    shape = Polygon.box(1.0, 1.0) if turns else AABB(1.0, 1.0)
    b = s.spawn(Transform(-40.0, 0.5), Velocity(5.0, 0.0),
                Hitbox(shape, friction=0.5, inertia=None if turns else math.inf))
    for _ in range(300):
        s.step(1 / 60)
    # decelerates at mu g = 5 from 5: v^2 / (2 mu g) = 2.5, less half a sub-step's travel at the start
    h = 1 / 240
    assert s.get(b, Transform).x + 40.0 == pytest.approx(2.5 - 5.0 * h / 2, abs=2e-4)
    assert s.get(b, Velocity).x == 0.0
    assert abs(s.get(b, Transform).rotation) < 1e-5  # mu = 1/2 below w / h = 1: slides, never tips


def test_a_box_on_a_slope_holds_or_slides():
    angle = math.radians(30)
    for mu, holds in ((0.7, True), (0.3, False)):
        s = soft()
        ramp = Polygon.box(40.0, 1.0)
        s.spawn(Transform(0.0, 0.0, angle), Hitbox(ramp, body="static", friction=mu))
        # a box resting on the ramp's top face, turned with it
        nx, ny = -math.sin(angle), math.cos(angle)
        b = s.spawn(Transform(nx * 1.0, ny * 1.0, angle), Velocity(),
                    Hitbox(Polygon.box(1.0, 1.0), friction=mu, inertia=None))
        for _ in range(120):
            s.step(1 / 60)
        v = s.get(b, Velocity)
        speed = math.hypot(v.x, v.y)
        if holds:
            assert speed < 1e-3
        else:  # slides at g (sin - mu cos)
            assert speed == pytest.approx(10 * (math.sin(angle) - mu * math.cos(angle)) * 2.0, rel=0.03)


def test_restitution_bounces_at_e_times_the_approach():
    s = soft()
    floor(s)
    b = s.spawn(Transform(0.0, 0.5 + 1 / 8), Velocity(0.0, -8.0), Hitbox(Circle(0.5), restitution=0.5))
    up = 0.0
    for _ in range(10):
        s.step(1 / 64)
        up = max(up, s.get(b, Velocity).y)
    assert up == pytest.approx(0.5 * 8.0, rel=0.05)


def test_a_head_on_hit_keeps_momentum():
    s = soft(gravity=(0.0, 0.0))
    a = s.spawn(Transform(-2.0, 0.0), Velocity(4.0, 0.0), Hitbox(AABB(1.0, 1.0), mass=1.0))
    b = s.spawn(Transform(2.0, 0.0), Velocity(-1.0, 0.0), Hitbox(AABB(1.0, 1.0), mass=3.0))
    for _ in range(120):
        s.step(1 / 60)
        p = s.get(a, Velocity).x * 1.0 + s.get(b, Velocity).x * 3.0
        assert p == pytest.approx(1.0, abs=1e-12)
    assert s.get(a, Velocity).x == pytest.approx(0.25, abs=1e-3)  # inelastic: one common velocity
    assert s.get(b, Transform).x - s.get(a, Transform).x > 1.0 - SLOP


# --- what game makers try first ---------------------------------------------------------------------


def test_a_fast_bullet_never_passes_a_thin_wall_and_its_hit_is_an_event():
    for speed in (100.0, 1000.0, 30000.0):
        s = soft(gravity=(0.0, 0.0))
        wall = s.spawn(Transform(10.0, 0.0), Hitbox(AABB(0.1, 4.0), body="static"))
        b = s.spawn(Transform(0.0, 0.0), Velocity(speed, 0.0), Hitbox(AABB(0.1, 0.1)))
        kinds = []
        for _ in range(30):
            s.step(1 / 60)
            assert s.get(b, Transform).x <= 9.9 + 1e-9
            kinds += [ev.kind for ev in s.events if {ev.a, ev.b} == {wall, b}]
        assert kinds[0] == "started" and kinds.count("started") == 1  # stopped at the face: it hit


def test_a_ball_bouncing_off_a_wall_starts_and_ends_once():
    s = soft(gravity=(0.0, 0.0))
    wall = s.spawn(Transform(10.0, 0.0), Hitbox(AABB(1.0, 4.0), body="static"))
    b = s.spawn(Transform(0.0, 0.0), Velocity(30.0, 0.0), Hitbox(Circle(0.25), restitution=1.0))
    kinds = []
    for _ in range(60):
        s.step(1 / 60)
        kinds += [ev.kind for ev in s.events if {ev.a, ev.b} == {wall, b}]
    assert kinds[0] == "started" and kinds[-1] == "ended"
    assert kinds.count("started") == 1 and kinds.count("ended") == 1
    assert s.get(b, Velocity).x == pytest.approx(-30.0, rel=1e-9)


def test_a_crate_that_can_turn_tips_off_a_ledge_only_past_its_centre():
    for over, tips in ((0.4, False), (0.6, True)):
        s = soft()
        s.spawn(Transform(-5.0, -0.5), Hitbox(AABB(10.0, 1.0), body="static"))  # a ledge ending at x = 0
        # the box overhangs the edge by ``over``: its centre is past the edge iff over > 1/2
        b = s.spawn(Transform(over - 0.5, 0.5), Velocity(), Hitbox(Polygon.box(1.0, 1.0), inertia=None))
        for _ in range(180):
            s.step(1 / 60)
        t = s.get(b, Transform)
        if tips:
            assert t.y < -1.0 and abs(t.rotation) > 0.3
        else:
            assert abs(t.y - 0.5) < 0.05 * SLOP and abs(t.rotation) < 2e-4


def test_events_start_once_stay_ongoing_at_rest_and_end_when_lifted():
    s = soft()
    ground = floor(s)
    b = s.spawn(Transform(0.0, 2.0), Velocity(), Hitbox(AABB(1.0, 1.0)))
    kinds = []
    for _ in range(300):
        s.step(1 / 60)
        kinds.append([ev.kind for ev in s.events if {ev.a, ev.b} == {ground, b}])
    flat = [k for ks in kinds for k in ks]
    assert flat.count("started") == 1
    first = next(i for i, ks in enumerate(kinds) if ks)
    assert all(ks == ["ongoing"] for ks in kinds[first + 1:])  # no flicker while resting
    s.get(b, Transform).y = 5.0
    s.step(1 / 60)
    assert [ev.kind for ev in s.events] == ["ended"]
    s.step(1 / 60)
    assert s.events == []


def test_a_sensor_reports_overlaps_and_stops_nothing():
    s = soft(gravity=(0.0, 0.0))
    zone = s.spawn(Transform(5.0, 0.0), Hitbox(AABB(2.0, 2.0), body="static", sensor=True))
    b = s.spawn(Transform(0.0, 0.0), Velocity(60.0, 0.0), Hitbox(Circle(0.25)))
    seen = []
    for _ in range(12):
        s.step(1 / 60)
        seen += [(ev.kind, ev.a, ev.b) for ev in s.events]
    assert s.get(b, Velocity).x == 60.0
    kinds = [k for k, *_ in seen]
    assert kinds[0] == "started" and kinds[-1] == "ended" and set(kinds[1:-1]) == {"ongoing"}
    assert all({a, b_} == {zone, b} for _, a, b_ in seen)


def test_layers_that_do_not_meet_pass_through():
    s = soft()
    s.spawn(Transform(0.0, -0.5), Hitbox(AABB(10.0, 1.0), body="static", layer=1, mask=1))
    ghost = s.spawn(Transform(0.0, 1.0), Velocity(), Hitbox(AABB(1.0, 1.0), layer=2, mask=2))
    for _ in range(60):
        s.step(1 / 60)
    assert s.get(ghost, Transform).y < -1.0
    assert s.events == []


def test_a_one_way_platform_lets_a_body_up_through_and_holds_it_on_top():
    s = soft()
    s.spawn(Transform(0.0, 2.0), Hitbox(AABB(4.0, 0.25), body="static", one_way=True))
    b = s.spawn(Transform(0.0, 0.0), Velocity(0.0, 9.0), Hitbox(AABB(0.5, 0.5)))
    top = 2.0 + 0.125 + 0.25
    for _ in range(240):
        s.step(1 / 60)
    assert s.get(b, Transform).y == pytest.approx(top, abs=0.05 * SLOP)


def test_two_bodies_in_a_pile_fall_asleep_and_a_touch_wakes_them():
    s = soft(effects=None)
    floor(s)
    a = s.spawn(Transform(0.0, 0.5), Velocity(), Hitbox(AABB(1.0, 1.0)))
    b = s.spawn(Transform(0.0, 1.5), Velocity(), Hitbox(AABB(1.0, 1.0)))
    for _ in range(120):
        s.step(1 / 60)
    assert s.counters["asleep"] == 2
    ball = s.spawn(Transform(0.0, 4.0), Velocity(0.0, -5.0), Hitbox(Circle(0.5)))
    woke = False
    for _ in range(60):
        s.step(1 / 60)
        woke |= s.counters["asleep"] < 2
    assert woke
    assert s.get(ball, Transform).y > s.get(b, Transform).y
    assert s.get(a, Transform).y == pytest.approx(0.5, abs=0.05 * SLOP)


# --- determinism, failed steps ---------------------------------------------------------------------------


def _mixed_pile(seed: int) -> tuple[Scene, list[int]]:
    rng = np.random.default_rng(seed)
    s = soft()
    floor(s, 12.0)
    s.spawn(Transform(-6.0, 5.0), Hitbox(AABB(1.0, 10.0), body="static"))
    s.spawn(Transform(6.0, 5.0), Hitbox(AABB(1.0, 10.0), body="static"))
    shapes = [Circle(0.3), Polygon.box(0.6, 0.6), hexagon(0.35), Capsule(0.2, 0.4), AABB(0.5, 0.5)]
    ents = [s.spawn(Transform(float(rng.uniform(-5, 5)), 1.0 + 0.8 * k), Velocity(),
                    Hitbox(shapes[k % 5], friction=0.4, inertia=math.inf if k % 5 >= 3 else None))
            for k in range(60)]
    return s, ents


def _state(s: Scene, ents: list[int]) -> bytes:
    return b"".join(np.array([[s.get(e, Transform).x, s.get(e, Transform).y, s.get(e, Transform).rotation,
                               s.get(e, Velocity).x, s.get(e, Velocity).y] for e in ents]).tobytes() for _ in [0])


def test_the_soft_step_is_deterministic():
    runs = []
    for _ in range(2):
        s, ents = _mixed_pile(3)
        for _ in range(200):
            s.step(1 / 60)
        runs.append(_state(s, ents))
        s.close()
    assert runs[0] == runs[1]


def test_a_mixed_pile_settles_without_overlap_or_escape():
    s, ents = _mixed_pile(5)
    for _ in range(600):
        s.step(1 / 60)
    for e in ents:
        t = s.get(e, Transform)
        assert -6.0 < t.x < 6.0 and t.y > 0.0
    deepest = max((c for c in s.contacts.depth), default=0.0)
    assert deepest < 2 * SLOP * 4


def test_a_failed_step_is_undone_and_the_run_continues_bit_for_bit():
    s1, e1 = _mixed_pile(7)
    s2, e2 = _mixed_pile(7)
    for _ in range(50):
        s1.step(1 / 60)
        s2.step(1 / 60)

    def boom(scene, dt):
        raise RuntimeError("game bug")

    s2.add_system(boom)
    with pytest.raises(RuntimeError, match="game bug"):
        s2.step(1 / 60)
    s2.remove_system(boom)
    for _ in range(50):
        s1.step(1 / 60)
        s2.step(1 / 60)
    assert _state(s1, e1) == _state(s2, e2)


# --- the broad phase: incremental pairs are the full sweep's --------------------------------------------


def test_candidate_pairs_kept_between_steps_are_those_a_full_sweep_finds():
    from framework.systems.soft_kernel import _candidate_pairs

    s, ents = _mixed_pile(11)
    s.spawn(Transform(0.0, 12.0), Velocity(3.0, -20.0), Hitbox(Circle(0.5)))  # a fast one, through the pile
    stage = s._stages["soft_step"]
    store = s.bodies.store
    incremental = 0
    before = stage.pairs
    for _ in range(240):
        s.step(1 / 60)
        cnt = stage._kernel_tables[1][8]  # (iprops: the vertex counts)
        fixed = (store.body == 2) | ~store.has_vel
        full = _candidate_pairs(stage.fat, cnt, fixed, store.layer, store.mask, True, store.entity,
                                np.arange(store.n))
        assert np.array_equal(full, stage.pairs)
        # (pairs that changed without a full sweep: the incremental update ran)
        incremental += s.counters["rehashed"] == 0 and not np.array_equal(before, stage.pairs)
        before = stage.pairs
    assert incremental >= 10


@pytest.mark.parametrize("seed", range(4))
def test_the_sweep_finds_every_overlapping_pair_of_a_heap(seed):
    """The sort-and-sweep (its pairs written by a helper that hands back when its arrays are full:
    a heap of 60 rows on one spot has far more pairs than its first guess of 4 per row) finds the
    pairs brute force finds, sorted by key, with fixed rows, one owner's shapes and touching bounds."""
    from framework.systems.soft_kernel import _candidate_pairs

    rng = np.random.default_rng(seed)
    n = 60
    x0, y0 = np.round(rng.random(n), 2), np.round(rng.random(n), 2)
    fat = np.stack([x0, y0, x0 + np.round(rng.random(n), 2) + 0.5, y0 + 1.0], axis=1)  # (a heap: most overlap)
    cnt = np.where(rng.random(n) < 0.05, 0, 4)
    fixed = rng.random(n) < 0.2
    owner = np.arange(n)
    owner[1] = owner[0]  # (two shapes of one body never pair)
    entity = rng.permutation(5 * n)[:n].astype(np.int64)
    layer = mask = np.ones(n, dtype=np.int64)
    got = _candidate_pairs(fat, cnt, fixed, layer, mask, True, entity, owner)
    want = []
    for i in range(n):
        for j in range(i + 1, n):
            if cnt[i] == 0 or cnt[j] == 0 or (fixed[i] and fixed[j]) or owner[i] == owner[j]:
                continue
            if fat[j, 0] > fat[i, 2] or fat[i, 0] > fat[j, 2] or fat[j, 1] > fat[i, 3] or fat[i, 1] > fat[j, 3]:
                continue
            a, b = (i, j) if entity[i] < entity[j] else (j, i)
            want.append((a, b, (int(entity[a]) << 32) | int(entity[b])))
    want.sort(key=lambda t: t[2])
    assert len(want) > 4 * n + 16  # (the helper's arrays grew)
    assert got.tolist() == [list(t) for t in want]


def test_a_snapshot_restored_continues_bit_for_bit():
    s, ents = _mixed_pile(13)
    for _ in range(40):
        s.step(1 / 60)
    snap = s.snapshot()
    for _ in range(40):
        s.step(1 / 60)
    expected = _state(s, ents)
    other, ents2 = _mixed_pile(13)  # another scene built the same way
    other.restore(snap)
    for _ in range(40):
        other.step(1 / 60)
    assert _state(other, ents2) == expected
    s.restore(snap)  # and the scene itself
    for _ in range(40):
        s.step(1 / 60)
    assert _state(s, ents) == expected


def test_a_snapshot_file_restored_continues_bit_for_bit(tmp_path):
    from framework.snapshot_file import load_snapshot, save_snapshot

    s, ents = _mixed_pile(17)
    for _ in range(30):
        s.step(1 / 60)
    save_snapshot(s, tmp_path / "soft.npz")
    for _ in range(30):
        s.step(1 / 60)
    other, ents2 = _mixed_pile(17)
    load_snapshot(other, tmp_path / "soft.npz")
    for _ in range(30):
        other.step(1 / 60)
    assert _state(other, ents2) == _state(s, ents)


def test_a_soft_snapshot_does_not_restore_into_an_exact_scene():
    s, _ = _mixed_pile(1)
    s.step(1 / 60)
    snap = s.snapshot()
    exact = Scene(gravity=(0.0, -10.0))
    with pytest.raises(InvalidValue, match="another shape"):
        exact.restore(snap)


# --- the platformer and its characters -------------------------------------------------------------------


@pytest.mark.slow
def test_the_platformers_demo_plays_the_same_in_the_soft_step():
    from examples.platformer import Game
    from examples.platformer.demo import Autoplay, level1

    summaries = []
    for solver in ("exact", "soft"):
        game = Game(autoplay=Autoplay(level1), scene=Scene(solver=solver, length_unit=32.0))
        frames = 0
        while frames < 3600 and not game.state.reached_goal:
            game.step()
            frames += 1
        summaries.append((frames, game.summary()))
        game.scene.close()
    assert summaries[0] == summaries[1]
    assert summaries[1][1]["reached_goal"] and summaries[1][1]["deaths"] == 0


def test_a_character_rides_a_moving_platform_and_is_not_moved_twice():
    from framework.character import CharacterController

    for solver in ("exact", "soft"):
        s = Scene(gravity=(0.0, -20.0), solver=solver)
        platform = s.spawn(Transform(0.0, 0.0), Velocity(2.0, 0.0), Hitbox(AABB(4.0, 0.5), body="kinematic"))
        hero = s.spawn(Transform(0.0, 0.25 + 0.5), Velocity(0.0, 0.0),
                       Hitbox(AABB(0.5, 1.0), body="kinematic"), CharacterController())
        for _ in range(60):
            s.step(1 / 60)
        hx, px = s.get(hero, Transform).x, s.get(platform, Transform).x
        assert px == pytest.approx(2.0, abs=1e-9), solver
        # carried along from the second step on (the first finds the floor), and no faster
        assert hx == pytest.approx(px - 2.0 / 60, abs=1e-6), solver
        assert s.get(hero, Transform).y == pytest.approx(0.75, abs=1e-3), solver


@pytest.mark.slow
def test_a_first_step_that_compiles_says_so_once_and_a_quick_one_says_nothing(monkeypatch, capsys):
    import time

    import framework.systems.soft_step as ss

    calls = []

    def slow(*args):
        calls.append(args)
        time.sleep(1.3)  # as numba compiling it would
        return "out"

    monkeypatch.setattr(ss, "soft_step", slow)
    monkeypatch.setattr(ss, "_COMPILED", set())
    assert ss._first_call((1, 2), False) == "out"
    assert ss.COMPILE_NOTICE in capsys.readouterr().err
    assert ss._COMPILED == {False}
    # the variant for scenes with joints is compiled apart: its first call says so too
    assert ss._first_call((1, 2), True) == "out"
    assert ss.COMPILE_NOTICE in capsys.readouterr().err
    assert ss._COMPILED == {False, True}
    monkeypatch.setattr(ss, "_COMPILED", set())
    monkeypatch.setattr(ss, "soft_step", lambda *args: "quick")
    assert ss._first_call((1, 2), False) == "quick"
    assert capsys.readouterr().err == ""


def _event_story(solver: str) -> list:
    class Bullet:
        pass

    class Wall:
        pass

    s = Scene(gravity=(0.0, -10.0), solver=solver)
    s.spawn(Transform(0.0, -0.5), Hitbox(AABB(10.0, 1.0), body="static"))
    a = s.spawn(Transform(0.0, 0.5), Velocity(), Hitbox(AABB(1.0, 1.0)))
    b = s.spawn(Transform(2.0, 0.5), Velocity(), Hitbox(AABB(1.0, 1.0)))
    s.spawn(Transform(8.0, 3.0), Hitbox(AABB(1.0, 4.0), body="static"), Wall())
    s.spawn(Transform(3.0, 3.0), Velocity(60.0, 0.0), Hitbox(Circle(0.2)), Bullet())
    s.on_collision(Bullet, Wall, lambda scene, ev: scene.despawn(ev.a))
    story = []

    def step():
        s.step(1 / 60)
        story.append(sorted((e.kind, e.a, e.b) for e in s.events))

    for _ in range(5):
        step()
    s.despawn(a)  # a resting body goes: its contact ends
    step()
    s.get(b, Hitbox).shape = Circle(0.5)  # a shape changed in place: the contact goes on
    step()
    s.get(b, Transform).y = 5.0  # lifted by game code: it ends
    step()
    s.close()
    return story


def test_events_tell_the_same_story_in_both_solvers():
    # resting contacts, a bullet a handler despawns on hitting a wall, a despawned resting body, a
    # shape changed in place, a body lifted by game code
    assert _event_story("soft") == _event_story("exact")


@pytest.mark.parametrize("field,value", [("x", math.nan), ("vy", math.inf), ("x", 1e16)])
def test_a_bad_value_is_refused_before_the_soft_step_changes_anything(field, value):
    s, ents = _mixed_pile(19)
    for _ in range(10):
        s.step(1 / 60)
    before = _state(s, ents)
    target = s.get(ents[3], Transform if field == "x" else Velocity)
    setattr(target, "x" if field == "x" else "y", value)
    with pytest.raises(ValueError, match=f"entity {ents[3]}"):
        s.step(1 / 60)
    setattr(target, "x" if field == "x" else "y", 0.0 if field == "vy" else 0.25)
    after = _state(s, ents)
    # only the mended field differs: nothing else moved
    differs = np.frombuffer(before, dtype=float) != np.frombuffer(after, dtype=float)
    assert differs.sum() <= 1


@pytest.mark.slow
def test_the_soft_step_gives_the_same_bytes_in_another_process():
    import subprocess
    import sys
    from pathlib import Path

    here_dir = str(Path(__file__).resolve().parent)
    code = (f"import sys; sys.path.insert(0, {here_dir!r}); import hashlib\n"
            "from test_soft_step import _mixed_pile, _state\n"
            "s, e = _mixed_pile(23)\n"
            "for _ in range(120): s.step(1 / 60)\n"
            "print(hashlib.sha256(_state(s, e)).hexdigest())")
    here = _mixed_pile(23)
    for _ in range(120):
        here[0].step(1 / 60)
    import hashlib

    mine = hashlib.sha256(_state(*here)).hexdigest()
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-1] == mine
