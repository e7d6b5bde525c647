"""The drift-marginalised fit: the Kalman whitening and smoother against the dense Gaussian
closed forms, the robust lines against least squares."""

from __future__ import annotations

import numpy as np
import pytest

from skyquill.painting.robust_fit import DriftModel, RandomWalkFilter, fit_lines
from skyquill.painting.segmentation import fit_pieces

RATE, NOISE = 0.004, 0.01


def _times(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Contacts over two flights (drift reset between them), shuffled."""
    battery = (np.arange(n) >= n // 2).astype(int)
    airborne = np.concatenate(
        [np.sort(rng.uniform(1, 480, n // 2)), np.sort(rng.uniform(1, 480, n - n // 2))]
    )
    shuffle = rng.permutation(n)
    return battery[shuffle], airborne[shuffle]


def _covariance(battery: np.ndarray, airborne: np.ndarray) -> np.ndarray:
    """The random walk (reset per flight) plus white noise, written out."""
    same = battery[:, None] == battery[None, :]
    walk = RATE**2 * np.minimum(airborne[:, None], airborne[None, :]) * same
    return walk + NOISE**2 * np.eye(battery.size)


def test_whitening_makes_the_covariance_the_identity() -> None:
    rng = np.random.default_rng(0)
    battery, airborne = _times(rng, 30)
    filt = RandomWalkFilter(battery, airborne, RATE, NOISE)
    w = filt.whiten(np.eye(30))  # column j: the whitening of e_j; so w = W
    assert w @ _covariance(battery, airborne) @ w.T == pytest.approx(np.eye(30), abs=1e-9)


def test_smoother_is_the_gaussian_posterior_mean() -> None:
    rng = np.random.default_rng(1)
    battery, airborne = _times(rng, 25)
    filt = RandomWalkFilter(battery, airborne, RATE, NOISE)
    e = rng.normal(0, 0.05, 25)
    walk = _covariance(battery, airborne) - NOISE**2 * np.eye(25)
    expected = walk @ np.linalg.solve(walk + NOISE**2 * np.eye(25), e)
    assert filt.smooth(e) == pytest.approx(expected, abs=1e-10)


def test_no_drift_is_a_plain_scaled_fit() -> None:
    rng = np.random.default_rng(2)
    battery, airborne = _times(rng, 10)
    filt = RandomWalkFilter(battery, airborne, 0.0, NOISE)
    e = rng.normal(size=(10, 3))
    assert filt.whiten(e) == pytest.approx(e / NOISE)
    assert filt.smooth(e[:, 0]) == pytest.approx(np.zeros(10))


def test_gaussian_lines_match_generalised_least_squares() -> None:
    """Without outliers the soft-L1 fit of the whitened innovations is the GLS line."""
    rng = np.random.default_rng(3)
    n = 60
    battery, airborne = _times(rng, n)
    x = rng.uniform(-1.75, 1.75, n)
    cov = _covariance(battery, airborne)
    y = 1.1 - 0.17 * x + np.linalg.cholesky(cov) @ rng.normal(size=n)
    keep = np.ones(n, dtype=bool)
    pieces = fit_pieces(x, y, max_pieces=1)
    fit = fit_lines(x, y, keep, [pieces], noise_m=NOISE, drift=DriftModel(battery, airborne, RATE))
    design = np.column_stack([x, np.ones(n)])
    gls = np.linalg.solve(
        design.T @ np.linalg.solve(cov, design), design.T @ np.linalg.solve(cov, y)
    )
    # soft-L1 departs from squares only beyond 2 sigma: a few innovations, a small shift
    assert fit.pieces.slopes[0] == pytest.approx(gls[0], abs=3e-3)
    assert fit.pieces.intercepts[0] == pytest.approx(gls[1], abs=3e-3)


def test_the_drift_model_recovers_a_slope_the_drift_bends() -> None:
    """Along the wall and back (a probing pass, then a tour): the drift bends the apparent
    wall; the fit that knows the drift's rate gets the slope back better than the plain one.
    (One sweep alone could not tell a slope from a drift that grows with time.)"""
    errors: dict[str, list[float]] = {"drift": [], "plain": []}
    for seed in range(8):
        rng = np.random.default_rng(seed)
        n = 120
        x = np.concatenate([np.linspace(-1.75, 1.75, 20), np.linspace(1.75, -1.75, n - 20)])
        airborne = np.linspace(5, 470, n)
        battery = np.zeros(n, dtype=int)
        walk = np.cumsum(rng.normal(0, RATE * np.sqrt(np.diff(airborne, prepend=0.0))))
        y = 1.1 - 0.1763 * x + walk + rng.normal(0, NOISE, n)
        keep = np.ones(n, dtype=bool)
        pieces = fit_pieces(x, y, max_pieces=1)
        for name, rate in (("drift", RATE), ("plain", 0.0)):
            fit = fit_lines(
                x, y, keep, [pieces], noise_m=NOISE, drift=DriftModel(battery, airborne, rate)
            )
            errors[name].append(abs(fit.pieces.slopes[0] + 0.1763))
    assert np.mean(errors["drift"]) < 0.5 * np.mean(errors["plain"])
