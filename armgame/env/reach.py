"""``armgame/Reach-v0`` and ``armgame/ReachContinuous-v0``: one game of armgame as a Gymnasium env.

The env is a thin shell over ``GameSession``: an action is a set of key events (or muscle
levels) applied before a decision step of several physics steps, exactly as a player's keys
reach the game, so an episode is a game with the same seed, rules and score. The spaces and the
reward are defined here once and shared with the vector env (``armgame.env.vector``).

What every version of the Reach envs shares is here too: their settings (``ReachSettings``, checked
once), the bounds and ``ReachBaseEnv``, the episode loop that ``ReachEnv`` (v0) and
``reach_v1.ReachV1Env`` each derive from as siblings.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from ..errors import UserError
from ..game.rules import MAX_CONFIG_SECONDS, GameConfig
from ..game.session import GameSession
from ..valid import INT64_MAX
from .base import EnvArgumentError, SessionEnv
from .features import REACH_REWARDS, check_dtype, check_reward, reach_bounds_v1
from .suite import TRAINING_SEED_LIMIT
from .variants import ReachVariant

#: Decision step of the standard envs in physics steps: 5 x 4 ms = 20 ms, a 50 Hz controller.
DEFAULT_DECISION_STEPS = 5
MAX_DECISION_STEPS = 1000
#: The longest game an env plays, in seconds: the game's own limit (``GameConfig``).
MAX_TIME_LIMIT = MAX_CONFIG_SECONDS
#: The game's seeds (``GameConfig.seed``) are whole numbers below this.
SEED_LIMIT = INT64_MAX + 1
OBSERVATION_NAMES = ("q1", "q2", "w1", "w2", "a_d", "a_f", "a_j", "a_k", "target_x", "target_y", "time_left")


@dataclasses.dataclass(frozen=True)
class ReachSettings:
    """The arguments of a Reach env, checked once and shared by the single and the vector env."""

    config: GameConfig
    decision_steps: int
    continuous: bool
    reset_key: bool
    #: 0: ``Reach-v0``'s spaces and reward; 1: ``Reach-v1``'s (``armgame.env.reach_v1``).
    version: int = 0
    reward: str = "sparse"
    progress_weight: float = 0.0
    hit_bonus: float = 1.0
    observation_dtype: str = "float64"
    #: v1's harder tasks (``armgame.env.variants``); the game itself by default.
    variant: ReachVariant = dataclasses.field(default_factory=ReachVariant)

    @classmethod
    def of(cls, config: GameConfig | None, time_limit: float | None, decision_steps: int, continuous: bool,
           reset_key: bool, version: int = 0, reward: str = "sparse", progress_weight: float = 0.0,
           hit_bonus: float = 1.0, observation_dtype: object = "float32",
           variant: ReachVariant | None = None) -> ReachSettings:
        if config is None:
            config = GameConfig()
        elif not isinstance(config, GameConfig):
            raise EnvArgumentError(f"config must be an armgame GameConfig, got {type(config).__name__}")
        if time_limit is not None:
            # At least one physics step: a game of none is over at its reset, and v1's observation divides
            # the time left by the game's length.
            low, high = config.dt, MAX_TIME_LIMIT
            if isinstance(time_limit, bool) or not isinstance(time_limit, int | float) \
                    or not (math.isfinite(time_limit) and low <= time_limit <= high):
                raise EnvArgumentError(f"time_limit must be a number of seconds from {low:g} (one physics step) "
                                       f"to {high:g}, got {time_limit!r}")
            try:
                config = dataclasses.replace(config, time_limit=float(time_limit))
            except UserError as exc:  # the game's own check, in its words
                raise EnvArgumentError(str(exc)) from None
        if config.total_steps < 1:
            raise EnvArgumentError(f"config.time_limit must be at least one physics step ({config.dt:g} s), got "
                                   f"{config.time_limit!r}")
        if isinstance(decision_steps, bool) or not isinstance(decision_steps, int | np.integer) \
                or not 1 <= decision_steps <= MAX_DECISION_STEPS:
            raise EnvArgumentError(f"decision_steps must be a whole number of physics steps from 1 to "
                                   f"{MAX_DECISION_STEPS}, got {decision_steps!r}")
        for name, flag in (("continuous", continuous), ("reset_key", reset_key)):
            if not isinstance(flag, bool | np.bool_):
                raise EnvArgumentError(f"{name} must be True or False, got {flag!r}")
        if version == 0:
            return cls(config, int(decision_steps), bool(continuous), bool(reset_key))
        reward, progress_weight, hit_bonus = check_reward(reward, progress_weight, hit_bonus, REACH_REWARDS)
        return cls(config, int(decision_steps), bool(continuous), bool(reset_key), 1, reward, progress_weight,
                   hit_bonus, check_dtype(observation_dtype), variant or ReachVariant())

    @property
    def joint_speed_bound(self) -> float:
        """Either joint's speed bound (rad/s) for these settings: the arm's energy bound with the muscles as
        strong as the variant's noise can make them (a field's game is held to it by the variant's guard)."""
        return speed_bound(self.variant.bound_config(self.config))

    @property
    def decision_time(self) -> float:
        """Seconds of game time per env step."""
        return self.decision_steps * self.config.dt

    @property
    def episode_steps(self) -> int:
        """Env steps in a whole game (the last one may hold fewer physics steps)."""
        return -(-self.config.total_steps // self.decision_steps)

    def game(self, seed: int) -> GameConfig:
        return dataclasses.replace(self.config, seed=seed)

    @property
    def action_width(self) -> int:
        return 5 if self.reset_key else 4

    def action_space(self) -> spaces.Space:
        n = self.action_width
        if self.continuous:
            # v1: centred on 0, as SB3's Gaussian policies (and their squashing) expect by default.
            return spaces.Box(-1.0 if self.version else 0.0, 1.0, (n,), np.float32)
        return spaces.MultiBinary(n)

    def observation_space(self) -> spaces.Box:
        if self.version:
            # A viscous field's symmetric part does work on the arm, so no energy bound holds under it: its game
            # stops at this bound instead (armgame.game.variant's guard), so the bound is declared all the same.
            low, high = reach_bounds_v1(self.config, self.joint_speed_bound)
            dtype = np.dtype(self.observation_dtype)
            return spaces.Box(low.astype(dtype), high.astype(dtype), dtype=dtype)
        low, high = observation_bounds(self.config)
        return spaces.Box(low, high, dtype=np.float64)


def speed_bound(config: GameConfig) -> float:
    """A bound on either joint speed (rad/s) that no action can break, from the arm's energy.

    With no gravity the Coriolis-centrifugal torques do no work, so the kinetic energy
    ``E = w'M(q)w / 2`` changes at ``tau'w - w'Bw <= |tau| |w| - b |w|^2`` (``b`` the smaller joint
    damping). Above ``|w| = |tau| / b`` it can only fall, so from rest (every game and every
    reset starts at rest) ``E <= lmax (|tau| / b)^2 / 2`` and ``|w| <= sqrt(lmax / lmin) |tau| / b``,
    with ``lmin``, ``lmax`` the extreme eigenvalues of M over all elbow angles and ``|tau|`` the
    largest joint torque the muscles make together. About 34 rad/s for the game's arm, plus 1 %
    for the integrator's error. Infinite for an arm with gravity or without damping.
    """
    p = config.arm
    damping = min(p.damping1, p.damping2)
    if p.has_gravity or damping <= 0.0:
        return math.inf
    a = p.i1 + p.i2 + p.m1 * p.r1**2 + p.m2 * (p.l1**2 + p.r2**2)
    b, d = p.m2 * p.l1 * p.r2, p.i2 + p.m2 * p.r2**2
    c = np.cos(np.linspace(0.0, math.pi, 4097))  # M depends on q2 through cos q2 only
    trace, det = a + d + 2.0 * b * c, (a + 2.0 * b * c) * d - (d + b * c) ** 2
    root = np.sqrt(trace**2 - 4.0 * det)
    lmin, lmax = float(np.min((trace - root) / 2.0)), float(np.max((trace + root) / 2.0))
    # |sum a_i m_i| is convex in the activations, so its largest value is at a corner of [0, 1]^4.
    moments = [m.moment for m in config.muscles]
    torque = max(math.hypot(sum(m[0] for m, on in zip(moments, corner, strict=True) if on),
                            sum(m[1] for m, on in zip(moments, corner, strict=True) if on))
                 for corner in itertools.product((False, True), repeat=len(moments)))
    return 1.01 * math.sqrt(lmax / lmin) * torque / damping


def observation_bounds(config: GameConfig) -> tuple[np.ndarray, np.ndarray]:
    xmin, xmax, ymin, ymax = config.view
    r, w = config.target_radius, speed_bound(config)
    low = np.array([-math.pi, -math.pi, -w, -w, 0, 0, 0, 0, xmin + r, ymin + r, 0.0])
    # The clock runs in whole physics steps: 0.23 s at 4 ms is 58 steps, 0.232 s.
    high = np.array([math.pi, math.pi, w, w, 1, 1, 1, 1, xmax - r, ymax - r, config.total_steps * config.dt])
    return low, high


def wrap_angle(q: float) -> float:
    """``q`` in [-pi, pi]: itself when already there, else ``q - 2 pi round(q / 2 pi)``."""
    if -math.pi <= q <= math.pi:
        return q
    return min(max(q - math.tau * round(q / math.tau), -math.pi), math.pi)


def check_seed(seed: object) -> int:
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or not 0 <= seed < SEED_LIMIT:
        raise EnvArgumentError(f"seed must be a whole number from 0 to 2^63 - 1, got {seed!r}")
    return int(seed)


def drawn_seed(generator: np.random.Generator) -> int:
    """The game seed of a reset without one, from the env's generator: below ``suite.TRAINING_SEED_LIMIT``, so that
    an autoreset (every training game after the first) is a training game by construction, never a validation or
    test game (before issue 52 it took any 63-bit seed, and missed those ranges only by chance)."""
    return int(generator.integers(TRAINING_SEED_LIMIT))


class ReachBaseEnv(SessionEnv):
    """What the Reach envs' versions share: a ``GameSession`` made at each reset and driven a decision step
    at a time (``reset``, ``step``, ``info``, frames). Each version is its own sibling subclass (as
    Gymnasium keeps its mujoco versions), giving its session, what happens before and during a decision's
    physics steps, its reward and its observation; a change to one version never reaches another.
    """

    family = "Reach"

    def _configure(self, settings: ReachSettings, render_mode: str | None, render_size: tuple[int, int]) -> None:
        self._check_render_mode(render_mode)
        self.settings = settings
        self.version = settings.version
        self.continuous = self.settings.continuous
        self.config = self.settings.config
        self.decision_steps = self.settings.decision_steps
        self.decision_time = self.settings.decision_time
        self.render_mode = render_mode
        self.render_size = _check_size(render_size)
        self.metadata = {**self.metadata, "render_fps": 1.0 / self.decision_time}
        self.action_space = self.settings.action_space()
        self.observation_space = self.settings.observation_space()
        self.session: GameSession | None = None
        self._view: Any = None  # armgame.ui.env_view.EnvView, made on the first frame

    # ----------------------------------------------------------------- the API
    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict]:
        if seed is not None:
            seed = check_seed(seed)
        super().reset(seed=seed)
        game_seed = seed if seed is not None else drawn_seed(self.np_random)
        self.session = self._new_session(self.settings.game(game_seed))
        return self._first_view()

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict]:
        session = self._session_begun()
        if session.over:
            raise gym.error.ResetNeeded("the game is over (truncated): call reset() before another step()")
        board = session.rules.board
        hits, resets = board.hits, board.resets
        if self.continuous:
            self._set_levels(action, self.action_space.shape[0])
        else:
            self._press_keys(action, self.action_space.n)
        self._before_advance(session)
        stopped = self._advance(session)
        reward = self._reward(board.hits - hits, board.resets - resets)
        if self.render_mode == "human":
            self.render()
        if stopped:  # the game ended before its clock: terminated, with the reason in one line
            return self._observation(), reward, True, False, self._info() | stopped
        return self._observation(), reward, False, session.over, self._info()

    # ------------------------------------------------------- each version's own
    def _new_session(self, config: GameConfig) -> GameSession:
        """The game of an episode, of ``config`` (the settings' game with the episode's seed)."""
        raise NotImplementedError

    def _before_advance(self, session: GameSession) -> None:
        """What the version does to the game before each decision's physics steps."""
        raise NotImplementedError

    def _advance(self, session: GameSession) -> dict[str, Any]:
        """Run the decision's physics steps; what stopped the game early, for ``info`` (empty: nothing did)."""
        raise NotImplementedError

    def _reward(self, hits: int, resets: int) -> float:
        """The step's reward from its hits and reset presses."""
        raise NotImplementedError

    def _observation(self) -> np.ndarray:
        raise NotImplementedError

    # --------------------------------------------------------------- shared
    def _new_view(self) -> Any:
        from ..ui.env_view import EnvView  # pygame is imported here and only here

        return EnvView(self.render_mode, self.render_size, self.metadata["render_fps"])

    def _info(self) -> dict[str, int]:
        assert self.session is not None
        board = self.session.rules.board
        return {"score": board.score, "hits": board.hits, "resets": board.resets}


class ReachEnv(ReachBaseEnv):
    r"""
    ## Description

    The armgame game: a two-joint arm (shoulder and elbow) moving in the horizontal plane with
    joint viscosity, driven by four muscles, has to put its hand on red targets. A hit scores a
    point and a new target appears at once elsewhere in the workspace; the game lasts 60 s. The
    dynamics are the Lagrangian equations of motion ``tau = M(q) qdd + C(q, qd) + B qd`` stepped by
    RK4 at 250 Hz, and each muscle's activation follows first-order dynamics toward its command
    (rise 80 ms, decay 100 ms); see the README's "play" section and ``armgame.game``.

    An episode is exactly a game of ``armgame play`` with the same seed: ``reset(seed=10)`` shows
    the targets of ``armgame play --seed 10``, and with key actions the episode's key timeline
    (``env.unwrapped.session.timeline``) replays to the same score.

    ## Action Space

    ``armgame/Reach-v0``: ``MultiBinary(4)``, the muscle keys held during the coming decision step.

    | Num | Key | Muscle            | Torque at full activation (N m) |
    |-----|-----|-------------------|---------------------------------|
    | 0   | d   | pectoralis        | shoulder +1.5                   |
    | 1   | f   | posterior deltoid | shoulder -1.5                   |
    | 2   | j   | biceps            | elbow +1.125                    |
    | 3   | k   | triceps           | elbow -1.125                    |

    A 1 holds the key (the activation rises toward 1), a 0 releases it (it decays toward 0).

    ``armgame/ReachContinuous-v0``: ``Box(0, 1, (4,), float32)``, the level each muscle's activation
    moves toward (``GameSession.set_muscle_levels``), same order; values outside [0, 1] are
    clipped, NaN is refused.

    With ``reset_key=True`` a fifth component presses the reset key (space) at the start of the
    step (for the continuous env: a value of 0.5 or more). A reset puts the arm back at rest in its
    start posture with the muscles relaxed and costs the reset cost (1 point). Off by default: a
    player resets to get out of a bad posture, which an agent can always steer out of, and the
    keys alone are the game's skill.

    ## Observation Space

    ``Box(low, high, (11,), float64)`` (float64 so that a controller sees the game's state exactly):

    | Num | Observation                                  | Min     | Max      | Unit  |
    |-----|----------------------------------------------|---------|----------|-------|
    | 0   | shoulder angle q1, from +x, counter-clockwise | -pi     | pi       | rad   |
    | 1   | elbow angle q2, relative to the upper arm     | -pi     | pi       | rad   |
    | 2   | shoulder angular velocity                     | -34.4   | 34.4     | rad/s |
    | 3   | elbow angular velocity                        | -34.4   | 34.4     | rad/s |
    | 4-7 | activations of d, f, j, k                     | 0       | 1        |       |
    | 8   | target centre x (forward)                     | -0.75   | 0.75     | m     |
    | 9   | target centre y (left)                        | -0.35   | 1.15     | m     |
    | 10  | time left in the game                         | 0       | 60       | s     |

    Angles are wrapped into [-pi, pi] (the game itself does not wrap them). The velocity bound
    is proven, not observed (``speed_bound``: the arm's energy from rest cannot exceed what the
    muscles can feed against the damping). The target, of radius 0.05 m, is always wholly inside
    the game's view, the square x in [-0.8, 0.8] m, y in [-0.4, 1.2] m around the shoulder at the
    origin. The hand is at ``(l1 cos q1 + l2 cos(q1 + q2), l1 sin q1 + l2 sin(q1 + q2))`` with
    ``l1 = 0.34`` m and ``l2 = 0.46`` m.

    ## Rewards

    +1 for each hit, minus the reset cost (1) for each reset, during the step. The return of an
    episode is the game's score, except that the game's score never drops below 0 and the return
    can (only with ``reset_key=True``). ``info`` carries the game's ``score``, ``hits`` and ``resets``
    so far.

    ## Starting State

    The arm at rest at q1 = 45 deg, q2 = 90 deg, muscles relaxed, the first target of the
    game's seed on screen. The seed of ``reset(seed=s)`` is the game's seed (0 to 2^63 - 1); a reset
    without a seed draws the game's seed from the env's generator (``env.np_random``), so a seeded
    first reset fixes every later episode.

    ## Episode End

    1. Termination: never; the game has no terminal state.
    2. Truncation: when the game's clock runs out (``time_limit``, 60 s: 3,000 steps of 20 ms).
       The time left is in the observation, so a learner can tell the end coming.

    ## Arguments

    ```python
    >>> import gymnasium as gym
    >>> import armgame.env
    >>> env = gym.make("armgame/Reach-v0", time_limit=10.0, decision_steps=5)
    >>> obs, info = env.reset(seed=10)
    >>> obs.shape, info
    ((11,), {'score': 0, 'hits': 0, 'resets': 0})
    >>> env.unwrapped.decision_time, env.unwrapped.settings.episode_steps
    (0.02, 500)

    ```

    * ``render_mode``: ``None``, ``"rgb_array"`` (frames of ``render_size`` pixels, the game's own
      renderer) or ``"human"`` (a window, paced to real time: ``render_fps`` = 1 / decision time).
    * ``time_limit``: the game's length in seconds (default: the game's 60 s).
    * ``decision_steps``: physics steps (4 ms each) per env step, 1 to 1000 (default 5: 20 ms).
    * ``reset_key``: adds the reset key as a fifth action (default ``False``).
    * ``config``: a whole ``armgame.game.rules.GameConfig`` for a variant of the game (its seed is
      replaced by each reset's); ``time_limit`` overrides its time limit.
    * ``render_size``: ``(width, height)`` of the frames in pixels (default ``(600, 600)``).

    ## Version History

    * v0: Initial version (armgame 0.1).
    """

    version = 0

    def __init__(self, render_mode: str | None = None, *, time_limit: float | None = None,
                 decision_steps: int = DEFAULT_DECISION_STEPS, continuous: bool = False, reset_key: bool = False,
                 config: GameConfig | None = None, render_size: tuple[int, int] = (600, 600)) -> None:
        self._configure(ReachSettings.of(config, time_limit, decision_steps, continuous, reset_key), render_mode,
                        render_size)

    def _new_session(self, config: GameConfig) -> GameSession:
        return GameSession(config)

    def _before_advance(self, session: GameSession) -> None:
        """v0: nothing."""

    def _advance(self, session: GameSession) -> dict[str, Any]:
        """v0: the decision's physics steps, which nothing stops early."""
        session.advance(self.decision_steps)
        return {}

    def _reward(self, hits: int, resets: int) -> float:
        """v0: the game's score change, never floored."""
        return float(hits - self.config.reset_cost * resets)

    def _observation(self) -> np.ndarray:
        session = self.session
        assert session is not None
        q1, q2, w1, w2 = session.state
        target = session.rules.target
        return np.array((wrap_angle(q1), wrap_angle(q2), w1, w2,
                         *session.muscles.activation, target.x, target.y, session.time_left))


def _check_size(size: object) -> tuple[int, int]:
    if not (isinstance(size, tuple | list) and len(size) == 2
            and all(isinstance(v, int) and not isinstance(v, bool) and 16 <= v <= 8192 for v in size)):
        raise EnvArgumentError(f"render_size must be (width, height), 16 to 8192 pixels each, got {size!r}")
    return int(size[0]), int(size[1])
