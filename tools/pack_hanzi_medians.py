"""Pack the stroke medians of hanzi-writer-data into ``hanzi_medians.npz`` (skyquill's copy).

Usage::

    npm pack hanzi-writer-data@2.0.1 && tar xzf hanzi-writer-data-2.0.1.tgz
    python tools/pack_hanzi_medians.py package src/skyquill/strokes/data/hanzi/hanzi_medians.npz

The package holds one ``<character>.json`` per character with ``"strokes"`` (SVG
outlines), ``"medians"`` (per stroke, the ``[x, y]`` points of its centre line)
and ``"radStrokes"``; only the medians are kept. They are given in a 1024-unit
em box as integers or, for a few strokes, multiples of 1/4 and 1/9, so 36 times
each coordinate is an integer: stored exactly as int32, 9,574 characters, 112,617
strokes and 629,258 points take ~2 MB compressed, against 47 MB of JSON.

Arrays of the file:

* ``codepoints`` (C,) uint32: the characters, sorted by code point;
* ``first_stroke`` (C + 1,) int32: character ``i`` has strokes
  ``first_stroke[i]:first_stroke[i + 1]``;
* ``first_point`` (S + 1,) int32: stroke ``j`` has points ``first_point[j]:first_point[j + 1]``;
* ``units`` (P, 2) int32: the points, in em-box units times :data:`SCALE`.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

#: Em-box units are stored times this (every coordinate is a multiple of 1/36).
SCALE = 36


def pack(package: Path, out: Path) -> None:
    """Read every ``<character>.json`` of ``package`` and write the arrays to ``out``."""
    files = sorted(
        (f for f in package.glob("*.json") if len(f.stem) == 1), key=lambda f: ord(f.stem)
    )
    codepoints, first_stroke, first_point, points = [], [0], [0], []
    for file in files:
        medians = json.loads(file.read_text(encoding="utf-8"))["medians"]
        codepoints.append(ord(file.stem))
        for stroke in medians:
            scaled = SCALE * np.asarray(stroke, dtype=float)
            exact = np.round(scaled)
            if np.abs(scaled - exact).max() > 1e-6:
                raise ValueError(f"{file.name}: a coordinate is not a multiple of 1/{SCALE}")
            points.append(exact.astype(np.int32))
            first_point.append(first_point[-1] + len(stroke))
        first_stroke.append(first_stroke[-1] + len(medians))
    np.savez_compressed(
        out,
        codepoints=np.array(codepoints, dtype=np.uint32),
        first_stroke=np.array(first_stroke, dtype=np.int32),
        first_point=np.array(first_point, dtype=np.int32),
        units=np.concatenate(points),
        scale=np.array(SCALE),
    )
    print(f"{out}: {len(codepoints)} characters, {len(first_point) - 1} strokes")


if __name__ == "__main__":
    pack(Path(sys.argv[1]), Path(sys.argv[2]))
