"""Placement and wall shape estimated together from every contact so far (beyond paper 002).

The model
---------
The wall, seen from above in the wall frame ``R_w``, is ``K`` plane pieces ``y_w = t_k x_w +
e_k`` side by side (``K`` and the breaks unknown; the flat wall is ``K = 1``). The wall in front
of the take-off point -- at ``x_w = 0`` -- *is* the wall frame's reference: there it runs along
``x_w`` through the origin, as on the paper's walls (Fig. 13: the middle segment is 0 deg). A
contact ``c`` measured in the onboard frame ``R_rho`` lies on the wall: ``p = R(gamma) c +
delta`` (eq. 1) satisfies ``p_y = t_k p_x + e_k`` for its piece. The unknowns are the placement
``(gamma, delta_y)`` and the pieces ``(t_k, e_k)``, tied by that reference.

Seen from ``R_rho`` the same model is ``K`` lines ``y = a_k x + b_k`` with no constraint (the
wall's shape and the placement together are exactly a wall in ``R_rho``: the reference only
says which rotation and shift of it is the wall frame). In that form it is linear, so it is
fitted there, to *all* contacts at once, by robust least squares (``scipy.optimize.
least_squares``, soft-L1 loss, its scale the contacts' own robust scale); the placement is then
read off the fitted wall at ``x_w = 0`` (:func:`read_placement`), and every piece is known in
the wall frame through it. When the piece at ``x_w = 0`` is a plane reaching 0.5 m on both
sides, the placement is that piece's line (all its contacts: the most precise). When it is not
-- a curved wall cut into chords, a narrow piece -- the direction at ``x_w = 0`` comes from a
quadratic fitted to the contacts around it (measured on a 20 m cylinder: the chord holding
``x_w = 0`` alone is off-centre by up to half a piece, 1.1 deg, 2 cm of aim error).

``delta_x`` (a slide along the wall) is not observable from contacts, whatever the wall: any
slide is absorbed by moving the unknown breaks. It stays at the operator's nominal value, as in
:class:`~skyquill.painting.estimate.RigidEstimator`. Contacts are *not* paired with the dots
they were aimed at (eq. 3 pairs them): a dot painted under a wrong estimate lands away from its
reference along the wall, and pairing would read that as rotation; a contact says where the
wall is, nothing more.

How many pieces and where they break is chosen before the least squares: the contacts, sorted
along the wall, are cut into ``K`` runs by dynamic programming and ``K`` by the Bayesian
information criterion (:mod:`skyquill.painting.segmentation`, which says why not RANSAC).
False contacts (the IMU firing short of the wall) are dropped by a local test before the cut
(:func:`~skyquill.painting.segmentation.screen`), weighed down by the soft-L1 loss, and dropped
when they are short of the fitted wall by more than ``3.5`` robust scales (at least 3 cm); the
cut and the fit are then repeated without them. The test is one-sided because the fault is: a
contact is never measured beyond the wall, so one beyond the model says the model is wrong and
is kept to correct it (a piece fitted to false contacts would otherwise discard the real ones
behind it). Missed contacts simply add nothing. With onboard localization every contact is
off by the drift since the last take-off; the fit marginalises it as the random walk it is
(:mod:`skyquill.painting.robust_fit`), and the plan adds the drift of the latest contact of the
current flight to the target's depth (the wall as the drone now sees it).

Where this departs from the paper
---------------------------------
* eq. 3-10 (rigid SVD registration of contacts onto references) and eq. 14 (a greedy test of
  each contact against the last line, a new line through two contacts when it fails) are
  replaced by the fit above: all contacts are re-cut and re-fitted after every contact, so an
  early wrong cut is undone as soon as the contacts say so, and the placement is corrected on
  walls of several pieces too (the paper's segment model never corrects it).
* eq. 11 holds, with ``P_ref`` on the estimated wall: ``P* = R(gamma)^T (P_ref - delta)``,
  ``P_ref = (x, t_k x + e_k, z)`` (the paper's eq. 15 moves ``y`` onto the wall the same way).
* eq. 12 (yaw ``-gamma``: the tool along the wall frame's ``y``) holds for the front-view
  drawing (``update="depth"``) on every piece, also on the paper's segmented walls where §5.2
  turns the drone normal to the piece instead: approaching along the viewing direction, an
  error in the estimated depth of the wall moves the dot in depth only, not across the
  drawing. For the fresco (``update="normal"``) the drone faces each piece, as §5.2 says.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from skyquill.errors import InputError
from skyquill.painting.estimate import MAX_GAMMA_HAT_RAD, Estimator, Plan, UpdateMode
from skyquill.painting.robust_fit import DriftModel, LineFit, fit_lines
from skyquill.painting.segmentation import Pieces, Splits, fit_pieces, screen
from skyquill.painting.wall import Placement, rot2
from skyquill.validation import FloatArray, as_float, as_int

#: Contacts spread over less than this along the wall give no direction yet, m.
MIN_BASELINE_M = 0.3
#: Fewest contacts the first estimate is made from: with two or three, one false contact
#: decides the line (measured: a 48 deg estimate from the first two probes, one false), with
#: four the robust fit out-votes it. (The paper starts at two, eq. 3 for i >= 2.)
MIN_CONTACTS = 4
#: Residuals beyond this many robust scales (and beyond ``REJECT_FLOOR_M``) are outliers.
REJECT_SCALES = 3.5
REJECT_FLOOR_M = 0.03
#: Below this many contacts the fit is redone after every contact; above, each time the
#: count has grown by ``REFIT_GROWTH`` (a mural of 10,000 dots refits ~200 times, not 10,000).
REFIT_EVERY_UNTIL = 200
REFIT_GROWTH = 1.02


@dataclass(frozen=True)
class WallFit:
    """How well the piecewise-planar model explains the contacts.

    Attributes
    ----------
    pieces
        Number of plane pieces chosen.
    residual_m
        Root mean square distance (along the drone's forward axis at take-off) of the kept
        contacts from the model, m.
    outliers
        Contacts dropped as false.
    contacts
        Contacts fitted (kept and dropped).
    tolerance_m
        What ``residual_m`` may be for the wall to fit the model, m.
    fits
        ``residual_m <= tolerance_m``, fewer pieces than the most allowed, and at most a
        quarter of the contacts dropped.
    """

    pieces: int
    residual_m: float
    outliers: int
    contacts: int
    tolerance_m: float
    fits: bool

    def summary(self) -> dict[str, object]:
        """The JSON-able form."""
        return {
            "pieces": self.pieces,
            "residual_m": self.residual_m,
            "outliers": self.outliers,
            "contacts": self.contacts,
            "tolerance_m": self.tolerance_m,
            "fits": self.fits,
        }


@dataclass(frozen=True)
class WallModel:
    """The estimated wall in ``R_w``: pieces ``y = t_k x + e_k`` split at ``breaks_w``.

    Attributes
    ----------
    slopes, offsets
        ``t_k`` and ``e_k``, shape (K,).
    breaks_w
        ``x_w`` where each piece ends, shape (K - 1,), m.
    reference
        Index of the piece holding ``x_w = 0``.
    """

    slopes: FloatArray
    offsets: FloatArray
    breaks_w: FloatArray
    reference: int

    def piece_of(self, x_w: float) -> int:
        """Piece under ``x_w`` (the end pieces extend beyond the contacts)."""
        return int(np.searchsorted(self.breaks_w, x_w, side="right"))

    def depth(self, x_w: float) -> float:
        """``y_w`` of the estimated wall at ``x_w``, m."""
        k = self.piece_of(x_w)
        return float(self.slopes[k] * x_w + self.offsets[k])


class JointEstimator(Estimator):
    """Placement and piecewise-planar wall by one robust least-squares fit (module notes).

    Parameters
    ----------
    prior
        The nominal placement: the plan until the contacts span :data:`MIN_BASELINE_M`, and
        ``delta_x`` / ``delta_z`` forever (they are not observable).
    update
        ``"depth"`` (the drawing right seen from the front, eq. 15) or ``"normal"`` (fresco).
    max_pieces
        Most plane pieces the wall may have.
    tolerance_m
        Residual up to which the wall is said to fit the model, m.
    noise_floor_m
        Contact noise below which more pieces are never worth it (the criterion's floor), m.
    noise_m, drift_m_per_sqrt_s
        The localization's specification: white noise per coordinate, m, and drift rate (a
        random walk reset at every landing), m / sqrt(s). With a drift rate each contact's
        drift is fitted with the wall (:mod:`skyquill.painting.robust_fit`).
    """

    name = "joint"

    def __init__(
        self,
        prior: Placement,
        *,
        update: UpdateMode = "depth",
        max_pieces: int = 8,
        tolerance_m: float = 0.03,
        noise_floor_m: float = 0.002,
        noise_m: float = 0.0,
        drift_m_per_sqrt_s: float = 0.0,
    ) -> None:
        super().__init__(prior)
        if update not in ("depth", "normal"):
            raise InputError(f"update: got {update!r}, expected 'depth' or 'normal'")
        self.update_mode: UpdateMode = update
        self.max_pieces = as_int("max_pieces", max_pieces, low=1, high=32)
        self.tolerance = as_float("tolerance_m", tolerance_m, positive=True)
        self.noise_floor = as_float("noise_floor_m", noise_floor_m, positive=True)
        self.noise = math.hypot(as_float("noise_m", noise_m, nonneg=True), self.noise_floor)
        self.drift_rate = as_float("drift_m_per_sqrt_s", drift_m_per_sqrt_s, nonneg=True)
        self._contacts: list[FloatArray] = []
        self._battery: list[int] = []
        self._airborne: list[float] = []
        self._clock = (0, 0.0)
        self._drift = np.zeros(0)
        self._estimate = prior
        self._model: WallModel | None = None
        self._pieces: Pieces | None = None
        self._kept = np.zeros(0, dtype=bool)
        self._fitted_at = 0
        self.fit: WallFit | None = None

    # -- the estimate -------------------------------------------------------------------------

    def tick(self, battery: int, airborne_s: float) -> None:
        """Keep the mission's clock: contacts are stamped with it, plans use its drift."""
        self._clock = (int(battery), float(airborne_s))

    def update(self, ref_w: FloatArray, contact_rho: FloatArray) -> None:
        """Add a contact (``ref_w`` is not used: contacts are not paired) and refit."""
        del ref_w
        self._contacts.append(np.asarray(contact_rho[:2], dtype=float))
        self._battery.append(self._clock[0])
        self._airborne.append(self._clock[1])
        n = len(self._contacts)
        if n > REFIT_EVERY_UNTIL and n < self._fitted_at * REFIT_GROWTH:
            return
        pts = np.array(self._contacts)
        if n < MIN_CONTACTS or np.ptp(pts[:, 0]) < MIN_BASELINE_M:
            return  # too few, or too close together, to give a direction
        self._refit(pts)
        self._fitted_at = n

    def _refit(self, pts: FloatArray) -> None:
        """Cut, fit, drop outliers, and again while the outliers change (at most 3 times)."""
        x, y = pts[:, 0], pts[:, 1]
        drift = DriftModel(np.array(self._battery), np.array(self._airborne), self.drift_rate)
        d = np.concatenate([self._drift, np.zeros(x.size - self._drift.size)])
        keep = screen(x, y - d)
        if np.ptp(x[keep]) < MIN_BASELINE_M:
            keep = np.ones(x.size, dtype=bool)
        for _ in range(3):
            fit = self._select(x, y, keep, d, drift)
            pieces, d, scale = fit.pieces, fit.drift, fit.scale
            residual = y - d - pieces.predict(x)
            # one-sided: a false contact is short of the wall, no contact is beyond it (one
            # beyond the model says the model is wrong, and is kept to correct it)
            new_keep = residual >= -max(REJECT_SCALES * scale, REJECT_FLOOR_M)
            if np.array_equal(new_keep, keep) or np.ptp(x[new_keep]) < MIN_BASELINE_M:
                break
            keep = new_keep
        straight = max(REJECT_SCALES * scale, 2.0 * self.noise_floor)
        corrected = np.column_stack([x, y - d])[keep]
        estimate = read_placement(pieces, self._estimate, corrected, straight)
        if estimate is None or abs(estimate.gamma_rad) > MAX_GAMMA_HAT_RAD:
            return  # not said yet, or degenerate: keep the last estimate
        self._estimate, self._pieces, self._kept, self._drift = estimate, pieces, keep, d
        self._model = wall_in_w(pieces, estimate)
        self.fit = self._wall_fit(pieces, keep, residual)

    def _select(
        self, x: FloatArray, y: FloatArray, keep: np.ndarray, d: FloatArray, drift: DriftModel
    ) -> LineFit:
        """The pieces and lines that explain the kept contacts best.

        Without drift: the BIC-best cut (:func:`fit_pieces`), its lines fitted robustly. With
        drift, a cut seen in the contacts as measured may be drift, and one seen after the
        last fit's drift was removed may have had a corner taken for drift; so the best cuts
        of both, with one piece fewer and one more, are each fitted with the drift
        marginalised and compared by the information criterion on that likelihood
        (:func:`~skyquill.painting.robust_fit.fit_lines`), not on residuals after the drift.
        """
        xk = x[keep]
        if self.drift_rate == 0.0:
            pieces = fit_pieces(xk, y[keep], max_pieces=self.max_pieces, noise_floor_m=self.noise)
            return fit_lines(x, y, keep, [pieces], noise_m=self.noise, drift=drift)
        spread = math.hypot(self.noise, self.drift_rate * math.sqrt(float(drift.airborne_s.mean())))
        seen: dict[tuple[int, ...], Pieces] = {}
        sources = [(y, spread)] + ([(y - d, self.noise)] if np.any(d != 0.0) else [])
        for data, floor in sources:
            splits = Splits(xk, data[keep], max_pieces=self.max_pieces, noise_floor_m=floor)
            for k in range(max(splits.best - 1, 1), min(splits.best + 1, splits.most) + 1):
                pieces = splits.pieces(k)
                seen.setdefault(tuple(np.round(pieces.breaks, 3)), pieces)
        return fit_lines(x, y, keep, list(seen.values()), noise_m=self.noise, drift=drift)

    def _wall_fit(self, pieces: Pieces, keep: np.ndarray, residual: FloatArray) -> WallFit:
        """How well the model explains the contacts (residuals along ``R_rho``'s ``y``)."""
        rms = float(np.sqrt(np.mean(residual[keep] ** 2)))
        n_out = int((~keep).sum())
        return WallFit(
            pieces=pieces.n_pieces,
            residual_m=rms,
            outliers=n_out,
            contacts=int(keep.size),
            tolerance_m=self.tolerance,
            fits=bool(
                rms <= self.tolerance
                and (pieces.n_pieces < self.max_pieces or self.max_pieces == 1)
                and n_out <= 0.25 * keep.size
            ),
        )

    # -- the plan -----------------------------------------------------------------------------

    def plan(self, ref_w: FloatArray) -> Plan:
        """Eq. 11 with ``P_ref`` on the estimated wall; eq. 12's yaw (depth) or the piece's normal.

        ``ref_w`` is the dot on the nominal wall, ``(x_w, 0, z_w)``.
        """
        est, model = self._estimate, self._model
        if model is None:
            return Plan(est.to_rho(ref_w), -est.gamma_rad)
        x, z = float(ref_w[0]), float(ref_w[2])
        k = model.piece_of(x)
        t, e = float(model.slopes[k]), float(model.offsets[k])
        shift = np.array([0.0, self.drift_now(), 0.0])  # the wall as the drone sees it now
        if self.update_mode == "depth":
            target_w = np.array([x, t * x + e, z])
            return Plan(est.to_rho(target_w) + shift, -est.gamma_rad)
        u = np.array([1.0, t]) / math.hypot(1.0, t)
        anchor = np.array([0.0, e])
        foot = anchor + ((np.array([x, 0.0]) - anchor) @ u) * u
        target = est.to_rho(np.array([foot[0], foot[1], z])) + shift
        return Plan(target, math.atan(t) - est.gamma_rad)

    def drift_now(self) -> float:
        """The drift of this flight's latest fitted contact (a random walk's best guess of
        the drift now), m; 0 before a contact of this flight (the localization was reset)."""
        n = self._drift.size
        if n == 0:
            return 0.0
        same = np.flatnonzero(np.array(self._battery[:n]) == self._clock[0])
        return float(self._drift[same[-1]]) if same.size else 0.0

    @property
    def placement(self) -> Placement:
        """The latest ``(delta_hat, gamma_hat)``."""
        return self._estimate

    @property
    def model(self) -> WallModel | None:
        """The latest wall model (None until the contacts span :data:`MIN_BASELINE_M`)."""
        return self._model

    @property
    def kept(self) -> np.ndarray:
        """Mask of the contacts the latest fit kept, shape (n_fitted,)."""
        return self._kept

    def lines_rho(self) -> FloatArray:
        """``[[a, b, x_lo, x_hi], ...]`` of each piece in ``R_rho`` (for plots)."""
        if self._pieces is None:
            return np.zeros((0, 4))
        p = self._pieces
        return np.column_stack([p.slopes, p.intercepts, p.x_lo, p.x_hi])


def read_placement(
    pieces: Pieces, previous: Placement, contacts: FloatArray, straight_m: float
) -> Placement | None:
    """``(gamma, delta)`` that make the fitted wall run along ``x_w`` through ``x_w = 0``.

    The piece under the previous estimate's ``x_w = 0`` gives ``gamma = -atan(a)`` and
    ``delta_y = -b cos(gamma)`` (the flat wall ``y_w = 0`` seen from ``R_rho`` is ``y =
    -tan(gamma) x - delta_y / cos(gamma)``); it is found again under the new estimate until it
    stays the same. That is the answer when the piece reaches :data:`GAUGE_HALF_WIDTH_M` on
    both sides of ``x_w = 0`` and its own contacts show no curvature (a quadratic's square
    term within three standard errors of 0). Otherwise -- a curved wall cut into chords, whose
    chord at ``x_w = 0`` is off-centre, or a narrow piece -- the direction and depth at
    ``x_w = 0`` come from a quadratic fitted to the ``contacts`` (N, 2, ``R_rho``) over the
    widest window ``|x_w| <= h`` (at most :data:`LOCAL_HALF_WIDTH_M`) on which it stays within
    ``straight_m`` of them (:func:`_local_tangent`); when too few contacts are near
    ``x_w = 0`` for that yet, None: the contacts do not say the direction there (measured
    onboard: a piece of three drifted contacts at ``x_w = 0`` turned the estimate by 16 deg
    for one dot, 34 cm of aim error). ``delta_x`` stays at the previous (nominal) value.
    """
    estimate, k = previous, _piece_at_origin(pieces, previous)
    for _ in range(3):
        gamma = -math.atan(float(pieces.slopes[k]))
        delta = previous.delta_w.copy()
        delta[1] = -float(pieces.intercepts[k]) * math.cos(gamma)
        estimate = Placement(delta, gamma)
        moved = _piece_at_origin(pieces, estimate)
        if moved == k:
            break
        k = moved
    own = contacts[pieces.piece_of(contacts[:, 0]) == k]
    if _reaches(pieces, k, estimate) and not _curved(own @ rot2(estimate.gamma_rad).T):
        return estimate
    for attempt in range(3):
        w = contacts @ rot2(estimate.gamma_rad).T + estimate.delta_w[:2]
        tangent = _local_tangent(w, straight_m)
        if tangent is None:
            return None if attempt == 0 else estimate
        turn, depth = tangent
        delta = estimate.delta_w.copy()
        delta[1] -= depth
        estimate = Placement(delta, estimate.gamma_rad - turn)
        if abs(turn) < 1e-10:
            break
    return estimate


def _curved(points: FloatArray) -> bool:
    """Whether a quadratic through ``points`` (N, 2) bends significantly: its square term
    beyond three standard errors (needs six points; fewer never count as curved)."""
    if len(points) < 6:
        return False
    x, y = points[:, 0] - points[:, 0].mean(), points[:, 1]
    design = np.column_stack([np.ones_like(x), x, x * x])
    coef, rss, rank, _ = np.linalg.lstsq(design, y, rcond=None)
    if rank < 3:
        return False
    dof = len(points) - 3
    sigma2 = float(rss[0]) / dof if rss.size else 0.0
    var = sigma2 * float(np.linalg.inv(design.T @ design)[2, 2])
    return bool(abs(float(coef[2])) > 3.0 * math.sqrt(max(var, 1e-30)))


def _piece_at_origin(pieces: Pieces, estimate: Placement) -> int:
    """The piece under the wall frame's origin seen from ``R_rho`` (``R^T (0 - delta)``)."""
    return int(pieces.piece_of(np.array([estimate.to_rho(np.zeros(3))[0]]))[0])


#: The piece at ``x_w = 0`` gives the wall frame's direction if it reaches this far on both
#: sides, m.
GAUGE_HALF_WIDTH_M = 0.5
#: Widest half-window of the quadratic that gives it otherwise, m: wide enough to average the
#: onboard localization's noise (the slope's error falls as the window's width to the 1.5).
LOCAL_HALF_WIDTH_M = 1.0


def _reaches(pieces: Pieces, k: int, estimate: Placement) -> bool:
    """Whether piece ``k`` spans ``|x_w| <= GAUGE_HALF_WIDTH_M`` under ``estimate``."""
    breaks = _breaks_w(pieces, estimate)
    left = breaks[k - 1] if k > 0 else -math.inf
    right = breaks[k] if k < breaks.size else math.inf
    return bool(left <= -GAUGE_HALF_WIDTH_M and right >= GAUGE_HALF_WIDTH_M)


def _local_tangent(w: FloatArray, straight_m: float) -> tuple[float, float] | None:
    """Direction (rad) and depth (m) at ``x_w = 0`` of a quadratic through the contacts ``w``
    (N, 2, ``R_w``) near it: the widest window ``|x_w| <= h`` (h from the half-width down to
    10 cm) with six contacts or more on both sides of 0 whose quadratic misses none of them by
    more than ``straight_m``. A quadratic, not a line: a window not centred on the contacts
    would tilt a line by the wall's curvature. None when no window qualifies."""
    for h in np.arange(LOCAL_HALF_WIDTH_M, 0.1 - 1e-9, -0.05):
        sel = np.abs(w[:, 0]) <= h
        x, y = w[sel, 0], w[sel, 1]
        if x.size < 6 or x.min() > -0.3 * h or x.max() < 0.3 * h:
            continue
        design = np.column_stack([np.ones_like(x), x, x * x])
        coef = np.linalg.lstsq(design, y, rcond=None)[0]
        if float(np.max(np.abs(design @ coef - y))) <= straight_m:
            return math.atan(float(coef[1])), float(coef[0])
    return None


def wall_in_w(pieces: Pieces, estimate: Placement) -> WallModel:
    """The fitted pieces seen in ``R_w`` under ``estimate``."""
    slopes = np.empty(pieces.n_pieces)
    offsets = np.empty(pieces.n_pieces)
    for k in range(pieces.n_pieces):
        slopes[k], offsets[k] = _line_in_w(pieces, k, estimate)
    breaks = _breaks_w(pieces, estimate)
    reference = int(np.searchsorted(breaks, 0.0, side="right"))
    return WallModel(slopes, offsets, breaks, reference)


def _line_in_w(pieces: Pieces, k: int, estimate: Placement) -> tuple[float, float]:
    """Piece ``k``'s ``R_rho`` line seen in ``R_w`` under ``estimate``: ``(t, e)``."""
    xs = np.array([pieces.x_lo[k], pieces.x_hi[k] + 1.0])
    rho = np.column_stack([xs, pieces.slopes[k] * xs + pieces.intercepts[k], np.zeros(2)])
    w = estimate.to_w(rho)
    t = float((w[1, 1] - w[0, 1]) / (w[1, 0] - w[0, 0]))
    return t, float(w[0, 1] - t * w[0, 0])


def _breaks_w(pieces: Pieces, estimate: Placement) -> FloatArray:
    """The pieces' breaks (``R_rho``) as ``x_w``, the mean over the two lines at a step."""
    out = np.empty(pieces.breaks.size)
    for k, xb in enumerate(pieces.breaks):
        ys = [pieces.slopes[j] * xb + pieces.intercepts[j] for j in (k, k + 1)]
        w = estimate.to_w(np.array([[xb, ys[0], 0.0], [xb, ys[1], 0.0]]))
        out[k] = float(w[:, 0].mean())
    return np.maximum.accumulate(out)
