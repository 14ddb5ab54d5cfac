"""Does the return track the score? Each reward's return against hits, game by game, within one policy.

    python benchmarks/reward_signal.py                 # 50 games a policy; about a minute
    python benchmarks/reward_signal.py --games 20 --ids armgame/Reach-v1

For each policy (random keys, the naive and the model bot) and id, plays games on the evaluation
seeds and correlates, across games, each reward's return with the game's hits (Pearson's r). A
reward whose return tracks hits within a policy tells a learner which of its own games were
better; docs/programs.md reports the table. ``reward="score"``'s return is the score by
construction (``tests/test_env_suite.py`` checks it to 1e-9), so its r is that of score and hits.
"""

from __future__ import annotations

import argparse
import sys

import gymnasium as gym
import numpy as np

import armgame.env  # noqa: F401  (registers the ids)
from armgame.env.policies import BotPolicy
from armgame.env.suite import EVALUATION_SEEDS

REWARDS = ("dense", "score")


def returns(env_id: str, policy: str, games: int) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Hits of each game and each reward's return, the same games for every reward (the reward does not
    change the game)."""
    hits, got = [], {r: [] for r in REWARDS}
    envs = {r: gym.make(env_id, reward=r) for r in REWARDS}
    for seed in EVALUATION_SEEDS[:games]:
        per_reward = {}
        for reward, env in envs.items():
            bot = None if policy == "random" else BotPolicy(policy, env)
            obs, info = env.reset(seed=seed)
            env.action_space.seed(seed)
            total, done = 0.0, False
            while not done:
                obs, r, terminated, truncated, info = env.step(bot(obs) if bot else env.action_space.sample())
                total += r
                done = terminated or truncated
            per_reward[reward] = (total, info["hits"])
        assert len({h for _, h in per_reward.values()}) == 1  # one game, whatever the reward
        hits.append(per_reward["dense"][1])
        for reward in REWARDS:
            got[reward].append(per_reward[reward][0])
    return np.array(hits), {r: np.array(v) for r, v in got.items()}


def correlation(x: np.ndarray, y: np.ndarray) -> float:
    return float(np.corrcoef(x, y)[0, 1]) if x.std() > 0 and y.std() > 0 else float("nan")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--games", type=int, default=50)
    parser.add_argument("--ids", nargs="*", default=["armgame/Reach-v1", "armgame/ReachHold-v1"])
    args = parser.parse_args(argv)
    print("| id | policy | hits (mean, range) | r(dense return, hits) | r(score return, hits) |")
    print("|---|---|---|---:|---:|")
    for env_id in args.ids:
        for policy in ("random", "naive", "model"):
            hits, got = returns(env_id, policy, args.games)
            print(f"| `{env_id.split('/')[1]}` | {policy} | {hits.mean():.1f} ({hits.min()} to {hits.max()}) | "
                  f"{correlation(got['dense'], hits):.2f} | {correlation(got['score'], hits):.2f} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
