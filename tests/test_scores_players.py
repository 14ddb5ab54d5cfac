"""One row per student (issue 26, item 4): ``armgame scores`` lists each player once, at their best game
with how many games they played; ``--all-games`` lists every game; ``--top`` counts players; and every
rank a game is told (``play``, ``scores --add``, the end screen) is its player's place among players."""

import json
import os

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

import pytest

import armgame.records.batch_verify as batch_verify
import armgame.records.listing as listing_module
from armgame.cli import build_parser, main
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession, InputEvent
from armgame.records.replay import Replay
from armgame.records.scores import ScoreTable
from armgame.records.standings import one_row_per_player, place_of_new


@pytest.fixture(autouse=True)
def _private_folders(tmp_path, monkeypatch):
    monkeypatch.setenv("ARMGAME_SCORES", str(tmp_path / "default-scores"))
    monkeypatch.setenv("ARMGAME_CACHE", str(tmp_path / "private" / "cache"))


def ranked_game(player: str, press: int, hit: bool = False) -> Replay:
    """A standard keyboard game of seed 10 (the ranked list), each ``press`` another game; ``hit``: it
    scores 1 (k held for the first 40 steps reaches the first target), else 0."""
    events = [InputEvent(0, "k", "down"), InputEvent(40, "k", "up")] if hit else []
    config = GameConfig(seed=10)
    events.append(InputEvent(14_000 + press, "f", "down"))
    session = GameSession(config)
    session.play(events)
    return Replay.from_session(session, "keyboard", None, player)


def class_table(folder) -> tuple[ScoreTable, list]:
    """A keen student (6 games: their fourth scores 1), then Bo and Cy (one game each, 0)."""
    table = ScoreTable(folder)
    keen = [table.add(ranked_game("Keen", i, hit=i == 3)) for i in range(6)]
    bo, cy = table.add(ranked_game("Bo", 10)), table.add(ranked_game("Cy", 11))
    assert [e.score for e in keen] == [0, 0, 0, 1, 0, 0]
    return table, [*keen, bo, cy]


def rows_of(out: str) -> list[list[str]]:
    """The ranked list's rows (name first) of ``armgame scores``'s output."""
    lines = out.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("Ranked")) + 2
    rows = []
    for line in lines[start:]:
        if not line.split() or not line.split()[0].isdigit():
            break
        rows.append(line.split()[1:])
    return rows


def test_a_keen_student_takes_one_row_at_their_best_game(tmp_path, capsys):
    table, _ = class_table(tmp_path / "t")
    assert main(["scores", "--scores", str(table.folder)]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[2].split()[:4] == ["#", "name", "score", "games"]
    # name, score, games: Keen's best (their fourth game, 1) and all six of theirs.
    assert [row[:3] for row in rows_of(out)] == [["Keen", "1", "6"], ["Bo", "0", "1"], ["Cy", "0", "1"]]
    assert "One row a player" in out and "flagged:" not in out
    assert main(["scores", "--scores", str(table.folder), "--top", "2"]) == 0  # rows are players
    assert [row[0] for row in rows_of(capsys.readouterr().out)] == ["Keen", "Bo"]
    assert main(["scores", "--scores", str(table.folder), "--all-games"]) == 0  # the old list: every game
    out = capsys.readouterr().out
    assert [row[:2] for row in rows_of(out)] == [["Keen", "1"], *[["Keen", "0"]] * 5, ["Bo", "0"], ["Cy", "0"]]
    assert "One row a player" not in out and out.splitlines()[2].split()[:4] == ["#", "name", "score", "hits"]
    assert main(["scores", "--scores", str(table.folder), "--all-games", "--top", "3", "--no-check"]) == 0
    assert [row[0] for row in rows_of(capsys.readouterr().out)] == ["Keen"] * 3


def test_games_counts_no_game_found_flagged(tmp_path, capsys):
    """The bounded, honest count: a player's games below their best are counted as entered, not replayed
    (``--all`` replays them all), and a game found flagged never counts."""
    table, entries = class_table(tmp_path / "t")
    keen_last = entries[5]
    path = table.replay_path(keen_last)
    path.write_bytes(path.read_bytes().replace(b'"date"', b'"date" ', 1))  # not the replay it was entered with
    assert main(["scores", "--scores", str(table.folder), "--all"]) == 0
    out = capsys.readouterr().out
    assert rows_of(out)[0][:3] == ["Keen", "1", "5"] and "REPLAY CHANGED" in out and "1 flagged:" in out
    # The same replay file entered again under Keen: a copy, known unread, never a game played.
    data = json.loads(table.path.read_text())
    data["entries"].append({**next(e for e in data["entries"] if e["id"] == entries[1].id), "id": "c" * 32,
                            "entered": 99})
    table.path.write_text(json.dumps(data))
    assert main(["scores", "--scores", str(table.folder), "--all"]) == 0
    out = capsys.readouterr().out
    assert rows_of(out)[0][:3] == ["Keen", "1", "5"] and "2 flagged:" in out and "DUPLICATE" in out


def test_a_listed_players_other_games_are_not_replayed(tmp_path, capsys, monkeypatch):
    """The cost bound: --top N replays until N players have rows, and no game of a player already listed
    (batches of two here, so the bound shows on a small table)."""
    table, entries = class_table(tmp_path / "t")
    path = table.replay_path(entries[5])  # Keen's last game, changed: only a replay would find it
    path.write_bytes(path.read_bytes().replace(b'"date"', b'"date" ', 1))
    monkeypatch.setattr(listing_module, "MIN_BATCH", 2)
    replayed = []
    real = batch_verify.verify_replays
    monkeypatch.setattr(batch_verify, "verify_replays",
                        lambda games, kernel=None: replayed.extend(r.player for r in games) or real(games, kernel))
    assert main(["scores", "--scores", str(table.folder), "--top", "1", "--no-check"]) == 0
    assert rows_of(capsys.readouterr().out)[0][:3] == ["Keen", "1", "6"]
    assert main(["scores", "--scores", str(table.folder), "--top", "1"]) == 0
    out = capsys.readouterr().out
    # Keen's best (the first batch: it and the next best) is replayed; the rest of theirs are counted as entered.
    assert rows_of(out) == [rows_of(out)[0]] and rows_of(out)[0][:3] == ["Keen", "1", "6"]
    assert replayed == ["Keen", "Keen"] and "flagged:" not in out


def test_every_rank_a_game_is_told_is_its_players(tmp_path, capsys):
    from armgame.commands.play import _preview, _standing, game_config
    from armgame.commands.scores import where_it_went

    table, entries = class_table(tmp_path / "t")
    bo, cy = entries[6], entries[7]
    assert table.rank(bo) == 2 and table.rank(cy) == 2 and table.rank(entries[0]) == 1  # Bo and Cy tie at 0
    assert where_it_went(table, cy).startswith("#2 in the ranked table")  # third student, tied second, eighth game
    # play --name for a student with a game in: their place at their best (Keen's 0 is below their 1).
    assert main(["scores", "--scores", str(table.folder), "--add", str(_saved(tmp_path, "Keen", 20)),
                 "--name", "Keen"]) == 0
    assert "#1 in the ranked table" in capsys.readouterr().out
    # The end screen: a new player's preview, then their place once named, among 3 (then 4) players.
    args = build_parser().parse_args(["play", "--scores", str(table.folder)])
    session = GameSession(game_config(args))
    session.play([InputEvent(14_000 + 30, "f", "down")])
    preview = _preview(session, args)()
    assert (preview.rank, preview.entries, preview.pending) == (2, 4, True)  # tied with every 0 already in
    assert [row[:2] for row in preview.top] == [(1, "Keen"), (2, "Bo"), (2, "Cy"), (2, "")] and preview.own_row == 3
    standing = _standing(session, args)("Dee")
    assert (standing.rank, standing.entries) == (2, 4) and [row[1] for row in standing.top][-1] == "Dee"
    assert standing.mine == 3  # the row that is Dee's, not every row of their place
    keen_again = GameSession(game_config(args))
    keen_again.play([InputEvent(14_000 + 31, "f", "down")])
    standing = _standing(keen_again, args)("keen")  # the same player, however it is typed
    assert (standing.rank, standing.entries) == (1, 4) and standing.top[0][1:] == ("Keen", 1)
    capsys.readouterr()


def _saved(tmp_path, player: str, press: int):
    path = tmp_path / f"{player}-{press}.json"
    ranked_game(player, press).save(path)
    return path


def test_a_new_players_place():
    rows = one_row_per_player([_Game("Ann", 5), _Game("Bo", 3), _Game("Ann", 2), _Game("Cy", 3)])
    assert [place_of_new(rows, s) for s in (6, 5, 4, 3, 0)] == [1, 1, 2, 2, 4]  # an equal score shares a place


class _Game:
    def __init__(self, name: str, score: int) -> None:
        self.name, self.score = name, score
