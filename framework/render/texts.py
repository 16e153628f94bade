"""The labels of a scene's :class:`~framework.text.Text` components: pyglet labels, batched.

One label per entity with a visible, non-empty ``Text``, in one of two batches: world texts (drawn
with the camera's view, so they move and zoom with the world) and screen texts (drawn with the
identity view: a HUD). A label is made again only when its ``Text`` changed (its ``version``) and
moved when its entity or the view did; texts are few (a HUD, a few names), so they are visited one
by one each frame shown, not column-wise like the sprites.
"""

from __future__ import annotations

from typing import Any

import pyglet
from pyglet.graphics import Batch, Group

from ..components import Transform
from ..text import Text

__all__ = ["TextLabels", "screen_position"]


def screen_position(text: Text, width: int, height: int) -> tuple[float, float]:
    """Where a screen text sits in a ``width`` x ``height`` view (pixels, y up): its corner plus
    its offset."""
    corner = text.corner
    cx = 0.5 * width if corner == "center" else (float(width) if corner.endswith("right") else 0.0)
    cy = 0.5 * height if corner == "center" else (float(height) if corner.startswith("top") else 0.0)
    return cx + text.offset[0], cy + text.offset[1]


class TextLabels:
    """The labels of a scene's texts (:meth:`sync`), drawn by :meth:`draw_world` and
    :meth:`draw_screen`. Needs the GL context it was first used in to be current."""

    def __init__(self) -> None:
        self._world = Batch()
        self._screen = Batch()
        self._groups: dict[tuple[bool, int], Group] = {}
        # entity -> (label, the Text it shows, the Text's version then)
        self._labels: dict[int, tuple[Any, Text, int]] = {}

    def __len__(self) -> int:
        return len(self._labels)

    def _group(self, screen: bool, z: int) -> Group:
        group = self._groups.get((screen, z))
        if group is None:
            group = self._groups[(screen, z)] = Group(order=z)
        return group

    def sync(self, scene: Any, width: int, height: int) -> None:
        """Bring the labels in line with ``scene.query(Text)`` in a ``width`` x ``height`` view:
        make, remake, move or delete them. A world text whose entity has no Transform is not drawn."""
        seen: set[int] = set()
        for entity, text in scene.query(Text):
            if not text.visible or not text.text:
                continue
            if text.screen:
                x, y = screen_position(text, width, height)
            else:
                transform = scene.try_get(entity, Transform)
                if transform is None:
                    continue
                x, y = transform.x + text.offset[0], transform.y + text.offset[1]
            seen.add(entity)
            had = self._labels.get(entity)
            if had is not None and had[1] is text and had[2] == text.version:
                label = had[0]
                if label.position[:2] != (x, y):
                    label.position = (x, y, 0.0)
                continue
            if had is not None:
                had[0].delete()
            label = pyglet.text.Label(
                text.text, x=x, y=y, font_name=text.font, font_size=text.size, color=text.color,
                anchor_x=text.anchor_x, anchor_y=text.anchor_y,
                batch=self._screen if text.screen else self._world, group=self._group(text.screen, text.z))
            self._labels[entity] = (label, text, text.version)
        for entity in [e for e in self._labels if e not in seen]:
            self._labels.pop(entity)[0].delete()

    def draw_world(self) -> None:
        """Draw the world texts (the camera's view must be set)."""
        self._world.draw()

    def draw_screen(self) -> None:
        """Draw the screen texts (the identity view must be set)."""
        self._screen.draw()

    def delete(self) -> None:
        """Delete every label (made again by the next :meth:`sync`)."""
        for label, _text, _version in self._labels.values():
            label.delete()
        self._labels.clear()
