"""The example platformer: run, jump, stomp, collect, reach the goal.

``python -m examples.platformer`` plays it in a window; ``--headless --demo`` plays the first level
by itself. Installed (``pip install framework``) it is ``framework.examples.platformer``, with its
levels and images next to its modules. See docs/platformer.md.
"""

from .components import GameState, Tuning
from .game import DT, Game
from .levels import Level, LevelError, builtin_levels, load_level, parse_text, parse_tmj

__all__ = [
    "DT", "Game", "GameState", "Level", "LevelError", "Tuning", "builtin_levels", "load_level", "parse_text",
    "parse_tmj",
]
