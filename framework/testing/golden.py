"""Golden runs: record a scene's trace (every step's positions, rotations, velocities and
collision events) to a file once, and compare later runs with it bit for bit.

::

    check_golden(scene, "tests/golden/coin_pickup.json", steps=120, keys=script)

A run with ``update=True`` (or the environment variable ``FRAMEWORK_UPDATE_GOLDEN=1``, or
pytest's ``--update-golden``) writes the file; without, a missing file fails saying how to record
it (a golden file nobody checked in must not pass silently), and every run compares and fails at
the first step that differs, saying which entity, which field, the golden
value and the new one (``atol`` allows a tolerance). The failure carries a snapshot of the scene
one step before the difference (:attr:`GoldenMismatch.snapshot`, see :mod:`framework.snapshot`)
to restore and inspect. A file written by another version of the trace format or of the
framework is an error that says so (rerun with update to accept the new behaviour).

A golden file larger than ``max_bytes`` (default :data:`MAX_BYTES`, 16 MiB: about 120 steps of
1,000 bodies) is refused before it is read: parsing JSON costs up to about 25 bytes of memory per
byte of file, so the default keeps a hostile or runaway file well under 1 GiB. Pass a larger
``max_bytes`` for longer traces.
"""

from __future__ import annotations

import json
import math
import os
import re
from pathlib import Path
from typing import Any

from ..validation import InvalidValue
from .running import DT, Keys, _hold, _steps
from .tracebacks import hide_on_failure

__all__ = ["GOLDEN_FORMAT", "MAX_BYTES", "GoldenMismatch", "check_golden", "trace_step"]

GOLDEN_FORMAT = 1
FIELDS = ("x", "y", "rot", "vx", "vy", "w")
MAX_BYTES = 16 * 1024 * 1024  # a golden file's size, by default (check_golden(max_bytes=...))


class GoldenMismatch(AssertionError):
    """A run that differs from its golden file; ``step``: the first step that differs,
    ``snapshot``: the scene one step before it."""

    def __init__(self, message: str, step: int, snapshot: Any) -> None:
        super().__init__(message)
        self.step, self.snapshot = step, snapshot


def trace_step(scene: Any) -> dict[str, Any]:
    """One step of a trace: the frame, each entity's position fields, the step's events."""
    store = scene.bodies.store
    bodies = {str(int(store.entity[r])): [float(store.cols[f][r]) for f in FIELDS] for r in range(store.n)}
    return {"frame": scene.frame, "bodies": bodies, "events": [[e.kind, e.a, e.b] for e in scene.events]}


def _update_wanted(update: bool | None) -> bool:
    if update is not None:
        return bool(update)
    return os.environ.get("FRAMEWORK_UPDATE_GOLDEN", "") not in ("", "0")


def check_golden(scene: Any, path: str | Path, steps: int, *, keys: Keys = None, dt: float = DT,
                 update: bool | None = None, atol: float = 0.0, max_bytes: int = MAX_BYTES) -> None:
    """Run ``scene`` ``steps`` steps (holding ``keys``, at ``dt``) and compare each step with the
    golden file at ``path``, or write it (see the module docstring); a file over ``max_bytes`` is
    refused before it is read."""
    __tracebackhide__ = hide_on_failure
    from .. import __version__

    n = _steps(steps, None, dt, "check_golden")
    if not (isinstance(atol, (int, float)) and _a_float(atol) and atol >= 0 and math.isfinite(atol)):
        raise InvalidValue(f"atol must be a finite number >= 0, got {atol!r}")
    if isinstance(max_bytes, bool) or not isinstance(max_bytes, int) or max_bytes <= 0:
        raise InvalidValue(f"max_bytes must be an int > 0, got {max_bytes!r}")
    path = Path(path)
    if _update_wanted(update):
        trace = []
        for k in range(n):
            _hold(scene, keys, k)
            scene.step(dt)
            trace.append(trace_step(scene))
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps({"format": GOLDEN_FORMAT, "framework": __version__, "dt": dt, "steps": n,
                                    "trace": trace}, indent=None, separators=(",", ":")))
        return
    if not path.exists():
        raise AssertionError(f"no golden file {path}: run once with update=True, FRAMEWORK_UPDATE_GOLDEN=1 or "
                             "pytest --update-golden to record it")
    size = path.stat().st_size
    if size > max_bytes:
        raise InvalidValue(f"{path}: the file is {size} bytes, more than the limit of {max_bytes} for a golden trace "
                           "(max_bytes)")
    try:
        golden = json.loads(path.read_bytes().decode("utf-8"))
        fmt, version, trace = golden["format"], golden["framework"], golden["trace"]
    except (ValueError, KeyError, TypeError) as exc:  # UnicodeDecodeError is a ValueError
        raise InvalidValue(f"{path}: not a golden trace ({type(exc).__name__}: {exc})") from None
    except RecursionError:
        raise InvalidValue(f"{path}: not a golden trace (nested too deeply)") from None
    if fmt != GOLDEN_FORMAT or version != __version__:
        raise InvalidValue(f"{path}: a golden trace from another version (trace format {_show(fmt)}, "
                           f"framework {_show(version)}; "
                           f"this is format {GOLDEN_FORMAT}, framework {__version__!r}); rerun with update to "
                           "record it again")
    if golden.get("dt") != dt or golden.get("steps") != n:
        raise InvalidValue(f"{path}: recorded with dt={_show(golden.get('dt'))} over "
                           f"{_show(golden.get('steps'))} steps; "
                           f"this run asks dt={dt!r} over {n} steps")
    if not isinstance(trace, list) or len(trace) != n or not all(_step_ok(t) for t in trace):
        raise InvalidValue(f"{path}: not a golden trace (the trace must be {n} steps of bodies and events)")
    for k in range(n):
        before = scene.snapshot()
        _hold(scene, keys, k)
        scene.step(dt)
        problem = _difference(trace[k], trace_step(scene), atol)
        if problem:
            raise GoldenMismatch(f"{path}: step {k + 1} of {n} (frame {scene.frame}) differs from the golden run: "
                                 f"{problem}", k + 1, before)


_ENTITY = re.compile(r"-?[0-9]{1,19}")  # what str(int) writes for an entity id: ASCII digits ('²' is not one)


def _step_ok(step: Any) -> bool:
    """Whether one step of a trace read from a file has the shape :func:`trace_step` writes: entity
    keys of ASCII digits (``int()`` takes them all), values that are numbers float64 holds."""
    if not isinstance(step, dict) or not isinstance(step.get("bodies"), dict) or not isinstance(step.get("events"),
                                                                                                  list):
        return False
    return all(isinstance(k, str) and _ENTITY.fullmatch(k) and isinstance(v, list) and len(v) == len(FIELDS)
               and all(_a_float(x) for x in v)
               for k, v in step["bodies"].items())


def _a_float(x: Any) -> bool:
    """A number float64 holds (NaN and the infinities too: a different run, not a bad file); not
    ``True``, not ``10**400``."""
    if isinstance(x, float):
        return True
    if isinstance(x, bool) or not isinstance(x, int):
        return False
    try:
        float(x)
    except OverflowError:
        return False
    return True


def _show(value: Any, width: int = 80) -> str:
    """``repr`` of a value read from a file, cut to ``width`` characters, never raising (a list
    nested near the recursion limit)."""
    try:
        text = repr(value)
    except (ValueError, RecursionError):
        return f"a {type(value).__name__} too long or too deeply nested to show"
    return text if len(text) <= width else f"{text[:width - 20]}... ({len(text)} characters)"


def _difference(want: dict[str, Any], got: dict[str, Any], atol: float) -> str | None:
    wb, gb = want["bodies"], got["bodies"]
    if set(wb) != set(gb):
        gone, new = sorted(set(wb) - set(gb), key=int), sorted(set(gb) - set(wb), key=int)
        return f"entities differ: missing now {gone}, new now {new}"
    for e in sorted(wb, key=int):
        for name, a, b in zip(FIELDS, wb[e], gb[e]):
            if not (a == b or abs(a - b) <= atol):
                return f"entity {e} {name}: golden {a!r}, now {b!r} (differs by {b - a:.3g})"
    if want["events"] != got["events"]:
        return f"events: golden {_show(want['events'], 400)}, now {got['events']}"
    return None
