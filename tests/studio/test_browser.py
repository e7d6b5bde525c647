"""The studio end to end in a real headless browser (Debian's chromium, driven by Playwright).

The server runs in a thread on a free loopback port; the test draws two strokes
with mouse events, plans them, waits for the preview, checks that the path is
painted, downloads the setpoint CSV and parses it, and saves a screenshot under
the test's output directory (and at ``$SKYQUILL_STUDIO_SCREENSHOT`` when set:
that is how ``docs/studio.png`` is made).
"""

from __future__ import annotations

import csv
import os
import shutil
import socket
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any
from urllib.parse import urlparse

import pytest

from skyquill.io.points import TRAJECTORY_COLUMNS
from skyquill.studio import JobManager, create_app

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking"]
#: Strokes as fractions of the canvas: a "V" and a bar across it.
STROKES = (
    [(0.2, 0.25), (0.35, 0.5), (0.5, 0.75), (0.65, 0.5), (0.8, 0.25)],
    [(0.25, 0.45), (0.5, 0.42), (0.75, 0.45)],
)

playwright_api = pytest.importorskip("playwright.sync_api")
uvicorn = pytest.importorskip("uvicorn")
pytestmark = pytest.mark.skipif(
    not CHROMIUM.exists(),
    reason="needs Debian's chromium at /usr/bin/chromium (make test installs it as root)",
)


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port


@pytest.fixture(scope="module")
def studio_url() -> Iterator[str]:
    """The studio served by uvicorn in a thread, on a free loopback port."""
    port = _free_port()
    app = create_app(jobs=JobManager(time_limit_s=60.0), allowed_hosts=["127.0.0.1"])
    server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning"))
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + 20.0
    while not server.started:
        assert time.monotonic() < deadline, "the studio server did not start"
        time.sleep(0.05)
    yield f"http://127.0.0.1:{port}/"
    server.should_exit = True
    thread.join(timeout=10.0)


@pytest.fixture
def page(studio_url: str) -> Iterator[Any]:
    """A fresh page of the studio in headless chromium; no page errors allowed."""
    with playwright_api.sync_playwright() as pw:
        browser = pw.chromium.launch(
            executable_path=str(CHROMIUM), args=CHROMIUM_ARGS, headless=True
        )
        context = browser.new_context(
            viewport={"width": 1480, "height": 980}, accept_downloads=True
        )
        tab = context.new_page()
        tab.problems = []
        tab.hosts = set()
        tab.on("pageerror", lambda exc: tab.problems.append(str(exc)))
        tab.on("request", lambda request: tab.hosts.add(urlparse(request.url).hostname))
        tab.goto(studio_url)
        tab.wait_for_selector("#studio[data-ready='true']", timeout=10_000)
        yield tab
        context.close()
        browser.close()


def _draw(page: Any, stroke: list[tuple[float, float]]) -> None:
    """One stroke with mouse events, its points given as fractions of the canvas."""
    box = page.locator("#ink").bounding_box()
    xy = [(box["x"] + fx * box["width"], box["y"] + fy * box["height"]) for fx, fy in stroke]
    page.mouse.move(*xy[0])
    page.mouse.down()
    for x, y in xy[1:]:
        page.mouse.move(x, y, steps=6)
    page.mouse.up()


def _painted(page: Any, canvas: str) -> int:
    """Pixels of ``canvas`` that are not transparent."""
    script = """(id) => {
        const c = document.getElementById(id);
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let n = 0;
        for (let i = 3; i < d.length; i += 4) if (d[i] > 0) n += 1;
        return n;
    }"""
    return int(page.evaluate(script, canvas))


def test_draw_plan_preview_download(page: Any, tmp_path: Path) -> None:
    """Two strokes -> Plan -> path, plots, simulated flight, a CSV that parses, a screenshot."""
    for stroke in STROKES:
        _draw(page, list(stroke))
    assert page.text_content("#stroke-count") == "2 strokes"
    assert _painted(page, "overlay") == 0

    start = time.perf_counter()
    page.click("#plan")
    page.wait_for_selector("#studio[data-state='planned']", timeout=45_000)
    shown = time.perf_counter() - start
    print(f"plan shown after {shown:.2f} s: {page.text_content('#summary')}")

    assert int(page.get_attribute("#overlay", "data-path-points")) > 100
    assert _painted(page, "overlay") > 2_000  # path, trace, flight and drone drawn
    assert _painted(page, "plots") > 2_000
    assert "every limit met" in page.text_content("#summary")
    assert "simulated RMSE" in page.text_content("#summary")
    assert page.is_hidden("#error")

    with page.expect_download() as info:
        page.click("a[data-file='setpoints.csv']")
    download = info.value
    assert download.suggested_filename == "setpoints.csv"
    rows = list(csv.reader(Path(download.path()).read_text().splitlines()))
    assert rows[0] == [*TRAJECTORY_COLUMNS, "yaw", "pen"]
    table = [[float(v) for v in row] for row in rows[1:]]
    assert len(table) > 100 and all(len(r) == len(rows[0]) for r in table)
    assert {r[-1] for r in table} == {0.0, 1.0}  # pen up and pen down

    # Pause the animation mid-flight, so the screenshot shows the drone writing.
    page.eval_on_selector(
        "#time",
        "(el) => { el.value = String(0.55 * Number(el.max));"
        " el.dispatchEvent(new Event('input')); }",
    )
    shot = tmp_path / "studio.png"
    page.screenshot(path=str(shot), full_page=True)
    assert shot.stat().st_size > 10_000
    if target := os.environ.get("SKYQUILL_STUDIO_SCREENSHOT"):
        shutil.copyfile(shot, target)
    assert page.problems == []
    assert page.hosts - {None} == {"127.0.0.1"}  # offline: nothing fetched from elsewhere


def test_the_page_shows_the_servers_message(page: Any) -> None:
    """A request the studio refuses comes back as a readable line on the page."""
    page.fill("#text", "é")
    page.click("#plan")
    page.wait_for_selector("#error:not([hidden])", timeout=10_000)
    assert "not in Hershey font" in page.text_content("#error")
    assert page.get_attribute("#studio", "data-state") == "error"
    assert page.problems == []
