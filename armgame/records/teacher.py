"""The teacher's record of a table: what a classmate could edit in a shared table's file, kept where only
the teacher's account writes.

A class shares one table folder, which every member can write. The table's file says which seed ranks
and in which order its entries came (``entered``: ties and duplicates go to the earlier entry), and a
classmate can edit both: change the seed to one they play well, or plant a copy of a rival's game with
``"entered": 1`` so that the rival's entry becomes the later duplicate. So the account that starts a
table (``armgame scores --new``) keeps its own record of it, in a file of its own:

* the seed it started the table with;
* each entry it entered there itself (``play --name``, ``scores --add``, the window's end screen): the
  entry's id, its replay's SHA-256 and its game's digest, with the record's own number for it (1, 2,
  ...) and the time.

Reading the table on that account, the record wins where the two disagree: the record's seed ranks, and
the order of entry is the record's: the entries it knows, in its order, then every entry it does not know
(entered from another account, or planted), in the table's order. A planted copy can therefore never
come before a game this account entered, whatever ``entered`` it claims or lacks. Each disagreement is
said in one line. An account that did not start the table (a student's, or anyone's own table) has no
record of it and reads the table as it says.

Where: beside the verification cache (``cache.default_cache_dir``, ``--cache DIR``, ``$ARMGAME_CACHE``),
one file a table, named by the SHA-256 of the table folder's resolved path; the folder's device and
inode are kept too, and a folder found replaced at that path is reported (the record still applies:
it is all this account knows of the table). Trust: the record is read and written only under the
verification cache's rules (``cache.private_place_reason``: the folder and the file this user's alone,
never in or beside the table's folder); otherwise it is ignored with a one-line note. Deleting the
cache folder forgets the records: the tables are then read as they say.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any, Protocol, TypeVar

from ..limits import MAX_TABLE_BYTES, MAX_TABLE_ENTRIES
from ..valid import COUNT_MAX, HEX32, HEX64, INT64_MAX, check_date, check_int, check_keys
from .cache import private_place_reason, usable_cache_dir
from .storage import DataFileError, atomic_write_bytes, parse_json, read_limited

RECORD_FORMAT = "armgame-table-record"
RECORD_VERSION = 1
#: The most entries one record keeps: a table's limit, twice (entries deleted from the table stay known).
MAX_RECORDED = 2 * MAX_TABLE_ENTRIES


class _Entry(Protocol):
    @property
    def id(self) -> str: ...

    @property
    def replay_sha256(self) -> str: ...


E = TypeVar("E", bound=_Entry)


@dataclass(frozen=True)
class Recorded:
    """An entry this account entered: its replay and game, its number in the record's order, and when."""

    id: str
    replay_sha256: str
    game_sha256: str | None
    order: int
    at: str


@dataclass(frozen=True)
class RecordData:
    """What the record holds of one table."""

    seed: int
    folder: str
    device: int
    inode: int
    started: str
    entries: dict[str, Recorded]

    def knows(self, entry: _Entry) -> Recorded | None:
        """The record of ``entry``: the same entry id with the same replay, else None."""
        known = self.entries.get(entry.id)
        return known if known is not None and known.replay_sha256 == entry.replay_sha256 else None

    def as_json(self) -> bytes:
        return json.dumps({
            "format": RECORD_FORMAT, "format_version": RECORD_VERSION, "folder": self.folder,
            "device": self.device, "inode": self.inode, "seed": self.seed, "started": self.started,
            "entries": [[r.id, r.replay_sha256, r.game_sha256, r.order, r.at]
                        for r in sorted(self.entries.values(), key=lambda r: r.order)],
        }, allow_nan=False).encode()


def _parse_record(data: bytes) -> RecordData:
    """A record file's contents; raises ValueError naming the first bad field (it is read as hostile data)."""
    top = check_keys("record", parse_json(data), {"format", "format_version", "folder", "device", "inode", "seed",
                                                  "started", "entries"})
    if top["format"] != RECORD_FORMAT or top["format_version"] != RECORD_VERSION:
        raise ValueError(f"not a table record of format {RECORD_VERSION}")
    folder = top["folder"]
    if not isinstance(folder, str) or not 0 < len(folder) <= 4096:
        raise ValueError("folder must be a path")
    items = top["entries"]
    if not isinstance(items, list) or len(items) > MAX_RECORDED:
        raise ValueError(f"entries must be a list of at most {MAX_RECORDED:,}")
    entries: dict[str, Recorded] = {}
    for item in items:
        if not (isinstance(item, list) and len(item) == 5):
            raise ValueError("an entry must be [id, replay_sha256, game_sha256, order, at]")
        id_, replay, game, order, at = item
        if not (isinstance(id_, str) and HEX32.fullmatch(id_) and isinstance(replay, str) and HEX64.fullmatch(replay)
                and (game is None or (isinstance(game, str) and HEX64.fullmatch(game)))):
            raise ValueError(f"entry {id_!r}: not an entry id, replay digest and game digest")
        entries[id_] = Recorded(id_, replay, game, check_int("order", order, 1, COUNT_MAX), check_date("at", at))
    return RecordData(check_int("seed", top["seed"], 0, INT64_MAX), folder,
                      check_int("device", top["device"], 0, 2**64), check_int("inode", top["inode"], 0, 2**64),
                      check_date("started", top["started"]), entries)


class TeacherRecord:
    """This account's record of the table in ``table_folder``, kept in ``folder`` (None: the verification
    cache's, ``cache.default_cache_dir``). ``warn`` receives one-line notes. Reading and writing never
    raise: a record that cannot be used is said once and left out (the table is read as it says)."""

    def __init__(self, table_folder: Path, folder: Path | None = None,
                 warn: Callable[[str], None] | None = None) -> None:
        self.table_folder = Path(table_folder)
        self.warn = warn or (lambda message: None)
        self.folder = Path(folder) if folder is not None else usable_cache_dir(self.warn, "the teacher's record")
        self._loaded = False
        self._data: RecordData | None = None
        self._said: set[str] = set()

    def _say(self, message: str) -> None:
        if message not in self._said:
            self._said.add(message)
            self.warn(message)

    def _where(self) -> tuple[Path, str] | None:
        """The record's file and the table folder's resolved path, or None where there can be no record."""
        if self.folder is None:
            return None
        try:
            resolved = str(self.table_folder.resolve())
        except (OSError, RuntimeError):
            return None
        key = hashlib.sha256(resolved.encode("utf-8", "surrogateescape")).hexdigest()[:32]
        return self.folder / f"table-{key}.json", resolved

    def _distrust(self, path: Path) -> str | None:
        assert self.folder is not None
        return private_place_reason(self.folder, path, [self.table_folder])

    def load(self, fresh: bool = False) -> RecordData | None:
        """The record of the table, or None if this account has none it can trust (said once why)."""
        if self._loaded and not fresh:
            return self._data
        self._loaded, self._data = True, None
        where = self._where()
        if where is None:
            return None
        path, resolved = where
        if not (path.exists() or path.is_symlink()):
            return None
        reason = self._distrust(path)
        if reason is not None:
            self._say(f"note: this account's record of the table in {self.table_folder} is not trusted "
                      f"({reason}): ignored, the table is read as it says")
            return None
        try:
            data = _parse_record(read_limited(path, MAX_TABLE_BYTES, "table record", follow=False))
        except (DataFileError, ValueError, UnicodeDecodeError, RecursionError) as exc:
            self._say(f"note: this account's record of the table in {self.table_folder} ({path}) cannot be read "
                      f"({str(exc).splitlines()[0][:200] if str(exc) else type(exc).__name__}): ignored, the "
                      f"table is read as it says")
            return None
        if data.folder != resolved:  # another folder's record under this name: never applied
            return None
        with contextlib.suppress(OSError):
            st = os.stat(self.table_folder)
            if (st.st_dev, st.st_ino) != (data.device, data.inode):
                self._say(f"note: {self.table_folder} is not the folder this account started its table in (it was "
                          f"replaced or restored): this account's record of the table is applied all the same")
        self._data = data
        return data

    def start(self, seed: int) -> None:
        """Start the record of a table just started with ``seed``; an older record of the folder is kept aside."""
        where = self._where()
        if where is None:
            return
        path, resolved = where
        try:
            st = os.stat(self.table_folder)
        except OSError:
            return
        data = RecordData(seed, resolved, st.st_dev, st.st_ino, _now(), {})
        if (path.exists() or path.is_symlink()) and self._distrust(path) is None:
            aside = path.with_name(f"{path.name}.replaced-{datetime.now(UTC).strftime('%Y%m%dT%H%M%SZ')}")
            try:
                os.replace(path, aside)
            except OSError as exc:
                self._say(f"note: this account's earlier record of the table in {self.table_folder} cannot be kept "
                          f"aside ({exc.strerror or exc}): it is left as it was, and the new table has none")
                return
            self._say(f"note: this account's earlier record of the table in {self.table_folder} is kept as {aside}")
        self._write(path, data)

    def entered(self, entries: Sequence[Any]) -> None:
        """Record the entries this account just entered in the table (each with its ``id``, ``replay_sha256``,
        ``game_sha256`` and ``entered_at``), if it keeps a record of the table: one write for them all."""
        data = self.load(fresh=True)
        where = self._where()
        if data is None or where is None or not entries:
            return
        recorded = dict(data.entries)
        order = max((r.order for r in recorded.values()), default=0)
        for e in entries:
            if len(recorded) >= MAX_RECORDED or order >= COUNT_MAX:
                self._say(f"note: this account's record of the table in {self.table_folder} is full "
                          f"({len(recorded):,} entries): new entries are not recorded")
                break
            order += 1
            recorded[e.id] = Recorded(e.id, e.replay_sha256, e.game_sha256, order, e.entered_at or _now())
        data = RecordData(data.seed, data.folder, data.device, data.inode, data.started, recorded)
        if self._write(where[0], data):
            self._data = data

    def _write(self, path: Path, data: RecordData) -> bool:
        assert self.folder is not None
        reason = self._distrust(path)
        if reason is None:
            try:
                self.folder.mkdir(parents=True, exist_ok=True, mode=0o700)
                reason = self._distrust(path)  # created just now: checked again
                if reason is None:
                    atomic_write_bytes(path, data.as_json(), "table record")
                    os.chmod(path, 0o600)  # whatever the umask: a group-writable record is not trusted next time
                    return True
            except (OSError, DataFileError) as exc:
                reason = f"{getattr(exc, 'strerror', None) or exc}"
        self._say(f"note: this account's record of the table in {self.table_folder} cannot be kept ({reason}): "
                  f"the table's own file is all there is")
        return False


def in_recorded_order(entries: Iterable[E], data: RecordData, file_order: Callable[[E], Any]) -> list[E]:
    """``entries`` in the record's order of entry: those it knows by its numbers, then the rest by ``file_order``."""
    known: list[tuple[int, E]] = []
    unknown: list[E] = []
    for e in entries:
        found = data.knows(e)
        if found is not None:
            known.append((found.order, e))
        else:
            unknown.append(e)
    known.sort(key=lambda pair: pair[0])
    unknown.sort(key=file_order)
    return [e for _, e in known] + unknown


def disagreements(entries: Sequence[Any], data: RecordData, file_order: Callable[[Any], Any]) -> list[str]:
    """One line for each way the table's order of entry disagrees with the record where it counts.

    * the entries the record knows are in another order in the table;
    * the table places an entry the record does not know before one it knows with the same score (a tie),
      game or replay (a duplicate): the planted copy with ``"entered": 1``. Entries entered from other
      accounts, earlier but not tied, are no disagreement: every class that enters from several machines
      has them;
    * entries the record knows are no longer in the table as entered (deleted, or their replay changed).
    """
    by_file = sorted(entries, key=file_order)
    known = [(data.knows(e), e) for e in by_file]
    in_file = [e.id for r, e in known if r is not None]
    in_record = [e.id for r, e in sorted(((r, e) for r, e in known if r is not None), key=lambda pair: pair[0].order)]
    notes = []
    moved = sum(a != b for a, b in zip(in_file, in_record, strict=True))
    if moved:
        notes.append(f"the table's order of entry was changed for {moved} of the {len(in_file)} entries this "
                     f"account entered: ranked in this account's order (its record of the table)")
    last: dict[tuple[str, object], int] = {}  # a score, game or replay: the last place in the file of a known one
    for i, (r, e) in enumerate(known):
        if r is not None:
            for key in _tie_keys(e):
                last[key] = i
    ahead = sum(1 for i, (r, e) in enumerate(known)
                if r is None and any(last.get(key, -1) > i for key in _tie_keys(e)))
    if ahead:
        notes.append(f"{ahead} {'entry' if ahead == 1 else 'entries'} this account did not enter "
                     f"{'is' if ahead == 1 else 'are'} placed by the table before a tied or identical game it "
                     f"entered: {'it counts' if ahead == 1 else 'they count'} after the games this account entered "
                     f"(its record of the table)")
    lost = len(data.entries) - len(in_file)
    if lost:
        notes.append(f"{lost} of the {len(data.entries)} games this account entered in the table "
                     f"{'is' if lost == 1 else 'are'} no longer in it as entered (deleted, or changed by hand)")
    return notes


def _tie_keys(e: Any) -> list[tuple[str, object]]:
    keys: list[tuple[str, object]] = [("score", e.score), ("replay", e.replay_sha256)]
    if e.game_sha256 is not None:
        keys.append(("game", e.game_sha256))
    return keys


def _now() -> str:
    return datetime.now(UTC).isoformat(timespec="seconds")
