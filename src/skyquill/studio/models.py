"""The studio's JSON: pydantic request and response models, with every size bounded.

Units enter here (DESIGN: units are converted only where input enters): the
page sends canvas points (any unit, y up) and limits in SI. Every list has a
maximum length and every number a finite range, so one request can only ask
for a bounded amount of planning.
"""

from __future__ import annotations

import re
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from skyquill.phases import MAX_MIN_ALTITUDE_M, MIN_ALTITUDE_M

#: Strokes in one drawing.
MAX_STROKES = 200
#: Points in one stroke.
MAX_STROKE_POINTS = 5_000
#: Points over all strokes (a tablet at 120 Hz for ~3 minutes).
MAX_POINTS = 20_000
#: Characters of typed text.
MAX_TEXT = 40
#: Drones writing at once.
MAX_DRONES = 8
#: Largest coordinate magnitude of a drawn point, in the page's units.
MAX_COORDINATE = 1e6

#: The vehicles the page offers (:data:`TARGETS`).
Target = Literal["generic", "crazyflie", "skybrush"]

Coordinate = Annotated[float, Field(ge=-MAX_COORDINATE, le=MAX_COORDINATE, strict=True)]
Point = tuple[Coordinate, Coordinate]
Stroke = Annotated[list[Point], Field(min_length=2, max_length=MAX_STROKE_POINTS)]
Timestamp = Annotated[float, Field(ge=0.0, le=1e7, strict=True)]
StrokeTimes = Annotated[list[Timestamp], Field(max_length=MAX_STROKE_POINTS)]


class PlanRequest(BaseModel):
    """What the page asks to be planned: a drawing or typed text, and the limits.

    Exactly one of ``strokes`` and ``text`` is given.
    """

    # Numbers and flags are strict (Field(strict=True)): a JSON true is not the number 1,
    # nor "2" a number: refuse, don't repair.
    model_config = ConfigDict(
        extra="forbid",
        allow_inf_nan=False,
        json_schema_extra={
            "examples": [
                {
                    "strokes": [[[0, 0], [50, 80], [100, 0]], [[20, 30], [80, 30]]],
                    "t": [[0.0, 0.2, 0.4], [1.0, 1.3]],
                    "size_m": 0.5,
                    "vmax": 1.0,
                    "amax": 2.0,
                    "jmax": 10.0,
                },
                {"text": "Hi", "drones": 2, "board": "wall"},
            ]
        },
    )

    strokes: Annotated[list[Stroke] | None, Field(max_length=MAX_STROKES)] = Field(
        default=None,
        description="Drawn strokes in drawing order: lists of [x, y] points, y up, any unit.",
    )
    t: Annotated[list[StrokeTimes] | None, Field(max_length=MAX_STROKES)] = Field(
        default=None,
        description="Optional timestamps, s: one list per stroke, one per point, increasing.",
    )
    text: Annotated[str | None, Field(min_length=1, max_length=MAX_TEXT)] = Field(
        default=None, description="Text to write instead of strokes (Latin or Chinese)."
    )
    board: Literal["horizontal", "wall"] = Field(
        default="horizontal", description="A horizontal board (paper 000) or a wall."
    )
    size_m: float = Field(
        default=0.5,
        ge=0.05,
        le=5.0,
        strict=True,
        description="Larger side of each drone's writing, m.",
    )
    vmax: float = Field(
        default=1.0, gt=0.0, le=20.0, strict=True, description="Speed: the velocity's norm, m/s."
    )
    amax: float = Field(
        default=2.0, gt=0.0, le=50.0, strict=True, description="Acceleration norm, m/s^2."
    )
    jmax: float = Field(
        default=10.0, gt=0.0, le=1000.0, strict=True, description="Jerk norm, m/s^3."
    )
    drones: int = Field(
        default=1,
        ge=1,
        le=MAX_DRONES,
        strict=True,
        description="Drones writing at once, boards side by side.",
    )
    fly: bool = Field(
        default=True, strict=True, description="Also fly every drone in closed-loop simulation."
    )
    target: Target = Field(
        default="generic",
        description="The vehicle the flight is for: its files, estimates and warnings "
        "(``crazyflie``: planned to fit its uploads; ``skybrush``: a show file).",
    )
    min_altitude_m: float = Field(
        default=MIN_ALTITUDE_M,
        ge=0.0,
        le=MAX_MIN_ALTITUDE_M,
        strict=True,
        description="Lowest altitude of the mission above the ground, m: each drone takes off "
        "to a hover this high above its pad and nothing between take-off and landing is "
        "planned below it.",
    )

    @model_validator(mode="after")
    def _one_input(self) -> PlanRequest:
        """Exactly one input; timestamps only with strokes; total points bounded."""
        if (self.strokes is None) == (self.text is None):
            got = "both" if self.strokes is not None else "neither"
            raise ValueError(f"got {got} of strokes and text, expected exactly one")
        if self.t is not None and self.strokes is None:
            raise ValueError("t: got timestamps without strokes, expected them only with strokes")
        if self.strokes is not None:
            total = sum(len(s) for s in self.strokes)
            if total > MAX_POINTS:
                raise ValueError(
                    f"strokes: got {total} points in all, expected at most {MAX_POINTS}"
                )
        if self.text is not None and not self.text.strip():
            raise ValueError(f"text: got {self.text!r}, expected at least one visible character")
        return self


JobState = Literal["queued", "running", "done", "error", "cancelled"]

#: The page's label of each request field, for messages a person reads (the API's
#: errors name the field as the JSON does; the page shows these and highlights the field).
FIELD_LABELS = {
    "strokes": "Drawing",
    "t": "Drawing",
    "text": "Text",
    "board": "Surface",
    "size_m": "Size of the writing, m",
    "drones": "Drones",
    "vmax": "Speed, m/s",
    "amax": "Acceleration, m/s²",
    "jmax": "Jerk, m/s³",
    "fly": "Fly it in simulation",
    "target": "Vehicle",
    "limits": "Limits",  # not a field: the three limits together (an infeasible plan)
}

#: Words a message may start with that are about one field without being its name.
FIELD_ALIASES = {"stroke": "strokes", "times": "t"}
_LEADING_NAME = re.compile(r"([a-z_]+)")


def field_of(message: str) -> str | None:
    """The request field a ``"name: got X, expected Y"`` message is about, if it is one."""
    found = _LEADING_NAME.match(message)
    if found is None:
        return None
    name = FIELD_ALIASES.get(found.group(1), found.group(1))
    return name if name in FIELD_LABELS else None


class Estimate(BaseModel):
    """What a request would plan, from its route alone (no solve): milliseconds to compute.

    The flight time is the timing the planner starts from (its fastest try:
    :func:`~skyquill.calligraphy.mission.initial_flight_time`); the planner may
    stretch it. ``warnings`` are about the chosen vehicle only
    (:data:`~skyquill.studio.estimate.WARN_FLIGHT_S`, ...), for a person.
    """

    target: Target = Field(description="The vehicle the estimate is for.")
    path_length_m: float = Field(description="Longest drone's route (strokes, lifts, legs), m.")
    flight_time_s: float = Field(description="Longest drone's flight as first timed, s.")
    crazyflie_uploads: int | None = Field(
        default=None,
        description="Crazyflie uploads of the longest drone, at most (target crazyflie only).",
    )
    setpoint_bytes: int = Field(description="Size of the setpoint CSV(s), about, bytes.")
    warnings: list[str] = Field(description="Thresholds crossed, in the page's words.")


class Limits(BaseModel):
    """The limits the plan was asked to respect: the speed, the acceleration and jerk norms."""

    vmax: float
    amax: float
    jmax: float


class LimitReport(BaseModel):
    """One limit as the dense verification found it."""

    label: str
    max_value: float
    relative_excess: float
    guaranteed: bool


class DronePlan(BaseModel):
    """One drone's plan, in its board's coordinates: u right, v up, h off the board (m).

    Attributes of the page's overlay: ``source_lo`` and ``source_scale`` map
    board coordinates back to the units the strokes came in
    (``source = source_lo + uv / source_scale``), so the path lands on the ink.
    """

    board_u0: float = Field(description="This board's left edge, m along the row of boards.")
    source_lo: tuple[float, float]
    source_scale: float = Field(description="Metres per source unit.")
    input: list[list[tuple[float, float]]] = Field(description="The strokes on the board, m.")
    t: list[float] = Field(description="Sample times, s.")
    path: list[tuple[float, float, float]] = Field(description="Planned tip (u, v, h), m.")
    pen: list[int] = Field(description="1 where the pen is down at t, else 0.")
    speed: list[float] = Field(description="Speed (the velocity's norm) at t, m/s.")
    acc: list[float] = Field(description="Acceleration norm at t, m/s^2.")
    jerk: list[float] = Field(description="Jerk norm at t, m/s^3.")
    flight: list[tuple[float, float, float]] = Field(
        description="Simulated tip (u, v, h), m, at the same times (empty if not flown)."
    )
    ink: list[list[tuple[float, float]]] = Field(
        description="What the simulated brush drew on the board, m (horizontal board only)."
    )
    ink_t: list[list[float]] = Field(
        default_factory=list,
        description="When each point of ``ink`` was laid, s (the page lays the ink as it plays).",
    )
    duration_s: float
    planning_time_s: float
    deviation_max_m: float
    checks: list[LimitReport]
    flight_rmse_m: float | None = None
    ink_width_m: float = Field(
        description="Width of the planned strokes' ink (the brush's footprint at its press), m."
    )
    ink_max_deviation_m: float | None = Field(
        default=None,
        description="Two-sided distance between the simulated ink and the input strokes in "
        "the board's plane, m (None: not flown, no contact board, or no ink).",
    )
    ink_iou: float | None = Field(
        default=None,
        description="Overlap of the simulated ink with the input drawn at the planned stroke "
        "width: intersection over union of their areas (None: not flown or no contact board).",
    )


class Delivered(BaseModel):
    """One download as its consumer plays it, against the plan's limits (``as_played``)."""

    kind: str = Field(description="The download (``show``, ``crazyswarm``).")
    verdict: Literal[
        "every limit met", "within the delivery tolerance", "limits exceeded", "refused"
    ] = Field(description="``refused``: the format cannot play the plan inside its limits.")
    relative_excess: dict[str, float] = Field(
        default_factory=dict,
        description="Largest excess over the speed, acceleration and jerk limits, relative.",
    )
    allowed_relative_excess: dict[str, float] = Field(default_factory=dict)


class DownloadFile(BaseModel):
    """A file the page offers for download."""

    name: str = Field(description="``skyquill-<plan id>-<kind>``: the name it downloads as.")
    kind: str = Field(description="What it is, the same in every plan (``setpoints.csv``).")
    url: str
    description: str
    size_bytes: int


class PlanResult(BaseModel):
    """Everything the page shows after a plan."""

    plan_id: str = Field(description="In every download's name and in summary.json.")
    source: Literal["strokes", "text"]
    board: Literal["horizontal", "wall"]
    target: Target = "generic"
    size_m: float
    limits: Limits
    duration_s: float
    planning_time_s: float
    min_separation_m: float | None
    drones: list[DronePlan]
    files: list[DownloadFile]
    delivered: list[Delivered] = Field(
        default_factory=list,
        description="Each download as played (summary.json: exports.<kind>.as_played): "
        "'every limit met' is said only when every one of them meets every limit.",
    )
    notes: list[str]


class TargetChoice(BaseModel):
    """A vehicle the page offers."""

    name: Target
    label: str
    help: str


class PageLimits(BaseModel):
    """What the page states up front and checks before sending: the request's bounds."""

    max_strokes: int = MAX_STROKES
    max_points: int = MAX_POINTS
    max_stroke_points: int = MAX_STROKE_POINTS
    max_text: int = MAX_TEXT
    max_drones: int = MAX_DRONES
    targets: list[TargetChoice]


class JobAccepted(BaseModel):
    """The answer to a plan request: where to poll."""

    job_id: str
    url: str


class JobStatus(BaseModel):
    """A planning job: its state, progress and, once done, the result."""

    job_id: str
    state: JobState
    progress: float = Field(ge=0.0, le=1.0)
    stage: str
    message: str = ""
    field: str | None = Field(
        default=None, description="The request field an error is about (None: no one field)."
    )
    user_message: str = Field(
        default="", description="The error in the page's words (the field as labelled)."
    )
    progress_known: bool = Field(
        default=True,
        description="False while the stage's length cannot be known in advance (a drone's "
        "solves): the page then shows the stage, not a fraction.",
    )
    elapsed_s: float
    result: PlanResult | None = None
