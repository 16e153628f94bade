"""The level-test sweep: ``python -m examples.platformer.sweep --workers N --episodes M``.

Plays every level (or ``--levels 0,2``) many times with two agents and reports how often each
finishes: the **scripted** agent (the level's demo script, :mod:`.demo`; deterministic, so it plays
each level once) and the **random** agent (random actions of the Gymnasium environment,
:mod:`.env`, biased to run right; one episode per seed ``0 .. M-1``). It answers "does every level
stay finishable after a change?" and measures how fast episodes run.

Episodes run on Ray (``ray.init()`` on this machine with ``--workers`` CPUs by default;
``--address`` joins a cluster) or, with ``--workers 0``, in this process without Ray. Writes a
JSON summary (``--out``, default ``sweep.json``: completion rate, frames and deaths per level and
agent, game frames per second overall and per worker) and, with matplotlib, a plot (``--plot``).
Needs the ``rl`` extra (gymnasium, and ray for ``--workers`` > 0).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Iterable
from pathlib import Path
from typing import Any

__all__ = ["Task", "main", "run_episode", "run_tasks", "summarize", "tasks_for"]

Task = tuple[int, str, int]  # (level index, agent, seed)
AGENTS = ("scripted", "random")
MAX_FRAMES = 3600  # a minute of game time per episode


def tasks_for(levels: Iterable[int], episodes: int, agents: Iterable[str] = AGENTS) -> list[Task]:
    """Every episode to play: the scripted agent once per level, the random one ``episodes`` times."""
    out: list[Task] = []
    for level in levels:
        for agent in agents:
            out += [(level, agent, seed) for seed in range(1 if agent == "scripted" else episodes)]
    return out


def run_episode(task: Task, max_frames: int = MAX_FRAMES) -> dict[str, Any]:
    """Play one episode; its result (completed, frames, deaths, coins, seconds)."""
    level, agent, seed = task
    t0 = time.perf_counter()
    if agent == "scripted":
        from .demo import SCRIPTS, Autoplay
        from .game import Game
        from .levels import builtin_levels

        game = Game([builtin_levels()[level]], autoplay=Autoplay(SCRIPTS[level]))
        try:
            while not game.state.reached_goal and game.state.deaths == 0 and game.scene.frame < max_frames:
                game.step()
            st, frames = game.state, game.scene.frame
            result = {"completed": st.reached_goal, "deaths": st.deaths, "coins": st.coins, "frames": frames}
        finally:
            game.close()
    elif agent == "random":
        import numpy as np

        from .env import PlatformerEnv

        env = PlatformerEnv(level, max_frames=max_frames)
        rng = np.random.default_rng(seed)
        try:
            env.reset(seed=seed)
            weights = np.array([1, 1, 4, 2, 1, 4, 1], dtype=float)  # run right, jump often
            weights /= weights.sum()
            info: dict[str, Any] = {}
            while True:
                _obs, _r, term, trunc, info = env.step(int(rng.choice(7, p=weights)))
                if term or trunc:
                    break
            result = {"completed": bool(info["reached_goal"]), "deaths": info["deaths"], "coins": info["coins"],
                      "frames": info["frames"]}
        finally:
            env.close()
    else:
        raise ValueError(f"unknown agent {agent!r} (agents: {', '.join(AGENTS)})")
    return {"level": level, "agent": agent, "seed": seed, **result, "seconds": time.perf_counter() - t0}


def _run_batch(tasks: list[Task], max_frames: int) -> list[dict[str, Any]]:
    return [run_episode(t, max_frames) for t in tasks]


def run_tasks(tasks: list[Task], workers: int, *, address: str | None = None, max_frames: int = MAX_FRAMES,
              progress: bool = True) -> tuple[list[dict[str, Any]], float]:
    """Play ``tasks``; ``(results, wall seconds)``. ``workers`` 0: in this process; else on Ray."""
    from framework.bench.progress import Progress

    t0 = time.perf_counter()
    results: list[dict[str, Any]] = []
    with Progress(len(tasks), "sweep", enabled=progress) as bar:
        if workers == 0:
            for task in tasks:
                bar.task(f"level {task[0]} {task[1]} seed {task[2]}")
                results.append(run_episode(task, max_frames))
                bar.advance()
        else:
            import ray

            started_here = not ray.is_initialized()
            if started_here:
                if address is not None:
                    ray.init(address=address, log_to_driver=False)
                else:
                    ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False)
            try:
                remote = ray.remote(num_cpus=1)(_run_batch)
                # Small batches: enough of them to keep every worker busy to the end.
                size = max(1, len(tasks) // (4 * workers))
                pending = [remote.remote(tasks[i:i + size], max_frames) for i in range(0, len(tasks), size)]
                while pending:
                    done, pending = ray.wait(pending, num_returns=1)
                    batch = ray.get(done[0])
                    results += batch
                    bar.advance(len(batch))
            finally:
                if started_here:
                    ray.shutdown()
    results.sort(key=lambda r: (r["level"], r["agent"], r["seed"]))
    return results, time.perf_counter() - t0


def summarize(results: list[dict[str, Any]], seconds: float, workers: int, level_names: dict[int, str]) -> dict:
    """Completion rate, frames and deaths per level and agent; frames per second."""
    rows = []
    for level in sorted({r["level"] for r in results}):
        for agent in AGENTS:
            rs = [r for r in results if r["level"] == level and r["agent"] == agent]
            if not rs:
                continue
            rows.append({
                "level": level, "name": level_names.get(level, str(level)), "agent": agent, "episodes": len(rs),
                "completion_rate": sum(r["completed"] for r in rs) / len(rs),
                "mean_frames": sum(r["frames"] for r in rs) / len(rs),
                "mean_deaths": sum(r["deaths"] for r in rs) / len(rs),
            })
    frames = sum(r["frames"] for r in results)
    busy = sum(r["seconds"] for r in results)
    return {
        "workers": workers, "episodes": len(results), "frames": frames, "seconds": seconds,
        "frames_per_second": frames / seconds if seconds > 0 else 0.0,
        "frames_per_second_per_worker": frames / busy if busy > 0 else 0.0,
        "rows": rows, "episodes_detail": results,
    }


def plot(summary: dict[str, Any], path: str | Path) -> bool:
    """A bar chart of the completion rate per level and agent (False without matplotlib)."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return False
    rows = summary["rows"]
    levels = sorted({(r["level"], r["name"]) for r in rows})
    fig, ax = plt.subplots(figsize=(6, 3.2))
    for k, agent in enumerate(AGENTS):
        rates = [next((r["completion_rate"] for r in rows if r["level"] == lv and r["agent"] == agent), 0.0)
                 for lv, _ in levels]
        ax.bar([i + 0.38 * (k - 0.5) for i in range(len(levels))], rates, width=0.38, label=agent)
    ax.set_xticks(range(len(levels)), [name for _, name in levels])
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("levels finished (fraction of episodes)")
    ax.set_title(f"{summary['episodes']} episodes, {summary['frames_per_second']:.0f} game frames/s, "
                 f"{summary['workers']} workers", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return True


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(prog=f"python -m {__package__}.sweep", description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=2, help="Ray workers (CPUs); 0: in this process, no Ray")
    ap.add_argument("--episodes", type=int, default=8, help="random-agent episodes per level (seeds 0..M-1)")
    ap.add_argument("--levels", default=None, help="level indices to play, e.g. 0,2 (default: every level)")
    ap.add_argument("--address", default=None, help="a Ray cluster to join (default: start Ray here)")
    ap.add_argument("--max-frames", type=int, default=MAX_FRAMES, help="game frames per episode at most")
    ap.add_argument("--out", default="sweep.json", help="where to write the JSON summary")
    ap.add_argument("--plot", default=None, help="where to write the plot (PNG; needs matplotlib)")
    ap.add_argument("--no-progress", action="store_true", help="no progress bar")
    return ap.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    from .levels import builtin_levels, load_level

    shipped = builtin_levels()

    def fail(message: str) -> int:
        print(f"error: {message}", file=sys.stderr)
        return 2

    if args.workers < 0:
        return fail(f"--workers must be >= 0, got {args.workers}")
    if args.episodes < 1 or args.max_frames < 1:
        return fail(f"--episodes and --max-frames must be >= 1, got {args.episodes} and {args.max_frames}")
    try:
        levels = list(range(len(shipped))) if args.levels is None else [int(v) for v in args.levels.split(",")]
    except ValueError:
        return fail(f"--levels must be level indices separated by commas, got {args.levels!r}")
    for level in levels:
        if not 0 <= level < len(shipped):
            return fail(f"there is no level {level}: the shipped levels are 0 to {len(shipped) - 1}")
    try:
        import gymnasium  # noqa: F401
    except ImportError:
        return fail("the sweep needs the rl extra: pip install -e '.[rl]' (gymnasium is missing)")
    if args.workers > 0:
        try:
            import ray  # noqa: F401
        except ImportError:
            return fail(f"--workers {args.workers} needs Ray (the rl extra: pip install -e '.[rl]'); "
                        "--workers 0 runs in this process without it")
    names = {i: load_level(shipped[i]).name for i in levels}
    results, seconds = run_tasks(tasks_for(levels, args.episodes), args.workers, address=args.address,
                                 max_frames=args.max_frames, progress=not args.no_progress)
    summary = summarize(results, seconds, args.workers, names)
    Path(args.out).write_text(json.dumps(summary, indent=1))
    for r in summary["rows"]:
        print(f"{r['name']:<10} {r['agent']:<9} {r['completion_rate']:6.1%} of {r['episodes']:3d} episodes, "
              f"{r['mean_frames']:7.0f} frames, {r['mean_deaths']:.2f} deaths")
    print(f"{summary['episodes']} episodes, {summary['frames']} frames in {seconds:.1f} s: "
          f"{summary['frames_per_second']:.0f} frames/s "
          f"({summary['frames_per_second_per_worker']:.0f} per busy worker)")
    if args.plot:
        print(f"plot: {args.plot}" if plot(summary, args.plot) else "no plot: matplotlib is not installed")
    print(f"summary: {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
