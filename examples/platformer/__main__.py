"""Command line: ``python -m examples.platformer [options]`` (installed: ``framework.examples.platformer``).

Plays in a window by default (arrows/WASD to run, space/up/W to jump, down+jump to drop through a
one-way platform, R to restart the level, F1 for the debug overlay, Esc to quit).

--headless         run without a window; print a one-line JSON summary as the last line
--demo             scripted input instead of the keyboard (headless: stops at the first goal; with
                   --level, that level's script if it is a shipped one, else the first level's)
--frames N         stop after N frames (headless default: 600, or 3600 with --demo)
--level PATH       play this map (.tmj or .txt) instead of the shipped levels
--screenshot PATH  after the run, write a PNG of the last frame (headless rendering)
--debug            start with the debug overlay (and draw it in the screenshot)
--zoom Z           camera zoom (screen pixels per world unit)

Without a display (and without --headless), it says so in one line on stderr, with how to play
instead, and exits with status 1: it never runs an invisible window.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

from .demo import SCRIPTS, Autoplay, level1, play_all
from .game import DT, Game
from .hud import install_hud
from .levels import LevelError, builtin_levels

__all__ = ["BACKGROUND", "camera_for", "demo_script", "hud", "main", "make_game", "parse_args", "run_headless",
           "run_window"]

WIDTH, HEIGHT = 960, 540
BACKGROUND = (24, 26, 38)


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(prog=f"python -m {__package__}", description="The example platformer.")
    ap.add_argument("--headless", action="store_true", help="run without a window and print a JSON summary")
    ap.add_argument("--demo", action="store_true", help="scripted input that plays the first level")
    ap.add_argument("--frames", type=int, default=None, metavar="N", help="stop after N frames")
    ap.add_argument("--level", default=None, metavar="PATH", help="a level file (.tmj or .txt)")
    ap.add_argument("--screenshot", default=None, metavar="PATH", help="write a PNG of the last frame")
    ap.add_argument("--debug", action="store_true", help="start with the debug overlay")
    ap.add_argument("--zoom", type=float, default=1.0, metavar="Z", help="camera zoom (default 1)")
    args = ap.parse_args(argv)
    if args.frames is not None and args.frames < 0:
        ap.error(f"--frames must be >= 0, got {args.frames}")
    if not args.zoom > 0:
        ap.error(f"--zoom must be > 0, got {args.zoom}")
    return args


def demo_script(level: str | None, headless: bool) -> Any:
    """What ``--demo`` plays: the shipped levels one after the other in a window; headless, the
    first level; with ``--level``, the script of that level if it is a shipped one (else the first
    level's)."""
    if level is not None:
        shipped = [p.resolve() for p in builtin_levels()]
        path = Path(level).resolve()
        return SCRIPTS[shipped.index(path)] if path in shipped[:len(SCRIPTS)] else level1
    return level1 if headless else play_all


def make_game(args: argparse.Namespace) -> Game:
    levels = [args.level] if args.level else builtin_levels()
    autoplay = None
    if args.demo:
        autoplay = Autoplay(demo_script(args.level, args.headless))
    view = (WIDTH / args.zoom, HEIGHT / args.zoom)
    return Game(levels, view=view, autoplay=autoplay)


def camera_for(game: Game, zoom: float) -> Any:
    from framework.render import Camera

    return Camera(target=game.state.player, bounds=game.state.bounds, zoom=zoom)


def hud(game: Game) -> str:
    st = game.state
    text = (f"Platformer - {st.level_name} ({st.level_index + 1}/{len(game.levels)}) - "
            f"coins {st.coins_in_level}/{st.coin_total_in_level} - deaths {st.deaths}")
    if st.finished:
        text += " - all levels done! R replays the last one"
    elif st.level_done:
        text += " - level complete!"
    return text


def run_headless(game: Game, args: argparse.Namespace) -> dict[str, Any]:
    limit = args.frames if args.frames is not None else (3600 if args.demo else 600)
    frames = 0
    t0 = time.perf_counter()
    while frames < limit:
        if args.demo and game.state.reached_goal:
            break
        game.step()
        frames += 1
    elapsed = time.perf_counter() - t0
    return {"frames": frames, "ms_per_frame": round(1e3 * elapsed / max(frames, 1), 4)}


def run_window(game: Game, args: argparse.Namespace) -> dict[str, Any]:
    from framework.render import run

    scene = game.scene
    camera = camera_for(game, args.zoom)

    def window_hud(scene: Any, dt: float) -> None:
        # The camera follows whichever player entity the current level has; the title says what the
        # on-screen HUD (hud.py) does, for the task bar.
        renderer = scene.renderer
        if renderer is None:
            return
        renderer.camera.target = game.state.player
        renderer.camera.bounds = game.state.bounds
        renderer.background = BACKGROUND
        window = getattr(renderer, "window", None)
        text = hud(game)
        if window is not None and getattr(window, "caption", None) != text:
            window.set_caption(text)

    scene.add_system(window_hud, after="response")
    t0 = time.perf_counter()
    run(scene, width=WIDTH, height=HEIGHT, title=hud(game), fps=round(1.0 / DT), camera=camera,
        debug=args.debug, max_frames=args.frames)
    ms = 1e3 * (time.perf_counter() - t0) / max(scene.frame, 1)
    return {"frames": scene.frame, "ms_per_frame": round(ms, 4)}


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    if not args.headless:  # before loading the levels: say at once that no window can be shown
        from framework.render.display import no_display_reason, no_window_line

        reason = no_display_reason()
        if reason is not None:
            print(no_window_line(reason, __package__), file=sys.stderr)
            return 1
    try:
        game = make_game(args)
    except LevelError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    with game:
        if not args.headless or args.screenshot:  # coins, deaths and the level on screen
            install_hud(game)
        if args.headless:
            result = run_headless(game, args)
        else:
            from framework.render import NoDisplayError

            try:
                result = run_window(game, args)
            except NoDisplayError as exc:  # the display is there but fails to open
                print(no_window_line(exc, __package__), file=sys.stderr)
                return 1
        if args.screenshot:
            from framework.render import screenshot

            screenshot(game.scene, args.screenshot, width=WIDTH, height=HEIGHT,
                       camera=camera_for(game, args.zoom), debug=args.debug, background=BACKGROUND)
        if args.headless:
            summary = {**result, **game.summary(), "levels": len(game.levels)}
            if args.screenshot:
                summary["screenshot"] = args.screenshot
            print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
