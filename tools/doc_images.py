"""Make the documentation's pictures from real runs of the command line.

Every picture in ``docs/images/`` that shows a result is the picture a ``skyquill`` command wrote,
run here on the bundled examples with its defaults, then shrunk for the web (at most
``MAX_WIDTH`` pixels wide, optimised PNG). ``docs/images/summary.json`` records for each picture
the command line that made it and the numbers it reported, so a reader can rerun it::

    .venv/bin/python tools/doc_images.py            # all pictures (about two minutes)
    .venv/bin/python tools/doc_images.py --only fit # one of them

The studio's screenshots come from ``tools/studio_screenshots.py`` instead
(``docs/guides/studio.md``).
"""

from __future__ import annotations

import argparse
import json
import shlex
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from PIL import Image
from rich.progress import Progress
from typer.testing import CliRunner

from skyquill.cli.main import app

ROOT = Path(__file__).resolve().parents[1]
IMAGES = ROOT / "docs" / "images"
MAX_WIDTH = 1400


@dataclass(frozen=True)
class Picture:
    """One picture: the command that draws it, the file it draws, where it goes in the docs."""

    name: str
    args: str
    drawn: str
    image: str
    #: A command run first, whose output folder is ``{plan}`` in ``args``.
    setup: str = ""


PICTURES = (
    Picture("first-character", "write 永 --out {out}", "plot.png", "first-character.png"),
    Picture("ink", "write 永 --fly --out {out}", "ink.png", "ink-yong.png"),
    Picture(
        "fit", "fit examples/spiral.csv --timing path --out {out}", "plot.png", "fit-spiral.png"
    ),
    Picture(
        "fly", "fly {plan} --out {out}", "plot.png", "fly-yong.png", setup="write 永 --out {plan}"
    ),
    Picture(
        "coverage",
        "cover examples/coverage/l_field.geojson --out {out}",
        "plot.png",
        "coverage-l-field.png",
    ),
    Picture(
        "painting",
        "paint examples/painting/paper_140.csv --gamma 10 --out {out}",
        "plot.png",
        "wall-painting.png",
    ),
    Picture(
        "light-painting",
        "write SKY --drones 3 --board sky --out {out}",
        "long_exposure.png",
        "light-painting-sky.png",
    ),
    Picture(
        "show", "show examples/show_small.toml --out {out}", "long_exposure.png", "show-small.png"
    ),
)


def run(command: str, **folders: Path) -> None:
    """Run one ``skyquill`` command line (without ``skyquill``), its folders filled in."""
    args = shlex.split(command.format(**folders))
    args = [str(ROOT / a) if a.startswith("examples/") else a for a in args]
    result = CliRunner().invoke(app, args)
    if result.exit_code != 0:
        raise SystemExit(f"error: skyquill {command}: exit {result.exit_code}: {result.output}")


def make(picture: Picture, work: Path) -> dict[str, Any]:
    """Run ``picture``'s command in ``work`` and copy its picture, shrunk, into ``docs/images``."""
    out, plan = work / picture.name, work / f"{picture.name}-plan"
    if picture.setup:
        run(picture.setup, plan=plan)
    start = time.perf_counter()
    run(picture.args, out=out, plan=plan)
    seconds = time.perf_counter() - start
    with Image.open(out / picture.drawn) as img:
        img.load()
        shrunk = img.convert("RGB") if img.mode in {"RGBA", "P"} else img
        if shrunk.width > MAX_WIDTH:
            height = round(shrunk.height * MAX_WIDTH / shrunk.width)
            shrunk = shrunk.resize((MAX_WIDTH, height), Image.Resampling.LANCZOS)
        shrunk.save(IMAGES / picture.image, optimize=True)
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    numbers = {k: summary[k] for k in ("duration_s", "max_excess") if k in summary}
    return {
        "command": " && ".join(
            f"skyquill {c.format(out='OUT', plan='PLAN')}"
            for c in (picture.setup, picture.args)
            if c
        ),
        "drawn": picture.drawn,
        "seconds": round(seconds, 1),
        **numbers,
    }


def main(argv: list[str] | None = None) -> None:
    """Make the pictures asked for (all by default) and update ``docs/images/summary.json``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", choices=[p.name for p in PICTURES], action="append")
    chosen = parser.parse_args(argv).only
    pictures = [p for p in PICTURES if not chosen or p.name in chosen]
    record_path = IMAGES / "summary.json"
    record = json.loads(record_path.read_text()) if record_path.exists() else {}
    with tempfile.TemporaryDirectory() as tmp, Progress() as bar:
        task = bar.add_task("pictures", total=len(pictures))
        for picture in pictures:
            bar.update(task, description=picture.name)
            record[picture.image] = make(picture, Path(tmp))
            bar.advance(task)
    record_path.write_text(json.dumps(record, indent=1, ensure_ascii=False) + "\n")
    print(f"wrote {len(pictures)} picture(s) into {IMAGES}", file=sys.stderr)


if __name__ == "__main__":
    main()
