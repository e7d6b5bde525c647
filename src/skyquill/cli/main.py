"""``skyquill`` command line: the app, its error handling, and the commands' registry.

Commands live one module each -- ``fit`` and ``demo`` (:mod:`.fit_cmd`),
``fly`` (:mod:`.fly_cmd`), ``reproduce`` (:mod:`.reproduce_cmd`). Every command
writes into ``--out DIR`` and leaves a ``summary.json`` there. Errors that are
the user's (bad input, infeasible limits) are printed as one red line and exit
with status 2; no traceback.
"""

from __future__ import annotations

import logging
import re
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.text import Text

from skyquill.cli.boundary import (
    OneLineGroup,
    as_options,
    console,
    fail,
    os_error_line,
    progress_bar,
    quiet_warnings,
)
from skyquill.colors import hex_rgb
from skyquill.errors import InputError, SkyquillError
from skyquill.io.numbers import parse_number
from skyquill.io.outputs import check_folder
from skyquill.targets import TARGETS, UploadTarget
from skyquill.validation import FloatArray

app = typer.Typer(
    cls=OneLineGroup,
    add_completion=False,
    no_args_is_help=True,
    help="Plan smooth, limit-respecting quadrotor trajectories for aerial drawing.",
)
EXAMPLES = Path(__file__).resolve().parents[3] / "examples"

OutDir = Annotated[Path, typer.Option("--out", help="Output directory (created).")]

# One meaning per limit in every command (docs/architecture.md): the norms, and
# per-axis boxes only under their own names.
Vmax = Annotated[float, typer.Option(help="Speed limit: the norm of the velocity, m/s.")]
Amax = Annotated[
    float, typer.Option(help="Acceleration limit: the norm of the acceleration, m/s^2.")
]
Jmax = Annotated[float, typer.Option(help="Jerk limit: the norm of the jerk, m/s^3.")]
VmaxAxis = Annotated[
    float | None, typer.Option(help="Optional per-axis bound on |vx|, |vy|, |vz|, m/s.")
]
AmaxAxis = Annotated[
    float | None, typer.Option(help="Optional per-axis bound on |ax|, |ay|, |az|, m/s^2.")
]
JmaxAxis = Annotated[
    float | None, typer.Option(help="Optional per-axis bound on |jx|, |jy|, |jz|, m/s^3.")
]
Force = Annotated[
    bool,
    typer.Option(help="Replace files in --out that skyquill did not write there itself."),
]
NormSides = Annotated[
    int | None,
    typer.Option(
        help="Hold the norms by an inscribed polytope of this many sides (a QP) instead of "
        "exactly (second-order cones)."
    ),
]
MinAltitude = Annotated[
    float,
    typer.Option(
        "--min-altitude",
        help="Lowest altitude of the mission above the ground, m (0 to 100): between take-off "
        "and landing nothing is planned below it (summary.json: phases).",
    ),
]
Altitude = Annotated[
    float | None,
    typer.Option(
        help="Altitude a 2-D input (x, y) is flown at, m (from --min-altitude to 120; default "
        "1, or --min-altitude if higher); refused with 3-D input, which has its own z."
    ),
]
Target = Annotated[
    str | None,
    typer.Option(
        help="Plan for a vehicle's trajectory memory: 'crazyflie' (at most 31 polynomial "
        "pieces per upload, uploads changed while hovering)."
    ),
]


def min_altitude(value: float) -> float:
    """``--min-altitude``, m, checked (:func:`skyquill.phases.check_min_altitude`)."""
    from skyquill.phases import check_min_altitude

    return check_min_altitude("--min-altitude", value)


def upload_target(name: str | None) -> UploadTarget | None:
    """The :class:`UploadTarget` called ``name`` (``--target``); ``None`` for none."""
    if name is None:
        return None
    if name not in TARGETS:
        raise InputError(f"--target: got {name!r}, expected one of {', '.join(TARGETS)}")
    return TARGETS[name]


def installed_version() -> str:
    """skyquill's version as installed (the package metadata, i.e. ``pyproject.toml``)."""
    from importlib.metadata import version

    return version("skyquill")


def _print_version(asked: bool) -> None:
    if asked:
        typer.echo(f"skyquill {installed_version()}")
        raise typer.Exit()


@app.callback()
def main(
    verbose: Annotated[
        bool, typer.Option("--verbose", "-v", help="Log what the planners do (INFO level).")
    ] = False,
    version: Annotated[
        bool,
        typer.Option(
            "--version",
            help="Print the installed version and exit.",
            callback=_print_version,
            is_eager=True,
        ),
    ] = False,
) -> None:
    """skyquill: aerial drawing and painting with quadrotors."""
    # Without --verbose a warning is one plain line: no level or module names.
    logging.basicConfig(
        level=logging.INFO if verbose else logging.WARNING,
        format=logging.BASIC_FORMAT if verbose else "%(message)s",
    )
    quiet_warnings(verbose)


@contextmanager
def user_errors() -> Iterator[None]:
    """The one error boundary of a command: expected failures are one plain line, exit 2.

    skyquill's own errors (bad input, infeasible, solver), the operating
    system's (a folder that cannot be written, a missing file), undecodable
    text, memory and nesting limits are the user's to fix: one line, printed
    literally (never as rich markup: paths and messages may hold ``[...]``),
    exit status 2. Anything else is a bug: one line saying so, exit status 1.
    """
    try:
        yield
    except typer.Exit:
        raise
    except SkyquillError as exc:
        fail(as_options(str(exc)))
    except OSError as exc:
        fail(os_error_line(exc))
    except UnicodeError as exc:
        fail(f"got text that is not UTF-8 ({exc}), expected UTF-8 text")
    except MemoryError:
        fail("ran out of memory; expected a smaller job (a lower --rate, a smaller input)")
    except RecursionError:
        fail("got input nested too deeply to read, expected a flatter file")
    except Exception as exc:
        if _raised_from_ctrl_c(exc):
            # Ctrl+C inside a compiled module's start (matplotlib's, imported to draw a
            # picture here) fails its import: "ImportError: initialization failed", raised
            # from the KeyboardInterrupt. The person pressed Ctrl+C: say that.
            raise KeyboardInterrupt from None
        fail(
            f"internal error ({type(exc).__name__}: {exc}); this is a bug in skyquill, please "
            "report it with the command line that caused it",
            status=1,
        )


def _raised_from_ctrl_c(exc: BaseException) -> bool:
    """Whether ``exc`` was raised from, or while handling, a ``KeyboardInterrupt``."""
    seen: set[int] = set()
    cause = exc.__cause__ or exc.__context__
    while cause is not None and id(cause) not in seen:
        if isinstance(cause, KeyboardInterrupt):
            return True
        seen.add(id(cause))
        cause = cause.__cause__ or cause.__context__
    return False


@contextmanager
def stage_progress() -> Iterator[Callable[[int, int, str], None]]:
    """A rich bar fed by a planner's ``progress(done, total, stage)`` callback.

    The planners of several drones (``write``, ``show``) report each step as it is done;
    the bar shows the stage, how many of how many, and the time so far.
    """
    from rich.progress import BarColumn, MofNCompleteColumn, TextColumn, TimeElapsedColumn

    with progress_bar(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
    ) as bar:
        task = bar.add_task("planning", total=None)

        def report(done: int, total: int, stage: str) -> None:
            bar.update(task, completed=done, total=total, description=stage)

        yield report


def say_done(message: str) -> None:
    """``done message`` on stderr, the message printed literally (it holds user paths)."""
    console.print(Text("done ", style="green") + Text(message), soft_wrap=True)


def check_out(out: Path) -> None:
    """Refuse an ``--out`` that cannot be a folder before any work starts (it is made later)."""
    check_folder(out, "--out")


#: Sample rates of the files commands write (trajectory.csv, setpoints, exports), Hz: below
#: 1 Hz a sample every second or more no longer follows a drawing's strokes; above 10 kHz
#: only the file grows (the samples-written ceiling bounds it too).
SAMPLE_RATE_HZ = (1.0, 10_000.0)


def positive_rate(
    rate: float,
    option: str = "--rate",
    low: float = SAMPLE_RATE_HZ[0],
    high: float = SAMPLE_RATE_HZ[1],
) -> float:
    """``--rate`` (Hz), checked against ``[low, high]`` (NaN fails too)."""
    if not low <= rate <= high:
        raise InputError(f"{option}: got {rate:g}, expected {low:g} to {high:g} Hz")
    return rate


def in_range(
    option: str, value: float, low: float, high: float, unit: str, *, open_low: bool = False
) -> float:
    """``value`` of ``option`` within ``[low, high]`` (``(low, high]`` with ``open_low``).

    NaN fails too. Every option a command takes is checked so at the entry, against
    the range docs/ceilings.md states, before any work starts.
    """
    if not (low < value <= high if open_low else low <= value <= high):
        bracket = "more than" if open_low else "from"
        raise InputError(f"{option}: got {value:g}, expected {bracket} {low:g} to {high:g} {unit}")
    return value


def parse_vector3(option: str, text: str, unit: str) -> FloatArray:
    """Parse ``"x,y,z"`` into a (3,) float array; InputError naming ``option`` otherwise."""
    try:
        values = [parse_number(p) for p in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 3:
        raise InputError(
            f"{option}: got {text!r}, expected three comma-separated finite numbers in {unit}, "
            "e.g. 2,0,0"
        )
    return np.array(values)


#: Most ``--workers`` (processes): more than any machine's cores is a typo.
MAX_WORKERS = 256


def worker_count(workers: int | None) -> int | None:
    """``--workers``: 1 to :data:`MAX_WORKERS` processes, or None (one per CPU)."""
    if workers is not None and not 1 <= workers <= MAX_WORKERS:
        raise InputError(f"--workers: got {workers}, expected 1 to {MAX_WORKERS}")
    return workers


#: A dask.distributed scheduler address: ``local``, ``tcp://host:port`` (or tls, ws, wss,
#: ucx, inproc) or ``host:port``.
_SCHEDULER = re.compile(
    r"local|(?:(?:tcp|tls|ws|wss|ucx|inproc)://)?[A-Za-z0-9._\-\[\]:]+(?::[0-9]{1,5})?", re.ASCII
)


def scheduler_address(text: str | None) -> str | None:
    """``--scheduler``, checked to look like an address before dask is asked to reach it."""
    if text is None:
        return None
    if not _SCHEDULER.fullmatch(text) or (
        "://" not in text and text != "local" and ":" not in text
    ):
        raise InputError(
            f"--scheduler: got {text!r}, expected 'local' or a dask scheduler address such as "
            "tcp://10.0.0.5:8786"
        )
    return text


_BYTE = re.compile(r"\s*[0-9]{1,3}\s*", re.ASCII)


def parse_color(flag: str, text: str) -> tuple[int, int, int]:
    """A light colour given as ``R,G,B`` (integers 0..255) or ``#RRGGBB``; errors name ``flag``."""
    parts = text.split(",")
    if len(parts) == 3 and all(_BYTE.fullmatch(p) and int(p) <= 255 for p in parts):
        return (int(parts[0]), int(parts[1]), int(parts[2]))
    rgb = hex_rgb(text[1:]) if text.startswith("#") else None
    if rgb is not None:
        return rgb
    raise InputError(
        f"{flag}: got {text!r}, expected R,G,B with three integers in 0..255 or #RRGGBB"
    )


# Register the commands (each module adds its own to ``app``).
from skyquill.cli import (  # noqa: E402
    check_cmd,
    cover_cmd,
    export_cmd,
    fit_cmd,
    fly_cmd,
    hanzi_cmd,
    paint_cmd,
    render_cmd,
    reproduce_cmd,
    show_cmd,
    studio_cmd,
    write_cmd,
)

__all__ = [
    "app",
    "check_cmd",
    "console",
    "cover_cmd",
    "export_cmd",
    "fail",
    "fit_cmd",
    "fly_cmd",
    "hanzi_cmd",
    "paint_cmd",
    "progress_bar",
    "render_cmd",
    "reproduce_cmd",
    "show_cmd",
    "studio_cmd",
    "write_cmd",
]

if __name__ == "__main__":  # pragma: no cover
    app()
