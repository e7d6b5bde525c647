"""Minimum-snap interpolation by one banded solve: the optimum, checked three ways.

Against the peer package ``minsnap-trajectories`` (its own closed form), against the
dense KKT system of the same problem written in the pieces' power coefficients (an
independent formulation), and against the optimality conditions themselves (continuity
up to the derivative 2s - 2, the given ends, interpolation).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.optimize.minsnap import min_snap
from skyquill.reproduce.peers import minsnap_interpolate
from skyquill.trajectory import PiecewisePolynomial


def _waypoints(n: int, seed: int, dim: int = 3) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    return rng.uniform(-5, 5, (n, dim)), np.cumsum(np.r_[0.3, rng.uniform(0.2, 4.0, n - 1)])


def _dense_kkt(w: np.ndarray, t: np.ndarray, s: int) -> PiecewisePolynomial:
    """The same optimum from the full KKT system in the power coefficients (small sizes)."""
    m, n = w.shape[0] - 1, 2 * s
    T = np.diff(t)
    hess = np.zeros((m * n, m * n))
    for i in range(m):  # ∫_0^T (c^(s))^2: entries j!k!/((j-s)!(k-s)!) T^(j+k-2s+1)/(j+k-2s+1)
        for j in range(s, n):
            for k in range(s, n):
                f = math.perm(j, s) * math.perm(k, s)
                hess[i * n + j, i * n + k] = f * T[i] ** (j + k - 2 * s + 1) / (j + k - 2 * s + 1)
    rows, rhs = [], []

    def deriv_row(i: int, r: int, tau: float) -> np.ndarray:
        row = np.zeros(m * n)
        for j in range(r, n):
            row[i * n + j] = math.perm(j, r) * tau ** (j - r)
        return row

    for i in range(m):
        rows += [deriv_row(i, 0, 0.0), deriv_row(i, 0, T[i])]
        rhs += [w[i], w[i + 1]]
    for r in range(1, s):
        rows += [deriv_row(0, r, 0.0), deriv_row(m - 1, r, T[-1])]
        rhs += [np.zeros(w.shape[1])] * 2
        for i in range(m - 1):
            rows.append(deriv_row(i, r, T[i]) - deriv_row(i + 1, r, 0.0))
            rhs.append(np.zeros(w.shape[1]))
    A, b = np.array(rows), np.array(rhs)
    kkt = np.block([[hess, A.T], [A, np.zeros((A.shape[0], A.shape[0]))]])
    sol = np.linalg.lstsq(kkt, np.vstack([np.zeros((m * n, w.shape[1])), b]), rcond=None)[0]
    return PiecewisePolynomial(t - t[0], sol[: m * n].reshape(m, n, w.shape[1]))


def _close(a: PiecewisePolynomial, b: PiecewisePolynomial, order: int, rtol: float) -> None:
    tt = np.linspace(0.0, a.duration, 997)
    for k in range(order + 1):
        pa, pb = a.evaluate(tt, k), b.evaluate(tt, k)
        assert np.abs(pa - pb).max() <= rtol * max(1.0, np.abs(pb).max()), k


@pytest.mark.parametrize("n", [2, 3, 10, 40])
def test_matches_the_peer(n: int) -> None:
    w, t = _waypoints(n, n)
    _close(min_snap(w, t), minsnap_interpolate(w, t).trajectory, 4, 1e-6)


@pytest.mark.parametrize("order", [2, 3, 4])
def test_matches_the_dense_kkt_system(order: int) -> None:
    w, t = _waypoints(6, 7, dim=2)
    _close(min_snap(w, t, order=order), _dense_kkt(w, t, order), order, 1e-7)


def _piece_derivative(traj: PiecewisePolynomial, piece: int, tau: float, r: int) -> np.ndarray:
    """Derivative ``r`` of one piece at its local time ``tau`` (a one-sided limit at a join)."""
    c = traj.coeffs[piece]
    powers = np.arange(r, c.shape[0])
    factors = np.array([math.perm(j, r) for j in powers], dtype=float)
    return (factors * tau ** (powers - r)) @ c[r:]


def _jump_tolerance(r: int, order: int) -> float:
    """Largest jump of derivative ``r`` at a waypoint, relative to the derivatives' size.

    The highest continuous one (``2 order - 2``: the sixth for min-snap) carries the banded
    solve's round-off amplified most: up to 1.8e-6 of the size in 600 random draws of
    degree-7 chains (the lower ones stay below 1e-7). It is the solve's, not the test's
    evaluation: relative to the sum of the evaluated terms' magnitudes it is the same.
    """
    return 1e-5 if r == 2 * order - 2 else 1e-7


@settings(max_examples=40, deadline=None)
@given(
    st.integers(2, 30),
    st.integers(0, 2**32 - 1),
    st.sampled_from([2, 3, 4]),
    st.floats(1e-3, 1e3),
)
@example(16, 1, 4, 1.0)  # the sixth derivative's jump at waypoint 14: 1.0004e-7 of its size
def test_optimality_conditions_hold(n: int, seed: int, order: int, time_scale: float) -> None:
    w, t = _waypoints(n, seed)
    t = t * time_scale
    rng = np.random.default_rng(seed)
    start = rng.normal(size=(order - 1, 3)) / time_scale ** np.arange(1, order)[:, None]
    traj = min_snap(w, t, start=start, order=order)
    assert traj.degree == 2 * order - 1
    assert np.allclose(traj.evaluate(t - t[0]), w, atol=1e-9 * max(1.0, np.abs(w).max()))
    T = np.diff(traj.breaks)
    for r in range(1, order):
        assert np.allclose(_piece_derivative(traj, 0, 0.0, r), start[r - 1], rtol=1e-7, atol=1e-12)
        end = _piece_derivative(traj, n - 2, T[-1], r)
        assert np.abs(end).max() <= 1e-7 * time_scale ** (-r) * max(1.0, np.abs(w).max())
    # Continuity of the derivatives up to 2s - 2 at every interior waypoint (Euler-Lagrange),
    # relative to the size of the derivatives there in the same time unit.
    for i in range(1, n - 1):
        size = max(
            float(np.abs(_piece_derivative(traj, i, 0.0, k)).max()) * (time_scale**k)
            for k in range(2 * order - 1)
        )
        for r in range(2 * order - 1):
            left = _piece_derivative(traj, i - 1, T[i - 1], r)
            right = _piece_derivative(traj, i, 0.0, r)
            jump = np.abs(left - right).max() * time_scale**r
            assert jump <= _jump_tolerance(r, order) * size, (r, i)


def _hermite_pieces(derivs: np.ndarray, T: np.ndarray) -> PiecewisePolynomial:
    """Degree-7 pieces with the given derivatives 0..3 at both ends of each (solved directly)."""
    coeffs = []
    for i, dt in enumerate(T):
        rows = [
            [math.perm(j, r) * tau ** (j - r) if j >= r else 0.0 for j in range(8)]
            for tau in (0.0, dt)
            for r in range(4)
        ]
        coeffs.append(np.linalg.solve(np.array(rows), np.vstack([derivs[i], derivs[i + 1]])))
    return PiecewisePolynomial(np.r_[0.0, np.cumsum(T)], np.array(coeffs))


def test_perturbed_interior_derivatives_never_lower_the_cost() -> None:
    # Any other choice of the interior velocities, accelerations and jerks is another
    # feasible C3 interpolant through the same waypoints: its snap integral is never lower.
    w, t = _waypoints(8, 3)
    best = min_snap(w, t)
    cost = best.squared_derivative_integral(4)
    T = np.diff(best.breaks)
    at = [(min(i, 6), 0.0 if i < 7 else T[-1]) for i in range(8)]
    derivs = np.array([[_piece_derivative(best, p, tau, r) for r in range(4)] for p, tau in at])
    assert np.allclose(_hermite_pieces(derivs, T).coeffs, best.coeffs, atol=1e-8)
    rng = np.random.default_rng(0)
    for _ in range(20):
        moved = derivs.copy()
        moved[1:-1, 1:] += rng.normal(scale=1e-2, size=(6, 3, 3))
        other = _hermite_pieces(moved, T)
        assert np.allclose(other.evaluate(t - t[0]), w)
        assert other.squared_derivative_integral(4) > cost


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"waypoints": np.zeros((1, 3)), "times": np.zeros(1)}, "waypoints: got shape"),
        ({"waypoints": np.zeros((3, 3)), "times": np.zeros(2)}, "times: got shape"),
        ({"waypoints": np.zeros((3, 3)), "times": np.array([0.0, 1.0, 1.0])}, "times: got a step"),
        ({"waypoints": np.full((3, 3), np.nan), "times": np.arange(3.0)}, "non-finite"),
        ({"waypoints": np.zeros((3, 3)), "times": np.arange(3.0), "order": 5}, "order: got 5"),
        ({"waypoints": np.zeros((3, 3)), "times": np.arange(3.0), "end": np.zeros(3)}, "end: got"),
    ],
)
def test_bad_input(kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(InputError, match=message):
        min_snap(**kwargs)  # type: ignore[arg-type]
