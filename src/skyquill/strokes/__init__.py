"""Stroke input: what a person writes, types or draws, as ordered 2-D polylines.

Loaders return :class:`Strokes` (y up, in the source's units; call
:meth:`Strokes.scaled` to get metres):

* :func:`load_stroke_json` -- a tablet's or the studio's recording (JSON);
* :func:`load_svg` -- every drawn path of an SVG drawing (:func:`load_svg_layers`:
  one :class:`Strokes` per layer);
* :func:`text_strokes` -- Latin text in a Hershey vector font;
* :func:`hanzi_strokes`, :func:`hanzi_text` -- Chinese characters from the
  Make Me a Hanzi stroke medians (:func:`hanzi_file`: one character's file);
* :func:`typed_strokes` -- either, by the script of the text
  (:func:`typed_parts`: shared between drones with one scale).

:func:`turning_points` keeps the start, end and turning points of a stroke by
split-and-merge (paper 000, section 4).
"""

from skyquill.strokes.hanzi import bundled_hanzi, hanzi_file, hanzi_strokes, hanzi_text
from skyquill.strokes.hershey import hershey_fonts, line_extent, text_strokes
from skyquill.strokes.json_io import load_stroke_json
from skyquill.strokes.model import Strokes
from skyquill.strokes.svg import load_svg, load_svg_layers
from skyquill.strokes.text import is_cjk, split_text, typed_parts, typed_strokes
from skyquill.strokes.turning import segment_distances, turning_points

__all__ = [
    "Strokes",
    "bundled_hanzi",
    "hanzi_file",
    "hanzi_strokes",
    "hanzi_text",
    "hershey_fonts",
    "is_cjk",
    "line_extent",
    "load_stroke_json",
    "load_svg",
    "load_svg_layers",
    "segment_distances",
    "split_text",
    "text_strokes",
    "turning_points",
    "typed_parts",
    "typed_strokes",
]
