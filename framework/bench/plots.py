"""The benchmarks' plots (matplotlib, optional: without it the plots are skipped with a note)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .report import optional_module, stderr_note

__all__ = ["plot_accuracy", "plot_perf", "plot_regimes"]


def _pyplot():
    mpl = optional_module("matplotlib")
    if mpl is None:
        return None
    mpl.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, plt, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(path, dpi=110, metadata={"Software": None})  # no version stamp: reruns differ only by data
    plt.close(fig)


def plot_perf(report: dict[str, Any], path: Path) -> bool:
    """Log-log ms per step against N (ours, pymunk, floor, brute force) and the per-stage split."""
    plt = _pyplot()
    if plt is None:
        stderr_note(f"matplotlib is not installed: no plot written to {path} (pip install 'framework[bench]')")
        return False
    rows = report["rows"]
    boxes = sorted((r for r in rows if r["scene"].startswith("boxes-") and "+" not in r["scene"]),
                   key=lambda r: r["bodies"])
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.8))
    n = [r["bodies"] for r in boxes]
    ax.loglog(n, [r["ms_per_step"] for r in boxes], "o-", label="ours: full step")
    if any(r["pymunk_ms_per_step"] for r in boxes):
        ax.loglog(n, [r["pymunk_ms_per_step"] for r in boxes], "s-", label="pymunk: space.step")
    ax.loglog(n, [r["floor_ms"] for r in boxes], "^--", label="floor: SpatialHash.pairs alone")
    brute = [r for r in rows if r["scene"].startswith("brute-force")]
    if brute:
        ax.loglog([r["bodies"] for r in brute], [r["ms_per_step"] for r in brute], "x:", ms=9,
                  label="brute-force detection (numpy, all pairs)")
    for r in rows:
        if "+tiles" in r["scene"]:
            ax.loglog([r["bodies"]], [r["ms_per_step"]], "D", label=f"ours + {r['static']:,} static tiles")
    if n:
        x0, y0 = n[0], boxes[0]["ms_per_step"]
        ax.loglog([x0, n[-1]], [y0, y0 * n[-1] / x0], color="grey", lw=0.8, ls=":", label="slope 1 (linear)")
    ax.set_xlabel("moving boxes N")
    ax.set_ylabel("ms per step (median)")
    ax.set_title("Cost of a step, ~1 pair per box")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")

    staged = [r for r in rows if r["movement_ms"] is not None]
    labels = [r["scene"] for r in staged]
    left = [0.0] * len(staged)
    keys = (("movement_ms", "movement"), ("broad_ms", "broad phase"), ("narrow_ms", "narrow phase"),
            ("response_ms", "response"), ("other_ms", "other"))
    total = [sum(max(0.0, r[k] or 0.0) for k, _ in keys) or 1.0 for r in staged]
    for key, name in keys:
        vals = [max(0.0, r[key] or 0.0) / t * 100 for r, t in zip(staged, total)]
        bx.barh(labels, vals, left=left, label=name)
        left = [a + b for a, b in zip(left, vals)]
    for i, r in enumerate(staged):
        bx.annotate(f"{r['ms_per_step']:.3g} ms", (100, i), xytext=(4, 0), textcoords="offset points",
                    va="center", fontsize=8)
    bx.set_xlim(0, 118)
    bx.set_xlabel("share of the step (%), median of each stage")
    bx.set_title("Where a step's time goes")
    bx.invert_yaxis()
    bx.legend(fontsize=8, ncol=5, loc="upper center", bbox_to_anchor=(0.5, -0.13))
    fig.suptitle(f"python -m framework.bench perf, {report['machine']['date']}", fontsize=9)
    _save(fig, plt, path)
    return True


def plot_accuracy(report: dict[str, Any], path: Path) -> bool:
    """One panel per scenario: the error metric against the knob, with the cost where it differs."""
    plt = _pyplot()
    if plt is None:
        stderr_note(f"matplotlib is not installed: no plot written to {path} (pip install 'framework[bench]')")
        return False
    rows = report["rows"]
    fig, axes = plt.subplots(2, 3, figsize=(15, 8.5))
    (a_bul, a_cost, a_crate), (a_rest, a_crowd, a_ball) = axes

    bullets = [r for r in rows if r["scenario"] == "bullet"]
    for mode in dict.fromkeys(r["mode"] for r in bullets):
        mr = [r for r in bullets if r["mode"] == mode]
        a_bul.semilogx([r["speed"] for r in mr], [100 * r["missed"] for r in mr], "o-", label=mode)
        a_cost.bar(mode, sorted(r["ms_per_step"] for r in mr)[len(mr) // 2])
    a_bul.set_xlabel("bullet speed (units per step; wall 0.25 thick, bullet r 0.125)")
    a_bul.set_ylabel("bullets through the wall (%)")
    a_bul.set_title("Bullets: missed hits")
    a_bul.legend(fontsize=8)
    a_bul.grid(True, alpha=0.3)
    a_cost.set_ylabel("ms per step (median)")
    a_cost.set_title("Bullets: cost of the lanes' step")
    a_cost.tick_params(axis="x", labelrotation=30)

    crates = [r for r in rows if r["scenario"] == "crate"]
    xs = range(len(crates))
    a_crate.bar([x - 0.2 for x in xs], [100 * r["fp_rate"] for r in crates], 0.4, label="false positive")
    a_crate.bar([x + 0.2 for x in xs], [100 * r["fn_rate"] for r in crates], 0.4, label="false negative")
    a_crate.set_xticks(list(xs), [f"{r['mode']}\n{r['ms_per_step']:.2f} ms" for r in crates])
    a_crate.set_ylabel("rate (%)")
    a_crate.set_title("Rotated crates: hitbox approximations")
    a_crate.legend(fontsize=8)

    rest = [r for r in rows if r["scenario"] in ("stack", "character", "character-walk")]
    modes = list(dict.fromkeys(r["mode"] for r in rest))
    for k, scen in enumerate(("stack", "character", "character-walk")):
        sr = {r["mode"]: r for r in rest if r["scenario"] == scen}
        a_rest.bar([i + (k - 1) * 0.27 for i in range(len(modes))],
                   [sr[m]["max_depth"] if m in sr else 0 for m in modes], 0.27, label=f"{scen}: max depth")
    a_rest.set_xticks(range(len(modes)), [m.replace("response-iterations-", "iter-") for m in modes],
                      rotation=30, fontsize=8)
    a_rest.set_ylabel("max penetration after a step (units)")
    a_rest.set_title("Resting bodies (exact answer: 0)")
    a_rest.legend(fontsize=8)

    for scen, ax, key, label in (("crowd", a_crowd, "residual", "overlap left after one step (%)"),
                                 ("ball", a_ball, "energy_drift", "energy drift per 1,000 steps (%)")):
        srows = [r for r in rows if r["scenario"] == scen]
        ax.plot([r["ms_per_step"] for r in srows], [100 * r[key] for r in srows], "o")
        for r in srows:
            ax.annotate(r["mode"].replace("response-iterations-", "iter-"), (r["ms_per_step"], 100 * r[key]),
                        fontsize=8, xytext=(4, 3), textcoords="offset points")
        ax.set_xlabel("ms per step (median)")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    a_crowd.set_title("Crowd of 64 overlapping boxes: accuracy against cost")
    a_ball.set_title("Elastic ball: energy against cost")
    fig.suptitle(f"python -m framework.bench accuracy, {report['machine']['date']}", fontsize=9)
    _save(fig, plt, path)
    return True


def plot_regimes(report: dict[str, Any], path: Path) -> bool:
    """Per scene: ms per step of the three engines (log scale, ours / faster peer written above), and
    the deepest overlap each left (symlog: 0 stays visible)."""
    plt = _pyplot()
    if plt is None:
        stderr_note(f"matplotlib is not installed: no plot written to {path} (pip install 'framework[bench]')")
        return False
    rows = report["rows"]
    names = [r["scene"] for r in rows]
    engines = (("ours", "ours (exact)"), ("soft", "ours (soft)"), ("pymunk", "pymunk"), ("box2d", "Box2D v3 (pyb2d3)"))
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(13, 8.5), sharex=True)
    width = 0.2
    xs = range(len(rows))
    for k, (key, label) in enumerate(engines):
        ms = [r[f"{key}_ms"] or 0.0 for r in rows]
        pen = [r[f"pen_{key}"] if r[f"pen_{key}"] is not None else float("nan") for r in rows]
        if any(ms):
            ax.bar([x + (k - 1.5) * width for x in xs], ms, width, label=label)
            bx.bar([x + (k - 1.5) * width for x in xs], pen, width, label=label)
    for x, r in zip(xs, rows):
        if r["ratio"] is not None:
            top = max(r[f"{k}_ms"] or 0.0 for k, _ in engines)
            label = f"{r['ratio']:.2f}x" if r["ratio"] < 10 else f"{r['ratio']:.0f}x"
            ax.annotate(label, (x, top), xytext=(0, 3), textcoords="offset points", ha="center",
                        fontsize=8, color="black" if r["time_pass"] else "firebrick")
    ax.set_yscale("log")
    ax.set_ylabel("ms per step (median, interleaved)")
    ax.set_title("Cost of a step; label: ours / the faster peer (red: above the issue's goal)")
    ax.grid(True, axis="y", which="both", alpha=0.3)
    ax.legend(fontsize=8)
    bx.set_yscale("symlog", linthresh=1e-3)
    bx.set_ylabel("deepest overlap left (units)")
    bx.set_title("Accuracy: deepest overlap at the end of the run, one oracle (our exact geometry) for all")
    bx.grid(True, axis="y", alpha=0.3)
    bx.set_xticks(list(xs), names, rotation=30, ha="right", fontsize=8)
    fig.suptitle(f"python -m framework.bench regimes, {report['machine']['date']}", fontsize=9)
    _save(fig, plt, path)
    return True


def plot_render(report: dict[str, Any], path: Path) -> bool:
    """Log-log ms per frame against the number of sprites, one panel per kind: ours, the numpy
    floor, a naive pyglet loop and arcade."""
    plt = _pyplot()
    if plt is None:
        stderr_note(f"matplotlib is not installed: no plot written to {path} (pip install 'framework[bench]')")
        return False
    rows = report["rows"]
    kinds = list(dict.fromkeys(r["kind"] for r in rows))
    fig, axes = plt.subplots(1, len(kinds), figsize=(3.6 * len(kinds), 3.8), squeeze=False)
    for ax, kind in zip(axes[0], kinds):
        mine = sorted((r for r in rows if r["kind"] == kind), key=lambda r: r["n"])
        n = [r["n"] for r in mine]
        for key, style, label in (("ours_ms", "o-", "ours"), ("floor_ms", "^--", "floor (numpy, one vertex list)"),
                                  ("naive_ms", "s:", "naive pyglet"), ("arcade_ms", "x-.", "arcade SpriteList")):
            pts = [(x, r[key]) for x, r in zip(n, mine) if r.get(key)]
            if pts:
                ax.loglog(*zip(*pts), style, label=label)
        ax.set_title(kind)
        ax.set_xlabel("moving sprites")
        ax.grid(True, which="both", alpha=0.3)
    axes[0][0].set_ylabel("ms per frame (median)")
    axes[0][0].legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True
