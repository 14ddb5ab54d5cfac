"""One row per player: the standings a class reads, each player's best game and how many they played.

A table holds games; a class ranks people. ``one_row_per_player`` folds a best-first list of games
into one row a player, in the order of each player's best game, so one keen student cannot fill the
top of the table. ``armgame scores`` (each of its lists, unless ``--all-games``), ``play`` and
``scores --add`` ("#3 in the ranked table": the third place, ``ScoreTable.rank``) and the play
window's end screen (``rank_of``; before a name is typed, ``place_of_new``) all ask it, so "your
rank" means the same thing everywhere.

Equal scores share a place, and the places after them skip as many: 1, 2, 2, 4 (standard competition
ranking; ``places``). The projector, a round's winners, a hand-in's answer, the end screens and
``armgame scores`` all number their rows so. A place names no row, so the row that is a player's own
is found by their name (``row_of``), never by the place: two players tied at 2nd are two rows.

Players are told apart by ``player_key``: two names a projector shows alike are one player. The name
as typed, compatibility-normalised (NFKC: a full-width "Ａlice" is "Alice"), case-folded, its spaces
collapsed ("Ann  B" is "Ann B"), and its letters of other scripts that are drawn like a Latin letter
read as that letter (a Cyrillic "Аnn" is "Ann"; ``LOOKALIKES``), so "alice", "Alice " and "Аlice" are
one player, and a classmate cannot stand on the projector as a second "Ann". The name shown is always
the one typed.
"""

from __future__ import annotations

import unicodedata
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Generic, TypeVar

T = TypeVar("T")


#: After case folding, the letters of Cyrillic and Greek drawn, in capital or small form, like a Latin letter
#: (Unicode's confusables, UTS #39, for the letters of these two scripts that fonts draw alike), and the
#: digits drawn like letters. Not "I" and "l": alike in sans-serif capitals, but no case-blind key can
#: part "Eli" from "Ell" and still join "Ian" with "ian".
LOOKALIKES = str.maketrans({
    "а": "a", "в": "b", "е": "e", "к": "k", "м": "m", "н": "h", "о": "o", "р": "p", "с": "c", "т": "t",
    "у": "y", "х": "x", "і": "i", "ј": "j", "ѕ": "s", "ԁ": "d", "һ": "h", "ӏ": "l", "ԛ": "q", "ԝ": "w",
    "α": "a", "β": "b", "ε": "e", "ζ": "z", "η": "h", "ι": "i", "κ": "k", "μ": "m", "ν": "n", "ο": "o",
    "ρ": "p", "τ": "t", "υ": "y", "χ": "x", "0": "o", "1": "l",
})


def player_key(name: str) -> str:
    """The key two names of one player share (see the module): NFKC-normalised, case-folded, lookalike
    letters read as Latin ones, runs of spaces as one, surrounding spaces dropped."""
    return " ".join(unicodedata.normalize("NFKC", name).casefold().translate(LOOKALIKES).split())


def legacy_player_key(name: str) -> str:
    """The key before lookalikes and inner spaces counted (identity version 2's): files written then name
    their players by it (a class's ``class.json``), and ``player_key`` of it is today's key."""
    return unicodedata.normalize("NFKC", name).casefold().strip()


@dataclass(frozen=True)
class PlayerRow(Generic[T]):
    """A player's row: their best game (the first of theirs in the list given) and the games they played."""

    name: str
    best: T
    games: int


def one_row_per_player(best_first: Iterable[T], name_of: Callable[[T], str] = lambda e: e.name  # type: ignore[attr-defined]
                       ) -> list[PlayerRow[T]]:
    """One row a player, best first. ``best_first`` is already in rank order (equal scores: the earlier
    entry first), so a player's first game in it is their best and the rows keep that order."""
    rows: dict[str, list] = {}
    for item in best_first:
        key = player_key(name_of(item))
        row = rows.get(key)
        if row is None:
            rows[key] = [name_of(item), item, 1]
        else:
            row[2] += 1
    return [PlayerRow(name, best, games) for name, best, games in rows.values()]


def places(scores: Iterable[int]) -> list[int]:
    """The place of each of a best-first list's scores: equal scores share a place, and the next place skips
    as many (30, 20, 20, 10 are 1, 2, 2, 4)."""
    out: list[int] = []
    previous = None
    for i, score in enumerate(scores, 1):
        out.append(out[-1] if out and score == previous else i)
        previous = score
    return out


def row_of(rows: list[PlayerRow[T]], name: str) -> int | None:
    """The position (1-based) of a player's own row in the rows, or None if they have none."""
    key = player_key(name)
    return next((i for i, row in enumerate(rows, 1) if player_key(row.name) == key), None)


def rank_of(rows: list[PlayerRow[T]], name: str, score_of: Callable[[T], int] = lambda e: e.score  # type: ignore[attr-defined]
            ) -> int | None:
    """A player's place (1-based; shared with every row of an equal score) in the rows, or None if they have
    none."""
    position = row_of(rows, name)
    if position is None:
        return None
    return place_of_new(rows[:position - 1], score_of(rows[position - 1].best), score_of)


def place_of_new(rows: list[PlayerRow[T]], score: int, score_of: Callable[[T], int] = lambda e: e.score  # type: ignore[attr-defined]
                 ) -> int:
    """The place (1-based) a new player whose game scores ``score`` would take: shared with every row of an
    equal score (their row goes after those, the earlier games)."""
    return 1 + sum(1 for row in rows if score_of(row.best) > score)


def shared_rank(above: Sequence[Mapping[str, object]], score: int) -> int:
    """The place of a row scoring ``score`` below the rows ``above`` (best first, each with its "rank" and
    "score"): equal scores share a place (1, 2, 2, 4), as a class reads a table."""
    if above and above[-1]["score"] == score:
        return int(above[-1]["rank"])  # type: ignore[call-overload]
    return len(above) + 1
