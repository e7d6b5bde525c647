"""Area coverage: regions, covering paths, time-optimal jerk-limited speed planning (paper 001)."""
