"""Inputs that gave a traceback or ran on (issue 26, item 6): each is now one line naming what is wrong
and a non-zero exit, or ends quietly, within bounded work."""

import math
import os
import subprocess
import sys

import pytest

from armgame.cli import main


def error_lines(capsys, argv, code=2) -> list[str]:
    """stderr's lines of ``armgame argv`` run in this process, which must exit with ``code``."""
    assert main([str(a) for a in argv]) == code
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.strip(), err
    return err.strip().splitlines()


# ------------------------------------------------------------------ analyze --fit on nothing to fit

TINY = """name = "tiny"
timeout = 0.5
delay_min = 0.1
delay_max = 0.1
[[blocks]]
name = "exposure"
trials = {trials}
{perturbation}
"""


@pytest.mark.parametrize(("perturbation", "trials", "said"), [
    ('perturbation = "curl"\nb = 0.0', 2, "its perturbation is zero (curl b=0 N s/m)"),
    ('perturbation = "curl"', 2, "its perturbation is zero (curl b=0 N s/m)"),  # b left at its default, 0
    ('perturbation = "rotation"\nangle = 0', 2, "its perturbation is zero (rotation angle=0 deg)"),
    ('perturbation = "viscous"\nmatrix = [[0, 0], [0.0, 0]]', 2, "its perturbation is zero (viscous B=[[0, 0]"),
    ('perturbation = "curl"\nb = 2.0', 1, "1 trial with a value: a two-rate fit needs at least 8"),
])
def test_a_fit_to_nothing_to_fit_is_one_line(tmp_path, capsys, perturbation, trials, said):
    protocol = tmp_path / "p.toml"
    protocol.write_text(TINY.format(trials=trials, perturbation=perturbation))
    run = tmp_path / "run.json"
    assert main(["lab", str(protocol), "--bot", "model", "--headless", "--record", str(run)]) == 0
    capsys.readouterr()
    lines = error_lines(capsys, ["analyze", run, "--fit", "two-rate", "--no-figures"])
    assert len(lines) == 2 and lines[1] == "armgame analyze: error: no replay could be analysed"
    assert lines[0].startswith(f"armgame analyze: {run}: cannot fit the two-rate model to its ") and said in lines[0]


def test_the_zero_field_is_no_reference_for_a_later_one():
    """A zero field before a real one counts as no disturbance; the real one is the unit."""
    from armgame.lab.analysis import disturbance_schedule
    from armgame.lab.perturbations import Perturbation
    from armgame.lab.protocol import Block, Protocol

    zero, field = Perturbation.make("curl", b=0.0), Perturbation.make("curl", b=2.0)
    protocol = Protocol("p", (Block("a", 1, zero), Block("b", 1, field),
                              Block("c", 1, Perturbation.make("curl", b=-1.0))))
    plans = [type("Plan", (), {"channel": False, "active": b.perturbation})() for b in protocol.blocks]
    disturbance, clamped = disturbance_schedule(protocol, plans)
    assert disturbance.tolist() == [0.0, 1.0, -0.5] and not clamped.any()
    assert Perturbation().is_null and zero.is_null and not field.is_null
    assert not Perturbation.make("mirror", axis=0.0).is_null and Perturbation.make("rotation", angle=0).is_null
    assert math.isfinite(disturbance.sum())


def test_analyze_fit_prints_without_out(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    protocol = tmp_path / "p.toml"
    protocol.write_text(TINY.format(trials=10, perturbation='perturbation = "curl"\nb = 2.0'))
    assert main(["lab", str(protocol), "--bot", "adaptive", "--headless", "--record", "run.json"]) == 0
    capsys.readouterr()
    assert main(["analyze", "run.json", "--fit", "two-rate"]) == 0  # no --out: no figure, nothing written
    out = capsys.readouterr().out
    assert "two-rate fit to max_perpendicular_error_m (10 trials)" in out and "wrote" not in out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.toml", "run.json"]
    assert error_lines(capsys, ["analyze", "run.json"]) == [
        "armgame analyze: error: --out is needed: a .csv file or a folder for the reaches' table (only --fit "
        "prints without it)"]
    assert error_lines(capsys, ["analyze", "--class", tmp_path]) == [
        "armgame analyze: error: --class needs --out DIR: the folder for class_curve.csv and class_curve.png"]


# ------------------------------------------------------------------ env arguments

@pytest.mark.parametrize("env_id", ["armgame/Reach-v1", "armgame/ReachContinuous-v0"])
@pytest.mark.parametrize("time_limit", [1e-9, 0.0, -1.0, math.nan, math.inf, 1e300])
def test_an_env_with_no_game_to_play_is_refused_naming_the_argument(env_id, time_limit):
    gym = pytest.importorskip("gymnasium")
    import armgame.env  # noqa: F401  (registers the ids)

    with pytest.raises(ValueError, match=r"^time_limit must be a number of seconds from 0\.004 \(one physics step\) "
                                         r"to 86400, got "):
        gym.make(env_id, time_limit=time_limit)


def test_a_vector_env_or_a_config_with_no_game_to_play_is_refused():
    pytest.importorskip("gymnasium")
    from armgame.env.reach_v1 import ReachV1Env
    from armgame.env.vector import ReachV1VectorEnv
    from armgame.game.rules import GameConfig

    with pytest.raises(ValueError, match="time_limit must be a number of seconds from"):
        ReachV1VectorEnv(2, time_limit=1e-9)
    with pytest.raises(ValueError, match=r"config\.time_limit must be at least one physics step \(0\.004 s\)"):
        ReachV1Env(config=GameConfig(time_limit=1e-9))
    env = ReachV1Env(time_limit=0.004)  # the shortest game: one physics step, one env step
    env.reset(seed=1)
    assert env.step(env.action_space.sample())[3] is True


# ------------------------------------------------------------------ output into a closed pipe

@pytest.mark.skipif(sys.platform == "win32", reason="a closed pipe is EINVAL there, and no SIGPIPE")
def test_output_into_a_pipe_closed_early_ends_quietly(tmp_path):
    """``armgame scores --all | head -1``: the listing stops when its reader has gone, with no traceback."""
    import dataclasses

    from armgame.cli import EXIT_BROKEN_PIPE
    from armgame.records.rulesets import RULESETS
    from armgame.records.scores import ScoreEntry, table_bytes

    one = ScoreEntry.from_dict(dict(id="0" * 32, name="a", driven="keyboard", driver=None, score=9, hits=9, resets=0,
                                    seed=10, scene="game", duration=60.0, date="2025-03-01T10:00:00+00:00",
                                    version="0.1.0", replay="r.json", replay_sha256="0" * 64, ruleset="standard",
                                    config_sha256=RULESETS["standard"].digest))
    entries = [dataclasses.replace(one, id=f"{i:032x}", name=f"p{i}") for i in range(3000)]  # ~200 KB listed
    (tmp_path / "scores.json").write_bytes(table_bytes(entries))
    env = {**os.environ, "ARMGAME_CACHE": str(tmp_path / "cache")}
    argv = [sys.executable, "-m", "armgame", "scores", "--all", "--no-check", "--scores", str(tmp_path)]
    child = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
    assert child.stdout.readline().startswith(b"High scores in ")
    child.stdout.close()  # the reader leaves, as head does
    with child.stderr:
        err = child.stderr.read()
    assert child.wait(timeout=60) == EXIT_BROKEN_PIPE == 141 and err == b""


def test_a_broken_pipe_inside_any_command_is_its_exit_status(monkeypatch, capsys):
    from armgame import cli

    def gone(_args):
        raise BrokenPipeError(32, "Broken pipe")

    monkeypatch.setattr("armgame.commands.settings.run", gone)  # register() reads it on every main()
    assert cli.main(["settings"]) == cli.EXIT_BROKEN_PIPE
    assert capsys.readouterr().err == ""


# ------------------------------------------------------------------ paths too long for the file system

def _too_long(tmp_path, kind: str) -> str:
    """A path the file system cannot name: one name past its longest name, or a whole past its longest path."""
    from armgame.files import path_limits

    name_max, path_max = path_limits(tmp_path)
    if kind == "name":
        return str(tmp_path / ("x" * (name_max + 45)))
    return str(tmp_path.joinpath(*["y" * 200] * (path_max // 201 + 2)))


@pytest.mark.parametrize("kind", ["name", "path"])
@pytest.mark.parametrize("argv", [
    ["scores", "--scores", "{p}"], ["scores", "--scores", "{p}", "--all"], ["scores", "--new", "--scores", "{p}"],
    ["scores", "--add", "{p}"], ["scores", "--cache", "{p}"],
    ["play", "--headless", "--duration", "0.1", "--name", "Ann", "--scores", "{p}"],
    ["play", "--headless", "--duration", "0.1", "--record", "{p}"], ["play", "--headless", "--script", "{p}"],
    ["verify", "{p}"], ["replay", "{p}", "--headless"], ["settings", "--settings", "{p}"],
    ["lab", "{p}", "--headless", "--bot", "model"], ["lab", "null", "--headless", "--bot", "model", "--record", "{p}"],
    ["lab", "null", "--headless", "--bot", "model", "--out", "{p}"],
    ["analyze", "--class", "{p}", "--out", "{tmp}"], ["analyze", "{tmp}/r.json", "--out", "{p}"],
    ["simulate", "--scene", "pendulum", "--out", "{p}"], ["demo", "chaos", "--headless", "--out", "{p}"],
])
def test_a_path_too_long_for_the_file_system_is_one_line(tmp_path, capsys, monkeypatch, argv, kind):
    monkeypatch.setenv("ARMGAME_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("ARMGAME_SCORES", str(tmp_path / "scores"))
    p = _too_long(tmp_path, kind)
    (line,) = error_lines(capsys, [a.format(p=p, tmp=tmp_path) for a in argv])
    assert line.startswith(f"armgame {argv[0]}: error: ") and "more than the file system allows" in line
    assert len(line) < 400 and not any(tmp_path.iterdir())  # refused before anything was made


@pytest.mark.parametrize("argv", [["scores"], ["play", "--headless", "--duration", "0.1", "--name", "Ann"]])
def test_an_armgame_scores_too_long_is_one_line(tmp_path, capsys, monkeypatch, argv):
    monkeypatch.setenv("ARMGAME_SCORES", _too_long(tmp_path, "name"))
    (line,) = error_lines(capsys, argv)
    assert f"error: $ARMGAME_SCORES {tmp_path}" in line and "more than the file system allows" in line


def test_analyze_names_a_replay_too_long_and_goes_on(tmp_path, capsys):
    lines = error_lines(capsys, ["analyze", _too_long(tmp_path, "name"), "--out", tmp_path / "t.csv"])
    assert lines[0].startswith(f"armgame analyze: REPLAY {tmp_path}") and "more than the file system" in lines[0]
    assert lines[1:] == ["armgame analyze: error: no replay could be analysed"]


def test_a_table_too_deep_for_its_own_files_is_refused_before_writing(tmp_path):
    from armgame.files import path_limits
    from armgame.game.rules import GameConfig
    from armgame.game.session import GameSession
    from armgame.records.replay import Replay
    from armgame.records.scores import ScoreTable, TableError
    from armgame.records.storage import DataFileError, check_output_path, check_writable_folder

    _, path_max = path_limits(tmp_path)
    left = path_max - 1 - 60 - len(str(tmp_path))  # a folder 60 bytes short of the longest path
    full, rest = divmod(left, 201)  # names of 200 bytes and their separators, and one name of what is left
    if rest < 2:
        full, rest = full - 1, rest + 201
    folder = tmp_path.joinpath(*["z" * 200] * full, "w" * (rest - 1))
    assert len(str(folder)) == path_max - 61
    session = GameSession(GameConfig(time_limit=0.1))
    session.advance(session.total_steps)
    with pytest.raises(TableError, match=r"^the table's folder .*more than the file system allows \(with room"):
        ScoreTable(folder).add(Replay.from_session(session, "keyboard", None, "Ann"))
    assert not any(tmp_path.iterdir())
    deep = _too_long(tmp_path, "path")
    with pytest.raises(DataFileError, match="cannot write the replay: File name too long"):
        check_output_path(tmp_path / deep / "r.json", "replay")  # pathlib's is_dir() raised here
    with pytest.raises(Exception, match="more than the file system allows") as caught:
        check_writable_folder(tmp_path / deep, "--scores")
    assert "Traceback" not in str(caught.value)


# ------------------------------------------------------------------ a hit storm's verification

def _storm(hits: int, steps: int | None = None):
    """A custom game whose targets are all drawn on the hand's start (both ranges one angle): every step hits,
    and every hit tries 1,000 postures for its next target. Its replay claims ``hits`` in ``steps``."""
    import json

    from armgame.game.rules import GameConfig
    from armgame.game.session import GameSession
    from armgame.records.replay import Replay

    steps = hits if steps is None else steps
    config = GameConfig(seed=10, time_limit=steps * 0.004, target_shoulder_range=(45.0, 45.0),
                        target_elbow_range=(90.0, 90.0))
    data = Replay.from_session(GameSession(config), "keyboard", None, "storm").as_dict()
    data["result"].update(score=hits, hits=hits, steps=steps)
    return Replay.from_dict(json.loads(json.dumps(data)))


#: A verification's budget in these tests: the default's 60,000,000 is about 7 s of a hit storm, this 0.07 s.
BUDGET = 600_000


@pytest.fixture
def small_budget(monkeypatch):
    """Every verification's budget ``BUDGET``: the commands' (``limits.MAX_VERIFY_WORK``, read when they run)
    and ``Replay.verify``'s default."""
    from armgame.records.replay import Replay

    monkeypatch.setattr("armgame.limits.MAX_VERIFY_WORK", BUDGET)
    real = Replay.verify
    monkeypatch.setattr(Replay, "verify", lambda self, max_work=BUDGET: real(self, max_work))


def test_a_hit_storm_is_stopped_at_its_budget_and_an_honest_game_never_is():
    import time

    from armgame.game.rules import MAX_TRIES
    from armgame.limits import MAX_EVENTS, MAX_GAME_SECONDS, MAX_GAME_STEPS, MAX_VERIFY_WORK
    from armgame.records import checking
    from armgame.records.replay import EVENT_WORK, TRY_WORK, VerifyCostError

    storm = _storm(5000)
    start = time.perf_counter()
    with pytest.raises(VerifyCostError, match=r"^by step ([\d,]+) of 5,000 its game had tried ([\d,]+) target "
                                              r"postures for [\d,]+ hits \(5,000 claimed\): more work than one "
                                              r"verification spends \(600,000 steps\), its targets keep landing "
                                              r"on the hand$") as caught:
        storm.verify(max_work=BUDGET)
    assert time.perf_counter() - start < 2.0
    words = caught.value.args[0].split(" ")
    step, tries = int(words[2].replace(",", "")), int(words[9].replace(",", ""))
    one_hit = TRY_WORK * MAX_TRIES  # the budget is passed by one hit's drawing at most
    assert BUDGET - one_hit <= step + TRY_WORK * tries <= BUDGET + one_hit
    small = _storm(90)  # the same storm claiming what the budget covers is checked, and matches
    assert checking.replay_work(small) <= BUDGET and small.verify(max_work=BUDGET)[0]
    assert small.verify(max_work=None)[0]  # None: whatever it costs
    # No game whose targets land clear of the hand comes near the default: the longest, with the most events,
    # hitting 5 targets a second, each drawn in 10 tries (the standard game's draws take 1.35 on average, 9 at most).
    assert MAX_GAME_STEPS + EVENT_WORK * MAX_EVENTS + TRY_WORK * 10 * 5 * MAX_GAME_SECONDS < MAX_VERIFY_WORK / 5
    with pytest.raises(VerifyCostError, match=r"^its 5,000 steps and 0 input events are more work \(5,000 steps\)"):
        storm.verify(max_work=4_999)  # refused before anything runs


def test_verify_of_a_hit_storm_is_one_line_in_bounded_time(tmp_path, capsys, small_budget):
    path = tmp_path / "storm.json"
    _storm(5000).save(path)
    assert main(["verify", str(path)]) == 3  # verify's "some games were left unchecked"
    said = capsys.readouterr()
    assert said.err == "" and said.out.startswith(f"{path}: NOT CHECKED: by step ") and said.out.count("\n") == 1
    assert said.out.rstrip().endswith("its targets keep landing on the hand (--max-work N spends up to N)")
    (line,) = error_lines(capsys, ["scores", "--scores", tmp_path / "t", "--add", path])
    assert line.startswith(f"armgame scores: error: {path}: by step ") and line.endswith(": not entered")
    _storm(150).save(path)  # 900,150 steps of work: past the budget, within a --max-work that asks for more
    assert main(["verify", str(path)]) == 3
    assert main(["verify", str(path), "--max-work", "1000000"]) == 0
    assert "matches" in capsys.readouterr().out.splitlines()[-1]


def test_a_headless_replay_of_a_hit_storm_is_one_line_in_bounded_time(tmp_path, capsys, small_budget):
    import time

    path = tmp_path / "storm.json"
    _storm(5000).save(path)
    start = time.perf_counter()
    (line,) = error_lines(capsys, ["replay", "--headless", path])
    assert time.perf_counter() - start < 2.0
    assert line.startswith(f"armgame replay: error: {path}: not replayed: by step ")
    assert line.endswith("its targets keep landing on the hand (--max-work N spends up to N)")
    _storm(150).save(path)  # past the default budget, within a --max-work that asks for more
    assert main(["replay", "--headless", str(path), "--max-work", "1000000"]) == 0
    assert "score 150 (150 hits, 0 resets), as recorded" in capsys.readouterr().out


def test_verify_of_a_folder_or_a_table_goes_on_past_a_hit_storm(tmp_path, capsys, small_budget):
    from armgame.records.scores import ScoreTable

    folder = tmp_path / "runs"
    folder.mkdir()
    _storm(5000).save(folder / "a-storm.json")
    _storm(50).save(folder / "b-small.json")
    assert main(["verify", str(folder)]) == 3
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith(f"{folder / 'a-storm.json'}: NOT CHECKED: by step ")
    assert out[1].startswith(f"{folder / 'b-small.json'}: matches: ")
    assert out[2] == f"{folder}: 2 replays, 0 differ, 0 unreadable, 1 not checked (over their work budget)"
    table = ScoreTable(tmp_path / "t")
    table.add(_storm(5000))
    assert main(["verify", str(tmp_path / "t")]) == 3
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("storm: score 5000 (keyboard, custom rules, ") and ": NOT CHECKED: by step " in out[0]


def test_an_armgame_cache_too_long_is_a_note_and_the_game_still_enters(tmp_path, capsys, monkeypatch):
    """The cache and the teacher's record only save work and add trust: a $ARMGAME_CACHE the file system
    cannot name is ignored, said once for each."""
    monkeypatch.setenv("ARMGAME_CACHE", _too_long(tmp_path, "name"))
    table = tmp_path / "t"
    assert main(["play", "--headless", "--duration", "0.1", "--name", "Ann", "--scores", str(table)]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert [line.split(" $ARMGAME_CACHE ")[0] for line in err] == ["armgame play: note: the verification cache",
                                                                   "armgame play: note: the teacher's record"]
    assert all("more than the file system allows (" in line and line.endswith("): ignored") for line in err)
    assert (table / "scores.json").is_file()
