"""Suite-wide test setup.

``ARMGAME_TEST_NO_POSIX=1`` runs the tests as on a platform without POSIX's file locking and open
flags (Windows), as armgame's own modules see it: their ``import fcntl`` fails and their ``os`` lacks
``O_NOFOLLOW``, ``O_NONBLOCK`` and ``O_NOCTTY`` (``tests/no_posix.py``; the standard library and pytest
keep theirs, as on Windows). Done here, before any armgame module is imported
(``tests/test_portable.py`` runs the records tests so).

Where ``PYTHONDONTWRITEBYTECODE`` is set, the suite still writes bytecode as Python does by default
(``__pycache__`` folders, which git ignores): otherwise every xdist worker and every ``armgame``
subprocess compiles armgame and the test modules anew, which made a fresh checkout's run 92 to 98 s
instead of 89 s on two cores (and a second run 86 s). Moving the bytecode to a prefix folder instead
does not help: Python then compiles numpy, scipy and the standard library there too."""

import os
import shutil
import sys
import tempfile

import no_posix

no_posix.install_if_asked()


def pytest_configure(config) -> None:
    # No test writes into the user's own cache folder (verdicts, the teacher's records of tables): each
    # process of the run gets a private one, and tests that need their own set it themselves.
    folder = tempfile.mkdtemp(prefix="armgame-test-cache-")
    os.chmod(folder, 0o700)
    os.environ["ARMGAME_CACHE"] = folder
    config.add_cleanup(lambda: shutil.rmtree(folder, ignore_errors=True))
    # Nor into the checkout: Hypothesis keeps its examples and caches in the same private folder (its default is
    # ./.hypothesis), as do the subprocesses the tests start; pytest's own cache is off (pyproject's addopts).
    from hypothesis.configuration import set_hypothesis_home_dir

    os.environ["HYPOTHESIS_STORAGE_DIRECTORY"] = os.path.join(folder, "hypothesis")
    set_hypothesis_home_dir(os.environ["HYPOTHESIS_STORAGE_DIRECTORY"])
    config.add_cleanup(_close_browser)
    if sys.dont_write_bytecode:
        sys.dont_write_bytecode = False
        os.environ.pop("PYTHONDONTWRITEBYTECODE", None)  # the armgame subprocesses the tests start too


def _close_browser() -> None:
    """The chromium the browser tests share in this process (tests/browser.py), if one was started."""
    browser = sys.modules.get("browser")
    if browser is not None and hasattr(browser, "close_shared"):
        browser.close_shared()


def pytest_xdist_auto_num_workers(config) -> int:
    """``-n auto`` (pyproject's addopts): one worker more than the cores this process may use. Many tests wait
    rather than compute (a subprocess, a class's server thread, chromium), and a third worker fills those waits:
    on two cores the suite took 50 to 52 s with three workers against 55 to 58 s with two (alternate runs)."""
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    return cores + 1
