"""One line on stderr while numba compiles.

The compiled paths are compiled on their first call after installing (then loaded from numba's
cache, ``cache=True``): seconds of a silent terminal, which a new user takes for a hang (issue 36).
A first call that has not returned within a second is compiling, not loading: say so, once.
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["FIRST_STEP_NOTICE", "notice_if_slow"]

FIRST_STEP_NOTICE = ("framework: compiling the physics kernels for this scene (once per installation, 15 to 30 "
                     "seconds; later runs load them from numba's cache)")


@contextmanager
def notice_if_slow(message: str, after: float = 1.0) -> Iterator[None]:
    """Print ``message`` on stderr if the block has not finished within ``after`` seconds."""
    timer = threading.Timer(after, lambda: print(message, file=sys.stderr, flush=True))
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()
