"""``trajectory.json``: the exact spline of a planned trajectory, for exporters.

``trajectory.csv`` is sampled; exporters that can be exact (Crazyswarm
polynomials, Bézier shows) need the spline itself:
``{"format": "skyquill-bspline", "version": 1, "degree": k, "duration_s": T,
"control_points": [[x, y, z], ...], "frame": "..."}`` (clamped uniform knots,
paper 003 eq. 4; 2-D splines are stored with z = 0).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from skyquill.errors import InputError
from skyquill.trajectory import SplineTrajectory

FORMAT = "skyquill-bspline"


def write_spline_json(path: str | Path, traj: SplineTrajectory, **extra: Any) -> None:
    """Write ``traj`` (padded to 3-D) and any ``extra`` JSON-able fields."""
    ctrl = traj.control_points
    if ctrl.shape[1] == 2:
        ctrl = np.column_stack([ctrl, np.zeros(len(ctrl))])
    data = {
        "format": FORMAT,
        "version": 1,
        "degree": traj.degree,
        "duration_s": traj.duration,
        "frame": "world, z up, m, s; clamped uniform B-spline (paper 003 eq. 4)",
        "control_points": ctrl.tolist(),
        **extra,
    }
    Path(path).write_text(json.dumps(data) + "\n", encoding="utf-8")


def read_spline_json(path: str | Path) -> SplineTrajectory:
    """Read a ``trajectory.json``; :class:`InputError` naming the file and field if malformed."""
    file = Path(path)
    if not file.is_file():
        raise InputError(f"trajectory file: got {str(file)!r}, expected an existing JSON file")
    try:
        data = json.loads(file.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{file.name}: got invalid JSON ({exc}), expected {FORMAT}") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise InputError(f"{file.name}: got no 'format': {FORMAT!r} field, expected a spline")
    try:
        return SplineTrajectory(
            np.asarray(data["control_points"], dtype=float), data["degree"], data["duration_s"]
        )
    except KeyError as exc:
        raise InputError(f"{file.name}: got no {exc.args[0]!r} field, expected one") from None
    except (TypeError, ValueError) as exc:
        raise InputError(f"{file.name}: {exc}") from None
