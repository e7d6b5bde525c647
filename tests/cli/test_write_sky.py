"""``skyquill write --board sky``: light painting, the 20-drone grid, ``--split strokes``."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from skyquill.calligraphy.board import sky_board
from skyquill.cli.main import app, parse_color
from skyquill.export.skybrush.lights import light_slices, program_bytes
from skyquill.export.skybrush.skyc_file import read_show_json

runner = CliRunner()


def test_write_on_a_turned_sky_board(tmp_path: Path) -> None:
    args = ["write", "Hi", "--board", "sky", "--board-yaw", "30", "--board-tilt", "20"]
    result = runner.invoke(app, [*args, "--board-height", "2", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    for name in ("trajectory.csv", "trajectory.json", "summary.json", "plot.png"):
        assert (tmp_path / name).stat().st_size > 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["max_excess"] <= 1e-9 and summary["drones"][0]["faithful"]
    assert summary["drones"][0]["follow"] == "path"
    # The light is the vehicle: pen-down rows of the CSV lie on the board's plane.
    data = np.loadtxt(tmp_path / "trajectory.csv", delimiter=",", skiprows=1)
    board = sky_board(np.array([0.0, 0.0, 2.0]), yaw_deg=30.0, tilt_deg=20.0)
    lit = board.to_board(data[data[:, -1] == 1.0][:, 1:4])
    assert np.abs(lit[:, 2]).max() < 2e-3
    assert lit[:, 1].min() > -0.01  # the writing's bottom at --board-height
    strokes = json.loads((tmp_path / "input_strokes.json").read_text())["strokes"]
    on_plane = board.to_board(np.array([p for s in strokes for p in s]))
    np.testing.assert_allclose(on_plane[:, 2], 0.0, atol=1e-12)  # no brush offset


PALETTE = ["#ff3000", "0,160,255", "90,255,90", "#ffffff"]


@pytest.mark.timeout(300)
def test_twenty_drones_write_twenty_characters_exported_with_lights_and_checked(
    tmp_path: Path,
) -> None:
    """Issue 18's must-show: 20 characters by 20 drones in the air, each lit in its colour,
    exported to .skyc, loaded back and proven apart by ``skyquill check`` (not the planner)."""
    text, plan = "ABCDEFGHIJKLMNOPQRST", tmp_path / "plan"
    colors = [a for c in PALETTE for a in ("--light-color", c)]
    args = ["write", text, "--drones", "20", "--board", "sky", *colors, "--out", str(plan)]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    summary = json.loads((plan / "summary.json").read_text())
    assert len(summary["drones"]) == 20 and summary["grid"] == {"rows": 4, "columns": 5}
    assert summary["min_separation_m"] >= 1.0 and summary["max_excess"] <= 1e-9
    assert len(list(plan.glob("trajectory_*.csv"))) == 20
    assert (plan / "long_exposure.png").is_file() and (plan / "preview.gif").is_file()
    skyc = tmp_path / "show.skyc"
    result = runner.invoke(app, ["export", str(plan), "--format", "skyc", "--out", str(skyc)])
    assert result.exit_code == 0, result.output
    show = read_show_json(skyc)
    expected = [parse_color("c", PALETTE[i % 4]) for i in range(20)]
    for i, drone in enumerate(show["swarm"]["drones"]):
        data = program_bytes("l", drone["settings"]["lights"])
        shown = {tuple(int(c) for c in s.start_rgb) for s in light_slices("l", data, 1e6)}
        assert shown == {(0, 0, 0), expected[i]}
    check = tmp_path / "check"
    args = ["check", str(skyc), "--min-distance", "1", "--out", str(check)]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    verdict = json.loads((check / "summary.json").read_text())
    assert verdict["separation"]["guaranteed_lower_bound_m"] >= 1.0


def test_split_strokes_balances_the_flights(tmp_path: Path) -> None:
    args = ["write", "HELLO", "--drones", "3", "--split", "strokes", "--board", "sky"]
    result = runner.invoke(app, [*args, "--size", "8", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "summary.json").read_text())
    split = summary["split"]
    assert sorted(i for s in split["strokes_per_drone"] for i in s) == list(range(10))
    times = split["flight_time_s"]
    assert split["max_over_min_flight_time"] == pytest.approx(max(times) / min(times))
    assert split["max_over_min_flight_time"] < 1.25  # measured 1.13
    assert summary["min_separation_m"] >= 1.0


def test_split_too_close_is_infeasible(tmp_path: Path) -> None:
    args = ["write", "HELLO", "--drones", "3", "--split", "strokes", "--board", "sky"]
    result = runner.invoke(app, [*args, "--size", "2", "--out", str(tmp_path)])
    assert result.exit_code == 2, result.output
    line = " ".join(result.output.split())
    assert "separation: drone" in line and "come within" in line and "at t = " in line


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["Hi", "--board", "ceiling"], "--board: got 'ceiling', expected horizontal, wall or sky"),
        (
            ["Hi", "--board", "sky", "--board-tilt", "85"],
            "--board-tilt: got 85, expected -80 to 80",
        ),
        (["Hi", "--board", "sky", "--board-yaw", "400"], "--board-yaw: got 400, expected -180"),
        (["Hi", "--board", "wall", "--board-tilt", "5"], "--board-tilt: got it with --board wall"),
        (["Hi", "--plane-weight", "1"], "--plane-weight: got it with --board horizontal"),
        (["Hi", "--board", "sky", "--plane-weight", "-1"], "--plane-weight: got -1, expected >= 0"),
        (["Hi", "--board", "sky", "--lift", "0.1"], "--lift: got 0.1 m with --board sky"),
        (["Hi", "--board", "sky", "--fly"], "--fly: got --board sky, expected horizontal"),
        (["Hi", "--board", "sky", "--grid", "2by2"], "--grid: got '2by2', expected ROWSxCOLUMNS"),
        (["ABC", "--board", "sky", "--drones", "3", "--grid", "1x2"], "grid: got 1x2 = 2 cells"),
        (["ABC", "--board", "sky", "--drones", "4"], "got 4 drones for 3 character(s)"),
        (["Hi", "--split", "strokes", "--drones", "20"], "got 20 drones for a drawing of"),
        (["Hi", "--split", "strokes"], "--split: got --drones 1, expected at least 2"),
        (["Hi", "--split", "words", "--drones", "2"], "--split: got 'words', expected strokes"),
        (
            ["E" * 1001, "--board", "sky", "--drones", "1001"],
            "--drones: got 1001, expected 1 to 1000",
        ),
    ],
)
def test_bad_input(tmp_path: Path, args: list[str], message: str) -> None:
    result = runner.invoke(app, ["write", *args, "--out", str(tmp_path / "o")])
    assert result.exit_code == 2, result.output
    assert message in " ".join(result.output.split())


def test_a_colour_per_stroke_is_kept_in_the_plan(tmp_path: Path) -> None:
    args = ["write", "Hi", "--board", "sky", "--color-by", "stroke", "--out", str(tmp_path)]
    colors = ["--light-color", "#ff0000", "--light-color", "0,0,255"]
    result = runner.invoke(app, [*args, *colors])
    assert result.exit_code == 0, result.output
    planned = json.loads((tmp_path / "trajectory.json").read_text())
    n = len(planned["pen_windows_s"])
    assert planned["pen_rgb"] == [[255, 0, 0] if k % 2 == 0 else [0, 0, 255] for k in range(n)]
    assert json.loads((tmp_path / "summary.json").read_text())["pictures"]["lit_windows"] == n


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--light-color", "blue"], "--light-color: got 'blue', expected R,G,B"),
        (["--color-by", "word"], "--color-by: got 'word', expected one of drone, stroke"),
    ],
)
def test_bad_light_colours_exit_2(tmp_path: Path, extra: list[str], message: str) -> None:
    result = runner.invoke(app, ["write", "Hi", "--board", "sky", "--out", str(tmp_path), *extra])
    assert result.exit_code == 2 and message in result.output
    assert not (tmp_path / "summary.json").exists()
