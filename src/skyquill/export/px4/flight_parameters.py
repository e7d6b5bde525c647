"""PX4 parameters that keep its own take-off and landing inside a plan's limits.

``send_mavsdk`` lets PX4 take off and land by itself (:mod:`.setpoints`). PX4 flies both
through its jerk-limited trajectory generator (PX4-Autopilot ``FlightTaskAuto``, with
``VelocitySmoothing``), whose setpoints keep

* the vertical speed within ``MPC_TKO_SPEED`` on take-off and ``MPC_LAND_SPEED`` near the
  ground on landing, ``MPC_Z_V_AUTO_UP`` / ``MPC_Z_V_AUTO_DN`` above it;
* the vertical acceleration within ``MPC_ACC_UP_MAX`` / ``MPC_ACC_DOWN_MAX``;
* the jerk within ``MPC_JERK_AUTO``.

These bound the *setpoints* PX4 commands, as our other checks bound what is commanded (PX4
maintainers: the measured motion may exceed them while the controller tracks,
PX4-Autopilot issue 19101). :func:`px4_flight_parameters` sets each to the smaller of PX4's
default and the plan's own bound for that order in any direction
(:func:`skyquill.phases.leg_limits`), so the take-off and the landing are never faster than
the plan allows nor than PX4 would fly them by default.
"""

from __future__ import annotations

from collections.abc import Sequence

from skyquill.limits import DerivativeLimit
from skyquill.phases import leg_limits

#: PX4's defaults (PX4-Autopilot ``mc_pos_control`` parameters, v1.14): name -> (order, value).
PX4_DEFAULTS: dict[str, tuple[int, float]] = {
    "MPC_TKO_SPEED": (1, 1.5),
    "MPC_LAND_SPEED": (1, 0.7),
    "MPC_Z_V_AUTO_UP": (1, 3.0),
    "MPC_Z_V_AUTO_DN": (1, 1.5),
    "MPC_ACC_UP_MAX": (2, 4.0),
    "MPC_ACC_DOWN_MAX": (2, 3.0),
    "MPC_JERK_AUTO": (3, 4.0),
}


def px4_flight_parameters(limits: Sequence[DerivativeLimit]) -> dict[str, float]:
    """The take-off and landing parameters for a plan with ``limits`` (module docstring).

    Returns
    -------
    dict[str, float]
        PX4 parameter name to value: m/s, m/s^2 and m/s^3.
    """
    bounds = leg_limits(limits)
    return {
        name: min(default, bounds[order - 1]) for name, (order, default) in PX4_DEFAULTS.items()
    }
