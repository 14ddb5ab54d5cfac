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
lock to clean up. The new table is written to a temporary file in the same folder,
fsynced and renamed over the old one (``armgame.records.storage.atomic_write_bytes``): readers
need no lock, since they always see a whole table, old or new. An append-only log would
need partial-line recovery and a compaction step that is itself such a rewrite.

Trust: the table is parsed as data with a schema check of every field. A damaged table
(truncated, not JSON, an entry failing its checks) is never overwritten silently: the next
write first renames it to ``scores.json.corrupt-<UTC time>``, says so in one line, and
keeps every valid entry it can find. An entry names its replay file and the file's
SHA-256, so a score typed into the table, a replay edited, or replays swapped between
entries all show up when ``check`` recomputes the game.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import sys
import uuid
from collections.abc import Callable, Iterator
from dataclasses import asdict, dataclass, fields
from datetime import UTC, datetime
from pathlib import Path

from ..game.session import GameResult
from .replay import (
    DRIVEN,
    MAX_REPLAY_BYTES,
    Replay,
    check_date,
    check_name,
    check_word,
    now_iso,
)
from .storage import (
    STRICT_DECODER,
    DataFileError,
    atomic_write_bytes,
    check_float,
    check_int,
    check_keys,
    check_str,
    parse_json,
    read_limited,
)

SCORES_ENV = "ARMGAME_SCORES"
TABLE_NAME = "scores.json"
LOCK_NAME = "scores.lock"
REPLAYS_DIR = "replays"
FORMAT = "armgame-scores"
FORMAT_VERSION = 1
MAX_TABLE_BYTES = 32 * 1024 * 1024
_COUNT_MAX = 10**9
_REPLAY_FILE = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,150}\.json")
_HEX64 = re.compile(r"[0-9a-f]{64}")
_HEX32 = re.compile(r"[0-9a-f]{32}")


def default_scores_dir() -> Path:
    """Where the table lives unless ``--scores`` says otherwise.

    ``$ARMGAME_SCORES`` if set; else the checkout's own ``scores/`` folder when armgame runs
    from a checkout (an editable install included); else the per-user data folder:
    ``$XDG_DATA_HOME/armgame/scores`` (``~/.local/share/armgame/scores``), or
    ``%LOCALAPPDATA%\\armgame\\scores`` on Windows.
    """
    env = os.environ.get(SCORES_ENV)
    if env:
        return Path(env).expanduser()
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

    def as_dict(self) -> dict[str, object]:
        return asdict(self)

    @property
    def when(self) -> datetime:
        return datetime.fromisoformat(self.date)

    @property
    def how(self) -> str:
        return f"{self.driven} ({self.driver})" if self.driver else self.driven

    @classmethod
    def from_dict(cls, data: object) -> ScoreEntry:
        """Check every field; raises ValueError naming the first bad one."""
        d = check_keys("entry", data, {f.name for f in fields(cls)})
        driven = check_str("driven", d["driven"], 20)
        if driven not in DRIVEN:
            raise ValueError(f"driven must be one of {', '.join(DRIVEN)}, got {driven!r}")
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
        )
        if entry.score > entry.hits:
            raise ValueError(f"score {entry.score} is more than the hits {entry.hits}")
        if entry.name != d["name"]:
            raise ValueError(f"name {d['name']!r} has surrounding spaces")
        return entry


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
    """What recomputing an entry's game says: ``ok``, or a short label and why not."""

    ok: bool
    label: str
    detail: str = ""


@dataclass(frozen=True)
class Damage:
    reason: str
    recovered: int
    found: int

    def describe(self, path: Path) -> str:
        entries = "1 valid entry" if self.recovered == 1 else f"{self.recovered} valid entries"
        return f"{path} is damaged ({self.reason}); {entries} recovered"


class ScoreTable:
    """The table in ``folder``; ``warn`` receives one-line notices (a damaged table, say)."""

    def __init__(self, folder: Path, warn: Callable[[str], None] | None = None) -> None:
        self.folder = Path(folder)
        self.path = self.folder / TABLE_NAME
        self.lock_path = self.folder / LOCK_NAME
        self.replays = self.folder / REPLAYS_DIR
        self.warn = warn or (lambda message: print(message, file=sys.stderr))

    # ------------------------------------------------------------------ reading
    def read(self) -> tuple[list[ScoreEntry], Damage | None]:
        """The valid entries, unsorted, and what is wrong with the file if anything. No side effects."""
        try:
            data = read_limited(self.path, MAX_TABLE_BYTES, "score table")
        except DataFileError as exc:
            if not self.path.exists():
                return [], None
            return [], Damage(str(exc).removeprefix(f"{self.path}: "), 0, 0)
        return parse_table(data)

    def entries(self) -> list[ScoreEntry]:
        """Valid entries, best first; a damaged file is reported through ``warn``."""
        entries, damage = self.read()
        if damage:
            self.warn(damage.describe(self.path) + "; the file will be kept aside at the next save")
        return sorted(entries, key=sort_key)

    # ------------------------------------------------------------------ writing
    @contextlib.contextmanager
    def _locked(self) -> Iterator[None]:
        import fcntl  # POSIX only; imported here so reading the table works everywhere

        self.folder.mkdir(parents=True, exist_ok=True)
        fd = os.open(self.lock_path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
            yield
        finally:
            os.close(fd)  # closing drops the lock

    def add(self, replay: Replay) -> ScoreEntry:
        """Save ``replay`` beside the table and enter its game; returns the new entry."""
        if replay.player is None:
            raise ValueError("a game enters the table under a player's name")
        if not replay.complete:
            raise ValueError("only a game played to the end enters the table")
        entry_id = uuid.uuid4().hex
        data = replay.to_bytes()
        r = replay.result
        stamp = replay.date or now_iso()
        slug = re.sub(r"[^A-Za-z0-9]+", "-", replay.player).strip("-")[:24] or "player"
        file_name = f"{datetime.fromisoformat(stamp).strftime('%Y%m%dT%H%M%S')}-{slug}-{entry_id[:8]}.json"
        entry = ScoreEntry.from_dict(dict(
            id=entry_id, name=replay.player, driven=replay.driven, driver=replay.driver, score=r.score,
            hits=r.hits, resets=r.resets, seed=r.seed, scene=r.scene, duration=r.duration, date=stamp,
            version=replay.version, replay=file_name, replay_sha256=hashlib.sha256(data).hexdigest(),
        ))
        self.replays.mkdir(parents=True, exist_ok=True)
        # The replay first: a crash in between leaves a spare replay, never an entry without one.
        atomic_write_bytes(self.replays / file_name, data)
        with self._locked():
            # Under the lock nobody else is writing the table: any temporary file of it was left by a
            # writer that died mid-write (the kill leaves no chance to clean up). Replays are written
            # outside the lock, so their temporary files are left alone.
            for stale in self.folder.glob(f".{TABLE_NAME}.*.tmp"):
                with contextlib.suppress(OSError):
                    stale.unlink()
            entries, damage = self.read()
            if damage:
                kept = self._set_aside()
                self.warn(f"{damage.describe(self.path)}; the damaged file is kept as {kept.name}")
            entries.append(entry)
            atomic_write_bytes(self.path, table_bytes(entries))
        return entry

    def _set_aside(self) -> Path:
        stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%SZ")
        for n in range(1000):
            kept = self.folder / f"{TABLE_NAME}.corrupt-{stamp}{f'-{n}' if n else ''}"
            if not kept.exists():
                break
        os.replace(self.path, kept)
        return kept

    def rank(self, entry: ScoreEntry) -> int:
        ordered = self.entries()
        return next((i for i, e in enumerate(ordered, 1) if e.id == entry.id), len(ordered))

    # ------------------------------------------------------------------ trust
    def replay_path(self, entry: ScoreEntry) -> Path:
        return self.replays / entry.replay

    def check(self, entry: ScoreEntry) -> Check:
        """Whether the entry's replay is the one it names and reproduces its game."""
        found = self.claimed_replay(entry)
        if isinstance(found, Check):
            return found
        return self.reproduced(found, *found.verify())

    def claimed_replay(self, entry: ScoreEntry) -> Replay | Check:
        """The entry's replay if it is the one the entry names, else the failed ``Check``; not yet replayed.

        ``check`` is this and ``reproduced``; split so that many entries' replays can be
        recomputed in one batch (``records.batch_verify``).
        """
        path = self.replay_path(entry)
        try:
            data = read_limited(path, MAX_REPLAY_BYTES, "replay file")
        except DataFileError as exc:
            return Check(False, "REPLAY MISSING" if not path.exists() else "REPLAY UNREADABLE", str(exc))
        if hashlib.sha256(data).hexdigest() != entry.replay_sha256:
            return Check(False, "REPLAY CHANGED", f"{path.name} is not the replay this entry was saved with")
        try:
            replay = Replay.from_bytes(data, str(path))
        except DataFileError as exc:
            return Check(False, "BAD REPLAY", str(exc))
        r = replay.result
        claimed = {"name": replay.player, "score": r.score, "hits": r.hits, "resets": r.resets, "seed": r.seed,
                   "scene": r.scene, "duration": r.duration, "driven": replay.driven}
        for key, value in claimed.items():
            if getattr(entry, key) != value:
                return Check(False, "NOT ITS REPLAY",
                             f"the entry says {key} {getattr(entry, key)!r}, its replay {value!r}")
        return replay

    @staticmethod
    def reproduced(replay: Replay, ok: bool, recomputed: GameResult) -> Check:
        """The verdict on a replay whose game was recomputed as ``recomputed`` (``ok``: the same outcome)."""
        r = replay.result
        if not ok:
            return Check(False, "NOT REPRODUCED",
                         f"recorded score {r.score}, the replay gives {recomputed.score} "
                         f"({recomputed.hits} hits, {recomputed.resets} resets)")
        return Check(True, "ok")


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
        if version != FORMAT_VERSION:
            raise ValueError(f"table format {version} is not one this armgame reads ({FORMAT_VERSION})")
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


def _salvage(text: str, reason: str) -> tuple[list[ScoreEntry], Damage]:
    decoder = STRICT_DECODER
    entries: list[ScoreEntry] = []
    seen: set[str] = set()
    i = text.find("{")
    while i != -1:
        try:
            item, end = decoder.raw_decode(text, i)
            entry = ScoreEntry.from_dict(item)
        except (ValueError, RecursionError):
            i = text.find("{", i + 1)
            continue
        if entry.id not in seen:
            seen.add(entry.id)
            entries.append(entry)
        i = text.find("{", end)
    return entries, Damage(reason, len(entries), len(entries))


def table_bytes(entries: list[ScoreEntry]) -> bytes:
    """The table file: one entry a line, best first, so it reads (and diffs) as a list."""
    lines = [json.dumps(e.as_dict(), sort_keys=True, ensure_ascii=False, allow_nan=False)
             for e in sorted(entries, key=sort_key)]
    head = json.dumps({"format": FORMAT, "format_version": FORMAT_VERSION})[:-1]
    return (head + ', "entries": [\n' + ",\n".join(lines) + "\n]}\n").encode("utf-8")
