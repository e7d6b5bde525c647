"""Estimators: SVD registration against independent solves, robust variants, line models."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.linalg import orthogonal_procrustes
from scipy.spatial.transform import Rotation

from skyquill.errors import InputError
from skyquill.painting.estimate import (
    RigidEstimator,
    SegmentEstimator,
    ransac_line_inliers,
    svd_registration,
)
from skyquill.painting.wall import Placement, Wall, rot2

PRIOR = Placement(np.array([0.0, -1.1, 0.0]), 0.0)


def test_svd_matches_orthogonal_procrustes_on_random_data() -> None:
    rng = np.random.default_rng(1)
    for _ in range(20):
        src = rng.normal(size=(15, 2))
        dst = rng.normal(size=(15, 2))  # no exact transform: a true least-squares problem
        R, t = svd_registration(src, dst)
        # orthogonal_procrustes: min || A Omega - B ||, A, B centred; R = Omega^T
        omega, _ = orthogonal_procrustes(src - src.mean(0), dst - dst.mean(0))
        if np.linalg.det(omega) > 0:  # procrustes may return a reflection; ours never does
            assert np.allclose(R, omega.T, atol=1e-10)
        assert np.linalg.det(R) == pytest.approx(1.0)
        assert np.allclose(t, dst.mean(0) - R @ src.mean(0))


def test_weighted_svd_matches_align_vectors() -> None:
    rng = np.random.default_rng(2)
    src = rng.normal(size=(12, 2))
    dst = src @ rot2(0.4).T + rng.normal(scale=0.1, size=(12, 2)) + [0.3, -1.0]
    w = rng.uniform(0.1, 2.0, 12)
    R, t = svd_registration(src, dst, w)
    xbar, ybar = w @ src / w.sum(), w @ dst / w.sum()
    a = np.column_stack([dst - ybar, np.zeros(12)])
    b = np.column_stack([src - xbar, np.zeros(12)])
    rot, _ = Rotation.align_vectors(a, b, weights=w)  # rotates b onto a, weighted
    assert np.allclose(R, rot.as_matrix()[:2, :2], atol=1e-9)
    assert np.allclose(t, ybar - R @ xbar)


@settings(max_examples=60, deadline=None)
@given(
    gamma=st.floats(-60, 60),
    tx=st.floats(-3, 3),
    ty=st.floats(-3, 3),
    n=st.integers(2, 30),
    seed=st.integers(0, 2**31),
    collinear=st.booleans(),
)
def test_svd_recovers_an_exact_rigid_motion(
    gamma: float, tx: float, ty: float, n: int, *, seed: int, collinear: bool
) -> None:
    rng = np.random.default_rng(seed)
    dst = rng.uniform(-2, 2, size=(n, 2))
    if collinear:  # the paper's case: every reference dot on the wall line y_w = 0
        dst[:, 1] = 0.0
    if np.ptp(dst[:, 0]) < 0.05:
        dst[0, 0] += 0.5
    R_true = rot2(math.radians(gamma))
    src = (dst - [tx, ty]) @ R_true  # src = R^T (dst - t)
    R, t = svd_registration(src, dst)
    assert np.allclose(R, R_true, atol=1e-7)
    assert np.allclose(t, [tx, ty], atol=1e-7)


def test_svd_refuses_zero_weights() -> None:
    with pytest.raises(InputError, match=r"weights: got sum 0, expected a positive total"):
        svd_registration(np.zeros((2, 2)), np.zeros((2, 2)), np.zeros(2))


def _contacts(gamma_deg: float, xs: np.ndarray, z: float = 1.5) -> tuple[Placement, list]:
    truth = Placement(np.array([0.0, -1.1, 0.0]), math.radians(gamma_deg))
    refs = [np.array([x, 0.0, z]) for x in xs]
    return truth, [(r, truth.to_rho(r)) for r in refs]


def test_rigid_estimator_recovers_gamma_and_depth() -> None:
    truth, pairs = _contacts(12.0, np.linspace(-1.5, 1.5, 8))
    est = RigidEstimator(PRIOR)
    est.update(*pairs[0])
    assert est.placement is PRIOR  # one contact: the prior (paper: i < 2)
    for pair in pairs[1:]:
        est.update(*pair)
    assert est.placement.gamma_deg == pytest.approx(12.0, abs=1e-9)
    assert est.placement.delta_w == pytest.approx(truth.delta_w, abs=1e-9)
    plan = est.plan(np.array([0.7, 0.0, 1.0]))
    assert plan.yaw_rad == pytest.approx(-math.radians(12.0))  # eq. 12
    assert np.allclose(truth.to_w(plan.target_rho), [0.7, 0.0, 1.0])  # eq. 11


def test_robust_rejects_false_contacts_that_fool_svd() -> None:
    _, pairs = _contacts(10.0, np.linspace(-1.5, 1.5, 20))
    rng = np.random.default_rng(3)
    bad = {0, 7, 13}  # the far probe among them
    plain, robust = RigidEstimator(PRIOR), RigidEstimator(PRIOR, robust=True)
    for k, (ref, contact) in enumerate(pairs):
        c = contact.copy()
        if k in bad:  # a false contact: short of the wall along the approach
            c[1] -= rng.uniform(0.15, 0.4)
        plain.update(ref, c)
        robust.update(ref, c)
    assert abs(robust.placement.gamma_deg - 10.0) < 1e-6
    assert abs(plain.placement.gamma_deg - 10.0) > 0.3
    assert np.count_nonzero(robust.weights == 0) == len(bad)


def test_ransac_finds_the_line() -> None:
    pts = np.column_stack([np.linspace(0, 2, 10), 0.2 * np.linspace(0, 2, 10) + 1.0])
    pts[[2, 5], 1] -= 0.3
    assert ransac_line_inliers(pts).tolist() == [0, 1, 3, 4, 6, 7, 8, 9]


def _segment_contacts(wall: Wall, truth: Placement, xs: np.ndarray) -> list:
    return [
        (np.array([x, 0.0, 1.0]), truth.to_rho(np.array([x, wall.depth(np.array([x]))[0], 1.0])))
        for x in xs
    ]


def test_segment_estimator_finds_three_lines() -> None:
    wall = Wall.segmented([-10, 0, 10], (-1.5, 1.5))
    truth = Placement(np.array([0.0, -1.1, 0.0]), 0.0)
    est = SegmentEstimator(PRIOR, eps_bar_m=0.02)
    for ref, c in _segment_contacts(wall, truth, np.linspace(1.5, -1.5, 31)):  # right to left
        est.update(ref, c)
    slopes = sorted(math.degrees(math.atan(line.a)) for line in est.lines)
    assert slopes[0] == pytest.approx(-10, abs=0.5) and slopes[-1] == pytest.approx(10, abs=0.5)
    assert min(abs(s) for s in slopes) < 1.0
    for x in (-1.2, 0.1, 1.3):  # eq. 15: the depth of the next dot is on the wall
        plan = est.plan(np.array([x, 0.0, 1.0]))
        assert truth.to_w(plan.target_rho)[1] == pytest.approx(
            wall.depth(np.array([x]))[0], abs=2e-3
        )


def test_segment_normal_update_projects_normally() -> None:
    wall = Wall.segmented([0, 20], (-1.0, 1.0))
    truth = Placement(np.array([0.0, -1.1, 0.0]), 0.0)
    est = SegmentEstimator(PRIOR, update="normal")
    for ref, c in _segment_contacts(wall, truth, np.linspace(0.3, 1.0, 8)):
        est.update(ref, c)
    plan = est.plan(np.array([0.6, 0.0, 1.0]))
    foot = wall.foot(np.array([[0.6, 0.0]]))[0]
    assert truth.to_w(plan.target_rho)[:2] == pytest.approx(foot, abs=2e-3)
    assert plan.yaw_rad == pytest.approx(math.radians(20), abs=math.radians(0.5))


def test_robust_segments_ignore_a_single_disagreeing_contact() -> None:
    wall = Wall.flat()
    truth = Placement(np.array([0.0, -1.1, 0.0]), 0.0)
    pairs = _segment_contacts(wall, truth, np.linspace(1.5, -1.5, 15))
    est = SegmentEstimator(PRIOR, robust=True)
    plain = SegmentEstimator(PRIOR)
    for k, (ref, contact) in enumerate(pairs):
        c = contact.copy()
        if k == 6:
            c[1] -= 0.3
        est.update(ref, c)
        plain.update(ref, c)
    assert len(est.lines) == 1 and est.rejected == 1
    assert len(plain.lines) > 1


@settings(max_examples=25, deadline=None)
@given(
    angles=st.lists(st.sampled_from([-20.0, -10.0, 0.0, 10.0, 20.0]), min_size=1, max_size=4),
    n=st.integers(1, 40),
    seed=st.integers(0, 2**31),
    robust=st.booleans(),
    noise=st.floats(0.0, 0.05),
)
def test_estimators_survive_random_dots_and_walls(
    angles: list[float], n: int, seed: int, robust: bool, noise: float
) -> None:
    """Any dots on any wall, noisy contacts: finite plans that still face the wall."""
    rng = np.random.default_rng(seed)
    wall = Wall.segmented(angles, (-2.0, 2.0))
    truth = Placement(np.array([0.0, -1.1, 0.0]), math.radians(rng.uniform(-15, 15)))
    xs = rng.uniform(-2, 2, n)
    for est in (
        RigidEstimator(PRIOR, robust=robust),
        SegmentEstimator(PRIOR, robust=robust),
        SegmentEstimator(PRIOR, robust=robust, update="normal"),
    ):
        for ref, c in _segment_contacts(wall, truth, xs):
            est.update(ref, c + rng.normal(0, noise + 1e-9, 3))
            plan = est.plan(ref)
            assert np.all(np.isfinite(plan.target_rho))
            assert abs(plan.yaw_rad) <= math.radians(60) + 1e-9
        assert abs(est.placement.gamma_rad) < math.pi / 2
