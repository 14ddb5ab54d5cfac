"""The batch kernel's lanes (``_cbatch.c``: games side by side in SIMD registers) against its one-at-a-time
loop, the hand's trig the kernel hands back, and an install without a C compiler.

The lanes change no game's operations, only how many games an instruction serves, so their states
equal the one-at-a-time loop's bit for bit, exact and fast alike (and the exact loop equals the single
session bit for bit: tests/test_batch.py). Games here have different lengths, commands, resets and
hits, so lanes are refilled mid-run, wait for each other and fill as a block.
"""

import math
import os
import random

import numpy as np
import pytest
from test_batch import student_timeline

from armgame.game import session as session_module
from armgame.game.batch import BatchGameSession, compiled, replay_many
from armgame.game.rules import GameConfig

needs_build = pytest.mark.skipif(not (compiled.AVAILABLE or os.environ.get("ARMGAME_REQUIRE_COMPILED")),
                                 reason="the compiled kernel is not built here")


def played(lanes: bool, exact: bool, n: int = 37, seconds: float = 6.0) -> BatchGameSession:
    """``n`` games (more than two blocks of lanes, not a multiple of them) of different lengths and keys."""
    rng = random.Random(5)
    configs = [GameConfig(seed=i, time_limit=seconds - (i % 5) * 0.5) for i in range(n)]
    timelines = [student_timeline(rng, configs[0].dt, c.time_limit) for c in configs]
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(compiled, "LANES", lanes)
        batch = BatchGameSession(configs, exact=exact, kernel="compiled")
        batch.play(timelines)
    return batch


@needs_build
@pytest.mark.parametrize("exact", [True, False])
def test_the_lanes_equal_the_games_one_at_a_time_bit_for_bit(exact):
    lanes, one = played(True, exact), played(False, exact)
    assert lanes.hits.sum() > 0 and lanes.resets.sum() > 0  # hits and resets went through the lanes
    assert lanes._xs[:4].tolist() == one._xs[:4].tolist()
    assert lanes._act.tolist() == one._act.tolist()
    assert (lanes.hits.tolist(), lanes.score.tolist(), lanes.steps.tolist()) == (
        one.hits.tolist(), one.score.tolist(), one.steps.tolist())


@needs_build
def test_a_vector_envs_lockstep_in_short_calls_equals_one_long_run():
    """Many calls of a few steps (a vector env's) fill the lanes as blocks: the same states as one at a time."""
    runs = []
    for lanes in (True, False):
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(compiled, "LANES", lanes)
            batch = BatchGameSession([GameConfig(seed=i, time_limit=4.0) for i in range(40)], exact=False)
            rng = np.random.default_rng(1)
            for _ in range(100):
                batch.set_held(rng.random((40, 4)) < 0.5)
                batch.advance(5)
        runs.append(batch)
    assert runs[0]._xs[:4].tolist() == runs[1]._xs[:4].tolist() and runs[0].hits.sum() > 0
    assert runs[0].hits.tolist() == runs[1].hits.tolist()


@needs_build
def test_the_hands_trig_is_the_c_librarys_of_the_games_angles():
    batch = played(True, True, n=20)
    q1, q2 = batch.q1.tolist(), batch.q2.tolist()
    c1, s1, c12, s12 = batch.hand_trig().tolist()
    assert c1 == [math.cos(a) for a in q1] and s1 == [math.sin(a) for a in q1]
    assert c12 == [math.cos(a + b) for a, b in zip(q1, q2, strict=True)]
    assert s12 == [math.sin(a + b) for a, b in zip(q1, q2, strict=True)]
    batch.reset_arms(np.ones(20, dtype=bool) & ~batch.over)  # the arm moved outside the kernel: trig anew
    batch._x[0, 0] = 0.5
    hx, _ = batch.hand()
    arm = batch.config.arm
    assert math.isclose(hx[0], arm.l1 * math.cos(0.5) + arm.l2 * math.cos(0.5 + batch.q2[0]), abs_tol=1e-15)


def test_an_install_without_a_c_compiler_plays_the_same_games(monkeypatch):
    """No compiled loop at all (pip install with no compiler): the numpy kernel and the Python loop give the
    compiled build's results bit for bit (the arm's sine is the same Python, numpy and C, see test_trig)."""
    rng = random.Random(2)
    configs = [GameConfig(seed=i, time_limit=3.0) for i in range(6)]
    timelines = [student_timeline(rng, configs[0].dt, 3.0) for _ in configs]
    built = replay_many(configs, timelines, exact=True)
    monkeypatch.setattr(compiled, "AVAILABLE", False)
    monkeypatch.setattr(session_module, "_c_game_steps", None)
    batch = BatchGameSession(configs, exact=True)
    assert batch.compiled is None
    assert replay_many(configs, timelines, exact=True) == built
    assert session_module.GameSession(configs[0]).play(timelines[0]) == built[0]


@needs_build
def test_the_kernel_benchmark_runs():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parent.parent / "benchmarks" / "kernel_speed.py"
    spec = importlib.util.spec_from_file_location("kernel_speed", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    result = bench.measure(4, 0.2, 1)
    rates = result["switching"]["rates"]
    assert set(rates) == {"single", "exact lanes", "fast lanes", "exact one by one", "fast one by one"}
    assert all(r[0] > 0 for r in rates.values()) and bench.bounds(None) is None
