"""Crazyswarm CSV export / import, checked by an independent evaluator written here."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.export.crazyflie.csv_file import (
    COLUMNS,
    HEADER,
    crazyswarm_pieces,
    read_crazyswarm,
    read_crazyswarm_table,
    upload_pieces,
    write_crazyswarm,
)
from skyquill.trajectory import PiecewisePolynomial, SplineTrajectory, Trajectory


def spline(degree: int, dim: int, n_ctrl: int = 20, seed: int = 0) -> SplineTrajectory:
    """A random spline over 8 s with control points in a 2 m cube."""
    ctrl = np.random.default_rng(seed).uniform(-1.0, 1.0, (n_ctrl, dim))
    return SplineTrajectory(ctrl, degree, 8.0)


def reference_pieces(path: Path) -> list[tuple[float, list[list[float]]]]:
    """Parse the CSV with the csv module: [(duration, [coeffs of x, y, z, yaw])]."""
    with path.open(newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == [
        "duration",
        *(f"{a}^{j}" for a in ("x", "y", "z", "yaw") for j in range(8)),
    ]
    out = []
    for row in rows[1:]:
        assert len(row) == 33
        vals = [float(v) for v in row]
        out.append((vals[0], [vals[1 + 8 * a : 9 + 8 * a] for a in range(4)]))
    return out


def reference_eval(
    pieces: list[tuple[float, list[list[float]]]], t: float, order: int
) -> list[float]:
    """Horner on the derivative of the piece containing ``t``; x, y, z."""
    start, i = 0.0, 0
    while i < len(pieces) - 1 and t >= start + pieces[i][0]:
        start += pieces[i][0]
        i += 1
    axes = pieces[i][1]
    tau = t - start
    result = []
    for c in axes[:3]:
        acc = 0.0
        for j in range(7, order - 1, -1):
            acc = acc * tau + c[j] * math.perm(j, order)
        result.append(acc)
    return result


def scale(traj: Trajectory, order: int, t: np.ndarray) -> float:
    """Tolerance scale: the size of the derivative being compared."""
    return max(1.0, float(np.abs(traj.evaluate(t, order)).max()))


@pytest.mark.parametrize("degree", [3, 5, 7])
@pytest.mark.parametrize("dim", [2, 3])
def test_export_is_exact_against_independent_evaluator(
    tmp_path: Path, degree: int, dim: int
) -> None:
    traj = spline(degree, dim, seed=degree * 10 + dim)
    path = write_crazyswarm(crazyswarm_pieces(traj, yaw=0.25), tmp_path / "traj.csv")
    assert path == tmp_path / "traj.csv"
    pieces = reference_pieces(path)
    assert len(pieces) == 20 - degree
    assert all(axes[3] == [0.25, 0, 0, 0, 0, 0, 0, 0] for _, axes in pieces)
    # Degree < 7 is zero-padded: no coefficient above the degree.
    assert all(c[j] == 0.0 for _, axes in pieces for c in axes for j in range(degree + 1, 8))
    if dim == 2:
        assert all(axes[2] == [0.0] * 8 for _, axes in pieces)
    t = np.sort(np.random.default_rng(1).uniform(0.0, traj.duration, 2000))
    back = read_crazyswarm(path)
    np.testing.assert_array_equal(read_crazyswarm_table(path), crazyswarm_pieces(traj, yaw=0.25))
    for order in range(4):
        want = traj.evaluate(t, order)
        if dim == 2:
            want = np.column_stack([want, np.zeros(t.size)])
        tol = 1e-9 * scale(traj, order, t)
        got = np.array([reference_eval(pieces, float(ti), order) for ti in t])
        np.testing.assert_allclose(got, want, rtol=0, atol=tol)
        np.testing.assert_allclose(back.evaluate(t, order), want, rtol=0, atol=tol)
    np.testing.assert_allclose(back.evaluate_yaw(t), 0.25)
    np.testing.assert_array_equal(back.evaluate_yaw(t, 1), 0.0)
    # The round trip is exact: the coefficients come back bit for bit.
    table = crazyswarm_pieces(traj, yaw=0.25)
    np.testing.assert_allclose(np.diff(back.breaks), table[:, 0], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(back.coeffs.transpose(0, 2, 1).reshape(-1, 24), table[:, 1:25])
    assert back.duration == pytest.approx(traj.duration, abs=1e-12)
    assert back.dim == 3
    assert isinstance(back, Trajectory)


def test_pieces_shape_and_columns() -> None:
    traj = spline(3, 3)
    table = crazyswarm_pieces(traj)
    breaks, coeffs = traj.to_piecewise_polynomial()
    assert table.shape == (17, 33)
    np.testing.assert_allclose(table[:, 0], np.diff(breaks))
    np.testing.assert_array_equal(table[:, 1:5], coeffs[:, :, 0])  # x^0..x^3
    np.testing.assert_array_equal(table[:, 9:13], coeffs[:, :, 1])  # y^0..y^3
    assert len(COLUMNS) == 33 and HEADER.startswith("duration,x^0,x^1")


def test_an_upload_is_its_parts_back_to_back_and_polynomials_are_written_as_they_are(
    tmp_path: Path,
) -> None:
    first, second = spline(7, 3, n_ctrl=12, seed=1), spline(5, 3, n_ctrl=9, seed=2)
    table = upload_pieces([first, second])
    assert table.shape == (5 + 4, 33)
    np.testing.assert_array_equal(table[:5], crazyswarm_pieces(first))
    # A piecewise polynomial read back from a file is written again unchanged, yaw included.
    path = write_crazyswarm(crazyswarm_pieces(second, yaw=0.5), tmp_path / "a.csv")
    again = write_crazyswarm(crazyswarm_pieces(read_crazyswarm(path)), tmp_path / "b.csv")
    assert again.read_text() == path.read_text()


def test_export_rejects_bad_arguments(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"table: got shape \(3, 4\), expected \(P, 33\)"):
        write_crazyswarm(np.zeros((3, 4)), tmp_path / "a.csv")
    with pytest.raises(InputError, match="parts: got none, expected at least one trajectory"):
        upload_pieces([])
    with pytest.raises(InputError, match="parts: got a str, expected a SplineTrajectory or a"):
        upload_pieces(["x"])  # type: ignore[list-item]
    poly9 = PiecewisePolynomial(np.array([0.0, 1.0]), np.ones((1, 10, 3)))
    with pytest.raises(InputError, match="traj: got degree 9, expected at most 7"):
        crazyswarm_pieces(poly9)
    with pytest.raises(InputError, match="yaw: got nan, expected a finite number"):
        crazyswarm_pieces(spline(3, 3), yaw=float("nan"))
    with pytest.raises(InputError, match="traj: got a 1-D trajectory, expected 2 or 3 axes"):
        crazyswarm_pieces(spline(3, 1))
    with pytest.raises(InputError, match="traj: got str, expected a SplineTrajectory or a Piece"):
        crazyswarm_pieces("x")  # type: ignore[arg-type]


def row(duration: str = "0.5", cell: str = "0") -> str:
    return ",".join([duration, *[cell] * 32])


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "bad.csv"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("", r"bad.csv: got an empty file, expected a header line with columns duration,x\^0"),
        ("t,x,y\n" + row(), r"bad.csv: got columns \['t', 'x', 'y'\], expected columns dura"),
        (HEADER + ",note\n" + row() + ",1", "bad.csv: got unknown column.s. 'note', expected only"),
        (HEADER + "\n", r"bad.csv: got 0 data row\(s\), expected at least 1"),
        (HEADER + "\n" + row() + "\n0.5,1,2\n", "line 3: got 3 columns, expected 33"),
        (HEADER + "\n" + row(cell="abc"), "line 2, column x\\^0: got 'abc', expected a number"),
        (HEADER + "\n" + row(cell="nan"), "line 2, column x\\^0: got 'nan', expected a finite"),
        (HEADER + "\n" + row(cell="inf"), "line 2, column x\\^0: got 'inf', expected a finite"),
        (HEADER + "\n" + row(duration="0"), "line 2, column duration: got 0, expected a dur"),
        (HEADER + "\n" + row(duration="-1"), "line 2, column duration: got -1, expected a dur"),
        (HEADER + "\n" + row(duration="1e300") + "\n" + row(duration="1e-300"), "add up"),
    ],
)
def test_read_rejects_bad_files(tmp_path: Path, text: str, match: str) -> None:
    with pytest.raises(InputError, match=match):
        read_crazyswarm(write(tmp_path, text))


def test_read_rejects_a_missing_file(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"crazyswarm file: got '.*nope\.csv', expected an exis"):
        read_crazyswarm(tmp_path / "nope.csv")


def test_read_accepts_crazyswarm_capitalised_header_and_blank_lines(tmp_path: Path) -> None:
    # Crazyswarm's own examples (figure8.csv) write "Duration".
    text = "Duration" + HEADER[len("duration") :] + "\n" + row("2", "1") + "\n\n"
    traj = read_crazyswarm(write(tmp_path, text))
    assert traj.duration == 2.0 and traj.n_pieces == 1
    # x = 1 + 2 + 4 + ... + 2^7 at tau = 2
    np.testing.assert_allclose(traj.evaluate(np.array([2.0]))[0], [255.0, 255.0, 255.0])
    np.testing.assert_allclose(traj.evaluate(np.array([0.0]), 8), [[0.0, 0.0, 0.0]])


def test_polynomial_trajectory_validates() -> None:
    traj = PiecewisePolynomial(np.array([0.0, 1.0]), np.zeros((1, 8, 3)), np.zeros((1, 8)))
    with pytest.raises(InputError, match=r"t: got times in \[0, 2\] s, expected within \[0, 1\]"):
        traj.evaluate(np.array([0.0, 2.0]))
    with pytest.raises(InputError, match="breaks: got breaks\\[0\\] = 1, expected 0"):
        PiecewisePolynomial(np.array([1.0, 2.0]), np.zeros((1, 8, 3)), np.zeros((1, 8)))
    with pytest.raises(InputError, match="coeffs: got an array of shape"):
        PiecewisePolynomial(np.array([0.0, 1.0]), np.zeros((2, 8, 3)), np.zeros((1, 8)))
    assert traj.sample(10.0).p.shape == (11, 3)


CELLS = st.sampled_from(["0", "1", "-2.5", "1e308", "1e-320", "nan", "inf", "x", "", " 3 ", '"'])


@st.composite
def csv_texts(draw: st.DrawFn) -> str:
    header = draw(st.sampled_from([HEADER, "Duration" + HEADER[8:], "t,x", "", HEADER + ",x"]))
    lines = [header]
    for _ in range(draw(st.integers(0, 4))):
        n = draw(st.sampled_from([0, 1, 32, 33, 33, 33, 34]))
        lines.append(",".join(draw(st.lists(CELLS, min_size=n, max_size=n))))
    if draw(st.booleans()):
        lines.append(draw(st.text(max_size=40)))
    return "\n".join(lines)


@settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(text=csv_texts())
def test_read_random_text_only_input_error(tmp_path: Path, text: str) -> None:
    path = tmp_path / "random.csv"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    try:
        traj = read_crazyswarm(path)
    except InputError:
        return
    assert traj.n_pieces >= 1 and traj.duration > 0
