"""The soft step's manifolds (``framework.collision.soft_manifold``, through the kernel's own narrow
phase) against the exact oracle, ``framework.collision.collide``: every overlap is found, at the
depth collide gives (two boxes, polygons and circles), never shallower (capsules, whose rounded
ends Box2D's separating-axis test measures from their faces); and the manifold functions' points
where the answer is exact."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from framework import AABB, Capsule, Circle, Hitbox, Polygon, Scene, Transform, Velocity, collide
from framework.collision.soft_manifold import box_box, capsule_capsule, polygon_polygon


def _measure(shape_a, pose_a, shape_b, pose_b):
    """The soft step's contact of B against A, as its kernel's narrow phase measures it (a scene of
    the two, detection alone): ``(normal, depth)`` or None."""
    s = Scene(solver="soft", effects={"detection"})
    a = s.spawn(Transform(*pose_a), Velocity(), Hitbox(shape_a))
    b = s.spawn(Transform(*pose_b), Velocity(), Hitbox(shape_b))
    s.step(1 / 60)
    c = s.contacts
    s.close()
    if c.a.size == 0:
        return None
    assert (int(c.a[0]), int(c.b[0])) == (a, b)
    return (float(c.nx[0]), float(c.ny[0])), float(c.depth[0])


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


@pytest.mark.slow
@example(ka="triangle", kb="triangle", sa=1.0, sb=1.0, bx=0.0, by=-1.5331679973654795e-230, ra=-2.5, rb=0.0)
@settings(max_examples=300, deadline=None, derandomize=True)
@given(ka=SHAPES, kb=SHAPES, sa=st.floats(0.5, 2.0), sb=st.floats(0.5, 2.0),
       bx=st.floats(-2.0, 2.0), by=st.floats(-2.0, 2.0), ra=st.floats(-3.2, 3.2), rb=st.floats(-3.2, 3.2))
def test_every_overlap_is_found_at_least_as_deep_as_the_oracle_says(ka, kb, sa, sb, bx, by, ra, rb):
    a, b = _shape(ka, sa), _shape(kb, sb)
    pose_a, pose_b = (0.0, 0.0, ra), (bx, by, rb)
    exact = collide(a, pose_a, b, pose_b)
    soft = _measure(a, pose_a, b, pose_b)
    if exact is None:
        # apart or touching: in contact only within rounding of touching
        assert soft is None or soft[1] < 1e-9
        return
    if soft is None:  # decided in floats: an overlap within rounding of touching may be missed
        assert exact.depth < 1e-9
        return
    (nx, ny), depth = soft
    assert depth >= exact.depth - 1e-9
    assert math.hypot(nx, ny) == pytest.approx(1.0)
    if "capsule" not in (ka, kb):  # the same depth (along collide's normal, unless two axes tie)
        assert depth == pytest.approx(exact.depth, abs=1e-9)


def _local(points):
    """World vertices and normals of a counter-clockwise outline, as the kernel's tables hold them."""
    v = np.array(points, dtype=float)
    e = np.roll(v, -1, axis=0) - v
    n = np.stack([e[:, 1], -e[:, 0]], axis=1) / np.hypot(e[:, 0], e[:, 1])[:, None]
    return v, n


@pytest.mark.parametrize("turned", [False, True])
def test_a_face_on_a_face_gives_two_points_at_the_ends_of_the_shared_run(turned):
    # a unit box resting 1/64 deep on a floor, its centre at x = 1/4: points at x = -1/4 and 3/4
    floor_v, floor_n = _local([(-5.0, -1.0), (5.0, -1.0), (5.0, 0.0), (-5.0, 0.0)])
    box_v, box_n = _local([(-0.25, -1 / 64), (0.75, -1 / 64), (0.75, 1 - 1 / 64), (-0.25, 1 - 1 / 64)])
    out = np.zeros((2, 4))
    if turned:  # as polygons (the kernel's path for boxes that turn)
        V, N = np.stack([floor_v, box_v]), np.stack([floor_n, box_n])
        count, nx, ny = polygon_polygon(V, N, 0, 4, 0.0, 1, 4, 0.0, 0.005, 0.0, out)
    else:  # as AABBs
        count, nx, ny = box_box(0.0, -0.5, 5.0, 0.5, 0.25, 0.5 - 1 / 64, 0.5, 0.5, 0.0, out)
    assert count == 2 and (nx, ny) == (0.0, 1.0)
    assert out[:, 2] == pytest.approx([-1 / 64, -1 / 64])
    assert sorted(out[:, 0]) == pytest.approx([-0.25, 0.75])
    assert out[:, 1] == pytest.approx([-1 / 128, -1 / 128])  # halfway between the faces


@pytest.mark.parametrize("gap", [1e-6, 0.5])
def test_two_capsules_end_to_end_are_measured_by_their_caps(gap):
    # the polygon clipper finds no face against a face here: the segments' closest points do
    V = np.array([[[0.0, -0.5], [0.0, 0.5]], [[0.0, 1.0 + gap], [0.0, 2.0 + gap]]])
    out = np.zeros((2, 4))
    count, nx, ny = capsule_capsule(V, 0, 0.25, 1, 0.25, 1.0, out)
    assert count == 1 and (nx, ny) == (0.0, 1.0)
    assert out[0, 2] == pytest.approx(gap - 0.0)  # 0.5 between the segments' ends, less two radii
