"""The shared argument checks of :mod:`skyquill.validation`."""

from __future__ import annotations

import numpy as np
import pytest

from skyquill.errors import InputError
from skyquill.validation import as_seed


def test_seed_accepts_non_negative_integers() -> None:
    assert as_seed("seed", 0) == 0
    assert as_seed("seed", np.int64(7)) == 7
    assert as_seed("seed", 2**64 - 1) == 2**64 - 1
    np.random.default_rng(as_seed("seed", 2**64 - 1))  # numpy accepts the largest one


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (-1, "seed: got -1, expected an integer >= 0"),
        (1.5, "seed: got 1.5, expected an integer >= 0"),
        (True, "seed: got True, expected an integer >= 0"),
        ("3", "seed: got '3', expected an integer >= 0"),
        (2**64, "seed: got 18446744073709551616, expected an integer from 0 to 2**64 - 1"),
    ],
)
def test_seed_refuses_with_a_named_message(value: object, message: str) -> None:
    with pytest.raises(InputError, match=f"^{message.replace('*', '[*]')}$"):
        as_seed("seed", value)


def test_known_keys_names_the_table_and_the_unknown_key() -> None:
    from skyquill.validation import known_keys

    assert known_keys({"a": 1}, "[t]", ("a", "b")) == {"a": 1}
    with pytest.raises(InputError, match=r"^\[t\]: got unknown key 'c', expected one of a, b$"):
        known_keys({"a": 1, "c": 2}, "[t]", ("a", "b"))
    with pytest.raises(InputError, match=r"^\[t\]: got list, expected a table$"):
        known_keys([1], "[t]", ("a",))


def test_largest_magnitude_checks_finite_as_as_array_does() -> None:
    from skyquill.validation import as_array, largest_magnitude

    assert largest_magnitude("x", np.array([[1.0, -3.0], [2.0, 0.5]])) == 3.0
    assert largest_magnitude("x", np.zeros((2, 0))) == 0.0  # no entries: no scale
    for bad in ([[np.nan, 0.0], [1.0, 2.0]], [[1.0, -np.inf], [np.inf, np.nan]]):
        with pytest.raises(InputError) as checked:
            as_array("x", bad)
        unchecked = as_array("x", bad, finite=False)  # converted, not checked
        with pytest.raises(InputError) as here:
            largest_magnitude("x", unchecked)
        assert str(here.value) == str(checked.value)
        assert str(here.value).startswith(f"x: got {np.sum(~np.isfinite(unchecked))} NaN or")
