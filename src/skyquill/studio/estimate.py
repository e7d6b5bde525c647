"""What a plan would be, before it is planned: its route's length, flight time, uploads, files.

Milliseconds of arithmetic on the route (no solve), so the page can ask on every
Plan press and warn before a person waits minutes for a 27-minute flight. The
numbers are lower bounds or rough sizes, said so where they are shown: the
planner stretches the timing where the limits or the tolerance need it.
"""

from __future__ import annotations

import math

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.mission import WritingOptions, route_length
from skyquill.calligraphy.show import layout
from skyquill.limits import VehicleLimits
from skyquill.strokes import Strokes
from skyquill.studio.models import Estimate, PlanRequest
from skyquill.studio.planner import CSV_RATE_HZ, SEPARATION_M, parts_of
from skyquill.targets import CRAZYFLIE
from skyquill.validation import FloatArray

#: A flight longer than this is worth a second thought, s: paper 000's characters
#: take well under a minute, and a Crazyflie's battery lasts about seven.
WARN_FLIGHT_S = 300.0
#: More Crazyflie uploads than this is a show nobody wants to upload by hand: each
#: one is a hover and a radio write (a 0.5 m character at 1 m/s needs about five).
WARN_UPLOADS = 20
#: Setpoint CSV bytes per row at :data:`~skyquill.studio.planner.CSV_RATE_HZ`
#: (14 columns of about 10 characters; measured 130-150 on the bundled examples).
CSV_ROW_BYTES = 150


def estimate(request: PlanRequest) -> Estimate:
    """The longest drone's route, flight time, Crazyflie uploads and the CSVs' size.

    The flight time is the route's length at the speed limit plus, per stroke,
    a stop and a start at the acceleration limit (``2 vmax / amax``): a lower
    bound of what the planner returns. Uploads assume the mission spline's knot
    span every ``WritingOptions.knot_interval`` seconds, one polynomial piece each.

    Raises
    ------
    InputError
        The request cannot be turned into strokes (as :func:`parts_of`).
    """
    parts = parts_of(request)
    options = WritingOptions(
        size_m=request.size_m, limits=VehicleLimits(request.vmax, request.amax, request.jmax)
    )
    places = layout(len(parts), request.size_m, SEPARATION_M, kind=request.board)
    lengths, times = [], []
    for part, (board, home) in zip(parts, places, strict=True):
        length = _length(part, options, board, home)
        lengths.append(length)
        stops = part.n_strokes * 2.0 * request.vmax / request.amax
        times.append(length / request.vmax + stops)
    flight = max(times)
    pieces = math.ceil(flight / options.knot_interval)
    uploads = math.ceil(pieces / CRAZYFLIE.max_pieces)
    rows = sum(math.ceil(t * CSV_RATE_HZ) + 1 for t in times)
    return Estimate(
        path_length_m=round(max(lengths), 3),
        flight_time_s=round(flight, 1),
        crazyflie_uploads=uploads,
        setpoint_bytes=rows * CSV_ROW_BYTES,
        warnings=_warnings(flight, uploads, max(lengths), request.vmax),
    )


def _length(part: Strokes, options: WritingOptions, board: Board, home: FloatArray) -> float:
    """One drone's route length, m (:func:`route_length`; ``home`` (3,) is the vehicle's)."""
    scaled = part.scaled(options.size_m)
    strokes_world = tuple(board.to_world(path) for path in scaled.paths)
    tip_home = home - options.brush.length_m * board.normal  # the route is the tip's
    return route_length(strokes_world, board, tip_home)


def _warnings(flight_s: float, uploads: int, length_m: float, vmax: float) -> list[str]:
    """The thresholds crossed, each with what makes the plan long."""
    out = []
    if flight_s > WARN_FLIGHT_S:
        out.append(
            f"a flight of at least {flight_s / 60:.1f} min ({length_m:.1f} m of route at "
            f"{vmax:g} m/s); more than {WARN_FLIGHT_S / 60:g} min is longer than a battery "
            "and slow to plan: raise the speed or draw less"
        )
    if uploads > WARN_UPLOADS:
        out.append(
            f"about {uploads:,} Crazyflie uploads (more than {WARN_UPLOADS}): each is a hover "
            "and a radio write"
        )
    return out
