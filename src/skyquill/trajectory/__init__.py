"""Trajectories: the one currency every pipeline stage speaks (``docs/architecture.md``).

:class:`Trajectory` is the protocol (duration, breakpoints, evaluate, sample).
Its kinds, one file each:

* :class:`SplineTrajectory` -- the clamped uniform B-spline the engine returns;
* :class:`PiecewisePolynomial` -- a polynomial per piece (Crazyswarm files,
  min-snap peers, time-optimal legs);
* :class:`SampledTrajectory` -- known from samples (``trajectory.csv`` read back);
* :class:`RetimedPath` -- a path curve and its timing law (coverage);
* :class:`RestToRestSequence` -- pieces flown one after another, at rest where
  they meet (stop-and-go, part by part, several uploads).

:mod:`skyquill.trajectory.codec` turns any of them into the dictionary that
``trajectory.json`` stores. Positions are in the z-up world frame, metres;
time in seconds from 0.
"""

from skyquill.trajectory.base import (
    DENSE_MIN_TOTAL,
    DENSE_PER_SPAN,
    MAX_SAMPLES,
    Samples,
    Trajectory,
    dense_times,
    derivatives,
    evaluation_times,
    sample,
    sample_times,
)
from skyquill.trajectory.polynomial import PiecewisePolynomial
from skyquill.trajectory.retimed import RetimedPath
from skyquill.trajectory.sampled import SampledTrajectory
from skyquill.trajectory.sequence import RestToRestSequence, concatenate
from skyquill.trajectory.spline import SplineTrajectory

__all__ = [
    "DENSE_MIN_TOTAL",
    "DENSE_PER_SPAN",
    "MAX_SAMPLES",
    "PiecewisePolynomial",
    "RestToRestSequence",
    "RetimedPath",
    "SampledTrajectory",
    "Samples",
    "SplineTrajectory",
    "Trajectory",
    "concatenate",
    "dense_times",
    "derivatives",
    "evaluation_times",
    "sample",
    "sample_times",
]
