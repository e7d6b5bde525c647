"""skyquill: aerial drawing and painting with quadrotors.

The public surface of the trajectory engine is re-exported here; see the
documentation site (``docs/``, ``make docs``) for a tour.
"""

from importlib.metadata import version

from skyquill.errors import InfeasibleError, InputError, SkyquillError, SolverError

__all__ = ["InfeasibleError", "InputError", "SkyquillError", "SolverError"]
# One version, pyproject.toml's, as installed (what ``skyquill --version`` prints).
__version__ = version("skyquill")
