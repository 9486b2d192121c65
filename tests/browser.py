"""Headless Chromium for the tests: Debian's chromium (never a downloaded browser) driven by
Playwright's Python package, every request that is not file:// blocked and recorded.
Without chromium or playwright a test skips with the install hint, except in CI (CI set),
where it fails."""
from __future__ import annotations

import contextlib
import os
import shutil

import pytest

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                 "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync"]
CI_REQUIRED = bool(os.environ.get("CI"))
#: a browser without WebGL (the HTML view's 2D-canvas fallback)
NO_WEBGL = ("--disable-3d-apis",)


def sync_playwright():
    """Playwright's ``sync_playwright``, or a skip (a failure in CI) saying what to install."""
    if not CHROMIUM:
        if CI_REQUIRED:
            pytest.fail("CI needs Debian's chromium for the browser test: apt-get install "
                        "chromium")
        pytest.skip("no chromium: install Debian's package (apt-get install chromium) to run "
                    "the browser test")
    try:
        from playwright.sync_api import sync_playwright as sp
    except ImportError:
        if CI_REQUIRED:
            pytest.fail("CI needs playwright (pip install '.[test]')")
        pytest.skip("no playwright: pip install '.[test]'")
    return sp


@contextlib.contextmanager
def page(viewport=(900, 700), args=()):
    """A page of a fresh headless Chromium (``args``: more command-line switches, e.g.
    ``NO_WEBGL``); yields ``(page, log)`` where ``log`` collects console errors, page
    errors, dialogs and requests that left file://."""
    sp = sync_playwright()
    log = {"errors": [], "outside": [], "dialogs": []}
    with sp() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS + list(args))
        try:
            pg = browser.new_page(viewport={"width": viewport[0], "height": viewport[1]})
            pg.on("console", lambda m: log["errors"].append(m.text)
                  if m.type == "error" else None)
            pg.on("pageerror", lambda e: log["errors"].append(str(e)))

            def dialog(d):
                log["dialogs"].append(d.message)
                d.dismiss()
            pg.on("dialog", dialog)

            def route(r):
                if r.request.url.startswith("file://"):
                    r.continue_()
                else:
                    log["outside"].append(r.request.url)
                    r.abort()
            pg.route("**/*", route)
            yield pg, log
        finally:
            browser.close()
