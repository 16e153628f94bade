"""The platformer as a Gymnasium environment (the ``rl`` extra; skipped without gymnasium)."""

from __future__ import annotations

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium", reason="the rl extra (gymnasium) is not installed: pip install -e '.[rl]'")

from examples.platformer import parse_text  # noqa: E402
from examples.platformer.env import ACTION_NAMES, ENV_ID, PlatformerEnv  # noqa: E402
from framework import InvalidValue  # noqa: E402

RUN_TO_GOAL = parse_text("""
#..........#
#.P...C...G#
############
""", "goal.txt")
SPIKES = parse_text("""
#..........#
#.P..^^^..G#
############
""", "spikes.txt")


@pytest.fixture
def env():
    e = PlatformerEnv(0)
    yield e
    e.close()


def test_passes_gymnasiums_env_checker(env):
    from gymnasium.utils.env_checker import check_env

    check_env(env, skip_render_check=True)
    assert env.action_space.n == len(ACTION_NAMES) == 7
    assert env.observation_space.shape == (6 + 3 * 16,) and env.observation_space.dtype == np.float32


def test_registered_and_made_by_id():
    made = gym.make(ENV_ID, level=0, frame_skip=2)
    try:
        obs, info = made.reset(seed=0)
        assert made.observation_space.contains(obs) and info["level"] == "Meadow"
    finally:
        made.close()


@pytest.mark.slow
def test_reset_with_a_seed_is_deterministic_and_restores_the_start(env):
    rng = np.random.default_rng(5)
    actions = rng.integers(0, 7, size=120).tolist()

    def episode(seed: int) -> list[tuple]:
        obs, _ = env.reset(seed=seed)
        out = [obs.tobytes()]
        for a in actions:
            obs, reward, term, trunc, info = env.step(a)
            out.append((obs.tobytes(), reward, term, trunc, info["x"]))
            if term or trunc:
                break
        return out

    first = episode(7)
    assert episode(7) == first  # the same episode again, bit for bit
    assert episode(8) == first  # the level has no randomness: the seed only seeds the action space
    assert env.game.scene.frame > 0


@pytest.mark.slow
def test_resets_restore_the_snapshot_and_never_read_the_level_again(monkeypatch):
    """The level file is loaded and parsed, and its entities spawned, once, when the environment
    is made; every reset restores the start's snapshot instead."""
    from examples.platformer import env as env_module
    from examples.platformer import levels
    from examples.platformer.game import Game
    from framework import Scene

    calls: dict[str, int] = {}

    def counted(owner, name):
        real = getattr(owner, name)

        def wrapper(*args, **kwargs):
            calls[name] = calls.get(name, 0) + 1
            return real(*args, **kwargs)

        monkeypatch.setattr(owner, name, wrapper)

    for owner, name in ((env_module, "load_level"), (levels, "parse_tmj"), (levels, "parse_text"),
                        (Game, "spawn_level"), (Scene, "restore")):
        counted(owner, name)
    e = PlatformerEnv(0, frame_skip=2)
    try:
        made = dict(calls)
        assert made == {"load_level": 1, "parse_tmj": 1, "spawn_level": 1}
        rng = np.random.default_rng(3)
        firsts = []
        for episode in range(5):
            obs, _info = e.reset(seed=episode)
            firsts.append(obs.tobytes())
            for a in rng.integers(0, 7, size=40).tolist():
                if any(e.step(a)[2:4]):
                    break
        assert calls == {**made, "restore": 5}  # nothing loaded, parsed or spawned again
        assert len(set(firsts)) == 1  # and every episode starts where the first did
    finally:
        e.close()


def test_rewards_progress_coins_and_the_goal_and_terminates_there():
    env = PlatformerEnv(RUN_TO_GOAL, frame_skip=4)
    env.reset(seed=0)
    total, coins_seen, steps = 0.0, 0, 0
    while True:
        obs, reward, term, trunc, info = env.step(2)  # right
        total += reward
        steps += 1
        coins_seen = info["coins"]
        assert env.observation_space.contains(obs)
        if term or trunc:
            break
    assert term and not trunc and info["reached_goal"]
    # 6.5 tiles of progress (3.5 to the goal's edge), a coin, the goal's 10.
    assert coins_seen == 1 and total == pytest.approx(info["x"] - 2.5 + 1 + 10, abs=1e-6)
    env.close()


def test_dying_terminates_with_a_penalty_and_frames_truncate():
    env = PlatformerEnv(SPIKES, frame_skip=4)
    env.reset(seed=0)
    rewards = []
    while True:
        _obs, reward, term, trunc, info = env.step(2)
        rewards.append(reward)
        if term or trunc:
            break
    assert term and info["deaths"] == 1 and rewards[-1] < -4.0
    short = PlatformerEnv(RUN_TO_GOAL, frame_skip=4, max_frames=20)
    short.reset()
    ends = [short.step(0)[2:4] for _ in range(5)]
    assert ends[-1] == (False, True) and all(e == (False, False) for e in ends[:-1])
    short.close()
    env.close()


def test_rays_see_walls_dangers_and_pickups(env):
    e = PlatformerEnv(SPIKES, rays=4, ray_range=8.0)
    obs, _ = e.reset()
    # Ray 0 looks right (spikes 3 tiles on: the danger channel), ray 3 down (the floor just under).
    solid, danger = obs[6:10], obs[10:14]
    assert danger[0] < 1.0 and solid[3] < 0.1
    e.close()


def test_bad_input_is_a_clear_error(env):
    env.reset()
    for action in (7, -1, 2.5, "right", None):
        with pytest.raises(InvalidValue, match="not in the action space"):
            env.step(action)
    with pytest.raises(InvalidValue, match="level 9 does not exist"):
        PlatformerEnv(9)
    with pytest.raises(InvalidValue, match="frame_skip"):
        PlatformerEnv(0, frame_skip=0)
    with pytest.raises(InvalidValue, match="render_mode"):
        PlatformerEnv(0, render_mode="ascii")


def _make():
    return PlatformerEnv(0, frame_skip=2)


@pytest.mark.parametrize("kind", ["sync", "async"])
def test_works_in_vector_envs(kind):
    cls = gym.vector.SyncVectorEnv if kind == "sync" else gym.vector.AsyncVectorEnv
    envs = cls([_make, _make])
    try:
        obs, _info = envs.reset(seed=[1, 2])
        assert obs.shape == (2, 54)
        for _ in range(10):
            obs, reward, term, trunc, _info = envs.step(np.array([2, 5]))
        assert obs.shape == (2, 54) and reward.shape == (2,) and np.isfinite(obs).all()
    finally:
        envs.close()


def test_rgb_array_renders_headless():
    try:
        import framework.render as render

        render.offscreen_window()
    except Exception as exc:  # no GL library, no EGL device: not a failure of the code under test
        pytest.skip(f"no OpenGL context available here ({type(exc).__name__}: {exc})")
    e = PlatformerEnv(0, render_mode="rgb_array")
    e.reset()
    frame = e.render()
    assert frame.shape == (270, 480, 3) and frame.dtype == np.uint8 and frame.std() > 0
    e.close()


def test_human_mode_shows_each_step_in_a_window():
    """A smoke test of ``render_mode="human"``: a window is made on the first step, each step is
    drawn into it and shown (what it shows is the rgb_array picture of the same step), and closing
    the environment closes it. Headless (PYGLET_HEADLESS, see conftest.py) the window is pyglet's
    offscreen EGL surface: all of the human path but the display runs."""
    try:
        import framework.render as render

        render.offscreen_window()
    except Exception as exc:  # no GL library, no EGL device, no display: nothing to open a window on
        pytest.skip(f"no OpenGL context available here for a window ({type(exc).__name__}: {exc})")
    from framework.render.offscreen import read_pixels

    actions = [2, 2, 5, 2, 2]
    e = PlatformerEnv(0, render_mode="human")
    try:
        e.reset(seed=0)
        assert e._window is None  # made on the first step that shows something
        e.step(actions[0])
        window = e._window
        assert window is not None and (window.width, window.height) == (480, 270)
        assert window.caption == f"{ENV_ID}: Meadow"
        shown = []
        real_flip = window.flip

        def flip():  # what the window is about to show
            shown.append(read_pixels(480, 270)[:, :, :3].copy())
            real_flip()

        window.flip = flip
        for a in actions[1:]:
            obs, _r, _term, _trunc, _info = e.step(a)
            assert e.observation_space.contains(obs)
        assert e.render() is None and len(shown) == len(actions)  # steps 2 to 5, and render()
    finally:
        e.close()
    assert e._window is None and e._renderer is None
    picture = PlatformerEnv(0, render_mode="rgb_array")
    try:
        picture.reset(seed=0)
        for a in actions:
            picture.step(a)
        want = picture.render()
    finally:
        picture.close()
    # The same picture, up to the colour depth of the window's surface (headless EGL gives 5-6-5
    # bits: a channel is off by up to 255 / 31 / 2 ~ 4 after rounding, and blending adds a little).
    assert np.abs(shown[-1].astype(int) - want).max() <= 8


def _reference_rays(env, player):
    """The observation's rays, the slow way: one scene.raycast_all per ray (the oracle)."""
    from examples.platformer.components import ENEMY, HAZARD, ONE_WAY, PICKUP, SOLID
    from framework import Transform

    scene = env.game.scene
    t = scene.get(player, Transform)
    out = np.ones((3, env.rays))
    for i, direction in enumerate(env._directions):
        for hit in scene.raycast_all((t.x, t.y), direction, env._range, mask=SOLID | ONE_WAY | ENEMY | HAZARD | PICKUP):
            if hit.entity == player:
                continue
            channel = env._channel(hit.entity)
            if channel is not None and out[channel, i] == 1.0:
                out[channel, i] = hit.distance / env._range
                if channel == 0:
                    break
    return out


@pytest.mark.slow
@pytest.mark.parametrize("level", [0, 1, 2])
def test_the_vectorised_rays_agree_with_one_raycast_per_ray(level):
    e = PlatformerEnv(level)
    e.reset()
    rng = np.random.default_rng(level)
    for k in range(120):
        e.step(int(rng.choice([2, 5, 3, 0, 1])))
        if k % 10 == 0:
            player = e.game.state.player
            from framework import Transform

            t = e.game.scene.get(player, Transform)
            got = e._rays(t.x, t.y, player)
            want = _reference_rays(e, player)
            assert np.allclose(got, want, atol=1e-9), (got, want)
    e.close()
