"""Every trajectory kind to and from a JSON-ready dictionary that names its kind.

``trajectory.json`` (:mod:`skyquill.io.trajectory_json`) stores
``{"kind": ..., ...}``; this module is the one place that knows each kind's
fields. A new kind of trajectory adds its file and one entry to :data:`CODECS`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.interpolate import BSpline

from skyquill.errors import InputError
from skyquill.trajectory.base import Trajectory
from skyquill.trajectory.polynomial import PiecewisePolynomial
from skyquill.trajectory.retimed import RetimedPath
from skyquill.trajectory.sampled import SampledTrajectory
from skyquill.trajectory.sequence import RestToRestSequence
from skyquill.trajectory.spline import SplineTrajectory

#: Nesting depth accepted for sequences of sequences (a hostile file is not a stack overflow).
MAX_DEPTH = 8


@dataclass(frozen=True)
class Codec:
    """How one kind becomes a dictionary and back."""

    kind: str
    cls: type
    encode: Callable[[Any], dict[str, Any]]
    decode: Callable[[dict[str, Any], int], Trajectory]


def _array(data: dict[str, Any], key: str) -> Any:
    if key not in data:
        raise InputError(f"trajectory {data.get('kind')!r}: got no {key!r} field, expected one")
    try:
        # No dtype here: asarray(..., dtype=float) would turn the string "1" into 1.0.
        raw = np.asarray(data[key])
    except (TypeError, ValueError, OverflowError):
        raw = None
    if raw is None or (raw.size and raw.dtype.kind not in "iuf"):
        raise InputError(
            f"trajectory {data.get('kind')!r}, field {key!r}: got a ragged or non-numeric "
            "array, expected a rectangular array of numbers"
        )
    return raw.astype(float)


def _encode_spline(traj: SplineTrajectory) -> dict[str, Any]:
    return {
        "degree": traj.degree,
        "duration_s": traj.duration,
        "control_points": traj.control_points.tolist(),
    }


def _decode_spline(data: dict[str, Any], depth: int) -> Trajectory:
    ctrl = _array(data, "control_points")
    # SplineTrajectory validates degree and duration, naming them.
    degree: Any = data.get("degree")
    duration: Any = data.get("duration_s")
    return SplineTrajectory(ctrl, degree, duration)


def _encode_polynomial(traj: PiecewisePolynomial) -> dict[str, Any]:
    out: dict[str, Any] = {"breaks": traj.breaks.tolist(), "coeffs": traj.coeffs.tolist()}
    if traj.yaw_coeffs is not None:
        out["yaw_coeffs"] = traj.yaw_coeffs.tolist()
    return out


def _decode_polynomial(data: dict[str, Any], depth: int) -> Trajectory:
    yaw = _array(data, "yaw_coeffs") if "yaw_coeffs" in data else None
    return PiecewisePolynomial(_array(data, "breaks"), _array(data, "coeffs"), yaw)


def _encode_retimed(traj: RetimedPath) -> dict[str, Any]:
    return {
        "curve": {
            "knots": np.asarray(traj.curve.t).tolist(),
            "coefficients": np.asarray(traj.curve.c).tolist(),
            "degree": int(traj.curve.k),
        },
        "timing": _encode_polynomial(traj.timing),
    }


def _decode_retimed(data: dict[str, Any], depth: int) -> Trajectory:
    curve, timing = data.get("curve"), data.get("timing")
    if not isinstance(curve, dict) or not isinstance(timing, dict):
        raise InputError("trajectory 'retimed': got no 'curve' and 'timing' objects, expected both")
    curve = {"kind": "retimed curve", **curve}
    knots, coefficients = _array(curve, "knots"), _array(curve, "coefficients")
    degree = curve.get("degree")
    if not isinstance(degree, int) or not 1 <= degree <= 7:
        raise InputError(f"trajectory 'retimed', curve degree: got {degree!r}, expected 1 to 7")
    n_coef = coefficients.shape[0] if coefficients.ndim == 2 else -1
    if knots.ndim != 1 or knots.size != n_coef + degree + 1 or np.any(np.diff(knots) < 0):
        raise InputError(
            f"trajectory 'retimed', curve: got {knots.size} knots for {n_coef} coefficient rows "
            f"of degree {degree}, expected rows + degree + 1 non-decreasing knots"
        )
    spline = BSpline(knots, coefficients, degree)
    poly = _decode_polynomial({"kind": "retimed timing", **timing}, depth)
    assert isinstance(poly, PiecewisePolynomial)
    return RetimedPath(spline, poly)


def _encode_sequence(traj: RestToRestSequence) -> dict[str, Any]:
    return {"pieces": [encode(p) for p in traj.pieces]}


def _decode_sequence(data: dict[str, Any], depth: int) -> Trajectory:
    pieces = data.get("pieces")
    if not isinstance(pieces, list) or not pieces:
        raise InputError("trajectory 'sequence': got no 'pieces' list, expected one or more")
    return RestToRestSequence(tuple(decode(p, depth + 1) for p in pieces))


def _encode_sampled(traj: SampledTrajectory) -> dict[str, Any]:
    out = {"t": (traj.t - traj.t0).tolist(), "p": traj.p.tolist(), "v": traj.v.tolist()}
    out["a"] = traj.a.tolist()
    if traj.j is not None:
        out["j"] = traj.j.tolist()
    return out


def _decode_sampled(data: dict[str, Any], depth: int) -> Trajectory:
    j = _array(data, "j") if "j" in data else None
    return SampledTrajectory(
        _array(data, "t"), _array(data, "p"), _array(data, "v"), _array(data, "a"), j
    )


CODECS: tuple[Codec, ...] = (
    Codec("bspline", SplineTrajectory, _encode_spline, _decode_spline),
    Codec("polynomial", PiecewisePolynomial, _encode_polynomial, _decode_polynomial),
    Codec("retimed", RetimedPath, _encode_retimed, _decode_retimed),
    Codec("sequence", RestToRestSequence, _encode_sequence, _decode_sequence),
    Codec("sampled", SampledTrajectory, _encode_sampled, _decode_sampled),
)
KINDS = tuple(c.kind for c in CODECS)


def encode(traj: Trajectory) -> dict[str, Any]:
    """``{"kind": ..., <fields>}`` for any trajectory kind of :data:`CODECS`."""
    for codec in CODECS:
        if isinstance(traj, codec.cls):
            return {"kind": codec.kind, **codec.encode(traj)}
    raise InputError(f"trajectory: got a {type(traj).__name__}, expected one of the kinds {KINDS}")


def decode(data: object, depth: int = 0) -> Trajectory:
    """The trajectory a dictionary of :func:`encode` describes; :class:`InputError` if malformed."""
    if depth > MAX_DEPTH:
        raise InputError(
            f"trajectory: got sequences nested deeper than {MAX_DEPTH}, expected fewer"
        )
    if not isinstance(data, dict):
        raise InputError(f"trajectory: got a JSON {type(data).__name__}, expected an object")
    kind = data.get("kind")
    for codec in CODECS:
        if codec.kind == kind:
            return codec.decode(data, depth)
    raise InputError(f"trajectory kind: got {kind!r}, expected one of {KINDS}")
