"""typed_parts and Strokes.box: a line shared between drones keeps one scale."""

from __future__ import annotations

import numpy as np
import pytest

from skyquill.errors import InputError
from skyquill.strokes import Strokes, hanzi_strokes, line_extent, typed_parts, typed_strokes


def _ink(s: Strokes) -> tuple[np.ndarray, np.ndarray]:
    pts = np.concatenate(s.paths)
    return pts.min(axis=0), pts.max(axis=0)


def test_yi_is_as_wide_on_its_own_board_as_beside_yong() -> None:
    yong, yi = (p.scaled(0.5) for p in typed_parts("永一", 2))
    # One em box per board: the ink keeps its size and place in the em box.
    for part, char in ((yong, "永"), (yi, "一")):
        lo, hi = _ink(part)
        ref_lo, ref_hi = _ink(hanzi_strokes(char))
        np.testing.assert_allclose(hi - lo, (ref_hi - ref_lo) * 0.5 / 1024)
        np.testing.assert_allclose(lo, (ref_lo - [0.0, -124.0]) * 0.5 / 1024)
    lo, hi = _ink(yi)
    assert hi[1] - lo[1] < 0.1 * 0.5  # flat, not stretched to the board's height
    assert hi[0] - lo[0] < 0.9 * 0.5  # nor to its width


def test_every_part_has_the_same_extent_so_the_same_scale() -> None:
    parts = typed_parts("一马当先", 4)
    extents = [hi - lo for lo, hi in (p.bounds() for p in parts)]
    np.testing.assert_array_equal(extents, [[1024.0, 1024.0]] * 4)
    parts = typed_parts("I am here", 3)
    extents = np.array([hi - lo for lo, hi in (p.bounds() for p in parts)])
    assert np.all(extents == extents[0])


def test_narrow_word_stays_narrow() -> None:
    narrow, wide = (p.scaled(0.5) for p in typed_parts("I mmmm", 2))
    lo, hi = _ink(narrow)
    assert hi[0] - lo[0] < 1e-9  # "I" is one vertical stroke
    bottom, top = line_extent()
    cap = 0.5 * 21.0 / (_ink(typed_strokes("mmmm"))[1][0] - 0.0)  # cap height, m
    assert hi[1] - lo[1] == pytest.approx(cap, rel=1e-9)
    assert (bottom, top) == (-7.0, 21.0)
    _, w_hi = _ink(wide)
    assert w_hi[0] == pytest.approx(0.5)  # the widest part fills its board


def test_one_part_is_typed_strokes_unchanged() -> None:
    (one,) = typed_parts("永", 1)
    assert one.box is None
    np.testing.assert_array_equal(one.scaled(0.5).bounds()[1].max(), 0.5)


@pytest.mark.parametrize("parts", [0, -1, 1.5, True])
def test_parts_must_be_a_positive_integer(parts: object) -> None:
    with pytest.raises(InputError, match=rf"parts: got {parts!r}, expected an integer >= 1"):
        typed_parts("永一", parts)  # type: ignore[arg-type]


def test_box_is_fitted_and_moves_with_the_strokes() -> None:
    s = Strokes(paths=([[1.0, 1.0], [2.0, 1.0]],), box=[[0.0, 0.0], [4.0, 2.0]])
    lo, hi = s.bounds()
    np.testing.assert_array_equal([lo, hi], [[0.0, 0.0], [4.0, 2.0]])
    t = s.scaled(2.0)
    np.testing.assert_array_equal(t.paths[0], [[0.5, 0.5], [1.0, 0.5]])
    assert t.box is not None
    np.testing.assert_array_equal(t.box, [[0.0, 0.0], [2.0, 1.0]])
    # Ink outside the box grows the extent: nothing is ever scaled off the board.
    u = Strokes(paths=([[-1.0, 0.0], [1.0, 3.0]],), box=[[0.0, 0.0], [1.0, 1.0]])
    np.testing.assert_array_equal(np.stack(u.bounds()), [[-1.0, 0.0], [1.0, 3.0]])


@pytest.mark.parametrize(
    ("box", "message"),
    [
        ([[0.0, 0.0], [-1.0, 1.0]], r"box: got lower corner \(0, 0\) above or right of upper"),
        ([[0.0, 0.0, 1.0]], r"box: got an array of shape \(1, 3\), expected shape \(2, 2\)"),
        ([[0.0, np.nan], [1.0, 1.0]], r"box: got"),
        ("box", r"box: got"),
    ],
)
def test_bad_box_is_refused(box: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        Strokes(paths=([[0.0, 0.0], [1.0, 1.0]],), box=box)  # type: ignore[arg-type]
