"""Area coverage: regions, covering paths, time-optimal jerk-limited speed planning (paper 001)."""

#: The coverage a plan reaches unless the user asks for less (issue 16: Fields2Cover's
#: users' first complaint is the last swath missing), fraction of the region's area.
#: Here, not in :mod:`~skyquill.coverage.plan`, so that the CLI's help needs no planner import.
DEFAULT_MIN_COVERAGE = 0.99
