"""The camera: which part of the world the screen shows, as a world-to-screen transform.

Pure arithmetic, no pyglet: a camera can be built, moved and queried without any GL.

World units, y up (the contract's convention, and pyglet's). At zoom 1 a world unit is one screen
pixel. The camera's ``(x, y)`` is the world point at the centre of the view; it follows a target
entity and is clamped to the level's bounds each frame (:meth:`Camera.update`).

The transform is ``screen = world * zoom + offset``. With ``pixel_snap`` (the default) the offset is
rounded to whole pixels, so a scene drawn at integer world coordinates lands on exact pixels and a
camera that moves by whole pixels moves the picture by exactly that many pixels (no shimmering
edges while scrolling).
"""

from __future__ import annotations

import math
from typing import Any

from ..components import Transform
from ..validation import InvalidValue, finite, positive

__all__ = ["Camera"]

Box = tuple[float, float, float, float]


class Camera:
    """World-to-screen transform with follow-a-target, level bounds and zoom.

    - ``x, y``: the world point at the centre of the view; ``None`` (the default) puts the view's
      bottom-left corner at the world origin, so world coordinates are screen pixels.
    - ``zoom``: screen pixels per world unit (> 0).
    - ``target``: an entity to follow (the view centres on its Transform), or ``None``. A target
      that no longer exists is ignored: the camera stays where it was.
    - ``bounds``: ``(minx, miny, maxx, maxy)`` of the level, or ``None``. When the level is larger
      than the view on an axis, the view never shows anything outside it on that axis; when it
      is smaller, the level is centred on that axis.
    - ``pixel_snap``: round the screen offset to whole pixels.
    """

    def __init__(
        self,
        x: float | None = None,
        y: float | None = None,
        *,
        zoom: float = 1.0,
        target: int | None = None,
        bounds: Box | None = None,
        pixel_snap: bool = True,
    ) -> None:
        if (x is None) != (y is None):
            raise InvalidValue(f"give the camera both x and y, or neither; got x={x!r}, y={y!r}")
        self.x: float | None = None if x is None else finite("Camera x", x)
        self.y: float | None = None if y is None else finite("Camera y", y)
        self.zoom = zoom
        self.target = target
        self.bounds = bounds
        self.pixel_snap = bool(pixel_snap)
        #: viewport size in screen pixels, set by :meth:`update` (the renderer's size)
        self.width = 960.0
        self.height = 540.0

    # --- validated settings -----------------------------------------------------------------

    @property
    def zoom(self) -> float:
        """Screen pixels per world unit."""
        return self._zoom

    @zoom.setter
    def zoom(self, value: float) -> None:
        self._zoom = positive("Camera zoom", value)

    @property
    def bounds(self) -> Box | None:
        """``(minx, miny, maxx, maxy)`` of the level, or ``None`` (unbounded)."""
        return self._bounds

    @bounds.setter
    def bounds(self, value: Box | None) -> None:
        if value is None:
            self._bounds = None
            return
        try:
            x0, y0, x1, y1 = (finite("Camera bounds", v) for v in value)
        except (TypeError, ValueError) as exc:
            raise InvalidValue(
                f"Camera bounds must be (minx, miny, maxx, maxy), got {value!r}: {exc}"
            ) from None
        if not (x1 > x0 and y1 > y0):
            raise InvalidValue(f"Camera bounds need maxx > minx and maxy > miny, got {value!r}")
        self._bounds = (x0, y0, x1, y1)

    @property
    def target(self) -> int | None:
        """The entity the camera follows, or ``None``."""
        return self._target

    @target.setter
    def target(self, value: int | None) -> None:
        if value is not None and (isinstance(value, bool) or not isinstance(value, int)):
            raise InvalidValue(f"Camera target must be an entity id (int) or None, got {value!r}")
        self._target = value

    def follow(self, entity: int | None) -> None:
        """Follow ``entity`` from the next frame on (``None``: stop following)."""
        self.target = entity

    # --- per frame --------------------------------------------------------------------------

    def update(self, scene: Any, width: float, height: float) -> None:
        """Take the viewport size, move to the target (if it exists) and clamp to the bounds."""
        self.width, self.height = positive("viewport width", width), positive("viewport height", height)
        if self._target is not None and scene is not None and scene.exists(self._target):
            t = scene.try_get(self._target, Transform)
            if t is not None:
                x, y = t.x, t.y
                if isinstance(x, float | int) and isinstance(y, float | int) and math.isfinite(x) \
                        and math.isfinite(y):
                    self.x, self.y = float(x), float(y)
        if self._bounds is not None:
            self.x, self.y = self._clamped(*self.center)

    @property
    def center(self) -> tuple[float, float]:
        """The world point at the centre of the view (before pixel snapping)."""
        if self.x is None or self.y is None:
            return self.width * 0.5 / self._zoom, self.height * 0.5 / self._zoom
        return self.x, self.y

    def _clamped(self, cx: float, cy: float) -> tuple[float, float]:
        assert self._bounds is not None
        x0, y0, x1, y1 = self._bounds
        hw, hh = self.width * 0.5 / self._zoom, self.height * 0.5 / self._zoom
        cx = (x0 + x1) * 0.5 if x1 - x0 <= 2.0 * hw else min(max(cx, x0 + hw), x1 - hw)
        cy = (y0 + y1) * 0.5 if y1 - y0 <= 2.0 * hh else min(max(cy, y0 + hh), y1 - hh)
        return cx, cy

    # --- the transform ----------------------------------------------------------------------

    @property
    def offset(self) -> tuple[float, float]:
        """Screen position of the world origin: ``screen = world * zoom + offset``."""
        cx, cy = self.center
        ox = self.width * 0.5 - cx * self._zoom
        oy = self.height * 0.5 - cy * self._zoom
        if self.pixel_snap:
            ox, oy = float(round(ox)), float(round(oy))
        return ox, oy

    def world_to_screen(self, x: float, y: float) -> tuple[float, float]:
        """Screen pixel coordinates (origin bottom-left, y up) of a world point."""
        ox, oy = self.offset
        return x * self._zoom + ox, y * self._zoom + oy

    def screen_to_world(self, sx: float, sy: float) -> tuple[float, float]:
        """The world point under a screen position (origin bottom-left, y up)."""
        ox, oy = self.offset
        return (sx - ox) / self._zoom, (sy - oy) / self._zoom

    def view_box(self) -> Box:
        """``(minx, miny, maxx, maxy)``: the part of the world the view shows."""
        x0, y0 = self.screen_to_world(0.0, 0.0)
        x1, y1 = self.screen_to_world(self.width, self.height)
        return x0, y0, x1, y1

    def matrix(self) -> tuple[float, ...]:
        """The view matrix (world to screen pixels), 16 floats in column-major order."""
        z = self._zoom
        ox, oy = self.offset
        return (z, 0.0, 0.0, 0.0, 0.0, z, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, ox, oy, 0.0, 1.0)

    def __repr__(self) -> str:
        return (f"Camera(x={self.x!r}, y={self.y!r}, zoom={self._zoom!r}, target={self._target!r}, "
                f"bounds={self._bounds!r})")
