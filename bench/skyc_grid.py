"""Which time-optimal moves far from the origin a ``.skyc`` can hold (issue 27, part 4).

Skybrush stores a drone's positions in units of ``scale`` mm, chosen by the farthest
coordinate it reaches (:func:`skyquill.export.skybrush.playback.scaling_factor`). For each
unit, random time-optimal moves (a move out and back with a hold, Ruckig's cubic phases) are
planned where that unit applies, at the jerk
:func:`~skyquill.export.skybrush.keyframe_times.playable_jerk` allows there, and exported
the way ``skyquill show`` exports them (:func:`~skyquill.export.skybrush.refit.played_keyframes`:
keyframes on the grid, played with Skybrush's arithmetic, checked against the limits, at
most 2 cm from the plan). Peer in the same run: the same moves at the limits' own jerk.

Written to ``bench/results/skyc_grid.json``. Run: ``.venv/bin/python bench/skyc_grid.py``
(about 2 minutes on a free core); ``--units 14 16`` for fewer units, ``--seeds 0 1 2``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits

from common import jsonable, machine_info
from skyquill.errors import InfeasibleError
from skyquill.export.skybrush.keyframe_times import playable_jerk
from skyquill.export.skybrush.refit import played_keyframes
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.limits import VehicleLimits
from skyquill.optimize.legs import LegLimits, leg_pieces
from skyquill.trajectory import PiecewisePolynomial, RestToRestSequence

RESULTS = Path(__file__).resolve().parent / "results"
#: ``(vmax, amax, jmax)`` tried.
LIMITS = ((4.0, 2.0, 10.0), (3.0, 2.0, 10.0), (8.0, 4.0, 40.0), (2.0, 1.0, 5.0))
MOVES_PER_CASE = 4
#: Moves are planned this fraction inside the limits (as ``skyquill show`` plans them).
INSIDE = 0.99


def move(a: np.ndarray, b: np.ndarray, limits: LegLimits) -> PiecewisePolynomial:
    """The time-optimal rest-to-rest move from ``a`` to ``b`` (Ruckig's cubic phases)."""
    durations, coeffs = leg_pieces(a, b, limits)
    return PiecewisePolynomial(np.concatenate([[0.0], np.cumsum(durations)]), coeffs)


def flight(unit_mm: int, rng: np.random.Generator, jerk: float, lim: tuple[float, ...]) -> Any:
    """Out, hold 2 s, back: near the largest coordinate stored in ``unit_mm`` units."""
    vmax, amax, _ = lim
    far = unit_mm * 32.767 - 1.0
    start = np.array(
        [far * rng.choice([-1, 1]) * rng.uniform(0.9, 1), rng.uniform(-20, 20), rng.uniform(5, 30)]
    )
    goal = start + rng.uniform(-1, 1, 3) * rng.choice([1.0, 10.0, 60.0])
    goal[2], goal[0] = max(goal[2], 2.0), np.clip(goal[0], -far, far)
    legs = LegLimits(vmax * INSIDE, amax * INSIDE, jerk * INSIDE)
    hold = PiecewisePolynomial(np.array([0.0, 2.0]), np.array([[goal]]))
    return RestToRestSequence((move(start, goal, legs), hold, move(goal, start, legs)))


def exports(traj: Any, lim: tuple[float, ...]) -> bool:
    """Whether the ``.skyc`` keyframes of ``traj`` are accepted (inside the limits, near it)."""
    planned = PlannedTrajectory(traj, (), VehicleLimits(*lim).derivative_limits(3))
    try:
        played_keyframes("d", planned)
    except InfeasibleError:
        return False
    return True


def run(unit_mm: int, seed: int) -> dict[str, Any]:
    """Moves at ``unit_mm`` units: how many export at the playable jerk and at ``jmax``."""
    rng = np.random.default_rng([seed, unit_mm])
    counts = {"moves": 0, "exported_at_playable_jerk": 0, "exported_at_jmax": 0}
    for lim in LIMITS:
        _, amax, jmax = lim
        jerk = playable_jerk(amax, jmax, unit_mm * 32.767 - 1.0)
        for _ in range(MOVES_PER_CASE):
            state = rng.bit_generator.state
            counts["moves"] += 1
            counts["exported_at_playable_jerk"] += exports(flight(unit_mm, rng, jerk, lim), lim)
            rng.bit_generator.state = state  # the same move at the limits' own jerk
            counts["exported_at_jmax"] += exports(flight(unit_mm, rng, jmax, lim), lim)
    return {"unit_mm": unit_mm, "seed": seed} | counts


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--units", type=int, nargs="+", default=[1, 4, 8, 14, 16, 20, 30])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    args = parser.parse_args()
    rows = []
    with threadpool_limits(1):
        for unit in args.units:
            for seed in args.seeds:
                rows.append(run(unit, seed))
                print(rows[-1])
    report = {
        "machine": machine_info(("numpy", "scipy", "ruckig")),
        "limits": LIMITS,
        "runs": rows,
        "note": "moves out and back with a 2 s hold, near the largest coordinate of each unit; "
        "exported: skyquill's .skyc keyframes play inside the limits (1 % speed and "
        "acceleration, 5 % jerk) within 2 cm of the plan",
    }
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "skyc_grid.json").write_text(json.dumps(jsonable(report), indent=2) + "\n")


if __name__ == "__main__":
    main()
