"""How long a Crazyflie's own take-off, approach and landing take to stay inside the plan's limits.

The firmware flies ``takeoff``, ``go_to`` and ``land`` as one 7th-order polynomial from rest
to rest (``pptraj.c``, ``poly7_nojerk``; :mod:`.commander`): over a distance ``d`` in ``T``
seconds it is ``d x(t / T)`` with ``x(s) = 35 s^4 - 84 s^5 + 70 s^6 - 20 s^7``, whose
speed, acceleration and jerk peak at ``PEAKS[n] d / T^n``. The shortest ``T`` that keeps
every limit of the plan (the smallest bound each order states in any direction,
:func:`skyquill.phases.leg_limits`) is the manoeuvre's duration, never below
:data:`MIN_MANOEUVRE_S`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from skyquill.limits import DerivativeLimit
from skyquill.phases import leg_limits

#: ``x(s)`` of the firmware's rest-to-rest polynomial, lowest power first.
UNIT_PROFILE = np.polynomial.Polynomial([0, 0, 0, 0, 35, -84, 70, -20])
#: ``max |x^(n)(s)|`` over ``[0, 1]`` for n = 1, 2, 3 (2.1875, 7.513, 52.5).
PEAKS = {
    n: float(np.abs(UNIT_PROFILE.deriv(n)(np.linspace(0.0, 1.0, 100_001))).max()) for n in (1, 2, 3)
}
#: Shortest take-off, approach or landing, s (the firmware's own examples use 2 to 3 s).
MIN_MANOEUVRE_S = 2.0
#: How far from the point below its first mission point a drone may stand before take-off
#: (the approach after the take-off covers it), m.
APPROACH_OFFSET_M = 0.5


def manoeuvre_s(distance_m: float, limits: Sequence[DerivativeLimit]) -> float:
    """Duration of a firmware manoeuvre over ``distance_m`` within ``limits``, s."""
    bounds = leg_limits(limits)
    d = abs(float(distance_m))
    needed = [(PEAKS[n] * d / bounds[n - 1]) ** (1.0 / n) for n in (1, 2, 3)]
    return float(max(MIN_MANOEUVRE_S, *needed))
