"""The game window under SDL's dummy driver: what is drawn where, input through real pygame events,
the countdown, the end screen, replays' controls, and the layout of every screen at every window size."""

import math
import os
import signal
import subprocess
import sys

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ["SDL_AUDIODRIVER"] = "dummy"

import pygame
import pytest

from armgame.game.bots import Autopilot, make_bot
from armgame.game.muscles import DEFAULT_MUSCLES, remap_keys
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession, RealTimeDriver
from armgame.ui.display import fit_size
from armgame.ui.frontend import END_KEY_DELAY, GameWindow, ReplaySource, open_window
from armgame.ui.render import MIN_TEXT_AT_720, PALETTES, GameRenderer, Hud, Standing, Viewport, contrast_ratio

PALETTE = PALETTES["okabe-ito"]
SIZES = [(640, 480), (1280, 720), (1366, 768), (1920, 1080), (720, 1280), (800, 800)]


class FakeClock:
    """Real time that moves only when the test says so: no test ever sleeps."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


class FakeSounds:
    available = True

    def __init__(self) -> None:
        self.played: list[str] = []
        self.muted = False

    def play(self, name):
        if not self.muted:
            self.played.append(name)

    def toggle(self):
        self.muted = not self.muted
        return self.muted


@pytest.fixture
def window():
    def make(size=(1280, 720), countdown=False, window_options=None, **config):
        screen = open_window(size)
        clock = FakeClock()
        win = GameWindow(GameSession(GameConfig(**config)), screen, clock=clock, fps=0, countdown=countdown,
                         **(window_options or {}))
        return win, clock

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


def post_key(name, down=True):
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN if down else pygame.KEYUP, key=pygame.key.key_code(name)))


@pytest.mark.parametrize("size", [(800, 800), (1280, 720), (600, 900)])
def test_arm_target_and_hud_are_drawn_where_the_state_says(window, size):
    win, _ = window(size)
    win.frame(0.0)
    lay = win.renderer.layout(win.screen.get_size(), win.session, win.hud())
    view = lay.view
    hand, mid_upper, mid_fore = world_points(win.session)
    target = win.session.rules.target
    assert colour_at(win.screen, view.to_screen(target.x, target.y)) == PALETTE.target  # the bullseye's dot
    ring_gap = view.to_screen(target.x + target.radius * 0.5, target.y)
    assert colour_at(win.screen, ring_gap) != PALETTE.target  # a ring around a dot: not the hand's disc
    assert colour_at(win.screen, view.to_screen(*hand)) == PALETTE.hand
    assert colour_at(win.screen, view.to_screen(*mid_upper)) not in (PALETTE.scene, PALETTE.workspace)  # the body
    assert colour_at(win.screen, view.to_screen(*mid_fore)) == PALETTE.skin
    assert colour_at(win.screen, view.to_screen(0.7, 1.1)) == PALETTE.scene  # outside the reachable workspace
    assert colour_at(win.screen, view.to_screen(-0.5, 0.3)) == PALETTE.workspace
    # The score is written where the layout puts it: dark text pixels in its rectangle.
    score = next(lab for lab in lay.labels if lab.role == "score")
    assert any(sum(colour_at(win.screen, (x, y))) < 200 for x in range(score.rect.left, score.rect.right)
               for y in range(score.rect.top, score.rect.bottom))
    assert lay.scene.contains(pygame.Rect(view.to_screen(-0.8, 1.2), (1, 1)))


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
    view = win.renderer.layout(win.screen.get_size(), win.session, win.hud()).view
    hand, mid_upper, _ = world_points(win.session)
    assert not win.session.rules.arm_visible
    assert colour_at(win.screen, view.to_screen(*mid_upper)) in (PALETTE.scene, PALETTE.workspace)
    assert colour_at(win.screen, view.to_screen(*hand)) == PALETTE.hand


def test_countdown_holds_the_clock_and_any_key_skips_it(window):
    sounds = FakeSounds()
    win, _ = window(countdown=True, window_options={"sounds": sounds})
    win.frame(0.0)
    assert win.hud().countdown == 3
    for _ in range(60):  # 1.5 s of the 3 s countdown
        win.frame(0.025)
    assert win.session.steps == 0 and win.hud().countdown == 2
    assert sounds.played == ["tick", "tick"]
    post_key("d")  # skips the countdown; it is not a muscle command
    win.frame(0.1)
    assert win.countdown_left is None and win.session.timeline == [] and win.session.held == [False] * 4
    win.frame(0.1)
    assert win.session.steps == round(0.2 / win.session.config.dt)  # the clock starts in the frame of the key
    assert sounds.played[-1] == "go"


def test_countdown_runs_out_by_itself(window):
    win, _ = window(countdown=True)
    frames = 0
    while win.countdown_left is not None:
        win.frame(0.1)
        frames += 1
    assert frames in (30, 31) and win.session.steps == 0
    win.frame(0.2)
    assert win.session.steps == round(0.2 / win.session.config.dt)


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


def test_feedback_sounds_and_trail_leave_the_result_alone():
    """Countdown, hit flashes, "+1", fades, the trail, sounds, pause and the end screen only read the game."""
    screen = open_window((1280, 720))
    try:
        config = GameConfig(time_limit=8.0, seed=4)
        session = GameSession(config)
        sounds = FakeSounds()
        driver = RealTimeDriver(Autopilot(session, make_bot("model")))  # type: ignore[arg-type]
        win = GameWindow(session, screen, clock=FakeClock(), fps=0, driver=driver, sounds=sounds, trail=True,
                         driven_by="AUTOPILOT: model", standing=lambda name: None)
        frames = 0
        while not win.ended:
            win.frame(1 / 37)  # an odd frame rate: the physics must not care
            frames += 1
            if frames == 200:
                win.set_paused(True)
            if frames == 230:
                win.set_paused(False)
            if frames == 150:
                assert len(win.hud().trail) > 10
        assert session.rules.board.hits >= 3
        assert sounds.played.count("hit") == session.rules.board.hits and sounds.played[-1] == "end"
        headless = GameSession(config)
        assert headless.play(session.timeline) == session.result()
        assert headless.state == session.state
    finally:
        pygame.display.quit()


def test_hit_flashes_and_says_plus_one(window):
    win, _ = window()
    target = win.session.rules.target
    win.session.rules.hand_moved(target.x, target.y, 0.0)  # as the physics reports a hit
    win.hits.append((target.x, target.y, win.session.time))
    win.frame(0.0)
    lay = win.renderer.layout(win.screen.get_size(), win.session, win.hud())
    plus = [lab for lab in lay.labels if lab.text == "+1"]
    assert plus and lay.scene.contains(plus[0].rect)
    assert colour_at(win.screen, lay.view.to_screen(target.x, target.y)) == PALETTE.flash
    # The next target fades in: right after the hit it is still close to the scene's colour.
    new = win.session.rules.target
    centre = colour_at(win.screen, lay.view.to_screen(new.x, new.y))
    assert sum(abs(a - b) for a, b in zip(centre, PALETTE.scene, strict=True)) < 30


def test_clock_turns_colour_in_the_last_ten_seconds(window):
    win, _ = window(time_limit=12.0)
    clock = next(lab for lab in win.renderer.layout((1280, 720), win.session, win.hud()).labels
                 if lab.role == "clock")
    assert clock.colour == PALETTE.ink
    win.session.advance(round(3.0 / win.session.config.dt))
    clock = next(lab for lab in win.renderer.layout((1280, 720), win.session, win.hud()).labels
                 if lab.role == "clock")
    assert clock.colour == PALETTE.warn


def test_pause_stops_the_clock_releases_keys_and_leaves_hand_and_target_visible(window):
    win, _ = window()
    post_key("d")
    win.frame(0.1)
    post_key("p")
    win.frame(0.5)
    steps = win.session.steps
    win.frame(0.5)
    assert win.paused and win.session.steps == steps
    assert win.session.held == [False] * 4
    lay = win.renderer.layout(win.screen.get_size(), win.session, win.hud())
    assert any(lab.text == "PAUSED" for lab in lay.labels)
    assert not any(lay.scene.colliderect(lab.rect) for lab in lay.labels)  # the panel is aside
    target = win.session.rules.target
    assert colour_at(win.screen, lay.view.to_screen(target.x, target.y)) == PALETTE.target
    assert colour_at(win.screen, lay.view.to_screen(*win.session.hand())) == PALETTE.hand
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


def test_ctrl_c_ends_the_game_at_the_frame_s_end_as_closing_the_window_does(window):
    """The first Ctrl-C asks the window to close and the frame under way ends whole; a second one raises, for a
    loop that would not stop; the SIGINT handler before the window is put back."""
    before = signal.getsignal(signal.SIGINT)
    win, _ = window()
    frames, draw = [], win.frame

    def frame(seconds):
        frames.append(seconds)
        if len(frames) == 3:
            signal.raise_signal(signal.SIGINT)  # Ctrl-C in the terminal, on every platform
        draw(0.1)

    win.frame = frame
    win.run(max_frames=50)
    assert len(frames) == 3 and not win.running and win.session.time > 0
    assert signal.getsignal(signal.SIGINT) is before
    stuck, _ = window()
    stuck.frame = lambda _seconds: (signal.raise_signal(signal.SIGINT), signal.raise_signal(signal.SIGINT))
    with pytest.raises(KeyboardInterrupt):
        stuck.run(max_frames=50)
    assert signal.getsignal(signal.SIGINT) is before


@pytest.mark.slow  # a process with a window: a second or two
def test_ctrl_c_during_a_game_keeps_its_replay_and_says_so(tmp_path):
    """``armgame play`` stopped by Ctrl-C in the terminal (here raised at the 30th frame drawn) prints the score and
    keeps the game's replay, as closing the window does, and exits 0: a stopped game is not an error."""
    code = (
        "import os, signal, sys\n"
        "os.environ['SDL_VIDEODRIVER'] = 'dummy'; os.environ['SDL_AUDIODRIVER'] = 'dummy'\n"
        "import pygame\n"
        "flip, frames = pygame.display.flip, []\n"
        "def counted():\n"
        "    frames.append(1)\n"
        "    if len(frames) == 1:  # any key skips the countdown\n"
        "        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_d))\n"
        "    if len(frames) == 30:\n"
        "        signal.raise_signal(signal.SIGINT)\n"
        "    flip()\n"
        "pygame.display.flip = counted\n"
        "from armgame.cli import main\n"
        f"sys.exit(main(['play', '--scores', {str(tmp_path / 'scores')!r}, '--settings', "
        f"{str(tmp_path / 'settings.toml')!r}]))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "interrupted" not in out.stderr and "the game was stopped at" in out.stdout, out.stdout
    kept = list((tmp_path / "scores").rglob("*.json"))
    assert len(kept) == 1 and str(kept[0]) in out.stdout


def labels_of(win):
    return win.renderer.layout(win.screen.get_size(), win.session, win.hud()).labels


def test_end_screen_shows_rank_and_table_at_once_then_saves_the_name_then_enter_plays_again(window):
    asked = []
    table = tuple((i, f"P{i}", 20 - i) for i in range(1, 11))

    def standing(name):
        asked.append(name)
        return Standing(2, 12, table, "custom games")

    def preview():
        return Standing(3, 12, ((1, "P1", 19), (2, "P2", 18), (3, "", 0)), "custom games", pending=True)

    win, _ = window(time_limit=0.5, window_options={"ask_name": True, "standing": standing, "preview": preview})
    for _ in range(40):
        win.frame(1 / 60)
    assert win.session.over and win.ended and win.name_entry == ""
    texts = [lab.text for lab in labels_of(win)]
    # Score, rank, the list's heading and the table, before any name is typed; and the length limit.
    assert "Your score: 0" in texts and "You would rank 3 of 12" in texts and "Custom games" in texts
    assert "P2" in texts and "you" in texts and "0/24" in texts and asked == []
    for _ in range(40):
        win.frame(1 / 60)
    pygame.event.post(pygame.event.Event(pygame.TEXTINPUT, text="Ann"))
    win.frame(0.0)
    texts = [lab.text for lab in labels_of(win)]
    assert "Ann" in texts and "3/24" in texts  # the name typed shows in its row of the table, and its length
    post_key("return")
    win.frame(0.0)
    assert asked == ["Ann"] and win.player_name == "Ann"
    texts = [lab.text for lab in labels_of(win)]
    assert "Rank 2 of 12" in texts and "P10" in texts and "Enter plays again    Esc quits" in texts
    post_key("return")  # too soon: the Enter that saved, pressed twice, does not start a game
    win.frame(0.1)
    assert win.running
    win.frame(END_KEY_DELAY)
    post_key("x")  # not a key of the end screen
    win.frame(0.0)
    assert win.running and not win.play_again
    post_key("return")
    win.frame(0.0)
    assert not win.running and win.play_again


def test_keys_held_at_the_buzzer_never_reach_the_name(window):
    win, _ = window(time_limit=1.0, window_options={"ask_name": True})
    post_key("j")
    while not win.ended:  # j held to the end: the game takes it, and its repeats follow
        win.frame(1 / 60)
    post_key("k")  # mashed as the end screen opens, and held
    win.frame(0.1)
    for _ in range(60):  # a second of the keyboard's repeats of both held keys
        pygame.event.post(pygame.event.Event(pygame.TEXTINPUT, text="j"))
        pygame.event.post(pygame.event.Event(pygame.TEXTINPUT, text="k"))
        win.frame(1 / 60)
    post_key("return")
    win.frame(0.0)
    assert win.name_entry == "" and not win.typing and win.running
    post_key("j", down=False)
    pygame.event.post(pygame.event.Event(pygame.TEXTINPUT, text="k"))
    win.frame(0.0)
    assert win.name_entry == ""  # k is still held
    post_key("k", down=False)
    pygame.event.post(pygame.event.Event(pygame.TEXTINPUT, text="Bo"))
    win.frame(0.0)
    assert win.typing and win.name_entry == "Bo"
    pygame.event.post(pygame.event.Event(pygame.TEXTINPUT, text="x" * 40))
    win.frame(0.0)
    assert len(win.name_entry) == 24 and "24/24" in [lab.text for lab in labels_of(win)]


def test_escape_on_the_end_screen_quits_without_playing_again(window):
    win, _ = window(time_limit=0.2, window_options={"ask_name": True})
    while not win.ended:
        win.frame(0.05)
    post_key("escape")
    win.frame(0.0)
    assert not win.running and not win.play_again and win.player_name is None


# ------------------------------------------------------------------------------------------ replays
def test_replay_speed_and_skips_match_a_fresh_replay(window):
    config = GameConfig(time_limit=20.0, seed=5)
    played = GameSession(config)
    Autopilot(played, make_bot("model")).play()
    source = ReplaySource(config, tuple(played.timeline), played.steps, "Ann")
    screen = open_window((1280, 720))
    win = GameWindow(GameSession(config), screen, clock=FakeClock(), fps=0, replay=source, driven_by="REPLAY")
    # The help line names the player and lists exactly the keys that work.
    assert win.help_items() == ("watching Ann's game", "p pause", "-/+ speed", "1 real speed", "left/right 5 s",
                                "F11 fullscreen", "Esc quit")
    post_key("up")  # not one of them: nothing happens
    win.frame(0.0)
    assert win.speed == 1.0
    assert win.countdown_left is None and not win.keyboard
    win.frame(0.2)
    assert win.session.steps == round(0.2 / config.dt)
    post_key("=")
    post_key("=")
    win.frame(0.0)
    win.frame(0.2)
    assert win.speed == 4.0 and win.session.steps == round(1.0 / config.dt)
    post_key("right")
    win.frame(0.0)
    assert win.session.steps == round(6.0 / config.dt)
    post_key("left")
    post_key("left")
    win.frame(0.0)
    assert win.session.steps == 0  # clamped at the start
    post_key("right")
    post_key("right")
    win.frame(0.0)
    post_key("left")
    win.frame(0.0)
    fresh = GameSession(config)
    fresh.play(played.timeline, round(5.0 / config.dt))
    assert win.session.steps == fresh.steps and win.session.state == fresh.state
    assert win.session.result() == fresh.result()
    for _ in range(10):
        post_key("-")
    win.frame(0.0)
    assert win.speed == 0.25
    lay = win.renderer.layout((1280, 720), win.session, win.hud())
    assert lay.progress is not None and lay.progress[1] == pytest.approx(0.25)
    assert any("left/right 5 s" in lab.text for lab in lay.labels if lab.role == "help")
    assert not any("shoulder" in lab.text for lab in lay.labels if lab.role == "help")
    post_key("p")
    win.frame(0.0)
    assert "p resume" in win.help_items()
    win.skip_to(source.stop_step)
    win.frame(0.0)
    assert win.ended and win.session.result() == played.result()
    win.frame(END_KEY_DELAY)
    post_key("left")  # the replay's keys still work at its end: back 5 s, and it plays on
    win.frame(0.0)
    assert not win.ended and win.session.steps == source.stop_step - round(5.0 / config.dt)
    win.skip_to(source.stop_step)
    win.frame(0.0)
    win.frame(END_KEY_DELAY)
    post_key("return")  # Enter watches again
    win.frame(0.0)
    assert win.running and not win.ended and win.session.steps == 0


# ------------------------------------------------------------------------------------------- layout
def screens(session, renderer):
    """Every screen the game window shows, as the HUD it hands the renderer."""
    keys = session.muscles.keys
    play_help = (f"{keys[0]}/{keys[1]} shoulder", f"{keys[2]}/{keys[3]} elbow", "space reset (-1)", "tab hide arm",
                 "p pause", "m mute", "F11 fullscreen", "Esc quit")
    table = Standing(3, 40, tuple((i, "W" * 24, 999) for i in range(1, 11)), mine=2)
    return {
        "play": Hud(details=("seed 10",), help=play_help),
        "countdown": Hud(details=("seed 10",), help=play_help, countdown=3),
        "paused": Hud(details=("seed 10",), help=play_help, paused=True),
        "hit": Hud(details=("seed 10",), help=play_help, hits=[(0.1, 0.6, 0.1)]),
        "bot": Hud(driver="AUTOPILOT: model", help=("p pause", "m mute", "F11 fullscreen", "Esc quit")),
        "replay": Hud(driver="REPLAY", details=("Wolfgang Amadeus", "2026-11-22 23:59"), progress=(12.3, 60.0),
                      speed=0.25,
                      help=("p pause", "-/+ speed", "left/right 5 s", "m mute", "F11 fullscreen", "Esc quit")),
        "name": Hud(ended=True, name_entry="W" * 24),
        "name and table": Hud(ended=True, name_entry="W" * 24, end_hint="Enter saves    Esc quits (the "
                              "game's replay is kept)", standing=Standing(3, 40, table.top, "custom games", True)),
        "end": Hud(ended=True, standing=table),
        "end, ranked low": Hud(ended=True, standing=Standing(
            38, 40, (*table.top, (38, "W" * 24, 0)), "the ranked table", mine=10)),
        "end, no table": Hud(driver="REPLAY", ended=True),
    }


def assert_fits(size, boxes, min_height, what):
    window = pygame.Rect((0, 0), size)
    for name, rect in boxes:
        assert window.contains(rect), f"{what} at {size}: {name!r} {rect} is cut"
        if not name.startswith("bar") and name != "progress":
            assert rect.height >= min_height, f"{what} at {size}: {name!r} is {rect.height} px high"
    for i, (a, ra) in enumerate(boxes):
        for b, rb in boxes[i + 1:]:
            assert not ra.colliderect(rb), f"{what} at {size}: {a!r} {ra} overlaps {b!r} {rb}"


@pytest.mark.parametrize("size", SIZES)
def test_every_screen_fits_every_window(size):
    pygame.display.init()
    pygame.font.init()
    session = GameSession(GameConfig())
    session.key_event("d", "down")
    session.advance(100)
    renderer = GameRenderer(session.muscles.keys, tuple(m.name for m in session.config.muscles))
    min_height = max(math.floor(MIN_TEXT_AT_720 * min(size) / 720), round(0.025 * size[1]))
    for what, hud in screens(session, renderer).items():
        lay = renderer.layout(size, session, hud)
        assert lay.labels, what
        assert_fits(size, lay.boxes(), min_height, what)
        if not hud.ended:  # the HUD never covers the arm's workspace
            assert not any(lay.scene.colliderect(lab.rect) for lab in lay.labels if lab.role
                           not in ("countdown", "effect")), what
            assert min(lay.scene.size) >= 0.5 * min(size), what


@pytest.mark.parametrize("palette", sorted(PALETTES))
def test_text_colours_meet_wcag_aa(palette):
    p = PALETTES[palette]
    for text in (p.ink, p.faint):
        for background in (p.window, p.scene, p.panel):
            assert contrast_ratio(text, background) >= 4.5, (palette, text, background)
    # The warning clock and the player's own row in the table are text too.
    assert contrast_ratio(p.warn, p.window) >= 4.5 and contrast_ratio(p.warn, p.panel) >= 4.5
    assert contrast_ratio((0, 0, 0), (255, 255, 255)) == pytest.approx(21.0)
    assert contrast_ratio((118, 118, 118), (255, 255, 255)) == pytest.approx(4.54, abs=0.01)  # WCAG's example


def test_muscle_colours_are_okabe_ito():
    okabe_ito = {(230, 159, 0), (86, 180, 233), (0, 158, 115), (240, 228, 66), (0, 114, 178), (213, 94, 0),
                 (204, 121, 167)}
    assert set(PALETTE.muscles) <= okabe_ito and len(set(PALETTE.muscles)) == 4
    assert PALETTE.target in okabe_ito


# ------------------------------------------------------------------------------------ window sizes
def test_windows_fit_the_desktop():
    # Nothing asked: the default's shape, as large as the desktop allows (room for a title bar).
    assert fit_size(None, (1200, 800), (1920, 1080)) == (1524, 1016)
    assert fit_size(None, (1200, 800), (1280, 720)) == (984, 656)
    for desktop in ((1024, 768), (1280, 720), (1920, 1080), (3840, 2160), (1080, 1920)):
        for default in ((1200, 800), (1280, 720), (800, 800)):
            w, h = fit_size(None, default, desktop)
            assert w <= desktop[0] and h <= desktop[1] and max(w / desktop[0], h / desktop[1]) >= 0.9
    assert fit_size((3000, 3000), (800, 800), (1366, 768)) == (704, 704)
    assert fit_size((1024, 600), (800, 800), (1366, 768)) == (1024, 600)
    screen = open_window((5000, 4000))
    desktop = pygame.display.get_desktop_sizes()[0]
    assert screen.get_width() <= desktop[0] and screen.get_height() <= desktop[1]
    pygame.display.quit()


def test_f11_toggles_fullscreen(window):
    win, _ = window((800, 600))
    post_key("f11")
    win.frame(0.0)
    assert win.fullscreen
    post_key("f11")
    win.frame(0.0)
    assert not win.fullscreen and win.screen.get_size() == (800, 600)


def test_a_view_still_maps_the_world_as_before():
    view = Viewport.fit((800, 800), GameConfig().view)
    assert view.to_screen(0.0, 0.0) == (400, 600) and view.scale == 500 and view.length(0.1) == 50


def test_each_mode_says_what_it_is_and_offers_only_its_keys(window):
    screen = open_window((1280, 720))
    session = GameSession(GameConfig())
    bot = GameWindow(session, screen, clock=FakeClock(), fps=0, driven_by="AUTOPILOT: naive",
                     driver=RealTimeDriver(Autopilot(session, make_bot("naive"))), sounds=FakeSounds())
    assert bot.help_items() == ("p pause", "m mute", "F11 fullscreen", "Esc quit")
    bot.frame(0.0)
    lay = bot.renderer.layout((1280, 720), bot.session, bot.hud())
    assert [lab.text for lab in lay.labels if lab.role == "mode"] == ["AUTOPILOT: naive"]
    post_key("space")  # not a key of this mode: nothing happens
    post_key("d")
    bot.frame(0.0)
    assert bot.session.rules.board.resets == 0 and bot.session.timeline == []
    player, _ = window(window_options={"sounds": FakeSounds()})
    assert "space reset (-1)" in player.help_items() and "m mute" in player.help_items()
    mapped = GameWindow(GameSession(GameConfig(muscles=remap_keys(DEFAULT_MUSCLES, "mjkl"))), screen, fps=0,
                        sounds=FakeSounds())
    assert "m mute" not in mapped.help_items()  # m is a muscle there


def test_demo_windows_toggle_fullscreen_with_f11():
    from armgame.demos.catalog import make_run
    from armgame.ui.demo_window import DemoWindow

    demo = DemoWindow("chaos", make_run("chaos"), clock=lambda: 0.0, size=(800, 600))
    demo.open()
    try:
        demo.handle(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_F11))
        assert demo.fullscreen
        demo.handle(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_F11))
        assert not demo.fullscreen and demo.size == (800, 600)
    finally:
        demo.close()


def test_a_resize_is_remembered_but_a_fullscreen_round_trip_is_not(window):
    win, _ = window((800, 600))
    for _ in range(2):
        post_key("f11")
        win.frame(0.0)
    pygame.event.post(pygame.event.Event(pygame.VIDEORESIZE, w=800, h=600, size=(800, 600)))
    win.frame(0.0)
    assert not win.resized
    pygame.event.post(pygame.event.Event(pygame.VIDEORESIZE, w=900, h=650, size=(900, 650)))
    win.frame(0.0)
    assert win.resized and win.windowed_size == (900, 650)


# ------------------------------------------------------------------------------- the play command
def scripted_games(monkeypatch, plans):
    """``armgame play`` with each game's window driven by a plan: the game played out on a fake clock,
    then each step's keys posted (text or key names) one second apart. Returns the windows' last labels."""
    seen = []

    def run(self, max_frames=None):
        self.countdown_left = None
        while not self.ended:
            self.frame(0.05)
        for step in plans.pop(0):
            self.frame(1.0)
            for kind, value in step:
                if kind == "text":
                    pygame.event.post(pygame.event.Event(pygame.TEXTINPUT, text=value))
                else:
                    post_key(value)
            self.frame(0.0)
            seen.append([lab.text for lab in labels_of(self)])
            if not self.running:
                break
        return self.session

    monkeypatch.setattr(GameWindow, "run", run)
    return seen


def test_play_enter_plays_again_with_the_same_options_and_esc_keeps_the_replay(tmp_path, monkeypatch, capsys):
    from armgame.cli import main
    from armgame.records.replay import Replay
    from armgame.records.scores import ScoreTable

    scores = tmp_path / "scores"
    seen = scripted_games(monkeypatch, [
        [[("text", "Ann"), ("key", "return")], [("key", "return")]],  # saved, then Enter: another game
        [[("key", "escape")]],  # the second game: Esc on the name prompt
    ])
    options = ["--duration", "0.5", "--seed", "4", "--scores", str(scores), "--settings", str(tmp_path / "s.toml")]
    assert main(["play", *options]) == 0
    out = capsys.readouterr().out
    assert out.count("your score is") == 2 and "saved to the high-score table as Ann" in out
    assert "Custom games" in seen[0] and "Enter plays again    Esc quits" in seen[0]
    table = ScoreTable(scores)
    assert [e.name for e in table.all_entries()] == ["Ann"]
    # The second game, not entered, is kept anyway; the line printed says how to enter it, and that works.
    (kept,) = [p for p in table.replays.iterdir() if p.name != table.all_entries()[0].replay]
    game = Replay.load(kept)
    assert game.config.seed == 4 and game.config.time_limit == 0.5 and game.complete  # the same options
    add = next(line for line in out.splitlines() if "to enter it later:" in line).split("later: ")[1]
    assert add == f"armgame scores --add {kept} --name NAME --scores {scores}"
    # Nothing was pressed in either game: the same game as Ann's, which enters once (issue 16).
    capsys.readouterr()
    assert main(add.replace("NAME", "Bo").split()[1:]) == 2
    assert "already in the table: entered by Ann" in capsys.readouterr().err
    assert [e.name for e in ScoreTable(scores).all_entries()] == ["Ann"]


def test_the_end_screen_draws_a_name_in_any_script_as_it_is_typed(window, monkeypatch):
    """A Hebrew name typed at the buzzer, and an Arabic one in the standings, are drawn with a font that has their
    letters (names.TextRenderer), not the default font's empty boxes."""
    def preview():
        return Standing(2, 3, ((1, "محمد علي", 30), (2, "", 0)), "custom games", pending=True)

    win, _ = window(time_limit=0.5, window_options={"ask_name": True, "standing": lambda name: None,
                                                    "preview": preview})
    for _ in range(80):
        win.frame(1 / 60)
    pygame.event.post(pygame.event.Event(pygame.TEXTINPUT, text="שירה"))
    win.frame(0.0)
    drawn: list[str] = []
    original = win.renderer.draw_label
    monkeypatch.setattr(win.renderer, "draw_label", lambda screen, label: (drawn.append(label.text),
                                                                           original(screen, label))[1])
    win.frame(0.0)
    assert "שירה" in drawn and "محمد علي" in drawn
    for name in ("שירה", "محمد علي"):
        boxes = win.renderer.font(30).render(name, True, (0, 0, 0))
        letters = win.renderer.text(name, 30, (0, 0, 0))
        assert pygame.image.tobytes(letters, "RGBA") != pygame.image.tobytes(boxes, "RGBA")
