"""Suite-wide test setup.

``ARMGAME_TEST_NO_POSIX=1`` runs the tests as on a platform without POSIX's file locking and open
flags (Windows): ``fcntl`` cannot be imported and ``os`` lacks ``O_NOFOLLOW``, ``O_NONBLOCK`` and
``O_NOCTTY``. Done here, before any armgame module is imported, so that every module sees the
platform as it would be (``tests/test_portable.py`` runs the records tests so)."""

import os
import sys

if os.environ.get("ARMGAME_TEST_NO_POSIX") == "1":
    sys.modules["fcntl"] = None  # type: ignore[assignment]  # "import fcntl" now raises ImportError
    for flag in ("O_NOFOLLOW", "O_NONBLOCK", "O_NOCTTY"):
        if hasattr(os, flag):
            delattr(os, flag)
