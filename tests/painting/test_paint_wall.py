"""Frames and walls: round trips, corners, ray hits, normal feet, angle parsing."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.painting.wall import KINK_TOLERANCE_M, Placement, Wall, parse_angles, rot2


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


@pytest.mark.parametrize("radius", [20.0, -20.0, 6.0])
def test_cylinder_polygon_stays_on_the_circle(radius: float) -> None:
    wall = Wall.cylinder(radius, step_deg=0.5)
    x = np.linspace(-4.0, 4.0, 401)
    circle = np.sign(radius) * (abs(radius) - np.sqrt(radius**2 - x**2))
    # circumscribed polygon: within R (1 / cos(step / 2) - 1) of the circle along its radius,
    # that over the cosine of the steepest slope along y
    radial = abs(radius) * (1 / math.cos(math.radians(0.25)) - 1)
    steepest = math.asin(4.0 / abs(radius))
    assert np.max(np.abs(wall.depth(x) - circle)) <= radial / math.cos(steepest) + 1e-12
    assert wall.depth(np.array([0.0]))[0] == pytest.approx(0.0, abs=1e-12)


def test_recess_depths() -> None:
    wall = Wall.recess(0.6, 1.4, 0.1, side_deg=45.0)
    x = np.array([0.0, 0.6, 0.65, 1.0, 1.35, 1.4, 3.0])
    assert wall.depth(x) == pytest.approx([0, 0, 0.05, 0.1, 0.05, 0, 0], abs=1e-12)


def _hit_one_by_one(wall: Wall, start: np.ndarray, direction: np.ndarray) -> float:
    """The ray's hit tried segment by segment (the definition the vectorised one keeps): the
    first segment whose line the ray meets within that segment, up to round-off."""
    edges = [-math.inf, *wall.breaks_m.tolist(), math.inf]
    for k in range(wall.n_segments):
        anchor, u = wall.line(k)
        n = np.array([-u[1], u[0]])
        along = float(direction @ n)
        if along <= 1e-12:
            continue
        t = float((anchor - start) @ n) / along
        x = start[0] + t * direction[0]
        if edges[k] - KINK_TOLERANCE_M <= x <= edges[k + 1] + KINK_TOLERANCE_M:
            return t
    return math.inf


def test_a_ray_from_a_kink_of_the_wall_hits_it_there() -> None:
    # Hypothesis: the ray from the kink between a 0 and a 1 deg segment found no wall
    # (inf): round-off put each line's root just inside the other segment.
    wall = Wall.segmented([0.0, 0.0, 1.0, 0.0], (-2.0, 2.0))
    direction = rot2(math.radians(1.0)) @ np.array([0.0, 1.0])
    assert wall.hit(np.zeros(2), direction) == pytest.approx(0.0, abs=1e-12)


@settings(max_examples=60, deadline=None)
@given(
    angles=st.lists(st.floats(-60, 60), min_size=1, max_size=5),
    x0=st.floats(-3, 3),
    y0=st.floats(-2, 0.5),
    heading=st.floats(-80, 80),
)
def test_hit_matches_the_segment_by_segment_definition(
    angles: list[float], x0: float, y0: float, heading: float
) -> None:
    wall = Wall.segmented(angles, (-2.0, 2.0))
    start = np.array([x0, y0])
    direction = rot2(math.radians(heading)) @ np.array([0.0, 1.0])
    expected = _hit_one_by_one(wall, start, direction)
    assert wall.hit(start, direction) == pytest.approx(expected, rel=1e-12, abs=1e-12)
