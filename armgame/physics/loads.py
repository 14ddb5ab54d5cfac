"""External loads on the two-joint arm: a force at the hand and a torque at the joints.

A force ``F`` at the hand does virtual work ``F . dx = F . J(q) dq``, so it enters the
equations of motion as the joint torque ``J(q)^T F`` (MotorNet's "endpoint load"), added to
the muscles' torque INSIDE the right-hand side: every stage of a Runge-Kutta step, and every
iterate of an implicit one, sees the force at its own state, so the integrator keeps its
order. A joint load adds ``torque + viscosity qd`` the same way.

Built-in hand fields (forces in N, positions in m, velocities in m/s, world frame: x forward,
y up):

* ``CurlField(b)``: ``F = b [[0, 1], [-1, 0]] v``. The matrix is antisymmetric, so
  ``v . F = 0``: the field pushes the hand sideways and does no work. With ``b > 0`` the force
  points 90 degrees clockwise from the hand's velocity (a reach bows clockwise).
* ``ConstantForce(fx, fy)``: a steady pull, e.g. a weight hung on the hand.
* ``SpringField(stiffness, anchor)``: ``F = -k (x - anchor)``, a spring to a point.
* ``ViscousField(matrix)``: ``F = B v`` with any 2 x 2 ``B`` (N s/m), as Shadmehr & Mussa-Ivaldi
  (1994) used. Its power is ``v . B v = v . sym(B) v``: only ``B``'s antisymmetric (curl) part does
  no work, so a field with a symmetric part feeds the arm energy or drains it.
* ``ChannelField(stiffness, damping, origin, direction)``: a force channel (error clamp): a spring
  and damper acting only across the straight line through ``origin`` along ``direction``,
  ``F = -(k d + c v_n) n`` with ``n`` the line's left normal, ``d`` the hand's signed distance
  from the line and ``v_n`` its velocity across it. Motion along the line is free.

``loaded_arm(model, loads)`` returns an object with the arm's ``component_dynamics`` whose
closures include the loads, for ``Integrator``. With no load it returns the arm itself, so a
scene without perturbations runs exactly the closures it ran before, at the same speed: the
game (``GameSession``) never builds a loaded arm at all.

A field may depend on time: the closures read ``clock.t``, which the caller sets before each
step (the time at the step's start, held over the step as the muscle torque is).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from . import trig
from .twojoint import ComponentDynamics, TwoJointArm


class HandForce(Protocol):
    """A force on the hand, ``force(x, y, vx, vy, t) -> (fx, fy)`` in N, on floats or numpy arrays."""

    def force(self, x: Any, y: Any, vx: Any, vy: Any, t: float) -> tuple[Any, Any]: ...


@dataclass(frozen=True)
class CurlField:
    """``F = b [[0, 1], [-1, 0]] v`` (N s/m): sideways, no work; ``b > 0`` pushes clockwise of the motion."""

    b: float

    def force(self, x: Any, y: Any, vx: Any, vy: Any, t: float) -> tuple[Any, Any]:
        b = self.b
        return b * vy, -b * vx


@dataclass(frozen=True)
class ConstantForce:
    """A steady force (N) on the hand."""

    fx: float
    fy: float

    def force(self, x: Any, y: Any, vx: Any, vy: Any, t: float) -> tuple[Any, Any]:
        return self.fx + 0.0 * x, self.fy + 0.0 * y


@dataclass(frozen=True)
class SpringField:
    """``F = -stiffness (x - anchor)`` (N/m): the hand tied to a point by a spring of zero rest length."""

    stiffness: float
    anchor: tuple[float, float]

    def force(self, x: Any, y: Any, vx: Any, vy: Any, t: float) -> tuple[Any, Any]:
        k = self.stiffness
        return -k * (x - self.anchor[0]), -k * (y - self.anchor[1])


@dataclass(frozen=True)
class ViscousField:
    """``F = B v`` (N s/m) for a full matrix ``B = ((b11, b12), (b21, b22))``; its symmetric part does work."""

    matrix: tuple[tuple[float, float], tuple[float, float]]

    def force(self, x: Any, y: Any, vx: Any, vy: Any, t: float) -> tuple[Any, Any]:
        (b11, b12), (b21, b22) = self.matrix
        return b11 * vx + b12 * vy, b21 * vx + b22 * vy


@dataclass(frozen=True)
class ChannelField:
    """A force channel along the line through ``origin`` with unit ``direction`` (ux, uy): a spring
    (``stiffness``, N/m) and a damper (``damping``, N s/m) across the line only, so the hand moves freely
    along it and is held on it. ``lateral`` is the force's signed size along the left normal ``(-uy, ux)``."""

    stiffness: float
    damping: float
    origin: tuple[float, float]
    direction: tuple[float, float]

    def lateral(self, x: Any, y: Any, vx: Any, vy: Any) -> Any:
        """The channel's force on the hand across the line (N, + = to the left of the line's direction)."""
        ux, uy = self.direction
        d = -uy * (x - self.origin[0]) + ux * (y - self.origin[1])
        vn = -uy * vx + ux * vy
        return -(self.stiffness * d + self.damping * vn)

    def force(self, x: Any, y: Any, vx: Any, vy: Any, t: float) -> tuple[Any, Any]:
        ux, uy = self.direction
        f = self.lateral(x, y, vx, vy)
        return -uy * f, ux * f


@dataclass(frozen=True)
class JointLoad:
    """Joint torques ``torque + viscosity @ qd`` (N m; N m s/rad), added to the muscles'."""

    torque: tuple[float, float] = (0.0, 0.0)
    viscosity: tuple[tuple[float, float], tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))


@dataclass
class Clock:
    """The time (s) a time-dependent field is evaluated at; the caller moves it between steps."""

    t: float = 0.0


@dataclass(frozen=True)
class Loads:
    """What pushes on the arm besides its muscles. Empty by default: the arm's own closures run."""

    hand: HandForce | None = None
    joint: JointLoad | None = None
    clock: Clock = field(default_factory=Clock, compare=False)

    @property
    def empty(self) -> bool:
        return self.hand is None and self.joint is None


def hand_force_torque(model: TwoJointArm, force: HandForce, q: Any, qd: Any, t: float = 0.0) -> np.ndarray:
    """``J(q)^T F(x, v, t)`` for arrays of states (last axis: joints): the loads' torque, computed
    through ``TwoJointArm``'s own kinematics (the closures below write it out by hand)."""
    q, qd = np.asarray(q, dtype=float), np.asarray(qd, dtype=float)
    x = model.hand(q)
    v = model.hand_velocity(q, qd)
    fx, fy = force.force(x[..., 0], x[..., 1], v[..., 0], v[..., 1], t)
    f = np.stack(np.broadcast_arrays(fx, fy), axis=-1)
    return np.einsum("...ji,...j->...i", model.jacobian(q), f)


class LoadedArm:
    """A ``TwoJointArm`` with loads: ``component_dynamics(backend)`` includes them; everything else
    (kinematics, energy, the unloaded dynamics) is the arm's own.

    ``arm_sine``: the hand and the Jacobian a hand force acts through take the arm's own sine (``physics.trig``,
    the same bits on every machine and in the browser's lab) instead of the C library's (the float backend's
    default, which the compiled fields of ``_ckernel.c`` match)."""

    def __init__(self, model: TwoJointArm, loads: Loads, arm_sine: bool = False) -> None:
        self.model = model
        self.params = model.params
        self.loads = loads
        self.arm_sine = arm_sine
        self._components: dict[str, ComponentDynamics] = {}

    def __getattr__(self, name: str) -> Any:
        return getattr(self.model, name)

    def component_dynamics(self, backend: str = "float") -> ComponentDynamics:
        if backend not in self._components:
            base = self.model.component_dynamics(backend)
            if backend == "float" and self.arm_sine:
                built = _with_loads(base, self.model, self.loads, trig.cos, trig.sin)
            elif backend == "float":
                built = _with_loads(base, self.model, self.loads, math.cos, math.sin)
            else:
                built = _with_loads(base, self.model, self.loads, np.cos, np.sin)
            self._components[backend] = built
        return self._components[backend]


def loaded_arm(model: TwoJointArm, loads: Loads | None, arm_sine: bool = False) -> TwoJointArm | LoadedArm:
    """The arm itself when nothing loads it (today's closures, untouched), else a ``LoadedArm``."""
    if loads is None or loads.empty:
        return model
    return LoadedArm(model, loads, arm_sine)


def _with_loads(base: ComponentDynamics, model: TwoJointArm, loads: Loads, cos: Callable,
                sin: Callable) -> ComponentDynamics:
    l1, l2 = model.params.l1, model.params.l2
    hand, joint, clock = loads.hand, loads.joint, loads.clock
    force = hand.force if hand is not None else None
    c1, c2 = joint.torque if joint is not None else (0.0, 0.0)
    (v11, v12), (v21, v22) = joint.viscosity if joint is not None else ((0.0, 0.0), (0.0, 0.0))

    def external(q1, q2, w1, w2):
        e1 = c1 + v11 * w1 + v12 * w2
        e2 = c2 + v21 * w1 + v22 * w2
        if force is not None:
            s1, k1 = sin(q1), cos(q1)
            s12, k12 = sin(q1 + q2), cos(q1 + q2)
            # J = [[j11, j12], [j21, j22]]: rows x, y of the hand; columns shoulder, elbow.
            j12 = -l2 * s12
            j22 = l2 * k12
            j11 = -l1 * s1 + j12
            j21 = l1 * k1 + j22
            fx, fy = force(l1 * k1 + l2 * k12, l1 * s1 + l2 * s12, j11 * w1 + j12 * w2, j21 * w1 + j22 * w2,
                           clock.t)
            e1 = e1 + j11 * fx + j21 * fy
            e2 = e2 + j12 * fx + j22 * fy
        return e1, e2

    base_accel, base_hamilton, velocity = base.accel, base.hamilton, base.velocity

    def accel(q1, q2, w1, w2, t1, t2):
        e1, e2 = external(q1, q2, w1, w2)
        return base_accel(q1, q2, w1, w2, t1 + e1, t2 + e2)

    def hamilton(q1, q2, p1, p2, t1, t2):
        w1, w2 = velocity(q1, q2, p1, p2)
        e1, e2 = external(q1, q2, w1, w2)
        return base_hamilton(q1, q2, p1, p2, t1 + e1, t2 + e2)

    return ComponentDynamics(accel=accel, momentum=base.momentum, velocity=velocity, hamilton=hamilton,
                             largest=base.largest)
