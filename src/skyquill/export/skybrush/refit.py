"""Keyframes Skybrush plays inside the plan's limits: built, played, checked, refitted or refused.

Each drone's keyframes (:func:`~.keyframes.skybrush_keyframes`) are played with Skybrush's own
arithmetic (:mod:`.playback`) and checked densely against the plan's limits
(:func:`~skyquill.export.base.check_delivered`). Played speed and acceleration may be at most
1 % over a limit and the jerk 5 % (:data:`~skyquill.export.base.ALLOWED_EXCESS`: what the
millimetre grid cannot avoid where the plan touches a limit). Beyond that the keyframes are
made again, each time further from the limits: :data:`ATTEMPTS` (a planning margin on the fit,
longer fit segments, and at last every segment fitted, none copied from the plan); if even the
last plays over a limit, the export is refused with the numbers. A fit that keeps the limits
only by leaving the plan (more than :data:`MAX_DEVIATION_M` from it: a plan over its own
limits) is refused too.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from skyquill.errors import InfeasibleError, SolverError
from skyquill.export.base import ALLOWED_EXCESS, ORDER_NAMES, DeliveredCheck, check_delivered
from skyquill.export.skybrush.keyframes import Keyframes, skybrush_keyframes
from skyquill.export.skybrush.playback import played_trajectory
from skyquill.io.trajectory_json import PlannedTrajectory
from skyquill.trajectory import Trajectory
from skyquill.verify import verify

#: ``(margin, exact pieces kept, fit segment scale)`` tried in order: as planned; shorter fit
#: segments (nearer a plan the longer ones cannot follow, the rounding then left to the
#: limit-aware search); a planning margin; a margin and longer segments, everything fitted.
ATTEMPTS = ((0.0, True, 1.0), (0.0, True, 0.5), (0.02, True, 1.0), (0.05, False, 2.0))
#: Farthest the keyframes may be from the plan before rounding, m: a fit farther off is a
#: plan its limits cannot fly (it is over them), not the plan delivered.
MAX_DEVIATION_M = 0.02


@dataclass(frozen=True)
class PlayedKeyframes:
    """A drone's keyframes, the trajectory Skybrush plays from them, its check, and the attempt
    that made them."""

    keyframes: Keyframes
    played: Trajectory
    delivered: DeliveredCheck
    attempt: int

    def report(self) -> dict[str, Any]:
        """JSON-ready: how the keyframes were made and refitted."""
        margin, exact, scale = ATTEMPTS[self.attempt]
        return self.keyframes.report() | {
            "refit": {
                "attempt": self.attempt + 1,
                "of": len(ATTEMPTS),
                "margin": margin,
                "exact_pieces": exact,
                "segment_scale": scale,
            }
        }


def played_keyframes(name: str, planned: PlannedTrajectory) -> PlayedKeyframes:
    """Keyframes of ``planned`` that play within the allowed excess of its limits.

    Raises
    ------
    InfeasibleError
        When the last attempt still plays over a limit: naming the drone, the limit, how
        far over, and what to do.
    """
    last: PlayedKeyframes | None = None
    far: float | None = None  # the least distance of keyframes that kept the limits
    infeasible: InfeasibleError | SolverError | None = None
    for i, (margin, exact, scale) in enumerate(ATTEMPTS):
        try:
            frames = skybrush_keyframes(
                planned.trajectory, planned.limits, margin=margin, exact=exact, segment_scale=scale
            )
        except (InfeasibleError, SolverError) as exc:
            # A fit region that cannot keep the limits, or whose QP the solver could not
            # settle (seen on long coverage plans): the next attempt's segments differ.
            infeasible = exc
            continue
        back = played_trajectory(name, {"points": frames.points()}).trajectory()
        here = PlayedKeyframes(frames, back, check_delivered(name, planned, back), i)
        inside = here.delivered.within_allowed or not planned.limits
        if inside and frames.fit_error_m <= MAX_DEVIATION_M:
            return here
        if inside:  # kept the limits by leaving the plan
            far = frames.fit_error_m if far is None else min(far, frames.fit_error_m)
        else:
            last = here
    if last is not None and far is None:
        raise _refusal(name, last.delivered)
    if far is not None:
        raise _unfittable(
            name,
            planned,
            f"keyframes inside them are {100 * far:.1f} cm from it at best, farther than "
            f"{100 * MAX_DEVIATION_M:g} cm",
        )
    raise _unfittable(name, planned, str(infeasible))


def _unfittable(name: str, planned: PlannedTrajectory, cause: str) -> InfeasibleError:
    """The refusal of a drone no keyframes keep inside its limits, with the plan's own excess."""
    own = verify(planned.trajectory, planned.limits, guaranteed=False)
    orders = [(n, own.excess(n)) for n in ORDER_NAMES]
    order, excess = max(orders, key=lambda item: item[1])
    itself = (
        f"the plan itself is {100 * excess:.2f} % over its {ORDER_NAMES[order]} limit"
        if excess > 0
        else "the plan keeps its limits, but not on Skybrush's grid"
    )
    return InfeasibleError(
        f"plan: got drone {name}, which no C2 cubic keyframes on Skybrush's ms and mm grid "
        f"keep inside its limits ({cause}): {itself}; expected a plan inside its limits",
        ("limits",),
    )


def _refusal(name: str, check: DeliveredCheck) -> InfeasibleError:
    """The refusal of a drone whose keyframes play over a limit, with the numbers."""
    order, excess = max(
        enumerate(check.excess_by_order, start=1),
        key=lambda item: item[1] - ALLOWED_EXCESS[item[0]],
    )
    what = ORDER_NAMES[order]
    return InfeasibleError(
        f"plan: got drone {name}'s {what} {100 * excess:.2f} % over its limit as Skybrush "
        f"plays it (after {len(ATTEMPTS)} fits on Skybrush's ms and mm grid), expected at "
        f"most {100 * ALLOWED_EXCESS[order]:g} % over; plan it with a lower {what} limit",
        ("limits",),
    )
