"""Tests for skyquill.limits: validation, the inscribed m-gon prism, relative excess."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.limits import BoxLimit, CylinderLimit, order_name, vehicle_limits

FloatArray = NDArray[np.float64]


# ------------------------------------------------------------------ BoxLimit validation
def test_box_valid_and_halfspaces() -> None:
    lim = BoxLimit(2, np.array([-1.0, -2.0, -3.0]), np.array([1.0, 0.5, 3.0]))
    assert lim.dim == 3
    assert lim.label == "acceleration box"
    A, b = lim.halfspaces()
    assert A.shape == (6, 3)
    assert b.shape == (6,)
    inside = np.array([0.9, -1.9, 2.9])
    assert np.all(A @ inside <= b)
    for v in ([1.1, 0, 0], [0, 0.6, 0], [0, -2.1, 0], [0, 0, -3.5]):
        assert np.any(A @ np.array(v) > b)


@pytest.mark.parametrize(
    ("lower", "upper", "i"),
    [
        ([1.0, -1.0], [0.0, 1.0], 0),
        ([-1.0, 1.0], [1.0, 1.0], 1),  # equal bounds are rejected too
    ],
)
def test_box_lower_not_below_upper(lower: list[float], upper: list[float], i: int) -> None:
    pattern = (
        rf"speed limit: got lower\[{i}\] = {lower[i]:g} >= upper\[{i}\] = {upper[i]:g}, "
        r"expected lower < upper"
    )
    with pytest.raises(InputError, match=pattern):
        BoxLimit(1, np.array(lower), np.array(upper))


def test_box_shape_mismatch() -> None:
    with pytest.raises(
        InputError,
        match=r"jerk lower: got an array of shape \(3,\), "
        r"expected shape \(2,\)",
    ):
        BoxLimit(3, np.zeros(3) - 1, np.ones(2))


def test_box_non_finite() -> None:
    with pytest.raises(InputError, match=r"speed upper: got 1 NaN or infinite"):
        BoxLimit(1, np.array([-1.0, -1.0]), np.array([1.0, np.inf]))


@pytest.mark.parametrize("order", [0, 8, -1])
def test_box_bad_order(order: int) -> None:
    with pytest.raises(InputError, match=rf"order: got {order}, expected an integer from 1 to 7"):
        BoxLimit(order, np.array([-1.0]), np.array([1.0]))


@pytest.mark.parametrize("bound", [0.0, -2.0])
def test_symmetric_box_needs_positive_bound(bound: float) -> None:
    with pytest.raises(
        InputError,
        match=rf"acceleration limit: got {bound:g}, "
        r"expected a number > 0",
    ):
        BoxLimit.symmetric(2, bound, 3)


def test_symmetric_box() -> None:
    lim = BoxLimit.symmetric(3, 4.0, 2)
    np.testing.assert_array_equal(lim.lower, [-4.0, -4.0])
    np.testing.assert_array_equal(lim.upper, [4.0, 4.0])


def test_order_names() -> None:
    assert [order_name(n) for n in (1, 2, 3, 4, 5)] == [
        "speed",
        "acceleration",
        "jerk",
        "snap",
        "derivative 5",
    ]


# ------------------------------------------------------------------ CylinderLimit validation
@pytest.mark.parametrize("radius", [0.0, -1.5])
def test_cylinder_radius_positive(radius: float) -> None:
    with pytest.raises(
        InputError,
        match=rf"acceleration radius: got {radius:g}, "
        r"expected a number > 0",
    ):
        CylinderLimit(2, radius)


@pytest.mark.parametrize(("z_lower", "z_upper"), [(-1.0, None), (None, 2.0)])
def test_cylinder_z_bounds_one_sided(z_lower: float | None, z_upper: float | None) -> None:
    with pytest.raises(
        InputError,
        match=r"jerk vertical bounds: got z_lower=.*, z_upper=.*, "
        r"expected both or neither",
    ):
        CylinderLimit(3, 1.0, z_lower=z_lower, z_upper=z_upper)


@pytest.mark.parametrize(("z_lower", "z_upper"), [(1.0, 1.0), (2.0, -2.0)])
def test_cylinder_z_bounds_order(z_lower: float, z_upper: float) -> None:
    with pytest.raises(
        InputError,
        match=rf"speed vertical bounds: got z_lower={z_lower:g} >= "
        rf"z_upper={z_upper:g}, expected z_lower < z_upper",
    ):
        CylinderLimit(1, 1.0, z_lower=z_lower, z_upper=z_upper)


@pytest.mark.parametrize("sides", [2, 0, -3])
def test_cylinder_sides(sides: int) -> None:
    with pytest.raises(InputError, match=rf"sides: got {sides}, expected an integer from 3"):
        CylinderLimit(2, 1.0, sides=sides)


def test_cylinder_non_finite_z() -> None:
    with pytest.raises(InputError, match=r"z_lower: got nan, expected a finite number"):
        CylinderLimit(2, 1.0, z_lower=float("nan"), z_upper=1.0)


def test_cylinder_dim_and_label() -> None:
    assert CylinderLimit(2, 1.0).dim == 2
    lim = CylinderLimit(3, 1.0, z_lower=-2.0, z_upper=1.0, sides=6)
    assert lim.dim == 3
    assert lim.label == "jerk cylinder (6-gon)"
    A, b = lim.halfspaces()
    assert A.shape == (8, 3)
    assert b.shape == (8,)
    # Vertical rows.
    assert np.all(A @ np.array([0.0, 0.0, 0.99]) <= b)
    assert np.any(A @ np.array([0.0, 0.0, 1.01]) > b)
    assert np.all(A @ np.array([0.0, 0.0, -1.99]) <= b)
    assert np.any(A @ np.array([0.0, 0.0, -2.01]) > b)


# ------------------------------------------------------------------ the inscribed polygon
def _vertices(A: FloatArray, b: FloatArray) -> FloatArray:
    """Intersections of consecutive edge lines of a 2-D polygon {x : A x <= b}."""
    m = A.shape[0]
    return np.array([np.linalg.solve(A[[j - 1, j]], b[[j - 1, j]]) for j in range(m)])


@pytest.mark.parametrize("sides", [3, 4, 6, 8, 13, 64])
@pytest.mark.parametrize("radius", [0.7, 5.0])
def test_inscribed_polygon(sides: int, radius: float) -> None:
    A, b = CylinderLimit(2, radius, sides=sides).halfspaces()
    assert A.shape == (sides, 2)
    np.testing.assert_allclose(np.linalg.norm(A, axis=1), 1.0, rtol=1e-15)
    V = _vertices(A, b)
    # Every vertex lies on the circle.
    np.testing.assert_allclose(np.linalg.norm(V, axis=1), radius, rtol=1e-12)
    # ... at angles 2 pi j / m.
    angles = np.arctan2(V[:, 1], V[:, 0])
    expected = 2 * np.pi * np.arange(sides) / sides
    # Circular distance from each expected angle to the nearest vertex: one vertex each.
    gap = np.abs(np.angle(np.exp(1j * (expected[:, None] - angles[None, :]))))
    np.testing.assert_allclose(gap.min(axis=1), 0.0, atol=1e-12)
    assert sorted(np.argmin(gap, axis=1).tolist()) == list(range(sides))
    # Every vertex satisfies all constraints (two of them with equality).
    slack = b[None, :] - V @ A.T
    assert slack.min() >= -1e-12 * radius
    assert np.all(np.sum(np.abs(slack) <= 1e-12 * radius, axis=1) == 2)
    # The whole boundary (sampled) is inside the disk and inside the polytope.
    u = np.linspace(0.0, 1.0, 101)
    boundary = np.concatenate(
        [(1 - u)[:, None] * V[j - 1] + u[:, None] * V[j] for j in range(sides)]
    )
    assert float(np.linalg.norm(boundary, axis=1).max()) <= radius * (1 + 1e-12)
    assert float((boundary @ A.T - b).max()) <= 1e-12 * radius
    # Inscribed, not circumscribed: the circle between two vertices is outside.
    mid = radius * np.array([np.cos(np.pi / sides), np.sin(np.pi / sides)])
    assert float((A @ mid - b).max()) > 0
    # ... and the disk of radius r cos(pi/m) is inside.
    th = np.linspace(0, 2 * np.pi, 721)
    inner = radius * np.cos(np.pi / sides) * (1 - 1e-12) * np.c_[np.cos(th), np.sin(th)]
    assert float((inner @ A.T - b).max()) <= 0


def test_polygon_inside_disk_for_random_points() -> None:
    """Any point meeting the polytope meets the cylinder (sufficiency of the constraint)."""
    rng = np.random.default_rng(0)
    lim = CylinderLimit(2, 2.0, z_lower=-1.0, z_upper=3.0, sides=8)
    A, b = lim.halfspaces()
    pts = rng.uniform(-3.0, 4.0, size=(20000, 3))
    ok = np.all(pts @ A.T <= b, axis=1)
    assert ok.sum() > 1000
    assert np.all(np.hypot(pts[ok, 0], pts[ok, 1]) <= 2.0)
    assert np.all((pts[ok, 2] >= -1.0) & (pts[ok, 2] <= 3.0))
    assert lim.relative_excess(pts[ok])[1] == 0.0


# ------------------------------------------------------------------ relative excess
def test_box_relative_excess_hand_values() -> None:
    lim = BoxLimit(1, np.array([-1.0, -2.0]), np.array([2.0, 1.0]))
    # Axis 0 over by 1 (of 2): 0.5; axis 1 under by 2 (of |-2|): 1.0.
    value, rel = lim.relative_excess(np.array([[3.0, 0.0], [0.0, -4.0]]))
    assert value == 4.0
    assert rel == pytest.approx(1.0)
    value, rel = lim.relative_excess(np.array([[3.0, 0.0], [0.0, -1.0]]))
    assert value == 3.0
    assert rel == pytest.approx(0.5)
    value, rel = lim.relative_excess(np.array([[1.9, -1.9], [-0.9, 0.9]]))
    assert value == pytest.approx(1.9)
    assert rel == 0.0
    # Exactly on the bound is no excess.
    assert lim.relative_excess(np.array([[2.0, -2.0], [-1.0, 1.0]]))[1] == 0.0


def test_box_relative_excess_empty_values() -> None:
    lim = BoxLimit.symmetric(1, 1.0, 2)
    assert lim.relative_excess(np.zeros((0, 2))) == (0.0, 0.0)


def test_box_relative_excess_zero_bound_is_absolute() -> None:
    lim = BoxLimit(1, np.array([-1.0]), np.array([0.0]))
    assert lim.relative_excess(np.array([[0.5]]))[1] == pytest.approx(0.5)


def test_cylinder_relative_excess_hand_values() -> None:
    lim2 = CylinderLimit(2, 2.0)
    value, rel = lim2.relative_excess(np.array([[3.0, 4.0], [0.0, 1.0]]))
    assert value == pytest.approx(5.0)
    assert rel == pytest.approx(1.5)  # (5 - 2) / 2
    # Inside the cylinder but outside the inscribed polygon: no excess (the check is the cylinder).
    on_circle = 2.0 * np.array([[np.cos(np.pi / 8), np.sin(np.pi / 8)]])
    assert lim2.relative_excess(on_circle)[1] == 0.0

    lim3 = CylinderLimit(2, 2.0, z_lower=-1.0, z_upper=2.0)
    assert lim3.relative_excess(np.array([[0.0, 0.0, 3.0]]))[1] == pytest.approx(0.5)
    assert lim3.relative_excess(np.array([[0.0, 0.0, -1.5]]))[1] == pytest.approx(0.5)
    assert lim3.relative_excess(np.array([[0.0, 0.0, -3.0]]))[1] == pytest.approx(2.0)
    value, rel = lim3.relative_excess(np.array([[1.0, 1.0, 1.0], [-1.2, 0.0, -0.5]]))
    assert value == pytest.approx(np.sqrt(2.0))
    assert rel == 0.0
    # The largest of horizontal and vertical excess.
    assert lim3.relative_excess(np.array([[2.4, 0.0, 0.0], [0.0, 0.0, 2.2]]))[1] == (
        pytest.approx(0.2)
    )


# ------------------------------------------------------------------ vehicle_limits
def test_vehicle_limits_per_axis() -> None:
    lims = vehicle_limits(3, vmax=2.0, amax=3.0, jmax=10.0)
    assert [type(x) for x in lims] == [BoxLimit] * 3
    assert [x.order for x in lims] == [1, 2, 3]
    for lim, bound in zip(lims, (2.0, 3.0, 10.0), strict=True):
        assert isinstance(lim, BoxLimit)
        assert lim.dim == 3
        np.testing.assert_array_equal(lim.upper, [bound] * 3)
        np.testing.assert_array_equal(lim.lower, [-bound] * 3)


@pytest.mark.parametrize("dim", [2, 3])
def test_vehicle_limits_coupled(dim: int) -> None:
    lims = vehicle_limits(dim, amax=3.0, jmax=10.0, coupled_sides=6)
    assert [type(x) for x in lims] == [CylinderLimit] * 2
    assert [x.order for x in lims] == [2, 3]
    for lim, bound in zip(lims, (3.0, 10.0), strict=True):
        assert isinstance(lim, CylinderLimit)
        assert lim.dim == dim
        assert lim.radius == bound
        assert lim.sides == 6
        if dim == 3:
            assert (lim.z_lower, lim.z_upper) == (-bound, bound)
        else:
            assert lim.z_lower is None
            assert lim.z_upper is None
        A, _ = lim.halfspaces()
        assert A.shape == (6 + (2 if dim == 3 else 0), dim)


def test_vehicle_limits_none_leaves_order_free() -> None:
    assert vehicle_limits(2) == ()
    assert [x.order for x in vehicle_limits(2, jmax=1.0)] == [3]


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"dim": 3, "vmax": -1.0}, r"speed limit: got -1, expected a number > 0"),
        ({"dim": 3, "amax": 0.0}, r"acceleration limit: got 0, expected a number > 0"),
        ({"dim": 2, "jmax": float("nan")}, r"jerk limit: got nan, expected a finite number"),
        ({"dim": 4, "vmax": 1.0}, r"dim: got 4, expected an integer from 2 to 3"),
        ({"dim": 1, "vmax": 1.0}, r"dim: got 1, expected an integer from 2 to 3"),
        ({"dim": 3, "vmax": 1.0, "coupled_sides": 2}, r"sides: got 2, expected an integer from 3"),
    ],
)
def test_vehicle_limits_errors(kwargs: dict[str, float], pattern: str) -> None:
    with pytest.raises(InputError, match=pattern):
        vehicle_limits(**kwargs)  # type: ignore[arg-type]
