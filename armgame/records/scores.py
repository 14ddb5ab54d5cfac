"""The high-score table: entries that are never lost, each backed by the replay it came from.

``ScoreTable`` is the table a command reads and adds to. It is three things, each in its module:
``entry`` (``ScoreEntry``: what an entry says, each field checked), ``tablefile`` (the file: read,
parsed or salvaged, written whole under its lock, its head and counters) and ``checking`` (each entry
checked against its replay, within a cost counted beforehand). Here: which list an entry goes to, its
rank, and the table as this account's record of it has it (``records.teacher``). The names the
commands and tests import from here are imported from those modules below.

Which list an entry goes to (``ScoreTable.list_of``), the first that applies:

* ``programs``: a game that says a program drove it (a bot, a script, or anything but the
  keyboard with no driver named). A replay cannot prove a human pressed the keys: this only
  keeps the games that declare themselves programs out of the people's ranking.
* ``custom``: a game whose rules are not a ranked ruleset (``armgame.records.rulesets``).
* ``practice``: a keyboard game of the standard rules with another seed than the table's
  (``seed`` in the table's head, the default game's unless ``armgame scores --new --seed N``
  set it): shopping for an easy seed does not pay.
* ``ranked``: the rest, keyboard games of the standard rules and the table's seed.

One game enters once: each entry holds its game's digest (``armgame.records.identity``), and a
second entry of the same game is refused, whoever's name and whatever date it carries. A digest
stays the one the armgame that entered it computed: an entry is judged against its replay's digest
by that identity version (``identity.names_its_game``), so a new version flags no old entry. Ties
are broken by the order of entry, a counter the table keeps under its lock (``entered``),
never by the date a player's file claims; on the account that started the table, by that
account's own record of it, whatever the file says.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import shlex
import sys
import uuid
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path

from ..files import user_data_dir
from ..limits import DEFAULT_SEED, MAX_REPLAY_BYTES
from .cache import VerificationCache, default_cache_dir, file_signature  # noqa: F401 (the cache's old home)
from .checking import (  # noqa: F401 (imported from here by the commands and tests)
    HIT_WORK,
    NOT_CHECKED,
    RANKED_HIT_WORK,
    Check,
    TableChecks,
    not_checked_detail,
    replay_work,
)
from .entry import ScoreEntry, entry_order, replay_claims, sort_key
from .identity import game_digests
from .journalmend import mend_journal
from .replay import EVENT_WORK, Replay, now_iso  # noqa: F401 (EVENT_WORK: imported from here, as HIT_WORK)
from .rulesets import CUSTOM, RULESETS, ruleset_by_digest
from .standings import one_row_per_player, rank_of
from .storage import DataFileError, atomic_write_many, read_limited, user_path
from .tablefile import (  # noqa: F401 (imported from here by the commands and tests)
    LOCK_NAME,
    LOCK_WAIT,
    REPLAYS_DIR,
    TABLE_NAME,
    TableBusyError,
    TableError,
    TableFile,
)
from .tableformat import (  # noqa: F401 (imported from here by the commands and tests)
    FORMAT,
    FORMAT_VERSION,
    READS_FORMATS,
    Damage,
    TableHead,
    parse_table,
    parse_with_head,
    table_bytes,
)
from .teacher import disagreements, in_recorded_order

SCORES_ENV = "ARMGAME_SCORES"

#: The lists an entry can go to (``ScoreTable.list_of``), in the order ``armgame scores`` prints them.
RANKED, PRACTICE, PROGRAMS, CUSTOM_GAMES = "ranked", "practice", "programs", "custom"
LIST_TITLES = {
    RANKED: "the ranked table",
    PRACTICE: "practice (another seed than the table's: not ranked)",
    PROGRAMS: "programs (bots and scripts: listed apart, never ranked)",
    CUSTOM_GAMES: "custom games (their own rules: not ranked)",
}


def default_scores_dir() -> Path:
    """Where the table lives unless ``--scores`` says otherwise.

    ``$ARMGAME_SCORES`` if set; else the checkout's own ``scores/`` folder when armgame runs
    from a checkout (an editable install included); else the platform's per-user data folder
    (``platformdirs``): ``$XDG_DATA_HOME/armgame/scores`` (``~/.local/share/armgame/scores``) on
    Linux, ``~/Library/Application Support/armgame/scores`` on macOS,
    ``%LOCALAPPDATA%\\armgame\\scores`` on Windows.
    """
    env = os.environ.get(SCORES_ENV)
    if env:
        return user_path(env, f"${SCORES_ENV}")
    root = Path(__file__).resolve().parents[2]
    if (root / "pyproject.toml").is_file() and (root / "scores").is_dir():
        return root / "scores"
    return user_data_dir() / "scores"


class ScoreTable(TableFile, TableChecks):
    """The table in ``folder``; ``warn`` receives one-line notices (a damaged table, say).

    ``records``: the folder of this account's records of tables (``records.teacher``; None: the
    verification cache's folder). Where this account started the table, its record decides the seed
    and the order of entry, whatever the file says (``read``)."""

    def __init__(self, folder: Path, warn: Callable[[str], None] | None = None,
                 cache: VerificationCache | None = None, records: Path | None = None) -> None:
        if records is None and cache is not None:
            records = cache.folder
        super().__init__(folder, warn or (lambda message: print(message, file=sys.stderr)), records)
        self.cache = cache
        if cache is not None:
            cache.guard(self.folder)
        #: One line for each way the table disagrees with this account's record, or of a seed that is not valid.
        self.notes: list[str] = []
        self._said: set[str] = set()

    def read(self) -> tuple[list[ScoreEntry], Damage | None]:
        """The valid entries, unsorted, and what is wrong with the file if anything. No side effects.

        A table that is not a regular file or is over the size limit raises ``TableError``:
        it is not damage, and nothing may be written over it.
        """
        data = self._file_bytes()
        if data is None:
            return [], None
        entries, damage, head = parse_with_head(data, self._replay_backs())
        entries, _, damage = self._with_journal(entries, damage)
        entries, self._seed, self.notes = self._as_recorded(entries, head)
        return entries, damage

    def _as_recorded(self, entries: list[ScoreEntry], head: TableHead) -> tuple[list[ScoreEntry], int, list[str]]:
        """The entries as this account's record of the table has them (``records.teacher``), the seed
        that ranks and the notes: without a record, the table as it says. With one, the entries are
        numbered 1, 2, ... in the record's order of entry (those it knows first; the others after, in the
        table's order), so that every tie and duplicate goes by the record."""
        record = self.record.load()
        if record is None:
            if head.seed is not None:
                return entries, head.seed, []
            return entries, DEFAULT_SEED, [f"the table's seed {head.seed_problem}: games are ranked as the default "
                                           f"seed {DEFAULT_SEED} until \"seed\" is set in {self.path}"]
        notes = []
        if head.seed is None:
            notes.append(f"the table's seed {head.seed_problem}; ranking seed {record.seed} (this account's record "
                         f"of the table)")
        elif head.seed != record.seed:
            notes.append(f"the table's seed was changed from {record.seed} to {head.seed}; ranking seed "
                         f"{record.seed} (this account's record of the table)")
        notes += disagreements(entries, record, entry_order)
        ordered = in_recorded_order(entries, record, entry_order)
        renumbered = []
        for i, e in enumerate(ordered, 1):
            known = record.knows(e)
            renumbered.append(replace(e, entered=i, entered_at=known.at if known is not None else e.entered_at))
        return renumbered, record.seed, notes

    @property
    def seed(self) -> int:
        """The seed this table ranks: this account's record's, else its head's (the default game's for a
        table without one, or whose seed is not valid: ``notes`` says so)."""
        if self._seed is None:
            with contextlib.suppress(DataFileError):
                self.read()
            self._seed = DEFAULT_SEED if self._seed is None else self._seed
        return self._seed

    def all_entries(self) -> list[ScoreEntry]:
        """Every valid entry, in any list, best first; a damaged file and the ``notes`` are reported
        through ``warn`` (a note once)."""
        entries, damage = self.read()
        if damage:
            self.warn(damage.describe(self.path) + "; the file will be kept aside at the next save")
        for note in self.notes:
            self._say(note)
        return sorted(entries, key=sort_key)

    def _say(self, note: str) -> None:
        if note not in self._said:
            self._said.add(note)
            self.warn(note)

    def entries(self) -> list[ScoreEntry]:
        """The ranked entries (keyboard games of a ranked ruleset and the table's seed), best first."""
        return [e for e in self.all_entries() if self.list_of(e) == RANKED]

    def ruleset(self, entry: ScoreEntry, check: Check | None = None) -> str:
        """The ruleset an entry plays: its own claim (``check`` compares it with its replay).

        An entry carried over from a format 1 table makes no claim: its check (or a cached one)
        says what its replay plays; unchecked, it counts as a custom game. Its replay is never
        read just to list it: a planted table of old entries cannot make listing read each replay.
        """
        if entry.config_sha256 is not None:
            found = ruleset_by_digest(entry.config_sha256)
            return found.name if found and found.name == entry.ruleset else CUSTOM
        if check is not None and check.ruleset is not None:
            return check.ruleset
        cached = self.cache.get(entry.replay_sha256) if self.cache is not None else None
        if cached is not None and cached["claims"] is not None:
            return cached["claims"]["ruleset"]
        return CUSTOM

    def list_of(self, entry: ScoreEntry, check: Check | None = None) -> str:
        """Which list the entry goes to: ``ranked``, ``practice``, ``programs`` or ``custom`` (module docstring)."""
        if entry.program:
            return PROGRAMS
        if self.ruleset(entry, check) not in RULESETS:
            return CUSTOM_GAMES
        if entry.seed != self.seed:
            return PRACTICE
        return RANKED

    def add(self, replay: Replay, replay_path: Path | None = None) -> ScoreEntry:
        """Save ``replay`` beside the table and enter its game; returns the new entry.

        Raises ``TableBusyError`` (the replay is saved; ``armgame scores --add`` enters it later) or
        ``TableError``/``ValueError`` with nothing changed.
        """
        _enterable(replay)
        # The replay first: a crash in between leaves a spare replay, never an entry without one.
        self._safe_folder()
        path = replay_path or self.save_replay(replay)
        data = read_limited(path, MAX_REPLAY_BYTES, "replay file", follow=False)
        entry = _new_entry(replay, path.name, data)
        try:
            with self._locked():
                result = self._enter_many([(entry, frozenset(game_digests(replay)))])[0]
            if isinstance(result, Exception):
                raise result
            return result
        except TableBusyError as exc:
            later = shlex.join(["armgame", "scores", "--scores", str(self.folder), "--add", str(path)])
            raise TableBusyError(f"{exc}; your game's replay is kept as {path}: enter it later with {later}") from None

    def add_many(self, replays: Sequence[Replay], digests: Sequence[Sequence[str]] | None = None,
                 journal: bool = False) -> list[ScoreEntry | ValueError]:
        """``add`` for many games at once, for a server taking a class's games: their replays written with
        one folder fsync, the table read and written once under the lock. Returns, for each game, its
        entry or the ValueError (a ``TableError`` for a game already in) that kept it out; raises
        ``TableError`` (busy, over a limit, not a safe place) with none entered. ``digests``: each game's
        ``identity.game_digests``, where the caller computed them already (a quarter of a class server's
        work was computing them again). ``journal``: the entries are appended to the table's journal, not
        written into a whole new table (``tablefile``: what a server taking many games a second does; durable
        alike, and its cost does not grow with the table)."""
        results: list[tuple[ScoreEntry, frozenset[str]] | ValueError] = []
        files: dict[str, bytes] = {}
        for i, replay in enumerate(replays):
            try:
                _enterable(replay)
                data = replay.to_bytes()
                sha256 = hashlib.sha256(data).hexdigest()  # once: the file's name and the entry's replay_sha256
                name = self._replay_name(replay, sha256)
                known = game_digests(replay) if digests is None else tuple(digests[i])
                results.append((_new_entry(replay, name, data, known, sha256), frozenset(known)))
                files[name] = data
            except ValueError as exc:
                results.append(exc)
        self._safe_folder()
        atomic_write_many([(self.replays / name, data) for name, data in files.items()], "replay")
        entries = [r for r in results if not isinstance(r, ValueError)]
        with self._locked():
            entered = iter(self._append(entries) if journal else self._enter_many(entries))
        return [r if isinstance(r, ValueError) else next(entered) for r in results]

    def compact(self, mend: bool = False) -> None:
        """``TableFile.compact``; with ``mend``, the journal is first mended from the replays where a line of it was
        damaged (``journalmend``: each notice through ``warn``). A class's server mends as it starts, where a journal
        is one a kill left (a clean stop takes it in); checking each line's replay costs about a millisecond a
        student's game, which its stop does not spend again on the lines it wrote itself."""
        if not mend:
            super().compact()
            return
        if not os.path.lexists(self.journal_path):
            return
        with self._locked():
            table = self._file_bytes()
            entries = parse_with_head(table, self._replay_backs())[0] if table is not None else []
            for line in mend_journal(self.journal_path, self.replays, {e.replay_sha256 for e in entries},
                                     {e.id for e in entries}, _new_entry):
                self.warn(line)
            self._enter_many([])

    def new(self, seed: int) -> None:
        """Start the table (empty) ranking ``seed``; refused if it already holds entries."""
        self._safe_folder()
        with self._locked():
            self._enter_many([], seed)

    def of_list(self, name: str, entries: list[ScoreEntry] | None = None) -> list[ScoreEntry]:
        """The entries of one list (``list_of``), best first: the entries one game is compared with.
        ``entries``: ``all_entries()`` already read (the table is not read again)."""
        return [e for e in (self.all_entries() if entries is None else entries) if self.list_of(e) == name]

    def rank(self, entry: ScoreEntry) -> int:
        """The place of the entry's player in its list, one row a player (``standings``): #3 is the third
        place, ranked by their best game, whichever of theirs this entry is (equal scores share a place).
        Unchecked, like ``of_list``."""
        rows = one_row_per_player(self.of_list(self.list_of(entry)))
        return rank_of(rows, entry.name) or len(rows)


def _enterable(replay: Replay) -> None:
    """Refuse a game that can never enter a table: no player's name, a lab run, a game stopped early."""
    if replay.player is None:
        raise ValueError("a game enters the table under a player's name")
    if replay.task is not None:
        raise ValueError("a lab run is not a game: it never enters the high-score table")
    if not replay.complete:
        raise ValueError("only a game played to the end enters the table")


def _new_entry(replay: Replay, replay_name: str, data: bytes, digests: Sequence[str] | None = None,
               sha256: str | None = None) -> ScoreEntry:
    """The entry of ``replay``, whose file ``replay_name`` in replays/ holds ``data`` (not yet entered); ``sha256``:
    the digest of ``data``, where the caller has it already."""
    claims = replay_claims(replay, digests)
    r = replay.result
    return ScoreEntry.from_dict(dict(
        id=uuid.uuid4().hex, name=replay.player, driven=replay.driven, driver=replay.driver, score=r.score,
        hits=r.hits, resets=r.resets, seed=r.seed, scene=r.scene, duration=r.duration,
        date=replay.date or now_iso(), version=replay.version, replay=replay_name,
        replay_sha256=sha256 or hashlib.sha256(data).hexdigest(), ruleset=claims["ruleset"],
        config_sha256=claims["config_sha256"], game_sha256=claims["game_sha256"], complete=True,
    ))
