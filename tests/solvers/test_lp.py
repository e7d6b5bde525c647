"""The rebuild-free LP adapter: both backends against closed forms and each other."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import skyquill.solvers.lp as lp_module
from skyquill.errors import InputError
from skyquill.solvers.lp import LinearProgram, highspy_available, resolve_backend, vertex_basis
from skyquill.validation import FloatArray

BACKENDS = ["linprog", *(["highspy"] if highspy_available() else [])]


def _box_lp(backend: str) -> LinearProgram:
    # max x + y  s.t.  -1 <= x - y <= 1,  x + 2y <= 4  (rows), 0 <= x, y.
    a = sp.csr_array(np.array([[1.0, -1.0], [1.0, 2.0]]))
    lp = LinearProgram(a, [-1.0, -1.0], backend=backend)
    lp.update_bounds(row_lower=np.array([-1.0, -np.inf]), row_upper=np.array([1.0, 4.0]))
    return lp


@pytest.mark.parametrize("backend", BACKENDS)
def test_optimum_matches_the_vertex(backend: str) -> None:
    lp = _box_lp(backend)
    sol = lp.solve()
    # Vertex of x - y = 1 and x + 2y = 4: x = 2, y = 1.
    assert sol.status == "optimal" and sol.solver == backend
    assert sol.x is not None
    assert np.allclose(sol.x, [2.0, 1.0], atol=1e-9)
    assert lp.solves == 1 and lp.solve_time_s >= 0.0


@pytest.mark.parametrize("backend", BACKENDS)
def test_re_solve_after_bound_changes(backend: str) -> None:
    lp = _box_lp(backend)
    lp.solve()
    lp.update_bounds(col_upper=np.array([1.5, np.inf]))
    sol = lp.solve()
    assert sol.x is not None
    # x capped at 1.5: y = min(1.5 + 1, (4 - 1.5) / 2) = 1.25.
    assert np.allclose(sol.x, [1.5, 1.25], atol=1e-9)
    lp.update_bounds(row_upper=np.array([1.0, 1.0]), col_upper=np.array([np.inf, np.inf]))
    sol = lp.solve()
    assert sol.x is not None
    # x - y <= 1 and x + 2y <= 1: x = 1, y = 0.
    assert np.allclose(sol.x, [1.0, 0.0], atol=1e-9)
    assert lp.solves == 3


@pytest.mark.parametrize("backend", BACKENDS)
def test_added_rows_cut_the_last_optimum(backend: str) -> None:
    lp = _box_lp(backend)
    lp.solve()  # at (2, 1)
    lp.add_rows(sp.csr_array(np.array([[1.0, 0.0]])), np.array([-np.inf]), np.array([1.5]))
    sol = lp.solve()
    assert sol.x is not None and lp.a.shape == (3, 2)
    # x <= 1.5 cuts (2, 1) off: y = min(1.5 + 1, (4 - 1.5) / 2) = 1.25.
    assert np.allclose(sol.x, [1.5, 1.25], atol=1e-9)
    # The new row's bounds move like the others.
    lp.update_bounds(row_lower=np.array([-1.0, -np.inf, -np.inf]),
                     row_upper=np.array([1.0, 4.0, 1.0]))  # fmt: skip
    sol = lp.solve()
    assert sol.x is not None and np.allclose(sol.x, [1.0, 1.5], atol=1e-9)


def test_added_rows_of_the_wrong_shape_are_refused() -> None:
    lp = _box_lp("linprog")
    with pytest.raises(InputError, match="expected"):
        lp.add_rows(sp.csr_array(np.ones((1, 3))), np.zeros(1), np.ones(1))
    with pytest.raises(InputError, match="expected"):
        lp.add_rows(sp.csr_array(np.ones((1, 2))), np.zeros(2), np.ones(2))


@pytest.mark.parametrize("backend", BACKENDS)
def test_infeasible_is_a_status(backend: str) -> None:
    lp = _box_lp(backend)
    lp.update_bounds(row_lower=np.array([-1.0, -np.inf]), row_upper=np.array([1.0, -1.0]))
    sol = lp.solve()
    assert sol.status == "infeasible" and sol.x is None


def test_backends_agree_on_a_random_lp() -> None:
    if not highspy_available():
        pytest.skip("highspy not installed")
    rng = np.random.default_rng(3)
    a = sp.random_array((40, 25), density=0.3, rng=rng, format="csr")
    cost = -rng.uniform(0.5, 1.5, 25)
    xs = []
    for backend in ("highspy", "linprog"):
        lp = LinearProgram(a, cost, backend=backend)
        for scale in (1.0, 0.7):
            rows = np.full(40, scale)
            lp.update_bounds(row_lower=-rows, row_upper=rows, col_upper=np.full(25, 3.0))
            sol = lp.solve()
        assert sol.x is not None
        xs.append(sol.x)
    assert cost @ xs[0] == pytest.approx(cost @ xs[1], rel=1e-9)


def test_bad_arguments_are_named() -> None:
    a = sp.csr_array(np.eye(2))
    with pytest.raises(InputError, match=r"^cost: got shape"):
        LinearProgram(a, [1.0, 2.0, 3.0])
    with pytest.raises(InputError, match=r"^backend: got 'glpk'"):
        LinearProgram(a, [1.0, 1.0], backend="glpk")
    with pytest.raises(InputError, match=r"^lp_backend: got 'cplex'"):
        resolve_backend("cplex")
    lp = LinearProgram(a, [1.0, 1.0])
    with pytest.raises(InputError, match=r"^col_upper: got shape"):
        lp.update_bounds(col_upper=np.ones(3))


def test_a_stalled_hot_start_is_told_by_iterations_and_solved_cold(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """No wall-time guess: the same problem takes the same path on a busy machine."""
    if not highspy_available():
        pytest.skip("highspy not installed")
    monkeypatch.setattr(lp_module, "HOT_SOLVE_ITERATIONS_PER_COLUMN", 0)
    lp = _box_lp("highspy")
    sol = lp.solve()
    assert sol.status == "optimal" and sol.solver == "linprog"
    assert lp.backend == "linprog"  # for good


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_spent_time_limit_is_a_status(backend: str) -> None:
    rng = np.random.default_rng(5)
    a = sp.random_array((3000, 1500), density=0.01, rng=rng, format="csr")
    lp = LinearProgram(a, -rng.uniform(0.5, 1.5, 1500), backend=backend, time_limit_s=1e-6)
    lp.update_bounds(row_lower=-np.ones(3000), row_upper=np.ones(3000))
    assert lp.solve().status == "time_limit"


@pytest.mark.skipif(not highspy_available(), reason="highspy is not installed")
def test_the_first_highs_model_prints_nothing_on_stdout() -> None:
    # HiGHS prints its banner once per process, at the first instance's first call:
    # only a fresh interpreter shows whether it reaches stdout (it did, in `cover`).
    import subprocess
    import sys

    script = (
        "import numpy as np, scipy.sparse as sp\n"
        "from skyquill.solvers.lp import LinearProgram\n"
        "lp = LinearProgram(sp.csr_array(np.eye(2)), [-1.0, -1.0], backend='highspy')\n"
        "lp.update_bounds(row_lower=np.zeros(2), row_upper=np.ones(2))\n"
        "lp.solve()\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=120, check=True
    )
    assert done.stdout == ""


def _random_lp(seed: int) -> tuple[LinearProgram, FloatArray]:
    """A random LP with 150 columns and 600 two-sided rows, and a point 1e-9 from its
    optimum inside it: HiGHS's interior point, stopped before its crossover."""
    rng = np.random.default_rng(seed)
    a = sp.random_array((600, 150), density=0.05, rng=rng, format="csr")
    cost = -rng.uniform(0.5, 1.5, 150)
    lp = LinearProgram(a, cost, backend="highspy")
    rows = rng.uniform(0.5, 2.0, 600)
    lp.update_bounds(row_lower=-rows, row_upper=rows, col_upper=np.full(150, 3.0))
    interior = LinearProgram(a, cost, backend="highspy")
    interior.update_bounds(row_lower=-rows, row_upper=rows, col_upper=np.full(150, 3.0))
    assert interior._highs is not None
    options = {"solver": "ipm", "run_crossover": "off", "ipm_optimality_tolerance": 1e-10}
    for option, value in options.items():
        interior._highs.highs.setOptionValue(option, value)
    sol = interior.solve()
    assert sol.status == "optimal" and sol.x is not None
    return lp, sol.x


def _pivots(lp: LinearProgram) -> int:
    assert lp._highs is not None
    return int(lp._highs.highs.getInfo().simplex_iteration_count)


@pytest.mark.skipif(not highspy_available(), reason="highspy not installed")
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_start_near_the_optimum_gives_its_vertex_in_a_few_pivots(seed: int) -> None:
    lp, near = _random_lp(seed)
    cold = lp.solve()
    cold_pivots = _pivots(lp)
    lp, near = _random_lp(seed)
    started = lp.solve(start=near)
    assert started.status == "optimal" and started.x is not None and cold.x is not None
    assert lp.cost @ started.x == pytest.approx(lp.cost @ cold.x, rel=1e-9)
    assert _pivots(lp) <= max(5, cold_pivots // 10)


@pytest.mark.skipif(not highspy_available(), reason="highspy not installed")
def test_any_start_gives_the_optimum() -> None:
    lp, _ = _random_lp(4)
    cold = lp.solve()
    assert cold.x is not None
    for start in (np.zeros(150), np.full(150, 3.0), np.random.default_rng(0).uniform(0, 3, 150)):
        lp, _ = _random_lp(4)
        got = lp.solve(start=start)
        assert got.status == "optimal" and got.x is not None
        assert lp.cost @ got.x == pytest.approx(lp.cost @ cold.x, rel=1e-9)


@pytest.mark.skipif(not highspy_available(), reason="highspy not installed")
def test_a_basis_highs_cannot_go_on_from_is_dropped_for_the_last_one(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A basis HiGHS stops on ("excessive dual values", "Not Set"): solved from the last."""
    highspy = pytest.importorskip("highspy")
    lp, near = _random_lp(5)
    cold = lp.solve()
    assert cold.x is not None
    assert lp._highs is not None
    runs: list[float] = []
    real_run = lp._highs._run

    def first_run_fails(limit_s: float) -> object:
        runs.append(limit_s)
        status = real_run(limit_s)
        return highspy.HighsModelStatus.kNotset if len(runs) == 1 else status

    monkeypatch.setattr(lp._highs, "_run", first_run_fails)
    lp.update_bounds(col_upper=np.full(150, 2.0))
    got = lp.solve(start=near)
    assert len(runs) == 2 and got.status == "optimal" and got.x is not None
    check = LinearProgram(lp.a, lp.cost, backend="highspy")
    check.update_bounds(row_lower=lp.row_lower, row_upper=lp.row_upper, col_upper=lp.col_upper)
    ref = check.solve()
    assert ref.x is not None
    assert lp.cost @ got.x == pytest.approx(lp.cost @ ref.x, rel=1e-9)


def test_no_vertex_where_fewer_bounds_than_columns() -> None:
    if not highspy_available():
        pytest.skip("highspy not installed")
    a = sp.csr_array(np.array([[1.0, 1.0]]))
    lp = LinearProgram(a, [-1.0, -1.0], backend="highspy")
    lp.update_bounds(row_upper=np.array([1.0]), col_lower=np.full(2, -np.inf))
    assert vertex_basis(lp, np.array([0.5, 0.5])) is None
    sol = lp.solve(start=np.array([0.5, 0.5]))
    assert sol.status == "optimal" and sol.x is not None
    assert sol.x.sum() == pytest.approx(1.0)


@pytest.mark.skipif(not highspy_available(), reason="highspy not installed")
def test_a_stalled_hot_start_starts_again_from_the_restart_point(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """With a restart point the stall is told early and HiGHS, not linprog, answers."""
    lp, near = _random_lp(6)
    lp.solve()
    moved = lp.row_upper * np.random.default_rng(7).uniform(0.3, 1.0, lp.row_upper.size)
    lp.update_bounds(row_lower=-moved, row_upper=moved)  # pivots to make from the last basis
    check = LinearProgram(lp.a, lp.cost, backend="highspy")
    check.update_bounds(row_lower=lp.row_lower, row_upper=lp.row_upper, col_upper=lp.col_upper)
    cold = check.solve()
    assert cold.x is not None
    monkeypatch.setattr(lp_module, "RESTART_ITERATIONS_PER_COLUMN", 0)
    asked: list[int] = []

    def restart() -> FloatArray:
        asked.append(1)
        return near

    got = lp.solve(restart=restart)
    assert asked == [1] and got.solver == "highspy" and lp.backend == "highspy"
    assert got.status == "optimal" and got.x is not None
    assert lp.cost @ got.x == pytest.approx(lp.cost @ cold.x, rel=1e-9)
    # No restart point: linprog, for good, as before.
    moved = lp.row_upper * np.random.default_rng(8).uniform(0.3, 1.0, lp.row_upper.size)
    lp.update_bounds(row_lower=-moved, row_upper=moved)
    got = lp.solve(restart=lambda: None)
    assert got.solver == "linprog" and lp.backend == "linprog"
