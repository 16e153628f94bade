"""A small progress bar on stderr (no dependency).

On a terminal it redraws one line in place (``\\r``); elsewhere (a log, a pipe) it prints a line
with the count and the task at most every few seconds, and one when it finishes, so logs stay
short. ``Progress(total=0)`` and ``enabled=False`` print nothing.
"""

from __future__ import annotations

import sys
import time
from typing import TextIO

__all__ = ["Progress"]


class Progress:
    """``with Progress(total, "perf") as bar: ... bar.advance(note="10k")``."""

    def __init__(self, total: int, label: str, *, enabled: bool = True, stream: TextIO | None = None,
                 width: int = 28) -> None:
        self.total = max(0, int(total))
        self.label = label
        self.stream = sys.stderr if stream is None else stream
        self.enabled = enabled and self.total > 0
        self.tty = self.enabled and getattr(self.stream, "isatty", lambda: False)()
        self.width = width
        self.done = 0
        self.note = ""
        self.t0 = time.perf_counter()
        self._last_draw = 0.0
        self._last_line: float | None = None
        self.log_every = 5.0  # seconds between lines when not on a terminal

    def __enter__(self) -> Progress:
        self._draw(force=True)
        return self

    def __exit__(self, *exc: object) -> None:
        self.finish()

    def task(self, note: str) -> None:
        """Name what is running now (shown next to the bar)."""
        if note != self.note:
            self.note = note
            if self.enabled and not self.tty:
                now = time.perf_counter()
                if self._last_line is None or now - self._last_line >= self.log_every:
                    self._last_line = now
                    pct = 100 * self.done / self.total if self.total else 100.0
                    self.stream.write(f"{self.label}: {self.done}/{self.total} ({pct:.0f}%) {note} ...\n")
                    self.stream.flush()
            self._draw(force=True)

    def advance(self, n: int = 1, note: str | None = None) -> None:
        self.done = min(self.total, self.done + n)
        if note is not None:
            self.task(note)
        self._draw()

    def finish(self) -> None:
        if not self.enabled:
            return
        self.done = self.total
        elapsed = time.perf_counter() - self.t0
        if self.tty:
            self._draw(force=True)
            self.stream.write("\n")
        else:
            self.stream.write(f"{self.label}: done in {elapsed:.1f} s\n")
        self.stream.flush()
        self.enabled = False

    def _draw(self, force: bool = False) -> None:
        if not self.tty:
            return
        now = time.perf_counter()
        if not force and now - self._last_draw < 0.1:
            return
        self._last_draw = now
        frac = self.done / self.total if self.total else 1.0
        fill = int(round(frac * self.width))
        elapsed = now - self.t0
        eta = f" eta {elapsed / frac - elapsed:4.0f} s" if 0.0 < frac < 1.0 else ""
        line = (f"\r{self.label} [{'#' * fill}{'.' * (self.width - fill)}] {100 * frac:3.0f}% "
                f"{elapsed:5.1f} s{eta}  {self.note}")
        self.stream.write(line[:120].ljust(120))
        self.stream.flush()
