"""Measurements of armgame's fixed-step schemes on the hard cases, and the shared case setup.

Every method, ours and the peers', is measured the same way on a case:

* **time** per simulated second: the median of ``repeats`` timed runs over the first 2 s,
  one arm, stepped in a plain Python loop with the torque looked up per step, as the game does;
* **RHS** evaluations per simulated second, counted in a separate run through wrapped closures,
  so the timed runs pay nothing for the counting;
* **hand error**: the largest distance between the hand and the DOP853 reference
  (rtol = atol = 1e-12) over the first 2 s;
* **energy drift**: the largest relative energy error over 60 s of torque-free motion, started
  from the reference state at the moment the case's torques stop (against the reference's own
  energy, which is constant unless the arm is damped);
* **blow-up**: a non-finite state or a joint speed beyond ``BLOWUP_SPEED`` in either run.
"""

from __future__ import annotations

import dataclasses
import math
import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..physics.defaults import BLOWUP_SPEED
from ..physics.integrators import SCHEMES
from ..physics.reference import reference_trajectory
from ..physics.twojoint import ComponentDynamics, TwoJointArm
from ..scenes import SCENES, Scene

HARD_CASES = ("passive", "propeller", "upright", "stiff", "game")
#: From the 2012 game's frame step down to a step where every scheme here is converged.
STEPS = (1 / 30, 1 / 60, 1 / 120, 1 / 250, 1 / 500, 1 / 1000, 1 / 2000, 1 / 4000)
#: The quick grid keeps the 2012 game's step and the game's default (1/250 s).
QUICK_STEPS = (1 / 30, 1 / 250, 1 / 1000)
ERROR_WINDOW = 2.0  # s
ENERGY_WINDOW = 60.0  # s
QUICK_ENERGY_WINDOW = 10.0  # s: --quick must finish in under 30 s
ENERGY_SAMPLE = 0.05  # s between energy samples


@dataclass
class Row:
    """One method at one setting on one case."""

    case: str
    method: str
    family: str  # "armgame", "tutorial", "scipy" or "mujoco"
    setting: str  # "dt=1/250" or "tol=1e-08"
    dt: float | None
    tol: float | None
    time_per_sim_s: float  # s of wall time per simulated second
    rhs_per_sim_s: float
    hand_error: float  # m
    energy_drift: float  # relative
    blew_up: bool
    note: str = ""

    def as_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)


def step_label(dt: float) -> str:
    return f"dt=1/{round(1 / dt)}"


@dataclass
class Case:
    """A hard case with its reference solutions, computed once and shared by every method."""

    scene: Scene
    model: TwoJointArm
    segments: tuple[tuple[float, tuple[float, float]], ...]
    free_start: float
    free_state: tuple[float, float, float, float]
    energy_window: float = ENERGY_WINDOW
    _ref_cache: dict[tuple[int, float], NDArray[np.float64]] = field(default_factory=dict)
    _energy_cache: dict[float, NDArray[np.float64]] = field(default_factory=dict)

    @property
    def name(self) -> str:
        return self.scene.name

    def reference_hand(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        key = (len(t), float(t[-1]))
        if key not in self._ref_cache:
            states = reference_trajectory(self.model, self.scene.initial, t, self.segments)
            self._ref_cache[key] = self.model.hand(states[:, :2])
        return self._ref_cache[key]

    def reference_energy(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        """The reference energy at times ``t`` after the torques stop (t = 0 at the stop)."""
        key = float(t[1] - t[0]) if len(t) > 1 else 0.0
        if key not in self._energy_cache:
            e0 = float(self.model.energy(self.free_state[:2], self.free_state[2:]))
            if not self.model.params.has_damping:
                self._energy_cache[key] = np.full(len(t), e0)
            else:
                states = reference_trajectory(self.model, self.free_state, t)
                self._energy_cache[key] = self.model.energy(states[:, :2], states[:, 2:])
        return self._energy_cache[key]

    def energy_scale(self) -> float:
        return abs(float(self.model.energy(self.free_state[:2], self.free_state[2:])))


def make_case(name: str, energy_window: float = ENERGY_WINDOW) -> Case:
    scene = SCENES[name]
    free_start = 0.0 if scene.free_after == math.inf else scene.free_after
    if scene.free_after == math.inf:
        raise ValueError(f"case {name!r} never goes torque-free, so its energy cannot be checked")
    if free_start > 0.0:
        # Python floats, not numpy scalars: the schemes run several times faster on them.
        free_state = tuple(map(float, reference_trajectory(scene.model, scene.initial, [free_start],
                                                           scene.torque_segments)[0]))
    else:
        free_state = scene.initial
    return Case(scene, scene.model, scene.torque_segments, free_start, free_state,  # type: ignore[arg-type]
                energy_window)


def step_torques(segments: Sequence[tuple[float, tuple[float, float]]], dt: float, steps: int) -> list:
    """The torque held over each of ``steps`` steps; each switch lands on the step nearest its time."""
    out: list[tuple[float, float]] = []
    starts = [max(0, round(s / dt)) for s, _ in segments] + [steps]
    for k, (_, torque) in enumerate(segments):
        lo, hi = min(starts[k], steps), min(max(starts[k + 1], starts[k]), steps)
        out.extend([torque] * (hi - lo))
    out.extend([segments[-1][1]] * (steps - len(out)))
    return out


def median_time(run: Callable[[], Any], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        run()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def counting(dyn: ComponentDynamics) -> tuple[ComponentDynamics, list[int]]:
    """A copy of ``dyn`` whose right-hand sides (accel, hamilton) count their calls."""
    count = [0]

    def wrap(f: Callable) -> Callable:
        def counted(*args: Any) -> Any:
            count[0] += 1
            return f(*args)

        return counted

    return dataclasses.replace(dyn, accel=wrap(dyn.accel), hamilton=wrap(dyn.hamilton)), count


def _finite_and_sane(w1: float, w2: float, *rest: float) -> bool:
    return all(math.isfinite(v) for v in (w1, w2, *rest)) and abs(w1) < BLOWUP_SPEED and abs(w2) < BLOWUP_SPEED


def hand_error(case: Case, t: NDArray[np.float64], states: NDArray[np.float64]) -> float:
    with np.errstate(all="ignore"):
        diff = case.model.hand(states[:, :2]) - case.reference_hand(t)
        err = float(np.max(np.linalg.norm(diff, axis=-1)))
    return err if math.isfinite(err) else math.inf


def energy_drift(case: Case, t: NDArray[np.float64], states: NDArray[np.float64]) -> float:
    with np.errstate(all="ignore"):
        e = case.model.energy(states[:, :2], states[:, 2:])
        drift = float(np.max(np.abs(e - case.reference_energy(t)))) / case.energy_scale()
    return drift if math.isfinite(drift) else math.inf


def measure_scheme(case: Case, name: str, dt: float, repeats: int) -> Row:
    dyn = case.model.component_dynamics("float")
    step = SCHEMES[name].build(dyn)
    steps = round(ERROR_WINDOW / dt)
    torques = step_torques(case.segments, dt, steps)
    start = case.scene.initial

    # Counted and recorded run: hand error and RHS evaluations.
    counted_dyn, count = counting(dyn)
    counted_step = SCHEMES[name].build(counted_dyn)
    q1, q2, w1, w2 = start
    states = [start]
    ok = True
    try:
        for t1, t2 in torques:
            q1, q2, w1, w2 = counted_step(q1, q2, w1, w2, t1, t2, dt)
            states.append((q1, q2, w1, w2))
            if not _finite_and_sane(w1, w2, q1, q2):
                ok = False
                break
    except (OverflowError, ZeroDivisionError, ValueError):  # math.cos(inf) and kin: the run blew up
        ok = False
    t = np.arange(steps + 1) * dt
    error = hand_error(case, t, np.array(states)) if ok else math.inf
    rhs = count[0] / max(1, len(states) - 1) / dt

    timed = scheme_run(case, name, dt)

    # A blown-up run can overflow into slow paths: time it, but only once.
    with np.errstate(all="ignore"):
        try:
            elapsed = median_time(timed, repeats if ok else 1)
        except (OverflowError, ZeroDivisionError, ValueError):
            elapsed = math.nan
    drift, energy_ok = _scheme_energy(case, step, dt) if ok else (math.inf, False)
    return Row(case.name, name, "armgame", step_label(dt), dt, None, elapsed / ERROR_WINDOW, rhs, error, drift,
               not (ok and energy_ok))


def scheme_run(case: Case, name: str, dt: float) -> Callable[[], None]:
    """The timed part of ``measure_scheme``: one arm over the error window, stepped as the game steps it."""
    step = SCHEMES[name].build(case.model.component_dynamics("float"))
    torques = step_torques(case.segments, dt, round(ERROR_WINDOW / dt))
    start = case.scene.initial

    def timed() -> None:
        q1, q2, w1, w2 = start
        for t1, t2 in torques:
            q1, q2, w1, w2 = step(q1, q2, w1, w2, t1, t2, dt)

    return timed


def _scheme_energy(case: Case, step: Callable, dt: float) -> tuple[float, bool]:
    steps = round(case.energy_window / dt)
    every = max(1, round(ENERGY_SAMPLE / dt))
    q1, q2, w1, w2 = case.free_state
    samples = [case.free_state]
    try:
        for i in range(1, steps + 1):
            q1, q2, w1, w2 = step(q1, q2, w1, w2, 0.0, 0.0, dt)
            if i % every == 0:
                samples.append((q1, q2, w1, w2))
                if not _finite_and_sane(w1, w2, q1, q2):
                    return math.inf, False
    except (OverflowError, ZeroDivisionError, ValueError):
        return math.inf, False
    t = np.arange(len(samples)) * every * dt
    return energy_drift(case, t, np.array(samples)), True


def measure_schemes(case: Case, names: Sequence[str], steps: Sequence[float], repeats: int) -> list[Row]:
    return [measure_scheme(case, name, dt, repeats) for name in names for dt in steps]


# ------------------------------------------------------------------------------ defaults
@dataclass(frozen=True)
class Choice:
    integrator: str
    dt: float
    time_per_sim_s: float
    reason: str


def choose(
    rows: Sequence[Row],
    error_cases: Sequence[str],
    max_error: float,
    max_drift: float,
    cost_case: str,
    drift_cases: Sequence[str] = ("passive",),
) -> Choice | None:
    """The cheapest (integrator, dt) of ours on ``cost_case`` that meets the bars on every case measured.

    It must keep the hand within ``max_error`` on each of ``error_cases``, the energy of each of
    ``drift_cases`` within ``max_drift``, and blow up on no case.
    """
    ours = [r for r in rows if r.family == "armgame"]
    by_key: dict[tuple[str, float], dict[str, Row]] = {}
    for r in ours:
        by_key.setdefault((r.method, r.dt), {})[r.case] = r  # type: ignore[index]
    best: Choice | None = None
    for (name, dt), per_case in by_key.items():
        if cost_case not in per_case or not any(c in per_case for c in drift_cases):
            continue
        if any(r.blew_up for r in per_case.values()):
            continue
        if any(c in per_case and per_case[c].hand_error >= max_error for c in error_cases):
            continue
        drift = max(per_case[c].energy_drift for c in drift_cases if c in per_case)
        if drift >= max_drift:
            continue
        cost = per_case[cost_case].time_per_sim_s
        if best is None or cost < best.time_per_sim_s:
            worst = max(per_case[c].hand_error for c in error_cases if c in per_case)
            reason = (f"cheapest on {cost_case} ({cost * 1e3:.3g} ms per simulated s) with hand error "
                      f"{worst:.2g} m < {max_error:g} m on {', '.join(error_cases)}, energy drift "
                      f"{drift:.2g} < {max_drift:g} on {', '.join(drift_cases)}, no blow-up")
            best = Choice(name, dt, cost, reason)
    return best
