"""Suite-wide: tests sharing a costly module fixture run on one xdist worker, so it is built once.

``ARMGAME_TEST_NO_POSIX=1`` runs the tests as on a platform without POSIX's file locking and open
flags (Windows): ``fcntl`` cannot be imported and ``os`` lacks ``O_NOFOLLOW``, ``O_NONBLOCK`` and
``O_NOCTTY``. Done here, before any armgame module is imported, so that every module sees the
platform as it would be (``tests/test_portable.py`` runs the records tests so)."""

import os
import sys

import pytest

if os.environ.get("ARMGAME_TEST_NO_POSIX") == "1":
    sys.modules["fcntl"] = None  # type: ignore[assignment]  # "import fcntl" now raises ImportError
    for flag in ("O_NOFOLLOW", "O_NONBLOCK", "O_NOCTTY"):
        if hasattr(os, flag):
            delattr(os, flag)

# fixture name -> xdist group; `--dist loadgroup` (pyproject's addopts) sends each group to one worker.
COSTLY_MODULE_FIXTURES = {
    "curl_run": "lab-curl-run",  # a whole 120-trial lab run of the adapting bot
    "planning": "planning-optimum",  # the minimum-torque-change optimisation
    "seeds": "replay-seeds",  # a search over 200 seeds
}


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        for fixture, group in COSTLY_MODULE_FIXTURES.items():
            if fixture in getattr(item, "fixturenames", ()):
                item.add_marker(pytest.mark.xdist_group(group))
