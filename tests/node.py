"""Node.js for the tests of the browser's JavaScript (the engine, the lab, the pages' modules): where it is, how a
runner (tests/*.mjs) is asked, and how a double crosses from one language to the other.

Without ``node`` the tests that need it are skipped, unless ``ARMGAME_REQUIRE_BROWSER`` is set (CI sets it): then
they fail."""

from __future__ import annotations

import json
import os
import shutil
import struct
import subprocess
from pathlib import Path

import pytest

NODE = shutil.which("node")
REQUIRED = bool(os.environ.get("ARMGAME_REQUIRE_BROWSER"))


def skip_without_node(unchecked: str) -> None:
    """Skips the test, or the whole module at its top, where node is missing and not required; ``unchecked`` says
    what goes unchecked."""
    if NODE is None and not REQUIRED:
        pytest.skip(f"node (Node.js) is not installed, and ARMGAME_REQUIRE_BROWSER is unset: {unchecked} (CI sets it)",
                    allow_module_level=True)


def bits(x: float) -> str:
    """A double's 64 bits in hex, as the runners write them: nothing, not even a zero's sign, is lost."""
    return struct.pack(">d", x).hex()


def node(*args: str, cwd: Path | None = None, stdin: str | None = None,
         timeout: float = 60) -> subprocess.CompletedProcess:
    """``node`` with these arguments, its output captured as text."""
    assert NODE is not None, "ARMGAME_REQUIRE_BROWSER is set but node is not installed"
    return subprocess.run([NODE, *args], cwd=cwd, input=stdin, capture_output=True, text=True, timeout=timeout,
                          check=False)


def run_node(runner: Path, request: dict, timeout: float = 120) -> dict:
    """One JSON request to a runner on its stdin; its JSON answer on stdout."""
    done = node(str(runner), stdin=json.dumps(request), timeout=timeout)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)
