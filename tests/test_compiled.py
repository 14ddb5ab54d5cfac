"""The compiled loops' boundary: what they refuse, when they are used, and that they are exact.

The batch kernel's results are tested against the single session in tests/test_batch.py (both
kernels). The single session's own compiled loop (``_ckernel.game_steps``) is held here to its
Python loop, ``GameSession(compiled=False)``, with ``==``.
"""

import math
import os
import random
import struct
import types
from dataclasses import replace

import numpy as np
import pytest

from armgame.game import session as session_module
from armgame.game.batch import BatchGameSession, compiled
from armgame.game.muscles import MuscleSpec
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession, InputEvent, NonFiniteStateError

needs_build = pytest.mark.skipif(not (compiled.AVAILABLE or os.environ.get("ARMGAME_REQUIRE_COMPILED")),
                                 reason="the compiled kernel is not built here")


def arrays(n: int = 3) -> dict:
    """A valid argument set for ``_ckernel.run``, as ``CompiledKernel`` passes it."""
    batch = BatchGameSession([GameConfig(seed=s, time_limit=1.0) for s in range(n)], kernel="numpy")
    kernel = compiled.CompiledKernel(batch.kernel_inputs, batch.arrays, batch._hit_test)
    events = compiled.MuscleEvents.by_game(n, np.array([0, 5]), np.array([0, n + 1]), np.array([1.0, 1.0]),
                                           np.array([0.1, 0.1]))
    return {"params": kernel.params, "mode": kernel.mode, "fast": False, "n": n, "x": batch._xs,
            "act": batch._act, "goal": batch._goal, "rate": batch._rate, "slack": batch._slack,
            "tx": batch.target_x, "ty": batch.target_y, "steps": batch.steps,
            "halt": np.full(n, 50, dtype=np.int64), "cursor": events.cursor, "ev_end": events.end,
            "ev_step": events.step, "ev_muscle": events.muscle, "ev_goal": events.goal, "ev_rate": events.rate,
            "flags": np.zeros(n, dtype=np.uint8), "trig": None, "lanes": True}


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
    # Sizes n * 8 that wrap to 0 divided by zero (SIGFPE: the process gone, no message at all).
    ({"n": 2**61}, "at most"),
    ({"n": 2**62}, "at most"),
    ({"n": 2**63 - 1}, "at most"),
    # Counts a game cannot have (it is at most 24 h long: 21,600,000 steps of 4 ms) ran for as long as anyone
    # waited; NaN or infinite params stepped every game to NaN.
    ({"halt": np.full(3, 2**62, dtype=np.int64)}, r"game 0: steps 0, halt 4611686018427387904: expected 0 to "
                                                  r"21600001 \(86400 s at dt 0\.004\)"),
    ({"halt": np.array([50, 50, -1], dtype=np.int64)}, "game 2: steps 0, halt -1"),
    ({"steps": np.array([0, -2**62, 0], dtype=np.int64)}, "game 1: steps -4611686018427387904"),
    ({"params": np.where(np.arange(26) == 0, np.nan, 1.0)}, "params dt is not finite"),
    ({"params": np.where(np.arange(26) == 3, np.inf, 1.0)}, "params b is not finite"),
    ({"params": np.where(np.arange(26) == 0, -0.004, 1.0)}, "params dt must be positive"),
    ({"ev_goal": np.array([1.0, np.nan])}, "event 1: its goal or rate is not finite"),
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


# ------------------------------------------------------------- the single session's compiled loop
needs_loop = pytest.mark.skipif(not (session_module._c_game_steps or os.environ.get("ARMGAME_REQUIRE_COMPILED")),
                                reason="the compiled loop is not built here")

GAME = GameConfig()
#: The params bytes of a game with dt 4 ms and nothing else: enough for a call's checks.
DT_ONLY = struct.pack("=26d", 0.004, *[0.0] * 25)
#: One arm per accel the loop must copy (TwoJointArm._build_components): damped (the game's), neither
#: damped nor under gravity, and under gravity with damping (a weak one: the game's muscles cannot
#: lift the arm against 9.81 m/s^2 to any target).
ARMS = {"damped": GAME.arm, "unforced": GAME.arm.replace(damping1=0.0, damping2=0.0),
        "gravity": GAME.arm.replace(gravity=0.5)}


def keys_resets_and_levels(rng: random.Random, config: GameConfig) -> list[tuple[int, object]]:
    """(step, input) pairs: muscle keys every 0.05-0.4 s, resets, tab and a few muscle-level commands."""
    inputs, t = [], 0.0
    while (t := t + rng.uniform(0.05, 0.4)) < config.time_limit:
        step = round(t / config.dt)
        r = rng.random()
        if r < 0.05:
            inputs.append((step, ("space", "down")))
        elif r < 0.07:
            inputs.append((step, ("tab", "down")))
        elif r < 0.15:
            inputs.append((step, [rng.choice((0.0, 0.3, 1.0)) for _ in range(4)]))
        else:
            inputs.append((step, (rng.choice("dfjk"), rng.choice(("down", "up")))))
    return inputs


def run_both(config: GameConfig, inputs: list[tuple[int, object]]) -> tuple[GameSession, GameSession]:
    """The same inputs into a compiled and a Python session, compared after every call."""
    fast, slow = GameSession(config), GameSession(config, compiled=False)
    assert fast._compiled is not None and slow._compiled is None
    for step, given in [*inputs, (config.total_steps, None)]:
        for s in (fast, slow):
            s.advance(step - s.steps)
            if isinstance(given, tuple):
                s.key_event(*given)
            elif given is not None:
                s.set_muscle_levels(given)
        assert fast.state == slow.state and fast.previous_state == slow.previous_state
        assert fast.muscles.activation == slow.muscles.activation and fast.steps == slow.steps
    assert fast.rules.board == slow.rules.board and fast.rules.target == slow.rules.target
    assert fast.result() == slow.result() and fast.timeline == slow.timeline
    return fast, slow


@needs_loop
@pytest.mark.parametrize("arm", list(ARMS))
def test_the_compiled_loop_is_the_python_loop_bit_for_bit(arm):
    """Every state, activation, hit time and target equal with ``==``, for each accel, over whole games."""
    rng = random.Random(arm)
    hits = 0
    for seed in range(3):
        config = GameConfig(seed=seed, time_limit=20.0, target_radius=0.2, arm=ARMS[arm])
        fast, _ = run_both(config, keys_resets_and_levels(rng, config))
        hits += fast.rules.board.hits
    assert hits >= 3  # the hit path ran, not just the steps


@needs_loop
def test_a_bots_game_steps_one_period_at_a_time_as_the_python_loop_does():
    from armgame.game.bots import Autopilot, make_bot

    config = GameConfig(time_limit=15.0)
    fast, slow = GameSession(config), GameSession(config, compiled=False)
    assert Autopilot(fast, make_bot("model")).play() == Autopilot(slow, make_bot("model")).play()
    assert fast.state == slow.state and fast.rules.board.hit_times == slow.rules.board.hit_times
    assert fast.rules.board.hits >= 5


@needs_loop
@pytest.mark.parametrize("inside", [True, False])
def test_a_hit_on_the_knife_edge_is_decided_by_the_python_loops_own_test(inside):
    """A target whose edge passes within an ulp or so of where the hand will be: the loop's looser
    "near" stops there and the session's own ``**`` test decides, as the Python loop does."""
    from test_batch import KNIFE_SCRIPT, knife_edge_target

    config = GameConfig(time_limit=1.0)
    edge = knife_edge_target(config, inside)
    results = []
    for compiled_loop in (True, False):
        single = GameSession(config, compiled=compiled_loop)
        single.rules.target = edge
        results.append(single.play(KNIFE_SCRIPT))
        assert (60 * config.dt in single.rules.board.hit_times) == inside
    assert results[0] == results[1]


@needs_loop
def test_a_state_gone_non_finite_stops_in_one_line_as_the_python_loop_does():
    muscles = tuple(MuscleSpec(f"m{i}", k, (50.0, -50.0), 0.02, 0.02) for i, k in enumerate("dfjk"))
    wild = GameConfig(dt=0.02, muscles=muscles, arm=GAME.arm.replace(m1=0.01, m2=0.01, i1=1e-5, i2=1e-5))
    messages = []
    for compiled_loop in (True, False):
        single = GameSession(wild, compiled=compiled_loop)
        with pytest.raises(NonFiniteStateError) as info:
            single.play([InputEvent(0, "d", "down")])
        messages.append(str(info.value))
    assert messages[0] == messages[1] and "\n" not in messages[0]


@needs_loop
def test_the_compiled_loop_runs_rk4_and_steps_it_is_given_run_in_python():
    assert GameSession(GAME)._compiled is not None
    for integrator in ("euler", "symplectic-euler", "midpoint", "gauss4"):
        assert GameSession(replace(GAME, integrator=integrator))._compiled is None
    # A step swapped in (as tests/test_batch.py does to perturb round-off) is the one that runs.
    session = GameSession(GAME)
    calls = []
    real = session._physics_step

    def counted(*args):
        calls.append(1)
        return real(*args)

    session._physics_step = counted
    session.advance(10)
    assert len(calls) == 10


@needs_loop
@pytest.mark.parametrize(("args", "message"), [
    ((), "22 arguments"),
    ((b"short", 1, 5, *[0.0] * 19), "params"),
    (("not bytes", 1, 5, *[0.0] * 19), "params"),
    ((bytes(26 * 8), 3, 5, *[0.0] * 19), "mode 3"),
    ((DT_ONLY, 1, -1, *[0.0] * 19), "steps >= 0"),
    ((bytes(26 * 8), 1, 5, "q1", *[0.0] * 18), "must be real number"),
    # A count past the longest game at this dt (24 h: 21,600,001 steps of 4 ms) ran for as long as anyone
    # waited; a NaN anywhere gave NaN back.
    ((DT_ONLY, 1, 2**62, *[0.0] * 19), r"game_steps: 4611686018427387904 steps: expected steps >= 0 and at most "
                                       r"21600001 \(86400 s at dt 0\.004\)"),
    ((DT_ONLY, 1, 21_600_002, *[0.0] * 19), "at most 21600001"),
    ((bytes(26 * 8), 1, 5, *[0.0] * 19), "params dt must be positive"),
    ((DT_ONLY[:8] + struct.pack("=d", math.nan) + DT_ONLY[16:], 1, 5, *[0.0] * 19), "params h is not finite"),
    ((DT_ONLY, 1, 5, math.nan, *[0.0] * 18), "game_steps: q1 is not finite"),
    ((DT_ONLY, 1, 5, *[0.0] * 16, 1.0, math.inf, 0.0), "game_steps: ty is not finite"),
    ((DT_ONLY, 1, 5, *[0.0] * 18, -math.inf), "game_steps: rr is not finite"),
])
def test_game_steps_refuses_bad_arguments_before_any_step(args, message):
    with pytest.raises((TypeError, ValueError), match=message):
        session_module._c_game_steps(*args)


@needs_loop
@pytest.mark.parametrize("arm", list(ARMS))
def test_the_compiled_rk4_step_is_the_python_step_bit_for_bit(arm):
    """``_ckernel.rk4_step`` (the lab's unloaded step) against ``Integrator("rk4")``'s, with ``==``."""
    session = GameSession(GameConfig(arm=ARMS[arm]))
    fast, slow = session.unloaded_step(), session._physics_step
    assert fast is not slow
    rng = random.Random(arm)
    for _ in range(2000):
        x = (rng.uniform(-4, 4), rng.uniform(-4, 4), rng.uniform(-30, 30), rng.uniform(-30, 30),
             rng.uniform(-3, 3), rng.uniform(-3, 3), rng.choice((0.001, 0.004, 0.02)))
        assert fast(*x) == slow(*x)


@needs_loop
def test_a_lab_run_with_the_compiled_step_is_the_python_loops_bit_for_bit():
    """A curl field (loaded steps in Python) between unloaded blocks (the compiled step), the adapting bot."""
    from armgame.game.bots import Autopilot
    from armgame.lab.bots import make_lab_bot
    from armgame.lab.perturbations import Perturbation
    from armgame.lab.presets import CURL_B
    from armgame.lab.protocol import Block, Protocol
    from armgame.lab.session import LabSession, lab_config

    kinds = (Perturbation(), Perturbation.make("curl", b=CURL_B), Perturbation())
    protocol = Protocol("short", tuple(Block(n, 4, k) for n, k in zip(("baseline", "exposure", "washout"), kinds,
                                                                          strict=True)))
    runs = []
    for compiled_loop in (True, False):
        session = LabSession(lab_config(protocol, 3), protocol, compiled=compiled_loop)
        Autopilot(session, make_lab_bot("adaptive")).play()
        runs.append(session)
    fast, slow = runs
    assert fast.unloaded_step() is not slow.unloaded_step()
    assert fast.trial_records() == slow.trial_records() and fast.state == slow.state
    assert all(a.xs == b.xs and a.ys == b.ys for a, b in zip(fast.outcomes, slow.outcomes, strict=True))
    assert len(fast.outcomes) == 12


@needs_loop
@pytest.mark.parametrize(("args", "message"), [
    ((), "9 arguments"),
    ((b"short", 1, *[0.0] * 7), "params"),
    ((bytes(26 * 8), -1, *[0.0] * 7), "mode -1"),
    ((bytes(26 * 8), 1, "q1", *[0.0] * 6), "must be real number"),
    ((bytes(26 * 8), 1, math.nan, *[0.0] * 6), "rk4_step: q1 is not finite"),
    ((bytes(26 * 8), 1, *[0.0] * 6, math.inf), "rk4_step: dt is not finite"),
    ((struct.pack("=26d", math.nan, *[0.0] * 25), 1, *[0.0] * 6, 0.004), "rk4_step: params dt is not finite"),
])
def test_rk4_step_refuses_bad_arguments(args, message):
    with pytest.raises((TypeError, ValueError), match=message):
        session_module._c_rk4_step(*args)


@needs_loop
@pytest.mark.parametrize("arm", list(ARMS))
def test_rk4_run_is_the_python_step_bit_for_bit_and_stops_at_a_blow_up(arm):
    """``_ckernel.rk4_run`` (the benchmark's compiled rows) against ``Integrator("rk4")``'s steps, with ``==``:
    a torque row per step, the last row held, every second state kept."""
    session = GameSession(GameConfig(arm=ARMS[arm]))
    params, mode, step = session._compiled
    buffer = np.frombuffer(params, dtype=float)
    rng = random.Random(arm)
    torques = np.array([(rng.uniform(-2, 2), rng.uniform(-2, 2)) for _ in range(150)])
    start = (0.3, 1.2, 2.0, -1.0)
    x, states = np.array(start), np.empty((101, 4))
    assert session_module._ckernel.rk4_run(buffer, mode, 0.004, x, torques, 200, states, 2, 1e4) == 200
    q = start
    expected = [q]
    for i in range(200):
        q = step(*q, *torques[min(i, 149)], 0.004)
        if i % 2 == 1:
            expected.append(q)
    assert [tuple(s) for s in states.tolist()] == expected and tuple(x.tolist()) == q
    # Past the speed limit it stops after the step that crossed it, as the benchmark's Python run does.
    x = np.array(start)
    assert session_module._ckernel.rk4_run(buffer, mode, 0.004, x, torques, 200, np.empty((0, 4)), 1, 1.5) == 1


@needs_loop
@pytest.mark.parametrize(("change", "message"), [
    ({"dt": 0.0}, "finite dt > 0"),
    ({"every": 0}, "every >= 1"),
    ({"torques": np.empty((0, 2))}, "a torque row"),
    ({"torques": np.full((1, 2), math.nan)}, "a torque is not finite"),
    ({"x": np.array([math.inf, 0.0, 0.0, 0.0])}, "x is not finite"),
    ({"steps": 10**12}, "24 h"),
    ({"x": np.zeros(3)}, "x: 24 bytes, expected 32"),
])
def test_rk4_run_refuses_bad_arguments_before_any_step(change, message):
    session = GameSession(GameConfig())
    args = {"params": np.frombuffer(session._compiled[0], dtype=float), "mode": session._compiled[1], "dt": 0.004,
            "x": np.zeros(4), "torques": np.zeros((1, 2)), "steps": 10, "states": np.empty((0, 4)), "every": 1,
            "limit": 1e4} | change
    with pytest.raises(ValueError, match=message):
        session_module._ckernel.rk4_run(*args.values())


def test_every_compiled_module_is_loaded_by_one_helper_that_refuses_another_convention():
    """``armgame._native.load``: a module not built, or built from another version of its ``.c`` file, is
    None (the Python twin runs); one that speaks the convention asked is handed over."""
    from armgame import _native

    assert _native.load("armgame.game._no_such_module", 1) is None
    assert _native.load("armgame.game._ckernel", compiled.KERNEL_VERSION + 1, PARAMS=26) is None
    assert not _native.speaks(types.SimpleNamespace(VERSION=1), 1, PARAMS=26)
    assert _native.speaks(types.SimpleNamespace(VERSION=1, PARAMS=26), 1, PARAMS=26)
    assert _native.speaks(types.SimpleNamespace(), None)
    if compiled.AVAILABLE:
        assert _native.load("armgame.game._ckernel", compiled.KERNEL_VERSION, PARAMS=26) is compiled._ckernel
