"""An upper bound on the hits a game of each Reach id can hold, whatever the policy (docs/programs.md, "A bound").

    python benchmarks/hit_bound.py                                  # print it
    python benchmarks/hit_bound.py --out benchmarks/results/hit_bound.json
    python benchmarks/hit_bound.py --table benchmarks/results/hit_bound.json        # docs/programs.md's table

A relaxation, each step of which only makes the task easier, so its hits are at least any policy's:

1. **Energy.** Without gravity the Coriolis torques do no work and the curl field none, so the kinetic energy
   changes at ``tau.w - w'Bw``, which is negative outside ``R = {w: max_tau tau.w >= w'Bw}``; from rest (every game
   starts at rest) it never passes ``E* = max over elbow angles and R of w'M w / 2``. The torques are the muscles'
   at full activation (times the noise's largest factor, 2, on the noisy ids).
2. **The hand's speed and acceleration.** Over every elbow angle and every joint speed of energy at most ``E*``,
   and every torque the muscles can give, the hand's speed is at most ``V`` and its acceleration
   (``J M^-1 (tau - c - Bw + J'F) + Jdot w``) at most ``A``: the torque's, the damping's and the field's, and the
   Coriolis and centripetal parts, each at its own largest and added. The muscles' rise (80 ms) is dropped: the
   torque may jump.
3. **A point hand.** The hand is a point in the plane with ``|a| <= A`` and speed ``v0`` (``|v0| <= V``) at the hit.
   To enter a disc of radius ``r`` at distance ``d`` from it, it needs at least
   ``tau(u, d) = (sqrt(u^2 + 2 A (d - r)) - u) / A``, ``u`` the part of ``v0`` toward the target (the sideways part
   is let off for free), and then the dwell's physics steps after the first (``(hold - 1) dt``) on ReachHold and
   ReachHard. The speed bound is dropped after the hit.
4. **The next target is unknown at the hit** (the game draws it then): the hand's position and ``v0`` are chosen
   before it, so each reach takes in expectation at least ``g = min over hand positions and v0 of E[tau]``, the
   expectation over the game's draw (uniform joint angles in the target box, the draws within 3 radii of the hand
   refused). The hand at a hit is within ``r`` of the last target's centre: the minimum is over a grid of target
   centres with nine positions in each disc, and over a polar grid of ``v0`` refined twice around its best (a
   numerical minimum of a convex function of ``v0``; the expectation is the midpoint rule on a grid of the box).
5. **Counting.** With ``Y_i <= T_i`` the reaches' lower bounds, ``E[Y_i | the past] >= g`` and each ``Y_i`` at most
   ``Ymax``, so optional stopping at the first reach that ends past the game's ``L`` seconds gives
   ``E[hits] <= (L + Ymax) / g - 1``.

An oracle that knows the game's draws (the seeds are public) escapes step 4: for it each reach's ``v0`` points at its
target at speed ``V``, and its bound is reported beside (``oracle``).

Bad input (an unknown id, a result that is not one) is one line and exit 1.
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

#: The five distinct games (``benchmarks/ceiling.py``'s): every other Reach id's bound is one of these (a continuous
#: twin's levels act within the same torques; a delay only hides the state).
DISTINCT = ("armgame/Reach-v1", "armgame/ReachHold-v1", "armgame/ReachNoisy-v1", "armgame/ReachField-v1",
            "armgame/ReachHard-v1")
#: Grids: elbow angles and directions for the maxima (each then raised by ``MARGIN``), the target box's midpoints
#: for the draw's expectation, target centres for the hand at a hit.
ELBOW_GRID, DIRECTIONS, DRAW_GRID, CENTRE_GRID = 2048, 1440, 40, 6
MARGIN = 1.01


def game_of(env_id: str) -> dict[str, Any]:
    """What the bound needs of ``env_id``'s game: the arm, the torques' corners, the target box and rules."""
    import gymnasium as gym

    import armgame.env  # noqa: F401  (registers the ids)
    from armgame.game.variant import NOISE_FACTOR_MAX

    env = gym.make(env_id)
    base = env.unwrapped
    config, variant = base.settings.config, base.game_variant
    env.close()
    factor = NOISE_FACTOR_MAX if variant.motor_noise else 1.0
    moments = np.array([m.moment for m in config.muscles]) * factor
    corners = np.array([np.array(on, dtype=float) @ moments for on in itertools.product((0, 1), repeat=len(moments))])
    return {"arm": config.arm, "corners": corners, "radius": config.target_radius, "dt": config.dt,
            "hold": max(1, variant.hold_steps), "curl": float(variant.field_parameters[0]) if variant.field else 0.0,
            "time_limit": config.time_limit, "shoulder": np.radians(config.target_shoulder_range),
            "elbow": np.radians(config.target_elbow_range)}


def mass(p: Any, q2: np.ndarray) -> np.ndarray:
    """M(q2), (..., 2, 2)."""
    a = p.i1 + p.i2 + p.m1 * p.r1**2 + p.m2 * (p.l1**2 + p.r2**2)
    b, d = p.m2 * p.l1 * p.r2, p.i2 + p.m2 * p.r2**2
    c = np.cos(q2)
    return np.stack([np.stack([a + 2 * b * c, d + b * c], -1), np.stack([d + b * c, np.full_like(c, d)], -1)], -2)


def jacobian(p: Any, q2: np.ndarray) -> np.ndarray:
    """The hand's Jacobian at shoulder angle 0 (the bound's magnitudes do not depend on it), (..., 2, 2)."""
    s2, c2 = np.sin(q2), np.cos(q2)
    return np.stack([np.stack([-p.l2 * s2, -p.l2 * s2], -1), np.stack([p.l1 + p.l2 * c2, p.l2 * c2], -1)], -2)


def hand_acceleration(p: Any, q2: np.ndarray, w: np.ndarray, tau: np.ndarray, curl: float) -> np.ndarray:
    """The hand's acceleration at shoulder angle 0, elbow ``q2``, joint speeds ``w`` and torques ``tau`` (...,2)."""
    m, j = mass(p, q2), jacobian(p, q2)
    h = p.m2 * p.l1 * p.r2 * np.sin(q2)
    w1, w2 = w[..., 0], w[..., 1]
    coriolis = np.stack([-h * (2 * w1 * w2 + w2 * w2), h * w1 * w1], -1)
    v = np.einsum("...ij,...j->...i", j, w)
    force = curl * np.stack([v[..., 1], -v[..., 0]], -1)
    rhs = tau - coriolis - w * np.array([p.damping1, p.damping2]) + np.einsum("...ji,...j->...i", j, force)
    qdd = np.linalg.solve(m, rhs[..., None])[..., 0]
    c2, s2 = np.cos(q2), np.sin(q2)
    # Jdot w at shoulder angle 0: -(l1 w1^2, 0) - l2 (w1 + w2)^2 (cos q2, sin q2).
    centripetal = -np.stack([p.l1 * w1 * w1 + p.l2 * c2 * (w1 + w2) ** 2, p.l2 * s2 * (w1 + w2) ** 2], -1)
    return np.einsum("...ij,...j->...i", j, qdd) + centripetal


def limits(game: dict[str, Any]) -> dict[str, float]:
    """``E*`` (J), ``V`` (m/s) and ``A`` (m/s^2) of steps 1 and 2."""
    p, corners, curl = game["arm"], game["corners"], game["curl"]
    q2 = np.linspace(0.0, 2 * math.pi, ELBOW_GRID, endpoint=False)
    angle = np.linspace(0.0, 2 * math.pi, DIRECTIONS, endpoint=False)
    u = np.stack([np.cos(angle), np.sin(angle)], -1)
    damping = np.array([p.damping1, p.damping2])
    scale = np.max(corners @ u.T, axis=0) / (u * u @ damping)  # R's edge along each direction
    m = mass(p, q2)
    energy = MARGIN * float(np.max(0.5 * scale[None, :] ** 2 * np.einsum("ki,qij,kj->qk", u, m, u)))
    j = jacobian(p, q2)
    # Speeds of energy E*: w = sqrt(2 E*) L^-T u with M = L L'.
    chol = np.linalg.cholesky(m)
    w = math.sqrt(2 * energy) * np.linalg.solve(np.swapaxes(chol, -1, -2)[:, None], u[None, :, :, None])[..., 0]
    speed = MARGIN * float(np.max(np.linalg.norm(np.einsum("qij,qkj->qki", j, w), axis=-1)))
    q2w = np.broadcast_to(q2[:, None], w.shape[:2])
    zero = np.zeros(2)
    torque = np.max(np.linalg.norm(hand_acceleration(p, q2[:, None], np.zeros((1, 1, 2)), corners[None], 0.0),
                                   axis=-1), axis=1)
    linear = hand_acceleration(p, q2w, w, zero, curl)
    # Split the speed terms: linear (damping, field) and quadratic (Coriolis, centripetal) are each largest on the
    # ellipse's edge, as they are homogeneous in w; the sum of the three largest bounds the largest sum.
    quadratic = hand_acceleration(p.replace(damping1=0.0, damping2=0.0), q2w, w, zero, 0.0)
    linear = linear - quadratic
    accel = torque + np.max(np.linalg.norm(linear, axis=-1), 1) + np.max(np.linalg.norm(quadratic, axis=-1), 1)
    return {"energy": energy, "speed": speed, "accel": MARGIN * float(np.max(accel))}


def hand(p: Any, q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    return np.stack([p.l1 * np.cos(q1) + p.l2 * np.cos(q1 + q2), p.l1 * np.sin(q1) + p.l2 * np.sin(q1 + q2)], -1)


def reach_time(u: np.ndarray, d: np.ndarray, accel: float) -> np.ndarray:
    """Step 3's least time to cover ``d`` (m) at acceleration ``accel`` from speed ``u`` toward it (stable form)."""
    root = np.sqrt(u * u + 2 * accel * d)
    return np.where(u > 0, 2 * d / (root + u + 1e-300), (root - u) / accel)


def bound(env_id: str) -> dict[str, Any]:
    game = game_of(env_id)
    p, r = game["arm"], game["radius"]
    lim = limits(game)
    accel, speed = lim["accel"], lim["speed"]
    lo1, hi1 = game["shoulder"]
    lo2, hi2 = game["elbow"]
    mid = (np.arange(DRAW_GRID) + 0.5) / DRAW_GRID
    g1, g2 = np.meshgrid(lo1 + (hi1 - lo1) * mid, lo2 + (hi2 - lo2) * mid)
    draws = hand(p, g1.ravel(), g2.ravel())
    cm = np.linspace(0.0, 1.0, CENTRE_GRID)
    c1, c2 = np.meshgrid(lo1 + (hi1 - lo1) * cm, lo2 + (hi2 - lo2) * cm)
    centres = hand(p, c1.ravel(), c2.ravel())
    ring = np.array([[0.0, 0.0]] + [[r * math.cos(a), r * math.sin(a)] for a in np.arange(8) * math.pi / 4])
    hands = (centres[:, None, :] + ring[None]).reshape(-1, 2)
    dwell = (game["hold"] - 1) * game["dt"]
    best, oracle = math.inf, math.inf
    for h in hands:
        x = draws - h
        dist = np.linalg.norm(x, axis=1)
        keep = dist > 3 * r
        x, dist = x[keep], dist[keep]
        unit = x / dist[:, None]

        def expected(v0: np.ndarray, unit: np.ndarray = unit, dist: np.ndarray = dist) -> np.ndarray:
            return reach_time(v0 @ unit.T, dist[None, :] - r, accel).mean(axis=1)

        # A polar grid of v0, then two finer square grids around its best (the expectation is convex in v0).
        sp, an = np.meshgrid(np.linspace(0, speed, 41), np.linspace(0, 2 * math.pi, 72, endpoint=False))
        v0 = np.stack([(sp * np.cos(an)).ravel(), (sp * np.sin(an)).ravel()], -1)
        values = expected(v0)
        centre, step = v0[np.argmin(values)], speed / 40
        for _ in range(2):
            off = np.linspace(-step, step, 21)
            grid = centre + np.stack(np.meshgrid(off, off), -1).reshape(-1, 2)
            grid = grid[np.linalg.norm(grid, axis=1) <= speed]
            values = expected(grid)
            centre, step = grid[np.argmin(values)], step / 10
        best = min(best, float(values.min()))
        oracle = min(oracle, float(reach_time(np.full(len(dist), speed), dist - r, accel).mean()))
    span = float(np.max(np.linalg.norm(draws[:, None] - draws[None], axis=-1))) + 2 * r
    longest = float(reach_time(np.array(-speed), np.array(span), accel)) + dwell
    limit = game["time_limit"]
    out = {"env_id": env_id, "time_limit": limit, "radius": r, "dwell": dwell, **lim, "longest_reach": longest}
    for name, g in (("bound", best + dwell), ("oracle", oracle + dwell)):
        out[f"{name}_reach"] = g
        out[f"{name}_hits"] = (limit + longest) / g - 1
    return out


RESULTS = Path(__file__).resolve().parent / "results"


def committed_scores(results: Path = RESULTS) -> dict[str, float]:
    """Each Reach id's best committed mean hits: PPO's runs (each seed), the controller's and the reference's results
    (for every id playing their games), the bots and protocol 1's PPO (``references.py``) and protocol 2's ceiling."""
    import importlib.util

    from armgame.env.references import CEILINGS, REFERENCE_HITS

    spec = importlib.util.spec_from_file_location("ceiling_benchmark", Path(__file__).resolve().parent / "ceiling.py")
    bench = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(bench)  # type: ignore[union-attr]
    best: dict[str, float] = {}

    def seen(env_id: str, hits: float) -> None:
        if "CenterOut" not in env_id:
            best[env_id] = max(best.get(env_id, -math.inf), hits)

    for path in results.glob("ppo*/**/result.json"):
        result = json.loads(path.read_text(encoding="utf-8"))
        seen(result["env_id"], float(result["mean_hits"]))
    for folder in ("ceiling", "reference"):
        for path in (results / folder).glob("*.json"):
            data = bench.read_result(path)
            for env_id in (data["env_id"], *[k for k, v in bench.STANDS_FOR.items() if v == data["env_id"]]):
                if data["hits"]:
                    seen(env_id, float(np.mean(data["hits"])))
    for env_id, row in REFERENCE_HITS.items():
        for policy in ("random", "naive", "model", "ppo"):
            seen(env_id, row[policy])
    for env_id, row in CEILINGS.items():
        seen(env_id, row["hits"])
    return best


def table(rows: list[dict[str, Any]], results: Path = RESULTS) -> str:
    """docs/programs.md's table of the bound, each game's best measured score over every id that plays its games."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("ceiling_benchmark", Path(__file__).resolve().parent / "ceiling.py")
    bench = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(bench)  # type: ignore[union-attr]
    scores = committed_scores(results)
    lines = ["| game | `E*` (J) | `V` (m/s) | `A` (m/s^2) | mean reach at least (ms) | bound: hits a game "
             "| an oracle's | best measured | bound / best |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for row in rows:
        best = max(v for k, v in scores.items() if bench.STANDS_FOR.get(k, k) == row["env_id"])
        lines.append(f"| `{row['env_id'].split('/')[1]}` | {row['energy']:.1f} | {row['speed']:.1f} | "
                     f"{row['accel']:.0f} | {row['bound_reach'] * 1000:.0f} | **{row['bound_hits']:.0f}** | "
                     f"{row['oracle_hits']:.0f} | {best:.1f} | {row['bound_hits'] / best:.0f} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ids", nargs="+", default=list(DISTINCT))
    parser.add_argument("--out", type=Path, default=None)
    parser.add_argument("--table", type=Path, default=None, metavar="RESULT",
                        help="print docs/programs.md's table from a result of --out (and the committed scores)")
    args = parser.parse_args(argv)
    if args.table is not None:
        try:
            print(table(json.loads(args.table.read_text(encoding="utf-8"))))
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise SystemExit(f"{args.table}: not a result of hit_bound.py --out ({type(exc).__name__})") from None
        return 0
    for env_id in args.ids:
        if env_id not in DISTINCT:
            raise SystemExit(f"{env_id}: not one of the five distinct Reach games ({', '.join(DISTINCT)})")
    rows = []
    for env_id in args.ids:
        row = bound(env_id)
        rows.append(row)
        print(f"{env_id}: at most {row['bound_hits']:.0f} hits a game "
              f"(an oracle of the draws {row['oracle_hits']:.0f});"
              f" E* {row['energy']:.2f} J, V {row['speed']:.2f} m/s, A {row['accel']:.1f} m/s^2, "
              f"a reach at least {row['bound_reach'] * 1000:.0f} ms on average", flush=True)
    if args.out is not None:
        args.out.write_text(json.dumps(rows, indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
