"""Fixed-step integrators behind one interface, for one arm or a batch of arms.

Every scheme is written once, on components (q1, q2, qd1, qd2) and a torque (t1, t2) held
constant over the step. Fed Python floats it steps one arm as fast as Python allows; fed
numpy arrays (one value per arm) the very same code steps a batch.

Why two energy-keeping schemes work on (q, p) and not on (q, qd): the arm's mass matrix
depends on the elbow angle, so the map (q, qd) -> (q', qd') of semi-implicit Euler is not
symplectic for it, and after a fast spin it bleeds energy (three quarters within seconds at
1 ms). Implicit midpoint and the two-stage Gauss-Legendre method applied to Hamilton's
equations in (q, p = M(q) qd) are symplectic and symmetric: their energy error stays
bounded, without a trend, for as long as the run lasts.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import UserError
from ..words import unknown_name
from .twojoint import ComponentDynamics, largest_abs_float

# The implicit stages are solved by fixed-point iteration to round-off: a looser solve
# would reintroduce the energy drift the schemes exist to remove.
IMPLICIT_TOLERANCE = 1e-15
IMPLICIT_MAX_ITERATIONS = 60

StepFunction = Callable[..., tuple[Any, Any, Any, Any]]


def _euler(dyn: ComponentDynamics) -> StepFunction:
    accel = dyn.accel

    def step(q1, q2, w1, w2, t1, t2, dt):
        a1, a2 = accel(q1, q2, w1, w2, t1, t2)
        return q1 + dt * w1, q2 + dt * w2, w1 + dt * a1, w2 + dt * a2

    return step


def _symplectic_euler(dyn: ComponentDynamics) -> StepFunction:
    accel = dyn.accel

    def step(q1, q2, w1, w2, t1, t2, dt):
        a1, a2 = accel(q1, q2, w1, w2, t1, t2)
        w1 = w1 + dt * a1
        w2 = w2 + dt * a2
        return q1 + dt * w1, q2 + dt * w2, w1, w2

    return step


_SIXTH = 1.0 / 6.0


def _rk4(dyn: ComponentDynamics) -> StepFunction:
    accel = dyn.accel

    def step(q1, q2, w1, w2, t1, t2, dt):
        # Separate assignments, not tuple packing: this is the game's hot path, run per arm per step.
        h = 0.5 * dt
        a1, a2 = accel(q1, q2, w1, w2, t1, t2)
        v1 = w1 + h * a1
        v2 = w2 + h * a2
        b1, b2 = accel(q1 + h * w1, q2 + h * w2, v1, v2, t1, t2)
        u1 = w1 + h * b1
        u2 = w2 + h * b2
        c1, c2 = accel(q1 + h * v1, q2 + h * v2, u1, u2, t1, t2)
        s1 = w1 + dt * c1
        s2 = w2 + dt * c2
        d1, d2 = accel(q1 + dt * u1, q2 + dt * u2, s1, s2, t1, t2)
        k = dt * _SIXTH
        return (
            q1 + k * (w1 + s1 + 2.0 * (v1 + u1)),
            q2 + k * (w2 + s2 + 2.0 * (v2 + u2)),
            w1 + k * (a1 + d1 + 2.0 * (b1 + c1)),
            w2 + k * (a2 + d2 + 2.0 * (b2 + c2)),
        )

    return step


def _implicit_midpoint(dyn: ComponentDynamics) -> StepFunction:
    """z' = z + dt f((z + z') / 2) on z = (q, p), by fixed-point iteration on the slope."""
    hamilton, momentum, velocity, largest = dyn.hamilton, dyn.momentum, dyn.velocity, dyn.largest

    def step(q1, q2, w1, w2, t1, t2, dt):
        p1, p2 = momentum(q1, q2, w1, w2)
        h = 0.5 * dt
        scale = 1.0 + largest(q1, q2, p1, p2)
        k1, k2, k3, k4 = hamilton(q1, q2, p1, p2, t1, t2)
        for _ in range(IMPLICIT_MAX_ITERATIONS):
            n1, n2, n3, n4 = hamilton(q1 + h * k1, q2 + h * k2, p1 + h * k3, p2 + h * k4, t1, t2)
            change = largest(n1 - k1, n2 - k2, n3 - k3, n4 - k4) * dt
            k1, k2, k3, k4 = n1, n2, n3, n4
            if change <= IMPLICIT_TOLERANCE * scale:
                break
        q1, q2, p1, p2 = q1 + dt * k1, q2 + dt * k2, p1 + dt * k3, p2 + dt * k4
        w1, w2 = velocity(q1, q2, p1, p2)
        return q1, q2, w1, w2

    def step_floats(q1, q2, w1, w2, t1, t2, dt):
        # ``step`` for one arm on floats, bit for bit: the largest change taken in line (max of the same
        # values in the same order) and the bound once per step, some 8 iterations a step saved a call each.
        p1, p2 = momentum(q1, q2, w1, w2)
        h = 0.5 * dt
        bound = IMPLICIT_TOLERANCE * (1.0 + max(abs(q1), abs(q2), abs(p1), abs(p2)))
        k1, k2, k3, k4 = hamilton(q1, q2, p1, p2, t1, t2)
        for _ in range(IMPLICIT_MAX_ITERATIONS):
            n1, n2, n3, n4 = hamilton(q1 + h * k1, q2 + h * k2, p1 + h * k3, p2 + h * k4, t1, t2)
            change = max(abs(n1 - k1), abs(n2 - k2), abs(n3 - k3), abs(n4 - k4)) * dt
            k1, k2, k3, k4 = n1, n2, n3, n4
            if change <= bound:
                break
        q1, q2, p1, p2 = q1 + dt * k1, q2 + dt * k2, p1 + dt * k3, p2 + dt * k4
        w1, w2 = velocity(q1, q2, p1, p2)
        return q1, q2, w1, w2

    return step_floats if largest is largest_abs_float else step


_GL_A11 = 0.25
_GL_A12 = 0.25 - math.sqrt(3.0) / 6.0
_GL_A21 = 0.25 + math.sqrt(3.0) / 6.0
_GL_A22 = 0.25


def _gauss4(dyn: ComponentDynamics) -> StepFunction:
    """The two-stage Gauss-Legendre collocation method (order 4) on z = (q, p)."""
    hamilton, momentum, velocity, largest = dyn.hamilton, dyn.momentum, dyn.velocity, dyn.largest
    a11, a12, a21, a22 = _GL_A11, _GL_A12, _GL_A21, _GL_A22

    def step(q1, q2, w1, w2, t1, t2, dt):
        p1, p2 = momentum(q1, q2, w1, w2)
        scale = 1.0 + largest(q1, q2, p1, p2)
        k1, k2, k3, k4 = hamilton(q1, q2, p1, p2, t1, t2)
        j1, j2, j3, j4 = k1, k2, k3, k4
        for _ in range(IMPLICIT_MAX_ITERATIONS):
            x, y = a11 * dt, a12 * dt
            n1, n2, n3, n4 = hamilton(
                q1 + x * k1 + y * j1, q2 + x * k2 + y * j2, p1 + x * k3 + y * j3, p2 + x * k4 + y * j4, t1, t2
            )
            x, y = a21 * dt, a22 * dt
            m1, m2, m3, m4 = hamilton(
                q1 + x * n1 + y * j1, q2 + x * n2 + y * j2, p1 + x * n3 + y * j3, p2 + x * n4 + y * j4, t1, t2
            )
            change = largest(n1 - k1, n2 - k2, n3 - k3, n4 - k4, m1 - j1, m2 - j2, m3 - j3, m4 - j4) * dt
            k1, k2, k3, k4, j1, j2, j3, j4 = n1, n2, n3, n4, m1, m2, m3, m4
            if change <= IMPLICIT_TOLERANCE * scale:
                break
        h = 0.5 * dt
        q1, q2 = q1 + h * (k1 + j1), q2 + h * (k2 + j2)
        p1, p2 = p1 + h * (k3 + j3), p2 + h * (k4 + j4)
        w1, w2 = velocity(q1, q2, p1, p2)
        return q1, q2, w1, w2

    def step_floats(q1, q2, w1, w2, t1, t2, dt):
        # ``step`` on floats, bit for bit (as the midpoint's): the change in line, the stage weights once.
        p1, p2 = momentum(q1, q2, w1, w2)
        bound = IMPLICIT_TOLERANCE * (1.0 + max(abs(q1), abs(q2), abs(p1), abs(p2)))
        k1, k2, k3, k4 = hamilton(q1, q2, p1, p2, t1, t2)
        j1, j2, j3, j4 = k1, k2, k3, k4
        x1, y1, x2, y2 = a11 * dt, a12 * dt, a21 * dt, a22 * dt
        for _ in range(IMPLICIT_MAX_ITERATIONS):
            n1, n2, n3, n4 = hamilton(
                q1 + x1 * k1 + y1 * j1, q2 + x1 * k2 + y1 * j2, p1 + x1 * k3 + y1 * j3, p2 + x1 * k4 + y1 * j4,
                t1, t2,
            )
            m1, m2, m3, m4 = hamilton(
                q1 + x2 * n1 + y2 * j1, q2 + x2 * n2 + y2 * j2, p1 + x2 * n3 + y2 * j3, p2 + x2 * n4 + y2 * j4,
                t1, t2,
            )
            change = max(abs(n1 - k1), abs(n2 - k2), abs(n3 - k3), abs(n4 - k4),
                         abs(m1 - j1), abs(m2 - j2), abs(m3 - j3), abs(m4 - j4)) * dt
            k1, k2, k3, k4, j1, j2, j3, j4 = n1, n2, n3, n4, m1, m2, m3, m4
            if change <= bound:
                break
        h = 0.5 * dt
        q1, q2 = q1 + h * (k1 + j1), q2 + h * (k2 + j2)
        p1, p2 = p1 + h * (k3 + j3), p2 + h * (k4 + j4)
        w1, w2 = velocity(q1, q2, p1, p2)
        return q1, q2, w1, w2

    return step_floats if largest is largest_abs_float else step


@dataclass(frozen=True)
class Scheme:
    name: str
    order: int
    symplectic: bool
    build: Callable[[ComponentDynamics], StepFunction]
    description: str


SCHEMES: dict[str, Scheme] = {
    s.name: s
    for s in (
        Scheme("euler", 1, False, _euler, "explicit Euler on (q, qd)"),
        Scheme("symplectic-euler", 1, False, _symplectic_euler,
               "semi-implicit Euler on (q, qd): velocity first, as the 2012 game did"),
        Scheme("rk4", 4, False, _rk4, "classic fourth-order Runge-Kutta on (q, qd)"),
        Scheme("midpoint", 2, True, _implicit_midpoint, "implicit midpoint on (q, p): symplectic"),
        Scheme("gauss4", 4, True, _gauss4, "two-stage Gauss-Legendre on (q, p): symplectic, order 4"),
    )
}

#: Names accepted wherever an integrator is chosen; dop853 is the adaptive reference.
INTEGRATOR_NAMES = (*SCHEMES, "dop853")


class UnknownIntegratorError(UserError, ValueError):
    pass


def scheme(name: str) -> Scheme:
    try:
        return SCHEMES[name]
    except KeyError:
        raise UnknownIntegratorError(
            unknown_name("integrator", name, SCHEMES)
        ) from None


class Integrator:
    """A fixed-step scheme bound to an arm model.

    ``step(state, torque, dt)`` takes a state (q1, q2, qd1, qd2) and returns the next one:
    as a tuple of floats for ``backend="float"`` (one arm, the fast path), or as an array
    with the four state components on its last axis for ``backend="numpy"`` (any batch
    shape). ``step_components`` skips the packing for callers that keep components apart.
    """

    def __init__(self, name: str, model: Any, backend: str = "float") -> None:
        self.scheme = scheme(name)
        self.name = name
        self.backend = backend
        self.step_components: StepFunction = self.scheme.build(model.component_dynamics(backend))

    def step(self, state: Any, torque: Any, dt: float) -> Any:
        if self.backend == "float":
            q1, q2, w1, w2 = state
            t1, t2 = torque
            return self.step_components(q1, q2, w1, w2, t1, t2, dt)
        x = np.asarray(state, dtype=float)
        u = np.broadcast_to(np.asarray(torque, dtype=float), (*x.shape[:-1], 2))
        out = self.step_components(x[..., 0], x[..., 1], x[..., 2], x[..., 3], u[..., 0], u[..., 1], dt)
        return np.stack(out, axis=-1)

    def run(self, state: ArrayLike, torque: ArrayLike, dt: float, steps: int) -> NDArray[np.float64]:
        """``steps`` steps at constant torque; returns the (steps + 1, ..., 4) trajectory."""
        x = np.asarray(state, dtype=float)
        out = np.empty((steps + 1, *x.shape))
        out[0] = x
        current = tuple(map(float, x)) if self.backend == "float" else x
        for i in range(steps):
            current = self.step(current, torque, dt)
            out[i + 1] = current
        return out
