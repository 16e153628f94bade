"""The platformer's own components (plain data) and collision layers.

Physics components (``Transform``, ``Velocity``, ``Hitbox``, ``Visual``) come from the framework;
these only mark what an entity *is* to the game and hold its game state.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = [
    "ALL", "BridgePlank", "Checkpoint", "Coin", "ENEMY", "Enemy", "GameState", "Goal", "Hazard", "LevelPiece",
    "MovingPlatform", "ONE_WAY", "PICKUP", "PLAYER", "Player", "SOLID", "SwingRope", "SwingingPlatform", "Tuning",
]

# Collision layers (Hitbox.layer / Hitbox.mask bits).
SOLID = 1 << 0     # solid tiles (static) and solid moving platforms
ONE_WAY = 1 << 1   # one-way tiles and one-way moving platforms
PLAYER = 1 << 2
ENEMY = 1 << 3
PICKUP = 1 << 4    # coins, checkpoints, the goal (sensors)
HAZARD = 1 << 5    # spikes (sensors)
ALL = 0xFFFFFFFF


@dataclass(frozen=True)
class Tuning:
    """How the player moves, in tiles and seconds (scaled by the level's tile size)."""

    gravity: float = 44.0          # tiles/s^2
    run_speed: float = 7.0         # tiles/s
    ground_accel: float = 70.0     # tiles/s^2 toward the target speed on the ground
    air_accel: float = 40.0        # ... in the air
    jump_speed: float = 17.5       # tiles/s: about 3.5 tiles high
    jump_cut: float = 0.45         # releasing jump while rising keeps this fraction of vy
    fall_speed: float = 18.0       # tiles/s, terminal
    coyote_time: float = 0.1       # s after leaving the ground a jump still works
    jump_buffer: float = 0.12      # s a jump pressed before landing is remembered
    stomp_bounce: float = 12.0     # tiles/s up after stomping an enemy (jump held: jump_speed)
    drop_time: float = 0.2         # s the one-way layer stays out of the mask after down+jump
    player_size: tuple[float, float] = (0.75, 0.875)  # tiles
    enemy_size: tuple[float, float] = (0.75, 0.6875)
    coin_radius: float = 0.25
    crate_size: float = 0.875      # tiles (a square)
    crate_mass: float = 2.0        # the player's is 1
    barrel_radius: float = 0.375   # tiles
    prop_friction: float = 0.6     # crates and barrels
    step_height: float = 0.3       # tiles: the player and walkers walk up steps this high
    push_mass: float = 1.0         # the player pushes crates and barrels, and weighs on bridges, as a body of this mass
    plank_mass: float = 0.25       # a bridge plank's (a bridge's ``mass`` property overrides it)


@dataclass
class Player:
    """The player's control state (the body itself is Transform + Velocity + Hitbox)."""

    grounded: bool = False
    ground: int | None = None        # the entity stood on after the last step
    since_ground: float = 1e9        # s since last grounded (coyote time)
    since_jump_press: float = 1e9    # s since jump was pressed (jump buffer)
    jumping: bool = False            # rising from a jump (releasing cuts it)
    drop_timer: float = 0.0          # > 0: falling through one-way platforms
    facing: int = 1
    prev_bottom: float = 0.0         # where the feet were when the step started (stomps)
    dead_frame: int = -1             # the frame the player last died (one death per frame)


@dataclass
class Enemy:
    """A walker that turns at walls and ledges; dies when stomped."""

    speed: float                     # world units/s
    direction: int = -1
    prev_top: float = 0.0
    turned_frame: int = -1


@dataclass
class MovingPlatform:
    """A kinematic platform going back and forth between ``start`` and ``end`` at ``speed``."""

    start: tuple[float, float]
    end: tuple[float, float]
    speed: float
    pause: float = 0.5                       # s it waits at each end
    toward_end: bool = True
    waiting: float = 0.0


@dataclass
class SwingingPlatform:
    """A kinematic board hanging from ``pivot`` on a rope ``length`` long (world units), swinging
    as a pendulum: at time ``t`` its angle from straight down is ``theta(t) = amplitude *
    sin(2 pi t / period + phase)`` (radians, counter-clockwise), its centre is ``pivot + length *
    (sin theta, -cos theta)`` and it is turned by ``theta`` (the board tilts with its rope).
    ``time`` is the swing's clock, advanced by :func:`.systems.swing_platforms` each step."""

    pivot: tuple[float, float]
    length: float
    amplitude: float                         # radians, the largest angle
    period: float                            # s
    phase: float = 0.0                       # radians
    time: float = 0.0

    def angle(self, t: float) -> float:
        """theta(t), radians from straight down (counter-clockwise: the board swung to the right)."""
        return self.amplitude * math.sin(2.0 * math.pi * t / self.period + self.phase)

    def pose(self, t: float) -> tuple[float, float, float]:
        """The board's centre and rotation at time ``t``: ``(x, y, theta)``."""
        theta = self.angle(t)
        return (self.pivot[0] + self.length * math.sin(theta), self.pivot[1] - self.length * math.cos(theta),
                theta)


@dataclass
class SwingRope:
    """The drawn rope of a swing (no collisions): a thin box from the pivot down to the board,
    turned with it."""

    swing: SwingingPlatform


@dataclass
class BridgePlank:
    """Plank ``index`` (from the left, 0 to ``planks - 1``) of a rope bridge: a dynamic board hinged
    to its neighbours (the end ones to the anchors) by ``RevoluteJoint``s. Whoever stands on it
    weighs on it (:func:`.systems.weigh_on_bridges`)."""

    index: int
    planks: int


@dataclass
class Coin:
    value: int = 1


@dataclass
class Hazard:
    pass


@dataclass
class Goal:
    pass


@dataclass
class Checkpoint:
    active: bool = False


@dataclass
class LevelPiece:
    """Marks every entity a level spawned (despawned when the level is left)."""

    kind: str = ""


@dataclass
class GameState:
    """The game's progress, a scene resource (``scene.resources[GameState]``)."""

    level_index: int = 0
    level_name: str = ""
    tile: float = 32.0
    art: bool = False                 # the level is drawn with the tile images (see art.py)
    coins: int = 0                    # collected in the whole run
    coins_in_level: int = 0
    coin_total_in_level: int = 0
    deaths: int = 0
    reached_goal: bool = False        # a goal was reached in this run
    level_done: bool = False          # the current level's goal was reached
    levels_completed: int = 0
    finished: bool = False            # the last level was completed
    checkpoint: tuple[float, float] = (0.0, 0.0)  # respawn point (feet)
    player: int | None = None
    bounds: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    camera: tuple[float, float] = (0.0, 0.0)      # where the camera looks (world)
    view: tuple[float, float] = (960.0, 540.0)    # world size the camera shows
    pending: str | None = None         # "restart" / "next": a level change asked for
    pending_stage: int = 0
    goal_timer: float = 0.0
    stomps: int = 0
