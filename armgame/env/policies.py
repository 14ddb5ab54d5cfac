"""The game's bots as Gymnasium policies: observation in, keys out.

``BotPolicy`` rebuilds, from an observation alone, the little a bot reads of a session (the
joint state, the four activations, the target, the clock) and turns the key events the bot
returns into a ``MultiBinary(4)`` action. What the bot knows besides (the arm, the muscles, the
physics step) is the game's description, ``env.unwrapped.config``, not its state: the bot never
sees the seed. The observation is float64, so the bot sees exactly what it sees in the game,
and with a decision step equal to its control period it plays exactly the game's game.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from ..game.bots import ReachingBot, make_bot
from ..game.muscles import MuscleSet
from ..game.rules import GameConfig, Target
from ..game.session import DOWN
from .features import hand_and_velocity


class _Rules:
    __slots__ = ("target",)

    def __init__(self, target: Target) -> None:
        self.target = target


class _SeenGame:
    """The part of a ``GameSession`` a bot reads, filled in from observations."""

    over = False

    def __init__(self, config: GameConfig, muscles: MuscleSet, target: Target) -> None:
        self.config = config
        self.muscles = muscles
        self.rules = _Rules(target)
        self.held = [False] * MuscleSet.COUNT
        self.state = (0.0, 0.0, 0.0, 0.0)
        self.time = 0.0


def _act(bot: ReachingBot, seen: _SeenGame, continuous: bool) -> np.ndarray:
    """The bot's decision on what it has seen, as an action: keys held, or levels -1 and 1, which act as keys."""
    keys = seen.muscles.keys
    for key, action in bot.act(seen):  # type: ignore[arg-type]  # quacks like a GameSession
        seen.held[keys.index(key)] = action == DOWN
    if continuous:
        return np.where(seen.held, 1.0, -1.0).astype(np.float32)
    return np.array(seen.held, dtype=np.int8)


class BotPolicy:
    """A bot (``"model"``, ``"naive"`` or a ``ReachingBot``) playing through a Reach env, v0 or v1.

    ``policy(observation) -> action``. It decides at every env step, so a bot made here gets the
    env's decision time as its control period; the game's bots decide every 4 ms, which
    ``decision_steps=1`` gives. A new episode is recognised by its clock (time left going up).
    On a v1 env it reads the target as the hand plus the hand-to-target vector (a target counts as
    the same while it moves less than a millimetre: float32 rounds the sum) and the time left from
    its fraction; on a continuous env it answers with levels -1 and 1, which act as its keys::

        >>> import gymnasium as gym
        >>> import armgame.env
        >>> env = gym.make("armgame/Reach-v1", time_limit=3.0)
        >>> policy = BotPolicy("model", env)
        >>> obs, info = env.reset(seed=10)
        >>> done = False
        >>> while not done:
        ...     obs, reward, terminated, truncated, info = env.step(policy(obs))
        ...     done = terminated or truncated
        >>> info["hits"] >= 1
        True

    A variant's noise, delay or field reaches the bot as it reaches any policy: it sees the delayed
    observation and knows nothing of the noise or the field.
    """

    #: A v1 target read from float32 observations moves by round-off only; a new target is at least
    #: three radii from the hand (``GameRules``), far beyond this.
    SAME_TARGET = 1e-3

    def __init__(self, bot: str | ReachingBot, env: Any) -> None:
        base = env.unwrapped
        settings = getattr(base, "settings", None)
        if settings is None or getattr(base, "family", None) != "Reach":
            raise ValueError("a bot plays armgame's Reach envs (armgame/Reach-v0, Reach-v1 and their variants)")
        if settings.reset_key:
            raise ValueError("a bot plays the four muscle keys: make the env without reset_key")
        self.version = settings.version
        self.continuous = settings.continuous
        if self.continuous and not self.version:
            raise ValueError("a bot plays armgame/ReachContinuous-v1, not -v0 (whose levels are not centred)")
        self.config: GameConfig = settings.config
        self.dt = self.config.dt
        self.total_steps = self.config.total_steps
        if isinstance(bot, str):
            make_bot(bot)  # refuses unknown names in the game's words
            bot = ReachingBot(bot, interaction=bot == "model", control_period=settings.decision_time)
        elif bot.period_steps(self.dt) != settings.decision_steps:
            raise ValueError(f"the bot decides every {bot.control_period} s, the env every "
                             f"{settings.decision_time} s: make it with control_period={settings.decision_time}")
        self.bot = bot
        self._muscles = MuscleSet(self.config.muscles, self.dt)
        self._seen: _SeenGame | None = None
        self._time_left = -1.0

    def reset(self) -> None:
        """Forget the game under way: the next observation starts a new game whatever its clock says
        (``armgame.env.evaluate`` calls it before every game)."""
        self._seen = None
        self._time_left = -1.0

    def _read(self, observation: np.ndarray) -> tuple[tuple[float, ...], tuple[float, ...], float, float, float]:
        """(joint state, activations, target x, target y, time left in s) from an observation of the env's version."""
        values = np.asarray(observation, dtype=np.float64).tolist()
        if not self.version:
            q1, q2, w1, w2, a0, a1, a2, a3, tx, ty, time_left = values
            return (q1, q2, w1, w2), (a0, a1, a2, a3), tx, ty, time_left
        q1, q2, w1, w2, a0, a1, a2, a3, hx, hy, _, _, dx, dy, fraction = values
        return (q1, q2, w1, w2), (a0, a1, a2, a3), hx + dx, hy + dy, fraction * self.total_steps * self.dt

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        state, activation, tx, ty, time_left = self._read(observation)
        seen = self._seen
        if seen is None or time_left > self._time_left:
            # A new game: a config of its own, so the bot binds afresh (its plan and memory cleared).
            seen = self._seen = _SeenGame(dataclasses.replace(self.config), self._muscles,
                                          Target(tx, ty, self.config.target_radius))
        self._time_left = time_left
        target = seen.rules.target
        if abs(tx - target.x) > self.SAME_TARGET or abs(ty - target.y) > self.SAME_TARGET \
                or (not self.version and (tx, ty) != (target.x, target.y)):
            seen.rules.target = Target(tx, ty, self.config.target_radius)
        seen.state = state  # type: ignore[assignment]
        seen.muscles.activation = list(activation)
        seen.time = (self.total_steps - round(time_left / self.dt)) * self.dt  # as GameSession.time
        return _act(self.bot, seen, self.continuous)


class CenterOutV1BotPolicy:
    """A bot (``"model"`` or ``"naive"``) playing ``armgame/CenterOut-v1`` (or a variant) from its observations.

    The shown target is the cursor plus the cursor-to-target vector (home during a hold): the bot reaches for
    it with the hand, as the game's bots reach for a target, and holds the posture there, which is what a
    trial's hold asks. It keeps its own clock (decisions times the decision step): the observation's time
    runs per phase, and the bot needs only time that moves on. Under a visual perturbation it aims the hand
    at the shown target, as a person does before adapting.

    >>> import gymnasium as gym
    >>> import armgame.env
    >>> env = gym.make("armgame/CenterOut-v1")
    >>> policy = CenterOutV1BotPolicy("model", env)
    >>> obs, info = env.reset(seed=3)
    >>> done = False
    >>> while not done:
    ...     obs, reward, terminated, truncated, info = env.step(policy(obs))
    ...     done = terminated or truncated
    >>> info["hits"]
    8
    """

    def __init__(self, bot: str, env: Any) -> None:
        base = env.unwrapped
        if getattr(base, "family", None) != "CenterOut" or getattr(base, "version", 0) < 1:
            raise ValueError("CenterOutV1BotPolicy plays armgame/CenterOut-v1 and its variants")
        make_bot(bot)  # refuses unknown names in the game's words
        from ..lab.session import lab_config  # the lab's arm, muscles and home, as the env's runs have them

        self.continuous = base.continuous
        self.protocol = base.protocol
        self.config: GameConfig = lab_config(self.protocol, 0)
        self.decision_time = base.decision_steps * self.config.dt
        self.name = bot
        self.home = hand_and_velocity(self.config.arm, *self.config.start_posture, 0.0, 0.0)[:2]
        self.reset()

    def reset(self) -> None:
        """A new episode: a new bot, its own clock from zero (``armgame.env.evaluate`` calls it before every
        game; a bot whose clock ran on from the last episode held home too long or too short)."""
        self.bot = ReachingBot(self.name, interaction=self.name == "model", control_period=self.decision_time)
        self._muscles = MuscleSet(self.config.muscles, self.config.dt)
        self._seen = _SeenGame(dataclasses.replace(self.config), self._muscles,
                               Target(*self.home, self.protocol.home_radius))
        self._decisions = 0

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        (q1, q2, w1, w2, a0, a1, a2, a3, cx, cy, _, _, dx, dy, phase, _) = \
            np.asarray(observation, dtype=np.float64).tolist()
        seen = self._seen
        tx, ty = self.home[0] + cx + dx, self.home[1] + cy + dy
        radius = self.protocol.target_radius if phase >= 0.5 else self.protocol.home_radius
        target = seen.rules.target
        if math.hypot(tx - target.x, ty - target.y) > BotPolicy.SAME_TARGET:
            seen.rules.target = Target(tx, ty, radius)
        seen.state = (q1, q2, w1, w2)
        seen.muscles.activation = [a0, a1, a2, a3]
        seen.time = self._decisions * self.decision_time
        self._decisions += 1
        return _act(self.bot, seen, self.continuous)


def bot_policy(bot: str, env: Any) -> BotPolicy | CenterOutV1BotPolicy:
    """The game's bot ``"naive"`` or ``"model"`` as a policy for ``env``: a Reach env (v0 or v1) or CenterOut-v1."""
    if getattr(env.unwrapped, "family", None) == "CenterOut":
        return CenterOutV1BotPolicy(bot, env)
    return BotPolicy(bot, env)
