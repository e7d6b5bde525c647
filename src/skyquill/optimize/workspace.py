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

from collections.abc import Callable
from typing import TypeVar

import numpy as np
import scipy.sparse as sp

from skyquill.optimize.assemble import Assembled, AssemblyCache, assemble
from skyquill.optimize.problem import SmoothingProblem
from skyquill.solvers import PiqpSession

T = TypeVar("T")


class Workspace:
    """Caches of one sequence of solves (module docstring)."""

    def __init__(self) -> None:
        self.assembly = AssemblyCache()
        self._sessions: dict[str, PiqpSession] = {}
        self._last: tuple[SmoothingProblem, Assembled] | None = None
        self._memo: dict[str, tuple[tuple[object, ...], object]] = {}
        self._kron: tuple[sp.csr_array, int, sp.csc_array] | None = None

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

    def memo(self, name: str, keys: tuple[object, ...], build: Callable[[], T]) -> T:
        """``build()``, re-used while ``keys`` are the very objects of the last call.

        For matrices derived from assembly blocks that :class:`AssemblyCache`
        hands out again unchanged (the same objects): identity is the exact
        key, and the memo holds the keys, so they cannot be recycled.
        """
        held = self._memo.get(name)
        same = held is not None and len(held[0]) == len(keys)
        if held is not None and same and all(a is b for a, b in zip(held[0], keys, strict=True)):
            return held[1]  # type: ignore[return-value]
        value = build()
        self._memo[name] = (keys, value)
        return value

    def kron_eye(self, A: sp.csr_array, d: int) -> sp.csc_array:
        """``kron(A, I_d)`` (CSC) of a canonical CSR ``A``, shape (M d, M d).

        The Hessians of one re-segmentation share their sparsity pattern (the
        band of the basis); the Kronecker product's pattern, and where each of
        its entries comes from in ``A.data``, are computed once by scipy's
        ``kron`` on the entry numbers and re-used while the pattern holds.
        """
        A = sp.csr_array(A)
        A.sum_duplicates()  # canonical: the pattern then says where each entry is
        held = self._kron
        if not (
            held is not None
            and held[1] == d
            and held[0].shape == A.shape
            and np.array_equal(held[0].indptr, A.indptr)
            and np.array_equal(held[0].indices, A.indices)
        ):
            numbers = sp.csr_array((np.arange(1.0, A.nnz + 1.0), A.indices, A.indptr), A.shape)
            held = (A, d, sp.kron(numbers, sp.eye_array(d), format="csc"))
            self._kron = held
        where = held[2]
        source = where.data.astype(np.intp) - 1
        return sp.csc_array((A.data[source], where.indices, where.indptr), shape=where.shape)

    @property
    def sessions(self) -> dict[str, PiqpSession]:
        """The PIQP sessions by route (a copy; for tests and benchmarks)."""
        return dict(self._sessions)
