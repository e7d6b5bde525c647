"""Validation at construction: every bad input raises InputError with a useful message.

Each message names the argument, what came and what was expected
(docs/architecture.md); the tests match all three parts where the message has them.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from skyquill.errors import InputError
from skyquill.limits import BoxLimit, CylinderLimit
from skyquill.optimize import (
    Boundary,
    Corridor,
    Interpolation,
    LineDeviation,
    PlaneDeviation,
    PointDeviation,
    SmoothingProblem,
    solve,
)
from skyquill.solvers import QuadraticProgram, solve_qp

NAN, INF = float("nan"), float("inf")
EYE2 = np.eye(2)
BOX2 = (np.vstack([EYE2, -EYE2]), np.array([1.0, 1.0, 1.0, 1.0]))


def problem(**kwargs: Any) -> SmoothingProblem:
    """A valid 2-D problem on [0, 4] s, with ``kwargs`` overriding fields."""
    args: dict[str, Any] = {
        "dim": 2,
        "degree": 5,
        "n_ctrl": 12,
        "duration": 4.0,
        "boundary": Boundary.rest(np.zeros(2), np.ones(2), 3),
    }
    args.update(kwargs)
    return SmoothingProblem(**args)


def test_the_base_problem_is_valid() -> None:
    assert solve(problem()).method == "closed_form"


# ------------------------------------------------------------------ non-finite values
@pytest.mark.parametrize(
    ("make", "match"),
    [
        (
            lambda: PointDeviation([0.5, NAN], [[0, 0], [1, 1]]),
            r"points\.times: got 1 NaN or infinite value\(s\), expected finite numbers",
        ),
        (
            lambda: PointDeviation([0.5, 1.0], [[0, INF], [1, NAN]]),
            r"points\.points: got 2 NaN or infinite value\(s\), expected finite",
        ),
        (
            lambda: Interpolation([0.5, INF], [[0, 0], [1, 1]]),
            r"interpolation\.times: got 1 NaN or infinite",
        ),
        (lambda: Interpolation([0.5], [[NAN, 0]]), r"interpolation\.points: got 1 NaN"),
        (lambda: Boundary(0, [0.0, NAN]), r"boundary\.start: got 1 NaN or infinite"),
        (lambda: Boundary(1, None, [-INF, 0.0]), r"boundary\.end: got 1 NaN or infinite"),
        (lambda: Boundary.rest([0, 0], [NAN, 1], 3), r"end: got 1 NaN or infinite"),
        (lambda: Corridor([[1, NAN]], [1.0], 0, 1), r"corridor\.A: got 1 NaN or infinite"),
        (lambda: Corridor([[1, 0]], [INF], 0, 1), r"corridor\.b: got 1 NaN or infinite"),
        (
            lambda: Corridor(*BOX2, NAN, 1.0),
            r"corridor\.t_start: got nan, expected a finite number",
        ),
        (lambda: LineDeviation([0, NAN], [1, 1], 0, 1), r"line\.a: got 1 NaN or infinite"),
        (
            lambda: LineDeviation([0, 0], [1, 1], 0, INF),
            r"line\.t_end: got inf, expected a finite number",
        ),
        (
            lambda: PlaneDeviation([0, 0, 1], [0, 0, NAN], 0, 1),
            r"plane\.anchor: got 1 NaN or infinite",
        ),
        (
            lambda: PointDeviation([0.5], [[0, 0]], weight=NAN),
            r"points\.weight: got nan, expected a finite number",
        ),
        (lambda: problem(duration=INF), r"duration: got inf, expected a finite number"),
        (lambda: problem(smoothness={3: NAN}), r"smoothness\[3\]: got nan, expected a finite"),
    ],
)
def test_non_finite_values(make: Callable[[], object], match: str) -> None:
    with pytest.raises(InputError, match=match):
        make()


# ------------------------------------------------------------------ shapes and dimensions
@pytest.mark.parametrize(
    ("make", "match"),
    [
        (
            lambda: PointDeviation([[0.5, 1.0]], [[0, 0], [1, 1]]),
            r"points\.times: got an array of shape \(1, 2\), expected 1 dimension",
        ),
        (
            lambda: PointDeviation([0.5, 1.0], [0, 0]),
            r"points\.points: got an array of shape \(2,\), expected 2 dimension",
        ),
        (
            lambda: PointDeviation([0.5, 1.0], [[0, 0], [1, 1], [2, 2]]),
            r"points\.points: got 3 rows, expected one per time \(2\)",
        ),
        (
            lambda: PointDeviation([], np.zeros((0, 2))),
            r"points\.times: got an empty array, expected at least one time",
        ),
        (
            lambda: Interpolation([1.0, 0.5], [[0, 0], [1, 1]]),
            r"interpolation\.times: got interpolation\.times\[0\] = 1 followed by 0\.5, "
            r"expected strictly increasing",
        ),
        (
            lambda: Boundary(0, [[0.0, 0.0]]),
            r"boundary\.start: got an array of shape \(1, 2\), expected 1 dimension",
        ),
        (lambda: Boundary(0), r"boundary: got start=None and end=None, expected at least one"),
        (
            lambda: Boundary.rest([0, 0], [1, 1, 1], 3),
            r"end: got an array of shape \(3,\), expected shape \(2,?\)",
        ),
        (
            lambda: LineDeviation([0, 0], [1, 1, 1], 0, 1),
            r"line\.b: got an array of shape \(3,\), expected shape \(2,?\)",
        ),
        (
            lambda: LineDeviation([1, 1], [1, 1], 0, 1),
            r"line: got a == b == \[1\.0, 1\.0\], expected two distinct points",
        ),
        (
            lambda: PlaneDeviation([0, 0], [0, 0], 0, 1),
            r"plane\.normal: got the zero vector, expected a non-zero normal",
        ),
        (
            lambda: Corridor([1.0, 0.0], [1.0], 0, 1),
            r"corridor\.A: got an array of shape \(2,\), expected 2 dimension",
        ),
        (
            lambda: Corridor(EYE2, [1.0, 1.0, 1.0], 0, 1),
            r"corridor\.b: got an array of shape \(3,\), expected shape \(2,?\)",
        ),
        (
            lambda: Corridor(np.zeros((2, 0)), [1.0, 1.0], 0, 1),
            r"corridor\.A: got shape \(2, 0\), expected at least one column",
        ),
    ],
)
def test_shapes(make: Callable[[], object], match: str) -> None:
    with pytest.raises(InputError, match=match):
        make()


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (
            {"deviations": (PointDeviation([1.0], [[0, 0, 0]]),)},
            r"PointDeviation\.points: got 3 axes, expected dim = 2",
        ),
        (
            {"interpolation": (Interpolation([1.0], [[0.0]]),)},
            r"Interpolation\.points: got 1 axes, expected dim = 2",
        ),
        (
            {"boundary": (Boundary(0, [0.0, 0.0, 0.0]),)},
            r"boundary \(order 0\): got 3 axes, expected dim = 2",
        ),
        ({"limits": (BoxLimit.symmetric(1, 2.0, 3),)}, r"speed box: got 3 axes, expected dim = 2"),
        (
            {"limits": (CylinderLimit(2, 2.0, -1.0, 1.0),)},
            r"acceleration cylinder \(8-gon\): got 3 axes, expected dim = 2",
        ),
        (
            {"corridors": (Corridor(np.eye(3), np.ones(3), 0, 1),)},
            r"Corridor: got 3 axes, expected dim = 2",
        ),
        (
            {"deviations": (LineDeviation([0, 0, 0], [1, 1, 1], 0, 1),)},
            r"LineDeviation: got 3 axes, expected dim = 2",
        ),
        (
            {"deviations": (PlaneDeviation([0, 0, 1], [0, 0, 0], 0, 1),)},
            r"PlaneDeviation: got 3 axes, expected dim = 2",
        ),
    ],
)
def test_dimension_mismatch(kwargs: dict[str, Any], match: str) -> None:
    with pytest.raises(InputError, match=match):
        problem(**kwargs)


# ------------------------------------------------------------------ times and windows
@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (
            {"deviations": (PointDeviation([1.0, 4.5], [[0, 0], [1, 1]]),)},
            r"PointDeviation\.times: got times in \[1, 4\.5\] s, expected within the duration "
            r"\[0, 4\] s",
        ),
        (
            {"deviations": (PointDeviation([-0.1, 1.0], [[0, 0], [1, 1]]),)},
            r"PointDeviation\.times: got times in \[-0\.1, 1\] s, expected within",
        ),
        (
            {"interpolation": (Interpolation([1.0, 4.01], [[0, 0], [1, 1]]),)},
            r"Interpolation\.times: got times in \[1, 4\.01\] s, expected within",
        ),
        (
            {"deviations": (LineDeviation([0, 0], [1, 1], 3.0, 5.0),)},
            r"LineDeviation window: got times in \[3, 5\] s, expected within the duration",
        ),
        (
            {"deviations": (PlaneDeviation([0, 1], [0, 0], -1.0, 2.0),)},
            r"PlaneDeviation window: got times in \[-1, 2\] s, expected within",
        ),
        (
            {"corridors": (Corridor(*BOX2, 2.0, 4.5),)},
            r"Corridor window: got times in \[2, 4\.5\] s, expected within",
        ),
    ],
)
def test_times_outside_the_duration(kwargs: dict[str, Any], match: str) -> None:
    with pytest.raises(InputError, match=match):
        problem(**kwargs)


def test_times_at_the_ends_are_accepted() -> None:
    p = problem(
        deviations=(
            PointDeviation([0.0, 4.0], [[0, 0], [1, 1]]),
            LineDeviation([0, 0], [1, 1], 0.0, 4.0),
        ),
        corridors=(Corridor(np.vstack([EYE2, -EYE2]), [2.0, 2.0, 1.0, 1.0], 0.0, 4.0),),
    )
    assert p.has_inequalities


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (
            lambda: LineDeviation([0, 0], [1, 1], 2.0, 1.0),
            r"line window: got \[2, 1\] s, expected t_start < t_end",
        ),
        (
            lambda: LineDeviation([0, 0], [1, 1], 1.0, 1.0),
            r"line window: got \[1, 1\] s, expected t_start < t_end",
        ),
        (
            lambda: PlaneDeviation([0, 1], [0, 0], 3.0, 0.5),
            r"plane window: got \[3, 0\.5\] s, expected t_start < t_end",
        ),
        (
            lambda: Corridor(*BOX2, 1.0, 1.0),
            r"corridor window: got \[1, 1\] s, expected t_start < t_end",
        ),
        (lambda: Corridor(*BOX2, "0", 1.0), r"corridor\.t_start: got '0', expected a number"),
    ],
)
def test_windows(make: Callable[[], object], match: str) -> None:
    with pytest.raises(InputError, match=match):
        make()


# ------------------------------------------------------------------ corridors
def test_empty_corridor() -> None:
    A = np.array([[1.0, 0.0], [-1.0, 0.0]])  # x <= 0 and x >= 1
    with pytest.raises(
        InputError,
        match=r"corridor: got half-spaces with an empty intersection on \[0, 2\] s, "
        r"expected a non-empty polytope",
    ):
        Corridor(A, [0.0, -1.0], 0.0, 2.0)


def test_corridor_without_rows() -> None:
    with pytest.raises(
        InputError, match=r"corridor\.A: got no half-spaces, expected at least one row"
    ):
        Corridor(np.zeros((0, 2)), np.zeros(0), 0.0, 1.0)


def test_unbounded_and_degenerate_corridors_are_accepted() -> None:
    assert Corridor([[1.0, 0.0]], [0.0], 0.0, 1.0).is_nonempty()  # a half-plane
    flat = Corridor(np.vstack([EYE2, -EYE2]), [1.0, 0.0, 1.0, 0.0], 0.0, 1.0)  # a segment
    assert flat.is_nonempty()


# ------------------------------------------------------------------ weights and orders
@pytest.mark.parametrize(
    ("make", "match"),
    [
        (
            lambda: PointDeviation([0.5], [[0, 0]], weight=-1.0),
            r"points\.weight: got -1, expected a number >= 0",
        ),
        (
            lambda: LineDeviation([0, 0], [1, 1], 0, 1, weight=-0.5),
            r"line\.weight: got -0\.5, expected a number >= 0",
        ),
        (
            lambda: PlaneDeviation([0, 1], [0, 0], 0, 1, weight=-2),
            r"plane\.weight: got -2, expected a number >= 0",
        ),
        (
            lambda: PointDeviation([0.5], [[0, 0]], weight="1"),
            r"points\.weight: got '1', expected a number",
        ),
        (lambda: problem(smoothness={3: -1.0}), r"smoothness\[3\]: got -1, expected a number >= 0"),
        (
            lambda: problem(smoothness={6: 1.0}),
            r"smoothness order: got 6, expected an integer from 1 to 5",
        ),
        (
            lambda: problem(smoothness={0: 1.0}),
            r"smoothness order: got 0, expected an integer from 1 to 5",
        ),
        (
            lambda: problem(smoothness=[1.0]),
            r"smoothness: got list, expected a mapping \{order: weight\}",
        ),
    ],
)
def test_weights(make: Callable[[], object], match: str) -> None:
    with pytest.raises(InputError, match=match):
        make()


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"degree": 0}, r"degree: got 0, expected an integer from 1 to 7"),
        ({"degree": 8}, r"degree: got 8, expected an integer from 1 to 7"),
        ({"degree": 3.0}, r"degree: got 3\.0, expected an integer from 1 to 7"),
        ({"degree": 5, "n_ctrl": 5}, r"n_ctrl: got 5, expected an integer .*degree \+ 1 = 6"),
        ({"dim": 0}, r"dim: got 0, expected an integer from 1 to 16"),
        ({"dim": "2"}, r"dim: got '2', expected an integer"),
        ({"duration": 0.0}, r"duration: got 0, expected a number > 0"),
        ({"duration": -1.0}, r"duration: got -1, expected a number > 0"),
        (
            {"degree": 3, "boundary": (Boundary(3, [0.0, 0.0]),)},
            r"boundary order: got 3, expected at most 2 for degree 3",
        ),
        (
            {"degree": 5, "boundary": (Boundary(5, None, [0.0, 0.0]),)},
            r"boundary order: got 5, expected at most 4 for degree 5",
        ),
        (
            {"degree": 3, "boundary": (), "limits": (BoxLimit.symmetric(4, 1.0, 2),)},
            r"limit order: got 4, expected at most 3 for degree 3",
        ),
        (
            {
                "degree": 2,
                "boundary": (),
                "smoothness": {2: 1.0},
                "limits": (CylinderLimit(3, 1.0),),
            },
            r"limit order: got 3, expected at most 2 for degree 2",
        ),
        ({"hull": "convex"}, r"hull: got 'convex', expected 'bspline' or 'bezier'"),
        ({"hull": None}, r"hull: got None, expected 'bspline' or 'bezier'"),
        ({"hull": np.array(["bspline", "bezier"])}, r"hull: got array\(.*expected 'bspline'"),
    ],
)
def test_problem_arguments(kwargs: dict[str, Any], match: str) -> None:
    with pytest.raises(InputError, match=match):
        problem(**kwargs)


def test_boundary_order_and_rest_orders() -> None:
    with pytest.raises(InputError, match=r"boundary\.order: got -1, expected an integer from 0"):
        Boundary(-1, [0.0])
    with pytest.raises(InputError, match=r"boundary\.order: got 1\.0, expected an integer"):
        Boundary(1.0, [0.0])  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"orders: got 0, expected an integer from 1 to 7"):
        Boundary.rest([0.0], [1.0], 0)
    with pytest.raises(InputError, match=r"orders: got '3', expected an integer"):
        Boundary.rest([0.0], [1.0], "3")  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("field", "value", "match"),
    [
        (
            "deviations",
            (Boundary(0, [0.0, 0.0]),),
            r"deviations\[0\]: got Boundary, expected PointDeviation / LineDeviation / "
            r"PlaneDeviation",
        ),
        (
            "deviations",
            PointDeviation([1.0], [[0, 0]]),
            r"deviations: got PointDeviation, expected a tuple of PointDeviation",
        ),
        ("interpolation", (None,), r"interpolation\[0\]: got NoneType, expected Interpolation"),
        ("boundary", (1,), r"boundary\[0\]: got int, expected Boundary"),
        ("limits", ("jerk",), r"limits\[0\]: got str, expected BoxLimit / CylinderLimit"),
        ("corridors", "box", r"corridors: got str, expected a tuple of Corridor"),
    ],
)
def test_terms_of_the_wrong_kind(field: str, value: object, match: str) -> None:
    with pytest.raises(InputError, match=match):
        problem(**{field: value})


def test_term_lists_are_accepted_as_tuples() -> None:
    p = problem(deviations=[PointDeviation([1.0], [[0, 0]])])
    assert isinstance(p.deviations, tuple)


# ------------------------------------------------------------------ solver names
def test_unknown_solver_name() -> None:
    with pytest.raises(
        InputError, match=r"solver: got 'gurobi', expected one of \['clarabel', 'osqp', 'piqp'\]"
    ):
        solve(problem(), "gurobi")
    limited = problem(limits=(BoxLimit.symmetric(1, 10.0, 2),))
    with pytest.raises(InputError, match=r"solver: got 'CLARABEL'"):
        solve(limited, "CLARABEL")


def test_unknown_backend_in_solve_qp() -> None:
    import scipy.sparse as sp

    qp = QuadraticProgram(
        sp.csc_array(np.eye(1)),
        np.zeros(1),
        sp.csc_array((0, 1)),
        np.zeros(0),
        sp.csc_array((0, 1)),
        np.zeros(0),
    )
    with pytest.raises(InputError, match=r"solver: got 'mosek', expected one of"):
        solve_qp(qp, "mosek")


# ------------------------------------------------------------------ garbage in
_HUGE = [10**400, -(10**400), 2**63, 1e308, -1e308, 1e-320, -0.0, 0, -1, -(10**9)]
_leaf = st.one_of(
    st.none(),
    st.booleans(),
    st.text(max_size=4),
    st.binary(max_size=3),
    st.integers(-(10**12), 10**12),
    st.sampled_from(_HUGE),
    st.floats(allow_nan=True, allow_infinity=True),
    st.complex_numbers(max_magnitude=10),
)
_nested = st.recursive(_leaf, lambda inner: st.lists(inner, max_size=4), max_leaves=12)
_arrays = hnp.arrays(
    dtype=st.sampled_from([np.float64, np.int64, np.complex128, np.bool_]),
    shape=hnp.array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=4),
)
_nan_arrays = st.builds(
    np.full,
    hnp.array_shapes(min_dims=1, max_dims=2, max_side=4),
    st.sampled_from([NAN, INF, -INF, 1e308]),
)
GARBAGE = st.one_of(
    _leaf,
    _nested,
    _arrays,
    _nan_arrays,
    st.dictionaries(st.one_of(st.integers(-3, 9), st.text(max_size=2)), _leaf, max_size=3),
    st.tuples(_leaf, _leaf),
    st.just(object()),
)


def _or_garbage(valid: object) -> st.SearchStrategy[Any]:
    """Mostly garbage, sometimes the valid value, so later checks are reached too."""
    return st.one_of(st.just(valid), GARBAGE)


def _construct_or_input_error(make: Callable[[], object]) -> None:
    """Construction either succeeds or raises InputError; anything else propagates."""
    with contextlib.suppress(InputError):
        make()


_valid_point = PointDeviation([1.0, 2.0], [[0.0, 0.0], [1.0, 1.0]])
_valid_corridor = Corridor(*BOX2, 0.0, 2.0)
_valid_limit = BoxLimit.symmetric(2, 3.0, 2)


@settings(max_examples=40, deadline=None)
@given(times=_or_garbage([1.0, 2.0]), points=_or_garbage([[0, 0], [1, 1]]), weight=_or_garbage(1.0))
def test_garbage_point_deviation(times: Any, points: Any, weight: Any) -> None:
    _construct_or_input_error(lambda: PointDeviation(times, points, weight))
    _construct_or_input_error(lambda: Interpolation(times, points))


@settings(max_examples=40, deadline=None)
@given(order=_or_garbage(1), start=_or_garbage([0.0, 0.0]), end=_or_garbage([1.0, 1.0]))
def test_garbage_boundary(order: Any, start: Any, end: Any) -> None:
    _construct_or_input_error(lambda: Boundary(order, start, end))
    _construct_or_input_error(lambda: Boundary.rest(start, end, order))


@settings(max_examples=40, deadline=None)
@given(A=_or_garbage(BOX2[0]), b=_or_garbage(BOX2[1]), t0=_or_garbage(0.0), t1=_or_garbage(1.0))
def test_garbage_corridor(A: Any, b: Any, t0: Any, t1: Any) -> None:
    _construct_or_input_error(lambda: Corridor(A, b, t0, t1))
    _construct_or_input_error(lambda: LineDeviation(A, b, t0, t1))
    _construct_or_input_error(lambda: PlaneDeviation(b, A, t0, t1))


@settings(max_examples=40, deadline=None)
@given(
    dim=_or_garbage(2),
    degree=_or_garbage(5),
    n_ctrl=_or_garbage(12),
    duration=_or_garbage(4.0),
    smoothness=_or_garbage({3: 1.0}),
    deviations=_or_garbage((_valid_point,)),
    interpolation=_or_garbage(()),
    boundary=_or_garbage(Boundary.rest([0.0, 0.0], [1.0, 1.0], 3)),
    limits=_or_garbage((_valid_limit,)),
    corridors=_or_garbage((_valid_corridor,)),
    hull=_or_garbage("bezier"),
)
def test_garbage_problem(**kwargs: Any) -> None:
    _construct_or_input_error(lambda: SmoothingProblem(**kwargs))


def test_complex_array_is_rejected() -> None:
    with pytest.raises(InputError, match=r"points\.points"):
        PointDeviation([1.0], np.array([[1.0 + 2.0j, 0.0]]))


@settings(max_examples=30, deadline=None)
@given(
    n=st.integers(1, 20),
    d=st.integers(1, 3),
    weight=st.floats(0.0, 1e5),
    gain=st.none() | st.floats(-1.0, 1.0),
)
def test_a_term_of_checked_arrays_is_the_validated_term(
    n: int, d: int, weight: float, gain: float | None
) -> None:
    """``PointDeviation.of_checked`` (the writing planner's terms, from arrays it
    checked once) holds what the validating constructor holds, a zero gain as None."""
    rng = np.random.default_rng(n * 7 + d)
    times, points = np.sort(rng.random(n)), rng.normal(size=(n, d))
    accel_gain = None if gain is None else np.full(d, gain)
    checked = PointDeviation.of_checked(times, points, weight, accel_gain)
    validated = PointDeviation(times, points, weight, accel_gain)
    assert np.array_equal(checked.times, validated.times)
    assert np.array_equal(checked.points, validated.points)
    assert checked.weight == validated.weight
    if validated.accel_gain is None:
        assert checked.accel_gain is None
    else:
        assert np.array_equal(checked.accel_gain, validated.accel_gain)
    assert [(m.tolist(), g) for m, g in checked.axis_groups()] == [
        (m.tolist(), g) for m, g in validated.axis_groups()
    ]


def test_a_term_of_checked_arrays_refuses_an_empty_selection() -> None:
    with pytest.raises(InputError, match="points: got times of shape \\(0,\\)"):
        PointDeviation.of_checked(np.zeros(0), np.zeros((0, 3)), 1.0)
