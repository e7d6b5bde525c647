"""The wall-time budget of one coverage plan: checked between steps, shared with the speed LP.

A plan is a chain of steps (the path, the speed LP's solves, the dense
check, the coverage measure). None of them can be interrupted from outside
cheaply, so the budget is cooperative: every step asks :meth:`Deadline.check`
before it starts, and the speed LP hands HiGHS what is left as its own time
limit. A plan therefore ends, or stops with an :class:`InfeasibleError`
naming the step it was in, within the budget plus one step.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from skyquill.errors import InfeasibleError, InputError

#: Default planning budget of ``plan_coverage`` and ``skyquill cover --time-limit``, s.
DEFAULT_TIME_LIMIT_S = 60.0
#: The constraint family an over-budget plan reports (``InfeasibleError.families``).
TIME_LIMIT = "time_limit"

#: ``progress(step, elapsed_s, limit_s)``: told at every step (a CLI draws a bar).
Progress = Callable[[str, float, float], None]


def check_time_limit(value: object, name: str = "time_limit") -> float:
    """``value`` as a budget in seconds: a finite number > 0."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InputError(f"{name}: got {type(value).__name__}, expected a number of seconds")
    seconds = float(value)
    if not (math.isfinite(seconds) and seconds > 0.0):
        raise InputError(f"{name}: got {seconds!r}, expected a finite number of seconds > 0")
    return seconds


@dataclass
class Deadline:
    """A budget of ``limit_s`` seconds from construction.

    Attributes
    ----------
    limit_s : float
        The budget, s.
    progress : Progress or None
        Told the step, the elapsed and the limit at every :meth:`check`.
    start : float
        ``time.perf_counter()`` at construction, s.
    """

    limit_s: float
    progress: Progress | None = None
    start: float = field(default_factory=time.perf_counter)

    def elapsed(self) -> float:
        """Seconds since the start."""
        return time.perf_counter() - self.start

    def remaining(self) -> float:
        """Seconds left (0 when spent)."""
        return max(self.limit_s - self.elapsed(), 0.0)

    def check(self, step: str) -> None:
        """Report ``step`` and refuse to start it once the budget is spent.

        Raises
        ------
        InfeasibleError
            With family :data:`TIME_LIMIT`; the message names the step.
        """
        elapsed = self.elapsed()
        if self.progress is not None:
            self.progress(step, elapsed, self.limit_s)
        if elapsed > self.limit_s:
            raise InfeasibleError(
                f"time_limit: got {self.limit_s:g} s, expected enough for this plan: it stopped "
                f"at {step} after {elapsed:.1f} s (allow more time, widen the swath or split "
                "the region)",
                (TIME_LIMIT,),
            )


def is_time_limit(exc: InfeasibleError) -> bool:
    """Whether ``exc`` is a spent budget (to be passed on, never taken for an infeasible trial)."""
    return TIME_LIMIT in exc.families
