"""The Crazyflie fly script replayed through the firmware's high-level commander (issue 26).

Each plan is made by ``skyquill fit --target crazyflie`` and exported by ``skyquill export
--format crazyswarm``; the fly script written beside the uploads flies it through cflib's
own commander and memory into the model of crazyflie-firmware's high-level commander
(``replay_link.py``, :mod:`skyquill.export.crazyflie.commander`). From the end of the
firmware's take-off to the landing command, the position it commands never goes below the
minimum altitude: for a plan that starts on the ground, one that starts in the air, and a
2-D fit.
"""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from skyquill.cli.main import app
from skyquill.io.plan_dir import read_plan

sys.path.insert(0, str(Path(__file__).parent))
from replay_link import ReplayLink

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
runner = CliRunner()
#: Round-off allowed below the minimum altitude (float32 positions), m.
FLOAT32_M = 1e-6


FLOOR_M = 0.5


def _ground_plan(folder: Path) -> None:
    """A plan with its own take-off and landing: a time-optimal climb from the ground to
    1 m, a loop at about 1 m (the engine's degree-7 spline, 20 pieces), straight down;
    rest to rest, as a plan directory."""
    from skyquill.io.plan_dir import write_plan
    from skyquill.io.trajectory_json import PlannedTrajectory
    from skyquill.limits import VehicleLimits
    from skyquill.optimize import Boundary, PointDeviation, SmoothingProblem, solve
    from skyquill.optimize.legs import LegLimits, stop_and_go
    from skyquill.trajectory import RestToRestSequence

    limits = VehicleLimits(1.0, 2.0, 8.0).derivative_limits(3)
    t = np.linspace(0.0, 4.0, 81)
    s = t / 4.0
    angle = 2 * np.pi * s**3 * (10 - 15 * s + 6 * s**2)
    loop = np.column_stack(
        [0.5 * np.sin(angle), 0.5 * (1 - np.cos(angle)), 1 + 0.2 * np.sin(angle)]
    )
    problem = SmoothingProblem(
        dim=3, degree=7, n_ctrl=27, duration=4.0, deviations=(PointDeviation(t, loop, 1e6),),
        boundary=Boundary.rest(loop[0], loop[-1], 4), limits=limits,
    )  # fmt: skip
    legs = LegLimits(1.0, 2.0, 8.0)
    up = stop_and_go(np.array([[0.0, 0.0, 0.0], loop[0]]), legs).trajectory
    down = stop_and_go(np.array([loop[-1], [0.0, 0.0, 0.0]]), legs).trajectory
    plan = RestToRestSequence((up, solve(problem).trajectory, down))
    write_plan(folder, [PlannedTrajectory(plan, (), limits)], rate=50.0, guaranteed=True,
               summary={}, min_altitude_m=FLOOR_M)  # fmt: skip


def _planned(tmp_path: Path, case: str) -> tuple[Path, float]:
    """Plan and export ``case``; the export folder and the minimum altitude planned for."""
    plan = tmp_path / "plan"
    if case == "ground":
        _ground_plan(plan)
    else:
        args = (
            [str(EXAMPLES / "segments.csv"), "--timing", "segments"]
            if case == "air"
            else [str(EXAMPLES / "spiral.csv"), "--altitude", "0.8"]  # a 2-D drawing at 0.8 m
        )
        result = runner.invoke(
            app, ["fit", *args, "--target", "crazyflie", "--min-altitude", str(FLOOR_M),
                  "--out", str(plan)],
        )  # fmt: skip
        assert result.exit_code == 0, result.output
    floor = FLOOR_M
    out = tmp_path / "cf" / "cs.csv"
    result = runner.invoke(app, ["export", str(plan), "--format", "crazyswarm", "--out", str(out)])
    assert result.exit_code == 0, result.output
    return out.parent, floor


def _script(folder: Path, monkeypatch: pytest.MonkeyPatch) -> Any:
    spec = importlib.util.spec_from_file_location("cs_fly", folder / "cs_fly.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, "cs_fly", module)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("case", ["ground", "air", "2d"])
def test_the_commanded_position_stays_above_the_minimum_altitude(
    case: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    folder, floor = _planned(tmp_path, case)
    script = _script(folder, monkeypatch)
    flight = script.flight_of(None, script.SCHEDULE)
    script.check_mission(flight, folder)  # the script's own refusal passes
    # The drone stands on its pad, below the mission's first point.
    pad = (flight.first_point[0], flight.first_point[1], 0.0)
    link = ReplayLink(pad)
    script.fly(link.cf, flight, folder, clock=link.clock, sleep=link.sleep)
    link.sleep(1.0)
    (takeoff,), (land,) = link.when("takeoff"), link.when("land")
    assert link.when("stop") and link.setpoints[-1][1] is None  # motors off at the end
    airborne = link.commanded(takeoff + flight.takeoff_s, land)
    assert airborne.size and airborne[:, 2].min() >= floor - FLOAT32_M
    # the take-off climbs from the pad, the landing comes down to the ground
    climb = link.commanded(takeoff, takeoff + flight.takeoff_s)
    assert climb[0, 2] < 0.05 and climb[-1, 2] == pytest.approx(flight.first_point[2], abs=1e-3)
    assert link.commanded(land, link.now)[-1, 2] == pytest.approx(0.0, abs=1e-3)
    # during the uploads the firmware commands the plan's mission
    summary = json.loads((folder / "cs.csv.summary.json").read_text())
    mission = summary["drone_uploads"][0]["flight"]["mission_s"]
    ((_, planned),) = read_plan(tmp_path / "plan")
    (start,) = link.when("start_trajectory")[:1]
    t_end = start + summary["drone_uploads"][0]["uploads"][0]["end_s"]
    during = [(t, g.position) for t, g in link.setpoints if start < t < t_end and g is not None]
    times = np.array([t - start + mission[0] for t, _ in during])
    np.testing.assert_allclose(
        np.array([p for _, p in during]), planned.trajectory.evaluate(times), atol=1e-5
    )


def test_the_script_refuses_a_mission_below_the_minimum_altitude(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The schedule says 0.5 m; a mission edited to pass lower is refused before flying."""
    folder, _ = _planned(tmp_path, "air")
    script = _script(folder, monkeypatch)
    flight = script.flight_of(None, script.SCHEDULE)
    from dataclasses import replace

    with pytest.raises(SystemExit) as exit_info:
        script.check_mission(replace(flight, min_altitude_m=1.2), folder)
    assert exit_info.value.code == 2
    assert "error: mission: got" in capsys.readouterr().err


@pytest.mark.parametrize(("found", "ok"), [((0, 1, 28), False), ((0, 1, 29), True), ((1, 0), True)])
def test_the_script_checks_the_cflib_it_needs(
    found: tuple[int, ...], ok: bool, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    folder, _ = _planned(tmp_path, "air")
    script = _script(folder, monkeypatch)
    if ok:
        script.check_cflib(found)
        return
    with pytest.raises(SystemExit):
        script.check_cflib(found)
    assert script.cflib_version() >= script.CFLIB_NEEDED  # the one installed here


@pytest.mark.parametrize("case", ["ground", "air", "2d"])
def test_the_whole_flight_checked_is_what_the_firmware_commands(
    case: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The exporter's model of the whole flight (take-off, approach, uploads, landing) is
    the position the replayed firmware commands, tick by tick, and keeps the plan's limits
    from motors start to stop (summary: the flight's ``as_played``)."""
    from skyquill.export.crazyflie.exporter import read_export
    from skyquill.export.crazyflie.whole_flight import whole_flight

    folder, floor = _planned(tmp_path, case)
    script = _script(folder, monkeypatch)
    flight = script.flight_of(None, script.SCHEDULE)
    pad = np.array([flight.first_point[0] + 0.3, flight.first_point[1], 0.0])
    link = ReplayLink(tuple(pad))
    script.fly(link.cf, flight, folder, clock=link.clock, sleep=link.sleep)
    (takeoff,) = link.when("takeoff")
    summary = json.loads((folder / "cs.csv.summary.json").read_text())
    (drone,) = summary["drone_uploads"]
    flown = read_export(folder / "cs.csv.summary.json")[drone["drone"]]
    model = whole_flight(drone["flight"], flown, pad=pad)
    ticks = [(t - takeoff, g.position) for t, g in link.setpoints if t > takeoff and g is not None]
    times = np.array([t for t, _ in ticks])
    assert times[-1] == pytest.approx(model.duration, abs=0.011)
    np.testing.assert_allclose(
        np.array([p for _, p in ticks]), model.evaluate(np.minimum(times, model.duration)),
        atol=2e-5,
    )  # fmt: skip
    played = drone["flight"]["as_played"]
    assert max(played["relative_excess"].values()) <= 1e-6  # float32 rounding only
    assert played["lowest_after_takeoff_m"] >= floor - FLOAT32_M
    assert summary["as_played"]["every_limit_met"]


def test_a_take_off_too_short_for_the_limits_is_seen_as_played(tmp_path: Path) -> None:
    """The whole-flight check sees the firmware's take-off: halved, it breaks the limits."""
    from skyquill.export.crazyflie.exporter import read_export
    from skyquill.export.crazyflie.whole_flight import whole_flight
    from skyquill.verify import verify

    folder, _ = _planned(tmp_path, "air")
    summary = json.loads((folder / "cs.csv.summary.json").read_text())
    (drone,) = summary["drone_uploads"]
    flown = read_export(folder / "cs.csv.summary.json")[drone["drone"]]
    ((_, planned),) = read_plan(tmp_path / "plan")
    flight = drone["flight"]
    flight["takeoff"]["duration_s"] /= 2
    check = verify(whole_flight(flight, flown), planned.limits, guaranteed=False)
    assert check.max_excess > 0.5
