"""The simulated ink against the input: IoU, two-sided distance, stroke count, picture."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from skyquill.calligraphy.board import Board
from skyquill.calligraphy.ink import (
    SAMPLE_M,
    InkFidelity,
    flight_ink,
    ink_fidelity,
    measure_ink,
)
from skyquill.calligraphy.mission import Mission, WritingOptions, contact_board, plan_writing
from skyquill.errors import InputError
from skyquill.strokes import Strokes

L, W = 0.1, 0.012  # the synthetic stroke: (0, 0) to (L, 0), m, drawn W wide


def line(start: tuple[float, float], end: tuple[float, float], n: int = 201) -> np.ndarray:
    """``n`` points from ``start`` to ``end``, (n, 2)."""
    return np.linspace(start, end, n)


def stadium_iou(r: float, length: float, d: float) -> float:
    """IoU of two stadiums (segment ``length`` swept by a disc of radius ``r``) offset by
    ``d < 2 r`` across the segment: the intersection is the strip ``2 r - d`` wide plus
    the lens of two discs ``d`` apart (the two half-lenses at the ends)."""
    lens = 2 * r**2 * math.acos(d / (2 * r)) - 0.5 * d * math.sqrt(4 * r**2 - d**2)
    inter = length * (2 * r - d) + lens
    area = 2 * r * length + math.pi * r**2
    return inter / (2 * area - inter)


def straight(offset: float = 0.0, end: float = L, width: float = W) -> InkFidelity:
    ink = line((0.0, offset), (end, offset))
    return ink_fidelity([ink], [np.full(len(ink), width)], [line((0, 0), (L, 0), 2)], W)


def test_ink_on_its_stroke_at_the_planned_width_has_iou_1() -> None:
    f = straight()
    assert f.iou == pytest.approx(1.0, abs=1e-3)
    assert f.max_deviation_m == pytest.approx(0.0, abs=1e-12)
    assert f.ink_shape.area == pytest.approx(2 * 0.5 * W * L + math.pi * (0.5 * W) ** 2, rel=1e-3)


@pytest.mark.parametrize("d", [0.001, 0.004, 0.011])
def test_offset_ink_has_the_iou_of_two_offset_stadiums(d: float) -> None:
    f = straight(offset=d)
    assert f.iou == pytest.approx(stadium_iou(0.5 * W, L, d), abs=1e-3)
    # Both centre lines are straight and parallel: d apart either way.
    assert f.ink_to_input_max_m == pytest.approx(d, abs=1e-12)
    assert f.input_to_ink_max_m == pytest.approx(d, abs=1e-12)
    assert f.max_deviation_m == pytest.approx(d, abs=1e-12)
    assert f.mean_m == pytest.approx(d, abs=1e-12)


def test_ink_missing_the_last_2_cm_is_2_cm_from_the_input() -> None:
    f = straight(end=L - 0.02)
    assert f.input_to_ink_max_m == pytest.approx(0.02, abs=1e-12)
    assert f.ink_to_input_max_m == pytest.approx(0.0, abs=1e-12)
    assert f.max_deviation_m == pytest.approx(0.02, abs=1e-12)
    r = 0.5 * W  # the ink is the input's stadium, 2 cm shorter: IoU = ratio of their areas
    shorter, full = (2 * r * length + math.pi * r**2 for length in (L - 0.02, L))
    assert f.iou == pytest.approx(shorter / full, abs=1e-3)


def test_a_gap_in_the_middle_of_a_long_segment_is_found() -> None:
    """The input is resampled, not just its vertices: a 4 cm gap is 2 cm from the ink."""
    ink = [line((0.0, 0.0), (0.03, 0.0)), line((0.07, 0.0), (L, 0.0))]
    f = ink_fidelity(ink, [np.full(201, W)] * 2, [line((0, 0), (L, 0), 2)], W)
    assert f.input_to_ink_max_m == pytest.approx(0.02, abs=0.5 * SAMPLE_M)
    assert f.ink_strokes == 2 and f.input_strokes == 1


def test_ink_strokes_count_the_runs_that_left_ink() -> None:
    runs = [line((0, 0), (0.05, 0)), np.zeros((0, 2)), line((0.06, 0), (L, 0)), [[0.0, 0.02]]]
    widths = [np.full(len(r), W) for r in runs]
    strokes = [line((0, 0), (L, 0), 2), line((0, 0.02), (L, 0.02), 2)]
    f = ink_fidelity(runs, widths, strokes, W)
    assert (f.ink_strokes, f.input_strokes) == (3, 2)


def test_a_touch_in_place_is_a_disc_and_a_tapered_segment_the_hull_of_two() -> None:
    dot = ink_fidelity([[[0.0, 0.0]]], [[0.01]], [line((0, 0), (L, 0), 2)], W)
    assert dot.ink_shape.area == pytest.approx(math.pi * 0.005**2, rel=2e-3)
    taper = ink_fidelity([[[0.0, 0.0], [0.05, 0.0]]], [[0.0, 0.01]], [[[0, 0], [L, 0]]], W)
    # A cone's outline: the disc's tangents meet at the apex, 5 cm from the centre.
    r, a = 0.005, 0.05
    half_angle = math.asin(r / a)
    tangent = math.sqrt(a**2 - r**2)
    kite = tangent * r  # two right triangles (apex, tangent point, centre)
    arc = (math.pi + 2 * half_angle) * r**2 / 2  # the disc beyond the tangent points
    assert taper.ink_shape.area == pytest.approx(kite + arc, rel=2e-3)


def test_no_ink_is_infinitely_far_and_does_not_overlap() -> None:
    f = ink_fidelity([], [], [line((0, 0), (L, 0), 2)], W)
    assert f.ink_strokes == 0 and f.iou == 0.0
    assert math.isinf(f.max_deviation_m) and math.isinf(f.input_to_ink_max_m)
    assert f.as_dict()["max_deviation_m"] is None and f.as_dict()["ink_to_input_max_m"] == 0.0
    json.dumps(f.as_dict(), allow_nan=False)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (([[[0.0, 0.0]]], [], [[[0, 0], [1, 0]]], W), "ink_width_m: got 0 run(s), expected one"),
        (([[[0.0, 0.0]]], [[-1.0]], [[[0, 0], [1, 0]]], W), "ink_width_m[0]: got a negative"),
        (([[[0.0, 0.0]]], [[1.0, 2.0]], [[[0, 0], [1, 0]]], W), "ink_width_m[0]: got an array"),
        (([[[np.nan, 0.0]]], [[1.0]], [[[0, 0], [1, 0]]], W), "ink_uv[0]: got 1 NaN"),
        (([], [], [], W), "input_uv: got no stroke"),
        (([], [], [[[0, 0], [1, 0]]], -1.0), "width_m: got -1"),
    ],
)
def test_bad_input_names_the_argument(args: tuple[object, ...], message: str) -> None:
    with pytest.raises(InputError, match=re.escape(message)):
        ink_fidelity(*args)  # type: ignore[arg-type]


# --- on a planned mission: world frame, the pressing depth, the contact board -------------


@pytest.fixture(scope="module")
def mission() -> Mission:
    strokes = Strokes((np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([[0.0, 0.5], [1.0, 0.5]])))
    return plan_writing(strokes, options=WritingOptions(resegment="off"))


def pressed(mission: Mission, depth: float, n: int = 400) -> list[np.ndarray]:
    """Tip positions along each input stroke, ``depth`` into the contact board (world, m)."""
    board = contact_board(mission)
    assert board is not None
    out = []
    for stroke in mission.strokes_world:
        p = np.linspace(stroke[0], stroke[-1], n)
        p[:, 2] = board.height_m - depth
        out.append(p)
    return out


def test_measure_ink_of_the_planned_depth_reproduces_the_input(mission: Mission) -> None:
    brush = mission.options.brush
    height = contact_board(mission).height_m  # type: ignore[union-attr]
    f = measure_ink(pressed(mission, brush.press_depth_m), mission, height)
    assert f.iou == pytest.approx(1.0, abs=1e-3)
    assert f.max_deviation_m < 1e-9  # the pressing depth is not a deviation in the plane
    assert (f.ink_strokes, f.input_strokes, f.width_m) == (2, 2, brush.stroke_width_m)


def test_measure_ink_draws_deeper_ink_wider(mission: Mission) -> None:
    brush = mission.options.brush
    height = contact_board(mission).height_m  # type: ignore[union-attr]
    deep = 2 * brush.press_depth_m
    f = measure_ink(pressed(mission, deep), mission, height)
    length = sum(float(np.linalg.norm(s[-1] - s[0])) for s in mission.strokes_world)
    r = 0.5 * float(brush.ink_width(deep))
    assert f.ink_shape.area == pytest.approx(2 * r * length + 2 * math.pi * r**2, rel=1e-3)
    assert f.iou < 0.9


class Flown:
    """What :func:`flight_ink` reads of a :class:`~skyquill.sim.Flight`."""

    def __init__(self, ink: list[np.ndarray]) -> None:
        self.ink = tuple(ink)


def test_flight_ink_is_measured_on_the_contact_board(mission: Mission) -> None:
    flown = Flown(pressed(mission, mission.options.brush.press_depth_m))
    fidelity = flight_ink(flown, mission)  # type: ignore[arg-type]
    assert fidelity is not None and fidelity.iou == pytest.approx(1.0, abs=1e-3)


def test_a_wall_has_no_ink(mission: Mission) -> None:
    wall = plan_writing(
        Strokes((np.array([[0.0, 0.0], [1.0, 0.0]]),)),
        Board("wall", np.array([0.0, 0.0, 1.0])),
        WritingOptions(resegment="off"),
    )
    assert flight_ink(Flown([]), wall) is None  # type: ignore[arg-type]


# Whole nanometres: GEOS's simplification divides by squared lengths, which
# coordinates like 1e-300 m underflow (a warning); no flight is measured that finely.
finite = st.integers(-700_000_000, 700_000_000).map(lambda n: n * 1e-9)


@settings(
    max_examples=100, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    runs=st.lists(
        st.integers(0, 25).flatmap(
            lambda k: st.tuples(
                arrays(float, (k, 2), elements=finite),
                arrays(float, (k,), elements=st.integers(-10_000, 60_000).map(lambda n: n * 1e-6)),
            )
        ),
        max_size=4,
    )
)
def test_measure_ink_takes_any_ink(mission: Mission, runs: list[tuple[np.ndarray, ...]]) -> None:
    height = contact_board(mission).height_m  # type: ignore[union-attr]
    ink = [np.column_stack([uv + mission.board.origin[:2], height - depth]) for uv, depth in runs]
    f = measure_ink(ink, mission, height)
    assert f.ink_strokes == sum(len(uv) > 0 for uv, _ in runs) and f.input_strokes == 2
    assert 0.0 <= f.iou <= 1.0 + 1e-12
    assert f.max_deviation_m == max(f.ink_to_input_max_m, f.input_to_ink_max_m)
    assert f.ink_to_input_max_m <= f.max_deviation_m
    json.dumps(f.as_dict(), allow_nan=False)
