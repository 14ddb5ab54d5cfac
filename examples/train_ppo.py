"""Train PPO (Stable-Baselines3) to play armgame: ``armgame/Reach-v1``, SB3's defaults but the batch.

    pip install -e '.[rl]'
    python examples/train_ppo.py                            # 1,500,000 env steps, then the test games
    python examples/train_ppo.py --steps 300000 --out ppo-run --env armgame/ReachHold-v1

The heart of it is five lines: make the native vector env through the SB3 adapter, hand it to
PPO, learn, and play deterministic games. It follows the suite's protocol (docs/programs.md, "The
protocol"): the budget is env steps (``--steps``), not wall time, so runs on different machines train
alike; training plays game seeds below ``TRAINING_SEED_LIMIT``; every ``--eval-every`` steps it plays 10
**validation** games (``VALIDATION_SEEDS``, the deterministic policy) and prints their mean hits, which
is what a run may look at; only at the end it plays the 100 **test** games (``armgame.env.evaluate`` on
the evaluation seeds) once. ``--out`` keeps the curve (``curve.csv``: env steps, wall seconds,
mean/min/max hits on the validation games), ``result.json`` (the id, training seed, budget and the test
games' hits, what ``benchmarks/reference_scores.py aggregate`` summarises over training seeds), the
model (``model.zip``) and the policy's game of seed 0 as a replay anyone can watch (``armgame replay
ppo-run/game.json``) or check (``armgame verify``): the game's own rules, and the id's dwell, noise and
field, recount its hits. ``--minutes`` caps the wall time as well, for a laptop (then say so: the budget
reached is in ``result.json``).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from collections.abc import Callable
from pathlib import Path

import gymnasium as gym
import numpy as np
import torch
from stable_baselines3 import PPO
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.vec_env import VecMonitor

import armgame.env  # noqa: F401  (registers the ids)
from armgame.env.evaluation import Evaluation, evaluate
from armgame.env.record import replay_of
from armgame.env.references import REFERENCE_HITS, TIER_HITS
from armgame.env.sb3 import make_sb3_vec_env
from armgame.env.suite import PROTOCOL_VERSION, VALIDATION_SEEDS

# What a run watches: validation games, never the test games evaluate() plays at the end (armgame.env.suite).
VALIDATION = list(VALIDATION_SEEDS[:10])


def validate(model: BaseAlgorithm, env_id: str) -> np.ndarray:
    """Hits in each of 10 whole validation games played by the deterministic policy."""
    envs = gym.make_vec(env_id, num_envs=len(VALIDATION), vectorization_mode="vector_entry_point")
    obs, info = envs.reset(seed=VALIDATION)
    done = np.zeros(len(VALIDATION), dtype=bool)
    hits = np.zeros(len(VALIDATION), dtype=np.int64)
    while not done.all():  # an episode of CenterOut ends when its trials do, each at its own step
        actions, _ = model.predict(obs, deterministic=True)
        obs, _, terminated, truncated, info = envs.step(actions)
        ended = (terminated | truncated) & ~done
        hits[ended] = info["hits"][ended]
        done |= ended
    envs.close()
    return hits


def keep_a_game(model: PPO, env_id: str, path: Path) -> int:
    """Plays game seed 0 with the deterministic policy in a single env and saves its replay; its hits."""
    env = gym.make(env_id)
    obs, _ = env.reset(seed=0)
    done = False
    while not done:
        obs, _, terminated, truncated, info = env.step(model.predict(obs, deterministic=True)[0])
        done = terminated or truncated
    replay_of(env, driver="ppo").save(path)
    return int(info["hits"])


class Curve(BaseCallback):
    """Validates every ``every`` env steps with ``validate`` (hits in each validation game; train_recurrent.py hands
    its own); stops training at the optional wall-clock cap."""

    def __init__(self, env_id: str, every: int, seconds: float, out: Path | None,
                 validate: Callable[[BaseAlgorithm, str], np.ndarray] = validate) -> None:
        super().__init__()
        self.env_id, self.every, self.seconds, self.out = env_id, every, seconds, out
        self.validate = validate
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
        hits = self.validate(self.model, self.env_id)
        self.rows.append((self.num_timesteps, round(wall, 1), float(hits.mean()), int(hits.min()), int(hits.max())))
        print(f"{self.num_timesteps:>9,} steps  {wall:7.0f} s  validation hits per game: mean {hits.mean():5.1f} "
              f"(min {hits.min()}, max {hits.max()})", flush=True)
        if self.out is not None:
            with (self.out / "curve.csv").open("w", newline="") as f:
                writer = csv.writer(f)
                writer.writerow(["env_steps", "wall_seconds", "mean_hits", "min_hits", "max_hits"])
                writer.writerows(self.rows)


def arguments(argv: list[str] | None, description: str, env: str, steps: int) -> argparse.Namespace:
    """The recipe's command line (train_recurrent.py's too), ``env`` and ``steps`` its defaults; makes ``--out``."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--env", default=env, help="an armgame id with a vector entry point")
    parser.add_argument("--steps", type=int, default=steps, help=f"the budget in env steps (default {steps:,})")
    parser.add_argument("--minutes", type=float, default=math.inf, help="a wall-clock cap as well (default none)")
    parser.add_argument("--envs", type=int, default=32, help="games stepped together (default 32)")
    parser.add_argument("--seed", type=int, default=0, help="training seed")
    parser.add_argument("--eval-every", type=int, default=100_000, help="env steps between validations")
    parser.add_argument("--test-games", type=int, default=100, help="test games played at the end (default 100)")
    parser.add_argument("--out", type=Path, help="folder for curve.csv, result.json, model.zip and game.json")
    args = parser.parse_args(argv)
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
    return args


def save_result(args: argparse.Namespace, algorithm: str, model: BaseAlgorithm, test: Evaluation) -> None:
    """Writes ``--out``'s model.zip and result.json, what ``benchmarks/reference_scores.py aggregate`` reads."""
    model.save(args.out / "model.zip")
    result = {"env_id": args.env, "algorithm": algorithm, "training_seed": args.seed, "env_steps": model.num_timesteps,
              "budget_steps": args.steps, "test_seeds": [test.seeds[0], test.seeds[-1]],
              "test_hits": list(test.hits), "mean_hits": test.mean_hits, "normalised": test.normalised,
              "protocol": PROTOCOL_VERSION,  # the normalised score's: a file without it is protocol 1's
              "hits_per_minute": test.hits_per_minute}
    if test.reach_seconds:  # CenterOut: where every trial is hit, the time to the target still ranks
        result["reach_seconds"] = [None if math.isnan(t) else round(t, 4) for t in test.reach_seconds]
        # and each game's length, for hits a minute's interval over the games (Evaluation.hits_per_minute_ci95)
        result["game_minutes"] = [round(m, 8) for m in test.game_minutes]
    (args.out / "result.json").write_text(json.dumps(result, indent=1) + "\n", encoding="utf-8")


def main(argv: list[str] | None = None) -> int:
    args = arguments(argv, __doc__.splitlines()[0], env="armgame/Reach-v1", steps=1_500_000)

    # A 64-unit MLP gains nothing from a second thread and loses much when another process shares the cores.
    torch.set_num_threads(1)
    # Game seeds from seed * 1000 up: below the validation and test ranges, and apart for each training seed.
    envs = VecMonitor(make_sb3_vec_env(args.env, args.envs, seed=args.seed * 1000), info_keywords=("hits",))
    model = PPO("MlpPolicy", envs, n_steps=128, batch_size=256, seed=args.seed, device="cpu", verbose=0)
    curve = Curve(args.env, args.eval_every, args.minutes * 60.0, args.out)
    model.learn(args.steps, callback=curve)
    curve.record()
    test = evaluate(model, args.env, games=args.test_games)  # once, at the end: the test games
    print(test.summary())
    if args.out is not None:
        save_result(args, "PPO", model, test)
        hits = keep_a_game(model, args.env, args.out / "game.json")
        print(f"its game of seed 0 ({hits} hits): armgame replay {args.out / 'game.json'}")
    best = max(row[2] for row in curve.rows)
    naive = (REFERENCE_HITS.get(args.env) or TIER_HITS.get(args.env) or {}).get("naive")
    beside = f" (the naive bot's on the test games: {naive:.1f})" if naive is not None else ""
    print(f"best validation mean hits per game: {best:.1f}{beside}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
