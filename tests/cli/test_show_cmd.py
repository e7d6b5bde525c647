"""``skyquill show``: the small example end to end, and bad input in one line (exit 2)."""

from __future__ import annotations

import gc
import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from skyquill.cli.main import app
from skyquill.cli.show_cmd import _out_of_collectors_sight
from skyquill.export.skybrush.csv_file import read_csv_zip
from skyquill.export.skybrush.lights import light_colors, light_slices, program_bytes
from skyquill.export.skybrush.skyc_file import read_show_json
from skyquill.io.plan_dir import read_plan
from skyquill.show import ShowDrone, check_show
from skyquill.show.script import load_script

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
runner = CliRunner()


@pytest.fixture
def small(tmp_path: Path) -> Path:
    out = tmp_path / "out"
    result = runner.invoke(app, ["show", str(EXAMPLES / "show_small.toml"), "--out", str(out)])
    assert result.exit_code == 0, result.output
    return out


def test_the_small_example_end_to_end(small: Path) -> None:
    # One test for the one (16 s) run: files, summary, the independent check, the .skyc.
    _files_and_summary(small)
    _passes_the_independent_check(small)
    _skyc_reads_back(small)
    # skyquill check on the plan directory, with the script's limits: exit 0
    limits = ["--max-speed-xy", "3", "--max-speed-up", "3", "--max-speed-down", "3"]
    limits += ["--max-acceleration", "2", "--min-distance", "1.5"]
    result = runner.invoke(app, ["check", str(small), *limits])
    assert result.exit_code == 0, result.output


def _files_and_summary(small: Path) -> None:
    for i in range(10):
        assert (small / f"trajectory_{i}.csv").is_file()
        assert (small / f"trajectory_{i}.json").is_file()
    summary = json.loads((small / "summary.json").read_text())
    assert summary["drones"] == 10
    sep = summary["min_separation_m"]
    assert sep["requested"] == 1.5 and sep["guaranteed"] >= 1.5
    assert {"takeoff", "formation", "write", "land", "check", "skyc", "files"} <= set(
        summary["planning_time_s"]
    )
    assert [s["type"] for s in summary["scenes"]] == [
        "takeoff", "formation", "write", "formation", "land",
    ]  # fmt: skip
    assert summary["plan"]["max_excess"] <= 1e-6
    lights = summary["lights"][0]
    assert len(lights["rgb"]) == len(lights["windows_s"]) > 0
    # Skybrush Studio's CSVs, read back as Studio reads them: the colours on their rows
    studio = {d.name: d for d in read_csv_zip(small / "show.zip")}
    assert len(studio) == 10 and summary["skybrush_csv"]["lights_exact_to_ms"]
    rows = studio["trajectory_0"]
    for (a, b), rgb in zip(lights["windows_s"], lights["rgb"], strict=True):
        inside = (rows.t_ms > round(a * 1000)) & (rows.t_ms < round(b * 1000))
        assert np.all(rows.colors[inside] == rgb)


def _passes_the_independent_check(small: Path) -> None:
    script = load_script(EXAMPLES / "show_small.toml")
    drones = [ShowDrone(p.trajectory, n) for n, p in read_plan(small)]
    report = check_show(drones, script.safety_m, None)
    assert report.separation.passed and report.separation.lower_bound_m >= 1.5
    # densely sampled, every pair stays apart
    t = np.linspace(0.0, max(d.end_s for d in drones), 6000)
    p = np.stack([d.trajectory.evaluate(np.minimum(t, d.end_s)) for d in drones], axis=1)
    gaps = np.linalg.norm(p[:, :, None] - p[:, None, :], axis=3)
    gaps[:, np.arange(10), np.arange(10)] = np.inf
    assert gaps.min() >= 1.5


def _skyc_reads_back(small: Path) -> None:
    """The .skyc as Skybrush plays it: every drone, its lights in the scenes' colours, and
    the separation proven again on the played curves (by skyquill check, exit 0)."""
    show = read_show_json(small / "show.skyc")
    assert len(show["swarm"]["drones"]) == 10
    planned = read_plan(small)
    for (_, plan), drone in zip(planned, show["swarm"]["drones"], strict=True):
        data = program_bytes("l", drone["settings"]["lights"])
        mid_ms = np.array([500.0 * (a + b) for a, b in plan.pen_windows_s])
        shown = light_colors(light_slices("l", data, 1e6), mid_ms)
        np.testing.assert_array_equal(shown, np.array(plan.pen_rgb))
    assert len({c for _, p in planned for c in p.pen_rgb}) >= 2  # the scenes' colours
    summary = json.loads((small / "summary.json").read_text())
    played = summary["skyc"]["played_back"]
    out = small.parent / "skyc-check"
    minimum = str(played["checked_against_m"])
    args = ["check", str(small / "show.skyc"), "--min-distance", minimum, "--out", str(out)]
    result = runner.invoke(app, args)
    assert result.exit_code in (0, 1), result.output  # limits may fail on the ms/mm rounding
    assert json.loads((out / "summary.json").read_text())["separation"]["passed"]
    assert played["guaranteed_separation_m"] >= played["checked_against_m"] >= 1.5 - 0.004
    assert (small / "long_exposure.png").is_file() and (small / "preview.gif").is_file()


def _one_error_line(output: str) -> str:
    lines = [line for line in output.splitlines() if line.strip()]
    assert len(lines) == 1, output
    assert "Traceback" not in output
    return lines[0]


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (("drones = 10", "drones = 40"), "drones: got 40, expected at most"),
        (('type = "hold"', 'type = "dance"'), "got 'dance', expected one of takeoff"),
        (("[show]", "[show"), "malformed TOML"),
        (("safety_distance = 1.5", "safety_distance = -1.5"), "safety_distance: got -1.5"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(
    tmp_path: Path, edit: tuple[str, str], message: str
) -> None:
    text = (EXAMPLES / "show_small.toml").read_text()
    if edit[0] == 'type = "hold"':  # the example has no hold: add an unknown scene instead
        text = text.replace('type = "land"', 'type = "dance"\n\n[[scene]]\ntype = "land"')
    else:
        assert edit[0] in text
        text = text.replace(edit[0], edit[1], 1)
    script = tmp_path / "show.toml"
    script.write_text(text)
    result = runner.invoke(app, ["show", str(script), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2, result.output
    assert message in _one_error_line(result.output)


def test_a_missing_script_is_refused(tmp_path: Path) -> None:
    result = runner.invoke(app, ["show", str(tmp_path / "nope.toml"), "--out", str(tmp_path)])
    assert result.exit_code == 2
    assert "SHOW: got" in _one_error_line(result.output)


@pytest.mark.parametrize(
    ("fence", "status", "message"),
    [
        ("POLYGON ((-50 0, 50 0, 50 50, -50 50, -50 0))", 2,
         "[show].geofence: got a fence that excludes the take-off pad of drone 0"),
        ("POLYGON ((-10 -20, 10 -20, 10 -7, -10 -7, -10 -20))", 2,
         "the check refuses the plan: geofence"),
        ("POLYGON ((-50 -50, 50 -50, 50 50, -50 50, -50 -50))", 0, "no two closer than"),
    ],
)  # fmt: skip
def test_a_geofence_in_the_script(tmp_path: Path, fence: str, status: int, message: str) -> None:
    """Pads outside the fence: bad input before planning; a show that leaves it: refused."""
    (tmp_path / "fence.wkt").write_text(fence)
    text = (EXAMPLES / "show_small.toml").read_text()
    script = tmp_path / "show.toml"
    script.write_text(text.replace("[show]\n", '[show]\ngeofence = "fence.wkt"\n', 1))
    result = runner.invoke(app, ["show", str(script), "--out", str(tmp_path / "out")])
    assert result.exit_code == status, result.output
    assert message in " ".join(result.output.split())


def test_the_plan_is_frozen_out_of_the_collectors_sight_only_while_writing() -> None:
    kept = [[k] for k in range(100)]  # objects alive while the files are written
    with _out_of_collectors_sight():
        assert gc.get_freeze_count() >= len(kept)
    assert gc.get_freeze_count() == 0
    with pytest.raises(RuntimeError), _out_of_collectors_sight():
        raise RuntimeError("a refused export")
    assert gc.get_freeze_count() == 0
