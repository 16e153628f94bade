"""The on-screen HUD: coins, deaths and the level as :class:`~framework.text.Text` components.

Screen texts (a corner of the view, untouched by the camera) on entities of their own, which no
level owns, so they stay through level changes and restarts; one system rewrites them from the
:class:`~.components.GameState` after each step (a text written unchanged costs nothing).

The window and ``--screenshot`` runs install it (:func:`install_hud`); plain headless runs, the
tests and the Gymnasium environment do not, so their scenes hold only the level's entities.
"""

from __future__ import annotations

from typing import Any

from framework.text import Text

from .components import GameState

__all__ = ["HUD_COLOR", "HUD_SIZE", "MESSAGE_SIZE", "hud_texts", "install_hud"]

HUD_SIZE = 14.0  # points
MESSAGE_SIZE = 24.0
HUD_COLOR = (255, 255, 255)
MARGIN = 12.0  # pixels from the view's edges


def hud_texts(state: GameState, levels: int) -> dict[str, str]:
    """What the HUD says: ``coins`` of this level, ``deaths``, the ``level`` (number of ``levels``
    and name), and a ``message`` ("" for none)."""
    if state.finished:
        message = "All levels done! R replays the last one"
    elif state.level_done:
        message = "Level complete!"
    else:
        message = ""
    return {
        "coins": f"coins {state.coins_in_level}/{state.coin_total_in_level}",
        "deaths": f"deaths {state.deaths}",
        "level": f"level {state.level_index + 1}/{levels}: {state.level_name}",
        "message": message,
    }


def install_hud(game: Any) -> dict[str, int]:
    """Spawn the HUD's texts in ``game.scene`` and the system that keeps them up to date; the
    entity of each text by name (``coins``, ``deaths``, ``level``, ``message``)."""
    scene = game.scene

    def top(corner: str, offset: tuple[float, float], anchor_x: str = "left") -> Text:
        return Text(screen=True, size=HUD_SIZE, color=HUD_COLOR, corner=corner, offset=offset, anchor_x=anchor_x,
                    anchor_y="top", z=1)

    entities = {
        "coins": scene.spawn(top("top_left", (MARGIN, -MARGIN))),
        "deaths": scene.spawn(top("top_left", (MARGIN, -MARGIN - 1.6 * HUD_SIZE))),
        "level": scene.spawn(top("top_right", (-MARGIN, -MARGIN), "right")),
        "message": scene.spawn(Text(screen=True, size=MESSAGE_SIZE, color=HUD_COLOR, corner="center",
                                    offset=(0.0, 60.0), anchor_x="center", anchor_y="center", z=1)),
    }
    texts = {name: scene.get(e, Text) for name, e in entities.items()}

    def update_hud(scene: Any, dt: float) -> None:
        for name, line in hud_texts(game.state, len(game.levels)).items():
            texts[name].text = line

    scene.add_system(update_hud, after="response")
    update_hud(scene, 0.0)  # the first frame shows it before any step
    return entities
