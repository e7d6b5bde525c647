"""The studio end to end in a real headless browser (Debian's chromium, driven by Playwright).

The server runs in a thread on a free loopback port; the tests draw strokes
with mouse events (or type), plan, and check what a person sees: the path and
the ink painted, downloads named by the plan, a result marked out of date as
soon as an input changes, the drawing locked while planning, Cancel, the
estimate's warning, errors at their field, a phone's screen; at 1366x768,
1280x720 and 390x844 that the progress, the result and any error are in view
without scrolling; a reload keeping the work; looser limits never lengthening a
flight; axe-core in the page. Screenshots go under each test's output directory
(the documentation's are made by ``tools/studio_screenshots.py``).
"""

from __future__ import annotations

import contextlib
import csv
import itertools
import json
import socket
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any
from urllib.parse import urlparse

import pytest
from studio_fakes import over_limits_planner, slow_planner

from skyquill.io.points import TRAJECTORY_COLUMNS
from skyquill.strokes import load_stroke_json
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
    with _serve(JobManager(time_limit_s=60.0)) as url:
        yield url


@pytest.fixture(scope="module")
def slow_studio_url() -> Iterator[str]:
    """A studio whose plans never end (until cancelled or timed out)."""
    with _serve(JobManager(time_limit_s=30.0, planner=slow_planner)) as url:
        yield url


@pytest.fixture(scope="module")
def over_limits_studio_url() -> Iterator[str]:
    """A studio whose show files play over the limits (or are refused)."""
    with _serve(JobManager(time_limit_s=60.0, planner=over_limits_planner)) as url:
        yield url


@contextlib.contextmanager
def _serve(jobs: JobManager) -> Iterator[str]:
    port = _free_port()
    app = create_app(jobs=jobs, allowed_hosts=["127.0.0.1"])
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


#: A desktop's window and a phone's (an iPhone 12-15's CSS pixels).
DESKTOP = {"width": 1480, "height": 980}
PHONE = {"width": 390, "height": 844}


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    """One headless chromium for the module (a launch costs ~1 s)."""
    with playwright_api.sync_playwright() as pw:
        chromium = pw.chromium.launch(
            executable_path=str(CHROMIUM), args=CHROMIUM_ARGS, headless=True
        )
        yield chromium
        chromium.close()


@contextlib.contextmanager
def _open(
    browser: Any, url: str, viewport: dict[str, int] = DESKTOP, *, touch: bool = False
) -> Iterator[Any]:
    """A fresh page of the studio; it records page errors, hosts and API calls."""
    context = browser.new_context(viewport=viewport, accept_downloads=True, has_touch=touch)
    tab = context.new_page()
    tab.problems = []
    tab.hosts = set()
    tab.calls = []
    tab.on("pageerror", lambda exc: tab.problems.append(str(exc)))
    tab.on("request", lambda request: tab.hosts.add(urlparse(request.url).hostname))
    tab.on(
        "request", lambda request: tab.calls.append((request.method, urlparse(request.url).path))
    )
    tab.goto(url)
    tab.wait_for_selector("#studio[data-ready='true']", timeout=10_000)
    try:
        yield tab
    finally:
        context.close()


@pytest.fixture
def page(browser: Any, studio_url: str) -> Iterator[Any]:
    """A fresh page of the studio in headless chromium; no page errors allowed."""
    with _open(browser, studio_url) as tab:
        yield tab
        assert tab.problems == []


def _screenshot(page: Any, tmp_path: Path, name: str) -> None:
    """Save a screenshot under the test's directory."""
    shot = tmp_path / name
    page.screenshot(path=str(shot))
    assert shot.stat().st_size > 10_000


def _wait_planned(page: Any, timeout_ms: int = 45_000) -> None:
    page.wait_for_selector("#studio[data-state='planned']", timeout=timeout_ms)


def _download(page: Any, kind: str) -> tuple[str, str]:
    """Click the download of ``kind``: its suggested name and its text."""
    with page.expect_download() as info:
        page.click(f"a[data-file='{kind}']")
    return info.value.suggested_filename, Path(info.value.path()).read_text()


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
    """Two strokes -> Plan -> path, ink, plots, files named by the plan, a screenshot."""
    for stroke in STROKES:
        _draw(page, list(stroke))
    assert page.text_content("#stroke-count") == "2 of 200 strokes"
    assert _painted(page, "overlay") == 0

    start = time.perf_counter()
    page.click("#plan")
    _wait_planned(page)
    shown = time.perf_counter() - start
    summary = page.text_content("#summary")
    print(f"plan shown after {shown:.2f} s: {summary}")

    assert int(page.get_attribute("#overlay", "data-path-points")) > 100
    assert _painted(page, "overlay") > 2_000  # path, ink, trace, flight and drone drawn
    assert _painted(page, "plots") > 2_000
    assert "every limit met" in summary and "in simulation it flew on average" in summary
    assert "every limit met" in page.text_content("#status")
    # The ink is explained: in the legend, and its distance and overlap in the summary.
    assert page.is_visible(".legend .key.sim-ink")
    assert page.text_content(".legend .key.sim-ink") == "ink laid so far"
    assert "its ink within" in summary and "% of its ink overlaps yours" in summary
    # "Planned in" is the wait, click to result (the server's solve time is less).
    waited = float(summary.split("planned in ")[1].split(" s")[0])
    assert 0.0 < waited <= shown + 0.2
    assert page.is_hidden("#error") and page.is_visible("#estimate")
    assert page.locator(".legend .key.drone").count() == 0  # one drone: nothing to tell apart
    # The generic vehicle's files: no Crazyflie or Skybrush download.
    kinds = {a.get_attribute("data-file") for a in page.query_selector_all("#files a")}
    assert kinds == {"setpoints.csv", "summary.json", "drawing.json"}

    plan_id = page.get_attribute("#studio", "data-plan-id")
    name, text = _download(page, "setpoints.csv")
    assert name == f"skyquill-{plan_id}-setpoints.csv"
    rows = list(csv.reader(text.splitlines()))
    assert rows[0] == [*TRAJECTORY_COLUMNS, "yaw", "pen"]
    table = [[float(v) for v in row] for row in rows[1:]]
    assert len(table) > 100 and all(len(r) == len(rows[0]) for r in table)
    assert {r[-1] for r in table} == {0.0, 1.0}  # pen up and pen down
    name, text = _download(page, "summary.json")
    assert name == f"skyquill-{plan_id}-summary.json" and json.loads(text)["plan_id"] == plan_id
    name, text = _download(page, "drawing.json")
    assert name == f"skyquill-{plan_id}-drawing.json"
    (tmp_path / name).write_text(text)
    assert load_stroke_json(tmp_path / name).n_strokes == 2  # as `skyquill write --strokes` reads

    # Pause the animation mid-flight, so the screenshot shows the drone writing.
    page.evaluate("window.scrollTo(0, 0)")
    page.eval_on_selector(
        "#time",
        "(el) => { el.value = String(0.55 * Number(el.max));"
        " el.dispatchEvent(new Event('input')); }",
    )
    _screenshot(page, tmp_path, "studio-desktop.png")
    assert page.hosts - {None} == {"127.0.0.1"}  # offline: nothing fetched from elsewhere


def test_the_default_form_is_valid_enter_plans_and_a_change_makes_it_stale(page: Any) -> None:
    """Defaults pass the browser's checks; Enter plans; any change: out of date, no downloads."""
    assert page.evaluate("document.getElementById('form').checkValidity()") is True
    page.uncheck("#fly")
    page.fill("#drones", "2")
    page.fill("#text", "L T")
    page.press("#text", "Enter")
    _wait_planned(page)
    assert page.get_attribute("a[data-file='setpoints.zip']", "href")
    assert page.is_hidden("#stale")
    # Each drone in its own colour, on the canvas and in the plots, with a legend; the
    # one-drone "planned path" key gives way to the drones' (no colour means two things).
    assert page.is_hidden("#path-key")
    for keys, names in (
        (
            page.locator(".legend .key.drone"),
            ["drone 1's path, pen down", "drone 2's path, pen down"],
        ),
        (page.locator("#plot-legend .key"), ["drone 1", "drone 2"]),
    ):
        assert keys.all_text_contents() == names
        colours = {
            k.evaluate("(el) => el.style.getPropertyValue('--key-color')") for k in keys.all()
        }
        assert len(colours) == 2

    page.fill("#vmax", "0.8")  # a limit the result was not planned with
    assert page.get_attribute("#studio", "data-state") == "stale"
    assert page.is_visible("#stale") and "Out of date" in page.text_content("#stale")
    for link in page.query_selector_all("#files a"):
        assert link.get_attribute("href") is None
        assert link.get_attribute("aria-disabled") == "true"

    # A failed plan removes the result: nothing left to download.
    page.fill("#text", "é")
    page.press("#text", "Enter")
    page.wait_for_selector("#text-error:not([hidden])", timeout=10_000)
    assert page.get_attribute("#studio", "data-state") == "error"
    assert page.query_selector_all("#files a") == []
    assert page.is_hidden("#stale") and page.text_content("#summary") == ""


def test_errors_name_the_field_as_labelled_and_point_at_it(page: Any) -> None:
    """The server's message in the page's words, its field highlighted and focused."""
    page.fill("#text", "Hi")
    page.fill("#drones", "3")
    page.click("#plan")
    page.wait_for_selector("#drones-error:not([hidden])", timeout=10_000)
    error = page.text_content("#drones-error")
    assert error.startswith("Drones: 3 drones for 1 character or word;")
    assert "Choose at most 1 drone" in error
    assert page.is_visible(".field.invalid #drones")
    assert "see Drones" in page.text_content("#error")
    assert page.get_attribute("#drones", "aria-invalid") == "true"
    assert page.evaluate("document.activeElement.id") == "drones"
    assert "one drone per" in page.text_content("#drones-rule").lower()


def test_the_drawing_is_locked_while_planning(page: Any) -> None:
    """A stroke drawn while a plan runs is not taken; the result and drawing.json agree."""
    _draw(page, list(STROKES[0]))
    page.uncheck("#fly")
    page.click("#plan")
    _draw(page, list(STROKES[1]))  # while planning: refused
    page.fill("#amax", "1.5")  # a setting changed while planning: the result comes out of date
    assert page.text_content("#stroke-count") == "1 of 200 strokes"
    page.wait_for_selector("#studio[data-state='stale']", timeout=45_000)
    assert page.text_content("#stroke-count") == "1 of 200 strokes"
    assert page.is_visible("#stale")
    page.fill("#amax", "2")
    page.click("#plan")
    _wait_planned(page)
    drawn = page.evaluate("document.querySelectorAll('#files a').length")
    assert drawn >= 3
    _, text = _download(page, "drawing.json")
    assert len(json.loads(text)["strokes"]) == 1


def test_cancel_stops_the_plan(browser: Any, slow_studio_url: str) -> None:
    """Cancel kills the job; the page is back to idle with nothing planned."""
    with _open(browser, slow_studio_url) as page:
        _draw(page, list(STROKES[0]))
        page.click("#plan")
        # The fake planner's stages ("step N"): the job runs (the page's CSP forbids eval).
        page.wait_for_selector("#stage:has-text('step')", timeout=10_000)
        assert page.is_visible("#cancel")
        page.click("#cancel")
        page.wait_for_selector("#studio[data-state='drawn']", timeout=5_000)
        assert page.is_hidden("#progress-box") and page.is_hidden("#cancel")
        assert page.is_enabled("#plan") and page.is_hidden("#error")
        # Nothing of the plan's clock is left: no stage, no elapsed time, the playback at 0.
        assert page.text_content("#stage") == "" and page.text_content("#clock") == "0.0 s"
        assert page.text_content("#status").startswith("Cancelled")
        assert ("DELETE", next(p for m, p in page.calls if p.startswith("/api/jobs/"))) in (
            page.calls
        )
        assert page.problems == []


def test_a_slow_speed_is_warned_of_before_planning(page: Any) -> None:
    """At 1 cm/s the estimate warns (flight minutes, uploads) and nothing is planned yet."""
    _draw(page, list(STROKES[0]))
    page.fill("#vmax", "0.01")
    page.click("#plan")
    page.wait_for_selector("#warning:not([hidden])", timeout=5_000)
    warning = page.text_content("#warning")
    assert "min" in warning and "raise the Speed" in warning
    # Estimates and warnings only about the chosen vehicle (any drone: no Crazyflie uploads).
    assert "Crazyflie" not in warning and "Crazyflie" not in page.text_content("#estimate")
    assert ("POST", "/api/estimate") in page.calls and ("POST", "/api/plan") not in page.calls
    assert page.is_enabled("#plan") and page.is_hidden("#progress-box")
    page.click("#dismiss")
    assert page.is_hidden("#warning")


def test_on_a_phone_plan_is_near_the_canvas_and_the_result_in_view(
    browser: Any, studio_url: str, tmp_path: Path
) -> None:
    """390 x 844: Plan within a screen of the canvas's bottom; the result scrolled into view."""
    with _open(browser, studio_url, PHONE) as page:
        canvas = page.locator("#ink").bounding_box()
        plan = page.locator("#plan").bounding_box()
        assert 0 <= plan["y"] - (canvas["y"] + canvas["height"]) < PHONE["height"]
        assert plan["y"] + plan["height"] <= PHONE["height"]  # on the first screen
        _draw(page, list(STROKES[0]))
        _draw(page, list(STROKES[1]))
        page.evaluate("window.scrollTo(0, document.body.scrollHeight)")
        page.click("#plan")
        _wait_planned(page)
        box = page.locator("#overlay").bounding_box()
        assert box["y"] >= -1 and box["y"] + box["height"] <= PHONE["height"] + 1
        page.eval_on_selector(
            "#time",
            "(el) => { el.value = String(0.55 * Number(el.max));"
            " el.dispatchEvent(new Event('input')); }",
        )
        _screenshot(page, tmp_path, "studio-phone.png")
        assert page.problems == []


def test_the_page_shows_the_servers_message(page: Any) -> None:
    """A request the studio refuses comes back as a readable line on the page."""
    page.fill("#text", "é")
    page.click("#plan")
    page.wait_for_selector("#text-error:not([hidden])", timeout=10_000)
    assert page.text_content("#text-error").startswith("Text: é cannot be written")
    assert page.get_attribute("#studio", "data-state") == "error"


#: The laptop, small-laptop and phone screens the layout must serve (CSS pixels).
SCREENS = {
    "1366x768": {"width": 1366, "height": 768},
    "1280x720": {"width": 1280, "height": 720},
    "390x844": {"width": 390, "height": 844},
}
#: A drawn cross: a bar and an upright through it (fractions of the canvas).
CROSS = ([(0.2, 0.5), (0.8, 0.5)], [(0.5, 0.2), (0.5, 0.8)])


def _in_view(page: Any, selector: str) -> bool:
    """Whether ``selector`` is shown and wholly inside the window as it is (no scrolling)."""
    box = page.locator(selector).bounding_box()
    size = page.viewport_size
    return (
        page.is_visible(selector)
        and box is not None
        and box["y"] >= -1
        and box["x"] >= -1
        and box["y"] + box["height"] <= size["height"] + 1
        and box["x"] + box["width"] <= size["width"] + 1
    )


@contextlib.contextmanager
def _screen(browser: Any, url: str, screen: str) -> Iterator[Any]:
    """The studio on one of :data:`SCREENS` (the phone with touch)."""
    with _open(browser, url, SCREENS[screen], touch=screen == "390x844") as page:
        yield page
        assert page.problems == []


@pytest.mark.parametrize("screen", list(SCREENS))
def test_plan_progress_result_and_errors_are_in_view(
    browser: Any, studio_url: str, slow_studio_url: str, screen: str, tmp_path: Path
) -> None:
    """After Plan, without scrolling: the error at its field, the progress, the result."""
    with _screen(browser, studio_url, screen) as page:
        assert _in_view(page, "#plan")
        # An unknown character: its error sits at the text field, names it, marks the field.
        page.fill("#text", "龘")
        page.press("#text", "Enter")
        page.wait_for_selector("#text-error:not([hidden])", timeout=10_000)
        error = page.text_content("#text-error")
        assert error.startswith("Text: 龘 is not among") and "draw it on the canvas" in error
        assert "--" not in error and "skyquill" not in error  # no command line, no Python
        assert page.get_attribute("#text", "aria-invalid") == "true"
        assert _in_view(page, "#text-error") and _in_view(page, "#error")
        _screenshot(page, tmp_path, f"studio-error-{screen}.png")
        # A drawn cross: the result (the verdict by Plan, and the canvas) in view.
        page.fill("#text", "")
        for stroke in CROSS:
            _draw(page, list(stroke))
        page.click("#plan")
        _wait_planned(page)
        assert _in_view(page, "#status") and "every limit met" in page.text_content("#status")
        assert _in_view(page, "#overlay")
        _screenshot(page, tmp_path, f"studio-result-{screen}.png")
    with _screen(browser, slow_studio_url, screen) as page:
        _draw(page, list(CROSS[0]))
        page.click("#plan")
        page.wait_for_selector("#stage:has-text('step')", timeout=10_000)
        assert _in_view(page, "#progress-box") and _in_view(page, "#cancel")
        page.click("#cancel")
        page.wait_for_selector("#studio[data-state='drawn']", timeout=5_000)


def test_a_reload_keeps_the_drawing_and_the_settings(page: Any) -> None:
    """Strokes and every setting survive a reload (local storage); no result is invented."""
    for stroke in CROSS:
        _draw(page, list(stroke))
    page.fill("#vmax", "1.5")
    page.select_option("#target", "skybrush")
    page.select_option("#board", "wall")
    painted = _painted(page, "ink")
    page.reload()
    page.wait_for_selector("#studio[data-ready='true']", timeout=10_000)
    assert page.text_content("#stroke-count") == "2 of 200 strokes"
    assert _painted(page, "ink") == painted
    assert page.input_value("#vmax") == "1.5"
    assert page.input_value("#target") == "skybrush" and page.input_value("#board") == "wall"
    assert page.get_attribute("#studio", "data-state") == "drawn"
    # The drawing goes on from where it was: a third stroke after the reload.
    _draw(page, [(0.3, 0.3), (0.4, 0.35)])
    assert page.text_content("#stroke-count") == "3 of 200 strokes"


@pytest.mark.parametrize(
    "stored",
    ["{not json", '{"strokes": [[1]], "settings": {"vmax": 5}}', "[]", '"x"', "null"],
)
def test_a_damaged_store_is_ignored(page: Any, stored: str) -> None:
    """Whatever sits under the page's storage key, the page starts clean (and says nothing)."""
    page.evaluate("(v) => localStorage.setItem('skyquill-studio-v1', v)", stored)
    page.reload()
    page.wait_for_selector("#studio[data-ready='true']", timeout=10_000)
    assert page.text_content("#stroke-count") == "0 of 200 strokes"
    assert page.input_value("#vmax") == "1"


def test_leaving_mid_plan_asks_first(browser: Any, slow_studio_url: str) -> None:
    """A reload or a closed tab while a plan runs asks before the plan is lost."""
    with _open(browser, slow_studio_url) as page:
        _draw(page, list(CROSS[0]))
        page.click("#plan")
        page.wait_for_selector("#stage:has-text('step')", timeout=10_000)
        with page.expect_event("dialog", timeout=5_000) as asked:
            page.close(run_before_unload=True)
        assert asked.value.type == "beforeunload"
        asked.value.dismiss()  # stay: the plan goes on
        assert not page.is_closed()
        page.click("#cancel")


def test_limits_are_stated_and_kept_before_sending(page: Any) -> None:
    """Counters for strokes and characters; text past the limit is refused, never cut."""
    assert page.text_content("#stroke-count") == "0 of 200 strokes"
    assert page.text_content("#text-count") == "0 of 40 characters"
    page.fill("#text", "a" * 45)
    assert page.input_value("#text") == "a" * 45  # nothing cut silently
    assert page.text_content("#text-count") == "45 of 40 characters"
    assert page.is_visible("#text-error")
    assert page.text_content("#text-error").startswith("Text: 45 characters, at most 40")
    page.press("#text", "Enter")
    assert ("POST", "/api/estimate") not in page.calls


def test_typed_text_hides_the_drawing_it_replaces(page: Any) -> None:
    """A drawing under typed text is shown as not flown."""
    _draw(page, list(CROSS[0]))
    assert page.is_hidden("#not-flown")
    page.fill("#text", "Hi")
    assert page.is_visible("#not-flown") and "Not flown" in page.text_content("#not-flown")
    assert page.get_attribute("#studio", "data-input") == "text"


@pytest.mark.parametrize(
    ("target", "kind", "absent"),
    [("crazyflie", "crazyswarm", "show.skyc"), ("skybrush", "show.skyc", "crazyswarm")],
)
def test_the_vehicle_decides_the_files_and_the_warnings(
    page: Any, target: str, kind: str, absent: str
) -> None:
    """Crazyflie: its uploads estimated and its files offered; Skybrush: its show file."""
    for stroke in STROKES:
        _draw(page, list(stroke))
    page.uncheck("#fly")
    page.select_option("#target", target)
    assert page.text_content("#target-hint")
    page.click("#plan")
    _wait_planned(page)
    estimate = page.text_content("#estimate")
    assert ("Crazyflie upload" in estimate) == (target == "crazyflie")
    kinds = [a.get_attribute("data-file") for a in page.query_selector_all("#files a")]
    assert any(k.startswith(kind) for k in kinds) and not any(k.startswith(absent) for k in kinds)
    assert "read back as" in page.text_content("#notes")


def test_a_skybrush_show_is_warned_of_skybrush_limits(page: Any) -> None:
    """Limits above what Skybrush Studio allows are said before planning, for Skybrush only."""
    _draw(page, list(CROSS[0]))
    page.fill("#vmax", "5")
    page.click("#plan")
    page.wait_for_selector("#studio[data-state='planned'], #warning:not([hidden])")
    assert page.is_hidden("#warning")  # any drone: nothing about Skybrush
    page.select_option("#target", "skybrush")
    page.click("#plan")
    page.wait_for_selector("#warning:not([hidden])", timeout=10_000)
    assert "Skybrush Studio's safety check" in page.text_content("#warning")


#: The limits raised 1x, 5x and 20x (speed; acceleration and jerk more): (vmax, amax, jmax).
RAISED = [("1", "2", "10"), ("5", "10", "100"), ("20", "50", "1000")]


def _flown_at(page: Any, limits: tuple[str, str, str]) -> tuple[float, float]:
    """Plan at ``limits``: the planned duration and the estimate shown before it, s."""
    for field, value in zip(("#vmax", "#amax", "#jmax"), limits, strict=True):
        page.fill(field, value)
    page.click("#plan")
    _wait_planned(page, timeout_ms=90_000)
    planned = float(page.get_attribute("#studio", "data-duration"))
    estimated = float(page.get_attribute("#estimate", "data-seconds"))
    return planned, estimated


@pytest.mark.slow
@pytest.mark.parametrize("what", ["永", "cross"])
def test_looser_limits_never_lengthen_the_flight(page: Any, what: str) -> None:
    """Limits raised 1x, 5x, 20x: each flight no longer than the last, each estimate within 2x."""
    if what == "cross":
        for stroke in CROSS:
            _draw(page, list(stroke))
    else:
        page.fill("#text", what)
    page.uncheck("#fly")
    flights = [_flown_at(page, limits) for limits in RAISED]
    print(f"{what}: (planned, estimated) s at 1x, 5x, 20x: {flights}")
    durations = [planned for planned, _ in flights]
    assert all(b <= a + 1e-6 for a, b in itertools.pairwise(durations)), durations
    assert all(0.5 <= planned / estimated <= 2.0 for planned, estimated in flights), flights


@pytest.mark.parametrize("screen", ["1366x768", "390x844"])
def test_axe_finds_no_serious_or_critical_violation(
    browser: Any, studio_url: str, screen: str
) -> None:
    """axe-core in the page: empty, with an error at a field, and with a result shown."""
    from axe_playwright_python.sync_playwright import Axe

    axe = Axe()

    def serious(page: Any) -> list[str]:
        found = axe.run(page).response["violations"]
        return [
            f"{v['id']} ({v['impact']}): {[n['target'] for n in v['nodes']][:3]}"
            for v in found
            if v["impact"] in ("serious", "critical")
        ]

    with _screen(browser, studio_url, screen) as page:
        assert serious(page) == []
        page.fill("#text", "龘")
        page.press("#text", "Enter")
        page.wait_for_selector("#text-error:not([hidden])", timeout=10_000)
        assert serious(page) == []
        page.fill("#text", "")
        for stroke in CROSS:
            _draw(page, list(stroke))
        page.click("#plan")
        _wait_planned(page)
        page.click("#play")  # paused: the frame stays put while axe reads the page
        assert serious(page) == []
        page.fill("#vmax", "0.9")  # out of date: struck-out downloads
        assert serious(page) == []


@pytest.mark.parametrize(("text", "said"), [("L", "acceleration 135.00 %"), ("R", "not made")])
def test_a_show_file_over_the_limits_is_not_every_limit_met(
    browser: Any, over_limits_studio_url: str, text: str, said: str
) -> None:
    """Limits the .skyc cannot meet (issue 26): the plan meets them, the show file as played
    does not (or is refused); the page never says "every limit met", it says which file."""
    with _open(browser, over_limits_studio_url) as page:
        page.fill("#text", text)
        page.uncheck("#fly")
        page.select_option("#target", "skybrush")
        page.click("#plan")
        _wait_planned(page, timeout_ms=90_000)
        summary = page.text_content("#summary")
        assert "every limit met" not in summary
        assert "limits met as planned, but" in summary and said in summary
        assert page.problems == []
