"""How fast Stable-Baselines3 trains on armgame: the adapter over the native vector env against SB3's DummyVecEnv.

    python benchmarks/sb3_speed.py              # about two minutes (needs the rl extra)
    python benchmarks/sb3_speed.py --quick
    python benchmarks/sb3_speed.py --share armgame/Reach-v1 armgame/ReachHardContinuous-v1 --json

Two figures, each in interleaved repeats (adapter, DummyVecEnv, adapter, ...) so that load from
elsewhere falls on both, reported as the median and range of steps per second and the median of
the paired ratios:

* stepping: env steps per second of ``armgame/Reach-v1`` with random actions, at 1, 4, 8, 16 and 32 games
  (below 16 games ``make_sb3_vec_env`` gives SB3's own ``DummyVecEnv``: issue 28 asks no slower than
  ``DummyVecEnv`` at every size);
* training: env steps per second of PPO (``examples/train_ppo.py``'s settings: 32 games x 128 steps,
  minibatches of 256, one torch thread), rollouts and updates together.

With ``--share ID ...``, instead: how much of PPO's training is the env, for each id, on ``train_ppo.py``'s 32
games: the CPU time inside the env's ``reset`` and ``step`` against the whole ``learn``, in interleaved repeats,
beside MotorNet's reaching env stepped at the same 32 games (``env_speed.py``'s runner, where motornet imports).
From these, what PPO would make per CPU second with MotorNet's env in place of armgame's, and with an env 20 times
as fast as MotorNet's (issue 40, item 5): PPO's own work per env step plus each env's step. An env faster than
armgame's can save a run at most its share.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time
from typing import Any

import gymnasium as gym
import numpy as np
import torch
from stable_baselines3 import PPO
from stable_baselines3.common.vec_env import DummyVecEnv, VecEnv, VecEnvWrapper, VecMonitor

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


class _Timed(VecEnvWrapper):
    """The CPU seconds spent inside the wrapped env's ``reset`` and ``step``."""

    def __init__(self, venv: VecEnv) -> None:
        super().__init__(venv)
        self.cpu = 0.0

    def _timed(self, call: Any, *args: Any) -> Any:
        start = time.process_time()
        try:
            return call(*args)
        finally:
            self.cpu += time.process_time() - start

    def reset(self) -> Any:
        return self._timed(self.venv.reset)

    def step_async(self, actions: np.ndarray) -> None:
        self._timed(self.venv.step_async, actions)

    def step_wait(self) -> Any:
        return self._timed(self.venv.step_wait)


def env_share(env_id: str, steps: int) -> dict[str, float]:
    """One PPO ``learn`` of ``steps`` env steps with ``train_ppo.py``'s settings after a warm-up update: its CPU
    seconds in all and inside the env."""
    timed = _Timed(make_sb3_vec_env(env_id, GAMES, seed=0))
    model = PPO("MlpPolicy", VecMonitor(timed, info_keywords=("hits",)), n_steps=128, batch_size=256, seed=0,
                device="cpu")
    model.learn(GAMES * 128)  # the first update pays torch's warm-up
    timed.cpu, before, start = 0.0, model.num_timesteps, time.process_time()
    model.learn(steps, reset_num_timesteps=False)
    return {"steps": model.num_timesteps - before, "cpu": time.process_time() - start, "env_cpu": timed.cpu}


def measure_share(env_ids: list[str], steps: int, repeats: int, seconds: float) -> dict[str, object]:
    """``env_share`` of each id, interleaved over ``repeats``, and MotorNet's env at 32 games between them."""
    from env_speed import _run_facts, motornet_facts, motornet_runner  # the side-by-side run's own MotorNet

    load = os.getloadavg()[0]
    facts = motornet_facts("reacher")
    runner = None if "missing" in facts else motornet_runner(GAMES, "reacher")
    runs: dict[str, list[dict[str, float]]] = {env_id: [] for env_id in env_ids}
    motornet: list[float] = []
    for _ in range(repeats):
        for env_id in env_ids:
            runs[env_id].append(env_share(env_id, steps))
        if runner is not None:
            motornet.append(runner(seconds)[1])
    result: dict[str, object] = {"machine": _run_facts(load, seconds), "games": GAMES, "steps": steps,
                                 "repeats": repeats, "motornet": facts, "ids": {}}  # the load now: after
    mn_step = 1e6 / statistics.median(motornet) if motornet else None  # CPU us an env step
    if motornet:
        facts["cpu"] = {"median": statistics.median(motornet), "min": min(motornet), "max": max(motornet)}
    for env_id, found in runs.items():
        total = statistics.median(1e6 * r["cpu"] / r["steps"] for r in found)
        env = statistics.median(1e6 * r["env_cpu"] / r["steps"] for r in found)
        own = total - env  # PPO's work an env step, whichever env it steps
        shares = [r["env_cpu"] / r["cpu"] for r in found]
        entry = {"runs": found, "us_per_step": total, "env_us_per_step": env, "ppo_us_per_step": own,
                 "share": {"median": statistics.median(shares), "min": min(shares), "max": max(shares)}}
        if mn_step is not None:
            entry["with_motornet_us_per_step"] = own + mn_step
            entry["with_20x_motornet_us_per_step"] = own + mn_step / 20
        result["ids"][env_id] = entry  # type: ignore[index]
    return result


def report_share(result: dict) -> None:
    print(f"PPO ({result['games']} games, {result['steps']:,} env steps a repeat, {result['repeats']} repeats): CPU "
          "microseconds an env step, in all and in the env; per CPU second with MotorNet's env (and one 20 times as "
          "fast) in armgame's place")
    if "missing" in result["motornet"]:
        print(f"MotorNet: not measured ({result['motornet']['missing']})")
    for env_id, e in result["ids"].items():
        line = (f"{env_id:>30}: {1e6 / e['us_per_step']:8,.0f} env steps/CPU s, {e['us_per_step']:6.1f} us a step, "
                f"env {e['env_us_per_step']:5.1f} us ({100 * e['share']['median']:.1f} % "
                f"[{100 * e['share']['min']:.1f} - {100 * e['share']['max']:.1f}])")
        if "with_motornet_us_per_step" in e:
            line += (f"; with MotorNet's env {1e6 / e['with_motornet_us_per_step']:,.0f}, with 20x MotorNet "
                     f"{1e6 / e['with_20x_motornet_us_per_step']:,.0f}")
        print(line)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--share", nargs="+", metavar="ID", help="the env's share of PPO's training on these ids")
    parser.add_argument("--repeats", type=int, default=3, help="with --share (default 3)")
    parser.add_argument("--json", action="store_true", help="with --share: one JSON object as well")
    args = parser.parse_args()
    torch.set_num_threads(1)
    if args.share:
        result = measure_share(args.share, GAMES * 128 * (2 if args.quick else 8), args.repeats, 0.3)
        report_share(result)
        if args.json:
            print(json.dumps(result, default=str))
        return
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
          f"load {os.getloadavg()[0]:.2f}")
    for games in SIZES:
        compare(f"stepping {games:>2}", stepping, (200 if args.quick else 1000) * max(1, 32 // games) // 4,
                2 if args.quick else 5, games)
    compare("training", training, GAMES * 128 * (2 if args.quick else 8), 2 if args.quick else 3)
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
