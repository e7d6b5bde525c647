"""Concave regions, step 2: the order in which the convex parts are visited."""

from __future__ import annotations

import itertools

import pytest
import shapely
from concave_regions import CONCAVE, L_SHAPE, U_SHAPE, WIDTH
from shapely.geometry import Polygon

from skyquill.coverage.part_order import order_parts
from skyquill.coverage.partition import convex_parts
from skyquill.errors import InputError


def _shares_edge(a: Polygon, b: Polygon) -> bool:
    return bool(shapely.intersection(a.boundary, b.boundary).length > 1e-9)


@pytest.mark.parametrize("name", ["L", "U", "field"])
def test_order_visits_adjacent_parts(name: str) -> None:
    parts = convex_parts(CONCAVE[name], WIDTH)
    ordered = order_parts(parts[::-1])
    assert sorted(p.wkt for p in ordered) == sorted(p.wkt for p in parts)
    assert all(_shares_edge(a, b) for a, b in itertools.pairwise(ordered))


def test_order_honours_the_start() -> None:
    parts = convex_parts(U_SHAPE, WIDTH)
    for k in range(len(parts)):
        assert order_parts(parts, start=k)[0].equals(parts[k])


def test_bad_inputs_are_named() -> None:
    with pytest.raises(InputError, match="parts"):
        order_parts([])
    with pytest.raises(InputError, match="start"):
        order_parts(convex_parts(L_SHAPE, WIDTH), start=2)
