"""Every reader over mutated valid files: a correct result or one InputError, in bounded memory.

Hypothesis takes a valid file of each format skyquill reads (CSV, JSON strokes, SVG,
GeoJSON, WKT, a TOML show script, a .skyc show) and mutates its bytes: a slice
replaced by random bytes or by a hostile token (``NaN``, ``1e999``, ``1_0``, ``٠.١``,
a UTF-16 mark, a NUL, a deep bracket), a slice deleted or repeated. The reader must
return a result or raise :class:`~skyquill.errors.SkyquillError` (the CLI prints its
one line) -- never another exception (a traceback) -- and its peak allocation
(tracemalloc, which sees numpy's buffers too) must stay under :data:`PEAK_BYTES`.
"""

from __future__ import annotations

import io
import json
import tempfile
import tracemalloc
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from skyquill.errors import SkyquillError

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
#: Largest allocation a reader may make on one of these small mutated files.
PEAK_BYTES = 256 * 2**20
HOSTILE = [
    b"NaN", b"nan", b"Infinity", b"1e999", b"-1e999", b"1_0", "٠.١".encode(), "０.５".encode(),
    b"\xff\xfe", b"\x00", b"[" * 200, b"{" * 200, b'"', b",", b"\r\n", b"\xef\xbb\xbf", b"-",
    b"99999999999999999999999", b"<!ENTITY a 'aaaa'>", b"M", b"Z", b"(", b")", b"=", b"[[", b"]]",
]  # fmt: skip


def _valid_files() -> dict[str, bytes]:
    csv = "x,y,t\n" + "".join(
        f"{0.1 * k:.3f},{0.05 * (k % 3):.3f},{0.2 * k:.2f}\n" for k in range(8)
    )
    strokes = {"strokes": [[[0, 0], [1, 1], [2, 0]], [[0, 1], [2, 1]]]}
    svg = (
        '<svg xmlns="http://www.w3.org/2000/svg" width="10mm" height="10mm" viewBox="0 0 10 10">'
        '<g transform="translate(1,1) scale(0.5)"><path d="M0 0 L4 4 C5 5 6 6 7 4 Z"/>'
        '<polyline points="0,5 5,5 5,9"/><rect x="1" y="1" width="3" height="2"/>'
        '<circle cx="5" cy="5" r="2"/></g></svg>'
    )
    square = [[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]]
    geojson = {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon",
               "coordinates": [square]}}  # fmt: skip
    return {
        "csv": csv.encode(),
        "strokes": json.dumps(strokes).encode(),
        "svg": svg.encode(),
        "geojson": json.dumps(geojson).encode(),
        "wkt": b"POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0), (2 2, 3 2, 3 3, 2 2))",
        "toml": (EXAMPLES / "show_small.toml").read_bytes(),
        "skyc": _skyc_json(),
    }


def _skyc_json() -> bytes:
    from skyquill.export.skybrush.keyframes import skybrush_keyframes
    from skyquill.export.skybrush.skyc_file import SkycDrone, write_skyc
    from skyquill.trajectory import SplineTrajectory

    ctrl = np.column_stack([np.linspace(0, 2, 8), np.zeros(8), np.full(8, 1.0)])
    # In a folder of its own: every xdist worker builds this at collection, at once.
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "seed.skyc"
        write_skyc([SkycDrone("d0", skybrush_keyframes(SplineTrajectory(ctrl, 5, 4.0)))], path)
        return zipfile.ZipFile(path).read("show.json")


def _read_csv(path: Path) -> Any:
    from skyquill.io.points import read_points_csv

    return read_points_csv(path)


def _read_strokes(path: Path) -> Any:
    from skyquill.strokes import load_stroke_json

    return load_stroke_json(path)


def _read_svg(path: Path) -> Any:
    from skyquill.strokes import load_svg

    return load_svg(path, true_size=True)


def _read_region(path: Path) -> Any:
    from skyquill.coverage.regions import load_region

    return load_region(path)


def _read_toml(path: Path) -> Any:
    from skyquill.show.script import load_script

    return load_script(path)


def _read_skyc(path: Path) -> Any:
    from skyquill.show import load_show

    raw = path.read_bytes()
    archive = path.with_suffix(".skyc")
    with zipfile.ZipFile(archive, "w") as out:
        out.writestr("show.json", raw)
    return load_show([archive])


READERS: dict[str, tuple[str, Callable[[Path], Any]]] = {
    "csv": ("p.csv", _read_csv),
    "strokes": ("s.json", _read_strokes),
    "svg": ("d.svg", _read_svg),
    "geojson": ("r.geojson", _read_region),
    "wkt": ("r.wkt", _read_region),
    "toml": ("s.toml", _read_toml),
    "skyc": ("show.json", _read_skyc),
}
VALID = _valid_files()


@st.composite
def _mutated(draw: st.DrawFn, valid: bytes) -> bytes:
    data = bytearray(valid)
    for _ in range(draw(st.integers(1, 4))):
        start = draw(st.integers(0, len(data)))
        stop = draw(st.integers(start, min(len(data), start + 12)))
        kind = draw(st.sampled_from(["token", "bytes", "delete", "repeat"]))
        if kind == "token":
            data[start:stop] = draw(st.sampled_from(HOSTILE))
        elif kind == "bytes":
            data[start:stop] = draw(st.binary(max_size=8))
        elif kind == "delete":
            del data[start:stop]
        else:
            data[start:start] = bytes(data[start:stop]) * draw(st.integers(1, 50))
    return bytes(data)


def _outcome(reader: Callable[[Path], Any], path: Path) -> int:
    """Run ``reader``; only a result or a SkyquillError may come out. Its peak bytes."""
    tracemalloc.start()
    try:
        reader(path)
    except SkyquillError:
        pass
    finally:
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
    return peak


@pytest.mark.parametrize("kind", sorted(READERS))
def test_the_valid_files_are_read(kind: str, tmp_path: Path) -> None:
    name, reader = READERS[kind]
    (tmp_path / name).write_bytes(VALID[kind])
    assert reader(tmp_path / name) is not None


@pytest.mark.parametrize("kind", sorted(READERS))
@settings(
    max_examples=30,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data())
def test_mutated_files_give_a_result_or_one_input_error(
    kind: str, tmp_path: Path, data: st.DataObject
) -> None:
    name, reader = READERS[kind]
    path = tmp_path / name
    path.write_bytes(data.draw(_mutated(VALID[kind]), label=kind))
    assert _outcome(reader, path) < PEAK_BYTES


def test_the_mutations_reach_the_readers_refusals(tmp_path: Path) -> None:
    """A sanity check of the strategy: the hostile tokens are refused, not read."""
    path = tmp_path / "p.csv"
    path.write_bytes(VALID["csv"].replace(b"0.100", b"1_0"))
    with pytest.raises(SkyquillError, match="plain decimal"):
        _read_csv(path)
    buffer = io.BytesIO(VALID["strokes"].replace(b"[0, 1]", b"[NaN, 1]"))
    path = tmp_path / "s.json"
    path.write_bytes(buffer.getvalue())
    with pytest.raises(SkyquillError, match="NaN"):
        _read_strokes(path)
