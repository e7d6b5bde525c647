"""Where every input file is opened (issue 25): a regular file, a size known first, one BOM rule."""

from __future__ import annotations

import os
import re
import threading
from pathlib import Path

import pytest

from skyquill.errors import InputError
from skyquill.io.source import decode_text, open_text, read_bytes, read_text, special_kind


def test_a_named_pipe_is_refused_at_once_without_blocking(tmp_path: Path) -> None:
    """Issue 25: the JSON stroke reader blocked forever on a pipe no one writes to."""
    pipe = tmp_path / "p.json"
    os.mkfifo(pipe)
    failures: list[str] = []

    def read() -> None:
        try:
            read_bytes(pipe, "a stroke JSON file", max_bytes=100)
        except InputError as exc:
            failures.append(str(exc))

    worker = threading.Thread(target=read, daemon=True)
    worker.start()
    worker.join(timeout=10)
    assert not worker.is_alive(), "blocked on a named pipe"
    assert failures == [f"{pipe}: got a named pipe, expected a stroke JSON file (a regular file)"]
    assert special_kind(pipe) == "a named pipe"


@pytest.mark.parametrize(("path", "kind"), [("/dev/zero", "a character device"), (".", "a folder")])
def test_devices_and_folders_are_refused(path: str, kind: str) -> None:
    with pytest.raises(InputError, match=f"got {kind}"):
        read_bytes(path, "a CSV file", max_bytes=100)
    with pytest.raises(InputError, match=f"got {kind}"), open_text(path, "a CSV", max_bytes=100):
        pass


def test_a_link_to_a_regular_file_is_read(tmp_path: Path) -> None:
    (tmp_path / "a.csv").write_text("x\n")
    (tmp_path / "b.csv").symlink_to(tmp_path / "a.csv")
    assert read_text(tmp_path / "b.csv", "a CSV file", max_bytes=10) == "x\n"


def test_the_size_is_checked_before_reading(tmp_path: Path) -> None:
    (tmp_path / "big.json").write_bytes(b" " * 101)
    with pytest.raises(InputError, match="got 101 bytes, expected a JSON file of at most 100"):
        read_bytes(tmp_path / "big.json", "a JSON file", max_bytes=100)
    with pytest.raises(InputError, match="no such file"):
        read_bytes(tmp_path / "none.json", "a JSON file", max_bytes=100)


@pytest.mark.parametrize("raw", [b"x,y\n1,2\n", b"\xef\xbb\xbfx,y\n1,2\n"])
def test_utf8_with_or_without_its_byte_order_mark_is_the_same_text(raw: bytes) -> None:
    assert decode_text(raw, "p.csv", "a CSV file") == "x,y\n1,2\n"


@pytest.mark.parametrize(
    ("raw", "message"),
    [("x,y".encode("utf-16"), "got UTF-16 text"),
     (b"x,\x00y", "a NUL byte at offset 2"),
     (b"x,\xe9", "not UTF-8 (at offset 2)")],
)  # fmt: skip
def test_other_encodings_and_binary_data_are_refused(raw: bytes, message: str) -> None:
    with pytest.raises(InputError, match=re.escape(message)):
        decode_text(raw, "p.csv", "a CSV file")


def test_every_text_reader_shares_the_one_rule(tmp_path: Path) -> None:
    """A BOM in a CSV, stroke JSON, SVG, WKT and TOML file is read like its absence."""
    from skyquill.coverage.regions import load_region
    from skyquill.io.points import read_points_csv
    from skyquill.show.script import load_script
    from skyquill.strokes import load_stroke_json, load_svg

    bom = b"\xef\xbb\xbf"
    files = {
        "p.csv": b"x,y\n0,0\n1,1\n",
        "s.json": b'{"strokes": [[[0, 0], [1, 1]]]}',
        "d.svg": b'<svg xmlns="http://www.w3.org/2000/svg"><path d="M0 0 L9 9"/></svg>',
        "r.wkt": b"POLYGON ((0 0, 10 0, 10 10, 0 10, 0 0))",
        "s.toml": (
            Path(__file__).resolve().parents[2] / "examples" / "show_small.toml"
        ).read_bytes(),
    }
    readers = {
        "p.csv": lambda p: read_points_csv(p)[0].tolist(),
        "s.json": lambda p: [a.tolist() for a in load_stroke_json(p).paths],
        "d.svg": lambda p: [a.tolist() for a in load_svg(p).paths],
        "r.wkt": lambda p: repr(load_region(p)),
        "s.toml": lambda p: repr(load_script(p)).replace(str(p.parent), "<folder>"),
    }
    for name, raw in files.items():
        (tmp_path / "plain").mkdir(exist_ok=True)
        (tmp_path / "marked").mkdir(exist_ok=True)
        (tmp_path / "plain" / name).write_bytes(raw)
        (tmp_path / "marked" / name).write_bytes(bom + raw)
        read = readers[name]
        assert read(tmp_path / "plain" / name) == read(tmp_path / "marked" / name), name
