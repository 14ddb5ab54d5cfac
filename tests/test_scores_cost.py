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
    import armgame.records.checking as checking_module
    import armgame.records.replay as replay_module
    import armgame.records.tablefile as tablefile_module

    reads = []
    for module in (storage, checking_module, tablefile_module, replay_module):
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
    assert "flagged:" not in out and "1 not checked yet (costly replay" in out  # a cost, not a verdict


def test_an_input_event_costs_its_verification_event_work_counted_before_and_while_it_runs():
    """``EVENT_WORK`` bounds what an input event costs a verification: ``replay_work`` counts it before a game is
    read again, and ``Replay.verify`` refuses, before its first step, a game whose steps and events cost more than
    it spends, at exactly that count: one unit of work fewer is refused, the count (and the first target's
    drawing, at most ``MAX_TRIES`` tries) is run and matches."""
    from armgame.game.rules import MAX_TRIES
    from armgame.records.replay import TRY_WORK, VerifyCostError

    session = GameSession(GameConfig(seed=10, time_limit=0.4))
    while session.steps < session.total_steps - 1:  # a key pressed and released at every step: 2 events a step
        session.key_event("d", "down")
        session.key_event("d", "up")
        session.advance(1)
    session.advance(session.total_steps - session.steps)
    busy = Replay.from_session(session, "script", "masher")
    steps, events = busy.result.steps, len(busy.timeline)
    assert busy.result.hits == 0 and events == 2 * (steps - 1)
    work = steps + EVENT_WORK * events
    assert replay_work(busy) == work and EVENT_WORK * events > 10 * steps  # the events are nearly all of it
    with pytest.raises(VerifyCostError, match=rf"^its {steps:,} steps and {events:,} input events are more work "
                                              rf"\({work:,} steps\) than one verification spends \({work - 1:,}\)$"):
        busy.verify(max_work=work - 1)
    assert busy.verify(max_work=work + TRY_WORK * MAX_TRIES)[0]


# ------------------------------------------------------------------ honest games are never flagged (issue 26, 5)

def test_the_largest_honest_games_are_well_within_the_budget():
    """The largest honest games ``benchmarks/honest_work.py`` found, with the margin MAX_CHECK_WORK states."""
    from armgame.game.bots import play_bot
    from armgame.records.listing import MAX_CHECK_WORK

    model = Replay.from_session(play_bot(GameConfig(seed=18), "model"), "bot", "model")  # the model bot's worst seed
    session = GameSession(GameConfig(seed=10))
    for step in range(0, session.total_steps, 12):  # each of the four keys pressed 20 times a second
        for i, key in enumerate("dfjk"):
            session.advance(step + 3 * i - session.steps)
            session.key_event(key, "down")
            session.advance(step + 3 * i + 6 - session.steps)
            session.key_event(key, "up")
    session.advance(session.total_steps)
    masher = Replay.from_session(session, "keyboard", None, "fast")
    assert replay_work(model) == 333_900 and 200_000 < replay_work(masher) < 220_000
    assert 2.5 * max(replay_work(model), replay_work(masher)) < MAX_CHECK_WORK


def standard_game(player: str, presses: int) -> Replay:
    """A standard 60 s game of seed 10 with ``presses`` key presses."""
    session = GameSession(GameConfig(seed=10))
    for i in range(presses):
        session.advance(100 + 50 * i - session.steps)
        session.key_event("d", "down")
        session.advance(20)
        session.key_event("d", "up")
    session.advance(session.total_steps)
    return Replay.from_session(session, "keyboard", None, player)


def test_a_costly_game_is_listed_apart_unflagged_and_ranked_once_verify_checks_it(tmp_path, monkeypatch, capsys):
    import armgame.records.listing as listing_module

    table = ScoreTable(tmp_path / "t")
    table.add(standard_game("cheap", 1))  # 15,000 steps and 2 events: 15,040
    table.add(standard_game("busy", 10))  # 20 events: 15,400
    monkeypatch.setattr(listing_module, "MAX_CHECK_WORK", 15_100)
    assert main(["scores", "--scores", str(table.folder)]) == 0
    out = capsys.readouterr().out
    ranked, apart = out.split("not checked yet")
    assert "cheap" in ranked and "busy" not in ranked and "flagged:" not in out
    assert "1 not checked yet (costly replay: armgame verify checks it; not ranked until then)" in out
    assert "busy (0, " in apart and "15,400 steps of work" in apart
    assert main(["verify", str(table.folder)]) == 0  # checks everything, whatever it costs
    capsys.readouterr()
    assert main(["scores", "--scores", str(table.folder)]) == 0
    out = capsys.readouterr().out
    assert "not checked" not in out and "busy" in out.split("Ranked")[1] and "flagged:" not in out


def test_verify_max_work_bounds_a_run_and_says_what_it_left(tmp_path, monkeypatch, capsys):
    import armgame.records.batch_verify as batch_verify

    table = ScoreTable(tmp_path / "t")
    cheap, busy = table.add(standard_game("cheap", 1)), table.add(standard_game("busy", 10))
    recomputed = []
    real = batch_verify.verify_replays
    monkeypatch.setattr(batch_verify, "verify_replays",
                        lambda replays, kernel=None: recomputed.extend(r.player for r in replays) or real(replays))
    assert main(["verify", str(table.folder), "--max-work", "15100"]) == 3
    out = capsys.readouterr().out
    assert "busy: score 0" in out and "NOT CHECKED: its replay claims" in out and "15,400 steps of work" in out
    assert out.splitlines()[-1].endswith("2 entries, 0 flagged, 1 not checked (over --max-work)")
    assert main(["verify", str(table.replay_path(busy)), "--max-work", "15100"]) == 3
    assert main(["verify", str(table.replay_path(cheap)), "--max-work", "15100"]) == 0
    assert main(["verify", str(table.replays), "--max-work", "15100"]) == 3
    assert "2 replays, 0 differ, 0 unreadable, 1 not checked (over --max-work)" in capsys.readouterr().out
    assert "busy" not in recomputed  # never run, on the table or the folder
    forged = json.loads(table.replay_path(cheap).read_text())
    forged["result"].update(resets=2)  # no more work claimed: it is recomputed, and differs
    table.replay_path(cheap).write_text(json.dumps(forged))
    assert main(["verify", str(table.replays), "--max-work", "15100"]) == 1  # a difference outranks a game left
    with pytest.raises(SystemExit) as exit_:
        main(["verify", str(table.folder), "--max-work", "0"])
    assert exit_.value.code == 2 and capsys.readouterr().err.count("\n") == 1
