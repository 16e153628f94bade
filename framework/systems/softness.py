"""Box2D v3's soft constraint coefficients (``b2MakeSoft``), shared by contacts and joints.

A soft constraint is a damped spring of ``hertz`` and damping ratio ``zeta`` solved implicitly
over a sub-step ``h``: the impulse is ``-mass_scale * m * (Cdot + bias_rate * C) - impulse_scale *
accumulated`` (Erin Catto, "Solver2D", 2024). ``hertz == 0`` is rigid: no bias, the full mass.
"""

from __future__ import annotations

import math

from ..compiled import leaf

__all__ = ["soft"]


@leaf
def soft(hertz, zeta, h):
    """(bias rate, mass scale, impulse scale) of a soft constraint."""
    if hertz == 0.0:
        return 0.0, 1.0, 0.0
    omega = 2.0 * math.pi * hertz
    a1 = 2.0 * zeta + h * omega
    a2 = h * omega * a1
    a3 = 1.0 / (1.0 + a2)
    return omega / a1, a2 * a3, a3
