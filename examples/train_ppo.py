"""Train PPO (Stable-Baselines3) to play armgame: ``armgame/Reach-v1``, SB3's defaults but the batch.

    pip install -e '.[rl]'
    python examples/train_ppo.py                  # 10 minutes, then the policy's hits per game
    python examples/train_ppo.py --minutes 2 --out ppo-run

The heart of it is five lines: make the native vector env through the SB3 adapter, hand it to
PPO, learn, and play deterministic games. Every ``--eval-every`` steps it plays 10 whole games (the
first 10 of the suite's evaluation seeds, which training never plays; the deterministic policy) and
prints their mean hits, the number to compare with the
game's bots (``armgame play --bot naive``: about 22 a game) and with players. ``--out`` keeps the
curve (``curve.csv``: env steps, wall seconds, mean/min/max hits), the model (``model.zip``) and, for
the keys env, the policy's game of seed 0 as a replay anyone can watch (``armgame replay
ppo-run/game.json``) or check (``armgame verify``): the game's own rules recount its hits.
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path

import gymnasium as gym
import numpy as np
import torch
from stable_baselines3 import PPO
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.vec_env import VecMonitor

import armgame.env  # noqa: F401  (registers the ids)
from armgame.env.sb3 import make_sb3_vec_env
from armgame.env.suite import EVALUATION_SEEDS
from armgame.records.replay import Replay

# Held-out games: the suite's evaluation seeds, which training never plays (armgame.env.suite).
EVAL_SEEDS = list(EVALUATION_SEEDS[:10])


def evaluate(model: PPO, env_id: str) -> np.ndarray:
    """Hits in each of 10 whole games (the first 10 evaluation seeds) played by the deterministic policy."""
    envs = gym.make_vec(env_id, num_envs=len(EVAL_SEEDS), vectorization_mode="vector_entry_point")
    obs, info = envs.reset(seed=EVAL_SEEDS)
    while True:
        actions, _ = model.predict(obs, deterministic=True)
        obs, _, terminated, truncated, info = envs.step(actions)
        if (terminated | truncated).all():
            return info["hits"].copy()


def keep_a_game(model: PPO, env_id: str, path: Path) -> int:
    """Plays game seed 0 with the deterministic policy in a single env and saves its replay; its hits."""
    env = gym.make(env_id)
    obs, _ = env.reset(seed=0)
    truncated = False
    while not truncated:
        obs, _, _, truncated, info = env.step(model.predict(obs, deterministic=True)[0])
    Replay.from_session(env.unwrapped.session, "script", driver="ppo").save(path)
    return int(info["hits"])


class Curve(BaseCallback):
    """Evaluates every ``every`` env steps and stops training at the wall-clock budget."""

    def __init__(self, env_id: str, every: int, seconds: float, out: Path | None) -> None:
        super().__init__()
        self.env_id, self.every, self.seconds, self.out = env_id, every, seconds, out
        self.start = time.perf_counter()
        self.next_eval = 0
        self.rows: list[tuple[int, float, float, int, int]] = []

    def _on_step(self) -> bool:
        if self.num_timesteps >= self.next_eval:
            self.record()
            self.next_eval += self.every
        return time.perf_counter() - self.start < self.seconds

    def record(self) -> None:
        wall = time.perf_counter() - self.start
        hits = evaluate(self.model, self.env_id)
        self.rows.append((self.num_timesteps, round(wall, 1), float(hits.mean()), int(hits.min()), int(hits.max())))
        print(f"{self.num_timesteps:>9,} steps  {wall:7.0f} s  hits per game: mean {hits.mean():5.1f} "
              f"(min {hits.min()}, max {hits.max()})", flush=True)
        if self.out is not None:
            with (self.out / "curve.csv").open("w", newline="") as f:
                writer = csv.writer(f)
                writer.writerow(["env_steps", "wall_seconds", "mean_hits", "min_hits", "max_hits"])
                writer.writerows(self.rows)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="armgame/Reach-v1", help="an armgame id with a vector entry point")
    parser.add_argument("--minutes", type=float, default=10.0, help="wall-clock budget (default 10)")
    parser.add_argument("--steps", type=int, default=50_000_000, help="env steps at most")
    parser.add_argument("--envs", type=int, default=32, help="games stepped together (default 32)")
    parser.add_argument("--seed", type=int, default=0, help="training seed")
    parser.add_argument("--eval-every", type=int, default=100_000, help="env steps between evaluations")
    parser.add_argument("--out", type=Path, help="folder for curve.csv and model.zip")
    args = parser.parse_args(argv)
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)

    # A 64-unit MLP gains nothing from a second thread and loses much when another process shares the cores.
    torch.set_num_threads(1)
    envs = VecMonitor(make_sb3_vec_env(args.env, args.envs, seed=args.seed))
    model = PPO("MlpPolicy", envs, n_steps=128, batch_size=256, seed=args.seed, device="cpu", verbose=0)
    curve = Curve(args.env, args.eval_every, args.minutes * 60.0, args.out)
    model.learn(args.steps, callback=curve)
    curve.record()
    if args.out is not None:
        model.save(args.out / "model.zip")
        if isinstance(envs.action_space, gym.spaces.MultiBinary):  # a levels game has no key timeline
            hits = keep_a_game(model, args.env, args.out / "game.json")
            print(f"its game of seed 0 ({hits} hits): armgame replay {args.out / 'game.json'}")
    best = max(row[2] for row in curve.rows)
    print(f"best mean hits per game: {best:.1f} (the naive bot: about 22)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
