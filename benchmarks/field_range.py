"""How strong a force field the arm can take: the numbers behind ``armgame.env.variants``' field ranges.

    python benchmarks/field_range.py              # about 40 s of CPU
    python benchmarks/field_range.py --json

For each field and strength, whole games of ``armgame/Reach-v1`` (``--seconds`` long, seeds 0, 1, ...)
played by two policies: random keys (the env's action space, seeded) and the **pump**, which holds at each
joint the muscle that pushes the way the joint already turns, feeding the arm all the energy its muscles
can (the worst a policy can do to the speed bound, at each instant). Printed: the largest joint speed seen
(rad/s), how many games the speed guard stopped (``info["stopped"]``: the joint speed passed the declared
bound, 34.4 rad/s for the game's arm) and random play's mean hits (a field that feeds the arm energy makes
random keys fling the hand through targets). Strengths beyond the env's range are played through a
``ReachVariant`` set on the env directly (the env refuses them).

Measured on the AMD EPYC (2 cores), Python 3.11.7, 20 s games, 10 seeds (before the guard, at 4 random
keys spun the arm to 314 rad/s, at 5 to 410, and at 20 one game in three overflowed): the viscous field
stays well inside the bound up to 2 (the pump: 21.1 rad/s at 2, 29.1 at 3) and runs away from about 4,
so its range is -2 to 2; the curl field does no work, and at +-50 the pump stays as slow as in the game.
"""

from __future__ import annotations

import argparse
import json
import sys

import gymnasium as gym
import numpy as np

import armgame.env  # noqa: F401  (registers the ids)
from armgame.env.variants import ReachVariant

CASES = (("viscous", (0.0, 1.0, -1.0, 2.0, -2.0, 3.0, -3.0, 4.0, -4.0, 6.0)), ("curl", (50.0, -50.0)))


def pump(observation: np.ndarray) -> np.ndarray:
    """The keys that push each joint the way it turns: the muscles' power at its largest."""
    w1, w2 = observation[2], observation[3]
    return np.array([w1 > 0, w1 <= 0, w2 > 0, w2 <= 0], dtype=np.int8)


def sweep(field: str, strength: float, games: int, seconds: float) -> dict[str, object]:
    env = gym.make("armgame/Reach-v1", time_limit=seconds, observation_dtype="float64")
    # Set directly, so that strengths beyond the env's range are measured too.
    env.unwrapped.variant = ReachVariant(field=field if strength else None, field_strength=strength)
    row: dict[str, object] = {"field": field, "strength": strength}
    for name in ("random", "pump"):
        fastest, stopped, hits = 0.0, 0, []
        for seed in range(games):
            observation, info = env.reset(seed=seed)
            env.action_space.seed(seed)
            done = False
            while not done:
                action = env.action_space.sample() if name == "random" else pump(observation)
                observation, _, terminated, truncated, info = env.step(action)
                fastest = max(fastest, abs(float(observation[2])), abs(float(observation[3])))
                done = terminated or truncated
            stopped += "stopped" in info
            hits.append(info["hits"])
        row[name] = {"max_joint_speed": round(fastest, 1), "stopped": stopped, "mean_hits": float(np.mean(hits))}
    env.close()
    return row


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--games", type=int, default=10)
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)
    rows = [sweep(field, s, args.games, args.seconds) for field, strengths in CASES for s in strengths]
    if args.json:
        print(json.dumps(rows, indent=1))
        return 0
    print(f"{'field':8} {'strength':>8}  random: max |w|, stopped, hits   pump: max |w|, stopped")
    for r in rows:
        a, b = r["random"], r["pump"]
        print(f"{r['field']:8} {r['strength']:8g}  {a['max_joint_speed']:7.1f} {a['stopped']:4d} {a['mean_hits']:6.1f}"
              f"        {b['max_joint_speed']:7.1f} {b['stopped']:4d}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
