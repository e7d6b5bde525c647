"""Minimum-snap interpolation and straight Ruckig legs against their peers, in one run.

Issue 27, part 6: "at most 2 us per piece at 10,000 waypoints (banded solve), at least 10x
minsnap-trajectories at 10 waypoints; Ruckig legs at most 3x a direct call."

* **Min-snap**: :func:`skyquill.optimize.minsnap.min_snap` (one banded Cholesky solve) against
  ``minsnap-trajectories``' closed form (``skyquill.reproduce.peers.minsnap_interpolate``) on
  the same random waypoints in a 10 m cube with times from ``allocate_segment_times``, rest
  to rest, degree 7; timed alternately (ours, peer, ours, ...), the medians compared. At
  10,000 waypoints ours alone (the peer's dense solve does not scale), per piece. Both
  answers are compared (largest position difference over dense samples).
* **Legs**: ``stop_and_go`` over K random waypoints (its legs timed by the closed-form
  rest-to-rest profile, ``optimize/double_s.py``; at 1,000 the chain has 6 legs too short
  to reach the speed limit) against the direct call: ``Ruckig(1).calculate`` on reused
  objects, one leg at a time, which returns no pieces -- the least any leg timing costs
  through Ruckig's Python API. Also chains with every fifth leg too short to reach the
  speed limit (``short legs``: a zigzag's turns, a show's small moves), whose legs are
  timed on their own.

``--legs-only`` times the legs alone and merges them into the JSON (a few seconds).

BLAS is pinned to one thread, the collector is off while timing, and the clock is the
process's CPU time; the machine has 2 noisy cores, so the ratios (same run, interleaved)
are the numbers to quote.

Run: ``.venv/bin/python bench/minsnap.py [--quick]`` -> ``bench/results/minsnap.json``.
"""

from __future__ import annotations

import argparse
import itertools
import json
import time
from collections.abc import Callable
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from rich.console import Console
from rich.table import Table
from ruckig import InputParameter, Ruckig, Trajectory
from threadpoolctl import threadpool_limits

from common import gc_off, jsonable, machine_info
from skyquill.optimize.double_s import cruise
from skyquill.optimize.legs import LegLimits, stop_and_go
from skyquill.optimize.minsnap import min_snap
from skyquill.optimize.timing import allocate_segment_times
from skyquill.reproduce.peers import minsnap_interpolate

RESULTS = Path(__file__).resolve().parent / "results" / "minsnap.json"
#: Waypoint counts with the peer, and how many alternating rounds each.
PEER_ROUNDS = {10: 60, 100: 10, 1000: 1}
#: Waypoint counts timed for ours alone.
OURS_ONLY = (10_000,)
#: Legs per stop-and-go chain, and rounds.
LEG_COUNTS = {10: 200, 100: 50, 1000: 10}
GOALS = {"minsnap_ratio_at_10": 10.0, "minsnap_us_per_piece_at_10000": 2.0, "legs_ratio": 3.0}


def _waypoints(n: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(n)
    wp = rng.uniform(-5.0, 5.0, size=(n, 3))
    return wp, allocate_segment_times(wp, vmax=2.0, amax=1.0)


def _interleaved(fns: list[Callable[[], Any]], rounds: int) -> list[np.ndarray]:
    """Each of ``fns`` timed ``rounds`` times, alternating, after one warm-up call each (s).

    The clock is the process's CPU time (``time.process_time``): on a shared machine the
    wall clock also counts the other processes' time slices, which dwarfed the calls here.
    """
    for fn in fns:
        fn()
    times = np.empty((len(fns), rounds))
    with gc_off():
        for r in range(rounds):
            for i, fn in enumerate(fns):
                start = time.process_time()
                fn()
                times[i, r] = time.process_time() - start
    return list(times)


def minsnap_cases(quick: bool) -> list[dict[str, Any]]:
    out = []
    for n, rounds in PEER_ROUNDS.items():
        if quick and n > 100:
            continue
        wp, t = _waypoints(n)
        ours_t, peer_t = _interleaved(
            [lambda w=wp, tt=t: min_snap(w, tt), lambda w=wp, tt=t: minsnap_interpolate(w, tt)],
            max(1, rounds // (5 if quick else 1)),
        )
        ours, peer = min_snap(wp, t), minsnap_interpolate(wp, t).trajectory
        dense = np.linspace(0.0, ours.duration, 20 * n)
        out.append(
            {
                "waypoints": n,
                "pieces": n - 1,
                "runs": int(ours_t.size),
                "ours_median_s": float(np.median(ours_t)),
                "peer_median_s": float(np.median(peer_t)),
                "ratio_peer_over_ours": float(np.median(peer_t) / np.median(ours_t)),
                "ours_us_per_piece": float(np.median(ours_t)) / (n - 1) * 1e6,
                "max_position_difference_m": float(
                    np.abs(ours.evaluate(dense) - peer.evaluate(dense)).max()
                ),
            }
        )
    for n in OURS_ONLY:
        wp, t = _waypoints(n)
        (ours_t,) = _interleaved([lambda w=wp, tt=t: min_snap(w, tt)], 3 if quick else 15)
        out.append(
            {
                "waypoints": n,
                "pieces": n - 1,
                "runs": int(ours_t.size),
                "ours_median_s": float(np.median(ours_t)),
                "ours_us_per_piece": float(np.median(ours_t)) / (n - 1) * 1e6,
            }
        )
    return out


def _direct(lengths: np.ndarray, lim: LegLimits, *, read: bool = False) -> Callable[[], None]:
    """Ruckig's own call, objects reused, one 1-D leg after another (no pieces made).

    With ``read``, each leg's phase durations are read back too (``profiles[0][0].t``):
    the least any leg timing that returns the profile can cost through Ruckig's Python
    binding; not a goal, it says how much of ours is the binding.
    """
    inp, traj, otg = InputParameter(1), Trajectory(1), Ruckig(1)
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [lim.vmax], [lim.amax], [lim.jmax]

    def run() -> None:
        for length in lengths:
            inp.target_position = [length]
            otg.calculate(inp, traj)

    def run_and_read() -> None:  # a second loop: no test for `read` in the timed one
        for length in lengths:
            inp.target_position = [length]
            otg.calculate(inp, traj)
            traj.profiles[0][0].t  # noqa: B018 -- the read is what is timed

    return run_and_read if read else run


#: Every this many legs one is scaled down to this fraction in the chains with short legs
#: (to at most 1.7 m, most of them below the 1.93 m a leg needs to reach 2 m/s under
#: 3 m/s^2 and 10 m/s^3; ``short_legs`` in the JSON counts those that do not).
SHORT_EVERY, SHORT_SCALE = 5, 0.05


def _chain(k: int, *, short: bool) -> np.ndarray:
    """K random legs in a 20 m cube; with ``short``, every :data:`SHORT_EVERY`-th scaled."""
    pts = np.random.default_rng(k).uniform(0.0, 20.0, size=(k + 1, 3))
    if not short:
        return pts
    steps = np.diff(pts, axis=0)
    steps[::SHORT_EVERY] *= SHORT_SCALE
    return np.vstack([pts[:1], pts[0] + np.cumsum(steps, axis=0)])


def leg_cases(quick: bool) -> list[dict[str, Any]]:
    out = []
    lim = LegLimits(2.0, 3.0, 10.0)
    profile = cruise(lim.vmax, float(lim.amax), float(lim.jmax))
    assert profile is not None
    ramp_s = profile.ramp_s  # a leg no longer than vmax ramp_s does not cruise
    for (k, rounds), short in itertools.product(LEG_COUNTS.items(), (False, True)):
        pts = _chain(k, short=short)
        lengths = np.linalg.norm(np.diff(pts, axis=0), axis=1).tolist()
        ours_t, direct_t, read_t = _interleaved(
            [
                lambda p=pts: stop_and_go(p, lim),
                _direct(np.asarray(lengths), lim),
                _direct(np.asarray(lengths), lim, read=True),
            ],
            max(1, rounds // (5 if quick else 1)),
        )
        out.append(
            {
                "legs": k,
                "short_legs": int(np.sum(np.asarray(lengths) <= lim.vmax * ramp_s)),
                "runs": int(ours_t.size),
                "ours_us_per_leg": float(np.median(ours_t)) / k * 1e6,
                "direct_us_per_leg": float(np.median(direct_t)) / k * 1e6,
                "ratio_ours_over_direct": float(np.median(ours_t) / np.median(direct_t)),
                "direct_reading_phase_times_us_per_leg": float(np.median(read_t)) / k * 1e6,
            }
        )
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer rounds, no 1,000-waypoint peer")
    parser.add_argument(
        "--legs-only", action="store_true", help="time the legs alone, merged into the JSON"
    )
    args = parser.parse_args()
    console = Console()
    start = time.perf_counter()
    with threadpool_limits(1), console.status("timing min-snap and legs"):
        if args.legs_only:
            earlier = json.loads(RESULTS.read_text())
            minsnap = earlier["minsnap"]
        else:
            minsnap = minsnap_cases(args.quick)
        legs = leg_cases(args.quick)
    at10 = next(c for c in minsnap if c["waypoints"] == 10)
    at10k = next(c for c in minsnap if c["waypoints"] == 10_000)
    summary = {
        "goals": GOALS,
        "minsnap_ratio_at_10": at10["ratio_peer_over_ours"],
        "minsnap_us_per_piece_at_10000": at10k["ours_us_per_piece"],
        "legs_ratio_worst": max(c["ratio_ours_over_direct"] for c in legs),
    }
    summary["meets"] = {
        "minsnap_ratio_at_10": summary["minsnap_ratio_at_10"] >= GOALS["minsnap_ratio_at_10"],
        "minsnap_us_per_piece_at_10000": summary["minsnap_us_per_piece_at_10000"]
        <= GOALS["minsnap_us_per_piece_at_10000"],
        "legs_ratio": summary["legs_ratio_worst"] <= GOALS["legs_ratio"],
    }
    now = datetime.now(UTC).isoformat(timespec="seconds")
    machine = machine_info(("scipy", "ruckig", "minsnap-trajectories"))
    if args.legs_only:
        result = earlier | {"legs": legs, "summary": summary, "legs_generated_utc": now,
                            "legs_machine": machine}  # fmt: skip
    else:
        result = {
            "schema": 1,
            "generated_utc": now,
            "quick": args.quick,
            "total_wall_s": time.perf_counter() - start,
            "machine": machine,
            "blas_threads_pinned_to": 1,
            "minsnap": minsnap,
            "legs": legs,
            "summary": summary,
        }
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(json.dumps(jsonable(result), indent=2) + "\n")
    table = Table(title="min-snap (banded) vs minsnap-trajectories; legs vs a direct Ruckig call")
    for col in ("case", "ours", "peer", "ratio"):
        table.add_column(col)
    for c in minsnap:
        table.add_row(
            f"min-snap {c['waypoints']} wp",
            f"{c['ours_median_s'] * 1e3:.3f} ms ({c['ours_us_per_piece']:.2f} us/piece)",
            f"{c['peer_median_s'] * 1e3:.1f} ms" if "peer_median_s" in c else "-",
            f"{c['ratio_peer_over_ours']:.0f}x faster" if "ratio_peer_over_ours" in c else "-",
        )
    for c in legs:
        table.add_row(
            f"{c['legs']} legs ({c['short_legs']} short)",
            f"{c['ours_us_per_leg']:.2f} us/leg",
            f"{c['direct_us_per_leg']:.2f} us/leg (direct)",
            f"{c['ratio_ours_over_direct']:.2f}x the direct call",
        )
    console.print(table)
    console.print(f"wrote {RESULTS}")


if __name__ == "__main__":
    main()
