"""The example platformer (examples/platformer): headless, scripted input through ``Input``.

Levels are written inline in the text format (``#`` solid, ``-`` one-way, ``P`` player, ``C`` coin,
``E`` enemy, ``^`` spikes, ``G`` goal, ``K`` checkpoint, ``M`` moving platform, ``~`` its path);
one tile is 32 world units, the bottom row of a map is y 0..32.
"""

from __future__ import annotations

import base64
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from examples.platformer import Game, LevelError, builtin_levels, load_level, parse_text, parse_tmj
from examples.platformer.__main__ import main as cli_main
from examples.platformer.components import Coin, Enemy, Hazard, MovingPlatform, Player, Tuning
from examples.platformer.demo import Autoplay, level1, level2
from examples.platformer.levels import to_tmj
from framework import Hitbox, Transform, Velocity
from framework.testing import (
    EventLog,
    assert_at_rest,
    assert_inside,
    assert_on_floor,
    bounds,
    feet,
    run,
    step_until,
)

ROOT = Path(__file__).resolve().parents[1]
T = 32.0
TU = Tuning()
RUN = TU.run_speed * T          # world units / s
JUMP = TU.jump_speed * T
G = TU.gravity * T
DT = 1.0 / 60.0


def vel(g: Game) -> Velocity:
    return g.scene.get(g.player, Velocity)


# --- the demo and the command line ---------------------------------------------------------------


@pytest.mark.slow
def test_demo_plays_the_first_level_to_its_goal():
    g = Game(autoplay=Autoplay(level1))
    while not g.state.reached_goal and g.scene.frame < 2400:
        g.step()
    assert g.state.reached_goal and g.state.level_index == 0
    assert g.state.deaths == 0 and g.state.coins >= 10
    assert not g.scene.query(Enemy)  # it stomped both walkers on the way


@pytest.mark.slow
def test_second_level_can_be_played_through():
    g = Game([builtin_levels()[1]], autoplay=Autoplay(level2))
    while not g.state.reached_goal and g.scene.frame < 2600:
        g.step()
    assert g.state.reached_goal and g.state.deaths == 0


@pytest.mark.slow
def test_cli_headless_demo_prints_a_json_summary_last():
    out = subprocess.run([sys.executable, "-m", "examples.platformer", "--headless", "--demo"], cwd=ROOT,
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    summary = json.loads(out.stdout.strip().splitlines()[-1])
    assert summary["reached_goal"] is True and summary["deaths"] == 0 and summary["coins"] >= 10
    assert 0 < summary["frames"] < 3600 and summary["ms_per_frame"] > 0


def test_headless_run_without_screenshot_never_imports_pyglet_gl(tmp_path):
    level = tmp_path / "tiny.txt"
    level.write_text("#......#\n#.P..G.#\n########\n")
    code = ("import sys, io, contextlib\n"
            "from examples.platformer.__main__ import main\n"
            "buf = io.StringIO()\n"
            "with contextlib.redirect_stdout(buf):\n"
            f"    main(['--headless', '--frames', '30', '--level', {str(level)!r}])\n"
            "print(buf.getvalue().strip().splitlines()[-1])\n"
            "print(sorted(m for m in sys.modules if m.startswith(('pyglet.gl', 'pyglet.window'))))\n")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    summary, mods = out.stdout.strip().splitlines()[-2:]
    assert json.loads(summary)["frames"] == 30
    assert mods == "[]"


def test_cli_reports_a_bad_level_and_exits_2(tmp_path, capsys):
    bad = tmp_path / "broken.tmj"
    bad.write_text("{not json")
    assert cli_main(["--headless", "--level", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "broken.tmj" in err and "not valid JSON" in err


def test_cli_screenshot(tmp_path):
    try:
        import framework.render as render

        render.offscreen_window()
    except Exception as exc:  # no GL library, no EGL device: not a failure of the game
        pytest.skip(f"no OpenGL context available here ({type(exc).__name__}: {exc})")
    png = tmp_path / "shot.png"
    assert cli_main(["--headless", "--frames", "5", "--screenshot", str(png)]) == 0
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert int.from_bytes(data[16:20], "big") == 960 and int.from_bytes(data[20:24], "big") == 540


# --- standing, running, walls --------------------------------------------------------------------


@pytest.mark.slow
def test_lands_and_stands_still_for_thousands_of_frames():
    g = Game([parse_text("""
#..........#
#....P.....#
#..........#
############
""")])
    run(g.scene, 40, keys=set())
    y0 = g.player_transform.y
    assert feet(g.scene, g.player) == pytest.approx(T, abs=1e-9)  # on top of the floor row (y 0..32)
    for _ in range(2000):
        g.step(set())
        assert abs(g.player_transform.y - y0) <= 1e-9
        assert g.player_state.grounded
        assert_on_floor(g.scene, g.player)
    assert_at_rest(g.scene, g.player, speed=0.0)


def test_runs_across_tile_seams_at_constant_speed():
    g = Game([parse_text("#" + "." * 60 + "#\n#P" + "." * 58 + "G#\n" + "#" * 62)])
    run(g.scene, 10, keys=set())
    xs, ys = [], []
    for _ in range(200):
        g.step({"right"})
        xs.append(g.player_transform.x)
        ys.append(g.player_transform.y)
        assert g.player_state.grounded
    # From full speed on, every step covers exactly RUN * DT: no seam slows it down.
    full = [b - a for a, b in zip(xs[20:], xs[21:])]
    assert all(abs(d - RUN * DT) < 1e-9 for d in full)
    assert max(ys) - min(ys) <= 1e-9


@pytest.mark.parametrize("direction", ["right", "left"])
def test_cannot_run_through_a_thin_wall(direction):
    g = Game([parse_text("""
#...............#
#...............#
#.......#.......#
#...P...#...G...#
#################
""")])
    wall_x = 8.5 * T
    side = -1 if direction == "right" else 1
    if direction == "left":
        g.player_transform.x = 12.5 * T
    run(g.scene, 10, keys=set())
    for _ in range(240):  # keeps pushing at full speed
        g.step({direction})
        assert (g.player_transform.x - wall_x) * side > 0.5 * T
    assert vel(g).x == 0.0 or abs(vel(g).x) < RUN


def test_cannot_fall_through_a_one_tile_floor_at_terminal_speed():
    g = Game([parse_text("#....#\n#.P..#\n" + "#....#\n" * 40 + "######\n" + "#....#\n" * 3 + "#...G#\n")])
    floor_top = 5 * T  # the floor is row 42 of 47
    vmin = 0.0
    for _ in range(400):
        g.step(set())
        vmin = min(vmin, vel(g).y)
        assert feet(g.scene, g.player) >= floor_top - 1e-9
    assert vmin <= -TU.fall_speed * T  # it did reach terminal speed
    assert feet(g.scene, g.player) == pytest.approx(floor_top, abs=1e-9) and g.player_state.grounded
    assert_on_floor(g.scene, g.player)


def test_cannot_jump_through_a_one_tile_ceiling():
    g = Game([parse_text("""
#......#
#......#
########
#......#
#..P..G#
########
""")])
    run(g.scene, 10, keys=set())
    ceiling = 3 * T
    for _ in range(60):
        g.step({"space"})
        assert bounds(g.scene, g.player)[3] <= ceiling + 1e-9  # its head


def test_diagonal_max_speed_into_a_corner_stays_inside():
    g = Game([parse_text("""
#......#
#.P....#
#......#
#.....G#
########
""")])
    for _ in range(120):
        vel(g).y = -TU.fall_speed * T  # the fastest the game ever moves the player, down and right
        g.step({"right"})
        assert_inside(g.scene, g.player, (T, T - 1e-9, 7 * T + 1e-9, 5 * T))  # the walls, the floor


# --- jumping ---------------------------------------------------------------------------------------


def _apex(g: Game, hold: int) -> float:
    start = feet(g.scene, g.player)
    top = start
    for i in range(90):
        g.step({"space"} if i < hold else set())
        top = max(top, feet(g.scene, g.player))
    return top - start


def test_variable_jump_height():
    level = "#" + "." * 8 + "#\n"
    g = Game([parse_text(level * 8 + "#...P...G#\n" + "#" * 10)])
    run(g.scene, 10, keys=set())
    full = _apex(g, 60)
    run(g.scene, 10, keys=set())
    tap = _apex(g, 3)
    # A full jump rises v^2 / 2g (about 3.5 tiles; semi-implicit Euler lands a step's fall short).
    assert full == pytest.approx(JUMP * JUMP / (2 * G), abs=JUMP * DT)
    assert tap < 0.5 * full


LEDGE_LEVEL = """
#..............#
#..............#
#.P............#
#####..........#
#..............#
#..............#
#..............#
#.............G#
################
"""


def _run_off_the_ledge(g: Game) -> None:
    run(g.scene, 10, keys=set())
    step_until(g.scene, lambda s: not g.player_state.grounded, within=120, keys={"right"}, what="running off the ledge")


def test_coyote_time():
    g = Game([parse_text(LEDGE_LEVEL)])
    _run_off_the_ledge(g)
    run(g.scene, 4, keys={"right"})  # 5 frames in the air: still within coyote time (0.1 s)
    g.step({"right", "space"})
    assert vel(g).y > 0.5 * JUMP
    g = Game([parse_text(LEDGE_LEVEL)])
    _run_off_the_ledge(g)
    run(g.scene, 12, keys={"right"})  # too late
    g.step({"right", "space"})
    assert vel(g).y < 0
    run(g.scene, 60, keys=set())
    assert g.player_state.grounded and feet(g.scene, g.player) == pytest.approx(T, abs=1e-9)  # landed, no jump
    assert_on_floor(g.scene, g.player)


def _jump_pressed_before_landing(early: int) -> float:
    """A full jump from the ledge, then the same jump with jump tapped ``early`` steps before it
    lands; the highest vertical velocity in the few steps after the landing."""
    g = Game([parse_text(LEDGE_LEVEL)])
    run(g.scene, 10, keys=set())
    g.step({"space"})
    n = 1 + step_until(g.scene, lambda s: g.player_state.grounded, within=240, keys=set(), what="landing")
    run(g.scene, 5, keys=set())
    g.step({"space"})
    run(g.scene, n - 1 - early, keys=set())
    g.step({"space"})  # tapped: pressed and released
    best = -math.inf
    for _ in range(early + 4):
        g.step(set())
        best = max(best, vel(g).y)
    return best


def test_jump_buffer():
    assert _jump_pressed_before_landing(5) > 0  # remembered: it jumps as it lands (a short hop)
    assert _jump_pressed_before_landing(12) <= 0  # too early: forgotten


# --- one-way platforms -----------------------------------------------------------------------------


ONE_WAY_LEVEL = """
#........#
#........#
#........#
#........#
#...---..#
#........#
#....P..G#
##########
"""


@pytest.mark.slow
def test_one_way_platform_jump_up_through_land_stay_drop_down():
    g = Game([parse_text(ONE_WAY_LEVEL)])
    top = 4 * T  # the slab is the top quarter of row 4 of 8: 3 tiles above the floor
    run(g.scene, 10, keys=set())
    rise = []
    for _ in range(40):
        g.step({"space"})
        rise.append(feet(g.scene, g.player))
    assert max(rise) > top  # went up through it from below
    run(g.scene, 30, keys=set())
    assert feet(g.scene, g.player) == pytest.approx(top, abs=1e-9) and g.player_state.grounded  # and landed on it
    y = g.player_transform.y
    for _ in range(500):
        g.step(set())
        assert abs(g.player_transform.y - y) <= 1e-9
        assert_on_floor(g.scene, g.player)
    g.step({"space"})  # a plain jump from it is a jump, not a drop
    assert vel(g).y > 0
    run(g.scene, 60, keys=set())
    assert feet(g.scene, g.player) == pytest.approx(top, abs=1e-9)
    g.step({"down"})
    g.step({"down", "space"})  # down + jump: drop through
    run(g.scene, 40, keys={"down"})
    assert feet(g.scene, g.player) == pytest.approx(T, abs=1e-9) and g.player_state.grounded
    assert_on_floor(g.scene, g.player)
    hb = g.scene.get(g.player, Hitbox)
    assert hb.mask & 2  # the one-way layer is back in the mask
    run(g.scene, 10, keys=set())
    run(g.scene, 60, keys={"space"})  # and it is solid from above again after the drop
    assert feet(g.scene, g.player) == pytest.approx(top, abs=1e-9)


def test_walks_off_a_one_way_platform_edge_and_lands_on_the_floor():
    g = Game([parse_text(ONE_WAY_LEVEL)])
    run(g.scene, 10, keys=set())
    g.step({"space"})
    run(g.scene, 60, keys=set())
    run(g.scene, 60, keys={"right"})
    run(g.scene, 30, keys=set())
    assert feet(g.scene, g.player) == pytest.approx(T, abs=1e-9)
    assert_on_floor(g.scene, g.player)


# --- moving platforms ------------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("path", ["horizontal", "vertical"])
def test_rides_the_moving_platform(path):
    if path == "horizontal":
        text = "#..............#\n#.......P......#\n#.......MMM~~~~#\n" + "#..............#\n" * 3
    else:
        text = "#..............#\n#.......P......#\n#.......MMM....#\n" + "#.......~......#\n" * 3
    g = Game([parse_text(text + "#.............G#\n################")])
    (pe, plat), = g.scene.query(MovingPlatform)
    run(g.scene, 10, keys=set())
    pt = g.scene.get(pe, Transform)
    offsets = set()
    xs = set()
    for _ in range(720):  # several trips both ways, pauses and turns included
        g.step(set())
        assert g.player_state.grounded and g.player_state.ground == pe
        assert_on_floor(g.scene, g.player)
        offsets.add((round(g.player_transform.x - pt.x, 6), round(g.player_transform.y - pt.y, 6)))
        xs.add(round(pt.x if path == "horizontal" else pt.y))
    assert len(offsets) == 1  # carried exactly, never sliding or hopping
    assert max(xs) - min(xs) == pytest.approx(4 * T if path == "horizontal" else 3 * T, abs=1)


def test_can_walk_and_jump_on_a_moving_platform():
    g = Game([parse_text("#..............#\n#.......P......#\n#.......MMM~~~~#\n" + "#..............#\n" * 3
             + "#.............G#\n################")])
    (pe, _), = g.scene.query(MovingPlatform)
    run(g.scene, 10, keys=set())
    pt = g.scene.get(pe, Transform)
    dx0 = g.player_transform.x - pt.x
    run(g.scene, 8, keys={"right"})
    assert g.player_transform.x - pt.x > dx0 + 0.5 * T  # walks relative to it
    g.step({"space"})
    run(g.scene, 70, keys=set())
    assert g.player_state.ground == pe  # and lands on it again


# --- coins, spikes, enemies, checkpoints, the goal -------------------------------------------------


def test_coins_are_collected_exactly_once():
    g = Game([parse_text("""
#................#
#................#
#.P.CCCCC...CC..G#
##################
""")])
    assert g.state.coin_total_in_level == 7
    log = EventLog(g.scene)
    run(g.scene, 10, keys=set())
    run(g.scene, 120, keys={"right"})
    assert g.state.coins == 7 and g.state.coins_in_level == 7
    assert not g.scene.query(Coin)
    touched = log.between(Player, Coin, "started")  # one touch per coin: each taken at its first
    assert len(touched) == 7 and len({r.b if Coin in r.types_b else r.a for r in touched}) == 7
    run(g.scene, 120, keys={"left"})  # back over where they were
    assert g.state.coins == 7 and len(log.between(Player, Coin, "started")) == 7


def test_stomping_an_enemy_kills_it():
    g = Game([parse_text("""
#............#
#.....P......#
#............#
#............#
#.....E......#
#...........G#
##############
""")])
    (e, en), = g.scene.query(Enemy)
    en.speed = 0.0  # stands still under the falling player
    log = EventLog(g.scene)
    step_until(g.scene, lambda s: not s.query(Enemy), within=60, keys=set(), what="the stomp")
    log.assert_started(Player, e)
    assert g.state.deaths == 0
    assert vel(g).y > 0  # bounced off it


def test_touching_an_enemy_from_the_side_kills_and_respawns_at_the_checkpoint():
    g = Game([parse_text("""
#..................#
#.P...K.........E.G#
####################
""")])
    run(g.scene, 10, keys=set())
    checkpoint = (6.5 * T, T)
    log = EventLog(g.scene)
    step_until(g.scene, lambda s: g.state.deaths > 0, within=300, keys={"right"}, what="a death")
    log.assert_started(Player, Enemy)
    assert g.state.deaths == 1
    assert (g.player_transform.x, feet(g.scene, g.player)) == pytest.approx(checkpoint)
    assert_at_rest(g.scene, g.player, speed=0.0)
    assert len(g.scene.query(Enemy)) == 1


def test_spikes_and_falling_out_kill():
    g = Game([parse_text("""
#..........#
#.P..^^....#
#######...G#
""")])
    run(g.scene, 10, keys=set())
    log = EventLog(g.scene)
    step_until(g.scene, lambda s: g.state.deaths > 0, within=60, keys={"right"}, what="a death")
    log.assert_started(Player, Hazard)
    assert g.state.deaths == 1
    assert g.player_transform.x == pytest.approx(2.5 * T)  # no checkpoint: back to the start
    g.player_transform.x = 8.5 * T  # over the hole
    run(g.scene, 90, keys=set())
    assert g.state.deaths == 2 and feet(g.scene, g.player) == pytest.approx(T, abs=1e-9)
    assert_on_floor(g.scene, g.player)


@pytest.mark.slow
def test_enemies_turn_at_walls_and_spikes():
    g = Game([parse_text("""
#.......................#
#P#..E....#...^..E..#..G#
#########################
""")])
    seen: dict[int, set[int]] = {}
    xs: dict[int, list[float]] = {}
    log = EventLog(g.scene)
    for _ in range(600):
        g.step(set())
        for e, (en, t) in g.scene.query(Enemy, Transform):
            seen.setdefault(e, set()).add(en.direction)
            xs.setdefault(e, []).append(t.x / T)
    a, b = sorted(xs)
    assert seen[a] == seen[b] == {-1, 1}
    assert 3.0 < min(xs[a]) < 3.6 and 9.4 < max(xs[a]) < 10.0  # between the walls
    assert 14.9 < min(xs[b]) < 15.6 and 19.4 < max(xs[b]) < 20.0  # between the spikes and the wall
    log.assert_started(b, Hazard)  # the second turns where it touches the spikes ahead (its rule) ...
    log.assert_never(a, Hazard)  # ... the first, between two walls, never meets them
    assert g.state.deaths == 0


@pytest.mark.slow
def test_enemy_turns_at_a_ledge():
    g = Game([parse_text("""
#.............#
#....E........#
#...####......#
#............G#
#.P...........#
###############
""")])
    xs = []
    for _ in range(400):
        g.step(set())
        ((e, (_en, t)),) = g.scene.query(Enemy, Transform)
        xs.append(t.x / T)
        assert_on_floor(g.scene, e)  # never over the edge
    assert 4.0 < min(xs) < 4.6 and 7.4 < max(xs) < 8.0


def test_goal_then_next_level_and_restart():
    lvl_a = parse_text("#.....#\n#.P.G.#\n#######", "a.txt")
    lvl_b = parse_text("#......#\n#.C.P.G#\n########", "b.txt")
    g = Game([lvl_a, lvl_b])
    first = g.player
    step_until(g.scene, lambda s: g.state.reached_goal, within=120, keys={"right"}, what="the goal")
    assert g.state.levels_completed == 1
    # A second to see it, then the next level.
    step_until(g.scene, lambda s: g.state.level_index == 1 and g.state.player is not None, within=80, keys=set(),
               what="the next level")
    assert g.state.level_index == 1 and g.player != first and not g.scene.exists(first)
    assert g.player_transform.x == pytest.approx(4.5 * T)
    run(g.scene, 40, keys={"left"})
    assert g.state.coins == 1 and g.state.coins_in_level == 1
    g.step({"r"})  # restart: the level as it was, its coins back
    run(g.scene, 3, keys=set())
    assert g.state.level_index == 1 and g.state.coins_in_level == 0 and len(g.scene.query(Coin)) == 1
    assert g.player_transform.x == pytest.approx(4.5 * T) and g.state.coins == 1


def test_camera_follows_the_player_within_the_level():
    g = Game([parse_text("#" * 80 + "\n" + ("#" + "." * 78 + "#\n") * 3 + "#P" + "." * 76 + "G#\n" + "#" * 80)])
    vw, vh = g.state.view
    w, h = g.level.size
    xs = []
    for _ in range(400):
        g.step({"right"})
        cx, cy = g.state.camera
        xs.append(cx)
        assert vw / 2 <= cx <= w - vw / 2
        assert cy == pytest.approx(h / 2)  # the level is lower than the view: centred
    assert xs[0] == vw / 2 and xs[-1] > xs[0]


# --- level files -----------------------------------------------------------------------------------


def test_shipped_levels_load_and_round_trip_through_tiled_json():
    paths = builtin_levels()
    assert len(paths) >= 2 and all(p.suffix == ".tmj" for p in paths)
    for p in paths:
        lvl = load_level(p)
        assert lvl.of_kind("player") and lvl.of_kind("goal") and lvl.of_kind("coin")
        again = parse_tmj(json.loads(json.dumps(to_tmj(lvl))), "again.tmj")
        assert again.tiles == lvl.tiles and again.objects == lvl.objects


def _anchors(level) -> list[tuple]:
    """Where each object puts its entity: feet for the player and enemies, centre for coins,
    the rectangle for the rest (a text map gives cells, a Tiled map points)."""
    out = []
    for o in level.objects:
        if o.kind in ("player", "enemy"):
            out.append((o.kind, o.x, o.bottom))
        elif o.kind == "coin":
            out.append((o.kind, o.x, o.y))
        else:
            out.append((o.kind, o.x, o.y, o.width, o.height, sorted(o.props.items())))
    return out


def test_text_and_tiled_versions_of_a_level_agree_and_base64_data_works():
    text = "#.......#\n#.P.C.E.#\n#.MM~~.G#\n#--^^##.#\n#########"
    lvl = parse_text(text, "t.txt")
    tmj = to_tmj(lvl)
    layer = tmj["layers"][0]
    raw = b"".join(int(g).to_bytes(4, "little") for g in layer.pop("data"))
    layer.update(encoding="base64", data=base64.b64encode(raw).decode())
    again = parse_tmj(tmj, "b64.tmj")
    assert again.tiles == lvl.tiles and _anchors(again) == _anchors(lvl)
    kinds = {k for row in lvl.tiles for k in row}
    assert kinds == {None, "solid", "oneway", "spikes"}
    (plat,) = lvl.of_kind("platform")
    assert plat.props["dx"] == 2 and plat.width == 2 * T


def _tmj(**changes) -> dict:
    base = to_tmj(parse_text("#....#\n#P.CG#\n######", "x.txt"))
    for k, v in changes.items():
        if v is None:
            base.pop(k)
        else:
            base[k] = v
    return base


def _bad_tmj(mutate) -> str:
    d = _tmj()
    mutate(d)
    return json.dumps(d)


BAD_FILES = [
    ("broken.tmj", "{oops", "not valid JSON"),
    ("list.tmj", "[1, 2]", "must be a JSON object"),
    ("nowidth.tmj", json.dumps(_tmj(width=None)), "missing 'width'"),
    ("zero.tmj", json.dumps(_tmj(height=0)), "'height' must be a positive integer"),
    ("nonsquare.tmj", json.dumps(_tmj(tileheight=16)), "tiles must be square"),
    ("short.tmj", _bad_tmj(lambda d: d["layers"][0]["data"].pop()), "has 17 tiles, expected"),
    ("gid.tmj", _bad_tmj(lambda d: d["layers"][0]["data"].__setitem__(0, 9)), "tile 9"),
    ("objtype.tmj", _bad_tmj(lambda d: d["layers"][1]["objects"][0].__setitem__("type", "dragon")),
     "unknown object type 'dragon'"),
    ("noplayer.tmj", _bad_tmj(lambda d: d["layers"][1]["objects"].pop(0)), "exactly one player"),
    ("size.tmj", _bad_tmj(lambda d: d["layers"][1]["objects"][2].__setitem__("width", -3)), "negative size"),
    ("infinite.tmj", json.dumps(_tmj(infinite=True)), "infinite maps"),
    ("layer.tmj", _bad_tmj(lambda d: d["layers"][0].__setitem__("type", "hexlayer")), "unknown layer type"),
    ("pos.tmj", _bad_tmj(lambda d: d["layers"][1]["objects"][0].__setitem__("x", "left")),
     "'x' must be a finite number"),
    ("twoplayers.txt", "#....#\n#PP.G#\n######", "exactly one player start, found 2"),
    ("char.txt", "#....#\n#P.XG#\n######", "unknown character 'X' at line 2, column 4"),
    ("empty.txt", "\n\n", "the map is empty"),
    ("nopath.txt", "#......#\n#P.MM.G#\n########", "has no path"),
    ("twopaths.txt", "#.......#\n#P~MM~.G#\n#########", "several sides"),
    ("stray.txt", "#......#\n#P.~..G#\n########", "not next to a moving platform"),
    ("level.png", "whatever", "unknown level format '.png'"),
]


@pytest.mark.parametrize(("name", "content", "problem"), BAD_FILES, ids=[b[0] for b in BAD_FILES])
def test_bad_level_files_raise_value_error_naming_the_file(tmp_path, name, content, problem):
    path = tmp_path / name
    path.write_text(content)
    with pytest.raises(ValueError) as info:
        load_level(path)
    assert isinstance(info.value, LevelError)
    msg = str(info.value)
    assert msg.startswith(str(path)) and problem in msg, msg


def test_missing_level_file(tmp_path):
    with pytest.raises(ValueError, match="nothere.tmj: no such level file"):
        load_level(tmp_path / "nothere.tmj")


def test_player_state_resets_on_death():
    g = Game([parse_text("#.........#\n#.P..^...G#\n###########")])
    run(g.scene, 5, keys=set())
    g.scene.get(g.player, Player).drop_timer = 0.1
    step_until(g.scene, lambda s: g.state.deaths > 0, within=60, keys={"right"}, what="a death")
    p = g.player_state
    assert g.state.deaths == 1 and p.drop_timer == 0.0 and not p.jumping
    assert math.isfinite(g.player_transform.x)


def test_an_enemy_that_falls_out_of_the_level_is_removed():
    g = Game([parse_text("""
#.........#
#.P.....E.#
#######...#
""")])
    g.scene.get(g.scene.query(Enemy)[0][0], Enemy).direction = 1
    run(g.scene, 90, keys=set())
    assert not g.scene.query(Enemy) and g.state.deaths == 0


# --- crates and barrels (friction and rolling) ---------------------------------------------------------


def _prop(g: Game, kind: str) -> int:
    from examples.platformer.components import LevelPiece

    return next(e for e, p in g.scene.query(LevelPiece) if p.kind == kind)


def test_a_crate_moves_while_the_player_pushes_it_and_stops_when_it_stops():
    g = Game([parse_text("""
....................
.P.B................
####################
""")])
    crate = _prop(g, "crate")
    x0 = g.scene.get(crate, Transform).x
    run(g.scene, 60, keys={"right"})
    pushed = g.scene.get(crate, Transform).x
    assert pushed > x0 + 3 * T  # pushed along, several tiles in a second
    assert g.scene.get(crate, Velocity).x > 0.5 * RUN
    run(g.scene, 60, keys=set())  # let go: friction (0.6 of g) stops it within a fraction of a second
    stop = g.scene.get(crate, Transform).x
    assert_at_rest(g.scene, crate, speed=0.0)
    # it slides at most v^2 / (2 mu g) past where the push ended (plus a step of travel)
    assert stop - pushed <= RUN ** 2 / (2 * TU.prop_friction * G) + RUN * DT
    assert g.scene.get(crate, Transform).y == pytest.approx(T + TU.crate_size * T / 2, abs=1e-6)  # on the floor
    assert_on_floor(g.scene, crate)


def test_a_barrel_pushed_along_rolls_on_and_off_a_ledge():
    g = Game([parse_text("""
.......................
.P.O...................
##########.............
""")])
    barrel = _prop(g, "barrel")
    run(g.scene, 20, keys={"right"})
    v = g.scene.get(barrel, Velocity)
    assert v.x > 0.0 and v.angular == pytest.approx(-v.x / (TU.barrel_radius * T), rel=1e-6)  # rolling
    run(g.scene, 120, keys=set())  # let go: a rolling barrel keeps rolling (no rolling resistance) ...
    t = g.scene.get(barrel, Transform)
    assert t.x > 10 * T and t.y < T  # ... off the ledge at x = 10 tiles, falling


def test_crates_and_barrels_come_from_text_and_tiled_maps():
    level = parse_text("""
.P.B.O..
########
""", "props.txt")
    assert [o.kind for o in level.objects if o.kind in ("crate", "barrel")] == ["crate", "barrel"]
    again = parse_tmj(to_tmj(level), "props.tmj")
    assert [(o.kind, o.x, o.bottom) for o in again.objects] == [(o.kind, o.x, o.bottom) for o in level.objects]
    shipped = load_level(builtin_levels()[1])  # the caverns: a crate with a barrel on it behind the start
    assert {o.kind for o in shipped.objects} >= {"crate", "barrel"}
