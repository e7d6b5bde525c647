"""Issue 18's must-show: the 100-drone show planned, proven, exported with lights, loaded back.

``examples/show_100.toml`` (take-off, the word SKY as a formation, five drones writing QUILL on
sky boards while 95 hold, a transition to a circle, landing) through ``skyquill show``; then,
from the files only: the minimum distance proven again by ``show.check_show`` (the code of
``skyquill check``, not the planner's) at or above the 3 m asked for over the whole show, the
``.skyc`` read back as Skybrush plays it with every drone's lights in the scenes' colours.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from skyquill.cli.main import app
from skyquill.export.skybrush.lights import light_colors, light_slices, program_bytes
from skyquill.export.skybrush.refit import MAX_DEVIATION_M
from skyquill.export.skybrush.skyc_file import read_show_json
from skyquill.io.plan_dir import read_plan
from skyquill.show import ShowDrone, check_show, load_show

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "show_100.toml"


@pytest.mark.timeout(900)
def test_the_100_drone_show(tmp_path: Path) -> None:
    out = tmp_path / "show100"
    result = CliRunner().invoke(app, ["show", str(EXAMPLE), "--out", str(out)])
    assert result.exit_code == 0, result.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["drones"] == 100
    kinds = [s["type"] for s in summary["scenes"]]
    assert kinds == ["takeoff", "formation", "write", "formation", "land"]
    planned = read_plan(out)
    assert len(planned) == 100
    # proven apart again, from the written files, by the checker
    report = check_show([ShowDrone(p.trajectory, n) for n, p in planned], 3.0, None)
    assert report.separation.passed and report.separation.lower_bound_m >= 3.0
    assert summary["min_separation_m"]["guaranteed"] >= 3.0
    # the .skyc as the drones play it: 100 drones, proven apart to within the export rounding
    played = load_show([out / "show.skyc"])
    assert len(played) == 100
    # checked against 3 m less twice the keyframes' distance from the plan (two drones)...
    allowed = summary["skyc"]["played_back"]["checked_against_m"]
    assert 3.0 - 2 * MAX_DEVIATION_M <= allowed <= 3.0
    assert check_show(played, allowed, None).separation.passed
    # ... and this show, as played, keeps the whole 3 m (issue 26: what is delivered)
    assert summary["skyc"]["played_back"]["guaranteed_separation_m"] >= 3.0
    assert summary["skyc"]["as_played"]["within_allowed"]
    # every drone's light, as Skybrush shows it, in the colour of each of its windows
    show = read_show_json(out / "show.skyc")
    for (_, plan), drone in zip(planned, show["swarm"]["drones"], strict=True):
        data = program_bytes("l", drone["settings"]["lights"])
        mid_ms = np.array([500.0 * (a + b) for a, b in plan.pen_windows_s])
        shown = light_colors(light_slices("l", data, 1e7), mid_ms)
        np.testing.assert_array_equal(shown, np.array(plan.pen_rgb))
    writers = [p for _, p in planned if (255, 255, 255) in p.pen_rgb]
    assert len(writers) == 5
    assert (out / "long_exposure.png").is_file() and (out / "preview.gif").is_file()
