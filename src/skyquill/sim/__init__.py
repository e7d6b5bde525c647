"""Closed-loop flight simulation: quadrotor model, outer-loop controllers, disturbances."""

from skyquill.sim.bounds import MAX_SIM_STEPS, check_rest_ends
from skyquill.sim.contact import ContactBoard
from skyquill.sim.controllers import CascadePID, OuterLoop, RPTAxisGains, RPTController
from skyquill.sim.disturbances import Disturbances
from skyquill.sim.result import Flight
from skyquill.sim.simulate import simulate
from skyquill.sim.vehicle import Quadrotor

__all__ = [
    "MAX_SIM_STEPS",
    "CascadePID",
    "ContactBoard",
    "Disturbances",
    "Flight",
    "OuterLoop",
    "Quadrotor",
    "RPTAxisGains",
    "RPTController",
    "check_rest_ends",
    "simulate",
]
