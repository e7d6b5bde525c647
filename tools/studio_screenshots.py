"""Screenshots of the studio for docs/guides/studio.md, taken from real plans in headless chromium.

Starts the studio on a free loopback port (in this process), drives Debian's
chromium through Playwright at a laptop's and a phone's size, plans for real and
saves the pictures into ``docs/images/`` (or ``--out``)::

    .venv/bin/python tools/studio_screenshots.py

Chinese text typed into the page shows as boxes unless a CJK font is installed
(``apt-get install fonts-noto-cjk``); the planned characters are drawn by the
page itself and need no font.
"""

from __future__ import annotations

import argparse
import socket
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import uvicorn
from playwright.sync_api import sync_playwright

from skyquill.studio import JobManager, create_app

CHROMIUM = "/usr/bin/chromium"
LAPTOP = {"width": 1366, "height": 768}
PHONE = {"width": 390, "height": 844}
#: A drawn cross and a loop, as fractions of the canvas.
DRAWING = (
    [(0.2, 0.5), (0.8, 0.5)],
    [(0.5, 0.2), (0.5, 0.8)],
    [(0.3, 0.3), (0.25, 0.2), (0.35, 0.15), (0.4, 0.25), (0.3, 0.3)],
)


@contextmanager
def serve() -> Iterator[str]:
    """The studio on a free loopback port, in a thread."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    app = create_app(jobs=JobManager(time_limit_s=120.0), allowed_hosts=["127.0.0.1"])
    server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning"))
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    while not server.started:
        time.sleep(0.05)
    try:
        yield f"http://127.0.0.1:{port}/"
    finally:
        server.should_exit = True
        thread.join(timeout=10.0)


def draw(page: Any, stroke: list[tuple[float, float]]) -> None:
    box = page.locator("#ink").bounding_box()
    xy = [(box["x"] + fx * box["width"], box["y"] + fy * box["height"]) for fx, fy in stroke]
    page.mouse.move(*xy[0])
    page.mouse.down()
    for x, y in xy[1:]:
        page.mouse.move(x, y, steps=8)
    page.mouse.up()


def pause_at(page: Any, fraction: float) -> None:
    """Stop the playback at ``fraction`` of the flight."""
    page.eval_on_selector(
        "#time",
        f"(el) => {{ el.value = String({fraction} * Number(el.max));"
        " el.dispatchEvent(new Event('input')); }",
    )


def shoot(browser: Any, url: str, out: Path) -> list[Path]:
    """Every picture docs/guides/studio.md shows."""
    saved = []

    def save(page: Any, name: str) -> None:
        path = out / name
        page.screenshot(path=str(path))
        saved.append(path)
        print(f"wrote {path}")

    context = browser.new_context(viewport=LAPTOP)
    page = context.new_page()
    page.goto(url)
    page.wait_for_selector("#studio[data-ready='true']")
    page.fill("#text", "永")
    page.press("#text", "Enter")
    page.wait_for_selector("#stage:has-text('solve')", timeout=60_000)
    save(page, "studio-planning.png")
    page.wait_for_selector("#studio[data-state='planned']", timeout=120_000)
    pause_at(page, 0.55)
    save(page, "studio-desktop.png")
    page.fill("#text", "龘")
    page.press("#text", "Enter")
    page.wait_for_selector("#text-error:not([hidden])")
    save(page, "studio-error.png")
    page.fill("#text", "永 中 人")
    page.fill("#drones", "3")
    page.uncheck("#fly")
    page.press("#text", "Enter")
    page.wait_for_selector("#studio[data-state='planned']", timeout=120_000)
    pause_at(page, 0.5)
    save(page, "studio-drones.png")
    context.close()

    context = browser.new_context(viewport=PHONE, has_touch=True)
    page = context.new_page()
    page.goto(url)
    page.wait_for_selector("#studio[data-ready='true']")
    for stroke in DRAWING:
        draw(page, list(stroke))
    page.click("#plan")
    page.wait_for_selector("#studio[data-state='planned']", timeout=120_000)
    pause_at(page, 0.55)
    save(page, "studio-phone.png")
    context.close()
    return saved


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("docs/images"))
    opts = parser.parse_args()
    opts.out.mkdir(parents=True, exist_ok=True)
    with serve() as url, sync_playwright() as pw:
        browser = pw.chromium.launch(
            executable_path=CHROMIUM, args=["--no-sandbox", "--disable-gpu"], headless=True
        )
        try:
            shoot(browser, url, opts.out)
        finally:
            browser.close()


if __name__ == "__main__":
    main()
