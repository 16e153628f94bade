"""The fixed rule that picks one push-out direction among equally short ones.

Candidates are ``(depth, nx, ny)`` with unit normals from A toward B. The rule never depends on
argument order: swapping A and B negates every candidate and the rule picks the negated winner,
except where the direction is truly undefined (a candidate and its negation tie, as for identical
boxes at one place), where the upward (then rightward) one wins whichever shape comes first.

1. Keep the candidates within ``tol`` of the shortest depth (rounding must not decide).
2. Prefer the direction closest to vertical: the largest ``|ny|`` (a box landing on a corner is
   pushed up, not sideways).
3. Then the fixed angular order: fold each direction into the upper half-plane (negate it if
   ``ny < 0``, or ``ny == 0`` and ``nx < 0``) and prefer the largest folded ``nx``. Folding commutes
   with negation, so this step is symmetric too.
4. A direction and its negation still tie (the direction is undefined): prefer ``ny > 0``, then
   ``nx > 0``, and return the shortest of the tied depths, so that both argument orders give the
   same depth (the winner's own depth exceeds it by less than the tolerance of step 1).

The batch kernels implement the same steps on arrays; keep the two in step.
"""

from __future__ import annotations

__all__ = ["DEPTH_TOL", "DIR_TOL", "pick"]

# Relative depth tolerance (times the pair's size) and absolute tolerance on unit-vector
# components under which two candidates count as equal.
DEPTH_TOL = 1e-12
DIR_TOL = 1e-12


def _folded_x(nx: float, ny: float) -> float:
    if ny < -DIR_TOL or (abs(ny) <= DIR_TOL and nx < 0.0):
        return -nx
    return nx


def pick(cands: list[tuple[float, float, float]], size: float) -> tuple[float, float, float]:
    """The winning ``(depth, nx, ny)`` among ``cands``; ``size`` scales the depth tolerance."""
    if len(cands) == 1:
        return cands[0]
    best_depth = min(c[0] for c in cands)
    tol = DEPTH_TOL * size
    near = [c for c in cands if c[0] <= best_depth + tol]
    if len(near) == 1:
        return near[0]
    top = max(abs(c[2]) for c in near)
    near = [c for c in near if abs(c[2]) >= top - DIR_TOL]
    if len(near) == 1:
        return near[0]
    fx = max(_folded_x(c[1], c[2]) for c in near)
    near = [c for c in near if _folded_x(c[1], c[2]) >= fx - DIR_TOL]
    if len(near) == 1:
        return near[0]
    # Only a direction and (near-)copies of it or its negation remain.
    _, nx, ny = max(near, key=lambda c: (c[2] > DIR_TOL, c[1] > DIR_TOL, -c[0]))
    return min(c[0] for c in near), nx, ny
