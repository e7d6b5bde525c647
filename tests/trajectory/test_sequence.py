"""RestToRestSequence: pieces on one clock, joins checked at rest."""

from __future__ import annotations

import numpy as np
import pytest
from trajectory_kinds import rest_to_rest_leg, retimed_arc

from skyquill.errors import InputError
from skyquill.trajectory import RestToRestSequence, concatenate


def test_legs_back_to_back() -> None:
    a = rest_to_rest_leg(np.zeros(2), np.array([1.0, 0.0]), 2.0)
    b = rest_to_rest_leg(np.array([1.0, 0.0]), np.array([1.0, 3.0]), 3.0)
    seq = RestToRestSequence((a, b))
    assert seq.duration == 5.0
    np.testing.assert_allclose(seq.evaluate(np.array([0.0, 2.0, 5.0])), [[0, 0], [1, 0], [1, 3]])
    np.testing.assert_allclose(seq.evaluate(np.array([3.5]), 1), b.evaluate(np.array([1.5]), 1))
    np.testing.assert_allclose(seq.breakpoints, [0.0, 2.0, 5.0])
    assert seq.piece_at(np.array([0.0, 1.99, 2.0, 5.0])).tolist() == [0, 0, 1, 1]


def test_mixed_kinds_and_one_piece() -> None:
    arc = retimed_arc(4.0)
    end = arc.evaluate(np.array([4.0]))[0]
    leg = rest_to_rest_leg(end, end + np.array([0.0, 1.0]), 1.5)
    seq = concatenate([arc, leg])
    assert isinstance(seq, RestToRestSequence) and seq.duration == pytest.approx(5.5)
    assert concatenate([leg]) is leg
    assert seq.sample(10.0).j.shape == (56, 2)


def test_join_must_be_continuous_and_at_rest() -> None:
    a = rest_to_rest_leg(np.zeros(2), np.array([1.0, 0.0]), 2.0)
    far = rest_to_rest_leg(np.array([1.5, 0.0]), np.array([2.0, 0.0]), 1.0)
    with pytest.raises(InputError, match=r"pieces\[1\]: got a start 0.5 m from where"):
        RestToRestSequence((a, far))
    half = rest_to_rest_leg(np.zeros(2), np.array([2.0, 0.0]), 2.0)
    cut = type(half)(np.array([0.0, 1.0]), half.coeffs)  # stops mid-motion
    nxt = rest_to_rest_leg(cut.evaluate(np.array([1.0]))[0], np.zeros(2), 1.0)
    with pytest.raises(InputError, match=r"pieces\[0\]: got speed .* expected rest"):
        RestToRestSequence((cut, nxt))
    with pytest.raises(InputError, match="pieces: got none"):
        RestToRestSequence(())
    three = rest_to_rest_leg(np.zeros(3), np.ones(3), 1.0)
    with pytest.raises(InputError, match=r"pieces: got axes \[2, 3\]"):
        RestToRestSequence((a, three))


def test_evaluate_orders_is_each_piece_at_its_own_clock() -> None:
    arc = retimed_arc(4.0)
    end = arc.evaluate(np.array([4.0]))[0]
    seq = RestToRestSequence((arc, rest_to_rest_leg(end, end + np.array([0.0, 1.0]), 1.5)))
    t = np.random.default_rng(7).uniform(0.0, seq.duration, 200)  # not sorted
    got = seq.evaluate_orders(t, (3, 0, 1))
    assert list(got) == [3, 0, 1]
    for n, values in got.items():
        for i, ti in enumerate(t):
            k = int(seq.piece_at(np.array([ti]))[0])
            local = np.array([ti - seq.starts[k]])
            np.testing.assert_array_equal(values[i], seq.pieces[k].evaluate(local, n)[0])
