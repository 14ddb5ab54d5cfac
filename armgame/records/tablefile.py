"""The table's file: read, parsed (or salvaged), written whole under a lock, with its head and counters.

Storage, in one folder (see ``scores.default_scores_dir``)::

    scores.json           the table: JSON, one entry a line
    scores.lock           locked by whoever writes the table (``records.locking``)
    replays/*.json        one replay per entry, named by the entry

Why one file under a lock rather than an append-only log with a merge: the table stays
one small, readable JSON file a teacher can open, and every change is all or nothing. A
change is read-modify-write under an exclusive lock on ``scores.lock`` (``flock`` on Linux and
macOS, ``LockFileEx`` on Windows: ``armgame.records.locking``), so two games finishing at the
same moment queue for a few milliseconds and both entries land; the kernel drops the lock
when its holder exits, even by SIGKILL, so there is no stale lock to clean up. A writer waits
at most ``LOCK_WAIT`` seconds for the lock, then says the table is busy; the game's replay
is already saved and ``armgame scores --add`` enters it later. The new table is written to a
temporary file in the same folder, fsynced and renamed over the old one
(``armgame.records.storage``): readers need no lock, since they always see a whole table,
old or new.

The journal: a server that takes a class's games (``ScoreTable.add_many(..., journal=True)``) does not
rewrite the whole table for each game, which cost it more with every entry. Under the same lock it appends
each new entry as one line to ``scores.journal`` beside the table and fsyncs it (and the folder, when the
journal is new) before it answers, so what it acknowledged survives a kill as the table's own write does.
Every reader reads the table and then the journal's lines; a last line without its newline is a write that
a kill cut off (never acknowledged: left out, and cut off by the next append). The next whole write of the
table (another ``add``, or ``compact``, which the class server runs at its start and its stop) takes the
journal's entries into ``scores.json``, and only then removes the journal: a kill in between leaves entries
in both, which are one entry (one id) to every reader. The journal is only appended to a clean table
(no damage, no planted counter or seed, every entry numbered); otherwise the whole table is written, which
repairs or sets aside what it must, as before. A class's server, as it starts, first mends a damaged journal line
from the replay it names (``ScoreTable.compact(mend=True)``, ``journalmend``), or names it to the teacher.

Trust: the table's bytes are parsed as data (``records.tableformat``). A damaged table is never overwritten
silently: the next write first copies its bytes to ``scores.json.corrupt-<UTC time>``, then writes the new table
with every valid entry it could find, and only that rename retires the damaged file; if anything fails, the table
stays as it was. A valid table is never set aside: one over the size limit is refused whole (no entry added) rather
than dropped. A planted counter is repaired at the next write, and a table that would not read back as written is
never written (``_reads_back``).
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import stat
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

from ..errors import UserError
from ..files import _BINARY, _CLOEXEC, _NOFOLLOW
from ..limits import DEFAULT_SEED, MAX_REPLAY_BYTES, MAX_TABLE_BYTES, MAX_TABLE_ENTRIES
from ..valid import COUNT_MAX
from ..words import plural
from .entry import ScoreEntry
from .locking import LockBusyError, LockError, file_lock
from .replay import Replay, now_iso
from .storage import (
    DataFileError,
    atomic_write_bytes,
    check_path_length,
    copy_aside,
    fsync_folder,
    open_regular,
    parse_json,
    read_limited,
)
from .tableformat import (
    Damage,
    TableHead,
    entry_line,
    journal_entries,
    numbered,
    parse_with_head,
    table_bytes,
)
from .teacher import TeacherRecord

TABLE_NAME = "scores.json"
JOURNAL_NAME = "scores.journal"
LOCK_NAME = "scores.lock"
REPLAYS_DIR = "replays"
#: The most replay bytes one read of a table hashes to tell which of two entries sharing an id is the table's.
MAX_TWIN_BYTES = 4 * MAX_REPLAY_BYTES
#: Seconds a writer waits for the table's lock before saying the table is busy.
LOCK_WAIT = 5.0
#: The longest path the table makes inside its folder, in bytes, with room: a replay's temporary file,
#: ``/replays/.YYYYmmddTHHMMSS-<24>-<8>.json.<12>.tmp`` (81).
_FOLDER_ROOM = 96


class TableError(DataFileError):
    """The table cannot be changed (busy, over its limits, not a safe place): nothing was changed."""


class TableBusyError(TableError):
    """The lock was not free within ``LOCK_WAIT`` seconds."""


class TableFile:
    """The table's file in ``folder``, and the one way it is written (``_enter``, under its lock).

    ``warn`` receives one-line notices; ``records``: the folder of this account's records of tables
    (``records.teacher``; None: the verification cache's), told of each entry this account enters."""

    def __init__(self, folder: Path, warn: Callable[[str], None], records: Path | None = None) -> None:
        self.folder = Path(folder)
        self.path = self.folder / TABLE_NAME
        self.journal_path = self.folder / JOURNAL_NAME
        self.lock_path = self.folder / LOCK_NAME
        #: The lock file's permissions: everyone's for a table classmates share, the owner's for a live class's.
        self.lock_mode = 0o666
        self.replays = self.folder / REPLAYS_DIR
        self.warn = warn
        self.record = TeacherRecord(self.folder, records, warn)
        self._seed: int | None = None
        self._index: _Index | None = None  # what the journal's appender knows of the table (``_append``)

    def _replay_backs(self) -> Callable[[ScoreEntry], bool]:
        """Whether an entry's replay file in ``replays/`` is the one it names (its SHA-256) and was played
        under the entry's name (a copy of an honest entry with another name names the same file): asked
        only of entries sharing an id (``parse_with_head``), each file read once, and at most ``MAX_TWIN_BYTES`` of
        them per read, so a table planted full of twins costs a bounded read."""
        seen: dict[str, tuple[str, object] | None] = {}
        left = MAX_TWIN_BYTES

        def backs(entry: ScoreEntry) -> bool:
            nonlocal left
            if entry.replay not in seen:
                if left <= 0:
                    return False
                try:
                    data = read_limited(self.replays / entry.replay, MAX_REPLAY_BYTES, "replay", follow=False)
                    left -= len(data)
                    player = parse_json(data).get("player")
                except (DataFileError, OSError, ValueError, AttributeError):
                    seen[entry.replay] = None
                else:
                    seen[entry.replay] = (hashlib.sha256(data).hexdigest(), player)
            found = seen[entry.replay]
            return found is not None and found == (entry.replay_sha256, entry.name)

        return backs

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

    def _file_bytes(self) -> bytes | None:
        """The table file's bytes, or None if there is none (``_open_table``'s refusals raise)."""
        fd = self._open_table()
        if fd is None:
            return None
        with os.fdopen(fd, "rb") as f:
            return f.read(MAX_TABLE_BYTES + 1)

    def _safe_folder(self) -> None:
        """Create the folder and replays/; refuse a replays/ or scores.lock planted as a symlink, or a folder
        too deep for the file system to name the files made in it."""
        try:
            check_path_length(self.folder, "the table's folder", _FOLDER_ROOM)
        except UserError as exc:
            raise TableError(str(exc)) from None
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
        wait = LOCK_WAIT if wait is None else wait
        try:
            with file_lock(self.lock_path, wait, self.lock_mode):
                yield
        except LockBusyError:
            raise TableBusyError(f"the table in {self.folder} is busy (another program has held its "
                                 f"lock for {wait:g} s)") from None
        except LockError as exc:
            raise TableError(f"{self.lock_path}: cannot take the lock: {exc}") from None

    def save_replay(self, replay: Replay) -> Path:
        """Save the replay in replays/ (before the table is touched); returns its path."""
        self._safe_folder()
        data = replay.to_bytes()
        path = self.replays / self._replay_name(replay, hashlib.sha256(data).hexdigest())
        try:
            if read_limited(path, MAX_REPLAY_BYTES, "replay file", follow=False) == data:
                return path  # already there, byte for byte
        except DataFileError:
            pass
        atomic_write_bytes(path, data, "replay")
        return path

    @staticmethod
    def _replay_name(replay: Replay, sha256: str) -> str:
        """A replay's file name in replays/: its date, its player and its bytes' digest (``sha256``, hex; never a
        name a file or a client gave)."""
        stamp = replay.date or now_iso()
        slug = name_slug(replay.player or "")
        when = datetime.fromisoformat(stamp).strftime("%Y%m%dT%H%M%S")
        return f"{when}-{slug}-{sha256[:8]}.json"

    def _enter_many(self, new_entries: Sequence[tuple[ScoreEntry, frozenset[str]]], seed: int | None = None
                    ) -> list[ScoreEntry | TableError]:
        """Under the lock: write the table with ``new_entries`` added in order (each its place in the order
        of entry and the time given here; a game already in is refused, as its TableError), or, with
        ``seed``, an empty table ranking that seed. Returns each entry as entered, or why not. Each entry
        comes with its game's digests by every identity version (``identity.game_digests``)."""
        # Under the lock nobody else is writing the table: any temporary file of it was left by a
        # writer that died mid-write. Replays are written outside the lock, so theirs are left alone.
        for stale in self.folder.glob(f".{TABLE_NAME}.*.tmp"):
            with contextlib.suppress(OSError):
                if stat.S_ISREG(os.lstat(stale).st_mode):
                    stale.unlink()
        fd = self._open_table()
        try:
            if fd is None:
                entries, damage, head = [], None, TableHead()
            else:
                data = _read_all(fd)
                entries, damage, head = parse_with_head(data, self._replay_backs())
            entries, journaled, damage = self._with_journal(entries, damage)
            self._index = None  # the appender reads the table again after a whole write
            record = self.record.load(fresh=True)  # under the lock: what this account's last write left
            if seed is not None:
                if entries:
                    raise TableError(f"{self.path} already holds {plural(len(entries), 'entry')}: a new table "
                                     f"needs its own folder (--scores DIR); nothing was changed")
                head = TableHead(seed=seed, next_entry=head.next_entry)
                record = None  # the new table's record is started below
            notes = []
            ranked, kept_seed = head.seed, head.kept_seed
            if record is not None and head.seed != record.seed:
                was = f"was changed from {record.seed} to {head.seed}" if head.seed is not None \
                    else head.seed_problem
                notes.append(f"the table's seed {was}: this account's record of the table puts seed {record.seed} "
                             f"back")
                ranked = record.seed
            elif ranked is None:
                notes.append(f"the table's seed {head.seed_problem}: kept as it is (nothing here chooses a seed for "
                             f"the table); games are ranked as the default seed {DEFAULT_SEED} until \"seed\" is "
                             f"set in {self.path}")
            entries, next_entry, counter_note = numbered(entries, head, len(new_entries))
            if counter_note is not None:
                notes.append(counter_note)
            self._seed = DEFAULT_SEED if ranked is None else ranked
            results: list[ScoreEntry | TableError] = []
            for entry, digests in new_entries:
                try:
                    entry = self._admit(entry, entries, next_entry, digests)
                except TableError as exc:
                    results.append(exc)
                    continue
                entries.append(entry)
                results.append(entry)
                next_entry += 1
            if len(entries) > MAX_TABLE_ENTRIES:
                raise TableError(f"the table holds {len(entries) - 1} entries, its limit: not entered (nothing was "
                                 f"dropped; start a new table with --scores)")
            new = table_bytes(entries, ranked, next_entry, kept_seed)
            if len(new) > MAX_TABLE_BYTES:
                raise TableError("the table would grow past its size limit: not entered (nothing was dropped)")
            _reads_back(new, entries, ranked, next_entry)
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
            journal = os.path.lexists(self.journal_path)
            if journal:  # its entries are in the table now: a kill before this leaves them in both, one entry
                if damage is not None:  # its bytes kept, as a damaged table's are
                    with contextlib.suppress(OSError, DataFileError):
                        journal_fd = open_regular(self.journal_path, "table journal", follow=False)
                        try:
                            copy_aside(journal_fd, self.folder / f"{JOURNAL_NAME}.corrupt-"
                                       f"{datetime.now(UTC).strftime('%Y%m%dT%H%M%SZ')}")
                        finally:
                            os.close(journal_fd)
                self.journal_path.unlink()
                fsync_folder(self.folder)
            if seed is not None:
                self.record.start(seed)
            elif record is not None:
                unknown = [e for e in journaled if record.knows(e) is None]  # appended: recorded now, in order
                self.record.entered(sorted(unknown, key=lambda e: e.entered or 0)
                                    + [e for e in results if isinstance(e, ScoreEntry)])
            if damage is not None:
                where = f"; the damaged file is kept as {kept.name}" if kept else ""
                self.warn(f"{damage.describe(self.path)}{where}")
            for note in notes:
                self.warn(note)
            return results
        finally:
            if fd is not None:
                os.close(fd)

    @staticmethod
    def _admit(entry: ScoreEntry, entries: list[ScoreEntry], place: int, digests: frozenset[str]) -> ScoreEntry:
        """``entry`` with its place in the order of entry; refused if its game or replay is already in
        (its game by any identity version's digest: an entry taken before a bump holds the older one)."""
        twin = next((e for e in entries if e.replay_sha256 == entry.replay_sha256
                     or (e.game_sha256 is not None and e.game_sha256 in digests)), None)
        if twin is not None:
            when = (twin.entered_at or twin.date)[:16].replace("T", " ")
            raise TableError(f"this game is already in the table: entered by {twin.name} on {when} UTC "
                             f"(entry #{twin.entered}); a game enters once, whoever's name it carries")
        return ScoreEntry(**{**entry.as_dict(), "entered": place,
                             "entered_at": datetime.now(UTC).isoformat(timespec="seconds")})

    # ------------------------------------------------------------------ the journal
    def _journal_data(self) -> bytes:
        """The journal's bytes (b"" if there is none). Never follows a symlink; over the table's size limit it
        is refused like the table."""
        try:
            mode = os.lstat(self.journal_path).st_mode
        except FileNotFoundError:
            return b""
        except OSError as exc:
            raise TableError(f"{self.journal_path}: cannot read: {exc.strerror or exc}") from None
        if not stat.S_ISREG(mode):
            raise TableError(f"{self.journal_path}: is not a regular file (a symbolic link is not followed)")
        try:
            return read_limited(self.journal_path, MAX_TABLE_BYTES, "table journal", follow=False)
        except DataFileError as exc:
            raise TableError(str(exc)) from None

    def _with_journal(self, entries: list[ScoreEntry], damage: Damage | None
                      ) -> tuple[list[ScoreEntry], list[ScoreEntry], Damage | None]:
        """The table's entries and the journal's after them (an entry already in the table by its id is one
        entry: a kill between a compaction's write and the journal's removal); the journal's own entries; and
        the damage, the journal's bad lines counted in it."""
        journal, problem, found = journal_entries(self._journal_data())
        ids = {e.id for e in entries}
        fresh = [e for e in journal if e.id not in ids]
        if problem is not None:
            reason = f"{JOURNAL_NAME}: {problem}"
            damage = Damage(reason if damage is None else f"{damage.reason}; {reason}",
                            len(entries) + len(fresh), (damage.found if damage else len(entries)) + found)
        return entries + fresh, fresh, damage

    def compact(self) -> None:
        """Take the journal's entries into ``scores.json`` (one whole write under the lock) and remove it; nothing
        to do without a journal. A class's server runs it at its start and its stop."""
        if not os.path.lexists(self.journal_path):
            return
        with self._locked():
            self._enter_many([])

    def _signature(self) -> tuple:
        """What tells the appender the table and the journal are as it left them (another writer's whole write
        makes a new file; another append, a longer journal)."""
        def of(path: Path) -> tuple | None:
            try:
                st = os.lstat(path)
            except FileNotFoundError:
                return None
            return st.st_ino, st.st_size, st.st_mtime_ns, st.st_mode
        return of(self.path), of(self.journal_path)

    def _load_index(self) -> _Index | None:
        """Under the lock: the table and its journal read whole, once; None if the journal may not be appended
        to (damage, a planted counter or seed, an entry without its place, this account's record of another
        seed): the whole table is written then, as ``_enter_many`` does."""
        fd = self._open_table()
        if fd is None:
            return None
        try:
            data = _read_all(fd)
        finally:
            os.close(fd)
        entries, damage, head = parse_with_head(data, self._replay_backs())
        entries, _, damage = self._with_journal(entries, damage)
        record = self.record.load(fresh=True)
        if (damage is not None or head.seed is None or head.counter_problem is not None
                or any(e.entered is None for e in entries) or (record is not None and record.seed != head.seed)):
            return None
        last = max([0, *(e.entered or 0 for e in entries)])
        next_entry = max(head.next_entry, last + 1)
        if next_entry + MAX_TABLE_ENTRIES > COUNT_MAX:  # near the counter's end: the whole write renumbers
            return None
        self._seed = head.seed
        return _Index(self._signature(), {e.replay_sha256 for e in entries},
                      {e.game_sha256: e for e in entries if e.game_sha256 is not None}, next_entry, len(entries))

    def _append(self, new_entries: Sequence[tuple[ScoreEntry, frozenset[str]]]) -> list[ScoreEntry | TableError]:
        """Under the lock: ``_enter_many``'s entries appended to the journal, fsynced, without rewriting the
        table; the whole write where the journal may not be used (``_load_index``)."""
        index = self._index if self._index is not None and self._index.signature == self._signature() else None
        if index is None:
            index = self._index = self._load_index()
        if index is None:
            return self._enter_many(new_entries)
        results: list[ScoreEntry | TableError] = []
        lines: list[bytes] = []
        shas, games, place = set(index.replays), dict(index.games), index.next_entry
        for entry, digests in new_entries:
            twin = next((games[d] for d in digests if d in games), None)
            if entry.replay_sha256 in shas or twin is not None:
                twin = twin or next(e for e in games.values() if e.replay_sha256 == entry.replay_sha256)
                when = (twin.entered_at or twin.date)[:16].replace("T", " ")
                results.append(TableError(f"this game is already in the table: entered by {twin.name} on {when} "
                                          f"UTC (entry #{twin.entered}); a game enters once, whoever's name it "
                                          f"carries"))
                continue
            entry = ScoreEntry(**{**entry.as_dict(), "entered": place,
                                  "entered_at": datetime.now(UTC).isoformat(timespec="seconds")})
            line = entry_line(entry).encode("utf-8") + b"\n"
            back, problem, _ = journal_entries(line)
            if problem is not None or back != [entry]:
                raise TableError(f"the table's journal line would not read back ({problem or 'another entry'}): "
                                 f"not entered, nothing was changed")
            shas.add(entry.replay_sha256)
            if entry.game_sha256 is not None:
                games[entry.game_sha256] = entry
            lines.append(line)
            results.append(entry)
            place += 1
        if not lines:
            return results
        count = index.count + len(lines)
        if count > MAX_TABLE_ENTRIES:
            raise TableError(f"the table holds {index.count} entries, its limit: not entered (nothing was "
                             f"dropped; start a new table with --scores)")
        table_size = (index.signature[0] or (0, 0))[1]
        journal_size = (index.signature[1] or (0, 0))[1]
        if table_size + journal_size + sum(map(len, lines)) > MAX_TABLE_BYTES:
            raise TableError("the table would grow past its size limit: not entered (nothing was dropped)")
        self._write_journal(b"".join(lines))
        self._index = _Index(self._signature(), shas, games, place, count)
        return results

    def _write_journal(self, data: bytes) -> None:
        """Append ``data`` (whole lines) to the journal and fsync it, and its folder if the journal is new. A cut
        last line (a writer killed mid-append, never acknowledged) is cut off first, so no line is ever joined
        to it."""
        flags = os.O_RDWR | os.O_CREAT | _NOFOLLOW | _CLOEXEC | _BINARY  # read too: its last byte
        new = not os.path.lexists(self.journal_path)
        try:
            fd = os.open(self.journal_path, flags, 0o666)
        except OSError as exc:
            raise TableError(f"{self.journal_path}: cannot write: {exc.strerror or exc}") from None
        end = 0
        try:
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                raise TableError(f"{self.journal_path}: is not a regular file")
            # lseek and read rather than pread: Windows has no pread.
            end = os.lseek(fd, 0, os.SEEK_END)
            if end:
                os.lseek(fd, end - 1, os.SEEK_SET)
                if os.read(fd, 1) != b"\n":
                    os.lseek(fd, 0, os.SEEK_SET)
                    end = _read_all(fd).rfind(b"\n") + 1
                    os.ftruncate(fd, end)
            os.lseek(fd, end, os.SEEK_SET)
            view = memoryview(data)
            while view:
                view = view[os.write(fd, view):]
            os.fsync(fd)
        except OSError as exc:
            with contextlib.suppress(OSError):
                os.ftruncate(fd, end)  # nothing of this write is left to be read as entered
            raise TableError(f"{self.journal_path}: cannot write: {exc.strerror or exc}") from None
        finally:
            os.close(fd)
        if new:
            fsync_folder(self.folder)

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


def _reads_back(new: bytes, entries: list[ScoreEntry], seed: int | None, next_entry: int) -> None:
    """Refuse to write a table that would not read back as written: every entry, its seed, its counter.

    Whatever a planted value did to the counters, a table that the next read would call damaged (and set
    aside, with entries dropped) is never written."""
    back, damage, head = parse_with_head(new)
    problem = (damage.reason if damage is not None
               else f"{len(back)} of {len(entries)} entries" if len(back) != len(entries)
               else f"next_entry {head.next_entry}, not {next_entry}" if head.next_entry != next_entry
               or head.counter_problem is not None
               else f"seed {head.seed}, not {seed}" if head.seed != seed
               else None)
    if problem is not None:
        raise TableError(f"the table as it would be written does not read back ({problem}): not entered, "
                         f"nothing was changed")


def _read_all(fd: int) -> bytes:
    chunks = []
    size = 0
    while chunk := os.read(fd, 1 << 20):
        chunks.append(chunk)
        size += len(chunk)
        if size > MAX_TABLE_BYTES:
            raise TableError("the table grew past its size limit while being read; nothing was changed")
    return b"".join(chunks)


@dataclass(frozen=True)
class _Index:
    """What the journal's appender knows of the table at ``signature`` (``TableFile._signature``): its replays'
    digests, its games by digest, the next place in the order of entry and how many entries it holds."""

    signature: tuple
    replays: set[str]
    games: dict[str, ScoreEntry]
    next_entry: int
    count: int


def name_slug(name: str) -> str:
    """A player's name as part of a file name armgame makes: ASCII letters and digits joined by dashes,
    at most 24 characters ("player" if nothing is left). A name never becomes a path."""
    return re.sub(r"[^A-Za-z0-9]+", "-", name).strip("-")[:24] or "player"
