"""Drone shows: checked as one (``skyquill check``) and planned from a script (``skyquill show``).

Validation, for any set of trajectories:

* :mod:`.load` -- the drones of plan directories, trajectory files and ``.skyc`` archives;
* :mod:`.motion` -- a drone as exact polynomial pieces on the show clock, with speed bounds;
* :mod:`.separation` -- the closest approach of every pair, guaranteed between samples;
* :mod:`.geofence` -- a polygon in the show's metres and a ceiling;
* :mod:`.limits` -- speeds, acceleration, altitude and geofence per drone, sampled densely;
* :mod:`.report` -- violations, measured extremes, the report;
* :mod:`.check` -- all of it on one show.

Planning (``docs/show-format.md``):

* :mod:`.script` -- the TOML show script, validated, with its ceilings;
* :mod:`.formation` -- points on a shape (text, SVG, grid, circle) and the take-off pads;
* :mod:`.transition` -- assignment, waves (:mod:`.waves`, :mod:`.moves`), depth layers, proof;
  :mod:`.route` -- to and from the pads, through a curtain where that is shorter;
* :mod:`.writing` -- a ``write`` scene's light painting on sky boards;
* :mod:`.build` -- every scene on one clock: each drone's flight and its light windows;
* :mod:`.lights` -- colours per drone or per stroke from a palette.
"""

from skyquill.show.check import MIN_DISTANCE_M, check_show, require_separation, separation_of
from skyquill.show.geofence import Geofence, read_geofence
from skyquill.show.limits import ShowLimits
from skyquill.show.load import ShowDrone, load_show
from skyquill.show.report import Measured, ShowReport, Violation
from skyquill.show.separation import Encounter, Separation, guaranteed_separation

__all__ = [
    "MIN_DISTANCE_M",
    "Encounter",
    "Geofence",
    "Measured",
    "Separation",
    "ShowDrone",
    "ShowLimits",
    "ShowReport",
    "Violation",
    "check_show",
    "guaranteed_separation",
    "load_show",
    "read_geofence",
    "require_separation",
    "separation_of",
]
