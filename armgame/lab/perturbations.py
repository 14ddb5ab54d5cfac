"""A protocol's perturbation made concrete: the loads on the arm and the transform of the shown hand.

Visual transforms change the hand AS SHOWN AND SCORED: the task tests the transformed hand
against home and the targets, and the metrics measure it, as in the experiments, where the
subject sees only a cursor. Each transform is ``show(x, y, q1, q2) -> (x', y')`` on floats.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from ..physics.loads import ConstantForce, CurlField, JointLoad, Loads, SpringField, ViscousField
from .protocol import Perturbation

Display = Callable[[float, float, float, float], tuple[float, float]]


def loads_for(p: Perturbation, home: tuple[float, float]) -> Loads | None:
    """The hand force (or, for ``joint_viscous``, the joint torque) of a force perturbation; None for the others
    (the arm's own dynamics run)."""
    if p.kind == "curl":
        return Loads(hand=CurlField(p["b"])) if p["b"] != 0.0 else None
    if p.kind == "constant":
        return Loads(hand=ConstantForce(p["fx"], p["fy"])) if (p["fx"], p["fy"]) != (0.0, 0.0) else None
    if p.kind == "viscous":
        matrix = p.matrix
        return Loads(hand=ViscousField(matrix)) if any(v != 0.0 for row in matrix for v in row) else None  # type: ignore[union-attr]
    if p.kind == "joint_viscous":  # torque W qdot at the joints (issue 41), whatever the posture
        matrix = p.joint_matrix
        return Loads(joint=JointLoad(viscosity=matrix)) if any(v != 0.0 for row in matrix for v in row) else None  # type: ignore[union-attr]
    if p.kind == "spring":
        return Loads(hand=SpringField(p["stiffness"], home)) if p["stiffness"] != 0.0 else None
    return None


def rotation(angle_deg: float, centre: tuple[float, float]) -> Display:
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    cx, cy = centre

    def show(x: float, y: float, q1: float, q2: float) -> tuple[float, float]:
        dx, dy = x - cx, y - cy
        return cx + c * dx - s * dy, cy + s * dx + c * dy

    return show


def mirror(axis_deg: float, centre: tuple[float, float]) -> Display:
    # Reflection in the line through the centre with direction (cos a, sin a): the matrix [[cos 2a, sin 2a],
    # [sin 2a, -cos 2a]].
    c, s = math.cos(2.0 * math.radians(axis_deg)), math.sin(2.0 * math.radians(axis_deg))
    cx, cy = centre

    def show(x: float, y: float, q1: float, q2: float) -> tuple[float, float]:
        dx, dy = x - cx, y - cy
        return cx + c * dx + s * dy, cy + s * dx - c * dy

    return show


def joint_space(gain: float, centre: tuple[float, float], home_q: tuple[float, float]) -> Display:
    cx, cy = centre
    h1, h2 = home_q

    def show(x: float, y: float, q1: float, q2: float) -> tuple[float, float]:
        return cx + gain * (q1 - h1), cy + gain * (q2 - h2)

    return show


def display_for(p: Perturbation, home: tuple[float, float], home_q: tuple[float, float]) -> Display | None:
    """The transform of the shown hand, or None for the hand as it is."""
    if p.kind == "rotation":
        return rotation(p["angle"], home) if p["angle"] != 0.0 else None
    if p.kind == "mirror":
        return mirror(p["axis"], home)
    if p.kind == "jointspace":
        return joint_space(p["gain"], home, home_q)
    return None
