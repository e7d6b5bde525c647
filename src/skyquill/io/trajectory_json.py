"""``trajectory.json``: the exact trajectory of a plan, whatever its kind, for exporters.

``trajectory.csv`` is sampled; exporters that can be exact (Crazyswarm
polynomials, Bézier shows) and the verification of what was written need the
trajectory itself::

    {"format": "skyquill-trajectory", "version": 2,
     "frame": "world, z up, m, s",
     "trajectory": {"kind": "bspline" | "polynomial" | "retimed" | "sequence" | "sampled", ...},
     "pen_windows_s": [[t0, t1], ...],
     "pen_rgb": [[r, g, b], ...],              (optional: one light colour per window)
     "limits": [{"type": "BoxLimit" | "CylinderLimit" | ..., <its fields>}, ...],
     "phases": {"takeoff_s": [0, t1], "mission_s": [t1, t2], "landing_s": [t2, T],
                "min_altitude_m": ..., ...}}      (optional: :class:`~skyquill.phases.FlightPhases`)

(:mod:`skyquill.trajectory.codec` gives each kind's fields.) Version 1 files,
``{"format": "skyquill-bspline", "degree", "duration_s", "control_points"}``,
are still read.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from skyquill.colors import RGB, window_colors
from skyquill.errors import InputError
from skyquill.io.atomic import write_text
from skyquill.io.json_read import parse_json
from skyquill.io.source import read_bytes
from skyquill.limits import BoxLimit, CylinderLimit, DerivativeLimit, NormLimit
from skyquill.phases import MIN_ALTITUDE_M, FlightPhases, flight_phases
from skyquill.trajectory import Trajectory
from skyquill.trajectory.codec import decode, encode
from skyquill.validation import FloatArray, as_array

FORMAT = "skyquill-trajectory"
VERSION = 2
LEGACY_FORMAT = "skyquill-bspline"
#: Largest file read, bytes: a 10 ha coverage flight is ~20 MB.
MAX_BYTES = 500_000_000


@dataclass(frozen=True)
class PlannedTrajectory:
    """A trajectory and when its pen (brush, spray, light) is down.

    Attributes
    ----------
    trajectory
        Any trajectory kind, z-up world frame.
    pen_windows_s
        ``(start, end)`` times in s when the pen is down, in order; empty when
        the task has no pen.
    limits
        The limits it was planned for (every exporter checks what its
        consumer will fly against them).
    pen_rgb
        The light's colour in each pen window, three integers 0..255 each (light
        painting, shows); empty: the exporter's one colour for every window.
    phases
        When it takes off, flies its mission and lands (:mod:`skyquill.phases`), or
        ``None`` when not recorded (an older plan, a CSV): :meth:`flight` computes them.
    """

    trajectory: Trajectory
    pen_windows_s: tuple[tuple[float, float], ...] = ()
    limits: tuple[DerivativeLimit, ...] = ()
    pen_rgb: tuple[RGB, ...] = ()
    phases: FlightPhases | None = None

    def flight(self, min_altitude_m: float = MIN_ALTITUDE_M) -> FlightPhases:
        """The recorded phases, else those of the trajectory at ``min_altitude_m``."""
        return self.phases or flight_phases(self.trajectory, min_altitude_m)

    def __post_init__(self) -> None:
        if self.pen_rgb:
            colors = window_colors("pen_rgb", self.pen_windows_s, self.pen_rgb)
            object.__setattr__(self, "pen_rgb", colors)

    def pen(self, t: Any) -> Any:
        """1.0 where the pen is down at times ``t`` (N,), else 0.0."""
        return pen_down(t, self.pen_windows_s)

    def colors(self, default: RGB) -> tuple[RGB, ...]:
        """The colour of each pen window: :attr:`pen_rgb`, or ``default`` for all."""
        return self.pen_rgb or (default,) * len(self.pen_windows_s)

    def light(self, t: Any, default: RGB) -> NDArray[np.int64]:
        """The light's colour at times ``t`` (N,), s: its window's, black outside (N, 3)."""
        return light_at(t, self.pen_windows_s, self.colors(default))


def pen_down(t: Any, windows: Sequence[tuple[float, float]]) -> FloatArray:
    """1.0 at the times ``t`` (N,) inside one of the ``(start, end)`` ``windows`` (s), else 0.0."""
    times = np.asarray(t, dtype=float)
    down = np.zeros(times.size)
    for start, end in windows:
        down[(times >= start) & (times <= end)] = 1.0
    return down


def light_at(
    t: Any, windows: Sequence[tuple[float, float]], colors: Sequence[RGB]
) -> NDArray[np.int64]:
    """The colour of the window each time ``t`` (N,) falls in, black outside, shape (N, 3)."""
    times = np.asarray(t, dtype=float)
    out = np.zeros((times.size, 3), dtype=np.int64)
    for (start, end), rgb in zip(windows, colors, strict=True):
        out[(times >= start) & (times <= end)] = rgb
    return out


def write_trajectory_json(path: str | Path, planned: PlannedTrajectory) -> None:
    """Write ``planned`` to ``path`` atomically."""
    data = {
        "format": FORMAT,
        "version": VERSION,
        "frame": "world, z up, m, s",
        "trajectory": encode(planned.trajectory),
        "pen_windows_s": [list(w) for w in planned.pen_windows_s],
        **({"pen_rgb": [list(c) for c in planned.pen_rgb]} if planned.pen_rgb else {}),
        "limits": [_encode_limit(lim) for lim in planned.limits],
        **({"phases": planned.phases.as_dict()} if planned.phases is not None else {}),
    }
    write_text(path, json.dumps(data, allow_nan=False) + "\n")


def read_trajectory_json(path: str | Path) -> PlannedTrajectory:
    """Read a ``trajectory.json`` (either version).

    Raises
    ------
    InputError
        Naming the file and what is wrong: missing, too large, not UTF-8 JSON,
        nested too deep, another format, or a malformed trajectory.
    """
    file = Path(path)
    if not file.exists():
        raise InputError(f"trajectory file: got {str(file)!r}, expected an existing JSON file")
    what = f"a {FORMAT} JSON file"
    data = parse_json(read_bytes(file, what, max_bytes=MAX_BYTES, name=file.name), file.name, what)
    try:
        return _planned(data)
    except InputError as exc:
        raise InputError(f"{file.name}: {exc}") from None


def _planned(data: object) -> PlannedTrajectory:
    if not isinstance(data, dict):
        raise InputError(f"got a JSON {type(data).__name__}, expected an object")
    if data.get("format") == LEGACY_FORMAT:
        return PlannedTrajectory(decode({"kind": "bspline", **data}), _windows(data))
    if data.get("format") != FORMAT:
        raise InputError(f"got format {data.get('format')!r}, expected {FORMAT!r}")
    limits = data.get("limits", [])
    if not isinstance(limits, list):
        raise InputError(f"limits: got a JSON {type(limits).__name__}, expected a list")
    windows = _windows(data)
    colors = data.get("pen_rgb", [])
    phases = data.get("phases")
    return PlannedTrajectory(
        decode(data.get("trajectory")),
        windows,
        tuple(_decode_limit(item) for item in limits),
        window_colors("pen_rgb", windows, colors) if colors != [] else (),
        None if phases is None else FlightPhases.from_dict(phases),
    )


#: The limit shapes ``trajectory.json`` stores, by class name.
LIMIT_TYPES: dict[str, type] = {cls.__name__: cls for cls in (BoxLimit, CylinderLimit, NormLimit)}


def _encode_limit(limit: DerivativeLimit) -> dict[str, Any]:
    fields = {f.name: getattr(limit, f.name) for f in dataclasses.fields(limit) if f.init}
    plain = {k: v.tolist() if isinstance(v, np.ndarray) else v for k, v in fields.items()}
    return {"type": type(limit).__name__, **plain}


def _decode_limit(data: object) -> DerivativeLimit:
    if not isinstance(data, dict) or data.get("type") not in LIMIT_TYPES:
        got = data.get("type") if isinstance(data, dict) else type(data).__name__
        raise InputError(f"limits: got {got!r}, expected one of {sorted(LIMIT_TYPES)}")
    cls = LIMIT_TYPES[data["type"]]
    names = {f.name for f in dataclasses.fields(cls) if f.init}
    try:
        limit: DerivativeLimit = cls(**{k: v for k, v in data.items() if k in names})
    except TypeError:
        raise InputError(f"limits: got fields {sorted(data)}, expected {sorted(names)}") from None
    return limit


def _windows(data: dict[str, Any]) -> tuple[tuple[float, float], ...]:
    raw = data.get("pen_windows_s", [])
    if isinstance(raw, list) and not raw:
        return ()
    windows = as_array("pen_windows_s", raw, shape=(None, 2))
    if np.any(windows[:, 1] < windows[:, 0]) or np.any(windows[1:, 0] < windows[:-1, 1]):
        raise InputError("pen_windows_s: got overlapping or reversed windows, expected in order")
    return tuple((float(a), float(b)) for a, b in windows)
