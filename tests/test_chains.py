"""Chains: polylines and loops of one-sided segments with ghost vertices (Box2D's chain shapes).

The chain's rules (framework.collision.chain) on single pairs: one-sided from both sides, snapped
normals at straight and inward joints, neighbours' directions left to them at outward joints; rays
and casts. In scenes, both solvers: a box, a turning box and a capsule slide along a random chain of
hundreds of segments at many speeds, both ways along it, and never lose speed at a joint (the same
joints as plain two-sided segments do catch them), and a body passes through a chain from behind.
"""

from __future__ import annotations

import math
import random

import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from framework import AABB, Capsule, Chain, ChainSegment, Circle, Hitbox, Polygon, Scene, Segment, Transform, Velocity
from framework.chains import spawn_chain
from framework.collision import collide, manifold, raycast, time_of_impact
from framework.collision.batch import collide_many
from framework.collision.results import Contact, Vec2

FAST = settings(max_examples=150, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])

# Drawn right to left: the solid side (on the left of the direction) is below, bodies meet its top.
FLOOR = Chain([(2, 0), (1, 0), (0, 0), (-1, 0)])


# --- the chain and its segments ------------------------------------------------------------------

def test_a_chain_links_its_segments_through_ghost_vertices() -> None:
    s0, s1, s2 = FLOOR.segments
    assert (s1.a, s1.b, s1.ghost1, s1.ghost2) == ((1.0, 0.0), (0.0, 0.0), (2.0, 0.0), (-1.0, 0.0))
    assert s1.normal == (0.0, 1.0)
    # The free ends: ghosts behind them, square to the segment (the ends are corners).
    assert s0.ghost1 == (2.0, -1.0) and s2.ghost2 == (-1.0, -1.0)
    loop = Chain([(0, 0), (2, 0), (2, 2), (0, 2), (0, 0)], loop=True)  # closed given: the repeat dropped
    assert len(loop) == 4 and loop.points == ((0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0))
    assert [(s.ghost1, s.ghost2) for s in loop.segments][0] == ((0.0, 2.0), (2.0, 2.0))
    assert isinstance(s1, Segment) and s1.kind == "segment"
    for bad, word in [(([(0, 0)],), "at least 2"), (([(0, 0), (1, 0)], True), "at least 3"),
                      (([(0, 0), (0, 0), (1, 0)],), "equal"), (([(0, 0), (math.nan, 0)],), "nan"),
                      (("ab",), "'ab'"), (([(0, 0), (1, 0)], 1), "loop must be True or False")]:
        with pytest.raises(ValueError, match=word):
            Chain(*bad)
    with pytest.raises(ValueError, match="ghosts must differ"):
        ChainSegment((0, 0), (1, 0), (0, 0), (2, 0))


# --- one pair --------------------------------------------------------------------------------------

@pytest.mark.parametrize("shape", [AABB(1, 1), Circle(0.5), Polygon.box(1, 1), Capsule(0.5, 1)],
                         ids=["aabb", "circle", "polygon", "capsule"])
def test_one_sided_from_both_sides(shape) -> None:
    seg = FLOOR.segments[1]
    half = shape.height / 2 if isinstance(shape, Capsule) else 0.5
    above = collide(seg, (0, 0), shape, (0.5, half - 0.25))
    assert above == Contact(Vec2(0.0, 1.0), 0.25, above.point) and 0 <= above.point.x <= 1
    assert collide(shape, (0.5, half - 0.25), seg, (0, 0)).normal == (0.0, -1.0)
    # The same overlap from below: the body's centre is behind the segment, it passes.
    assert collide(seg, (0, 0), shape, (0.5, -half + 0.25)) is None
    assert collide(shape, (0.5, -half + 0.25), seg, (0, 0)) is None
    # ... where the plain segment pushes it down.
    assert collide(Segment(seg.a, seg.b), (0, 0), shape, (0.5, -half + 0.25)).normal == (0.0, -1.0)
    # Rays and casts: from the front only.
    assert raycast(seg, (0, 0), (0.5, 5), (0, -1)).normal == (0.0, 1.0)
    assert raycast(seg, (0, 0), (0.5, -5), (0, 1)) is None
    assert time_of_impact(shape, (0.5, half + 1), (0, -2), seg, (0, 0)).fraction == 0.5
    assert time_of_impact(shape, (0.5, -half - 1), (0, 2), seg, (0, 0)) is None


def test_a_straight_joint_pushes_out_along_the_segment_not_sideways() -> None:
    s1 = FLOOR.segments[1]  # from (1, 0) to (0, 0); the next segment runs on from (1, 0) to (2, 0)
    # A box sunk 0.05, its left side 0.03 past the joint: the plain segment pushes it out sideways,
    # back over the joint (the snag); the chain segment pushes it up, out of the line.
    box = (AABB(1, 1), (1.47, 0.45))
    assert collide(Segment(s1.a, s1.b), (0, 0), *box).normal == (1.0, 0.0)
    c = collide(s1, (0, 0), *box)
    assert c.normal == (0.0, 1.0) and c.depth == pytest.approx(0.05, abs=1e-15)
    assert collide(box[0], box[1], s1, (0, 0)).normal == (0.0, -1.0)
    m = manifold(s1, (0, 0), *box)
    assert m.normal == (0.0, 1.0) and sorted(p.point.x for p in m.points) == pytest.approx([0.97, 1.0])
    # An impact at the joint, sideways on the plain segment, is along the normal on the chain.
    assert time_of_impact(AABB(1, 1), (2, 0.4), (-2, 0), Segment(s1.a, s1.b), (0, 0)).normal == (-1.0, 0.0)
    assert time_of_impact(AABB(1, 1), (2, 0.4), (-2, 0), s1, (0, 0)).normal == (0.0, -1.0)


def test_an_outward_joint_leaves_the_neighbours_directions_to_it() -> None:
    # A hill: from (4, 0) up to the top (2, 1), down to (0, 0) (drawn right to left: solid below).
    right, left = Chain([(4, 0), (2, 1), (0, 0)]).segments
    # A circle over the top: both segments see the vertex, in the cone between their normals.
    for seg in (right, left):
        c = collide(seg, (0, 0), Circle(0.5), (2, 1.375))
        assert c.normal == (0.0, 1.0) and c.depth == pytest.approx(0.125)
    # A circle on the left slope just past the top, sunk 0.05 into it: the left segment's face holds
    # it; the right segment's plain vertex would push it out along a direction beyond the right
    # segment's normal cone (toward the left slope's): that direction is the left segment's.
    n = (-1 / math.sqrt(5), 2 / math.sqrt(5))  # the left slope's normal
    d = (-2 / math.sqrt(5), -1 / math.sqrt(5))  # down the left slope
    at = (2 + 0.1 * d[0] + 0.45 * n[0], 1 + 0.1 * d[1] + 0.45 * n[1])
    face = collide(left, (0, 0), Circle(0.5), at)
    assert face.normal == pytest.approx(n) and face.depth == pytest.approx(0.05)
    assert collide(Segment(right.a, right.b), (0, 0), Circle(0.5), at) is not None  # the plain vertex
    assert collide(right, (0, 0), Circle(0.5), at) is None


def test_a_ray_through_a_joint_hits_and_from_behind_misses() -> None:
    s0, s1, _ = FLOOR.segments
    assert raycast(s1, (0, 0), (1, 5), (0, -1)).point == (1.0, 0.0)
    assert raycast(s0, (0, 0), (1, 5), (0, -1)).point == (1.0, 0.0)
    assert raycast(s1, (0, 0), (1, -5), (0, 1)) is None and raycast(s0, (0, 0), (1, -5), (0, 1)) is None


segs = st.sampled_from([*FLOOR.segments, *Chain([(4, 0), (2, 1), (0, 0), (-2, 0.5)]).segments,
                        *Chain([(0, 0), (3, 0), (3, 2), (0, 2)], loop=True).segments])
others = st.one_of(st.builds(AABB, st.integers(1, 16).map(lambda i: i / 8), st.integers(1, 16).map(lambda i: i / 8)),
                   st.builds(Circle, st.integers(1, 16).map(lambda i: i / 8)),
                   st.builds(Capsule, st.integers(1, 8).map(lambda i: i / 8), st.integers(1, 8).map(lambda i: i / 8)),
                   st.sampled_from([Polygon.box(1, 0.5), Polygon([(-0.5, -0.5), (0.5, -0.5), (0, 0.5)])]))
coords = st.integers(-32, 32).map(lambda i: i / 8)


@FAST
@given(segs, others, coords, coords, st.sampled_from([0.0, 0.5, -1.0]))
def test_the_chain_rules_hold_for_every_pair_and_the_batch_agrees(seg, other, x, y, rot):
    c = collide(seg, (0, 0), other, (x, y, rot))
    s = collide(other, (x, y, rot), seg, (0, 0))
    assert (c is None) == (s is None)
    two = collide(Segment(seg.a, seg.b), (0, 0), other, (x, y, rot))
    many = collide_many([seg, other], [(0, 0), (x, y, rot)], [other, seg], [(x, y, rot), (0, 0)])
    assert list(many.hit) == [c is not None, s is not None]
    if c is None:
        return
    assert two is not None  # a chain segment never finds more than its segment
    assert s.depth == c.depth and s.normal == (-c.normal[0], -c.normal[1])
    assert (many.nx[0], many.ny[0], many.depth[0]) == (c.normal.x, c.normal.y, c.depth)
    assert (many.nx[1], many.ny[1], many.depth[1]) == (s.normal.x, s.normal.y, s.depth)
    # the body's hitbox origin is in front of the segment (or of a neighbour turning outward)
    ex, ey = seg.b[0] - seg.a[0], seg.b[1] - seg.a[1]
    front = ey * (x - seg.a[0]) - ex * (y - seg.a[1]) >= 0
    assume(front)
    # the normal is the segment's, or lies between it and a neighbour's (a vertex at an outward joint)
    n1 = seg.normal
    assert c.normal == pytest.approx(n1, abs=1e-12) or c.normal[0] * n1[0] + c.normal[1] * n1[1] > -1.0


# --- scenes ---------------------------------------------------------------------------------------

SOLVERS = ["exact", "soft"]
SLIDERS = {"aabb": (AABB(1, 1), 0.5), "turning box": (Polygon.box(1, 1), 0.5), "capsule": (Capsule(0.5, 1), 1.0)}
THETA = 0.1  # the chain falls to the right at this angle


def ground(n: int = 300, seed: int = 5, theta: float = THETA, jitter: float = 0.0) -> list[tuple[float, float]]:
    """A straight line falling to the right at ``theta`` through random (not dyadic) joints along x
    in [-100, 100], drawn right to left (its top is solid): its joints are straight up to rounding
    (and to ``jitter``, a random offset of each point across the line)."""
    rng = random.Random(seed)
    us = sorted({rng.uniform(-100, 100) for _ in range(n)}, reverse=True)
    c, s = math.cos(theta), math.sin(theta)
    return [(u * c + j * s, -u * s + j * c) for u in us for j in [rng.uniform(-jitter, jitter)]]


def slide(solver: str, name: str, speed: float, *, chain: bool = True, steps: int = 240, seed: int = 5,
          theta: float = THETA, jitter: float = 0.0) -> float:
    """A frictionless body sliding along the ground at ``speed`` (negative: up the slope); the worst
    shortfall of its speed along the ground against g sin(theta) t (0: never lost speed)."""
    shape, rest = SLIDERS[name]
    s = Scene(solver="soft") if solver == "soft" else Scene()
    s.gravity = (0, -10.0)
    pts = ground(seed=seed, theta=theta, jitter=jitter)
    if chain:
        spawn_chain(s, Chain(pts))
    else:
        for a, b in zip(pts, pts[1:]):
            s.spawn(Transform(0, 0), Hitbox(Segment(a, b), body="static"))
    c, sn = math.cos(theta), math.sin(theta)
    turned = not isinstance(shape, AABB)
    h = rest if turned else 0.5 * (c + abs(sn))  # an AABB does not turn: it rests on its lower corner
    u0 = -60.0 if speed > 0 else 60.0
    body = s.spawn(Transform(u0 * c + sn * h, -u0 * sn + c * h, -theta if turned else 0.0),
                   Velocity(speed * c, -speed * sn), Hitbox(shape, inertia=math.inf))
    worst = 0.0
    for i in range(steps):
        s.step(1 / 60)
        v = s.get(body, Velocity)
        along = v.x * c - v.y * sn
        worst = min(worst, along - (speed + 10.0 * sn * (i + 1) / 60))
        if abs(s.get(body, Transform).x) > 95:
            break
    return worst


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("name", list(SLIDERS))
@pytest.mark.parametrize("speed", [1.0, 5.0, 20.0, -8.0])
def test_bodies_slide_along_a_chain_of_hundreds_of_segments_without_catching(solver, name, speed) -> None:
    # frictionless: the speed along the ground follows g sin(theta) t, to rounding, at every joint
    assert slide(solver, name, speed) > -1e-6


@pytest.mark.parametrize("solver", SOLVERS)
@settings(max_examples=12, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(name=st.sampled_from(list(SLIDERS)), seed=st.integers(0, 10**6),
       theta=st.floats(-0.3, 0.3), speed=st.floats(0.25, 40.0), up=st.booleans(),
       jitter=st.sampled_from([0.0, 1e-9]))
def test_no_joint_of_a_random_chain_catches_a_body_at_any_speed(solver, name, seed, theta, speed, up, jitter):
    # any tilt either way, any speed, up or down the slope, joints straight to rounding (or a hair off)
    assert slide(solver, name, -speed if up else speed, seed=seed, theta=theta, jitter=jitter, steps=120) > -1e-6


@pytest.mark.parametrize("solver", SOLVERS)
def test_the_same_joints_catch_bodies_on_plain_segments(solver) -> None:
    # the control: two-sided segments at the same joints stop some body dead at some speed
    worst = min(slide(solver, name, speed, chain=False) for name in SLIDERS for speed in (1.0, 20.0))
    assert worst < -1.0


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("shape", [AABB(1, 1), Circle(0.5), Polygon.box(1, 1), Capsule(0.5, 1)],
                         ids=["aabb", "circle", "polygon", "capsule"])
def test_a_body_lands_on_a_chain_from_the_front_and_passes_from_behind(solver, shape) -> None:
    s = Scene(solver="soft") if solver == "soft" else Scene()
    s.gravity = (0, 0)
    spawn_chain(s, Chain([(5, 0), (2, 0), (-1, 0), (-5, 0)]))
    half = shape.height / 2 if isinstance(shape, Capsule) else 0.5
    # (not on a joint: the soft solver spins a turning box caught at two corners by two bodies, a
    # floor of two boxes as much; the exact solver lands it flat there too, see below)
    down = s.spawn(Transform(0.5, 3), Velocity(0, -8), Hitbox(shape))
    up = s.spawn(Transform(-2.5, -3), Velocity(0, 8), Hitbox(shape))
    for _ in range(60):
        s.step(1 / 60)
    assert s.get(down, Transform).y == pytest.approx(half, abs=1e-2)  # stopped on top
    assert s.get(up, Transform).y > 3 and s.get(up, Velocity).y == pytest.approx(8.0)  # went through


def test_a_turning_box_lands_flat_across_a_joint_in_the_exact_solver() -> None:
    s = Scene()
    spawn_chain(s, Chain([(5, 0), (2, 0), (-1, 0), (-5, 0)]))
    box = s.spawn(Transform(1.5, 3), Velocity(0, -8), Hitbox(Polygon.box(1, 1)))  # a corner on the joint
    for _ in range(60):
        s.step(1 / 60)
    t = s.get(box, Transform)
    assert (t.x, t.y, t.rotation) == pytest.approx((1.5, 0.5, 0.0), abs=1e-9)


@pytest.mark.parametrize("solver", SOLVERS)
def test_a_box_rests_in_a_loop_and_on_it(solver) -> None:
    s = Scene(solver="soft") if solver == "soft" else Scene()
    s.gravity = (0, -10)
    # a loop drawn clockwise: its inside is the open side (a room); counter-clockwise: a solid block
    spawn_chain(s, Chain([(-4, 0), (-4, 6), (4, 6), (4, 0)], loop=True))
    spawn_chain(s, Chain([(10, 0), (14, 0), (14, 2), (10, 2)], loop=True))
    inside = s.spawn(Transform(0, 2), Velocity(0, 0), Hitbox(AABB(1, 1)))
    on_top = s.spawn(Transform(12, 4), Velocity(0, 0), Hitbox(AABB(1, 1)))
    for _ in range(180):
        s.step(1 / 60)
    assert s.get(inside, Transform).y == pytest.approx(0.5, abs=1e-3)
    assert s.get(on_top, Transform).y == pytest.approx(2.5, abs=1e-3)
    hit = s.raycast((12, 10), (0, -1))
    assert hit.point == pytest.approx((12.0, 3.0), abs=1e-3)  # the top of the box on top
    hit = s.raycast((12, 1), (0, 1))  # from inside the solid block: through its top's back, to the box
    assert hit.entity == on_top and hit.point == pytest.approx((12.0, 2.0), abs=1e-3)


def test_a_character_walks_a_chain_up_a_ramp_as_it_walks_tiles() -> None:
    # docs/character.md's walk (flat ground at y = 32, a 45-degree ramp up to 64 over x 128..160),
    # the ground drawn as one chain instead of tiles: the same path.
    from framework.character import CharacterController

    scene = Scene(gravity=(0.0, -1024.0))
    spawn_chain(scene, Chain([(320, 64), (160, 64), (128, 32), (96, 32), (40, 32), (0, 32)]))
    hero = scene.spawn(Transform(64.0, 46.0), Velocity(), Hitbox(AABB(24.0, 28.0), body="kinematic"),
                       CharacterController(step_height=8.0))
    ctrl, body, vel = scene.get(hero, CharacterController), scene.get(hero, Transform), scene.get(hero, Velocity)
    path = []
    for step in range(60):
        vel.x = 128.0
        scene.step(1 / 64)
        if step % 10 == 9:
            path.append((body.x, round(body.y - 14, 9), ctrl.on_floor, round(ctrl.floor_normal[1], 3)))
    assert path == [(84.0, 32.0, True, 1.0), (104.0, 32.0, True, 1.0), (124.0, 40.0, True, 0.707),
                    (144.0, 60.0, True, 0.707), (164.0, 64.0, True, 1.0), (184.0, 64.0, True, 1.0)]


@pytest.mark.parametrize("solver", SOLVERS)
def test_a_fast_body_with_ccd_stops_on_a_chain_from_above_and_passes_from_below(solver) -> None:
    s = Scene(solver="soft") if solver == "soft" else Scene()
    spawn_chain(s, Chain([(4, 0), (0, 0), (-4, 0)]))
    down = s.spawn(Transform(1, 3), Velocity(0, -600), Hitbox(Circle(0.25), ccd=True))  # 10 units a step
    up = s.spawn(Transform(-1, -3), Velocity(0, 600), Hitbox(Circle(0.25), ccd=True))
    s.step(1 / 60)
    assert s.get(down, Transform).y == pytest.approx(0.25, abs=1e-2)
    assert s.get(up, Transform).y == pytest.approx(7.0)
