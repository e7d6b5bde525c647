"""Hypothesis throws random and hostile JSON at ``POST /api/plan``: never a 500."""

from __future__ import annotations

import json
from collections.abc import Iterator
from typing import Any

import pytest
from fastapi.testclient import TestClient
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from skyquill.studio import JobManager, create_app
from skyquill.studio.models import PlanRequest

FIELDS = sorted(PlanRequest.model_fields)
VALID: dict[str, Any] = {"strokes": [[[0, 0], [10, 5], [20, 0]]], "t": [[0.0, 0.1, 0.2]]}

scalars = (
    st.none()
    | st.booleans()
    | st.integers(min_value=-(10**30), max_value=10**30)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.text(max_size=30)
)
values = st.recursive(
    scalars,
    lambda inner: (
        st.lists(inner, max_size=6) | st.dictionaries(st.text(max_size=8), inner, max_size=6)
    ),
    max_leaves=40,
)
#: Bodies that look like requests: real field names with anything in them.
requests = st.dictionaries(st.sampled_from(FIELDS), values, max_size=len(FIELDS))
#: A valid request with one field replaced by anything.
mutated = st.builds(lambda k, v: VALID | {k: v}, st.sampled_from(FIELDS), values)
points = st.lists(
    st.tuples(st.floats(-1e7, 1e7), st.floats(-1e7, 1e7)).map(list), min_size=0, max_size=6
)
drawings = st.builds(lambda s: {"strokes": s}, st.lists(points, max_size=4))


@pytest.fixture(scope="module")
def client() -> Iterator[TestClient]:
    # max_active=0: every well-formed request is validated in full (strokes, text
    # lookup) and then refused as busy, so the property test plans nothing.
    with TestClient(create_app(jobs=JobManager(max_active=0))) as c:
        yield c


def _check(client: TestClient, content: bytes) -> None:
    answer = client.post("/api/plan", content=content, headers={"content-type": "application/json"})
    assert answer.status_code in (400, 413, 422, 429), answer.text
    detail = answer.json()["detail"]
    assert isinstance(detail, str) and detail


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(body=values | requests | mutated | drawings)
def test_hostile_json_never_gets_a_500(client: TestClient, body: Any) -> None:
    _check(client, json.dumps(body, allow_nan=True).encode())


@settings(max_examples=60, deadline=None)
@given(raw=st.binary(max_size=300))
def test_hostile_bytes_never_get_a_500(client: TestClient, raw: bytes) -> None:
    _check(client, raw)


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ({"text": "Hi", "drones": True}, "drones"),
        ({"text": "Hi", "fly": "yes"}, "fly"),
        ({"text": "Hi", "vmax": "2"}, "vmax"),
        ({"text": "Hi", "size_m": "0.5"}, "size_m"),
        ({"strokes": [[["1", 2], [3, 4]]]}, "strokes"),
        ({"strokes": [[[0, 0], [1, 1]]], "t": [["0", 1]]}, "t"),
    ],
)
def test_values_of_the_wrong_type_are_refused_not_converted(
    client: TestClient, body: dict[str, Any], field: str
) -> None:
    answer = client.post("/api/plan?wait=true", json=body)
    assert answer.status_code == 422
    assert field in answer.json()["detail"]


def test_a_body_nested_too_deeply_names_the_body(client: TestClient) -> None:
    """Issue 25: the studio's deep-nesting 400 came without a field."""
    for raw in (
        b"[" * 100_000 + b"]" * 100_000,
        b'{"strokes": ' + b"[" * 5000 + b"]" * 5000 + b"}",
    ):
        answer = client.post("/api/plan", content=raw, headers={"content-type": "application/json"})
        assert answer.status_code == 400
        assert answer.json()["field"] == "body"
        assert answer.json()["detail"].startswith("body: got JSON that cannot be read")
    assert client.get("/no/such/page").status_code == 404  # other HTTP errors as before
