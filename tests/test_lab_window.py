"""The lab window under SDL's dummy driver: keys drive the task, the cursor and targets are drawn where the
session says, and a bot in the window plays the same trials as headless."""

import argparse
import json
import os
import re
from pathlib import Path

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ["SDL_AUDIODRIVER"] = "dummy"

import pygame
import pytest

from armgame.game.bots import Autopilot
from armgame.game.session import RealTimeDriver
from armgame.lab.bots import make_lab_bot
from armgame.lab.perturbations import Perturbation
from armgame.lab.presets import preset
from armgame.lab.protocol import Block, Protocol
from armgame.lab.session import LabSession, lab_config
from armgame.limits import MAX_GAME_SECONDS
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


def start(win):
    """Past the instruction card (space), one frame drawn."""
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_SPACE))
    win.frame(0.0)
    assert win.card is None


def test_keys_move_the_cursor_and_the_go_cue_shows_the_target(screen):
    session = LabSession(lab_config(PROTOCOL, 2), PROTOCOL)
    clock = FakeClock()
    win = LabWindow(session, screen, clock=clock, fps=0)
    start(win)
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
            if i == 1:
                pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_SPACE))
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
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    record = tmp_path / "me.json"
    assert main(["lab", "curl", "--record", str(record), "--name", "Ann", "--size", "640x480",
                 "--no-figures"]) == 0
    out = capsys.readouterr().out
    assert "(stopped before the end)" in out and f"replay saved to {record}" in out
    kept = list((tmp_path / "data" / "armgame" / "lab").glob("*_curl/trials.csv"))
    assert len(kept) == 1 and f"wrote {kept[0]}" in out  # a window run is always kept
    assert main(["verify", str(record)]) == 0
    assert "matches: Ann's lab run (curl, keyboard" in capsys.readouterr().out
    data = json.loads(record.read_text())
    assert data["driven"] == "keyboard" and [e[1] for e in data["timeline"]] == ["j", "j"]
    assert len(data["task"]["trials"]) >= 2
    # A person's clock (curl: 120 trials): three times the worst trials and two minutes more, not a
    # program's one and a half times and one minute.
    curl = preset("curl")
    worst = curl.trials * (curl.delay[1] + curl.timeout)
    assert data["config"]["time_limit"] == 3 * worst + 120 == lab_config(curl, 10, person=True).time_limit


def test_a_persons_run_has_room_on_the_clock_and_says_when_it_ran_out(capsys):
    """A volunteer slow to bring the hand home still finishes the lesson where a program's clock would
    have ended the run; a run whose clock does run out says so, not just "stopped"."""
    from armgame.commands.lab import _report

    lesson = preset("lesson")
    program, person = lab_config(lesson, 1).time_limit, lab_config(lesson, 1, person=True).time_limit
    assert (program, person) == (204, 408)  # docs/lab.md, the task
    assert person >= 2 * program and lab_config(preset("curl"), 1, person=True).time_limit <= MAX_GAME_SECONDS
    slow = LabSession(lab_config(lesson, 1, person=True), lesson)
    pilot, dawdled = Autopilot(slow, make_lab_bot("model")), -1
    while not slow.over:
        if slow.phase == "hold" and slow.trial_index != dawdled:  # 8 s off home before each trial, then home
            dawdled = slow.trial_index
            slow.key_event("k", "down")
            slow.advance(round(8.0 / slow.config.dt))
            slow.key_event("k", "up")
            slow.key_event("space", "down")
            slow.key_event("space", "up")
        pilot.advance(1)
    assert slow.finished and slow.steps > program / slow.config.dt  # past where a program's clock ends
    idle = LabSession(lab_config(THREE, 1), THREE)
    idle.key_event("k", "down")  # the hand never back home: no trial starts
    while not idle.over:
        idle.advance(idle.total_steps)
    _report(idle, argparse.Namespace())
    assert idle.out_of_time and "(its time ran out)" in capsys.readouterr().out


THREE = Protocol("three", (Block("baseline", 2, Perturbation(), 0, "Reach straight."),
                           Block("exposure", 2, Perturbation.make("rotation", angle=30.0), 0, "Keep reaching."),
                           Block("washout", 2, Perturbation(), 0, "Back to normal.")), timeout=1.0)


def key(k, down=True):
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN if down else pygame.KEYUP, key=k))


def test_the_lab_waits_for_space_before_the_first_trial(screen):
    session = LabSession(lab_config(PROTOCOL, 2), PROTOCOL)
    win = LabWindow(session, screen, clock=FakeClock(), fps=0)
    key(pygame.K_d)  # a muscle key does not start the lab, nor reach the arm
    for _ in range(20):
        win.frame(0.1)
    assert win.card is not None and session.steps == 0 and session.timeline == []
    assert "Hold the cursor" in " ".join(win.card.lines) and win.card.prompt == "space starts"
    key(pygame.K_SPACE)
    win.frame(0.1)
    win.frame(0.1)
    assert win.card is None and session.steps > 0


def test_cards_and_paths_stop_the_window_clock_but_never_change_the_trials(screen):
    """A person's window run with its cards and knowledge of results replays headless to the same trials:
    the window only stops between steps, it never changes one."""
    session = LabSession(lab_config(PROTOCOL, 3), PROTOCOL)
    win = LabWindow(session, screen, clock=FakeClock(), fps=0)
    key(pygame.K_SPACE)
    frames, feedback_seen, block_card, pressed = 0, 0, None, None
    while not session.over and frames < 600:
        if session.phase == "reach" and pressed is None:
            key(pygame.K_j)  # a short push in each reach
            pressed = frames
        if pressed is not None and frames == pressed + 3:
            key(pygame.K_j, down=False)
        if session.phase == "hold":
            pressed = None
        if win.feedback is not None and feedback_seen < len(session.outcomes):
            feedback_seen = len(session.outcomes)
            steps = session.steps
            assert steps == session.outcomes[-1].end_step  # stopped exactly at the trial's end
            assert not any(session.held)  # the keys were let go as the clock stopped
            win.frame(0.5)
            assert session.steps == steps and ("off the line" in win.feedback.words or "aimed" in win.feedback.words
                                               or "no reach" in win.feedback.words)
        if win.card is not None and frames > 2:
            block_card = win.card.title
            steps = session.steps
            win.frame(2.0)
            assert session.steps == steps and win.card is not None  # a person's card waits
            key(pygame.K_SPACE)
        win.frame(0.05)
        frames += 1
    assert session.finished and block_card == "Block 2 of 2: keep reaching"
    headless = LabSession(lab_config(PROTOCOL, 3), PROTOCOL)
    headless.play(session.timeline, session.steps)
    assert headless.trial_records() == session.trial_records() and headless.state == session.state
    assert [o.xs for o in headless.outcomes] == [o.xs for o in session.outcomes]


def test_the_end_shows_the_learning_curve_and_where_the_run_was_kept(screen):
    session = LabSession(lab_config(THREE, 4), THREE)
    driver = RealTimeDriver(Autopilot(session, make_lab_bot("model")))
    kept = []
    win = LabWindow(session, screen, clock=FakeClock(), fps=0, driver=driver, mode="AUTOPILOT: model",
                    on_finish=lambda s: kept.append(len(s.outcomes)) or ["Kept in ~/somewhere:", "   trials.csv"])
    frames = 0
    while not win.ended and frames < 400:
        win.frame(0.1)  # a bot's cards go on by themselves
        frames += 1
    win.frame(0.1)
    assert kept == [6]  # kept once, at the end
    curve = win.curve
    assert [b.name for b in curve.blocks] == ["baseline", "exposure", "washout"]
    assert [b.perturbed for b in curve.blocks] == [False, True, False] and len(curve.points) == 6
    assert curve.unit == "deg" and curve.after_effect is not None and curve.after_effect[0] == 5
    from armgame.ui.lab_panels import draw_end

    placed = draw_end(win.renderer, win.screen, win.summary, curve, win.saved, win.help_items())
    texts = [t for t, _ in placed]
    assert "after-effect" in texts and "   trials.csv" in texts and any(t.startswith("Block means") for t in texts)
    rects = [r for _, r in placed]
    from armgame.ui.render import text_heights

    small = text_heights(win.screen.get_size(), win.renderer.text_scale)[2]
    assert small >= 0.025 * win.screen.get_height() - 0.5
    for i, a in enumerate(rects):
        assert win.screen.get_rect().contains(a), placed[i][0]
        assert not any(a.colliderect(b) for b in rects[i + 1:]), placed[i][0]


def test_lab_replay_keys_move_by_trials_and_change_speed(screen):
    from armgame.lab.record import LabTask
    from armgame.ui.lab_window import LabReplay

    recorded = LabSession(lab_config(PROTOCOL, 5), PROTOCOL)
    Autopilot(recorded, make_lab_bot("model")).play()
    task = LabTask.of(recorded)
    source = LabReplay(recorded.config, task.new_session, recorded.timeline, recorded.steps, "Ann")
    win = LabWindow(source.new_session(recorded.config), screen, clock=FakeClock(), fps=0, mode="REPLAY   Ann",
                    replay=source)
    assert win.card is None  # a replay has no cards
    ends = [o.end_step for o in recorded.outcomes]
    key(pygame.K_RIGHT)
    win.frame(0.0)
    assert len(win.session.outcomes) == 1 and win.session.steps == ends[0]
    key(pygame.K_RIGHT)
    win.frame(0.0)
    assert win.session.steps == ends[1]
    key(pygame.K_LEFT)
    win.frame(0.0)
    assert win.session.steps == ends[0] and len(win.session.outcomes) == 1  # back to the previous trial's start
    key(pygame.K_PLUS)
    key(pygame.K_p)
    win.frame(0.5)
    assert win.speed == 2.0 and win.paused and win.session.steps == ends[0]
    key(pygame.K_p)
    win.frame(0.0)
    win.frame(0.1)
    assert win.session.steps == ends[0] + round(0.2 / recorded.config.dt)
    items = win.help_items()
    assert items == ("REPLAY of Ann", "p pause", "-/+ speed", "left/right trial", "F11 fullscreen", "Esc quit")
    while not win.ended:
        key(pygame.K_RIGHT)
        win.frame(0.0)
    assert win.session.trial_records() == recorded.trial_records() and win.curve is not None


def bot_window(screen, protocol, seed=4, **options):
    session = LabSession(lab_config(protocol, seed), protocol)
    driver = RealTimeDriver(Autopilot(session, make_lab_bot("model")))
    return LabWindow(session, screen, clock=FakeClock(), fps=0, driver=driver, mode="AUTOPILOT: model", **options)


def test_the_last_screen_closes_only_on_esc_or_runs_again_on_r(screen):
    """Volunteers press space all run long to pass the cards: one press too many must not close the curve."""
    win = bot_window(screen, THREE)
    for _ in range(400):
        if win.ended:
            break
        win.frame(0.1)
    assert win.ended and win.curve is not None
    assert win.help_items() == ("r run again", "Esc quit")
    for k in (pygame.K_SPACE, pygame.K_RETURN, pygame.K_KP_ENTER):
        key(k)
        win.frame(2.0)
    assert win.running and not win.play_again
    from armgame.ui.lab_panels import draw_end

    texts = [t for t, _ in draw_end(win.renderer, win.screen, win.summary, win.curve, win.saved, win.help_items())]
    assert "r run again    Esc quit" in texts
    key(pygame.K_r)
    win.frame(0.1)
    assert win.play_again and not win.running


def spoken(win):
    """Every text the renderer draws in the next frame."""
    said = []
    text = win.renderer.text

    def spy(words, *args, **kwargs):
        said.append(words)
        return text(words, *args, **kwargs)

    win.renderer.text = spy
    win.frame(0.0)
    win.renderer.text = text
    return said


def test_the_header_names_the_block_of_the_reach_on_screen(screen):
    """The last exposure reach's path is shown as the washout's first trial waits: the header still says
    exposure, the trial shown."""
    win = bot_window(screen, THREE)
    for _ in range(400):
        if win.feedback is not None and win.feedback.outcome.plan.index == 3:
            break
        win.frame(0.05)
    assert win.session.block.name == "washout" and win.feedback.outcome.plan.block_name == "exposure"
    said = spoken(win)
    assert "Trial 4 of 6  -  exposure" in said and not any(t.startswith("Trial") and "washout" in t for t in said)
    assert "Keep reaching." in said  # the instruction of the block shown, not the next one's


def test_the_cards_say_what_to_do_never_what_will_happen(screen):
    from armgame.lab.presets import preset
    from armgame.lab.protocol import DEFAULT_INSTRUCTIONS

    lesson = preset("lesson")
    assert [b.trials for b in lesson.blocks] == [4, 16, 4] and lesson.targets == 4
    short = Protocol("lesson", tuple(Block(b.name, 1, b.perturbation, 0, DEFAULT_INSTRUCTIONS[b.name])
                                     for b in lesson.blocks), targets=4)
    win = bot_window(screen, short)
    cards = []
    for _ in range(400):
        if win.card is not None and (not cards or cards[-1] is not win.card):
            cards.append(win.card)
        if win.ended:
            break
        win.frame(0.1)
    assert [c.title for c in cards] == ["The reaching lab", "Block 2 of 3: keep reaching",
                                        "Block 3 of 3: keep reaching"]
    words = " ".join(" ".join((c.title, *c.lines)) for c in cards).lower()
    for telling in ("normal", "chang", "field", "force", "washout", "exposure", "back"):
        assert telling not in words, telling


def test_a_bots_run_has_a_speed_key_and_plays_the_same_trials(screen):
    headless = LabSession(lab_config(PROTOCOL, 2), PROTOCOL)
    Autopilot(headless, make_lab_bot("model")).play()
    frames = {}
    for speed_ups in (0, 3):
        win = bot_window(screen, PROTOCOL, seed=2)
        assert "-/+ speed" in win.help_items()
        for _ in range(speed_ups):
            key(pygame.K_PLUS)
        win.frame(0.0)
        assert win.speed == 2.0 ** speed_ups
        assert f"{win.speed:g}x" in spoken(win)
        n = 0
        while not win.ended and n < 3000:
            win.frame(1 / 30)
            n += 1
        frames[speed_ups] = n
        assert win.session.trial_records() == headless.trial_records()  # the same steps, only sooner
    # 8x: the reaching, the paths and the cards all go 8 times as fast.
    assert frames[3] < frames[0] / 6
    person = LabWindow(LabSession(lab_config(PROTOCOL, 2), PROTOCOL), screen, clock=FakeClock(), fps=0)
    key(pygame.K_PLUS)
    person.frame(0.0)
    assert person.speed == 1.0 and "-/+ speed" not in person.help_items()  # a person plays at real speed


TINY_TOML = """
name = "tiny"
targets = 4
[[blocks]]
name = "baseline"
trials = 1
[[blocks]]
name = "exposure"
trials = 1
perturbation = "curl"
b = 2.0
"""


def test_r_runs_again_in_the_same_window_and_each_file_is_listed_where_it_is(tmp_path, monkeypatch, capsys):
    """armgame lab --record volunteers/v1.json: the last screen lists the replay under its own folder, the
    run's folder with what is in it; r runs again into v1-2.json and a folder of its own; Esc then quits."""
    from armgame.cli import main
    from armgame.commands.lab import kept_lines

    screens = []

    def play_to_the_end(self, max_frames=None):
        for _ in range(500):
            if self.ended:
                break
            self.frame(0.1)
        screens.append((self.saved, self.screen))
        key(pygame.K_r if len(screens) == 1 else pygame.K_ESCAPE)
        self.frame(0.1)
        assert not self.running
        return self.session

    monkeypatch.setattr(LabWindow, "run", play_to_the_end)
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    monkeypatch.chdir(tmp_path)
    (tmp_path / "volunteers").mkdir()
    (tmp_path / "tiny.toml").write_text(TINY_TOML)
    assert main(["lab", "tiny.toml", "--bot", "model", "--record", "volunteers/v1.json", "--size", "640x480",
                 "--no-figures", "--speed", "8"]) == 0
    out = capsys.readouterr().out
    assert out.count("lab tiny: 2 of 2 trials") == 2
    runs = sorted((tmp_path / "data" / "armgame" / "lab").glob("*_tiny*"))
    assert len(runs) == 2 and screens[0][1] is screens[1][1]  # the window stayed open for the second run
    for (saved, _), replay, folder in zip(screens, ("v1.json", "v1-2.json"), runs, strict=True):
        assert (tmp_path / "volunteers" / replay).is_file() and (folder / "trials.csv").is_file()
        assert list(saved) == [f"Kept in {tmp_path / 'volunteers'}:", f"   {replay}", f"Kept in {folder}:",
                               "   trials.csv"]
    assert main(["verify", "volunteers/v1-2.json"]) == 0
    from armgame.commands.lab import _numbered

    (tmp_path / "run-2").mkdir()
    assert _numbered(tmp_path / "run", 1) == tmp_path / "run" and _numbered(tmp_path / "run", 2) == tmp_path / "run-3"
    home = Path.home()
    assert kept_lines([home / "a" / "r.json", home / "a" / "t.csv"]) == ["Kept in ~/a:", "   r.json   t.csv"]


def test_losing_the_focus_never_stalls_the_run(screen):
    """Issue 39: a volunteer's pointer left the window, the window lost the focus and paused until p, which no
    volunteer is told: the run stood still for 1.5 minutes at trial 3. Now it waits only while the window is away:
    the focus back, or any key, plays on; a key held as it left is let go, in the timeline."""
    session = LabSession(lab_config(PROTOCOL, 2), PROTOCOL)
    win = LabWindow(session, screen, clock=FakeClock(), fps=0)
    start(win)
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_d))
    win.frame(0.05)
    assert session.held[0]
    pygame.event.post(pygame.event.Event(pygame.WINDOWFOCUSLOST))
    win.frame(0.05)
    assert win.paused and win.away and not session.held[0] and session.timeline[-1].action == "up"
    steps = session.steps
    win.frame(0.5)
    assert session.steps == steps  # away: the run waits (the volunteer may be gone)
    pygame.event.post(pygame.event.Event(pygame.WINDOWFOCUSGAINED))
    win.frame(0.05)
    assert not win.paused and session.steps > steps
    # A window manager that never says the focus came back: the first key plays on, and acts.
    pygame.event.post(pygame.event.Event(pygame.WINDOWFOCUSLOST))
    win.frame(0.05)
    steps = session.steps
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_j))
    win.frame(0.05)
    assert not win.paused and session.held[2] and session.steps > steps
    # p, the key the pause panel names, resumes too rather than pausing again.
    pygame.event.post(pygame.event.Event(pygame.WINDOWFOCUSLOST))
    win.frame(0.05)
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_p))
    win.frame(0.05)
    assert not win.paused and not win.away
    # A pause asked for with p is the volunteer's: the focus coming back does not lift it.
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_p))
    pygame.event.post(pygame.event.Event(pygame.WINDOWFOCUSLOST))
    pygame.event.post(pygame.event.Event(pygame.WINDOWFOCUSGAINED))
    win.frame(0.05)
    assert win.paused


def test_a_bots_run_goes_on_without_the_focus(screen):
    session = LabSession(lab_config(PROTOCOL, 2), PROTOCOL)
    win = LabWindow(session, screen, clock=FakeClock(), fps=0, driver=RealTimeDriver(Autopilot(session,
                                                                                               make_lab_bot("model"))),
                    mode="AUTOPILOT: model")
    win.card = None
    pygame.event.post(pygame.event.Event(pygame.WINDOWFOCUSLOST))
    win.frame(0.0)
    steps = session.steps
    win.frame(0.2)
    assert not win.paused and session.steps > steps


def test_a_bots_intro_card_names_the_bot_and_a_replays_says_so(screen):
    """The card says who plays the run from what the window was told (``bot``), never from its help line."""
    from armgame.game.timeline import TimelineDriver

    session = LabSession(lab_config(PROTOCOL, 2), PROTOCOL)
    driver = RealTimeDriver(Autopilot(session, make_lab_bot("model")))
    win = LabWindow(session, screen, clock=FakeClock(), fps=0, driver=driver, mode="AUTOPILOT: model", bot="model")
    assert win.card is not None and win.card.lines[0] == "The model bot plays this run: watch its cursor."
    recorded = LabSession(lab_config(PROTOCOL, 2), PROTOCOL)
    watched = LabSession(lab_config(PROTOCOL, 2), PROTOCOL)
    win = LabWindow(watched, screen, clock=FakeClock(), fps=0, driver=TimelineDriver(watched, recorded.timeline, 0),
                    mode="REPLAY   Ann", cards=True)
    assert win.card is not None and win.card.lines[0] == "A replay plays this run: watch its cursor."


NO_VISION = Protocol("probes", (Block("baseline", 2, Perturbation(), 0, "Reach straight."),
                                Block("endpoint", 4, Perturbation.make("rotation", angle=30.0), 0, "Keep reaching.",
                                      feedback="endpoint"),
                                Block("no vision", 4, Perturbation(), 0, "Reach without the cursor.",
                                      feedback="none")), timeout=1.0)


def test_a_no_vision_probe_says_nothing_of_how_it_ended_and_a_miss_is_called_a_miss(screen):
    """A probe without vision gives no knowledge of results: neither the line under the header while its reach is
    on screen nor the status line after it says hit, miss or time out. A reach that stopped off the target before
    its time ran out (a trial without a cursor) is "missed", not "time out"."""
    win = bot_window(screen, NO_VISION)
    told: dict[int, list[str]] = {}
    for _ in range(2000):
        if win.ended:
            break
        win.frame(0.05)
        if win.feedback is not None and win.feedback.outcome.plan.index not in told:
            index = win.feedback.outcome.plan.index
            shown = spoken(win)
            win.feedback = None  # the path's time on screen over: the status line of the trial before
            told[index] = shown + spoken(win)
    outcomes = win.session.outcomes
    assert sorted(told) == list(range(len(outcomes))) == list(range(10))
    for o in outcomes:
        said = told[o.plan.index]
        if o.plan.feedback == "none":
            assert "last trial: reach done" in said, said
            assert not any(re.search(r"\b(hit|miss|missed|time out)\b", t) for t in said), said
            continue
        ran_out = o.end_step - o.go_step >= win.session.timeout_steps
        word = "hit" if o.hit else "time out" if ran_out else "missed"
        verdicts = [t for t in said if t.startswith(("last trial: ", "hit", "missed", "time out"))]
        assert verdicts and all(t.removeprefix("last trial: ").startswith(word) for t in verdicts), (word, said)
    assert any(not o.hit and o.end_step - o.go_step < win.session.timeout_steps and o.plan.feedback == "endpoint"
               for o in outcomes)  # a miss was met, and named as one
