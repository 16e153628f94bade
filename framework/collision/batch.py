"""Batch (numpy) collision kernels: the contacts of :func:`~framework.collision.collide` for
arrays of pairs at once, one kernel per family of shape pairs (which pair goes to which kernel:
:data:`framework.collision.kinds.PAIRS`).

Every kernel takes ``[P]`` arrays (scalars broadcast) and returns a :class:`ContactArrays` whose
row ``i`` is what ``collide`` gives for pair ``i``: the same overlap decision on every input
(touching is never a collision and an overlap of one ulp always is), the same normal and depth up
to rounding (the same tie-break rule) and the same point up to rounding. No Python loop runs over
the pairs, except over the rare ones within rounding of touching that need exact integer
arithmetic (none for AABB pairs).

=============================  ===============================================================
``circle_circle``              circles A and B
``aabb_aabb``                  axis-aligned boxes, by centre and half extents
``aabb_aabb_fast``             the same, for the pipeline: the overlap rectangle's centre as point
``polygon_circle``             polygon (or any box, via :func:`outlines`) A, circle B; with
                               ``flip=True`` the circle is shape A of the pair
``polygon_polygon``            polygons and boxes in any mix but AABB / AABB
``capsule_many``               a capsule against any shape's core (:mod:`.capsule`)
=============================  ===============================================================

Polygon kernels take each shape's hitbox origin in world coordinates and its outline relative
to that origin, already rotated: ``verts [P, K, 2]`` and ``counts [P]`` as :func:`outlines` gives
them, gathered per pair. They accept an optional ``size`` ``[P]`` (the two bounding radii summed,
the scale of the tie-break tolerance) and otherwise measure it from the outlines.

Numerics, as in the scalar code (whose module docstring explains them): each pair is worked in a
local frame (A's hitbox origin; the polygon's for a polygon / circle pair) scaled by a power of two,
so a scene at x = 1e9 gives the answers of the scene at the origin and radii of 1e-200 or 1e300
neither underflow nor overflow; floats decide wherever the answer is clear of rounding, exact
arithmetic inside a thin band around touching (:mod:`~framework.collision.exact`).

Inputs must be finite (the systems check components); kernels never return NaN or inf.
:func:`collide_many` groups arbitrary shape pairs by kind and is the convenient (validated) entry.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import cast

import numpy as np
from numpy.typing import NDArray

from ..shapes import AABB, Capsule, ChainSegment, Circle, Polygon, Segment, Shape
from ..validation import InvalidValue
from .batch_box import aabb_aabb, aabb_aabb_fast
from .batch_circle import circle_circle, polygon_circle
from .batch_common import F64, ContactArrays, no_contacts
from .batch_polygon import polygon_polygon
from .capsule import capsule_first, capsule_many, half_segments
from .collide import collide
from .kinds import BOXES, CAPSULES, CIRCLES, PAIRS, POLYGON_CIRCLE, POLYGONS, kind_of, pair_code
from .placement import check_shape, pose

__all__ = [
    "ContactArrays",
    "aabb_aabb",
    "capsule_many",
    "aabb_aabb_fast",
    "circle_circle",
    "collide_many",
    "outlines",
    "polygon_circle",
    "polygon_polygon",
]


def _template(shape: object) -> tuple[tuple[tuple[float, float], ...], bool]:
    """Local outline of a box or polygon (or a segment: its two ends) and whether it turns with its
    transform."""
    if isinstance(shape, AABB):
        hw, hh = shape.width * 0.5, shape.height * 0.5
        return ((-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh)), False
    if isinstance(shape, Polygon):
        return shape.points, True
    if isinstance(shape, Segment):
        return (shape.a, shape.b), True
    raise InvalidValue(f"outlines needs AABB, Polygon or Segment shapes, got {shape!r}")


def outlines(
    shapes: Sequence[AABB | Polygon | Segment], rotations: object,
) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """Outlines of boxes and polygons (a segment: its two ends), rotated, relative to their hitbox
    origins.

    Returns ``(verts, counts)``: ``verts [N, K, 2]`` float64, counter-clockwise, ``K`` the largest
    vertex count, the slots past a shape's count repeating its last vertex; ``counts [N]``.
    ``rotations`` (``[N]`` or a scalar, radians) turns polygons and ``Polygon.box``; AABBs never
    turn. The vertices are those of the scalar code's outlines bit for bit (``math.cos`` and
    ``math.sin``, the same products), up to its power-of-two scaling.
    """
    n = len(shapes)
    rot = np.asarray(rotations, dtype=F64)
    if rot.shape != (n,):
        rot = np.broadcast_to(rot, (n,))
    if n and not np.isfinite(rot).all():
        i = int(np.flatnonzero(~np.isfinite(rot))[0])
        raise InvalidValue(f"rotations[{i}] must be finite, got {rot[i]!r}")
    # One template per distinct shape object: batches usually share a few shapes.
    ids = [id(s) for s in shapes]
    uniq = {i: s for i, s in zip(ids, shapes, strict=True)}
    slot = {i: j for j, i in enumerate(uniq)}
    temps = [_template(s) for s in uniq.values()]
    k = max((len(t[0]) for t in temps), default=4)
    table = np.empty((len(temps), k, 2), dtype=F64)
    tcount = np.empty(len(temps), dtype=np.intp)
    turns = np.empty(len(temps), dtype=bool)
    for j, (pts, turn) in enumerate(temps):
        table[j, : len(pts)] = pts
        table[j, len(pts):] = pts[-1]
        tcount[j] = len(pts)
        turns[j] = turn
    idx = np.fromiter(map(slot.__getitem__, ids), dtype=np.intp, count=n)
    verts = table[idx]
    counts = tcount[idx]
    rows = np.flatnonzero(turns[idx] & (rot != 0.0))
    if rows.size:
        # math.cos / math.sin, as the scalar code, so the outlines agree bit for bit.
        r = rot[rows].tolist()
        c = np.fromiter(map(math.cos, r), dtype=F64, count=len(r))[:, None]
        s = np.fromiter(map(math.sin, r), dtype=F64, count=len(r))[:, None]
        x, y = verts[rows, :, 0], verts[rows, :, 1]
        verts[rows, :, 0] = c * x - s * y
        verts[rows, :, 1] = s * x + c * y
    return verts, counts


# The shape-pair table as columns indexed by pair code: kernel family, flipped (the circle is A).
_PAIR_FAMILY = np.array([rule.family for rule in PAIRS.values()], dtype=np.int64)
_PAIR_FLIP = np.array([rule.flip for rule in PAIRS.values()])


def collide_many(
    shapes_a: Sequence[Shape], transforms_a: Sequence[object],
    shapes_b: Sequence[Shape], transforms_b: Sequence[object],
) -> ContactArrays:
    """``collide(shapes_a[i], transforms_a[i], shapes_b[i], transforms_b[i])`` for every ``i``, as
    arrays in input order. Transforms are :class:`~framework.components.Transform` or
    ``(x, y[, rotation])``; everything is validated as ``collide`` validates it."""
    n = len(shapes_a)
    if not (len(transforms_a) == len(shapes_b) == len(transforms_b) == n):
        raise InvalidValue(
            f"collide_many needs sequences of one length, got {n}, {len(transforms_a)}, "
            f"{len(shapes_b)} and {len(transforms_b)}"
        )
    sa = [check_shape(f"shapes_a[{i}]", s) for i, s in enumerate(shapes_a)]
    sb = [check_shape(f"shapes_b[{i}]", s) for i, s in enumerate(shapes_b)]
    pa = np.array([pose(f"transforms_a[{i}]", t) for i, t in enumerate(transforms_a)], dtype=F64)
    pb = np.array([pose(f"transforms_b[{i}]", t) for i, t in enumerate(transforms_b)], dtype=F64)
    out = no_contacts(n)
    if n == 0:
        return out
    code = pair_code(np.array([kind_of(s) for s in sa]), np.array([kind_of(s) for s in sb]))
    family, flip = _PAIR_FAMILY[code], _PAIR_FLIP[code]
    ra = np.array([s.bounding_radius for s in sa])
    rb = np.array([s.bounding_radius for s in sb])

    def run(mask: NDArray[np.bool_], kernel: Callable[[NDArray[np.intp]], ContactArrays]) -> None:
        rows = np.flatnonzero(mask)
        if rows.size:
            res = kernel(rows)
            for dst, src in zip(out, res, strict=True):
                dst[rows] = src

    def radius(shapes: list[Shape], rows: NDArray[np.intp]) -> NDArray[np.float64]:
        return np.array([shapes[i].radius for i in rows])

    def half(shapes: list[Shape], rows: NDArray[np.intp], attr: str) -> NDArray[np.float64]:
        return np.array([getattr(shapes[i], attr) * 0.5 for i in rows])

    def shape_outlines(
        shapes: list[Shape], rot: NDArray[np.float64], rows: NDArray[np.intp],
    ) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
        # (the pair table sends only boxes, polygons and segments here)
        return outlines(cast("list[AABB | Polygon | Segment]", [shapes[i] for i in rows]), rot[rows])

    run(family == CIRCLES, lambda r: circle_circle(
        pa[r, 0], pa[r, 1], radius(sa, r), pb[r, 0], pb[r, 1], radius(sb, r)))
    run(family == BOXES, lambda r: aabb_aabb(
        pa[r, 0], pa[r, 1], half(sa, r, "width"), half(sa, r, "height"),
        pb[r, 0], pb[r, 1], half(sb, r, "width"), half(sb, r, "height")))
    run((family == POLYGON_CIRCLE) & ~flip, lambda r: polygon_circle(
        pa[r, 0], pa[r, 1], *shape_outlines(sa, pa[:, 2], r),
        pb[r, 0], pb[r, 1], radius(sb, r), size=ra[r] + rb[r]))
    run((family == POLYGON_CIRCLE) & flip, lambda r: polygon_circle(
        pb[r, 0], pb[r, 1], *shape_outlines(sb, pb[:, 2], r),
        pa[r, 0], pa[r, 1], radius(sa, r), flip=True, size=ra[r] + rb[r]))
    caps = np.flatnonzero(family == CAPSULES)
    if caps.size:
        # The capsule first: the caller's B where the pair rule flips it, and of two capsules the
        # one placed first (as collide orders them).
        swap = flip[caps].copy()
        for j, i in enumerate(caps.tolist()):
            if not swap[j] and isinstance(sb[i], Capsule):
                # (not flipped: A is a capsule too; the poses are rows of three)
                swap[j] = not capsule_first(sa[i], tuple(pa[i]), sb[i], tuple(pb[i]))  # type: ignore[arg-type]
        res = _capsule_rows(
            cast("list[Capsule]", [sb[i] if w else sa[i] for i, w in zip(caps.tolist(), swap.tolist(), strict=True)]),
            np.where(swap[:, None], pb[caps], pa[caps]),
            [sa[i] if w else sb[i] for i, w in zip(caps.tolist(), swap.tolist(), strict=True)],
            np.where(swap[:, None], pa[caps], pb[caps]), swap)
        for dst, src in zip(out, res, strict=True):
            dst[caps] = src
    run(family == POLYGONS, lambda r: polygon_polygon(
        pa[r, 0], pa[r, 1], *shape_outlines(sa, pa[:, 2], r),
        pb[r, 0], pb[r, 1], *shape_outlines(sb, pb[:, 2], r), size=ra[r] + rb[r]))
    for i in np.flatnonzero(out.hit).tolist():
        if isinstance(sa[i], ChainSegment) or isinstance(sb[i], ChainSegment):
            # What the chain's rules keep of it: collide's answer (worked with the segment first).
            c = collide(sa[i], tuple(pa[i]), sb[i], tuple(pb[i]))
            if c is None:
                out.hit[i] = False
                out.nx[i] = out.ny[i] = out.depth[i] = out.px[i] = out.py[i] = 0.0
            else:
                out.nx[i], out.ny[i], out.depth[i], out.px[i], out.py[i] = *c.normal, c.depth, *c.point
    return out


def core_rows(
    shapes: Sequence[Shape], rotations: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.float64]]:
    """The cores of shapes for :func:`capsule_many`, rotated, about their hitbox origins:
    ``(verts [N, K, 2], counts [N], radii [N])`` (a circle: its centre; a capsule: its ends ``-u``,
    ``+u``; a box or polygon: its outline, a segment: its two ends, radius 0)."""
    n = len(shapes)
    rot = np.broadcast_to(np.asarray(rotations, dtype=F64), (n,))
    outl = [i for i, s in enumerate(shapes) if isinstance(s, (AABB, Polygon, Segment))]
    caps = [i for i, s in enumerate(shapes) if isinstance(s, Capsule)]
    outlined = cast("list[AABB | Polygon | Segment]", [shapes[i] for i in outl])
    verts_o, count_o = outlines(outlined, rot[outl]) if outl else (np.zeros((0, 2, 2)), None)
    k = max(2, verts_o.shape[1])
    verts = np.zeros((n, k, 2))
    counts = np.ones(n, dtype=np.int64)
    radii = np.zeros(n)
    if outl:
        verts[outl, : verts_o.shape[1]] = verts_o
        verts[outl, verts_o.shape[1]:] = verts_o[:, -1:]
        counts[outl] = count_o  # type: ignore[assignment]  # (not None: there are outlines)
    if caps:
        # (the rows `caps` hold capsules)
        ux, uy = half_segments([shapes[i].half_length for i in caps], rot[caps])  # type: ignore[attr-defined]
        verts[caps, 0, 0], verts[caps, 0, 1] = -ux, -uy
        verts[caps, 1:, 0], verts[caps, 1:, 1] = ux[:, None], uy[:, None]
        counts[caps] = 2
    for i, s in enumerate(shapes):
        if isinstance(s, (Circle, Capsule)):
            radii[i] = s.radius
    return verts, counts, radii


def _capsule_rows(caps: list[Capsule], pc: NDArray[np.float64], others: list[Shape], po: NDArray[np.float64],
                  flip: NDArray[np.bool_]) -> ContactArrays:
    """:func:`capsule_many` of capsules ``caps`` at poses ``pc [P, 3]`` against ``others`` at ``po``."""
    ux, uy = half_segments([c.half_length for c in caps], pc[:, 2])
    verts, counts, radii = core_rows(others, po[:, 2])
    return capsule_many(pc[:, 0], pc[:, 1], ux, uy, np.array([c.radius for c in caps]),
                        np.array([c.bounding_radius for c in caps]), po[:, 0], po[:, 1], verts, counts, radii,
                        np.array([o.bounding_radius for o in others]), flip)
