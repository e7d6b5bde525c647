"""The figure of a simulated flight: reference against flown, top view, position error."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from skyquill.sim.result import Flight

AXES = "xyz"


def plot_flight(flight: Flight, path: str | Path, title: str = "") -> None:
    """Save a figure of ``flight`` as a PNG.

    Top row: x, y and z (m) against t (s), reference dashed and flown solid.
    Bottom row: the top view (x-y, equal aspect) with the reference, the
    flown path and the ink strokes if the flight left any; and the position
    error ``|p - p_ref|`` (mm) against t with its RMSE.

    Parameters
    ----------
    flight
        The flight to show (``t`` (N,), ``p_ref`` and ``p`` (N, 3), m).
    path
        PNG file to write.
    title
        Figure title (the controller, simulator and errors are appended).
    """
    # A fixed layout: constrained layout draws the figure twice to measure it.
    fig = plt.figure(figsize=(13, 8))
    grid = fig.add_gridspec(
        2, 3, height_ratios=(1.0, 1.4), left=0.06, right=0.98, bottom=0.07, top=0.91,
        hspace=0.3, wspace=0.25,
    )  # fmt: skip
    t = flight.t
    for i, axis in enumerate(AXES):
        panel = fig.add_subplot(grid[0, i])
        panel.plot(t, flight.p_ref[:, i], "--", lw=1.2, color="0.45", label="reference")
        panel.plot(t, flight.p[:, i], "-", lw=1.0, color="C0", label="flown")
        panel.set(xlabel="t [s]", ylabel=f"{axis} [m]", title=f"{axis} against time")
        if i == 0:
            panel.legend(loc="upper right", fontsize=8)  # "best" tests every point

    top = fig.add_subplot(grid[1, 0])
    top.plot(flight.p_ref[:, 0], flight.p_ref[:, 1], "--", lw=1.2, color="0.45", label="reference")
    top.plot(flight.p[:, 0], flight.p[:, 1], "-", lw=1.0, color="C0", label="flown")
    for k, stroke in enumerate(flight.ink):
        top.plot(
            stroke[:, 0], stroke[:, 1], "-", lw=2.5, color="k", label="ink" if k == 0 else None
        )
    top.set(xlabel="x [m]", ylabel="y [m]", aspect="equal", title="top view")
    top.legend(loc="upper right", fontsize=8)

    err = fig.add_subplot(grid[1, 1:])
    error_mm = 1e3 * flight.position_error
    err.plot(t, error_mm, "-", lw=1.0, color="C3", label="|p - p_ref|")
    err.axhline(1e3 * flight.rmse_m, ls=":", color="k", lw=1.0, label="RMSE")
    err.set(xlabel="t [s]", ylabel="position error [mm]", title="position error")
    err.set_ylim(bottom=0.0)
    err.legend(loc="upper right", fontsize=8)

    saturated = sum(flight.saturations.values())
    fig.suptitle(
        f"{title}  {flight.controller} on {flight.sim}: RMSE {1e3 * flight.rmse_m:.2f} mm, "
        f"max {1e3 * flight.max_error_m:.2f} mm, {saturated} saturated step(s)".strip()
    )
    fig.savefig(path, dpi=110)
    plt.close(fig)
