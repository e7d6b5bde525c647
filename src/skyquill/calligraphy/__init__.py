"""Writing and light painting on boards (paper 000): missions, brushes, ink, several drones.

* :mod:`~skyquill.calligraphy.board`: the boards (horizontal, wall, sky) and their frames;
* :mod:`~skyquill.calligraphy.mission`: one writing flight, take-off to landing, as one
  smoothing problem (:func:`~skyquill.calligraphy.mission.plan_writing`);
* :mod:`~skyquill.calligraphy.brush`, :mod:`~skyquill.calligraphy.fidelity`,
  :mod:`~skyquill.calligraphy.ink`: the brush on its bearing, the plan's distance from the
  input and its predicted ink, the simulated ink of a flight;
* :mod:`~skyquill.calligraphy.budget`: a vehicle's upload budget (``--target crazyflie``);
* :mod:`~skyquill.calligraphy.show`, :mod:`~skyquill.calligraphy.artwork`: several drones,
  boards side by side, sky grids and drawings split among drones;
* :mod:`~skyquill.calligraphy.distortion`: how a light painting looks from off its axis.
"""
