"""The wasm page (docs/browser.md) in headless Chromium, served from a built site on localhost.

The seed case is run and what the page shows read back: tests/test_wasm_page.py asserts on it; run as a
script it writes the page's screenshot, the one docs/browser.md shows:

    .venv/bin/python tests/wasm_page.py docs/_build/html docs/images/wasm_page.png

Chromium is Debian's (`apt-get install chromium`), driven by Playwright's Python package: no
browser is downloaded.
"""

from __future__ import annotations

import contextlib
import functools
import http.server
import re
import sys
import threading
from collections.abc import Iterator
from pathlib import Path

CHROMIUM = Path("/usr/bin/chromium")
# Chromium as a test runs it: no sandbox (root in a container), no GPU, nothing fetched behind
# the page's back.
CHROMIUM_ARGUMENTS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]
VIEWPORT = {"width": 1000, "height": 900}
# The longest a page takes to load its FMU, or to run a case (ms).
WAIT_MS = 120_000


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, format, *args):
        """Say nothing per request: the test reads the page, not the log."""


@contextlib.contextmanager
def served(site: Path) -> Iterator[str]:
    """The folder site served over HTTP on 127.0.0.1 at an ephemeral port, for the block's span.

    Yields
    ------
    str
        The base URL, such as http://127.0.0.1:40123.
    """
    handler = functools.partial(_QuietHandler, directory=str(site))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()
        thread.join(timeout=10)


@contextlib.contextmanager
def browser_page() -> Iterator:
    """A fresh page of headless Chromium (Debian's), downloads accepted."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGUMENTS)
        try:
            context = browser.new_context(viewport=VIEWPORT, accept_downloads=True)
            page = context.new_page()
            page.set_default_timeout(WAIT_MS)
            yield page
        finally:
            browser.close()


# Errors in the console that are not the page's: the site's missing favicon (the browser asks
# for one) and the theme's scripts (_static/; pydata's says so of a first visit's theme setting).
NOT_THE_PAGE_S = re.compile(r"/favicon\.ico$|/_static/")


def _is_the_page_s_error(message) -> bool:
    return message.type == "error" and not NOT_THE_PAGE_S.search(message.location.get("url", ""))


def run_seed_case(page, base_url: str) -> dict:
    """Open the page and run its default signal, the seed case (20 N.m, 3 s, 1 ms): run_case's
    answer, with errors, what the page's console and scripts reported as errors.
    """
    errors: list[str] = []
    page.on("console", lambda message: _is_the_page_s_error(message) and errors.append(message.text))
    page.on("pageerror", lambda error: errors.append(str(error)))
    page.goto(f"{base_url}/browser.html")
    page.wait_for_selector("#run:enabled")
    return {**run_case(page, "constant"), "errors": errors}


def run_case(page, kind: str) -> dict:
    """Run the page's signal of that kind ("constant", "step", "csv") as its fields stand.

    Returns
    -------
    dict
        theta (theta at the stop time, as the page prints it), difference (its largest
        |wasm - native|, or None where it shows none), status (its status line).
    """
    page.select_option("#signal-kind", kind)
    page.evaluate("document.getElementById('theta-final').removeAttribute('data-value')")
    page.click("#run")
    page.wait_for_selector("#theta-final[data-value]")
    difference = page.get_attribute("#max-difference", "data-value")
    return {
        "theta": float(page.get_attribute("#theta-final", "data-value")),
        "difference": float(difference) if difference else None,
        "status": page.inner_text("#wasm-status"),
    }


def screenshot(page, path: Path) -> None:
    """The page's app, as run, into path (PNG)."""
    page.locator("#wasm-app").screenshot(path=str(path))


def main(argv: list[str]) -> int:
    """Write the screenshot of the built site's page after the seed case (see the module's doc)."""
    if len(argv) != 2:
        print("usage: tests/wasm_page.py BUILT_SITE OUT.png", file=sys.stderr)
        return 2
    site, out = Path(argv[0]), Path(argv[1])
    with served(site) as base_url, browser_page() as page:
        shown = run_seed_case(page, base_url)
        screenshot(page, out)
    print(f"{out}: theta(3 s) = {shown['theta']!r} rad; {shown['status']}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
