"""The Crazyswarm export: one file per upload, checked as the Crazyflie flies it; its fly script.

Plans are built target-shaped here (rest-to-rest degree-7 splines of at most
31 knot spans, hovers between them), planned by the engine against limits so
that the limits are active; the uploads are checked with cflib's own packing.
"""

from __future__ import annotations

import importlib.util
import json
import sys
import types
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from cflib.crazyflie.mem import MemoryElement, Poly4D
from scipy.interpolate import make_interp_spline

from skyquill.errors import InputError
from skyquill.export import EXPORTERS, ExportOptions
from skyquill.export.base import check_delivered
from skyquill.export.crazyflie.csv_file import read_crazyswarm
from skyquill.export.crazyflie.exporter import (
    FLOAT32_LIMIT_TOLERANCE,
    read_export,
)
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.limits import vehicle_limits
from skyquill.optimize import Boundary, PointDeviation, SmoothingProblem, solve
from skyquill.targets import hover
from skyquill.trajectory import (
    PiecewisePolynomial,
    RestToRestSequence,
    RetimedPath,
    SplineTrajectory,
)

LIMITS = vehicle_limits(3, vmax=1.0, amax=2.0, jmax=8.0, coupled_sides=16)
EXPORT = EXPORTERS["crazyswarm"]


def loop(r: float, duration: float, spans: int, z: float = 1.0) -> SplineTrajectory:
    """A rest-to-rest loop of radius ``r`` m fitted by the engine inside :data:`LIMITS`."""
    t = np.linspace(0.0, duration, spans * 4 + 1)
    s = t / duration
    angle = 2 * np.pi * s**3 * (10 - 15 * s + 6 * s**2)
    points = np.column_stack([r * np.sin(angle), r * (1 - np.cos(angle)), z + 0.2 * np.sin(angle)])
    problem = SmoothingProblem(
        dim=3,
        degree=7,
        n_ctrl=spans + 7,
        duration=duration,
        deviations=(PointDeviation(t, points, 1e6),),
        boundary=Boundary.rest(points[0], points[-1], 4),
        limits=LIMITS,
    )
    return solve(problem).trajectory


@pytest.fixture(scope="module")
def two_uploads() -> PlannedTrajectory:
    """28 + 20 pieces with a 1 s hover between: two uploads; the jerk limit is active."""
    first, second = loop(0.5, 2.6, 28), loop(0.3, 1.9, 20)
    end = first.evaluate(np.array([first.duration]))[0]
    plan = RestToRestSequence((first, hover(end, 1.0), second))
    return PlannedTrajectory(plan, ((0.5, 2.0), (3.8, 5.0)), LIMITS)


@pytest.fixture(scope="module")
def one_upload() -> PlannedTrajectory:
    return PlannedTrajectory(loop(0.4, 3.0, 12), (), LIMITS)


def cflib_bytes(path: Path) -> bytes:
    """The upload as cflib 0.1.34 packs it (Poly4D per CSV row)."""
    rows = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    data = bytearray()
    for row in rows:
        axes = [Poly4D.Poly([float(v) for v in row[1 + 8 * a : 9 + 8 * a]]) for a in range(4)]
        data += Poly4D(float(row[0]), *axes).pack()
    return bytes(data)


def export(tmp_path: Path, *plans: PlannedTrajectory, names: Sequence[str] = ("d",)) -> Any:
    report = EXPORT(list(zip(names, plans, strict=True)), tmp_path / "cs.csv", ExportOptions())
    summary = report.as_dict()
    (tmp_path / "cs.summary.json").write_text(json.dumps(summary))
    return report, summary


def test_two_uploads_fit_rest_and_fly_as_planned(
    tmp_path: Path, two_uploads: PlannedTrajectory
) -> None:
    report, summary = export(tmp_path, two_uploads)
    assert [f.name for f in report.files] == ["cs_part1.csv", "cs_part2.csv", "cs_fly.py"]
    (drone,) = summary["drone_uploads"]
    uploads = drone["uploads"]
    assert [u["pieces"] for u in uploads] == [28, 20]
    assert [u["hover_before_s"] for u in uploads] == [0.0, 1.0]
    assert uploads[1]["start_s"] == pytest.approx(2.6 + 1.0)
    for u in uploads:
        data = cflib_bytes(tmp_path / u["file"])
        assert u["bytes"] == len(data) == 132 * u["pieces"] <= 4096
        assert u["at_rest"]
        for where in ("start", "end"):
            assert np.abs(u[where]["velocity"]).max() <= 1e-6
            assert np.abs(u[where]["acceleration"]).max() <= 1e-6
    # The CSV is exact: each file is its upload's splines to float64 rounding.
    first = read_crazyswarm(tmp_path / "cs_part1.csv")
    t = np.linspace(0.0, 2.6, 500)
    assert np.abs(first.evaluate(t) - two_uploads.trajectory.evaluate(t)).max() < 1e-12
    # Float32 as the firmware flies it: within 1 mm (in fact ~1e-7 m); the limits hold up to
    # float32 rounding of the active jerk limit (~1.2e-7 relative), reported.
    (check,) = report.delivered
    assert check.max_error_m < 1e-5 and check.pen_down_max_error_m <= check.max_error_m
    assert 0.0 <= check.limit_excess <= FLOAT32_LIMIT_TOLERANCE
    assert drone["delivered_within_limits"] and "WARNING" not in report.message
    assert summary["delivered"][0]["limit_excess"] == check.limit_excess
    assert report.max_error_m == check.max_error_m
    # The summary and its files alone give back what the exporter checked: the mission's
    # check from the files, its limits report and excess the worse of it and the whole
    # flight's (take-off and landing included, "as_played": test_fly_replay.py).
    flown = read_export(tmp_path / "cs.summary.json")["d"]
    mission = check_delivered("d", two_uploads, flown)
    played = drone["flight"]["as_played"]["relative_excess"]
    worse = tuple(
        max(e, played[name])
        for e, name in zip(mission.excess_by_order, ("speed", "acceleration", "jerk"), strict=True)
    )
    whole = replace(mission, limits=check.limits, excess_by_order=worse,
                    limit_excess=max(mission.limit_excess, *played.values()))  # fmt: skip
    assert whole == check


def test_one_upload_is_one_file_and_drones_are_named(
    tmp_path: Path, one_upload: PlannedTrajectory, two_uploads: PlannedTrajectory
) -> None:
    report, summary = export(tmp_path, one_upload)
    assert [f.name for f in report.files] == ["cs.csv", "cs_fly.py"]
    assert summary["drone_uploads"][0]["uploads"][0]["hover_before_s"] == 0.0
    both = EXPORT([("d1", one_upload), ("d2", two_uploads)], tmp_path / "b.csv", ExportOptions())
    assert [f.name for f in both.files] == [
        "b_d1.csv",
        "b_d2_part1.csv",
        "b_d2_part2.csv",
        "b_fly.py",
    ]
    assert [d.drone for d in both.delivered] == ["d1", "d2"]


@pytest.mark.parametrize(
    ("plan", "match"),
    [
        (
            lambda: SplineTrajectory(np.random.default_rng(0).normal(size=(47, 3)), 7, 8.0),
            r"trajectory: got 40 pieces between rests at 0.000 s, expected at most 31 .* "
            r"plan it with target 'crazyflie'",
        ),
        (
            lambda: PiecewisePolynomial(np.array([0.0, 1.0]), np.zeros((1, 10, 3))),
            r"trajectory: got a PiecewisePolynomial at 0.000 s, expected polynomial pieces of "
            r"degree at most 7 .* target 'crazyflie'",
        ),
        (
            lambda: RetimedPath.from_samples(
                make_interp_spline(np.linspace(0, 1, 6), np.eye(6)[:, :3], k=3),
                np.linspace(0.0, 2.0, 21),
                np.linspace(0.0, 1.0, 21),
                np.full(21, 0.5),
                np.zeros(21),
            ),
            r"trajectory: got a RetimedPath at 0.000 s, expected polynomial pieces",
        ),
        (
            lambda: SplineTrajectory(np.random.default_rng(0).normal(size=(14, 3)), 7, 8.0),
            r"trajectory: got speed .* at the start of upload 1 \(0.000 s\), expected rest",
        ),
    ],
    ids=["too-many-pieces", "degree-9", "not-polynomial", "in-motion"],
)
def test_a_plan_that_does_not_fit_is_refused_and_nothing_is_written(
    tmp_path: Path, plan: Any, match: str
) -> None:
    with pytest.raises(InputError, match=match):
        EXPORT([("d", PlannedTrajectory(plan(), (), LIMITS))], tmp_path / "cs.csv", ExportOptions())
    assert not any(tmp_path.iterdir())


CORRUPTIONS = {
    "truncated": lambda text: text[: len(text) // 2],
    "nan": lambda text: text.replace(text.splitlines()[2].split(",")[3], "nan", 1),
    "columns": lambda text: "\n".join(
        [*text.splitlines()[:2], text.splitlines()[2] + ",0", *text.splitlines()[3:]]
    ),
    "negative-duration": lambda text: "\n".join(
        [text.splitlines()[0], "-" + text.splitlines()[1], *text.splitlines()[2:]]
    ),
    "row-dropped": lambda text: "\n".join(text.splitlines()[:-1]) + "\n",
}
MESSAGES = {
    "truncated": r"cs_part2.csv( line \d+: got \d+ columns, expected 33|: got \d+ pieces, exp)",
    "nan": r"cs_part2.csv line 3, column x\^2: got 'nan', expected a finite",
    "columns": r"cs_part2.csv line 3: got 34 columns, expected 33",
    "negative-duration": r"cs_part2.csv line 2, column duration: got -0.\d+, expected a dur",
    "row-dropped": r"cs_part2.csv: got 19 pieces, expected 20 \(as exported\)",
}


@pytest.mark.parametrize("kind", list(CORRUPTIONS))
def test_a_corrupted_export_read_back_is_refused(
    tmp_path: Path, two_uploads: PlannedTrajectory, kind: str
) -> None:
    export(tmp_path, two_uploads)
    part = tmp_path / "cs_part2.csv"
    part.write_text(CORRUPTIONS[kind](part.read_text()))
    with pytest.raises(InputError, match=MESSAGES[kind]):
        read_export(tmp_path / "cs.summary.json")


def test_a_missing_part_or_summary_is_refused(
    tmp_path: Path, two_uploads: PlannedTrajectory
) -> None:
    export(tmp_path, two_uploads)
    (tmp_path / "cs_part2.csv").unlink()
    with pytest.raises(InputError, match=r"crazyswarm file: got '.*cs_part2.csv', expected an"):
        read_export(tmp_path / "cs.summary.json")
    (tmp_path / "x.json").write_text('{"format": "csv"}')
    with pytest.raises(InputError, match=r"summary: got '.*x.json' \('drone_uploads'\)"):
        read_export(tmp_path / "x.json")


# ----------------------------------------------------------------- the fly script


@dataclass
class FakeLink:
    """A Crazyflie as cflib's high-level commander and memory see it; records every call."""

    now: float = 0.0
    write_s: float = 0.4
    calls: list[tuple[Any, ...]] = field(default_factory=list)
    memory_bytes: bytearray = field(default_factory=bytearray)

    def clock(self) -> float:
        return self.now

    def sleep(self, seconds: float) -> None:
        self.now += seconds

    @property
    def cf(self) -> Any:
        link = self

        class Memory:
            def __init__(self) -> None:
                self.trajectory: list[Any] = []

            def write_data_sync(self) -> bool:
                data = b"".join(p.pack() for p in self.trajectory)
                link.memory_bytes[:] = data
                link.calls.append(("upload", link.now, data))
                link.now += link.write_s
                return True

        def get_mems(kind: int) -> tuple[Any, ...]:
            assert kind == MemoryElement.TYPE_TRAJ
            return (Memory(),)

        def record(name: str) -> Any:
            return lambda *a, **k: link.calls.append((name, link.now, *a, *k.values()))

        hlc = types.SimpleNamespace(
            **{n: record(n) for n in ("takeoff", "go_to", "define_trajectory", "land", "stop")},
            start_trajectory=record("start_trajectory"),
        )
        return types.SimpleNamespace(mem=types.SimpleNamespace(get_mems=get_mems),
                                     high_level_commander=hlc)  # fmt: skip


def load_script(path: Path, monkeypatch: pytest.MonkeyPatch) -> Any:
    """Import the written script as a module (registered, as its dataclass needs)."""
    spec = importlib.util.spec_from_file_location("cs_fly", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, "cs_fly", module)
    spec.loader.exec_module(module)
    return module


def test_the_fly_script_uploads_while_hovering_and_starts_on_time(
    tmp_path: Path, two_uploads: PlannedTrajectory, monkeypatch: pytest.MonkeyPatch
) -> None:
    _, summary = export(tmp_path, two_uploads)
    script = load_script(tmp_path / "cs_fly.py", monkeypatch)
    assert "uploadTrajectory" in script.__doc__ and "startTrajectory" in script.__doc__
    flight = script.flight_of(None, script.SCHEDULE)
    link = FakeLink()
    script.fly(link.cf, flight, tmp_path, clock=link.clock, sleep=link.sleep)
    names = [c[0] for c in link.calls]
    assert names == [
        "upload", "define_trajectory", "takeoff", "go_to", "start_trajectory",
        "go_to", "upload", "define_trajectory", "start_trajectory", "land", "stop",
    ]  # fmt: skip
    uploads = [c for c in link.calls if c[0] == "upload"]
    for call, u in zip(uploads, summary["drone_uploads"][0]["uploads"], strict=True):
        assert call[2] == cflib_bytes(tmp_path / u["file"]) and len(call[2]) <= 4096
    defined = [c for c in link.calls if c[0] == "define_trajectory"]
    assert [c[2:] for c in defined] == [(1, 0, 28), (1, 0, 20)]
    starts = [c[1] for c in link.calls if c[0] == "start_trajectory"]
    planned = [u["start_s"] for u in summary["drone_uploads"][0]["uploads"]]
    # On the plan's clock: the second upload starts exactly its planned time after the first.
    assert starts[1] - starts[0] == pytest.approx(planned[1] - planned[0])
    # The hover's go_to holds the end of upload 1 before its memory is overwritten.
    hold = next(c for c in link.calls[5:] if c[0] == "go_to")
    first_end = summary["drone_uploads"][0]["uploads"][0]["end"]["position"]
    np.testing.assert_allclose(hold[2:5], first_end)
    assert hold[1] == pytest.approx(starts[0] + 2.6)
    assert link.calls[-2][1] == pytest.approx(starts[1] + 1.9)  # lands after the last upload


def test_a_slow_upload_starts_late_and_says_so(
    tmp_path: Path,
    two_uploads: PlannedTrajectory,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    export(tmp_path, two_uploads)
    script = load_script(tmp_path / "cs_fly.py", monkeypatch)
    link = FakeLink(write_s=1.5)  # longer than the 1 s hover
    script.fly(
        link.cf, script.flight_of("drone", script.SCHEDULE), tmp_path, link.clock, link.sleep
    )
    starts = [c[1] for c in link.calls if c[0] == "start_trajectory"]
    assert starts[1] - starts[0] == pytest.approx(2.6 + 1.5)
    assert "cs_part2.csv: written 0.50 s after its planned start" in capsys.readouterr().out
    with pytest.raises(SystemExit):
        script.flight_of("x", script.SCHEDULE)
    assert "error: --drone: got 'x', expected one of drone" in capsys.readouterr().err
