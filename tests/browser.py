"""A real headless browser for the tests of the class's pages: Debian's chromium, driven by Playwright.

Playwright's own browser download cannot be reached from the machines this is tested on, so the
system's chromium is driven instead (``.ci/run`` installs it where it is missing). Without it the
browser tests are skipped, unless ``ARMGAME_REQUIRE_BROWSER=1`` (CI), where they fail."""

from __future__ import annotations

import contextlib
import os
import shutil
from collections.abc import Iterator

import pytest

FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
         "--disable-component-update", "--disable-sync"]


def chromium_path() -> str:
    found = shutil.which("chromium") or shutil.which("chromium-browser")
    if found is None:
        if os.environ.get("ARMGAME_REQUIRE_BROWSER") == "1":
            pytest.fail("chromium is needed for the page's tests (apt-get install chromium)")
        pytest.skip("no chromium on this machine (apt-get install chromium)")
    return found


@contextlib.contextmanager
def browser_page(width: int, height: int, **options: object) -> Iterator[object]:
    """A page of a fresh headless chromium at ``width`` x ``height`` (``options``: Playwright's ``new_page``
    ones, e.g. ``has_touch=True``); its dialogs are counted in ``page.dialogs`` (and dismissed), so a test
    sees any script a name could have smuggled in."""
    sync_api = pytest.importorskip("playwright.sync_api")
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium_path(), args=FLAGS)
        try:
            page = browser.new_page(viewport={"width": width, "height": height}, **options)
            page.dialogs = []
            page.on("dialog", lambda dialog: (page.dialogs.append(dialog.message), dialog.dismiss()))
            yield page
        finally:
            browser.close()
