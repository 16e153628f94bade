"""Sprite sheets and animations: which part of which image an entity shows, and when.

Plain, validated data with no GL (pyglet is imported only by :mod:`framework.render`), so a
headless test asks a :class:`~framework.components.Visual` which frame it shows at a given scene
time and gets the answer the renderer draws.

- :class:`Frame`: a rectangle of an image file, in pixels from the image's top-left corner (as an
  image editor and Tiled count them).
- :class:`SpriteSheet`: an image cut into a grid of equal frames (with Tiled's margin and
  spacing), numbered row by row from the top-left; :meth:`SpriteSheet.from_tiled` reads a Tiled
  tileset (``.tsj`` / ``.json``) with its per-tile animations.
- :class:`Animation`: frames shown one after another for given durations (seconds), looping or
  once (then holding the last frame).

Animation time is the scene's clock (``scene.time``, advanced by every step), so a run, its
replay and a restored snapshot show the same frames whatever the display does.
"""

from __future__ import annotations

import json
import math
import os
import stat
import struct
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .validation import InvalidValue

__all__ = ["MAX_FRAMES", "MAX_TILESET_BYTES", "Animation", "Frame", "SpriteSheet", "image_size"]

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
#: Frames a sheet may have, by default (``SpriteSheet(..., max_frames=)``, ``from_tiled(max_frames=)``):
#: a 4,096 x 4,096 image (a texture size every desktop GPU takes) cut into 16-pixel tiles. An image's
#: header is a few bytes, so without a bound a 55-byte tileset declaring 2**31 one-pixel tiles
#: asked for 2**31 frames.
MAX_FRAMES = 65_536
#: A tileset file's size, by default (``from_tiled(max_bytes=)``): parsing JSON costs up to about
#: 25 bytes of memory a byte of text.
MAX_TILESET_BYTES = 16 * 1024 * 1024


def image_size(path: str | Path) -> tuple[int, int]:
    """``(width, height)`` of an image file in pixels, read from its header (PNG, GIF, BMP) without
    decoding it. A missing or unreadable file, or another format, is an ``InvalidValue`` naming it."""
    p = Path(path)
    try:
        if not stat.S_ISREG(os.stat(p).st_mode):  # a FIFO or a device named by a file would block or never end
            raise InvalidValue(f"image file {str(path)!r} is not a regular file")
        with open(p, "rb") as f:
            head = f.read(32)
    except OSError as exc:
        raise InvalidValue(f"image file {str(path)!r} cannot be read: {exc.strerror or exc}") from None
    except ValueError as exc:  # a name with a NUL character in it ("embedded null byte")
        if isinstance(exc, InvalidValue):
            raise
        raise InvalidValue(f"image file {str(path)!r} cannot be read: {exc}") from None
    if head[:8] == _PNG_SIGNATURE and head[12:16] == b"IHDR" and len(head) >= 24:
        w, h = struct.unpack(">II", head[16:24])
    elif head[:6] in (b"GIF87a", b"GIF89a") and len(head) >= 10:
        w, h = struct.unpack("<HH", head[6:10])
    elif head[:2] == b"BM" and len(head) >= 26:
        w, h = struct.unpack("<ii", head[18:26])
        h = abs(h)
    else:
        raise InvalidValue(f"image file {str(path)!r} is not a PNG, GIF or BMP image")
    if w <= 0 or h <= 0:
        raise InvalidValue(f"image file {str(path)!r} declares a size of {w} x {h} pixels")
    return int(w), int(h)


def _count(what: str, value: Any, minimum: int = 0) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise InvalidValue(f"{what} must be an int >= {minimum}, got {_show(value)}")
    return int(value)


@dataclass(frozen=True)
class Frame:
    """The rectangle ``x, y, width, height`` (pixels, from the top-left corner) of the image file
    ``image``; drawn centred on its entity, one image pixel per world unit."""

    image: str
    x: int
    y: int
    width: int
    height: int

    def __post_init__(self) -> None:
        if not isinstance(self.image, str) or not self.image:
            raise InvalidValue(f"Frame image must be a file path, got {self.image!r}")
        _count("Frame x", self.x)
        _count("Frame y", self.y)
        _count("Frame width", self.width, 1)
        _count("Frame height", self.height, 1)

    @classmethod
    def whole(cls, image: str | Path) -> Frame:
        """The whole image (its size read from the file's header)."""
        w, h = image_size(image)
        return cls(str(image), 0, 0, w, h)


def _grid_side(path: str, axis: str, size: int, frame: int, margin: int, spacing: int) -> int:
    """How many frames fit along one side of a sheet; the grid must cover it exactly."""
    usable = size - 2 * margin + spacing
    if usable <= 0 or usable % (frame + spacing):
        raise InvalidValue(
            f"sprite sheet {path!r}: a grid of frames {_show(frame)} px {axis} (margin {_show(margin)}, "
            f"spacing {_show(spacing)}) "
            f"does not divide the image's {size} px {axis}")
    return usable // (frame + spacing)


class _Frames(Sequence[Frame]):
    """A sheet's frames, made when asked for (a sheet of 65,536 tiles costs nothing until used);
    each made once and then shared."""

    __slots__ = ("_sheet", "_made")

    def __init__(self, sheet: SpriteSheet) -> None:
        self._sheet = sheet
        self._made: dict[int, Frame] = {}

    def __len__(self) -> int:
        return self._sheet.rows * self._sheet.columns

    def __getitem__(self, index: Any) -> Any:
        if isinstance(index, slice):
            return tuple(self[i] for i in range(*index.indices(len(self))))
        i = int(index)
        n = len(self)
        if not -n <= i < n:
            raise IndexError(f"frame {i} of {n}")
        i %= n
        frame = self._made.get(i)
        if frame is None:
            sh = self._sheet
            r, c = divmod(i, sh.columns)
            frame = self._made[i] = Frame(sh.image, sh.margin + c * (sh.frame_width + sh.spacing),
                                          sh.margin + r * (sh.frame_height + sh.spacing), sh.frame_width,
                                          sh.frame_height)
        return frame

    def __iter__(self) -> Iterator[Frame]:
        return (self[i] for i in range(len(self)))

    def __eq__(self, other: object) -> bool:
        if isinstance(other, (_Frames, tuple, list)):
            return len(self) == len(other) and all(a == b for a, b in zip(self, other))
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"<{len(self)} frames of {self._sheet.image!r}>"


class SpriteSheet:
    """An image cut into a grid of ``frame_width`` x ``frame_height`` frames.

    ``margin``: pixels around the grid; ``spacing``: pixels between frames (Tiled's terms). The grid
    must cover the image exactly, else ``InvalidValue`` naming the file. ``sheet[i]`` is frame
    ``i``, counted row by row from the top-left; ``len(sheet)`` their number, at most
    ``max_frames`` (:data:`MAX_FRAMES`, 65,536, by default), checked before any frame is made;
    ``sheet.frames`` makes each frame when it is first asked for."""

    def __init__(self, image: str | Path, frame_width: int, frame_height: int, *, margin: int = 0,
                 spacing: int = 0, max_frames: int = MAX_FRAMES) -> None:
        path = str(image)
        fw = _count(f"sprite sheet {path!r} frame_width", frame_width, 1)
        fh = _count(f"sprite sheet {path!r} frame_height", frame_height, 1)
        margin = _count(f"sprite sheet {path!r} margin", margin)
        spacing = _count(f"sprite sheet {path!r} spacing", spacing)
        max_frames = _count(f"sprite sheet {path!r} max_frames", max_frames, 1)
        width, height = image_size(path)
        self.image = path
        self.frame_width, self.frame_height = fw, fh
        self.margin, self.spacing = margin, spacing
        self.columns = _grid_side(path, "wide", width, fw, margin, spacing)
        self.rows = _grid_side(path, "high", height, fh, margin, spacing)
        if self.columns * self.rows > max_frames:
            raise InvalidValue(f"sprite sheet {path!r}: {self.columns} x {self.rows} = {self.columns * self.rows} "
                               f"frames, more than the limit of {max_frames} (max_frames)")
        self.frames: Sequence[Frame] = _Frames(self)
        #: Animations the sheet declares (Tiled tile animations), by the first tile's index.
        self.animations: dict[int, Animation] = {}

    def __len__(self) -> int:
        return len(self.frames)

    def __getitem__(self, index: int) -> Frame:
        if isinstance(index, bool) or not isinstance(index, (int, np.integer)) or not -len(self) <= index < len(self):
            raise InvalidValue(f"sprite sheet {self.image!r} has {len(self)} frames; there is no frame {_show(index)}")
        return self.frames[int(index)]

    def animation(self, indices: Sequence[int], duration: float | Sequence[float], *,
                  loop: bool = True) -> Animation:
        """An :class:`Animation` of the frames ``indices`` of this sheet."""
        return Animation([self[i] for i in indices], duration, loop=loop)

    def __repr__(self) -> str:
        return (f"SpriteSheet({self.image!r}, {self.frame_width}, {self.frame_height}, margin={self.margin}, "
                f"spacing={self.spacing})")

    @classmethod
    def from_tiled(cls, tileset: str | Path, *, max_frames: int = MAX_FRAMES,
                   max_bytes: int = MAX_TILESET_BYTES) -> SpriteSheet:
        """A sheet from a Tiled tileset file (JSON: ``.tsj`` or ``.json``) with one image; its tiles'
        animations (Tiled's per-tile ``animation``, durations in milliseconds) in ``animations``.
        Anything malformed is an ``InvalidValue`` naming the file and the field, whatever the file
        holds (a tileset is a file from strangers: see ``docs/reliability.md``): a file over
        ``max_bytes`` is refused before it is read, a sheet of more than ``max_frames`` frames
        before any frame is made."""
        path = Path(tileset)
        max_bytes = _count("from_tiled max_bytes", max_bytes, 1)
        try:
            size = path.stat().st_size
            if size <= max_bytes:
                data = json.loads(path.read_text(encoding="utf-8"))
        except OSError as exc:
            raise InvalidValue(f"tileset {str(path)!r} cannot be read: {exc.strerror or exc}") from None
        except (ValueError, RecursionError) as exc:
            raise InvalidValue(f"tileset {str(path)!r} is not valid JSON: {exc}") from None
        if size > max_bytes:
            raise InvalidValue(f"tileset {str(path)!r}: the file is {size} bytes, more than the limit of {max_bytes} "
                               "(max_bytes)")
        if not isinstance(data, dict):
            raise InvalidValue(f"tileset {str(path)!r}: not a JSON object")

        def field(name: str, default: Any = None) -> Any:
            value = data.get(name, default)
            if value is None:
                raise InvalidValue(f"tileset {str(path)!r}: no {name!r}")
            return value

        image = field("image")
        if not isinstance(image, str):
            raise InvalidValue(f"tileset {str(path)!r}: 'image' must be a file name, got {_show(image)}")
        try:
            sheet = cls(path.parent / image, field("tilewidth"), field("tileheight"), margin=field("margin", 0),
                        spacing=field("spacing", 0), max_frames=max_frames)
        except InvalidValue as exc:
            raise InvalidValue(f"tileset {str(path)!r}: {exc}") from None
        tiles = data.get("tiles", [])
        if not isinstance(tiles, list):
            raise InvalidValue(f"tileset {str(path)!r}: 'tiles' must be a list")
        for k, tile in enumerate(tiles):
            if not isinstance(tile, dict) or "animation" not in tile:
                continue
            where = f"tileset {str(path)!r}: tiles[{k}]"
            steps = tile["animation"]
            if not isinstance(steps, list) or not all(isinstance(s, dict) for s in steps):
                raise InvalidValue(f"{where}.animation must be a list of {{tileid, duration}}")
            try:
                tile_id = _count(f"{where}.id", tile.get("id"))
                frames = [sheet[_count(f"{where}.animation tileid", s.get("tileid"))] for s in steps]
                durations = [_milliseconds(f"{where}.animation duration", s.get("duration")) for s in steps]
                sheet.animations[tile_id] = Animation(frames, durations)
            except InvalidValue as exc:
                raise InvalidValue(f"{where}: {exc}") from None
        return sheet


def _milliseconds(what: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InvalidValue(f"{what} must be a number of milliseconds, got {_show(value)}")
    try:
        return float(value) / 1000.0
    except OverflowError:  # an int beyond float64 (10**400)
        raise InvalidValue(f"{what} must be a finite number of milliseconds, got {_show(value)}") from None


def _duration(what: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InvalidValue(f"{what} must be a number of seconds, got {_show(value)}")
    try:
        d = float(value)
    except OverflowError:  # an int beyond float64 (10**400)
        d = math.inf
    if not math.isfinite(d) or d <= 0.0:
        raise InvalidValue(f"{what} must be finite and > 0 seconds, got {_show(value)}")
    return d


def _show(value: Any) -> str:
    """``repr`` of a value a file gave, for a message: cut to 80 characters, never raising (a list
    nested near the recursion limit; an int of more than 4,300 digits)."""
    try:
        text = repr(value)
    except (ValueError, RecursionError):
        return f"a {type(value).__name__} too long or too deeply nested to show"
    return text if len(text) <= 80 else f"{text[:60]}... ({len(text)} characters)"


class Animation:
    """``frames`` shown in turn, frame ``i`` for ``durations[i]`` seconds (one number: every frame
    that long); with ``loop`` they repeat, else the last frame stays.

    No frames, a non-Frame, or a duration that is zero, negative, NaN or infinite is an
    ``InvalidValue`` naming it. Animations compare (and hash) by value."""

    __slots__ = ("frames", "durations", "loop", "_ends")

    def __init__(self, frames: Sequence[Frame], duration: float | Sequence[float], *, loop: bool = True) -> None:
        frames = tuple(frames) if isinstance(frames, (list, tuple)) else frames
        if not isinstance(frames, tuple) or not frames:
            raise InvalidValue(f"an Animation needs at least one frame, got {frames!r}")
        for i, f in enumerate(frames):
            if not isinstance(f, Frame):
                raise InvalidValue(f"Animation frame {i} must be a Frame, got {f!r}")
        if isinstance(duration, (list, tuple)):
            if len(duration) != len(frames):
                raise InvalidValue(f"Animation has {len(frames)} frames but {len(duration)} durations")
            durations = tuple(_duration(f"Animation duration of frame {i}", d) for i, d in enumerate(duration))
        else:
            durations = (_duration("Animation duration", duration),) * len(frames)
        with np.errstate(over="ignore"):
            ends = np.cumsum(durations)
        if not math.isfinite(ends[-1]):
            raise InvalidValue(f"Animation durations add up to more seconds than a float64 holds "
                               f"({len(frames)} frames)")
        self.frames: tuple[Frame, ...] = frames
        self.durations: tuple[float, ...] = durations
        self.loop = bool(loop)
        self._ends = ends

    @property
    def total(self) -> float:
        """Seconds of one pass through the frames."""
        return float(self._ends[-1])

    def index_at(self, elapsed: float) -> int:
        """The frame shown ``elapsed`` seconds after the animation started (0 before it starts)."""
        return int(self.indices_at(np.asarray([elapsed], dtype=np.float64))[0])

    def indices_at(self, elapsed: np.ndarray) -> np.ndarray:
        """:meth:`index_at` for an array of elapsed times (what the renderer calls)."""
        t = np.maximum(np.asarray(elapsed, dtype=np.float64), 0.0)
        if self.loop:
            t = np.fmod(t, self.total)
        idx = np.searchsorted(self._ends, t, side="right")
        return np.minimum(idx, len(self.frames) - 1)

    def frame_at(self, elapsed: float) -> Frame:
        """The :class:`Frame` shown ``elapsed`` seconds after the animation started."""
        return self.frames[self.index_at(elapsed)]

    def _key(self) -> tuple[Any, ...]:
        return self.frames, self.durations, self.loop

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Animation) and self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    def __repr__(self) -> str:
        return f"Animation({len(self.frames)} frames, {self.total:g} s, loop={self.loop})"

    def __getstate__(self) -> dict[str, Any]:
        return {"frames": self.frames, "durations": self.durations, "loop": self.loop}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.frames, self.durations, self.loop = state["frames"], state["durations"], state["loop"]
        self._ends = np.cumsum(self.durations)

