"""The joint estimator on contacts made exactly on known walls: placement, shape, faults."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.painting.joint import JointEstimator
from skyquill.painting.wall import Placement, Wall

PRIOR = Placement(np.array([0.0, -1.1, 0.0]), 0.0)


def _contacts(wall: Wall, truth: Placement, xs: np.ndarray) -> list[np.ndarray]:
    """Where a drone placed at ``truth`` touches ``wall`` at each ``x_w``, seen in R_rho."""
    pts = np.column_stack([xs, wall.depth(xs), np.full(xs.size, 1.5)])
    return list(truth.to_rho(pts))


def _feed(est: JointEstimator, contacts: list[np.ndarray]) -> JointEstimator:
    for c in contacts:
        est.update(np.zeros(3), c)
    return est


def _spread(n: int, seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-1.75, 1.75, n)


@pytest.mark.parametrize("gamma", [-15.0, 0.0, 10.0, 25.0])
def test_flat_wall_placement_is_exact(gamma: float) -> None:
    truth = Placement(np.array([0.0, -1.3, 0.0]), math.radians(gamma))
    est = _feed(JointEstimator(PRIOR), _contacts(Wall.flat(), truth, _spread(30)))
    assert est.placement.gamma_deg == pytest.approx(gamma, abs=1e-6)
    assert est.placement.delta_w[:2] == pytest.approx([0.0, -1.3], abs=1e-6)
    assert est.fit is not None and est.fit.pieces == 1 and est.fit.fits


@pytest.mark.parametrize("angles", [(-10.0, 0.0, 10.0), (10.0, 0.0, 10.0), (-15.0, 0.0, 15.0)])
def test_segmented_wall_placement_and_pieces(angles: tuple[float, ...]) -> None:
    wall = Wall.segmented(angles, (-1.75, 1.75))
    truth = Placement(np.array([0.0, -1.1, 0.0]), math.radians(10.0))
    est = _feed(JointEstimator(PRIOR), _contacts(wall, truth, _spread(60)))
    assert est.placement.gamma_deg == pytest.approx(10.0, abs=1e-3)
    model = est.model
    assert model is not None and model.slopes.size == 3
    assert np.degrees(np.arctan(model.slopes)) == pytest.approx(list(angles), abs=0.05)
    assert model.breaks_w == pytest.approx(wall.breaks_m, abs=0.05)
    for x in (-1.5, 0.2, 1.4):  # eq. 11 with P_ref on the wall: the target is on it
        plan = est.plan(np.array([x, 0.0, 1.0]))
        hit = truth.to_w(plan.target_rho)
        assert hit[:2] == pytest.approx([x, wall.depth(np.array([x]))[0]], abs=1e-3)
        assert plan.yaw_rad == pytest.approx(-math.radians(10.0), abs=1e-5)  # eq. 12 (depth)


def test_fresco_faces_each_piece() -> None:
    wall = Wall.segmented([0.0, 20.0], (-1.0, 2.0))  # the corner at x = 0.5
    truth = Placement(np.array([0.0, -1.1, 0.0]), math.radians(-5.0))
    est = _feed(JointEstimator(PRIOR, update="normal"), _contacts(wall, truth, _spread(50)))
    plan = est.plan(np.array([1.2, 0.0, 1.0]))
    foot = wall.foot(np.array([[1.2, 0.0]]))[0]
    assert truth.to_w(plan.target_rho)[:2] == pytest.approx(foot, abs=2e-3)
    assert plan.yaw_rad == pytest.approx(math.radians(25.0), abs=math.radians(0.3))


def test_cylinder_placement_from_the_tangent_at_the_origin() -> None:
    """A curved wall cut into chords: the direction comes from the tangent at x_w = 0."""
    truth = Placement(np.array([0.0, -1.1, 0.0]), math.radians(10.0))
    est = _feed(JointEstimator(PRIOR), _contacts(Wall.cylinder(20.0), truth, _spread(80)))
    assert est.placement.gamma_deg == pytest.approx(10.0, abs=0.1)
    assert est.fit is not None and est.fit.fits and est.fit.pieces >= 2


def test_recess_fits_the_model() -> None:
    wall = Wall.recess(0.6, 1.4, 0.1)
    truth = Placement(np.array([0.0, -1.1, 0.0]), math.radians(-10.0))
    est = _feed(JointEstimator(PRIOR), _contacts(wall, truth, _spread(90)))
    assert est.placement.gamma_deg == pytest.approx(-10.0, abs=0.01)
    assert est.fit is not None and est.fit.fits
    model = est.model
    assert model is not None
    assert model.depth(1.0) == pytest.approx(0.1, abs=2e-3)  # inside the recess
    assert model.depth(-1.0) == pytest.approx(0.0, abs=2e-3)


def test_a_wall_beyond_the_model_is_reported() -> None:
    """A tight cylinder with at most two pieces allowed: the wall does not fit, and says so."""
    wall = Wall.cylinder(3.0, x_range_m=(-2.0, 2.0))
    est = _feed(JointEstimator(PRIOR, max_pieces=2), _contacts(wall, PRIOR, _spread(60)))
    assert est.fit is not None and not est.fit.fits
    assert est.fit.residual_m > est.fit.tolerance_m


def test_false_contacts_short_of_the_wall_are_dropped() -> None:
    wall = Wall.segmented([-10.0, 0.0, 10.0], (-1.75, 1.75))
    truth = Placement(np.array([0.0, -1.1, 0.0]), math.radians(10.0))
    contacts = _contacts(wall, truth, _spread(70, seed=3))
    rng = np.random.default_rng(4)
    false = sorted(rng.choice(np.arange(6, 70), 7, replace=False).tolist())
    for k in false:  # short along the approach (R_rho's y)
        contacts[k] = contacts[k] - np.array([0.0, rng.uniform(0.05, 0.5), 0.0])
    est = _feed(JointEstimator(PRIOR), contacts)
    assert est.placement.gamma_deg == pytest.approx(10.0, abs=0.05)
    assert np.flatnonzero(~est.kept).tolist() == false


def test_first_estimate_waits_for_four_contacts() -> None:
    truth = Placement(np.array([0.0, -1.1, 0.0]), math.radians(10.0))
    est = JointEstimator(PRIOR)
    for c in _contacts(Wall.flat(), truth, np.array([-1.5, 1.5, 0.0])):
        est.update(np.zeros(3), c)
    assert est.placement is PRIOR and est.model is None


def test_drift_is_fitted_and_reset_at_landing() -> None:
    """Contacts with a known drift: the drift estimate follows it; a new flight starts at 0."""
    rng = np.random.default_rng(5)
    truth = Placement(np.array([0.0, -1.1, 0.0]), math.radians(10.0))
    est = JointEstimator(PRIOR, noise_m=0.001, drift_m_per_sqrt_s=0.004)
    xs = np.concatenate([np.linspace(-1.75, 1.75, 15), rng.uniform(-1.75, 1.75, 45)])
    times = np.linspace(2.0, 400.0, xs.size)
    walk = np.cumsum(rng.normal(0, 0.004 * np.sqrt(np.diff(times, prepend=0.0))))
    for x, t, d in zip(xs, times, walk, strict=True):
        c = _contacts(Wall.flat(), truth, np.array([x]))[0] + np.array([0.0, d, 0.0])
        est.tick(0, float(t))
        est.update(np.zeros(3), c)
    assert est.placement.gamma_deg == pytest.approx(10.0, abs=0.5)
    assert est.drift_now() == pytest.approx(walk[-1], abs=0.01)
    est.tick(1, 0.0)  # landed: the localization was reset
    assert est.drift_now() == 0.0


def test_bad_arguments() -> None:
    with pytest.raises(InputError, match=r"update: got 'sideways', expected 'depth' or 'normal'"):
        JointEstimator(PRIOR, update="sideways")  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"max_pieces"):
        JointEstimator(PRIOR, max_pieces=0)
    with pytest.raises(InputError, match=r"drift_m_per_sqrt_s"):
        JointEstimator(PRIOR, drift_m_per_sqrt_s=-1.0)


@settings(max_examples=25, deadline=None)
@given(
    angles=st.lists(st.sampled_from([-20.0, -10.0, 0.0, 10.0, 20.0]), min_size=1, max_size=4),
    n=st.integers(1, 50),
    seed=st.integers(0, 2**31),
    noise=st.floats(0.0, 0.05),
    false_rate=st.floats(0.0, 0.3),
    drift=st.sampled_from([0.0, 0.004]),
)
def test_any_contacts_give_plans_that_face_the_wall(
    angles: list[float], n: int, seed: int, *, noise: float, false_rate: float, drift: float
) -> None:
    rng = np.random.default_rng(seed)
    wall = Wall.segmented(angles, (-2.0, 2.0))
    truth = Placement(np.array([0.0, -1.1, 0.0]), math.radians(rng.uniform(-20, 20)))
    est = JointEstimator(PRIOR, noise_m=noise, drift_m_per_sqrt_s=drift)
    for k, exact in enumerate(_contacts(wall, truth, rng.uniform(-2, 2, n))):
        c = exact + rng.normal(0, noise + 1e-9, 3)
        if rng.random() < false_rate:
            c[1] -= rng.uniform(0.05, 0.6)
        est.tick(0, 5.0 * k)
        est.update(np.zeros(3), c)
        plan = est.plan(np.array([rng.uniform(-2, 2), 0.0, 1.0]))
        assert np.all(np.isfinite(plan.target_rho))
        assert abs(plan.yaw_rad) < math.pi / 2
    assert abs(est.placement.gamma_rad) <= math.radians(60.0) + 1e-12
