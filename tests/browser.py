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


#: This process's chromium, launched by the first page and kept for the rest of the run (closed by
#: ``close_shared``, from ``tests/conftest.py`` at the session's end): each page gets a context of its own
#: (its own cookies, storage and cache, as a fresh browser has), so a launch (about 0.8 s) is paid once a
#: worker instead of once a page.
_shared: dict[str, object] = {}


def _shared_browser() -> object:
    sync_api = pytest.importorskip("playwright.sync_api")
    executable = chromium_path()
    if "browser" not in _shared or not _shared["browser"].is_connected():
        close_shared()
        _shared["playwright"] = sync_api.sync_playwright().start()
        _shared["browser"] = _shared["playwright"].chromium.launch(executable_path=executable, args=FLAGS)
    return _shared["browser"]


def close_shared() -> None:
    """Close this process's chromium and Playwright, if a page started them."""
    browser, playwright = _shared.pop("browser", None), _shared.pop("playwright", None)
    try:
        if browser is not None:
            browser.close()
    finally:
        if playwright is not None:
            playwright.stop()


@contextlib.contextmanager
def browser_page(width: int, height: int, **options: object) -> Iterator[object]:
    """A page of headless chromium at ``width`` x ``height`` in a fresh browser context (``options``:
    Playwright's ``new_context`` ones, e.g. ``has_touch=True``); its dialogs are counted in ``page.dialogs``
    (and dismissed), so a test sees any script a name could have smuggled in."""
    context = _shared_browser().new_context(viewport={"width": width, "height": height}, **options)
    try:
        page = context.new_page()
        page.dialogs = []
        page.on("dialog", lambda dialog: (page.dialogs.append(dialog.message), dialog.dismiss()))
        yield page
    finally:
        context.close()
