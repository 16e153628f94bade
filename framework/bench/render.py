"""The render benchmark: N moving sprites, ours beside a naive pyglet loop, a numpy floor and arcade.

Each frame is what a game pays to show moving sprites: move them, bring the drawing up to date,
draw into a 960 x 540 offscreen framebuffer, and wait for the GL to finish (``glFinish``), headless
(Mesa's llvmpipe here). Median milliseconds per frame over the timed frames.

- ``ours``: a scene with ``effects={"movement"}`` and a renderer attached; ``scene.step`` (moving
  the bodies and running the render stage), then the renderer's draw.
- ``naive``: what a user writes by hand with pyglet: one ``pyglet.shapes`` object (or
  ``pyglet.sprite.Sprite``) per body in a batch, positions moved with numpy and set body by body.
- ``ours CPU``: ours less what ``glFinish`` waits for (the render stage and issuing the draw
  calls): the part that grows with Python and numpy work, judged for linear growth.
- ``floor``: the cost of writing N quads' positions from numpy into one vertex list and drawing
  it: no per-body Python at all, and no rotation, colour or texture. The goal is measured
  against it: at 10,000 sprites, ours at most 1.5x the floor.
- ``arcade`` (optional: ``pip install arcade``): a ``SpriteList`` of ``SpriteSolidColor`` /
  textured sprites moved with ``sprite_list.update()`` and drawn, timed in its own process (it
  makes its own window and context), in rounds alternating with ours; the spread of the rounds is
  shown.

Kinds: ``boxes`` (filled AABBs), ``polygons`` (turning hexagons), ``circles``, ``images`` (one
image, a sprite each) and ``animated`` (a four-frame sprite sheet animation each, started at
different times). Ours, naive and floor are interleaved frame by frame in one process and GL context.
"""

from __future__ import annotations

import importlib.util
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from .report import Column, format_table, frozen_gc, machine_info, median, provenance

__all__ = ["FULL", "KINDS", "QUICK", "markdown", "run_render", "text_report"]

KINDS = ("boxes", "polygons", "circles", "images", "animated")
WIDTH, HEIGHT = 960, 540
SIZE = 6.0  # a sprite's side in pixels
DT = 1.0 / 60.0
FULL: dict[str, Any] = {"sizes": (1_000, 10_000, 50_000), "frames": {1_000: 60, 10_000: 40, 50_000: 16},
                        "warmup": 5, "arcade_rounds": 3}
QUICK: dict[str, Any] = {"sizes": (1_000, 10_000), "frames": {1_000: 20, 10_000: 12}, "warmup": 3,
                         "arcade_rounds": 1}


def _layout(n: int, seed: int = 7) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    x = rng.uniform(40.0, WIDTH - 40.0, n)
    y = rng.uniform(40.0, HEIGHT - 40.0, n)
    vx = rng.uniform(-30.0, 30.0, n)
    vy = rng.uniform(-30.0, 30.0, n)
    return x, y, vx, vy


def sheet_path(directory: Path) -> Path:
    """A 4-frame sprite sheet (24 x 6 pixels) written into ``directory``."""
    from ..render import write_png

    path = directory / "bench-sheet.png"
    if not path.exists():
        img = np.zeros((6, 24, 4), dtype=np.uint8)
        for k in range(4):
            img[:, 6 * k: 6 * k + 6] = (60 * k + 60, 200 - 40 * k, 90, 255)
        write_png(path, img)
    return path


# --- ours ---------------------------------------------------------------------------------------------


class Ours:
    def __init__(self, kind: str, n: int, directory: Path) -> None:
        from .. import AABB, Circle, Hitbox, Polygon, Scene, Transform, Velocity
        from ..components import Visual
        from ..render import Renderer
        from ..sprites import SpriteSheet

        self.scene = Scene(effects={"movement"})
        self.renderer = Renderer(width=WIDTH, height=HEIGHT, background=(0, 0, 0))
        self.scene.renderer = self.renderer
        x, y, vx, vy = _layout(n)
        sheet = SpriteSheet(sheet_path(directory), 6, 6)
        run = sheet.animation([0, 1, 2, 3], 0.1)
        hexagon = Polygon([(SIZE * 0.5 * math.cos(a), SIZE * 0.5 * math.sin(a))
                           for a in np.linspace(0, 2 * math.pi, 7)[:-1]])
        image = str(sheet_path(directory).with_name("bench-image.png"))
        if kind == "images" and not Path(image).exists():
            from ..render import write_png

            write_png(image, np.full((6, 6, 4), 220, dtype=np.uint8))
        for i in range(n):
            t = Transform(float(x[i]), float(y[i]))
            if kind == "boxes":
                comps: tuple[Any, ...] = (Hitbox(AABB(SIZE, SIZE)), Visual((200, 80, 60)))
            elif kind == "polygons":
                comps = (Hitbox(hexagon), Visual((80, 200, 60)))
            elif kind == "circles":
                comps = (Hitbox(Circle(SIZE / 2)), Visual((60, 80, 200)))
            elif kind == "images":
                comps = (Visual(image=image),)
            else:
                comps = (Visual(animation=run, started=-0.013 * (i % 31)),)
            w = 1.5 if kind in ("polygons", "images", "animated") else 0.0
            self.scene.spawn(t, Velocity(float(vx[i]), float(vy[i]), w), *comps)
        self.scene.step(DT)  # makes the drawables
        self.renderer.capture()
        self.cpu_ms: list[float] = []

    def frame(self) -> None:
        from pyglet import gl

        self.scene.step(DT)
        t0 = time.perf_counter()
        self.renderer._target.draw(WIDTH, HEIGHT, (0, 0, 0), self.renderer.render)
        issued = time.perf_counter() - t0
        gl.glFinish()
        # The CPU side of the frame: the render stage (in the step) and issuing the draw calls;
        # what glFinish waits for is the rasteriser (here llvmpipe, on the CPU too).
        self.cpu_ms.append(self.renderer.draw_ms + issued * 1e3)

    def close(self) -> None:
        self.renderer.close()
        self.scene.close()


# --- a naive pyglet loop and the floor ---------------------------------------------------------------


class _OneBatch:
    """A peer drawing one pyglet batch into the offscreen target, in the hidden window's context."""

    window: Any
    batch: Any

    def show(self, target: Any) -> None:
        from pyglet import gl

        target.draw(WIDTH, HEIGHT, (0, 0, 0), self._draw)
        gl.glFinish()

    def _draw(self) -> None:
        self.window.projection = _projection()
        self.batch.draw()


class Naive(_OneBatch):
    """One pyglet shape or sprite per body, positions moved with numpy and set one by one."""

    def __init__(self, kind: str, n: int, directory: Path) -> None:
        import pyglet

        from ..render import offscreen_window

        self.window = offscreen_window()
        self.batch = pyglet.graphics.Batch()
        self.x, self.y, self.vx, self.vy = _layout(n)
        self.angle = np.zeros(n)
        self.kind = kind
        self.objs: list[Any] = []  # pyglet shapes or sprites, one per body
        shapes = pyglet.shapes
        if kind in ("images", "animated"):
            sheet = pyglet.image.load(str(sheet_path(directory)))
            self.frames = list(pyglet.image.ImageGrid(sheet, 1, 4).get_texture_sequence())
            for f in self.frames:
                f.anchor_x = f.anchor_y = int(SIZE / 2)
            self.objs = [pyglet.sprite.Sprite(self.frames[0], float(x), float(y), batch=self.batch)
                         for x, y in zip(self.x, self.y)]
            self.shown = np.zeros(n, dtype=np.int64)
            self.started = -0.013 * (np.arange(n) % 31)
        elif kind == "circles":
            self.objs = [shapes.Circle(float(x), float(y), SIZE / 2, color=(60, 80, 200), batch=self.batch)
                         for x, y in zip(self.x, self.y)]
        elif kind == "polygons":
            pts = [(SIZE * 0.5 * math.cos(a), SIZE * 0.5 * math.sin(a)) for a in np.linspace(0, 2 * math.pi, 7)[:-1]]
            self.objs = [shapes.Polygon(*pts, color=(80, 200, 60), batch=self.batch) for _ in range(n)]
            for o, x, y in zip(self.objs, self.x, self.y):
                o.anchor_position = (0.0, 0.0)
                o.position = (float(x), float(y))
        else:
            self.objs = [shapes.Rectangle(float(x) - SIZE / 2, float(y) - SIZE / 2, SIZE, SIZE, color=(200, 80, 60),
                                          batch=self.batch) for x, y in zip(self.x, self.y)]
        self.time = 0.0

    def frame(self, target: Any) -> None:

        self.x += self.vx * DT
        self.y += self.vy * DT
        self.time += DT
        kind = self.kind
        if kind == "boxes":
            for o, x, y in zip(self.objs, (self.x - SIZE / 2).tolist(), (self.y - SIZE / 2).tolist()):
                o.position = (x, y)
        elif kind == "circles":
            for o, x, y in zip(self.objs, self.x.tolist(), self.y.tolist()):
                o.position = (x, y)
        else:
            self.angle += 1.5 * DT
            deg = (-np.degrees(self.angle)).tolist()
            if kind == "animated":
                idx = (np.floor(np.fmod(self.time - self.started, 0.4) / 0.1).astype(np.int64)).clip(0, 3)
                for o, i, old in zip(self.objs, idx.tolist(), self.shown.tolist()):
                    if i != old:
                        o.image = self.frames[i]
                self.shown = idx
            if kind == "polygons":
                for o, x, y, r in zip(self.objs, self.x.tolist(), self.y.tolist(), deg):
                    o.position = (x, y)
                    o.rotation = r
            else:
                for o, x, y, r in zip(self.objs, self.x.tolist(), self.y.tolist(), deg):
                    o.update(x=x, y=y, rotation=r)
        self.show(target)

    def close(self) -> None:
        for o in self.objs:
            o.delete()


_FLOOR_VERTEX = """#version 150 core
in vec2 position;
in vec4 colors;
out vec4 vertex_colors;
uniform WindowBlock { mat4 projection; mat4 view; } window;
void main() { gl_Position = window.projection * window.view * vec4(position, 0.0, 1.0); vertex_colors = colors; }
"""
_FLOOR_FRAGMENT = """#version 150 core
in vec4 vertex_colors;
out vec4 final_colors;
void main() { final_colors = vertex_colors; }
"""


class Floor(_OneBatch):
    """N quads (two triangles each) whose positions are written from numpy into one vertex list."""

    def __init__(self, kind: str, n: int, directory: Path) -> None:
        import pyglet
        from pyglet import gl

        from ..render import offscreen_window

        self.window = offscreen_window()
        self.batch = pyglet.graphics.Batch()
        ctx = pyglet.gl.current_context
        assert ctx is not None  # offscreen_window() made it current
        self.program = ctx.create_program((_FLOOR_VERTEX, "vertex"), (_FLOOR_FRAGMENT, "fragment"))
        self.x, self.y, self.vx, self.vy = _layout(n)
        self.corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, -1], [1, 1], [-1, 1]], dtype=np.float32) * SIZE / 2
        self.vlist: Any = self.program.vertex_list(6 * n, gl.GL_TRIANGLES, self.batch,
                                              colors=("Bn", (200, 80, 60, 255) * (6 * n)))
        self.n = n

    def frame(self, target: Any) -> None:

        self.x += self.vx * DT
        self.y += self.vy * DT
        centres = np.stack([self.x, self.y], axis=1).astype(np.float32)
        pos = (centres[:, None, :] + self.corners[None, :, :]).reshape(-1)
        self.vlist.position[:] = pos
        self.show(target)

    def close(self) -> None:
        self.vlist.delete()


def _projection() -> Any:
    from pyglet.math import Mat4

    return Mat4.orthogonal_projection(0.0, float(WIDTH), 0.0, float(HEIGHT), -8192.0, 8192.0)


# --- arcade, in its own process ---------------------------------------------------------------------


_ARCADE_SCRIPT = r"""
import json, math, os, sys, time
os.environ.setdefault("ARCADE_HEADLESS", "1")
import numpy as np
import arcade
kind, n, frames, warmup, sheet = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), sys.argv[5]
window = arcade.Window(960, 540, "bench", visible=False)
rng = np.random.default_rng(7)
x = rng.uniform(40.0, 920.0, n); y = rng.uniform(40.0, 500.0, n)
vx = rng.uniform(-30.0, 30.0, n); vy = rng.uniform(-30.0, 30.0, n)
sprites = arcade.SpriteList()
if kind in ("images", "animated"):
    textures = [arcade.load_texture(sheet).crop(6 * k, 0, 6, 6) for k in range(4)]
for i in range(n):
    if kind in ("images", "animated"):
        if kind == "animated":
            s = arcade.TextureAnimationSprite(animation=arcade.TextureAnimation(
                [arcade.TextureKeyframe(t, 100) for t in textures]))
        else:
            s = arcade.Sprite(textures[0])
    elif kind == "circles":
        s = arcade.SpriteCircle(3, (60, 80, 200))
    else:
        s = arcade.SpriteSolidColor(6, 6, color=(200, 80, 60))
    s.center_x, s.center_y = float(x[i]), float(y[i])
    s.change_x, s.change_y = float(vx[i]) / 60.0, float(vy[i]) / 60.0
    if kind in ("polygons", "images", "animated"):
        s.change_angle = math.degrees(1.5) / 60.0
    sprites.append(s)
ctx = window.ctx
fbo = ctx.framebuffer(color_attachments=[ctx.texture((960, 540), components=4)])
times = []
for k in range(warmup + frames):
    t0 = time.perf_counter()
    sprites.update(1 / 60)
    if kind == "animated":
        sprites.update_animation(1 / 60)
    with fbo.activate():
        fbo.clear()
        sprites.draw()
    ctx.finish()
    if k >= warmup:
        times.append((time.perf_counter() - t0) * 1e3)
print(json.dumps({"ms": sorted(times)[len(times) // 2], "arcade": arcade.version.VERSION}))
"""


def _arcade_round(kind: str, n: int, frames: int, warmup: int, sheet: Path) -> tuple[float | None, str]:
    with tempfile.NamedTemporaryFile("w", suffix=".py", delete=False) as f:
        f.write(_ARCADE_SCRIPT)
        script = f.name
    try:
        env = dict(os.environ, PYGLET_HEADLESS="1", PYGLET_SHADOW_WINDOW="0")
        out = subprocess.run([sys.executable, script, kind, str(n), str(frames), str(warmup), str(sheet)],
                             capture_output=True, text=True, timeout=600, env=env)
        if out.returncode != 0:
            return None, out.stderr.strip().splitlines()[-1] if out.stderr.strip() else "failed"
        data = json.loads(out.stdout.strip().splitlines()[-1])
        return float(data["ms"]), str(data["arcade"])
    except (subprocess.TimeoutExpired, ValueError, KeyError) as exc:
        return None, str(exc)
    finally:
        os.unlink(script)


# --- the run ----------------------------------------------------------------------------------------


def _time_interleaved(contenders: dict[str, Any], frames: int, warmup: int, target: Any) -> dict[str, float | None]:
    times: dict[str, list[float]] = {name: [] for name in contenders}
    for k in range(warmup + frames):
        for name, c in contenders.items():
            t0 = time.perf_counter()
            c.frame() if name == "ours" else c.frame(target)
            if k >= warmup:
                times[name].append((time.perf_counter() - t0) * 1e3)
    return {name: median(ts) for name, ts in times.items()}


def run_render(*, sizes: tuple[int, ...] = FULL["sizes"], kinds: tuple[str, ...] = KINDS, quick: bool = False,
               progress: bool = True, arcade: bool = True) -> dict[str, Any]:
    """Time every kind at every size; a report with one row per (kind, size)."""
    import framework.render  # noqa: F401  (headless pyglet set-up before pyglet's GL modules load)

    from ..render.offscreen import OffscreenTarget

    cfg = QUICK if quick else FULL
    # arcade is only looked for here: it runs in its own process (imported here, it would set up
    # pyglet's windowing for itself).
    have_arcade = arcade and importlib.util.find_spec("arcade") is not None
    rows: list[dict[str, Any]] = []
    target = OffscreenTarget()
    arcade_version = ""
    with tempfile.TemporaryDirectory() as tmp:
        directory = Path(tmp)
        for kind in kinds:
            for n in sizes:
                frames = cfg["frames"].get(n, min(60, max(8, 400_000 // max(n, 1))))
                if progress:
                    print(f"render: {kind} x {n} ...", file=sys.stderr, flush=True)
                ours = Ours(kind, n, directory)
                naive = Naive(kind, n, directory)
                floor = Floor(kind, n, directory)
                with frozen_gc():
                    ms = _time_interleaved({"ours": ours, "naive": naive, "floor": floor}, frames, cfg["warmup"],
                                           target)
                draws = ours.renderer.stats.get("drawn", 0)
                cpu = median(ours.cpu_ms[-frames:])
                for c in (ours, naive, floor):
                    c.close()
                arcade_ms: list[float] = []
                if have_arcade:
                    for _ in range(cfg["arcade_rounds"]):
                        value, arcade_version = _arcade_round(kind, n, frames, cfg["warmup"], sheet_path(directory))
                        if value is not None:
                            arcade_ms.append(value)
                row: dict[str, Any] = {"kind": kind, "n": n, "drawn": draws, "ours_ms": ms["ours"], "ours_cpu_ms": cpu,
                                       "naive_ms": ms["naive"], "floor_ms": ms["floor"],
                                       "arcade_ms": median(arcade_ms),
                                       "arcade_spread": (f"{min(arcade_ms):.1f}-{max(arcade_ms):.1f}"
                                                         if arcade_ms else "")}
                row["vs_floor"] = row["ours_ms"] / row["floor_ms"] if row["floor_ms"] else None
                row["vs_naive"] = row["ours_ms"] / row["naive_ms"] if row["naive_ms"] else None
                row["vs_arcade"] = row["ours_ms"] / row["arcade_ms"] if row["arcade_ms"] else None
                rows.append(row)
    target.delete()
    for kind in kinds:  # growth of a frame's CPU cost per sprite from the smallest size
        mine = [r for r in rows if r["kind"] == kind]
        if len(mine) >= 2 and mine[0]["ours_cpu_ms"]:
            lo = mine[0]
            for r in mine:
                r["per_sprite_growth"] = (r["ours_cpu_ms"] / r["n"]) / (lo["ours_cpu_ms"] / lo["n"])
    goals = _goals(rows)
    return {"benchmark": "render", "quick": quick, "machine": machine_info(), "rows": rows, "goals": goals,
            "arcade": arcade_version or ("not installed" if not have_arcade else "failed")}


def _goals(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    out = []
    at10k = [r for r in rows if r["n"] == 10_000]
    for r in at10k:
        out.append({"goal": f"{r['kind']} at 10k: ours <= 1.5x floor", "value": r["vs_floor"],
                    "met": r["vs_floor"] is not None and r["vs_floor"] <= 1.5})
        if r["vs_arcade"] is not None:
            out.append({"goal": f"{r['kind']} at 10k: ours >= 2x faster than arcade", "value": r["vs_arcade"],
                        "met": r["vs_arcade"] <= 0.5})
    for kind in {r["kind"] for r in rows}:
        mine = [r for r in rows if r["kind"] == kind and "per_sprite_growth" in r]
        if len(mine) >= 2:
            worst = max(r["per_sprite_growth"] for r in mine)
            out.append({"goal": f"{kind}: CPU cost per sprite grows no faster than linearly (<= 1.0x from "
                                f"{mine[0]['n']:,} to {mine[-1]['n']:,})", "value": worst, "met": worst <= 1.0})
    return out


COLUMNS: list[Column] = [
    ("kind", "kind", "str"), ("n", "sprites", "int"), ("ours_ms", "ours ms", "ms"),
    ("ours_cpu_ms", "ours CPU ms", "ms"),
    ("floor_ms", "floor ms", "ms"), ("naive_ms", "naive pyglet ms", "ms"), ("arcade_ms", "arcade ms", "ms"),
    ("arcade_spread", "arcade rounds", "str"), ("vs_floor", "ours / floor", "ratio"),
    ("vs_naive", "ours / naive", "ratio"), ("vs_arcade", "ours / arcade", "ratio"),
]


def text_report(report: dict[str, Any]) -> str:
    lines = [format_table(report["rows"], COLUMNS), ""]
    for g in report["goals"]:
        lines.append(f"{'PASS' if g['met'] else 'FAIL'}  {g['goal']}: {g['value']:.2f}")
    lines.append(f"arcade: {report['arcade']}")
    return "\n".join(lines)


def markdown(report: dict[str, Any], command: str, plot: str | None = None) -> str:
    m = report["machine"]
    stem = "render-quick" if report["quick"] else "render"
    head = provenance(m, command, f"arcade {report['arcade']}", stem)
    lines = [head, "", "| " + " | ".join(h for _, h, _ in COLUMNS) + " |",
             "|" + "|".join("---" if f == "str" else "---:" for _, _, f in COLUMNS) + "|"]
    from .report import fmt

    for r in report["rows"]:
        lines.append("| " + " | ".join(fmt(r.get(k), f) for k, _, f in COLUMNS) + " |")
    lines += ["", "| goal | value | met |", "|---|---:|---|"]
    for g in report["goals"]:
        lines.append(f"| {g['goal']} | {g['value']:.2f} | {'yes' if g['met'] else '**no**'} |")
    if plot:
        lines += ["", f"![render benchmark]({plot})"]
    return "\n".join(lines)
