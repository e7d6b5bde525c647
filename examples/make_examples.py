"""Regenerate the example inputs in this directory (numpy only, deterministic).

Run from anywhere::

    python examples/make_examples.py

Writes, next to this script:

* ``spiral.csv`` -- a hand-drawn Archimedean spiral as a tablet records it
  (``x,y,t``; metres, seconds; ~60 Hz, human-like speed, position jitter).
* ``segments.csv`` -- a 3-D zigzag line-segment plan (``x,y,z``), the kind of
  output a sampling-based planner hands over (paper 003, Fig. 7).
* ``s_corridor.json`` -- an S-shaped safe corridor of 7 yaw-rotated boxes with
  a nominal waypoint path (paper 003, Sec. 5.4, Fig. 9). Its geometry is
  checked with asserts before it is written.

World frame is z-up; all lengths in metres, times in seconds.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
RNG = np.random.default_rng(7)


# --------------------------------------------------------------------------- spiral
def make_spiral(n: int = 400, turns: float = 2.5, span: float = 0.8) -> np.ndarray:
    """Return an (n, 3) array of ``x, y, t`` samples of a hand-drawn spiral r = a*theta.

    ``span`` is the width of the outermost crossing through the centre, r(end) + r(end - pi).
    """
    theta_end = 2.0 * np.pi * turns
    a = span / (2.0 * theta_end - np.pi)
    # Dense arc-length table of the ideal spiral, to place samples by distance drawn.
    th = np.linspace(0.0, theta_end, 20001)
    ds = np.hypot(a, a * th)  # |dp/dtheta| for r = a*theta
    s_tab = np.concatenate([[0.0], np.cumsum(0.5 * (ds[1:] + ds[:-1]) * np.diff(th))])

    # Timestamps: nominal 60 Hz with ~1 ms jitter, kept strictly increasing.
    dt = np.clip(1.0 / 60.0 + RNG.normal(0.0, 1e-3, n - 1), 0.008, None)
    t = np.concatenate([[0.0], np.cumsum(dt)])

    # Pen speed: slow start then accelerating (smoothstep ramp from 25% to 100%),
    # times +-15% jitter smoothed over ~10 samples.
    u = t / t[-1]
    base = 0.25 + 0.75 * (3 * u**2 - 2 * u**3)
    noise = np.convolve(RNG.normal(size=n + 9), np.ones(10) / 10.0, mode="valid")
    speed = base * (1.0 + 0.15 * noise / np.max(np.abs(noise)))
    s = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * dt)])
    s *= s_tab[-1] / s[-1]  # scale so the last sample ends the spiral

    th_s = np.interp(s, s_tab, th)
    xy = a * th_s[:, None] * np.column_stack([np.cos(th_s), np.sin(th_s)])
    xy += RNG.normal(0.0, 1.5e-3, xy.shape)  # hand / digitiser jitter
    assert np.all(np.diff(t) > 0.0)
    return np.column_stack([xy, t])


# ------------------------------------------------------------------------- segments
SEGMENT_WAYPOINTS = np.array(
    [
        [0.0, 0.0, 1.0],
        [2.5, 1.5, 1.4],
        [4.0, -0.5, 1.8],
        [6.5, 1.2, 1.3],
        [8.0, -0.8, 2.0],
        [10.5, 0.6, 1.5],
    ]
)


# ------------------------------------------------------------------------- corridor
# Centreline of the S: headings turn left 0 -> 180 deg, then right 180 -> 0 deg.
HEADINGS_DEG = [0.0, 60.0, 135.0, 180.0, 120.0, 45.0, 0.0]
SEG_LENGTHS = [3.5, 3.0, 3.2, 3.0, 3.2, 3.0, 3.5]  # metres, sum 22.4
WIDTHS = [1.4, 1.5, 1.4, 1.6, 1.4, 1.5, 1.4]  # lateral box size, metres
HEIGHT = 1.2  # vertical box size, metres
END_EXT = 0.7  # each box reaches this far past its centreline endpoints
MIN_CLEARANCE = 0.35  # overlap waypoints are >= this far from every face of both boxes


def box_halfspaces(box: dict) -> tuple[np.ndarray, np.ndarray]:
    """A (6, 3), b (6,) with box = {p : A p <= b} (independent of skyquill)."""
    c, size, yaw = np.array(box["center"]), np.array(box["size"]), np.radians(box["yaw_deg"])
    axes = np.array([[np.cos(yaw), np.sin(yaw), 0.0], [-np.sin(yaw), np.cos(yaw), 0.0], [0, 0, 1]])
    A = np.concatenate([axes, -axes])
    return A, A @ c + np.concatenate([size, size]) / 2.0


def clearance(box: dict, p: np.ndarray) -> np.ndarray:
    """Signed distance of points p (N, 3) inside the box's faces (> 0 means inside)."""
    A, b = box_halfspaces(box)
    return np.min(b[None, :] - p @ A.T, axis=1)


def boxes_overlap_xy(b1: dict, b2: dict) -> bool:
    """Separating-axis test of the two boxes' footprints (rotated rectangles)."""
    polys, axes = [], []
    for box in (b1, b2):
        A = box_halfspaces(box)[0]
        c, (hl, hw, _) = np.array(box["center"][:2]), np.array(box["size"]) / 2.0
        u, v = A[0, :2], A[1, :2]
        polys.append(np.array([c + sx * hl * u + sy * hw * v for sx in (-1, 1) for sy in (-1, 1)]))
        axes += [u, v]
    p1, p2 = polys
    return all(max(p1 @ ax) >= min(p2 @ ax) and max(p2 @ ax) >= min(p1 @ ax) for ax in axes)


def make_corridor() -> dict:
    """Build the S corridor dict and assert its geometric promises."""
    n = len(HEADINGS_DEG)
    nodes = [np.zeros(2)]
    for hdg, length in zip(HEADINGS_DEG, SEG_LENGTHS, strict=True):
        nodes.append(
            nodes[-1] + length * np.array([np.cos(np.radians(hdg)), np.sin(np.radians(hdg))])
        )
    zc = 1.2 + 0.1 * np.arange(n)  # box centre heights climb gently: 1.2 ... 1.8
    node_z = np.concatenate([[zc[0]], 0.5 * (zc[1:] + zc[:-1]), [zc[-1]]])
    waypoints = np.round(np.column_stack([np.array(nodes), node_z]), 4)
    boxes = [
        {
            "center": np.round([*(0.5 * (nodes[i] + nodes[i + 1])), zc[i]], 4).tolist(),
            "size": [SEG_LENGTHS[i] + 2 * END_EXT, WIDTHS[i], HEIGHT],
            "yaw_deg": HEADINGS_DEG[i],
        }
        for i in range(n)
    ]
    # --- checks, done on the rounded numbers that get written -------------------
    assert len(boxes) == 7 and waypoints.shape == (8, 3)
    for b in boxes:
        lo, hi = b["center"][2] - HEIGHT / 2, b["center"][2] + HEIGHT / 2
        assert lo >= 0.5 and hi <= 2.5, b
    assert clearance(boxes[0], waypoints[:1])[0] > 0 and clearance(boxes[-1], waypoints[-1:])[0] > 0
    s = np.linspace(0.0, 1.0, 1001)[:, None]
    for i, box in enumerate(boxes):  # segment i lies in box i
        seg = (1 - s) * waypoints[i] + s * waypoints[i + 1]
        assert np.all(clearance(box, seg) > 0.0), f"segment {i} leaves box {i}"
    for i in range(1, n):  # each overlap waypoint has a healthy ball around it in both boxes
        for box in (boxes[i - 1], boxes[i]):
            assert clearance(box, waypoints[i : i + 1])[0] >= MIN_CLEARANCE, f"overlap {i}"
    for i in range(n):  # no shortcuts: only consecutive boxes touch
        for j in range(i + 2, n):
            assert not boxes_overlap_xy(boxes[i], boxes[j]), f"boxes {i} and {j} overlap"
    length = float(np.sum(np.linalg.norm(np.diff(waypoints, axis=0), axis=1)))
    assert 20.0 <= length <= 25.0, length
    return {
        "description": (
            "S-shaped safe corridor: 7 yaw-rotated boxes chained along a path that turns "
            "left by 180 deg then right by 180 deg (paper 003, Sec. 5.4, Fig. 9). "
            f"Nominal path length {length:.2f} m; waypoints = start, one point in each "
            "consecutive overlap, goal; segment i lies in box i."
        ),
        "frame": "world, z-up, metres",
        "start": waypoints[0].tolist(),
        "goal": waypoints[-1].tolist(),
        "boxes": boxes,
        "waypoints": waypoints.tolist(),
    }


def main() -> None:
    """Write all example files next to this script."""
    spiral = make_spiral()
    np.savetxt(HERE / "spiral.csv", spiral, fmt="%.6f", delimiter=",", header="x,y,t", comments="")

    seg_len = np.linalg.norm(np.diff(SEGMENT_WAYPOINTS, axis=0), axis=1)
    assert np.all((seg_len >= 1.5) & (seg_len <= 4.0)), seg_len
    np.savetxt(
        HERE / "segments.csv",
        SEGMENT_WAYPOINTS,
        fmt="%.6f",
        delimiter=",",
        header="x,y,z",
        comments="",
    )

    corridor = make_corridor()
    text = json.dumps(corridor, indent=2)
    text = re.sub(r"\[\s+([^\[\]{}]+?)\s+\]", lambda m: "[" + " ".join(m[1].split()) + "]", text)
    (HERE / "s_corridor.json").write_text(text + "\n")  # number lists kept on one line
    print(f"wrote spiral.csv ({len(spiral)} samples), segments.csv, s_corridor.json")


if __name__ == "__main__":
    main()
