"""Collision shapes: plain, validated, immutable data in local coordinates.

A shape knows nothing of where it is; a :class:`~framework.components.Transform` places it. The
hitbox origin is local (0, 0): AABBs and circles are centred on it, polygons rotate about it.

- :class:`AABB` is an axis-aligned box that never rotates, whatever the transform's rotation.
- :class:`Circle` is centred on the origin.
- :class:`Capsule` is the set of points within ``radius`` of a segment of ``length`` through the
  origin, vertical at rotation 0 (a "stadium"); it rotates about the origin.
- :class:`Polygon` is a convex outline, either winding; it is stored counter-clockwise, starting at
  its lowest (then leftmost) vertex, so equal outlines given in any order compare equal and give
  the same answers bit for bit.
- :class:`Segment` is a two-sided line from ``a`` to ``b`` in local coordinates: no area, so it is
  terrain (a static or kinematic body's hitbox), never a dynamic body's only shape.
- :class:`ChainSegment` is a one-sided segment with ghost vertices, one link of a :class:`Chain`
  (a polyline or loop of them: terrain drawn as lines that bodies slide along without catching on
  a joint), as Box2D's chain shapes.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

from .validation import InvalidValue, finite, positive

__all__ = ["AABB", "Capsule", "Chain", "ChainSegment", "Circle", "Polygon", "Segment", "Shape"]

# Tolerance of the "collinear" test: a vertex within this fraction of the polygon's extent (plus 16
# units of rounding of its coordinates) of the line through its neighbours is on that line. It is a
# distance, not an angle: rounding moves points by a distance, whatever the edge lengths. Small
# enough for a 1 x 1e13 sliver to be a polygon, large enough to absorb computed collinear points.
_COLLINEAR_REL = 1e-14
_ROUNDING = 16.0 * 2.0**-52
# A polygon's centroid closer to its origin than this fraction of its bounding radius is its origin
# (the rounding of a centred outline's computed points, a thousand times over).
_CENTRED = 2.0**-40


class Shape:
    """Base of the collision shapes. ``kind`` names the shape for dispatch tables."""

    kind: ClassVar[str] = "shape"
    __slots__ = ()

    @property
    def bounding_radius(self) -> float:
        """Radius of the smallest origin-centred circle that holds the shape at any rotation."""
        raise NotImplementedError

    @property
    def area(self) -> float:
        """The shape's area (a hitbox's mass from its density)."""
        raise NotImplementedError

    @property
    def second_moment(self) -> float:
        """The moment of inertia of the shape, uniformly filled, about its origin, per unit of
        mass (a body of mass ``m`` turning about its hitbox origin has inertia ``m`` times this)."""
        raise NotImplementedError

    @property
    def centroid(self) -> tuple[float, float]:
        """The centre of the shape's area (its centre of mass, uniformly filled), in its local
        coordinates: (0, 0) for every shape but a :class:`Polygon` whose outline is not centred (a
        polygon's centroid within ``2**-40`` of its bounding radius of the origin, the rounding of a
        symmetric outline's computed points, is the origin)."""
        return (0.0, 0.0)

    @property
    def central_moment(self) -> float:
        """The moment of inertia of the shape, uniformly filled, about its :attr:`centroid`, per unit
        of mass: :attr:`second_moment` less the squared distance of the centroid from the origin
        (the parallel-axis theorem), worked without that subtraction's cancellation."""
        return self.second_moment


@dataclass(frozen=True, slots=True)
class AABB(Shape):
    """Axis-aligned box ``width`` x ``height`` centred on the hitbox origin; never rotates."""

    width: float
    height: float
    kind: ClassVar[str] = "aabb"

    def __post_init__(self) -> None:
        object.__setattr__(self, "width", _halvable("AABB width", self.width))
        object.__setattr__(self, "height", _halvable("AABB height", self.height))

    @property
    def half_width(self) -> float:
        return self.width * 0.5

    @property
    def half_height(self) -> float:
        return self.height * 0.5

    @property
    def bounding_radius(self) -> float:
        return math.hypot(self.width * 0.5, self.height * 0.5)

    @property
    def area(self) -> float:
        return self.width * self.height

    @property
    def second_moment(self) -> float:
        return (self.width * self.width + self.height * self.height) / 12.0


@dataclass(frozen=True, slots=True)
class Circle(Shape):
    """Circle of ``radius`` centred on the hitbox origin."""

    radius: float
    kind: ClassVar[str] = "circle"

    def __post_init__(self) -> None:
        object.__setattr__(self, "radius", positive("Circle radius", self.radius))

    @property
    def bounding_radius(self) -> float:
        return self.radius

    @property
    def area(self) -> float:
        return math.pi * self.radius * self.radius

    @property
    def second_moment(self) -> float:
        return 0.5 * self.radius * self.radius


@dataclass(frozen=True, slots=True)
class Capsule(Shape):
    """The points within ``radius`` of the segment from (0, -length/2) to (0, +length/2): a
    rectangle ``2 radius`` x ``length`` capped by two half discs, centred on the hitbox origin,
    vertical at rotation 0; it rotates with its transform about the origin."""

    radius: float
    length: float
    kind: ClassVar[str] = "capsule"

    def __post_init__(self) -> None:
        object.__setattr__(self, "radius", positive("Capsule radius", self.radius))
        object.__setattr__(self, "length", _halvable("Capsule length", self.length))
        if not math.isfinite(self.length * 0.5 + self.radius):
            raise InvalidValue(
                f"Capsule({self.radius!r}, {self.length!r}) is too large: its half height overflows float64"
            )

    @property
    def half_length(self) -> float:
        """Half the length of the core segment: its ends are (0, -half_length) and (0, half_length)."""
        return self.length * 0.5

    @property
    def height(self) -> float:
        """Height at rotation 0: ``length + 2 radius``."""
        return self.length + 2.0 * self.radius

    @property
    def width(self) -> float:
        """Width at rotation 0: ``2 radius``."""
        return 2.0 * self.radius

    @property
    def bounding_radius(self) -> float:
        return self.length * 0.5 + self.radius

    @property
    def area(self) -> float:
        r, ln = self.radius, self.length
        return 2.0 * r * ln + math.pi * r * r

    @property
    def second_moment(self) -> float:
        # The rectangle 2r x L about its centre: 2rL (4r^2 + L^2) / 12. Each half disc, its flat
        # side at distance L/2 from the origin (v: the distance past it): the integral of
        # x^2 + v^2 (pi r^4 / 4), plus L times that of v (2 r^3 / 3), plus L^2/4 times its area
        # (pi r^2 / 2). Summed: r L^3 / 6 + 2 L r^3 + pi r^4 / 2 + pi L^2 r^2 / 4, over the area.
        # Worked on the sizes over the larger one (no overflow), times its square at the end.
        scale = max(self.radius, self.length)
        r, ln = self.radius / scale, self.length / scale
        moment = r * ln * ln * ln / 6.0 + 2.0 * ln * r * r * r + math.pi * r * r * r * r / 2.0 \
            + math.pi * ln * ln * r * r / 4.0
        return moment / (2.0 * r * ln + math.pi * r * r) * scale * scale


@dataclass(frozen=True, slots=True)
class Polygon(Shape):
    """Convex polygon in local coordinates; rotates with its transform about local (0, 0).

    ``points`` may wind either way. Duplicate points and points on a straight run are dropped.
    Fewer than 3 non-collinear points, a non-convex outline, a spike (the outline doubling back on
    itself) or an outline that winds more than once raise :class:`ValueError`.
    """

    points: tuple[tuple[float, float], ...]
    kind: ClassVar[str] = "polygon"
    _radius: float = field(init=False, repr=False, compare=False)

    def __init__(self, points: Iterable[Sequence[float]]) -> None:
        object.__setattr__(self, "points", _normalise_outline(points))
        object.__setattr__(
            self, "_radius", max(math.hypot(x, y) for x, y in self.points)
        )

    @classmethod
    def box(cls, width: float, height: float) -> Polygon:
        """A ``width`` x ``height`` box centred on the origin that rotates with its transform."""
        hw = _halvable("Polygon.box width", width) * 0.5
        hh = _halvable("Polygon.box height", height) * 0.5
        try:
            return cls([(-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh)])
        except InvalidValue:
            raise InvalidValue(
                f"Polygon.box({width!r}, {height!r}) is too thin to be a polygon in float64 (width and "
                "height more than ~1e13 apart); an AABB has no such limit"
            ) from None

    @property
    def bounding_radius(self) -> float:
        return self._radius

    @property
    def area(self) -> float:
        pts = self.points
        return 0.5 * abs(math.fsum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1])))

    @property
    def second_moment(self) -> float:
        return _origin_moment(self.points)  # (the points are counter-clockwise)

    @property
    def centroid(self) -> tuple[float, float]:
        # A fan of triangles from the first vertex (a point of the outline: the terms stay as small
        # as the polygon, wherever it lies); triangle (p0, p_i, p_i+1) of twice-area D has its
        # centroid at p0 + (e1 + e2) / 3, e1 and e2 its edges from p0.
        pts = self.points
        x0, y0 = pts[0]
        twice_area, mx, my = [], [], []
        for (x1, y1), (x2, y2) in zip(pts[1:-1], pts[2:]):
            e1x, e1y, e2x, e2y = x1 - x0, y1 - y0, x2 - x0, y2 - y0
            d = e1x * e2y - e1y * e2x
            twice_area.append(d)
            mx.append(d * (e1x + e2x))
            my.append(d * (e1y + e2y))
        three_a = 3.0 * math.fsum(twice_area)
        cx, cy = x0 + math.fsum(mx) / three_a, y0 + math.fsum(my) / three_a
        # A centroid within rounding of the origin (a symmetric outline whose points were computed,
        # a regular hexagon's) is the origin: the body is centred, as its outline was meant to be.
        if math.hypot(cx, cy) <= _CENTRED * self._radius:
            return (0.0, 0.0)
        return (cx, cy)

    @property
    def central_moment(self) -> float:
        # The origin formula of second_moment, on the outline moved so its centroid is the origin.
        cx, cy = self.centroid
        return _origin_moment([(x - cx, y - cy) for x, y in self.points])

    def __len__(self) -> int:
        return len(self.points)


@dataclass(frozen=True, slots=True)
class Segment(Shape):
    """The straight line from ``a`` to ``b`` (points in local coordinates), two-sided; it rotates with
    its transform about the hitbox origin, local (0, 0).

    A segment has no interior of its own: another shape collides with it when the segment enters
    that shape's interior (touching is no collision). Its area is 0, so it gives a body no mass:
    it is for static and kinematic bodies (terrain drawn as lines). The two ends must be finite
    and distinct; anything else raises :class:`ValueError` naming the bad value.
    """

    a: tuple[float, float]
    b: tuple[float, float]
    kind: ClassVar[str] = "segment"

    def __post_init__(self) -> None:
        a = _point("Segment a", self.a)
        b = _point("Segment b", self.b)
        if a == b:
            raise InvalidValue(f"Segment ends must be distinct, got a = b = {self.a!r}")
        if not math.isfinite(math.hypot(b[0] - a[0], b[1] - a[1])):
            raise InvalidValue(f"Segment from {self.a!r} to {self.b!r} is too long: its length overflows float64")
        object.__setattr__(self, "a", a)
        object.__setattr__(self, "b", b)

    @property
    def length(self) -> float:
        return math.hypot(self.b[0] - self.a[0], self.b[1] - self.a[1])

    @property
    def normal(self) -> tuple[float, float]:
        """The unit normal on the right of the direction a -> b, ``(dy, -dx) / |d|``, in local
        coordinates (for a segment drawn left to right, it points down)."""
        dx, dy = self.b[0] - self.a[0], self.b[1] - self.a[1]
        ln = math.hypot(dx, dy)
        return dy / ln + 0.0, -dx / ln + 0.0

    @property
    def bounding_radius(self) -> float:
        return max(math.hypot(*self.a), math.hypot(*self.b))

    @property
    def area(self) -> float:
        return 0.0

    @property
    def second_moment(self) -> float:
        # A uniform rod from a to b, about the origin: the mean of |a + t (b - a)|^2 over t in [0, 1].
        (ax, ay), (bx, by) = self.a, self.b
        return (ax * ax + ay * ay + ax * bx + ay * by + bx * bx + by * by) / 3.0

    @property
    def centroid(self) -> tuple[float, float]:
        """The segment's midpoint (a uniform rod's centre)."""
        return (0.5 * self.a[0] + 0.5 * self.b[0], 0.5 * self.a[1] + 0.5 * self.b[1])

    @property
    def central_moment(self) -> float:
        ln = self.length
        return ln * ln / 12.0


@dataclass(frozen=True, slots=True)
class ChainSegment(Segment):
    """A one-sided segment from ``a`` to ``b`` with *ghost vertices*: ``ghost1``, the vertex before
    ``a`` in its chain, and ``ghost2``, the one after ``b`` (Box2D's ``b2ChainSegment``). Made by
    :class:`Chain`; rarely built by hand.

    Its solid side is on the left of ``a -> b``: it collides with shapes on its right, the side of
    :attr:`~Segment.normal` (for a loop drawn counter-clockwise, the outside), and lets a shape
    whose centre is behind it pass. The ghost vertices give the shape of the terrain on either side,
    so that a contact never pushes a body out sideways at a joint where the chain runs on straight
    or bends inward (it is pushed out along this segment's normal instead), and leaves to the
    neighbour the contacts that its own side owns at a joint that bends outward. The pair functions
    (:func:`~framework.collision.collide` and the others) apply these rules; in every other way
    it is a :class:`Segment`."""

    ghost1: tuple[float, float]
    ghost2: tuple[float, float]

    def __post_init__(self) -> None:
        Segment.__post_init__(self)
        g1 = _point("ChainSegment ghost1", self.ghost1)
        g2 = _point("ChainSegment ghost2", self.ghost2)
        if g1 == self.a or g2 == self.b:
            raise InvalidValue(f"ChainSegment ghosts must differ from the ends they lead to and from, got "
                               f"ghost1={self.ghost1!r}, a={self.a!r}, b={self.b!r}, ghost2={self.ghost2!r}")
        object.__setattr__(self, "ghost1", g1)
        object.__setattr__(self, "ghost2", g2)


class Chain:
    """A polyline (``loop=False``) or a closed loop (``loop=True``) of one-sided segments, terrain
    drawn as lines: :attr:`segments` holds one :class:`ChainSegment` per pair of consecutive
    points (and, for a loop, one from the last point back to the first), each with its neighbours'
    far ends as ghost vertices. A body collides with the right side of each segment (the outside of
    a loop drawn counter-clockwise, y up; the top of a polyline drawn right to left) and slides
    along the chain without catching on a joint.

    An open chain's two free ends are corners: a body meets them from the front as it meets a
    segment's end (their ghosts are placed behind the end, square to the segment). ``points``: 2 or
    more finite (x, y) pairs (3 or more for a loop), no two consecutive ones equal. A chain is not a
    hitbox shape itself: :func:`framework.chains.spawn_chain` spawns one static body per segment.
    """

    __slots__ = ("loop", "points", "segments")

    def __init__(self, points: Iterable[Sequence[float]], loop: bool = False) -> None:
        if not isinstance(loop, bool):
            raise InvalidValue(f"Chain loop must be True or False, got {loop!r}")
        raw = _listed(points, "Chain")
        pts = [_point(f"Chain point {i}", p) for i, p in enumerate(raw)]
        if loop and len(pts) > 1 and pts[0] == pts[-1]:
            pts.pop()  # a loop given closed
        need = 3 if loop else 2
        if len(pts) < need:
            raise InvalidValue(f"Chain {'loop ' if loop else ''}needs at least {need} points, got {raw!r}")
        n = len(pts)
        for i in range(n if loop else n - 1):
            if pts[i] == pts[(i + 1) % n]:
                raise InvalidValue(f"Chain points {i} and {(i + 1) % n} are equal ({raw[i]!r}): a segment "
                                   "needs two distinct ends")
        self.points: tuple[tuple[float, float], ...] = tuple(pts)
        self.loop = loop
        segs = []
        for i in range(n if loop else n - 1):
            a, b = pts[i], pts[(i + 1) % n]
            if loop or i > 0:
                g1 = pts[i - 1]
            else:  # a free end: behind it, square to the segment
                g1 = _behind(a, a, b)
            if loop or i < n - 2:
                g2 = pts[(i + 2) % n]
            else:
                g2 = _behind(b, a, b)
            segs.append(ChainSegment(a, b, g1, g2))
        self.segments: tuple[ChainSegment, ...] = tuple(segs)

    def __repr__(self) -> str:
        return f"Chain({list(self.points)!r}, loop={self.loop!r})"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Chain) and (self.points, self.loop) == (other.points, other.loop)

    def __hash__(self) -> int:
        return hash((self.points, self.loop))

    def __len__(self) -> int:
        return len(self.segments)


def _behind(p: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> tuple[float, float]:
    """The ghost of a free chain end ``p`` of segment a -> b: one segment length behind it, square to
    the segment (the segment's normal is on its right: behind is on its left)."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    return p[0] - dy, p[1] + dx


def _point(name: str, p: object) -> tuple[float, float]:
    """A finite (x, y) pair (-0.0 made 0.0), its distance from the origin finite."""
    if isinstance(p, (str, bytes)):
        raise InvalidValue(f"{name} must be an (x, y) pair, got {p!r}")
    try:
        n = len(p)  # type: ignore[arg-type]
    except TypeError:
        raise InvalidValue(f"{name} must be an (x, y) pair, got {p!r}") from None
    if n != 2:
        raise InvalidValue(f"{name} must be an (x, y) pair, got {p!r}")
    seq: Sequence[object] = p  # type: ignore[assignment]
    x = finite(f"{name} x", seq[0]) + 0.0
    y = finite(f"{name} y", seq[1]) + 0.0
    if not math.isfinite(math.hypot(x, y)):
        raise InvalidValue(f"{name} {p!r} is too far from the origin: its distance overflows float64")
    return x, y


def _halvable(name: str, value: object) -> float:
    """A positive size whose half is still > 0 (only the smallest subnormal, 5e-324, is not)."""
    x = positive(name, value)
    if x * 0.5 == 0.0:
        raise InvalidValue(f"{name} must be finite and > 0 with a half > 0, got {value!r}")
    return x


def _cross(ax: float, ay: float, bx: float, by: float) -> float:
    return ax * by - ay * bx


def _segments_cross(p: tuple[float, float], q: tuple[float, float],
                    r: tuple[float, float], s: tuple[float, float]) -> bool:
    """Closed segments pq and rs share a point (used only to word an error message)."""
    d1 = _cross(q[0] - p[0], q[1] - p[1], r[0] - p[0], r[1] - p[1])
    d2 = _cross(q[0] - p[0], q[1] - p[1], s[0] - p[0], s[1] - p[1])
    d3 = _cross(s[0] - r[0], s[1] - r[1], p[0] - r[0], p[1] - r[1])
    d4 = _cross(s[0] - r[0], s[1] - r[1], q[0] - r[0], q[1] - r[1])
    if ((d1 > 0) != (d2 > 0) or d1 == 0 or d2 == 0) and ((d3 > 0) != (d4 > 0) or d3 == 0 or d4 == 0):
        def within(a: tuple[float, float], b: tuple[float, float], c: tuple[float, float]) -> bool:
            return min(a[0], b[0]) <= c[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= c[1] <= max(a[1], b[1])
        if d1 == d2 == 0:  # collinear: overlapping only if one holds an end of the other
            return within(p, q, r) or within(p, q, s) or within(r, s, p) or within(r, s, q)
        return True
    return False


def _self_intersecting(pts: list[tuple[float, float]]) -> bool:
    n = len(pts)
    for i in range(n):
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue  # adjacent through the closing edge
            if _segments_cross(pts[i], pts[(i + 1) % n], pts[j], pts[(j + 1) % n]):
                return True
    return False


def _normalise_outline(points: Iterable[Sequence[float]]) -> tuple[tuple[float, float], ...]:
    """Validate a convex outline; return it counter-clockwise from its lowest-leftmost vertex.

    Every decision is made on the points scaled by a power of two (exact), so that neither huge nor
    tiny coordinates overflow or underflow, and in an order that does not depend on where the
    outline starts or which way it winds: equal outlines give the same Polygon bit for bit.
    """
    pts, shown = _read_points(points)
    out = _distinct(pts, shown)
    q, thr = _scaled(out)
    _not_collinear(q, thr, shown)
    idx = _corners(out, q, thr, shown)
    turns = _convex_turns(out, q, idx, shown)
    res = [out[i] for i in idx]
    if turns[0] < 0:
        res.reverse()
    start = min(range(len(res)), key=lambda i: (res[i][1], res[i][0]))
    return tuple(res[start:] + res[:start])


def _origin_moment(pts: Sequence[tuple[float, float]]) -> float:
    """A counter-clockwise outline's second moment about the origin, per unit area: each edge and
    the origin span a triangle; summed with the sign of their winding, they give the integrals of
    1 and x^2 + y^2."""
    twice_area, moment = [], []
    for (x0, y0), (x1, y1) in zip(pts, [*pts[1:], *pts[:1]]):
        cross = x0 * y1 - x1 * y0
        twice_area.append(cross)
        moment.append(cross * (x0 * x0 + x0 * x1 + x1 * x1 + y0 * y0 + y0 * y1 + y1 * y1))
    return math.fsum(moment) / (6.0 * math.fsum(twice_area))


def _listed(points: Any, what: str) -> list[Any]:
    """``points`` as a list (text is not a sequence of points), or :class:`InvalidValue` saying
    ``what``'s points must be (x, y) pairs."""
    if isinstance(points, (str, bytes)):
        raise InvalidValue(f"{what} points must be a sequence of (x, y) pairs, got {points!r}")
    try:
        return list(points)
    except TypeError:
        raise InvalidValue(f"{what} points must be a sequence of (x, y) pairs, got {points!r}") from None


def _read_points(points: Iterable[Sequence[float]]) -> tuple[list[tuple[float, float]], str]:
    """The points as finite float pairs (-0.0 made 0.0), and how to show the argument in errors."""
    raw = _listed(points, "Polygon")
    # Name the bad value as the caller wrote it (a tuple stays a tuple); a one-shot iterator is
    # shown as the list of what it gave.
    shown = repr(points) if hasattr(points, "__len__") and hasattr(points, "__getitem__") else repr(raw)
    pts: list[tuple[float, float]] = []
    for i, p in enumerate(raw):
        if isinstance(p, (str, bytes)):
            raise InvalidValue(f"Polygon point {i} must be an (x, y) pair, got {p!r}")
        try:
            n = len(p)
        except TypeError:
            raise InvalidValue(f"Polygon point {i} must be an (x, y) pair, got {p!r}") from None
        if n != 2:
            raise InvalidValue(f"Polygon point {i} must be an (x, y) pair, got {p!r}")
        # "+ 0.0" turns -0.0 into 0.0, so equal outlines are equal bit for bit.
        x = finite(f"Polygon point {i} x", p[0]) + 0.0
        y = finite(f"Polygon point {i} y", p[1]) + 0.0
        if not math.isfinite(math.hypot(x, y)):
            raise InvalidValue(
                f"Polygon point {i} {p!r} is too far from the origin: its distance overflows float64"
            )
        pts.append((x, y))
    return pts, shown


def _distinct(pts: list[tuple[float, float]], shown: str) -> list[tuple[float, float]]:
    """The points without repeats (consecutive ones, including the closing repeat of the first)."""
    out: list[tuple[float, float]] = []
    for p in pts:
        if not out or p != out[-1]:
            out.append(p)
    while len(out) > 1 and out[0] == out[-1]:
        out.pop()
    if len(set(out)) != len(out):
        raise InvalidValue(f"Polygon outline visits a point twice, so it is not convex: {shown}")
    if len(out) < 3:
        raise InvalidValue(f"Polygon needs at least 3 non-collinear points, got {shown}")
    return out


def _scaled(out: list[tuple[float, float]]) -> tuple[list[tuple[float, float]], float]:
    """The points scaled by a power of two so the largest coordinate is in [0.5, 1) (exact, and no
    product below can overflow or lose a tiny polygon to underflow), and the thinness threshold."""
    k = math.frexp(max(max(abs(x), abs(y)) for x, y in out))[1]
    q = [(math.ldexp(x, -k), math.ldexp(y, -k)) for x, y in out]
    xs, ys = [p[0] for p in q], [p[1] for p in q]
    ext = max(max(xs) - min(xs), max(ys) - min(ys))
    thr = _COLLINEAR_REL * ext + _ROUNDING * max(max(map(abs, xs)), max(map(abs, ys)))
    return q, thr


def _not_collinear(q: list[tuple[float, float]], thr: float, shown: str) -> None:
    """All points on one line (within thr of the line through the lexicographic extremes, which are
    the two ends when they are collinear) is an error. Not a signed-area test: a bow-tie's area
    cancels."""
    lo, hi = min(q), max(q)
    lx, ly = hi[0] - lo[0], hi[1] - lo[1]
    span = math.hypot(lx, ly)
    if max(abs(_cross(lx, ly, x - lo[0], y - lo[1])) for x, y in q) <= thr * span:
        raise InvalidValue(f"Polygon needs at least 3 non-collinear points, got {shown}")


def _corners(out: list[tuple[float, float]], q: list[tuple[float, float]], thr: float, shown: str) -> list[int]:
    """Indices of the vertices kept: those where the outline runs straight on are dropped; one where
    it doubles back is a spike (an error). A vertex is degenerate when its triangle with its two
    neighbours is thinner than thr (the triangle's least height: twice its area over its longest
    side). The thinnest goes first, so the result does not depend on the starting point or the
    winding."""
    idx = list(range(len(out)))
    while len(idx) >= 3:
        best = None
        for j in range(len(idx)):
            ax, ay = q[idx[j - 1]]
            bx, by = q[idx[j]]
            cx, cy = q[idx[(j + 1) % len(idx)]]
            e1x, e1y, e2x, e2y = bx - ax, by - ay, cx - bx, cy - by
            side = max(math.hypot(e1x, e1y), math.hypot(e2x, e2y), math.hypot(cx - ax, cy - ay))
            h = abs(_cross(e1x, e1y, e2x, e2y)) / side
            key = (h, q[idx[j]])
            if best is None or key < best[0]:
                best = (key, j, e1x * e2x + e1y * e2y)
        assert best is not None
        (h, _), j, dot = best
        if h > thr:
            break
        if dot < 0.0:
            raise InvalidValue(
                f"Polygon outline doubles back on itself at point {out[idx[j]]!r} "
                f"(a spike is not convex): {shown}"
            )
        del idx[j]
    if len(idx) < 3:
        raise InvalidValue(f"Polygon needs at least 3 non-collinear points, got {shown}")
    return idx


def _convex_turns(out: list[tuple[float, float]], q: list[tuple[float, float]], idx: list[int],
                  shown: str) -> list[float]:
    """The turn at each kept vertex; an error unless every turn has the same sign and the outline
    turns once around (not a star)."""
    n = len(idx)
    turns = []
    for j in range(n):
        ax, ay = q[idx[j - 1]]
        bx, by = q[idx[j]]
        cx, cy = q[idx[(j + 1) % n]]
        e1x, e1y, e2x, e2y = bx - ax, by - ay, cx - bx, cy - by
        turns.append(math.atan2(_cross(e1x, e1y, e2x, e2y), e1x * e2x + e1y * e2y))
    same_sign = all(t > 0 for t in turns) or all(t < 0 for t in turns)
    if not same_sign or abs(abs(sum(turns)) - 2.0 * math.pi) > 1e-6:
        if _self_intersecting([q[i] for i in idx]):
            raise InvalidValue(
                f"Polygon outline crosses itself (self-intersecting), so it is not convex: {shown}"
            )
        bad = next((out[idx[j]] for j, t in enumerate(turns) if (t > 0) != (sum(turns) > 0)), out[idx[0]])
        raise InvalidValue(f"Polygon is not convex (the outline turns the other way at {bad!r}): {shown}")
    return turns
