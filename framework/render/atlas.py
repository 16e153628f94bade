"""The texture atlas: every image the renderer draws, packed into one texture.

One texture for all images lets one draw call serve every sprite of a layer, whatever image or
animation frame each shows. Images are packed whole (a sprite sheet once, not frame by frame) on
shelves, in the order they are first needed, one transparent pixel apart; when the atlas is full
it doubles its side and packs everything again (the frames' texture coordinates then change,
which :attr:`Atlas.version` tells). A frame's texture coordinates are its image's place in the
atlas plus the frame's rectangle in the image.

The atlas is kept as a numpy array (rows bottom-up, as OpenGL reads them) and uploaded whole when
it changed, sampled nearest (crisp pixels).
"""

from __future__ import annotations

import ctypes
from typing import Any

import numpy as np
from pyglet import gl

from ..sprites import Frame

__all__ = ["Atlas", "load_rgba"]

START_SIDE = 256
GAP = 1  # transparent pixels between two packed images


def load_rgba(path: str) -> np.ndarray:
    """The image file's pixels as a ``(height, width, 4)`` uint8 array, bottom row first."""
    import pyglet

    data = pyglet.image.load(path).get_image_data()
    raw = data.get_data("RGBA", data.width * 4)
    return np.frombuffer(raw, dtype=np.uint8).reshape(data.height, data.width, 4).copy()


def _shelf_pack(sizes: list[tuple[int, int]], side: int) -> list[tuple[int, int]] | None:
    """Bottom-left corners of ``(width, height)`` boxes packed on shelves in a ``side`` square, in
    order; ``None`` when they do not fit."""
    out: list[tuple[int, int]] = []
    x = y = shelf = 0
    for w, h in sizes:
        if w + GAP > side:
            return None
        if x + w + GAP > side:
            x, y, shelf = 0, y + shelf, 0
        if y + h + GAP > side:
            return None
        out.append((x, y))
        x += w + GAP
        shelf = max(shelf, h + GAP)
    return out


class Atlas:
    """Images packed into one RGBA texture; frames of them numbered, with their texture coordinates.

    :meth:`frame_id` gives a frame's number (loading and packing its image on first use);
    :attr:`uv` ``[id]`` its ``(u0, v0, u1, v1)`` (left, bottom, right, top) and :attr:`size`
    ``[id]`` its ``(width, height)`` in pixels. ``max_side``: the largest texture side to grow to."""

    def __init__(self, max_side: int = 8192) -> None:
        self.max_side = max_side
        self.side = START_SIDE
        self.pixels = np.zeros((self.side, self.side, 4), dtype=np.uint8)
        self.version = 0  # bumped when frames' texture coordinates change (a re-pack)
        self._images: dict[str, np.ndarray] = {}  # path -> pixels
        self._place: dict[str, tuple[int, int]] = {}  # path -> bottom-left corner in the atlas
        self._frames: dict[Frame, int] = {}
        self._frame_list: list[Frame] = []
        self.uv = np.zeros((0, 4), dtype=np.float32)
        self.size = np.zeros((0, 2), dtype=np.float32)
        self._texture_id: int | None = None
        self._uploaded = -1  # the upload count the GL texture holds
        self._changes = 0

    # --- frames ------------------------------------------------------------------------------

    def frame_id(self, frame: Frame) -> int:
        """The number of ``frame``, its image loaded and packed on first use. A missing or
        unreadable image, or a frame reaching outside its image, is a ``ValueError`` naming the file."""
        known = self._frames.get(frame)
        if known is not None:
            return known
        pixels = self._image(frame.image)
        h, w = pixels.shape[:2]
        if frame.x + frame.width > w or frame.y + frame.height > h:
            raise ValueError(f"frame {frame.x},{frame.y} {frame.width}x{frame.height} reaches outside image "
                             f"{frame.image!r} ({w} x {h} pixels)")
        fid = len(self._frame_list)
        self._frames[frame] = fid
        self._frame_list.append(frame)
        self.uv = np.concatenate([self.uv, np.zeros((1, 4), dtype=np.float32)])
        self.size = np.concatenate([self.size, np.array([[frame.width, frame.height]], dtype=np.float32)])
        self._uv_of(np.array([fid]))
        return fid

    def whole(self, path: str) -> Frame:
        """The frame covering all of image ``path`` (loaded and packed on first use)."""
        h, w = self._image(path).shape[:2]
        return Frame(path, 0, 0, w, h)

    def _uv_of(self, ids: np.ndarray) -> None:
        side = float(self.side)
        for fid in ids.tolist():
            f = self._frame_list[fid]
            ax, ay = self._place[f.image]
            ih = self._images[f.image].shape[0]
            left, bottom = ax + f.x, ay + ih - f.y - f.height  # frame rows count from the image's top
            self.uv[fid] = (left / side, bottom / side, (left + f.width) / side, (bottom + f.height) / side)

    # --- images ------------------------------------------------------------------------------

    def _image(self, path: str) -> np.ndarray:
        pixels = self._images.get(path)
        if pixels is not None:
            return pixels
        try:
            pixels = load_rgba(path)
        except Exception as exc:  # missing, unreadable, not an image: say which file
            raise ValueError(f"image {path!r} could not be loaded: {exc}") from exc
        self._images[path] = pixels
        sizes = [(p.shape[1], p.shape[0]) for p in self._images.values()]
        places = _shelf_pack(sizes, self.side)
        side = self.side
        while places is None:
            side *= 2
            if side > self.max_side:
                del self._images[path]
                raise ValueError(f"image {path!r} does not fit in the texture atlas "
                                 f"({self.max_side} x {self.max_side} pixels, shared by every image drawn)")
            places = _shelf_pack(sizes, side)
        regrown = side != self.side or any(self._place.get(p) != xy for p, xy in zip(self._images, places))
        if side != self.side:
            self.side = side
            self.pixels = np.zeros((side, side, 4), dtype=np.uint8)
        for (p, img), (x, y) in zip(self._images.items(), places):
            self._place[p] = (x, y)
            self.pixels[y:y + img.shape[0], x:x + img.shape[1]] = img
        if regrown and self._frame_list:
            self._uv_of(np.arange(len(self._frame_list)))
            self.version += 1
        self._changes += 1
        return pixels

    # --- GL ----------------------------------------------------------------------------------

    def texture_id(self) -> int:
        """The GL texture holding the atlas, uploaded again if images were added since."""
        if self._texture_id is None:
            tex = gl.GLuint()
            gl.glGenTextures(1, ctypes.byref(tex))
            self._texture_id = int(tex.value)
        if self._uploaded != self._changes:
            gl.glBindTexture(gl.GL_TEXTURE_2D, self._texture_id)
            gl.glPixelStorei(gl.GL_UNPACK_ALIGNMENT, 1)
            gl.glTexImage2D(gl.GL_TEXTURE_2D, 0, gl.GL_RGBA8, self.side, self.side, 0, gl.GL_RGBA,
                            gl.GL_UNSIGNED_BYTE, self.pixels.ctypes.data_as(ctypes.POINTER(gl.GLubyte)))
            for name in (gl.GL_TEXTURE_MIN_FILTER, gl.GL_TEXTURE_MAG_FILTER):
                gl.glTexParameteri(gl.GL_TEXTURE_2D, name, gl.GL_NEAREST)
            for name in (gl.GL_TEXTURE_WRAP_S, gl.GL_TEXTURE_WRAP_T):
                gl.glTexParameteri(gl.GL_TEXTURE_2D, name, gl.GL_CLAMP_TO_EDGE)
            gl.glBindTexture(gl.GL_TEXTURE_2D, 0)
            self._uploaded = self._changes
        return self._texture_id

    def delete(self) -> None:
        """Delete the GL texture (in the context that made it)."""
        if self._texture_id is not None:
            gl.glDeleteTextures(1, ctypes.byref(gl.GLuint(self._texture_id)))
            self._texture_id = None
            self._uploaded = -1

    def stats(self) -> dict[str, Any]:
        return {"side": self.side, "images": len(self._images), "frames": len(self._frame_list)}
