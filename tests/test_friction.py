"""Coulomb friction (issue 23, part 1): exact stops, static friction on slopes, the combining rule.

Semi-implicit Euler moves a body with the velocity the step ends with, friction included, so a
crate braked at ``a = mu g`` from ``v`` covers ``v^2 / (2 a) - v dt / 2`` (the analytic distance
less half a step of its first speed) and stops after exactly ``v / a`` seconds; with dyadic values
(v = 4, mu = 1/2, g = 8, dt = 1/64) both are exact in floating point. A body sliding down a slope
gains ``g (sin t - mu cos t) dt`` per step, to rounding; one whose friction holds it does not move.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from framework import AABB, Circle, Hitbox, Polygon, Scene, Transform, Velocity
from framework.collision import collide
from framework.effects import DEFAULT_EFFECTS
from framework.validation import InvalidValue

DT = 1.0 / 64.0
G = 8.0


def _crate_scene(mu_crate, mu_floor=None, v0=4.0, effects=None, tiles=False):
    s = Scene(gravity=(0.0, -G), effects=effects)
    if tiles:  # a floor of unit tiles: the crate crosses a seam every unit
        for i in range(-8, 40):
            s.spawn(Transform(i + 0.5, -0.5), Hitbox(AABB(1.0, 1.0), body="static", friction=mu_floor))
    else:
        s.spawn(Transform(0.0, -0.5), Hitbox(AABB(1000.0, 1.0), body="static", friction=mu_floor))
    crate = s.spawn(Transform(0.0, 0.5), Velocity(v0, 0.0), Hitbox(AABB(1.0, 1.0), friction=mu_crate))
    return s, crate


def _slide(s, crate, steps):
    """Step ``steps`` times; the step on which the crate first stood still (or None)."""
    stop = None
    for k in range(steps):
        s.step(DT)
        if stop is None and s.get(crate, Velocity).x == 0.0:
            stop = k + 1
    return stop


@pytest.mark.parametrize("mu_floor", [None, 0.5], ids=["floor-without-material", "floor-also-0.5"])
def test_a_pushed_crate_stops_after_v2_over_2_mu_g(mu_floor):
    s, crate = _crate_scene(0.5, mu_floor)
    with s:
        stop = _slide(s, crate, 100)
        t = s.get(crate, Transform)
        # v / (mu g) = 1 s = 64 steps; v^2 / (2 mu g) - v dt / 2 = 2 - 1/32
        assert stop == 64
        assert (t.x, t.y) == (2.0 - 1.0 / 32.0, 0.5)
        assert (s.get(crate, Velocity).x, s.get(crate, Velocity).y) == (0.0, 0.0)


def test_a_crate_crosses_tile_seams_as_it_crosses_one_floor():
    # Friction never catches on the seams between tiles, nor pushes the crate into them.
    s, crate = _crate_scene(0.5, tiles=True)
    with s:
        assert _slide(s, crate, 100) == 64
        t = s.get(crate, Transform)
        assert (t.x, t.y) == (2.0 - 1.0 / 32.0, 0.5)


def test_without_the_friction_effect_or_a_coefficient_the_crate_slides_on():
    for s, crate in (_crate_scene(0.5, effects=DEFAULT_EFFECTS - {"friction"}), _crate_scene(None),
                     _crate_scene(0.0, 0.5)):  # sqrt(0 * 0.5) = 0
        with s:
            _slide(s, crate, 64)
            assert s.get(crate, Velocity).x == 4.0 and s.get(crate, Transform).x == 4.0


def test_friction_coefficients_combine_as_documented():
    with Scene() as s:
        pairs = [(0.5, None, 0.5), (None, 0.5, 0.5), (0.25, 1.0, 0.5), (None, None, 0.0), (0.0, 2.0, 0.0),
                 (2.0, 0.5, 1.0)]
        rows = []
        for fa, fb, _ in pairs:
            a = s.spawn(Transform(0.0, 0.0), Hitbox(AABB(1.0, 1.0), friction=fa))
            b = s.spawn(Transform(0.0, 0.0), Hitbox(AABB(1.0, 1.0), friction=fb))
            rows.append((s.bodies.store.row_of[a], s.bodies.store.row_of[b]))
        ra, rb = (np.array(r) for r in zip(*rows))
        assert s.bodies.store.pair_friction(ra, rb).tolist() == [m for _, _, m in pairs]


# --- slopes ------------------------------------------------------------------------------------
# A slope rising 3 in 4 (tan t = 3/4, sin t = 3/5, cos t = 4/5) through the origin, g = 10.

SIN, COS = 0.6, 0.8


def _on_slope(mu, shape, sin=SIN, cos=COS):
    """A box, a circle that may not turn (``inertia=inf``: it slides as a box does) or a disk
    (``"disk"``: it rolls) resting on a slope (rising to the right at the angle of ``sin, cos``)
    at the origin."""
    s = Scene(gravity=(0.0, -10.0))
    L = 40.0
    s.spawn(Transform(0.0, 0.0), Hitbox(Polygon([(-L * cos, -L * sin), (L * cos, L * sin), (L * cos, -L * sin)]),
                                        body="static"))
    if shape == "box":  # its lower right corner on the slope at the origin
        body = s.spawn(Transform(-0.5, 0.5), Velocity(), Hitbox(AABB(1.0, 1.0), friction=mu))
    else:  # touching the slope at the origin
        inertia = math.inf if shape == "circle" else None
        body = s.spawn(Transform(-0.5 * sin, 0.5 * cos), Velocity(),
                       Hitbox(Circle(0.5), friction=mu, inertia=inertia))
    return s, body


def _slope_run(mu, shape, steps, sin=SIN, cos=COS):
    """:func:`_on_slope` stepped ``steps`` times at 1/60 s: the body's speed down the slope, how
    far it moved, and its angular velocity."""
    s, body = _on_slope(mu, shape, sin, cos)
    with s:
        t0 = s.get(body, Transform)
        x0, y0 = t0.x, t0.y
        for _ in range(steps):
            s.step(1.0 / 60.0)
        t, v = s.get(body, Transform), s.get(body, Velocity)
        return -(v.x * cos + v.y * sin), math.hypot(t.x - x0, t.y - y0), v.angular


@pytest.mark.parametrize("shape", ["box", "circle"])
@pytest.mark.parametrize("mu", [0.76, 0.8, 1.5])
def test_static_friction_holds_a_body_on_a_slope_without_creeping(shape, mu):
    s, body = _on_slope(mu, shape)
    with s:
        start = s.get(body, Transform)
        x0, y0 = start.x, start.y
        for _ in range(5 * 60):
            s.step(1.0 / 60.0)
        t, v = s.get(body, Transform), s.get(body, Velocity)
        assert math.hypot(t.x - x0, t.y - y0) < 1e-12  # rounding, not creep (5 s would show 1e-3/s)
        assert math.hypot(v.x, v.y) < 1e-12


@pytest.mark.parametrize("shape", ["box", "circle"])
@pytest.mark.parametrize("mu", [0.0, 0.25, 0.7])
def test_a_body_slides_down_a_slope_at_g_sin_minus_mu_g_cos(shape, mu):
    s, body = _on_slope(mu, shape)
    with s:
        n = 120
        for _ in range(n):
            s.step(1.0 / 60.0)
        v = s.get(body, Velocity)
        a = 10.0 * (SIN - mu * COS)
        along = -(v.x * COS + v.y * SIN)  # down the slope
        across = -v.x * SIN + v.y * COS
        assert along == pytest.approx(a * n / 60.0, rel=1e-9)
        assert abs(across) < 1e-9 * a * n / 60.0 + 1e-12
        # and it is on the slope, not in it (touching to the solver's tolerance)
        floor = s.query_point(0.0, -1.0)  # the slope's entity
        c = collide(s.get(floor[0], Hitbox).shape, s.get(floor[0], Transform), s.get(body, Hitbox).shape,
                    s.get(body, Transform))
        assert c is None or c.depth < 1e-9


# --- between moving bodies ------------------------------------------------------------------------


def test_a_box_sliding_on_a_box_drags_it_and_momentum_is_kept():
    # The lower box stands on a frictionless floor (its floor gives 0: sqrt(0 * 0.5) = 0), the upper
    # one slides on it at 4: each is braked (or driven) at mu g = 4, so after 1/2 s both move at 2.
    with Scene(gravity=(0.0, -G)) as s:
        s.spawn(Transform(0.0, -0.5), Hitbox(AABB(1000.0, 1.0), body="static", friction=0.0))
        low = s.spawn(Transform(0.0, 0.5), Velocity(), Hitbox(AABB(4.0, 1.0), friction=0.5))
        top = s.spawn(Transform(0.0, 1.5), Velocity(4.0, 0.0), Hitbox(AABB(1.0, 1.0), friction=0.5))
        for k in range(64):
            s.step(DT)
            vl, vt = s.get(low, Velocity).x, s.get(top, Velocity).x
            assert vl + vt == 4.0  # momentum, exactly
            if k + 1 == 32:
                assert (vl, vt) == (2.0, 2.0)
        assert (s.get(low, Velocity).x, s.get(top, Velocity).x) == (2.0, 2.0)
        assert (s.get(low, Transform).y, s.get(top, Transform).y) == (0.5, 1.5)


def test_a_kinematic_platform_carries_a_box_with_friction():
    with Scene(gravity=(0.0, -G)) as s:
        plat = s.spawn(Transform(0.0, -0.5), Velocity(2.0, 0.0), Hitbox(AABB(8.0, 1.0), body="kinematic"))
        box = s.spawn(Transform(0.0, 0.5), Velocity(), Hitbox(AABB(1.0, 1.0), friction=1.0))
        for _ in range(64):
            s.step(DT)
        assert s.get(box, Velocity).x == 2.0  # taken up within the first steps (mu g = 8: 2 units/s in 16 steps)
        # and it rides: no slip once it moves with the platform
        gap = s.get(box, Transform).x - s.get(plat, Transform).x
        for _ in range(64):
            s.step(DT)
        assert s.get(box, Transform).x - s.get(plat, Transform).x == gap
        assert s.get(box, Transform).y == 0.5


@pytest.mark.slow
def test_friction_makes_no_energy_in_a_closed_box_of_bodies():
    # Boxes and balls thrown about a closed room with friction everywhere: the total energy
    # (kinetic, of rolling too, + potential) never rises above its start (rounding: 1e-9 of it).
    rng = np.random.default_rng(7)
    with Scene(gravity=(0.0, -10.0)) as s:
        walls = ((5.0, -0.5, 12.0, 1.0), (5.0, 10.5, 12.0, 1.0), (-0.5, 5.0, 1.0, 12.0), (10.5, 5.0, 1.0, 12.0))
        for x, y, w, h in walls:
            s.spawn(Transform(x, y), Hitbox(AABB(w, h), body="static", friction=0.6))
        bodies = []
        for i in range(30):
            x, y = 1.0 + (i % 6) * 1.5, 1.0 + (i // 6) * 1.5
            shape = AABB(0.8, 0.8) if i % 2 else Circle(0.4)
            vx, vy = rng.uniform(-6.0, 6.0, 2)
            mu = float(rng.uniform(0.1, 1.0))
            bodies.append(s.spawn(Transform(x, y), Velocity(vx, vy), Hitbox(shape, friction=mu)))

        def energy():  # mass 1; the balls roll: I = r^2 / 2
            total = 0.0
            for e in bodies:
                v, inertia = s.get(e, Velocity), 0.08 if isinstance(s.get(e, Hitbox).shape, Circle) else 0.0
                total += 0.5 * (v.x ** 2 + v.y ** 2 + inertia * v.angular ** 2) + 10.0 * s.get(e, Transform).y
            return total

        e0 = energy()
        for _ in range(600):
            s.step(1.0 / 60.0)
            assert energy() <= e0 + 1e-9 * abs(e0)
        for e in bodies:  # all inside the room
            t = s.get(e, Transform)
            assert 0.0 < t.x < 10.0 and 0.0 < t.y < 10.0


# --- bad input ------------------------------------------------------------------------------------


@pytest.mark.parametrize("bad", [-0.5, math.nan, math.inf, "rough", True])
def test_bad_friction_is_refused(bad):
    with pytest.raises(InvalidValue, match="friction"):
        Hitbox(AABB(1.0, 1.0), friction=bad)


def test_a_bad_friction_written_later_is_refused_and_the_scene_is_unchanged():
    s, crate = _crate_scene(0.5)
    with s:
        s.step(DT)
        before = (s.get(crate, Transform).x, s.get(crate, Velocity).x)
        s.get(crate, Hitbox).friction = -1.0
        with pytest.raises(InvalidValue, match="friction"):
            s.step(DT)
        assert (s.get(crate, Transform).x, s.get(crate, Velocity).x) == before
        s.get(crate, Hitbox).friction = 0.5
        s.step(DT)
        assert s.get(crate, Velocity).x == 4.0 - 2 * 0.5 * G * DT


# --- rolling -------------------------------------------------------------------------------------------
# A solid disk (I = m r^2 / 2) rolls without slipping where mu >= tan(t) / 3 (here 1/4), at
# (2/3) g sin t with w = v / r; below, it slips: v' = g (sin t - mu cos t), w' = 2 mu g cos t / r.


@pytest.mark.parametrize("mu", [0.25, 0.5, 1.0])
def test_a_disk_rolls_down_a_slope_at_two_thirds_g_sin(mu):
    n = 120
    along, _, w = _slope_run(mu, "disk", n)
    assert along == pytest.approx(2.0 / 3.0 * 10.0 * SIN * n / 60.0, rel=1e-9)  # 8
    assert w == pytest.approx(along / 0.5, rel=1e-9)  # rolling: w = v / r (counter-clockwise)


def test_a_disk_on_a_slippery_slope_slips_and_spins_up_at_its_friction():
    n = 120
    along, _, w = _slope_run(0.1, "disk", n)
    assert along == pytest.approx(10.0 * (SIN - 0.1 * COS) * n / 60.0, rel=1e-9)  # 10.4
    assert w == pytest.approx(2.0 * 0.1 * 10.0 * COS / 0.5 * n / 60.0, rel=1e-9)  # 6.4


def test_a_disk_thrown_without_spin_ends_rolling_at_two_thirds_of_its_speed():
    # v0 = 3 on a flat floor, mu g = 4: it slows at 4 and spins up (w r) at 8; the slip 3 - 12 t
    # ends at t = 1/4 (16 steps of 1/64), at v = w r = 2 = (2/3) v0, exactly; it rolls on at 2.
    with Scene(gravity=(0.0, -G)) as s:
        s.spawn(Transform(0.0, -0.5), Hitbox(AABB(1000.0, 1.0), body="static"))
        disk = s.spawn(Transform(0.0, 0.5), Velocity(3.0, 0.0), Hitbox(Circle(0.5), friction=0.5))
        for k in range(64):
            s.step(DT)
            v = s.get(disk, Velocity)
            if k + 1 < 16:
                assert v.x > 2.0 and v.x + 0.5 * v.angular > 0.0  # slipping
            else:
                assert (v.x, v.angular, v.y) == (2.0, -4.0, 0.0)
        assert s.get(disk, Transform).y == 0.5


def test_inertia_may_be_given_and_infinite_inertia_never_turns():
    # A ring (I = m r^2): rolls at g sin t / 2 = 3 (slope 3-4-5, g 10); inertia inf: slides.
    s, _ = _on_slope(0.5, "disk")
    with s:
        ring = s.spawn(Transform(-10.0 * COS - 0.5 * SIN, -10.0 * SIN + 0.5 * COS), Velocity(),
                       Hitbox(Circle(0.5), friction=0.5, inertia=0.25))
        for _ in range(60):
            s.step(1.0 / 60.0)
        v = s.get(ring, Velocity)
        assert -(v.x * COS + v.y * SIN) == pytest.approx(3.0, rel=1e-9)
    s, circle = _on_slope(0.0, "circle")
    with s:
        for _ in range(60):
            s.step(1.0 / 60.0)
        assert s.get(circle, Velocity).angular == 0.0 and s.get(circle, Transform).rotation == 0.0


def test_without_the_rotation_effect_a_disk_slides():
    with Scene(gravity=(0.0, -G), effects=DEFAULT_EFFECTS - {"rotation"}) as s:
        s.spawn(Transform(0.0, -0.5), Hitbox(AABB(1000.0, 1.0), body="static"))
        disk = s.spawn(Transform(0.0, 0.5), Velocity(3.0, 0.0), Hitbox(Circle(0.5), friction=0.5))
        for _ in range(64):
            s.step(DT)
        assert (s.get(disk, Velocity).x, s.get(disk, Velocity).angular) == (0.0, 0.0)  # stopped at 3 / 4 s


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, "heavy", False])
def test_bad_inertia_is_refused(bad):
    with pytest.raises(InvalidValue, match="inertia"):
        Hitbox(Circle(1.0), inertia=bad)


def test_a_bad_inertia_written_later_names_the_entity_and_changes_nothing():
    with Scene(gravity=(0.0, -G)) as s:
        s.spawn(Transform(0.0, -0.5), Hitbox(AABB(1000.0, 1.0), body="static"))
        disk = s.spawn(Transform(0.0, 0.5), Velocity(3.0, 0.0), Hitbox(Circle(0.5), friction=0.5))
        s.step(DT)
        before = (s.get(disk, Transform).x, s.get(disk, Velocity).x, s.get(disk, Velocity).angular)
        s.get(disk, Hitbox).inertia = math.nan
        with pytest.raises(InvalidValue, match=f"entity {disk}: Hitbox inertia"):
            s.step(DT)
        assert (s.get(disk, Transform).x, s.get(disk, Velocity).x, s.get(disk, Velocity).angular) == before


# --- mass from density ------------------------------------------------------------------------------


def test_density_gives_mass_and_inertia_from_the_shape():
    assert Hitbox(AABB(2.0, 4.0), density=0.25).mass == 2.0
    assert Hitbox(Polygon.box(2.0, 4.0), density=0.25).mass == 2.0
    assert Hitbox(Circle(2.0), density=0.25).mass == pytest.approx(math.pi)
    assert Hitbox(AABB(2.0, 4.0)).mass == 1.0 and Hitbox(AABB(2.0, 4.0), mass=3.0).mass == 3.0
    with Scene() as s:  # a disk of density 2 / pi and radius 1/2: mass 1/2, inertia m r^2 / 2 = 1/16
        e = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(Circle(0.5), density=2.0 / math.pi))
        row = s.bodies.store.row_of[e]
        assert s.bodies.store.inv_mass[row] == pytest.approx(2.0)
        assert s.bodies.store.inv_inertia[row] == pytest.approx(16.0)


def test_densities_split_a_push_by_mass():
    # A 2 x 2 box of density 1 (mass 4) and a unit box of density 1 (mass 1) overlapping by 1/2:
    # the small one takes 4/5 of the push, the big one 1/5.
    with Scene(gravity=(0.0, 0.0)) as s:
        big = s.spawn(Transform(0.0, 0.0), Velocity(), Hitbox(AABB(2.0, 2.0), density=1.0))
        small = s.spawn(Transform(1.0, 0.0), Velocity(), Hitbox(AABB(1.0, 1.0), density=1.0))
        s.step(1 / 64)
        assert s.get(big, Transform).x == pytest.approx(-0.1) and s.get(small, Transform).x == pytest.approx(1.4)


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, math.inf, "dense"])
def test_bad_density_is_refused(bad):
    with pytest.raises(InvalidValue, match="density"):
        Hitbox(AABB(1.0, 1.0), density=bad)


def test_mass_and_density_together_are_refused_and_a_later_edit_names_the_entity():
    with pytest.raises(InvalidValue, match="mass and density"):
        Hitbox(AABB(1.0, 1.0), mass=2.0, density=1.0)
    with Scene(gravity=(0.0, 0.0)) as s:
        e = s.spawn(Transform(0.0, 0.0), Velocity(1.0, 0.0), Hitbox(AABB(1.0, 1.0), density=1.0))
        s.step(DT)
        x = s.get(e, Transform).x
        s.get(e, Hitbox).mass = 3.0
        with pytest.raises(InvalidValue, match=f"entity {e}: Hitbox mass and density"):
            s.step(DT)
        assert s.get(e, Transform).x == x
        s.get(e, Hitbox).density = -1.0
        s.get(e, Hitbox).mass = 1.0
        with pytest.raises(InvalidValue, match=f"entity {e}: Hitbox density"):
            s.step(DT)


# --- any slope, any friction (hypothesis) --------------------------------------------------------------


@pytest.mark.slow
@settings(max_examples=40, deadline=None, derandomize=True)
@given(theta=st.floats(math.radians(5.0), math.radians(60.0)), ratio=st.floats(0.0, 2.0))
def test_a_box_on_any_slope_holds_or_slides_as_coulomb_says(theta, ratio):
    # mu = ratio * tan(theta): holds (exactly, no creep) above 1, slides at g (sin - mu cos) below.
    assume(abs(ratio - 1.0) > 0.02)
    mu = ratio * math.tan(theta)
    speed, moved, _ = _slope_run(mu, "box", 60, math.sin(theta), math.cos(theta))
    if ratio > 1.0:
        assert moved < 1e-12 and abs(speed) < 1e-12
    else:
        expected = 10.0 * (math.sin(theta) - mu * math.cos(theta))
        assert speed == pytest.approx(expected, rel=1e-9, abs=1e-12)


@pytest.mark.slow
@settings(max_examples=40, deadline=None, derandomize=True)
@given(theta=st.floats(math.radians(5.0), math.radians(60.0)), ratio=st.floats(0.0, 3.0))
def test_a_disk_on_any_slope_rolls_or_slips_as_coulomb_says(theta, ratio):
    # A solid disk rolls (w = v / r, v' = (2/3) g sin) where mu >= tan / 3, else slips.
    assume(abs(ratio - 1.0) > 0.02)
    mu = ratio * math.tan(theta) / 3.0
    speed, _, w = _slope_run(mu, "disk", 60, math.sin(theta), math.cos(theta))
    if ratio > 1.0:
        assert speed == pytest.approx(10.0 * math.sin(theta) * 2.0 / 3.0, rel=1e-9)
        assert w == pytest.approx(speed / 0.5, rel=1e-9)
    else:
        assert speed == pytest.approx(10.0 * (math.sin(theta) - mu * math.cos(theta)), rel=1e-9)
        assert w == pytest.approx(2.0 * mu * 10.0 * math.cos(theta) / 0.5, rel=1e-9, abs=1e-12)


@pytest.mark.slow
@settings(max_examples=25, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(2, 8), gravity=st.sampled_from([0.0, 10.0]))
def test_friction_never_adds_energy_to_random_bodies(seed, n, gravity):
    # Boxes and disks of random sizes, masses, frictions and velocities in a closed room with
    # friction on its walls: the mechanical energy (m v^2 / 2 + m g y, plus I w^2 / 2 for the
    # rolling disks) never rises above where it started (rounding: 1e-9 of it). Step to step it may
    # rise by a hair: semi-implicit Euler's energy in flight swings by g vy dt / 2, and a body
    # friction stops on a slope keeps the last swing; the scene as a whole never gains.
    rng = np.random.default_rng(seed)
    dt = 1.0 / 60.0
    with Scene(gravity=(0.0, -gravity)) as s:
        walls = ((4.0, -0.5, 10.0, 1.0), (4.0, 8.5, 10.0, 1.0), (-0.5, 4.0, 1.0, 10.0), (8.5, 4.0, 1.0, 10.0))
        for x, y, w, h in walls:
            s.spawn(Transform(x, y), Hitbox(AABB(w, h), body="static", friction=float(rng.uniform(0.0, 1.0))))
        bodies = []
        for k in range(n):
            size = float(rng.uniform(0.4, 1.2))
            shape = AABB(size, float(rng.uniform(0.4, 1.2))) if k % 2 else Circle(size / 2)
            hb = Hitbox(shape, mass=float(rng.uniform(0.5, 3.0)), friction=float(rng.uniform(0.0, 1.5)))
            x, y = 1.0 + (k % 4) * 1.8, 1.0 + (k // 4) * 2.0
            bodies.append(s.spawn(Transform(x, y), Velocity(*(float(v) for v in rng.uniform(-5.0, 5.0, 2))), hb))

        def energy() -> float:
            total = 0.0
            for e in bodies:
                hb, v, t = s.get(e, Hitbox), s.get(e, Velocity), s.get(e, Transform)
                inertia = 0.5 * hb.mass * hb.shape.radius ** 2 if isinstance(hb.shape, Circle) else 0.0
                total += hb.mass * (0.5 * (v.x ** 2 + v.y ** 2) + gravity * t.y) + 0.5 * inertia * v.angular ** 2
            return total

        start = energy()
        for _ in range(240):
            s.step(dt)
            assert energy() <= start * (1.0 + 1e-9), (energy(), start)
