"""The problem factory's contract is checked on every call."""

from __future__ import annotations

import pytest
from resegment_cases import Array, spiral

from skyquill.errors import InputError
from skyquill.optimize import SmoothingProblem
from skyquill.optimize.resegment import point_fit_factory, resegment


def test_rejects_a_factory_that_breaks_the_contract() -> None:
    pts, times = spiral(8)
    good = point_fit_factory(pts, 14)

    def padded(t: Array) -> SmoothingProblem:
        p = good(t)
        return SmoothingProblem(
            p.dim, p.degree, p.n_ctrl, p.duration + 1.0, p.smoothness, p.deviations
        )

    def growing(t: Array) -> SmoothingProblem:
        n_ctrl = 14 if t[-1] == times[-1] else 15
        return point_fit_factory(pts, n_ctrl)(t)

    with pytest.raises(InputError, match="expected duration == times\\[-1\\]"):
        resegment(pts, times, padded)
    with pytest.raises(InputError, match="expected the same n_ctrl = 14"):
        resegment(pts, times, growing, mode="free", time_penalty=1.0)
