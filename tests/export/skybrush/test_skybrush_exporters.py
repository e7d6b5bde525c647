"""Skybrush exports of a written character: what the drones play is what was verified.

The must-show of issue 14: 永 planned by ``plan_writing``, exported to ``.skyc`` and played
back with Skybrush's own arithmetic (the server's ms and mm rounding, the firmware's float32
Bézier evaluation; ``skyquill.export.skybrush.playback``, checked against a literal copy of
that code in ``tests/export/skybrush/test_skybrush_playback.py``): within 2 mm of the plan over
the whole show (28 mm before), lit exactly in the pen windows rounded to the 20 ms light frame,
validation settings consistent with the plan.
"""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import numpy as np
import pytest

from skyquill.calligraphy.mission import plan_writing
from skyquill.export import EXPORTERS, ExportOptions
from skyquill.export.base import NamedPlan
from skyquill.export.skybrush.csv_file import read_csv_zip
from skyquill.export.skybrush.lights import (
    colored_frames,
    light_colors,
    light_slices,
    program_bytes,
)
from skyquill.export.skybrush.pads import on_pads
from skyquill.export.skybrush.skyc_file import read_show_json, show_trajectories
from skyquill.io.trajectory_json import PlannedTrajectory, pen_down
from skyquill.limits import VehicleLimits
from skyquill.strokes import hanzi_strokes
from skyquill.trajectory import SplineTrajectory, dense_times
from skyquill.verify import verify


def frame_windows(windows: list[tuple[float, float]]) -> list[tuple[int, int]]:
    """The light windows (20 ms frames) of pen windows of one colour."""
    return [(a, b) for a, b, _ in colored_frames(windows, [(1, 1, 1)] * len(windows))]


RGB = (255, 40, 0)
#: The second drone writes the same character this far to the side, m.
OFFSET_M = np.array([1.5, 0.0, 0.0])


@pytest.fixture(scope="module")
def plans() -> list[NamedPlan]:
    """Two drones writing 永 side by side, as delivered: from their pads, back to them (the
    mission hovers above the first stroke; the export adds the climb and the descent)."""
    mission = plan_writing(hanzi_strokes("永"))
    traj = mission.vehicle_trajectory()
    assert isinstance(traj, SplineTrajectory)
    moved = SplineTrajectory(traj.control_points + OFFSET_M, traj.degree, traj.duration)
    return [
        (name, on_pads(PlannedTrajectory(t, tuple(mission.pen_windows), mission.limits)))
        for name, t in (("left", traj), ("right", moved))
    ]


def test_the_show_plays_within_2_mm_of_the_plan(plans: list[NamedPlan], tmp_path: Path) -> None:
    report = EXPORTERS["skyc"](plans, tmp_path / "yong.skyc", ExportOptions(light_rgb=RGB))
    show = read_show_json(report.files[0])
    for (name, plan), back, checked in zip(
        plans, show_trajectories(show), report.delivered, strict=True
    ):
        t = dense_times(plan.trajectory.breakpoints)
        error = np.linalg.norm(back.evaluate(t) - plan.trajectory.evaluate(t), axis=1)
        assert error.max() <= 2e-3  # 28 mm with the old 0.0999 s keyframes
        assert checked.drone == name and checked.max_error_m == pytest.approx(error.max())
        # keyframes on whole milliseconds, coordinates on whole millimetres
        points = next(d for d in show["swarm"]["drones"] if d["settings"]["name"] == name)
        points = points["settings"]["trajectory"]["points"]
        times = np.array([p[0] for p in points])
        assert np.array_equal(times, np.round(times * 1000) / 1000)
        values = np.array([c for p in points for c in [p[1], *p[2]]]) * 1000
        assert np.abs(values - np.round(values)).max() < 1e-9
    assert report.max_error_m <= 2e-3
    summary = report.as_dict()
    assert len(summary["delivered"]) == 2 and summary["scale_mm"] == [1, 1]


def test_the_limits_on_the_played_curve_are_reported(
    plans: list[NamedPlan], tmp_path: Path
) -> None:
    report = EXPORTERS["skyc"](plans, tmp_path / "yong.skyc", ExportOptions())
    excess = max(d.limit_excess for d in report.delivered)
    assert report.details["limit_excess"] == excess
    summary = report.as_dict()["as_played"]
    assert summary["within_allowed"] and report.details["limits_hold"]
    assert summary["relative_excess"]["acceleration"] <= 0.01
    assert summary["relative_excess"]["jerk"] <= 0.05
    assert f"as Skybrush plays it: {report.as_played.describe()}" in report.message
    assert "(as_played in the summary)" in report.message


def test_limits_the_plan_touches_are_kept_as_played(tmp_path: Path) -> None:
    """Limits at the plan's own maxima: as played, within 1 % (speed, acceleration) and 5 %
    (jerk), and the message says how far over it is instead of "every limit met"."""
    ctrl = np.random.default_rng(1).normal(scale=0.3, size=(14, 3)) + np.array([0.0, 0.0, 1.0])
    ctrl[:3], ctrl[-3:] = ctrl[0], ctrl[-1]
    traj = SplineTrajectory(ctrl, 5, 5.0)
    own = verify(traj, VehicleLimits(100.0, 100.0, 1000.0).derivative_limits(3))
    tight = VehicleLimits(*(r["max_value"] for r in own.limits_report())).derivative_limits(3)
    plan = [("d", PlannedTrajectory(traj, (), tight))]
    report = EXPORTERS["skyc"](plan, tmp_path / "tight.skyc", ExportOptions())
    played = report.as_played
    assert played.within_allowed and report.details["limits_hold"]
    assert ("every limit met" in report.message) == played.exact
    show = read_show_json(report.files[0])
    back = show_trajectories(show)[0]
    check = verify(back, tight, guaranteed=False)
    assert max(check.excess(1), check.excess(2)) <= 0.01 and check.excess(3) <= 0.05
    # the validation settings written are ones the played curve meets
    validation = show["settings"]["validation"]
    t = dense_times(back.breakpoints)
    for order, keys in ((1, "maxVelocity"), (2, "maxAcceleration")):
        d = back.evaluate(t, order)
        assert np.hypot(d[:, 0], d[:, 1]).max() <= validation[f"{keys}XY"]
        assert d[:, 2].max() <= validation[f"{keys}ZUp"]
        assert -d[:, 2].min() <= validation[f"{keys}Z"]


def _move(amax: float, limits_amax: float) -> PlannedTrajectory:
    """A 6 m time-optimal move at ``amax``, planned "for" ``limits_amax`` (m/s^2)."""
    from skyquill.optimize.legs import LegLimits, leg_pieces
    from skyquill.trajectory import PiecewisePolynomial

    start, end = np.array([0.0, 0.0, 1.0]), np.array([6.0, 0.0, 1.0])
    durations, coeffs = leg_pieces(start, end, LegLimits(3.0, amax, 40.0))
    return PlannedTrajectory(
        PiecewisePolynomial(np.concatenate([[0.0], np.cumsum(durations)]), coeffs),
        (),
        VehicleLimits(3.0, limits_amax, 40.0).derivative_limits(3),
    )


@pytest.mark.parametrize(("amax", "why"), [(2.2, "cm from it"), (20.0, "cm from it")])
def test_a_plan_that_cannot_be_played_in_its_limits_is_refused(
    amax: float, why: str, tmp_path: Path
) -> None:
    """A move accelerating 10 % (or ten times) over its limit: keyframes inside the limit
    cannot follow it (the fit leaves it by centimetres), so the export refuses, naming the
    drone, how far the fit is and the plan's own excess."""
    from skyquill.errors import InfeasibleError

    over = rf"plan: got drone d, which no C2 cubic keyframes .*{why}.*the plan itself is .* over"
    with pytest.raises(InfeasibleError, match=over):
        EXPORTERS["skyc"]([("d", _move(amax, 2.0))], tmp_path / "over.skyc", ExportOptions())


def test_the_lights_are_on_exactly_in_the_pen_windows(
    plans: list[NamedPlan], tmp_path: Path
) -> None:
    report = EXPORTERS["skyc"](plans, tmp_path / "yong.skyc", ExportOptions(light_rgb=RGB))
    show = read_show_json(report.files[0])
    windows = plans[0][1].pen_windows_s
    for i in range(2):
        data = program_bytes("l", show["swarm"]["drones"][i]["settings"]["lights"])
        t_ms = np.arange(0.0, 20_100.0)
        lit = np.all(light_colors(light_slices("l", data, 20_100), t_ms) == RGB, axis=1)
        expected = np.zeros_like(lit)
        for a, b in frame_windows(windows):
            expected[a * 20 : b * 20] = True
        assert np.array_equal(lit, expected)  # to the millisecond, on Skybrush's 20 ms frames
        lit_s = t_ms / 1000
        wrong = lit != pen_down(lit_s, windows).astype(bool)
        assert wrong.sum() <= 2 * len(windows) * 10  # each switch within half a frame
    assert all(d["max_offset_ms"] <= 10 for d in report.details["lights"]["per_drone"])
    assert report.details["lights"]["per_drone"][0]["lit_windows"] == len(windows)
    yaw = show["swarm"]["drones"][0]["settings"]["yawControl"]
    assert {s[1] for s in yaw["setpoints"]} == {0.0} and yaw["autoYaw"] is False


def test_the_validation_settings_follow_the_plan(plans: list[NamedPlan], tmp_path: Path) -> None:
    report = EXPORTERS["skyc"](plans, tmp_path / "yong.skyc", ExportOptions())
    show = read_show_json(report.files[0])
    validation = show["settings"]["validation"]
    assert validation == report.details["validation"]
    vmax, amax = 1.0, 2.0  # plan_writing's default limits (norms)
    # the limits, raised where the played curves pass them (by at most 1 %)
    for key in ("maxVelocityXY", "maxVelocityZ", "maxVelocityZUp"):
        assert vmax <= validation[key] <= 1.01 * vmax
    for key in ("maxAccelerationXY", "maxAccelerationZ", "maxAccelerationZUp"):
        assert amax <= validation[key] <= 1.01 * amax
    played = show_trajectories(show)
    t = np.linspace(0.0, min(p.duration for p in played), 40_001)
    positions = [p.evaluate(t) for p in played]
    top = max(float(p[:, 2].max()) for p in positions)
    assert top <= validation["maxAltitude"] <= top + 1e-3
    closest = min(
        float(np.linalg.norm(a - b, axis=1).min()) for a, b in itertools.combinations(positions, 2)
    )
    assert closest - 2e-3 <= validation["minDistance"] <= closest
    assert validation["minDistance"] == pytest.approx(1.5, abs=2e-3)


def test_the_zipped_csv_round_trips_with_lights_to_the_ms(
    plans: list[NamedPlan], tmp_path: Path
) -> None:
    report = EXPORTERS["skybrush-csv"](
        plans, tmp_path / "yong.zip", ExportOptions(rate_hz=50.0, light_rgb=RGB)
    )
    assert report.details["lights_exact_to_ms"] and report.max_error_m <= 1e-3
    drones = read_csv_zip(report.files[0])
    assert [d.name for d in drones] == ["left", "right"] and len(report.delivered) == 2
    windows = plans[0][1].pen_windows_s
    for drone in drones:
        lit = np.all(drone.colors == RGB, axis=1)
        for a, b in windows:
            a_ms, b_ms = round(a * 1000), round(b * 1000)
            rows = {int(t): bool(on) for t, on in zip(drone.t_ms, lit, strict=True)}
            assert rows[a_ms - 1] is False and rows[a_ms] is True
            assert rows[b_ms] is True and rows[b_ms + 1] is False
        assert np.array_equal(
            lit, pen_down(drone.t_ms, [(round(a * 1e3), round(b * 1e3)) for a, b in windows]) > 0
        )
    summary = json.loads(json.dumps(report.as_dict()))
    assert summary["delivered"][0]["limits"][0]["relative_excess"] <= 1e-9  # the speed


def _per_stroke(plans: list[NamedPlan]) -> list[NamedPlan]:
    """The plans with each pen window in its own colour (a palette of three, cycled)."""
    palette = [(255, 0, 0), (0, 255, 0), (0, 0, 255)]
    out = []
    for name, plan in plans:
        colors = tuple(palette[k % 3] for k in range(len(plan.pen_windows_s)))
        out.append(
            (name, PlannedTrajectory(plan.trajectory, plan.pen_windows_s, plan.limits, colors))
        )
    return out


def test_a_colour_per_stroke_is_what_skybrush_shows(plans: list[NamedPlan], tmp_path: Path) -> None:
    """Each stroke lit in its own colour: the .skyc read back shows it, within half a frame."""
    coloured = _per_stroke(plans)
    report = EXPORTERS["skyc"](coloured, tmp_path / "yong.skyc", ExportOptions())
    show = read_show_json(report.files[0])
    _, plan = coloured[0]
    data = program_bytes("l", show["swarm"]["drones"][0]["settings"]["lights"])
    mid_ms = np.array([500.0 * (a + b) for a, b in plan.pen_windows_s])
    shown = light_colors(light_slices("l", data, 30_000), mid_ms)
    np.testing.assert_array_equal(shown, np.array(plan.pen_rgb))
    per_drone = report.details["lights"]["per_drone"]
    assert all(d["max_offset_ms"] <= 10 and d["colors"] == 3 for d in per_drone)


def test_a_colour_per_stroke_is_in_the_zipped_csv(plans: list[NamedPlan], tmp_path: Path) -> None:
    coloured = _per_stroke(plans)
    report = EXPORTERS["skybrush-csv"](coloured, tmp_path / "yong.zip", ExportOptions())
    assert report.details["lights_exact_to_ms"]
    drone = read_csv_zip(report.files[0])[0]
    _, plan = coloured[0]
    for (a, b), rgb in zip(plan.pen_windows_s, plan.pen_rgb, strict=True):
        rows = drone.colors[(drone.t_ms >= round(a * 1000)) & (drone.t_ms <= round(b * 1000))]
        assert rows.size and np.all(rows == rgb)


@pytest.mark.slow
@pytest.mark.timeout(180)
def test_exports_made_in_worker_processes_or_on_dask_are_the_ones_made_here(
    plans: list[NamedPlan], tmp_path: Path
) -> None:
    """The .skyc and the zipped CSV of a show whose drones are exported in a process pool
    (``skyquill show --workers``) or on a dask cluster (``--scheduler``) are the ones made
    in-process."""
    from skyquill.export.skybrush.csv_exporter import SkybrushCsvExporter
    from skyquill.export.skybrush.skyc_exporter import SkycExporter

    pytest.importorskip("distributed")
    skyc, csv = SkycExporter(), SkybrushCsvExporter()
    here = [export(plans, tmp_path / "here", ExportOptions()) for export in (skyc, csv)]
    for where in ({"workers": 2}, {"scheduler": "local"}):
        name = "_".join(where)
        for export, want in zip(
            (SkycExporter(**where), SkybrushCsvExporter(**where)),  # type: ignore[arg-type]
            here,
            strict=True,
        ):
            there = export(plans, tmp_path / name, ExportOptions())
            assert there.details == want.details
            assert there.delivered == want.delivered
            assert _members(there.files[0]) == _members(want.files[0])


def _members(path: Path) -> dict[str, bytes]:
    """A ZIP's members, name -> bytes (the archive's own bytes hold the time it was written)."""
    import zipfile

    with zipfile.ZipFile(path) as archive:
        return {name: archive.read(name) for name in archive.namelist()}


def test_the_show_read_back_by_the_export_is_the_file_as_check_loads_it(
    plans: list[NamedPlan], tmp_path: Path
) -> None:
    """``skyquill show`` proves the .skyc as played from the show.json the exporter read back
    (not reading the file a second time): the same drones ``skyquill check`` loads."""
    from skyquill.export.skybrush.skyc_exporter import SkycExporter
    from skyquill.show import load_show
    from skyquill.show.load import skyc_drones

    report, show = SkycExporter().export(plans, tmp_path / "yong", ExportOptions())
    assert show == read_show_json(report.files[0])
    loaded = load_show([report.files[0]])
    shared = skyc_drones(show, report.files[0].name)
    assert [(d.name, d.start_s) for d in shared] == [(d.name, d.start_s) for d in loaded]
    for a, b in zip(shared, loaded, strict=True):
        t = dense_times(b.trajectory.breakpoints)
        np.testing.assert_array_equal(a.trajectory.evaluate(t), b.trajectory.evaluate(t))
