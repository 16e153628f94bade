"""Internal faces in the soft step: a floor or a wall built of separate static boxes (tiles) is as
flat as one box. A body sliding or rolling over the seam between two tiles must not catch on the
next tile's covered side face or corner (the soft step reports contacts up to a speculative distance
ahead, so an uncovered side face would stop a crate dead at the first seam).

The oracle is the same scene on one long floor box: the tiled floor must give the same motion.
Dyadic values (dt 1/64, gravity 8, speed 6) keep the frictionless answer exact.
"""

from __future__ import annotations

import numpy as np
import pytest

from framework import AABB, Capsule, Circle, Hitbox, Polygon, Scene, Transform, Velocity
from framework.collision.soft_manifold import DOWN, LEFT, RIGHT, UP
from framework.systems.soft_kernel import internal_faces
from framework.systems.soft_step import SOFT_SETTINGS

SLOP = SOFT_SETTINGS["slop"]
DT = 1 / 64
SHAPES = {
    "aabb": (AABB(1.0, 1.0), 0.5),
    "polygon box (turns)": (Polygon.box(1.0, 1.0), 0.5),
    "circle": (Circle(0.5), 0.5),
    "capsule": (Capsule(0.25, 1.0), 0.75),
}


def slide(shape, rest_y: float, *, tiled: bool, mu: float | None = None, steps: int = 240):
    """A body moving right at 6 over a floor 40 long (top at y = 0): 40 unit tiles, or one box."""
    scene = Scene(solver="soft", gravity=(0.0, -8.0))
    if tiled:
        for i in range(40):
            scene.spawn(Transform(i + 0.5, -0.5), Hitbox(AABB(1.0, 1.0), body="static", friction=mu))
    else:
        scene.spawn(Transform(20.0, -0.5), Hitbox(AABB(40.0, 1.0), body="static", friction=mu))
    body = scene.spawn(Transform(2.0, rest_y), Hitbox(shape, friction=mu), Velocity(6.0, 0.0))
    for _ in range(steps):
        scene.step(DT)
    t, v = scene.get(body, Transform), scene.get(body, Velocity)
    return t.x, t.y, t.rotation, v.x, v.y


@pytest.mark.parametrize("name", list(SHAPES))
def test_a_frictionless_body_slides_over_every_seam_of_a_tiled_floor(name):
    shape, rest_y = SHAPES[name]
    x, y, rot, vx, vy = slide(shape, rest_y, tiled=True)
    # 240 steps of 1/64 at 6: 22.5 further, at the speed it had, level, still on the floor
    assert x == pytest.approx(24.5, abs=1e-3)
    assert vx == pytest.approx(6.0, abs=1e-3)
    assert abs(rot) < 1e-3
    assert rest_y - SLOP < y <= rest_y + 1e-9


@pytest.mark.parametrize("name", list(SHAPES))
@pytest.mark.parametrize("mu", [None, 0.5])
def test_a_tiled_floor_moves_a_body_as_one_floor_box_does(name, mu):
    shape, rest_y = SHAPES[name]
    x, y, rot, vx, vy = slide(shape, rest_y, tiled=True, mu=mu)
    wx, wy, wrot, wvx, wvy = slide(shape, rest_y, tiled=False, mu=mu)
    # the same motion (the contacts differ where two tiles meet: by less than a slop); a rolling
    # circle's angle (28 radians by the end) to a part in 10^4
    assert (x, y, vx, vy) == pytest.approx((wx, wy, wvx, wvy), abs=SLOP / 4)
    assert rot == pytest.approx(wrot, rel=1e-4, abs=1e-4)


def test_coulomb_stop_on_a_tiled_floor():
    # v0 = 6, mu g = 4: stops 4.5 further, less half a sub-step of motion (the sub-stepped integration)
    x, y, _rot, vx, _vy = slide(AABB(1.0, 1.0), 0.5, tiled=True, mu=0.5)
    h = DT / SOFT_SETTINGS["substeps"]
    assert x == pytest.approx(6.5 - 6.0 * h / 2, abs=2e-4)
    assert vx == 0.0


def press_against_wall(shape, *, tiled: bool, steps: int = 160):
    """A floor (top at y = 0) and a wall 6 high at x = 10..11, each 1 x 1 tiles or one box; a body
    starting 4 up against the wall, gravity pressing it into the wall as it falls: its (x, y) after
    every step."""
    scene = Scene(solver="soft", gravity=(4.0, -8.0))
    if tiled:
        for i in range(16):
            scene.spawn(Transform(i + 0.5, -0.5), Hitbox(AABB(1.0, 1.0), body="static"))
        for j in range(6):
            scene.spawn(Transform(10.5, j + 0.5), Hitbox(AABB(1.0, 1.0), body="static"))
    else:
        scene.spawn(Transform(8.0, -0.5), Hitbox(AABB(16.0, 1.0), body="static"))
        scene.spawn(Transform(10.5, 3.0), Hitbox(AABB(1.0, 6.0), body="static"))
    body = scene.spawn(Transform(9.5, 4.5), Hitbox(shape), Velocity(0.0, 0.0))
    path = []
    for _ in range(steps):
        scene.step(DT)
        t = scene.get(body, Transform)
        path.append((t.x, t.y))
    return np.array(path)


@pytest.mark.parametrize("shape", [AABB(1.0, 1.0), Polygon.box(1.0, 1.0)], ids=["aabb", "polygon"])
def test_a_body_pressed_against_a_wall_of_tiles_slides_down_it_to_the_floor(shape):
    # the wall's tiles are stacked: each one's top face is covered by the next (a body sliding down
    # must not land on a seam), and the lowest one stands on the floor (its bottom face is covered:
    # a body in the corner is held by the floor and the wall, never pushed into the floor)
    tiled = press_against_wall(shape, tiled=True)
    whole = press_against_wall(shape, tiled=False)
    assert np.abs(tiled - whole).max() < 2 * SLOP
    assert (tiled[:, 0] <= 9.5 + SLOP).all()  # never into the wall
    assert tiled[-1, 1] == pytest.approx(0.5, abs=SLOP)  # down on the floor


def _faces(boxes, **kw):
    """``internal_faces`` of static boxes given as (x, y, w, h)."""
    n = len(boxes)
    x = np.array([b[0] for b in boxes], dtype=float)
    y = np.array([b[1] for b in boxes], dtype=float)
    half = np.array([(b[2] / 2, b[3] / 2) for b in boxes], dtype=float)
    layer = np.asarray(kw.get("layer", [1] * n), dtype=np.int64)
    mask = np.ones(n, dtype=np.int64) * 0xFFFFFFFF
    eligible = np.asarray(kw.get("eligible", [True] * n))
    return internal_faces(x, y, np.zeros(n), np.zeros((n, 2)), half, np.full(n, 4, dtype=np.int64), eligible,
                          layer, mask).tolist()


def test_internal_faces_of_a_block_of_tiles():
    block = [(i + 0.5, j + 0.5, 1.0, 1.0) for j in range(3) for i in range(3)]
    faces = _faces(block)
    assert faces[4] == LEFT | RIGHT | DOWN | UP  # the centre: covered all round
    assert faces[0] == RIGHT | UP  # bottom-left corner
    assert faces[8] == LEFT | DOWN  # top-right corner
    assert faces[1] == LEFT | RIGHT | UP  # bottom middle: its bottom is open


def test_a_face_is_internal_only_when_a_neighbour_spans_all_of_it():
    # right of tile 0: a half-height box (covers half the face), and far above, a box that does
    faces = _faces([(0.5, 0.5, 1.0, 1.0), (1.5, 0.25, 1.0, 0.5), (10.5, 10.5, 1.0, 1.0), (11.5, 10.5, 1.0, 2.0)])
    assert faces[0] == 0
    assert faces[1] == LEFT  # tile 0 spans the half-height box's left face
    assert faces[2] == RIGHT
    assert faces[3] == 0  # tile 2 covers half of its left face


def test_no_internal_face_across_a_gap_across_layers_or_with_a_box_that_takes_no_part():
    assert _faces([(0.5, 0.5, 1.0, 1.0), (1.501, 0.5, 1.0, 1.0)]) == [0, 0]  # a gap of 1/1000
    assert _faces([(0.5, 0.5, 1.0, 1.0), (1.5, 0.5, 1.0, 1.0)], layer=[1, 2]) == [0, 0]
    assert _faces([(0.5, 0.5, 1.0, 1.0), (1.5, 0.5, 1.0, 1.0)], eligible=[True, False]) == [0, 0]
    # flush up to the coordinates' rounding: 0.1 + 0.2 is 0.30000000000000004, 0.35 - 0.05 is 0.29999999999999993
    assert 0.1 + 0.2 != 0.35 - 0.05
    assert _faces([(0.1, 0.5, 0.4, 1.0), (0.35, 0.5, 0.1, 1.0)]) == [RIGHT, LEFT]
