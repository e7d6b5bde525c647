"""``skyquill studio``: options, refusals with exit 2, and what it hands to uvicorn."""

from __future__ import annotations

import socket
from typing import Any

import pytest
import uvicorn
from fastapi.testclient import TestClient
from typer.testing import CliRunner

from skyquill.cli.main import app

runner = CliRunner()


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port


@pytest.fixture
def served(monkeypatch: pytest.MonkeyPatch) -> dict[str, Any]:
    """What ``uvicorn.run`` was called with (nothing is served)."""
    calls: dict[str, Any] = {}

    def fake_run(asgi: Any, **kwargs: Any) -> None:
        calls.update(kwargs, app=asgi)

    monkeypatch.setattr(uvicorn, "run", fake_run)
    return calls


def test_help_shows_the_loopback_default() -> None:
    result = runner.invoke(app, ["studio", "--help"])
    assert result.exit_code == 0
    assert "127.0.0.1" in result.output and "8765" in result.output


def test_it_serves_on_loopback_by_default(served: dict[str, Any]) -> None:
    port = _free_port()
    result = runner.invoke(app, ["studio", "--port", str(port)])
    assert result.exit_code == 0, result.output
    assert f"http://127.0.0.1:{port}/" in result.output
    assert served["host"] == "127.0.0.1" and served["port"] == port
    with TestClient(served["app"], base_url="http://127.0.0.1") as client:
        assert client.get("/").status_code == 200
        assert client.get("/", headers={"host": "evil.example"}).status_code == 400


def test_a_public_address_gets_a_warning(served: dict[str, Any]) -> None:
    result = runner.invoke(app, ["studio", "--host", "0.0.0.0", "--port", str(_free_port())])
    assert result.exit_code == 0, result.output
    assert "warning" in result.output and "no login" in result.output


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--port", "0"], "--port: got 0, expected a TCP port from 1 to 65535"),
        (["--port", "70000"], "--port: got 70000, expected a TCP port from 1 to 65535"),
        (["--host", "my laptop"], "--host: got 'my laptop', expected an IP address"),
        (["--time-limit", "0"], "--time-limit: got 0, expected 1 to 3600 s"),
    ],
)
def test_bad_options_are_one_clear_line(
    served: dict[str, Any], args: list[str], message: str
) -> None:
    result = runner.invoke(app, ["studio", *args])
    assert result.exit_code == 2
    assert message in " ".join(result.output.split())
    assert served == {}


def test_a_port_in_use_is_a_clear_error(served: dict[str, Any]) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        result = runner.invoke(app, ["studio", "--port", str(port)])
    assert result.exit_code == 2
    assert f"--port: cannot listen on 127.0.0.1:{port}" in " ".join(result.output.split())
    assert served == {}
