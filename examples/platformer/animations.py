"""The platformer's animations: sprite sheets made by ``art.py``, cut into frames and timed.

The player idles, runs and jumps (its sheet faces right; the renderer mirrors it with
``Visual.flip_x``), walkers step, coins turn. :func:`animate` (a game system) picks the player's
animation from its state each step; frames follow the scene's clock, so replays and headless runs
show the same frames.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

from framework.sprites import Animation, SpriteSheet

__all__ = ["IMAGES", "SHEETS", "animations"]

IMAGES = Path(__file__).with_name("images")
SHEETS = ("player_sheet", "enemy_sheet", "coin_sheet")


@cache
def animations() -> dict[str, Animation]:
    """``idle``, ``run``, ``jump`` (the player), ``walk`` (walkers) and ``coin``."""
    player = SpriteSheet(IMAGES / "player_sheet.png", 24, 28)
    enemy = SpriteSheet(IMAGES / "enemy_sheet.png", 24, 22)
    coin = SpriteSheet(IMAGES / "coin_sheet.png", 16, 16)
    return {
        "idle": player.animation([0, 1], 0.5),
        "run": player.animation([2, 3, 4, 5], 0.1),
        "jump": player.animation([6], 1.0, loop=False),
        "walk": enemy.animation([0, 1], 0.2),
        "coin": coin.animation([0, 1, 2, 3], 0.125),
    }
