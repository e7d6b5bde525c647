"""One exception tree for everything skyquill raises on purpose.

``SkyquillError`` is the root; callers that want to catch "anything skyquill
refused or could not do" catch it. Each subclass says *whose* fault it is:

* :class:`InputError` -- the caller gave something malformed (wrong shape,
  NaN, a negative limit, ...). The message names the argument, what was
  received and what was expected.
* :class:`InfeasibleError` -- the input is well formed but the constraints
  cannot all be met (for example a jerk limit too small for the time given).
* :class:`SolverError` -- a numerical backend failed for a reason that is not
  infeasibility (iteration limit, numerical trouble).
"""

from __future__ import annotations


class SkyquillError(Exception):
    """Root of every error skyquill raises deliberately."""


class InputError(SkyquillError, ValueError):
    """Malformed input: names the argument, what came and what was expected."""


class InfeasibleError(SkyquillError):
    """The constraints asked for cannot all be satisfied.

    Parameters
    ----------
    message
        Human-readable explanation.
    families
        The constraint families (e.g. ``"limit:order=3"``, ``"corridor[2]"``)
        that were found infeasible, as far as could be determined.
    """

    def __init__(self, message: str, families: tuple[str, ...] = ()) -> None:
        super().__init__(message)
        self.families = families


class SolverError(SkyquillError):
    """A numerical backend failed for a reason other than infeasibility."""
