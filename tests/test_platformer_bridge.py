"""The platformer's rope bridge (issue 37 part 5): planks hinged end to end by ``RevoluteJoint``s,
hung between two anchors, that sag under the player and that the player walks across through the
character controller. A level with a bridge is played with the soft solver (the only one that
solves joints); the scene switches between levels (``Scene.solver``), so the other levels keep the
exact solver. Levels are written in the text format (a run of ``=`` is a bridge) or as Tiled maps.

One tile is 32 world units; the player's box is 24 x 28; a plank weighs ``Tuning.plank_mass``
(0.25), the player ``Tuning.push_mass`` (1).

The sag is checked against statics (:mod:`examples.platformer.bridge`): a chain of hinged planks
hangs in the funicular polygon of its loads, each plank's weight half at each of its hinges and
the player's weight shared by the two hinges of the plank under its feet. The soft solver's hinges
give a little under load (a few tenths of a unit), so the chain is compared with the statics of
links as long as the simulated ones are, hinge to hinge.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import replace

import numpy as np
import pytest

from examples.platformer import Game, LevelError, builtin_levels, load_level, parse_text, parse_tmj
from examples.platformer.bridge import deck_sag, hang, plank_length
from examples.platformer.components import BridgePlank, Tuning
from examples.platformer.demo import SCRIPTS, Autoplay, jump_from, level5, run_to
from examples.platformer.levels import to_tmj
from framework import Hitbox, Polygon, RevoluteJoint, Scene, Transform, Velocity
from framework.character import CharacterController
from framework.validation import InvalidValue

T = 32.0
TU = Tuning()
W, H = TU.player_size[0] * T, TU.player_size[1] * T  # 24 x 28

# A bridge of ten planks over a pit ten tiles wide: anchors at x 128 and 448, the deck's top there
# at the ground's top (y 96), sagging one tile in the middle.
BRIDGE = """
#......................#
#......................#
#......................#
#.P..................G.#
####==========##########
####..........##########
####..........##########
"""
PLAIN = """
#.......#
#.P...G.#
#########
"""


def bridge_game(text: str = BRIDGE, tuning: Tuning | None = None, **props) -> tuple[Game, list[int]]:
    level = parse_text(text)
    level.objects[:] = [replace(o, props={**o.props, **props}) if o.kind == "bridge" else o for o in level.objects]
    g = Game([level], tuning=tuning)
    planks = [e for e, _p in sorted(g.scene.query(BridgePlank), key=lambda ep: ep[1].index)]
    return g, planks


def ends(g: Game, planks: list[int]) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    """Each plank's two ends on its middle line (where its hinges hold it), left then right."""
    out = []
    for e in planks:
        t, box = g.scene.get(e, Transform), g.scene.get(e, Hitbox).shape
        half = 0.5 * (max(p[0] for p in box.points) - min(p[0] for p in box.points))
        c, s = math.cos(t.rotation), math.sin(t.rotation)
        out.append(((t.x - c * half, t.y - s * half), (t.x + c * half, t.y + s * half)))
    return out


def hinges(g: Game, planks: list[int]) -> tuple[np.ndarray, float]:
    """The hinges (the anchors, then the middle between each two planks' meeting ends) and the
    widest gap between two planks' ends (how much the hinges give)."""
    e = ends(g, planks)
    pts = [e[0][0], *(((a[1][0] + b[0][0]) / 2, (a[1][1] + b[0][1]) / 2) for a, b in zip(e, e[1:])), e[-1][1]]
    return np.array(pts), max(math.dist(a[1], b[0]) for a, b in zip(e, e[1:]))


def settle(g: Game, steps: int, keys=frozenset()) -> tuple[np.ndarray, float]:
    """Step ``steps`` times; the hinges averaged over those steps (the bridge still sways a
    little), and the widest gap seen."""
    total, widest = 0.0, 0.0
    planks = [e for e, _p in sorted(g.scene.query(BridgePlank), key=lambda ep: ep[1].index)]
    for _ in range(steps):
        g.step(set(keys))
        pts, gap = hinges(g, planks)
        total, widest = total + pts, max(widest, gap)
    return total / steps, widest


def statics(pts: np.ndarray, loads: list[float]) -> np.ndarray:
    """Where a chain of links as long, on average, as the simulated ones (hinge to hinge) hangs
    between the same anchors under ``loads`` (at the inner hinges)."""
    link = float(np.hypot(*np.diff(pts, axis=0).T).mean())
    return np.array(hang(tuple(pts[0]), tuple(pts[-1]), len(pts) - 1, link, loads))


def player_loads(pts: np.ndarray, plank: int, x: float, mass: float, planks_mass: float) -> list[float]:
    """The inner hinges' loads: each plank's weight, half at each end, and ``mass`` standing at
    ``x`` on plank ``plank``, shared by its two hinges as the lever rule says."""
    n = len(pts) - 1
    loads = [planks_mass] * (n - 1)
    f = (x - pts[plank][0]) / (pts[plank + 1][0] - pts[plank][0])
    assert 0.0 <= f <= 1.0
    if plank > 0:
        loads[plank - 1] += (1.0 - f) * mass
    if plank < n - 1:
        loads[plank] += f * mass
    return loads


def stand(g: Game, plank: int, dx: float = 5.0) -> None:
    """Drop the player onto ``plank``, ``dx`` right of its middle; it lands there."""
    p, t = g.scene.get(plank, Transform), g.player_transform
    t.x, t.y = p.x + dx, p.y + 30.0
    for _ in range(30):
        g.step(set())
    ctrl = g.scene.get(g.player, CharacterController)
    assert ctrl.on_floor and ctrl.floor_entity == plank


# --- the statics ------------------------------------------------------------------------------------


def test_the_statics_of_two_planks_is_a_v_whatever_the_loads():
    # two links of 5 between anchors 8 apart: the hinge is 3 below the middle (a 3-4-5 triangle)
    for loads in ([1.0], [0.1], [7.0]):
        (_a, hinge, _b) = hang((0.0, 0.0), (8.0, 0.0), 2, 5.0, loads)
        assert hinge == pytest.approx((4.0, -3.0), abs=1e-12)
    assert plank_length(8.0, 3.0, 2) == pytest.approx(5.0, rel=1e-12)


def test_the_statics_hangs_where_the_potential_energy_is_least():
    # Equilibrium of a chain under loads is where their potential energy is stationary among the
    # shapes the links allow: move each inner hinge a little, then put the chain back on its link
    # lengths (the two hinges after it follow); the energy never goes down.
    left, right, n, length = (0.0, 0.0), (10.0, 1.0), 6, 2.0
    loads = [1.0, 0.5, 3.0, 0.5, 1.0]
    pts = np.array(hang(left, right, n, length, loads))
    assert np.allclose(np.hypot(*np.diff(pts, axis=0).T), length, atol=1e-9)

    def energy(p: np.ndarray) -> float:
        return float(np.dot(loads, p[1:-1, 1]))

    base = energy(pts)
    rng = np.random.default_rng(3)
    for _ in range(200):
        # turn the first j links about the left anchor's chain by small angles, then close the
        # chain: a one-parameter family through the shape, found by bisection on the last joint
        angles = np.arctan2(*np.diff(pts, axis=0).T[::-1]) + rng.normal(0.0, 1e-3, n)
        ux, uy = np.cos(angles) * length, np.sin(angles) * length
        x, y = np.cumsum(ux), np.cumsum(uy)
        # close it: the last two links from the hinge before them to the right anchor (a V)
        hx, hy = x[n - 3], y[n - 3]
        d = math.dist((hx, hy), right)
        if d >= 2 * length:
            continue
        mx, my = (hx + right[0]) / 2, (hy + right[1]) / 2
        depth = math.sqrt(length * length - d * d / 4)
        nx, ny = (right[1] - hy) / d, -(right[0] - hx) / d  # below the line, as in the shape
        moved = np.array([left, *zip(x[:n - 2], y[:n - 2], strict=True), (mx + nx * depth, my + ny * depth), right])
        assert energy(moved) >= base - 1e-9


def test_plank_length_gives_the_sag_asked_for():
    for span, sag, n in ((320.0, 32.0, 10), (288.0, 32.0, 9), (512.0, 64.0, 16), (100.0, 40.0, 3)):
        length = plank_length(span, sag, n)
        assert n * length > span
        pts = hang((0.0, 0.0), (span, 0.0), n, length, [1.0] * (n - 1))
        assert deck_sag(pts) == pytest.approx(sag, rel=1e-9)


# --- the bridge in the game -----------------------------------------------------------------------------


def test_a_bridge_is_planks_hinged_end_to_end_and_to_its_anchors_in_the_soft_solver():
    g, planks = bridge_game()
    assert g.scene.solver == "soft" and g.solver == "exact"  # (the level asks for soft; the game's own is exact)
    assert len(planks) == 10
    for e in planks:
        hb = g.scene.get(e, Hitbox)
        assert isinstance(hb.shape, Polygon) and hb.body.value == "dynamic" and hb.mass == TU.plank_mass
        assert hb.mask == 0  # it meets nothing in the solver: the player stands on it through its controller
    joints = [j for _e, j in g.scene.query(RevoluteJoint)]
    pairs = sorted((j.a, -1 if j.b is None else j.b) for j in joints)
    assert pairs == sorted([(planks[0], -1), *zip(planks, planks[1:]), (planks[-1], -1)])
    # spawned at rest where the statics hang it: the anchors at the run's ends, half a plank below
    # the deck's top (the ground's top, 96), sagging a tile
    pts, gap = hinges(g, planks)
    assert gap < 1e-9
    assert pts[0] == pytest.approx((128.0, 92.0)) and pts[-1] == pytest.approx((448.0, 92.0))
    expected = hang((128.0, 92.0), (448.0, 92.0), 10, plank_length(320.0, 32.0, 10), [1.0] * 9)
    assert np.allclose(pts, expected, atol=1e-9)
    assert deck_sag(pts) == pytest.approx(32.0)


def test_the_bridge_hangs_in_the_statics_shape_of_its_planks():
    g, planks = bridge_game()
    settle(g, 120)
    pts, gap = settle(g, 240)
    assert gap < 0.4  # the hinges give a little (about 1% of a plank's 32.8)
    assert np.abs(statics(pts, [TU.plank_mass] * 9) - pts).max() < 0.1


@pytest.mark.parametrize("weight", [1.0, 2.0])
def test_the_bridge_sags_under_the_player_as_under_its_weight_and_rises_after(weight):
    g, planks = bridge_game(tuning=Tuning(push_mass=weight))
    settle(g, 120)
    rest, _gap = settle(g, 240)
    k = 5
    stand(g, planks[k])
    settle(g, 90)
    loaded, gap = settle(g, 240)
    assert gap < 0.3 + 0.15 * weight
    ctrl = g.scene.get(g.player, CharacterController)
    assert ctrl.on_floor and ctrl.floor_entity == planks[k] and g.state.deaths == 0
    x = g.player_transform.x
    loads = player_loads(loaded, k, x, weight, TU.plank_mass)
    # the shape is the statics' with the player's weight where it stands (the hinges' heights to
    # 0.1 unit, of a chain 320 long; across, to 0.3: the hinges near the player give more than the
    # others, which links of one length leave out), and far from it without that weight, or with
    # twice it
    off = np.abs(statics(loaded, loads) - loaded)
    assert off[:, 1].max() < 0.1 and off[:, 0].max() < 0.3
    assert np.abs(statics(loaded, [TU.plank_mass] * 9) - loaded)[:, 1].max() > 2.0
    twice = player_loads(loaded, k, x, 2 * weight, TU.plank_mass)
    assert np.abs(statics(loaded, twice) - loaded)[:, 1].max() > 1.0
    # the plank under the player lowers by what the statics says (to 0.15), several units
    drop = (rest[k, 1] + rest[k + 1, 1] - loaded[k, 1] - loaded[k + 1, 1]) / 2
    want = (statics(rest, [TU.plank_mass] * 9)[[k, k + 1], 1].sum() - statics(loaded, loads)[[k, k + 1], 1].sum()) / 2
    assert drop == pytest.approx(want, abs=0.1)
    assert drop > 3.5 * weight ** 0.7
    # off the bridge again: it rises back where it hung
    t = g.player_transform
    t.x, t.y = 2.5 * T, 3.5 * T
    settle(g, 300)
    after, _gap = settle(g, 120)
    assert np.abs(after - rest).max() < 0.1


def above_deck(g: Game, planks: list[int], x: float, y: float) -> float | None:
    """How far the point ``(x, y)`` is above the top face of the plank under it (the lowest, where
    two overlap at a hinge); None over no plank."""
    length = float(np.ptp([p[0] for p in g.scene.get(planks[0], Hitbox).shape.points]))
    best = None
    for e in planks:
        p = g.scene.get(e, Transform)
        c, s = math.cos(p.rotation), math.sin(p.rotation)
        if abs(c * (x - p.x) + s * (y - p.y)) <= length / 2:
            up = -s * (x - p.x) + c * (y - p.y) - 4.0  # (the top face is 4 above the middle line)
            best = up if best is None else min(best, up)
    return best


@pytest.mark.parametrize("way", ["right", "left"])
def test_the_player_walks_across_on_the_deck_every_step(way):
    g, planks = bridge_game()
    t = g.player_transform
    if way == "left":
        t.x = 20.5 * T
    settle(g, 60)
    ctrl = g.scene.get(g.player, CharacterController)
    on = set()
    xs: list[float] = []
    heights: list[float] = []
    for _ in range(200):
        g.step({way})
        if 128.0 + W / 2 < t.x < 448.0 - W / 2:  # over the pit: on a plank every step
            xs.append(t.x)
            assert ctrl.on_floor and ctrl.floor_entity in planks
            on.add(ctrl.floor_entity)
            feet = [above_deck(g, planks, x, t.y - H / 2) for x in (t.x - W / 2, t.x + W / 2)]
            if None not in feet:  # (both feet over planks: not on the ground's corner at an end)
                heights.append(min(h for h in feet if h is not None))
        if (way == "right" and t.x > 480.0) or (way == "left" and t.x < 100.0):
            break
    steps = np.diff(xs) * (1 if way == "right" else -1)
    assert steps.min() > 2.5 and steps.max() < 5.5  # no snag, no leap: about the run speed, 3.73 a step
    assert len(on) == 10 and g.state.deaths == 0
    assert (t.x > 480.0) if way == "right" else (t.x < 100.0)
    # The feet on the deck at the end of every step: the controller stands them on a plank, the soft
    # step moves the planks on, and stand_on_bridges puts them back on the deck (a hair above it,
    # 2**-20 tile), never in it (where two planks meet in the feet, the controller would find the
    # player crushed)
    assert len(heights) > 60 and 0.0 < min(heights) and max(heights) < 1e-4


def test_the_player_jumps_off_a_plank_and_lands_back_on_the_bridge():
    g, planks = bridge_game()
    stand(g, planks[4])
    g.step({"space"})
    assert not g.scene.get(g.player, CharacterController).on_floor
    ctrl = g.scene.get(g.player, CharacterController)
    for _ in range(120):
        g.step({"space"})
        if ctrl.on_floor:
            break
    assert ctrl.on_floor and ctrl.floor_entity in planks and g.state.deaths == 0


@pytest.mark.parametrize(("dx", "frames"), [(0.2, 12), (-0.4, 12), (0.0, 16), (0.4, 20)])
def test_running_and_hopping_along_the_bridges_never_crushes_the_player(dx, frames):
    # Jumps of several heights from several places on the swaying decks, landing where they may
    # (on a hinge, where two planks meet under the feet): the player is never found inside the
    # deck, so never crushed, and never dies. (Before stand_on_bridges, the first two died: the
    # deck rose into the feet where two planks meet, and pushed out of one into the other, the
    # controller found the player crushed.)
    def script(game):
        for x in (12.4, 32.4, 37.4):
            yield from jump_from(game, x + dx, frames)
        yield from run_to(game, 58.0)

    g = Game([builtin_levels()[4]], autoplay=Autoplay(script))
    ctrl = g.scene.get(g.player, CharacterController)
    while not g.state.reached_goal and g.scene.frame < 2000:
        g.step()
        assert not ctrl.crushed
    assert g.state.reached_goal and g.state.deaths == 0


def test_the_bridge_is_the_same_bytes_every_run_whatever_solver_the_game_was_made_with():
    def play(solver: str) -> tuple[int, str]:
        g = Game([builtin_levels()[4]], autoplay=Autoplay(level5), scene=Scene(solver=solver))
        h = hashlib.sha256()
        while not g.state.reached_goal and g.scene.frame < 2000:
            g.step()
            rows = [(e, t.x, t.y, t.rotation) for e, t in g.scene.query(Transform)]
            h.update(np.array(rows, dtype=np.float64).tobytes())
        assert g.scene.solver == "soft"
        return g.scene.frame, h.hexdigest()

    assert play("exact") == play("exact") == play("soft")


# --- solvers level by level -----------------------------------------------------------------------------


def test_the_game_switches_to_a_bridge_levels_solver_and_back_between_levels():
    plain, bridge = parse_text(PLAIN, "plain.txt"), parse_text(BRIDGE, "bridge.txt")
    assert plain.solver is None and bridge.solver == "soft"
    g = Game([plain, bridge, plain])
    seen = []
    for _ in range(400):
        g.step({"right"})
        seen.append((g.state.level_index, g.state.player is not None, g.scene.solver))
        if g.state.level_index == 1 and g.state.player is not None and len(set(s for _i, _p, s in seen)) == 2:
            break
    # level 0 exact; the level change's first step clears it and switches as it ends; the second
    # spawns the bridge level in the soft scene
    assert seen[0] == (0, True, "exact")
    assert (1, True, "soft") in seen and (0, True, "soft") not in seen
    assert g.scene.query(BridgePlank)
    g.state.pending, g.state.pending_stage = "next", 0
    for _ in range(3):
        g.step(set())
    assert g.state.level_index == 2 and g.scene.solver == "exact" and not g.scene.query(BridgePlank)


def test_a_game_made_soft_plays_plain_levels_soft():
    g = Game([parse_text(PLAIN)], scene=Scene(solver="soft"))
    assert g.solver == "soft" and g.scene.solver == "soft"


def test_spawning_a_level_of_another_solver_during_a_step_is_refused():
    g = Game([parse_text(PLAIN), parse_text(BRIDGE)])

    def spawn_now(scene, dt):
        g.spawn_level(1)

    g.scene.add_system(spawn_now, before="movement")
    with pytest.raises(InvalidValue, match="cannot change during a step"):
        g.step(set())
    assert g.scene.solver == "exact" and not g.scene.query(BridgePlank)


# --- level files -----------------------------------------------------------------------------------------


def test_a_text_bridge_is_the_rectangle_of_its_run_and_round_trips_through_tiled_json():
    level = parse_text(BRIDGE, "b.txt")
    (b,) = level.of_kind("bridge")
    assert (b.x, b.y, b.width, b.height) == (288.0, 80.0, 320.0, 32.0) and b.props == {}
    assert level.tiles[4][4:14] == [None] * 10  # (the run's cells hold no tile)
    tmj = to_tmj(level)
    assert {"name": "solver", "type": "string", "value": "soft"} in tmj["properties"]
    back = parse_tmj(json.loads(json.dumps(tmj)), "b.tmj")
    assert back.of_kind("bridge") == [b] and back.solver == "soft"


def _bridge_map(map_props: dict | None = None, **props) -> str:
    tmj = to_tmj(parse_text(BRIDGE, "b.txt"))
    (obj,) = [o for o in tmj["layers"][1]["objects"] if o["type"] == "bridge"]
    obj["properties"] = [{"name": k, "value": v} for k, v in props.items() if k not in ("width", "height")]
    for key in ("width", "height"):
        if key in props:
            obj[key] = props[key]
    if map_props is not None:
        tmj["properties"] = [{"name": "title", "value": "b"}, *({"name": k, "value": v} for k, v in map_props.items())]
    return json.dumps(tmj)


BAD_BRIDGES = [
    ({"planks": 1}, "planks must be an integer >= 2, got 1"),
    ({"planks": 0}, "planks must be an integer >= 2, got 0"),
    ({"planks": 2.5}, "planks must be an integer >= 2, got 2.5"),
    ({"planks": "many"}, "planks must be an integer >= 2, got 'many'"),
    ({"planks": True}, "planks must be an integer >= 2, got True"),
    ({"thickness": 0}, "thickness must be > 0, got 0"),
    ({"thickness": -0.5}, "thickness must be > 0, got -0.5"),
    ({"thickness": "thick"}, "thickness must be a number, got 'thick'"),
    ({"thickness": 1.5}, "thickness must be less than a plank's length (1.026 tiles for 10 planks), got 1.5"),
    ({"planks": 40, "thickness": 0.5}, "thickness must be less than a plank's length"),
    ({"mass": 0}, "mass must be > 0, got 0"),
    ({"mass": -1}, "mass must be > 0, got -1"),
    ({"mass": [1]}, "mass must be a number, got [1]"),
    ({"height": 0}, "needs a rectangle: its width the span between the anchors, its height the sag"),
    ({"width": 0}, "needs a rectangle"),
]


@pytest.mark.parametrize(("props", "problem"), BAD_BRIDGES, ids=[p for _, p in BAD_BRIDGES])
def test_bad_bridge_properties_are_level_errors_naming_the_value(tmp_path, props, problem):
    path = tmp_path / "bridge.tmj"
    path.write_text(_bridge_map(**props))
    with pytest.raises(LevelError) as info:
        load_level(path)
    msg = str(info.value)
    assert msg.startswith(str(path)) and "bridge at (" in msg and problem in msg, msg


@pytest.mark.parametrize(("map_props", "problem"), [
    ({"solver": "exact"}, "the level has a bridge, whose hinges are joints, which only the soft solver solves: "
                          "solver must be soft (or not given), got 'exact'"),
    ({"solver": "fast"}, "solver must be one of exact, soft, got 'fast'"),
    ({"solver": 2}, "solver must be one of exact, soft, got 2"),
])
def test_a_bad_level_solver_is_a_level_error_naming_it(tmp_path, map_props, problem):
    path = tmp_path / "bridge.tmj"
    path.write_text(_bridge_map(map_props))
    with pytest.raises(LevelError) as info:
        load_level(path)
    assert str(info.value) == f"{path}: {problem}"


def test_good_bridge_properties_and_a_level_solver_load(tmp_path):
    path = tmp_path / "bridge.tmj"
    path.write_text(_bridge_map({"solver": "soft"}, planks=12, thickness=0.5, mass=2.0))
    level = load_level(path)
    (b,) = level.of_kind("bridge")
    assert b.props == {"planks": 12, "thickness": 0.5, "mass": 2.0} and level.solver == "soft"
    g = Game([level])
    planks = [e for e, _p in g.scene.query(BridgePlank)]
    assert len(planks) == 12 and all(g.scene.get(e, Hitbox).mass == 2.0 for e in planks)
    plain = json.loads(_bridge_map())
    plain["layers"][1]["objects"] = [o for o in plain["layers"][1]["objects"] if o["type"] != "bridge"]
    plain["properties"].append({"name": "solver", "value": "soft"})
    assert parse_tmj(plain, "p.tmj").solver == "soft"  # a level may ask for the soft solver without a bridge
    plain["properties"][-1]["value"] = "exact"
    assert parse_tmj(plain, "p.tmj").solver == "exact"


def test_a_one_cell_text_bridge_is_a_level_error():
    with pytest.raises(LevelError, match="bridge at line 3, column 3 is one cell long"):
        parse_text("#.P.G#\n#....#\n##=###", "b.txt")


# --- the shipped level 5, and levels 1-4 as they were ----------------------------------------------------


def test_the_bridge_level_has_two_bridges_over_pits_a_checkpoint_and_a_goal():
    paths = builtin_levels()
    assert len(paths) == 5 and len(SCRIPTS) == 5 and paths[4].name == "05-bridge.tmj"
    level = load_level(paths[4])
    assert level.name == "Bridge" and level.solver == "soft"
    bridges = level.of_kind("bridge")
    assert len(bridges) == 2 and len(level.of_kind("checkpoint")) == 1 and len(level.of_kind("goal")) == 1
    for b in bridges:  # each spans a pit: no ground under it, down to the bottom of the map
        first, last = int((b.x - b.width / 2) // level.tile), int((b.x + b.width / 2) // level.tile) - 1
        for col in range(first, last + 1):
            assert all(level.tiles[row][col] is None for row in range(len(level.tiles)))
        assert level.tiles[-2][first - 1] == "solid" and level.tiles[-2][last + 1] == "solid"
    assert [load_level(p).solver for p in paths[:4]] == [None] * 4


@pytest.mark.slow
def test_demo_crosses_the_bridges_to_the_goal_with_every_coin():
    g = Game([builtin_levels()[4]], autoplay=Autoplay(level5))
    on = set()
    while not g.state.reached_goal and g.scene.frame < 2000:
        g.step()
        ground = g.player_state.ground
        if ground is not None and g.scene.try_get(ground, BridgePlank) is not None:
            on.add(g.scene.get(ground, BridgePlank).planks)
    assert g.state.reached_goal and g.state.deaths == 0
    assert on == {9, 16}  # it walked on both bridges
    assert g.state.coins == g.state.coin_total_in_level == 14
    assert g.scene.frame == 596  # (docs/platformer.md gives it)


# Each shipped level's demo run before the bridge came (commit 78a84b5): frames, coins, and every
# body's pose and velocity hashed step by step.
BEFORE = [(1658, 18, "3bd22fbd2ac9595c"), (2081, 13, "b85098f61e2055ce"), (742, 2, "3bac2fc43a1c4868"),
          (1356, 12, "fcab9e4205e45fd0")]
# The same hash every 250 frames (2026-11-27, the same runs): where a run that differs first left
# its path, to start looking from (Caverns' run once failed in one full CI run, not since).
CHECKPOINTS = [["2f3e67ac", "53b7bf93", "8d802aec", "cd2e536a", "2d4a4e7a", "a5fd2a1b"],
               ["e38149da", "e5f7e0ee", "5d8c962c", "8d322429", "1c0e77dd", "3ac18cfd", "96bfa74c", "652f9708"],
               ["c1a3a0b0", "b11feccb"], ["98843b65", "b9d7f343", "9fd8e2fa", "af1e3a7a", "a5f7291f"]]


@pytest.mark.slow
@pytest.mark.parametrize("index", range(4))
def test_levels_1_to_4_play_bit_for_bit_as_before(index):
    g = Game([builtin_levels()[index]], autoplay=Autoplay(SCRIPTS[index]))
    h = hashlib.sha256()
    marks, deaths = [], []  # (the hash every 250 frames; the frames the player died in)
    while not g.state.reached_goal and g.scene.frame < 4000:
        dead = g.state.deaths
        g.step()
        rows = []
        for e in g.scene.entities:
            t = g.scene.try_get(e, Transform)
            if t is None:
                continue
            v = g.scene.try_get(e, Velocity)
            rows.append((e, t.x, t.y, t.rotation, *((v.x, v.y, v.angular) if v is not None else (0.0, 0.0, 0.0))))
        h.update(np.array(rows, dtype=np.float64).tobytes())
        if g.scene.frame % 250 == 0:
            marks.append(h.hexdigest()[:8])
        if g.state.deaths != dead:
            deaths.append(g.scene.frame)
    left = next((250 * (k + 1) for k, (got, want) in enumerate(zip(marks, CHECKPOINTS[index])) if got != want), None)
    where = f"first unlike the stored run by frame {left}; died in frames {deaths}"
    assert g.scene.solver == "exact" and g.state.deaths == 0, where
    assert (g.scene.frame, g.state.coins, h.hexdigest()[:16]) == BEFORE[index], where
    assert marks == CHECKPOINTS[index], where
