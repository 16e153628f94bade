"""The benchmarks' reference answers and accuracy claims (``python -m framework.bench``).

Tiny configurations only: the module functions are called with small sizes. Times are reported by
the benchmarks, never asserted here.
"""

from __future__ import annotations

import io
import json
import math

import numpy as np
import pytest

from framework import AABB, Circle
from framework.bench import accuracy as acc
from framework.bench import perf
from framework.bench import regimes as reg
from framework.bench.__main__ import main
from framework.bench.progress import Progress
from framework.bench.report import format_table, replace_generated, to_json, write_csv
from framework.collision import time_of_impact

shapely = pytest.importorskip("shapely")
from shapely.geometry import Polygon as ShapelyPolygon  # noqa: E402


def tiny_perf(**kw):
    args = dict(sizes=(48, 96), rounds={48: 3, 96: 3}, tiles=300, tile_bodies=48, brute_sizes=(48,),
                check_up_to=96, progress=False, queries=30, query_rounds=1, query_bodies=40)
    args.update(kw)
    return perf.run_perf(**args)


# --- reference answers --------------------------------------------------------------------------------


@pytest.mark.parametrize("speed", [0.125, 1.0, 7.5, 64.0])
def test_analytic_bullet_toi_equals_time_of_impact(speed):
    x0s, dys = acc.bullet_lanes(16, speed, seed=3)
    wall = AABB(acc.WALL_THICKNESS, acc.WALL_HEIGHT)
    for x0, dy in zip(x0s.tolist(), dys.tolist()):
        t = acc.analytic_bullet_toi(x0, speed)
        assert 1.0 <= t <= 2.0
        k = math.floor(t)  # the step in which the bullet first touches, and the fraction of it
        imp = time_of_impact(Circle(acc.BULLET_RADIUS), (x0 + k * speed, dy, 0.0), (speed, 0.0), wall, (0.0, 0.0, 0.0))
        assert imp is not None
        assert imp.fraction == pytest.approx(t - k, rel=1e-9, abs=1e-12)
        assert imp.normal == (1.0, 0.0)
        # over the whole run at once: the same moment
        whole = time_of_impact(Circle(acc.BULLET_RADIUS), (x0, dy, 0.0), (4 * speed, 0.0), wall, (0.0, 0.0, 0.0))
        assert whole.fraction * 4 == pytest.approx(t, rel=1e-9)


def _corners(x, y, w, h, theta):
    c, s = math.cos(theta), math.sin(theta)
    return [(x + c * px - s * py, y + s * px + c * py) for px, py in
            ((-w / 2, -h / 2), (w / 2, -h / 2), (w / 2, h / 2), (-w / 2, h / 2))]


def test_exact_crate_contact_equals_shapely_intersection():
    p = acc.crate_placements(600, seed=7)
    exact = acc.crates_overlap_exact(p)
    assert 0.3 < exact.mean() < 0.85  # both answers well represented
    for i in range(exact.size):
        a = ShapelyPolygon(_corners(p["ax"][i], p["ay"][i], p["aw"][i], p["ah"][i], p["at"][i]))
        b = ShapelyPolygon(_corners(p["bx"][i], p["by"][i], p["bw"][i], p["bh"][i], p["bt"][i]))
        assert exact[i] == (a.intersection(b).area > 0.0), i


def test_exact_crate_contact_touching_is_not_contact():
    p = {k: np.array([v]) for k, v in dict(ax=0.0, ay=0.0, aw=2.0, ah=1.0, at=0.0,
                                           bx=2.0, by=0.0, bw=2.0, bh=1.0, bt=0.0).items()}
    assert not acc.crates_overlap_exact(p)[0]
    p["bx"] = np.array([1.75])
    assert acc.crates_overlap_exact(p)[0]


def test_crate_hitbox_shapes():
    assert acc.crate_hitbox("aabb", 2.0, 1.0, 0.5) == AABB(2.0, 1.0)
    turned = acc.crate_hitbox("aabb-bounds", 2.0, 1.0, math.pi / 2)
    assert (turned.width, turned.height) == (pytest.approx(1.0), pytest.approx(2.0))
    assert acc.crate_hitbox("circle", 2.0, 1.0, 0.0).radius == pytest.approx(math.sqrt(2.0 / math.pi))
    with pytest.raises(ValueError, match="unknown crate mode"):
        acc.crate_hitbox("ellipse", 1.0, 1.0, 0.0)


# --- accuracy claims ----------------------------------------------------------------------------------


def test_swept_detection_misses_no_bullet_at_any_speed():
    for speed in (0.25, 1.0, 8.0, 64.0):
        row = acc.run_bullets("swept", speed, lanes=8)
        assert row["missed"] == 0.0 and row["undetected"] == 0.0, row
        assert row["stop_error"] < 1e-5  # stopped at the analytic contact position


def test_discrete_detection_misses_fast_bullets_but_not_slow_ones():
    assert acc.run_bullets("discrete", 0.125, lanes=8)["missed"] == 0.0
    fast = acc.run_bullets("discrete", 64.0, lanes=8)
    assert fast["missed"] > 0.5 and fast["undetected"] > 0.5


def test_substeps_catch_what_their_smaller_step_allows():
    # at 1 unit per step, 8 sub-steps move 1/8 per sub-step: less than the wall's half-thickness
    # plus the bullet's radius, so none passes; one step does let bullets through
    assert acc.run_bullets("substeps-8", 1.0, lanes=8)["missed"] == 0.0
    assert acc.run_bullets("discrete", 1.0, lanes=8)["missed"] > 0.0


def test_polygon_hitboxes_are_exact_and_bounds_never_miss():
    poly = acc.run_crates("polygon", count=150, steps=1)
    assert poly["fp_rate"] == 0.0 and poly["fn_rate"] == 0.0
    bounds = acc.run_crates("aabb-bounds", count=150, steps=1)
    assert bounds["fn_rate"] == 0.0 and bounds["fp_rate"] > 0.0
    box = acc.run_crates("aabb", count=150, steps=1)
    assert box["fp_rate"] > 0.0 and box["fn_rate"] > 0.0


def test_more_response_iterations_leave_less_overlap_in_a_crowd():
    one = acc.run_crowd("response-iterations-1", crowds=2)
    eight = acc.run_crowd("response-iterations-8", crowds=2)
    assert eight["residual"] < one["residual"]


@pytest.mark.slow
def test_substeps_reduce_the_elastic_balls_energy_drift():
    one = acc.run_ball("substeps-1", steps=300)
    four = acc.run_ball("substeps-4", steps=300)
    assert abs(four["energy_drift"]) < abs(one["energy_drift"])


@pytest.mark.slow
def test_friction_rows_meet_the_analytic_answers():
    # The crate stops v dt / 2 short of v^2 / (2 mu g) (semi-implicit Euler: 1/60 of 2.5 at one
    # sub-step, a quarter of that at four); the rest is exact to rounding.
    for mode, short in (("substeps-1", 1 / 60), ("substeps-4", 1 / 240)):
        row = acc.run_friction("crate-stop", mode)
        assert row["expected"] == 2.5 and row["rel_error"] == pytest.approx(short, rel=1e-9)
    for case in ("slope-hold", "slope-slide", "disk-roll", "disk-slip"):
        row = acc.run_friction(case, "substeps-1")
        assert row["rel_error"] < 1e-12, (case, row)


def test_pendulum_period_is_the_small_angle_one_corrected_for_amplitude():
    small = 2 * math.pi * math.sqrt(1.0 / 20.0)
    assert acc.pendulum_period(1.0, 20.0, 1e-9) == pytest.approx(small, rel=1e-15)
    a = 0.05  # the series: 1 + a^2 / 16 + 11 a^4 / 3072 + ...
    assert acc.pendulum_period(1.0, 20.0, a) / small == pytest.approx(1 + a * a / 16 + 11 * a ** 4 / 3072, rel=1e-10)
    assert acc.pendulum_period(1.0, 9.81, math.pi / 2) == pytest.approx(1.18034 * 2 * math.pi / math.sqrt(9.81),
                                                                        rel=1e-5)  # 90 degrees: 1.18034 times


@pytest.mark.parametrize("case", ["pendulum-distance", "pendulum-revolute"])
def test_soft_pendulum_swings_at_its_exact_period(case):
    row = acc.run_joint(case, "soft", periods=2)
    assert row["scenario"] == "joints" and row["case"] == case and list(row) == acc.ROW_KEYS
    assert row["rel_error"] < 2e-4 and row["measured"] == pytest.approx(row["expected"], rel=2e-4)
    assert 0.0 <= row["max_stretch"] < 1e-3 and abs(row["apex_drop"]) < 5e-3


def test_rope_rows_measure_its_stretch():
    for case in ("rope-20-hanging", "rope-20-swinging"):
        row = acc.run_joint(case, "soft", steps=30)
        assert row["expected"] == 5.0 and row["measured"] == pytest.approx(5.0 * (1 + row["rel_error"]))
        assert 0.0 < row["rel_error"] <= row["max_stretch"] < 0.1, row  # a few percent at most, never negative


@pytest.mark.parametrize("case", ["offset-spin", "offset-throw"])
def test_centre_of_mass_rows_soft_turns_about_it_exact_about_the_origin(case):
    """The accuracy report's centre-of-mass case (issue 38): the soft solver keeps the centre of a
    spinning offset box on its exact path to rounding; the exact solver turns it about its origin,
    so the centre swings round it, a full diameter (2 x the offset 1) off in a turn."""
    soft = acc.run_mass(case, "soft")
    exact = acc.run_mass(case, "substeps-1")
    assert soft["scenario"] == "mass" and list(soft) == acc.ROW_KEYS and soft["expected"] == 0.0
    assert soft["measured"] < 1e-9 and soft["rel_error"] == soft["measured"] / acc.MASS_OFFSET
    assert exact["measured"] == pytest.approx(2.0 * acc.MASS_OFFSET, rel=1e-3)


def test_resting_stack_metrics_have_the_documented_keys():
    row = acc.run_rest("stack", "response-iterations-4", steps=20)
    assert row["max_depth"] >= 0.0 and row["jitter"] >= 0.0 and row["snags"] is None
    walk = acc.run_rest("character-walk", "response-iterations-4", steps=20)
    assert isinstance(walk["snags"], int)


# --- the perf benchmark -------------------------------------------------------------------------------


def test_perf_pipeline_pairs_equal_brute_force():
    wl = perf.make_boxes(300, seed=5)
    out = perf.check_pairs(wl)
    # About one pair per box at the start; the response then pushes them apart (the contact solver
    # leaves fewer overlapping after each step than the old push-out passes did, so the later steps
    # have fewer pairs to check, but still some: boxes keep running into each other).
    assert out["ok"] and out["pairs"][0] > 250 and min(out["pairs"]) > 20
    tiled = perf.check_pairs(perf.with_tiles(wl, count=600, overlapping=True))
    assert tiled["ok"] and tiled["pairs"][0] > out["pairs"][0]  # the moving-static pairs are found too


def test_perf_pair_check_fails_loudly(monkeypatch):
    real = perf.brute_force_pairs

    def one_pair_short(*a, **k):
        i, j = real(*a, **k)
        return i[1:], j[1:]

    monkeypatch.setattr(perf, "brute_force_pairs", one_pair_short)
    with pytest.raises(perf.PairMismatch, match="candidate pairs"):
        perf.check_pairs(perf.make_boxes(100, seed=1), steps=1)


def test_perf_workload_density_and_tiles():
    wl = perf.make_boxes(2000, seed=2)
    assert wl.side == pytest.approx(math.sqrt(2000) * 14)
    i, _ = perf.brute_force_pairs(wl.x - wl.w / 2, wl.y - wl.h / 2, wl.x + wl.w / 2, wl.y + wl.h / 2)
    assert 0.8 < i.size / wl.n < 1.2  # about one overlapping pair per box
    t = perf.with_tiles(wl, count=5000, steps=100)
    assert t.tiles == 5000
    # the level lies below anything a mover can reach in 100 steps
    assert (t.tile_y + 0.5).max() < (wl.y - wl.h / 2).min() - 0.5 * 100


@pytest.mark.slow
def test_perf_report_has_the_documented_columns_and_json():
    report = tiny_perf()
    rows = report["rows"]
    assert [r["scene"] for r in rows] == ["boxes-48", "boxes-48+tiles-300", "brute-force-48", "boxes-96"]
    for r in rows:
        assert set(perf.ROW_KEYS) <= set(r)
    data = json.loads(to_json(report))
    assert isinstance(data["rows"], list) and data["rows"][0]["bodies"] == 48
    assert {g["goal"].split(" ")[0] for g in data["goals"]} >= {"ours", "tiles", "log-log"}
    assert all(c["ok"] for c in report["checks"])
    assert "boxes-48+tiles-300" in perf.text_report(report)
    assert "| scene" in perf.markdown(report, "python -m framework.bench perf", "images/perf.png")
    queries = report["queries"]
    assert [q["query"].split(" ")[0] for q in queries] == ["query_points", "nearest_many", "nearest_many",
                                                            "raycast_many", "raycast_many"]
    for q in queries:
        assert {k for k, _, _ in perf.QUERY_COLUMNS} <= set(q) and q["queries"] == 30 and q["speedup"] > 0.0
    assert "loop/batch" in perf.text_report(report) and "### Batch queries" in perf.markdown(report, "c", None)


def test_perf_query_check_fails_loudly(monkeypatch):
    """A batch answer that differs from the single queries' stops the benchmark."""
    from framework.scene import Scene

    real = Scene.nearest_many

    def one_off(self, points, **kw):
        res = real(self, points, **kw)
        res.distance[0] += 1e-9
        return res

    monkeypatch.setattr(Scene, "nearest_many", one_off)
    with pytest.raises(perf.QueryMismatch, match="nearest_many"):
        perf.run_queries(20, bodies=30, tiles=10, rounds=1)


def test_perf_without_pymunk_has_null_columns(monkeypatch, tmp_path):
    monkeypatch.setenv("FRAMEWORK_BENCH_WITHOUT", "pymunk,matplotlib")
    report = tiny_perf(sizes=(48,), rounds={48: 2}, tile_bodies=None, brute_sizes=())
    (row,) = report["rows"]
    assert row["pymunk_ms_per_step"] is None and row["ratio"] is None and row["ms_per_step"] > 0
    from framework.bench.plots import plot_perf

    assert plot_perf(report, tmp_path / "p.png") is False and not (tmp_path / "p.png").exists()


@pytest.mark.slow
def test_cli_quick_json_of_a_tiny_configuration(capsys, tmp_path):
    plot = tmp_path / "perf.png"
    code = main(["perf", "--quick", "--json", "--sizes", "40,80", "--tiles", "200", "--rounds", "2",
                 "--no-progress", "--out", str(tmp_path), "--plot", str(plot)])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert [r["scene"] for r in data["rows"]][:2] == ["boxes-40", "boxes-40+tiles-200"]
    for r in data["rows"]:
        assert set(perf.ROW_KEYS) <= set(r)
    assert data["command"].startswith("python -m framework.bench perf --quick")
    assert json.loads((tmp_path / "perf-quick.json").read_text())["rows"] == data["rows"]
    assert (tmp_path / "perf-quick.csv").read_text().startswith("scene,bodies,static,ms_per_step")
    if perf.optional_module("matplotlib") is not None:
        assert plot.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.slow
def test_accuracy_report_of_a_tiny_configuration(tmp_path):
    cfg = {"lanes": 4, "crates": 40, "rest_steps": 12, "ball_steps": 40, "runs": 1, "crate_steps": 1, "crowds": 1,
           "pendulum_periods": 2, "rope_steps": 12}
    report = acc.run_accuracy(cfg, progress=False, speeds=(1.0, 64.0))
    rows = report["rows"]
    assert {r["scenario"] for r in rows} == set(acc.SCENARIOS)
    for r in rows:
        assert list(r) == acc.ROW_KEYS
        assert r["ms_per_step"] > 0
        assert (r["missed"] is not None) == (r["scenario"] == "bullet")
    assert len([r for r in rows if r["scenario"] == "bullet"]) == 2 * len(acc.BULLET_MODES)
    data = json.loads(to_json(report))
    assert isinstance(data["rows"], list)
    text = acc.text_report(report)
    assert "discrete (default)" in text and "energy drift" in text
    if perf.optional_module("matplotlib") is not None:
        from framework.bench.plots import plot_accuracy

        assert plot_accuracy(report, tmp_path / "a.png")
        assert (tmp_path / "a.png").read_bytes()[:4] == b"\x89PNG"


# --- the regimes benchmark ----------------------------------------------------------------------------

TINY_REGIMES = {"rounds": ((10**12, 2),), "platformer_rounds": 2, "crowd_steps": 4,
                "settle": dict.fromkeys(reg.SETTLE, 3)}


def test_pile_layout_knows_the_exact_resting_height():
    x, y, top = reg.pile_layout(4, 3)
    assert top == 2.5  # three unit boxes on a floor at y = 0: the top centre is 2.5 up
    assert sorted(set(x.tolist())) == [0.5, 1.5, 2.5, 3.5]  # four columns filling a pit 4 wide
    rows = np.repeat(np.arange(3), 4)
    assert (y - (rows + 0.5) == (rows + 1) * reg.GAP).all()  # each row lifted by exactly its gaps
    pile = reg.box_pile(4, 3)
    assert pile.bodies == 12 and pile.statics == 3 and pile.exact_top == 2.5 and pile.height == 3.0
    assert [pile.pieces[k].y for k in pile.top] == [2.5 + 3 * reg.GAP] * 4  # the top row, lifted
    assert reg.stack(20).exact_top == 19.5 and reg.pyramid(20).exact_top == 19.5
    assert reg.pyramid(20).bodies == 210


class _Frozen(reg.Engine):
    """An engine whose bodies stay where it is told (to check the figures' arithmetic)."""

    def __init__(self, regime, y_shift=None):
        super().__init__(regime)
        self.x = np.array([p.x for p in regime.pieces])
        self.y = np.array([p.y for p in regime.pieces])
        for k, dy in (y_shift or {}).items():
            self.y[k] += dy

    def state(self):
        z = np.zeros(self.x.size)
        return self.x, self.y, z, z, np.ones(self.x.size, dtype=bool)


def test_sink_is_the_top_rows_lowest_box_below_its_exact_height_over_the_pile_height():
    pile = reg.box_pile(2, 4)  # pieces 0-2: the pit; 3-10: the boxes, two a row
    at_rest = {k: -(i // 2 + 1) * reg.GAP for i, k in enumerate(range(3, 11))}  # every box at rest
    assert reg.judge(pile, _Frozen(pile, at_rest))["sink"] == 0.0
    sunk = {**at_rest, pile.top[1]: at_rest[pile.top[1]] - 0.5}
    fig = reg.judge(pile, _Frozen(pile, sunk))
    assert fig["sink"] == 0.125  # 0.5 below, over a pile 4 high
    assert fig["pen"] == 0.5  # it sank into the box below by as much


def test_penetration_oracle_measures_known_overlaps_exactly():
    shapes = [AABB(1.0, 1.0), AABB(1.0, 1.0), Circle(0.5), Circle(0.5), AABB(2.0, 2.0), AABB(2.0, 2.0)]
    x = [0.0, 0.75, 10.0, 10.625, 20.0, 20.5]
    y = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    static = [False, False, False, False, True, True]
    assert reg.max_penetration(shapes, x, y, static) == 0.375  # the circles; static pairs never count
    assert reg.max_penetration(shapes[:2], x[:2], y[:2], static[:2]) == 0.25
    assert reg.max_penetration(shapes[:2], [0.0, 1.0], [0.0, 0.0], [False, False]) == 0.0  # touching
    assert reg.max_penetration(shapes[:2], x[:2], y[:2], [False, True]) == 0.25
    assert reg.max_penetration(shapes[:4], x[:4], y[:4], static[:4], dynamic_pairs=False) == 0.0
    hexagon = reg._hexagon(0.5)  # flat top and bottom, 2 * sin(60 deg) * 0.5 tall
    assert reg.max_penetration([hexagon, AABB(1.0, 1.0)], [0.0, 0.0], [0.0, 0.5 + math.sqrt(3) / 4 - 0.125],
                               [False, True]) == pytest.approx(0.125)


def test_every_engine_builds_the_same_bodies():
    pile = reg.shape_pile("mixed", 3, 2, seed=4)
    engines = reg.make_engines(pile)
    try:
        for eng in engines:
            x, y, vx, vy, alive = eng.state()
            assert alive.all()
            assert x == pytest.approx([p.x for p in pile.pieces], abs=1e-6)  # Box2D keeps float32
            assert y == pytest.approx([p.y for p in pile.pieces], abs=1e-6)
    finally:
        for eng in engines:
            eng.close()
    assert {e.name for e in engines} == {"ours", "soft"} | {n for n, m in reg.peer_modules().items() if m}


@pytest.mark.parametrize("shape", ["crate", "disk"])
def test_friction_regimes_give_every_engine_the_same_friction(shape):
    # A crate at 5 units/s on a floor, mu 1/2, g 10: every engine stops it near v^2 / (2 mu g) = 2.5
    # (within a step's travel); a rolling disk thrown at 3 without spin ends rolling at 2 in each.
    crate = shape == "crate"
    piece = reg.Piece(AABB(1.0, 1.0) if crate else Circle(0.5), 0.0, 0.5, vx=5.0 if crate else 3.0)
    floor = reg.Piece(AABB(100.0, 1.0), 0.0, -0.5, kind="static")
    regime = reg.with_friction(reg.Regime("one", "pile", [floor, piece]), 0.5, rolling=not crate)
    engines = reg.make_engines(regime)
    try:
        for eng in engines:
            for _ in range(120):
                eng.step()
            x, _, vx, _, _ = eng.state()
            if crate:
                assert x[1] == pytest.approx(2.5, abs=5.0 / 60.0), eng.name
                assert abs(vx[1]) < 1e-6, eng.name
            else:
                assert vx[1] == pytest.approx(2.0, abs=0.02), eng.name
    finally:
        for eng in engines:
            eng.close()


JOINT_SCENES = ("chain-100", "bridge-30", "ragdolls-20")


def _joint_gaps(eng):
    """Each hinge's gap as the engine's own joint measures it (its anchors on its bodies now)."""
    if eng.name == "pymunk":
        return [(j.a.local_to_world(j.anchor_a) - j.b.local_to_world(j.anchor_b)).length for j in eng.joints]
    if eng.name == "box2d":
        out = []
        for j in eng.joints:
            pa, pb = j.body_a.world_point(j.local_anchor_a), j.body_b.world_point(j.local_anchor_b)
            out.append(math.hypot(pa.x - pb.x, pa.y - pb.y))
        return out
    from framework import RevoluteJoint, Transform

    out = []
    for e in eng.joints:
        j = eng.scene.get(e, RevoluteJoint)
        ends = []
        for body, (lx, ly) in ((j.a, j._frame[0:2]), (j.b, j._frame[2:4])):
            t = eng.scene.get(body, Transform)
            c, s = math.cos(t.rotation), math.sin(t.rotation)
            ends.append((t.x + c * lx - s * ly, t.y + s * lx + c * ly))
        out.append(math.dist(*ends))
    return out


@pytest.mark.parametrize("name", JOINT_SCENES)
def test_joint_regimes_build_the_same_hinged_bodies_in_every_engine(name):
    regime = reg.SCENES[name]()
    assert regime.kind == "joints" and regime.tumbling and regime.hinges
    assert {"chain-100": 100, "bridge-30": 35, "ragdolls-20": 200}[name] == regime.bodies
    assert len(regime.hinges) == {"chain-100": 101, "bridge-30": 31, "ragdolls-20": 180}[name]
    engines = reg.make_engines(regime)
    try:
        # the exact solver refuses joints: ours runs them soft only
        assert [e.name for e in engines] == ["soft"] + [n for n, m in reg.peer_modules().items() if m]
        for eng in engines:
            x, y, _, _, alive = eng.state()
            assert alive.all()
            assert x == pytest.approx([p.x for p in regime.pieces], abs=1e-6), eng.name  # Box2D keeps float32
            assert y == pytest.approx([p.y for p in regime.pieces], abs=1e-6), eng.name
            assert eng.angles() == pytest.approx([p.angle for p in regime.pieces], abs=1e-6), eng.name
            assert len(eng.joints) == len(regime.hinges), eng.name
            assert reg.hinge_stretch(regime, x, y, eng.angles()) < 1e-5, eng.name  # every hinge shut at spawn
        for eng in engines:
            for _ in range(3):
                eng.step()
            x, y, _, _, _ = eng.state()
            # the engine's own joints are the regime's hinges: their gaps are the ones the oracle measures
            assert _joint_gaps(eng) == pytest.approx(reg.hinge_gaps(regime, x, y, eng.angles()), abs=1e-5), eng.name
            fig = reg.judge(regime, eng)
            assert fig["stretch"] < 0.05 and fig["pen"] < 0.05, (eng.name, fig)
    finally:
        for eng in engines:
            eng.close()


@pytest.mark.parametrize("left", [False, True])
def test_hinge_limits_turn_the_same_way_in_every_engine(left):
    # A bar hinged at one end to a post (or, pointing left, to the world) with a limit on its turn
    # of [0, 0.5]: pointing right, gravity turns it clockwise (negative), the lower limit 0 holds it
    # level; pointing left, it turns counter-clockwise until the upper limit, 0.5.
    side = -1.0 if left else 1.0
    post = reg.Piece(AABB(0.5, 0.5), 5.0 if left else 0.0, 0.0, kind="static")  # (left: out of the way)
    bar = reg.Piece(AABB(1.0, 0.1), side * 0.5, 0.0)
    regime = reg.Regime("bar", "joints", [post, bar], tumbling=True,
                        hinges=[reg.Hinge(1, None if left else 0, 0.0, 0.0, 0.0, 0.5)])
    engines = reg.make_engines(regime)
    try:
        for eng in engines:
            for _ in range(90):
                eng.step()
            assert eng.angles()[1] == pytest.approx(0.5 if left else 0.0, abs=0.03), eng.name
    finally:
        for eng in engines:
            eng.close()


def test_jointed_pairs_are_left_out_of_the_penetration_figure():
    chain = reg.chain(links=10, span=2.0)  # a deep V: its links overlap at the bottom hinge
    frozen = _Frozen(chain)
    frozen.angles = lambda: np.array([p.angle for p in chain.pieces])
    shapes = [reg._ours_shape(chain, p.shape) for p in chain.pieces]
    static = [p.kind == "static" for p in chain.pieces]
    args = (shapes, frozen.x, frozen.y, static, True, frozen.angles())
    assert reg.max_penetration(*args) > 0.001  # the two links at the V's bottom hinge, and each link at its anchor
    assert reg.judge(chain, frozen)["pen"] == 0.0 and reg.judge(chain, frozen)["stretch"] < 1e-12


def test_chain_and_bridge_hang_between_their_anchors():
    chain = reg.chain()
    links = [p for p in chain.pieces if p.kind == "dynamic"]
    assert sum(p.shape.width for p in links) == pytest.approx(25.0) and chain.pieces[1].x == 18.0
    h = chain.hinges
    assert (h[-2].x, h[-2].y) == (0.0, 0.0) and (h[-1].x, h[-1].y) == pytest.approx((18.0, 0.0), abs=1e-9)
    assert min(p.y for p in links) < -5.0  # with slack
    bridge = reg.bridge()
    ends = sorted((hh.x, hh.y) for hh in bridge.hinges)
    assert ends[0] == (-7.0, 0.0) and ends[-1] == pytest.approx((7.0, 0.0))  # the posts' inner top corners
    assert all(y <= 1e-12 for _, y in ends)  # hanging, lowest in the middle


@pytest.mark.slow
def test_regimes_report_of_a_tiny_configuration(tmp_path):
    report = reg.run_regimes(TINY_REGIMES, scenes=("stack-20", "scattered-10", "platformer-1"), crowds=("boxes",),
                             progress=False)
    rows = report["rows"]
    assert [r["scene"] for r in rows] == ["stack-20", "scattered-10", "platformer-1"]
    peers = reg.peer_modules()
    for r in rows:
        assert list(r) == reg.ROW_KEYS
        assert r["ours_ms"] > 0 and r["pen_ours"] >= 0.0
        assert r["soft_ms"] is not None and r["soft_ms"] > 0  # (the platformer's game in a soft scene too)
        assert (r["pymunk_ms"] is not None) == (peers["pymunk"] is not None)
        assert (r["box2d_ms"] is not None) == (peers["box2d"] is not None)
    assert rows[0]["sink_ours"] is not None and rows[1]["sink_ours"] is None
    crowd = report["crowds"]
    assert [c["engine"] for c in crowd] == ["ours", "soft"] + [n for n in ("pymunk", "box2d") if peers[n]]
    assert all(c["steps"] == 4 and c["pass"] is None for c in crowd)  # a 4-step cap decides nothing
    data = json.loads(to_json(report))
    assert set(reg.ROW_KEYS) <= set(data["rows"][0]) and set(reg.CROWD_KEYS) == set(data["crowds"][0])
    assert {g["goal"].split(":")[0] for g in data["goals"]} >= {"every scene", "scattered-10000"}
    text = reg.text_report(report)
    assert "| stack-20" in text and "Platformer: of our" in text
    assert "| scene" in reg.markdown(report, "python -m framework.bench regimes", "images/regimes.png")


def test_regimes_report_of_a_joint_scene():
    report = reg.run_regimes(TINY_REGIMES, scenes=("bridge-30",), crowds=(), progress=False)
    (row,) = report["rows"]
    peers = reg.peer_modules()
    assert list(row) == reg.ROW_KEYS
    # no exact column: the soft solver's time is the one compared
    assert row["ours_ms"] is None and row["ratio"] is None and row["pen_ours"] is None and row["stretch_ours"] is None
    assert row["ours_stages_ms"] is None
    assert row["soft_ms"] > 0 and 0.0 <= row["stretch_soft"] < 0.05 and row["pen_soft"] >= 0.0
    for n in ("pymunk", "box2d"):
        assert (row[f"stretch_{n}"] is not None) == (peers[n] is not None)
    if any(peers.values()):
        assert row["ratio_soft"] > 0 and row["time_pass"] == (row["ratio_soft"] <= row["target"])
    assert "| bridge-30" in reg.text_report(report)


def test_regimes_without_peers_has_null_columns(monkeypatch, tmp_path):
    monkeypatch.setenv("FRAMEWORK_BENCH_WITHOUT", "pymunk,pyb2d3,matplotlib")
    report = reg.run_regimes(TINY_REGIMES, scenes=("scattered-10",), crowds=(), progress=False)
    (row,) = report["rows"]
    assert row["pymunk_ms"] is None and row["box2d_ms"] is None and row["ratio"] is None
    assert row["time_pass"] is None and row["ours_ms"] > 0
    assert "pyb2d3 is not installed" in reg.text_report(report)
    from framework.bench.plots import plot_regimes

    assert plot_regimes(report, tmp_path / "r.png") is False and not (tmp_path / "r.png").exists()


@pytest.mark.slow
def test_cli_regimes_quick_json_of_a_tiny_configuration(capsys, tmp_path):
    plot = tmp_path / "regimes.png"
    code = main(["regimes", "--quick", "--json", "--rounds", "2", "--crowd-steps", "3", "--scenes",
                 "scattered-10,scattered-100", "--crowds", "balls", "--no-progress", "--out", str(tmp_path),
                 "--plot", str(plot)])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert [r["scene"] for r in data["rows"]] == ["scattered-10", "scattered-100"]
    assert data["command"].startswith("python -m framework.bench regimes --quick")
    assert json.loads((tmp_path / "regimes-quick.json").read_text())["rows"] == data["rows"]
    assert (tmp_path / "regimes-quick.csv").read_text().startswith("scene,bodies,static,ours_ms")
    assert (tmp_path / "regimes-crowds-quick.csv").read_text().startswith("crowd,engine")
    if perf.optional_module("matplotlib") is not None:
        assert plot.read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(SystemExit):
        main(["regimes", "--scenes", "no-such-scene", "--no-save"])


# --- plumbing -----------------------------------------------------------------------------------------


def test_generated_section_is_replaced_between_markers(tmp_path):
    doc = tmp_path / "d.md"
    begin = "<!-- generated by `x`: begin (do not edit by hand; rerun the command) -->"
    doc.write_text(f"intro\n{begin}\nold\n<!-- generated by `x`: end -->\noutro\n")
    replace_generated(doc, "x", "new table")
    assert doc.read_text() == f"intro\n{begin}\nnew table\n<!-- generated by `x`: end -->\noutro\n"
    with pytest.raises(SystemExit, match="markers"):
        replace_generated(doc, "y", "t")


def test_table_and_csv_formatting(tmp_path):
    rows = [{"name": "a", "ms": 1.23456, "rate": 0.5, "n": None}]
    cols = [("name", "name", "str"), ("ms", "ms", "ms"), ("rate", "rate", "pct"), ("n", "n", "int")]
    table = format_table(rows, cols)
    assert table.splitlines()[2] == "| a    | 1.23 | 50.0% | – |"
    write_csv(tmp_path / "x.csv", rows)
    assert (tmp_path / "x.csv").read_text().splitlines() == ["name,ms,rate,n", "a,1.23456,0.5,"]


def test_progress_bar_writes_to_its_stream_only_when_enabled():
    out = io.StringIO()
    with Progress(3, "t", stream=out) as bar:
        bar.advance(note="one")
        bar.advance(2)
    assert "t: 1/3 (33%) one ..." in out.getvalue() and "done" in out.getvalue()
    quiet = io.StringIO()
    with Progress(3, "t", stream=quiet, enabled=False) as bar:
        bar.advance()
    assert quiet.getvalue() == ""


# --- the render benchmark -----------------------------------------------------------------------------


@pytest.mark.slow
def test_render_cli_of_a_tiny_configuration(render, capsys, tmp_path):
    """Every kind at a tiny size, through the command line: a row per (kind, size) with all three
    in-process contenders timed, ratios that are what they say, goals stated; JSON and CSV written."""
    from framework.bench import render as rb

    code = main(["render", "--quick", "--json", "--sizes", "30,60", "--no-arcade", "--no-progress",
                 "--out", str(tmp_path)])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert [(r["kind"], r["n"]) for r in data["rows"]] == [(k, n) for k in rb.KINDS for n in (30, 60)]
    for r in data["rows"]:
        assert r["ours_ms"] > 0 and r["floor_ms"] > 0 and r["naive_ms"] > 0 and r["arcade_ms"] is None
        assert r["vs_floor"] == pytest.approx(r["ours_ms"] / r["floor_ms"])
        assert r["drawn"] == r["n"]  # every sprite in view, drawn
    assert {g["goal"].split(":")[0] for g in data["goals"]} >= {"boxes", "animated"}
    assert (tmp_path / "render-quick.csv").read_text().startswith("kind,n,drawn,ours_ms")
    assert "| kind" in rb.markdown(data, "python -m framework.bench render", "images/render.png")
