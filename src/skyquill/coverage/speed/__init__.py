"""Time-optimal speed planning along a parametric path by linear programming.

Implements the speed planner of §2.1 and the second-order Taylor interpolator
of §2.2 of the coverage-path paper (``001_61beb0e01a19013a``): the path
``C(u)``, ``u in [0, 1]``, is sampled at ``n`` grid points and the decision
variable at each point is ``b_i = u_dot_i**2``.  The problem

    maximise   sum_i b_i
    subject to |C'(u_i)|**2 b_i <= vmax**2                    (speed)
               |C'|**2 b_i <= 8 rho eps / T**2                 (chord error)
               |C''_k b + 0.5 C'_k b'| <= amax_k               (acceleration)
               sqrt(b) |C'''_k b + 1.5 C''_k b' + 0.5 C'_k b''| <= jmax_k
               b_0 = b_{n-1} = 0

is linear in ``b`` except for the ``sqrt(b)`` factor of the jerk (the paper's
expression drops it); it is linearised at the previous iterate ("pseudo-jerk")
and the LP re-solved with HiGHS.  With highspy installed one HiGHS model is
built once: the linearisation point only changes row bounds
(``|X_i| <= jmax / sqrt(b_ref_i)``), so every re-solve is a dual-simplex hot
start from the previous basis (tens of pivots instead of a cold solve);
without it each LP goes to ``scipy.optimize.linprog``.

Discretisation choices (the grid LP is otherwise optimistic):

* Optionally (``grid="adaptive"``) the grid is not uniform in ``u``: the LP
  runs on ``C(g(sigma))`` with a uniform ``sigma`` grid, ``g`` chosen so that
  half of the points are uniform in arc length and half uniform in an
  estimated traversal time (crowding the rest ends and tight curls, where a
  spiral winding into its centre has features short relative to a uniform
  ``u`` grid).  ``SpeedPlan.u``/``b`` and ``Setpoints.u`` stay in ``u``.
* Between grid points ``b`` is taken piecewise linear in ``u`` (constant
  ``u_ddot``); the acceleration constraint is imposed for every interval at
  both ends with that interval's slope.  The duration is the
  exact time of this model, ``dt = 2 du / (sqrt(b_i) + sqrt(b_{i+1}))``, which
  stays finite at the rest-to-rest ends where a trapezoid of ``1/sqrt(b)``
  diverges/under-estimates.
* With a jerk limit the rest ends behave like ``b ~ s**(4/3)``; the first and
  last interior ``b`` are capped so that the acceleration builds up from zero
  at <= jmax, ``w = b**(3/4)`` (regular there) is represented by a cubic
  B-spline *quasi-interpolant* (no ringing at the kinks of the optimum, unlike
  an interpolating spline), and the §2.2 Taylor recursion gets a third-order
  term so that it leaves the rest start (the paper injects a small speed).
  The pseudo-jerk iteration alternates between over- and under-estimates with
  shrinking amplitude; the last LP is a *certification* LP with ``sqrt(B)`` as
  linearisation point and ``b <= B`` (``B`` the element-wise max of the last
  two iterates), so that ``sqrt(b) |X| <= sqrt(B) |X| <= jmax`` holds exactly
  at the grid points.
* The grid constraints do not bound the interpolated profile between the
  nodes.  A *local refinement* evaluates the chain-rule speed/acceleration/jerk
  of the interpolant at the resolution of :meth:`SpeedPlan.verify`, divides
  the limits of the nodes around every excess by ``(1 + excess)**r`` (``r``
  the round, 1, 2, ...) and re-solves from the previous basis, until the
  excess is below ``max_excess`` (2 % by default).  Unlike the global
  ``safety`` factor (still available) this keeps the speed elsewhere.

With ``norm_sides`` the acceleration and jerk limits are Euclidean norms held
through an inscribed regular polygon (:mod:`.norms`) instead of per axis.

Modules, one job each: :mod:`.curve` (the path, checked evaluation,
reparametrisation), :mod:`.profile` (:class:`SpeedPlan`, the interpolated
profile and its setpoints), :mod:`.rows` (the grid LP's rows and bounds, on
:class:`skyquill.solvers.lp.LinearProgram`), :mod:`.norms` (per-axis or norm
limits), :mod:`.iteration` (pseudo-jerk iteration, certification,
refinement), :mod:`.grid` (the adaptive grid), :mod:`.validate` and
:mod:`.plan` (:func:`plan_speed`).
"""

from skyquill.coverage.speed.curve import PathCurve
from skyquill.coverage.speed.plan import plan_speed
from skyquill.coverage.speed.profile import Setpoints, SpeedPlan

__all__ = ["PathCurve", "Setpoints", "SpeedPlan", "plan_speed"]
