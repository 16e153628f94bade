"""The built-in demo: scripted input that plays the first shipped level to its goal.

The script is a generator of key sets, one per step. It reads the game only the way a player
watches the screen (where the player, the enemies and the moving platform are) to time its
presses; the input itself goes through ``Input`` exactly like a keyboard's.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

from framework import Transform

from .components import Enemy, MovingPlatform

__all__ = ["Autoplay", "level1"]

Keys = set[str]
TIMEOUT = 600  # steps any one wait may take before the script gives up on it


def _x(game) -> float:
    return game.player_transform.x / game.state.tile


def run_to(game, x: float, keys: tuple[str, ...] = ("right",)) -> Iterator[Keys]:
    for _ in range(TIMEOUT):
        if _x(game) >= x:
            return
        yield set(keys)


def land(game, keys: tuple[str, ...] = ("right",)) -> Iterator[Keys]:
    for _ in range(TIMEOUT):
        if game.player_state.grounded:
            return
        yield set(keys)


def idle(frames: int, keys: tuple[str, ...] = ()) -> Iterator[Keys]:
    for _ in range(frames):
        yield set(keys)


def jump(frames: int, keys: tuple[str, ...] = ("right",)) -> Iterator[Keys]:
    """Hold jump (and ``keys``) for ``frames`` steps: the longer, the higher (up to a full jump)."""
    for _ in range(frames):
        yield {*keys, "space"}


def jump_from(game, x: float, frames: int = 30, keys: tuple[str, ...] = ("right",)) -> Iterator[Keys]:
    """Run to ``x`` on the ground, jump, and hold ``keys`` until landing."""
    yield from land(game, keys)
    yield from run_to(game, x)
    yield from jump(frames, keys)
    yield from land(game, keys)


def hop_onto(game, x: float, frames: int = 30) -> Iterator[Keys]:
    """Jump from where the player stands, steering right until past ``x``, then drop straight down."""
    yield from land(game, ())
    for i in range(frames):
        yield {"space", "right"} if _x(game) < x else {"space"}
    for _ in range(TIMEOUT):
        if game.player_state.grounded:
            return
        yield {"right"} if _x(game) < x else set()


def stomp(game, near: float = 0.9, far: float = 1.6) -> Iterator[Keys]:
    """Wait for the nearest enemy to walk toward the player from ``near``-``far`` tiles away, then
    jump straight up and come down on it."""
    tile = game.state.tile
    for _ in range(TIMEOUT):
        enemies = [(t.x / tile - _x(game), en.direction) for _e, (en, t) in game.scene.query(Enemy, Transform)]
        if not enemies:
            return
        d, heading = min(enemies, key=lambda e: abs(e[0]))
        if near <= abs(d) <= far and d * heading < 0:
            break
        yield set()
    yield from jump(30, ())
    yield from land(game, ())


def ride(game, board_x: float, leave_x: float) -> Iterator[Keys]:
    """Wait at the pit for the moving platform to come back, jump on, ride, jump off."""
    tile = game.state.tile
    yield from run_to(game, board_x)
    (pe, plat), = game.scene.query(MovingPlatform)
    start_x = plat.start[0] / tile
    for _ in range(2 * TIMEOUT):  # wait until it is back at its start
        t = game.scene.get(pe, Transform)
        if plat.toward_end and abs(t.x / tile - start_x) < 0.3:
            break
        yield set()
    for i in range(40):  # jump on, steering over its middle
        keys = {"space"} if i < 25 else set()
        if _x(game) < game.scene.get(pe, Transform).x / tile - 0.3:
            keys.add("right")
        yield keys
    for _ in range(TIMEOUT):  # ride to the far end
        if game.scene.get(pe, Transform).x / tile >= leave_x:
            break
        yield set()
    yield from jump(40)
    yield from land(game)


def level1(game) -> Iterator[Keys]:
    """Plays ``01-meadow.tmj``: hop, cross the pit, climb the ledges, stomp, ride, climb, goal."""
    yield from jump_from(game, 11.0, 20)        # onto the first block (coins above it)
    yield from jump_from(game, 15.5, 25)        # over the first pit
    yield from jump_from(game, 20.5, 30)        # up the one-way ledges
    yield from jump_from(game, 26.0, 30)
    yield from run_to(game, 32.5)               # down again, over the wall into the pen
    yield from land(game)
    yield from jump_from(game, 33.5, 20)
    yield from stomp(game)                      # the pen's enemy
    yield from jump_from(game, 42.3, 20)        # out of the pen; the checkpoint
    yield from jump_from(game, 49.6, 30)        # over the spikes
    yield from ride(game, 55.6, 65.3)           # the moving platform over the big pit
    yield from stomp(game)                      # the second enemy
    yield from jump_from(game, 75.6, 20)        # the block, the tall block, the high ledge
    yield from hop_onto(game, 78.8)
    yield from hop_onto(game, 81.2)
    yield from jump_from(game, 82.3, 30)        # over to the plateau
    yield from run_to(game, 96.0)               # the goal


class Autoplay:
    """A system that feeds a script's keys into ``Input`` before the game's own systems read it.

    ``script(game)`` is a generator of key sets; when it ends, no keys are held."""

    def __init__(self, script: Callable[..., Iterator[Keys]]) -> None:
        self.script = script
        self._it: Iterator[Keys] | None = None

    def keys(self, game) -> Keys:
        if self._it is None:
            self._it = self.script(game)
        try:
            return next(self._it)
        except StopIteration:
            return set()
