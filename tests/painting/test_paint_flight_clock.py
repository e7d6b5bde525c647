"""FlightClock: a lower bound of the painting flight's duration at every dot of the mission.

The bound lets ``skyquill paint`` refuse a ``trajectory.csv`` too long for its readers while
the mission is simulated. Checked here against what is delivered: the duration of the
trajectory :func:`~skyquill.painting.flight.painting_flight` builds from the whole mission.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from skyquill.cli.main import app
from skyquill.painting.flight import FlightClock, painting_flight
from skyquill.painting.mission import MissionConfig, run_mission
from skyquill.painting.wall import Placement, Wall


@settings(max_examples=8, deadline=None)
@given(
    dots=st.integers(1, 12),
    seed=st.integers(0, 2**16),
    false_contacts=st.sampled_from([0.0, 0.3]),
)
def test_the_clock_never_passes_the_flight_it_bounds(
    dots: int, seed: int, false_contacts: float
) -> None:
    rng = np.random.default_rng(seed)
    points = np.column_stack([rng.uniform(0.0, 2.0, dots), rng.uniform(0.5, 2.0, dots)])
    seen: list[float] = []
    clock = FlightClock(seen.append)
    result = run_mission(
        points,
        wall=Wall.flat(),
        truth=Placement(np.array([0.0, -1.1, 0.0]), np.radians(5.0)),
        config=MissionConfig(false_contact_rate=false_contacts),
        rng=np.random.default_rng(seed),
        flown=clock.add,
    )
    duration = painting_flight(result).trajectory.duration
    assert seen == sorted(seen) and len(seen) >= dots  # told after every dot, never less
    # every leg but the last flight home is counted: a bound, and a close one
    assert 0.5 * duration < clock.at_least_s <= duration * (1 + 1e-12)


def test_a_painting_too_long_for_its_file_is_refused_while_simulated(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    dots = tmp_path / "dots.csv"
    table = np.column_stack([rng.uniform(0.0, 3.0, 3000), rng.uniform(0.0, 3.0, 3000)])
    np.savetxt(dots, table, delimiter=",", header="x,z", comments="")
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["paint", str(dots), "--rate", "2000", "--out", str(out)])
    assert result.exit_code == 2
    message = " ".join(result.output.split())
    assert "--rate: got 2000 Hz over a flight of at least" in message
    assert "expected at most 1,000,000 rows in trajectory.csv" in message
    assert not out.exists()
    # stopped well before the 3,000 dots: about 6 s of flight a dot, 500 s at most here
    assert float(message.split("at least ")[1].split(" s")[0]) < 520.0
