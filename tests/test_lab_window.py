"""The lab window under SDL's dummy driver: keys drive the task, the cursor and targets are drawn where the
session says, and a bot in the window plays the same trials as headless."""

import json
import os

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ["SDL_AUDIODRIVER"] = "dummy"

import pygame
import pytest

from armgame.game.bots import Autopilot
from armgame.game.session import RealTimeDriver
from armgame.lab.bots import make_lab_bot
from armgame.lab.protocol import Block, Perturbation, Protocol
from armgame.lab.session import LabSession, lab_config
from armgame.ui.frontend import open_window
from armgame.ui.lab_window import CURSOR, HOME, LabWindow
from armgame.ui.render import PALETTES, Viewport

TARGET = PALETTES["okabe-ito"].target

PROTOCOL = Protocol("tiny", (Block("baseline", 2, Perturbation(), 0, "Reach straight."),
                             Block("exposure", 2, Perturbation.make("rotation", angle=30.0), 0, "Keep reaching.")),
                    timeout=1.0)


class FakeClock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


@pytest.fixture
def screen():
    yield open_window((1280, 720))
    pygame.display.quit()


def view_of(win):
    s = win.session
    hx, hy = s.home
    span = max(0.08, 1.45 * s.protocol.distance)
    return Viewport.fit(win.screen.get_size(), (hx - span, hx + span, hy - span, hy + 1.35 * span))


def test_keys_move_the_cursor_and_the_go_cue_shows_the_target(screen):
    session = LabSession(lab_config(PROTOCOL, 2), PROTOCOL)
    clock = FakeClock()
    win = LabWindow(session, screen, clock=clock, fps=0)
    win.frame(0.0)
    view = view_of(win)
    assert tuple(win.screen.get_at(view.to_screen(*session.cursor)))[:3] == CURSOR
    ring = view.to_screen(session.home[0] + 0.7 * session.protocol.home_radius, session.home[1])
    assert tuple(win.screen.get_at(ring))[:3] == HOME  # filled while holding
    while session.phase == "hold":
        win.frame(0.05)
    win.frame(0.0)
    target = session.rules.target
    assert tuple(win.screen.get_at(view.to_screen(target.x, target.y)))[:3] == TARGET
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_d))
    before = session.cursor
    for _ in range(6):
        win.frame(0.05)
    assert session.held[0] and session.cursor != before
    assert session.timeline[0].key == "d"


def test_a_bot_in_the_window_plays_the_headless_trials(screen):
    headless = LabSession(lab_config(PROTOCOL, 2), PROTOCOL)
    Autopilot(headless, make_lab_bot("model")).play()
    session = LabSession(lab_config(PROTOCOL, 2), PROTOCOL)
    driver = RealTimeDriver(Autopilot(session, make_lab_bot("model")))
    win = LabWindow(session, screen, clock=FakeClock(), fps=0, driver=driver)
    frames = 0
    while not session.over and frames < 2000:
        win.frame(1 / 30)  # frames of any length: the same steps
        frames += 1
    assert session.trial_records() == headless.trial_records()
    win.frame(0.0)  # the end banner draws


def test_a_lab_replay_plays_back_in_the_lab_window(screen):
    """armgame replay of a lab run: the timeline drives a LabSession in the lab window, to the same trials."""
    from armgame.game.timeline import TimelineDriver
    from armgame.lab.record import LabTask

    recorded = LabSession(lab_config(PROTOCOL, 5), PROTOCOL)
    Autopilot(recorded, make_lab_bot("model")).play()
    task = LabTask.of(recorded)
    session = task.new_session(recorded.config)
    driver = TimelineDriver(session, recorded.timeline, recorded.steps)
    win = LabWindow(session, screen, clock=FakeClock(), fps=0, driver=driver)
    frames = 0
    while not driver.done and frames < 1000:
        win.frame(0.25)
        frames += 1
    assert session.trial_records() == recorded.trial_records() and session.state == recorded.state


def test_a_person_quitting_early_keeps_a_replay_that_verifies(tmp_path, monkeypatch, capsys):
    """armgame lab in a window: keys pressed, Esc after a few seconds; the partial run is recorded and
    verifies, and analyze measures the reaches it finished."""
    from armgame.cli import main

    def play_a_little(self, max_frames=None):
        for i in range(200):
            if i == 40:
                pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_j))
            if i == 44:
                pygame.event.post(pygame.event.Event(pygame.KEYUP, key=pygame.K_j))
            self.frame(1 / 20)
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_ESCAPE))
        self.frame(1 / 20)
        assert not self.running
        return self.session

    monkeypatch.setattr(LabWindow, "run", play_a_little)
    record = tmp_path / "me.json"
    assert main(["lab", "curl", "--record", str(record), "--name", "Ann", "--size", "640x480"]) == 0
    out = capsys.readouterr().out
    assert "(stopped before the end)" in out and f"replay saved to {record}" in out
    assert main(["verify", str(record)]) == 0
    assert "matches: Ann's lab run (curl, keyboard" in capsys.readouterr().out
    data = json.loads(record.read_text())
    assert data["driven"] == "keyboard" and [e[1] for e in data["timeline"]] == ["j", "j"]
    assert len(data["task"]["trials"]) >= 2
