"""One row's geometry kept current when the pipeline moves it (``Bodies.place_row``, the
character stage's placements): bit for bit what a full update computes, for every shape kind,
with and without hitbox offsets, turned or not."""

from __future__ import annotations

import math

import numpy as np
import pytest

from framework import AABB, Capsule, Circle, Hitbox, Polygon, Scene, Transform, Velocity
from framework.geometry import Geometry

SHAPES = [AABB(1.0, 0.5), Circle(0.3), Capsule(0.2, 0.6), Polygon([(-0.3, -0.2), (0.5, -0.1), (0.1, 0.4)])]


@pytest.mark.parametrize("offset", [(0.0, 0.0), (0.25, -0.125)])
def test_a_placed_row_has_the_bounds_a_full_update_gives(offset):
    s = Scene()
    s.spawn(Transform(0.0, -5.0), Hitbox(AABB(10.0, 1.0), body="static"))
    rows = []
    for k, shape in enumerate(SHAPES):
        e = s.spawn(Transform(1.5 * k, 0.1 * k, 0.3 + 0.7 * k), Velocity(),
                    Hitbox(shape, body="kinematic", offset=offset))
        rows.append(s.bodies.store.row_of[e])
    bodies = s.bodies
    bodies.ensure_geometry()
    for k, row in enumerate(rows):
        bodies.place_row(row, 1.0 / 3.0 + k * math.pi, -2.0 / 7.0 * k)
    store = bodies.store
    assert bodies._geometry_stamp == (store.motion, store.writes, store.version, store.n)  # kept current
    kept = bodies.ensure_geometry()  # (so not recomputed)
    fresh = Geometry()
    fresh.update(store)
    for name in ("hx", "hy", "minx", "maxx", "miny", "maxy"):
        assert np.array_equal(getattr(kept, name), getattr(fresh, name)), name
    assert kept is bodies.geometry


@pytest.mark.parametrize("where", [(0.0, 0.0), (-0.0, 5e-324), (1e-300, -3e-310), (1e15 + 0.5, -7.25e14),
                                   (2.0**-1022, 2.0**-1074), (123456.789, -0.1)])
@pytest.mark.parametrize("size", [(1.0, 0.5), (1e-12, 3e7), (0.1, 0.1)])
def test_a_placed_box_has_the_bounds_of_the_compiled_pass(where, size):
    """A box row is placed by Python float arithmetic (not the compiled pass): the same bits, at
    zero, subnormals, large and odd coordinates and sizes."""
    s = Scene()
    e = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(AABB(*size), body="kinematic"))
    bodies = s.bodies
    bodies.ensure_geometry()
    row = bodies.store.row_of[e]
    bodies.place_row(row, *where)
    kept = bodies.geometry
    fresh = Geometry()
    fresh.update(bodies.store)
    for name in ("minx", "maxx", "miny", "maxy"):
        assert getattr(kept, name)[row].tobytes() == getattr(fresh, name)[row].tobytes(), name
