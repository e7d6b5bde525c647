"""What the audience sees: a long-exposure photograph of the lights, and an animated preview.

Both take the drones of a show on one clock (each a
:class:`~skyquill.io.trajectory_json.PlannedTrajectory`: its flight, its light windows and
their colours) and a :class:`~skyquill.viz.camera.Camera`.

* :func:`long_exposure` draws every lit stretch of every drone as a photograph with the
  shutter open for the whole show would record it: glowing lines on black, in the lights'
  colours, seen through the camera (perspective: near strokes are larger).
* :func:`animate_show` writes a GIF: the drones as dots (lit in their colour, dark grey
  when off) with a trail of their light, on a clock that plays the whole show in at
  most :data:`MAX_FRAMES` frames, so it stays cheap enough to look at after every plan.

:func:`write_pictures` writes both for a command, framed from one :class:`View`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation, PillowWriter
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure

from skyquill.colors import RGB
from skyquill.errors import InputError
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.validation import FloatArray, as_float, as_int
from skyquill.viz.camera import Camera

#: Light samples per second for the photograph (1 cm at 1 m/s).
EXPOSURE_RATE_HZ = 100.0
#: Most light samples drawn in one photograph (memory and drawing time).
MAX_EXPOSURE_SAMPLES = 2_000_000
#: Glow passes of the photograph: line width (px at 100 dpi) and opacity, outermost first.
GLOW = ((7.0, 0.07), (3.5, 0.2), (1.4, 1.0))
#: Most frames of the preview, and its frame rate (frames per second).
MAX_FRAMES = 120
PREVIEW_FPS = 12
#: Samples per second of the preview's trails.
TRAIL_RATE_HZ = 25.0
#: Colour of a drone whose light is off (RGB 0..1).
DARK = (0.35, 0.35, 0.35)
DPI = 100


@dataclass(frozen=True)
class View:
    """Where the audience looks from (see :meth:`Camera.framing`).

    Attributes
    ----------
    azimuth_deg
        Direction from the show to the camera, degrees counter-clockwise from +x
        (-90: in front of boards that face -y).
    elevation_deg
        Camera height above the show centre's horizon, degrees.
    fov_deg
        Horizontal field of view, degrees.
    """

    azimuth_deg: float = -90.0
    elevation_deg: float = 10.0
    fov_deg: float = 50.0


@dataclass(frozen=True)
class Exposure:
    """What the photograph recorded.

    Attributes
    ----------
    path
        The PNG written.
    lit_windows
        Light windows drawn, over all drones.
    lit_length_m
        Length of the lit path, m.
    drones
        Drones in the show.
    """

    path: Path
    lit_windows: int
    lit_length_m: float
    drones: int


def _lit_polylines(
    drones: Sequence[PlannedTrajectory], default: RGB
) -> list[tuple[FloatArray, tuple[float, float, float]]]:
    """Each lit window of each drone as (positions (K, 3), colour 0..1)."""
    total = sum(b - a for d in drones for a, b in d.pen_windows_s) * EXPOSURE_RATE_HZ
    rate = EXPOSURE_RATE_HZ * min(1.0, MAX_EXPOSURE_SAMPLES / max(total, 1.0))
    out = []
    for drone in drones:
        for (a, b), rgb in zip(drone.pen_windows_s, drone.colors(default), strict=True):
            t = np.linspace(a, b, max(2, int(np.ceil((b - a) * rate)) + 1))
            points = drone.trajectory.evaluate(np.minimum(t, drone.trajectory.duration))
            out.append((points, (rgb[0] / 255, rgb[1] / 255, rgb[2] / 255)))
    return out


def _segments(camera: Camera, points: FloatArray) -> FloatArray:
    """Image segments (M, 2, 2) of a polyline, the parts behind the camera left out."""
    uv, front = camera.project(points)
    keep = front[:-1] & front[1:]
    return np.stack([uv[:-1], uv[1:]], axis=1)[keep]


def _extent_px(segs: FloatArray) -> float:
    """Largest side of the image box of ``segs`` (M, 2, 2), px; inf when none is visible."""
    if segs.size == 0:
        return math.inf
    points = segs.reshape(-1, 2)
    return float(np.max(points.max(axis=0) - points.min(axis=0)))


def _black_figure(camera: Camera) -> tuple[Figure, Axes]:
    fig = plt.figure(figsize=(camera.width_px / DPI, camera.height_px / DPI), dpi=DPI)
    fig.patch.set_facecolor("black")
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_facecolor("black")
    ax.set_xlim(0, camera.width_px)
    ax.set_ylim(camera.height_px, 0)
    ax.set_axis_off()
    return fig, ax


def long_exposure(
    drones: Sequence[PlannedTrajectory],
    camera: Camera,
    path: str | Path,
    default_rgb: RGB = (255, 255, 255),
) -> Exposure:
    """Write the long-exposure photograph of the show's lights as a PNG.

    Parameters
    ----------
    drones
        The drones on one clock, each with its light windows (and colours).
    camera
        Where the photograph is taken from.
    path
        PNG file to write.
    default_rgb
        The colour of windows whose drone has no colours of its own.

    Raises
    ------
    InputError
        No drone.
    """
    if not drones:
        raise InputError("drones: got none, expected at least one to photograph")
    fig, ax = _black_figure(camera)
    lines = _lit_polylines(drones, default_rgb)
    segments = [(_segments(camera, points), rgb) for points, rgb in lines]
    for width, alpha in GLOW:
        for segs, rgb in segments:
            # the core of a light trace is whiter than its halo, as on a sensor
            core = tuple(0.6 * c + 0.4 for c in rgb) if alpha == 1.0 else rgb
            ax.add_collection(
                LineCollection(list(segs), colors=[core], linewidths=width, alpha=alpha)
            )
            if _extent_px(segs) < width:  # a light held still (a formation): a dot
                u, v = segs.reshape(-1, 2).mean(axis=0)
                ax.scatter(u, v, s=(1.6 * width) ** 2, color=[core], alpha=alpha, lw=0)
    fig.savefig(path, dpi=DPI, facecolor="black")
    plt.close(fig)
    length = sum(float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum()) for p, _ in lines)
    return Exposure(Path(path), len(lines), length, len(drones))


def animate_show(
    drones: Sequence[PlannedTrajectory],
    camera: Camera,
    path: str | Path,
    default_rgb: RGB = (255, 255, 255),
    *,
    trail_s: float = 1.0,
    max_frames: int = MAX_FRAMES,
) -> int:
    """Write an animated GIF of the show through ``camera``; returns the number of frames.

    Parameters
    ----------
    drones, camera, default_rgb
        As for :func:`long_exposure`.
    path
        GIF file to write.
    trail_s
        How long a light's trail stays on screen, s, >= 0 (``inf``: the whole show,
        the preview builds up the photograph).
    max_frames
        Most frames; the show is played faster when it is longer than
        ``max_frames / PREVIEW_FPS`` seconds.
    """
    if not drones:
        raise InputError("drones: got none, expected at least one to animate")
    frames = as_int("max_frames", max_frames, low=2, high=10 * MAX_FRAMES)
    horizon = max(d.trajectory.duration for d in drones)
    trail = horizon if trail_s == math.inf else as_float("trail_s", trail_s, nonneg=True)
    clock = np.linspace(0.0, horizon, max(2, int(horizon * TRAIL_RATE_HZ)) + 1)
    uv, lit, colors = _tracks(drones, camera, clock, default_rgb)
    fig, ax = _black_figure(camera)
    dots = ax.scatter(uv[:, 0, 0], uv[:, 0, 1], s=14, c=[DARK] * len(drones))
    trails = LineCollection([], linewidths=2.0)
    ax.add_collection(trails)
    stamp = ax.text(10, 24, "", color="0.8", fontsize=11)
    times = np.linspace(0.0, horizon, min(frames, max(2, int(horizon * PREVIEW_FPS))))

    def draw(t: float) -> None:
        k = int(np.searchsorted(clock, t))
        k = min(k, clock.size - 1)
        dots.set_offsets(uv[:, k])
        dots.set_facecolor([tuple(c) for c in np.where(lit[:, k, None], colors[:, k], DARK)])
        first = max(0, int(np.searchsorted(clock, t - trail)))
        segs, cols = _trail_segments(uv[:, first : k + 1], lit[:, first : k + 1], colors[:, first:])
        trails.set_segments(list(segs))
        trails.set_color([tuple(c) for c in cols])
        stamp.set_text(f"t = {t:5.1f} s")

    FuncAnimation(fig, draw, frames=times, blit=False).save(
        str(path), writer=PillowWriter(fps=PREVIEW_FPS), dpi=DPI
    )
    plt.close(fig)
    return int(times.size)


def _tracks(
    drones: Sequence[PlannedTrajectory], camera: Camera, clock: FloatArray, default: RGB
) -> tuple[FloatArray, np.ndarray, FloatArray]:
    """Image positions (D, T, 2), lit (D, T) and colours 0..1 (D, T, 3) on ``clock``."""
    uv = np.empty((len(drones), clock.size, 2))
    lit = np.zeros((len(drones), clock.size), dtype=bool)
    colors = np.zeros((len(drones), clock.size, 3))
    for i, drone in enumerate(drones):
        points = drone.trajectory.evaluate(np.minimum(clock, drone.trajectory.duration))
        image, front = camera.project(points)
        uv[i] = np.where(front[:, None], image, np.nan)
        light = drone.light(clock, default)
        lit[i] = light.any(axis=1) & front
        colors[i] = light / 255.0
    return uv, lit, colors


def _trail_segments(
    uv: FloatArray, lit: np.ndarray, colors: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Segments (M, 2, 2) between consecutive lit samples, and their colours (M, 3)."""
    both = lit[:, :-1] & lit[:, 1:]
    segs = np.stack([uv[:, :-1], uv[:, 1:]], axis=2)[both]
    return segs, colors[:, : uv.shape[1] - 1][both]


#: Size of the photograph and of the preview, pixels (width, height).
PHOTO_PX = (1280, 720)
PREVIEW_PX = (640, 360)


def write_pictures(
    drones: Sequence[PlannedTrajectory],
    folder: Path,
    view: View = View(),
    default_rgb: RGB = (255, 255, 255),
    *,
    trail_s: float = 1.0,
) -> dict[str, object]:
    """Write ``long_exposure.png`` and ``preview.gif`` into ``folder``; their summary entry.

    The photograph frames the lit path (what the camera records); the preview frames
    the whole flight (take-off and landing included).
    """
    everything = _positions(drones, lit_only=False)
    lit = _positions(drones, lit_only=True)
    photo_camera = Camera.framing(
        lit if lit.size else everything,
        view.azimuth_deg,
        view.elevation_deg,
        fov_deg=view.fov_deg,
        width_px=PHOTO_PX[0],
        height_px=PHOTO_PX[1],
    )
    photo = long_exposure(drones, photo_camera, folder / "long_exposure.png", default_rgb)
    preview_camera = Camera.framing(
        everything,
        view.azimuth_deg,
        view.elevation_deg,
        fov_deg=view.fov_deg,
        width_px=PREVIEW_PX[0],
        height_px=PREVIEW_PX[1],
    )
    frames = animate_show(
        drones, preview_camera, folder / "preview.gif", default_rgb, trail_s=trail_s
    )
    return {
        "long_exposure": photo.path.name,
        "preview": "preview.gif",
        "preview_frames": frames,
        "lit_windows": photo.lit_windows,
        "lit_length_m": photo.lit_length_m,
        "view": {
            "azimuth_deg": view.azimuth_deg,
            "elevation_deg": view.elevation_deg,
            "fov_deg": view.fov_deg,
        },
    }


def _positions(drones: Sequence[PlannedTrajectory], *, lit_only: bool) -> FloatArray:
    """Sampled positions of every drone (M, 3): the lit ones, or the whole flights."""
    if lit_only:
        lines = _lit_polylines(drones, (255, 255, 255))
        return np.concatenate([p for p, _ in lines]) if lines else np.empty((0, 3))
    return np.concatenate(
        [d.trajectory.evaluate(np.linspace(0.0, d.trajectory.duration, 400)) for d in drones]
    )
