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
otherwise bit for bit), rewards, truncations and infos exactly (a hit decided within 1e-11 m of a
target's edge could differ: about 3e-8 a crossing, see ``armgame.game.batch``).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from ..game.batch import BatchGameSession
from ..game.rules import GameConfig
from .reach import (
    DEFAULT_DECISION_STEPS,
    SEED_LIMIT,
    EnvArgumentError,
    ReachSettings,
    check_seed,
    wrap_angles,
)

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
    """``num_envs`` Reach games in lockstep; the arguments are the single env's (see ``ReachEnv``).

    ``reset(seed=s)`` seeds game ``i`` with ``s + i`` (or ``seed[i]`` from a list); ``step(actions)``
    takes a ``(num_envs, 4)`` array (5 with ``reset_key``) of keys held (0 or 1) or, for the
    continuous env, muscle levels (clipped to [0, 1]). ``info`` holds the games' ``score``, ``hits``
    and ``resets`` as arrays (with Gymnasium's ``_score`` ... masks, all true). No rendering: render
    one game with the single env.

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

    metadata: dict[str, Any] = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}  # noqa: RUF012

    def __init__(self, num_envs: int = 1, *, time_limit: float | None = None,
                 decision_steps: int = DEFAULT_DECISION_STEPS, continuous: bool = False, reset_key: bool = False,
                 config: GameConfig | None = None, render_mode: str | None = None) -> None:
        if isinstance(num_envs, bool) or not isinstance(num_envs, int | np.integer) or num_envs < 1:
            raise EnvArgumentError(f"num_envs must be a whole number from 1 to {MAX_ENVS:,}, got {num_envs!r}")
        if num_envs > MAX_ENVS:
            raise EnvArgumentError(
                f"num_envs {int(num_envs):,} would take about {num_envs * BYTES_PER_ENV / 1024**3:.1f} GiB "
                f"({BYTES_PER_ENV // 1024} KiB a game), more than a vector env may ({MAX_ENV_MEMORY // 1024**3} GiB: "
                f"at most {MAX_ENVS:,} games); run several envs in several processes")
        if render_mode is not None:
            raise EnvArgumentError(f"the vector env does not render (render_mode={render_mode!r}): "
                                   "render one game with gymnasium.make")
        self.settings = ReachSettings.of(config, time_limit, decision_steps, continuous, reset_key)
        self.config = self.settings.config
        self.num_envs = n = int(num_envs)
        self.decision_steps = self.settings.decision_steps
        self.decision_time = self.settings.decision_time
        self.render_mode = None
        self.single_action_space = self.settings.action_space()
        self.single_observation_space = self.settings.observation_space()
        self.action_space = batch_space(self.single_action_space, n)
        self.observation_space = batch_space(self.single_observation_space, n)
        self._width = (self.single_action_space.shape or (0,))[0]
        #: The games as consecutive slices of ``GAMES_PER_BATCH``, each one ``BatchGameSession``.
        self.parts: list[tuple[slice, BatchGameSession]] = []
        # One generator per game, as each single env of a SyncVectorEnv has its own np_random.
        self._generators: list[np.random.Generator | None] = [None] * n
        self._autoreset = np.zeros(n, dtype=bool)

    # ----------------------------------------------------------------- the API
    def reset(self, *, seed: int | list[int | None] | None = None,
              options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict[str, Any]]:
        n = self.num_envs
        if seed is None or isinstance(seed, int | np.integer):
            super().reset(seed=None if seed is None else check_seed(seed))
            seeds: list[int | None] = [None] * n if seed is None else [int(seed) + i for i in range(n)]
        elif isinstance(seed, list | tuple) and len(seed) == n:
            seeds = list(seed)
        else:
            raise EnvArgumentError(f"seed must be None, a whole number or a list of {n} seeds, got {seed!r}")
        game_seeds = [self._game_seed(i, s) for i, s in enumerate(seeds)]
        if not self.parts:
            for start in range(0, n, GAMES_PER_BATCH):
                part = slice(start, min(n, start + GAMES_PER_BATCH))
                self.parts.append((part, BatchGameSession([self.settings.game(s) for s in game_seeds[part]],
                                                                   exact=False)))
        else:
            for part, batch in self.parts:
                batch.restart(np.ones(batch.n, dtype=bool), game_seeds[part])
        self._autoreset[:] = False
        return self._observations(), self._infos()

    def step(self, actions: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if not self.parts:
            from gymnasium.error import ResetNeeded

            raise ResetNeeded("call reset() before step()")
        actions = self._check(actions)
        n = self.num_envs
        rewards = np.empty(n)
        truncated = np.empty(n, dtype=bool)
        for part, batch in self.parts:
            self._step_part(part, batch, actions, rewards, truncated)
        self._autoreset = truncated.copy()
        return self._observations(), rewards, np.zeros(n, dtype=bool), truncated, self._infos()

    # --------------------------------------------------------------- internals
    def _step_part(self, part: slice, batch: BatchGameSession, actions: np.ndarray, rewards: np.ndarray,
                   truncated: np.ndarray) -> None:
        # Games that ended at the last step are over, so neither their actions (the batch ignores
        # input to a game that is over) nor the physics touch them here; they start their next
        # game after the others have stepped.
        restart = self._autoreset[part]
        hits, resets = batch.hits.copy(), batch.resets.copy()  # before the actions: a reset key costs
        self._apply(batch, actions[part])
        batch.advance(self.decision_steps)
        rewards[part] = batch.hits - hits
        if self.config.reset_cost:
            rewards[part] -= self.config.reset_cost * (batch.resets - resets)
        if restart.any():
            chosen = np.flatnonzero(restart) + part.start
            batch.restart(restart, [self._game_seed(int(i), None) for i in chosen])
        truncated[part] = batch.over  # a restarted game is not over

    def _game_seed(self, i: int, seed: int | None) -> int:
        """Game ``i``'s next seed, exactly as single env ``i``'s ``reset(seed=seed)`` chooses it."""
        if seed is not None:
            seed = check_seed(seed)
            self._generators[i] = seeding.np_random(seed)[0]
            return seed
        generator = self._generators[i]
        if generator is None:
            generator = self._generators[i] = seeding.np_random()[0]
        return int(generator.integers(SEED_LIMIT))

    def _check(self, actions: Any) -> np.ndarray:
        shape = (self.num_envs, self._width)
        if self.settings.continuous:
            levels = np.asarray(actions, dtype=np.float64)
            if levels.shape != shape or not np.isfinite(levels).all():
                raise ValueError(f"actions must be a {shape} array of finite muscle levels, got shape {levels.shape}")
            return np.clip(levels, 0.0, 1.0)
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
            batch.set_held(actions[:, :4])
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

    def _infos(self) -> dict[str, Any]:
        info: dict[str, Any] = {}
        for name in ("score", "hits", "resets"):
            info[name] = np.concatenate([getattr(batch, name) for _, batch in self.parts])
            info[f"_{name}"] = np.ones(self.num_envs, dtype=bool)
        return info
