"""Issue 9's attacks, one class at a time, as a hostile classmate would try them.

Classes: (1) only the standard game ranks, (2) one bad entry never takes the table down,
(3) bounded work, (4) files are never misused, (5) nothing committed is lost, (6) one line,
never a traceback or a hang. Everything is written under tmp_path.
"""

import copy
import json
import os
import subprocess
import sys
import threading
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import armgame.records.batch_verify as batch_verify
import armgame.records.replay as replay_module
import armgame.records.tablefile as tablefile_module
from armgame import __version__
from armgame.cli import main
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession, NonFiniteStateError
from armgame.records.locking import file_lock
from armgame.records.replay import Replay, config_to_dict
from armgame.records.rulesets import RULESETS, config_digest, ruleset_name
from armgame.records.scores import ScoreTable, parse_table
from armgame.records.storage import DataFileError, atomic_write_bytes, read_limited

REPO = Path(__file__).resolve().parent.parent


@pytest.fixture(autouse=True)
def _private_folders(tmp_path, monkeypatch):
    monkeypatch.setenv("ARMGAME_SCORES", str(tmp_path / "default-scores"))
    monkeypatch.setenv("ARMGAME_CACHE", str(tmp_path / "cache"))


def game(player="ann", seed=10, driven="keyboard", **config) -> Replay:
    """A finished game, standard unless ``config`` says otherwise, with a few key presses: a keyboard
    game of the table's seed (ranked) unless told otherwise, each player's own (a game enters once)."""
    session = GameSession(GameConfig(seed=seed, **config))
    session.key_event("d", "down")
    session.advance(session.total_steps // 3 + sum(map(ord, player)) % 50)
    session.key_event("d", "up")
    session.advance(session.total_steps)
    return Replay.from_session(session, driven, None if driven == "keyboard" else "s.txt", player=player)


def armgame(*argv, timeout=20, env=None):
    """Run the real program in a subprocess: hangs and tracebacks show up as they would for a user."""
    return subprocess.run([sys.executable, "-m", "armgame", *map(str, argv)], capture_output=True, text=True,
                          timeout=timeout, cwd=REPO, env={**os.environ, **(env or {})})


def one_line_error(proc) -> str:
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    return lines[0]


# ------------------------------------------------------------------ 1. ranked play is the standard game

def test_standard_ruleset_is_the_default_game_whatever_the_seed_and_keys():
    from armgame.game.muscles import DEFAULT_MUSCLES, remap_keys

    assert ruleset_name(GameConfig(seed=123)) == "standard"
    assert ruleset_name(GameConfig(muscles=remap_keys(DEFAULT_MUSCLES, "asdf"))) == "standard"
    assert RULESETS["standard"].steps == 15_000
    for change in (dict(target_radius=0.06), dict(time_limit=61.0), dict(dt=0.002), dict(integrator="euler"),
                   dict(view=(-0.8, 0.8, -0.4, 1.25)), dict(start_posture=(0.8, 1.5)),
                   dict(target_elbow_range=(45.0, 91.0))):
        assert ruleset_name(GameConfig(**change)) == "custom", change
    # The digest is of the canonical config, floats by repr: the next float up is another game.
    import math
    assert config_digest(GameConfig(target_radius=math.nextafter(0.05, 1.0))) != config_digest(GameConfig())


def test_a_rigged_game_is_kept_but_never_ranked(tmp_path, capsys):
    table = ScoreTable(tmp_path)
    fair = table.add(game("fair"))
    rigged = table.add(game("rigger", target_radius=0.4))  # a huge target: many hits
    assert rigged.score > fair.score and rigged.ruleset == "custom" and fair.ruleset == "standard"
    assert [e.id for e in table.entries()] == [fair.id]
    assert table.rank(fair) == 1
    assert main(["scores", "--scores", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    ranked, custom = out.split("Custom games")
    assert "fair" in ranked and "rigger" not in ranked and "rigger" in custom
    assert main(["verify", str(table.replay_path(rigged))]) == 0
    assert "custom rules" in capsys.readouterr().out
    assert main(["verify", str(table.replay_path(fair))]) == 0
    assert "standard rules" in capsys.readouterr().out


def test_an_entry_that_claims_the_standard_rules_for_a_custom_replay_is_flagged(tmp_path):
    table = ScoreTable(tmp_path)
    rigged = table.add(game("rigger", target_radius=0.4))
    text = table.path.read_text().replace(rigged.config_sha256, RULESETS["standard"].digest)
    table.path.write_text(text.replace('"ruleset": "custom"', '"ruleset": "standard"'))
    (entry,) = table.entries()  # the table claims it ranks...
    check = table.check(entry)  # ...its replay says otherwise
    assert not check.ok and check.label == "NOT ITS REPLAY" and "config_sha256" in check.detail


@pytest.mark.parametrize("field", ["name", "driver", "seed", "date"])
def test_an_entry_must_say_what_its_replay_says(tmp_path, field):
    table = ScoreTable(tmp_path)
    entry = table.add(game())
    changed = {"name": "bob", "driver": "other.txt", "seed": 11, "date": "2020-01-01T00:00:00+00:00"}[field]
    data = json.loads(table.path.read_text())
    data["entries"][0][field] = changed
    table.path.write_text(json.dumps(data))
    (entry,) = table.all_entries()
    assert table.check(entry).label == "NOT ITS REPLAY"


def test_the_same_replay_enters_once(tmp_path, capsys):
    table = ScoreTable(tmp_path)
    replay = game()
    entry = table.add(replay)
    with pytest.raises(DataFileError, match="already in the table"):
        table.add(replay)
    # Planted by hand: a second entry for the same replay is flagged, never ranked twice.
    data = json.loads(table.path.read_text())
    data["entries"].append({**data["entries"][0], "id": "f" * 32, "date": entry.date})
    table.path.write_text(json.dumps(data))
    assert main(["scores", "--scores", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "DUPLICATE" in out and "1 flagged" in out


# ------------------------------------------------------------------ 2. one bad entry never takes the table down

@pytest.mark.parametrize(("path", "value", "field"), [
    (("arm", "m1"), 1e-300, "config.arm.m1"),
    (("arm", "i2"), 1e-300, "config.arm.i2"),
    (("arm", "l1"), 1e5, "config.arm.l1"),
    (("arm", "gravity"), 1e9, "config.arm.gravity"),
    (("muscles", 0, "moment", 0), 1e30, "config.muscles[0].moment[0]"),
    (("muscles", 1, "rise_time"), 1e-300, "config.muscles[1].rise_time"),
    (("muscles", 2, "decay_time"), 0.001, "config.muscles[2].decay_time"),  # shorter than one step
    (("dt",), 1e-9, "config.dt"),
    (("target_radius",), 50.0, "config.target_radius"),
    (("view", 1), -5.0, "config.view"),
    (("time_limit",), 1e7, "config.time_limit"),
])
def test_parameters_out_of_range_are_refused_at_load_naming_the_field(tmp_path, path, value, field):
    data = json.loads(game().to_bytes())
    where = data["config"]
    for key in path[:-1]:
        where = where[key]
    where[path[-1]] = value
    with pytest.raises(DataFileError, match=field.replace("[", r"\[").replace("]", r"\]")) as info:
        Replay.from_bytes(json.dumps(data).encode(), "r.json")
    assert "\n" not in str(info.value)


def test_a_run_that_goes_non_finite_stops_with_one_line():
    from armgame.game.muscles import MuscleSpec

    muscles = tuple(MuscleSpec(f"m{i}", k, (50.0, -50.0), 0.02, 0.02) for i, k in enumerate("dfjk"))
    session = GameSession(GameConfig(integrator="euler", dt=0.02, muscles=muscles,
                                     arm=GameConfig().arm.replace(m1=0.01, m2=0.01, i1=1e-5, i2=1e-5)))
    session.key_event("d", "down")
    with pytest.raises(NonFiniteStateError, match="non-finite"):
        session.advance(session.total_steps)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # numpy overflowing on the way to NaN: expected
@pytest.mark.parametrize("kernel", ["compiled", "numpy"])
@pytest.mark.parametrize("integrator", ["rk4", "euler"])
def test_a_batch_that_goes_non_finite_stops_with_one_line_as_the_single_game_does(kernel, integrator):
    from armgame.game.batch import BatchGameSession, compiled
    from armgame.game.muscles import MuscleSpec
    from armgame.game.session import InputEvent

    if kernel == "compiled" and not (compiled.AVAILABLE or os.environ.get("ARMGAME_REQUIRE_COMPILED")):
        pytest.skip("the compiled kernel is not built here")
    muscles = tuple(MuscleSpec(f"m{i}", k, (50.0, -50.0), 0.02, 0.02) for i, k in enumerate("dfjk"))
    # A 3 s game: this arm blows up in its first steps, and the calm games need not play the standard 60 s on.
    wild = GameConfig(integrator=integrator, dt=0.02, muscles=muscles, time_limit=3.0,
                      arm=GameConfig().arm.replace(m1=0.01, m2=0.01, i1=1e-5, i2=1e-5))
    single = GameSession(wild)
    with pytest.raises(NonFiniteStateError):
        single.play([InputEvent(0, "d", "down")])
    calm: list[InputEvent] = []  # no torque: this arm stays where it is
    for play in (lambda b: b.play([calm, [InputEvent(0, "d", "down")], calm]),
                 lambda b: (b.set_held(np.array([[False] * 4, [True, False, False, False], [False] * 4])),
                            b.advance(b.config.total_steps))):
        batch = BatchGameSession([replace(wild, seed=s) for s in range(3)], kernel=kernel)
        with pytest.raises(NonFiniteStateError, match=r"^game 1: .*non-finite.*blows up") as info:
            play(batch)
        assert "\n" not in str(info.value)


def test_one_failing_entry_is_marked_and_the_others_are_still_checked(tmp_path, capsys, monkeypatch):
    table = ScoreTable(tmp_path)
    good = [table.add(game(f"p{i}", seed=i)) for i in range(3)]
    bad = table.add(game("boom", seed=99))
    real = Replay.verify

    def verify(self):
        if self.player == "boom":
            raise RuntimeError("anything at all")
        return real(self)

    monkeypatch.setattr(Replay, "verify", verify)

    def no_batch(*args, **kwargs):
        raise RuntimeError("the batch stops")  # so the listing falls back to one game at a time

    monkeypatch.setattr(batch_verify, "replay_many", no_batch)
    assert table.check(bad).label == "BAD REPLAY"
    assert main(["scores", "--scores", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "BAD REPLAY: anything at all" in out and all(e.name in out for e in good)
    assert main(["verify", str(tmp_path)]) == 1
    out = capsys.readouterr().out
    assert out.count(": ok") == 3 and "BAD REPLAY" in out


# ------------------------------------------------------------------ 3. bounded work

def test_a_replay_longer_than_the_limit_is_refused_before_running(tmp_path, capsys):
    data = json.loads(game(time_limit=1.0).to_bytes())
    data["config"]["time_limit"] = 3600.0
    data["config"]["dt"] = 1e-4  # 36 M steps
    data["result"].update(steps=36_000_000, duration=3600.0, dt=1e-4)
    path = tmp_path / "long.json"
    path.write_text(json.dumps(data))
    line = in_process_error(capsys, "verify", path)
    assert "physics steps long" in line or "config.dt" in line


def test_a_refused_replay_runs_no_physics_step(tmp_path, monkeypatch, capsys):
    """The work is bounded before it starts: not one step of the 36 M is simulated (counted, not timed)."""
    data = json.loads(game(time_limit=1.0).to_bytes())
    data["config"]["time_limit"] = 3600.0
    data["config"]["dt"] = 1e-4
    data["result"].update(steps=36_000_000, duration=3600.0, dt=1e-4)
    path = tmp_path / "long.json"
    path.write_text(json.dumps(data))
    ran = []
    real = GameSession._advance
    monkeypatch.setattr(GameSession, "_advance", lambda self, n: ran.append(n) or real(self, n))
    assert main(["verify", str(path)]) == 2
    assert ran == [] and len(capsys.readouterr().err.strip().splitlines()) == 1


def test_verification_stops_once_the_replay_passes_its_claim():
    # A target as big as the view is hit almost every step: the claim of 0 hits ends the replay early.
    # The 600 s claim is written into a 20 s game's replay (hits in it): the test need not play
    # 150,000 steps to forge it.
    replay = game(target_radius=0.5, view=(-5.0, 5.0, -5.0, 5.0), time_limit=20.0)
    assert replay.result.hits > 0 and replay.result.steps % replay_module._VERIFY_CHUNK == 0
    data = json.loads(replay.to_bytes())
    data["config"]["time_limit"] = 600.0
    data["result"].update(score=0, hits=0, steps=150_000, duration=600.0)
    forged = Replay.from_bytes(json.dumps(data).encode())
    assert forged.result.steps == 150_000
    ok, got = forged.verify()
    # Counted, not timed: the replay stopped within the 20 s that scored, not after the 150,000 steps claimed.
    assert not ok and 0 < got.steps <= replay.result.steps and got.hits > 0


def test_scores_replays_each_game_once_then_uses_the_per_user_cache(tmp_path, monkeypatch, capsys):
    folder = tmp_path / "table"
    table = ScoreTable(folder)
    for i in range(4):
        table.add(game(f"p{i}", seed=i))
    calls = []
    real = batch_verify.verify_replays
    monkeypatch.setattr(batch_verify, "verify_replays",
                        lambda replays, kernel=None: calls.extend(r.player for r in replays) or real(replays, kernel))
    assert main(["scores", "--scores", str(folder)]) == 0
    assert len(calls) == 4
    assert main(["scores", "--scores", str(folder)]) == 0
    assert len(calls) == 4  # all from the cache
    assert not list(folder.glob("*verified*")) and list((tmp_path / "cache").glob("verified-*.json"))
    assert main(["scores", "--scores", str(folder), "--cache", str(tmp_path / "other")]) == 0
    assert len(calls) == 8
    out = capsys.readouterr().out
    assert out.count(" ok") >= 12


def test_scores_checks_at_most_top_custom_entries_flagged_or_not(tmp_path, monkeypatch, capsys):
    table = ScoreTable(tmp_path)
    for i in range(6):
        table.add(game(f"c{i}", seed=i, time_limit=0.2))
    for entry in table.all_entries():  # every custom replay planted broken
        table.replay_path(entry).write_text("{}")
    checked = []
    real = ScoreTable.check_many
    monkeypatch.setattr(ScoreTable, "check_many",
                        lambda self, es, *args: checked.extend(e.name for e in es) or real(self, es, *args))
    assert main(["scores", "--scores", str(tmp_path), "--top", "2"]) == 0
    assert len(checked) == 2 and "2 flagged" in capsys.readouterr().out


def test_a_planted_cache_beside_the_table_is_not_trusted(tmp_path, capsys):
    table = ScoreTable(tmp_path)
    entry = table.add(game())
    forged = json.loads(table.replay_path(entry).read_text())
    forged["result"].update(score=40, hits=40)
    atomic_write_bytes(table.replay_path(entry), json.dumps(forged).encode())
    data = json.loads(table.path.read_text())
    import hashlib
    data["entries"][0].update(score=40, hits=40,
                              replay_sha256=hashlib.sha256(table.replay_path(entry).read_bytes()).hexdigest())
    table.path.write_text(json.dumps(data))
    # Whatever name a classmate guesses, the running version's cache name among them.
    for name in (f"verified-{__version__}.json", "cache.json"):
        (tmp_path / name).write_text(json.dumps({"format": "armgame-verified", "version": __version__, "items": {
            data["entries"][0]["replay_sha256"]: {"ok": True, "label": "ok", "detail": "", "claims": None}}}))
    assert main(["verify", str(tmp_path)]) == 1
    assert "NOT REPRODUCED" in capsys.readouterr().out


def in_process_error(capsys, *argv) -> str:
    """``main(argv)``'s one line on stderr and exit 2, as ``one_line_error`` checks a subprocess's."""
    assert main([str(a) for a in argv]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1, lines
    return lines[0]


def test_play_refuses_up_front_what_it_could_not_replay(tmp_path, monkeypatch, capsys):
    """Counted, not timed: neither refusal plays a single step."""
    ran = []
    monkeypatch.setattr(GameSession, "_advance", lambda self, n: ran.append(n) or 0)
    assert "--duration" in in_process_error(capsys, "play", "--headless", "--duration", "86400")
    script = tmp_path / "many.txt"
    script.write_text("".join(f"{i * 0.004:.3f} d {'down' if i % 2 == 0 else 'up'}\n" for i in range(200_001)))
    assert "more than 200000 events" in in_process_error(capsys, "play", "--headless", "--script", script,
                                                         "--duration", "900")
    assert ran == []


def test_a_game_that_reaches_the_event_limit_stops_there_and_replays(tmp_path, monkeypatch, capsys):
    import armgame.game.session as session_module

    monkeypatch.setattr(session_module, "MAX_EVENTS", 40)
    record = tmp_path / "bot.json"
    assert main(["play", "--headless", "--bot", "model", "--record", str(record), "--name", "bot",
                 "--scores", str(tmp_path / "t")]) == 0
    captured = capsys.readouterr()
    assert "reached 40 input events" in captured.err and "stopped before the end" in captured.out
    replay = Replay.load(record)
    assert len(replay.timeline) == 40 and not replay.complete and replay.verify()[0]


@pytest.mark.parametrize(("args", "message"), [
    (["--dt", "1e-12"], "10,000,000,000,000 steps"),
    (["--duration", "1e7"], "too large"),
    (["--sample-rate", "1e9", "--dt", "1e-6", "--duration", "100"], "too large"),
    (["--dt", "10", "--duration", "100"], "blew up"),
    (["--dt", "10"], "blew up"),  # the case: one step, a finite state moving at 1e18 rad/s
    (["--initial=1e308,1e308,1e308,1e308", "--integrator", "dop853"], "--initial"),
    (["--initial=700,0,1e6,0", "--integrator", "dop853"], "--initial"),
])
def test_simulate_refuses_or_stops_in_one_line(tmp_path, args, message, monkeypatch, capsys):
    """In-process, the work counted (not timed): a refusal steps the arm not once, a blow-up at
    most the ten steps it took to show."""
    import armgame.simulation as simulation

    steps = []

    class CountingIntegrator(simulation.Integrator):
        def __init__(self, *a, **k):
            super().__init__(*a, **k)
            real = self.step_components
            self.step_components = lambda *x: steps.append(1) or real(*x)

    monkeypatch.setattr(simulation, "Integrator", CountingIntegrator)
    monkeypatch.setattr(simulation, "reference_trajectory", lambda *a, **k: pytest.fail("the reference ran"))
    out = tmp_path / "x.csv"
    args = ["--scene", "passive", *args] if "--scene" not in args else args
    assert main(["simulate", *args, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not out.exists() and not list(tmp_path.iterdir())
    assert (1 <= len(steps) <= 10) if message == "blew up" else steps == []


def test_simulate_reports_a_dop853_blow_up(tmp_path, monkeypatch):
    import armgame.simulation as sim
    from armgame.errors import UserError
    from armgame.scenes import get_scene

    monkeypatch.setattr(sim, "reference_trajectory", lambda *a, **k: __import__("numpy").full((len(a[2]), 4), 1e400))
    with pytest.raises(UserError, match="blew up"):
        sim.simulate_to_csv(get_scene("passive"), "dop853", 0.01, tmp_path / "x.csv", 1.0)
    assert not list(tmp_path.iterdir())


def test_dop853_has_an_evaluation_budget(tmp_path, monkeypatch):
    import armgame.simulation as sim
    from armgame.errors import UserError
    from armgame.scenes import get_scene

    monkeypatch.setattr(sim, "DOP853_MAX_EVALS", 1000)
    with pytest.raises(UserError, match="budget of 1,000 evaluations"):
        sim.simulate_to_csv(get_scene("propeller"), "dop853", 0.01, tmp_path / "x.csv", 10.0)
    assert not list(tmp_path.iterdir())


def test_simulate_streams_rows_in_chunks():
    from armgame.scenes import get_scene
    from armgame.simulation import _CHUNK_ROWS, stream

    chunks = list(stream(get_scene("passive"), "rk4", 0.001, 30.0, sample_rate=1000.0))
    assert max(len(t) for t, _ in chunks) == _CHUNK_ROWS and sum(len(t) for t, _ in chunks) == 30_001


# ------------------------------------------------------------------ 4. files are never misused

def test_outputs_are_only_regular_files(tmp_path, capsys):
    """A FIFO in a subprocess (were it opened for writing, it would wait for a reader: the timeout
    shows the hang); a device and a folder in-process."""
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    (tmp_path / "dir").mkdir()
    for target in ("/dev/null", fifo, tmp_path / "dir"):
        for cmd in (["simulate", "--scene", "passive", "--duration", "0.1", "--out", target],
                    ["play", "--headless", "--duration", "0.1", "--record", target]):
            if cmd[0] == "play" and target == tmp_path / "dir":
                continue  # play --record FOLDER: a numbered file inside it (test_new_files)
            line = one_line_error(armgame(*cmd, timeout=10)) if target == fifo else in_process_error(capsys, *cmd)
            assert "is a " in line and "regular file" in line
    assert os.path.exists("/dev/null") and fifo.is_fifo()


def test_a_planted_temporary_symlink_is_never_written_through(tmp_path):  # in-process: nothing here can hang
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    out = tmp_path / "out.csv"
    for name in ("out.csv.part", ".out.csv.tmp", "out.csv.tmp"):
        (tmp_path / name).symlink_to(victim)
    out.symlink_to(victim)  # even the target itself: refused, and with --force replaced, never written through
    assert main(["simulate", "--scene", "passive", "--duration", "0.1", "--out", str(out)]) == 2
    assert victim.read_text() == "precious" and out.is_symlink()
    assert main(["simulate", "--scene", "passive", "--duration", "0.1", "--out", str(out), "--force"]) in (0, None)
    assert victim.read_text() == "precious" and out.is_file() and not out.is_symlink()


@pytest.mark.slow  # each command against a FIFO: about 2 s
def test_inputs_that_are_fifos_never_hang(tmp_path):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    table = tmp_path / "t"
    table.mkdir()
    os.mkfifo(table / "scores.json")
    for cmd in (["play", "--headless", "--script", fifo], ["verify", fifo], ["replay", "--headless", fifo],
                ["scores", "--add", fifo, "--scores", tmp_path / "u"], ["scores", "--scores", table],
                ["verify", table]):
        line = one_line_error(armgame(*cmd, timeout=10))
        assert "FIFO" in line or "no score table" in line, line


def test_symlinked_replays_folder_or_lock_is_refused(tmp_path):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    for planted in ("replays", "scores.lock"):
        folder = tmp_path / planted
        folder.mkdir()
        (folder / planted).symlink_to(elsewhere / planted if planted == "scores.lock" else elsewhere)
        with pytest.raises(DataFileError, match="symbolic link"):
            ScoreTable(folder).add(game())
        assert not list(elsewhere.iterdir())


def test_a_replay_planted_as_a_symlink_is_not_followed(tmp_path):
    table = ScoreTable(tmp_path)
    entry = table.add(game())
    secret = tmp_path / "secret.json"
    secret.write_bytes(table.replay_path(entry).read_bytes())
    table.replay_path(entry).unlink()
    table.replay_path(entry).symlink_to(secret)
    check = table.check(entry)
    assert check.label == "REPLAY UNREADABLE" and "symbolic link" in check.detail


def test_a_busy_table_keeps_the_game_and_says_how_to_enter_it(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(tablefile_module, "LOCK_WAIT", 0.3)
    folder = tmp_path / "t"
    ScoreTable(folder).add(game("first"))
    holder = file_lock(folder / "scores.lock", 1.0)
    waits = []  # counted, not timed: play asks for the lock once, for LOCK_WAIT, and gives up
    monkeypatch.setattr(tablefile_module, "file_lock",
                        lambda path, wait, *mode: waits.append(wait) or file_lock(path, wait, *mode))
    holder.__enter__()  # someone else holds the table
    try:
        code = main(["play", "--headless", "--duration", "0.5", "--name", "Late", "--scores", str(folder)])
    finally:
        holder.__exit__(None, None, None)
    assert waits == [0.3]
    err = capsys.readouterr().err
    assert code == 2 and "busy" in err and err.count("\n") == 1
    command = err[err.index("armgame scores"):].strip()
    argv = command.split()[1:]
    assert main(argv) == 0
    assert "entered Late's game" in capsys.readouterr().out
    assert sorted(e.name for e in ScoreTable(folder).all_entries()) == ["Late", "first"]


def test_scores_add_enters_a_recorded_game_once_and_checks_it(tmp_path, capsys):
    record = tmp_path / "mine.json"
    assert main(["play", "--headless", "--record", str(record)]) == 0
    folder = tmp_path / "t"
    assert main(["scores", "--scores", str(folder), "--add", str(record)]) == 2
    assert "--name" in capsys.readouterr().err
    assert main(["scores", "--scores", str(folder), "--add", str(record), "--name", "Kim"]) == 0
    assert "ranked" in capsys.readouterr().out
    assert main(["scores", "--scores", str(folder), "--add", str(record), "--name", "Kim"]) == 0  # a loop run again
    assert capsys.readouterr().out.startswith("already in: Kim's game")
    assert main(["scores", "--scores", str(folder), "--add", str(record), "--name", "Lee"]) == 2  # another's copy
    assert "already in the table" in capsys.readouterr().err
    data = json.loads(record.read_text())
    data["result"]["score"] = data["result"]["hits"] = 30
    record.write_text(json.dumps(data))
    assert main(["scores", "--scores", str(folder), "--add", str(record), "--name", "Kim"]) == 2
    assert "does not reproduce" in capsys.readouterr().err


# ------------------------------------------------------------------ 5. nothing committed is lost

def test_a_damaged_table_on_a_full_disk_loses_nothing(tmp_path, monkeypatch):
    table = ScoreTable(tmp_path, warn=lambda m: None)
    first, second = table.add(game("ann", time_limit=1.0)), table.add(game("al", time_limit=1.0))
    damaged = table.path.read_bytes()
    damaged = damaged[: damaged.index(second.id.encode())]  # cut inside the second entry
    table.path.write_bytes(damaged)

    def full(path, data, what="file"):
        if Path(path).name == "scores.json":
            raise DataFileError(f"{path}: cannot write the {what}: No space left on device")
        return atomic_write_bytes(path, data, what)

    monkeypatch.setattr(tablefile_module, "atomic_write_bytes", full)
    with pytest.raises(DataFileError, match="No space"):
        table.add(game("bob", time_limit=1.0))
    assert table.path.read_bytes() == damaged  # everything as it was
    assert not list(tmp_path.glob("scores.json.corrupt-*"))
    assert [e.id for e in table.all_entries()] == [first.id]
    monkeypatch.undo()
    monkeypatch.setenv("ARMGAME_CACHE", str(tmp_path / "cache"))
    table.add(game("cleo", time_limit=1.0))
    assert [p.read_bytes() for p in tmp_path.glob("scores.json.corrupt-*")] == [damaged]
    assert sorted(e.name for e in table.all_entries()) == ["ann", "cleo"]


def test_a_valid_table_padded_past_32_mib_keeps_every_entry(tmp_path):
    table = ScoreTable(tmp_path)
    entries = [table.add(game(f"p{i}", time_limit=0.1, seed=i)) for i in range(3)]
    data = table.path.read_bytes()
    table.path.write_bytes(data[:-3] + b" " * (33 * 1024 * 1024) + data[-3:])
    assert {e.id for e in table.all_entries()} == {e.id for e in entries}
    table.add(game("p3", time_limit=0.1, seed=3))
    assert len(table.all_entries()) == 4 and not list(tmp_path.glob("scores.json.corrupt-*"))


def test_a_table_over_the_limit_is_refused_whole_never_set_aside(tmp_path, monkeypatch, capsys):
    table = ScoreTable(tmp_path)
    table.add(game("p0", time_limit=0.1))
    before = table.path.read_bytes()
    monkeypatch.setattr(tablefile_module, "MAX_TABLE_BYTES", len(before) - 1)
    with pytest.raises(DataFileError, match="nothing was changed"):
        table.add(game("p1", time_limit=0.1))
    assert main(["scores", "--scores", str(tmp_path)]) == 2
    assert table.path.read_bytes() == before and not list(tmp_path.glob("scores.json.corrupt-*"))
    monkeypatch.setattr(tablefile_module, "MAX_TABLE_BYTES", 10**9)
    monkeypatch.setattr(tablefile_module, "MAX_TABLE_ENTRIES", 1)
    with pytest.raises(DataFileError, match="nothing was dropped"):
        table.add(game("p2", time_limit=0.1))
    assert table.path.read_bytes() == before


@pytest.mark.slow  # 2.6 s to read the table the limits allow: CI runs it after the suite (the slow tier)
def test_a_table_of_100000_entries_is_read(tmp_path):
    from armgame.records.scores import ScoreEntry, table_bytes

    one = ScoreEntry.from_dict(dict(id="0" * 32, name="a" * 40, driven="script", driver="d" * 60, score=99,
                                    hits=99, resets=9, seed=2**62, scene="game", duration=60.0,
                                    date="2025-03-01T10:00:00.000000+00:00", version="0.1.0",
                                    replay="r" * 40 + ".json", replay_sha256="0" * 64, ruleset="standard",
                                    config_sha256=RULESETS["standard"].digest))
    import dataclasses

    def table_of(n: int) -> bytes:
        """table_bytes of ``n`` copies of ``one`` under ids 0, 1, ...: its one-entry table with the
        entry's line repeated (the writer's own bytes, checked below, without building 100,000 entries)."""
        text = table_bytes([one]).decode()
        field = f'"id": "{one.id}"'
        line = next(x for x in text.splitlines() if field in x)
        lines = (line.replace(field, f'"id": "{i:032x}"') for i in range(n))
        return text.replace(line, ",\n".join(lines)).encode()

    assert table_of(3) == table_bytes([dataclasses.replace(one, id=f"{i:032x}") for i in range(3)])
    data = table_of(100_000)
    assert len(data) <= tablefile_module.MAX_TABLE_BYTES
    (tmp_path / "scores.json").write_bytes(data)
    read, damage = ScoreTable(tmp_path).read()
    assert damage is None and len(read) == 100_000


@pytest.mark.parametrize("text", [
    '{"a":' * 400_000,
    '{"' + "{" * 2_000_000,
    '{"x": "' * 300_000,
    "{" * 2_000_000,
    '{"id": "' + "a" * 2_000_000,
])
def test_recovery_runs_in_linear_time(text):
    start = time.perf_counter()
    entries, damage = parse_table(text.encode())
    assert entries == [] and damage is not None
    assert time.perf_counter() - start < 10  # quadratic scanning took minutes on inputs like these


# ------------------------------------------------------------------ 6. one line, never a traceback or a hang

def test_script_attacks_give_one_line(tmp_path, capsys):
    script = tmp_path / "s.txt"
    script.write_text("1e308 d down\n")
    assert "time must be" in in_process_error(capsys, "play", "--headless", "--script", script)
    script.write_bytes("\ufeff0.1 d down\n0.2 d up\n".encode())
    assert main(["play", "--headless", "--script", str(script), "--duration", "0.5"]) in (0, None)


@pytest.mark.parametrize("name", ["evil\x1b[2J\nname.txt", "x" * 230 + ".txt"])
def test_a_hostile_script_name_still_saves_the_game_under_a_clean_driver(tmp_path, name, capsys):
    script = tmp_path / name
    script.write_text("0.1 d down\n")
    code = main(["play", "--headless", "--script", str(script), "--duration", "0.5", "--name", "Eve",
                 "--scores", str(tmp_path / "t")])
    out, err = capsys.readouterr()
    assert code in (0, None) and "saved to the high-score table" in out, err
    (entry,) = ScoreTable(tmp_path / "t").all_entries()
    assert entry.driver.isprintable() and len(entry.driver) <= 60
    assert ScoreTable(tmp_path / "t").check(entry).ok


def test_no_such_user_home_gives_one_line(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    with monkeypatch.context() as patch:
        patch.setenv("ARMGAME_SCORES", "~nosuchuser/x")
        assert "home folder" in in_process_error(capsys, "play", "--headless", "--name", "a", "--duration", "0.1")
        assert "home folder" in in_process_error(capsys, "scores")
    for option in ("--scores", "--record"):
        line = in_process_error(capsys, "play", "--headless", "--name", "a", "--duration", "0.1", option,
                                "~nosuchuser/x")
        assert option in line and "home folder" in line
    assert list(tmp_path.iterdir()) == []


def test_an_unwritable_scores_folder_is_found_before_the_game(tmp_path, monkeypatch, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("")
    played = []
    monkeypatch.setattr(GameSession, "play", lambda self, *a, **k: played.append(1))
    assert main(["play", "--headless", "--name", "a", "--scores", str(blocker / "t")]) == 2
    assert "not a folder" in capsys.readouterr().err and not played


def test_simulate_with_an_empty_out_is_one_line(capsys):
    assert "--out is empty" in in_process_error(capsys, "simulate", "--scene", "passive", "--out", "")


def test_slow_lock_holder_does_not_lose_entries(tmp_path):
    """Two writers, one holding the lock a while: the other waits (bounded) and both land."""
    folder = tmp_path / "t"
    ScoreTable(folder).add(game("a", time_limit=0.1, seed=1))
    holder = file_lock(folder / "scores.lock", 1.0)
    holder.__enter__()
    timer = threading.Timer(0.5, holder.__exit__, (None, None, None))
    timer.start()
    ScoreTable(folder).add(game("b", time_limit=0.1, seed=2))
    timer.join()
    assert len(ScoreTable(folder).all_entries()) == 2


def test_read_limited_refuses_special_files_without_blocking(tmp_path, monkeypatch):
    fifo = tmp_path / "f"
    os.mkfifo(fifo)
    reads = []  # counted, not timed: refused before a byte is read (a FIFO's read waits for a writer)
    real_fdopen = os.fdopen
    monkeypatch.setattr(os, "fdopen", lambda *a, **k: reads.append(a) or real_fdopen(*a, **k))
    for path in (fifo, Path("/dev/zero"), tmp_path):
        with pytest.raises(DataFileError):
            read_limited(path, 100, "file")
    assert reads == []


def test_config_to_dict_is_unchanged_for_old_replays():
    # Format 1 replays (every replay so far) still load: the replay format did not change.
    assert set(config_to_dict(GameConfig())) >= {"arm", "muscles", "seed", "view"}


# ------------------------------------------------------------------ 7. anything at all: scores and verify hold

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

HOSTILE_VALUES = st.sampled_from([
    None, True, -1, 0, 1, 2**70, -(2**63), 1e-300, 1e308, -1e308, 0.5, "", "x" * 300, "a\x1b[2J\nb", "../../x",
    "/etc/passwd", [], {}, [1, 2], {"a": 1}, "standard", "custom", "0" * 64, "NaN",
])
_BASE = None


def _base_replay() -> dict:
    global _BASE
    if _BASE is None:
        _BASE = json.loads(game("base", time_limit=0.3).to_bytes())
    return json.loads(json.dumps(_BASE))


def _paths(value, prefix=()):
    yield prefix
    if isinstance(value, dict):
        for k, v in value.items():
            yield from _paths(v, (*prefix, k))
    elif isinstance(value, list) and len(value) <= 8:
        for i, v in enumerate(value):
            yield from _paths(v, (*prefix, i))


def _mutate(data, path, value):
    if not path:
        return value
    where = data
    for key in path[:-1]:
        where = where[key]
    where[path[-1]] = value
    return data


@st.composite
def hostile_replays(draw):
    data = _base_replay()
    paths = list(_paths(data))
    for _ in range(draw(st.integers(0, 3))):
        # A copy: a later mutation inside a drawn {} or [] must not change HOSTILE_VALUES' own, which
        # would make the strategy draw differently the next time (hypothesis: FlakyStrategyDefinition).
        data = _mutate(data, draw(st.sampled_from(paths)), copy.deepcopy(draw(HOSTILE_VALUES)))
        if not isinstance(data, dict):
            break
        paths = list(_paths(data))
    raw = json.dumps(data).encode()
    cut = draw(st.one_of(st.none(), st.integers(0, len(raw))))
    return raw if cut is None else raw[:cut]


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                                  HealthCheck.too_slow])
@given(replay=hostile_replays(), entry_changes=st.dictionaries(
    st.sampled_from(["name", "score", "hits", "seed", "date", "replay", "replay_sha256", "ruleset",
                     "config_sha256", "driver", "id", "extra"]), HOSTILE_VALUES, max_size=2),
    table_cut=st.one_of(st.none(), st.integers(0, 2000)))
def test_scores_and_verify_never_raise_stay_bounded_and_write_only_their_cache(tmp_path_factory, replay,
                                                                                entry_changes, table_cut):
    import hashlib

    root = tmp_path_factory.mktemp("h")
    folder, cache = root / "t", root / "cache"
    (folder / "replays").mkdir(parents=True)
    (folder / "replays" / "r.json").write_bytes(replay)
    entry = dict(id="1" * 32, name="base", driven="script", driver="s.txt", score=0, hits=0, resets=0, seed=10,
                 scene="game", duration=0.3, date=_base_replay()["date"], version="0.1.0", replay="r.json",
                 replay_sha256=hashlib.sha256(replay).hexdigest(), ruleset="custom",
                 config_sha256="0" * 64)
    entry.update(entry_changes)
    text = json.dumps({"format": "armgame-scores", "format_version": 2, "entries": [entry]}).encode()
    (folder / "scores.json").write_bytes(text if table_cut is None else text[:table_cut])
    before = {p: p.read_bytes() for p in root.rglob("*") if p.is_file()}
    os.environ["ARMGAME_CACHE"] = str(cache)
    for argv in (["scores", "--scores", str(folder), "--all"], ["verify", str(folder)],
                 ["verify", str(folder / "replays" / "r.json")], ["replay", "--headless", str(folder / "replays" /
                                                                                          "r.json")]):
        start = time.perf_counter()
        assert main(argv) in (0, 1, 2)
        assert time.perf_counter() - start < 20
    after = {p: p.read_bytes() for p in root.rglob("*") if p.is_file()}
    assert {p: b for p, b in after.items() if cache not in p.parents} == before
