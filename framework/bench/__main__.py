"""Command line: ``python -m framework.bench {perf,accuracy,regimes,render} [--quick] [--json] [--plot P] [--docs]``."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import Any

from .report import DATA_DIR, REPO, command_line, replace_generated, to_json, write_csv, write_json

__all__ = ["main"]

DOCS = {"perf": REPO / "docs" / "performance.md", "accuracy": REPO / "docs" / "accuracy.md",
        "regimes": REPO / "docs" / "performance.md", "render": REPO / "docs" / "performance.md"}
QUICK_HELP = {"perf": "perf < 2 min", "accuracy": "accuracy < 1 min", "regimes": "regimes ~2 min",
              "render": "render ~2 min"}


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m framework.bench", description=__doc__)
    sub = p.add_subparsers(dest="benchmark", required=True)
    for name, help_ in (("perf", "cost of a step: ours vs pymunk vs the broad-phase floor"),
                        ("accuracy", "accuracy knobs against exact answers"),
                        ("regimes", "piles, stacks, scattered boxes, the platformer, crowds: ours vs pymunk vs Box2D"),
                        ("render", "moving sprites: ours vs a naive pyglet loop, a numpy floor and arcade")):
        s = sub.add_parser(name, help=help_)
        s.add_argument("--quick", action="store_true", help=f"fewer sizes and rounds ({QUICK_HELP[name]})")
        s.add_argument("--json", action="store_true", help="print the report as JSON (an object with a 'rows' list)")
        s.add_argument("--plot", metavar="PATH", help="write a PNG plot (needs matplotlib)")
        s.add_argument("--docs", action="store_true",
                       help=f"rewrite the generated section of {DOCS[name].relative_to(REPO)}")
        s.add_argument("--out", metavar="DIR", default=str(DATA_DIR),
                       help="where the raw JSON and CSV go (default docs/data)")
        s.add_argument("--no-save", action="store_true", help="write no JSON/CSV files")
        s.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
        if name == "perf":
            s.add_argument("--sizes", type=_ints, metavar="N,N,...",
                           help="box counts (default: 1k,10k,50k; quick: 1k,10k)")
            s.add_argument("--rounds", type=int, metavar="R", help="timed rounds per size (default: by size)")
            s.add_argument("--tiles", type=int, metavar="T", help="static tiles of the level (default 100,000)")
            s.add_argument("--tile-bodies", type=int, metavar="N", help="moving boxes over the level (default 1,000)")
        elif name == "render":
            s.add_argument("--sizes", type=_ints, metavar="N,N,...", help="sprite counts (default 1k,10k,50k)")
            s.add_argument("--kinds", type=_names, metavar="A,B,...", help="only these kinds (default: all)")
            s.add_argument("--no-arcade", action="store_true", help="leave arcade out even if it is installed")
        elif name == "accuracy":
            s.add_argument("--scenarios", type=_names, metavar="A,B,...", help="only these scenarios (default: all)")
        else:
            s.add_argument("--scenes", type=_names, metavar="A,B,...", help="only these scenes (default: all)")
            s.add_argument("--crowds", type=_names, metavar="A,B,...",
                           help="only these crowds: balls, boxes, mixed, mixed-friction ('' for none; default: all)")
            s.add_argument("--rounds", type=int, metavar="R", help="timed rounds of every scene (default: by size)")
            s.add_argument("--crowd-steps", type=int, metavar="S",
                           help="cap on a crowd's steps (default 1,800, the issue's 30 s; quick: 600)")
    return p


def _names(text: str) -> tuple[str, ...]:
    return tuple(v for v in text.split(",") if v)


def _ints(text: str) -> tuple[int, ...]:
    return tuple(int(v.replace("k", "000")) for v in text.split(",") if v)


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = _parser()
    args = parser.parse_args(argv)
    progress = not args.no_progress
    report: dict[str, Any]
    mod: Any  # the benchmark's module: its markdown() and text_report() write the report
    if args.benchmark == "perf":
        from . import perf

        mod = perf
        cfg: dict[str, Any] = perf.QUICK if args.quick else perf.FULL
        sizes = args.sizes or cfg["sizes"]
        tile_bodies = args.tile_bodies or (1_000 if args.sizes is None else min(sizes))
        rounds = {n: args.rounds for n in (*sizes, tile_bodies)} if args.rounds else cfg["rounds"]
        small = [n for n in (*sizes, tile_bodies) if n <= cfg["check_up_to"]]
        report = perf.run_perf(sizes=sizes, rounds=rounds, tiles=perf.TILES if args.tiles is None else args.tiles,
                              tile_bodies=tile_bodies, brute_sizes=cfg["brute_sizes"] if args.sizes is None else
                              (min(sizes),), check_up_to=max(small, default=min(sizes)), progress=progress,
                              quick=args.quick, query_rounds=3 if args.quick else 10,
                              **({} if args.sizes is None else {"queries": 100, "query_bodies": min(sizes)}))
    elif args.benchmark == "render":
        from . import render

        mod = render
        cfg = render.QUICK if args.quick else render.FULL
        if set(args.kinds or ()) - set(render.KINDS):
            parser.error(f"unknown {sorted(set(args.kinds) - set(render.KINDS))}; known: {', '.join(render.KINDS)}")
        report = render.run_render(sizes=args.sizes or cfg["sizes"], kinds=args.kinds or render.KINDS,
                                   quick=args.quick, progress=progress, arcade=not args.no_arcade)
    elif args.benchmark == "accuracy":
        from . import accuracy

        mod = accuracy
        report = accuracy.run_accuracy(progress=progress, quick=args.quick, scenarios=args.scenarios)
    else:
        from . import regimes

        mod = regimes
        for given, known in ((args.scenes, regimes.SCENES), (args.crowds, regimes.CROWDS)):
            if set(given or ()) - set(known):
                parser.error(f"unknown {sorted(set(given) - set(known))}; known: {', '.join(known)}")
        cfg = {}
        if args.rounds:
            cfg.update(rounds=((10**12, args.rounds),), platformer_rounds=args.rounds)
        if args.crowd_steps:
            cfg.update(crowd_steps=args.crowd_steps)
        report = regimes.run_regimes(cfg, scenes=args.scenes, crowds=args.crowds, progress=progress,
                                     quick=args.quick)
    command = command_line(argv)
    report["command"] = command
    stem = args.benchmark + ("-quick" if args.quick else "")
    if not args.no_save:
        out = Path(args.out)
        write_json(out / f"{stem}.json", report)
        write_csv(out / f"{stem}.csv", report["rows"])
        if report.get("crowds"):  # regimes-crowds.csv, regimes-crowds-quick.csv
            write_csv(out / (stem.replace(args.benchmark, args.benchmark + "-crowds", 1) + ".csv"), report["crowds"])
    plot_rel = None
    if args.plot:
        from .plots import plot_accuracy, plot_perf, plot_regimes, plot_render

        plot = Path(args.plot)
        plotters = {"perf": plot_perf, "accuracy": plot_accuracy, "regimes": plot_regimes, "render": plot_render}
        drawn = plotters[args.benchmark](report, plot)
        if drawn:
            plot_rel = os.path.relpath(plot.resolve(), DOCS[args.benchmark].parent)
    if args.docs:
        replace_generated(DOCS[args.benchmark], f"python -m framework.bench {args.benchmark}",
                          mod.markdown(report, command, plot_rel))
    print(to_json(report) if args.json else mod.text_report(report))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
