"""What a sequence of solves of closely related problems can share.

Re-segmentation solves a dozen problems that differ only in the point times
(paper 000 §5.4), and takes the gradient at each accepted one. A
:class:`Workspace` carries between those solves:

* the assembly blocks the times do not change (:class:`AssemblyCache`);
* one PIQP session per QP route (:class:`skyquill.solvers.PiqpSession`):
  the programs of one route keep their sparsity pattern, so PIQP is updated
  instead of set up;
* the assembly of the last problem solved, so that the gradient's
  multipliers (:mod:`skyquill.optimize.resegment.multipliers`) do not
  assemble it again.

A workspace belongs to one caller and one sequence (it holds no global
state, and is not thread-safe). A result solved with a workspace is the one
a fresh solve returns, to the QP backend's tolerance
(``tests/optimize/test_workspace.py``).
"""

from __future__ import annotations

from skyquill.optimize.assemble import Assembled, AssemblyCache, assemble
from skyquill.optimize.problem import SmoothingProblem
from skyquill.solvers import PiqpSession


class Workspace:
    """Caches of one sequence of solves (module docstring)."""

    def __init__(self) -> None:
        self.assembly = AssemblyCache()
        self._sessions: dict[str, PiqpSession] = {}
        self._last: tuple[SmoothingProblem, Assembled] | None = None

    def session(self, route: str) -> PiqpSession:
        """The PIQP session of a QP route (``"qp"``, ``"relaxed"``): one sparsity pattern each."""
        return self._sessions.setdefault(route, PiqpSession())

    def assemble(self, problem: SmoothingProblem) -> Assembled:
        """``assemble(problem)``, re-using the last one for the same problem object."""
        if self._last is not None and self._last[0] is problem:
            return self._last[1]
        asm = assemble(problem, self.assembly)
        self._last = (problem, asm)
        return asm

    @property
    def sessions(self) -> dict[str, PiqpSession]:
        """The PIQP sessions by route (a copy; for tests and benchmarks)."""
        return dict(self._sessions)
