"""Argument checks shared by every entry point.

Each helper either returns a clean ``float64`` array / number or raises
:class:`~skyquill.errors.InputError` whose message names the argument, says
what was received and what was expected. Nothing is clipped or repaired.
"""

from __future__ import annotations

import math
from typing import Any, NoReturn

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InputError

FloatArray = NDArray[np.float64]


def _describe(value: Any) -> str:
    if isinstance(value, np.ndarray) and value.ndim > 0:
        return f"an array of shape {value.shape} and dtype {value.dtype}"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def as_array(
    name: str,
    value: Any,
    *,
    ndim: int | None = None,
    shape: tuple[int | None, ...] | None = None,
    max_abs: float | None = None,
    finite: bool = True,
) -> FloatArray:
    """Convert ``value`` to a finite float64 array and check its rank and shape.

    ``shape`` entries of ``None`` match any length; ``max_abs`` bounds every
    entry's magnitude (coordinates beyond it are almost surely in the wrong unit,
    and would overflow squared distances). Without ``finite`` the entries are not
    checked finite here: the caller checks them with :func:`largest_magnitude`.
    """
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError, OverflowError, UnicodeError) as exc:
        raise InputError(
            f"{name}: got {_describe(value)}, expected a rectangular array of real numbers"
        ) from exc
    if raw.dtype.kind not in "iuf":
        what = "complex numbers" if raw.dtype.kind == "c" else f"values of type {raw.dtype}"
        raise InputError(f"{name}: got {what}, expected real numbers")
    arr = raw.astype(float)
    want_ndim = len(shape) if shape is not None else ndim
    if want_ndim is not None and arr.ndim != want_ndim:
        raise InputError(
            f"{name}: got an array of shape {arr.shape}, expected {want_ndim} dimension(s)"
            + (f" with shape {_shape_text(shape)}" if shape is not None else "")
        )
    if shape is not None and any(
        w is not None and w != a for w, a in zip(shape, arr.shape, strict=True)
    ):
        raise InputError(
            f"{name}: got an array of shape {arr.shape}, expected shape {_shape_text(shape)}"
        )
    # (The ufunc's reduction: numpy.all and the method .all() wrap it in Python.)
    if finite and not np.logical_and.reduce(np.isfinite(arr), axis=None):
        _refuse_non_finite(name, arr)
    if max_abs is not None and arr.size and np.abs(arr).max() > max_abs:
        raise InputError(
            f"{name}: got a value of magnitude {np.abs(arr).max():.3g}, expected at most "
            f"{max_abs:g}"
        )
    return arr


def largest_magnitude(name: str, arr: FloatArray) -> float:
    """The largest magnitude among the entries of ``arr`` (0 if it has none), the entries
    checked finite as :func:`as_array` checks them, with the same refusal.

    For callers that need the array's scale anyway: after ``as_array(..., finite=False)``,
    one reduction does both (the second pass cost about 1.4 us, 7 % of
    :func:`~skyquill.optimize.legs.stop_and_go` on a chain of ten legs).

    Raises
    ------
    InputError
        ``arr`` holds a NaN or an infinity (the maximum is NaN or infinite then).
    """
    largest = float(np.maximum.reduce(abs(arr), axis=None, initial=0.0))
    if not largest < math.inf:
        _refuse_non_finite(name, arr)
    return largest


def _refuse_non_finite(name: str, arr: FloatArray) -> NoReturn:
    """Refuse ``arr``, which holds a NaN or an infinity, counting them."""
    bad = int(np.count_nonzero(~np.isfinite(arr)))
    raise InputError(f"{name}: got {bad} NaN or infinite value(s), expected finite numbers")


def _shape_text(shape: tuple[int | None, ...]) -> str:
    parts = ["any" if s is None else str(s) for s in shape]
    return "(" + ", ".join(parts) + ("," if len(parts) == 1 else "") + ")"


def as_float(name: str, value: Any, *, positive: bool = False, nonneg: bool = False) -> float:
    """A finite float, optionally required ``> 0`` or ``>= 0``."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise InputError(f"{name}: got {_describe(value)}, expected a number")
    try:
        x = float(value)
    except OverflowError:
        raise InputError(
            f"{name}: got an integer too large for a float, expected a number"
        ) from None
    if not np.isfinite(x):
        raise InputError(f"{name}: got {x}, expected a finite number")
    if positive and x <= 0.0:
        raise InputError(f"{name}: got {x:g}, expected a number > 0")
    if nonneg and x < 0.0:
        raise InputError(f"{name}: got {x:g}, expected a number >= 0")
    return x


def as_int(name: str, value: Any, *, low: int, high: int | None = None) -> int:
    """An integer in ``[low, high]``."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise InputError(f"{name}: got {_describe(value)}, expected an integer")
    i = int(value)
    if i < low or (high is not None and i > high):
        rng = f"from {low} to {high}" if high is not None else f">= {low}"
        raise InputError(f"{name}: got {i}, expected an integer {rng}")
    return i


def strictly_increasing(name: str, times: FloatArray) -> None:
    """Raise unless the 1-D array ``times`` is strictly increasing."""
    steps = np.diff(times)
    if np.any(steps <= 0.0):
        i = int(np.argmax(steps <= 0.0))
        raise InputError(
            f"{name}: got {name}[{i}] = {times[i]:g} followed by {times[i + 1]:g}, "
            "expected strictly increasing values"
        )


def per_axis(name: str, value: Any, dim: int) -> FloatArray:
    """A positive finite limit per axis, (dim,), from a scalar or a (dim,) sequence."""
    arr = as_array(name, value)
    if arr.ndim == 0:
        arr = np.full(dim, float(arr))
    if arr.shape != (dim,):
        raise InputError(f"{name}: got shape {arr.shape}, expected a number or shape ({dim},)")
    if np.any(arr <= 0.0):
        raise InputError(f"{name}: got {arr.tolist()}, expected positive limits")
    return arr


#: Largest seed accepted: numpy's SeedSequence takes any non-negative integer,
#: but a seed that does not fit 64 bits is almost surely a typo or overflow.
MAX_SEED = 2**64 - 1


def as_seed(name: str, value: Any) -> int:
    """A seed for :func:`numpy.random.default_rng`: an integer in ``[0, 2**64 - 1]``.

    ``default_rng(-1)`` raises a bare ``ValueError``; this names the argument first.
    """
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise InputError(f"{name}: got {_describe(value)}, expected an integer >= 0")
    seed = int(value)
    if seed < 0:
        raise InputError(f"{name}: got {seed}, expected an integer >= 0")
    if seed > MAX_SEED:
        raise InputError(f"{name}: got {seed}, expected an integer from 0 to 2**64 - 1")
    return seed


def known_keys(table: Any, where: str, keys: tuple[str, ...]) -> dict[str, Any]:
    """``table`` (a parsed TOML or JSON table) when every key of it is in ``keys``.

    Raises
    ------
    InputError
        ``table`` is not a table, or it holds a key not in ``keys`` (named with
        ``where``, the table's place in the file, and the keys expected): a typo in
        an optional key would otherwise be ignored silently.
    """
    if not isinstance(table, dict):
        raise InputError(f"{where}: got {type(table).__name__}, expected a table")
    for key in table:
        if key not in keys:
            raise InputError(f"{where}: got unknown key {key!r}, expected one of {', '.join(keys)}")
    return table
