"""Regenerate the painting examples: ``paper_140.csv`` and ``quill.png``.

Run from the repository root: ``.venv/bin/python examples/painting/make_examples.py``.

* ``paper_140.csv`` -- the 140-dot, 3.5 m x 2.1 m drawing used for paper 002's tables
  (:func:`skyquill.painting.dots.paper_drawing`), in the paper's order (right to left, top to
  bottom).
* ``quill.png`` -- a small greyscale picture (a dark disc with a lighter feather stroke and a
  gradient band) for ``skyquill paint --image``.
"""

from __future__ import annotations

from pathlib import Path

from PIL import Image, ImageDraw

from skyquill.painting.dots import paper_drawing, write_dots_csv
from skyquill.painting.order import paper_order

HERE = Path(__file__).resolve().parent


def make_image(path: Path) -> None:
    """A 160 x 96 px picture: dark disc, white feather, grey gradient along the bottom."""
    img = Image.new("L", (160, 96), 255)
    draw = ImageDraw.Draw(img)
    draw.ellipse((20, 8, 100, 88), fill=40)
    draw.polygon([(40, 80), (95, 15), (105, 22), (50, 84)], fill=235)
    for x in range(110, 156):
        draw.line([(x, 60), (x, 90)], fill=int(255 * (x - 110) / 46))
    img.save(path)


def main() -> None:
    """Write both example files next to this script."""
    dots = paper_drawing()
    write_dots_csv(HERE / "paper_140.csv", dots[paper_order(dots)])
    make_image(HERE / "quill.png")


if __name__ == "__main__":
    main()
