"""Skybrush .skyc shows: written, read back, and every malformed show named."""

from __future__ import annotations

import copy
import io
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
from skyquill.export.skybrush import skyc_file as skyc
from skyquill.export.skybrush.keyframes import skybrush_keyframes
from skyquill.export.skybrush.lights import encode_light_program, program_bytes
from skyquill.export.skybrush.skyc_file import (
    SkycDrone,
    read_show_json,
    show_trajectories,
    validate_show,
    write_skyc,
)
from skyquill.trajectory import SplineTrajectory


def spline(degree: int, seed: int = 0, n_ctrl: int = 14, duration: float = 8.0) -> SplineTrajectory:
    """Random 3-D spline in a 2 m cube lifted 1 m up."""
    ctrl = np.random.default_rng(seed).uniform(-1.0, 1.0, (n_ctrl, 3)) + np.array([0.0, 0.0, 1.0])
    return SplineTrajectory(ctrl, degree, duration)


def drone(traj: SplineTrajectory, name: str = "d", lights: bytes | None = None) -> SkycDrone:
    return SkycDrone(name, skybrush_keyframes(traj), lights)


def test_a_show_holds_trajectories_lights_yaw_and_validation(tmp_path: Path) -> None:
    trajs = [spline(5, seed=s) for s in range(3)]
    program = encode_light_program([(1.0, 2.0)], (1, 2, 3), 8.0)
    drones = [drone(t, f"d{i}", program if i == 0 else None) for i, t in enumerate(trajs)]
    path = write_skyc(drones, tmp_path / "three.skyc", validation={"maxAltitude": 2.5}, title="3")
    with zipfile.ZipFile(path) as archive:
        assert archive.namelist() == ["show.json"]
    show = read_show_json(path)
    assert show["meta"]["title"] == "3" and show["environment"]["type"] == "indoor"
    assert show["settings"]["validation"] == {"maxAltitude": 2.5}
    for i, entry in enumerate(show["swarm"]["drones"]):
        settings = entry["settings"]
        assert settings["name"] == f"d{i}"
        assert settings["trajectory"]["takeoffTime"] == 0.0
        assert settings["home"] == settings["trajectory"]["points"][0][1]
        assert settings["yawControl"] == {
            "version": 1,
            "setpoints": [[0.0, 0.0], [8.0, 0.0]],
            "autoYaw": False,
        }
        assert ("lights" in settings) == (i == 0)
    assert program_bytes("l", show["swarm"]["drones"][0]["settings"]["lights"]) == program
    t = np.linspace(0.0, 8.0, 20_001)
    for back, traj in zip(show_trajectories(show), trajs, strict=True):
        assert np.linalg.norm(back.evaluate(t) - traj.evaluate(t), axis=1).max() <= 2e-3


def test_nothing_to_write_is_refused(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="drones: got nothing"):
        write_skyc([], tmp_path / "x.skyc")
    with pytest.raises(InputError, match="title: got int"):
        write_skyc([drone(spline(3))], tmp_path / "x.skyc", title=3)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"settings.validation.minDistance: got -1"):
        write_skyc([drone(spline(3))], tmp_path / "x.skyc", validation={"minDistance": -1.0})


def valid_show(tmp_path: Path) -> dict[str, Any]:
    lights = encode_light_program([(1.0, 2.0)], (9, 9, 9), 8.0)
    drones = [drone(spline(3), "a", lights), drone(spline(3, 1), "b", lights)]
    return read_show_json(write_skyc(drones, tmp_path / "v.skyc", validation={"minDistance": 1}))


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
        (
            (*TRAJ, "points", 1, 0),
            0.0004,
            r"points\[1\]\[0\]: got 0.0004 after 0.0, expected .* 1 ms",
        ),
        ((*TRAJ, "points", 2, 2), [[0, 0, 0]] * 3, r"points\[2\]\[2\]: got 3 control points"),
        ((*TRAJ, "takeoffTime"), -1, r"takeoffTime: got -1, expected a finite time >= 0"),
        ((*TRAJ, "home"), [0, 0], r"trajectory.home: got \[0, 0\]"),
        (
            ("swarm", "drones", 1, "settings", "lights", "data"),
            "@@",
            r"drones\[1\].settings.lights.data",
        ),
        (
            ("swarm", "drones", 1, "settings", "yawControl", "setpoints"),
            [[0]],
            r"yawControl.setpoints",
        ),
        (
            ("swarm", "drones", 1, "settings", "yawControl", "autoYaw"),
            1,
            r"yawControl.autoYaw: got 1",
        ),
        (("settings", "validation", "maxAltitude"), "high", r"validation.maxAltitude: got 'high'"),
        (("settings",), [], r"show.json: settings: got list"),
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


def test_a_truncated_or_nan_show_is_an_input_error(tmp_path: Path) -> None:
    path = write_skyc([drone(spline(3))], tmp_path / "t.skyc")
    whole = path.read_bytes()
    show = json.loads(zipfile.ZipFile(io.BytesIO(whole)).read("show.json"))
    path.write_bytes(whole[: len(whole) // 2])
    with pytest.raises(InputError, match=r"t\.skyc: "):
        read_show_json(path)
    show["swarm"]["drones"][0]["settings"]["trajectory"]["points"][1][1][0] = math.nan
    nan = _archive(tmp_path / "nan.skyc", json.dumps(show).encode())  # json writes NaN
    with pytest.raises(InputError, match=r"show.json: got NaN, expected a Skybrush show object"):
        read_show_json(nan)


_MUTATIONS = (
    lambda p: p,
    lambda p: [p[0], p[1]],  # a point of two fields
    lambda p: [True, p[1], p[2]],  # a boolean time
    lambda p: [p[0], [*p[1][:2], "1"], p[2]],  # a string coordinate
    lambda p: [p[0], [*p[1][:2], float("nan")], p[2]],
    lambda p: [p[0], p[1][:2], p[2]],  # two coordinates
    lambda p: [p[0], p[1], [[0.0, 0.0, 0.0]] * 3],  # three control points
    lambda p: [p[0], p[1], [[0.0, 0.0]]],  # a short control point
    lambda p: [p[0], p[1], {}],  # controls not a list
    lambda p: [p[0] + 70.0, p[1], p[2]],  # a 70 s step
    lambda p: [p[0] - 5.0, p[1], p[2]],  # back in time
    lambda p: [int(p[0]), [int(c) for c in p[1]], p[2]],  # integers are numbers too
)


@settings(max_examples=200, deadline=None)
@given(
    seed=st.integers(0, 10**6),
    count=st.integers(1, 12),
    mutation=st.integers(0, len(_MUTATIONS) - 1),
    where=st.integers(0, 11),
)
def test_the_bulk_check_accepts_exactly_what_the_field_by_field_one_accepts(
    seed: int, count: int, mutation: int, where: int
) -> None:
    rng = np.random.default_rng(seed)
    times = np.cumsum(rng.uniform(0.001, 3.0, count)).round(3).tolist()
    points = [
        [
            t,
            rng.uniform(-5, 5, 3).tolist(),
            [] if k == 0 else rng.uniform(-5, 5, (int(rng.integers(0, 3)), 3)).tolist(),
        ]
        for k, t in enumerate(times)
    ]
    k = where % count
    points[k] = _MUTATIONS[mutation](points[k])
    bulk = skyc._well_formed(points)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(skyc, "_well_formed", lambda _: False)
        try:
            skyc._check_trajectory("t", {"version": 1, "points": points})
            one_by_one = True
        except InputError:
            one_by_one = False
    assert bulk == one_by_one
