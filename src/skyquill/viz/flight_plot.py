"""The figure of a simulated flight: reference against flown, top view, position error."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from matplotlib.figure import Figure

from skyquill.viz.figures import figure_style, new_figure, save_png, stack_time_panels
from skyquill.viz.sampled import FlightSamples, sample_flight

if TYPE_CHECKING:
    from skyquill.sim.result import Flight

AXES = "xyz"


def plot_flight(flight: Flight, path: str | Path, title: str = "") -> None:
    """Save a figure of ``flight`` as a PNG.

    Left: the top view (x-y, equal aspect) with the reference, the flown path and the
    ink strokes if the flight left any. Right, stacked on one shared time axis (one set
    of time tick labels: most of a panel's drawing time is its ticks and text): x, y and
    z (m) against t (s), reference dashed and flown solid, and the position error
    ``|p - p_ref|`` (mm) with its RMSE.

    Parameters
    ----------
    flight
        The flight to show (``t`` (N,), ``p_ref`` and ``p`` (N, 3), m).
    path
        PNG file to write.
    title
        Figure title (the controller, simulator and errors are appended).
    """
    draw_flight(sample_flight(flight, title), path)


def draw_flight(samples: FlightSamples, path: str | Path) -> None:
    """Draw :func:`plot_flight`'s figure of ``samples``
    (:func:`~skyquill.viz.sampled.sample_flight`).

    Parameters
    ----------
    samples
        The flight sampled.
    path
        PNG file to write.
    """
    # A fixed layout: constrained layout draws the figure twice to measure it.
    fig = new_figure((13, 8))
    with figure_style():
        _draw(fig, samples)
    save_png(fig, path, dpi=110)


def _draw(fig: Figure, flight: FlightSamples) -> None:
    """The five panels of :func:`plot_flight` and its title, on ``fig``."""
    top = fig.add_axes((0.06, 0.07, 0.42, 0.84))
    top.plot(flight.p_ref[:, 0], flight.p_ref[:, 1], "--", lw=1.2, color="0.45", label="reference")
    top.plot(flight.p[:, 0], flight.p[:, 1], "-", lw=1.0, color="C0", label="flown")
    for k, stroke in enumerate(flight.ink):
        top.plot(
            stroke[:, 0], stroke[:, 1], "-", lw=2.5, color="k", label="ink" if k == 0 else None
        )
    top.set(xlabel="x [m]", ylabel="y [m]", aspect="equal", title="top view")
    top.legend(loc="upper right", fontsize=8)  # "best" tests every point

    *axes, err = stack_time_panels(fig, (0.56, 0.07, 0.42, 0.84), 4)
    t = flight.t
    for i, (panel, axis) in enumerate(zip(axes, AXES, strict=True)):
        panel.plot(t, flight.p_ref[:, i], "--", lw=1.2, color="0.45", label="reference")
        panel.plot(t, flight.p[:, i], "-", lw=1.0, color="C0", label="flown")
        panel.set_ylabel(f"{axis} [m]")
        # A hover at 1 m would read "+1" above ticks of 0.0000..0.0006: show the heights.
        panel.ticklabel_format(axis="y", useOffset=False)
    axes[0].set_title("position and error against time")
    axes[0].legend(loc="upper right", fontsize=8, ncols=2)

    error_mm = 1e3 * flight.position_error
    err.plot(t, error_mm, "-", lw=1.0, color="C3", label="|p - p_ref|")
    err.axhline(1e3 * flight.rmse_m, ls=":", color="k", lw=1.0, label="RMSE")
    err.set(xlabel="t [s]", ylabel="position error [mm]")
    err.set_ylim(bottom=0.0)
    err.legend(loc="upper right", fontsize=8, ncols=2)

    fig.suptitle(flight.title)
