"""Separation of drones writing at once: proven, not sampled."""

from __future__ import annotations

import math

from skyquill.trajectory import Trajectory
from skyquill.validation import as_float


def check_separation(
    trajectories: list[Trajectory], minimum_m: float = 1.0, rate_hz: float = 50.0
) -> float:
    """Guaranteed smallest pairwise distance over the whole flight, m; raise if below ``minimum_m``.

    Not sampled: :func:`skyquill.show.separation_of` bounds the distance between
    samples, so a show that passes here passes ``skyquill check --min-distance``.
    Drones that finish early hold their last position (landed at home).
    ``rate_hz`` is kept for callers and no longer used.
    """
    from skyquill.show import ShowDrone, require_separation

    minimum = as_float("minimum_m", minimum_m, positive=True)
    as_float("rate_hz", rate_hz, positive=True)
    if len(trajectories) < 2:
        return math.inf  # no pair (what the proof returns, without building its motions)
    drones = [ShowDrone(tr, f"drone {i}") for i, tr in enumerate(trajectories)]
    return require_separation(drones, minimum, "separation").lower_bound_m
