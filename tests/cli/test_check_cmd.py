"""``skyquill check``: exit 0 on a pass, 1 on a failure, 2 with one line for bad input."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from skyquill.cli.main import app

sys.path.insert(0, str(Path(__file__).parents[1] / "show"))
from show_cases import plan, planted, row

runner = CliRunner()


@pytest.fixture(scope="module")
def safe(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return plan(tmp_path_factory.mktemp("safe"), row(0.0))


@pytest.fixture(scope="module")
def close(tmp_path_factory: pytest.TempPathFactory) -> Path:
    hover, flyer, _ = planted()
    return plan(tmp_path_factory.mktemp("close"), [hover, flyer])


def _one_error_line(output: str) -> str:
    lines = [line for line in output.splitlines() if line.strip()]
    assert len(lines) == 1, output
    assert "Traceback" not in output
    return lines[0]


def test_a_safe_show_passes_and_writes_a_summary(safe: Path, tmp_path: Path) -> None:
    out = tmp_path / "report"
    result = runner.invoke(app, ["check", str(safe), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "(guaranteed)" in result.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["passed"] is True
    assert summary["separation"]["guaranteed_lower_bound_m"] >= 3.0
    assert summary["paths"] == [str(safe)]


def test_the_planted_violation_fails_with_exit_1(close: Path) -> None:
    result = runner.invoke(app, ["check", str(close), "--max-speed-xy", "25", "--json"])
    assert result.exit_code == 1, result.output
    summary = json.loads(result.stdout)
    (violation,) = summary["violations"]
    assert violation["check"] == "separation"
    assert violation["drones"] == [f"{close.name}/trajectory_0", f"{close.name}/trajectory_1"]
    assert violation["first_time_s"] == pytest.approx(5.075, abs=1e-5)


def test_the_table_names_the_failure(close: Path) -> None:
    result = runner.invoke(app, ["check", str(close)])
    assert result.exit_code == 1
    assert "FAILED" in result.output and "separation" in result.output
    assert "speed_xy" in result.output  # the flyer's 20 m/s


def test_a_skyc_and_a_plan_together(safe: Path, tmp_path: Path) -> None:
    show = tmp_path / "show.skyc"
    exported = runner.invoke(app, ["export", str(safe), "--format", "skyc", "--out", str(show)])
    assert exported.exit_code == 0, exported.output
    other = plan(tmp_path / "other", row(12.0))
    result = runner.invoke(app, ["check", str(show), str(other), "--json"])
    assert result.exit_code == 0, result.output
    assert len(json.loads(result.stdout)["drones"]) == 6
    # The plan and its own export fly the same drones: 0 m apart.
    both = runner.invoke(app, ["check", str(show), str(safe), "--json"])
    assert both.exit_code == 1


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--min-distance", "-1"], "error: --min-distance: got -1, expected a finite number >= 0"),
        (["--max-speed-up", "nan"], "error: --max-speed-up: got nan, expected"),
        (["--geofence", "missing.geojson"], "error: --geofence: got 'missing.geojson'"),
    ],
)
def test_bad_options_are_one_line_exit_2(safe: Path, args: list[str], message: str) -> None:
    result = runner.invoke(app, ["check", str(safe), *args])
    assert result.exit_code == 2
    assert _one_error_line(result.output).startswith(message)


def test_bad_paths_are_one_line_exit_2(tmp_path: Path) -> None:
    odd = tmp_path / "show.txt"
    odd.write_text("x")
    for path, message in [
        (tmp_path / "nope", "which does not exist"),
        (odd, "expected a plan directory or a file ending in"),
    ]:
        result = runner.invoke(app, ["check", str(path)])
        assert result.exit_code == 2
        assert message in _one_error_line(result.output)


def test_a_geofence_that_excludes_the_start_is_exit_2(safe: Path, tmp_path: Path) -> None:
    fence = tmp_path / "fence.wkt"
    fence.write_text("POLYGON ((1 -1, 5 -1, 5 20, 1 20, 1 -1))")
    result = runner.invoke(app, ["check", str(safe), "--geofence", str(fence)])
    assert result.exit_code == 2
    line = _one_error_line(result.output)
    assert line.startswith("error: --geofence: got a fence that excludes")


def test_a_geofence_breach_later_is_exit_1(safe: Path, tmp_path: Path) -> None:
    fence = tmp_path / "fence.wkt"
    fence.write_text("POLYGON ((-1 -1, 3 -1, 3 20, -1 20, -1 -1))")  # the drones fly to x = 4
    result = runner.invoke(app, ["check", str(safe), "--geofence", str(fence), "--json"])
    assert result.exit_code == 1
    checks = {v["check"] for v in json.loads(result.stdout)["violations"]}
    assert checks == {"geofence"}


def test_a_show_skyquill_writes_passes_its_own_check(tmp_path: Path) -> None:
    out = tmp_path / "w"
    written = runner.invoke(app, ["write", "一马", "--drones", "2", "--out", str(out)])
    assert written.exit_code == 0, written.output
    claimed = json.loads((out / "summary.json").read_text())["min_separation_m"]
    result = runner.invoke(app, ["check", str(out), "--min-distance", "1.0", "--json"])
    assert result.exit_code == 0, result.output
    separation = json.loads(result.stdout)["separation"]
    assert separation["guaranteed_lower_bound_m"] == pytest.approx(claimed, abs=1e-9)
