"""Who and what a table entry is: people rank apart from programs, one game enters once, one seed
ranks, ties go to the earlier entry, and a planted verification cache is never believed.

Each test is an attack a classmate (or a teacher's honest mistake) tried on the table."""

import hashlib
import json
import os
import subprocess
import sys
from dataclasses import replace

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

import pytest

from armgame.cli import main
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession, InputEvent
from armgame.records import tablefile
from armgame.records.identity import game_digest
from armgame.records.replay import Replay
from armgame.records.scores import PRACTICE, PROGRAMS, RANKED, ScoreTable, TableError, replay_claims
from armgame.records.storage import atomic_write_bytes


@pytest.fixture(autouse=True)
def _private_folders(tmp_path, monkeypatch):
    monkeypatch.setenv("ARMGAME_SCORES", str(tmp_path / "default-scores"))
    monkeypatch.setenv("ARMGAME_CACHE", str(tmp_path / "private" / "cache"))


def played(player="ann", driven="keyboard", driver=None, seed=10, press=100, time_limit=None) -> Replay:
    """A whole game with one key press at step ``press`` (each press a different game)."""
    config = GameConfig(seed=seed) if time_limit is None else GameConfig(seed=seed, time_limit=time_limit)
    session = GameSession(config)
    session.advance(press)
    session.key_event("f", "down")
    session.advance(300)
    session.key_event("f", "up")
    session.advance(session.total_steps)
    return Replay.from_session(session, driven, driver, player)


# ------------------------------------------------------------------ 1. people rank, programs listed apart

def test_a_bot_game_is_listed_apart_never_above_a_keyboard_game(tmp_path, capsys):
    table = ScoreTable(tmp_path)
    student = table.add(played("student"))
    bot = table.add(played("Me", "bot", "model", press=5))
    script = table.add(played("scripted", "script", "go.txt", press=7))
    assert table.list_of(student) == RANKED and table.list_of(bot) == PROGRAMS == table.list_of(script)
    assert [e.id for e in table.entries()] == [student.id] and table.rank(student) == 1
    assert main(["scores", "--scores", str(tmp_path)]) == 0
    ranked, programs = capsys.readouterr().out.split("Programs")
    assert "student" in ranked and "Me" not in ranked and "Me" in programs and "scripted" in programs


def test_a_keyboard_game_that_names_a_driver_is_a_program(tmp_path):
    # Nothing a keyboard game writes names a driver: a replay that does is not provably the keyboard's.
    table = ScoreTable(tmp_path)
    odd = table.add(played("odd", "keyboard", "autohotkey"))
    assert table.list_of(odd) == PROGRAMS


def test_scores_add_and_play_say_which_list_the_game_went_to(tmp_path, capsys):
    replay = tmp_path / "bot.json"
    assert main(["play", "--headless", "--bot", "model", "--duration", "1", "--record", str(replay)]) == 0
    capsys.readouterr()
    assert main(["scores", "--scores", str(tmp_path / "t"), "--add", str(replay), "--name", "Me"]) == 0
    assert "programs" in capsys.readouterr().out
    assert main(["play", "--headless", "--bot", "model", "--duration", "1", "--seed", "3", "--name", "Me",
                 "--scores", str(tmp_path / "t")]) == 0
    assert "in programs (bots and scripts" in capsys.readouterr().out


# ------------------------------------------------------------------ 2. one game enters once

def _copies(replay: Replay) -> dict[str, Replay]:
    later = replay.date.replace(replay.date[20:26], f"{(int(replay.date[20:26]) + 1) % 10**6:06d}")
    noop = (*replay.timeline[:1], InputEvent(replay.timeline[0].step, replay.timeline[0].key, "down"),
            *replay.timeline[1:], InputEvent(replay.timeline[-1].step, "f", "up"))
    return {"re-dated": replace(replay, date=later), "renamed": replay.with_player("bob"),
            "no-op events": replace(replay, timeline=noop)}


@pytest.mark.parametrize("how", ["re-dated", "renamed", "no-op events", "re-serialised"])
def test_the_same_game_enters_once_however_it_is_copied(tmp_path, how):
    table = ScoreTable(tmp_path)
    original = played("ann")
    table.add(original)
    if how == "re-serialised":
        copy = tmp_path / "copy.json"
        copy.write_text(json.dumps(json.loads(original.to_bytes()), indent=7))
        assert copy.read_bytes() != original.to_bytes()
        copy_replay = Replay.load(copy)
        with pytest.raises(TableError, match=r"already in the table: entered by ann on .* UTC"):
            table.add(copy_replay, copy)
        return
    copy_replay = _copies(original)[how]
    assert game_digest(copy_replay) == game_digest(original)
    assert copy_replay.verify()[0]
    with pytest.raises(TableError, match=r"already in the table: entered by ann on .* UTC \(entry #1\)"):
        table.add(copy_replay)
    assert len(table.all_entries()) == 1


def test_a_different_game_is_a_different_digest():
    a = played(press=100)
    assert game_digest(played(press=101)) != game_digest(a)
    assert game_digest(played(seed=11, press=100)) != game_digest(a)


def test_scores_add_refuses_a_copy_in_one_line(tmp_path):
    table = ScoreTable(tmp_path / "t")
    table.add(played("ann"))
    copy = tmp_path / "copy.json"
    played("ann").with_player("bob").save(copy)
    proc = subprocess.run([sys.executable, "-m", "armgame", "scores", "--scores", str(tmp_path / "t"), "--add",
                           str(copy)], capture_output=True, text=True, timeout=30, env={**os.environ})
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1 and "entered by ann" in proc.stderr


def test_a_copy_planted_in_the_table_is_flagged_and_ties_go_to_the_earlier_entry(tmp_path, capsys):
    table = ScoreTable(tmp_path)
    first = table.add(played("first", press=50))
    second = table.add(played("second", press=60))
    assert first.score == second.score and first.entered < second.entered
    # A copy of second's game, entered by hand with another name and a 1970 date.
    data = json.loads(table.path.read_text())
    copy = dict(next(e for e in data["entries"] if e["id"] == second.id))
    copied = played("second", press=60).with_player("thief")
    copied = replace(copied, date="1970-01-01T00:00:00+00:00")
    path = table.save_replay(copied)
    copy.update(id="c" * 32, name="thief", date=copied.date, replay=path.name, entered=99,
                replay_sha256=hashlib.sha256(path.read_bytes()).hexdigest())
    data["entries"].append(copy)
    table.path.write_text(json.dumps(data))
    # The 1970 date wins no tie: the order of entry breaks it.
    assert [e.name for e in table.all_entries()] == ["first", "second", "thief"]
    assert main(["scores", "--scores", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "thief (" in out and "DUPLICATE: the same game as second's entry" in out
    assert main(["verify", str(tmp_path)]) == 1
    out = capsys.readouterr().out
    assert "thief: score" in out and "DUPLICATE: the same game as second's earlier entry" in out


@pytest.mark.parametrize("planted", ["a copy under another name", "a copy naming a forged replay"])
def test_an_entry_planted_under_an_honest_ones_id_never_pushes_it_out(tmp_path, planted):
    """A copy of Ann's entry put above it in the file with her id: the table is damaged (said, and kept aside
    at the next write), but the entry kept under the id is the one her replay file backs, so the next game
    written leaves Ann's entry in and the copy out."""
    table = ScoreTable(tmp_path)
    ann = table.add(played("Ann", press=50))
    data = json.loads(table.path.read_text())
    copy = dict(data["entries"][0], name="Mallory")
    if planted == "a copy naming a forged replay":
        forged = table.save_replay(played("Ann", press=50).with_player("Mallory"))
        copy.update(replay=forged.name, replay_sha256="0" * 64)
    data["entries"].insert(0, copy)
    table.path.write_text(json.dumps(data))
    entries, damage = table.read()
    assert damage is not None and "appears twice" in damage.reason
    assert [(e.id, e.name) for e in entries] == [(ann.id, "Ann")]
    table.add(played("Bo", press=70))
    assert sorted(e.name for e in table.all_entries()) == ["Ann", "Bo"]
    assert len(list(tmp_path.glob("scores.json.corrupt-*"))) == 1  # the planted file kept aside, not lost
    assert tablefile.MAX_TWIN_BYTES == 64 * 2**20  # what docs/scores.md says a read hashes at most


def test_an_old_table_gets_its_order_of_entry_once(tmp_path):
    table = ScoreTable(tmp_path)
    table.add(played("a", press=1))
    data = json.loads(table.path.read_text())
    for e in data["entries"]:  # as a format 2 table wrote it
        for key in ("entered", "entered_at", "game_sha256", "complete"):
            del e[key]
    data["format_version"] = 2
    del data["seed"], data["next_entry"]
    table.path.write_text(json.dumps(data))
    b = table.add(played("b", press=2))
    entries = {e.name: e for e in table.all_entries()}
    assert entries["a"].entered == 1 and b.entered == 2 and entries["b"].complete is True


# ------------------------------------------------------------------ 3. the ranked seed

def test_other_seeds_are_practice_and_a_teacher_sets_the_seed(tmp_path, capsys):
    table = ScoreTable(tmp_path / "default")
    tens, other = table.add(played("ten")), table.add(played("shopper", seed=3))
    assert table.list_of(tens) == RANKED and table.list_of(other) == PRACTICE
    assert main(["scores", "--scores", str(tmp_path / "mine"), "--new", "--seed", "3"]) == 0
    assert "seed 3" in capsys.readouterr().out
    mine = ScoreTable(tmp_path / "mine")
    three, ten = mine.add(played("three", seed=3)), mine.add(played("ten", seed=10))
    assert mine.list_of(three) == RANKED and mine.list_of(ten) == PRACTICE
    assert main(["scores", "--scores", str(tmp_path / "mine"), "--new"]) == 2  # it holds entries
    assert "already holds 2 entries" in capsys.readouterr().err
    assert main(["scores", "--scores", str(tmp_path / "mine"), "--no-check"]) == 0
    out = capsys.readouterr().out
    assert "seed 3" in out and out.index("three") < out.index("Practice") < out.index("ten ")


# ------------------------------------------------------------------ 4. no planted verdicts

def _forge_99(table: ScoreTable, entry) -> dict:
    forged = json.loads(table.replay_path(entry).read_text())
    forged["result"].update(score=99, hits=99)
    atomic_write_bytes(table.replay_path(entry), json.dumps(forged).encode())
    digest = hashlib.sha256(table.replay_path(entry).read_bytes()).hexdigest()
    data = json.loads(table.path.read_text())
    data["entries"][0].update(score=99, hits=99, replay_sha256=digest)
    table.path.write_text(json.dumps(data))
    claims = replay_claims(Replay.load(table.replay_path(entry)))  # what the forged replay says: score 99
    assert claims["score"] == data["entries"][0]["score"] == 99
    return {digest: {"ok": True, "label": "ok", "detail": "", "claims": claims}}


@pytest.mark.parametrize("where", ["group-writable", "in the table", "beside the table"])
def test_a_planted_ok_in_a_cache_others_can_write_is_ignored(tmp_path, capsys, where):
    from armgame import __version__

    table = ScoreTable(tmp_path / "class" / "scores")
    entry = table.add(played("forger"))
    items = _forge_99(table, entry)
    cache = {"group-writable": tmp_path / "shared-cache", "in the table": table.folder / "c",
             "beside the table": tmp_path / "class"}[where]
    cache.mkdir(exist_ok=True)
    (cache / f"verified-{__version__}.json").write_text(json.dumps(
        {"format": "armgame-verified", "version": __version__, "items": items}))
    if where == "group-writable":
        os.chmod(cache, 0o775)
    assert main(["scores", "--scores", str(table.folder), "--cache", str(cache)]) == 0
    captured = capsys.readouterr()
    assert "NOT REPRODUCED" in captured.out and "no ranked games yet" in captured.out
    notes = [line for line in captured.err.splitlines() if "verification cache" in line]
    assert len(notes) == 1 and "ignored" in notes[0]


def test_a_private_cache_is_used_and_keeps_failures_too(tmp_path, monkeypatch, capsys):
    import armgame.records.batch_verify as batch_verify

    table = ScoreTable(tmp_path / "t")
    entry = table.add(played("forger"))
    _forge_99(table, entry)
    calls = []
    real = batch_verify.verify_replays
    monkeypatch.setattr(batch_verify, "verify_replays",
                        lambda replays, kernel=None: calls.extend(replays) or real(replays, kernel))
    for _ in range(2):
        assert main(["scores", "--scores", str(tmp_path / "t")]) == 0
        assert "NOT REPRODUCED" in capsys.readouterr().out
    assert len(calls) == 1  # the failure was cached: the second listing replayed nothing
    cached = next((tmp_path / "private" / "cache").glob("verified-*.json"))
    assert cached.stat().st_mode & 0o077 == 0
