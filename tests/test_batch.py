"""The batch (numpy) kernels against the scalar reference ``collide``, pair for pair.

For every ordered pair of shape kinds (AABB, circle, rotated ``Polygon.box``, general polygon):
thousands of random pairs, about half overlapping, plus exact touching on dyadic coordinates,
identical and concentric shapes, containment, and all of it again at coordinates near 1e9. The
kernels must make the same overlap decision as ``collide`` on every pair, give the same depth and
normal to 1e-12 (relative to the pair's size) and the same point to 1e-9 (or else a point of the
overlap).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from framework.collision import collide
from framework.collision.batch import (
    ContactArrays,
    aabb_aabb,
    aabb_aabb_fast,
    circle_circle,
    collide_many,
    outlines,
    polygon_circle,
    polygon_polygon,
)
from framework.components import Transform
from framework.shapes import AABB, Circle, Polygon

KINDS = ("aabb", "circle", "box", "polygon")
COMBOS = [(a, b) for a in KINDS for b in KINDS]
N_RANDOM = 1000

Pair = tuple[object, tuple[float, float, float], object, tuple[float, float, float]]


# --- shapes and pairs ------------------------------------------------------------------------

def dyadic(rng: np.random.Generator, lo: float, hi: float, denom: int = 16) -> float:
    return float(rng.integers(int(lo * denom), int(hi * denom) + 1)) / denom


def random_polygon(rng: np.random.Generator) -> Polygon:
    while True:
        n = int(rng.integers(3, 9))
        ang = np.sort(rng.uniform(0.0, 2.0 * math.pi, n))
        rx, ry = rng.uniform(0.3, 3.0, 2)
        cx, cy = rng.uniform(-0.5, 0.5, 2) * min(rx, ry)  # origin off the centroid
        pts = [(cx + rx * math.cos(a), cy + ry * math.sin(a)) for a in ang]
        try:
            return Polygon(pts)
        except ValueError:
            continue


def random_shape(rng: np.random.Generator, kind: str):
    if kind == "aabb":
        return AABB(dyadic(rng, 0.25, 6), dyadic(rng, 0.25, 6))
    if kind == "circle":
        return Circle(dyadic(rng, 0.125, 3))
    if kind == "box":
        return Polygon.box(dyadic(rng, 0.25, 6), dyadic(rng, 0.25, 6))
    return random_polygon(rng)


def random_rotation(rng: np.random.Generator, kind: str) -> float:
    u = rng.random()
    if kind == "circle" or u < 0.3:
        return 0.0
    if u < 0.4:
        return float(rng.integers(-4, 5)) * math.pi / 2
    return float(rng.uniform(-math.pi, math.pi))  # also given to AABBs, which ignore it


def random_pairs(rng: np.random.Generator, ka: str, kb: str, n: int) -> list[Pair]:
    pairs = []
    for _ in range(n):
        sa, sb = random_shape(rng, ka), random_shape(rng, kb)
        ax, ay = dyadic(rng, -64, 64), dyadic(rng, -64, 64)
        reach = sa.bounding_radius + sb.bounding_radius
        ang = rng.uniform(0.0, 2.0 * math.pi)
        spread = {0: 1.0, 1: 1.2, 2: 1.5}[(ka, kb).count("circle")]  # about half overlap
        dist = reach * spread * rng.uniform(0.0, 1.0) ** 0.7
        bx, by = ax + dist * math.cos(ang), ay + dist * math.sin(ang)
        if rng.random() < 0.5:  # dyadic positions: exact arithmetic, exact touching possible
            bx, by = round(bx * 64) / 64, round(by * 64) / 64
        pairs.append((sa, (ax, ay, random_rotation(rng, ka)), sb, (bx, by, random_rotation(rng, kb))))
    return pairs


def _solid(kind: str, w: float, h: float):
    return {"aabb": AABB, "box": Polygon.box}[kind](w, h) if kind != "circle" else Circle(w / 2)


def touching_pairs(ka: str, kb: str) -> list[Pair]:
    """Exactly touching (gap 0) pairs on dyadic coordinates, plus the same one ulp closer."""
    out: list[Pair] = []
    rng = np.random.default_rng(7)
    for _ in range(60):
        w1, h1, w2, h2 = (dyadic(rng, 0.25, 4, 8) for _ in range(4))
        ax, ay = dyadic(rng, -20, 20, 4), dyadic(rng, -20, 20, 4)
        if ka in ("aabb", "box") and kb in ("aabb", "box"):
            a, b = _solid(ka, w1, h1), _solid(kb, w2, h2)
            sx, sy = rng.choice([-1, 1], 2)
            gx, gy = (w1 + w2) / 2, (h1 + h2) / 2
            for dx, dy in ((sx * gx, dyadic(rng, -gy, gy, 8)), (dyadic(rng, -gx, gx, 8), sy * gy),
                           (sx * gx, sy * gy)):
                out.append((a, (ax, ay, 0.0), b, (ax + dx, ay + dy, 0.0)))
        elif ka == "circle" and kb == "circle":
            s = dyadic(rng, 0.125, 2, 8)
            ra = 5 * s * float(rng.integers(1, 8)) / 8
            a, b = Circle(ra), Circle(5 * s - ra)
            sx, sy = rng.choice([-1, 1], 2)
            out.append((a, (ax, ay, 0.0), b, (ax + sx * 3 * s, ay + sy * 4 * s, 0.0)))
        elif "circle" in (ka, kb) and {ka, kb} <= {"aabb", "box", "circle"}:
            box = _solid(ka if ka != "circle" else kb, w1, h1)
            s = dyadic(rng, 0.125, 1, 8)
            hw, hh = w1 / 2, h1 / 2
            cases = [(dyadic(rng, -hw, hw, 8), hh + 5 * s), (hw + 5 * s, dyadic(rng, -hh, hh, 8)),
                     (hw + 3 * s, hh + 4 * s), (-hw - 4 * s, -hh - 3 * s)]
            for dx, dy in cases:
                c = (Circle(5 * s), (ax + dx, ay + dy, 0.0))
                p = (box, (ax, ay, 0.0))
                out.append((*p, *c) if ka != "circle" else (*c, *p))
        else:
            # An integer triangle with its bottom edge on y = 0, the other shape just below it
            # (the line y = 0 separates them exactly).
            tri = Polygon([(0, 0), (4 + int(4 * w1), 0), (int(2 * w1), 1 + int(4 * h1))])
            kind = kb if ka == "polygon" else ka
            if kind == "circle":
                other, top, dx = Circle(w2), w2, 2.0
            elif kind == "polygon":
                other, top, dx = Polygon([(0, 0), (3, 1), (1, 3)]), 3.0, 1.0
            else:
                other, top, dx = _solid(kind, w2, h2), h2 / 2, 2.0
            p = (tri, (ax, ay, 0.0))
            o = (other, (ax + dx, ay - top, 0.0))
            out.append((*p, *o) if ka == "polygon" else (*o, *p))
    # One ulp into the overlap: a collision, decided the same way.
    closer = []
    for sa, ta, sb, tb in out:
        bx, by = tb[0], tb[1]
        mx = math.nextafter(bx, ta[0]) if bx != ta[0] else bx
        my = math.nextafter(by, ta[1]) if by != ta[1] else by
        closer.append((sa, ta, sb, (mx, my, tb[2])))
    return out + closer


SMALL = {"aabb": AABB(0.25, 0.125), "circle": Circle(0.0625), "box": Polygon.box(0.25, 0.125),
         "polygon": Polygon([(0, 0), (0.25, 0), (0, 0.125)])}
BIG = {"aabb": AABB(20, 16), "circle": Circle(10), "box": Polygon.box(20, 16),
       "polygon": Polygon([(-10, -9), (11, -8), (9, 10), (-8, 9)])}


def special_pairs(rng: np.random.Generator, ka: str, kb: str) -> list[Pair]:
    """Identical and concentric shapes, containment."""
    out: list[Pair] = []
    for _ in range(40):
        sa = random_shape(rng, ka)
        sb = sa if ka == kb else random_shape(rng, kb)
        ax, ay = dyadic(rng, -10, 10), dyadic(rng, -10, 10)
        rot = random_rotation(rng, ka)
        out.append((sa, (ax, ay, rot), sb, (ax, ay, rot if ka == kb else random_rotation(rng, kb))))
        # B much smaller, inside A, and A much smaller, inside B.
        off = (dyadic(rng, -3, 3), dyadic(rng, -3, 3))
        out.append((BIG[ka], (ax, ay, rot), SMALL[kb], (ax + off[0], ay + off[1], random_rotation(rng, kb))))
        out.append((SMALL[ka], (ax + off[0], ay + off[1], random_rotation(rng, ka)), BIG[kb], (ax, ay, rot)))
    return out


def shifted(pairs: list[Pair], sx: float, sy: float) -> list[Pair]:
    return [(sa, (ta[0] + sx, ta[1] + sy, ta[2]), sb, (tb[0] + sx, tb[1] + sy, tb[2]))
            for sa, ta, sb, tb in pairs]


def all_pairs(ka: str, kb: str) -> list[Pair]:
    rng = np.random.default_rng(100 + 10 * KINDS.index(ka) + KINDS.index(kb))
    pairs = random_pairs(rng, ka, kb, N_RANDOM) + touching_pairs(ka, kb) + special_pairs(rng, ka, kb)
    far = shifted(pairs[: N_RANDOM // 4], 1e9, -1e9) + shifted(pairs[N_RANDOM:], 1e9, 1e9)
    return pairs + far


# --- kernels, called as the narrow phase calls them --------------------------------------------

def _kind(shape: object) -> str:
    if isinstance(shape, AABB):
        return "aabb"
    return "circle" if isinstance(shape, Circle) else "polygon"


def kernel_results(pairs: list[Pair], fallback: bool = True) -> ContactArrays:
    """The kernel of this (single) kind combination on the pairs.
    ``fallback=False``: the kernels as the response calls them (no exact fallback, no points)."""
    sa = [p[0] for p in pairs]
    sb = [p[2] for p in pairs]
    ta = np.array([p[1] for p in pairs], dtype=float).reshape(-1, 3)
    tb = np.array([p[3] for p in pairs], dtype=float).reshape(-1, 3)
    ka, kb = {_kind(s) for s in sa}, {_kind(s) for s in sb}
    assert len(ka) <= 1 and len(kb) <= 1
    ka_, kb_ = (ka.pop() if ka else "polygon"), (kb.pop() if kb else "polygon")
    ax, ay, bx, by = ta[:, 0], ta[:, 1], tb[:, 0], tb[:, 1]
    if ka_ == kb_ == "circle":
        args = (ax, ay, [s.radius for s in sa], bx, by, [s.radius for s in sb])
        return circle_circle(*args, exact=fallback)
    if ka_ == kb_ == "aabb":
        args = (ax, ay, [s.width / 2 for s in sa], [s.height / 2 for s in sa],
                bx, by, [s.width / 2 for s in sb], [s.height / 2 for s in sb])
        if not fallback:
            return aabb_aabb_fast(*args, exact=False, points=False)
        return aabb_aabb(*args)
    if kb_ == "circle":
        args = (ax, ay, *outlines(sa, ta[:, 2]), bx, by, [s.radius for s in sb])
        return polygon_circle(*args, exact=fallback)
    if ka_ == "circle":
        args = (bx, by, *outlines(sb, tb[:, 2]), ax, ay, [s.radius for s in sa])
        return polygon_circle(*args, flip=True, exact=fallback)
    args = (ax, ay, *outlines(sa, ta[:, 2]), bx, by, *outlines(sb, tb[:, 2]))
    return polygon_polygon(*args, exact=fallback, points=fallback)


# --- comparison ------------------------------------------------------------------------------

def outside_by(shape, t, x: float, y: float) -> float:
    """How far (x, y) lies outside the shape (<= 0 inside), in world units."""
    tx, ty, rot = t
    if isinstance(shape, Circle):
        return math.hypot(x - tx, y - ty) - shape.radius
    if isinstance(shape, AABB):
        pts = [(-shape.width / 2, -shape.height / 2), (shape.width / 2, -shape.height / 2),
               (shape.width / 2, shape.height / 2), (-shape.width / 2, shape.height / 2)]
        rot = 0.0
    else:
        pts = list(shape.points)
    c, s = math.cos(rot), math.sin(rot)
    lx, ly = x - tx, y - ty
    worst = -math.inf
    for i in range(len(pts)):
        (x0, y0), (x1, y1) = pts[i], pts[(i + 1) % len(pts)]
        x0, y0, x1, y1 = c * x0 - s * y0, s * x0 + c * y0, c * x1 - s * y1, s * x1 + c * y1
        ex, ey = x1 - x0, y1 - y0
        worst = max(worst, (ey * (lx - x0) - ex * (ly - y0)) / math.hypot(ex, ey))
    return worst


def assert_matches(pairs: list[Pair], res: ContactArrays, label: str) -> None:
    for arr in res:
        assert arr.shape == (len(pairs),)
    floats = np.stack(res[1:])
    assert np.isfinite(floats).all()
    assert not np.signbit(res.nx[res.nx == 0.0]).any() and not np.signbit(res.ny[res.ny == 0.0]).any()
    assert (floats[:, ~res.hit] == 0.0).all()
    for i, (sa, ta, sb, tb) in enumerate(pairs):
        c = collide(sa, ta, sb, tb)
        where = f"{label} pair {i}: {sa!r} {ta!r} / {sb!r} {tb!r}"
        assert bool(res.hit[i]) == (c is not None), f"{where}: batch {bool(res.hit[i])}, collide {c}"
        if c is None:
            continue
        size = sa.bounding_radius + sb.bounding_radius
        got_n = (res.nx[i], res.ny[i])
        assert abs(got_n[0] - c.normal.x) <= 1e-12 and abs(got_n[1] - c.normal.y) <= 1e-12, \
            f"{where}: normal {got_n} vs {c}"
        assert abs(res.depth[i] - c.depth) <= 1e-12 * max(c.depth, size), \
            f"{where}: depth {res.depth[i]} vs {c}"
        assert res.depth[i] > 0.0
        tol = 1e-9 * (1.0 + size) + 4 * float(np.spacing(abs(ta[0]) + abs(ta[1]) + size))
        px, py = float(res.px[i]), float(res.py[i])
        if abs(px - c.point.x) <= tol and abs(py - c.point.y) <= tol:
            continue
        slack = 1e-9 * size + 4 * float(np.spacing(abs(ta[0]) + abs(ta[1]) + size))
        assert outside_by(sa, ta, px, py) <= slack and outside_by(sb, tb, px, py) <= slack, \
            f"{where}: point {(px, py)} vs {c}, not in the overlap"


@pytest.mark.parametrize(("ka", "kb"), COMBOS, ids=[f"{a}-{b}" for a, b in COMBOS])
def test_kernels_match_collide(ka: str, kb: str) -> None:
    pairs = all_pairs(ka, kb)
    res = kernel_results(pairs)
    assert_matches(pairs, res, "kernel")
    assert res.hit.dtype == bool
    frac = res.hit[:N_RANDOM].mean()
    assert 0.3 < frac < 0.8, f"random pairs should overlap about half the time, got {frac}"


def test_collide_many_mixed_order_and_transforms() -> None:
    rng = np.random.default_rng(11)
    pairs: list[Pair] = []
    for ka, kb in COMBOS:
        pairs += random_pairs(rng, ka, kb, 40)
    order = rng.permutation(len(pairs))
    pairs = [pairs[i] for i in order]
    ta = [Transform(*t) if i % 2 else t for i, (_, t, _, _) in enumerate(pairs)]
    tb = [t[:2] if t[2] == 0.0 else t for _, _, _, t in pairs]
    res = collide_many([p[0] for p in pairs], ta, [p[2] for p in pairs], tb)
    assert_matches(pairs, res, "collide_many")
    assert 0.3 < res.hit.mean() < 0.8


def test_touching_is_exact_and_one_ulp_overlaps() -> None:
    a, b = AABB(2, 2), AABB(2, 4)
    res = aabb_aabb([0.0, 0.0], [0.0, 0.0], 1.0, [1.0, 1.0], [2.0, math.nextafter(2.0, 0)], 0.5, 1.0, 2.0)
    assert res.hit.tolist() == [False, True]
    assert collide(a, (0, 0), b, (2, 0.5)) is None
    res = circle_circle(0.0, 0.0, 2.0, [3.0, 3.0], [4.0, math.nextafter(4.0, 0)], 3.0)
    assert res.hit.tolist() == [False, True]


def test_coincident_centres_push_up() -> None:
    res = circle_circle([1e9, 0.0], [5.0, -3.0], [1.0, 2.0], [1e9, 0.0], [5.0, -3.0], [2.0, 2.0])
    assert res.hit.all()
    assert res.nx.tolist() == [0.0, 0.0] and res.ny.tolist() == [1.0, 1.0]
    assert res.depth.tolist() == [3.0, 4.0]


def test_far_offset_matches_origin() -> None:
    rng = np.random.default_rng(5)
    pairs = [(sa, (ta[0], ta[1], ta[2]), sb, (round(tb[0] * 64) / 64, round(tb[1] * 64) / 64, tb[2]))
             for sa, ta, sb, tb in random_pairs(rng, "polygon", "box", 300)]
    near = collide_many(*zip(*[(p[0], p[1], p[2], p[3]) for p in pairs], strict=True))
    # An integer offset keeps dyadic positions exact, so the answers are the same.
    far = collide_many(*zip(*shifted(pairs, 2.0**30, -(2.0**30)), strict=True))
    assert (near.hit == far.hit).all()
    assert np.allclose(near.depth, far.depth, rtol=0, atol=1e-12)
    assert np.allclose(near.nx, far.nx, rtol=0, atol=1e-12)
    assert np.allclose(near.px[near.hit] + 2.0**30, far.px[far.hit], rtol=0, atol=1e-6)


def test_empty_inputs() -> None:
    e = np.zeros(0)
    v, c = outlines([], e)
    assert v.shape[0] == 0 and c.shape == (0,)
    results = [
        circle_circle(e, e, e, e, e, e), aabb_aabb(e, e, e, e, e, e, e, e),
        polygon_circle(e, e, v, c, e, e, e), polygon_circle(e, e, v, c, e, e, e, flip=True),
        polygon_polygon(e, e, v, c, e, e, v, c), collide_many([], [], [], []),
    ]
    for r in results:
        assert all(a.shape == (0,) for a in r)


def test_outlines_rotate_polygons_not_aabbs_and_pad() -> None:
    tri = Polygon([(0, 0), (2, 0), (0, 1)])
    v, c = outlines([AABB(2, 4), tri, Polygon.box(2, 2)], [1.0, math.pi / 2, 0.0])
    assert v.shape == (3, 4, 2) and c.tolist() == [4, 3, 4]
    assert v[0].tolist() == [[-1, -2], [1, -2], [1, 2], [-1, 2]]
    assert np.allclose(v[1, :3], [[0, 0], [0, 2], [-1, 0]], atol=1e-15)
    assert (v[1, 3] == v[1, 2]).all()
    # Padding written by the caller in another scheme is masked the same way.
    pairs_a = np.array([[[0, 0], [2, 0], [0, 1], [99, 99]]], dtype=float)
    res = polygon_polygon(0.0, 0.0, pairs_a, [3], 0.5, 0.25, v[2:], c[2:])
    ref = collide(tri, (0, 0), Polygon.box(2, 2), (0.5, 0.25))
    assert res.hit[0] and abs(res.depth[0] - ref.depth) < 1e-12


def test_bad_inputs_raise() -> None:
    with pytest.raises(ValueError):
        outlines([Circle(1)], [0.0])
    with pytest.raises(ValueError):
        outlines([AABB(1, 1)], [math.nan])
    with pytest.raises(ValueError):
        collide_many([AABB(1, 1)], [(0, math.inf)], [AABB(1, 1)], [(0, 0)])
    with pytest.raises(ValueError):
        collide_many([AABB(1, 1)], [(0, 0)], [], [])


def test_vectorised_tie_break_matches_scalar_rule() -> None:
    """The array form of ``tiebreak.pick`` on candidate sets full of ties: equal and near-equal
    depths, directions and their negations, vertical / horizontal / diagonal, signed zeros."""
    from framework.collision.batch_common import BIG, pick
    from framework.collision.tiebreak import pick as scalar_pick

    rng = np.random.default_rng(3)
    dirs = [(0.0, 1.0), (-0.0, 1.0), (0.0, -1.0), (1.0, 0.0), (-1.0, 0.0), (1.0, -0.0), (-1.0, -0.0),
            (math.sqrt(0.5), math.sqrt(0.5)), (-math.sqrt(0.5), math.sqrt(0.5)),
            (math.sqrt(0.5), -math.sqrt(0.5)), (0.6, 0.8), (-0.6, 0.8), (0.8, -0.6), (1e-13, 1.0)]
    p, c_max = 3000, 12
    depth = np.full((c_max, p), BIG)
    nx = np.zeros((c_max, p))
    ny = np.zeros((c_max, p))
    size = rng.choice([1.0, 3.0, 1e-6, 1e6], p)
    cands_all = []
    for j in range(p):
        n = int(rng.integers(1, c_max + 1))
        base = float(rng.choice([0.5, 1.0, 2.0]))
        cands = []
        for _ in range(n):
            if rng.random() < 0.6:
                d, (x, y) = base, dirs[int(rng.integers(len(dirs)))]
            else:
                a = rng.uniform(0, 2 * math.pi)
                d, (x, y) = base * rng.uniform(1.0, 1.5), (math.cos(a), math.sin(a))
            d += float(rng.choice([0.0, 0.0, 0.3e-12, 2e-12, 1e-16])) * size[j] * base
            cands.append((d * size[j], x, y))
        cands_all.append(cands)
        for i, (d, x, y) in enumerate(cands):
            depth[i, j], nx[i, j], ny[i, j] = d, x, y
    got = pick(depth, nx, ny, size)
    for j, cands in enumerate(cands_all):
        want = scalar_pick(cands, float(size[j]))
        assert (got[0][j], got[1][j], got[2][j]) == want, (cands, size[j], want)


@pytest.mark.parametrize("scale", [2.0**-600, 1e-200, 1e200, 2.0**600])
def test_tiny_and_huge_scenes(scale: float) -> None:
    """Radii of 1e-200 or 1e200 neither underflow nor overflow: the kernels work in the scalar
    code's power-of-two-scaled frame and agree with it."""
    def scaled(shape):
        if isinstance(shape, AABB):
            return AABB(shape.width * scale, shape.height * scale)
        if isinstance(shape, Circle):
            return Circle(shape.radius * scale)
        return Polygon([(x * scale, y * scale) for x, y in shape.points])

    pairs: list[Pair] = []
    for ka, kb in COMBOS:
        rng = np.random.default_rng(21)
        pairs += random_pairs(rng, ka, kb, 25) + touching_pairs(ka, kb)[:6]
    pairs = [(scaled(sa), (ta[0] * scale, ta[1] * scale, ta[2]),
              scaled(sb), (tb[0] * scale, tb[1] * scale, tb[2])) for sa, ta, sb, tb in pairs]
    res = collide_many(*zip(*pairs, strict=True))
    assert_matches(pairs, res, f"scale {scale}")


def test_fast_box_kernel_matches_the_exact_one():
    """The pipeline's box kernel: same decisions, normals and depths as aabb_aabb; its point is the
    overlap rectangle's centre, inside the overlap."""
    from framework.collision.batch import aabb_aabb, aabb_aabb_fast

    rng = np.random.default_rng(5)
    P = 20_000
    ax, ay = rng.integers(-40, 40, P) / 4.0, rng.integers(-40, 40, P) / 4.0  # dyadic: many touch
    bx, by = ax + rng.integers(-16, 16, P) / 4.0, ay + rng.integers(-16, 16, P) / 4.0
    ahw, ahh, bhw, bhh = (rng.integers(1, 12, P) / 4.0 for _ in range(4))
    ax[:1000] += 1e9  # far from the origin
    bx[:1000] += 1e9
    bx[1000:1100], by[1000:1100] = ax[1000:1100], ay[1000:1100]  # concentric
    ref = aabb_aabb(ax, ay, ahw, ahh, bx, by, bhw, bhh)
    fast = aabb_aabb_fast(ax, ay, ahw, ahh, bx, by, bhw, bhh)
    assert np.array_equal(ref.hit, fast.hit)
    assert np.array_equal(ref.nx, fast.nx) and np.array_equal(ref.ny, fast.ny)
    np.testing.assert_allclose(fast.depth, ref.depth, rtol=1e-12, atol=0)
    h = ref.hit
    assert np.all(np.abs(fast.px[h] - ax[h]) <= ahw[h] + 1e-6) and np.all(np.abs(fast.px[h] - bx[h]) <= bhw[h] + 1e-6)
    assert np.all(np.abs(fast.py[h] - ay[h]) <= ahh[h] + 1e-6) and np.all(np.abs(fast.py[h] - by[h]) <= bhh[h] + 1e-6)
    touching = (np.abs(bx - ax) == ahw + bhw) | (np.abs(by - ay) == ahh + bhh)
    assert touching.sum() > 500 and not fast.hit[touching].any()


def test_fast_box_kernel_matches_the_exact_one_within_ulps_of_touching():
    """Non-dyadic boxes pushed to touching leave overlaps and gaps of a few ulps (the response does
    that every step): the fast kernel decides them exactly, with the exact normals, and depths to
    rounding."""
    from framework.collision.batch import aabb_aabb, aabb_aabb_fast

    rng = np.random.default_rng(8)
    P = 20_000
    ax, ay = rng.uniform(-500, 500, P), rng.uniform(-500, 500, P)
    ahw, ahh, bhw, bhh = (rng.uniform(0.1, 9.0, P) for _ in range(4))
    side = rng.integers(0, 4, P)
    ulps = rng.integers(-6, 7, P)
    bx = np.where(side == 0, ax + (ahw + bhw), np.where(side == 1, ax - (ahw + bhw), ax + rng.uniform(-1, 1, P)))
    by = np.where(side == 2, ay + (ahh + bhh), np.where(side == 3, ay - (ahh + bhh), ay + rng.uniform(-1, 1, P)))
    for k in range(P):  # walk the touching coordinate by a few ulps either way
        for _ in range(abs(int(ulps[k]))):
            d = np.inf if ulps[k] > 0 else -np.inf
            if side[k] < 2:
                bx[k] = np.nextafter(bx[k], d)
            else:
                by[k] = np.nextafter(by[k], d)
    ref = aabb_aabb(ax, ay, ahw, ahh, bx, by, bhw, bhh)
    fast = aabb_aabb_fast(ax, ay, ahw, ahh, bx, by, bhw, bhh)
    assert 0.2 * P < ref.hit.sum() < 0.8 * P  # both outcomes are well represented
    assert np.array_equal(ref.hit, fast.hit)
    assert np.array_equal(ref.nx, fast.nx) and np.array_equal(ref.ny, fast.ny)
    # Depths agree to the rounding of the magnitudes (a few ulps of the sizes and offsets).
    mag = (ahw + bhw) + (ahh + bhh) + np.abs(bx - ax) + np.abs(by - ay)
    assert np.all(np.abs(fast.depth - ref.depth) <= 2.0**-50 * mag)
    assert (fast.depth[fast.hit] > 0).all()


@pytest.mark.parametrize(("ka", "kb"), COMBOS, ids=[f"{a}-{b}" for a, b in COMBOS])
def test_kernels_without_the_exact_fallback_drop_only_touching_rows(ka: str, kb: str) -> None:
    """As the response re-measures (``exact=False``): a pair within rounding of touching counts
    as apart; every other row is the exact kernel's answer (same normal, same depth)."""
    pairs = all_pairs(ka, kb)
    ref = kernel_results(pairs)
    fast = kernel_results(pairs, fallback=False)
    assert not (fast.hit & ~ref.hit).any()
    dropped = np.flatnonzero(ref.hit & ~fast.hit)
    for i in dropped.tolist():
        sa, ta, sb, tb = pairs[i]
        scale = sa.bounding_radius + sb.bounding_radius + abs(tb[0] - ta[0]) + abs(tb[1] - ta[1])
        assert ref.depth[i] <= 1e-9 * scale, (i, pairs[i], ref.depth[i])
    both = ref.hit & fast.hit
    assert both[:N_RANDOM].sum() >= 0.99 * ref.hit[:N_RANDOM].sum()  # random pairs seldom touch
    assert np.array_equal(ref.nx[both], fast.nx[both]) and np.array_equal(ref.ny[both], fast.ny[both])
    np.testing.assert_allclose(fast.depth[both], ref.depth[both], rtol=1e-12, atol=0)


def test_kernels_without_the_exact_fallback_drop_one_ulp_overlaps() -> None:
    # Two unit boxes overlapping by one ulp of their offset: an overlap to collide, touching to
    # the response; the same for polygons and circles.
    x = np.nextafter(1.0, 0.0)
    box = outlines([Polygon.box(1.0, 1.0)], [0.0])
    pp = (0.0, 0.0, *box, x, 0.0, *box)
    assert polygon_polygon(*pp).hit[0] and not polygon_polygon(*pp, exact=False).hit[0]
    pc = (0.0, 0.0, *box, x, 0.0, [0.5])
    assert polygon_circle(*pc).hit[0] and not polygon_circle(*pc, exact=False).hit[0]
    cc = (0.0, 0.0, [0.5], x, 0.0, [0.5])
    assert circle_circle(*cc).hit[0] and not circle_circle(*cc, exact=False).hit[0]


def test_polygon_circle_takes_a_flip_per_row() -> None:
    """One call with a flip per row (the pipeline mixes polygon-circle and circle-polygon pairs)
    gives bit for bit what two calls give, touching and exact rows included."""
    pc, cp = all_pairs("polygon", "circle"), all_pairs("circle", "box")
    poly = [p[0] for p in pc] + [p[2] for p in cp]
    circ = [p[2] for p in pc] + [p[0] for p in cp]
    tp = np.array([p[1] for p in pc] + [p[3] for p in cp], dtype=float).reshape(-1, 3)
    tc = np.array([p[3] for p in pc] + [p[1] for p in cp], dtype=float).reshape(-1, 3)
    v, n = outlines(poly, tp[:, 2])
    joined = [tp[:, 0], tp[:, 1], v, n, tc[:, 0], tc[:, 1], np.array([c.radius for c in circ])]
    k = len(pc)
    one, two = [a[:k] for a in joined], [a[k:] for a in joined]
    flip = np.r_[np.zeros(len(pc), dtype=bool), np.ones(len(cp), dtype=bool)]
    got = polygon_circle(*joined, flip=flip)
    want = [np.concatenate([a, b]) for a, b in zip(polygon_circle(*one), polygon_circle(*two, flip=True), strict=True)]
    for g, w in zip(got, want, strict=True):
        assert np.array_equal(g, w)
    assert got.hit[: len(pc)].any() and got.hit[len(pc):].any()


def test_the_pipeline_measures_a_mixed_batch_as_it_measures_each_pair() -> None:
    """pair_contacts gives a kernel one call per family of pairs (boxes, circles, polygon-circle
    either way round, polygons with boxes): each row's answer is what it gets on its own."""
    from framework import Hitbox, Scene
    from framework.systems.narrow_phase import pair_contacts

    rng = np.random.default_rng(21)
    with Scene() as s:
        ents = []
        for i in range(40):
            kind = KINDS[i % len(KINDS)]
            t = Transform(dyadic(rng, -4, 4), dyadic(rng, -4, 4), random_rotation(rng, kind))
            ents.append(s.spawn(t, Hitbox(random_shape(rng, kind), body="static" if i % 5 == 0 else "dynamic")))
        s.ensure_geometry()  # (where they were spawned: a mix of overlaps and misses)
        rows = np.array([s.store.row_of[e] for e in ents])
        ra, rb = (g.ravel() for g in np.meshgrid(rows, rows, indexing="ij"))
        keep = ra != rb
        ra, rb = ra[keep], rb[keep]
        for remeasure in (False, True):
            whole = pair_contacts(s.store, s.geometry, ra, rb, remeasure=remeasure)
            assert 0.1 < whole.hit.mean() < 0.9
            for i in range(0, ra.size, 7):
                one = pair_contacts(s.store, s.geometry, ra[i:i + 1], rb[i:i + 1], remeasure=remeasure)
                for w, o in zip(whole, one, strict=True):
                    assert w[i] == o[0], (i, remeasure, whole, one)
