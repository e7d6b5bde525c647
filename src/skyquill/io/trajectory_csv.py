"""Read ``trajectory.csv`` back into a trajectory that can be flown; write ``flight.csv``.

``trajectory.csv`` is what every planning command writes
(:data:`skyquill.io.points.TRAJECTORY_COLUMNS`): ``t,x,y,z,vx,vy,vz,ax,ay,az``
and optionally ``jx,jy,jz``, SI units, z-up world frame, one row per sample.
:func:`read_trajectory_csv` turns those samples into a
:class:`SampledTrajectory` that a simulator can fly; :func:`write_flight_csv`
writes the time series of a :class:`~skyquill.sim.Flight`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np
from scipy.interpolate import BSpline, CubicHermiteSpline, make_interp_spline

from skyquill.errors import InputError
from skyquill.io.table import Table, read_table
from skyquill.sim.result import Flight
from skyquill.trajectory import Samples, evaluation_times, sample
from skyquill.validation import FloatArray, as_array, as_int

#: Columns :func:`read_trajectory_csv` needs (jerk ``jx,jy,jz`` is optional).
REQUIRED_COLUMNS = ("t", "x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az")
JERK_COLUMNS = ("jx", "jy", "jz")

#: ``flight.csv``: reference and flown state, commands; SI units, z-up world frame.
FLIGHT_COLUMNS = (
    "t",
    "x_ref",
    "y_ref",
    "z_ref",
    "x",
    "y",
    "z",
    "vx_ref",
    "vy_ref",
    "vz_ref",
    "vx",
    "vy",
    "vz",
    "ax_cmd",
    "ay_cmd",
    "az_cmd",
    "thrust",
    "tilt",
)

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


def read_trajectory_csv(path: str | Path) -> SampledTrajectory:
    """Read a ``trajectory.csv`` (as written by ``skyquill fit``) into a trajectory.

    Parameters
    ----------
    path
        CSV file with a header naming at least ``t,x,y,z,vx,vy,vz,ax,ay,az``
        (any order, case and surrounding spaces ignored; other columns are
        ignored) and optionally all three of ``jx,jy,jz``. Units: s, m, m/s,
        m/s^2, m/s^3. Blank lines are skipped.

    Returns
    -------
    SampledTrajectory
        Time shifted so that the first row is at 0 (see :attr:`SampledTrajectory.t0`).

    Raises
    ------
    InputError
        Naming the file, and the column or line, for everything
        :func:`~skyquill.io.table.read_table` refuses (missing or unreadable
        file, missing or repeated column, ragged row, a cell that is not a
        finite number, fewer than 2 rows), a magnitude above 1e6 (1e7 for
        ``t``), only some of ``jx,jy,jz``, or times not strictly increasing.
    """
    table = read_table(
        path,
        required=REQUIRED_COLUMNS,
        optional=JERK_COLUMNS,
        min_rows=2,
        name="trajectory file",
    )
    present = [c for c in JERK_COLUMNS if table.has(c)]
    if present and len(present) < len(JERK_COLUMNS):
        raise InputError(
            f"{table.name}: got jerk column(s) {','.join(present)}, expected all of jx,jy,jz "
            "or none"
        )
    _check_magnitudes(table)
    t = table.column("t")
    steps = np.diff(t)
    if np.any(steps < MIN_STEP_S):
        k = int(np.argmax(steps < MIN_STEP_S))
        raise InputError(
            f"{table.name} line {table.lines[k + 1]}, column t: got {t[k + 1]:.9g} after "
            f"{t[k]:.9g}, expected strictly increasing times (at least {MIN_STEP_S:g} s apart)"
        )
    return SampledTrajectory(
        t=t,
        p=table.select(REQUIRED_COLUMNS[1:4]),
        v=table.select(REQUIRED_COLUMNS[4:7]),
        a=table.select(REQUIRED_COLUMNS[7:10]),
        j=table.select(JERK_COLUMNS) if present else None,
    )


def _check_magnitudes(table: Table) -> None:
    """Times within 1e7 s, other values within :data:`MAX_VALUE`: SI units, no overflow."""
    limits = np.array([1e7 if c == "t" else MAX_VALUE for c in table.columns])
    over = np.abs(table.data) > limits
    if np.any(over):
        r, c = np.argwhere(over)[0]
        raise InputError(
            f"{table.name} line {table.lines[r]}, column {table.columns[c]}: got "
            f"{table.data[r, c]:.9g}, expected a magnitude of at most {limits[c]:g} (SI units)"
        )


def flight_table(flight: Flight) -> FloatArray:
    """The ``flight.csv`` table, shape (N, 18), columns :data:`FLIGHT_COLUMNS`."""
    return np.column_stack(
        [
            flight.t,
            flight.p_ref,
            flight.p,
            flight.v_ref,
            flight.v,
            flight.a_cmd,
            flight.thrust,
            flight.tilt,
        ]
    )


def write_flight_csv(path: str | Path, flight: Flight) -> int:
    """Write ``flight.csv`` (columns :data:`FLIGHT_COLUMNS`, SI units); returns the row count.

    ``thrust`` is the commanded collective thrust in N, ``tilt`` the commanded
    tilt from vertical in rad, ``a*_cmd`` the outer loop's acceleration command
    (gravity excluded), m/s^2.
    """
    table = flight_table(flight)
    np.savetxt(path, table, delimiter=",", header=",".join(FLIGHT_COLUMNS), comments="", fmt="%.9g")
    return int(table.shape[0])
