"""One function over many independent items: here, in a process pool, or on a dask cluster.

The per-drone stages of a large show (the ``.skyc`` keyframes of 1,000 drones) are
independent and CPU-bound, like the writing flights (:mod:`skyquill.calligraphy.show`,
which has its own pool for its progress reports). :func:`parallel_map` runs them in this
process (``workers=1``), in a local process pool, or on a ``dask.distributed`` cluster
(``scheduler``: an address, or ``"local"`` for a cluster of this machine's cores); the
results are the same, in the order of the items. The function and the items must pickle
(a module-level function; the exceptions it raises arrive as raised).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass
from functools import partial
from types import ModuleType
from typing import Any, TypeVar

from threadpoolctl import threadpool_limits

from skyquill.errors import InputError

#: How long to wait for a ``dask.distributed`` scheduler to answer, s.
SCHEDULER_TIMEOUT_S = 5.0
#: Items per dask task: about this many tasks per worker, so that a slow item does not
#: hold the others back and a task's overhead (scheduling) stays small. A local pool hands
#: out one item at a time (:func:`parallel_map`).
TASKS_PER_WORKER = 4

T = TypeVar("T")
R = TypeVar("R")


@dataclass(frozen=True)
class Where:
    """Where independent work runs: in this process, a local pool, or a dask cluster.

    Attributes
    ----------
    workers : int or None
        Processes of the local pool; ``None``: one per CPU; 1: in this process.
    scheduler : str or None
        A ``dask.distributed`` scheduler's address, or ``"local"`` (see :func:`parallel_map`).
    """

    workers: int | None = 1
    scheduler: str | None = None

    @property
    def here(self) -> bool:
        """Whether the work runs in this process, one item after the other."""
        return self.scheduler is None and self.workers == 1

    def map(self, fn: Callable[[T], R], items: Sequence[T]) -> list[R]:
        """:func:`parallel_map` of ``fn`` over ``items`` here."""
        return parallel_map(fn, items, workers=self.workers, scheduler=self.scheduler)

    def describe(self) -> str:
        """Where, in a person's words: "2 processes", "the dask cluster at ..."."""
        if self.scheduler == "local":
            return "a local dask cluster"
        if self.scheduler is not None:
            return f"the dask cluster at {self.scheduler}"
        count = self.workers or os.cpu_count() or 1
        return "this process" if count == 1 else f"{count} processes"


#: In this process, one item after the other.
HERE = Where()


def parallel_map(
    fn: Callable[[T], R],
    items: Sequence[T],
    *,
    workers: int | None = 1,
    scheduler: str | None = None,
) -> list[R]:
    """``[fn(item) for item in items]``, computed in parallel.

    Parameters
    ----------
    fn
        A module-level function (it is pickled to the workers).
    items
        Its arguments, one per call.
    workers
        Processes of the local pool; ``None``: one per CPU; 1: in this process.
        Ignored when ``scheduler`` is given.
    scheduler
        ``None``: local (see ``workers``); ``"local"``: a ``dask.distributed`` cluster of
        this machine's cores, started for the call; otherwise a running scheduler's address.

    Raises
    ------
    InputError
        dask.distributed not installed, or a scheduler that does not answer within
        :data:`SCHEDULER_TIMEOUT_S`. Whatever ``fn`` raises, as raised.
    """
    if scheduler is not None:
        return _on_cluster(fn, list(items), scheduler)
    if workers == 1 or len(items) <= 1:
        return [fn(item) for item in items]
    count = workers or os.cpu_count() or 1
    with ProcessPoolExecutor(max_workers=count, initializer=one_blas_thread) as pool:
        # One item at a time: a free worker takes the next, so items given largest first
        # (a mission's pieces) end together. In pairs, the 10 ha field's two largest pieces
        # went to one worker, which finished 0.3-0.5 s after the other (4.8-5.0 s in all,
        # against 5.3 s).
        return list(pool.map(fn, items))


def one_blas_thread() -> None:
    """Keep this process's BLAS (and OpenMP) to one thread: a worker of a local pool, whose
    processes already fill the cores.

    Each worker inherits a BLAS that starts a thread per core: two workers on two cores
    ran four threads, and the held-out 1.3 ha field's pieces planned in 8.7-9.0 s at once
    against 4.6 s with one thread each (the banded interior point's factorisations). dask's
    own workers are started with one (its nanny sets ``OPENBLAS_NUM_THREADS=1``).
    """
    threadpool_limits(1)


def _chunk(items: int, workers: int) -> int:
    return max(1, math.ceil(items / (TASKS_PER_WORKER * workers)))


def _run_chunk(fn: Callable[[T], R], chunk: list[T]) -> list[R]:
    return [fn(item) for item in chunk]


def _on_cluster(fn: Callable[[T], R], items: list[T], scheduler: str) -> list[R]:
    with dask_client(scheduler) as (_, client):
        workers = max(1, len(client.scheduler_info().get("workers", {})))
        size = _chunk(len(items), workers)
        chunks = [items[k : k + size] for k in range(0, len(items), size)]
        futures: list[Any] = client.map(partial(_run_chunk, fn), chunks, pure=False)
        return [result for chunk in client.gather(futures) for result in chunk]


@contextmanager
def dask_client(scheduler: str) -> Iterator[tuple[ModuleType, Any]]:
    """``distributed`` and a client of ``scheduler``, closed (with its cluster) on exit.

    Parameters
    ----------
    scheduler
        A running scheduler's address, or ``"local"``: a ``LocalCluster`` of one
        single-threaded worker process per core of this machine, started here.

    Raises
    ------
    InputError
        dask.distributed not installed, or a scheduler that does not answer within
        :data:`SCHEDULER_TIMEOUT_S`.
    """
    distributed = import_distributed()
    if scheduler != "local":
        with _connect(distributed, scheduler) as client:
            yield distributed, client
        return
    # Worker processes, not threads: planning holds the GIL for much of its time (20 sky
    # drones: 21.5 s of planning on two threads, 5.5 s on two processes after a 2 s start).
    with (
        distributed.LocalCluster(
            n_workers=os.cpu_count() or 1,
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
        ) as cluster,
        _connect(distributed, cluster.scheduler_address) as client,
    ):
        yield distributed, client


def _connect(distributed: ModuleType, address: str) -> Any:
    try:
        return distributed.Client(address, timeout=SCHEDULER_TIMEOUT_S, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError(
            f"scheduler: got {address!r}, which did not answer within {SCHEDULER_TIMEOUT_S:g} s "
            f"({exc}), expected the address of a running dask scheduler"
        ) from None


def import_distributed() -> ModuleType:
    """``distributed``, or InputError saying how to install it."""
    try:
        import distributed
    except ImportError as exc:
        raise InputError(
            "scheduler: dask.distributed is not installed; pip install 'skyquill[dask]'"
        ) from exc
    return distributed
