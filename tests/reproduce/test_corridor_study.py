"""Paper 003 §5.4 reproduction: coupled against decoupled limits in the S corridor."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from skyquill.errors import InputError
from skyquill.limits import BoxLimit, CylinderLimit
from skyquill.reproduce.corridor import EQ55, eq55_limits, run_corridor_study

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def study(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict[str, object], Path]:
    out = tmp_path_factory.mktemp("corridor")
    # Reduced M grid: coupled-8 alone (44), both coupled (52), all three (60, 80).
    summary = run_corridor_study(
        EXAMPLES / "s_corridor.json", out, n_ctrl_values=(44, 52, 60, 80), repeats=1
    )
    return summary, out


def test_decoupled_box_is_the_largest_square_in_each_cylinder() -> None:
    for lim, (order, r, lo, hi) in zip(eq55_limits(None), EQ55, strict=True):
        assert isinstance(lim, BoxLimit) and lim.order == order
        np.testing.assert_allclose(lim.upper, [r / np.sqrt(2), r / np.sqrt(2), hi])
        np.testing.assert_allclose(lim.lower, [-r / np.sqrt(2), -r / np.sqrt(2), lo])
        # Its corners lie on the cylinder.
        assert np.hypot(lim.upper[0], lim.upper[1]) == pytest.approx(r)
    for lim in eq55_limits(6):
        assert isinstance(lim, CylinderLimit) and lim.sides == 6


def test_files_exist_and_summary_parses(study: tuple[dict[str, object], Path]) -> None:
    summary, out = study
    for name in ("fig10.png", "corridor.png", "results.json", "summary.json"):
        assert (out / name).stat().st_size > 0, name
    on_disk = json.loads((out / "summary.json").read_text())
    assert on_disk["variants"] == ["decoupled", "coupled-6", "coupled-8"]
    assert set(on_disk["n_feasible"]) == set(on_disk["variants"])
    assert on_disk["coupled_lower_cost_everywhere"] == summary["coupled_lower_cost_everywhere"]
    results = json.loads((out / "results.json").read_text())
    assert len(results["records"]) == 4 * 3


def test_coupled_costs_less_wherever_both_are_feasible(
    study: tuple[dict[str, object], Path],
) -> None:
    summary, out = study
    records = json.loads((out / "results.json").read_text())["records"]
    by = {(r["n_ctrl"], r["variant"]): r for r in records}
    compared = 0
    for m in (44, 52, 60, 80):
        dec = by[(m, "decoupled")]
        for name in ("coupled-6", "coupled-8"):
            cop = by[(m, name)]
            if dec["feasible"] and cop["feasible"]:
                assert cop["cost"] < dec["cost"], (m, name)
                compared += 1
    assert compared >= 2  # the comparison is not vacuous
    assert summary["coupled_lower_cost_everywhere"] is True


def test_every_feasible_solve_respects_limits_and_corridor(
    study: tuple[dict[str, object], Path],
) -> None:
    _, out = study
    records = json.loads((out / "results.json").read_text())["records"]
    feasible = [r for r in records if r["feasible"]]
    assert feasible
    for r in feasible:
        assert r["max_excess"] <= 1e-9, r["variant"]
        assert r["corridor_excess_m"] <= 1e-9, r["variant"]
        # The polytopes are inside the cylinders of eq. (55): those hold too.
        assert r["max_excess_eq55_cylinders"] <= 1e-9, r["variant"]


def test_coupled_is_feasible_with_fewer_control_points(
    study: tuple[dict[str, object], Path],
) -> None:
    summary, _ = study
    smallest = summary["smallest_feasible_n_ctrl"]
    assert isinstance(smallest, dict)
    assert smallest["coupled-8"] is not None
    assert smallest["decoupled"] is None or smallest["coupled-8"] < smallest["decoupled"]


def test_rejects_bad_arguments(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="n_ctrl_values"):
        run_corridor_study(EXAMPLES / "s_corridor.json", tmp_path, n_ctrl_values=())
    with pytest.raises(InputError, match=r"n_ctrl_values\[i\]: got 3"):
        run_corridor_study(EXAMPLES / "s_corridor.json", tmp_path, n_ctrl_values=(3,))
    with pytest.raises(InputError, match=r"sides\[i\]: got 2"):
        run_corridor_study(EXAMPLES / "s_corridor.json", tmp_path, sides=(2,))


def test_a_study_without_one_feasible_solve_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Issue 25: no feasible solve exited 0 with ``coupled_lower_cost_everywhere: true``."""
    from typer.testing import CliRunner

    from skyquill.cli.main import app
    from skyquill.errors import InfeasibleError
    from skyquill.reproduce import corridor

    def infeasible(*_: object) -> None:
        raise InfeasibleError("limits: got an empty feasible set", ("corridor",))

    monkeypatch.setattr(corridor, "solve", infeasible)
    with pytest.raises(InfeasibleError, match="corridor: got no feasible solve for any of M"):
        run_corridor_study(EXAMPLES / "s_corridor.json", tmp_path / "o", n_ctrl_values=(44,))
    result = CliRunner().invoke(app, ["reproduce", "corridor", "--out", str(tmp_path / "cli")])
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert result.exit_code == 2 and len(lines) == 1, result.output
    assert lines[0].startswith("error: corridor: got no feasible solve")
    assert not (tmp_path / "cli" / "summary.json").exists()
