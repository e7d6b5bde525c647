"""``skyquill write`` and ``skyquill demo``: files, columns, summary, bad input."""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib.image
import numpy as np
import pytest
from typer.testing import CliRunner

from skyquill.cli.main import app
from skyquill.geometry import polyline_distance

runner = CliRunner()
COLUMNS = "t,x,y,z,vx,vy,vz,ax,ay,az,jx,jy,jz,yaw,pen"


def test_demo_writes_and_flies_yong(tmp_path: Path) -> None:
    result = runner.invoke(app, ["demo", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["max_excess"] <= 1e-9
    assert summary["deviation"]["max_m"] <= 0.005
    assert summary["drones"][0]["flight"]["rmse_m"] < 0.01
    assert (tmp_path / "plot.png").stat().st_size > 10_000


def test_write_text_gives_pen_column_and_input_strokes(tmp_path: Path) -> None:
    result = runner.invoke(app, ["write", "Hi", "--size", "0.4", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    header = (tmp_path / "trajectory.csv").read_text().splitlines()[0]
    assert header == COLUMNS
    data = np.loadtxt(tmp_path / "trajectory.csv", delimiter=",", skiprows=1)
    assert set(np.unique(data[:, -1])) == {0.0, 1.0}
    strokes = json.loads((tmp_path / "input_strokes.json").read_text())["strokes"]
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert len(strokes) == summary["strokes"]
    # The brush tip read from the CSV (0.3 m along the thrust axis below the vehicle:
    # the acceleration columns give it) lies, pen down, near the input strokes (given at
    # the vehicle's height: same frame), in the board's plane.
    down = data[data[:, -1] == 1.0]
    thrust = down[:, 7:10] + np.array([0.0, 0.0, 9.81])
    tip = down[:, 1:4] + 0.3 * (
        np.array([0.0, 0.0, 1.0]) - thrust / np.linalg.norm(thrust, axis=1)[:, None]
    )
    flat = [np.array(s)[:, :2] for s in strokes]
    nearest = np.min([polyline_distance(tip[:, :2], s) for s in flat], axis=0)
    assert nearest.max() <= 0.01 * 0.4
    for key in (
        "duration_s",
        "planning_time_s",
        "limits",
        "max_speed",
        "max_acc",
        "max_jerk",
        "max_excess",
        "deviation",
        "strokes",
        "drones",
    ):
        assert key in summary
    assert {"max_m", "mean_m", "hausdorff_m"} <= summary["deviation"].keys()


def test_four_drones_write_yi_ma_dang_xian_and_fly(tmp_path: Path) -> None:
    """Paper 000 Fig. 11b: 一马当先 by four drones at once, each flown in simulation."""
    result = runner.invoke(
        app, ["write", "一马当先", "--drones", "4", "--fly", "--out", str(tmp_path)]
    )
    assert result.exit_code == 0, result.output
    for i in range(4):
        assert (tmp_path / f"trajectory_{i}.csv").exists()
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["min_separation_m"] >= 1.0
    assert len(summary["drones"]) == 4
    for drone in summary["drones"]:
        assert drone["faithful"] and drone["max_excess"] <= 1e-9
        assert drone["flight"]["rmse_m"] < 0.01
        assert drone["flight"]["saturations"] == {"thrust_max": 0, "thrust_min": 0, "tilt": 0}
    strokes = json.loads((tmp_path / "input_strokes.json").read_text())
    assert strokes["first_stroke_of_drone"][-1] == len(strokes["strokes"]) == summary["strokes"]
    # Each drone's ink beside its input, named like its trajectory_<i>.csv.
    assert sorted(p.name for p in tmp_path.glob("ink*.png")) == [f"ink_{i}.png" for i in range(4)]
    for drone in summary["drones"]:
        assert drone["flight"]["ink_strokes"] == drone["flight"]["input_strokes"]
        assert 0.0 < drone["flight"]["ink_iou"] <= 1.0


def test_write_yong_and_fly_draws_and_measures_the_ink(tmp_path: Path) -> None:
    """Issue 15: ink.png beside the input, and the ink's fidelity in the flight section."""
    result = runner.invoke(app, ["write", "永", "--fly", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    image = matplotlib.image.imread(tmp_path / "ink.png")  # a PNG matplotlib reads back
    assert image.ndim == 3 and image.shape[1] > 2 * image.shape[0]
    summary = json.loads((tmp_path / "summary.json").read_text())
    flight = summary["drones"][0]["flight"]
    keys = ("ink_max_deviation_m", "ink_strokes", "input_strokes", "ink_iou", "ink_width_m")
    assert set(keys) <= flight.keys()
    ink = flight["ink"]
    assert (
        flight["ink_max_deviation_m"]
        == ink["max_deviation_m"]
        == max(ink["ink_to_input_max_m"], ink["input_to_ink_max_m"])
    )
    assert flight["input_strokes"] == summary["strokes"] == ink["input_strokes"]
    assert flight["ink_strokes"] == ink["ink_strokes"] >= 1
    assert 0.0 < flight["ink_iou"] == ink["iou"] <= 1.0
    assert flight["ink_width_m"] == ink["width_m"] == pytest.approx(0.012)  # 2 mm + 2 x 5 mm
    # Written by write, owned by write: a second run replaces it without --force.
    again = runner.invoke(app, ["write", "永", "--out", str(tmp_path)])
    assert again.exit_code == 0, again.output
    assert not (tmp_path / "ink.png").exists()  # not flown: no ink, the old picture removed


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["write"], "expected exactly one of TEXT, --strokes FILE or --svg FILE"),
        (["write", "一马", "--drones", "3"], "got 3 drones for 2 character(s)"),
        (["write", "Hi", "--size", "-1"], "--size: got -1"),
        (["write", "Hi", "--rate", "0"], "--rate: got 0"),
        (["write", "Hi", "--follow", "ink"], "--follow: got 'ink', expected tip or path"),
        (
            ["write", "Hi", "--brush-length", "0.01"],
            "--brush-length: got 0.01 m, expected at least",
        ),
        (["write", "Hi", "--brush-length", "3"], "--brush-length: got 3 m, expected at most 2 m"),
        (
            ["write", "Hi", "--press-depth", "0.05"],
            "--press-depth: got 0.05 m, expected less",
        ),
        (["write", "Hi", "--board-height", "-1"], "--board-height: got -1, expected more than 0"),
        (["write", "Hi", "--board-height", "200"], "--board-height: got 200, expected more"),
    ],
)
def test_bad_input(tmp_path: Path, args: list[str], message: str) -> None:
    result = runner.invoke(app, [*args, "--out", str(tmp_path / "o")])
    assert result.exit_code == 2, result.output
    assert message in " ".join(result.output.split())


def test_wall_board(tmp_path: Path) -> None:
    result = runner.invoke(app, ["write", "Hi", "--board", "wall", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    strokes = json.loads((tmp_path / "input_strokes.json").read_text())["strokes"]
    # On the wall y = 0 the vehicle flies the brush length in front of it.
    assert np.allclose([p[1] for s in strokes for p in s], -0.3)
    bad = runner.invoke(app, ["write", "Hi", "--board", "wall", "--fly", "--out", str(tmp_path)])
    assert bad.exit_code == 2


def _held_out(tmp_path: Path) -> Path:
    """丁 and 十, not bundled: hanzi-writer-data files (medians in the 1024 em box, y up)."""
    folder = tmp_path / "hanzi"
    folder.mkdir()
    hook = [[500, 700], [505, 300], [480, 90], [400, 150]]
    medians = {
        "丁": [[[120, 700], [500, 710], [900, 700]], hook],
        "十": [[[100, 450], [500, 460], [920, 450]], [[510, 880], [505, 450], [500, 60]]],
    }
    for char, strokes in medians.items():
        (folder / f"{char}.json").write_text(json.dumps({"medians": strokes}), encoding="utf-8")
    return folder


def test_write_for_a_crazyflie_fits_every_upload(tmp_path: Path) -> None:
    hanzi = _held_out(tmp_path)
    out = tmp_path / "o"
    args = ["write", "丁十", "--hanzi", str(hanzi), "--drones", "2", "--size", "0.3"]
    # The vehicle's path fitted: fitting the tip, 0.3 m characters stray 4 mm in a
    # Crazyflie's 31 pieces per upload (the swing needs more knot spans).
    args += ["--follow", "path"]
    result = runner.invoke(app, [*args, "--target", "crazyflie", "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "upload(s) for crazyflie" in " ".join(result.output.split())
    summary = json.loads((out / "summary.json").read_text())
    assert summary["target"]["name"] == "crazyflie"
    assert summary["target"]["max_upload_pieces"] <= 31
    assert summary["target"]["max_upload_bytes"] <= 4096
    for drone, written in zip(summary["drones"], summary["plan"]["drones"], strict=True):
        uploads = drone["target"]["uploads"]
        assert all(u["pieces"] <= 31 and u["bytes"] <= 4096 for u in uploads)
        assert [u["hover_before_s"] for u in uploads] == [0.0] + [1.0] * (len(uploads) - 1)
        assert drone["faithful"] and drone["max_excess"] <= 1e-9
        # What was written and read back is the plan, densely within the limits.
        assert written["verification"]["max_excess"] <= 1e-9
        assert written["kind"] == ("bspline" if len(uploads) == 1 else "sequence")


def test_write_target_unknown(tmp_path: Path) -> None:
    args = ["write", "Hi", "--target", "tello", "--out", str(tmp_path / "o")]
    result = runner.invoke(app, args)
    assert result.exit_code == 2, result.output
    assert "--target: got 'tello', expected one of crazyflie" in " ".join(result.output.split())
