"""Every command under hostile but fair input: one plain line and exit 2, files left alone.

Each case runs a command with broken, huge, tiny, non-UTF-8 or adversarial
input and asserts what the README promises: exit status 2 (or 0 where the
input is one the ecosystem really produces, such as a UTF-8 BOM), one line that
names the problem, no traceback, within the per-test time limit, and a file the
user already had in ``--out`` left untouched.
"""

from __future__ import annotations

import json
import os
import struct
import zlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest
from typer.testing import CliRunner

from skyquill.cli.main import app

runner = CliRunner()
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SPIRAL = str(EXAMPLES / "spiral.csv")
SQUARE = str(EXAMPLES / "coverage" / "square_10m.geojson")
DOTS = str(EXAMPLES / "painting" / "paper_140.csv")
#: A file the user had in the output folder: no command may change it.
SENTINEL = "notes.txt"


@dataclass(frozen=True)
class Case:
    """A command line (``{tmp}`` and ``{out}`` filled in), and what must come of it."""

    name: str
    args: list[str]
    message: str  # a piece of the one line of output
    status: int = 2
    setup: Callable[[Path], None] | None = None


def _write(path: str, data: bytes | str) -> Callable[[Path], None]:
    def make(tmp: Path) -> None:
        target = tmp / path
        target.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(data, bytes):
            target.write_bytes(data)
        else:
            target.write_text(data, encoding="utf-8")

    return make


def _both(
    first: Callable[[Path], None] | None, second: Callable[[Path], None]
) -> Callable[[Path], None]:
    def make(tmp: Path) -> None:
        if first is not None:
            first(tmp)
        second(tmp)

    return make


def _png(width: int, height: int) -> bytes:
    """A PNG whose header claims ``width x height`` (one tiny, bogus data chunk)."""

    def chunk(kind: bytes, body: bytes) -> bytes:
        return (
            struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
        )

    header = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(b"\0"))
        + chunk(b"IEND", b"")
    )


def _fit(*extra: str) -> list[str]:
    return ["fit", SPIRAL, "--out", "{out}", *extra]


def _write_cmd(*extra: str) -> list[str]:
    return ["write", "Hi", "--out", "{out}", *extra]


def _cover(*extra: str) -> list[str]:
    return ["cover", SQUARE, "--out", "{out}", *extra]


def _paint(*extra: str) -> list[str]:
    return ["paint", DOTS, "--out", "{out}", *extra]


def _fly(*extra: str) -> list[str]:
    return ["fly", "{tmp}/traj.csv", "--out", "{out}", *extra]


def _export(*extra: str) -> list[str]:
    return ["export", "{tmp}/traj.csv", "--out", "{out}/x.csv", *extra]


TRAJ = (
    "t,x,y,z,vx,vy,vz,ax,ay,az\n0,0,0,1,0,0,0,0,0,0\n1,0.5,0,1,0,0,0,0,0,0\n2,1,0,1,0,0,0,0,0,0\n"
)
WITH_TRAJ = _write("traj.csv", TRAJ)

BAD_NUMBERS = [("-1", "got -1"), ("0", "got 0"), ("nan", "nan"), ("inf", "inf")]

CASES: list[Case] = []

# -- Numbers that cannot be limits, in every command that takes them -------------------------
for cmd, make in (("fit", _fit), ("write", _write_cmd), ("cover", _cover)):
    for flag in ("--vmax", "--amax", "--jmax"):
        for value, message in BAD_NUMBERS:
            CASES.append(Case(f"{cmd} {flag} {value}", make(flag, value), message))
    for value, message in (("0", "rate"), ("-5", "rate"), ("nan", "rate"), ("1e9", "rate")):
        CASES.append(Case(f"{cmd} --rate {value}", make("--rate", value), message))
for flag in ("--vmax-axis", "--amax-axis", "--jmax-axis"):
    for value, message in BAD_NUMBERS[:2]:
        CASES.append(Case(f"fit {flag} {value}", _fit(flag, value), message))

# -- Output folders that cannot be used, in every command --------------------------------------
OUT_COMMANDS: dict[str, list[str]] = {
    "fit": _fit(),
    "write": _write_cmd(),
    "cover": _cover(),
    "paint": _paint(),
    "fly": _fly(),
    "reproduce segments": ["reproduce", "segments", "--out", "{out}"],
    "demo": ["demo", "--out", "{out}"],
}

# -- Input files a user might hand over --------------------------------------------------------
CSV_CASES = [
    ("utf-16", "\ufeffx,y\n0,0\n1,1\n".encode("utf-16"), "UTF-16"),
    ("binary", bytes(range(256)) * 4, "expected"),
    ("latin-1", "x,y\n0,0\n1,é\n".encode("latin-1"), "UTF-8"),
    ("empty", b"", "empty"),
    ("header only", b"x,y\n", "row"),
    ("one row", b"x,y\n0,0\n", "row"),
    ("two x columns", b"x,x,y\n0,1,0\n1,2,1\n", "more than once"),
    ("strings", b"x,y\n0,0\n1,one\n", "one"),
    ("nan", b"x,y\n0,0\nnan,1\n", "nan"),
    ("ragged", b"x,y\n0,0\n1,1,1\n", "columns"),
    ("no y", b"x,z\n0,0\n1,1\n", "missing y"),
    ("huge coordinate", b"x,y\n0,0\n1e300,1\n", "magnitude"),
    ("repeated times", b"x,y,t\n0,0,0\n1,1,0\n", "increasing"),
]
for label, data, message in CSV_CASES:
    args = ["fit", "{tmp}/p.csv", "--out", "{out}"]
    CASES.append(Case(f"fit csv {label}", args, message, setup=_write("p.csv", data)))
BOM_CSV = "\ufeffx,y\n" + "".join(f"{i / 10},{(i % 3) / 10}\n" for i in range(12))
CASES.append(
    Case(
        "fit csv with a UTF-8 BOM is accepted",
        ["fit", "{tmp}/p.csv", "--out", "{out}"],
        "done",
        status=0,
        setup=_write("p.csv", BOM_CSV),
    )
)
for label, data, message in [
    ("missing columns", "t,x,y,z\n0,0,0,0\n1,1,1,1\n", "expected columns"),
    ("one row", TRAJ.splitlines()[0] + "\n" + TRAJ.splitlines()[1] + "\n", "row"),
    ("backwards time", TRAJ.replace("\n2,", "\n0.5,"), "increasing"),
    ("utf-16", TRAJ.encode("utf-16"), "UTF-16"),
]:
    CASES.append(Case(f"fly trajectory {label}", _fly(), message, setup=_write("traj.csv", data)))
    CASES.append(
        Case(f"export trajectory {label}", _export(), message, setup=_write("traj.csv", data))
    )
SPLINE_JSON = (
    '{{"format": "skyquill-bspline", "degree": 5, "duration_s": 1, "control_points": {points}}}'
)
for label, text, message in [
    ("not json", "{", "malformed JSON"),
    ("deep json", "[" * 100_000 + "]" * 100_000, "nested"),
    ("other format", '{"format": "x"}', "format"),
    ("ragged spline", SPLINE_JSON.format(points="[[0,0],[1]]"), "ragged"),
    (
        "nan spline",
        SPLINE_JSON.format(points=json.dumps([[0, 0, "NaN"]] + [[0, 0, 0]] * 5)),
        "non-numeric",
    ),
]:
    export_args = ["export", "{tmp}/t.json", "--out", "{out}/x.csv"]
    fly_args = ["fly", "{tmp}/t.json", "--out", "{out}"]
    CASES.append(Case(f"export json {label}", export_args, message, setup=_write("t.json", text)))
    CASES.append(Case(f"fly json {label}", fly_args, message, setup=_write("t.json", text)))

# -- Stroke, SVG, region and image files ---------------------------------------------------------
STROKE = [[0, 0], [1, 1]]
SVG = '<svg xmlns="http://www.w3.org/2000/svg">{}</svg>'
SQUARE_RING = [[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]]
READER_CASES = [
    ("strokes deep", "write", "s.json", "[" * 100_000 + "]" * 100_000, "nested"),
    ("strokes strings", "write", "s.json", json.dumps({"strokes": [[["1", "2"], [3, 4]]]}),
     "two JSON numbers"),
    ("strokes too many", "write", "s.json", json.dumps({"strokes": [STROKE] * 3000}), "at most"),
    ("strokes utf-16", "write", "s.json", json.dumps({"strokes": [STROKE]}).encode("utf-16"),
     "UTF-16"),
    ("strokes binary", "write", "s.json", b"\x00\x01\x02" * 100, "binary"),
    ("svg nan", "write", "d.svg", SVG.format('<path d="M 0 0 L NaN 5"/>'), "nan"),
    ("svg many paths", "write", "d.svg", SVG.format('<path d="M 0 0 L 1 1"/>' * 3000), "at most"),
    ("geojson strings", "cover", "r.geojson",
     json.dumps({"type": "Polygon", "coordinates": [[[str(c) for c in p] for p in SQUARE_RING]]}),
     "number"),
    ("geojson z", "cover", "r.geojson",
     json.dumps({"type": "Polygon", "coordinates": [[[*p, 5] for p in SQUARE_RING]]}), "2-D"),
    ("geojson deep", "cover", "r.geojson", "[" * 100_000 + "]" * 100_000, "nested"),
    ("geojson latin-1", "cover", "r.geojson", '{"type": "Polygon", "name": "é"}'.encode("latin-1"),
     "UTF-8"),
    ("image too large", "paint", "big.png", _png(20000, 20000), "pixels"),
    ("image not an image", "paint", "x.png", b"not a png at all", "png"),
]  # fmt: skip
for label, cmd, name, data, message in READER_CASES:
    if cmd == "write":
        flag = "--svg" if name.endswith(".svg") else "--strokes"
        args = ["write", flag, f"{{tmp}}/{name}", "--out", "{out}"]
    elif cmd == "cover":
        args = ["cover", f"{{tmp}}/{name}", "--out", "{out}"]
    else:
        args = ["paint", "--image", f"{{tmp}}/{name}", "--out", "{out}"]
    CASES.append(Case(f"{cmd} {label}", args, message, setup=_write(name, data)))

# -- Work that would not end, or not be what was asked (estimated before it starts) ---------------
KM_SQUARE = json.dumps(
    {"type": "Polygon", "coordinates": [[[0, 0], [1000, 0], [1000, 1000], [0, 1000], [0, 0]]]}
)
LONG_TRAJ = "t,x,y,z,vx,vy,vz,ax,ay,az\n0,0,0,1,0,0,0,0,0,0\n1000000,1,0,1,0,0,0,0,0,0\n"
MOVING_END = TRAJ.replace("2,1,0,1,0,0,0", "2,1,0,1,0.5,0,0")
BOUND_CASES = [
    Case("fit at 1000 m/s is re-timed slower", _fit("--timing", "path", "--vmax", "1000"), "done",
         status=0),
    Case("fit that cannot follow its points", _fit("--knot-interval", "5"), "from the points"),
    Case("write --size 1e-6", _write_cmd("--size", "1e-6"), "--size: got 1e-06 m"),
    Case("write --size 1e6", _write_cmd("--size", "1e6"), "--size: got 1e+06 m"),
    Case("write --lift 1000", _write_cmd("--lift", "1000"), "lift"),
    Case("write limits of 1e12", _write_cmd("--vmax", "1e12", "--amax", "1e12", "--jmax", "1e12"),
         "SI units"),
    Case("write at 1000 m/s cannot stay on the strokes",
         _write_cmd("--vmax", "1000", "--amax", "1e4", "--jmax", "1e6"), "lower speed limit"),
    Case("cover --altitude -5", _cover("--altitude", "-5"), "altitude"),
    Case("cover a km square at 2 m",
         ["cover", "{tmp}/km.geojson", "--out", "{out}", "--crs", "local"], "km",
         setup=_write("km.geojson", KM_SQUARE)),
    Case("cover --width 0.001", _cover("--width", "0.001"), "km"),
    Case("fly --rate 1e6", _fly("--rate", "1e6"), "rate", setup=WITH_TRAJ),
    Case("fly 10^6 s", _fly(), "steps", setup=_write("traj.csv", LONG_TRAJ)),
    Case("fly a moving end", _fly(), "expected rest", setup=_write("traj.csv", MOVING_END)),
    Case("fly --seed -1", _fly("--seed", "-1"), "seed", setup=WITH_TRAJ),
    Case("paint --seed -1", _paint("--seed", "-1"), "seed"),
    Case("paint --rate 0", _paint("--rate", "0"), "--rate: got 0"),
]  # fmt: skip
CASES.extend(BOUND_CASES)

# -- Options out of range -----------------------------------------------------------------------
OPTION_CASES = [
    ("fit --degree 9", _fit("--degree", "9"), "degree"),
    ("fit --timing sideways", _fit("--timing", "sideways"), "--timing"),
    ("fit --hull round", _fit("--hull", "round"), "--hull"),
    ("fit --solver cplex", _fit("--solver", "cplex"), "solver"),
    ("fit --knot-interval 0", _fit("--knot-interval", "0"), "--knot-interval: got 0"),
    ("fit --norm-sides 2", _fit("--norm-sides", "2"), "--norm-sides: got 2"),
    ("fit --weight -1", _fit("--weight", "-1"), "weight"),
    ("write --board ceiling", _write_cmd("--board", "ceiling"), "--board"),
    ("write --drones 0", _write_cmd("--drones", "0"), "drones"),
    ("write --drones -3", _write_cmd("--drones", "-3"), "drones"),
    ("write no input", ["write", "--out", "{out}"], "expected"),
    ("write --font nope", _write_cmd("--font", "nope"), "font"),
    ("write absent svg", ["write", "--svg", "{tmp}/none.svg", "--out", "{out}"], "svg"),
    (
        "write absent strokes",
        ["write", "--strokes", "{tmp}/none.json", "--out", "{out}"],
        "strokes",
    ),
    ("write --fly on a wall", _write_cmd("--fly", "--board", "wall"), "--fly"),
    ("cover --pattern snake", _cover("--pattern", "snake"), "pattern"),
    ("cover --width 0", _cover("--width", "0"), "width"),
    ("cover --width 50", _cover("--width", "50"), "width"),
    ("cover --epsilon 2", _cover("--epsilon", "2"), "epsilon"),
    ("cover --delta 0", _cover("--delta", "0"), "delta"),
    ("cover --min-coverage 1.5", _cover("--min-coverage", "1.5"), "--min-coverage"),
    ("cover --contours wavy", _cover("--contours", "wavy"), "contours"),
    ("cover --drift sideways", _cover("--drift", "sideways"), "drift"),
    ("cover norms and axes", _cover("--amax", "5", "--amax-axis", "5"), "got both"),
    ("cover absent region", ["cover", "{tmp}/none.geojson", "--out", "{out}"], "none.geojson"),
    ("paint --gamma 90", _paint("--gamma", "90"), "--gamma"),
    ("paint --offset 1,2", _paint("--offset", "1,2"), "--offset"),
    ("paint --offset in front", _paint("--offset", "0,1,0"), "--offset"),
    ("paint --estimator magic", _paint("--estimator", "magic"), "estimator"),
    ("paint --order random", _paint("--order", "random"), "order"),
    ("paint --update sideways", _paint("--update", "sideways"), "--update"),
    ("paint --false-contacts 1", _paint("--false-contacts", "1"), "--false-contacts"),
    ("paint --missed-contacts -0.1", _paint("--missed-contacts", "-0.1"), "--missed-contacts"),
    ("paint --wall-angles x", _paint("--wall-angles", "x"), "wall"),
    ("paint no dots", ["paint", "--out", "{out}"], "exactly one"),
    ("paint absent image", ["paint", "--image", "{tmp}/none.png", "--out", "{out}"], "none.png"),
    ("fly --controller lqr", _fly("--controller", "lqr"), "--controller"),
    ("fly --sim gazebo", _fly("--sim", "gazebo"), "--sim"),
    ("fly --wind a,b", _fly("--wind", "a,b"), "--wind"),
    ("fly --wind 1e5,0,0", _fly("--wind", "1e5,0,0"), "--wind"),
    ("fly --gust -1", _fly("--gust", "-1"), "--gust"),
    ("fly --noise inf", _fly("--noise", "inf"), "--noise"),
    ("fly --rate 0", _fly("--rate", "0"), "--rate"),
    ("fly absent plan", ["fly", "{tmp}/none", "--out", "{out}"], "plan"),
    ("export --format kml", _export("--format", "kml"), "--format"),
    ("export --out of another kind", ["export", "{tmp}/traj.csv", "--out", "{out}/r.dat"], ".csv"),
    ("export --rate 0", _export("--rate", "0"), "rate"),
    ("export absent plan", ["export", "{tmp}/none", "--out", "{out}/x.csv"], "plan"),
    ("studio --port 0", ["studio", "--port", "0"], "--port"),
    ("studio --port 70000", ["studio", "--port", "70000"], "--port"),
    ("studio --time-limit 0", ["studio", "--time-limit", "0"], "--time-limit"),
    (
        "reproduce corridor absent",
        ["reproduce", "corridor", "--corridor", "{tmp}/no.json", "--out", "{out}"],
        "no.json",
    ),
]
for name, args, message in OPTION_CASES:
    setup = WITH_TRAJ if args[0] in ("fly", "export") else None
    CASES.append(Case(name, args, message, setup=setup))

# -- Output folders: an existing file, a folder under a file, a name with rich markup -------------
for cmd, args in OUT_COMMANDS.items():
    setup = WITH_TRAJ if cmd == "fly" else None
    make_file = _both(setup, _write("a_file", "x"))
    as_file = [a.replace("{out}", "{tmp}/a_file") for a in args]
    under_file = [a.replace("{out}", "{tmp}/a_file/sub") for a in args]
    CASES.append(Case(f"{cmd} --out is a file", as_file, "existing file", setup=make_file))
    CASES.append(Case(f"{cmd} --out under a file", under_file, "a_file", setup=make_file))

# -- Text from the user printed literally (rich markup would eat or choke on it) ----------------
CASES.append(
    Case(
        "a missing file named like markup",
        ["fit", "{tmp}/a[/]b[red].csv", "--out", "{out}"],
        "a[/]b[red].csv",
    )
)
CASES.append(
    Case(
        "columns listed in brackets",
        ["fit", "{tmp}/p.csv", "--out", "{out}"],
        "['a', 'b']",
        setup=_write("p.csv", "a,b\n0,0\n1,1\n"),
    )
)
CASES.append(
    Case(
        "an --out folder named like markup",
        ["fit", SPIRAL, "--out", "{tmp}/[bold]x[/]", "--rate", "20"],
        "done",
        status=0,
    )
)


# -- Data that would be lost ----------------------------------------------------------------------
def _plan(tmp: Path) -> None:
    done = runner.invoke(app, ["fit", SPIRAL, "--out", str(tmp / "plan"), "--rate", "20"])
    assert done.exit_code == 0, done.output


CASES.append(
    Case(
        "fly into the plan folder it reads",
        ["fly", "{tmp}/plan", "--out", "{tmp}/plan", "--rate", "100"],
        "was written by skyquill fit",
        setup=_plan,
    )
)
CASES.append(
    Case(
        "export json over the plan's own trajectory.json",
        ["export", "{tmp}/plan", "--format", "json", "--out", "{tmp}/plan/trajectory.json"],
        "inputs",
        setup=_plan,
    )
)
# -- Show scripts, pictures and light painting -------------------------------------------------
SMALL_SHOW = (EXAMPLES / "show_small.toml").read_text()


def _show(edit: tuple[str, str] | None = None, raw: bytes | None = None) -> Callable[[Path], None]:
    """A show script in {tmp}/s.toml: the small example edited, or raw bytes."""
    text = SMALL_SHOW if edit is None else SMALL_SHOW.replace(*edit, 1)
    return _write("s.toml", raw if raw is not None else text)


SHOW = ["show", "{tmp}/s.toml", "--out", "{out}"]
SHOW_CASES = [
    ("binary", _show(raw=bytes(range(256)) * 8), "TOML"),
    ("utf-16", _show(raw=SMALL_SHOW.encode("utf-16")), "got UTF-16 text"),
    ("5000 drones", _show(("drones = 10", "drones = 5000")), "expected an integer from 1 to 1000"),
    ("hold a day", _show(("hold = 3.0", "hold = 86400")), "holding"),
    ("stagger 1e9", _show(("stagger = 1.0", "stagger = 1e9")), "holding"),
    ("altitude 1e4", _show(("altitude = 3.0", "altitude = 1e4")), "altitude: got 10000 m"),
    ("radius 1e6", _show(("radius = 4.0", "radius = 1e6")), "radius: got 1e+06 m"),
    ("far origin", _show(("[-3.0, -6.0, 6.0]", "[1e300, 0, 6.0]")), "within 10000 m"),
    ("rate 1e9", _show(("rate = 20", "rate = 1e9")), "rate: got 1e+09 Hz"),
    ("scene type a list", _show(('type = "write"', 'type = ["write"]')), "type"),
    ("nan size", _show(("size = 1.5", "size = nan")), "size"),
    ("unknown key", _show(("hold = 3.0", "hold = 3.0\nsparkle = true")), "sparkle"),
    ("absent geofence", _show(("rate = 20", 'rate = 20\ngeofence = "none.wkt"')), "geofence"),
]
for label, setup, message in SHOW_CASES:
    CASES.append(Case(f"show {label}", SHOW, message, setup=setup))
RENDER = ["render", "{tmp}/traj.csv", "--out", "{out}"]
CASES.extend(
    [
        Case("render --trail nan", [*RENDER, "--trail", "nan"], "--trail", setup=WITH_TRAJ),
        Case("render --fov 180", [*RENDER, "--fov", "180"], "--fov: got 180", setup=WITH_TRAJ),
        Case("render --light 1,2", [*RENDER, "--light", "1,2"], "--light", setup=WITH_TRAJ),
        Case("render absent", ["render", "{tmp}/none", "--out", "{out}"], "none"),
        Case("write --board-tilt 90", _write_cmd("--board", "sky", "--board-tilt", "90"), "tilt"),
        Case("write --grid 0x3", _write_cmd("--board", "sky", "--grid", "0x3"), "--grid"),
        Case("write --light-color red", _write_cmd("--light-color", "red"), "--light-color"),
        Case("write --split words", _write_cmd("--split", "words"), "--split"),
    ]
)

OVER_INPUT = ["export", "{tmp}/traj.csv", "--out", "{tmp}/traj.csv"]
CASES.append(Case("export over its own input", OVER_INPUT, "inputs", setup=WITH_TRAJ))

# -- paint: wall descriptions that are not walls, dots outside them (issue 29) -----------------
PAINT_WALL = ["paint", DOTS, "--wall", "{tmp}/w.toml", "--out", "{out}"]
THREE_SEGMENTS = "".join(
    f"[[segment]]\nfrom = {a}\nto = {b}\nangle = {angle}\n"
    for a, b, angle in ((-4, -0.6, -10), (-0.6, 0.6, 0), (0.6, 4, 10))
)
WALL_CASES = [
    ("segments overlap", THREE_SEGMENTS.replace("from = 0.6", "from = 0.2"), "overlaps"),
    ("segments leave a gap", THREE_SEGMENTS.replace("from = 0.6", "from = 0.9"), "gap"),
    ("angle 90", THREE_SEGMENTS.replace("angle = 10", "angle = 90"), "segment[2].angle"),
    ("angle 135", THREE_SEGMENTS.replace("angle = 10", "angle = 135"), "90 deg or more"),
    ("turned middle", THREE_SEGMENTS.replace("angle = 0", "angle = 5"), "holding x = 0"),
    ("not toml", "[[segment", "malformed TOML"),
    ("binary", bytes(range(256)), "not UTF-8"),
    ("unknown key", "colour = 1\n" + THREE_SEGMENTS, "wall: got unknown key 'colour'"),
    ("two shapes", "[cylinder]\nradius = 20\n[recess]\nfrom = 1\nto = 2\ndepth = 0.1\n",
     "exactly one"),
    ("tight cylinder", "[cylinder]\nradius = 2\n", "cylinder.radius"),
    ("recess over the origin", "[recess]\nfrom = -0.5\nto = 0.5\ndepth = 0.1\n", "beside x = 0"),
    ("dots beside it", "extent = [-1.0, 1.0]\n[cylinder]\nradius = 20\n", "outside the wall"),
    ("dots above it", "height = 1.5\n[cylinder]\nradius = 20\n", "outside the wall"),
]  # fmt: skip
for label, text, message in WALL_CASES:
    CASES.append(Case(f"paint --wall {label}", PAINT_WALL, message, setup=_write("w.toml", text)))
CASES.extend(
    [
        Case("paint --wall absent", PAINT_WALL, "w.toml"),
        Case(
            "paint --wall and --wall-angles",
            [*PAINT_WALL, "--wall-angles", "-10,0,10"],
            "got both",
            setup=_write("w.toml", THREE_SEGMENTS),
        ),
        Case("paint --wall-angles 90", _paint("--wall-angles", "-10,90,10"), "--wall-angles"),
        Case("paint --probe-spacing -1", _paint("--probe-spacing", "-1"), "--probe-spacing"),
        Case("paint --probe-spacing nan", _paint("--probe-spacing", "nan"), "--probe-spacing"),
        Case("paint --order spiral", _paint("--order", "spiral"), "--order"),
    ]
)


# -- Issue 25: the last hostile findings, each a row ----------------------------------------------
def _fifo(name: str) -> Callable[[Path], None]:
    """A named pipe no program writes to: reading it would block forever."""

    def make(tmp: Path) -> None:
        os.mkfifo(tmp / name)

    return make


def _refifo(path: Path) -> None:
    """``path`` replaced by a named pipe no program writes to."""
    path.unlink()
    os.mkfifo(path)


def _copy(source: Path, name: str) -> Callable[[Path], None]:
    return _write(name, source.read_bytes())


ONE_HANZI = json.dumps({"strokes": ["M 0 0"], "medians": [[[100, 500], [900, 500]]]})
NO_OVERLAP = json.loads((EXAMPLES / "s_corridor.json").read_text())
NO_OVERLAP["boxes"][3]["center"] = [100.0, 100.0, 1.3]
OPEN_RING = {"type": "Polygon", "coordinates": [[[0, 0], [10, 0], [10, 10], [0, 10]]]}
BOM_SHOW = b"\xef\xbb\xbf" + SMALL_SHOW.replace("drones = 10", "drones = 5000", 1).encode()
LONG_NAME = "a" * 300
ISSUE25 = [
    # Hangs: a reader meets a named pipe (the JSON stroke reader blocked forever).
    Case("write --strokes a named pipe", ["write", "--strokes", "{tmp}/p.json", "--out", "{out}"],
         "got a named pipe", setup=_fifo("p.json")),
    Case("write --svg a named pipe", ["write", "--svg", "{tmp}/p.svg", "--out", "{out}"],
         "got a named pipe", setup=_fifo("p.svg")),
    Case("write --hanzi a named pipe",
         ["write", "永", "--hanzi", "{tmp}/永.json", "--out", "{out}"], "got a named pipe",
         setup=_fifo("永.json")),
    Case("fit a named pipe", ["fit", "{tmp}/p.csv", "--out", "{out}"], "got a named pipe",
         setup=_fifo("p.csv")),
    Case("cover a named pipe", ["cover", "{tmp}/r.geojson", "--out", "{out}"], "got a named pipe",
         setup=_fifo("r.geojson")),
    Case("show a named pipe", ["show", "{tmp}/s.toml", "--out", "{out}"], "got a named pipe",
         setup=_fifo("s.toml")),
    Case("check a named pipe", ["check", "{tmp}/s.skyc"], "got a named pipe",
         setup=_fifo("s.skyc")),
    Case("paint --image a named pipe", ["paint", "--image", "{tmp}/p.png", "--out", "{out}"],
         "got a named pipe", setup=_fifo("p.png")),
    Case("export a named pipe", ["export", "{tmp}/t.json", "--out", "{out}/x.csv"],
         "got a named pipe", setup=_fifo("t.json")),
    Case("fly a named pipe", ["fly", "{tmp}/t.csv", "--out", "{out}"], "got a named pipe",
         setup=_fifo("t.csv")),
    Case("check --geofence a named pipe",
         ["check", "{tmp}/traj.csv", "--geofence", "{tmp}/g.wkt"], "got a named pipe",
         setup=_both(WITH_TRAJ, _fifo("g.wkt"))),
    Case("write --svg /dev/zero", ["write", "--svg", "/dev/zero", "--out", "{out}"],
         "got a character device"),
    Case("paint a dot CSV that is a named pipe", ["paint", "{tmp}/d.csv", "--out", "{out}"],
         "got a named pipe", setup=_fifo("d.csv")),
    Case("cover a WKT named pipe", ["cover", "{tmp}/r.wkt", "--out", "{out}"],
         "got a named pipe", setup=_fifo("r.wkt")),
    Case("render a named pipe", ["render", "{tmp}/t.csv", "--out", "{out}"], "got a named pipe",
         setup=_fifo("t.csv")),
    Case("reproduce corridor --corridor a named pipe",
         ["reproduce", "corridor", "--corridor", "{tmp}/c.json", "--out", "{out}"],
         "got a named pipe", setup=_fifo("c.json")),
    Case("fly a plan folder whose trajectory.json is a named pipe",
         ["fly", "{tmp}/plan", "--out", "{out}"], "got a named pipe",
         setup=_both(_plan, lambda tmp: _refifo(tmp / "plan" / "trajectory.json"))),
    Case("write --strokes /dev/zero", ["write", "--strokes", "/dev/zero", "--out", "{out}"],
         "got a character device"),
    Case("fit a folder", ["fit", "{tmp}", "--out", "{out}"], "got a folder"),
    Case("fit above the knot-span ceiling", _fit("--knot-interval", "1e-4"), "--knot-interval"),
    Case("fit --timing segments above the knot-span ceiling (took 260 s and 1 GB)",
         _fit("--timing", "segments", "--knot-interval", "1e-4"), "--knot-interval"),
    # Tracebacks.
    Case("write --light-color 1,2,²", _write_cmd("--light-color", "1,2,²"), "--light-color"),
    Case("export --light 1,2,²", _export("--light", "1,2,²"), "--light", setup=WITH_TRAJ),
    Case("render --light 1,2,²", [*RENDER, "--light", "1,2,²"], "--light", setup=WITH_TRAJ),
    Case("write --scheduler nonsense://x", _write_cmd("--scheduler", "nonsense://x"),
         "--scheduler: got 'nonsense://x'"),
    Case("show --scheduler nonsense://x", [*SHOW, "--scheduler", "nonsense://x"], "--scheduler",
         setup=_show()),
    Case("write --scheduler at a port no scheduler answers (was a Client.__del__ traceback)",
         ["write", "H I", "--drones", "2", "--scheduler", "tcp://127.0.0.1:9", "--out", "{out}"],
         "expected the address of a running dask scheduler"),
    Case("cover --origin-alt 1e308", _cover("--origin-alt", "1e308"), "--origin-alt"),
    # Wrong results that exited 0.
    Case("export --rate 1e-3", _export("--rate", "1e-3"), "--rate: got 0.001", setup=WITH_TRAJ),
    Case("export --rate 1e-320", _export("--rate", "1e-320"), "--rate", setup=WITH_TRAJ),
    Case("export read back beyond --tolerance", ["export", "{tmp}/plan", "--rate", "1", "--out",
         "{out}/x.csv"], "--tolerance: got x.csv", setup=_plan),
    Case("reproduce corridor with a box that overlaps nothing",
         ["reproduce", "corridor", "--corridor", "{tmp}/c.json", "--out", "{out}"],
         "each box to overlap the next", setup=_write("c.json", json.dumps(NO_OVERLAP))),
    Case("write 永一 --hanzi one.json", ["write", "永一", "--hanzi", "{tmp}/one.json", "--out",
         "{out}"], "named after its character", setup=_write("one.json", ONE_HANZI)),
    Case("cover polygon_field.geojson is GeoJSON, not WKT",
         ["cover", "{tmp}/polygon_field.geojson", "--out", "{out}", "--width", "9"], "done spiral",
         status=0, setup=_copy(Path(SQUARE), "polygon_field.geojson")),
    # Silent repairs.
    *[Case(f"fit csv cell {cell}", ["fit", "{tmp}/p.csv", "--out", "{out}"],
           "expected a number in plain decimal digits",
           setup=_write("p.csv", f"x,y\n0,0\n{cell},1\n2,2\n"))
      for cell in ("1_0", "٠.١", "０.５", "0x1", " 1e")],
    *[Case(f"write svg {label}", ["write", "--svg", "{tmp}/d.svg", "--out", "{out}"], message,
           setup=_write("d.svg", SVG.format(body)))
      for label, body, message in [
          ("nan transform", '<g transform="translate(NaN,0)"><path d="M0 0 L10 10"/></g>',
           "<g> number 1 transform"),
          ("garbage transform", '<g transform="rotate(3) wobble"><path d="M0 0 L9 9"/></g>',
           "transform: got 'rotate(3) wobble'"),
          ("odd polyline", '<polyline id="p" points="0,0 10,10 20"/>',
           "<polyline id='p'> points"),
          ("rect width abc", '<rect width="abc" height="10"/><path d="M0 0 L9 9"/>',
           "<rect> number 1 width: got 'abc'"),
          ("path missing a coordinate", '<path d="M0 0 L10 10 L 5"/>',
           "expected 2 numbers for each 'l'"),
          ("negative radius", '<circle cx="0" cy="0" r="-5"/>', "r: got '-5'"),
      ]],
    Case("cover an unclosed GeoJSON ring", ["cover", "{tmp}/r.geojson", "--out", "{out}",
         "--crs", "local"], "rfc 7946", setup=_write("r.geojson", json.dumps(OPEN_RING))),
    Case("write --strokes with a key twice", ["write", "--strokes", "{tmp}/s.json", "--out",
         "{out}"], "got the key 'strokes' twice",
         setup=_write("s.json", '{"strokes": [[[0,0],[1,1]]], "strokes": [[[0,0],[2,2]]]}')),
    Case("cover GeoJSON with a key twice", ["cover", "{tmp}/r.geojson", "--out", "{out}"],
         "got the key 'type' twice",
         setup=_write("r.geojson", '{"type": "Polygon", "type": "Point", "coordinates": []}')),
    Case("export trajectory.json with NaN", ["export", "{tmp}/t.json", "--out", "{out}/x.csv"],
         "got nan", setup=_write("t.json", '{"format": NaN}')),
    *[Case(f"{cmd} --out ''", [a if a != "{out}" else "" for a in args],
           "--out: got '', expected a path")
      for cmd, args in (("fit", _fit()), ("write", _write_cmd()), ("cover", _cover()),
                        ("paint", _paint()), ("fly", _fly()))],
    Case("cover --origin-alt nan", _cover("--origin-alt", "nan"), "--origin-alt: got nan"),
    # Unclear errors.
    *[Case(f"{cmd} --vmax ''", make("--vmax", ""), "--vmax: got '', expected a number")
      for cmd, make in (("fit", _fit), ("write", _write_cmd), ("cover", _cover))],
    Case("fit --vmax 1_0", _fit("--vmax", "1_0"), "--vmax: got '1_0'"),
    Case("fit --degree 1.5", _fit("--degree", "1.5"), "--degree: got '1.5', expected a whole"),
    Case("fit --bogus", _fit("--bogus"), "--bogus: got an option skyquill fit does not have"),
    Case("an extra argument (was 'got Got unexpected')", _fit("crazyswarm"),
         "skyquill fit: got unexpected extra argument(s) (crazyswarm), expected its usage"),
    Case("fit without --out", ["fit", SPIRAL], "--out: got nothing"),
    Case("no such command", ["paint-by-numbers"], "got the command 'paint-by-numbers'"),
    Case("fly --rate 1e-320 (was control_period: got inf)", _fly("--rate", "1e-320"),
         "--rate: got 9.99989e-321, expected 50 to 10000 hz", setup=WITH_TRAJ),
    Case("cover --rate 1e-320", _cover("--rate", "1e-320"), "--rate: got 9.99989e-321"),
    Case("cover --pattern zigzag-jerk on a field too small to turn (was pattern 'zigzag-jerk')",
         ["cover", "{tmp}/r.wkt", "--pattern", "zigzag-jerk", "--width", "1.38",
          "--min-coverage", "0", "--out", "{out}"], "--pattern: got 'zigzag-jerk' for a region",
         setup=_write("r.wkt", "POLYGON ((-2.47 -0.99, -0.67 1.22, 2.95 0.87, -2.47 -0.99))")),
    Case("cover --altitude 1e300 (was trajectory.csv line 2, column z)",
         _cover("--altitude", "1e300"), "--altitude: got 1e+300"),
    Case("write --grid 1000x1000 (was the board height)",
         _write_cmd("--board", "sky", "--drones", "2", "--grid", "1000x1000"),
         "--grid: got '1000x1000'"),
    Case("write --size 1e-6 names the option", _write_cmd("--size", "1e-6"), "--size: got"),
    Case("fit a knot interval too long names the options", _fit("--knot-interval", "5"),
         "--tolerance"),
    Case("--out with a name too long for the file system",
         ["fit", SPIRAL, "--out", f"{{tmp}}/{LONG_NAME}"],
         "got 'file name too long' from the operating system, expected a shorter name"),
    Case("a TOML byte-order mark is read like any other file's", SHOW,
         "expected an integer from 1 to 1000", setup=_write("s.toml", BOM_SHOW)),
    Case("paint --dots 0 after the progress bar started",
         ["paint", "--image", str(EXAMPLES / "painting" / "quill.png"), "--dots", "0", "--out",
          "{out}"], "--dots"),
    Case("show a TOML float with underscores", SHOW, "got the number 3_0.0",
         setup=_show(("hold = 3.0", "hold = 3_0.0"))),
    Case("cover WKT with a NaN", ["cover", "{tmp}/r.wkt", "--out", "{out}"], "got 'nan'",
         setup=_write("r.wkt", "POLYGON ((0 0, 10 0, 10 nan, 0 10, 0 0))")),
    Case("paint --wall-angles 1_0", _paint("--wall-angles", "1_0"), "--wall-angles"),
    Case("fly --wind 1_0,0,0", _fly("--wind", "1_0,0,0"), "--wind", setup=WITH_TRAJ),
    Case("export --tolerance 0", _export("--tolerance", "0"), "--tolerance", setup=WITH_TRAJ),
    Case("show --workers 100000", [*SHOW, "--workers", "100000"], "--workers", setup=_show()),
    # Every option at the entry against a stated range (a scan of every numeric option with
    # 1e300, -1e300 and nan found these running on, or refused under another name).
    Case("fit --weight 1e300 (did not end)", _fit("--weight", "1e300"), "--weight: got 1e+300"),
    Case("fit --tolerance 1e300", _fit("--tolerance", "1e300"), "--tolerance: got 1e+300"),
    Case("write --board-height 1e300 (was board: ...)", _write_cmd("--board-height", "1e300"),
         "--board-height: got 1e+300"),
    Case("write --separation 1e300", _write_cmd("--separation", "1e300"), "--separation"),
    Case("cover --delta 1e300 (did not end)", _cover("--delta", "1e300"), "--delta: got 1e+300"),
    Case("cover --time-limit 1e300", _cover("--time-limit", "1e300"), "--time-limit"),
    Case("paint --dots 999999999 with a CSV (was ignored)", _paint("--dots", "999999999"),
         "--dots: got 999999999"),
    Case("paint --width nan with a CSV (was ignored)", _paint("--width", "nan"),
         "--width: got nan"),
    Case("render --azimuth 1e300", [*RENDER, "--azimuth", "1e300"], "--azimuth", setup=WITH_TRAJ),
]  # fmt: skip
CASES.extend(ISSUE25)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_hostile_input(case: Case, tmp_path: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / SENTINEL).write_text("the user's own file")
    if case.setup is not None:
        case.setup(tmp_path)
    args = [a.replace("{tmp}", str(tmp_path)).replace("{out}", str(out)) for a in case.args]
    result = runner.invoke(app, args)
    text = result.output
    assert result.exit_code == case.status, text
    assert "Traceback" not in text
    assert case.message.lower() in " ".join(text.split()).lower(), text
    if case.status == 2:
        lines = [line for line in text.splitlines() if line.strip()]
        assert len(lines) == 1 and lines[0].startswith("error: "), text
    assert (out / SENTINEL).read_text() == "the user's own file"


#: Command lines that, unrefused, took all 24 GB of the machine.
MEMORY_HUNGRY = [
    (["write", "Hi", "--size", "1e6", "--out", "{out}"], "--size"),
    (["fly", "{tmp}/long.csv", "--out", "{out}"], "steps"),
    (["fit", SPIRAL, "--rate", "1e9", "--out", "{out}"], "rate"),
]


@pytest.mark.timeout(120)
@pytest.mark.parametrize(("args", "message"), MEMORY_HUNGRY, ids=["size", "long flight", "rate"])
def test_memory_hungry_input_is_refused_under_a_memory_limit(
    tmp_path: Path, args: list[str], message: str
) -> None:
    """Run in a child process limited to 3 GiB of address space: refused before allocating."""
    import resource
    import subprocess
    import sys

    _write("long.csv", LONG_TRAJ)(tmp_path)
    argv = [a.replace("{tmp}", str(tmp_path)).replace("{out}", str(tmp_path / "o")) for a in args]

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (3 * 2**30, 3 * 2**30))

    code = "from skyquill.cli.main import app; app(prog_name='skyquill')"
    done = subprocess.run(
        [sys.executable, "-c", code, *argv],
        preexec_fn=limit,
        capture_output=True,
        text=True,
        timeout=110,
        check=False,
    )
    assert done.returncode == 2, done.stderr
    assert message in done.stderr and "Traceback" not in done.stderr
