"""Stop-and-go legs (Ruckig) against the closed-form jerk-limited rest-to-rest time."""

from __future__ import annotations

import numpy as np
import pytest

from skyquill.coverage.stopgo import stop_and_go_legs, stop_and_go_setpoints
from skyquill.errors import InputError


def _rest_to_rest(length: float, v: float, a: float, j: float) -> float:
    """Time-optimal rest-to-rest time of a 1-D jerk-limited move (closed form).

    Reaching speed ``w`` from rest takes ``t(w) = w/a + a/j`` (acceleration
    limit reached) or ``2 sqrt(w/j)``, over ``w t(w) / 2``; braking mirrors it.
    """

    def ramp(w: float) -> float:
        return w / a + a / j if w * j >= a * a else 2.0 * np.sqrt(w / j)

    if v * ramp(v) <= length:
        return 2.0 * ramp(v) + (length - v * ramp(v)) / v
    lo, hi = 0.0, v  # the peak speed w with w t(w) = length, by bisection
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if mid * ramp(mid) <= length else (lo, mid)
    return 2.0 * ramp(lo)


@pytest.mark.parametrize("length", [0.3, 2.0, 8.0, 40.0])
def test_leg_time_is_the_closed_form(length: float) -> None:
    legs = stop_and_go_legs(np.array([[0.0, 0.0], [length, 0.0]]), 3.0, 5.0, 3.0)
    assert legs[0].duration == pytest.approx(_rest_to_rest(length, 3.0, 5.0, 3.0), rel=1e-6)


def test_diagonal_leg_uses_the_per_axis_limits_along_the_line() -> None:
    # At 45 deg each axis sees a / sqrt(2): the line may accelerate sqrt(2) times harder.
    leg = stop_and_go_legs(np.array([[0.0, 0.0], [6.0, 6.0]]), 3.0, 5.0, 3.0)[0]
    s2 = np.sqrt(2.0)
    assert leg.duration == pytest.approx(_rest_to_rest(6 * s2, 3.0, 5 * s2, 3 * s2), rel=1e-6)


def test_setpoints_rest_at_every_corner_and_respect_limits() -> None:
    pts = np.array([[0.0, 0.0], [8.0, 0.0], [8.0, 2.0], [0.0, 3.0]])
    legs = stop_and_go_legs(pts, 3.0, 5.0, 3.0)
    sp = stop_and_go_setpoints(legs, 0.001)
    starts = np.cumsum([0.0] + [leg.duration for leg in legs])
    for t_corner, p_corner in zip(starts, pts, strict=True):
        k = int(np.argmin(np.abs(sp.t - t_corner)))
        assert np.linalg.norm(sp.p[k] - p_corner) < 1e-6
        assert np.linalg.norm(sp.v[k]) < 1e-2
    # Finite differences of the positions (independent of Ruckig's own derivatives).
    jerk = np.abs(np.diff(sp.p, n=3, axis=0)) / 0.001**3
    assert jerk.max() <= 3.0 * 1.001
    assert np.abs(sp.a).max() <= 5.0 + 1e-9
    assert np.linalg.norm(sp.v, axis=1).max() <= 3.0 + 1e-9
    assert sp.u[0] == 0.0 and sp.u[-1] == pytest.approx(1.0)


def test_bad_input_is_named() -> None:
    with pytest.raises(InputError, match="waypoints"):
        stop_and_go_legs(np.array([[0.0, 0.0]]), 3.0, 5.0, 3.0)
    with pytest.raises(InputError, match="jmax"):
        stop_and_go_legs(np.array([[0.0, 0.0], [1.0, 0.0]]), 3.0, 5.0, -1.0)
    with pytest.raises(InputError, match="coincident"):
        stop_and_go_legs(np.array([[1.0, 1.0], [1.0, 1.0]]), 3.0, 5.0, 3.0)
