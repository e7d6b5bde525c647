"""The command line's outer edge: what reaches stderr, and with which exit status.

Whatever goes wrong, a person sees one line, ``error: <option or file>: got <what
came>, expected <what was expected>``, and nothing else on stderr:

* Click's own refusals (an option that does not exist, a value that is not a
  number, a missing argument) are that one line (:class:`OneLineGroup`), not a
  usage box; numbers on the command line follow the one grammar of
  :mod:`skyquill.io.numbers` (``--vmax 1_0`` is refused, ``--trail inf`` is
  left to the option's own range check), and an empty path (``--out ''``) is
  refused rather than read as the current folder;
* Ctrl+C at any moment ends with one line and exit status 130 (the console
  script, :mod:`skyquill.cli.entry`, covers the imports before the app exists);
* Python warnings (numpy, scipy, shapely) are logged, shown with ``--verbose``
  only; errors raised in finalizers (a dask client closing after a refused
  address) are logged too, never printed as a traceback;
* progress bars are drawn only on a terminal, and leave nothing behind;
* operating-system errors name the file the user knows (never the staging
  folder) in the same "got ... expected ..." form (:func:`os_error_line`).
"""

from __future__ import annotations

import errno
import logging
import re
import sys
import types
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NoReturn, Union

import typer
from rich.console import Console
from rich.progress import Progress, ProgressColumn
from rich.text import Text
from typer.core import TyperGroup

try:  # typer 0.2x carries its own copy of Click
    from typer._click import exceptions as click_errors
except ImportError:  # pragma: no cover - older typer on the click package
    from click import exceptions as click_errors  # type: ignore[no-redef]

from skyquill.io.numbers import EXPECTED, is_literal
from skyquill.io.outputs import shown_path

#: The one console every command prints its progress and messages to (stderr).
console = Console(stderr=True)
#: Exit status of an interrupted command (128 + SIGINT), as shells report it.
INTERRUPTED = 130
INTERRUPTED_LINE = (
    "interrupted by Ctrl+C; every file already in the output folder is whole (the one that "
    "was there, or the new one)"
)
_INTEGER = re.compile(r"[-+]?[0-9]+", re.ASCII)
logger = logging.getLogger("skyquill.cli")


def error_line(message: str) -> None:
    """Print ``error: message`` as one literal line on stderr (never rich markup)."""
    console.print(Text("error: ", style="bold red") + Text(message), soft_wrap=True)


def fail(message: str, status: int = 2) -> NoReturn:
    """:func:`error_line`, then exit with ``status``."""
    error_line(message)
    raise typer.Exit(status)


def progress_bar(*columns: str | ProgressColumn) -> Progress:
    """A rich progress bar on the console: drawn on a terminal only, and gone when done."""
    return Progress(*columns, console=console, transient=True, disable=not console.is_terminal)


def quiet_warnings(verbose: bool) -> None:
    """Send Python warnings and finalizer errors to logging: shown with ``--verbose`` only."""
    logging.captureWarnings(True)
    logging.getLogger("py.warnings").setLevel(logging.INFO if verbose else logging.ERROR)
    sys.unraisablehook = _log_unraisable


def _log_unraisable(unraisable: Any) -> None:
    logger.debug(
        "ignored in %r: %s", unraisable.object, unraisable.exc_value, exc_info=unraisable.exc_value
    )


def os_error_line(exc: OSError) -> str:
    """An operating-system error as "<path>: got <reason> from the system, expected <what>"."""
    where = shown_path(exc.filename) if exc.filename else "a file or folder"
    reason = exc.strerror or str(exc) or type(exc).__name__
    return (
        f"{where}: got {reason!r} from the operating system, expected "
        f"{_OS_EXPECTED.get(exc.errno or 0, 'a file or folder skyquill can use')}"
    )


_OS_EXPECTED = {
    errno.ENOSPC: "free space on its disk",
    errno.EDQUOT: "free space within the disk quota",
    errno.EACCES: "permission to read (and, for an output, to write) it",
    errno.EPERM: "permission to read (and, for an output, to write) it",
    errno.EROFS: "a file system that can be written to",
    errno.ENAMETOOLONG: "a shorter name",
    errno.ENOENT: "an existing file or folder",
    errno.EISDIR: "a file, not a folder",
    errno.ENOTDIR: "a folder",
    errno.EMFILE: "fewer files open at once",
    errno.ENFILE: "fewer files open at once",
    errno.EIO: "a disk that can be read",
}


#: The Python argument names the core's messages use, and the option a person typed.
#: (The core never imports the CLI, so its messages name arguments; the CLI says options.)
OPTION_OF = {
    "vmax": "--vmax",
    "amax": "--amax",
    "jmax": "--jmax",
    "vmax_axis": "--vmax-axis",
    "amax_axis": "--amax-axis",
    "jmax_axis": "--jmax-axis",
    "norm_sides": "--norm-sides",
    "degree": "--degree",
    "weight": "--weight",
    "knot_interval": "--knot-interval",
    "tolerance_m": "--tolerance",
    "best_effort": "--best-effort",
    "rate": "--rate",
    "rate_hz": "--rate",
    "control_period": "--rate",
    "size_m": "--size",
    "lift_m": "--lift",
    "separation_m": "--separation",
    "board_height_m": "--board-height",
    "tilt_deg": "--board-tilt",
    "plane_weight": "--plane-weight",
    "drones": "--drones",
    "grid": "--grid",
    "brush length_m": "--brush-length",
    "brush press_depth_m": "--press-depth",
    "scheduler": "--scheduler",
    "width": "--width",
    "pattern": "--pattern",
    "width_m": "--width",
    "epsilon": "--epsilon",
    "delta": "--delta",
    "altitude": "--altitude",
    "time_limit": "--time-limit",
    "min_coverage": "--min-coverage",
    "alt_m": "--origin-alt",
    "crs": "--crs",
    "n_dots": "--dots",
    "gamma_rad": "--gamma",
    "azimuth_deg": "--azimuth",
    "elevation_deg": "--elevation",
    "fov_deg": "--fov",
    "trail_s": "--trail",
    "wind_mps": "--wind",
    "noise_m": "--noise",
    "min_distance_m": "--min-distance",
}
_LEADING_NAME = re.compile(r"((?:brush )?[A-Za-z_][A-Za-z0-9_]*)(?=: )")
_INNER_NAMES = re.compile(
    r"(?<![\w.-])("
    + "|".join(sorted((n for n in OPTION_OF if "_" in n), key=len, reverse=True))
    + r")(?![\w.])"
)


def as_options(message: str) -> str:
    """A core message with its argument names replaced by the options a person typed.

    The leading ``name:`` is replaced when ``name`` is an option's argument; inside
    the message only names with an underscore (``tolerance_m``, ``best_effort``),
    which no sentence holds by chance.
    """
    lead = _LEADING_NAME.match(message)
    if lead is not None and lead.group(1) in OPTION_OF:
        message = OPTION_OF[lead.group(1)] + message[lead.end() :]
    return _INNER_NAMES.sub(lambda m: OPTION_OF[m.group(1)], message)


class OptionError(typer.BadParameter):
    """A value refused before Click converts it; its message is the whole line."""

    def format_message(self) -> str:
        return self.message


class OneLineGroup(TyperGroup):
    """A typer group whose every refusal is one ``error:`` line (see the module docstring)."""

    def main(  # type: ignore[override]
        self,
        args: Sequence[str] | None = None,
        prog_name: str | None = None,
        complete_var: str | None = None,
        standalone_mode: bool = True,
        **extra: Any,
    ) -> Any:
        try:
            code = super().main(args, prog_name, complete_var, standalone_mode=False, **extra)
        except typer.Abort:
            error_line(INTERRUPTED_LINE)
            code = INTERRUPTED
        except KeyboardInterrupt:
            error_line(INTERRUPTED_LINE)
            code = INTERRUPTED
        except click_errors.ClickException as exc:
            if type(exc).__name__ != "NoArgsIsHelpError":  # the help was printed
                error_line(click_line(exc))
            code = exc.exit_code
        code = code if isinstance(code, int) else 0
        if standalone_mode:
            sys.exit(code)
        return code

    def make_context(self, *args: Any, **extra: Any) -> Any:
        # Typer turns Ctrl+C while it reads the top-level options (it imports pydantic
        # then) into a silent exit status 130: say the line here, as invoke does.
        try:
            return super().make_context(*args, **extra)
        except KeyboardInterrupt:
            error_line(INTERRUPTED_LINE)
            raise typer.Exit(INTERRUPTED) from None

    def invoke(self, ctx: Any) -> Any:
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt:
            error_line(INTERRUPTED_LINE)
            raise typer.Exit(INTERRUPTED) from None

    def resolve_command(self, ctx: Any, args: list[str]) -> Any:
        name, command, rest = super().resolve_command(ctx, args)
        if command is not None and not isinstance(command, TyperGroup):
            check_option_values(command, rest)
        return name, command, rest


def click_line(exc: Any) -> str:
    """One "what: got ..., expected ..." line for a Click usage error."""
    exceptions = click_errors
    ctx = getattr(exc, "ctx", None)
    # The program is skyquill however it was started (python -c, a test runner).
    command = " ".join(["skyquill", *ctx.command_path.split(" ")[1:]]) if ctx else "skyquill"
    see = f"see '{command} --help'"
    if isinstance(exc, OptionError):
        return str(exc.message)
    if isinstance(exc, exceptions.NoSuchOption):
        also = f"; did you mean {', '.join(exc.possibilities)}?" if exc.possibilities else ""
        return (
            f"{exc.option_name}: got an option {command} does not have, expected one of its "
            f"options ({see}){also}"
        )
    if isinstance(exc, exceptions.MissingParameter):
        return f"{_hint(exc)}: got nothing, expected a value ({see})"
    if isinstance(exc, exceptions.BadParameter):
        value = _input_of(exc)
        got = "a value" if value is None else repr(value)
        return f"{_hint(exc)}: got {got}, expected {_kind(exc.param)}"
    if isinstance(exc, exceptions.BadOptionUsage):
        return f"{exc.option_name}: got {exc.message.rstrip('.')}, expected its usage ({see})"
    message = exc.format_message().rstrip(".")
    if message.startswith("No such command") and ctx is not None:
        names = ", ".join(ctx.command.list_commands(ctx))
        wrong = message.removeprefix("No such command").strip(" .")
        return f"{command}: got the command {wrong}, expected one of {names}"
    # Click's own sentences may start with the word this line starts with ("Got unexpected
    # extra argument (x)"): said once.
    return f"{command}: got {message.removeprefix('Got ')}, expected its usage ({see})"


def _hint(exc: Any) -> str:
    param = getattr(exc, "param", None)
    if param is None:
        return str(exc.param_hint or "argument")
    if param.param_type_name == "option":
        return str(param.opts[0])
    return str(param.human_readable_name)


def _input_of(exc: Any) -> Any:
    """The text typer's validation refused (pydantic keeps it in the cause)."""
    cause = exc.__cause__
    errors = getattr(cause, "errors", None)
    if callable(errors):
        found = errors()
        if found and "input" in found[0]:
            return found[0]["input"]
    return None


def _kind(param: Any) -> str:
    annotation = _base(getattr(getattr(param, "type_descriptor", None), "annotation", None))
    if annotation is float:
        return EXPECTED
    if annotation is int:
        return "a whole number such as 3"
    if annotation is bool:
        return "true or false"
    return "a value of the right kind"


def _base(annotation: Any) -> Any:
    """``float`` of ``float | None``; the annotation itself otherwise."""
    if isinstance(annotation, types.UnionType) or getattr(annotation, "__origin__", None) is Union:
        kinds = [a for a in annotation.__args__ if a is not type(None)]
        return kinds[0] if len(kinds) == 1 else annotation
    return annotation


def check_option_values(command: Any, tokens: Sequence[str]) -> None:
    """Refuse option values Click would read too kindly: numbers and empty paths.

    Numbers follow :mod:`skyquill.io.numbers` (``inf`` and ``nan`` are let
    through to the option's own range check, which names them); ``""`` for a
    path is refused (``Path("")`` is the current folder).
    """
    options = {
        opt: param
        for param in command.params
        if param.param_type_name == "option" and not getattr(param, "is_flag", False)
        for opt in param.opts
    }
    i = 0
    while i < len(tokens):
        token = tokens[i]
        if token == "--":
            return
        name, sep, value = token.partition("=")
        param = options.get(name)
        if param is not None and not sep:
            if i + 1 >= len(tokens):
                return  # Click says the value is missing
            value = tokens[i + 1]
            i += 1
        if param is not None:
            _check_value(name, param, value)
        i += 1


def _check_value(option: str, param: Any, value: str) -> None:
    annotation = _base(getattr(param.type_descriptor, "annotation", None))
    if annotation is list or getattr(annotation, "__origin__", None) is list:
        annotation = annotation.__args__[0] if getattr(annotation, "__args__", None) else str
    if annotation is float and not is_literal(value, non_finite=True):
        raise OptionError(f"{option}: got {value!r}, expected {EXPECTED}")
    if annotation is int and _INTEGER.fullmatch(value.strip(" ")) is None:
        raise OptionError(f"{option}: got {value!r}, expected a whole number such as 3")
    if annotation is Path and not value:
        raise OptionError(f"{option}: got '', expected a path ('.' for the current folder)")
