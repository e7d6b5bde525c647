"""Tests for skyquill.limits: NormLimit (cone and inscribed polytopes) and VehicleLimits."""

from __future__ import annotations

import numpy as np
import pytest

from skyquill.errors import InputError
from skyquill.limits import BoxLimit, NormLimit, VehicleLimits


# ------------------------------------------------------------------ NormLimit validation
def test_norm_defaults_to_a_3d_cone() -> None:
    lim = NormLimit(1, 2.0)
    assert lim.is_cone
    assert lim.dim == 3
    assert lim.label == "speed norm (cone)"
    assert lim.inscribed_fraction == 1.0


@pytest.mark.parametrize(
    ("sides", "dim", "label"),
    [
        (16, 3, "jerk norm (16-gon globe)"),
        (8, 2, "jerk norm (8-gon)"),
        (5, 1, "jerk norm (interval)"),
    ],
)
def test_norm_polytope_labels(sides: int, dim: int, label: str) -> None:
    assert NormLimit(3, 1.0, sides, dim).label == label


@pytest.mark.parametrize("radius", [0.0, -1.0, np.inf])
def test_norm_radius_positive(radius: float) -> None:
    with pytest.raises(InputError, match=r"acceleration norm radius: got .*expected"):
        NormLimit(2, radius)


def test_norm_radius_not_a_number() -> None:
    with pytest.raises(InputError, match=r"speed norm radius: got .*, expected a number"):
        NormLimit(1, "fast")  # type: ignore[arg-type]


@pytest.mark.parametrize("sides", [2, 1025])
def test_norm_sides_range(sides: int) -> None:
    with pytest.raises(InputError, match=rf"sides: got {sides}"):
        NormLimit(1, 1.0, sides)


def test_norm_polytope_needs_at_most_three_axes() -> None:
    with pytest.raises(InputError, match=r"sides: got 8 for a 4-axis norm, expected None"):
        NormLimit(1, 1.0, 8, dim=4)
    assert NormLimit(1, 1.0, None, dim=4).dim == 4  # cones exist in any dimension


def test_norm_cone_has_no_halfspaces() -> None:
    with pytest.raises(InputError, match=r"speed norm \(cone\): got sides=None"):
        NormLimit(1, 1.0).halfspaces()


# ------------------------------------------------------------------ inscribed polytopes
def _extent(A: np.ndarray, b: np.ndarray, u: np.ndarray) -> np.ndarray:
    """How far the polytope ``A x <= b`` reaches along each unit direction ``u`` (K, d)."""
    Au = u @ A.T  # (K, m)
    with np.errstate(divide="ignore"):
        ratio = np.where(Au > 0, b / Au, np.inf)
    return np.asarray(ratio.min(axis=1))


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("sides", [3, 4, 8, 16, 33])
def test_polytope_is_inscribed(dim: int, sides: int) -> None:
    """Every direction reaches at most the radius (inside the ball) and at least the inradius."""
    radius = 2.5
    lim = NormLimit(2, radius, sides, dim)
    A, b = lim.halfspaces()
    np.testing.assert_allclose(np.linalg.norm(A, axis=1), 1.0, rtol=1e-12)
    u = np.random.default_rng(sides).standard_normal((20_000, dim))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    reach = _extent(A, b, u)
    assert reach.max() <= radius * (1 + 1e-12)
    assert reach.min() >= radius * lim.inscribed_fraction * (1 - 1e-12)
    assert np.all(b >= radius * lim.inscribed_fraction * (1 - 1e-12))


@pytest.mark.parametrize("sides", [4, 8, 16])
def test_globe_vertices_on_sphere_and_equator_is_the_polygon(sides: int) -> None:
    """The globe touches the sphere at the poles and at the equator's m-gon vertices."""
    A, b = NormLimit(1, 1.0, sides, 3).halfspaces()
    angles = 2 * np.pi * np.arange(sides) / sides
    touch = np.vstack(
        [np.column_stack([np.cos(angles), np.sin(angles), np.zeros(sides)]), np.eye(3)[[2]]]
    )
    reach = _extent(A, b, touch)
    np.testing.assert_allclose(reach, 1.0, rtol=1e-10)
    polygon = NormLimit(1, 1.0, sides, 2)
    mid = np.array([[np.cos(np.pi / sides), np.sin(np.pi / sides), 0.0]])
    np.testing.assert_allclose(_extent(A, b, mid), polygon.inscribed_fraction, rtol=1e-10)


def test_inscribed_fraction_grows_with_sides() -> None:
    fractions = [NormLimit(1, 1.0, m, 3).inscribed_fraction for m in (4, 8, 16, 32)]
    assert np.all(np.diff(fractions) > 0)
    assert NormLimit(1, 1.0, 8, 2).inscribed_fraction == pytest.approx(np.cos(np.pi / 8))
    assert NormLimit(1, 1.0, 7, 1).inscribed_fraction == 1.0


def test_norm_relative_excess_hand_values() -> None:
    lim = NormLimit(1, 2.0)
    values = np.array([[1.0, 1.0, 1.0], [0.0, 2.4, 0.0], [0.0, 0.0, -1.0]])
    peak, excess = lim.relative_excess(values)
    assert peak == pytest.approx(2.4)
    assert excess == pytest.approx(0.2)
    assert lim.relative_excess(np.array([[1.2, 1.6, 0.0]])) == pytest.approx((2.0, 0.0))
    assert lim.relative_excess(np.zeros((0, 3))) == (0.0, 0.0)


# ------------------------------------------------------------------ VehicleLimits
def test_vehicle_limits_builds_norms_then_boxes() -> None:
    vl = VehicleLimits(vmax=2.0, amax=3, jmax=None, vmax_axis=1.5, jmax_axis=9.0)
    limits = vl.derivative_limits(3)
    assert [type(lim).__name__ for lim in limits] == [
        "NormLimit",
        "BoxLimit",
        "NormLimit",
        "BoxLimit",
    ]
    assert [lim.order for lim in limits] == [1, 1, 2, 3]
    norm = limits[0]
    assert isinstance(norm, NormLimit) and norm.is_cone and norm.radius == 2.0
    box = limits[1]
    assert isinstance(box, BoxLimit)
    np.testing.assert_array_equal(box.upper, [1.5, 1.5, 1.5])
    assert isinstance(vl.amax, float)


def test_vehicle_limits_polytope_sides_and_dim() -> None:
    limits = VehicleLimits(vmax=1.0, amax=2.0).derivative_limits(2, sides=16)
    assert all(isinstance(lim, NormLimit) and lim.sides == 16 and lim.dim == 2 for lim in limits)
    assert [lim.label for lim in limits] == ["speed norm (16-gon)", "acceleration norm (16-gon)"]


def test_vehicle_limits_norm_lookup() -> None:
    vl = VehicleLimits(vmax=1.0, jmax=5.0)
    assert (vl.norm(1), vl.norm(2), vl.norm(3), vl.norm(4)) == (1.0, None, 5.0, None)
    with pytest.raises(InputError, match=r"order: got 0"):
        vl.norm(0)


def test_vehicle_limits_empty() -> None:
    assert VehicleLimits().derivative_limits(3) == ()


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"vmax": 0.0}, r"vmax: got 0, expected a number > 0"),
        ({"amax": -2.0}, r"amax: got -2, expected a number > 0"),
        ({"jmax": float("nan")}, r"jmax: got nan, expected a finite number"),
        ({"vmax_axis": "1"}, r"vmax_axis: got .*, expected a number"),
        ({"jmax_axis": True}, r"jmax_axis: got .*, expected a number"),
    ],
)
def test_vehicle_limits_errors(kwargs: dict[str, object], pattern: str) -> None:
    with pytest.raises(InputError, match=pattern):
        VehicleLimits(**kwargs)  # type: ignore[arg-type]


def test_vehicle_limits_bad_dim_and_sides() -> None:
    vl = VehicleLimits(vmax=1.0)
    with pytest.raises(InputError, match=r"dim: got 4"):
        vl.derivative_limits(4)
    with pytest.raises(InputError, match=r"sides: got 2"):
        vl.derivative_limits(3, sides=2)


def test_vehicle_limits_as_dict_names_units_and_meaning() -> None:
    d = VehicleLimits(vmax=2.0, amax_axis=4.0).as_dict()
    assert list(d) == ["vmax", "amax", "jmax", "vmax_axis", "amax_axis", "jmax_axis"]
    assert d["vmax"] == {
        "value": 2.0,
        "unit": "m/s",
        "meaning": "speed: Euclidean norm of the velocity",
    }
    assert d["amax"] == {
        "value": None,
        "unit": "m/s^2",
        "meaning": "Euclidean norm of the acceleration",
    }
    amax_axis = d["amax_axis"]
    assert isinstance(amax_axis, dict) and amax_axis["value"] == 4.0
    assert "per-axis" in amax_axis["meaning"]


def test_vehicle_limits_is_frozen() -> None:
    vl = VehicleLimits(vmax=1.0)
    with pytest.raises(AttributeError):
        vl.vmax = 2.0  # type: ignore[misc]
