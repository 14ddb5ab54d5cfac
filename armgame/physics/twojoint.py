"""Kinematics and dynamics of the planar two-joint arm.

Derived here from the Lagrangian L = T - U (and checked against a SymPy derivation in
``tests/test_derivation.py``), in the armgame convention: shoulder at the origin, x forward,
y up, q1 the shoulder angle from +x (counter-clockwise), q2 the elbow angle relative to the
upper arm. With the shorthand

    a = i1 + i2 + m1 r1^2 + m2 (l1^2 + r2^2),   b = m2 l1 r2,   d = i2 + m2 r2^2

the equations of motion  tau = M(q) qdd + C(q, qd) + G(q) + B qd  have

    M = [[a + 2 b cos q2, d + b cos q2],
         [d + b cos q2,   d           ]]
    C = b sin q2 [-(2 qd1 qd2 + qd2^2), qd1^2]
    G = g [(m1 r1 + m2 l1) cos q1 + m2 r2 cos(q1 + q2), m2 r2 cos(q1 + q2)]

The tutorial measures its shoulder angle a1 from the downward vertical, so q1 = a1 - pi/2
and q2 = a2; its G then reads with sines, which is the same torque.

Two forms of the same equations live here:

* ``TwoJointArm`` methods take arrays whose last axis holds the joint components
  (``q[..., 0]`` shoulder, ``q[..., 1]`` elbow) with any leading batch dimensions: one state
  and a batch of states run the same code.
* ``component_dynamics`` returns closures over separate components (q1, q2, qd1, qd2, ...)
  for the integrators. Given ``math`` functions they run on Python floats, which is about
  thirty times faster than numpy for one arm stepped per frame; given numpy functions the
  same closures step a whole batch of arms held as one array per component.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import UserError
from .hand import hand_xy_arrays
from .params import TwoJointParams
from .trig import cos as trig_cos
from .trig import cos_array, sin_array, sin_cos, sin_cos_array
from .trig import sin as trig_sin

FloatArray = NDArray[np.float64]


class UnreachableError(UserError, ValueError):
    """A hand position outside the arm's annular workspace."""


@dataclass(frozen=True)
class ComponentDynamics:
    """The equations of motion as functions of separate components.

    ``accel(q1, q2, w1, w2, t1, t2) -> (qdd1, qdd2)``;
    ``momentum(q1, q2, w1, w2) -> (p1, p2)`` with p = M(q) qd;
    ``velocity(q1, q2, p1, p2) -> (w1, w2)``;
    ``hamilton(q1, q2, p1, p2, t1, t2) -> (dq1, dq2, dp1, dp2)``, the same motion written
    on (q, p), which the energy-keeping integrators need;
    ``largest(*xs)``, the largest absolute value over components (floats or arrays).
    """

    accel: Callable[..., tuple[Any, Any]]
    momentum: Callable[..., tuple[Any, Any]]
    velocity: Callable[..., tuple[Any, Any]]
    hamilton: Callable[..., tuple[Any, Any, Any, Any]]
    largest: Callable[..., float]


def largest_abs_float(*xs: float) -> float:
    return max(map(abs, xs))


def largest_abs_array(*xs: Any) -> float:
    return max(float(np.max(np.abs(x))) for x in xs)


class TwoJointArm:
    """The two-joint arm's kinematics and dynamics for arrays of states."""

    def __init__(self, params: TwoJointParams) -> None:
        self.params = params
        p = params
        self.a = p.i1 + p.i2 + p.m1 * p.r1**2 + p.m2 * (p.l1**2 + p.r2**2)
        self.b = p.m2 * p.l1 * p.r2
        self.d = p.i2 + p.m2 * p.r2**2
        self.g1 = p.gravity * (p.m1 * p.r1 + p.m2 * p.l1)
        self.g2 = p.gravity * p.m2 * p.r2
        self._components: dict[str, ComponentDynamics] = {}

    # ----------------------------------------------------------------- kinematics
    def elbow(self, q: ArrayLike) -> FloatArray:
        q = np.asarray(q, dtype=float)
        l1 = self.params.l1
        return np.stack([l1 * np.cos(q[..., 0]), l1 * np.sin(q[..., 0])], axis=-1)

    def hand(self, q: ArrayLike) -> FloatArray:
        q = np.asarray(q, dtype=float)
        l1, l2 = self.params.l1, self.params.l2
        return np.stack(hand_xy_arrays(l1, l2, q[..., 0], q[..., 1]), axis=-1)

    def jacobian(self, q: ArrayLike) -> FloatArray:
        """d(hand)/dq, shape (..., 2, 2): rows x, y; columns shoulder, elbow."""
        q = np.asarray(q, dtype=float)
        l1, l2 = self.params.l1, self.params.l2
        q12 = q[..., 0] + q[..., 1]
        s1, c1 = np.sin(q[..., 0]), np.cos(q[..., 0])
        s12, c12 = np.sin(q12), np.cos(q12)
        row_x = np.stack([-l1 * s1 - l2 * s12, -l2 * s12], axis=-1)
        row_y = np.stack([l1 * c1 + l2 * c12, l2 * c12], axis=-1)
        return np.stack([row_x, row_y], axis=-2)

    def hand_velocity(self, q: ArrayLike, qd: ArrayLike) -> FloatArray:
        return np.einsum("...ij,...j->...i", self.jacobian(q), np.asarray(qd, dtype=float))

    def inverse_kinematics(self, hand: ArrayLike, elbow_sign: float = 1.0) -> FloatArray:
        """Joint angles that put the hand at ``hand``.

        ``elbow_sign`` picks one of the two solutions: +1 for q2 >= 0 (elbow bent
        counter-clockwise), -1 for q2 <= 0. Raises UnreachableError for any point
        nearer than |l1 - l2| or further than l1 + l2 from the shoulder.
        """
        hand = np.asarray(hand, dtype=float)
        l1, l2 = self.params.l1, self.params.l2
        x, y = hand[..., 0], hand[..., 1]
        cos_q2 = (x * x + y * y - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
        # Points within rounding of the workspace boundary are reachable (arm straight or folded).
        if np.any(~np.isfinite(cos_q2)) or np.any(np.abs(cos_q2) > 1.0 + 1e-12):
            bad = np.argmax(~np.isfinite(cos_q2) | (np.abs(cos_q2) > 1.0 + 1e-12))
            bx, by = np.ravel(x)[bad], np.ravel(y)[bad]
            raise UnreachableError(
                f"hand position ({bx:.4g}, {by:.4g}) m is out of reach: its distance from the shoulder "
                f"must lie between {abs(l1 - l2):.4g} and {l1 + l2:.4g} m"
            )
        q2 = np.copysign(np.arccos(np.clip(cos_q2, -1.0, 1.0)), elbow_sign)
        q1 = np.arctan2(y, x) - np.arctan2(l2 * np.sin(q2), l1 + l2 * np.cos(q2))
        return np.stack([q1, q2], axis=-1)

    def inverse_kinematics_both(self, hand: ArrayLike) -> tuple[FloatArray, FloatArray]:
        return self.inverse_kinematics(hand, 1.0), self.inverse_kinematics(hand, -1.0)

    # ------------------------------------------------------------------- dynamics
    def mass_matrix(self, q: ArrayLike) -> FloatArray:
        q = np.asarray(q, dtype=float)
        c2 = np.cos(q[..., 1])
        m11 = self.a + 2.0 * self.b * c2
        m12 = self.d + self.b * c2
        m22 = np.broadcast_to(self.d, m11.shape)
        return np.stack([np.stack([m11, m12], -1), np.stack([m12, m22], -1)], -2)

    def coriolis(self, q: ArrayLike, qd: ArrayLike) -> FloatArray:
        """Coriolis-centrifugal torques C(q, qd) (on the same side as M qdd)."""
        q, qd = np.asarray(q, dtype=float), np.asarray(qd, dtype=float)
        h = self.b * np.sin(q[..., 1])
        w1, w2 = qd[..., 0], qd[..., 1]
        return np.stack([-h * (2.0 * w1 * w2 + w2 * w2), h * w1 * w1], axis=-1)

    def gravity(self, q: ArrayLike) -> FloatArray:
        q = np.asarray(q, dtype=float)
        c12 = np.cos(q[..., 0] + q[..., 1])
        return np.stack([self.g1 * np.cos(q[..., 0]) + self.g2 * c12, self.g2 * c12], axis=-1)

    def damping(self, qd: ArrayLike) -> FloatArray:
        qd = np.asarray(qd, dtype=float)
        return qd * np.array([self.params.damping1, self.params.damping2])

    def forward_dynamics(self, q: ArrayLike, qd: ArrayLike, tau: ArrayLike) -> FloatArray:
        """qdd = M(q)^-1 (tau - C - G - B qd), the 2x2 system solved in closed form."""
        q, qd = np.asarray(q, dtype=float), np.asarray(qd, dtype=float)
        f = np.asarray(tau, dtype=float) - self.coriolis(q, qd) - self.gravity(q) - self.damping(qd)
        c2 = np.cos(q[..., 1])
        m11 = self.a + 2.0 * self.b * c2
        m12 = self.d + self.b * c2
        det = m11 * self.d - m12 * m12
        f1, f2 = f[..., 0], f[..., 1]
        return np.stack([(self.d * f1 - m12 * f2) / det, (m11 * f2 - m12 * f1) / det], axis=-1)

    def inverse_dynamics(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> FloatArray:
        """tau = M(q) qdd + C(q, qd) + G(q) + B qd."""
        q, qd, qdd = (np.asarray(v, dtype=float) for v in (q, qd, qdd))
        inertial = np.einsum("...ij,...j->...i", self.mass_matrix(q), qdd)
        return inertial + self.coriolis(q, qd) + self.gravity(q) + self.damping(qd)

    def kinetic_energy(self, q: ArrayLike, qd: ArrayLike) -> FloatArray:
        qd = np.asarray(qd, dtype=float)
        return 0.5 * np.einsum("...i,...ij,...j->...", qd, self.mass_matrix(q), qd)

    def potential_energy(self, q: ArrayLike) -> FloatArray:
        """Gravitational energy, zero with the arm hanging straight down (as the tutorial sets it)."""
        q = np.asarray(q, dtype=float)
        return self.g1 * (np.sin(q[..., 0]) + 1.0) + self.g2 * (np.sin(q[..., 0] + q[..., 1]) + 1.0)

    def energy(self, q: ArrayLike, qd: ArrayLike) -> FloatArray:
        return self.kinetic_energy(q, qd) + self.potential_energy(q)

    def momentum(self, q: ArrayLike, qd: ArrayLike) -> FloatArray:
        """Generalised momenta p = M(q) qd."""
        return np.einsum("...ij,...j->...i", self.mass_matrix(q), np.asarray(qd, dtype=float))

    # ------------------------------------------------------- component closures
    def component_dynamics(self, backend: str = "float") -> ComponentDynamics:
        """The equations of motion as closures on components: ``"float"`` or ``"numpy"``."""
        if backend not in self._components:
            if backend == "float":
                self._components[backend] = self._build_components(sin_cos, trig_cos, trig_sin,
                                                                   largest_abs_float)
            elif backend == "numpy":
                self._components[backend] = self._build_components(sin_cos_array, cos_array, sin_array,
                                                                   largest_abs_array)
            else:
                raise ValueError(f"unknown backend {backend!r}: use 'float' or 'numpy'")
        return self._components[backend]

    def _build_components(self, sin_cos: Callable, cos: Callable, sin: Callable,
                          largest: Callable) -> ComponentDynamics:
        # The joint angles' trig is the arm's own (physics.trig), the same bits in C, numpy and Python.
        a, b, d = self.a, self.b, self.d
        g1, g2 = self.g1, self.g2
        k1, k2 = self.params.damping1, self.params.damping2
        extra_forces = self.params.has_gravity or self.params.has_damping

        # det(M) = a d - d^2 - (b cos q2)^2 and m11 = m12 + (a - d) + b cos q2: fewer operations
        # than forming M, which matters because one arm's RK4 step calls accel four times.
        det0 = a * d - d * d
        a_minus_d = a - d

        def accel_unforced(q1, q2, w1, w2, t1, t2):
            # Only the bias of a horizontal, undamped arm: the common game case pays for nothing else.
            sn, cs = sin_cos(q2)
            bc = b * cs
            h = b * sn
            m12 = d + bc
            f1 = t1 + h * (w1 + w1 + w2) * w2
            f2 = t2 - h * w1 * w1
            r = 1.0 / (det0 - bc * bc)
            return (d * f1 - m12 * f2) * r, ((m12 + a_minus_d + bc) * f2 - m12 * f1) * r

        def accel_with_gravity_and_damping(q1, q2, w1, w2, t1, t2):
            # accel_unforced written out again: a nested call would cost a tenth of an RK4 step.
            gc12 = g2 * cos(q1 + q2)
            sn, cs = sin_cos(q2)
            bc = b * cs
            h = b * sn
            m12 = d + bc
            f1 = t1 + h * (w1 + w1 + w2) * w2 - g1 * cos(q1) - gc12 - k1 * w1
            f2 = t2 - h * w1 * w1 - gc12 - k2 * w2
            r = 1.0 / (det0 - bc * bc)
            return (d * f1 - m12 * f2) * r, ((m12 + a_minus_d + bc) * f2 - m12 * f1) * r

        def accel_with_damping(q1, q2, w1, w2, t1, t2):
            # The game's arm: viscous joints in the horizontal plane, and no gravity to pay for.
            sn, cs = sin_cos(q2)
            bc = b * cs
            h = b * sn
            m12 = d + bc
            f1 = t1 + h * (w1 + w1 + w2) * w2 - k1 * w1
            f2 = t2 - h * w1 * w1 - k2 * w2
            r = 1.0 / (det0 - bc * bc)
            return (d * f1 - m12 * f2) * r, ((m12 + a_minus_d + bc) * f2 - m12 * f1) * r

        def momentum(q1, q2, w1, w2):
            c = cos(q2)
            m12 = d + b * c
            return (a + 2.0 * b * c) * w1 + m12 * w2, m12 * w1 + d * w2

        def velocity(q1, q2, p1, p2):
            c = cos(q2)
            m11 = a + 2.0 * b * c
            m12 = d + b * c
            det = m11 * d - m12 * m12
            return (d * p1 - m12 * p2) / det, (m11 * p2 - m12 * p1) / det

        def hamilton_unforced(q1, q2, p1, p2, t1, t2):
            c = cos(q2)
            m11 = a + 2.0 * b * c
            m12 = d + b * c
            det = m11 * d - m12 * m12
            w1 = (d * p1 - m12 * p2) / det
            w2 = (m11 * p2 - m12 * p1) / det
            # dp/dt = dL/dq + tau; dL/dq2 = 1/2 qd' (dM/dq2) qd = -b sin(q2) (qd1^2 + qd1 qd2).
            return w1, w2, t1, t2 - b * sin(q2) * w1 * (w1 + w2)

        def hamilton_with_gravity_and_damping(q1, q2, p1, p2, t1, t2):
            c = cos(q2)
            m11 = a + 2.0 * b * c
            m12 = d + b * c
            det = m11 * d - m12 * m12
            w1 = (d * p1 - m12 * p2) / det
            w2 = (m11 * p2 - m12 * p1) / det
            c12 = cos(q1 + q2)
            return (
                w1,
                w2,
                t1 - g1 * cos(q1) - g2 * c12 - k1 * w1,
                t2 - b * sin(q2) * w1 * (w1 + w2) - g2 * c12 - k2 * w2,
            )

        if self.params.has_gravity:
            accel = accel_with_gravity_and_damping
        elif self.params.has_damping:
            accel = accel_with_damping
        else:
            accel = accel_unforced
        return ComponentDynamics(
            accel=accel,
            momentum=momentum,
            velocity=velocity,
            hamilton=hamilton_with_gravity_and_damping if extra_forces else hamilton_unforced,
            largest=largest,
        )
