"""What a simulation may be asked: the step budget, the rate range, rest at both ends.

Checked before anything is allocated: a two-row trajectory 10^6 s long, or
``rate_hz=1e6``, once exhausted 24 GB in the per-step arrays.
"""

from __future__ import annotations

import numpy as np

from skyquill.errors import InputError
from skyquill.trajectory import Trajectory
from skyquill.validation import as_float

#: Most integration steps one flight may take. :func:`~skyquill.sim.simulate`
#: keeps ~30 float64 per step (references, state, commands: ~0.5 GB here) and
#: its Python loop runs ~50 k steps/s, so this is already ~40 s of wall time;
#: RotorPy keeps dictionaries of arrays per step and is slower still. At the
#: default 500 Hz it is a flight of 4000 s (over an hour: longer than any battery).
MAX_SIM_STEPS = 2_000_000
#: Slowest rate accepted, Hz: the fastest time constant of the model is the
#: motor lag (1 / 40 rad/s = 25 ms); a step of 20 ms is the coarsest that
#: still resolves it (commands are held for a whole step).
MIN_RATE_HZ = 50.0
#: Fastest rate accepted, Hz: a 0.1 ms step is 250 times below that time
#: constant; beyond it only the step count (memory, wall time) grows.
MAX_RATE_HZ = 10_000.0
#: Default speed under which an end of the trajectory counts as rest, m/s
#: (the plans' rest ends are held by the solver to ~1e-6 m/s).
REST_TOLERANCE_MPS = 0.01


def check_rate(rate_hz: float) -> float:
    """The simulation rate, Hz, in ``[MIN_RATE_HZ, MAX_RATE_HZ]``; InputError otherwise."""
    rate = as_float("rate_hz", rate_hz, positive=True)
    if not MIN_RATE_HZ <= rate <= MAX_RATE_HZ:
        raise InputError(
            f"rate_hz: got {rate:g} Hz, expected {MIN_RATE_HZ:g} to {MAX_RATE_HZ:g} Hz "
            "(the step must resolve the 25 ms motor lag without wasting steps)"
        )
    return rate


def check_steps(duration_s: float, rate_hz: float) -> int:
    """The number of steps of a ``duration_s`` flight at ``rate_hz``, at most :data:`MAX_SIM_STEPS`.

    Raises
    ------
    InputError
        Above the ceiling; the message says which duration or rate would fit.
    """
    duration = as_float("trajectory.duration", duration_s, positive=True)
    steps = duration * rate_hz
    if steps + 1 > MAX_SIM_STEPS:
        raise InputError(
            f"trajectory: got a {duration:.6g} s flight at {rate_hz:g} Hz ({steps:.3g} steps), "
            f"expected at most {MAX_SIM_STEPS:,} steps (at {rate_hz:g} Hz a flight of at most "
            f"{(MAX_SIM_STEPS - 1) / rate_hz:.6g} s: lower rate_hz or fly it in parts)"
        )
    return int(steps) + 1


def check_rest_ends(trajectory: Trajectory, tolerance: float = REST_TOLERANCE_MPS) -> None:
    """Raise unless ``trajectory`` starts and ends at rest (speed <= ``tolerance`` m/s).

    A simulation starts the vehicle at rest at the first point; a reference
    that starts moving, or ends moving, is not a plan skyquill made (those
    all rest at both ends) and the flight would not be the one planned.

    Parameters
    ----------
    trajectory
        The reference, any ``dim``, m, s.
    tolerance
        Largest speed, m/s, that counts as rest.

    Raises
    ------
    InputError
        Naming the end and its speed.
    """
    tol = as_float("tolerance", tolerance, nonneg=True)
    ends = np.array([0.0, float(trajectory.duration)])
    speed = np.linalg.norm(trajectory.evaluate(ends, 1), axis=1)
    for end, verb in ((0, "starts"), (1, "ends")):
        if not speed[end] <= tol:
            raise InputError(
                f"trajectory: {verb} at {speed[end]:.3g} m/s, expected rest (a plan from "
                f"fit/write/cover/paint); a speed of at most {tol:g} m/s at both ends"
            )
