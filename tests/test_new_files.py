"""Nothing a person made is overwritten (issue 27): --record and --out refuse an existing file before the
game or the run (--force replaces it), numbered names never collide, an abandoned game writes nothing."""

import errno
import os

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

import pytest

from armgame.cli import main
from armgame.records.storage import DataFileError, atomic_write_bytes, fresh_files, link_new, write_new

GAME = ["play", "--headless", "--bot", "model", "--duration", "0.5"]


@pytest.fixture(autouse=True)
def _home(tmp_path, monkeypatch):
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.setenv("ARMGAME_SCORES", str(tmp_path / "scores"))
    monkeypatch.setenv("ARMGAME_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    monkeypatch.chdir(tmp_path)


def test_record_refuses_an_existing_file_before_the_game_and_force_replaces_it(tmp_path, capsys):
    kept = tmp_path / "v1.json"
    kept.write_text("a volunteer's run")
    assert main([*GAME, "--record", str(kept)]) == 2
    captured = capsys.readouterr()
    assert "your score" not in captured.out  # refused before the game: no minute of play lost
    (line,) = captured.err.strip().splitlines()
    assert str(kept) in line and "already exists" in line and "--force" in line
    assert kept.read_text() == "a volunteer's run"
    assert main([*GAME, "--record", str(kept), "--force"]) == 0
    assert kept.read_text().startswith("{") and f"replay saved to {kept}" in capsys.readouterr().out


def test_record_into_a_folder_names_each_game_after_its_player_and_number(tmp_path, capsys):
    hand_in = tmp_path / "hand-in"
    hand_in.mkdir()
    (hand_in / "ann-b-game7.json").write_text("an earlier game")
    (hand_in / "bo-game9.json").write_text("someone else's")
    assert main([*GAME, "--record", str(hand_in), "--name", "Ann B"]) == 0
    assert main([*GAME, "--record", f"{hand_in}{os.sep}", "--name", "Ann B", "--seed", "2"]) == 0
    out = capsys.readouterr().out
    assert f"replay saved to {hand_in / 'ann-b-game8.json'}" in out
    assert f"replay saved to {hand_in / 'ann-b-game9.json'}" in out
    assert (hand_in / "ann-b-game7.json").read_text() == "an earlier game"
    assert main([*GAME, "--record"]) == 0  # alone: the current folder, no name given
    assert "replay saved to player-game1.json" in capsys.readouterr().out and (tmp_path / "player-game1.json").exists()
    assert main([*GAME, "--record", str(tmp_path / "no-such") + os.sep]) == 2
    assert "no such folder" in capsys.readouterr().err


def test_numbered_names_are_claimed_atomically_and_never_replace(tmp_path, monkeypatch):
    (tmp_path / "g1.json").write_text("first")
    name_of = lambda n: tmp_path / f"g{n}.json"  # noqa: E731
    assert write_new(name_of, 1, b"second") == tmp_path / "g2.json"
    assert (tmp_path / "g1.json").read_text() == "first" and (tmp_path / "g2.json").read_bytes() == b"second"

    def no_hard_links(src, dst):
        raise OSError(errno.EPERM, "hard links not supported")

    monkeypatch.setattr(os, "link", no_hard_links)  # FAT, some network shares: the exclusive claim instead
    assert write_new(name_of, 1, b"third") == tmp_path / "g3.json"
    assert [(tmp_path / f"g{n}.json").read_bytes() for n in (1, 2, 3)] == [b"first", b"second", b"third"]
    tmp = tmp_path / "t"
    tmp.write_bytes(b"x")
    with pytest.raises(FileExistsError):
        link_new(tmp, tmp_path / "g1.json")
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]  # no temporary file left behind


def test_a_file_that_appears_during_the_run_is_not_replaced(tmp_path):
    target = tmp_path / "out" / "trials.csv"
    target.parent.mkdir()
    target.write_text("made meanwhile")
    with fresh_files(folders=[target.parent]), pytest.raises(DataFileError, match="already exists"):
        atomic_write_bytes(target, b"new")
    assert target.read_text() == "made meanwhile"
    atomic_write_bytes(target, b"new")  # outside the block, armgame's own files are replaced as ever
    assert target.read_bytes() == b"new"
    assert [p.name for p in target.parent.iterdir()] == ["trials.csv"]


@pytest.mark.parametrize("command", [
    ["simulate", "--scene", "passive", "--duration", "0.1", "--out", "{d}/s.csv"],
    ["demo", "pendulum", "--headless", "--no-figures", "--duration", "0.1", "--out", "{d}"],
    ["lab", "curl", "--headless", "--bot", "model", "--no-figures", "--out", "{d}"],
    ["analyze", "{d}/r.json", "--out", "{d}"],
    ["analyze", "--class", "{d}", "--out", "{d}", "--no-figures"],
])
def test_every_out_refuses_to_replace_before_it_starts(tmp_path, capsys, command):
    made = {"simulate": "s.csv", "demo": "pendulum.csv", "lab": "trials.csv"}.get(command[0])
    made = made or ("class_curve.csv" if "--class" in command else "r.trials.csv")
    (tmp_path / made).write_text("mine")
    assert main([part.replace("{d}", str(tmp_path)) for part in command]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert made in line and "already exists" in line and "--force" in line
    assert (tmp_path / made).read_text() == "mine"


def test_lab_record_refuses_an_existing_run_and_numbers_into_a_folder(tmp_path, capsys):
    run = tmp_path / "v1.json"
    run.write_text("the volunteer's")
    protocol = tmp_path / "two.toml"
    protocol.write_text("[[blocks]]\ntrials = 2\n")
    lab = ["lab", str(protocol), "--headless", "--bot", "model", "--name", "Vol 1"]
    assert main([*lab, "--record", str(run)]) == 2
    assert "lab two" not in capsys.readouterr().out and run.read_text() == "the volunteer's"
    assert main([*lab, "--record", str(tmp_path)]) == 0
    assert main([*lab, "--record", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert f"replay saved to {tmp_path / 'vol-1-lab1.json'}" in out and "vol-1-lab2.json" in out
    assert main(["verify", str(tmp_path / "vol-1-lab2.json")]) == 0


def test_a_window_game_quit_at_its_countdown_writes_nothing_and_the_end_screen_names_the_file(tmp_path, monkeypatch,
                                                                                           capsys):
    import pygame

    from armgame.game.session import DOWN, UP
    from armgame.ui.frontend import GameWindow

    screens = []

    def run(self, max_frames=None):
        if screens:  # the second game: Esc at its countdown
            pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_ESCAPE, mod=0, unicode="",
                                                 scancode=0))
            self.frame(0.0)
            return self.session
        self.countdown_left = None
        self.session.key_event("d", DOWN)
        self.frame(0.1)
        self.session.key_event("d", UP)
        while not self.ended:
            self.frame(0.05)
        screens.append([lab.text for lab in self.renderer.layout(self.screen.get_size(), self.session,
                                                                  self.hud()).labels])
        self.play_again, self.running = True, False
        return self.session

    monkeypatch.setattr(GameWindow, "run", run)
    assert main(["play", "--duration", "0.3", "--name", "Ann B", "--record", str(tmp_path),
                 "--settings", str(tmp_path / "s.toml")]) == 0
    out = capsys.readouterr().out
    assert "Saved as ann-b-game1.json" in screens[0]
    assert f"replay saved to {tmp_path / 'ann-b-game1.json'}" in out and "quit before it started: nothing kept" in out
    assert sorted(p.name for p in tmp_path.glob("*.json")) == ["ann-b-game1.json"]
