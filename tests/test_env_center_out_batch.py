"""CenterOut-v1's batched vector env against Gymnasium's SyncVectorEnv of single envs (issue 52, item 5): every
sub-env's observations, rewards, flags and infos equal, bit for bit, for each id and each field kind, the
autoreset modes the batch runs, and the speed guard's stop."""

from __future__ import annotations

from dataclasses import replace

import gymnasium as gym
import numpy as np
import pytest

import armgame.env  # noqa: F401  (registers the ids)
from armgame.env import center_out as center_out_module
from armgame.env import center_out_batch
from armgame.env.base import EnvArgumentError
from armgame.env.center_out_batch import CenterOutBatchVectorEnv, center_out_vector_env
from armgame.env.center_out_v1 import CenterOutVectorEnv
from armgame.lab.presets import preset

pytestmark = pytest.mark.skipif(center_out_batch._ccenter is None, reason="armgame.env._ccenter was not built")

IDS = ("armgame/CenterOut-v1", "armgame/CenterOutContinuous-v1", "armgame/CenterOutHold-v1",
       "armgame/CenterOutHoldContinuous-v1")
#: One field or display of each kind, at or near its range's extremes (the matrices at the feeding limits).
KINDS = ("none", {"perturbation": "curl", "b": -50.0}, {"perturbation": "constant", "fx": 20.0, "fy": -20.0},
         {"perturbation": "spring", "stiffness": 250.0},
         {"perturbation": "viscous", "matrix": [[2.0, 50.0], [-50.0, 0.0]]},
         {"perturbation": "joint_viscous", "matrix": [[0.15, 5.0], [-5.0, 0.0]]},
         {"perturbation": "rotation", "angle": -180.0}, {"perturbation": "mirror", "axis": 45.0})

#: The null preset from its exposure block on: the field (or display) given as ``perturbation`` is on from the first
#: trial's go cue (but on catch trials).
EXPOSED = replace(preset("null"), blocks=preset("null").blocks[1:])


def same(a: object, b: object, where: str) -> None:
    if isinstance(a, tuple):
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            same(x, y, f"{where}[{k}]")
    elif isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), (where, sorted(set(a) ^ set(b)))
        for key in a:
            same(a[key], b[key], f"{where}/{key}")
    elif isinstance(a, np.ndarray) and a.dtype == object:
        assert isinstance(b, np.ndarray) and b.dtype == object and len(a) == len(b), where
        for x, y in zip(a, b, strict=True):
            assert str(x) == str(y), (where, x, y)  # rows hold NaN measures: their text is equal, == is not
    else:
        assert isinstance(b, np.ndarray) and a.dtype == b.dtype, (where, a, b)
        assert np.array_equal(a, b, equal_nan=True), (where, a, b)


def played(env_id: str, n: int, steps: int, seed: int = 3, **kwargs: object) -> dict[str, int]:
    """Step the batch and SyncVectorEnv side by side on the same random actions; what happened, counted."""
    spec = gym.spec(env_id)
    args = {**spec.kwargs, **kwargs}
    sync, batch = CenterOutVectorEnv(n, **args), CenterOutBatchVectorEnv(n, **args)
    same(sync.reset(seed=seed), batch.reset(seed=seed), "reset")
    sync.action_space.seed(seed)
    seen = {"ends": 0, "reaches": 0, "stopped": 0}
    for t in range(steps):
        action = sync.action_space.sample()
        a, b = sync.step(action), batch.step(action)
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            same(x, y, f"step {t}, item {k}")
        seen["ends"] += int((a[2] | a[3]).sum())
        seen["reaches"] += int(a[4].get("_reaches", np.zeros(1, bool)).sum())
        seen["stopped"] += int(a[4].get("_stopped", np.zeros(1, bool)).sum())
    return seen


@pytest.mark.parametrize("env_id", IDS)
def test_each_id_equals_sync(env_id: str) -> None:
    seen = played(env_id, 2, 220, episode_trials=1)
    assert seen["reaches"] > 0 or "Hold" in env_id  # random keys rarely hold still at home


@pytest.mark.parametrize("kind", KINDS, ids=lambda k: k if isinstance(k, str) else k["perturbation"])
def test_each_field_kind_equals_sync(kind: object) -> None:
    played("armgame/CenterOutContinuous-v1", 2, 200, episode_trials=1, protocol=EXPOSED, perturbation=kind)


def test_jointspace_continue_run_sparse_and_float64() -> None:
    played("armgame/CenterOut-v1", 2, 200, protocol="jointspace", episode_trials=1, continue_run=True)
    played("armgame/CenterOut-v1", 2, 150, episode_trials=1, reward="sparse", time_cost=0.5,
           observation_dtype="float64")


def test_the_guards_stop_equals_sync(monkeypatch: pytest.MonkeyPatch) -> None:
    # A bound the field breaks within a reach: both stop the run there, terminated, info["stopped"] the same.
    monkeypatch.setattr(center_out_module, "speed_bound", lambda config: 0.5)
    monkeypatch.setattr(center_out_batch, "speed_bound", lambda config: 0.5)
    seen = played("armgame/CenterOutContinuous-v1", 3, 200, episode_trials=2, protocol=EXPOSED,
                  perturbation={"perturbation": "constant", "fx": 20.0, "fy": 20.0})
    assert seen["stopped"] > 0


def test_disabled_autoreset_and_masks_equal_sync() -> None:
    args = {"continuous": False, "episode_trials": 1}
    sync = CenterOutVectorEnv(2, autoreset_mode="Disabled", **args)
    batch = CenterOutBatchVectorEnv(2, autoreset_mode="Disabled", **args)
    same(sync.reset(seed=5), batch.reset(seed=5), "reset")
    sync.action_space.seed(5)
    for t in range(300):
        action = sync.action_space.sample()
        a, b = sync.step(action), batch.step(action)
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            same(x, y, f"step {t}, item {k}")
        ended = a[2] | a[3]
        if ended.any():
            same(sync.reset(options={"reset_mask": ended}), batch.reset(options={"reset_mask": ended}), "mask")


def test_make_vec_takes_the_batch_where_it_runs() -> None:
    assert isinstance(gym.make_vec("armgame/CenterOut-v1", num_envs=8192), CenterOutBatchVectorEnv)
    assert isinstance(center_out_vector_env(2, protocol="null", autoreset_mode="SameStep"), CenterOutVectorEnv)
    with pytest.raises(EnvArgumentError, match="1 to 4096"):
        center_out_vector_env(5000, autoreset_mode="SameStep")


@pytest.mark.slow
@pytest.mark.parametrize("env_id", IDS)
def test_longer_runs_of_every_kind_equal_sync(env_id: str) -> None:
    for kind in KINDS:
        played(env_id, 4, 1500, seed=11, perturbation=kind, protocol=EXPOSED, episode_trials=3)
    played(env_id, 4, 1500, seed=12, protocol="curl", episode_trials="block", continue_run=True)
