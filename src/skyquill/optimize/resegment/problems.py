"""The problem factory ``times -> SmoothingProblem`` and the checks of its contract.

Contract on ``make_problem(times)``: ``duration == times[-1]`` (times start
at 0), ``n_ctrl`` the same for every call (so that ``f`` is smooth in ``T``),
and the times enter only through point-deviation / interpolation terms whose
``times`` equal the argument (other time-tagged terms are taken as fixed in
seconds) and through ``alpha``. Smoothness weights, point weights, boundary
values and limits must not depend on the times.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from skyquill.errors import InputError
from skyquill.limits import DerivativeLimit
from skyquill.optimize.problem import Boundary, PointDeviation, SmoothingProblem
from skyquill.spline import HullKind
from skyquill.validation import FloatArray, as_array, strictly_increasing

ProblemFactory = Callable[[FloatArray], SmoothingProblem]


def point_fit_factory(
    points: FloatArray,
    n_ctrl: int,
    *,
    degree: int = 5,
    weight: float = 1e4,
    rest_orders: int = 3,
    limits: Sequence[DerivativeLimit] = (),
    hull: HullKind = "bspline",
) -> ProblemFactory:
    """The paper's problem for given times: jerk cost, point deviation, rest boundary.

    Parameters
    ----------
    points
        Shape (N, d), m.
    n_ctrl
        Control points, fixed for every ``times`` (paper 000: ``M + 6``).
    degree
        Spline degree (3 in paper 000).
    weight
        Point-deviation weight against the jerk cost (paper 000's ``1 / w_g``).
    rest_orders
        Position and derivatives ``1 .. rest_orders - 1`` fixed at both ends
        (zero derivatives: at rest).
    limits
        Derivative limits (the QP of paper 000 §5.3).
    hull
        Hull kind for the limits.

    Returns
    -------
    Callable
        ``make_problem(times) -> SmoothingProblem`` with ``duration = times[-1]``.
    """
    pts = as_array("points", points, ndim=2)
    boundary = Boundary.rest(pts[0], pts[-1], rest_orders)
    lims = tuple(limits)

    def make_problem(times: FloatArray) -> SmoothingProblem:
        return SmoothingProblem(
            dim=pts.shape[1],
            degree=degree,
            n_ctrl=n_ctrl,
            duration=float(times[-1]),
            smoothness={3: 1.0},
            deviations=(PointDeviation(times, pts, weight),),
            boundary=boundary,
            limits=lims,
            hull=hull,
        )

    return make_problem


def times_from_segments(T: FloatArray) -> FloatArray:
    """Point times (N,) from segment durations ``T`` (N - 1,), starting at 0."""
    return np.concatenate([[0.0], np.cumsum(T)])


def zero_based(name: str, times: FloatArray) -> FloatArray:
    """Validated strictly increasing times (N >= 2) with ``times[0] == 0``."""
    t = as_array(name, times, ndim=1)
    if t.size < 2:
        raise InputError(f"{name}: got {t.size} time(s), expected at least 2")
    strictly_increasing(name, t)
    if t[0] != 0.0:
        raise InputError(f"{name}: got {name}[0] = {t[0]:g}, expected 0 (the first point's time)")
    return t


def check_problem(problem: SmoothingProblem, t: FloatArray, n_ctrl: int | None) -> None:
    """Raise :class:`InputError` if ``problem`` (made for times ``t``) breaks the contract."""
    if not isinstance(problem, SmoothingProblem):
        raise InputError(
            f"make_problem: returned {type(problem).__name__}, expected a SmoothingProblem"
        )
    if abs(problem.duration - t[-1]) > 1e-12 * t[-1]:
        raise InputError(
            f"make_problem: got duration {problem.duration:.17g} s for times ending at "
            f"{t[-1]:.17g} s, expected duration == times[-1]"
        )
    if n_ctrl is not None and problem.n_ctrl != n_ctrl:
        raise InputError(
            f"make_problem: got n_ctrl = {problem.n_ctrl}, expected the same n_ctrl = {n_ctrl} "
            "for every call (f is only smooth in the times at a fixed knot count)"
        )


def check_initial(problem: SmoothingProblem, t: FloatArray) -> None:
    """Raise :class:`InputError` unless ``problem`` (of a given result) is made for times ``t``.

    Its duration must be ``t[-1]`` and every point-deviation time one of ``t``
    (the factory's contract); the result is then taken as the solve at ``t``.
    """
    check_problem(problem, t, None)
    tol = 1e-12 * max(1.0, float(t[-1]))
    for term in problem.deviations:
        if not isinstance(term, PointDeviation):
            continue
        idx = np.clip(np.searchsorted(t, term.times - tol), 0, t.size - 1)
        if not bool(np.all(np.abs(t[idx] - term.times) <= tol)):
            raise InputError(
                "initial_result: got a solve whose point times are not the times given, "
                "expected the solve of make_problem(times)"
            )
