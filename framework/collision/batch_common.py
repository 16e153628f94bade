"""Shared pieces of the batch (numpy) collision kernels.

The result record, input coercion, frames, padded-outline helpers and the tie-break rule of
:mod:`framework.collision.tiebreak` on arrays. The kernels live in ``batch_circle``, ``batch_box``
and ``batch_polygon``, the contact point of polygons in ``batch_point``, the exact fallback near
touching in :mod:`~framework.collision.exact` (shared with the scalar code);
:mod:`framework.collision.batch` is the public face.

Padded outlines: a batch of convex counter-clockwise outlines is an array ``[P, K, 2]`` plus a
count per row; slots at and past the count repeat the last real vertex. Edge ``i`` runs from slot
``i`` to slot ``i + 1``, and the last slot's edge closes the outline back to slot 0, so the real
edges are ``i < count - 1`` and ``i == K - 1`` (in the scalar code's order) and the padding edges
between them have length exactly zero: every test that skips zero edges skips them.

Frames: like the scalar code, every kernel works in a local frame (A's hitbox origin; the
polygon's for polygon / circle pairs) scaled by a power of two per row (:func:`frame`), with each
shape in its own local coordinates and B's offset kept apart: a projection is
``u . local + u . offset``.
"""

from __future__ import annotations

from typing import NamedTuple, TypeVar

import numpy as np
from numpy.typing import NDArray

from ..validation import InvalidValue
from .exact import TINY
from .tiebreak import DEPTH_TOL, DIR_TOL

__all__ = ["ContactArrays", "sum_leading"]

F64 = np.float64
_T = TypeVar("_T", bound=np.generic)


def sum_leading(values: NDArray[_T]) -> NDArray[_T]:
    """The sum over every axis but the last (the pairs, ``[..., P]``), in one fixed order (first
    index first), so a pair's sum does not depend on how many pairs share the batch. (numpy sums
    a 1-D run pairwise: a batch of one pair would add its terms in another order than a batch of
    several, and differ in the last bit.)"""
    if values.shape[-1] == 0 or values.size == 0:
        return np.zeros(values.shape[-1], dtype=values.dtype)
    flat = values.reshape(-1, values.shape[-1])
    if flat.shape[1] == 1:
        return np.cumsum(flat[:, 0])[-1:] if flat.shape[0] else np.zeros(1, dtype=flat.dtype)
    return np.add.reduce(flat, axis=0)


class ContactArrays(NamedTuple):
    """Contacts of P pairs, one row per pair, in the pairs' order.

    ``hit``: the interiors overlap. Where ``hit``: ``(nx, ny)`` the unit normal from A toward B,
    ``depth`` (> 0) the penetration depth and ``(px, py)`` a world point in the overlap region,
    exactly as :func:`framework.collision.collide` gives them. Elsewhere every value is 0.
    """

    hit: NDArray[np.bool_]
    nx: NDArray[np.float64]
    ny: NDArray[np.float64]
    depth: NDArray[np.float64]
    px: NDArray[np.float64]
    py: NDArray[np.float64]


def no_contacts(n: int) -> ContactArrays:
    z = np.zeros(n, dtype=F64)
    return ContactArrays(np.zeros(n, dtype=bool), z, z.copy(), z.copy(), z.copy(), z.copy())


def columns(*values: object) -> list[NDArray[np.float64]]:
    """The inputs as float64 1-D arrays of one common length (scalars broadcast)."""
    n = -1
    for v in values:  # (the pipeline's calls: contiguous float64 columns of one length, taken as they are)
        if type(v) is not np.ndarray or v.dtype != F64 or v.ndim != 1 or not v.flags.c_contiguous or (
                n >= 0 and v.shape[0] != n):
            break
        n = v.shape[0]
    else:
        return list(values)  # type: ignore[arg-type]
    arrs = np.broadcast_arrays(*(np.atleast_1d(np.asarray(v, dtype=F64)) for v in values))
    if arrs[0].ndim != 1:
        raise InvalidValue(f"batch inputs must be 1-D arrays, got shape {arrs[0].shape}")
    return [np.ascontiguousarray(a) for a in arrs]


def columns_of(n: int, *values: object) -> list[NDArray[np.float64]]:
    """The inputs as float64 arrays of shape ``(n,)`` (scalars broadcast)."""
    out = []
    for v in values:
        a = np.asarray(v, dtype=F64)
        if a.shape != (n,):
            try:
                a = np.broadcast_to(a, (n,))
            except ValueError:
                raise InvalidValue(f"batch input of shape {a.shape} does not match {n} pairs") from None
        out.append(np.ascontiguousarray(a))
    return out


def frame(
    ox: NDArray[np.float64], oy: NDArray[np.float64], qx: NDArray[np.float64], qy: NDArray[np.float64],
    reach: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int32]]:
    """The scaled local frame of the scalar code: ``(dx, dy, k)`` with the offset of q from o
    scaled by ``2**-k`` so that it and ``reach`` (the larger bounding radius) are about 1.

    Scaling by a power of two is exact, so ordinary scenes get the unscaled answers bit for bit,
    while radii of 1e-200 or 1e300 neither underflow nor overflow.
    """
    # Halves first: 0.5 * q - 0.5 * o never overflows, and halving is exact above the subnormals.
    hx, hy = 0.5 * qx - 0.5 * ox, 0.5 * qy - 0.5 * oy
    k = np.frexp(np.maximum(np.maximum(np.abs(hx), np.abs(hy)), 0.5 * reach))[1]
    return np.ldexp(hx, 1 - k), np.ldexp(hy, 1 - k), k


def finish(
    hit: NDArray[np.bool_], nx: NDArray[np.float64], ny: NDArray[np.float64], depth: NDArray[np.float64],
    px: NDArray[np.float64], py: NDArray[np.float64], k: NDArray[np.int32], ox: NDArray[np.float64],
    oy: NDArray[np.float64],
) -> ContactArrays:
    """Contacts of the ``hit`` rows (compressed, in the scaled local frame of origin (ox, oy),
    all ``[H]``) unscaled, moved to the world and spread back to all rows (zeros elsewhere)."""
    n = hit.shape[0]
    # An overlap below the smallest float (shapes 1e300 times smaller than the scene) is still an
    # overlap: depth > 0.
    depth = np.maximum(np.ldexp(depth, k), TINY)
    px = ox + np.ldexp(px, k)
    py = oy + np.ldexp(py, k)
    if not (np.isfinite(depth).all() and np.isfinite(px).all() and np.isfinite(py).all()):
        raise InvalidValue("batch collide: a contact is beyond float64's range")
    outs = []
    for v in (nx, ny, depth, px, py):
        o = np.zeros(n, dtype=F64)
        o[hit] = v
        outs.append(o)
    # "+ 0.0" turns a -0.0 normal component into 0.0, as the scalar code does.
    outs[0] += 0.0
    outs[1] += 0.0
    return ContactArrays(hit, *outs)


# --- padded outlines, vertex-major -------------------------------------------------------------
# Inside the kernels a batch of outlines is ``vx, vy [K, P]`` (slot-major): every reduction over
# the few slots is then a reduction over axis 0, which numpy vectorises along the P pairs (a
# reduction over a short last axis costs some 30 times more).

def outline_rows(
    verts: object, count: object, name: str,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.intp]]:
    """``(vx [K, P], vy [K, P], count [P])`` of an outline batch ``[P, K, 2]`` (an outline of two
    points is a segment); the padding is rewritten to repeat each outline's last vertex, whatever
    the caller put there."""
    v = np.asarray(verts, dtype=F64)
    if v.ndim != 3 or v.shape[2] != 2:
        raise InvalidValue(f"{name} must have shape [P, K, 2], got {v.shape}")
    p, k = v.shape[0], v.shape[1]
    c = np.asarray(count)
    if c.shape != (p,):
        c = np.broadcast_to(c, (p,))
    c = c.astype(np.intp, copy=False)
    if p and (c.min() < 2 or c.max() > k):
        raise InvalidValue(f"{name} counts must lie in [2, {k}], got {c.min()}..{c.max()}")
    vx = np.ascontiguousarray(v[:, :, 0].T)
    vy = np.ascontiguousarray(v[:, :, 1].T)
    if p and c.min() < k:
        idx = np.minimum(np.arange(k)[:, None], c - 1)
        col = np.arange(p)  # (plain fancy indexing: take_along_axis costs microseconds per call)
        vx = vx[idx, col]
        vy = vy[idx, col]
    return vx, vy, c


def edges(v: NDArray[np.float64]) -> NDArray[np.float64]:
    """One coordinate of the edge vectors of padded outlines ``[K, P]`` (module docstring)."""
    e = np.empty_like(v)
    np.subtract(v[1:], v[:-1], out=e[:-1])
    np.subtract(v[0], v[-1], out=e[-1])
    return e


def edge_mask(ex: NDArray[np.float64], ey: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The edges that give an axis; padding edges (and, as in the scalar code, an edge scaled
    away to nothing) have length exactly zero."""
    return (ex != 0.0) | (ey != 0.0)


def vertex_mask(count: NDArray[np.intp], k: int) -> NDArray[np.bool_]:
    """``[K, P]``: the real (not padding) vertex slots."""
    return np.arange(k)[:, None] < count


def norm(x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float64]:
    """``|(x, y)|`` for values of order 1 (a scaled frame): the root of the squares, which is
    several times faster than ``np.hypot``, with ``hypot`` where the squares would underflow."""
    n = np.sqrt(x * x + y * y)
    tiny = n < 1e-150
    if tiny.any():
        n[tiny] = np.hypot(x[tiny], y[tiny])
    return n


def extent(vx: NDArray[np.float64], vy: NDArray[np.float64]) -> NDArray[np.float64]:
    """Per outline ``[K, P]``, a length within a factor 2 of its bounding radius (for scaling)."""
    return np.maximum(np.abs(vx).max(axis=0), np.abs(vy).max(axis=0))


# In the scaled frames every value is of order 1, so ``BIG`` can stand for "absent" in a min.
# Selections are written as arithmetic (``x * m + (1 - m) * BIG``, exact where ``m`` is 1) rather
# than ``np.where``, which is several times slower on unpredictable masks.
BIG = 1e300


def first(mask: NDArray[np.bool_]) -> NDArray[np.intp]:
    """Per column of ``mask [C, P]``, the first row that is True (0 where none is): ``argmax``
    returns the first of equal maxima (ten times faster than a loop over the rows on the few dozen
    pairs a re-measure holds)."""
    return np.argmax(mask, axis=0)


def first_min(v: NDArray[np.float64]) -> NDArray[np.intp]:
    """Per column of ``v [C, P]``, the first row holding the column's minimum (as ``argmin``)."""
    return first(v == v.min(axis=0))


def cols(v: NDArray[_T], rows: NDArray[np.intp]) -> NDArray[_T]:
    """The pairs ``rows`` (integer indices) of a slot-major array ``[C, P]``, C-contiguous (plain
    ``v[:, mask]`` can come out column-major, which makes every later axis-0 reduction slow)."""
    return np.take(v, rows, axis=1)


def take(v: NDArray[_T], i: NDArray[np.intp]) -> NDArray[_T]:
    """``v[i[p], p]`` for every column p."""
    return v[i, np.arange(v.shape[1])]


# --- the tie-break rule on arrays ------------------------------------------------------------

def pick(
    depth: NDArray[np.float64], nx: NDArray[np.float64], ny: NDArray[np.float64], size: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Per column, the winning ``(depth, nx, ny)`` among candidates ``[C, P]`` (``depth`` >= BIG
    for absent ones), by the steps of :func:`framework.collision.tiebreak.pick`."""
    best = depth.min(axis=0)
    near = depth <= best + DEPTH_TOL * size
    # 2. closest to vertical (|ny| >= 0, so zeroing the others leaves the max over the near ones)
    any_ = np.abs(ny)
    top = (any_ * near.astype(F64)).max(axis=0)
    near &= any_ >= top - DIR_TOL
    # 3. fixed angular order of the directions folded into the upper half-plane (x + 0 is x
    # exactly; a candidate that is not near scores below -2)
    fold = (ny < -DIR_TOL) | ((any_ <= DIR_TOL) & (nx < 0.0))
    fx = nx * (1.0 - 2.0 * fold.astype(F64))
    top = (fx + (near.astype(F64) - 1.0) * 4.0).max(axis=0)
    near &= fx >= top - DIR_TOL
    # 4. Only a direction and (near-)copies of it or its negation remain: the direction of the max
    # over key (ny > tol, nx > tol, -depth), the first of equals winning, with the shortest depth
    # of them all.
    shortest = (depth + (1.0 - near.astype(F64)) * BIG).min(axis=0)
    for key in (ny > DIR_TOL, nx > DIR_TOL):
        keep = near & key
        near = keep | (near & ~keep.any(axis=0))
    low = (depth + (1.0 - near.astype(F64)) * BIG).min(axis=0)
    i = first(near & (depth == low))
    return shortest, take(nx, i), take(ny, i)
