"""CenterOut-v1's batched vector env against Gymnasium's SyncVectorEnv of single envs (issue 52, item 5): every
sub-env's observations, rewards, flags and infos equal, bit for bit, for each id and each field kind, the
autoreset modes the batch runs, and the speed guard's stop."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import armgame.env  # noqa: F401  (registers the ids)
from armgame.env import center_out as center_out_module
from armgame.env import center_out_batch
from armgame.env.base import EnvArgumentError
from armgame.env.center_out_batch import CenterOutBatchVectorEnv, center_out_vector_env
from armgame.env.center_out_v1 import CenterOutVectorEnv
from armgame.lab.metrics import METRIC_COLUMNS, Reach, reach_metrics
from armgame.lab.presets import preset
from armgame.lab.session import schedule

compiled = pytest.mark.skipif(center_out_batch._ccenter is None, reason="armgame.env._ccenter was not built")

IDS = ("armgame/CenterOut-v1", "armgame/CenterOutContinuous-v1", "armgame/CenterOutHold-v1",
       "armgame/CenterOutHoldContinuous-v1")
#: One field or display of each kind, at or near its range's extremes (the matrices at the feeding limits).
KINDS = ("none", {"perturbation": "curl", "b": -50.0}, {"perturbation": "constant", "fx": 20.0, "fy": -20.0},
         {"perturbation": "spring", "stiffness": 250.0},
         {"perturbation": "viscous", "matrix": [[2.0, 50.0], [-50.0, 0.0]]},
         {"perturbation": "joint_viscous", "matrix": [[0.15, 5.0], [-5.0, 0.0]]},
         {"perturbation": "rotation", "angle": -180.0}, {"perturbation": "mirror", "axis": 45.0})

#: The null preset from its exposure block on: the field (or display) given as ``perturbation`` is on from the first
#: trial's go cue (but on catch trials).
EXPOSED = replace(preset("null"), blocks=preset("null").blocks[1:])


def same(a: object, b: object, where: str) -> None:
    if isinstance(a, tuple):
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            same(x, y, f"{where}[{k}]")
    elif isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), (where, sorted(set(a) ^ set(b)))
        for key in a:
            same(a[key], b[key], f"{where}/{key}")
    elif isinstance(a, np.ndarray) and a.dtype == object:
        assert isinstance(b, np.ndarray) and b.dtype == object and len(a) == len(b), where
        for x, y in zip(a, b, strict=True):
            assert str(x) == str(y), (where, x, y)  # rows hold NaN measures: their text is equal, == is not
    else:
        assert isinstance(b, np.ndarray) and a.dtype == b.dtype, (where, a, b)
        assert np.array_equal(a, b, equal_nan=True), (where, a, b)


def played(env_id: str, n: int, steps: int, seed: int = 3, **kwargs: object) -> dict[str, int]:
    """Step the batch and SyncVectorEnv side by side on the same random actions; what happened, counted."""
    spec = gym.spec(env_id)
    args = {**spec.kwargs, **kwargs}
    sync, batch = CenterOutVectorEnv(n, **args), CenterOutBatchVectorEnv(n, **args)
    same(sync.reset(seed=seed), batch.reset(seed=seed), "reset")
    sync.action_space.seed(seed)
    seen = {"ends": 0, "reaches": 0, "stopped": 0}
    for t in range(steps):
        action = sync.action_space.sample()
        a, b = sync.step(action), batch.step(action)
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            same(x, y, f"step {t}, item {k}")
        seen["ends"] += int((a[2] | a[3]).sum())
        seen["reaches"] += int(a[4].get("_reaches", np.zeros(1, bool)).sum())
        seen["stopped"] += int(a[4].get("_stopped", np.zeros(1, bool)).sum())
    return seen


@compiled
@pytest.mark.parametrize("env_id", IDS)
def test_each_id_equals_sync(env_id: str) -> None:
    seen = played(env_id, 2, 220, episode_trials=1)
    assert seen["reaches"] > 0 or "Hold" in env_id  # random keys rarely hold still at home


@compiled
@pytest.mark.parametrize("kind", KINDS, ids=lambda k: k if isinstance(k, str) else k["perturbation"])
def test_each_field_kind_equals_sync(kind: object) -> None:
    played("armgame/CenterOutContinuous-v1", 2, 200, episode_trials=1, protocol=EXPOSED, perturbation=kind)


@compiled
def test_jointspace_continue_run_sparse_and_float64() -> None:
    played("armgame/CenterOut-v1", 2, 200, protocol="jointspace", episode_trials=1, continue_run=True)
    played("armgame/CenterOut-v1", 2, 150, episode_trials=1, reward="sparse", time_cost=0.5,
           observation_dtype="float64")


@compiled
def test_the_guards_stop_equals_sync(monkeypatch: pytest.MonkeyPatch) -> None:
    # A bound the field breaks within a reach: both stop the run there, terminated, info["stopped"] the same.
    monkeypatch.setattr(center_out_module, "speed_bound", lambda config: 0.5)
    monkeypatch.setattr(center_out_batch, "speed_bound", lambda config: 0.5)
    seen = played("armgame/CenterOutContinuous-v1", 3, 200, episode_trials=2, protocol=EXPOSED,
                  perturbation={"perturbation": "constant", "fx": 20.0, "fy": 20.0})
    assert seen["stopped"] > 0


@compiled
@pytest.mark.parametrize("kind", ["none", KINDS[1], {"perturbation": "constant", "fx": 20.0, "fy": 20.0}],
                         ids=["none", "curl", "constant"])
def test_runs_in_vector_lanes_equal_sync(monkeypatch: pytest.MonkeyPatch, kind: object) -> None:
    # From 16 runs on, the C loop steps blocks of 16 side by side (_lanes.h's RK4): two blocks and 3 runs alone, their
    # lanes in step without a field, all with one, in different phases of a field's trial, and stopped by the guard.
    monkeypatch.setattr(center_out_module, "speed_bound", lambda config: 0.5)
    monkeypatch.setattr(center_out_batch, "speed_bound", lambda config: 0.5)
    seen = played("armgame/CenterOutContinuous-v1", 35, 300, seed=7, episode_trials=2, protocol=EXPOSED,
                  perturbation=kind)
    assert seen["stopped" if "constant" in str(kind) else "reaches"] > 0, seen


@compiled
def test_disabled_autoreset_and_masks_equal_sync() -> None:
    args = {"continuous": False, "episode_trials": 1}
    sync = CenterOutVectorEnv(2, autoreset_mode="Disabled", **args)
    batch = CenterOutBatchVectorEnv(2, autoreset_mode="Disabled", **args)
    same(sync.reset(seed=5), batch.reset(seed=5), "reset")
    sync.action_space.seed(5)
    for t in range(300):
        action = sync.action_space.sample()
        a, b = sync.step(action), batch.step(action)
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            same(x, y, f"step {t}, item {k}")
        ended = a[2] | a[3]
        if ended.any():
            same(sync.reset(options={"reset_mask": ended}), batch.reset(options={"reset_mask": ended}), "mask")


@compiled
def test_make_vec_takes_the_batch_where_it_runs() -> None:
    assert isinstance(gym.make_vec("armgame/CenterOut-v1", num_envs=8192), CenterOutBatchVectorEnv)
    assert isinstance(center_out_vector_env(2, protocol="null", autoreset_mode="SameStep"), CenterOutVectorEnv)
    with pytest.raises(EnvArgumentError, match="1 to 4096"):
        center_out_vector_env(5000, autoreset_mode="SameStep")


@compiled
@pytest.mark.slow
@pytest.mark.parametrize("env_id", IDS)
def test_longer_runs_of_every_kind_equal_sync(env_id: str) -> None:
    for kind in KINDS:
        played(env_id, 4, 1500, seed=11, perturbation=kind, protocol=EXPOSED, episode_trials=3)
    played(env_id, 4, 1500, seed=12, protocol="curl", episode_trials="block", continue_run=True)


def test_the_docs_batch_figures_are_the_committed_run() -> None:
    """docs/programs.md's figures for CenterOut's batch are the committed runs': beside SyncVectorEnv
    (benchmarks/results/env_speed_center_out.json: its load, each id's rate and ratio at 8,192 envs, CenterOut-v1's
    range there, and the ratios at 4 envs), and beside MotorNet's matched env
    (benchmarks/results/env_speed_center_out_motornet.json: its load, its env's step, and each size's table row)."""
    root = Path(__file__).resolve().parent.parent
    results = root / "benchmarks" / "results"
    run = json.loads((results / "env_speed_center_out.json").read_text(encoding="utf-8"))
    prose = " ".join((root / "docs" / "programs.md").read_text(encoding="utf-8").split())
    ids = ("armgame/CenterOut-v1", "armgame/CenterOutContinuous-v1")
    assert run["peer"] == "sync" and run["motornet"] is None and set(run["ids"]) == set(ids)
    top = [run["ids"][i]["sizes"]["8192"] for i in ids]
    at4 = [run["ids"][i]["sizes"]["4"] for i in ids]
    spread = min(top[0]["make_vec"]["cpu_rates"]), max(top[0]["make_vec"]["cpu_rates"])
    assert f"(its repeats: {spread[0] / 1e6:.2f} to {spread[1] / 1e6:.2f} M)" in prose
    load = run["load_average"]
    assert f"measured on 2 cores under a load average of {load[0]:.1f} to {load[1]:.1f}" in prose
    assert (f"the batch makes {top[0]['make_vec']['cpu']['median'] / 1e6:.2f} M (`CenterOut-v1`) and "
            f"{top[1]['make_vec']['cpu']['median'] / 1e6:.2f} M (`CenterOutContinuous-v1`) env steps at 8,192 envs, "
            f"{top[0]['ratio']['median']:.2f} and {top[1]['ratio']['median']:.2f} times Gymnasium's `SyncVectorEnv` of "
            f"single envs ({top[0]['sync']['cpu']['median'] / 1e3:.0f} k and "
            f"{top[1]['sync']['cpu']['median'] / 1e3:.0f} k;") in prose
    assert (f"and {at4[0]['ratio']['median']:.2f} and {at4[1]['ratio']['median']:.2f} times it at 4 envs") in prose
    assert all(run["ids"][i]["batch_from"] == center_out_batch.BATCH_FROM for i in ids)
    matched = json.loads((results / "env_speed_center_out_motornet.json").read_text(encoding="utf-8"))
    facts = matched["motornet"]
    assert matched["peer"] == "motornet" and set(matched["ids"]) == set(ids)
    assert facts["matched"] and (facts["dt"], facts["ministeps"], facts["integration"]) == (0.02, 5, "rk4")
    load = matched["load_average"]
    assert f"({facts['versions']}; load average {load[0]:.1f} to {load[1]:.1f})" in prose
    for n in matched["ids"][ids[0]]["sizes"]:
        cells = []
        for i in ids:
            rates = matched["ids"][i]["sizes"][n]
            ratio = rates["ratio"]
            cells += [f"{rates['make_vec']['cpu']['median']:,.0f}", f"{rates['motornet']['cpu']['median']:,.0f}",
                      f"{ratio['median']:.2f} [{ratio['min']:.2f} - {ratio['max']:.2f}]"]
        assert f"| {int(n):,} | " + " | ".join(cells) + " |" in prose, n
    at = {size: [matched["ids"][i]["sizes"][size] for i in ids] for size in ("4096", "8192")}
    assert (f"{at['4096'][0]['ratio']['median']:.2f} and {at['4096'][1]['ratio']['median']:.2f} times at 4,096 envs, "
            f"{at['8192'][0]['ratio']['median']:.2f} and {at['8192'][1]['ratio']['median']:.2f} at 8,192") in prose
    assert f"each range, {at['8192'][0]['ratio']['min']:.2f} and {at['8192'][1]['ratio']['min']:.2f})" in prose
    assert all(rates["ratio"]["median"] >= 10 for i in ids for rates in matched["ids"][i]["sizes"].values())
    assert (f"makes {at['8192'][0]['motornet']['cpu']['median'] / 1e3:.0f} k and "
            f"{at['8192'][1]['motornet']['cpu']['median'] / 1e3:.0f} k env steps a CPU second") in prose
    spread = [sorted(run["ids"][i]["sizes"]["8192"]["make_vec"]["cpu_rates"]) for i in ids]
    assert f"the continuous id ({spread[1][0] / 1e6:.2f} to {spread[1][-1] / 1e6:.2f} M)" in prose


def test_the_docs_table_of_a_steps_parts_is_the_committed_run() -> None:
    """docs/programs.md's table of where a CenterOut batch step's time goes is the runs of
    benchmarks/results/center_out_parts.json (benchmarks/center_out_parts.py), each figure the mean of the before's
    runs and of the now's."""
    root = Path(__file__).resolve().parent.parent
    parts = json.loads((root / "benchmarks" / "results" / "center_out_parts.json").read_text(encoding="utf-8"))
    prose = (root / "docs" / "programs.md").read_text(encoding="utf-8")
    runs = {label: [r for r in parts["runs"] if r["label"] == label] for label in ("e354ef1, before", "this change")}
    assert all(len(kept) == 2 for kept in runs.values())
    assert {(r["env_id"], r["num_envs"], r["steps"], r["warm"]) for r in parts["runs"]} == {
        ("armgame/CenterOut-v1", 8192, 1500, 1500)}

    def mean(label: str, part: str | None) -> float:
        return float(np.mean([r["ms_per_step"] if part is None else r["parts_ms_per_step"][part] for r in runs[label]]))

    rows = [line for line in prose.splitlines() if line.startswith("| ") and line.count(" | ") == 2]
    table = rows[rows.index("| part | ms a step, before | now |") + 1:]
    names = ("advance", "measures", "ended trials", "episode starts", "actions", "dense reward", "the rest")
    for name, line in zip(names, table, strict=False):
        cells = line.strip("| ").split(" | ")
        assert cells[1:] == [f"{mean('e354ef1, before', name):.2f}", f"{mean('this change', name):.2f}"], (name, line)
    total = f"| **a step** | **{mean('e354ef1, before', None):.2f}** | **{mean('this change', None):.2f}** |"
    assert table[len(names)] == total
    ended = {r["trials_ended_per_step"] for r in parts["runs"]}
    assert f"about {round(min(ended))} trials ending a step" in " ".join(prose.split())


@pytest.mark.parametrize("name", ("null", "curl", "savings", "random-fields", "generalization"))
def test_a_schedules_first_trials_are_the_full_schedules(name: str) -> None:
    # The batch draws a run's first episode's trials only (``limit``): they must be the full schedule's, probes and
    # mixed blocks included, whatever the cut.
    protocol = preset(name)
    full = schedule(protocol, 7, 0.004, (0.0, 0.4))
    for limit in (1, 2, 9, protocol.blocks[0].trials, protocol.blocks[0].trials + 3, len(full), len(full) + 5):
        assert schedule(protocol, 7, 0.004, (0.0, 0.4), limit=limit) == full[:limit], limit


@compiled
def test_the_c_reach_measures_are_reach_metrics_bit_for_bit() -> None:
    # _ccenter.measures stands for lab.metrics.reach_metrics on each ended trial: smooth, noisy, still, cut-off,
    # random and too-short paths, targets off and on the home position, several steps and go cues.
    rng = np.random.default_rng(52)
    cap, count = 300, 1500
    xs, ys = np.zeros((count, cap)), np.zeros((count, cap))
    samples, go, geometry = np.zeros(count, np.int64), np.zeros(count, np.int64), np.zeros((count, 5))
    for k in range(count):
        n = int(rng.integers(0, cap + 1)) if k % 10 else int(rng.integers(0, 4))
        home = rng.normal(0.0, 0.3, 2)
        target = home + rng.normal(0.0, 0.1, 2) if k % 20 else home
        s = np.clip((np.arange(n) - rng.integers(-20, 60)) / rng.integers(10, 200), 0.0, 1.0)
        shape = 10 * s**3 - 15 * s**4 + 6 * s**5
        x, y = home[0] + (target[0] - home[0]) * shape, home[1] + (target[1] - home[1]) * shape
        kind = k % 4
        if kind == 1:
            x, y = x + rng.normal(0, 1e-4, n).cumsum(), y + rng.normal(0, 1e-4, n).cumsum()
        elif kind == 2:
            x, y = np.full(n, home[0]), np.full(n, home[1]) + 1e-9 * (k % 8 == 2) * np.arange(n)
        elif kind == 3:
            x, y = rng.normal(0.0, 0.05, n), rng.normal(0.0, 0.05, n)
        xs[k, :n], ys[k, :n] = x, y
        samples[k], go[k] = n, rng.integers(0, 3000)
        geometry[k] = (float(rng.choice([0.004, 0.001, 1 / 240])), *home, *target)
    out = np.zeros((count, len(METRIC_COLUMNS)))
    center_out_batch._ccenter.measures(xs, ys, np.arange(count), samples, go, geometry, out)
    for k in range(count):
        n, dt = int(samples[k]), geometry[k, 0]
        reach = Reach(t=(go[k] + np.arange(n)) * dt, hand=np.column_stack((xs[k, :n], ys[k, :n])),
                      start=tuple(geometry[k, 1:3]), target=tuple(geometry[k, 3:5]), go_time=int(go[k]) * dt, hit=True)
        want = np.array(list(reach_metrics(reach).as_dict().values()))
        assert np.array_equal(np.isnan(want), np.isnan(out[k])), k
        assert want[~np.isnan(want)].tobytes() == out[k][~np.isnan(out[k])].tobytes(), (k, want, out[k])


def measured_as_reach_metrics(paths: list[tuple[np.ndarray, np.ndarray, int, float, tuple, tuple]]) -> int:
    """Each (x, y, go, dt, home, target) through _ccenter.measures and through reach_metrics, the same bits; the count
    of measures defined."""
    cap = max(len(x) for x, *_ in paths)
    xs, ys = np.zeros((len(paths), cap)), np.zeros((len(paths), cap))
    samples, go, geometry = np.zeros(len(paths), np.int64), np.zeros(len(paths), np.int64), np.zeros((len(paths), 5))
    for k, (x, y, start, dt, home, target) in enumerate(paths):
        xs[k, :len(x)], ys[k, :len(x)], samples[k], go[k], geometry[k] = x, y, len(x), start, (dt, *home, *target)
    out = np.zeros((len(paths), len(METRIC_COLUMNS)))
    center_out_batch._ccenter.measures(xs, ys, np.arange(len(paths)), samples, go, geometry, out)
    for k, (x, y, start, dt, home, target) in enumerate(paths):
        reach = Reach(t=(start + np.arange(len(x))) * dt, hand=np.column_stack((x, y)), start=home, target=target,
                      go_time=start * dt, hit=True)
        with np.errstate(all="ignore"):  # the huge and tiny paths overflow as numpy measures them
            want = np.array(list(reach_metrics(reach).as_dict().values()))
        assert np.array_equal(np.isnan(want), np.isnan(out[k])), (k, want, out[k])
        assert want[~np.isnan(want)].tobytes() == out[k][~np.isnan(out[k])].tobytes(), (k, want, out[k])
    return int((~np.isnan(out)).sum())


@compiled
def test_the_c_reach_measures_are_reach_metrics_at_their_edges() -> None:
    # _ccenter.measures takes a speed's hypot only where the squared differences cannot settle it within their margin:
    # speeds within ulps of the 5% level (on a step of 2^-8, so that a speed is hypot of 128 times the differences),
    # the crossing at the first and last samples, speeds tied and nearly tied at the peak, and coordinates, steps and
    # go cues past the margin's bounds, where every speed is hypot's.
    paths = []
    n, dt = 64, 2.0**-8
    k = np.arange(n) - 11.0
    ramp = np.where(k > 0, 1e-3 * k * (1.0 + k / 20.0), 0.0)  # still, then every speed above the level up to the end
    rng = np.random.default_rng(5)
    for angle in (0.0, *rng.uniform(0.0, 2 * math.pi, 60)):
        c, s = math.cos(angle), math.sin(angle)
        speed = np.hypot(*np.gradient(np.column_stack((c * ramp, s * ramp)), dt, axis=0).T)
        level = 0.05 * float(speed.max())
        for ulps in range(-12, 13):
            # sample 10's speed (128 times its differences), and from sample 10 on, the first sample's speed (256 times
            # them): the level, and up to 12 ulps of x to either side; kept where the level and the squared
            # differences compared, as the squares they are, would not say what hypot says
            x, y, ex, ey = c * ramp, s * ramp, c * ramp, s * ramp
            x[11], y[11], ex[11], ey[11] = c * level / 128.0, s * level / 128.0, c * level / 256.0, s * level / 256.0
            for _ in range(abs(ulps)):
                x[11] = math.nextafter(x[11], math.copysign(math.inf, ulps))
                ex[11] = math.nextafter(ex[11], math.copysign(math.inf, ulps))
            scaled = (level / 128.0) ** 2
            if angle == 0.0 or (x[11] ** 2 + y[11] ** 2 < scaled) != (np.hypot(x[11], y[11]) * 128 < level):
                for path in ((x, y), (x[::-1], y[::-1]), (x[9:], y[9:]), (x[9:][::-1], y[9:][::-1])):
                    paths.append((*path, 0, dt, (0.0, 0.0), (0.1 * c, 0.1 * s)))
            if angle == 0.0 or (4 * (ex[11] ** 2 + ey[11] ** 2) < scaled) != (np.hypot(ex[11], ey[11]) * 256 < level):
                for path in ((ex[10:], ey[10:]), (ex[10:][::-1], ey[10:][::-1])):
                    paths.append((*path, 0, dt, (0.0, 0.0), (0.1 * c, 0.1 * s)))
    assert len(paths) >= 200
    for a1, b1 in rng.uniform(0.3, 0.6, (6, 2)):
        # two steps of the hand, (a1, b1) at sample 20 and back by (a2, b2) at sample 40, a few ulps from it, whose
        # speeds' order (or tie) the squared differences get wrong
        grid = np.arange(-40, 41)
        a2, b2 = np.broadcast_arrays(a1 + grid[:, None] * np.spacing(a1), b1 - grid * np.spacing(b1))
        wrong = (a2 * a2 + b2 * b2 > a1 * a1 + b1 * b1) != (np.hypot(a2, b2) > np.hypot(a1, b1))
        for a, b in list(zip(a2[wrong], b2[wrong], strict=True))[:6]:
            x, y = (np.concatenate([np.zeros(20), [c / 2], np.full(19, c), [c - d / 2], np.full(20, c - d)])
                    for c, d in ((a1, a), (b1, b)))
            paths.append((x, y, 0, dt, (0.0, 0.0), (0.1, 0.1)))
    tied = np.concatenate([np.zeros(20), np.arange(1.0, 101.0) * 2.0**-10, np.full(30, 100 * 2.0**-10)])
    paths.append((tied, np.zeros(len(tied)), 3, dt, (0.0, 0.0), (0.1, 0.0)))  # every speed on the way the same
    paths.append((tied, tied, 3, dt, (0.0, 0.0), (0.1, 0.1)))
    u = np.clip(np.arange(120) / 80.0 - 0.2, 0.0, 1.0)
    x = 0.05 * u**3 * (10 - 15 * u + 6 * u * u)
    for scale in (1e-320, 1e-300, 1e-120, 1e-101, 1e-99, 1.0, 1e99, 1e101, 1e120, 1e300):
        for dt_ in (1e-300, 1e-101, 1e-99, 0.004, 1e99, 1e101):
            paths.append((scale * x, scale * (u - 0.5) * 1e-3, 1, dt_, (0.0, 0.0), (scale, scale)))
    for offset in (9.9e99, 1.1e100):  # coordinates within and past 1e100 in size, their differences far smaller
        paths.append((offset + 1e90 * x, np.full(len(x), -1e-100), 5, 0.004, (offset, 0.0), (offset + 1e90, 1e89)))
    for start, step in ((2**52 - 100, 0.004), (2**53 - 50, 1.0), (-60, 0.004), (-60, -0.004), (0, 5e-324),
                        (0, 2.2250738585072014e-308), (10, 1e306), (2**52 - 130, 0.004)):
        paths.append((x, x * 0.5, start, step, (0.0, 0.0), (0.05, 0.025)))
    assert measured_as_reach_metrics(paths) > 4 * len(paths)


@compiled
def test_the_dense_rewards_distance_is_math_hypot_bit_for_bit() -> None:
    # _ccenter.edges stands for the single env's max(0.0, math.hypot(dx, dy) - radius): CPython's own hypot (not the
    # C library's, which differs in the last bit now and then), on game-sized, huge, tiny, subnormal, far-apart and
    # special values, and random bit patterns.
    rng = np.random.default_rng(53)
    count = 60_000
    special = (0.0, -0.0, 5e-324, 1e-310, 2.2250738585072014e-308, 0.5, 1.0, 3.0, 4.0, 0.1, 1e308,
               1.7976931348623157e308, np.inf, -np.inf, np.nan)
    xy = np.concatenate([rng.normal(0.0, 0.3, (count, 2)),
                         rng.uniform(-1, 1, (count, 2)) * 10.0 ** rng.integers(-320, 309, (count, 1)),
                         rng.integers(0, 2**63, (count, 2), dtype=np.int64).view(np.float64),
                         np.column_stack([rng.normal(size=count), rng.normal(size=count) * 10.0 ** rng.integers(
                             -200, 200, count)]),
                         [(x, y) for x in special for y in special]])
    n = len(xy)
    obs, ints, trials = np.zeros((n, 16)), np.zeros((n, center_out_batch.I_COUNT), np.int64), \
        np.zeros((n, center_out_batch.T_COUNT))
    obs[:, 12:14] = xy
    ints[:, center_out_batch.I_PHASE] = rng.integers(0, 2, n)
    trials[:, center_out_batch.T_TR] = rng.uniform(0.0, 0.05, n) * (np.arange(n) % 3 > 0)
    trials[:, center_out_batch.T_HR] = rng.uniform(0.0, 0.05, n)
    out = np.empty(n)
    center_out_batch._ccenter.edges(obs, ints, trials, None, out)
    radius = np.where(ints[:, center_out_batch.I_PHASE] == 1, trials[:, center_out_batch.T_TR],
                      trials[:, center_out_batch.T_HR])
    want = np.array([max(0.0, math.hypot(x, y) - r) for (x, y), r in zip(xy.tolist(), radius.tolist(), strict=True)])
    assert want.tobytes() == out.tobytes()
    runs = rng.integers(0, n, 1000)
    some = np.empty(len(runs))
    center_out_batch._ccenter.edges(obs, ints, trials, runs, some)
    assert some.tobytes() == want[runs].tobytes()


@compiled
@pytest.mark.parametrize("continuous", (False, True))
def test_actions_of_every_type_and_bad_ones_as_sync(continuous: bool) -> None:
    # The batch maps the actions in C (_ccenter.act): keys as bools, int8, int64, float64, float32 and lists, levels
    # as float64, ints and lists, equal to SyncVectorEnv's. A bad value in a stepping run is refused in one line before
    # any run's muscles change: the batch goes on as its twin, which was never given it.
    args = {"continuous": continuous, "episode_trials": 1}
    sync, batch, twin = CenterOutVectorEnv(4, **args), CenterOutBatchVectorEnv(4, **args), \
        CenterOutBatchVectorEnv(4, **args)
    same(sync.reset(seed=9), batch.reset(seed=9), "reset")
    twin.reset(seed=9)
    rng = np.random.default_rng(9)
    kinds = ((lambda a: a.astype(np.float64), lambda a: (a * 2 - 1).astype(np.int64), lambda a: (a - 0.5).tolist())
             if continuous else (lambda a: a.astype(bool), lambda a: a.astype(np.int8), lambda a: a.astype(np.int64),
                                 lambda a: a.astype(np.float64), lambda a: a.astype(np.float32), lambda a: a.tolist()))
    for t in range(120):
        keys = rng.integers(0, 2, (4, 4)) if not continuous else rng.uniform(0, 1, (4, 4))
        action = kinds[t % len(kinds)](keys)
        if t % 17 == 5:
            bad = np.array(action, dtype=np.float64)
            bad[t % 4, t % 3] = np.nan if continuous else 2.0
            with pytest.raises(ValueError, match="finite numbers" if continuous else "zeros or ones"):
                batch.step(bad)
        a, b = sync.step(action), batch.step(action)
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            same(x, y, f"step {t}, item {k}")
        same(b, twin.step(action), f"twin, step {t}")
