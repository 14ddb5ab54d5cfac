"""What `armgame play --join` says of each game handed in, and how it exits: a game the class refuses exits 1
with its reason in one line on stderr; a game kept for the next join exits 0; a game handed in from the
window prints its line in the terminal too."""

from __future__ import annotations

import argparse

import pytest
from class_server import final_answer, running_class

from armgame.classroom import client
from armgame.cli import main
from armgame.commands.play import _class_standing
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession


@pytest.fixture
def machine(tmp_path, monkeypatch):
    """``machine(name)``: that student's machine (its own client folder) is the current one."""
    return lambda name: monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "machines" / name))


def test_a_bot_game_the_class_refuses_exits_1_with_its_reason_on_stderr_and_one_kept_exits_0(tmp_path, machine,
                                                                                              capsys):
    folder = tmp_path / "class"
    with running_class(folder) as opened:
        join = ["--join", f"127.0.0.1:{opened.port}", "--code", opened.clerk.roster.code]
        machine("ann")
        assert main(["play", "--headless", "--bot", "model", *join, "--name", "Ann's robot"]) == 0
        assert "handed in: 1st of 1 among the programs" in capsys.readouterr().out
        machine("bo")  # the same bot on the same seed: the same game, which counts once, whoever hands it in
        assert main(["play", "--headless", "--bot", "model", *join, "--name", "Bo's robot"]) == 1
        captured = capsys.readouterr()
        assert captured.err.splitlines()[-1] == ("armgame play: not handed in: this game was already handed in by "
                                                 "Ann's robot: a game counts once, whoever hands it in")
        assert "your score is: " in captured.out and "handed in" not in captured.out
        machine("ann")  # the same game again from the machine that handed it in: not a refusal
        assert main(["play", "--headless", "--bot", "model", *join, "--name", "Ann's robot"]) == 0
        assert "already handed in: 1st of 1 among the programs" in capsys.readouterr().out
    # The class gone: the game is kept and goes in at the next join. Not a refusal: nothing is lost (exit 0).
    assert main(["play", "--headless", "--bot", "naive", *join]) == 0
    assert "your game is kept and will be handed in the next time you join" in capsys.readouterr().out


def test_each_game_handed_in_from_the_window_prints_its_line_in_the_terminal(tmp_path, machine, capsys):
    with running_class(tmp_path / "class") as opened:
        address, code = client.ClassAddress.parse(f"127.0.0.1:{opened.port}"), opened.clerk.roster.code
        machine("ann")
        ann = client.join(address, code, "Ann")
        machine("bo")
        bo = client.join(address, code, "Bo")
        session = GameSession(GameConfig(seed=ann.seed))
        session.play([])
        args = argparse.Namespace(bot=None)
        final = final_answer(_class_standing(session, args, ann)(None))
        assert final.note.startswith("Handed in:")
        assert capsys.readouterr().out == "handed in: 1st of 1 in the class (your best so far)\n"
        assert not getattr(args, "refused", False)
        final = final_answer(_class_standing(session, args, bo)(None))  # Ann's game, from Bo's machine: refused
        captured = capsys.readouterr()
        assert captured.out == "" and captured.err == ("armgame play: not handed in: this game was already handed in "
                                                       "by Ann: a game counts once, whoever hands it in\n")
        assert args.refused and final.note.startswith("Not handed in:")


def test_a_window_closed_while_its_game_is_on_the_way_waits_for_the_class(tmp_path, machine, capsys):
    """Esc on the end screen as it says "Handing your game in...": the command waits for the answer (the hand-in
    runs on a thread the process would otherwise cut off) and prints its line."""
    from armgame.commands.play import _wait_for_hand_ins

    machine("ann")
    with running_class(tmp_path / "class") as opened:
        ann = client.join(client.ClassAddress.parse(f"127.0.0.1:{opened.port}"), opened.clerk.roster.code, "Ann")
        session = GameSession(GameConfig(seed=ann.seed))
        session.play([])
        args = argparse.Namespace(bot=None)
        _class_standing(session, args, ann)(None)  # the window closes at once: later() is never asked
        _wait_for_hand_ins(args)
        assert len(opened.clerk.entries) == 1
    assert capsys.readouterr().out.splitlines()[-1] == "handed in: 1st of 1 in the class (your best so far)"
