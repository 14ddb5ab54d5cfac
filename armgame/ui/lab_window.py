"""The lab's window: the centre-out task seen as in a reaching experiment, with a class in mind.

As on a manipulandum under a screen, the player sees no arm, only a cursor: the hand as the
task scores it (rotated, mirrored or shown as joint angles when the block says so). The view
is the workspace around home: the home circle, the target when the go cue comes, a trial
counter with the block's name, the block's one-line instruction, and the four muscle bars.

Around the trials, the window teaches: a card before the first trial says what to do and waits
for space; a card before each new block names it and waits again; after each reach its path
stays on screen for about a second with its measure (knowledge of results); at the end the
learning curve is drawn in the window, with where the run was kept. None of this changes a
step: the window stops the session's clock exactly at a trial's end (``TrialGate``) and simply
does not advance it while a card or a path is shown, so the recorded timeline replays headless
to the same trials. A bot's run shows the same, its cards going on by themselves; a replay
(``LabReplay``) shows each path without stopping and has the replay keys: + and - speed, left and
right a trial back or on, p pause.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import pygame

from ..game.rules import GameConfig
from ..game.session import UP, InputEvent, RealTimeDriver
from ..game.timeline import TimelineDriver
from ..lab.analysis import LearningCurve, figure_metric, learning_curve, outcome_word, result_words, trial_rows
from ..lab.session import HOLD, LabSession, TrialOutcome
from ..words import plural
from .frontend import GameWindow, key_name, seek
from .lab_panels import draw_card, draw_end, draw_feedback
from .playback import MAX_FRAME, REPLAY_SPEEDS, skip_sign, speed_after
from .render import GameRenderer, Hud, Viewport, text_heights

CAPTION = "armgame lab - reach from home to each target"
HOME = (0, 114, 178)  # Okabe-Ito blue: told apart from the (vermilion) target by colour-blind players too
HIT = (0, 128, 90)
CURSOR = (0, 0, 0)
#: How long a reach's path stays on screen after it (real seconds; session seconds in a replay).
FEEDBACK_SECONDS = 1.2
#: A bot's cards go on by themselves after this long (a person's wait for space).
BOT_CARD_SECONDS = 2.5
START_KEYS = ("space", "return", "enter")
#: On the last screen: another run (a replay: watched again). Esc alone quits.
RUN_AGAIN = "r"


@dataclass
class Card:
    """A pause between trials that tells what comes next."""

    title: str
    lines: tuple[str, ...]
    prompt: str
    shown_for: float = 0.0


@dataclass
class Feedback:
    """Knowledge of results: a reach's path and its measure, shown after the trial."""

    outcome: TrialOutcome
    words: str
    shown_for: float = 0.0
    at_time: float = 0.0  # session time at the trial's end (a replay's feedback ages in session time)


@dataclass
class LabHud(Hud):
    card: Card | None = None
    feedback: Feedback | None = None
    curve: LearningCurve | None = None
    summary: str = ""
    saved: Sequence[str] = field(default_factory=tuple)
    away: bool = False  # paused because the window lost the focus


class LabRenderer(GameRenderer):
    """Draws one frame of a ``LabSession``; text and fonts cached as the game's renderer does."""

    #: What drives the run: "LAB" (a person at the keys), "AUTOPILOT: NAME", "REPLAY", or "" (a program).
    mode = "LAB"

    def view(self, size: tuple[int, int], session: LabSession, home: tuple[float, float] | None = None) -> Viewport:
        hx, hy = session.home if home is None else home
        span = max(0.08, 1.45 * session.protocol.distance)
        return Viewport.fit(size, (hx - span, hx + span, hy - span, hy + 1.35 * span))

    def draw(self, screen: pygame.Surface, session: LabSession, alpha: float = 1.0,  # type: ignore[override]
             hud: Hud | None = None) -> None:
        hud = hud or Hud()
        lab = hud if isinstance(hud, LabHud) else None
        p = self.palette
        # A reach's path is shown in its own workspace, though the next trial's block may start at another posture.
        shown = lab.feedback.outcome.plan.home if lab is not None and lab.feedback is not None else session.home
        view = self.view(screen.get_size(), session, shown)
        line = max(3, round(min(screen.get_size()) / 240))
        screen.fill(p.scene)
        for x, y in session.protocol.target_positions(shown):
            pygame.draw.circle(screen, p.edge, view.to_screen(x, y), view.length(session.protocol.target_radius), line)
        home = session.home_target
        holding = session.phase == HOLD and not session.over
        pygame.draw.circle(screen, HOME, view.to_screen(home.x, home.y), view.length(home.radius),
                           0 if holding else line)
        feedback = lab.feedback if lab is not None else None
        if feedback is not None:
            draw_feedback(self, screen, view, session, feedback.outcome)
        elif not holding and not session.over:
            target = session.rules.target
            pygame.draw.circle(screen, p.target, view.to_screen(target.x, target.y), view.length(target.radius))
        if feedback is None and session.cursor_visible:  # a trial without vision hides it from the go cue on
            pygame.draw.circle(screen, CURSOR, view.to_screen(*session.cursor), view.length(0.006))
        self._hud(screen, session, hud)
        if lab is not None and lab.curve is not None:
            draw_end(self, screen, lab.summary, lab.curve, lab.saved, hud.help)
        elif lab is not None and lab.card is not None:
            draw_card(self, screen, lab.card.title, lab.card.lines, lab.card.prompt)
        elif hud.paused and not hud.ended:
            self._panel(screen, "Paused", "click here or press a key to play on" if lab is not None and lab.away
                        else "p to play on")
        elif session.over or hud.ended:
            done = len(session.outcomes)
            self._panel(screen, "Done" if session.finished else "Time is up",
                        f"{plural(done, 'trial')}, {plural(session.result().hits, 'hit')}   -   Esc quits")

    def _text_heights(self, screen: pygame.Surface) -> tuple[int, int, int]:
        """Text heights (big, normal, small) for this window: never below the projector minimum."""
        return text_heights(screen.get_size(), self.text_scale)

    def _panel(self, screen: pygame.Surface, title: str, subtitle: str) -> None:
        big, normal, _ = self._text_heights(screen)
        head, sub = self.text(title, big), self.text(subtitle, normal, self.palette.faint)
        pad = normal
        panel = pygame.Rect(0, 0, max(head.get_width(), sub.get_width()) + 2 * pad,
                            head.get_height() + sub.get_height() + 3 * pad)
        panel.center = screen.get_rect().center
        pygame.draw.rect(screen, self.palette.panel, panel, border_radius=pad // 2)
        pygame.draw.rect(screen, self.palette.edge, panel, 3, border_radius=pad // 2)
        screen.blit(head, head.get_rect(midtop=(panel.centerx, panel.top + pad)))
        screen.blit(sub, sub.get_rect(midbottom=(panel.centerx, panel.bottom - pad)))

    def help_line(self, hud: Hud) -> str:
        if hud.help:
            return "    ".join(hud.help)
        keys = self.key_labels
        if self.mode == "LAB":
            return f"{keys[0]}/{keys[1]} shoulder   {keys[2]}/{keys[3]} elbow   space home   p pause   Esc quit"
        if self.mode:  # a bot or a replay drives: the muscle keys do nothing
            return f"{self.mode}   p pause   Esc quit"
        return " "  # frames for a program (the Gymnasium env): no keys at all

    def _hud(self, screen: pygame.Surface, session: LabSession, hud: Hud) -> None:
        p = self.palette
        big, normal, small = self._text_heights(screen)
        margin = small
        plan = session.plan
        total = len(session.plans)
        feedback = hud.feedback if isinstance(hud, LabHud) else None
        number = total if plan is None else plan.index + 1
        block = session.block
        if feedback is not None:  # still the trial just made, and its block (the next may be another)
            number = feedback.outcome.plan.index + 1
            block = session.protocol.blocks[feedback.outcome.plan.block]
        y = margin
        title = self.text(self.fit_text(f"Trial {number} of {total}  -  {block.name}", big,
                                        screen.get_width() - 2 * margin), big)
        screen.blit(title, (margin, y))
        y += title.get_height() + small // 3
        if block.instruction:
            screen.blit(self.text(self.fit_text(block.instruction, normal, screen.get_width() - 2 * margin), normal),
                        (margin, y))
            y += normal + small // 3
        verdict = outcome_word(session, feedback.outcome) if feedback is not None else None
        if feedback is not None and verdict is None:
            screen.blit(self.text(self.fit_text(feedback.words, big, screen.get_width() - 2 * margin), big,
                                  p.faint), (margin, y))
        elif feedback is not None:
            screen.blit(self.text(self.fit_text(f"{verdict}: {feedback.words}", big, screen.get_width() - 2 * margin),
                                  big, HIT if feedback.outcome.hit else p.warn), (margin, y))
        elif session.outcomes:
            last = session.outcomes[-1]
            said = outcome_word(session, last)
            if said is None:  # a probe without vision: not even whether it hit
                line, colour = "last trial: reach done", p.faint
            elif last.hit:
                line, colour = f"last trial: hit, {(last.end_step - last.go_step) * session.config.dt:.2f} s", HIT
            else:
                line, colour = f"last trial: {said}", p.warn
            screen.blit(self.text(line, small, colour), (margin, y))
        if hud.progress is not None or hud.speed is not None:
            shown = f"{hud.progress[0]:.0f} s   " if hud.progress is not None else ""
            speed = f"{hud.speed:g}x" if hud.speed is not None else ""
            status = self.text(f"{shown}{speed}".strip(), small)
            screen.blit(status, status.get_rect(topright=(screen.get_width() - margin, margin)))
        keys = self.key_labels
        help_text = self.text(self.fit_text(self.help_line(hud), small, screen.get_width() - 2 * margin), small,
                              p.faint)
        screen.blit(help_text, (margin, screen.get_height() - help_text.get_height() - margin))
        bar_w, bar_h, gap = 6 * small, small * 2 // 3, small // 2
        bx = screen.get_width() - bar_w - margin
        by = screen.get_height() - help_text.get_height() - 2 * margin - 4 * (bar_h + gap)
        for i, a in enumerate(session.muscles.activation):
            row = by + i * (bar_h + gap)
            label = self.text(keys[i], small)
            screen.blit(label, (bx - label.get_width() - small // 2, row + (bar_h - label.get_height()) // 2))
            pygame.draw.rect(screen, p.bar_back, (bx, row, bar_w, bar_h))
            if a > 0.002:
                pygame.draw.rect(screen, p.muscles[i], (bx, row, max(1.0, bar_w * min(a, 1.0)), bar_h))


class TrialGate:
    """Stands between a ``RealTimeDriver`` and what it advances (the session, or a bot's ``Autopilot``) and
    stops at the end of a trial, so the window can show it before the next one begins.

    It only chooses where a frame's advance stops (``LabSession.steps_before_an_end``): the steps are
    the session's own, so the timeline, and the trials, are those of a run with no stops at all.
    """

    def __init__(self, inner: object, session: LabSession) -> None:
        self.inner = inner
        self.session = session
        self.config = session.config

    def advance(self, n: int) -> int:
        lab, trials, done = self.session, len(self.session.outcomes), 0
        while done < n and not lab.over and len(lab.outcomes) == trials:
            ran = self.inner.advance(min(n - done, lab.steps_before_an_end()))  # type: ignore[attr-defined]
            if ran <= 0:
                break
            done += ran
        return done


@dataclass
class LabReplay:
    """A recorded lab run to watch: how the window starts it afresh, or at any step (to skip back)."""

    config: GameConfig
    new_session: Callable[[GameConfig], LabSession]
    timeline: Sequence[InputEvent]
    stop_step: int
    player: str = "no name"

    def start(self, step: int = 0) -> tuple[LabSession, TimelineDriver]:
        session = self.new_session(self.config)
        driver = TimelineDriver(session, self.timeline, self.stop_step, max_frame_time=MAX_FRAME * max(REPLAY_SPEEDS))
        seek(driver, step)
        return session, driver


class LabWindow(GameWindow):
    """The game window's loop (keys, pause, fullscreen, real-time fixed steps) drawing the lab.

    ``mode``: "LAB" for a person at the keys, else what drives it ("AUTOPILOT: adaptive", "REPLAY   Ann").
    ``replay``: a recorded run, watched with the replay keys. ``on_finish``: called once when the last
    trial is done, with the session; returns the lines that say where the run was kept (shown on the
    end screen). ``cards``: the instruction and block cards (default: on, except in a replay).
    """

    def __init__(self, session: LabSession, screen: pygame.Surface, clock: Callable[[], float] = time.perf_counter,
                 fps: int = 60, driver: RealTimeDriver | None = None, mode: str = "LAB", *,
                 replay: LabReplay | None = None, on_finish: Callable[[LabSession], Sequence[str]] | None = None,
                 cards: bool | None = None, palette: str = "okabe-ito", text_scale: float = 1.0,
                 bot: str | None = None) -> None:
        if replay is not None and driver is None:
            session, driver = replay.start()
        super().__init__(session, screen, clock, fps, driver, ask_name=False, countdown=False, palette=palette)
        #: What drives the run, as the help line and the cards say it ("LAB": the person at the keys).
        self.mode = mode
        #: The bot that plays the run, by name, as its intro card says it (None: a person, or a replay).
        self.bot = bot
        pygame.display.set_caption(CAPTION)
        self.renderer = LabRenderer(session.muscles.keys, tuple(m.name for m in session.config.muscles), palette,
                                    text_scale=text_scale)
        self.renderer.mode = mode
        self.lab_replay = replay
        #: A replay (or any timeline) is watched: no stops, no cards; the replay keys when it is a LabReplay.
        self.watching = isinstance(self.driver, TimelineDriver)
        if not self.watching:
            self.driver.session = TrialGate(self.driver.session, session)  # type: ignore[assignment]
            # At 8x a frame carries 8 frames' steps: the driver's clamp on a stalled frame must allow them.
            self.driver.max_frame_time = MAX_FRAME * max(REPLAY_SPEEDS)
        self.on_finish = on_finish
        self.saved: tuple[str, ...] = ()
        self.curve: LearningCurve | None = None
        self.summary = ""
        self.feedback: Feedback | None = None
        self.seen = len(session.outcomes)
        #: Paused because the window lost the focus (not by p): focus back, or any key, plays on.
        self.away = False
        show_cards = not self.watching if cards is None else cards
        self.card: Card | None = self._intro_card() if show_cards and session.steps == 0 else None
        self.block_cards = show_cards

    # ------------------------------------------------------------------ cards
    def _prompt(self) -> str:
        return "space starts" if self.keyboard else "space goes on (or wait)"

    def _intro_card(self) -> Card:
        s = self.session
        keys = s.muscles.keys
        blocks = s.protocol.blocks
        first = blocks[0]
        # What to do, never what will happen: a volunteer told that something changes, or goes back to
        # normal, reaches differently, and the after-effect the lesson shows shrinks.
        lines = (
            "Hold the cursor (the black dot) in the blue home circle.",
            "Wait for the target; then reach it and hold it there.",
            f"{keys[0]}/{keys[1]} turn the shoulder, {keys[2]}/{keys[3]} the elbow; space brings the hand home.",
            f"{plural(s.protocol.trials, 'trial')} in {plural(len(blocks), 'block')}, a card before each.",
            f"Block 1 of {len(blocks)}: {first.instruction or 'reach each target and hold it.'}",
        )
        if not self.keyboard:
            who = f"The {self.bot} bot" if self.bot else "A replay"
            lines = (f"{who} plays this run: watch its cursor.", *lines[3:])
        return Card("The reaching lab", lines, self._prompt())

    def _block_card(self) -> Card | None:
        s = self.session
        plan = s.plan
        if plan is None or not s.outcomes or s.outcomes[-1].plan.block == plan.block:
            return None
        block = s.protocol.blocks[plan.block]
        lines = (block.instruction,) if block.instruction else ()
        return Card(f"Block {plan.block + 1} of {len(s.protocol.blocks)}: keep reaching",
                    (*lines, f"{plural(block.trials, 'trial')}."), self._prompt())

    @property
    def stopped(self) -> bool:
        """The session's clock is held for a card or a path (never in a replay)."""
        return self.card is not None or (self.feedback is not None and not self.watching)

    # ------------------------------------------------------------------ input
    def help_items(self) -> tuple[str, ...]:
        keys = self.session.muscles.keys
        if self.ended:
            return ("r watch again" if self.lab_replay is not None else "r run again", "Esc quit")
        items: list[str] = []
        if self.keyboard:
            items += [f"{keys[0]}/{keys[1]} shoulder", f"{keys[2]}/{keys[3]} elbow", "space home"]
        elif self.lab_replay is not None:
            items.append(f"REPLAY of {self.lab_replay.player}")
        elif self.mode:
            items.append(self.mode)
        items.append("p pause")
        if self.lab_replay is not None:
            items += ["-/+ speed", "left/right trial"]
        elif not self.keyboard:  # a bot's run: as fast as the class needs it
            items.append("-/+ speed")
        items += ["F11 fullscreen", "Esc quit"]
        return tuple(items)

    def handle(self, event: pygame.event.Event) -> None:
        if event.type == pygame.WINDOWFOCUSLOST:
            self._track(event)
            # The game pauses until p; a lab volunteer knows no p (issue 39: a run stood 1.5 minutes at trial 3
            # after the pointer left the window). A person's keys are let go (the releases would go elsewhere)
            # and the run waits only while the window is away; a bot's or a replay's runs on.
            if self.keyboard and not self.finished and not self.paused:
                self.set_paused(True)
                self.away = True
            return
        if event.type == pygame.WINDOWFOCUSGAINED:
            if self.away:
                self.away = False
                self.set_paused(False)
            return
        if event.type == pygame.KEYDOWN and self.away:
            # Keys reach the window again: the focus is back, whatever the window manager said.
            self.away = False
            self.set_paused(False)
            if key_name(event) == "p":
                return  # the key a volunteer was told for the pause: it resumes, it does not pause again
        if event.type == pygame.KEYDOWN:
            name = key_name(event)
            if self.card is not None and name in START_KEYS:
                self.card = None
                return
            if self.ended:
                # Only Esc (in GameWindow) closes the last screen: a volunteer presses space all run long
                # to pass the cards, and one press too many would close the curve the class came to see.
                if name == RUN_AGAIN:
                    self._run_again()
                    return
                if name in START_KEYS:
                    return
            if self.lab_replay is not None and self._lab_replay_key(name):
                return
            if not self.keyboard and self.lab_replay is None and (speed := speed_after(name, self.speed)) is not None:
                self.speed = speed  # a bot's run: its steps are the same at any speed, only sooner
                return
            if self.stopped and name not in ("escape", "f11", "p"):
                return  # a card or a path on screen: keys are not game input
        elif event.type == pygame.KEYUP and self.stopped:
            return  # the keys were released when the clock stopped
        super().handle(event)

    def _run_again(self) -> None:
        """r on the last screen: a replay is watched again from its start; a run ends, asking the command
        for another (``play_again``), which keeps this one first."""
        if self.lab_replay is None:
            self.play_again = True
            self.running = False
            return
        self.session, self.driver = self.lab_replay.start(0)  # type: ignore[assignment]
        self.ended = False
        self.curve = None
        self.seen = 0
        self.feedback = None
        self.hits.clear()

    def _lab_replay_key(self, name: str) -> bool:
        if (speed := speed_after(name, self.speed)) is not None:
            self.speed = speed
        elif skip_sign(name):
            self.skip_trials(skip_sign(name))
        else:
            return False
        return True

    def skip_trials(self, by: int) -> None:
        """A replay shown from the start of the next trial (``by`` 1) or of the previous one (-1)."""
        assert self.lab_replay is not None
        s = self.session
        if by < 0:
            current = len(s.outcomes)  # the trial under way (or the one about to start)
            back = max(current - 1, 0)
            step = s.outcomes[back - 1].end_step if back > 0 else 0
            self.session, self.driver = self.lab_replay.start(step)  # type: ignore[assignment]
            self.ended = False
        else:
            driver: TimelineDriver = self.driver  # type: ignore[assignment]
            trials = len(s.outcomes)
            while len(s.outcomes) == trials and not driver.done and not s.over:
                driver.input.run_to(s, s.steps + s.steps_before_an_end())
            seek(driver, s.steps)
        self.seen = len(self.session.outcomes)
        self.feedback = None
        self.hits.clear()
        self.alpha = 1.0

    def _stop_the_clock(self) -> None:
        """Keys held as a trial ends are let go (recorded in the timeline), as a pause does."""
        if self.keyboard:
            for key, held in zip(self.session.muscles.keys, self.session.held, strict=True):
                if held:
                    self.session.key_event(key, UP)

    # ------------------------------------------------------------------ frames
    def _after_steps(self) -> None:
        s = self.session
        if len(s.outcomes) <= self.seen:
            return
        self.seen = len(s.outcomes)
        last = s.outcomes[-1]
        # Knowledge of results only as the trial gives it: none on a trial without vision (issue 41).
        words = "reach done" if last.plan.feedback == "none" else result_words(s, last)
        self.feedback = Feedback(last, words, at_time=last.end_step * s.config.dt)
        if not self.watching:
            self._stop_the_clock()

    def _tick(self, elapsed: float) -> None:
        """Cards and paths age (in real time, sped up with a bot's run; a replay's paths in its own time)."""
        if not self.keyboard:
            elapsed *= self.speed
        if self.card is not None:
            self.card.shown_for += elapsed
            if not self.keyboard and self.card.shown_for >= BOT_CARD_SECONDS:
                self.card = None
            return
        if self.feedback is None:
            return
        if self.watching:
            age = self.session.time - self.feedback.at_time
            if not 0.0 <= age < FEEDBACK_SECONDS:
                self.feedback = None
            return
        self.feedback.shown_for += elapsed
        if self.feedback.shown_for >= FEEDBACK_SECONDS:
            self.feedback = None
            if self.block_cards:
                self.card = self._block_card()

    def _finish(self) -> None:
        """The run is over: the learning curve, and the run kept (once)."""
        s = self.session
        rows = trial_rows(s)
        self.curve = learning_curve(rows, figure_metric(s.protocol))
        self.summary = f"{s.protocol.name}: {plural(len(s.outcomes), 'trial')}, {plural(s.result().hits, 'hit')}" \
            f"{s.ending}"
        if self.on_finish is not None:
            self.renderer.draw(self.screen, s, 1.0, self._lab_hud(saving=True))
            pygame.display.flip()
            self.saved = tuple(self.on_finish(s))

    def _lab_hud(self, saving: bool = False) -> LabHud:
        hud = self.hud()
        if not self.keyboard and hud.speed is None:  # a bot's run or a replay: the speed the keys set
            hud.speed = self.speed
        saved = ("saving the run ...",) if saving else self.saved
        return LabHud(**{f: getattr(hud, f) for f in Hud.__dataclass_fields__}, card=self.card,
                      feedback=self.feedback, curve=self.curve, summary=self.summary, saved=saved, away=self.away)

    def frame(self, elapsed: float) -> None:
        """Handle pending events; advance physics by ``elapsed`` real seconds unless a card, a path or the
        pause holds it; draw."""
        for event in pygame.event.get():
            self.handle(event)
        if self.finished:
            if not self.ended:
                self._end(0.0)
                self.feedback = None
                self._finish()
            else:
                self._end(elapsed)
        elif self.paused:
            pass
        elif self.stopped:
            self._tick(elapsed)
        else:
            self._advance(elapsed)
            self._after_steps()
            if self.watching:
                self._tick(elapsed)
        self.screen = pygame.display.get_surface() or self.screen
        self.renderer.draw(self.screen, self.session, self.alpha, self._lab_hud())
        pygame.display.flip()
