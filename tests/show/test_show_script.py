"""Show scripts: the TOML format, and every refusal naming what is wrong."""

from __future__ import annotations

import contextlib
from pathlib import Path

import pytest
import tomli_w
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.show.script import (
    FormationScene,
    Land,
    Takeoff,
    WriteScene,
    load_script,
    parse_script,
)

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

HEAD = """
[show]
drones = 4
safety_distance = 1.5
[limits]
vmax = 2.0
[[scene]]
type = "takeoff"
"""
TAIL = """
[[scene]]
type = "land"
"""


def test_the_examples_parse() -> None:
    small = load_script(EXAMPLES / "show_small.toml")
    assert small.drones == 10 and small.safety_m == 1.5
    assert isinstance(small.scenes[0], Takeoff) and isinstance(small.scenes[-1], Land)
    assert any(isinstance(s, WriteScene) for s in small.scenes)
    big = load_script(EXAMPLES / "show_100.toml")
    assert big.drones == 100
    assert [type(s).__name__ for s in big.scenes] == [
        "Takeoff", "FormationScene", "WriteScene", "FormationScene", "Land",
    ]  # fmt: skip


def test_colours_and_defaults() -> None:
    s = parse_script(HEAD + '[[scene]]\ntype = "formation"\nshape = "circle"\n'
                     'center = [0, 0, 9]\ncolor = "#ff8000"\n' + TAIL)  # fmt: skip
    f = s.scenes[1]
    assert isinstance(f, FormationScene) and f.color == (255, 128, 0)
    assert s.limits.vmax == 2.0 and s.limits.amax == 2.0
    assert s.home_spacing_m == pytest.approx(1.5 * 2**0.5)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (HEAD + '[[scene]]\ntype = "dance"\n' + TAIL,
         r"scene\[1\]\.type: got 'dance', expected one of takeoff, formation, write, hold, land"),
        (HEAD + '[[scene]]\ntype = "hold"\nduraton = 3\n' + TAIL,
         r"scene\[1\]: got unknown key 'duraton', expected one of type, duration, color"),
        (HEAD.replace("[limits]", "[limit]"),
         r"show script: got unknown key 'limit', expected one of show, limits, scene"),
        (HEAD.replace("1.5", "-1.5") + TAIL,
         r"\[show\]\.safety_distance: got -1\.5"),
        (HEAD + "[[scene]\n", r"show script: got malformed TOML"),
        (HEAD, r"scene\[0\]\.type: got 'takeoff', expected 'land' last"),
        (HEAD + '[[scene]]\ntype = "formation"\nshape = "star"\norigin = [0, 0, 5]\n' + TAIL,
         r"scene\[1\]\.shape: got 'star', expected one of text, svg, grid, circle"),
        (HEAD + '[[scene]]\ntype = "hold"\ncolor = [300, 0, 0]\n' + TAIL,
         r"scene\[1\]\.color: got \[300, 0, 0\], expected three integers"),
    ],
)  # fmt: skip
def test_bad_scripts_are_refused_naming_what(text: str, message: str) -> None:
    with pytest.raises(InputError, match=message):
        parse_script(text)


_VALUES = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-(10**12), 10**12)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.text(max_size=8),
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner, max_size=4)
    ),
    max_leaves=12,
)
_KEYS = st.sampled_from(
    ["type", "shape", "hold", "color", "origin", "center", "size", "text", "radius", "columns",
     "spacing", "duration", "altitude", "stagger", "drones", "font"]
)  # fmt: skip


@settings(max_examples=150, deadline=None)
@given(
    scene=st.dictionaries(_KEYS, _VALUES, max_size=6),
    show=st.dictionaries(
        st.sampled_from(["drones", "safety_distance", "home_spacing", "rate", "home_origin"]),
        _VALUES,
        max_size=4,
    ),
)
def test_random_scripts_give_a_script_or_an_input_error(
    scene: dict[str, object], show: dict[str, object]
) -> None:
    """Hostile values anywhere in a script: parsed, or refused with an InputError, nothing else."""
    data = {
        "show": show,
        "scene": [{"type": "takeoff"}, scene, {"type": "land"}],
    }
    try:
        text = tomli_w.dumps(data)
    except (TypeError, ValueError):
        return  # not representable in TOML (None, NaN keys...)
    with contextlib.suppress(InputError):
        parse_script(text)


def test_a_thousand_drones_are_accepted_and_more_refused() -> None:
    """The ceiling of issue 27: shows of 1,000 drones (was 200); above it, one plain refusal."""
    script = "[show]\ndrones = {n}\nsafety_distance = 1.5\n" + HEAD.split("\n", 4)[4] + TAIL
    assert parse_script(script.format(n=1000)).drones == 1000
    refused = r"^\[show\]\.drones: got 1001, expected an integer from 1 to 1000"
    with pytest.raises(InputError, match=refused):
        parse_script(script.format(n=1001))
