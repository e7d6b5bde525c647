"""load_svg on small SVG files written in tmp_path."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from skyquill.errors import InputError
from skyquill.strokes import load_svg, segment_distances

_HEAD = '<svg xmlns="http://www.w3.org/2000/svg" width="200" height="200" viewBox="0 0 200 200">'


def _svg(tmp_path: Path, body: str, name: str = "d.svg") -> Path:
    p = tmp_path / name
    p.write_text(_HEAD + body + "</svg>", encoding="utf-8")
    return p


def _cubic(p0, p1, p2, p3, t):  # type: ignore[no-untyped-def]
    t = np.asarray(t)[:, None]
    return (
        (1 - t) ** 3 * np.asarray(p0)
        + 3 * (1 - t) ** 2 * t * np.asarray(p1)
        + 3 * (1 - t) * t**2 * np.asarray(p2)
        + t**3 * np.asarray(p3)
    )


def test_line_path_flips_y(tmp_path: Path) -> None:
    s = load_svg(_svg(tmp_path, '<path d="M 10 20 L 30 20 L 30 60"/>'))
    assert s.n_strokes == 1
    np.testing.assert_allclose(s.paths[0], [[10, -20], [30, -20], [30, -60]])
    assert s.source == "d.svg"


def test_transform_and_cubic(tmp_path: Path) -> None:
    body = (
        '<g transform="translate(10,20) scale(2)">'
        '<path d="M 0 0 C 0 30 40 30 40 0"/>'
        "</g>"
        '<path d="M 100 100 L 150 100 M 100 150 L 150 150 Z"/>'
    )
    s = load_svg(_svg(tmp_path, body))
    assert s.n_strokes == 3  # one subpath per stroke
    curve = s.paths[0]
    # transformed control points: (x, y) -> (10 + 2x, 20 + 2y), then y flipped
    ctrl = [(10, 20), (10, 80), (90, 80), (90, 20)]
    np.testing.assert_allclose(curve[0], [10, -20])
    np.testing.assert_allclose(curve[-1], [90, -20])
    assert curve.shape[0] > 8  # flattened, not just its ends
    exact = _cubic(*ctrl, np.linspace(0, 1, 20001))
    exact[:, 1] = -exact[:, 1]
    # every vertex lies on the curve (on a dense polyline of it, chord error ~1e-6) ...
    on_curve = np.min(
        [segment_distances(curve, a, b) for a, b in itertools.pairwise(exact)],
        axis=0,
    )
    assert on_curve.max() < 1e-5
    # ... and the curve stays within the default tolerance (0.1 % of the diagonal)
    lo = np.array([10.0, 20.0])
    hi = np.array([150.0, 150.0])
    tol = 1e-3 * float(np.hypot(*(hi - lo)))
    dist = np.min(
        [segment_distances(exact, a, b) for a, b in itertools.pairwise(curve)],
        axis=0,
    )
    assert dist.max() <= tol * 1.01
    # the apex of the curve, y = 20 + 2 * 22.5 = 65, is reached (y up: -65)
    assert curve[:, 1].min() == pytest.approx(-65.0, abs=tol)
    # the closed subpath returns to its start
    np.testing.assert_allclose(s.paths[2], [[100, -150], [150, -150], [100, -150]])


def test_explicit_tolerance_refines(tmp_path: Path) -> None:
    p = _svg(tmp_path, '<circle cx="100" cy="100" r="50"/>')
    coarse = load_svg(p)
    fine = load_svg(p, tolerance=1e-3)
    assert fine.paths[0].shape[0] > coarse.paths[0].shape[0]
    r = np.hypot(*(fine.paths[0] - [100, -100]).T)
    np.testing.assert_allclose(r, 50.0, atol=1e-9)


def test_shapes_other_than_path(tmp_path: Path) -> None:
    s = load_svg(
        _svg(
            tmp_path, '<rect x="0" y="0" width="10" height="5"/><line x1="0" y1="0" x2="3" y2="4"/>'
        )
    )
    assert s.n_strokes == 2
    np.testing.assert_allclose(s.paths[0], [[0, 0], [10, 0], [10, -5], [0, -5], [0, 0]])


def test_hidden_and_defs_are_not_drawn(tmp_path: Path) -> None:
    body = (
        '<defs><path id="a" d="M 0 0 L 50 50"/></defs>'
        '<path d="M 0 0 L 5 5" style="display:none"/>'
        '<path d="M 1 1 L 2 1"/>'
    )
    s = load_svg(_svg(tmp_path, body))
    assert s.n_strokes == 1


def test_svg_without_paths(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"empty\.svg: no path or shape found"):
        load_svg(_svg(tmp_path, '<text x="0" y="10">hi</text>', "empty.svg"))


def test_svg_with_only_a_lone_moveto(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="non-zero"):
        load_svg(_svg(tmp_path, '<path d="M 5 5"/>'))


def test_malformed_svg(tmp_path: Path) -> None:
    p = tmp_path / "broken.svg"
    p.write_text("<svg><path d='M 0 0 L 1 1'", encoding="utf-8")
    with pytest.raises(InputError, match=r"broken\.svg: cannot be parsed as SVG"):
        load_svg(p)


def test_missing_svg(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"none\.svg: no such file"):
        load_svg(tmp_path / "none.svg")


def test_bad_tolerance(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="tolerance: got -1"):
        load_svg(_svg(tmp_path, '<path d="M 0 0 L 1 1"/>'), tolerance=-1.0)
