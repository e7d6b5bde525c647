"""Skybrush .skyc export, checked by an independent Bézier evaluator."""

from __future__ import annotations

import copy
import itertools
import json
import math
import tempfile
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.io import skyc
from skyquill.io.skyc import MAX_SEGMENT_S, read_show_json, validate_show, write_skyc
from skyquill.trajectory import SplineTrajectory
from skyquill.validation import FloatArray


def spline(degree: int, seed: int = 0, n_ctrl: int = 14, duration: float = 8.0) -> SplineTrajectory:
    """Random 3-D spline in a 2 m cube lifted 1 m up."""
    ctrl = np.random.default_rng(seed).uniform(-1.0, 1.0, (n_ctrl, 3)) + np.array([0.0, 0.0, 1.0])
    return SplineTrajectory(ctrl, degree, duration)


def bezier_positions(points: list[Any], t: FloatArray) -> FloatArray:
    """Evaluate Skybrush keyframes at times ``t`` by de Casteljau (independent of skyc.py).

    ``points[i] = [t_i, p_i, controls_i]``: the segment from ``t_{i-1}`` to
    ``t_i`` has control points ``p_{i-1}, *controls_i, p_i``.
    """
    times = np.array([float(p[0]) for p in points])
    out = np.empty((t.size, 3))
    for n, tn in enumerate(t):
        i = int(np.clip(np.searchsorted(times, tn, side="right"), 1, len(points) - 1))
        ctrl = [np.array(points[i - 1][1])] + [np.array(c) for c in points[i][2]]
        ctrl.append(np.array(points[i][1]))
        s = (tn - times[i - 1]) / (times[i] - times[i - 1])
        while len(ctrl) > 1:
            ctrl = [(1 - s) * a + s * b for a, b in itertools.pairwise(ctrl)]
        out[n] = ctrl[0]
    return out


def drone_points(show: dict[str, Any], i: int) -> list[Any]:
    points: list[Any] = show["swarm"]["drones"][i]["settings"]["trajectory"]["points"]
    return points


def dense(traj: SplineTrajectory) -> FloatArray:
    return np.linspace(0.0, traj.duration, 20_001)


@pytest.mark.parametrize("degree", [1, 2, 3])
def test_degree_up_to_3_is_exact(tmp_path: Path, degree: int) -> None:
    traj = spline(degree)
    result = write_skyc([traj], tmp_path / "show.skyc")
    assert result.exact
    assert result.max_error_m <= 1e-12
    assert result.segments == len(traj.knot_times) - 1  # one cubic per knot span
    show = read_show_json(result.path)
    t = dense(traj)
    err = np.linalg.norm(bezier_positions(drone_points(show, 0), t) - traj.evaluate(t), axis=1)
    assert err.max() <= 1e-9


def test_degree_5_within_tolerance_and_reported(tmp_path: Path) -> None:
    traj = spline(5, seed=1)
    tol = 1e-3
    result = write_skyc([traj], tmp_path / "show.skyc", tolerance=tol)
    assert not result.exact
    assert 0.0 < result.max_error_m <= tol
    assert "approximated" in result.message
    show = read_show_json(result.path)
    t = dense(traj)
    err = np.linalg.norm(bezier_positions(drone_points(show, 0), t) - traj.evaluate(t), axis=1)
    assert err.max() <= tol
    # the reported error is what an independent dense check finds, to a few percent
    assert err.max() == pytest.approx(result.max_error_m, rel=0.05)


def test_tighter_tolerance_gives_more_segments(tmp_path: Path) -> None:
    traj = spline(5, seed=2)
    coarse = write_skyc([traj], tmp_path / "a.skyc", tolerance=1e-2)
    fine = write_skyc([traj], tmp_path / "b.skyc", tolerance=1e-5)
    assert fine.segments > coarse.segments
    assert fine.max_error_m <= 1e-5


def test_several_drones_homes_and_structure(tmp_path: Path) -> None:
    trajs = [spline(3, seed=s) for s in range(3)]
    homes = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    result = write_skyc(trajs, tmp_path / "three.skyc", homes=homes, title="three")
    with zipfile.ZipFile(result.path) as archive:
        assert "show.json" in archive.namelist()
    show = read_show_json(result.path)
    assert show["version"] == 1
    assert show["environment"]["type"] == "indoor"
    assert show["meta"]["title"] == "three"
    drones = show["swarm"]["drones"]
    assert len(drones) == 3
    for i, (drone, traj) in enumerate(zip(drones, trajs, strict=True)):
        settings = drone["settings"]
        assert settings["home"] == homes[i].tolist()
        trajectory = settings["trajectory"]
        assert trajectory["version"] == 1
        assert trajectory["takeoffTime"] == 0.0
        assert trajectory["points"][0][2] == []
        assert trajectory["points"][0][0] == 0.0
        assert trajectory["points"][-1][0] == pytest.approx(traj.duration)
        t = dense(traj)
        got = bezier_positions(trajectory["points"], t)
        assert np.abs(got - traj.evaluate(t)).max() <= 1e-9


def test_default_home_is_start_position(tmp_path: Path) -> None:
    traj = spline(3)
    show = read_show_json(write_skyc([traj], tmp_path / "s.skyc").path)
    home = show["swarm"]["drones"][0]["settings"]["home"]
    np.testing.assert_allclose(home, traj.evaluate(np.zeros(1))[0], atol=1e-12)


def test_long_spans_are_split_to_the_segment_limit(tmp_path: Path) -> None:
    traj = spline(3, n_ctrl=5, duration=300.0)  # 2 spans of 150 s
    result = write_skyc([traj], tmp_path / "long.skyc")
    points = drone_points(read_show_json(result.path), 0)
    steps = np.diff([p[0] for p in points])
    assert steps.max() <= MAX_SEGMENT_S
    t = dense(traj)
    assert np.abs(bezier_positions(points, t) - traj.evaluate(t)).max() <= 1e-9


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"trajectories": []}, "trajectories: got nothing"),
        ({"tolerance": 0.0}, r"tolerance: got 0"),
        ({"tolerance": math.nan}, r"tolerance: got nan"),
        ({"homes": np.zeros((2, 3))}, r"homes: got an array of shape \(2, 3\)"),
        ({"trajectories": ["x"]}, r"trajectories\[0\]"),
    ],
)
def test_bad_arguments(tmp_path: Path, kwargs: dict[str, Any], match: str) -> None:
    args: dict[str, Any] = {"trajectories": [spline(3)], **kwargs}
    with pytest.raises(InputError, match=match):
        write_skyc(args.pop("trajectories"), tmp_path / "x.skyc", **args)


def test_2d_trajectory_rejected(tmp_path: Path) -> None:
    flat = SplineTrajectory(np.random.default_rng(0).uniform(size=(6, 2)), 3, 2.0)
    with pytest.raises(InputError, match=r"trajectories\[0\]: got a 2-D trajectory"):
        write_skyc([flat], tmp_path / "x.skyc")


def valid_show(tmp_path: Path) -> dict[str, Any]:
    return read_show_json(write_skyc([spline(3), spline(3, 1)], tmp_path / "v.skyc").path)


def _set(show: dict[str, Any], path: tuple[Any, ...], value: Any) -> dict[str, Any]:
    bad = copy.deepcopy(show)
    node: Any = bad
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return bad


TRAJ = ("swarm", "drones", 1, "settings", "trajectory")


@pytest.mark.parametrize(
    ("path", "value", "match"),
    [
        (("version",), 2, r"show.json: version: got 2"),
        (("environment", "type"), "space", r"environment.type: got 'space'"),
        (("swarm", "drones"), [], r"swarm.drones: got \[\]"),
        (("swarm", "drones", 1, "settings", "home"), [0, 0], r"drones\[1\].settings.home"),
        ((*TRAJ, "version"), 0, r"drones\[1\].settings.trajectory.version: got 0"),
        ((*TRAJ, "takeoffTime"), "soon", r"trajectory.takeoffTime: got 'soon'"),
        ((*TRAJ, "points", 3, 0), 0.0, r"trajectory.points\[3\]\[0\]: got 0.0 after"),
        ((*TRAJ, "points", 2, 1), [0, 0, math.inf], r"trajectory.points\[2\]\[1\]"),
        ((*TRAJ, "points", 2, 2, 1), [1, 2], r"trajectory.points\[2\]\[2\]\[1\]"),
        ((*TRAJ, "points", 0, 2), [[0, 0, 0]], r"points\[0\]\[2\]: got 1 control point"),
        ((*TRAJ, "points", 1), [1.0, [0, 0, 0]], r"points\[1\]: got"),
    ],
)
def test_validate_show_names_the_bad_field(
    tmp_path: Path, path: tuple[Any, ...], value: Any, match: str
) -> None:
    show = valid_show(tmp_path)
    validate_show(show)
    with pytest.raises(InputError, match=match):
        validate_show(_set(show, path, value))


def test_read_show_json_bad_files(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"expected an existing \.skyc file"):
        read_show_json(tmp_path / "missing.skyc")
    not_zip = tmp_path / "n.skyc"
    not_zip.write_text("hello", encoding="utf-8")
    with pytest.raises(InputError, match="not a ZIP"):
        read_show_json(not_zip)
    empty = tmp_path / "e.skyc"
    with zipfile.ZipFile(empty, "w") as archive:
        archive.writestr("other.json", "{}")
    with pytest.raises(InputError, match=r"expected a show\.json"):
        read_show_json(empty)
    broken = tmp_path / "b.skyc"
    with zipfile.ZipFile(broken, "w") as archive:
        archive.writestr("show.json", "{not json")
    with pytest.raises(InputError, match=r"show\.json: got malformed JSON at line 1"):
        read_show_json(broken)
    wrong = tmp_path / "w.skyc"
    with zipfile.ZipFile(wrong, "w") as archive:
        archive.writestr("show.json", json.dumps({"version": 1}))
    with pytest.raises(InputError, match="environment"):
        read_show_json(wrong)


def _archive(path: Path, show: bytes, compression: int = zipfile.ZIP_DEFLATED) -> Path:
    with zipfile.ZipFile(path, "w", compression=compression) as archive:
        archive.writestr("show.json", show)
    return path


def test_a_zip_bomb_is_refused_before_inflating(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(skyc, "MAX_SHOW_BYTES", 10_000)  # a real bomb would claim gigabytes
    bomb = _archive(tmp_path / "bomb.skyc", b" " * 1_000_000)
    assert bomb.stat().st_size < 10_000
    with pytest.raises(
        InputError, match=r"bomb\.skyc: show\.json: got 1,000,000 bytes, expected at most 10,000"
    ):
        read_show_json(bomb)


def test_a_corrupt_member_is_named(tmp_path: Path) -> None:
    path = _archive(tmp_path / "c.skyc", b'{"version": 1}' * 100)
    raw = bytearray(path.read_bytes())
    start = raw.index(b"show.json") + len("show.json")  # the local header's name, then data
    raw[start : start + 20] = b"\xff" * 20
    path.write_bytes(bytes(raw))
    with pytest.raises(InputError, match=r"c\.skyc: (show\.json cannot be extracted|got )"):
        read_show_json(path)


@pytest.mark.parametrize(
    ("show", "match"),
    [
        (b"[" * 100_000 + b"]" * 100_000, r"show\.json: got JSON nested too deeply"),
        (b'{"swarm": ' + b"[" * 70 + b"]" * 70 + b"}", r"show\.json: got JSON nested more than 64"),
        ('{"version": 1}'.encode("utf-16"), r"show\.json: got UTF-16 text"),
        (b'{"version": "\xe9"}', r"show\.json: got bytes that are not UTF-8"),
    ],
)
def test_deep_and_undecodable_show_json_is_named(tmp_path: Path, show: bytes, match: str) -> None:
    with pytest.raises(InputError, match=rf"s\.skyc: {match}"):
        read_show_json(_archive(tmp_path / "s.skyc", show))


@settings(max_examples=100, deadline=None)
@given(raw=st.binary(max_size=80), zipped=st.booleans())
def test_random_bytes_give_an_input_error(raw: bytes, zipped: bool) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "r.skyc"
        if zipped:
            _archive(path, raw)
        else:
            path.write_bytes(b"PK\x03\x04" + raw)
        with pytest.raises(InputError, match=r"r\.skyc|show\.json"):
            read_show_json(path)


@settings(max_examples=100, deadline=None)
@given(
    doc=st.recursive(
        st.one_of(st.none(), st.floats(), st.integers(), st.text(max_size=3)),
        lambda inner: st.one_of(
            st.lists(inner, max_size=4),
            st.dictionaries(
                st.sampled_from(["version", "environment", "swarm", "drones", "type", "settings"]),
                inner,
                max_size=4,
            ),
        ),
        max_leaves=30,
    )
)
def test_random_show_json_gives_a_show_or_an_input_error(doc: object) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = _archive(Path(tmp) / "r.skyc", json.dumps(doc).encode())
        try:
            read_show_json(path)
        except InputError as exc:
            assert "show.json" in str(exc)
