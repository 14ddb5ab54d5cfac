"""A demo's playback clock: real time into fixed physics steps, with speed, pause, skip and restart.

No pygame: the demo window (``demo_window``) owns one and asks it, each frame, to catch up with the real
time (``advance``) and for the arms' poses between the last two steps (``poses``); the tests drive it
with a clock of their own and never open a window or sleep.

Physics advances in fixed steps (the run's ``dt``) from an accumulator of real time (``clock``,
``time.perf_counter`` by default), scaled by the playback speed; a frame longer than ``MAX_FRAME`` (a
window dragged, a debugger) counts as ``MAX_FRAME``, so the run never races to catch up. A snapshot of
the run is kept every ``SKIP_SECONDS`` of simulated time, so a skip back restores one and runs at most
``SKIP_SECONDS`` again, however long the demo has run.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any, Protocol

from ..demos.runs import VISIBLY_APART
from .playback import MAX_FRAME, SKIP_SECONDS

#: The playback speeds the speed keys step through.
SPEEDS = (0.125, 0.25, 0.5, 1.0, 2.0, 4.0)


class DemoRun(Protocol):
    """What a demo's run offers the playback (``demos.runs.PassiveRun``, ``demos.reach.ReachRun``,
    ``demos.planning.PlanningRun``): fixed steps of ``dt`` seconds from a state that can be reset, each
    arm's state now (``states``: q1, q2, w1, w2, ...) and before the last step (``previous``)."""

    dt: float
    steps: int
    states: Any
    previous: Any

    @property
    def t(self) -> float: ...

    def reset(self) -> None: ...

    def step(self) -> None: ...


class DemoPlayback:
    """Plays ``run`` at ``speed`` times real time from ``clock``; ``hands_apart`` (the chaos demo's two arms'
    ``hand_distance``): note when it first exceeds ``VISIBLY_APART`` (``parted_at``).

    ``jumps`` counts restarts and skips: what was drawn along the way (the trails) no longer follows."""

    def __init__(self, run: DemoRun, speed: float = 1.0, clock: Callable[[], float] = time.perf_counter,
                 hands_apart: Callable[[], float] | None = None) -> None:
        self.run = run
        self.speed = speed
        self.clock = clock
        self.hands_apart = hands_apart
        self.paused = False
        #: Real time (s, times the speed) not yet stepped, and the clock's reading at the last frame.
        self.accumulator = 0.0
        self.last_time: float | None = None
        #: When the hands parted (s of simulated time), if they have.
        self.parted_at: float | None = None
        self.jumps = 0
        self._snapshots: dict[int, tuple[Any, Any]] = {}

    def restart(self) -> None:
        """The run from its start, the clock afresh."""
        self.run.reset()
        self.accumulator = 0.0
        self.last_time = None
        self.parted_at = None
        self._snapshots = {}
        self.jumps += 1

    def toggle_pause(self) -> None:
        self.paused = not self.paused
        self.last_time = None  # a pause must not count as elapsed time

    def _skip_steps(self) -> int:
        return max(1, round(SKIP_SECONDS / self.run.dt))

    def step(self) -> None:
        """One physics step, keeping a snapshot every SKIP_SECONDS for a skip back to come back to."""
        run = self.run
        if run.steps % self._skip_steps() == 0:
            self._snapshots[run.steps] = (run.states, run.previous)
        run.step()

    def _note_parting(self) -> None:
        if self.hands_apart is not None and self.parted_at is None and self.hands_apart() > VISIBLY_APART:
            self.parted_at = self.run.t

    def skip(self, seconds: float) -> None:
        """``seconds`` of simulated time back (from the last snapshot before; never before the start) or forth
        (run at once)."""
        run = self.run
        target = max(0, run.steps + round(seconds / run.dt))
        if target < run.steps:
            base = max(k for k in self._snapshots if k <= target)  # step 0 is always there once run
            run.states, run.previous = self._snapshots[base]
            run.steps = base
            if self.parted_at is not None and self.parted_at > target * run.dt:
                self.parted_at = None
        while run.steps < target:
            self.step()
        self.accumulator = 0.0
        self.jumps += 1
        self._note_parting()

    def advance(self) -> None:
        """Catch up with the clock: the real time since the last call, times the speed, in whole steps."""
        now = self.clock()
        if self.last_time is None or self.paused:
            self.last_time = now
            return
        elapsed = min(max(now - self.last_time, 0.0), MAX_FRAME)
        self.last_time = now
        self.accumulator += elapsed * self.speed
        dt = self.run.dt
        while self.accumulator >= dt:
            self.step()
            self.accumulator -= dt
        self._note_parting()

    def poses(self) -> list[tuple[float, float]]:
        """Joint angles of each arm, interpolated between the last two physics steps."""
        alpha = min(self.accumulator / self.run.dt, 1.0)
        return [(p[0] + alpha * (c[0] - p[0]), p[1] + alpha * (c[1] - p[1]))
                for p, c in zip(self.run.previous, self.run.states, strict=True)]
