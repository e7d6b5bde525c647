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
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from numpy.typing import NDArray
from PIL import Image, ImageDraw

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
#: Colours a GIF frame holds.
GIF_COLORS = 256
PREVIEW_FPS = 12
#: Samples per second of the preview's trails.
TRAIL_RATE_HZ = 25.0
#: Colour of a drone whose light is off (RGB 0..1).
DARK = (0.35, 0.35, 0.35)
#: Colour of the preview's clock (RGB 0..255).
STAMP = (204, 204, 204)
#: The photograph keeps a sample where the light has moved on by this much, px.
THIN_PX = 0.5
#: Longest trail segment rasterised, px (a segment across the whole preview).
MAX_SEGMENT_PX = 2000
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


#: A lit stretch of one drone: positions (K, 3), m, and its colour (0..1).
Polyline = tuple[FloatArray, tuple[float, float, float]]


def lit_polylines(drones: Sequence[PlannedTrajectory], default: RGB) -> list[Polyline]:
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


def _image_runs(camera: Camera, points: FloatArray) -> list[FloatArray]:
    """The visible runs (K, 2) of a polyline in the image, thinned to :data:`THIN_PX`.

    The parts behind the camera are left out. A sample is kept where the path has
    moved on by another :data:`THIN_PX` along the image, and at both ends: the
    photograph cannot show the samples in between (a formation's drones hold still
    for seconds at 100 samples a second).
    """
    uv, front = camera.project(points)
    runs = []
    cuts = np.flatnonzero(np.diff(front.astype(np.int8))) + 1
    for run, seen in zip(np.split(uv, cuts), np.split(front, cuts), strict=True):
        if not seen[0]:
            continue
        arc = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(run, axis=0).T))])
        step = np.floor(arc / THIN_PX)
        keep = np.concatenate([[True], step[1:] != step[:-1]])
        keep[-1] = True
        runs.append(run[keep])
    return runs


def _extent_px(runs: Sequence[FloatArray]) -> float:
    """Largest side of the image box of ``runs``, px; inf when none is visible."""
    if not runs:
        return math.inf
    points = np.concatenate(runs)
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
    *,
    lines: Sequence[Polyline] | None = None,
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
    lines
        The lit polylines (:func:`lit_polylines`) when the caller has them already.

    Raises
    ------
    InputError
        No drone.
    """
    if not drones:
        raise InputError("drones: got none, expected at least one to photograph")
    lines = lit_polylines(drones, default_rgb) if lines is None else lines
    fig, ax = _black_figure(camera)
    runs = [_image_runs(camera, points) for points, _ in lines]
    rgb = np.array([c for _, c in lines]).reshape(-1, 3)
    extent = np.array([_extent_px(r) for r in runs])
    counts = np.array([len(r) for r in runs], dtype=np.intp)
    every = [run for window in runs for run in window]
    centres = np.array(
        [np.concatenate(r).mean(axis=0) if r else (np.nan, np.nan) for r in runs]
    ).reshape(-1, 2)
    # One collection per glow pass, one path per lit window (not one artist per window,
    # nor one path per sample: a thousand drones were a million segments); the core of
    # a light trace is whiter than its halo.
    for width, alpha in GLOW:
        colour = 0.6 * rgb + 0.4 if alpha == 1.0 else rgb
        ax.add_collection(
            LineCollection(
                every, colors=np.repeat(colour, counts, axis=0), linewidths=width, alpha=alpha
            )
        )
        still = extent < width  # a light held still (a formation place): a dot
        if still.any():
            u, v = centres[still].T
            ax.scatter(u, v, s=(1.6 * width) ** 2, c=colour[still], alpha=alpha, lw=0)
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

    Frames are drawn straight into pixel arrays (numpy) and written by Pillow: every
    lit stretch of every drone is rasterised once, as the pixels of its segments with
    the time each is reached, and a frame shows those inside its trail window; the
    drones are 3 px squares, lit in their colour or dark grey.

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
    # One palette for every frame (the lights' colours, dark, the stamp), instead of
    # Pillow's median cut per frame: the frames hold only these colours. With at most 256
    # of them the frames are drawn as palette indices (no quantizing of 120 RGB frames).
    palette = _palette_colors(colors)
    index = _indexer(palette)
    pixels = _trail_pixels(uv, lit, colors, clock, camera)
    if index is not None:
        pixels = replace(pixels, rgb=index(pixels.rgb))
    times = np.linspace(0.0, horizon, min(frames, max(2, int(horizon * PREVIEW_FPS))))
    size = (camera.height_px, camera.width_px) + (() if index is not None else (3,))
    built = np.zeros(size, dtype=np.uint8)  # trails that never fade (trail >= the show)
    shown = 0
    stamp = _Stamp.of(palette, index)
    images = []
    for t in times:
        k = min(int(np.searchsorted(clock, t)), clock.size - 1)
        end = int(np.searchsorted(pixels.t, t, side="right"))
        if trail >= horizon:
            pixels.paint(built, shown, end)
            shown = end
            frame = built.copy()
        else:
            frame = np.zeros(size, dtype=np.uint8)
            pixels.paint(frame, int(np.searchsorted(pixels.t, t - trail)), end)
        dots = _rgb(np.where(lit[:, k, None], colors[:, k], DARK))
        _paint_dots(frame, uv[:, k], dots if index is None else index(dots))
        images.append(stamp.on(frame, f"t = {t:5.1f} s"))
    if index is None:  # more colours than a GIF holds: each pixel to its nearest
        quantized = _palette_image(palette[:GIF_COLORS])
        images = [im.quantize(palette=quantized, dither=Image.Dither.NONE) for im in images]
    images[0].save(
        str(path),
        format="GIF",
        save_all=True,
        append_images=images[1:],
        duration=round(1000 / PREVIEW_FPS),
        loop=0,
        optimize=False,  # the palette is ours already: no histogram of every frame
    )
    return int(times.size)


@dataclass(frozen=True)
class _Pixels:
    """Pixels of every lit trail segment, by the time each is reached (sorted); ``rgb``: their
    colours (N, 3), or their palette indices (N,) for an indexed frame."""

    t: FloatArray
    u: NDArray[np.intp]
    v: NDArray[np.intp]
    rgb: NDArray[np.uint8]

    def paint(self, frame: NDArray[np.uint8], start: int, end: int) -> None:
        """Set the pixels ``[start, end)`` (2 px wide: each with its right and lower neighbours)."""
        u, v, rgb = self.u[start:end], self.v[start:end], self.rgb[start:end]
        height, width = frame.shape[:2]
        for du, dv in ((0, 0), (1, 0), (0, 1), (1, 1)):
            frame[np.minimum(v + dv, height - 1), np.minimum(u + du, width - 1)] = rgb


def _trail_pixels(
    uv: FloatArray, lit: NDArray[np.bool_], colors: FloatArray, clock: FloatArray, camera: Camera
) -> _Pixels:
    """Rasterise the segments between consecutive lit samples (one pixel step along each)."""
    both = lit[:, :-1] & lit[:, 1:]
    drone, k = np.nonzero(both)
    a, b = uv[drone, k], uv[drone, k + 1]
    box = np.array([camera.width_px, camera.height_px], dtype=float)
    inside = np.all((a > -box) & (a < 2 * box) & (b > -box) & (b < 2 * box), axis=1)
    a, b, drone, k = a[inside], b[inside], drone[inside], k[inside]
    steps = np.minimum(np.ceil(np.abs(b - a).max(axis=1)).astype(np.intp), MAX_SEGMENT_PX) + 1
    seg = np.repeat(np.arange(steps.size), steps)
    frac = (np.arange(steps.sum()) - np.repeat(np.cumsum(steps) - steps, steps)) / np.repeat(
        steps, steps
    )
    points = a[seg] + frac[:, None] * (b[seg] - a[seg])
    when = clock[k[seg]] + frac * (clock[k[seg] + 1] - clock[k[seg]])
    keep = np.all((points >= 0) & (points < box), axis=1)
    order = np.argsort(when[keep], kind="stable")
    rgb = _rgb(colors[drone[seg], k[seg]])
    return _Pixels(
        when[keep][order],
        points[keep, 0].astype(np.intp)[order],
        points[keep, 1].astype(np.intp)[order],
        rgb[keep][order],
    )


@dataclass(frozen=True)
class _Stamp:
    """How a frame becomes an image with its time stamped on: indexed frames in P mode with
    the show's palette (``palette``: Pillow's 768 values), RGB frames as they are (None);
    ``fill``: the stamp's palette index or colour. Made once for every frame."""

    palette: list[int] | None
    fill: int | tuple[int, ...]

    @classmethod
    def of(
        cls,
        palette: NDArray[np.uint8],
        index: Callable[[NDArray[np.uint8]], NDArray[np.uint8]] | None,
    ) -> _Stamp:
        """For frames in ``palette``'s indices (``index``) or, without ``index``, in RGB."""
        if index is None:
            return cls(None, STAMP)
        return cls(_flat(palette), int(index(np.array([STAMP], dtype=np.uint8))[0]))

    def on(self, frame: NDArray[np.uint8], text: str) -> Image.Image:
        """``frame`` as an image, ``text`` stamped on."""
        if self.palette is None:
            image = Image.fromarray(frame)
        else:
            image = Image.frombytes("P", (frame.shape[1], frame.shape[0]), frame.tobytes())
            image.putpalette(self.palette)
        draw = ImageDraw.Draw(image)
        draw.fontmode = "1"  # no antialiasing: the frame keeps the palette's colours
        draw.text((10, 10), text, fill=self.fill)
        return image


def _rgb(colors: FloatArray) -> NDArray[np.uint8]:
    """Colours 0..1, shape (..., 3), as bytes 0..255."""
    out: NDArray[np.uint8] = np.clip(np.round(255 * colors), 0, 255).astype(np.uint8)
    return out


def _packed(rgb: NDArray[np.integer[Any]]) -> NDArray[np.int64]:
    """Colours (..., 3) as 24-bit integers (...,): sorted as the rows are."""
    wide = rgb.astype(np.int64)
    out: NDArray[np.int64] = (wide[..., 0] << 16) | (wide[..., 1] << 8) | wide[..., 2]
    return out


def _indexer(
    palette: NDArray[np.uint8],
) -> Callable[[NDArray[np.uint8]], NDArray[np.uint8]] | None:
    """Colours (..., 3) -> their indices (...,) in ``palette`` (sorted rows holding them);
    None when the palette is too large for a GIF."""
    if palette.shape[0] > GIF_COLORS:
        return None
    packed = _packed(palette)

    def index(rgb: NDArray[np.uint8]) -> NDArray[np.uint8]:
        found: NDArray[np.uint8] = np.searchsorted(packed, _packed(rgb)).astype(np.uint8)
        return found

    return index


def _flat(palette: NDArray[np.uint8]) -> list[int]:
    """A palette (K, 3) as Pillow's list of 768 values."""
    flat = np.zeros(768, dtype=np.uint8)
    flat[: palette.size] = palette.ravel()
    values: list[int] = flat.tolist()
    return values


def _palette_image(palette: NDArray[np.uint8]) -> Image.Image:
    """A P-mode image with ``palette`` (K <= 256, 3), for :meth:`PIL.Image.Image.quantize`."""
    image = Image.new("P", (1, 1))
    image.putpalette(_flat(palette))
    return image


def _palette_colors(colors: FloatArray) -> NDArray[np.uint8]:
    """Black, dark, the stamp and every light colour, shape (K, 3), rows sorted."""
    # unique colours as packed 24-bit integers (a 1-D unique: np.unique(axis=0) sorts rows
    # of the whole show's samples one by one, 4 s at 250 drones); same rows, same order.
    # Only the samples whose colour differs from the one before are rounded: the same
    # colours (each first seen at such a change) at a sliver of the 10 million samples of
    # a 1,000-drone show.
    every_sample = colors.reshape(-1, 3)
    changed = np.ones(every_sample.shape[0], dtype=bool)
    changed[1:] = (every_sample[1:] != every_sample[:-1]).any(axis=1)
    packed = np.unique(_packed(_rgb(every_sample[changed])))
    lights = np.column_stack([packed >> 16, (packed >> 8) & 255, packed & 255]).astype(float)
    fixed = np.array([(0, 0, 0), [round(255 * c) for c in DARK], STAMP], dtype=float)
    every: NDArray[np.uint8] = np.unique(np.concatenate([fixed, lights]), axis=0).astype(np.uint8)
    return every


def _paint_dots(frame: NDArray[np.uint8], uv: FloatArray, values: NDArray[np.uint8]) -> None:
    """Each drone as a 3 px square at ``uv`` (D, 2) in its colour (none if hidden): ``values``
    (D, 3) bytes in an RGB frame, (D,) palette indices in an indexed one."""
    height, width = frame.shape[:2]
    seen = np.all(np.isfinite(uv), axis=1)
    centre = np.round(uv[seen]).astype(np.intp)
    colour = values[seen]
    for du in (-1, 0, 1):
        for dv in (-1, 0, 1):
            u, v = centre[:, 0] + du, centre[:, 1] + dv
            on = (u >= 0) & (u < width) & (v >= 0) & (v < height)
            frame[v[on], u[on]] = colour[on]


def _tracks(
    drones: Sequence[PlannedTrajectory], camera: Camera, clock: FloatArray, default: RGB
) -> tuple[FloatArray, NDArray[np.bool_], FloatArray]:
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
    the whole flight (take-off and landing included). The lit path is sampled once for
    both the framing and the photograph.
    """
    lines = lit_polylines(drones, default_rgb)
    everything = _positions(drones)
    lit = np.concatenate([p for p, _ in lines]) if lines else np.empty((0, 3))
    photo_camera = Camera.framing(
        lit if lit.size else everything,
        view.azimuth_deg,
        view.elevation_deg,
        fov_deg=view.fov_deg,
        width_px=PHOTO_PX[0],
        height_px=PHOTO_PX[1],
    )
    photo = long_exposure(
        drones, photo_camera, folder / "long_exposure.png", default_rgb, lines=lines
    )
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


def _positions(drones: Sequence[PlannedTrajectory]) -> FloatArray:
    """Positions of every drone's whole flight, 400 samples each (M, 3)."""
    return np.concatenate(
        [d.trajectory.evaluate(np.linspace(0.0, d.trajectory.duration, 400)) for d in drones]
    )
