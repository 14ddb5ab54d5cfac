"""The game window under SDL's dummy driver: what is drawn where, and input through real pygame events."""

import math
import os

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ["SDL_AUDIODRIVER"] = "dummy"

import pygame
import pytest

from armgame.game.rules import GameConfig
from armgame.game.session import GameSession
from armgame.ui.frontend import GameWindow, open_window
from armgame.ui.render import BACKGROUND, HAND, LINK, PANEL, TARGET, Viewport


class FakeClock:
    """Real time that moves only when the test says so: no test ever sleeps."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


@pytest.fixture
def window():
    def make(size=(800, 800), **config):
        screen = open_window(size)
        clock = FakeClock()
        return GameWindow(GameSession(GameConfig(**config)), screen, clock=clock, fps=0), clock

    yield make
    pygame.display.quit()


def colour_at(screen, point):
    return tuple(screen.get_at(point))[:3]


def world_points(session):
    arm = session.config.arm
    q1 = session.state[0]
    elbow = (arm.l1 * math.cos(q1), arm.l1 * math.sin(q1))
    hand = session.hand()
    mid_upper = (elbow[0] / 2, elbow[1] / 2)
    mid_fore = ((elbow[0] + hand[0]) / 2, (elbow[1] + hand[1]) / 2)
    return hand, mid_upper, mid_fore


@pytest.mark.parametrize("size", [(800, 800), (1280, 720), (600, 900)])
def test_arm_target_and_hud_are_drawn_where_the_state_says(window, size):
    win, _ = window(size)
    win.frame(0.0)
    view = Viewport.fit(win.screen.get_size(), win.session.config.view)
    hand, mid_upper, mid_fore = world_points(win.session)
    target = win.session.rules.target
    assert colour_at(win.screen, view.to_screen(target.x, target.y)) == TARGET
    assert colour_at(win.screen, view.to_screen(*hand)) == HAND
    assert colour_at(win.screen, view.to_screen(*mid_upper)) == LINK
    assert colour_at(win.screen, view.to_screen(*mid_fore)) == LINK
    # Far from the arm and the target: background.
    assert colour_at(win.screen, view.to_screen(0.7, -0.35)) == BACKGROUND
    # The HUD's score line sits at the top left of the scene: dark text pixels there.
    x0, y0 = round(view.left + 16 * view.scale / 500), round(view.top + 12 * view.scale / 500)
    box = [colour_at(win.screen, (x, y)) for x in range(x0, x0 + round(100 * view.scale / 500))
           for y in range(y0, y0 + round(25 * view.scale / 500))]
    assert any(sum(c) < 200 for c in box)
    if size == (800, 800):
        # The 2012 game's geometry: shoulder at (400, 600), 500 px per metre.
        assert view.to_screen(0.0, 0.0) == (400, 600) and view.scale == 500


def post_key(name, down=True):
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN if down else pygame.KEYUP, key=pygame.key.key_code(name)))


def test_keyboard_drives_the_arm_and_tab_hides_it(window):
    win, clock = window()
    post_key("d")
    post_key("k")
    for _ in range(30):
        clock.now += 1 / 60
        win.frame(1 / 60)
    assert win.session.steps == round(0.5 / win.session.config.dt)
    assert win.session.held == [True, False, False, True]
    assert win.session.state[0] > math.radians(45) and win.session.state[1] < math.radians(90)
    post_key("tab")
    win.frame(0.0)
    view = Viewport.fit(win.screen.get_size(), win.session.config.view)
    hand, mid_upper, _ = world_points(win.session)
    assert not win.session.rules.arm_visible
    assert colour_at(win.screen, view.to_screen(*mid_upper)) == BACKGROUND
    assert colour_at(win.screen, view.to_screen(*hand)) == HAND


def test_windowed_game_equals_headless_replay_of_its_timeline(window):
    win, _ = window(time_limit=2.0, seed=3)
    schedule = {0: [("d", True)], 10: [("d", False), ("j", True)], 25: [("j", False)], 40: [("space", True)]}
    frame = 0
    while not win.session.over:
        for name, down in schedule.get(frame, []):
            post_key(name, down)
        win.frame(1 / 50)
        frame += 1
    replay = GameSession(GameConfig(time_limit=2.0, seed=3))
    replay.play(win.session.timeline)
    assert replay.state == win.session.state
    assert replay.result() == win.session.result()
    assert win.session.rules.board.resets == 1


def test_pause_stops_the_clock_and_releases_held_keys(window):
    win, _ = window()
    post_key("d")
    win.frame(0.1)
    post_key("p")
    win.frame(0.5)
    steps = win.session.steps
    win.frame(0.5)
    assert win.paused and win.session.steps == steps
    assert win.session.held == [False] * 4
    post_key("p")
    win.frame(0.1)
    assert not win.paused and win.session.steps > steps


def test_escape_and_close_end_the_window(window):
    win, _ = window()
    post_key("escape")
    win.frame(0.0)
    assert not win.running
    win2, _ = window()
    pygame.event.post(pygame.event.Event(pygame.QUIT))
    win2.run(max_frames=5)
    assert not win2.running


def test_end_screen_shows_the_score(window):
    win, _ = window(time_limit=0.5)
    for _ in range(40):
        win.frame(1 / 60)
    assert win.session.over
    view = Viewport.fit(win.screen.get_size(), win.session.config.view)
    cy = round(view.top + view.scale * 0.55)
    row = [colour_at(win.screen, (x, cy - 22)) for x in range(250, 550)]
    assert PANEL in row and any(sum(c) < 100 for c in row)  # the panel, and the title's dark letters on it
