"""The peers, measured on the same cases as armgame's schemes (see ``measure`` for the metrics).

* the tutorial's method: scipy's ``odeint`` on a right-hand side that builds numpy matrices
  and inverts M with ``np.linalg.inv`` on every call, as the tutorial's ``twojointarm`` does;
* scipy's ``solve_ivp`` (RK45, DOP853) on armgame's own float right-hand side;
* MuJoCo's RK4 and Euler on the same arm as an MJCF model, stepped one ``mj_step`` per step
  from Python as the game would step it.

Adaptive solvers produce output at a 200 Hz grid; they integrate each constant-torque
segment separately, as the reference does, so they are not charged for crossing jumps.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..physics.reference import reference_trajectory
from ..physics.twojoint import TwoJointArm
from .measure import (
    BLOWUP_SPEED,
    ENERGY_SAMPLE,
    ERROR_WINDOW,
    Case,
    Row,
    counting,
    energy_drift,
    hand_error,
    median_time,
    step_label,
    step_torques,
)
from .mjcf import build_model

OUTPUT_RATE = 200.0  # Hz, the tutorial's sampling
ODEINT_DEFAULT_TOL = 1.49012e-8  # odeint's own default rtol and atol, which the tutorial kept
ODEINT_TOLS = (1e-4, 1e-6, ODEINT_DEFAULT_TOL, 1e-10)
SOLVE_IVP_TOLS = (1e-4, 1e-6, 1e-8, 1e-10)


def tutorial_rhs(model: TwoJointArm) -> Callable[..., list[float]]:
    """The tutorial's ``twojointarm`` in armgame's angles, with torques and damping added.

    Kept in the tutorial's style on purpose, down to ``numpy.matrix`` and ``inv(M) * (...)``
    on every call: it is the baseline being measured. (numpy.matrix is what makes it slow:
    plain 2-D arrays would cost about a third as much per call.)
    """
    p = model.params
    l1, m1, m2, i1, i2, r1, r2, g = p.l1, p.m1, p.m2, p.i1, p.i2, p.r1, p.r2, p.gravity
    matrix, inv, cos, sin = np.matrix, np.linalg.inv, np.cos, np.sin

    def twojointarm(state: Sequence[float], _t: float, tau: tuple[float, float]) -> list[float]:
        a1, a2, a1d, a2d = state
        M11 = i1 + i2 + (m1 * r1 * r1) + (m2 * ((l1 * l1) + (r2 * r2) + (2 * l1 * r2 * cos(a2))))
        M12 = i2 + (m2 * ((r2 * r2) + (l1 * r2 * cos(a2))))
        M21 = M12
        M22 = i2 + (m2 * r2 * r2)
        M = matrix([[M11, M12], [M21, M22]])
        C1 = -(m2 * l1 * a2d * a2d * r2 * sin(a2)) - (2 * m2 * l1 * a1d * a2d * r2 * sin(a2))
        C2 = m2 * l1 * a1d * a1d * r2 * sin(a2)
        C = matrix([[C1], [C2]])
        G1 = (g * cos(a1) * ((m2 * l1) + (m1 * r1))) + (g * m2 * r2 * cos(a1 + a2))
        G2 = g * m2 * r2 * cos(a1 + a2)
        G = matrix([[G1], [G2]])
        Q = matrix([[tau[0] - p.damping1 * a1d], [tau[1] - p.damping2 * a2d]])
        ACC = inv(M) * (Q - C - G)
        return [a1d, a2d, ACC[0, 0], ACC[1, 0]]

    return twojointarm


def _odeint_segments(rhs: Callable, state0: Sequence[float], t: NDArray[np.float64], segments: Sequence,
                     tol: float) -> NDArray[np.float64]:
    from scipy.integrate import odeint

    out = np.empty((len(t), 4))
    y = np.asarray(state0, dtype=float)
    starts = [max(0.0, s) for s, _ in segments] + [math.inf]
    for k, (_, torque) in enumerate(segments):
        lo, hi = starts[k], min(starts[k + 1], float(t[-1]))
        if hi <= lo:
            continue
        inside = (t > lo) & (t < hi)
        sol = odeint(rhs, y, np.concatenate([[lo], t[inside], [hi]]), args=(torque,), rtol=tol, atol=tol)
        out[t == lo] = y
        out[inside] = sol[1:-1]
        y = sol[-1]
        out[t == hi] = y
    return out


def _grid(window: float, rate: float) -> NDArray[np.float64]:
    return np.arange(round(window * rate) + 1) / rate


def _sane(states: NDArray[np.float64]) -> bool:
    return bool(np.all(np.isfinite(states)) and np.all(np.abs(states[:, 2:]) < BLOWUP_SPEED))


def odeint_run(case: Case, tol: float) -> Callable[[], None]:
    """The timed part of ``measure_odeint``: the tutorial's method over the error window."""
    rhs = tutorial_rhs(case.model)
    t = _grid(ERROR_WINDOW, OUTPUT_RATE)

    def timed() -> None:
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.filterwarnings("ignore", "the matrix subclass", PendingDeprecationWarning)
            _odeint_segments(rhs, case.scene.initial, t, case.segments, tol)

    return timed


def measure_odeint(case: Case, tol: float, repeats: int) -> Row:
    rhs = tutorial_rhs(case.model)
    count = [0]

    def counted(state: Any, t: float, tau: tuple[float, float]) -> list[float]:
        count[0] += 1
        return rhs(state, t, tau)

    t = _grid(ERROR_WINDOW, OUTPUT_RATE)
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.filterwarnings("ignore", "the matrix subclass", PendingDeprecationWarning)
        states = _odeint_segments(counted, case.scene.initial, t, case.segments, tol)
        elapsed = median_time(lambda: _odeint_segments(rhs, case.scene.initial, t, case.segments, tol), repeats)
        te = _grid(case.energy_window, 1.0 / ENERGY_SAMPLE)
        free = _odeint_segments(rhs, case.free_state, te, ((0.0, (0.0, 0.0)),), tol)
    ok = _sane(states) and _sane(free)
    label = "odeint (tutorial)"
    note = "odeint's default tolerance, as the tutorial ran it" if tol == ODEINT_DEFAULT_TOL else ""
    return Row(case.name, label, "tutorial", f"tol={tol:.3g}", None, tol, elapsed / ERROR_WINDOW,
               count[0] / ERROR_WINDOW, hand_error(case, t, states) if ok else math.inf,
               energy_drift(case, te, free) if ok else math.inf, not ok, note)


class _CountingModel:
    """Hands ``reference_trajectory`` a counting right-hand side, nothing else changed."""

    def __init__(self, model: TwoJointArm) -> None:
        self.dyn, self.count = counting(model.component_dynamics("float"))

    def component_dynamics(self, _backend: str = "float") -> Any:
        return self.dyn


def measure_solve_ivp(case: Case, method: str, tol: float, repeats: int) -> Row:
    t = _grid(ERROR_WINDOW, OUTPUT_RATE)
    counter = _CountingModel(case.model)
    te = _grid(case.energy_window, 1.0 / ENERGY_SAMPLE)
    ok = True
    try:
        states = reference_trajectory(counter, case.scene.initial, t, case.segments, rtol=tol, atol=tol,
                                      method=method)
        elapsed = median_time(lambda: reference_trajectory(case.model, case.scene.initial, t, case.segments,
                                                           rtol=tol, atol=tol, method=method), repeats)
        free = reference_trajectory(case.model, case.free_state, te, rtol=tol, atol=tol, method=method)
    except RuntimeError:
        ok, elapsed = False, math.nan
    ok = ok and _sane(states) and _sane(free)
    return Row(case.name, f"solve_ivp {method}", "scipy", f"tol={tol:.0e}", None, tol, elapsed / ERROR_WINDOW,
               counter.count[0] / ERROR_WINDOW, hand_error(case, t, states) if ok else math.inf,
               energy_drift(case, te, free) if ok else math.inf, not ok)


def _mujoco_run(mujoco: Any, mj_model: Any, data: Any, state: Sequence[float], torques: Sequence,
                record_every: int = 0) -> list:
    data.qpos[:] = state[:2]
    data.qvel[:] = state[2:]
    data.time = 0.0
    mujoco.mj_forward(mj_model, data)
    applied = data.qfrc_applied
    records = [tuple(state)]
    step = mujoco.mj_step
    for i, (t1, t2) in enumerate(torques, start=1):
        applied[0] = t1
        applied[1] = t2
        step(mj_model, data)
        if record_every and i % record_every == 0:
            records.append((*data.qpos, *data.qvel))
    return records


def measure_mujoco(mujoco: Any, case: Case, integrator: str, dt: float, repeats: int) -> Row:
    mj_model, data = build_model(mujoco, case.model.params, dt, integrator)
    steps = round(ERROR_WINDOW / dt)
    torques = step_torques(case.segments, dt, steps)
    states = np.array(_mujoco_run(mujoco, mj_model, data, case.scene.initial, torques, record_every=1))
    ok = _sane(states) and len(states) == steps + 1
    t = np.arange(steps + 1) * dt
    elapsed = median_time(lambda: _mujoco_run(mujoco, mj_model, data, case.scene.initial, torques), repeats)
    every = max(1, round(ENERGY_SAMPLE / dt))
    free = np.array(_mujoco_run(mujoco, mj_model, data, case.free_state, [(0.0, 0.0)] * round(case.energy_window / dt),
                                record_every=every))
    te = np.arange(len(free)) * every * dt
    ok = ok and _sane(free)
    rhs = {"RK4": 4, "Euler": 1}[integrator]
    note = "semi-implicit Euler, damping implicit" if integrator == "Euler" else ""
    return Row(case.name, f"mujoco {integrator.lower()}", "mujoco", step_label(dt), dt, None, elapsed / ERROR_WINDOW,
               rhs / dt, hand_error(case, t, states) if ok else math.inf,
               energy_drift(case, te, free) if ok else math.inf, not ok, note)
