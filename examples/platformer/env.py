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
from numpy.typing import NDArray

from framework import Hitbox, Transform, Velocity
from framework.collision.kinds import KIND_AABB
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

    metadata: dict[str, Any] = {"render_modes": ["human", "rgb_array"], "render_fps": 15}

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
        # Exact zeros along the axes (cos(pi / 2) is 6e-17), so the slab test sees them as such.
        self._dir_x = np.array([0.0 if abs(c) < 1e-12 else c for c, _ in self._directions])
        self._dir_y = np.array([0.0 if abs(s) < 1e-12 else s for _, s in self._directions])
        self._channels: dict[int, int] = {}
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

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None,
    ) -> tuple[NDArray[np.float32], dict[str, Any]]:
        super().reset(seed=seed)
        self.game.scene.restore(self._start)
        self._channels.clear()
        self._frames = 0
        self._best_x = self._player_x()
        return self._observe(), self._info()

    def step(self, action: Any) -> tuple[NDArray[np.float32], float, bool, bool, dict[str, Any]]:
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

    def render(self) -> NDArray[np.uint8] | None:
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

    def _observe(self) -> NDArray[np.float32]:
        game, scene = self.game, self.game.scene
        state, tile = game.state, self.level.tile
        obs = np.ones(PLAYER_VALUES + 3 * self.rays, dtype=np.float32)
        player = state.player
        if player is None:
            return obs
        t, v, p = scene.get(player, Transform), scene.get(player, Velocity), game.player_state
        width, height = self.level.size
        fall = self.tuning.fall_speed * tile
        obs[:PLAYER_VALUES] = (2.0 * t.x / width - 1.0, 2.0 * t.y / height - 1.0, v.x / fall, v.y / fall,
                               1.0 if p.grounded else -1.0, float(p.facing))
        obs[PLAYER_VALUES:] = self._rays(t.x, t.y, player).reshape(-1)
        return np.clip(obs, -1.0, 1.0)

    def _rays(self, ox: float, oy: float, player: int) -> NDArray[np.float64]:
        """``(3, rays)``: per channel (solid, danger, pickup) and ray, the distance over the range
        to the nearest such thing the ray meets before any solid one (1: none). Boxes (most of a
        level) are met by one vectorised slab test for every ray at once; other shapes by
        :func:`framework.collision.raycast`."""
        from framework.collision import raycast

        scene, reach = self.game.scene, self._range
        bodies = scene.bodies  # the read-only surface (docs/rendering.md): the store and its geometry
        store, geom = bodies.store, bodies.ensure_geometry()
        n = store.n
        near = ((geom.minx[:n] < ox + reach) & (geom.maxx[:n] > ox - reach) & (geom.miny[:n] < oy + reach)
                & (geom.maxy[:n] > oy - reach) & (store.kind[:n] >= 0)
                & ((store.layer[:n] & (SOLID | ONE_WAY | ENEMY | HAZARD | PICKUP)) != 0)
                & (store.entity[:n] != player))
        rows = np.flatnonzero(near)
        channels = np.array([self._channel_of(int(e)) for e in store.entity[rows].tolist()], dtype=np.int64)
        keep = channels >= 0
        rows, channels = rows[keep], channels[keep]
        dist = np.full((3, self.rays), np.inf)
        box = store.kind[rows] == KIND_AABB
        for r, channel in zip(rows[~box].tolist(), channels[~box].tolist()):
            shape = store.hitboxes[r].shape  # (rows with kind >= 0 have one)
            pose = (float(geom.hx[r]), float(geom.hy[r]), float(store.rot[r]))
            for i, direction in enumerate(self._directions):
                ray = raycast(shape, pose, (ox, oy), direction, reach)
                if ray is not None and ray.distance < dist[channel, i]:
                    dist[channel, i] = ray.distance
        br = rows[box]
        if br.size:
            b = np.stack([geom.hx[br], geom.hy[br], store.hw[br], store.hh[br], channels[box]], axis=1)
            dx, dy = self._dir_x[:, None], self._dir_y[:, None]
            with np.errstate(divide="ignore", invalid="ignore"):
                tx1, tx2 = (b[:, 0] - b[:, 2] - ox) / dx, (b[:, 0] + b[:, 2] - ox) / dx
                ty1, ty2 = (b[:, 1] - b[:, 3] - oy) / dy, (b[:, 1] + b[:, 3] - oy) / dy
            # A ray along an axis: inside the slab is all of time, outside it none.
            inx = (np.abs(ox - b[:, 0]) < b[:, 2])[None, :]
            iny = (np.abs(oy - b[:, 1]) < b[:, 3])[None, :]
            lox = np.where(dx == 0.0, np.where(inx, -np.inf, np.inf), np.minimum(tx1, tx2))
            hix = np.where(dx == 0.0, np.where(inx, np.inf, -np.inf), np.maximum(tx1, tx2))
            loy = np.where(dy == 0.0, np.where(iny, -np.inf, np.inf), np.minimum(ty1, ty2))
            hiy = np.where(dy == 0.0, np.where(iny, np.inf, -np.inf), np.maximum(ty1, ty2))
            enter, leave = np.maximum(lox, loy), np.minimum(hix, hiy)
            hit = (enter < leave) & (leave > 0.0) & (enter <= reach)
            d = np.where(hit, np.maximum(enter, 0.0), np.inf)
            for channel in range(3):
                mine = b[:, 4] == channel
                if mine.any():
                    dist[channel] = np.minimum(dist[channel], d[:, mine].min(axis=1))
        dist[1:] = np.where(dist[1:] < dist[0], dist[1:], np.inf)  # nothing behind a wall is seen
        return np.where(np.isfinite(dist), dist / reach, 1.0)

    def _channel_of(self, entity: int) -> int:
        """:meth:`_channel`, remembered per entity for the episode (-1: none)."""
        channel = self._channels.get(entity)
        if channel is None:
            found = self._channel(entity)
            channel = self._channels[entity] = -1 if found is None else found
        return channel

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
        from pyglet import gl

        from framework.render import Camera, Renderer

        if self._window is None:
            self._window = pyglet.window.Window(WIDTH, HEIGHT, caption=f"{ENV_ID}: {self.level.name}")
            self._renderer = Renderer(width=WIDTH, height=HEIGHT, window=self._window, background=BACKGROUND,
                                      camera=Camera(target=self.game.state.player, bounds=self.game.state.bounds))
        self._renderer.camera.target = self.game.state.player
        self._renderer.draw(self.game.scene)
        self._window.switch_to()
        self._window.dispatch_events()
        r, g, b = (c / 255.0 for c in BACKGROUND)
        gl.glClearColor(r, g, b, 1.0)  # (as the window runner does; else black)
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
    """Register ``framework/Platformer-v0`` with Gymnasium (done when this module is imported).

    ``gym.make("framework.examples.platformer.env:framework/Platformer-v0")`` imports this module
    by itself, so a script needs no import but Gymnasium's (Gymnasium 1.x has no plugin entry
    points that could register it on Gymnasium's import; see docs/headless.md)."""
    if ENV_ID not in gym.registry:
        gym.register(ENV_ID, entry_point=f"{__name__}:PlatformerEnv")


register()
