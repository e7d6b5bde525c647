"""Skybrush light programs: written for the pen windows, read back by a copy of its player."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skyquill.colors import check_rgb
from skyquill.errors import InputError
from skyquill.export.skybrush import lights
from skyquill.export.skybrush.lights import (
    LightSlice,
    colored_frames,
    encode_light_program,
    light_colors,
    light_slices,
    lights_json,
    longest_mismatch_ms,
    program_bytes,
)
from skyquill.io.trajectory_json import light_at


def frame_windows(windows: list[tuple[float, float]]) -> list[tuple[int, int]]:
    """The light windows (20 ms frames) of pen windows of one colour."""
    return [(a, b) for a, b, _ in colored_frames(windows, [(1, 1, 1)] * len(windows))]


RGB = (255, 40, 0)


def lit(program: bytes, end_ms: float) -> np.ndarray:
    t = np.arange(0.0, end_ms + 1)
    return np.all(light_colors(light_slices("p", program, end_ms), t) == RGB, axis=1)


def test_the_light_is_on_exactly_in_the_frame_rounded_pen_windows() -> None:
    windows = [(0.5, 1.234), (2.0, 2.011), (10.0, 12.5)]  # 12.5 s: a duration over 127 frames
    program = encode_light_program(windows, RGB, 14.0)
    on = lit(program, 14_000)
    expected = np.zeros_like(on)
    for a, b in frame_windows(windows):
        expected[a * 20 : b * 20] = True  # the slice [a, b) frames; at b the next slice wins
    assert np.array_equal(on, expected)
    assert frame_windows(windows) == [(25, 62), (100, 101), (500, 625)]
    # every switch within half a frame of the pen
    for (a, b), (fa, fb) in zip(windows, frame_windows(windows), strict=True):
        assert abs(fa * 20 - a * 1000) <= 10 and abs(fb * 20 - b * 1000) <= 10


def test_short_windows_vanish_and_touching_ones_merge() -> None:
    assert frame_windows([(1.0, 1.005)]) == []
    assert frame_windows([(1.0, 1.2), (1.2, 1.5)]) == [(50, 75)]


def test_a_fade_and_a_loop_are_read_as_skybrush_reads_them() -> None:
    # fade to white in 50 frames (1 s), then twice: set red 1 frame, black 1 frame; end
    program = bytes([11, 50, 12, 2, 4, 255, 0, 0, 1, 6, 1, 13, 0])
    slices = light_slices("p", program, 10_000)
    colors = light_colors(slices, np.array([500.0, 1000.0, 1010.0, 1030.0, 1050.0, 1070.0, 5000.0]))
    np.testing.assert_allclose(colors[0], [127.5] * 3)
    np.testing.assert_allclose(
        colors[1:], [[255, 0, 0], [255, 0, 0], [0, 0, 0], [255, 0, 0], [0, 0, 0], [0, 0, 0]]
    )


def test_the_json_object_round_trips() -> None:
    program = encode_light_program([(0.1, 0.3)], RGB, 1.0)
    assert program_bytes("l", lights_json(program)) == program


@pytest.mark.parametrize(
    ("program", "match"),
    [
        (bytes([4, 255, 0]), r"ends inside a command at byte 3"),
        (bytes([99]), r"got light command 99 at byte 0"),
        (bytes([13]), r"got a loop end at byte 1"),
        (bytes([12, 0, 1, 13]), r"still running after 1,000 commands"),
        (bytes([2, 255, 255, 255, 255, 255, 1]), r"duration over 5 bytes"),
    ],
)
def test_a_broken_program_is_an_input_error(
    program: bytes, match: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(lights, "MAX_STEPS", 1000)  # a loop of nothing runs forever
    with pytest.raises(InputError, match=match):
        light_slices("p", program, 1e9)


@pytest.mark.parametrize(
    ("lights", "match"),
    [
        ({"version": 2, "data": ""}, r"l: got"),
        ({"version": 1, "data": "not base64!"}, r"l.data: got 'not base64!', expected base64"),
        ({"version": 1, "data": 5}, r"l.data: got 5, expected a base64 string"),
    ],
)
def test_a_broken_lights_object_is_an_input_error(lights: object, match: str) -> None:
    with pytest.raises(InputError, match=match):
        program_bytes("l", lights)


@pytest.mark.parametrize("rgb", [(256, 0, 0), (0, 0), (1.0, 2, 3), "red", (True, 0, 0), (-1, 0, 0)])
def test_a_bad_colour_is_named(rgb: object) -> None:
    with pytest.raises(InputError, match=r"light_rgb: got .*expected three integers in 0..255"):
        check_rgb("light_rgb", rgb)


def test_touching_windows_of_two_colours_switch_on_the_frame() -> None:
    red, blue = (255, 0, 0), (0, 0, 255)
    windows = [(1.0, 1.2), (1.2, 1.5), (2.0, 2.4)]
    frames = lights.colored_frames(windows, [red, blue, blue])
    assert frames == [(50, 60, red), (60, 75, blue), (100, 120, blue)]
    program = encode_light_program(windows, [red, blue, blue], 3.0)
    colors = light_colors(light_slices("p", program, 3000), np.array([1100.0, 1300.0, 1700.0]))
    np.testing.assert_array_equal(colors, [red, blue, (0, 0, 0)])


@pytest.mark.parametrize(
    ("colors", "message"),
    [
        ([(1, 2, 3)], r"rgb: got 1 colours, expected one per pen window \(2\)"),
        ([(1, 2, 3), (1, 2, 300)], r"rgb\[1\]: got \(1, 2, 300\), expected three integers"),
        ("red", "expected one R, G, B triple per pen window"),
    ],
)
def test_bad_colours_per_window_are_named(colors: object, message: str) -> None:
    with pytest.raises(InputError, match=message):
        encode_light_program([(0.0, 1.0), (2.0, 3.0)], colors, 4.0)  # type: ignore[arg-type]


def _every_millisecond(
    slices: list[LightSlice],
    windows: list[tuple[float, float]],
    colors: list[tuple[int, int, int]],
    end_ms: int,
) -> int:
    """The longest run of wrong milliseconds, comparing every one of them."""
    t = np.arange(0.0, end_ms + 1)
    wrong = np.any(light_colors(slices, t) != light_at(t / 1000, windows, colors), axis=1)
    runs = np.diff(np.flatnonzero(np.diff(np.concatenate([[0], wrong.astype(int), [0]]))))[::2]
    return int(runs.max()) if runs.size else 0


@settings(max_examples=80, deadline=None)
@given(seed=st.integers(0, 10**6), fades=st.booleans())
def test_the_longest_mismatch_is_what_every_millisecond_compared_finds(
    seed: int, fades: bool
) -> None:
    rng = np.random.default_rng(seed)
    palette = [(255, 0, 0), (0, 255, 0), (255, 255, 255)]
    cuts = np.sort(rng.uniform(0.0, 4000.0, int(rng.integers(1, 8))))
    slices = [LightSlice(0.0, 0.0, (0.0, 0.0, 0.0), None)]
    for a, b in itertools.pairwise([*cuts.tolist(), 4000.0]):
        rgb = tuple(float(c) for c in palette[int(rng.integers(0, 3))])
        end = tuple(float(c) for c in palette[int(rng.integers(0, 3))]) if fades else None
        slices.append(LightSlice(a, b, rgb, end))  # type: ignore[arg-type]
    slices.append(LightSlice(4000.0, np.inf, (0.0, 0.0, 0.0), None))
    # windows near the slices' edges (off by whole and fractional milliseconds)
    edges = np.sort(rng.choice(cuts, 2 * int(rng.integers(0, 4))) / 1000)
    edges = edges + rng.choice([0.0, 0.001, -0.001, 0.0004, 1e-12], edges.size)
    windows = [(float(a), float(b)) for a, b in edges.reshape(-1, 2) if b >= a]
    colors = [palette[int(rng.integers(0, 3))] for _ in windows]
    end_ms = int(rng.integers(1, 4500))
    assert longest_mismatch_ms(slices, windows, colors, end_ms) == _every_millisecond(
        slices, windows, colors, end_ms
    )


def test_a_program_written_for_the_pen_switches_within_a_frame() -> None:
    windows = [(0.5, 1.2), (1.25, 2.0)]
    colors: list[tuple[int, int, int]] = [(255, 0, 0), (0, 0, 255)]
    slices = light_slices("t", encode_light_program(windows, colors, 3.0), 3000.0)
    offset = longest_mismatch_ms(slices, windows, colors, 3000)
    assert offset == _every_millisecond(slices, windows, colors, 3000)
    assert 0 < offset <= 20
