"""``armgame/Reach-v1`` and ``armgame/ReachContinuous-v1``: the game, with what a learner needs to start.

v0 gave the joint state and the target, and one point per hit: every learner had to compute the hand
and shape its own reward before anything learned. v1 is the same game (an episode is still the
game of its seed, its score in ``info``) with the hand, its velocity and the hand-to-target vector
in a float32 observation, a dense reward (``armgame.env.features``), and centred continuous actions.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..game.rules import GameConfig
from ..game.session import GameSession
from ..game.variant import GameVariant, MuscleNoise, RunawayError
from .features import DEFAULT_HIT_BONUS, DEFAULT_PROGRESS_WEIGHT, hand_and_velocity
from .reach import DEFAULT_DECISION_STEPS, ReachBaseEnv, ReachSettings, wrap_angle
from .variants import DelayedObservations, HiddenObservations, ReachVariant, with_target_radius

OBSERVATION_NAMES_V1 = ("q1", "q2", "w1", "w2", "a_d", "a_f", "a_j", "a_k", "hand_x", "hand_y", "hand_vx", "hand_vy",
                        "to_target_x", "to_target_y", "time_left_fraction")


class ReachV1Env(ReachBaseEnv):
    r"""
    ## Description

    The armgame game (see ``armgame/Reach-v0`` and docs/programs.md): a two-joint arm in the
    horizontal plane, four muscles, red targets to hit with the hand within 60 s; each hit scores a
    point and the next target appears at once. An episode is the game of ``armgame play --seed S``.

    ## Action Space

    ``armgame/Reach-v1``: ``MultiBinary(4)``, the muscle keys d, f, j, k held during the coming
    decision step (shoulder flexor, shoulder extensor, elbow flexor, elbow extensor: +1.5, -1.5,
    +1.125 and -1.125 N m at full activation).

    ``armgame/ReachContinuous-v1``: ``Box(-1, 1, (4,), float32)``: action ``a`` commands muscle level
    ``(a + 1) / 2``, so 0 is half activation, -1 relaxed, 1 full; outside [-1, 1] is clipped, NaN
    refused. A Gaussian policy's defaults (SB3's PPO and SAC) fit it with no wrapper.

    ``reset_key=True`` adds a fifth entry that presses the reset key (space): 1, or for the
    continuous env 0 or more.

    ## Observation Space

    ``Box(low, high, (15,), float32)``; every bound holds (tested), so an agent needs no
    normalisation wrapper to start:

    | Num   | Observation                                   | Min   | Max   | Unit  |
    |-------|-----------------------------------------------|-------|-------|-------|
    | 0     | shoulder angle q1 (from +x), wrapped          | -pi   | pi    | rad   |
    | 1     | elbow angle q2 (relative), wrapped            | -pi   | pi    | rad   |
    | 2-3   | joint angular velocities                      | -34.4 | 34.4  | rad/s |
    | 4-7   | activations of d, f, j, k                     | 0     | 1     |       |
    | 8-9   | hand x (forward), y (left) from the shoulder  | -0.8  | 0.8   | m     |
    | 10-11 | hand velocity x, y                            | -43.3 | 43.3  | m/s   |
    | 12    | hand to target centre, x                      | -1.55 | 1.55  | m     |
    | 13    | hand to target centre, y                      | -1.15 | 1.95  | m     |
    | 14    | fraction of the game's time left              | 0     | 1     |       |

    The speed bounds are proven, not observed (``reach.speed_bound``; the hand's from the joints':
    ``(l1 + 2 l2) w``); in play the hand moves at up to about 3 m/s. The target's radius is 0.05 m.

    The separating tier's ids hide entries, which then read 0 (the game is unchanged):
    ``armgame/ReachMemory-v1`` and ``ReachMemoryHold-v1`` entries 12-13 (m) from 0.1 s after each target appears
    (its first 5 observations show it) to the next target; ``armgame/ReachPositions-v1`` entries 2-7 (rad/s and
    activations) and 10-11 (m/s).

    ## Rewards

    ``reward="dense"`` (the default): ``r = w (e_prev - e) + bonus * hits - c * resets``, with ``e``
    the hand's distance to the current target's edge at the end of the step (0 on a step with a
    hit: the progress term restarts with each new target, so a far new target costs nothing),
    ``w = progress_weight`` (10 per metre), ``bonus = hit_bonus`` (1) and ``c`` the reset cost (1).
    Summed over a game it is ``w (sum of each target's starting distance - the last target's final
    distance) + bonus H - c R`` (``armgame.env.features``). ``reward="sparse"``: one per hit less the
    reset cost, as v0. ``reward="score"``: the game's score as it changes (hits less the reset cost,
    never below 0) plus ``w (phi' - phi)``, ``phi = -e``, with ``phi = 0`` at the reset and at the
    game's end: a potential-based shaping that sums to exactly nothing, so **the return is the game's
    score** (to round-off). Report the score (``info["score"]``, or ``armgame.env.evaluate``): the
    dense return tracks it only loosely within a policy (docs/programs.md measures both). Either way
    ``info`` carries the game's ``score``, ``hits`` and ``resets``.

    ## Starting State

    The arm at rest at q1 = 45 deg, q2 = 90 deg, muscles relaxed, the seed's first target shown.
    ``reset(seed=s)`` plays game seed ``s``; without a seed the game's seed comes from the env's
    generator.

    ## Episode End

    Never terminated; truncated when the game's clock runs out (60 s: 3,000 steps of 20 ms). A shorter
    ``time_limit`` gives shorter episodes; compare them by hits (or score) per minute.

    ## Arguments

    ```python
    >>> import gymnasium as gym
    >>> import armgame.env
    >>> env = gym.make("armgame/Reach-v1")
    >>> obs, info = env.reset(seed=10)
    >>> obs.dtype, obs.shape, info
    (dtype('float32'), (15,), {'score': 0, 'hits': 0, 'resets': 0})
    >>> obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    >>> env.unwrapped.reward_kind, env.unwrapped.settings.progress_weight
    ('dense', 10.0)

    ```

    * ``observation_dtype``: ``"float32"`` (default) or ``"float64"`` (the game's state exactly, for
      a controller that models the arm; the bounds are the same).
    * ``reward``: ``"dense"`` (default), ``"sparse"`` or ``"score"``; ``progress_weight`` (0 to 1000 per
      metre, default 10) weighs the dense and the score rewards' shaping, ``hit_bonus`` (0 to 1000,
      default 1) the dense one's hits.
    * The harder tasks (``armgame.env.variants``; each off by default, the game itself):
      ``hold_time`` (s, 0 to 5: a hit counts once the hand has stayed in the target that long),
      ``motor_noise`` (0 to 1: signal-dependent noise, each muscle's force times ``1 + n``,
      ``n`` of that s.d., correlated over 50 ms), ``observation_delay`` (env steps, 0 to 100),
      ``field`` (``"curl"`` or ``"viscous"``) with ``field_strength`` (curl: ``b`` in N s/m, -50 to
      50; viscous: the lab's matrix times it, -2 to 2; default 1; a field game whose joint speed passes
      the declared bound stops, terminated, ``info["stopped"]`` saying why), ``target_radius`` (m, 0.001 to 0.2;
      default the game's 0.05). The suite's ids fix them: ``ReachHold-v1``, ``ReachNoisy-v1``,
      ``ReachDelay-v1``, ``ReachField-v1``, ``ReachHard-v1`` and their ``Continuous`` twins
      (``armgame.env.suite``).
    * What the observation hides (``armgame.env.variants``; the game unchanged): ``target_shown`` (s, 0 to
      3600; default None, always: the hand-to-target vector reads 0 once its target has been seen that long,
      at least one observation) and ``positions_only`` (default False: True reads 0 for the velocities and
      the activations). The separating tier's ids fix them: ``ReachMemory-v1`` (``target_shown=0.1``),
      ``ReachMemoryHold-v1`` (the same and ``hold_time=0.2``) and ``ReachPositions-v1`` (``positions_only=True``),
      key ids only (``armgame.env.suite.TIER``).
    * ``time_limit``, ``decision_steps`` (default 5: a 20 ms step), ``reset_key``, ``config``,
      ``render_mode`` (``"rgb_array"`` or ``"human"``), ``render_size``: as ``armgame/Reach-v0``.

    Since armgame 0.5.0 (unreleased): the observation's hiding arguments (``target_shown``, ``positions_only``)
    and the separating tier's ids ``ReachMemory-v1``, ``ReachMemoryHold-v1`` and ``ReachPositions-v1``, new ids
    of v1 that leave every other id's behaviour as it was.

    ## Version History

    * v1: hand position and velocity and the hand-to-target vector observed, float32; the
      fraction of time left instead of seconds; the target's position only relative to the hand;
      a dense reward by default; continuous actions in [-1, 1]; the score reward, the harder
      tasks' arguments and the suite's ids (armgame 0.2).
    * v0: Initial version (armgame 0.1).
    """

    version = 1

    def __init__(self, render_mode: str | None = None, *, time_limit: float | None = None,
                 decision_steps: int = DEFAULT_DECISION_STEPS, continuous: bool = False, reset_key: bool = False,
                 reward: str = "dense", progress_weight: float = DEFAULT_PROGRESS_WEIGHT,
                 hit_bonus: float = DEFAULT_HIT_BONUS, observation_dtype: str = "float32",
                 hold_time: float = 0.0, motor_noise: float = 0.0, observation_delay: int = 0,
                 field: str | None = None, field_strength: float | None = None, target_radius: float | None = None,
                 target_shown: float | None = None, positions_only: bool = False,
                 config: GameConfig | None = None, render_size: tuple[int, int] = (600, 600)) -> None:
        variant = ReachVariant.of(hold_time, motor_noise, observation_delay, field, field_strength, target_shown,
                                  positions_only)
        if target_radius is not None:
            config = with_target_radius(config or GameConfig(), target_radius)
        settings = ReachSettings.of(config, time_limit, decision_steps, continuous, reset_key, 1, reward,
                                    progress_weight, hit_bonus, observation_dtype, variant)
        self._configure(settings, render_mode, render_size)
        self.variant = variant
        self._edge = 0.0
        self._score = 0
        self._noise: MuscleNoise | None = None
        #: Why the game stopped before its clock ran out (a field's runaway), or None.
        self._stopped: str | None = None
        self._delayed = DelayedObservations(variant.observation_delay) if variant.observation_delay else None
        self._hidden = HiddenObservations(variant, settings.config.dt) if variant.hides else None

    @property
    def reward_kind(self) -> str:
        return self.settings.reward

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict]:
        observation, info = super().reset(seed=seed, options=options)
        # The score reward's potential is 0 at the reset by convention, so its shaping sums to nothing.
        self._edge = 0.0 if self.settings.reward == "score" else self._edge_now()
        self._score = 0
        if self._delayed is not None:
            observation = self._delayed.reset(observation)
        return observation, info

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict]:
        observation, reward, terminated, truncated, info = super().step(action)
        if self._delayed is not None:
            observation = self._delayed.step(observation)
        return observation, reward, terminated, truncated, info

    def _new_session(self, config: GameConfig) -> GameSession:
        self._stopped = None
        game = self.game_variant
        if game.plain:
            self._noise = None
            return GameSession(config)
        session = game.session(config)
        self._noise = game.noise(config, session)
        return session

    @property
    def game_variant(self) -> GameVariant:
        """The game's rules and physics of this env's variant, as its replay carries them (``armgame.env.record``)."""
        s = self.settings
        return self.variant.game_variant(s.config, s.decision_steps, s.joint_speed_bound)

    def _advance(self, session: GameSession) -> dict[str, Any]:
        """The decision's physics steps; a field's runaway ends the game where it began (``GameVariant``'s guard)."""
        try:
            session.advance(self.decision_steps)
        except RunawayError as exc:
            session.total_steps = session.steps  # the game is over here: its replay says so ("stopped")
            self._stopped = str(exc)
        return {} if self._stopped is None else {"stopped": self._stopped}

    def _before_advance(self, session: GameSession) -> None:
        if self._noise is not None:
            self._noise.apply(session)

    def _edge_now(self) -> float:
        session = self.session
        assert session is not None
        hx, hy = session.hand()
        target = session.rules.target
        return max(0.0, math.hypot(hx - target.x, hy - target.y) - target.radius)

    def _reward(self, hits: int, resets: int) -> float:
        s = self.settings
        if s.reward == "sparse":  # v0's reward: the game's score change, never floored
            return float(hits - self.config.reset_cost * resets)
        if s.reward == "score":
            return self._score_reward()
        before, self._edge = self._edge, self._edge_now()
        progress = before - (0.0 if hits else self._edge)
        return s.progress_weight * progress + s.hit_bonus * hits - self.config.reset_cost * resets

    def _score_reward(self) -> float:
        """The score's change plus ``w (phi' - phi)``, ``phi = -e`` (the edge distance), with ``phi = 0`` at the
        reset and at the game's end, so the shaping sums to exactly nothing over a game."""
        session = self.session
        assert session is not None
        score, self._score = self._score, session.rules.board.score
        before, self._edge = self._edge, 0.0 if session.over else self._edge_now()
        return float(self._score - score) + self.settings.progress_weight * (before - self._edge)

    def _observation(self) -> np.ndarray:
        session = self.session
        assert session is not None
        q1, q2, w1, w2 = session.state
        hx, hy, vx, vy = hand_and_velocity(self.config.arm, q1, q2, w1, w2)
        target = session.rules.target
        total = self.config.total_steps
        left = (total - min(session.steps, total)) / total
        observation = np.array((wrap_angle(q1), wrap_angle(q2), w1, w2, *session.muscles.activation, hx, hy, vx, vy,
                                target.x - hx, target.y - hy, left), dtype=self.settings.observation_dtype)
        if self._hidden is not None:  # before the delay: a delayed observation hides what it hid when made
            self._hidden.apply(observation, target, session.steps)
        return observation
