"""Paint dots: read them from a CSV, make them from a picture, or draw the paper's set.

Dots are ``(x, z)`` in the wall frame ``R_w``, metres: ``x`` along the wall, ``z`` the height
above the floor. Shape (N, 2) everywhere.

The picture route is weighted Voronoi stippling (Secord 2002), which paper 002 does not have:
seed points by rejection sampling on the image's darkness, then Lloyd relaxation -- each dot
moves to the darkness-weighted centroid of its Voronoi cell, computed on the pixel grid
(every pixel goes to its nearest dot through a k-d tree). Dark areas end up densely dotted,
white ones empty.
"""

from __future__ import annotations

import csv
import math
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from skyquill.errors import InputError
from skyquill.io.source import open_binary
from skyquill.io.table import read_table
from skyquill.validation import FloatArray, as_array, as_int

#: Longest side the picture is resampled to before stippling, px: enough for a few thousand
#: dots, and it keeps each Lloyd step to a few milliseconds.
STIPPLE_MAX_SIDE = 200
#: Most dots a mission takes (a mural of 10,000 dots is ~ 20 h of flight already).
MAX_DOTS = 10_000
#: Largest picture accepted, pixels (checked from the header, before decoding): a 40 Mpx
#: photo decodes to ~160 MB of RGBA; Pillow's own bomb check stops only at twice 89 Mpx.
MAX_IMAGE_PIXELS = 40_000_000
#: Largest picture file read, bytes (a 40 Mpx PNG of noise compresses to ~120 MB).
MAX_IMAGE_BYTES = 256 * 2**20
#: The picture formats read: Pillow's others (EPS runs Ghostscript, for one) are refused.
IMAGE_FORMATS = ("PNG", "JPEG")
#: Most pixels :func:`stipple` takes: every Lloyd step queries every pixel's
#: nearest dot (40 steps), ~1 s per million pixels each; :func:`load_darkness`
#: gives at most STIPPLE_MAX_SIDE^2.
MAX_STIPPLE_PIXELS = 1_000_000


def read_dots_csv(path: str | Path) -> FloatArray:
    """Read a dots CSV with columns ``x`` and ``z`` (m, wall frame; other columns ignored).

    The file is read by :func:`~skyquill.io.table.read_table` (its refusals apply), at
    most :data:`MAX_DOTS` rows.

    Returns
    -------
    numpy.ndarray, shape (N, 2), m
    """
    table = read_table(path, required=("x", "z"), max_rows=MAX_DOTS, name="dots file")
    return check_dots(table.name, table.select(("x", "z")))


def check_dots(name: str, dots: object) -> FloatArray:
    """A finite (N, 2) array with 1 <= N <= :data:`MAX_DOTS`; InputError otherwise."""
    arr = as_array(name, dots, ndim=2, max_abs=1e4)
    if arr.shape[1] != 2:
        raise InputError(f"{name}: got shape {arr.shape}, expected (N, 2) columns x, z")
    if not 1 <= arr.shape[0] <= MAX_DOTS:
        raise InputError(f"{name}: got {arr.shape[0]} dots, expected 1 to {MAX_DOTS}")
    return arr


def write_dots_csv(path: str | Path, dots: FloatArray) -> None:
    """Write ``x,z`` rows, m, 4 decimals (0.1 mm)."""
    with Path(path).open("w", newline="", encoding="utf-8") as handle:
        out = csv.writer(handle)
        out.writerow(["x", "z"])
        out.writerows([[f"{x:.4f}", f"{z:.4f}"] for x, z in dots])


def load_darkness(path: str | Path) -> FloatArray:
    """The picture as darkness in [0, 1] (1 = black), shape (H, W), longest side <= 200 px.

    The file is a PNG or a JPEG of at most :data:`MAX_IMAGE_PIXELS` pixels; the size is
    read from the header and checked before anything is decoded, so a small file that
    claims to be 20000 x 20000 px (a decompression bomb) is refused without the
    gigabyte it would take. Transparent pixels count as white paper; 16-bit greys keep
    their full range.

    Raises
    ------
    InputError
        Naming ``--image`` when the file is missing, not a PNG or JPEG Pillow can
        decode (truncated, corrupt), or larger than :data:`MAX_IMAGE_PIXELS`.
    """
    from PIL import Image

    file = Path(path)
    if not file.exists():
        raise InputError(f"--image: got {str(file)!r}, expected an existing PNG or JPEG file")
    try:
        with (
            open_binary(file, "a PNG or JPEG picture", max_bytes=MAX_IMAGE_BYTES) as stream,
            warnings.catch_warnings(),
        ):
            # Pillow warns from 89 Mpx; our own ceiling, checked next, is lower
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            img = Image.open(stream, formats=IMAGE_FORMATS)
            _check_pixels(file, img.size)
            img.load()  # decoded while the file is open
        with img:
            gray = _gray(img)
    except InputError:
        raise
    except Image.DecompressionBombError:  # Pillow refuses at open from 179 Mpx
        raise InputError(
            f"--image: got {file.name!r} of more than {2 * (Image.MAX_IMAGE_PIXELS or 0):,} px, "
            f"expected a picture of 1 to {MAX_IMAGE_PIXELS:,} pixels"
        ) from None
    except Exception as exc:  # Pillow's decoders raise OSError, ValueError, SyntaxError,
        # struct.error, EOFError, DecompressionBombError or MemoryError on a hostile file
        raise InputError(
            f"--image: got {file.name!r} that Pillow cannot read ({type(exc).__name__}: "
            f"{str(exc)[:120]}), expected a PNG or JPEG"
        ) from None
    scale = STIPPLE_MAX_SIDE / max(gray.size)
    if scale < 1.0:
        size = (max(1, round(gray.width * scale)), max(1, round(gray.height * scale)))
        gray = gray.resize(size, Image.Resampling.LANCZOS)
    if gray.mode == "F":  # 16-bit grey, already in [0, 1]; Lanczos may overshoot it
        darkness: FloatArray = 1.0 - np.clip(np.asarray(gray, dtype=float), 0.0, 1.0)
    else:
        darkness = 1.0 - np.asarray(gray, dtype=float) / 255.0
    return darkness


def _check_pixels(file: Path, size: tuple[int, int]) -> None:
    width, height = size
    if width < 1 or height < 1 or width * height > MAX_IMAGE_PIXELS:
        raise InputError(
            f"--image: got {file.name!r} of {width} x {height} px, expected a picture of 1 to "
            f"{MAX_IMAGE_PIXELS:,} pixels (it is resampled to {STIPPLE_MAX_SIDE} px anyway)"
        )


def _gray(img: Any) -> Any:
    """``img`` as an 8-bit grey (mode ``L``) image, or 16-bit grey as ``F`` in [0, 1]."""
    from PIL import Image

    if img.mode.startswith("I;16"):
        # convert("L") would clip every value above 255 to white
        return Image.fromarray(np.asarray(img, dtype=np.float32) / 65535.0)
    if "A" in img.mode or "transparency" in img.info:
        rgba = img.convert("RGBA")
        paper = Image.new("RGBA", rgba.size, (255, 255, 255, 255))
        return Image.alpha_composite(paper, rgba).convert("L")
    return img.convert("L")


def stipple(
    darkness: FloatArray,
    n_dots: int,
    *,
    width_m: float = 3.5,
    bottom_m: float = 0.5,
    rng: np.random.Generator,
    iterations: int = 40,
    progress: Callable[[int, int], None] | None = None,
) -> FloatArray:
    """Weighted Voronoi stippling of ``darkness`` (H, W) into ``n_dots`` dots on the wall.

    Parameters
    ----------
    darkness
        Values in [0, 1], shape (H, W); row 0 is the top of the picture.
    n_dots
        Number of dots, 1 to :data:`MAX_DOTS`.
    width_m
        Width of the drawing on the wall, m; the height follows the picture's aspect ratio. The
        drawing is centred on ``x = 0``.
    bottom_m
        Height of the picture's bottom edge, m.
    rng
        Seeds the initial rejection sampling.
    iterations
        Lloyd steps (it stops earlier once no dot moves by more than 0.01 px).
    progress
        Called as ``progress(done, total)`` after each step.

    Returns
    -------
    numpy.ndarray, shape (n_dots, 2), m, ``(x_w, z_w)``
    """
    from scipy.spatial import cKDTree

    n = as_int("--dots", n_dots, low=1, high=MAX_DOTS)
    rho = np.clip(as_array("darkness", darkness, ndim=2), 0.0, 1.0)
    if rho.size > MAX_STIPPLE_PIXELS:
        raise InputError(
            f"darkness: got a {rho.shape[0]} x {rho.shape[1]} picture, expected at most "
            f"{MAX_STIPPLE_PIXELS:,} pixels (downscale it, as load_darkness does to "
            f"{STIPPLE_MAX_SIDE} px)"
        )
    if rho.sum() <= 0.0:
        raise InputError("--image: got an all-white picture, expected some dark pixels to stipple")
    h, w = rho.shape
    yy, xx = np.mgrid[0:h, 0:w]
    pixels = np.column_stack([xx.ravel() + 0.5, yy.ravel() + 0.5])
    weight = rho.ravel()
    # seeds: pixels drawn with probability ~ darkness, jittered inside the pixel
    pick = rng.choice(weight.size, size=n, p=weight / weight.sum())
    points = pixels[pick] + rng.uniform(-0.5, 0.5, size=(n, 2))
    for step in range(iterations):
        owner = cKDTree(points).query(pixels)[1]
        mass = np.bincount(owner, weights=weight, minlength=n)
        cx = np.bincount(owner, weights=weight * pixels[:, 0], minlength=n)
        cy = np.bincount(owner, weights=weight * pixels[:, 1], minlength=n)
        moved = mass > 0  # a cell with no ink keeps its dot where it is
        new = points.copy()
        new[moved] = np.column_stack([cx[moved], cy[moved]]) / mass[moved, None]
        shift = float(np.abs(new - points).max())
        points = new
        if progress is not None:
            progress(step + 1, iterations)
        if shift < 0.01:
            break
    metres = width_m / w
    x = (points[:, 0] - w / 2) * metres
    z = bottom_m + (h - points[:, 1]) * metres
    return np.column_stack([x, z])


def paper_drawing(n_dots: int = 140, *, width_m: float = 3.5, height_m: float = 2.1) -> FloatArray:
    """A 140-dot drawing the size of the paper's Fig. 3 (3.5 m x 2.1 m), centred on x = 0.

    The paper's picture is not given as numbers; this one is an ellipse outline (half the
    dots) around a five-pointed star (the other half), equally spaced along each curve,
    bottom edge at 0.5 m. It spans the full width and height, which is what the error
    from ``gamma`` depends on.
    """
    n = as_int("n_dots", n_dots, low=4, high=MAX_DOTS)
    n_ellipse = n // 2
    t = np.linspace(0.0, 2 * np.pi, 2000)
    ellipse = np.column_stack([0.5 * width_m * np.cos(t), 0.5 * height_m * np.sin(t)])
    angles = np.pi / 2 + np.arange(11) * 2 * np.pi / 10
    radius = np.where(np.arange(11) % 2 == 0, 0.42 * height_m, 0.17 * height_m)
    star = np.column_stack([radius * np.cos(angles), radius * np.sin(angles)])
    star_dense = _resample(star, 2000)
    dots = np.vstack(
        [_equal_spacing(ellipse, n_ellipse), _equal_spacing(star_dense, n - n_ellipse)]
    )
    dots[:, 1] += 0.5 + 0.5 * height_m
    return dots


def _resample(vertices: FloatArray, n: int) -> FloatArray:
    """A polyline through ``vertices`` (M, 2) with ``n`` points, equally spaced in length."""
    return _equal_spacing(vertices, n, closed=False)


def _equal_spacing(curve: FloatArray, n: int, *, closed: bool = True) -> FloatArray:
    """``n`` points equally spaced along the polyline ``curve`` (M, 2)."""
    seg = np.linalg.norm(np.diff(curve, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    stops = np.linspace(0.0, s[-1], n, endpoint=not closed)
    return np.column_stack([np.interp(stops, s, curve[:, 0]), np.interp(stops, s, curve[:, 1])])


def drawing_span(dots: FloatArray) -> tuple[float, float]:
    """``(x_min, x_max)`` of the dots, widened to 1 m if narrower (to split a wall), m."""
    lo, hi = float(dots[:, 0].min()), float(dots[:, 0].max())
    if hi - lo < 1.0:
        mid = 0.5 * (lo + hi)
        lo, hi = mid - 0.5, mid + 0.5
    return lo, hi


def nearest_spacing(dots: FloatArray) -> float:
    """Median nearest-neighbour distance between dots, m (``inf`` for one dot)."""
    from scipy.spatial import cKDTree

    if len(dots) < 2:
        return math.inf
    d = np.asarray(cKDTree(dots).query(dots, k=2)[0])
    return float(np.median(d[:, 1]))
