"""``Scene.shape_cast``: sweep a shape through a scene, first hit with exact dyadic answers."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from framework import AABB, Capsule, Circle, Hitbox, InvalidValue, Polygon, Scene, Transform, Velocity, collide
from framework.collision import time_of_impact


@pytest.fixture
def scene():
    s = Scene()
    yield s
    s.close()


def floor(s: Scene, x: float = 0.0, y: float = 0.0, w: float = 64.0, h: float = 32.0, **kw) -> int:
    return s.spawn(Transform(x, y), Hitbox(AABB(w, h), body="static", **kw))


def test_box_cast_down_onto_a_floor(scene):
    f = floor(scene)
    hit = scene.shape_cast(AABB(24.0, 28.0), (0.0, 40.0), (0.0, -40.0))
    # The box's bottom (26 at the start) meets the floor's top (16) after 10 of 80 units.
    assert hit == (f, 0.125, (0.0, 16.0), (0.0, 1.0))


def test_circle_cast_diagonally_meets_the_top_face(scene):
    f = floor(scene)
    hit = scene.shape_cast(Circle(8.0), (40.0, 40.0), (-40.0, -40.0))
    assert hit.entity == f and hit.fraction == 0.2 and hit.point == (24.0, 16.0) and hit.normal == (0.0, 1.0)


def test_cast_into_a_corner_of_a_rotated_square(scene):
    # A square turned 45 degrees: a diamond with its top corner at (0, 16 * sqrt 2).
    d = scene.spawn(Transform(0.0, 0.0, math.pi / 4), Hitbox(Polygon.box(32.0, 32.0), body="static"))
    hit = scene.shape_cast(AABB(8.0, 8.0), (0.0, 100.0), (0.0, 0.0))
    top = 16.0 * math.sqrt(2.0)
    assert hit.entity == d and hit.fraction == pytest.approx((100.0 - 4.0 - top) / 100.0, abs=1e-15)
    assert hit.point == pytest.approx((0.0, top), abs=1e-12)
    assert hit.normal.y > 0.0


def test_sliding_along_a_surface_at_gap_zero_is_a_miss(scene):
    floor(scene, 0.0, 0.0)
    floor(scene, 64.0, 0.0)
    assert scene.shape_cast(AABB(24.0, 28.0), (-20.0, 30.0), (100.0, 30.0)) is None  # bottom at 16 = top


def test_overlapping_at_the_start_hits_at_fraction_zero_with_collides_normal(scene):
    f = floor(scene)
    hit = scene.shape_cast(AABB(24.0, 28.0), (0.0, 28.0), (0.0, 100.0))
    c = collide(AABB(24.0, 28.0), (0.0, 28.0), AABB(64.0, 32.0), (0.0, 0.0))
    assert hit.entity == f and hit.fraction == 0.0
    assert hit.normal == (-c.normal.x, -c.normal.y) and hit.point == c.point


def test_nearest_of_several_wins_and_ties_go_to_the_lowest_entity(scene):
    far = floor(scene, 0.0, -100.0)
    near = floor(scene, 0.0, 0.0)
    assert scene.shape_cast(Circle(4.0), (0.0, 50.0), (0.0, -200.0)).entity == near
    a = floor(scene, 100.0, 0.0, 16.0, 32.0)
    b = floor(scene, 116.0, 0.0, 16.0, 32.0)  # a and b side by side: both tops met at once
    hit = scene.shape_cast(AABB(8.0, 8.0), (108.0, 40.0), (108.0, 0.0))
    assert hit.entity == min(a, b) and hit.fraction == 0.5
    assert far != near


def test_sensors_ignored_entities_and_masks_are_passed_through(scene):
    sensor = floor(scene, 0.0, 0.0, sensor=True)
    other_layer = floor(scene, 0.0, -64.0, layer=2)
    wall = floor(scene, 0.0, -128.0)
    shape = Circle(4.0)
    assert scene.shape_cast(shape, (0.0, 50.0), (0.0, -200.0)).entity == other_layer
    assert scene.shape_cast(shape, (0.0, 50.0), (0.0, -200.0), mask=1).entity == wall
    assert scene.shape_cast(shape, (0.0, 50.0), (0.0, -200.0), ignore=[other_layer]).entity == wall
    assert sensor not in {h.entity for h in [scene.shape_cast(shape, (0.0, 50.0), (0.0, -200.0))]}


def test_moving_bodies_are_cast_against_where_they_are(scene):
    body = scene.spawn(Transform(300.0, 0.0), Velocity(-64.0, 0.0), Hitbox(AABB(16.0, 16.0)))
    assert scene.shape_cast(AABB(8.0, 8.0), (0.0, 0.0), (400.0, 0.0)).fraction == (300.0 - 12.0) / 400.0
    scene.step(0.25)
    hit = scene.shape_cast(AABB(8.0, 8.0), (0.0, 0.0), (400.0, 0.0))
    assert hit.entity == body and hit.fraction == (284.0 - 12.0) / 400.0


def test_far_from_the_origin_gives_the_same_answer(scene):
    base = floor(scene, 0.0, 0.0)
    far = floor(scene, 2.0**30, 2.0**30)
    near_hit = scene.shape_cast(AABB(24.0, 28.0), (0.0, 40.0), (0.0, -40.0), ignore=[far])
    far_hit = scene.shape_cast(AABB(24.0, 28.0), (2.0**30, 2.0**30 + 40.0), (2.0**30, 2.0**30 - 40.0), ignore=[base])
    assert near_hit.fraction == far_hit.fraction and near_hit.normal == far_hit.normal
    assert (far_hit.point.x - 2.0**30, far_hit.point.y - 2.0**30) == near_hit.point


@pytest.mark.parametrize("kw, match", [
    ({"start": (math.nan, 0.0)}, "start"), ({"end": (0.0, math.inf)}, "end"),
    ({"shape": "box"}, "shape"), ({"rotation": math.nan}, "rotation"),
])
def test_bad_input_is_a_clear_error(scene, kw, match):
    args = {"shape": AABB(1.0, 1.0), "start": (0.0, 0.0), "end": (1.0, 0.0)} | kw
    rotation = args.pop("rotation", 0.0)
    with pytest.raises(InvalidValue, match=match):
        scene.shape_cast(args["shape"], args["start"], args["end"], rotation=rotation)


shapes = st.sampled_from([AABB(8.0, 4.0), Circle(3.0), Polygon([(-4, -2), (4, -2), (0, 5)]), Polygon.box(6.0, 2.0),
                          Capsule(2.0, 6.0), Capsule(3.0, 0.5)])
coord = st.integers(-64, 64).map(lambda v: v / 4.0)


@settings(max_examples=150, deadline=None)
@given(shapes, shapes, coord, coord, coord, coord, st.integers(0, 7))
def test_a_cast_agrees_with_time_of_impact_and_touches_at_the_point(a, b, x0, y0, mx, my, turn):
    s = Scene()
    try:
        rot = turn * math.pi / 8
        e = s.spawn(Transform(0.0, 0.0, rot), Hitbox(b, body="static"))
        hit = s.shape_cast(a, (x0, y0), (x0 + mx, y0 + my))
        toi = time_of_impact(a, (x0, y0), (mx, my), b, (0.0, 0.0, rot))
        assert (hit is None) == (toi is None)
        if hit is None:
            return
        assert hit.entity == e and hit.fraction == toi.fraction
        assert hit.normal == (-toi.normal.x, -toi.normal.y)
        if hit.fraction > 0.0:
            # The point lies on both outlines: within rounding of each shape's boundary.
            from framework.casting import shape_bounds

            at = (x0 + mx * hit.fraction, y0 + my * hit.fraction)
            for shape, pose in ((a, (*at, 0.0)), (b, (0.0, 0.0, rot))):
                lo_x, lo_y, hi_x, hi_y = shape_bounds(shape, *pose)
                assert lo_x - 1e-9 <= hit.point.x <= hi_x + 1e-9 and lo_y - 1e-9 <= hit.point.y <= hi_y + 1e-9
    finally:
        s.close()
