"""The studio's JSON API with FastAPI's TestClient: plans, refusals, limits, security.

Every plan here is real (plan_writing, the closed-loop simulation and the
exporters) and is checked against an independent reading of what it returned:
the CSV parsed back, the Crazyswarm uploads read and evaluated, the .skyc
show validated by skyquill's own reader.
"""

from __future__ import annotations

import csv
import io
import json
import time
import zipfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient
from studio_fakes import crashing_planner, refusing_planner, slow_planner

from skyquill.export.crazyflie.csv_file import read_crazyswarm
from skyquill.export.skybrush.skyc_file import read_show_json
from skyquill.io.points import TRAJECTORY_COLUMNS
from skyquill.studio import JobManager, create_app
from skyquill.studio.app import MAX_BODY_BYTES
from skyquill.studio.models import MAX_POINTS

#: Two strokes, as the page sends them (canvas px, y up): a "V" and a bar.
TWO_STROKES: dict[str, Any] = {
    "strokes": [
        [[112, 420], [196, 280], [280, 140], [364, 280], [448, 420]],
        [[140, 308], [280, 325], [420, 308]],
    ],
    "t": [[0.0, 0.1, 0.2, 0.3, 0.4], [1.0, 1.1, 1.2]],
}
#: A 5 cm bar with a jerk limit of 1 mm/s^3: infeasible even after every stretch.
INFEASIBLE: dict[str, Any] = {"strokes": [[[0, 0], [100, 0]]], "size_m": 0.05, "jmax": 0.001}


def _client(**jobs: Any) -> TestClient:
    return TestClient(create_app(jobs=JobManager(**jobs)))


@pytest.fixture(scope="module")
def client() -> Iterator[TestClient]:
    with _client(time_limit_s=60.0) as c:
        yield c


@pytest.fixture(scope="module")
def planned(client: TestClient) -> dict[str, Any]:
    """The two strokes planned and flown, synchronously."""
    answer = client.post("/api/plan?wait=true", json=TWO_STROKES)
    assert answer.status_code == 200, answer.text
    job: dict[str, Any] = answer.json()
    return job


def _wait(client: TestClient, url: str, timeout: float = 30.0) -> list[dict[str, Any]]:
    """Every status of a job polled until it ends."""
    seen, deadline = [], time.monotonic() + timeout
    while time.monotonic() < deadline:
        seen.append(client.get(url).json())
        if seen[-1]["state"] in ("done", "error", "cancelled"):
            return seen
        time.sleep(0.05)
    raise AssertionError(f"job {url} did not end in {timeout} s: {seen[-1]}")


def test_a_plan_of_two_strokes(planned: dict[str, Any]) -> None:
    """The answer holds the planned path, the curves, the flight and every file."""
    assert planned["state"] == "done" and planned["progress"] == 1.0
    result = planned["result"]
    (drone,) = result["drones"]
    n = len(drone["t"])
    assert n > 100
    assert len(drone["path"]) == len(drone["pen"]) == len(drone["speed"]) == n
    assert len(drone["flight"]) == n and drone["ink"]
    assert set(drone["pen"]) == {0, 1}
    assert [len(s) for s in drone["input"]] == [5, 3]
    # The curves the page plots respect the limits (to the 0.1 mm/s rounding).
    limits = result["limits"]
    assert max(drone["speed"]) <= limits["vmax"] + 1e-4
    assert max(drone["acc"]) <= limits["amax"] + 1e-4
    assert max(drone["jerk"]) <= limits["jmax"] + 1e-4
    assert all(c["relative_excess"] <= 1e-9 for c in drone["checks"])
    # Pen down, the (swung) tip presses into the board within the brush's travel (2 cm)
    # and lies within 1 % of 0.5 m of the input.
    down = np.array(drone["path"])[np.array(drone["pen"]) == 1]
    assert down[:, 2].min() >= -0.02 and down[:, 2].max() < 2e-3
    assert drone["deviation_max_m"] <= 0.005 + 1e-9
    assert drone["flight_rmse_m"] < 0.02
    # Any drone (the default vehicle): the setpoints and the summary, nothing of one vehicle.
    assert [f["kind"] for f in result["files"]] == ["setpoints.csv", "summary.json"]
    assert result["target"] == "generic" and result["notes"] == []


def test_the_flight_measures_its_ink(planned: dict[str, Any]) -> None:
    """The simulated ink against the input (calligraphy.ink): in-plane distance and IoU."""
    (drone,) = planned["result"]["drones"]
    assert 0.0 <= drone["ink_max_deviation_m"] < 0.05
    assert 0.0 < drone["ink_iou"] <= 1.0


@pytest.fixture(scope="module", params=["crazyflie", "skybrush"])
def planned_for(client: TestClient, request: pytest.FixtureRequest) -> dict[str, Any]:
    """The two strokes planned for a vehicle (not flown)."""
    body = TWO_STROKES | {"target": request.param, "fly": False}
    answer = client.post("/api/plan?wait=true", json=body)
    assert answer.status_code == 200, answer.text
    job: dict[str, Any] = answer.json()
    return job


def test_the_files_read_back(
    client: TestClient, planned_for: dict[str, Any], tmp_path: Path
) -> None:
    """Each vehicle's files: the Crazyflie's uploads, the Skybrush show, read back."""
    result = planned_for["result"]
    files = {f["kind"]: client.get(f["url"]) for f in result["files"]}
    assert all(r.status_code == 200 for r in files.values())
    assert "attachment" in files["setpoints.csv"].headers["content-disposition"]
    rows = list(csv.reader(io.StringIO(files["setpoints.csv"].text)))
    assert rows[0] == [*TRAJECTORY_COLUMNS, "yaw", "pen"]
    table = np.array(rows[1:], dtype=float)
    assert np.all(np.isfinite(table))
    (note,) = result["notes"]
    assert note.startswith("The ") and "read back as" in note
    if result["target"] == "crazyflie":  # planned for its uploads: the download exists
        (swarm,) = [n for n in files if n.startswith("crazyswarm")]
        assert "show.skyc" not in files
        with zipfile.ZipFile(io.BytesIO(files[swarm].content)) as archive:
            archive.extractall(tmp_path)
        parts = sorted(tmp_path.glob("crazyswarm*.csv"))
        assert parts and all(read_crazyswarm(part).n_pieces <= 31 for part in parts)
    else:
        assert not any(n.startswith("crazyswarm") for n in files)
        (tmp_path / "show.skyc").write_bytes(files["show.skyc"].content)
        show = read_show_json(tmp_path / "show.skyc")
        assert len(show["swarm"]["drones"]) == 1
    summary = json.loads(files["summary.json"].text)
    assert summary["drones"][0]["max_excess"] <= 1e-9


def test_a_plan_reports_progress_while_it_runs(client: TestClient) -> None:
    """POST answers 202 at once; polling shows the stages, then the result."""
    answer = client.post("/api/plan", json=TWO_STROKES | {"fly": False})
    assert answer.status_code == 202
    accepted = answer.json()
    assert accepted["url"] == f"/api/jobs/{accepted['job_id']}"
    seen = _wait(client, accepted["url"])
    assert seen[-1]["state"] == "done", seen[-1]["message"]
    progress = [s["progress"] for s in seen]
    assert progress == sorted(progress) and progress[-1] == 1.0
    assert seen[-1]["result"]["drones"][0]["flight"] == []


def test_typed_text_for_two_drones(client: TestClient) -> None:
    """Text is shared out word by word; two boards, one setpoint file each, in a zip."""
    answer = client.post("/api/plan?wait=true", json={"text": "L T", "drones": 2, "fly": False})
    assert answer.status_code == 200, answer.text
    result = answer.json()["result"]
    assert result["source"] == "text" and len(result["drones"]) == 2
    assert result["drones"][1]["board_u0"] > result["size_m"]
    assert result["min_separation_m"] >= 1.0
    files = {f["kind"]: f for f in result["files"]}
    archive = zipfile.ZipFile(io.BytesIO(client.get(files["setpoints.zip"]["url"]).content))
    assert sorted(archive.namelist()) == ["setpoints_1.csv", "setpoints_2.csv"]


@pytest.mark.parametrize(
    ("body", "message"),
    [
        (TWO_STROKES | {"vmax": -1}, "vmax: got -1, expected greater than 0"),
        (TWO_STROKES | {"drones": 9}, "drones: got 9, expected less than or equal to 8"),
        (TWO_STROKES | {"board": "ceiling"}, "board: got 'ceiling', expected 'horizontal' or"),
        (TWO_STROKES | {"text": "Hi"}, "got both of strokes and text, expected exactly one"),
        ({}, "got neither of strokes and text, expected exactly one"),
        ({"text": "Hi", "colour": "red"}, "colour: got an unknown field"),
        ({"strokes": [[[0, 0]]]}, "strokes[0]: got [[0, 0]], expected list should have at least 2"),
        ({"strokes": [[[0, 0], ["a", 1]]]}, "strokes[0][1][0]: got 'a', expected a valid number"),
        ({"strokes": [[[0, 0], [0, 0]]]}, "stroke 0: got 2 points all equal to (0, 0)"),
        (
            {"strokes": [[[0, 0], [1, 1]]], "t": [[1.0, 0.5]]},
            "got t[0] = 1 followed by t[1] = 0.5, expected strictly increasing times",
        ),
        ({"text": "é"}, "text: got 'é' (U+00E9) in 'é', expected characters the studio can"),
        ({"text": "Hi", "drones": 3}, "drones: got 3 drones for 1 character or word"),
        ([1, 2], "request: got [1, 2], expected a valid dictionary"),
    ],
)
def test_a_malformed_body_is_422_with_a_clear_message(
    client: TestClient, body: Any, message: str
) -> None:
    answer = client.post("/api/plan", json=body)
    assert answer.status_code == 422, answer.text
    assert message in answer.json()["detail"]


@pytest.mark.parametrize(
    ("raw", "message"),
    [
        (b'{"text": ', "body: malformed JSON (Expecting value), expected a JSON object"),
        (b'{"text": "Hi", "vmax": NaN}', "vmax: got nan, expected a finite number"),
        (b'{"text": "Hi", "jmax": Infinity}', "jmax: got inf, expected a finite number"),
    ],
)
def test_malformed_json_is_422_with_a_clear_message(
    client: TestClient, raw: bytes, message: str
) -> None:
    answer = client.post("/api/plan", content=raw, headers={"content-type": "application/json"})
    assert answer.status_code == 422
    assert answer.json()["detail"] == message


def test_an_oversized_body_is_413(client: TestClient) -> None:
    """Declared too long, or streamed without a length: 413 before it is all read."""
    big = b" " * (MAX_BODY_BYTES + 1)
    declared = client.post("/api/plan", content=big, headers={"content-type": "application/json"})
    assert declared.status_code == 413
    assert "larger than 1,000,000 bytes" in declared.json()["detail"]

    def chunks() -> Iterator[bytes]:
        for _ in range(11):
            yield b" " * 100_000

    streamed = client.post(
        "/api/plan", content=chunks(), headers={"content-type": "application/json"}
    )
    assert streamed.status_code == 413


def test_too_many_points_under_the_byte_limit_is_422(client: TestClient) -> None:
    stroke = [[float(i), float(i % 7)] for i in range(4_000)]
    body = {"strokes": [stroke] * 6}
    assert len(json.dumps(body)) < MAX_BODY_BYTES
    answer = client.post("/api/plan", json=body)
    assert answer.status_code == 422
    assert f"got 24000 points in all, expected at most {MAX_POINTS}" in answer.json()["detail"]


def test_an_infeasible_request_is_a_clear_message_not_a_500(client: TestClient) -> None:
    """A jerk limit of 1 mm/s^3 cannot be met: 422 with the limits named (the job: error)."""
    answer = client.post("/api/plan?wait=true", json=INFEASIBLE)
    assert answer.status_code == 422
    detail = answer.json()["detail"]
    assert "jerk" in detail and "0.001" in detail
    assert (
        "infeasible" in detail
        or "could not plan drone 1's flight within" in detail
        or "expected within the tolerance" in detail
    )


def test_unknown_jobs_and_files_are_404(client: TestClient, planned: dict[str, Any]) -> None:
    job = planned["job_id"]
    assert client.get(f"/api/jobs/{'0' * 32}").status_code == 404
    plan_id = planned["result"]["plan_id"]
    assert client.get(f"/api/jobs/{job}/files/skyquill-{plan_id}-flight.csv").status_code == 404
    assert client.get(f"/api/jobs/{job}/files/setpoints.csv").status_code in (404, 422)
    # Anything that is not a job id or a file name is refused before any lookup.
    assert client.get("/api/jobs/..%2F..%2Fetc").status_code in (404, 422)
    assert client.get(f"/api/jobs/{job}/files/..%2Fsetpoints.csv").status_code in (404, 422)
    assert client.get(f"/api/jobs/{job}/files/%2Fetc%2Fpasswd").status_code in (404, 422)


def test_the_page_openapi_and_security_headers(client: TestClient) -> None:
    page = client.get("/")
    assert page.status_code == 200 and "skyquill studio" in page.text
    assert "default-src 'self'" in page.headers["content-security-policy"]
    for asset in ("/static/studio.js", "/static/studio.css"):
        assert client.get(asset).status_code == 200
    schema = client.get("/openapi.json").json()
    assert "/api/plan" in schema["paths"] and "PlanRequest" in schema["components"]["schemas"]
    assert client.get("/docs").status_code == 200
    # No CORS: another origin's script gets no permission to read the answers.
    answer = client.get("/openapi.json", headers={"Origin": "http://evil.example"})
    assert "access-control-allow-origin" not in answer.headers


def test_a_foreign_host_header_is_refused() -> None:
    """Bound to loopback, the studio answers only to loopback names (no DNS rebinding)."""
    app = create_app(allowed_hosts=["127.0.0.1", "localhost"])
    with TestClient(app, base_url="http://127.0.0.1") as client:
        assert client.get("/").status_code == 200
        assert client.get("/", headers={"host": "evil.example"}).status_code == 400


def test_a_plan_over_the_time_limit_is_stopped() -> None:
    with _client(time_limit_s=1.0, planner=slow_planner) as client:
        start = time.monotonic()
        answer = client.post("/api/plan?wait=true", json=TWO_STROKES)
        assert answer.status_code == 422
        assert "longer than the studio's limit of 1 s" in answer.json()["detail"]
        assert time.monotonic() - start < 5.0
        assert client.get("/").status_code == 200


def test_a_crashing_planner_fails_its_job_not_the_server() -> None:
    with _client(planner=crashing_planner) as client:
        accepted = client.post("/api/plan", json=TWO_STROKES).json()
        end = _wait(client, accepted["url"])[-1]
        assert end["state"] == "error"
        assert "planning crashed (signal SIGSEGV)" in end["message"]
        assert client.get("/").status_code == 200


def test_too_many_plans_at_once_is_429() -> None:
    with _client(max_active=1, planner=slow_planner, time_limit_s=5.0) as client:
        assert client.post("/api/plan", json=TWO_STROKES).status_code == 202
        busy = client.post("/api/plan", json=TWO_STROKES)
        assert busy.status_code == 429
        assert "busy" in busy.json()["detail"] and busy.headers["retry-after"] == "5"


def test_a_refused_job_says_why_and_old_jobs_are_forgotten() -> None:
    """skyquill's errors end a polled job as "error" with the message; memory stays bounded."""
    with _client(planner=refusing_planner, max_kept=2) as client:
        urls = []
        for _ in range(3):
            accepted = client.post("/api/plan", json=TWO_STROKES)
            assert accepted.status_code == 202
            urls.append(accepted.json()["url"])
            end = _wait(client, urls[-1])[-1]
            assert end["state"] == "error"
            assert end["message"] == "limits: nothing can be planned here (a test planner)"
        assert client.get(urls[0]).status_code == 404  # the oldest, forgotten
        assert [client.get(u).status_code for u in urls[1:]] == [200, 200]


def test_every_download_carries_the_plan_id(client: TestClient, planned: dict[str, Any]) -> None:
    """One id per plan: in each file's name, its Content-Disposition and summary.json."""
    result = planned["result"]
    plan_id = result["plan_id"]
    assert len(plan_id) == 12 and planned["job_id"].startswith(plan_id)
    for file in result["files"]:
        assert file["name"] == f"skyquill-{plan_id}-{file['kind']}"
        answer = client.get(file["url"])
        assert (
            f'filename="skyquill-{plan_id}-{file["kind"]}"' in answer.headers["content-disposition"]
        )
    summary_url = next(f["url"] for f in result["files"] if f["kind"] == "summary.json")
    assert client.get(summary_url).json()["plan_id"] == plan_id


def test_the_summary_records_the_request_and_the_simulated_flight(
    client: TestClient, planned: dict[str, Any]
) -> None:
    """summary.json says what was asked (limits, board, size, drones, options) and what flew."""
    result = planned["result"]
    summary_url = next(f["url"] for f in result["files"] if f["kind"] == "summary.json")
    summary = client.get(summary_url).json()
    assert summary["request"] == {
        "board": "horizontal",
        "size_m": 0.5,
        "vmax": 1.0,
        "amax": 2.0,
        "jmax": 10.0,
        "drones": 1,
        "fly": True,
        "target": "generic",
        "min_altitude_m": 0.3,
        "strokes": 2,
        "points": 8,
        "timestamps": True,
    }
    # each download as its vehicle plays it (issue 26): the page's verdict comes from these
    assert set(summary["exports"]) == {kind for kind, _ in result_kinds(result)}
    assert all("as_played" in e or "refused" in e for e in summary["exports"].values())
    (flown,) = summary["simulated_flight"]
    (drone,) = result["drones"]
    assert flown["duration_s"] == drone["duration_s"]
    assert flown["path_rmse_m"] == drone["flight_rmse_m"]
    assert flown["ink_max_deviation_m"] == drone["ink_max_deviation_m"]
    assert flown["ink_iou"] == drone["ink_iou"]
    assert flown["limit_excess"] <= 1e-9
    # The ink is drawn as wide as the brush's footprint at its press (Brush defaults).
    assert flown["ink_width_m"] == pytest.approx(0.002 + 2.0 * 0.005)


def test_an_estimate_is_cheap_and_warns_of_a_slow_flight(client: TestClient) -> None:
    """/api/estimate plans nothing; at 1 cm/s it warns of the flight and the uploads."""
    start = time.perf_counter()
    usual = client.post("/api/estimate", json=TWO_STROKES)
    slow = client.post("/api/estimate", json=TWO_STROKES | {"vmax": 0.01})
    assert time.perf_counter() - start < 2.0
    assert usual.status_code == slow.status_code == 200
    assert usual.json()["warnings"] == []
    guess = slow.json()
    assert guess["flight_time_s"] > 40 * usual.json()["flight_time_s"]  # mostly length / vmax
    assert guess["path_length_m"] == usual.json()["path_length_m"]
    assert guess["setpoint_bytes"] > 1_000_000
    # Any drone: nothing about a Crazyflie's uploads.
    assert guess["crazyflie_uploads"] is None
    assert [w.split(" ")[:3] for w in guess["warnings"]] == [["a", "flight", "of"]]


def test_the_estimate_is_about_the_chosen_vehicle(client: TestClient) -> None:
    """Crazyflie: its uploads (at most one per stroke); Skybrush: its safety check's limits."""
    crazyflie = client.post("/api/estimate", json=TWO_STROKES | {"target": "crazyflie"}).json()
    assert crazyflie["crazyflie_uploads"] == 2 and crazyflie["warnings"] == []
    fast = TWO_STROKES | {"target": "skybrush", "vmax": 5.0, "amax": 10.0}
    skybrush = client.post("/api/estimate", json=fast).json()
    assert skybrush["crazyflie_uploads"] is None
    (warning,) = skybrush["warnings"]
    assert warning.startswith("Skybrush Studio's safety check may refuse the show: Speed 5")
    assert "Acceleration 10" in warning


def test_the_estimate_is_the_planners_first_timing(
    client: TestClient, planned: dict[str, Any]
) -> None:
    """At the default limits the plan needs no stretch: the estimate is its duration."""
    guess = client.post("/api/estimate", json=TWO_STROKES).json()
    assert guess["flight_time_s"] == pytest.approx(planned["result"]["duration_s"], abs=0.05)


def test_a_running_plan_is_cancelled() -> None:
    """DELETE kills the planning process; the job ends "cancelled" at once."""
    with _client(planner=slow_planner, time_limit_s=30.0) as client:
        accepted = client.post("/api/plan", json=TWO_STROKES).json()
        while client.get(accepted["url"]).json()["progress"] == 0.0:
            time.sleep(0.02)
        start = time.monotonic()
        assert client.delete(accepted["url"]).status_code == 200
        end = _wait(client, accepted["url"], timeout=5.0)[-1]
        assert end["state"] == "cancelled" and time.monotonic() - start < 2.0
        assert end["result"] is None
        # The studio is free again: a new plan is accepted.
        assert client.post("/api/plan", json=TWO_STROKES).status_code == 202
        assert client.delete(f"/api/jobs/{'0' * 32}").status_code == 404


def test_a_time_out_says_what_made_the_plan_long() -> None:
    """At 1 cm/s the flight is the cause, and the message says so (not the drawing's size)."""
    with _client(time_limit_s=1.0, planner=slow_planner) as client:
        answer = client.post("/api/plan?wait=true", json=TWO_STROKES | {"vmax": 0.01})
        detail = answer.json()["detail"]
        assert "a flight of about" in detail and "at 0.01 m/s" in detail
        assert "raise the speed limit" in detail


@pytest.mark.parametrize(
    ("body", "field"),
    [
        (TWO_STROKES | {"vmax": -1}, "vmax"),
        (TWO_STROKES | {"size_m": 9.0}, "size_m"),
        ({"text": "é"}, "text"),
        ({"text": "Hi", "drones": 3}, "drones"),
        ({"strokes": [[[0, 0], [0, 0]]]}, "strokes"),
    ],
)
def test_an_error_names_its_field(client: TestClient, body: Any, field: str) -> None:
    """The page highlights the field an error is about: the JSON says which."""
    answer = client.post("/api/plan", json=body)
    assert answer.status_code == 422
    assert answer.json()["field"] == field


def result_kinds(result: dict[str, Any]) -> list[tuple[str, str]]:
    """The result's verdicts on its downloads: (kind, verdict)."""
    return [(d["kind"], d["verdict"]) for d in result["delivered"]]
