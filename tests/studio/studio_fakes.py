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
