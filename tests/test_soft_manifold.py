"""The soft step's manifolds (``framework.collision.soft_manifold``, through the kernel's shape
tables) against the exact oracle, ``framework.collision.collide``: every overlap is found, at the
depth and along the normal collide gives (two boxes, polygons and circles), never shallower
(capsules, whose rounded ends Box2D's separating-axis test measures from their faces)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from framework import AABB, Capsule, Circle, Hitbox, Polygon, Scene, Transform, collide
from framework.systems.soft_kernel import _manifold, _world_shapes
from framework.systems.soft_step import shape_tables


def _measure(shape_a, pose_a, shape_b, pose_b, speculative=0.0):
    """``(count, nx, ny, points)`` of the soft manifold of B against A."""
    s = Scene(solver="soft")
    for shape, (x, y, r) in ((shape_a, pose_a), (shape_b, pose_b)):
        s.spawn(Transform(x, y, r), Hitbox(shape, body="static"))
    store = s.bodies.store
    off, lv, ln, cnt, rr, spin = shape_tables(store)
    n, k = store.n, lv.shape[1]
    wc, wv, wn = np.empty((n, 2)), np.empty((n, k, 2)), np.empty((n, k, 2))
    lo, hi, reach = np.empty((n, 2)), np.empty((n, 2)), np.zeros(n)
    _world_shapes(store.x, store.y, store.rot, store.vx, store.vy, store.w, np.zeros(n, dtype=bool),
                  np.zeros(n, dtype=bool), off, lv, ln, cnt, rr, spin, store.bound, 0.0, 0.0, 0.0, 0.0,
                  wc, wv, wn, lo, hi, reach)
    out = np.zeros((2, 4))
    count, nx, ny = _manifold(0, 1, store.kind, wc, lv, wv, wn, cnt, rr, 0.005, speculative, out)
    s.close()
    return count, nx, ny, out[:count].copy()


def _hexagon(r):
    return Polygon([(r * math.cos(k * math.pi / 3), r * math.sin(k * math.pi / 3)) for k in range(6)])


SHAPES = st.sampled_from(["aabb", "box", "circle", "hexagon", "triangle", "capsule"])


def _shape(kind, size):
    if kind == "aabb":
        return AABB(size, size * 0.75)
    if kind == "box":
        return Polygon.box(size, size * 0.5)
    if kind == "circle":
        return Circle(size / 2)
    if kind == "hexagon":
        return _hexagon(size / 2)
    if kind == "triangle":
        return Polygon([(0.0, 0.0), (size, 0.0), (size / 3, size * 0.8)])
    return Capsule(size / 4, size)


@settings(max_examples=400, deadline=None, derandomize=True)
@given(ka=SHAPES, kb=SHAPES, sa=st.floats(0.5, 2.0), sb=st.floats(0.5, 2.0),
       bx=st.floats(-2.0, 2.0), by=st.floats(-2.0, 2.0), ra=st.floats(-3.2, 3.2), rb=st.floats(-3.2, 3.2))
def test_every_overlap_is_found_at_least_as_deep_as_the_oracle_says(ka, kb, sa, sb, bx, by, ra, rb):
    a, b = _shape(ka, sa), _shape(kb, sb)
    pose_a, pose_b = (0.0, 0.0, ra), (bx, by, rb)
    exact = collide(a, pose_a, b, pose_b)
    count, nx, ny, points = _measure(a, pose_a, b, pose_b)
    if exact is None:
        return  # (apart or touching: the soft manifold may report a speculative contact; see below)
    assert count > 0
    depth = -points[:, 2].min()
    assert depth >= exact.depth - 1e-9
    assert math.hypot(nx, ny) == pytest.approx(1.0)
    if "capsule" not in (ka, kb):
        # the same depth, along the same normal (unless two axes tie)
        assert depth == pytest.approx(exact.depth, abs=1e-9)
        if abs(nx * exact.normal[0] + ny * exact.normal[1] - 1.0) > 1e-9:
            # a tie: the soft normal separates by the same depth
            assert depth == pytest.approx(exact.depth, abs=1e-9)


@settings(max_examples=200, deadline=None, derandomize=True)
@given(ka=SHAPES, kb=SHAPES, sa=st.floats(0.5, 2.0), sb=st.floats(0.5, 2.0), angle=st.floats(0.0, 2 * math.pi),
       gap=st.floats(0.011, 3.0), ra=st.floats(-3.2, 3.2), rb=st.floats(-3.2, 3.2))
def test_shapes_apart_by_more_than_the_speculative_distance_have_no_manifold(ka, kb, sa, sb, angle, gap, ra, rb):
    a, b = _shape(ka, sa), _shape(kb, sb)
    # B's centre far enough along a direction that their bounding circles are ``gap`` apart
    d = a.bounding_radius + b.bounding_radius + gap
    pose_b = (d * math.cos(angle), d * math.sin(angle), rb)
    count, *_ = _measure(a, (0.0, 0.0, ra), b, pose_b, speculative=0.01)
    assert count == 0


@pytest.mark.parametrize("shape", [AABB(1.0, 1.0), Polygon.box(1.0, 1.0), _hexagon(0.5)])
def test_a_face_on_a_face_gives_two_points_at_the_ends_of_the_shared_run(shape):
    floor = AABB(10.0, 1.0)
    y = 0.5 + (math.sqrt(3) / 4 if isinstance(shape, Polygon) and len(shape.points) == 6 else 0.5) - 1 / 64
    count, nx, ny, points = _measure(floor, (0.0, 0.0, 0.0), shape, (0.25, y, 0.0))
    assert count == 2 and (nx, ny) == (0.0, 1.0)
    assert points[:, 2] == pytest.approx([-1 / 64, -1 / 64])
    half = 0.5 if len(getattr(shape, "points", ())) != 6 else 0.25
    assert sorted(points[:, 0]) == pytest.approx([0.25 - half, 0.25 + half])
