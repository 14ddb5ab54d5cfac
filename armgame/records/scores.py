"""The high-score table: entries that are never lost, each backed by the replay it came from.

Storage, in one folder (see ``default_scores_dir``)::

    scores.json           the table: JSON, one entry a line
    scores.lock           taken (flock) by whoever writes the table
    replays/*.json        one replay per entry, named by the entry

Why one file under a lock rather than an append-only log with a merge: the table stays
one small, readable JSON file a teacher can open, and every change is all or nothing. A
change is read-modify-write under an exclusive ``fcntl.flock`` on ``scores.lock``, so two
games finishing at the same moment queue for a few milliseconds and both entries land;
the kernel drops the lock when its holder exits, even by SIGKILL, so there is no stale
lock to clean up. A writer waits at most ``LOCK_WAIT`` seconds for the lock, then says the
table is busy; the game's replay is already saved and ``armgame scores --add`` enters it
later. The new table is written to a temporary file in the same folder, fsynced and renamed
over the old one (``armgame.records.storage``): readers need no lock, since they always see
a whole table, old or new.

Trust: the table is parsed as data with a schema check of every field. A damaged table
(truncated, not JSON, an entry failing its checks) is never overwritten silently: the next
write first copies its bytes to ``scores.json.corrupt-<UTC time>``, then writes the new
table with every valid entry it could find, and only that rename retires the damaged file;
if anything fails, the table stays as it was. A valid table is never set aside: one over
the size limit is refused whole (no entry added) rather than dropped. An entry names its
replay file and the file's SHA-256, so a score typed into the table, a replay edited, or
replays swapped between entries all show up when ``check`` recomputes the game. Only games
of a ranked ruleset (``armgame.records.rulesets``) rank; the others are listed apart.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import shlex
import stat
import sys
import time
import uuid
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, fields
from datetime import UTC, datetime
from pathlib import Path

from .. import __version__
from ..game.session import GameResult
from ..limits import MAX_REPLAY_BYTES, MAX_TABLE_BYTES, MAX_TABLE_ENTRIES
from ..words import plural
from .replay import DRIVEN, Replay, check_date, check_name, check_word, now_iso
from .rulesets import CUSTOM, RULESETS, config_digest, ruleset_name
from .storage import (
    STRICT_DECODER,
    DataFileError,
    atomic_write_bytes,
    check_float,
    check_int,
    check_keys,
    check_str,
    copy_aside,
    open_regular,
    parse_json,
    read_limited,
    user_path,
)

SCORES_ENV = "ARMGAME_SCORES"
CACHE_ENV = "ARMGAME_CACHE"
TABLE_NAME = "scores.json"
LOCK_NAME = "scores.lock"
REPLAYS_DIR = "replays"
FORMAT = "armgame-scores"
#: 2 adds each entry's ruleset and config digest; format 1 tables are still read (and rewritten as 2).
FORMAT_VERSION = 2
READS_FORMATS = (1, 2)
#: Seconds a writer waits for the table's lock before saying the table is busy.
LOCK_WAIT = 5.0
_COUNT_MAX = 10**9
_REPLAY_FILE = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,150}\.json")
_HEX64 = re.compile(r"[0-9a-f]{64}")
_HEX32 = re.compile(r"[0-9a-f]{32}")
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)


class TableError(DataFileError):
    """The table cannot be changed (busy, over its limits, not a safe place): nothing was changed."""


def default_scores_dir() -> Path:
    """Where the table lives unless ``--scores`` says otherwise.

    ``$ARMGAME_SCORES`` if set; else the checkout's own ``scores/`` folder when armgame runs
    from a checkout (an editable install included); else the per-user data folder:
    ``$XDG_DATA_HOME/armgame/scores`` (``~/.local/share/armgame/scores``), or
    ``%LOCALAPPDATA%\\armgame\\scores`` on Windows.
    """
    env = os.environ.get(SCORES_ENV)
    if env:
        return user_path(env, f"${SCORES_ENV}")
    root = Path(__file__).resolve().parents[2]
    if (root / "pyproject.toml").is_file() and (root / "scores").is_dir():
        return root / "scores"
    if sys.platform == "win32" and os.environ.get("LOCALAPPDATA"):
        return Path(os.environ["LOCALAPPDATA"]) / "armgame" / "scores"
    data = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
    return Path(data) / "armgame" / "scores"


@dataclass(frozen=True)
class ScoreEntry:
    id: str
    name: str
    driven: str
    driver: str | None
    score: int
    hits: int
    resets: int
    seed: int
    scene: str
    duration: float
    date: str
    version: str
    replay: str
    replay_sha256: str
    #: The ruleset the game claims (``standard``, or ``custom``) and its config digest; None in
    #: entries carried over from a format 1 table (their replay decides, see ``ScoreTable.ruleset``).
    ruleset: str | None = None
    config_sha256: str | None = None

    def as_dict(self) -> dict[str, object]:
        return {name: getattr(self, name) for name in _ENTRY_FIELDS}  # dataclasses.asdict deep-copies: 10x slower

    @property
    def when(self) -> datetime:
        return datetime.fromisoformat(self.date)

    @property
    def how(self) -> str:
        return f"{self.driven} ({self.driver})" if self.driver else self.driven

    @classmethod
    def from_dict(cls, data: object) -> ScoreEntry:
        """Check every field; raises ValueError naming the first bad one."""
        d = check_keys("entry", data, _REQUIRED, _OPTIONAL)
        driven = check_str("driven", d["driven"], 20)
        if driven not in DRIVEN:
            raise ValueError(f"driven must be one of {', '.join(DRIVEN)}, got {driven!r}")
        ruleset, digest = d.get("ruleset"), d.get("config_sha256")
        entry = cls(
            id=_match("id", d["id"], _HEX32),
            name=check_name(d["name"]),
            driven=driven,
            driver=None if d["driver"] is None else check_str("driver", d["driver"], 200),
            score=check_int("score", d["score"], 0, _COUNT_MAX),
            hits=check_int("hits", d["hits"], 0, _COUNT_MAX),
            resets=check_int("resets", d["resets"], 0, _COUNT_MAX),
            seed=check_int("seed", d["seed"], 0, 2**63 - 1),
            scene=check_word("scene", d["scene"]),
            duration=check_float("duration", d["duration"], 0.0, 86400.0, low_open=True),
            date=check_date("date", d["date"]),
            version=check_word("version", d["version"]),
            replay=_match("replay", d["replay"], _REPLAY_FILE),
            replay_sha256=_match("replay_sha256", d["replay_sha256"], _HEX64),
            ruleset=None if ruleset is None else check_word("ruleset", ruleset),
            config_sha256=None if digest is None else _match("config_sha256", digest, _HEX64),
        )
        if (entry.ruleset is None) != (entry.config_sha256 is None):
            raise ValueError("ruleset and config_sha256 come together")
        if entry.score > entry.hits:
            raise ValueError(f"score {entry.score} is more than the hits {entry.hits}")
        if entry.name != d["name"]:
            raise ValueError(f"name {d['name']!r} has surrounding spaces")
        return entry


_ENTRY_FIELDS = tuple(f.name for f in fields(ScoreEntry))
_OPTIONAL = frozenset({"ruleset", "config_sha256"})
_REQUIRED = set(_ENTRY_FIELDS) - _OPTIONAL


def _match(name: str, value: object, pattern: re.Pattern[str]) -> str:
    value = check_str(name, value, 200)
    if not pattern.fullmatch(value):
        raise ValueError(f"{name} is not a valid {name.replace('_', ' ')}: {value!r}")
    return value


def sort_key(entry: ScoreEntry) -> tuple[int, datetime, str]:
    """Best first; equal scores by date, the earlier game first."""
    return (-entry.score, entry.when, entry.id)


@dataclass(frozen=True)
class Check:
    """What recomputing an entry's game says: ``ok``, or a short label and why not.

    ``ruleset`` is the ruleset the replay plays (``custom`` if none), when the replay could be read.
    """

    ok: bool
    label: str
    detail: str = ""
    ruleset: str | None = None


@dataclass(frozen=True)
class Damage:
    reason: str
    recovered: int
    found: int

    def describe(self, path: Path) -> str:
        return f"{path} is damaged ({self.reason}); {plural(self.recovered, 'valid entry')} recovered"


def replay_claims(replay: Replay) -> dict[str, object]:
    """What an entry must say about its replay's game, field for field."""
    r = replay.result
    return {"name": replay.player, "driven": replay.driven, "driver": replay.driver, "score": r.score,
            "hits": r.hits, "resets": r.resets, "seed": r.seed, "scene": r.scene, "duration": r.duration,
            "date": replay.date, "config_sha256": config_digest(replay.config),
            "ruleset": ruleset_name(replay.config)}


class ScoreTable:
    """The table in ``folder``; ``warn`` receives one-line notices (a damaged table, say)."""

    def __init__(self, folder: Path, warn: Callable[[str], None] | None = None,
                 cache: VerificationCache | None = None) -> None:
        self.folder = Path(folder)
        self.path = self.folder / TABLE_NAME
        self.lock_path = self.folder / LOCK_NAME
        self.replays = self.folder / REPLAYS_DIR
        self.warn = warn or (lambda message: print(message, file=sys.stderr))
        self.cache = cache
        self._legacy_rulesets: dict[str, str] = {}

    # ------------------------------------------------------------------ reading
    def _open_table(self) -> int | None:
        """A descriptor of the table file, or None if there is none. Never follows a symlink."""
        try:
            st = os.lstat(self.path)
        except FileNotFoundError:
            return None
        except OSError as exc:
            raise TableError(f"{self.path}: cannot read: {exc.strerror or exc}") from None
        if stat.S_ISLNK(st.st_mode):
            raise TableError(f"{self.path}: is a symbolic link; the table must be a regular file in its folder")
        fd = open_regular(self.path, "score table", follow=False)
        if os.fstat(fd).st_size > MAX_TABLE_BYTES:
            os.close(fd)
            raise TableError(f"{self.path}: larger than {MAX_TABLE_BYTES // (1024 * 1024)} MiB, more than armgame "
                             f"reads; nothing was changed (move some entries to another table)")
        return fd

    def read(self) -> tuple[list[ScoreEntry], Damage | None]:
        """The valid entries, unsorted, and what is wrong with the file if anything. No side effects.

        A table that is not a regular file or is over the size limit raises ``TableError``:
        it is not damage, and nothing may be written over it.
        """
        fd = self._open_table()
        if fd is None:
            return [], None
        with os.fdopen(fd, "rb") as f:
            data = f.read(MAX_TABLE_BYTES + 1)
        return parse_table(data)

    def all_entries(self) -> list[ScoreEntry]:
        """Every valid entry, ranked or not, best first; a damaged file is reported through ``warn``."""
        entries, damage = self.read()
        if damage:
            self.warn(damage.describe(self.path) + "; the file will be kept aside at the next save")
        return sorted(entries, key=sort_key)

    def entries(self) -> list[ScoreEntry]:
        """The ranked entries (games of a ranked ruleset), best first."""
        return [e for e in self.all_entries() if self.ruleset(e) in RULESETS]

    def ruleset(self, entry: ScoreEntry) -> str:
        """The ruleset an entry plays: its own claim (checked against its replay by ``check``), or,
        for an entry from a format 1 table, what its replay's configuration says."""
        if entry.config_sha256 is not None:
            found = next((r for r in RULESETS.values() if r.digest == entry.config_sha256), None)
            return found.name if found and found.name == entry.ruleset else CUSTOM
        if entry.replay_sha256 not in self._legacy_rulesets:
            cached = self.cache.get(entry.replay_sha256) if self.cache is not None else None
            if all((entry.duration, entry.scene) != (r.config.time_limit, r.config.scene) for r in RULESETS.values()):
                name = CUSTOM  # no ranked ruleset has this length: no need to read the replay
            elif cached is not None:  # a check already read this replay: its ruleset is known
                name = cached["claims"]["ruleset"] if cached["claims"] else CUSTOM
            else:  # read its configuration (no replaying: this serves the end screen too)
                try:
                    name = ruleset_name(Replay.load(self._replay_file(entry), follow=False).config)
                except DataFileError:
                    name = CUSTOM
            self._legacy_rulesets[entry.replay_sha256] = name
        return self._legacy_rulesets[entry.replay_sha256]

    # ------------------------------------------------------------------ writing
    def _safe_folder(self) -> None:
        """Create the folder and replays/; refuse a replays/ or scores.lock planted as a symlink."""
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            for path, folder in ((self.replays, True), (self.lock_path, False)):
                with contextlib.suppress(FileNotFoundError):
                    mode = os.lstat(path).st_mode
                    if stat.S_ISLNK(mode):
                        raise TableError(f"{path}: is a symbolic link; armgame writes only inside {self.folder}")
                    if folder and not stat.S_ISDIR(mode):
                        raise TableError(f"{path}: is not a folder")
                    if not folder and not stat.S_ISREG(mode):
                        raise TableError(f"{path}: is not a regular file")
            self.replays.mkdir(exist_ok=True)
        except OSError as exc:
            raise TableError(f"cannot write the table in {self.folder}: {exc.strerror or exc}") from None

    @contextlib.contextmanager
    def _locked(self, wait: float | None = None) -> Iterator[None]:
        import fcntl  # POSIX only; imported here so reading the table works everywhere

        wait = LOCK_WAIT if wait is None else wait
        try:
            # Read-only is enough for flock, so classmates can share a lock file one of them created.
            fd = os.open(self.lock_path, os.O_RDONLY | os.O_CREAT | _NOFOLLOW | os.O_NONBLOCK, 0o644)
        except OSError as exc:
            raise TableError(f"{self.lock_path}: cannot open the lock: {exc.strerror or exc}") from None
        try:
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                raise TableError(f"{self.lock_path}: is not a regular file")
            deadline = time.monotonic() + wait
            while True:
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                    break
                except BlockingIOError:
                    if time.monotonic() >= deadline:
                        raise TableBusyError(f"the table in {self.folder} is busy (another program has held its "
                                        f"lock for {wait:g} s)") from None
                    time.sleep(0.05)
            yield
        finally:
            os.close(fd)  # closing drops the lock

    def save_replay(self, replay: Replay) -> Path:
        """Save the replay in replays/ (before the table is touched); returns its path."""
        self._safe_folder()
        data = replay.to_bytes()
        digest = hashlib.sha256(data).hexdigest()
        stamp = replay.date or now_iso()
        slug = re.sub(r"[^A-Za-z0-9]+", "-", replay.player or "").strip("-")[:24] or "player"
        name = f"{datetime.fromisoformat(stamp).strftime('%Y%m%dT%H%M%S')}-{slug}-{digest[:8]}.json"
        path = self.replays / name
        try:
            if read_limited(path, MAX_REPLAY_BYTES, "replay file", follow=False) == data:
                return path  # already there, byte for byte
        except DataFileError:
            pass
        atomic_write_bytes(path, data, "replay")
        return path

    def add(self, replay: Replay, replay_path: Path | None = None) -> ScoreEntry:
        """Save ``replay`` beside the table and enter its game; returns the new entry.

        Raises ``TableBusyError`` (the replay is saved; ``armgame scores --add`` enters it later) or
        ``TableError``/``ValueError`` with nothing changed.
        """
        if replay.player is None:
            raise ValueError("a game enters the table under a player's name")
        if replay.task is not None:
            raise ValueError("a lab run is not a game: it never enters the high-score table")
        if not replay.complete:
            raise ValueError("only a game played to the end enters the table")
        # The replay first: a crash in between leaves a spare replay, never an entry without one.
        self._safe_folder()
        path = replay_path or self.save_replay(replay)
        data = read_limited(path, MAX_REPLAY_BYTES, "replay file", follow=False)
        claims = replay_claims(replay)
        r = replay.result
        entry = ScoreEntry.from_dict(dict(
            id=uuid.uuid4().hex, name=replay.player, driven=replay.driven, driver=replay.driver, score=r.score,
            hits=r.hits, resets=r.resets, seed=r.seed, scene=r.scene, duration=r.duration,
            date=replay.date or now_iso(), version=replay.version, replay=path.name,
            replay_sha256=hashlib.sha256(data).hexdigest(), ruleset=claims["ruleset"],
            config_sha256=claims["config_sha256"],
        ))
        try:
            with self._locked():
                self._enter(entry)
        except TableBusyError as exc:
            later = shlex.join(["armgame", "scores", "--scores", str(self.folder), "--add", str(path)])
            raise TableBusyError(f"{exc}; your game's replay is kept as {path}: enter it later with {later}") from None
        return entry

    def _enter(self, entry: ScoreEntry) -> None:
        # Under the lock nobody else is writing the table: any temporary file of it was left by a
        # writer that died mid-write. Replays are written outside the lock, so theirs are left alone.
        for stale in self.folder.glob(f".{TABLE_NAME}.*.tmp"):
            with contextlib.suppress(OSError):
                if stat.S_ISREG(os.lstat(stale).st_mode):
                    stale.unlink()
        fd = self._open_table()
        try:
            if fd is None:
                entries, damage = [], None
            else:
                data = _read_all(fd)
                entries, damage = parse_table(data)
            twin = next((e for e in entries if e.replay_sha256 == entry.replay_sha256), None)
            if twin is not None:
                raise TableError(f"this replay is already in the table (entered {twin.date[:16]} as {twin.name})")
            if len(entries) >= MAX_TABLE_ENTRIES:
                raise TableError(f"the table holds {len(entries)} entries, its limit: not entered (nothing was "
                                 f"dropped; start a new table with --scores)")
            entries.append(entry)
            new = table_bytes(entries)
            if len(new) > MAX_TABLE_BYTES:
                raise TableError("the table would grow past its size limit: not entered (nothing was dropped)")
            kept = None
            if damage is not None and fd is not None:
                kept = self._copy_aside(fd)  # the damaged bytes, copied before anything else changes
            try:
                atomic_write_bytes(self.path, new, "score table")  # the rename retires the damaged file
            except BaseException:
                if kept is not None:
                    with contextlib.suppress(OSError):
                        kept.unlink()
                raise
            if damage is not None:
                where = f"; the damaged file is kept as {kept.name}" if kept else ""
                self.warn(f"{damage.describe(self.path)}{where}")
        finally:
            if fd is not None:
                os.close(fd)

    def _copy_aside(self, fd: int) -> Path:
        stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%SZ")
        for n in range(1000):
            kept = self.folder / f"{TABLE_NAME}.corrupt-{stamp}{f'-{n}' if n else ''}"
            try:
                copy_aside(fd, kept)
                return kept
            except FileExistsError:
                continue
            except OSError as exc:
                raise TableError(f"cannot keep a copy of the damaged table: {exc.strerror or exc}; nothing was "
                                 f"changed") from None
        raise TableError("cannot name a copy of the damaged table; nothing was changed")

    def of_kind(self, ranked: bool) -> list[ScoreEntry]:
        """Ranked games, or else custom games, best first: the entries one game is compared with."""
        if ranked:
            return self.entries()
        return [e for e in self.all_entries() if self.ruleset(e) not in RULESETS]

    def same_kind(self, entry: ScoreEntry) -> list[ScoreEntry]:
        """The entries ``entry`` is compared with, best first."""
        return self.of_kind(self.ruleset(entry) in RULESETS)

    def rank(self, entry: ScoreEntry) -> int:
        """The entry's place among the entries of its own kind (ranked games, or custom games)."""
        ordered = self.same_kind(entry)
        return next((i for i, e in enumerate(ordered, 1) if e.id == entry.id), len(ordered))

    # ------------------------------------------------------------------ trust
    def replay_path(self, entry: ScoreEntry) -> Path:
        return self.replays / entry.replay

    def _replay_file(self, entry: ScoreEntry) -> Path:
        mode = os.lstat(self.replays).st_mode if self.replays.exists() or self.replays.is_symlink() else None
        if mode is not None and not stat.S_ISDIR(mode):
            raise DataFileError(f"{self.replays}: is not a folder (a symbolic link is not followed)")
        return self.replay_path(entry)

    def check(self, entry: ScoreEntry) -> Check:
        """Whether the entry's replay is the one it names and reproduces its game. Never raises."""
        return self.check_many([entry])[0]

    def check_many(self, entries: Sequence[ScoreEntry],
                   recompute: Callable[[Sequence[Replay]], list[tuple[bool, GameResult]]] | None = None,
                   ) -> list[Check]:
        """``check`` for each entry; the games not in the cache are recomputed together.

        ``recompute`` maps replays to ``replay.verify()`` of each (``records.batch_verify`` passes
        the batched one); if it fails, the games are recomputed one at a time, so one entry's
        failure still marks only that entry.
        """
        found: list[Check | tuple[str, dict | Replay]] = []
        for entry in entries:
            try:
                found.append(self._claim(entry))
            except Exception as exc:  # one entry's failure never takes the table down
                found.append(_bad(exc))
        pending = {digest: item for f in found if not isinstance(f, Check)
                   for digest, item in [f] if isinstance(item, Replay)}
        verdicts = _recompute(list(pending.values()), recompute)
        for (digest, replay), verdict in zip(pending.items(), verdicts, strict=True):
            cached = {"claims": replay_claims(replay), **verdict}
            if self.cache:
                self.cache.put(digest, cached)
            pending[digest] = cached  # type: ignore[assignment]
        checks = []
        for entry, f in zip(entries, found, strict=True):
            if isinstance(f, Check):
                checks.append(f)
                continue
            digest, item = f
            try:
                checks.append(self._judge(entry, pending[digest] if isinstance(item, Replay) else item))
            except Exception as exc:
                checks.append(_bad(exc))
        return checks

    def _claim(self, entry: ScoreEntry) -> Check | tuple[str, dict | Replay]:
        """A failed ``Check``; or the replay's digest with its cached verdict, or the replay still to recompute."""
        try:
            path = self._replay_file(entry)
            data = read_limited(path, MAX_REPLAY_BYTES, "replay file", follow=False)
        except DataFileError as exc:
            missing = not self.replay_path(entry).exists() and not self.replay_path(entry).is_symlink()
            return Check(False, "REPLAY MISSING" if missing else "REPLAY UNREADABLE", str(exc))
        digest = hashlib.sha256(data).hexdigest()
        if digest != entry.replay_sha256:
            return Check(False, "REPLAY CHANGED", f"{path.name} is not the replay this entry was saved with")
        cached = self.cache.get(digest) if self.cache else None
        if cached is not None:
            return digest, cached
        try:
            replay = Replay.from_bytes(data, str(path))
        except DataFileError as exc:
            cached = {"claims": None, "ok": False, "label": "BAD REPLAY", "detail": str(exc)}
            if self.cache:
                self.cache.put(digest, cached)
            return digest, cached
        if replay.task is not None:
            return Check(False, "NOT A GAME", f"{path.name} is a lab run, which is never ranked")
        return digest, replay

    @staticmethod
    def _judge(entry: ScoreEntry, cached: dict) -> Check:
        """The verdict on an entry whose replay's claims and recomputed verdict are ``cached``."""
        claims = cached["claims"]
        if claims is None:
            return Check(False, cached["label"], cached["detail"])
        wanted = dict(claims)
        if entry.config_sha256 is None:  # a format 1 entry makes no claim about its rules
            wanted.pop("config_sha256")
            wanted.pop("ruleset")
        for key, value in wanted.items():
            if getattr(entry, key) != value:
                return Check(False, "NOT ITS REPLAY", f"the entry says {key} {getattr(entry, key)!r}, its replay "
                             f"{value!r}", claims["ruleset"])
        return Check(cached["ok"], cached["label"], cached["detail"], claims["ruleset"])


def _bad(exc: Exception) -> Check:
    reason = str(exc).splitlines()[0][:200] if str(exc) else type(exc).__name__
    return Check(False, "BAD REPLAY", reason)


def _recompute(replays: list[Replay],
               recompute: Callable[[Sequence[Replay]], list[tuple[bool, GameResult]]] | None) -> list[dict]:
    if replays and recompute is not None:
        try:
            return [_judged(replay, *outcome) for replay, outcome in zip(replays, recompute(replays), strict=True)]
        except Exception:  # e.g. one game's blow-up stopped the batch: find it one game at a time
            pass
    return [_verdict(replay) for replay in replays]


class TableBusyError(TableError):
    """The lock was not free within ``LOCK_WAIT`` seconds."""


def _read_all(fd: int) -> bytes:
    chunks = []
    size = 0
    while chunk := os.read(fd, 1 << 20):
        chunks.append(chunk)
        size += len(chunk)
        if size > MAX_TABLE_BYTES:
            raise TableError("the table grew past its size limit while being read; nothing was changed")
    return b"".join(chunks)


def _verdict(replay: Replay) -> dict[str, object]:
    try:
        ok, recomputed = replay.verify()
    except Exception as exc:  # a blow-up (NonFiniteState) or anything else the game raises
        return {"ok": False, "label": "BAD REPLAY", "detail": str(exc) or type(exc).__name__}
    return _judged(replay, ok, recomputed)


def _judged(replay: Replay, ok: bool, recomputed: GameResult) -> dict[str, object]:
    if ok:
        return {"ok": True, "label": "ok", "detail": ""}
    r = replay.result
    return {"ok": False, "label": "NOT REPRODUCED",
            "detail": f"recorded score {r.score}, the replay gives {recomputed.score} "
                      f"({plural(recomputed.hits, 'hit')}, {plural(recomputed.resets, 'reset')})"}


# ------------------------------------------------------------------ the verification cache

def default_cache_dir() -> Path | None:
    """``$ARMGAME_CACHE``, else ``$XDG_CACHE_HOME/armgame`` (``~/.cache/armgame``): written only by its user."""
    env = os.environ.get(CACHE_ENV)
    if env:
        return user_path(env, f"${CACHE_ENV}")
    base = os.environ.get("XDG_CACHE_HOME")
    if not base:
        try:
            base = str(Path.home() / ".cache")
        except RuntimeError:  # no home folder at all: no cache (a shared temporary folder could be planted)
            return None
    return Path(base) / "armgame"


class VerificationCache:
    """Verdicts of replays already recomputed, keyed by the replay's SHA-256 and the armgame version.

    It lives in the per-user cache folder, never beside a shared table: a classmate who can write
    the table's folder cannot plant an "ok". The file is read as hostile data like any other (a
    damaged cache is ignored), and a failure to write it only costs time.
    """

    FORMAT = "armgame-verified"
    MAX_BYTES = 64 * 1024 * 1024
    MAX_ITEMS = 200_000

    def __init__(self, folder: Path | None = None) -> None:
        self.folder = Path(folder) if folder is not None else default_cache_dir()
        self.path = self.folder / f"verified-{__version__}.json" if self.folder is not None else None
        #: Without a folder the cache lives only as long as the command.
        self._items: dict[str, dict] | None = None if self.path is not None else {}
        self._new: dict[str, dict] = {}

    def _load(self) -> dict[str, dict]:
        if self._items is None:
            self._items = {}
            try:
                data = parse_json(read_limited(self.path, self.MAX_BYTES, "cache file", follow=False))
                if isinstance(data, dict) and data.get("format") == self.FORMAT \
                        and data.get("version") == __version__ and isinstance(data.get("items"), dict):
                    self._items = {k: v for k, v in data["items"].items() if _HEX64.fullmatch(k) and _valid(v)}
            except (DataFileError, ValueError, UnicodeDecodeError):
                pass  # no cache, or a damaged one: everything is verified afresh
        return self._items

    def get(self, digest: str) -> dict | None:
        return self._new.get(digest) or self._load().get(digest)

    def put(self, digest: str, verdict: dict) -> None:
        self._new[digest] = verdict

    def save(self) -> None:
        if not self._new or self.folder is None or self.path is None:
            return
        items = {**self._load(), **self._new}
        if len(items) > self.MAX_ITEMS:
            items = dict(self._new)
        with contextlib.suppress(OSError, DataFileError):
            self.folder.mkdir(parents=True, exist_ok=True, mode=0o700)
            payload = {"format": self.FORMAT, "version": __version__, "items": items}
            atomic_write_bytes(self.path, json.dumps(payload, sort_keys=True, allow_nan=False).encode(), "cache")
        self._new = {}


def _valid(v: object) -> bool:
    if not (isinstance(v, dict) and isinstance(v.get("ok"), bool) and isinstance(v.get("label"), str)
            and isinstance(v.get("detail"), str)):
        return False
    claims = v.get("claims")
    return claims is None or (isinstance(claims, dict) and set(claims) == {
        "name", "driven", "driver", "score", "hits", "resets", "seed", "scene", "duration", "date",
        "config_sha256", "ruleset"})


# ------------------------------------------------------------------ the file

def parse_table(data: bytes) -> tuple[list[ScoreEntry], Damage | None]:
    """Entries of a table file, and the damage if it is not a clean table.

    A clean table yields all its entries. Otherwise every object in the text that passes
    the entry schema is recovered, wherever it sits (truncated tails, broken brackets).
    """
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("utf-8", errors="replace")
        return _salvage(text, "not UTF-8 text")
    try:
        table = parse_json(text)
    except ValueError as exc:
        return _salvage(text, str(exc))
    try:
        if not isinstance(table, dict) or table.get("format") != FORMAT:
            raise ValueError(f"not an armgame score table (no \"format\": \"{FORMAT}\")")
        check_keys("table", table, {"format", "format_version", "entries"})
        version = check_int("format_version", table["format_version"], 1, 10**6)
        if version not in READS_FORMATS:
            raise ValueError(f"table format {version} is not one this armgame reads "
                             f"({', '.join(map(str, READS_FORMATS))})")
        if not isinstance(table["entries"], list):
            raise ValueError("entries must be a list")
    except ValueError as exc:
        return _salvage(text, str(exc))
    entries: list[ScoreEntry] = []
    seen: set[str] = set()
    problem = None
    for i, item in enumerate(table["entries"]):
        try:
            entry = ScoreEntry.from_dict(item)
            if entry.id in seen:
                raise ValueError(f"id {entry.id} appears twice")
        except ValueError as exc:
            problem = problem or f"entry {i + 1}: {exc}"
            continue
        seen.add(entry.id)
        entries.append(entry)
    n = len(table["entries"])
    return entries, (Damage(problem, len(entries), n) if problem else None)


#: A flat JSON object (an entry has no nested values), strings honoured. Possessive quantifiers
#: never backtrack, so the scan is linear in the file's size whatever it holds.
_FLAT_OBJECT = re.compile(r'\{(?:[^{}"\[\]]++|"(?:[^"\\]++|\\.)*+")*+\}')


def _salvage(text: str, reason: str) -> tuple[list[ScoreEntry], Damage]:
    entries: list[ScoreEntry] = []
    seen: set[str] = set()
    for match in _FLAT_OBJECT.finditer(text):
        try:
            entry = ScoreEntry.from_dict(STRICT_DECODER.decode(match.group()))
        except (ValueError, RecursionError):
            continue
        if entry.id not in seen:
            seen.add(entry.id)
            entries.append(entry)
    return entries, Damage(reason, len(entries), len(entries))


def table_bytes(entries: list[ScoreEntry]) -> bytes:
    """The table file: one entry a line, best first, so it reads (and diffs) as a list."""
    lines = [json.dumps(e.as_dict(), sort_keys=True, ensure_ascii=False, allow_nan=False)
             for e in sorted(entries, key=sort_key)]
    head = json.dumps({"format": FORMAT, "format_version": FORMAT_VERSION})[:-1]
    return (head + ', "entries": [\n' + ",\n".join(lines) + "\n]}\n").encode("utf-8")
