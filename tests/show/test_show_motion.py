"""Every trajectory kind as exact polynomial pieces on the show clock, with true speed bounds."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import make_interp_spline
from show_cases import line, move

from skyquill.errors import InputError
from skyquill.show.motion import motion_of
from skyquill.trajectory import (
    PiecewisePolynomial,
    RestToRestSequence,
    RetimedPath,
    SampledTrajectory,
    Trajectory,
)


def _retimed() -> RetimedPath:
    """A cubic curve flown along a smooth-step timing law (as coverage's speed planning does)."""
    rng = np.random.default_rng(0)
    curve = make_interp_spline(np.linspace(0.0, 1.0, 12), rng.normal(size=(12, 3)), k=3)
    t = np.linspace(0.0, 5.0, 9)
    x = t / 5.0
    return RetimedPath.from_samples(
        curve, t, x**2 * (3 - 2 * x), 6 * x * (1 - x) / 5.0, 6 * (1 - 2 * x) / 25.0
    )


def _sampled() -> SampledTrajectory:
    traj = move([0, 0, 1], [2, 1, 2], 3.0)
    s = traj.sample(20.0)
    return SampledTrajectory(s.t, s.p, s.v, s.a)


KINDS: dict[str, Trajectory] = {
    "polynomial": line([0, 0, 1], [1, 2, 0], 2.0),
    "bspline": move([0, 0, 1], [2, 1, 2], 3.0),
    "sampled": _sampled(),
    "retimed": _retimed(),
    "sequence": RestToRestSequence(
        (move([0, 0, 1], [1, 0, 1], 2.0), move([1, 0, 1], [1, 1, 1], 2.5))
    ),
}


@pytest.mark.parametrize("kind", list(KINDS))
def test_positions_match_the_trajectory_then_hold(kind: str) -> None:
    traj = KINDS[kind]
    motion = motion_of(kind, traj, traj.duration + 2.0, start_s=0.5)
    t = np.linspace(0.0, traj.duration, 777)
    assert np.allclose(motion.position(t + 0.5), traj.evaluate(t), atol=1e-9)
    before = motion.position(np.array([0.0, 0.25]))
    after = motion.position(np.array([traj.duration + 0.6, traj.duration + 2.0]))
    assert np.allclose(before, traj.evaluate(np.zeros(2)), atol=1e-9)
    assert np.allclose(after, traj.evaluate(np.full(2, traj.duration)), atol=1e-9)


@pytest.mark.parametrize("kind", list(KINDS))
def test_speed_bound_holds_on_random_intervals(kind: str) -> None:
    traj = KINDS[kind]
    motion = motion_of(kind, traj, traj.duration)
    rng = np.random.default_rng(3)
    a = rng.uniform(0.0, traj.duration - 0.3, 200)
    b = a + rng.uniform(1e-3, 0.3, 200)
    bound = motion.local(a, b).speed
    for lo, hi, s in zip(a, b, bound, strict=True):
        t = np.linspace(lo, hi, 201)
        p = motion.position(t)
        speed = np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(t)
        assert speed.max() <= s * (1 + 1e-9) + 1e-12


def test_a_round_off_jump_is_accepted_and_recorded() -> None:
    """A file's micrometre jumps (a Skybrush show as played) are kept as the motion's slack."""
    coeffs = np.zeros((2, 1, 3))
    coeffs[1, 0] = [2e-6, 0.0, 0.0]
    motion = motion_of("d0", PiecewisePolynomial(np.array([0.0, 1.0, 2.0]), coeffs), 2.0)
    assert motion.jump_m == pytest.approx(2e-6)
    across = motion.local(np.array([0.5, 1.2]), np.array([1.5, 1.8]))
    assert across.jump.tolist() == pytest.approx([2e-6, 0.0])


def test_a_jump_between_pieces_is_refused() -> None:
    coeffs = np.zeros((2, 1, 3))
    coeffs[1, 0] = [1.0, 0.0, 0.0]
    jumpy = PiecewisePolynomial(np.array([0.0, 1.0, 2.0]), coeffs)
    with pytest.raises(
        InputError, match=r"d0: got a jump of 1 m at t = 1 s, expected a continuous"
    ):
        motion_of("d0", jumpy, 2.0)


class _Unknown:
    """A trajectory kind the check does not know (only the protocol)."""

    duration = 1.0
    dim = 3
    breakpoints = np.array([0.0, 1.0])

    def evaluate(self, t: np.ndarray, order: int = 0) -> np.ndarray:
        return np.zeros((np.asarray(t).size, 3))

    def sample(self, rate: float) -> None:
        raise NotImplementedError


def test_an_unknown_kind_is_refused_by_name() -> None:
    with pytest.raises(InputError, match=r"d1: got a _Unknown trajectory, expected a polynomial"):
        motion_of("d1", _Unknown(), 2.0)  # type: ignore[arg-type]


def test_two_axes_are_refused() -> None:
    flat = PiecewisePolynomial(np.array([0.0, 1.0]), np.zeros((1, 1, 2)))
    with pytest.raises(InputError, match=r"d2: got 2 axes, expected 3"):
        motion_of("d2", flat, 1.0)
