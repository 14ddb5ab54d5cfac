"""The game window: keyboard in, frames and sounds out, physics at its own fixed rate.

Real elapsed time comes from ``time.perf_counter`` (injectable for tests), never from
``pygame.time.Clock``, which sleeps to whole milliseconds; the clock only caps the frame
rate. Keys become session events at the physics step they arrive before.

Everything the window adds to the game (the 3-2-1 countdown, a hit's flash and "+1", sounds,
the trail, the pause panel, the end screen) only reads the session: the game's timeline, and so
its result, are the same as a headless run of that timeline. The countdown runs before the
game's clock starts, and its keys are not game input.
"""

from __future__ import annotations

import math
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import pygame

from ..game.rules import GameConfig
from ..game.session import DOWN, UP, GameSession, InputEvent, RealTimeDriver
from ..game.timeline import TimelineDriver
from ..physics.hand import hand_xy
from .display import open_window as _open_window
from .display import toggle_fullscreen
from .loop import run_loop
from .names import TextRenderer
from .playback import MAX_FRAME, PLAYBACK_HELP, REPLAY_SPEEDS, SKIP_SECONDS, skip_sign, speed_after
from .render import PLUS_ONE_TIME, Hud, Standing
from .settings import MIN_SIDE, Settings, SettingsError
from .settings import load as load_settings
from .settings import save as save_settings

CAPTION = "armgame - hit the targets with the hand"
DEFAULT_SIZE = (1200, 800)
NAME_LENGTH = 24
#: Keys still being mashed as the clock runs out must not type themselves into the name, nor play
#: again before the player has seen the end screen: nothing typed in its first NAME_ENTRY_DELAY
#: seconds counts, and a key held at the buzzer (or pressed in those first moments) types nothing,
#: its repeats included, until it is let go.
NAME_ENTRY_DELAY = 0.5
END_KEY_DELAY = 0.8
ENTER = ("return", "enter")
COUNTDOWN = 3
TRAIL_SECONDS = 1.0


def open_window(size: tuple[int, int] | None = DEFAULT_SIZE, fullscreen: bool = False,
                caption: str = CAPTION) -> pygame.Surface:
    """The game's window, fitted to the desktop (see ``armgame.ui.display``)."""
    return _open_window(size, fullscreen, caption, DEFAULT_SIZE)


class SoundPlayer(Protocol):
    """What the window needs of its sounds (``armgame.ui.sound.Sounds``; the tests pass a recorder)."""

    available: bool
    muted: bool

    def play(self, name: str) -> None: ...

    def toggle(self) -> bool: ...


def key_name(event: pygame.event.Event) -> str:
    return pygame.key.name(event.key).lower()


@dataclass
class ReplaySource:
    """A recorded game to watch: its configuration, its timeline and where it stopped."""

    config: GameConfig
    timeline: Sequence[InputEvent]
    stop_step: int
    player: str | None = None  # named on the help line: whose game is being watched

    def start(self, step: int = 0) -> tuple[GameSession, TimelineDriver]:
        """A fresh session replayed to ``step`` at once: how the window skips back, deterministically."""
        session = GameSession(self.config)
        # Sped up, a frame covers up to 8 times the usual stall limit: the window clamps real time itself.
        driver = TimelineDriver(session, self.timeline, self.stop_step, max_frame_time=MAX_FRAME * max(REPLAY_SPEEDS))
        seek(driver, step)
        return session, driver


def seek(driver: TimelineDriver, step: int) -> None:
    """Run the driver's session forward to ``step`` (no further than the recording) with no clock."""
    session = driver.session
    driver.input.run_to(session, max(step, session.steps))
    driver.steps_taken = session.steps
    driver.clock = session.steps * session.config.dt


class GameWindow:
    """Runs one game in a window until the player quits; ``run`` returns the session.

    ``driver``: the input when it is not the keyboard (a bot or a replay's timeline; keys then only
    pause and quit). ``replay``: a recorded game, which adds speed and skip keys. ``standing``: called
    once, with the name typed on the end screen (or None when none is asked), to keep the game and
    return the table's standing to show; ``preview``: called when the end screen opens to ask a
    name, returns where the score would stand without entering it, so that rank and table show at
    once (the command passes both in: the window knows nothing of score files). On the end screen,
    Enter saves the name, then Enter again sets ``play_again`` and closes (a replay: watches again).
    ``driven_by`` and ``details`` say what is on screen (``Hud``'s ``driver`` and ``details``: None and
    ("seed 10",) for the player's game, "AUTOPILOT: model", "REPLAY" and ("Ann", "2026-11-22 14:03"));
    ``countdown`` puts 3-2-1 before the clock (never for a replay); ``sounds`` plays hit, reset, tick, go
    and end; ``on_mute`` hears the m key (to persist it); ``trail`` keeps the hand's last second for drawing.
    """

    def __init__(
        self,
        session: GameSession,
        screen: pygame.Surface,
        clock: Callable[[], float] = time.perf_counter,
        fps: int = 60,
        driver: RealTimeDriver | None = None,
        ask_name: bool = False,
        *,
        driven_by: str | None = None,
        details: Sequence[str] = (),
        countdown: bool = True,
        sounds: SoundPlayer | None = None,
        trail: bool = False,
        palette: str = "okabe-ito",
        standing: Callable[[str | None], Standing | None] | None = None,
        on_mute: Callable[[bool], None] | None = None,
        replay: ReplaySource | None = None,
        preview: Callable[[], Standing | None] | None = None,
    ) -> None:
        self.session = session
        self.screen = screen
        self.clock = clock
        self.fps = fps
        self.replay = replay
        if replay is not None and driver is None:
            session, driver = replay.start()
            self.session = session
        # A driver given from outside (a bot, a replay's timeline) is the only input: keys just pause and quit.
        self.keyboard = driver is None
        self.driver = driver or RealTimeDriver(session)
        #: The name typed on the end screen while it is being typed (None: no prompt), and once confirmed.
        self.name_entry: str | None = None
        self.player_name: str | None = None
        self.ask_name = ask_name
        self.driven_by, self.details = driven_by, tuple(details)
        self.sounds = sounds
        self.trail_on = trail
        self.standing_of = standing
        self.preview = preview
        self.standing: Standing | None = None
        #: Enter on the finished game's end screen: the command starts the next game with the same options.
        self.play_again = False
        #: Keys down now (from the events seen), and those that may not type into the name until let go.
        self._down: set[int] = set()
        self._blocked: set[int] = set()
        self.on_mute = on_mute
        self.ended = False
        self._over_for = 0.0
        names = tuple(m.name for m in session.config.muscles)
        # Any script: a student's name on the end screen and in the standings (names.TextRenderer).
        self.renderer = TextRenderer(session.muscles.keys, names, palette)
        self.paused = False
        self.running = True
        self.fullscreen = bool(screen.get_flags() & pygame.FULLSCREEN)
        self.windowed_size = DEFAULT_SIZE if self.fullscreen else screen.get_size()
        self.resized = False
        self.alpha = 1.0
        self.speed = 1.0
        self.countdown_left: float | None = float(COUNTDOWN) if countdown and replay is None else None
        self._last_count: int | None = None
        self.hits: list[tuple[float, float, float]] = []  # x, y (m), game time of the hit
        self.trail: deque[tuple[float, float, float]] = deque()

    # ------------------------------------------------------------------ input
    @property
    def finished(self) -> bool:
        """The game is over, or the replay has shown all that was recorded."""
        if self.session.over:
            return True
        return isinstance(self.driver, TimelineDriver) and self.driver.done

    def help_items(self) -> tuple[str, ...]:
        keys = self.session.muscles.keys
        items: list[str] = []
        if self.keyboard:
            items += [f"{keys[0]}/{keys[1]} shoulder", f"{keys[2]}/{keys[3]} elbow",
                      f"space reset (-{self.session.config.reset_cost})", "tab hide arm"]
        if self.replay is not None:
            items.insert(0, f"watching {self.replay.player}'s game" if self.replay.player else "watching a game")
        items.append("p resume" if self.paused else "p pause")
        if self.replay is not None:
            items += list(PLAYBACK_HELP)
        if self.sounds is not None and getattr(self.sounds, "available", False) and self._mute_key_free():
            items.append("m unmute" if self.sounds.muted else "m mute")
        items += ["F11 fullscreen", "Esc quit"]
        return tuple(items)

    def _mute_key_free(self) -> bool:
        return not (self.keyboard and "m" in self.session.muscles.keys)

    def handle(self, event: pygame.event.Event) -> None:
        self._track(event)
        if event.type == pygame.QUIT:
            self.close()
        elif event.type == pygame.VIDEORESIZE and not self.fullscreen:
            # SDL also reports the size a window opens at, or comes back to from fullscreen: not a change.
            if (event.w, event.h) != self.windowed_size:
                self.windowed_size = (event.w, event.h)
                self.resized = True
        elif self.name_entry is not None and event.type in (pygame.TEXTINPUT, pygame.KEYDOWN):
            self._type_name(event)
        elif event.type == pygame.KEYDOWN:
            self._key_down(event)
        elif event.type == pygame.KEYUP and not self.paused and self.keyboard and self.countdown_left is None:
            self.session.key_event(key_name(event), UP)
        elif event.type == pygame.WINDOWFOCUSLOST and not self.finished:
            self.set_paused(True)

    def _track(self, event: pygame.event.Event) -> None:
        """Which keys are held, and which of them are the game's (held at the buzzer, or mashed as the
        end screen opens): those type nothing into the name, repeats included, until released."""
        if event.type == pygame.KEYDOWN:
            self._down.add(event.key)
            if self.name_entry is not None and self._over_for < NAME_ENTRY_DELAY:
                self._blocked.add(event.key)
        elif event.type == pygame.KEYUP:
            self._down.discard(event.key)
            self._blocked.discard(event.key)
        elif event.type == pygame.WINDOWFOCUSLOST:  # the releases go elsewhere
            self._down.clear()
            self._blocked.clear()

    @property
    def typing(self) -> bool:
        """The name box takes keys: the end screen has been up a moment and no game key is still held."""
        return self.name_entry is not None and self._over_for >= NAME_ENTRY_DELAY and not self._blocked

    def _key_down(self, event: pygame.event.Event) -> None:
        name = key_name(event)
        if name == "escape":
            self.running = False
        elif name == "f11":
            self._toggle_fullscreen()
        elif self.ended:
            self._end_key(name)
        elif name == "m" and self.sounds is not None and self._mute_key_free():
            muted = self.sounds.toggle()
            if self.on_mute is not None:
                self.on_mute(muted)
        elif self.countdown_left is not None:
            self.countdown_left = None  # any other key skips the countdown, and is not game input
            self._play("go")
        elif self.keyboard and not self.paused and name in self.session.muscles.keys:
            self.session.key_event(name, DOWN)
        elif name == "p":
            self.set_paused(not self.paused)
        elif self.replay is not None:
            self._replay_key(name)
        elif not self.paused and self.keyboard:
            self.session.key_event(name, DOWN)

    def _replay_key(self, name: str) -> None:
        speed = speed_after(name, self.speed)
        if speed is not None:
            self.speed = speed
        elif skip_sign(name):
            self.skip_to(self.session.steps + round(SKIP_SECONDS / self.session.config.dt) * skip_sign(name))

    def _end_key(self, name: str) -> None:
        """The end screen: Enter plays again (a replay: watches again); a replay's keys still move it."""
        if name in ENTER and self._over_for >= END_KEY_DELAY:
            if self.replay is not None:
                self.skip_to(0)
            else:
                self.play_again = True
                self.running = False
        elif self.replay is not None:
            self._replay_key(name)

    def skip_to(self, step: int) -> None:
        """Show the replay at ``step``: forward by running on, back by replaying from the start."""
        assert self.replay is not None
        step = min(max(step, 0), self.replay.stop_step)
        if step < self.session.steps:
            self.session, self.driver = self.replay.start(step)
            self.hits.clear()
        else:
            seek(self.driver, step)  # type: ignore[arg-type]
        self.trail.clear()
        self.alpha = 1.0
        if not self.finished:  # skipped back from the end: the replay plays on
            self.ended = False

    def _type_name(self, event: pygame.event.Event) -> None:
        if event.type == pygame.TEXTINPUT:
            if self.typing:
                typed = "".join(c for c in event.text if c.isprintable())
                self.name_entry = (self.name_entry + typed)[:NAME_LENGTH]
            return
        name = key_name(event)
        if name == "escape":
            self.running = False
        elif name == "f11":
            self._toggle_fullscreen()
        elif not self.typing:
            return
        elif name == "backspace":
            self.name_entry = self.name_entry[:-1]
        elif name in ENTER and self.name_entry.strip():
            self.player_name = self.name_entry.strip()
            self.name_entry = None
            pygame.key.stop_text_input()
            self._over_for = 0.0
            self._show_standing(self.player_name)

    def set_paused(self, paused: bool) -> None:
        if paused and self.keyboard:
            # A key released while paused (or while the window is away) would otherwise stay held.
            for key, held in zip(self.session.muscles.keys, self.session.held, strict=True):
                if held:
                    self.session.key_event(key, UP)
        self.paused = paused

    def _toggle_fullscreen(self) -> None:
        self.screen = toggle_fullscreen(self.windowed_size)
        self.fullscreen = bool(self.screen.get_flags() & pygame.FULLSCREEN)

    def _play(self, name: str) -> None:
        if self.sounds is not None:
            self.sounds.play(name)

    def _show_standing(self, name: str | None) -> None:
        if self.standing_of is not None:
            self.standing = self.standing_of(name)

    # ------------------------------------------------------------------ frames
    def _count_down(self, elapsed: float) -> None:
        self.countdown_left -= max(elapsed, 0.0)
        if self.countdown_left <= 0.0:
            self.countdown_left = None
            self._play("go")
            return
        number = math.ceil(self.countdown_left)
        if number != self._last_count:
            self._last_count = number
            self._play("tick")

    def _advance(self, elapsed: float) -> None:
        session = self.session
        board = session.rules.board
        hits, resets, target = board.hits, board.resets, session.rules.target
        self.alpha = self.driver.advance(min(max(elapsed, 0.0), MAX_FRAME) * self.speed)
        if board.hits > hits:
            # A task that keeps no hit times (the lab) still flashes where the target was.
            self.hits.append((target.x, target.y, board.hit_times[-1] if board.hit_times else session.time))
            self._play("hit")
        if board.resets > resets:
            self._play("reset")

    def _end(self, elapsed: float) -> None:
        self.alpha = 1.0
        self._over_for += elapsed
        if self.ended:
            return
        self.ended = True
        self._over_for = 0.0
        self._play("end")
        if self.ask_name and self.player_name is None and self.session.over:
            self.name_entry = ""
            self._blocked = set(self._down)  # held at the buzzer: typing waits for their release
            pygame.key.start_text_input()
            if self.preview is not None:
                self.standing = self.preview()
        else:
            self._show_standing(None)

    def hud(self) -> Hud:
        if self.standing is not None and self.standing.later is not None:
            self.standing = self.standing.later() or self.standing
        now = self.session.time
        self.hits = [h for h in self.hits if 0.0 <= now - h[2] < PLUS_ONE_TIME]
        hud = Hud(driver=self.driven_by, details=self.details, help=self.help_items(), paused=self.paused,
                  countdown=None if self.countdown_left is None else math.ceil(self.countdown_left),
                  name_entry=self.name_entry, name_limit=NAME_LENGTH, standing=self.standing, ended=self.ended,
                  end_hint=self._end_hint(),
                  hits=[(x, y, now - t) for x, y, t in self.hits],
                  trail=[(x, y) for _, x, y in self.trail])
        if self.replay is not None:
            dt = self.session.config.dt
            hud.progress = (self.session.steps * dt, self.replay.stop_step * dt)
            hud.speed = self.speed
        return hud

    def _end_hint(self) -> str:
        """The end screen's keys, as actions."""
        if self.name_entry is not None:
            return "Enter saves    Esc quits (the game's replay is kept)"
        if self.replay is not None:
            return f"Enter watches again    left/right {SKIP_SECONDS:g} s    Esc quits"
        return "Enter plays again    Esc quits"

    def _update_trail(self) -> None:
        if not self.trail_on:
            return
        arm = self.session.config.arm
        q1, q2 = self.session.interpolated_angles(self.alpha)
        now = (self.session.steps - 1 + self.alpha) * self.session.config.dt
        x, y = hand_xy(arm.l1, arm.l2, q1, q2)
        if not self.trail or self.trail[-1][0] < now:
            self.trail.append((now, x, y))
        while self.trail and self.trail[0][0] < now - TRAIL_SECONDS:
            self.trail.popleft()

    def frame(self, elapsed: float) -> None:
        """Handle pending events, advance physics by ``elapsed`` real seconds, draw."""
        for event in pygame.event.get():
            self.handle(event)
        if self.finished:
            self._end(elapsed)
        elif self.countdown_left is not None:
            self._count_down(0.0 if self.paused else elapsed)
        elif not self.paused:
            self._advance(elapsed)
            if self.finished:
                self._end(0.0)
        self._update_trail()
        self.screen = pygame.display.get_surface() or self.screen
        self.renderer.draw(self.screen, self.session, self.alpha, self.hud())
        pygame.display.flip()

    def run(self, max_frames: int | None = None) -> GameSession:
        run_loop(self.frame, lambda: self.running, fps=self.fps, max_frames=max_frames, clock=self.clock,
                 on_interrupt=self.close)
        return self.session

    def close(self) -> None:
        """End the window at the end of this frame, as its close button does (Ctrl-C in the terminal calls it)."""
        self.running = False


@dataclass
class NextGame:
    """What the command hands the window for one more game (Enter on the end screen)."""

    session: GameSession
    driver: RealTimeDriver | None = None
    standing: Callable[[str | None], Standing | None] | None = None
    preview: Callable[[], Standing | None] | None = None


def play_window(session: GameSession, settings: Settings, settings_path: Path, *, fullscreen: bool = False,
                fps: int = 60, driver: RealTimeDriver | None = None, ask_name: bool = False, trail: bool = False,
                standing: Callable[[str | None], Standing | None] | None = None,
                driven_by: str | None = None, details: Sequence[str] = (), replay: ReplaySource | None = None,
                caption: str = CAPTION,
                preview: Callable[[], Standing | None] | None = None,
                next_game: Callable[[GameWindow], NextGame | None] | None = None) -> GameWindow:
    """Open the window, play until the player quits, close it; returns the last game's window.

    ``settings`` (``armgame.ui.settings.Settings``) give the size, palette and mute; a change made in
    the window (m, a resize) is written back to ``settings_path``, re-read first so that an edit made
    meanwhile is kept. Sounds play only if the mixer opens. When the player asks to play again,
    ``next_game`` is given the finished window (the command keeps that game) and returns the next
    game, played in the same window with the same options (None: no more games).
    """
    import sys

    from .sound import Sounds

    def remember(**changes: object) -> None:
        try:
            current, _ = load_settings(settings_path)
            save_settings(current.with_changes(**changes), settings_path)
        except SettingsError as exc:
            print(f"armgame: settings not saved: {exc}", file=sys.stderr)

    screen = open_window(settings.size, fullscreen, caption)
    sounds = Sounds(muted=settings.mute)
    try:
        game: NextGame | None = NextGame(session, driver, standing, preview)
        resized = False
        while game is not None:
            window = GameWindow(game.session, screen, fps=fps, driver=game.driver, ask_name=ask_name,
                                driven_by=driven_by, details=details,
                                sounds=sounds, trail=trail, palette=settings.palette, standing=game.standing,
                                preview=game.preview, on_mute=lambda muted: remember(mute=muted), replay=replay)
            window.renderer.text_scale = settings.text_scale
            window.run()
            screen = window.screen
            resized = resized or window.resized
            game = next_game(window) if window.play_again and next_game is not None else None
        if resized:
            w, h = window.windowed_size
            remember(size=(max(MIN_SIDE, w), max(MIN_SIDE, h)))
    finally:
        sounds.close()
        pygame.display.quit()
    return window
