"""Strokes of Chinese characters from the Make Me a Hanzi stroke medians.

The data is that of the npm package ``hanzi-writer-data`` 2.0.1 (derived from
Make Me a Hanzi, under the Arphic Public License, see ``data/hanzi/ARPHICPL.TXT``
and ``SOURCE.txt``): one JSON per character with ``"strokes"`` (SVG outlines of
the brush shapes) and ``"medians"`` (per stroke, the ``[x, y]`` points of its
centre line in writing direction). Only the medians are used: they are what a
brush held by a drone follows. All 9,574 characters ship with skyquill, packed
exactly (``data/hanzi/hanzi_medians.npz``, ~2.5 MB; ``tools/pack_hanzi_medians.py``
makes it from the package). Coordinates are in a 1024-unit em box with y
already up: top-left ``(0, 900)``, bottom-right ``(1024, -124)``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from skyquill.errors import InputError
from skyquill.io.source import special_kind
from skyquill.strokes.json_io import read_json
from skyquill.strokes.model import Strokes
from skyquill.validation import FloatArray, as_float

#: Environment variable naming a directory of ``<char>.json`` files (for example
#: an unpacked ``hanzi-writer-data`` package) searched before the bundled set.
HANZI_DIR_ENV = "SKYQUILL_HANZI_DIR"

#: Side of the em box the medians are given in, and the default advance of
#: :func:`hanzi_text`.
EM = 1024.0
#: Bottom and top of the em box, y up: the box of one character is
#: ``[[0, EM_BOTTOM], [EM, EM_TOP]]``.
EM_BOTTOM = -124.0
EM_TOP = EM_BOTTOM + EM

#: The 57 common characters the benchmarks and paper reproductions plan (they
#: were the whole bundle before the full data set shipped).
BENCHMARK_HANZI = (
    "永光成一马当先的是不了人我在有他这中大来上国个到说们为子和你地出道也时年得就那"
    "要下以生会自着去之过家学对可里后小么"
)
#: What is said about a character outside every data set searched.
ALTERNATIVES = (
    "write it from a drawing (--svg FILE, or load_svg in Python), from other stroke "
    "data (--hanzi FILE|DIR, hanzi-writer-data's format), or as text in a Hershey font "
    "(--font); `skyquill hanzi TEXT` lists which characters are available"
)


@dataclass(frozen=True)
class _Bundle:
    """The packed medians (``tools/pack_hanzi_medians.py`` says how they are laid out)."""

    index: dict[str, int]
    first_stroke: NDArray[np.int32]
    first_point: NDArray[np.int32]
    units: NDArray[np.int32]
    scale: float

    def medians(self, char: str) -> list[FloatArray] | None:
        """The strokes of ``char`` (each (K, 2), em-box units), or ``None``."""
        i = self.index.get(char)
        if i is None:
            return None
        strokes = range(int(self.first_stroke[i]), int(self.first_stroke[i + 1]))
        bounds = [(int(self.first_point[j]), int(self.first_point[j + 1])) for j in strokes]
        return [self.units[a:b] / self.scale for a, b in bounds]


@cache
def _bundle() -> _Bundle:
    ref = resources.files("skyquill.strokes").joinpath("data", "hanzi", "hanzi_medians.npz")
    with resources.as_file(ref) as path, np.load(path) as data:
        chars = "".join(map(chr, data["codepoints"].tolist()))
        return _Bundle(
            {c: i for i, c in enumerate(chars)},
            data["first_stroke"],
            data["first_point"],
            data["units"],
            float(data["scale"]),
        )


def bundled_hanzi() -> str:
    """Every character shipped with skyquill (9,574), by code point, as one string."""
    return "".join(_bundle().index)


def missing_hanzi(text: str) -> str:
    """The characters of ``text`` (spaces aside) not shipped with skyquill, each once."""
    index = _bundle().index
    return "".join(dict.fromkeys(c for c in text if not c.isspace() and c not in index))


def _medians_in(entry: Any, char: str, where: str) -> Any:
    """The medians of one character's record (a medians list, or an object with them)."""
    if isinstance(entry, dict):
        if "medians" not in entry:
            raise InputError(f'{where}: the record of {char!r} has no "medians" field')
        return entry["medians"]
    return entry


def _lookup_file(path: Path, char: str) -> Any | None:
    data = read_json(path, f"hanzi-writer data for {char!r}")
    if isinstance(data, dict) and "medians" in data:
        # One character's file, as in hanzi-writer-data: its name says which character.
        held = path.name.removesuffix(".json")
        if len(held) != 1:
            raise InputError(
                f"{path}: got one character's hanzi-writer data in a file named {path.name!r}, "
                f"expected it named after its character (such as 永.json) to write {char!r}, "
                "or an object {character: medians}"
            )
        return data["medians"] if held == char else None
    if isinstance(data, dict):
        if char in data:
            return _medians_in(data[char], char, str(path))
        return None
    raise InputError(
        f'{path}: got a JSON {type(data).__name__}, expected an object with "medians" or '
        "{character: medians}"
    )


def _lookup_dir(directory: Path, char: str) -> Any | None:
    file = directory / f"{char}.json"
    if not file.is_file():
        return None
    return _lookup_file(file, char)


def _lookup(place: Path, char: str) -> Any | None:
    if place.is_dir():
        return _lookup_dir(place, char)
    if place.is_file():
        return _lookup_file(place, char)
    kind = special_kind(place) or "no such file or directory"
    raise InputError(f"{place}: got {kind}, expected hanzi data (a JSON file or a folder)")


def hanzi_strokes(char: str, source: str | Path | None = None) -> Strokes:
    """Strokes of one Chinese character, in stroke order and writing direction.

    Lookup order: ``source`` alone if given; otherwise the directory named by the
    environment variable ``SKYQUILL_HANZI_DIR`` (if set) and then the bundled set
    (:func:`bundled_hanzi`: all 9,574 characters of hanzi-writer-data 2.0.1).

    Parameters
    ----------
    char
        Exactly one character.
    source
        A JSON file (one character's ``hanzi-writer-data`` file with a
        ``"medians"`` field, or an object ``{character: medians}``) or a
        directory of ``<character>.json`` files.

    Returns
    -------
    Strokes
        One stroke per brush stroke (its median), in em-box units (1024 per em),
        y up; ``source`` reads ``"hanzi 永"``.

    Raises
    ------
    InputError
        If ``char`` is not a single character, or is not found (the message
        names it and every place searched), or its data is malformed.
    """
    if not isinstance(char, str) or len(char) != 1:
        raise InputError(
            f"char: got {char!r}, expected exactly one character (use hanzi_text for several)"
        )
    looked: list[str] = []
    medians: Any | None = None
    where = ""
    if source is not None:
        place = Path(source)
        medians = _lookup(place, char)
        looked.append(str(place))
        where = str(place)
    else:
        env = os.environ.get(HANZI_DIR_ENV)
        if env:
            place = Path(env)
            medians = _lookup(place, char)
            looked.append(f"{place} (${HANZI_DIR_ENV})")
            where = str(place)
        if medians is None:
            medians = _bundle().medians(char)
            looked.append(f"the {len(_bundle().index):,} characters of hanzi-writer-data 2.0.1")
            where = "bundled hanzi data"
    if medians is None:
        raise InputError(
            f"char: {char!r} (U+{ord(char):04X}) not found; looked in {'; '.join(looked)}; "
            + ALTERNATIVES
        )
    if not isinstance(medians, list):
        raise InputError(
            f"{where}: medians of {char!r} are a JSON {type(medians).__name__}, "
            "expected a list of strokes"
        )
    return Strokes(paths=tuple(medians), source=f"hanzi {char}")


def hanzi_file(path: str | Path) -> Strokes:
    """Strokes of the character of one ``hanzi-writer-data`` file, named by its file.

    The package ships one JSON per character, named after it (``永.json``),
    holding ``{"strokes": [SVG outlines], "medians": [[[x, y], ...], ...]}``
    (and sometimes ``"radStrokes"``): the file alone says what to write.

    Parameters
    ----------
    path
        The file; its name without ``.json`` is the character.

    Returns
    -------
    Strokes
        As :func:`hanzi_strokes`: one stroke per median, em-box units, y up.

    Raises
    ------
    InputError
        If ``path`` is not a file (a directory needs the text to write), its
        name is not one character, it is not JSON, it is not an object with a
        ``"medians"`` list, or ``"strokes"`` and ``"medians"`` differ in length.
    """
    p = Path(path)
    if not p.is_file():
        what = "a directory" if p.is_dir() else "no such file"
        raise InputError(
            f"hanzi file {p}: got {what}, expected one character's hanzi-writer-data file "
            "such as 永.json (give the text to write to pick from a directory)"
        )
    char = p.name.removesuffix(".json")
    if len(char) != 1:
        raise InputError(
            f"hanzi file {p}: got the name {char!r}, expected a file named after its one "
            "character, such as 永.json"
        )
    data = read_json(p, f"hanzi-writer data for {char!r}")
    if not isinstance(data, dict) or not isinstance(data.get("medians"), list):
        got = f"a JSON {type(data).__name__}" + (
            f" with keys {sorted(data)[:5]}" if isinstance(data, dict) else ""
        )
        raise InputError(
            f'hanzi file {p}: got {got}, expected an object with a "medians" list '
            "(one character's hanzi-writer-data file)"
        )
    outlines = data.get("strokes")
    if isinstance(outlines, list) and len(outlines) != len(data["medians"]):
        raise InputError(
            f'hanzi file {p}: got {len(outlines)} "strokes" and {len(data["medians"])} '
            '"medians", expected one median per stroke'
        )
    return Strokes(paths=tuple(data["medians"]), source=f"hanzi {char}")


def hanzi_text(text: str, source: str | Path | None = None, *, advance: float = EM) -> Strokes:
    """Strokes of several Chinese characters laid left to right.

    Parameters
    ----------
    text
        The characters; a space leaves an empty cell.
    source
        As for :func:`hanzi_strokes`.
    advance
        Horizontal distance between successive characters' em boxes, em-box
        units (> 0); the default 1024 puts the boxes side by side.

    Returns
    -------
    Strokes
        All strokes, character after character, in em-box units, y up; the first
        character's box starts at ``x = 0``.

    Raises
    ------
    InputError
        If ``text`` is empty or only spaces, ``advance`` is not > 0, or any
        character is not found (as :func:`hanzi_strokes`).
    """
    if not isinstance(text, str):
        raise InputError(f"text: got {type(text).__name__}, expected a str")
    if not text.strip():
        raise InputError(f"text: got {text!r}, expected at least one character")
    step = as_float("advance", advance, positive=True)
    paths: list[Any] = []
    for i, ch in enumerate(text):
        if ch.isspace():
            continue
        shift = np.array([i * step, 0.0])
        paths.extend(p + shift for p in hanzi_strokes(ch, source).paths)
    return Strokes(paths=tuple(paths), source=f"hanzi {text}")
