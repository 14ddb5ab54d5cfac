"""The fixed-step game session: physics, muscles and rules driven from any input source.

The session knows nothing of windows or clocks. It advances in whole physics steps, and
input events take effect at the start of a given step, so a game is fully determined by
its configuration and its input timeline: a headless script, the keyboard in a window and
a replay all produce the same result from the same timeline, bit for bit, whatever the
frame rate or the machine's load. ``RealTimeDriver`` turns real elapsed time into steps for
the window.
"""

from __future__ import annotations

import functools
import math
import struct
from collections.abc import Callable, Iterable, Sequence
from dataclasses import asdict, dataclass
from types import ModuleType

from .. import __version__
from .._native import load, speaks
from ..errors import UserError
from ..limits import MAX_EVENTS
from ..physics.hand import hand_xy
from ..physics.integrators import _SIXTH, Integrator
from ..physics.params import TwoJointParams
from ..physics.trig import sin_cos
from ..physics.twojoint import TwoJointArm
from .muscles import MuscleLevelError, MuscleSet
from .rules import GameConfig, GameRules

#: The calling convention of ``_ckernel.c`` this package speaks: this module's one game and
#: ``batch/compiled.py``'s batches. A build of another (a stale ``.so``) is not used.
KERNEL_VERSION = 7
#: How many doubles the kernel's params hold (its P_* enum).
KERNEL_PARAMS = 26


def speaks_our_convention(module: object) -> bool:
    """Whether a built ``_ckernel`` is the one this package calls (not a stale build of another)."""
    return speaks(module, KERNEL_VERSION, PARAMS=KERNEL_PARAMS)


def compiled_kernel() -> ModuleType | None:
    """``armgame.game._ckernel`` where built and speaking ``KERNEL_VERSION`` (else None): the one way this
    game, the batch's wrapper (``batch/compiled.py``) and the benchmark load it."""
    return load("armgame.game._ckernel", KERNEL_VERSION, PARAMS=KERNEL_PARAMS)


#: The compiled loops (setup.py builds them where a C compiler is found), or None: the Python loop runs.
_ckernel = compiled_kernel()
_c_game_steps = None if _ckernel is None else _ckernel.game_steps
_c_rk4_step = None if _ckernel is None else _ckernel.rk4_step


def kernel_params(model: TwoJointArm, dt: float, shoulder: Sequence[float], elbow: Sequence[float],
                  radius: float = 0.0, near: float = 0.0, reach: tuple[float, float] = (0.0, 0.0),
                  limit2: float = 0.0) -> list[float]:
    """The kernel's params in the order of ``_ckernel.c``'s P_* enum: the arm, dt and the muscles'
    moment arms (``shoulder``, ``elbow``: each muscle's), then what only a batch reads (its targets'
    radius and "near" bound, its hands' move bounds, the fast stages' series limit)."""
    p = model.params
    values = [dt, 0.5 * dt, dt * _SIXTH, model.b, model.d, model.a * model.d - model.d * model.d, model.a - model.d,
              model.g1, model.g2, p.damping1, p.damping2, p.l1, p.l2, radius, near, *reach, limit2, *shoulder, *elbow]
    assert len(values) == KERNEL_PARAMS
    return values


def kernel_mode(params: TwoJointParams) -> int:
    """Which accel the kernel runs for arm parameters ``params`` (``TwoJointArm._build_components``'s)."""
    return 2 if params.has_gravity else 1 if params.has_damping else 0


DOWN, UP = "down", "up"
RESET_KEY, TOGGLE_ARM_KEY = "space", "tab"


@dataclass(frozen=True)
class InputEvent:
    """A key going down or up, taking effect before physics step ``step``."""

    step: int
    key: str
    action: str


@dataclass(frozen=True)
class LevelEvent:
    """Muscle levels (0 to 1, one a muscle) commanded before physics step ``step``: a program's continuous action,
    kept in ``GameSession.level_events`` so that its game can be replayed (``armgame.game.variant``)."""

    step: int
    levels: tuple[float, ...]


class NonFiniteStateError(UserError):
    """The arm's state overflowed: the configuration's physics blows up at this step."""


@dataclass(frozen=True)
class GameResult:
    score: int
    hits: int
    resets: int
    seed: int
    duration: float
    steps: int
    scene: str
    integrator: str
    dt: float
    version: str

    def as_dict(self) -> dict[str, object]:
        return asdict(self)


class GameSession:
    """One game: ``key_event`` and ``set_muscle_levels`` take input, ``advance`` runs physics steps.

    ``compiled`` (the default) runs RK4 games through ``_ckernel.game_steps`` where the install
    built it: the same floats as the Python loop in ``_advance``, operation for operation, some
    ten times faster. ``compiled=False`` runs the Python loop, the reference the tests hold the
    compiled one to (``==``); other integrators always run it.
    """

    def __init__(self, config: GameConfig, *, compiled: bool = True, rules: GameRules | None = None) -> None:
        self.config = config
        self.model = TwoJointArm(config.arm)
        self._physics_step = Integrator(config.integrator, self.model).step_components
        self.muscles = MuscleSet(config.muscles, config.dt)
        self._compiled = self._compiled_loop() if compiled else None
        if rules is not None and rules.config is not config:
            raise ValueError("the rules given must be made from the session's own config")
        #: The game's rules, or a variant's (``rules.DwellRules``): both loops call its ``hand_moved``.
        self.rules = rules if rules is not None else GameRules(config)
        self.keys = (*self.muscles.keys, RESET_KEY, TOGGLE_ARM_KEY)
        self.steps = 0
        self.total_steps = config.total_steps
        q1, q2 = config.start_posture
        self.state: tuple[float, float, float, float] = (q1, q2, 0.0, 0.0)
        self.previous_state = self.state
        self.held = [False] * len(self.muscles.keys)
        self.timeline: list[InputEvent] = []
        #: The continuous actions that changed a muscle's command (``set_muscle_levels``), in order; at most
        #: ``MAX_EVENTS`` (``level_events_overflow`` tells when more came: that game cannot be replayed).
        self.level_events: list[LevelEvent] = []
        self.level_events_overflow = False
        self.event_limit_reached = False

    # ------------------------------------------------------------------ queries
    @property
    def time(self) -> float:
        return self.steps * self.config.dt

    @property
    def time_left(self) -> float:
        return max(0.0, (self.total_steps - self.steps) * self.config.dt)

    @property
    def over(self) -> bool:
        return self.steps >= self.total_steps

    def hand(self) -> tuple[float, float]:
        p = self.config.arm
        return hand_xy(p.l1, p.l2, self.state[0], self.state[1])

    def result(self) -> GameResult:
        b, c = self.rules.board, self.config
        return GameResult(b.score, b.hits, b.resets, c.seed, c.time_limit, self.steps, c.scene, c.integrator, c.dt,
                          __version__)

    # ------------------------------------------------------------------- input
    def key_event(self, key: str, action: str) -> bool:
        """Apply a key event before the next physics step. Returns whether it changed anything.

        Unknown keys, repeats of a held key and events after the end are ignored, and
        only events that did something enter the timeline. A game's identity (``records.identity``,
        ``applied_input``) is read from what this applies: what acts here, and when, is what it counts.
        """
        if self.over:
            return False
        if len(self.timeline) >= MAX_EVENTS:
            # A replay holds at most MAX_EVENTS events: the game stops here rather than record
            # what no reader would accept. The replay is of a game stopped early (never ranked).
            self.total_steps = self.steps
            self.event_limit_reached = True
            return False
        if key in self.muscles.keys:
            i = self.muscles.keys.index(key)
            down = action == DOWN
            if self.held[i] == down:
                return False
            self.held[i] = down
            self.muscles.command(i, down)
        elif key == RESET_KEY and action == DOWN:
            self._reset_arm()
        elif key == TOGGLE_ARM_KEY and action == DOWN:
            self.rules.toggle_arm()
        else:
            return False
        self.timeline.append(InputEvent(self.steps, key, action))
        return True

    def set_muscle_levels(self, levels: Sequence[float]) -> None:
        """Command every muscle's activation level (0 to 1) before the next physics step.

        The continuous counterpart of the muscle keys, for programs (Gymnasium's continuous
        reach): not recorded in the key timeline, ignored after the end, and it leaves the
        keys' held state alone. Levels 0 and 1 act exactly as releasing and pressing a key.
        A call that changes a muscle's command (its goal or rate) is kept in ``level_events``.
        """
        if self.over:
            return
        if len(levels) != MuscleSet.COUNT:
            raise MuscleLevelError(f"expected {MuscleSet.COUNT} muscle levels, got {len(levels)}")
        values = [float(v) for v in levels]
        for i, level in enumerate(values):  # check all before changing any
            if not 0.0 <= level <= 1.0:
                raise MuscleLevelError(f"muscle level {i} must be from 0 to 1, got {level!r}")
        muscles = self.muscles
        before = (list(muscles.goal), list(muscles.rate))
        for i, level in enumerate(values):
            muscles.set_level(i, level)
        # A call that changes nothing (the same levels again, the activation on the same side) is not kept:
        # goal and rate are all set_level changes, so replaying the kept calls gives the same commands.
        if (muscles.goal, muscles.rate) != before:
            if len(self.level_events) < MAX_EVENTS:
                self.level_events.append(LevelEvent(self.steps, tuple(values)))
            else:
                self.level_events_overflow = True

    def set_muscle_moments(self, moments: tuple[tuple[float, float], ...]) -> None:
        """Each muscle's (shoulder, elbow) moment from the next step on (motor noise rescales them between
        decisions): the Python loop reads them afresh each ``advance``, the compiled one from its params, packed
        again here."""
        self.muscles.moments = moments
        compiled = self._compiled
        if compiled is not None:
            params, mode, _ = self._compiled_loop()  # type: ignore[misc]
            # Still the step it replaced: a step swapped in since (a field's) keeps the Python loop running.
            self._compiled = params, mode, compiled[2]

    def _compiled_loop(self) -> tuple[bytes, int, object] | None:
        """(params, mode, the step it replaces) for ``_ckernel.game_steps``, or None where it cannot run."""
        if _c_game_steps is None or self.config.integrator != "rk4":
            return None
        moments = self.muscles.moments
        values = kernel_params(self.model, self.config.dt, [m[0] for m in moments], [m[1] for m in moments])
        return struct.pack(f"={KERNEL_PARAMS}d", *values), kernel_mode(self.model.params), self._physics_step

    def field_step(self, kind: int, parameters: tuple[float, float, float, float]
                   ) -> Callable[..., tuple[float, float, float, float]] | None:
        """The physics step with a field at the hand (``_ckernel.c``'s FIELD_* ``kind`` and its ``parameters``) in C,
        ``_ckernel.rk4_step_loaded``: ``physics.loads``' RK4 step, the same floats; None where it is not built."""
        compiled = self._compiled
        if compiled is None or _ckernel is None:
            return None
        return functools.partial(_ckernel.rk4_step_loaded, compiled[0], compiled[1], kind, *parameters)

    def unloaded_step(self) -> Callable[..., tuple[float, float, float, float]]:
        """The physics step of the arm with nothing added: ``_physics_step`` itself, or its operations in C
        (``_ckernel.rk4_step``, the same floats) where the compiled loop runs. For loops of their own
        (the lab's), which step the arm one step at a time."""
        compiled = self._compiled
        if compiled is None or compiled[2] is not self._physics_step:
            return self._physics_step
        return functools.partial(_c_rk4_step, compiled[0], compiled[1])

    def _reset_arm(self) -> None:
        q1, q2 = self.config.start_posture
        self.state = self.previous_state = (q1, q2, 0.0, 0.0)
        self.muscles.reset()
        self.rules.reset_penalty()

    # ----------------------------------------------------------------- physics
    def advance(self, n: int) -> int:
        """Run up to ``n`` physics steps (fewer if the game ends); returns how many ran.

        A state that goes non-finite (a configuration whose physics blows up) raises
        ``NonFiniteStateError`` in one line. Checked once per call, not per step, so the hot
        loop in ``_advance`` is untouched.
        """
        start = self.steps
        try:
            ran = self._advance(n)
        except (ValueError, OverflowError, ZeroDivisionError):  # math.cos(inf) on the way to the hand
            ran = -1
        if ran < 0 or not math.isfinite(self.state[0] + self.state[1] + self.state[2] + self.state[3]):
            dt = self.config.dt
            raise NonFiniteStateError(f"the arm's state became non-finite between t = {start * dt:g} and "
                                      f"{(start + n) * dt:g} s: this game's physics blows up "
                                      f"({self.config.integrator}, dt {dt:g} s)")
        return ran

    def _advance(self, n: int) -> int:
        """Run up to ``n`` physics steps (fewer if the game ends); returns how many ran.

        This is the hot loop of every game, so the muscle update (exactly
        ``MuscleSet.step``, unrolled for the four muscles), the torque and the hit test are
        written out here with local names rather than called.
        """
        n = min(n, self.total_steps - self.steps)
        if n <= 0:
            return 0
        step = self._physics_step
        compiled = self._compiled
        if compiled is not None and compiled[2] is step:  # a step swapped in (tests do) runs in Python
            return self._advance_compiled(n, compiled[0], compiled[1])
        dt = self.config.dt
        arm = self.config.arm
        l1, l2 = arm.l1, arm.l2
        trig = sin_cos  # the rules' hand (rules.hand_position): the arm's own sine, the same bits everywhere
        rules = self.rules
        target = rules.target
        tx, ty, rr = target.x, target.y, target.radius * target.radius
        muscles = self.muscles
        a0, a1, a2, a3 = muscles.activation
        g0, g1, g2, g3 = muscles.goal
        r0, r1, r2, r3 = muscles.rate
        (s0, e0), (s1, e1), (s2, e2), (s3, e3) = muscles.moments
        q1, q2, w1, w2 = self.state
        previous = self.state
        start = self.steps
        for k in range(n):
            t1 = a0 * s0 + a1 * s1 + a2 * s2 + a3 * s3
            t2 = a0 * e0 + a1 * e1 + a2 * e2 + a3 * e3
            a0 += (g0 - a0) * r0
            a1 += (g1 - a1) * r1
            a2 += (g2 - a2) * r2
            a3 += (g3 - a3) * r3
            previous = (q1, q2, w1, w2)
            q1, q2, w1, w2 = step(q1, q2, w1, w2, t1, t2, dt)
            sn1, cs1 = trig(q1)
            sn12, cs12 = trig(q1 + q2)
            hx = l1 * cs1 + l2 * cs12
            hy = l1 * sn1 + l2 * sn12
            dx, dy = hx - tx, hy - ty
            if dx * dx + dy * dy <= rr:
                rules.hand_moved(hx, hy, (start + k + 1) * dt)
                target = rules.target
                tx, ty, rr = target.x, target.y, target.radius * target.radius
        muscles.activation = [a0, a1, a2, a3]
        self.steps = start + n
        self.state = (q1, q2, w1, w2)
        self.previous_state = previous
        return n

    def _advance_compiled(self, n: int, params: bytes, mode: int) -> int:
        """``_advance``'s loop in C: it stops after each step that brings the hand near the target,
        and the hit is decided here, by the Python loop's own test on the same floats.

        The locals are unpacked as ``_advance`` unpacks them, on purpose: a bot calls this once a
        step, and packing them into tuples and slices cost a bot's game a tenth more time."""
        dt = self.config.dt
        rules = self.rules
        target = rules.target
        tx, ty, rr = target.x, target.y, target.radius * target.radius
        muscles = self.muscles
        a0, a1, a2, a3 = muscles.activation
        g0, g1, g2, g3 = muscles.goal
        r0, r1, r2, r3 = muscles.rate
        q1, q2, w1, w2 = self.state
        previous = self.state
        start, done = self.steps, 0
        game_steps = _c_game_steps
        while done < n:
            (ran, near, q1, q2, w1, w2, p1, p2, p3, p4, a0, a1, a2, a3, hx, hy) = game_steps(
                params, mode, n - done, q1, q2, w1, w2, a0, a1, a2, a3, g0, g1, g2, g3, r0, r1, r2, r3, tx, ty, rr)
            previous = (p1, p2, p3, p4)
            done += ran
            if near and (hx - tx) * (hx - tx) + (hy - ty) * (hy - ty) <= rr:
                rules.hand_moved(hx, hy, (start + done) * dt)
                target = rules.target
                tx, ty, rr = target.x, target.y, target.radius * target.radius
        muscles.activation = [a0, a1, a2, a3]
        self.steps = start + n
        self.state = (q1, q2, w1, w2)
        self.previous_state = previous
        return n

    def play(self, events: Iterable[InputEvent], stop_step: int | None = None) -> GameResult:
        """Play the game from a timeline (sorted by step) with no clock at all.

        ``stop_step`` ends a game that was quit early where it stopped: the arm could still
        drift onto a target afterwards, so playing on to the clock's end would not reproduce it.
        """
        TimelineInput(events, stop_step).run_to(self, self.total_steps)
        return self.result()

    def interpolated_angles(self, alpha: float) -> tuple[float, float]:
        """Joint angles a fraction ``alpha`` of a step past the previous state, for smooth drawing."""
        (p1, p2, _, _), (c1, c2, _, _) = self.previous_state, self.state
        return p1 + alpha * (c1 - p1), p2 + alpha * (c2 - p2)


class TimelineInput:
    """Feeds a sorted timeline into a session up to a given step, remembering where it is."""

    def __init__(self, events: Iterable[InputEvent], stop_step: int | None = None) -> None:
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


class RealTimeDriver:
    """Consumes real elapsed time in fixed physics steps ("Fix Your Timestep!").

    A frame longer than ``max_frame_time`` (a dragged window, a stall) is clamped, so the
    game slows down for a moment rather than freezing in a spiral of catch-up steps. The
    clock is kept as a running total rather than a leftover fraction, so frames of 1/30 s
    and of 1/120 s reach the same step at the same moment.
    """

    def __init__(self, session: GameSession, max_frame_time: float = 0.25) -> None:
        self.session = session
        self.max_frame_time = max_frame_time
        self.clock = 0.0
        self.steps_taken = 0

    def advance(self, elapsed: float) -> float:
        """Step the session through ``elapsed`` seconds; returns the interpolation fraction."""
        dt = self.session.config.dt
        self.clock += min(max(elapsed, 0.0), self.max_frame_time)
        due = math.floor(self.clock / dt + 1e-9)
        self.session.advance(due - self.steps_taken)
        self.steps_taken = due
        return min(max(self.clock / dt - due, 0.0), 1.0)
