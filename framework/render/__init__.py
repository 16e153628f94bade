"""Rendering with pyglet: the render system, camera, debug overlay, window runner and headless
screenshots. See docs/rendering.md.

This package is the only place the framework imports pyglet, and nothing else in the framework
imports it: ``import framework`` and scenes without a renderer never load pyglet's GL modules.

Without a display (Linux with neither ``DISPLAY`` nor ``WAYLAND_DISPLAY``), importing this package
switches pyglet to headless EGL rendering, unless ``PYGLET_HEADLESS`` is set or pyglet's window
module was already imported. pyglet's shadow window is turned off the same way (the renderer makes
the contexts it needs), unless ``PYGLET_SHADOW_WINDOW`` is set.
"""

from __future__ import annotations

import os
import sys

import pyglet as _pyglet

if "pyglet.window" not in sys.modules and "pyglet.gl" not in sys.modules:
    if "PYGLET_HEADLESS" not in os.environ and sys.platform.startswith("linux") \
            and not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        _pyglet.options["headless"] = True
    if "PYGLET_SHADOW_WINDOW" not in os.environ:
        _pyglet.options["shadow_window"] = False

from .camera import Camera  # noqa: E402
from .headless import screenshot  # noqa: E402
from .offscreen import offscreen_window, write_png  # noqa: E402
from .overlay import OVERLAY_COLORS, DebugOverlay  # noqa: E402
from .renderer import Renderer  # noqa: E402
from .window import Runner, key_name, run  # noqa: E402

__all__ = [
    "OVERLAY_COLORS", "Camera", "DebugOverlay", "Renderer", "Runner", "key_name", "offscreen_window", "run",
    "screenshot", "write_png",
]
