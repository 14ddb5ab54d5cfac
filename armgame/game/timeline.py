"""A recorded input timeline as an input source: for replays, headless or in real time.

``play_timeline`` runs a game from a timeline with no clock; ``TimelineDriver`` does the
same paced by real elapsed time, for a window that only draws. Both apply each event after
exactly ``event.step`` physics steps, as ``GameSession.play`` does, so a replay watched in a
window ends in the same state, bit for bit, as the headless one.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from .session import GameResult, GameSession, InputEvent, RealTimeDriver


class TimelineInput:
    """Feeds a sorted timeline into a session up to a given step, remembering where it is."""

    def __init__(self, events: Sequence[InputEvent], stop_step: int | None = None) -> None:
        self.events = list(events)
        self.index = 0
        self.stop_step = stop_step

    def run_to(self, session: GameSession, step: int) -> None:
        """Advance ``session`` to ``step`` (or its end, or ``stop_step``), applying due events."""
        limit = min(step, session.total_steps if self.stop_step is None else self.stop_step)
        events = self.events
        while self.index < len(events) and events[self.index].step <= limit:
            event = events[self.index]
            session.advance(event.step - session.steps)
            session.key_event(event.key, event.action)
            self.index += 1
        session.advance(limit - session.steps)

    @property
    def finished(self) -> bool:
        return self.index >= len(self.events)


def play_timeline(session: GameSession, events: Sequence[InputEvent], stop_step: int | None = None) -> GameResult:
    """Play a game from its timeline with no clock, up to ``stop_step`` (default: the end).

    A game quit early stops at ``stop_step``: the arm could still drift onto a target
    afterwards, so playing on to the clock's end would not reproduce its result.
    """
    TimelineInput(events, stop_step).run_to(session, session.total_steps)
    return session.result()


class TimelineDriver(RealTimeDriver):
    """A ``RealTimeDriver`` whose input comes from a timeline instead of the keyboard."""

    def __init__(self, session: GameSession, events: Sequence[InputEvent], stop_step: int | None = None,
                 max_frame_time: float = 0.25) -> None:
        super().__init__(session, max_frame_time)
        self.input = TimelineInput(events, stop_step)
        self.stop_step = session.total_steps if stop_step is None else min(stop_step, session.total_steps)

    @property
    def done(self) -> bool:
        return self.session.steps >= self.stop_step

    def advance(self, elapsed: float) -> float:
        # The clock arithmetic of RealTimeDriver.advance, with the timeline applied on the way.
        dt = self.session.config.dt
        self.clock += min(max(elapsed, 0.0), self.max_frame_time)
        due = math.floor(self.clock / dt + 1e-9)
        self.input.run_to(self.session, self.session.steps + (due - self.steps_taken))
        self.steps_taken = due
        if self.done:
            return 1.0
        return min(max(self.clock / dt - due, 0.0), 1.0)
