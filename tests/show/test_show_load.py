"""Reading a show: plan directories, trajectory files, .skyc from skyquill's exporter, together."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from show_cases import plan, row
from typer.testing import CliRunner

from skyquill.cli.main import app
from skyquill.errors import InputError
from skyquill.show import load_show


@pytest.fixture(scope="module")
def three(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return plan(tmp_path_factory.mktemp("three"), row(0.0))


def test_a_plan_directory_with_several_drones(three: Path) -> None:
    drones = load_show([three])
    assert [d.name for d in drones] == [f"{three.name}/trajectory_{i}" for i in range(3)]
    expected = row(0.0)
    for drone, traj in zip(drones, expected, strict=True):
        t = np.linspace(0.0, traj.duration, 50)
        assert np.allclose(drone.trajectory.evaluate(t), traj.evaluate(t), atol=1e-9)
        assert drone.start_s == 0.0


@pytest.mark.parametrize("name", ["trajectory_1.json", "trajectory_1.csv"])
def test_a_single_trajectory_file(three: Path, name: str) -> None:
    (drone,) = load_show([three / name])
    assert drone.name == f"{three.name}/trajectory_1"
    assert drone.trajectory.duration == pytest.approx(7.0)


def test_a_skyc_written_by_skyquill(three: Path, tmp_path: Path) -> None:
    show = tmp_path / "show.skyc"
    result = CliRunner().invoke(app, ["export", str(three), "--format", "skyc", "--out", str(show)])
    assert result.exit_code == 0, result.output
    drones = load_show([show])
    assert [d.name for d in drones] == [f"show.skyc/trajectory_{i}" for i in range(3)]
    # A Skybrush show starts and ends on its pads (issue 26): the plan with its climb from
    # the ground and its descent to it.
    from skyquill.export.skybrush.pads import on_pads
    from skyquill.io.plan_dir import read_plan

    delivered = [on_pads(planned).trajectory for _, planned in read_plan(three)]
    for drone, traj in zip(drones, delivered, strict=True):
        t = np.linspace(0.0, traj.duration, 50)
        # Skybrush's mm grid: the played show is within a millimetre of the plan.
        assert np.abs(drone.trajectory.evaluate(t) - traj.evaluate(t)).max() < 1e-3


def test_several_paths_are_one_show(three: Path, tmp_path: Path) -> None:
    other = plan(tmp_path / "other", row(20.0)[:1])
    drones = load_show([three, other / "trajectory.json"])
    assert len(drones) == 4 and drones[-1].name == "other/trajectory"


def test_a_missing_path_and_an_unknown_type_are_refused(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"PATH: got '.*nope', which does not exist"):
        load_show([tmp_path / "nope"])
    odd = tmp_path / "show.txt"
    odd.write_text("x")
    with pytest.raises(InputError, match=r"PATH: got '.*show.txt', expected a plan directory or"):
        load_show([odd])
    with pytest.raises(InputError, match=r"PATH: got none"):
        load_show([])
