"""Windows, as armgame's own modules see it: no ``fcntl``, and no ``O_NOFOLLOW``, ``O_NONBLOCK`` or
``O_NOCTTY`` in ``os``.

Only armgame's modules are fooled: an ``import os`` (or ``from os import ...``) in a module whose name
starts with ``armgame`` gets a view of ``os`` without those flags, and its ``import fcntl`` raises
``ImportError``; the standard library, pytest and every other library keep the real ones, as they
would on Windows (Python 3.13's ``shutil.rmtree`` opens folders with ``os.O_NONBLOCK``, so taking the
flags from ``os`` itself broke pytest's own clean-up, not armgame). The view looks every other name up
in the real ``os`` at each use, so a test's ``monkeypatch.setattr(os, "open", ...)`` reaches armgame.

``install()`` must run before any armgame module is imported: ``tests/conftest.py`` calls it when
``ARMGAME_TEST_NO_POSIX=1``, and so does every module a ``spawn`` child starts from (``table_writer``).
"""

from __future__ import annotations

import builtins
import os
import types

ENV = "ARMGAME_TEST_NO_POSIX"
POSIX_ONLY_FLAGS = ("O_NOFOLLOW", "O_NONBLOCK", "O_NOCTTY")
POSIX_ONLY_MODULES = ("fcntl",)


class _OsWithoutPosixFlags(types.ModuleType):
    def __getattr__(self, name: str):
        if name in POSIX_ONLY_FLAGS:
            raise AttributeError(f"module 'os' has no attribute {name!r}")
        return getattr(os, name)

    def __dir__(self):
        return [name for name in dir(os) if name not in POSIX_ONLY_FLAGS]


OS_AS_ARMGAME_SEES_IT = _OsWithoutPosixFlags("os")
_real_import = builtins.__import__


def _importer_is_armgame(globals_) -> bool:
    name = (globals_ or {}).get("__name__") or ""
    return name == "armgame" or name.startswith("armgame.")


def _import(name, globals=None, locals=None, fromlist=(), level=0):
    if level == 0 and _importer_is_armgame(globals):
        top = name.partition(".")[0]
        if top in POSIX_ONLY_MODULES:
            raise ImportError(f"No module named {name!r} (simulated: not on Windows)", name=name)
        if name == "os":
            module = OS_AS_ARMGAME_SEES_IT
            for flag in fromlist or ():
                if flag in POSIX_ONLY_FLAGS:
                    raise ImportError(f"cannot import name {flag!r} from 'os' (simulated: not on Windows)")
            return module
        if top == "os" and not fromlist:  # "import os.path" binds "os"
            _real_import(name, globals, locals, fromlist, level)
            return OS_AS_ARMGAME_SEES_IT
    return _real_import(name, globals, locals, fromlist, level)


def asked() -> bool:
    return os.environ.get(ENV) == "1"


def install() -> None:
    """Fool armgame's modules from now on (idempotent)."""
    builtins.__import__ = _import


def install_if_asked() -> None:
    if asked():
        install()
