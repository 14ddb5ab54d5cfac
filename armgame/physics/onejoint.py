"""The one-joint arm (a physical pendulum), in the armgame convention.

q is the link's angle from +x, counter-clockwise; gravity pulls along -y. The equation of
motion, from L = 1/2 (i + m r^2) qd^2 - m g r sin q, is

    tau = (i + m r^2) qdd + m g r cos q + damping qd.

The tutorial measures theta from the downward vertical, so q = theta - pi/2: its start at
theta = 90 deg is q = 0, the link horizontal. As in the tutorial, the potential energy is zero
with the link hanging down: U = m g r (1 + sin q).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .params import OneJointParams
from .twojoint import ComponentDynamics, largest_abs_array, largest_abs_float

FloatArray = NDArray[np.float64]


class OneJointArm:
    """Kinematics and dynamics of the one-joint arm; angles are arrays of any shape."""

    def __init__(self, params: OneJointParams) -> None:
        self.params = params
        self.inertia = params.i + params.m * params.r**2
        self.gravity_gain = params.m * params.gravity * params.r
        self._components: dict[str, ComponentDynamics] = {}

    def hand(self, q: ArrayLike) -> FloatArray:
        q = np.asarray(q, dtype=float)
        return np.stack([self.params.l * np.cos(q), self.params.l * np.sin(q)], axis=-1)

    def gravity(self, q: ArrayLike) -> FloatArray:
        return self.gravity_gain * np.cos(np.asarray(q, dtype=float))

    def forward_dynamics(self, q: ArrayLike, qd: ArrayLike, tau: ArrayLike) -> FloatArray:
        qd = np.asarray(qd, dtype=float)
        return (np.asarray(tau, dtype=float) - self.gravity(q) - self.params.damping * qd) / self.inertia

    def inverse_dynamics(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> FloatArray:
        qd = np.asarray(qd, dtype=float)
        return self.inertia * np.asarray(qdd, dtype=float) + self.gravity(q) + self.params.damping * qd

    def kinetic_energy(self, q: ArrayLike, qd: ArrayLike) -> FloatArray:
        qd = np.asarray(qd, dtype=float)
        return 0.5 * self.inertia * qd * qd

    def potential_energy(self, q: ArrayLike) -> FloatArray:
        return self.gravity_gain * (1.0 + np.sin(np.asarray(q, dtype=float)))

    def energy(self, q: ArrayLike, qd: ArrayLike) -> FloatArray:
        return self.kinetic_energy(q, qd) + self.potential_energy(q)

    def small_angle_period(self) -> float:
        """Period of small swings about hanging straight down: 2 pi sqrt(I / (m g r))."""
        return 2.0 * math.pi * math.sqrt(self.inertia / self.gravity_gain)

    def component_dynamics(self, backend: str = "float") -> ComponentDynamics:
        """Closures for the two-degree-of-freedom integrators.

        The integrators are written once, for two degrees of freedom; this arm rides along
        with a second coordinate that no force reaches and that therefore stays at rest.
        """
        if backend not in self._components:
            if backend == "float":
                self._components[backend] = self._build_components(math.cos, largest_abs_float)
            elif backend == "numpy":
                self._components[backend] = self._build_components(np.cos, largest_abs_array)
            else:
                raise ValueError(f"unknown backend {backend!r}: use 'float' or 'numpy'")
        return self._components[backend]

    def _build_components(self, cos: Callable, largest: Callable) -> ComponentDynamics:
        inertia, gain, k = self.inertia, self.gravity_gain, self.params.damping

        def accel(q1, q2, w1, w2, t1, t2):
            return (t1 - gain * cos(q1) - k * w1) / inertia, 0.0 * w2

        def momentum(q1, q2, w1, w2):
            return inertia * w1, w2

        def velocity(q1, q2, p1, p2):
            return p1 / inertia, p2

        def hamilton(q1, q2, p1, p2, t1, t2):
            w1 = p1 / inertia
            return w1, p2, t1 - gain * cos(q1) - k * w1, 0.0 * p2

        return ComponentDynamics(accel, momentum, velocity, hamilton, largest)
