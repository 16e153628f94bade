"""``python -m framework.bench accuracy``: what the accuracy knobs buy, against exact answers.

Scenarios (each has an exact reference, so every error is measured, not judged by eye):

- **bullet**: a small circle shot at a thin static wall, at a range of speeds, in many lanes. The
  analytic time of impact is known (the bullet's leading edge reaches the wall's face), so every
  bullet must be stopped at the face. ``missed``: fraction that ended beyond the wall (tunnelled,
  or detected too deep and pushed out the far side); ``undetected``: fraction that never produced
  a contact event; ``stop_error``: the largest distance of a stopped bullet from the analytic
  contact position. Modes ``discrete``, ``swept`` (``Hitbox(ccd=True)``) and ``substeps-N``.
- **crate**: pairs of rotated rectangular crates at random placements, approximated by ``aabb``
  (the crate's unrotated box: an AABB never turns), ``aabb-bounds`` (the box around the rotated
  crate), ``circle`` (same area) or ``polygon`` (``Polygon.box``, rotating) hitboxes. The exact
  answer is the rotated rectangles' interiors overlapping (separating axes, checked against shapely
  in the tests). ``fp_rate``: contacts reported where the crates do not touch, over the pairs that
  do not; ``fn_rate``: contacts missed, over the pairs that do.
- **stack**, **character**, **character-walk**: a resting stack of unit boxes on a static ground;
  a character box standing on a floor of unit tiles across a seam; the same character walking
  along the tiles. Exact answer: at rest on the surface, no penetration, no motion.
  ``max_depth``: the largest penetration after a step (measured with ``collide``) over the second
  half of the run; ``jitter``: the largest standard deviation of a body's y over that half;
  ``sink``: the largest mean distance below the exact resting height; ``snags``: steps in which the
  walking character advanced less than half its commanded distance. Modes
  ``response-iterations-N`` (one step each) and ``substeps-N`` (4 iterations each), plus
  ``default-sleeping`` (the default effects, with sleeping: what a game gets).
- **crowd**: 64 unit boxes dropped overlapping into a small square, no gravity; after one step,
  ``max_depth`` (deepest overlap left) and ``residual`` (summed depth left over summed depth
  before). Exact answer: nothing left. Dynamic bodies in several contacts with each other are what
  ``response_iterations`` is for. Modes as for the stack.
- **ball**: a ball with restitution 1 bouncing on a static floor under gravity. Exact answer: its
  energy is conserved. ``energy_drift``: the least-squares slope of the energy over 1,000 steps,
  relative to the initial energy; ``apex_drop``: how much lower than its start the last apex was,
  relative. Modes ``substeps-N``.
- **friction**: gravity 10, friction as a game maker would set it, against the analytic answers.
  ``crate-stop``: a crate at 5 units/s on a floor, mu 0.5, stops after ``v^2 / (2 mu g) = 2.5``;
  ``slope-hold``: a box on a 30 degree slope with mu 0.7 (> tan 30) must not move in 5 s;
  ``slope-slide``: with mu 0.3 it slides at ``g (sin - mu cos)``; ``disk-roll``: a solid disk on
  that slope with mu 0.5 rolls at ``(2/3) g sin``; ``disk-slip``: with mu 0.1 (< tan 30 / 3) it
  slips at ``g (sin - mu cos)``; ``box-tip``: a unit box (``Polygon.box``, mu 0.5) dropped from
  1 unit tilted by 0.3 rad tips flat and rests at half its height, 0.5 (contacts at the two points
  of the face it lands on); ``box-tip-one-point``: the same without the ``rotation`` effect, one
  contact point per pair through the centres, as before boxes could tip (it stays on its corner).
  ``measured`` / ``expected``: the stop distance, the distance moved, the acceleration (speed after
  2 s over 2 s) or the resting height after 3 s; ``rel_error``: their relative difference
  (``slope-hold``: the distance itself). Modes ``substeps-N``.

- **controller**: the character controller (``framework.character``) on unit tiles built by
  ``framework.tiles.terrain_pieces``: a 0.75 x 0.875 character walking at 6 units/s (gravity 20).
  ``slope-45-up`` / ``-down`` and ``slope-2:1-up`` / ``-down``: over flat ground, a slope four
  tiles high and flat ground again; exact answer: the feet on the surface every step, the x advance
  every step exactly the commanded 0.1. ``gap_max`` / ``gap_min``: the largest and the smallest
  distance of the feet above the surface under them (the highest ground below the feet's width)
  over the walk; ``speed_error``: the largest difference of a step's x advance from 0.1.
  ``step-up``: a step of a quarter tile in the way (``step_height`` 0.3); ``measured``: steps
  taken to reach x = 10 from x = 2, ``expected``: at constant speed (80). ``ride-reverse``: standing
  on a platform that turns back every 20 steps and up and down every 15 (``measured``: the largest
  drift of the character from where it stood on it). Modes ``substeps-N``.
- **joints** (the soft solver: the exact one refuses joints): ``pendulum-distance``: a ball of
  radius 0.05 on a rod (``DistanceJoint`` to the world) 1 long, let go 0.05 rad from the
  vertical; exact period ``2 pi sqrt(L / g) / AGM(1, cos(a / 2))`` (the finite amplitude's, 1.6e-4
  above the small-angle ``2 pi sqrt(L / g)``); ``pendulum-revolute``: the ball hinged to the world
  (``RevoluteJoint``) turns with the rod, a physical pendulum of length ``L + r^2 / (2 L)``.
  ``measured``: the period from the zero crossings (least squares over the run's, 10 periods;
  quick 4); ``max_stretch``: the rod's largest change of length, over L; ``apex_drop``: how much
  less than 0.05 rad the last period's widest swing was, relative (sampled once a step: to about
  1e-3). ``rope-20-hanging``: 20 links (0.25 x 0.05, mass 1) hinged end to end, hanging at rest
  from a hinge to the world; ``rope-20-swinging``: laid out level, falling and swinging.
  ``measured``: the rope's length along its links (the links' plus every hinge's gap), the mean
  over the second half of the run (600 steps; quick 240); ``rel_error``: that stretch over the
  rope's 5; ``max_stretch``: the largest over the run. Modes ``soft`` and ``soft-substeps-N``
  (the scene's ``substeps``: N soft steps, of the solver's own 4 sub-steps each, a step).

- **mass** (the centre of mass, issue 38): a box 1 x 0.5 whose centre is 1 from its hitbox origin
  (``Polygon`` points (0.5, -0.25) to (1.5, 0.25)), mass 1. ``offset-spin``: spinning at one turn a
  second, no gravity, for 2 s; exact answer: its centre of mass stays where it is.
  ``offset-throw``: thrown at (3, 6) spinning as fast, gravity 20, for 1 s; exact answer: its
  centre of mass moves as a twin's that does not spin (the same box centred on its origin, thrown
  alike in the same scene: the integrator's own error, the same for both, is left out).
  ``measured``: the largest distance of the centre of mass from the exact answer over the run;
  ``rel_error``: that over the offset (1). The soft solver
  turns a body about its centre of mass, as Box2D and pymunk do; the exact solver turns it about
  its hitbox origin (documented in docs/physics.md), so there the centre swings round the origin.
  Modes ``substeps-1`` (the exact solver's default) and ``soft``.

Sleeping is off in every scene (except ``default-sleeping``) so the solver is measured, not the
sleep. ``ms_per_step``: median over the steps of every repeated run, timed in the same process
(the scene's whole step, for the scenario's scene). All scenes use ``dt = 1/60`` s, gravity
(0, -20) units/s^2 where there is gravity.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from functools import partial
from typing import TYPE_CHECKING, Any

import numpy as np

from ..arrays import BoolArray, F64Array
from ..collision import collide
from ..components import Hitbox, Transform, Velocity
from ..shapes import AABB, Circle, Polygon
from .progress import Progress
from .report import Column, format_table, frozen_gc, machine_info, median

if TYPE_CHECKING:
    from ..scene import Scene

__all__ = [
    "BULLET_MODES", "CONTROLLER_CASES", "CONTROLLER_MODES", "CRATE_MODES", "REST_MODES", "BALL_MODES",
    "FRICTION_CASES", "FRICTION_MODES", "JOINT_CASES", "JOINT_MODES", "MASS_CASES", "MASS_MODES", "ROW_KEYS",
    "analytic_bullet_toi", "bullet_lanes", "crate_placements", "crates_overlap_exact", "markdown", "run_accuracy",
    "pendulum_period", "run_ball", "run_bullets", "run_controller", "run_crates", "run_friction", "run_joint",
    "run_mass",
    "run_rest", "text_report",
]

DT = 1.0 / 60.0
GRAVITY = (0.0, -20.0)

WALL_THICKNESS = 0.25
WALL_HEIGHT = 4.0
BULLET_RADIUS = 0.125
LANE_SPACING = 8.0
#: bullet speeds in units per step (x 60 for units per second)
SPEEDS = (0.125, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 64.0)
BULLET_MODES = ("discrete", "swept", "substeps-2", "substeps-4", "substeps-8", "soft")
CRATE_MODES = ("aabb", "aabb-bounds", "circle", "polygon")
REST_MODES = ("response-iterations-1", "response-iterations-2", "response-iterations-4",
              "response-iterations-8", "substeps-2", "substeps-4", "substeps-8", "soft", "default-sleeping")
BALL_MODES = ("substeps-1", "substeps-2", "substeps-4", "substeps-8", "soft")
FRICTION_MODES = ("substeps-1", "substeps-2", "substeps-4", "soft")
FRICTION_CASES = ("crate-stop", "slope-hold", "slope-slide", "disk-roll", "disk-slip", "box-tip", "box-tip-one-point")
CONTROLLER_CASES = ("slope-45-up", "slope-45-down", "slope-2:1-up", "slope-2:1-down", "step-up", "ride-reverse")
CONTROLLER_MODES = ("substeps-1", "substeps-4")
JOINT_CASES = ("pendulum-distance", "pendulum-revolute", "rope-20-hanging", "rope-20-swinging")
JOINT_MODES = ("soft", "soft-substeps-2", "soft-substeps-4")  # (the exact solver refuses joints)
MASS_CASES = ("offset-spin", "offset-throw")
MASS_MODES = ("substeps-1", "soft")
SCENARIOS = ("bullet", "crate", "stack", "character", "character-walk", "crowd", "ball", "friction", "controller",
             "joints", "mass")
DEFAULT_MODES = {"discrete", "response-iterations-4", "substeps-1", "default-sleeping"}

FULL: dict[str, Any] = {"lanes": 128, "crates": 10_000, "rest_steps": 600, "ball_steps": 1_000, "runs": 3,
                        "crate_steps": 10, "crowds": 15, "pendulum_periods": 10, "rope_steps": 600}
QUICK: dict[str, Any] = {"lanes": 32, "crates": 2_000, "rest_steps": 240, "ball_steps": 1_000, "runs": 1,
                         "crate_steps": 3, "crowds": 5, "pendulum_periods": 4, "rope_steps": 240}
CROWD_MODES = REST_MODES[:-1]
CROWD_BOXES = 64

ROW_KEYS = ["scenario", "mode", "speed", "ms_per_step", "missed", "undetected", "stop_error", "fp_rate", "fn_rate",
            "max_depth", "jitter", "sink", "snags", "residual", "energy_drift", "apex_drop", "case", "measured",
            "expected", "rel_error", "samples", "steps", "gap_max", "gap_min", "speed_error", "max_stretch"]


def _row(scenario: str, mode: str, **values: Any) -> dict[str, Any]:
    row: dict[str, Any] = {k: None for k in ROW_KEYS}
    row.update(scenario=scenario, mode=mode, **values)
    return row


def _scene_for(mode: str, gravity=(0.0, 0.0), effects=None):
    """A scene configured by a mode name: ``substeps-N``, ``response-iterations-N``, ``soft`` (the
    soft-step solver), ``soft-substeps-N`` (it, N pipeline steps a step), else defaults. Sleeping
    is off unless the mode is ``default-sleeping``."""
    from ..scene import DEFAULT_EFFECTS, Scene

    kw: dict[str, Any] = {}
    if mode == "soft":
        kw["solver"] = "soft"
    elif mode.startswith("soft-substeps-"):
        kw["solver"], kw["substeps"] = "soft", int(mode.rsplit("-", 1)[1])
    elif mode.startswith("substeps-"):
        kw["substeps"] = int(mode.rsplit("-", 1)[1])
    elif mode.startswith("response-iterations-"):
        kw["response_iterations"] = int(mode.rsplit("-", 1)[1])
    if effects is None:
        effects = DEFAULT_EFFECTS if mode == "default-sleeping" else DEFAULT_EFFECTS - {"sleeping"}
    return Scene(gravity=gravity, effects=effects, **kw)


def _timed_steps(scene, steps: int, before: Callable[[int], None] | None = None,
                 after: Callable[[int], None] | None = None) -> list[float]:
    """Step ``steps`` times; return each step's milliseconds (the callbacks are not timed)."""
    out = []
    with frozen_gc():
        for k in range(steps):
            if before is not None:
                before(k)
            t0 = time.perf_counter()
            scene.step(DT)
            out.append((time.perf_counter() - t0) * 1e3)
            if after is not None:
                after(k)
    return out


# --- bullets ------------------------------------------------------------------------------------------


def analytic_bullet_toi(x0: float, speed: float) -> float:
    """Steps until a bullet centred at ``x0`` moving at ``speed`` units per step along +x first
    touches the wall (centred at x = 0): its leading edge ``x0 + r + speed * t`` meets the face
    ``-thickness / 2``."""
    return (-WALL_THICKNESS / 2 - BULLET_RADIUS - x0) / speed


def bullet_lanes(lanes: int, speed: float, seed: int = 0) -> tuple[F64Array, F64Array]:
    """Start ``(x0, y offset)`` of each lane's bullet: the first contact comes 1 to 2 steps in (so at
    every fraction of a step), the path meets the wall's flat face."""
    rng = np.random.default_rng(seed)
    t_hit = rng.uniform(1.0, 2.0, lanes)
    x0 = -WALL_THICKNESS / 2 - BULLET_RADIUS - speed * t_hit
    dy = rng.uniform(-1.0, 1.0, lanes) * (WALL_HEIGHT / 2 - BULLET_RADIUS) * 0.9
    return x0, dy


def run_bullets(mode: str, speed: float, lanes: int = 32, runs: int = 1, seed: int = 0) -> dict[str, Any]:
    """One bullet row: ``lanes`` bullets at ``speed`` units per step against thin walls."""
    x0s, dys = bullet_lanes(lanes, speed, seed)
    steps = 4  # first contact within 2 steps; 2 more to see a tunnelled bullet leave
    times: list[float] = []
    result: dict[str, Any] = {}
    for _ in range(runs):
        ms, result = _bullet_run(mode, speed, x0s, dys, steps)
        times += ms
    return _row("bullet", mode, speed=speed, ms_per_step=median(times), samples=lanes, steps=steps, **result)


def _bullet_run(mode: str, speed: float, x0s: F64Array, dys: F64Array, steps: int):
    contact_x = -WALL_THICKNESS / 2 - BULLET_RADIUS
    scene = _scene_for("discrete" if mode == "swept" else mode)
    try:
        bullets = []
        for k, (x0, dy) in enumerate(zip(x0s.tolist(), dys.tolist())):
            y = k * LANE_SPACING
            scene.spawn(Transform(0.0, y), Hitbox(AABB(WALL_THICKNESS, WALL_HEIGHT), body="static"))
            bullets.append(scene.spawn(Transform(x0, y + dy), Velocity(speed / DT, 0.0),
                                       Hitbox(Circle(BULLET_RADIUS), ccd=mode == "swept")))
        detected: set[int] = set()
        bullet_set = set(bullets)

        def after(k: int) -> None:
            for ev in scene.events:
                if ev.kind == "started":
                    detected.update({ev.a, ev.b} & bullet_set)

        times = _timed_steps(scene, steps, after=after)
        xs = np.array([scene.get(b, Transform).x for b in bullets])
        missed = xs > 0.0
        stopped = ~missed
        return times, {
            "missed": float(missed.mean()),
            "undetected": float(np.mean([b not in detected for b in bullets])),
            "stop_error": float(np.abs(xs[stopped] - contact_x).max()) if stopped.any() else None,
        }
    finally:
        scene.close()


# --- crates -------------------------------------------------------------------------------------------


def crate_placements(k: int, seed: int = 0) -> dict[str, F64Array]:
    """``k`` pairs of crates: sizes in [0.5, 2], any rotation; B's centre uniform over the disc in
    which the two crates' bounding circles overlap (about two thirds of the pairs then overlap)."""
    rng = np.random.default_rng(seed)
    aw, ah, bw, bh = (rng.uniform(0.5, 2.0, k) for _ in range(4))
    at, bt = rng.uniform(0.0, math.pi, k), rng.uniform(0.0, math.pi, k)
    reach = 0.5 * (np.hypot(aw, ah) + np.hypot(bw, bh))
    d = np.sqrt(rng.uniform(0.0, 1.0, k)) * reach
    phi = rng.uniform(0.0, 2 * math.pi, k)
    return {"ax": np.zeros(k), "ay": np.zeros(k), "aw": aw, "ah": ah, "at": at,
            "bx": d * np.cos(phi), "by": d * np.sin(phi), "bw": bw, "bh": bh, "bt": bt}


def crates_overlap_exact(p: dict[str, F64Array]) -> BoolArray:
    """Exact answer: the rotated rectangles' interiors overlap (separating axis theorem over the
    four edge directions; touching is not an overlap)."""
    dx, dy = p["bx"] - p["ax"], p["by"] - p["ay"]
    ca, sa, cb, sb = np.cos(p["at"]), np.sin(p["at"]), np.cos(p["bt"]), np.sin(p["bt"])
    axes_a = ((ca, sa), (-sa, ca))
    axes_b = ((cb, sb), (-sb, cb))
    overlap = np.ones(dx.shape, dtype=bool)
    for ux, uy in (*axes_a, *axes_b):
        ra = 0.5 * p["aw"] * np.abs(axes_a[0][0] * ux + axes_a[0][1] * uy) + \
            0.5 * p["ah"] * np.abs(axes_a[1][0] * ux + axes_a[1][1] * uy)
        rb = 0.5 * p["bw"] * np.abs(axes_b[0][0] * ux + axes_b[0][1] * uy) + \
            0.5 * p["bh"] * np.abs(axes_b[1][0] * ux + axes_b[1][1] * uy)
        overlap &= np.abs(dx * ux + dy * uy) < ra + rb
    return overlap


def crate_hitbox(mode: str, w: float, h: float, theta: float):
    """The hitbox shape that stands for a ``w`` x ``h`` crate turned by ``theta``."""
    if mode == "aabb":
        return AABB(w, h)
    if mode == "aabb-bounds":
        c, s = abs(math.cos(theta)), abs(math.sin(theta))
        return AABB(w * c + h * s, w * s + h * c)
    if mode == "circle":
        return Circle(math.sqrt(w * h / math.pi))
    if mode == "polygon":
        return Polygon.box(w, h)
    raise ValueError(f"unknown crate mode {mode!r}; modes are {CRATE_MODES}")


def crate_contacts(mode: str, p: dict[str, F64Array], steps: int = 1) -> tuple[BoolArray, list[float]]:
    """Which placements the pipeline reports in contact, with ``mode`` hitboxes; and step times.

    Every pair sits in its own cell of a grid (20 units apart), both crates kinematic (static pairs
    are never tested) and still; the scene declares detection and events only. One untimed step
    first: the crates do not move, and the first mode timed no longer pays the cold start (the
    `aabb` row, timed first, once read ten times its true cost)."""
    from ..scene import Scene

    k = p["aw"].size
    cols = max(1, int(math.ceil(math.sqrt(k))))
    scene = Scene(effects=("detection", "events"))
    try:
        owner: dict[int, int] = {}
        for i in range(k):
            ox, oy = 20.0 * (i % cols), 20.0 * (i // cols)
            for s in "ab":
                theta = float(p[s + "t"][i])
                shape = crate_hitbox(mode, float(p[s + "w"][i]), float(p[s + "h"][i]), theta)
                e = scene.spawn(Transform(ox + float(p[s + "x"][i]), oy + float(p[s + "y"][i]), theta),
                                Hitbox(shape, body="kinematic"))
                owner[e] = i
        scene.step(DT)  # warm-up (still bodies: the contacts are the same)
        times = _timed_steps(scene, steps)
        hit = np.zeros(k, dtype=bool)
        for a, b in zip(scene.contacts.a.tolist(), scene.contacts.b.tolist()):
            if owner[a] != owner[b]:
                raise AssertionError(f"crates of different placements {owner[a]} and {owner[b]} touch")
            hit[owner[a]] = True
    finally:
        scene.close()
    return hit, times


def run_crates(mode: str, count: int = 2_000, steps: int = 3, seed: int = 0) -> dict[str, Any]:
    p = crate_placements(count, seed)
    exact = crates_overlap_exact(p)
    hit, times = crate_contacts(mode, p, steps)
    fp = hit & ~exact
    fn = ~hit & exact
    return _row("crate", mode, ms_per_step=median(times), samples=count, steps=steps,
                fp_rate=float(fp.sum() / max(1, (~exact).sum())), fn_rate=float(fn.sum() / max(1, exact.sum())))


# --- resting: stack, character ------------------------------------------------------------------------


def _rest_scene(scenario: str, mode: str, steps: int):
    """``(scene, movers, exact resting y of each, walk speed)``: bodies start 1/16 above their rest."""
    scene = _scene_for(mode, gravity=GRAVITY)
    gap = 1.0 / 16.0
    movers, rest_y = [], []
    walk = 0.0
    if scenario == "stack":
        scene.spawn(Transform(0.0, -0.5), Hitbox(AABB(8.0, 1.0), body="static"))
        for i in range(8):
            movers.append(scene.spawn(Transform(0.0, 0.5 + i * (1.0 + gap) + gap), Velocity(), Hitbox(AABB(1.0, 1.0))))
            rest_y.append(0.5 + i)
    else:
        walk = 6.0 if scenario == "character-walk" else 0.0
        n_tiles = int(math.ceil(walk * DT * steps)) + 8
        for k in range(-4, n_tiles - 4):
            scene.spawn(Transform(k + 0.5, 0.5), Hitbox(AABB(1.0, 1.0), body="static"))
        # centred on the seam at x = 0, its feet across two tiles
        movers.append(scene.spawn(Transform(0.0, 1.0 + 0.875 + gap), Velocity(walk, 0.0),
                                  Hitbox(AABB(0.75, 1.75))))
        rest_y.append(1.875)
    return scene, movers, np.array(rest_y), walk


def _max_depth(scene, ents: list[int]) -> float:
    """The deepest overlap, after the step, of any mover with anything near it (exact ``collide``)."""
    deepest = 0.0
    for e in ents:
        t, hb = scene.get(e, Transform), scene.get(e, Hitbox)
        ext = hb.shape.bounding_radius + 1.0
        for o in scene.query_box(t.x - ext, t.y - ext, t.x + ext, t.y + ext):
            if o == e:
                continue
            to, ho = scene.get(o, Transform), scene.get(o, Hitbox)
            c = collide(hb.shape, (t.x, t.y, t.rotation), ho.shape, (to.x, to.y, to.rotation))
            if c is not None:
                deepest = max(deepest, c.depth)
    return deepest


def run_rest(scenario: str, mode: str, steps: int = 240, runs: int = 1) -> dict[str, Any]:
    """A stack or character row; metrics over the second half of the run."""
    times: list[float] = []
    result: dict[str, Any] = {}
    samples = 0
    for _ in range(runs):
        ms, result, samples = _rest_run(scenario, mode, steps)
        times += ms
    return _row(scenario, mode, ms_per_step=median(times), samples=samples, steps=steps, **result)


def _rest_run(scenario: str, mode: str, steps: int):
    scene, movers, rest_y, walk = _rest_scene(scenario, mode, steps)
    try:
        ys = np.zeros((steps, len(movers)))
        xs = np.zeros((steps, len(movers)))
        depth = np.zeros(steps)
        window = steps // 2

        def before(k: int) -> None:
            if walk:  # game code: the player holds "right"
                for e in movers:
                    scene.get(e, Velocity).x = walk

        def after(k: int) -> None:
            for j, e in enumerate(movers):
                t = scene.get(e, Transform)
                xs[k, j], ys[k, j] = t.x, t.y
            if k >= steps - window:
                depth[k] = _max_depth(scene, movers)

        times = _timed_steps(scene, steps, before, after)
        w = ys[-window:]
        dx = np.diff(xs[:, 0])
        return times, {
            "max_depth": float(depth.max()),
            "jitter": float(w.std(axis=0).max()),
            "sink": float((rest_y - w.mean(axis=0)).max()),
            "snags": int((dx < 0.5 * walk * DT).sum()) if walk else None,
        }, len(movers)
    finally:
        scene.close()


# --- ball ---------------------------------------------------------------------------------------------


def run_ball(mode: str, steps: int = 1_000, runs: int = 1) -> dict[str, Any]:
    """A ball of radius 0.5 dropped from 5 units (its bottom 4.5 above the floor), restitution 1.

    ``energy_drift``: least-squares slope of the energy per unit mass (``v^2 / 2 + g h``) over the
    run, per 1,000 steps, relative to the initial energy; ``apex_drop``: how much lower than the
    4.5 units it started from the ball's last apex of the run was, relative."""
    times: list[float] = []
    result: dict[str, Any] = {}
    for _ in range(runs):
        ms, result = _ball_run(mode, steps)
        times += ms
    return _row("ball", mode, ms_per_step=median(times), samples=1, steps=steps, **result)


def _ball_run(mode: str, steps: int):
    g = -GRAVITY[1]
    scene = _scene_for(mode, gravity=GRAVITY)
    try:
        scene.spawn(Transform(0.0, -0.5), Hitbox(AABB(8.0, 1.0), body="static"))
        ball = scene.spawn(Transform(0.0, 5.0), Velocity(), Hitbox(Circle(0.5), restitution=1.0))
        t, v = scene.get(ball, Transform), scene.get(ball, Velocity)
        energy, height, vy = np.zeros(steps), np.zeros(steps), np.zeros(steps)

        def after(k: int) -> None:
            height[k], vy[k] = t.y - 0.5, v.y
            energy[k] = 0.5 * (v.x * v.x + v.y * v.y) + g * height[k]

        times = _timed_steps(scene, steps, after=after)
        e0 = g * 4.5
        slope = float(np.polyfit(np.arange(steps), energy, 1)[0])
        apex = height[1:][(vy[:-1] > 0.0) & (vy[1:] <= 0.0)]
        return times, {"energy_drift": slope * 1000.0 / e0,
                       "apex_drop": float((4.5 - apex[-1]) / 4.5) if apex.size else None}
    finally:
        scene.close()


# --- crowd: overlaps among dynamic bodies -------------------------------------------------------------


def _overlap_depths(scene: Scene, ents: list[int]) -> F64Array:
    """Penetration depth of every overlapping pair among ``ents`` (exact ``collide``)."""
    poses = [(scene.get(e, Transform), scene.get(e, Hitbox).shape) for e in ents]
    out = []
    for i, (ta, sa) in enumerate(poses):
        for tb, sb in poses[i + 1:]:
            if abs(ta.x - tb.x) < 2.0 and abs(ta.y - tb.y) < 2.0:
                c = collide(sa, (ta.x, ta.y, ta.rotation), sb, (tb.x, tb.y, tb.rotation))
                if c is not None:
                    out.append(c.depth)
    return np.array(out)


def run_crowd(mode: str, crowds: int = 5, boxes: int = CROWD_BOXES) -> dict[str, Any]:
    """``boxes`` unit boxes dropped overlapping into a small square, no gravity: the response must
    push them apart. After one step, ``max_depth`` is the deepest remaining overlap and
    ``residual`` the summed remaining depth over the summed initial depth (mean over ``crowds``
    random crowds). Exact answer: no overlap left. This is where ``response_iterations`` works:
    bodies in several contacts with other dynamic bodies."""
    times, deepest, residual = [], [], []
    side = math.sqrt(boxes) * 0.8
    for seed in range(crowds):
        rng = np.random.default_rng(seed)
        scene = _scene_for(mode)
        try:
            ents = [scene.spawn(Transform(float(x), float(y)), Velocity(), Hitbox(AABB(1.0, 1.0)))
                    for x, y in rng.uniform(0.0, side, (boxes, 2))]
            before = _overlap_depths(scene, ents).sum()
            times += _timed_steps(scene, 1)
            after = _overlap_depths(scene, ents)
            deepest.append(float(after.max()) if after.size else 0.0)
            residual.append(float(after.sum() / before) if before > 0 else 0.0)
        finally:
            scene.close()
    return _row("crowd", mode, ms_per_step=median(times), samples=crowds, steps=1,
                max_depth=float(np.mean(deepest)), residual=float(np.mean(residual)))


# --- friction -----------------------------------------------------------------------------------------

FRICTION_G = 10.0
SLOPE = math.radians(30.0)


def run_friction(case: str, mode: str, runs: int = 1) -> dict[str, Any]:
    """One friction case (see the module's docstring) in one mode; the row."""
    times: list[float] = []
    measured = expected = 0.0
    steps = 0
    for _ in range(runs):
        ms, measured, expected, steps = _friction_run(case, mode)
        times += ms
    error = abs(measured) if case == "slope-hold" else abs(measured - expected) / expected
    return _row("friction", mode, case=case, ms_per_step=median(times), measured=measured, expected=expected,
                rel_error=error, samples=1, steps=steps)


def _friction_run(case: str, mode: str) -> tuple[list[float], float, float, int]:
    g, sin, cos = FRICTION_G, math.sin(SLOPE), math.cos(SLOPE)
    effects = None
    if case == "box-tip-one-point":
        from ..scene import DEFAULT_EFFECTS

        effects = DEFAULT_EFFECTS - {"sleeping", "rotation"}
    scene = _scene_for(mode, gravity=(0.0, -g), effects=effects)
    try:
        if case.startswith("box-tip"):
            scene.spawn(Transform(0.0, -0.5), Hitbox(AABB(100.0, 1.0), body="static"))
            body = scene.spawn(Transform(0.0, 1.0, 0.3), Velocity(), Hitbox(Polygon.box(1.0, 1.0), friction=0.5))
            times = _timed_steps(scene, 180)
            return times, scene.get(body, Transform).y, 0.5, 180
        if case == "crate-stop":
            scene.spawn(Transform(0.0, -0.5), Hitbox(AABB(100.0, 1.0), body="static"))
            body = scene.spawn(Transform(0.0, 0.5), Velocity(5.0, 0.0), Hitbox(AABB(1.0, 1.0), friction=0.5))
            times = _timed_steps(scene, 120)  # it stops after 1 s
            return times, scene.get(body, Transform).x, 25.0 / (2.0 * 0.5 * g), 120
        length = 60.0  # a static triangle whose long side is the slope, rising to the right through (0, 0)
        scene.spawn(Transform(0.0, 0.0), Hitbox(Polygon([(-length * cos, -length * sin), (length * cos, length * sin),
                                                         (length * cos, -length * sin)]), body="static"))
        mu = {"slope-hold": 0.7, "slope-slide": 0.3, "disk-roll": 0.5, "disk-slip": 0.1}[case]
        if case.startswith("slope"):  # a box with its lower right corner on the slope at the origin
            body = scene.spawn(Transform(-0.5, 0.5), Velocity(), Hitbox(AABB(1.0, 1.0), friction=mu))
        else:  # a disk of radius 1/2 touching the slope at the origin
            body = scene.spawn(Transform(-0.5 * sin, 0.5 * cos), Velocity(), Hitbox(Circle(0.5), friction=mu))
        t = scene.get(body, Transform)
        x0, y0 = t.x, t.y
        steps = 300 if case == "slope-hold" else 120
        times = _timed_steps(scene, steps)
        if case == "slope-hold":
            return times, math.hypot(t.x - x0, t.y - y0), 0.0, steps
        v = scene.get(body, Velocity)
        accel = -(v.x * cos + v.y * sin) / (steps * DT)
        expected = (2.0 / 3.0) * g * sin if case == "disk-roll" else g * (sin - mu * cos)
        return times, accel, expected, steps
    finally:
        scene.close()


# --- joints: a pendulum's period, a rope's stretch ----------------------------------------------------

PENDULUM_LENGTH = 1.0
PENDULUM_AMPLITUDE = 0.05  # radians: small, and the exact period at it is known all the same
BOB_RADIUS = 0.05
ROPE_LINKS = 20
ROPE_LINK = 0.25


def pendulum_period(length: float, g: float, amplitude: float) -> float:
    """The exact period of a simple pendulum of ``length`` swinging ``amplitude`` radians either
    side: ``2 pi sqrt(L / g) / AGM(1, cos(amplitude / 2))`` (the complete elliptic integral by the
    arithmetic-geometric mean; 1 + amplitude^2 / 16 + ... times the small-angle period)."""
    a, b = 1.0, math.cos(amplitude / 2)
    while abs(a - b) > 1e-15 * a:
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    return 2.0 * math.pi * math.sqrt(length / g) / a


def _crossings(t: F64Array, x: F64Array) -> F64Array:
    """The times at which ``x`` crosses 0 (linear between samples)."""
    k = np.flatnonzero((x[:-1] < 0.0) != (x[1:] < 0.0))
    return t[k] + (t[k + 1] - t[k]) * x[k] / (x[k] - x[k + 1])


def run_joint(case: str, mode: str, periods: int = 10, steps: int = 600, runs: int = 1) -> dict[str, Any]:
    """One joint case (see the module's docstring) in one mode; the row."""
    times: list[float] = []
    out: dict[str, Any] = {}
    for _ in range(runs):
        ms, out = (_pendulum_run(case, mode, periods) if case.startswith("pendulum") else
                   _rope_run(case, mode, steps))
        times += ms
    return _row("joints", mode, case=case, ms_per_step=median(times), samples=1, **out)


def _pendulum_run(case: str, mode: str, periods: int) -> tuple[list[float], dict[str, Any]]:
    from ..joints import DistanceJoint, RevoluteJoint

    g, length, a0, r = -GRAVITY[1], PENDULUM_LENGTH, PENDULUM_AMPLITUDE, BOB_RADIUS
    scene = _scene_for(mode, gravity=GRAVITY)
    try:
        bob = scene.spawn(Transform(length * math.sin(a0), -length * math.cos(a0)), Velocity(),
                          Hitbox(Circle(r), mass=1.0))
        if case == "pendulum-distance":  # a point mass: the rod pulls through its centre, it never turns
            scene.spawn(DistanceJoint(bob, None, anchor_b=(0.0, 0.0)))
            reach = length
        else:  # the disk turns with the rod: a physical pendulum, of length L + I / (m L)
            scene.spawn(RevoluteJoint(bob, None, (0.0, 0.0)))
            reach = length + 0.5 * r * r / length
        expected = pendulum_period(reach, g, a0)
        steps = int(math.ceil(periods * expected / DT)) + 2
        t = scene.get(bob, Transform)
        xs, swing, stretch = np.zeros(steps), np.zeros(steps), np.zeros(steps)

        def after(k: int) -> None:
            xs[k], swing[k] = t.x, math.atan2(t.x, -t.y)
            if case == "pendulum-distance":
                stretch[k] = abs(math.hypot(t.x, t.y) - length) / length
            else:  # the disk's point that was at the hinge, against the hinge
                c, s = math.cos(t.rotation), math.sin(t.rotation)
                lx, ly = -length * math.sin(a0), length * math.cos(a0)  # (the hinge in the disk's frame at spawn)
                stretch[k] = math.hypot(t.x + c * lx - s * ly, t.y + s * lx + c * ly) / length

        times = _timed_steps(scene, steps, after=after)
        when = _crossings(np.arange(1, steps + 1, dtype=np.float64) * DT, xs)
        # crossings come every half period: twice the least-squares slope of their times
        measured = 2.0 * float(np.polyfit(np.arange(when.size), when, 1)[0]) if when.size >= 2 else math.nan
        last = swing[-int(expected / DT):]  # the last period's widest swing, against the first
        return times, {"measured": measured, "expected": expected, "rel_error": abs(measured - expected) / expected,
                       "apex_drop": float(1.0 - np.abs(last).max() / a0),
                       "max_stretch": float(stretch.max()), "steps": steps}
    finally:
        scene.close()


def _rope_run(case: str, mode: str, steps: int) -> tuple[list[float], dict[str, Any]]:
    """``rope-20-hanging``: 20 links hanging straight down at rest from a hinge at the origin;
    ``rope-20-swinging``: the same laid out level to the right, falling and swinging. The rope's
    length along its links is its links' plus every hinge's gap (each link's point at the hinge
    against the next's, the first's against the world point)."""
    from ..joints import RevoluteJoint

    n, link = ROPE_LINKS, ROPE_LINK
    level = case.endswith("swinging")
    scene = _scene_for(mode, gravity=GRAVITY)
    try:
        links = []
        for k in range(n):
            c = (k + 0.5) * link
            links.append(scene.spawn(Transform(c, 0.0) if level else Transform(0.0, -c), Velocity(),
                                     Hitbox(Polygon.box(link, link / 5) if level else Polygon.box(link / 5, link),
                                            mass=1.0)))
        for k in range(n):
            scene.spawn(RevoluteJoint(links[k], links[k - 1] if k else None, (k * link, 0.0) if level else
                                      (0.0, -k * link)))
        poses = [scene.get(e, Transform) for e in links]
        # each link's ends in its frame: at its hinge with the one before (or the world), at the next's
        ex, ey = ((-0.5 * link, 0.0), (0.5 * link, 0.0)) if level else ((0.0, 0.5 * link), (0.0, -0.5 * link))
        total = n * link
        stretch = np.zeros(steps)

        def point(t: Transform, lx: float, ly: float) -> tuple[float, float]:
            c, s = math.cos(t.rotation), math.sin(t.rotation)
            return t.x + c * lx - s * ly, t.y + s * lx + c * ly

        def after(k: int) -> None:
            gaps = math.dist((0.0, 0.0), point(poses[0], *ex))
            for a, b in zip(poses, poses[1:]):
                gaps += math.dist(point(a, *ey), point(b, *ex))
            stretch[k] = gaps / total

        times = _timed_steps(scene, steps, after=after)
        half = stretch[steps // 2:]
        return times, {"measured": total * (1.0 + float(half.mean())), "expected": total,
                       "rel_error": float(half.mean()), "max_stretch": float(stretch.max()), "steps": steps}
    finally:
        scene.close()


# --- the centre of mass ---------------------------------------------------------------------------------

MASS_OFFSET = 1.0  # the box's centre from its hitbox origin
MASS_SPIN = 2.0 * math.pi  # rad/s: a turn a second
MASS_THROW = (3.0, 6.0)


def run_mass(case: str, mode: str, runs: int = 1) -> dict[str, Any]:
    """One centre-of-mass case (see the module's docstring) in one mode; the row."""
    times: list[float] = []
    worst = 0.0
    steps = 0
    for _ in range(runs):
        ms, worst, steps = _mass_run(case, mode)
        times += ms
    return _row("mass", mode, case=case, ms_per_step=median(times), samples=1, measured=worst, expected=0.0,
                rel_error=worst / MASS_OFFSET, steps=steps)


def _mass_run(case: str, mode: str) -> tuple[list[float], float, int]:
    """The spinning offset box, and 100 to its right a twin that does not spin, its box centred
    on its origin: the same centre of mass, thrown alike. The exact answer (the centre of mass
    moves as if the body did not turn) is the twin's path, so the integrator's own error (the same
    for both) is not counted, only how the turn moves the centre."""
    throw = case == "offset-throw"
    g = -GRAVITY[1] if throw else 0.0
    scene = _scene_for(mode, gravity=(0.0, -g))
    try:
        c, hh, apart = MASS_OFFSET, 0.25, 100.0
        box = Polygon([(c - 0.5, -hh), (c + 0.5, -hh), (c + 0.5, hh), (c - 0.5, hh)])
        vx, vy = MASS_THROW if throw else (0.0, 0.0)
        # (Velocity is the centre of mass's in the soft solver, the origin's in the exact one: the
        # same numbers given to both, as a game would)
        e = scene.spawn(Transform(0.0, 0.0), Velocity(vx, vy, MASS_SPIN), Hitbox(box, mass=1.0))
        twin = scene.spawn(Transform(c + apart, 0.0), Velocity(vx, vy), Hitbox(Polygon.box(1.0, 2 * hh), mass=1.0))
        cx, cy = scene.get(e, Hitbox).mass_data.center
        t, tt = scene.get(e, Transform), scene.get(twin, Transform)
        steps = int(round((1.0 if throw else 2.0) / DT))
        drift = np.zeros(steps)

        def after(k: int) -> None:
            cs, sn = math.cos(t.rotation), math.sin(t.rotation)
            x = t.x + cs * cx - sn * cy
            y = t.y + sn * cx + cs * cy
            drift[k] = math.hypot(x - (tt.x - apart), y - tt.y)

        times = _timed_steps(scene, steps, after=after)
        return times, float(drift.max()), steps
    finally:
        scene.close()


# --- the character controller -------------------------------------------------------------------------

WALK = 6.0  # units/s: 0.1 a step
CHAR_W, CHAR_H = 0.75, 0.875


def _slope_cells(case: str) -> tuple[list[list[str | None]], Callable[[float], float]]:
    """Terrain cells (rows top down, unit tiles, 6 rows) and the exact surface height y(x):
    flat at 1 to x = 6, then four tiles of rise (45 degrees over 4 columns, 2:1 over 8), flat."""
    width, rows = 28, 6
    cells: list[list[str | None]] = [[None] * width for _ in range(rows)]
    run = 4 if "45" in case else 8
    for c in range(width):
        h = 1 if c < 6 else min(5, 1 + (c - 6) * 4 // run)
        for k in range(h):
            cells[rows - 1 - k][c] = "solid"
        if 6 <= c < 6 + run:
            if run == 4:
                cells[rows - 1 - h][c] = "slope_up"
            else:
                cells[rows - 1 - h][c] = "slope_up_low" if (c - 6) % 2 == 0 else "slope_up_high"

    def surface(x: float) -> float:
        return 1.0 + min(max(x - 6.0, 0.0), float(run)) * 4.0 / run

    return cells, surface


def run_controller(case: str, mode: str, runs: int = 1) -> dict[str, Any]:
    """One controller case (see the module's docstring) in one mode; the row."""
    times: list[float] = []
    out: dict[str, Any] = {}
    for _ in range(runs):
        ms, out = _controller_run(case, mode)
        times += ms
    return _row("controller", mode, case=case, ms_per_step=median(times), samples=1, **out)


def _controller_run(case: str, mode: str) -> tuple[list[float], dict[str, Any]]:
    from ..character import CharacterController
    from ..tiles import terrain_pieces

    scene = _scene_for(mode, gravity=GRAVITY)
    try:
        if case.startswith("slope"):
            cells, surface = _slope_cells(case)
        else:
            cells = [[None] * 28, ["solid"] * 28]

            def surface(x: float) -> float:
                return 1.0

        for pc in terrain_pieces(cells, 1.0):
            scene.spawn(Transform(pc.x, pc.y), Hitbox(pc.shape, body="static"))
        up = not case.endswith("down")
        x0 = 2.0 if up else 20.0
        kw: dict[str, Any] = {"step_height": 0.3} if case == "step-up" else {}
        if case == "step-up":
            scene.spawn(Transform(7.0, 1.125), Hitbox(AABB(2.0, 0.25), body="static"))  # 6 .. 8, top 1.25
        plat = None
        if case == "ride-reverse":
            plat = scene.spawn(Transform(10.0, 3.0), Velocity(), Hitbox(AABB(3.0, 0.5), body="kinematic"))
            x0 = 10.0
        feet0 = surface(x0) + (2.25 if case == "ride-reverse" else 0.0)
        body = scene.spawn(Transform(x0, feet0 + CHAR_H / 2), Velocity(),
                           Hitbox(AABB(CHAR_W, CHAR_H), body="kinematic"), CharacterController(**kw))
        t, v = scene.get(body, Transform), scene.get(body, Velocity)
        for _ in range(30):
            scene.step(DT)
        hw = CHAR_W / 2
        if case == "ride-reverse":
            pt, pv = scene.get(plat, Transform), scene.get(plat, Velocity)
            off0 = (t.x - pt.x, t.y - pt.y)
            drift = [0.0]

            def steer(k: int) -> None:
                pv.x = 2.0 if (k // 20) % 2 == 0 else -2.0
                pv.y = 1.0 if (k // 15) % 2 == 0 else -1.0

            def watch(k: int) -> None:
                drift[0] = max(drift[0], abs(t.x - pt.x - off0[0]), abs(t.y - pt.y - off0[1]))

            times = _timed_steps(scene, 240, steer, watch)
            return times, {"measured": drift[0], "expected": 0.0, "rel_error": drift[0], "steps": 240}
        speed = WALK if up else -WALK
        gaps: list[float] = []
        advances: list[float] = []
        last = [t.x]
        reached = [0]

        def walk(_k: int) -> None:
            v.x = speed

        def watch(k: int) -> None:
            xs = [t.x - hw, t.x + hw] + [b for b in (6.0, 10.0, 14.0) if t.x - hw < b < t.x + hw]
            gaps.append(t.y - CHAR_H / 2 - max(surface(x) for x in xs))
            advances.append(t.x - last[0])
            last[0] = t.x
            if not reached[0] and t.x >= 10.0 - 1e-9:
                reached[0] = k + 1

        steps = 80 if case == "step-up" else 170
        times = _timed_steps(scene, steps, walk, watch)
        err = max(abs(a - speed * DT) for a in advances)
        if case == "step-up":
            expected = (10.0 - x0) / (WALK * DT)
            measured = float(reached[0] or steps + 1)
            return times, {"measured": measured, "expected": expected, "rel_error": abs(measured - expected) / expected,
                           "speed_error": err, "steps": steps}
        return times, {"gap_max": max(gaps), "gap_min": min(gaps), "speed_error": err, "steps": steps}
    finally:
        scene.close()


# --- the whole benchmark ------------------------------------------------------------------------------


def run_accuracy(config: dict[str, Any] | None = None, progress: bool = True, quick: bool = False,
                 speeds: tuple[float, ...] = SPEEDS, scenarios: tuple[str, ...] | None = None) -> dict[str, Any]:
    """Every scenario and mode; returns the report (``rows``, ``machine``, ``config``)."""
    cfg = dict(QUICK if quick else FULL)
    cfg.update(config or {})
    want = set(scenarios or SCENARIOS)
    jobs: list[tuple[str, Callable[[], dict[str, Any]]]] = []
    if "bullet" in want:
        for mode in BULLET_MODES:
            for s in speeds:
                jobs.append((f"bullet {mode} {s:g}/step",
                             partial(run_bullets, mode, s, cfg["lanes"], cfg["runs"])))
    if "crate" in want:
        for mode in CRATE_MODES:
            jobs.append((f"crate {mode}", partial(run_crates, mode, cfg["crates"], cfg["crate_steps"])))
    for scen in ("stack", "character", "character-walk"):
        if scen in want:
            for mode in REST_MODES:
                jobs.append((f"{scen} {mode}", partial(run_rest, scen, mode, cfg["rest_steps"], cfg["runs"])))
    if "crowd" in want:
        for mode in CROWD_MODES:
            jobs.append((f"crowd {mode}", partial(run_crowd, mode, cfg["crowds"])))
    if "ball" in want:
        for mode in BALL_MODES:
            jobs.append((f"ball {mode}", partial(run_ball, mode, cfg["ball_steps"], cfg["runs"])))
    if "friction" in want:
        for case in FRICTION_CASES:
            for mode in FRICTION_MODES:
                jobs.append((f"friction {case} {mode}", partial(run_friction, case, mode, cfg["runs"])))
    if "controller" in want:
        for case in CONTROLLER_CASES:
            for mode in CONTROLLER_MODES:
                jobs.append((f"controller {case} {mode}", partial(run_controller, case, mode, cfg["runs"])))
    if "joints" in want:
        for case in JOINT_CASES:
            for mode in JOINT_MODES:
                jobs.append((f"joints {case} {mode}", partial(run_joint, case, mode, cfg["pendulum_periods"],
                                                             cfg["rope_steps"], cfg["runs"])))
    if "mass" in want:
        for case in MASS_CASES:
            for mode in MASS_MODES:
                jobs.append((f"mass {case} {mode}", partial(run_mass, case, mode, cfg["runs"])))
    rows = []
    with Progress(len(jobs), "accuracy", enabled=progress) as bar:
        for name, job in jobs:
            bar.task(name)
            rows.append(job())
            bar.advance()
    return {
        "benchmark": "accuracy", "quick": quick, "machine": machine_info(), "config": cfg,
        "setup": {"dt": DT, "gravity": list(GRAVITY), "wall_thickness": WALL_THICKNESS, "wall_height": WALL_HEIGHT,
                  "bullet_radius": BULLET_RADIUS, "defaults": "response_iterations=4, substeps=1, ccd off per body"},
        "rows": rows,
    }


# --- text ---------------------------------------------------------------------------------------------

_COMMON: list[Column] = [("mode", "mode", "str"), ("ms_per_step", "ms/step", "ms")]
TABLES: dict[str, tuple[str, list[Column]]] = {
    "bullet": ("Bullets (r = 0.125) against walls 0.25 thick; speed in units per step",
               [("mode", "mode", "str"), ("speed", "speed", "g"), ("ms_per_step", "ms/step", "ms"),
                ("missed", "missed", "pct"), ("undetected", "undetected", "pct"),
                ("stop_error", "stop error", "sci")]),
    "crate": ("Rotated crates: contact decisions against the exact rotated rectangles",
              [*_COMMON, ("fp_rate", "false positive", "pct"), ("fn_rate", "false negative", "pct"),
               ("samples", "placements", "int")]),
    "stack": ("Resting stack of 8 unit boxes (second half of the run)",
              [*_COMMON, ("max_depth", "max depth", "sci"), ("jitter", "jitter (std y)", "sci"),
               ("sink", "sink", "sci")]),
    "character": ("Character 0.75 x 1.75 standing across a seam of unit tiles",
                  [*_COMMON, ("max_depth", "max depth", "sci"), ("jitter", "jitter (std y)", "sci"),
                   ("sink", "sink", "sci")]),
    "character-walk": ("The character walking at 6 units/s along the tiles",
                       [*_COMMON, ("max_depth", "max depth", "sci"), ("jitter", "jitter (std y)", "sci"),
                        ("sink", "sink", "sci"), ("snags", "snags", "int")]),
    "crowd": (f"Crowd: {CROWD_BOXES} overlapping unit boxes, no gravity, after one step",
              [*_COMMON, ("max_depth", "max depth left", "g"), ("residual", "overlap left", "pct")]),
    "ball": ("Ball with restitution 1 bouncing on a floor",
             [*_COMMON, ("energy_drift", "energy drift / 1,000 steps", "pct"),
              ("apex_drop", "last apex lower by", "pct")]),
    "friction": ("Friction and rolling against the analytic answers (g = 10; slope 30 degrees)",
                 [("case", "case", "str"), *_COMMON, ("measured", "measured", "g"), ("expected", "exact", "g"),
                  ("rel_error", "relative error (hold: distance)", "sci")]),
    "controller": ("The character controller on slopes, a step and a platform that turns back (6 units/s)",
                   [("case", "case", "str"), *_COMMON, ("gap_max", "feet above surface, max", "sci"),
                    ("gap_min", "min", "sci"), ("speed_error", "x advance error", "sci"),
                    ("measured", "steps / drift", "g"), ("expected", "exact", "g")]),
    "joints": (f"Joints (soft solver): a pendulum's period (L = {PENDULUM_LENGTH:g}, {PENDULUM_AMPLITUDE:g} rad), "
               f"a rope of {ROPE_LINKS} links' length (g = 20)",
               [("case", "case", "str"), *_COMMON, ("measured", "period (s) / rope length", "g7"),
                ("expected", "exact", "g7"), ("rel_error", "relative error (rope: stretch)", "sci"),
                ("max_stretch", "largest stretch, of the length", "sci"),
                ("apex_drop", "swing lost over the run", "sci")]),
    "mass": (f"The centre of mass of a box whose centre is {MASS_OFFSET:g} from its origin, spinning a turn a "
             "second (free, and thrown under g = 20)",
             [("case", "case", "str"), *_COMMON, ("measured", "centre of mass off its exact path, largest", "sci"),
              ("rel_error", "of the offset", "sci")]),
}


def _marked(rows):
    return [dict(r, mode=r["mode"] + (" (default)" if r["mode"] in DEFAULT_MODES else "")) for r in rows]


def bullet_summary(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """One line per bullet mode: missed fraction at each speed (a compact view of the bullet rows)."""
    out = []
    for mode in dict.fromkeys(r["mode"] for r in rows if r["scenario"] == "bullet"):
        mr = [r for r in rows if r["scenario"] == "bullet" and r["mode"] == mode]
        line: dict[str, Any] = {"mode": mode, "ms_per_step": median(r["ms_per_step"] for r in mr)}
        for r in mr:
            line[f"v{r['speed']:g}"] = r["missed"]
        out.append(line)
    return out


def _tables(report: dict[str, Any], heading: str) -> list[str]:
    rows = report["rows"]
    parts: list[str] = []
    bullets = [r for r in rows if r["scenario"] == "bullet"]
    if bullets:
        speeds = list(dict.fromkeys(r["speed"] for r in bullets))
        cols: list[Column] = [("mode", "mode", "str"), ("ms_per_step", "ms/step (median)", "ms")]
        cols += [(f"v{s:g}", f"{s:g}", "pct") for s in speeds]
        parts += [f"{heading} Bullets: fraction missed, by speed (units per step; r = {BULLET_RADIUS}, "
                  f"wall {WALL_THICKNESS} thick)", "", format_table(_marked(bullet_summary(rows)), cols), ""]
        parts += [f"{heading} Bullets: every row", "", format_table(_marked(bullets), TABLES["bullet"][1]), ""]
    for scen, (title, cols) in TABLES.items():
        if scen == "bullet":
            continue
        sr = [r for r in rows if r["scenario"] == scen]
        if sr:
            parts += [f"{heading} {title}", "", format_table(_marked(sr), cols), ""]
    return parts


def text_report(report: dict[str, Any]) -> str:
    m = report["machine"]
    head = [f"accuracy{' --quick' if report['quick'] else ''}: {m['date']}, Python {m['python']}, numpy {m['numpy']}, "
            f"dt = 1/60 s; defaults: response_iterations=4, substeps=1, ccd off", ""]
    return "\n".join(head + _tables(report, "##")).rstrip()


def markdown(report: dict[str, Any], command: str, plot: str | None) -> str:
    m = report["machine"]
    parts = [
        f"Taken **{m['date']}** with `{command}` on {m['platform']} ({m['machine']}, {m['cpus']} cpus), "
        f"Python {m['python']}, numpy {m['numpy']}, esper {m['esper']}. Rerunning the command rewrites this "
        "section, the plot and `docs/data/accuracy.json` / `accuracy.csv`. Modes marked (default) are what a "
        "scene gets without asking.",
        "",
    ]
    if plot:
        parts += [f"![accuracy against cost, per scenario]({plot})", ""]
    parts += _tables(report, "###")
    return "\n".join(parts)
