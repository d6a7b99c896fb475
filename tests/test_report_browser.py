"""The reports in a real browser: Debian's Chromium (installed by scripts/setup.sh), driven by
Playwright for Python (never Playwright's own browser download), the pages served on localhost.

A small run is made once (a campaign of a few samples and the two nominal missions), then each
page is opened at a phone width (390 px) and a desktop width (1366 px): every image loads, the
console shows no error, nothing overflows the page sideways, and the verdict is on the first
screen."""

from __future__ import annotations

import functools
import http.server
import pathlib
import shutil
import threading

import pytest

from tailsim.campaign.driver import main as campaign_main
from tailsim.reports import analysis as analysis_report
from tailsim.reports.compare import main as compare_main

CHROMIUM = pathlib.Path("/usr/bin/chromium")
#: As on the probe of this kind of machine: headless, no sandbox (root), no network of its own.
ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
VIEWPORTS = [(390, 844), (1366, 768)]


@pytest.fixture(scope="module")
def served(tmp_path_factory):
    """A small run's report folder, served on localhost; yields its base address."""
    out = tmp_path_factory.mktemp("browser") / "out"
    # The analysis report of the tests' small analysis data (a fixture of the Rust campaign).
    shutil.copytree(pathlib.Path(__file__).parent / "data" / "analysis", out / "analysis")
    analysis_report.write(out / "analysis")
    assert (
        campaign_main(["--samples", "3", "--seed", "1", "--out", str(out / "campaign"), "--serial", "--no-progress"])
        == 0
    )
    assert compare_main(["--out", str(out), "--no-steps", "--no-avionics"]) == 0
    handler = functools.partial(QuietHandler, directory=str(out))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}", out
    server.shutdown()
    server.server_close()


class QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):  # the test's output is the assertions, not the access log
        pass


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    assert CHROMIUM.exists(), f"{CHROMIUM} missing: run scripts/setup.sh (installs Debian's chromium)"
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        context = p.chromium.launch_persistent_context(
            str(tmp_path_factory.mktemp("chromium-profile")),
            executable_path=str(CHROMIUM),
            headless=True,
            args=ARGS,
        )
        yield context
        context.close()


def open_page(browser, url: str, width: int, height: int):
    """The page at `url` in a window of `width` × `height`, with the console errors it logged."""
    page = browser.new_page()
    page.set_viewport_size({"width": width, "height": height})
    errors: list[str] = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    response = page.goto(url, wait_until="load")
    assert response is not None and response.ok, url
    return page, errors


def check_page(page, errors: list[str], width: int) -> None:
    images = page.evaluate("[...document.images].map(i => [i.alt, i.complete && i.naturalWidth > 0])")
    assert images, "no image on the page"
    assert all(ok for _, ok in images), [alt for alt, ok in images if not ok]
    assert errors == [], errors
    scroll, client = page.evaluate("[document.documentElement.scrollWidth, document.documentElement.clientWidth]")
    assert scroll <= client, f"the page is {scroll} px wide in a {client} px window at {width} px"
    # Wide tables scroll inside their own box, never the page.
    outside = page.evaluate(
        "[...document.querySelectorAll('table')].filter(t => !t.parentElement.classList.contains('table-wrap')).length"
    )
    assert outside == 0


@pytest.mark.parametrize(("width", "height"), VIEWPORTS)
def test_report_in_chromium(served, browser, width, height):
    base, out = served
    page, errors = open_page(browser, f"{base}/report.html", width, height)
    check_page(page, errors, width)
    # The verdict: its heading and its sentence are on the first screen.
    box = page.evaluate(
        "(() => { const h = document.getElementById('verdict'); const p = h.nextElementSibling;"
        " return [h.getBoundingClientRect().top, p.getBoundingClientRect().bottom, p.textContent, innerHeight]; })()"
    )
    top, bottom, sentence, screen = box
    assert 0 <= top and bottom <= screen, box
    assert "better" in sentence or "separated" in sentence, sentence
    # The table of contents links to headings that exist; the campaign's plots are in the page.
    missing = page.evaluate(
        "[...document.querySelectorAll('a[href^=\"#\"]')].map(a => a.getAttribute('href').slice(1))"
        ".filter(id => !document.getElementById(id))"
    )
    assert missing == []
    alts = page.evaluate("[...document.images].map(i => i.alt)")
    assert {p.stem for p in (out / "campaign").glob("*.png")} <= set(alts)
    # Rendered Markdown: no literal emphasis or code marks left in the text.
    text = page.evaluate("document.body.innerText")
    assert "**" not in text and "`" not in text
    page.close()


@pytest.mark.parametrize("page_path", ["campaign/report.html", "analysis/report.html"])
@pytest.mark.parametrize(("width", "height"), VIEWPORTS)
def test_other_reports_in_chromium(served, browser, width, height, page_path):
    base, _ = served
    page, errors = open_page(browser, f"{base}/{page_path}", width, height)
    check_page(page, errors, width)
    page.close()
