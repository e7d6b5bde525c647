"""``skyquill paint``: writes summary.json, painted.csv and plot.png; bad input exits 2."""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image
from typer.testing import CliRunner

from skyquill.cli.main import app

EXAMPLES = Path(__file__).parents[2] / "examples" / "painting"
SUMMARY_KEYS = {
    "rmse_m",
    "max_error_m",
    "n_dots",
    "flight_time_s",
    "landings",
    "contacts",
    "estimate",
    "truth",
}
runner = CliRunner()


def paint(out: Path, *args: str) -> dict[str, Any]:
    result = runner.invoke(app, ["paint", *args, "--out", str(out)])
    assert result.exit_code == 0, result.output
    summary: dict[str, Any] = json.loads((out / "summary.json").read_text())
    return summary


@pytest.fixture(scope="module")
def gamma10(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("gamma10")
    paint(out, str(EXAMPLES / "paper_140.csv"), "--gamma", "10", "--localization", "truth")
    return out


def test_writes_summary_painted_csv_and_plot(gamma10: Path) -> None:
    summary = json.loads((gamma10 / "summary.json").read_text())
    assert summary.keys() >= SUMMARY_KEYS
    assert summary["n_dots"] == 140
    assert summary["truth"] == {"gamma_deg": 10.0, "delta_m": [0.0, -1.1, 0.0]}
    assert summary["estimate"]["gamma_deg"] == pytest.approx(10.0, abs=0.3)
    assert summary["rmse_m"] < 0.07
    with (gamma10 / "painted.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 140
    assert set(rows[0]) >= {"x_ref", "z_ref", "x_painted", "z_painted"}
    assert Image.open(gamma10 / "plot.png").size[0] > 500


def test_no_estimation_is_worse(gamma10: Path, tmp_path: Path) -> None:
    csv_path = str(EXAMPLES / "paper_140.csv")
    summary = paint(tmp_path, csv_path, "--gamma", "10", "--localization", "truth",
                    "--estimator", "none")  # fmt: skip
    assert summary["rmse_m"] > 2 * json.loads((gamma10 / "summary.json").read_text())["rmse_m"]


def test_image_segmented_wall_shortest_order(tmp_path: Path) -> None:
    summary = paint(
        tmp_path, "--image", str(EXAMPLES / "quill.png"), "--dots", "60",
        "--wall-angles", "-10,0,10", "--order", "shortest", "--estimator", "robust",
        "--update", "normal", "--offset", "0,-1.2,0",
    )  # fmt: skip
    assert summary["n_dots"] == 60
    assert summary["wall_angles_deg"] == pytest.approx([-10.0, 0.0, 10.0])
    assert summary["estimator"] == "segments-robust" and summary["update"] == "normal"


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ([], "DOTS.csv / --image: got neither, expected exactly one"),
        (["--wall-angles", "-10,x"], "--wall-angles: got '-10,x', expected comma-separated"),
        (["--offset", "0,-1.1"], "--offset: got '0,-1.1', expected three comma-separated"),
        (["--offset", "0,1,0"], "--offset: got '0,1,0', expected the drone in front"),
        (["--gamma", "95"], "--gamma: got 95, expected an angle from -60 to 60 deg"),
        (["--estimator", "ekf"], "--estimator: got 'ekf', expected one of none, svd, robust"),
        (["--localization", "gps"], "--localization: got 'gps', expected 'onboard'"),
        (["--order", "spiral"], "--order: got 'spiral', expected one of given, paper, shortest"),
        (["--probe-spacing", "-0.1"], "--probe-spacing: got -0.1, expected 0 (no probing pass)"),
        (["--false-contacts", "2"], "--false-contacts: got 2, expected a probability"),
    ],
)
def test_bad_options_exit_2(tmp_path: Path, args: list[str], message: str) -> None:
    dots = [] if not args else [str(EXAMPLES / "paper_140.csv")]
    result = runner.invoke(app, ["paint", *dots, *args, "--out", str(tmp_path / "o")])
    assert result.exit_code == 2, result.output
    assert message in " ".join(result.output.split())
    assert "Traceback" not in result.output


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("x,z\n", "got 0 dots, expected 1 to 10000"),
        ("x,z\n0,nan\n", "line 2, column z: got 'nan', expected a finite number"),
        ("x,z\n9,1\n", "got 1 dot(s) outside the wall"),
    ],
)
def test_bad_dots_exit_2(tmp_path: Path, text: str, message: str) -> None:
    (tmp_path / "d.csv").write_text(text)
    result = runner.invoke(app, ["paint", str(tmp_path / "d.csv"), "--out", str(tmp_path / "o")])
    assert result.exit_code == 2, result.output
    assert message in " ".join(result.output.split())


def test_unreadable_image_exits_2(tmp_path: Path) -> None:
    (tmp_path / "x.png").write_text("nope")
    result = runner.invoke(
        app, ["paint", "--image", str(tmp_path / "x.png"), "--out", str(tmp_path / "o")]
    )
    assert result.exit_code == 2, result.output
    assert "that Pillow cannot read" in " ".join(result.output.split())


def test_out_is_a_file(tmp_path: Path) -> None:
    (tmp_path / "f").write_text("")
    result = runner.invoke(
        app, ["paint", str(EXAMPLES / "paper_140.csv"), "--out", str(tmp_path / "f")]
    )
    assert result.exit_code == 2 and "an existing file" in " ".join(result.output.split())


def test_joint_on_a_wall_file(tmp_path: Path) -> None:
    """The default estimator on a cylinder described in a file: the wall fit, the aim error,
    the probing pass and the battery use are in the summary and in the last line."""
    wall = tmp_path / "tower.toml"
    wall.write_text("[cylinder]\nradius = 20.0\n")
    result = runner.invoke(
        app,
        ["paint", str(EXAMPLES / "paper_140.csv"), "--wall", str(wall), "--gamma", "10",
         "--localization", "truth", "--out", str(tmp_path / "o")],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert "batteries" in result.output
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["estimator"] == "joint" and summary["order"] == "shortest"
    assert summary["wall"] == str(wall)
    assert summary["probes"] == 10 and summary["wall_fit"]["fits"]
    assert summary["aim_rmse_m"] < 0.01 and summary["rmse_m"] < 0.06
    assert summary["estimate"]["gamma_deg"] == pytest.approx(10.0, abs=0.3)
    assert summary["battery_use"] == pytest.approx(summary["flight_time_s"] / 480.0)
    assert (tmp_path / "o" / "plot.png").exists()


def test_a_wall_that_does_not_fit_says_so(tmp_path: Path) -> None:
    """A wall of steps every 20 cm is no wall of eight plane pieces: said in the last line."""
    steps = "".join(
        f"[[segment]]\nfrom = {a:.1f}\nto = {a + 0.2:.1f}\nangle = {0 if k % 2 == 0 else 40}\n"
        for k, a in enumerate(np.arange(-2.1, 2.1, 0.2))
    )
    wall = tmp_path / "steps.toml"
    wall.write_text(steps)
    dots = tmp_path / "d.csv"
    dots.write_text("x,z\n" + "".join(f"{x:.3f},1.5\n" for x in np.linspace(-1.9, 1.9, 40)))
    result = runner.invoke(
        app,
        ["paint", str(dots), "--wall", str(wall), "--localization", "truth",
         "--out", str(tmp_path / "o")],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert not summary["wall_fit"]["fits"]
    assert "does not fit" in " ".join(result.output.split())
