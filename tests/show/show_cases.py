"""Small shows for the show checks: straight lines, eased moves, plans written by skyquill."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from skyquill.io.plan_dir import write_plan
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.trajectory import PiecewisePolynomial, SplineTrajectory, Trajectory


def line(start: Sequence[float], velocity: Sequence[float], duration: float) -> PiecewisePolynomial:
    """``p(t) = start + velocity t`` on ``[0, duration]``."""
    coeffs = np.array([[start, velocity]], dtype=float)
    return PiecewisePolynomial(np.array([0.0, duration]), coeffs)


def move(
    a: Sequence[float], b: Sequence[float], duration: float, spans: int = 10
) -> SplineTrajectory:
    """A rest-to-rest degree-7 B-spline from ``a`` to ``b``."""
    s = np.linspace(0.0, 1.0, spans + 7)
    ease = s**3 * (10 - 15 * s + 6 * s**2)
    ease[:4], ease[-4:] = 0.0, 1.0
    return SplineTrajectory(np.asarray(a, float) + ease[:, None] * np.subtract(b, a), 7, duration)


def planted() -> tuple[PiecewisePolynomial, PiecewisePolynomial, float]:
    """Two drones closer than 3 m for exactly 50 ms, between 5 Hz samples; and when it starts.

    One hovers at the origin; the other passes at 20 m/s on a line whose chord inside
    the 3 m sphere is 1 m long (50 ms), centred on t = 5.1 s (5 Hz samples at 5.0 and 5.2);
    the closest it comes is ``sqrt(3^2 - 0.5^2)`` ~ 2.958 m.
    """
    speed, centre = 20.0, 5.1
    half_chord = speed * 0.025
    offset = float(np.sqrt(9.0 - half_chord**2))
    hover = line([0.0, 0.0, 5.0], [0.0, 0.0, 0.0], 10.0)
    flyer = line([-speed * centre, offset, 5.0], [speed, 0.0, 0.0], 10.0)
    return hover, flyer, centre - half_chord / speed


def plan(folder: Path, trajectories: Sequence[Trajectory]) -> Path:
    """A plan directory as the planning commands write it (no flight phases: some of these
    drones are already moving at their start, which no vehicle could take off into)."""
    planned = [PlannedTrajectory(t) for t in trajectories]
    write_plan(folder, planned, rate=50.0, guaranteed=True, summary={}, min_altitude_m=None)
    return folder


def row(y: float) -> list[SplineTrajectory]:
    """Three drones 4 m apart in y moving 4 m along x (a safe show at 3 m)."""
    return [move([0.0, y + 4.0 * k, 1.0], [4.0, y + 4.0 * k, 2.0], 6.0 + k) for k in range(3)]
