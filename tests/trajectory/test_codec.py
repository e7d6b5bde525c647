"""Every trajectory kind to a dictionary and back, exactly; malformed input refused by name."""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from trajectory_kinds import rest_to_rest_leg, retimed_arc

from skyquill.errors import InputError
from skyquill.trajectory import (
    PiecewisePolynomial,
    RestToRestSequence,
    SampledTrajectory,
    SplineTrajectory,
    Trajectory,
)
from skyquill.trajectory.codec import KINDS, decode, encode


def _kinds() -> dict[str, Trajectory]:
    spline = SplineTrajectory(np.random.default_rng(0).normal(size=(9, 3)), 5, 3.0)
    leg = rest_to_rest_leg(np.zeros(2), np.array([1.0, 2.0]), 2.0)
    arc = retimed_arc(3.0)
    end = arc.evaluate(np.array([3.0]))[0]
    t = np.linspace(0.0, 1.0, 11)
    sampled = SampledTrajectory(t, np.c_[t, t, t], np.ones((11, 3)), np.zeros((11, 3)))
    return {
        "bspline": spline,
        "polynomial": leg,
        "retimed": arc,
        "sequence": RestToRestSequence((arc, rest_to_rest_leg(end, end + 1.0, 1.0))),
        "sampled": sampled,
    }


@pytest.mark.parametrize("kind", KINDS)
def test_round_trip_through_json_is_exact(kind: str) -> None:
    traj = _kinds()[kind]
    data = json.loads(json.dumps(encode(traj)))
    assert data["kind"] == kind
    back = decode(data)
    assert type(back) is type(traj) and back.duration == traj.duration
    t = np.linspace(0.0, traj.duration, 501)
    for order in range(4):
        np.testing.assert_array_equal(back.evaluate(t, order), traj.evaluate(t, order))


def test_yaw_survives() -> None:
    traj = PiecewisePolynomial(np.array([0.0, 1.0]), np.ones((1, 2, 3)), np.ones((1, 2)))
    back = decode(encode(traj))
    assert isinstance(back, PiecewisePolynomial)
    np.testing.assert_array_equal(back.evaluate_yaw(np.array([0.5])), [1.5])


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ([], "got a JSON list, expected an object"),
        ({"kind": "nurbs"}, "trajectory kind: got 'nurbs'"),
        ({"kind": "bspline", "degree": 5, "duration_s": 1.0}, "no 'control_points' field"),
        ({"kind": "bspline", "control_points": [[0, 0], [1]], "degree": 1, "duration_s": 1},
         "ragged or non-numeric"),
        ({"kind": "bspline", "control_points": [[0, 0]] * 6, "degree": 5, "duration_s": -1},
         "duration"),
        ({"kind": "polynomial", "breaks": [0, 1], "coeffs": [[[1.0, "x"]]]}, "non-numeric"),
        ({"kind": "retimed", "curve": {}}, "expected both"),
        ({"kind": "sequence", "pieces": []}, "expected one or more"),
    ],
)  # fmt: skip
def test_malformed_dictionaries_are_named(data: Any, message: str) -> None:
    with pytest.raises(InputError, match=message):
        decode(data)


def test_nesting_is_bounded() -> None:
    data: dict[str, Any] = {"kind": "sequence", "pieces": []}
    deep = data
    for _ in range(20):
        inner: dict[str, Any] = {"kind": "sequence", "pieces": []}
        deep["pieces"] = [inner]
        deep = inner
    with pytest.raises(InputError, match="nested deeper than 8"):
        decode(data)


json_values = st.recursive(
    st.none() | st.booleans() | st.floats() | st.integers() | st.text(max_size=5),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner),
    max_leaves=20,
)


@settings(max_examples=200, deadline=None)
@given(kind=st.sampled_from(KINDS), fields=st.dictionaries(st.sampled_from(
    ["control_points", "degree", "duration_s", "breaks", "coeffs", "curve", "timing", "pieces",
     "t", "p", "v", "a", "j", "yaw_coeffs"]), json_values))  # fmt: skip
def test_hostile_dictionaries_are_refused_or_decoded(kind: str, fields: dict[str, Any]) -> None:
    try:
        traj = decode({"kind": kind, **fields})
    except InputError:
        return
    assert traj.duration > 0.0
