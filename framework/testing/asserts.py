"""Physics assertions for tests of a game, with messages that say what was seen.

Each raises ``AssertionError`` naming the entity, the step and the numbers: ``entity 7 is not at
rest at step 120: velocity (0.31, -2.5), speed 2.52 > 1e-06``, not ``assert 2.52 <= 1e-06``.
:func:`bounds` and :func:`feet` measure where an entity is, for a test's own comparisons.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..collision import collide
from ..components import Hitbox, Transform, Velocity
from ..validation import InvalidValue
from .tracebacks import hide_on_failure

__all__ = ["assert_at_rest", "assert_inside", "assert_no_overlap", "assert_on_floor", "bounds", "feet", "overlaps"]


def _row(scene: Any, entity: int) -> int:
    __tracebackhide__ = hide_on_failure
    if not scene.exists(entity):
        raise AssertionError(f"entity {entity} does not exist at step {scene.frame}")
    row = scene.bodies.store.row_of.get(entity)
    if row is None:
        raise InvalidValue(f"entity {entity} has no Transform: it has no position to check")
    return row


def bounds(scene: Any, entity: int) -> tuple[float, float, float, float]:
    """``(minx, miny, maxx, maxy)`` of ``entity``'s hitbox where it is now, exactly as its shape
    and pose give it (a box's bottom is ``y - height / 2`` to the bit; the broad phase's bounds are
    wider by an ulp or two); its position, as a point, without a hitbox."""
    __tracebackhide__ = hide_on_failure
    from ..casting import shape_bounds

    row = _row(scene, entity)
    store = scene.bodies.store
    hitbox = store.hitboxes[row]
    if hitbox is None:
        t = scene.get(entity, Transform)
        return t.x, t.y, t.x, t.y
    geom = scene.bodies.ensure_geometry()  # (its hitbox origin: the position, turned offset added)
    return shape_bounds(hitbox.shape, float(geom.hx[row]), float(geom.hy[row]), float(store.rot[row]))


def feet(scene: Any, entity: int) -> float:
    """The lowest point of ``entity``'s hitbox now: where it stands (``bounds(...)[1]``)."""
    __tracebackhide__ = hide_on_failure
    return bounds(scene, entity)[1]


def assert_at_rest(scene: Any, entity: int, *, speed: float = 1e-6) -> None:
    """``entity`` moves no faster than ``speed`` (units/s), and does not turn faster either."""
    __tracebackhide__ = hide_on_failure
    _row(scene, entity)
    v = scene.try_get(entity, Velocity)
    if v is None:
        return  # no velocity: it never moves
    now = math.hypot(v.x, v.y)
    if not (now <= speed and abs(v.angular) <= speed):
        raise AssertionError(f"entity {entity} is not at rest at step {scene.frame}: velocity ({v.x:.6g}, {v.y:.6g}), "
                             f"speed {now:.6g}, turning {v.angular:.6g} rad/s (allowed {speed:g})")


def overlaps(scene: Any, deeper_than: float = 0.0, among: set[int] | None = None) -> list[tuple[int, int, float]]:
    """The solid pairs (no sensors) overlapping deeper than ``deeper_than`` now, measured with
    :func:`~framework.collision.collide` where the bodies stand: ``(a, b, depth)``, deepest first;
    ``among``: only pairs with an entity of this set."""
    scene.bodies.ensure_geometry()
    store, geom = scene.bodies.store, scene.bodies.geometry
    rows = [r for r in range(store.n) if store.hitboxes[r] is not None and not store.sensor[r]]
    out = []
    for i, ra in enumerate(rows):
        for rb in rows[i + 1:]:
            ea, eb = int(store.entity[ra]), int(store.entity[rb])
            if among is not None and ea not in among and eb not in among:
                continue
            if store.body[ra] == store.body[rb] == 2:  # two static bodies are never resolved
                continue
            if not (geom.minx[ra] < geom.maxx[rb] and geom.minx[rb] < geom.maxx[ra]
                    and geom.miny[ra] < geom.maxy[rb] and geom.miny[rb] < geom.maxy[ra]):
                continue
            c = collide(store.hitboxes[ra].shape, (float(geom.hx[ra]), float(geom.hy[ra]), float(store.rot[ra])),
                        store.hitboxes[rb].shape, (float(geom.hx[rb]), float(geom.hy[rb]), float(store.rot[rb])))
            if c is not None and c.depth > deeper_than:
                out.append((ea, eb, c.depth))
    return sorted(out, key=lambda p: -p[2])


def assert_no_overlap(scene: Any, *, deeper_than: float = 0.0, among: set[int] | None = None) -> None:
    """No two solid hitboxes overlap deeper than ``deeper_than`` (see :func:`overlaps`)."""
    __tracebackhide__ = hide_on_failure
    found = overlaps(scene, deeper_than, among)
    if found:
        a, b, depth = found[0]
        raise AssertionError(f"{len(found)} pair(s) overlap deeper than {deeper_than:g} at step {scene.frame}; the "
                             f"deepest: entities {a} and {b}, by {depth:.6g}")


def assert_inside(scene: Any, entity: int, box: tuple[float, float, float, float]) -> None:
    """``entity``'s hitbox (or its position, without one) lies inside ``box`` = (minx, miny,
    maxx, maxy)."""
    __tracebackhide__ = hide_on_failure
    x0, y0, x1, y1 = box
    if not (x1 > x0 and y1 > y0):
        raise InvalidValue(f"box must be (minx, miny, maxx, maxy) with max > min, got {box!r}")
    b = bounds(scene, entity)
    if not (b[0] >= x0 and b[1] >= y0 and b[2] <= x1 and b[3] <= y1):
        raise AssertionError(f"entity {entity} is not inside {box!r} at step {scene.frame}: it spans "
                             f"({b[0]:.6g}, {b[1]:.6g}) to ({b[2]:.6g}, {b[3]:.6g})")


def assert_on_floor(scene: Any, entity: int, *, gap: float = 1e-6) -> None:
    """``entity`` stands on something: its character controller says so, or a solid hitbox lies
    right under it (a shape cast ``gap`` down meets one with an upward normal)."""
    __tracebackhide__ = hide_on_failure
    row = _row(scene, entity)
    from ..character import CharacterController

    ctrl = scene.try_get(entity, CharacterController)
    if ctrl is not None:
        if not ctrl.on_floor:
            t = scene.get(entity, Transform)
            raise AssertionError(f"entity {entity} is not on a floor at step {scene.frame}: at ({t.x:.6g}, {t.y:.6g}), "
                                 f"on a wall: {ctrl.on_wall}, under a ceiling: {ctrl.on_ceiling}")
        return
    hb = scene.try_get(entity, Hitbox)
    if hb is None:
        raise InvalidValue(f"entity {entity} has no Hitbox: nothing can stand")
    geom = scene.bodies.ensure_geometry()
    x, y, rot = float(geom.hx[row]), float(geom.hy[row]), float(scene.bodies.store.rot[row])
    size = float(np.hypot(geom.maxx[row] - geom.minx[row], geom.maxy[row] - geom.miny[row]))
    reach = gap * max(1.0, size)
    hit = scene.shape_cast(hb.shape, (x, y), (x, y - reach), rotation=rot, mask=hb.mask, ignore=[entity])
    if hit is None or hit.normal.y <= 0.5:
        below = "nothing" if hit is None else f"entity {hit.entity} (normal {hit.normal})"
        raise AssertionError(f"entity {entity} is not on a floor at step {scene.frame}: at ({x:.6g}, {y:.6g}), "
                             f"{below} within {reach:g} below it")
