"""Offscreen GL: the hidden window whose context draws without a display, an RGBA8 render target,
reading pixels back, and writing them as a PNG.

The lowest layer of the render package: it imports nothing from it, and the renderer
(:mod:`.renderer`) and the screenshots (:mod:`.headless`) both build on it.

Frames are drawn into an RGBA8 texture attached to a :class:`pyglet.image.Framebuffer`, not into
the window: the headless default framebuffer is RGB565, which would round every colour.
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pyglet
from pyglet import gl

__all__ = ["OffscreenTarget", "offscreen_window", "read_pixels", "write_png"]

_offscreen_window: Any = None


def offscreen_window() -> Any:
    """The hidden window whose GL context offscreen rendering uses (one per process, made on first
    call, made again if it was closed)."""
    global _offscreen_window
    if _offscreen_window is None or _offscreen_window.context is None:
        _offscreen_window = pyglet.window.Window(16, 16, visible=False, caption="framework offscreen")
    return _offscreen_window


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


class OffscreenTarget:
    """An RGBA8 texture attached to a framebuffer, made on first use and made again when the size
    changes. Needs the GL context it was first used in to be current."""

    def __init__(self) -> None:
        self._framebuffer: Any = None
        self._texture: Any = None
        self._size = (0, 0)

    def capture(self, width: int, height: int, background: tuple[int, ...], draw: Callable[[], None]) -> np.ndarray:
        """Clear the target to ``background`` (r, g, b), call ``draw()`` into it and return its
        pixels (see :func:`read_pixels`)."""
        return self.draw(width, height, background, draw, read=True)

    def draw(self, width: int, height: int, background: tuple[int, ...], draw: Callable[[], None],
             read: bool = False) -> Any:
        """Clear the target to ``background``, call ``draw()`` into it; its pixels when ``read``
        (the render benchmark draws without reading back)."""
        if self._framebuffer is None or self._size != (width, height):
            self.delete()
            self._texture = pyglet.image.Texture.create(width, height, internalformat=gl.GL_RGBA8)
            self._framebuffer = pyglet.image.Framebuffer()
            self._framebuffer.attach_texture(self._texture)
            self._size = (width, height)
        framebuffer = self._framebuffer
        framebuffer.bind()
        try:
            if not framebuffer.is_complete:
                raise RuntimeError(f"offscreen framebuffer incomplete: {framebuffer.get_status()}")
            gl.glViewport(0, 0, width, height)
            r, g, b = (c / 255.0 for c in background[:3])
            gl.glClearColor(r, g, b, 1.0)
            gl.glClear(gl.GL_COLOR_BUFFER_BIT | gl.GL_DEPTH_BUFFER_BIT)
            draw()
            return read_pixels(width, height) if read else None
        finally:
            framebuffer.unbind()

    def delete(self) -> None:
        """Delete the framebuffer and its texture (made again by the next :meth:`capture`)."""
        if self._framebuffer is not None:
            self._framebuffer.delete()
            self._texture.delete()
        self._framebuffer = self._texture = None
        self._size = (0, 0)
