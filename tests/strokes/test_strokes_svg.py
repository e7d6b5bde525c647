"""load_svg on small SVG files written in tmp_path."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.strokes import load_svg, segment_distances
from skyquill.strokes.model import MAX_POINTS, MAX_STROKES

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


@pytest.mark.parametrize(
    ("body", "match"),
    [
        (
            '<path d="M 0 0 L 5 5 L nan 5 L 10 10"/>',
            r"<path> number 1 d: got 'M 0 0 L 5 5 L nan 5 L 10 10', expected 2 numbers for each "
            r"'L' \(character 14 has 0",
        ),
        ('<path d="M 0 0 L inf 5"/>', r"<path> number 1 d: got 'M 0 0 L inf 5', expected 2"),
        (
            '<polyline points="0,0 NaN,1 3,3"/>',
            r"<polyline> number 1 points: got '0,0 NaN,1 3,3', expected x,y pairs",
        ),
    ],
)
def test_nan_in_path_data_is_refused_not_cut(tmp_path: Path, body: str, match: str) -> None:
    with pytest.raises(InputError, match=rf"d\.svg: {match}"):
        load_svg(_svg(tmp_path, body))


@pytest.mark.parametrize(
    ("body", "match"),
    [
        (
            '<g transform="translate(NaN,0)"><path d="M0 0 L10 10"/></g>',
            r"<g> number 1 transform: got 'translate\(NaN,0\)', expected a list of matrix",
        ),
        (
            '<g id="a" transform="skew(1,2,3) garbage"><path d="M0 0 L10 10"/></g>',
            r"<g id='a'> transform: got 'skew\(1,2,3\) garbage'",
        ),
        ('<path d="M0 0 L10 10" transform="rotate(1,2)"/>', r"<path> number 1 transform"),
        (
            '<polyline points="0,0 10,10 20"/>',
            r"points: got '0,0 10,10 20', expected x,y pairs .*5 num",
        ),
        (
            '<rect width="abc" height="10"/><path d="M0 0 L10 10"/>',
            r"<rect> number 1 width: got 'abc', expected a length",
        ),
        (
            '<rect width="10" height="-3"/>',
            r"<rect> number 1 height: got '-3', expected a length >= 0",
        ),
        (
            '<path d="M0 0 L10 10 L 5"/>',
            r"d: got 'M0 0 L10 10 L 5', expected 2 numbers for each 'L'",
        ),
        ('<path d="M0 0 C1 1 2 2 3"/>', r"expected 6 numbers for each 'C'"),
        ('<path d="M0 0 A5 5 0 2 0 10 10"/>', r"expected 7 numbers for each 'A'"),
        ('<path d="L0 0 L10 10"/>', r"expected path data that starts with a move-to"),
        (
            '<circle cx="0" cy="0" r="-5"/>',
            r"<circle> number 1 r: got '-5', expected a length >= 0",
        ),
        ('<ellipse cx="0" cy="0" rx="5" ry="-1"/>', r"<ellipse> number 1 ry: got '-1'"),
        ('<line x1="0" y1="0" x2="١" y2="3"/>', r"<line> number 1 x2: got '١', expected a length"),
    ],
)
def test_what_svgelements_would_drop_or_repair_is_refused(
    tmp_path: Path, body: str, match: str
) -> None:
    """Issue 25: a NaN or garbage transform, an odd coordinate, a bad length, a missing path
    coordinate and a negative radius were read without a word; each names its element."""
    with pytest.raises(InputError, match=rf"d\.svg: .*{match}"):
        load_svg(_svg(tmp_path, body))


def test_compact_and_unusual_but_valid_path_data_is_read(tmp_path: Path) -> None:
    body = (
        '<path d="M0,0 10,10 20,0"/><path d="m30 0a5 5 0 1010 10"/>'
        '<path d="M1.5.5L1-2h3v4z" transform="translate(1) scale(2,2) rotate(30 1 1)"/>'
        '<rect x="1mm" y="2" width="3" height="4" rx="0"/>'
    )
    assert len(load_svg(_svg(tmp_path, body)).paths) == 4


def test_overflowing_number_is_refused(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"d\.svg: .*(inf|NaN or infinite)"):
        load_svg(_svg(tmp_path, '<path d="M 0 0 L 1e400 5 L 10 10"/>'))


def test_too_many_paths_are_refused(tmp_path: Path) -> None:
    body = "".join(f'<path d="M {i % 200} 0 L {i % 200} 1"/>' for i in range(10_000))
    with pytest.raises(
        InputError, match=rf"got 10,000 drawn shapes, expected at most {MAX_STROKES:,} strokes"
    ):
        load_svg(_svg(tmp_path, body))


def test_too_many_subpaths_are_refused(tmp_path: Path) -> None:
    d = " ".join(f"M {i % 200} 0 L {i % 200} 1" for i in range(MAX_STROKES + 1))
    with pytest.raises(InputError, match=rf"got more than {MAX_STROKES:,} subpaths"):
        load_svg(_svg(tmp_path, f'<path d="{d}"/>'))


def test_tiny_tolerance_is_bounded(tmp_path: Path) -> None:
    p = _svg(tmp_path, '<path d="M 0 0 C 50 200 150 -100 200 100"/>')
    with pytest.raises(InputError, match=rf"got more than {MAX_POINTS:,} points after flattening"):
        load_svg(p, tolerance=1e-300)


def test_entities_are_not_expanded_without_bound(tmp_path: Path) -> None:
    entities = "".join(
        f'<!ENTITY {chr(98 + i)} "' + f"&{chr(97 + i)};" * 10 + '">' for i in range(9)
    )
    p = tmp_path / "lol.svg"
    p.write_text(
        f'<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY a "1 1 2 2 ">{entities}]>'
        '<svg xmlns="http://www.w3.org/2000/svg"><path d="M 0 0 L &j;"/></svg>',
        encoding="utf-8",
    )
    with pytest.raises(InputError, match=r"lol\.svg: cannot be parsed as SVG"):
        load_svg(p)


def test_external_entities_are_not_fetched(tmp_path: Path) -> None:
    secret = tmp_path / "secret.txt"
    secret.write_text("M 0 0 L 5 5", encoding="utf-8")
    p = tmp_path / "xxe.svg"
    p.write_text(
        f'<?xml version="1.0"?><!DOCTYPE svg [<!ENTITY x SYSTEM "file://{secret}">]>'
        '<svg xmlns="http://www.w3.org/2000/svg"><path d="&x;"/></svg>',
        encoding="utf-8",
    )
    with pytest.raises(InputError, match=r"xxe\.svg: cannot be parsed as SVG"):
        load_svg(p)


def test_deeply_nested_groups_are_named(tmp_path: Path) -> None:
    body = "<g>" * 5000 + '<path d="M 0 0 L 1 1"/>' + "</g>" * 5000
    with pytest.raises(InputError, match=r"d\.svg: cannot be parsed as SVG"):
        load_svg(_svg(tmp_path, body))


_svg_number = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-(10**6), 10**6).map(str),
    st.sampled_from(["nan", "NaN", "inf", "-inf", "1e400", "-1e-400", "1e308", ".5", "-", "e"]),
)
_svg_token = st.one_of(_svg_number, st.sampled_from(list("MmLlHhVvCcSsQqTtAaZz,")))
_svg_body = st.one_of(
    st.lists(_svg_token, max_size=16).map(lambda t: f'<path d="M 0 0 {" ".join(t)}"/>'),
    st.lists(_svg_number, max_size=8).map(lambda t: f'<polyline points="{" ".join(t)}"/>'),
    st.tuples(_svg_number, _svg_number, _svg_number).map(
        lambda t: f'<g transform="translate({t[0]} {t[1]}) scale({t[2]})"><path d="M0 0 L9 9"/></g>'
    ),
    st.text(max_size=30),
)


@settings(
    max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(bodies=st.lists(_svg_body, min_size=1, max_size=3))
def test_random_svg_gives_strokes_or_input_error(tmp_path: Path, bodies: list[str]) -> None:
    p = _svg(tmp_path, "".join(bodies), "random.svg")
    try:
        s = load_svg(p)
    except InputError as exc:
        assert "random.svg" in str(exc)
        return
    assert all(np.all(np.isfinite(path)) and path.shape[0] >= 2 for path in s.paths)


@settings(
    max_examples=100, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(raw=st.binary(max_size=60))
def test_random_bytes_give_input_error_svg(tmp_path: Path, raw: bytes) -> None:
    p = tmp_path / "raw.svg"
    p.write_bytes(raw)
    with pytest.raises(InputError, match=r"raw\.svg"):
        load_svg(p)
