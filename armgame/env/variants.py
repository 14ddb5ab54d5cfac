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
  ``b = field_strength`` N s/m, or the lab's viscous matrix scaled by ``field_strength``.
* ``target_radius`` (m): the game's targets smaller or larger (the game's 0.05 by default).

A variant's game is not the game of ``armgame play``: with any of these on, the episode has no
replay and its score is not comparable with a player's. The noise and the field run the physics
in Python (about five times slower a step than the compiled loop); the others cost nothing.
"""

from __future__ import annotations

import dataclasses
import math
from collections import deque
from typing import Any

import numpy as np

from ..game.muscles import MuscleSpec
from ..game.rules import DwellRules, GameConfig, GameRules
from ..game.session import GameSession
from ..physics.integrators import Integrator
from ..physics.loads import CurlField, Loads, ViscousField, loaded_arm
from .errors import EnvArgumentError

FIELDS = ("curl", "viscous")
#: The motor noise's correlation time (s): a force held between decisions drifts rather than jitters.
NOISE_CORRELATION_TIME = 0.05
#: The largest factor noise puts on a muscle's force: the speed bounds are computed for it.
NOISE_FACTOR_MAX = 2.0
MAX_HOLD_TIME = 5.0
MAX_OBSERVATION_DELAY = 100
MAX_FIELD_STRENGTH = 50.0


@dataclasses.dataclass(frozen=True)
class ReachVariant:
    """The harder task's arguments, checked (``ReachVariant.of``); the defaults are the game itself."""

    hold_time: float = 0.0
    motor_noise: float = 0.0
    observation_delay: int = 0
    field: str | None = None
    field_strength: float = 0.0

    @classmethod
    def of(cls, hold_time: object = 0.0, motor_noise: object = 0.0, observation_delay: object = 0,
           field: object = None, field_strength: object = None) -> ReachVariant:
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
            strength = default if field_strength is None else _number(
                "field_strength", field_strength, -MAX_FIELD_STRENGTH, MAX_FIELD_STRENGTH, "")
        return cls(hold, noise, int(observation_delay), field if strength != 0.0 else None, strength)  # type: ignore[arg-type]

    @property
    def plain(self) -> bool:
        """Whether this is the game itself (no variant on)."""
        return self == ReachVariant()

    def hold_steps(self, dt: float) -> int:
        return max(1, round(self.hold_time / dt))

    def loads(self) -> Loads | None:
        if self.field == "curl":
            return Loads(hand=CurlField(self.field_strength))
        if self.field == "viscous":
            from ..lab.protocol import VISCOUS_B  # the lab's matrix, once

            return Loads(hand=ViscousField(tuple(tuple(self.field_strength * v for v in row)  # type: ignore[arg-type]
                                                 for row in VISCOUS_B)))
        return None

    def bound_config(self, config: GameConfig) -> GameConfig:
        """A config whose speed bound holds for this variant: the muscles as strong as noise can make them."""
        if not self.motor_noise:
            return config
        muscles = tuple(MuscleSpec(m.name, m.key, (NOISE_FACTOR_MAX * m.moment[0], NOISE_FACTOR_MAX * m.moment[1]),
                                   m.rise_time, m.decay_time) for m in config.muscles)
        return dataclasses.replace(config, muscles=muscles)

    def session(self, config: GameConfig) -> GameSession:
        """The game of ``config`` with this variant's rules and physics."""
        rules: GameRules | None = DwellRules(config, self.hold_steps(config.dt)) if self.hold_time else None
        # Noise rescales the muscles' moments between decisions, which only the Python loop reads afresh.
        session = GameSession(config, compiled=not self.motor_noise, rules=rules)
        loads = self.loads()
        if loads is not None:
            # The session runs a step swapped in through its Python loop (the compiled one has no loads).
            session._physics_step = Integrator(config.integrator, loaded_arm(session.model, loads)).step_components
        return session

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


class MuscleNoise:
    """``ReachVariant.motor_noise`` on a session's muscles: ``apply`` before each decision's steps.

    The factors scale each muscle's moments (its force at full activation), so the force noise is
    proportional to the activation; ``ReachVariant.session`` gives a noisy game the Python loop, which reads
    the moments afresh each call (the compiled loop packs them once)."""

    def __init__(self, level: float, seed: int, decision_time: float, session: GameSession) -> None:
        self.level = level
        self._rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence([seed, 0x5EED_0015E])))
        self._keep = math.exp(-decision_time / NOISE_CORRELATION_TIME)
        self._fresh = level * math.sqrt(1.0 - self._keep * self._keep)
        # Started from its stationary spread, so the first decision is as noisy as the last.
        self.state = self._rng.standard_normal(4) * level
        self._moments = session.muscles.moments

    def apply(self, session: GameSession) -> None:
        self.state = self._keep * self.state + self._fresh * self._rng.standard_normal(4)
        factors = np.clip(1.0 + self.state, 0.0, NOISE_FACTOR_MAX).tolist()
        session.muscles.moments = tuple((f * s, f * e) for f, (s, e) in zip(factors, self._moments, strict=True))


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
