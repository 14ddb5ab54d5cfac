"""The compiled loops in the benchmark: what the game runs, timed as it runs.

The game steps its arm in C (``_ckernel.game_steps``: muscles, RK4 and the hand's hit test in one
loop), not through the Python step the table's ``armgame`` rows time. So the table gets rows of
family ``compiled``: RK4 in ``_ckernel.rk4_run``, the same operations as the Python step (its
states equal the ``rk4`` rows' bit for bit, so its errors are theirs) under the case's torques, one
call per run; and the speed bars time ``game_steps`` itself, muscles and hit tests included. RK4 is
the only scheme compiled (the game's and ``simulate``'s default); an install without a C compiler
has no such rows and says so.
"""

from __future__ import annotations

import math
import statistics
import struct
import time
from collections.abc import Callable

import numpy as np

from ..game.session import compiled_kernel, kernel_mode, kernel_params
from ..physics.params import TwoJointParams
from ..physics.twojoint import TwoJointArm
from .measure import (
    BLOWUP_SPEED,
    ENERGY_SAMPLE,
    ERROR_WINDOW,
    Case,
    Row,
    energy_drift,
    hand_error,
    step_label,
    step_torques,
)

#: The game's C module (None: not built here), loaded as the game loads it.
_ckernel = compiled_kernel()

#: The compiled schemes (the scheme each runs, as the table names it).
METHODS = {"rk4": "rk4 (compiled)"}
#: A timed sample lasts at least this long (a compiled run of 2 s is some 50 us: too short to time once).
MIN_SAMPLE = 2e-3  # s


def available() -> bool:
    return _ckernel is not None


def _params(model: TwoJointArm, dt: float) -> tuple[np.ndarray, int]:
    return np.array(kernel_params(model, dt, (0.0,) * 4, (0.0,) * 4), dtype=float), kernel_mode(model.params)


def runner(model: TwoJointArm, dt: float, start: tuple[float, ...], torques: np.ndarray,
           steps: int) -> Callable[[np.ndarray], int]:
    """A call that runs ``steps`` RK4 steps from ``start`` in C, writing every state into its argument
    (rows of 4; an empty one for a timed run) and returning the steps run (fewer after a blow-up)."""
    params, mode = _params(model, dt)
    torques = np.ascontiguousarray(torques, dtype=float).reshape(-1, 2)
    x0 = np.array(start, dtype=float)
    x = np.empty(4)
    run = _ckernel.rk4_run

    def go(states: np.ndarray, every: int = 1) -> int:
        x[:] = x0
        return run(params, mode, dt, x, torques, steps, states, every, BLOWUP_SPEED)

    return go


def _sane(row: np.ndarray) -> bool:
    return bool(np.all(np.isfinite(row)) and abs(row[2]) < BLOWUP_SPEED and abs(row[3]) < BLOWUP_SPEED)


def timed_run(case: Case, dt: float) -> Callable[[], None]:
    """One compiled run over the error window, as ``measure.scheme_run`` times the Python step."""
    steps = round(ERROR_WINDOW / dt)
    go = runner(case.model, dt, case.scene.initial, np.array(step_torques(case.segments, dt, steps)), steps)
    none = np.empty((0, 4))
    return lambda: go(none)  # type: ignore[func-returns-value]


def seconds_per_run(run: Callable[[], object], repeats: int) -> float:
    """The median over ``repeats`` samples, each of enough runs to last ``MIN_SAMPLE``."""
    t0 = time.perf_counter()
    run()
    once = max(time.perf_counter() - t0, 1e-7)
    inner = max(1, math.ceil(MIN_SAMPLE / once))
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(inner):
            run()
        times.append((time.perf_counter() - t0) / inner)
    return statistics.median(times)


def measure_compiled(case: Case, dt: float, repeats: int) -> Row:
    """``measure.measure_scheme``'s row for the compiled RK4: the same metrics, the loop in C."""
    steps = round(ERROR_WINDOW / dt)
    go = runner(case.model, dt, case.scene.initial, np.array(step_torques(case.segments, dt, steps)), steps)
    states = np.empty((steps + 1, 4))
    ran = go(states)
    ok = ran == steps and _sane(states[-1])
    error = hand_error(case, np.arange(steps + 1) * dt, states) if ok else math.inf
    with np.errstate(all="ignore"):
        elapsed = seconds_per_run(timed_run(case, dt), repeats if ok else 1)
    drift, energy_ok = _energy(case, dt) if ok else (math.inf, False)
    return Row(case.name, METHODS["rk4"], "compiled", step_label(dt), dt, None, elapsed / ERROR_WINDOW, 4 / dt,
               error, drift, not (ok and energy_ok), note="C loop, one call a run")


def _energy(case: Case, dt: float) -> tuple[float, bool]:
    steps = round(case.energy_window / dt)
    every = max(1, round(ENERGY_SAMPLE / dt))
    go = runner(case.model, dt, case.free_state, np.zeros(2), steps)
    samples = np.empty((steps // every + 1, 4))
    ran = go(samples, every)
    if ran < steps or not _sane(samples[-1]):
        return math.inf, False
    return energy_drift(case, np.arange(len(samples)) * every * dt, samples), True


def game_loop(params: TwoJointParams, dt: float, state: tuple[float, float, float, float]) -> Callable[[int], None]:
    """``k`` steps of the game's own compiled loop (``GameSession._advance_compiled``'s call): the muscles
    (two on, held), RK4 and the hand's distance from a target it never reaches, every step."""
    model = TwoJointArm(params)
    moments = ((1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0))
    values = kernel_params(model, dt, [m[0] for m in moments], [m[1] for m in moments])
    packed, mode = struct.pack(f"={len(values)}d", *values), kernel_mode(params)
    game_steps = _ckernel.game_steps
    q1, q2, w1, w2 = state

    def run(k: int) -> None:
        game_steps(packed, mode, k, q1, q2, w1, w2, 0.2, 0.0, 0.0, 0.1, 0.2, 0.0, 0.0, 0.1, 0.05, 0.05, 0.05, 0.05,
                   100.0, 100.0, 0.0004)

    return run
