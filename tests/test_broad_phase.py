"""The broad phase (``framework.collision.broad_phase``) against the O(N^2) brute-force reference.

The pair set must be exactly the brute-force one: bounds overlapping strictly on both axes (touching
is not a pair), never two static bodies, each pair once as ``(i, j)`` with ``i < j``, sorted. Hand
cases cover each known pitfall of grid hashing (negative coordinates, bounds on cell borders,
bodies spanning many cells, one huge body, float floor division with a 0.1 cell, duplicates,
N = 0 and 1, all static, coordinates near 1e9, points, NaN and inf); property tests compare random
scenes snapped to a coarse dyadic grid, so that many bounds touch exactly or sit on cell borders.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from framework.collision import grid
from framework.collision.broad_phase import SpatialHash, brute_force_pairs


def find_pairs(minx, miny, maxx, maxy, static=None, cell_size=None):
    """The broad-phase pairs ``(i, j)`` of bodies numbered by position, through a SpatialHash: the
    static ones hashed, then the others paired with them and among themselves; without a
    ``cell_size`` the hash chooses one from all bodies (not only the statics)."""
    b = grid.as_bounds(minx, miny, maxx, maxy)
    n = b[0].shape[0]
    st = np.zeros(n, dtype=bool) if static is None else np.asarray(static, dtype=bool).reshape(-1)
    assert st.shape[0] == n
    ids = np.arange(n, dtype=np.int64)
    h = SpatialHash(cell_size)
    if cell_size is None:
        h._choose_cell(b)
    h.set_static(*grid.subset(b, st), ids[st])
    return h.pairs(*grid.subset(b, ~st), ids[~st])


def as_set(pairs) -> set[tuple[int, int]]:
    a, b = pairs
    return set(zip(a.tolist(), b.tolist(), strict=True))


def assert_exact(minx, miny, maxx, maxy, static=None, cell_size=None):
    """find_pairs equals brute force, as arrays (so also in order and dtype kind)."""
    got = find_pairs(minx, miny, maxx, maxy, static, cell_size)
    exp = brute_force_pairs(minx, miny, maxx, maxy, static)
    assert got[0].dtype.kind == "i" and got[1].dtype.kind == "i"
    assert np.array_equal(got[0], exp[0]) and np.array_equal(got[1], exp[1]), (
        f"missing {as_set(exp) - as_set(got)}, extra {as_set(got) - as_set(exp)}"
    )
    return got


def boxes(*rows):
    """Bounds arrays from (minx, miny, maxx, maxy) rows."""
    a = np.array(rows, dtype=np.float64).reshape(-1, 4)
    return a[:, 0], a[:, 1], a[:, 2], a[:, 3]


def hashed_pairs(minx, miny, maxx, maxy, static, ids, cell_size=None):
    """Pairs through the SpatialHash API with caller ids: statics first, then the movers."""
    h = SpatialHash(cell_size)
    b = (np.asarray(minx), np.asarray(miny), np.asarray(maxx), np.asarray(maxy))
    h.set_static(*(v[static] for v in b), ids[static])
    return h, h.pairs(*(v[~static] for v in b), ids[~static])


# --- the reference itself ---------------------------------------------------------------------


def test_brute_force_semantics():
    b = boxes(
        (0, 0, 2, 2),  # 0
        (1, 1, 3, 3),  # 1 overlaps 0
        (2, 0, 4, 2),  # 2 touches 0 along an edge, overlaps 1
        (3, 3, 5, 5),  # 3 touches 1 at a corner only
        (0.5, 0.5, 0.5, 0.5),  # 4 a point inside 0
        (2, 1.5, 2, 1.5),  # 5 a point on the edges of 0 and 2 (touching), inside 1
    )
    static = np.array([False, False, False, False, False, True])
    assert as_set(brute_force_pairs(*b, static)) == {(0, 1), (1, 2), (0, 4), (1, 5)}
    assert as_set(brute_force_pairs(*b, np.array([True, True, False, False, False, False]))) == {
        (1, 2), (0, 4), (1, 5)
    }


# --- sizes of N and trivial inputs --------------------------------------------------------------


@pytest.mark.parametrize("static", [None, [True], [False]])
def test_no_bodies_and_one_body(static):
    e = np.zeros(0)
    a, b = find_pairs(e, e, e, e)
    assert a.shape == (0,) and b.shape == (0,) and a.dtype == np.int64
    assert as_set(find_pairs([0.0], [0.0], [1.0], [1.0], static)) == set()


def test_empty_hash_queries():
    h = SpatialHash()
    assert h.cell_size is None
    assert h.query_box(0, 0, 1, 1).shape == (0,)
    assert h.cells_in_use().shape == (0, 2)
    e = np.zeros(0)
    a, b = h.pairs(e, e, e, e, np.zeros(0, dtype=np.int64))
    assert a.shape == (0,) and h.rehashed_last == 0


def test_all_static_gives_no_pairs():
    b = boxes((0, 0, 2, 2), (1, 1, 3, 3), (0, 0, 2, 2))
    assert as_set(find_pairs(*b, np.ones(3, dtype=bool))) == set()


# --- touching, borders, negative coordinates ------------------------------------------------------


def test_touching_is_not_a_pair_but_one_ulp_is():
    up = np.nextafter(2.0, 3.0)
    b = boxes(
        (0, 0, 2, 2),
        (2, 0, 4, 2),  # touches 0 on x = 2
        (0, 2, 2, 4),  # touches 0 on y = 2
        (2, 2, 4, 4),  # corner
        (np.nextafter(2.0, 1.0), 5, 3, 6),  # far in y
    )
    assert_exact(*b, cell_size=1.0)
    assert as_set(find_pairs(*b, cell_size=1.0)) == set()
    b2 = boxes((0, 0, up, 2), (2, 0, 4, 2))
    assert as_set(assert_exact(*b2, cell_size=1.0)) == {(0, 1)}
    assert as_set(assert_exact(*b2, cell_size=2.0)) == {(0, 1)}


@pytest.mark.parametrize("cell", [1.0, 2.0, 0.5, 4.0, None])
def test_bounds_exactly_on_cell_borders(cell):
    # unit tiles on integer coordinates, some overlapping by half, some touching, all on borders
    rows = []
    for i in range(-3, 4):
        for j in range(-3, 4):
            rows.append((i, j, i + 1, j + 1))
    rows += [(-0.5, -0.5, 0.5, 0.5), (0, 0, 2, 2), (1, -3, 1, 4), (-4, 0, 4, 0), (0, 0, 0, 0)]
    b = boxes(*rows)
    static = np.zeros(len(rows), dtype=bool)
    static[: 49] = True
    got = assert_exact(*b, static, cell_size=cell)
    assert len(got[0]) > 0
    assert_exact(*b, None, cell_size=cell)


def test_negative_coordinates_mirror_positive():
    rng = np.random.default_rng(3)
    x = np.round(rng.uniform(0, 40, 300) * 4) / 4
    y = np.round(rng.uniform(0, 40, 300) * 4) / 4
    w = np.round(rng.uniform(0, 4, 300) * 4) / 4
    h = np.round(rng.uniform(0, 4, 300) * 4) / 4
    pos = assert_exact(x, y, x + w, y + h, cell_size=2.0)
    # mirrored through the origin, every interval flips: the same pairs
    neg = assert_exact(-(x + w), -(y + h), -x, -y, cell_size=2.0)
    assert as_set(pos) == as_set(neg)
    # and straddling the origin
    assert_exact(x - 20, y - 20, x + w - 20, y + h - 20, cell_size=2.0)


# --- sizes relative to the cell -------------------------------------------------------------------


def test_bodies_larger_than_a_cell_pair_once():
    # two big boxes sharing a 10 x 10 block of cells, and small ones inside and around them
    b = boxes((0, 0, 12, 12), (2, 2, 14, 14), (5, 5, 6, 6), (13, 13, 20, 20), (-3, 5, 0, 6))
    got = assert_exact(*b, cell_size=1.0)
    assert as_set(got) == {(0, 1), (0, 2), (1, 2), (1, 3)}
    assert len(got[0]) == len(set(zip(*got, strict=True)))


def test_one_huge_body_does_not_blow_up_the_cells():
    rng = np.random.default_rng(7)
    n = 400
    x, y = rng.uniform(-100, 100, n), rng.uniform(-100, 100, n)
    b = [x, y, x + rng.uniform(0.5, 2, n), y + rng.uniform(0.5, 2, n)]
    b = [np.append(v, e) for v, e in zip(b, (-1e12, -1e12, 1e12, 1e12), strict=True)]
    static = np.zeros(n + 1, dtype=bool)
    static[:: 3] = True
    got = assert_exact(*b, static)
    assert (n, n) not in as_set(got) and len(got[0]) >= n - static[:n].sum()  # huge one meets all
    h = SpatialHash(1.0)
    h.set_static(*(v[static] for v in b), np.flatnonzero(static))
    h.pairs(*(v[~static] for v in b), np.flatnonzero(~static))
    # the huge body is kept aside: a few hundred cells in use, not 10**24
    assert len(h.cells_in_use()) < 10 * n
    # also as a static body
    static[n] = True
    assert_exact(*b, static)


def test_huge_and_tall_bodies_against_each_other():
    b = boxes(
        (-1e6, 0, 1e6, 1), (0, -1e6, 1, 1e6),  # a huge horizontal and a huge vertical bar
        (-1e6, 0.5, 1e6, 0.75), (0.25, 0.25, 0.5, 0.5), (3, 3, 4, 4), (0, 10, 1, 11),
    )
    for static in (None, np.array([1, 0, 0, 0, 0, 0], bool), np.array([1, 1, 0, 0, 0, 1], bool)):
        assert_exact(*b, static, cell_size=1.0)


# --- float pitfalls -----------------------------------------------------------------------------


def test_floor_division_with_a_tenth_cell():
    assert 1.0 // 0.1 == 9.0  # the pitfall: floor division and floor(x / cell) disagree
    # bounds near multiples of 0.1 built every which way, plus one ulp either side
    ks = np.arange(-30, 31)
    vals = np.concatenate([ks / 10, ks * 0.1, ks * 0.1 + 0.0, np.cumsum(np.full(61, 0.1)) - 3.1])
    vals = np.concatenate([vals, np.nextafter(vals, np.inf), np.nextafter(vals, -np.inf)])
    rng = np.random.default_rng(11)
    lo_x, lo_y = rng.choice(vals, 800), rng.choice(vals, 800)
    span = rng.choice([0.0, 0.1, 0.2, 0.3, 1.0], 800)
    hi_x = np.maximum(lo_x, rng.choice(vals, 800) * 0 + lo_x + span)
    hi_y = np.maximum(lo_y, lo_y + rng.choice([0.0, 0.1, 0.3], 800))
    static = rng.random(800) < 0.5
    for cell in (0.1, 0.3, 0.7, 1.0):
        assert_exact(lo_x, lo_y, hi_x, hi_y, static, cell)


@pytest.mark.parametrize("cell", [0.1, 0.7, 1.7, 1 / 3])
def test_pairs_whose_quotients_round_together(cell):
    # minx_b < maxx_a by one ulp, yet minx_b / cell and maxx_a / cell round to the same integer
    # (1.7 / 0.1 == 17.0 and so is the float below 1.7 divided by 0.1)
    found = 0
    for k in range(1, 400):
        for hi in (k * cell, np.nextafter(k * cell, np.inf), np.nextafter(k * cell, 0.0)):
            lo = np.nextafter(hi, 0.0)
            q = hi / cell
            if lo / cell == q and q == math.floor(q):
                b = boxes((hi - 1, 0, hi, 1), (lo, 0, lo + 1, 1),  # in x; and the same in y, far away
                          (1e3, hi - 1, 1e3 + 1, hi), (1e3, lo, 1e3 + 1, lo + 1))
                assert as_set(assert_exact(*b, cell_size=cell)) == {(0, 1), (2, 3)}
                found += 1
    assert found > 10


def test_coordinates_near_1e9():
    rng = np.random.default_rng(5)
    x = np.round(rng.uniform(0, 64, 500) * 4) / 4
    y = np.round(rng.uniform(0, 64, 500) * 4) / 4
    w = np.round(rng.uniform(0, 3, 500) * 4) / 4
    static = rng.random(500) < 0.3
    near = assert_exact(x, y, x + w, y + w, static)
    off = 2.0**30  # ~1.07e9, and the sums stay exact at quarter units
    far = assert_exact(x + off, y - off, x + w + off, y + w - off, static)
    assert as_set(near) == as_set(far)
    assert_exact(x + 1e9, y + 1e9, x + w + 1e9, y + w + 1e9, static)
    assert_exact(x + 1e9, y + 1e9, x + w + 1e9, y + w + 1e9, static, cell_size=0.1)


def test_scene_spread_over_an_astronomical_span():
    # cell 1 with bodies at +-1e9 and +-1e12: cell indices are clipped and the cell keys need a
    # sparse lookup; nothing may be lost
    corners = [(-1e12, -1e12), (-1e9, 1e9), (1e9, -1e9), (1e12, 1e12), (0.0, 0.0), (1e9, 1e9)]
    rows = []
    for cx, cy in corners:
        for dx, dy, s in ((0, 0, 2), (1, 1, 2), (2, 0, 1), (2.5, 0.5, 0.25)):
            rows.append((cx + dx, cy + dy, cx + dx + s, cy + dy + s))
    b = boxes(*rows)
    static = np.arange(len(rows)) % 2 == 0
    for cell in (1.0, 1e-3, None):
        got = assert_exact(*b, static, cell)
        assert len(got[0]) >= 6
    # boxes over that span
    ids = np.arange(len(rows))
    for cell in (1.0, None):
        h, _ = hashed_pairs(*b, static, ids, cell)
        for k, (cx, cy) in enumerate(corners):
            at = ids[4 * k: 4 * k + 4]
            assert h.query_box(cx + 0.5, cy + 0.5, cx + 1.5, cy + 1.5).tolist() == at[:2].tolist()
    # the extremes of float64: spans overflow to inf
    big = boxes((-1.7e308, 0, -1.6e308, 1), (-1.65e308, 0.5, -1e308, 2), (1e308, 0, 1.7e308, 1),
                (1.6e308, 0, 1.7e308, 3), (0, 0, 1, 1), (0.5, 0.5, 1e308, 0.75))
    for cell in (1.0, None, 1e300, 1e307):
        assert len(assert_exact(*big, None, cell)[0]) == 3


def test_points_and_zero_width_bounds():
    b = boxes(
        (0, 0, 4, 4),  # 0
        (2, 2, 2, 2),  # 1 point inside 0: a pair by the strict-overlap formula
        (4, 1, 4, 1),  # 2 point on 0's edge: touching
        (2, 2, 2, 2),  # 3 the same point as 1: two points never overlap
        (1, -1, 1, 5),  # 4 vertical segment through 0 and through point 1's column
        (-1, 2, 5, 2),  # 5 horizontal segment crossing 4 and through point 1
    )
    for cell in (None, 1.0, 2.0, 0.5):
        assert as_set(assert_exact(*b, cell_size=cell)) == {(0, 1), (0, 3), (0, 4), (0, 5), (4, 5)}
    # all points: the automatic cell size still works
    p = np.arange(10.0)
    assert_exact(p, p, p, p)
    h = SpatialHash()
    h.pairs(p, p, p, p, np.arange(10))
    assert h.cell_size is not None and h.cell_size > 0


def test_duplicates_and_identical_boxes_pair_once():
    b = boxes(*[(0.5, 0.5, 3.5, 3.5)] * 5, (1, 1, 2, 2))
    got = assert_exact(*b, cell_size=1.0)
    assert len(got[0]) == 15


def test_nan_and_inf_bounds():
    b = boxes(
        (0, 0, 2, 2),
        (np.nan, 0, 1, 1),
        (1, 1, np.inf, np.inf),  # overlaps everything up and to the right
        (-np.inf, -np.inf, 0.5, 0.5),
        (1, np.nan, 2, np.nan),
        (5, 5, 6, 6),
    )
    for static in (None, np.array([0, 0, 1, 0, 0, 1], bool), np.array([1, 1, 0, 1, 0, 0], bool)):
        assert_exact(*b, static)


def test_inverted_and_mismatched_bounds_raise():
    with pytest.raises(ValueError, match="maxx"):
        find_pairs([0.0, 1.0], [0.0, 0.0], [1.0, 0.5], [1.0, 1.0])
    with pytest.raises(ValueError, match="maxy"):
        SpatialHash().set_static([0.0], [1.0], [1.0], [0.0], [0])
    with pytest.raises(ValueError, match="length"):
        SpatialHash().pairs([0.0], [0.0], [1.0, 2.0], [1.0], [0])
    with pytest.raises(ValueError, match="ids"):
        SpatialHash().pairs([0.0], [0.0], [1.0], [1.0], [0, 1])
    with pytest.raises(ValueError, match="cell_size"):
        SpatialHash(0.0)
    h = SpatialHash(1.0)
    h.set_static([0.0], [0.0], [2.0], [2.0], [7])
    with pytest.raises(ValueError, match="unique"):
        h.pairs([1.0], [1.0], [3.0], [3.0], [7])


# --- the SpatialHash API ------------------------------------------------------------------------


def test_pairs_are_reported_in_ids_sorted():
    b = boxes((0, 0, 2, 2), (1, 1, 3, 3), (1.5, 0, 2.5, 1.2), (10, 10, 11, 11))
    static = np.array([True, False, False, True])
    ids = np.array([900, 40, 7, 3])
    _, (a, c) = hashed_pairs(*b, static, ids)
    assert a.tolist() == [7, 7, 40] and c.tolist() == [40, 900, 900]
    # ids far apart take the general sort path
    ids = np.array([2**45, 5, 2**40, -3])
    _, (a, c) = hashed_pairs(*b, static, ids)
    assert list(zip(a.tolist(), c.tolist(), strict=True)) == sorted(
        [(5, 2**45), (5, 2**40), (2**40, 2**45)]
    )


def test_statics_are_hashed_once():
    k = 40  # 1,600 unit tiles and 120 movers
    gx, gy = np.meshgrid(np.arange(k, dtype=float), np.arange(k, dtype=float))
    sx, sy = gx.ravel(), gy.ravel()
    h = SpatialHash()
    h.set_static(sx, sy, sx + 1, sy + 1, np.arange(k * k))
    assert h.rehashed_last == k * k
    index = h._static
    cell = h.cell_size
    assert cell == pytest.approx(2.0)
    rng = np.random.default_rng(2)
    for step in range(20):
        m = 120
        x, y = rng.uniform(-2, k + 2, m), rng.uniform(-2, k + 2, m)
        w = rng.uniform(0.2, 1.5, m)
        ids = np.arange(10_000, 10_000 + m)
        a, b = h.pairs(x, y, x + w, y + w, ids)
        assert h.rehashed_last == m
        assert h._static is index and h.cell_size == cell
        if step % 5 == 0:
            allb = [np.concatenate([s, v]) for s, v in zip((sx, sy, sx + 1, sy + 1), (x, y, x + w, y + w),
                                                            strict=True)]
            static = np.arange(k * k + m) < k * k
            ea, eb = brute_force_pairs(*allb, static)
            all_ids = np.concatenate([np.arange(k * k), ids])
            assert np.array_equal(a, all_ids[ea]) and np.array_equal(b, all_ids[eb])


def test_cell_size_is_chosen_once_from_the_first_build():
    h = SpatialHash()
    h.set_static([0.0, 10.0], [0.0, 0.0], [3.0, 13.0], [3.0, 2.0], [0, 1])
    assert h.cell_size == pytest.approx(6.0)  # twice the median extent (3)
    h.pairs([0.0], [0.0], [100.0], [100.0], [5])
    assert h.cell_size == pytest.approx(6.0)
    assert SpatialHash(0.25).cell_size == 0.25


def test_auto_cell_size_guards():
    med = grid.auto_cell_size(*boxes((0, 0, 1, 1), (0, 0, 2, 1), (0, 0, 4, 4), (0, 0, 1e9, 1)))
    assert 2 <= med <= 8  # the median ignores one huge body
    pts = np.array([0.0, 100.0])
    assert grid.auto_cell_size(pts, pts, pts, pts) > 0
    far = np.array([1e15, 1e15 + 0.125])
    assert grid.auto_cell_size(far, far, far + 1e-3, far + 1e-3) >= 1e15 * 2.0**-28
    nan = np.array([np.nan])
    assert grid.auto_cell_size(nan, nan, nan, nan) is None


def test_order_of_bodies_does_not_matter_and_runs_repeat_exactly():
    rng = np.random.default_rng(9)
    n = 600
    x, y = rng.uniform(-30, 30, n), rng.uniform(-30, 30, n)
    w, h = rng.uniform(0, 3, n), rng.uniform(0, 3, n)
    static = rng.random(n) < 0.4
    ids = rng.permutation(10 * n)[:n]
    _, first = hashed_pairs(x, y, x + w, y + h, static, ids)
    _, again = hashed_pairs(x, y, x + w, y + h, static, ids)
    assert first[0].tobytes() == again[0].tobytes() and first[1].tobytes() == again[1].tobytes()
    p = rng.permutation(n)
    _, shuffled = hashed_pairs(x[p], y[p], (x + w)[p], (y + h)[p], static[p], ids[p])
    assert np.array_equal(first[0], shuffled[0]) and np.array_equal(first[1], shuffled[1])


@pytest.mark.parametrize("seed", range(4))
def test_larger_random_scenes(seed):
    # enough bodies for the vectorised sweep (not only its tail), with some long and tall bodies
    rng = np.random.default_rng(seed)
    n = 2500
    side = math.sqrt(n) * 14
    x, y = rng.uniform(-side / 2, side / 2, n), rng.uniform(-side / 2, side / 2, n)
    w, h = rng.uniform(4, 16, n), rng.uniform(4, 16, n)
    w[:10] *= rng.uniform(5, 20, 10)  # long bodies, many cells but not "large"
    h[10:20] *= rng.uniform(5, 20, 10)
    x, y, w, h = (np.round(v * 2) / 2 for v in (x, y, w, h))
    static = rng.random(n) < [0.0, 0.3, 0.7, 1.0][seed]
    got = assert_exact(x, y, x + w, y + h, static)
    assert len(got[0]) > n / 4 or static.all()
    assert_exact(x, y, x + w, y + h, static, cell_size=8.0)


def test_a_crowd_in_one_cell():
    rng = np.random.default_rng(4)
    x, y = rng.uniform(0, 1, 500), rng.uniform(0, 1, 500)
    got = assert_exact(x, y, x + 0.5, y + 0.5, cell_size=10.0)
    assert len(got[0]) > 20_000


# --- queries ------------------------------------------------------------------------------------


def brute_box(b, box):
    minx, miny, maxx, maxy = b
    return np.flatnonzero((maxx > box[0]) & (box[2] > minx) & (maxy > box[1]) & (box[3] > miny))


def test_query_box_hand_cases():
    b = boxes((0, 0, 1, 1), (1, 0, 2, 1), (-5, -5, -4, -4), (0, 0, 10, 10), (3, 3, 3, 3))
    static = np.array([True, True, True, False, False])
    ids = np.array([10, 11, 12, 13, 14])
    h, _ = hashed_pairs(*b, static, ids, cell_size=1.0)
    assert h.query_box(0.25, 0.25, 0.75, 0.75).tolist() == [10, 13]
    assert h.query_box(1, 0, 1, 1).tolist() == [13]  # a zero-width box on the border of 10 and 11
    assert h.query_box(1, 0.5, 1, 0.5).tolist() == [13]
    assert h.query_box(-4, -4, -3, -3).tolist() == []  # touches 12 only
    assert h.query_box(-100, -100, 100, 100).tolist() == [10, 11, 12, 13, 14]  # 14: point inside
    assert h.query_box(2.5, 2.5, 3.5, 3.5).tolist() == [13, 14]
    with pytest.raises(ValueError):
        h.query_box(1, 1, 0, 0)
    with pytest.raises(ValueError):
        h.query_box(0, 0, math.nan, 1)


def test_queries_over_many_moving_bodies():
    # after a few queries the moving bodies get cells of their own; answers must not change
    rng = np.random.default_rng(12)
    n = 3000
    x, y = np.round(rng.uniform(-200, 200, n)), np.round(rng.uniform(-200, 200, n))
    w = np.round(rng.uniform(0, 8, n) * 2) / 2
    static = np.arange(n) < 800
    h, _ = hashed_pairs(x, y, x + w, y + w, static, np.arange(n))
    b = (x, y, x + w, y + w)
    for q in range(12):
        bx, by = rng.uniform(-220, 200, 2).round()
        bw = [0.0, 3.0, 40.0, 500.0][q % 4]
        assert np.array_equal(h.query_box(bx, by, bx + bw, by + bw), brute_box(b, (bx, by, bx + bw, by + bw)))
    assert h._moving_cells is not None
    # a new step drops them
    m = ~static
    h.pairs(x[m] + 1, y[m], x[m] + w[m] + 1, y[m] + w[m], np.arange(800, n))
    assert h._moving_cells is None


@pytest.mark.parametrize("direct", [0, 10**9], ids=["through the cell index", "bounds tested directly"])
def test_box_queries_answer_the_same_with_and_without_the_cell_index(monkeypatch, direct):
    # up to DIRECT_QUERY bodies a box query tests every bound without the index: both ways are brute force's
    import framework.collision.broad_phase as bp

    monkeypatch.setattr(bp, "DIRECT_QUERY", direct)
    test_query_box_hand_cases()
    test_queries_over_many_moving_bodies()


def test_the_caller_may_overwrite_its_arrays():
    b = [np.array(v) for v in boxes((0, 0, 1, 1), (5, 5, 6, 6), (-1e9, 3, 1e9, 4))]
    h = SpatialHash(1.0)
    h.pairs(*b, np.array([1, 2, 3]))
    for v in b:
        v[:] = 100.0  # the caller reuses its columns for the next step
    assert h.query_box(0.5, 0.5, 0.75, 0.75).tolist() == [1]
    assert h.query_box(5.5, 5.5, 7, 7).tolist() == [2]
    assert h.query_box(0, 3.5, 0, 3.5).tolist() == [3]


def test_argument_checks():
    with pytest.raises(ValueError, match="static"):
        brute_force_pairs([0.0], [0.0], [1.0], [1.0], [True, False])
    with pytest.raises(ValueError, match="integers"):
        SpatialHash().pairs([0.0], [0.0], [1.0], [1.0], [0.5])
    SpatialHash().pairs([], [], [], [], [])  # an empty list of ids is fine


def test_cells_in_use():
    b = boxes((0, 0, 1, 1), (2.5, -1.5, 3.5, -0.5), (-1e9, -1e9, 1e9, 1e9))
    static = np.array([True, False, False])
    h, _ = hashed_pairs(*b, static, np.arange(3), cell_size=1.0)
    cells = h.cells_in_use()
    assert cells.dtype.kind == "i" and cells.shape[1] == 2
    # tile (0,0)-(1,1) is in cell (0, 0) only (it merely touches the next ones); the mover spans
    # 2 x 2 cells; the huge one occupies none
    assert cells.tolist() == [[0, 0], [2, -2], [2, -1], [3, -2], [3, -1]]


# --- property tests -----------------------------------------------------------------------------

quarter = st.integers(-64, 64).map(lambda i: i / 4)
size = st.one_of(st.just(0.0), st.integers(0, 12).map(lambda i: i / 4), st.integers(0, 40).map(float))
body = st.tuples(quarter, quarter, size, size, st.booleans())
cells = st.sampled_from([None, 0.1, 0.25, 0.3, 0.5, 1.0, 1.5, 2.0, 3.0, 8.0])


@st.composite
def scenes(draw):
    bodies = draw(st.lists(body, max_size=40))
    if bodies and draw(st.booleans()):  # copies: identical and touching bodies
        bodies += draw(st.lists(st.sampled_from(bodies), max_size=8))
    a = np.array([bb[:4] for bb in bodies], dtype=np.float64).reshape(-1, 4)
    static = np.array([bb[4] for bb in bodies], dtype=bool)
    b = (a[:, 0], a[:, 1], a[:, 0] + a[:, 2], a[:, 1] + a[:, 3])
    return b, static


@pytest.mark.slow
@settings(max_examples=300, deadline=None)
@given(scenes(), cells, st.integers(0, 2**40))
def test_random_scenes_match_brute_force(scene, cell, id_base):
    b, static = scene
    assert_exact(*b, static, cell)
    ids = id_base + 3 * np.arange(len(static))[::-1]
    h, (a, c) = hashed_pairs(*b, static, ids, cell)
    ea, ec = brute_force_pairs(*b, static)
    lo, hi = np.minimum(ids[ea], ids[ec]), np.maximum(ids[ea], ids[ec])
    order = np.lexsort((hi, lo))
    assert np.array_equal(a, lo[order]) and np.array_equal(c, hi[order])
    assert h.rehashed_last == int((~static).sum())


@pytest.mark.slow
@settings(max_examples=200, deadline=None)
@given(scenes(), cells, quarter, quarter, size, size, st.integers(1, 6))
def test_random_query_box_matches_brute_force(scene, cell, x, y, w, hh, repeat):
    b, static = scene
    ids = np.arange(len(static)) + 100
    h, _ = hashed_pairs(*b, static, ids, cell)
    box = (x, y, x + w, y + hh)
    exp = ids[brute_box(b, box)]
    for _ in range(repeat):  # later queries may use the moving bodies' cells
        assert np.array_equal(h.query_box(*box), exp)


def test_moving_pairs_false_gives_only_moving_static_pairs():
    rng = np.random.default_rng(11)
    n_s, n_m = 300, 200
    sx, sy = rng.uniform(0, 100, n_s), rng.uniform(0, 100, n_s)
    mx, my = rng.uniform(0, 100, n_m), rng.uniform(0, 100, n_m)
    sw, mw = rng.uniform(1, 6, n_s), rng.uniform(1, 6, n_m)
    sw[0] = 400.0  # a large static among small ones
    mw[0] = 300.0  # and a large mover
    h = SpatialHash(4.0)
    h.set_static(sx, sy, sx + sw, sy + sw, np.arange(n_s))
    ids = np.arange(n_s, n_s + n_m)
    a, b = h.pairs(mx, my, mx + mw, my + mw, ids, moving_pairs=False)
    ra, rb = h.pairs(mx, my, mx + mw, my + mw, ids)
    cross = (ra < n_s) != (rb < n_s)
    assert np.array_equal(a, ra[cross]) and np.array_equal(b, rb[cross])
    assert a.size > 0 and (ra.size - a.size) > 0
    # static_pairs gives the same pairs and leaves the last pairs() call's movers for queries.
    before = h.query_box(0.0, 0.0, 50.0, 50.0)
    sa, sb = h.static_pairs(mx[1:50], my[1:50], mx[1:50] + mw[1:50], my[1:50] + mw[1:50], ids[1:50])
    keep = np.isin(a, ids[1:50]) | np.isin(b, ids[1:50])
    assert np.array_equal(sa, a[keep]) and np.array_equal(sb, b[keep]) and sa.size > 0
    assert np.array_equal(h.query_box(0.0, 0.0, 50.0, 50.0), before)


odd_box = st.sampled_from([(math.nan, 0.0, 1.0, 1.0), (1.0, 1.0, math.inf, math.inf),
                           (-math.inf, -math.inf, 0.5, 0.5), (-1e300, -4.0, 1e300, 4.0), (-30.0, -30.0, 30.0, 30.0),
                           (2.0, 2.0, 2.0, 2.0)])


@settings(max_examples=300, deadline=None)
@given(scenes(), scenes(), cells, st.booleans(), st.lists(odd_box, max_size=3))
def test_static_pairs_are_the_brute_force_pairs(statics, queries, cell, sparse, odd):
    """``static_pairs`` (each box looking in the statics' cells it covers, one compiled pass) gives
    exactly brute force's box-static pairs: boxes on cell borders, touching, copied, wider than the
    large limit, not finite; statics in a dense table of cells or (one static far away: a grid too
    sparse for one) found by search; large statics among the small ones."""
    sb, _ = statics
    qb, _ = queries
    if sparse:  # a static 1e6 cells away: the used cells are searched, not tabled
        sb = tuple(np.append(v, w) for v, w in zip(sb, (1e6, 1e6, 1e6 + 1.0, 1e6 + 1.0), strict=True))
    qb = tuple(np.append(v, [o[k] for o in odd]) for k, v in enumerate(qb))
    n_s, n_q = sb[0].size, qb[0].size
    h = SpatialHash(cell if cell is not None else 1.0)
    h.set_static(*sb, np.arange(n_s, dtype=np.int64) + 1000)
    a, b = h.static_pairs(*qb, np.arange(n_q, dtype=np.int64))
    both = tuple(np.concatenate([q, s]) for q, s in zip(qb, sb, strict=True))
    i, j = brute_force_pairs(*both, static=np.arange(n_q + n_s) >= n_q)
    cross = j >= n_q  # (brute force pairs the boxes among themselves too)
    assert np.array_equal(a, i[cross]) and np.array_equal(b, j[cross] + 1000 - n_q)


@pytest.mark.parametrize("far", [False, True])
def test_static_pairs_of_tiles_a_large_static_and_a_far_one(far):
    """Hand case of ``static_pairs``' two ways of finding a cell (a table; a search where one static
    1e6 cells away leaves the grid too sparse for a table) and of its large statics: 200 unit tiles
    edge to edge, a static 500 wide, boxes on tile borders, touching tiles, spanning many cells."""
    tx = np.arange(200, dtype=np.float64) - 100.0
    sb = [tx, np.full(200, -1.0), tx + 1.0, np.zeros(200)]
    extra = [(-250.0, -10.0, 250.0, -9.0)] + ([(1e6, 1e6, 1e6 + 1.0, 1e6 + 1.0)] if far else [])
    sb = [np.append(v, [e[k] for e in extra]) for k, v in enumerate(sb)]
    h = SpatialHash(1.0)
    h.set_static(*sb, np.arange(sb[0].size, dtype=np.int64) + 1000)
    assert (h._static.dense.size == 0) == far and h._static.large.size == 1
    qb = boxes((0.0, -0.5, 1.0, 0.5),  # on tile borders: one tile
               (0.5, 0.0, 1.5, 1.0),  # touching two tiles from above: none
               (-3.25, -9.5, 3.25, -0.25),  # over the large static and seven tiles
               (-90.0, -2.0, 90.0, 2.0),  # past the large limit: tested against every static
               (1e6 + 0.5, 1e6 + 0.5, 1e6 + 0.75, 1e6 + 0.75))  # inside the far static (if any)
    a, b = h.static_pairs(*qb, np.arange(5, dtype=np.int64))
    both = tuple(np.concatenate([q, s]) for q, s in zip(qb, sb, strict=True))
    i, j = brute_force_pairs(*both, static=np.arange(5 + sb[0].size) >= 5)
    cross = j >= 5  # (brute force pairs the boxes among themselves too)
    assert np.array_equal(a, i[cross]) and np.array_equal(b, j[cross] + 1000 - 5)
    assert np.bincount(a, minlength=5).tolist() == [1, 0, 9, 180, int(far)]


@pytest.mark.parametrize("large", [False, True])
def test_near_statics_never_misses_a_static_pair(large):
    rng = np.random.default_rng(3)
    sx, sy = rng.uniform(0, 60, 400), rng.uniform(0, 60, 400)
    sw = rng.uniform(0.5, 3.0, 400)
    if large:
        sw[0] = 40.0  # one large static
    h = SpatialHash(2.0)
    h.set_static(sx, sy, sx + sw, sy + sw, np.arange(400))
    mx, my = rng.uniform(-40, 100, 3000), rng.uniform(-40, 100, 3000)
    mw = rng.uniform(0.1, 6.0, 3000)
    near = h.near_statics(mx, my, mx + mw, my + mw)
    i, j = brute_force_pairs(np.concatenate([mx, sx]), np.concatenate([my, sy]), np.concatenate([mx + mw, sx + sw]),
                             np.concatenate([my + mw, sy + sw]), static=np.arange(3400) >= 3000)
    meets = np.zeros(3000, dtype=bool)
    meets[i[(i < 3000) & (j >= 3000)]] = True
    assert meets.sum() > 100 and (~near).sum() > 100  # both kinds are present
    assert not (meets & ~near).any()
    h2 = SpatialHash(2.0)
    assert not h2.near_statics(mx, my, mx + mw, my + mw).any()  # no statics at all


def _scene_pairs(seed: int, direct: bool, movers: tuple[int, int] = (2, 30)):
    """A random scene's first steps' candidate pairs (entities) through the broad phase stage, the
    direct pass on or off: ``movers`` (low, high) movers (some touching, some sleeping), tiles
    touching edge to edge, bodies without a hitbox in between."""
    import framework.systems.broad_phase as stage
    from framework import AABB, Circle, Hitbox, Polygon, Scene, Transform, Velocity

    rng = np.random.default_rng(seed)
    s = Scene(gravity=(0.0, -10.0))
    for k in range(40):  # a floor of unit tiles, edge to edge, and a few floating blocks
        s.spawn(Transform(k - 20.0 + 0.5, -0.5), Hitbox(AABB(1.0, 1.0), body="static", friction=0.5))
    for _ in range(8):
        s.spawn(Transform(float(rng.uniform(-15, 15)), float(rng.uniform(1, 6))),
                Hitbox(AABB(float(rng.uniform(0.5, 3)), 0.5), body="static"))
    shapes = [AABB(1.0, 1.0), Circle(0.5), Polygon.box(1.0, 0.5), AABB(0.5, 2.0)]
    for k in range(int(rng.integers(*movers))):
        s.spawn(Transform(float(rng.uniform(-15, 15)), float(rng.uniform(0.2, 8))),
                Velocity(float(rng.uniform(-3, 3)), 0.0), Hitbox(shapes[k % 4], friction=0.5))
        if k % 5 == 0:
            s.spawn(Transform(0.0, 0.0))  # a row without a hitbox
    seen = []
    limit = stage.DIRECT_PAIRS
    stage.DIRECT_PAIRS = limit if direct else -1
    s.add_system(_check_pairs, after="broad_phase")
    try:
        for _ in range(150):
            s.step(1 / 30)
            ea, eb, _ra, _rb = s._pipeline.frame.pairs
            seen.append((ea.tolist(), eb.tolist(), s._pipeline.frame.n_asleep))
    finally:
        stage.DIRECT_PAIRS = limit
    return seen


def _check_pairs(scene, _dt) -> None:
    """A system right after the broad phase: its pairs are the oracle's."""
    ea, eb, _ra, _rb = scene._pipeline.frame.pairs
    assert (ea.tolist(), eb.tolist()) == _every_pair(scene)


def _every_pair(scene) -> tuple[list[int], list[int]]:
    """The oracle: every two hitbox rows, one moving and the other moving, static or asleep, whose
    bounds (as the broad phase saw them) strictly overlap, as entity pairs a < b in sorted order."""
    from framework.store import STATIC

    bodies = scene._pipeline.bodies
    store, geom = bodies.store, bodies.ensure_geometry()
    n = store.n
    moving = np.zeros(n, dtype=bool)
    moving[store.active()[1]] = True
    other = (store.kind[:n] >= 0) & ((store.body[:n] == STATIC) | store.asleep[:n]) & ~moving
    found = []
    for i in np.flatnonzero(moving).tolist():
        for j in np.flatnonzero(moving | other).tolist():
            if (moving[j] and j <= i) or not (geom.maxx[i] > geom.minx[j] and geom.maxx[j] > geom.minx[i]
                                              and geom.maxy[i] > geom.miny[j] and geom.maxy[j] > geom.miny[i]):
                continue
            a, b = sorted((int(store.entity[i]), int(store.entity[j])))
            found.append((a, b))
    found.sort()
    return [a for a, _ in found], [b for _, b in found]


@pytest.mark.parametrize("seed", range(6))
def test_a_few_movers_paired_directly_give_the_kept_pairs_in_their_order(seed):
    # the broad phase pairs few enough movers with every hitbox in one compiled pass, and more
    # movers from candidates kept between steps (kept_pairs): the same pairs, in the same order,
    # each step the oracle's (_every_pair), as the bodies fall, land on tiles, slide into each
    # other and fall asleep
    direct, hashed = _scene_pairs(seed, True), _scene_pairs(seed, False)
    assert direct == hashed
    assert any(pairs for pairs, _b, _n in direct) and any(n for _a, _b, n in direct)  # pairs, sleepers


@pytest.mark.parametrize("seed", range(2))
def test_a_crowd_paired_directly_gives_the_kept_pairs(seed):
    # a crowd of 100 to 160 piling up, the direct pass against the kept candidates, step by step
    direct, hashed = _scene_pairs(seed, True, (100, 160)), _scene_pairs(seed, False, (100, 160))
    assert direct == hashed
    assert any(len(pairs) > 100 for pairs, _b, _n in direct)


def test_kept_pairs_are_kept_while_a_pile_rests_and_rebuilt_when_it_changes():
    # 300 boxes dropped into a pit (too many for the direct pass): the candidates are built again
    # while they fall, then kept while they rest; a despawn, a new body and a static moved build
    # them again; every step the pairs are the oracle's
    from framework import AABB, Hitbox, Scene, Transform, Velocity
    from framework.effects import DEFAULT_EFFECTS
    from framework.systems.broad_phase import BroadPhase

    s = Scene(gravity=(0.0, -10.0), effects=DEFAULT_EFFECTS - {"sleeping"})
    s.spawn(Transform(10.0, -0.5), Hitbox(AABB(24.0, 1.0), body="static"))
    wall = s.spawn(Transform(-1.5, 10.0), Hitbox(AABB(1.0, 22.0), body="static"))
    s.spawn(Transform(21.5, 10.0), Hitbox(AABB(1.0, 22.0), body="static"))
    boxes = [s.spawn(Transform(0.5 + (k % 20) * 1.0, 0.5 + (k // 20) * 1.25), Velocity(), Hitbox(AABB(1.0, 1.0)))
             for k in range(300)]
    stage = s._stages["broad_phase"]
    assert isinstance(stage, BroadPhase)
    s.add_system(_check_pairs, after="broad_phase")

    def steps(count: int) -> int:
        before = stage.kept.builds
        for _ in range(count):
            s.step(1 / 60)
        return stage.kept.builds - before

    assert steps(240) > 1
    assert steps(60) == 0  # at rest: kept
    s.despawn(boxes[-1])
    assert steps(2) >= 1
    s.spawn(Transform(10.0, 30.0), Velocity(0.0, -5.0), Hitbox(AABB(1.0, 1.0)))
    assert steps(2) >= 1
    s.get(wall, Transform).x = -1.25  # a static moved: pushes the pile's edge
    assert steps(30) >= 1


@pytest.mark.parametrize("layout", ["crowd", "crowd and statics", "two crowds far apart", "crowd and a huge box"])
def test_kept_candidates_are_brought_up_to_date_as_drifting_boxes_leave_their_fat_bounds(layout):
    # 600 boxes of sizes 1 to 4 drifting without gravity (the perf workload's kind of scene): every
    # step some leave their fat bounds, too few to build the candidates again, so only theirs are
    # found again (through a grid of every mover's fat bounds, and the hash of the statics: a few
    # static boxes among them); where the grid cannot take the movers (two crowds 200,000 apart, a
    # box 500 wide among them) the candidates are built again instead. Every step the pairs are
    # the oracle's.
    from framework import AABB, Hitbox, Scene, Transform, Velocity
    from framework.effects import DEFAULT_EFFECTS
    from framework.systems.broad_phase import BroadPhase

    rng = np.random.default_rng(5)
    s = Scene(gravity=(0.0, 0.0), effects=DEFAULT_EFFECTS - {"sleeping"})
    side = 90.0
    if layout == "crowd and statics":
        for x, y in rng.uniform(0.0, side, (40, 2)):
            s.spawn(Transform(float(x), float(y)), Hitbox(AABB(2.0, 2.0), body="static"))
    far = np.where(np.arange(600) % 2 == 1, 200_000.0, 0.0) if layout == "two crowds far apart" else np.zeros(600)
    for x, y, w, h, vx, vy, dx in zip(rng.uniform(0.0, side, 600), rng.uniform(0.0, side, 600),
                                      rng.uniform(1.0, 4.0, 600), rng.uniform(1.0, 4.0, 600),
                                      rng.uniform(-3.0, 3.0, 600), rng.uniform(-3.0, 3.0, 600), far):
        s.spawn(Transform(float(x + dx), float(y)), Velocity(float(vx), float(vy)), Hitbox(AABB(float(w), float(h))))
    if layout == "crowd and a huge box":
        s.spawn(Transform(side / 2, side / 2), Velocity(0.5, 0.0), Hitbox(AABB(500.0, 1.0)))
    stage = s._stages["broad_phase"]
    assert isinstance(stage, BroadPhase)
    s.add_system(_check_pairs, after="broad_phase")
    for _ in range(90):
        s.step(1 / 60)
    if layout in ("crowd", "crowd and statics"):
        assert stage.kept.updates >= 20, (stage.kept.updates, stage.kept.builds)
    else:
        assert stage.kept.builds >= 5, (stage.kept.updates, stage.kept.builds)


def test_a_scene_keeping_its_candidates_restores_and_continues_bit_for_bit(tmp_path):
    # the kept candidates travel with a snapshot (in memory and in a file): a pile of 300 boxes
    # restored, even into a scene that kept other candidates, continues as the original does
    from framework import AABB, Hitbox, Scene, Transform, Velocity
    from framework.effects import DEFAULT_EFFECTS
    from framework.snapshot_file import load_snapshot, save_snapshot

    def pile():
        s = Scene(gravity=(0.0, -10.0), effects=DEFAULT_EFFECTS - {"sleeping"})
        s.spawn(Transform(10.0, -0.5), Hitbox(AABB(24.0, 1.0), body="static"))
        for k in range(300):
            s.spawn(Transform(0.5 + (k % 20) * 1.0, 0.5 + (k // 20) * 1.25), Velocity(), Hitbox(AABB(1.0, 1.0)))
        return s

    def state(s):
        return [(s.get(e, Transform).x, s.get(e, Transform).y) for e in sorted(s.entities)]

    s = pile()
    for _ in range(120):
        s.step(1 / 60)
    snap = s.snapshot()
    save_snapshot(s, tmp_path / "pile.npz")
    for _ in range(60):
        s.step(1 / 60)
    want = state(s)
    for _ in range(30):  # (this scene's kept candidates are its own now)
        s.step(1 / 60)
    s.restore(snap)
    for _ in range(60):
        s.step(1 / 60)
    assert state(s) == want
    other = pile()
    other.step(1 / 60)
    load_snapshot(other, tmp_path / "pile.npz")
    for _ in range(60):
        other.step(1 / 60)
    assert state(other) == want
    assert s._stages["broad_phase"].kept.builds > 0  # (the kept candidates were in use)


@pytest.mark.parametrize("gap", [5.0, 0.0, -0.25])
def test_movers_far_from_every_static_are_not_swept_against_them(monkeypatch, gap):
    """A level's tiles cost the broad phase nothing while every mover's bounds lie outside the box
    around all of them (``gap`` above their top; touching is outside, as for a pair), and the pairs
    are brute force's either way: 100 movers above a floor of 2,000 unit tiles."""
    rng = np.random.default_rng(7)
    tx = np.arange(2000, dtype=np.float64) - 1000.0
    tiles = (tx, np.full(2000, -1.0), tx + 1.0, np.zeros(2000))
    x, y = rng.uniform(-30.0, 30.0, 100), rng.uniform(gap, gap + 20.0, 100)
    movers = (x, y, x + rng.uniform(0.5, 2.0, 100), y + rng.uniform(0.5, 2.0, 100))
    b = tuple(np.concatenate([m, t]) for m, t in zip(movers, tiles, strict=True))
    static = np.arange(2100) >= 100
    swept = []
    real = SpatialHash._cross_static
    monkeypatch.setattr(SpatialHash, "_cross_static", lambda self, *a: swept.append(1) or real(self, *a))
    got = hashed_pairs(*b, static, np.arange(2100, dtype=np.int64))[1]
    exp = brute_force_pairs(*b, static)
    assert np.array_equal(got[0], exp[0]) and np.array_equal(got[1], exp[1])
    assert (len(swept) == 0) == (gap >= 0.0)
    assert bool((exp[1] >= 100).any()) == (gap < 0.0)  # (mover-tile pairs only when they overlap)


def _direct_pairs_by_brute_force(moving, kind, body, asleep, entity, minx, miny, maxx, maxy, static_kind):
    """What ``direct_pairs`` answers, spelled out: each mover against every hitbox row that is
    static, asleep or moving (a moving pair from its lower row), bounds strictly overlapping."""
    movers = set(moving.tolist())
    keys = []
    for i in moving.tolist():
        for r in range(kind.size):
            if kind[r] < 0 or not (r in movers or body[r] == static_kind or asleep[r]) or r == i:
                continue
            if r in movers and r < i:
                continue
            if maxx[i] > minx[r] and maxx[r] > minx[i] and maxy[i] > miny[r] and maxy[r] > miny[i]:
                a, b = sorted((int(entity[i]), int(entity[r])))
                keys.append((a << 32) | b)
    return np.sort(np.array(keys, dtype=np.int64))


@pytest.mark.parametrize("seed", range(6))
def test_direct_pairs_tested_or_swept_are_the_brute_force_pairs(seed):
    """Few movers are tested against every row, many are swept by left edge (movers against each
    other; each against the still rows within the widest one to its left): the same pairs, in the
    order of their keys, as brute force, and their rows, with touching boxes, wide static rows,
    movers without a hitbox and sleepers."""
    from framework.collision.broad_phase import SWEEP_FROM, direct_pairs

    rng = np.random.default_rng(seed)
    swept = tested = 0
    for trial in range(40):
        n = int(rng.integers(1, 260))
        kind = rng.integers(-1, 3, n)
        body = rng.integers(0, 3, n)
        asleep = rng.random(n) < 0.2
        entity = rng.permutation(10 * n)[:n].astype(np.int64)
        x, y = np.round(rng.random(n) * 20, 1), np.round(rng.random(n) * 20, 1)  # (tenths: many touch)
        w, h = np.round(rng.random(n) * (3 if trial % 2 else 30), 1), np.round(rng.random(n) * 3, 1)
        minx, maxx, miny, maxy = x - w, x + w, y - h, y + h
        moving = np.flatnonzero((body != 1) & ~asleep).astype(np.int64)
        lut = np.full(10 * n, -1, dtype=np.int64)
        lut[entity] = np.arange(n)
        layers_open = trial % 3 != 0  # (else random layers and masks: the pairs whose layers meet)
        layer = np.ones(n, dtype=np.int64) if layers_open else 1 << rng.integers(0, 3, n)
        mask = np.full(n, -1, dtype=np.int64) if layers_open else rng.integers(0, 8, n)
        ea, eb, ra, rb = direct_pairs(moving, kind, body, asleep, entity, minx, miny, maxx, maxy, 1, lut, layer, mask,
                                      layers_open)
        want = _direct_pairs_by_brute_force(moving, kind, body, asleep, entity, minx, miny, maxx, maxy, 1)
        wa, wb = lut[want >> 32], lut[want & 0xFFFFFFFF]
        want = want[((layer[wa] & mask[wb]) != 0) & ((layer[wb] & mask[wa]) != 0)]
        assert ((ea << 32) | eb).tobytes() == want.tobytes(), trial
        assert (entity[ra] == ea).all() and (entity[rb] == eb).all()
        still = int(np.count_nonzero((kind >= 0) & (body != 1) & asleep | (kind >= 0) & (body == 1)))
        swept += moving.size * (moving.size + still) > SWEEP_FROM
        tested += moving.size * (moving.size + still) <= SWEEP_FROM
    assert swept > 5 and tested > 5  # (both ways were taken)
