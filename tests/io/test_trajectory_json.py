"""trajectory.json: every kind with its pen windows and limits; version 1 still read."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from skyquill.errors import InputError
from skyquill.io.trajectory_json import (
    PlannedTrajectory,
    read_trajectory_json,
    write_trajectory_json,
)
from skyquill.limits import BoxLimit, CylinderLimit, NormLimit
from skyquill.trajectory import SplineTrajectory

SPLINE = SplineTrajectory(np.arange(18, dtype=float).reshape(6, 3), 5, 2.0)


def test_limits_and_pen_round_trip(tmp_path: Path) -> None:
    limits = (NormLimit(1, 1.5), BoxLimit.symmetric(2, 2.0, 3), CylinderLimit(3, 4.0, -1.0, 1.0))
    write_trajectory_json(tmp_path / "t.json", PlannedTrajectory(SPLINE, ((0.1, 0.5),), limits))
    back = read_trajectory_json(tmp_path / "t.json")
    assert back.pen_windows_s == ((0.1, 0.5),)
    assert [lim.label for lim in back.limits] == [lim.label for lim in limits]
    np.testing.assert_array_equal(back.pen(np.array([0.0, 0.3])), [0.0, 1.0])


def test_version_1_is_read(tmp_path: Path) -> None:
    legacy = {
        "format": "skyquill-bspline",
        "version": 1,
        "degree": 5,
        "duration_s": 2.0,
        "control_points": SPLINE.control_points.tolist(),
        "pen_windows_s": [[0.0, 1.0]],
    }
    (tmp_path / "old.json").write_text(json.dumps(legacy))
    back = read_trajectory_json(tmp_path / "old.json")
    assert isinstance(back.trajectory, SplineTrajectory) and back.pen_windows_s == ((0.0, 1.0),)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("{", "invalid JSON"),
        ("[" * 100_000 + "]" * 100_000, "nested too deeply"),
        ('{"format": "other"}', "got format 'other'"),
        ('{"format": "skyquill-trajectory", "trajectory": {"kind": "x"}}', "kind: got 'x'"),
        ('{"format": "skyquill-trajectory", "trajectory": {}, "limits": {}}', "limits: got a JSON"),
    ],
)
def test_malformed_files_are_named(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "bad.json"
    path.write_text(text)
    with pytest.raises(InputError, match=message):
        read_trajectory_json(path)


def test_bad_limits_and_windows_are_named(tmp_path: Path) -> None:
    good = json.loads(json.dumps({"format": "skyquill-trajectory", "version": 2}))
    good["trajectory"] = {"kind": "bspline", "degree": 5, "duration_s": 2.0,
                          "control_points": SPLINE.control_points.tolist()}  # fmt: skip
    for field, value, message in (
        ("limits", [{"type": "Magic"}], "expected one of"),
        ("limits", [{"type": "BoxLimit", "order": 1}], "expected"),
        ("pen_windows_s", [[1.0, 0.5]], "overlapping or reversed"),
    ):
        (tmp_path / "x.json").write_text(json.dumps(good | {field: value}))
        with pytest.raises(InputError, match=message):
            read_trajectory_json(tmp_path / "x.json")
