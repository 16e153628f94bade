"""Whether a window can be seen here: headless EGL where there is no display, and saying so.

Where there is no display (Linux with neither ``DISPLAY`` nor ``WAYLAND_DISPLAY``), importing
:mod:`framework.render` switches pyglet to headless EGL rendering (:func:`choose_headless`), so
screenshots and tests work. A window opened then would be invisible: the window runner asks
:func:`no_display_reason` first and raises :class:`NoDisplayError` instead of running an invisible
window that nobody can see or close. Headless asked for by the user (``PYGLET_HEADLESS=1``, or
``pyglet.options["headless"]`` set before importing :mod:`framework.render`) is not refused.

The lowest layer of the render package, with :mod:`.offscreen`: it imports nothing from it.
"""

from __future__ import annotations

import os
import sys

import pyglet

__all__ = ["NoDisplayError", "choose_headless", "no_display_reason", "no_window_line", "open_failure"]

_chose_headless = False  # True once choose_headless switched pyglet to headless for want of a display


class NoDisplayError(RuntimeError):
    """No display to show a window on. The message is one line: why, and what to do instead."""


def _linux_without_display() -> bool:
    return sys.platform.startswith("linux") and not os.environ.get("DISPLAY") \
        and not os.environ.get("WAYLAND_DISPLAY")


def choose_headless() -> None:
    """Before pyglet's window or GL modules are imported: headless EGL rendering where there is no
    display (unless ``PYGLET_HEADLESS`` is set either way), and no shadow window (unless
    ``PYGLET_SHADOW_WINDOW`` is set). Does nothing once pyglet's window or GL modules are loaded."""
    global _chose_headless
    if "pyglet.window" in sys.modules or "pyglet.gl" in sys.modules:
        return
    if "PYGLET_HEADLESS" not in os.environ and not pyglet.options["headless"] and _linux_without_display():
        pyglet.options["headless"] = True
        _chose_headless = True
    if "PYGLET_SHADOW_WINDOW" not in os.environ:
        pyglet.options["shadow_window"] = False


def no_display_reason() -> str | None:
    """Why a visible window cannot be opened here, in a few words; ``None`` when it can (as far as
    can be told without opening one: see :func:`open_failure` for a display that fails to open)."""
    if _chose_headless and pyglet.options["headless"]:
        return "no display (neither DISPLAY nor WAYLAND_DISPLAY is set)"
    return None


def no_window_line(reason: object, module: str) -> str:
    """The one line a ``python -m module`` command with a window says where none can be shown: why,
    and how to run it instead (the examples' play commands)."""
    return (f"error: {reason}. Play with a display (set DISPLAY), or without a window: "
            f"python -m {module} --headless --demo")


def open_failure(exc: BaseException) -> str | None:
    """Why opening a window failed, in a few words, when ``exc`` says the display could not be
    opened (pyglet raises ``NoSuchDisplayException``, of a class per platform); else ``None``."""
    if type(exc).__name__ != "NoSuchDisplayException":
        return None
    # (pyglet's own message names no display on Linux: "Cannot connect to None".)
    shown = os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    return f"cannot open the display {shown!r}" if shown else "cannot open a display"
