"""Running a scene in a test: a number of steps or seconds, or until something happens; scripted
input over time.

``run`` and ``step_until`` step any :class:`~framework.scene.Scene`; with ``keys`` they hold keys
through the scene's :class:`~framework.input.Input` resource before each step, exactly as a
keyboard (or a replay) would, so the game's own systems see them.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from typing import Any

from ..input import Input
from ..validation import InvalidValue
from .tracebacks import hide_on_failure

__all__ = ["DT", "KeyScript", "run", "step_until", "describe"]

DT = 1.0 / 60.0


class KeyScript:
    """Scripted input over the frames of a run: which keys are held at each frame (frame 0 is the
    first step of the run that plays it).

    ::

        script = KeyScript().hold("right", 0, 90).press("space", 30).press("space", 60, frames=12)
        run(scene, 120, keys=script)
    """

    def __init__(self) -> None:
        self._spans: list[tuple[str, int, int]] = []

    def hold(self, key: str, start: int = 0, end: int | None = None) -> KeyScript:
        """Hold ``key`` from frame ``start`` up to (not including) ``end`` (None: to the end)."""
        _frame("start", start)
        if end is not None:
            _frame("end", end)
            if end < start:
                raise InvalidValue(f"KeyScript.hold({key!r}): end {end} is before start {start}")
        self._spans.append((_key(key), start, math.inf if end is None else end))  # type: ignore[arg-type]
        return self

    def press(self, key: str, at: int, frames: int = 1) -> KeyScript:
        """Press ``key`` at frame ``at`` and hold it for ``frames`` frames, then release it."""
        _frame("at", at)
        if isinstance(frames, bool) or not isinstance(frames, int) or frames < 1:
            raise InvalidValue(f"KeyScript.press({key!r}): frames must be an int >= 1, got {frames!r}")
        return self.hold(key, at, at + frames)

    def keys_at(self, frame: int) -> set[str]:
        """The keys held at ``frame``."""
        return {k for k, a, b in self._spans if a <= frame < b}

    def __repr__(self) -> str:
        return f"KeyScript({self._spans!r})"


def _frame(name: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise InvalidValue(f"KeyScript {name} must be a frame number (an int >= 0), got {value!r}")
    return value


def _key(key: Any) -> str:
    if not isinstance(key, str) or not key:
        raise InvalidValue(f"a key must be a key name such as 'right' or 'space', got {key!r}")
    return key


Keys = KeyScript | Iterable[str] | None


def _hold(scene: Any, keys: Keys, frame: int) -> None:
    if keys is None:
        return
    held = keys.keys_at(frame) if isinstance(keys, KeyScript) else set(keys)
    scene.resources[Input].set_held(held)


def _steps(steps: int | None, seconds: float | None, dt: float, what: str) -> int:
    if steps is not None and seconds is not None:
        raise InvalidValue(f"{what}: give steps or seconds, not both")
    if seconds is not None:
        if isinstance(seconds, bool) or not isinstance(seconds, (int, float)) or not (seconds >= 0 and
                                                                                      math.isfinite(seconds)):
            raise InvalidValue(f"{what}: seconds must be a finite number >= 0, got {seconds!r}")
        return round(seconds / dt)
    if steps is None:
        raise InvalidValue(f"{what} needs a bound: a number of steps, or seconds=")
    if isinstance(steps, bool) or not isinstance(steps, int) or steps < 0:
        raise InvalidValue(f"{what}: steps must be an int >= 0, got {steps!r}")
    return steps


def run(scene: Any, steps: int | None = None, *, seconds: float | None = None, dt: float = DT,
        keys: Keys = None) -> int:
    """Step ``scene`` ``steps`` times (or ``seconds`` of it, at ``dt``), holding ``keys`` (a
    :class:`KeyScript`, or a set held throughout); return the scene's frame after."""
    n = _steps(steps, seconds, dt, "run")
    for k in range(n):
        _hold(scene, keys, k)
        scene.step(dt)
    return scene.frame


def step_until(scene: Any, predicate: Callable[[Any], bool], *, within: int | None = None,
               seconds: float | None = None, dt: float = DT, keys: Keys = None,
               describe_with: Callable[[Any], str] | None = None, what: str | None = None) -> int:
    """Step until ``predicate(scene)`` holds; return how many steps that took (0: it held already).

    A bound is required: ``within`` steps or ``seconds``. ``keys`` are held while it steps, as in
    :func:`run`: a :class:`KeyScript` (its frame 0 is this call's first step) or a set of keys held
    throughout (``keys={"left"}``). When the bound runs out, ``AssertionError`` says what was
    awaited (``what``, else the predicate's name) and what was last seen (``describe_with(scene)``,
    else :func:`describe`); the traceback shows the test's call, not this function."""
    __tracebackhide__ = hide_on_failure
    n = _steps(within, seconds, dt, "step_until")
    if predicate(scene):
        return 0
    for k in range(n):
        _hold(scene, keys, k)
        scene.step(dt)
        if predicate(scene):
            return k + 1
    name = what or getattr(predicate, "__name__", "the condition")
    seen = (describe_with or describe)(scene)
    raise AssertionError(f"{name} did not happen within {n} steps (frame {scene.frame}); last seen: {seen}")


def describe(scene: Any) -> str:
    """A short account of a scene for failure messages: its frame, its moving bodies (up to 6:
    entity, position, velocity) and this step's events."""
    store = scene.bodies.store
    movers = [r for r in range(store.n) if store.has_vel[r]][:6]
    bodies = ", ".join(f"{int(store.entity[r])} at ({store.x[r]:.6g}, {store.y[r]:.6g}) moving "
                       f"({store.vx[r]:.6g}, {store.vy[r]:.6g})" for r in movers)
    events = ", ".join(f"{e.kind} {e.a}-{e.b}" for e in scene.events[:8])
    return f"frame {scene.frame}; bodies: {bodies or 'none moving'}; events: {events or 'none'}"
