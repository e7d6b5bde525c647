"""Congruent pieces of a mission: which pieces are one polygon moved, and by which motion.

A field cut round its holes often gives pieces that are copies of each other:
``holes_1_3ha``'s 11 pieces hold three pairs (302, 290 and 2990 m²: rectangles,
shifted copies), each planned twice before; the 10 ha field's four 108 m² triangles
round its round hole are one turned four ways. A piece is planned once
per class (:func:`congruence_classes`) and its plan moved onto the others
(:func:`~skyquill.trajectory.moved.moved`).

Which motions keep a plan valid depends on the limits: norm limits (speed,
acceleration and jerk as vector norms) are the same after any rotation or
mirror, so ``"rigid"``; per-axis limits only after a shift, so
``"translations"``. The pieces are compared as point sets: a straight vertex a
cut left on one side of a piece and not on its copy does not matter.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.linalg import orthogonal_procrustes
from shapely.geometry import Polygon

from skyquill.validation import FloatArray

#: Which motions a plan may be moved by: any rigid one (norm limits) or shifts only.
Motions = Literal["rigid", "translations"]

#: Vertices match within this fraction of the piece's size (round-off of the cuts: 1e-13).
MATCH_TOLERANCE = 1e-9


@dataclass(frozen=True)
class Motion:
    """``x -> rotation @ x + shift`` in the horizontal plane.

    Attributes
    ----------
    rotation : ndarray, shape (2, 2)
        Orthogonal: a rotation, or a mirror (determinant -1).
    shift : ndarray, shape (2,)
        m.
    """

    rotation: FloatArray
    shift: FloatArray

    @classmethod
    def identity(cls) -> Motion:
        """The motion that leaves every point where it is."""
        return cls(np.eye(2), np.zeros(2))

    def apply(self, points: FloatArray) -> FloatArray:
        """``points`` (K, 2) moved, m."""
        out: FloatArray = points @ self.rotation.T + self.shift
        return out


def congruence_classes(pieces: list[Polygon], motions: Motions) -> list[tuple[int, Motion]]:
    """For each piece, the first piece it is a copy of and the motion onto it from there.

    Parameters
    ----------
    pieces
        Hole-free polygons (m).
    motions
        ``"rigid"``: copies turned, mirrored and shifted; ``"translations"``: shifted only.

    Returns
    -------
    list of (int, Motion)
        ``(k, motion)`` per piece: ``pieces[k]`` (``k`` the lowest such index, the
        piece itself when it is the first of its class) moved by ``motion`` is
        this piece. A class's first piece has the identity.
    """
    classes: list[tuple[int, Motion]] = []
    firsts: list[int] = []
    for piece in pieces:
        found = None
        for k in firsts:
            motion = motion_onto(pieces[k], piece, motions)
            if motion is not None:
                found = (k, motion)
                break
        if found is None:
            firsts.append(len(classes))
            found = (len(classes), Motion.identity())
        classes.append(found)
    return classes


def motion_onto(a: Polygon, b: Polygon, motions: Motions) -> Motion | None:
    """The motion that takes ``a`` onto ``b`` (their corners onto each other), or None.

    A shift is tried first: a copy that is only shifted keeps its plan under
    per-axis limits too, and a symmetric piece (a rectangle) is also its own
    turned or mirrored image.
    """
    size = 1.0 + float(np.sqrt(a.area))
    pa, pb = _corners(a, MATCH_TOLERANCE * size), _corners(b, MATCH_TOLERANCE * size)
    if len(pa) != len(pb) or abs(a.area - b.area) > MATCH_TOLERANCE * size**2:
        return None
    ca, cb = pa.mean(axis=0), pb.mean(axis=0)
    # Corners in b's order from each start, and reversed (a mirror reverses the order).
    orders = [np.roll(pb, -k, axis=0) for k in range(len(pb))]
    candidates = [np.eye(2)]
    if motions == "rigid":
        orders += [np.roll(pb[::-1], -k, axis=0) for k in range(len(pb))]
        # Procrustes: the orthogonal matrix (mirrors allowed) that best fits the corners.
        candidates += [orthogonal_procrustes(pa - ca, t - cb)[0].T for t in orders]
    for rotation in candidates:
        motion = Motion(rotation, cb - rotation @ ca)
        moved = motion.apply(pa)
        for target in orders:
            if np.abs(moved - target).max() <= MATCH_TOLERANCE * size:
                return motion
    return None


def _corners(piece: Polygon, tolerance: float) -> FloatArray:
    """The exterior's corners (K, 2) without the closing repeat or straight vertices (within
    ``tolerance`` m of the line through their neighbours: computed cut points are straight
    only up to round-off), m."""
    corners = np.asarray(piece.exterior.coords, dtype=np.float64)[:-1]
    while len(corners) > 3:
        before, after = np.roll(corners, 1, axis=0), np.roll(corners, -1, axis=0)
        chord = after - before
        # Distance of each vertex from the chord joining its neighbours.
        offset = corners - before
        cross = chord[:, 0] * offset[:, 1] - chord[:, 1] * offset[:, 0]
        straight = np.abs(cross) <= tolerance * np.linalg.norm(chord, axis=1)
        if not straight.any():
            break
        corners = np.delete(corners, int(np.argmax(straight)), axis=0)  # one at a time
    return corners
