"""Shared plumbing of the benchmarks: timing, tables, raw data files, the generated part of the docs.

Tables are Markdown pipe tables: readable in a terminal and pasted as they are into ``docs/``.
"""

from __future__ import annotations

import csv
import datetime as _dt
import gc
import json
import math
import os
import platform
import re
import statistics
import sys
from collections.abc import Callable, Iterable, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "Column", "REPO", "format_table", "fmt", "frozen_gc", "machine_info", "median", "optional_module",
    "provenance", "replace_generated", "write_csv", "write_json",
]

REPO = Path(__file__).resolve().parents[2]
DATA_DIR = REPO / "docs" / "data"

Column = tuple[str, str, str]  # (row key, header, format: "int", "ms", "ratio", "g", "pct", "sci", "str")


def optional_module(name: str) -> Any:
    """The module, or ``None`` when it is not installed (pymunk and matplotlib are optional)."""
    if os.environ.get("FRAMEWORK_BENCH_WITHOUT", "") and name in os.environ["FRAMEWORK_BENCH_WITHOUT"].split(","):
        return None  # lets a run pretend an optional dependency is absent
    try:
        return __import__(name)
    except ImportError:
        return None


def median(values: Iterable[float]) -> float | None:
    vals = [v for v in values if v is not None and math.isfinite(v)]
    return statistics.median(vals) if vals else None


@contextmanager
def frozen_gc():
    """Collect, then ``gc.freeze()`` what the set-up made, so the collector does not walk it while
    timing; unfreeze afterwards."""
    gc.collect()
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


def machine_info() -> dict[str, Any]:
    info: dict[str, Any] = {
        "date": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "platform": platform.platform(terse=True),
        "machine": platform.machine(),
        "cpus": os.cpu_count(),
    }
    try:
        info["load_average"] = [round(x, 2) for x in os.getloadavg()]
    except OSError:  # pragma: no cover - not on every OS
        pass
    for name in ("esper", "pymunk", "matplotlib"):
        mod = optional_module(name)
        info[name] = getattr(mod, "__version__", getattr(mod, "version", "installed")) if mod else None
    return info


def provenance(m: dict[str, Any], command: str, peers: str, stem: str, more: Sequence[str] = ()) -> str:
    """The first line of a generated docs section: when, how and on what the numbers were taken
    (``m``: :func:`machine_info`; ``peers``: e.g. ``"pymunk 7.3.1"``; ``stem``: the data files' name,
    ``more``: other files the command writes to ``docs/data``)."""
    files = " / ".join(f"`{f}`" for f in (f"docs/data/{stem}.json", f"{stem}.csv", *more))
    return (f"Taken **{m['date']}** with `{command}` on {m['platform']} ({m['machine']}, {m['cpus']} cpus, "
            f"load average {m.get('load_average', 'n/a')} at the start), Python {m['python']}, numpy {m['numpy']}, "
            f"esper {m['esper']}, {peers}. Rerunning the command rewrites this section, the plot and {files}.")


def command_line(argv: Sequence[str]) -> str:
    return " ".join(["python -m framework.bench", *argv])


def fmt(value: Any, kind: str) -> str:
    """One table cell."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "–"
    if kind == "str":
        return str(value)
    if kind == "int":
        return f"{int(round(value)):,}"
    if kind == "ms":
        v = float(value)
        return f"{v:.3f}" if v < 1 else f"{v:.2f}" if v < 10 else f"{v:.1f}" if v < 1000 else f"{v:,.0f}"
    if kind == "ratio":
        return f"{float(value):.2f}"
    if kind == "pct":
        return f"{100 * float(value):.1f}%"
    if kind == "sci":
        v = float(value)
        return "0" if v == 0 else f"{v:.2e}"
    if kind == "g7":  # (seven significant digits: a period against its exact value)
        return f"{float(value):.7g}"
    return f"{float(value):.4g}"


def format_table(rows: Sequence[dict[str, Any]], columns: Sequence[Column]) -> str:
    """A Markdown pipe table with right-aligned numbers."""
    head = [h for _, h, _ in columns]
    body = [[fmt(r.get(k), kind) for k, _, kind in columns] for r in rows]
    widths = [max(len(head[i]), *(len(b[i]) for b in body)) if body else len(head[i]) for i in range(len(head))]
    left = [kind == "str" for _, _, kind in columns]

    def line(cells):
        return "| " + " | ".join(c.ljust(w) if lf else c.rjust(w) for c, w, lf in zip(cells, widths, left)) + " |"

    rule = "|" + "|".join((":" + "-" * (w + 1)) if lf else ("-" * (w + 1) + ":") for w, lf in zip(widths, left)) + "|"
    return "\n".join([line(head), rule, *(line(b) for b in body)])


def _jsonable(v: Any) -> Any:
    if isinstance(v, dict):
        return {k: _jsonable(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_jsonable(x) for x in v]
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, (np.floating, float)):
        f = float(v)
        return f if math.isfinite(f) else None
    if isinstance(v, np.bool_):
        return bool(v)
    return v


def to_json(report: dict[str, Any]) -> str:
    return json.dumps(_jsonable(report), indent=2)


def write_json(path: Path, report: dict[str, Any]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(to_json(report) + "\n")


def write_csv(path: Path, rows: Sequence[dict[str, Any]]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    keys: list[str] = []
    for r in rows:
        keys.extend(k for k in r if k not in keys)
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if r.get(k) is None else _jsonable(r.get(k))) for k in keys})


BEGIN = "<!-- generated by `{name}`: begin (do not edit by hand; rerun the command) -->"
END = "<!-- generated by `{name}`: end -->"


def replace_generated(path: Path, name: str, text: str) -> None:
    """Put ``text`` between the begin/end markers of ``name`` in the Markdown file ``path``."""
    src = path.read_text()
    begin, end = BEGIN.format(name=name), END.format(name=name)
    pat = re.compile(re.escape(begin) + r".*?" + re.escape(end), flags=re.S)
    if not pat.search(src):
        raise SystemExit(f"{path}: markers for {name!r} not found; expected a line\n{begin}\nand later\n{end}")
    path.write_text(pat.sub(lambda _: f"{begin}\n{text.rstrip()}\n{end}", src, count=1))


def time_call(fn: Callable[[], Any]) -> tuple[float, Any]:
    """``(milliseconds, result)`` of one call."""
    import time

    t0 = time.perf_counter()
    out = fn()
    return (time.perf_counter() - t0) * 1e3, out


def stderr_note(msg: str) -> None:
    sys.stderr.write(msg + "\n")
    sys.stderr.flush()
