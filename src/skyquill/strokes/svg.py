"""Strokes from the paths of an SVG drawing."""

from __future__ import annotations

import logging
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import svgelements as se
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.strokes.model import MAX_POINTS, MAX_STROKES, Strokes

logger = logging.getLogger(__name__)

FloatArray = NDArray[np.float64]

#: Curve flattening tolerance as a fraction of the drawing's bounding-box diagonal.
RELATIVE_TOLERANCE = 1e-3

# Every curve starts from this many equal parameter steps before refinement, so
# that an S-shaped cubic whose midpoint happens to lie on its chord is not
# mistaken for a straight line.
_INITIAL_STEPS = 8
_MAX_REFINEMENTS = 30
#: Largest SVG file read, bytes: checked before the XML parser sees it.
MAX_BYTES = 32 * 2**20

# What path data and point lists may hold: numbers, separators and (in path
# data) command letters. svgelements stops at the first token it cannot read
# (``NaN``, ``inf``, a stray letter) and keeps the path up to there; these
# patterns find that token so the file is refused instead of cut short.
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_PATH_TOKEN = re.compile(rf"\s+|,|{_NUMBER}|[MmZzLlHhVvCcSsQqTtAa]")
_POINTS_TOKEN = re.compile(rf"\s+|,|{_NUMBER}")


def load_svg(path: str | Path, *, tolerance: float | None = None) -> Strokes:
    """Load every drawn path of an SVG file as strokes.

    Every shape (``path``, ``rect``, ``circle``, ``ellipse``, ``line``,
    ``polyline``, ``polygon``) is read with ``svgelements``, which applies the
    nested ``transform`` attributes and the ``viewBox`` and leaves out hidden
    elements and ``<defs>``; text is not drawn. Each subpath becomes one stroke,
    in document order. Curves (quadratic and cubic Béziers, elliptical arcs) are
    flattened to polylines whose chord error is at most ``tolerance``; a closing
    ``Z`` draws the segment back to the subpath's start.

    Parameters
    ----------
    path
        The SVG file.
    tolerance
        Largest distance between a curve and its polyline, in SVG user units
        after the viewBox (CSS px). Default: 0.1 % of the diagonal of the
        drawing's bounding box.

    Returns
    -------
    Strokes
        Points in SVG user units with y flipped to point up (``(x, -y)``), so the
        drawing reads the right way up; ``source`` is the file's name.

    Raises
    ------
    InputError
        If the file is missing, larger than :data:`MAX_BYTES` or is not parseable
        SVG; if a path's ``d`` or a polyline's ``points`` holds anything but
        numbers and commands (``NaN``, ``inf``: svgelements would cut the path
        there); if a point is not finite; if it has no drawn shape, or if every
        subpath is a lone point; if it has more than
        :data:`~skyquill.strokes.model.MAX_STROKES` subpaths, or flattening
        needs more than :data:`~skyquill.strokes.model.MAX_POINTS` points.

    Notes
    -----
    A subpath that never leaves its starting point (a lone ``M``, or ``M`` then
    zero-length segments) is skipped and logged: it would be a stroke of one
    repeated point, which :class:`Strokes` refuses.
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file, expected an SVG file")
    size = p.stat().st_size
    if size > MAX_BYTES:
        raise InputError(f"{p}: got {size:,} bytes, expected an SVG file of at most {MAX_BYTES:,}")
    try:
        svg = se.SVG.parse(str(p))
        elements = [e for e in svg.elements() if isinstance(e, se.Shape)]
    except Exception as exc:  # svgelements lets XML, value, recursion and I/O errors through
        raise InputError(f"{p}: cannot be parsed as SVG ({exc}), expected an SVG file") from None
    for i, element in enumerate(elements):
        _check_data(p, i, element)
    shapes: list[Any] = [e if isinstance(e, se.Path) else se.Path(e) for e in elements]
    shapes = [s for s in shapes if len(s) > 0]
    if len(shapes) > MAX_STROKES:
        raise InputError(
            f"{p}: got {len(shapes):,} drawn shapes, expected at most {MAX_STROKES:,} strokes"
        )
    if not shapes:
        raise InputError(
            f"{p}: no path or shape found (text and <defs> are not drawn), "
            "expected an SVG with at least one path"
        )
    tol = _tolerance(p, shapes) if tolerance is None else float(tolerance)
    if not (math.isfinite(tol) and tol > 0.0):
        raise InputError(f"tolerance: got {tol:g}, expected a finite number > 0")

    strokes: list[FloatArray] = []
    skipped = 0
    budget = _Budget(p)
    for shape in shapes:
        for sub in _subpaths(shape, tol, budget):
            if len(sub) < 2:
                skipped += 1
                continue
            if len(strokes) == MAX_STROKES:
                raise InputError(
                    f"{p}: got more than {MAX_STROKES:,} subpaths, expected at most "
                    f"{MAX_STROKES:,} strokes"
                )
            arr = np.asarray(sub, dtype=np.float64)
            if not np.all(np.isfinite(arr)):
                raise InputError(
                    f"{p}: stroke {len(strokes)}: got a NaN or infinite coordinate (a number "
                    "beyond the float range, or a transform of one), expected finite numbers"
                )
            arr[:, 1] = -arr[:, 1]
            strokes.append(arr)
    if skipped:
        logger.info("%s: skipped %d subpath(s) that never leave their start point", p, skipped)
    if not strokes:
        raise InputError(
            f"{p}: every subpath is a single point, expected at least one path of non-zero length"
        )
    return Strokes(paths=tuple(strokes), source=p.name)


def _check_data(p: Path, index: int, element: Any) -> None:
    """Refuse path data or a point list that holds a token svgelements would stop at."""
    for attribute, pattern in (("d", _PATH_TOKEN), ("points", _POINTS_TOKEN)):
        text = element.values.get(attribute)
        if not isinstance(text, str):
            continue
        at = _first_stranger(text, pattern)
        if at is not None:
            token = re.split(r"[\s,]", text[at:], maxsplit=1)[0][:20]
            raise InputError(
                f"{p}: shape {index} ({type(element).__name__}) {attribute}: got {token!r} at "
                f"character {at}, expected only numbers"
                + (" and path commands" if attribute == "d" else "")
            )


def _first_stranger(text: str, pattern: re.Pattern[str]) -> int | None:
    """Index of the first character of ``text`` no token of ``pattern`` covers, or None."""
    at = 0
    while at < len(text):
        match = pattern.match(text, at)
        if match is None or match.end() == at:
            return at
        at = match.end()
    return None


class _Budget:
    """Counts the points flattening makes; refuses past :data:`MAX_POINTS`.

    An explicit tiny ``tolerance`` or a huge drawing would otherwise bisect every
    curve thirty times: billions of points, hours and gigabytes.
    """

    def __init__(self, p: Path) -> None:
        self.p = p
        self.used = 0

    def take(self, n: int) -> None:
        """Count ``n`` more points."""
        self.check(n)
        self.used += n

    def check(self, n: int) -> None:
        """Refuse if ``n`` more points would pass the ceiling."""
        if self.used + n > MAX_POINTS:
            raise InputError(
                f"{self.p}: got more than {MAX_POINTS:,} points after flattening the curves, "
                f"expected at most {MAX_POINTS:,} (a larger tolerance, or a simpler drawing)"
            )


def _tolerance(p: Path, shapes: list[Any]) -> float:
    boxes = [b for b in (s.bbox() for s in shapes) if b is not None]
    if not boxes:
        raise InputError(f"{p}: the paths have no extent, expected paths of non-zero length")
    arr = np.asarray(boxes, dtype=np.float64)
    with np.errstate(invalid="ignore", over="ignore"):  # inf - inf: refused just below
        diag = math.hypot(arr[:, 2].max() - arr[:, 0].min(), arr[:, 3].max() - arr[:, 1].min())
    if not (math.isfinite(diag) and diag > 0.0):
        raise InputError(
            f"{p}: the drawing's bounding box has diagonal {diag:g}, "
            "expected paths of non-zero, finite extent"
        )
    return RELATIVE_TOLERANCE * diag


def _subpaths(shape: Any, tol: float, budget: _Budget) -> list[list[tuple[float, float]]]:
    """Flatten one reified path into point lists, one per subpath (y still down)."""
    out: list[list[tuple[float, float]]] = []
    current: list[tuple[float, float]] = []

    def add(x: float, y: float) -> None:
        # Exact repeats (a segment of zero length, a "Z" after returning to the
        # start) carry no drawing and would only confuse chord-length steps.
        if not current or current[-1] != (x, y):
            current.append((x, y))
            budget.take(1)

    for seg in shape.segments():
        if isinstance(seg, se.Move):
            if current:
                out.append(current)
            current = []
            add(float(seg.end.x), float(seg.end.y))
        elif isinstance(seg, se.Line | se.Close):
            if not current:  # a segment with no Move before it starts where it starts
                add(float(seg.start.x), float(seg.start.y))
            add(float(seg.end.x), float(seg.end.y))
        else:
            if not current:
                add(float(seg.start.x), float(seg.start.y))
            for x, y in _flatten_curve(seg, tol, budget):
                add(float(x), float(y))
    if current:
        out.append(current)
    return out


def _flatten_curve(seg: Any, tol: float, budget: _Budget) -> FloatArray:
    """Points along a curve segment, excluding its start, chord error <= ``tol``.

    Bisects every parameter interval whose midpoint is farther than ``tol`` from
    the interval's chord, level by level, until none is.
    """
    ts = np.linspace(0.0, 1.0, _INITIAL_STEPS + 1)
    for _ in range(_MAX_REFINEMENTS):
        pts = _points(seg, ts)
        mids_t = 0.5 * (ts[:-1] + ts[1:])
        mids = _points(seg, mids_t)
        a, b = pts[:-1], pts[1:]
        ab = b - a
        am = mids - a
        # Distance to the chord as a segment: a cusp's midpoint can sit on the
        # chord's line yet far beyond its ends.
        denom = np.einsum("ij,ij->i", ab, ab)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = np.where(denom > 0.0, np.einsum("ij,ij->i", am, ab) / denom, 0.0)
        diff = am - np.clip(s, 0.0, 1.0)[:, None] * ab
        dev = np.hypot(diff[:, 0], diff[:, 1])
        bad = dev > tol
        if not np.any(bad):
            break
        # The points of this curve alone may not exceed what the drawing has left.
        budget.check(ts.size + int(bad.sum()))
        ts = np.sort(np.concatenate([ts, mids_t[bad]]))
    return _points(seg, ts[1:])


def _points(seg: Any, ts: FloatArray) -> FloatArray:
    return np.asarray(seg.npoint(ts), dtype=np.float64).reshape(-1, 2)
