"""The built-in demo: scripted input that plays the first shipped level to its goal.

The script is a generator of key sets, one per step. It reads the game only the way a player
watches the screen (where the player, the enemies and the moving platform are) to time its
presses; the input itself goes through ``Input`` exactly like a keyboard's.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

from framework import Transform

from .components import Enemy, MovingPlatform, SwingingPlatform

__all__ = ["Autoplay", "SCRIPTS", "hop_up", "level1", "level2", "level3", "level4", "level5", "play_all"]

Keys = set[str]
TIMEOUT = 600  # steps any one wait may take before the script gives up on it
JUMP_ONTO = 42  # steps a full jump takes to come down onto a board a tile and a half up


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
    for _ in range(frames):
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
        enemies = [(t.x / tile - _x(game), en.direction)
                   for _e, (en, t) in game.scene.query(Enemy, Transform)]
        if not enemies:
            return
        d, heading = min(enemies, key=lambda e: abs(e[0]))
        if near <= abs(d) <= far and d * heading < 0:
            break
        yield set()
    yield from jump(30, ())
    yield from land(game, ())


def ride(game, board_x: float) -> Iterator[Keys]:
    """Wait at the pit for the moving platform to stop at its start, jump on, ride it to its end,
    jump off."""
    tile = game.state.tile
    yield from run_to(game, board_x)
    (pe, plat), = game.scene.query(MovingPlatform)
    for _ in range(2 * TIMEOUT):
        if plat.toward_end and plat.waiting > 0.0:
            break
        yield set()
    for i in range(40):  # jump on, steering over its middle
        keys = {"space"} if i < 25 else set()
        if _x(game) < game.scene.get(pe, Transform).x / tile - 0.3:
            keys.add("right")
        yield keys
    for _ in range(2 * TIMEOUT):  # ride to the far end
        if not plat.toward_end:
            break
        yield set()
    yield from jump(40)
    yield from land(game)


def lift(game, step_off_x: float) -> Iterator[Keys]:
    """Wait for the lift (the level's moving platform) to stop at its start, walk on, ride it to
    its end, walk off to ``step_off_x``."""
    tile = game.state.tile
    (pe, plat), = game.scene.query(MovingPlatform)
    for _ in range(2 * TIMEOUT):
        if plat.toward_end and plat.waiting > 0.0:
            break
        yield set()
    for _ in range(TIMEOUT):  # on to its middle
        if _x(game) >= plat.start[0] / tile:
            break
        yield {"right"}
    for _ in range(2 * TIMEOUT):
        if not plat.toward_end and plat.waiting > 0.0:  # arrived at the end
            break
        yield set()
    yield from run_to(game, step_off_x)


def swing(game, edge_x: float) -> Iterator[Keys]:
    """Cross a pit on the swing over it. Walk to ``edge_x`` (the pit's edge) and watch the board
    (the nearest ahead) swing once: the steps it takes from its far end to its near end. Then, as
    it leaves the far end again, wait until a jump's fall from now would meet it at the near end,
    and jump on, steering over its middle; ride without a key held until it comes to the far end
    and jump off toward the far side."""
    tile = game.state.tile
    yield from land(game, ("right",))
    yield from run_to(game, edge_x)
    boards = [(game.scene.get(e, Transform).x / tile, e) for e, _sw in game.scene.query(SwingingPlatform)]
    _bx, be = min((b for b in boards if b[0] > _x(game)), default=min(boards))
    board = game.scene.get(be, Transform)

    def until_it_turns(way: float) -> Iterator[Keys]:
        """Until the board, moving the other way (or at rest), moves ``way`` (+1 right, -1 left)."""
        last = board.x
        for _ in range(2 * TIMEOUT):
            moved, last = board.x - last, board.x
            if moved * way > 0.0:
                return
            yield set()

    yield from until_it_turns(+1.0)     # (somewhere in its swing: to the far end, then back)
    yield from until_it_turns(-1.0)     # it left the far end
    start = game.scene.frame
    yield from until_it_turns(+1.0)     # and came to the near end: half a swing
    half = game.scene.frame - start
    yield from until_it_turns(-1.0)     # it leaves the far end again
    yield from idle(max(0, half - JUMP_ONTO))
    for i in range(60):  # jump on, steering over its middle
        keys = {"space"} if i < 25 else set()
        if _x(game) < board.x / tile - 0.2:
            keys.add("right")
        yield keys
        if i > 5 and game.player_state.grounded:
            break
    yield from land(game, ())
    yield from until_it_turns(+1.0)     # ride it across: from the near end...
    yield from until_it_turns(-1.0)     # ...until it stops at the far end
    yield from jump(40)
    yield from land(game)


def drop(game) -> Iterator[Keys]:
    """Down + jump: fall through the one-way platform underfoot, then land on whatever is below."""
    yield from land(game, ())
    yield {"down"}
    yield {"down", "space"}
    for _ in range(10):
        yield {"down"}
    yield from land(game, ())


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
    yield from ride(game, 55.6)           # the moving platform over the big pit
    yield from stomp(game)                      # the second enemy
    yield from jump_from(game, 75.6, 20)        # the block, the tall block, the high ledge
    yield from hop_onto(game, 78.8)
    yield from hop_onto(game, 81.2)
    yield from jump_from(game, 82.3, 30)        # over to the plateau
    yield from run_to(game, 96.0)               # the goal


def level2(game) -> Iterator[Keys]:
    """Plays ``02-caverns.tmj``: spikes, a walker, the lift, two more walkers, the drop room."""
    yield from jump_from(game, 7.3, 30)         # over the spikes
    yield from stomp(game)
    yield from jump_from(game, 18.5, 25)        # the one-way ledge, then the raised floor
    yield from hop_onto(game, 24.5)
    yield from run_to(game, 31.0)
    yield from lift(game, 37.5)                 # up the shaft
    yield from stomp(game)
    yield from jump_from(game, 46.3, 25)        # over the bump
    yield from stomp(game)
    yield from run_to(game, 64.0)               # down through the drop room's one-way floors
    for _ in range(4):
        yield from drop(game)
    yield from run_to(game, 75.5)               # out of the door, over the spikes
    yield from jump_from(game, 75.6, 30)
    yield from stomp(game)
    yield from jump_from(game, 84.5, 25)        # onto the goal's block
    yield from run_to(game, 87.0)


def level3(game) -> Iterator[Keys]:
    """Plays ``03-hills.tmj``: up a 2:1 and a 45-degree slope, over the hill, through the V, the
    lift over the pit, a walker, the wall before the goal."""
    yield from jump_from(game, 16.0, 20)        # the coins over the hilltop
    yield from jump_from(game, 31.6, 22)        # the coins over the V
    yield from run_to(game, 40.3)               # the pit's edge
    yield from lift(game, 50.5)
    yield from stomp(game)
    yield from jump_from(game, 56.8, 30)        # over the wall
    yield from run_to(game, 62.0)


def level4(game) -> Iterator[Keys]:
    """Plays ``04-swings.tmj``: three pits, each crossed on a swing (longer ropes, wider pits),
    the coins on the way and at the bottom of each swing, the checkpoint, the goal."""
    yield from swing(game, 9.5)
    yield from swing(game, 25.5)
    yield from swing(game, 43.5)
    yield from run_to(game, 64.0)               # the coins, the goal


def hop_up(game, x: float, frames: int = 20) -> Iterator[Keys]:
    """Run right to just before ``x``, jump straight up (through what hangs over ``x``) and land."""
    yield from land(game)
    yield from run_to(game, x - 0.3)
    yield from jump(frames, ())
    yield from land(game, ())


def level5(game) -> Iterator[Keys]:
    """Plays ``05-bridge.tmj``: across the two rope bridges, hopping straight up over the middle of
    the first and twice on the second for the coins over them (the deck sags under the player and
    sways a little: the hops are taken from wherever it is), the checkpoint between them, the goal."""
    yield from hop_up(game, 13.5)               # the first bridge's coins
    yield from hop_up(game, 33.5)               # the second bridge's two pairs
    yield from hop_up(game, 38.5)
    yield from run_to(game, 58.0)               # the coins, the goal


SCRIPTS = (level1, level2, level3, level4, level5)


def play_all(game) -> Iterator[Keys]:
    """The scripts of the shipped levels, one after the other (holding nothing in between)."""
    for index, script in enumerate(SCRIPTS):
        while game.state.level_index != index or game.state.player is None:
            if game.state.finished:
                return
            yield set()
        yield from script(game)
        while not game.state.reached_goal or game.state.levels_completed <= index:
            yield set()


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
