"""Frames and walls: round trips, corners, ray hits, normal feet, angle parsing."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.painting.wall import Placement, Wall, parse_angles, rot2


def test_placement_round_trip_and_eq1() -> None:
    p = Placement(np.array([0.3, -1.1, 0.2]), math.radians(10))
    pts = np.random.default_rng(0).normal(size=(20, 3))
    assert np.allclose(p.to_w(p.to_rho(pts)), pts)
    # eq. 1: the wall origin seen from R_rho is R(gamma)^T (0 - delta)
    expected = rot2(math.radians(10)).T @ -np.array([0.3, -1.1])
    assert np.allclose(p.to_rho(np.zeros(3))[:2], expected)


def test_placement_refuses_a_drone_facing_away() -> None:
    with pytest.raises(InputError, match=r"gamma: got 95 deg, expected \|gamma\| < 90"):
        Placement(np.zeros(3), math.radians(95))


def test_flat_wall_depth_normal_hit() -> None:
    wall = Wall.flat()
    assert np.allclose(wall.depth(np.array([-3.0, 0.0, 2.0])), 0.0)
    assert np.allclose(wall.normal(np.array([1.0])), [[0.0, 1.0]])
    u = rot2(math.radians(20)) @ np.array([0.0, 1.0])
    assert wall.hit(np.array([0.0, -1.0]), u) == pytest.approx(1.0 / math.cos(math.radians(20)))
    assert wall.hit(np.array([0.0, 0.5]), np.array([0.0, 1.0])) == pytest.approx(-0.5)
    assert wall.hit(np.array([0.0, -1.0]), np.array([1.0, 0.0])) == math.inf


def test_three_segments_are_continuous_with_the_middle_through_the_origin() -> None:
    wall = Wall.segmented([-10, 0, 10], (-1.5, 1.5))
    assert np.allclose(wall.breaks_m, [-0.5, 0.5])
    assert wall.depth(np.array([0.0]))[0] == pytest.approx(0.0)
    eps = 1e-9
    for b in wall.breaks_m:
        left, right = wall.depth(np.array([b - eps, b + eps]))
        assert left == pytest.approx(right, abs=1e-8)
    # both outer segments recede: right with +10 deg, left with -10 deg
    assert wall.depth(np.array([1.5]))[0] == pytest.approx(math.tan(math.radians(10)))
    assert wall.depth(np.array([-1.5]))[0] == pytest.approx(math.tan(math.radians(10)))
    assert np.allclose(wall.normal(np.array([1.0]))[0], [-math.sin(0.1745329), math.cos(0.1745329)])


@settings(max_examples=60, deadline=None)
@given(
    angles=st.lists(st.floats(-40, 40), min_size=1, max_size=5),
    x=st.floats(-3.5, 3.5),
    heading=st.floats(-30, 30),
)
def test_hit_lands_on_the_wall(angles: list[float], x: float, heading: float) -> None:
    wall = Wall.segmented(angles, (-2.0, 2.0))
    start = np.array([x, wall.depth(np.array([x]))[0] - 1.0])
    u = rot2(math.radians(heading)) @ np.array([0.0, 1.0])
    t = wall.hit(start, u)
    assert math.isfinite(t)
    p = start + t * u
    assert p[1] == pytest.approx(wall.depth(np.array([p[0]]))[0], abs=1e-9)


def test_foot_is_perpendicular() -> None:
    wall = Wall.segmented([-15, 0, 15], (-1.5, 1.5))
    p = np.array([[1.2, 0.0], [-1.4, 0.0], [0.1, 0.0]])
    foot = wall.foot(p)
    for q, f in zip(p, foot, strict=True):
        n = wall.normal(np.array([q[0]]))[0]
        d = q - f
        assert abs(d @ np.array([n[1], -n[0]])) < 1e-12  # p - foot is along the normal


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("", r"--wall-angles: got '', expected comma-separated finite angles"),
        ("-10,,10", r"--wall-angles: got '-10,,10', expected comma-separated"),
        ("a", r"--wall-angles: got 'a', expected"),
        ("nan", r"--wall-angles: got 'nan', expected comma-separated finite"),
        ("0,75", r"--wall-angles: got '0,75', expected each angle within \+-60 deg"),
    ],
)
def test_malformed_angle_lists(text: str, match: str) -> None:
    with pytest.raises(InputError, match=match):
        parse_angles(text)


def test_angle_list_forms() -> None:
    assert parse_angles("-10|0|+10") == [-10.0, 0.0, 10.0]
    assert parse_angles(" 5 ") == [5.0]


def test_wall_validation() -> None:
    with pytest.raises(InputError, match=r"wall breaks: got \[0.5, -0.5\], expected increasing"):
        Wall(np.zeros(3), np.array([0.5, -0.5]))
    with pytest.raises(InputError, match=r"wall angles: got 2 angle\(s\) and 0 corner"):
        Wall(np.zeros(2), np.zeros(0))
