"""Point CSV reading and trajectory.csv / summary.json writing."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from skyquill.errors import InputError
from skyquill.io.atomic import write_json
from skyquill.io.points import (
    TRAJECTORY_COLUMNS,
    read_points_csv,
    table_text,
    trajectory_table,
    write_trajectory_csv,
)
from skyquill.trajectory import SplineTrajectory


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "points.csv"
    path.write_text(text, encoding="utf-8")
    return path


def test_reads_xy_xyz_and_t_in_any_column_order(tmp_path: Path) -> None:
    pts, t = read_points_csv(write(tmp_path, "x,y\n0,0\n1,2\n"))
    assert pts.shape == (2, 2) and t is None
    pts, t = read_points_csv(write(tmp_path, "t, Z ,y,x\n0,3,2,1\n0.5,6,5,4\n"))
    assert np.array_equal(pts, [[1, 2, 3], [4, 5, 6]])
    assert t is not None and np.array_equal(t, [0.0, 0.5])


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("a,b\n1,2\n3,4\n", r"got columns \['a', 'b'\], expected columns x,y .*missing x,y"),
        ("x,z\n1,2\n3,4\n", "missing y"),
        ("x,y\n1,2\n", "got 1 data row"),
        ("x,y\n1,2\n3,oops\n", "line 3, column y: got 'oops', expected a number"),
        ("x,y\n1,2\n3,nan\n", "line 3, column y: got 'nan', expected a finite number"),
        ("x,y\n1,2\n3\n", "line 3: got 1 columns, expected 2"),
        ("", "got an empty file, expected a header line with columns x,y"),
    ],
)
def test_bad_csv_is_named(tmp_path: Path, text: str, message: str) -> None:
    with pytest.raises(InputError, match=message):
        read_points_csv(write(tmp_path, text))


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"points file: got .*nope\.csv', expected an existing"):
        read_points_csv(tmp_path / "nope.csv")


@settings(max_examples=60, deadline=None)
@given(st.text(max_size=200))
def test_hostile_csv_text_gives_input_error_or_points(text: str) -> None:
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "p.csv"
        path.write_text("x,y\n" + text, encoding="utf-8")
        try:
            pts, _ = read_points_csv(path)
        except InputError:
            return
        assert np.all(np.isfinite(pts))


def test_trajectory_csv_columns_and_2d_padding(tmp_path: Path) -> None:
    traj = SplineTrajectory(np.random.default_rng(0).normal(size=(8, 2)), 5, 2.0)
    rows = write_trajectory_csv(tmp_path / "trajectory.csv", traj, 50.0)
    header = (tmp_path / "trajectory.csv").read_text().splitlines()[0]
    assert tuple(header.split(",")) == TRAJECTORY_COLUMNS
    data = np.loadtxt(tmp_path / "trajectory.csv", delimiter=",", skiprows=1)
    assert data.shape == (rows, 13) and rows == 101
    assert np.array_equal(data[:, 3], np.zeros(rows))  # z = 0 for 2-D input
    t = data[:, 0]
    assert t[0] == 0.0 and t[-1] == pytest.approx(2.0)
    table = trajectory_table(traj, 50.0)
    assert np.allclose(data, table, rtol=1e-8, atol=1e-9)
    assert np.allclose(table[:, 7:9], traj.evaluate(t, 2), atol=1e-9)


def test_write_json_refuses_nan(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="Out of range float"):
        write_json(tmp_path / "s.json", {"x": float("nan")})


def test_a_trajectory_csv_is_never_longer_than_its_read_back_takes(tmp_path: Path) -> None:
    """Issue 25: paint at its dot ceiling wrote 813 MB of trajectory.csv, then refused it."""
    from skyquill.io.points import check_rows_written, write_trajectory_csv
    from skyquill.io.table import MAX_ROWS

    check_rows_written(MAX_ROWS / 100.0 - 1.0, 100.0)
    long = SplineTrajectory(np.zeros((6, 3)), 5, MAX_ROWS / 100.0)
    with pytest.raises(
        InputError, match=r"^rate: got 100 Hz over a 10000 s flight \(1,000,002 rows\)"
    ):
        write_trajectory_csv(tmp_path / "t.csv", long, 100.0)
    assert not (tmp_path / "t.csv").exists()


def test_the_refusal_names_where_the_rate_came_from() -> None:
    from skyquill.io.points import check_rows_written

    with pytest.raises(InputError, match=r"^\[show\]\.rate: got 100 Hz over a 20000 s flight"):
        check_rows_written(20_000.0, 100.0, "[show].rate")


@settings(max_examples=40, deadline=None)
@given(
    table=hnp.arrays(
        float,
        hnp.array_shapes(min_dims=2, max_dims=2, min_side=0, max_side=12),
        elements=st.floats(allow_nan=True, allow_infinity=True, width=64),
    ),
)
def test_table_text_is_what_savetxt_writes(table: np.ndarray, tmp_path_factory: Any) -> None:
    path = tmp_path_factory.mktemp("savetxt") / "t.csv"
    header = ",".join(f"c{i}" for i in range(table.shape[1]))
    np.savetxt(path, table, delimiter=",", header=header, comments="", fmt="%.9g")
    assert table_text(table, header).encode("latin-1") == path.read_bytes()
