"""Where a step of CenterOut's batched vector env spends its time, part by part.

    python benchmarks/center_out_parts.py                      # CenterOut-v1 at 8,192 envs, about a minute
    python benchmarks/center_out_parts.py --envs 4096 --steps 1500 --json
    PYTHONPATH=/path/to/another/checkout python benchmarks/center_out_parts.py --json --label "before"

``gym.make_vec(ID, num_envs=N)`` (``armgame.env.center_out_batch``) steps random actions drawn before the
clock starts, ``--warm`` steps first (as ``env_speed.py`` does: past the runs' first trial and episode ends,
so trials end and episodes restart in every measured step), then ``--steps`` steps with each part's process
time summed around its calls:

* ``advance``: the C loop (``_ccenter.advance``: the muscles, the RK4 of 16 runs at a time in the game's
  vector lanes, the C library's sine and cosine of the hand, the rules, the observations);
* ``measures``: the ended trials' reach measures in C (``_ccenter.measures``);
* ``ended trials, Python``: the rest of ``_end_trials`` (each ended trial's ``info["reaches"]`` row, the
  next trial's row for the C loop);
* ``episode starts``: ``_start_episode`` for the runs that begin a new episode (their trials drawn by
  ``lab.session.schedule``);
* ``actions`` and ``dense reward``: ``_ccenter.act`` and ``_ccenter.progress``;
* ``the rest``: the step's own numpy work (flags, infos, the observation's copy) and the loop between.

The figures are ms a step (the mean over the measured steps) and each part's share. Process time, one
thread: the machine's load falls on the clock less than on wall time, but the report gives the load too.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from collections import Counter
from collections.abc import Callable
from typing import Any

import gymnasium as gym

import armgame.env  # noqa: F401  (registers the ids)
from armgame.env import center_out_batch

#: The batch's parts, by the name the report gives them: (the object the function is on, its name).
PARTS = {"advance": ("module", "advance"), "measures": ("module", "measures"), "actions": ("module", "act"),
         "dense reward": ("module", "progress"), "episode starts": ("batch", "_start_episode"),
         "ended trials": ("batch", "_end_trials")}


def _timed(function: Callable[..., Any], name: str, clock: Counter[str]) -> Callable[..., Any]:
    def timed(*args: Any, **kwargs: Any) -> Any:
        start = time.process_time()
        try:
            return function(*args, **kwargs)
        finally:
            clock[name] += time.process_time() - start
    return timed


class _TimedModule:
    """``_ccenter`` with some of its functions timed."""

    def __init__(self, module: Any, names: dict[str, str], clock: Counter[str]) -> None:
        self._module = module
        for part, name in names.items():
            setattr(self, name, _timed(getattr(module, name), part, clock))

    def __getattr__(self, name: str) -> Any:
        return getattr(self._module, name)


def measure(env_id: str, num_envs: int, steps: int, warm: int, label: str = "") -> dict[str, Any]:
    """The parts' ms a step of ``env_id``'s batch at ``num_envs`` envs, over ``steps`` steps after ``warm``; ``label``
    names the code measured (the armgame imported: another checkout's, with PYTHONPATH)."""
    envs = gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="vector_entry_point")
    if not isinstance(envs, center_out_batch.CenterOutBatchVectorEnv):
        raise SystemExit(f"{env_id} at {num_envs} envs is not the batch here ({type(envs).__name__})")
    envs.action_space.seed(0)
    actions = [envs.action_space.sample() for _ in range(16)]
    envs.reset(seed=0)
    for i in range(warm):
        envs.step(actions[i % 16])
    clock: Counter[str] = Counter()
    module = center_out_batch._ccenter
    on_module = {part: name for part, (where, name) in PARTS.items() if where == "module"}
    center_out_batch._ccenter = _TimedModule(module, on_module, clock)  # type: ignore[assignment]
    for part, (where, name) in PARTS.items():
        if where == "batch":
            setattr(envs, name, _timed(getattr(envs, name), part, clock))
    load = os.getloadavg()[0]
    try:
        start = time.process_time()
        ended = 0
        for i in range(steps):
            info = envs.step(actions[i % 16])[4]
            ended += sum(len(rows) for rows in info.get("reaches", ()) if rows)
        total = time.process_time() - start
    finally:
        center_out_batch._ccenter = module
    parts = {part: clock[part] for part in PARTS}
    parts["ended trials"] -= parts["measures"]  # _end_trials calls measures: its own Python is the rest
    parts["the rest"] = total - sum(parts.values())
    per_step = {part: round(seconds / steps * 1e3, 4) for part, seconds in parts.items()}
    return {"label": label, "env_id": env_id, "num_envs": num_envs, "steps": steps, "warm": warm,
            "ms_per_step": round(total / steps * 1e3, 4), "parts_ms_per_step": per_step,
            "trials_ended_per_step": round(ended / steps, 2),
            "machine": f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
            "load_average": [round(load, 2), round(os.getloadavg()[0], 2)]}


def report(result: dict[str, Any]) -> None:
    total = result["ms_per_step"]
    print(f"{result['env_id']} at {result['num_envs']:,} envs: {total:.2f} ms a step (process time, mean of "
          f"{result['steps']} steps after {result['warm']}; {result['trials_ended_per_step']} trials end a step)")
    print(f"{result['machine']}; load average {result['load_average'][0]} before, {result['load_average'][1]} after")
    for part, ms in sorted(result["parts_ms_per_step"].items(), key=lambda item: -item[1]):
        print(f"  {part:20s} {ms:7.3f} ms  {ms / total:6.1%}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--id", default="armgame/CenterOut-v1", help="a CenterOut id")
    parser.add_argument("--envs", type=int, default=8192)
    parser.add_argument("--steps", type=int, default=1500)
    parser.add_argument("--warm", type=int, default=1500)
    parser.add_argument("--json", action="store_true", help="one JSON object instead of the report")
    parser.add_argument("--label", default="", help="a name for the code measured, kept in the JSON")
    args = parser.parse_args()
    for name in ("envs", "steps"):
        if getattr(args, name) < 1:
            parser.error(f"--{name} must be at least 1")
    if args.warm < 0:
        parser.error("--warm must be 0 or more")
    result = measure(args.id, args.envs, args.steps, args.warm, args.label)
    if args.json:
        print(json.dumps(result, indent=1))
    else:
        report(result)


if __name__ == "__main__":
    main()
