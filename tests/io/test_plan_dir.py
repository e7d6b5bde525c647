"""The plan directory: one writer, the check on what was written, one reader for fly/export."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from skyquill.errors import InputError
from skyquill.io.plan_dir import read_plan, trajectory_names, write_plan
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.limits import VehicleLimits
from skyquill.trajectory import SplineTrajectory


def _spline(seed: int = 0, dim: int = 3) -> SplineTrajectory:
    ctrl = np.random.default_rng(seed).normal(scale=0.2, size=(12, dim))
    ctrl[:, -1] += 1.0  # in the air: the mission keeps the minimum altitude (0.3 m)
    ctrl[:3] = ctrl[0]  # at rest at both ends
    ctrl[-3:] = ctrl[-1]
    return SplineTrajectory(ctrl, 5, 4.0)


def _write(out: Path, n: int = 1, **kwargs: object) -> dict[str, object]:
    limits = VehicleLimits(5.0, 5.0, 50.0).derivative_limits(3)
    planned = [PlannedTrajectory(_spline(i), ((0.5, 2.0),), limits) for i in range(n)]
    return write_plan(out, planned, rate=50.0, guaranteed=True, summary={"mine": 1}, **kwargs)  # type: ignore[arg-type]


def test_one_drone_writes_checks_and_reads_back(tmp_path: Path) -> None:
    summary = _write(tmp_path, plot=lambda path: path.write_bytes(b"png"))
    assert {p.name for p in tmp_path.iterdir()} == {
        "trajectory.csv", "trajectory.json", "summary.json", "plot.png"
    }  # fmt: skip
    on_disk = json.loads((tmp_path / "summary.json").read_text())
    assert on_disk == summary and on_disk["mine"] == 1
    drone = on_disk["plan"]["drones"][0]
    assert drone["kind"] == "bspline" and drone["rows"] == 201
    assert drone["verification"]["max_excess"] == 0.0
    assert drone["verification"]["csv_max_difference_m"] < 1e-6
    header = (tmp_path / "trajectory.csv").read_text().splitlines()[0]
    assert header.endswith(",yaw,pen")
    [(name, planned)] = read_plan(tmp_path)
    assert name == "trajectory" and planned.pen_windows_s == ((0.5, 2.0),)
    assert len(planned.limits) == 3
    np.testing.assert_array_equal(planned.trajectory.control_points, _spline(0).control_points)  # type: ignore[attr-defined]


def test_several_drones_and_the_summary_decides_which_files(tmp_path: Path) -> None:
    _write(tmp_path, n=3)
    assert [n for n, _ in read_plan(tmp_path)] == ["trajectory_0", "trajectory_1", "trajectory_2"]
    # Planned again with one drone: the stale numbered files are not what the plan holds.
    _write(tmp_path, n=1)
    assert [n for n, _ in read_plan(tmp_path)] == ["trajectory"]
    assert trajectory_names(2) == [
        ("trajectory_0.csv", "trajectory_0.json"), ("trajectory_1.csv", "trajectory_1.json")
    ]  # fmt: skip


def test_single_files_are_plans_too(tmp_path: Path) -> None:
    _write(tmp_path)
    [(_, from_json)] = read_plan(tmp_path / "trajectory.json")
    [(_, from_csv)] = read_plan(tmp_path / "trajectory.csv")
    t = np.linspace(0.0, 4.0, 101)
    np.testing.assert_allclose(
        from_csv.trajectory.evaluate(t), from_json.trajectory.evaluate(t), atol=1e-6
    )


def test_bad_plans_are_named(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"plan: got .* expected a plan directory"):
        read_plan(tmp_path / "absent")
    with pytest.raises(InputError, match=r"without trajectory\.json"):
        read_plan(tmp_path)
    (tmp_path / "summary.json").write_text("{not json")
    with pytest.raises(InputError, match=r"summary.json: got malformed JSON"):
        read_plan(tmp_path)
    with pytest.raises(InputError, match="expected 3 \\(x, y, z\\)"):
        write_plan(
            tmp_path / "o",
            [PlannedTrajectory(_spline(dim=2))],
            rate=10.0,
            guaranteed=True,
            summary={},
        )
    with pytest.raises(InputError, match="expected at least one"):
        write_plan(tmp_path / "o", [], rate=10.0, guaranteed=True, summary={})


def test_the_phases_are_recorded_and_a_mission_below_the_minimum_altitude_refused(
    tmp_path: Path,
) -> None:
    from skyquill.errors import InfeasibleError

    summary = _write(tmp_path / "ok")
    drone = summary["plan"]["drones"][0]  # type: ignore[index]
    assert summary["plan"]["min_altitude_m"] == 0.3  # type: ignore[index]
    assert drone["phases"]["mission_s"] == [0.0, 4.0] and drone["phases"]["lowest_m"] >= 0.3
    [(_, planned)] = read_plan(tmp_path / "ok")
    assert planned.phases is not None and planned.phases.as_dict() == drone["phases"]
    with pytest.raises(InfeasibleError, match=r"min_altitude_m: got a plan that never rests"):
        _write(tmp_path / "low", min_altitude_m=1.5)


def test_files_written_by_worker_processes_are_the_ones_written_here(tmp_path: Path) -> None:
    here = _write(tmp_path / "here", n=5)
    there = _write(tmp_path / "there", n=5, workers=2)
    assert there == here
    for name in sorted(p.name for p in (tmp_path / "here").iterdir()):
        assert (tmp_path / "there" / name).read_bytes() == (tmp_path / "here" / name).read_bytes()
