"""The demo windows' playback clock (``ui.demo_playback.DemoPlayback``), without pygame or a display.

A stand-in run counts its steps and keeps its state as the step count, so each test reads exactly which
steps ran; the clock is a number the test sets, so nothing sleeps (times in 64ths of a second, exact in
binary, so that whole steps are whole).
"""

import subprocess
import sys

import pytest

from armgame.ui.demo_playback import SPEEDS, DemoPlayback
from armgame.ui.playback import MAX_FRAME, SKIP_SECONDS


class CountingRun:
    """One arm whose angles are (steps, -steps): what ran is read off the state."""

    dt = 1 / 64

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        self.steps = 0
        self.states = [(0.0, 0.0, 0.0, 0.0)]
        self.previous = self.states

    @property
    def t(self) -> float:
        return self.steps * self.dt

    def step(self) -> None:
        self.previous = self.states
        self.steps += 1
        self.states = [(float(self.steps), -float(self.steps), 0.0, 0.0)]


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


@pytest.fixture
def played():
    clock = Clock()
    return DemoPlayback(CountingRun(), clock=clock), clock


def test_the_first_frame_only_starts_the_clock_then_real_time_becomes_whole_steps(played):
    playback, clock = played
    playback.advance()
    assert playback.run.steps == 0
    clock.now += 10.5 / 64
    playback.advance()
    assert playback.run.steps == 10 and playback.accumulator == 0.5 / 64
    # Half a step of time left over: the pose lies halfway between the last two states (steps 9 and 10).
    assert playback.poses() == [(9.5, -9.5)]


def test_speed_scales_real_time_and_a_long_frame_counts_as_max_frame(played):
    playback, clock = played
    playback.speed = 0.5
    playback.advance()
    clock.now += 16 / 64
    playback.advance()
    assert playback.run.steps == 8
    playback.speed = 1.0
    clock.now += 60.0  # the window was dragged for a minute
    playback.advance()
    assert playback.run.steps == 8 + round(MAX_FRAME / CountingRun.dt)
    assert 1.0 in SPEEDS and min(SPEEDS) < 1.0 < max(SPEEDS)


def test_a_pause_stops_the_run_and_its_time_is_not_counted_after(played):
    playback, clock = played
    playback.advance()
    playback.toggle_pause()
    clock.now += 32 / 64
    playback.advance()
    assert playback.run.steps == 0 and playback.paused
    playback.toggle_pause()
    playback.advance()  # the first frame after the pause starts the clock again
    clock.now += 5 / 64
    playback.advance()
    assert playback.run.steps == 5


def test_skips_run_forward_at_once_and_back_from_a_snapshot_never_before_the_start(played):
    playback, _ = played
    jumps = playback.jumps
    playback.skip(2 * SKIP_SECONDS)
    steps = round(2 * SKIP_SECONDS / CountingRun.dt)
    assert playback.run.steps == steps and playback.run.states[0][0] == steps
    playback.skip(-SKIP_SECONDS)
    back = steps - round(SKIP_SECONDS / CountingRun.dt)
    assert playback.run.steps == back and playback.run.states[0][0] == back  # the snapshot's state, restored
    playback.skip(-10 * SKIP_SECONDS)
    assert playback.run.steps == 0 and playback.run.states[0][0] == 0.0
    assert playback.jumps == jumps + 3 and playback.accumulator == 0.0


def test_restart_runs_from_the_start_with_a_fresh_clock(played):
    playback, clock = played
    playback.advance()
    clock.now += 12 / 64
    playback.advance()
    assert playback.run.steps == 12
    playback.restart()
    assert playback.run.steps == 0 and playback.last_time is None and playback.accumulator == 0.0
    playback.advance()
    assert playback.run.steps == 0


def test_parting_is_noted_when_the_hands_first_lie_visibly_apart_and_forgotten_on_a_skip_back():
    run = CountingRun()
    playback = DemoPlayback(run, clock=Clock(), hands_apart=lambda: run.steps * 1e-3)
    playback.skip(SKIP_SECONDS)  # 0.32 m apart by then
    assert playback.parted_at == run.t
    playback.skip(-SKIP_SECONDS)
    assert playback.parted_at is None


def test_the_playback_needs_no_pygame():
    code = "import sys, armgame.ui.demo_playback; print('pygame' in sys.modules)"
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True).stdout.strip() == "False"
