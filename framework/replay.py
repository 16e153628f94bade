"""Replays: recorded input, one set of held keys per frame, to play a game back exactly.

A scene is deterministic (the same components and the same input give the same bytes, whatever
``PYTHONHASHSEED``; see ``docs/reliability.md``), so the keys held at each frame, the step ``dt``
and the seed the game used for its own randomness are all it takes to replay a session: a bug
report, a demo, a regression test.

File format: JSON lines, UTF-8. The first line is a header object, each further line one frame:
the sorted list of the key names held during that frame (the names of :class:`~framework.input.Input`,
e.g. ``"left"``, ``"space"``)::

    {"format": "framework-replay", "version": 1, "dt": 0.016666666666666666, "seed": 7, "frames": 3, "meta": {}}
    []
    ["right"]
    ["right", "space"]

``frames`` in the header is the number of frame lines, so a truncated file is caught. ``seed`` is
an int or null; ``meta`` any JSON object (level name, game version...). :meth:`Replay.load`
refuses anything else with a ``ValueError`` naming the file and the line.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable, Iterator
from typing import Any

from .input import Input
from .validation import InvalidValue

__all__ = ["FORMAT", "MAX_BYTES", "MAX_FRAMES", "VERSION", "Replay"]

FORMAT = "framework-replay"
VERSION = 1
MAX_BYTES = 16 * 1024 * 1024   # a replay file's size, by default (Replay.load(max_bytes=...)): 4 to 25 hours at 60 Hz
MAX_FRAMES = 10_000_000        # frames a replay may declare (46 hours at 60 Hz), by default


def _keys(keys: object, where: str) -> frozenset[str]:
    if isinstance(keys, (str, bytes)) or not isinstance(keys, Iterable):
        raise InvalidValue(f"{where}: the held keys must be a list of key names, got {_short(keys)}")
    out = []
    for k in keys:
        if not isinstance(k, str) or not k:
            raise InvalidValue(f"{where}: a key name must be a non-empty string, got {_short(k)}")
        out.append(k)
    held = frozenset(out)
    if len(held) != len(out):
        raise InvalidValue(f"{where}: a key is listed twice in {sorted(out)!r}")
    return held


def _dt(value: object, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (_finite(value) and value > 0):
        raise InvalidValue(f"{where}: dt must be a finite number > 0, got {_short(value)}")
    return float(value)


def _finite(value: int | float) -> bool:
    """``math.isfinite`` that says False for an int beyond float64 (``10**400``) instead of raising."""
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def _short(value: object) -> str:
    """``repr(value)`` cut to 80 characters (a file's value may be 4,300 digits long)."""
    try:
        text = repr(value)
    except (RecursionError, ValueError):  # nested deeper than repr goes; an int of more than 4,300 digits
        return f"a {type(value).__name__} too deep or too long to show"
    return text if len(text) <= 80 else f"{text[:60]}... ({len(text)} characters)"


def _seed(value: object, where: str) -> int | None:
    if value is not None and (isinstance(value, bool) or not isinstance(value, int)):
        raise InvalidValue(f"{where}: seed must be an int or null, got {_short(value)}")
    return value


def _meta(value: object, where: str) -> dict[str, Any]:
    if not isinstance(value, dict) or not all(isinstance(k, str) for k in value):
        raise InvalidValue(f"{where}: meta must be an object with string keys, got {_short(value)}")
    try:
        json.dumps(value, allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise InvalidValue(f"{where}: meta must hold only JSON values ({exc})") from None
    return dict(value)


class Replay:
    """The keys held at each frame of a session, with the step ``dt``, the game's ``seed`` and free
    ``meta`` data. Frames are frozensets of key names; frame ``i`` is the input of step ``i``."""

    def __init__(self, frames: Iterable[Iterable[str]] = (), *, dt: float = 1 / 60, seed: int | None = None,
                 meta: dict[str, Any] | None = None) -> None:
        self.dt = _dt(dt, "Replay")
        self.seed = _seed(seed, "Replay")
        self.meta = _meta({} if meta is None else meta, "Replay")
        self.frames: list[frozenset[str]] = [_keys(f, f"Replay frame {i}") for i, f in enumerate(frames)]

    # --- recording and playing ----------------------------------------------------------------

    def record(self, keys: Iterable[str]) -> None:
        """Append a frame: the keys held during the next step (e.g. ``scene.resources[Input].held``)."""
        self.frames.append(_keys(keys, f"Replay frame {len(self.frames)}"))

    def apply(self, scene: Any, frame: int) -> None:
        """Make the keys of ``frame`` the held keys of ``scene.resources[Input]`` (presses and
        releases follow, as from a keyboard); call it before stepping that frame."""
        if isinstance(frame, bool) or not isinstance(frame, int) or not 0 <= frame < len(self.frames):
            raise InvalidValue(f"frame must be an int in [0, {len(self.frames)}), got {frame!r}")
        inp = scene.resources.get(Input)
        if inp is None:
            inp = scene.resources[Input] = Input()
        inp.set_held(self.frames[frame])

    def play(self, scene: Any, start: int = 0, stop: int | None = None) -> None:
        """Apply and step frames ``start`` to ``stop`` (default: the end) with the replay's ``dt``."""
        for i in range(start, len(self.frames) if stop is None else stop):
            self.apply(scene, i)
            scene.step(self.dt)

    def __len__(self) -> int:
        return len(self.frames)

    def __iter__(self) -> Iterator[frozenset[str]]:
        return iter(self.frames)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Replay):
            return NotImplemented
        return (self.frames, self.dt, self.seed, self.meta) == (other.frames, other.dt, other.seed, other.meta)

    __hash__ = None  # type: ignore[assignment]  # mutable

    def __repr__(self) -> str:
        return f"Replay({len(self.frames)} frames, dt={self.dt!r}, seed={self.seed!r}, meta={self.meta!r})"

    # --- files --------------------------------------------------------------------------------

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the replay as JSON lines (see the module docstring), replacing ``path``."""
        header = {"format": FORMAT, "version": VERSION, "dt": self.dt, "seed": self.seed, "frames": len(self.frames),
                  "meta": self.meta}
        lines = [json.dumps(header, allow_nan=False)]
        lines.extend(json.dumps(sorted(f)) for f in self.frames)
        tmp = f"{os.fspath(path)}.tmp"
        with open(tmp, "w", encoding="utf-8", newline="\n") as f:
            f.write("\n".join(lines) + "\n")
        os.replace(tmp, path)  # never a half-written replay under the real name

    @classmethod
    def load(cls, path: str | os.PathLike[str], *, max_bytes: int = MAX_BYTES, max_frames: int = MAX_FRAMES) -> Replay:
        """Read a replay written by :meth:`save`; ``ValueError`` naming the file (and line) if it
        is not one, whatever it holds (a file over ``max_bytes``, or declaring more than
        ``max_frames`` frames, is refused before it is read). A missing file raises
        ``FileNotFoundError``. Identical frame lines share one frozenset (read once), so a replay
        costs about 8 bytes of memory a frame beyond its distinct frames; parsing costs up to
        about 40 bytes a byte of distinct lines, so the default limit keeps any file well under
        1 GiB."""
        name = os.fspath(path)
        size = os.stat(name).st_size
        if size > max_bytes:
            raise InvalidValue(f"{name}: the file is {size} bytes, more than the limit of {max_bytes} (max_bytes)")
        try:
            with open(name, encoding="utf-8") as f:
                text = f.read()
        except UnicodeDecodeError as exc:
            raise InvalidValue(f"{name}: not a replay: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
        # The lines, one at a time (a list of them all cost up to 100 bytes a byte of file).
        nlines = text.count("\n") + (0 if text == "" or text.endswith("\n") else 1)
        if not nlines:
            raise InvalidValue(f"{name}: not a replay: the file is empty")

        def each_line() -> Iterator[str]:  # split a MiB at a time (never the whole text at once)
            start, limit = 0, len(text) - 1 if text.endswith("\n") else len(text)
            while True:
                end = text.find("\n", min(start + (1 << 20), limit), limit)
                end = limit if end < 0 else end
                yield from text[start:end].split("\n")
                if end >= limit:
                    return
                start = end + 1

        lines = each_line()
        first = next(lines)

        def parse(i: int, line: str) -> Any:
            try:
                return _DECODER.decode(line)
            except ValueError as exc:
                raise InvalidValue(f"{name}: line {i + 1}: not JSON ({exc})") from None
            except RecursionError:
                raise InvalidValue(f"{name}: line {i + 1}: nested too deeply to be part of a replay") from None

        header = parse(0, first)
        if not isinstance(header, dict) or header.get("format") != FORMAT:
            raise InvalidValue(f"{name}: line 1: not a replay header (expected an object with "
                               f'"format": "{FORMAT}"), got {first[:80]!r}')
        if header.get("version") != VERSION:
            raise InvalidValue(f"{name}: line 1: unsupported replay version {_short(header.get('version'))} "
                               f"(this framework reads version {VERSION})")
        unknown = set(header) - {"format", "version", "dt", "seed", "frames", "meta"}
        if unknown:
            raise InvalidValue(f"{name}: line 1: unknown header fields {sorted(unknown)!r}")
        where = f"{name}: line 1"
        count = header.get("frames")
        if isinstance(count, bool) or not isinstance(count, int) or count < 0:
            raise InvalidValue(f"{where}: frames must be an int >= 0, got {_short(count)}")
        if count > max_frames:
            raise InvalidValue(f"{where}: {count} frames, more than the limit of {max_frames} (max_frames)")
        if count != nlines - 1:
            raise InvalidValue(f"{name}: the header promises {count} frames but the file has {nlines - 1} "
                               "(truncated or edited?)")
        replay = cls(dt=_dt(header.get("dt"), where), seed=_seed(header.get("seed"), where),
                     meta=_meta(header.get("meta", {}), where))
        seen: dict[str, frozenset[str]] = {}  # a line read before: the same frame, the same frozenset
        frames = replay.frames
        # one JSON value from the start of a line, no decoder made per line (scan_once is set by
        # JSONDecoder.__init__; typeshed does not declare it)
        scan = _DECODER.scan_once  # type: ignore[attr-defined]
        for i, line in enumerate(lines, start=1):
            held: frozenset[str] | None = seen.get(line)
            if held is None:
                try:
                    frame, end = scan(line, 0)
                except (StopIteration, ValueError, RecursionError):
                    end = -1
                if end != len(line):  # not one bare JSON value: the full decoder says what is wrong
                    frame = parse(i, line)
                if type(frame) is not list:
                    raise InvalidValue(f"{name}: line {i + 1}: a frame must be a list of key names, got {line[:80]!r}")
                keys: frozenset[str] | None = None
                try:  # the common case at C speed: distinct non-empty key names
                    keys = frozenset(frame)
                    "".join(frame)  # a TypeError unless every member is text
                    ok = len(keys) == len(frame) and "" not in keys
                except TypeError:
                    ok = False
                if not ok or keys is None:
                    keys = _keys(frame, f"{name}: line {i + 1}")  # raises, naming what is wrong
                seen[line] = held = keys
            frames.append(held)
        return replay


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not JSON")


_DECODER = json.JSONDecoder(parse_constant=_no_constant)
