"""The suite's reference scores: random, the naive bot, the model bot and PPO on every v1 id.

    python benchmarks/reference_scores.py bots --out refs            # the three fixed policies, 100 games each
    python benchmarks/reference_scores.py bots --out refs --ids armgame/CenterOutHold-v1 --policies naive model
    python benchmarks/reference_scores.py bots --out benchmarks/results/center-out-time --policies shooting \
        --ids armgame/CenterOut-v1 armgame/CenterOutContinuous-v1 armgame/CenterOutHold-v1 \
        armgame/CenterOutHoldContinuous-v1                           # CenterOut's shooting controller
    python benchmarks/reference_scores.py ppo armgame/ReachHold-v1 --seed 0 --out refs   # one PPO run (rl extra)
    python benchmarks/reference_scores.py table                      # docs/programs.md's table, from the results
    python benchmarks/reference_scores.py ceilings                   # armgame/env/references.py's CEILINGS
    python benchmarks/reference_scores.py runs-table                 # docs/programs.md's table of the protocol runs
    python benchmarks/reference_scores.py tier-table                 # docs/programs.md's table of the separating tier
    python benchmarks/reference_scores.py center-out-table           # CenterOut's hits a minute and time to target
    python benchmarks/reference_scores.py figure                     # docs/img/ppo_curves.png, their curves
    python benchmarks/reference_scores.py table-v1 refs              # protocol 1's table (the model bot normalising)
    python benchmarks/reference_scores.py references refs            # armgame/env/references.py's dict
    python benchmarks/reference_scores.py aggregate runs             # IQM over train_ppo.py --out runs' result.json
    python benchmarks/reference_scores.py aggregate runs --protocol 2  # the same, normalised by protocol 2's ceilings
    python benchmarks/reference_scores.py curves benchmarks/results/ppo  # the committed runs' curves over seeds
    python benchmarks/reference_scores.py runs --ids armgame/ReachHard-v1 --seeds 0 1 2 3 4 --steps 4000000 \
        --out benchmarks/results/ppo                                 # protocol runs, over as many sittings as it takes

``runs`` is how long runs are spread over sittings (issue 40, item 1): each (id, training seed) is one
``examples/train_ppo.py --out OUT/ID/seedN`` run; a finished one (its ``result.json``) is skipped, an interrupted
one started again, so the same command goes on where the last sitting stopped, and its files (not the model,
which .gitignore leaves out) are committed as they come; ``curves`` and ``aggregate`` are made from them.

Every score is ``armgame.env.evaluate`` on the evaluation seeds (the first 100 of
``EVALUATION_SEEDS``), so the numbers here and a paper's are hits on the same games. PPO is
``examples/train_ppo.py``'s recipe (SB3's defaults but ``n_steps=128``, ``batch_size=256`` over 32
envs, one torch thread), trained for a fixed budget of env steps (``PPO_STEPS``) on game seeds below
the evaluation range, then its deterministic policy evaluated. Each result is one JSON file in
``--out``; ``table`` reads them all. ``armgame/env/references.py`` holds the table's numbers that
``evaluate`` normalises by (random and the model bot) and ``tests/test_env_suite.py`` checks them.
"""

from __future__ import annotations

import argparse
import functools
import json
import platform
import sys
import textwrap
import time
from pathlib import Path
from typing import Any

import numpy as np

import armgame.env  # noqa: F401  (registers the ids)
from armgame.env.errors import EnvArgumentError
from armgame.env.evaluation import evaluate
from armgame.env.suite import PROTOCOL_VERSION, PROTOCOLS, suite_ids

GAMES = 100
PPO_STEPS = 500_000
IDS = ("armgame/Reach-v1", "armgame/ReachContinuous-v1", "armgame/CenterOut-v1", "armgame/CenterOutContinuous-v1",
       *suite_ids())


#: The candidates for a CenterOut id's protocol 3 reference (``center_out_references``), by the policy their
#: ``bots`` file names, with the code that plays each.
CENTER_OUT_REFERENCES = {"model": 'armgame.env.evaluate("model", ...): the model bot',
                         "shooting": "armgame.env.center_out_reference.CenterOutShootingController()"}
#: Game seconds a decision (an env step) of every v1 id: 5 physics steps of 4 ms.
DECISION_SECONDS = 0.02


def slug(env_id: str) -> str:
    return env_id.split("/")[-1]


def hit_range(env_id: str) -> dict[str, float]:
    """The values a mean of hits a game can take on ``env_id``, as ``mean_interval``'s ``low`` and ``high``: from 0
    to, on a CenterOut id, the trials an episode holds (every one hit); a Reach game's hits have no fixed top."""
    import gymnasium

    if "CenterOut" not in env_id:
        return {"low": 0.0, "high": float("inf")}
    from armgame.env.center_out_v1 import DEFAULT_EPISODE_TRIALS

    trials = gymnasium.spec(env_id).kwargs.get("episode_trials", DEFAULT_EPISODE_TRIALS)
    return {"low": 0.0, "high": float(trials) if isinstance(trials, int) else float("inf")}


def per_minute_interval(data: dict[str, Any], path: Path | str = "a bots file") -> tuple[float, float]:
    """Hits a minute's 95 % interval over the games of a ``bots`` file (``ratio_interval`` of each game's hits and
    minutes, never below 0); a file from before ``bots`` kept each game's minutes is refused in one line."""
    from armgame.env.evaluation import ratio_interval

    if "game_minutes" not in data:
        raise ValueError(f"{path}: no game_minutes (a run before bots kept each game's length): run bots again")
    return ratio_interval(data["hits"], data["game_minutes"], low=0.0)


def run_bots(out: Path, ids: tuple[str, ...], games: int,
             policies: tuple[str, ...] = ("random", "naive", "model")) -> None:
    for env_id in ids:
        for policy in policies:
            start, cpu = time.perf_counter(), time.process_time()
            result = evaluate(policy, env_id, games=games, policy_factory=_factory(policy))
            # CenterOut: each game's seconds from a go cue to a hit too, which ranks policies that hit every trial;
            # and the CPU a decision cost, the env's step included, for protocol 3's reference (the model bot's).
            # Every game's decisions, not a mean game's times the games: episodes differ in length.
            decisions = round(sum(result.game_minutes) * 60 / DECISION_SECONDS)
            # Each game's minutes too: a CenterOut episode lasts as its trials take, and hits a minute's interval
            # (Evaluation.hits_per_minute_ci95) is over the games' hits and lengths, not a mean game's.
            timing = {"hits_per_minute": round(result.hits_per_minute, 4), "minutes": round(result.minutes, 6),
                      "game_minutes": [round(m, 8) for m in result.game_minutes],
                      "cpu_seconds": round(time.process_time() - cpu, 3), "decisions": decisions,
                      "processor": _ceiling_benchmark().processor()} | (
                {"reach_seconds": [None if np.isnan(t) else round(t, 4) for t in result.reach_seconds]}
                if result.reach_seconds else {})
            write(out / f"{slug(env_id)}.{policy}.json", env_id, policy, result.hits, time.perf_counter() - start,
                  timing)
            print(result.summary(), flush=True)


def _factory(policy: str) -> Any:
    """``shooting``: a fresh ``CenterOutShootingController`` a game (``armgame.env.center_out_reference``, a
    CenterOut id's time-optimal controller on the true state); the bots need none."""
    if policy != "shooting":
        return None
    from armgame.env.center_out_reference import CenterOutShootingController

    return CenterOutShootingController


def run_ppo(out: Path, env_id: str, seed: int, steps: int, games: int) -> None:
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecMonitor

    from armgame.env.sb3 import make_sb3_vec_env

    torch.set_num_threads(1)
    start = time.perf_counter()
    envs = VecMonitor(make_sb3_vec_env(env_id, 32, seed=seed * 1000))
    model = PPO("MlpPolicy", envs, n_steps=128, batch_size=256, seed=seed, device="cpu", verbose=0)
    model.learn(steps)
    trained = time.perf_counter() - start
    result = evaluate(model, env_id, games=games)
    write(out / f"{slug(env_id)}.ppo-{seed}.json", env_id, f"ppo-{seed}", result.hits, trained,
          {"steps": steps, "train_seconds": round(trained, 1)})
    print(f"{result.summary()} after {steps:,} steps in {trained:.0f} s", flush=True)


def write(path: Path, env_id: str, policy: str, hits: tuple[int, ...], seconds: float,
          extra: dict | None = None) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    record = {"env_id": env_id, "policy": policy, "games": len(hits), "mean_hits": float(np.mean(hits)),
              "hits": list(hits), "seconds": round(seconds, 1), "machine": platform.processor() or platform.machine(),
              **(extra or {})}
    path.write_text(json.dumps(record, indent=1) + "\n", encoding="utf-8")


def references_of(folder: Path, first: int = 5) -> dict[str, dict[str, Any]]:
    """Each id's reference entry from the runs in ``folder``, in ``IDS``' order (an id whose three bots have not all
    run is left out): mean hits by policy (PPO: the mean of its seeds' means) and the first ``first`` games'
    hits of random and the model bot, which the tests replay. The table and references.py are both this."""
    runs: dict[str, dict[str, dict]] = {}
    for path in sorted(folder.glob("*.json")):
        r = json.loads(path.read_text(encoding="utf-8"))
        runs.setdefault(r["env_id"], {})[r["policy"]] = r
    entries: dict[str, dict[str, Any]] = {}
    for env_id in sorted(runs, key=lambda i: IDS.index(i) if i in IDS else len(IDS)):
        row = runs[env_id]
        if not {"random", "naive", "model"} <= set(row):
            continue
        ppo = [row[k]["mean_hits"] for k in sorted(row) if k.startswith("ppo-")]
        entry: dict[str, Any] = {p: round(row[p]["mean_hits"], 2) for p in ("random", "naive", "model")}
        if ppo:
            entry["ppo"] = round(float(np.mean(ppo)), 4)
            entry["ppo_seeds"] = [round(v, 2) for v in ppo]
        entry["random_first"] = row["random"]["hits"][:first]
        entry["model_first"] = row["model"]["hits"][:first]
        entries[env_id] = entry
    return entries


def table_v1(folder: Path) -> str:
    """Protocol 1's table (the model bot normalising): the reference entries and PPO's normalised score."""
    lines = ["| id | random | naive bot | model bot | PPO: mean (each training seed) | PPO normalised |",
             "|---|---|---|---|---|---|"]
    for env_id, entry in references_of(folder).items():
        cells = [f"{entry[p]:.1f}" for p in ("random", "naive", "model")]
        if "ppo" in entry:
            low, high, mean = entry["random"], entry["model"], entry["ppo"]
            cells.append(f"{mean:.1f} ({', '.join(f'{p:.1f}' for p in entry['ppo_seeds'])})")
            cells.append(f"{(mean - low) / (high - low):.2f}")
        else:
            cells += ["not measured", ""]
        lines.append(f"| `{env_id.split('/')[-1]}` | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def references(folder: Path) -> str:
    """``armgame/env/references.py``'s dict, as Python source."""
    lines = ["REFERENCE_HITS: dict[str, dict[str, Any]] = {"]
    for env_id, entry in references_of(folder).items():
        items = ", ".join(f"{json.dumps(k)}: {json.dumps(v)}" for k, v in entry.items())
        lines.append(f"    {json.dumps(env_id)}: {{")
        lines.append(textwrap.fill(items, width=116, initial_indent=" " * 8, subsequent_indent=" " * 8))
        lines.append("    },")
    lines.append("}")
    return "\n".join(lines)


RESULTS = Path(__file__).resolve().parent / "results"

#: The fewest training seeds whose mean counts toward a ceiling (the protocol's five).
CEILING_SEEDS = 5


def long_runs(root: Path = RESULTS) -> dict[str, dict[int, list[float]]]:
    """Each id's protocol runs committed under ``root`` (``runs``' folders ``ppo*``, a budget each): budget (env
    steps) -> every finished training seed's mean hits on the test games, by seed."""
    found: dict[str, dict[int, list[float]]] = {}
    for (env_id, budget), runs in protocol_run_sets(root).items():
        found.setdefault(env_id, {})[budget] = [float(result["mean_hits"]) for _, _, result in runs]
    return found


def _reference_hits() -> dict[str, dict[str, Any]]:
    from armgame.env.references import REFERENCE_HITS

    return REFERENCE_HITS


def _controller_rows(folder: Path) -> dict[str, tuple[float, float, float, int, str]]:
    """``benchmarks/ceiling.py``'s ``summary`` of ``folder`` (none where there is no folder)."""

    if not folder.is_dir():
        return {}
    return _ceiling_benchmark().summary(folder)


def ceilings(reference: dict[str, dict[str, Any]] | None = None, controller_folder: Path = RESULTS / "ceiling",
             root: Path = RESULTS) -> dict[str, dict[str, Any]]:
    """Protocol 2's ceiling of every id with reference scores: the best mean hits measured on its 100 test games by
    a policy that knows the task or has learnt it, and which that is. The candidates: the shooting controller
    (``benchmarks/ceiling.py``'s results), PPO's protocol runs of five training seeds or more at any budget (the
    mean over seeds), protocol 1's PPO (500,000 env steps, three seeds), for CenterOut the trials an episode holds
    (every one hit), for a continuous twin its key id's ceiling (its levels 0 and 1 are the keys, so it can play
    whatever the key id plays), and for an id without an observation delay the ceiling of its delayed variant (the
    same games: a policy can delay what it sees itself, so the delay can only cost)."""
    if reference is None:
        reference = _reference_hits()
    return _ceilings_of(reference, _controller_rows(controller_folder), long_runs(root))


def _ceilings_of(reference: dict[str, dict[str, Any]], controller: dict[str, tuple[float, float, float, int, str]],
                 runs: dict[str, dict[int, list[float]]]) -> dict[str, dict[str, Any]]:
    delayed = delayed_variants(list(reference))
    out: dict[str, dict[str, Any]] = {}
    # Delayed ids first (the id without the delay reads theirs), then key ids before twins (a twin reads its key id's).
    for env_id in sorted(reference, key=lambda i: (i in delayed, "Continuous" in i)):
        entry = reference[env_id]
        candidates: list[tuple[float, str]] = []
        if "CenterOut" in env_id:
            from armgame.env.center_out_v1 import DEFAULT_EPISODE_TRIALS

            candidates.append((float(DEFAULT_EPISODE_TRIALS), "every trial of the episode hit"))
        if env_id in controller:
            mean, _, _, games, source = controller[env_id]
            seen = "" if source == env_id else f", {slug(source)}'s games"
            candidates.append((round(mean, 4), f"the shooting controller ({games} games{seen})"))
        if "ppo" in entry:
            candidates.append((entry["ppo"], f"PPO, {PPO_STEPS:,} env steps, {len(entry['ppo_seeds'])} seeds"))
        for budget, means in runs.get(env_id, {}).items():
            if len(means) >= CEILING_SEEDS:
                candidates.append((round(float(np.mean(means)), 4), f"PPO, {budget:,} env steps, {len(means)} seeds"))
        key = env_id.replace("Continuous", "")
        if key != env_id and key in out:
            candidates.append((out[key]["hits"], f"{slug(key)}'s ceiling"))
        for variant in delayed.get(env_id, ()):
            candidates.append((out[variant]["hits"], f"{slug(variant)}'s ceiling (a delay can only cost)"))
        hits, by = max(candidates, key=lambda c: c[0])
        out[env_id] = {"hits": hits, "by": by}
    return {env_id: out[env_id] for env_id in reference if env_id in out}


def delayed_variants(env_ids: list[str]) -> dict[str, list[str]]:
    """For each of ``env_ids``, the others that are the same game with an observation delay added (the same spec
    but ``observation_delay``): ``{"armgame/Reach-v1": ["armgame/ReachDelay-v1"], ...}``."""
    import gymnasium

    specs = {env_id: gymnasium.spec(env_id) for env_id in env_ids}
    delay = {env_id: spec.kwargs.get("observation_delay") for env_id, spec in specs.items()}
    game = {env_id: (str(spec.entry_point), sorted((k, v) for k, v in spec.kwargs.items() if k != "observation_delay"))
            for env_id, spec in specs.items()}
    found: dict[str, list[str]] = {}
    for env_id in env_ids:
        if delay[env_id]:
            for other in env_ids:
                if not delay[other] and game[other] == game[env_id]:
                    found.setdefault(other, []).append(env_id)
    return found


def table(reference: dict[str, dict[str, Any]] | None = None, controller_folder: Path = RESULTS / "ceiling",
          root: Path = RESULTS) -> str:
    """docs/programs.md's reference table (protocol 2): the bots, the shooting controller, PPO (its longest protocol
    runs of five seeds or more, else protocol 1's) and the ceiling, each with its interval, PPO normalised by it."""
    from armgame.env.evaluation import mean_interval

    if reference is None:
        reference = _reference_hits()
    controller = _controller_rows(controller_folder)
    runs = long_runs(root)
    tops = _ceilings_of(reference, controller, runs)
    lines = ["| id | random | model bot | shooting controller (95% CI) | PPO: env steps, seeds: mean (95% CI over "
             "seeds) | ceiling: hits, by | PPO normalised |", "|---|---:|---:|---|---|---|---:|"]
    for env_id, entry in reference.items():
        cells = [f"{entry['random']:.1f}", f"{entry['model']:.1f}"]
        if env_id in controller:
            mean, low, high, _, source = controller[env_id]
            cells.append(f"{mean:.1f} ({low:.1f}-{high:.1f})" + ("" if source == env_id else f" = {slug(source)}"))
        else:
            cells.append("")
        long = [(budget, means) for budget, means in runs.get(env_id, {}).items() if len(means) >= CEILING_SEEDS]
        budget, means = long[-1] if long else (PPO_STEPS, entry.get("ppo_seeds", []))
        if means:
            low, high = mean_interval(means)  # protocol 2's table as published (no interval of it is below 0)
            ppo = float(np.mean(means))
            cells.append(f"{budget / 1e6:g} M, {len(means)}: {ppo:.1f} ({low:.1f}-{high:.1f})")
        else:
            cells.append("")
        top = tops[env_id]
        cells.append(f"**{top['hits']:.1f}**, {top['by']}")
        cells.append(f"{(ppo - entry['random']) / (top['hits'] - entry['random']):.2f}" if means else "")
        lines.append(f"| `{slug(env_id)}` | " + " | ".join(cells) + " |")
    return "\n".join(lines)


@functools.cache
def _ceiling_benchmark() -> Any:
    """``benchmarks/ceiling.py`` as a module, run once however many tables and runs read it."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("ceiling_benchmark", Path(__file__).resolve().parent / "ceiling.py")
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


def references_v3(ceiling_folder: Path = RESULTS / "ceiling", reference_folder: Path = RESULTS / "reference",
                  center_out_folder: Path = RESULTS / "center-out-time") -> dict[str, dict[str, Any]]:
    """Protocol 3's reference of every Reach id: the shooting controller at ``benchmarks/ceiling.py``'s
    ``REFERENCE`` settings, its mean hits on the test games played so far (``games`` of them, with the 95 % interval
    over games), the code that plays it, and the CPU seconds a decision cost in the same run, on its machine. Read
    from ``reference_folder`` where it holds the id at those settings, else from ``ceiling_folder`` (issue 40's runs,
    whose settings are the reference's on four ids). An id whose games are another's (``STANDS_FOR``) takes its."""
    from armgame.env.evaluation import mean_interval

    bench = _ceiling_benchmark()
    measured: dict[str, dict[str, Any]] = {}
    for env_id in bench.DISTINCT:
        settings = bench.REFERENCE.get(env_id, {})
        for folder in (reference_folder, ceiling_folder):
            path = folder / f"{bench.slug(env_id)}.json"
            if path.is_file() and bench.read_result(path)["settings"] == settings:
                data = bench.read_result(path)
                break
        else:
            continue
        hits = data["hits"]
        low, high = mean_interval(hits, **hit_range(env_id))
        decisions = data.get("decisions", len(hits) * 3000)  # issue 40's runs: 60 s games of 20 ms decisions
        arguments = ", ".join(f"{k}={v!r}" for k, v in settings.items())
        measured[env_id] = {
            "hits": round(float(np.mean(hits)), 3), "low": round(low, 3), "high": round(high, 3), "games": len(hits),
            "code": f"armgame.env.ceiling.ShootingController({arguments})",
            "cpu_per_decision": round(float(data["cpu_seconds"]) / decisions, 5),
            "machine": f"{data.get('processor', 'processor not recorded')}; {data['machine']}",
            "games_of": env_id}
    from armgame.env.references import REFERENCE_HITS, TIER_HITS

    # Each id's own random play is its 0 (a continuous twin's random differs from its key id's, their games do not).
    reach = {env_id: {**measured[bench.STANDS_FOR.get(env_id, env_id)], "unit": "hits a game",
                      "random": (REFERENCE_HITS.get(env_id) or TIER_HITS[env_id])["random"]}
             for env_id in (*bench.DISTINCT, *bench.STANDS_FOR) if bench.STANDS_FOR.get(env_id, env_id) in measured}
    return reach | center_out_references(center_out_folder)


def center_out_references(folder: Path = RESULTS / "center-out-time") -> dict[str, dict[str, Any]]:
    """Protocol 3's reference of every CenterOut id: the policy with the most hits a minute on the 100 test games
    among the candidates' files in ``folder`` (``CENTER_OUT_REFERENCES``: those that record their CPU), since every
    trial is hit and speed is what still ranks them; the interval is hits a minute's over the games, from each game's
    hits and length (``per_minute_interval``: the reference hits every trial, so its episodes' lengths are what
    spread); the 0 is random play's hits a minute. An id without a candidate or random play's file is left out."""
    rows = {}
    for env_id in IDS:
        if "CenterOut" not in env_id:
            continue
        random = folder / f"{slug(env_id)}.random.json"
        candidates = [json.loads(path.read_text(encoding="utf-8")) for path in
                      (folder / f"{slug(env_id)}.{policy}.json" for policy in CENTER_OUT_REFERENCES) if path.is_file()]
        candidates = [data for data in candidates if "cpu_seconds" in data]  # a run before bots recorded their CPU
        if not (candidates and random.is_file()):
            continue
        data = max(candidates, key=lambda data: data["hits_per_minute"])
        low, high = per_minute_interval(data, folder / f"{slug(env_id)}.{data['policy']}.json")
        rows[env_id] = {
            "hits": round(data["hits_per_minute"], 3), "low": round(low, 3), "high": round(high, 3),
            "games": data["games"], "unit": "hits a minute",
            "random": round(json.loads(random.read_text(encoding="utf-8"))["hits_per_minute"], 4),
            "code": CENTER_OUT_REFERENCES[data["policy"]],
            "cpu_per_decision": round(data["cpu_seconds"] / data["decisions"], 6),
            "machine": f"{data['processor']}; {data['machine']}", "games_of": env_id}
    return rows


def tier_table(root: Path = RESULTS) -> str:
    """docs/programs.md's table of the separating tier (``armgame.env.suite.TIER``), from the committed results: each
    id's reference (``REFERENCES_V3``, its suite game's) and that game's bound (``hit_bound.json``), the bots' 100 test
    games (``tier-bots``), PPO's probe (one training seed at 300,000 env steps, ``tier-probe``), RecurrentPPO's (the
    same with an LSTM, ``examples/train_recurrent.py``, ``tier-recurrent``: a learner with memory) and PPO's protocol
    runs at 4 M env steps (``ppo-tier``: the seeds finished so far), with PPO's protocol 3 score."""
    from armgame.env.evaluation import mean_interval, normalised_score
    from armgame.env.references import REFERENCES_V3
    from armgame.env.suite import TIER, tier_ids

    bounds = {row["env_id"]: row for row in json.loads((root / "hit_bound.json").read_text(encoding="utf-8"))}
    bots = {(r["env_id"], r["policy"]): r for r in
            (json.loads(p.read_text(encoding="utf-8")) for p in sorted((root / "tier-bots").glob("*.json")))}
    lines = ["| id | hidden | reference: the shooting controller (95% CI, games) | bound | random | naive bot "
             "| model bot | PPO 300 k steps, 1 seed (protocol 3) | RecurrentPPO 300 k steps, 1 seed (protocol 3) "
             "| PPO 4 M steps: seeds done, mean (95% CI over seeds) | PPO / reference (protocol 3) |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---|---:|"]
    for env_id, name in zip(tier_ids(), TIER, strict=True):
        ref = REFERENCES_V3[env_id]
        hidden = ", ".join(f"`{k}={v!r}`" for k, v in TIER[name].items() if k in ("target_shown", "positions_only"))
        bound = bounds[ref["games_of"]]["bound_hits"]
        cells = [f"{bots[(env_id, p)]['mean_hits']:.2f}" if (env_id, p) in bots else "" for p in
                 ("random", "naive", "model")]
        probes = []
        for folder in ("tier-probe", "tier-recurrent"):  # PPO's and RecurrentPPO's: its hits, and its protocol 3 score
            probe_path = root / folder / slug(env_id) / "result.json"
            hits = json.loads(probe_path.read_text(encoding="utf-8"))["mean_hits"] if probe_path.is_file() else None
            probes.append("" if hits is None else f"{hits:.1f} ({normalised_score(env_id, hits, protocol=3):.2f})")
        means = [json.loads(p.read_text(encoding="utf-8"))["mean_hits"]
                 for p in sorted((root / "ppo-tier" / slug(env_id)).glob("seed*/result.json"))]
        if means:
            low, high = mean_interval(means, **hit_range(env_id))
            runs = f"{len(means)} of 5: {np.mean(means):.1f}" + (f" ({low:.1f}-{high:.1f})" if len(means) > 1 else "")
            score = f"{normalised_score(env_id, float(np.mean(means)), protocol=3):.2f}"
        else:
            runs, score = "0 of 5: not yet run", ""
        lines.append(f"| `{slug(env_id)}` | {hidden} | {ref['hits']:.1f} ({ref['low']:.1f}-{ref['high']:.1f}, "
                     f"{ref['games']}; {slug(ref['games_of'])}'s) | {bound:.0f} | {' | '.join(cells)} "
                     f"| {' | '.join(probes)} | {runs} | {score} |")
    return "\n".join(lines)


def center_out_timing_table(folder: Path = RESULTS / "center-out-time") -> str:
    """docs/programs.md's table of the CenterOut ids' policies (``bots``' files in ``folder``): hits, hits a minute
    and the seconds from a trial's go cue to its hit (the mean over games with a hit, 95 % interval over them),
    which ranks policies that all hit every trial; and PPO's timed runs (``center_out_ppo``), pooled over seeds.
    Every interval is clipped to the values its quantity can take (``mean_interval``: hits from 0 to the trials an
    episode holds, seconds and hits a minute from 0). Hits a minute's is over the games (``per_minute_interval``);
    PPO's files from before ``train_ppo.py`` kept each game's length have each seed's hits a minute only, so such a
    row's is over the seeds."""
    from armgame.env.evaluation import mean_interval, ratio_interval

    lines = ["| id | policy | hits a game (95% CI) | hits a minute (95% CI) | s from the go cue to a hit (95% CI) "
             "| games with a hit |", "|---|---|---|---|---|---:|"]
    paths = sorted(folder.glob("*.json"))
    rows = [json.loads(path.read_text(encoding="utf-8")) for path in paths]
    for r, path in zip(rows, paths, strict=True):
        r["per_minute"] = per_minute_interval(r, path)
    for env_id, results in center_out_ppo(folder / "ppo").items():  # pooled: every seed's 100 test games
        per_seed = [r["hits_per_minute"] for r in results]
        hits = [h for r in results for h in r["test_hits"]]
        if all("game_minutes" in r for r in results):  # runs since train_ppo.py kept each game's length
            minutes = [m for r in results for m in r["game_minutes"]]
            rate, per_minute = sum(hits) / sum(minutes), ratio_interval(hits, minutes, low=0.0)
        else:
            rate, per_minute = float(np.mean(per_seed)), (*mean_interval(per_seed, low=0.0), " over seeds")
        rows.append({"env_id": env_id, "policy": f"PPO 1 M, {len(results)} seeds", "hits": hits,
                     "hits_per_minute": rate, "per_minute": per_minute,
                     "reach_seconds": [t for r in results for t in r["reach_seconds"]],
                     "games": sum(len(r["test_hits"]) for r in results)})
    order = {"random": 0, "naive": 1, "model": 2}
    for r in sorted(rows, key=lambda r: (IDS.index(r["env_id"]) if r["env_id"] in IDS else len(IDS), r["env_id"],
                                         order.get(r["policy"], 3), r["policy"])):
        low, high = mean_interval(r["hits"], **hit_range(r["env_id"]))
        times = [t for t in r.get("reach_seconds", []) if t is not None]
        if times:
            t_low, t_high = mean_interval(times, low=0.0)
            reach = f"{np.mean(times):.2f} ({t_low:.2f}-{t_high:.2f})"
        else:
            reach = "no hit"
        m_low, m_high, *over = r["per_minute"]
        per_minute = f"{r['hits_per_minute']:.1f} ({m_low:.1f}-{m_high:.1f}{''.join(over)})"
        lines.append(f"| `{slug(r['env_id'])}` | {r['policy']} | {np.mean(r['hits']):.2f} ({low:.2f}-{high:.2f}) "
                     f"| {per_minute} | {reach} | {len(times)} of {r['games']} |")
    return "\n".join(lines)


def references_v3_table() -> str:
    """docs/programs.md's table of protocol 3's references (``references_v3``), every suite id: a Reach row without
    games yet says so; a CenterOut row is the model bot's hits a minute, beside PPO's timed runs
    (``center_out_ppo``)."""
    from armgame.env.evaluation import normalised_score

    bench = _ceiling_benchmark()
    rows = references_v3()
    runs = long_runs()
    timed = center_out_ppo()
    lines = ["| id | reference | test games so far | its score (95% CI over games) | CPU s a decision | machine "
             "| PPO's longest runs, protocol 3 |", "|---|---|---:|---|---:|---|---:|"]
    for env_id in (*bench.DISTINCT, *bench.STANDS_FOR):
        name = env_id.split("/")[1]
        row = rows.get(env_id)
        if row is None:
            settings = ", ".join(f"{k}={v!r}" for k, v in bench.REFERENCE.get(bench.STANDS_FOR.get(env_id, env_id),
                                                                               {}).items())
            lines.append(f"| `{name}` | `ShootingController({settings})` | 0 (running) | | | | |")
            continue
        code = row["code"].removeprefix("armgame.env.ceiling.")
        games = f"{row['games']}" + ("" if row["games"] >= 100 else " (incomplete)")
        same = "" if row["games_of"] == env_id else f" = {row['games_of'].split('/')[1]}"
        ppo = runs.get(env_id, {})
        score = normalised_score(env_id, float(np.mean(ppo[max(ppo)])), protocol=3) if ppo else None
        shown = "" if score is None else f"{score:.2f}"
        lines.append(f"| `{name}` | `{code}` | {games} | {row['hits']:.1f} hits a game ({row['low']:.1f}-"
                     f"{row['high']:.1f}){same} | {row['cpu_per_decision']:.4f} | {row['machine']} | {shown} |")
    for env_id, row in rows.items():
        if row["unit"] != "hits a minute":
            continue
        results = timed.get(env_id, [])
        score = (normalised_score(env_id, float(np.mean([r["mean_hits"] for r in results])), protocol=3,
                                  hits_per_minute=float(np.mean([r["hits_per_minute"] for r in results])))
                 if results else None)
        shown = "" if score is None else f"{score:.2f} ({len(results)} of 5 seeds at 1 M)"
        code = row["code"].removeprefix("armgame.env.center_out_reference.")
        lines.append(f"| `{env_id.split('/')[1]}` | `{code}` | {row['games']} | {row['hits']:.1f} hits a minute "
                     f"({row['low']:.1f}-{row['high']:.1f}) | {row['cpu_per_decision']:.5f} | {row['machine']} "
                     f"| {shown} |")
    short = [f"{env_id.split('/')[1]} {rows[env_id]['games'] if env_id in rows else 0}" for env_id in bench.DISTINCT
             if rows.get(env_id, {}).get("games", 0) < 100]
    head = (f"**The table is incomplete**: the test games so far of {', '.join(short)} (of 100; their twins' the "
            "same). "
            "An id without games is left out of `REFERENCES_V3`." if short else "Every id has its 100 test games.")
    return head + "\n\n" + "\n".join(lines)


def center_out_ppo(folder: Path = RESULTS / "center-out-time" / "ppo") -> dict[str, list[dict[str, Any]]]:
    """PPO's CenterOut runs that recorded their hits a minute (``runs --out`` of ``folder``: the protocol runs' recipe
    at 1 M env steps, made again once ``evaluate`` timed CenterOut), each id's ``result.json`` by training seed."""
    found: dict[str, list[dict[str, Any]]] = {}
    for path in sorted(folder.glob("*/seed*/result.json")):
        result = json.loads(path.read_text(encoding="utf-8"))
        found.setdefault(result["env_id"], []).append(result)
    return found


def references_v3_source() -> str:
    """``armgame/env/references.py``'s ``REFERENCES_V3``, as Python source."""
    lines = ["REFERENCES_V3: dict[str, dict[str, Any]] = {"]
    for env_id, row in references_v3().items():
        lines.append(f"    {env_id!r}: {{")
        lines += [f"        {key!r}: {value!r}," for key, value in row.items()]
        lines.append("    },")
    return "\n".join([*lines, "}"])


def ceilings_source(reference: dict[str, dict[str, Any]] | None = None) -> str:
    """``armgame/env/references.py``'s ``CEILINGS``, as Python source."""
    lines = ["CEILINGS: dict[str, dict[str, Any]] = {"]
    for env_id, entry in ceilings(reference).items():
        lines.append(f"    {json.dumps(env_id)}: {{")
        lines.append(f"        \"hits\": {entry['hits']!r}, \"by\": {json.dumps(entry['by'])}}},")
    lines.append("}")
    return "\n".join(lines)


def aggregate(folder: Path, protocol: int = PROTOCOL_VERSION) -> str:
    """The IQM, mean and median normalised score under ``protocol``, with stratified bootstrap intervals, of the
    ``result.json`` files (``examples/train_ppo.py --out``) anywhere under ``folder``: one run a training seed and
    id. Each run is scored from its hits (and hits a minute), whatever protocol its file was written under."""
    from armgame.env.evaluation import aggregate_runs

    runs: dict[str, dict[int, dict[str, Any]]] = {}
    budgets = set()
    for path in sorted(folder.rglob("result.json")):
        r = json.loads(path.read_text(encoding="utf-8"))
        runs.setdefault(r["env_id"], {})[int(r["training_seed"])] = r
        budgets.add(int(r["budget_steps"]))
    if not runs:
        raise SystemExit(f"{folder}: no result.json under it")
    seeds = {tuple(sorted(by_seed)) for by_seed in runs.values()}
    if len(seeds) != 1:
        raise SystemExit(f"{folder}: the ids were not trained with the same seeds: {sorted(seeds)}")
    order = sorted(next(iter(seeds)))
    try:
        result = aggregate_runs({env_id: [by_seed[s] for s in order] for env_id, by_seed in runs.items()},
                                protocol=protocol)
    except EnvArgumentError as error:
        raise SystemExit(f"{folder}: {error}") from None
    lines = [result.summary(), f"budget: {', '.join(f'{b:,}' for b in sorted(budgets))} env steps; "
                               f"training seeds {order}; protocol {protocol}"]
    for name in ("iqm", "mean", "median"):
        point, low, high = getattr(result, name)
        lines.append(f"  {name:6} {point:.3f} [{low:.3f}, {high:.3f}]")
    return "\n".join(lines)


def protocol_runs(out: Path, ids: list[str], seeds: list[int], steps: int, test_games: int,
                  every: int | None = None) -> None:
    """``examples/train_ppo.py`` for each id and training seed not yet finished under ``out``, one after another,
    validating every ``every`` env steps (a twentieth of the budget by default).

    Each run is claimed by a lock on ``OUT/ID/seedN.lock`` while it trains (``armgame.records.locking``: the kernel
    drops it when its process ends, killed or not), so the same command in several terminals shares the runs out, one
    core each, and a run another process is training is left to it, never started again over its files."""
    import importlib.util
    import shutil

    from armgame.records.locking import LockBusyError, file_lock

    every = every or max(1, steps // 20)
    example = Path(__file__).resolve().parent.parent / "examples" / "train_ppo.py"
    spec = importlib.util.spec_from_file_location("train_ppo", example)
    train_ppo = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(train_ppo)  # type: ignore[union-attr]
    elsewhere = []
    for env_id in ids:
        for seed in seeds:
            folder = out / slug(env_id) / f"seed{seed}"
            folder.parent.mkdir(parents=True, exist_ok=True)
            try:
                with file_lock(folder.parent / f"seed{seed}.lock", wait=0.0, mode=0o644):
                    if (folder / "result.json").is_file():  # looked at under the lock: never half a run's
                        print(f"{env_id} seed {seed}: done before ({folder / 'result.json'})", flush=True)
                        continue
                    if folder.is_dir():  # a run a sitting left unfinished starts again: its curve would have a gap
                        shutil.rmtree(folder)
                    print(f"{env_id} seed {seed}: {steps:,} env steps into {folder}", flush=True)
                    train_ppo.main(["--env", env_id, "--steps", str(steps), "--eval-every", str(every),
                                    "--seed", str(seed), "--test-games", str(test_games), "--out", str(folder)])
            except LockBusyError:
                print(f"{env_id} seed {seed}: another process is training it; left to it", flush=True)
                elsewhere.append(f"{slug(env_id)} seed {seed}")
    # Every run asked for is in (or in another process's hands): what they add up to, and where it goes next.
    print(curves(out), flush=True)
    if elsewhere:
        print(f"still training elsewhere: {', '.join(elsewhere)}; the same command again afterwards reports them",
              flush=True)
    print(f"next: `python {Path(__file__).name} aggregate {out}` for the IQM over ids; runs committed under "
          f"benchmarks/results/ppo* go into `ceilings`, `table`, `runs-table` and `figure`", flush=True)


Run = tuple[int, dict[int, float], dict[str, Any]]  # (training seed, validation mean hits by env steps, result)


def runs_of(folder: Path) -> dict[str, list[Run]]:
    """Each id's ``train_ppo.py --out`` runs under ``folder`` (``curve.csv`` and ``result.json``), by training seed;
    one line (SystemExit) where there is none."""
    by_id = _runs_in(folder)
    if not by_id:
        raise SystemExit(f"{folder}: no result.json under it")
    return by_id


def protocol_run_sets(root: Path = RESULTS) -> dict[tuple[str, int], list[Run]]:
    """Every protocol run committed under ``root``'s ``ppo*`` folders, by (id, budget in env steps), in that order:
    each training seed's run, in seed order. ``long_runs``, ``runs_table`` and ``curves_figure`` all read these."""
    found: dict[tuple[str, int], dict[int, Run]] = {}
    for folder in sorted(path for path in root.glob("ppo*") if path.is_dir()):  # not a file named so
        for env_id, runs in _runs_in(folder).items():
            for run in runs:
                found.setdefault((env_id, int(run[2]["budget_steps"])), {})[run[0]] = run
    return {key: [by_seed[seed] for seed in sorted(by_seed)] for key, by_seed in sorted(found.items())}


def _runs_in(folder: Path) -> dict[str, list[Run]]:
    import csv

    by_id: dict[str, list[Run]] = {}
    for result_path in sorted(folder.rglob("result.json")):
        result = json.loads(result_path.read_text(encoding="utf-8"))
        with (result_path.parent / "curve.csv").open(newline="", encoding="utf-8") as f:
            curve = {int(row["env_steps"]) // 1000 * 1000: float(row["mean_hits"]) for row in csv.DictReader(f)}
        by_id.setdefault(result["env_id"], []).append((int(result["training_seed"]), curve, result))
    return {env_id: sorted(runs, key=lambda run: run[0]) for env_id, runs in by_id.items()}


def validation_medians(runs: list[Run]) -> tuple[list[int], list[float], list[tuple[float, float]]]:
    """The validation curve over training seeds: the env steps every run validated at, the median of the seeds' mean
    hits there and their range."""
    steps = sorted(set.intersection(*(set(curve) for _, curve, _ in runs)))
    values = [[curve[step] for _, curve, _ in runs] for step in steps]
    return steps, [float(np.median(v)) for v in values], [(min(v), max(v)) for v in values]


def late_slope(steps: list[int], medians: list[float]) -> tuple[float, float, float] | None:
    """How much the median still rises over the last half of the budget, in hits per million env steps, with +-2
    standard errors (None with fewer than 4 points there). 10 validation games make each point noisy (a few hits),
    so two points' difference says little; a line through the last half says how much is left."""
    from scipy.stats import linregress

    half = [i for i, step in enumerate(steps) if step >= steps[-1] / 2]
    if len(half) < 4:
        return None
    if len({medians[i] for i in half}) == 1:  # a curve at its ceiling throughout: no spread for a standard error
        return 0.0, 0.0, 0.0
    fit = linregress(np.array(steps)[half] / 1e6, np.array(medians)[half])
    width = float(fit.stderr) * 2.0
    return float(fit.slope), float(fit.slope) - width, float(fit.slope) + width


def curves(folder: Path) -> str:
    """Each id's PPO runs under ``folder``: its validation curve over training seeds (the median and range of the
    seeds' mean hits on the 10 validation games at each budget), how much it still rises over the last half of the
    budget (``late_slope``), and the test games' hits of each seed with the mean over seeds and its 95 % interval
    (Student's t over seeds: the training seed's spread, not one policy's game-to-game)."""
    from armgame.env.evaluation import mean_interval

    out = []
    for env_id, runs in runs_of(folder).items():
        out.append(f"{env_id}: PPO, training seeds {[seed for seed, _, _ in runs]}, validation mean hits (10 games) "
                   "by env steps")
        out.append("| env steps | median over seeds | range |")
        out.append("|---:|---:|---:|")
        steps, medians, ranges = validation_medians(runs)
        for step, median, (low, high) in zip(steps, medians, ranges, strict=True):
            out.append(f"| {step:,} | {median:.1f} | {low:.1f} - {high:.1f} |")
        slope = late_slope(steps, medians)
        if slope is not None:
            out.append(f"over the last half of the budget the median rises {slope[0]:+.2f} hits per million env "
                       f"steps (+-2 standard errors: {slope[1]:+.2f} to {slope[2]:+.2f})")
        means = [float(result["mean_hits"]) for _, _, result in runs]
        low, high = mean_interval(means, **hit_range(env_id))
        after = ", ".join(f"{b:,}" for b in sorted({int(result["env_steps"]) for _, _, result in runs}))
        games = sorted({len(result["test_hits"]) for _, _, result in runs})
        out.append(f"test games ({', '.join(map(str, games))}): {', '.join(f'{m:.1f}' for m in means)}; mean "
                   f"{np.mean(means):.1f} "
                   f"(95% CI over seeds {low:.1f} to {high:.1f}) after {after} env steps")
        out.append("")
    return "\n".join(out)


#: Where ``runs_table`` reads the validation curve, in twentieths of the budget (``runs``' default validation).
CURVE_POINTS = (1, 2, 5, 10, 15, 20)


def runs_table(root: Path = RESULTS) -> str:
    """docs/programs.md's table of PPO's protocol runs: every id and budget with five training seeds or more under
    ``root``'s ``ppo*`` folders, its validation curve (the median over seeds at a twentieth, a tenth, a quarter,
    half, three quarters and all of the budget), whether it has flattened (the last half's slope, ``late_slope``:
    flat where its +-2 standard errors hold 0), each seed's mean hits on the 100 test games, and their mean with its
    95 % interval over seeds."""
    from fractions import Fraction

    from armgame.env.evaluation import mean_interval

    order = {env_id: i for i, env_id in enumerate(IDS)}
    rows = []
    for (env_id, budget), runs in protocol_run_sets(root).items():
        if len(runs) < CEILING_SEEDS:
            continue
        steps, medians, _ = validation_medians(runs)
        at = {step: median for step, median in zip(steps, medians, strict=True)}
        curve = []
        for twentieths in CURVE_POINTS:
            step = budget * twentieths // 20 // 1000 * 1000
            curve.append(f"{at[step]:.1f}" if step in at else "")
        slope = late_slope(steps, medians)
        if slope is None:
            shape = ""
        else:
            word = "flat" if slope[1] <= 0 <= slope[2] else ("rising" if slope[0] > 0 else "falling")
            shape = f"{word}: {slope[0]:+.2f} ({slope[1]:+.2f} to {slope[2]:+.2f})"
        means = [float(result["mean_hits"]) for _, _, result in runs]
        low, high = mean_interval(means, **hit_range(env_id))
        cells = [f"`{slug(env_id)}`", f"{budget / 1e6:g} M, {len(runs)}", *curve, shape,
                 ", ".join(f"{m:.1f}" for m in means), f"**{np.mean(means):.1f}** ({low:.1f}-{high:.1f})"]
        rows.append(((order.get(env_id, len(order)), budget), "| " + " | ".join(cells) + " |"))
    points = [str(Fraction(t, 20)) if t < 20 else "all" for t in CURVE_POINTS]
    head = ["| id | env steps, seeds | validation median at " + " | ".join(points) + " of the budget | last half, "
            "hits per M steps (+-2 SE) | test hits by training seed | mean (95% CI over seeds) |",
            "|---|---|" + "---:|" * len(CURVE_POINTS) + "---|---|---|"]
    return "\n".join(head + [row for _, row in sorted(rows)])


def curves_figure(out: Path, root: Path = RESULTS) -> list[str]:
    """docs/img/ppo_curves.png: every id with five seeds or more, at its longest budget, a panel of its validation
    curve over training seeds (the median, and the range shaded) against env steps, with its protocol 2 ceiling and
    protocol 3 reference where it has them, the shooting controller where it plays the id and random play as lines.
    Returns the panels' titles, in order."""
    import matplotlib

    matplotlib.use("Agg")  # a file, never a window
    import matplotlib.pyplot as plt

    from armgame.env.references import CEILINGS, REFERENCE_HITS, REFERENCES_V3, TIER_HITS

    controller = _controller_rows(root / "ceiling")
    longest: dict[str, tuple[int, list[Run]]] = {}  # id -> (budget, its runs): the budgets come in rising order
    for (env_id, budget), runs in protocol_run_sets(root).items():
        if len(runs) >= CEILING_SEEDS:
            longest[env_id] = budget, runs
    order = sorted(longest, key=lambda i: IDS.index(i) if i in IDS else len(IDS))
    if not order:
        raise SystemExit(f"{root}: no id has {CEILING_SEEDS} seeds of protocol runs")
    columns = min(3, len(order))
    rows = -(-len(order) // columns)
    # Constrained layout keeps the title clear of the first row's panels, however many rows there are.
    figure, axes = plt.subplots(rows, columns, figsize=(4.2 * columns, 3.1 * rows), squeeze=False,
                                layout="constrained")
    titles = []
    for ax, env_id in zip(axes.flat, order, strict=False):
        budget, runs = longest[env_id]
        steps, medians, ranges = validation_medians(runs)
        x = np.array(steps) / 1e6
        ax.fill_between(x, [r[0] for r in ranges], [r[1] for r in ranges], color="#9ecae1", lw=0,
                        label=f"range over {len(runs)} seeds")
        ax.plot(x, medians, color="#08519c", lw=1.6, label="median (10 validation games)")
        # The tier's ids were made after protocol 2, so they have a protocol 3 reference and no ceiling.
        if env_id in CEILINGS:
            ax.axhline(CEILINGS[env_id]["hits"], color="black", ls="--", lw=1, label="ceiling (protocol 2)")
        if env_id in REFERENCES_V3:
            ax.axhline(REFERENCES_V3[env_id]["hits"], color="#7b3294", ls="-.", lw=1.2,
                       label="reference (protocol 3)")
        if env_id in controller:
            ax.axhline(controller[env_id][0], color="#d95f02", ls=":", lw=1.4, label="shooting controller")
        random_hits = (REFERENCE_HITS.get(env_id) or TIER_HITS[env_id])["random"]
        ax.axhline(random_hits, color="grey", lw=0.8, label="random")
        titles.append(f"{slug(env_id)}, {budget / 1e6:g} M steps")
        ax.set_title(titles[-1], fontsize=10)
        ax.set_xlabel("env steps (millions)", fontsize=9)
        ax.set_ylabel("hits per game", fontsize=9)
        ax.set_xlim(0, x[-1])
        ax.grid(alpha=0.3)
    for ax in list(axes.flat)[len(order):]:
        ax.axis("off")
    axes.flat[0].legend(fontsize=7, loc="lower right")
    figure.suptitle("PPO's validation curves (examples/train_ppo.py's recipe; reference_scores.py figure)", fontsize=11)
    figure.savefig(out, dpi=110)
    plt.close(figure)
    return titles


def main(argv: list[str] | None = None) -> int:
    try:
        return _main(argv)
    except (OSError, ValueError, KeyError, TypeError) as exc:  # a run's file unreadable, not JSON or not a run's
        raise SystemExit(f"reference_scores.py: {type(exc).__name__}: {exc}") from None


def _main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    bots = sub.add_parser("bots")
    bots.add_argument("--out", type=Path, required=True)
    bots.add_argument("--games", type=int, default=GAMES)
    bots.add_argument("--ids", nargs="*", default=list(IDS))
    bots.add_argument("--policies", nargs="*", default=["random", "naive", "model"],
                      choices=["random", "naive", "model", "shooting"],
                      help="some of random, naive and model (a row's bots rerun alone); shooting: CenterOut's "
                      "shooting controller (armgame.env.center_out_reference), on the CenterOut ids only")
    ppo = sub.add_parser("ppo")
    ppo.add_argument("env_id")
    ppo.add_argument("--seed", type=int, default=0)
    ppo.add_argument("--steps", type=int, default=PPO_STEPS)
    ppo.add_argument("--games", type=int, default=GAMES)
    ppo.add_argument("--out", type=Path, required=True)
    sub.add_parser("table", help="docs/programs.md's reference table, from the committed results (protocol 2)")
    sub.add_parser("ceilings", help="armgame/env/references.py's CEILINGS, from the committed results")
    sub.add_parser("references-v3", help="armgame/env/references.py's REFERENCES_V3 (protocol 3's normaliser)")
    sub.add_parser("references-v3-table", help="docs/programs.md's table of protocol 3's references")
    timing = sub.add_parser("center-out-table", help="docs/programs.md's table of CenterOut's hits a minute and time "
                            "to the target, from bots' runs")
    timing.add_argument("folder", type=Path, nargs="?", default=RESULTS / "center-out-time")
    sub.add_parser("tier-table", help="docs/programs.md's table of the separating tier, from the committed results")
    sub.add_parser("runs-table", help="docs/programs.md's table of PPO's protocol runs, from the committed results")
    fig = sub.add_parser("figure", help="docs/img/ppo_curves.png: the protocol runs' validation curves (matplotlib)")
    fig.add_argument("--out", type=Path, default=Path(__file__).resolve().parent.parent / "docs" / "img" /
                     "ppo_curves.png")
    tab = sub.add_parser("table-v1", help="protocol 1's table from a folder of bots' and PPO's runs")
    tab.add_argument("folder", type=Path)
    refs = sub.add_parser("references")
    refs.add_argument("folder", type=Path)
    agg = sub.add_parser("aggregate")
    agg.add_argument("folder", type=Path)
    agg.add_argument("--protocol", type=int, choices=PROTOCOLS, default=PROTOCOL_VERSION,
                     help=f"the normalisation (default {PROTOCOL_VERSION}; 2: protocol 2's ceilings)")
    cur = sub.add_parser("curves")
    cur.add_argument("folder", type=Path)
    many = sub.add_parser("runs")
    many.add_argument("--ids", nargs="+", required=True)
    many.add_argument("--seeds", nargs="+", type=int, default=[0, 1, 2, 3, 4])
    many.add_argument("--steps", type=int, required=True, help="each run's budget in env steps")
    many.add_argument("--games", type=int, default=GAMES)
    many.add_argument("--eval-every", type=int, help="env steps between validations (default: a twentieth)")
    many.add_argument("--out", type=Path, required=True)
    args = parser.parse_args(argv)
    if args.command == "bots":
        run_bots(args.out, tuple(args.ids), args.games, tuple(args.policies))
    elif args.command == "ppo":
        run_ppo(args.out, args.env_id, args.seed, args.steps, args.games)
    elif args.command == "references":
        print(references(args.folder))
    elif args.command == "aggregate":
        print(aggregate(args.folder, args.protocol))
    elif args.command == "curves":
        print(curves(args.folder))
    elif args.command == "runs":
        protocol_runs(args.out, args.ids, args.seeds, args.steps, args.games, args.eval_every)
    elif args.command == "table":
        print(table())
    elif args.command == "ceilings":
        print(ceilings_source())
    elif args.command == "references-v3":
        print(references_v3_source())
    elif args.command == "references-v3-table":
        print(references_v3_table())
    elif args.command == "runs-table":
        print(runs_table())
    elif args.command == "tier-table":
        print(tier_table())
    elif args.command == "center-out-table":
        print(center_out_timing_table(args.folder))
    elif args.command == "figure":
        print(f"wrote {args.out}: {', '.join(curves_figure(args.out))}")
    else:
        print(table_v1(args.folder))
    return 0


if __name__ == "__main__":
    sys.exit(main())
