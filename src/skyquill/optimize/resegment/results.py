"""What the re-segmentation returns: the time gradient and the descent's outcome."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from skyquill.optimize.solve import FitResult
from skyquill.validation import FloatArray

Mode = Literal["fixed", "free"]
Status = Literal["converged", "max_iter", "stalled"]


@dataclass(frozen=True)
class TimeGradient:
    """The smoothing cost and its gradient with respect to the point times.

    Attributes
    ----------
    cost
        ``f``: the engine's optimal cost (``FitResult.cost``), no time price.
    grad_times
        ``df/dt_j``, shape (N,), cost per second; entry 0 belongs to
        ``t_0 = 0``, which is not a variable.
    grad_segments
        ``df/dT_i``, shape (N - 1,).
    result
        The solve at these times.
    n_active
        Number of inequality rows with a positive multiplier.
    stationarity_residual
        Relative residual ``||grad J + E'Lambda + G'mu + A_c' z_c||`` (``z_c``:
        cone multipliers, :attr:`FitResult.cone_z`) against the larger
        of the two parts of ``grad J = 2 H x + f`` (0 when no multiplier was
        needed) at the point the gradient was taken.
    polished_cost
        Cost at that point: on the QP route the exact minimiser on the active
        set of the solver's duals (:mod:`.polish`), of which the gradient is
        the exact derivative; equal to ``cost`` on the closed-form route. The
        QP backends' ``cost`` can lie above it by ~1e-8 relative.
    n_active_cones
        Number of second-order cones (hull points of exact norm limits) with
        a positive multiplier.
    """

    cost: float
    grad_times: FloatArray
    grad_segments: FloatArray
    result: FitResult
    n_active: int
    stationarity_residual: float
    polished_cost: float
    n_active_cones: int = 0


@dataclass(frozen=True)
class ResegmentResult:
    """Outcome of :func:`skyquill.optimize.resegment.resegment`.

    Attributes
    ----------
    times
        Optimised point times, shape (N,), s, ``times[0] = 0``.
    result
        The engine's solve at ``times``.
    mode
        ``"fixed"`` or ``"free"``.
    time_penalty
        ``rho`` of the objective ``f + rho * total_time`` (cost per second).
    history
        Objective ``f + rho * total_time`` at every accepted iterate, the
        initial one first; non-increasing. Shape (iterations + 1,).
    total_time_history
        Total time at every accepted iterate, s.
    iterations
        Accepted descent steps.
    status
        ``"converged"`` (scaled gradient below ``tol`` or relative decrease
        below ``ftol``), ``"max_iter"``, or ``"stalled"`` (the line search
        found no decrease: the objective is flat to the solver's accuracy).
    gradient_norm
        2-norm of the (projected, in fixed mode) gradient in ``T`` at the end;
        ``nan`` where :func:`resegment` was asked not to compute it
        (``final_gradient=False``).
    n_solves
        Engine solves, line search included.
    elapsed_s
        Wall time of the whole run.
    gradient_time_s
        Wall time spent in the analytic gradients (solves excluded).
    initial_times
        The starting times (shifted to start at 0), shape (N,).
    """

    times: FloatArray
    result: FitResult
    mode: Mode
    time_penalty: float
    history: FloatArray
    total_time_history: FloatArray
    iterations: int
    status: Status
    gradient_norm: float
    n_solves: int
    elapsed_s: float
    gradient_time_s: float
    initial_times: FloatArray

    @property
    def cost(self) -> float:
        """Final smoothing cost ``f`` (without the time price)."""
        return self.result.cost

    @property
    def total_time(self) -> float:
        """Final total time, s."""
        return float(self.times[-1])
