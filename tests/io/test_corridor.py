"""Tests for skyquill.io.corridor: the shipped S corridor and input validation."""

from __future__ import annotations

import copy
import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from skyquill.errors import InputError
from skyquill.io.corridor import BoxCorridor, OrientedBox, load_box_corridor

EXAMPLES = Path(__file__).parents[2] / "examples"
S_CORRIDOR = EXAMPLES / "s_corridor.json"


@pytest.fixture(scope="module")
def corridor() -> BoxCorridor:
    return load_box_corridor(S_CORRIDOR)


@pytest.fixture
def raw() -> dict[str, Any]:
    data: dict[str, Any] = json.loads(S_CORRIDOR.read_text())
    return data


def _write(tmp_path: Path, data: Any) -> Path:
    path = tmp_path / "corridor.json"
    path.write_text(json.dumps(data))
    return path


# ------------------------------------------------------------------ shipped example
def test_example_shape(corridor: BoxCorridor) -> None:
    assert len(corridor.boxes) == 7
    assert corridor.start.shape == (3,) and corridor.goal.shape == (3,)
    assert corridor.waypoints.shape == (8, 3)
    np.testing.assert_allclose(corridor.waypoints[0], corridor.start)
    np.testing.assert_allclose(corridor.waypoints[-1], corridor.goal)
    length = np.sum(np.linalg.norm(np.diff(corridor.waypoints, axis=0), axis=1))
    assert 20.0 <= length <= 25.0
    for box in corridor.boxes:
        lo, hi = box.center[2] - box.size[2] / 2, box.center[2] + box.size[2] / 2
        assert 0.5 <= lo < hi <= 2.5


def test_example_s_shape(corridor: BoxCorridor) -> None:
    """Yaw turns left by a total of ~180 deg, then right by ~180 deg."""
    yaws = np.unwrap([b.yaw_rad for b in corridor.boxes])
    turns = np.diff(yaws)
    sign_changes = np.count_nonzero(np.diff(np.sign(turns[turns != 0.0])))
    assert sign_changes == 1
    assert np.isclose(yaws.max() - yaws[0], np.pi) and np.isclose(yaws.max() - yaws[-1], np.pi)


def test_start_goal_inside(corridor: BoxCorridor) -> None:
    assert corridor.boxes[0].contains(corridor.start[None, :])[0]
    assert corridor.boxes[-1].contains(corridor.goal[None, :])[0]


def test_waypoint_segments_inside_their_boxes(corridor: BoxCorridor) -> None:
    s = np.linspace(0.0, 1.0, 501)[:, None]
    for i, box in enumerate(corridor.boxes):
        a, b = corridor.waypoints[i], corridor.waypoints[i + 1]
        assert np.all(box.contains((1 - s) * a + s * b)), f"segment {i} leaves box {i}"


def test_overlap_waypoints_have_clearance(corridor: BoxCorridor) -> None:
    """Each interior waypoint sits >= 0.3 m inside both boxes it joins (overlap >= 0.6 m)."""
    for i in range(1, len(corridor.boxes)):
        for box in corridor.boxes[i - 1 : i + 1]:
            A, b = box.halfspaces()
            assert np.min(b - A @ corridor.waypoints[i]) >= 0.3


def test_halfspaces_agree_with_contains(corridor: BoxCorridor) -> None:
    rng = np.random.default_rng(0)
    for box in corridor.boxes:
        A, b = box.halfspaces()
        assert A.shape == (6, 3) and b.shape == (6,)
        np.testing.assert_allclose(np.linalg.norm(A, axis=1), 1.0)
        p = box.center + rng.uniform(-1.0, 1.0, (4000, 3)) * box.size
        inside = box.contains(p)
        assert inside.shape == (4000,) and inside.dtype == np.bool_
        np.testing.assert_array_equal(inside, np.all(p @ A.T <= b, axis=1))
        assert 0 < inside.sum() < len(p)  # both cases exercised
        # independent check: coordinates in the box frame within +-size/2
        c, s = math.cos(box.yaw_rad), math.sin(box.yaw_rad)
        rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        local = (p - box.center) @ rot
        margin = np.min(box.size / 2 - np.abs(local), axis=1)
        clear = np.abs(margin) > 1e-9
        np.testing.assert_array_equal(inside[clear], (margin >= 0)[clear])


def test_box_geometry_and_tol() -> None:
    box = OrientedBox(center=np.array([1.0, 2.0, 1.0]), size=np.array([4.0, 2.0, 1.0]), yaw_rad=0.5)
    u = np.array([math.cos(0.5), math.sin(0.5), 0.0])
    v = np.array([-math.sin(0.5), math.cos(0.5), 0.0])
    corners = box.center + np.array(
        [sx * 2.0 * u + sy * 1.0 * v + sz * np.array([0, 0, 0.5]) for sx in (-1, 1)
         for sy in (-1, 1) for sz in (-1, 1)]
    )  # fmt: skip
    assert np.all(box.contains(corners, tol=1e-12))
    outward = box.center + 1.05 * (corners - box.center)
    assert not np.any(box.contains(outward))
    assert np.all(box.contains(outward, tol=0.2))
    assert not box.contains(box.center, tol=-0.6)[0]  # shrunk past the half height
    assert box.contains(box.center).shape == (1,)


def test_box_direct_validation() -> None:
    with pytest.raises(InputError, match=r"OrientedBox\.size"):
        OrientedBox(center=np.zeros(3), size=np.array([1.0, 0.0, 1.0]), yaw_rad=0.0)
    with pytest.raises(InputError, match=r"OrientedBox\.center.*shape"):
        OrientedBox(center=np.zeros(2), size=np.ones(3), yaw_rad=0.0)
    with pytest.raises(InputError, match=r"OrientedBox\.yaw_rad"):
        OrientedBox(center=np.zeros(3), size=np.ones(3), yaw_rad=float("nan"))
    box = OrientedBox(center=np.zeros(3), size=np.ones(3), yaw_rad=0.0)
    with pytest.raises(InputError, match=r"\bp\b.*shape"):
        box.contains(np.zeros((4, 2)))


# ------------------------------------------------------------------------ bad inputs
Mutation = Callable[[dict[str, Any]], None]


def _set(*keys: Any, value: Any) -> Mutation:
    def mutate(d: dict[str, Any]) -> None:
        target: Any = d
        for k in keys[:-1]:
            target = target[k]
        target[keys[-1]] = value

    return mutate


def _delete(*keys: Any) -> Mutation:
    def mutate(d: dict[str, Any]) -> None:
        target: Any = d
        for k in keys[:-1]:
            target = target[k]
        del target[keys[-1]]

    return mutate


BAD_CASES: list[tuple[str, Mutation, str]] = [
    ("missing boxes", _delete("boxes"), r"^boxes in .*expected the required key"),
    ("missing start", _delete("start"), r"^start in .*expected the required key"),
    ("missing goal", _delete("goal"), r"^goal in "),
    ("missing waypoints", _delete("waypoints"), r"^waypoints in "),
    ("missing box size", _delete("boxes", 3, "size"), r"^boxes\[3\]\.size in "),
    ("missing yaw", _delete("boxes", 0, "yaw_deg"), r"^boxes\[0\]\.yaw_deg in "),
    ("unknown key", _set("speed", value=3.0), r"^speed in .*unknown key"),
    ("unknown box key", _set("boxes", 1, "yaw", value=3.0), r"^boxes\[1\]\.yaw in .*unknown"),
    ("no boxes", _set("boxes", value=[]), r"^boxes in .*got \[\], expected .*at least 1 box"),
    ("boxes not list", _set("boxes", value={"a": 1}), r"^boxes in .*list"),
    ("box not object", _set("boxes", 2, value=[1, 2, 3]), r"^boxes\[2\] in .*object"),
    (
        "start 2 values",
        _set("start", value=[0.0, 0.0]),
        r"^start in .*got 2 values.*expected exactly 3",
    ),
    (
        "goal 4 values",
        _set("goal", value=[0, 0, 0, 0]),
        r"^goal in .*got 4 values.*expected exactly 3",
    ),
    ("center length", _set("boxes", 4, "center", value=[1.0]), r"^boxes\[4\]\.center in "),
    (
        "size nan",
        _set("boxes", 2, "size", 1, value=math.nan),
        r"corridor.json: got NaN, expected .*not JSON",  # json_read refuses it first
    ),
    ("start inf", _set("start", 2, value=math.inf), r"corridor.json: got Infinity, expected"),
    ("yaw nan", _set("boxes", 5, "yaw_deg", value=math.nan), r"corridor.json: got NaN"),
    ("yaw string", _set("boxes", 5, "yaw_deg", value="45"), r"^boxes\[5\]\.yaw_deg in .*'45'"),
    ("yaw bool", _set("boxes", 5, "yaw_deg", value=True), r"^boxes\[5\]\.yaw_deg in .*True"),
    ("size zero", _set("boxes", 1, "size", 2, value=0.0), r"^boxes\[1\]\.size in .*> 0"),
    ("size negative", _set("boxes", 6, "size", 0, value=-1.0), r"^boxes\[6\]\.size in .*> 0"),
    ("waypoint short", _set("waypoints", 3, value=[1.0, 2.0]), r"^waypoints\[3\] in .*exactly 3"),
    ("waypoint nan", _set("waypoints", 2, 0, value=math.nan), r"corridor.json: got NaN"),
    ("one waypoint", _set("waypoints", value=[[0.0, 0.0, 1.2]]), r"^waypoints in .*at least 2"),
    ("waypoints flat", _set("waypoints", value=[1.0, 2.0, 3.0]), r"^waypoints\[0\] in "),
    ("start outside", _set("start", value=[3.0, 5.0, 1.2]), r"^start in .*inside boxes\[0\]"),
    ("start too high", _set("start", 2, value=2.0), r"^start in .*outside that box"),
    ("goal outside", _set("goal", value=[0.0, 0.0, 1.2]), r"^goal in .*inside boxes\[6\]"),
    ("description type", _set("description", value=3), r"^description in .*string"),
]


@pytest.mark.parametrize(
    ("mutate", "pattern"), [c[1:] for c in BAD_CASES], ids=[c[0] for c in BAD_CASES]
)
def test_bad_corridor_fields(
    tmp_path: Path, raw: dict[str, Any], mutate: Mutation, pattern: str
) -> None:
    data = copy.deepcopy(raw)
    mutate(data)
    with pytest.raises(InputError, match=pattern):
        load_box_corridor(_write(tmp_path, data))


def test_unmodified_copy_loads(tmp_path: Path, raw: dict[str, Any]) -> None:
    corridor = load_box_corridor(_write(tmp_path, raw))
    assert len(corridor.boxes) == 7


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(
        InputError, match=r"nope\.json: no such file, expected a corridor JSON file"
    ):
        load_box_corridor(tmp_path / "nope.json")


def test_invalid_json(tmp_path: Path) -> None:
    path = tmp_path / "broken.json"
    path.write_text('{"boxes": [}')
    with pytest.raises(InputError, match=r"broken\.json: got malformed JSON at line 1"):
        load_box_corridor(path)


def test_top_level_not_object(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"top level.*got list, expected a JSON object"):
        load_box_corridor(_write(tmp_path, [1, 2, 3]))


def test_message_says_what_was_received(tmp_path: Path, raw: dict[str, Any]) -> None:
    raw["boxes"][2]["size"] = [1.0, -2.0, 1.2]
    with pytest.raises(InputError) as info:
        load_box_corridor(_write(tmp_path, raw))
    msg = str(info.value)
    assert msg.startswith("boxes[2].size") and "-2.0" in msg and "> 0" in msg
