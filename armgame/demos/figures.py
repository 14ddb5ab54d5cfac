"""The demos' figures, drawn with matplotlib (the optional ``plot`` extra) straight to PNG files.

Figures are built on ``matplotlib.figure.Figure`` rather than pyplot, so no GUI backend or global
state is touched: a headless run never needs a display.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import UserError
from .reach import COMPONENTS, ReachTable
from .runs import VISIBLY_APART

ARM_A, ARM_B = "#223344", "#ff7f0e"


def require_matplotlib() -> None:
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise UserError("figures need matplotlib: pip install 'armgame[plot]' (or pass --no-figures)") from None


def _figure(width: float, height: float) -> Any:
    from matplotlib.figure import Figure

    return Figure(figsize=(width, height), dpi=100, layout="constrained")


def _save(fig: Any, path: Path) -> Path:
    from ..records.storage import save_figure

    try:
        return save_figure(fig, path)  # only a regular file, written whole or not at all
    except OSError as exc:
        raise UserError(f"cannot write {path}: {exc.strerror or exc}") from None


def pendulum_figure(t: NDArray[np.float64], q: NDArray[np.float64], qd: NDArray[np.float64], path: Path) -> Path:
    """The tutorial's figure: its angle (from hanging straight down) and angular velocity, in degrees."""
    fig = _figure(8, 4.5)
    ax = fig.add_subplot()
    ax.plot(t, np.degrees(q) + 90.0, label="theta (deg, from hanging down)")
    ax.plot(t, np.degrees(qd), label="theta_dot (deg/s)")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("angle (deg) & angular velocity (deg/s)")
    ax.set_title("One-joint passive arm released from 90 deg (the tutorial's pendulum)")
    ax.legend(loc="upper right")
    ax.grid(alpha=0.3)
    return _save(fig, path)


def passive_figure(t: NDArray[np.float64], q: NDArray[np.float64], hand: NDArray[np.float64], path: Path) -> Path:
    fig = _figure(11, 4.8)
    left, right = fig.subplots(1, 2, width_ratios=(1.5, 1))
    left.plot(t, np.degrees(q[:, 0]), label="shoulder q1 (from +x)")
    left.plot(t, np.degrees(q[:, 1]), label="elbow q2 (from the upper arm)")
    left.set_xlabel("time (s)")
    left.set_ylabel("joint angle (deg)")
    left.set_title("Two-joint passive arm: joint angles")
    left.margins(y=0.2)  # headroom for the legend above the swings
    left.legend(loc="upper center", ncols=2)
    left.grid(alpha=0.3)
    right.plot(hand[:, 0], hand[:, 1], color=ARM_A, lw=0.8)
    right.plot(hand[0, 0], hand[0, 1], "o", color="tab:green", label="start")
    right.plot(0.0, 0.0, "s", color="black", label="shoulder")
    right.set_aspect("equal")
    right.set_xlabel("x (m)")
    right.set_ylabel("y (m)")
    right.set_title("hand path")
    right.legend(loc="upper right")
    right.grid(alpha=0.3)
    return _save(fig, path)


def chaos_figure(t: NDArray[np.float64], distance: NDArray[np.float64], hand_a: NDArray[np.float64],
                 hand_b: NDArray[np.float64], path: Path) -> Path:
    fig = _figure(11, 4.8)
    left, right = fig.subplots(1, 2, width_ratios=(1.5, 1))
    left.semilogy(t, np.maximum(distance, 1e-16), color="black")
    left.axhline(VISIBLY_APART, color="tab:red", ls="--", lw=1, label=f"visibly apart ({VISIBLY_APART * 100:g} cm)")
    apart = np.flatnonzero(distance > VISIBLY_APART)
    if len(apart):
        left.axvline(t[apart[0]], color="tab:red", ls=":", lw=1)
        left.set_title(f"Two arms 1e-6 rad apart: hands part visibly at t = {t[apart[0]]:.1f} s")
    else:
        left.set_title("Two arms 1e-6 rad apart: distance between the hands")
    left.set_xlabel("time (s)")
    left.set_ylabel("distance between the hands (m)")
    left.legend(loc="lower right")
    left.grid(alpha=0.3, which="both")
    right.plot(hand_a[:, 0], hand_a[:, 1], color=ARM_A, lw=0.8, label="arm A")
    right.plot(hand_b[:, 0], hand_b[:, 1], color=ARM_B, lw=0.8, alpha=0.8, label="arm B")
    right.plot(0.0, 0.0, "s", color="black")
    right.set_aspect("equal")
    right.set_xlabel("x (m)")
    right.set_ylabel("y (m)")
    right.set_title("hand paths")
    right.legend(loc="upper right")
    right.grid(alpha=0.3)
    return _save(fig, path)


def interaction_figure(table: ReachTable, gravity: bool, path: Path) -> Path:
    fig = _figure(9, 9)
    speed_ax, *joint_axes = fig.subplots(3, 1, sharex=True, height_ratios=(1, 2, 2))
    speed_ax.plot(table.t, np.hypot(table.hand_velocity[:, 0], table.hand_velocity[:, 1]), color="black")
    speed_ax.set_ylabel("hand speed (m/s)")
    plane = "vertical plane, gravity on" if gravity else "horizontal plane, no gravity"
    speed_ax.set_title(f"A fast minimum-jerk reach out and back ({plane}): the torques it takes")
    for j, (ax, joint) in enumerate(zip(joint_axes, ("shoulder", "elbow"), strict=True)):
        for name, label, colour in COMPONENTS:
            values = table.parts[name][:, j]
            if np.any(values != 0.0):
                ax.plot(table.t, values, color=colour, label=label)
        ax.plot(table.t, table.total[:, j], color="black", lw=2.2, label="total (inverse dynamics)")
        ax.axhline(0.0, color="grey", lw=0.6)
        ax.set_ylabel(f"{joint} torque (N m)")
        ax.legend(loc="upper right", fontsize="small")
        ax.grid(alpha=0.3)
    joint_axes[-1].set_xlabel("time (s)")
    for ax in (speed_ax, *joint_axes):
        ax.grid(alpha=0.3)
    return _save(fig, path)
