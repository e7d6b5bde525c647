"""Optimal time segmentation (paper 000 §5.4, eqs. 55-56) with an analytic gradient.

The point times of a smoothing problem are moved to lower its optimal cost
(plus a price on the total time), by gradient descent on the segment
durations. One module per job:

* :mod:`.problems` -- the problem factory ``times -> SmoothingProblem``
  (:func:`point_fit_factory`) and its contract;
* :mod:`.multipliers` -- the solve's duals in the shape the gradient needs;
* :mod:`.gradient` -- the time gradient by the envelope theorem
  (:func:`time_gradient`);
* :mod:`.finite_difference` -- the paper's finite differences, the reference
  (:func:`finite_difference_gradient`);
* :mod:`.descent` -- the search (:func:`resegment`);
* :mod:`.results` -- :class:`TimeGradient`, :class:`ResegmentResult`.
"""

from skyquill.optimize.resegment.descent import resegment
from skyquill.optimize.resegment.finite_difference import finite_difference_gradient
from skyquill.optimize.resegment.gradient import time_gradient
from skyquill.optimize.resegment.problems import ProblemFactory, point_fit_factory
from skyquill.optimize.resegment.results import ResegmentResult, TimeGradient

__all__ = [
    "ProblemFactory",
    "ResegmentResult",
    "TimeGradient",
    "finite_difference_gradient",
    "point_fit_factory",
    "resegment",
    "time_gradient",
]
