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


def test_names_the_projector_shows_alike_are_one_player():
    """A classmate cannot stand on the projector as a second "Ann": lookalike letters of other scripts, digits
    drawn like letters and extra inner spaces make the same key; names that look different stay apart."""
    same = [("Ann B", "\u0410nn B"), ("Ann B", "Ann   B"), ("Bob", "B0b"), ("OLGA", "\u039fLGA"),
            ("Kai", "\u041a\u0430i"), ("Emma", "\u0395mm\u03b1"), ("Ann", "\u0391\u039d\u039d")]
    for typed, lookalike in same:
        assert player_key(typed) == player_key(lookalike), (typed, lookalike)
    for a, b in [("Eli", "Ell"), ("Ann", "Anne"), ("Ольга", "Olga"), ("李小龙", "李小虎"), ("Ann B", "AnnB")]:
        assert player_key(a) != player_key(b), (a, b)
    games = [Game("Ann", 40), Game("\u0410nn", 50), Game("Bo", 35)]
    assert [(r.name, r.best.score, r.games) for r in one_row_per_player(sorted(games, key=lambda g: -g.score))] == [
        ("\u0410nn", 50, 2), ("Bo", 35, 1)]
