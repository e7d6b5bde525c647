"""Which legs of a painting flight end at the wall, in memory linear in legs and marks."""

from __future__ import annotations

import tracemalloc
from types import SimpleNamespace
from typing import Any

import numpy as np

from skyquill.painting.flight import _touched


def _result(path: np.ndarray, contacts: np.ndarray, painted: np.ndarray) -> Any:
    return SimpleNamespace(path_w=path, contacts_w=contacts, painted_w=painted)


def test_a_leg_is_touched_when_it_ends_on_a_mark() -> None:
    rng = np.random.default_rng(3)
    path = rng.uniform(-4, 4, size=(200, 3))
    contacts, painted = path[1:40:3].copy(), path[50:120:2].copy()
    painted[::5] = np.nan  # dots not painted
    result = _result(path, contacts, painted)
    marks = np.vstack([contacts, painted[np.isfinite(painted[:, 0])]])
    brute = [bool(np.min(np.linalg.norm(marks - end, axis=1)) < 1e-9) for end in path[1:]]
    assert _touched(result) == brute
    assert _touched(_result(path, np.empty((0, 3)), np.empty((0, 3)))) == [False] * 199


def test_the_ceiling_of_dots_is_found_in_linear_memory() -> None:
    """30,000 legs and 20,000 marks: the table of every pair took 13.5 GiB."""
    rng = np.random.default_rng(4)
    marks = rng.uniform(-4, 4, size=(20_000, 3))
    path = np.vstack([marks, rng.uniform(-4, 4, size=(10_001, 3))])
    tracemalloc.start()
    try:
        touched = _touched(_result(path, marks[:10_000], marks[10_000:]))
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert sum(touched) == 19_999  # every mark but the path's start
    assert peak < 64 * 2**20
