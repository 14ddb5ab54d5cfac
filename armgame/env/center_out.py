"""``armgame/CenterOut-v0`` and ``armgame/CenterOutContinuous-v0``: a lab run of the centre-out task as an env.

The env is a thin shell over ``armgame.lab.session.LabSession``, the session ``armgame lab``
plays: an episode is one protocol run, with the same seed, trials, perturbations and key
timeline. The task's rules, the perturbations and the per-reach measures stay in
``armgame.lab``; this module owns the spaces, the reward and the options of a reset.
``CenterOutBotPolicy`` lets the lab's bots play through the env from its observations.

``CenterOutBaseEnv`` is what every version shares (the arguments, the run, a reset's options, the
frames): ``CenterOutEnv`` (v0) and ``center_out_v1.CenterOutV1Env`` derive from it as siblings.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Mapping
from dataclasses import replace
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from ..errors import UserError
from ..game.muscles import MuscleSet
from ..game.rules import MAX_CONFIG_SECONDS, Target
from ..game.session import DOWN
from ..game.variant import RunawayError
from ..lab.analysis import trial_row
from ..lab.bots import LAB_BOT_NAMES, make_lab_bot
from ..lab.perturbations import KINDS, NONE, Perturbation
from ..lab.presets import PRESETS, preset
from ..lab.protocol import MAX_TRIALS, Protocol, with_perturbation
from ..lab.session import HOLD, REACH, LabSession, lab_config
from ..physics.hand import hand_xy
from ..physics.twojoint import TwoJointArm
from ..words import unknown_name
from .base import EnvArgumentError, SessionEnv
from .reach import (
    DEFAULT_DECISION_STEPS,
    MAX_DECISION_STEPS,
    _check_size,
    check_seed,
    drawn_seed,
    speed_bound,
    wrap_angle,
)

OBSERVATION_NAMES = ("q1", "q2", "w1", "w2", "a_d", "a_f", "a_j", "a_k", "cursor_x", "cursor_y", "home_x", "home_y",
                     "target_x", "target_y", "phase", "time_in_phase", "trial", "time_left")
#: The lab's clock never runs longer than a game may (``lab_config``): a day.
MAX_RUN_SECONDS = MAX_CONFIG_SECONDS
#: Reward lost per second of the task's time.
DEFAULT_TIME_COST = 0.1


def protocol_option(value: object) -> Protocol:
    """A protocol from a preset name or a ``Protocol``."""
    if isinstance(value, Protocol):
        return value
    if isinstance(value, str):
        if value not in PRESETS:
            raise EnvArgumentError(f"protocol must be a lab preset ({', '.join(PRESETS)}) or an armgame Protocol, "
                                   f"got {value!r}")
        return preset(value)
    raise EnvArgumentError(f"protocol must be a lab preset name or an armgame Protocol, got {type(value).__name__}")


def perturbation_option(value: object) -> Perturbation:
    """A perturbation from a ``Perturbation``, a preset's name (its exposure: ``"curl"`` is b = 2 N s/m),
    ``"none"``, or a mapping in a protocol file's words, e.g. ``{"perturbation": "curl", "b": 5.0}``."""
    if isinstance(value, Perturbation):
        return value
    if isinstance(value, str):
        if value == "none":
            return NONE
        if value in PRESETS and value != "null":
            return next(b.perturbation for b in preset(value).blocks if b.perturbation.kind != "none")
        raise EnvArgumentError(f"perturbation {value!r}: give none, a preset's name (curl, rotation, mirror, "
                               "jointspace), a Perturbation or a mapping such as {'perturbation': 'curl', 'b': 5.0}")
    if isinstance(value, Mapping):
        values = dict(value)
        kind = values.pop("perturbation", None)
        if not isinstance(kind, str):
            raise EnvArgumentError("a perturbation mapping names its kind under 'perturbation'")
        known = KINDS.get(kind)
        if known is not None and "matrix" in values and "matrix" in known.file_keys():
            try:  # as a protocol file writes it: matrix = [[b11, b12], [b21, b22]]
                values.update(known.read({"matrix": values.pop("matrix")}).items())
            except UserError as exc:
                raise EnvArgumentError(f"perturbation {kind}: {exc}") from None
        limits = {p.name: p for p in known.parameters()} if known is not None else {}
        for name, number in values.items():
            if name in limits and (isinstance(number, bool) or not isinstance(number, int | float)
                                   or not limits[name].low <= number <= limits[name].high):
                raise EnvArgumentError(f"perturbation {kind}: {name} must be a number from {limits[name].low:g} "
                                       f"to {limits[name].high:g}, got {number!r}")
        try:
            return Perturbation.make(kind, **values)
        except UserError as exc:
            raise EnvArgumentError(str(exc)) from None
    raise EnvArgumentError(f"perturbation must be a Perturbation, a name or a mapping, got {type(value).__name__}")


def run_protocol(protocol: object, perturbation: object | None) -> Protocol:
    """The protocol an episode runs: ``protocol`` with ``perturbation`` (if given) in its perturbed blocks."""
    chosen = versioned_schedule(protocol_option(protocol))
    if perturbation is None:
        return chosen
    try:
        return with_perturbation(chosen, perturbation_option(perturbation))
    except EnvArgumentError:
        raise
    except UserError as exc:
        raise EnvArgumentError(str(exc)) from None


def versioned_schedule(protocol: Protocol) -> Protocol:
    """The protocol with the catch and channel trials placed as v0 and v1 always placed them (``random``), so
    these versioned envs run the trials they ran before the lab's ``balanced`` placement (issue 29); a
    protocol whose blocks name their directions (new with it, and needing it) keeps ``balanced``."""
    if any(b.directions is not None or b.probe_directions is not None for b in protocol.blocks):
        return protocol
    return replace(protocol, probe_schedule="random")


class CenterOutBaseEnv(SessionEnv):
    """What the CenterOut envs' versions share: the arguments every version takes, a ``LabSession`` run of
    the protocol made at a reset and driven a decision step at a time, a reset's options, and the frames.
    Each version is its own sibling subclass (as Gymnasium keeps its mujoco versions), giving its spaces,
    when an episode starts a run and ends, its reward, observation and ``info``; a change to one version
    never reaches another.
    """

    family = "CenterOut"
    #: The lab's rule, that a trial's go cue waits for the cursor to stay in home: each version says.
    hold_at_home: bool

    def _configure(self, render_mode: str | None, protocol: str | Protocol, perturbation: object | None,
                   decision_steps: int, continuous: bool, time_cost: float, render_size: tuple[int, int]) -> None:
        """The arguments every version takes, checked in this order (one line for the first bad one)."""
        self._check_render_mode(render_mode)
        if isinstance(decision_steps, bool) or not isinstance(decision_steps, int | np.integer) \
                or not 1 <= decision_steps <= MAX_DECISION_STEPS:
            raise EnvArgumentError(f"decision_steps must be a whole number of physics steps from 1 to "
                                   f"{MAX_DECISION_STEPS}, got {decision_steps!r}")
        if not isinstance(continuous, bool | np.bool_):
            raise EnvArgumentError(f"continuous must be True or False, got {continuous!r}")
        if isinstance(time_cost, bool) or not isinstance(time_cost, int | float) or not 0.0 <= time_cost <= 10.0:
            raise EnvArgumentError(f"time_cost must be a number from 0 to 10 (reward per second), got {time_cost!r}")
        self.protocol = run_protocol(protocol, perturbation)
        self.decision_steps = int(decision_steps)
        self.continuous = bool(continuous)
        self.time_cost = float(time_cost)
        self.render_mode = render_mode
        self.render_size = _check_size(render_size)
        base = lab_config(self.protocol, 0)
        self.decision_time = self.decision_steps * base.dt
        self.metadata = {**self.metadata, "render_fps": 1.0 / self.decision_time}
        self.session: LabSession | None = None
        self._view: Any = None  # armgame.ui.lab_env_view.LabEnvView, made on the first frame

    # ----------------------------------------------------------------- the API
    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict]:
        self._start_episode(seed, options)
        return self._first_view()

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict]:
        session = self._session_begun()
        if self._episode_over():
            raise gym.error.ResetNeeded("the episode is over: call reset() before another step()")
        if self.continuous:
            self._set_levels(action, 4)
        else:
            self._press_keys(action, 4)
        done, hits, steps = len(session.outcomes), session.rules.board.hits, session.steps
        with contextlib.suppress(RunawayError):  # the run ends at its last allowed state (LabSession's guard)
            session.advance(self.decision_steps)
        ran = session.steps - steps
        reward = self._reward(session.rules.board.hits - hits) - self.time_cost * ran * session.config.dt
        info = self._info()
        if len(session.outcomes) > done:
            info["reaches"] = [trial_row(session, o) for o in session.outcomes[done:]]
        if session.stopped is not None:
            info["stopped"] = session.stopped
        if self.render_mode == "human":
            self.render()
        truncated = session.over and not session.finished and session.stopped is None  # the run's clock ran out
        return self._observation(), reward, self._episode_over() and not truncated, truncated, info

    # ------------------------------------------------------- each version's own
    def _start_episode(self, seed: int | None, options: Mapping[str, Any] | None) -> None:
        """Start an episode: a new run (``_new_run``), or the next trials of the one under way."""
        raise NotImplementedError

    def _episode_over(self) -> bool:
        raise NotImplementedError

    def _reward(self, hits: int) -> float:
        """The step's reward from its hits, before the time cost."""
        raise NotImplementedError

    def _bounds(self, protocol: Protocol) -> tuple[np.ndarray, np.ndarray]:
        """The observation's bounds (float64) for runs of ``protocol``."""
        raise NotImplementedError

    def _observation(self) -> np.ndarray:
        raise NotImplementedError

    def _info(self) -> dict[str, Any]:
        raise NotImplementedError

    # --------------------------------------------------------------- shared
    def _new_run(self, seed: int | None, options: Mapping[str, Any] | None) -> None:
        if seed is not None:
            seed = check_seed(seed)
        if options:
            self._take_options(options)
        super().reset(seed=seed)
        lab_seed = seed if seed is not None else drawn_seed(self.np_random)
        try:
            config = lab_config(self.protocol, lab_seed)
            self.session = LabSession(config, self.protocol, hold_at_home=self.hold_at_home,
                                      speed_limit=speed_bound(config))
        except UserError as exc:  # a target out of the arm's reach, in the lab's words
            raise EnvArgumentError(str(exc)) from None

    def _take_options(self, options: Mapping[str, Any]) -> None:
        """A reset's ``protocol`` and ``perturbation``, refused if the observation space cannot bound them."""
        if not isinstance(options, Mapping):
            raise EnvArgumentError(f"options must be a dict, got {type(options).__name__}")
        unknown = set(options) - {"protocol", "perturbation"}
        if unknown:
            raise EnvArgumentError(f"unknown reset option(s) {', '.join(sorted(map(str, unknown)))}: "
                                   "choose protocol, perturbation")
        protocol = run_protocol(options.get("protocol", self.protocol), options.get("perturbation"))
        low, high = self._bounds(protocol)
        space = self.observation_space
        if np.any(low.astype(space.dtype) < space.low) or np.any(high.astype(space.dtype) > space.high):
            raise EnvArgumentError("a protocol with a jointspace display (an unbounded cursor) needs an env made "
                                   "with it, e.g. gym.make(id, protocol='jointspace'): this env's observation space "
                                   "bounds the cursor")
        self.protocol = protocol

    def _new_view(self) -> Any:
        from ..ui.lab_env_view import LabEnvView  # pygame is imported here and only here

        return LabEnvView(self.render_mode, self.render_size, self.metadata["render_fps"])


class CenterOutEnv(CenterOutBaseEnv):
    r"""
    ## Description

    The lab's centre-out reaching task (``armgame lab``; README "Lab"): the game's two-joint arm and
    four muscles, a home circle and targets 10 cm from it in 8 directions. Each trial: hold the
    cursor in home for a random 0.5-1.0 s, then at the go cue home goes, a target appears, and the
    cursor must reach it and stay 0.2 s inside (a hit) before a 3 s time-out; then the arm is put
    back at home at rest, muscles relaxed, and the next trial's hold begins. A protocol is blocks of
    trials (the presets: 16 baseline, 80 exposure, 24 washout); a block's perturbation is on from a
    trial's go cue to its end: a force field at the hand (``curl``, ``constant``, ``spring``) or a
    transform of the cursor (``rotation``, ``mirror``, ``jointspace``). The cursor is the hand as
    shown and scored: a visual transform moves what the task tests against home and the targets.

    An episode is exactly ``armgame lab PROTOCOL --seed S``: ``env.unwrapped.session`` is the
    ``LabSession``, whose key timeline (``session.timeline``) replays the run and whose
    ``outcomes`` are its trials.

    ## Action Space

    ``armgame/CenterOut-v0``: ``MultiBinary(4)``, the muscle keys held during the coming decision step.

    | Num | Key | Muscle            | Torque at full activation (N m) |
    |-----|-----|-------------------|---------------------------------|
    | 0   | d   | pectoralis        | shoulder +1.5                   |
    | 1   | f   | posterior deltoid | shoulder -1.5                   |
    | 2   | j   | biceps            | elbow +1.125                    |
    | 3   | k   | triceps           | elbow -1.125                    |

    ``armgame/CenterOutContinuous-v0``: ``Box(0, 1, (4,), float32)``, the level each muscle's
    activation moves toward (``GameSession.set_muscle_levels``; clipped to [0, 1], NaN refused).

    ## Observation Space

    ``Box(low, high, (18,), float64)``:

    | Num   | Observation                                        | Min    | Max    | Unit  |
    |-------|----------------------------------------------------|--------|--------|-------|
    | 0     | shoulder angle q1, from +x, counter-clockwise      | -pi    | pi     | rad   |
    | 1     | elbow angle q2, relative to the upper arm          | -pi    | pi     | rad   |
    | 2     | shoulder angular velocity                          | -34.4  | 34.4   | rad/s |
    | 3     | elbow angular velocity                             | -34.4  | 34.4   | rad/s |
    | 4-7   | activations of d, f, j, k                          | 0      | 1      |       |
    | 8-9   | cursor x, y: the hand as shown and scored          | -2.4   | 2.4    | m     |
    | 10-11 | home centre x, y                                   | -0.8   | 0.8    | m     |
    | 12-13 | the shown target's centre x, y: home in a hold     | -0.8   | 0.8    | m     |
    | 14    | phase: 0 hold (home shown), 1 reach (after go)     | 0      | 1      |       |
    | 15    | time since the phase began                         | 0      | 86400  | s     |
    | 16    | trials finished (the current trial's index)        | 0      | 2000   |       |
    | 17    | time left on the run's clock                       | 0      | 86400  | s     |

    Coordinates are the game's: x forward, y left, metres from the shoulder. Home and the targets are
    within the arm's reach (0.8 m). The cursor is the hand, or the hand rotated or mirrored about home,
    so within three arm's lengths (2.4 m) of the shoulder; the ``jointspace`` display shows it at
    ``home + gain (q - q_home)`` for joint angles that nothing bounds, so an env whose protocol (or
    perturbation) at ``make`` has that display observes the cursor in (-inf, inf) instead; an env made
    without it refuses a reset option that brings it in. The speed bound is proven for the arm and a
    curl field (which does no work); any other field (a constant force, a spring, a viscous or joint
    field, a channel) can feed the arm more energy, so a run whose joint speed would pass the bound
    stops at its last state within it, **terminated**, ``info["stopped"]`` saying why in one line, as
    ``armgame/Reach-v1``'s fields do. The angles are wrapped as in
    ``armgame/Reach-v0``. The run's clock is the lab's (``lab_config``: 1.5 times the slowest run's
    length plus 60 s, at most a day); a run that fidgets at home past it is truncated.

    ## Rewards

    +1 for each trial ended with a hit (the target reached and held), minus ``time_cost`` (default
    0.1) per second of the task's time, during the step. ``info["hits"]`` counts the hits.

    ## Starting State

    The arm at rest at the protocol's home posture (45 deg, 90 deg for the presets), muscles relaxed,
    home shown, the first trial's hold begun. The seed of ``reset(seed=s)`` is the lab's seed (0 to
    2^63 - 1: the trials' order, delays and catch trials); a reset without one draws it from the
    env's generator.

    ## Episode End

    1. Termination: when the protocol's last trial ends.
    2. Truncation: when the run's clock runs out first.

    At each step in which trials ended, ``info["reaches"]`` lists their rows of the lab's trials table
    (``armgame.lab.metrics.TRIAL_COLUMNS``: block, trial, target_deg, perturbation, reaction_time_s,
    movement_time_s, peak_speed_m_per_s, initial_direction_error_deg, max_perpendicular_error_m,
    path_length_ratio, hit, channel_force_peak_n, channel_force_at_peak_speed_n, adaptation_index,
    hand_sent_home;
    docs/lab.md "Measures"), measured on the cursor's path by
    ``armgame.lab.metrics.reach_metrics``. Every step's ``info`` has ``trials_done``, ``hits`` and
    ``block`` (the current block's name).

    ## Arguments

    ```python
    >>> import gymnasium as gym
    >>> import armgame.env
    >>> env = gym.make("armgame/CenterOut-v0", protocol="curl", decision_steps=5)
    >>> obs, info = env.reset(seed=10, options={"perturbation": {"perturbation": "curl", "b": 4.0}})
    >>> obs.shape, info
    ((18,), {'trials_done': 0, 'hits': 0, 'block': 'baseline'})
    >>> env.unwrapped.session.protocol.blocks[1].perturbation.label()
    'curl b=4 N s/m'

    ```

    * ``protocol``: a lab preset's name (``null``, ``curl``, ``rotation``, ``mirror``, ``jointspace``;
      default ``null``) or an ``armgame.lab.protocol.Protocol`` (``armgame.lab.protocol_file.load_protocol`` reads a
      TOML file).
    * ``perturbation``: replaces the protocol's perturbation in its perturbed blocks (in the ``null``
      preset: its exposure block): a ``Perturbation``, a preset's name for its exposure (``"curl"``,
      b = 2 N s/m), ``"none"``, or a mapping such as ``{"perturbation": "rotation", "angle": 45.0}``.
    * ``reset(options={"protocol": ..., "perturbation": ...})``: either for one episode (and the ones
      after it without options).
    * ``decision_steps``: physics steps (4 ms each) per env step, 1 to 1000 (default 5: 20 ms).
    * ``time_cost``: reward lost per second, 0 to 10 (default 0.1).
    * ``render_mode``: ``None``, ``"rgb_array"`` or ``"human"``: the lab window's view (cursor, home,
      target, trial counter, muscle bars) by ``armgame.ui.lab_window.LabRenderer``; ``render_size``
      ``(width, height)`` pixels (default ``(600, 600)``).

    Since issue 52 a field's runaway stops the run (terminated, ``info["stopped"]``) where it raised
    ``NonFiniteStateError`` or left the observation space, and a constant force or a spring no longer leaves the
    speeds unbounded: games that did neither are unchanged, so the version is too.

    ## Version History

    * v0: Initial version (armgame 0.1).
    """

    version = 0
    #: The lab's rule: a trial's go cue waits for the cursor to stay in home.
    hold_at_home = True

    def __init__(self, render_mode: str | None = None, *, protocol: str | Protocol = "null",
                 perturbation: object | None = None, decision_steps: int = DEFAULT_DECISION_STEPS,
                 continuous: bool = False, time_cost: float = DEFAULT_TIME_COST,
                 render_size: tuple[int, int] = (600, 600)) -> None:
        self._configure(render_mode, protocol, perturbation, decision_steps, continuous, time_cost, render_size)
        if self.continuous:
            self.action_space = spaces.Box(0.0, 1.0, (4,), np.float32)
        else:
            self.action_space = spaces.MultiBinary(4)
        self.observation_space = spaces.Box(*observation_bounds(self.protocol), dtype=np.float64)

    def _start_episode(self, seed: int | None, options: Mapping[str, Any] | None) -> None:
        """v0: every episode is a new run."""
        self._new_run(seed, options)

    def _episode_over(self) -> bool:
        assert self.session is not None
        return self.session.over

    def _reward(self, hits: int) -> float:
        return float(hits)

    def _bounds(self, protocol: Protocol) -> tuple[np.ndarray, np.ndarray]:
        return observation_bounds(protocol)

    def _observation(self) -> np.ndarray:
        s = self.session
        assert s is not None
        q1, q2, w1, w2 = s.state
        target = s.rules.target
        return np.array((wrap_angle(q1), wrap_angle(q2), w1, w2, *s.muscles.activation, *s.cursor, *s.home,
                         target.x, target.y, 1.0 if s.phase == REACH else 0.0,
                         (s.steps - s.phase_start_step) * s.config.dt, float(s.trial_index), s.time_left))

    def _info(self) -> dict[str, Any]:
        s = self.session
        assert s is not None
        return {"trials_done": len(s.outcomes), "hits": s.rules.board.hits, "block": s.block.name}


def observation_bounds(protocol: Protocol) -> tuple[np.ndarray, np.ndarray]:
    """The observation's bounds for runs of ``protocol``.

    The speed bound is the game's (``reach.speed_bound``: the energy the muscles can feed against the
    damping), which a curl field keeps (its force is perpendicular to the hand's velocity: it does no
    work). Every other field (a constant force, a spring, a viscous matrix, a joint field, a channel) can
    feed the arm energy of its own, so the run's speed guard holds the bound instead: a run whose joint
    speed would pass it stops there, terminated, ``info["stopped"]`` saying why (``LabSession.speed_limit``,
    as Reach-v1's fields). The joint-space display's cursor follows unbounded joint angles."""
    kinds = {p.kind for p in protocol.perturbations}
    config = lab_config(protocol, 0)
    reach = config.arm.l1 + config.arm.l2
    pi, day = math.pi, MAX_RUN_SECONDS
    speed = speed_bound(config)
    # |cursor - home| = |hand - home| <= |hand| + |home| under a rotation or mirror about home, both within reach.
    c = math.inf if "jointspace" in kinds else 3.0 * reach
    low = np.array([-pi, -pi, -speed, -speed, 0, 0, 0, 0, -c, -c, -reach, -reach, -reach, -reach, 0, 0, 0, 0])
    high = np.array([pi, pi, speed, speed, 1, 1, 1, 1, c, c, reach, reach, reach, reach, 1, day, MAX_TRIALS, day])
    return low, high


# ------------------------------------------------------------------ the lab's bots as policies
class _Outcome:
    __slots__ = ("plan",)

    def __init__(self, index: int, channel: bool) -> None:
        self.plan = _Plan(index, channel)


class _Plan:
    __slots__ = ("channel", "index")

    def __init__(self, index: int, channel: bool) -> None:
        self.index = index
        #: Whether the finished trial was an error-clamp trial: the player felt the channel hold the hand.
        self.channel = channel


class _Rules:
    __slots__ = ("target",)

    def __init__(self, target: Target) -> None:
        self.target = target


class _SeenLab:
    """The part of a ``LabSession`` a lab bot reads, filled in from observations and the task's description."""

    over = False

    def __init__(self, session: LabSession, target: Target) -> None:
        self.config = session.config
        self.protocol = session.protocol
        self.home = session.home
        self.model = TwoJointArm(session.config.arm)
        self.muscles = MuscleSet(session.config.muscles, session.config.dt)
        self.rules = _Rules(target)
        self.held = [False] * MuscleSet.COUNT
        self.state = (0.0, 0.0, 0.0, 0.0)
        self.cursor = session.home
        self.phase = HOLD
        self.trial_index = 0
        self.outcomes: list[_Outcome] = []
        self.time = 0.0

    def hand(self) -> tuple[float, float]:
        p = self.config.arm
        return hand_xy(p.l1, p.l2, self.state[0], self.state[1])


class CenterOutBotPolicy:
    """A lab bot (``model``, ``naive`` or ``adaptive``) playing ``armgame/CenterOut-v0`` from its observations.

    ``policy(observation) -> action``. What the bot reads of the run's state (the joints, the
    activations, the cursor, the shown target, the phase, the trial, the clock) comes from the
    observation; what it knows besides is the task's description: the arm, the muscles, home and the
    protocol's target distance, which it takes from ``env.unwrapped.session`` at each new episode
    (recognised by the clock's time left going up), never the seed or the trials to come. It decides
    at every env step, so with ``decision_steps=1`` (the lab bots' 4 ms) it plays exactly
    ``armgame lab --bot NAME`` on the same seed. A fresh bot plays each episode (an adaptive bot starts
    unadapted).
    """

    def __init__(self, bot: str, env: Any) -> None:
        if bot not in LAB_BOT_NAMES:
            raise UserError(unknown_name("lab bot", bot, LAB_BOT_NAMES))
        base = env.unwrapped
        if not isinstance(base, CenterOutEnv) or base.continuous:
            raise ValueError("a lab bot plays the keys of armgame/CenterOut-v0")
        self.name = bot
        self.env = base
        self.bot = make_lab_bot(bot)
        self._seen: _SeenLab | None = None
        self._time_left = -1.0

    def __call__(self, observation: np.ndarray) -> np.ndarray:
        (q1, q2, w1, w2, a0, a1, a2, a3, cx, cy, _hx, _hy, tx, ty, phase, _in_phase, trial,
         time_left) = observation.tolist()
        seen = self._seen
        if seen is None or time_left > self._time_left:
            session = self.env.session
            assert session is not None
            seen = self._seen = _SeenLab(session, Target(tx, ty, session.rules.target.radius))
            self.bot = make_lab_bot(self.name)
            self.bot.control_period = self.env.decision_time
        self._time_left = time_left
        target = seen.rules.target
        if (tx, ty) != (target.x, target.y):
            radius = seen.protocol.home_radius if phase == 0.0 else seen.protocol.target_radius
            seen.rules.target = Target(tx, ty, radius)
        index = int(trial)
        while len(seen.outcomes) < index:
            done = len(seen.outcomes)
            seen.outcomes.append(_Outcome(done, self.env.session.outcomes[done].plan.channel))
        seen.trial_index = index
        seen.phase = REACH if phase == 1.0 else HOLD
        seen.state = (q1, q2, w1, w2)
        seen.cursor = (cx, cy)
        seen.muscles.activation = [a0, a1, a2, a3]
        seen.time = (seen.config.total_steps - round(time_left / seen.config.dt)) * seen.config.dt
        keys = seen.muscles.keys
        for key, action in self.bot.act(seen):  # type: ignore[arg-type]  # quacks like a LabSession
            seen.held[keys.index(key)] = action == DOWN
        return np.array(seen.held, dtype=np.int8)


__all__ = ["OBSERVATION_NAMES", "CenterOutBotPolicy", "CenterOutEnv", "perturbation_option", "protocol_option",
           "run_protocol"]
