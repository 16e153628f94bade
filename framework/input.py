"""Keyboard input as a scene resource, so game systems read it without globals.

The window runner (or a test, or a replay) feeds key presses and releases; systems read
``scene.resources[Input]``. Keys are plain lower-case names (``"left"``, ``"space"``, ``"a"``,
``"f1"``), independent of pyglet, so headless tests drive a game exactly as a keyboard would.
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = ["Input"]


class Input:
    """Which keys are held, and which went down or up since the last step."""

    def __init__(self) -> None:
        self.held: set[str] = set()
        self.pressed: set[str] = set()   # went down since the last step
        self.released: set[str] = set()  # went up since the last step

    def press(self, key: str) -> None:
        if key not in self.held:
            self.held.add(key)
            self.pressed.add(key)

    def release(self, key: str) -> None:
        if key in self.held:
            self.held.discard(key)
            self.released.add(key)

    def set_held(self, keys: Iterable[str]) -> None:
        """Make exactly ``keys`` held (for scripted input): presses and releases follow."""
        keys = set(keys)
        for k in sorted(self.held - keys):
            self.release(k)
        for k in sorted(keys - self.held):
            self.press(k)

    def end_step(self) -> None:
        """Forget this step's edges (the scene calls this after each step)."""
        self.pressed.clear()
        self.released.clear()

    def is_held(self, *keys: str) -> bool:
        return any(k in self.held for k in keys)

    def was_pressed(self, *keys: str) -> bool:
        return any(k in self.pressed for k in keys)

    def was_released(self, *keys: str) -> bool:
        return any(k in self.released for k in keys)
