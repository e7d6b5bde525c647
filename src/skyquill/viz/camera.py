"""A pinhole camera: where a photographer stands, what the picture of a show looks like.

The long exposure and the show preview (:mod:`skyquill.viz.light_painting`) project world
points (z up, m) through it. A camera looks from ``position`` at ``target``; the image's
up is the world's up as far as the view allows; ``fov_deg`` is the horizontal field of
view. :meth:`Camera.framing` places one so that a set of points fills the picture from a
given direction, the way a photographer frames a show from the audience.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.validation import FloatArray, as_array, as_float, as_int

#: Points closer to the camera than this along its axis are not drawn, m.
NEAR_M = 0.05
#: Room around the framed points, as a fraction of their radius.
FRAMING_MARGIN = 0.1
#: Largest picture side, pixels.
MAX_PIXELS = 4096


@dataclass(frozen=True)
class Camera:
    """A pinhole camera.

    Attributes
    ----------
    position, target
        Where it is and what it looks at, (3,) each, m, world frame (z up).
    fov_deg
        Horizontal field of view, degrees, in (1, 170).
    width_px, height_px
        Picture size, pixels.
    """

    position: FloatArray
    target: FloatArray
    fov_deg: float = 50.0
    width_px: int = 1280
    height_px: int = 720

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", as_array("camera position", self.position, shape=(3,)))
        object.__setattr__(self, "target", as_array("camera target", self.target, shape=(3,)))
        _check_fov(self.fov_deg)
        as_int("width_px", self.width_px, low=16, high=MAX_PIXELS)
        as_int("height_px", self.height_px, low=16, high=MAX_PIXELS)
        if np.linalg.norm(self.target - self.position) < NEAR_M:
            raise InputError("camera target: got the camera's own position, expected a point ahead")

    @classmethod
    def framing(
        cls,
        points: FloatArray,
        azimuth_deg: float = -90.0,
        elevation_deg: float = 10.0,
        **kwargs: float,
    ) -> Camera:
        """A camera that fits ``points`` (N, 3) in the picture, seen from a direction.

        Parameters
        ----------
        points
            What must be in the picture, (N, 3), m.
        azimuth_deg
            Direction from the points' centre to the camera, degrees counter-clockwise
            from +x: -90 stands at -y, in front of a board that faces -y (the audience).
        elevation_deg
            Height of the camera above the centre's horizon, degrees, in [-89, 89].
        **kwargs
            ``fov_deg``, ``width_px``, ``height_px``.
        """
        p = as_array("points", points, shape=(None, 3))
        if p.shape[0] == 0:
            raise InputError("points: got none, expected at least one point to frame")
        az = math.radians(as_float("azimuth_deg", azimuth_deg))
        el = as_float("elevation_deg", elevation_deg)
        if not -89.0 <= el <= 89.0:
            raise InputError(f"elevation_deg: got {el:g}, expected -89 to 89 degrees")
        centre = 0.5 * (p.min(axis=0) + p.max(axis=0))
        radius = max(float(np.linalg.norm(p - centre, axis=1).max()), 0.5)
        fov = _check_fov(kwargs.get("fov_deg", 50.0))
        aspect = float(kwargs.get("height_px", 720)) / float(kwargs.get("width_px", 1280))
        # the narrower of the two fields of view must hold the sphere round the points
        half = math.atan(math.tan(math.radians(fov) / 2) * min(1.0, aspect))
        distance = (1 + FRAMING_MARGIN) * radius / math.sin(half)
        e = math.radians(el)
        direction = np.array([math.cos(e) * math.cos(az), math.cos(e) * math.sin(az), math.sin(e)])
        return cls(centre + distance * direction, centre, **kwargs)  # type: ignore[arg-type]

    def axes(self) -> FloatArray:
        """Rows: the image's right, up, and the viewing direction, unit vectors (3, 3)."""
        forward = self.target - self.position
        forward = forward / np.linalg.norm(forward)
        world_up = np.array([0.0, 0.0, 1.0])
        if abs(forward @ world_up) > 0.999:  # looking straight down or up: north is up
            world_up = np.array([0.0, 1.0, 0.0])
        right = np.cross(forward, world_up)
        right /= np.linalg.norm(right)
        return np.stack([right, np.cross(right, forward), forward])

    def project(self, points: FloatArray) -> tuple[FloatArray, NDArray[np.bool_]]:
        """Pixel coordinates of ``points`` (N, 3): ``(uv (N, 2), in_front (N,))``.

        ``u`` grows to the right and ``v`` downwards from the top-left corner; points
        behind the camera (or nearer than :data:`NEAR_M`) have ``in_front`` false and
        coordinates that must not be drawn.
        """
        local = (np.asarray(points, dtype=float) - self.position) @ self.axes().T
        depth = local[:, 2]
        in_front = depth > NEAR_M
        focal = 0.5 * self.width_px / math.tan(math.radians(self.fov_deg) / 2)
        safe = np.where(in_front, depth, 1.0)
        u = 0.5 * self.width_px + focal * local[:, 0] / safe
        v = 0.5 * self.height_px - focal * local[:, 1] / safe
        return np.column_stack([u, v]), in_front


def _check_fov(fov_deg: object) -> float:
    """``fov_deg`` as a float in (1, 170) degrees; :class:`InputError` otherwise."""
    fov = as_float("fov_deg", fov_deg)
    if not 1.0 < fov < 170.0:
        raise InputError(f"fov_deg: got {fov:g}, expected 1 to 170 degrees")
    return fov
