"""``skyquill write`` with inputs as users hand them over: a hanzi file, SVG layers, true size."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from skyquill.cli.main import app
from skyquill.strokes import hanzi_strokes

runner = CliRunner()

# A 100 mm x 100 mm Inkscape drawing: a square outline and a diagonal on two
# layers, and a hidden layer of notes.
SQUARE_MM = """<?xml version="1.0" encoding="UTF-8"?>
<svg width="100mm" height="100mm" viewBox="0 0 100 100" version="1.1"
   xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
   xmlns="http://www.w3.org/2000/svg">
  <g inkscape:label="Square" inkscape:groupmode="layer" id="layer1">
    <path style="fill:none;stroke:#000000" d="M 0,0 H 100 V 100 H 0 Z" />
  </g>
  <g inkscape:label="Notes" inkscape:groupmode="layer" id="layer2" style="display:none">
    <path d="M 0,50 H 100" />
  </g>
  <g inkscape:label="Diagonal" inkscape:groupmode="layer" id="layer3">
    <path d="M 20,80 L 80,20" />
  </g>
</svg>
"""


def _run(tmp_path: Path, *args: str) -> tuple[int, str, Path]:
    out = tmp_path / "out"
    result = runner.invoke(app, ["write", *args, "--out", str(out)])
    return result.exit_code, " ".join(result.output.split()), out


def _strokes(out: Path) -> tuple[list[np.ndarray], list[int]]:
    data = json.loads((out / "input_strokes.json").read_text())
    return [np.array(s) for s in data["strokes"]], data["first_stroke_of_drone"]


def _hanzi_file(tmp_path: Path, char: str, name: str | None = None) -> Path:
    medians = [p.tolist() for p in hanzi_strokes(char).paths]
    p = tmp_path / (name or f"{char}.json")
    data = {"strokes": ["M 0 0 Z"] * len(medians), "medians": medians}
    p.write_text(json.dumps(data, ensure_ascii=False), encoding="utf-8")
    return p


def test_hanzi_file_alone_writes_its_character(tmp_path: Path) -> None:
    code, output, out = _run(tmp_path, "--hanzi", str(_hanzi_file(tmp_path, "永")))
    assert code == 0, output
    strokes, _ = _strokes(out)
    assert len(strokes) == hanzi_strokes("永").n_strokes
    pts = np.concatenate(strokes)[:, :2]
    assert np.ptp(pts, axis=0).max() == pytest.approx(0.5)


def test_svg_true_size_keeps_100_mm(tmp_path: Path) -> None:
    # A circle rather than the square: its corners cannot be flown within 1 mm at
    # 10 cm and the default limits (1.14 mm after 8 stretches).
    svg = tmp_path / "circle.svg"
    svg.write_text(
        SQUARE_MM.replace(
            'd="M 0,0 H 100 V 100 H 0 Z"', 'd="M 0,50 A 50,50 0 1 1 100,50 A 50,50 0 1 1 0,50"'
        ),
        encoding="utf-8",
    )
    # The vehicle's path fitted: fitting the swung tip on a 10 cm drawing, its touch-downs
    # stray 1.1-2 mm (beyond 1 % = 1 mm), and slower timing does not bring them in (an open
    # problem, noted in issue 15's closing note).
    args = ("--svg", str(svg), "--true-size", "--size", "0.5", "--follow", "path")
    code, output, out = _run(tmp_path, *args)
    assert code == 0, output
    strokes, _ = _strokes(out)
    assert len(strokes) == 2  # the circle and the diagonal, not the hidden notes
    np.testing.assert_allclose(np.ptp(np.concatenate(strokes)[:, :2], axis=0), [0.1, 0.1])
    np.testing.assert_allclose(np.ptp(strokes[1][:, :2], axis=0), [0.06, 0.06])
    summary = json.loads((out / "summary.json").read_text())
    assert summary["max_excess"] <= 1e-9
    assert summary["deviation"]["max_m"] <= 0.001  # 1 % of the 0.1 m drawing


def test_svg_layers_kept_give_a_drone_each_on_one_scale(tmp_path: Path) -> None:
    svg = tmp_path / "square.svg"
    svg.write_text(SQUARE_MM, encoding="utf-8")
    code, output, out = _run(tmp_path, "--svg", str(svg), "--layers", "keep", "--size", "0.4")
    assert code == 0, output
    strokes, first = _strokes(out)
    assert first == [0, 1, 2]
    np.testing.assert_allclose(np.ptp(strokes[0][:, :2], axis=0), [0.4, 0.4])
    # The diagonal keeps its size within the drawing (60 of 100 mm), not the board's.
    np.testing.assert_allclose(np.ptp(strokes[1][:, :2], axis=0), [0.24, 0.24])


def test_drones_share_a_line_with_one_scale(tmp_path: Path) -> None:
    code, output, out = _run(tmp_path, "永一", "--drones", "2", "--size", "0.4")
    assert code == 0, output
    strokes, first = _strokes(out)
    yi = np.concatenate(strokes[first[1] :])[:, :2]
    ref = hanzi_strokes("一").paths[0]
    # 一 as wide as in its em box at 0.4 m per em, not stretched to the board.
    assert np.ptp(yi[:, 0]) == pytest.approx(np.ptp(ref[:, 0]) * 0.4 / 1024)
    assert np.ptp(yi[:, 0]) < 0.9 * 0.4


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--hanzi", "{tmp}"], "got a directory, expected one character's hanzi-writer-data"),
        (["--hanzi", "{yi}"], "got the name 'yi', expected a file named after its one"),
        (["--hanzi", "{bad}"], 'expected an object with a "medians" list'),
        (["--hanzi", "{yong}", "--svg", "{svg}"], "--hanzi: got it with --svg, expected TEXT"),
        (["--hanzi", "{yong}", "--drones", "2"], "--drones: several drones need TEXT"),
        (["Hi", "--true-size"], "--true-size: got it with TEXT, expected --svg FILE"),
        (["--hanzi", "{yong}", "--layers", "keep"], "--layers: got it with --hanzi, expected"),
        (["--svg", "{svg}", "--layers", "split"], "--layers: got 'split', expected merge or keep"),
        (["--svg", "{tiny}", "--true-size"], "--true-size: got a drawing of 0.005 m, expected"),
        (["--svg", "{pct}", "--true-size"], "width: got '100%', expected an absolute length"),
    ],
)
def test_wrong_inputs_are_one_line_exit_2(tmp_path: Path, args: list[str], message: str) -> None:
    svg = tmp_path / "square.svg"
    svg.write_text(SQUARE_MM, encoding="utf-8")
    tiny = tmp_path / "tiny.svg"
    tiny.write_text(SQUARE_MM.replace('"100mm"', '"5mm"'), encoding="utf-8")
    pct = tmp_path / "pct.svg"
    pct.write_text(SQUARE_MM.replace('width="100mm"', 'width="100%"'), encoding="utf-8")
    bad = tmp_path / "永.json"
    bad.write_text('{"strokes": []}', encoding="utf-8")
    (tmp_path / "ok").mkdir()
    places = {
        "tmp": str(tmp_path),
        "yi": str(_hanzi_file(tmp_path, "一", "yi.json")),
        "bad": str(bad),
        "yong": str(_hanzi_file(tmp_path / "ok", "永")),
        "svg": str(svg),
        "tiny": str(tiny),
        "pct": str(pct),
    }
    code, output, _ = _run(tmp_path, *(a.format(**places) for a in args))
    assert code == 2, output
    assert message in output
    assert "Traceback" not in output
