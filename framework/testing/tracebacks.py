"""Failures that point at the game's test, not at the toolkit.

A failed :func:`~framework.testing.step_until` or ``assert_*`` is the test's failure: the line
worth reading is the test's call, followed by the message. pytest leaves out of a traceback every
frame whose function sets ``__tracebackhide__`` (its own helpers do, and so do pytest's
``pytest.raises`` and ``approx``); a callable decides per exception. The toolkit's helpers set
:func:`hide_on_failure`, which hides their frames for assertion failures only: an exception a game's
system raises during a step keeps its whole path, the toolkit's frames included.
"""

from __future__ import annotations

from typing import Any

__all__ = ["hide_on_failure"]


def hide_on_failure(excinfo: Any) -> bool:
    """For ``__tracebackhide__``: hide the frame when the exception is an ``AssertionError``
    (a test's failure, ``GoldenMismatch`` included), show it for anything else."""
    return excinfo is not None and excinfo.errisinstance(AssertionError)
