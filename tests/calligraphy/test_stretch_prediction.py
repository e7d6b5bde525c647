"""The predicted timing stretch: skips attempts that cannot pass, never overshoots."""

from __future__ import annotations

import math

import pytest

from skyquill.calligraphy.allocation import DEVIATION_EXPONENT, _stretches_needed
from skyquill.calligraphy.options import WritingOptions


@pytest.mark.parametrize(
    ("ratio", "expected"), [(1.01, 1), (2.0, 1), (2.3, 2), (4.4, 2), (12.0, 4)]
)
def test_stretches_follow_the_deviation_model(ratio: float, expected: int) -> None:
    opts = WritingOptions()
    assert _stretches_needed(ratio * opts.tolerance, opts) == expected


def test_the_model_falls_faster_than_measured() -> None:
    # measured: the deviation halves per x1.25 (p = log 2 / log 1.25 = 3.1); a larger p
    # predicts fewer stretches, so the prediction never skips past the one-step answer
    assert math.log(2) / math.log(1.25) < DEVIATION_EXPONENT
    opts = WritingOptions()
    for ratio in (1.5, 2.0, 3.9, 4.0, 7.9, 8.0, 15.9):
        halving = max(1, math.ceil(math.log2(ratio)))
        assert _stretches_needed(ratio * opts.tolerance, opts) <= halving
