"""The harder Reach tasks: a dwell, motor noise, a feedback delay, a force field and the target's size.

Each is an argument of ``armgame/Reach-v1`` (and ``ReachContinuous-v1``), off by default, and
``ReachVariant`` holds them checked. The suite registers a few as ids of their own
(``armgame.env.__init__``): ``ReachHold-v1``, ``ReachNoisy-v1``, ``ReachDelay-v1``, ``ReachField-v1``
and ``ReachHard-v1``, all four at once. What each does to the game:

* ``hold_time`` (s): a hit counts once the hand has stayed in the target that long
  (``armgame.game.rules.DwellRules``), so the hand must stop on the target, not fly through it.
* ``motor_noise``: signal-dependent noise (Harris & Wolpert 1998): each muscle's force is multiplied
  by ``1 + n``, ``n`` a Gaussian of s.d. ``motor_noise`` (a coefficient of variation) correlated over
  ``NOISE_CORRELATION_TIME`` (first-order autoregressive, one draw per muscle and decision), clipped
  to ``[0, 2]`` so that a muscle only pulls and the speed bounds still hold. A relaxed muscle makes
  no noise; a fully active one the most. The stream is seeded by the game's seed.
* ``observation_delay`` (env steps): the observation is that many decisions old, as feedback
  reaches a player a reaction time late; the reward and ``info`` are not delayed (they are the
  task's bookkeeping, not what the agent senses).
* ``field`` (``"curl"`` or ``"viscous"``) and ``field_strength``: a force at the hand all game long,
  the lab's fields (``armgame.physics.loads``): the curl field ``F = b [[0, 1], [-1, 0]] v`` with
  ``b = field_strength`` N s/m (-50 to 50: it does no work, so the speed bound holds whatever ``b``), or
  the lab's viscous matrix scaled by ``field_strength`` (-2 to 2, ``MAX_VISCOUS_STRENGTH``). The viscous
  matrix's symmetric part feeds the arm energy (at some postures more than the joints' damping takes out
  even at strength 1), so no bound is proven under it: from about 4 the arm runs away (issue 40 found
  one game in three overflowing at 20, within the old range of 50). The range is what was measured
  stable with margin (``benchmarks/field_range.py``: a policy that feeds the arm all the energy its
  muscles can reaches 21.1 rad/s at strength 2 and 29.1 at 3, under the game's bound of 34.4), and a
  guard keeps the declared speed bounds true beyond it: a game whose joint speed passes them stops,
  terminated, ``info["stopped"]`` saying why in one line (``armgame.game.variant.RunawayError``).
* ``target_radius`` (m): the game's targets smaller or larger (the game's 0.05 by default).
* ``target_shown`` (s) and ``positions_only``: what the observation hides, the game unchanged. With
  ``target_shown`` the hand-to-target vector is seen only in the observations of that long after each target
  appears (the first at least), then reads 0 until the next target: where to go must be remembered.
  ``positions_only=True`` reads 0 for the joints' and the hand's velocities and the muscles' activations: a
  policy must tell them from the positions it has seen and the keys it has pressed. The separating tier's ids
  fix them (``armgame.env.suite.TIER``).

A variant's game is not the game of ``armgame play``, and its score is not comparable with a player's,
but it is recorded all the same: ``armgame.env.record.replay_of(env)`` writes a replay whose task
section carries the variant (``armgame.game.variant.GameVariant``), which ``armgame verify`` replays.
A single env with noise runs the game's compiled loop (its moments packed again each decision); with a field,
the session's Python loop around a compiled RK4 step with the field (``GameSession.field_step``). At 1 env
(docs/programs.md, "Beside MotorNet") ReachNoisy-v1 stepped at 0.68 times Reach-v1's rate, ReachField-v1 at 0.79
and ReachHard-v1 at 0.58. ``gymnasium.make_vec`` plays every one in the batch's compiled kernel
(``armgame.game.batch.variant``), each game equal to its single env.
"""

from __future__ import annotations

import dataclasses
import math
from collections import deque
from typing import Any

import numpy as np

from ..game.muscles import MuscleSpec
from ..game.rules import GameConfig
from ..game.session import GameSession
from ..game.variant import NOISE_CORRELATION_TIME, NOISE_FACTOR_MAX, GameVariant, MuscleNoise
from .errors import EnvArgumentError

__all__ = ["FIELDS", "MAX_FIELD_STRENGTH", "MAX_VISCOUS_STRENGTH", "NOISE_CORRELATION_TIME", "NOISE_FACTOR_MAX",
           "DelayedObservations", "HiddenObservations", "MuscleNoise", "ReachVariant", "with_target_radius"]

FIELDS = ("curl", "viscous")
MAX_HOLD_TIME = 5.0
MAX_OBSERVATION_DELAY = 100
#: ``target_shown`` at most (s): the game's longest.
MAX_TARGET_SHOWN = 3600.0
#: The curl field's ``b`` (N s/m) at most, either sign: it does no work, so any ``b`` keeps the speed bound.
MAX_FIELD_STRENGTH = 50.0
#: The viscous field's scale at most, either sign: what was measured stable, with margin (module docstring).
MAX_VISCOUS_STRENGTH = 2.0


@dataclasses.dataclass(frozen=True)
class ReachVariant:
    """The harder task's arguments, checked (``ReachVariant.of``); the defaults are the game itself."""

    hold_time: float = 0.0
    motor_noise: float = 0.0
    observation_delay: int = 0
    field: str | None = None
    field_strength: float = 0.0
    #: Seconds the hand-to-target vector is observed after each target appears (None: always).
    target_shown: float | None = None
    #: Whether only positions are observed (the velocities and the activations read 0).
    positions_only: bool = False

    @classmethod
    def of(cls, hold_time: object = 0.0, motor_noise: object = 0.0, observation_delay: object = 0,
           field: object = None, field_strength: object = None, target_shown: object = None,
           positions_only: object = False) -> ReachVariant:
        hold = _number("hold_time", hold_time, 0.0, MAX_HOLD_TIME, "s")
        noise = _number("motor_noise", motor_noise, 0.0, 1.0, "(a coefficient of variation)")
        if isinstance(observation_delay, bool) or not isinstance(observation_delay, int | np.integer) \
                or not 0 <= observation_delay <= MAX_OBSERVATION_DELAY:
            raise EnvArgumentError(f"observation_delay must be a whole number of env steps from 0 to "
                                   f"{MAX_OBSERVATION_DELAY}, got {observation_delay!r}")
        if field is not None and field not in FIELDS:
            raise EnvArgumentError(f"field must be 'curl', 'viscous' or None, got {field!r}")
        if field is None:
            if field_strength not in (None, 0, 0.0):
                raise EnvArgumentError("field_strength needs a field: field='curl' or 'viscous'")
            strength = 0.0
        else:
            default = DEFAULT_FIELD_STRENGTH[field]  # type: ignore[index]
            most = MAX_FIELD_STRENGTH if field == "curl" else MAX_VISCOUS_STRENGTH
            unit = "N s/m" if field == "curl" else "(times the lab's viscous matrix; stronger runs away)"
            strength = default if field_strength is None else _number("field_strength", field_strength, -most, most,
                                                                       unit)
        shown = None if target_shown is None else _number("target_shown", target_shown, 0.0, MAX_TARGET_SHOWN,
                                                            "s (or None: always)")
        if not isinstance(positions_only, bool | np.bool_):
            raise EnvArgumentError(f"positions_only must be True or False, got {positions_only!r}")
        return cls(hold, noise, int(observation_delay), field if strength != 0.0 else None, strength,  # type: ignore[arg-type]
                   shown, bool(positions_only))

    @property
    def hides(self) -> bool:
        """Whether the observation hides part of the state (``target_shown``, ``positions_only``)."""
        return self.target_shown is not None or self.positions_only

    @property
    def plain(self) -> bool:
        """Whether this is the game itself (no variant on)."""
        return self == ReachVariant()

    def hold_steps(self, dt: float) -> int:
        return max(1, round(self.hold_time / dt))

    def game_variant(self, config: GameConfig, decision_steps: int, speed_limit: float = math.inf) -> GameVariant:
        """The game's rules and physics of this variant for decisions of ``decision_steps`` physics steps: what
        its replay carries (the field as its parameter, the viscous matrix itself). ``speed_limit``: the joint
        speed bound the env declares (``reach.speed_bound``), which a game with a field stops at rather than
        pass (``armgame.game.variant.RunawayError``)."""
        parameter: Any = None
        if self.field == "curl":
            parameter = self.field_strength
        elif self.field == "viscous":
            from ..lab.presets import VISCOUS_B  # the lab's matrix, once

            parameter = tuple(tuple(self.field_strength * v for v in row) for row in VISCOUS_B)
        return GameVariant(self.hold_steps(config.dt) if self.hold_time else 0, self.motor_noise, decision_steps,
                           self.field, parameter, speed_limit if self.field is not None else math.inf)

    def bound_config(self, config: GameConfig) -> GameConfig:
        """A config whose speed bound holds for this variant: the muscles as strong as noise can make them."""
        if not self.motor_noise:
            return config
        muscles = tuple(MuscleSpec(m.name, m.key, (NOISE_FACTOR_MAX * m.moment[0], NOISE_FACTOR_MAX * m.moment[1]),
                                   m.rise_time, m.decay_time) for m in config.muscles)
        return dataclasses.replace(config, muscles=muscles)

    def session(self, config: GameConfig, decision_steps: int = 1, speed_limit: float = math.inf) -> GameSession:
        """The game of ``config`` with this variant's rules and physics (its noise: ``game_variant().noise``)."""
        return self.game_variant(config, decision_steps, speed_limit).session(config)

    def as_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)


#: A field's default strength: the lab's curl preset's b (N s/m), the lab's viscous matrix as it is.
DEFAULT_FIELD_STRENGTH = {"curl": 1.0, "viscous": 1.0}


def _number(name: str, value: object, low: float, high: float, unit: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.floating | np.integer) \
            or not (math.isfinite(value) and low <= value <= high):
        raise EnvArgumentError(f"{name} must be a number from {low:g} to {high:g} {unit}".rstrip()
                               + f", got {value!r}")
    return float(value)


class HiddenObservations:
    """An observation with what the variant hides read as 0: the hand-to-target vector (entries 12 and 13) once
    its target has been seen for ``target_shown`` seconds; with ``positions_only`` the velocities (2, 3, 10, 11) and
    the activations (4 to 7).
    A target's age counts from the first observation that shows it (the end of the decision it appeared in), in
    physics steps, so it is seen in ``ceil(target_shown / decision time)`` observations, at least one."""

    def __init__(self, variant: ReachVariant, dt: float) -> None:
        self.shown_steps = None if variant.target_shown is None else max(1, round(variant.target_shown / dt))
        self.positions_only = variant.positions_only
        self._target: object = None
        self._since = 0

    def apply(self, observation: np.ndarray, target: object, steps: int) -> np.ndarray:
        if self.shown_steps is not None:
            if target is not self._target:
                self._target, self._since = target, steps
            if steps - self._since >= self.shown_steps:
                observation[12:14] = 0.0
        if self.positions_only:
            observation[2:8] = 0.0
            observation[10:12] = 0.0
        return observation


class DelayedObservations:
    """The observations an agent gets ``delay`` decisions late (the first repeated until the delay fills)."""

    def __init__(self, delay: int) -> None:
        self.delay = delay
        self._queue: deque[np.ndarray] = deque(maxlen=delay + 1)

    def reset(self, observation: np.ndarray) -> np.ndarray:
        self._queue.clear()
        self._queue.extend([observation] * (self.delay + 1))
        return observation.copy()

    def step(self, observation: np.ndarray) -> np.ndarray:
        self._queue.append(observation)
        return self._queue[0].copy()  # an agent may keep and change what it was given


def with_target_radius(config: GameConfig, radius: object) -> GameConfig:
    """``config`` with targets of ``radius`` metres (1 mm to 20 cm)."""
    if isinstance(radius, bool) or not isinstance(radius, int | float | np.floating) \
            or not (math.isfinite(radius) and 0.001 <= radius <= 0.2):
        raise EnvArgumentError(f"target_radius must be a number of metres from 0.001 to 0.2, got {radius!r}")
    return dataclasses.replace(config, target_radius=float(radius))
