"""Rope bridges: the statics of a chain of planks hung between two anchors.

A bridge is ``n`` planks of one length ``L``, joined end to end by hinges, its two end planks
hinged to the anchors. Under vertical loads it hangs in the shape where every hinge is in
equilibrium. Each plank carries its weight as half at each end hinge (a uniform plank pinned at
both ends: the end forces are a push or pull along the plank plus half its weight, which balance
its weight and its moment), and a load standing on a plank at a fraction ``f`` of its horizontal
run is ``1 - f`` of it at the plank's left hinge and ``f`` at its right one. So the chain is a
funicular polygon of massless links with point loads ``W_j`` at the hinges: the horizontal
tension ``H`` is the same in every plank, and the slope of plank ``i`` is the slope of the one
before plus ``W_i / H``:

    tan(theta_i) = a + b * (W_1 + ... + W_i),   b = 1 / H

with ``a`` the first plank's slope. The two unknowns ``a`` and ``b`` are fixed by the anchors:
``sum L cos(theta_i)`` is the horizontal span and ``sum L sin(theta_i)`` the rise from one anchor
to the other. For a given ``b`` the rise grows with ``a``, and for the ``a`` that gives the rise,
the span shrinks as ``b`` grows (a slacker chain sags more): two nested bisections find them
exactly (to float64), with no starting guess to go wrong.

:func:`hang` gives the hinges' positions; :func:`plank_length` the length of the planks that make
an unloaded bridge sag by a given depth. Nothing here knows about the scene: the game spawns the
planks where :func:`hang` puts them (so a bridge starts at rest) and its tests compare the
simulated bridge with the same statics.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = ["deck_sag", "hang", "plank_length"]

_ROUNDS = 200  # bisection rounds: far more than float64 needs (each halves the bracket)


def _slopes(a: float, b: float, cumulative: Sequence[float]) -> list[float]:
    return [a + b * c for c in cumulative]


def _rise(slopes: Sequence[float], length: float) -> float:
    return sum(length * s / math.sqrt(1.0 + s * s) for s in slopes)


def _run(slopes: Sequence[float], length: float) -> float:
    return sum(length / math.sqrt(1.0 + s * s) for s in slopes)


def _first_slope(b: float, cumulative: Sequence[float], length: float, rise: float) -> float:
    """The first plank's slope ``a`` for which the chain rises by ``rise``: Newton's method on the
    rise, which grows with ``a`` (its derivative, ``sum L / (1 + s^2)^1.5``, is > 0), kept inside
    a bracket that shrinks every round (a step leaving it bisects instead)."""
    lo, hi = -1.0, 1.0
    while _rise(_slopes(lo, b, cumulative), length) > rise:
        lo *= 2.0
    while _rise(_slopes(hi, b, cumulative), length) < rise:
        hi *= 2.0
    a = 0.5 * (lo + hi)
    for _ in range(_ROUNDS):
        slopes = _slopes(a, b, cumulative)
        f = _rise(slopes, length) - rise
        if f == 0.0:
            return a
        if f < 0.0:
            lo = a
        else:
            hi = a
        step = f / sum(length / (1.0 + s * s) ** 1.5 for s in slopes)
        nxt = a - step
        if not lo < nxt < hi:
            nxt = 0.5 * (lo + hi)
        if nxt == a or not lo < nxt < hi:
            break
        a = nxt
    return a


def hang(left: tuple[float, float], right: tuple[float, float], planks: int, length: float,
         loads: Sequence[float]) -> list[tuple[float, float]]:
    """The hinges of a chain of ``planks`` links of ``length`` hung from ``left`` to ``right``
    (``planks + 1`` points, the anchors first and last) in equilibrium under the vertical
    ``loads`` at its inner hinges (``planks - 1`` weights, downward, > 0 in total). ``ValueError``
    if the chain is not longer than the anchors are apart (it cannot hang: it would need an
    infinite pull)."""
    if planks < 2 or len(loads) != planks - 1:
        raise ValueError(f"a chain of {planks} planks has {planks - 1} inner hinges, got {len(loads)} loads")
    span, rise = right[0] - left[0], right[1] - left[1]
    if not span > 0.0:
        raise ValueError(f"the right anchor must be right of the left one, got {left} and {right}")
    if not planks * length > math.hypot(span, rise):
        raise ValueError(f"{planks} planks of {length:g} do not reach from {left} to {right} with any sag")
    if not sum(loads) > 0.0 or min(loads) < 0.0:
        raise ValueError(f"the loads must be >= 0 and not all 0, got {list(loads)}")
    cumulative = [0.0]
    for w in loads:
        cumulative.append(cumulative[-1] + w)
    # b = 1 / H: the span shrinks as b grows; b = 0 is a straight line (too long a span).
    lo, hi = 0.0, 1.0 / sum(loads)
    while _run(_slopes(_first_slope(hi, cumulative, length, rise), hi, cumulative), length) > span:
        hi *= 2.0
    for _ in range(_ROUNDS):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        if _run(_slopes(_first_slope(mid, cumulative, length, rise), mid, cumulative), length) > span:
            lo = mid
        else:
            hi = mid
    b = 0.5 * (lo + hi)
    slopes = _slopes(_first_slope(b, cumulative, length, rise), b, cumulative)
    points = [left]
    x, y = left
    for s in slopes[:-1]:
        c = 1.0 / math.sqrt(1.0 + s * s)
        x, y = x + length * c, y + length * s * c
        points.append((x, y))
    points.append(right)
    return points


def deck_sag(points: Sequence[tuple[float, float]]) -> float:
    """How far the chain's lowest point (a hinge, or a plank's middle where two hinges are
    lowest) hangs below the lower anchor's line: for anchors at one height, below the anchors."""
    top = min(points[0][1], points[-1][1])
    lowest = min(y for _x, y in points)
    return top - lowest


def plank_length(span: float, sag: float, planks: int) -> float:
    """The length of each of ``planks`` equal planks (of equal weight) that, hung from two anchors
    ``span`` apart at one height, hang ``sag`` deep in the middle.

    Equal loads ``w`` at the inner hinges and anchors at one height make the chain symmetric, so
    its slopes are ``s_i = t (i - (n - 1) / 2)`` with the one unknown ``t = w / H``: the span is
    ``L sum cos(theta_i)`` and the sag ``L`` times the sum of ``sin(theta_i)`` over the planks
    down to the middle. Their ratio grows with ``t`` (bisection), and then ``L`` is the span over
    the sum of the cosines. (The shape does not depend on the weight, only on the ratio of loads.)"""
    if not (span > 0.0 and sag > 0.0) or planks < 2:
        raise ValueError(f"need span > 0, sag > 0 and 2 or more planks, got {span}, {sag}, {planks}")
    centre = 0.5 * (planks - 1)

    def shape(t: float) -> tuple[float, float]:
        """(sum of cosines, sag per unit length) of the chain with ``t``."""
        slopes = [t * (i - centre) for i in range(planks)]
        return _run(slopes, 1.0), -sum(s / math.sqrt(1.0 + s * s) for s in slopes[:planks // 2])

    want = sag / span
    lo, hi = 0.0, 1.0
    while shape(hi)[1] / shape(hi)[0] < want:
        hi *= 2.0
    for _ in range(_ROUNDS):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        run, depth = shape(mid)
        if depth / run < want:
            lo = mid
        else:
            hi = mid
    return span / shape(0.5 * (lo + hi))[0]
