"""Transitions at scale: within 1.5x the lower bound, proven apart by the independent check."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.optimize.legs import LegLimits
from skyquill.show import ShowDrone, ShowLimits, check_show
from skyquill.show.build import _air, make_formation
from skyquill.show.capt import bottleneck_distance, lower_bound_s, one_wave
from skyquill.show.formation import home_grid
from skyquill.show.route import Route, route_to
from skyquill.show.script import ShowScript, parse_script

LIMITS = LegLimits(4.0, 2.0, 10.0)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10**6), n=st.integers(1, 5), extra=st.integers(0, 2))
def test_the_bottleneck_is_the_best_longest_move_over_every_assignment(
    seed: int, n: int, extra: int
) -> None:
    rng = np.random.default_rng(seed)
    a, b = rng.uniform(-10, 10, (n, 3)), rng.uniform(-10, 10, (n + extra, 3))
    distance = np.linalg.norm(a[:, None] - b[None], axis=2)
    best = min(
        distance[np.arange(n), list(p)].max() for p in itertools.permutations(range(n + extra), n)
    )
    assert bottleneck_distance(a, b) == pytest.approx(best, abs=1e-12)


def test_crossing_paths_are_not_one_wave() -> None:
    a = np.array([[0.0, 0, 5], [0.0, 0, 15]])
    assert one_wave(a, a[::-1].copy(), LIMITS, 2.0) is None
    assert one_wave(a, a + np.array([20.0, 0, 0]), LIMITS, 2.0) is not None


def _script(n: int, home_spacing: float, spacing: float) -> ShowScript:
    columns = math.ceil(math.sqrt(n))
    return parse_script(f"""
[show]
drones = {n}
safety_distance = 3.0
home_spacing = {home_spacing}
home_origin = [{-home_spacing * columns / 2:.1f}, -60]
[limits]
vmax = 4.0
amax = 2.0
jmax = 10.0
[[scene]]
type = "takeoff"
[[scene]]
type = "formation"
shape = "text"
text = "SKY"
origin = [-30, 0, 10]
size = 60
[[scene]]
type = "formation"
shape = "grid"
origin = [-20, 0, 10]
spacing = {spacing}
columns = {max(2, columns // 2)}
[[scene]]
type = "land"
""")


def _proven_independently(start: np.ndarray, route: Route, script: ShowScript) -> None:
    """skyquill check on the flights, knowing nothing of the planner; and the goals reached."""
    for leg in route.legs:
        flights = [leg.trajectory(i) for i in range(len(start))]
        speed = 4.0 * (1 + 1e-6)
        limits = ShowLimits(speed, speed, speed, 2.0 * (1 + 1e-6), None, None)
        report = check_show([ShowDrone(f, str(i)) for i, f in enumerate(flights)], 3.0, limits)
        assert report.passed, report.violations[:2]
        ends = np.array([f.evaluate(np.array([f.duration]))[0] for f in flights])
        np.testing.assert_allclose(ends, leg.goals, atol=1e-9)


@pytest.mark.parametrize(("home_spacing", "spacing"), [(4.5, 4.5), (3.0, 3.0)])
def test_take_off_formations_and_landing_within_one_and_a_half_times_the_lower_bound(
    home_spacing: float, spacing: float
) -> None:
    script = _script(40, home_spacing, spacing)
    homes = home_grid(40, origin=script.home_origin, spacing_m=home_spacing, safety_m=3.0)
    air = _air(homes, 3.0, script)
    text = make_formation(script.scenes[1], script).points  # type: ignore[arg-type]
    grid = make_formation(script.scenes[2], script).points  # type: ignore[arg-type]
    here = air
    for goal in (text, grid, air):  # take-off to a formation, formation to formation, landing
        route = route_to(here, goal, script)
        _proven_independently(here, route, script)
        assert route.lower_bound_s <= route.duration <= 1.5 * route.lower_bound_s
        here = goal[route.chosen]


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 10**6), n=st.integers(2, 14), plane=st.sampled_from(["y", "z"]))
def test_any_planar_formation_is_reached_proven_and_never_below_the_bound(
    seed: int, n: int, plane: str
) -> None:
    rng = np.random.default_rng(seed)

    def spread(count: int, offset: float) -> np.ndarray:
        kept: list[np.ndarray] = []
        while len(kept) < count:  # points at least the safety distance apart on a plane
            uv = rng.uniform(0, 4.0 * math.sqrt(count) + 6, 2)
            if all(np.linalg.norm(uv - k) >= 3.0 * (1 + 1e-6) for k in kept):
                kept.append(uv)
        uv = np.array(kept)
        if plane == "y":
            return np.column_stack([uv[:, 0], np.full(count, offset), 5 + uv[:, 1]])
        return np.column_stack([uv[:, 0], uv[:, 1], np.full(count, 5 + offset)])

    script = _script(n, 4.5, 4.5)
    start, goal = spread(n, 0.0), spread(n, float(rng.uniform(0, 30)))
    route = route_to(start, goal, script)
    _proven_independently(start, route, script)
    assert route.duration >= route.lower_bound_s - 1e-9
    assert lower_bound_s(bottleneck_distance(start, goal), LIMITS) == pytest.approx(
        route.lower_bound_s
    )
