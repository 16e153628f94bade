"""Scene snapshots: a restored scene steps bit-identically to the original, in this process or
after a pickle into a scene built the same way; bad snapshots change nothing."""

from __future__ import annotations

import hashlib
import math
import pickle
import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from framework import AABB, Circle, Hitbox, InvalidValue, Polygon, Scene, Transform, Velocity
from framework.character import CharacterController
from framework.input import Input
from framework.shapes import Capsule
from framework.snapshot import SNAPSHOT_VERSION, Snapshot

DT = 1.0 / 60.0


def state_hash(scene: Scene) -> str:
    """Positions, rotations, velocities (by row), entity ids and this step's events."""
    h = hashlib.sha256()
    store = scene.bodies.store
    for col in ("x", "y", "rot", "vx", "vy", "w", "entity"):
        h.update(store.cols[col][: store.n].tobytes())
    h.update(repr([(e.kind, e.a, e.b) for e in scene.events]).encode())
    h.update(repr((scene.frame, scene.time)).encode())
    return h.hexdigest()


class Tag:
    """A game's own component."""

    def __init__(self, n: int) -> None:
        self.n = n


def count_contacts(scene: Scene, dt: float) -> None:
    """A game system with state in a component: counts each body's contacts."""
    c = scene.contacts
    for e, tag in scene.query(Tag):
        tag.n += int(((c.a == e) | (c.b == e)).sum())


def build(seed: int, bodies: int = 24, system: bool = True) -> Scene:
    """A floor, walls and a random mix of falling bodies (every shape; friction on some)."""
    s = Scene(gravity=(0.0, -10.0))
    s.spawn(Transform(0.0, -0.5), Hitbox(AABB(40.0, 1.0), body="static"))
    for x in (-8.0, 8.0):
        s.spawn(Transform(x, 5.0), Hitbox(AABB(1.0, 10.0), body="static"))
    rng = random.Random(seed)
    for _ in range(bodies):
        shape = rng.choice([AABB(1.0, 1.0), Circle(0.5), Polygon.box(1.0, 0.5), Capsule(0.25, 0.5),
                            Polygon([(-0.5, -0.4), (0.5, -0.4), (0.0, 0.6)])])
        s.spawn(Transform(rng.uniform(-6.0, 6.0), rng.uniform(1.0, 12.0), rng.uniform(0.0, 3.0)),
                Velocity(rng.uniform(-2.0, 2.0), 0.0),
                Hitbox(shape, friction=rng.choice([None, 0.5]), restitution=rng.choice([0.0, 0.3])), Tag(0))
    if system:
        s.add_system(count_contacts)
    return s


def run(scene: Scene, steps: int) -> list[str]:
    out = []
    for _ in range(steps):
        scene.step(DT)
        out.append(state_hash(scene))
    return out


@pytest.mark.slow
def test_a_restored_scene_steps_bit_identically():
    s = build(1)
    run(s, 40)
    snap = s.snapshot()
    tags_then = {e: t.n for e, t in s.query(Tag)}
    first = run(s, 120)
    s.restore(snap)
    assert {e: t.n for e, t in s.query(Tag)} == tags_then
    assert run(s, 120) == first
    s.restore(snap)  # a snapshot restores as often as asked
    assert run(s, 120) == first


@pytest.mark.slow
def test_a_snapshot_pickles_and_restores_into_a_scene_built_the_same_way():
    s = build(2)
    run(s, 30)
    blob = pickle.dumps(s.snapshot())
    first = run(s, 100)
    fresh = build(99)  # built the same way (other bodies: they are replaced)
    fresh.restore(pickle.loads(blob))
    assert run(fresh, 100) == first


@pytest.mark.slow
@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000), st.integers(0, 60), st.integers(1, 60))
def test_random_scenes_and_random_points_of_snapshot(seed, before, after):
    s = build(seed, bodies=12)
    run(s, before)
    snap = s.snapshot()
    first = run(s, after)
    s.restore(snap)
    assert run(s, after) == first
    other = build(seed + 1, bodies=3)
    other.restore(pickle.loads(pickle.dumps(snap)))
    assert run(other, after) == first


def test_entities_spawned_and_despawned_after_the_snapshot_are_undone():
    s = build(3)
    run(s, 5)
    snap = s.snapshot()
    before = sorted(s.entities)
    gone = before[-1]
    s.despawn(gone)
    late = s.spawn(Transform(0.0, 20.0), Velocity(), Hitbox(Circle(0.5)))
    run(s, 5)
    s.restore(snap)
    assert sorted(s.entities) == before and s.exists(gone)
    assert s.spawn(Transform(0.0, 30.0)) == late  # the next id is the one it was


def test_sleeping_contacts_and_characters_are_restored():
    s = Scene(gravity=(0.0, -1024.0))
    for i in range(10):
        s.spawn(Transform(16.0 + 32.0 * i, 16.0), Hitbox(AABB(32.0, 32.0), body="static"))
    box = s.spawn(Transform(200.0, 60.0), Velocity(), Hitbox(AABB(16.0, 16.0)))
    hero = s.spawn(Transform(60.0, 50.0), Velocity(), Hitbox(AABB(24.0, 28.0), body="kinematic"),
                   CharacterController(step_height=8.0))
    run(s, 80)
    assert s.bodies.store.asleep[s.bodies.store.row_of[box]]
    snap = s.snapshot()
    ctrl = s.get(hero, CharacterController)
    assert ctrl.on_floor
    plan = [128.0 if k % 30 < 20 else -64.0 for k in range(90)]

    def go() -> list[str]:
        out = []
        for vx in plan:
            s.get(hero, Velocity).x = vx
            s.step(1.0 / 64.0)
            out.append(state_hash(s))
        return out

    first = go()
    s.restore(snap)
    assert s.get(hero, CharacterController).on_floor and s.get(hero, CharacterController) is not ctrl
    assert go() == first


class Score:
    def __init__(self) -> None:
        self.points = 0


class Live:
    def __init__(self) -> None:
        self.gen = (i for i in range(3))  # a generator: cannot be pickled


def test_resources_are_restored_in_place_and_unpicklable_ones_are_skipped():
    s = build(4, bodies=3)
    score, live = Score(), Live()
    s.resources[Score], s.resources[Live] = score, live
    s.resources[Input].set_held({"left"})
    snap = s.snapshot()
    assert snap.skipped == (f"{__name__}.{Live.__qualname__}",)
    score.points = 7
    s.resources[Input].set_held({"right"})
    s.restore(snap)
    assert s.resources[Score] is score and score.points == 0  # the same object, its old value
    assert s.resources[Live] is live
    assert s.resources[Input].is_held("left") and not s.resources[Input].is_held("right")


def test_a_snapshot_of_another_shape_or_version_is_refused_and_changes_nothing():
    s = build(5)
    run(s, 10)
    snap = s.snapshot()
    other = build(5, system=False)  # no game system: another shape
    run(other, 3)
    before = state_hash(other)
    with pytest.raises(InvalidValue, match="another shape"):
        other.restore(snap)
    assert state_hash(other) == before
    with pytest.raises(InvalidValue, match="another version"):
        s.restore(Snapshot(SNAPSHOT_VERSION + 1, snap.framework, snap.shape, snap.frame, snap.data))
    with pytest.raises(InvalidValue, match="another version"):
        s.restore(Snapshot(snap.version, "0.0.0", snap.shape, snap.frame, snap.data))
    with pytest.raises(InvalidValue, match="cannot be read"):
        s.restore(Snapshot(snap.version, snap.framework, snap.shape, snap.frame, b"not a snapshot"))
    with pytest.raises(InvalidValue, match="takes a Snapshot"):
        s.restore({"frame": 3})  # type: ignore[arg-type]
    substeps = Scene(substeps=2)
    with pytest.raises(InvalidValue, match="substeps"):
        substeps.restore(Scene().snapshot())


def test_an_unpicklable_component_is_named():
    s = build(6, bodies=2)
    e = s.spawn(Transform(0.0, 0.0), Tag(0))
    s.get(e, Tag).n = lambda: 3  # noqa: E731 - a lambda cannot be pickled
    with pytest.raises(InvalidValue, match=rf"entity {e}: its Tag component cannot be saved"):
        s.snapshot()


def test_no_snapshot_or_restore_inside_a_step():
    s = build(7, bodies=1)
    snap = s.snapshot()
    seen = []

    def inside(scene: Scene, dt: float) -> None:
        for call in (scene.snapshot, lambda: scene.restore(snap)):
            try:
                call()
            except InvalidValue as exc:
                seen.append(str(exc))

    s.add_system(inside)
    s.step(DT)
    assert len(seen) == 2 and all("inside a step" in m for m in seen)


def test_rollback_rewinds_eight_frames_and_replays_with_corrected_input():
    """The rollback pattern: keep a snapshot per frame; when a late input arrives for a past
    frame, restore that frame's snapshot and replay from it with the corrected input."""
    s = Scene(gravity=(0.0, -1024.0))
    for i in range(20):
        s.spawn(Transform(16.0 + 32.0 * i, 16.0), Hitbox(AABB(32.0, 32.0), body="static"))
    hero = s.spawn(Transform(100.0, 46.0), Velocity(), Hitbox(AABB(24.0, 28.0), body="kinematic"),
                   CharacterController())
    inputs = [128.0] * 40
    history = {}
    for frame, vx in enumerate(inputs):
        history[frame] = s.snapshot()
        s.get(hero, Velocity).x = vx
        s.step(1.0 / 64.0)
    # A late input: from frame 32 on the player ran left. Rewind 8 frames and replay.
    corrected = inputs[:32] + [-128.0] * 8
    s.restore(history[32])
    for vx in corrected[32:]:
        s.get(hero, Velocity).x = vx
        s.step(1.0 / 64.0)
    # The same as if the right input had been known all along.
    truth = Scene(gravity=(0.0, -1024.0))
    for i in range(20):
        truth.spawn(Transform(16.0 + 32.0 * i, 16.0), Hitbox(AABB(32.0, 32.0), body="static"))
    t_hero = truth.spawn(Transform(100.0, 46.0), Velocity(), Hitbox(AABB(24.0, 28.0), body="kinematic"),
                         CharacterController())
    for vx in corrected:
        truth.get(t_hero, Velocity).x = vx
        truth.step(1.0 / 64.0)
    assert state_hash(s) == state_hash(truth)
    assert s.get(hero, Transform).x == 100.0 + 32 * 2.0 - 8 * 2.0
    assert math.isfinite(s.time)


@pytest.mark.slow
def test_the_platformer_restores_bit_identically_in_place_and_in_a_new_game():
    from examples.platformer import Game
    from examples.platformer.components import GameState

    g = Game()
    for k in range(240):
        g.step({"right"} if k % 50 < 40 else {"space", "right"})
    snap = g.scene.snapshot()
    assert snap.skipped == ()  # the Game resource too: its reference to the scene stays one to the scene
    rng = random.Random(3)
    plan = [set(rng.sample(["left", "right", "space", "down"], rng.randint(0, 2))) for _ in range(300)]

    def play(game: Game) -> list[str]:
        out = []
        for keys in plan:
            game.step(keys)
            out.append(state_hash(game.scene))
        return out

    coins = g.state.coins
    first = play(g)
    g.scene.restore(snap)
    assert g.scene.resources[GameState] is g.state and g.state.coins == coins
    assert play(g) == first
    fresh = Game()
    fresh.scene.restore(pickle.loads(pickle.dumps(snap)))
    assert fresh.scene.resources[Game] is fresh and fresh.scene.resources[GameState] is fresh.state
    assert fresh.state.coins == coins and fresh.scene is not g.scene
    assert play(fresh) == first
    g.close()
    fresh.close()
