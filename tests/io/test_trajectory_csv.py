"""Reading trajectory.csv back (SampledTrajectory) and writing flight.csv."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.io.points import TRAJECTORY_COLUMNS, trajectory_table, write_trajectory_csv
from skyquill.io.trajectory_csv import (
    FLIGHT_COLUMNS,
    REQUIRED_COLUMNS,
    read_trajectory_csv,
    write_flight_csv,
)
from skyquill.sim import simulate
from skyquill.trajectory import SampledTrajectory, SplineTrajectory, Trajectory

HEADER = ",".join(TRAJECTORY_COLUMNS)


def spline(seed: int = 0, dim: int = 3) -> SplineTrajectory:
    """A random quintic over 6 s, 24 control points in a 1 m cube (about 1 m/s)."""
    ctrl = np.random.default_rng(seed).uniform(-0.5, 0.5, (24, dim))
    return SplineTrajectory(ctrl, 5, 6.0)


def write(tmp_path: Path, text: str, name: str = "traj.csv") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def rows(n: int = 3, columns: tuple[str, ...] = TRAJECTORY_COLUMNS) -> str:
    """A valid table of ``n`` rows at 10 Hz with the given columns."""
    lines = [",".join(columns)]
    for i in range(n):
        values = {c: 0.1 * i if c in ("t", "x") else 0.0 for c in columns}
        values["vx"] = 1.0
        lines.append(",".join(f"{values[c]:g}" for c in columns))
    return "\n".join(lines) + "\n"


def test_round_trip_at_100_hz(tmp_path: Path) -> None:
    traj = spline()
    path = tmp_path / "trajectory.csv"
    write_trajectory_csv(path, traj, 100.0)
    back = read_trajectory_csv(path)
    assert isinstance(back, Trajectory)
    assert back.dim == 3 and back.t0 == 0.0
    assert back.duration == pytest.approx(traj.duration, abs=1e-9)
    t = np.random.default_rng(1).uniform(0.0, traj.duration, 2000)
    t = np.concatenate([t, [0.0, traj.duration]])
    assert np.abs(back.evaluate(t) - traj.evaluate(t)).max() < 1e-6
    assert np.abs(back.evaluate(t, 1) - traj.evaluate(t, 1)).max() < 1e-4
    # Linear between samples: off by ~h^2 |a''| / 8.
    scale = np.abs(traj.evaluate(t, 2)).max()
    assert np.abs(back.evaluate(t, 2) - traj.evaluate(t, 2)).max() < 1e-2 * scale
    scale = np.abs(traj.evaluate(t, 3)).max()
    assert np.abs(back.evaluate(t, 3) - traj.evaluate(t, 3)).max() < 2e-2 * scale


def test_exact_at_the_samples_and_sample_method(tmp_path: Path) -> None:
    traj = spline(2)
    path = tmp_path / "trajectory.csv"
    write_trajectory_csv(path, traj, 50.0)
    table = np.loadtxt(path, delimiter=",", skiprows=1)
    back = read_trajectory_csv(path)
    for order, cols in enumerate((slice(1, 4), slice(4, 7), slice(7, 10), slice(10, 13))):
        assert np.allclose(back.evaluate(table[:, 0], order), table[:, cols], atol=1e-12)
    s = back.sample(20.0)
    assert s.t[0] == 0.0 and s.t[-1] == pytest.approx(back.duration)
    assert s.p.shape == s.v.shape == s.a.shape == s.j.shape == (s.t.size, 3)


def test_two_dimensional_plan_reads_back_with_z_zero(tmp_path: Path) -> None:
    traj = spline(3, dim=2)
    path = tmp_path / "trajectory.csv"
    write_trajectory_csv(path, traj, 100.0)
    back = read_trajectory_csv(path)
    t = np.linspace(0.0, traj.duration, 333)
    assert np.abs(back.evaluate(t)[:, :2] - traj.evaluate(t)).max() < 1e-6
    assert np.all(back.evaluate(t)[:, 2] == 0.0)


def test_start_time_is_shifted_to_zero(tmp_path: Path) -> None:
    traj = spline(4)
    table = trajectory_table(traj, 100.0)
    table[:, 0] += 12.5
    path = tmp_path / "late.csv"
    np.savetxt(path, table, delimiter=",", header=HEADER, comments="", fmt="%.12g")
    back = read_trajectory_csv(path)
    assert back.t0 == pytest.approx(12.5)
    assert back.duration == pytest.approx(traj.duration)
    t = np.linspace(0.0, traj.duration, 101)
    assert np.abs(back.evaluate(t) - traj.evaluate(t)).max() < 1e-6


def test_without_jerk_columns_jerk_is_the_slope_of_the_acceleration(tmp_path: Path) -> None:
    traj = spline(5)
    table = trajectory_table(traj, 100.0)[:, :10]
    path = tmp_path / "nojerk.csv"
    np.savetxt(path, table, delimiter=",", header=",".join(REQUIRED_COLUMNS), comments="")
    back = read_trajectory_csv(path)
    assert back.j is None
    mid = 0.5 * (table[:-1, 0] + table[1:, 0])
    slope = np.diff(table[:, 7:10], axis=0) / np.diff(table[:, 0])[:, None]
    assert np.allclose(back.evaluate(mid, 3), slope)
    assert np.all(back.evaluate(mid, 4) == 0.0)


def test_higher_orders_are_derivatives_of_the_jerk_interpolant(tmp_path: Path) -> None:
    path = tmp_path / "trajectory.csv"
    write_trajectory_csv(path, spline(6), 100.0)
    back = read_trajectory_csv(path)
    t = np.array([0.005, 1.0051])
    h = 1e-5
    finite = (back.evaluate(t + h, 3) - back.evaluate(t - h, 3)) / (2 * h)
    assert np.allclose(back.evaluate(t, 4), finite, rtol=1e-6, atol=1e-6)
    assert np.all(back.evaluate(t, 5) == 0.0)


def test_evaluate_refuses_times_outside_and_negative_orders(tmp_path: Path) -> None:
    back = read_trajectory_csv(write(tmp_path, rows()))
    with pytest.raises(
        InputError, match=r"t: got times in \[-1, 0\] s, expected within \[0, 0.2\]"
    ):
        back.evaluate(np.array([-1.0, 0.0]))
    with pytest.raises(InputError, match="order: got -1"):
        back.evaluate(np.array([0.0]), -1)


def test_flies_in_the_simulator(tmp_path: Path) -> None:
    path = tmp_path / "trajectory.csv"
    traj = SplineTrajectory(np.random.default_rng(7).uniform(-0.1, 0.1, (12, 3)), 5, 8.0)
    write_trajectory_csv(path, traj, 100.0)
    ours, theirs = simulate(read_trajectory_csv(path)), simulate(traj)
    # The random spline does not start at rest, so both flights have the same
    # start-up transient: only their agreement is checked.
    assert abs(ours.rmse_m - theirs.rmse_m) < 1e-5
    assert np.abs(ours.p - theirs.p).max() < 1e-4


def test_write_flight_csv(tmp_path: Path) -> None:
    flight = simulate(spline(8), rate_hz=100.0)
    path = tmp_path / "flight.csv"
    n = write_flight_csv(path, flight)
    assert path.read_text().splitlines()[0] == ",".join(FLIGHT_COLUMNS)
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    assert data.shape == (n, 18) == (flight.t.size, 18)
    assert np.allclose(data[:, 4:7], flight.p, atol=1e-8)
    assert np.allclose(data[:, 16], flight.thrust)


BAD = [
    (rows().replace("vx", "speed"), r"traj.csv: got columns \[.*\], expected columns t,x,y,z"),
    ("t,x,y,z\n0,0,0,0\n1,1,1,1\n", "traj.csv: got columns .* missing vx,vy,vz,ax,ay,az"),
    ("", r"traj.csv: got an empty file, expected a header line with columns t,x,y,z"),
    (rows(1), r"traj.csv: got 1 data row\(s\), expected at least 2"),
    (rows(0), r"traj.csv: got 0 data row\(s\), expected at least 2"),
    (rows().replace("\n0.1,0.1,", "\n0.1,abc,"), "traj.csv line 3, column x: got 'abc', expected"),
    (rows() + "0.3,0.3\n", "traj.csv line 5: got 2 columns, expected 13"),
    (rows().replace("\n0.2,0.2,0,0,1", "\n0.2,0.2,0,nan,1"), "line 4, column z: got 'nan', "),
    (
        rows().replace("\n0,0,0,0,1", "\n0,0,0,0,inf"),
        "line 2, column vx: got 'inf', expected a fin",
    ),
    (rows().replace("\n0.2,", "\n0.1,"), "line 4, column t: got 0.1 after 0.1, expected strictly"),
    (rows().replace("\n0.2,", "\n0.05,"), "line 4, column t: got 0.05 after 0.1, expected strict"),
    (
        rows().replace("\n0.1,0.1,0,0,1", "\n0.1,0.1,0,0,1e9"),
        r"line 3, column vx: got 1e\+09, expected a magnitude of at most 1e\+06",
    ),
    (rows(3, (*REQUIRED_COLUMNS, "jx")), "got jerk column.s. jx, expected all of jx,jy,jz or none"),
    (rows().replace("\n", ",0\n").replace("jz,0", "jz,vx"), r"got column\(s\) 'vx' more than once"),
    ('t,x\n"0,0\n', "traj.csv: got columns"),
]


@pytest.mark.parametrize(("text", "message"), BAD)
def test_bad_files_raise_input_error_naming_file_and_place(
    tmp_path: Path, text: str, message: str
) -> None:
    with pytest.raises(InputError, match=message):
        read_trajectory_csv(write(tmp_path, text))


def test_missing_file_and_non_utf8(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"trajectory file: got '.*nope.csv', expected an exist"):
        read_trajectory_csv(tmp_path / "nope.csv")
    with pytest.raises(InputError, match=r"got a folder, expected a CSV file \(a regular file\)"):
        read_trajectory_csv(tmp_path)
    path = tmp_path / "binary.csv"
    path.write_bytes(HEADER.encode() + b"\n\xff\xfe\x00\n")
    with pytest.raises(InputError, match=r"binary\.csv: got bytes that are not UTF-8"):
        read_trajectory_csv(path)


def test_blank_lines_extra_columns_spaces_and_any_order_are_fine(tmp_path: Path) -> None:
    text = "AX , ay,az, t,x,y,z,vx,vy,vz,note\n0,0,0,0,0,0,0,1,0,0,a\n\n0,0,0,0.1,0.1,0,0,1,0,0,b\n"
    back = read_trajectory_csv(write(tmp_path, text))
    assert back.duration == pytest.approx(0.1)
    assert back.evaluate(np.array([0.05]))[0, 0] == pytest.approx(0.05)


def test_constructor_validates() -> None:
    t = np.array([0.0, 0.1, 0.2])
    ok = np.zeros((3, 3))
    with pytest.raises(InputError, match=r"p: got an array of shape \(3, 2\), expected shape"):
        SampledTrajectory(t, np.zeros((3, 2)), ok, ok)
    with pytest.raises(InputError, match=r"t: got t\[0\] = 0.2 followed by 0.1, expected strictly"):
        SampledTrajectory(t[::-1], ok, ok, ok)
    with pytest.raises(InputError, match=r"t: got 1 sample\(s\), expected at least 2"):
        SampledTrajectory(t[:1], ok[:1], ok[:1], ok[:1])
    with pytest.raises(InputError, match=r"j: got 1 NaN or infinite value"):
        SampledTrajectory(t, ok, ok, ok, np.array([[0.0, 0.0, np.nan], [0, 0, 0], [0, 0, 0]]))


_CELL = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-5, 5).map(str),
    st.text(alphabet=st.characters(exclude_categories=("Cs",)), max_size=6),
    st.sampled_from(["", " ", "nan", "1e999", '"', "1,2", "\n", "\x00", "0x10", "1_0"]),
)
_ROW = st.lists(_CELL, min_size=0, max_size=15).map(",".join)
_HEADER = st.one_of(
    st.just(HEADER),
    st.just(",".join(REQUIRED_COLUMNS)),
    st.permutations(TRAJECTORY_COLUMNS).map(",".join),
    _ROW,
)


@settings(
    max_examples=300, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(header=_HEADER, body=st.lists(_ROW, max_size=6))
def test_random_text_gives_input_error_or_a_usable_trajectory(
    tmp_path: Path, header: str, body: list[str]
) -> None:
    path = tmp_path / "fuzz.csv"
    path.write_text("\n".join([header, *body]) + "\n", encoding="utf-8")
    try:
        traj = read_trajectory_csv(path)
    except InputError:
        return
    t = np.linspace(0.0, traj.duration, 7)
    for order in range(5):
        assert np.all(np.isfinite(traj.evaluate(t, order)))


@settings(
    max_examples=100, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    table=st.lists(st.lists(st.floats(-1e3, 1e3), min_size=13, max_size=13), min_size=2, max_size=8)
)
def test_random_numeric_tables(tmp_path: Path, table: list[list[float]]) -> None:
    path = tmp_path / "numeric.csv"
    lines = [HEADER] + [",".join(repr(v) for v in row) for row in table]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    t = np.array([row[0] for row in table])
    try:
        traj = read_trajectory_csv(path)
    except InputError as exc:
        assert "strictly increasing" in str(exc)
        assert np.any(np.diff(t) < 1e-6)
        return
    assert traj.duration == pytest.approx(t[-1] - t[0])
    assert np.allclose(traj.evaluate(t - t[0]), np.array(table)[:, 1:4], atol=1e-9)
