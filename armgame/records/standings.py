"""One row per player: the standings a class reads, each player's best game and how many they played.

A table holds games; a class ranks people. ``one_row_per_player`` folds a best-first list of games
into one row a player, in the order of each player's best game, so one keen student cannot fill the
top of the table. ``armgame scores`` (each of its lists, unless ``--all-games``), ``play`` and
``scores --add`` ("#3 in the ranked table": the third player, ``ScoreTable.rank``) and the play
window's end screen (``rank_of``; before a name is typed, ``place_of_new``) all ask it, so "your
rank" means the same thing everywhere.

Players are told apart by ``player_key``: the name as typed, compatibility-normalised (NFKC: a
full-width "Ａlice" is "Alice") and case-folded, so "alice" and "Alice " are one player.
"""

from __future__ import annotations

import unicodedata
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Generic, TypeVar

T = TypeVar("T")


def player_key(name: str) -> str:
    """The key two names of one player share: NFKC-normalised, case-folded, surrounding spaces dropped."""
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


def rank_of(rows: list[PlayerRow[T]], name: str) -> int | None:
    """A player's place (1-based) in the rows, or None if they have none."""
    key = player_key(name)
    return next((i for i, row in enumerate(rows, 1) if player_key(row.name) == key), None)


def place_of_new(rows: list[PlayerRow[T]], score: int, score_of: Callable[[T], int] = lambda e: e.score  # type: ignore[attr-defined]
                 ) -> int:
    """The place (1-based) a new player whose game scores ``score`` would take: after every row whose
    best scores as much (an equal score already in is the earlier game)."""
    return 1 + sum(1 for row in rows if score_of(row.best) >= score)
