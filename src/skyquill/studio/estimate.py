"""What a plan would be, before it is planned: its route's length, flight time, uploads, files.

Milliseconds of arithmetic on the route (no solve), so the page can ask on every
Plan press and warn before a person waits minutes for a 27-minute flight. The
flight time is a first timing of the route
(:func:`~skyquill.calligraphy.mission.initial_flight_time`: the route at the
speed limit, slowing to a stop at corners, the lifts within the jerk limit);
``bench/studio_estimate.py`` measures it against the planned flights. Warnings
are about the chosen vehicle only.

At loose limits the writing is not slowed by the vehicle but by fidelity: the
planner writes at the fastest pace that stays within the tolerance
(``docs/calligraphy-timing.md``), whatever the vehicle allows beyond it. The
estimate therefore times the route with the limits capped at
:data:`TYPICAL_FAITHFUL_PACE`, the pace the bundled set writes at.
"""

from __future__ import annotations

import math

import numpy as np

from skyquill.calligraphy.mission import WritingOptions, initial_flight_time, route_length
from skyquill.calligraphy.show import layout
from skyquill.calligraphy.timing import TimingBounds
from skyquill.limits import VehicleLimits
from skyquill.show.limits import ShowLimits
from skyquill.studio.models import Estimate, PlanRequest
from skyquill.studio.planner import CSV_RATE_HZ, SEPARATION_M, parts_of

#: The pace (speed m/s; acceleration and jerk of the pace's shape, 2 p^2 and 10 p^3) the
#: studio's requests are written at when the vehicle allows more, measured with
#: ``bench/studio_estimate.py`` (12 bundled characters, a word, 4 drawings at 1x, 5x and
#: 20x the default limits): capping the estimate's limits at 1.25 / 1.5 / 1.75 / 2.0 /
#: 2.5 put planned / estimated in 0.73-1.00 / 0.86-1.02 / 0.99-1.18 / 1.00-1.34 /
#: 1.00-1.64; 1.75 is the lowest that does not promise a faster flight than planned.
TYPICAL_FAITHFUL_PACE = 1.75
#: A flight longer than this is worth a second thought, s: paper 000's characters
#: take well under a minute, and a Crazyflie's battery lasts about seven.
WARN_FLIGHT_S = 300.0
#: More Crazyflie uploads than this is a flight nobody wants to upload by hand: each
#: one is a hover and a radio write.
WARN_UPLOADS = 20
#: Setpoint CSV bytes per row at :data:`~skyquill.studio.planner.CSV_RATE_HZ`
#: (14 columns of about 10 characters; measured 130-150 on the bundled examples).
CSV_ROW_BYTES = 150
#: What Skybrush Studio's safety check allows when a show does not say
#: (:class:`~skyquill.show.limits.ShowLimits`' defaults).
SKYBRUSH = ShowLimits()


def estimate(request: PlanRequest) -> Estimate:
    """The longest drone's route and flight time, uploads (Crazyflie) and the CSVs' size.

    Raises
    ------
    InputError
        The request cannot be turned into strokes (as :func:`parts_of`).
    """
    parts = parts_of(request)
    paced = TimingBounds(request.vmax, request.amax, request.jmax).at_pace(TYPICAL_FAITHFUL_PACE)
    limits = VehicleLimits(paced.vmax, paced.amax, paced.jmax)
    options = WritingOptions(size_m=request.size_m, limits=limits)
    places = layout(len(parts), request.size_m, SEPARATION_M, kind=request.board)
    lengths, times = [], []
    for part, (board, place) in zip(parts, places, strict=True):
        home = np.array(place, dtype=float)  # raised to the minimum altitude, as planned
        home[2] = max(home[2], request.min_altitude_m)
        tip_home = home - options.brush.length_m * board.normal  # the route is the tip's
        scaled = part.scaled(options.size_m)
        lengths.append(route_length(tuple(map(board.to_world, scaled.paths)), board, tip_home))
        times.append(initial_flight_time(part, board, options, home))
    flight = max(times)
    uploads = None
    if request.target == "crazyflie":
        # The planner fits the Crazyflie's memory with one upload when it can, else
        # cuts where the brush is lifted: at most one upload per stroke, each after a hover.
        uploads = max(p.n_strokes for p in parts)
    rows = sum(math.ceil(t * CSV_RATE_HZ) + 1 for t in times)
    return Estimate(
        target=request.target,
        path_length_m=round(max(lengths), 3),
        flight_time_s=round(flight, 1),
        crazyflie_uploads=uploads,
        setpoint_bytes=rows * CSV_ROW_BYTES,
        warnings=_warnings(request, flight, uploads, max(lengths)),
    )


def _warnings(
    request: PlanRequest, flight_s: float, uploads: int | None, length_m: float
) -> list[str]:
    """The thresholds crossed for the chosen vehicle, each with what to change in the page."""
    out = []
    if flight_s > WARN_FLIGHT_S:
        out.append(
            f"a flight of about {flight_s / 60:.1f} min ({length_m:.1f} m of route at "
            f"{request.vmax:g} m/s); more than {WARN_FLIGHT_S / 60:g} min is longer than a "
            "battery lasts and slow to plan: raise the Speed or draw less"
        )
    if uploads is not None and uploads > WARN_UPLOADS:
        out.append(
            f"up to {uploads:,} Crazyflie uploads (one per stroke when the flight does not fit "
            f"one), more than {WARN_UPLOADS}: the drone hovers while each is sent; draw fewer "
            "strokes"
        )
    if request.target == "skybrush":
        out.extend(_skybrush_warnings(request))
    return out


def _skybrush_warnings(request: PlanRequest) -> list[str]:
    """Limits above what Skybrush Studio's safety check allows a show by default."""
    vertical = min(SKYBRUSH.max_speed_up or math.inf, SKYBRUSH.max_speed_down or math.inf)
    over = []
    if request.vmax > vertical:
        over.append(
            f"Speed {request.vmax:g} m/s (it takes off and lands at up to {vertical:g} m/s, "
            f"and flies at up to {SKYBRUSH.max_speed_xy:g} m/s)"
        )
    if SKYBRUSH.max_acceleration is not None and request.amax > SKYBRUSH.max_acceleration:
        over.append(f"Acceleration {request.amax:g} m/s² (it allows {SKYBRUSH.max_acceleration:g})")
    if not over:
        return []
    return [
        "Skybrush Studio's safety check may refuse the show: "
        + " and ".join(over)
        + f"; lower them to plan a show it accepts (e.g. Speed {vertical:g})"
    ]
