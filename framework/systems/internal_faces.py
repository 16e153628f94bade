"""Internal faces of static boxes: the response never pushes a body out through a face that another
static box covers.

In a tiled level the bottom face of a wall's lowest tile lies flat on the floor tile under it. A
body that slid into the wall and entered that tile deeper sideways than it overlaps it vertically
would, by the minimum-depth rule, be pushed *down* out of the tile, into the floor, which pushes it
back up: it stays in the corner, and its next step carries it through the wall. Such a covered
face is *internal*: nothing can be outside it. The response therefore re-measures a contact whose
push-out direction leaves a static box through an internal face along the box's open faces and
takes the shallowest of those (the same idea as Box2D's ghost vertices on chain shapes).

A face of static box ``T`` is internal when one other static box ``N`` (not one-way, not a sensor,
the same layer and mask) spans the whole face and reaches past it, to within a tolerance of the
coordinates' rounding. Computed lazily, per static box that meets a contact, and kept until the
static set changes. Events keep the contact normal of the contract; only the push changes.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from ..arrays import BoolArray, F64Array, I64Array, IntpArray, distinct
from ..collision.broad_phase import SpatialHash
from ..compiled import kernel, leaf
from ..geometry import Geometry
from ..store import KIND_AABB, STATIC, BodyStore

__all__ = ["InternalFaces"]

RowsOf = Callable[[I64Array], I64Array]  # entity ids -> store rows

# Face bits, by the direction a body leaves the box through them.
LEFT, RIGHT, DOWN, UP = 1, 2, 4, 8
AXIS_TOLERANCE = 1e-9  # a unit normal's other component below this: the normal is along an axis
_UNKNOWN = 255


class InternalFaces:
    """Per static row, which faces of its box are covered by another static box (lazily)."""

    def __init__(self) -> None:
        self._key: tuple = ()
        self._mask = np.zeros(0, dtype=np.uint8)

    def masks(self, store: BodyStore, geom: Geometry, hash_: SpatialHash, rows_of: RowsOf,
              rows: IntpArray) -> NDArray[np.uint8]:
        """Face bits of the static AABB ``rows`` (0 for rows of other kinds)."""
        self.table(store)
        todo = distinct(rows[self._mask[rows] == _UNKNOWN])
        if todo.size:
            self._mask[todo] = self._compute(store, geom, hash_, rows_of, todo)
        return self._mask[rows]

    def table(self, store: BodyStore) -> NDArray[np.uint8]:
        """The face bits per row, as far as known (``_UNKNOWN``: not yet), for the current statics."""
        key = (store.version, store.static_epoch, store.n)
        if key != self._key:
            self._key = key
            self._mask = np.full(store.n, _UNKNOWN, dtype=np.uint8)
        return self._mask

    @staticmethod
    def _eligible(store: BodyStore, rows: IntpArray) -> BoolArray:
        return (store.kind[rows] == KIND_AABB) & (store.body[rows] == STATIC) & ~store.one_way[rows] \
            & ~store.sensor[rows]

    def _compute(self, store: BodyStore, geom: Geometry, hash_: SpatialHash, rows_of: RowsOf,
                 rows: IntpArray) -> NDArray[np.uint8]:
        out = np.zeros(rows.size, dtype=np.uint8)
        ok = self._eligible(store, rows)
        if not ok.any():
            return out
        t = rows[ok]
        tx0, tx1 = geom.hx[t] - store.hw[t], geom.hx[t] + store.hw[t]
        ty0, ty1 = geom.hy[t] - store.hh[t], geom.hy[t] + store.hh[t]
        tol = 1e-9 * (1.0 + np.maximum(np.abs(tx0), np.abs(tx1)) + np.maximum(np.abs(ty0), np.abs(ty1)))
        # Ask with ids above every entity id, so each pair comes as (neighbour entity, query).
        base = int(store.entity.max()) + 1
        ea, eb = hash_.static_pairs(tx0 - tol, ty0 - tol, tx1 + tol, ty1 + tol, base + np.arange(t.size))
        i, n = eb - base, rows_of(ea)
        keep = (n >= 0) & (n != t[i])
        i, n = i[keep], n[keep]
        r = t[i]
        good = self._eligible(store, n) & (store.layer[n] == store.layer[r]) & (store.mask[n] == store.mask[r])
        n, i = n[good], i[good]
        nx0, nx1 = geom.hx[n] - store.hw[n], geom.hx[n] + store.hw[n]
        ny0, ny1 = geom.hy[n] - store.hh[n], geom.hy[n] + store.hh[n]
        e = tol[i]
        spans_x = (nx0 <= tx0[i] + e) & (nx1 >= tx1[i] - e)
        spans_y = (ny0 <= ty0[i] + e) & (ny1 >= ty1[i] - e)
        bits = np.zeros(i.size, dtype=np.uint8)
        bits |= np.where(spans_x & (ny0 < ty0[i] - e) & (ny1 >= ty0[i] - e), DOWN, 0).astype(np.uint8)
        bits |= np.where(spans_x & (ny1 > ty1[i] + e) & (ny0 <= ty1[i] + e), UP, 0).astype(np.uint8)
        bits |= np.where(spans_y & (nx0 < tx0[i] - e) & (nx1 >= tx0[i] - e), LEFT, 0).astype(np.uint8)
        bits |= np.where(spans_y & (nx1 > tx1[i] + e) & (nx0 <= tx1[i] + e), RIGHT, 0).astype(np.uint8)
        acc = np.zeros(t.size, dtype=np.uint8)
        np.bitwise_or.at(acc, i, bits)
        out[ok] = acc
        return out

    def redirect(self, store: BodyStore, geom: Geometry, hash_: SpatialHash, rows_of: RowsOf, ra: IntpArray,
                 rb: IntpArray, nx: F64Array, ny: F64Array, depth: F64Array, hit: BoolArray,
                 rank: F64Array) -> int:
        """Re-aim (in place) the contacts whose push-out leaves a static box through an internal face:
        along the box's open face the body is least deep behind; or, if the body's middle lies
        beyond that face, drop them (``hit`` False: the covering box's own contact resolves the
        body). Returns how many changed.

        ``rank`` (the depth, on entry) orders a body's contacts for the deepest-first push-out. A
        re-aimed contact ranks below every plain one, and among re-aimed ones by its measured
        depth: its body also overlaps the box that covers the face, and that contact goes first
        (a box that slid into a wall's lowest tile leaves it sideways, and the floor tile under the
        wall, whose top is covered, is then not touched at all)."""
        found = self._through_covered(store, geom, hash_, rows_of, ra, rb, nx, ny, hit)
        if found is None:
            return 0
        cand, t, m, sgn, faces, px, py = found
        # The body's extent along the box's axes (exact for any convex shape: its bounds).
        lo_x, hi_x, lo_y, hi_y = _extent(store, geom, m)
        tx, ty = geom.hx[t], geom.hy[t]
        # A body whose middle lies beyond the covered face is mostly in the box covering it, and
        # that contact resolves it: this one is dropped (a triangle resting in a corner, poking a
        # sliver into the floor tile under the wall, must not be pushed through that tile).
        beyond = np.where(px != 0.0, (0.5 * (lo_x + hi_x) - tx) * px - store.hw[t],
                          (0.5 * (lo_y + hi_y) - ty) * py - store.hh[t]) > 0.0
        if beyond.any():
            hit[cand[beyond]] = False
            keep = ~beyond
            cand, t, m, sgn, faces = cand[keep], t[keep], m[keep], sgn[keep], faces[keep]
            lo_x, hi_x, lo_y, hi_y, tx, ty = lo_x[keep], hi_x[keep], lo_y[keep], hi_y[keep], tx[keep], ty[keep]
            if cand.size == 0:
                return int(beyond.sum())
        d = np.stack([
            hi_x - (tx - store.hw[t]),  # LEFT: leave through the left face
            (tx + store.hw[t]) - lo_x,  # RIGHT
            hi_y - (ty - store.hh[t]),  # DOWN
            (ty + store.hh[t]) - lo_y,  # UP
        ], axis=1)
        blocked = (faces[:, None] & np.array([LEFT, RIGHT, DOWN, UP], dtype=np.uint8)[None, :]) != 0
        d = np.where(blocked | ~(d > 0.0), np.inf, d)
        best = np.argmin(d, axis=1)
        dd = d[np.arange(cand.size), best]
        ok = np.isfinite(dd)  # every face covered (a body buried in the ground): keep the contact
        if not ok.any():
            return int(beyond.sum())
        cand, best, dd, sgn = cand[ok], best[ok], dd[ok], sgn[ok]
        dirs = np.array([[-1.0, 0.0], [1.0, 0.0], [0.0, -1.0], [0.0, 1.0]])
        nx[cand] = dirs[best, 0] * sgn
        ny[cand] = dirs[best, 1] * sgn
        depth[cand] = dd
        rank[cand] = -1.0 / (1.0 + rank[cand])  # in (-1, 0): below every plain depth, same order
        return int(cand.size + beyond.sum())


    def _through_covered(self, store: BodyStore, geom: Geometry, hash_: SpatialHash, rows_of: RowsOf,
                         ra: IntpArray, rb: IntpArray, nx: F64Array, ny: F64Array, among: BoolArray):
        """The contacts ``among`` these whose push-out leaves a static box through an internal face:
        ``(index, box row, body row, sign, the box's faces, push x, push y)``, or None; the push
        ``(px, py)`` is along the covered face's normal.

        A normal along an axis (to the rounding of a turning polygon's: a box turned by -0.0 has
        normals like (-1, 4e-11)) leaves through the face it is the normal of; a corner's (a circle
        or a polygon's corner off the box's corner) through the two faces that meet there: if one
        of them is covered, the corner is that face's end (a ball rolling over the seam of two tiles
        is on the floor, not on a bump). (One compiled pass, :func:`covered_exits`; asked again once
        the faces of boxes met for the first time are known.)"""
        c = store.cols
        table = self.table(store)
        while True:
            ints, floats, todo = covered_exits(ra, rb, among, nx, ny, c["body"], c["kind"], STATIC, KIND_AABB, table,
                                               _UNKNOWN, AXIS_TOLERANCE)
            if todo.size == 0:
                break
            self.masks(store, geom, hash_, rows_of, todo)  # (their faces, into the table)
        if ints.shape[1] == 0:
            return None  # (no push here leaves a box through a covered face)
        cand, t, m, faces = ints
        sgn, px, py = floats
        return cand, t, m, sgn, faces, px, py


@kernel
def covered_exits(ra, rb, among, nx, ny, body, kind, static, box, faces, unknown, tolerance):
    # pragma: no cover - compiled
    """``InternalFaces._through_covered`` over the contacts ``among`` these: those between a static
    box and a body that is not static whose push (normal ``nx, ny``, the body moving along ``sign *
    n``) leaves the box through a face its bits in ``faces`` say is covered, as ``(ints, floats,
    todo)``: the rows of ``ints`` (index, box row, body row, the box's face bits), of ``floats``
    (sign, push x, push y). Where some such box's bits are not known yet (``unknown``), nothing but
    ``todo``, those boxes' rows (with repeats), for the caller to work out first."""
    n = ra.size
    idx = np.empty(n, dtype=np.int64)
    todo = np.empty(n, dtype=np.int64)
    k = w = 0
    for i in range(n):
        if not among[i]:
            continue
        a, b = ra[i], rb[i]
        static_a, static_b = body[a] == static, body[b] == static
        t = a if static_a else b
        if static_a != static_b and kind[t] == box:
            if faces[t] == unknown:
                todo[w] = t
                w += 1
            elif faces[t] != 0:  # (a box with no covered face re-aims nothing)
                idx[k] = i
                k += 1
    if w:
        k = 0  # (the boxes' faces first)
    ints, floats = np.empty((4, k), dtype=np.int64), np.empty((3, k))
    m = 0
    for j in range(k):
        i = idx[j]
        static_a = body[ra[i]] == static
        t, mover = (ra[i], rb[i]) if static_a else (rb[i], ra[i])
        sgn = 1.0 if static_a else -1.0
        px, py = nx[i] * sgn, ny[i] * sgn
        f = faces[t]
        cov_x = (f & (LEFT if px < 0 else RIGHT)) != 0
        cov_y = (f & (DOWN if py < 0 else UP)) != 0
        along_x = abs(py) <= tolerance
        along_y = not along_x and abs(px) <= tolerance
        # the covered face it leaves through: its axis's; at a corner, the covered one of the two
        # (both covered: the one nearer the normal)
        use_x = along_x or (not along_y and (cov_x if cov_x != cov_y else abs(px) >= abs(py)))
        if not (cov_x if use_x else cov_y):
            continue
        ints[0, m], ints[1, m], ints[2, m], ints[3, m] = i, t, mover, f
        floats[0, m] = sgn
        floats[1, m] = _sign(px) if use_x else 0.0
        floats[2, m] = 0.0 if use_x else _sign(py)
        m += 1
    return ints[:, :m], floats[:, :m], todo[:w]


@leaf
def _sign(x):  # pragma: no cover - compiled
    """``np.sign`` of a float (0.0 for either zero, as numpy; numba's keeps -0.0)."""
    return 1.0 if x > 0.0 else -1.0 if x < 0.0 else x if x != x else 0.0


def _extent(store: BodyStore, geom: Geometry, rows: IntpArray) -> tuple[F64Array, F64Array, F64Array, F64Array]:
    """``(minx, maxx, miny, maxy)`` of the rows' hitboxes where their origins are now."""
    hx, hy = geom.hx[rows], geom.hy[rows]
    ex, ey = store.hw[rows].copy(), store.hh[rows].copy()
    lo_x, hi_x, lo_y, hi_y = hx - ex, hx + ex, hy - ey, hy + ey
    poly = np.flatnonzero(geom.poly_slot[rows] >= 0) if geom.poly_slot.size else np.zeros(0, dtype=np.int64)
    if poly.size:
        w = geom.world_poly[geom.poly_slot[rows[poly]]]  # relative to the hitbox origin
        lo_x[poly], hi_x[poly] = hx[poly] + w[:, :, 0].min(axis=1), hx[poly] + w[:, :, 0].max(axis=1)
        lo_y[poly], hi_y[poly] = hy[poly] + w[:, :, 1].min(axis=1), hy[poly] + w[:, :, 1].max(axis=1)
    return lo_x, hi_x, lo_y, hi_y
