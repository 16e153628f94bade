"""Soak: a busy level stepped for a long time stays sound.

A closed box level of static unit tiles holds a few hundred boxes, circles and polygons: some
bouncing (restitution 0.5 to 1), some dead (restitution 0, they come to rest and sleep), a few fast
ones with continuous detection. Under gravity, stepped at 60 Hz, we check:

- no NaN or inf in the store;
- no body escapes the level: every centre stays inside the walls;
- no body sinks: penetration into any wall, floor or ceiling tile stays below a bound;
- energy is bounded: kinetic + potential never exceeds the initial total plus a small margin
  (collisions may lose energy, never make it), and never rises between two checks by more than
  1% of the initial total (a pile that has lost most of its energy could otherwise hand one body
  all the rest unseen);
- memory is flat: tracemalloc shows no growth between an early and a late step beyond a small bound.

The short version (2,000 steps) always runs. The long one (100,000 steps) is marked ``slow`` and
runs only with ``RUN_SLOW=1``::

    RUN_SLOW=1 .venv/bin/pytest tests/test_soak.py -m slow -s

(``-s`` prints its summary: steps, time, worst penetration, energy, memory growth.) Its result is
quoted, with its date, in ``docs/reliability.md``.
"""

from __future__ import annotations

import gc
import math
import os
import sys
import time
import tracemalloc

import numpy as np
import pytest

from framework import AABB, Circle, Hitbox, Polygon, Scene, Transform, Velocity

G = 10.0
DT = 1.0 / 60.0
W, H = 64, 20  # level size in tiles: tiles centred at x = 0..W-1, y = 0..H-1 on the border
LEFT, RIGHT, BOTTOM, TOP = 0.5, W - 1.5, 0.5, H - 1.5  # inner faces of the walls, floor and ceiling
PENETRATION_BOUND = 0.25  # world units; bodies are 0.3 to 0.8 across
ENERGY_MARGIN = 1e-3  # relative to the initial total (measured from the floor)
# The largest rise of the total between two checks, relative to the initial total: push-outs
# add a little potential energy; a body pumped up by the response (the step-9,215 runaway: 6% of
# the initial total in three steps, in a pile that had lost 95% of it) is far above this.
RISE_BOUND = 0.01
MEMORY_BOUND = 256 * 1024  # bytes of growth allowed between the two tracemalloc snapshots
BLOCK_BOUND = 20_000  # Python memory blocks of growth allowed between an early step and the end
RSS_BOUND = 32 * 2**20  # resident size growth allowed (bytes): coarse, the allocator keeps freed pages
# Sizes (environment variables override them): the short soak must stay well under 20 s on a busy
# 2-core machine. The long one is the "hundreds of bodies": 200 for 100,000 steps took 37
# minutes on 2026-11-24 (about 0.1 ms per body per step in a busy pile; the response measures each
# support level again); LONG_SOAK_BODIES=40 runs in about half that.
SHORT_STEPS, SHORT_BODIES = int(os.environ.get("SOAK_STEPS", 1500)), int(os.environ.get("SOAK_BODIES", 20))
LONG_STEPS, LONG_BODIES = int(os.environ.get("LONG_SOAK_STEPS", 100_000)), int(os.environ.get("LONG_SOAK_BODIES", 200))


def build_level(n_bodies: int, seed: int, restitution: bool = True,
                effects=None) -> tuple[Scene, np.ndarray, list]:
    """The level and its bodies (``effects``: the scene's, default the defaults); returns (scene,
    entity ids, local outline of each body)."""
    rng = np.random.default_rng(seed)
    s = Scene(gravity=(0.0, -G), effects=effects)
    for x in range(W):
        s.spawn(Transform(float(x), 0.0), Hitbox(AABB(1.0, 1.0), body="static"))
        s.spawn(Transform(float(x), float(H - 1)), Hitbox(AABB(1.0, 1.0), body="static"))
    for y in range(1, H - 1):
        s.spawn(Transform(0.0, float(y)), Hitbox(AABB(1.0, 1.0), body="static"))
        s.spawn(Transform(float(W - 1), float(y)), Hitbox(AABB(1.0, 1.0), body="static"))
    # Bodies on a grid of 1-unit cells, so none overlaps another at the start (an overlap at
    # spawn is pushed apart, which is energy the check would have to allow for).
    cells = [(x + 1.0, y + 1.5) for y in range(1, H - 4) for x in range(1, W - 3)]
    order = rng.permutation(len(cells))[:n_bodies]
    ents, outlines = [], []
    for k, ci in enumerate(order.tolist()):
        x, y = cells[ci]
        kind = k % 4
        size = float(rng.uniform(0.3, 0.8))
        if kind == 0:
            shape = AABB(size, float(rng.uniform(0.3, 0.8)))
        elif kind == 1:
            shape = Circle(size / 2)
        elif kind == 2:
            shape = Polygon.box(size, float(rng.uniform(0.3, 0.8)))
        else:
            shape = Polygon([(-size / 2, -size / 3), (size / 2, -size / 3), (0.0, size / 2)])
        bouncy = restitution and k % 3 != 0
        fast = k % 25 == 0
        speed = 40.0 if fast else 4.0
        angle = float(rng.uniform(0.0, 2 * math.pi))
        hb = Hitbox(shape, restitution=float(rng.uniform(0.5, 1.0)) if bouncy else 0.0, ccd=fast,
                    mass=float(rng.uniform(0.5, 2.0)))
        ents.append(s.spawn(Transform(x, y, float(rng.uniform(0, 3)) if kind >= 2 else 0.0),
                            Velocity(speed * math.cos(angle), speed * math.sin(angle)), hb))
        outlines.append(shape)
    return s, np.array(ents), outlines


class Meter:
    """Vectorised checks over the bodies, from the store's columns and each body's own shape."""

    def __init__(self, scene: Scene, ents: np.ndarray, shapes: list) -> None:
        self.scene, self.ents = scene, ents
        self.mass = np.array([scene.get(int(e), Hitbox).mass for e in ents])
        # moments of inertia (boxes and polygons turn from contacts; an AABB never does): the
        # default rule, the mass times the shape's second moment about its centre
        self.inertia = np.array([0.0 if isinstance(sh, AABB) else m * sh.second_moment
                                 for m, sh in zip(self.mass, shapes)])
        n = len(ents)
        self.kind = np.array([0 if isinstance(sh, AABB) else 1 if isinstance(sh, Circle) else 2 for sh in shapes])
        self.hw = np.array([sh.width / 2 if isinstance(sh, AABB) else sh.radius if isinstance(sh, Circle) else 0.0
                            for sh in shapes])
        self.hh = np.array([sh.height / 2 if isinstance(sh, AABB) else sh.radius if isinstance(sh, Circle) else 0.0
                            for sh in shapes])
        self.poly = np.flatnonzero(self.kind == 2)
        pts = np.zeros((n, 4, 2))
        for i in self.poly.tolist():
            p = np.asarray(shapes[i].points)
            pts[i, : len(p)] = p
            pts[i, len(p):] = p[-1]
        self.pts = pts[self.poly]

    def rows(self) -> np.ndarray:
        store = self.scene.store
        return np.array([store.row_of[int(e)] for e in self.ents])

    def measure(self) -> dict[str, float]:
        store = self.scene.store
        r = self.rows()
        x, y, rot = store.x[r], store.y[r], store.rot[r]
        vx, vy = store.vx[r], store.vy[r]
        minx, maxx, miny, maxy = x - self.hw, x + self.hw, y - self.hh, y + self.hh
        if self.poly.size:
            c, s = np.cos(rot[self.poly])[:, None], np.sin(rot[self.poly])[:, None]
            wx = c * self.pts[:, :, 0] - s * self.pts[:, :, 1]
            wy = s * self.pts[:, :, 0] + c * self.pts[:, :, 1]
            minx[self.poly] = x[self.poly] + wx.min(axis=1)
            maxx[self.poly] = x[self.poly] + wx.max(axis=1)
            miny[self.poly] = y[self.poly] + wy.min(axis=1)
            maxy[self.poly] = y[self.poly] + wy.max(axis=1)
        # Penetration into the level's flat inner faces (exact for these shapes: their lowest,
        # leftmost... points are the bounds).
        pen = np.maximum.reduce([LEFT - minx, maxx - RIGHT, BOTTOM - miny, maxy - TOP, np.zeros_like(x)])
        escaped = (x < LEFT) | (x > RIGHT) | (y < BOTTOM) | (y > TOP)
        w = store.w[r]
        energy = float(np.sum(self.mass * (0.5 * (vx * vx + vy * vy) + G * (y - BOTTOM)) + 0.5 * self.inertia * w * w))
        finite = all(bool(np.isfinite(col[: store.n]).all()) for col in store.cols.values()
                     if col.dtype.kind == "f")
        return {"penetration": float(pen.max()), "escaped": int(escaped.sum()), "energy": energy,
                "finite": finite, "asleep": int(store.asleep.sum())}


def _rss_bytes() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def soak(steps: int, n_bodies: int, seed: int = 1, check_every: int = 1, memory_from: int = 200,
         trace_from: int | None = None, trace_steps: int = 100, report=None, restitution: bool = True) -> dict:
    """Step the level ``steps`` times, checking every ``check_every`` steps; return a summary with
    the first step that broke each invariant (``None``: never broken) and the worst values seen.

    Memory: Python's allocated blocks and the process's resident size are compared between step
    ``memory_from`` and the end (cheap, whole run); tracemalloc (which slows stepping about five
    times) compares snapshots ``trace_steps`` steps apart from step ``trace_from``."""
    s, ents, shapes = build_level(n_bodies, seed, restitution)
    meter = Meter(s, ents, shapes)
    e0 = meter.measure()["energy"]
    first: dict[str, int | None] = {"nan": None, "escape": None, "penetration": None, "energy": None,
                                    "energy_rise": None}
    worst_pen, worst_energy, escaped, worst_rise, last_energy = 0.0, e0, 0, 0.0, e0
    t0 = time.perf_counter()
    blocks0 = rss0 = snap0 = None
    traced = 0
    try:
        for i in range(1, steps + 1):
            s.step(DT)
            if i == memory_from:
                gc.collect()
                blocks0, rss0 = sys.getallocatedblocks(), _rss_bytes()
            if i == trace_from:
                gc.collect()
                tracemalloc.start()
                snap0 = tracemalloc.take_snapshot()
            elif trace_from is not None and i == trace_from + trace_steps:
                gc.collect()
                snap1 = tracemalloc.take_snapshot()
                traced = sum(st.size_diff for st in snap1.compare_to(snap0, "filename"))
                tracemalloc.stop()
            if i % check_every and i != steps:
                continue
            m = meter.measure()
            broken = {"nan": not m["finite"], "escape": m["escaped"] > 0,
                      "penetration": m["penetration"] > PENETRATION_BOUND,
                      "energy": m["energy"] > e0 * (1 + ENERGY_MARGIN),
                      "energy_rise": m["energy"] - last_energy > RISE_BOUND * e0}
            worst_rise = max(worst_rise, (m["energy"] - last_energy) / e0)
            last_energy = m["energy"]
            for k, bad in broken.items():
                if bad and first[k] is None:
                    first[k] = i
            if broken["nan"]:
                break
            worst_pen = max(worst_pen, m["penetration"])
            worst_energy = max(worst_energy, m["energy"])
            escaped = max(escaped, m["escaped"])
            if report is not None and i % max(1, steps // 50) == 0:
                report(f"step {i}: {time.perf_counter() - t0:.0f} s, energy {m['energy'] / e0:.4f} of the initial "
                       f"(max {worst_energy / e0:.4f}, largest rise {worst_rise:.1e}), worst penetration "
                       f"{worst_pen:.4f}, asleep {m['asleep']}, first violations {first}")
        gc.collect()
        blocks = sys.getallocatedblocks() - blocks0 if blocks0 is not None else 0
        rss = _rss_bytes() - rss0 if rss0 is not None else 0
        last = meter.measure()
    finally:
        if tracemalloc.is_tracing():
            tracemalloc.stop()
        s.close()
    return {"steps": steps, "bodies": n_bodies, "seconds": round(time.perf_counter() - t0, 1),
            "first_violation": first, "worst_penetration": worst_pen, "most_escaped": escaped,
            "energy_max_ratio": worst_energy / e0, "energy_final_ratio": last["energy"] / e0,
            "largest_energy_rise": worst_rise,
            "asleep_final": last["asleep"], "block_growth": blocks, "rss_growth_bytes": rss,
            "traced_growth_bytes": traced}


def check(out: dict) -> None:
    """Every invariant held over the whole run; memory stayed flat."""
    assert out["first_violation"] == {"nan": None, "escape": None, "penetration": None, "energy": None,
                                      "energy_rise": None}, out
    assert out["worst_penetration"] <= PENETRATION_BOUND and out["energy_max_ratio"] <= 1 + ENERGY_MARGIN, out
    assert out["traced_growth_bytes"] <= MEMORY_BOUND, out
    assert out["block_growth"] <= BLOCK_BOUND and out["rss_growth_bytes"] <= RSS_BOUND, out


@pytest.mark.slow
def test_short_soak():
    out = soak(SHORT_STEPS, SHORT_BODIES, seed=1, memory_from=200, trace_from=600, trace_steps=100)
    check(out)
    assert out["energy_final_ratio"] < 1.0  # collisions lose energy (restitution < 1, dead bodies)


@pytest.mark.slow
@pytest.mark.skipif(os.environ.get("RUN_SLOW") != "1", reason="long soak: set RUN_SLOW=1 to run it")
def test_long_soak():
    out = soak(LONG_STEPS, LONG_BODIES, seed=2, check_every=10, memory_from=1000, trace_from=LONG_STEPS - 500,
               trace_steps=300, report=print)
    print("long soak:", out)
    check(out)


# --- what the soak found (in the response stage; open) --------------------------------------------


def _energy(s: Scene, ents) -> float:
    """The energy semi-implicit Euler keeps exactly in flight: v^2/2 + g y - g vy dt/2 per unit mass
    (see response._bounce_speed); the plain v^2/2 + g y swings by g vy dt with the sign of vy."""
    total = 0.0
    for e in ents:
        v, y = s.get(e, Velocity), s.get(e, Transform).y
        total += s.get(e, Hitbox).mass * (0.5 * (v.x ** 2 + v.y ** 2) + G * y - G * v.y * DT / 2)
    return total


def test_a_ball_bouncing_into_a_box_creates_no_energy():
    # Was: the ball, bouncing off the floor, counted as immovable support (shock propagation) for
    # the box it hit next step, which took a full reflection (40 units/s) while the ball kept 20.
    with Scene(gravity=(0.0, -G)) as s:
        s.spawn(Transform(0.0, 0.0), Hitbox(AABB(4.0, 1.0), body="static"))  # top at y = 0.5
        ball = s.spawn(Transform(0.0, 0.76), Velocity(0.0, -20.0), Hitbox(Circle(0.25), restitution=1.0))
        box = s.spawn(Transform(0.0, 1.7), Velocity(0.0, 0.0), Hitbox(AABB(1.0, 1.0), restitution=1.0))
        e0 = _energy(s, (ball, box))
        for _ in range(3):
            s.step(DT)  # the ball bounces, then hits the box and hands it its speed
            assert _energy(s, (ball, box)) <= e0 * (1 + 1e-9)
        assert s.get(box, Velocity).y > 19.0 and abs(s.get(ball, Velocity).y) < 1.0  # equal masses swap speeds


def test_a_body_hit_by_three_at_once_gains_no_energy():
    # Was: the velocity pass summed the full impulse of each of a body's contacts, all measured
    # from the same velocities: a slab hit by three falling blocks took three full bounces
    # (kinetic energy 6 -> 18). The contact solver solves the three contacts together: each pair
    # parts at the speed it met (restitution 1), momentum -6 is kept, so the slab goes on at -3 and
    # the blocks at -1, with exactly the kinetic energy there was (never more, rounding included).
    with Scene() as s:
        slab = s.spawn(Transform(0.0, 0.0), Velocity(0.0, 0.0), Hitbox(AABB(3.0, 1.0), restitution=1.0))
        blocks = [s.spawn(Transform(x, 0.9921875), Velocity(0.0, -2.0), Hitbox(AABB(0.875, 1.0), restitution=1.0))
                  for x in (-1.0, 0.0, 1.0)]
        ents = (slab, *blocks)

        def kinetic() -> float:
            return sum(0.5 * s.get(e, Hitbox).mass * (s.get(e, Velocity).x ** 2 + s.get(e, Velocity).y ** 2)
                       for e in ents)

        def momentum() -> float:
            return sum(s.get(e, Hitbox).mass * s.get(e, Velocity).y for e in ents)

        k0, p0 = kinetic(), momentum()
        s.step(1.0 / 64.0)
        # (to the solver's tolerance, 1e-9 of the speeds)
        assert kinetic() <= k0 and kinetic() == pytest.approx(k0, rel=1e-8)
        assert p0 == -6.0 and momentum() == pytest.approx(p0, abs=1e-8)
        assert s.get(slab, Velocity).y == pytest.approx(-3.0, abs=1e-8)
        assert all(s.get(b, Velocity).y == pytest.approx(-1.0, abs=1e-8) for b in blocks)


def test_a_box_bouncing_up_under_a_resting_ball_makes_no_energy():
    # Was: a box falling with a ball on it bounced off the box below, and the ball (one level up
    # the stack) then bounced off it as off a wall moving up, while the box kept its speed: the
    # long soak's runaway (a box at 80 units/s down through the floor, step 9,215 with 200
    # bodies). The contact solver solves the three contacts together: the box bounces off the base
    # (restitution 1) and carries the ball, which was falling with it, up at the same speed.
    with Scene(gravity=(0.0, -G)) as s:
        s.spawn(Transform(0.0, -0.5), Hitbox(AABB(8.0, 1.0), body="static"))  # top at y = 0
        base = s.spawn(Transform(0.0, 0.5), Velocity(0.0, 0.0), Hitbox(AABB(1.0, 1.0)))
        box = s.spawn(Transform(0.0, 1.2421875), Velocity(0.0, -4.0), Hitbox(AABB(1.0, 0.5), restitution=1.0))
        ball = s.spawn(Transform(0.0, 1.734375), Velocity(0.0, -4.0), Hitbox(Circle(0.25), restitution=1.0))
        ents = (base, box, ball)
        e0 = _energy(s, ents)
        for i in range(30):
            s.step(DT)
            if i == 0:  # the box bounced off the base, and the ball goes up with it (to the solver's tolerance)
                assert s.get(box, Velocity).y == pytest.approx(4.0, abs=1e-6)
                assert s.get(ball, Velocity).y == pytest.approx(s.get(box, Velocity).y, abs=1e-6)
                assert _energy(s, ents) <= e0
            # Allowed: the ball rides up with the box's push-out (0.086 units), potential energy
            # the response does not take back for a body lifted by another (only for one bounced
            # off something immovable). Before the fix the total reached 120 (from 51.4).
            assert _energy(s, ents) <= e0 + G * 0.09
            assert s.get(box, Transform).y >= 1.25 and s.get(ball, Transform).y >= s.get(box, Transform).y + 0.5


def test_a_bouncy_ball_comes_to_rest_and_sleeps():
    # Was: resting on the floor, it bounced by e*g*dt every step forever (no restitution threshold).
    with Scene(gravity=(0.0, -G)) as s:
        s.spawn(Transform(0.0, 0.0), Hitbox(AABB(4.0, 1.0), body="static"))
        ball = s.spawn(Transform(0.0, 1.5), Velocity(), Hitbox(Circle(0.25), restitution=0.8))
        for _ in range(1200):
            s.step(DT)
        assert s.store.asleep[s.store.row_of[ball]]


def test_a_fast_box_sliding_into_a_tiled_corner_stays_inside():
    # Was: entering the wall's lowest tile deeper (in x) than it overlapped it (in y), the tile
    # pushed the body down into the floor, which pushed it back up; the next step carried it through
    # the wall. Now the tile's bottom face, covered by the floor, is internal (internal_faces.py).
    # Found by the soak with 200 bodies: a box knocked to 47 units/s (0.78 per step, less than the
    # wall's thickness) slides along the floor out of the level at step 45.
    with Scene(gravity=(0.0, -G)) as s:
        for x in range(12):
            s.spawn(Transform(float(x), 0.0), Hitbox(AABB(1.0, 1.0), body="static"))  # floor, top at y = 0.5
        for y in range(1, 4):
            s.spawn(Transform(11.0, float(y)), Hitbox(AABB(1.0, 1.0), body="static"))  # wall, face at x = 10.5
        box = s.spawn(Transform(9.994, 0.728), Velocity(46.8, 0.0), Hitbox(AABB(0.392, 0.456)))
        for _ in range(3):
            s.step(DT)
            assert s.get(box, Transform).x <= 10.5 - 0.196 + 1e-9
