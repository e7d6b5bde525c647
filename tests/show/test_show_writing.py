"""A write scene's writers of one letter share one planned flight, moved to their boards."""

from __future__ import annotations

import numpy as np
import pytest

from skyquill.calligraphy.mission import WritingOptions, plan_writing
from skyquill.show.script import WriteScene, parse_script
from skyquill.show.writing import first_alike, plan_writing_scene, writing_boards
from skyquill.strokes import typed_parts

SCRIPT = """
[show]
drones = 3
safety_distance = 1.5
home_spacing = 2.2
home_origin = [-2.0, -8.0]
[limits]
vmax = 3.0
amax = 2.0
jmax = 10.0
[[scene]]
type = "takeoff"
altitude = 2.0
[[scene]]
type = "write"
text = "I L I"
size = 1.5
origin = [-3.0, -5.0, 5.0]
columns = 2
color = [255, 255, 255]
[[scene]]
type = "land"
altitude = 2.0
"""


def test_repeated_letters_are_planned_once_and_moved_exactly_to_their_board() -> None:
    script = parse_script(SCRIPT)
    scene = script.scenes[1]
    assert isinstance(scene, WriteScene)
    parts = typed_parts(scene.text, 3, scene.font)
    boards = writing_boards(3, scene, script.safety_m)
    assert first_alike(parts, boards) == [0, 1, 0]  # the second I is the first one, moved
    writing = plan_writing_scene(scene, script, workers=1)
    # The third writer's flight planned on its own board (second row: another x and z) is
    # the first writer's moved there: same timing, pen windows and path to round-off.
    alone = plan_writing(parts[2], boards[2], WritingOptions(size_m=1.5, limits=script.limits))
    moved = writing.flights[2]
    assert moved.duration == pytest.approx(alone.trajectory.duration, rel=1e-12)
    np.testing.assert_allclose(writing.pen_windows[2], alone.pen_windows, rtol=0, atol=1e-9)
    t = np.linspace(0.0, moved.duration, 2001)
    # The path to 10 nm, its derivatives to 1e-5 of their limits (3 m/s, 2 m/s^2, 10 m/s^3):
    # the solver stops on other round-off in other coordinates (measured: 1.2e-9 m, 7e-9 m/s,
    # 1.9e-7 m/s^2, 2e-5 m/s^3).
    for order, atol in enumerate((1e-8, 3e-5, 2e-5, 1e-4)):
        np.testing.assert_allclose(
            moved.evaluate(t, order),
            alone.vehicle_trajectory().evaluate(t, order),
            rtol=0,
            atol=atol,
        )
    np.testing.assert_allclose(
        writing.starts[2] - writing.starts[0], boards[2].origin - boards[0].origin, atol=1e-12
    )


def test_different_letters_or_board_poses_are_planned_apart() -> None:
    script = parse_script(SCRIPT)
    scene = script.scenes[1]
    assert isinstance(scene, WriteScene)
    parts = typed_parts("I L I L", 4, scene.font)
    boards = writing_boards(4, scene, script.safety_m)
    assert first_alike(parts, boards) == [0, 1, 0, 1]
    turned = [boards[0], boards[1], boards[2], type(boards[3])("sky", boards[3].origin, 0.0, 10.0)]
    assert first_alike(parts, turned) == [0, 1, 0, 3]
