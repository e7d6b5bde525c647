"""plan_show on a dask.distributed cluster gives the same missions as in-process.

Two bundled characters (一 and 人; 二 is not bundled), resegmentation off to keep it fast.
"""

from __future__ import annotations

import sys
import time

import numpy as np
import pytest

from skyquill.calligraphy.mission import WritingOptions
from skyquill.calligraphy.show import Show, plan_show
from skyquill.errors import InputError
from skyquill.strokes import Strokes, hanzi_strokes

distributed = pytest.importorskip("distributed")

pytestmark = pytest.mark.timeout(120)

OPTIONS = WritingOptions(resegment="off")
SEPARATION_M = 1.0


@pytest.fixture(scope="module")
def parts() -> list[Strokes]:
    return [hanzi_strokes("一"), hanzi_strokes("人")]


@pytest.fixture(scope="module")
def reference(parts: list[Strokes]) -> Show:
    return plan_show(parts, OPTIONS, SEPARATION_M, workers=1)


def _assert_same(show: Show, reference: Show) -> None:
    # Worker processes do not inherit this process's BLAS thread limit, so sums may be
    # ordered differently: the same plan to 1e-9 m, not to the last bit.
    assert len(show.missions) == len(reference.missions)
    for got, want in zip(show.missions, reference.missions, strict=True):
        assert got.trajectory.duration == pytest.approx(want.trajectory.duration, abs=1e-9)
        np.testing.assert_allclose(
            got.trajectory.control_points, want.trajectory.control_points, rtol=0, atol=1e-9
        )
        np.testing.assert_allclose(got.pen_windows, want.pen_windows, rtol=0, atol=1e-9)
    for got_home, want_home in zip(show.homes, reference.homes, strict=True):
        np.testing.assert_array_equal(got_home, want_home)
    assert show.min_separation_m == pytest.approx(reference.min_separation_m, abs=1e-9)
    assert show.min_separation_m >= SEPARATION_M


def test_local_scheduler_matches_in_process(parts: list[Strokes], reference: Show) -> None:
    show = plan_show(parts, OPTIONS, SEPARATION_M, scheduler="local")
    _assert_same(show, reference)


def test_cluster_address_matches_in_process(parts: list[Strokes], reference: Show) -> None:
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        show = plan_show(
            parts,
            OPTIONS,
            SEPARATION_M,
            scheduler=cluster.scheduler_address,
        )
    _assert_same(show, reference)


def test_unreachable_scheduler_is_an_input_error(parts: list[Strokes]) -> None:
    start = time.perf_counter()
    with pytest.raises(InputError, match=r"tcp://127\.0\.0\.1:1"):
        plan_show(parts, OPTIONS, SEPARATION_M, scheduler="tcp://127.0.0.1:1")
    assert time.perf_counter() - start < 30.0


def test_empty_scheduler_is_an_input_error(parts: list[Strokes]) -> None:
    with pytest.raises(InputError, match="scheduler"):
        plan_show(parts, OPTIONS, SEPARATION_M, scheduler="")


def test_process_pool_matches_in_process(parts: list[Strokes], reference: Show) -> None:
    _assert_same(plan_show(parts, OPTIONS, SEPARATION_M, workers=2), reference)


def test_missing_dask_names_the_extra(
    parts: list[Strokes], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(InputError, match=r"pip install 'skyquill\[dask\]'"):
        plan_show(parts, OPTIONS, SEPARATION_M, scheduler="local")


def test_progress_as_the_cluster_returns_each_drone(parts: list[Strokes]) -> None:
    calls: list[tuple[int, int, str]] = []
    plan_show(parts, OPTIONS, SEPARATION_M, scheduler="local", progress=lambda *c: calls.append(c))
    assert [c[:2] for c in calls] == [(0, 2), (1, 2), (2, 2)]
    assert sorted(c[2] for c in calls[1:]) == ["planned drone 1 of 2", "planned drone 2 of 2"]
