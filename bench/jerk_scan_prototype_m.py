"""Session 34, second prototype (removed in the next commit): lowering-only jerk scan with
feasible iterates (b <= r, water-level caps at r), phi-hull for the centre-only side.

Run from the worktree: .venv/bin/python bench/jerk_scan_prototype_m.py nohull 500 (or hull).
"""
import math, sys, time
import numpy as np
from skyquill.coverage.speed.reach import ReachPass
from skyquill.coverage.speed.rows import jerk_coefficients


def lower_hull_x(x, v):
    hull = []
    for k in range(len(x)):
        while len(hull) >= 2:
            a, c = hull[-2], hull[-1]
            if (v[c] - v[a]) * (x[k] - x[a]) >= (v[k] - v[a]) * (x[c] - x[a]):
                hull.pop()
            else:
                break
        hull.append(k)
    return np.interp(x, np.asarray(x)[hull], np.asarray(v)[hull])


def centre_hull(b, cm, cc, cp, lim):
    """Greatest b' <= b with, per node, the tightest centre-only side held (phi transform)."""
    n = b.size
    # centre-only side: s = -1 when cm, cp >= 0 and cc < 0 (coefs -cm,-cc,-cp); s = +1 when cm, cp <= 0, cc > 0
    ok_neg = (cm >= 0) & (cp >= 0) & (cc < 0)
    ok_pos = (cm <= 0) & (cp <= 0) & (cc > 0)
    P = np.where(ok_neg, cm, np.where(ok_pos, -cm, np.nan))  # P' >= 0
    R = np.where(ok_neg, cp, np.where(ok_pos, -cp, np.nan))
    Q = np.where(ok_neg, -cc, np.where(ok_pos, cc, np.nan))
    with np.errstate(invalid="ignore", divide="ignore"):
        bound = (lim[:, None] + P * b[:-2, None] + R * b[2:, None]) / Q
    bound = np.where(np.isfinite(bound), bound, np.inf)
    j = np.argmin(bound, axis=1)
    idx = np.arange(n - 2)
    has = np.isfinite(bound[idx, j]) & (R[idx, j] > 0) & (P[idx, j] > 0)
    Pj, Qj, Rj = P[idx, j], Q[idx, j], R[idx, j]
    out = b.copy()
    bl = b.tolist()
    i = 1
    hasl = has.tolist()
    Pl, Ql, Rl, liml = Pj.tolist(), Qj.tolist(), Rj.tolist(), lim.tolist()
    while i <= n - 2:
        if not hasl[i - 1]:
            i += 1
            continue
        lo = i
        phi = [1.0, 1.0]  # at lo-1, lo
        k = lo
        while k <= n - 2 and hasl[k - 1]:
            nxt = (Ql[k - 1] * phi[-1] - Pl[k - 1] * phi[-2]) / Rl[k - 1]
            if not (1e-8 < nxt < 1e8):
                break
            phi.append(nxt)
            k += 1
        hi = k - 1  # run lo..hi ; phi covers lo-1..hi+1
        if hi < lo:
            i += 1
            continue
        m = hi - lo + 3
        ph = np.asarray(phi[:m])
        # weights
        x = [0.0]
        pi = 1.0
        kap = [0.0]
        for t in range(lo, hi + 1):
            # node t: nu_t = P'_t phi_{t-1}, mu_t = R'_t phi_{t+1}; c_{t-1/2} = pi_t nu_t
            a = t - (lo - 1)
            c_left = pi * Pl[t - 1] * ph[a - 1]
            if t == lo:
                x.append(x[-1] + 1.0 / c_left)
            kap.append(pi * liml[t - 1])
            c_right = pi * Rl[t - 1] * ph[a + 1]
            x.append(x[-1] + 1.0 / c_right)
            pi = c_right / (Pl[t] * ph[a]) if t < hi else pi
        kap.append(0.0)
        x = np.asarray(x)
        # q: convex with slope jumps kap at the interior nodes
        slope = np.cumsum(kap[:-1])  # slope on segment a -> a+1
        q = np.concatenate([[0.0], np.cumsum(slope * np.diff(x))])
        v = np.asarray(bl[lo - 1 : hi + 2]) / ph
        w = lower_hull_x(x.tolist(), (v + q).tolist()) - q
        out[lo : hi + 1] = np.minimum(out[lo : hi + 1], np.maximum(w[1:-1] * ph[1:-1], 0.0))
        i = hi + 1
    return out


def water(coef, vals, budget):
    order = sorted(range(len(vals)), key=lambda j: vals[j])
    below = 0.0
    above = sum(coef)
    for j in order:
        t = (budget - below) / above
        if t <= vals[j]:
            return max(t, 0.0)
        below += coef[j] * vals[j]
        above -= coef[j]
    return math.inf


def sweep(b, r, rows, lim, order):
    cm, cc, cp = rows
    for i in order:
        lo_ = lim[i - 1]
        for p, q, s_ in zip(cm[i - 1], cc[i - 1], cp[i - 1]):
            for sg in (1.0, -1.0):
                co = (sg * p, sg * q, sg * s_)
                vals = (b[i - 1], b[i], b[i + 1])
                if co[0] * vals[0] + co[1] * vals[1] + co[2] * vals[2] <= lo_:
                    continue
                pos = [k for k in range(3) if co[k] > 0]
                budget = lo_ - sum(co[k] * vals[k] for k in range(3) if co[k] <= 0)
                if len(pos) == 1:
                    k = pos[0]
                    b[i - 1 + k] = max(min(vals[k], budget / co[k]), 0.0)
                else:
                    t = water([co[k] for k in pos], [r[i - 1 + k] for k in pos], budget)
                    for k in pos:
                        b[i - 1 + k] = min(b[i - 1 + k], t)


def excess(b, rows_np, lim):
    cm, cc, cp = rows_np
    x = cm * b[:-2, None] + cc * b[1:-1, None] + cp * b[2:, None]
    return np.max(np.abs(x), axis=1) / lim - 1.0


def solve_m(passes, rows_np, jf, acc, ub, outer=30, inner=50, tol=1e-4, use_hull=True, stats=None):
    cm, cc, cp = rows_np
    rows = (cm.tolist(), cc.tolist(), cp.tolist())
    r = passes.solve(acc, ub)
    n = r.size
    tot_inner = 0
    for it in range(outer):
        lim = jf[1:-1] / np.sqrt(np.maximum(r[1:-1], 1e-300))
        b = r.copy()
        for _ in range(inner):
            tot_inner += 1
            before = b
            if use_hull:
                b = centre_hull(b, cm, cc, cp, lim)
            bl = b.tolist()
            rl = r.tolist()
            sweep(bl, rl, rows, lim.tolist(), range(1, n - 1))
            sweep(bl, rl, rows, lim.tolist(), range(n - 2, 0, -1))
            b = passes.solve(acc, np.minimum(np.asarray(bl), before))
            if np.max(before - b) <= 1e-7 * b.max():
                break
        change = np.max(np.abs(np.sqrt(b) - np.sqrt(r))) / np.sqrt(b.max())
        r = b
        if change < tol:
            break
    if stats is not None:
        stats.update(outer=it + 1, inner=tot_inner)
    # certify exact rows
    ej = np.max(np.sqrt(b[1:-1]) * np.max(np.abs(cm * b[:-2, None] + cc * b[1:-1, None] + cp * b[2:, None]), axis=1) / jf[1:-1])
    ea = np.max(np.abs(passes.rows.alpha * b[:-1, None] + passes.rows.beta * b[1:, None]).max(axis=1) / acc)
    sc = min(1.0, 1.0 / max(ea, 1e-300), ej ** (-2 / 3) if ej > 0 else 1.0)
    if stats is not None:
        stats.update(scale=sc)
    return b * sc

if __name__ == "__main__":
    import sys, time
    import numpy as np
    sys.path.insert(0, "/work/wt-i27b2/tests/coverage"); sys.path.insert(0, "/tmp/i34")
    from speed_curves import square_spiral, wiggle
    from skyquill.coverage.speed import plan_speed
    from skyquill.coverage.speed.curve import _derivs3
    from skyquill.coverage.speed.norms import component_limits, components
    from skyquill.coverage.speed.reach import acceleration_rows, ReachPass
    from skyquill.coverage.speed.rows import _speed_bounds, _end_caps, _Bounds, _ones, jerk_coefficients
    from skyquill.coverage.speed.profile import _duration
    
    use_hull = sys.argv[1] == "hull"
    ns = [int(x) for x in sys.argv[2:]]
    curves = {"spiral": square_spiral(1.0), "wiggle": wiggle([(0,0),(1,0),(1,1),(0,1),(2,-1),(1,1),(1,0)])}
    for name, curve in curves.items():
      for sides in (None,):
        for n in ns:
            sig = np.linspace(0, 1, n)
            c1, c2, c3 = _derivs3(curve, sig)
            ub, vb = _speed_bounds(c1, c2, 3.0, chord_error=None, period=0.02)
            p1, p2, p3 = (components(c, sides) for c in (c1, c2, c3))
            alim = component_limits(np.full(2, 5.0), sides); jlim = component_limits(np.full(2, 3.0), sides)
            acc = acceleration_rows(p1, p2, sig[1], alim)
            bounds = _Bounds(ub, vb, p1.shape[1], *_ones(n)); _end_caps(bounds.ub, p1, jlim)
            cm, cc, cp = jerk_coefficients((p1, p2, p3))
            rows = (cm / jlim, cc / jlim, cp / jlim)
            st = {}
            t = time.perf_counter()
            b = solve_m(ReachPass(acc), rows, bounds.jerk, bounds.acc, bounds.cols(), use_hull=use_hull, stats=st)
            t = time.perf_counter() - t
            dur = _duration(b, sig[1], jerk=True)
            lp = plan_speed(curve, 3.0, 5.0, 3.0, n=n, norm_sides=sides, max_excess=None, method="lp")
            print(f"{name} {sides} n={n}: M {dur:.4f}s ({t:.2f}s, {st}) lp {lp.duration:.4f}s gap {dur/lp.duration-1:+.4f}", flush=True)
