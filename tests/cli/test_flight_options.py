"""Bad input to the delivery options (issue 26): one plain line naming the option, exit 2.

``--min-altitude`` below 0 or above its ceiling, ``--altitude`` for 3-D input, and a plan
that cannot be delivered inside its limits (a ``.skyc`` the grid cannot play inside them).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from skyquill.cli.main import app

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
runner = CliRunner()


def _refused(args: list[str], starts: str) -> None:
    result = runner.invoke(app, args)
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert lines and lines[0].startswith(f"error: {starts}: got"), result.output
    assert "Traceback" not in result.output


@pytest.mark.parametrize("value", ["-0.1", "100.5"])
@pytest.mark.parametrize("command", ["fit", "cover"])
def test_a_minimum_altitude_out_of_range_is_refused(
    command: str, value: str, tmp_path: Path
) -> None:
    source = (
        EXAMPLES / "spiral.csv"
        if command == "fit"
        else EXAMPLES / "coverage" / "square_10m.geojson"
    )
    _refused(
        [command, str(source), "--min-altitude", value, "--out", str(tmp_path / "o")],
        "--min-altitude",
    )
    assert not (tmp_path / "o").exists()


def test_an_altitude_for_3d_input_is_refused(tmp_path: Path) -> None:
    _refused(
        ["fit", str(EXAMPLES / "segments.csv"), "--altitude", "1", "--out", str(tmp_path / "o")],
        "--altitude",
    )


def test_an_altitude_below_the_minimum_altitude_is_refused(tmp_path: Path) -> None:
    _refused(
        ["fit", str(EXAMPLES / "spiral.csv"), "--altitude", "0.2", "--out", str(tmp_path / "o")],
        "--altitude",
    )


def test_a_plan_that_cannot_be_delivered_inside_its_limits_is_refused(tmp_path: Path) -> None:
    """A move accelerating 10 % over its stated limit: no .skyc plays it inside them."""
    from skyquill.io.plan_dir import write_plan
    from skyquill.io.trajectory_json import PlannedTrajectory
    from skyquill.limits import VehicleLimits
    from skyquill.optimize.legs import LegLimits, leg_pieces
    from skyquill.trajectory import PiecewisePolynomial

    start, end = np.array([0.0, 0.0, 1.0]), np.array([6.0, 0.0, 1.0])
    durations, coeffs = leg_pieces(start, end, LegLimits(3.0, 2.2, 40.0))
    move = PiecewisePolynomial(np.concatenate([[0.0], np.cumsum(durations)]), coeffs)
    plan = tmp_path / "plan"
    limits = VehicleLimits(3.0, 2.0, 40.0).derivative_limits(3)
    write_plan(plan, [PlannedTrajectory(move, (), limits)], rate=50.0, guaranteed=False, summary={})
    out = tmp_path / "over.skyc"
    _refused(["export", str(plan), "--format", "skyc", "--out", str(out)], "plan")
    assert not out.exists()


def test_a_2d_fit_is_flown_at_its_altitude_and_records_its_phases(tmp_path: Path) -> None:
    """Never silently at z = 0: the default altitude, printed; phases in both files."""
    import json

    from skyquill.io.plan_dir import read_plan

    out = tmp_path / "spiral"
    result = runner.invoke(app, ["fit", str(EXAMPLES / "spiral.csv"), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "flown at 1 m (--altitude)" in " ".join(result.output.split())
    ((_, planned),) = read_plan(out)
    t = np.linspace(0.0, planned.trajectory.duration, 2001)
    z = planned.trajectory.evaluate(t)[:, 2]
    np.testing.assert_allclose(z, 1.0, atol=1e-9)
    summary = json.loads((out / "summary.json").read_text())
    (drone,) = summary["plan"]["drones"]  # the plan writer's record
    assert planned.phases is not None and drone["phases"] == planned.phases.as_dict()
    assert drone["phases"]["min_altitude_m"] == 0.3 and drone["phases"]["lowest_m"] >= 0.3
    assert summary["altitude_m"] == 1.0
