"""The sky grid and the stroke split planned on a local dask cluster: as in-process."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from skyquill.calligraphy.artwork import split_homes, split_strokes
from skyquill.calligraphy.board import sky_board
from skyquill.calligraphy.mission import WritingOptions
from skyquill.calligraphy.show import Show, plan_show
from skyquill.strokes import Strokes, typed_parts, typed_strokes

pytest.importorskip("distributed")

pytestmark = pytest.mark.timeout(180)

OPTIONS = WritingOptions(size_m=0.4, resegment="off")


def _same(show: Show, reference: Show) -> None:
    for got, want in zip(show.missions, reference.missions, strict=True):
        np.testing.assert_allclose(
            got.trajectory.control_points, want.trajectory.control_points, rtol=0, atol=1e-12
        )
    assert show.min_separation_m == pytest.approx(reference.min_separation_m, abs=1e-12)


def _grid(parts: list[Strokes], **run: Any) -> Show:
    return plan_show(
        parts, OPTIONS, 1.0, board_kind="sky", board_height_m=2.0, board_tilt_deg=10.0, **run
    )


def test_sky_grid_on_a_local_cluster() -> None:
    parts = typed_parts("L T I V", 4, "futural")
    reports: list[tuple[int, int]] = []
    show = _grid(parts, scheduler="local", progress=lambda d, n, _: reports.append((d, n)))
    _same(show, _grid(parts, workers=1))
    assert reports[0] == (0, 4) and sorted(reports)[-1] == (4, 4)


def test_stroke_split_on_a_local_cluster() -> None:
    options = WritingOptions(size_m=6.0, resegment="off")
    board = sky_board(np.array([0.0, 0.0, 2.0]))
    split = split_strokes(typed_strokes("HI", "futural"), 2, board, options)
    places = [(board, h) for h in split_homes(split, board, 6.0, 1.0)]
    show = plan_show(split.parts, options, 1.0, scheduler="local", places=places)
    _same(show, plan_show(split.parts, options, 1.0, workers=1, places=places))
    assert show.min_separation_m >= 1.0
