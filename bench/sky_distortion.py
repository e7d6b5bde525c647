"""Light painting seen from the side: distortion with and without the plane cost (paper 003 §5.3).

Run from the repository root::

    .venv/bin/python bench/sky_distortion.py     # ~1 minute

It writes ``bench/results/sky_distortion.json`` and ``docs/images/sky_distortion.png``
(three orthographic views, 0°, 55° and 90° about the board's vertical axis, as
paper 003's Fig. 8, with and without the plane cost) and prints the table.
BLAS is pinned to one thread. Distortion: the image-plane distance of the light
path (pen-on samples) from the intended strokes, both projected, max and RMS, mm
(:mod:`skyquill.calligraphy.distortion`); ``off_plane`` is ``|h|``, the path's
distance from the plane itself.

Cases:

* ``M``: paper 003 Fig. 8's M. Its five vertices (2 x 2 m) on a sky board at
  yaw 35°, tilt 25°: the two ends are rest boundary conditions, the three inner
  ones position points (weight 1e5) at equal times over 8 s; per-axis speed
  1.2 m/s and acceleration 1.5 m/s^2 (axis-decoupled boxes, paper 003 §5.3);
  degree 5, jerk cost, 0.05 s knot spans. The boxes bind (z speed and
  acceleration at their limits), at different times on each axis, so the path
  leaves the plane: the plane is not aligned with the boxes. ``M-aligned``:
  the same on an unturned board (yaw 0, tilt 0), the control: the boxes are
  then symmetric about the plane, so the optimum is in it with or without the
  cost. Plane cost: 0 and 1e5 (weight sweep 1e3..1e6 in ``M_sweep``).
* ``word``: ``skyquill write "light" --board sky --size 1`` on a board at yaw
  30°, tilt 20°, 2 m up, home 2 m in front on the ground, through
  :func:`plan_writing`, with the default norm limits (1 m/s, 2 m/s^2,
  10 m/s^3, cones) and with the same numbers per axis; plane weight 0 and
  the default :data:`~skyquill.calligraphy.mission.PLANE_WEIGHT`, and the
  sweep that chose it (``word_sweep``: per-axis limits, 0..1e6).
"""

from __future__ import annotations

import json
import sys
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits

from skyquill.calligraphy.board import Board, sky_board
from skyquill.calligraphy.distortion import (
    VIEW_ANGLES_DEG,
    mission_distortion,
    project,
    view_distortion,
)
from skyquill.calligraphy.mission import PLANE_WEIGHT, Mission, WritingOptions, plan_writing
from skyquill.limits import VehicleLimits
from skyquill.optimize import Boundary, PlaneDeviation, PointDeviation, SmoothingProblem, solve
from skyquill.strokes import typed_strokes

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import jsonable, machine_info

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results" / "sky_distortion.json"
FIGURE = ROOT / "docs" / "images" / "sky_distortion.png"

M_VERTICES = np.array([[0.0, 0.0], [0.5, 2.0], [1.0, 0.8], [1.5, 2.0], [2.0, 0.0]])
M_DURATION_S = 8.0
M_WEIGHT = 1e5
WEIGHTS = (0.0, 1e3, 1e4, 1e5, 1e6)
WORD = "light"


def m_path(board: Board, weight: float) -> tuple[np.ndarray, np.ndarray, float]:
    """The M on ``board`` with plane cost ``weight``: samples (K, 3), vertices (5, 3), miss m."""
    P = board.to_world(M_VERTICES)
    T = M_DURATION_S
    t = np.linspace(0.0, T, len(P))
    deviations: tuple[Any, ...] = (PointDeviation(t[1:-1], P[1:-1], 1e5),)
    if weight > 0:
        deviations += (PlaneDeviation(board.normal, board.origin, 0.0, T, weight),)
    limits = VehicleLimits(None, None, None, 1.2, 1.5, None).derivative_limits(3)
    problem = SmoothingProblem(
        3, 5, round(T / 0.05) + 5, T, {3: 1.0}, deviations,
        boundary=Boundary.rest(P[0], P[-1], 3), limits=limits,
    )  # fmt: skip
    fit = solve(problem)
    assert fit.verification.max_excess <= 1e-9
    miss = float(np.linalg.norm(fit.trajectory.evaluate(t[1:-1]) - P[1:-1], axis=1).max())
    return fit.trajectory.evaluate(np.linspace(0.0, T, 4000)), P, miss


def m_case(board: Board, weight: float) -> dict[str, Any]:
    path, P, miss = m_path(board, weight)
    views = [view_distortion([path], [P], board, a).as_dict() for a in VIEW_ANGLES_DEG]
    h = board.to_board(path)[:, 2]
    return {
        "plane_weight": weight,
        "views": views,
        "off_plane": {"max_mm": 1e3 * float(np.abs(h).max()), "rms_mm": 1e3 * _rms(h)},
        "vertex_miss_mm": 1e3 * miss,
    }


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def word_mission(limits: VehicleLimits, weight: float) -> Mission:
    board = sky_board(np.array([0.0, 0.0, 2.0]), yaw_deg=30.0, tilt_deg=20.0)
    opts = WritingOptions(size_m=1.0, limits=limits, plane_weight=weight)
    home = np.array([0.5, -2.0, 0.0])
    return plan_writing(typed_strokes(WORD, "futural"), board, opts, home)


def word_case(limits: VehicleLimits, weight: float) -> dict[str, Any]:
    mission = word_mission(limits, weight)
    t = np.concatenate([np.linspace(a, b, 400) for a, b in mission.pen_windows])
    h = mission.board.to_board(mission.trajectory.evaluate(t))[:, 2]
    return {
        "limits": limits.describe(),
        "plane_weight": weight,
        "views": [v.as_dict() for v in mission_distortion(mission)],
        "off_plane": {"max_mm": 1e3 * float(np.abs(h).max()), "rms_mm": 1e3 * _rms(h)},
        "deviation_mm": 1e3 * mission.deviation.max_m,
        "duration_s": mission.trajectory.duration,
        "planning_time_s": mission.planning_time_s,
        "max_excess": mission.verification.max_excess,
    }


def figure(word_pair: tuple[Mission, Mission]) -> None:
    """Three views of the M and of the word, without (red) and with (blue) the plane cost."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(15, 9))
    # Seen edge-on (90°) the drawing is a few millimetres wide: that view's x in mm.
    gain = {a: (1e3 if a == 90.0 else 1.0) for a in VIEW_ANGLES_DEG}

    def drawn(xy: np.ndarray, angle: float) -> tuple[np.ndarray, np.ndarray]:
        return xy[:, 0] * gain[angle], xy[:, 1]

    board = sky_board(np.array([0.0, 0.0, 2.0]), yaw_deg=35.0, tilt_deg=25.0)
    for col, angle in enumerate(VIEW_ANGLES_DEG):
        ax = axes[0, col]
        for weight, colour, label in ((0.0, "tab:red", "w/o SP"), (M_WEIGHT, "tab:blue", "w/ SP")):
            path, P, _ = m_path(board, weight)
            xy = project(board.to_board(path), angle)
            ax.plot(*drawn(xy, angle), color=colour, lw=1.4, label=label)
        ref = project(board.to_board(P), angle)
        ax.plot(*drawn(ref, angle), "k--", lw=0.8, label="intended")
        ax.set_title(f"M, yaw 35°, tilt 25°: {angle:g}° view", fontsize=10)
        ax.legend(fontsize=7)
        ax = axes[1, col]
        for mission, colour in zip(word_pair, ("tab:red", "tab:blue"), strict=True):
            for t0, t1 in mission.pen_windows:
                p = mission.trajectory.evaluate(np.linspace(t0, t1, 200))
                xy = project(mission.board.to_board(p), angle)
                ax.plot(*drawn(xy, angle), color=colour, lw=1.0)
        for stroke in word_pair[0].strokes_world:
            ref = project(word_pair[0].board.to_board(stroke), angle)
            ax.plot(*drawn(ref, angle), "k--", lw=0.5)
        ax.set_title(f'"{WORD}", yaw 30°, tilt 20°: {angle:g}° view', fontsize=10)
    for row in axes:
        for ax, angle in zip(row, VIEW_ANGLES_DEG, strict=True):
            if angle != 90.0:
                ax.set_aspect("equal")
            ax.set_xlabel("image x, " + ("mm (off the plane)" if angle == 90.0 else "m"))
            ax.set_ylabel("image y (board's vertical), m")
    fig.suptitle(
        "Light painting seen from the side (paper 003 Fig. 8), per-axis limits: red without, "
        "blue with the plane cost; black dashed: intended"
    )
    fig.tight_layout()
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE, dpi=110)
    plt.close(fig)


def main() -> None:
    norm = VehicleLimits(1.0, 2.0, 10.0)
    axis = VehicleLimits(None, None, None, 1.0, 2.0, 10.0)
    turned = sky_board(np.array([0.0, 0.0, 2.0]), yaw_deg=35.0, tilt_deg=25.0)
    aligned = sky_board(np.array([0.0, 0.0, 2.0]))
    out: dict[str, Any] = {
        "generated": datetime.now(UTC).isoformat(timespec="seconds"),
        "machine": machine_info(("scipy", "clarabel", "piqp")),
        "views_deg": list(VIEW_ANGLES_DEG),
        "M": [m_case(turned, w) for w in (0.0, M_WEIGHT)],
        "M-aligned": [m_case(aligned, w) for w in (0.0, M_WEIGHT)],
        "M_sweep": [m_case(turned, w) for w in WEIGHTS],
        "word": [word_case(lim, w) for lim in (norm, axis) for w in (0.0, PLANE_WEIGHT)],
        "word_sweep": [word_case(axis, w) for w in WEIGHTS],
    }
    RESULTS.write_text(json.dumps(jsonable(out), indent=2) + "\n")
    figure((word_mission(axis, 0.0), word_mission(axis, PLANE_WEIGHT)))
    for name in ("M", "M-aligned", "M_sweep", "word", "word_sweep"):
        for row in out[name]:
            views = "  ".join(
                f"{v['angle_deg']:>4g}°: {v['max_mm']:7.2f} / {v['rms_mm']:6.2f}"
                for v in row["views"]
            )
            extra = f" {row['limits'][:22]:<22}" if "limits" in row else ""
            print(
                f"{name:<10}{extra} w={row['plane_weight']:<8g} {views}  off-plane "
                f"{row['off_plane']['max_mm']:7.2f} / {row['off_plane']['rms_mm']:6.2f} mm"
                + (f"  dur {row['duration_s']:.2f} s dev {row['deviation_mm']:.2f} mm"
                   if "duration_s" in row else f"  miss {row['vertex_miss_mm']:.1f} mm")
            )  # fmt: skip


if __name__ == "__main__":
    with threadpool_limits(1):
        main()
