"""Replays: exact round trips, the CLI (play --record, replay, verify), tampering, hostile files."""

import json
import math
import os
import re

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

import pytest

from armgame.cli import main
from armgame.errors import UserError
from armgame.game.muscles import DEFAULT_MUSCLES, remap_keys
from armgame.game.rules import GAME_RANGES, GameConfig
from armgame.game.session import GameSession, InputEvent
from armgame.game.timeline import TimelineDriver
from armgame.physics.params import GAME_ARM
from armgame.records.replay import CONFIG_FIELDS, Replay, config_from_dict, config_to_dict
from armgame.records.storage import DataFileError

SCRIPT = """\
0.00 k down
0.30 k up
0.40 d down
0.70 d up
0.80 k down
0.90 k up
1.20 d down
1.50 d up
1.60 f down
1.90 f up
2.40 space down
2.50 space up
"""


@pytest.fixture(autouse=True)
def _scores_in_tmp(tmp_path, monkeypatch):
    monkeypatch.setenv("ARMGAME_SCORES", str(tmp_path / "scores"))  # never the repository's scores/
    monkeypatch.setenv("ARMGAME_CACHE", str(tmp_path / "cache"))  # nor the user's verification cache


def played(time_limit=3.0, seed=4, stop=None, **config) -> GameSession:
    session = GameSession(GameConfig(time_limit=time_limit, seed=seed, **config))
    events = [InputEvent(round(float(t) / session.config.dt), k, a)
              for t, k, a in (line.split() for line in SCRIPT.splitlines())]
    session.play(events, stop)
    return session


@pytest.fixture(scope="module")
def seeds() -> tuple[int, int]:
    """A seed whose targets the script hits and one whose it misses: found, not assumed, so that
    the tests outlive a retuning of the arm."""
    hit = miss = None
    for seed in range(200):
        if played(seed=seed).rules.board.hits:
            hit = seed if hit is None else hit
        else:
            miss = seed if miss is None else miss
        if hit is not None and miss is not None:
            return hit, miss
    pytest.skip("the script hits no target with any seed tried")


def test_game_config_round_trips_exactly_through_json():
    config = GameConfig(
        arm=GAME_ARM.replace(damping1=0.1 + 0.2, m2=1.0 / 3.0), start_posture=(0.1, math.pi / 3), time_limit=7.7,
        target_radius=0.031, target_shoulder_range=(20.0, 70.0), target_elbow_range=(50.5, 80.0), seed=2**62 + 1,
        muscles=remap_keys(DEFAULT_MUSCLES, "asdf"), integrator="gauss4", dt=1.0 / 300.0, reset_cost=2,
        view=(-1.0, 1.0, -0.5, 1.5), scene="game",
    )
    data = config_to_dict(config)
    assert set(data) == CONFIG_FIELDS  # a new GameConfig field must be added to the replay format
    assert config_from_dict(json.loads(json.dumps(data))) == config


@pytest.mark.parametrize("kind, field, refusal", [
    ("dt", "dt", "the physics step must be between 0 and 0.05 s"),
    ("time_limit", "time_limit", "the game's duration must be between 0 and 86400 s"),
])
def test_a_game_config_takes_more_than_a_replay_holds_as_the_one_table_says(kind, field, refusal):
    """``GAME_RANGES`` is both readers' table: a ``GameConfig`` takes up to its ``config`` high, which a replay's
    reader refuses past its own high, and refuses what is past it, each in its own words."""
    setting = GAME_RANGES[kind]
    low, high = setting.config
    assert setting.high < high  # a replay is the stricter
    built = GameConfig(**{field: high})
    with pytest.raises(ValueError, match=rf"^config\.{field} must be a finite number (from|above) {setting.low:g} "
                                         rf"(to|and at most) {setting.high:g}, got {high!r}$"):
        config_from_dict(config_to_dict(built))
    past = math.nextafter(high, math.inf)
    with pytest.raises(UserError, match=f"^{re.escape(refusal)}, got {past!r}$"):
        GameConfig(**{field: past})
    with pytest.raises(UserError, match=f"^{re.escape(refusal)}, got {low!r}$"):
        GameConfig(**{field: low})


def test_replay_file_round_trip_and_verify(tmp_path):
    session = played()
    replay = Replay.from_session(session, "script", "reach.txt", "Ann")
    path = tmp_path / "r.json"
    replay.save(path)
    loaded = Replay.load(path)
    assert loaded == replay
    ok, recomputed = loaded.verify()
    assert ok and recomputed == session.result()


def test_a_game_stopped_early_replays_to_where_it_stopped():
    session = played(time_limit=3.0, stop=600)
    session.key_event("space", "down")  # at the very step the player quit on: it still counts
    replay = Replay.from_session(session, "keyboard")
    assert not replay.complete and replay.steps == 600
    assert replay.replay() == session.result()


def run_cli(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_play_record_verify_replay_give_the_same_json(tmp_path, capsys):
    script = tmp_path / "reach.txt"
    script.write_text(SCRIPT)
    record = tmp_path / "game.json"
    code, played_json, err = run_cli(capsys, "play", "--headless", "--script", script, "--duration", 3, "--seed", 4,
                                     "--json", "--record", record)
    assert code == 0 and "replay saved" in err
    assert json.loads(played_json)["resets"] == 1
    code, out, _ = run_cli(capsys, "verify", record)
    assert code == 0 and "matches" in out
    code, replayed_json, _ = run_cli(capsys, "replay", record, "--headless", "--json")
    assert code == 0 and replayed_json == played_json
    code, out, _ = run_cli(capsys, "replay", record, "--headless")
    assert code == 0 and "as recorded" in out


def tamper(path, change):
    data = json.loads(path.read_text())
    change(data)
    path.write_text(json.dumps(data))


@pytest.mark.parametrize("change", [
    lambda d: d["result"].update(score=d["result"]["score"] + 5, hits=d["result"]["hits"] + 5),
    lambda d: d["timeline"].insert(0, [0, "space", "down"]),
    lambda d: d["timeline"].clear(),
    "other-seed",
], ids=["typed-score", "added-event", "no-events", "other-seed"])
def test_a_tampered_replay_is_detected(tmp_path, capsys, change, seeds):
    hit, miss = seeds
    path = tmp_path / "r.json"
    Replay.from_session(played(seed=hit), "script").save(path)
    if change == "other-seed":  # the same inputs on other targets: the recorded hit does not follow
        def change(d):
            d["config"]["seed"] = d["result"]["seed"] = miss
    tamper(path, change)
    code, out, _ = run_cli(capsys, "verify", path)
    assert code == 1 and "DIFFERS" in out


def _nest(depth):
    return "[" * depth + "]" * depth


HOSTILE = {
    "not-json": lambda d: b"\x00\x01 this is not json",
    "truncated": lambda d: json.dumps(d).encode()[:300],
    "nan": lambda d: json.dumps(d).replace('"dt": 0.', '"dt": NaN, "x": 0.', 1).encode(),
    "overflow": lambda d: json.dumps(d).replace('"time_limit": 3.0', '"time_limit": 1e999').encode(),
    "deep": lambda d: _nest(100_000).encode(),
    "pickle": lambda d: b"\x80\x04\x95\x10\x00\x00\x00\x00\x00\x00\x00\x8c\x05posix\x94.",
}
EDITS = {
    "duration-1e308": lambda d: d["config"].update(time_limit=1e308),
    "long-name": lambda d: d.update(player="x" * 10_000),
    "control-chars": lambda d: d.update(player="a\x1b[2Jb"),
    "negative-score": lambda d: d["result"].update(score=-1),
    "wrong-type": lambda d: d["config"].update(dt="0.004"),
    "bool-for-int": lambda d: d["result"].update(hits=True),
    "unknown-field": lambda d: d.update(run="os.system('rm -rf /')"),
    "future-format": lambda d: d.update(format_version=99),
    "not-a-replay": lambda d: d.update(format="something-else"),
    "unsorted-timeline": lambda d: d["timeline"].append([0, "d", "down"]),
    "unknown-key": lambda d: d["timeline"].append([700, "q", "down"]),
    "event-after-end": lambda d: d["timeline"].append([10**7, "d", "down"]),
    "huge-game": lambda d: d["config"].update(dt=1e-9) or d["result"].update(dt=1e-9),
    "bad-integrator": lambda d: d["config"].update(integrator="__import__('os')"),
    "three-muscles": lambda d: d["config"]["muscles"].pop(),
    "impossible-arm": lambda d: d["config"]["arm"].update(r1=5.0),
    "score-above-hits": lambda d: d["result"].update(score=d["result"]["hits"] + 1),
}


@pytest.mark.parametrize("name", [*HOSTILE, *EDITS])
def test_hostile_replay_files_are_refused_in_one_line(tmp_path, capsys, name):
    path = tmp_path / "r.json"
    Replay.from_session(played(), "script").save(path)
    data = json.loads(path.read_text())
    if name in HOSTILE:
        path.write_bytes(HOSTILE[name](data))
    else:
        EDITS[name](data)
        path.write_text(json.dumps(data))
    if name == "score-above-hits":  # a consistent-looking lie: not a bad file, a wrong score
        code, out, _ = run_cli(capsys, "verify", path)
        assert code == 1 and "DIFFERS" in out
        return
    with pytest.raises(DataFileError):
        Replay.load(path)
    code, out, err = run_cli(capsys, "verify", path)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and str(path) in err and len(err) < 300


def test_missing_replay_file(tmp_path, capsys):
    code, _, err = run_cli(capsys, "replay", tmp_path / "nope.json", "--headless")
    assert code == 2 and "no such replay file" in err


def test_the_window_plays_a_replay_from_its_timeline_only(tmp_path):
    import pygame

    from armgame.ui.frontend import GameWindow, open_window

    recorded = played(time_limit=2.0)
    replay = Replay.from_session(recorded, "script")
    session = GameSession(replay.config)
    screen = open_window((400, 400))
    try:
        window = GameWindow(session, screen, fps=0, driver=TimelineDriver(session, replay.timeline, replay.steps))
        frame = 0
        while not session.over:
            # The keyboard drives nothing in a replay, and frames of any length give the same game.
            pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_j, mod=0, unicode="j", scancode=0))
            window.frame((1 / 61, 1 / 23, 0.0, 0.3)[frame % 4])
            frame += 1
    finally:
        pygame.display.quit()
    assert session.timeline == recorded.timeline
    assert session.state == recorded.state and session.result() == recorded.result()


def _long_game(events: int = 1_500, seed: int = 3) -> Replay:
    """A game with a bot's many events (enough that a read keeps its timeline's text)."""
    config = GameConfig(seed=seed)
    keys = [m.key for m in config.muscles]
    timeline = []
    for i in range(events):
        step = i * (config.total_steps - 1) // events
        timeline.append(InputEvent(step, keys[i % 4], "down" if (i // 4) % 2 == 0 else "up"))
    timeline.append(InputEvent(config.total_steps - 1, "space", "down"))
    session = GameSession(config)
    session.play(timeline)
    return Replay.from_session(session, "bot", "model")


def test_a_long_replay_read_keeps_its_timeline_text_and_writes_the_same_bytes():
    """``Replay.timeline_text``: a file read whose timeline is written as ``to_bytes`` writes it is written again
    from its own text, byte for byte what encoding the events gives (as read, under another player's name, with
    another date); a replay rebuilt with another timeline writes its own."""
    import dataclasses

    original = _long_game()
    data = original.to_bytes()
    read = Replay.from_bytes(data)
    assert read.timeline_text is not None and read.timeline_text[0] is read.timeline
    assert read == original and read.timeline == original.timeline
    assert all(type(e) is InputEvent and e == f for e, f in zip(read.timeline, original.timeline, strict=True))
    bare = dataclasses.replace(read, timeline_text=None)
    assert read.to_bytes() == data == bare.to_bytes()
    assert read.with_player("Ann").to_bytes() == bare.with_player("Ann").to_bytes()
    assert dataclasses.replace(read, date="2020-01-01T00:00:00+00:00").to_bytes() == \
        dataclasses.replace(bare, date="2020-01-01T00:00:00+00:00").to_bytes()
    as_text = Replay.from_bytes(data.decode())  # type: ignore[arg-type]  # text is read as well; nothing kept
    assert as_text == original and as_text.timeline_text is None and as_text.to_bytes() == data
    shorter = dataclasses.replace(read, timeline=read.timeline[:-1])
    assert shorter.to_bytes() == dataclasses.replace(bare, timeline=bare.timeline[:-1]).to_bytes() != data


def test_a_timeline_written_otherwise_is_not_kept():
    """A file whose timeline is written another way (compact JSON, a step with a space, a key escaped) keeps no
    text: it is written again as ``to_bytes`` writes it."""
    original = _long_game()
    canonical = original.to_bytes()
    spaced = canonical.replace(b'[\n   0,\n', b'[\n   0 ,\n', 1)
    escaped = canonical.replace(b'"down"\n  ]', b'"\\u0064own"\n  ]', 1)
    for data in (json.dumps(json.loads(canonical), separators=(",", ":")).encode(), spaced, escaped):
        assert data != canonical
        read = Replay.from_bytes(data)
        assert read.timeline_text is None
        assert read == original and read.to_bytes() == canonical
