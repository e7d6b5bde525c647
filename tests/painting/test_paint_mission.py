"""Missions: the paper's tables in miniature, landings, faults, determinism, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from skyquill.errors import InputError
from skyquill.painting.dots import paper_drawing
from skyquill.painting.mission import ContactModel, Localization, MissionConfig, run_mission
from skyquill.painting.wall import Placement, Wall

DOTS = paper_drawing()


def truth(gamma_deg: float) -> Placement:
    return Placement(np.array([0.0, -1.1, 0.0]), math.radians(gamma_deg))


def rmse(gamma_deg: float, estimator: str, seed: int, **kw: object) -> float:
    result = run_mission(
        DOTS,
        wall=kw.pop("wall", Wall.flat()),  # type: ignore[arg-type]
        truth=truth(gamma_deg),
        estimator=estimator,
        rng=np.random.default_rng(seed),
        **kw,  # type: ignore[arg-type]
    )
    return result.rmse_m


@pytest.mark.parametrize("gamma", [-15.0, -10.0, 10.0, 15.0])
@pytest.mark.parametrize("localization", ["truth", "onboard"])
def test_table1_estimation_wins_at_every_nonzero_gamma(gamma: float, localization: str) -> None:
    with_est = rmse(gamma, "svd", 0, localization=localization)
    without = rmse(gamma, "none", 0, localization="truth")
    assert with_est < without
    # the error without estimation is the geometry: ~ d tan(gamma) along the wall
    assert without > 0.8 * 1.1 * math.tan(math.radians(abs(gamma)))


def test_table1_gamma0_without_estimation_is_the_hover_error() -> None:
    r = rmse(0.0, "none", 1, localization="truth")
    assert 0.035 < r < 0.055  # sqrt(2) * 3 cm hover error


def test_estimate_converges_to_the_truth() -> None:
    result = run_mission(
        DOTS, wall=Wall.flat(), truth=truth(10.0), localization="truth",
        rng=np.random.default_rng(2),
    )  # fmt: skip
    assert result.estimate.gamma_deg == pytest.approx(10.0, abs=0.2)
    assert result.estimate.delta_w[1] == pytest.approx(-1.1, abs=0.01)
    assert result.contacts == len(DOTS) + 1  # the far first point of §4.1
    assert result.history["dot"][0] == -1
    summary = result.summary()
    assert summary["truth"]["gamma_deg"] == pytest.approx(10.0)
    assert summary["n_dots"] == 140 and summary["painted_dots"] == 140


def test_landings_keep_flights_under_the_battery() -> None:
    cfg = MissionConfig(battery_s=300.0)
    result = run_mission(
        DOTS, wall=Wall.flat(), truth=truth(0.0), config=cfg, rng=np.random.default_rng(0)
    )
    assert result.landings >= 3
    t = result.history["t_s"]
    starts = np.concatenate([[0.0], t[result.history["landing"].astype(bool)]])
    assert np.all(np.diff(starts) <= 300.0 + 60.0)  # an approach ends after the check


def test_table2_segments_match_no_estimation_with_truth() -> None:
    wall = Wall.segmented([-10, 0, 10], (-1.75, 1.75))
    est = rmse(0.0, "svd", 0, wall=wall, localization="truth")
    none = rmse(0.0, "none", 0, wall=wall, localization="truth")
    assert est < 1.1 * none
    assert est < 0.06


def test_robust_keeps_its_accuracy_with_false_contacts() -> None:
    cfg = MissionConfig(false_contact_rate=0.1)
    seeds = range(3)
    clean = np.mean([rmse(10.0, "robust", s, localization="truth") for s in seeds])
    dirty = np.mean([rmse(10.0, "robust", s, localization="truth", config=cfg) for s in seeds])
    assert dirty < 1.2 * clean


def test_missed_and_false_contacts_are_counted() -> None:
    cfg = MissionConfig(false_contact_rate=0.2, missed_contact_rate=0.2)
    result = run_mission(
        DOTS[:40], wall=Wall.flat(), truth=truth(5.0), config=cfg, rng=np.random.default_rng(4)
    )
    assert result.false_contacts > 0 and result.missed_contacts > 0
    # a false contact paints nothing (it may also hit the unpainted far first point)
    assert 0 < np.isnan(result.errors_m).sum() <= result.false_contacts


def test_a_soft_slow_touch_is_missed_by_the_imu() -> None:
    rng = np.random.default_rng(0)
    assert ContactModel().detect(0.2, 1.0, rng)[0]
    _, delay, squeeze = ContactModel().detect(0.2, 1.0, rng)
    assert 0.0 < delay < 0.05 and 0.0 < squeeze < 0.01
    assert not ContactModel(imu_noise_g=0.0).detect(0.02, 1.0, rng)[0]


def test_same_seed_same_mission() -> None:
    a = rmse(10.0, "robust", 7, localization="onboard", order="shortest")
    b = rmse(10.0, "robust", 7, localization="onboard", order="shortest")
    assert a == b


def test_shortest_order_flies_less() -> None:
    kw = {"wall": Wall.flat(), "truth": truth(10.0), "localization": "truth"}
    paper = run_mission(DOTS, order="paper", rng=np.random.default_rng(0), **kw)  # type: ignore[arg-type]
    short = run_mission(DOTS, order="shortest", rng=np.random.default_rng(0), **kw)  # type: ignore[arg-type]
    assert short.flight_time_s < paper.flight_time_s
    assert short.transit_m < 0.5 * paper.transit_m


@pytest.mark.parametrize(
    ("dots", "match"),
    [
        (np.zeros((0, 2)), r"dots: got 0 dots, expected 1 to 10000"),
        (np.array([[0.0, np.nan]]), r"dots: got 1 NaN or infinite value\(s\)"),
        (np.array([[0.0, 1.0], [5.0, 1.0]]), r"dots: got 1 dot\(s\) outside the wall, .*x=5"),
        (np.array([[0.0, -0.5]]), r"dots: got 1 dot\(s\) outside the wall"),
        (np.zeros((3, 3)), r"dots: got shape \(3, 3\), expected \(N, 2\)"),
    ],
)
def test_bad_dots(dots: np.ndarray, match: str) -> None:
    with pytest.raises(InputError, match=match):
        run_mission(dots, wall=Wall.flat(), truth=truth(0.0), rng=np.random.default_rng(0))


def test_bad_options() -> None:
    kw = {"wall": Wall.flat(), "truth": truth(0.0), "rng": np.random.default_rng(0)}
    with pytest.raises(InputError, match=r"--estimator: got 'kalman', expected one of none"):
        run_mission(DOTS, estimator="kalman", **kw)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"--localization: got 'gps', expected 'onboard'"):
        run_mission(DOTS, localization="gps", **kw)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"false_contact_rate: got 1.5, expected a probability"):
        MissionConfig(false_contact_rate=1.5)
    with pytest.raises(InputError, match=r"noise_m: got -1, expected a number >= 0"):
        Localization(noise_m=-1.0)


@settings(max_examples=15, deadline=None)
@given(
    dots=hnp.arrays(
        np.float64,
        st.tuples(st.integers(1, 12), st.just(2)),
        elements=st.floats(-2.5, 2.5),
    ),
    angles=st.lists(st.sampled_from([-15.0, -5.0, 0.0, 5.0, 15.0]), min_size=1, max_size=3),
    gamma=st.floats(-20, 20),
    estimator=st.sampled_from(["none", "svd", "robust"]),
    seed=st.integers(0, 1000),
)
def test_random_dot_sets_and_walls_fly_to_the_end(
    dots: np.ndarray, angles: list[float], gamma: float, estimator: str, seed: int
) -> None:
    dots = dots.copy()
    dots[:, 1] = np.abs(dots[:, 1]) + 0.5  # heights on the wall
    wall = Wall.segmented(angles, (-2.5, 2.5))
    cfg = MissionConfig(false_contact_rate=0.1, missed_contact_rate=0.05)
    result = run_mission(
        dots, wall=wall, truth=truth(gamma), estimator=estimator, config=cfg,
        rng=np.random.default_rng(seed),
    )  # fmt: skip
    assert result.order.size == len(dots)
    ok = result.painted
    assert np.all(np.isfinite(result.errors_m[ok]))
    assert abs(result.estimate.gamma_deg) < 60.0
    assert result.flight_time_s > 0.0
