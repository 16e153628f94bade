"""A picture of a scene for a failing test: rendered headless with the debug overlay (hitboxes,
contacts, velocities), the camera fitted to everything that has a hitbox."""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["WIDTH", "HEIGHT", "fitted_camera", "picture"]

WIDTH, HEIGHT = 800, 450


def fitted_camera(scene: Any, width: int = WIDTH, height: int = HEIGHT) -> Any:
    """A camera that shows every hitbox of ``scene`` (with a margin)."""
    from ..render import Camera

    bodies = scene.bodies
    geom = bodies.ensure_geometry()
    store = bodies.store
    has = store.kind >= 0
    if not has.any():
        return Camera(0.0, 0.0)
    x0, x1 = float(geom.minx[has].min()), float(geom.maxx[has].max())
    y0, y1 = float(geom.miny[has].min()), float(geom.maxy[has].max())
    w, h = max(x1 - x0, 1e-9), max(y1 - y0, 1e-9)
    zoom = 0.9 * min(width / w, height / h)
    return Camera((x0 + x1) * 0.5, (y0 + y1) * 0.5, zoom=zoom, pixel_snap=False)


def picture(scene: Any, path: str | Path, width: int = WIDTH, height: int = HEIGHT) -> Path:
    """Write a PNG of ``scene`` as it is now (debug overlay on) to ``path``; return the path."""
    from ..render import screenshot

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    screenshot(scene, path, width=width, height=height, camera=fitted_camera(scene, width, height), debug=True,
               background=(16, 18, 28))
    return path
