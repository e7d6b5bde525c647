"""A Skybrush drone's flight from its pad back to a pad, as Skybrush expects a show to be.

Skybrush flies a whole show from the trajectory alone: the drone stands at the
trajectory's first point (its ``home``) until the show starts, and its firmware takes off
and lands by itself where the trajectory does. libskybrush's statistics decide when
(``src/trajectory/stats.c``, ``sb_trajectory_stats_calculator_run``, used by
``sb_trajectory_propose_takeoff_time_sec`` and ``sb_trajectory_propose_landing_time_sec``):

* take-off: the first instant the trajectory is ``min_ascent`` above its start (2.5 m by
  the calculator's default, ``sb_trajectory_stats_calculator_init``), less the time a
  climb of that height takes at the take-off speed (2 m/s) and acceleration (4 m/s^2):
  the drone takes off then and meets the trajectory there;
* landing: the start of the trajectory's last vertical section (within 5 cm,
  ``verticality_threshold``), or as much of it as ``preferred_descent`` (2.5 m) allows;
  from there the drone lands by itself.

So a show starts on the ground and climbs straight up, and ends coming straight down to the
ground. A plan that starts in the air (a mission hovering at its first point:
:mod:`skyquill.phases`) gets a vertical climb from the ground below that point in front, and
one that ends in the air a vertical descent after it, each time-optimal within the plan's
limits (:func:`skyquill.phases.grounded`). A show planned by ``skyquill show`` already
starts and ends on its pads.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.phases import flight_phases, grounded
from skyquill.trajectory import Trajectory, dense_times

#: libskybrush's default climb above the start that marks the take-off, m.
MIN_ASCENT_M = 2.5


def on_pads(planned: PlannedTrajectory) -> PlannedTrajectory:
    """``planned`` starting and ending on the ground (module docstring); unchanged if it does.

    The pen windows move with the plan's clock; the phases are those of the flight as
    delivered (the climb its take-off, the descent its landing).
    """
    phases = planned.flight()
    traj, shift = grounded(planned.trajectory, phases, planned.limits)
    if traj is planned.trajectory:
        return replace(planned, phases=phases)
    windows = tuple((a + shift, b + shift) for a, b in planned.pen_windows_s)
    delivered = flight_phases(traj, phases.min_altitude_m, phases.ground_m)
    return PlannedTrajectory(traj, windows, planned.limits, planned.pen_rgb, delivered)


def takeoff_report(traj: Trajectory) -> dict[str, Any]:
    """When Skybrush's firmware would see the take-off of ``traj``: the first time it is
    :data:`MIN_ASCENT_M` above its start (``None`` if never), and how high it climbs, m."""
    t = dense_times(np.asarray(traj.breakpoints, dtype=float))
    z = traj.evaluate(t)[:, 2]
    above = np.flatnonzero(z >= z[0] + MIN_ASCENT_M)
    return {
        "start_m": traj.evaluate(np.zeros(1))[0].tolist(),
        "end_m": traj.evaluate(np.array([traj.duration]))[0].tolist(),
        "climb_m": float(z.max() - z[0]),
        "min_ascent_m": MIN_ASCENT_M,
        "min_ascent_reached_s": float(t[above[0]]) if above.size else None,
    }
