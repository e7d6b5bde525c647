"""A Crazyflie's whole flight as its firmware plans it, from motors start to motors stop.

The fly script (:mod:`.fly_script`) sends, in order: ``takeoff`` to the mission's first
height, ``go_to`` the mission's first point, the uploads (``start_trajectory``, a ``go_to``
to the point where each ended while the next is written), ``land`` to the ground. The
firmware plans each ``takeoff``, ``go_to`` and ``land`` as one ``poly7_nojerk`` polynomial
from rest to rest (crazyflie-firmware ``planner.c``, ``plan_takeoff``, ``plan_go_to_from``,
``plan_land``; ``pptraj.c``, ``piecewise_plan_7th_order_no_jerk``), which
:func:`.commander.rest_to_rest` computes in float32 as the firmware does; the uploads are
flown as :class:`~.memory.FlownUploads` evaluates them. :func:`whole_flight` puts them on
one clock, so that the dense limit check sees every instant the motors run.

Where the drone stands is the user's: the script asks for a pad within
:data:`~.manoeuvres.APPROACH_OFFSET_M` of the point below the mission's first point. The
approach's speed, acceleration and jerk grow with its length (``PEAKS[n] d / T^n``), so
the flight is checked from a pad that far away: every nearer pad flies inside what is
checked.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from skyquill.export.crazyflie.commander import Goal, rest_to_rest
from skyquill.export.crazyflie.manoeuvres import APPROACH_OFFSET_M
from skyquill.export.crazyflie.memory import FlownUploads
from skyquill.trajectory import RestToRestSequence
from skyquill.validation import FloatArray

#: How close the firmware's float32 pieces meet at rest: 1 mm, 1 mm/s, 1 mm/s^2. They end
#: within a float32 rounding of their targets (about 1e-6 m at 10 m; a 1 s take-off's
#: acceleration within 1.5e-4 m/s^2), and what is checked here is what is commanded.
FLOAT32_JOIN_M = 1e-3


def _at_rest(point: FloatArray) -> Goal:
    return Goal(np.asarray(point, dtype=float), np.zeros(3), np.zeros(3))


def whole_flight(
    flight: dict[str, Any], mission: FlownUploads, pad: FloatArray | None = None
) -> RestToRestSequence:
    """The commanded trajectory from take-off to the end of the landing, on one clock.

    Parameters
    ----------
    flight
        The drone's take-off, approach and landing as the fly script's schedule holds them
        (``takeoff``: ``height_m``, ``duration_s``; ``approach``: ``point_m``,
        ``duration_s``; ``landing``: ``height_m``, ``from_m``, ``duration_s``).
    mission
        The uploads as flown on the mission's clock (3 axes), starting and ending at rest.
    pad
        Where the drone stands, (3,) m; default :data:`~.manoeuvres.APPROACH_OFFSET_M`
        east of the point below the first point, on the ground (the farthest pad the
        script allows).

    Returns
    -------
    RestToRestSequence
        Take-off, approach, mission, landing (4 pieces), z-up world frame, m and s.
    """
    first = np.array(flight["approach"]["point_m"], dtype=float)
    last = np.array(flight["landing"]["from_m"], dtype=float)
    if pad is None:
        pad = np.array([first[0] + APPROACH_OFFSET_M, first[1], flight["landing"]["height_m"]])
    pad = np.asarray(pad, dtype=float)
    # plan_takeoff: straight up from the last setpoint (the vehicle on its pad).
    up = np.array([pad[0], pad[1], flight["takeoff"]["height_m"]])
    takeoff = rest_to_rest(float(flight["takeoff"]["duration_s"]), _at_rest(pad), up)
    approach = rest_to_rest(float(flight["approach"]["duration_s"]), _at_rest(up), first)
    down = np.array([last[0], last[1], flight["landing"]["height_m"]])
    landing = rest_to_rest(float(flight["landing"]["duration_s"]), _at_rest(last), down)
    return RestToRestSequence((takeoff, approach, mission, landing), FLOAT32_JOIN_M)
