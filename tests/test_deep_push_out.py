"""Bodies deep inside static boxes go out where a player expects (issue 34, item 4).

The least push out of a slab is through its nearer face, and between the top and bottom faces of a
body placed in a floor's middle the contract's tie order picks the bottom: such a body fell out of
the world. The solve now takes a movable body whose centre lies inside a static AABB back out the
side it came from when it came in this step, and otherwise (spawned or teleported there) out of
the face against gravity unless that is more than its own height farther than the nearest face
(a ball in the middle of a tall wall still leaves by the near side). Faces other tiles cover stay
closed (internal faces): a body in the middle of a column of tiles leaves sideways.

All positions are dyadic: every expected resting place is exact.
"""

from __future__ import annotations

import pytest

from framework import AABB, Circle, Hitbox, Polygon, Scene, Transform, Velocity

DT = 1.0 / 64.0
SHAPES = {
    "box": lambda: AABB(0.5, 0.5),
    "circle": lambda: Circle(0.25),
    "turning-box": lambda: Polygon.box(0.5, 0.5),
    "triangle": lambda: Polygon([(-0.25, -0.25), (0.25, -0.25), (0.0, 0.25)]),
}


def _settle(s: Scene, steps: int = 64) -> None:
    for _ in range(steps):
        s.step(DT)


def _tolerance(shape: str) -> float:
    """Exact for bodies that do not turn; 1e-6 for those that do, where the solver stops at 1e-8
    of their size and a turn couples to a slide along a wall (measured up to 8e-8)."""
    return 1e-6 if shape in ("turning-box", "triangle") else 1e-9


def _pose(s: Scene, e: int) -> tuple[float, float]:
    t = s.get(e, Transform)
    return t.x, t.y


@pytest.mark.parametrize("shape", list(SHAPES))
@pytest.mark.parametrize("y", [0.0, 0.125, -0.125, -0.1875])
@pytest.mark.parametrize("how", ["spawned", "teleported"])
def test_a_body_put_inside_a_floor_slab_pops_up_on_top(shape, y, how):
    # A slab one unit thick (top at y = 1/2); a body of half-height 1/4 put with its centre inside
    # it, at the middle or up to 3/16 below: it ends resting on top, centre at y = 3/4 (the
    # defect: pushed out of the bottom, it fell forever).
    s = Scene(gravity=(0.0, -8.0))
    s.spawn(Transform(0.0, 0.0), Hitbox(AABB(10.0, 1.0), body="static"))
    with s:
        if how == "spawned":
            body = s.spawn(Transform(0.0, y), Velocity(), Hitbox(SHAPES[shape]()))
        else:  # stepped once up in the air, then moved into the slab by game code
            body = s.spawn(Transform(3.0, 4.0), Velocity(), Hitbox(SHAPES[shape]()))
            s.step(DT)
            t = s.get(body, Transform)
            t.x, t.y = 0.0, y
        _settle(s)
        assert _pose(s, body) == pytest.approx((0.0, 0.75), abs=1e-9)
        assert abs(s.get(body, Transform).rotation) < 1e-9


@pytest.mark.parametrize("shape", list(SHAPES))
def test_a_body_inside_a_tall_wall_goes_out_of_the_near_side(shape):
    # A wall 1 wide and 10 tall standing on a floor; a body put 1/8 right of its middle line, 3
    # above the floor: out of the right face (3/8 + 1/4 away, against 7 up), then down to the
    # floor beside the wall: x = 1/2 + 1/4, y = 1/4.
    s = Scene(gravity=(0.0, -8.0))
    s.spawn(Transform(0.0, -0.5), Hitbox(AABB(20.0, 1.0), body="static"))
    s.spawn(Transform(0.0, 5.0), Hitbox(AABB(1.0, 10.0), body="static"))
    with s:
        body = s.spawn(Transform(0.125, 3.0), Velocity(), Hitbox(SHAPES[shape]()))
        _settle(s, 128)
        assert _pose(s, body) == pytest.approx((0.75, 0.25), abs=_tolerance(shape))


@pytest.mark.parametrize("shape", list(SHAPES))
def test_a_body_inside_a_column_of_tiles_leaves_by_an_open_face(shape):
    # A column of five unit tiles on a floor. A body in the middle tile cannot go up or down
    # through the tiles covering it: it leaves sideways (left, the internal faces' order) and
    # falls to the floor beside the column; one in the top tile pops up onto the column.
    s = Scene(gravity=(0.0, -8.0))
    s.spawn(Transform(0.0, -0.5), Hitbox(AABB(40.0, 1.0), body="static"))
    for i in range(5):
        s.spawn(Transform(0.0, 0.5 + i), Hitbox(AABB(1.0, 1.0), body="static"))
    with s:
        middle = s.spawn(Transform(0.0, 2.5), Velocity(), Hitbox(SHAPES[shape]()))
        top = s.spawn(Transform(0.0, 4.5), Velocity(), Hitbox(SHAPES[shape]()))
        _settle(s, 128)
        assert _pose(s, middle) == pytest.approx((-0.75, 0.25), abs=_tolerance(shape))
        assert _pose(s, top) == pytest.approx((0.0, 5.25), abs=_tolerance(shape))


@pytest.mark.parametrize("shape", list(SHAPES))
def test_a_fast_body_that_sank_past_a_slab_s_middle_in_one_step_goes_back_out_the_top(shape):
    # Without continuous detection, a body falling at 96 units/s (1.5 a step of 1/64) from just
    # above a slab two thick (top at y = 1) ends its first step with its centre 0.2 below the
    # slab's middle, nearer the bottom face; it came from above, so it goes back out of the top.
    s = Scene(gravity=(0.0, -8.0))
    s.spawn(Transform(0.0, 0.0), Hitbox(AABB(10.0, 2.0), body="static"))
    with s:
        body = s.spawn(Transform(0.0, 1.3), Velocity(0.0, -96.0), Hitbox(SHAPES[shape]()))
        _settle(s)
        assert _pose(s, body) == pytest.approx((0.0, 1.25), abs=1e-9)
