"""Screenshots of a scene without a display, pixel-exact.

:func:`screenshot` draws the scene as it is now with a fresh :class:`~.renderer.Renderer` in the
hidden offscreen window's GL context (:mod:`.offscreen`) and reads the pixels back. Without a
display, set ``PYGLET_HEADLESS=1`` (EGL, e.g. Mesa's llvmpipe) before pyglet's window or GL
modules are imported; :mod:`framework.render` does so itself on Linux when neither ``DISPLAY`` nor
``WAYLAND_DISPLAY`` is set.
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np

from .camera import Camera
from .offscreen import offscreen_window, read_pixels, write_png
from .renderer import Renderer

__all__ = ["offscreen_window", "read_pixels", "screenshot", "write_png"]


def screenshot(
    scene: Any,
    path: str | Path | None = None,
    *,
    width: int = 640,
    height: int = 360,
    camera: Camera | None = None,
    debug: bool = False,
    background: tuple[int, int, int] = (0, 0, 0),
) -> np.ndarray:
    """Render the scene as it is now into a ``(height, width, 4)`` uint8 RGBA array, top row
    first, and write it as a PNG when ``path`` is given.

    ``camera``: the view (default: a copy of the attached renderer's camera if there is one,
    else world coordinates as pixels); it is updated (target, bounds) as a frame would. ``debug``:
    draw the overlay (it shows the last step's contacts, rays and timings). The scene is not
    stepped and its own renderer, if any, is not touched."""
    if camera is None:
        attached = scene.renderer
        camera = copy.copy(attached.camera) if isinstance(attached, Renderer) else Camera()
    renderer = Renderer(width=width, height=height, camera=camera, debug=debug, background=background,
                        window=offscreen_window())
    try:
        renderer.draw(scene)
        return renderer.capture(None if path is None else str(path))
    finally:
        renderer.close()
