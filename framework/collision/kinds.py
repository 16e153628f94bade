"""Shape kinds and shape pairs: the one table of kind codes and the one shape-pair dispatch table.

Every place that dispatches on shapes reads these: the body store's ``kind`` column holds the kind
codes; :func:`~framework.collision.collide`, :func:`~framework.collision.batch.collide_many`, the
narrow phase (:func:`framework.systems.narrow_phase.pair_contacts`) and
:func:`~framework.collision.time_of_impact` look up :data:`PAIRS` to learn how an ordered pair of
kinds is computed.

Families: a pair of kinds is computed by one of four families of functions. Each dispatcher maps a
family to its own function (its column of this table):

===================  ==========================  =============================  ====================
family               ``collide``                 batch kernel                   ``time_of_impact``
===================  ==========================  =============================  ====================
``BOXES``            ``polygon_polygon``         ``aabb_aabb`` (the pipeline:   ``_polygon_polygon``
                     (boxes are polygons)        ``aabb_aabb_fast``)
``CIRCLES``          ``circle_circle``           ``circle_circle``              ``_circle_circle``
``POLYGON_CIRCLE``   ``polygon_circle``          ``polygon_circle``             ``_polygon_circle``
``POLYGONS``         ``polygon_polygon``         ``polygon_polygon``            ``_polygon_polygon``
``CAPSULES``         ``capsule.capsule_pair``    ``capsule.capsule_many``       ``_capsule_pair``
                     (every pair with a capsule)
===================  ==========================  =============================  ====================

A segment is a polygon to these families: an outline of two points (its two edges are its two
sides), against a box, a polygon or a circle; against a capsule a core of two points rounded by 0.
Two segments have no interior to overlap: the polygon functions give them no contact.

``flip``: the family's functions take the polygon first (``CAPSULES``: the capsule first), so a
circle-first pair (a pair with one capsule, second) is computed with the shapes swapped (in the
polygon's, or the capsule's, frame) and its normals turned round to point from A to B. A pair of
two capsules is not flipped: :mod:`~framework.collision.capsule` orders the two itself.
"""

from __future__ import annotations

from typing import NamedTuple

from ..shapes import AABB, Capsule, Circle, Polygon, Segment, Shape

__all__ = [
    "BOXES", "CAPSULES", "CIRCLES", "KINDS", "KIND_AABB", "KIND_CAPSULE", "KIND_CIRCLE", "KIND_NAMES", "KIND_NONE",
    "KIND_POLYGON", "KIND_SEGMENT", "PAIRS", "POLYGONS", "POLYGON_CIRCLE", "PairRule", "kind_of",
    "pair_code",
]

# Kind codes, as the store's int8 ``kind`` column holds them; KIND_NONE: a row without a hitbox.
KIND_NONE, KIND_AABB, KIND_CIRCLE, KIND_POLYGON, KIND_CAPSULE, KIND_SEGMENT = -1, 0, 1, 2, 3, 4
KINDS = (KIND_AABB, KIND_CIRCLE, KIND_POLYGON, KIND_CAPSULE, KIND_SEGMENT)
# The shapes' own names for their kinds (``Shape.kind``), by code.
KIND_NAMES = {KIND_AABB: AABB.kind, KIND_CIRCLE: Circle.kind, KIND_POLYGON: Polygon.kind, KIND_CAPSULE: Capsule.kind,
              KIND_SEGMENT: Segment.kind}


def kind_of(shape: Shape) -> int:
    """The kind code of a shape (any shape that is not an AABB, a circle, a capsule or a segment is
    a polygon)."""
    if isinstance(shape, AABB):
        return KIND_AABB
    if isinstance(shape, Circle):
        return KIND_CIRCLE
    if isinstance(shape, Segment):
        return KIND_SEGMENT
    return KIND_CAPSULE if isinstance(shape, Capsule) else KIND_POLYGON


def pair_code(kind_a, kind_b):
    """One code per ordered pair of kinds, ``0 .. 24`` (ints or integer arrays): the position of
    the pair in :data:`PAIRS`."""
    return kind_a * len(KINDS) + kind_b


# Families of functions that compute a pair (module docstring).
BOXES, CIRCLES, POLYGON_CIRCLE, POLYGONS, CAPSULES = 0, 1, 2, 3, 4


class PairRule(NamedTuple):
    """How an ordered pair of kinds (A, B) is computed."""

    name: str  # "circle-polygon": the narrow phase's pair counters
    family: int  # BOXES, CIRCLES, POLYGON_CIRCLE, POLYGONS or CAPSULES
    flip: bool  # computed as (B, A), normals turned round: the circle of a polygon-circle pair is A,
    # or the capsule of a pair with one capsule is B


# (kind_a, kind_b) -> how the pair is computed, in pair_code order.
PAIRS: dict[tuple[int, int], PairRule] = {
    (KIND_AABB, KIND_AABB): PairRule("aabb-aabb", BOXES, False),
    (KIND_AABB, KIND_CIRCLE): PairRule("aabb-circle", POLYGON_CIRCLE, False),
    (KIND_AABB, KIND_POLYGON): PairRule("aabb-polygon", POLYGONS, False),
    (KIND_AABB, KIND_CAPSULE): PairRule("aabb-capsule", CAPSULES, True),
    (KIND_AABB, KIND_SEGMENT): PairRule("aabb-segment", POLYGONS, False),
    (KIND_CIRCLE, KIND_AABB): PairRule("circle-aabb", POLYGON_CIRCLE, True),
    (KIND_CIRCLE, KIND_CIRCLE): PairRule("circle-circle", CIRCLES, False),
    (KIND_CIRCLE, KIND_POLYGON): PairRule("circle-polygon", POLYGON_CIRCLE, True),
    (KIND_CIRCLE, KIND_CAPSULE): PairRule("circle-capsule", CAPSULES, True),
    (KIND_CIRCLE, KIND_SEGMENT): PairRule("circle-segment", POLYGON_CIRCLE, True),
    (KIND_POLYGON, KIND_AABB): PairRule("polygon-aabb", POLYGONS, False),
    (KIND_POLYGON, KIND_CIRCLE): PairRule("polygon-circle", POLYGON_CIRCLE, False),
    (KIND_POLYGON, KIND_POLYGON): PairRule("polygon-polygon", POLYGONS, False),
    (KIND_POLYGON, KIND_CAPSULE): PairRule("polygon-capsule", CAPSULES, True),
    (KIND_POLYGON, KIND_SEGMENT): PairRule("polygon-segment", POLYGONS, False),
    (KIND_CAPSULE, KIND_AABB): PairRule("capsule-aabb", CAPSULES, False),
    (KIND_CAPSULE, KIND_CIRCLE): PairRule("capsule-circle", CAPSULES, False),
    (KIND_CAPSULE, KIND_POLYGON): PairRule("capsule-polygon", CAPSULES, False),
    (KIND_CAPSULE, KIND_CAPSULE): PairRule("capsule-capsule", CAPSULES, False),
    (KIND_CAPSULE, KIND_SEGMENT): PairRule("capsule-segment", CAPSULES, False),
    (KIND_SEGMENT, KIND_AABB): PairRule("segment-aabb", POLYGONS, False),
    (KIND_SEGMENT, KIND_CIRCLE): PairRule("segment-circle", POLYGON_CIRCLE, False),
    (KIND_SEGMENT, KIND_POLYGON): PairRule("segment-polygon", POLYGONS, False),
    (KIND_SEGMENT, KIND_CAPSULE): PairRule("segment-capsule", CAPSULES, True),
    (KIND_SEGMENT, KIND_SEGMENT): PairRule("segment-segment", POLYGONS, False),
}
