"""A trajectory known from its samples: ``trajectory.csv`` read back, setpoint files."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.interpolate import BSpline, CubicHermiteSpline, make_interp_spline

from skyquill.errors import InputError
from skyquill.trajectory.base import Samples, evaluation_times, sample
from skyquill.validation import FloatArray, as_array, as_int

#: Largest magnitude accepted in any column (m, m/s, ...): beyond it a value is
#: almost surely in the wrong unit, and spline arithmetic would overflow.
MAX_VALUE = 1e6
#: Smallest accepted time step, s: finer sampling than 1 MHz is not a trajectory
#: anyone planned, and the Hermite slopes ``dp / dt`` would overflow.
MIN_STEP_S = 1e-6


@dataclass(frozen=True)
class SampledTrajectory:
    """A trajectory known from samples, implementing the Trajectory protocol.

    Interpolation between samples (time ``t`` from 0 to :attr:`duration`):

    * position: cubic Hermite through ``(t_i, p_i, v_i)``
      (:class:`scipy.interpolate.CubicHermiteSpline`): exact at the samples
      and C1;
    * velocity: cubic Hermite through ``(t_i, v_i, a_i)``, exact and C1. It
      is therefore *not* exactly the derivative of the position interpolant
      (which is only a C0 quadratic); each order is the best interpolant of
      the samples of that order;
    * acceleration: linear between the ``a_i`` (C0);
    * jerk: linear between the ``j_i`` when jerk samples are given; otherwise
      the derivative of the linear acceleration, i.e. the constant
      ``(a_{i+1} - a_i) / (t_{i+1} - t_i)`` on each interval (right-continuous;
      the last interval's value at ``t = duration``);
    * order 4 and up: derivatives of the jerk interpolant (as
      :class:`~skyquill.trajectory.SplineTrajectory` returns 0 above its
      degree): with jerk samples, snap is the piecewise-constant slope of the
      linear jerk and order 5 and up is 0; without them, 0 from order 4. The
      samples carry no information about these orders -- RotorPy asks for
      snap, and gets this.

    Parameters
    ----------
    t
        Sample times, shape (N,), s, N >= 2, strictly increasing (steps of at
        least 1 µs). They may start anywhere: the trajectory's own time is
        ``t - t[0]``, and :attr:`t0` keeps ``t[0]``.
    p, v, a
        Position (m), velocity (m/s) and acceleration (m/s^2), shape (N, 3),
        z-up world frame.
    j
        Jerk (m/s^3), shape (N, 3), or ``None``.
    """

    t: FloatArray
    p: FloatArray
    v: FloatArray
    a: FloatArray
    j: FloatArray | None = None

    def __post_init__(self) -> None:
        t = as_array("t", self.t, ndim=1, max_abs=1e7)
        if t.size < 2:
            raise InputError(f"t: got {t.size} sample(s), expected at least 2")
        steps = np.diff(t)
        if np.any(steps < MIN_STEP_S):
            i = int(np.argmax(steps < MIN_STEP_S))
            raise InputError(
                f"t: got t[{i}] = {t[i]:.9g} followed by {t[i + 1]:.9g}, expected strictly "
                f"increasing times at least {MIN_STEP_S:g} s apart"
            )
        object.__setattr__(self, "t", t)
        names = ("p", "v", "a") + (("j",) if self.j is not None else ())
        for name in names:
            arr = as_array(name, getattr(self, name), shape=(t.size, 3), max_abs=MAX_VALUE)
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        t.setflags(write=False)

    @property
    def t0(self) -> float:
        """Time of the first sample in the source, s (the trajectory's time 0)."""
        return float(self.t[0])

    @property
    def duration(self) -> float:
        """Length in seconds; the trajectory is defined on ``[0, duration]``."""
        return float(self.t[-1] - self.t[0])

    @property
    def dim(self) -> int:
        """Number of axes: always 3 (x, y, z)."""
        return 3

    @property
    def breakpoints(self) -> FloatArray:
        """The sample times in trajectory time (``t - t0``), shape (N,), s."""
        return np.asarray(self.t - self.t[0])

    @cached_property
    def _interpolants(self) -> tuple[CubicHermiteSpline | BSpline, ...]:
        tau = self.t - self.t[0]
        acc = make_interp_spline(tau, self.a, k=1)
        jerk = make_interp_spline(tau, self.j, k=1) if self.j is not None else acc.derivative()
        chain: list[CubicHermiteSpline | BSpline] = [
            CubicHermiteSpline(tau, self.p, self.v),
            CubicHermiteSpline(tau, self.v, self.a),
            acc,
            jerk,
        ]
        if jerk.k > 0:
            chain.append(jerk.derivative())  # snap, piecewise constant
        return tuple(chain)

    def evaluate(self, t: FloatArray, order: int = 0) -> FloatArray:
        """The ``order``-th time derivative at times ``t``.

        Parameters
        ----------
        t
            Times, shape (N,), each in ``[0, duration]`` s (trajectory time,
            i.e. source time minus :attr:`t0`).
        order
            0 (position, m) to 3 (jerk, m/s^3); higher orders are the
            derivatives of the jerk interpolant (see the class docstring).

        Returns
        -------
        numpy.ndarray, shape (N, 3)
        """
        times = evaluation_times(t, self.duration)
        as_int("order", order, low=0)
        if order >= len(self._interpolants):
            return np.zeros((times.size, 3))
        values = self._interpolants[order](times)
        return np.asarray(values, dtype=float).reshape(times.size, 3)

    def sample(self, rate: float) -> Samples:
        """Samples at ``rate`` Hz (position to jerk), from 0 to ``duration`` inclusive."""
        return sample(self, rate)
