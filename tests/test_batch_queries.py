"""The batch scene queries (issue 38, part 3): ``query_points``, ``nearest_many`` and ``raycast_many``
answer many points or rays in one compiled pass. Held to the single queries asked one by one (the
same entities and the same floats, bit for bit), to brute force over every hitbox with the
collision functions, and to hand-made dyadic cases with exact answers."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from framework import AABB, Capsule, Chain, Circle, Hitbox, Polygon, Scene, Segment, Transform
from framework.collision import raycast
from framework.collision.batch_queries import hypot
from framework.collision.distance import point_distance
from framework.tiles import terrain_pieces

HEXAGON = Polygon([(math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)) for k in range(6)])
TRIANGLE = Polygon([(-1.0, -0.5), (1.0, -0.5), (0.0, 1.0)])
# (segments and chain segments too: a batch once took a segment for a polygon of no points)
CHAIN = Chain([(-2.0, 0.0), (-1.0, 0.5), (0.0, 0.0), (1.0, -0.5)])
SHAPES = [AABB(1.0, 2.0), AABB(0.5, 0.5), Circle(0.75), Circle(0.25), Capsule(0.25, 1.5), Capsule(0.5, 0.5),
          HEXAGON, TRIANGLE, Polygon.box(2.0, 0.5), Segment((-1.0, -0.5), (1.0, 0.75)),
          Segment((0.0, -1.0), (0.0, 1.0)), CHAIN.segments[1], CHAIN.segments[2]]


# --- helpers ------------------------------------------------------------------------------------


def _hit_tuple(h):
    return None if h is None else (h.entity, h.distance, tuple(h.point), tuple(h.normal))


def _batch_ray(hits, i):
    if hits.entity[i] < 0:
        return None
    return (int(hits.entity[i]), float(hits.distance[i]), tuple(hits.point[i].tolist()),
            tuple(hits.normal[i].tolist()))


def _near_tuple(n):
    return None if n is None else (n.entity, n.distance, tuple(n.point))


def _batch_near(res, i):
    if res.entity[i] < 0:
        return None
    return int(res.entity[i]), float(res.distance[i]), tuple(res.point[i].tolist())


def _brute_ray(placed, origin, direction, max_distance=math.inf, mask=0xFFFFFFFF):
    """The first hitbox entered, by a naive loop over every hitbox (collision.raycast each)."""
    hits = []
    for e, (shape, pose, layer) in placed.items():
        if layer & mask:
            h = raycast(shape, pose, origin, direction, max_distance)
            if h is not None:
                hits.append((h.distance, e, tuple(h.point), tuple(h.normal)))
    if not hits:
        return None
    d, e, p, n = min(hits, key=lambda h: (h[0], h[1]))
    return e, d, p, n


def _brute_nearest(placed, point, max_distance=math.inf, mask=0xFFFFFFFF):
    best = None
    for e, (shape, pose, layer) in placed.items():
        if layer & mask:
            d, at = point_distance(shape, *pose, *point)
            if d <= max_distance and (best is None or (d, e) < (best[1], best[0])):
                best = (e, d, tuple(at))
    return best


def _spawn(s, items):
    """items: (shape, x, y, rot, layer, body); entity -> (shape, pose, layer)."""
    placed = {}
    for shape, x, y, rot, layer, body in items:
        body = "static" if isinstance(shape, Segment) else body  # (a segment has no area: never dynamic)
        e = s.spawn(Transform(x, y, rot), Hitbox(shape, layer=layer, body=body))
        placed[e] = (shape, (x, y, rot), layer)
    return placed


# --- random scenes against the single queries and brute force ------------------------------------

COORD = st.integers(-48, 48).map(lambda k: k / 8)
FCOORD = st.floats(-6.0, 6.0, allow_nan=False)
ANGLE = st.one_of(st.just(0.0), st.integers(0, 31).map(lambda k: k * math.pi / 16), st.floats(0.0, 6.3))
BODY = st.tuples(st.sampled_from(SHAPES), st.one_of(COORD, FCOORD), st.one_of(COORD, FCOORD), ANGLE,
                 st.sampled_from([1, 2]), st.sampled_from(["dynamic", "static"]))
POINT = st.tuples(st.one_of(COORD, FCOORD), st.one_of(COORD, FCOORD))
DIRECTION = st.one_of(
    st.sampled_from([(1.0, 0.0), (0.0, -1.0), (-2.0, 0.0), (1.0, 1.0), (-0.5, 0.25), (0.0, 3.0)]),
    st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)).filter(lambda d: d != (0.0, 0.0)),
)


@settings(max_examples=120, deadline=None)
@given(st.lists(BODY, max_size=14), st.lists(POINT, min_size=1, max_size=24), st.sampled_from([1, 2, 3]),
       st.sampled_from([math.inf, 0.0, 0.5, 3.0]))
def test_points_and_nearest_equal_the_single_queries_and_brute_force(bodies, points, mask, max_distance):
    with Scene() as s:
        placed = _spawn(s, bodies)
        inside = s.query_points(points, mask=mask)
        near = s.nearest_many(points, max_distance=max_distance, mask=mask)
        assert inside.offsets.shape == (len(points) + 1,) and inside.offsets[0] == 0
        assert np.isfinite(near.distance).all() and np.isfinite(near.point).all()  # (never inf, never NaN)
        for i, p in enumerate(points):
            single = s.query_point(*p, mask=mask)
            assert inside.of(i) == single
            assert _batch_near(near, i) == _near_tuple(s.nearest(p, max_distance=max_distance, mask=mask))
            assert _batch_near(near, i) == _brute_nearest(placed, p, max_distance, mask)
            # brute force on containment: every hitbox strictly holding the point is listed, and
            # every one listed is within rounding of it
            for e, (shape, pose, layer) in placed.items():
                d = point_distance(shape, *pose, *p)[0]
                if e in single:
                    assert layer & mask and d <= 1e-9
                elif layer & mask:
                    assert d > 0.0 or _on_boundary(shape, pose, p)


def _on_boundary(shape, pose, p):
    """Whether p is within rounding of the hitbox's boundary (where float containment may say
    either): a step of 1e-9 outward leaves it, inward enters it."""
    return point_distance(shape, *pose, p[0] + 1e-9, p[1])[0] > 0.0 or \
        point_distance(shape, *pose, p[0] - 1e-9, p[1])[0] > 0.0 or \
        point_distance(shape, *pose, p[0], p[1] + 1e-9)[0] > 0.0 or \
        point_distance(shape, *pose, p[0], p[1] - 1e-9)[0] > 0.0


@settings(max_examples=150, deadline=None)
@given(st.lists(BODY, max_size=14), st.lists(st.tuples(POINT, DIRECTION), min_size=1, max_size=16),
       st.sampled_from([1, 2, 3]), st.sampled_from([math.inf, 0.0, 1.0, 4.0]))
def test_rays_equal_the_single_queries_and_brute_force(bodies, rays, mask, max_distance):
    with Scene() as s:
        placed = _spawn(s, bodies)
        origins = [o for o, _ in rays]
        directions = [d for _, d in rays]
        hits = s.raycast_many(origins, directions, max_distance=max_distance, mask=mask)
        assert all(np.isfinite(a).all() for a in (hits.distance, hits.point, hits.normal))  # (never inf or NaN)
        for i, (o, d) in enumerate(rays):
            got = _batch_ray(hits, i)
            assert got == _hit_tuple(s.raycast(o, d, max_distance=max_distance, mask=mask))
            assert got == _brute_ray(placed, o, d, max_distance, mask)


@settings(max_examples=40, deadline=None)
@given(st.lists(BODY, min_size=1, max_size=10), st.lists(st.tuples(POINT, DIRECTION), min_size=1, max_size=10),
       st.sampled_from([1e9, -3e7, 2.0**40]))
def test_far_from_the_origin_the_same_as_one_by_one(bodies, rays, shift):
    """A scene placed at x = 1e9: the batch gives the single queries' answers there too."""
    with Scene() as s:
        _spawn(s, [(sh, x + shift, y - shift, r, la, b) for sh, x, y, r, la, b in bodies])
        origins = [(o[0] + shift, o[1] - shift) for o, _ in rays]
        directions = [d for _, d in rays]
        hits = s.raycast_many(origins, directions)
        near = s.nearest_many(origins)
        inside = s.query_points(origins)
        for i, o in enumerate(origins):
            assert _batch_ray(hits, i) == _hit_tuple(s.raycast(o, directions[i]))
            assert _batch_near(near, i) == _near_tuple(s.nearest(o))
            assert inside.of(i) == s.query_point(*o)


def test_offset_hitboxes_tiles_and_many_points_at_once():
    """Offsets (hitbox origins off the transform), terrain tiles with slopes, 3,000 points and rays
    in one call: equal to the single queries one by one."""
    rng = np.random.default_rng(7)
    cells = [["solid", None, "slope_up", "solid", "slope_down", None, "slope_up_low", "slope_up_high", "solid"],
             ["solid", "solid", "solid", "solid", "solid", "step", "solid", "solid", "solid"]]
    with Scene() as s:
        for piece in terrain_pieces(cells, 2.0, origin=(-9.0, -6.0)):
            s.spawn(Transform(piece.x, piece.y), Hitbox(piece.shape, body="static"))
        for k in range(40):
            shape = SHAPES[k % len(SHAPES)]
            s.spawn(Transform(*rng.uniform(-9, 9, 2), float(rng.uniform(0, 6))),
                    Hitbox(shape, offset=tuple(rng.uniform(-1, 1, 2)), layer=1 + k % 3,
                           body="kinematic" if isinstance(shape, Segment) else "dynamic"))
        s.step(1 / 60)
        pts = rng.uniform(-10, 10, (3000, 2))
        dirs = rng.normal(size=(3000, 2))
        inside = s.query_points(pts)
        near = s.nearest_many(pts, mask=2)
        hits = s.raycast_many(pts, dirs, max_distance=6.0)
        assert inside.counts.sum() > 100 and (hits.entity >= 0).sum() > 1000
        for i in range(0, 3000, 7):
            p, d = tuple(pts[i]), tuple(dirs[i])
            assert inside.of(i) == s.query_point(*p)
            assert _batch_near(near, i) == _near_tuple(s.nearest(p, mask=2))
            assert _batch_ray(hits, i) == _hit_tuple(s.raycast(p, d, max_distance=6.0))


# --- hand-made dyadic cases -------------------------------------------------------------------


def _box_field(s):
    """A 2 x 2 box at the origin, a unit circle at (4, 0) on layer 2, a 2 x 2 box touching the first
    at x = 1 (centre (2, 0)) and a capsule lying along y = 4."""
    a = s.spawn(Transform(0.0, 0.0), Hitbox(AABB(2.0, 2.0), body="static"))
    c = s.spawn(Transform(4.0, 0.0), Hitbox(Circle(1.0), layer=2))
    b = s.spawn(Transform(2.0, 0.0), Hitbox(AABB(2.0, 2.0)))
    k = s.spawn(Transform(0.0, 4.0, math.pi / 2), Hitbox(Capsule(0.5, 2.0)))
    return a, c, b, k


def test_points_on_boundaries_count_and_are_sorted():
    with Scene() as s:
        a, c, b, k = _box_field(s)
        pts = [(1.0, 0.0), (-1.0, 1.0), (5.0, 0.0), (4.0, 0.0), (1.5, 1.0), (0.0, 4.5), (1.5, 4.0), (9.0, 9.0),
               (3.0, 0.0)]
        hits = s.query_points(pts)
        assert [hits.of(i) for i in range(len(pts))] == [
            sorted([a, b]),  # on the seam of the two boxes: both
            [a],  # a corner
            [c],  # on the circle
            [c],
            [b],  # on b's top edge
            [k],  # on the capsule's side (it lies along y = 4 from x = -1 to 1, radius 0.5)
            [k],  # the tip of its right cap
            [],
            sorted([b, c]),  # b's right edge touches the circle's leftmost point
        ]
        assert hits.offsets.tolist() == [0, 2, 3, 4, 5, 6, 7, 8, 8, 10]
        only2 = s.query_points(pts, mask=2)
        assert only2.entities.tolist() == [c, c, c] and only2.counts.tolist() == [0, 0, 1, 1, 0, 0, 0, 0, 1]


def test_rays_graze_hit_at_max_distance_and_start_inside():
    with Scene() as s:
        a, c, b, k = _box_field(s)
        rays = [
            ((-5.0, 1.0), (1.0, 0.0)),  # along the boxes' top edges: a graze, then the circle's tangent
            ((-5.0, 0.0), (2.0, 0.0)),  # into a's left face
            ((0.0, 0.0), (0.0, -1.0)),  # from inside a: distance 0, the negated direction
            ((-1.0, 0.5), (1.0, 0.0)),  # on a's left face heading in: distance 0, that face's normal
            ((4.0, -5.0), (0.0, 1.0)),  # up into the circle's bottom
            ((-5.0, 5.0), (1.0, -1.0)),  # through the corner (-1, 1) of a: the diagonal enters there
            ((0.0, 9.0), (0.0, -1.0)),  # down onto the capsule's top side at y = 4.5
            ((-9.0, -9.0), (-1.0, 0.0)),  # away from everything
        ]
        hits = s.raycast_many([r[0] for r in rays], [r[1] for r in rays])
        got = [_batch_ray(hits, i) for i in range(len(rays))]
        assert got == [
            None,
            (a, 4.0, (-1.0, 0.0), (-1.0, 0.0)),
            (a, 0.0, (0.0, 0.0), (0.0, 1.0)),
            (a, 0.0, (-1.0, 0.5), (-1.0, 0.0)),
            (c, 4.0, (4.0, -1.0), (0.0, -1.0)),
            (a, got[5][1], (-1.0, 1.0), (0.0, 1.0)),  # a corner: the upward face, by the tie rule
            (k, 4.5, (0.0, 4.5), got[6][3]),  # (cos(pi / 2) is 6e-17: the normal's x)
            None,
        ]
        assert got[5][1] == math.hypot(4.0, 4.0) and got[6][3] == pytest.approx((0.0, 1.0), abs=1e-15)
        assert got == [_hit_tuple(s.raycast(*r)) for r in rays]
        assert hits.distance[0] == -1.0 and hits.point[0].tolist() == [0.0, 0.0]  # (a miss: never inf)
        # a hit at exactly max_distance counts; a hair short of it does not
        at = s.raycast_many([(-5.0, 0.0)], [(1.0, 0.0)], max_distance=4.0)
        short = s.raycast_many([(-5.0, 0.0)], [(1.0, 0.0)], max_distance=3.999999)
        assert at.entity.tolist() == [a] and at.distance.tolist() == [4.0] and short.entity.tolist() == [-1]
        # masks: the circle alone
        only2 = s.raycast_many([(-5.0, 0.0), (4.0, -5.0)], [(1.0, 0.0), (0.0, 1.0)], mask=2)
        assert only2.entity.tolist() == [c, c] and only2.distance.tolist() == [8.0, 4.0]
        assert s.raycast_many([(-5.0, 0.0)], [(1.0, 0.0)], mask=4).entity.tolist() == [-1]


def test_nearest_far_away_ties_and_masks():
    with Scene() as s:
        a, c, b, k = _box_field(s)
        res = s.nearest_many([(0.0, -1e6), (-3.0, 0.0), (4.0, 0.0), (8.0, 0.0), (2.5, 2.5)])
        assert _batch_near(res, 0) == (a, 1e6 - 1.0, (0.0, -1.0))  # a and b tie at (1, -1)... a is nearer below 0
        assert _batch_near(res, 1) == (a, 2.0, (-1.0, 0.0))
        assert _batch_near(res, 2) == (c, 0.0, (4.0, 0.0))
        assert _batch_near(res, 3) == (c, 3.0, (5.0, 0.0))
        # (2.5, 2.5): b's top edge at distance 1.5 and the capsule's cap... b wins, at (2.5, 1)
        assert _batch_near(res, 4) == (b, 1.5, (2.5, 1.0))
        tie = s.nearest_many([(1.0, -3.0)])  # a's and b's bottom corners share (1, -1): the lower id
        assert _batch_near(tie, 0) == (min(a, b), 2.0, (1.0, -1.0))
        masked = s.nearest_many([(-3.0, 0.0), (-3.0, 0.0)], mask=2, max_distance=7.0)
        assert _batch_near(masked, 0) == (c, 6.0, (3.0, 0.0))
        none = s.nearest_many([(-3.0, 0.0)], mask=2, max_distance=5.5)
        assert none.entity.tolist() == [-1] and none.distance[0] == -1.0  # (a miss: never inf)
        assert none.point.tolist() == [[-3.0, 0.0]]


def test_segments_and_chain_segments_as_the_single_queries():
    """A segment's ray hit, nearest point and the points on it, exact and dyadic; a chain segment
    is met by a ray from its front only."""
    with Scene() as s:
        seg = s.spawn(Transform(0.0, 0.0), Hitbox(Segment((-1.0, 0.0), (1.0, 0.0)), body="static"))
        hits = s.raycast_many([(0.0, 1.0), (0.5, -2.0)], [(0.0, -1.0), (0.0, 1.0)])
        assert _batch_ray(hits, 0) == (seg, 1.0, (0.0, 0.0), (0.0, 1.0))
        assert _batch_ray(hits, 1) == (seg, 2.0, (0.5, 0.0), (0.0, -1.0))
        near = s.nearest_many([(0.0, 1.0), (4.0, 4.0)])
        assert _batch_near(near, 0) == (seg, 1.0, (0.0, 0.0)) and _batch_near(near, 1) == (seg, 5.0, (1.0, 0.0))
        inside = s.query_points([(0.5, 0.0), (0.5, 0.25), (1.5, 0.0)])
        assert [inside.of(i) for i in range(3)] == [[seg], [], []] == [s.query_point(*p) for p in
                                                                       ((0.5, 0.0), (0.5, 0.25), (1.5, 0.0))]
    with Scene() as s:
        chain = Chain([(-2.0, 0.0), (-1.0, 0.0), (1.0, 0.0), (2.0, 0.0)])  # solid on the right: below
        ents = [s.spawn(Transform(0.0, 0.0), Hitbox(piece, body="static")) for piece in chain.segments]
        hits = s.raycast_many([(0.0, 1.0), (0.0, -1.0)], [(0.0, -1.0), (0.0, 1.0)])
        single = [_hit_tuple(s.raycast(o, d)) for o, d in (((0.0, 1.0), (0.0, -1.0)), ((0.0, -1.0), (0.0, 1.0)))]
        assert [_batch_ray(hits, 0), _batch_ray(hits, 1)] == single
        assert (single[0] is None) != (single[1] is None) and ents[1] in [h[0] for h in single if h]


def test_an_empty_scene_and_no_queries():
    with Scene() as s:
        assert s.query_points([(0.0, 0.0), (1.0, 2.0)]).offsets.tolist() == [0, 0, 0]
        assert s.nearest_many([(0.0, 0.0)]).entity.tolist() == [-1]
        assert s.raycast_many([(0.0, 0.0)], [(1.0, 0.0)]).entity.tolist() == [-1]
        s.spawn(Transform(0.0, 0.0), Hitbox(Circle(1.0)))
        empty = np.zeros((0, 2))
        assert s.query_points(empty).offsets.tolist() == [0] and s.query_points([]).entities.size == 0
        assert s.nearest_many(empty).point.shape == (0, 2)
        hits = s.raycast_many(empty, empty)
        assert hits.entity.shape == (0,) and hits.normal.shape == (0, 2)


def test_float32_and_integer_input():
    with Scene() as s:
        a, c, b, k = _box_field(s)
        pts64 = np.array([[0.1, 0.2], [3.3, 0.7], [-2.5, 4.25]])
        pts32 = pts64.astype(np.float32)
        as64 = pts32.astype(np.float64)
        assert s.query_points(pts32).entities.tolist() == s.query_points(as64).entities.tolist()
        n32, n64 = s.nearest_many(pts32), s.nearest_many(as64)
        assert n32.distance.tolist() == n64.distance.tolist() and n32.point.tolist() == n64.point.tolist()
        for i in range(3):
            assert _batch_near(n32, i) == _near_tuple(s.nearest((pts32[i, 0], pts32[i, 1])))
        dirs = np.array([[1, 0], [0, -1], [1, 1]], dtype=np.float32)
        r32 = s.raycast_many(pts32, dirs)
        for i in range(3):
            assert _batch_ray(r32, i) == _hit_tuple(s.raycast((pts32[i, 0], pts32[i, 1]), (dirs[i, 0], dirs[i, 1])))
        ints = s.raycast_many(np.array([[-5, 0]]), np.array([[2, 0]]))
        assert _batch_ray(ints, 0) == (a, 4.0, (-1.0, 0.0), (-1.0, 0.0))


@pytest.mark.parametrize("call, match", [
    (lambda s: s.query_points([(0.0, 0.0), (math.nan, 1.0)]), r"points\[1\] must be finite"),
    (lambda s: s.query_points([(0.0, 0.0), (1.0, math.inf)]), r"points\[1\] must be finite"),
    (lambda s: s.query_points([1.0, 2.0]), r"points must be an \(n, 2\) array.*shape \(2,\)"),
    (lambda s: s.query_points(np.zeros((3, 3))), r"shape \(3, 3\)"),
    (lambda s: s.query_points([("a", "b")]), "points must be an"),
    (lambda s: s.query_points([(True, False)]), "points must be an"),
    (lambda s: s.query_points([(0.0, 0.0)], mask=1.5), "mask"),
    (lambda s: s.nearest_many([(0.0, 0.0)], max_distance=-1.0), "max_distance must be >= 0"),
    (lambda s: s.nearest_many([(0.0, 0.0)], max_distance=math.nan), "max_distance"),
    (lambda s: s.nearest_many([[0.0, 0.0, 0.0]]), r"shape \(1, 3\)"),
    (lambda s: s.raycast_many([(0.0, 0.0), (1.0, 1.0)], [(1.0, 0.0), (0.0, 0.0)]), r"directions\[1\] must not be zero"),
    (lambda s: s.raycast_many([(0.0, 0.0)], [(1.0, 0.0), (1.0, 0.0)]), "same shape"),
    (lambda s: s.raycast_many([(0.0, 0.0)], [(math.inf, 0.0)]), r"directions\[0\] must be finite"),
    (lambda s: s.raycast_many([(0.0, 0.0)], [(1.0, 0.0)], max_distance=-0.5), "max_distance must be >= 0"),
])
def test_bad_input_is_refused_naming_it_and_the_scene_is_unchanged(call, match):
    with Scene() as s:
        e = s.spawn(Transform(0.5, 0.25), Hitbox(Circle(1.0)))
        s.step(1 / 60)
        store = s.store
        before = (store.version, store.x.copy(), store.y.copy(), store.rot.copy(), s.step_frame.ray_log[:])
        with pytest.raises(ValueError, match=match):
            call(s)
        after = (store.version, store.x, store.y, store.rot, s.step_frame.ray_log)
        assert before[0] == after[0] and before[4] == after[4]
        assert all(np.array_equal(u, v) for u, v in zip(before[1:4], after[1:4]))
        assert s.query_points([(0.5, 0.25)]).entities.tolist() == [e]


def test_an_edited_hitbox_before_the_next_step_is_read_as_the_single_queries_read_it():
    with Scene() as s:
        e = s.spawn(Transform(0.0, 0.0), Hitbox(Circle(1.0)))
        s.step(1 / 60)
        s.get(e, Hitbox).shape = Circle(0.5)  # read by the queries at once, by the step next step
        pts = [(0.75, 0.0), (0.25, 0.0), (3.0, 0.0)]
        assert [s.query_points(pts).of(i) for i in range(3)] == [s.query_point(*p) for p in pts] == [[], [e], []]
        near = s.nearest_many(pts)
        assert [_batch_near(near, i) for i in range(3)] == [_near_tuple(s.nearest(p)) for p in pts]


def test_hypot_is_cpythons():
    """The compiled hypot gives math.hypot's bits (the C library's differs in about 1 in 500)."""
    rng = np.random.default_rng(3)
    for scale in (1.0, 1e-9, 1e9, 1e300, 1e-310):
        xs = rng.normal(size=3000) * scale
        ys = xs * rng.choice([0.0, 1e-8, 0.3, 1.0, 7.0], size=3000) + rng.normal(size=3000) * scale
        for x, y in zip(xs.tolist(), ys.tolist()):
            assert hypot(x, y) == math.hypot(x, y), (x, y)
    assert hypot(math.inf, math.nan) == math.inf and math.isnan(hypot(math.nan, 1.0)) and hypot(0.0, -0.0) == 0.0


def test_a_ray_after_a_spawn_or_a_hitbox_edit_meets_the_live_shapes():
    """Between a spawn (or an edited hitbox) and the next step, a scene's ray reads the shapes as
    they are now, from a table of its candidates alone, and answers as the shape's own raycast."""
    with Scene() as s:
        box = s.spawn(Transform(0.0, 0.0), Hitbox(AABB(2.0, 2.0), body="static"))
        s.step(1 / 60)
        assert s.raycast((-4.0, 0.25), (1.0, 0.0)).distance == 3.0
        s.get(box, Hitbox).shape = Circle(0.5)  # (waits for the next step in the store, not for queries)
        hit = s.raycast((-4.0, 0.0), (1.0, 0.0))
        assert _hit_tuple(hit) == (box, 3.5, (-0.5, 0.0), (-1.0, 0.0))
        tri = s.spawn(Transform(-2.0, 0.0), Hitbox(TRIANGLE, body="static"))
        got = [_hit_tuple(h) for h in s.raycast_all((-4.0, 0.0), (1.0, 0.0))]
        want = [_hit_tuple(h) for h in sorted(
            (h for h in (_scene_hit(e, sh, p) for e, sh, p in ((box, Circle(0.5), (0.0, 0.0, 0.0)),
                                                                   (tri, TRIANGLE, (-2.0, 0.0, 0.0)))) if h),
            key=lambda h: (h.distance, h.entity))]
        assert got == want and len(got) == 2


def _scene_hit(entity, shape, pose):
    from framework.queries import SceneHit

    h = raycast(shape, pose, (-4.0, 0.0), (1.0, 0.0))
    return None if h is None else SceneHit(entity, *h)


def test_rays_after_a_restore_read_the_restored_shapes_not_a_table_of_another_timeline():
    """The queries keep their shape tables until the store changes; a restored snapshot is another
    store, even where its change count equals the one a table was made at: here two timelines from
    one snapshot each despawn one body (the same count), leaving a different body in row 0."""
    with Scene() as s:
        box = s.spawn(Transform(0.0, 0.0), Hitbox(AABB(2.0, 2.0), body="static"))
        ball = s.spawn(Transform(10.0, 0.0), Hitbox(Circle(0.5), body="static"))
        s.step(1 / 60)
        snap = s.snapshot()
        s.despawn(box)
        s.step(1 / 60)  # (row 0 is the ball's now)
        assert [(h.entity, h.distance) for h in s.raycast_all((-4.0, 0.0), (1.0, 0.0))] == [(ball, 13.5)]
        many = s.raycast_many(np.array([[-4.0, 0.0]]), np.array([[1.0, 0.0]]))
        assert (int(many.entity[0]), float(many.distance[0])) == (ball, 13.5)
        s.restore(snap)
        s.despawn(ball)
        s.step(1 / 60)  # (row 0 is the box's, at the same count of changes as above)
        assert [(h.entity, h.distance) for h in s.raycast_all((-4.0, 0.0), (1.0, 0.0))] == [(box, 3.0)]
        many = s.raycast_many(np.array([[-4.0, 0.0]]), np.array([[1.0, 0.0]]))
        assert (int(many.entity[0]), float(many.distance[0])) == (box, 3.0)
