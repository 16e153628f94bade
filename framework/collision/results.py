"""Immutable result records of the collision queries."""

from __future__ import annotations

from typing import NamedTuple

__all__ = ["Contact", "Impact", "Manifold", "ManifoldPoint", "RayHit", "Vec2"]


class Vec2(NamedTuple):
    """A 2D vector of float64: compares equal to the plain tuple ``(x, y)``."""

    x: float
    y: float


class Contact(NamedTuple):
    """Overlap of two shapes A and B.

    ``normal``: unit vector from A toward B; ``depth`` (> 0): the penetration depth, so moving B by
    ``normal * depth`` leaves the two touching; ``point``: a world point in the overlap region.
    """

    normal: Vec2
    depth: float
    point: Vec2


class ManifoldPoint(NamedTuple):
    """One point of a contact manifold: a world ``point`` in the overlap region, on the boundary
    of one shape, and how deep it lies inside the other (``depth`` > 0, along the normal)."""

    point: Vec2
    depth: float


class Manifold(NamedTuple):
    """Where two overlapping shapes touch: the ``normal`` from A toward B (as :class:`Contact`'s)
    and one or two ``points``, deepest first (two where a face rests on a face)."""

    normal: Vec2
    points: tuple[ManifoldPoint, ...]


class RayHit(NamedTuple):
    """Where a ray enters a shape: ``distance`` in world units along the ray, the entry ``point``
    and the unit surface ``normal`` there, facing the ray."""

    distance: float
    point: Vec2
    normal: Vec2


class Impact(NamedTuple):
    """First moment two moving shapes' interiors overlap: ``fraction`` of the step in [0, 1] and
    the unit ``normal`` from A toward B at that moment."""

    fraction: float
    normal: Vec2
