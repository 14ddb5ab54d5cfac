"""A recorded input timeline as an input source: for replays, headless or in real time.

``GameSession.play`` runs a game from a timeline with no clock; ``TimelineDriver`` does the
same paced by real elapsed time, for a window that only draws. Both feed the timeline through
``TimelineInput``, applying each event after exactly ``event.step`` physics steps, so a replay
watched in a window ends in the same state, bit for bit, as the headless one.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from .session import GameSession, InputEvent, RealTimeDriver, TimelineInput


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
