"""Skybrush light programs: pen down lights a colour, pen up is black, in Skybrush's bytecode.

The format (skybrush-io/libskybrush ``src/lights/commands.h`` and ``executor.cpp``; the player
of Skybrush Live, skybrush-io/skybrush.js ``packages/show-format/src/lights.ts``) is a byte
string of commands. Durations are unsigned variable-length integers (7 bits a byte, least
significant first, the high bit set on every byte but the last) counting **20 ms frames**:
the lights switch on a 50 Hz clock, so a pen window's ends are rounded to the nearest frame
(at most 10 ms off). A ``.skyc`` keeps the program base64-encoded in a drone's settings:
``"lights": {"version": 1, "data": "..."}``.

:func:`light_slices` is a copy of ``lights.ts``'s executor and player, so the export checks
the colours Skybrush shows, not the windows it meant.
"""

from __future__ import annotations

import base64
import binascii
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from skyquill.colors import RGB, check_rgb, is_rgb, window_colors
from skyquill.errors import InputError
from skyquill.io.trajectory_json import light_at
from skyquill.validation import FloatArray

#: One light-program frame, ms (libskybrush executor.cpp: ``durationInHalfFrames * 20``).
FRAME_MS = 20
#: Commands the encoder writes.
END, SLEEP, WAIT_UNTIL, SET_COLOR, SET_GRAY, SET_BLACK, SET_WHITE = 0, 2, 3, 4, 5, 6, 7
FADE_TO_COLOR, FADE_TO_GRAY, FADE_TO_BLACK, FADE_TO_WHITE = 8, 9, 10, 11
LOOP_BEGIN, LOOP_END, NOP, SET_PYRO, SET_PYRO_ALL = 12, 13, 1, 20, 21
#: Most commands executed when reading a program back (a loop of zero-length commands
#: would run forever).
MAX_STEPS = 1_000_000
#: Largest program read back, bytes (Skybrush's binary block holds 65535).
MAX_PROGRAM_BYTES = 65_535


def colored_frames(
    windows_s: Sequence[tuple[float, float]], colors: Sequence[RGB]
) -> list[tuple[int, int, RGB]]:
    """Pen windows (s) and their colours as light windows on the 20 ms frame clock.

    Ends are rounded to the nearest frame; a window shorter than half a frame vanishes
    (Skybrush cannot show it); windows that touch or overlap after rounding merge when
    they have the same colour, else the later one starts where it starts and the earlier
    one ends there.
    """
    out: list[tuple[int, int, RGB]] = []
    for (a, b), rgb in sorted(zip(windows_s, colors, strict=True)):
        start, end = round(a * 1000 / FRAME_MS), round(b * 1000 / FRAME_MS)
        if end <= start:
            continue
        if out and start <= out[-1][1]:
            before, stop, color = out.pop()
            if color == rgb:
                start, end = before, max(stop, end)
            elif start > before:
                out.append((before, start, color))
        out.append((start, end, rgb))
    return out


def _varuint(value: int) -> bytes:
    out = bytearray()
    while value >= 0x80:
        out.append((value & 0x7F) | 0x80)
        value >>= 7
    out.append(value)
    return bytes(out)


def encode_light_program(
    windows_s: Sequence[tuple[float, float]], colors: RGB | Sequence[RGB], duration_s: float
) -> bytes:
    """Bytecode: black, then each pen window in its colour, black until ``duration_s``.

    Parameters
    ----------
    windows_s
        Pen-down windows ``(start, end)`` on the show clock, s.
    colors
        The pen-down colour (three integers in 0..255), or one per window.
    duration_s
        Length of the show, s (the program ends black at least one frame after the last
        window).
    """
    per_window = (
        (check_rgb("rgb", colors),) * len(windows_s)
        if is_rgb(colors)
        else window_colors("rgb", windows_s, colors)
    )
    program = bytearray()
    now = 0
    for start, end, rgb in colored_frames(windows_s, per_window):
        if start > now:
            program += bytes([SET_BLACK]) + _varuint(start - now)
        program += bytes([SET_COLOR, *rgb]) + _varuint(end - start)
        now = end
    last = max(now + 1, round(duration_s * 1000 / FRAME_MS))
    program += bytes([SET_BLACK]) + _varuint(last - now) + bytes([END])
    return bytes(program)


def lights_json(program: bytes) -> dict[str, Any]:
    """The ``lights`` object of a drone's settings in ``show.json``."""
    return {"version": 1, "data": base64.b64encode(program).decode("ascii")}


def program_bytes(where: str, lights: Any) -> bytes:
    """The bytecode of a ``lights`` object of ``show.json``; :class:`InputError` when malformed."""
    if not isinstance(lights, dict) or lights.get("version") != 1:
        raise InputError(f"{where}: got {lights!r:.60}, expected {{'version': 1, 'data': base64}}")
    data = lights.get("data")
    if not isinstance(data, str) or len(data) > 2 * MAX_PROGRAM_BYTES:
        raise InputError(f"{where}.data: got {data!r:.40}, expected a base64 string")
    try:
        return base64.b64decode(data, validate=True)
    except (binascii.Error, ValueError):
        raise InputError(f"{where}.data: got {data!r:.40}, expected base64") from None


@dataclass(frozen=True)
class LightSlice:
    """A time interval of the light program: constant, or a linear fade.

    Attributes
    ----------
    start_ms, end_ms
        The interval on the show clock, ms (closed: a later slice wins at a shared end).
    start_rgb, end_rgb
        Colour at the start, and at the end for a fade (``None``: constant), 0..255.
    """

    start_ms: float
    end_ms: float
    start_rgb: tuple[float, float, float]
    end_rgb: tuple[float, float, float] | None


class _Reader:
    """``createLightProgramExecutor`` of ``lights.ts``: the state machine over the bytes."""

    def __init__(self, where: str, data: bytes) -> None:
        self.where, self.data, self.index = where, data, 0
        self.end_ms = 0.0
        self.start = [0.0, 0.0, 0.0]
        self.fade_to: list[float] | None = None

    def byte(self) -> int:
        if self.index >= len(self.data):
            raise InputError(
                f"{self.where}: got a light program that ends inside a command at byte "
                f"{self.index}, expected complete commands"
            )
        value = self.data[self.index]
        self.index += 1
        return value

    def frames_ms(self) -> float:
        value, shift = 0, 0
        while True:
            byte = self.byte()
            value |= (byte & 0x7F) << shift
            shift += 7
            if byte < 0x80:
                return float(value * FRAME_MS)
            if shift >= 35:
                raise InputError(f"{self.where}: got a duration over 5 bytes at byte {self.index}")

    def advance(self, ms: float) -> None:
        if self.fade_to is not None:  # a fade ends on its target colour
            self.start, self.fade_to = self.fade_to, None
        self.end_ms += ms

    def snapshot(self, start: float) -> LightSlice:
        fade = None if self.fade_to is None else tuple(self.fade_to)
        return LightSlice(start, self.end_ms, tuple(self.start), fade)  # type: ignore[arg-type]


def light_slices(where: str, data: bytes, horizon_ms: float) -> list[LightSlice]:
    """The slices Skybrush's player builds from ``data``, up to ``horizon_ms`` (then held).

    Raises
    ------
    InputError
        On an unknown command, a truncated command, a loop end without a loop, more than
        :data:`MAX_STEPS` commands, or more than :data:`MAX_PROGRAM_BYTES` bytes.
    """
    if len(data) > MAX_PROGRAM_BYTES:
        raise InputError(
            f"{where}: got {len(data):,} bytes, expected at most {MAX_PROGRAM_BYTES:,}"
        )
    reader = _Reader(where, data)
    slices = [LightSlice(0.0, 0.0, (0.0, 0.0, 0.0), None)]
    loops: list[list[float]] = []
    for _ in range(MAX_STEPS):
        if reader.index >= len(data) or reader.end_ms > horizon_ms:
            break
        command = reader.byte()
        if command == END:
            break
        duration = _step(reader, command, loops)
        if duration > 0:
            slices.append(reader.snapshot(reader.end_ms - duration))
    else:
        raise InputError(f"{where}: got a light program still running after {MAX_STEPS:,} commands")
    last = slices[-1]
    slices.append(LightSlice(last.end_ms, np.inf, last.end_rgb or last.start_rgb, None))
    return slices


def _step(reader: _Reader, command: int, loops: list[list[float]]) -> float:
    """Execute one command (``lights.ts`` ``execute``); its duration, ms."""
    if command in (SET_COLOR, FADE_TO_COLOR):
        color = [float(reader.byte()) for _ in range(3)]
    elif command in (SET_GRAY, FADE_TO_GRAY):
        color = [float(reader.byte())] * 3
    else:
        color = {SET_BLACK: [0.0] * 3, FADE_TO_BLACK: [0.0] * 3}.get(command, [255.0] * 3)
    if command in (SET_COLOR, SET_GRAY, SET_BLACK, SET_WHITE):
        duration = reader.frames_ms()
        reader.advance(duration)
        reader.start = color
        return duration
    if command in (FADE_TO_COLOR, FADE_TO_GRAY, FADE_TO_BLACK, FADE_TO_WHITE):
        duration = reader.frames_ms()
        reader.advance(duration)
        reader.fade_to = color
        return duration
    if command == SLEEP:
        duration = reader.frames_ms()
        if duration > 0:
            reader.advance(duration)
        return duration
    if command == WAIT_UNTIL:
        # lights.ts leaves the waiting time without a slice; the firmware holds the colour,
        # and so does this copy
        duration = max(reader.end_ms, reader.frames_ms()) - reader.end_ms
        if duration > 0:
            reader.advance(duration)
            reader.advance(0.0)
        return duration
    if command == LOOP_BEGIN:
        count = reader.byte()
        loops.append([float(reader.index), float(count) if count > 0 else np.inf])
        return 0.0
    if command == LOOP_END:
        if not loops:
            raise InputError(
                f"{reader.where}: got a loop end at byte {reader.index}, expected a loop"
            )
        loops[-1][1] -= 1
        if loops[-1][1]:
            reader.index = int(loops[-1][0])
        else:
            loops.pop()
        return 0.0
    if command in (SET_PYRO, SET_PYRO_ALL):
        reader.byte()
        return 0.0
    if command == NOP:
        return 0.0
    raise InputError(
        f"{reader.where}: got light command {command} at byte {reader.index - 1}, expected one "
        "Skybrush Live plays (0-13, 20, 21)"
    )


def light_colors(slices: Sequence[LightSlice], t_ms: FloatArray) -> FloatArray:
    """Colours at show times ``t_ms`` (N,), ms, as ``evaluateColorAt`` finds them, (N, 3), 0..255.

    The slices are contiguous, so the last one that contains ``t`` (``lights.ts`` scans from
    the back) is the last one starting at or before it.
    """
    t = np.asarray(t_ms, dtype=float)
    starts = np.array([s.start_ms for s in slices])
    i = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(slices) - 1)
    first = np.array([s.start_rgb for s in slices])[i]
    last = np.array([s.end_rgb if s.end_rgb is not None else s.start_rgb for s in slices])[i]
    length = np.array([s.end_ms - s.start_ms for s in slices])[i]
    ratio = np.divide(
        t - starts[i], length, out=np.zeros_like(t), where=np.isfinite(length) & (length > 0)
    )
    return np.asarray(first + ratio[:, None] * (last - first))


def longest_mismatch_ms(
    slices: Sequence[LightSlice],
    windows: Sequence[tuple[float, float]],
    colors: Sequence[RGB],
    end_ms: int,
) -> int:
    """The longest run of whole milliseconds ``0..end_ms`` where the light differs from the pen's.

    What comparing :func:`light_colors` with the pen's colour (the colour of the window
    each ``t / 1000`` s falls in, a later window winning, black outside:
    :func:`skyquill.io.trajectory_json.light_at`) on every millisecond finds, from the
    milliseconds where either can change: between two of them both are constant (but
    in a fade, where every millisecond is compared). A thousand drones over five
    minutes were 300 million comparisons; this is a few hundred per drone.
    """
    starts = [math.ceil(sl.start_ms) for sl in slices if math.isfinite(sl.start_ms)]
    edges = {0, end_ms + 1, *starts}
    for a, b in windows:
        edges |= {_first_at_or_after(a), _last_at_or_before(b) + 1}
    cuts = np.array(sorted(e for e in edges if 0 <= e <= end_ms + 1), dtype=float)
    fades = [sl for sl in slices if sl.end_rgb is not None and sl.end_rgb != sl.start_rgb]
    # every millisecond of a fade, one representative of every other stretch
    dense = [np.arange(max(0, math.ceil(f.start_ms)), min(end_ms, f.end_ms) + 1) for f in fades]
    t = np.unique(np.concatenate([cuts[:-1], *dense])) if dense else cuts[:-1]
    wrong = np.any(light_colors(slices, t) != light_at(t / 1000, windows, colors), axis=1)
    # each sample stands for the milliseconds up to the next one
    length = np.diff(np.append(t, end_ms + 1))
    runs, current = 0.0, 0.0
    for bad, ms in zip(wrong.tolist(), length.tolist(), strict=True):
        current = current + ms if bad else 0.0
        runs = max(runs, current)
    return int(runs)


def _first_at_or_after(seconds: float) -> int:
    """The first whole millisecond ``t`` with ``t / 1000 >= seconds`` in float arithmetic."""
    t = math.ceil(seconds * 1000)
    while (t - 1) / 1000 >= seconds:
        t -= 1
    while t / 1000 < seconds:
        t += 1
    return t


def _last_at_or_before(seconds: float) -> int:
    """The last whole millisecond ``t`` with ``t / 1000 <= seconds`` in float arithmetic."""
    t = math.floor(seconds * 1000)
    while (t + 1) / 1000 <= seconds:
        t += 1
    while t / 1000 > seconds:
        t -= 1
    return t
