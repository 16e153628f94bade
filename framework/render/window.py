"""The window runner: a pyglet window that steps a scene at a fixed timestep and shows it.

Fixed timestep with an accumulator: each frame adds the real time that passed (at most
:data:`MAX_FRAME_TIME`, so a stall drops time instead of spiralling) to an accumulator, then
runs ``scene.step(1 / fps)`` while a whole step fits in it (at most :data:`MAX_STEPS_PER_FRAME`).
The simulation therefore always advances by the same ``dt`` whatever the display does, and a
run is reproducible given the same input per step. The frame then shows the *last* state
(no interpolation between the last two states): a frame that ran no step shows the same picture
again; the leftover fraction of a step waits in the accumulator for the next frame.

Keys go into ``scene.resources[Input]`` as lower-case names (``"left"``, ``"space"``, ``"a"``,
``"f1"``, ``"escape"``, digits as ``"1"``): game systems read them in the next step, no globals.
F1 toggles the debug overlay, Escape closes the window; ``on_key(scene, key)`` is called on every
key press (after the Input update) and may return a new scene to switch to (e.g. a restart).

Where no window can be seen (no display, or one that fails to open), :class:`~.display.NoDisplayError`
is raised before anything runs: never an invisible window running on with nobody to close it.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import pyglet
from pyglet import gl
from pyglet.window import key as _key

from ..input import Input
from .camera import Camera
from .display import NoDisplayError, no_display_reason, open_failure
from .renderer import Renderer

__all__ = ["MAX_FRAME_TIME", "MAX_STEPS_PER_FRAME", "Runner", "key_name", "run"]

MAX_FRAME_TIME = 0.25
MAX_STEPS_PER_FRAME = 8


def key_name(symbol: int) -> str:
    """pyglet's key symbol as the framework's lower-case key name (``key.LEFT`` -> ``"left"``,
    ``key._1`` -> ``"1"``, ``key.NUM_1`` -> ``"num_1"``)."""
    name = _key.symbol_string(symbol).lower()
    return name[1:] if name.startswith("_") and len(name) > 1 else name


def _open_window(width: int, height: int, title: str) -> Any:
    """A visible, resizable window; :class:`NoDisplayError` where none can be seen (no display, or
    the display fails to open), never an invisible one."""
    reason = no_display_reason()
    if reason is None:
        if not pyglet.app.event_loop.is_running:
            # pyglet's app.run() turns the window event queue off for good: a window made after an
            # earlier run() ended would handle its first resize before it can draw (AttributeError
            # 'ubo'), so the second run() of a process (a game's restart) failed. Queue, as at start.
            pyglet.window.Window._enable_event_queue = True
        try:
            return pyglet.window.Window(width, height, caption=title, resizable=True, visible=True)
        except Exception as exc:
            reason = open_failure(exc)
            if reason is None:
                raise
            raise NoDisplayError(f"{reason}; no window can be shown") from exc
    raise NoDisplayError(f"{reason}; no window can be shown")


class Runner:
    """Drives one scene in one window; :func:`run` makes one and runs it. Methods are the window's
    event handlers, so tests can call them directly."""

    def __init__(
        self,
        scene: Any,
        *,
        width: int = 960,
        height: int = 540,
        title: str = "framework",
        fps: float = 60,
        camera: Camera | None = None,
        debug: bool = False,
        on_key: Callable[[Any, str], Any] | None = None,
        max_frames: int | None = None,
        background: tuple[int, int, int] = (0, 0, 0),
    ) -> None:
        if not (fps > 0):
            raise ValueError(f"fps must be > 0, got {fps!r}")
        self.dt = 1.0 / float(fps)
        self.on_key = on_key
        self.max_frames = max_frames
        self.frames = 0
        self.steps = 0
        self.accumulator = 0.0
        self.window = _open_window(width, height, title)
        self.renderer = Renderer(width=width, height=height, camera=camera, debug=debug,
                                 background=background, window=self.window)
        self.scene = scene
        scene.renderer = self.renderer
        self.renderer.debug = debug or self.renderer.debug
        self._last_time: float | None = None
        self._fps_avg = 0.0
        self.window.push_handlers(
            on_draw=self.on_draw, on_key_press=self.on_key_press, on_key_release=self.on_key_release,
            on_resize=self.on_resize, on_deactivate=self.on_deactivate, on_close=self.on_close,
        )
        self.window.switch_to()
        self.renderer.draw(scene)  # the first frame shows the scene as it is before any step

    # --- time -------------------------------------------------------------------------------

    def tick(self, elapsed: float) -> int:
        """Add ``elapsed`` real seconds and run every whole step that fits; return how many ran."""
        self.accumulator += min(max(elapsed, 0.0), MAX_FRAME_TIME)
        ran = 0
        self.window.switch_to()
        # A relative tolerance keeps 60 frames of 1/60 s from running 59 steps by rounding.
        while self.accumulator >= self.dt * (1.0 - 1e-9) and ran < MAX_STEPS_PER_FRAME:
            self.scene.step(self.dt)
            self.accumulator -= self.dt
            ran += 1
        if ran == MAX_STEPS_PER_FRAME:
            self.accumulator = min(self.accumulator, self.dt)
        self.accumulator = max(self.accumulator, 0.0)
        self.steps += ran
        return ran

    def frame(self, _dt: float = 0.0) -> None:
        """One frame: measure the time since the last, step, draw, count (scheduled by :meth:`run`)."""
        now = time.perf_counter()
        elapsed = self.dt if self._last_time is None else now - self._last_time
        self._last_time = now
        if elapsed > 0:
            inst = 1.0 / elapsed
            self._fps_avg = inst if self._fps_avg == 0.0 else 0.9 * self._fps_avg + 0.1 * inst
            self.renderer.fps = self._fps_avg
        self.tick(elapsed)
        if self.window.context is None:  # closed during the step (e.g. by on_key)
            return
        self.window.draw(elapsed)
        self.frames += 1
        if self.max_frames is not None and self.frames >= self.max_frames:
            self.close()

    # --- window events ------------------------------------------------------------------------

    def on_draw(self) -> bool:
        w, h = self.window.get_framebuffer_size()
        gl.glViewport(0, 0, w, h)
        r, g, b = (c / 255.0 for c in self.renderer.background[:3])
        gl.glClearColor(r, g, b, 1.0)
        self.window.clear()
        self.renderer.render(self.window)
        return True

    def on_resize(self, width: int, height: int) -> bool:
        if width > 0 and height > 0:
            self.renderer.width, self.renderer.height = width, height
        return True  # the renderer sets its own projection

    def on_key_press(self, symbol: int, modifiers: int) -> bool:
        name = key_name(symbol)
        self.scene.resources.setdefault(Input, Input()).press(name)
        if self.on_key is not None:
            new = self.on_key(self.scene, name)
            if new is not None and new is not self.scene and hasattr(new, "step"):
                self.switch_scene(new)
        if name == "f1":
            self.renderer.debug = not self.renderer.debug
        elif name == "escape":
            self.close()
        return True  # handled: pyglet's default Escape handler does not run

    def on_key_release(self, symbol: int, modifiers: int) -> bool:
        inp = self.scene.resources.get(Input)
        if inp is not None:
            inp.release(key_name(symbol))
        return True

    def on_deactivate(self) -> None:
        """The window lost focus: its keys will not see their release, so release them now."""
        inp = self.scene.resources.get(Input)
        if inp is not None:
            inp.set_held(())

    def on_close(self) -> bool:
        self.close()
        return True

    # --- scenes and lifetime --------------------------------------------------------------------

    def switch_scene(self, scene: Any) -> None:
        """Show and step ``scene`` from now on; the keys held so far stay held in it."""
        old = self.scene
        held = set(old.resources[Input].held) if Input in old.resources else set()
        if not getattr(old, "closed", False):
            old.renderer = None
        self.renderer.reset()
        self.scene = scene
        scene.renderer = self.renderer
        scene.resources.setdefault(Input, Input()).set_held(held)
        self.window.switch_to()
        self.renderer.draw(scene)

    def close(self) -> None:
        """Close the window and leave the event loop."""
        if self.window.context is not None:
            self.renderer.close()
            if not getattr(self.scene, "closed", False) and self.scene.renderer is self.renderer:
                self.scene.renderer = None
            self.window.close()
        pyglet.clock.unschedule(self.frame)
        pyglet.app.exit()

    def run(self) -> None:
        """Enter pyglet's event loop until the window closes (or ``max_frames`` frames)."""
        pyglet.clock.schedule_interval(self.frame, self.dt)
        try:
            pyglet.app.run(None)
        finally:
            pyglet.clock.unschedule(self.frame)


def run(
    scene: Any,
    *,
    width: int = 960,
    height: int = 540,
    title: str = "framework",
    fps: float = 60,
    camera: Camera | None = None,
    debug: bool = False,
    on_key: Callable[[Any, str], Any] | None = None,
    max_frames: int | None = None,
    background: tuple[int, int, int] = (0, 0, 0),
) -> None:
    """Open a window and run ``scene`` in it at ``fps`` fixed steps per second until the window
    is closed (Escape), or for ``max_frames`` frames.

    ``camera``: the view (see :class:`~framework.render.camera.Camera`; e.g. ``Camera(target=player,
    bounds=level, zoom=2)``); ``debug``: start with the overlay on (F1 toggles it); ``on_key(scene,
    key)``: called on every key press with the key's name; return a new scene to switch to it;
    ``background``: the clear colour (r, g, b), 0-255.

    Raises :class:`~.display.NoDisplayError` (one line: why) where no window can be seen."""
    Runner(scene, width=width, height=height, title=title, fps=fps, camera=camera, debug=debug,
           on_key=on_key, max_frames=max_frames, background=background).run()
