"""The fleet's table answers exactly what each drone's own motion answers."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.show.fleet import Fleet
from skyquill.show.motion import Motion
from skyquill.trajectory.horner import horner


def _motion(rng: np.random.Generator, horizon: float, order: int) -> Motion:
    pieces = int(rng.integers(1, 6))
    cuts = np.sort(rng.uniform(0.0, horizon, pieces - 1))
    breaks = np.concatenate([[0.0], cuts, [horizon]])
    coeffs = rng.normal(size=(pieces, order, 3))
    for i in range(1, pieces):  # continuous where pieces meet
        coeffs[i, 0] = horner(coeffs[i - 1 : i], np.array([breaks[i] - breaks[i - 1]]))[0]
    return Motion(breaks, coeffs, float(rng.uniform(0.0, 1e-4)))


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10**6), drones=st.integers(1, 6), horizon=st.floats(0.5, 2000.0))
def test_positions_and_bounds_match_each_motion(seed: int, drones: int, horizon: float) -> None:
    rng = np.random.default_rng(seed)
    motions = [_motion(rng, horizon, int(rng.integers(1, 7))) for _ in range(drones)]
    fleet = Fleet(motions)
    who = rng.integers(0, drones, 200)
    # times at and between the breaks: the lookup settles round-off at a boundary
    breaks = np.concatenate([m.breaks for m in motions])
    t = np.where(rng.random(200) < 0.3, rng.choice(breaks, 200), rng.uniform(0, horizon, 200))
    width = rng.exponential(horizon / 20, 200)
    a, b = np.maximum(0.0, t - width), np.minimum(horizon, t + width)
    local = fleet.local(who, a, b)
    for d in range(drones):
        mine = who == d
        if not mine.any():
            continue
        np.testing.assert_allclose(fleet.position(who[mine], t[mine]), motions[d].position(t[mine]))
        own = motions[d].local(a[mine], b[mine])
        np.testing.assert_array_equal(local.inside[mine], own.inside)
        np.testing.assert_allclose(local.speed[mine], own.speed, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(local.jump[mine], own.jump)
        k = own.derivatives.shape[1]
        np.testing.assert_allclose(local.derivatives[mine][:, :k], own.derivatives, atol=1e-12)
        assert not local.derivatives[mine][:, k:].any()  # higher orders of a lower degree


def test_the_piece_at_a_break_is_the_one_that_starts_there() -> None:
    breaks = np.array([0.0, 0.1, 0.2, 0.30000000000000004, 1000.0])
    motion = Motion(breaks, np.zeros((4, 1, 3)))
    fleet = Fleet([motion, motion, motion])
    who = np.array([2, 2, 2, 2])
    t = breaks[:4]
    np.testing.assert_array_equal(fleet.piece(who, t) - fleet.offset[2], [0, 1, 2, 3])
    np.testing.assert_array_equal(fleet.piece(who, t, "left") - fleet.offset[2], [0, 0, 1, 2])
