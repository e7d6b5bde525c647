"""Strokes from the paths of an SVG drawing."""

from __future__ import annotations

import io
import logging
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import svgelements as se
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.io.source import read_bytes
from skyquill.strokes.model import MAX_POINTS, MAX_STROKES, Strokes
from skyquill.strokes.svg_checks import check_svg_markup

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
#: CSS pixels per inch: what a unitless SVG length means on paper.
PPI = 96.0
INCH_M = 0.0254
#: Top-level layers whose label starts with this are not drawn by a plotter
#: (AxiDraw's documentation layers; vpype's ``% pen up trajectories``).
PLOTTER_SKIP_PREFIX = "%"
_INKSCAPE_LABEL = "{http://www.inkscape.org/namespaces/inkscape}label"

# What path data and point lists may hold: numbers, separators and (in path
# data) command letters. svgelements stops at the first token it cannot read
# (``NaN``, ``inf``, a stray letter) and keeps the path up to there; these
# patterns find that token so the file is refused instead of cut short.
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_PATH_TOKEN = re.compile(rf"\s+|,|{_NUMBER}|[MmZzLlHhVvCcSsQqTtAa]")
_POINTS_TOKEN = re.compile(rf"\s+|,|{_NUMBER}")
_UNIT_M = {
    "mm": 1e-3,
    "cm": 1e-2,
    "in": INCH_M,
    "pt": INCH_M / 72.0,
    "pc": INCH_M / 6.0,
    "px": INCH_M / PPI,
}
_ABSOLUTE_LENGTH = re.compile(rf"\s*({_NUMBER})\s*(mm|cm|in|pt|pc|px)?\s*", re.IGNORECASE)


def load_svg(
    path: str | Path, *, tolerance: float | None = None, true_size: bool = False
) -> Strokes:
    """Load every drawn path of an SVG file as strokes, all layers merged.

    Every shape (``path``, ``rect``, ``circle``, ``ellipse``, ``line``,
    ``polyline``, ``polygon``) is read with ``svgelements``, which applies the
    nested ``transform`` attributes and the ``viewBox`` and leaves out hidden
    elements (``display:none``, so hidden Inkscape layers) and ``<defs>``; text
    is not drawn. Top-level layers whose label starts with ``%`` are left out:
    a plotter does not draw them (AxiDraw's documentation layers; vpype writes
    its pen-up moves as ``% pen up trajectories``). Each subpath becomes one
    stroke, in document order. Curves (quadratic and cubic Béziers, elliptical
    arcs) are flattened to polylines whose chord error is at most
    ``tolerance``; a closing ``Z`` draws the segment back to the subpath's start.

    Parameters
    ----------
    path
        The SVG file.
    tolerance
        Largest distance between a curve and its polyline, in SVG user units
        after the viewBox (CSS px). Default: 0.1 % of the diagonal of the
        drawing's bounding box.
    true_size
        Return metres, from the root's ``width`` and ``height`` (mm, cm, in, pt,
        pc, or px at 96 per inch) and its ``viewBox``: a drawing 10 cm wide on
        paper spans 0.1.

    Returns
    -------
    Strokes
        Points in SVG user units (metres with ``true_size``) with y flipped to
        point up (``(x, -y)``), so the drawing reads the right way up;
        ``source`` is the file's name.

    Raises
    ------
    InputError
        If the file is missing, larger than :data:`MAX_BYTES` or is not parseable
        SVG; if a path's ``d`` or a polyline's ``points`` holds anything but
        numbers and commands (``NaN``, ``inf``: svgelements would cut the path
        there); if a point is not finite; if it has no drawn shape, or if every
        subpath is a lone point; if it has more than
        :data:`~skyquill.strokes.model.MAX_STROKES` subpaths, or flattening
        needs more than :data:`~skyquill.strokes.model.MAX_POINTS` points; with
        ``true_size``, if ``width`` or ``height`` is missing or relative (``%``,
        ``em``).

    Notes
    -----
    A subpath that never leaves its starting point (a lone ``M``, or ``M`` then
    zero-length segments) is skipped and logged: it would be a stroke of one
    repeated point, which :class:`Strokes` refuses.
    """
    parts = _read_parts(Path(path), tolerance, true_size)
    strokes = tuple(stroke for _, _, part in parts for stroke in part)
    return Strokes(paths=strokes, source=Path(path).name)


def load_svg_layers(
    path: str | Path, *, tolerance: float | None = None, true_size: bool = False
) -> list[Strokes]:
    """Load an SVG file as one :class:`Strokes` per drawn layer, in document order.

    A layer is a top-level group (Inkscape's ``<g inkscape:groupmode="layer">``,
    vpype's ``<g id="layer1">``); shapes outside every group form one more
    layer. Hidden layers and ``%`` layers are left out, as by :func:`load_svg`,
    and so is a layer with nothing to draw.

    Parameters
    ----------
    path, tolerance, true_size
        As for :func:`load_svg`.

    Returns
    -------
    list of Strokes
        ``source`` reads ``"drawing.svg layer 'Outline'"`` (the layer's
        ``inkscape:label``, else its ``id``); every layer's ``box`` is the
        bounding box of the whole drawing, so that each scales as the drawing
        does and keeps its place in it.

    Raises
    ------
    InputError
        As :func:`load_svg`.
    """
    p = Path(path)
    parts = _read_parts(p, tolerance, true_size)
    stacked = np.concatenate([s for _, _, part in parts for s in part], axis=0)
    box = np.stack([stacked.min(axis=0), stacked.max(axis=0)])
    layers: dict[int, tuple[str, list[FloatArray]]] = {}
    for key, name, part in parts:  # the shapes outside every layer (key -1) join up
        layers.setdefault(key, (name, []))[1].extend(part)
    return [
        Strokes(paths=tuple(layer), source=f"{p.name} layer {name!r}", box=box)
        for name, layer in layers.values()
    ]


def _read_parts(
    p: Path, tolerance: float | None, true_size: bool
) -> list[tuple[int, str, list[FloatArray]]]:
    """Strokes (y up; metres with ``true_size``) by top-level element, in document order.

    Each entry is ``(layer key, layer name, strokes)`` of one top-level element
    with something to draw: a layer's key is its index, a shape outside every
    layer has key -1 and name ``""``.
    """
    raw = read_bytes(p, "an SVG file", max_bytes=MAX_BYTES)
    try:
        svg = se.SVG.parse(io.BytesIO(raw), ppi=PPI)
        grouped = _drawn_parts(svg)
    except Exception as exc:  # svgelements lets XML, value, recursion and I/O errors through
        raise InputError(f"{p}: cannot be parsed as SVG ({exc}), expected an SVG file") from None
    check_svg_markup(p, raw)
    metres = _metres_per_px(p, svg) if true_size else 1.0
    parts = [(key, name, _reified(part)) for key, name, part in grouped]
    shapes = [s for _, _, part in parts for s in part]
    if len(shapes) > MAX_STROKES:
        raise InputError(
            f"{p}: got {len(shapes):,} drawn shapes, expected at most {MAX_STROKES:,} strokes"
        )
    if not shapes:
        raise InputError(
            f"{p}: no path or shape found (text, <defs>, hidden and % layers are not drawn), "
            "expected an SVG with at least one path"
        )
    tol = _tolerance(p, shapes) if tolerance is None else float(tolerance)
    if not (math.isfinite(tol) and tol > 0.0):
        raise InputError(f"tolerance: got {tol:g}, expected a finite number > 0")
    budget = _Budget(p)
    out: list[tuple[int, str, list[FloatArray]]] = []
    for key, name, part in parts:
        strokes = _flattened(p, part, tol, budget, first=sum(len(s) for _, _, s in out))
        if strokes:
            out.append((key, name, [s * metres for s in strokes]))
    if not out:
        raise InputError(
            f"{p}: every subpath is a single point, expected at least one path of non-zero length"
        )
    return out


def _reified(layer: list[Any]) -> list[Any]:
    shapes = [e if isinstance(e, se.Path) else se.Path(e) for e in layer]
    return [s for s in shapes if len(s) > 0]


def _flattened(
    p: Path, shapes: list[Any], tol: float, budget: _Budget, first: int
) -> list[FloatArray]:
    """One layer's subpaths as ``(K, 2)`` arrays, y up; ``first`` strokes came before."""
    strokes: list[FloatArray] = []
    skipped = 0
    for shape in shapes:
        for sub in _subpaths(shape, tol, budget):
            if len(sub) < 2:
                skipped += 1
                continue
            if first + len(strokes) == MAX_STROKES:
                raise InputError(
                    f"{p}: got more than {MAX_STROKES:,} subpaths, expected at most "
                    f"{MAX_STROKES:,} strokes"
                )
            arr = np.asarray(sub, dtype=np.float64)
            if not np.all(np.isfinite(arr)):
                raise InputError(
                    f"{p}: stroke {first + len(strokes)}: got a NaN or infinite coordinate (a "
                    "number beyond the float range, or a transform of one), expected finite numbers"
                )
            arr[:, 1] = -arr[:, 1]
            strokes.append(arr)
    if skipped:
        logger.info("%s: skipped %d subpath(s) that never leave their start point", p, skipped)
    return strokes


def _drawn_parts(svg: Any) -> list[tuple[int, str, list[Any]]]:
    """The shapes a plotter draws by top-level element, in document order.

    Layers are the top-level groups; a shape outside them is an entry of its
    own (key -1), so that merging keeps the document's order.
    """
    parts: list[tuple[int, str, list[Any]]] = []
    for index, child in enumerate(svg):
        if isinstance(child, se.Shape):
            parts.append((-1, "", [child]))
            continue
        if not isinstance(child, se.Group | se.Use):
            continue
        attributes = child.values.get("attributes", {})
        label = attributes.get(_INKSCAPE_LABEL)
        if isinstance(label, str) and label.startswith(PLOTTER_SKIP_PREFIX):
            logger.info("left out layer %r: a plotter does not draw %s layers", label, "%")
            continue
        name = label or attributes.get("id") or f"group {index + 1}"
        parts.append((index, str(name), _shapes_under(child)))
    return [part for part in parts if part[2]]


def _shapes_under(group: Any) -> list[Any]:
    """Every shape inside ``group``, in document order.

    Walks the tree with an explicit stack: a deeply nested file must not hit
    Python's recursion limit here.
    """
    shapes: list[Any] = []
    stack = list(reversed(group))
    while stack:
        element = stack.pop()
        if isinstance(element, se.Shape):
            shapes.append(element)
        elif isinstance(element, se.Group | se.Use):
            stack.extend(reversed(element))
    return shapes


def _metres_per_px(p: Path, svg: Any) -> float:
    """Metres per user unit after the viewBox, from the root's absolute width and height."""
    attributes = svg.values.get("attributes", {})
    sizes: dict[str, float] = {}
    for name in ("width", "height"):
        text = attributes.get(name)
        match = _ABSOLUTE_LENGTH.fullmatch(text) if isinstance(text, str) else None
        if match is None or float(match.group(1)) <= 0.0:
            got = f"no {name}" if text is None else repr(text)
            raise InputError(
                f"{p}: {name}: got {got}, expected an absolute length > 0 (mm, cm, in, pt, pc "
                "or px) to draw at true size"
            )
        sizes[name] = float(match.group(1)) * _UNIT_M[(match.group(2) or "px").lower()]
    # svgelements has mapped the viewBox onto width x height px with its own
    # (7-digit) mm constant; dividing by its width in px undoes that rounding.
    return sizes["width"] / float(svg.width)


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
