"""Online estimation of where the wall is, from the contacts (paper 002 §4.2 and §5.2).

Every estimator turns the contacts seen so far into a *plan* for the next dot: the target
point ``P*`` in the onboard frame ``R_rho`` and the yaw that points the paint tool (body
``y``) at the wall. Four of them:

* :class:`NoEstimator` -- the operator's nominal placement forever (the paper's "without
  estimation" column): ``P* = R(gamma0)^T (P_ref - delta0)``, yaw ``-gamma0``.
* :class:`RigidEstimator` -- weighted SVD rigid registration of the contacts onto the reference
  dots after each contact (eq. 3-10), then eq. 11-12 for the next dots (``delta_x``, which
  contacts cannot observe, stays nominal: see the class notes). ``robust=True`` (beyond the
  paper) drops the contact-to-dot pairing: RANSAC finds the contacts that lie on one line,
  then a Huber-weighted total-least-squares line through them (an SVD again) gives ``gamma``
  and ``delta_y``. A false contact (the IMU firing before the wall, so a contact point short
  of the wall by up to the waiting distance) is off that line and gets weight 0.
* :class:`SegmentEstimator` -- a wall of several segments as a set of lines
  ``y_rho = a x_rho + b`` (eq. 13): a contact farther than ``eps_bar`` from the current line's
  prediction (eq. 14) opens a new line, otherwise the line is re-fitted by regression; the next
  dot is then moved in depth only (eq. 15, ``update="depth"``) or projected normally onto the
  line (``update="normal"``, the fresco case). ``robust=True`` waits for a second contact to
  confirm a new segment (a single disagreeing contact is treated as false) and fits each line
  with Huber weights.

All planar quantities are ``(x, y)`` of ``R_rho`` or ``R_w``: as in the paper, yaw does not
change height, so the registration is 2-D and ``z`` follows the nominal placement.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from skyquill.errors import InputError
from skyquill.painting.wall import Placement
from skyquill.validation import FloatArray, as_array, as_float

UpdateMode = Literal["depth", "normal"]
#: Huber's tuning constant: 95 % efficiency on Gaussian residuals.
HUBER_C = 1.345
#: Robust scale never below this, m: the contact noise floor, so that a handful of nearly
#: perfect contacts does not make every ordinary one an outlier.
SCALE_FLOOR_M = 0.02
#: Residuals beyond this many robust scales (and beyond ``REJECT_FLOOR_M``) get weight 0.
REJECT_SCALES = 3.5
REJECT_FLOOR_M = 0.06
#: An estimate of gamma beyond this is taken as degenerate and not adopted, rad (the drone
#: would no longer face the wall).
MAX_GAMMA_HAT_RAD = math.radians(60.0)
#: The slope prior of a new line weighs like contacts spread over +- this much along x, m.
SLOPE_PRIOR_SPAN_M = 0.05
#: Largest line slope adopted (tan 45 deg): beyond it the fit is noise, not a wall segment.
MAX_SLOPE = 1.0
#: Shortest pair of contacts allowed to propose a RANSAC line, m.
RANSAC_MIN_BASELINE_M = 0.3
#: RANSAC inlier distance, m: contact noise (localization 1 cm, bumper a few mm) with margin.
RANSAC_TOLERANCE_M = 0.04


@dataclass(frozen=True)
class Plan:
    """Where to paint the next dot, in the onboard frame.

    Attributes
    ----------
    target_rho
        The point ``P*`` to touch, shape (3,), m, ``R_rho``.
    yaw_rad
        Yaw reference ``psi_r`` in ``R_rho``, rad: body ``y`` = ``(-sin psi, cos psi)``.
    """

    target_rho: FloatArray
    yaw_rad: float

    @property
    def direction_rho(self) -> FloatArray:
        """Unit approach direction (body ``y``) in the xy plane of ``R_rho``, shape (2,)."""
        return np.array([-math.sin(self.yaw_rad), math.cos(self.yaw_rad)])


def svd_registration(
    source: FloatArray, target: FloatArray, weights: FloatArray | None = None
) -> tuple[FloatArray, FloatArray]:
    """Weighted least-squares rigid motion ``target ~ R source + t`` (eq. 3-10).

    Sorkine-Hornung and Rabinovich (2017), as the paper lists it: weighted centroids (eq. 4-5),
    centred vectors (eq. 6-7), ``S = X W Y^T`` (eq. 8), ``R = V diag(1, .., det(V U^T)) U^T``
    (eq. 9, the determinant keeps ``R`` a rotation, never a reflection, also when the points
    are collinear and ``S`` has rank 1), ``t = ybar - R xbar`` (eq. 10).

    Parameters
    ----------
    source
        Points to move, shape (N, D), N >= 1 (here the contacts in ``R_rho``).
    target
        Matching points, shape (N, D) (here the reference dots in ``R_w``).
    weights
        Strictly positive for the points that count, shape (N,); ``None`` is all ones (the
        paper's choice). Zero weights drop points.

    Returns
    -------
    R : numpy.ndarray, shape (D, D)
    t : numpy.ndarray, shape (D,)
    """
    w = np.ones(len(source)) if weights is None else np.asarray(weights, dtype=float)
    if w.sum() <= 0:
        raise InputError(f"weights: got sum {w.sum():g}, expected a positive total weight")
    xbar = w @ source / w.sum()
    ybar = w @ target / w.sum()
    X = (source - xbar).T
    Y = (target - ybar).T
    S = (X * w) @ Y.T
    U, _, Vt = np.linalg.svd(S)
    V = Vt.T
    D = np.eye(S.shape[0])
    D[-1, -1] = np.sign(np.linalg.det(V @ U.T)) or 1.0
    R = V @ D @ U.T
    return R, ybar - R @ xbar


def huber_weights(residuals: FloatArray, scale: float) -> FloatArray:
    """Huber IRLS weights ``min(1, c s / |r|)``, shape like ``residuals``."""
    r = np.abs(residuals)
    return np.minimum(1.0, HUBER_C * scale / np.maximum(r, 1e-300))


def robust_scale(residuals: FloatArray) -> float:
    """``1.4826 * median |r|``, never below :data:`SCALE_FLOOR_M`."""
    return max(1.4826 * float(np.median(np.abs(residuals))), SCALE_FLOOR_M)


def robust_weights(
    residual_fn: Callable[[FloatArray], FloatArray], n: int, iterations: int = 10
) -> FloatArray:
    """IRLS with Huber weights, then weight 0 beyond ``REJECT_SCALES`` robust scales.

    ``residual_fn(weights)`` fits with those weights and returns the residuals of all ``n``
    points, shape (n,). With fewer than 3 points nothing can be outvoted: all weights are 1.
    """
    w = np.ones(n)
    if n < 3:
        return w
    for _ in range(iterations):
        r = residual_fn(w)
        s = robust_scale(r[w > 0])
        w_new = huber_weights(r, s)
        if float(np.max(np.abs(w_new - w))) < 1e-6:
            break
        w = w_new
    r = residual_fn(w)
    s = robust_scale(r)
    keep = np.abs(r) <= max(REJECT_SCALES * s, REJECT_FLOOR_M)
    if keep.sum() < 2:  # never reject down to an undetermined fit
        return w
    return np.where(keep, huber_weights(r, s), 0.0)


def fit_wall_line(points: FloatArray, weights: FloatArray) -> tuple[float, float]:
    """Weighted total-least-squares line through contacts (N, 2) in ``R_rho``: ``(gamma, d_y)``.

    The principal direction of the weighted, centred contacts (an SVD, as eq. 8-9) is the
    wall's direction ``(cos gamma, -sin gamma)``; its normal towards the wall is
    ``(sin gamma, cos gamma)`` and the line is ``n . p + delta_y = 0``.
    """
    w = np.asarray(weights, dtype=float)
    centre = w @ points / w.sum()
    _, _, Vt = np.linalg.svd((points - centre) * np.sqrt(w)[:, None], full_matrices=False)
    u = Vt[0]
    n = np.array([-u[1], u[0]])
    if n[1] < 0:
        n = -n
    return math.atan2(n[0], n[1]), -float(n @ centre)


def ransac_line_inliers(
    points: FloatArray, *, tolerance_m: float = RANSAC_TOLERANCE_M, max_pairs: int = 300
) -> np.ndarray:
    """Indices of the points (N, 2) on the line that most of them share (RANSAC).

    Contacts on a flat wall lie on one line in ``R_rho`` whatever ``(delta, gamma)`` is, so a
    false contact (the IMU firing short of the wall) is off that line. Every pair (or
    ``max_pairs`` of them, drawn by a generator seeded with 0 so that the estimate is
    reproducible) proposes a line; the one with most points within ``tolerance_m`` wins, ties
    going to the smaller sum of squared distances. Why not Huber alone: the far first point
    of §4.1 has all the leverage while the dots are still clustered at one end, so a false
    probe drags the fit onto itself and keeps a small residual; a consensus over pairs
    out-votes it as soon as three contacts agree.
    """
    n = len(points)
    if n < 3:
        return np.arange(n)
    i, j = np.triu_indices(n, k=1)
    if i.size > max_pairs:
        pick = np.random.default_rng(0).choice(i.size, size=max_pairs, replace=False)
        i, j = i[pick], j[pick]
    d = points[j] - points[i]
    length = np.linalg.norm(d, axis=1)
    # a short pair gives a line of any slope (1 cm of noise over 5 cm is 11 deg): only pairs
    # at least RANSAC_MIN_BASELINE_M apart propose lines, unless there are none yet
    ok = length >= min(RANSAC_MIN_BASELINE_M, 0.5 * float(length.max()))
    ok &= length > 1e-6
    i, j, d, length = i[ok], j[ok], d[ok], length[ok]
    if i.size == 0:
        return np.arange(n)
    normal = np.column_stack([-d[:, 1], d[:, 0]]) / length[:, None]
    dist = np.abs((points[None, :, :] - points[i][:, None, :]) @ normal[:, :, None])[..., 0]
    inside = dist <= tolerance_m
    count = inside.sum(axis=1)
    cost = np.where(inside, dist**2, 0.0).sum(axis=1)
    best = np.lexsort((cost, -count))[0]
    return np.flatnonzero(inside[best])


class Estimator:
    """Base: the nominal placement ``prior`` and the plan it gives (no estimation)."""

    name = "none"

    def __init__(self, prior: Placement) -> None:
        self.prior = prior

    def update(self, ref_w: FloatArray, contact_rho: FloatArray) -> None:
        """Take one contact: ``ref_w`` the dot aimed at (3,), ``contact_rho`` where (3,), m."""

    def tick(self, battery: int, airborne_s: float) -> None:
        """The mission's clock before each approach: the battery (0 for the first flight,
        +1 at every landing) and the time since its take-off, s. The paper's estimators do
        not use it; one that models the localization's drift (reset at landing) does."""

    def plan(self, ref_w: FloatArray) -> Plan:
        """Target and yaw for the dot ``ref_w`` (shape (3,), m, ``R_w``)."""
        return Plan(self.prior.to_rho(ref_w), -self.prior.gamma_rad)

    @property
    def placement(self) -> Placement:
        """The current estimate ``(delta_hat, gamma_hat)``."""
        return self.prior


class NoEstimator(Estimator):
    """The paper's "without estimation": the nominal placement is never corrected."""


class RigidEstimator(Estimator):
    """Flat wall: SVD registration after each contact (eq. 3-12), optionally robust.

    Parameters
    ----------
    prior
        The nominal placement ``(delta0, gamma0)``, used while fewer than 2 contacts exist
        (paper §4.2: "For i < 2, the initial value is used").
    robust
        RANSAC over the contacts, then a Huber-weighted line fit (see ``_update_robust``)
        instead of eq. 3.
    along_wall
        ``"nominal"`` (default) keeps ``delta_x`` at the prior; ``"paper"`` takes eq. 10's
        ``x`` component as is.

    Notes
    -----
    Why ``delta_x`` stays nominal: contacts on a flat wall say nothing about a slide along it
    (every contact stays on the wall), so eq. 10's ``x`` component is set only by *where along
    the wall* the early dots happened to land -- dots painted under the nominal estimate, off
    by ``~ d tan(gamma)`` (19 cm at 10 deg). Eq. 3 pairs each of them with its reference as if
    it had landed there, and that error is then carried into every later dot (measured: RMSE
    23.7 cm against 20.2 cm without estimation at gamma = 10 deg). Rotation and depth (eq. 9
    and the ``y`` of eq. 10) are determined by the contacts and are used as the paper says.
    """

    def __init__(
        self, prior: Placement, *, robust: bool = False, along_wall: str = "nominal"
    ) -> None:
        super().__init__(prior)
        if along_wall not in ("nominal", "paper"):
            raise InputError(f"along_wall: got {along_wall!r}, expected 'nominal' or 'paper'")
        self.name = ("robust" if robust else "svd") + ("-paper" if along_wall == "paper" else "")
        self.along_wall = along_wall
        self.robust = robust
        self._refs: list[FloatArray] = []
        self._contacts: list[FloatArray] = []
        self._estimate = prior
        self.weights: FloatArray = np.zeros(0)

    def update(self, ref_w: FloatArray, contact_rho: FloatArray) -> None:
        """Add a contact and re-solve eq. 3 over all contacts so far."""
        self._refs.append(np.asarray(ref_w[:2], dtype=float))
        self._contacts.append(np.asarray(contact_rho[:2], dtype=float))
        if len(self._refs) < 2:
            return
        src, dst = np.array(self._contacts), np.array(self._refs)
        if np.ptp(src[:, 0]) < RANSAC_MIN_BASELINE_M:
            return  # contacts this close together give no angle (the reason for §4.1's probe)
        if self.robust:
            self._update_robust(src)
            return
        R, t = svd_registration(src, dst)
        self.weights = np.ones(len(src))
        x = t[0] if self.along_wall == "paper" else self.prior.delta_w[0]
        delta = np.array([x, t[1], self.prior.delta_w[2]])
        gamma = math.atan2(R[1, 0], R[0, 0])
        if abs(gamma) > MAX_GAMMA_HAT_RAD:  # degenerate early sets: keep the last sane estimate
            return
        self._estimate = Placement(delta, gamma)

    def _update_robust(self, src: FloatArray) -> None:
        """RANSAC inliers, then a Huber-weighted total-least-squares line through them.

        The robust estimator does not pair contacts with reference dots at all: a dot painted
        under a wrong estimate (after a false contact) lands far from its reference along the
        wall, and eq. 3 would read that as rotation (measured: gamma_hat = 47 deg after a false
        far first point). Contacts lie on the wall, ``sin(gamma) x + cos(gamma) y + delta_y =
        0`` in ``R_rho``, whatever dot they were meant for, so the wall line alone gives
        ``gamma`` and ``delta_y``; ``delta_x`` is unobservable and stays nominal.
        """
        inliers = ransac_line_inliers(src)
        if np.ptp(src[inliers, 0]) < RANSAC_MIN_BASELINE_M:
            return  # the agreeing contacts are too close together to give an angle
        pts = src[inliers]

        def residuals(w: FloatArray) -> FloatArray:
            gamma, delta_y = fit_wall_line(pts, w)
            out: FloatArray = pts @ [math.sin(gamma), math.cos(gamma)] + delta_y
            return out

        w_in = robust_weights(residuals, len(pts))
        gamma, delta_y = fit_wall_line(pts, w_in)
        self.weights = np.zeros(len(src))
        self.weights[inliers] = w_in
        if abs(gamma) > MAX_GAMMA_HAT_RAD:
            return
        delta = self.prior.delta_w.copy()
        delta[1] = delta_y
        self._estimate = Placement(delta, gamma)

    def plan(self, ref_w: FloatArray) -> Plan:
        """Eq. 11 (``P* = R(gamma_hat)^T (P_ref - delta_hat)``) and eq. 12 (yaw ``-gamma_hat``)."""
        est = self._estimate
        return Plan(est.to_rho(ref_w), -est.gamma_rad)

    @property
    def placement(self) -> Placement:
        """The latest ``(delta_hat, gamma_hat)``."""
        return self._estimate


@dataclass
class Line:
    """One wall segment's model ``y_rho = a x_rho + b`` and the contacts fitted (eq. 13).

    ``seed`` is a borrowed neighbour contact (the paper's ``P_{i-1}``) that only counts until
    the segment has 3 contacts of its own. ``slope0`` is a prior on the slope, one
    pseudo-observation ``a = slope0`` weighing like contacts spread over
    +-:data:`SLOPE_PRIOR_SPAN_M` (a ridge regression): the paper fits a line through the first
    two contacts, but two dots 5 cm apart with 1 cm of localization noise give a slope anywhere
    within +-20 deg, and the drone then turns away from the wall (measured: yaw references up
    to 50 deg with a stippled drawing). Once the contacts span a few decimetres the data
    dominate.
    """

    a: float
    b: float
    xs: list[float] = field(default_factory=list)
    ys: list[float] = field(default_factory=list)
    seed: tuple[float, float] | None = None
    slope0: float = 0.0

    def predict(self, x: float) -> float:
        """Wall depth ``a x + b`` at ``x``, m."""
        return self.a * x + self.b

    def span(self) -> tuple[float, float]:
        """``x`` range of the contacts of its own, m."""
        return min(self.xs), max(self.xs)

    def distance_to(self, x: float) -> float:
        """0 inside the span, else the gap to it, m."""
        lo, hi = self.span()
        return max(lo - x, x - hi, 0.0)

    def refit(self, *, robust: bool) -> None:
        """Least squares (Huber-weighted if ``robust``) over own contacts (+ seed if < 3)."""
        xs, ys = list(self.xs), list(self.ys)
        if self.seed is not None and len(xs) < 3:
            xs.append(self.seed[0])
            ys.append(self.seed[1])
        x, y = np.array(xs), np.array(ys)
        ridge = SLOPE_PRIOR_SPAN_M  # one pseudo-observation, whatever the contacts

        def fit(w: FloatArray) -> tuple[float, float]:
            A = np.column_stack([x, np.ones_like(x)]) * np.sqrt(w)[:, None]
            A = np.vstack([A, [ridge, 0.0]])
            rhs = np.append(y * np.sqrt(w), ridge * self.slope0)
            coef = np.linalg.lstsq(A, rhs, rcond=None)[0]
            return float(coef[0]), float(coef[1])

        def residuals(w: FloatArray) -> FloatArray:
            a, b = fit(w)
            out: FloatArray = y - (a * x + b)
            return out

        w = robust_weights(residuals, x.size) if robust else np.ones(x.size)
        self.a, self.b = fit(w)
        if abs(self.a) > MAX_SLOPE:  # a wall we could not face: keep the last slope's idea
            self.a = self.slope0
            self.b = float(np.average(y - self.a * x, weights=w))


class SegmentEstimator(Estimator):
    """Multi-segment wall: one line per segment in ``R_rho`` (eq. 13-15).

    Parameters
    ----------
    prior
        Nominal placement; gives ``x*`` and ``z*`` of every dot (eq. 2) and the plan until
        the first line exists (two contacts).
    eps_bar_m
        Discrepancy threshold of eq. 14, m.
    update
        ``"depth"``: eq. 15, only ``y*`` moves onto the line (no deformation along the width:
        the drawing is right seen from the front). ``"normal"``: ``P*`` is projected normally
        onto the line (the fresco case, each part drawn normal to its segment).
    robust
        Confirm a new segment by a second disagreeing contact; Huber-weighted regression.
    pair_gap_m
        The paper seeds a new line with the previous contact ``P_{i-1}``; that only makes
        sense when it is close (with the paper's row order the previous contact can be at
        the other end of the drawing). Farther than this, the new line keeps the neighbour
        segment's slope and only takes the new contact's depth.

    Notes
    -----
    Eq. 14 evaluates the line at ``x_i^{ref(rho)}``; the contact's own ``x_i^{c(rho)}`` is used
    here, since the line models contacts and the drone may touch the wall away from the
    reference abscissa. The line compared with is the one whose contacts span the nearest
    ``x`` (the paper's "current part of the facade"): with a row order the drone comes back to
    segments it already knows, and comparing with the last line used would open a new line at
    every row.
    """

    def __init__(
        self,
        prior: Placement,
        *,
        eps_bar_m: float = 0.04,
        update: UpdateMode = "depth",
        robust: bool = False,
        pair_gap_m: float = 0.5,
    ) -> None:
        super().__init__(prior)
        if update not in ("depth", "normal"):
            raise InputError(f"update: got {update!r}, expected 'depth' or 'normal'")
        self.name = "segments-robust" if robust else "segments"
        self.eps_bar = as_float("eps_bar_m", eps_bar_m, positive=True)
        self.pair_gap = as_float("pair_gap_m", pair_gap_m, positive=True)
        self.update_mode: UpdateMode = update
        self.robust = robust
        self.lines: list[Line] = []
        self._previous: tuple[float, float] | None = None
        self._pending: tuple[float, float] | None = None
        self.rejected = 0

    def _nearest(self, x: float) -> Line:
        return min(reversed(self.lines), key=lambda line: line.distance_to(x))

    def update(self, ref_w: FloatArray, contact_rho: FloatArray) -> None:
        """Eq. 14: compare with the current line; regress, or open a new line."""
        x, y = float(contact_rho[0]), float(contact_rho[1])
        previous, self._previous = self._previous, (x, y)
        if not self.lines:
            if previous is None:
                return
            slope0 = -math.tan(self.prior.gamma_rad)  # the nominal wall, seen from R_rho
            line = Line(slope0, 0.0, [previous[0], x], [previous[1], y], slope0=slope0)
            line.refit(robust=False)
            self.lines.append(line)
            return
        line = self._nearest(x)
        if abs(line.predict(x) - y) <= self.eps_bar:
            line.xs.append(x)
            line.ys.append(y)
            line.refit(robust=self.robust)
            self._pending = None
            return
        if self.robust and self._pending is None:
            self._pending = (x, y)  # one disagreeing contact may be a false one: wait
            self.rejected += 1
            return
        seed = self._pending if self.robust else previous
        self._pending = None
        self._open_line(x, y, seed, line)

    def _open_line(self, x: float, y: float, seed: tuple[float, float] | None, near: Line) -> None:
        if seed is not None and 1e-6 < abs(seed[0] - x) <= self.pair_gap:
            new = Line(near.a, near.b, [x], [y], seed, slope0=near.a)
            new.refit(robust=False)
        else:
            new = Line(near.a, y - near.a * x, [x], [y], slope0=near.a)
        self.lines.append(new)

    def plan(self, ref_w: FloatArray) -> Plan:
        """Eq. 15 (depth) or the normal projection onto the nearest line; yaw normal to it."""
        p0 = self.prior.to_rho(ref_w)
        if not self.lines:
            return Plan(p0, -self.prior.gamma_rad)
        line = self._nearest(float(p0[0]))
        yaw = math.atan(line.a)  # body y = (-a, 1)/sqrt(1 + a^2), the line's normal
        target = p0.copy()
        if self.update_mode == "depth":
            target[1] = line.predict(float(p0[0]))
        else:
            n = np.array([-line.a, 1.0]) / math.hypot(line.a, 1.0)
            beyond = (p0[1] - line.predict(float(p0[0]))) / math.hypot(line.a, 1.0)
            target[:2] = p0[:2] - beyond * n
        return Plan(target, yaw)

    @property
    def placement(self) -> Placement:
        """``(delta_hat, gamma_hat)`` read from the line in front of the take-off point.

        The wall ``y_w = 0`` seen from ``R_rho`` is ``y = -tan(gamma) x + d / cos(gamma)``
        (with ``delta = [0, -d, 0]``), so ``gamma_hat = -atan(a)`` and
        ``delta_y = -b cos(gamma_hat)``; ``delta_x`` (along the wall) is not observable from
        contacts and stays nominal.
        """
        if not self.lines:
            return self.prior
        line = self._nearest(0.0)
        gamma = -math.atan(line.a)
        delta = self.prior.delta_w.copy()
        delta[1] = -line.b * math.cos(gamma)
        return Placement(delta, gamma)


def line_params(lines: list[Line]) -> FloatArray:
    """``[[a, b, x_lo, x_hi], ...]`` of each line, shape (L, 4) (for plots and summaries)."""
    rows = [[ln.a, ln.b, *ln.span()] for ln in lines]
    return np.array(rows, dtype=float).reshape(-1, 4)


def check_points(name: str, value: object) -> FloatArray:
    """A finite (N, 2) or (N, 3) array; InputError naming ``name`` otherwise."""
    arr = as_array(name, value, ndim=2, max_abs=1e4)
    if arr.shape[1] not in (2, 3):
        raise InputError(f"{name}: got shape {arr.shape}, expected (N, 2) or (N, 3)")
    return arr
