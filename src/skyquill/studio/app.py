"""The studio's web app: one page, a JSON API, planning jobs, downloads.

Routes
------
``GET /``
    The page (``static/index.html``; its script and style under ``/static``).
``GET /api/limits``
    The request's bounds (strokes, points, characters, drones) and the vehicles,
    which the page states up front and checks before sending.
``POST /api/estimate``
    A :class:`~skyquill.studio.models.PlanRequest`; answers its
    :class:`~skyquill.studio.models.Estimate` (route length, flight time,
    uploads, warnings) without planning.
``POST /api/plan``
    A :class:`~skyquill.studio.models.PlanRequest`; answers 202 with a job id
    (or, with ``?wait=true``, the finished job, or 422 if it cannot be planned).
``GET /api/jobs/{job_id}``
    State, progress and, once done, the result.
``DELETE /api/jobs/{job_id}``
    Cancel the job (its planning process is killed); answers its status.
``GET /api/jobs/{job_id}/files/{name}``
    A generated download, ``skyquill-<plan id>-<kind>`` (kinds ``setpoints.csv``,
    ``crazyswarm.zip``, ``show.skyc``, ``summary.json``, ...).
``GET /docs``, ``GET /openapi.json``
    FastAPI's OpenAPI description (``/docs`` loads Swagger UI's assets from
    its CDN; ``/openapi.json`` works offline).

Errors are JSON ``{"detail": "<one readable line>", "field": <name or null>,
"user_message": "<the same in the page's words>"}`` (``field``: the request field it
is about, for the page to point at; ``user_message``: :mod:`skyquill.studio.messages`):
422 for anything the person sent that cannot be planned, 413 for a body over the size limit, 429
when busy, 404 for an unknown job or file. No route takes a file-system path.
"""

from __future__ import annotations

import reprlib
from collections.abc import AsyncIterator, Sequence
from contextlib import asynccontextmanager
from importlib import resources
from typing import Annotated, Any

from fastapi import FastAPI, HTTPException, Path, Query, Request, status
from fastapi.concurrency import run_in_threadpool
from fastapi.exceptions import RequestValidationError
from fastapi.responses import HTMLResponse, JSONResponse, Response
from fastapi.staticfiles import StaticFiles
from starlette.datastructures import MutableHeaders
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.middleware.trustedhost import TrustedHostMiddleware
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from skyquill.errors import SkyquillError
from skyquill.studio.estimate import estimate
from skyquill.studio.jobs import BusyError, Job, JobManager
from skyquill.studio.messages import StudioInputError, for_person, validation_message
from skyquill.studio.models import (
    Estimate,
    JobAccepted,
    JobStatus,
    PageLimits,
    PlanRequest,
    TargetChoice,
    field_of,
)

#: Largest request body, bytes: 20,000 points of two 20-character numbers, with room.
MAX_BODY_BYTES = 1_000_000
#: The page may load nothing from elsewhere: the studio works offline, and stays private.
PAGE_CSP = (
    "default-src 'self'; img-src 'self' data: blob:; style-src 'self'; script-src 'self'; "
    "connect-src 'self'; object-src 'none'; base-uri 'none'; frame-ancestors 'none'"
)
#: The vehicles the page offers, in its words.
TARGET_CHOICES = [
    TargetChoice(
        name="generic",
        label="Any drone (setpoint file)",
        help="Positions, velocities and accelerations 100 times a second, for any flight stack.",
    ),
    TargetChoice(
        name="crazyflie",
        label="Crazyflie",
        help="Planned to fit a Crazyflie's trajectory memory: the Crazyswarm files and a fly "
        "script to download.",
    ),
    TargetChoice(
        name="skybrush",
        label="Skybrush show",
        help="A show file for Skybrush Live and Studio, checked as Skybrush plays it.",
    ),
]
#: Validation problems listed in one message before "and N more".
MAX_LISTED_ERRORS = 4

JOB_ID = Annotated[str, Path(pattern=r"^[0-9a-f]{32}$", description="A job id from /api/plan.")]
FILE_NAME = Annotated[
    str,
    Path(
        pattern=r"^skyquill-[0-9a-f]{12}-[a-z_]{1,32}\.(csv|zip|skyc|json)$",
        description="A file of the job.",
    ),
]


class BodyTooLarge(HTTPException):
    """A request body over the limit (raised while the body streams in)."""

    def __init__(self, limit: int) -> None:
        super().__init__(
            status.HTTP_413_CONTENT_TOO_LARGE,
            f"request body: larger than {limit:,} bytes, expected a smaller drawing",
        )


class BodySizeLimit:
    """ASGI middleware: 413 for a body over ``max_bytes``, declared or streamed.

    The declared ``Content-Length`` is checked before anything is read; a body
    without one (chunked) is counted as it arrives, so a lying or absent header
    cannot get more than ``max_bytes`` into memory.
    """

    def __init__(self, app: ASGIApp, max_bytes: int) -> None:
        self.app = app
        self.max_bytes = max_bytes

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        """Check the declared length, then count the streamed body."""
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        declared = dict(scope["headers"]).get(b"content-length")
        if declared is not None and (not declared.isdigit() or int(declared) > self.max_bytes):
            await _too_large(self.max_bytes)(scope, receive, send)
            return
        received, started = 0, False

        async def counting_receive() -> Message:
            nonlocal received
            message = await receive()
            received += len(message.get("body", b""))
            if received > self.max_bytes:
                raise BodyTooLarge(self.max_bytes)
            return message

        async def tracking_send(message: Message) -> None:
            nonlocal started
            started = started or message["type"] == "http.response.start"
            await send(message)

        try:
            await self.app(scope, counting_receive, tracking_send)
        except BodyTooLarge:
            if not started:  # normally FastAPI answers it; this covers a raw read
                await _too_large(self.max_bytes)(scope, receive, send)


def _too_large(limit: int) -> JSONResponse:
    return JSONResponse({"detail": BodyTooLarge(limit).detail}, status.HTTP_413_CONTENT_TOO_LARGE)


def create_app(
    *,
    jobs: JobManager | None = None,
    max_body_bytes: int = MAX_BODY_BYTES,
    allowed_hosts: Sequence[str] | None = None,
) -> FastAPI:
    """The studio's FastAPI app.

    Parameters
    ----------
    jobs
        The job manager (default: one worker thread, 120 s per plan).
    max_body_bytes
        Largest request body; more is answered 413.
    allowed_hosts
        ``Host`` headers accepted (``None``: any). The CLI passes the loopback
        names when it binds loopback, so a web page elsewhere cannot reach the
        studio through DNS rebinding. CORS is not enabled: other origins'
        scripts cannot read the API's answers.
    """
    manager = jobs or JobManager()

    @asynccontextmanager
    async def lifespan(_: FastAPI) -> AsyncIterator[None]:
        manager.warm_up()
        yield
        manager.shutdown()

    app = FastAPI(
        title="skyquill studio",
        summary="Draw, plan, preview and download quadrotor writing flights.",
        version="1",
        lifespan=lifespan,
    )
    app.state.jobs = manager
    _add_error_handlers(app)
    _add_routes(app, manager)
    app.mount("/static", StaticFiles(packages=[("skyquill.studio", "static")]), name="static")
    app.add_middleware(SecurityHeaders)
    app.add_middleware(BodySizeLimit, max_bytes=max_body_bytes)
    if allowed_hosts is not None:
        app.add_middleware(TrustedHostMiddleware, allowed_hosts=list(allowed_hosts))
    return app


def _add_routes(app: FastAPI, manager: JobManager) -> None:
    @app.get("/", response_class=HTMLResponse, include_in_schema=False)
    def page() -> HTMLResponse:
        html = resources.files("skyquill.studio").joinpath("static", "index.html")
        return HTMLResponse(html.read_text(encoding="utf-8"))

    @app.get("/api/limits")
    def limits() -> PageLimits:
        """What the page states up front: the most strokes, points, characters and drones."""
        return PageLimits(targets=TARGET_CHOICES)

    @app.post(
        "/api/estimate",
        responses={422: {"description": "Malformed request; `detail` says why."}},
    )
    async def estimate_plan(request: PlanRequest) -> Estimate:
        """How long the flight would be, its uploads and files: no planning, milliseconds."""
        return await run_in_threadpool(estimate, request)

    @app.post(
        "/api/plan",
        status_code=status.HTTP_202_ACCEPTED,
        response_model=JobAccepted,
        responses={
            200: {"model": JobStatus, "description": "With ?wait=true: the finished job."},
            413: {"description": "Body over the size limit."},
            422: {"description": "Malformed or unplannable request; `detail` says why."},
            429: {"description": "Too many plans running."},
        },
    )
    async def plan(
        request: PlanRequest,
        wait: Annotated[bool, Query(description="Answer when planned (200) or 422.")] = False,
    ) -> JobAccepted | JSONResponse:
        """Start planning a drawing or text; poll the job (or ``?wait=true``)."""
        # Malformed strokes: 422 now, not later; the estimate explains a time-out.
        guess = await run_in_threadpool(estimate, request)
        job = manager.submit(request, guess)
        if not wait:
            return JobAccepted(job_id=job.id, url=f"/api/jobs/{job.id}")
        await manager.wait(job)
        done = job.status()
        if done.state != "done":
            raise _UnplannableError(done)
        return JSONResponse(done.model_dump(mode="json"))

    @app.get("/api/jobs/{job_id}", responses={404: {"description": "Unknown job."}})
    def job_status(job_id: JOB_ID) -> JobStatus:
        """A job's state, progress, message and (once done) result."""
        return _job(manager, job_id).status()

    @app.delete("/api/jobs/{job_id}", responses={404: {"description": "Unknown job."}})
    def cancel_job(job_id: JOB_ID) -> JobStatus:
        """Cancel a queued or running job (its process is killed); a finished one stays."""
        job = _job(manager, job_id)
        manager.cancel(job)
        return job.status()

    @app.get(
        "/api/jobs/{job_id}/files/{name}",
        response_class=Response,
        responses={404: {"description": "Unknown job or file."}},
    )
    def job_file(job_id: JOB_ID, name: FILE_NAME) -> Response:
        """A generated download of a finished job."""
        job = _job(manager, job_id)
        file = job.output.files.get(name) if job.output is not None else None
        if file is None:
            raise HTTPException(404, f"file: got {name!r}, not a file of job {job_id}")
        disposition = f'attachment; filename="{name}"'
        return Response(
            file.data, media_type=file.media_type, headers={"Content-Disposition": disposition}
        )


def _job(manager: JobManager, job_id: str) -> Job:
    job = manager.get(job_id)
    if job is None:
        raise HTTPException(404, f"job: got {job_id!r}, not a job of this studio (or forgotten)")
    return job


#: What FastAPI answers for a request body it cannot parse (JSON nested past Python's limit).
_UNPARSED_BODY = "There was an error parsing the body"
_NESTED_BODY = (
    "body: got JSON that cannot be read (nested too deeply), expected a JSON object of the "
    "fields listed at /docs"
)


class _UnplannableError(Exception):
    """A ``?wait=true`` plan that failed: its message goes back as a 422."""

    def __init__(self, job: JobStatus) -> None:
        super().__init__(job.message or "the plan did not finish")
        self.job = job


def _add_error_handlers(app: FastAPI) -> None:
    async def validation(_: Request, exc: Exception) -> JSONResponse:
        errors = exc.errors() if isinstance(exc, RequestValidationError) else []
        message = describe_errors(errors)
        field = _field(errors, message)
        person = validation_message(errors)
        return _detail(422, message, field=field, user_message=person, errors=_plain(errors))

    async def user_error(_: Request, exc: Exception) -> JSONResponse:
        if isinstance(exc, StudioInputError):
            return _detail(422, str(exc), field=exc.field, user_message=exc.person)
        if isinstance(exc, _UnplannableError):
            job = exc.job
            return _detail(422, str(exc), field=job.field, user_message=job.user_message)
        field = field_of(str(exc))
        return _detail(422, str(exc), field=field, user_message=for_person(str(exc), field))

    async def busy(_: Request, exc: Exception) -> JSONResponse:
        person = "The studio is busy with other plans; press Plan again in a moment"
        return _detail(429, str(exc), user_message=person, headers={"Retry-After": "5"})

    async def http_error(_: Request, exc: Exception) -> JSONResponse:
        assert isinstance(exc, StarletteHTTPException)
        if exc.status_code == 400 and exc.detail == _UNPARSED_BODY:
            # FastAPI's own words for a body json.loads gave up on (nested too deeply).
            return _detail(400, _NESTED_BODY, field="body")
        return _detail(exc.status_code, str(exc.detail), headers=exc.headers)

    app.add_exception_handler(StarletteHTTPException, http_error)
    app.add_exception_handler(RequestValidationError, validation)
    app.add_exception_handler(SkyquillError, user_error)
    app.add_exception_handler(_UnplannableError, user_error)
    app.add_exception_handler(BusyError, busy)


def _detail(code: int, detail: str, **extra: Any) -> JSONResponse:
    headers = extra.pop("headers", None)
    return JSONResponse({"detail": detail, **extra}, status_code=code, headers=headers)


class SecurityHeaders:
    """ASGI middleware: no sniffing anywhere; the page and its files load nothing from elsewhere.

    Pure ASGI (not ``BaseHTTPMiddleware``), so that the request body streams
    straight through to :class:`BodySizeLimit`'s counter.
    """

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        """Add the headers to the response's start."""
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        path = scope.get("path", "")
        page = path == "/" or path.startswith("/static/")

        async def with_headers(message: Message) -> None:
            if message["type"] == "http.response.start":
                headers = MutableHeaders(scope=message)
                headers["X-Content-Type-Options"] = "nosniff"
                if page:
                    headers["Content-Security-Policy"] = PAGE_CSP
            await send(message)

        await self.app(scope, receive, with_headers)


def _short_repr() -> reprlib.Repr:
    """A repr that keeps a hostile input's echo short."""
    short = reprlib.Repr()  # keyword arguments need Python 3.12
    short.maxstring = short.maxother = 40
    short.maxlist = short.maxdict = 4
    short.maxlevel = 2
    return short


_short = _short_repr()


def _where(loc: Sequence[Any]) -> str:
    """``("body", "strokes", 0, 3)`` -> ``strokes[0][3]``."""
    out = ""
    for part in loc:
        if part == "body" and not out:
            continue
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out or "request"


def describe_errors(errors: Sequence[Any]) -> str:
    """Pydantic errors as one line: ``field: got X, expected Y; ...``."""
    lines = [_describe(e) for e in errors[:MAX_LISTED_ERRORS]]
    if len(errors) > MAX_LISTED_ERRORS:
        lines.append(f"and {len(errors) - MAX_LISTED_ERRORS} more problem(s)")
    return "; ".join(lines) or "request: malformed"


def _describe(error: Any) -> str:
    where, kind = _where(error.get("loc", ())), error.get("type", "")
    message = str(error.get("msg", "invalid"))
    if kind == "json_invalid":
        reason = error.get("ctx", {}).get("error", "not JSON")
        return f"body: malformed JSON ({reason}), expected a JSON object"
    if kind == "missing":
        return f"{where}: missing, expected a value"
    if kind == "extra_forbidden":
        return f"{where}: got an unknown field, expected only the fields listed at /docs"
    if message.startswith("Value error, "):
        return f"{where}: {message.removeprefix('Value error, ')}"
    expected = message.removeprefix("Input should be ")
    expected = expected[0].lower() + expected[1:] if expected else "something else"
    return f"{where}: got {_short.repr(error.get('input'))}, expected {expected}"


def _field(errors: Sequence[Any], message: str) -> str | None:
    """The request field the first error is about: its location, else its message's name."""
    loc = list(errors[0].get("loc", ())) if errors else []
    if len(loc) > 1 and loc[0] == "body" and isinstance(loc[1], str):
        return field_of(loc[1])
    return field_of(message)


def _plain(errors: Sequence[Any]) -> list[dict[str, Any]]:
    """The errors' location and message only (inputs may be large or not JSON)."""
    return [
        {"loc": list(e.get("loc", ())), "msg": str(e.get("msg", ""))}
        for e in errors[:MAX_LISTED_ERRORS]
    ]
