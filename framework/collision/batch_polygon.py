"""Batch kernel for convex polygon / convex polygon pairs (boxes paired with polygons included).

Separating axes, vectorised over pairs: the axes are the unnormalised outward edge normals of A
and of B, ``[C, P]`` with ``C = Ka + Kb``; every vertex of both outlines is projected on every
axis (a loop over the few vertices, each step on ``[C, P]``), with B about its own origin and
``u . d`` added, exactly the scalar code's products and comparisons. Rows within the band of
touching on some axis are decided exactly (:mod:`framework.collision.exact`). Only the
overlapping rows go on to normalise their axes, build the ``2 C`` push-out candidates and apply
the tie-break rule.

Contact point: :func:`framework.collision.batch_point.overlap_point`, the scalar code's mean of
the vertices of A ∩ B.

Rows where both outlines are centred axis-aligned rectangles (``Polygon.box`` unturned, or an
AABB's outline) are, to the scalar code, two AABBs: they go to the exact box kernel instead.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..validation import InvalidValue
from .batch_box import aabb_aabb, aabb_aabb_fast
from .batch_common import (
    BIG,
    F64,
    ContactArrays,
    cols,
    columns_of,
    edge_mask,
    edges,
    extent,
    finish,
    frame,
    no_contacts,
    norm,
    outline_rows,
    pick,
)
from .batch_point import overlap_point
from .exact import BAND, TINY, float_rounded, polygon_polygon_exact

__all__ = ["polygon_polygon"]


def _frame(avx, avy, bvx, bvy, ax, ay, bx, by):
    """Both outlines ``[K, P]`` about their own origins and B's offset, in A's scaled frame."""
    dx, dy, k = frame(ax, ay, bx, by, np.maximum(extent(avx, avy), extent(bvx, bvy)))
    avx, avy, bvx, bvy = (np.ldexp(v, -k) for v in (avx, avy, bvx, bvy))
    # The bounding radii summed (fine for tolerances), in the scaled frame.
    size = np.sqrt((avx * avx + avy * avy).max(axis=0)) + np.sqrt((bvx * bvx + bvy * bvy).max(axis=0))
    return avx, avy, bvx, bvy, dx, dy, k, size


def _centred_boxes(vx: NDArray[np.float64], vy: NDArray[np.float64], count: NDArray[np.intp]) -> NDArray[np.bool_]:
    """The outlines that are ``(±hw, ±hh)`` exactly, as an AABB's (``Polygon.box`` unturned)."""
    if vx.shape[0] < 4:
        return np.zeros(count.shape, dtype=bool)
    x0, x1, x2, x3 = vx[:4]
    y0, y1, y2, y3 = vy[:4]
    return ((count == 4) & (x1 > 0.0) & (y2 > 0.0) & (x0 == -x1) & (x2 == x1) & (x3 == x0)
            & (y1 == y0) & (y0 == -y2) & (y3 == y2))


def _rows(ax, ay, averts, acount, bx, by, bverts, bcount):
    avx, avy, acount = outline_rows(averts, acount, "averts")
    bvx, bvy, bcount = outline_rows(bverts, bcount, "bverts")
    p = avx.shape[1]
    if bvx.shape[1] != p:
        raise InvalidValue(f"averts has {p} rows but bverts has {bvx.shape[1]}")
    ax, ay, bx, by = columns_of(p, ax, ay, bx, by)
    is_box = _centred_boxes(avx, avy, acount) & _centred_boxes(bvx, bvy, bcount)
    boxes, rest = np.flatnonzero(is_box), np.flatnonzero(~is_box)
    # Two centred axis-aligned boxes are, to the scalar code, the outlines of two AABBs: the box
    # kernel gives their contacts exactly and far more cheaply (no integer fallback when touching).
    box_args = (ax[boxes], ay[boxes], avx[1, boxes], avy[2, boxes],
                bx[boxes], by[boxes], bvx[1, boxes], bvy[2, boxes])
    return avx, avy, acount, bvx, bvy, bcount, ax, ay, bx, by, boxes, rest, box_args


def _extent(
    ux: NDArray[np.float64], uy: NDArray[np.float64], vx: NDArray[np.float64], vy: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Min and max of every vertex ``[K, P]`` projected on every axis ``[C, P]``: ``[C, P]``."""
    # A loop over the few vertices keeps the temporaries small (3x faster than [C, K, P]).
    lo = ux * vx[0]
    lo += uy * vy[0]
    hi = lo.copy()
    for j in range(1, vx.shape[0]):
        proj = ux * vx[j]
        proj += uy * vy[j]
        np.minimum(lo, proj, out=lo)
        np.maximum(hi, proj, out=hi)
    return lo, hi


def _sat(avx, avy, acount, bvx, bvy, bcount, ax, ay, bx, by, dx, dy, k, size, fallback: bool = True):
    """The separating-axis decision of every row, and the per-axis overlaps ``[C, P]``.

    A projection is ``u . local + u . offset``: B is projected about its own origin and
    ``ud = u . d`` added, as in the scalar code. Rows within the band of touching on some axis
    are decided exactly; their overlaps are then the exact ones (with ``fallback`` False they count
    as apart: the response re-measuring pairs it has just pushed to touching).
    """
    # Unnormalised outward normal (ey, -ex) of each edge of a CCW outline; exact for dyadic input.
    ux = np.concatenate((edges(avy), edges(bvy)))
    uy = -np.concatenate((edges(avx), edges(bvx)))
    valid = edge_mask(ux, uy)
    amin, amax = _extent(ux, uy, avx, avy)
    bmin, bmax = _extent(ux, uy, bvx, bvy)
    ud = ux * dx + uy * dy
    # How far B must move forward (+u) and backward (-u), times |u|.
    fwd = (amax - bmin) - ud
    bwd = (bmax - amin) + ud
    least = np.minimum(fwd, bwd)
    tol = BAND * (np.abs(ux) + np.abs(uy)) * (size + np.abs(dx) + np.abs(dy))
    # (two outlines of two points, two segments, have no interior to overlap)
    apart = ((least < -tol) & valid).any(axis=0) | ~valid.any(axis=0) | ((acount == 2) & (bcount == 2))
    border = ((least <= tol) & valid).any(axis=0) & ~apart
    hit = ~apart & ~border
    for i in np.flatnonzero(border) if fallback else ():
        pa = list(zip(avx[: acount[i], i].tolist(), avy[: acount[i], i].tolist(), strict=True))
        lb = list(zip(bvx[: bcount[i], i].tolist(), bvy[: bcount[i], i].tolist(), strict=True))
        exact = polygon_polygon_exact(pa, lb, (ax[i], ay[i], bx[i], by[i], int(k[i])))
        if exact is not None:
            found, u = exact
            hit[i] = True
            slots = np.flatnonzero(valid[:, i])
            fwd[slots, i], bwd[slots, i] = np.array([(float_rounded(fw, u), float_rounded(bw, u))
                                                     for fw, bw in found.values()]).T
    return hit, (ux, uy, valid, fwd, bwd)


def polygon_polygon(ax, ay, averts, acount, bx, by, bverts, bcount, size=None, exact: bool = True,
                    points: bool = True) -> ContactArrays:
    """Convex polygons A and B: hitbox origins (ax, ay), (bx, by) ``[P]`` and outlines relative
    to them, ``averts [P, Ka, 2]`` / ``bverts [P, Kb, 2]`` with ``acount`` / ``bcount`` vertices,
    as :func:`~framework.collision.batch.outlines` gives them (gathered per pair).

    ``size`` (optional ``[P]``): the pair's bounding radii summed (the scale of the tie-break and
    contact-point tolerances); by default it is measured from the outlines.

    ``exact=False``: pairs within rounding of touching count as apart (no exact fallback);
    ``points=False``: contact points are not computed. Both are for the response,
    which re-measures pairs it has just pushed apart and needs only normals and depths.
    """
    avx, avy, acount, bvx, bvy, bcount, ax, ay, bx, by, boxes, rest, box_args = _rows(
        ax, ay, averts, acount, bx, by, bverts, bcount
    )
    p = ax.shape[0]
    if size is not None:
        size = columns_of(p, size)[0]
    if not boxes.size:
        return _polygon_polygon(avx, avy, acount, bvx, bvy, bcount, ax, ay, bx, by, size, exact, points)
    out = no_contacts(p)
    res = aabb_aabb(*box_args) if exact and points else aabb_aabb_fast(*box_args, exact=exact, points=points)
    for dst, src in zip(out, res, strict=True):
        dst[boxes] = src
    if rest.size:
        r_avx, r_avy, r_acount, r_bvx, r_bvy, r_bcount = (
            cols(v, rest) if v.ndim == 2 else v[rest] for v in (avx, avy, acount, bvx, bvy, bcount))
        res = _polygon_polygon(
            r_avx, r_avy, r_acount, r_bvx, r_bvy, r_bcount, ax[rest], ay[rest], bx[rest], by[rest],
            None if size is None else size[rest], exact, points,
        )
        for dst, src in zip(out, res, strict=True):
            dst[rest] = src
    return out


def _polygon_polygon(avx, avy, acount, bvx, bvy, bcount, ax, ay, bx, by, size, exact=True,
                     points=True) -> ContactArrays:
    """:func:`polygon_polygon` on slot-major rows, by separating axes."""
    p = ax.shape[0]
    if p == 0:
        return no_contacts(0)
    avx, avy, bvx, bvy, dx, dy, k, sz = _frame(avx, avy, bvx, bvy, ax, ay, bx, by)
    if size is not None:
        sz = np.ldexp(size, -k)
    hit, axes = _sat(avx, avy, acount, bvx, bvy, bcount, ax, ay, bx, by, dx, dy, k, sz, exact)
    h = np.flatnonzero(hit)
    ux, uy, valid, fwd, bwd, avx, avy, bvx, bvy = (cols(a, h) for a in (*axes, avx, avy, bvx, bvy))
    acount, bcount = acount[h], bcount[h]
    dx, dy, sz = dx[h], dy[h], sz[h]
    absent = (~valid).astype(F64)
    ln = norm(ux, uy) + absent  # 1 on padding axes
    # Candidates in the scalar code's order: per axis, forward then backward ([C, 2, H]).
    c, n = ux.shape
    cdepth, cnx, cny = np.empty((c, 2, n)), np.empty((c, 2, n)), np.empty((c, 2, n))
    np.divide(ux, ln, out=cnx[:, 0])
    np.divide(uy, ln, out=cny[:, 0])
    np.negative(cnx[:, 0], out=cnx[:, 1])
    np.negative(cny[:, 0], out=cny[:, 1])
    absent *= BIG
    for j, over in enumerate((fwd, bwd)):
        d = cdepth[:, j]
        np.divide(over, ln, out=d)
        np.maximum(d, TINY, out=d)
        d += absent
    depth, nx, ny = pick(cdepth.reshape(2 * c, n), cnx.reshape(2 * c, n), cny.reshape(2 * c, n), sz)
    # The point is found with B at its offset.
    if points:
        bvx, bvy = bvx + dx, bvy + dy
        px, py = overlap_point(avx, avy, acount, bvx, bvy, bcount, nx, ny, depth, sz)
    else:
        px, py = np.zeros(h.size), np.zeros(h.size)
    return finish(hit, nx, ny, depth, px, py, k[h], ax[h], ay[h])
