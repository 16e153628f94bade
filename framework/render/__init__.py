"""Rendering with pyglet: the render system, camera, debug overlay, window runner and headless
screenshots. See docs/rendering.md.

This package is the only place the framework imports pyglet, and nothing else in the framework
imports it: ``import framework`` and scenes without a renderer never load pyglet's GL modules.

Without a display (Linux with neither ``DISPLAY`` nor ``WAYLAND_DISPLAY``), importing this package
switches pyglet to headless EGL rendering, unless ``PYGLET_HEADLESS`` is set or pyglet's window
module was already imported. pyglet's shadow window is turned off the same way (the renderer makes
the contexts it needs), unless ``PYGLET_SHADOW_WINDOW`` is set. A window is never opened
invisibly for want of a display: :func:`run` raises :class:`NoDisplayError` (see :mod:`.display`).
"""

from __future__ import annotations

from .display import NoDisplayError, choose_headless

choose_headless()  # before pyglet's window and GL modules load (imported below)

from .camera import Camera  # noqa: E402
from .headless import screenshot  # noqa: E402
from .offscreen import offscreen_window, write_png  # noqa: E402
from .overlay import OVERLAY_COLORS, DebugOverlay  # noqa: E402
from .renderer import Renderer  # noqa: E402
from .window import Runner, key_name, run  # noqa: E402

__all__ = [
    "OVERLAY_COLORS", "Camera", "DebugOverlay", "NoDisplayError", "Renderer", "Runner", "key_name",
    "offscreen_window", "run", "screenshot", "write_png",
]
