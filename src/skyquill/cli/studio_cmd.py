"""``skyquill studio``: serve the drawing studio (draw, plan, preview, download) in a browser."""

from __future__ import annotations

import ipaddress
import socket
from typing import Annotated

import typer
from rich.markup import escape

from skyquill.cli.main import app, console, user_errors
from skyquill.errors import InputError

#: Host names the studio answers to when it listens on loopback (no DNS rebinding).
LOOPBACK_NAMES = ("127.0.0.1", "localhost", "::1", "[::1]")


@app.command()
def studio(
    host: Annotated[
        str, typer.Option(help="Address to listen on; 127.0.0.1 keeps it to this machine.")
    ] = "127.0.0.1",
    port: Annotated[int, typer.Option(help="TCP port to listen on.")] = 8765,
    time_limit: Annotated[float, typer.Option(help="Longest a plan may take, s.")] = 120.0,
) -> None:
    """Serve the studio: draw with a mouse, finger or pen, plan, watch, download the files."""
    with user_errors():
        loopback = _check(host, port, time_limit)
        _check_free(host, port)
    import uvicorn

    from skyquill.studio import JobManager, create_app

    jobs = JobManager(time_limit_s=time_limit)
    studio_app = create_app(jobs=jobs, allowed_hosts=LOOPBACK_NAMES if loopback else None)
    shown = f"[{host}]" if ":" in host else host
    console.print(f"[green]skyquill studio[/] on http://{escape(shown)}:{port}/  (Ctrl+C stops it)")
    if not loopback:
        console.print(
            f"[yellow]warning:[/] listening on {escape(host)}: anyone who can reach this "
            "machine can use the studio (there is no login)",
            highlight=False,
        )
    uvicorn.run(studio_app, host=host, port=port, log_level="warning")


def _check(host: str, port: int, time_limit: float) -> bool:
    """Validate the options; whether ``host`` is a loopback address."""
    if not 1 <= port <= 65535:
        raise InputError(f"--port: got {port}, expected a TCP port from 1 to 65535")
    if not 1.0 <= time_limit <= 3600.0:
        raise InputError(f"--time-limit: got {time_limit:g}, expected 1 to 3600 s")
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        raise InputError(
            f"--host: got {host!r}, expected an IP address such as 127.0.0.1 or 0.0.0.0"
        ) from None


def _check_free(host: str, port: int) -> None:
    """Fail with one clear line if ``port`` cannot be bound (in use, or not ours to take)."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as uvicorn binds
        try:
            probe.bind((host, port))
        except OSError as exc:
            raise InputError(
                f"--port: cannot listen on {host}:{port} ({exc.strerror}), expected a free "
                f"port; try --port {port + 1 if port < 65535 else 8765}"
            ) from None
