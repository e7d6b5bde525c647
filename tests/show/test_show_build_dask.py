"""A show script planned with its writing on a dask cluster is the show planned in-process."""

from __future__ import annotations

import numpy as np
import pytest

from skyquill.show.build import ShowPlan, build_show
from skyquill.show.script import parse_script

pytest.importorskip("distributed")

pytestmark = [pytest.mark.timeout(180), pytest.mark.slow]

SCRIPT = """
[show]
drones = 4
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
type = "formation"
shape = "grid"
origin = [-3.0, 0.0, 6.0]
columns = 2
spacing = 3.0
hold = 1.0
color = "#ff0000"
[[scene]]
type = "write"
text = "I L"
size = 1.5
origin = [-3.0, -5.0, 5.0]
color = [255, 255, 255]
[[scene]]
type = "land"
altitude = 2.0
"""


def _samples(plan: ShowPlan) -> np.ndarray:
    """Every drone's position at 200 instants of the show, (drones, 200, 3) m."""
    end = max(d.trajectory.duration for d in plan.drones)
    t = np.linspace(0.0, end, 200)
    return np.stack(
        [d.trajectory.evaluate(np.minimum(t, d.trajectory.duration)) for d in plan.drones]
    )


def test_the_show_on_a_local_dask_cluster_is_the_show_in_process() -> None:
    script = parse_script(SCRIPT)
    here = build_show(script, workers=1)
    there = build_show(script, scheduler="local")
    assert [s["type"] for s in there.scenes] == [s["type"] for s in here.scenes]
    for got, want in zip(there.scenes, here.scenes, strict=True):
        assert got["end_s"] == pytest.approx(want["end_s"], abs=1e-9)
    # Worker processes sum in their own order (BLAS threads): the same plan to 1e-9 m.
    np.testing.assert_allclose(_samples(there), _samples(here), rtol=0, atol=1e-9)
    assert there.min_separation_m == pytest.approx(here.min_separation_m, abs=1e-9)
