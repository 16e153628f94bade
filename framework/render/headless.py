"""Offscreen rendering: screenshots of a scene without a display, pixel-exact.

A hidden pyglet window supplies the GL context (one per process, made on first use). Frames are
drawn into an RGBA8 texture attached to a :class:`pyglet.image.Framebuffer`, not into the window:
the headless default framebuffer is RGB565, which would round every colour. Without a display,
set ``PYGLET_HEADLESS=1`` (EGL, e.g. Mesa's llvmpipe) before pyglet's window or GL modules are
imported; :mod:`framework.render` does so itself on Linux when neither ``DISPLAY`` nor
``WAYLAND_DISPLAY`` is set.
"""

from __future__ import annotations

import copy
import struct
import zlib
from pathlib import Path
from typing import Any

import numpy as np
import pyglet
from pyglet import gl

from .camera import Camera

__all__ = ["offscreen_window", "read_pixels", "screenshot", "write_png"]

_offscreen: Any = None


def offscreen_window() -> Any:
    """The hidden window whose GL context offscreen rendering uses (made on first call)."""
    global _offscreen
    if _offscreen is None or _offscreen.context is None:
        _offscreen = pyglet.window.Window(16, 16, visible=False, caption="framework offscreen")
    return _offscreen


def read_pixels(width: int, height: int) -> np.ndarray:
    """The bound framebuffer's ``width`` x ``height`` pixels as ``(height, width, 4)`` uint8, top
    row first (GL's rows come bottom-up), alpha set to 255 (a screen is opaque)."""
    buf = np.empty((height, width, 4), dtype=np.uint8)
    gl.glPixelStorei(gl.GL_PACK_ALIGNMENT, 1)
    gl.glReadPixels(0, 0, width, height, gl.GL_RGBA, gl.GL_UNSIGNED_BYTE, buf.ctypes.data)
    out = np.ascontiguousarray(buf[::-1])
    out[..., 3] = 255
    return out


def write_png(path: str | Path, rgba: np.ndarray) -> None:
    """Write a ``(height, width, 4)`` uint8 array (top row first) as an RGBA PNG."""
    rgba = np.ascontiguousarray(rgba, dtype=np.uint8)
    if rgba.ndim != 3 or rgba.shape[2] != 4:
        raise ValueError(f"write_png needs an (H, W, 4) uint8 array, got shape {rgba.shape}")
    h, w = rgba.shape[:2]
    raw = np.concatenate([np.zeros((h, 1), dtype=np.uint8), rgba.reshape(h, w * 4)], axis=1)

    def chunk(tag: bytes, data: bytes) -> bytes:
        crc = zlib.crc32(tag + data) & 0xFFFFFFFF
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", crc)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw.tobytes(), 9)) + chunk(b"IEND", b"")
    Path(path).write_bytes(png)


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
    from .renderer import Renderer

    if camera is None:
        attached = getattr(scene, "renderer", None)
        camera = copy.copy(attached.camera) if isinstance(attached, Renderer) else Camera()
    renderer = Renderer(width=width, height=height, camera=camera, debug=debug, background=background,
                        window=offscreen_window())
    try:
        renderer.draw(scene)
        return renderer.capture(None if path is None else str(path))
    finally:
        renderer.close()
