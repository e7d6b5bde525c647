"""skyquill: aerial drawing and painting with quadrotors.

The public surface of the trajectory engine is re-exported here; see the
documentation site (``docs/``, ``make docs``) for a tour.
"""

from skyquill.errors import InfeasibleError, InputError, SkyquillError, SolverError

__all__ = ["InfeasibleError", "InputError", "SkyquillError", "SolverError"]


def __getattr__(name: str) -> str:
    """``__version__``: pyproject.toml's, as installed (what ``skyquill --version`` prints).

    Looked up on first use, not at import: ``importlib.metadata`` takes a noticeable
    time to import, and the console script (:mod:`skyquill.cli.entry`) can only turn
    Ctrl+C into one line once this package is imported.
    """
    if name == "__version__":
        from importlib.metadata import version

        return version("skyquill")
    raise AttributeError(f"module 'skyquill' has no attribute {name!r}")
