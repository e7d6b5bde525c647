"""The command line: fit and demo write what they promise; user errors exit 2 cleanly."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from skyquill.cli.main import app

EXAMPLES = Path(__file__).parents[2] / "examples"
SUMMARY_KEYS = {
    "duration_s",
    "solve_time_s",
    "cost",
    "max_speed",
    "max_acc",
    "max_jerk",
    "max_excess",
    "rms_deviation_m",
    "max_deviation_m",
}
runner = CliRunner()


def test_fit_writes_trajectory_plot_and_summary(tmp_path: Path) -> None:
    out = tmp_path / "fit"
    result = runner.invoke(
        app,
        [
            "fit",
            str(EXAMPLES / "segments.csv"),
            "--out",
            str(out),
            "--norm-sides",
            "8",
            "--vmax",
            "1.5",
            "--amax",
            "1.0",
            "--jmax",
            "4",
            "--rate",
            "50",
        ],
    )
    assert result.exit_code == 0, result.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary.keys() >= SUMMARY_KEYS
    assert summary["max_excess"] <= 1e-9
    assert len(summary["max_acc"]) == 3
    data = np.loadtxt(out / "trajectory.csv", delimiter=",", skiprows=1)
    assert data.shape[1] == 13
    assert np.diff(data[:, 0]).max() == pytest.approx(0.02)
    assert (out / "plot.png").stat().st_size > 10_000


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["fit", "missing.csv"], "expected an existing CSV file"),
        (["fit", str(EXAMPLES / "segments.csv"), "--vmax", "-1"], "vmax: got -1"),
        (["fit", str(EXAMPLES / "segments.csv"), "--degree", "9"], "degree: got 9"),
        (["fit", str(EXAMPLES / "segments.csv"), "--rate", "0"], "--rate: got 0"),
        (["fit", str(EXAMPLES / "segments.csv"), "--hull", "round"], "--hull: got 'round'"),
        (["fit", str(EXAMPLES / "segments.csv"), "--solver", "cplex"], "solver: got 'cplex'"),
        (
            ["fit", str(EXAMPLES / "segments.csv"), "--target", "tello"],
            "--target: got 'tello', expected one of crazyflie",
        ),
    ],
)
def test_user_errors_exit_2_with_one_line(tmp_path: Path, args: list[str], message: str) -> None:
    result = runner.invoke(app, [*args, "--out", str(tmp_path / "o")])
    assert result.exit_code == 2
    assert message in " ".join(result.output.split())
    assert "Traceback" not in result.output


def test_timing_choices(tmp_path: Path) -> None:
    """Tablet clock, re-timed along the path, or rest at every waypoint."""
    spiral = str(EXAMPLES / "spiral.csv")
    given = runner.invoke(app, ["fit", spiral, "--out", str(tmp_path / "g")])
    path = runner.invoke(app, ["fit", spiral, "--timing", "path", "--out", str(tmp_path / "p")])
    assert given.exit_code == 0 and path.exit_code == 0
    g = json.loads((tmp_path / "g" / "summary.json").read_text())
    p = json.loads((tmp_path / "p" / "summary.json").read_text())
    # The hand does not start at rest; re-timed, the fit follows the ink closely.
    assert p["rms_deviation_m"] < 0.005 < g["rms_deviation_m"]
    seg = runner.invoke(
        app,
        [
            "fit",
            str(EXAMPLES / "segments.csv"),
            "--timing",
            "segments",
            "--out",
            str(tmp_path / "s"),
        ],
    )
    assert seg.exit_code == 0
    s = json.loads((tmp_path / "s" / "summary.json").read_text())
    # Through every corner to 1.5 mm (the jerk norm, not a per-axis box, binds there).
    assert s["max_deviation_m"] < 2e-3


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--timing", "given"], "segments.csv has no t column"),
        (["--timing", "clock"], "--timing: got 'clock', expected given, path or segments"),
    ],
)
def test_bad_timing(tmp_path: Path, args: list[str], message: str) -> None:
    result = runner.invoke(
        app, ["fit", str(EXAMPLES / "segments.csv"), *args, "--out", str(tmp_path / "o")]
    )
    assert result.exit_code == 2
    assert message in " ".join(result.output.split())


def test_fit_for_a_crazyflie_writes_uploads_into_the_summary(tmp_path: Path) -> None:
    from skyquill.io.trajectory_json import read_trajectory_json
    from skyquill.targets import CRAZYFLIE, plan_uploads

    out = tmp_path / "fit"
    args = ["fit", str(EXAMPLES / "spiral.csv"), "--out", str(out), "--timing", "path"]
    result = runner.invoke(app, [*args, "--tolerance", "0.005", "--target", "crazyflie"])
    assert result.exit_code == 0, result.output
    summary = json.loads((out / "summary.json").read_text())
    target = summary["target"]
    assert target["name"] == "crazyflie" and target["strategy"] == "split"
    assert summary["degree"] == 7 and summary["max_deviation_m"] <= 0.005
    written = read_trajectory_json(out / "trajectory.json").trajectory
    uploads = plan_uploads(written, CRAZYFLIE)
    assert [u["pieces"] for u in target["uploads"]] == [u.pieces for u in uploads]
    assert all(u.pieces <= 31 for u in uploads) and len(uploads) >= 2
    assert [u["hover_before_s"] for u in target["uploads"]][1:] == [1.0] * (len(uploads) - 1)
    assert summary["plan"]["drones"][0]["verification"]["max_excess"] <= 1e-9
