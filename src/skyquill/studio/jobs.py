"""Planning jobs: each in a process of its own, with an id, progress and a time limit.

Planning is CPU-bound and runs skyquill's numerical core (QP solvers, sparse
factorisations) on whatever the person sent. Each job therefore runs in a
child process, not in the server: the event loop stays responsive, the time
limit is enforced by killing the child, and a crash in native code (seen:
scipy's ``splu`` segfaulting inside time re-segmentation on a jerk limit of
0.01 m/s^3) fails that one job instead of the server. Children come from a
``forkserver`` that preloads skyquill, so a job starts in milliseconds and
never forks the threaded server itself.

A small thread pool supervises the children (one thread per running job):
it relays progress, collects the result and kills a child past its time.
Everything is bounded: at most ``max_active`` jobs queued or running (more is
refused: the studio is busy), at most ``max_kept`` finished jobs kept in
memory with their files (the oldest forgotten first).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import multiprocessing
import signal
import threading
import time
import traceback
import uuid
from collections import OrderedDict
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from multiprocessing.connection import Connection
from typing import Any

from skyquill.errors import SkyquillError
from skyquill.studio.estimate import WARN_FLIGHT_S
from skyquill.studio.messages import StudioInputError, for_person
from skyquill.studio.models import Estimate, JobState, JobStatus, PlanRequest, field_of
from skyquill.studio.planner import PlanOutput, run_plan

logger = logging.getLogger(__name__)

#: A planner: the request, a progress callback, the URL of a file by its name, the plan id.
Planner = Callable[..., PlanOutput]


class BusyError(Exception):
    """Too many jobs are queued or running; the request should be retried later."""


#: Modules the forkserver imports once, so that each child starts warm.
PRELOAD = (
    "skyquill.studio.planner",
    "skyquill.cli.main",
    "skyquill.sim",
    "skyquill.export.skybrush.skyc_file",
)
#: How often a supervisor checks its child's messages, liveness and time, s.
POLL_S = 0.05
#: Hex digits of the job id that make the plan id (in file names): 48 bits, so two
#: plans of one studio share one with a chance of 1 in 10^14.
PLAN_ID_DIGITS = 12


@dataclass
class Job:
    """One planning job; mutated only by its worker thread and by :class:`JobManager`."""

    id: str
    request: PlanRequest
    deadline: float
    created: float = field(default_factory=time.monotonic)
    state: JobState = "queued"
    progress: float = 0.0
    stage: str = "waiting for a worker"
    message: str = ""
    output: PlanOutput | None = None
    finished: float | None = None
    future: Future[None] | None = None
    estimate: Estimate | None = None
    cancel_requested: bool = False
    progress_known: bool = True
    field: str | None = None
    user_message: str = ""

    @property
    def active(self) -> bool:
        """Queued or running."""
        return self.state in ("queued", "running")

    @property
    def plan_id(self) -> str:
        """The plan's identifier, in its files' names."""
        return self.id[:PLAN_ID_DIGITS]

    def status(self) -> JobStatus:
        """The JSON the page polls."""
        end = self.finished if self.finished is not None else time.monotonic()
        return JobStatus(
            job_id=self.id,
            state=self.state,
            progress=self.progress,
            stage=self.stage,
            message=self.message,
            field=self._error_field(),
            user_message=self._user_message(),
            progress_known=self.progress_known,
            elapsed_s=round(end - self.created, 3),
            result=self.output.result if self.output is not None else None,
        )

    def _error_field(self) -> str | None:
        if self.state != "error":
            return None
        return self.field or field_of(self.message)

    def _user_message(self) -> str:
        """The error in the page's words (the studio's own, else the field's label put in)."""
        if self.state != "error":
            return ""
        return self.user_message or for_person(self.message, self._error_field())


class JobManager:
    """Runs planning jobs in child processes and keeps a bounded number of them.

    Parameters
    ----------
    workers
        Plans running at once (each a child process with a supervising thread).
    max_active
        Jobs queued or running at once; :meth:`submit` raises :class:`BusyError` beyond.
    max_kept
        Jobs (with their files) kept in memory, finished ones forgotten oldest first.
    time_limit_s
        Longest a job may take from submission, s.
    planner
        The planning function, run in the child: :func:`~skyquill.studio.planner.run_plan`
        (tests pass a slow or crashing one); a module-level function, so that it pickles.
    """

    def __init__(
        self,
        *,
        workers: int = 2,
        max_active: int = 4,
        max_kept: int = 16,
        time_limit_s: float = 120.0,
        planner: Planner = run_plan,
    ) -> None:
        self.time_limit_s = time_limit_s
        self._max_active = max_active
        self._max_kept = max_kept
        self._planner = planner
        self._jobs: OrderedDict[str, Job] = OrderedDict()
        self._lock = threading.Lock()
        self._closed = False
        self._executor = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="skyquill-plan")
        self._context = multiprocessing.get_context("forkserver")
        self._context.set_forkserver_preload(list(PRELOAD))

    def submit(self, request: PlanRequest, estimate: Estimate | None = None) -> Job:
        """Queue a plan of ``request``; raise :class:`BusyError` when too many are active.

        ``estimate`` (of the request) explains a time-out: what made the plan long.
        """
        with self._lock:
            self._expire()
            if sum(job.active for job in self._jobs.values()) >= self._max_active:
                raise BusyError(
                    f"the studio is busy with {self._max_active} plans; try again in a moment"
                )
            job = Job(uuid.uuid4().hex, request, time.monotonic() + self.time_limit_s)
            job.estimate = estimate
            self._jobs[job.id] = job
            self._forget_old()
        job.future = self._executor.submit(self._run, job)
        return job

    def cancel(self, job: Job) -> None:
        """Stop ``job``: a queued one at once, a running one by killing its process.

        The job ends ``"cancelled"`` (a finished one is left as it is); its
        supervisor sees the request within :data:`POLL_S` and kills the child.
        """
        with self._lock:
            job.cancel_requested = True
            if job.state == "queued":
                self._finish(job, "cancelled", "cancelled before it started")

    def get(self, job_id: str) -> Job | None:
        """The job ``job_id``, or ``None`` if unknown or forgotten."""
        with self._lock:
            self._expire()
            return self._jobs.get(job_id)

    async def wait(self, job: Job) -> None:
        """Wait (without blocking the event loop) until ``job`` ends or its time is up."""
        assert job.future is not None
        remaining = max(0.0, job.deadline - time.monotonic())
        with contextlib.suppress(TimeoutError):  # the job is then failed by _expire
            await asyncio.wait_for(asyncio.shield(asyncio.wrap_future(job.future)), remaining)
        with self._lock:
            self._expire()

    def warm_up(self) -> None:
        """Start the forkserver (importing skyquill once) now, so the first plan starts fast."""
        from multiprocessing import forkserver

        threading.Thread(
            target=forkserver.ensure_running, name="skyquill-warm-up", daemon=True
        ).start()

    def shutdown(self) -> None:
        """Stop taking jobs; queued ones are cancelled, running ones stop at their next stage."""
        self._closed = True
        self._executor.shutdown(wait=False, cancel_futures=True)

    def _run(self, job: Job) -> None:
        """A supervisor thread's side of a job: start the child, relay, collect, kill."""
        if not self._begin(job):
            return
        receiver, sender = self._context.Pipe(duplex=False)
        child = self._context.Process(
            target=_child_main,
            args=(self._planner, job.request, job.id, job.plan_id, sender),
            name=f"skyquill-plan-{job.id[:8]}",
            daemon=True,
        )
        try:
            child.start()
        except Exception as exc:  # e.g. a script without the __main__ guard multiprocessing needs
            logger.exception("studio job %s: the planner process did not start", job.id)
            self._end(job, "error", f"internal error: planning could not start ({exc})")
            return
        finally:
            sender.close()  # the child holds the only writer now: EOF when it dies
        try:
            self._supervise(job, child, receiver)
        finally:
            if child.is_alive():
                child.kill()
            child.join(timeout=5.0)
            receiver.close()

    def _supervise(self, job: Job, child: Any, receiver: Connection) -> None:
        """Relay the child's messages until it reports an end, dies or runs out of time."""
        while True:
            if job.cancel_requested:
                self._end(job, "cancelled", "cancelled")
                return
            if self._closed or time.monotonic() > job.deadline:
                self._end(job, "error", self._timeout_message(job))
                return
            try:
                ready = receiver.poll(POLL_S)
                message = receiver.recv() if ready else None
            except (EOFError, OSError):  # died without a word: a crash
                child.join(timeout=1.0)
                self._end(job, "error", _crash_message(child.exitcode))
                return
            if message is None:
                continue
            kind, *payload = message
            if kind == "progress":
                job.progress, job.stage, job.progress_known = payload
                continue
            if kind == "error":
                detail, job.field, job.user_message = payload
                self._end(job, "error", detail)
            else:
                self._end(job, "done", "", payload[0])
            return

    def _begin(self, job: Job) -> bool:
        with self._lock:
            if job.state != "queued":
                return False  # timed out while it waited for a worker
            job.state, job.stage = "running", "starting"
            return True

    def _end(
        self, job: Job, state: JobState, message: str, output: PlanOutput | None = None
    ) -> None:
        with self._lock:
            if not job.active:
                return  # already failed by its time limit: drop the late result
            self._finish(job, state, message, output)

    @staticmethod
    def _finish(job: Job, state: JobState, message: str, output: PlanOutput | None = None) -> None:
        """Record the end of ``job`` (caller holds the lock)."""
        job.state, job.message, job.output = state, message, output
        job.finished = time.monotonic()
        if state == "done":
            job.progress, job.stage = 1.0, "done"
        elif state == "cancelled":
            job.stage = "cancelled"

    def _timeout_message(self, job: Job) -> str:
        """Why the plan stopped, with what made it long when the estimate says."""
        if self._closed:
            return "the studio was shut down before the plan finished"
        limit = f"planning took longer than the studio's limit of {self.time_limit_s:g} s"
        guess, request = job.estimate, job.request
        if guess is None:
            return f"{limit}; draw or type less, use fewer drones or raise the limits"
        flight = (
            f"a flight of about {guess.flight_time_s:,.0f} s "
            f"({guess.path_length_m:.1f} m of route at {request.vmax:g} m/s)"
        )
        if guess.flight_time_s > WARN_FLIGHT_S:  # long because slow: the speed is the cause
            return f"{limit}: {flight} is long to plan; raise the speed limit or draw less"
        what = f"{len(request.strokes)} strokes" if request.strokes else f"{request.text!r}"
        return (
            f"{limit} for {what} on {request.drones} drone(s), {flight}; "
            "draw or type less, or use more drones"
        )

    def _expire(self) -> None:
        """Fail the active jobs past their deadline (caller holds the lock)."""
        now = time.monotonic()
        for job in self._jobs.values():
            if job.active and now > job.deadline:
                job.state, job.message, job.finished = "error", self._timeout_message(job), now

    def _forget_old(self) -> None:
        """Drop the oldest finished jobs beyond ``max_kept`` (caller holds the lock)."""
        finished = [j.id for j in self._jobs.values() if not j.active]
        for job_id in finished[: max(0, len(self._jobs) - self._max_kept)]:
            del self._jobs[job_id]


def _file_url(job_id: str) -> Callable[[str], str]:
    """The download URL of a job's file, by name (never a file-system path)."""
    return lambda name: f"/api/jobs/{job_id}/files/{name}"


def _child_main(
    planner: Planner, request: PlanRequest, job_id: str, plan_id: str, sender: Connection
) -> None:
    """The child process: plan, sending progress and then one end message."""

    def progress(fraction: float, stage: str, known: bool = True) -> None:
        sender.send(("progress", fraction, stage, known))

    try:
        output = planner(request, progress=progress, file_url=_file_url(job_id), plan_id=plan_id)
    except StudioInputError as exc:  # the person's input, in the page's words too
        sender.send(("error", str(exc), exc.field, exc.person))
    except SkyquillError as exc:  # the person's input: say why, in their terms
        sender.send(("error", str(exc), None, ""))
    except Exception as exc:  # a bug: traceback to the server's log, a short line to the page
        traceback.print_exc()
        message = f"internal error while planning ({type(exc).__name__}: {exc})"
        sender.send(("error", message, None, ""))
    else:
        sender.send(("done", output))
    finally:
        sender.close()


def _crash_message(exitcode: int | None) -> str:
    """What to tell the person when the planner process died."""
    how = f"exit status {exitcode}"
    if exitcode is not None and exitcode < 0:
        with contextlib.suppress(ValueError):
            how = f"signal {signal.Signals(-exitcode).name}"
    return (
        f"planning crashed ({how}); this is a bug in skyquill, not in the drawing. "
        "Try other limits, and please report it"
    )


__all__ = ["BusyError", "Job", "JobManager", "Planner"]
