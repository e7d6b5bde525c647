"""load_svg / load_svg_layers on files as Inkscape and vpype write them: layers, true size."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from skyquill.errors import InputError
from skyquill.strokes import load_svg, load_svg_layers

# As vpype's write_svg(..., show_pen_up=True) writes `vpype rect 0 0 10cm 10cm line ...`:
# width/height in cm, a viewBox in px, the pen-up moves first as a "%" layer.
VPYPE = """<?xml version="1.0" encoding="utf-8" ?>
<svg baseProfile="tiny" height="10.0cm" version="1.2" viewBox="0 0 377.9527559055118 \
377.9527559055118" width="10.0cm" xmlns="http://www.w3.org/2000/svg" \
xmlns:ev="http://www.w3.org/2001/xml-events" xmlns:xlink="http://www.w3.org/1999/xlink" \
xmlns:cc="http://creativecommons.org/ns#" xmlns:dc="http://purl.org/dc/elements/1.1/" \
xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" \
xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#"><defs />
<metadata><rdf:RDF><cc:Work><dc:format>image/svg+xml</dc:format>
<dc:source>vpype rect 0 0 10cm 10cm line 0 10cm 5cm 5cm write -p out.svg</dc:source>
</cc:Work></rdf:RDF></metadata>
<g fill="none" id="pen_up_trajectories" inkscape:groupmode="layer" \
inkscape:label="% pen up trajectories" stroke="black" \
style="display:inline; stroke-opacity: 50%; stroke-width: 0.5">\
<line x1="0.0" y1="0.0" x2="0.0" y2="377.9527559055118" /></g>
<g fill="none" id="layer1" inkscape:groupmode="layer" inkscape:label="1" stroke="#0000ff" \
style="display:inline"><polygon points="0.0,0.0 377.9527559055118,0.0 \
377.9527559055118,377.9527559055118 0.0,377.9527559055118" /></g>
<g fill="none" id="layer2" inkscape:groupmode="layer" inkscape:label="2" stroke="#008000" \
style="display:inline"><line x1="0.0" x2="188.9763779527559" y1="377.9527559055118" \
y2="188.9763779527559" /></g>
</svg>
"""

# As Inkscape 1.x saves a 100 mm x 50 mm document: two visible layers (one with a
# transformed group inside), one hidden layer, a sodipodi:namedview.
INKSCAPE = """<?xml version="1.0" encoding="UTF-8" standalone="no"?>
<svg width="100mm" height="50mm" viewBox="0 0 100 50" version="1.1" id="svg1"
   inkscape:version="1.3.2 (091e20e, 2023-11-25)" sodipodi:docname="drawing.svg"
   xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
   xmlns:sodipodi="http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd"
   xmlns="http://www.w3.org/2000/svg" xmlns:svg="http://www.w3.org/2000/svg">
  <sodipodi:namedview id="namedview1" pagecolor="#ffffff" inkscape:document-units="mm" />
  <defs id="defs1" />
  <g inkscape:label="Outline" inkscape:groupmode="layer" id="layer1">
    <path style="fill:none;stroke:#000000;stroke-width:0.264583" d="M 0,50 100,0" id="path1" />
  </g>
  <g inkscape:groupmode="layer" id="layer2" inkscape:label="Notes" style="display:none">
    <path style="fill:none;stroke:#ff0000" d="M 10,10 H 90" id="path2" />
  </g>
  <g inkscape:groupmode="layer" id="layer3" inkscape:label="Detail">
    <g id="g1" transform="translate(5,0)">
      <path style="fill:none;stroke:#000000" d="m 10,40 h 20" id="path3" />
    </g>
  </g>
</svg>
"""


def _write(tmp_path: Path, text: str, name: str = "d.svg") -> Path:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def _extent(points: np.ndarray) -> np.ndarray:
    return np.asarray(points.max(axis=0) - points.min(axis=0))


def test_vpype_pen_up_layer_is_not_drawn(tmp_path: Path) -> None:
    s = load_svg(_write(tmp_path, VPYPE))
    # The square and the diagonal; not the pen-up move along x = 0.
    assert s.n_strokes == 2
    assert s.paths[0].shape == (5, 2)  # a polygon closes back to its start
    # User units: CSS px (svgelements rounds its mm-to-px constant to 7 digits).
    np.testing.assert_allclose(
        s.paths[1], [[0.0, -377.95275591], [188.97637795, -188.97637795]], rtol=1e-6
    )


def test_vpype_layers_kept_apart_share_the_page(tmp_path: Path) -> None:
    layers = load_svg_layers(_write(tmp_path, VPYPE), true_size=True)
    assert [s.source for s in layers] == ["d.svg layer '1'", "d.svg layer '2'"]
    for s in layers:
        lo, hi = s.bounds()  # the whole drawing, so that every layer scales alike
        np.testing.assert_allclose(hi - lo, [0.1, 0.1], rtol=1e-12)
    np.testing.assert_allclose(_extent(layers[1].paths[0]), [0.05, 0.05], rtol=1e-12)


def test_inkscape_hidden_layer_is_left_out(tmp_path: Path) -> None:
    p = _write(tmp_path, INKSCAPE)
    merged = load_svg(p)
    assert merged.n_strokes == 2
    layers = load_svg_layers(p)
    assert [s.source for s in layers] == ["d.svg layer 'Outline'", "d.svg layer 'Detail'"]
    assert [s.n_strokes for s in layers] == [1, 1]


def test_inkscape_true_size_in_metres(tmp_path: Path) -> None:
    s = load_svg(_write(tmp_path, INKSCAPE), true_size=True)
    np.testing.assert_allclose(s.paths[0], [[0.0, -0.05], [0.1, 0.0]], atol=1e-15)
    # The group's translate(5, 0) in mm, then the path from x = 10 mm to 30 mm.
    np.testing.assert_allclose(s.paths[1], [[0.015, -0.04], [0.035, -0.04]], atol=1e-15)


def test_without_true_size_user_units_stay(tmp_path: Path) -> None:
    s = load_svg(_write(tmp_path, INKSCAPE))
    # svgelements maps the 100-unit viewBox onto 100 mm = 377.95 CSS px.
    np.testing.assert_allclose(_extent(s.paths[0]), [377.95, 188.98], rtol=1e-4)


def test_shapes_outside_layers_form_one_unnamed_layer(tmp_path: Path) -> None:
    body = (
        '<svg xmlns="http://www.w3.org/2000/svg" width="2in" height="1in" viewBox="0 0 2 1">'
        '<path d="M 0 0 L 2 0"/><g id="pen2"><path d="M 0 1 L 1 1"/></g></svg>'
    )
    layers = load_svg_layers(_write(tmp_path, body), true_size=True)
    assert [s.source for s in layers] == ["d.svg layer ''", "d.svg layer 'pen2'"]
    np.testing.assert_allclose(_extent(layers[0].paths[0]), [2 * 0.0254, 0.0], atol=1e-15)


def test_merge_keeps_document_order_around_groups(tmp_path: Path) -> None:
    body = (
        '<svg xmlns="http://www.w3.org/2000/svg">'
        '<path d="M 0 0 L 1 0"/><g id="g"><path d="M 0 1 L 2 1"/></g><path d="M 0 2 L 3 2"/>'
        "</svg>"
    )
    p = _write(tmp_path, body)
    assert [float(np.ptp(s[:, 0])) for s in load_svg(p).paths] == [1.0, 2.0, 3.0]
    layers = load_svg_layers(p)
    assert [s.source for s in layers] == ["d.svg layer ''", "d.svg layer 'g'"]
    assert [float(np.ptp(s[:, 0])) for s in layers[0].paths] == [1.0, 3.0]


def test_only_plotter_skipped_layers_is_refused(tmp_path: Path) -> None:
    body = VPYPE.split('<g fill="none" id="layer1"', maxsplit=1)[0] + "</svg>"
    with pytest.raises(InputError, match=r"d.svg: no path or shape found .*% layers"):
        load_svg(_write(tmp_path, body))


@pytest.mark.parametrize(
    ("size", "message"),
    [
        ('width="100%" height="50mm"', "width: got '100%', expected an absolute length > 0"),
        ('height="50mm"', "width: got no width, expected an absolute length > 0"),
        ('width="40mm"', "height: got no height, expected an absolute length > 0"),
        ('width="0mm" height="5mm"', "width: got '0mm', expected an absolute length > 0"),
        ('width="10mm" height="-5mm"', "height: got '-5mm', expected an absolute length > 0"),
    ],
)
def test_true_size_needs_absolute_width_and_height(tmp_path: Path, size: str, message: str) -> None:
    body = f'<svg xmlns="http://www.w3.org/2000/svg" {size} viewBox="0 0 10 5">'
    p = _write(tmp_path, body + '<path d="M 0 0 L 10 5"/></svg>')
    with pytest.raises(InputError, match=rf"d.svg: {message}"):
        load_svg(p, true_size=True)


def test_a_relative_size_is_fine_without_true_size(tmp_path: Path) -> None:
    body = '<svg xmlns="http://www.w3.org/2000/svg" width="100%" viewBox="0 0 10 5">'
    assert load_svg(_write(tmp_path, body + '<path d="M 0 0 L 10 5"/></svg>')).n_strokes == 1


UNITS_M = {"mm": 1e-3, "cm": 1e-2, "in": 0.0254, "pt": 0.0254 / 72, "pc": 0.0254 / 6}
UNITS_M |= {"px": 0.0254 / 96, "": 0.0254 / 96}


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    width=st.floats(0.5, 5000.0),
    aspect=st.floats(0.2, 5.0),
    unit=st.sampled_from(sorted(UNITS_M)),
    box=st.floats(1.0, 1e4),
)
def test_true_size_is_width_times_unit_whatever_the_viewbox(
    tmp_path: Path, width: float, aspect: float, unit: str, box: float
) -> None:
    height = width * aspect
    head = (
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width!r}{unit}" '
        f'height="{height!r}{unit}" viewBox="0 0 {box!r} {box * aspect!r}">'
    )
    path = f'<path d="M 0 0 L {box!r} {box * aspect!r}"/></svg>'
    s = load_svg(_write(tmp_path, head + path), true_size=True)
    want = np.array([width, height]) * UNITS_M[unit]
    # svgelements composes the viewBox transform in floating point: ~1e-9 apart.
    np.testing.assert_allclose(_extent(s.paths[0]), want, rtol=1e-7)


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(width=st.text(max_size=12), label=st.text(max_size=12))
def test_hostile_sizes_and_labels_give_input_error_or_strokes(
    tmp_path: Path, width: str, label: str
) -> None:
    from xml.sax.saxutils import quoteattr

    body = (
        f'<svg xmlns="http://www.w3.org/2000/svg" '
        f'xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" '
        f'width={quoteattr(width)} height="10mm" viewBox="0 0 10 10">'
        f'<g inkscape:groupmode="layer" inkscape:label={quoteattr(label)}>'
        '<path d="M 0 0 L 10 10"/></g><path d="M 0 10 L 10 0"/></svg>'
    )
    p = _write(tmp_path, body)
    for true_size in (False, True):
        try:
            layers = load_svg_layers(p, true_size=true_size)
        except InputError as exc:
            assert "expected" in str(exc)
            continue
        drawn = 1 if label.startswith("%") else 2
        assert sum(s.n_strokes for s in layers) == drawn


@pytest.mark.parametrize("hidden", ['display="none"', 'style="display: none ;stroke:red"'])
def test_hidden_groups_in_either_spelling_are_left_out(tmp_path: Path, hidden: str) -> None:
    body = (
        f'<svg xmlns="http://www.w3.org/2000/svg"><g {hidden}><path d="M 0 0 L 1 1"/></g>'
        '<path d="M 0 0 L 2 1"/></svg>'
    )
    (s,) = load_svg_layers(_write(tmp_path, body))
    np.testing.assert_array_equal(s.paths[0], [[0.0, 0.0], [2.0, -1.0]])
