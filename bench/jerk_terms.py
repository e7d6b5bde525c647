"""Which term of the grid jerk row binds at the jerk-limited optimum (issue 27 part 3).

The grid jerk row of :mod:`skyquill.coverage.speed.rows` is, per limited
component and interior node ``i``,

    sqrt(b_i) |A (b_{i-1} - 2 b_i + b_{i+1}) + E (b_{i+1} - b_{i-1}) + F b_i| <= jmax

with ``A = C' / (2 h**2)`` (the change of the tangential acceleration: what a
CNC feed-rate scan limits), ``E = 3 C'' / (4 h)`` (curvature times the
tangential acceleration) and ``F = C'''`` (turning at speed, ``v**3``). This
script plans each path with the HiGHS LP (the reference, jerk on, no
refinement), takes the rows that bind (``>= 98 %`` of the limit) and reports
the share of the second-difference term in each, and how many nodes of the
jerk-free optimum (the scan's upper envelope) break the row by the first- and
zeroth-order terms alone. No timing: one plan per path and limit set.

    .venv/bin/python bench/jerk_terms.py     # ~1 min -> bench/results/jerk_terms.json
"""

from __future__ import annotations

import json
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from scipy.interpolate import BSpline, make_interp_spline

from common import jsonable, machine_info, one_blas_thread
from skyquill.coverage.paths import contours, spiral_control_points, spiral_curve
from skyquill.coverage.regions import region_from_vertices
from skyquill.coverage.speed import plan_speed
from skyquill.coverage.speed.curve import _derivs3
from skyquill.coverage.speed.norms import component_limits, components
from skyquill.coverage.speed.rows import jerk_coefficients

RESULTS = Path(__file__).resolve().parent / "results" / "jerk_terms.json"
VMAX, AMAX, JMAX = 3.0, 5.0, 3.0
N = 2000
#: A row binds at this share of its limit.
BINDING = 0.98


def paths() -> dict[str, BSpline]:
    """The 10 m square's spiral, a wiggle (tests/coverage/speed_curves.py) and a zigzag."""
    square = region_from_vertices([[0, 0], [10, 0], [10, 10], [0, 10]])
    spiral = spiral_curve(spiral_control_points(contours(square, 2.0, "offset"), 1.0))
    steps = [(0, 0), (1, 0), (1, 1), (0, 1), (2, -1), (1, 1), (1, 0)]
    wiggle = np.cumsum(np.asarray(steps, dtype=float), axis=0)
    lanes = np.array([[0, 0], [10, 0], [10, 2], [0, 2], [0, 4], [10, 4]], dtype=float)
    chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(lanes, axis=0), axis=1))])
    return {
        "spiral": spiral,
        "wiggle": make_interp_spline(np.linspace(0.0, 1.0, len(wiggle)), wiggle, k=4),
        "zigzag": make_interp_spline(chord / chord[-1], lanes, k=3),
    }


def terms(curve: BSpline, sides: int | None) -> dict[str, Any]:
    """The binding jerk rows' term shares at the LP optimum, and the envelope's excess."""
    plan = plan_speed(curve, VMAX, AMAX, JMAX, n=N, norm_sides=sides, max_excess=None,
                      method="lp")  # fmt: skip
    free = plan_speed(curve, VMAX, AMAX, None, n=N, norm_sides=sides, max_excess=None)
    c = _derivs3(curve, plan.u)
    p = tuple(components(x, sides) for x in c)
    limit = component_limits(np.full(c[0].shape[1], JMAX), sides)
    cm, cc, cp = jerk_coefficients((p[0], p[1], p[2]))
    a, e, f = 0.5 * (cm + cp), 0.5 * (cp - cm), cc + cm + cp

    def parts(b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        root = np.sqrt(b[1:-1])[:, None] / limit
        second = root * a * (b[:-2] - 2.0 * b[1:-1] + b[2:])[:, None]
        lower = root * (e * (b[2:] - b[:-2])[:, None] + f * b[1:-1, None])
        return second, lower

    second, lower = parts(plan.b)
    row = np.abs(second + lower)
    binding = row >= BINDING
    share = np.abs(second[binding]) / (np.abs(second[binding]) + np.abs(lower[binding]))
    _, lower_free = parts(free.b)
    alone = np.max(np.abs(lower_free), axis=1)
    return {
        "norm_sides": sides,
        "duration_s": plan.duration,
        "jerk_free_duration_s": free.duration,
        "binding_rows": int(binding.sum()),
        "nodes_with_a_binding_row": int(np.any(binding, axis=1).sum()),
        "interior_nodes": N - 2,
        "second_difference_share": {
            "median": float(np.median(share)),
            "p90": float(np.quantile(share, 0.9)),
            "below_half": float(np.mean(share < 0.5)),
        },
        "envelope_nodes_broken_by_lower_order_terms": float(np.mean(alone > 1.0)),
        "envelope_lower_order_max_ratio": float(np.max(alone)),
    }


def main() -> int:
    """Run every path per axis and with the 16-gon; write the JSON and print a line each."""
    rows = []
    with one_blas_thread():
        for name, curve in paths().items():
            for sides in (None, 16):
                row = {"path": name} | terms(curve, sides)
                rows.append(row)
                share = row["second_difference_share"]
                print(
                    f"{name:7s} sides={sides!s:4s} binding rows at "
                    f"{row['nodes_with_a_binding_row']}/{row['interior_nodes']} nodes; "
                    "second-difference share median "
                    f"{share['median']:.2f} (< 0.5 in {share['below_half']:.0%}); envelope "
                    f"broken by the lower-order terms alone at "
                    f"{row['envelope_nodes_broken_by_lower_order_terms']:.0%} of the nodes"
                )
    out = {
        "date": datetime.now(UTC).isoformat(timespec="seconds"),
        "machine": machine_info(("numpy", "scipy", "highspy")),
        "limits": {"vmax": VMAX, "amax_axis": AMAX, "jmax_axis": JMAX, "n": N},
        "binding_share": BINDING,
        "cases": rows,
    }
    RESULTS.write_text(json.dumps(jsonable(out), indent=2) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
