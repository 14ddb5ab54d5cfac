"""Which of a high-score table's entries a listing replays, which count in its lists and which are flagged.

``listing`` decides it, for ``armgame scores`` (which only prints what it returns): best first, each
list's rows until it has as many as it shows, the entries below a player's row counted unread, copies
of a game flagged (``identity.FirstEntries`` says which of two counts), a costly game listed apart
(``COSTLY``) until ``armgame verify`` checks it. The cost's bounds are here: ``MAX_CHECK_WORK`` (one
game's) and ``MIN_BATCH`` (how many are recomputed together).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from .batch_verify import check_entries
from .checking import NOT_CHECKED, Check
from .entry import ScoreEntry, sort_key
from .identity import FirstEntries
from .scores import CUSTOM_GAMES, LIST_TITLES, ScoreTable
from .standings import PlayerRow, one_row_per_player, player_key

__all__ = ["COSTLY", "MAX_CHECK_WORK", "MIN_BATCH", "Listed", "Lists", "listing"]

#: The most work ``scores`` spends recomputing one game, in physics steps of the compiled loop
#: (``records.checking.replay_work``: steps, 100 a claimed hit under a ranked ruleset and 6,000 under others,
#: 20 an input event): about 0.13 s. Three times the largest honest game measured: the model bot's standard
#: game of seed 18, 333,900 (15,000 steps, 50 hits, 15,695 events); the naive bot's largest is 64,720 and
#: a keyboard player pressing each of the four keys 20 times a second 214,960 (``python
#: benchmarks/honest_work.py``: both bots on seeds 0 to 41). A game of more (a long clock, a "hit storm"
#: claiming thousands of hits, a replay of 100,000 events) is listed apart, not checked yet and not ranked:
#: ``armgame verify`` checks it, whatever it costs, and the next listing has its verdict.
MAX_CHECK_WORK = 1_000_000
#: The rows of ``listing`` left unchecked for their cost (one a game): listed apart, neither flagged nor ranked.
COSTLY = "costly"
#: The fewest entries ``listing`` checks together (batches recompute many games at once): a list still
#: wanting rows checks at least this many of the entries below, not one game at a time.
MIN_BATCH = 256

#: A listed game: its entry and what checking it said (None: not replayed).
Listed = tuple[ScoreEntry, Check | None]
#: Each list's rows by list name (``scores.LIST_TITLES``'s, and ``COSTLY``).
Lists = dict[str, list[PlayerRow[Listed]]]


def listing(table: ScoreTable, entries: Sequence[ScoreEntry], limit: int | None, check: bool,
            per_player: bool = True) -> tuple[Lists, list[tuple[ScoreEntry, Check]]]:
    """Each list's rows best first, at most ``limit`` each, and the flagged entries ``(entry, check)``.

    A row is a ``standings.PlayerRow`` whose ``best`` is ``(entry, check)``: with ``per_player``, one a
    player (``standings.one_row_per_player``), their best game that checks out and how many games they
    played in that list; else one a game (``games`` 1), as ``--all-games`` lists them.

    Cost: no replay is read without ``check``. With it, entries are checked best first, in batches
    (``records.batch_verify``), only while a list still wants rows: at most ``limit`` rows (players) of
    each list of standard games (each costs exactly its ruleset's steps, once per user: verdicts,
    failures too, are cached), and at most ``limit`` custom games, flagged ones included (their cost
    is their own). Once a player has a row, their entries below it are not replayed (but for those in
    the batch that found it, checked together). So a row's
    ``games`` is the player's entries in its list less those found flagged (a check failed, or a copy of
    an earlier game): with a limit, their games below the best count as entered; with none (``--all``:
    every entry is checked), only games that check out count. Which of two entries of one game counts,
    and which is the copy, is ``records.identity.FirstEntries``'s to say; the entries flagged are those
    met on the way. A game whose replay costs more than ``MAX_CHECK_WORK`` is a row of ``lists[COSTLY]``
    (one a game): not checked yet, so neither flagged nor ranked.
    """
    walk = _Walk(table, limit, per_player)
    pending = sorted(entries, key=sort_key)
    size = max(2 * limit, MIN_BATCH) if limit else max(1, len(pending))

    def check_batch(batch: list[ScoreEntry]) -> None:
        results = check_entries(table, batch, MAX_CHECK_WORK) if check else ((e, None) for e in batch)
        walk.take(results)

    # One pass, best first: an entry its list no longer wants now is never wanted later (lists only fill).
    batch: list[ScoreEntry] = []
    custom_in_batch = 0
    for e in pending:
        if not walk.wants(e, custom_in_batch):
            continue
        batch.append(e)
        custom_in_batch += table.list_of(e) == CUSTOM_GAMES
        if len(batch) >= size:
            walk.custom_checked += custom_in_batch  # counted as listed before the check: an old entry's may rank it
            check_batch(batch)
            batch, custom_in_batch = [], 0
    if batch:
        check_batch(batch)
    return walk.lists(), walk.flagged


class _Walk:
    """What a listing has found so far, walking the entries best first: each list's counted games and the
    players with a row in it, the flagged entries and the costly ones."""

    def __init__(self, table: ScoreTable, limit: int | None, per_player: bool) -> None:
        self.table = table
        self.limit = limit
        self.per_player = per_player
        self.first: FirstEntries[ScoreEntry] = FirstEntries()
        self.counted: dict[str, list[Listed]] = {name: [] for name in LIST_TITLES}  # each list's games
        self.players: dict[str, set[str]] = {name: set() for name in LIST_TITLES}  # who has a row, by list
        self.flagged: list[tuple[ScoreEntry, Check]] = []
        self.costly: list[PlayerRow[Listed]] = []
        #: The custom games sent to be checked (in batches already sent).
        self.custom_checked = 0

    def who(self, e: ScoreEntry) -> str:
        return player_key(e.name) if self.per_player else e.id

    def wants(self, e: ScoreEntry, custom_in_batch: int) -> bool:
        """Whether ``e`` is to be checked (``custom_in_batch``: the custom games in the batch being filled);
        an entry not wanted is flagged (a copy of a replay file already counted) or counted unread."""
        twin = self.first.counted_file(e.replay_sha256)
        if twin is not None:  # a replay file already counted: the copy is flagged unread
            self.flagged.append((e, duplicate(twin)))
            return False
        name = self.table.list_of(e)
        limit = self.limit
        if limit is None:
            return True
        if self.who(e) in self.players[name]:  # their row is found: a game below it is counted, not replayed
            self.counted[name].append((e, None))
            return False
        if name == CUSTOM_GAMES:  # each may cost up to MAX_GAME_STEPS: never more than --top of them
            return self.custom_checked + custom_in_batch < limit
        return len(self.players[name]) < limit

    def take(self, results: Iterable[Listed]) -> None:
        """A batch's entries with their checks (None: not checked), in order: each counted, flagged or costly."""
        limit, players = self.limit, self.players
        for e, c in results:
            name = self.table.list_of(e, c)
            if limit is not None and name != CUSTOM_GAMES and len(players[name]) >= limit \
                    and self.who(e) not in players[name]:
                continue
            # Unchecked (--no-check), an entry is taken at its word: the earlier of two counts.
            twin = self.first.copy_of(e, e.replay_sha256, None if c is None else c.game, c is None or c.ok)
            if c is not None and c.label == NOT_CHECKED:
                self.costly.append(PlayerRow(e.name, (e, c), 1))  # honest or not, nobody knows yet: verify checks it
            elif c is not None and not c.ok:
                self.flagged.append((e, c))
            elif twin is not None:
                self.flagged.append((e, duplicate(twin)))
            else:
                players[name].add(self.who(e))
                self.counted[name].append((e, c))

    def lists(self) -> Lists:
        lists: Lists = {}
        for name, games in self.counted.items():
            games.sort(key=lambda game: sort_key(game[0]))
            lists[name] = (one_row_per_player(games, lambda game: game[0].name) if self.per_player
                           else [PlayerRow(e.name, (e, c), 1) for e, c in games])
        lists[COSTLY] = self.costly
        return lists


def duplicate(twin: ScoreEntry) -> Check:
    """The check of an entry that copies ``twin``'s game, which counts: flagged, naming it."""
    when = (twin.entered_at or twin.date)[:16].replace("T", " ")
    return Check(False, "DUPLICATE", f"the same game as {twin.name}'s entry of {when}, which counts")
