"""``skyquill cover``: plans a region, writes its three files, refuses bad input with exit 2."""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from skyquill.cli.main import app
from skyquill.io.points import TRAJECTORY_COLUMNS

EXAMPLES = Path(__file__).parents[2] / "examples" / "coverage"
SUMMARY_KEYS = {
    "duration_s",
    "path_length_m",
    "coverage_fraction",
    "max_speed",
    "max_acc",
    "max_jerk",
    "max_excess",
    "planning_time_s",
    "pattern",
    "missed_area_m2",
    "missed_fraction",
}


@pytest.mark.parametrize("pattern", ["spiral", "zigzag-stop"])
def test_cover_writes_summary_trajectory_and_plot(tmp_path: Path, pattern: str) -> None:
    out = tmp_path / "out"
    args = ["cover", str(EXAMPLES / "square_10m.geojson"), "--out", str(out)]
    result = CliRunner().invoke(app, [*args, "--pattern", pattern, "--rate", "50"])
    assert result.exit_code == 0, result.output
    summary = json.loads((out / "summary.json").read_text())
    assert set(summary) >= SUMMARY_KEYS
    assert summary["pattern"] == pattern
    header = (out / "trajectory.csv").read_text().splitlines()[0].split(",")
    assert header == [*TRAJECTORY_COLUMNS, "yaw", "pen"]
    table = np.loadtxt(out / "trajectory.csv", delimiter=",", skiprows=1)
    drone = summary["plan"]["drones"][0]
    assert table.shape[0] == drone["rows"]
    assert np.all(np.isfinite(table))
    # The dense check ran on the trajectory.json written, within the LP's 2 %.
    assert drone["verification"]["max_excess"] <= 0.02
    assert not summary["plan"]["limits_guaranteed"]
    steps = np.diff(table[:, 0])
    assert np.allclose(steps[:-1], 0.02, atol=1e-6) and 0.0 < steps[-1] <= 0.02 + 1e-6
    assert table[-1, 0] == pytest.approx(summary["duration_s"], abs=0.02)
    assert np.all(table[:, -1] == 1.0)
    assert (out / "plot.png").stat().st_size > 10_000


def test_cover_tunes_for_a_coverage_target(tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = CliRunner().invoke(
        app,
        ["cover", str(EXAMPLES / "square_10m.geojson"), "--out", str(out),
         "--pattern", "zigzag-stop", "--min-coverage", "0.98"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert json.loads((out / "summary.json").read_text())["coverage_fraction"] >= 0.98


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--width", "0"], "width"),
        (["--width", "50"], "width"),
        (["--width", "0.001"], "width: got 0.001 m on a region of 100 m²"),
        (["--time-limit", "0"], "--time-limit: got 0, expected more than 0"),
        (["--vmax", "-1"], "vmax"),
        (["--jmax", "0"], "jmax"),
        (["--pattern", "snake"], "pattern"),
        (["--min-coverage", "1.5"], "--min-coverage: got 1.5, expected 0"),
        (["--min-coverage", "-1"], "or a fraction in (0, 1]"),
        (["--min-coverage", "nan"], "--min-coverage: got nan"),
    ],
)
def test_bad_input_exits_2_with_a_message(tmp_path: Path, extra: list[str], message: str) -> None:
    args = ["cover", str(EXAMPLES / "square_10m.geojson"), "--out", str(tmp_path / "o"), *extra]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2
    assert message in result.output
    assert "Traceback" not in result.output


def test_a_self_intersecting_region_is_refused(tmp_path: Path) -> None:
    bowtie = tmp_path / "bowtie.geojson"
    bowtie.write_text('{"type": "Polygon", "coordinates": [[[0,0],[10,10],[10,0],[0,10],[0,0]]]}')
    result = CliRunner().invoke(app, ["cover", str(bowtie), "--out", str(tmp_path / "o")])
    assert result.exit_code == 2
    assert "region" in result.output or "bowtie" in result.output


def test_cover_for_a_crazyflie_writes_uploads_into_the_summary(tmp_path: Path) -> None:
    out = tmp_path / "out"
    args = ["cover", str(EXAMPLES / "square_10m.geojson"), "--out", str(out)]
    result = CliRunner().invoke(app, [*args, "--pattern", "zigzag-stop", "--target", "crazyflie"])
    assert result.exit_code == 0, result.output
    summary = json.loads((out / "summary.json").read_text())
    target = summary["target"]
    assert target["name"] == "crazyflie" and target["path_tolerance_m"] == pytest.approx(0.1)
    assert all(u["pieces"] <= 31 for u in target["uploads"])
    assert target["max_path_deviation_m"] <= target["path_tolerance_m"]
    # The refit holds the limits through the hull: a guaranteed check, excess 0.
    assert summary["plan"]["limits_guaranteed"]
    assert summary["plan"]["drones"][0]["verification"]["max_excess"] <= 1e-9


def test_cover_refuses_an_unknown_target_in_one_line(tmp_path: Path) -> None:
    args = ["cover", str(EXAMPLES / "square_10m.geojson"), "--out", str(tmp_path / "o")]
    result = CliRunner().invoke(app, [*args, "--target", "tello"])
    assert result.exit_code == 2
    assert "--target: got 'tello', expected one of crazyflie" in " ".join(result.output.split())
    assert "Traceback" not in result.output


#: The issue's 47 m x 30 m field with one reflex corner, in WKT (local metres).
HEXAGON_WKT = "POLYGON ((0 0, 47 0, 47 15, 30 30, 20 18, 0 30, 0 0))"


def test_the_concave_hexagon_writes_a_finite_trajectory(tmp_path: Path) -> None:
    region = tmp_path / "hexagon.wkt"
    region.write_text(HEXAGON_WKT)
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["cover", str(region), "--out", str(out)])
    assert result.exit_code == 0, result.output
    # Read back what was written: no row of NaN (12 of 15 such files once ended in one).
    table = np.loadtxt(out / "trajectory.csv", delimiter=",", skiprows=1)
    assert table.shape[0] > 1000 and np.all(np.isfinite(table))
    summary = json.loads((out / "summary.json").read_text())
    assert summary["options"]["time_limit"] == 60.0
    assert summary["planning_time_s"] < 60.0


def test_a_time_limit_below_the_estimate_exits_2_in_one_line(tmp_path: Path) -> None:
    region = tmp_path / "field.wkt"
    region.write_text("POLYGON ((0 0, 316 0, 316 316, 0 316, 0 0))")
    out = tmp_path / "out"
    args = ["cover", str(region), "--out", str(out), "--width", "5", "--time-limit", "5"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1
    assert lines[0].startswith("error: --time-limit: got 5 s, expected at least")
    assert not out.exists()


def test_a_spent_time_limit_exits_2_naming_the_step(tmp_path: Path) -> None:
    region = tmp_path / "hexagon.wkt"
    region.write_text(HEXAGON_WKT)
    out = tmp_path / "out"
    args = ["cover", str(region), "--out", str(out), "--time-limit", "1"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2
    assert "--time-limit: got 1 s, expected enough for this plan: it stopped at" in " ".join(
        result.output.split()
    )
    assert not out.exists()


def test_a_kilometre_square_at_a_2_m_swath_is_refused_at_once(tmp_path: Path) -> None:
    region = tmp_path / "km.wkt"
    region.write_text("POLYGON ((0 0, 1000 0, 1000 1000, 0 1000, 0 0))")
    result = CliRunner().invoke(app, ["cover", str(region), "--out", str(tmp_path / "o")])
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "a path of about 504 km, expected at most 200 km" in lines[0]


def test_a_flight_too_long_for_its_csv_rate_is_refused_before_planning(tmp_path: Path) -> None:
    # 100 ha at a 10 m swath and 3 m/s: at least 9 h of flight, 1.6 M rows at 50 Hz.
    region = EXAMPLES / "holes_100ha.geojson"
    out = tmp_path / "o"
    args = ["cover", str(region), "--width", "10", "--out", str(out)]
    started = time.perf_counter()
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2
    assert time.perf_counter() - started < 10.0  # nothing planned
    lines = result.output.strip().splitlines()
    assert len(lines) == 1
    assert "--rate: got 50 Hz over a flight of at least 31408.8 s" in lines[0]
    assert "expected at most 1,000,000 rows in trajectory.csv" in lines[0]
    assert not out.exists()
