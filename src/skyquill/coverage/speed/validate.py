"""Argument checks of :func:`~skyquill.coverage.speed.plan_speed`.

Every message names the argument, what came and what was expected.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from skyquill.errors import InputError
from skyquill.solvers.lp import LPBackend, resolve_backend
from skyquill.validation import FloatArray, as_float, as_int, per_axis

#: Grid kinds of :func:`~skyquill.coverage.speed.plan_speed`.
GRIDS = ("uniform", "adaptive")
#: Methods of :func:`~skyquill.coverage.speed.plan_speed`.
METHODS = ("auto", "reach", "warm", "banded", "lp")
#: Grid points from which ``method="auto"`` solves jerk-limited problems by the banded
#: interior point instead of the HiGHS LP (started at the interior point's first answer,
#: ``"warm"``). Measured end to end (``plan_speed``, one BLAS thread, 2 cores), on the
#: 10 m square's spiral per axis (bench/coverage_lp.py --scaling-only, session 38, 3 runs,
#: medians): the banded method's time over the warm-started LP's 2.4 at 500 points, 2.3 at
#: 2,000, 1.27 at 4,000, 0.78 at 8,000 (with the 16-gon, one run each: 1.12 at 4,000,
#: 0.69 at 8,000). Before the warm start, the banded method's over the LP's was 1.45 at
#: 2,000 points per axis (0.7 with the 16-gon), 0.8 / 0.38 at 4,000, 0.37 / 0.21 at
#: 8,000, and 2.8 on a coverage piece re-solved many times (the concave hexagon of
#: tests/coverage/test_deadline.py, 2,000 points, 16-gon, 54 solves): the simplex
#: re-solves from its last basis, the interior point from scratch. Coverage plans use at
#: most 4,000 points (the last grid, tried after two failed), where a grid that collapses
#: cost the interior point 17 s and the LP 6 s (the held-out 1.3 ha outline's spiral).
#: Session 39 (HiGHS on the rows that can bind, Devex pricing): the warm-started LP took
#: 0.74 / 1.37 s at 8,000 / 12,000 points per axis against the banded method's 1.21 / 1.90
#: s, 2.07 / 3.46 s against 5.16 / 8.21 s with the 16-gon; at 16,000 per axis HiGHS could
#: not start from the interior point's vertex and solved from scratch (7.6 s against 2.6 s;
#: with the 16-gon 6.1 s against 11.6 s). One run each of plan_speed on the spiral of
#: bench/coverage_lp.py, the method forced.
BANDED_FROM_POINTS = 16000
#: Fewest sides of the polygon that holds a norm limit.
MIN_NORM_SIDES = 4


@dataclass(frozen=True)
class Scalars:
    """The checked scalar arguments of ``plan_speed``."""

    n: int
    vmax: float
    control_period: float
    chord_error: float | None
    jerk_iterations: int
    jerk_tol: float
    safety: float


def _validate(
    curve: object,
    n: object,
    vmax: object,
    *,
    control_period: object,
    chord_error: object,
    jerk_iterations: object,
    jerk_tol: object,
    safety: object,
) -> Scalars:
    """Check the curve and the scalar arguments; their clean values."""
    if not callable(curve):
        raise InputError(f"curve: got {type(curve).__name__}, expected a callable curve(u, nu=k)")
    sf = as_float("safety", safety)
    if not 0.0 < sf <= 1.0:
        raise InputError(f"safety: got {sf:g}, expected a number in (0, 1]")
    return Scalars(
        n=as_int("n", n, low=3),
        vmax=as_float("vmax", vmax, positive=True),
        control_period=as_float("control_period", control_period, positive=True),
        chord_error=None
        if chord_error is None
        else as_float("chord_error", chord_error, positive=True),
        jerk_iterations=as_int("jerk_iterations", jerk_iterations, low=0),
        jerk_tol=as_float("jerk_tol", jerk_tol, nonneg=True),
        safety=sf,
    )


def _validate_refine(
    max_excess: object, refine_rounds: object, lp_backend: str, grid: object
) -> LPBackend:
    """Check the refinement/back-end/grid options; returns the back-end actually used."""
    if grid not in GRIDS:
        raise InputError(f"grid: got {grid!r}, expected one of {GRIDS}")
    if max_excess is not None:
        as_float("max_excess", max_excess, nonneg=True)
    as_int("refine_rounds", refine_rounds, low=0)
    return resolve_backend(lp_backend, argument="lp_backend")


def _validate_norm_sides(norm_sides: object, d: int) -> int | None:
    """``None`` (per-axis limits) or an even number of polygon sides >= 4 on a 2-D/3-D path."""
    if norm_sides is None:
        return None
    m = as_int("norm_sides", norm_sides, low=MIN_NORM_SIDES)
    if m % 2:
        # The LP's rows are two-sided (|n . a| <= r): a direction and its
        # opposite come in pairs, so an odd polygon would be held as its
        # 2m-gon intersection with its reflection.
        raise InputError(f"norm_sides: got {m}, expected an even integer >= {MIN_NORM_SIDES}")
    if d not in (2, 3):
        raise InputError(
            f"norm_sides: got {m} for a {d}-D path, expected None (norm limits need 2-D or 3-D)"
        )
    return m


def _validate_limits(
    amax: float | npt.ArrayLike,
    jmax: float | npt.ArrayLike | None,
    d: int,
    *,
    norm_sides: int | None,
) -> tuple[FloatArray, FloatArray | None]:
    """``amax``, ``jmax`` as ``(d,)`` arrays: per axis, or the one norm limit repeated."""
    if norm_sides is None:
        return per_axis("amax", amax, d), None if jmax is None else per_axis("jmax", jmax, d)
    # A norm limit is one number; an array here would be a per-axis intent.
    acc = np.full(d, as_float("amax", amax, positive=True))
    jerk = None if jmax is None else np.full(d, as_float("jmax", jmax, positive=True))
    return acc, jerk


def _validate_method(method: object, *, jerk: bool, n: int) -> str:
    """``"reach"``, ``"warm"``, ``"banded"`` or ``"lp"``: the solver ``method`` names for a
    problem with or without jerk on ``n`` grid points (without a jerk limit ``"warm"`` and
    ``"banded"`` are ``"reach"``: the same passes answer; ``"auto"`` with jerk is ``"warm"``
    below :data:`BANDED_FROM_POINTS` and ``"banded"`` from there)."""
    if method not in METHODS:
        raise InputError(f"method: got {method!r}, expected one of {METHODS}")
    if method == "reach" and jerk:
        raise InputError(
            "method: got 'reach' with a jerk limit, expected 'warm', 'banded', 'lp' or 'auto' (the "
            "passes hold speed and acceleration; jerk rows couple three nodes)"
        )
    if method == "auto":
        if not jerk:
            return "reach"
        return "banded" if n >= BANDED_FROM_POINTS else "warm"
    if method in ("warm", "banded") and not jerk:
        return "reach"
    return str(method)
