"""The demos by name: what each shows, how to build its run, and its headless outputs (CSV and PNG)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import UserError
from ..scenes import get_scene
from ..simulation import Trajectory, write_csv, write_table
from ..words import unknown_name
from . import DEMO_NAMES
from .reach import COMPONENTS, ReachRun, reach_table
from .runs import chaos_run, check_fixed_step, passive_run, pendulum_run, record


@dataclass(frozen=True)
class DemoInfo:
    name: str
    title: str  # the window's title bar
    caption: str  # the on-screen sentence: what the class is looking at
    duration: float  # seconds a headless run covers by default
    sample_rate: float  # CSV rows per simulated second
    vertical: bool  # arm in a vertical plane (hangs from a central shoulder) or the game's horizontal one


INFO: dict[str, DemoInfo] = {
    d.name: d
    for d in (
        DemoInfo("pendulum", "armgame demo: one-joint passive arm",
                 "One joint, no muscles: released from horizontal, gravity swings it for ever.", 10.0, 100.0, True),
        DemoInfo("passive", "armgame demo: two-joint passive arm",
                 "Two joints, no muscles: gravity and each link pushing on the other move the arm.",
                 10.0, 200.0, True),
        DemoInfo("chaos", "armgame demo: chaos",
                 "Two passive arms, one a millionth of a radian off: they move as one, then part.",
                 15.0, 200.0, True),
        DemoInfo("interaction", "armgame demo: interaction torques",
                 "A fast reach and the torque each joint needs. Interaction torques (orange, red) are there only "
                 "because the other joint moves.",
                 2.6, 1000.0, False),
        DemoInfo("planning", "armgame demo: planning a reach",
                 "One reach planned two ways. Minimum jerk (dark) moves the hand straight; minimum torque change "
                 "(orange), computed on the arm's own dynamics, curves it.",
                 0.6, 1000.0, False),
    )
}
assert tuple(INFO) == DEMO_NAMES


def get_info(name: str) -> DemoInfo:
    try:
        return INFO[name]
    except KeyError:
        raise UserError(unknown_name("demo", name, DEMO_NAMES)) from None


def make_run(name: str, integrator: str = "rk4", dt: float = 0.001, gravity: bool = False) -> Any:
    """The steppable run behind demo ``name``: a ``PassiveRun``, or for the prescribed reaches a ``ReachRun``
    (interaction) or a ``PlanningRun`` (planning)."""
    get_info(name)
    check_fixed_step(integrator, dt)
    if gravity and name != "interaction":
        raise UserError("--gravity applies to the interaction demo only (the others always have gravity)")
    if name == "pendulum":
        return pendulum_run(integrator, dt)
    if name == "passive":
        return passive_run(integrator, dt)
    if name == "chaos":
        return chaos_run(integrator, dt)
    if name == "planning":
        from .planning import PlanningRun

        return PlanningRun(dt)
    return ReachRun(gravity=gravity, dt=dt)




def _prepare_folder(out_dir: Path) -> Path:
    out_dir = Path(out_dir)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserError(f"cannot create the output folder {out_dir}: {exc.strerror or exc}") from None
    return out_dir


@dataclass(frozen=True)
class HeadlessResult:
    files: list[Path]
    summary: str


def run_headless(name: str, out_dir: Path, duration: float | None = None, integrator: str = "rk4",
                 dt: float = 0.001, gravity: bool = False, figures: bool = True) -> HeadlessResult:
    """Run demo ``name`` without a window; write ``NAME.csv`` and (with ``figures``) ``NAME.png`` to ``out_dir``."""
    info = get_info(name)
    if name == "planning" and duration is not None:
        raise UserError("--duration does not apply to the planning demo: it plans one reach of "
                        f"{info.duration:g} s (the optimal path's shape does not depend on its duration)")
    duration = info.duration if duration is None else duration
    if not (math.isfinite(duration) and duration > 0.0):
        raise UserError(f"--duration must be a positive, finite number of seconds, got {duration!r}")
    run = make_run(name, integrator, dt, gravity)
    if figures:  # after the arguments are checked: a bad one is the first thing to hear about
        from .figures import require_matplotlib

        require_matplotlib()
    out_dir = _prepare_folder(out_dir)
    csv_path, png_path = out_dir / f"{name}.csv", out_dir / f"{name}.png"
    files = [csv_path]
    if name in ("pendulum", "passive"):
        rec = record(run, duration, info.sample_rate)
        states = rec.states[:, 0, :]
        scene = get_scene(name)
        write_csv(Trajectory(scene, rec.t, states, np.zeros((len(rec.t), 2))), csv_path)
        hand = run.model.hand(states[:, 0] if run.joints == 1 else states[:, :2])
        if name == "pendulum":
            peak = np.degrees(np.max(np.abs(states[:, 2])))
            summary = f"peak angular velocity {peak:.1f} deg/s"
        else:
            summary = f"hand from ({hand[0, 0]:.4f}, {hand[0, 1]:.4f}) m to ({hand[-1, 0]:.4f}, {hand[-1, 1]:.4f}) m"
        if figures:
            from .figures import passive_figure, pendulum_figure

            if name == "pendulum":
                files.append(pendulum_figure(rec.t, states[:, 0], states[:, 2], png_path))
            else:
                files.append(passive_figure(rec.t, states[:, :2], hand, png_path))
    elif name == "chaos":
        rec = record(run, duration, info.sample_rate)
        hand_a = run.model.hand(rec.states[:, 0, :2])
        hand_b = run.model.hand(rec.states[:, 1, :2])
        distance = np.hypot(*(hand_a - hand_b).T)
        header, columns = ["t"], [rec.t]
        for arm, s, h in (("a", rec.states[:, 0], hand_a), ("b", rec.states[:, 1], hand_b)):
            header += [f"{arm}_{c}" for c in ("q1", "q2", "qd1", "qd2", "hand_x", "hand_y")]
            columns += [s[:, 0], s[:, 1], s[:, 2], s[:, 3], h[:, 0], h[:, 1]]
        write_table(csv_path, [*header, "hand_distance"], [*columns, distance])
        from .runs import VISIBLY_APART

        apart = np.flatnonzero(distance > VISIBLY_APART)
        summary = f"hands {distance[0]:.2e} m apart at t = 0, " + (
            f"{VISIBLY_APART:g} m apart from t = {rec.t[apart[0]]:.2f} s" if len(apart)
            else f"still within {VISIBLY_APART:g} m after {rec.t[-1]:g} s")
        if figures:
            from .figures import chaos_figure

            files.append(chaos_figure(rec.t, distance, hand_a, hand_b, png_path))
    elif name == "planning":
        from .planning import summary as planning_summary

        planning = run.planning
        header, columns = ["t"], [planning.jerk.t]
        for prefix, reach in (("mj", planning.jerk), ("mtc", planning.torque_change)):
            header += [f"{prefix}_{c}" for c in ("q1", "q2", "hand_x", "hand_y", "speed", "tau1", "tau2", "dtau1",
                                                 "dtau2")]
            columns += [*reach.q.T, *reach.hand.T, reach.speed, *reach.torque.T, *reach.torque_rate.T]
        write_table(csv_path, header, columns)
        summary = planning_summary(planning)
        if figures:
            from .figures import planning_figure

            files.append(planning_figure(planning, png_path))
    else:
        steps = math.floor(duration / dt + 1e-9)
        every = max(1, round(1.0 / (info.sample_rate * dt)))
        table = reach_table(run.arm, run.plan, np.arange(0, steps + 1, every) * dt)
        header = ["t", "q1", "q2", "qd1", "qd2", "qdd1", "qdd2", "hand_x", "hand_y", "hand_vx", "hand_vy",
                  "tau1", "tau2"]
        columns = [table.t, *table.q.T, *table.qd.T, *table.qdd.T, *table.hand.T, *table.hand_velocity.T,
                   *table.total.T]
        for key, _, _ in COMPONENTS:
            header += [f"{key}1", f"{key}2"]
            columns += [table.parts[key][:, 0], table.parts[key][:, 1]]
        write_table(csv_path, header, columns)
        peak = np.max(np.abs(table.total), axis=0)
        own = np.max(np.abs(table.parts["own_inertial"]), axis=0)
        inter = np.max(np.abs(table.parts["interaction_inertial"] + table.parts["coriolis_centrifugal"]), axis=0)
        summary = (f"peak torque shoulder {peak[0]:.2f} N m, elbow {peak[1]:.2f} N m; peak interaction torque "
                   f"shoulder {inter[0]:.2f}, elbow {inter[1]:.2f} N m (own inertia {own[0]:.2f}, {own[1]:.2f})")
        if figures:
            from .figures import interaction_figure

            files.append(interaction_figure(table, gravity, png_path))
    return HeadlessResult(files, summary)
