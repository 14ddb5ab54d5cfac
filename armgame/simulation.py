"""Offline simulation of a named scene with a chosen integrator, and its CSV output."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from .errors import UserError
from .physics.integrators import INTEGRATOR_NAMES, Integrator
from .physics.reference import reference_trajectory
from .scenes import Scene

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


def simulate(
    scene: Scene,
    integrator: str,
    dt: float,
    duration: float | None = None,
    initial: tuple[float, float, float, float] | None = None,
    sample_rate: float = DEFAULT_SAMPLE_RATE,
) -> Trajectory:
    """Run ``scene`` for ``duration`` seconds, recording at about ``sample_rate`` Hz.

    Fixed-step schemes hold each torque over a step from the step's start; ``dop853`` is
    the adaptive reference at tight tolerance, sampled at the same times.
    """
    duration = scene.duration if duration is None else duration
    _check_positive_finite("--duration", duration)
    _check_positive_finite("--dt", dt)
    if not math.isfinite(sample_rate) or sample_rate <= 0.0:
        raise UserError(f"--sample-rate must be a positive, finite number of hertz, got {sample_rate!r}")
    if dt > duration:
        raise UserError(f"--dt ({dt} s) is longer than --duration ({duration} s)")
    if integrator not in INTEGRATOR_NAMES:
        raise UserError(f"unknown integrator {integrator!r}: choose one of {', '.join(INTEGRATOR_NAMES)}")
    state0 = scene.initial if initial is None else initial
    if not all(math.isfinite(v) for v in state0):
        raise UserError(f"the initial state must be finite, got {state0!r}")
    if scene.joints == 1:
        state0 = (state0[0], 0.0, state0[2], 0.0)
    steps = math.floor(duration / dt + 1e-9)
    every = max(1, round(1.0 / (sample_rate * dt)))
    sample_steps = np.arange(0, steps + 1, every)
    t = sample_steps * dt
    torques = np.array([scene.torque_at(ti) for ti in t], dtype=float).reshape(-1, 2)

    if integrator == "dop853":
        segments = tuple((s, u) for s, u in scene.torque_segments if s < t[-1] or s == 0.0)
        states = reference_trajectory(scene.model, state0, t, segments)
    else:
        step = Integrator(integrator, scene.model).step_components
        states = np.empty((len(t), 4))
        q1, q2, w1, w2 = state0
        states[0] = state0
        row = 1
        for i in range(steps):
            t1, t2 = scene.torque_at(i * dt)
            try:
                q1, q2, w1, w2 = step(q1, q2, w1, w2, t1, t2, dt)
            except (ValueError, OverflowError, ZeroDivisionError):  # a diverged implicit solve ends in math.cos(inf)
                q1 = math.nan
            if (row < len(sample_steps) and sample_steps[row] == i + 1) or q1 != q1:
                if not all(map(math.isfinite, (q1, q2, w1, w2))):
                    raise UserError(
                        f"the run blew up at t = {(i + 1) * dt:g} s: {integrator} is unstable at --dt {dt:g} "
                        f"on this scene; try a smaller --dt or another --integrator"
                    )
                states[row] = (q1, q2, w1, w2)
                row += 1
    if scene.joints == 1:
        torques[:, 1] = 0.0
    return Trajectory(scene, t, states, torques)


def write_csv(trajectory: Trajectory, path: Path) -> None:
    """Columns: t, joint angles (rad) and velocities (rad/s), hand_x, hand_y (m), torques (N m), energy (J)."""
    hand = trajectory.hand()
    energy = trajectory.energy()
    s, u = trajectory.states, trajectory.torques
    if trajectory.scene.joints == 1:
        header = ["t", "q1", "qd1", "hand_x", "hand_y", "tau1", "energy"]
        columns = [trajectory.t, s[:, 0], s[:, 2], hand[:, 0], hand[:, 1], u[:, 0], energy]
    else:
        header = ["t", "q1", "q2", "qd1", "qd2", "hand_x", "hand_y", "tau1", "tau2", "energy"]
        columns = [trajectory.t, s[:, 0], s[:, 1], s[:, 2], s[:, 3], hand[:, 0], hand[:, 1], u[:, 0], u[:, 1], energy]
    write_table(Path(path), header, columns)


def write_table(path: Path, header: list[str], columns: list[NDArray[np.float64]]) -> Path:
    """A CSV with a header line and full float precision, written whole or not at all."""
    if path.parent and not path.parent.exists():
        raise UserError(f"cannot write {path}: folder {path.parent} does not exist")
    tmp = path.with_name(path.name + ".part")
    try:
        np.savetxt(tmp, np.column_stack(columns), delimiter=",", header=",".join(header), comments="", fmt="%.17g")
        tmp.replace(path)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise UserError(f"cannot write {path}: {exc.strerror or exc}") from None
    return path
