"""Shared random problems and references for the re-segmentation tests."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st
from numpy.typing import NDArray

from skyquill.io.points import read_points_csv
from skyquill.limits import BoxLimit, DerivativeLimit, NormLimit, vehicle_limits
from skyquill.optimize import (
    Boundary,
    Interpolation,
    PointDeviation,
    SmoothingProblem,
    solve,
)
from skyquill.optimize.resegment import point_fit_factory

Array = NDArray[np.float64]
Factory = Callable[[Array], SmoothingProblem]

SPIRAL = Path(__file__).resolve().parents[3] / "examples" / "spiral.csv"
SETTINGS = settings(
    max_examples=50,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
    derandomize=True,
)


def close(analytic: Array, reference: Array, rtol: float = 1e-5) -> None:
    err = float(np.linalg.norm(analytic - reference))
    assert err <= rtol * float(np.linalg.norm(reference)) + 1e-9, (err, analytic, reference)


# ------------------------------------------------------------------ factories
@dataclass(frozen=True)
class Spec:
    """Structure of a random problem; the numbers come from ``seed``."""

    kind: str
    dim: int
    degree: int
    n_points: int
    extra_ctrl: int
    seed: int


specs = st.builds(
    Spec,
    kind=st.sampled_from(["points", "orders", "interpolation", "moving_ends", "fixed_times"]),
    dim=st.integers(1, 3),
    degree=st.integers(3, 5),
    n_points=st.integers(4, 8),
    extra_ctrl=st.integers(2, 6),
    seed=st.integers(0, 2**16),
)


def random_problem(spec: Spec) -> tuple[Array, Factory]:
    """Initial times and ``make_problem`` of one random problem of ``spec.kind``."""
    rng = np.random.default_rng(spec.seed)
    n, d, k = spec.n_points, spec.dim, spec.degree
    times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.3, 1.5, n - 1))])
    pts = np.cumsum(rng.normal(0.0, 1.0, (n, d)), axis=0)
    weight = float(10.0 ** rng.uniform(0.0, 3.0))
    n_ctrl = max(n + k + 1, k + 1 + spec.extra_ctrl)
    smoothness = {3: 1.0} if spec.kind != "orders" else {2: 0.3, k: 0.05}
    boundary: tuple[Boundary, ...] = Boundary.rest(pts[0], pts[-1], min(3, k))
    if spec.kind == "moving_ends":
        boundary = (
            Boundary(0, pts[0], pts[-1]),
            Boundary(1, rng.normal(0.0, 1.0, d), rng.normal(0.0, 1.0, d)),
            Boundary(2, None, rng.normal(0.0, 1.0, d)),
        )
    fixed_t = np.array([0.2, 0.9]) * times[-1]  # stays inside [0, duration] under tiny steps
    fixed_p = rng.normal(0.0, 1.0, (2, d))

    def make(t: Array) -> SmoothingProblem:
        deviations = [PointDeviation(t, pts, weight)]
        if spec.kind == "fixed_times":
            deviations.append(PointDeviation(fixed_t, fixed_p, 0.5 * weight))
        return SmoothingProblem(
            dim=d,
            degree=k,
            n_ctrl=n_ctrl,
            duration=float(t[-1]),
            smoothness=smoothness,
            deviations=tuple(deviations) if spec.kind != "interpolation" else (),
            interpolation=(Interpolation(t, pts),) if spec.kind == "interpolation" else (),
            boundary=boundary,
        )

    return times, make


def spiral(n: int) -> tuple[Array, Array]:
    """``n`` points of the hand-drawn spiral, subsampled evenly, times from 0."""
    pts, t = read_points_csv(SPIRAL)
    assert t is not None
    idx = np.linspace(0, pts.shape[0] - 1, n).round().astype(int)
    return pts[idx], t[idx] - t[idx[0]]


def limited_spiral(n: int, n_ctrl: int, coupled: int | None) -> tuple[Array, Array, Factory]:
    """Spiral fit with speed / acceleration / jerk limits at 0.8 / 0.7 / 0.7 of the free fit."""
    pts, times = spiral(n)
    free = solve(point_fit_factory(pts, n_ctrl)(times)).trajectory.sample(500.0)
    vmax, amax, jmax = (float(np.abs(x).max()) for x in (free.v, free.a, free.j))
    limits = vehicle_limits(2, 0.8 * vmax, 0.7 * amax, 0.7 * jmax, coupled)
    return pts, times, point_fit_factory(pts, n_ctrl, limits=limits)


def limited_random(seed: int, dim: int, fraction: float) -> tuple[Array, Factory]:
    """Seven random points, degree 4, an acceleration box at ``fraction`` of the free fit's."""
    rng = np.random.default_rng(seed)
    n = 7
    pts = np.cumsum(rng.normal(0.0, 0.5, (n, dim)), axis=0)
    times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.5, 1.5, n - 1))])
    free = solve(point_fit_factory(pts, 14, degree=4, weight=100.0)(times))
    acc = float(np.abs(free.trajectory.sample(500.0).a).max())
    limit = BoxLimit.symmetric(2, fraction * acc, dim)
    return times, point_fit_factory(pts, 14, degree=4, weight=100.0, limits=(limit,))


def norm_limited_random(
    seed: int, dim: int, order: int, fraction: float, extra: tuple[DerivativeLimit, ...] = ()
) -> tuple[Array, Factory]:
    """Seven random points, degree 4, an exact norm limit (a cone) on derivative ``order``
    at ``fraction`` of the free fit's peak norm, then the ``extra`` limits."""
    rng = np.random.default_rng(seed)
    n = 7
    pts = np.cumsum(rng.normal(0.0, 0.5, (n, dim)), axis=0)
    times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.5, 1.5, n - 1))])
    free = solve(point_fit_factory(pts, 14, degree=4, weight=100.0)(times))
    sample = free.trajectory.sample(500.0)
    peak = float(np.linalg.norm((sample.v, sample.a)[order - 1], axis=1).max())
    limits = (NormLimit(order, fraction * peak, dim=dim), *extra)
    return times, point_fit_factory(pts, 14, degree=4, weight=100.0, limits=limits)
