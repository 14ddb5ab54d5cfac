"""The verification cache: verdicts of replays already recomputed, trusted only where nobody else writes.

A verdict is keyed by the replay file's SHA-256 and the armgame version, and holds what the
replay claims (so a cached entry is judged without reading its replay again) and whether it
reproduced. Its claims carry the game's identity version (``records.identity``): a verdict of
another version is recomputed, never compared, so a stale digest cannot pass or flag a game.
Failures are cached as well as passes: a planted failing replay costs its work once per user,
not at every ``armgame scores``.

Trust: a cache is a list of verdicts, so whoever can write it can plant an ``ok`` for a forged
game. It is read (and written) only when its folder and its file belong to the user running
armgame and no one else may write them (POSIX modes; on a platform without user ids, only
inside the user's own home folder), and never in or beside a table's folder. Otherwise it is
ignored with a one-line note, and verdicts live only as long as the command.

Each verdict may also carry the replay file's signature (device, inode, size, modification
and change times): a replay whose file still has that signature is known unchanged without
being read. The change time (ctime) is set by the kernel on any write or rename and cannot be
set back by a user, so a file swapped in place never matches.
"""

from __future__ import annotations

import contextlib
import json
import os
import stat
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from .. import __version__
from ..errors import UserError
from ..valid import HEX64
from .entry import CLAIM_FIELDS
from .identity import IDENTITY_FIELDS, current_claims
from .storage import DataFileError, atomic_write_bytes, parse_json, read_limited, user_path

CACHE_ENV = "ARMGAME_CACHE"
#: The fields of a verdict's claims (``entry.replay_claims``).
CLAIM_KEYS = frozenset((*CLAIM_FIELDS, *IDENTITY_FIELDS))


def default_cache_dir() -> Path | None:
    """``$ARMGAME_CACHE``, else the platform's per-user cache folder (``~/.cache/armgame`` on Linux)."""
    env = os.environ.get(CACHE_ENV)
    if env:
        return user_path(env, f"${CACHE_ENV}")
    try:
        import platformdirs

        return Path(platformdirs.user_cache_dir("armgame", appauthor=False))
    except (ImportError, RuntimeError, KeyError):  # no home folder at all: no cache (a shared one could be planted)
        return None


def usable_cache_dir(warn: Callable[[str], None], what: str) -> Path | None:
    """``default_cache_dir()``, or None where ``$ARMGAME_CACHE`` names no usable folder (too long for the file
    system, no such user's home), said to ``warn`` as a note that ``what`` is ignored: the cache and the
    teacher's record only save work or add trust, so a command goes on without them (a game just played
    still enters its table)."""
    try:
        return default_cache_dir()
    except UserError as exc:
        warn(f"note: {what} {exc}: ignored")
        return None


def file_signature(st: os.stat_result) -> list[int]:
    """What changes whenever a file's bytes can have changed (ctime cannot be set back by its owner)."""
    return [st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns]


def untrusted_reason(path: Path, kind: str) -> str | None:
    """Why ``path`` (an existing folder or file) is not a safe place for verdicts, or None if it is."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return None
    except OSError as exc:
        return f"cannot be inspected ({exc.strerror or exc})"
    if stat.S_ISLNK(st.st_mode):
        return "is a symbolic link"
    if not hasattr(os, "getuid"):  # no user ids (Windows): the user's own profile is the only private place
        try:
            Path(path).resolve().relative_to(Path.home().resolve())
        except (ValueError, RuntimeError, OSError):
            return "is outside your home folder"
        return None
    if st.st_uid != os.getuid():
        return "belongs to another user"
    if st.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        return f"is a {kind} others may write"
    return None


def private_place_reason(folder: Path, path: Path, tables: Sequence[Path]) -> str | None:
    """Why ``folder`` and its file ``path`` are not this user's alone (see the module docstring), or None.

    Shared with ``records.teacher``: the teacher's record of a table is trusted by the same rules."""
    try:
        resolved = folder.resolve()
        for table in tables:
            table = table.resolve()
            if resolved == table or table in resolved.parents or resolved == table.parent:
                return f"folder {folder} is in or beside the table's folder"
    except (OSError, RuntimeError):
        return f"folder {folder} cannot be resolved"
    for place, kind in ((folder, "folder"), (path, "file")):
        reason = untrusted_reason(place, kind)
        if reason is not None:
            return f"{kind} {place} {reason}"
    return None


class VerificationCache:
    """Verdicts of replays already recomputed (see the module docstring)."""

    FORMAT = "armgame-verified"
    MAX_BYTES = 64 * 1024 * 1024
    MAX_ITEMS = 200_000

    def __init__(self, folder: Path | None = None, warn: Callable[[str], None] | None = None) -> None:
        self.warn = warn or (lambda message: print(f"armgame: {message}", file=sys.stderr))
        if folder is None:  # as an untrusted one, an unusable $ARMGAME_CACHE is a note: every replay checked afresh
            folder = usable_cache_dir(self.warn, "the verification cache")
        self.folder = Path(folder) if folder is not None else None
        self.path = self.folder / f"verified-{__version__}.json" if self.folder is not None else None
        self.tables: list[Path] = []
        #: Without a (trusted) folder the cache lives only as long as the command.
        self._items: dict[str, dict] | None = None if self.path is not None else {}
        self._new: dict[str, dict] = {}
        # A replay file's signature -> its digest, for the saved verdicts (built on first use) and the new
        # ones: a verify of N entries asks once per entry, so a scan of the new verdicts would be N^2.
        self._by_signature: dict[tuple, str] | None = None
        self._new_by_signature: dict[tuple, str] = {}
        self._trusted: bool | None = None if self.path is not None else False

    def guard(self, table_folder: Path) -> None:
        """Never use a cache in or beside ``table_folder`` (a folder classmates may write)."""
        self.tables.append(Path(table_folder))

    def trusted(self) -> bool:
        """Whether the cache's folder and file are the user's alone; says once why not."""
        if self._trusted is None:
            reason = self._distrust()
            self._trusted = reason is None
            if reason is not None:
                self._items = {}
                self.warn(f"note: the verification cache {reason}: ignored (every replay is checked afresh)")
        return self._trusted

    def _distrust(self) -> str | None:
        assert self.folder is not None and self.path is not None
        return private_place_reason(self.folder, self.path, self.tables)

    def _load(self) -> dict[str, dict]:
        if self._items is None:
            self._items = {}
            if not self.trusted():
                return self._items
            try:
                data = parse_json(read_limited(self.path, self.MAX_BYTES, "cache file", follow=False))
                if isinstance(data, dict) and data.get("format") == self.FORMAT \
                        and data.get("version") == __version__ and isinstance(data.get("items"), dict):
                    self._items = {k: v for k, v in data["items"].items() if HEX64.fullmatch(k) and _valid(v)}
            except (DataFileError, ValueError, UnicodeDecodeError):
                pass  # no cache, or a damaged one: everything is verified afresh
        return self._items

    def get(self, digest: str) -> dict | None:
        return self._new.get(digest) or self._load().get(digest)

    def put(self, digest: str, verdict: dict) -> None:
        self._new[digest] = verdict
        if "file" in verdict:
            self._new_by_signature.setdefault(tuple(verdict["file"]), digest)

    def digest_of(self, signature: list[int]) -> str | None:
        """The SHA-256 of a replay file whose signature is ``signature``, if a verdict recorded it."""
        if self._by_signature is None:
            self._by_signature = {tuple(v["file"]): k for k, v in self._load().items() if "file" in v}
        found = self._by_signature.get(tuple(signature))
        return found if found is not None else self._new_by_signature.get(tuple(signature))

    def save(self) -> None:
        if not self._new or self.folder is None or self.path is None or not self.trusted():
            return
        items = {**self._load(), **self._new}
        if len(items) > self.MAX_ITEMS:
            items = dict(self._new)
        with contextlib.suppress(OSError, DataFileError):
            self.folder.mkdir(parents=True, exist_ok=True, mode=0o700)
            if untrusted_reason(self.folder, "folder") is None:  # created just now, or checked above
                payload = {"format": self.FORMAT, "version": __version__, "items": items}
                atomic_write_bytes(self.path, json.dumps(payload, sort_keys=True, allow_nan=False).encode(), "cache")
                os.chmod(self.path, 0o600)  # whatever the umask: a group-writable cache is not trusted next time
        self._new = {}
        self._new_by_signature = {}


def _valid(v: object) -> bool:
    if not (isinstance(v, dict) and isinstance(v.get("ok"), bool) and isinstance(v.get("label"), str)
            and isinstance(v.get("detail"), str)):
        return False
    if "file" in v and not (isinstance(v["file"], list) and len(v["file"]) == 5
                            and all(type(x) is int for x in v["file"])):
        return False
    if v["label"] == "NOT CHECKED" and type(v.get("work")) is not int:
        return False
    claims = v.get("claims")
    # Claims of another identity version hold digests this armgame does not compare (the cache file is
    # kept per armgame version, which a development checkout does not bump): such a verdict is recomputed.
    return claims is None or (isinstance(claims, dict) and set(claims) == CLAIM_KEYS and current_claims(claims)
                              and isinstance(claims["earlier_game_sha256"], list))
