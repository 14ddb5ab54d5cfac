"""``armgame/CenterOut-v1`` and ``armgame/CenterOutContinuous-v1``: the lab's task, shaped so an agent can start.

v0 is a whole 120-trial lab run with the human's rule that a trial waits for the cursor to stay in
home: random keys never hold still, so no trial starts and nothing is learned. v1 starts each trial
after its delay wherever the cursor is (``LabSession(hold_at_home=False)``; the human lab keeps its
hold), ends an episode after a set number of trials or a block, observes what a learner needs
(float32, bounded) and rewards progress toward the shown target. The task, its perturbations and its
per-reach measures are still the lab's (``armgame.lab``), so an agent's reaches are measured as a
student's are. ``CenterOutVectorEnv`` is the vector entry point.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, SyncVectorEnv

from ..lab.protocol import Protocol
from ..lab.session import REACH, lab_config
from .base import EnvArgumentError
from .center_out import MAX_RUN_SECONDS, CenterOutBaseEnv
from .features import DEFAULT_HIT_BONUS, DEFAULT_PROGRESS_WEIGHT, check_dtype, check_reward, hand_and_velocity
from .reach import DEFAULT_DECISION_STEPS, speed_bound, wrap_angle
from .vector_common import AutoresetBook

OBSERVATION_NAMES_V1 = ("q1", "q2", "w1", "w2", "a_d", "a_f", "a_j", "a_k", "cursor_from_home_x", "cursor_from_home_y",
                        "hand_vx", "hand_vy", "to_target_x", "to_target_y", "phase", "time_in_phase")
#: Trials in an episode by default: one of each of the eight targets, about 15 to 30 s of the task.
DEFAULT_EPISODE_TRIALS = 8
TRIAL_STARTS = ("delay", "hold")


def observation_bounds_v1(protocol: Protocol, trial_start: str) -> tuple[np.ndarray, np.ndarray]:
    """The bounds of a CenterOut-v1 observation for runs of ``protocol`` (float64; see ``CenterOutV1Env``)."""
    kinds = {p.kind for p in protocol.perturbations}
    config = lab_config(protocol, 0)
    reach = config.arm.l1 + config.arm.l2
    w = speed_bound(config)  # held by the run's speed guard under any field (``center_out.observation_bounds``)
    v = (config.arm.l1 + 2.0 * config.arm.l2) * w
    # The cursor is the hand, or the hand rotated or mirrored about home: within 2 reaches of home and
    # 3 of the shoulder; a shown target (home or a target) lies within reach of the shoulder.
    c, t = (math.inf, math.inf) if "jointspace" in kinds else (2.0 * reach, 4.0 * reach)
    # A phase lasts at most the longest delay (a hold, when the go cue does not wait) or the time-out.
    phase = max(protocol.delay[1], protocol.timeout) + config.dt if trial_start == "delay" else MAX_RUN_SECONDS
    pi = math.pi
    low = np.array([-pi, -pi, -w, -w, 0, 0, 0, 0, -c, -c, -v, -v, -t, -t, 0, 0])
    high = np.array([pi, pi, w, w, 1, 1, 1, 1, c, c, v, v, t, t, 1, phase])
    return low, high


class CenterOutV1Env(CenterOutBaseEnv):
    r"""
    ## Description

    The lab's centre-out reaching task (docs/lab.md; ``armgame/CenterOut-v0``): the game's arm and
    muscles, a home circle and targets 10 cm from it in 8 directions. A trial: a hold at home for
    the trial's delay (0.5-1.0 s), the go cue (the target appears), then 3 s to bring the cursor
    into the target and keep it there 0.2 s (a hit); then the arm goes home at rest and the next
    trial begins. A block's perturbation (a force field at the hand, or a transform of the cursor)
    is on from a trial's go cue to its end.

    By default (``trial_start="delay"``) the go cue comes the trial's delay after the trial began,
    wherever the cursor is: a policy that cannot hold still yet still meets targets. With
    ``trial_start="hold"`` the cue waits, as for a person, for the cursor to stay in home that long:
    ``armgame/CenterOutHold-v1`` (and ``CenterOutHoldContinuous-v1``) fixes it, the suite's
    CenterOut task that needs a stop at home before every reach as well as at the target.

    ## Action Space

    ``armgame/CenterOut-v1``: ``MultiBinary(4)``, the muscle keys d, f, j, k held (shoulder flexor
    and extensor, elbow flexor and extensor). ``armgame/CenterOutContinuous-v1``: ``Box(-1, 1, (4,),
    float32)``, muscle level ``(a + 1) / 2``, as ``armgame/ReachContinuous-v1``.

    ## Observation Space

    ``Box(low, high, (16,), float32)``:

    | Num   | Observation                                      | Min    | Max   | Unit  |
    |-------|--------------------------------------------------|--------|-------|-------|
    | 0-1   | shoulder and elbow angles, wrapped               | -pi    | pi    | rad   |
    | 2-3   | joint angular velocities                         | -34.4  | 34.4  | rad/s |
    | 4-7   | activations of d, f, j, k                        | 0      | 1     |       |
    | 8-9   | the cursor (the hand as shown) from home's centre | -1.6   | 1.6   | m     |
    | 10-11 | the hand's velocity (as felt, not as shown)      | -43.3  | 43.3  | m/s   |
    | 12-13 | from the cursor to the shown target's centre     | -3.2   | 3.2   | m     |
    | 14    | phase: 0 hold (home shown), 1 reach (after go)   | 0      | 1     |       |
    | 15    | time since the phase began                       | 0      | 3.004 | s     |

    The shown target is home during a hold. A protocol with a ``jointspace`` display leaves the
    cursor unbounded, as in v0, and a field's runaway stops the run at the speed bound, terminated,
    ``info["stopped"]`` saying why (v0's guard); with
    ``trial_start="hold"`` a hold has no end, so time in phase is bounded by a day.

    ## Rewards

    ``reward="dense"`` (default): ``w (e_prev - e) + bonus * hits - time_cost * seconds``, with ``e``
    the cursor's distance to the shown target's edge at the end of the step. On a step in which the
    shown target changes (the go cue, a trial's end) the progress term is 0 and restarts from the
    new target, so neither a far target nor the return home costs anything. ``w =
    progress_weight`` (10 per metre), ``bonus = hit_bonus`` (1), ``time_cost`` 0 by default.
    ``reward="sparse"``: ``hits - time_cost * seconds``, as v0.

    ## Starting State and Episodes

    ``reset(seed=s)`` starts a run of the protocol with lab seed ``s`` (its trials' order and
    delays), the arm at rest at home, at the start of the run's first trial. An episode is
    ``episode_trials`` trials (default 8), or with ``episode_trials="block"`` the rest of the current
    block; it ends **terminated** after its last trial. A ``reset()`` without a seed (an autoreset)
    starts a fresh episode as Gymnasium's envs do: a new run, its lab seed drawn from the env's
    generator, so every episode is a run's first trials, whenever the reset comes. Episodes then
    never leave the first ``episode_trials`` trials: a protocol's later blocks (the ``curl``
    preset's exposure after its baseline) need ``continue_run=True``.

    ``continue_run=True`` makes a protocol's blocks follow one another over episodes, as a
    participant's do: a ``reset()`` without a seed after an episode ended continues the same run at
    its next trial (the arm went home at rest when the last trial ended, within the episode's last
    step, so that episode starts at a trial's beginning too); once the run's last trial is done, or
    if the reset comes mid-episode (the trial under way cannot end early), it starts a new run with
    a seed from the env's generator. ``reset(options={"protocol": ..., "perturbation": ...})``
    starts a new run of those. The episode is truncated if the run's clock runs out (only possible
    with ``trial_start="hold"``).

    ``info``: ``trial`` (the index in the run of the trial under way, or of the next), ``trials_done``,
    ``hits``, ``block`` and, on a step in which trials ended, ``reaches``: their rows of the lab's
    trials table (``armgame.lab.metrics.TRIAL_COLUMNS``), measured on the cursor's path.

    ## Arguments

    ```python
    >>> import gymnasium as gym
    >>> import armgame.env
    >>> env = gym.make("armgame/CenterOut-v1", protocol="curl", episode_trials="block")
    >>> obs, info = env.reset(seed=10)
    >>> obs.shape, obs.dtype, info
    ((16,), dtype('float32'), {'trial': 0, 'trials_done': 0, 'hits': 0, 'block': 'baseline'})

    ```

    * ``protocol``, ``perturbation``, ``decision_steps``, ``render_mode``, ``render_size``: as v0.
    * ``trial_start``: ``"delay"`` (default) or ``"hold"`` (the lab's rule for people).
    * ``episode_trials``: trials per episode, 1 to 2000, or ``"block"`` (default 8).
    * ``continue_run``: ``False`` (default): every reset starts a new run; ``True``: a reset after an
      episode's end continues the run at its next trial, so episodes walk through the protocol's
      blocks.
    * ``reward`` (``"dense"`` or ``"sparse"``), ``progress_weight``, ``hit_bonus``,
      ``observation_dtype`` (``"float32"`` or ``"float64"``): as ``armgame/Reach-v1``; ``time_cost``:
      reward lost per second, 0 to 10 (default 0).

    Since issue 52 a field's runaway stops the run (v0's note) and an unseeded reset draws its seed below 10^9
    (the training seeds): games that did neither are unchanged, so the version is too.

    ## Version History

    * v1: trials start after their delay; episodes of a few trials or a block; the cursor, the
      hand's velocity and the cursor-to-target vector observed, float32, with no run clock or trial
      count; a dense reward; continuous actions in [-1, 1]; ``info["trial"]``; a reset without a
      seed starts a new run, ``continue_run=True`` continues the run over episodes (checkouts of
      the v1 env before armgame 0.2.0, which still called themselves 0.1.0, always continued the
      run, and a reset mid-episode changed nothing); ``armgame/CenterOutHold-v1`` and its
      ``Continuous`` twin registered, ``trial_start="hold"`` fixed (armgame 0.2).
    * v0: Initial version (armgame 0.1).
    """

    version = 1

    def __init__(self, render_mode: str | None = None, *, protocol: str | Protocol = "null",
                 perturbation: object | None = None, decision_steps: int = DEFAULT_DECISION_STEPS,
                 continuous: bool = False, trial_start: str = "delay",
                 episode_trials: int | str = DEFAULT_EPISODE_TRIALS, continue_run: bool = False,
                 reward: str = "dense",
                 progress_weight: float = DEFAULT_PROGRESS_WEIGHT, hit_bonus: float = DEFAULT_HIT_BONUS,
                 time_cost: float = 0.0, observation_dtype: str = "float32",
                 render_size: tuple[int, int] = (600, 600)) -> None:
        self._configure(render_mode, protocol, perturbation, decision_steps, continuous, time_cost, render_size)
        if trial_start not in TRIAL_STARTS:
            raise EnvArgumentError(f"trial_start must be 'delay' or 'hold', got {trial_start!r}")
        if episode_trials != "block" and (isinstance(episode_trials, bool)
                                          or not isinstance(episode_trials, int | np.integer)
                                          or not 1 <= episode_trials <= 2000):
            raise EnvArgumentError(f"episode_trials must be a whole number from 1 to 2000 or 'block', "
                                   f"got {episode_trials!r}")
        if not isinstance(continue_run, bool | np.bool_):
            raise EnvArgumentError(f"continue_run must be True or False, got {continue_run!r}")
        self.reward_kind, self.progress_weight, self.hit_bonus = check_reward(reward, progress_weight, hit_bonus)
        self.continue_run = bool(continue_run)
        self.trial_start = trial_start
        self.hold_at_home = trial_start == "hold"
        self.episode_trials = episode_trials if episode_trials == "block" else int(episode_trials)
        self.action_space = spaces.Box(-1.0, 1.0, (4,), np.float32) if self.continuous else spaces.MultiBinary(4)
        low, high = observation_bounds_v1(self.protocol, trial_start)
        self.observation_dtype = dtype = np.dtype(check_dtype(observation_dtype))
        self.observation_space = spaces.Box(low.astype(dtype), high.astype(dtype), dtype=dtype)
        self._first_trial = 0
        self._first_block = 0
        self._edge = 0.0
        self._shown = (0, 0)

    # --------------------------------------------------------------- internals
    def _start_episode(self, seed: int | None, options: Mapping[str, Any] | None) -> None:
        session = self.session
        # Only at an episode's end is the arm at rest at home at a trial's start: a reset mid-episode
        # that went on with the trial under way would start nothing fresh.
        if self.continue_run and seed is None and not options and session is not None and not session.over \
                and self._episode_over():
            gym.Env.reset(self)  # an episode of the same run: its next trial
        else:
            self._new_run(seed, options)
        session = self.session
        assert session is not None
        self._first_trial = session.trial_index
        self._first_block = (session.plan or session.plans[-1]).block
        self._shown = (session.trial_index, session.phase)
        self._edge = self._edge_now()

    def _bounds(self, protocol: Protocol) -> tuple[np.ndarray, np.ndarray]:
        return observation_bounds_v1(protocol, self.trial_start)

    def _episode_over(self) -> bool:
        s = self.session
        assert s is not None
        if s.over:
            return True
        if self.episode_trials == "block":
            return s.plans[s.trial_index].block != self._first_block
        return s.trial_index - self._first_trial >= self.episode_trials

    def _edge_now(self) -> float:
        s = self.session
        assert s is not None
        target = s.rules.target
        return max(0.0, math.hypot(s.cursor[0] - target.x, s.cursor[1] - target.y) - target.radius)

    def _reward(self, hits: int) -> float:
        s = self.session
        assert s is not None
        if self.reward_kind == "sparse":
            return float(hits)
        shown = (s.trial_index, s.phase)
        before, self._edge = self._edge, self._edge_now()
        progress = before - self._edge if shown == self._shown else 0.0
        self._shown = shown
        return self.progress_weight * progress + self.hit_bonus * hits

    def _observation(self) -> np.ndarray:
        s = self.session
        assert s is not None
        q1, q2, w1, w2 = s.state
        _, _, vx, vy = hand_and_velocity(s.config.arm, q1, q2, w1, w2)
        target = s.rules.target
        (cx, cy), (hx, hy) = s.cursor, s.home
        return np.array((wrap_angle(q1), wrap_angle(q2), w1, w2, *s.muscles.activation, cx - hx, cy - hy, vx, vy,
                         target.x - cx, target.y - cy, 1.0 if s.phase == REACH else 0.0,
                         (s.steps - s.phase_start_step) * s.config.dt), dtype=self.observation_dtype)

    def _info(self) -> dict[str, Any]:
        s = self.session
        assert s is not None
        return {"trial": s.trial_index, "trials_done": len(s.outcomes), "hits": s.rules.board.hits,
                "block": s.block.name}


class CenterOutVectorEnv(SyncVectorEnv):
    """``num_envs`` CenterOut-v1 envs as one vector env: the vector entry point of the v1 ids.

    The lab's session has no batch kernel (each run's trials, perturbations and measures are per
    run), so the games step one after another, exactly as ``SyncVectorEnv`` steps them: it *is*
    Gymnasium's ``SyncVectorEnv`` (reset masks, the three autoreset modes, ``render()`` a tuple of
    frames), made from the env's arguments, so that ``gymnasium.make_vec`` and the SB3 adapter
    (``armgame.env.sb3``) take the CenterOut ids as they take the Reach ones.

    >>> import gymnasium as gym
    >>> import armgame.env
    >>> envs = gym.make_vec("armgame/CenterOut-v1", num_envs=2, autoreset_mode="SameStep")
    >>> obs, info = envs.reset(seed=0)
    >>> obs.shape, envs.metadata["autoreset_mode"].value
    ((2, 16), 'SameStep')
    """

    def __init__(self, num_envs: int = 1, *, autoreset_mode: str | AutoresetMode = AutoresetMode.NEXT_STEP,
                 **kwargs: Any) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, int | np.integer) or not 1 <= num_envs <= 4096:
            raise EnvArgumentError(f"num_envs must be a whole number from 1 to 4096, got {num_envs!r}")
        mode = AutoresetBook(1, autoreset_mode).mode  # checked in one line
        # The first env checks the arguments (one line for a bad one) before the others are made.
        first = CenterOutV1Env(**kwargs)
        envs = iter([first] + [CenterOutV1Env(**kwargs) for _ in range(int(num_envs) - 1)])
        super().__init__([lambda: next(envs) for _ in range(int(num_envs))], autoreset_mode=mode)
