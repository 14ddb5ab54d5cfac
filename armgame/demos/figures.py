"""The demos' figures, drawn with matplotlib (the optional ``plot`` extra) straight to PNG files.

Each is a 16:9 slide in the style of ``armgame.plotstyle`` (1920 x 1080 px, no text under 10 pt,
legends off the data), built on ``matplotlib.figure.Figure``, so a headless run never needs a display.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import plotstyle
from .reach import COMPONENTS, ReachTable
from .runs import VISIBLY_APART

ARM_A, ARM_B = "#223344", "#ff7f0e"


def require_matplotlib() -> None:
    plotstyle.require_matplotlib("plot", "pass --no-figures")


def _figure(width: float, height: float) -> Any:
    return plotstyle.slide_figure(width, height)


def _save(fig: Any, path: Path) -> Path:
    return plotstyle.save(fig, path)


def _slide(draw: Callable[..., Path]) -> Callable[..., Path]:
    """Build and save a figure in the slide style (``armgame.plotstyle``), matplotlib checked first."""

    @functools.wraps(draw)
    def wrapped(*args: Any, **kwargs: Any) -> Path:
        require_matplotlib()
        with plotstyle.slide_style():
            return draw(*args, **kwargs)

    return wrapped


@_slide
def pendulum_figure(t: NDArray[np.float64], q: NDArray[np.float64], qd: NDArray[np.float64], path: Path) -> Path:
    """The tutorial's figure: its angle (from hanging straight down) and angular velocity, each on its own axis."""
    fig = _figure(16, 9)
    angle_ax, velocity_ax = fig.subplots(2, 1, sharex=True)
    angle_ax.plot(t, np.degrees(q) + 90.0, color=ARM_A)
    angle_ax.set_ylabel("angle from hanging (deg)")
    velocity_ax.plot(t, np.degrees(qd), color=ARM_B)
    velocity_ax.set_ylabel("angular velocity (deg/s)")
    velocity_ax.set_xlabel("time (s)")
    for ax in (angle_ax, velocity_ax):
        ax.axhline(0.0, color="grey", lw=0.8)
    fig.suptitle("One-joint passive arm released from 90 deg (the tutorial's pendulum)")
    return _save(fig, path)


def _hand_axes(ax: Any, title: str) -> None:
    ax.plot(0.0, 0.0, "s", color="black", ms=9, label="shoulder")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title)


def _legend_above(ax: Any, ncols: int) -> None:
    """A legend in a row above the panel, off the data."""
    ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.01, 1.0, 0.1), ncols=ncols, frameon=False, borderaxespad=0.0,
              mode="expand")


@_slide
def passive_figure(t: NDArray[np.float64], q: NDArray[np.float64], hand: NDArray[np.float64], path: Path) -> Path:
    fig = _figure(16, 9)
    left, right = fig.subplots(1, 2, width_ratios=(1.5, 1))
    left.plot(t, np.degrees(q[:, 0]), color=ARM_A, label="shoulder q1 (from +x)")
    left.plot(t, np.degrees(q[:, 1]), color=ARM_B, label="elbow q2 (from the upper arm)")
    left.set_xlabel("time (s)")
    left.set_ylabel("joint angle (deg)")
    _legend_above(left, 2)
    right.plot(hand[:, 0], hand[:, 1], color=ARM_A, lw=1.0, label="hand path")
    right.plot(hand[0, 0], hand[0, 1], "o", color="tab:green", ms=10, label="start")
    _hand_axes(right, "")
    _legend_above(right, 3)
    fig.suptitle("Two-joint passive arm: joint angles and the hand's path")
    return _save(fig, path)


@_slide
def chaos_figure(t: NDArray[np.float64], distance: NDArray[np.float64], hand_a: NDArray[np.float64],
                 hand_b: NDArray[np.float64], path: Path) -> Path:
    fig = _figure(16, 9)
    left, right = fig.subplots(1, 2, width_ratios=(1.5, 1))
    left.semilogy(t, np.maximum(distance, 1e-16), color="black", label="distance between the hands")
    left.axhline(VISIBLY_APART, color="tab:red", ls="--", lw=1.5, label=f"visibly apart ({VISIBLY_APART * 100:g} cm)")
    apart = np.flatnonzero(distance > VISIBLY_APART)
    if len(apart):
        left.axvline(t[apart[0]], color="tab:red", ls=":", lw=1.5)
        title = f"Two passive arms 1e-6 rad apart: the hands part visibly at t = {t[apart[0]]:.1f} s"
    else:
        title = "Two passive arms 1e-6 rad apart: the distance between the hands"
    left.set_xlabel("time (s)")
    left.set_ylabel("distance between the hands (m)")
    left.grid(alpha=0.3, which="both")
    _legend_above(left, 2)
    right.plot(hand_a[:, 0], hand_a[:, 1], color=ARM_A, lw=1.0, label="arm A")
    right.plot(hand_b[:, 0], hand_b[:, 1], color=ARM_B, lw=1.0, alpha=0.8, label="arm B")
    _hand_axes(right, "")
    _legend_above(right, 3)
    fig.suptitle(title)
    return _save(fig, path)


def _bar_values(ax: Any, bars: Any, values: NDArray[np.float64], unit: str) -> None:
    """Each bar's value printed just past its end."""
    ax.bar_label(bars, labels=[f"{v:.2f} {unit}" for v in values], padding=4, fontsize=12)


@_slide
def interaction_figure(table: ReachTable, gravity: bool, path: Path) -> Path:
    """Speed and the torques over time (left), and each part's largest size per joint as bars (right).

    Both joints share one N m scale, in the traces and in the bars, so the shoulder's larger
    torques look larger.
    """
    fig = _figure(16, 9)
    left, right = fig.subfigures(1, 2, width_ratios=(1.6, 1))
    speed_ax, *joint_axes = left.subplots(3, 1, sharex=True, height_ratios=(1, 2, 2))
    joint_axes[1].sharey(joint_axes[0])
    speed_ax.plot(table.t, np.hypot(table.hand_velocity[:, 0], table.hand_velocity[:, 1]), color="black")
    speed_ax.set_ylabel("hand speed\n(m/s)")
    shown = [(name, label, colour) for name, label, colour in COMPONENTS if np.any(table.parts[name] != 0.0)]
    for j, (ax, joint) in enumerate(zip(joint_axes, ("shoulder", "elbow"), strict=True)):
        for name, label, colour in shown:
            ax.plot(table.t, table.parts[name][:, j], color=colour, label=label)
        ax.plot(table.t, table.total[:, j], color="black", lw=3, label="total (inverse dynamics)")
        ax.axhline(0.0, color="grey", lw=0.8)
        ax.set_ylabel(f"{joint} torque (N m)")
    joint_axes[-1].set_xlabel("time (s)")
    left.legend(*joint_axes[0].get_legend_handles_labels(), loc="outside lower center", ncols=3, frameon=False)
    bar_axes = right.subplots(2, 1, sharex=True)
    names = [label for _, label, _ in shown] + ["total"]
    colours = [colour for _, _, colour in shown] + ["black"]
    for j, (ax, joint) in enumerate(zip(bar_axes, ("shoulder", "elbow"), strict=True)):
        peaks = np.array([np.max(np.abs(table.parts[name][:, j])) for name, _, _ in shown]
                         + [np.max(np.abs(table.total[:, j]))])
        bars = ax.barh(np.arange(len(names)), peaks, color=colours)
        _bar_values(ax, bars, peaks, "N m")
        ax.set_yticks(np.arange(len(names)), [n.replace("interaction: ", "interaction,\n") for n in names])
        ax.invert_yaxis()
        ax.set_title(f"{joint}: peak |torque|")
        ax.grid(axis="y", visible=False)
    bar_axes[-1].set_xlabel("N m (one scale for both joints)")
    biggest = max(float(np.max(np.abs(table.total))), *(float(np.max(np.abs(table.parts[n]))) for n, _, _ in shown))
    bar_axes[0].set_xlim(0.0, biggest * 1.35)  # room for the printed values
    plane = "vertical plane, gravity on" if gravity else "horizontal plane, no gravity"
    fig.suptitle(f"A fast minimum-jerk reach out and back ({plane}): the torques it takes")
    return _save(fig, path)


@_slide
def planning_figure(planning: Any, path: Path) -> Path:
    """Both planned reaches: hand paths (left); hand speed and each joint's torque over time (right)."""
    fig = _figure(16, 9)
    left, right = fig.subfigures(1, 2, width_ratios=(1, 1.35))
    path_ax = left.subplots()
    speed_ax, *torque_axes = right.subplots(3, 1, sharex=True)
    torque_axes[1].sharey(torque_axes[0])
    arm = planning.arm
    reaches = ((planning.jerk, ARM_A, "-"), (planning.torque_change, ARM_B, "-"))
    for q, style in ((planning.jerk.q[0], "-"), (planning.jerk.q[-1], "--")):
        points = np.array([(0.0, 0.0), arm.elbow(q), arm.hand(q)])
        path_ax.plot(points[:, 0], points[:, 1], style, color="#b0b0b8", lw=6, solid_capstyle="round", zorder=1)
    for reach, colour, style in reaches:
        deviation = abs(reach.max_deviation())
        shape = "straight" if deviation < 1e-6 else f"curved, {deviation * 100:.1f} cm off the line"
        label = f"{reach.model} ({shape}; cost {reach.cost:.0f})"
        path_ax.plot(reach.hand[:, 0], reach.hand[:, 1], style, color=colour, lw=3, label=label)
        speed_ax.plot(reach.t, reach.speed, color=colour)
        for j, ax in enumerate(torque_axes):
            ax.plot(reach.t, reach.torque[:, j], color=colour)
    path_ax.plot(*planning.start, "o", color="tab:green", ms=12, label="start (grey arm)", zorder=3)
    path_ax.plot(*planning.target, "X", color="tab:red", ms=13, label="target (dashed arm)", zorder=3)
    _hand_axes(path_ax, "hand paths")
    left.legend(*path_ax.get_legend_handles_labels(), loc="outside lower center", ncols=1, frameon=False)
    speed_ax.set_ylabel("hand speed\n(m/s)")
    for ax, joint in zip(torque_axes, ("shoulder", "elbow"), strict=True):
        ax.axhline(0.0, color="grey", lw=0.8)
        ax.set_ylabel(f"{joint}\ntorque (N m)")
    torque_axes[-1].set_xlabel("time (s)")
    fig.suptitle("One reach planned two ways: minimum jerk (Flash & Hogan 1985) and minimum torque change "
                 "(Uno, Kawato & Suzuki 1989)")
    return _save(fig, path)


@_slide
def autopilot_figure(rows: Any, duration: float, path: Path) -> Path:
    """Hits of the two bots on each seed, side by side: knowing the interaction torques pays on every one."""
    fig = _figure(16, 9)
    ax = fig.subplots()
    seeds = np.arange(len(rows))
    width = 0.4
    for offset, name, colour, label in ((-width / 2, "model", ARM_A, "model: knows the interaction torques"),
                                        (width / 2, "naive", ARM_B, "naive: drives each joint alone")):
        hits = np.array([r.hits[name] for r in rows], dtype=float)
        bars = ax.bar(seeds + offset, hits, width, color=colour, label=label)
        ax.bar_label(bars, labels=[f"{h:g}" for h in hits], padding=3, fontsize=12)
    ax.set_xticks(seeds, [str(r.seed) for r in rows])
    ax.set_xlabel("seed (the game's target sequence)")
    ax.set_ylabel(f"hits in {duration:g} s")
    ax.grid(axis="x", visible=False)
    _legend_above(ax, 2)
    top = max(max(r.hits.values()) for r in rows)
    ax.set_ylim(0, max(top, 1) * 1.15)  # room for the printed values
    ax.yaxis.get_major_locator().set_params(integer=True)
    fig.suptitle("Two autopilots play the same games: the one that knows the arm's interaction torques hits more")
    return _save(fig, path)
