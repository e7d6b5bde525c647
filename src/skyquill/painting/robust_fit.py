"""The pieces' lines fitted to the contacts by robust least squares, the localization drift
marginalised.

Given the pieces (which contact belongs to which, :mod:`skyquill.painting.segmentation`), every
piece's line ``y = a_k x + b_k`` (``R_rho``) is fitted to its contacts at once by
``scipy.optimize.least_squares`` with a soft-L1 loss: a contact that passed the outlier screen
but is still off its piece weighs like an absolute, not a squared, residual.

Onboard localization drifts: a contact is measured where the drone *believes* it is, off by a
random walk since its last take-off (reset at every landing, paper 002 §3.3). Along a short
tour, contacts close along the wall are close in time too, so the drift bends the wall the
contacts draw -- by several centimetres over a metre, which a piecewise model reads as wall
shape and as a turned placement (measured on the paper's walls: 4-9 cm of aim error from the
drift alone). The paper proposes weights "depending on the localization accuracy at the time of
contact" as future work; here that accuracy is modelled as what it is. A contact's residual
along ``R_rho``'s ``y`` (the only direction a contact on a wall facing the drone sees) is

    e_j = y_j - (a_k x_j + b_k) = D(tau_j) + n_j,

``D`` a random walk of rate ``s`` (m / sqrt(s)) starting at 0 at each take-off, ``n_j`` white
noise ``sigma``, ``tau`` the time since the take-off. Its exact likelihood is that of the
innovations of a scalar Kalman filter over each flight's contacts in time order: the filter
turns the residuals into independent unit-variance innovations, linearly, with gains that do
not depend on the data. So the lines are fitted by ``least_squares`` to the *whitened*
innovations (2 K unknowns, whatever the number of contacts), and each contact's drift is then
the Rauch-Tung-Striebel smoother's estimate given the fitted lines. The wall is what the
contacts say after the drift that time explains; drift that time cannot explain (a corner
crossed in a few seconds) stays wall. With no drift (``s = 0``) the filter is a division by
``sigma`` and the fit is an ordinary robust line fit. ``s`` and ``sigma`` are the
localization's specification, as an operator knows it (a motion-capture room: no drift; a
visual odometry: centimetres per minute), not its realisation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import least_squares

from skyquill.painting.segmentation import Pieces, corner_or_step
from skyquill.validation import FloatArray

#: Soft-L1's corner, in contact noise units: residuals beyond 2 sigma count linearly.
SOFT_L1_SIGMAS = 2.0


@dataclass(frozen=True)
class DriftModel:
    """When each contact was measured, and how fast the localization drifts.

    Attributes
    ----------
    battery
        Flight of each contact (0 for the first, +1 after each landing), shape (n,), ints.
    airborne_s
        Time since that flight's take-off, shape (n,), s.
    rate_m_per_sqrt_s
        Drift rate (random walk), m / sqrt(s); 0 for none.
    """

    battery: np.ndarray
    airborne_s: FloatArray
    rate_m_per_sqrt_s: float


@dataclass(frozen=True)
class LineFit:
    """The robust fit: the pieces with their lines, each contact's drift, the residual scale.

    Attributes
    ----------
    pieces
        The input pieces with the fitted lines (and the breaks that follow from them).
    drift
        Smoothed ``D`` at every contact (those not fitted: interpolated in time within their
        flight), shape (n,), m; zeros without drift.
    scale
        Robust scale (1.4826 x median) of the fitted contacts' residuals after the drift,
        never below the noise, m.
    misfit
        Twice ``least_squares``' final cost: the soft-L1 sum of the squared whitened
        innovations, which is -2 log-likelihood (up to a constant that depends on the contact
        times only) -- what models of the same contacts are compared by.
    """

    pieces: Pieces
    drift: FloatArray
    scale: float
    misfit: float


def fit_lines(
    x: FloatArray,
    y: FloatArray,
    keep: np.ndarray,
    candidates: list[Pieces],
    *,
    noise_m: float,
    drift: DriftModel,
) -> LineFit:
    """The candidate cut whose robustly fitted lines explain the kept contacts best.

    Each candidate's lines are fitted by least squares (soft-L1) to the whitened innovations;
    the one with the smallest ``misfit + (3K - 1) ln n`` (the Bayesian information criterion
    on the likelihood that counts the drift's own probability) is returned, with its drift.

    Parameters
    ----------
    x, y
        Every contact in ``R_rho``, shape (n,) each, m.
    keep
        The contacts the lines are fitted to, shape (n,), bools.
    candidates
        Cuts of the kept contacts into pieces (which line each belongs to, by ``x``), >= 1.
    noise_m
        The contacts' white noise (with any floor already in it), m, > 0.
    drift
        When the contacts were measured and the drift rate.
    """
    rows = np.flatnonzero(keep)
    filt = RandomWalkFilter(
        drift.battery[rows], drift.airborne_s[rows], drift.rate_m_per_sqrt_s, noise_m
    )
    designs = [_design(x[rows], pieces) for pieces in candidates]
    # one pass of the filter whitens the contacts and every candidate's design at once
    white = filt.whiten(np.column_stack([y[rows], *designs]))
    wy = white[:, 0]
    penalty = math.log(max(rows.size, 2))
    best: tuple[float, int, FloatArray, float] | None = None
    col = 1
    for i, design in enumerate(designs):
        wa = white[:, col : col + design.shape[1]]
        col += design.shape[1]
        theta, misfit = _robust(wa, wy)
        score = misfit + (design.shape[1] * 1.5 - 1.0) * penalty
        if best is None or score < best[0]:
            best = (score, i, theta, misfit)
    assert best is not None  # candidates is not empty
    _, i, theta, misfit = best
    pieces = candidates[i]
    residual = y[rows] - designs[i] @ theta
    d_rows = filt.smooth(residual)
    lines = theta.reshape(-1, 2)
    breaks = np.array(
        [
            corner_or_step(pieces.x_hi[k], pieces.x_lo[k + 1], lines[k], lines[k + 1])
            for k in range(pieces.n_pieces - 1)
        ]
    )
    fitted = replace(pieces, slopes=lines[:, 0], intercepts=lines[:, 1], breaks=breaks)
    scale = max(1.4826 * float(np.median(np.abs(residual - d_rows))), noise_m)
    return LineFit(fitted, _fill(drift, rows, d_rows), scale, misfit)


def _design(x: FloatArray, pieces: Pieces) -> FloatArray:
    """Columns ``x`` and 1 of each contact's piece: ``design @ [a_0, b_0, a_1, ...]``, (n, 2K)."""
    labels = pieces.piece_of(x)
    design = np.zeros((x.size, 2 * pieces.n_pieces))
    design[np.arange(x.size), 2 * labels] = x
    design[np.arange(x.size), 2 * labels + 1] = 1.0
    return design


def _robust(wa: FloatArray, wy: FloatArray) -> tuple[FloatArray, float]:
    """``least_squares`` (soft-L1) of ``wa @ theta ~ wy`` from the plain solution: theta and
    twice the final cost."""
    theta0 = np.linalg.lstsq(wa, wy, rcond=None)[0]

    def residuals(theta: FloatArray) -> FloatArray:
        out: FloatArray = wa @ theta - wy
        return out

    def jacobian(theta: FloatArray) -> FloatArray:
        del theta
        return wa

    sol = least_squares(
        residuals,
        theta0,
        jac=jacobian,
        loss="soft_l1",
        f_scale=SOFT_L1_SIGMAS,
        method="trf",
    )
    return sol.x, 2.0 * float(sol.cost)


class RandomWalkFilter:
    """Scalar Kalman filter and smoother for ``e_j = D(tau_j) + n_j`` over contacts.

    ``D`` restarts at 0 with each flight (``battery``); within a flight contacts are taken in
    the order of ``airborne_s``. The gains depend on the times only, so whitening is linear.
    """

    def __init__(
        self, battery: np.ndarray, airborne_s: FloatArray, rate: float, noise: float
    ) -> None:
        self.order = np.lexsort((airborne_s, battery))
        b, t = battery[self.order], airborne_s[self.order]
        n = b.size
        q = rate * rate
        r = noise * noise
        self.first = np.ones(n, dtype=bool)
        self.first[1:] = b[1:] != b[:-1]
        dt = np.where(self.first, t, np.diff(t, prepend=0.0))
        self.p_pred = np.empty(n)
        self.p_filt = np.empty(n)
        p = 0.0
        for j in range(n):
            p = (0.0 if self.first[j] else p) + q * max(float(dt[j]), 0.0)
            self.p_pred[j] = p
            p = p * r / (p + r)
            self.p_filt[j] = p
        self.s = self.p_pred + r
        self.gain = self.p_pred / self.s

    def whiten(self, e: FloatArray) -> FloatArray:
        """The innovations of the columns of ``e`` (n, m) divided by their deviation, (n, m)."""
        src = e[self.order]
        out = np.empty_like(src)
        state = np.zeros(src.shape[1])
        for j in range(src.shape[0]):
            if self.first[j]:
                state[:] = 0.0
            nu = src[j] - state
            out[j] = nu / np.sqrt(self.s[j])
            state += self.gain[j] * nu
        back = np.empty_like(out)
        back[self.order] = out
        return back

    def smooth(self, e: FloatArray) -> FloatArray:
        """Rauch-Tung-Striebel estimate of ``D`` at each contact given residuals ``e`` (n,)."""
        src = e[self.order]
        n = src.size
        filt = np.empty(n)
        state = 0.0
        for j in range(n):
            if self.first[j]:
                state = 0.0
            state += self.gain[j] * (src[j] - state)
            filt[j] = state
        smooth = filt.copy()
        for j in range(n - 2, -1, -1):
            if self.first[j + 1] or self.p_pred[j + 1] <= 0.0:
                continue
            c = self.p_filt[j] / self.p_pred[j + 1]
            smooth[j] = filt[j] + c * (smooth[j + 1] - filt[j])
        out = np.empty(n)
        out[self.order] = smooth
        return out


def _fill(drift: DriftModel, rows: np.ndarray, d_rows: FloatArray) -> FloatArray:
    """Drift at every contact: the smoothed values, interpolated in time for the others."""
    n = drift.battery.size
    out = np.zeros(n)
    out[rows] = d_rows
    others = np.setdiff1d(np.arange(n), rows)
    for j in others:
        mask = drift.battery[rows] == drift.battery[j]
        if mask.any():
            t = drift.airborne_s[rows[mask]]
            k = np.argsort(t)
            out[j] = float(np.interp(drift.airborne_s[j], t[k], d_rows[mask][k]))
    return out
