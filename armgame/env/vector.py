"""A native Gymnasium vector env: N Reach games stepped in lockstep as numpy arrays.

``ReachVectorEnv`` is the vector entry point of ``armgame/Reach-v0`` and
``armgame/ReachContinuous-v0``: ``gymnasium.make_vec(id, num_envs=N)`` returns one. It is one
``BatchGameSession`` under Gymnasium 1.x's vector API, with next-step autoreset
(``AutoresetMode.NEXT_STEP``, the default of ``SyncVectorEnv``): the step after a game ends
returns that game's first observation of a new game, with reward 0 and neither flag set, and
ignores its action.

Sub-env ``i`` is the single env of the same arguments, seeded as ``SyncVectorEnv`` seeds it
(``reset(seed=s)``: game ``i`` gets seed ``s + i``, and each later game of sub-env ``i`` draws its
seed from a generator seeded ``s + i``, as the single env's ``reset()`` does). So the vector env
equals N single envs: observations to the batch's round-off (``STATE_TOLERANCE``; the batches
run the fast kernel, ``BatchGameSession(exact=False)``, which for games up to 60 s rounds
differently from the single session: the compiled kernel's at any size, numpy's from 2,048 games;
otherwise bit for bit), truncations, infos and v0's rewards (whole hits) exactly (a hit decided within
1e-11 m of a target's edge could differ: about 3e-8 a crossing, see ``armgame.game.batch``). v1's dense
reward is a difference of distances computed from those states, so it agrees to the same round-off, not
bit for bit: within ``REWARD_TOLERANCE`` at the default progress weight (tests/test_env_protocol.py).
"""

from __future__ import annotations

import inspect
from types import SimpleNamespace
from typing import Any

import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from ..game.batch import BatchGameSession
from ..game.batch.compiled import available as compiled_available
from ..game.batch.variant import BatchMuscleNoise
from ..game.rules import GameConfig
from ..game.variant import GameVariant
from . import features
from .features import (
    DEFAULT_HIT_BONUS,
    DEFAULT_PROGRESS_WEIGHT,
    edge_distance,
    muscle_levels,
    observe_v1,
    wrap_angles,
)
from .reach import (
    DEFAULT_DECISION_STEPS,
    EnvArgumentError,
    ReachSettings,
    _check_size,
    check_seed,
    drawn_seed,
)
from .variants import ReachVariant, with_target_radius
from .vector_common import AutoresetBook, SingleEnvsVectorEnv, check_reset_mask

#: Memory one game of a vector env takes at its peak (reset and the first step): 5.1-5.2 KB measured at
#: 20,000 and 60,000 games (peak RSS over the games), rounded up.
BYTES_PER_ENV = 6 * 1024
#: The memory one vector env may take, known before anything is allocated.
MAX_ENV_MEMORY = 2 * 1024**3
#: The most games one vector env holds: its memory budget over a game's (349,525; setting them up takes
#: about 50 s of one core).
MAX_ENVS = MAX_ENV_MEMORY // BYTES_PER_ENV
#: Games per ``BatchGameSession``: larger vectors run as several batches, whose arrays stay
#: small enough for the caches. Measured per CPU second under load (benchmarks/env_speed.py's
#: runner): 8,192 envs as one batch 0.83 M env-steps against 0.79 M as two of 4,096; 32,768
#: envs as batches of 4,096 or 8,192 0.79-0.84 M against 0.73 M as one batch.
GAMES_PER_BATCH = 8192


class ReachVectorEnv(VectorEnv):
    """``num_envs`` Reach-v0 games in lockstep; the arguments are the single env's (see ``ReachEnv``).

    ``reset(seed=s)`` seeds game ``i`` with ``s + i`` (or ``seed[i]`` from a list);
    ``reset(options={"reset_mask": mask})`` restarts only the masked games (the others play on), as
    ``SyncVectorEnv`` does. ``step(actions)`` takes a ``(num_envs, 4)`` array (5 with ``reset_key``)
    of keys held (0 or 1) or, for the continuous env, muscle levels. ``info`` holds the games'
    ``score``, ``hits`` and ``resets`` as arrays (with Gymnasium's ``_score`` ... masks).

    ``autoreset_mode``: ``"NextStep"`` (the default), ``"SameStep"`` (a game that ends starts its
    next one in the same step; its last observation and info are in ``info["final_obs"]`` and
    ``info["final_info"]``) or ``"Disabled"`` (restart ended games with a ``reset_mask``); the mode is
    ``metadata["autoreset_mode"]``. ``render_mode="rgb_array"``: ``render()`` returns a tuple of
    frames, one per game, as ``SyncVectorEnv`` does.

    >>> import gymnasium as gym
    >>> import armgame.env
    >>> envs = gym.make_vec("armgame/Reach-v0", num_envs=3, vectorization_mode="vector_entry_point")
    >>> obs, info = envs.reset(seed=10)
    >>> obs.shape, info["hits"].tolist()
    ((3, 11), [0, 0, 0])
    >>> obs, reward, terminated, truncated, info = envs.step(envs.action_space.sample())
    >>> reward.dtype, terminated.any(), truncated.any()
    (dtype('float64'), np.False_, np.False_)
    """

    metadata: dict[str, Any] = {"autoreset_mode": AutoresetMode.NEXT_STEP,  # noqa: RUF012
                                "render_modes": ["rgb_array"]}

    def __init__(self, num_envs: int = 1, *, time_limit: float | None = None,
                 decision_steps: int = DEFAULT_DECISION_STEPS, continuous: bool = False, reset_key: bool = False,
                 config: GameConfig | None = None, render_mode: str | None = None,
                 render_size: tuple[int, int] = (600, 600),
                 autoreset_mode: str | AutoresetMode = AutoresetMode.NEXT_STEP) -> None:
        self._configure(num_envs, ReachSettings.of(config, time_limit, decision_steps, continuous, reset_key),
                        render_mode, render_size, autoreset_mode)

    def _configure(self, num_envs: int, settings: ReachSettings, render_mode: str | None,
                   render_size: tuple[int, int], autoreset_mode: str | AutoresetMode, extra_bytes: int = 0) -> None:
        # extra_bytes: what a game takes beyond the batch's (an observation delay's ring), known in advance too.
        per_game = BYTES_PER_ENV + extra_bytes
        most = MAX_ENV_MEMORY // per_game
        if isinstance(num_envs, bool) or not isinstance(num_envs, int | np.integer) or num_envs < 1:
            raise EnvArgumentError(f"num_envs must be a whole number from 1 to {most:,}, got {num_envs!r}")
        if num_envs > most:
            raise EnvArgumentError(
                f"num_envs {int(num_envs):,} would take about {num_envs * per_game / 1024**3:.1f} GiB "
                f"({per_game / 1024:.3g} KiB a game), more than a vector env may ({MAX_ENV_MEMORY // 1024**3} GiB: "
                f"at most {most:,} games); run several envs in several processes")
        if render_mode not in (None, "rgb_array"):
            raise EnvArgumentError(f"a vector env renders with render_mode='rgb_array' (a frame per game) or None, "
                                   f"got {render_mode!r}: for a window, render one game with gymnasium.make")
        self.settings = settings
        self.config = settings.config
        self.num_envs = n = int(num_envs)
        self.decision_steps = settings.decision_steps
        self.decision_time = settings.decision_time
        self.render_mode = render_mode
        self.render_size = _check_size(render_size)
        self._book = AutoresetBook(n, autoreset_mode)
        self.metadata = {**self.metadata, "autoreset_mode": self._book.mode,
                         "render_fps": 1.0 / self.decision_time}
        self.single_action_space = settings.action_space()
        self.single_observation_space = settings.observation_space()
        self.action_space = batch_space(self.single_action_space, n)
        self.observation_space = batch_space(self.single_observation_space, n)
        self._width = settings.action_width
        #: The games as consecutive slices of ``GAMES_PER_BATCH``, each one ``BatchGameSession``.
        self.parts: list[tuple[slice, BatchGameSession]] = []
        # One generator per game, as each single env of a SyncVectorEnv has its own np_random.
        self._generators: list[np.random.Generator | None] = [None] * n
        self._views: Any = None  # armgame.ui.env_view.EnvView per game, made on the first frame

    # ----------------------------------------------------------------- the API
    def reset(self, *, seed: int | list[int | None] | None = None,
              options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict[str, Any]]:
        n = self.num_envs
        options = dict(options or {})
        mask = check_reset_mask(options.pop("reset_mask", None), n, have_games=bool(self.parts))
        if options:
            raise EnvArgumentError(f"unknown reset option(s) {', '.join(sorted(map(str, options)))}: "
                                   "a Reach vector env takes reset_mask")
        if seed is None or isinstance(seed, int | np.integer):
            if mask is None:
                super().reset(seed=None if seed is None else check_seed(seed))
            seeds: list[int | None] = [None] * n if seed is None else [int(seed) + i for i in range(n)]
        elif isinstance(seed, list | tuple) and len(seed) == n:
            seeds = list(seed)
        else:
            raise EnvArgumentError(f"seed must be None, a whole number or a list of {n} seeds, got {seed!r}")
        chosen = np.ones(n, dtype=bool) if mask is None else mask
        game_seeds = {int(i): self._game_seed(int(i), seeds[i]) for i in np.flatnonzero(chosen)}
        if not self.parts:
            for start in range(0, n, GAMES_PER_BATCH):
                part = slice(start, min(n, start + GAMES_PER_BATCH))
                self.parts.append((part, BatchGameSession(
                    [self.settings.game(game_seeds[i]) for i in range(part.start, part.stop)], exact=False,
                    variant=self._game_variant())))
        else:
            for part, batch in self.parts:
                here = chosen[part]
                if here.any():
                    batch.restart(here, [game_seeds[int(i) + part.start] for i in np.flatnonzero(here)])
        self._started(chosen)
        self._book.reset(chosen)
        return self._observations(), self._infos(chosen)

    def step(self, actions: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if not self.parts:
            from gymnasium.error import ResetNeeded

            raise ResetNeeded("call reset() before step()")
        actions = self._check(actions)
        book = self._book
        book.before_step()
        n = self.num_envs
        rewards = np.zeros(n)
        terminated = np.zeros(n, dtype=bool)
        truncated = np.zeros(n, dtype=bool)
        restart = book.restart_now.copy()  # next-step mode: the games that ended last step
        for part, batch in self.parts:
            self._step_part(part, batch, actions, rewards, terminated, truncated, restart[part])
        ended = terminated | truncated
        infos = self._infos(np.ones(n, dtype=bool))
        if book.mode is AutoresetMode.SAME_STEP and ended.any():
            final_obs = self._observations()
            infos["final_obs"] = np.full(n, None, dtype=object)
            for i in np.flatnonzero(ended):
                infos["final_obs"][i] = final_obs[i]
            infos["_final_obs"] = ended.copy()
            infos["final_info"] = self._infos(ended)
            infos["_final_info"] = ended.copy()
            self._restart(ended)
            infos = {k: v for k, v in infos.items() if k.startswith("final") or k.startswith("_final")}
            infos.update(self._infos(np.ones(n, dtype=bool)))
        book.after_step(ended)
        return self._observations(), rewards, terminated, truncated, infos

    def render(self) -> tuple[np.ndarray, ...] | None:
        """Each game's frame now, as the single env draws it (a tuple of (height, width, 3) arrays)."""
        if self.render_mode is None:
            from gymnasium import logger

            logger.warn("render() needs render_mode='rgb_array': make the vector env with it")
            return None
        if not self.parts:
            from gymnasium.error import ResetNeeded

            raise ResetNeeded("call reset() before render()")
        if self._views is None:
            from ..ui.env_view import EnvView  # pygame is imported here and only here

            self._views = [EnvView("rgb_array", self.render_size, self.metadata["render_fps"])
                           for _ in range(self.num_envs)]
        return tuple(view.frame(game) for view, game in zip(self._views, self._games(), strict=True))

    def close_extras(self, **kwargs: Any) -> None:
        for view in self._views or ():
            view.close()
        self._views = None

    # --------------------------------------------------------------- internals
    def _games(self) -> list[_BatchGame]:
        return [_BatchGame(batch, i) for _, batch in self.parts for i in range(batch.n)]

    def _step_part(self, part: slice, batch: BatchGameSession, actions: np.ndarray, rewards: np.ndarray,
                   terminated: np.ndarray, truncated: np.ndarray, restart: np.ndarray) -> None:
        # Games that ended at the last step are over, so neither their actions (the batch ignores
        # input to a game that is over) nor the physics touch them here; they start their next
        # game after the others have stepped.
        hits, resets = batch.hits.copy(), batch.resets.copy()  # before the actions: a reset key costs
        self._apply(batch, actions[part])
        batch.apply_noise()  # the single env's order: the action, then the decision's noise, then physics
        batch.advance(self.decision_steps)
        rewards[part] = self._rewards(part, batch, batch.hits - hits, batch.resets - resets)
        if restart.any():
            self._restart_part(part, batch, restart)
            rewards[part] = np.where(restart, 0.0, rewards[part])
        if batch.variant is None:  # the game's own physics: a game ends at its clock only
            truncated[part] = batch.over  # a restarted game is not over
            return
        # A game the guard stopped ends before its clock (terminated, as the single env's), the others at it.
        stopped = batch.stopped
        terminated[part] = stopped
        truncated[part] = batch.over & ~stopped

    def _restart(self, games: np.ndarray) -> None:
        for part, batch in self.parts:
            if games[part].any():
                self._restart_part(part, batch, games[part])

    def _restart_part(self, part: slice, batch: BatchGameSession, games: np.ndarray) -> None:
        chosen = np.flatnonzero(games) + part.start
        batch.restart(games, [self._game_seed(int(i), None) for i in chosen])
        mask = np.zeros(self.num_envs, dtype=bool)
        mask[chosen] = True
        self._started(mask)

    def _game_variant(self) -> GameVariant | None:
        """The games' dwell, noise, field and guard (v1's ``ReachVariant``); None, the game itself."""
        return None

    def _started(self, games: np.ndarray) -> None:
        """Games ``games`` (a mask over all) have just begun: v1 measures their first distances here."""

    def _rewards(self, part: slice, batch: BatchGameSession, hits: np.ndarray, resets: np.ndarray) -> np.ndarray:
        rewards = hits.astype(np.float64)
        if self.config.reset_cost:
            rewards -= self.config.reset_cost * resets
        return rewards

    def _game_seed(self, i: int, seed: int | None) -> int:
        """Game ``i``'s next seed, exactly as single env ``i``'s ``reset(seed=seed)`` chooses it."""
        if seed is not None:
            seed = check_seed(seed)
            self._generators[i] = seeding.np_random(seed)[0]
            return seed
        generator = self._generators[i]
        if generator is None:
            generator = self._generators[i] = seeding.np_random()[0]
        return drawn_seed(generator)

    def _check(self, actions: Any) -> np.ndarray:
        shape = (self.num_envs, self._width)
        if self.settings.continuous:
            levels = np.asarray(actions, dtype=np.float64)
            if levels.shape != shape or not np.isfinite(levels).all():
                raise ValueError(f"actions must be a {shape} array of finite muscle levels, got shape {levels.shape}")
            return muscle_levels(levels, centred=self.settings.version > 0)
        pressed = np.asarray(actions)
        if pressed.shape != shape or not ((pressed == 0) | (pressed == 1)).all():
            raise ValueError(f"actions must be a {shape} array of zeros and ones (keys held), "
                             f"got shape {pressed.shape}")
        return pressed.astype(bool)

    def _apply(self, batch: BatchGameSession, actions: np.ndarray) -> None:
        if self.settings.continuous:
            batch.set_levels(actions[:, :4])
            press = actions[:, 4] >= 0.5 if self._width == 5 else None
        else:
            if features._c_hold_keys is None:
                batch.set_held(actions[:, :4])
            else:  # set_held's numpy passes were a tenth of a step at 8,192 games; the same copies in one pass
                features._c_hold_keys(np.ascontiguousarray(actions[:, :4]), batch.steps, batch.total_steps,
                                      batch._held, batch._goal, batch._rate, batch._rise, batch._decay)
            press = actions[:, 4] if self._width == 5 else None
        if press is not None and press.any():
            batch.reset_arms(press)

    def _observations(self) -> np.ndarray:
        obs = np.empty((self.num_envs, 11))
        for part, batch in self.parts:
            rows = obs[part]
            rows[:, 0] = wrap_angles(batch.q1)
            rows[:, 1] = wrap_angles(batch.q2)
            rows[:, 2] = batch.w1
            rows[:, 3] = batch.w2
            rows[:, 4:8] = batch.activation
            rows[:, 8] = batch.target_x
            rows[:, 9] = batch.target_y
            rows[:, 10] = batch.time_left
        return obs

    def _infos(self, games: np.ndarray) -> dict[str, Any]:
        """The games' infos, as ``SyncVectorEnv`` gathers them: values where ``games`` is true, 0 elsewhere."""
        info: dict[str, Any] = {}
        every = games.all()
        for name in ("score", "hits", "resets"):
            values = [getattr(batch, name) for _, batch in self.parts]
            values = np.concatenate(values) if len(values) > 1 else values[0].copy()
            info[name] = values if every else np.where(games, values, 0)
            info[f"_{name}"] = games.copy()
        # A stopped game's reason, as SyncVectorEnv gathers a single env's info["stopped"]: only where there is one.
        if all(batch.variant is None for _, batch in self.parts):
            return info
        stopped = np.zeros(self.num_envs, dtype=bool)
        for part, batch in self.parts:
            stopped[part] = batch.stopped
        stopped &= games
        if stopped.any():
            reasons = np.full(self.num_envs, None, dtype=object)
            for part, batch in self.parts:
                for i, reason in batch.stop_reasons.items():
                    if stopped[part.start + i]:
                        reasons[part.start + i] = reason
            info["stopped"], info["_stopped"] = reasons, stopped
        return info


class _BatchGame:
    """One game of a batch, read as the renderer reads a ``GameSession`` (the batch keeps its rules current)."""

    def __init__(self, batch: BatchGameSession, i: int) -> None:
        self.config = batch.configs[i]
        self.rules = batch.rules[i]
        self.muscles = SimpleNamespace(keys=batch.muscle_keys, activation=batch.activation[i].tolist())
        self.time_left = float(batch.time_left[i])
        self._angles = float(batch.q1[i]), float(batch.q2[i])

    def interpolated_angles(self, alpha: float) -> tuple[float, float]:
        return self._angles


class ReachV1VectorEnv(ReachVectorEnv):
    """``num_envs`` Reach-v1 games in lockstep: ``ReachVectorEnv`` with v1's observations and reward
    (see ``armgame.env.reach_v1.ReachV1Env``; the arguments are its). ``hold_time`` (``ReachHold-v1``) gives the
    batch's games the dwell (``BatchGameSession``'s ``hold_steps``); ``observation_delay`` (``ReachDelay-v1``)
    hands each game's observation out that many steps late, as the single env's ``DelayedObservations`` does;
    ``motor_noise`` and ``field`` (``ReachNoisy-v1``, ``ReachField-v1``, ``ReachHard-v1``) are the batch's
    ``variant`` (``armgame.game.batch.variant``: each game's own noise stream, the field and the speed guard in
    the compiled kernel), and a game the guard stops is ``terminated`` with ``info["stopped"]``, as the single
    env's. Noise and fields need the compiled kernel (refused in one line without it; ``make_vec`` then gives
    single envs). ``target_shown`` and ``positions_only`` (the separating tier) hide game by game what the single env's
    ``HiddenObservations`` hides, before the delay.

    >>> import gymnasium as gym
    >>> import armgame.env
    >>> envs = gym.make_vec("armgame/ReachContinuous-v1", num_envs=4)
    >>> obs, info = envs.reset(seed=0)
    >>> obs.shape, obs.dtype, envs.single_action_space
    ((4, 15), dtype('float32'), Box(-1.0, 1.0, (4,), float32))
    """

    def __init__(self, num_envs: int = 1, *, time_limit: float | None = None,
                 decision_steps: int = DEFAULT_DECISION_STEPS, continuous: bool = False, reset_key: bool = False,
                 reward: str = "dense", progress_weight: float = DEFAULT_PROGRESS_WEIGHT,
                 hit_bonus: float = DEFAULT_HIT_BONUS, observation_dtype: str = "float32",
                 hold_time: float = 0.0, motor_noise: float = 0.0, observation_delay: int = 0,
                 field: str | None = None, field_strength: float | None = None, target_radius: float | None = None,
                 target_shown: float | None = None, positions_only: bool = False,
                 config: GameConfig | None = None, render_mode: str | None = None,
                 render_size: tuple[int, int] = (600, 600),
                 autoreset_mode: str | AutoresetMode = AutoresetMode.NEXT_STEP) -> None:
        if reward == "score":  # its shaping needs each game's reset and end: make_vec plays it on single envs
            raise EnvArgumentError("the batched vector env has no reward='score': gymnasium.make_vec gives single "
                                   "envs for it")
        variant = ReachVariant.of(hold_time, motor_noise, observation_delay, field, field_strength, target_shown,
                                  positions_only)
        if target_radius is not None:
            config = with_target_radius(config or GameConfig(), target_radius)
        settings = ReachSettings.of(config, time_limit, decision_steps, continuous, reset_key, 1, reward,
                                    progress_weight, hit_bonus, observation_dtype, variant)
        if (variant.motor_noise or variant.field) and not compiled_available():
            raise EnvArgumentError("the batched vector env plays motor noise and fields in the compiled kernel, which "
                                   "is not built here: gymnasium.make_vec gives single envs for them")
        self._configure(num_envs, settings, render_mode, render_size, autoreset_mode,
                        delay_bytes(variant.observation_delay, observation_dtype)
                        + (BatchMuscleNoise.BYTES_PER_GAME if variant.motor_noise else 0))
        self.variant = variant
        self._edges = np.zeros(self.num_envs)
        self._edges_new = np.zeros(self.num_envs)
        # This step's observations, measured with the distances for the dense reward (one pass over each
        # batch: the hand and its trig once, where the observation and the reward each took them): valid until
        # a game restarts, and handed out once, as each step returns a new array.
        self._measured: np.ndarray | None = None
        # The observation delay (ReachDelay-v1): the last ``delay + 1`` observations of every game in a ring,
        # ``_head`` the newest's slot, so the oldest is the one the single env's deque hands out.
        delay = variant.observation_delay
        self._past = np.zeros((delay + 1, self.num_envs, 15), dtype=settings.observation_dtype) if delay else None
        self._head = 0
        #: Games begun since the observations were last read: their ring starts full of their first observation.
        self._fresh = np.zeros(self.num_envs, dtype=bool)
        #: Whether this step's observations are still to go into the ring (read twice a step in SameStep mode:
        #: once for ``final_obs``, once after the restarts).
        self._unpushed = False
        # What the observation hides (the separating tier), as the single env's ``HiddenObservations``: each game's
        # physics step at the first observation of its target and its hits then (a hit brings a new target).
        self._shown_steps = None if variant.target_shown is None else max(1, round(variant.target_shown
                                                                                   / settings.config.dt))
        self._seen_at = np.zeros(self.num_envs, dtype=np.int64)
        self._seen_hits = np.zeros(self.num_envs, dtype=np.int64)
        self._new_target = np.ones(self.num_envs, dtype=bool)

    def reset(self, *, seed: int | list[int | None] | None = None,
              options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict[str, Any]]:
        self._unpushed = False  # a reset steps no game (and a step refused half-way pushed nothing)
        return super().reset(seed=seed, options=options)

    def step(self, actions: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        self._unpushed = self._past is not None
        return super().step(actions)

    def _game_variant(self) -> GameVariant | None:
        s = self.settings
        return self.variant.game_variant(s.config, s.decision_steps, s.joint_speed_bound)

    def _measure(self, part: slice, batch: BatchGameSession, obs: np.ndarray, edges: np.ndarray | None) -> None:
        """Part ``part``'s observation rows into ``obs[part]`` and, unless None, its edge distances into ``edges``."""
        observe_v1(self.config.arm, self.config.target_radius, batch._xs, batch.hand_trig(), batch._act,
                   batch.target_x, batch.target_y, batch.steps, batch.total_steps, obs[part], edges)

    def _edges_now(self, batch: BatchGameSession) -> np.ndarray:
        hx, hy = batch.hand()
        return edge_distance(hx, hy, batch.target_x, batch.target_y, self.config.target_radius)

    def _started(self, games: np.ndarray) -> None:
        self._measured = None  # restarted games have new states and targets
        self._fresh |= games
        self._new_target |= games
        for part, batch in self.parts:
            self._edges[part] = np.where(games[part], self._edges_now(batch), self._edges[part])

    def _rewards(self, part: slice, batch: BatchGameSession, hits: np.ndarray, resets: np.ndarray) -> np.ndarray:
        s = self.settings
        if s.reward == "sparse":
            return super()._rewards(part, batch, hits, resets)
        if part.start == 0:
            self._measured = np.empty((self.num_envs, 15), dtype=s.observation_dtype)
        now = self._edges_new[part]
        self._measure(part, batch, self._measured, now)  # type: ignore[arg-type]
        before = self._edges[part]
        # before - where(hits > 0, 0, now), its bits: x - 0.0 is x.
        progress = before - now
        hit = hits > 0
        if hit.any():
            progress[hit] = before[hit]
        before[...] = now
        progress *= s.progress_weight
        progress += s.hit_bonus * hits
        if self.config.reset_cost:
            progress -= self.config.reset_cost * resets
        return progress

    def _observations(self) -> np.ndarray:
        obs = self._observed()
        if self.variant.hides:  # before the delay: a delayed observation hides what it hid when made
            self._hide(obs)
        past = self._past
        if past is None:
            return obs
        # As ``variants.DelayedObservations`` per game: a step appends the game's observation and hands out
        # the one ``delay`` steps older; a game's first observation fills its ring and is handed out itself.
        if self._unpushed:
            self._unpushed = False
            self._head = (self._head + 1) % len(past)
            past[self._head] = obs
        fresh, self._fresh = self._fresh, np.zeros(self.num_envs, dtype=bool)
        if fresh.any():
            past[:, fresh] = obs[fresh]
        return past[(self._head + 1) % len(past)].copy()

    def _hide(self, obs: np.ndarray) -> None:
        """What the variant hides read as 0, in place (``variants.HiddenObservations``, game by game). Read twice in a
        SameStep step (``final_obs``, then after the restarts), it marks nothing twice: a target is new once."""
        if self._shown_steps is not None:
            steps = np.concatenate([batch.steps for _, batch in self.parts])
            hits = np.concatenate([batch.hits for _, batch in self.parts])
            new = self._new_target | (hits != self._seen_hits)
            self._seen_at[new] = steps[new]
            self._seen_hits[...] = hits
            self._new_target[...] = False
            obs[steps - self._seen_at >= self._shown_steps, 12:14] = 0.0
        if self.variant.positions_only:
            obs[:, 2:8] = 0.0
            obs[:, 10:12] = 0.0

    def _observed(self) -> np.ndarray:
        """The games' observations now, undelayed."""
        obs, self._measured = self._measured, None
        if obs is not None:
            return obs
        obs = np.empty((self.num_envs, 15), dtype=self.settings.observation_dtype)
        for part, batch in self.parts:
            self._measure(part, batch, obs, None)
        return obs


def delay_bytes(delay: int, observation_dtype: str) -> int:
    """The memory a game's ring of ``delay + 1`` observations takes (0 without a delay)."""
    return 0 if not delay else (delay + 1) * 15 * np.dtype(observation_dtype).itemsize


#: How far Reach-v1's batched dense reward may lie from the single env's at the default progress weight
#: (10 per metre): the weight times the hands' round-off, which the states' (``STATE_TOLERANCE``, 1e-10)
#: bounds, with room to spare.
REWARD_TOLERANCE = 1e-9

#: Below this many games, ``gymnasium.make_vec`` of a Reach id steps single envs (``SingleEnvsVectorEnv``):
#: a game's compiled loop costs less than a batch's fixed numpy work a step. Per CPU second, the batch against
#: single envs (issue 40, AMD EPYC, load 4 to 5): Reach-v1 0.86 at 2 envs, 1.74 at 4, 2.34 at 6; its continuous
#: twin 0.81, 1.65, 1.66; ReachDelay-v1 1.15, 1.62, 2.37; Reach-v0 0.53, 1.04, 1.57 (it was 8 before the compiled
#: observation pass, when the batch made 0.77 times single envs' speed at 4).
BATCH_MIN_ENVS = 4
#: The same for motor noise or a field, whose single envs run the physics in Python: the batch made 0.88 to 1.18
#: times their speed at 1 env, 1.59 to 2.52 at 2 and 2.6 to 4.4 at 4 (ReachNoisy-v1, ReachField-v1, ReachHard-v1).
LOADED_BATCH_MIN_ENVS = 2
_NATIVE_V0 = frozenset(inspect.signature(ReachVectorEnv.__init__).parameters) - {"self", "num_envs"}
_NATIVE_V1 = frozenset(inspect.signature(ReachV1VectorEnv.__init__).parameters) - {"self", "num_envs"}


def reach_vector_env(num_envs: int = 1, **kwargs: Any) -> VectorEnv:
    """The vector entry point of ``armgame/Reach-v0`` and ``ReachContinuous-v0``: ``ReachVectorEnv`` from
    ``BATCH_MIN_ENVS`` games, Gymnasium's ``SyncVectorEnv`` of single envs below (the same games, faster)."""
    from .reach import ReachEnv

    return _chosen(ReachVectorEnv, ReachEnv, _NATIVE_V0, num_envs, kwargs)


def reach_v1_vector_env(num_envs: int = 1, **kwargs: Any) -> VectorEnv:
    """The vector entry point of ``armgame/Reach-v1``, ``ReachContinuous-v1`` and the suite's harder Reach ids:
    ``ReachV1VectorEnv`` from ``BATCH_MIN_ENVS`` games, else ``SyncVectorEnv`` of single envs: below that size,
    for the score reward, and for noise or a field where the compiled kernel is not built (the numpy kernel
    does not play them)."""
    from .reach_v1 import ReachV1Env

    return _chosen(ReachV1VectorEnv, ReachV1Env, _NATIVE_V1, num_envs, kwargs)


def batch_plays(env_id: str, kwargs: dict[str, Any]) -> bool:
    """Whether ``gymnasium.make_vec(env_id, num_envs=N, **kwargs)`` steps a batch (from ``batch_min_envs`` games)."""
    import gymnasium

    spec = gymnasium.spec(env_id)
    native = {"armgame.env.vector:reach_vector_env": _NATIVE_V0,
              "armgame.env.vector:reach_v1_vector_env": _NATIVE_V1}.get(str(spec.vector_entry_point))
    return native is not None and _batch_takes({**spec.kwargs, **kwargs}, native)


def _batch_takes(kwargs: dict[str, Any], native_arguments: frozenset[str]) -> bool:
    """Whether the batch plays a game of these arguments: its own arguments only, no score reward (whose
    shaping needs each game's reset and end), and motor noise or a field only where the compiled kernel is built."""
    return (set(kwargs) <= native_arguments and kwargs.get("reward", "dense") != "score"
            and (not _loaded(kwargs) or compiled_available()))


def _chosen(native: type[ReachVectorEnv], single: type, native_arguments: frozenset[str], num_envs: Any,
            kwargs: dict[str, Any]) -> VectorEnv:
    if kwargs.get("render_mode") not in (None, "rgb_array"):
        raise EnvArgumentError(f"a vector env renders with render_mode='rgb_array' (a frame per game) or None, "
                               f"got {kwargs['render_mode']!r}: for a window, render one game with gymnasium.make")
    # A bad count meets the native env's check.
    if _batch_takes(kwargs, native_arguments) and not _small(num_envs, batch_min_envs(kwargs)):
        return native(num_envs, **kwargs)
    return SingleEnvsVectorEnv(single, num_envs, **kwargs)


def batch_min_envs(kwargs: dict[str, Any]) -> int:
    """From how many games ``make_vec`` of these arguments steps the batch (``LOADED_BATCH_MIN_ENVS`` for motor
    noise or a field, else ``BATCH_MIN_ENVS``), where it plays them at all (``batch_plays``)."""
    return LOADED_BATCH_MIN_ENVS if _loaded(kwargs) else BATCH_MIN_ENVS


def _loaded(kwargs: dict[str, Any]) -> bool:
    return bool(kwargs.get("motor_noise")) or kwargs.get("field") is not None


def _small(num_envs: Any, least: int) -> bool:
    """Whether ``num_envs`` is a valid count below ``least`` (a bad one goes to the native env's check)."""
    return isinstance(num_envs, int | np.integer) and not isinstance(num_envs, bool) and 1 <= num_envs < least
