"""The reference controller's scores on the test games (issue 40's ceiling): ``armgame.env.ceiling``.

    python benchmarks/ceiling.py run --ids armgame/Reach-v1 --out benchmarks/results/ceiling     # 100 test games
    python benchmarks/ceiling.py run --ids armgame/ReachHold-v1 --games 3 --seconds 20 --out /tmp/look  # a look
    python benchmarks/ceiling.py show benchmarks/results/ceiling                                 # what is there
    python benchmarks/ceiling.py run --reference --out benchmarks/results/reference  # protocol 3's reference

``run`` plays ``armgame.env.evaluate`` with a fresh ``ShootingController`` a game on the first ``--games`` test
seeds of each id (the settings below, per id), ten games a call, and writes each id's hits so far to
``OUT/ID.json`` after every call: a run stopped part way goes on from there the next time (the games already
played are kept, the rest played), so a long measurement spreads over sittings. The continuous twins' games are
their key ids' game for game (levels 0 and 1 act exactly as keys: ``tests/test_ceiling.py``), and the observation
delay never reaches a controller that reads the true state, so ``ReachDelay-v1`` is ``Reach-v1`` and
``ReachDelayContinuous-v1`` too: ``run`` measures the five distinct games (``DISTINCT``) and ``show`` says which
id's result stands for which.

``--reference`` plays protocol 3's reference settings (``REFERENCE``: per id, the strongest tried) instead of
issue 40's, and each file then also holds the decisions played and the machine's processor, so the CPU a decision
costs is measured in the run that scores it. An id whose reference settings are issue 40's needs no new run: its
``benchmarks/results/ceiling`` file is its reference (``reference_scores.py`` reads both folders).

Bad input (an unknown id, a result file that is not one) is one line and exit 1.
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

import armgame.env
from armgame.env.ceiling import ShootingController
from armgame.env.evaluation import mean_interval
from armgame.env.suite import EVALUATION_SEEDS, TIER_GAMES, suite_ids

#: The controller's arguments per id (the defaults elsewhere): measured on three games of 20 s each
#: (``--games 3 --seconds 20``), the cheapest setting within a hit a minute of the best tried.
SETTINGS: dict[str, dict[str, Any]] = {
    "armgame/ReachNoisy-v1": {"replan": 1},
    "armgame/ReachHard-v1": {"coarse": 15, "fine": 4},
}

#: Protocol 3's reference: the controller's arguments per id, the strongest tried on the first three test games
#: (docs/programs.md, "Protocol 3's reference"). ``replan=1`` (a closed loop every decision) gained 8 hits in 3 games
#: on ReachHard-v1 (54, 53, 58 against 52, 50, 55) and 3 on ReachField-v1 (71, 69, 72 against 70, 68, 71), 1 on
#: ReachHold-v1 and lost 2 on Reach-v1, at two to three times the CPU, so ReachHard-v1's and ReachField-v1's
#: settings change; ReachNoisy-v1's were already ``replan=1``.
REFERENCE: dict[str, dict[str, Any]] = {**SETTINGS, "armgame/ReachHard-v1": {"replan": 1, "coarse": 15, "fine": 4},
                                        "armgame/ReachField-v1": {"replan": 1}}

#: The ids whose games differ for the controller; every other Reach id's games are one of these (``STANDS_FOR``).
DISTINCT = ("armgame/Reach-v1", "armgame/ReachHold-v1", "armgame/ReachNoisy-v1", "armgame/ReachField-v1",
            "armgame/ReachHard-v1")

#: Which measured id's games each other Reach id plays, game for game, under the controller.
STANDS_FOR = {"armgame/ReachContinuous-v1": "armgame/Reach-v1", "armgame/ReachDelay-v1": "armgame/Reach-v1",
              "armgame/ReachDelayContinuous-v1": "armgame/Reach-v1",
              **{f"armgame/{name}Continuous-v1": f"armgame/{name}-v1"
                 for name in ("ReachHold", "ReachNoisy", "ReachField", "ReachHard")},
              # The separating tier hides part of the observation, never the game, and only what an agent that
              # remembers can know (the target it saw; speeds and activations from the positions and its keys).
              **{f"armgame/{name}-v1": f"armgame/{game}-v1" for name, game in TIER_GAMES.items()}}

CHUNK = 10


def slug(env_id: str) -> str:
    return env_id.split("/")[-1]


def read_result(path: Path) -> dict[str, Any]:
    """A result file of ``run``, checked: one line (SystemExit) if it is not one."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise SystemExit(f"{path}: not a ceiling result ({type(exc).__name__})") from None
    hits = data.get("hits") if isinstance(data, dict) else None
    if (not isinstance(hits, list) or not all(isinstance(h, int) and not isinstance(h, bool) and h >= 0 for h in hits)
            or not isinstance(data.get("env_id"), str) or not isinstance(data.get("settings"), dict)):
        raise SystemExit(f"{path}: not a ceiling result (env_id, settings and a list of hits expected)")
    return data


def processor() -> str:
    """The machine's processor as its OS names it (Linux's /proc/cpuinfo), else ``platform``'s word for it."""
    try:
        for line in Path("/proc/cpuinfo").read_text(encoding="utf-8").splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def decision_seconds(env_id: str) -> float:
    """The game time (s) one decision of ``env_id`` lasts."""
    import gymnasium as gym

    env = gym.make(env_id)
    settings = env.unwrapped.settings
    env.close()
    return settings.decision_steps * settings.config.dt


def run(out: Path, ids: list[str], games: int, seconds: float | None, reference: bool = False) -> None:
    out.mkdir(parents=True, exist_ok=True)
    for env_id in ids:
        settings = (REFERENCE if reference else SETTINGS).get(env_id, {})
        path = out / f"{slug(env_id)}.json"
        hits: list[int] = []
        cpu = 0.0
        if path.is_file():
            done = read_result(path)
            if done["settings"] != settings or done.get("time_limit") != seconds:
                raise SystemExit(f"{path}: played with other settings; move it away to measure afresh")
            hits, cpu = list(done["hits"]), float(done.get("cpu_seconds", 0.0))
        kwargs = {} if seconds is None else {"time_limit": seconds}
        while len(hits) < games:
            seeds = EVALUATION_SEEDS[len(hits):min(games, len(hits) + CHUNK)]
            start = time.process_time()
            part = armgame.env.evaluate("shooting", env_id, seeds=seeds,
                                        policy_factory=partial(ShootingController, **settings), **kwargs)
            cpu += time.process_time() - start
            hits += [int(h) for h in part.hits]
            low, high = mean_interval(hits)
            record = {"env_id": env_id, "controller": "armgame.env.ceiling.ShootingController", "settings": settings,
                      "time_limit": seconds, "first_seed": EVALUATION_SEEDS[0], "hits": hits, "cpu_seconds": cpu,
                      "machine": f"{platform.machine()}, {platform.python_version()}, armgame {armgame.__version__}"}
            if reference:
                record["decisions"] = round(len(hits) * part.minutes * 60.0 / decision_seconds(env_id))
                record["processor"] = processor()
            tmp = path.with_suffix(".tmp")
            tmp.write_text(json.dumps(record, indent=1) + "\n", encoding="utf-8")
            tmp.replace(path)
            print(f"{env_id}: {len(hits)} games, {np.mean(hits):.1f} hits a game (95% CI {low:.1f} to {high:.1f}), "
                  f"{cpu / (len(hits) * part.minutes * 60.0):.3f} CPU s a game second", flush=True)


def summary(folder: Path) -> dict[str, tuple[float, float, float, int, str]]:
    """Each Reach id's ceiling controller score from ``folder``: (mean, low, high, games, the id measured)."""
    measured = {}
    for path in sorted(folder.glob("*.json")):
        data = read_result(path)
        if data["hits"]:
            low, high = mean_interval(data["hits"])
            measured[data["env_id"]] = (float(np.mean(data["hits"])), low, high, len(data["hits"]))
    rows = {}
    for env_id in (*DISTINCT, *STANDS_FOR):
        source = STANDS_FOR.get(env_id, env_id)
        if source in measured:
            rows[env_id] = (*measured[source], source)
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="play the test games (goes on where a last sitting stopped)")
    r.add_argument("--ids", nargs="+", default=list(DISTINCT))
    r.add_argument("--games", type=int, default=100)
    r.add_argument("--seconds", type=float, default=None, help="a shorter game (default: the id's 60 s)")
    r.add_argument("--out", type=Path, required=True)
    r.add_argument("--reference", action="store_true", help="protocol 3's reference settings (REFERENCE)")
    s = sub.add_parser("show", help="each Reach id's score from a folder of results")
    s.add_argument("folder", type=Path)
    args = parser.parse_args(argv)
    if args.command == "run":
        known = set(suite_ids()) | {"armgame/Reach-v1", "armgame/ReachContinuous-v1"}
        for env_id in args.ids:
            if env_id not in known or "CenterOut" in env_id:
                raise SystemExit(f"{env_id}: not a Reach id of the suite")
        if not 1 <= args.games <= 1000:
            raise SystemExit(f"--games {args.games}: expected 1 to 1000")
        run(args.out, args.ids, args.games, args.seconds, args.reference)
    else:
        for env_id, (mean, low, high, games, source) in summary(args.folder).items():
            note = "" if source == env_id else f" (the games of {source})"
            print(f"{env_id}: {mean:.1f} hits a game (95% CI {low:.1f} to {high:.1f}), {games} games{note}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
