"""Offline simulation of a named scene with a chosen integrator, and its CSV output.

A run's cost (steps, rows, bytes) is known and bounded before it starts (``plan_run``), rows
are written as they come (``simulate_to_csv``), and a run whose state overflows stops with one
line, for every integrator.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from .errors import UserError
from .limits import MAX_SIMULATE_ROWS, MAX_SIMULATE_STEPS, SIMULATE_ROW_BYTES
from .physics.defaults import BLOWUP_SPEED
from .physics.integrators import INTEGRATOR_NAMES, Integrator
from .physics.reference import reference_trajectory
from .records.storage import atomic_writer, check_output_path
from .scenes import Scene
from .words import unknown_name

DEFAULT_SAMPLE_RATE = 200.0


@dataclass(frozen=True)
class Trajectory:
    scene: Scene
    t: NDArray[np.float64]
    states: NDArray[np.float64]  # (samples, 4): q1, q2, qd1, qd2
    torques: NDArray[np.float64]  # (samples, 2), the torque applied from each sample on

    def hand(self) -> NDArray[np.float64]:
        if self.scene.joints == 1:
            return self.scene.model.hand(self.states[:, 0])
        return self.scene.model.hand(self.states[:, :2])

    def energy(self) -> NDArray[np.float64]:
        if self.scene.joints == 1:
            return self.scene.model.energy(self.states[:, 0], self.states[:, 2])
        return self.scene.model.energy(self.states[:, :2], self.states[:, 2:])


def _check_positive_finite(name: str, value: float) -> None:
    if not math.isfinite(value) or value <= 0.0:
        raise UserError(f"{name} must be a positive, finite number of seconds, got {value!r}")


#: Plausible initial states for ``--initial``: angles within two turns, speeds within 100 turns a second.
MAX_INITIAL_ANGLE = 4.0 * math.pi
MAX_INITIAL_SPEED = 200.0 * math.pi
#: Right-hand-side evaluations dop853 may spend per simulated second, and in all: its step adapts, so
#: a run that blows up would otherwise shrink its step without end. The hardest scene (propeller)
#: needs about 10,000 a second.
DOP853_EVALS_PER_SECOND = 20_000
DOP853_MAX_EVALS = 2_000_000
_CHUNK_ROWS = 4096


@dataclass(frozen=True)
class RunPlan:
    """What a run will cost, known before it starts."""

    steps: int
    every: int
    rows: int

    @property
    def csv_bytes(self) -> int:
        return self.rows * SIMULATE_ROW_BYTES

    def describe(self) -> str:
        return (f"{self.steps:,} steps, {self.rows:,} rows, about {_mib(self.csv_bytes)} of CSV and "
                f"{_mib(_CHUNK_ROWS * 20 * 8)} of memory, rows being streamed "
                f"(budget: {MAX_SIMULATE_STEPS:,} steps, {MAX_SIMULATE_ROWS:,} rows)")


def _mib(n: int) -> str:
    return f"{n / 2**20:,.0f} MiB" if n >= 2**20 else f"{n / 1024:,.0f} KiB"


def plan_run(scene: Scene, integrator: str, dt: float, duration: float | None = None,
             initial: tuple[float, float, float, float] | None = None,
             sample_rate: float = DEFAULT_SAMPLE_RATE) -> tuple[RunPlan, float, tuple[float, float, float, float]]:
    """Check every argument and the run's cost, before any work: UserError in one line if not."""
    duration = scene.duration if duration is None else duration
    _check_positive_finite("--duration", duration)
    _check_positive_finite("--dt", dt)
    if not math.isfinite(sample_rate) or sample_rate <= 0.0:
        raise UserError(f"--sample-rate must be a positive, finite number of hertz, got {sample_rate!r}")
    if dt > duration:
        raise UserError(f"--dt ({dt} s) is longer than --duration ({duration} s)")
    if integrator not in INTEGRATOR_NAMES:
        raise UserError(unknown_name("integrator", integrator, INTEGRATOR_NAMES))
    state0 = scene.initial if initial is None else initial
    if not all(math.isfinite(v) for v in state0):
        raise UserError(f"the initial state must be finite, got {state0!r}")
    if max(abs(state0[0]), abs(state0[1])) > MAX_INITIAL_ANGLE or \
            max(abs(state0[2]), abs(state0[3])) > MAX_INITIAL_SPEED:
        raise UserError(f"--initial must have angles within +-{math.degrees(MAX_INITIAL_ANGLE):g} deg and speeds "
                        f"within +-{math.degrees(MAX_INITIAL_SPEED):g} deg/s")
    if scene.joints == 1:
        state0 = (state0[0], 0.0, state0[2], 0.0)
    ratio = duration / dt
    every = max(1, round(min(1.0 / (sample_rate * dt), 1e18)))
    steps = math.floor(ratio + 1e-9) if ratio < 1e18 else 10**18
    plan = RunPlan(steps, every, steps // every + 1)
    # dop853 takes its own steps: its cost is bounded by DOP853_MAX_EVALS instead of the step budget.
    if (plan.steps > MAX_SIMULATE_STEPS and integrator != "dop853") or plan.rows > MAX_SIMULATE_ROWS:
        raise UserError(f"the run is too large: {plan.describe()}; raise --dt, lower --sample-rate or "
                        f"shorten --duration")
    return plan, duration, state0  # type: ignore[return-value]


def _blew_up(t: float, integrator: str, dt: float) -> UserError:
    return UserError(f"the run blew up at t = {t:g} s: {integrator} is unstable at --dt {dt:g} on this scene; "
                     f"try a smaller --dt or another --integrator")


def stream(scene: Scene, integrator: str, dt: float, duration: float | None = None,
           initial: tuple[float, float, float, float] | None = None,
           sample_rate: float = DEFAULT_SAMPLE_RATE) -> Iterator[tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """Chunks of ``(t, states)`` as the run goes (at most a few thousand rows at a time).

    Fixed-step schemes hold each torque over a step from the step's start; ``dop853`` is the
    adaptive reference at tight tolerance, sampled at the same times. Every row is finite: a
    run whose state overflows stops with one line naming the time (for every integrator).
    """
    plan, duration, state0 = plan_run(scene, integrator, dt, duration, initial, sample_rate)
    rows_t = (np.arange(0, plan.rows) * plan.every) * dt
    if integrator == "dop853":
        yield from _stream_reference(scene, rows_t, state0, dt)
        return
    step = Integrator(integrator, scene.model).step_components
    q1, q2, w1, w2 = state0
    every = plan.every
    i = 0
    for first in range(0, plan.rows, _CHUNK_ROWS):
        chunk = rows_t[first:first + _CHUNK_ROWS]
        out = np.empty((len(chunk), 4))
        for row in range(len(chunk)):
            if first + row > 0:
                for _ in range(every):
                    t1, t2 = scene.torque_at(i * dt)
                    try:
                        q1, q2, w1, w2 = step(q1, q2, w1, w2, t1, t2, dt)
                    except (ValueError, OverflowError, ZeroDivisionError):  # a diverged solve ends in cos(inf)
                        raise _blew_up((i + 1) * dt, integrator, dt) from None
                    i += 1
                # Once per row, so the step loop stays lean; NaN fails the comparisons too.
                if not (abs(w1) < BLOWUP_SPEED and abs(w2) < BLOWUP_SPEED and math.isfinite(q1 + q2)):
                    raise _blew_up(i * dt, integrator, dt)
            out[row] = (q1, q2, w1, w2)
        yield chunk, out


class _CountedModel:
    """The scene's model with a budget on right-hand-side evaluations (dop853's cost)."""

    def __init__(self, model: object, budget: int) -> None:
        self.model, self.budget = model, budget

    def component_dynamics(self, kind: str) -> object:
        dynamics = self.model.component_dynamics(kind)  # type: ignore[attr-defined]
        counter = self

        class Counted:
            @staticmethod
            def accel(*args: float) -> tuple[float, float]:
                counter.budget -= 1
                if counter.budget < 0:
                    raise _BudgetSpentError
                return dynamics.accel(*args)

        return Counted()


class _BudgetSpentError(Exception):
    pass


def _stream_reference(scene: Scene, rows_t: NDArray[np.float64], state0: tuple[float, float, float, float],
                      dt: float) -> Iterator[tuple[NDArray[np.float64], NDArray[np.float64]]]:
    budget = min(DOP853_MAX_EVALS, max(100_000, round(DOP853_EVALS_PER_SECOND * float(rows_t[-1]))))
    model = _CountedModel(scene.model, budget)
    y = np.asarray(state0, dtype=float)
    start = 0.0
    for first in range(0, len(rows_t), _CHUNK_ROWS):
        chunk = rows_t[first:first + _CHUNK_ROWS]
        # Each chunk starts from the last state, with the torque segments shifted to its clock.
        segments = tuple((max(0.0, s - start), u) for s, u in scene.torque_segments
                         if s < chunk[-1] or s == 0.0)
        live = [k for k, (s, _) in enumerate(segments) if s == 0.0]
        segments = segments[live[-1]:] if live else segments
        try:
            with np.errstate(all="ignore"):
                states = reference_trajectory(model, y, chunk - start, segments)
        except _BudgetSpentError:
            raise UserError(f"the run blew up or is too stiff near t = {start:g} s: dop853 spent its budget of "
                            f"{budget:,} evaluations; "
                            f"try a fixed-step --integrator") from None
        except (RuntimeError, ValueError, OverflowError, ZeroDivisionError):
            raise _blew_up(start, "dop853", dt) from None
        with np.errstate(invalid="ignore"):
            sane = np.isfinite(states).all(axis=1) & (np.abs(states[:, 2:]) < BLOWUP_SPEED).all(axis=1)
        if not sane.all():
            raise _blew_up(float(chunk[int(np.argmin(sane))]), "dop853", dt)
        yield chunk, states
        y, start = states[-1], float(chunk[-1])


def simulate(
    scene: Scene,
    integrator: str,
    dt: float,
    duration: float | None = None,
    initial: tuple[float, float, float, float] | None = None,
    sample_rate: float = DEFAULT_SAMPLE_RATE,
) -> Trajectory:
    """Run ``scene`` for ``duration`` seconds, recording at about ``sample_rate`` Hz (see ``stream``)."""
    ts, states = [], []
    for t, s in stream(scene, integrator, dt, duration, initial, sample_rate):
        ts.append(t)
        states.append(s)
    t = np.concatenate(ts)
    return Trajectory(scene, t, np.concatenate(states), _torques(scene, t))


def _torques(scene: Scene, t: NDArray[np.float64]) -> NDArray[np.float64]:
    torques = np.array([scene.torque_at(ti) for ti in t], dtype=float).reshape(-1, 2)
    if scene.joints == 1:
        torques[:, 1] = 0.0
    return torques


def _header(scene: Scene) -> list[str]:
    if scene.joints == 1:
        return ["t", "q1", "qd1", "hand_x", "hand_y", "tau1", "energy"]
    return ["t", "q1", "q2", "qd1", "qd2", "hand_x", "hand_y", "tau1", "tau2", "energy"]


def _columns(trajectory: Trajectory) -> list[NDArray[np.float64]]:
    hand = trajectory.hand()
    energy = trajectory.energy()
    s, u = trajectory.states, trajectory.torques
    if trajectory.scene.joints == 1:
        return [trajectory.t, s[:, 0], s[:, 2], hand[:, 0], hand[:, 1], u[:, 0], energy]
    return [trajectory.t, s[:, 0], s[:, 1], s[:, 2], s[:, 3], hand[:, 0], hand[:, 1], u[:, 0], u[:, 1], energy]


def write_csv(trajectory: Trajectory, path: Path) -> None:
    """Columns: t, joint angles (rad) and velocities (rad/s), hand_x, hand_y (m), torques (N m), energy (J)."""
    write_table(Path(path), _header(trajectory.scene), _columns(trajectory))


@dataclass
class RunSummary:
    rows: int
    t_end: float
    energy_start: float | None  # the first torque-free row's energy
    energy_end: float


def simulate_to_csv(scene: Scene, integrator: str, dt: float, path: Path, duration: float | None = None,
                    initial: tuple[float, float, float, float] | None = None,
                    sample_rate: float = DEFAULT_SAMPLE_RATE) -> RunSummary:
    """``simulate`` written as it runs: memory stays a few thousand rows whatever the length.

    The arguments are checked (and the run's cost bounded) before the file is touched; the CSV
    appears whole or not at all.
    """
    plan_run(scene, integrator, dt, duration, initial, sample_rate)
    check_output_path(Path(path), "CSV")
    summary = RunSummary(0, 0.0, None, 0.0)
    with atomic_writer(Path(path), "CSV") as f:
        f.write((",".join(_header(scene)) + "\n").encode())
        for t, states in stream(scene, integrator, dt, duration, initial, sample_rate):
            part = Trajectory(scene, t, states, _torques(scene, t))
            columns = _columns(part)
            np.savetxt(f, np.column_stack(columns), delimiter=",", fmt="%.17g")
            energy = columns[-1]
            free = t >= scene.free_after
            if summary.energy_start is None and free.any():
                summary.energy_start = float(energy[free][0])
            summary.rows += len(t)
            summary.t_end, summary.energy_end = float(t[-1]), float(energy[-1])
    return summary


def write_table(path: Path, header: list[str], columns: list[NDArray[np.float64]]) -> Path:
    """A CSV with a header line and full float precision, written whole or not at all, to a regular file."""
    path = Path(path)
    if path.parent and not path.parent.exists():
        raise UserError(f"cannot write {path}: folder {path.parent} does not exist")
    with atomic_writer(path, "CSV") as f:
        np.savetxt(f, np.column_stack(columns), delimiter=",", header=",".join(header), comments="", fmt="%.17g")
    return path
