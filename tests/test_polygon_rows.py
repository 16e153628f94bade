"""The compiled polygon kernel over the pipeline's rows (:mod:`framework.collision.polygon_rows`)
gives the numpy kernel's contacts bit for bit: every shape mix the polygon family holds (boxes
unturned and turned, ``Polygon.box``, convex polygons, segments), overlapping, apart, touching to
the last bit (the exact fallback it leaves to the numpy kernel), far from the origin and at
extreme scales, with and without exactness and points (the narrow phase's calls and the solve's
re-measures)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from framework import AABB, Circle, Polygon, Segment
from framework.collision import batch
from framework.collision.kinds import KIND_AABB, KIND_CIRCLE, KIND_POLYGON, KIND_SEGMENT
from framework.geometry import Geometry
from framework.systems.narrow_phase import _circle_pairs, _polygon_circle_pairs, _polygon_pairs


def _rows(shapes, poses):
    """A store and geometry holding ``shapes`` at ``poses`` (x, y, rotation), as the pipeline's."""
    n = len(shapes)
    kind = np.array([KIND_AABB if isinstance(s, AABB) else KIND_SEGMENT if isinstance(s, Segment) else
                     KIND_CIRCLE if isinstance(s, Circle) else KIND_POLYGON for s in shapes], dtype=np.int8)
    hw = np.array([s.width * 0.5 if isinstance(s, AABB) else 0.0 for s in shapes])
    hh = np.array([s.height * 0.5 if isinstance(s, AABB) else 0.0 for s in shapes])
    radius = np.array([s.radius if isinstance(s, Circle) else 0.0 for s in shapes])
    store = SimpleNamespace(kind=kind, hw=hw, hh=hh, radius=radius)
    geom = Geometry()
    outlined = np.flatnonzero((kind != KIND_AABB) & (kind != KIND_CIRCLE))
    verts, counts = batch.outlines([shapes[i] for i in outlined], np.array([poses[i][2] for i in outlined]))
    geom.K = max(4, verts.shape[1]) if outlined.size else 4
    geom.world_poly = np.zeros((outlined.size, geom.K, 2))
    geom.world_poly[:, : verts.shape[1]] = verts
    geom.world_poly[:, verts.shape[1]:] = verts[:, -1:]
    geom.poly_slot = np.full(n, -1, dtype=np.int64)
    geom.poly_slot[outlined] = np.arange(outlined.size)
    geom.count = np.zeros(n, dtype=np.int64)
    geom.count[outlined] = counts
    geom.segments = bool((kind == KIND_SEGMENT).any())
    geom.hx = np.array([p[0] for p in poses])
    geom.hy = np.array([p[1] for p in poses])
    return store, geom


def _numpy(store, geom, a, b, exact, points):
    va, na = geom.outlines(store, a)
    vb, nb = geom.outlines(store, b)
    return batch.polygon_polygon(geom.hx[a], geom.hy[a], va, na, geom.hx[b], geom.hy[b], vb, nb, exact=exact,
                                 points=points)


def _same_bits(got, want) -> None:
    assert np.array_equal(got.hit, want.hit)
    for g, w in zip(got[1:], want[1:], strict=True):
        assert np.array_equal(np.asarray(g).view(np.int64), np.asarray(w).view(np.int64)), (g, w)


def _check(shapes, poses, pairs) -> None:
    store, geom = _rows(shapes, poses)
    a = np.array([p[0] for p in pairs], dtype=np.int64)
    b = np.array([p[1] for p in pairs], dtype=np.int64)
    for exact in (True, False):
        for points in (True, False):
            if points and not exact:
                continue  # (the pipeline asks for points only with exactness)
            _same_bits(_polygon_pairs(store, geom, a, b, exact=exact, points=points),
                       _numpy(store, geom, a, b, exact, points))
            for i in range(a.size):  # a row's answer does not depend on its batch
                _same_bits(_polygon_pairs(store, geom, a[i:i + 1], b[i:i + 1], exact=exact, points=points),
                           _numpy(store, geom, a[i:i + 1], b[i:i + 1], exact, points))


_DYADIC = st.integers(-64, 64).map(lambda k: k / 16.0)
_SIZE = st.integers(1, 48).map(lambda k: k / 16.0)


@st.composite
def _shape(draw):
    which = draw(st.sampled_from(["aabb", "box", "polygon", "segment"]))
    if which == "aabb":
        return AABB(draw(_SIZE), draw(_SIZE))
    if which == "box":
        return Polygon.box(draw(_SIZE), draw(_SIZE))
    if which == "segment":
        a = (draw(_DYADIC), draw(_DYADIC))
        b = (draw(_DYADIC), draw(_DYADIC))
        return Segment(a, b) if a != b else Segment(a, (a[0] + 1.0, a[1]))
    n = draw(st.integers(3, 8))
    r = draw(_SIZE)
    start = draw(st.floats(0.0, 2.0 * math.pi))
    return Polygon([(r * math.cos(start + 2.0 * math.pi * k / n), r * math.sin(start + 2.0 * math.pi * k / n))
                    for k in range(n)])


_ROTATION = st.one_of(st.just(0.0), st.just(math.pi / 2), st.floats(-math.pi, math.pi, allow_nan=False))


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(_shape(), _DYADIC, _DYADIC, _ROTATION), min_size=2, max_size=7), st.data(),
       st.sampled_from([1.0, 2.0**40, 2.0**-600, 2.0**900]), st.sampled_from([0.0, 1e9]))
def test_random_rows_same_bits(bodies, data, scale, far) -> None:
    """Random shapes and poses (dyadic, so many pairs touch exactly or share edges), scaled by a
    power of two and moved far from the origin: the same bits as the numpy kernel."""
    shapes = [_scaled(s, scale) for s, *_ in bodies]
    poses = [(x * scale + far, y * scale, rot) for _s, x, y, rot in bodies]
    n = len(shapes)
    pairs = data.draw(st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)).filter(
        lambda p: p[0] != p[1] and not (isinstance(shapes[p[0]], AABB) and isinstance(shapes[p[1]], AABB))),
        min_size=1, max_size=12))
    _check(shapes, poses, pairs)


def _scaled(shape, k: float):
    if isinstance(shape, AABB):
        return AABB(shape.width * k, shape.height * k)
    if isinstance(shape, Segment):
        return Segment((shape.a[0] * k, shape.a[1] * k), (shape.b[0] * k, shape.b[1] * k))
    return Polygon([(x * k, y * k) for x, y in shape.points])


@pytest.mark.parametrize("dx, dy, rot", [
    (1.0, 0.0, 0.0), (0.75, 0.5, 0.0), (1.0, 1.0, 0.0), (0.5, 0.5, math.pi / 4), (0.0, 0.0, 0.0),
    (1.25, 0.0, 0.0), (0.5, 0.96875, 0.0), (0.5, 0.5, math.pi / 2),
])
def test_touching_overlapping_and_apart(dx, dy, rot) -> None:
    """A unit ``Polygon.box`` against an AABB, a turned box and a triangle: edges touching exactly
    (the exact fallback), corners touching, overlapping by dyadic depths, apart."""
    shapes = [Polygon.box(1.0, 1.0), AABB(1.0, 1.0), Polygon.box(1.0, 1.0), Polygon([(0, 0), (1, 0), (0, 1)]),
              Segment((-0.5, 0.0), (0.5, 0.0))]
    poses = [(0.0, 0.0, rot), (dx, dy, 0.0), (dx, -dy, rot), (-dx, dy, 0.0), (dy, dx, 0.0)]
    _check(shapes, poses, [(0, 1), (1, 0), (0, 2), (2, 0), (0, 3), (3, 2), (4, 0), (0, 4), (4, 3), (1, 2)])


def test_deep_and_nested() -> None:
    """One outline inside another, and two identical outlines on each other: every candidate
    ties, so the tie-break's every step decides; points are the mean of the inner outline."""
    shapes = [Polygon.box(4.0, 4.0), Polygon([(0, 0), (1, 0), (0.5, 1)]), Polygon.box(4.0, 4.0), AABB(1.0, 1.0)]
    poses = [(0.0, 0.0, 0.0), (0.25, 0.25, 0.0), (0.0, 0.0, math.pi / 2), (0.0, 0.0, 0.0)]
    _check(shapes, poses, [(0, 1), (1, 0), (0, 2), (2, 0), (0, 3), (3, 1), (2, 3)])


_FLOATS = st.one_of(_DYADIC, st.floats(-4.0, 4.0, allow_nan=False))
_HALF = st.one_of(_SIZE, st.floats(1e-3, 3.0, allow_nan=False))


@settings(max_examples=400, deadline=None)
@given(st.tuples(_FLOATS, _FLOATS, _HALF, _HALF, _FLOATS, _FLOATS, _HALF, _HALF),
       st.sampled_from([1.0, 2.0**-500, 2.0**500]), st.sampled_from([0.0, 1e9, -3e15]))
def test_centred_boxes_row_same_bits(box, scale, far) -> None:
    """Two centred boxes, the box kernel of one pair compiled (:mod:`framework.collision.box_pair_row`):
    ``aabb_aabb``'s contact bit for bit, touching (dyadic), overlapping and apart, far out and at
    extreme scales."""
    from framework.collision.batch_box import aabb_aabb
    from framework.collision.box_pair_row import aabb_exact_row

    ax, ay, ahw, ahh, bx, by, bhw, bhh = (v * scale for v in box)
    ax, bx = ax + far, bx + far
    hit, nx, ny, depth, px, py, found = aabb_exact_row(ax, ay, ahw, ahh, bx, by, bhw, bhh)
    want = aabb_aabb(ax, ay, ahw, ahh, bx, by, bhw, bhh)
    assert hit == bool(want.hit[0])
    if hit and found:
        got = np.array([nx, ny, depth, px, py])
        ref = np.array([want.nx[0], want.ny[0], want.depth[0], want.px[0], want.py[0]])
        assert np.array_equal(got.view(np.int64), ref.view(np.int64)), (got, ref)


# (hypothesis's favourite floats, 5e-324 and such, only make the float decision decline: UNSURE)
_OFFSET = st.one_of(st.just(0.0), st.floats(-8.0, 8.0).filter(lambda v: abs(v) > 1e-6))


@st.composite
def _touching_pair(draw):
    """A random convex outline A (turned: coordinates far from dyadic) and an outline B sharing one
    of A's edges reversed, with a third vertex outside it: they touch exactly along that edge. B's
    origin and A's are random; B's offset is nudged by 0 to 2 ulps either way."""
    n = draw(st.integers(3, 7))
    r = draw(st.floats(0.25, 4.0))
    turn = draw(st.floats(0.0, 2.0 * math.pi))
    a = [(r * math.cos(turn + 2.0 * math.pi * i / n), r * math.sin(turn + 2.0 * math.pi * i / n)) for i in range(n)]
    i = draw(st.integers(0, n - 1))
    (x0, y0), (x1, y1) = a[i], a[(i + 1) % n]
    out = draw(st.floats(0.125, 2.0))
    mx, my = 0.5 * (x0 + x1) + out * (y1 - y0), 0.5 * (y0 + y1) - out * (x1 - x0)
    ox, oy = draw(_OFFSET), draw(_OFFSET)
    qx, qy = draw(_OFFSET), draw(_OFFSET)
    # B about its own origin q, so that its world points are A's edge (world: o + a) and the apex.
    b = [(x1 + ox - qx, y1 + oy - qy), (x0 + ox - qx, y0 + oy - qy), (mx + ox - qx, my + oy - qy)]
    nudge = draw(st.integers(-2, 2))
    qx = float(np.nextafter(qx, math.copysign(math.inf, nudge))) if nudge else qx
    return a, b, (ox, oy, qx, qy)


@settings(max_examples=400, deadline=None)
@given(_touching_pair(), st.sampled_from([0, 1, -3]))
def test_exact_apart_decision_matches_the_integers(pair, k) -> None:
    """:func:`framework.collision.exact_sign.polygons_apart` (floats, expansions) decides as
    :func:`framework.collision.exact.polygon_polygon_exact` (integers) on outlines touching along
    an edge to the last bit, and nudged an ulp either way; where they overlap,
    :func:`~framework.collision.exact_sign.polygon_depths` rounds the integers' overlaps bit for
    bit."""
    from framework.collision.exact import float_rounded, polygon_polygon_exact
    from framework.collision.exact_sign import APART, OVERLAP, SCRATCH, UNSURE, polygon_depths, polygons_apart

    a, b, (ox, oy, qx, qy) = pair
    kk = 8
    avx, avy = (np.array([p[j] for p in a] + [a[-1][j]] * (kk - len(a))) for j in (0, 1))
    bvx, bvy = (np.array([p[j] for p in b] + [b[-1][j]] * (kk - len(b))) for j in (0, 1))
    need = np.full(2 * kk, 3, dtype=np.int64)
    got = polygons_apart(avx, avy, len(a), bvx, bvy, 3, ox, oy, qx, qy, k, need, np.empty(SCRATCH))
    want = polygon_polygon_exact(a, b, (ox, oy, qx, qy, k))
    values = [abs(v) for v in (*avx, *avy, *bvx, *bvy, ox, oy, qx, qy, qx - ox, qy - oy) if v != 0.0]
    if got == UNSURE:  # (only with a coordinate beyond the range where products are exact)
        assert min(values) < 2.0**-300 or max(values) > 2.0**300
        return
    assert got == (APART if want is None else OVERLAP)
    if want is None:
        return
    # Overlapping: every axis's exact overlaps, rounded, are the integers' (batch_polygon's order:
    # A's real edges, then B's, padding slots skipped).
    found, u = want
    fwd, bwd = np.full(2 * kk, np.nan), np.full(2 * kk, np.nan)
    assert polygon_depths(avx, avy, len(a), bvx, bvy, 3, ox, oy, qx, qy, k, fwd, bwd, np.empty(SCRATCH))
    valid = ~np.isnan(fwd)
    expect = np.array([(float_rounded(fw, u), float_rounded(bw, u)) for fw, bw in found.values()])
    assert valid.sum() == len(found)
    assert np.array_equal(fwd[valid].view(np.int64), expect[:, 0].view(np.int64))
    assert np.array_equal(bwd[valid].view(np.int64), expect[:, 1].view(np.int64))


def _check_circles(shapes, poses, pairs) -> None:
    """Polygon rows against circle rows, either way round: the compiled pass's bits are the numpy
    kernel's, in a batch and one row at a time."""
    store, geom = _rows(shapes, poses)
    poly = np.array([p[0] for p in pairs], dtype=np.int64)
    circ = np.array([p[1] for p in pairs], dtype=np.int64)
    flip = np.array([p[2] for p in pairs], dtype=bool)

    def numpy(rows):
        vp, np_ = geom.outlines(store, poly[rows])
        return batch.polygon_circle(geom.hx[poly[rows]], geom.hy[poly[rows]], vp, np_, geom.hx[circ[rows]],
                                    geom.hy[circ[rows]], store.radius[circ[rows]], flip=flip[rows], exact=exact)

    for exact in (True, False):
        every = np.arange(poly.size)
        _same_bits(_polygon_circle_pairs(store, geom, poly, circ, flip, exact=exact), numpy(every))
        for i in range(poly.size):
            one = every[i:i + 1]
            _same_bits(_polygon_circle_pairs(store, geom, poly[one], circ[one], flip[one], exact=exact), numpy(one))


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(_shape(), _DYADIC, _DYADIC, _ROTATION), min_size=1, max_size=5),
       st.lists(st.tuples(_SIZE, _DYADIC, _DYADIC), min_size=1, max_size=5), st.data(),
       st.sampled_from([1.0, 2.0**40, 2.0**-600]), st.sampled_from([0.0, 1e9]))
def test_random_circle_rows_same_bits(bodies, balls, data, scale, far) -> None:
    """Random polygons, boxes and segments against random circles (dyadic: many touch exactly,
    centres on faces and vertices), scaled and moved far out: the numpy kernel's bits."""
    shapes = [_scaled(s, scale) for s, *_ in bodies] + [Circle(r * scale) for r, _x, _y in balls]
    poses = [(x * scale + far, y * scale, rot) for _s, x, y, rot in bodies] + [
        (x * scale + far, y * scale, 0.0) for _r, x, y in balls]
    pairs = data.draw(st.lists(st.tuples(st.integers(0, len(bodies) - 1),
                                         st.integers(len(bodies), len(shapes) - 1), st.booleans()),
                               min_size=1, max_size=10))
    _check_circles(shapes, poses, pairs)


def test_circle_rows_inside_on_faces_and_corners() -> None:
    """A circle whose centre is inside a box (out through the nearest face; the middle: every
    face ties), on a face, at a corner, touching a face and a corner, and a segment's ends."""
    shapes = [Polygon.box(2.0, 2.0), AABB(2.0, 1.0), Segment((-1.0, 0.0), (1.0, 0.0)), Circle(0.5), Circle(0.5),
              Circle(0.5), Circle(0.5), Circle(0.25)]
    poses = [(0.0, 0.0, 0.0), (4.0, 0.0, 0.0), (0.0, 4.0, 0.0), (0.0, 0.0, 0.0), (0.25, 1.0, 0.0), (1.0, 1.0, 0.0),
             (0.0, 1.5, 0.0), (1.25, 4.0, 0.0)]
    pairs = [(p, c, f) for p in (0, 1, 2) for c in (3, 4, 5, 6, 7) for f in (False, True)]
    _check_circles(shapes, poses, pairs)


@st.composite
def _circle_on_outline(draw):
    """A turned outline (coordinates far from dyadic; a segment sometimes) and a circle whose
    centre is put at a distance r from a face, a vertex, or inside, its offset nudged by 0 to 2
    ulps: touching to the last bit, or just apart or overlapping."""
    n = draw(st.sampled_from([2, 3, 4, 5, 6]))
    rad = draw(st.floats(0.25, 4.0))
    turn = draw(st.floats(0.0, 2.0 * math.pi))
    pts = [(rad * math.cos(turn + 2.0 * math.pi * i / max(n, 3)), rad * math.sin(turn + 2.0 * math.pi * i / max(n, 3)))
           for i in range(n)]
    r = draw(st.floats(0.0625, 2.0))
    i = draw(st.integers(0, n - 1))
    (x0, y0), (x1, y1) = pts[i], pts[(i + 1) % n]
    where = draw(st.sampled_from(["face", "vertex", "inside"]))
    if where == "face":
        ln = math.hypot(x1 - x0, y1 - y0)
        u = draw(st.floats(0.0, 1.0))
        cx = x0 + u * (x1 - x0) + r * (y1 - y0) / ln
        cy = y0 + u * (y1 - y0) - r * (x1 - x0) / ln
    elif where == "vertex":
        a = draw(st.floats(0.0, 2.0 * math.pi))
        cx, cy = x0 + r * math.cos(a), y0 + r * math.sin(a)
    else:
        cx, cy = 0.25 * x0, 0.25 * y0
    ox, oy = draw(_OFFSET), draw(_OFFSET)
    qx, qy = ox + cx, oy + cy
    nudge = draw(st.integers(-2, 2))
    for _ in range(abs(nudge)):
        qy = float(np.nextafter(qy, math.copysign(math.inf, nudge)))
    return pts, r, (ox, oy, qx, qy)


@settings(max_examples=500, deadline=None)
@given(_circle_on_outline(), st.sampled_from([1.0, -1.0]))
def test_exact_polygon_circle_contact_matches_the_integers(case, f) -> None:
    """:func:`framework.collision.exact_sign.polygon_circle_contact` (floats, expansions) gives
    :func:`framework.collision.batch_circle._polygon_circle_exact`'s answer (integers) bit for bit:
    circles touching faces and vertices to the last bit, nudged an ulp either way, and inside."""
    from framework.collision.batch_circle import _polygon_circle_exact
    from framework.collision.exact_sign import APART, OVERLAP, SCRATCH_CIRCLE, UNSURE, polygon_circle_contact

    pts, r, (ox, oy, qx, qy) = case
    kk = 8
    vx, vy = (np.array([p[j] for p in pts] + [pts[-1][j]] * (kk - len(pts))) for j in (0, 1))
    cx, cy, size = qx - ox, qy - oy, 2.0
    verdict, *got = polygon_circle_contact(vx, vy, len(pts), ox, oy, qx, qy, 0, r, cx, cy, size, f,
                                           np.empty(SCRATCH_CIRCLE))
    want = _polygon_circle_exact(pts, (ox, oy, qx, qy, 0), r, cx, cy, size, f)
    values = [abs(v) for v in (*vx, *vy, r, ox, oy, qx, qy, qx - ox, qy - oy) if v != 0.0]
    if verdict == UNSURE:
        assert min(values) < 2.0**-200 or max(values) > 2.0**200
        return
    assert verdict == (APART if want is None else OVERLAP)
    if want is not None:
        assert np.array_equal(np.array(got).view(np.int64), np.array(want).view(np.int64)), (got, want)


@settings(max_examples=500, deadline=None)
@given(st.floats(0.5, 4.0), st.integers(-3, 3), st.sampled_from([0.0, 1.0, -1.0]), st.integers(-60, -1),
       st.booleans())
def test_expansions_round_to_nearest_ties_to_even(base, sign_half, nudge, tiny, negative) -> None:
    """The exact sum of an expansion rounded as Python rounds an exact fraction (and as
    ``math.fsum``): a double plus a multiple of half its spacing (ties, either way round to even),
    nudged by a tiny amount."""
    from fractions import Fraction

    from framework.collision.exact_sign import exact_sum

    hi = -base if negative else base
    gap = math.ulp(hi)
    parts = [hi, sign_half * gap * 0.5, nudge * gap * 2.0**tiny]
    got = exact_sum(np.array(parts))
    want = float(sum((Fraction(p) for p in parts), Fraction(0)))
    assert want == math.fsum(parts)
    assert got == want and math.copysign(1.0, got) == math.copysign(1.0, want)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.floats(-2.0**60, 2.0**60).filter(lambda v: v == 0.0 or abs(v) > 2.0**-500), min_size=1,
                max_size=12))
def test_exact_sum_is_fsum(parts) -> None:
    """Random doubles of many magnitudes (cancelling, too): the expansions' exact sum, rounded,
    is ``math.fsum``'s."""
    from framework.collision.exact_sign import exact_sum

    got, want = exact_sum(np.array(parts)), math.fsum(parts)
    assert got == want or (want == 0.0 and got == 0.0) or (abs(want) < 2.0**-900 and math.isnan(got))


def _check_circle_pairs(radii, centres, pairs) -> None:
    """Circle rows against circle rows: the compiled pass's bits are the numpy kernel's, in a
    batch and one row at a time, with and without exactness."""
    store = SimpleNamespace(radius=np.array(radii, dtype=float))
    geom = SimpleNamespace(hx=np.array([c[0] for c in centres]), hy=np.array([c[1] for c in centres]))
    a = np.array([p[0] for p in pairs], dtype=np.int64)
    b = np.array([p[1] for p in pairs], dtype=np.int64)

    def numpy(rows, exact):
        ra, rb = a[rows], b[rows]
        return batch.circle_circle(geom.hx[ra], geom.hy[ra], store.radius[ra], geom.hx[rb], geom.hy[rb],
                                   store.radius[rb], exact=exact)

    for exact in (True, False):
        every = np.arange(a.size)
        _same_bits(_circle_pairs(store, geom, a, b, exact=exact), numpy(every, exact))
        for i in range(a.size):
            one = every[i:i + 1]
            _same_bits(_circle_pairs(store, geom, a[one], b[one], exact=exact), numpy(one, exact))


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(_SIZE, _DYADIC, _DYADIC), min_size=2, max_size=8), st.data(),
       st.sampled_from([1.0, 2.0**40, 2.0**-600]), st.sampled_from([0.0, 1e9]))
def test_random_circle_pairs_same_bits(balls, data, scale, far) -> None:
    """Random circles at dyadic places (many touching exactly, some concentric), scaled and moved
    far out: the numpy kernel's bits, its exact fallback's included."""
    radii = [r * scale for r, _x, _y in balls]
    centres = [(x * scale + far, y * scale) for _r, x, y in balls]
    n = len(balls)
    pairs = data.draw(st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)).filter(lambda p: p[0] != p[1]),
                               min_size=1, max_size=12))
    _check_circle_pairs(radii, centres, pairs)


@settings(max_examples=300, deadline=None)
@given(st.floats(0.25, 2.0), st.floats(0.25, 2.0), st.floats(0.0, 2.0 * math.pi), _OFFSET, _OFFSET,
       st.integers(-2, 2))
def test_circles_touching_to_the_last_bit_same_bits(r1, r2, angle, ox, oy, nudge) -> None:
    """Two circles placed at the sum of their radii along a random direction (touching to rounding),
    nudged by up to two ulps: the exact excess on floats is the integers' (the numpy kernel's)."""
    qx, qy = ox + (r1 + r2) * math.cos(angle), oy + (r1 + r2) * math.sin(angle)
    for _ in range(abs(nudge)):
        qx = float(np.nextafter(qx, math.copysign(math.inf, nudge)))
    _check_circle_pairs([r1, r2], [(ox, oy), (qx, qy)], [(0, 1), (1, 0)])


_ANY_SHAPE = st.one_of(_shape(), _SIZE.map(Circle))


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(_ANY_SHAPE, _DYADIC, _DYADIC, _ROTATION), min_size=2, max_size=8), st.data(),
       st.sampled_from([1.0, 2.0**40, 2.0**-600, 2.0**900]), st.sampled_from([0.0, 1e9]))
def test_every_family_measured_at_once_as_family_by_family(bodies, data, scale, far) -> None:
    """The solve's re-measures in one compiled call (``measure_rows``: boxes, polygons, segments and
    circles in any mix, each family's own kernel) give the family-by-family path's contacts bit for
    bit, rows the kernels leave to their numpy variants (extreme scales) answered as it answers
    them; a pair of another shape (a capsule) or a row without a hitbox is left to that path."""
    from framework.collision.kinds import KIND_CAPSULE
    from framework.systems import narrow_phase
    from framework.systems.narrow_phase import _by_families, _measured_at_once

    shapes = [s if isinstance(s, Circle) else _scaled(s, scale) for s, *_ in bodies]
    shapes = [Circle(s.radius * scale) if isinstance(s, Circle) else s for s in shapes]
    poses = [(x * scale + far, y * scale, rot) for _s, x, y, rot in bodies]
    store, geom = _rows(shapes, poses)
    store.kinds_present = lambda: frozenset(int(k) for k in store.kind if k >= 0)  # (as BodyStore's)
    store.cols = {"hw": store.hw, "hh": store.hh}
    n = len(shapes)
    pairs = data.draw(st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)).filter(lambda p: p[0] != p[1]),
                               min_size=1, max_size=16))
    a = np.array([p[0] for p in pairs], dtype=np.int64)
    b = np.array([p[1] for p in pairs], dtype=np.int64)
    want = _by_families(store, geom, a, b, None, True)
    _same_bits(_measured_at_once(store, geom, a, b), want)
    # rows left to the families' variants (the kernels' defer and pending: inputs beyond what the
    # re-measure's floats settle, too rare to draw) are answered by them, whatever the kernel wrote
    real = narrow_phase.measure_rows

    def leaving(*args):
        floats, flags, ok = real(*args)
        flags[1, ::2] = True
        floats[:, ::2] = np.nan
        flags[0, ::2] = ~flags[0, ::2]
        return floats, flags, ok

    narrow_phase.measure_rows = leaving
    try:
        _same_bits(_measured_at_once(store, geom, a, b), want)
    finally:
        narrow_phase.measure_rows = real
    for other in (KIND_CAPSULE, -1):  # (a capsule's pairs, a row without a hitbox: the families' path)
        kind = store.kind.copy()
        store.kind[a[0]] = other
        assert _measured_at_once(store, geom, a, b) is None
        store.kind = kind
