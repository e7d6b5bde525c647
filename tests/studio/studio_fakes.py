"""Planners for the job tests, importable by the studio's planner processes.

They run in the child process (so they must be module-level functions): one
that outlives any time limit, one that crashes the way native code does.
"""

from __future__ import annotations

import os
import signal
import time
from typing import Any


def slow_planner(request: Any, *, progress: Any, file_url: Any, plan_id: str) -> Any:
    """Reports progress forever (until the studio kills it)."""
    for i in range(10_000):
        progress(min(0.99, i / 1000), f"step {i}")
        time.sleep(0.01)
    raise AssertionError("the studio should have stopped this plan")


def crashing_planner(request: Any, *, progress: Any, file_url: Any, plan_id: str) -> Any:
    """Dies of a segmentation fault after reporting a little progress."""
    progress(0.1, "about to crash")
    os.kill(os.getpid(), signal.SIGSEGV)
    time.sleep(10.0)  # never reached: the signal kills the process


def refusing_planner(request: Any, *, progress: Any, file_url: Any, plan_id: str) -> Any:
    """Refuses every request the way skyquill refuses bad input."""
    from skyquill.errors import InfeasibleError

    progress(0.5, "looking at it")
    raise InfeasibleError("limits: nothing can be planned here (a test planner)")


def over_limits_planner(request: Any, *, progress: Any, file_url: Any, plan_id: str) -> Any:
    """The real planner, whose show file then plays over the limits or is refused.

    The issue's case (limits 0.05 / 0.1 / 1: the .skyc peaked at 0.235 m/s^2 against 0.1)
    takes minutes to plan; the page's verdict is what is tested, so the real plan's
    ``delivered`` is replaced: ``request.text == "R"`` makes the show file refused, anything
    else makes it play 135 % over the acceleration limit.
    """
    from dataclasses import replace

    from skyquill.studio.models import Delivered
    from skyquill.studio.planner import run_plan

    output = run_plan(request, progress=progress, file_url=file_url, plan_id=plan_id)
    if request.text == "R":
        delivered = [Delivered(kind="show", verdict="refused")]
    else:
        excess = {"speed": 0.0, "acceleration": 1.35, "jerk": 0.0}
        delivered = [Delivered(kind="show", verdict="limits exceeded", relative_excess=excess)]
    return replace(output, result=output.result.model_copy(update={"delivered": delivered}))
