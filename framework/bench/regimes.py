"""``python -m framework.bench regimes``: the regimes games live in, ours against pymunk and Box2D v3.

Every scene is described once, engine-neutrally (a :class:`Regime`: a list of :class:`Piece`,
each one of our shapes at a position with a velocity and a body kind), and built from that in the
three engines (:class:`Ours`, :class:`PymunkEngine`, :class:`Box2DEngine`), so they step the same
bodies. Scenes (``dt = 1/60`` s, gravity (0, -10), unless said):

- **pile-boxes-N**: ``N`` unit boxes dropped into a pit exactly ``cols`` boxes wide, spawned in
  aligned columns with 1/16 gaps; at rest the top box's centre is exactly ``rows - 1/2`` above the
  floor (:func:`pile_layout`).
- **pile-circles-N**, **pile-mixed-N**: the same pit and grid, filled with circles of random radius
  (or a random mix of boxes, circles and hexagons) jittered sideways, so they form a real pile.
- **stack-20**: one column of 20 unit boxes; **pyramid-20**: 20 rows, each row offset by half a box
  (the classic Box2D pyramid; stable without friction, every contact being flat).
- **scattered-N**: :func:`framework.bench.perf.make_boxes` (boxes of side 4-16 moving through each
  other, no gravity, ``dt = 1`` as in the perf benchmark, about one overlapping pair per box).
- **platformer-crates**: the same with 20 dynamic crates of a tile in stacks of four along the
  player's way.
- **platformer-1**: ours is the platformer's :class:`Game` playing its first level with the
  scripted demo input; the peers get the same level's bodies (read from our game scene at spawn, in
  tile units), their enemies patrolling and the platform moving back and forth (:func:`platformer`).
  Our player and walkers are kinematic bodies moved by the character controller (shape casts
  against the level); the peers have no controller and get them as dynamic bodies.
- **chain-100**, **bridge-30**, **ragdolls-20** (joints: :class:`Hinge`, a revolute joint built
  alike in the three engines; every body turns, friction 0.6): a chain of 100 thin links hinged
  end to end between two static anchors, laid out with slack as a lopsided V so it swings
  (:func:`chain`); a bridge of 30 planks between two posts, laid out as it hangs, five boxes
  dropped onto it (:func:`bridge`); 20 ragdolls of ten bodies and nine limited hinges each
  dropped into a pit (:func:`ragdolls`). Ours runs them in the soft solver only (the exact one
  refuses joints: its columns stay empty, and the row's verdict is the soft one's). ``stretch``:
  the widest any hinge stands open at the end (:func:`hinge_stretch`, one measure for all three),
  how tight each engine holds its joints.

Every engine's bodies are of mass 1 and cannot rotate (our AABBs never turn): pymunk
``Body(1, inf)``, Box2D ``fixed_rotation=True`` with density 1 / area; friction and restitution 0.
Sleeping is off in every engine for the timed scenes (ours: the default effects minus
``sleeping``), so what is timed is the solver's work on awake bodies; the platformer is the game as
shipped (sleeping on; the peers then sleep too). Peers use their defaults otherwise (pymunk 10
iterations and its collision slop; Box2D 4 sub-steps).

Method (as :mod:`framework.bench.perf`): fixed seeds; each scene is built in the three engines and
stepped ``settle`` times untimed (the pile falls and comes to rest), then
:func:`~framework.bench.perf.run_interleaved` warms each engine up and times one step of each per
round, in rotating order, after ``gc.freeze()``; the figures are medians. Ratio = ours / the
faster peer.

Accuracy, judged by one oracle for all three (:func:`max_penetration`: our exact geometry,
``collide_many`` over the pairs whose bounds overlap, found by
:func:`~framework.collision.broad_phase.brute_force_pairs`, on the final positions): ``pen`` is
the deepest overlap left; ``sink`` (piles, stack, pyramid) is how far the top row's lowest box
lies below its exact resting height, over the pile's height.

**Crowds** (the issue's rest criterion, :func:`run_crowd`): 120 balls (radius 0.25-0.5), 120 boxes
(sides 0.5-1) or half of each, dropped into a pit 8 units wide, gravity 20, sleeping on in every
engine, stepped until every body sleeps or 1,800 steps (30 s). Reported per engine: the step at
which all sleep, the sum of squared speeds at the end, the deepest overlap left and the bodies
outside the pit.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from .. import AABB, Circle, Hitbox, Polygon, Shape, Transform, Velocity
from ..arrays import BoolArray, F64Array
from ..character import CharacterController
from ..collision.batch import collide_many
from ..collision.broad_phase import brute_force_pairs
from .perf import DT as PERF_DT
from .perf import EFFECTS as PERF_EFFECTS
from .perf import WARMUP, Task, make_boxes, run_interleaved
from .progress import Progress
from .report import Column, format_table, machine_info, median, optional_module, provenance

__all__ = [
    "COLUMNS", "CROWDS", "CROWD_COLUMNS", "CROWD_KEYS", "Box2DEngine", "Engine", "Hinge", "Ours", "Piece",
    "PymunkEngine", "ROW_KEYS", "Regime", "SCENES", "box_pile", "bridge", "chain", "chain_slopes", "crowd", "goals",
    "hinge_gaps",
    "hinge_stretch", "judge", "make_engines", "markdown", "max_penetration", "peer_modules", "pile_layout",
    "platformer", "pyramid", "ragdolls", "run_crowd", "run_regimes", "run_scene", "scattered", "shape_pile", "stack",
    "text_report", "with_friction",
]

DT = 1.0 / 60.0
GRAVITY = (0.0, -10.0)
GAP = 1.0 / 16.0  # spawn gap between rows of boxes: dyadic, so the exact heights are exact in floats
SLEEP_TIME = 0.5  # s at rest before a peer body sleeps (Box2D's b2_timeToSleep; pymunk gets the same)
CROWD: dict[str, Any] = {"bodies": 120, "pit": 8.0, "gravity": (0.0, -20.0), "max_steps": 1_800, "overlap": 0.02}
ENGINES = ("ours", "soft", "pymunk", "box2d")  # soft: ours with Scene(solver="soft")

CROWDS = ("balls", "boxes", "mixed", "mixed-friction")
#: untimed steps before timing, by scene kind (the same in --quick: the accuracy figures do not move)
SETTLE = {"pile": 240, "stack": 240, "pyramid": 240, "scattered": 0, "platformer": 0, "toy": 0, "joints": 120}
# timed rounds by the number of moving bodies (the first bound that is >= it); the crowds' step cap
FULL: dict[str, Any] = {"rounds": ((100, 500), (1_000, 200), (10**9, 80)), "platformer_rounds": 900,
        "crowd_steps": CROWD["max_steps"]}
QUICK: dict[str, Any] = {"rounds": ((100, 150), (1_000, 50), (10**9, 20)), "platformer_rounds": 300, "crowd_steps": 600}


# --- the engine-neutral description ---------------------------------------------------------------


@dataclass(frozen=True)
class Piece:
    """One body: one of our shapes at ``(x, y)``; ``kind`` is ``dynamic``, ``kinematic`` or ``static``.

    ``judged``: taken into account by the penetration oracle (not sensors, not one-way slabs that
    bodies may pass through from below). ``role``/``params``: what the peers' untimed game logic
    does with it in the platformer (``enemy``: patrol; ``platform``: back and forth). ``mass``: a
    dynamic piece's, in every engine (its inertia scales with it). ``angle``: a moving piece's
    rotation at spawn (static pieces never turn: 0)."""

    shape: Shape
    x: float
    y: float
    vx: float = 0.0
    vy: float = 0.0
    kind: str = "dynamic"
    sensor: bool = False
    judged: bool = True
    role: str | None = None
    params: tuple = ()
    mass: float = 1.0
    angle: float = 0.0


@dataclass(frozen=True)
class Hinge:
    """A revolute joint between pieces ``a`` and ``b`` (indices into the regime's pieces; ``b``
    ``None``: the world) at the world point ``(x, y)`` (where the pieces are at spawn), built alike
    in the three engines. ``lower``, ``upper``: limits on ``a``'s turn relative to ``b`` since
    spawn (radians, counter-clockwise; ``None``: none), as :class:`~framework.RevoluteJoint` says.
    The two bodies do not collide with each other (in every engine)."""

    a: int
    b: int | None
    x: float
    y: float
    lower: float | None = None
    upper: float | None = None


@dataclass
class Regime:
    """A scene as all three engines build it, and how to judge it.

    ``top``: indices of the pieces of the pile's top row, whose exact resting centre height is
    ``exact_top`` (``None`` where no exact answer exists); ``height``: the pile's height, for the
    sink ratio. ``friction``: every body's coefficient (the pair's, in all three engines; 0: none);
    ``rolling``: the circles may turn (a solid disk's inertia in every engine; else no body turns);
    ``tumbling``: every dynamic body turns (boxes as rotating polygons in ours, each shape's own
    inertia for mass 1 in every engine).
    ``kind`` picks the untimed steps before timing (:data:`SETTLE`). ``dynamic_pairs``:
    whether overlaps between two moving bodies count in the penetration figure. ``pit``: ``(minx, maxx, floor)`` for the
    crowds' outside count. ``hinges``: the scene's joints (:class:`Hinge`); a scene with any runs
    in our soft solver only (the exact one refuses joints), and its jointed pairs are left out of
    the penetration figure (they overlap at their hinges by design)."""

    name: str
    kind: str
    pieces: list[Piece]
    gravity: tuple[float, float] = GRAVITY
    dt: float = DT
    effects: frozenset[str] | None = None
    sleeping: bool = False
    friction: float = 0.0
    rolling: bool = False
    tumbling: bool = False
    top: list[int] = field(default_factory=list)
    exact_top: float | None = None
    height: float | None = None
    dynamic_pairs: bool = True
    pit: tuple[float, float, float] | None = None
    game: Any = None  # platformer only: the ours-side game, already built ...
    entities: list[int] = field(default_factory=list)  # ... the entity of each piece ...
    scale: float = 1.0  # ... and the game's units per piece unit
    remake: Any = None  # platformer only: the regime again, its game in the named solver (``remake("soft")``)
    hinges: list[Hinge] = field(default_factory=list)

    def __post_init__(self) -> None:
        for p in self.pieces:
            if p.kind == "static" and p.angle != 0.0:
                raise ValueError("a static piece never turns: its angle must be 0")

    @property
    def bodies(self) -> int:
        return sum(p.kind != "static" for p in self.pieces)

    @property
    def statics(self) -> int:
        return sum(p.kind == "static" for p in self.pieces)


def _pit(width: float, depth: float) -> list[Piece]:
    """A floor with its top at y = 0 from x = 0 to ``width`` and two walls ``depth`` high."""
    return [Piece(AABB(width + 2.0, 1.0), width / 2, -0.5, kind="static"),
            Piece(AABB(1.0, depth), -0.5, depth / 2, kind="static"),
            Piece(AABB(1.0, depth), width + 0.5, depth / 2, kind="static")]


def pile_layout(
    cols: int, rows: int, size: float = 1.0, gap: float = GAP,
) -> tuple[NDArray[np.floating], NDArray[np.floating], float]:
    """Spawn centres of ``cols x rows`` boxes of side ``size`` over a floor at y = 0, in aligned
    columns, row ``r`` lifted ``(r + 1) * gap`` above its resting place; and the exact resting
    centre height of the top row, ``(rows - 1/2) * size``: with nothing to slide sideways (the pit
    is exactly ``cols`` boxes wide), each column rests as a stack on the floor."""
    c, r = np.meshgrid(np.arange(cols), np.arange(rows))
    x = (c.ravel() + 0.5) * size
    y = (r.ravel() + 0.5) * size + (r.ravel() + 1) * gap
    return x, y, (rows - 0.5) * size


def box_pile(cols: int, rows: int) -> Regime:
    """``cols * rows`` unit boxes dropped into a pit ``cols`` wide; the exact top height is known."""
    x, y, top = pile_layout(cols, rows)
    pieces = _pit(cols, 2.0 * rows + 4.0)
    first = len(pieces)
    pieces += [Piece(AABB(1.0, 1.0), float(a), float(b)) for a, b in zip(x.tolist(), y.tolist())]
    n = cols * rows
    return Regime(f"pile-boxes-{n}", "pile", pieces, top=list(range(first + n - cols, first + n)),
                  exact_top=top, height=float(rows))


def _hexagon(radius: float) -> Polygon:
    return Polygon([(radius * math.cos(k * math.pi / 3), radius * math.sin(k * math.pi / 3)) for k in range(6)])


def shape_pile(shapes: str, cols: int, rows: int, seed: int = 0) -> Regime:
    """The pit and grid of :func:`box_pile` filled with ``circles`` (radius 0.3-0.5) or a ``mixed``
    third each of boxes (side 0.6-1), circles and hexagons (radius 0.3-0.5), each jittered sideways
    within its cell: they slide off each other into a real pile (no exact height)."""
    rng = np.random.default_rng(seed)
    x, y, _ = pile_layout(cols, rows)
    n = x.size
    which = np.zeros(n, dtype=int) if shapes == "circles" else rng.integers(0, 3, n)
    size = rng.uniform(0.3, 0.5, n)
    jitter = rng.uniform(-1.0, 1.0, n)
    pieces = _pit(cols, 2.0 * rows + 4.0)
    for k in range(n):
        s = float(size[k])
        shape: Shape = Circle(s) if which[k] == 0 else AABB(2 * s, 2 * s) if which[k] == 1 else _hexagon(s)
        pieces.append(Piece(shape, float(x[k] + jitter[k] * (0.5 - s)), float(y[k])))
    return Regime(f"pile-{shapes}-{n}", "pile", pieces)


def stack(n: int) -> Regime:
    """A column of ``n`` unit boxes on a floor (exact top: ``n - 1/2``)."""
    _, y, top = pile_layout(1, n)
    pieces = [Piece(AABB(8.0, 1.0), 0.0, -0.5, kind="static")]
    pieces += [Piece(AABB(1.0, 1.0), 0.0, float(v)) for v in y.tolist()]
    return Regime(f"stack-{n}", "stack", pieces, top=[n], exact_top=top, height=float(n))


def pyramid(rows: int) -> Regime:
    """``rows`` rows of unit boxes, ``rows - r`` in row ``r``, each row offset by half a box."""
    pieces = [Piece(AABB(rows + 10.0, 1.0), 0.0, -0.5, kind="static")]
    for r in range(rows):
        k = rows - r
        y = r + 0.5 + (r + 1) * GAP
        pieces += [Piece(AABB(1.0, 1.0), i - (k - 1) / 2, y) for i in range(k)]
    return Regime(f"pyramid-{rows}", "pyramid", pieces, top=[len(pieces) - 1], exact_top=rows - 0.5,
                  height=float(rows))


def stack_tumbling(n: int) -> Regime:
    """:func:`stack` with boxes that can tip (friction 0.6, every box turns): ``stack-N-tumbling``."""
    return with_friction(stack(n), 0.6, tumbling=True)


def physics_toy() -> Regime:
    """The issue's physics toy (62 bodies, every one turns, friction 0.6): a pyramid of 55 boxes
    (10 rows), a heavy ball (mass 20) thrown at it, three crates and a barrel on a slope."""
    pieces = [Piece(AABB(60.0, 1.0), 0.0, -0.5, kind="static"),
              Piece(Polygon([(0.0, 0.0), (8.0, 0.0), (0.0, 4.0)]), 14.0, 0.0, kind="static")]  # the slope
    top = 0
    for r in range(10):
        k = 10 - r
        for i in range(k):
            pieces.append(Piece(AABB(1.0, 1.0), i - (k - 1) / 2, r + 0.5 + (r + 1) * GAP))
        top = len(pieces) - 1
    pieces.append(Piece(Circle(0.75), -14.0, 2.0, vx=12.0, vy=3.0, mass=20.0))
    pieces += [Piece(AABB(1.5, 1.5), x, 0.75 + GAP) for x in (-9.0, -7.0, 8.0)]
    pieces.append(Piece(Circle(0.5), 15.0, 4.5))  # the barrel, dropped onto the slope
    regime = with_friction(Regime("toy", "toy", pieces, top=[top], height=10.0), 0.6, tumbling=True)
    return replace(regime, name="toy-62")


JOINT_FRICTION = 0.6  # the joint scenes' friction (every body turns)


def _hinged_run(pieces: list[Piece], hinges: list[Hinge], ends: list[tuple[float, float]], shape: Shape,
                first: int | None, last: int | None) -> list[int]:
    """Links of ``shape`` (a box as long as a link) from each point of ``ends`` to the next, each
    turned along its run, hinged to the next at their shared end, and the first and last ends to
    pieces ``first`` and ``last`` (``None``: left free); append them; return their indices."""
    links = []
    for (x0, y0), (x1, y1) in zip(ends, ends[1:]):
        links.append(len(pieces))
        pieces.append(Piece(shape, 0.5 * (x0 + x1), 0.5 * (y0 + y1), angle=math.atan2(y1 - y0, x1 - x0)))
    hinges += [Hinge(links[k], links[k - 1], *ends[k]) for k in range(1, len(links))]
    if first is not None:
        hinges.append(Hinge(links[0], first, *ends[0]))
    if last is not None:
        hinges.append(Hinge(links[-1], last, *ends[-1]))
    return links


def chain(links: int = 100, length: float = 0.25, span: float = 18.0, first_run: float = 0.6) -> Regime:
    """``chain-N``: ``links`` boxes ``length`` x ``length / 4`` (mass 1) hinged end to end between
    two small static anchors ``span`` apart at the same height, laid out with slack as a lopsided
    V: the first ``first_run`` of the links straight down to the right, the rest straight up to
    the other anchor (the two runs' slopes such that they meet the anchors). Far from the hanging
    shape, it swings from the first step and does not stop (hinges have no friction)."""
    n1 = round(links * first_run)
    n2 = links - n1
    lo, hi = 0.0, math.pi / 2  # the first run's slope: the runs' heights cancel, their widths make the span
    for _ in range(100):
        a = 0.5 * (lo + hi)
        b = math.asin(min(1.0, n1 / n2 * math.sin(a)))
        if length * (n1 * math.cos(a) + n2 * math.cos(b)) > span:
            lo = a
        else:
            hi = a
    b = math.asin(min(1.0, n1 / n2 * math.sin(a)))
    ends = [(0.0, 0.0)]
    for k in range(links):
        slope = -a if k < n1 else b
        ends.append((ends[-1][0] + length * math.cos(slope), ends[-1][1] + length * math.sin(slope)))
    ends[-1] = (span, 0.0)  # (within rounding already)
    pieces = [Piece(AABB(0.25, 0.25), 0.0, 0.0, kind="static"), Piece(AABB(0.25, 0.25), span, 0.0, kind="static")]
    hinges: list[Hinge] = []
    _hinged_run(pieces, hinges, ends, AABB(length, length / 4), 0, 1)
    return Regime(f"chain-{links}", "joints", pieces, friction=JOINT_FRICTION, rolling=True, tumbling=True,
                  hinges=hinges)


def chain_slopes(links: int, length: float, weight: float, load: float, half_span: float) -> list[float]:
    """The slopes (radians below level) of the links of a chain at rest, from the middle out: ``links``
    rigid links (each ``length`` long and ``weight`` heavy, at its middle), ``load`` hanging at its
    middle hinge, between two points at the same height ``2 half_span`` apart. Statics: the
    horizontal tension H is the same in every link; the vertical one in the k-th link from the
    middle is the load's half and the weight of the links between, so its slope is
    atan((load/2 + (k - 1/2) weight) / H); H is the one whose links span the gap (a bisection).
    The bridge regime is laid out by it; tests/test_joint_scenes.py holds a bridge to it."""
    half = links // 2

    def slopes(h: float) -> list[float]:
        return [math.atan((0.5 * load + (k - 0.5) * weight) / h) for k in range(1, half + 1)]

    lo, hi = 1e-9, 1e9
    for _ in range(200):
        h = math.sqrt(lo * hi)
        if sum(length * math.cos(a) for a in slopes(h)) < half_span:
            lo = h
        else:
            hi = h
    return slopes(lo)


def bridge(planks: int = 30, boxes: int = 5) -> Regime:
    """``bridge-N``: ``planks`` planks 0.5 x 0.125 (mass 1) hinged end to end between the top
    corners of two static posts 14 apart (the planks span 15), laid out as the rigid chain hangs at
    rest (:func:`chain_slopes`); ``boxes`` boxes of side 0.5 (mass 1) dropped onto it from 1.5
    above its ends' height, spread along it, which roll and slide toward its middle."""
    plank, half_span = 0.5, 7.0
    slopes = chain_slopes(planks, plank, 1.0, 0.0, half_span)[::-1]  # from the left post in
    ends = [(-half_span, 0.0)]
    for a in slopes:
        ends.append((ends[-1][0] + plank * math.cos(a), ends[-1][1] - plank * math.sin(a)))
    ends += [(-ends[k][0], ends[k][1]) for k in range(planks // 2 - 1, -1, -1)]
    pieces = [Piece(AABB(0.5, 1.0), -half_span - 0.25, -0.5, kind="static"),
              Piece(AABB(0.5, 1.0), half_span + 0.25, -0.5, kind="static")]
    hinges: list[Hinge] = []
    _hinged_run(pieces, hinges, ends, AABB(plank, plank / 4), 0, 1)
    for k in range(boxes):
        pieces.append(Piece(AABB(0.5, 0.5), -half_span + (k + 0.5) * 2 * half_span / boxes, 1.5))
    return Regime(f"bridge-{planks}", "joints", pieces, friction=JOINT_FRICTION, rolling=True, tumbling=True,
                  hinges=hinges)


def _ragdoll(pieces: list[Piece], hinges: list[Hinge], x0: float, y0: float) -> None:
    """One ragdoll of ten bodies with its torso's centre at ``(x0, y0)`` (tests/test_joint_scenes'):
    torso 0.3 x 0.6 (mass 2), head of radius 0.12 (1/2), upper and lower arms 0.3 x 0.1 (1/4
    each), thighs and shins 0.12 x 0.3 (1/2 each), hinged where they touch, with limits."""
    def part(x: float, y: float, shape: Shape, mass: float) -> int:
        pieces.append(Piece(shape, x, y, mass=mass))
        return len(pieces) - 1

    torso = part(x0, y0, AABB(0.3, 0.6), 2.0)
    head = part(x0, y0 + 0.45, Circle(0.12), 0.5)
    hinges.append(Hinge(head, torso, x0, y0 + 0.33, -0.5, 0.5))
    for side in (-1.0, 1.0):
        upper_arm = part(x0 + side * 0.3, y0 + 0.2, AABB(0.3, 0.1), 0.25)
        lower_arm = part(x0 + side * 0.6, y0 + 0.2, AABB(0.3, 0.1), 0.25)
        thigh = part(x0 + side * 0.08, y0 - 0.45, AABB(0.12, 0.3), 0.5)
        shin = part(x0 + side * 0.08, y0 - 0.75, AABB(0.12, 0.3), 0.5)
        hinges += [Hinge(upper_arm, torso, x0 + side * 0.15, y0 + 0.2, -1.5, 1.5),
                   Hinge(lower_arm, upper_arm, x0 + side * 0.45, y0 + 0.2, -1.5, 0.0),
                   Hinge(thigh, torso, x0 + side * 0.08, y0 - 0.3, -1.0, 1.0),
                   Hinge(shin, thigh, x0 + side * 0.08, y0 - 0.6, 0.0, 1.5)]


def ragdolls(count: int = 20, cols: int = 5) -> Regime:
    """``ragdolls-N``: ``count`` ragdolls (:func:`_ragdoll`: ten bodies, nine limited hinges) in rows
    of ``cols``, 2.4 apart, rows 2 apart and every other one shifted by 0.6, dropped into a pit
    ``2.4 cols`` wide from 0.6 above its floor up: they fall, land and pile."""
    width = 2.4 * cols
    pieces = _pit(width, 30.0)
    hinges: list[Hinge] = []
    for k in range(count):
        r, c = divmod(k, cols)
        _ragdoll(pieces, hinges, 1.2 + 2.4 * c + (0.6 if r % 2 else 0.0) - 0.3, 1.5 + 2.0 * r)
    return Regime(f"ragdolls-{count}", "joints", pieces, friction=JOINT_FRICTION, rolling=True, tumbling=True,
                  hinges=hinges)


def scattered(n: int, seed: int = 0) -> Regime:
    """The perf benchmark's workload (:func:`~framework.bench.perf.make_boxes`): ``n`` boxes moving
    through each other, no gravity, ``dt = 1``, our effects as in the perf benchmark."""
    wl = make_boxes(n, seed)
    pieces = [Piece(AABB(w, h), x, y, vx, vy) for x, y, w, h, vx, vy in
              zip(*(a.tolist() for a in (wl.x, wl.y, wl.w, wl.h, wl.vx, wl.vy)))]
    return Regime(f"scattered-{n}", "scattered", pieces, gravity=(0.0, 0.0), dt=PERF_DT,
                  effects=frozenset(PERF_EFFECTS))


def with_friction(regime: Regime, mu: float = 0.5, rolling: bool = False, tumbling: bool = False) -> Regime:
    """``regime`` with friction ``mu`` between every pair of bodies, named ``<name>-friction``
    (``rolling``: and its circles roll, ``<name>-rolling``; ``tumbling``: and every body turns,
    ``<name>-tumbling``)."""
    suffix = "tumbling" if tumbling else "rolling" if rolling else "friction"
    return replace(regime, name=f"{regime.name}-{suffix}", friction=mu, rolling=rolling or tumbling, tumbling=tumbling)


def _turns(regime: Regime, shape: Shape) -> bool:
    """Whether a dynamic piece of ``shape`` turns in ``regime``."""
    return regime.tumbling or (regime.rolling and isinstance(shape, Circle))


def _ours_shape(regime: Regime, shape: Shape) -> Shape:
    """The hitbox shape ours gives a dynamic piece: in a tumbling regime a box is a polygon (an AABB
    never turns)."""
    if regime.tumbling and isinstance(shape, AABB):
        return Polygon.box(shape.width, shape.height)
    return shape


def crowd(kind: str, seed: int = 0, bodies: int = CROWD["bodies"]) -> Regime:
    """``bodies`` balls (radius 0.25-0.5), boxes (sides 0.5-1) or ``mixed`` (alternating), on a
    grid of unit cells 8 wide, jittered within their cells, dropped into a pit 8 units wide
    (``<kind>-friction``: the same with friction 0.5)."""
    if kind.endswith("-friction"):
        return with_friction(crowd(kind.removesuffix("-friction"), seed, bodies))
    rng = np.random.default_rng(seed)
    width = CROWD["pit"]
    cols = int(width)
    pieces = _pit(width, 40.0)
    for k in range(bodies):
        ball = kind == "balls" or (kind == "mixed" and k % 2 == 0)
        if ball:
            r = float(rng.uniform(0.25, 0.5))
            shape: Shape = Circle(r)
            hw = hh = r
        else:
            w, h = (float(v) for v in rng.uniform(0.5, 1.0, 2))
            shape, hw, hh = AABB(w, h), w / 2, h / 2
        c, row = k % cols, k // cols
        x = c + 0.5 + float(rng.uniform(-1.0, 1.0)) * (0.5 - hw)
        pieces.append(Piece(shape, x, 1.0 + row * 1.1 + hh))
    return Regime(f"crowd-{kind}", "crowd", pieces, gravity=CROWD["gravity"], sleeping=True,
                  pit=(0.0, width, 0.0))


def _platformer_modules():
    """The platformer's modules (``framework.examples`` when installed, ``examples`` in a checkout),
    or ``None`` when neither is importable."""
    for root in ("framework.examples.platformer", "examples.platformer"):
        try:
            import importlib

            return tuple(importlib.import_module(f"{root}.{m}") for m in ("game", "demo", "levels", "components"))
        except ImportError:
            continue
    return None


def _scaled(shape: Shape, s: float) -> Shape:
    if isinstance(shape, AABB):
        return AABB(shape.width * s, shape.height * s)
    if isinstance(shape, Circle):
        return Circle(shape.radius * s)
    return Polygon([(x * s, y * s) for x, y in cast(Polygon, shape).points])


def platformer(crates: int = 0, solver: str = "exact") -> Regime | None:
    """The platformer's first level: ours is its :class:`Game` with the level's scripted demo input
    (``Regime.game``, its scene in ``solver``; ``Regime.remake`` builds it in the other); the
    pieces, for the peers and the oracle, are the game scene's bodies at spawn read through the
    public API, in tile units (the peers' defaults are tuned for bodies about 1 unit big; the
    game's tiles are 32 units). One-way slabs become solid slabs in the peers and are not judged
    (bodies jump through them); sensors (coins, spikes, goal) stay sensors. ``crates``: that many
    dynamic crates of a tile, in stacks of four on the ground along the player's way
    (``platformer-crates``). ``None`` when the example is not importable."""
    mods = _platformer_modules()
    if mods is None:
        return None
    from ..scene import Scene

    game_mod, demo, levels, comps = mods
    level = levels.load_level(levels.builtin_levels()[0])
    tile = level.tile
    game = game_mod.Game([level], autoplay=demo.Autoplay(demo.level1), scene=Scene(solver=solver, length_unit=tile))
    scene, s = game.scene, 1.0 / tile
    for k in range(crates):  # stacks of four, three tiles apart, from the tenth column on
        col, high = 9 + 3 * (k // 4), k % 4
        scene.spawn(Transform((col + 0.5) * tile, 2 * tile + (high + 0.5) * tile + (high + 1) * tile / 16),
                    Velocity(), Hitbox(AABB(tile, tile)))
    pieces, ents = [], []
    for e, (t, hb) in scene.query(Transform, Hitbox):
        v = scene.try_get(e, Velocity)
        enemy, plat = scene.try_get(e, comps.Enemy), scene.try_get(e, comps.MovingPlatform)
        role, params = (("enemy", (enemy.speed * s, enemy.direction)) if enemy else
                        ("platform", (*(c * s for c in (*plat.start, *plat.end)), plat.speed * s)) if plat
                        else (None, ()))
        ox, oy = hb.offset
        # Our player and walkers are kinematic bodies our character controller moves; the peers have
        # no controller, so they get them as dynamic bodies (as the game's were before it had one).
        body = "dynamic" if scene.try_get(e, CharacterController) is not None else hb.body.value
        pieces.append(Piece(_scaled(hb.shape, s), (t.x + ox) * s, (t.y + oy) * s,
                            v.x * s if v else 0.0, v.y * s if v else 0.0, body, hb.sensor,
                            judged=not (hb.sensor or hb.one_way), role=role, params=params))
        ents.append(e)
    name = "platformer-crates" if crates else "platformer-1"
    return Regime(name, "platformer", pieces, gravity=tuple(g * s for g in scene.gravity), sleeping=True,
                  dynamic_pairs=False, game=game, entities=ents, scale=tile,
                  remake=lambda other: platformer(crates, other))


# --- the three engines --------------------------------------------------------------------------------


class Engine:
    """One engine stepping one regime: ``step()`` is what is timed; ``after_step()`` runs untimed
    after it (the peers' game logic in the platformer) and returns what the step recorded;
    ``state()`` reads every piece back as arrays ``(x, y, vx, vy, alive)`` in the regime's units."""

    name = "?"

    def __init__(self, regime: Regime) -> None:
        self.regime = regime

    def step(self) -> None:
        raise NotImplementedError

    def after_step(self) -> dict[str, float]:
        return {}

    def state(self) -> tuple[F64Array, F64Array, F64Array, F64Array, BoolArray]:  # x, y, vx, vy, alive
        raise NotImplementedError

    def angles(self) -> F64Array:
        """Every piece's rotation (radians; 0 for those that cannot turn)."""
        return np.zeros(len(self.regime.pieces))

    def asleep(self) -> bool:
        """Every dynamic body sleeps."""
        raise NotImplementedError

    def close(self) -> None:
        pass


class Ours(Engine):
    """Our :class:`~framework.scene.Scene`, through its public API only: one entity per piece
    (``Transform``, ``Velocity`` unless static, ``Hitbox``, mass 1, restitution 0, the regime's
    friction on every hitbox, none when 0), a :class:`~framework.RevoluteJoint` entity per hinge
    (soft solver only); or, for the
    platformer, the game the regime carries. Effects: the regime's, else the default effects, minus
    ``sleeping`` unless the regime sleeps."""

    name = "ours"
    solver = "exact"

    def __init__(self, regime: Regime) -> None:
        super().__init__(regime)
        from ..scene import DEFAULT_EFFECTS, Scene

        self.joints: list[Any] = []  # the hinges' joint entities

        if regime.game is not None:
            mine = regime if self.solver == "exact" else regime.remake(self.solver)
            self.scene, self.entities, self._step = mine.game.scene, mine.entities, mine.game.step
            return
        effects = regime.effects or (DEFAULT_EFFECTS if regime.sleeping else DEFAULT_EFFECTS - {"sleeping"})
        scene = self.scene = Scene(gravity=regime.gravity, effects=effects, solver=self.solver)
        mu = regime.friction or None
        self.entities = [scene.spawn(Transform(p.x, p.y), Hitbox(p.shape, body=p.kind, sensor=p.sensor, friction=mu))
                         if p.kind == "static" else
                         scene.spawn(Transform(p.x, p.y, p.angle), Velocity(p.vx, p.vy),
                                     Hitbox(_ours_shape(regime, p.shape), body=p.kind, sensor=p.sensor, friction=mu,
                                            mass=p.mass if p.kind == "dynamic" else 1.0,
                                            inertia=None if _turns(regime, p.shape) else math.inf))
                         for p in regime.pieces]
        if regime.hinges:
            from ..joints import RevoluteJoint

            ents = self.entities
            self.joints = [scene.spawn(RevoluteJoint(ents[h.a], None if h.b is None else ents[h.b], (h.x, h.y),
                                                     h.lower, h.upper)) for h in regime.hinges]
        dt = regime.dt
        self._step = lambda: scene.step(dt)

    def step(self) -> None:
        self._step()

    def after_step(self) -> dict[str, float]:
        return {"stages_ms": sum(self.scene.stage_ms.values())}

    def state(self) -> tuple[F64Array, F64Array, F64Array, F64Array, BoolArray]:  # x, y, vx, vy, alive
        scene, s = self.scene, 1.0 / self.regime.scale
        out = np.zeros((len(self.entities), 5))
        for k, e in enumerate(self.entities):
            if scene.exists(e):  # the platformer's coins and stomped enemies go away
                t, v = scene.get(e, Transform), scene.try_get(e, Velocity)
                out[k] = (t.x * s, t.y * s, v.x * s if v else 0.0, v.y * s if v else 0.0, 1.0)
        x, y, vx, vy, alive = out.T
        return x, y, vx, vy, alive.astype(bool)

    def angles(self) -> F64Array:
        scene = self.scene
        return np.array([scene.get(e, Transform).rotation if scene.exists(e) else 0.0 for e in self.entities])

    def asleep(self) -> bool:
        n = sum(p.kind == "dynamic" for p in self.regime.pieces)
        return self.scene.counters.get("asleep", 0) >= n

    def close(self) -> None:
        self.scene.close()


class OursSoft(Ours):
    """:class:`Ours` with the soft-step solver (``Scene(solver="soft")``; the platformer's game in a
    soft scene of ``length_unit`` one tile)."""

    name = "soft"
    solver = "soft"


def _area(shape: Shape) -> float:
    if isinstance(shape, AABB):
        return shape.width * shape.height
    if isinstance(shape, Circle):
        return math.pi * shape.radius ** 2
    p = cast(Polygon, shape).points
    return abs(sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(p, p[1:] + p[:1]))) / 2


def _outline(shape: Shape, ox: float, oy: float) -> list[tuple[float, float]]:
    """A box's or polygon's corners, moved by ``(ox, oy)``."""
    if isinstance(shape, AABB):
        hw, hh = shape.half_width, shape.half_height
        return [(ox - hw, oy - hh), (ox + hw, oy - hh), (ox + hw, oy + hh), (ox - hw, oy + hh)]
    return [(ox + x, oy + y) for x, y in cast(Polygon, shape).points]


class Peer(Engine):
    """What the two peers share: a handle per moving piece, and the platformer's game logic
    (untimed, in :meth:`after_step`): enemies walk at their speed and turn when blocked or when the
    cell ahead of their feet holds no tile (as ours turn at walls and ledges); the platform goes back
    and forth between its ends (ours also pauses at each end; this one does not)."""

    def __init__(self, regime: Regime) -> None:
        super().__init__(regime)
        self.handles: list[Any] = []
        self.joints: list[Any] = []  # each hinge's joint (pymunk: its PivotJoint)
        self.heading = {i: p.params[1] for i, p in enumerate(regime.pieces) if p.role == "enemy"}
        self.toward_end = {i: True for i, p in enumerate(regime.pieces) if p.role == "platform"}
        # the cells (unit tiles) holding a solid static piece, for the enemies' ledge probe
        self.ground = {(math.floor(p.x), math.floor(p.y)) for p in regime.pieces if p.kind == "static"
                       and not p.sensor} if self.heading else set()

    def _pos(self, h) -> tuple[float, float]:
        raise NotImplementedError

    def _vel(self, h) -> tuple[float, float]:
        raise NotImplementedError

    def _set_vel(self, h, vx: float, vy: float) -> None:
        raise NotImplementedError

    def _start_logic(self) -> None:
        for i, d in self.heading.items():
            self._set_vel(self.handles[i], d * self.regime.pieces[i].params[0], 0.0)
        self.after_step()

    def after_step(self) -> dict[str, float]:
        pieces, dt = self.regime.pieces, self.regime.dt
        for i, d in self.heading.items():
            h, speed = self.handles[i], pieces[i].params[0]
            (x, y), (vx, vy) = self._pos(h), self._vel(h)
            hw, hh = _half_extents(pieces[i].shape)
            ledge = (math.floor(x + d * (hw + 0.1)), math.floor(y - hh - 0.5)) not in self.ground
            if abs(vx) < 0.5 * speed or (ledge and abs(vy) < 0.5 * speed):  # blocked, or at a ledge: turn
                d = self.heading[i] = -d
            self._set_vel(h, d * speed, vy)
        for i, toward in self.toward_end.items():
            sx, sy, ex, ey, speed = pieces[i].params
            (x, y), (tx, ty) = self._pos(self.handles[i]), ((ex, ey) if toward else (sx, sy))
            dist = math.hypot(tx - x, ty - y)
            if dist <= speed * dt:
                self.toward_end[i] = not toward
                tx, ty = (sx, sy) if toward else (ex, ey)
                dist = math.hypot(tx - x, ty - y) or 1.0
            self._set_vel(self.handles[i], (tx - x) / dist * speed, (ty - y) / dist * speed)
        return {}

    def state(self) -> tuple[F64Array, F64Array, F64Array, F64Array, BoolArray]:  # x, y, vx, vy, alive
        out = np.zeros((len(self.handles), 4))
        for k, (p, h) in enumerate(zip(self.regime.pieces, self.handles)):
            out[k] = (p.x, p.y, 0.0, 0.0) if h is None else (*self._pos(h), *self._vel(h))
        x, y, vx, vy = out.T
        return x, y, vx, vy, np.ones(x.size, dtype=bool)

    def angles(self) -> F64Array:
        return np.array([0.0 if h is None else float(h.angle) for h in self.handles])


class PymunkEngine(Peer):
    """pymunk: dynamic pieces on ``Body(1, inf)`` (mass 1, no rotation; a rolling regime's circles
    ``Body(1, r^2 / 2)``), kinematic ones on kinematic
    bodies, static ones as shapes of the space's static body; elasticity 0, friction the square root
    of the regime's on every shape (pymunk multiplies a pair's: the pair then has the regime's); sleeping
    (when the regime sleeps) after ``SLEEP_TIME`` s idle; everything else pymunk's defaults. Hinges
    are a ``PivotJoint`` and, with limits, a ``RotaryLimitJoint``, neither letting its bodies
    collide."""

    name = "pymunk"

    def __init__(self, regime: Regime, pymunk: Any) -> None:
        super().__init__(regime)
        space = self.space = pymunk.Space()
        space.gravity = regime.gravity
        if regime.sleeping:
            space.sleep_time_threshold = SLEEP_TIME
        items: list[Any] = []
        hinged = _hinged_statics(regime)
        bodies = []  # each piece's body (a jointed static piece's is its own)
        for k, p in enumerate(regime.pieces):
            if p.kind == "static" and k not in hinged:
                body, ox, oy, handle = space.static_body, p.x, p.y, None
            elif p.kind == "static":
                body, ox, oy, handle = pymunk.Body(body_type=pymunk.Body.STATIC), 0.0, 0.0, None
                body.position = (p.x, p.y)
                items.append(body)
            else:
                moment = p.mass * p.shape.second_moment if _turns(regime, p.shape) else math.inf
                body = handle = (pymunk.Body(p.mass, moment) if p.kind == "dynamic"
                                 else pymunk.Body(body_type=pymunk.Body.KINEMATIC))
                body.position, body.velocity, body.angle, ox, oy = (p.x, p.y), (p.vx, p.vy), p.angle, 0.0, 0.0
                items.append(body)
            shape = (pymunk.Circle(body, p.shape.radius, (ox, oy)) if isinstance(p.shape, Circle)
                     else pymunk.Poly(body, _outline(p.shape, ox, oy)))
            shape.friction, shape.elasticity, shape.sensor = math.sqrt(regime.friction), 0.0, p.sensor
            items.append(shape)
            self.handles.append(handle)
            bodies.append(body)
        if regime.hinges:
            world = pymunk.Body(body_type=pymunk.Body.STATIC)  # (b None: a body of its own, which nothing touches)
            items.append(world)
            for h in regime.hinges:
                a, b = bodies[h.a], world if h.b is None else bodies[h.b]
                joints = [pymunk.PivotJoint(a, b, (h.x, h.y))]
                if h.lower is not None or h.upper is not None:
                    # pymunk limits b's angle minus a's: ours are a's turn relative to b since spawn
                    ref = _angle0(regime, h.a) - _angle0(regime, h.b)
                    joints.append(pymunk.RotaryLimitJoint(b, a, ref + (-math.inf if h.lower is None else h.lower),
                                                          ref + (math.inf if h.upper is None else h.upper)))
                for j in joints:
                    j.collide_bodies = False
                items += joints
                self.joints.append(joints[0])
        space.add(*items)
        self.dt = regime.dt
        self._start_logic()

    def step(self) -> None:
        self.space.step(self.dt)

    def _pos(self, h) -> tuple[float, float]:
        return tuple(h.position)

    def _vel(self, h) -> tuple[float, float]:
        return tuple(h.velocity)

    def _set_vel(self, h, vx: float, vy: float) -> None:
        h.velocity = (vx, vy)

    def asleep(self) -> bool:
        return all(h.is_sleeping for h, p in zip(self.handles, self.regime.pieces) if p.kind == "dynamic")


class Box2DEngine(Peer):
    """Box2D v3 (``pyb2d3``): dynamic pieces on ``fixed_rotation`` bodies with density 1 / area (mass
    1; a rolling regime's circles turn), kinematic ones on kinematic bodies, static ones as shapes of
    one static body; restitution 0, the regime's friction on every shape (Box2D's pair rule is
    ``sqrt(f1 f2)``); ``sleeping_enabled`` as the regime says; ``step(dt, 4)`` (its default 4
    sub-steps)."""

    name = "box2d"

    def __init__(self, regime: Regime, b2: Any) -> None:
        super().__init__(regime)
        world = self.world = b2.World(gravity=regime.gravity)
        world.sleeping_enabled = regime.sleeping
        ground = world.create_static_body(position=(0.0, 0.0))
        hinged = _hinged_statics(regime)
        bodies = []  # each piece's body (a jointed static piece's is its own)
        for k, p in enumerate(regime.pieces):
            if p.kind == "static" and k not in hinged:
                body, ox, oy, handle = ground, p.x, p.y, None
            elif p.kind == "static":
                body, ox, oy, handle = world.create_static_body(position=(p.x, p.y)), 0.0, 0.0, None
            else:
                make = world.create_dynamic_body if p.kind == "dynamic" else world.create_kinematic_body
                body = handle = make(position=(p.x, p.y), rotation=b2.Rot(p.angle),  # (make_rot: an approximation)
                                     linear_velocity=(p.vx, p.vy), fixed_rotation=not _turns(regime, p.shape))
                ox = oy = 0.0
            bodies.append(body)
            sd = b2.shape_def(density=p.mass / _area(p.shape), is_sensor=p.sensor,
                              material=b2.surface_material(friction=regime.friction, restitution=0.0))
            if isinstance(p.shape, Circle):
                body.create_circle_shape(sd, b2.circle(center=(ox, oy), radius=p.shape.radius))
            elif isinstance(p.shape, AABB):
                body.create_polygon_shape(sd, b2.box(p.shape.half_width, p.shape.half_height, center=(ox, oy)))
            else:
                body.create_polygon_shape(sd, b2.polygon(points=_outline(p.shape, ox, oy)))
            self.handles.append(handle)
        world_body = world.create_static_body(position=(0.0, 0.0)) if regime.hinges else None
        for h in regime.hinges:
            # Box2D's angle is body_b's minus body_a's: ours (a's turn relative to b) with body_a = our b
            a, b = bodies[h.a], world_body if h.b is None else bodies[h.b]
            limited = h.lower is not None or h.upper is not None
            self.joints.append(world.create_revolute_joint(
                body_a=b, body_b=a, local_anchor_a=_local(regime, h.b, h.x, h.y),
                local_anchor_b=_local(regime, h.a, h.x, h.y),
                reference_angle=_angle0(regime, h.a) - _angle0(regime, h.b), enable_limit=limited,
                lower_angle=-math.pi if h.lower is None else h.lower,
                upper_angle=math.pi if h.upper is None else h.upper, collide_connected=False))
        self.dt = regime.dt
        self._start_logic()

    def step(self) -> None:
        self.world.step(self.dt, 4)

    def _pos(self, h) -> tuple[float, float]:
        p = h.position
        return p.x, p.y

    def _vel(self, h) -> tuple[float, float]:
        v = h.linear_velocity
        return v.x, v.y

    def _set_vel(self, h, vx: float, vy: float) -> None:
        h.linear_velocity = (vx, vy)

    def angles(self) -> F64Array:
        # from the rotation's cosine and sine: Box2D's own angle (b2Rot_GetAngle) is an approximate atan2
        return np.array([0.0 if h is None else math.atan2((r := h.rotation).s, r.c) for h in self.handles])

    def asleep(self) -> bool:
        return not any(h.awake for h, p in zip(self.handles, self.regime.pieces) if p.kind == "dynamic")

    def close(self) -> None:
        self.world.destroy()


def _hinged_statics(regime: Regime) -> set[int]:
    """The static pieces a hinge holds: the peers give each a static body of its own (a peer's
    jointed bodies do not collide, and its other static pieces share one body)."""
    held = {k for h in regime.hinges for k in (h.a, h.b) if k is not None}
    return {k for k in held if regime.pieces[k].kind == "static"}


def _angle0(regime: Regime, k: int | None) -> float:
    """Piece ``k``'s rotation at spawn (the world's, ``None``: 0)."""
    return 0.0 if k is None else regime.pieces[k].angle


def _local(regime: Regime, k: int | None, x: float, y: float) -> tuple[float, float]:
    """The world point ``(x, y)`` in piece ``k``'s frame at spawn (the world's, ``None``: itself)."""
    if k is None:
        return x, y
    p = regime.pieces[k]
    c, s = math.cos(p.angle), math.sin(p.angle)
    dx, dy = x - p.x, y - p.y
    return c * dx + s * dy, -s * dx + c * dy


def peer_modules() -> dict[str, Any]:
    """The installed peers: ``{"pymunk": module or None, "box2d": module or None}``."""
    return {"pymunk": optional_module("pymunk"), "box2d": optional_module("pyb2d3")}


def make_engines(regime: Regime, peers: dict[str, Any] | None = None) -> list[Engine]:
    """Ours (exact, unless the regime has hinges; and soft) and every installed peer, each with the
    regime built."""
    peers = peer_modules() if peers is None else peers
    out: list[Engine] = [] if regime.hinges else [Ours(regime)]  # (the exact solver refuses joints)
    if regime.game is None or regime.remake is not None:
        out.append(OursSoft(regime))
    if peers.get("pymunk") is not None:
        out.append(PymunkEngine(regime, peers["pymunk"]))
    if peers.get("box2d") is not None:
        out.append(Box2DEngine(regime, peers["box2d"]))
    return out


# --- the oracle -----------------------------------------------------------------------------------------


def _half_extents(shape: Shape) -> tuple[float, float]:
    if isinstance(shape, AABB):
        return shape.half_width, shape.half_height
    if isinstance(shape, Circle):
        return shape.radius, shape.radius
    pts = cast(Polygon, shape).points
    return max(abs(x) for x, _ in pts), max(abs(y) for _, y in pts)


def max_penetration(shapes: Sequence[Shape], x, y, static, dynamic_pairs: bool = True, rot=None,
                    skip: set[tuple[int, int]] | None = None) -> float:
    """The deepest overlap among the shapes at ``(x, y)`` (turned by ``rot``, default none), by our
    exact geometry: the
    pairs whose bounds overlap (:func:`~framework.collision.broad_phase.brute_force_pairs`, numpy in
    row blocks, never two static ones: once per scene, so its O(N^2) does not matter), then
    ``collide_many`` (the same answers as :func:`~framework.collision.collide`).
    ``dynamic_pairs=False``: only pairs with a static one; ``skip``: pairs ``(i, j)``, ``i < j``,
    left out (jointed ones). The same oracle judges all three engines, from their final positions."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    static = np.asarray(static, dtype=bool)
    if x.size < 2:
        return 0.0
    hw, hh = (np.array(v) for v in zip(*(_half_extents(s) for s in shapes)))
    rot = np.zeros(x.size) if rot is None else np.asarray(rot, dtype=float)
    turned = rot != 0.0
    if turned.any():  # (bounds that hold the shape at any rotation)
        reach = np.array([s.bounding_radius for s in shapes])
        hw, hh = np.where(turned, reach, hw), np.where(turned, reach, hh)
    i, j = brute_force_pairs(x - hw, y - hh, x + hw, y + hh, static)
    if not dynamic_pairs:
        keep = static[i] | static[j]
        i, j = i[keep], j[keep]
    if skip:
        keep = np.array([(min(a, b), max(a, b)) not in skip for a, b in zip(i.tolist(), j.tolist())], dtype=bool)
        i, j = i[keep], j[keep]
    if i.size == 0:
        return 0.0
    res = collide_many([shapes[k] for k in i.tolist()], list(zip(x[i].tolist(), y[i].tolist(), rot[i].tolist())),
                       [shapes[k] for k in j.tolist()], list(zip(x[j].tolist(), y[j].tolist(), rot[j].tolist())))
    return float(res.depth[res.hit].max()) if res.hit.any() else 0.0


def hinge_gaps(regime: Regime, x, y, rot) -> list[float]:
    """How wide each hinge of the regime stands open with its pieces at ``(x, y)`` turned by ``rot``:
    the distance between the hinge's point on ``a`` and on ``b`` (each the point that was at the
    hinge at spawn, carried with its piece; the world's stays put)."""
    out = []
    for h in regime.hinges:
        ends = []
        for k in (h.a, h.b):
            if k is None:
                ends.append((h.x, h.y))
                continue
            lx, ly = _local(regime, k, h.x, h.y)
            c, s = math.cos(float(rot[k])), math.sin(float(rot[k]))
            ends.append((float(x[k]) + c * lx - s * ly, float(y[k]) + s * lx + c * ly))
        out.append(math.dist(*ends))
    return out


def hinge_stretch(regime: Regime, x, y, rot) -> float | None:
    """The widest gap of :func:`hinge_gaps` (``None`` without hinges): how tight an engine holds
    its joints."""
    return max(hinge_gaps(regime, x, y, rot)) if regime.hinges else None


def judge(regime: Regime, engine: Engine) -> dict[str, Any]:
    """An engine's accuracy figures on the regime, from its bodies' positions now: ``pen`` (the
    deepest overlap among the judged pieces, jointed pairs left out), ``sink`` (where an exact
    height exists), ``stretch`` (:func:`hinge_stretch`, where there are hinges), and, for the
    crowds, ``speed2`` (sum of squared speeds) and ``outside`` (bodies whose centre left the pit)."""
    x, y, vx, vy, alive = engine.state()
    pieces = regime.pieces
    sel = np.flatnonzero(alive & np.array([p.judged for p in pieces]))
    shapes = [_ours_shape(regime, pieces[k].shape) if pieces[k].kind == "dynamic" else pieces[k].shape for k in sel]
    at = {k: n for n, k in enumerate(sel.tolist())}
    skip = {(min(at[h.a], at[h.b]), max(at[h.a], at[h.b])) for h in regime.hinges if h.a in at and h.b in at}
    pen = max_penetration(shapes, x[sel], y[sel], [pieces[k].kind != "dynamic" for k in sel], regime.dynamic_pairs,
                          engine.angles()[sel] if regime.tumbling else None, skip)
    out: dict[str, Any] = {"pen": pen, "sink": None, "stretch": hinge_stretch(regime, x, y, engine.angles())}
    if regime.exact_top is not None:
        out["sink"] = float((regime.exact_top - y[regime.top].min()) / regime.height)
    dyn = np.array([p.kind == "dynamic" for p in pieces]) & alive
    out["speed2"] = float((vx[dyn] ** 2 + vy[dyn] ** 2).sum())
    if regime.pit is not None:
        lo, hi, floor = regime.pit
        out["outside"] = int(((x[dyn] < lo) | (x[dyn] > hi) | (y[dyn] < floor)).sum())
    return out


# --- running --------------------------------------------------------------------------------------------

ROW_KEYS = ["scene", "bodies", "static", "ours_ms", "soft_ms", "pymunk_ms", "box2d_ms", "faster_peer", "ratio",
            "ratio_soft", "target", "time_pass", "ours_stages_ms", "sink_ours", "sink_soft", "sink_pymunk",
            "sink_box2d", "pen_ours", "pen_soft", "pen_pymunk", "pen_box2d", "sink_pass", "rounds", "settle",
            "stretch_ours", "stretch_soft", "stretch_pymunk", "stretch_box2d"]
SINK_GOAL = 0.01


def target_ratio(regime: Regime) -> float:
    """The issue's goal for the scene: 0.32x at 10,000 scattered boxes (today's figure, not to get
    worse), 0.5x from 1,000 bodies, else 1.0x (of the faster peer)."""
    return 0.32 if regime.name == "scattered-10000" else 0.5 if regime.bodies >= 1_000 else 1.0


def run_scene(regime: Regime, rounds: int, settle: int = 0, peers: dict[str, Any] | None = None,
              bar: Progress | None = None) -> dict[str, Any]:
    """Build the regime in every engine, step each ``settle`` times (untimed), time ``rounds``
    interleaved steps, judge every engine's final positions; return the scene's row."""
    engines = make_engines(regime, peers)
    try:
        for _ in range(settle):
            for eng in engines:
                eng.step()
                eng.after_step()
        tasks = [Task(f"{regime.name}/{eng.name}", eng.step, eng.after_step) for eng in engines]
        run_interleaved(tasks, rounds, WARMUP, bar)
        figures = {eng.name: judge(regime, eng) for eng in engines}
    finally:
        for eng in engines:
            eng.close()
    ms = {t.name.rsplit("/", 1)[1]: median(t.ms) for t in tasks}
    row: dict[str, Any] = {k: None for k in ROW_KEYS}
    exact = next((t for t in tasks if t.name.endswith("/ours")), None)  # (none in a scene with joints)
    row.update(scene=regime.name, bodies=regime.bodies, static=regime.statics, rounds=rounds, settle=settle,
               ours_stages_ms=median(e["stages_ms"] for e in exact.extra) if exact else None,
               target=target_ratio(regime))
    for name in ENGINES:
        row[f"{name}_ms"] = ms.get(name)
        if name in figures:
            row[f"sink_{name}"], row[f"pen_{name}"] = figures[name]["sink"], figures[name]["pen"]
            row[f"stretch_{name}"] = figures[name]["stretch"]
    peer_ms = {n: cast(float, ms[n]) for n in ("pymunk", "box2d") if ms.get(n)}
    if peer_ms:
        row["faster_peer"] = min(peer_ms, key=peer_ms.__getitem__)
        if ms.get("ours"):
            row["ratio"] = cast(float, ms["ours"]) / peer_ms[row["faster_peer"]]  # (timed rounds: never empty)
        if ms.get("soft"):
            row["ratio_soft"] = cast(float, ms["soft"]) / peer_ms[row["faster_peer"]]
        # a scene with joints has only the soft solver: its time verdict is the soft one's
        judged = row["ratio"] if row["ratio"] is not None else row["ratio_soft"]
        row["time_pass"] = None if judged is None else bool(judged <= row["target"])
    if row["sink_ours"] is not None:
        row["sink_pass"] = bool(row["sink_ours"] <= SINK_GOAL)
    return row


CROWD_KEYS = ["crowd", "engine", "bodies", "asleep_step", "rest_s", "steps", "speed2", "pen", "outside",
              "ms_per_step", "pass"]


def run_crowd(kind: str, engine: str, seed: int = 0, max_steps: int = CROWD["max_steps"],
              peers: dict[str, Any] | None = None) -> dict[str, Any] | None:
    """One crowd in one engine, sleeping on: step until every body sleeps or ``max_steps``; return
    the row (``None`` when the engine is not installed). ``pass``: asleep within the issue's 1,800
    steps, no overlap deeper than 0.02 left, nobody outside the pit; ``None`` (undecided) when a
    shorter cap (``--quick``) ended the run first. ``ms_per_step``: the mean over the run (not
    interleaved: for scale only)."""
    regime = crowd(kind, seed)
    peers = peer_modules() if peers is None else peers
    if engine not in ("ours", "soft") and peers.get(engine) is None:
        return None
    eng = Ours(regime) if engine == "ours" else OursSoft(regime) if engine == "soft" else (
        PymunkEngine if engine == "pymunk" else Box2DEngine)(regime, peers[engine])
    try:
        asleep_at, k, t0 = None, 0, time.perf_counter()
        while k < max_steps:
            k += 1
            eng.step()
            if eng.asleep():
                asleep_at = k
                break
        ms = (time.perf_counter() - t0) * 1e3 / max(1, k)
        fig = judge(regime, eng)
    finally:
        eng.close()
    ok = asleep_at is not None and fig["pen"] <= CROWD["overlap"] and fig["outside"] == 0
    undecided = asleep_at is None and k < CROWD["max_steps"]  # still falling or settling: judge later
    return {"crowd": kind, "engine": engine, "bodies": regime.bodies, "asleep_step": asleep_at,
            "rest_s": asleep_at * regime.dt if asleep_at else None, "steps": k, "speed2": fig["speed2"],
            "pen": fig["pen"], "outside": fig["outside"], "ms_per_step": ms, "pass": None if undecided else ok}


def _rounds(cfg: dict[str, Any], regime: Regime) -> int:
    if regime.kind == "platformer":
        return cfg["platformer_rounds"]
    return next(r for bound, r in cfg["rounds"] if regime.bodies <= bound)


#: the scenes, in table order: name -> its maker
SCENES: dict[str, Callable[[], Regime | None]] = {
    "pile-boxes-100": lambda: box_pile(10, 10),
    "pile-boxes-1000": lambda: box_pile(40, 25),
    "pile-circles-1000": lambda: shape_pile("circles", 40, 25),
    "pile-mixed-1000": lambda: shape_pile("mixed", 40, 25),
    "stack-20": lambda: stack(20),
    "pyramid-20": lambda: pyramid(20),
    "pile-boxes-1000-friction": lambda: with_friction(box_pile(40, 25)),
    "pile-mixed-1000-friction": lambda: with_friction(shape_pile("mixed", 40, 25)),
    "pyramid-20-friction": lambda: with_friction(pyramid(20)),
    "pile-circles-1000-rolling": lambda: with_friction(shape_pile("circles", 40, 25), rolling=True),
    "pyramid-20-tumbling": lambda: with_friction(pyramid(20), 0.6, tumbling=True),
    "stack-20-tumbling": lambda: stack_tumbling(20),
    "toy-62": physics_toy,
    "pile-boxes-1000-tumbling": lambda: with_friction(box_pile(40, 25), tumbling=True),
    "scattered-10": lambda: scattered(10),
    "scattered-100": lambda: scattered(100),
    "scattered-1000": lambda: scattered(1_000),
    "scattered-10000": lambda: scattered(10_000),
    "platformer-1": platformer,
    "platformer-crates": lambda: platformer(crates=20),
    "chain-100": chain,
    "bridge-30": bridge,
    "ragdolls-20": ragdolls,
}


def _versions() -> dict[str, str | None]:
    from importlib import metadata

    out: dict[str, str | None] = {}
    for key, dist in (("pymunk", "pymunk"), ("box2d", "pyb2d3")):
        try:
            out[key] = metadata.version(dist) if peer_modules()[key] is not None else None
        except metadata.PackageNotFoundError:
            out[key] = "installed"
    return out


def run_regimes(config: dict[str, Any] | None = None, scenes: Sequence[str] | None = None,
                crowds: Sequence[str] | None = None, progress: bool = True, quick: bool = False) -> dict[str, Any]:
    """Every scene and crowd (or those named); return the report (``rows``, ``crowds``, ``goals``,
    ``machine``, ``setup``). ``config`` overrides :data:`FULL` / :data:`QUICK` and may carry a
    ``settle`` table replacing :data:`SETTLE` (tests use tiny rounds and settling)."""
    cfg = dict(QUICK if quick else FULL)
    cfg.update(config or {})
    names = list(SCENES) if scenes is None else [n for n in scenes if _known(n, SCENES)]
    kinds = list(CROWDS) if crowds is None else [c for c in crowds if _known(c, CROWDS)]
    steps = cfg["crowd_steps"]
    peers = peer_modules()
    settle = cfg.get("settle", SETTLE)
    rows, crowd_rows = [], []
    with Progress(len(names) + len(kinds) * len(ENGINES), "regimes", enabled=progress) as bar:
        for name in names:
            bar.task(f"{name}: set-up, untimed steps, timing")
            regime = SCENES[name]()  # built one at a time: the scene's memory goes with it
            if regime is not None:
                rows.append(run_scene(regime, _rounds(cfg, regime), settle[regime.kind], peers))
            bar.advance()
        for kind in kinds:
            for engine in ENGINES:
                bar.task(f"crowd of {kind}: {engine}")
                row = run_crowd(kind, engine, max_steps=steps, peers=peers)
                if row is not None:
                    crowd_rows.append(row)
                bar.advance()
    report = {
        "benchmark": "regimes", "quick": quick, "machine": dict(machine_info(), **_versions()), "config": cfg,
        "setup": {"dt": DT, "gravity": list(GRAVITY), "warmup": WARMUP, "sleep_time": SLEEP_TIME, "settle": settle,
                  "crowd": dict(CROWD, max_steps=steps), "sink_goal": SINK_GOAL},
        "rows": rows, "crowds": crowd_rows,
    }
    report["goals"] = goals(rows, crowd_rows)
    return report


def _known(name: str, known) -> bool:
    if name not in known:
        raise ValueError(f"unknown name {name!r}; known: {', '.join(known)}")
    return True


# --- goals and text -------------------------------------------------------------------------------------

COLUMNS: list[Column] = [
    ("scene", "scene", "str"), ("bodies", "bodies", "int"), ("ours_ms", "ours ms", "ms"), ("soft_ms", "soft ms", "ms"),
    ("pymunk_ms", "pymunk ms", "ms"), ("box2d_ms", "box2d ms", "ms"), ("ratio", "ours/faster", "ratio"),
    ("ratio_soft", "soft/faster", "ratio"), ("target", "goal", "ratio"), ("result", "result", "str"),
    ("ours_stages_ms", "ours stages ms", "ms"), ("sink_ours", "sink ours", "pct"), ("sink_soft", "sink soft", "pct"),
    ("sink_pymunk", "sink pymunk", "pct"), ("sink_box2d", "sink box2d", "pct"), ("pen_ours", "pen ours", "sci"),
    ("pen_soft", "pen soft", "sci"), ("pen_pymunk", "pen pymunk", "sci"), ("pen_box2d", "pen box2d", "sci"),
    ("stretch_soft", "stretch soft", "sci"), ("stretch_pymunk", "stretch pymunk", "sci"),
    ("stretch_box2d", "stretch box2d", "sci"),
]
CROWD_COLUMNS: list[Column] = [
    ("crowd", "crowd", "str"), ("engine", "engine", "str"), ("bodies", "bodies", "int"),
    ("asleep", "all asleep at step", "str"), ("speed2", "sum v^2 at the end", "sci"), ("pen", "max overlap", "sci"),
    ("outside", "outside", "int"), ("ms_per_step", "ms/step (mean)", "ms"), ("result", "result", "str"),
]
GOAL_COLUMNS: list[Column] = [("goal", "goal", "str"), ("value", "value", "g"), ("where", "worst", "str"),
                              ("target", "target", "g"), ("result", "result", "str")]
_VERDICT = {True: "pass", False: "FAIL", None: "n/a"}


def _worst(rows: list[dict[str, Any]], key: str) -> tuple[float | None, str]:
    vals = [r for r in rows if r.get(key) is not None]
    if not vals:
        return None, ""
    r = max(vals, key=lambda r: r[key])
    return r[key], r["scene"]


def goals(rows: list[dict[str, Any]], crowd_rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The issue's goals, from the rows: each with its value, the worst scene and a verdict
    (``None`` when nothing measured it, e.g. without any peer)."""
    big = [r for r in rows if r["bodies"] >= 1_000]
    ours = [c for c in crowd_rows if c["engine"] == "ours"]
    figures = [
        ("every scene: ours / faster peer", *_worst(rows, "ratio"), 1.0),
        ("1,000 bodies or more: ours / faster peer", *_worst(big, "ratio"), 0.5),
        ("scattered-10000: ours / faster peer", *_worst([r for r in rows if r["scene"] == "scattered-10000"],
                                                       "ratio"), 0.32),
        ("sink of piles, stack, pyramid (ours), of the height", *_worst(rows, "sink_ours"), SINK_GOAL),
        ("soft solver, every scene: soft / faster peer", *_worst(rows, "ratio_soft"), 1.0),
        ("soft solver, 1,000 bodies or more: soft / faster peer", *_worst(big, "ratio_soft"), 0.5),
        ("soft solver, sink of piles, stack, pyramid, of the height", *_worst(rows, "sink_soft"), SINK_GOAL),
    ]
    out = [{"goal": g, "value": v, "where": w, "target": t, "pass": None if v is None else bool(v <= t)}
           for g, v, w, t in figures]
    if ours:
        failed = [c["crowd"] for c in ours if c["pass"] is False]
        open_ = [c["crowd"] + " (undecided)" for c in ours if c["pass"] is None]
        out.append({"goal": "crowds asleep within 30 s, overlap <= 0.02, none outside (ours): crowds passing",
                    "value": sum(c["pass"] is True for c in ours), "where": ", ".join(failed + open_),
                    "target": len(ours), "pass": False if failed else None if open_ else True})
    return out


def _scene_rows(report: dict[str, Any]) -> list[dict[str, Any]]:
    out = []
    for r in report["rows"]:
        bad = [k for k, ok in (("time", r["time_pass"]), ("sink", r["sink_pass"])) if ok is False]
        verdict = ("FAIL " + ", ".join(bad)) if bad else "n/a" if r["time_pass"] is None else "pass"
        out.append(dict(r, result=verdict))
    return out


def _crowd_rows(report: dict[str, Any]) -> list[dict[str, Any]]:
    return [dict(c, asleep=f"{c['asleep_step']:,} ({c['rest_s']:.1f} s)" if c["asleep_step"] else
                 f"never ({c['steps']:,} steps)", result=_VERDICT[c["pass"]]) for c in report["crowds"]]


def _goal_rows(report: dict[str, Any]) -> list[dict[str, Any]]:
    return [dict(g, result=_VERDICT[g["pass"]]) for g in report["goals"]]


def notes(report: dict[str, Any]) -> list[str]:
    """Observations computed from the rows (so they stay true when the numbers move)."""
    out = []
    m = report["machine"]
    for key, dist in (("pymunk", "pymunk"), ("box2d", "pyb2d3")):
        if m.get(key) is None:
            out.append(f"{dist} is not installed (pip install 'framework[bench]'): its columns are empty.")
    plat = next((r for r in report["rows"] if r["scene"].startswith("platformer")), None)
    if plat and plat["ours_ms"]:
        out.append(f"Platformer: of our {plat['ours_ms']:.3f} ms game step, the pipeline's stages take "
                   f"{plat['ours_stages_ms']:.3f} ms; the rest is the game's own systems (input, enemies, "
                   "camera) and the step's bookkeeping, which the peers' figures do not include.")
    never = [f"{c['crowd']}" for c in report["crowds"] if c["engine"] == "ours" and not c["asleep_step"]]
    if never:
        out.append(f"Our crowds that never all slept within {report['setup']['crowd']['max_steps']:,} steps: "
                   + ", ".join(never) + ".")
    return out


def _tables(report: dict[str, Any], heading: str) -> list[str]:
    parts = [f"{heading} Scenes (median ms per step, interleaved; accuracy at the end of the run)", "",
             format_table(_scene_rows(report), COLUMNS), ""]
    if report["crowds"]:
        parts += [f"{heading} Crowds dropped into a pit (sleeping on; up to "
                  f"{report['setup']['crowd']['max_steps']:,} steps)", "",
                  format_table(_crowd_rows(report), CROWD_COLUMNS), ""]
    parts += [f"{heading} Goals of the issue", "", format_table(_goal_rows(report), GOAL_COLUMNS), ""]
    return parts


def text_report(report: dict[str, Any]) -> str:
    m = report["machine"]
    head = [f"regimes{' --quick' if report['quick'] else ''}: {m['date']}, Python {m['python']}, numpy {m['numpy']}, "
            f"pymunk {m['pymunk'] or 'absent'}, pyb2d3 {m['box2d'] or 'absent'}, {m['cpus']} cpus; "
            "ratio = ours / the faster peer; sink = (exact top - top) / height; pen = deepest overlap left", ""]
    return "\n".join(head + _tables(report, "##") + notes(report)).rstrip()


def markdown(report: dict[str, Any], command: str, plot: str | None) -> str:
    """The generated part of docs/performance.md."""
    m = report["machine"]
    parts = [
        provenance(m, command, f"pymunk {m['pymunk'] or 'absent'}, pyb2d3 {m['box2d'] or 'absent'}", "regimes",
                   ["regimes-crowds.csv"]),
        "",
    ]
    if plot:
        parts += [f"![ms per step of each scene in the three engines, log scale]({plot})", ""]
    parts += _tables(report, "####")
    parts += [f"- {n}" for n in notes(report)]
    return "\n".join(parts)
