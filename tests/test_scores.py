"""The high-score table: ordering, concurrent writers, a kill mid-write, damaged and hostile
tables, tampering, the CLI and the name prompt. Everything is written under tmp_path."""

import json
import multiprocessing
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

import pytest
import table_writer

import armgame.records.entry as entry_module
import armgame.records.scores as scores_module
from armgame.cli import main
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession
from armgame.records.replay import Replay
from armgame.records.scores import ScoreEntry, ScoreTable, default_scores_dir, parse_table, table_bytes

REPO = Path(__file__).resolve().parent.parent


@pytest.fixture(autouse=True)
def _scores_in_tmp(tmp_path, monkeypatch):
    monkeypatch.setenv("ARMGAME_SCORES", str(tmp_path / "default-scores"))  # never the repository's scores/
    monkeypatch.setenv("ARMGAME_CACHE", str(tmp_path / "cache"))  # nor the user's verification cache


def quick_replay(player: str = "ann", resets: int = 0, seed: int = 10) -> Replay:
    """A finished 0.2 s game: cheap to write and to verify; each player's own game (a game enters once)."""
    session = GameSession(GameConfig(time_limit=0.2, seed=seed))
    session.advance(sum(map(ord, player)) % 40)
    session.key_event("d", "down")
    for _ in range(resets):
        session.key_event("space", "down")
        session.key_event("space", "up")
    session.advance(session.total_steps)
    return Replay.from_session(session, "script", player=player)


def fake_entry(n: int, score: int, date: str = "2025-03-01T10:00:00+00:00", **changes) -> dict:
    entry = dict(id=f"{n:032x}", name=f"player {n}", driven="keyboard", driver=None, score=score, hits=score,
                 resets=0, seed=10, scene="game", duration=60.0, date=date, version="0.1.0",
                 replay=f"r{n}.json", replay_sha256="0" * 64)
    entry.update(changes)
    return entry


def write_table(folder: Path, entries: list[dict]) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "scores.json"
    path.write_text(json.dumps({"format": "armgame-scores", "format_version": 1, "entries": entries}))
    return path


def test_entries_are_best_first_ties_by_date(tmp_path):
    write_table(tmp_path, [
        fake_entry(1, 5, "2025-03-01T10:00:02+00:00"),
        fake_entry(2, 9),
        fake_entry(3, 5, "2025-03-01T10:00:01+00:00"),
        fake_entry(4, 5, "2025-03-01T11:00:00+01:00"),  # 10:00:00 UTC: the earliest of the fives
    ])
    warnings = []
    assert [e.id[-1] for e in ScoreTable(tmp_path, warnings.append).all_entries()] == ["2", "4", "3", "1"]
    assert warnings == []


def test_add_saves_the_replay_beside_the_table_and_checks_out(tmp_path):
    table = ScoreTable(tmp_path)
    entry = table.add(quick_replay("Ann Lee"))
    assert [e.id for e in table.all_entries()] == [entry.id]
    assert table.entries() == []  # a 0.2 s game is a custom game: kept, never ranked
    assert (tmp_path / "replays" / entry.replay).is_file() and entry.replay.endswith(".json")
    assert table.check(entry).ok
    assert Replay.load(table.replay_path(entry)).player == "Ann Lee"


def test_unnamed_or_unfinished_games_do_not_enter(tmp_path):
    table = ScoreTable(tmp_path)
    with pytest.raises(ValueError, match="name"):
        table.add(Replay.from_session(GameSession(GameConfig(time_limit=0.2)), "script"))
    session = GameSession(GameConfig(time_limit=0.2))
    session.advance(10)
    with pytest.raises(ValueError, match="end"):
        table.add(Replay.from_session(session, "keyboard", player="ann"))


def test_concurrent_writers_all_keep_their_entries(tmp_path):
    # spawn, as on Windows and macOS: fork from pytest's threads is deprecated from Python 3.12 on.
    ctx = multiprocessing.get_context("spawn")
    writers, each = 6, 5
    barrier = ctx.Barrier(writers)
    procs = [ctx.Process(target=table_writer.write, args=(str(tmp_path), w, each, barrier)) for w in range(writers)]
    for p in procs:
        p.start()
    for p in procs:
        p.join(30)
        assert p.exitcode == 0
    warnings = []
    entries = ScoreTable(tmp_path, warnings.append).all_entries()
    assert len(entries) == writers * each and len({e.id for e in entries}) == writers * each
    assert sorted({e.name for e in entries}) == [f"writer {w}" for w in range(writers)]
    assert warnings == [] and len(list((tmp_path / "replays").iterdir())) == writers * each


KILLED_WRITER = """
import sys
from pathlib import Path
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession
from armgame.records.replay import Replay
from armgame.records.scores import ScoreTable
table = ScoreTable(Path(sys.argv[1]))
for seed in range(int(sys.argv[2]), 10**9):  # a new game each time: the same replay enters once
    session = GameSession(GameConfig(time_limit=0.02, seed=seed))
    session.advance(session.total_steps)
    table.add(Replay.from_session(session, "script", player="looper"))
    if seed == int(sys.argv[2]):
        print("ready", flush=True)  # one entry is in: the kill lands among the following writes
"""


def test_a_writer_killed_mid_write_never_leaves_a_partial_table(tmp_path):
    # A big table makes each rewrite long enough for the kill to land inside one.
    write_table(tmp_path, [fake_entry(n, n % 50) for n in range(1, 2001)])
    before = len(parse_table((tmp_path / "scores.json").read_bytes())[0])
    for delay in (0.13, 0.37):
        proc = subprocess.Popen([sys.executable, "-c", KILLED_WRITER, str(tmp_path), str(int(delay * 10**6))],
                                stdout=subprocess.PIPE, cwd=REPO)
        assert proc.stdout.readline() == b"ready\n"
        deadline = time.monotonic() + delay
        while time.monotonic() < deadline:  # every read, at any moment, is a whole table
            entries, damage = parse_table((tmp_path / "scores.json").read_bytes())
            assert damage is None and len(entries) >= before
            before = len(entries)
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
        proc.stdout.close()
        entries, damage = parse_table((tmp_path / "scores.json").read_bytes())
        assert damage is None and len(entries) >= before
        before = len(entries)
    assert before > 2000  # the writer did get entries in
    # A leftover temporary file is never taken for the table, and the next write works.
    ScoreTable(tmp_path).add(quick_replay("after", seed=10**6))
    assert len(ScoreTable(tmp_path).all_entries()) == before + 1
    assert not list(tmp_path.glob(".scores.json.*.tmp"))  # a killed writer's leftovers are cleared


def test_a_truncated_table_is_kept_aside_and_its_valid_entries_recovered(tmp_path):
    table = ScoreTable(tmp_path, warn=(warnings := []).append)
    first, second = table.add(quick_replay("ann")), table.add(quick_replay("bob"))
    data = table.path.read_bytes()
    table.path.write_bytes(data[: data.index(second.id.encode()) + 10])  # cut inside the second entry
    assert [e.id for e in table.all_entries()] == [first.id]
    assert len(warnings) == 1 and "damaged" in warnings[0] and "1 valid entry recovered" in warnings[0]
    damaged = table.path.read_bytes()
    third = table.add(quick_replay("cleo"))
    kept = list(tmp_path.glob("scores.json.corrupt-*"))
    assert len(kept) == 1 and kept[0].read_bytes() == damaged  # the damaged file, byte for byte
    assert "kept as scores.json.corrupt-" in warnings[-1] and warnings[-1].count("\n") == 0
    assert {e.id for e in table.all_entries()} == {first.id, third.id}
    assert len(warnings) == 2  # the table is clean again


@pytest.mark.parametrize("bad", [
    dict(name="x" * 10_000),
    dict(name="ann\x1b[2J"),
    dict(name="bob\nalice"),
    dict(name="  "),
    dict(score=-3),
    dict(score=True),
    dict(score="9"),
    dict(score=7, hits=2),
    dict(duration=1e308),
    dict(duration=-1.0),
    dict(seed=2**70),
    dict(date="yesterday"),
    dict(date="2025-03-01T10:00:00"),
    dict(date="9999-12-31T23:59:59-23:59"),
    dict(date="0001-01-01T00:00:00+23:59"),
    dict(replay="../../../etc/passwd"),
    dict(replay="/etc/passwd.json"),
    dict(replay_sha256="abc"),
    dict(driven="psychic"),
    dict(extra="field"),
    dict(id="not hex"),
], ids=lambda d: next(iter(d)) + ":" + repr(next(iter(d.values())))[:12])
def test_hostile_entries_are_dropped_with_a_clear_message(tmp_path, bad):
    write_table(tmp_path, [fake_entry(1, 4), {**fake_entry(2, 3), **bad}, fake_entry(3, 2)])
    entries, damage = ScoreTable(tmp_path).read()
    assert [e.id[-1] for e in entries] == ["1", "3"]
    assert damage is not None and damage.reason.startswith("entry 2: ")
    assert len(damage.describe(tmp_path / "scores.json")) < 300


@pytest.mark.parametrize("content", [
    b"",
    b"\xff\xfe garbage \x00",
    b"[]",
    b'{"format": "armgame-scores", "format_version": 1, "entries": [NaN]}',
    b'{"format": "armgame-scores", "format_version": 1, "entries": [1e999]}',
    b'{"format": "armgame-scores", "format_version": 4, "entries": []}',
    b"[" * 100_000,
    b"cos\nsystem\n(S'echo pwned'\ntR.",
])
def test_garbage_tables_are_damage_not_a_crash(tmp_path, content):
    tmp_path.joinpath("scores.json").write_bytes(content)
    table = ScoreTable(tmp_path, warn=(warnings := []).append)
    assert table.all_entries() == [] and len(warnings) == 1
    table.add(quick_replay())
    assert len(table.all_entries()) == 1
    assert [p.read_bytes() for p in tmp_path.glob("scores.json.corrupt-*")] == [content]


def test_salvage_finds_entries_in_a_reformatted_broken_file(tmp_path):
    good = [fake_entry(1, 4), fake_entry(2, 3)]
    text = json.dumps({"format": "armgame-scores", "format_version": 1, "entries": good}, indent=4)
    entries, damage = parse_table(text[:-3].encode())  # the closing brackets lost
    assert damage and [e.id for e in entries] == [g["id"] for g in good]


def test_tampering_is_flagged(tmp_path, capsys):
    table = ScoreTable(tmp_path)
    honest = table.add(quick_replay("honest"))
    typed, swapped, missing, forged = (table.add(quick_replay(n)) for n in ("typed", "swapped", "missing", "forged"))
    other = table.add(quick_replay("swapped", resets=1))
    # A score typed into the table (hits too, to pass the schema).
    data = table.path.read_text()
    line = next(x for x in data.splitlines() if typed.id in x)
    data = data.replace(line, line.replace('"hits": 0', '"hits": 50').replace('"score": 0', '"score": 50'))
    # A forged replay whose hash was updated in the table as well: its game still does not add up.
    forged_path = table.replay_path(forged)
    d = json.loads(forged_path.read_text())
    d["result"].update(score=40, hits=40)
    forged_path.write_text(json.dumps(d))
    import hashlib
    line = next(x for x in data.splitlines() if forged.id in x)
    new_line = line.replace(forged.replay_sha256, hashlib.sha256(forged_path.read_bytes()).hexdigest())
    data = data.replace(line, new_line.replace('"hits": 0', '"hits": 40').replace('"score": 0', '"score": 40'))
    table.path.write_text(data)
    # Another game's replay put in place of this one's; a replay deleted.
    table.replay_path(swapped).write_bytes(table.replay_path(other).read_bytes())
    table.replay_path(missing).unlink()
    labels = {e.name: table.check(e).label for e in table.all_entries() if e.id != other.id}
    assert labels == {"honest": "ok", "typed": "NOT ITS REPLAY", "swapped": "REPLAY CHANGED",
                      "missing": "REPLAY MISSING", "forged": "NOT REPRODUCED"}
    assert table.check(honest).ok
    code = main(["scores", "--scores", str(tmp_path)])
    out = capsys.readouterr().out
    assert code == 0 and "4 flagged" in out and "NOT REPRODUCED" in out
    assert main(["verify", str(tmp_path)]) == 1
    assert "4 flagged" in capsys.readouterr().out


def test_cli_headless_play_enters_the_table_only_with_a_name(tmp_path, capsys):
    folder = tmp_path / "table"
    assert main(["play", "--headless", "--duration", "0.2", "--scores", str(folder)]) == 0
    assert not folder.exists()
    assert main(["play", "--headless", "--duration", "0.2", "--scores", str(folder), "--name", "Zoe"]) == 0
    assert main(["play", "--headless", "--duration", "0.2", "--scores", str(folder), "--name", "Yan",
                 "--json", "--seed", "11"]) == 0
    out = capsys.readouterr().out
    assert "saved to the high-score table as Zoe" in out
    assert json.loads(out.splitlines()[-1])["score"] == 0  # with --json, stdout is only the JSON
    assert main(["scores", "--scores", str(folder)]) == 0
    out = capsys.readouterr().out.splitlines()
    # Headless games are a program's, and 0.2 s games not the standard game: listed apart, never ranked.
    assert out[2].strip() == "no ranked games yet" and out[3].startswith("Programs")
    assert out[4].split()[:4] == ["#", "name", "score", "games"]
    assert [row.split()[1] for row in out[5:7]] == ["Zoe", "Yan"]  # equal scores: the earlier entry first
    assert all(row.rstrip().endswith("ok") and " script " in row for row in out[5:7])
    assert out[7].startswith("One row a player") and len(out) == 8


@pytest.mark.parametrize("name", ["x" * 10_000, "a\x07b", "   "])
def test_a_bad_name_is_refused_before_the_game(tmp_path, capsys, name):
    assert main(["play", "--headless", "--scores", str(tmp_path), "--name", name]) == 2
    err = capsys.readouterr().err
    assert err.startswith("armgame play: error: --name") and err.count("\n") == 1
    assert not list(tmp_path.iterdir())


def test_scores_on_an_empty_folder(tmp_path, capsys):
    assert main(["scores", "--scores", str(tmp_path)]) == 0
    assert "no scores yet" in capsys.readouterr().out


def test_where_the_table_lives(tmp_path, monkeypatch):
    monkeypatch.setenv("ARMGAME_SCORES", str(tmp_path / "env"))
    assert default_scores_dir() == tmp_path / "env"
    monkeypatch.delenv("ARMGAME_SCORES")
    assert default_scores_dir() == REPO / "scores"  # running from this checkout
    monkeypatch.setattr(scores_module, "__file__", str(tmp_path / "site-packages" / "armgame" / "scores.py"))
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    assert default_scores_dir() == tmp_path / "data" / "armgame" / "scores"


def test_table_file_is_one_entry_a_line_and_reads_back(tmp_path):
    entries = [ScoreEntry.from_dict(fake_entry(n, n)) for n in (1, 2, 3)]
    data = table_bytes(entries)
    assert len(data.splitlines()) == 5
    assert parse_table(data) == (sorted(entries, key=lambda e: -e.score), None)


# ----------------------------------------------------------------- the name prompt in the window

@pytest.fixture
def finished_window():
    import pygame

    from armgame.ui.frontend import NAME_ENTRY_DELAY, GameWindow, open_window

    def make(**options):
        window = GameWindow(GameSession(GameConfig(time_limit=0.2)), open_window((500, 500)), fps=0, **options)
        while not window.session.over:
            window.frame(0.05)
        window.frame(NAME_ENTRY_DELAY)
        return window

    yield make
    pygame.display.quit()


def post(*events):
    import pygame

    for kind, value in events:
        if kind == "text":
            pygame.event.post(pygame.event.Event(pygame.TEXTINPUT, text=value))
        else:
            pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=value, mod=0, unicode="", scancode=0))


def test_the_end_screen_asks_for_a_name(finished_window):
    import pygame

    window = finished_window(ask_name=True)
    assert window.name_entry == "" and window.running
    post(("text", "Ann"), ("text", "\x1b"), ("text", "e"), ("key", pygame.K_BACKSPACE), ("text", " Lee"))
    window.frame(0.0)
    assert window.name_entry == "Ann Lee"
    post(("key", pygame.K_RETURN))
    window.frame(0.0)
    assert window.player_name == "Ann Lee" and window.running  # the end screen stays until a key
    window.frame(1.0)
    post(("key", pygame.K_x))  # not a key of the end screen
    window.frame(0.0)
    assert window.running
    post(("key", pygame.K_RETURN))
    window.frame(0.0)
    assert not window.running and window.play_again


def test_keys_mashed_as_the_clock_ends_are_not_typed_and_esc_saves_nothing(finished_window):
    import pygame

    window = finished_window(ask_name=True)
    window.name_entry, window._over_for = "", 0.0  # the moment the game ended
    post(("text", "d"), ("text", "f"), ("key", pygame.K_RETURN))
    window.frame(0.0)
    assert window.name_entry == "" and window.running  # nothing typed, and Enter on nothing does nothing
    post(("key", pygame.K_ESCAPE))
    window.frame(0.0)
    assert window.player_name is None and not window.running


def test_no_prompt_when_the_name_is_known(finished_window):
    window = finished_window(ask_name=False)
    assert window.name_entry is None


def _entry_by_the_generic_checks(data: object) -> ScoreEntry:
    """What ``ScoreEntry.from_dict`` did before it was written out field by field: the reference its
    fast paths must agree with, value for value and first error for first error."""
    from armgame import valid as v
    from armgame.records.replay import DRIVEN

    check_date, check_float, check_int, check_name, check_str, check_word = (
        v.check_date, v.check_float, v.check_int, v.check_name, v.check_str, v.check_word)
    check_bool, check_keys, HEX32, HEX64 = v.check_bool, v.check_keys, v.HEX32, v.HEX64
    m, big = v.check_pattern, 10**9
    d = check_keys("entry", data, entry_module._REQUIRED, entry_module._OPTIONAL)
    driven = check_str("driven", d["driven"], 20)
    if driven not in DRIVEN:
        raise ValueError(f"driven must be one of {', '.join(DRIVEN)}, got {driven!r}")
    h32, h64 = HEX32, HEX64
    ruleset, digest, game, entered, entered_at, complete = (
        d.get(k) for k in ("ruleset", "config_sha256", "game_sha256", "entered", "entered_at", "complete"))
    entry = ScoreEntry(
        id=m("id", d["id"], h32), name=check_name(d["name"]), driven=driven,
        driver=None if d["driver"] is None else check_str("driver", d["driver"], 200),
        score=check_int("score", d["score"], 0, big), hits=check_int("hits", d["hits"], 0, big),
        resets=check_int("resets", d["resets"], 0, big), seed=check_int("seed", d["seed"], 0, 2**63 - 1),
        scene=check_word("scene", d["scene"]),
        duration=check_float("duration", d["duration"], 0.0, 86400.0, low_open=True),
        date=check_date("date", d["date"]), version=check_word("version", d["version"]),
        replay=m("replay", d["replay"], entry_module._REPLAY_FILE),
        replay_sha256=m("replay_sha256", d["replay_sha256"], h64),
        ruleset=None if ruleset is None else check_word("ruleset", ruleset),
        config_sha256=None if digest is None else m("config_sha256", digest, h64),
        game_sha256=None if game is None else m("game_sha256", game, h64),
        entered=None if entered is None else check_int("entered", entered, 1, big),
        entered_at=None if entered_at is None else check_date("entered_at", entered_at),
        complete=None if complete is None else check_bool("complete", complete),
    )
    if (entry.ruleset is None) != (entry.config_sha256 is None):
        raise ValueError("ruleset and config_sha256 come together")
    if entry.score > entry.hits:
        raise ValueError(f"score {entry.score} is more than the hits {entry.hits}")
    if entry.name != d["name"]:
        raise ValueError(f"name {d['name']!r} has surrounding spaces")
    return entry


class _Text(str):
    pass


def test_entry_checks_written_out_agree_with_the_generic_checks():
    words = ["game", "", " game", "game ", "a" * 40, "a" * 41, "g\u00e9", "x\ny", "\u00e9t\u00e9", _Text("game"),
             "ok.1+2_-", "-a", 7, None, True, 1.5, ["game"]]
    hexes = ["0" * 32, "0" * 64, "A" * 64, "0" * 63, "0" * 65, "g" * 64, "0" * 63 + "\n", _Text("0" * 64), 0, None]
    numbers = [0, 1, -1, 10**9, 10**9 + 1, 2**63 - 1, 2**63, True, False, 1.0, 60.0, 86400.0, 86400.5, 0.0, -0.0,
               1e-300, float("nan"), float("inf"), "9", None, 3]
    values = {
        "id": [*hexes, "0" * 31 + "g"],
        "name": [*words, "a" * 39 + " ", " " * 3, "\u00a0ann", "ann\u00a0", "a" * 200],
        "driven": ["keyboard", "script", "bot", "psychic", _Text("bot"), None, 1, "x" * 30, "bot\n"],
        "driver": [*words, "d" * 200, "d" * 201], "score": numbers, "hits": numbers, "resets": numbers,
        "seed": numbers, "scene": words, "duration": numbers, "version": words,
        "date": ["2025-03-01T10:00:00+00:00", "2025-03-01T10:00:00", "yesterday", 1, None],
        "replay": ["r.json", "../r.json", "r" * 151 + ".json", "r" * 150 + ".json", "r.JSON", _Text("r.json"), 1],
        "replay_sha256": hexes, "ruleset": words, "config_sha256": hexes, "game_sha256": hexes, "entered": numbers,
        "entered_at": ["2025-03-01T10:00:00+00:00", "now", None], "complete": [True, False, None, 1, "true"],
    }
    base = fake_entry(1, 3, ruleset="standard", config_sha256="1" * 64, game_sha256="2" * 64, entered=1,
                      entered_at="2025-03-01T10:00:01+00:00", complete=True)

    def outcome(read, data):
        try:
            entry = read(data)
        except ValueError as exc:
            return str(exc)
        return [(k, type(v), v) for k, v in vars(entry).items()]

    cases = [{**base, field: value} for field, vs in values.items() for value in vs]
    cases += [{k: v for k, v in base.items() if k != field} for field in base]
    cases += [{**base, "extra": 1}, {**fake_entry(1, 3)}, [base], "entry", None]
    for data in cases:
        assert str(outcome(ScoreEntry.from_dict, data)) == str(outcome(_entry_by_the_generic_checks, data)), data
