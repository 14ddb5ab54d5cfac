"""CenterOut-v1's batched vector env: N lab runs stepped together in C (``_ccenter.c``).

``CenterOutBatchVectorEnv`` is what ``gymnasium.make_vec`` returns for the CenterOut-v1 ids from
``BATCH_FROM`` envs on, where the C extension was built and the protocol is one it runs; otherwise
``center_out_v1.CenterOutVectorEnv`` (``SyncVectorEnv`` of single envs) runs. The C loop owns each run's
physics and the task's hold and reach; this module keeps, per run, what the lab keeps per trial: the
trials (``lab.session.schedule``, drawn from the run's seed as ``LabSession`` draws them), the outcomes,
their rows of the lab's table (``info["reaches"]``), the hits, and the next trial's description.

Sub-env ``i`` is the single env seeded as ``SyncVectorEnv`` seeds it, bit for bit: observations,
rewards, flags and infos (``tests/test_env_center_out_batch.py``). What it does not run, ``batch_refusal``
says in one line: a protocol with channel trials, a hidden cursor, or blocks at another posture, the
``SameStep`` autoreset, and frames (``render_mode``).
"""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any

import numpy as np
from gymnasium.error import ResetNeeded
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from ..game.variant import runaway_message
from ..lab.analysis import trial_row
from ..lab.metrics import METRIC_COLUMNS, Reach
from ..lab.perturbations import Perturbation
from ..lab.protocol import Protocol
from ..lab.session import LabSession, TrialOutcome, TrialPlan, lab_config, schedule
from ..physics.loads import ConstantForce, CurlField, SpringField, ViscousField
from .base import EnvArgumentError
from .center_out_v1 import CenterOutV1Env
from .reach import check_seed, drawn_seed, speed_bound
from .vector_common import AutoresetBook, check_reset_mask

try:
    from . import _ccenter
except ImportError:  # no C compiler at install: the SyncVectorEnv of single envs runs
    _ccenter = None  # type: ignore[assignment]

#: From this many envs the batch is faster than ``SyncVectorEnv`` (benchmarks/results/env_speed_center_out.json:
#: 1.69 and 1.95 times at 4 envs; an earlier run with the batch from 1 env measured it 0.44 and 0.67 times as fast
#: at 1, where its per-step numpy and C calls cost more than one lab session's step).
BATCH_FROM = 4
#: The most runs one batched vector env holds: a run's arrays and its path buffer take about 13 KB.
MAX_BATCH_ENVS = 65536

# The columns of the C loop's arrays (``_ccenter.c``'s enums).
S_X, S_A, S_G, S_R, S_CX, S_CY, S_FW1, S_FW2, S_TRIG, S_COUNT = 0, 4, 8, 12, 16, 17, 18, 19, 20, 26
I_STEPS, I_TOTAL, I_PHASE, I_COUNTER, I_GO, I_EVENT, I_PATH, I_TODO, I_START, I_FRESH, I_COUNT = range(11)
T_DELAY, T_TX, T_TY, T_TR, T_HX, T_HY, T_HR, T_HQ1, T_HQ2, T_FIELD, T_FP = range(11)
T_SHOW, T_SP = T_FP + 4, T_FP + 5
T_HOLD_AT_HOME, T_HOLD, T_TIMEOUT, T_LIMIT, T_COUNT = T_SP + 6, T_SP + 7, T_SP + 8, T_SP + 9, T_SP + 10
EVENT_HIT, EVENT_MISS, EVENT_STOPPED = 1, 2, 3
#: A new run's kept hand trig (the C loop's S_TRIG columns: the angles q1 and q1 + q2, then sin and cos of each), of
#: angles 0.0, which a run at them reads: sin(0.0) and cos(0.0) are 0.0 and 1.0 in every C library.
KEPT_TRIG = (0.0, 0.0, 0.0, 1.0, 0.0, 1.0)


def batch_refusal(protocol: Protocol) -> str | None:
    """Why the batch cannot run ``protocol`` (one line), or None when it can."""
    if _ccenter is None:
        return "the C extension armgame.env._ccenter was not built"
    if protocol.has_channels:
        return "the protocol has channel trials"
    if len(protocol.postures_deg) > 1:
        return "the protocol has blocks at another posture"
    if any(b.feedback != "full" or b.probes_feedback != "full" for b in protocol.blocks):
        return "the protocol hides the cursor on some trials"
    return None


def field_row(perturbation: Perturbation, home: tuple[float, float]) -> tuple[int, tuple[float, ...]]:
    """The C loop's field (kind, parameters) for a perturbation's loads: kind 0 where the arm's own step runs."""
    loads = perturbation.loads(home)
    if loads is None:
        return 0, ()
    if loads.joint is not None:
        (a, b), (c, d) = loads.joint.viscosity
        assert loads.hand is None and loads.joint.torque == (0.0, 0.0)
        return 5, (a, b, c, d)
    hand = loads.hand
    if isinstance(hand, CurlField):
        return 1, (hand.b,)
    if isinstance(hand, ViscousField):
        (a, b), (c, d) = hand.matrix
        return 2, (a, b, c, d)
    if isinstance(hand, ConstantForce):
        return 3, (hand.fx, hand.fy)
    if isinstance(hand, SpringField):
        return 4, (hand.stiffness, *hand.anchor)
    raise EnvArgumentError(f"the batch has no field for {perturbation.kind}")


def show_row(perturbation: Perturbation, home: tuple[float, float],
             home_q: tuple[float, float]) -> tuple[int, tuple[float, ...]]:
    """The C loop's display (kind, numbers) from the transform's ``plan``: 0 for the hand as it is."""
    show = perturbation.display(home, home_q)
    if show is None:
        return 0, ()
    kind, *numbers = show.plan  # type: ignore[attr-defined]
    return (1 if kind == "linear" else 2), tuple(numbers)


class _Task:
    """What every run of one protocol shares: its session's constants, from one ``LabSession``."""

    def __init__(self, protocol: Protocol, hold_at_home: bool) -> None:
        config = lab_config(protocol, 0)
        session = LabSession(config, protocol, hold_at_home=hold_at_home, speed_limit=speed_bound(config))
        self.protocol, self.config, self.dt = protocol, config, config.dt
        self.home, self.home_q = session.home, tuple(session.home_q)
        self.total_steps = session.total_steps
        compiled = session._compiled
        if compiled is None:
            raise EnvArgumentError("the batch needs the game's compiled kernel (armgame.game._ckernel)")
        self.params = np.frombuffer(compiled[0], dtype=np.float64).copy()
        self.mode = int(compiled[1])
        self.rise = np.array(session.muscles._rise)
        self.decay = np.array(session.muscles._decay)
        base = np.zeros(T_COUNT)
        base[[T_HX, T_HY, T_HR, T_HQ1, T_HQ2]] = (*self.home, protocol.home_radius, *self.home_q)
        base[T_TR] = protocol.target_radius
        base[[T_HOLD_AT_HOME, T_HOLD, T_TIMEOUT, T_LIMIT]] = (float(hold_at_home), session.hold_steps,
                                                             session.timeout_steps, session.speed_limit)
        self.base = base
        self.cap = session.timeout_steps + 2
        self._rows: dict[Perturbation, np.ndarray] = {}
        self._table_rows: dict[tuple[object, ...], dict[str, object]] = {}
        self.stub = SimpleNamespace(config=SimpleNamespace(dt=self.dt), protocol=protocol)
        # A trial's block follows from its index alone (``schedule`` runs the blocks in order, each its own
        # count of trials), so every run of the protocol shares these; the seed draws only targets and delays.
        plans = schedule(protocol, 0, self.dt, self.home)
        self.blocks = np.array([p.block for p in plans], dtype=np.int64)
        self.block_names = np.array([p.block_name for p in plans], dtype=object)

    def base_row(self, perturbation: Perturbation) -> np.ndarray:
        """The C loop's ``trials`` row of every trial under ``perturbation``, but for its delay and target (kept: not
        to be written to)."""
        row = self._rows.get(perturbation)
        if row is None:
            row = self.base.copy()
            kind, numbers = field_row(perturbation, self.home)
            row[T_FIELD], row[T_FP:T_FP + len(numbers)] = kind, numbers
            kind, numbers = show_row(perturbation, self.home, self.home_q)  # type: ignore[arg-type]
            row[T_SHOW], row[T_SP:T_SP + len(numbers)] = kind, numbers
            self._rows[perturbation] = row
        return row

    def trial(self, plan: TrialPlan) -> np.ndarray:
        """A trial's row of the C loop's ``trials``."""
        row = self.base_row(plan.active).copy()
        row[T_DELAY], row[T_TX], row[T_TY] = plan.delay_steps, *plan.position
        return row

    def row(self, plan: TrialPlan) -> dict[str, object]:
        """A fresh copy of ``trial_row``'s row for a trial of this kind, but for the columns that differ from trial to
        trial (``trial``, ``target_deg``, ``hit`` and ``METRIC_COLUMNS``), which the caller sets. No trial the batch
        runs is a channel trial or one space sent home, so the rest follows from the plan's block and perturbation."""
        key = (plan.block, plan.block_name, plan.perturbation, plan.catch, plan.channel, plan.feedback, plan.home)
        row = self._table_rows.get(key)
        if row is None:
            empty = Reach(t=np.zeros(0), hand=np.zeros((0, 2)), start=plan.home, target=plan.position, go_time=0.0,
                          hit=False)
            row = self._table_rows[key] = trial_row(self.stub, TrialOutcome(plan, 0, 0, False),  # type: ignore[arg-type]
                                                    reach=empty)
        return dict(row)


class _Run:
    """One sub-env's run: its trials and, if the guard stopped it, why (its counts are the env's arrays)."""

    __slots__ = ("plans", "seed", "stopped", "task")

    def __init__(self, task: _Task, seed: int, first: int | None) -> None:
        self.task, self.seed = task, seed
        # A new run at every reset (the default) plays its first episode's trials only: those are the full schedule's
        # first (``schedule``'s ``limit``), and the rest are drawn if the run goes on (``plan``).
        self.plans = schedule(task.protocol, seed, task.dt, task.home, limit=first)
        self.stopped: str | None = None

    def plan(self, index: int) -> TrialPlan:
        if index >= len(self.plans):
            self.plans = schedule(self.task.protocol, self.seed, self.task.dt, self.task.home)
        return self.plans[index]


class CenterOutBatchVectorEnv(VectorEnv):
    """``num_envs`` CenterOut-v1 envs stepped together in C; the arguments are the single env's
    (``CenterOutV1Env``), with ``autoreset_mode`` ``"NextStep"`` (default) or ``"Disabled"``.

    >>> import gymnasium as gym
    >>> import armgame.env
    >>> envs = gym.make_vec("armgame/CenterOut-v1", num_envs=4)
    >>> type(envs).__name__
    'CenterOutBatchVectorEnv'
    >>> obs, info = envs.reset(seed=0)
    >>> obs.shape, info["trial"].tolist()
    ((4, 16), [0, 0, 0, 0])
    """

    metadata: dict[str, Any] = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}  # noqa: RUF012

    def __init__(self, num_envs: int = 1, *, autoreset_mode: str | AutoresetMode = AutoresetMode.NEXT_STEP,
                 **kwargs: Any) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, int | np.integer) \
                or not 1 <= num_envs <= MAX_BATCH_ENVS:
            raise EnvArgumentError(f"num_envs must be a whole number from 1 to {MAX_BATCH_ENVS:,}, got {num_envs!r}")
        self.template = env = CenterOutV1Env(**kwargs)  # checks the arguments, one line for a bad one
        self._book = AutoresetBook(int(num_envs), autoreset_mode)
        if self._book.mode is AutoresetMode.SAME_STEP:
            raise EnvArgumentError("the batched CenterOut vector env autoresets NextStep or Disabled")
        refusal = batch_refusal(env.protocol)
        if refusal is not None:
            raise EnvArgumentError(f"no batched CenterOut env for this protocol: {refusal}")
        self.num_envs = n = int(num_envs)
        self.metadata = {**self.metadata, "autoreset_mode": self._book.mode, "render_fps": 1.0 / env.decision_time}
        self.render_mode = None
        self.single_action_space = env.action_space
        self.single_observation_space = env.observation_space
        self.action_space = batch_space(env.action_space, n)
        self.observation_space = batch_space(env.observation_space, n)
        self._tasks: dict[Protocol, _Task] = {}
        task = self._task(env.protocol)
        self.state = np.zeros((n, S_COUNT))
        self.state[:, S_TRIG:] = KEPT_TRIG
        self.ints = np.zeros((n, I_COUNT), dtype=np.int64)
        self.trials = np.zeros((n, T_COUNT))
        self.xs = np.zeros((n, task.cap))
        self.ys = np.zeros((n, task.cap))
        self._obs = np.zeros((n, 16))
        self.held = np.zeros((n, 4), dtype=bool)
        self.runs: list[_Run | None] = [None] * n
        self._generators: list[np.random.Generator | None] = [None] * n
        self._edge = np.zeros(n)
        self._shown = np.zeros((n, 2), dtype=np.int64)
        # What the lab counts per run, as arrays so that a step reads them without a loop over the runs: the
        # trial under way (the trials done), the hits, where the episode began, and how the run ended.
        self._trial = np.zeros(n, dtype=np.int64)
        self._hits = np.zeros(n, dtype=np.int64)
        self._first_trial = np.zeros(n, dtype=np.int64)
        self._first_block = np.zeros(n, dtype=np.int64)
        self._finished = np.zeros(n, dtype=bool)
        self._stopped = np.zeros(n, dtype=bool)
        self._task_of = np.zeros(n, dtype=np.int64)
        self._task_list: list[_Task] = [task]
        self._tables()

    # ----------------------------------------------------------------- the API
    def reset(self, *, seed: int | list[int | None] | None = None,
              options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict[str, Any]]:
        n = self.num_envs
        options = dict(options or {})
        mask = check_reset_mask(options.pop("reset_mask", None), n, have_games=self.runs[0] is not None)
        if seed is None or isinstance(seed, int | np.integer):
            seeds: list[int | None] = [None] * n if seed is None else [int(check_seed(seed)) + i for i in range(n)]
        elif isinstance(seed, list | tuple) and len(seed) == n:
            seeds = list(seed)
        else:
            raise EnvArgumentError(f"seed must be None, a whole number or a list of {n} seeds, got {seed!r}")
        chosen = np.ones(n, dtype=bool) if mask is None else mask
        for i in np.flatnonzero(chosen):
            self._start_episode(int(i), seeds[i], options)
        self._advance()
        self._book.reset(chosen)
        return self._observations(), self._infos(np.ones(n, dtype=bool) if mask is None else chosen)

    def step(self, actions: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if self.runs[0] is None:
            raise ResetNeeded("call reset() before step()")
        book = self._book
        book.before_step()
        n = self.num_envs
        restart = book.restart_now.copy()
        stepping = ~restart
        self._act(actions, stepping)
        ints = self.ints
        steps_before = ints[:, I_STEPS].copy()
        hits_before = self._hits.copy()
        ints[:, I_TODO] = np.where(stepping, self.template.decision_steps, 0)
        reaches = self._advance()
        hits = self._hits - hits_before
        ran = ints[:, I_STEPS] - steps_before
        rewards = self._rewards(hits, stepping) - self.template.time_cost * ran * self.task_dt
        over = self._overs()
        finished, stopped = self._finished.copy(), self._stopped.copy()
        truncated = (ints[:, I_STEPS] >= ints[:, I_TOTAL]) & ~finished & ~stopped & stepping
        terminated = over & ~truncated & stepping
        infos = self._infos(np.ones(n, dtype=bool))
        if reaches:
            infos["reaches"] = np.full(n, None, dtype=object)
            infos["_reaches"] = np.zeros(n, dtype=bool)
            for i, rows in reaches.items():
                infos["reaches"][i] = rows
                infos["_reaches"][i] = True
        where = stopped & stepping
        if where.any():
            infos["stopped"] = np.full(n, None, dtype=object)
            for i in np.flatnonzero(where):
                infos["stopped"][i] = self.runs[i].stopped  # type: ignore[union-attr]
            infos["_stopped"] = where
        if restart.any():
            for i in np.flatnonzero(restart):
                self._start_episode(int(i), None, {})
            self._advance()
            rewards[restart] = 0.0
            # The restarted games' infos are their new episodes' (their trial, hits and block after the reset).
            again = np.flatnonzero(restart)
            trial = self._trial[again]
            infos["trial"][again] = infos["trials_done"][again] = trial
            infos["hits"][again] = self._hits[again]
            width = self._names.shape[1]
            infos["block"][again] = self._names.ravel().take(self._task_of[again] * width
                                                             + np.minimum(trial, width - 1))
        book.after_step(terminated | truncated)
        return self._observations(), rewards, terminated, truncated, infos

    # --------------------------------------------------------------- internals
    @property
    def task_dt(self) -> float:
        return self._task(self.template.protocol).dt

    def _task(self, protocol: Protocol) -> _Task:
        task = self._tasks.get(protocol)
        if task is None:
            task = self._tasks[protocol] = _Task(protocol, self.template.hold_at_home)
            if hasattr(self, "_task_list"):
                self._task_list.append(task)
                self._tables()
        return task

    def _tables(self) -> None:
        """Each task's trials' blocks and block names as one table's row, padded with its last trial's: indexed by
        (the run's task, its trial index clipped to the table) it is the block of the trial under way, or of the
        last trial once the run is done (as ``LabSession.block_name`` reads it)."""
        self._rise = np.stack([t.rise for t in self._task_list])
        self._decay = np.stack([t.decay for t in self._task_list])
        width = max(len(t.blocks) for t in self._task_list)
        self._blocks = np.stack([np.pad(t.blocks, (0, width - len(t.blocks)), mode="edge") for t in self._task_list])
        self._names = np.stack([np.concatenate([t.block_names, [t.block_names[-1]] * (width - len(t.block_names))])
                                for t in self._task_list])

    def _block_at(self, trial: np.ndarray) -> np.ndarray:
        return self._blocks[self._task_of, np.minimum(trial, self._blocks.shape[1] - 1)]

    def _start_episode(self, i: int, seed: int | None, options: dict[str, Any]) -> None:
        """CenterOutV1Env._start_episode for sub-env ``i``."""
        env, run = self.template, self.runs[i]
        if env.continue_run and seed is None and not options and run is not None \
                and not self._run_over(i) and self._over(i):
            self._first_trial[i] = self._trial[i]
            self._first_block[i] = run.plan(int(self._trial[i])).block
        else:
            if seed is not None:
                seed = check_seed(seed)
            protocol = env.protocol if run is None else run.task.protocol
            if options:
                env.protocol = protocol
                env._take_options(options)  # one line for a bad option, as the single env's reset
                protocol = env.protocol
                refusal = batch_refusal(protocol)
                if refusal is not None:
                    raise EnvArgumentError(f"no batched CenterOut env for this protocol: {refusal}")
            if seed is not None or self._generators[i] is None:
                self._generators[i], _ = seeding.np_random(seed)
            lab_seed = seed if seed is not None else drawn_seed(self._generators[i])  # type: ignore[arg-type]
            task = self._task(protocol)
            first = None if env.episode_trials == "block" else int(env.episode_trials) + 1  # its next trial's too
            run = self.runs[i] = _Run(task, lab_seed, first)
            self.state[i] = 0.0
            self.state[i, S_TRIG:] = KEPT_TRIG
            self.state[i, S_X:S_X + 2] = task.home_q
            self.state[i, S_R:S_R + 4] = task.decay
            self.state[i, S_CX:S_CY + 1] = task.home
            self.ints[i] = 0
            self.ints[i, I_TOTAL] = task.total_steps
            self.trials[i] = task.trial(run.plans[0])
            self.held[i] = False
            self._trial[i] = self._hits[i] = self._first_trial[i] = 0
            self._first_block[i] = run.plans[0].block
            self._finished[i] = self._stopped[i] = False
            self._task_of[i] = self._task_list.index(task)
        self.ints[i, I_FRESH] = 1
        self._shown[i] = (self._trial[i], self.ints[i, I_PHASE])
        self._edge[i] = math.nan  # measured after the C loop's observation (``_advance``)

    def _run_over(self, i: int) -> bool:
        return bool(self._finished[i] or self.ints[i, I_STEPS] >= self.ints[i, I_TOTAL])

    def _over(self, i: int) -> bool:
        if self._run_over(i):
            return True
        if self.template.episode_trials == "block":
            trial = min(int(self._trial[i]), self._blocks.shape[1] - 1)
            return bool(self._blocks[self._task_of[i], trial] != self._first_block[i])
        return bool(self._trial[i] - self._first_trial[i] >= self.template.episode_trials)

    def _overs(self) -> np.ndarray:
        """CenterOutV1Env's episode end for every run: its run over, or its episode's trials done."""
        over = self._finished | (self.ints[:, I_STEPS] >= self.ints[:, I_TOTAL])
        if self.template.episode_trials == "block":
            return over | (self._block_at(self._trial) != self._first_block)
        return over | (self._trial - self._first_trial >= self.template.episode_trials)

    def _act(self, actions: Any, stepping: np.ndarray) -> None:
        """The single env's ``_press_keys`` or ``_set_levels`` on every stepping run that is not over, in C
        (``_ccenter.act``)."""
        n = self.num_envs
        continuous = self.template.continuous
        given = np.asarray(actions)
        if continuous:
            if given.dtype not in (np.float64, np.float32):
                given = np.asarray(actions, dtype=np.float64)
        elif given.dtype.kind == "b" or given.dtype in (np.int8, np.uint8):
            given = given.view(np.uint8)  # int8's -1 reads 255: refused as a key, as it was
        elif given.dtype != np.int64 and given.dtype != np.float64:
            # Any other keys as 0, 1 or 2 (neither, refused where the run steps), compared as numpy compares them.
            given = np.where(given == 1, 1, np.where(given == 0, 0, 2)).astype(np.uint8)
        if given.shape != (n, 4) or not _ccenter.act(np.ascontiguousarray(given), continuous, stepping, self._finished,
                                                      self.ints, self.held, self.state, self._rise, self._decay,
                                                      self._task_of):
            what = "finite numbers in [-1, 1]" if continuous else "zeros or ones (keys held)"
            raise ValueError(f"a CenterOut-v1 vector action is ({n}, 4) {what}, got shape {given.shape}")

    def _advance(self) -> dict[int, list[dict[str, object]]]:
        """Run the C loop until every run has run its steps, ending trials as ``LabSession._task_step`` does."""
        reaches: dict[int, list[dict[str, object]]] = {}
        task = self._task(self.template.protocol)
        ints, state, trials = self.ints, self.state, self.trials
        while _ccenter.advance(task.params, task.mode, state, ints, trials, self.xs, self.ys, self._obs):
            runs = np.flatnonzero(ints[:, I_EVENT])
            events = ints[runs, I_EVENT]
            ints[runs, I_EVENT] = 0
            ints[runs, I_FRESH] = 1  # their trial, or their stop, changes what they observe
            for i in runs[events == EVENT_STOPPED].tolist():
                self.runs[i].stopped = runaway_message(  # type: ignore[union-attr]
                    trials[i, T_LIMIT], state[i, S_FW1], state[i, S_FW2])
                self._stopped[i] = True
                ints[i, I_TODO] = 0
            ended = events != EVENT_STOPPED
            if ended.any():
                self._end_trials(runs[ended], events[ended] == EVENT_HIT, reaches)
        self._measure_new()
        return reaches

    def _end_trials(self, ended: np.ndarray, hit: np.ndarray, reaches: dict[int, list[dict[str, object]]]) -> None:
        """The trials the C loop just ended (runs ``ended``, each its first event this call): their rows of the lab's
        table, the runs' hits and trial counts, and the next trials' rows for the C loop. The rows' reach measures
        come from ``_ccenter.measures`` for all of them at once (``reach_metrics``, bit for bit); the rest of a row
        is ``trial_row``'s, which the batch computes once per kind of trial (``_Task.row``)."""
        runs, ints = self.runs, self.ints
        indices = self._trial[ended].tolist()
        plans = [runs[i].plan(index) for i, index in zip(ended.tolist(), indices, strict=True)]  # type: ignore[union-attr]
        geometry = np.array([(runs[i].task.dt, *plan.home, *plan.position)  # type: ignore[union-attr]
                             for i, plan in zip(ended.tolist(), plans, strict=True)])
        measures = np.empty((len(plans), len(METRIC_COLUMNS)))
        _ccenter.measures(self.xs, self.ys, ended, ints[ended, I_PATH], ints[ended, I_GO], geometry, measures)
        for i, plan, values, won in zip(ended.tolist(), plans, measures.tolist(), hit.tolist(), strict=True):
            row = runs[i].task.row(plan)  # type: ignore[union-attr]
            row["trial"], row["target_deg"], row["hit"] = plan.index + 1, plan.target_deg, won
            row.update(zip(METRIC_COLUMNS, values, strict=True))
            reaches.setdefault(i, []).append(row)
        self._hits[ended] += hit
        self._trial[ended] += 1
        # The next trials' rows for the C loop, written in three assignments rather than a row at a time.
        going, plans = [], []
        for i, index in zip(ended.tolist(), self._trial[ended].tolist(), strict=True):
            run = runs[i]
            if index >= len(run.task.blocks):  # type: ignore[union-attr]
                self._finished[i] = True
                ints[i, I_TODO] = 0
            else:
                going.append(i)
                plans.append(run.plan(index))  # type: ignore[union-attr]
        if going:
            self.trials[going] = [runs[i].task.base_row(plan.active)  # type: ignore[union-attr]
                                  for i, plan in zip(going, plans, strict=True)]
            self.trials[going, T_DELAY] = [plan.delay_steps for plan in plans]
            self.trials[going, T_TX:T_TY + 1] = [plan.position for plan in plans]

    def _measure_new(self) -> None:
        fresh = np.flatnonzero(np.isnan(self._edge))
        if fresh.size:
            self._edge[fresh] = self._edges(fresh)

    def _edges(self, runs: np.ndarray | None = None) -> np.ndarray:
        """Each cursor's distance to its shown target's edge (of ``runs``, default all), by ``math.hypot`` as the
        single env measures it (``_ccenter.edges``: CPython's hypot in C)."""
        out = np.empty(self.num_envs if runs is None else len(runs))
        _ccenter.edges(self._obs, self.ints, self.trials, None if runs is None else runs.astype(np.int64), out)
        return out

    def _rewards(self, hits: np.ndarray, stepping: np.ndarray) -> np.ndarray:
        env = self.template
        if env.reward_kind == "sparse":
            return hits.astype(np.float64)
        # Each run's last edge less its edge now where it shows the same target, and now's kept where it stepped.
        progress = np.empty(self.num_envs)
        _ccenter.progress(self._obs, self.ints, self.trials, self._trial, self._shown, self._edge, stepping, progress)
        return env.progress_weight * progress + env.hit_bonus * hits

    def _observations(self) -> np.ndarray:
        return self._obs.astype(self.template.observation_dtype)

    def _infos(self, games: np.ndarray) -> dict[str, Any]:
        trial, hits = self._trial.copy(), self._hits.copy()
        width = self._names.shape[1]
        block = self._names.ravel().take(self._task_of * width + np.minimum(trial, width - 1))
        every = games.all()  # a step's infos: every game's, with no masking to do
        infos: dict[str, Any] = {}
        for key, value in (("trial", trial), ("trials_done", trial.copy()), ("hits", hits), ("block", block)):
            infos[key] = value if every else np.where(games, value, np.zeros_like(value) if value.dtype != object
                                                      else None)
            infos[f"_{key}"] = games.copy()
        return infos


def center_out_vector_env(num_envs: int = 1, *, autoreset_mode: str | AutoresetMode = AutoresetMode.NEXT_STEP,
                          render_mode: str | None = None, **kwargs: Any) -> VectorEnv:
    """The CenterOut-v1 ids' vector entry point: the batch where it runs (``batch_refusal``, from ``BATCH_FROM``
    envs, without frames or the ``SameStep`` autoreset), else ``SyncVectorEnv`` of single envs (at most 4,096)."""
    from .center_out import run_protocol
    from .center_out_v1 import CenterOutVectorEnv

    mode = AutoresetBook(1, autoreset_mode).mode  # checked in one line
    protocol = kwargs.get("protocol", "null")
    batched = render_mode is None and mode is not AutoresetMode.SAME_STEP \
        and isinstance(num_envs, int | np.integer) and not isinstance(num_envs, bool) and num_envs >= BATCH_FROM \
        and batch_refusal(run_protocol(protocol, kwargs.get("perturbation"))) is None
    if batched:
        return CenterOutBatchVectorEnv(num_envs, autoreset_mode=mode, **kwargs)
    return CenterOutVectorEnv(num_envs, autoreset_mode=mode, render_mode=render_mode, **kwargs)
