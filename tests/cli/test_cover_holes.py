"""``skyquill cover`` on fields with holes and on several fields: read back what was written.

The check here is independent of the planner and of its keep-out check: the
``trajectory.csv`` rows (50 Hz) are joined by straight lines, and shapely's
distances from that polyline, and from its rows with ``pen == 1``, to each
hole are taken directly.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Point, Polygon
from typer.testing import CliRunner

from skyquill.cli.main import app

SHELL = [[0, 0], [16, 0], [16, 16], [0, 16], [0, 0]]
HOLE = np.round(np.asarray(Point(8, 8).buffer(2.0).exterior.coords), 6).tolist()
WIDTH = 2.0


def _read(out: Path) -> tuple[np.ndarray, np.ndarray]:
    lines = (out / "trajectory.csv").read_text().splitlines()
    header = lines[0].split(",")
    table = np.loadtxt(out / "trajectory.csv", delimiter=",", skiprows=1)
    assert np.all(np.isfinite(table))
    xy = table[:, [header.index("x"), header.index("y")]]
    return xy, table[:, header.index("pen")] == 1.0


def test_a_field_with_a_hole_is_flown_around_it(tmp_path: Path) -> None:
    region = tmp_path / "holed.geojson"
    region.write_text(json.dumps({"type": "Polygon", "coordinates": [SHELL, HOLE]}))
    out = tmp_path / "out"
    args = ["cover", str(region), "--crs", "local", "--out", str(out), "--pattern", "zigzag"]
    args += ["--width", "2"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    xy, pen = _read(out)
    hole = Polygon(HOLE)
    assert LineString(xy).distance(hole) > 0.0  # the vehicle never over the hole
    sprayed = shapely.points(xy[pen])
    assert pen.any() and not pen.all()  # off somewhere: between the pieces
    assert shapely.distance(sprayed, hole).min() >= 0.5 * WIDTH * (1 - 1e-6)
    summary = json.loads((out / "summary.json").read_text())
    keepout = summary["keepout"]
    assert keepout["passed"] and keepout["margin_m"] == pytest.approx(1.0)
    [reported] = keepout["holes"]
    # The planner's check samples every 1 cm; the csv every 2 cm at most 3 m/s x 20 ms apart.
    assert reported["closest_m"] == pytest.approx(LineString(xy).distance(hole), abs=0.07)
    assert summary["region_area_m2"] == pytest.approx(256.0 - hole.area)
    assert summary["missed_area_m2"] == pytest.approx(
        summary["missed_fraction"] * summary["region_area_m2"]
    )
    assert (out / "plot.png").stat().st_size > 10_000


def test_two_fields_in_one_wkt_are_one_flight(tmp_path: Path) -> None:
    region = tmp_path / "two.wkt"
    region.write_text(
        "MULTIPOLYGON (((0 0, 10 0, 10 10, 0 10, 0 0)), ((20 0, 30 0, 30 10, 20 10, 20 0)))"
    )
    out = tmp_path / "out"
    result = CliRunner().invoke(
        app, ["cover", str(region), "--crs", "local", "--out", str(out), "--pattern", "zigzag"]
    )
    assert result.exit_code == 0, result.output
    xy, pen = _read(out)
    gap = (xy[:, 0] > 10.5) & (xy[:, 0] < 19.5)
    assert gap.any() and not pen[gap].any()  # crossed between the fields, spray off
    assert json.loads((out / "summary.json").read_text())["fields"] == 2


@pytest.mark.parametrize(
    ("rings", "message"),
    [
        ([SHELL, [[20, 20], [22, 20], [22, 22], [20, 20]]], "outside the shell (hole 1)"),
        ([[[0, 0], [10, 10], [10, 0], [0, 10], [0, 0]]], "self-intersecting or degenerate shell"),
        (
            [SHELL, [[4, 4], [7, 4], [7, 7], [4, 4]], [[5, 4.5], [9, 4.5], [9, 9], [5, 4.5]]],
            "holes 1 and 2 overlapping",
        ),
    ],
)
def test_bad_holes_exit_2_naming_the_problem(
    tmp_path: Path, rings: list[list[list[float]]], message: str
) -> None:
    region = tmp_path / "bad.geojson"
    region.write_text(json.dumps({"type": "Polygon", "coordinates": rings}))
    args = ["cover", str(region), "--crs", "local", "--out", str(tmp_path / "o")]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2
    assert message in " ".join(result.output.split())
    assert "Traceback" not in result.output


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("--workers", "0", "--workers: got 0, expected 1 to 256"),
        ("--scheduler", "not an address", "--scheduler: got 'not an address', expected 'local'"),
    ],
)
def test_where_the_pieces_are_planned_is_checked_first(
    tmp_path: Path, option: str, value: str, message: str
) -> None:
    region = tmp_path / "holed.geojson"
    region.write_text(json.dumps({"type": "Polygon", "coordinates": [SHELL, HOLE]}))
    args = ["cover", str(region), "--crs", "local", "--out", str(tmp_path / "o"), option, value]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2
    assert message in " ".join(result.output.split())
    assert not (tmp_path / "o").exists()
