"""A game with the harder tasks' rules and physics: a dwell, motor noise, a force field at the hand, a speed guard.

``armgame.env``'s Reach envs play these (``armgame.env.variants`` turns their arguments into a
``GameVariant``), and ``armgame.records.env_game`` replays them, so a replay of such a game carries
everything its result depends on and ``armgame verify`` recomputes it (issue 40). What each does:

* ``hold_steps``: a hit counts once the hand has stayed in the target that many physics steps in a row
  (``rules.DwellRules``); 0 is the game's rule.
* ``motor_noise``: each muscle's force times ``1 + n`` (``MuscleNoise``), ``n`` drawn afresh before every
  decision of ``decision_steps`` physics steps from a stream seeded by the game's seed: the noise depends
  on the decisions' rhythm, so the variant carries it.
* ``field``: a force at the hand, ``("curl", b)`` (``F = b [[0, 1], [-1, 0]] v``) or ``("viscous", B)``
  (``F = B v``, ``B`` the 2 x 2 matrix itself, so the replay does not depend on the lab's constants).
* ``speed_limit`` (rad/s): a viscous field's symmetric part feeds the arm energy, so no bound on the
  speeds holds under it; a game whose joint speed passes ``speed_limit`` after any physics step stops
  there (``RunawayError``, raised before the step's state is kept), which keeps the env's declared speed
  bounds true. Infinite: no guard.

A single session runs the Python loop whenever a field is on (its compiled loop has no loads); noise runs
in either (``GameSession.set_muscle_moments`` packs the compiled loop's moments again), the same floats.
A batch plays all of them in its compiled kernel (``armgame.game.batch.variant``).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence

import numpy as np

from ..errors import UserError
from ..physics.integrators import Integrator
from ..physics.loads import CurlField, Loads, ViscousField, loaded_arm
from .rules import DwellRules, GameConfig, GameRules
from .session import GameSession, LevelEvent

#: The motor noise's correlation time (s): a force held between decisions drifts rather than jitters.
NOISE_CORRELATION_TIME = 0.05
#: The largest factor noise puts on a muscle's force: the speed bounds are computed for it.
NOISE_FACTOR_MAX = 2.0
FIELD_KINDS = ("curl", "viscous")
#: Each field's code in the compiled kernels (``_ckernel.h``'s FIELD_*).
FIELD_CODES = {None: 0, "curl": 1, "viscous": 2}

Matrix = tuple[tuple[float, float], tuple[float, float]]


class RunawayError(UserError):
    """A joint's speed passed the variant's ``speed_limit``: the game stops (a field fed the arm too much energy)."""


@dataclasses.dataclass(frozen=True)
class GameVariant:
    """What a Reach env's game adds to the game's rules and physics (the defaults: the game itself)."""

    hold_steps: int = 0
    motor_noise: float = 0.0
    #: Physics steps per decision: the rhythm of the motor noise's draws.
    decision_steps: int = 1
    field: str | None = None
    #: The curl field's ``b`` (a number) or the viscous field's matrix ``B``.
    field_parameter: float | Matrix | None = None
    speed_limit: float = math.inf

    def __post_init__(self) -> None:
        if self.field is not None and self.field not in FIELD_KINDS:
            raise UserError(f"field must be 'curl' or 'viscous', got {self.field!r}")

    @property
    def plain(self) -> bool:
        """Whether this game's result is the game's own: no dwell, noise or field (the guard never acts on the
        game's arm: its speeds stay within ``reach.speed_bound``)."""
        return not self.hold_steps and not self.motor_noise and self.field is None

    def loads(self) -> Loads | None:
        if self.field == "curl":
            return Loads(hand=CurlField(float(self.field_parameter)))  # type: ignore[arg-type]
        if self.field == "viscous":
            return Loads(hand=ViscousField(self.field_parameter))  # type: ignore[arg-type]
        return None

    def session(self, config: GameConfig) -> GameSession:
        """A new game of ``config`` with this variant's rules and physics (noise: ``MuscleNoise``, applied by the
        caller before each decision)."""
        rules: GameRules | None = DwellRules(config, self.hold_steps) if self.hold_steps else None
        session = GameSession(config, rules=rules)
        loads = self.loads()
        if loads is not None:
            # A step swapped in runs through the session's Python loop (the compiled one has no loads): loads' RK4
            # step in C where built, the same floats as its Python.
            step = session.field_step(FIELD_CODES[self.field], self.field_parameters) \
                if config.integrator == "rk4" else None
            if step is None:
                step = Integrator(config.integrator, loaded_arm(session.model, loads)).step_components
            session._physics_step = guarded(step, self.speed_limit) if math.isfinite(self.speed_limit) else step
        return session

    @property
    def field_parameters(self) -> tuple[float, float, float, float]:
        """The field's parameter as the kernels take it: the curl field's ``(b, 0, 0, 0)``, the viscous field's
        matrix row by row (zeros without a field)."""
        parameter = self.field_parameter
        if self.field == "curl":
            return (float(parameter), 0.0, 0.0, 0.0)  # type: ignore[arg-type]
        if self.field == "viscous":
            (b11, b12), (b21, b22) = parameter  # type: ignore[misc]
            return (float(b11), float(b12), float(b21), float(b22))
        return (0.0, 0.0, 0.0, 0.0)

    def noise(self, config: GameConfig, session: GameSession) -> MuscleNoise | None:
        """The game's motor noise (None without): seeded by the game's seed."""
        if not self.motor_noise:
            return None
        return MuscleNoise(self.motor_noise, config.seed, self.decision_steps * config.dt, session)


def guarded(step: Callable[..., tuple[float, float, float, float]],
            limit: float) -> Callable[..., tuple[float, float, float, float]]:
    """``step`` that raises ``RunawayError`` instead of returning a state whose joint speed passes ``limit``
    (NaN too: the comparisons fail), so the session never keeps such a state."""

    def step_guarded(q1: float, q2: float, w1: float, w2: float, t1: float, t2: float,
                     dt: float) -> tuple[float, float, float, float]:
        q1, q2, w1, w2 = step(q1, q2, w1, w2, t1, t2, dt)
        if not (-limit <= w1 <= limit and -limit <= w2 <= limit):
            raise RunawayError(runaway_message(limit, w1, w2))
        return q1, q2, w1, w2

    return step_guarded


def runaway_message(limit: float, w1: float, w2: float) -> str:
    """Why a game stopped at the guard, in one line, from the joint speeds that passed ``limit``."""
    return f"the force field drove a joint past {limit:.1f} rad/s ({max(abs(w1), abs(w2)):.4g}): the game stops"


def noise_generator(seed: int) -> np.random.Generator:
    """The motor noise's stream of the game of seed ``seed`` (apart from the targets' stream of the same seed)."""
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence([seed, 0x5EED_0015E])))


class MuscleNoise:
    """Signal-dependent motor noise on a session's muscles (Harris & Wolpert 1998): ``apply`` before each decision.

    The factors ``clip(1 + n, 0, NOISE_FACTOR_MAX)`` scale each muscle's moments (its force at full
    activation), so the force noise is proportional to the activation; ``n`` is first-order
    autoregressive with s.d. ``level`` and correlation time ``NOISE_CORRELATION_TIME``, one draw per
    muscle and decision, from a stream seeded by the game's seed."""

    def __init__(self, level: float, seed: int, decision_time: float, session: GameSession) -> None:
        self.level = level
        self._rng = noise_generator(seed)
        self._keep = math.exp(-decision_time / NOISE_CORRELATION_TIME)
        self._fresh = level * math.sqrt(1.0 - self._keep * self._keep)
        # Started from its stationary spread, so the first decision is as noisy as the last.
        self.state = self._rng.standard_normal(4) * level
        self._moments = session.muscles.moments

    def apply(self, session: GameSession) -> None:
        self.state = self._keep * self.state + self._fresh * self._rng.standard_normal(4)
        factors = np.clip(1.0 + self.state, 0.0, NOISE_FACTOR_MAX).tolist()
        session.set_muscle_moments(tuple((f * s, f * e) for f, (s, e) in zip(factors, self._moments, strict=True)))


class VariantPlay:
    """A variant's game replayed from its key timeline and level events, decision by decision as an env plays it.

    At every physics step ``s`` it applies the levels commanded at ``s``, then the key events at ``s``, then,
    at a decision's start (``s`` a multiple of ``decision_steps``), the motor noise's draw; then physics to
    the next of these. That is the env's order within a step (``SessionEnv._set_levels`` before the reset
    key, ``_before_advance`` after both)."""

    def __init__(self, config: GameConfig, variant: GameVariant) -> None:
        self.variant = variant
        self.session = variant.session(config)
        self.noise = variant.noise(config, self.session)

    def play(self, timeline: Sequence, levels: Sequence[LevelEvent], steps: int, stopped: bool = False,
             budget: Callable[[GameSession], bool] | None = None) -> GameSession:
        """Play to ``steps``; ``stopped``: the game ended at a runaway in the decision after ``steps``, which is
        played too (its ``RunawayError`` expected, its hits kept; a decision that does not raise is played out,
        so the steps differ from the record's). ``budget(session)`` is asked between
        decisions whether to go on (a verifier stops a game that has already scored more than it claims)."""
        session, noise = self.session, self.noise
        d = self.variant.decision_steps
        keys = list(timeline)
        k = i = 0
        while session.steps < steps or (stopped and session.steps == steps):
            now = session.steps
            k, i = _apply_due(session, keys, k, levels, i)
            if now % d == 0:
                if budget is not None and not budget(session):
                    break
                if noise is not None:
                    noise.apply(session)
            stop = _next_input(keys, k, levels, i, now, min(now - now % d + d, steps if now < steps else now + d))
            try:
                session.advance(stop - now)
            except RunawayError:
                session.total_steps = session.steps  # over, as the env ended it
                return session
            if now >= steps or session.over:  # a claimed runaway that did not come plays on: the steps differ
                break
        return session


def play_inputs(session: GameSession, timeline: Sequence, levels: Sequence[LevelEvent], steps: int) -> GameSession:
    """Play ``session`` (any ``GameSession``: a lab run too) to ``steps`` from its key timeline and level events, each
    applied before its physics step, levels first (an env's order within a step)."""
    keys = list(timeline)
    k = i = 0
    while session.steps < steps and not session.over:
        now = session.steps
        k, i = _apply_due(session, keys, k, levels, i)
        session.advance(_next_input(keys, k, levels, i, now, steps) - now)
    return session


def _apply_due(session: GameSession, keys: Sequence, k: int, levels: Sequence[LevelEvent], i: int) -> tuple[int, int]:
    """The level events and key events due before the session's next step applied, levels first (an env's order
    within a step); the indices of the first of each still to come."""
    now = session.steps
    while i < len(levels) and levels[i].step <= now:
        session.set_muscle_levels(levels[i].levels)
        i += 1
    while k < len(keys) and keys[k].step <= now:
        session.key_event(keys[k].key, keys[k].action)
        k += 1
    return k, i


def _next_input(keys: Sequence, k: int, levels: Sequence[LevelEvent], i: int, now: int, stop: int) -> int:
    """``stop``, or the step of the next key or level event if one comes sooner (at least one step on)."""
    if k < len(keys):
        stop = min(stop, max(keys[k].step, now + 1))
    if i < len(levels):
        stop = min(stop, max(levels[i].step, now + 1))
    return stop
