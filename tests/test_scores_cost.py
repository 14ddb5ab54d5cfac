"""Bounded cost, whatever is planted (issue 16, class 5): listing reads no replay it does not need,
a replay's work is counted in steps, hits and events before it runs, and what ``scores`` will not
spend on is listed NOT CHECKED once, then remembered."""

import hashlib
import json

import pytest

from armgame.cli import main
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession
from armgame.records import storage
from armgame.records.replay import Replay
from armgame.records.scores import EVENT_WORK, HIT_WORK, ScoreTable, replay_work


@pytest.fixture(autouse=True)
def _private_folders(tmp_path, monkeypatch):
    monkeypatch.setenv("ARMGAME_SCORES", str(tmp_path / "default-scores"))
    monkeypatch.setenv("ARMGAME_CACHE", str(tmp_path / "private" / "cache"))


def short_game(player: str, press: int, time_limit: float = 0.4) -> Replay:
    session = GameSession(GameConfig(seed=10, time_limit=time_limit))
    session.advance(press)
    session.key_event("k", "down")
    session.advance(session.total_steps)
    return Replay.from_session(session, "keyboard", None, player)


def _as_old_format(table: ScoreTable) -> None:
    data = json.loads(table.path.read_text())
    for e in data["entries"]:
        for key in ("ruleset", "config_sha256", "game_sha256", "complete", "entered", "entered_at"):
            e.pop(key, None)
    table.path.write_text(json.dumps({"format": "armgame-scores", "format_version": 1, "entries": data["entries"]}))


def test_listing_and_ranking_old_entries_read_no_replay(tmp_path, monkeypatch, capsys):
    table = ScoreTable(tmp_path / "t")
    for i in range(3):  # standard games: their length and scene alone cannot say they are custom
        table.add(short_game(f"old{i}", i, 60.0))
    _as_old_format(table)
    import armgame.records.replay as replay_module
    import armgame.records.scores as scores_module

    reads = []
    for module in (storage, scores_module, replay_module):
        for name in ("open_regular", "read_limited"):
            if not hasattr(module, name):
                continue
            real = getattr(storage, name)
            monkeypatch.setattr(module, name,
                                lambda path, *a, _real=real, **k: reads.append(path) or _real(path, *a, **k))
    assert main(["scores", "--scores", str(tmp_path / "t"), "--no-check", "--top", "1"]) == 0
    assert main(["play", "--headless", "--duration", "0.2", "--name", "New", "--scores", str(tmp_path / "t")]) == 0
    assert [p for p in reads if "replays" in str(p) and "New" not in str(p)] == []


def _storm(player: str = "storm") -> Replay:
    replay = short_game(player, 1).as_dict()
    replay["result"].update(score=5000, hits=5000)
    return Replay.from_dict(json.loads(json.dumps(replay)))


def test_a_costly_replay_is_counted_before_it_runs_and_not_run_by_scores(tmp_path, monkeypatch, capsys):
    storm = _storm()
    assert replay_work(storm) == storm.result.steps + HIT_WORK * 5000 + EVENT_WORK * len(storm.timeline)
    table = ScoreTable(tmp_path / "t")
    entry = table.add(short_game("honest", 3))
    data = json.loads(table.path.read_text())
    path = table.save_replay(storm)

    data["entries"].append({**data["entries"][0], "id": "e" * 32, "name": "storm", "score": 5000, "hits": 5000,
                            "replay": path.name, "replay_sha256": hashlib.sha256(path.read_bytes()).hexdigest(),
                            "entered": 2, "date": storm.date})
    del data["entries"][1]["game_sha256"]
    table.path.write_text(json.dumps(data))
    parsed = []
    real = Replay.from_bytes
    monkeypatch.setattr(Replay, "from_bytes", classmethod(lambda cls, d, s="replay": parsed.append(s) or real(d, s)))
    for _ in range(2):
        assert main(["scores", "--scores", str(tmp_path / "t")]) == 0
        out = capsys.readouterr().out
        assert "storm (5000" in out and "NOT CHECKED: its replay claims" in out and "honest" in out
    assert len([s for s in parsed if path.name in s]) == 1  # the second listing knew it without reading it
    assert entry.name == "honest"
