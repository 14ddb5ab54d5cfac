"""One row per player: the standings every listing of a class shares."""

from dataclasses import dataclass

from armgame.records.standings import one_row_per_player, player_key, rank_of


@dataclass(frozen=True)
class Game:
    name: str
    score: int


def test_each_player_once_at_their_best_game_with_their_count():
    games = [Game("Ann", 40), Game("Ann", 38), Game("Bo", 35), Game("ann ", 30), Game("Cy", 12)]
    rows = one_row_per_player(games)
    assert [(r.name, r.best.score, r.games) for r in rows] == [("Ann", 40, 3), ("Bo", 35, 1), ("Cy", 12, 1)]
    assert rank_of(rows, "BO") == 2 and rank_of(rows, "Dee") is None


def test_names_are_one_player_by_their_normalised_case_folded_form():
    assert player_key("\uff21lice") == player_key("alice ") == player_key("ALICE")
    assert player_key("Alice") != player_key("Alicia")
