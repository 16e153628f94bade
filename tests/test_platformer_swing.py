"""The platformer's swinging platform (issue 37): a board hanging from a pivot, swinging as a
pendulum, that the player rides. Headless, in both solvers; levels are written in the text format
(``o`` a swing's pivot, a run of ``S`` below it its board at rest) or as Tiled maps in code.

One tile is 32 world units; the player's box is 24 x 28.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace

import pytest

from examples.platformer import Game, LevelError, builtin_levels, load_level, parse_text, parse_tmj
from examples.platformer.components import SwingingPlatform, SwingRope, Tuning
from examples.platformer.demo import Autoplay, level4
from examples.platformer.levels import to_tmj
from framework import Hitbox, Polygon, Scene, Transform, Velocity
from framework.character import CharacterController

T = 32.0
DT = 1.0 / 60.0
TU = Tuning()
W, H = TU.player_size[0] * T, TU.player_size[1] * T  # 24 x 28
SOLVERS = ["exact", "soft"]

# The board (3 cells, 96 x 16) hangs 3.75 tiles below the pivot (the 'o' cell's centre, row 1, to
# the top half of row 5): its centre at rest is (368, 56), the pivot (368, 176).
SWING = """
#..........o...........#
#......................#
#......................#
#......................#
#.P.......SSS.........G#
####..............######
"""
LENGTH = 3.75


def swing_game(solver: str = "exact", **props) -> tuple[Game, int, SwingingPlatform]:
    level = parse_text(SWING)
    level.objects[:] = [replace(o, props={**o.props, **props}) if o.kind == "swing" else o for o in level.objects]
    g = Game([level], scene=Scene(solver=solver))
    (board, swing), = g.scene.query(SwingingPlatform)
    return g, board, swing


def theta(t: float, amplitude: float, period: float, phase: float) -> float:
    return amplitude * math.sin(2.0 * math.pi * t / period + phase)


# --- the path ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("props", [{}, {"angle": 45.0, "period": 1.3, "phase": 120.0}, {"angle": 10.0, "phase": -90.0}])
def test_the_board_follows_the_pendulum_exactly_every_step(solver, props):
    g, board, swing = swing_game(solver, **props)
    amplitude = math.radians(props.get("angle", 30.0))
    period = props.get("period", 2.0 * math.pi * math.sqrt(LENGTH / TU.gravity))  # the pendulum's
    phase = math.radians(props.get("phase", 0.0))
    assert swing.period == pytest.approx(period, rel=1e-15)
    px, py, length = 368.0, 176.0, LENGTH * T
    worst = 0.0
    for k in range(round(2.5 * period / DT)):  # two and a half swings
        if k:
            g.step(set())
        t = k * DT
        th = theta(t, amplitude, period, phase)
        tr = g.scene.get(board, Transform)
        worst = max(worst, abs(tr.x - (px + length * math.sin(th))), abs(tr.y - (py - length * math.cos(th))),
                    abs(tr.rotation - th))
        assert abs(swing.time - t) < 1e-12
    assert worst < 1e-9
    # (and it does swing: out to the amplitude each side)
    assert g.scene.get(board, Velocity).angular != 0.0


def test_the_swing_is_a_kinematic_polygon_with_a_rope_that_meets_nothing():
    g, board, swing = swing_game()
    hb = g.scene.get(board, Hitbox)
    assert isinstance(hb.shape, Polygon) and hb.body.value == "kinematic" and hb.one_way  # (by default)
    (rope, r), = g.scene.query(SwingRope)
    assert r.swing is swing
    rope_box = g.scene.get(rope, Hitbox)
    assert rope_box.layer == 0 and rope_box.mask == 0 and rope_box.sensor
    for _ in range(20):
        g.step(set())
        assert g.scene.get(rope, Transform).rotation == pytest.approx(g.scene.get(board, Transform).rotation, abs=1e-9)
        assert (g.scene.get(rope, Transform).x, g.scene.get(rope, Transform).y) == pytest.approx(swing.pivot)


# --- riding -------------------------------------------------------------------------------------------


def stand_on(g: Game, board: int, at: float) -> None:
    """Put the player just above the board's top, ``at`` from its middle (along it), and let it land."""
    p = g.scene.get(board, Transform)
    c, s = math.cos(p.rotation), math.sin(p.rotation)
    x, y = p.x + c * at - s * 8.0, p.y + s * at + c * 8.0  # the top face's point
    t = g.player_transform
    t.x, t.y = x, y + H / 2 + W / 2 * abs(math.tan(p.rotation)) + 1.0
    for _ in range(6):
        g.step(set())
    ctrl = g.scene.get(g.player, CharacterController)
    assert ctrl.on_floor and ctrl.floor_entity == board


def place(g: Game, board: int) -> tuple[float, float]:
    """The player's feet (its bottom middle) in the board's frame: along it, and up from its middle."""
    p, t = g.scene.get(board, Transform), g.player_transform
    dx, dy = t.x - p.x, t.y - H / 2 - p.y
    c, s = math.cos(p.rotation), math.sin(p.rotation)
    return c * dx + s * dy, -s * dx + c * dy


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("at", [0.0, 28.0, -28.0])
@pytest.mark.parametrize("one_way", [False, True])
def test_a_player_standing_on_the_board_rides_a_whole_period_in_its_place(solver, at, one_way):
    # phase 90: the board starts at the end of its swing, at rest, tilted by the amplitude (30
    # degrees), and the player lands on it there. One-way or not, the board holds its rider (the
    # one-way test, whether the feet were above the board's top, is not asked of the floor it
    # stood on: for a tilted board that top is its higher end, above the feet)
    g, board, swing = swing_game(solver, phase=90.0, one_way=one_way)
    stand_on(g, board, at)
    along0, _ = place(g, board)
    ctrl = g.scene.get(g.player, CharacterController)
    # How far the place may wander. The controller carries the player's feet as a point of the
    # board (so its place is kept), then moves it straight up or down to keep its box, which does
    # not turn, with a lower corner on the tilted board: a vertical move dz shifts the place along
    # the board by dz sin(theta). The feet hang (W/2)|tan theta| above the board's top under them,
    # so between tilt 0 and theta the place shifts by (W/2) * integral of sin sec^2 = (W/2)(sec
    # theta - 1), and back as the tilt returns: at most (W/2)(sec A - 1) = 1.86 from where it was,
    # and where it was after a whole period.
    bound = W / 2 * (1.0 / math.cos(swing.amplitude) - 1.0)
    steps = round(swing.period / DT)
    worst = 0.0
    for _ in range(steps):
        g.step(set())
        assert ctrl.on_floor and ctrl.floor_entity == board
        along, up = place(g, board)
        worst = max(worst, abs(along - along0))
        assert 8.0 - 1e-6 <= up <= 8.0 + W / 2 * math.tan(swing.amplitude) + 1e-3  # on its top, not in it
    assert worst <= bound + 0.05
    assert abs(place(g, board)[0] - along0) < 0.05  # a whole period later: where it started
    assert g.state.deaths == 0


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("when", [0.1, 0.3, 0.55])
def test_jumping_off_the_board_keeps_the_velocity_of_its_point_under_the_feet(solver, when):
    g, board, swing = swing_game(solver, phase=90.0)
    stand_on(g, board, 20.0)
    while swing.time < when * swing.period:
        g.step(set())
    # the board's point under the feet this step: turned about the board's middle from its pose now
    # to its pose at the end of the step (what the controller carries the feet by)
    p, t = g.scene.get(board, Transform), g.player_transform
    fx, fy = t.x - p.x, t.y - H / 2 - p.y
    x1, y1, th1 = swing.pose(swing.time + DT)
    turn = th1 - p.rotation
    c, s = math.cos(turn), math.sin(turn)
    carried_x = x1 + c * fx - s * fy - t.x
    carried_y = y1 + s * fx + c * fy - (t.y - H / 2)
    g.step({"space"})
    v = g.scene.get(g.player, Velocity)
    assert not g.scene.get(g.player, CharacterController).on_floor
    assert v.x == pytest.approx(carried_x / DT, abs=1e-6)
    assert v.y == pytest.approx(TU.jump_speed * T + carried_y / DT - TU.gravity * T * DT, abs=1e-6)
    assert abs(carried_x / DT) > 50.0  # (the board was moving)


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("when", [0.0, 0.2, 0.45, 0.7])
def test_the_player_lands_on_a_one_way_swing_from_above(solver, when):
    g, board, swing = swing_game(solver, phase=90.0, one_way=True)
    while swing.time < when * swing.period:
        g.step(set())
    # dropped from two tiles above the board's middle, wherever the board is in its swing
    p = g.scene.get(board, Transform)
    t = g.player_transform
    t.x, t.y = p.x, p.y + 2 * T
    ctrl = g.scene.get(g.player, CharacterController)
    for _ in range(40):
        g.step(set())
        if ctrl.on_floor:
            break
    assert ctrl.on_floor and ctrl.floor_entity == board


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("when", [0.0, 0.2, 0.45, 0.7])
@pytest.mark.parametrize("one_way", [True, False])
def test_the_player_jumps_up_through_a_one_way_swing_and_bumps_into_a_solid_one(solver, when, one_way):
    g, board, swing = swing_game(solver, phase=90.0, one_way=one_way)
    while swing.time < when * swing.period:
        g.step(set())
    p = g.scene.get(board, Transform)
    t, v = g.player_transform, g.scene.get(g.player, Velocity)
    t.x, t.y = p.x, p.y - 8.0 - H / 2 - 4.0  # just under the board's middle, going up fast
    v.y = 600.0
    above = False
    for _ in range(30):
        g.step(set())
        top = g.scene.get(board, Transform).y + 8.0
        above = above or g.player_transform.y - H / 2 > top
    assert above == one_way


# --- level files ---------------------------------------------------------------------------------------


def test_a_text_swing_hangs_below_its_pivot_and_round_trips_through_tiled_json():
    level = parse_text(SWING)
    (sw,) = level.of_kind("swing")
    assert (sw.x, sw.y, sw.width, sw.height) == (368.0, 56.0, 96.0, 16.0)
    assert sw.props == {"length": LENGTH, "one_way": True}
    back = parse_tmj(json.loads(json.dumps(to_tmj(level))), "swing.tmj")  # its Tiled form loads back the same
    assert back.of_kind("swing") == [sw]


def _swing_map(**props) -> str:
    level = parse_text(SWING)
    tmj = to_tmj(level)
    (obj,) = [o for o in tmj["layers"][1]["objects"] if o["type"] == "swing"]
    obj["properties"] = [{"name": k, "value": v} for k, v in props.items() if v is not None]
    if props.get("width") is None and "width" in props:
        obj["width"] = 0
    return json.dumps(tmj)


BAD_SWINGS = [
    ({}, "has no length"),
    ({"length": 0}, "length must be > 0"),
    ({"length": -2.0}, "length must be > 0"),
    ({"length": "long"}, "length must be a number, got 'long'"),
    ({"length": True}, "length must be a number, got True"),
    ({"length": 3, "angle": 0}, "angle must be between 0 and 90 degrees"),
    ({"length": 3, "angle": 90}, "angle must be between 0 and 90 degrees"),
    ({"length": 3, "angle": -20}, "angle must be between 0 and 90 degrees"),
    ({"length": 3, "angle": "wide"}, "angle must be a number"),
    ({"length": 3, "period": 0}, "period must be > 0 seconds"),
    ({"length": 3, "period": -1.5}, "period must be > 0 seconds"),
    ({"length": 3, "period": [2]}, "period must be a number"),
    ({"length": 3, "phase": "late"}, "phase must be a number"),
    ({"length": 3, "one_way": "yes"}, "one_way must be true or false"),
    ({"length": 3, "width": None}, "needs a rectangle"),
]


@pytest.mark.parametrize(("props", "problem"), BAD_SWINGS, ids=[p for _, p in BAD_SWINGS])
def test_bad_swing_properties_are_level_errors_naming_the_problem(tmp_path, props, problem):
    path = tmp_path / "swing.tmj"
    path.write_text(_swing_map(**props))
    with pytest.raises(LevelError) as info:
        load_level(path)
    msg = str(info.value)
    assert msg.startswith(str(path)) and "swing at (" in msg and problem in msg, msg


def test_good_swing_properties_load(tmp_path):
    path = tmp_path / "swing.tmj"
    path.write_text(_swing_map(length=2.5, angle=45.0, period=3, phase=-30, one_way=True))
    (sw,) = load_level(path).of_kind("swing")
    assert sw.props == {"length": 2.5, "angle": 45.0, "period": 3, "phase": -30, "one_way": True}


@pytest.mark.parametrize(("text", "problem"), [
    ("#..o...#\n#......#\n#P.SS.G#\n########", "make it an odd number"),
    ("#......#\n#......#\n#P.SSSG#\n########", "has no pivot"),
    ("#..o...#\n#......#\n#P.SSSG#\n########", "has no pivot"),  # not above the middle
    ("#...o..#\n#...#..#\n#P.SSSG#\n########", "has no pivot"),  # a tile between
    ("#o.....#\n#......#\n#P...G.#\n########", "'o' at line 1, column 2 is not the pivot of a swing"),
])
def test_bad_text_swings_are_level_errors(text, problem):
    with pytest.raises(LevelError, match=problem):
        parse_text(text, "s.txt")


# --- the shipped level 4 ---------------------------------------------------------------------------------


def test_the_swings_level_has_three_swings_over_pits_a_checkpoint_and_a_goal():
    level = load_level(builtin_levels()[3])
    assert level.name == "Swings" and len(builtin_levels()) == 5
    swings = level.of_kind("swing")
    assert len(swings) == 3 and len(level.of_kind("checkpoint")) == 1 and len(level.of_kind("goal")) == 1
    ground = len(level.tiles) - 1
    for sw in swings:  # each hangs over a pit: no floor under the board's middle
        col = int(sw.x // level.tile)
        assert level.tiles[ground][col] is None and level.tiles[ground - 1][col] is None
    # the ropes grow longer, the pits wider
    assert [sw.props["length"] for sw in swings] == sorted(sw.props["length"] for sw in swings)


@pytest.mark.slow
@pytest.mark.parametrize("solver", SOLVERS)
def test_demo_crosses_the_swings_to_the_goal_with_every_coin(solver):
    g = Game([builtin_levels()[3]], autoplay=Autoplay(level4), scene=Scene(solver=solver))
    rides = set()
    while not g.state.reached_goal and g.scene.frame < 2000:
        g.step()
        ground = g.player_state.ground
        if ground is not None and g.scene.try_get(ground, SwingingPlatform) is not None:
            rides.add(ground)
    assert g.state.reached_goal and g.state.deaths == 0
    assert len(rides) == 3  # it rode every swing
    assert g.state.coins == g.state.coin_total_in_level == 12
    assert g.scene.frame == 1356  # (docs/platformer.md gives it)
