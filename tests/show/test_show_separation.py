"""The guaranteed separation: finds what 5 Hz sampling misses, never claims more than is true."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from show_cases import line, move, planted

from skyquill.errors import InputError
from skyquill.show import ShowDrone, separation, separation_of
from skyquill.show.motion import motion_of
from skyquill.show.separation import TOLERANCE_M, guaranteed_separation
from skyquill.trajectory import PiecewisePolynomial, SplineTrajectory
from skyquill.trajectory.horner import horner


def _dense_min(trajectories: list[PiecewisePolynomial], rate: float = 1000.0) -> float:
    horizon = max(t.duration for t in trajectories)
    t = np.linspace(0.0, horizon, int(horizon * rate) + 1)
    p = [tr.evaluate(np.minimum(t, tr.duration)) for tr in trajectories]
    return min(
        float(np.linalg.norm(p[i] - p[j], axis=1).min())
        for i in range(len(p))
        for j in range(i + 1, len(p))
    )


def test_a_jump_towards_the_other_drone_is_inside_the_bound() -> None:
    """A drone that jumps 0.9 mm closer where its pieces meet: the bound still holds."""
    still = PiecewisePolynomial(np.array([0.0, 2.0]), np.zeros((1, 1, 3)))
    coeffs = np.zeros((2, 2, 3))
    coeffs[0, 0], coeffs[0, 1] = [1.0, 0.0, 0.0], [-0.1, 0.0, 0.0]  # 1 m to 0.9 m
    coeffs[1, 0], coeffs[1, 1] = [0.9 - 9e-4, 0.0, 0.0], [0.1, 0.0, 0.0]  # jumps 0.9 mm in
    jumpy = PiecewisePolynomial(np.array([0.0, 1.0, 2.0]), coeffs)
    motions = [motion_of("a", still, 2.0), motion_of("b", jumpy, 2.0)]
    result = guaranteed_separation(motions, 0.5)
    true_min = 0.9 - 9e-4
    assert result.lower_bound_m <= true_min
    assert result.lower_bound_m >= true_min - 4 * 9e-4 - TOLERANCE_M


def test_planted_50_ms_violation_missed_at_5_hz_is_found() -> None:
    hover, flyer, start = planted()
    assert _dense_min([hover, flyer], rate=5.0) > 3.0  # Skybrush's sampling passes it
    result = separation_of([ShowDrone(hover, "a"), ShowDrone(flyer, "b")], 3.0)
    assert not result.passed
    (encounter,) = result.encounters
    assert encounter.drones == (0, 1)
    assert encounter.first_time_s == pytest.approx(start, abs=1e-5)
    assert encounter.closest_m == pytest.approx(np.sqrt(8.75), abs=1e-6)
    assert encounter.closest_time_s == pytest.approx(5.1, abs=1e-6)
    assert encounter.margin_m == pytest.approx(np.sqrt(8.75) - 3.0, abs=1e-6)


def test_safe_show_bound_is_below_the_true_minimum_and_above_the_request() -> None:
    trajectories = [
        move([0, 0, 1], [6, 0, 2], 6.0),
        move([6, 4, 1], [0, 2.5, 2], 7.0),
        move([3, -4, 3], [3, -1.5, 1], 8.0),
    ]
    polys = [PiecewisePolynomial(*t.to_piecewise_polynomial()) for t in trajectories]
    true_min = _dense_min(polys)
    result = separation_of([ShowDrone(t, str(i)) for i, t in enumerate(trajectories)], 1.0)
    assert result.passed
    assert 1.0 <= result.lower_bound_m <= true_min <= result.attained_m + 1e-12
    assert result.attained_m - result.lower_bound_m <= TOLERANCE_M


def test_formation_at_the_minimum_is_proven_without_bisecting_forever() -> None:
    # Drones flying side by side at 1 mm more than the minimum: the relative bound is 0.
    a = move([0, 0, 1], [50, 0, 1], 20.0)
    b = move([0, 3.001, 1], [50, 3.001, 1], 20.0)
    result = separation_of([ShowDrone(a, "a"), ShowDrone(b, "b")], 3.0)
    assert result.passed
    assert result.lower_bound_m == pytest.approx(3.001, abs=1e-9)
    assert result.intervals < 1000


def test_finished_drones_hold_their_last_position() -> None:
    short = line([0, 0, 0], [1, 0, 0], 1.0)  # ends at x = 1 at t = 1, then holds
    long = line([5, 0, 0], [-1, 0, 0], 4.0)  # reaches x = 1 at t = 4
    result = separation_of([ShowDrone(short, "s"), ShowDrone(long, "l")], 0.5)
    assert not result.passed
    assert result.encounters[0].first_time_s == pytest.approx(3.5, abs=1e-5)


def test_a_late_start_waits_at_its_first_position() -> None:
    first = line([0, 0, 0], [0, 0, 0], 10.0)
    late = line([0.2, 0, 0], [1, 0, 0], 2.0)
    drones = [ShowDrone(first, "a"), ShowDrone(late, "b", start_s=5.0)]
    result = separation_of(drones, 0.5)
    assert result.encounters[0].first_time_s == 0.0
    assert result.encounters[0].closest_m == pytest.approx(0.2)


def test_one_drone_has_no_pair() -> None:
    result = guaranteed_separation([motion_of("a", line([0, 0, 0], [1, 0, 0], 1.0), 1.0)], 3.0)
    assert result.passed and result.pairs == 0 and result.lower_bound_m == np.inf


def test_negative_minimum_is_refused() -> None:
    motion = motion_of("a", line([0, 0, 0], [1, 0, 0], 1.0), 1.0)
    with pytest.raises(InputError, match=r"minimum_m: got -1"):
        guaranteed_separation([motion, motion], -1.0)


def _continuous(seed: int, pieces: int, order: int) -> PiecewisePolynomial:
    rng = np.random.default_rng(seed)
    breaks = np.concatenate([[0.0], np.cumsum(rng.uniform(0.2, 2.0, pieces))])
    scale = np.array([2.0, 1.0, 0.5, 0.2, 0.1, 0.05])[:order, None]
    coeffs = rng.normal(size=(pieces, order, 3)) * scale
    for i in range(1, pieces):  # each piece starts where the previous ended
        coeffs[i, 0] = horner(coeffs[i - 1 : i], np.array([breaks[i] - breaks[i - 1]]))[0]
    return PiecewisePolynomial(breaks, coeffs)


@settings(max_examples=40, deadline=None)
@given(
    seeds=st.tuples(st.integers(0, 10**6), st.integers(0, 10**6)),
    pieces=st.tuples(st.integers(1, 4), st.integers(1, 4)),
    orders=st.tuples(st.integers(1, 6), st.integers(1, 6)),
    minimum=st.floats(0.0, 3.0),
)
def test_bound_never_exceeds_the_dense_minimum(
    seeds: tuple[int, int], pieces: tuple[int, int], orders: tuple[int, int], minimum: float
) -> None:
    pair = [_continuous(s, p, k) for s, p, k in zip(seeds, pieces, orders, strict=True)]
    result = separation_of([ShowDrone(t, str(i)) for i, t in enumerate(pair)], minimum)
    dense = _dense_min(pair, rate=20_000.0)
    assert result.lower_bound_m <= dense + 1e-9
    assert result.lower_bound_m <= result.attained_m
    assert result.passed == (not result.encounters and result.lower_bound_m >= minimum)
    if dense < minimum:
        assert not result.passed


def test_a_hundred_drones_are_pruned_to_their_neighbours() -> None:
    rng = np.random.default_rng(7)
    drones = []
    for k in range(100):
        base = np.array([4.0 * (k % 10), 4.0 * (k // 10), 10.0])
        wobble = rng.normal(scale=0.2, size=(40, 3))
        ctrl = base + wobble + np.linspace(0.0, 1.0, 40)[:, None] * np.array([30.0, 0.0, 0.0])
        drones.append(ShowDrone(SplineTrajectory(ctrl, 5, 60.0), f"d{k}"))
    result = separation_of(drones, 2.0)
    assert result.passed and result.pairs == 4950
    assert result.pairs_examined < 400  # neighbours only: the rest pruned by bounding boxes
    assert 2.0 <= result.lower_bound_m <= result.attained_m <= result.lower_bound_m + TOLERANCE_M


def test_pairs_compared_in_chunks_give_the_same_answer(monkeypatch: pytest.MonkeyPatch) -> None:
    drones = [
        ShowDrone(move([0, 3 * k, 1], [10, 3 * k + (k % 2), 1 + k % 3], 10.0 + k), f"d{k}")
        for k in range(8)
    ]
    whole = separation_of(drones, 1.0)
    monkeypatch.setattr(separation, "CHUNK", 7)
    chunked = separation_of(drones, 1.0)
    assert chunked == whole


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 10**6),
    drones=st.integers(2, 6),
    spread=st.floats(1.0, 30.0),
    minimum=st.floats(0.0, 2.0),
)
def test_the_pruned_proof_agrees_with_every_pair_compared(
    seed: int, drones: int, spread: float, minimum: float
) -> None:
    """Random small shows (drones scattered over ``spread`` metres, some close, some far):
    pruning by space-time boxes gives the verdict, the pairs found too close and the bound
    (to the tolerance) of comparing every pair in every window, and both bounds hold."""
    rng = np.random.default_rng(seed)
    trajectories = []
    for k in range(drones):
        path = _continuous(seed + k, int(rng.integers(1, 4)), int(rng.integers(1, 5)))
        offset = rng.uniform(-spread, spread, 3)
        coeffs = path.coeffs.copy()
        coeffs[:, 0] += offset
        trajectories.append(PiecewisePolynomial(path.breaks, coeffs))
    horizon = max(t.duration for t in trajectories)
    motions = [motion_of(str(i), t, horizon) for i, t in enumerate(trajectories)]
    pruned = guaranteed_separation(motions, minimum)
    every = guaranteed_separation(motions, minimum, prune=False)
    assert every.pairs_examined == every.pairs >= pruned.pairs_examined
    assert pruned.passed == every.passed
    assert {e.drones for e in pruned.encounters} == {e.drones for e in every.encounters}
    dense = _dense_min(trajectories, rate=2_000.0)  # at or above the true minimum
    for result in (pruned, every):
        assert result.lower_bound_m <= dense + 1e-9
    if pruned.passed:
        assert abs(pruned.lower_bound_m - every.lower_bound_m) <= TOLERANCE_M + 1e-9
