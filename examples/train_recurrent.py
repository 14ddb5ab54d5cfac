"""Train RecurrentPPO (sb3-contrib, an LSTM policy) to play armgame: a learner with memory, for the separating tier.

    pip install -e '.[rl]' sb3-contrib
    python examples/train_recurrent.py --steps 300000 --out lstm-run --env armgame/ReachMemory-v1

``examples/train_ppo.py``'s recipe with a memory: the same vector env, budget, seed ranges, validation and test games
and the same files in ``--out`` (``result.json`` names the algorithm ``RecurrentPPO``), but sb3-contrib's
``RecurrentPPO`` with its ``MlpLstmPolicy`` in place of PPO's ``MlpPolicy``: an LSTM before the actor's and another
before the critic's two 64-unit layers (sb3-contrib's defaults), each of 64 units, PPO's width (sb3-contrib's default
is 256, several times the cost). ``n_steps=128`` and ``batch_size=256`` over 32 envs are PPO's. The separating tier
(docs/programs.md, "A tier that keeps algorithms apart") hides what a policy must remember or tell from the past;
this is a learner that can. Every game it plays, the validation and test games and the kept replay, carries the
LSTM's state from step to step and starts it afresh at the game's first step (``armgame.env.evaluate`` does so for
any model whose ``predict`` takes ``state`` and ``episode_start``).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import gymnasium as gym
import numpy as np
import torch
from sb3_contrib import RecurrentPPO
from sb3_contrib.common.recurrent.policies import RecurrentActorCriticPolicy
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.vec_env import VecMonitor

import armgame.env  # noqa: F401  (registers the ids)
from armgame.env.evaluation import evaluate
from armgame.env.record import replay_of
from armgame.env.sb3 import make_sb3_vec_env
from armgame.env.suite import PROTOCOL_VERSION, VALIDATION_SEEDS

# What a run watches: validation games, never the test games evaluate() plays at the end (armgame.env.suite).
VALIDATION = list(VALIDATION_SEEDS[:10])


class LstmPolicy(RecurrentActorCriticPolicy):
    """sb3-contrib's ``MlpLstmPolicy``, the keys' log-probability taken of float actions: its rollout buffer hands
    the key ids' ``int8`` actions on as they are (SB3's own buffer casts them to float), and torch's Bernoulli
    refuses them ("result type Float can't be cast to the desired output type Char", sb3-contrib 2.9.2)."""

    def evaluate_actions(self, obs, actions, lstm_states, episode_starts):  # type: ignore[no-untyped-def]
        return super().evaluate_actions(obs, actions.float(), lstm_states, episode_starts)


def keep_a_game(model: RecurrentPPO, env_id: str, path: Path) -> int:
    """Plays game seed 0 with the deterministic policy in a single env, its LSTM state carried, and saves its
    replay; its hits."""
    env = gym.make(env_id)
    obs, _ = env.reset(seed=0)
    state, start = None, np.ones(1, dtype=bool)
    done = False
    while not done:
        action, state = model.predict(obs, state=state, episode_start=start, deterministic=True)
        start = np.zeros(1, dtype=bool)
        obs, _, terminated, truncated, info = env.step(action)
        done = terminated or truncated
    replay_of(env, driver="recurrent ppo").save(path)
    return int(info["hits"])


class Curve(BaseCallback):
    """Validates every ``every`` env steps (``evaluate`` on the validation seeds, the LSTM's state carried through
    each game); stops training at the optional wall-clock cap."""

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
        hits = np.array(evaluate(self.model, self.env_id, seeds=VALIDATION).hits)
        self.rows.append((self.num_timesteps, round(wall, 1), float(hits.mean()), int(hits.min()), int(hits.max())))
        print(f"{self.num_timesteps:>9,} steps  {wall:7.0f} s  validation hits per game: mean {hits.mean():5.1f} "
              f"(min {hits.min()}, max {hits.max()})", flush=True)
        if self.out is not None:
            lines = ["env_steps,wall_seconds,mean_hits,min_hits,max_hits"]
            lines += [",".join(str(v) for v in row) for row in self.rows]
            (self.out / "curve.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="armgame/ReachMemory-v1", help="an armgame id with a vector entry point")
    parser.add_argument("--steps", type=int, default=300_000, help="the budget in env steps (default 300,000)")
    parser.add_argument("--minutes", type=float, default=math.inf, help="a wall-clock cap as well (default none)")
    parser.add_argument("--envs", type=int, default=32, help="games stepped together (default 32)")
    parser.add_argument("--seed", type=int, default=0, help="training seed")
    parser.add_argument("--eval-every", type=int, default=100_000, help="env steps between validations")
    parser.add_argument("--test-games", type=int, default=100, help="test games played at the end (default 100)")
    parser.add_argument("--out", type=Path, help="folder for curve.csv, result.json, model.zip and game.json")
    args = parser.parse_args(argv)
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)

    torch.set_num_threads(1)  # as train_ppo.py: the cores are shared, and a second thread gains little here
    # Game seeds from seed * 1000 up: below the validation and test ranges, and apart for each training seed.
    envs = VecMonitor(make_sb3_vec_env(args.env, args.envs, seed=args.seed * 1000), info_keywords=("hits",))
    model = RecurrentPPO(LstmPolicy, envs, policy_kwargs={"lstm_hidden_size": 64}, n_steps=128, batch_size=256,
                         seed=args.seed, device="cpu", verbose=0)
    curve = Curve(args.env, args.eval_every, args.minutes * 60.0, args.out)
    model.learn(args.steps, callback=curve)
    curve.record()
    test = evaluate(model, args.env, games=args.test_games)  # once, at the end: the test games
    print(test.summary())
    if args.out is not None:
        model.save(args.out / "model.zip")
        result = {"env_id": args.env, "algorithm": "RecurrentPPO", "training_seed": args.seed,
                  "env_steps": model.num_timesteps, "budget_steps": args.steps,
                  "test_seeds": [test.seeds[0], test.seeds[-1]], "test_hits": list(test.hits),
                  "mean_hits": test.mean_hits, "normalised": test.normalised, "protocol": PROTOCOL_VERSION,
                  "hits_per_minute": test.hits_per_minute}
        (args.out / "result.json").write_text(json.dumps(result, indent=1) + "\n", encoding="utf-8")
        hits = keep_a_game(model, args.env, args.out / "game.json")
        print(f"its game of seed 0 ({hits} hits): armgame replay {args.out / 'game.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
