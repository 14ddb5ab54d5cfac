"""The batch kernel's speed in arm-steps per second on one core, beside the single compiled loop and the bound.

    python benchmarks/kernel_speed.py              # about a minute
    python benchmarks/kernel_speed.py --quick      # a few seconds
    python benchmarks/kernel_speed.py --json

An arm-step is one physics step of one game: its muscles, one RK4 step of the arm and the hand's
slack (``_ckernel.c``). The games are the standard game's (RK4 at 250 Hz), 60 s each, with their
targets out of reach so that only the kernel is timed (no hit goes back to Python). Timed in the
thread's CPU time (on a shared machine the wall clock counts other programs' turns on the core), in
turns within each repeat so that load from elsewhere falls on all of them:

* ``single``: ``_ckernel.game_steps``, the single session's compiled loop, one call a game;
* ``exact lanes`` / ``fast lanes``: ``_ckernel.run`` over all the games, the lanes of ``_cbatch.c``
  (games side by side in SIMD registers), exact (bit for bit the single session) and fast (the elbow's
  trig by angle addition, ``BatchGameSession(exact=False)``);
* ``exact one by one`` / ``fast one by one``: the same call, one game at a time (the loop before the lanes).

Two workloads: ``held`` (each game holds one set of keys the whole game: no commands, so the single
loop runs a game in one call, as the batch does) and ``switching`` (a key changes every 0.1-0.5 s, as
in a student's game: the batch applies the commands in C; the single loop is called once between
commands, as ``GameSession`` calls it).

The bound: both kernels are arithmetic (since version 0.3 the exact one's trig is the arm's own sine,
``arm_sin_cos``, made of multiplies and adds), bounded by the core's floating-point pipes. Where a C
compiler is found, a probe built on the spot measures them on this machine in the same run
(independent vector multiplies, adds and divides at the width the lanes use here: AVX-512's 8
doubles where the CPU has x86-64-v4, else AVX2's 4); each bound is its step's
operations (``EXACT_STEP_OPS``, ``FAST_STEP_OPS``) over those rates. The probe also times one sine after
another, each angle from the last (the latency the single loop's chain of stages waits on): the arm's
``arm_sin_cos`` against the C library's ``sincos``, which the single loop used before 0.3.
"""

from __future__ import annotations

import argparse
import ctypes
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import sysconfig
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from armgame.game.batch import BatchGameSession, compiled
from armgame.game.batch.schedule import MuscleEvents
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession

#: Floating-point operations of one fast arm-step (``step_lanes`` with ``fast``, the damped arm),
#: counted from the source: the torques and muscles (12 multiplies, 14 adds or subtracts), four accel
#: stages (13 and 12 each, one divide each), three stages' arguments (4 and 4 each), three series
#: turns of the elbow's trig and the next step's (14 and 10 each), the step's sums (8 and 16) and
#: the slack (2 and 4). Compares, selects and absolute values are left out (they use other ports or
#: are bit operations); so is the occasional full sincos (one step in 32) and the hand's check.
FAST_STEP_OPS = {"mul": 12 + 4 * 13 + 3 * 4 + 4 * 14 + 8 + 2, "add": 14 + 4 * 12 + 3 * 4 + 4 * 10 + 16 + 4,
                 "div": 4}
#: The arm's sine and cosine of one angle (``arm_sin_cos``, physics/_trig.h): the reduction (4 and 5),
#: the squares (2), sin's polynomial (8 and 5), cos's (9 and 10); its quadrant's selections are bit
#: operations, left out as above. The stage's b cos and b sin add 2 multiplies.
ARM_SIN_COS_OPS = {"mul": 4 + 2 + 8 + 9 + 2, "add": 5 + 5 + 10}
#: The exact step: the fast one with its four series turns of the elbow's trig replaced by four full ones.
EXACT_STEP_OPS = {"mul": FAST_STEP_OPS["mul"] - 4 * 14 + 4 * ARM_SIN_COS_OPS["mul"],
                  "add": FAST_STEP_OPS["add"] - 4 * 10 + 4 * ARM_SIN_COS_OPS["add"], "div": 4}

PROBE_C = r"""
#define _GNU_SOURCE
#include <math.h>
#include <time.h>
#include "_trig.h"
typedef double v4 __attribute__((vector_size(32)));
static double now(void) {
    struct timespec t; clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t); return t.tv_sec + 1e-9 * t.tv_nsec;
}
double chain_ns(long n, int own) {  /* one sine after another, each angle from the last: the latency */
    double x = 0.3, s, c, t = now();
    for (long i = 0; i < n; i++) {
        if (own)
            arm_sin_cos(x, &s, &c);
        else
            sincos(x, &s, &c);
        x = 1.0 + 0.5 * s * c + x * 1e-3;
    }
    t = now() - t;
    volatile double sink = x; (void)sink;
    return t / n * 1e9;
}
#if defined(__AVX512F__)
typedef double vec __attribute__((vector_size(64)));  /* the lanes' AVX-512 build */
#else
typedef double vec __attribute__((vector_size(32)));  /* their AVX2 build */
#endif
#define WIDTH (sizeof(vec) / sizeof(double))
double addmul_per_ns(long n) {  /* independent multiplies and adds at the lanes' width, 6 chains of each */
    const vec zero = {0}, f = zero + 1.0000001, g = zero + 1e-9;
    vec m0 = zero + 1, m1 = zero + 2, m2 = zero + 3, m3 = zero + 4, m4 = zero + 5, m5 = zero + 6;
    vec a0 = m0, a1 = m1, a2 = m2, a3 = m3, a4 = m4, a5 = m5;
    double t = now();
    for (long i = 0; i < n; i++) {
        m0 = m0 * f; m1 = m1 * f; m2 = m2 * f; m3 = m3 * f; m4 = m4 * f; m5 = m5 * f;
        a0 = a0 + g; a1 = a1 + g; a2 = a2 + g; a3 = a3 + g; a4 = a4 + g; a5 = a5 + g;
    }
    t = now() - t;
    volatile double sink = (m0 + m1 + m2 + m3 + m4 + m5 + a0 + a1 + a2 + a3 + a4 + a5)[0]; (void)sink;
    return 2.0 * 6 * WIDTH * n / (t * 1e9);
}
double div_per_ns(long n) {  /* independent divides at the lanes' width, 6 chains */
    const vec zero = {0}, c = zero + 1.5;
    vec x0 = zero + 1, x1 = zero + 1.1, x2 = zero + 1.2, x3 = zero + 1.3, x4 = zero + 1.4, x5 = zero + 1.5;
    double t = now();
    for (long i = 0; i < n; i++) {
        x0 = c / x0; x1 = c / x1; x2 = c / x2; x3 = c / x3; x4 = c / x4; x5 = c / x5;
    }
    t = now() - t;
    volatile double sink = (x0 + x1 + x2 + x3 + x4 + x5)[0]; (void)sink;
    return 6.0 * WIDTH * n / (t * 1e9);
}
double width(void) { return (double)WIDTH; }
"""


#: The CPU flags of x86-64-v4, the lanes' widest build (``LANES_CLONES`` in _clanes.c).
AVX512 = ("avx512f", "avx512bw", "avx512cd", "avx512dq", "avx512vl")


def probe() -> ctypes.CDLL | None:
    """The probe above, built with this Python's C compiler (the lanes' AVX2 where the CPU has it), or None."""
    cc = (sysconfig.get_config_var("CC") or "cc").split()[0]
    if shutil.which(cc) is None or platform.machine() not in ("x86_64", "AMD64"):
        return None
    folder = Path(tempfile.mkdtemp(prefix="armgame-probe-"))
    source, library = folder / "probe.c", folder / "probe.so"
    source.write_text(PROBE_C)
    flags = ["-O2", "-ffp-contract=off", "-fno-builtin-sin", "-fno-builtin-cos", "-shared", "-fPIC",
             f"-I{Path(__file__).resolve().parent.parent / 'armgame' / 'physics'}"]
    with open("/proc/cpuinfo") as f:
        cpu = f.read()
    if all(f" {flag}" in cpu for flag in AVX512):  # the lanes' x86-64-v4 build runs here
        flags += [f"-m{flag}" for flag in AVX512]
    elif " avx2" in cpu:
        flags.append("-mavx2")
    built = subprocess.run([cc, *flags, str(source), "-o", str(library), "-lm"], capture_output=True)
    if built.returncode:
        return None
    lib = ctypes.CDLL(str(library))
    for name in ("addmul_per_ns", "div_per_ns"):
        getattr(lib, name).restype = ctypes.c_double
        getattr(lib, name).argtypes = [ctypes.c_long]
    lib.width.restype = ctypes.c_double
    lib.chain_ns.restype = ctypes.c_double
    lib.chain_ns.argtypes = [ctypes.c_long, ctypes.c_int]
    return lib


def games(n: int, seconds: float, switching: bool) -> tuple[BatchGameSession, MuscleEvents, np.ndarray]:
    """``n`` standard games, their targets out of reach, their key commands, and their last steps."""
    batch = BatchGameSession([GameConfig(seed=10, time_limit=seconds)] * n, kernel="numpy")
    batch.target_x[:] = batch.target_y[:] = 100.0
    rng = np.random.default_rng(0)
    dt, total = batch.config.dt, int(batch.total_steps[0])
    rise, decay = batch.kernel_inputs.rise, batch.kernel_inputs.decay
    steps, flat, goal, rate = [], [], [], []
    for i in range(n):
        held = rng.random(4) < 0.5
        batch._goal[:, i] = held
        batch._rate[:, i] = np.where(held, rise, decay)
        t = 0
        while switching:
            t += int(rng.uniform(0.1, 0.5) / dt)
            if t >= total:
                break
            m = int(rng.integers(4))
            held[m] = not held[m]
            steps.append(t)
            flat.append(m * n + i)
            goal.append(1.0 if held[m] else 0.0)
            rate.append(rise[m] if held[m] else decay[m])
    events = MuscleEvents.by_game(n, np.array(steps, dtype=np.int64), np.array(flat, dtype=np.int64),
                                  np.array(goal), np.array(rate))
    return batch, events, np.full(n, total, dtype=np.int64)


def batch_runner(n: int, seconds: float, switching: bool, fast: bool, lanes: bool) -> Callable[[], float]:
    """Seconds for ``_ckernel.run`` to play the games from their start (a fresh copy each time)."""
    batch, events, halt = games(n, seconds, switching)
    kernel = compiled.CompiledKernel(batch.kernel_inputs, batch.arrays, batch._hit_test)
    start = [a.copy() for a in (batch._xs, batch._act, batch._goal, batch._rate, batch._slack)]

    def run() -> float:
        xs, act, goal, rate, slack = (a.copy() for a in start)
        steps, cursor, flags = np.zeros(n, dtype=np.int64), events.cursor.copy(), np.zeros(n, dtype=np.uint8)
        t = time.thread_time()
        flagged = compiled._ckernel.run(kernel.params, kernel.mode, fast, n, xs, act, goal, rate, slack,
                                        batch.target_x, batch.target_y, steps, halt, cursor, events.end,
                                        events.step, events.muscle, events.goal, events.rate, flags,
                                        None, lanes)
        t = time.thread_time() - t
        assert flagged == 0 and (steps == halt).all()
        return t

    return run


def single_runner(n: int, seconds: float, switching: bool) -> Callable[[], float]:
    """Seconds for ``_ckernel.game_steps`` to play the same games one after another, as ``GameSession`` calls it."""
    batch, events, halt = games(n, seconds, switching)
    game = GameSession(batch.config)
    params, mode, _ = game._compiled
    game_steps = compiled._ckernel.game_steps
    x0 = batch._x[:, 0].tolist()
    plans = []
    for i in range(n):
        lo, hi = int(events.cursor[i]), int(events.end[i])
        plans.append((batch._goal[:, i].tolist(), batch._rate[:, i].tolist(), events.step[lo:hi].tolist(),
                      events.muscle[lo:hi].tolist(), events.goal[lo:hi].tolist(), events.rate[lo:hi].tolist()))
    total = int(halt[0])

    def run() -> float:
        t = time.thread_time()
        for goal, rate, ev_step, ev_muscle, ev_goal, ev_rate in plans:
            g, r = goal[:], rate[:]
            x, a, s = x0, [0.0] * 4, 0
            for e in range(len(ev_step) + 1):
                upto = ev_step[e] if e < len(ev_step) else total
                if upto > s:
                    out = game_steps(params, mode, upto - s, *x, *a, *g, *r, 100.0, 100.0, 0.0004)
                    x, a, s = out[2:6], out[10:14], s + out[0]
                if e < len(ev_step):
                    g[ev_muscle[e]], r[ev_muscle[e]] = ev_goal[e], ev_rate[e]
        return time.thread_time() - t

    return run


def measure(n: int, seconds: float, repeats: int) -> dict[str, object]:
    steps = n * round(seconds * 250)
    out: dict[str, object] = {}
    for workload in ("held", "switching"):
        switching = workload == "switching"
        runners = {"single": single_runner(max(1, n // 4), seconds, switching),
                   "exact lanes": batch_runner(n, seconds, switching, False, True),
                   "fast lanes": batch_runner(n, seconds, switching, True, True),
                   "exact one by one": batch_runner(n, seconds, switching, False, False),
                   "fast one by one": batch_runner(n, seconds, switching, True, False)}
        rates: dict[str, list[float]] = {k: [] for k in runners}
        for _ in range(repeats):
            for name, run in runners.items():
                work = steps // 4 if name == "single" and n >= 4 else steps
                rates[name].append(work / run())
        ratios = {f"{k} / single": [a / b for a, b in zip(v, rates["single"], strict=True)]
                  for k, v in rates.items() if k != "single"}
        out[workload] = {"rates": rates, "ratios": ratios}
    return out


def bounds(lib: ctypes.CDLL | None) -> dict[str, float] | None:
    if lib is None:
        return None
    addmul = max(lib.addmul_per_ns(5_000_000) for _ in range(3))
    div = max(lib.div_per_ns(2_000_000) for _ in range(3))

    def bound(ops: dict[str, int]) -> float:
        return 1e9 / max((ops["mul"] + ops["add"]) / addmul, ops["div"] / div)

    return {"width": lib.width(), "addmul_per_ns": addmul, "div_per_ns": div,
            "exact_bound_per_s": bound(EXACT_STEP_OPS),
            "fast_bound_per_s": bound(FAST_STEP_OPS),
            "arm_sin_cos_chain_ns": min(lib.chain_ns(2_000_000, 1) for _ in range(3)),
            "libm_sincos_chain_ns": min(lib.chain_ns(2_000_000, 0) for _ in range(3))}


def spread(values: list[float]) -> str:
    return f"{statistics.median(values) / 1e6:6.1f} M [{min(values) / 1e6:.1f}-{max(values) / 1e6:.1f}]"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer games, shorter games, fewer repeats")
    parser.add_argument("--games", type=int, default=None, help="games in the batch (default 1024; quick 256)")
    parser.add_argument("--repeats", type=int, default=None, help="repeats (default 5; quick 3)")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)
    if not compiled.AVAILABLE:
        print("the compiled kernel is not built here: nothing to measure", file=sys.stderr)
        return 1
    n = args.games or (256 if args.quick else 1024)
    seconds = 20.0 if args.quick else 60.0
    repeats = args.repeats or (3 if args.quick else 5)
    load = os.getloadavg()[0]
    result = {"games": n, "seconds": seconds, "repeats": repeats, "load_before": load,
              "machine": f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
              "bounds": bounds(probe()), **measure(n, seconds, repeats), "load_after": os.getloadavg()[0]}
    if args.json:
        print(json.dumps(result))
        return 0
    print(f"{n} games of {seconds:g} s, {repeats} repeats taking turns; {result['machine']}; "
          f"load {load:.2f} before, {result['load_after']:.2f} after")
    for workload in ("held", "switching"):
        part = result[workload]
        print(f"{workload} keys: arm-steps per second, median [min-max]; ratio to the single loop within each repeat")
        for name, values in part["rates"].items():
            ratio = part["ratios"].get(f"{name} / single")
            extra = "" if ratio is None else (f"  {statistics.median(ratio):5.2f}x "
                                              f"[{min(ratio):.2f}-{max(ratio):.2f}]")
            print(f"  {name:>17}: {spread(values)}{extra}")
    b = result["bounds"]
    if b is None:
        print("bound: no C compiler here to build the probe")
    else:
        held = result["held"]["rates"]
        exact, fast = (statistics.median(held[k]) for k in ("exact lanes", "fast lanes"))
        print(f"bound, measured here at {b['width']:.0f} doubles a vector: {b['addmul_per_ns']:.1f} multiplies and "
              f"adds per ns, {b['div_per_ns']:.2f} divides per ns -> exact <= {b['exact_bound_per_s'] / 1e6:.0f} M "
              f"arm-steps/s (lanes at {exact / b['exact_bound_per_s']:.0%}), fast <= "
              f"{b['fast_bound_per_s'] / 1e6:.0f} M (lanes at {fast / b['fast_bound_per_s']:.0%})")
        print(f"one sine after another (the single loop's chain): the arm's {b['arm_sin_cos_chain_ns']:.1f} ns, "
              f"the C library's sincos {b['libm_sincos_chain_ns']:.1f} ns")
    return 0


if __name__ == "__main__":
    sys.exit(main())
