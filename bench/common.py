"""Shared helpers of the benchmark scripts (run as ``python bench/<name>.py``)."""

from __future__ import annotations

import gc
import math
import os
import platform
import subprocess
import sys
import tarfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt


@contextmanager
def gc_off() -> Iterator[None]:
    """Collect once, then keep the garbage collector off while timing (as ``timeit`` does)."""
    gc.collect()
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def one_blas_thread() -> Any:
    """Pin every BLAS the planners use to one thread, scipy's included.

    threadpoolctl limits only the libraries loaded when it is called: numpy and scipy wheels
    each bring their own OpenBLAS, and scipy's is loaded with ``scipy.linalg``, which skyquill
    imports lazily. Loading it first makes the pin take effect for the whole run.

    Returns
    -------
    threadpoolctl.threadpool_limits
        The limit, to use as a context manager.
    """
    import scipy.linalg  # noqa: F401  (loads scipy's OpenBLAS, see above)
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1, user_api="blas")


def jsonable(x: Any) -> Any:
    """``x`` with numpy scalars as Python numbers and non-finite floats as ``None`` (JSON)."""
    if isinstance(x, dict):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [jsonable(v) for v in x]
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def _version(name: str) -> str | None:
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return None


def machine_info(packages: tuple[str, ...]) -> dict[str, Any]:
    """Where the numbers were measured: platform, CPUs, load, and ``packages``' versions."""
    affinity = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None
    return {
        "platform": platform.platform(),
        "machine": platform.machine(),
        "processor": platform.processor(),
        "python": sys.version.split()[0],
        "python_implementation": platform.python_implementation(),
        "cpu_count": os.cpu_count(),
        "cpu_affinity_count": affinity,
        "loadavg_at_start": os.getloadavg() if hasattr(os, "getloadavg") else None,
        **{name: _version(name) for name in ("numpy", *packages, "skyquill")},
        "OPENBLAS_CORETYPE (read only)": os.environ.get("OPENBLAS_CORETYPE"),
    }


def time_calls(fn: Callable[[], Any], runs: int) -> tuple[npt.NDArray[np.float64], Any]:
    """``runs`` timed calls of ``fn`` with the collector off: the times (s) and the last result."""
    times = np.empty(runs)
    out = None
    with gc_off():
        for i in range(runs):
            start = time.perf_counter()
            out = fn()
            times[i] = time.perf_counter() - start
    return times, out


def time_stats(times: npt.NDArray[np.float64], warmup: int) -> dict[str, Any]:
    """Median, 10th and 90th percentile (s) of ``times``, with the run counts."""
    return {
        "median_s": float(np.median(times)),
        "p10_s": float(np.percentile(times, 10)),
        "p90_s": float(np.percentile(times, 90)),
        "runs": int(times.size),
        "warmup_runs": warmup,
    }


def export_base(rev: str, into: Path) -> Path:
    """``git archive`` of ``rev`` unpacked in ``into``; returns its ``src`` folder."""
    archive = into / "base.tar"
    subprocess.run(
        ["git", "archive", "-o", str(archive), rev],
        cwd=Path(__file__).resolve().parents[1],
        check=True,
    )
    with tarfile.open(archive) as tar:
        tar.extractall(into / "base", filter="data")
    return into / "base" / "src"


def toppra_path(curve: Any) -> Any:
    """toppra's geometric path around a 2-D scipy ``BSpline`` on ``[0, 1]``; None without toppra.

    The peer of the coverage speed LP (``bench/coverage_lp.py``, ``bench/coverage_scale.py``).
    """
    try:
        import toppra as ta
        from toppra.interpolator import AbstractGeometricPath
    except ImportError:
        return None
    ta.setup_logging("WARNING")

    class BSplinePath(AbstractGeometricPath):  # type: ignore[misc]
        """toppra geometric-path adapter around the scipy ``BSpline``."""

        def __call__(self, s: Any, order: int = 0) -> Any:
            return np.asarray(curve(np.clip(np.asarray(s, dtype=float), 0.0, 1.0), order))

        @property
        def dof(self) -> int:
            return 2

        @property
        def path_interval(self) -> Any:
            return np.array([0.0, 1.0])

    return BSplinePath()
