"""Session 34 prototype (removed in the next commit): the jerk scan against the LP, grid level.

Run from the worktree: .venv/bin/python bench/jerk_scan_prototype.py 500 2000
"""
import sys, time
import numpy as np
sys.path.insert(0, "/work/wt-i27b2/tests/coverage")
from speed_curves import square_spiral, wiggle
from skyquill.coverage.speed import plan_speed
from skyquill.coverage.speed.curve import _derivs3
from skyquill.coverage.speed.norms import component_limits, components
from skyquill.coverage.speed.reach import acceleration_rows
from skyquill.coverage.speed.rows import _speed_bounds, _end_caps, _Bounds, _ones
from skyquill.coverage.speed.profile import _duration
from skyquill.coverage.speed.iteration import _initial_solve
from skyquill.coverage.speed.jerk_scan import ScanGrid, jerk_rows

def scan_plan(curve, n, v, a, j, sides):
    sig = np.linspace(0, 1, n)
    c1, c2, c3 = _derivs3(curve, sig)
    ub, vb = _speed_bounds(c1, c2, v, chord_error=None, period=0.02)
    p1, p2, p3 = (components(c, sides) for c in (c1, c2, c3))
    d = c1.shape[1]
    alim = component_limits(np.full(d, a), sides); jlim = component_limits(np.full(d, j), sides)
    acc = acceleration_rows(p1, p2, sig[1], alim)
    bounds = _Bounds(ub, vb, p1.shape[1], *_ones(n))
    g = ScanGrid(acc, jerk_rows((p1, p2, p3), jlim), vb, None, None)
    t = time.perf_counter()
    b, its = _initial_solve(g, bounds, c1=p1, jmax=jlim, stop=(20, 1e-3), log=([], []))
    t = time.perf_counter() - t
    return b, _duration(b, sig[1], jerk=True), t, (its, g.scan.solves, g.scan.rounds)

curves = {"spiral": square_spiral(1.0), "wiggle": wiggle([(0,0),(1,0),(1,1),(0,1),(2,-1),(1,1),(1,0)])}
ns = [int(x) for x in sys.argv[1:]] or [500, 2000]
for name, curve in curves.items():
  for sides in (None, 16):
    for n in ns:
        b, dur, t, rounds = scan_plan(curve, n, 3.0, 5.0, 3.0, sides)
        t0 = time.perf_counter()
        lp = plan_speed(curve, 3.0, 5.0, 3.0, n=n, norm_sides=sides, max_excess=None, method="lp")
        t1 = time.perf_counter() - t0
        t0 = time.perf_counter()
        fr = plan_speed(curve, 3.0, 5.0, None, n=n, norm_sides=sides, max_excess=None)
        t2 = time.perf_counter() - t0
        print(f"{name} sides={sides} n={n}: scan {dur:.4f}s ({t:.3f}s, its/scans/rounds {rounds})  lp {lp.duration:.4f}s ({t1:.3f}s) gap {dur/lp.duration-1:+.4f}  jerkfree {t2:.3f}s", flush=True)
