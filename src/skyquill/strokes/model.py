"""The :class:`Strokes` container every stroke loader returns."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.validation import as_array, as_float

FloatArray = NDArray[np.float64]

#: Coordinates beyond this magnitude are almost surely in the wrong unit, and
#: squared distances of them would overflow in the geometry stages.
MAX_COORDINATE = 1e12
#: Most strokes a file reader (stroke JSON, SVG) accepts: a page of handwriting
#: has a few hundred; more is a drawing to be rasterised, not flown.
MAX_STROKES = 2_000
#: Most points, over all strokes, a file reader accepts (a 200 Hz tablet over
#: eight minutes of drawing); a larger drawing is refused before planning starts.
MAX_POINTS = 100_000


def _frozen(arr: FloatArray) -> FloatArray:
    out = np.array(arr, dtype=np.float64, copy=True)
    out.flags.writeable = False
    return out


@dataclass(frozen=True, eq=False)
class Strokes:
    """Ordered strokes, each a polyline in the plane, y up, in the source's units.

    Parameters
    ----------
    paths
        One ``(K_i, 2)`` array per stroke, in drawing order; each row is a point
        ``(x, y)`` with y up, in the units of the source (font units, SVG user
        units, metres after :meth:`scaled`, ...). Anything array-like is accepted
        and stored as read-only ``float64`` arrays.
    times
        Optional per-point timestamps (a tablet's), one ``(K_i,)`` array per
        stroke, in seconds (or the source's time unit); strictly increasing
        within each stroke and from one stroke to the next.
    source
        Where the strokes came from, for messages and plots (for example
        ``"text 'Hi' (futural)"``, ``"hanzi 永"``, ``"drawing.svg"``).
    box
        Optional ``(2, 2)`` layout box ``[[x_lo, y_lo], [x_hi, y_hi]]``, source
        units: the area the drawing is laid out in (the character cells of a
        line shared between drones, the whole drawing of one SVG layer).
        :meth:`bounds` and :meth:`scaled` then fit this box, grown to every
        point, instead of the ink alone, so that parts laid out together keep
        one scale and their places.

    Raises
    ------
    InputError
        If there is no stroke, a stroke has fewer than 2 points, a NaN or
        infinite coordinate, coordinates of magnitude above ``1e12``, or all its
        points equal; or if ``times`` does not match ``paths`` in lengths or is
        not strictly increasing; or if ``box`` is not a finite ``(2, 2)`` array
        with ``x_lo <= x_hi`` and ``y_lo <= y_hi``.
    """

    paths: tuple[FloatArray, ...]
    times: tuple[FloatArray, ...] | None = None
    source: str = ""
    box: FloatArray | None = None

    def __post_init__(self) -> None:
        label = f"strokes from {self.source}" if self.source else "strokes"
        paths = _check_paths(label, self.paths)
        object.__setattr__(self, "paths", paths)
        if self.times is not None:
            object.__setattr__(self, "times", _check_times(label, self.times, paths))
        if not isinstance(self.source, str):
            raise InputError(f"source: got {type(self.source).__name__}, expected a str")
        if self.box is not None:
            object.__setattr__(self, "box", _check_box(label, self.box))

    @property
    def n_points(self) -> int:
        """Total number of points over all strokes."""
        return sum(p.shape[0] for p in self.paths)

    @property
    def n_strokes(self) -> int:
        """Number of strokes."""
        return len(self.paths)

    def bounds(self) -> tuple[FloatArray, FloatArray]:
        """The drawing's extent: the bounding box of all points, grown to ``box``.

        Returns
        -------
        lo, hi
            ``(2,)`` arrays: the smallest and largest ``(x, y)``, source units.
        """
        stacked = np.concatenate(self.paths, axis=0)
        if self.box is not None:
            stacked = np.concatenate([stacked, self.box], axis=0)
        return stacked.min(axis=0), stacked.max(axis=0)

    def scaled(self, size: float) -> Strokes:
        """Uniformly scale and shift so the drawing fits a ``size`` square.

        Parameters
        ----------
        size
            Length of the larger side of the bounding box afterwards, m (> 0).

        Returns
        -------
        Strokes
            The same strokes with the extent's (:meth:`bounds`) bottom-left
            corner at ``(0, 0)`` and its larger side equal to ``size``; the
            aspect ratio, the times and the box (moved and scaled alike) are
            kept.

        Raises
        ------
        InputError
            If ``size`` is not a finite number > 0, or the drawing is so small
            that the scale factor overflows.
        """
        size = as_float("size", size, positive=True)
        lo, hi = self.bounds()
        extent = float(np.max(hi - lo))
        with np.errstate(over="ignore", divide="ignore"):
            factor = size / extent
        if not np.isfinite(factor):
            raise InputError(
                f"size: scaling a drawing of extent {extent:g} to {size:g} overflows; "
                "expected a drawing of non-negligible extent"
            )
        paths = tuple((p - lo) * factor for p in self.paths)
        box = None if self.box is None else (self.box - lo) * factor
        return Strokes(paths=paths, times=self.times, source=self.source, box=box)


def _check_box(label: str, raw: Any) -> FloatArray:
    box = as_array(f"{label}: box", raw, shape=(2, 2), max_abs=MAX_COORDINATE)
    if np.any(box[0] > box[1]):
        raise InputError(
            f"{label}: box: got lower corner ({box[0, 0]:g}, {box[0, 1]:g}) above or right of "
            f"upper corner ({box[1, 0]:g}, {box[1, 1]:g}), expected [[x_lo, y_lo], [x_hi, y_hi]]"
        )
    return _frozen(box)


def _check_paths(label: str, paths: Any) -> tuple[FloatArray, ...]:
    if isinstance(paths, np.ndarray) and paths.ndim == 3:
        paths = list(paths)
    if not isinstance(paths, Sequence) or isinstance(paths, str | bytes):
        raise InputError(
            f"{label}: paths: got {type(paths).__name__}, expected a sequence of (K, 2) arrays"
        )
    if len(paths) == 0:
        raise InputError(f"{label}: paths: got an empty list of strokes, expected at least one")
    out: list[FloatArray] = []
    for i, raw in enumerate(paths):
        name = f"{label}: stroke {i}"
        arr = as_array(name, raw, shape=(None, 2), max_abs=MAX_COORDINATE)
        if arr.shape[0] < 2:
            raise InputError(f"{name}: got {arr.shape[0]} point(s), expected at least 2")
        if np.all(arr == arr[0]):
            raise InputError(
                f"{name}: got {arr.shape[0]} points all equal to "
                f"({arr[0, 0]:g}, {arr[0, 1]:g}), expected a stroke of non-zero extent"
            )
        out.append(_frozen(arr))
    return tuple(out)


def _check_times(label: str, times: Any, paths: tuple[FloatArray, ...]) -> tuple[FloatArray, ...]:
    if not isinstance(times, Sequence) or isinstance(times, str | bytes):
        raise InputError(
            f"{label}: times: got {type(times).__name__}, expected a sequence of (K_i,) arrays"
        )
    if len(times) != len(paths):
        raise InputError(
            f"{label}: times: got {len(times)} time list(s), expected one per stroke ({len(paths)})"
        )
    out: list[FloatArray] = []
    previous_end: float | None = None
    for i, (raw, path) in enumerate(zip(times, paths, strict=True)):
        name = f"{label}: times of stroke {i}"
        t = as_array(name, raw, shape=(path.shape[0],))
        steps = np.diff(t)
        if np.any(steps <= 0.0):
            j = int(np.argmax(steps <= 0.0))
            raise InputError(
                f"{name}: got t[{j}] = {t[j]:g} followed by t[{j + 1}] = {t[j + 1]:g}, "
                "expected strictly increasing times"
            )
        if previous_end is not None and t[0] <= previous_end:
            raise InputError(
                f"{name}: starts at {t[0]:g}, not after the end of stroke {i - 1} "
                f"({previous_end:g}); expected times increasing across strokes"
            )
        previous_end = float(t[-1])
        out.append(_frozen(t))
    return tuple(out)
