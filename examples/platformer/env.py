"""The platformer as a Gymnasium environment: ``framework/Platformer-v0`` (the ``rl`` extra).

::

    import gymnasium as gym
    import examples.platformer.env  # registers framework/Platformer-v0 (installed: framework.examples...)

    env = gym.make("framework/Platformer-v0", level=0)
    obs, info = env.reset(seed=1)
    obs, reward, terminated, truncated, info = env.step(2)  # run right

**Actions** (``Discrete(7)``): 0 nothing, 1 left, 2 right, 3 jump, 4 left + jump, 5 right + jump,
6 drop (down + jump: through a one-way platform). Each action is held for ``frame_skip`` frames
(default 4) of the game at 60 Hz.

**Observation** (``float32``, 6 + 3 x ``rays`` values, each in [-1, 1]): the player's position
over the level's size, its velocity over the game's fall speed, whether it stands on the ground,
which way it faces; then a fan of ``rays`` ray casts (default 16, evenly around the player, each
``ray_range`` tiles long, default 8), giving per ray the distance (over the range; 1: nothing)
to the nearest solid thing (ground, slopes, platforms, crates), the nearest danger (spikes,
enemies) and the nearest pickup (coins, the goal).

**Reward**: the tiles of new progress to the right (the farthest x reached in the episode, so
running back and forth earns nothing), +1 a coin, +10 at the goal, -5 for dying.
**Terminated** at the goal or a death; **truncated** after ``max_frames`` game frames (default
3,600: a minute).

``reset(seed=...)`` is deterministic: the level's start is a :class:`~framework.snapshot.Snapshot`
taken once when the environment is made, restored at every reset (no level is parsed again).
``render_mode="rgb_array"`` renders through the headless renderer (``render()`` returns a
``(height, width, 3)`` uint8 array), ``"human"`` in a window.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from framework import Hitbox, Transform, Velocity
from framework.validation import InvalidValue

from .components import ENEMY, HAZARD, ONE_WAY, PICKUP, SOLID, Coin, Goal, Tuning
from .game import Game
from .levels import Level, builtin_levels, load_level

__all__ = ["ACTIONS", "ACTION_NAMES", "ENV_ID", "PlatformerEnv", "register"]

ENV_ID = "framework/Platformer-v0"
ACTIONS: tuple[tuple[str, ...], ...] = ((), ("left",), ("right",), ("space",), ("left", "space"),
                                        ("right", "space"), ("down", "space"))
ACTION_NAMES = ("noop", "left", "right", "jump", "left+jump", "right+jump", "drop")
PLAYER_VALUES = 6
WIDTH, HEIGHT = 480, 270
BACKGROUND = (24, 26, 38)


class PlatformerEnv(gym.Env):
    """One level of the platformer as an environment (see the module docstring).

    ``level``: an index into the shipped levels, a path, or a :class:`Level`. ``frame_skip``:
    game frames per step. ``max_frames``: game frames before truncation. ``rays`` and
    ``ray_range`` (tiles): the observation's fan of ray casts. ``render_mode``: None,
    ``"rgb_array"`` or ``"human"``."""

    metadata = {"render_modes": ["human", "rgb_array"], "render_fps": 15}

    def __init__(self, level: int | str | Path | Level = 0, *, frame_skip: int = 4, max_frames: int = 3600,
                 rays: int = 16, ray_range: float = 8.0, render_mode: str | None = None) -> None:
        super().__init__()
        for name, value, least in (("frame_skip", frame_skip, 1), ("max_frames", max_frames, 1), ("rays", rays, 1)):
            if isinstance(value, bool) or not isinstance(value, int) or value < least:
                raise InvalidValue(f"PlatformerEnv {name} must be an int >= {least}, got {value!r}")
        if not (isinstance(ray_range, (int, float)) and math.isfinite(ray_range) and ray_range > 0):
            raise InvalidValue(f"PlatformerEnv ray_range must be a number > 0, got {ray_range!r}")
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise InvalidValue(f"PlatformerEnv render_mode must be one of {self.metadata['render_modes']} or None, "
                               f"got {render_mode!r}")
        self.level = _level(level)
        self.frame_skip, self.max_frames, self.render_mode = frame_skip, max_frames, render_mode
        self.rays = rays
        angles = np.arange(rays) * (2.0 * math.pi / rays)
        self._directions = [(math.cos(a), math.sin(a)) for a in angles.tolist()]
        self.game = Game([self.level], view=(WIDTH, HEIGHT))
        self.tuning: Tuning = self.game.tuning
        self._range = float(ray_range) * self.level.tile
        self._start = self.game.scene.snapshot()  # every reset restores this
        self.action_space = spaces.Discrete(len(ACTIONS))
        size = PLAYER_VALUES + 3 * rays
        self.observation_space = spaces.Box(-1.0, 1.0, shape=(size,), dtype=np.float32)
        self._frames = 0
        self._best_x = 0.0
        self._window: Any = None
        self._renderer: Any = None

    # --- the Gymnasium API --------------------------------------------------------------------------

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict]:
        super().reset(seed=seed)
        self.game.scene.restore(self._start)
        self._frames = 0
        self._best_x = self._player_x()
        return self._observe(), self._info()

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict]:
        if not self.action_space.contains(action):
            raise InvalidValue(f"action {action!r} is not in the action space {self.action_space} "
                               f"({', '.join(f'{i} {n}' for i, n in enumerate(ACTION_NAMES))})")
        game, state = self.game, self.game.state
        keys = set(ACTIONS[int(action)])
        coins, deaths = state.coins, state.deaths
        for _ in range(self.frame_skip):
            game.step(keys)
            self._frames += 1
            if state.reached_goal or state.deaths > deaths:
                break
        x = self._player_x()
        reward = max(0.0, x - self._best_x) / self.level.tile + (state.coins - coins)
        self._best_x = max(self._best_x, x)
        died = state.deaths > deaths
        if state.reached_goal:
            reward += 10.0
        if died:
            reward -= 5.0
        terminated = bool(state.reached_goal or died)
        truncated = bool(not terminated and self._frames >= self.max_frames)
        if self.render_mode == "human":
            self.render()
        return self._observe(), float(reward), terminated, truncated, self._info()

    def render(self) -> np.ndarray | None:
        if self.render_mode == "rgb_array":
            from framework.render import Camera, screenshot

            camera = Camera(target=self.game.state.player, bounds=self.game.state.bounds)
            return screenshot(self.game.scene, width=WIDTH, height=HEIGHT, camera=camera,
                              background=BACKGROUND)[:, :, :3].copy()
        if self.render_mode == "human":
            self._show()
        return None

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        if self._window is not None:
            self._window.close()
            self._window = None
        self.game.close()
        super().close()

    # --- observation ----------------------------------------------------------------------------------

    def _player_x(self) -> float:
        player = self.game.state.player
        return self.game.scene.get(player, Transform).x if player is not None else 0.0

    def _observe(self) -> np.ndarray:
        game, scene = self.game, self.game.scene
        state, tile = game.state, self.level.tile
        obs = np.ones(self.observation_space.shape, dtype=np.float32)
        player = state.player
        if player is None:
            return obs
        t, v, p = scene.get(player, Transform), scene.get(player, Velocity), game.player_state
        width, height = self.level.size
        fall = self.tuning.fall_speed * tile
        obs[:PLAYER_VALUES] = (2.0 * t.x / width - 1.0, 2.0 * t.y / height - 1.0, v.x / fall, v.y / fall,
                               1.0 if p.grounded else -1.0, float(p.facing))
        n = self.rays
        for i, direction in enumerate(self._directions):
            hits = scene.raycast_all((t.x, t.y), direction, self._range, mask=SOLID | ONE_WAY | ENEMY | HAZARD | PICKUP)
            seen = [1.0, 1.0, 1.0]
            for hit in hits:
                if hit.entity == player:
                    continue
                channel = self._channel(hit.entity)
                if channel is not None and seen[channel] == 1.0:
                    seen[channel] = hit.distance / self._range
                    if channel == 0:
                        break  # nothing behind a wall is seen
            obs[PLAYER_VALUES + i] = seen[0]
            obs[PLAYER_VALUES + n + i] = seen[1]
            obs[PLAYER_VALUES + 2 * n + i] = seen[2]
        return np.clip(obs, -1.0, 1.0)

    def _channel(self, entity: int) -> int | None:
        """0 solid, 1 danger, 2 pickup (None: something else, e.g. a checkpoint)."""
        scene = self.game.scene
        hb = scene.try_get(entity, Hitbox)
        if hb is None:
            return None
        if hb.layer & (HAZARD | ENEMY):
            return 1
        if scene.try_get(entity, Coin) is not None or scene.try_get(entity, Goal) is not None:
            return 2
        if hb.layer & (SOLID | ONE_WAY) and not hb.sensor:
            return 0
        return None

    def _info(self) -> dict[str, Any]:
        st = self.game.state
        return {"frames": self._frames, "x": self._player_x() / self.level.tile, "coins": st.coins,
                "deaths": st.deaths, "reached_goal": st.reached_goal, "level": st.level_name}

    # --- a window ---------------------------------------------------------------------------------------

    def _show(self) -> None:
        import pyglet

        from framework.render import Camera, Renderer

        if self._window is None:
            self._window = pyglet.window.Window(WIDTH, HEIGHT, caption=f"{ENV_ID}: {self.level.name}")
            self._renderer = Renderer(width=WIDTH, height=HEIGHT, window=self._window, background=BACKGROUND,
                                      camera=Camera(target=self.game.state.player, bounds=self.game.state.bounds))
        self._renderer.camera.target = self.game.state.player
        self._renderer.draw(self.game.scene)
        self._window.switch_to()
        self._window.dispatch_events()
        self._window.clear()
        self._renderer.render()
        self._window.flip()


def _level(level: int | str | Path | Level) -> Level:
    if isinstance(level, Level):
        return level
    if isinstance(level, bool) or not isinstance(level, (int, str, Path)):
        raise InvalidValue(f"PlatformerEnv level must be an index, a path or a Level, got {level!r}")
    if isinstance(level, int):
        shipped = builtin_levels()
        if not 0 <= level < len(shipped):
            raise InvalidValue(f"PlatformerEnv level {level} does not exist: there are {len(shipped)} shipped levels "
                               f"(0 to {len(shipped) - 1})")
        return load_level(shipped[level])
    return load_level(level)


def register() -> None:
    """Register ``framework/Platformer-v0`` with Gymnasium (done when this module is imported)."""
    if ENV_ID not in gym.registry:
        gym.register(ENV_ID, entry_point=f"{__name__}:PlatformerEnv")


register()
