"""Hypothesis strategies for property tests of a game's systems: shapes, transforms and small
scenes (needs ``hypothesis``, which the ``dev`` extra installs).

Sizes and coordinates are dyadic (multiples of 1/8), so expected answers built from them are exact.

::

    @given(small_scenes())
    def test_nothing_sinks(scene):
        run(scene, 120)
        assert_no_overlap(scene, deeper_than=1e-6)
"""

from __future__ import annotations

from typing import Any

try:
    from hypothesis import strategies as st
except ImportError as exc:  # pragma: no cover - the dev extra installs it
    raise ImportError("framework.testing.strategies needs hypothesis: pip install hypothesis "
                      "(or the framework's dev extra)") from exc

from ..components import Hitbox, Transform, Velocity
from ..shapes import AABB, Capsule, Circle, Polygon

__all__ = ["coordinates", "shapes", "small_scenes", "sizes", "transforms"]


def sizes(low: float = 0.25, high: float = 4.0) -> st.SearchStrategy[float]:
    """Dyadic sizes in [low, high] (multiples of 1/8)."""
    return st.integers(max(1, round(low * 8)), round(high * 8)).map(lambda n: n / 8.0)


def coordinates(bound: float = 16.0) -> st.SearchStrategy[float]:
    """Dyadic coordinates in [-bound, bound] (multiples of 1/8)."""
    return st.integers(-round(bound * 8), round(bound * 8)).map(lambda n: n / 8.0)


@st.composite
def shapes(draw: Any, kinds: tuple[str, ...] = ("aabb", "circle", "box", "polygon", "capsule")) -> Any:
    """Any hitbox shape: AABB, circle, turning box, triangle or capsule, of dyadic sizes."""
    kind = draw(st.sampled_from(kinds))
    a, b = draw(sizes()), draw(sizes())
    if kind == "aabb":
        return AABB(a, b)
    if kind == "circle":
        return Circle(a / 2)
    if kind == "box":
        return Polygon.box(a, b)
    if kind == "capsule":
        return Capsule(a / 4, b)
    return Polygon([(-a / 2, -b / 2), (a / 2, -b / 2), (0.0, b / 2)])


@st.composite
def transforms(draw: Any, bound: float = 16.0, turn: bool = True) -> Transform:
    """A Transform at dyadic coordinates, turned by a multiple of 1/8 of a turn (or not)."""
    angle = draw(st.integers(0, 7)) * (3.141592653589793 / 4) if turn else 0.0
    return Transform(draw(coordinates(bound)), draw(coordinates(bound)), angle)


@st.composite
def small_scenes(draw: Any, max_bodies: int = 8, gravity: float = -10.0) -> Any:
    """A scene with a static floor (top at y = 0), walls at x = -10 and 10, and up to
    ``max_bodies`` dynamic bodies of random shapes dropped above it, apart from each other."""
    from ..scene import Scene

    scene = Scene(gravity=(0.0, gravity))
    scene.spawn(Transform(0.0, -0.5), Hitbox(AABB(24.0, 1.0), body="static"))
    for x in (-10.5, 10.5):
        scene.spawn(Transform(x, 10.0), Hitbox(AABB(1.0, 20.0), body="static"))
    n = draw(st.integers(0, max_bodies))
    for i in range(n):
        shape = draw(shapes())
        x = -8.0 + 16.0 * (i + 0.5) / max(n, 1)
        scene.spawn(Transform(x, 3.0 + 5.0 * (i % 2)), Velocity(), Hitbox(shape))
    return scene
