"""The path being timed: its protocol, checked evaluation, and reparametrisation."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from scipy.interpolate import BSpline

from skyquill.errors import InputError
from skyquill.validation import FloatArray


class PathCurve(Protocol):
    """A parametric path ``C(u)``, ``u in [0, 1]``, with derivatives ``nu``."""

    def __call__(self, x: Any, nu: int = ...) -> Any:
        """Evaluate the ``nu``-th derivative at ``x``."""
        ...


def _eval(curve: PathCurve, u: FloatArray, nu: int) -> FloatArray:
    """Evaluate ``curve(u, nu=nu)`` as an ``(len(u), d)`` float array."""
    try:
        out = np.asarray(curve(u, nu=nu), dtype=np.float64)
    except Exception as exc:
        raise InputError(f"curve(u, nu={nu}) failed: {exc}") from exc
    if out.ndim == 1 and out.shape[0] == u.shape[0]:
        out = out[:, None]
    if out.ndim != 2 or out.shape[0] != u.shape[0]:
        raise InputError(
            f"curve(u, nu={nu}) must return shape (len(u), d), got {out.shape} for len(u)={u.size}"
        )
    if not np.all(np.isfinite(out)):
        raise InputError(f"curve(u, nu={nu}) returned non-finite values")
    return out


@dataclass(frozen=True, eq=False)
class _Reparam:
    """``C(g(sigma))``: the path on the planning parameter ``sigma``, by the chain rule."""

    curve: PathCurve
    g: BSpline

    def __call__(self, x: Any, nu: int = 0) -> FloatArray:
        """Evaluate the ``nu``-th derivative (``nu <= 3``) with respect to ``sigma``."""
        s = np.atleast_1d(np.asarray(x, dtype=np.float64))
        u = np.clip(np.asarray(self.g(s), dtype=np.float64), 0.0, 1.0)
        c = [_eval(self.curve, u, k) for k in range(nu + 1)]
        if nu == 0:
            return c[0]
        g1, g2, g3 = (np.asarray(self.g(s, k), dtype=np.float64)[:, None] for k in (1, 2, 3))
        if nu == 1:
            return c[1] * g1
        if nu == 2:
            return c[2] * g1**2 + c[1] * g2
        if nu == 3:
            return c[3] * g1**3 + 3.0 * c[2] * g1 * g2 + c[1] * g3
        raise InputError(f"derivative order {nu} > 3 of a reparametrised path")

    def derivs(self, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """First three derivatives at once (one evaluation of ``C`` and ``g`` per order)."""
        u = np.clip(np.asarray(self.g(x), dtype=np.float64), 0.0, 1.0)
        c1, c2, c3 = (_eval(self.curve, u, k) for k in (1, 2, 3))
        g1, g2, g3 = (np.asarray(self.g(x, k), dtype=np.float64)[:, None] for k in (1, 2, 3))
        return (
            c1 * g1,
            c2 * g1**2 + c1 * g2,
            c3 * g1**3 + 3.0 * c2 * g1 * g2 + c1 * g3,
        )


def _derivs3(path: PathCurve, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """First, second and third derivative of ``path`` at ``x``."""
    if isinstance(path, _Reparam):
        return path.derivs(x)
    c1, c2, c3 = (_eval(path, x, k) for k in (1, 2, 3))
    return c1, c2, c3
