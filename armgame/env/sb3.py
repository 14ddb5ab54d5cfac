"""Stable-Baselines3's ``VecEnv`` over armgame's native vector envs (SB3 imported only by this module).

SB3 steps its own ``VecEnv`` interface, not Gymnasium's vector API: a finished env must already
hold its next episode's first observation, with the last one in ``info["terminal_observation"]``.
That is Gymnasium's same-step autoreset, so the adapter makes the native vector env with
``autoreset_mode="SameStep"`` and only reshapes what it returns. One ``BatchGameSession`` steps
every game, which is what makes this faster than SB3's ``DummyVecEnv`` of single envs from
``ADAPTER_MIN_ENVS`` games; below that, and for ids and arguments the batch does not play
(CenterOut's ids, the score reward: ``armgame.env.vector.batch_plays``), ``make_sb3_vec_env`` gives that
``DummyVecEnv``.

>>> from armgame.env.sb3 import make_sb3_vec_env      # doctest: +SKIP
>>> from stable_baselines3 import PPO                  # doctest: +SKIP
>>> PPO("MlpPolicy", make_sb3_vec_env("armgame/Reach-v1", 16)).learn(100_000)  # doctest: +SKIP

``armgame.env`` never imports this module: installing SB3 is the ``rl`` extra's business.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from stable_baselines3.common.vec_env import DummyVecEnv, VecEnv

import armgame.env  # noqa: F401  (registers the ids)

from .base import EnvArgumentError


def make_sb3_vec_env(env_id: str, num_envs: int, seed: int | None = None, **kwargs: Any) -> VecEnv:
    """``num_envs`` games of ``env_id`` (an armgame id with a vector entry point) as one SB3 ``VecEnv``.

    ``seed`` seeds game ``i``'s first episode with ``seed + i`` (SB3's own ``VecEnv.seed`` does the same);
    ``kwargs`` are the env's arguments. For episode statistics (``evaluate_policy`` without its warning,
    ``ep_rew_mean`` in the logs) wrap it as SB3's ``make_vec_env`` wraps its envs in ``Monitor``:
    ``VecMonitor(make_sb3_vec_env(...), info_keywords=("hits",))``.
    """
    if "autoreset_mode" in kwargs:
        raise EnvArgumentError("the SB3 adapter sets autoreset_mode itself (SameStep, as SB3 expects)")
    if not batched(env_id, num_envs, kwargs):
        # SB3's own vector env of single envs: faster than any adapter where no batch steps the games.
        adapter: VecEnv = DummyVecEnv([functools.partial(gym.make, env_id, **kwargs) for _ in range(num_envs)])
    else:
        adapter = SB3VecEnv(gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="vector_entry_point",
                                         autoreset_mode=AutoresetMode.SAME_STEP, **kwargs))
    if seed is not None:
        adapter.seed(seed)
    return adapter


#: From this many games the adapter over the batched vector env outruns SB3's ``DummyVecEnv`` of single envs
#: (``benchmarks/sb3_speed.py``: 0.87 times at 8 games, 2.2 times at 32); below, ``make_sb3_vec_env`` gives
#: the ``DummyVecEnv``.
ADAPTER_MIN_ENVS = 16


def batched(env_id: str, num_envs: object, kwargs: dict[str, Any]) -> bool:
    """Whether ``make_sb3_vec_env`` steps these games in a batch: a Reach id's batched vector env, of enough
    games, with arguments the batch plays (a bad count goes there too, for its one-line refusal)."""
    from .vector import batch_plays

    if not isinstance(num_envs, int) or isinstance(num_envs, bool) or num_envs < 1:
        return True
    return num_envs >= ADAPTER_MIN_ENVS and batch_plays(env_id, kwargs)


class SB3VecEnv(VecEnv):
    """A Gymnasium vector env with same-step autoreset, seen through SB3's ``VecEnv`` interface.

    Each step's ``infos[i]`` holds the game's info (``hits``, ``score``, ...); for a game that ended,
    its last observation (``terminal_observation``), whether the clock ended it
    (``TimeLimit.truncated``) and its final info's values, so ``infos[i]["hits"]`` is that game's
    hits, comparable with a player's.
    """

    def __init__(self, envs: VectorEnv) -> None:
        if envs.metadata.get("autoreset_mode") is not AutoresetMode.SAME_STEP:
            raise EnvArgumentError("SB3VecEnv needs a vector env made with autoreset_mode='SameStep'")
        self.envs = envs
        self._actions: np.ndarray | None = None
        self._started = False
        super().__init__(envs.num_envs, envs.single_observation_space, envs.single_action_space)

    def reset(self) -> np.ndarray:
        seeds = None if all(s is None for s in self._seeds) else list(self._seeds)
        observations, info = self.envs.reset(seed=seeds)
        self._reset_seeds()
        self._reset_options()
        self.reset_infos = _split(info, self.num_envs)
        self._started = True
        return observations

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = actions

    def step_wait(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        observations, rewards, terminated, truncated, info = self.envs.step(self._actions)
        dones = terminated | truncated
        infos = _split({k: v for k, v in info.items() if not k.startswith(("final_", "_final_"))}, self.num_envs)
        if dones.any():
            finals = _split(info["final_info"], self.num_envs)
            for i in np.flatnonzero(dones):
                infos[i].update(finals[i])
                infos[i]["terminal_observation"] = info["final_obs"][i]
                infos[i]["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
        return observations, rewards.astype(np.float32), dones, infos

    def close(self) -> None:
        self.envs.close()

    def get_images(self) -> Sequence[np.ndarray | None]:
        frames = self.envs.render()
        return list(frames) if frames is not None else [None] * self.num_envs

    # The games share one object: an attribute is the same for every index.
    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        return [getattr(self.envs, attr_name)] * len(self._get_indices(indices))

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        setattr(self.envs, attr_name, value)

    def env_method(self, method_name: str, *method_args: Any, indices: Any = None, **method_kwargs: Any) -> list[Any]:
        result = getattr(self.envs, method_name)(*method_args, **method_kwargs)
        return [result] * len(self._get_indices(indices))

    def env_is_wrapped(self, wrapper_class: type[gym.Wrapper], indices: Any = None) -> list[bool]:
        return [False] * len(self._get_indices(indices))


def _split(info: dict[str, Any], n: int) -> list[dict[str, Any]]:
    """Gymnasium's vector info (arrays with ``_key`` masks) as SB3's list of per-env dicts."""
    out: list[dict[str, Any]] = [{} for _ in range(n)]
    for key, values in info.items():
        if key.startswith("_"):
            continue
        present = info.get(f"_{key}", np.ones(n, dtype=bool))
        for i in np.flatnonzero(present):
            value = values[i]
            out[i][key] = value.item() if isinstance(value, np.generic) else value
    return out
