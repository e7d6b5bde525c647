"""Wall description files: the three kinds, and every way a description is not a wall."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.painting.wall import Wall
from skyquill.painting.wall_file import parse_wall, read_wall

THREE = """
[[segment]]
from = -4.0
to = -0.6
angle = -10
[[segment]]
from = -0.6
to = 0.6
angle = 0
[[segment]]
from = 0.6
to = 4.0
angle = 10
"""


def test_segments() -> None:
    wall = parse_wall(THREE)
    assert np.degrees(wall.angles_rad) == pytest.approx([-10, 0, 10])
    assert wall.breaks_m == pytest.approx([-0.6, 0.6])
    assert wall.x_range_m == (-4.0, 4.0)
    same = Wall(np.radians([-10, 0, 10]), np.array([-0.6, 0.6]))
    x = np.linspace(-4, 4, 33)
    assert wall.depth(x) == pytest.approx(same.depth(x))


def test_cylinder_and_recess() -> None:
    cyl = parse_wall("extent = [-3.0, 3.0]\nheight = 6\n[cylinder]\nradius = -15.0\n")
    x = np.linspace(-3, 3, 25)
    assert cyl.depth(x) == pytest.approx(-(15.0 - np.sqrt(225.0 - x**2)), abs=3e-4)
    assert cyl.height_m == 6.0
    rec = parse_wall("[recess]\nfrom = -1.5\nto = -0.5\ndepth = 0.2\nside_angle = 45\n")
    assert rec.depth(np.array([-4.0, -1.0, 0.0])) == pytest.approx([0.0, 0.2, 0.0], abs=1e-12)


def test_read_wall_names_the_file(tmp_path: Path) -> None:
    path = tmp_path / "w.toml"
    path.write_text(THREE.replace("to = 0.6", "to = 0.5"))
    with pytest.raises(
        InputError, match=r"^w.toml: segment\[2\].from: got 0.6 m, which leaves a gap"
    ):
        read_wall(path)
    with pytest.raises(InputError, match=r"--wall: got '.*none.toml', expected an existing"):
        read_wall(tmp_path / "none.toml")
    (tmp_path / "bin.toml").write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(InputError, match=r"--wall: got bin.toml, which is not UTF-8"):
        read_wall(tmp_path / "bin.toml")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            THREE.replace("from = 0.6", "from = 0.3"),
            r"segment\[2\].from: got 0.3 m, which overlaps segment\[1\]",
        ),
        (
            THREE.replace("angle = 10", "angle = 90"),
            r"segment\[2\].angle: got 90 deg, expected within \+-60",
        ),
        (THREE.replace("angle = 10", "angle = 135"), r"90 deg or more is not a wall"),
        (
            THREE.replace("angle = 0", "angle = 5"),
            r"segment\[1\].angle: got 5 deg for the segment holding x = 0",
        ),
        (
            THREE.replace("to = 4.0", "to = 0.2"),
            r"segment\[2\].to: got 0.2 m, expected more than its from",
        ),
        (
            "[[segment]]\nfrom = 0.5\nto = 2\nangle = 0\n",
            r"expected it to reach on both sides of x = 0",
        ),
        (
            "[[segment]]\nfrom = -1\nto = 0\nangle = 0\n[[segment]]\nfrom = 0\nto = 1\nangle = 0\n",
            r"segment\[1\].from: got 0 m, expected x = 0 inside a segment",
        ),
        ("[[segment]]\nfrom = -1\nto = 1\n", r"segment\[0\].angle: got nothing, expected a number"),
        ('[[segment]]\nfrom = -1\nto = 1\nangle = "flat"\n', r"segment\[0\].angle: got 'flat'"),
        (
            "[[segment]]\nfrom = -1\nto = 1\nangle = nan\n",
            r"segment\[0\].angle: got nan, expected a finite",
        ),
        ("[[segment]]\nfrom = -1e9\nto = 1\nangle = 0\n", r"expected a number within 1e6"),
        (
            "[[segment]]\nfrom = -1\nto = 1\nangle = 0\nslope = 3\n",
            r"segment\[0\]: got unknown key 'slope'",
        ),
        ("[cylinder]\nradius = 3\n", r"cylinder.radius: got 3 m, expected \|radius\| > 4.62 m"),
        ("[cylinder]\nradius = 0\n", r"cylinder.radius: got 0 m"),
        (
            "[recess]\nfrom = -0.2\nto = 0.4\ndepth = 0.1\n",
            r"recess: got from -0.2 to 0.4 m, expected it beside x = 0",
        ),
        (
            "[recess]\nfrom = 1\nto = 1.05\ndepth = 0.1\n",
            r"expected a recess wider than its two sides",
        ),
        (
            "[recess]\nfrom = 1\nto = 2\ndepth = -0.1\n",
            r"recess.depth: got -0.1, expected a positive",
        ),
        (
            "[recess]\nfrom = 1\nto = 2\ndepth = 0.1\nside_angle = 80\n",
            r"recess side angle: got 80 deg",
        ),
        (
            "[cylinder]\nradius = 20\n[recess]\nfrom = 1\nto = 2\ndepth = 0.1\n",
            r"wall: got cylinder and recess",
        ),
        ("height = 4\n", r"wall: got no shape, expected exactly one of"),
        ("height = 0\n[cylinder]\nradius = 20\n", r"height: got 0, expected a positive"),
        (
            "extent = [1, 2]\n[cylinder]\nradius = 20\n",
            r"extent: got \[1, 2\], expected x_min < 0 < x_max",
        ),
        ('extent = "wide"\n[cylinder]\nradius = 20\n', r"extent: got 'wide'"),
        ("extent = [-4, 4]\n" + THREE, r"extent: got it with \[\[segment\]\]"),
        ("[[segment\n", r"wall: got malformed TOML"),
        ("segment = 3\n", r"\[\[segment\]\]: got none, expected a list"),
        ("[wall]\nangles = [0]\n", r"wall: got unknown key 'wall'"),
    ],
)
def test_not_a_wall(text: str, message: str) -> None:
    with pytest.raises(InputError, match=message):
        parse_wall(text)


@settings(max_examples=60, deadline=None)
@given(st.text(max_size=300))
def test_any_text_is_a_wall_or_one_input_error(text: str) -> None:
    try:
        wall = parse_wall(text)
    except InputError as exc:
        assert "\n" not in str(exc)
    else:
        assert isinstance(wall, Wall)


@settings(max_examples=40, deadline=None)
@given(
    cuts=st.lists(st.floats(-3.9, 3.9), min_size=0, max_size=6, unique=True),
    angles=st.lists(st.floats(-89.0, 89.0), min_size=7, max_size=7),
)
def test_any_segment_list_is_a_wall_or_one_input_error(
    cuts: list[float], angles: list[float]
) -> None:
    edges = [-4.0, *sorted(cuts), 4.0]
    text = "".join(
        f"[[segment]]\nfrom = {a!r}\nto = {b!r}\nangle = {angle!r}\n"
        for (a, b), angle in zip(itertools.pairwise(edges), angles, strict=False)
    )
    try:
        wall = parse_wall(text)
    except InputError as exc:
        assert "\n" not in str(exc)
    else:
        assert np.all(np.abs(np.degrees(wall.angles_rad)) <= 60.0)
        assert np.all(np.isfinite(wall.depth(np.linspace(-4, 4, 50))))
