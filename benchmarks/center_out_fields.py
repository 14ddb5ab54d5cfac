"""How strong a field the lab's centre-out task can take: the numbers behind the lab's field ranges (issue 52).

    python benchmarks/center_out_fields.py                # about a minute of CPU
    python benchmarks/center_out_fields.py --json benchmarks/results/center_out_fields.json

Each force field the lab offers (``armgame.lab.perturbations.KINDS``) at a ladder of strengths, in matrices of
every shape that matters: the identity and all-ones (their symmetric part feeds the arm energy: negative
damping), a non-symmetric one, and their negatives (damping). A one-block protocol of 8 trials with the field on
from each go cue is played as ``armgame/CenterOut-v1`` episodes (seeds 0, 1, ...) by three policies: random
keys (seeded), **bang-bang** (flexors then extensors, switched every 0.1 s) and the **pump**, which holds at each
joint the muscle that pushes the way the joint already turns, feeding the arm all the energy its muscles can
(resonant by construction). Printed: the largest joint speed seen (rad/s) and how many episodes the speed guard
stopped (``info["stopped"]``: the joint speed would pass the declared bound, 34.4 rad/s). A strength holds when
no episode stops and the largest speed stays under 0.9 of the bound; the lab's ranges are the strongest that
hold, rounded down (docs/lab.md, "Perturbations").
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np

import armgame.env  # noqa: F401  (registers the ids)
from armgame.env.reach import speed_bound
from armgame.lab.perturbations import Perturbation
from armgame.lab.protocol import Block, Protocol
from armgame.lab.session import lab_config

SHAPES = {"identity": ((1, 0), (0, 1)), "ones": ((1, 1), (1, 1)), "skew": ((0, 1), (0, 0)),
          "-identity": ((-1, 0), (0, -1)), "-ones": ((-1, -1), (-1, -1))}
LADDERS = {"viscous": (50.0, 20.0, 10.0, 5.0, 2.0), "joint_viscous": (5.0, 2.0, 1.0, 0.5, 0.2)}
OTHERS = (("constant", {"fx": 20.0, "fy": 20.0}), ("constant", {"fx": -20.0, "fy": 0.0}),
          ("spring", {"stiffness": 500.0}), ("spring", {"stiffness": 250.0}), ("curl", {"b": 50.0}),
          ("curl", {"b": -50.0}))
POLICIES = ("random", "bang", "pump")
#: Decisions between bang-bang's switches: 5 of 20 ms, 0.1 s.
BANG_HALF_PERIOD = 5


def pump(observation: np.ndarray) -> np.ndarray:
    """The keys that push each joint the way it turns: the muscles' power at its largest."""
    w1, w2 = observation[2], observation[3]
    return np.array([w1 > 0, w1 <= 0, w2 > 0, w2 <= 0], dtype=np.int8)


def bang(step: int) -> np.ndarray:
    flex = (step // BANG_HALF_PERIOD) % 2 == 0
    return np.array([flex, not flex, flex, not flex], dtype=np.int8)


def perturbations() -> list[Perturbation]:
    out = []
    for kind, ladder in LADDERS.items():
        for scale in ladder:
            for shape in SHAPES.values():
                out.append(Perturbation.make(kind, **dict(zip(
                    [p.name for p in Perturbation.make(kind).parameters()],
                    [float(scale * v) for row in shape for v in row], strict=True))))
    return out + [Perturbation.make(kind, **values) for kind, values in OTHERS]


def play(perturbation: Perturbation, policy: str, seed: int, trials: int = 8) -> tuple[float, bool, bool]:
    """(the largest joint speed, whether the guard stopped it, whether every observation was in the space)."""
    protocol = Protocol("fields", (Block("exposure", trials, perturbation),))
    env = gym.make("armgame/CenterOut-v1", protocol=protocol, episode_trials=trials, observation_dtype="float64")
    observation, info = env.reset(seed=seed)
    env.action_space.seed(seed)
    fastest, inside, step, done = 0.0, True, 0, False
    while not done:
        action = env.action_space.sample() if policy == "random" else bang(step) if policy == "bang" \
            else pump(observation)
        observation, _, terminated, truncated, info = env.step(action)
        fastest = max(fastest, abs(float(observation[2])), abs(float(observation[3])))
        inside &= bool(env.observation_space.contains(observation))
        done, step = terminated or truncated, step + 1
    env.close()
    return fastest, "stopped" in info, inside


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=3)
    parser.add_argument("--json", type=Path, help="write the rows here")
    args = parser.parse_args(argv)
    bound = speed_bound(lab_config(Protocol("x", (Block("b", 8),)), 0))
    rows = []
    for perturbation in perturbations():
        row: dict[str, object] = {"perturbation": perturbation.label()}
        for policy in POLICIES:
            results = [play(perturbation, policy, seed) for seed in range(args.episodes)]
            row[policy] = {"max_joint_speed": round(max(r[0] for r in results), 1),
                           "stopped": sum(r[1] for r in results), "inside": all(r[2] for r in results)}
        row["holds"] = all(row[p]["stopped"] == 0 and row[p]["max_joint_speed"] < 0.9 * bound  # type: ignore[index]
                           for p in POLICIES)
        rows.append(row)
        cells = "  ".join(f"{p} {row[p]['max_joint_speed']:5.1f} {row[p]['stopped']}" for p in POLICIES)  # type: ignore[index]
        print(f"{row['perturbation']:52} {cells}  {'holds' if row['holds'] else 'RUNS AWAY'}", flush=True)
    if args.json:
        args.json.write_text(json.dumps({"speed_bound": round(bound, 2), "episodes": args.episodes, "rows": rows},
                                        indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
