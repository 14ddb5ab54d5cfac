"""A learner with no torch: the cross-entropy method over a linear policy, on the native vector env.

    python examples/train_es.py                     # about a minute: hits per 60 s game, then and before
    python examples/train_es.py --generations 5 --seconds 5

Each generation draws ``population`` linear policies ``a = tanh(W obs + b)`` (``W`` 4 x 15) from a
Gaussian, plays each in its own game of ``armgame/ReachContinuous-v1`` (one vector env: all the
games step together), keeps the best fifth by return and refits the Gaussian to them. The return is
the env's dense reward (progress toward the targets plus a bonus per hit), a smoother signal than
hits in a short game. ``tests/test_examples.py`` runs a small version and checks it beats random play;
that is the test which keeps the envs learnable.
"""

from __future__ import annotations

import argparse
import sys

import gymnasium as gym
import numpy as np

import armgame.env  # noqa: F401  (registers the ids)

ENV_ID = "armgame/ReachContinuous-v1"
#: Typical sizes of the observation's entries (rad, rad/s, activation, m, m/s, m, fraction): a linear
#: policy's weights then matter alike, which a search from one Gaussian needs.
TYPICAL = np.array([1.0, 1.0, 5.0, 5.0, 1.0, 1.0, 1.0, 1.0, 0.5, 0.5, 1.0, 1.0, 0.2, 0.2, 1.0])


def play(weights: np.ndarray, seconds: float, seed: int, env_id: str = ENV_ID) -> tuple[np.ndarray, np.ndarray]:
    """Returns and hits of games of ``seconds``, game ``i`` played by linear policy ``weights[i]`` (n, 4, 16)."""
    n = len(weights)
    envs = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", time_limit=seconds)
    obs, info = envs.reset(seed=seed)
    returns = np.zeros(n)
    while True:
        actions = np.tanh(np.einsum("nij,nj->ni", weights[:, :, :-1], obs / TYPICAL) + weights[:, :, -1])
        obs, reward, terminated, truncated, info = envs.step(actions)
        returns += reward
        if (terminated | truncated).all():
            return returns, info["hits"].copy()


def cem(generations: int = 30, population: int = 64, seconds: float = 10.0, elite: float = 0.2, seed: int = 0,
        init_std: float = 0.5, report: bool = False,
        env_id: str = ENV_ID) -> tuple[np.ndarray, list[tuple[int, float, float]]]:
    """The mean policy after ``generations`` of the cross-entropy method, and each generation's
    (generation, mean return, mean hits) of its population."""
    rng = np.random.default_rng(seed)
    obs_size = gym.make(env_id).observation_space.shape[0]
    mean = np.zeros((4, obs_size + 1))
    std = np.full_like(mean, init_std)
    keep = max(2, round(elite * population))
    history = []
    for generation in range(generations):
        weights = mean + std * rng.standard_normal((population, *mean.shape))
        # Every candidate of a generation plays the same targets; the targets change between generations.
        returns, hits = play(weights, seconds, int(rng.integers(2**31)) // population * population, env_id)
        best = weights[np.argsort(returns)[-keep:]]
        mean, std = best.mean(axis=0), best.std(axis=0) + 0.02
        history.append((generation, float(returns.mean()), float(hits.mean())))
        if report:
            print(f"generation {generation:>3}: return {returns.mean():7.1f}  hits {hits.mean():5.1f} "
                  f"(best {hits.max()}) in {seconds:g} s games", flush=True)
    return mean, history


def hits_per_game(policy: np.ndarray | None, games: int = 10, seconds: float = 60.0, seed: int = 0,
                  env_id: str = ENV_ID) -> np.ndarray:
    """Hits in ``games`` games (seeds ``seed`` ...) of the linear policy, or of random play for None."""
    if policy is not None:
        return play(np.repeat(policy[None], games, axis=0), seconds, seed, env_id)[1]
    envs = gym.make_vec(env_id, num_envs=games, vectorization_mode="vector_entry_point", time_limit=seconds)
    envs.reset(seed=seed)
    envs.action_space.seed(seed)
    while True:
        *_, terminated, truncated, info = envs.step(envs.action_space.sample())
        if (terminated | truncated).all():
            return info["hits"].copy()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--generations", type=int, default=30)
    parser.add_argument("--population", type=int, default=64)
    parser.add_argument("--seconds", type=float, default=10.0, help="length of each candidate's game")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    policy, _ = cem(args.generations, args.population, args.seconds, seed=args.seed, report=True)
    learned, random = hits_per_game(policy), hits_per_game(None)
    print(f"hits per 60 s game (10 games): the learned linear policy {learned.mean():.1f}, "
          f"random keys {random.mean():.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
