"""The one kind-code table and the one shape-pair dispatch table (framework.collision.kinds)."""

from __future__ import annotations

from framework import store
from framework.collision import kinds
from framework.collision.kinds import KIND_NAMES, KINDS, PAIRS, kind_of, pair_code
from framework.shapes import AABB, Circle, Polygon


def test_kind_codes_are_the_stores_and_name_the_shapes_kinds() -> None:
    assert (store.KIND_NONE, store.KIND_AABB, store.KIND_CIRCLE, store.KIND_POLYGON) == (-1, 0, 1, 2)
    assert store.KIND_AABB is kinds.KIND_AABB and store.KIND_POLYGON is kinds.KIND_POLYGON
    for shape in (AABB(1, 2), Circle(1), Polygon([(0, 0), (1, 0), (0, 1)]), Polygon.box(1, 1)):
        assert KIND_NAMES[kind_of(shape)] == shape.kind


def test_pair_table_covers_every_ordered_pair_in_pair_code_order() -> None:
    assert list(PAIRS) == [(a, b) for a in KINDS for b in KINDS]
    for code, ((a, b), rule) in enumerate(PAIRS.items()):
        assert pair_code(a, b) == code
        assert rule.name == f"{KIND_NAMES[a]}-{KIND_NAMES[b]}"
        if kinds.KIND_CAPSULE in (a, b):  # every pair with a capsule: one family, the capsule first
            assert rule.family == kinds.CAPSULES and rule.flip == (b == kinds.KIND_CAPSULE != a)
            continue
        circles = (a, b).count(kinds.KIND_CIRCLE)
        expected = {2: kinds.CIRCLES, 1: kinds.POLYGON_CIRCLE}.get(
            circles, kinds.BOXES if a == b == kinds.KIND_AABB else kinds.POLYGONS)
        assert rule.family == expected
        # Only a circle-first polygon-circle pair is computed with the shapes swapped.
        assert rule.flip == (circles == 1 and a == kinds.KIND_CIRCLE)
