"""The class's two lists (students, programs) as the projector ranks them, kept up to date as games arrive.

One row a player (``records.standings``' rule), best first: the clerk adds each game it enters (``add``), its
answer to the student reads their place from here (``rank``, ``row``: a binary search, not a pass over every
entry the table holds), and the views read the rows in order (``each``, ``rows``). Changed only on the clerk's
thread, like everything the clerk keeps.
"""

from __future__ import annotations

import bisect
from collections.abc import Iterable, Iterator

from ..records.scores import ScoreEntry, sort_key
from ..records.standings import PlayerRow, player_key


class Board:
    """One list's rows, one a player, best first (``standings.one_row_per_player`` of the list), kept up to
    date as entries arrive: a player's rank is a binary search, not a pass over every entry."""

    def __init__(self, best_first: Iterable[ScoreEntry] = (), renamed: dict[str, str] | None = None) -> None:
        self._rows: dict[str, PlayerRow] = {}
        self._order: list[tuple[tuple, str]] = []  # (sort_key of the row's best, its player's key), sorted
        #: Names the teacher changed (``Roster.renamed``: the old name's key to the name now shown): a renamed
        #: student's games from before and after are one row, under the new name.
        self.renamed = renamed or {}
        for entry in best_first:
            self.add(entry)

    def __len__(self) -> int:
        return len(self._order)

    def add(self, entry: ScoreEntry) -> None:
        name = self.renamed.get(player_key(entry.name), entry.name)
        key = player_key(name)
        row = self._rows.get(key)
        if row is None:
            self._rows[key] = PlayerRow(name, entry, 1)
            bisect.insort(self._order, (sort_key(entry), key))
        elif sort_key(entry) < sort_key(row.best):  # a new best: the row moves, under the best game's name
            del self._order[bisect.bisect_left(self._order, (sort_key(row.best), key))]
            self._rows[key] = PlayerRow(name, entry, row.games + 1)
            bisect.insort(self._order, (sort_key(entry), key))
        else:
            self._rows[key] = PlayerRow(row.name, row.best, row.games + 1)

    def rank(self, key: str) -> int:
        """The 1-based place of the player whose ``player_key`` is ``key`` (who has a row)."""
        return bisect.bisect_left(self._order, (sort_key(self._rows[key].best), key)) + 1

    def row(self, rank: int) -> PlayerRow:
        return self._rows[self._order[rank - 1][1]]

    def each(self) -> Iterator[PlayerRow]:
        """The rows best first, one at a time: the projector's standings stop at their 60th."""
        for _, key in self._order:
            yield self._rows[key]

    def rows(self, first: int | None = None) -> list[PlayerRow]:
        """The rows best first (the ``first`` ones only, if given)."""
        return [self._rows[key] for _, key in self._order[:first]]
