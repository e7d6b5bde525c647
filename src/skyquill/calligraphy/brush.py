"""The calligraphy brush: where it hangs, how far it gives, how wide it writes.

Paper 000 §2 (its Fig. 3): the brush hangs below the vehicle on a shaft through
a linear bearing, so pressing it into the board slides the shaft instead of
pushing the vehicle, and it turns freely about its axis. The paper gives no
numbers for the bearing or the bristles; the defaults here are those of a
large writing brush on its 0.5 m characters and are stated, not measured.

The footprint is the geometric model of a conical tuft (Lam and Yam's brush
footprint, paper 000's ref. [18], reduced to its width): a tip pressed ``d``
into the board leaves a mark ``tip_width_m + 2 d tan(half_angle)`` wide, up to
the tuft's diameter. So the pressing depth sets the stroke width, and a plan
that holds the depth holds the width.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skyquill.errors import InputError
from skyquill.validation import FloatArray, as_float

#: Longest brush accepted, m: the tip is modelled as rigid along the thrust
#: axis (``L (e_z - b3)``); a longer "brush" is a tether that swings on its own.
MAX_BRUSH_LENGTH_M = 2.0


@dataclass(frozen=True)
class Brush:
    """A rigid brush along the thrust axis, on a linear bearing (SI units).

    Attributes
    ----------
    length_m
        Vehicle centre to brush tip, m, along ``-b3`` (the thrust axis), at
        most :data:`MAX_BRUSH_LENGTH_M`.
    travel_m
        How far the tip can be pressed into the board before the bearing runs
        out, m: deeper, the board pushes the vehicle.
    press_depth_m
        How deep the plan presses the tip while the pen is down, m, in
        ``(0, travel_m)``; it sets the stroke width (:meth:`ink_width`).
    tip_width_m
        Width of the mark of the barely touching tip, m.
    spread
        Widening of the mark per metre pressed: ``2 tan(half_angle)`` of the
        tuft's cone (2.0: a 45 deg half-angle).
    max_width_m
        The tuft's diameter, m: the widest mark it leaves.
    stiffness_n_per_m, damping_ns_per_m
        The force on the vehicle per metre pressed, and per m/s: the bearing's
        light return spring and its friction. Paper 000's bearing is there to
        keep this force small: its outer loop (``w_n`` ~ 2 rad/s) would give
        way ~0.2 m per newton. At 2 N/m a 5 mm press pushes with 0.01 N and the
        vehicle gives way ~2 mm (the simulated ink is 0.8 of the planned width).
    """

    length_m: float = 0.3
    travel_m: float = 0.02
    press_depth_m: float = 0.005
    tip_width_m: float = 0.002
    spread: float = 2.0
    max_width_m: float = 0.03
    stiffness_n_per_m: float = 2.0
    damping_ns_per_m: float = 0.1

    def __post_init__(self) -> None:
        for name in ("length_m", "tip_width_m", "spread", "damping_ns_per_m"):
            as_float(f"brush {name}", getattr(self, name), nonneg=True)
        for name in ("travel_m", "press_depth_m", "max_width_m", "stiffness_n_per_m"):
            as_float(f"brush {name}", getattr(self, name), positive=True)
        if self.length_m > MAX_BRUSH_LENGTH_M:
            raise InputError(
                f"brush length_m: got {self.length_m:g} m, expected at most "
                f"{MAX_BRUSH_LENGTH_M:g} m (the brush is modelled as rigid)"
            )
        if self.press_depth_m >= self.travel_m:
            raise InputError(
                f"brush press_depth_m: got {self.press_depth_m:g} m, expected less than the "
                f"bearing's travel_m = {self.travel_m:g} m"
            )
        if self.tip_width_m > self.max_width_m:
            raise InputError(
                f"brush tip_width_m: got {self.tip_width_m:g} m, expected at most "
                f"max_width_m = {self.max_width_m:g} m"
            )

    def ink_width(self, depth_m: FloatArray | float) -> FloatArray:
        """Width of the mark (m) of a tip pressed ``depth_m`` (m, any shape) into the board.

        0 where the tip does not touch (``depth <= 0``).
        """
        depth = np.asarray(depth_m, dtype=float)
        width = np.minimum(self.tip_width_m + self.spread * depth, self.max_width_m)
        return np.where(depth > 0.0, width, 0.0)

    @property
    def stroke_width_m(self) -> float:
        """Width of the strokes as planned (at :attr:`press_depth_m`), m."""
        return float(self.ink_width(self.press_depth_m))
