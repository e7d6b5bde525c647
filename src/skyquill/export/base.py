"""The one protocol every exporter implements, and what they share.

An exporter takes the named trajectories of a plan (one per drone, any kind),
writes its files, reads them back the way its consumer does and reports the
largest difference from the trajectories it was given: what is verified is
what is delivered.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.trajectory import Trajectory, dense_times
from skyquill.validation import as_float

#: A drone's name (the stem of its trajectory file) and its planned trajectory.
NamedPlan = tuple[str, PlannedTrajectory]


@dataclass(frozen=True)
class ExportOptions:
    """What an export may be asked for.

    Attributes
    ----------
    rate_hz
        Sample rate of the sampled formats, Hz.
    """

    rate_hz: float = 100.0

    def __post_init__(self) -> None:
        as_float("rate_hz", self.rate_hz, positive=True)


@dataclass(frozen=True)
class ExportReport:
    """What an exporter wrote and how well its consumer will reproduce the plan.

    Attributes
    ----------
    format
        The exporter's name.
    files
        Every file written, in flight order.
    exact
        Whether the format holds the trajectory exactly (up to float rounding).
    max_error_m
        Largest distance between the trajectory read back from the files (as
        the consumer reads them) and the plan, over dense samples, m.
    message
        One sentence for the command line.
    details
        Format-specific numbers (pieces, uploads, rate, refit deviation, ...).
    """

    format: str
    files: tuple[Path, ...]
    exact: bool
    max_error_m: float
    message: str
    details: dict[str, Any] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: ``<out>.summary.json``."""
        return {
            "format": self.format,
            "files": [str(f) for f in self.files],
            "exact": self.exact,
            "max_error_m": self.max_error_m,
            "message": self.message,
            **self.details,
        }


class Exporter(Protocol):
    """A format: a name, its file suffix, a line of help, and the export itself."""

    @property
    def name(self) -> str: ...

    @property
    def suffix(self) -> str: ...

    @property
    def help(self) -> str: ...

    def __call__(
        self, plans: Sequence[NamedPlan], out: Path, options: ExportOptions
    ) -> ExportReport: ...


def target(out: Path, name: str, several: bool, suffix: str) -> Path:
    """The file for drone ``name``: ``out`` itself, or ``<out stem>_<name><suffix>`` for several."""
    return out.with_name(f"{out.stem}_{name}{suffix}") if several else out.with_suffix(suffix)


def max_distance(reference: Trajectory, back: Trajectory, offset_s: float = 0.0) -> float:
    """Largest distance between ``back`` and ``reference`` at the reference's dense times, m.

    ``back`` is evaluated at ``t + offset_s`` (a file whose clock starts
    elsewhere); times past its end are held at its end.
    """
    t = dense_times(reference.breakpoints)
    here = np.clip(t + offset_s, 0.0, back.duration)
    diff = reference.evaluate(t) - back.evaluate(here)
    return float(np.linalg.norm(diff, axis=1).max())
