"""Speed of the Gymnasium envs, beside Gymnasium's Acrobot-v1 measured in the same run.

    python benchmarks/env_speed.py              # about three minutes
    python benchmarks/env_speed.py --quick      # a few seconds a figure, fewer repeats
    python benchmarks/env_speed.py --json       # one JSON object
    python benchmarks/env_speed.py --suite armgame/ReachDelay-v1 --sizes 1 64 1024 8192 --seconds 0.3
    python benchmarks/env_speed.py --suite armgame/Reach-v1 armgame/ReachHard-v1 --motornet --seconds 0.3 --repeats 3
    python benchmarks/env_speed.py --suite armgame/CenterOut-v1 --motornet-matched --seconds 1 --repeats 3

Env steps per second (one env step = one decision: 5 physics steps of the game, 20 ms; one
RK4 step of 0.2 s for Acrobot) with random actions drawn before the clock starts, episodes
reset as they end:

* single env, both through ``gymnasium.make`` (with its checker and order wrappers), and Reach-v1
  against Reach-v0 (what the v1 observation and reward cost);
* vector env at 1, 4, 16, 64, 1,024 and 8,192 envs: armgame's native ``ReachVectorEnv``
  (``make_vec(..., vectorization_mode="vector_entry_point")``) and Acrobot's ``SyncVectorEnv``; and
  Reach-v1's native vector env against ``SyncVectorEnv`` of Reach-v1 single envs, side by side
  (issue 28: no slower at any size; at least 4 M env-steps/s at 8,192 envs);
* with ``--suite ID ...``, instead: each suite id's ``make_vec`` vector env (the native one where the batch
  plays the id, else single envs in ``SyncVectorEnv``) against ``SyncVectorEnv`` of its single envs, side by
  side (issue 40, item 5: at least 1 M env-steps/s at 8,192 envs); a size past the id's cap is reported so.
  A CenterOut id's ``make_vec`` env runs ``CENTER_OUT_WARM_STEPS`` steps before its clock starts: its trials,
  and its 8-trial episodes, first end together after hundreds of steps, and an ended trial costs its
  ``info["reaches"]`` row, so the figure is a step's cost once trials and episodes end on every step;
* with ``--suite ID ... --motornet``, instead of ``SyncVectorEnv``: MotorNet's reaching env beside each id's
  ``make_vec`` vector env at 1 to 8,192 envs (issue 40, item 5: at least 20 times MotorNet's env at every size);
* with ``--suite ID ... --motornet-matched``, MotorNet's same env with its step matched to armgame's (issue 52,
  item 5: the CenterOut ids at least 10 times it at every size, and at least 1 M env steps per CPU second at
  8,192 envs).

MotorNet's env is ``motornet.environment.RandomTargetReach`` (MotorNet 0.3.0's one reaching task: a start
posture and a target drawn at random, the batch stepped as one ``batch_size``) on the ``Reacher`` effector with
``ReluMuscle`` muscles, because that is MotorNet's arm closest to armgame's: the same two-joint planar arm
(``TwoDofArm``), four muscles (shoulder and elbow, flexor and extensor) of constant moment arm whose force is
the activation times the largest force, the activation following first-order dynamics toward the command, as
armgame's four muscles of constant torque do. (``--motornet-effector arm26`` takes MotorNet's
``RigidTendonArm26`` instead: six Hill muscles, ``RigidTendonHillMuscle``, with length- and velocity-dependent
forces and moment arms, a costlier model than armgame's.) MotorNet's defaults are kept: one env step is its
effector's ``timestep`` of 10 ms, one Euler step (``n_ministeps`` 1), against armgame's 20 ms (5 RK4 steps of
4 ms), so the report prints each side's simulated seconds per env step and the ratio per simulated second
beside the ratio per env step. ``differentiable=False`` (the reinforcement-learning mode: numpy observations
and rewards, as Gymnasium's envs give) and ``torch.set_num_threads(1)``: one core against one core, as
armgame's vector env is single-threaded. The actions, uniform in MotorNet's action space [0, 1], are tensors
drawn before the clock starts; MotorNet's episodes end for the whole batch at once (``max_ep_duration``, 1 s
by default: 100 steps), and the clock includes the ``reset`` that its API then expects. Where torch or
motornet does not import, the report says so in one line and gives armgame's columns alone.

MotorNet's matched env (``--motornet-matched``) is that env with its effector given armgame's step: ``timestep``
0.02 (20 ms an env step), ``n_ministeps`` 5 and ``integration_method`` ``"rk4"``, so that one env step is 5 RK4
steps of 4 ms on each side, as armgame's game and lab step the arm; its episodes stay 1 s long (50 steps now).
Only the step changes: the arm, its muscles, the task and the API are the default env's above.

Each figure is measured in several repeats, interleaved with its peer so that load from
elsewhere falls on both; the report gives the median and the range over repeats, and the
single-env ratio as the median of the paired ratios. Goals (issue 12): the single env no
slower than Acrobot-v1; the vector env at 8,192 envs at least 1 M env-steps/s.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time
from collections.abc import Callable
from typing import Any

import gymnasium as gym
import numpy as np

import armgame.env  # noqa: F401  (registers armgame/Reach-v0)
from armgame.env.vector import batch_min_envs

VECTOR_SIZES = (1, 4, 16, 64, 1024, 8192)
MOTORNET_SIZES = (1, 4, 16, 64, 256, 1024, 4096, 8192)  # issue 40: every size from 1 to 8,192
MOTORNET_GOAL = 20.0  # armgame's env steps per CPU second over MotorNet's, at every size (issue 40)
SINGLE_GOAL = 1.0  # Reach-v0 steps per second over Acrobot-v1's
VECTOR_GOAL = 1e6  # env-steps per second at 8,192 envs (v0)
#: Steps a CenterOut id's make_vec env runs before it is measured: past its first episodes' ends (8 trials of up to
#: about 200 steps each), after which trials and episodes end on every step of a batch of thousands.
CENTER_OUT_WARM_STEPS = 1500
V1_VECTOR_GOAL = 4e6  # Reach-v1's, at 8,192 envs (issue 28)


def single_runner(env_id: str) -> Callable[[float], tuple[float, float]]:
    """Steps per second of one env through gymnasium.make, run for about ``seconds``: (wall, CPU)."""
    env = gym.make(env_id)
    env.action_space.seed(0)
    actions = [env.action_space.sample() for _ in range(4096)]
    env.reset(seed=0)

    def run(seconds: float) -> tuple[float, float]:
        steps, start, cpu = 0, time.perf_counter(), time.process_time()
        end = start + seconds
        while True:
            for i in range(256):
                _, _, terminated, truncated, _ = env.step(actions[(steps + i) % 4096])
                if terminated or truncated:
                    env.reset()
            steps += 256
            now = time.perf_counter()
            if now >= end:
                return steps / (now - start), steps / (time.process_time() - cpu)

    return run


def vector_runner(env_id: str, num_envs: int, mode: str, warm: int = 1) -> Callable[[float], tuple[float, float]]:
    """Env-steps per second (vector steps x num_envs) of a vector env for about ``seconds``: (wall, CPU), after
    ``warm`` steps (the first may build what later steps reuse)."""
    envs = gym.make_vec(env_id, num_envs=num_envs, vectorization_mode=mode)
    envs.action_space.seed(0)
    actions = [envs.action_space.sample() for _ in range(8)]
    envs.reset(seed=0)
    for step in range(warm):
        envs.step(actions[step % 8])

    def run(seconds: float) -> tuple[float, float]:
        steps, start, cpu = 0, time.perf_counter(), time.process_time()
        end = start + seconds
        while True:
            envs.step(actions[steps % 8])
            steps += 1
            now = time.perf_counter()
            if now >= end:
                return steps * num_envs / (now - start), steps * num_envs / (time.process_time() - cpu)

    return run


#: MotorNet's effector arguments for armgame's step (``--motornet-matched``): 20 ms as 5 RK4 steps of 4 ms.
MATCHED_STEP = {"timestep": 0.02, "n_ministeps": 5, "integration_method": "rk4"}


def motornet_env(effector: str, matched: bool = False) -> Any:
    """MotorNet's reaching env on ``effector`` ("reacher" or "arm26"), its defaults kept or, ``matched``, its step
    armgame's (``MATCHED_STEP``; see the module's doc)."""
    import motornet as mn
    import torch

    torch.set_num_threads(1)  # one core against one core: armgame's vector env is single-threaded
    step = MATCHED_STEP if matched else {}
    if effector == "reacher":
        arm = mn.effector.Reacher(muscle=mn.muscle.ReluMuscle(), **step)
    else:
        arm = mn.effector.RigidTendonArm26(muscle=mn.muscle.RigidTendonHillMuscle(), **step)
    return mn.environment.RandomTargetReach(effector=arm, differentiable=False)


def motornet_facts(effector: str, matched: bool = False) -> dict[str, object]:
    """MotorNet's versions and its env step (simulated seconds, integration), or why it could not be imported."""
    try:
        import motornet as mn
        import torch
    except ImportError as exc:  # the benchmark runs without it: armgame's columns alone
        return {"missing": f"{type(exc).__name__}: {exc}"}
    env = motornet_env(effector, matched)
    arm = env.effector
    return {"matched": matched,
            "versions": f"torch {torch.__version__}, motornet {mn.__version__}, {torch.get_num_threads()} thread",
            "env": f"RandomTargetReach({type(arm).__name__}({type(arm.muscle).__name__}))",
            "dt": env.dt, "ministeps": arm.n_ministeps, "integration": arm.integration_method,
            "episode_seconds": env.max_ep_duration}


def motornet_runner(num_envs: int, effector: str, matched: bool = False) -> Callable[[float], tuple[float, float]]:
    """Env-steps per second (vector steps x batch size) of MotorNet's env for about ``seconds``: (wall, CPU)."""
    import torch

    env = motornet_env(effector, matched)
    generator = torch.Generator().manual_seed(0)
    actions = [torch.rand(num_envs, env.action_space.shape[0], generator=generator) for _ in range(8)]
    options = {"batch_size": num_envs}
    env.reset(seed=0, options=options)
    env.step(actions[0])  # as vector_runner's: the first step may build what later steps reuse

    def run(seconds: float) -> tuple[float, float]:
        steps, start, cpu = 0, time.perf_counter(), time.process_time()
        end = start + seconds
        while True:
            _, _, terminated, _, _ = env.step(actions[steps % 8])
            if terminated:  # the whole batch's episode ends at once: its API resets the batch
                env.reset(options=options)
            steps += 1
            now = time.perf_counter()
            if now >= end:
                return steps * num_envs / (now - start), steps * num_envs / (time.process_time() - cpu)

    return run


def spread(rates: list[float]) -> dict[str, float]:
    return {"median": statistics.median(rates), "min": min(rates), "max": max(rates), "repeats": len(rates)}


def paired(runners: dict[str, Callable[[float], tuple[float, float]]], seconds: float,
           repeats: int) -> dict[str, dict[str, dict[str, float]]]:
    """Each runner in turn, ``repeats`` times: wall-clock and CPU-time rates, each as median and range."""
    wall: dict[str, list[float]] = {name: [] for name in runners}
    cpu: dict[str, list[float]] = {name: [] for name in runners}
    for _ in range(repeats):
        for name, run in runners.items():
            w, c = run(seconds)
            wall[name].append(w)
            cpu[name].append(c)
    return {name: {"wall": spread(wall[name]), "cpu": spread(cpu[name]),
                   "wall_rates": wall[name], "cpu_rates": cpu[name]}  # type: ignore[dict-item]
            for name in runners}


def measure(quick: bool, sizes: tuple[int, ...] = VECTOR_SIZES, seconds: float | None = None,
            repeats: int | None = None) -> dict[str, object]:
    seconds = seconds or (0.3 if quick else 1.0)
    repeats = repeats or (3 if quick else 5)
    load_before = os.getloadavg()[0]
    single_runners = {"reach": single_runner("armgame/Reach-v0"), "acrobot": single_runner("Acrobot-v1"),
                      "reach_v1": single_runner("armgame/Reach-v1")}
    for run in single_runners.values():
        run(min(0.2, seconds))  # warm up
    single = paired(single_runners, seconds, repeats)
    ratios = [a / b for a, b in zip(single["reach"]["wall_rates"], single["acrobot"]["wall_rates"], strict=True)]
    v1_ratios = [a / b for a, b in zip(single["reach_v1"]["wall_rates"], single["reach"]["wall_rates"], strict=True)]
    vector = {}
    for n in sizes:
        vector[n] = paired({"reach": vector_runner("armgame/Reach-v0", n, "vector_entry_point"),
                            "acrobot_sync": vector_runner("Acrobot-v1", n, "sync"),
                            "reach_v1": vector_runner("armgame/Reach-v1", n, "vector_entry_point"),
                            "reach_v1_sync": vector_runner("armgame/Reach-v1", n, "sync")}, seconds, repeats)
        vector[n]["v1_ratio"] = spread([a / b for a, b in zip(vector[n]["reach_v1"]["cpu_rates"],
                                                              vector[n]["reach_v1_sync"]["cpu_rates"], strict=True)])
    return {
        **_run_facts(load_before, seconds),
        "single": single,
        "single_ratio": spread(ratios),
        "v1_ratio": spread(v1_ratios),
        "vector": vector,
    }


def _run_facts(load_before: float, seconds: float) -> dict[str, object]:
    """The machine, its load average before and after, and each repeat's length: beside every figure."""
    return {"machine": f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
                       f"numpy {np.__version__}, gymnasium {gym.__version__}, {_compiled()}",
            "load_average": [load_before, os.getloadavg()[0]], "seconds_per_repeat": seconds}


def _compiled() -> str:
    """Which of the batch's compiled modules this process loaded: without them it runs their Python twins,
    several times slower (a rebuild of the extensions while a run imports armgame can leave it without)."""
    from armgame.env import features
    from armgame.game.batch import compiled

    loaded = {"_ckernel": compiled._ckernel, "_cvector": features._cvector}  # what the batch steps with
    missing = [name for name, module in loaded.items() if module is None]
    return f"Python twins for {', '.join(missing)}" if missing else "compiled _ckernel and _cvector"


def measure_suite(env_ids: list[str], sizes: tuple[int, ...], seconds: float, repeats: int,
                  motornet: str | None = None, matched: bool = False) -> dict[str, object]:
    """Each id's ``make_vec`` vector env against its peer, paired, at each size: ``SyncVectorEnv`` of its single
    envs, or with ``motornet`` (an effector) MotorNet's env (``matched``: with armgame's step), where it imports
    (else ``make_vec`` alone)."""
    from armgame.env import CENTER_OUT_V1_IDS
    from armgame.env.base import EnvArgumentError
    from armgame.env.center_out_batch import BATCH_FROM
    from armgame.env.vector import batch_plays
    from armgame.lab.session import lab_config

    load_before = os.getloadavg()[0]
    facts = motornet_facts(motornet, matched) if motornet else None
    if facts is None:
        peer: str | None = "sync"
    else:  # MotorNet, or where it does not import no peer: make_vec's columns alone
        peer = None if "missing" in facts else "motornet"
    ids: dict[str, object] = {}
    for env_id in env_ids:
        single = gym.make(env_id)
        game = single.unwrapped  # its simulated time a step, beside MotorNet's
        step_seconds = game.decision_time
        config = game.settings.config if hasattr(game, "settings") else lab_config(game.protocol, 0)  # CenterOut's
        physics = f"{game.decision_steps} {config.integrator.upper()} steps of {config.dt * 1e3:g} ms"
        single.close()
        rates: dict[int, object] = {}
        center_out = env_id in CENTER_OUT_V1_IDS or "CenterOut" in env_id
        warm = CENTER_OUT_WARM_STEPS if center_out else 1
        for n in sizes:
            try:
                runners = {"make_vec": vector_runner(env_id, n, "vector_entry_point", warm)}
            except EnvArgumentError as exc:  # past the id's cap
                rates[n] = {"refused": str(exc)}
                continue
            if peer == "sync":
                try:
                    runners["sync"] = vector_runner(env_id, n, "sync")
                except EnvArgumentError as exc:  # SyncVectorEnv of CenterOut's single envs stops at 4,096
                    rates[n] = {**paired(runners, seconds, repeats), "sync": {"refused": str(exc)}}
                    continue
            if peer == "motornet":
                runners["motornet"] = motornet_runner(n, motornet, matched)  # type: ignore[arg-type]
            rates[n] = paired(runners, seconds, repeats)
            if peer:
                rates[n]["ratio"] = spread([a / b for a, b in zip(rates[n]["make_vec"]["cpu_rates"],  # type: ignore[index]
                                                                  rates[n][peer]["cpu_rates"], strict=True)])
        ids[env_id] = {"batched": True if center_out else batch_plays(env_id, {}),
                       "batch_from": BATCH_FROM if center_out else batch_min_envs(gym.spec(env_id).kwargs),
                       "sizes": rates, "step_seconds": step_seconds,
                       "physics": physics, "warm_steps": {"make_vec": warm, "peer": 1}}
    return {
        **_run_facts(load_before, seconds),
        "repeats": repeats,
        "peer": peer,
        "motornet": facts,
        "ids": ids,
    }


def report_suite(result: dict) -> None:
    load = result["load_average"]
    print(f"env steps per second, wall clock: median [min - max] of {result['repeats']} repeats of "
          f"{result['seconds_per_repeat']} s, interleaved with the peer; per CPU second: median")
    print(f"{result['machine']}; load average {load[0]:.1f} before, {load[1]:.1f} after")
    facts = result["motornet"]
    if facts is not None:
        if "missing" in facts:
            print(f"MotorNet not measured (does not import: {facts['missing']}): make_vec's columns alone")
        else:
            report_motornet(result)
            return
    if result["peer"] is None:
        for env_id, found in result["ids"].items():
            print(f"{env_id}: make_vec per CPU s " + ", ".join(
                f"{n}: {'refused' if 'refused' in rates else format(rates['make_vec']['cpu']['median'], ',.0f')}"
                for n, rates in found["sizes"].items()))
        return
    cpu = "per CPU s"
    for env_id, found in result["ids"].items():
        kind = "the batch" if found["batched"] else "single envs"
        print(f"{env_id} (make_vec steps {kind} from {found['batch_from']} envs)")
        print(f"{'envs':>6}  {'make_vec':>32} {cpu:>11}  {'SyncVectorEnv':>30} {cpu:>11}  make_vec / sync per CPU s")
        for n, rates in found["sizes"].items():
            if "refused" in rates:
                print(f"{n:>6}  refused: {rates['refused']}")
                continue
            if "refused" in rates["sync"]:  # past SyncVectorEnv's cap: make_vec alone
                print(f"{n:>6}  {fmt(rates['make_vec']['wall']):>32} {rates['make_vec']['cpu']['median']:>11,.0f}  "
                      f"SyncVectorEnv refused: {rates['sync']['refused']}")
                continue
            ours, theirs, r = rates["make_vec"], rates["sync"], rates["ratio"]
            print(f"{n:>6}  {fmt(ours['wall']):>32} {ours['cpu']['median']:>11,.0f}  {fmt(theirs['wall']):>30} "
                  f"{theirs['cpu']['median']:>11,.0f}  {r['median']:.2f} [{r['min']:.2f} - {r['max']:.2f}]")


def report_motornet(result: dict) -> None:
    """Each id's ``make_vec`` vector env beside MotorNet's env: per CPU second, the ratio per env step and per
    simulated second (the two sides' env steps simulate different times)."""
    facts = result["motornet"]
    steps = f"{facts['ministeps']} {facts['integration']} step{'s' if facts['ministeps'] > 1 else ''}"
    print(f"MotorNet{' (matched)' if facts.get('matched') else ''}: {facts['env']}, {facts['versions']}; its env step "
          f"{facts['dt'] * 1e3:g} ms simulated ({steps}), episodes of {facts['episode_seconds']:g} s "
          f"reset for the whole batch inside the clock")
    cpu = "per CPU s"
    for env_id, found in result["ids"].items():
        kind = "the batch" if found["batched"] else "single envs"
        per_sim = found["step_seconds"] / facts["dt"]  # armgame's simulated seconds per MotorNet's, per env step
        print(f"{env_id} (make_vec steps {kind} from {found['batch_from']} envs; its env step "
              f"{found['step_seconds'] * 1e3:g} ms simulated, {found['physics']})")
        print(f"{'envs':>6}  {'make_vec':>32} {cpu:>11}  {'MotorNet':>30} {cpu:>11}  "
              f"{'armgame / MotorNet per CPU s':>30}  {'per simulated s':>15}")
        for n, rates in found["sizes"].items():
            if "refused" in rates:
                print(f"{n:>6}  refused: {rates['refused']}")
                continue
            ours, theirs, r = rates["make_vec"], rates["motornet"], rates["ratio"]
            ratio = f"{r['median']:.2f} [{r['min']:.2f} - {r['max']:.2f}]"
            short = "" if r["median"] >= MOTORNET_GOAL else f" (< {MOTORNET_GOAL:g})"
            print(f"{n:>6}  {fmt(ours['wall']):>32} {ours['cpu']['median']:>11,.0f}  {fmt(theirs['wall']):>30} "
                  f"{theirs['cpu']['median']:>11,.0f}  {ratio + short:>30}  {r['median'] * per_sim:>15.2f}")


def profile(num_envs: int = 8192, steps: int = 60) -> list[tuple[str, float]]:
    """Where a vector step's time goes: the share of each function's own time, largest first."""
    import cProfile
    import pstats

    envs = gym.make_vec("armgame/Reach-v0", num_envs=num_envs, vectorization_mode="vector_entry_point")
    envs.action_space.seed(0)
    actions = [envs.action_space.sample() for _ in range(8)]
    envs.reset(seed=0)
    envs.step(actions[0])
    profiler = cProfile.Profile(time.process_time)
    profiler.enable()
    for i in range(steps):
        envs.step(actions[i % 8])
    profiler.disable()
    stats = pstats.Stats(profiler).stats  # type: ignore[attr-defined]
    total = sum(row[2] for row in stats.values())
    shares = sorted(((f"{os.path.basename(file)}:{line} {name}", row[2] / total)
                     for (file, line, name), row in stats.items()), key=lambda item: -item[1])
    return shares[:8]


def fmt(s: dict[str, float]) -> str:
    return f"{s['median']:,.0f} [{s['min']:,.0f} - {s['max']:,.0f}]"


def report(result: dict) -> None:
    load = result["load_average"]
    print(f"env steps per second, wall clock: median [min - max] of {result['single']['reach']['wall']['repeats']} "
          f"repeats of {result['seconds_per_repeat']} s, interleaved with the peer; per CPU second: median")
    print(f"{result['machine']}; load average {load[0]:.1f} before, {load[1]:.1f} after")
    s, r = result["single"], result["single_ratio"]
    print(f"single env (gymnasium.make): armgame/Reach-v0 {fmt(s['reach']['wall'])} "
          f"({s['reach']['cpu']['median']:,.0f} per CPU s); Acrobot-v1 {fmt(s['acrobot']['wall'])} "
          f"({s['acrobot']['cpu']['median']:,.0f} per CPU s)")
    print(f"  Reach-v0 / Acrobot-v1, paired: {r['median']:.2f} [{r['min']:.2f} - {r['max']:.2f}] "
          f"(goal >= {SINGLE_GOAL:g})")
    v1 = result["v1_ratio"]
    print(f"  armgame/Reach-v1 (the hand in its observation, the dense reward) {fmt(s['reach_v1']['wall'])}: "
          f"{v1['median']:.2f} [{v1['min']:.2f} - {v1['max']:.2f}] times Reach-v0's rate, paired")
    cpu = "per CPU s"
    print(f"{'envs':>6}  {'Reach-v0 vector env':>32} {cpu:>11}  {'Acrobot-v1 SyncVectorEnv':>30} {cpu:>11}")
    for n, rates in result["vector"].items():
        ours, theirs = rates["reach"], rates["acrobot_sync"]
        print(f"{n:>6}  {fmt(ours['wall']):>32} {ours['cpu']['median']:>11,.0f}  {fmt(theirs['wall']):>30} "
              f"{theirs['cpu']['median']:>11,.0f}")
    n = max(result["vector"])
    top = result["vector"][n]["reach"]
    print(f"vector env at {n:,} envs: {top['wall']['median'] / 1e6:.2f} M env-steps/s wall, "
          f"{top['cpu']['median'] / 1e6:.2f} M per CPU second (goal >= {VECTOR_GOAL / 1e6:g} M)")
    print(f"{'envs':>6}  {'Reach-v1 vector env':>32} {cpu:>11}  {'Reach-v1 SyncVectorEnv':>30} {cpu:>11}  "
          f"native / sync per CPU s")
    for n, rates in result["vector"].items():
        ours, theirs, r = rates["reach_v1"], rates["reach_v1_sync"], rates["v1_ratio"]
        print(f"{n:>6}  {fmt(ours['wall']):>32} {ours['cpu']['median']:>11,.0f}  {fmt(theirs['wall']):>30} "
              f"{theirs['cpu']['median']:>11,.0f}  {r['median']:.2f} [{r['min']:.2f} - {r['max']:.2f}]")
    top = result["vector"][n]["reach_v1"]
    print(f"Reach-v1 vector env at {n:,} envs: {top['wall']['median'] / 1e6:.2f} M env-steps/s wall, "
          f"{top['cpu']['median'] / 1e6:.2f} M per CPU second (goal >= {V1_VECTOR_GOAL / 1e6:g} M)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="shorter repeats, fewer of them")
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    parser.add_argument("--profile", action="store_true", help="also profile the vector env at 8,192 envs")
    parser.add_argument("--suite", nargs="+", metavar="ID",
                        help="instead: these ids' make_vec vector envs against SyncVectorEnv of their single envs")
    parser.add_argument("--motornet", action="store_true",
                        help="with --suite: MotorNet's reaching env as the peer instead of SyncVectorEnv")
    parser.add_argument("--motornet-matched", action="store_true",
                        help="with --suite: MotorNet's env with armgame's step (20 ms as 5 RK4 steps of 4 ms) as the "
                             "peer")
    parser.add_argument("--motornet-effector", choices=("reacher", "arm26"), default="reacher",
                        help="MotorNet's arm: Reacher with ReluMuscle (default, the closest to armgame's) or "
                             "RigidTendonArm26 with RigidTendonHillMuscle")
    parser.add_argument("--sizes", nargs="+", type=int,
                        help=f"the vector sizes (default {VECTOR_SIZES}; with --motornet {MOTORNET_SIZES})")
    parser.add_argument("--seconds", type=float, help="the seconds of one repeat (default 1, --quick 0.3)")
    parser.add_argument("--repeats", type=int, help="the repeats of each figure (default 5, --quick 3)")
    args = parser.parse_args()
    motornet = args.motornet or args.motornet_matched
    if motornet and not args.suite:
        parser.error("--motornet and --motornet-matched are measured beside --suite ID ...")
    sizes = tuple(args.sizes or (MOTORNET_SIZES if motornet else VECTOR_SIZES))
    if args.suite:
        result = measure_suite(args.suite, sizes, args.seconds or (0.3 if args.quick else 1.0),
                               args.repeats or (3 if args.quick else 5),
                               args.motornet_effector if motornet else None, args.motornet_matched)
        if args.json:
            print(json.dumps(result, default=str))
        else:
            report_suite(result)
        return
    result = measure(args.quick, sizes, args.seconds, args.repeats)
    if args.profile:
        result["profile"] = profile()
    if args.json:
        print(json.dumps(result, default=str))
        return
    report(result)
    if args.profile:
        print("where a vector step's CPU time goes at 8,192 envs (own time of each function):")
        for name, share in result["profile"]:
            print(f"  {share:6.1%}  {name}")


if __name__ == "__main__":
    main()
