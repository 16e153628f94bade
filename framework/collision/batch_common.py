"""Shared pieces of the batch (numpy) collision kernels.

The result record, input coercion, padded-outline helpers and the tie-break rule of
:mod:`framework.collision.tiebreak` on arrays. The kernels themselves live in ``batch_circle``,
``batch_box`` and ``batch_polygon``; :mod:`framework.collision.batch` is the public face.

Padded outlines: a batch of convex counter-clockwise outlines is an array ``[P, K, 2]`` plus a
count per row; slots at and past the count repeat the last real vertex. Edge ``i`` runs from slot
``i`` to slot ``i + 1``, and the last slot's edge closes the outline back to slot 0, so the real
edges are ``i < count - 1`` and ``i == K - 1`` (in the scalar code's order) and the padding edges
between them have length exactly zero.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..validation import InvalidValue
from .tiebreak import DEPTH_TOL, DIR_TOL

__all__ = ["ContactArrays"]

F64 = np.float64


class ContactArrays(NamedTuple):
    """Contacts of P pairs, one row per pair, in the pairs' order.

    ``hit``: the interiors overlap. Where ``hit``: ``(nx, ny)`` the unit normal from A toward B,
    ``depth`` (> 0) the penetration depth and ``(px, py)`` a world point in the overlap region,
    exactly as :func:`framework.collision.collide` gives them. Elsewhere every value is 0.
    """

    hit: np.ndarray
    nx: np.ndarray
    ny: np.ndarray
    depth: np.ndarray
    px: np.ndarray
    py: np.ndarray


def no_contacts(n: int) -> ContactArrays:
    z = np.zeros(n, dtype=F64)
    return ContactArrays(np.zeros(n, dtype=bool), z, z.copy(), z.copy(), z.copy(), z.copy())


def columns(*values: object) -> list[np.ndarray]:
    """The inputs as float64 1-D arrays of one common length (scalars broadcast)."""
    arrs = np.broadcast_arrays(*(np.atleast_1d(np.asarray(v, dtype=F64)) for v in values))
    if arrs[0].ndim != 1:
        raise InvalidValue(f"batch inputs must be 1-D arrays, got shape {arrs[0].shape}")
    return [np.ascontiguousarray(a) for a in arrs]


def columns_of(n: int, *values: object) -> list[np.ndarray]:
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


def scatter(hit: np.ndarray, nx, ny, depth, px, py) -> ContactArrays:
    """Contacts computed for the rows where ``hit`` (compressed) spread back to all rows."""
    n = hit.shape[0]
    outs = []
    for v in (nx, ny, depth, px, py):
        o = np.zeros(n, dtype=F64)
        o[hit] = v
        outs.append(o)
    # "+ 0.0" turns a -0.0 normal component into 0.0, as the scalar code does.
    outs[0] += 0.0
    outs[1] += 0.0
    return ContactArrays(hit, *outs)


# --- padded outlines ---------------------------------------------------------------------------

def outline_rows(verts: object, count: object, name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(vx, vy, count)`` of a padded outline batch; padding is rewritten to repeat the last vertex."""
    v = np.asarray(verts, dtype=F64)
    if v.ndim != 3 or v.shape[2] != 2:
        raise InvalidValue(f"{name} must have shape [P, K, 2], got {v.shape}")
    p, k = v.shape[0], v.shape[1]
    c = np.asarray(count)
    if c.shape != (p,):
        c = np.broadcast_to(c, (p,))
    c = c.astype(np.intp, copy=False)
    if p and (c.min() < 3 or c.max() > k):
        raise InvalidValue(f"{name} counts must lie in [3, {k}], got {c.min()}..{c.max()}")
    if p and c.min() < k:
        idx = np.minimum(np.arange(k), c[:, None] - 1)
        v = np.take_along_axis(v, idx[:, :, None], axis=1)
    return v[:, :, 0], v[:, :, 1], c


def edges(v: np.ndarray) -> np.ndarray:
    """One coordinate of the edge vectors of padded outlines (see the module docstring)."""
    e = np.empty_like(v)
    np.subtract(v[:, 1:], v[:, :-1], out=e[:, :-1])
    np.subtract(v[:, 0], v[:, -1], out=e[:, -1])
    return e


def edge_mask(count: np.ndarray, k: int) -> np.ndarray:
    """``[P, K]``: which edge slots are real edges of the outline."""
    i = np.arange(k)
    return (i < count[:, None] - 1) | (i == k - 1)


def vertex_mask(count: np.ndarray, k: int) -> np.ndarray:
    return np.arange(k) < count[:, None]


def radii(vx: np.ndarray, vy: np.ndarray) -> np.ndarray:
    """Bounding radius of each outline about its own hitbox origin."""
    return np.hypot(vx, vy).max(axis=1)


# --- the tie-break rule on arrays ------------------------------------------------------------

def pick(depth: np.ndarray, nx: np.ndarray, ny: np.ndarray, size: np.ndarray):
    """Per row, the winning ``(depth, nx, ny)`` among candidates ``[P, C]`` (``depth`` +inf for
    absent ones), by the steps of :func:`framework.collision.tiebreak.pick`."""
    p = depth.shape[0]
    best = depth.min(axis=1)
    near = depth <= (best + DEPTH_TOL * size)[:, None]
    # 2. closest to vertical
    any_ = np.abs(ny)
    top = np.where(near, any_, -np.inf).max(axis=1)
    near &= any_ >= (top - DIR_TOL)[:, None]
    # 3. fixed angular order of the directions folded into the upper half-plane
    fold = (ny < -DIR_TOL) | ((any_ <= DIR_TOL) & (nx < 0.0))
    fx = np.where(fold, -nx, nx)
    top = np.where(near, fx, -np.inf).max(axis=1)
    near &= fx >= (top - DIR_TOL)[:, None]
    # 4. max over key (ny > tol, nx > tol, -depth), the first of equals winning
    for key in (ny > DIR_TOL, nx > DIR_TOL):
        keep = near & key
        near = np.where(keep.any(axis=1)[:, None], keep, near)
    low = np.where(near, depth, np.inf).min(axis=1)
    near &= depth == low[:, None]
    i = near.argmax(axis=1)
    rows = np.arange(p)
    return depth[rows, i], nx[rows, i], ny[rows, i]
