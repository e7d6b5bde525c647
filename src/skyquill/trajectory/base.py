"""The :class:`Trajectory` protocol and what every kind shares: times, samples, dense times.

Positions are in the z-up world frame, metres; time in seconds from 0 to
``duration``. Every kind of trajectory (``docs/architecture.md``) implements
the protocol; the simulator, the verifier and every exporter take any of them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from skyquill.errors import InputError
from skyquill.validation import FloatArray, as_array, as_float

#: docs/architecture.md "verified": at least 20 samples per knot span and never fewer than 10,000.
DENSE_PER_SPAN = 20
DENSE_MIN_TOTAL = 10_000
#: Most samples one call of :func:`sample_times` may produce (memory: 13 columns
#: of float64 per sample, ~1 GB at this ceiling).
MAX_SAMPLES = 10_000_000


@dataclass(frozen=True)
class Samples:
    """A trajectory sampled at fixed times.

    Attributes
    ----------
    t
        Times, shape (N,), s.
    p, v, a, j
        Position (m), velocity (m/s), acceleration (m/s^2), jerk (m/s^3),
        each shape (N, d).
    """

    t: FloatArray
    p: FloatArray
    v: FloatArray
    a: FloatArray
    j: FloatArray


@runtime_checkable
class Trajectory(Protocol):
    """What every stage needs of a trajectory."""

    @property
    def duration(self) -> float:
        """Length in seconds; the trajectory is defined on ``[0, duration]``."""
        ...

    @property
    def dim(self) -> int:
        """Number of axes ``d``."""
        ...

    @property
    def breakpoints(self) -> FloatArray:
        """Where its pieces meet (knots, samples, legs), shape (L + 1,), s, 0 to duration."""
        ...

    def evaluate(self, t: FloatArray, order: int = 0) -> FloatArray:
        """The ``order``-th time derivative at times ``t`` (N,); returns (N, d)."""
        ...

    def sample(self, rate: float) -> Samples:
        """Samples at ``rate`` Hz from 0 to ``duration`` inclusive."""
        ...


@runtime_checkable
class ManyOrders(Protocol):
    """A trajectory that evaluates several derivative orders at once (the piecewise
    polynomial: its pieces looked up once for all of them)."""

    def evaluate_orders(self, t: FloatArray, orders: Sequence[int]) -> dict[int, FloatArray]: ...


@runtime_checkable
class Kinked(Protocol):
    """A trajectory whose highest derivatives have kinks inside its pieces (a path curve's
    knots crossed by a timing law): the dense check samples them too."""

    def kink_times(self) -> FloatArray: ...


def check_times(traj: Trajectory) -> FloatArray:
    """The times the dense check samples ``traj`` at, sorted, s: :func:`dense_times` of its
    breakpoints, each inner breakpoint also from the left, and, for a :class:`Kinked` kind,
    its kinks.

    A derivative that jumps at a breakpoint (the jerk of a path flown along a C2 quintic
    timing law) takes two values there, and a breakpoint's own sample gives only the right
    one: the end of the piece before it was never seen. On a 100 ha field's flight it was
    2.9 % over the jerk limit while its pieces' checks said 1.75 %. A jerk peak at a kink
    lasts well under a millisecond and falls between the evenly spaced samples: on a 1.3 ha
    field's coverage flight the samples saw 0.9 % over the jerk limit where the kinks reach
    2.3 % (200 samples a piece: 2.2 %).
    """
    breaks = traj.breakpoints
    extra = [np.nextafter(breaks[1:-1], -np.inf)]  # the last double of the piece before
    if isinstance(traj, Kinked):
        extra.append(traj.kink_times())
    return np.sort(np.concatenate([dense_times(breaks), *extra]))


def derivatives(traj: Trajectory, t: FloatArray, orders: Sequence[int]) -> dict[int, FloatArray]:
    """``{n: traj.evaluate(t, n)}`` for each of ``orders``, at once where the kind can
    (:class:`ManyOrders`); shape (N, d) each."""
    if isinstance(traj, ManyOrders):
        return traj.evaluate_orders(t, orders)
    return {n: traj.evaluate(t, n) for n in orders}


def evaluation_times(t: object, duration: float) -> FloatArray:
    """Times ``t`` (N,) checked to lie in ``[0, duration]`` (to round-off), clipped there.

    The check every trajectory's ``evaluate`` shares; :class:`InputError` otherwise.
    """
    times = as_array("t", t, ndim=1)
    tol = 1e-9 * max(1.0, duration)
    if times.size and (times.min() < -tol or times.max() > duration + tol):
        raise InputError(
            f"t: got times in [{times.min():g}, {times.max():g}] s, expected within "
            f"[0, {duration:g}] s"
        )
    return np.clip(times, 0.0, duration)  # only round-off reaches the clip


def sample_times(duration: float, rate: float) -> FloatArray:
    """``0, 1/rate, ...`` up to and including ``duration``; shape (N,).

    Raises
    ------
    InputError
        When more than :data:`MAX_SAMPLES` samples would be made.
    """
    rate = as_float("rate", rate, positive=True)
    count = duration * rate
    if count + 1 > MAX_SAMPLES:
        raise InputError(
            f"rate: got {rate:g} Hz over {duration:g} s ({count:.3g} samples), expected at most "
            f"{MAX_SAMPLES:,} samples (a lower rate)"
        )
    n = int(np.floor(count + 1e-9)) + 1
    t = np.arange(n) / rate
    if duration - t[-1] > 1e-9:
        t = np.append(t, duration)
    return np.minimum(t, duration)


def sample(traj: Trajectory, rate: float) -> Samples:
    """Sample any :class:`Trajectory` (position to jerk) at ``rate`` Hz."""
    t = sample_times(traj.duration, rate)
    p, v, a, j = (traj.evaluate(t, n) for n in range(4))
    return Samples(t, p, v, a, j)


def dense_times(breakpoints: FloatArray) -> FloatArray:
    """Times for the dense check (docs/architecture.md): >= 20 per span and >= 10,000 in all.

    Every span between consecutive ``breakpoints`` (L + 1,) gets the same number
    of evenly spaced samples, both ends of every span included, so that short
    spans (a turn, a rest) are sampled as finely as long ones.

    Returns
    -------
    numpy.ndarray, shape (N,)
        Sorted times, s.
    """
    spans = breakpoints.size - 1
    per_span = max(DENSE_PER_SPAN, -(-(DENSE_MIN_TOTAL - 1) // spans))
    fractions = np.arange(per_span) / per_span
    t = breakpoints[:-1, None] + np.diff(breakpoints)[:, None] * fractions[None, :]
    return np.append(t.ravel(), breakpoints[-1])


def check_breakpoints(name: str, breaks: object) -> FloatArray:
    """Piece boundaries: finite, starting at 0, strictly increasing; read-only copy (P + 1,)."""
    values = as_array(name, breaks, ndim=1)
    if values.size < 2:
        raise InputError(f"{name}: got {values.size} value(s), expected at least 2 (one piece)")
    if values[0] != 0.0:
        raise InputError(f"{name}: got {name}[0] = {values[0]:g}, expected 0")
    steps = np.diff(values)
    if np.any(steps <= 0.0):
        i = int(np.argmax(steps <= 0.0))
        raise InputError(
            f"{name}: got {name}[{i + 1}] = {values[i + 1]:.9g} after {values[i]:.9g}, "
            "expected strictly increasing times"
        )
    values.setflags(write=False)
    return values
