"""The compiled kernel's boundary: what it refuses, and when it is used.

Its results are tested against the single session in tests/test_batch.py (both kernels).
"""

import os
import random
import types

import numpy as np
import pytest

from armgame.game.batch import BatchGameSession, compiled
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession, InputEvent

needs_build = pytest.mark.skipif(not (compiled.AVAILABLE or os.environ.get("ARMGAME_REQUIRE_COMPILED")),
                                 reason="the compiled kernel is not built here")


def arrays(n: int = 3) -> dict:
    """A valid argument set for ``_ckernel.run``, as ``CompiledKernel`` passes it."""
    batch = BatchGameSession([GameConfig(seed=s, time_limit=1.0) for s in range(n)], kernel="numpy")
    kernel = compiled.CompiledKernel(batch)
    events = compiled.MuscleEvents.by_game(n, np.array([0, 5]), np.array([0, n + 1]), np.array([1.0, 1.0]),
                                           np.array([0.1, 0.1]))
    return {"params": kernel.params, "mode": kernel.mode, "fast": False, "n": n, "x": batch._xs,
            "act": batch._act, "goal": batch._goal, "rate": batch._rate, "slack": batch._slack,
            "tx": batch.target_x, "ty": batch.target_y, "steps": batch.steps,
            "halt": np.full(n, 50, dtype=np.int64), "cursor": events.cursor, "ev_end": events.end,
            "ev_step": events.step, "ev_muscle": events.muscle, "ev_goal": events.goal, "ev_rate": events.rate,
            "flags": np.zeros(n, dtype=np.uint8)}


def call(args: dict) -> int:
    return compiled._ckernel.run(*args.values())


@needs_build
def test_a_valid_call_steps_the_games_to_their_halt_and_applies_their_events():
    args = arrays()
    assert call(args) == 0
    assert args["steps"].tolist() == [50, 50, 50]
    assert args["cursor"].tolist() == args["ev_end"].tolist()
    assert args["goal"][0, 0] == 1.0 and args["goal"][1, 1] == 1.0 and args["act"][1, 1] > 0.0
    assert args["act"][1, 0] == 0.0  # game 0's second muscle was never commanded


@needs_build
@pytest.mark.parametrize(("change", "message"), [
    ({"act": np.zeros((4, 2))}, "act"),
    ({"x": np.zeros((3, 3))}, "x"),
    ({"steps": np.zeros(2, dtype=np.int64)}, "steps"),
    ({"params": np.zeros(5)}, "params"),
    ({"ev_muscle": np.array([0, 7], dtype=np.int64)}, "muscle 7"),
    ({"ev_goal": np.zeros(3)}, "ev_goal"),
    ({"cursor": np.array([0, 5, 0], dtype=np.int64)}, "events"),
    ({"ev_end": np.array([1, 2, 9], dtype=np.int64)}, "events"),
    ({"flags": np.zeros(2, dtype=np.uint8)}, "flags"),
    ({"mode": 3}, "mode"),
    ({"n": 0}, "at least one game"),
])
def test_bad_arguments_are_refused_before_any_step(change, message):
    args = arrays()
    state = args["x"].copy()
    args.update(change)
    with pytest.raises(ValueError, match=message):
        call(args)
    if "x" not in change:
        assert np.array_equal(args["x"], state)


@needs_build
def test_read_only_or_strided_arrays_are_refused():
    args = arrays()
    args["slack"] = args["slack"].copy()
    args["slack"].flags.writeable = False
    with pytest.raises((BufferError, ValueError, TypeError)):
        call(args)
    args = arrays()
    args["act"] = np.zeros((4, 6))[:, ::2]
    with pytest.raises((BufferError, ValueError, TypeError)):
        call(args)


def test_a_stale_build_is_not_used():
    assert not compiled.speaks_our_convention(types.SimpleNamespace(VERSION=compiled.KERNEL_VERSION - 1,
                                                                     PARAMS=25))
    assert not compiled.speaks_our_convention(types.SimpleNamespace())
    if compiled.AVAILABLE:
        assert compiled.speaks_our_convention(compiled._ckernel)


def test_asking_for_the_compiled_kernel_where_it_is_not_built_says_so(monkeypatch):
    monkeypatch.setattr(compiled, "AVAILABLE", False)
    with pytest.raises(ValueError, match="not built"):
        BatchGameSession([GameConfig()], kernel="compiled")
    assert BatchGameSession([GameConfig()]).compiled is None  # the default falls back to numpy
    with pytest.raises(ValueError, match="kernel 'fast'"):
        BatchGameSession([GameConfig()], kernel="fast")


@needs_build
def test_the_compiled_kernel_is_the_default_for_rk4_only():
    assert BatchGameSession([GameConfig()]).compiled is not None
    assert BatchGameSession([GameConfig(integrator="euler")], kernel="compiled").compiled is None
    assert BatchGameSession([GameConfig()], kernel="numpy").compiled is None


@needs_build
def test_a_batch_of_many_games_equals_the_numpy_kernel_and_the_single_session_bit_for_bit():
    """More games than lanes of anything, uneven lengths, a class-sized slice of student keys."""
    rng = random.Random(5)
    configs = [GameConfig(seed=s, time_limit=rng.choice([1.0, 2.5, 4.0]), target_radius=0.15) for s in range(40)]
    timelines = []
    for c in configs:
        events, t = [], 0.0
        while (t := t + rng.uniform(0.05, 0.4)) < c.time_limit:
            events.append(InputEvent(round(t / c.dt), rng.choice("dfjk"), rng.choice(("down", "up"))))
            if rng.random() < 0.05:
                events.append(InputEvent(round(t / c.dt), "space", "down"))
        timelines.append(events)
    fast, slow = BatchGameSession(configs), BatchGameSession(configs, kernel="numpy")
    results = fast.play(timelines)
    assert results == slow.play(timelines)
    assert np.array_equal(fast._x, slow._x) and np.array_equal(fast._act, slow._act)
    for i in (0, 17, 39):
        single = GameSession(configs[i])
        assert single.play(timelines[i]) == results[i]
        assert fast.state(i) == single.state
    assert sum(r.hits for r in results) >= 5 and sum(r.resets for r in results) > 0  # hits and resets ran
