"""``python -m framework.bench perf``: the cost of a step of the full pipeline, against pymunk and the
numpy broad-phase floor.

The workload: ``N`` axis-aligned boxes, sides uniform in [4, 16], velocities uniform in
[-0.5, 0.5] units per step on each axis (``dt = 1``), no gravity, scattered uniformly over a square
of side ``sqrt(N) * 14`` so that there is about one overlapping pair per box. The scene declares
the effects ``movement``, ``detection``, ``events`` and ``response`` (the full pipeline, no
sleeping: every box moves every step). The platformer-scale level adds 100,000 static unit tiles
in a grid well below the movers (they never touch) to the 1,000-box scene.

Method (see the guide's "Measuring"): fixed seeds; each scene is set up, then ``gc.freeze()``;
every timed thing (our step, the same scene stepped by pymunk, the broad-phase floor, the
brute-force baseline) first runs a few warm-up calls, then all of them are timed *interleaved*,
one call each per round in a rotating order, so a noisy machine slows all of them alike and the
ratios hold; each figure is the median over the rounds.

Before timing, on the small sizes, the pipeline's candidate pairs are checked against
:func:`~framework.collision.broad_phase.brute_force_pairs` on the same bounds (with and without
overlapping static tiles); a mismatch raises :class:`PairMismatch`.

Batch queries (:func:`run_queries`): a scene of every shape kind (boxes, circles, capsules,
polygons, turned) over a floor of unit tiles; ``Scene.query_points``, ``nearest_many`` and
``raycast_many`` of 1,000 random points or rays, timed interleaved against the same queries asked
one by one (``query_point``, ``nearest``, ``raycast`` in a Python loop). Their answers are checked
equal first (a mismatch raises :class:`QueryMismatch`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import partial
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from ..arrays import F64Array, I64Array
from ..collision.batch import aabb_aabb
from ..collision.broad_phase import SpatialHash, brute_force_pairs
from ..collision.grid import Bounds
from ..components import Hitbox, Transform, Velocity
from ..geometry import widen_down, widen_up
from ..shapes import AABB
from .progress import Progress
from .report import (
    Column,
    fmt,
    format_table,
    frozen_gc,
    machine_info,
    median,
    optional_module,
    provenance,
    time_call,
)

if TYPE_CHECKING:
    from ..scene import Scene

__all__ = [
    "COLUMNS", "EFFECTS", "PairMismatch", "QUERY_COLUMNS", "QueryMismatch", "Workload", "brute_detection",
    "build_pymunk", "build_scene", "check_pairs", "goals", "make_boxes", "markdown", "query_scene", "run_perf",
    "run_queries", "text_report", "with_tiles",
]

EFFECTS = ("movement", "detection", "events", "response")
SIDE_PER_SQRT_N = 14.0
SIZE_RANGE = (4.0, 16.0)
MAX_SPEED = 0.5
DT = 1.0
TILES = 100_000
FULL: dict[str, Any] = {"sizes": (1_000, 10_000, 50_000), "rounds": {1_000: 100, 10_000: 50, 50_000: 20},
                        "check_up_to": 10_000, "brute_sizes": (1_000, 10_000)}
QUICK: dict[str, Any] = {"sizes": (1_000, 10_000), "rounds": {1_000: 60, 10_000: 25}, "check_up_to": 1_000,
         "brute_sizes": (1_000,)}
WARMUP = 5

#: The documented columns of a row, in table order: (key, header, format).
COLUMNS: list[Column] = [
    ("scene", "scene", "str"),
    ("bodies", "moving", "int"),
    ("static", "static", "int"),
    ("ms_per_step", "ms/step", "ms"),
    ("pymunk_ms_per_step", "pymunk ms", "ms"),
    ("ratio", "ours/pymunk", "ratio"),
    ("pairs", "pairs", "int"),
    ("movement_ms", "movement", "ms"),
    ("broad_ms", "broad", "ms"),
    ("narrow_ms", "narrow", "ms"),
    ("response_ms", "response", "ms"),
    ("other_ms", "other", "ms"),
    ("floor_ms", "floor", "ms"),
    ("floor_ratio", "ours/floor", "ratio"),
]
ROW_KEYS = [k for k, _, _ in COLUMNS] + ["pairs_per_body", "cell_size", "rounds"]


class PairMismatch(AssertionError):
    """The pipeline's candidate pairs differ from the brute-force pairs on the same bounds."""


class QueryMismatch(AssertionError):
    """A batch query's answers differ from the single queries' asked one by one."""


# --- the workload -------------------------------------------------------------------------------------


@dataclass
class Workload:
    """Moving boxes (centres, sizes, velocities per step) and optional static unit tiles (centres)."""

    x: F64Array
    y: F64Array
    w: F64Array
    h: F64Array
    vx: F64Array
    vy: F64Array
    side: float
    tile_x: F64Array = field(default_factory=lambda: np.zeros(0))
    tile_y: F64Array = field(default_factory=lambda: np.zeros(0))

    @property
    def n(self) -> int:
        return int(self.x.size)

    @property
    def tiles(self) -> int:
        return int(self.tile_x.size)


def make_boxes(n: int, seed: int = 0) -> Workload:
    """The issue's workload: ``n`` boxes of side 4-16 in a square of side ``sqrt(n) * 14``.

    Expected overlapping pairs: two boxes overlap when their centres are closer than the mean of
    their sizes on both axes, a target of mean area ``E[wa + wb] * E[ha + hb] = 20 * 20 = 400``, so
    ``n^2 / 2 * 400 / side^2 = 200 n / 196``: about one pair per box at the start (the response
    then pushes boxes apart, and the steady state has somewhat fewer; ``pairs`` reports it).
    """
    rng = np.random.default_rng(seed)
    side = math.sqrt(n) * SIDE_PER_SQRT_N
    lo, hi = SIZE_RANGE
    return Workload(
        x=rng.uniform(0.0, side, n), y=rng.uniform(0.0, side, n),
        w=rng.uniform(lo, hi, n), h=rng.uniform(lo, hi, n),
        vx=rng.uniform(-MAX_SPEED, MAX_SPEED, n), vy=rng.uniform(-MAX_SPEED, MAX_SPEED, n),
        side=side,
    )


def with_tiles(wl: Workload, count: int = TILES, steps: int = 200, overlapping: bool = False) -> Workload:
    """``wl`` plus ``count`` static unit tiles on a unit grid, as wide as the movers' square.

    By default the grid's top row lies below the lowest mover by a margin no mover can cross in
    ``steps`` steps (the platformer-scale level: the tiles cost only where bodies are).
    ``overlapping=True`` scatters the grid's cells over the movers' square instead (for the pair
    check: moving-static pairs must be found too)."""
    cols = max(1, int(math.ceil(wl.side)))
    k = np.arange(count)
    if overlapping:
        rng = np.random.default_rng(count)
        cells = rng.choice(cols * cols, size=min(count, cols * cols), replace=False)
        tx, ty = (cells % cols) + 0.5, (cells // cols) + 0.5
    else:
        top = math.floor(float((wl.y - wl.h / 2).min()) - MAX_SPEED * steps - 2 * SIZE_RANGE[1])
        tx, ty = (k % cols) + 0.5, top - (k // cols) - 0.5
    return replace(wl, tile_x=tx.astype(float), tile_y=ty.astype(float))


def build_scene(wl: Workload, cell_size: float | None = None, effects=EFFECTS):
    """Our scene of the workload (imported lazily: ``framework.scene`` loads esper)."""
    from ..scene import Scene

    scene = Scene(effects=effects, cell_size=cell_size)
    tile = AABB(1.0, 1.0)
    for tx, ty in zip(wl.tile_x.tolist(), wl.tile_y.tolist()):
        scene.spawn(Transform(tx, ty), Hitbox(tile, body="static"))
    for x, y, w, h, vx, vy in zip(*(a.tolist() for a in (wl.x, wl.y, wl.w, wl.h, wl.vx, wl.vy))):
        scene.spawn(Transform(x, y), Velocity(vx, vy), Hitbox(AABB(w, h)))
    return scene


def build_pymunk(wl: Workload, pymunk: Any):
    """The same scene in pymunk: the boxes as ``Poly`` boxes on bodies of mass 1 that cannot rotate
    (our AABBs never turn), the same velocities, no gravity, friction 0, elasticity 0 (pymunk's
    defaults, like our restitution 0); the tiles as static ``Poly`` boxes. ``None`` without pymunk."""
    if pymunk is None:
        return None
    space = pymunk.Space()
    space.gravity = (0.0, 0.0)
    items: list[Any] = []
    for x, y, w, h, vx, vy in zip(*(a.tolist() for a in (wl.x, wl.y, wl.w, wl.h, wl.vx, wl.vy))):
        body = pymunk.Body(1.0, math.inf)
        body.position = (x, y)
        body.velocity = (vx, vy)
        items += [body, pymunk.Poly.create_box(body, (w, h))]
    sb = space.static_body
    for tx, ty in zip(wl.tile_x.tolist(), wl.tile_y.tolist()):
        items.append(pymunk.Poly(sb, [(tx - 0.5, ty - 0.5), (tx + 0.5, ty - 0.5), (tx + 0.5, ty + 0.5),
                                      (tx - 0.5, ty + 0.5)]))
    space.add(*items)
    return space


def mover_boxes(scene: Scene) -> tuple[F64Array, F64Array, F64Array, F64Array, I64Array]:
    """``(x, y, half_width, half_height, entity)`` of the scene's moving boxes, read through the
    public components (independent of the pipeline's own arrays)."""
    rows = [(e, t.x, t.y, hb.shape.half_width, hb.shape.half_height)
            for e, (t, _v, hb) in scene.query(Transform, Velocity, Hitbox)]
    e, x, y, hw, hh = (np.array(c) for c in zip(*rows)) if rows else (np.zeros(0),) * 5
    return x, y, hw, hh, e.astype(np.int64)


def mover_bounds(scene: Scene) -> tuple[F64Array, F64Array, F64Array, F64Array, I64Array]:
    """``(minx, miny, maxx, maxy, entity)`` of the scene's moving boxes (see :func:`mover_boxes`)."""
    x, y, hw, hh, e = mover_boxes(scene)
    return x - hw, y - hh, x + hw, y + hh, e


def tile_bounds(wl: Workload) -> Bounds:
    return wl.tile_x - 0.5, wl.tile_y - 0.5, wl.tile_x + 0.5, wl.tile_y + 0.5


def brute_detection(minx, miny, maxx, maxy):
    """The baseline detection: every pair's bounds tested in numpy (``brute_force_pairs``), then the
    narrow AABB kernel on the pairs found. Returns ``(i, j, contacts)``."""
    i, j = brute_force_pairs(minx, miny, maxx, maxy)
    cx, cy = (minx + maxx) * 0.5, (miny + maxy) * 0.5
    hw, hh = (maxx - minx) * 0.5, (maxy - miny) * 0.5
    return i, j, aabb_aabb(cx[i], cy[i], hw[i], hh[i], cx[j], cy[j], hw[j], hh[j])


# --- the pair check -------------------------------------------------------------------------------------


def check_pairs(wl: Workload, steps: int = 3) -> dict[str, Any]:
    """Step ``wl``'s scene ``steps`` times; at each step compare the pipeline's candidate pairs (their
    count, and the contacts, which for boxes are exactly the strictly overlapping bounds) with
    :func:`brute_force_pairs` on the bounds the broad phase saw. Raises :class:`PairMismatch`."""
    scene = build_scene(wl)
    tb = tile_bounds(wl)
    seen: dict[str, Any] = {}
    n_tiles = wl.tiles
    tile_ids = np.array(sorted(e for e, hb in scene.query(Hitbox) if hb.body.value == "static"), dtype=np.int64)

    def before_broad(s, dt):
        seen["boxes"] = mover_boxes(s)

    def after_narrow(s, dt):
        seen["candidates"] = int(s.counters["candidate_pairs"])
        seen["contacts"] = (s.contacts.a.copy(), s.contacts.b.copy())

    scene.add_system(before_broad, before="broad_phase")
    scene.add_system(after_narrow, after="narrow_phase")
    checked = []
    try:
        for k in range(steps):
            scene.step(DT)
            x, y, hw, hh, ents = seen["boxes"]
            allb = [np.concatenate([m, t]) for m, t in zip((x - hw, y - hh, x + hw, y + hh), tb)]
            cx, cy = np.concatenate([x, wl.tile_x]), np.concatenate([y, wl.tile_y])
            ex, ey = np.concatenate([hw, np.full(n_tiles, 0.5)]), np.concatenate([hh, np.full(n_tiles, 0.5)])
            ids = np.concatenate([ents, tile_ids])
            static = np.concatenate([np.zeros(ents.size, bool), np.ones(n_tiles, bool)])
            # The pipeline widens every bound by an ulp or two (see framework.geometry), so its
            # candidates are the brute-force overlaps of the widened bounds; its contacts, those of
            # the exact ones.
            wide = [(widen_down if k_ < 2 else widen_up)(v) for k_, v in enumerate(allb)]
            i, j = brute_force_pairs(wide[0], wide[1], wide[2], wide[3], static=static)
            if seen["candidates"] != i.size:
                raise PairMismatch(f"step {k}: the broad phase found {seen['candidates']} candidate pairs, "
                                   f"brute force {i.size} (N={wl.n}, tiles={n_tiles})")
            hit = aabb_aabb(cx[i], cy[i], ex[i], ey[i], cx[j], cy[j], ex[j], ey[j]).hit  # exact
            i, j = i[hit], j[hit]
            a, b = np.minimum(ids[i], ids[j]), np.maximum(ids[i], ids[j])
            order = np.lexsort((b, a))
            want = (a[order], b[order])
            got = seen["contacts"]
            if not (np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])):
                gs, ws = set(zip(*(g.tolist() for g in got))), set(zip(*(w.tolist() for w in want)))
                raise PairMismatch(f"step {k}: pipeline pairs != brute force (N={wl.n}, tiles={n_tiles}): "
                                   f"missing {sorted(ws - gs)[:5]}, extra {sorted(gs - ws)[:5]}")
            checked.append(int(want[0].size))
    finally:
        scene.close()
    return {"bodies": wl.n, "static": n_tiles, "steps": steps, "pairs": checked, "ok": True}


# --- timing ---------------------------------------------------------------------------------------------


@dataclass
class Task:
    """Something timed: ``fn`` is timed, ``after`` (not timed) records what the call produced."""

    name: str
    fn: Callable[[], Any]
    after: Callable[[], dict[str, float]] | None = None
    every: int = 1  # time it only every ``every``-th round (slow baselines)
    ms: list[float] = field(default_factory=list)
    extra: list[dict[str, float]] = field(default_factory=list)


def run_interleaved(tasks: list[Task], rounds: int, warmup: int = WARMUP, bar: Progress | None = None) -> None:
    """Warm every task up, then time one call of each per round, starting each round with the next
    task (rotating), so that every task sees the machine's noise alike."""
    for t in tasks:
        for _ in range(warmup if t.every == 1 else 1):
            t.fn()
    with frozen_gc():
        for r in range(rounds):
            k = r % len(tasks)
            for t in tasks[k:] + tasks[:k]:
                if r % t.every:
                    continue
                ms, _ = time_call(t.fn)
                t.ms.append(ms)
                if t.after is not None:
                    t.extra.append(t.after())
            if bar is not None:
                bar.advance()


def _stage_recorder(scene) -> Callable[[], dict[str, float]]:
    def after() -> dict[str, float]:
        out = dict(scene.stage_ms)
        out["pairs"] = float(scene.counters.get("candidate_pairs", 0))
        return out
    return after


def _scene_tasks(label: str, wl: Workload, pymunk: Any) -> tuple[list[Task], dict[str, Any]]:
    """Tasks of one scene: ours, pymunk's (if installed) and the floor on the same bounds."""
    scene = build_scene(wl)
    for _ in range(WARMUP):  # builds the hash, fixes the cell size, lets the first push-outs happen
        scene.step(DT)
    space = build_pymunk(wl, pymunk)
    if space is not None:
        space.step(DT)
    minx, miny, maxx, maxy, ents = mover_bounds(scene)
    floor_hash = SpatialHash(scene.hash.cell_size)  # on the bounds of the state the timing starts from
    if wl.tiles:
        floor_hash.set_static(*tile_bounds(wl), np.arange(wl.tiles, dtype=np.int64) + int(ents.max()) + 1)
    tasks = [Task(f"{label}/ours", lambda: scene.step(DT), _stage_recorder(scene))]
    if space is not None:
        tasks.append(Task(f"{label}/pymunk", lambda: space.step(DT)))
    tasks.append(Task(f"{label}/floor", lambda: floor_hash.pairs(minx, miny, maxx, maxy, ents)))
    ctx = {"scene": scene, "space": space, "bounds": (minx, miny, maxx, maxy), "cell_size": scene.hash.cell_size}
    return tasks, ctx


def _row(name: str, wl: Workload, tasks: dict[str, Task], label: str, ctx: dict[str, Any]) -> dict[str, Any]:
    ours = tasks[f"{label}/ours"]
    pm = tasks.get(f"{label}/pymunk")
    floor = tasks[f"{label}/floor"]
    ms = cast(float, median(ours.ms))  # (timed rounds: never empty)
    stages = {k: median(e.get(k, 0.0) for e in ours.extra) for k in
              ("movement", "broad_phase", "narrow_phase", "response")}
    pm_ms = median(pm.ms) if pm is not None else None
    floor_ms = cast(float, median(floor.ms))
    pairs = median(e["pairs"] for e in ours.extra)
    # the rest of the median step: validation, hooks, event bookkeeping outside the stages, timing
    other = max(0.0, ms - sum(v for v in stages.values() if v is not None))
    return {
        "scene": name, "bodies": wl.n, "static": wl.tiles, "ms_per_step": ms, "pymunk_ms_per_step": pm_ms,
        "ratio": ms / pm_ms if pm_ms else None, "pairs": pairs,
        "movement_ms": stages["movement"], "broad_ms": stages["broad_phase"], "narrow_ms": stages["narrow_phase"],
        "response_ms": stages["response"], "other_ms": other,
        "floor_ms": floor_ms, "floor_ratio": ms / floor_ms if floor_ms else None,
        "pairs_per_body": pairs / wl.n if pairs is not None else None,
        "cell_size": ctx["cell_size"], "rounds": len(ours.ms),
    }


def _label(n: int) -> str:
    return f"{n // 1000}k" if n % 1000 == 0 else str(n)


def _brute_row(label: str, n: int, brute: Task, hash_row: dict[str, Any]) -> dict[str, Any]:
    """The brute-force baseline's row, beside the hashed scene's row of the same size."""
    return {
        "scene": f"brute-force-{label}", "bodies": n, "static": 0, "ms_per_step": median(brute.ms),
        "pymunk_ms_per_step": None, "ratio": None, "pairs": hash_row["pairs"],
        "movement_ms": None, "broad_ms": None, "narrow_ms": None, "response_ms": None, "other_ms": None,
        "floor_ms": hash_row["floor_ms"],
        "floor_ratio": median(brute.ms) / hash_row["floor_ms"] if hash_row["floor_ms"] else None,
        "pairs_per_body": hash_row["pairs_per_body"], "cell_size": None, "rounds": len(brute.ms),
    }


# --- batch queries against a loop of single queries ----------------------------------------------------

#: The columns of the batch-query rows: (key, header, format).
QUERY_COLUMNS: list[Column] = [
    ("query", "query", "str"),
    ("queries", "queries", "int"),
    ("bodies", "bodies", "int"),
    ("batch_ms", "batch ms", "ms"),
    ("loop_ms", "loop ms", "ms"),
    ("speedup", "loop/batch", "ratio"),
    ("batch_us_per_query", "us/query", "ms"),
]


def query_scene(bodies: int = 1_000, tiles: int = 400, seed: int = 0) -> Scene:
    """A scene of ``bodies`` hitboxes of every kind (boxes, circles, capsules, polygons), turned, over a
    floor of ``tiles`` unit tiles, all static (what a game queries between steps)."""
    from ..scene import Scene
    from ..shapes import Capsule, Circle, Polygon

    rng = np.random.default_rng(seed)
    side = math.sqrt(bodies) * 6.0
    hexagon = Polygon([(math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)) for k in range(6)])
    shapes = [AABB(2.0, 1.0), Circle(0.75), Capsule(0.4, 1.5), hexagon, Polygon.box(2.0, 0.5)]
    scene = Scene()
    for k in range(bodies):
        x, y = rng.uniform(0.0, side, 2)
        scene.spawn(Transform(float(x), float(y), float(rng.uniform(0.0, 2.0 * math.pi))),
                    Hitbox(shapes[k % len(shapes)], body="static", layer=1 + k % 2))
    for k in range(tiles):
        scene.spawn(Transform(-0.5 * tiles + k + 0.5 + 0.5 * side, -1.5), Hitbox(AABB(1.0, 1.0), body="static"))
    scene.step(DT)
    return scene


def _same(batch: Any, loop: list[Any]) -> bool:
    """Whether a batch answer (PointHits, NearestMany or RayHits) equals the single answers."""
    if hasattr(batch, "offsets"):
        return all(batch.of(i) == one for i, one in enumerate(loop))
    for i, one in enumerate(loop):
        if one is None:
            if batch.entity[i] != -1:
                return False
            continue
        got = [int(batch.entity[i]), float(batch.distance[i]), tuple(batch.point[i].tolist())]
        want = [one.entity, one.distance, tuple(one.point)]
        if hasattr(batch, "normal"):
            got.append(tuple(batch.normal[i].tolist()))
            want.append(tuple(one.normal))
        if got != want:
            return False
    return True


def run_queries(queries: int = 1_000, bodies: int = 1_000, tiles: int = 400, rounds: int = 10, seed: int = 0,
                loop_sample: int = 200, bar: Progress | None = None) -> list[dict[str, Any]]:
    """Time each batch query against a Python loop of the single query (interleaved rounds); rows of
    :data:`QUERY_COLUMNS`. The loop asks the first ``loop_sample`` queries only (a loop of 1,000
    unbounded ``nearest`` takes seconds) and its time is scaled to all of them (it is linear:
    each query is asked on its own). The answers are compared first, on the loop's queries:
    :class:`QueryMismatch` if they differ."""
    scene = query_scene(bodies, tiles, seed)
    rng = np.random.default_rng(seed + 1)
    side = math.sqrt(bodies) * 6.0
    pts = rng.uniform(-2.0, side + 2.0, (queries, 2))
    dirs = rng.normal(size=(queries, 2))
    k = min(queries, loop_sample)
    plist = [tuple(p) for p in pts[:k].tolist()]
    dlist = [tuple(d) for d in dirs[:k].tolist()]
    reach = side / 4.0
    cases: list[tuple[str, Callable[[], Any], Callable[[], Any]]] = [
        ("query_points", lambda: scene.query_points(pts), lambda: [scene.query_point(*p) for p in plist]),
        ("nearest_many", lambda: scene.nearest_many(pts), lambda: [scene.nearest(p) for p in plist]),
        ("nearest_many (max_distance 2)", lambda: scene.nearest_many(pts, max_distance=2.0),
         lambda: [scene.nearest(p, max_distance=2.0) for p in plist]),
        (f"raycast_many (max_distance {reach:.0f})", lambda: scene.raycast_many(pts, dirs, max_distance=reach),
         lambda: [scene.raycast(p, d, max_distance=reach) for p, d in zip(plist, dlist)]),
        ("raycast_many", lambda: scene.raycast_many(pts, dirs),
         lambda: [scene.raycast(p, d) for p, d in zip(plist, dlist)]),
    ]
    tasks = []
    for name, batch, loop in cases:
        if not _same(batch(), loop()):
            scene.close()
            raise QueryMismatch(f"{name}: the batch's answers differ from the single queries' one by one")
        tasks += [Task(f"{name}/batch", batch), Task(f"{name}/loop", loop)]
    run_interleaved(tasks, rounds, warmup=1, bar=bar)
    scene.close()
    by = {t.name: t for t in tasks}
    rows = []
    for name, _, _ in cases:
        b = cast(float, median(by[f"{name}/batch"].ms))
        lp = cast(float, median(by[f"{name}/loop"].ms)) * queries / k
        rows.append({"query": name, "queries": queries, "bodies": bodies + tiles, "batch_ms": b, "loop_ms": lp,
                     "speedup": lp / b if b else None, "batch_us_per_query": b / queries * 1000.0,
                     "loop_sample": k})
    return rows


def run_perf(
    sizes: tuple[int, ...] = FULL["sizes"],
    rounds: dict[int, int] | None = None,
    tiles: int = TILES,
    tile_bodies: int | None = 1_000,
    brute_sizes: tuple[int, ...] = (1_000,),
    check_up_to: int = 1_000,
    seed: int = 0,
    progress: bool = True,
    quick: bool = False,
    queries: int = 1_000,
    query_rounds: int = 10,
    query_bodies: int = 1_000,
) -> dict[str, Any]:
    """Run the benchmark; return the report (``rows``, ``goals``, ``checks``, ``workload``, ``machine``).

    ``tile_bodies``: the movers of the platformer-scale level (``None``: no tiles rows); its rows are
    timed in the same rounds as the plain scene of that size. Any size works (tests use tiny ones).
    ``queries``: how many points or rays each batch query of :func:`run_queries` asks (0: none), in
    ``query_rounds`` rounds over a scene of ``query_bodies`` bodies.
    """
    pymunk = optional_module("pymunk")
    rounds = dict(rounds or {})
    sizes = tuple(sorted(set(sizes) | ({tile_bodies} if tile_bodies else set())))
    groups: list[tuple[int, int]] = [(n, rounds.get(n, 20)) for n in sizes]
    total = sum(r for _, r in groups) + len(sizes) + (query_rounds if queries else 0)
    checks: list[dict[str, Any]] = []
    rows: list[dict[str, Any]] = []
    with Progress(total, "perf", enabled=progress) as bar:
        for n in sizes:
            if n <= check_up_to:
                bar.task(f"pair check {_label(n)}")
                wl = make_boxes(n, seed)
                checks.append(check_pairs(wl))
                checks.append(check_pairs(with_tiles(wl, count=2 * n, overlapping=True)))
            bar.advance()
        for n, r in groups:
            label = _label(n)
            bar.task(f"set-up {label}")
            wl = make_boxes(n, seed)
            tasks, ctx = _scene_tasks(label, wl, pymunk)
            ctx_t = None
            if tile_bodies == n and tiles:
                wlt = with_tiles(wl, tiles, steps=WARMUP + r + 10)
                t_tasks, ctx_t = _scene_tasks(label + "+tiles", wlt, pymunk)
                tasks += t_tasks
            brute = None
            if n in brute_sizes:
                minx, miny, maxx, maxy = ctx["bounds"]
                every = 1 if n <= 2_000 else max(1, r // 8)
                brute = Task(f"{label}/brute", partial(brute_detection, minx, miny, maxx, maxy), every=every)
                tasks.append(brute)
            bar.task(f"timing {label}" + (" (with the tiles level)" if ctx_t else ""))
            run_interleaved(tasks, r, bar=bar)
            by = {t.name: t for t in tasks}
            rows.append(_row(f"boxes-{label}", wl, by, label, ctx))
            if ctx_t is not None:
                rows.append(_row(f"boxes-{label}+tiles-{_label(tiles)}", wlt, by, label + "+tiles", ctx_t))
            if brute is not None:
                rows.append(_brute_row(label, n, brute, rows[-1 if ctx_t is None else -2]))
            for c in (ctx, ctx_t):
                if c is not None:
                    c["scene"].close()
        query_rows: list[dict[str, Any]] = []
        if queries:
            bar.task(f"batch queries ({queries:,} each)")
            query_rows = run_queries(queries, bodies=query_bodies, tiles=min(400, query_bodies), rounds=query_rounds,
                                     seed=seed, bar=bar)
    report = {
        "benchmark": "perf",
        "quick": quick,
        "machine": machine_info(),
        "workload": {
            "boxes": "AABB, width and height uniform in [4, 16]", "velocity": "uniform in [-0.5, 0.5] per axis",
            "dt": DT, "world_side": "sqrt(N) * 14", "gravity": [0.0, 0.0], "effects": list(EFFECTS),
            "tiles": f"{tiles} static unit tiles on a unit grid below the movers, never touched",
            "seed": seed, "warmup": WARMUP,
            "brute_force": "brute_force_pairs + the AABB narrow kernel (detection only)",
            "floor": "SpatialHash.pairs alone on the same bounds and cell size",
            "queries": "query_scene(1,000 bodies of every kind + 400 tiles); 1,000 random points / rays per batch "
                       "against a Python loop of the single query (answers checked equal first)",
        },
        "rows": rows,
        "checks": checks,
        "queries": query_rows,
    }
    report["goals"] = goals(rows)
    return report


# --- goals and text -------------------------------------------------------------------------------------


def _find(rows, scene):
    return next((r for r in rows if r["scene"] == scene), None)


def loglog_slope(rows: list[dict[str, Any]]) -> tuple[float | None, str]:
    """Least-squares slope of log(ms/step) against log(N) over the plain box rows."""
    pts = [(r["bodies"], r["ms_per_step"]) for r in rows
           if r["scene"].startswith("boxes-") and "+" not in r["scene"] and r["ms_per_step"]]
    pts.sort()
    if len(pts) < 2:
        return None, ""
    lx, ly = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
    return float(np.polyfit(lx, ly, 1)[0]), f"{_label(pts[0][0])}..{_label(pts[-1][0])}"


def goals(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The issue's goal figures, computed from the rows (``value`` ``None`` when a row is missing)."""
    out = []
    r10 = _find(rows, "boxes-10k")
    tiles = next((r for r in rows if "+tiles" in r["scene"]), None)
    plain = _find(rows, tiles["scene"].split("+")[0]) if tiles else None
    slope, span = loglog_slope(rows)
    figures = [
        ("ours / pymunk at 10k", r10 and r10["ratio"], 0.5),
        ("ours / broad-phase floor at 10k", r10 and r10["floor_ratio"], 3.0),
        (f"tiles / no tiles ({_label(tiles['bodies']) if tiles else '?'} movers, "
         f"{_label(tiles['static']) if tiles else '?'} tiles)",
         tiles and plain and tiles["ms_per_step"] / plain["ms_per_step"], 1.25),
        (f"log-log slope of ms/step, {span or 'n/a'}", slope, 1.05),
    ]
    for name, value, target in figures:
        out.append({"goal": name, "value": value, "target": target,
                    "pass": None if value is None else bool(value <= target)})
    return out


GOAL_COLUMNS: list[Column] = [("goal", "goal", "str"), ("value", "value", "g"), ("target", "target (<=)", "ratio"),
                              ("verdict", "result", "str")]


def _goal_rows(report):
    return [dict(g, verdict={True: "pass", False: "FAIL", None: "n/a"}[g["pass"]]) for g in report["goals"]]


def notes(report: dict[str, Any]) -> list[str]:
    """Observations computed from the rows (so they stay true when the numbers move)."""
    rows = report["rows"]
    out = []
    plain = [r for r in rows if r["scene"].startswith("boxes-") and "+" not in r["scene"]]
    if plain:
        big = max(plain, key=lambda r: r["bodies"])
        parts = {"movement": big["movement_ms"], "broad phase": big["broad_ms"], "narrow phase": big["narrow_ms"],
                 "response": big["response_ms"], "other": big["other_ms"]}
        tot = sum(v or 0.0 for v in parts.values()) or 1.0
        shares = ", ".join(f"{k} {100 * (v or 0.0) / tot:.0f}%" for k, v in
                           sorted(parts.items(), key=lambda kv: -(kv[1] or 0.0)))
        out.append(f"At {big['bodies']:,} boxes the step splits: {shares}.")
        out.append("Pairs per box during the timed steps: "
                   + ", ".join(f"{_label(r['bodies'])} {r['pairs_per_body']:.2f}" for r in plain)
                   + " (about 1.0 at set-up; the response pushes boxes apart, so the steady state has fewer).")
    tiles = next((r for r in rows if "+tiles" in r["scene"]), None)
    base = tiles and _find(rows, tiles["scene"].split("+")[0])
    if tiles and base:
        out.append(
            f"Tiles level: the scene's automatic cell size is {tiles['cell_size']:.3g} (about twice the larger "
            f"median extent, of the movers or of the tiles) against {base['cell_size']:.3g} without tiles; "
            f"broad phase {fmt(tiles['broad_ms'], 'ms')} ms against {fmt(base['broad_ms'], 'ms')} ms "
            f"(floor {fmt(tiles['floor_ms'], 'ms')} against {fmt(base['floor_ms'], 'ms')}), response "
            f"{fmt(tiles['response_ms'], 'ms')} against {fmt(base['response_ms'], 'ms')} ms, movement "
            f"{fmt(tiles['movement_ms'], 'ms')} against {fmt(base['movement_ms'], 'ms')} ms, for the same "
            f"{tiles['bodies']:,} movers and the same pairs ({tiles['pairs']:.0f} and {base['pairs']:.0f}).")
    return out


def _query_lines(report: dict[str, Any]) -> list[str]:
    rows = report.get("queries") or []
    if not rows:
        return []
    return ["", format_table(rows, QUERY_COLUMNS), "",
            f"Batch queries: each answers {rows[0]['queries']:,} points or rays over {rows[0]['bodies']:,} hitboxes in "
            "one compiled pass; loop ms is the same queries asked one by one in Python (timed on the first "
            f"{rows[0]['loop_sample']:,} and scaled; their answers equal, checked before timing); loop/batch is the "
            "speed-up."]


def text_report(report: dict[str, Any]) -> str:
    m = report["machine"]
    lines = [
        f"perf{' --quick' if report['quick'] else ''}: {m['date']}, Python {m['python']}, numpy {m['numpy']}, "
        f"pymunk {m['pymunk'] or 'absent'}, {m['cpus']} cpus",
        "N boxes 4-16, |v| <= 0.5/step per axis, dt = 1, side sqrt(N)*14, no gravity; "
        "effects movement+detection+events+response; median ms over interleaved rounds",
        "",
        format_table(report["rows"], COLUMNS),
        "",
        format_table(_goal_rows(report), GOAL_COLUMNS),
        "",
        "pair checks (pipeline == brute_force_pairs): "
        + ", ".join(f"{c['bodies']} moving + {c['static']} static: ok" for c in report["checks"]),
        *notes(report),
        *_query_lines(report),
    ]
    if m["pymunk"] is None:
        lines.append("pymunk is not installed (pip install 'framework[bench]'): its columns are empty.")
    return "\n".join(lines)


def markdown(report: dict[str, Any], command: str, plot: str | None) -> str:
    """The generated part of docs/performance.md."""
    m = report["machine"]
    parts = [
        provenance(m, command, f"pymunk {m['pymunk'] or 'absent'}", "perf"),
        "",
        "### Steps (median ms per step; stage columns from `scene.stage_ms`)",
        "",
        format_table(report["rows"], COLUMNS),
        "",
        "### Goals of the issue",
        "",
        format_table(_goal_rows(report), GOAL_COLUMNS),
        "",
        "Pair check before timing (the pipeline's candidate pairs == `brute_force_pairs` on the same "
        "bounds, 3 steps each): " + ", ".join(f"{c['bodies']:,} moving + {c['static']:,} static"
                                              for c in report["checks"]) + ": all equal.",
        "",
        *(f"- {n}" for n in notes(report)),
        *(["", "### Batch queries against a loop of single queries", ""] + _query_lines(report)[1:]
          if report.get("queries") else []),
    ]
    if plot:
        parts += ["", f"![ms per step against N, log-log, and the per-stage split]({plot})"]
    return "\n".join(parts)
