"""Dot painting on walls with contact-driven online estimation (paper 002).

``dots`` reads or makes paint dots, ``wall`` holds the frames and walls, ``mission`` flies a
reduced-model mission, ``estimate`` the estimators, ``order`` the painting orders, ``plot``
the figures (matplotlib imported lazily) and ``crosscheck`` compares the reduced contact model
with the closed-loop simulator.
"""

from __future__ import annotations

from skyquill.painting.dots import paper_drawing, read_dots_csv, stipple
from skyquill.painting.mission import (
    ContactModel,
    Localization,
    MissionConfig,
    MissionResult,
    run_mission,
)
from skyquill.painting.wall import Placement, Wall

__all__ = [
    "ContactModel",
    "Localization",
    "MissionConfig",
    "MissionResult",
    "Placement",
    "Wall",
    "paper_drawing",
    "read_dots_csv",
    "run_mission",
    "stipple",
]
