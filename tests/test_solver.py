"""The contact solver (issue 19): piles and crowds that settle, exactly where they should.

The compiled loops are checked on problems with exact answers (dyadic values), the whole response
on scenes a game builds: crowds of every shape mix dropped into a pit come to rest within 30 s
of game time with no overlap deeper than 0.02 and nobody outside (the frictionless mix of balls
and boxes does not yet: a strict xfail until friction, issue 23); piles of boxes rest at their
exact height; a tall pile of balls pushes none of them through its walls.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from framework import AABB, Circle, Hitbox, Polygon, Scene, Transform, Velocity
from framework.collision import collide
from framework.effects import DEFAULT_EFFECTS
from framework.systems import solver_loops as loops

DT = 1.0 / 60.0
NONE = np.zeros(0)
NO_FRICTION_P = (NONE,) * 12  # solve_positions' friction arguments, for none
NO_FRICTION_V = (NONE,) * 9  # solve_velocities'


# --- the compiled loops, on problems with exact answers ---------------------------------------------


def _positions(a, b, nx, ny, sep0, share_a, share_b, n_bodies, push0=None, reach=None, passes=64):
    a, b = np.asarray(a, dtype=np.int64), np.asarray(b, dtype=np.int64)
    C = a.size
    push = np.zeros(C) if push0 is None else np.asarray(push0, dtype=float)
    dx, dy = loops.warm_start(a, b, np.asarray(nx, float), np.asarray(ny, float), np.asarray(share_a, float),
                              np.asarray(share_b, float), push, n_bodies)
    reach = np.full(n_bodies, np.inf) if reach is None else np.asarray(reach, float)
    used, held = loops.solve_positions(np.arange(C), a, b, np.asarray(nx, float), np.asarray(ny, float),
                                       np.asarray(sep0, float), np.asarray(share_a, float),
                                       np.asarray(share_b, float), push, dx, dy, passes, 0.0,
                                       np.ones(C, dtype=bool), reach, *NO_FRICTION_P)
    return push, dx, dy, used, held


def test_a_stack_on_the_floor_is_pushed_out_exactly_in_one_pass_from_the_bottom_up():
    # Floor (body 0, immovable) -> box 1 -> box 2, normals up; all fell by 1/64 together: the floor
    # contact overlaps by 1/64, the box-box contact touches. The lower body keeps still (shares 0, 1).
    push, dx, dy, used, held = _positions([0, 1], [1, 2], [0, 0], [1, 1], [-1 / 64, 0.0], [0, 0], [1, 1], 3)
    assert push.tolist() == [1 / 64, 1 / 64] and dy.tolist() == [0.0, 1 / 64, 1 / 64]
    assert dx.tolist() == [0.0, 0.0, 0.0] and used == 2 and not held  # one pass moves, the second sees nothing


def test_a_warm_started_stack_needs_one_pass():
    push, dx, dy, used, _ = _positions([0, 1], [1, 2], [0, 0], [1, 1], [-1 / 64, 0.0], [0, 0], [1, 1], 3,
                                       push0=[1 / 64, 1 / 64])
    assert push.tolist() == [1 / 64, 1 / 64] and dy.tolist() == [0.0, 1 / 64, 1 / 64] and used == 1


def test_equal_masses_share_a_push_and_a_pass_takes_back_too_much():
    # Two free bodies overlapping by 1/2 along x, equal shares: each moves 1/4. Warm started with a
    # push of 1 (too much), the solver takes it back to 1/2 (never pulls them together).
    push, dx, _, _, _ = _positions([0], [1], [1], [0], [-0.5], [0.5], [0.5], 2)
    assert push.tolist() == [0.5] and dx.tolist() == [-0.25, 0.25]
    push, dx, _, _, _ = _positions([0], [1], [1], [0], [-0.5], [0.5], [0.5], 2, push0=[1.0])
    assert push.tolist() == [0.5] and dx.tolist() == [-0.25, 0.25]
    push, dx, _, _, _ = _positions([0], [1], [1], [0], [0.25], [0.5], [0.5], 2, push0=[1.0])
    assert push.tolist() == [0.0] and dx.tolist() == [0.0, 0.0]  # apart: no push at all


def test_a_push_is_held_within_a_bodys_reach():
    push, dx, _, _, held = _positions([0], [1], [1], [0], [-1.0], [0.0], [1.0], 2, reach=[np.inf, 0.25])
    assert held and push.tolist() == [0.25] and dx.tolist() == [0.0, 0.25]


def test_velocities_stop_a_closing_pair_and_bounce_to_a_target():
    a, b = np.array([0]), np.array([1])
    n1, n0 = np.array([1.0]), np.array([0.0])
    half = np.array([0.5])
    vx, vy = np.array([2.0, -2.0]), np.zeros(2)
    impulse = np.zeros(1)
    used = loops.solve_velocities(np.arange(1), a, b, n1, n0, np.zeros(1), half, half, impulse, vx, vy, 8, 0.0,
                                  np.ones(1, dtype=bool), *NO_FRICTION_V)
    assert vx.tolist() == [0.0, 0.0] and impulse.tolist() == [4.0] and used == 2
    loops.solve_velocities(np.arange(1), a, b, n1, n0, np.array([4.0]), half, half, impulse, vx, vy, 8, 0.0,
                           np.ones(1, dtype=bool), *NO_FRICTION_V)
    assert vx.tolist() == [-2.0, 2.0] and impulse.tolist() == [8.0]  # an elastic bounce: speeds swapped


def test_support_follows_chains_up_from_immovable_bodies():
    # floor(0) -> 1 -> 2 rest on each other; 3 rests on 4, which rests on nothing; 5 beside 1
    a = np.array([0, 1, 4, 1])
    b = np.array([1, 2, 3, 5])
    up = np.array([1.0, 1.0, 1.0, 0.0])
    fixed_a = np.array([True, False, False, False])
    held = loops.supported(np.arange(4), a, b, up, fixed_a, np.zeros(4, dtype=bool), 6)
    assert held.tolist() == [False, True, True, False, False, False]


# --- scenes ----------------------------------------------------------------------------------------------


def pit(scene: Scene, width: float, depth: float = 40.0) -> None:
    """A floor with its top at y = 0 from x = 0 to ``width``, and two walls."""
    scene.spawn(Transform(width / 2, -0.5), Hitbox(AABB(width + 2.0, 1.0), body="static"))
    scene.spawn(Transform(-0.5, depth / 2), Hitbox(AABB(1.0, depth), body="static"))
    scene.spawn(Transform(width + 0.5, depth / 2), Hitbox(AABB(1.0, depth), body="static"))


def crowd(kind: str, seed: int = 0, bodies: int = 120, friction: float | None = None) -> tuple[Scene, list[int]]:
    """The issue's crowd: frictionless balls (radius 0.25-0.5), boxes (sides 0.5-1) or both, on a
    grid of unit cells, jittered, dropped into a pit 8 wide, gravity 20 (``friction``: the
    bodies' coefficient; the pit gives none, so it is theirs against it too)."""
    rng = np.random.default_rng(seed)
    s = Scene(gravity=(0.0, -20.0))
    pit(s, 8.0)
    ents = []
    for k in range(bodies):
        ball = kind == "balls" or (kind == "mixed" and k % 2 == 0)
        if ball:
            r = float(rng.uniform(0.25, 0.5))
            shape, hw, hh = Circle(r), r, r
        else:
            w, h = (float(v) for v in rng.uniform(0.5, 1.0, 2))
            shape, hw, hh = AABB(w, h), w / 2, h / 2
        x = k % 8 + 0.5 + float(rng.uniform(-1.0, 1.0)) * (0.5 - hw)
        ents.append(s.spawn(Transform(x, 1.0 + (k // 8) * 1.1 + hh), Velocity(), Hitbox(shape, friction=friction)))
    return s, ents


def deepest_overlap(s: Scene, ents: list[int]) -> float:
    """The deepest overlap between any two of ``ents`` or with the pit, by ``collide``."""
    items = [(s.get(e, Hitbox).shape, s.get(e, Transform)) for e in s.entities]
    worst = 0.0
    for i in range(len(items)):
        for j in range(i + 1, len(items)):
            c = collide(items[i][0], items[i][1], items[j][0], items[j][1])
            if c is not None:
                worst = max(worst, c.depth)
    return worst


MIXED_NOT_YET = pytest.mark.xfail(
    strict=True, reason="without friction this crowd rests after 33 s (13-39 s over five seeds): a box sliding on a "
    "flat top stops only at a wall; with friction it rests within 2.4 s (the friction case below). (Issue 33's "
    "shock-propagation change let it rest in 16 s while it applied to every hit; limited to a heavier body hitting a "
    "lighter one, since a 20-row pyramid of turning boxes fell apart without it, it is back to 33 s.)")


@pytest.mark.slow
@pytest.mark.parametrize(("kind", "seconds", "friction"), [
    ("balls", 30, None), ("boxes", 30, None), pytest.param("mixed", 30, None, marks=MIXED_NOT_YET),
    ("mixed", 60, None), ("mixed", 30, 0.5)])
def test_a_crowd_dropped_into_a_pit_comes_to_rest(kind, seconds, friction):
    """The issue's goal: a crowd rests within 30 s, with no overlap deeper than 0.02 and nobody
    outside. Balls alone (9 to 15 s over five seeds) and boxes alone (under 2 s) meet it. Half and
    half, without friction, a box that lands on a flat top with some sideways speed slides on until
    it meets a wall: that crowd rests after 13 to 39 s depending on the seed (measured 2026-11-25).
    Its 30 s case is a strict xfail (frictionless boxes do slide on); the 60 s case guards what
    holds. With friction 0.5 the same crowd rests in 1.7 to 2.4 s over five seeds (2026-11-25)."""
    s, ents = crowd(kind, friction=friction)
    with s:
        for _ in range(60 * seconds):
            s.step(DT)
            if s.counters["asleep"] == len(ents) and s.counters["integrated"] == 0:
                break
        assert s.counters["asleep"] == len(ents), f"{kind}: not all asleep after {seconds} s"
        assert deepest_overlap(s, ents) <= 0.02
        for e in ents:
            t = s.get(e, Transform)
            assert 0.0 < t.x < 8.0 and t.y > 0.0  # nobody outside the pit


def test_a_pile_of_boxes_rests_at_its_exact_height():
    with Scene(gravity=(0.0, -10.0)) as s:
        pit(s, 10.0)
        boxes = [s.spawn(Transform(c + 0.5, r + 0.5 + (r + 1) / 16), Velocity(), Hitbox(AABB(1.0, 1.0)))
                 for r in range(10) for c in range(10)]
        for _ in range(300):
            s.step(DT)
        ys = sorted(s.get(b, Transform).y for b in boxes)
        # every row where it rests (to the rounding of y + its push-out: an ulp or two)
        assert ys == pytest.approx([r + 0.5 for r in range(10) for _ in range(10)], abs=1e-12)


@pytest.mark.slow
def test_a_tall_pile_of_balls_pushes_none_through_its_walls():
    # Was (during the solver's development): the pile's pressure pushed a ball at the bottom corner
    # 2 units sideways out through the wall in one step.
    rng = np.random.default_rng(0)
    with Scene(gravity=(0.0, -10.0)) as s:
        pit(s, 12.0, 60.0)
        balls = []
        for r in range(30):
            for c in range(12):
                rad = float(rng.uniform(0.3, 0.5))
                x = c + 0.5 + float(rng.uniform(-1, 1)) * (0.5 - rad)
                balls.append(s.spawn(Transform(x, r * 1.0625 + 0.5 + 1 / 16), Velocity(), Hitbox(Circle(rad))))
        for _ in range(300):
            s.step(DT)
            for b in balls:  # none out, none in a wall or the floor (beyond the solver's tolerance)
                t, r = s.get(b, Transform), s.get(b, Hitbox).shape.radius
                assert t.x - r > -1e-6 and t.x + r < 12.0 + 1e-6 and t.y - r > -1e-6


def test_polygons_rest_on_each_other_without_sinking():
    with Scene(gravity=(0.0, -10.0)) as s:
        pit(s, 4.0)
        hexagon = Polygon([(0.5 * math.cos(k * math.pi / 3), 0.5 * math.sin(k * math.pi / 3)) for k in range(6)])
        low = s.spawn(Transform(2.0, 0.5), Velocity(), Hitbox(Polygon.box(2.0, 1.0)))
        top = s.spawn(Transform(2.0, 1.0 + 0.5 * math.sqrt(3) / 2 + 0.1), Velocity(), Hitbox(hexagon))
        for _ in range(240):
            s.step(DT)
        assert s.get(low, Transform).y == pytest.approx(0.5, abs=1e-9)
        assert s.get(top, Transform).y == pytest.approx(1.0 + 0.5 * math.sqrt(3) / 2, abs=1e-9)


def test_a_small_fast_box_sunk_deep_into_the_floor_ends_on_top_of_it():
    # A box 1/4 high moves 11/16 down in one step (22 units/s over 1/32), its bottom 9/16 into a
    # thick floor: many times its reach per round of pushing out of statics (found by the
    # hypothesis scene machine; it was left 1/16 inside). It ends exactly on top: centre 1/8,
    # touching, not overlapping.
    with Scene(gravity=(0.0, 0.0)) as s:
        floor = s.spawn(Transform(0.0, -2.0), Hitbox(AABB(64.0, 4.0), body="static"))
        box = s.spawn(Transform(0.0, 0.25), Velocity(0.0, -22.0), Hitbox(AABB(0.125, 0.25)))
        s.step(1 / 32)
        t = s.get(box, Transform)
        assert (t.x, t.y) == (0.0, 0.125)
        assert collide(s.get(floor, Hitbox).shape, s.get(floor, Transform), s.get(box, Hitbox).shape, t) is None


def test_a_box_whose_support_slides_away_sideways_falls():
    # Resting pairs that merely touch are kept in the solve (they fell together); one whose lower
    # body has slid out from under the upper one no longer holds it up, however small its gap
    # along the normal (found 2026-11-25: the upper box hung in the air, held by the kept pair).
    with Scene(gravity=(0.0, -10.0), effects=DEFAULT_EFFECTS - {"sleeping"}) as s:
        s.spawn(Transform(0.0, -0.5), Hitbox(AABB(100.0, 1.0), body="static"))
        low = s.spawn(Transform(0.0, 0.5), Velocity(), Hitbox(AABB(1.0, 1.0)))
        top = s.spawn(Transform(0.0, 1.25), Velocity(), Hitbox(AABB(0.5, 0.5)))
        for _ in range(120):
            s.step(DT)
        assert s.get(top, Transform).y == 1.25
        for _ in range(60):
            s.get(low, Velocity).x = 3.0  # the game drives the lower box out from under the upper one
            s.step(DT)
        assert s.get(low, Transform).x > 0.75 + 0.25  # clear of it
        assert s.get(top, Transform).y == pytest.approx(0.25, abs=1e-9) and s.get(top, Transform).x == 0.0
