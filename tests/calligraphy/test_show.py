"""plan_show's progress reports and closed-loop flights (the CLI's and the studio's planner)."""

from __future__ import annotations

import numpy as np
import pytest

from skyquill.calligraphy.mission import WritingOptions
from skyquill.calligraphy.show import fly_mission, plan_show
from skyquill.strokes import Strokes, hanzi_strokes

pytestmark = pytest.mark.timeout(180)

OPTIONS = WritingOptions(resegment="off")


@pytest.fixture(scope="module")
def parts() -> list[Strokes]:
    return [hanzi_strokes("一"), hanzi_strokes("人")]


class Recorder:
    """Keeps every ``progress(done, total, stage)`` call."""

    def __init__(self) -> None:
        self.calls: list[tuple[int, int, str]] = []

    def __call__(self, done: int, total: int, stage: str) -> None:
        self.calls.append((done, total, stage))


@pytest.mark.parametrize("workers", [1, 2])
def test_progress_after_each_drone_in_process_and_in_a_pool(
    parts: list[Strokes], workers: int
) -> None:
    progress = Recorder()
    show = plan_show(parts, OPTIONS, workers=workers, progress=progress)
    assert len(show.missions) == 2 and show.flights == ()
    assert progress.calls[0] == (0, 2, "planning 2 drone(s)")
    assert [c[:2] for c in progress.calls[1:]] == [(1, 2), (2, 2)]
    # A pool reports drones as they arrive, in any order; each one once.
    assert sorted(c[2] for c in progress.calls[1:]) == [
        "planned drone 1 of 2",
        "planned drone 2 of 2",
    ]


def test_fly_flies_every_mission_after_planning(parts: list[Strokes]) -> None:
    progress = Recorder()
    show = plan_show(parts, OPTIONS, workers=1, fly=True, progress=progress)
    assert [c[:2] for c in progress.calls] == [(0, 4), (1, 4), (2, 4), (3, 4), (4, 4)]
    assert progress.calls[-1][2] == "flew drone 2 of 2 in simulation"
    assert len(show.flights) == 2
    for mission, flight in zip(show.missions, show.flights, strict=True):
        assert flight.ink  # a horizontal board is a contact board: the brush inks it
        assert flight.rmse_m < 0.02
        again = fly_mission(mission)  # deterministic: the same flight
        np.testing.assert_array_equal(again.p, flight.p)


def test_a_progress_that_raises_stops_the_show(parts: list[Strokes]) -> None:
    class StopError(Exception):
        pass

    def stop_after_first(done: int, total: int, stage: str) -> None:
        if done == 1:
            raise StopError(stage)

    for workers in (1, 2):
        with pytest.raises(StopError, match="planned drone"):
            plan_show(parts, OPTIONS, workers=workers, progress=stop_after_first)


def test_plan_jobs_returns_missions_in_job_order_and_reports_each() -> None:
    """plan_jobs (the show scripts' planner) keeps job order and calls progress per drone."""
    from skyquill.calligraphy.show import layout, plan_jobs
    from skyquill.strokes import typed_strokes

    opts = WritingOptions()
    parts = [typed_strokes("一"), typed_strokes("二")]
    places = layout(2, opts.size_m, 1.0)
    calls: list[tuple[int, int]] = []
    missions = plan_jobs(
        [(p, b, opts, h) for p, (b, h) in zip(parts, places, strict=True)],
        workers=1,
        progress=lambda done, total, _: calls.append((done, total)),
    )
    assert [len(m.strokes_world) for m in missions] == [1, 2]
    assert calls == [(0, 2), (1, 2), (2, 2)]
