"""skyquill: aerial drawing and painting with quadrotors.

The public surface of the trajectory engine is re-exported here; see the
README for a tour.
"""

from skyquill.errors import InfeasibleError, InputError, SkyquillError, SolverError

__all__ = ["InfeasibleError", "InputError", "SkyquillError", "SolverError"]
__version__ = "0.1.0"
