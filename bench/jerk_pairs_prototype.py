"""Session 34, third prototype (removed in the next commit): TOPP-RA lifted to pairs
(b_i, b_{i+1}) inside the damped pseudo-jerk iteration, certified by scaling.

Run from the worktree: .venv/bin/python bench/jerk_pairs_prototype.py 100 200 500
"""
import numpy as np

EPS = 1e-12


def clip(poly, a, b, c):
    """Sutherland-Hodgman: polygon (list of (x,y)) clipped by a x + b y <= c."""
    out = []
    m = len(poly)
    if m == 0:
        return out
    scale = abs(c) + 1e-300
    for k in range(m):
        p = poly[k]
        q = poly[(k + 1) % m]
        fp = a * p[0] + b * p[1] - c
        fq = a * q[0] + b * q[1] - c
        tol = 1e-12 * (abs(a * p[0]) + abs(b * p[1]) + abs(c) + 1e-300)
        pin = fp <= tol
        qin = fq <= tol
        if pin:
            out.append(p)
        if pin != qin and m > 1:
            t = fp / (fp - fq)
            out.append((p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])))
    # dedupe
    res = []
    for v in out:
        if not res or abs(v[0] - res[-1][0]) + abs(v[1] - res[-1][1]) > 1e-15 * (abs(v[0]) + abs(v[1]) + 1e-300):
            res.append(v)
    if len(res) > 1 and abs(res[0][0] - res[-1][0]) + abs(res[0][1] - res[-1][1]) <= 1e-15 * (abs(res[0][0]) + abs(res[0][1]) + 1e-300):
        res.pop()
    return res


def polygon(halfplanes, xmax, ymax):
    poly = [(0.0, 0.0), (xmax, 0.0), (xmax, ymax), (0.0, ymax)]
    for a, b, c in halfplanes:
        poly = clip(poly, a, b, c)
        if not poly:
            return poly
    return poly


def tight(halfplanes, poly):
    """The H-representation of the polygon from its vertices (CCW)."""
    m = len(poly)
    if m == 1:
        x0, y0 = poly[0]
        return [(1.0, 0.0, x0), (-1.0, 0.0, -x0), (0.0, 1.0, y0), (0.0, -1.0, -y0)]
    out = []
    for k in range(m):
        (x0, y0), (x1, y1) = poly[k], poly[(k + 1) % m]
        a, b = y1 - y0, -(x1 - x0)
        s = abs(a) + abs(b)
        if s == 0:
            continue
        a, b = a / s, b / s
        out.append((a, b, a * x0 + b * y0))
    if m == 2:
        (x0, y0), (x1, y1) = poly
        dx, dy = x1 - x0, y1 - y0
        s = abs(dx) + abs(dy)
        dx, dy = dx / s, dy / s
        out.append((dx, dy, dx * x1 + dy * y1))
        out.append((-dx, -dy, -(dx * x0 + dy * y0)))
    return out


def _old_tight(halfplanes, poly):
    keep = []
    for a, b, c in halfplanes:
        tol = 1e-9 * (abs(c) + 1e-300)
        best = max(a * x + b * y - c for x, y in poly)
        if best >= -tol - 1e-9 * max(abs(a * x) + abs(b * y) for x, y in poly):
            keep.append((a, b, c))
    return keep


def rows_xy(acc_alpha, acc_beta, r):
    """|alpha x + beta y| <= r as half-planes in (x, y)."""
    out = []
    for al, be in zip(acc_alpha, acc_beta):
        out.append((al, be, r))
        out.append((-al, -be, r))
    return out


class PairsSolver:
    def __init__(self, acc_rows, jerk_rows):
        self.al = acc_rows.alpha
        self.be = acc_rows.beta
        self.cm, self.cc, self.cp = jerk_rows
        self.solves = 0
        self.time = 0.0

    def solve(self, acc, lim, ub):
        """acc (n-1,), lim (n-2,) linear jerk bounds |X_i| <= lim_i, 0 <= b <= ub."""
        n = ub.size
        self.solves += 1
        # K[i]: half-planes in (b_i, b_{i+1}) plus polygon vertices
        K = [None] * (n - 1)
        hp = rows_xy(self.al[n - 2], self.be[n - 2], acc[n - 2])
        poly = polygon(hp, ub[n - 2], ub[n - 1])
        K[n - 2] = (tight(hp, poly), poly)
        for i in range(n - 3, -1, -1):
            prev_hp, prev_poly = K[i + 1]
            if not prev_poly:
                prev_poly = [(0.0, 0.0)]  # b = 0 is always feasible: round-off lost it
                prev_hp = tight(None, prev_poly)
                self.empty = getattr(self, "empty", 0) + 1
            # constraints in (x, y, z) = (b_i, b_{i+1}, b_{i+2}) as (ax, ay, az, c)
            cons = [(0.0, a, b, c) for a, b, c in prev_hp]  # (y,z) in K_{i+1}
            j = i + 1  # jerk row at node i+1, index j-1 in the arrays
            if 1 <= j <= n - 2:
                L = lim[j - 1]
                for p, q, s in zip(self.cm[j - 1], self.cc[j - 1], self.cp[j - 1]):
                    cons.append((p, q, s, L))
                    cons.append((-p, -q, -s, L))
            up = [k for k in cons if k[2] > 0]
            dn = [k for k in cons if k[2] < 0]
            zero = [(k[0], k[1], k[3]) for k in cons if k[2] == 0]
            fm = list(zero)
            for u in up:
                for d in dn:
                    # u: ax x + ay y + az z <= c, az>0 ; d: az<0 -> combine with weights -d_az, u_az
                    wu, wd = -d[2], u[2]
                    fm.append((wu * u[0] + wd * d[0], wu * u[1] + wd * d[1], wu * u[3] + wd * d[3]))
            # also z range: y must have some z in [0, ub_{i+2}]: z>=0 and z<=ub are in prev box implicitly via polygon
            hp = fm + rows_xy(self.al[i], self.be[i], acc[i])
            # normalise
            hp2 = []
            for a, b, c in hp:
                s = abs(a) + abs(b)
                if s == 0:
                    continue
                hp2.append((a / s, b / s, c / s))
            poly = polygon(hp2, ub[i], ub[i + 1]) or [(0.0, 0.0)]
            K[i] = (tight(hp2, poly), poly)
        # forward greedy
        b = np.zeros(n)
        for i in range(0, n - 1):
            x = b[i]
            hp_i, poly_i = K[i]
            hi = ub[i + 1]
            lo = 0.0
            cons = list(hp_i)
            if i >= 1:
                L = lim[i - 1]
                for p, q, s in zip(self.cm[i - 1], self.cc[i - 1], self.cp[i - 1]):
                    # p b_{i-1} + q x + s y in [-L, L]
                    cons.append((0.0, s, L - p * b[i - 1] - q * x))
                    cons.append((0.0, -s, L + p * b[i - 1] + q * x))
            for a, bb, c in cons:
                rhs = c - a * x
                if bb > 0:
                    hi = min(hi, rhs / bb)
                elif bb < 0:
                    lo = max(lo, rhs / bb)
            b[i + 1] = max(min(hi, ub[i + 1]), 0.0) if hi >= lo - 1e-12 * (abs(lo) + 1e-300) else max(min(hi, ub[i + 1]), 0.0)
        return b


if __name__ == "__main__":
    import sys, time
    import numpy as np
    sys.path.insert(0, "/work/wt-i27b2/tests/coverage"); sys.path.insert(0, "/tmp/i34")
    from speed_curves import square_spiral, wiggle
    from skyquill.coverage.speed import plan_speed
    from skyquill.coverage.speed.curve import _derivs3
    from skyquill.coverage.speed.norms import component_limits, components
    from skyquill.coverage.speed.reach import acceleration_rows, ReachPass
    from skyquill.coverage.speed.rows import _speed_bounds, _end_caps, _Bounds, _ones, jerk_coefficients, _GridLP
    from skyquill.coverage.speed.profile import _duration
    from skyquill.coverage.speed.iteration import _initial_solve
    
    
    class Grid:
        def __init__(self, acc, rows, vb, q):
            self.passes = ReachPass(acc); self.pairs = PairsSolver(acc, rows); self.root = np.sqrt(vb[1:-1]); self.q = q
            self.time = 0.0; self.solves = 0
        def solve(self, r, ub, rough=False):
            n = ub.size; self.solves += 1
            acc = r[: n - 1]; jerk = r[self.q * 2 * (n - 1):][: n - 2]
            if not np.any(np.isfinite(jerk)):
                return self.passes.solve(acc, ub)
            return self.pairs.solve(acc, jerk / self.root, ub)
    
    curves = {"spiral": square_spiral(1.0), "wiggle": wiggle([(0,0),(1,0),(1,1),(0,1),(2,-1),(1,1),(1,0)])}
    ns = [int(x) for x in sys.argv[1:]]
    for name, curve in curves.items():
      for sides in (None,):
        for n in ns:
            sig = np.linspace(0, 1, n)
            c1, c2, c3 = _derivs3(curve, sig)
            ub, vb = _speed_bounds(c1, c2, 3.0, chord_error=None, period=0.02)
            p1, p2, p3 = (components(c, sides) for c in (c1, c2, c3))
            alim = component_limits(np.full(2, 5.0), sides); jlim = component_limits(np.full(2, 3.0), sides)
            acc = acceleration_rows(p1, p2, sig[1], alim)
            bounds = _Bounds(ub, vb, p1.shape[1], *_ones(n))
            cm, cc, cp = jerk_coefficients((p1, p2, p3))
            g = Grid(acc, (cm / jlim, cc / jlim, cp / jlim), vb, p1.shape[1])
            t = time.perf_counter()
            _end_caps(bounds.ub, p1, jlim)
            ref = g.solve(bounds.rows(None), bounds.cols())
            its = 0
            for _ in range(20):
                b = g.solve(bounds.rows(ref), bounds.cols()); its += 1
                ch = np.max(np.abs(np.sqrt(b) - np.sqrt(ref))) / np.sqrt(b.max())
                if ch < 1e-3: break
                ref = ref ** 0.35 * b ** 0.65
            ej0 = np.max(np.sqrt(b[1:-1]) * np.max(np.abs(cm/jlim * b[:-2, None] + cc/jlim * b[1:-1, None] + cp/jlim * b[2:, None]), axis=1))
            b = b * min(1.0, ej0 ** (-2/3))
            t = time.perf_counter() - t
            # exact-row check
            ej = np.max(np.sqrt(b[1:-1]) * np.max(np.abs(cm/jlim * b[:-2, None] + cc/jlim * b[1:-1, None] + cp/jlim * b[2:, None]), axis=1))
            ea = np.max(np.abs(acc.alpha * b[:-1, None] + acc.beta * b[1:, None]))
            dur = _duration(b, sig[1], jerk=True)
            lp = plan_speed(curve, 3.0, 5.0, 3.0, n=n, norm_sides=sides, max_excess=None, method="lp")
            print(f"{name} {sides} n={n}: pairs {dur:.4f}s ({t:.2f}s, its {its}, jerk ratio {ej:.6f}, acc ratio {ea:.6f}) lp {lp.duration:.4f}s gap {dur/lp.duration-1:+.5f}", flush=True)
