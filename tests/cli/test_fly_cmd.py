"""``skyquill fly``: flies a fitted trajectory, writes its files, refuses bad input with exit 2."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from skyquill.cli.main import app
from skyquill.io.trajectory_csv import FLIGHT_COLUMNS

EXAMPLES = Path(__file__).parents[2] / "examples"
SUMMARY_KEYS = {
    "rmse_m",
    "max_error_m",
    "vel_rmse_mps",
    "saturations",
    "sim_time_s",
    "wall_time_s",
    "controller",
    "sim",
    "realtime_factor",
    "duration_s",
    "rate_hz",
    "seed",
}
runner = CliRunner()


@pytest.fixture(scope="module")
def spiral(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The hand-drawn spiral fitted by ``skyquill fit`` (0.8 m across, 6.6 s)."""
    out = tmp_path_factory.mktemp("fit")
    result = runner.invoke(app, ["fit", str(EXAMPLES / "spiral.csv"), "--out", str(out)])
    assert result.exit_code == 0, result.output
    return out / "trajectory.csv"


def fly(trajectory: Path, out: Path, *args: str) -> dict[str, Any]:
    result = runner.invoke(app, ["fly", str(trajectory), "--out", str(out), *args])
    assert result.exit_code == 0, result.output
    summary: dict[str, Any] = json.loads((out / "summary.json").read_text())
    return summary


@pytest.fixture(scope="module")
def flown(spiral: Path, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """One undisturbed flight per controller: ``{controller: out dir}``."""
    outs = {}
    for controller in ("rpt", "pid-ff", "pid"):
        out = tmp_path_factory.mktemp(controller)
        fly(spiral, out, "--controller", controller)
        outs[controller] = out
    return outs


def summary_of(out: Path) -> dict[str, Any]:
    data: dict[str, Any] = json.loads((out / "summary.json").read_text())
    return data


@pytest.mark.parametrize("controller", ["rpt", "pid-ff", "pid"])
def test_each_controller_writes_summary_flight_and_plot(
    flown: dict[str, Path], controller: str
) -> None:
    out = flown[controller]
    summary = summary_of(out)
    assert summary.keys() >= SUMMARY_KEYS
    assert summary["controller"] == controller and summary["sim"] == "skyquill"
    assert summary["rate_hz"] == 500.0
    assert summary["sim_time_s"] == pytest.approx(summary["duration_s"])
    assert set(summary["saturations"]) == {"thrust_max", "thrust_min", "tilt"}
    lines = (out / "flight.csv").read_text().splitlines()
    assert lines[0].split(",") == list(FLIGHT_COLUMNS)
    data = np.loadtxt(out / "flight.csv", delimiter=",", skiprows=1)
    assert data.shape == (summary["flight_rows"], len(FLIGHT_COLUMNS))
    assert np.diff(data[:, 0]).max() == pytest.approx(1 / 500)
    error = np.linalg.norm(data[:, 4:7] - data[:, 1:4], axis=1)
    assert np.sqrt(np.mean(error**2)) == pytest.approx(summary["rmse_m"], rel=1e-6)
    assert (out / "plot.png").stat().st_size > 10_000


def test_rpt_tracks_within_5_mm_and_feed_forward_beats_plain_pid(
    flown: dict[str, Path],
) -> None:
    rmse = {name: summary_of(out)["rmse_m"] for name, out in flown.items()}
    assert rmse["rpt"] <= 5e-3
    assert rmse["pid-ff"] < rmse["pid"]
    assert rmse["rpt"] < rmse["pid-ff"]


def test_disturbances_are_seeded_and_recorded(spiral: Path, tmp_path: Path) -> None:
    args = ("--wind", "1,-0.5,0", "--gust", "0.5", "--noise", "0.001", "--rate", "250")
    a = fly(spiral, tmp_path / "a", *args, "--seed", "3")
    b = fly(spiral, tmp_path / "b", *args, "--seed", "3")
    c = fly(spiral, tmp_path / "c", *args, "--seed", "4")
    assert a["rmse_m"] == b["rmse_m"] != c["rmse_m"]
    assert a["wind_mps"] == [1.0, -0.5, 0.0]
    assert a["gust_std_mps"] == 0.5 and a["position_noise_m"] == 0.001
    assert a["rate_hz"] == 250.0


needs_rotorpy = pytest.mark.skipif(
    importlib.util.find_spec("rotorpy") is None
    or importlib.util.find_spec("skyquill.sim.rotorpy_adapter") is None,
    reason="RotorPy or its adapter is not installed",
)


@needs_rotorpy
def test_rotorpy_flies_the_same_file(spiral: Path, tmp_path: Path) -> None:
    summary = fly(spiral, tmp_path / "rotorpy", "--sim", "rotorpy", "--rate", "100")
    assert summary["sim"] == "rotorpy" and summary["controller"] == "rpt"
    assert 0.0 < summary["rmse_m"] < 0.5
    assert (tmp_path / "rotorpy" / "plot.png").is_file()


@needs_rotorpy
def test_rotorpy_default_tracks_as_well_as_se3(spiral: Path, tmp_path: Path) -> None:
    """The default rpt is matched to RotorPy's vehicle: no worse than RotorPy's own SE3."""
    default = fly(spiral, tmp_path / "rpt", "--sim", "rotorpy", "--rate", "100")
    se3 = fly(spiral, tmp_path / "se3", "--sim", "rotorpy", "--rate", "100", "--controller", "se3")
    assert (default["controller"], se3["controller"]) == ("rpt", "se3")
    assert default["rmse_m"] <= 1.2 * se3["rmse_m"]


@needs_rotorpy
@pytest.mark.parametrize("controller", ["pid-ff", "pid"])
def test_every_outer_loop_flies_on_rotorpy(spiral: Path, tmp_path: Path, controller: str) -> None:
    args = ("--sim", "rotorpy", "--rate", "100", "--controller", controller)
    summary = fly(spiral, tmp_path / controller, *args)
    assert summary["sim"] == "rotorpy" and summary["controller"] == controller
    assert summary["saturations"] == {"motor_speed_max": 0, "motor_speed_min": 0}


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--controller", "lqr"], "--controller: got 'lqr', expected one of rpt, pid-ff, pid"),
        (["--controller", "se3"], "--controller: got 'se3', expected rpt, pid-ff or pid"),
        (["--sim", "gazebo"], "--sim: got 'gazebo', expected 'skyquill' or 'rotorpy'"),
        (["--wind", "a,b"], "--wind: got 'a,b', expected three comma-separated finite numbers"),
        (["--wind", "1,2"], "--wind: got '1,2', expected three comma-separated"),
        (["--wind", "1,2,nan"], "--wind: got '1,2,nan', expected three"),
        (["--wind", "1e5,0,0"], "--wind: got '1e5,0,0', expected components of at most 100"),
        (["--gust", "-1"], "--gust: got -1, expected a number from 0 to 100"),
        (["--noise", "inf"], "--noise: got inf, expected a number from 0 to 1"),
        (["--rate", "0"], "--rate: got 0, expected 50 to 10000 Hz"),
        (["--sim", "rotorpy", "--wind", "1,0,0"], "--sim rotorpy: got --wind, --gust or --noise"),
    ],
)
def test_bad_options_exit_2_with_one_message(
    spiral: Path, tmp_path: Path, args: list[str], message: str
) -> None:
    result = runner.invoke(app, ["fly", str(spiral), "--out", str(tmp_path / "o"), *args])
    assert result.exit_code == 2
    assert message in " ".join(result.output.split())
    assert "Traceback" not in result.output
    assert not (tmp_path / "o" / "summary.json").exists()


def test_bad_files_exit_2_with_one_message(tmp_path: Path) -> None:
    bad = tmp_path / "points.csv"
    bad.write_text("t,x,y,z\n0,0,0,0\n1,1,1,1\n", encoding="utf-8")
    for path, message in (
        (bad, "points.csv: got columns ['t', 'x', 'y', 'z'], expected columns t,x,y,z,vx"),
        (tmp_path / "absent.csv", "plan: got"),
    ):
        result = runner.invoke(app, ["fly", str(path), "--out", str(tmp_path / "o")])
        assert result.exit_code == 2
        assert message in " ".join(result.output.split())
        assert "Traceback" not in result.output


@needs_rotorpy
def test_rotorpy_rpt_without_rotorpy_is_named(
    spiral: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """rpt on RotorPy reads RotorPy's vehicle before flying: a missing RotorPy exits 2."""
    import sys

    monkeypatch.setitem(sys.modules, "rotorpy.vehicles.px4_sihsim_quadx_params", None)
    args = ["fly", str(spiral), "--out", str(tmp_path / "o"), "--sim", "rotorpy"]
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    message = " ".join(result.output.split())
    assert "--sim rotorpy: RotorPy adapter unavailable (RotorPy is not installed" in message
    assert not (tmp_path / "o" / "summary.json").exists()
