"""How fast Stable-Baselines3 trains on armgame: the adapter over the native vector env against SB3's DummyVecEnv.

    python benchmarks/sb3_speed.py              # about two minutes (needs the rl extra)
    python benchmarks/sb3_speed.py --quick

Two figures, each in interleaved repeats (adapter, DummyVecEnv, adapter, ...) so that load from
elsewhere falls on both, reported as the median and range of steps per second and the median of
the paired ratios:

* stepping: env steps per second of ``armgame/Reach-v1`` with random actions, at 1, 4, 8, 16 and 32 games
  (below 16 games ``make_sb3_vec_env`` gives SB3's own ``DummyVecEnv``: issue 28 asks no slower than
  ``DummyVecEnv`` at every size);
* training: env steps per second of PPO (``examples/train_ppo.py``'s settings: 32 games x 128 steps,
  minibatches of 256, one torch thread), rollouts and updates together.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

import gymnasium as gym
import numpy as np
import torch
from stable_baselines3 import PPO
from stable_baselines3.common.vec_env import DummyVecEnv

import armgame.env  # noqa: F401  (registers the ids)
from armgame.env.sb3 import make_sb3_vec_env

ENV_ID, GAMES = "armgame/Reach-v1", 32
SIZES = (1, 4, 8, 16, 32)


def dummy(games: int = GAMES) -> DummyVecEnv:
    return DummyVecEnv([lambda: gym.make(ENV_ID) for _ in range(games)])


def stepping(make, steps: int, games: int = GAMES) -> float:
    envs = make()
    envs.seed(0)
    envs.reset()
    actions = np.random.default_rng(0).integers(0, 2, (steps, games, 4))
    start = time.perf_counter()
    for a in actions:
        envs.step(a)
    return steps * games / (time.perf_counter() - start)


def training(make, steps: int) -> float:
    model = PPO("MlpPolicy", make(), n_steps=128, batch_size=256, seed=0, device="cpu")
    model.learn(GAMES * 128)  # the first update pays torch's warm-up
    start = time.perf_counter()
    model.learn(steps, reset_num_timesteps=False)
    return steps / (time.perf_counter() - start)


def compare(name: str, measure, steps: int, repeats: int, games: int = GAMES) -> None:
    makes = {"adapter": lambda: make_sb3_vec_env(ENV_ID, games), "DummyVecEnv": lambda: dummy(games)}
    rates: dict[str, list[float]] = {k: [] for k in makes}
    for _ in range(repeats):
        for key, make in makes.items():
            rates[key].append(measure(make, steps, games) if games != GAMES else measure(make, steps))
    ratios = [a / d for a, d in zip(rates["adapter"], rates["DummyVecEnv"], strict=True)]
    for key, values in rates.items():
        print(f"{name:>9} {key:>12}: {statistics.median(values):>10,.0f} env steps/s "
              f"[{min(values):,.0f} - {max(values):,.0f}]")
    print(f"{name:>9} adapter / DummyVecEnv: {statistics.median(ratios):.2f} [{min(ratios):.2f} - {max(ratios):.2f}]")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    torch.set_num_threads(1)
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
          f"load {os.getloadavg()[0]:.2f}")
    for games in SIZES:
        compare(f"stepping {games:>2}", stepping, (200 if args.quick else 1000) * max(1, 32 // games) // 4,
                2 if args.quick else 5, games)
    compare("training", training, GAMES * 128 * (2 if args.quick else 8), 2 if args.quick else 3)
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
