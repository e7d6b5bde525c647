"""Write docs/ceilings.md, the table of every ceiling, from the constants in the code.

Work is estimated before it starts and refused above these; each number on the page is
read from the module constant that enforces it, so the page cannot drift from the code
(``tests/docs/test_ceilings_page.py`` fails when it does). Run after changing a ceiling:

    .venv/bin/python tools/ceilings.py            # rewrite docs/ceilings.md
    .venv/bin/python tools/ceilings.py --check    # exit 1 if the page is stale
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "ceilings.md"
#: The memory and time every input within the ceilings runs in, as measured by
#: bench/ceilings.py (worst input at each ceiling, one process each).
MEMORY_BOUND_GIB = 2.0
TIME_BOUND_S = 600.0


def _mib(n: int) -> str:
    return f"{n / 2**20:g} MiB" if n >= 2**20 else f"{n / 1e3:g} kB"


def _n(x: float) -> str:
    return f"{x:,.0f}" if float(x).is_integer() else f"{x:g}"


def rows() -> list[tuple[str, str, str]]:
    """``(what, ceiling, where it is enforced)`` for every ceiling, read from the code."""
    from skyquill.calligraphy import board, brush, mission
    from skyquill.calligraphy import show as calligraphy_show
    from skyquill.cli import (
        check_cmd,
        cover_cmd,
        export_cmd,
        fit_cmd,
        fly_cmd,
        main,
        paint_cmd,
        write_cmd,
    )
    from skyquill.coverage import cells, regions
    from skyquill.coverage import plan as coverage_plan
    from skyquill.export.skybrush import csv_file as skybrush_csv
    from skyquill.export.skybrush import skyc_file
    from skyquill.io import json_read, numbers, setpoints_json, table
    from skyquill.optimize import fit
    from skyquill.painting import dots
    from skyquill.show import script, separation
    from skyquill.sim import bounds
    from skyquill.strokes import json_io, model, svg
    from skyquill.studio import app as studio_app
    from skyquill.studio import models as studio_models
    from skyquill.trajectory import base

    limits = _limit_ceilings()
    lo, hi = main.SAMPLE_RATE_HZ
    size_lo, size_hi = mission.SIZE_RANGE_M
    alt_lo, alt_hi = cover_cmd.ALTITUDE_RANGE_M
    origin_lo, origin_hi = cover_cmd.ORIGIN_ALT_RANGE_M
    tol_lo, tol_hi = export_cmd.TOLERANCE_RANGE_M
    entries: list[tuple[str, Callable[[], str], str]] = [
        ("limits (every command)", lambda: limits, "limits._CEILINGS"),
        ("sample rate of written files (`--rate`)", lambda: f"{_n(lo)} to {_n(hi)} Hz",
         "cli.main.SAMPLE_RATE_HZ"),
        ("samples written (`--rate` x duration)", lambda: f"{_n(table.MAX_ROWS)} rows in a "
         f"`trajectory.csv` (what its readers take; `paint` refuses while it simulates, once the "
         f"flight is sure to be longer); {_n(base.MAX_SAMPLES)} samples in any one evaluation",
         "io.points.check_rows_written, painting.flight.FlightClock, trajectory.base.MAX_SAMPLES"),
        ("`fly` simulation", lambda: f"{_n(bounds.MAX_SIM_STEPS)} steps; rate "
         f"{_n(bounds.MIN_RATE_HZ)} to {_n(bounds.MAX_RATE_HZ)} Hz; wind and gusts "
         f"<= {_n(fly_cmd.MAX_WIND_MPS)} m/s", "sim.bounds, cli.fly_cmd.MAX_WIND_MPS"),
        ("`fit`", lambda: f"{_n(fit.MAX_POINTS)} points, {_n(fit.MAX_SPANS)} knot spans; "
         f"`--weight` {_n(fit_cmd.WEIGHT_RANGE[0])} to {fit_cmd.WEIGHT_RANGE[1]:.0e}, "
         f"`--tolerance` <= {_n(fit_cmd.TOLERANCE_RANGE_M[1])} m",
         "optimize.fit.MAX_POINTS, MAX_SPANS, cli.fit_cmd"),
        ("`write` input", lambda: f"{_n(model.MAX_STROKES)} strokes, {_n(model.MAX_POINTS)} "
         f"points (after flattening curves); {_n(mission.MAX_INPUT_POINTS)} points per drone "
         "before densifying", "strokes.model, calligraphy.mission.MAX_INPUT_POINTS"),
        ("`write` plan", lambda: f"size {_n(size_lo)} to {_n(size_hi)} m, lift <= "
         f"{_n(board.MAX_LIFT_M)} m, brush <= {_n(brush.MAX_BRUSH_LENGTH_M)} m, a route of "
         f"{_n(mission.MAX_ROUTE_SAMPLES)} samples, {_n(mission.MAX_SPANS)} knot spans per "
         f"solve, altitude (and `--board-height`) <= {_n(mission.MAX_ALTITUDE_M)} m, "
         f"`--separation` <= {_n(write_cmd.SEPARATION_RANGE_M[1])} m",
         "calligraphy.mission, board.MAX_LIFT_M, brush.MAX_BRUSH_LENGTH_M"),
        ("`write` drones", lambda: f"{_n(calligraphy_show.MAX_DRONES)} drones (`--grid` at "
         f"most as many boards), {_n(calligraphy_show.MAX_SHOW_STROKES)} strokes in all",
         "calligraphy.show.MAX_DRONES, MAX_SHOW_STROKES"),
        ("`cover`", lambda: f"a region <= {_n(coverage_plan.MAX_REGION_SIZE_M)} m across, "
         f"{_n(regions.MAX_VERTICES)} vertices, a path <= "
         f"{_n(regions.MAX_PATH_LENGTH_M / 1e3)} km planned as one, <= "
         f"{_n(regions.MAX_MISSION_PATH_M / 1e3)} km as pieces within it (lines >= "
         f"{_n(cells.MIN_CELL_SPACING_M)} m apart; estimated as area / swath + perimeter "
         f"before any path is built); `--altitude` {_n(alt_lo)} (excluded) to {_n(alt_hi)} m; "
         f"`--origin-alt` {_n(origin_lo)} to {_n(origin_hi)} m; `--delta` <= "
         f"{_n(cover_cmd.DELTA_RANGE_M[1])} m; `--time-limit` <= "
         f"{_n(cover_cmd.TIME_LIMIT_RANGE_S[1])} s; `--workers` <= {_n(main.MAX_WORKERS)}",
         "coverage.plan.MAX_REGION_SIZE_M, coverage.regions, coverage.cells, cli.cover_cmd, "
         "cli.main.MAX_WORKERS"),
        ("`paint`", lambda: f"{_n(dots.MAX_DOTS)} dots (`--dots` too); `--width` <= "
         f"{_n(paint_cmd.MAX_WIDTH_M)} m; pictures <= "
         f"{_n(dots.MAX_IMAGE_PIXELS / 1e6)} Mpx (from the header, before decoding) and "
         f"{_mib(dots.MAX_IMAGE_BYTES)}", "painting.dots"),
        ("`show` scripts", lambda: f"{_n(script.MAX_DRONES)} drones, {_n(script.MAX_SCENES)} "
         f"scenes, holding <= {_n(script.MAX_HOLDING_S)} s, extent <= "
         f"{_n(script.MAX_EXTENT_M)} m, altitude <= {_n(script.MAX_ALTITUDE_M)} m, rate <= "
         f"{_n(script.MAX_RATE_HZ)} Hz, `--workers` <= {_n(main.MAX_WORKERS)}",
         "show.script, cli.main.MAX_WORKERS"),
        ("`check`", lambda: f"{_n(check_cmd.MAX_DRONES)} drones; "
         f"{_n(separation.MAX_INTERVALS)} intervals of close approach",
         "cli.check_cmd.MAX_DRONES, show.separation.MAX_INTERVALS"),
        ("`export`", lambda: f"read back within `--tolerance` (default "
         f"{_n(export_cmd.DEFAULT_TOLERANCE_M * 1e3)} mm; {_n(tol_lo)} to {_n(tol_hi)} m)",
         "cli.export_cmd"),
        ("CSV files", lambda: f"{_mib(table.MAX_BYTES)}, {_n(table.MAX_ROWS)} rows, lines of "
         f"{_n(table.MAX_LINE_CHARS)} characters", "io.table"),
        ("JSON files", lambda: f"strokes {_mib(json_io.MAX_BYTES)}, regions "
         f"{_mib(regions.MAX_BYTES)}, setpoints {_mib(setpoints_json.MAX_BYTES)}, others "
         f"{_mib(json_read.MAX_BYTES)}; nesting <= {json_read.MAX_DEPTH}", "io.json_read"),
        ("SVG files", lambda: f"{_mib(svg.MAX_BYTES)}", "strokes.svg.MAX_BYTES"),
        ("show scripts (TOML)", lambda: f"{_mib(script.MAX_BYTES)}", "show.script.MAX_BYTES"),
        (".skyc and zipped CSV shows", lambda: f".skyc {_mib(skyc_file.MAX_SKYC_BYTES)}, its "
         f"show.json {_mib(skyc_file.MAX_SHOW_BYTES)} (from the ZIP directory, before "
         f"inflating); CSV zip {_mib(skybrush_csv.MAX_TOTAL_BYTES)}, "
         f"{_n(skybrush_csv.MAX_DRONES)} drones", "export.skybrush"),
        ("numbers in text", lambda: f"plain ASCII decimal literals of at most "
         f"{numbers.MAX_CHARS} characters", "io.numbers"),
        ("studio", lambda: f"bodies <= {_mib(studio_app.MAX_BODY_BYTES)}, "
         f"{_n(studio_models.MAX_STROKES)} strokes, {_n(studio_models.MAX_POINTS)} points, "
         f"{_n(studio_models.MAX_DRONES)} drones", "studio.app, studio.models"),
    ]  # fmt: skip
    return [(what, value(), where) for what, value, where in entries]


def _limit_ceilings() -> str:
    from skyquill.limits import _CEILINGS

    return (
        f"speed {_n(_CEILINGS[1])} m/s, acceleration {_CEILINGS[2]:.0e} m/s², jerk "
        f"{_CEILINGS[3]:.0e} m/s³ (more is a unit mistake)"
    ).replace("e+0", "e")


def render() -> str:
    """The whole page."""
    lines = [
        "# Ceilings",
        "",
        "<!-- Generated by tools/ceilings.py from the constants in the code; do not edit. -->",
        "",
        "Work is estimated before it starts and refused above these ceilings, with one line "
        "naming the option or file and what would fit (exit status 2). Every input within "
        f"them runs in at most **{MEMORY_BOUND_GIB:g} GiB** of memory and "
        f"**{TIME_BOUND_S / 60:g} minutes** of CPU: `bench/ceilings.py` runs the worst "
        "input at each ceiling in its own process and records its peak memory and wall time "
        "in `bench/results/ceilings.json`.",
        "",
        "| what | ceiling | enforced by (`skyquill.`...) |",
        "|---|---|---|",
    ]
    lines += [f"| {what} | {value} | `{where}` |" for what, value, where in rows()]
    lines += ["", *_RULES]
    return "\n".join(lines) + "\n"


#: How every input is read and every output written: the rules behind the refusals.
_RULES = [
    "## How input is read",
    "",
    "- **Regular files only.** Every reader opens its file without blocking and checks the "
    "open descriptor: a named pipe, a device (`/dev/zero`), a socket or a folder is refused at "
    "once (`skyquill.io.source`). Sizes are checked before a byte is read.",
    "- **One byte-order-mark rule.** Text is UTF-8, with or without the mark spreadsheets and "
    "Windows editors write (CSV, JSON, SVG, WKT, TOML alike); UTF-16, a NUL byte or bytes that "
    "are not UTF-8 are refused, naming the offset.",
    "- **One number grammar.** A number in a CSV cell, an SVG attribute, a WKT polygon, a TOML "
    "float or an option is a plain ASCII decimal literal (`1.5`, `-2`, `3e-4`): `1_0`, "
    "Arabic-Indic `٠.١`, full-width `０.５` and `0x10`, which Python's `float()` takes, are "
    "refused (`skyquill.io.numbers`). JSON keeps its own grammar; `NaN`, `Infinity`, numbers "
    "beyond the float range and a key repeated in one object are refused.",
    "- **SVG errors are errors.** A `transform` that is not a list of the six SVG functions, "
    "path data short of a coordinate, an odd number of polyline coordinates, a length that is "
    "not a number and a negative size or radius are refused, naming the element (tag and `id`, "
    "or its place) and the attribute, where svgelements would drop or repair them.",
    "- **GeoJSON as RFC 7946 writes it.** A ring is closed, with four or more positions; a "
    "position is `[x, y]` of JSON numbers.",
    "",
    "## How output is written",
    "",
    "- Files are staged inside `--out` and moved in by atomic renames under a lock of the "
    "folder, with the mode the user's umask gives; an interrupted run leaves every file whole.",
    "- `--out/.skyquill-files.json` is a record, never an authority: a file is replaced or "
    "removed only if it is a plain name inside `--out` whose regular file still has the inode "
    "and SHA-256 recorded when skyquill wrote it. Nothing outside `--out` is ever touched.",
    "- A result that is not faithful exits non-zero: a fit or plan beyond its tolerance, an "
    "export whose read-back misses `--tolerance`, a reproduction without a feasible solve.",
]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="fail if the page is stale")
    args = parser.parse_args(argv)
    text = render()
    if args.check:
        stale = not PAGE.is_file() or PAGE.read_text(encoding="utf-8") != text
        if stale:
            print(f"{PAGE} is stale: run python tools/ceilings.py", file=sys.stderr)
        return int(stale)
    PAGE.write_text(text, encoding="utf-8")
    print(f"wrote {PAGE}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
