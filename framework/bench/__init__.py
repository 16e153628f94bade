"""Benchmarks, run as scripts (never as timed tests):

- ``python -m framework.bench perf``: the cost of a step of the full pipeline, against pymunk and the
  numpy broad-phase floor (:mod:`framework.bench.perf`);
- ``python -m framework.bench accuracy``: what the accuracy knobs buy, against exact answers
  (:mod:`framework.bench.accuracy`);
- ``python -m framework.bench regimes``: piles, a stack, a pyramid, scattered boxes, the platformer
  and crowds, ours against pymunk and Box2D v3, with each engine's accuracy judged by one oracle
  (:mod:`framework.bench.regimes`).

Each prints a table, writes the raw rows as JSON and CSV under ``docs/data/`` and, with ``--plot`` and
``--docs``, the plot and the generated part of ``docs/performance.md`` / ``docs/accuracy.md``.
pymunk, pyb2d3 and matplotlib (the ``bench`` extra) are optional: without them the peers' columns
are empty and no plot is drawn.
"""

__all__ = ["main"]


def main(argv=None) -> int:
    from .__main__ import main as _main

    return _main(argv)
