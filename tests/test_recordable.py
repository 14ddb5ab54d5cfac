"""No replay is written that cannot be read back (issue 16, class 6): what ``verify`` and ``analyze``
would refuse is refused before the game or the lab run, in one line, and nothing is written."""

import os

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

import pytest

from armgame.cli import main


@pytest.mark.parametrize(("keys", "message"), [
    ("a\tb,c,d,e", "control characters"),
    ("x" * 52 + ",c,d,e", "at most 20 characters"),
])
def test_keys_a_replay_cannot_hold_are_refused_before_the_game(tmp_path, capsys, keys, message):
    record = tmp_path / "r.json"
    assert main(["play", "--headless", "--duration", "0.1", "--keys", keys, "--record", str(record)]) == 2
    err = capsys.readouterr().err
    assert message in err and "--keys" in err and len(err.strip().splitlines()) == 1
    assert not record.exists()


def test_a_protocol_whose_clock_passes_the_longest_game_is_refused_before_the_run(tmp_path, capsys):
    protocol = tmp_path / "long.toml"
    protocol.write_text("timeout = 3.0\n[[blocks]]\ntrials = 2000\n")  # about 12,000 s of clock
    assert main(["lab", str(protocol), "--headless", "--bot", "adaptive", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "time_limit" in err and "could not be read back" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()


def test_keys_a_replay_can_hold_still_play_and_verify(tmp_path, capsys):
    record = tmp_path / "r.json"
    assert main(["play", "--headless", "--duration", "0.1", "--keys", "a,s,d,f", "--record", str(record)]) == 0
    assert main(["verify", str(record)]) == 0
