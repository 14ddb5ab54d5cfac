"""How strong a field the lab's centre-out task can take: the numbers behind the lab's field ranges (issue 52).

    python benchmarks/center_out_fields.py                # about four minutes of CPU
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
hold, rounded down (docs/lab.md, "Perturbations"). The rows measure fields beyond the lab's ranges too, built
without the lab's checks (``unchecked``): what the ranges leave out is what they measure.

**How much energy a matrix field may feed** (``feeding``). A field ``F = M v`` at the hand (or ``tau = W qdot`` at
the joints) does work ``v . M v``, which only ``M``'s symmetric part does: at most the sum of its positive
eigenvalues times the squared speed (``perturbations.feeding``). The ladder puts that sum ``s`` at each rung into
every shape: all of it on one eigenvalue (rank one), three quarters and a quarter, half and half (the identity
times ``s/2``), ``s`` and ``-s`` (a saddle, as the lab's viscous preset is), each turned by 0, 45, 90 and 135 deg,
and the half-and-half with a curl part of 90% of the entries' range (which does no work) either way. A rung holds
when every shape holds for every policy and seed, as above. The lab's limit (``Viscous.max_feeding``,
``JointViscous.max_feeding``) is ``MARGIN`` of the largest rung that holds with every rung below it, rounded down
to the ladder's step: ``tests/test_env_fields_protocol.py`` holds the code to this file's figures.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import fields
from pathlib import Path

import gymnasium as gym
import numpy as np

import armgame.env  # noqa: F401  (registers the ids)
from armgame.env.reach import speed_bound
from armgame.lab.perturbations import KINDS, Perturbation
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
#: The feeding ladders: the sum of the symmetric part's positive eigenvalues (N s/m; N m s/rad), rung by rung.
FEEDING_LADDERS = {"viscous": tuple(round(1.0 + 0.2 * k, 1) for k in range(11)),
                   "joint_viscous": tuple(round(0.05 * k, 2) for k in range(1, 9))}
#: How the sum is shared between the two eigenvalues, and the turns of their axes (deg).
SPLITS = ((1.0, 0.0), (0.75, 0.25), (0.5, 0.5), (1.0, -1.0))
TURNS = (0, 45, 90, 135)
#: The limit is this share of the largest rung that holds (then rounded down to the ladder's step).
MARGIN = 0.85


def pump(observation: np.ndarray) -> np.ndarray:
    """The keys that push each joint the way it turns: the muscles' power at its largest."""
    w1, w2 = observation[2], observation[3]
    return np.array([w1 > 0, w1 <= 0, w2 > 0, w2 <= 0], dtype=np.int8)


def bang(step: int) -> np.ndarray:
    flex = (step // BANG_HALF_PERIOD) % 2 == 0
    return np.array([flex, not flex, flex, not flex], dtype=np.int8)


def unchecked(kind: str, **values: float) -> Perturbation:
    """The field ``kind`` with these parameters (the rest at their defaults) built without the lab's checks: a
    field beyond the ranges, for measuring them (and for the speed guard's tests). The lab never builds one."""
    cls = KINDS[kind]
    out = cls.__new__(cls)
    for f in fields(cls):
        object.__setattr__(out, f.name, float(values.get(f.name, f.default)))
    return out


def matrix_field(kind: str, matrix) -> Perturbation:
    names = [p.name for p in KINDS[kind].parameters()]
    return unchecked(kind, **dict(zip(names, [float(v) for row in matrix for v in row], strict=True)))


def perturbations() -> list[Perturbation]:
    out = []
    for kind, ladder in LADDERS.items():
        for scale in ladder:
            for shape in SHAPES.values():
                out.append(matrix_field(kind, [[scale * v for v in row] for row in shape]))
    return out + [unchecked(kind, **values) for kind, values in OTHERS]


def feeding_shapes(kind: str, total: float) -> list[Perturbation]:
    """Matrices whose symmetric part's positive eigenvalues sum to ``total``, in every shape the ladder plays."""
    out = []
    for a, b in SPLITS:
        for turn in TURNS:
            c, s = math.cos(math.radians(turn)), math.sin(math.radians(turn))
            # R diag(a, b) R^T, R the turn: the eigenvalues total * (a, b) along (c, s) and (-s, c).
            la, lb = total * a, total * b
            out.append(matrix_field(kind, [[la * c * c + lb * s * s, (la - lb) * c * s],
                                           [(la - lb) * c * s, la * s * s + lb * c * c]]))
    curl = 0.9 * KINDS[kind].parameters()[0].high
    for sign in (1.0, -1.0):
        out.append(matrix_field(kind, [[total / 2, sign * curl], [-sign * curl, total / 2]]))
    return out


def feeding_rung(kind: str, total: float, episodes: int, bound: float) -> dict[str, object]:
    """One rung of the feeding ladder: the fastest joint and the episodes stopped over every shape, by policy."""
    row: dict[str, object] = {"feeding": total}
    for policy in POLICIES:
        results = [play(p, policy, seed) for p in feeding_shapes(kind, total) for seed in range(episodes)]
        row[policy] = {"max_joint_speed": round(max(r[0] for r in results), 1),
                       "stopped": sum(r[1] for r in results), "inside": all(r[2] for r in results)}
    row["holds"] = holds(row, bound)
    return row


def holds(row: dict, bound: float) -> bool:
    return all(row[p]["stopped"] == 0 and row[p]["max_joint_speed"] < 0.9 * bound for p in POLICIES)


def limit(ladder: tuple[float, ...], rows: list[dict]) -> tuple[float, float]:
    """(the largest rung that holds with every rung below it, the limit: ``MARGIN`` of it rounded down to the
    ladder's step)."""
    held = 0.0
    for row in rows:
        if not row["holds"]:
            break
        held = row["feeding"]
    step = round(ladder[1] - ladder[0], 6)
    return held, round(math.floor(MARGIN * held / step + 1e-9) * step, 6)


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
        row["holds"] = holds(row, bound)
        rows.append(row)
        print(f"{row['perturbation']:52} {cells(row)}  {'holds' if row['holds'] else 'RUNS AWAY'}", flush=True)
    feeding: dict[str, object] = {}
    for kind, ladder in FEEDING_LADDERS.items():
        rungs = []
        for total in ladder:
            rungs.append(feeding_rung(kind, total, args.episodes, bound))
            print(f"{kind} feeding {total:<5g} {cells(rungs[-1])}  {'holds' if rungs[-1]['holds'] else 'RUNS AWAY'}",
                  flush=True)
        held, most = limit(ladder, rungs)
        print(f"{kind}: holds to {held:g}, the lab's limit {most:g}")
        feeding[kind] = {"holds_to": held, "margin": MARGIN, "limit": most, "ladder": rungs}
    if args.json:
        args.json.write_text(json.dumps({"speed_bound": round(bound, 2), "episodes": args.episodes, "rows": rows,
                                         "feeding": feeding}, indent=1) + "\n")
    return 0


def cells(row: dict) -> str:
    return "  ".join(f"{p} {row[p]['max_joint_speed']:5.1f} {row[p]['stopped']}" for p in POLICIES)


if __name__ == "__main__":
    sys.exit(main())
