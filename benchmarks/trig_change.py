"""What the arm's own sine (armgame 0.3, ``armgame.physics.trig``) changed: games' outcomes and speed.

    python benchmarks/trig_change.py                  # 3,000 students' scripts and 300 bots' games: minutes
    python benchmarks/trig_change.py --students 300 --bots 30
    python benchmarks/trig_change.py --json

**Outcomes.** Until 0.2 the equations of motion took cos and sin of the joint angles from the C library
(``math``). Putting ``math.sin`` and ``math.cos`` back into the Python step (``TwoJointArm``'s component
closures, which 0.2's compiled loop equalled bit for bit) gives 0.2's arithmetic exactly; each game is
played under it (the students' scripts of ``class_speed.py``, seed 10 for the first 2,000 as in a class
and the game's own number after; the model and naive bots alternately, seeds 0 on, their keys chosen
under 0.2's physics as they were then) and its recorded timeline is replayed under 0.3's. Printed: how
many games have the same result (score, hits, resets, steps) and the largest final joint-state
difference. Exit status 1 if any result differs.

**Accuracy**: the largest error in ulps against mpmath, the arm's sine and the C library's.

**Speed of the sine itself**, one call and a thousand angles: the pure Python ``sin_cos`` (an install
without a C compiler), the compiled one (``_ctrig``), ``math.sin`` and ``math.cos``; numpy's
``sin_cos_array`` against ``numpy.sin`` and ``numpy.cos``; and a 60 s game in ``GameSession``'s Python
loop with the pure Python sine against the compiled one. Medians of repeats in this one run.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import random
import sys
import time
import timeit
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from class_speed import student_timeline

from armgame.game.bots import Autopilot, make_bot
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession
from armgame.physics import trig, twojoint
from armgame.physics.integrators import scheme

CLASS_SEED = 10


def libm_session(config: GameConfig) -> GameSession:
    """A session whose physics step is 0.2's: the C library's sin and cos in the same expressions."""
    session = GameSession(config, compiled=False)
    components = session.model._build_components(lambda x: (math.sin(x), math.cos(x)), math.cos, math.sin,
                                                 twojoint.largest_abs_float)
    session._physics_step = scheme(config.integrator).build(components)
    return session


def outcomes(students: int, bots: int) -> dict[str, object]:
    same, worst, differ = 0, 0.0, []
    games = []
    for i in range(students):
        config = GameConfig(seed=CLASS_SEED if i < 2000 else i, time_limit=60.0)
        timeline = student_timeline(random.Random(i), config.dt, 60.0)
        old = libm_session(config)
        games.append(("student", i, config, timeline, old.play(timeline), old.state))
    for i in range(bots):
        config = GameConfig(seed=i, time_limit=60.0)
        old = libm_session(config)
        Autopilot(old, make_bot(("model", "naive")[i % 2])).play()
        games.append(("bot", i, config, list(old.timeline), old.result(), old.state))
    for kind, i, config, timeline, result, state in games:
        new = GameSession(config)
        got = new.play(timeline)
        if got == result:
            same += 1
        else:
            differ.append(f"{kind} {i}: {result} then, {got} now")
        worst = max(worst, max(abs(a - b) for a, b in zip(new.state, state, strict=True)))
    return {"games": len(games), "same_result": same, "largest_state_difference": worst, "differ": differ[:10]}


def accuracy(count: int = 20_000) -> dict[str, float]:
    """The largest error in ulps, against mpmath, of the arm's sine and cosine and of the C library's, on
    ``count`` angles in [-100, 100] rad."""
    import mpmath

    rng = random.Random(5)
    worst = {"arm": 0.0, "c_library": 0.0}
    for _ in range(count):
        x = rng.uniform(-100.0, 100.0)
        with mpmath.workdps(40):
            true = (mpmath.sin(mpmath.mpf(x)), mpmath.cos(mpmath.mpf(x)))
        for name, got in (("arm", trig.sin_cos_python(x)), ("c_library", (math.sin(x), math.cos(x)))):
            for value, want in zip(got, true, strict=True):
                worst[name] = max(worst[name], float(abs(mpmath.mpf(value) - want)) / math.ulp(float(want)))
    return worst


def speeds(repeats: int) -> dict[str, float]:
    def per_call(f: object, arg: object, number: int) -> float:
        return min(timeit.repeat(lambda: f(arg), number=number, repeat=repeats)) / number * 1e6

    angles = np.random.default_rng(0).uniform(-3.0, 3.0, 1000)
    s, c = np.empty(1000), np.empty(1000)
    config = GameConfig(seed=CLASS_SEED, time_limit=60.0)
    timeline = student_timeline(random.Random(0), config.dt, 60.0)

    def game_ms() -> float:
        best = math.inf
        for _ in range(repeats):
            session = GameSession(config, compiled=False)
            start = time.perf_counter()
            session.play(timeline)
            best = min(best, time.perf_counter() - start)
        return best * 1e3

    out = {"python_sin_cos_us": per_call(trig.sin_cos_python, 0.8, 100_000),
           "compiled_sin_cos_us": per_call(trig.sin_cos, 0.8, 100_000),
           "math_sin_and_cos_us": per_call(lambda x: (math.sin(x), math.cos(x)), 0.8, 100_000),
           "numpy_own_1000_us": per_call(lambda x: trig.sin_cos_array(x, s, c), angles, 2000),
           "numpy_sin_and_cos_1000_us": per_call(lambda x: (np.sin(x, out=s), np.cos(x, out=c)), angles, 2000),
           "compiled_sine": trig.sin_cos is not trig.sin_cos_python}
    out["python_loop_game_ms"] = game_ms()
    built = twojoint.sin_cos, twojoint.trig_cos, twojoint.trig_sin
    twojoint.sin_cos, twojoint.trig_cos, twojoint.trig_sin = trig.sin_cos_python, trig.cos_python, trig.sin_python
    try:
        out["python_loop_game_pure_python_sine_ms"] = game_ms()
    finally:
        twojoint.sin_cos, twojoint.trig_cos, twojoint.trig_sin = built
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--students", type=int, default=3000, help="students' scripts (default 3000)")
    parser.add_argument("--bots", type=int, default=300, help="bots' games (default 300)")
    parser.add_argument("--repeats", type=int, default=5, help="repeats of each timing (default 5)")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)
    if not (0 <= args.students <= 100_000 and 0 <= args.bots <= 10_000 and 1 <= args.repeats <= 50):
        parser.error("need 0 <= --students <= 100000, 0 <= --bots <= 10000, 1 <= --repeats <= 50")
    report = {"machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
                         f"Python {platform.python_version()}, numpy {np.__version__}",
              "load_before": os.getloadavg()[0] if hasattr(os, "getloadavg") else None,
              "speeds": speeds(args.repeats), "ulps": accuracy(),
              "outcomes": outcomes(args.students, args.bots)}
    found = report["outcomes"]
    if args.json:
        print(json.dumps(report, indent=1))
    else:
        sp = report["speeds"]
        print(f"{report['machine']}; load {report['load_before']}")
        print(f"sin_cos of one angle: pure Python {sp['python_sin_cos_us']:.3f} us, compiled "
              f"{sp['compiled_sin_cos_us']:.3f} us (built here: {sp['compiled_sine']}), math.sin and math.cos "
              f"{sp['math_sin_and_cos_us']:.3f} us")
        print(f"1,000 angles: sin_cos_array {sp['numpy_own_1000_us']:.1f} us, numpy.sin and numpy.cos "
              f"{sp['numpy_sin_and_cos_1000_us']:.1f} us")
        print(f"largest error on 20,000 angles in [-100, 100] rad, against mpmath: the arm's sine "
              f"{report['ulps']['arm']:.2f} ulp, the C library's {report['ulps']['c_library']:.2f} ulp")
        print(f"a 60 s game in the Python loop: {sp['python_loop_game_ms']:.1f} ms with the sine as built here, "
              f"{sp['python_loop_game_pure_python_sine_ms']:.1f} ms with the pure Python one")
        print(f"{found['same_result']:,} of {found['games']:,} games recorded with 0.2's sine have the same result "
              f"with 0.3's; largest final joint-state difference {found['largest_state_difference']:.1e}")
        for line in found["differ"]:
            print("  differs:", line)
    return 0 if found["same_result"] == found["games"] else 1


if __name__ == "__main__":
    sys.exit(main())
