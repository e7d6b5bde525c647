"""``skyquill export``: every format from a fit and from a several-drone write; bad input."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from skyquill.cli.main import app
from skyquill.export import EXPORTERS

EXAMPLES = Path(__file__).parents[2] / "examples"
runner = CliRunner()


@pytest.fixture(scope="module")
def fitted(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("fit")
    result = runner.invoke(
        app, ["fit", str(EXAMPLES / "segments.csv"), "--timing", "segments", "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    return out


@pytest.fixture(scope="module")
def targeted(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A plan shaped for a Crazyflie: two rest-to-rest moves of 20 and 25 spans, a hover between."""
    from skyquill.io.plan_dir import write_plan
    from skyquill.io.trajectory_json import PlannedTrajectory
    from skyquill.limits import VehicleLimits
    from skyquill.targets import hover
    from skyquill.trajectory import RestToRestSequence, SplineTrajectory

    def move(a: list[float], b: list[float], spans: int, duration: float) -> SplineTrajectory:
        s = np.linspace(0.0, 1.0, spans + 7)
        ease = s**3 * (10 - 15 * s + 6 * s**2)
        ease[:4], ease[-4:] = 0.0, 1.0  # rest to order 3 at both ends
        return SplineTrajectory(np.asarray(a) + ease[:, None] * np.subtract(b, a), 7, duration)

    plan = RestToRestSequence(
        (move([0, 0, 1], [1, 0, 1], 20, 4.0), hover(np.array([1.0, 0, 1]), 1.0),
         move([1, 0, 1], [1, 1, 1.5], 25, 5.0))
    )  # fmt: skip
    out = tmp_path_factory.mktemp("targeted")
    # jerk 13.4 m/s^3 at most (the eased spline): limits it keeps, as delivered too
    limits = VehicleLimits(1.0, 2.0, 15.0).derivative_limits(3)
    write_plan(out, [PlannedTrajectory(plan, (), limits)], rate=100.0, guaranteed=True, summary={})
    return out


@pytest.mark.parametrize("fmt", ["crazyswarm", "skyc", "skybrush-csv", "px4", "csv", "json"])
def test_every_format_from_a_targeted_plan(targeted: Path, tmp_path: Path, fmt: str) -> None:
    out = tmp_path / f"show{EXPORTERS[fmt].suffix}"
    result = runner.invoke(app, ["export", str(targeted), "--format", fmt, "--out", str(out)])
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / f"{out.name}.summary.json").read_text())
    assert summary["format"] == fmt and all(Path(f).exists() for f in summary["files"])


@pytest.mark.parametrize("fmt", ["skyc", "skybrush-csv", "px4", "csv", "json"])
def test_every_format_from_a_fit(fitted: Path, tmp_path: Path, fmt: str) -> None:
    out = tmp_path / f"show{EXPORTERS[fmt].suffix}"
    result = runner.invoke(app, ["export", str(fitted), "--format", fmt, "--out", str(out)])
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / f"{out.name}.summary.json").read_text())
    assert summary["format"] == fmt and summary["files"]
    for name in summary["files"]:
        assert Path(name).exists()
    if fmt == "skyc":
        with zipfile.ZipFile(summary["files"][0]) as archive:
            assert "show.json" in archive.namelist()


def test_an_out_file_of_another_kind_is_refused_not_renamed(fitted: Path, tmp_path: Path) -> None:
    out = tmp_path / "results.dat"
    result = runner.invoke(app, ["export", str(fitted), "--format", "csv", "--out", str(out)])
    assert result.exit_code == 2
    assert "expected a file ending in .csv for --format csv" in " ".join(result.output.split())
    assert not any(tmp_path.iterdir())


def test_an_export_never_writes_over_the_plan_it_reads(fitted: Path) -> None:
    before = (fitted / "trajectory.json").read_bytes()
    out = fitted / "trajectory.json"
    result = runner.invoke(app, ["export", str(fitted), "--format", "json", "--out", str(out)])
    assert result.exit_code == 2 and "one of this command's inputs" in result.output
    assert (fitted / "trajectory.json").read_bytes() == before


def test_crazyswarm_refuses_a_plan_that_does_not_fit(fitted: Path, tmp_path: Path) -> None:
    result = runner.invoke(
        app, ["export", str(fitted), "--format", "crazyswarm", "--out", str(tmp_path / "cf.csv")]
    )
    assert result.exit_code == 2
    text = " ".join(result.output.split())
    assert "expected at most 31 per upload" in text and "target 'crazyflie'" in text
    assert not any(tmp_path.iterdir())


def test_several_drones_give_several_files_or_one_show(tmp_path: Path) -> None:
    written = tmp_path / "write"
    result = runner.invoke(app, ["write", "一人", "--drones", "2", "--out", str(written)])
    assert result.exit_code == 0, result.output
    csv = runner.invoke(
        app, ["export", str(written), "--format", "csv", "--out", str(tmp_path / "d.csv")]
    )
    assert csv.exit_code == 0, csv.output
    assert (tmp_path / "d_trajectory_0.csv").exists() and (tmp_path / "d_trajectory_1.csv").exists()
    show = runner.invoke(
        app, ["export", str(written), "--format", "skyc", "--out", str(tmp_path / "s.skyc")]
    )
    assert show.exit_code == 0, show.output
    with zipfile.ZipFile(tmp_path / "s.skyc") as archive:
        data = json.loads(archive.read("show.json"))
    assert len(data["swarm"]["drones"]) == 2


def test_bad_input(tmp_path: Path, fitted: Path) -> None:
    empty = tmp_path / "empty"
    empty.mkdir()
    result = runner.invoke(app, ["export", str(empty), "--out", str(tmp_path / "x.csv")])
    assert result.exit_code == 2
    assert "without trajectory.json" in " ".join(result.output.split())
    result = runner.invoke(
        app, ["export", str(fitted), "--format", "kml", "--out", str(tmp_path / "x.csv")]
    )
    assert result.exit_code == 2 and "--format: got 'kml'" in " ".join(result.output.split())
    broken = tmp_path / "nan"
    broken.mkdir()
    data = json.loads((fitted / "trajectory.json").read_text())
    data["trajectory"]["control_points"][3][0] = float("nan")
    (broken / "trajectory.json").write_text(json.dumps(data))
    result = runner.invoke(app, ["export", str(broken), "--out", str(tmp_path / "x.csv")])
    assert result.exit_code == 2 and "NaN" in " ".join(result.output.split())


def test_crazyswarm_round_trip_flies_in_the_simulator(targeted: Path, tmp_path: Path) -> None:
    """Read the uploads back as the Crazyflie flies them (float32) and fly that."""
    from skyquill.export.crazyflie.exporter import read_export
    from skyquill.io.trajectory_json import read_trajectory_json
    from skyquill.sim import simulate

    result = runner.invoke(
        app, ["export", str(targeted), "--format", "crazyswarm", "--out", str(tmp_path / "cf.csv")]
    )
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "cf.csv.summary.json").read_text())
    assert [Path(f).name for f in summary["files"]] == ["cf_part1.csv", "cf_part2.csv", "cf_fly.py"]
    assert [u["pieces"] for u in summary["drone_uploads"][0]["uploads"]] == [20, 25]
    flown = read_export(tmp_path / "cf.csv.summary.json")["trajectory"]
    original = read_trajectory_json(targeted / "trajectory.json").trajectory
    t = np.linspace(0.0, original.duration, 3000)
    for order in range(3):
        scale = max(1.0, np.abs(original.evaluate(t, order)).max())
        assert np.abs(flown.evaluate(t, order) - original.evaluate(t, order)).max() < 1e-5 * scale
    assert summary["delivered"][0]["max_error_m"] < 1e-5
    flight = simulate(flown)
    assert flight.rmse_m < 0.01


def test_the_light_colour_reaches_the_skybrush_formats(fitted: Path, tmp_path: Path) -> None:
    out = tmp_path / "lit.zip"
    args = ["export", str(fitted), "--format", "skybrush-csv", "--out", str(out)]
    result = runner.invoke(app, [*args, "--light", "#0a141e"])  # 10,20,30
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "lit.zip.summary.json").read_text())
    assert summary["lights_exact_to_ms"] and summary["format"] == "skybrush-csv"


@pytest.mark.parametrize("light", ["10,20", "1,2,256", "red", "1,-2,3", "1.5,2,3", "#12345g"])
def test_a_bad_light_colour_is_named(fitted: Path, tmp_path: Path, light: str) -> None:
    out = tmp_path / "s.skyc"
    args = ["export", str(fitted), "--format", "skyc", "--out", str(out), "--light", light]
    result = runner.invoke(app, args)
    assert result.exit_code == 2
    assert f"--light: got {light!r}, expected R,G,B with three integers in 0..255 or #RRGGBB" in (
        result.output
    )
    assert not out.exists()


def test_two_exports_of_one_plan_into_one_folder_both_work(fitted: Path, tmp_path: Path) -> None:
    """The README's own sequence: a .skyc and Studio's zip of one plan, side by side; each
    summary is named after its whole file name, so neither refuses the other's."""
    for name, fmt in (("four.skyc", "skyc"), ("four.zip", "skybrush-csv")):
        result = runner.invoke(
            app, ["export", str(fitted), "--format", fmt, "--out", str(tmp_path / name)]
        )
        assert result.exit_code == 0, result.output
    for name, fmt in (("four.skyc", "skyc"), ("four.zip", "skybrush-csv")):
        summary = json.loads((tmp_path / f"{name}.summary.json").read_text())
        assert summary["format"] == fmt and Path(summary["files"][0]).name == name
    # and once more, each replacing only its own files
    again = runner.invoke(
        app, ["export", str(fitted), "--format", "skyc", "--out", str(tmp_path / "four.skyc")]
    )
    assert again.exit_code == 0, again.output
    assert (tmp_path / "four.zip.summary.json").exists()
