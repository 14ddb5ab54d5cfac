"""The planning demo: one reach planned as minimum jerk and as minimum torque change.

Two classic answers to "which of the infinitely many ways to reach does the brain pick?":

* **Minimum jerk** (Flash & Hogan 1985) is kinematic: the hand moves along the straight line with
  the bell-shaped speed of ``reach.minimum_jerk``, whatever the arm is made of.
* **Minimum torque change** (Uno, Kawato & Suzuki 1989) is dynamic: among the joint paths that start
  and end at rest at the same postures in the same time, pick the one minimising

      C = 1/2 int_0^T sum_i (d tau_i / dt)^2 dt,

  with tau the torques the arm's own dynamics (``TwoJointArm.inverse_dynamics`` of the game arm)
  demand. It predicts gently curved hand paths for some reaches, such as this one across the
  workspace.

Method. The joint angles are the minimum-jerk reach's joint path (inverse kinematics of the
straight hand path) plus ``basis_count`` polynomials per joint, ``phi_k(s) = (s (1 - s))^3 P_k(2 s - 1)``
with ``s = t / T`` and ``P_k`` the Legendre polynomials: each vanishes with its first two
derivatives at both ends, so every candidate starts and ends at the same postures at rest (zero
velocity and acceleration), and the coefficients all zero are exactly the minimum-jerk reach.
Velocities and accelerations are exact (the basis is differentiated as polynomials); the torques
come from inverse dynamics on a 1 ms grid, their rate from second-order central differences on
that grid, and the integral from the trapezoidal rule. C is a sum of squares of the sampled
torque rates, so ``scipy.optimize.least_squares`` (Levenberg-Marquardt) minimises it; it converges
in about ten evaluations of its Jacobian, and ``scipy.optimize.minimize`` (L-BFGS-B) reaches the
same cost far more slowly. Ten polynomials per joint put the cost within 0.1% of twelve and the
path within 0.01 mm; halving the grid step moves the cost by under 0.05%.

With no gravity and no damping (the game arm in its horizontal plane) every torque scales as
1 / T^2 when the movement time T changes, so the optimal path's shape does not depend on T, and
the optimal reach back is the reach out played backwards (the window plays it so).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import Legendre, Polynomial
from numpy.typing import NDArray

from ..errors import UserError
from ..physics.params import GAME_ARM
from ..physics.twojoint import TwoJointArm
from .reach import joint_motion, minimum_jerk

FloatArray = NDArray[np.float64]
Point = tuple[float, float]

#: From near the right shoulder out to the far left: a reach across the workspace, where the two
#: models part most visibly (about 4 cm at mid-reach on the game arm).
START: Point = (0.30, 0.20)
TARGET: Point = (-0.10, 0.60)
MOVE_TIME = 0.6  # s
BASIS_PER_JOINT = 10
GRID_STEP = 0.001  # s: the optimisation's grid, and the CSV's rows


def basis(count: int, s: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``phi_k(s) = w(s) P_k(2 s - 1)`` with ``w = (s (1 - s))^3``, for k < count, and their first two
    derivatives in s; each (len(s), count).

    Evaluated as the product ``w P_k`` (not as one expanded polynomial) so that all three vanish
    exactly, not merely to round-off, at s = 0 and 1: w, w' and w'' have integer coefficients and
    s or 1 - s as a factor.
    """
    s = np.asarray(s, dtype=float)
    w = Polynomial([0.0, 1.0, -1.0]) ** 3
    w0, w1, w2 = (w.deriv(k)(s)[:, None] for k in range(3))
    legendre = [Legendre.basis(k, domain=[0.0, 1.0]) for k in range(count)]
    p0, p1, p2 = (np.stack([p.deriv(k)(s) if k else p(s) for p in legendre], axis=1) for k in range(3))
    return w0 * p0, w1 * p0 + w0 * p1, w2 * p0 + 2.0 * w1 * p1 + w0 * p2


@dataclass(frozen=True)
class PlannedReach:
    """One model's reach sampled on the grid ``t`` (s); angles in rad, hand in m, torques in N m."""

    model: str  # "minimum jerk" or "minimum torque change"
    t: FloatArray  # (n,)
    q: FloatArray  # (n, 2)
    qd: FloatArray
    qdd: FloatArray
    hand: FloatArray  # (n, 2)
    hand_velocity: FloatArray  # (n, 2)
    torque: FloatArray  # (n, 2): inverse dynamics
    torque_rate: FloatArray  # (n, 2), N m / s
    cost: float  # 1/2 int |d tau/dt|^2 dt, N^2 m^2 / s

    @property
    def speed(self) -> FloatArray:
        return np.hypot(self.hand_velocity[:, 0], self.hand_velocity[:, 1])

    def deviation(self) -> FloatArray:
        """Signed distance (m) of the hand from the straight start-target line, + to its left."""
        start, end = self.hand[0], self.hand[-1]
        along = (end - start) / np.hypot(*(end - start))
        normal = np.array([-along[1], along[0]])
        return (self.hand - start) @ normal

    def max_deviation(self) -> float:
        """The signed deviation of largest size (m)."""
        d = self.deviation()
        return float(d[np.argmax(np.abs(d))])


@dataclass(frozen=True)
class Planning:
    """Both reaches and how the optimisation went."""

    start: Point
    target: Point
    duration: float
    jerk: PlannedReach
    torque_change: PlannedReach
    coefficients: FloatArray  # (basis_count, 2): the minimum-torque-change path's offsets from minimum jerk (rad)
    evaluations: int  # the optimiser's function evaluations, as scipy counts them
    optimality: float  # largest component of the cost's gradient at the optimum, over the cost
    arm: TwoJointArm

    def motion(self, t: FloatArray, which: str) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Joint angles, velocities and accelerations of one model (``jerk`` or ``torque_change``) at any
        times ``t``; before the reach it rests at the start, after it at the target."""
        coefficients = self.coefficients if which == "torque_change" else np.zeros_like(self.coefficients)
        return _motion(self.arm, self.start, self.target, self.duration, coefficients, np.asarray(t, dtype=float))


_ARM = TwoJointArm(GAME_ARM)


def _motion(arm: TwoJointArm, start: Point, target: Point, duration: float, coefficients: FloatArray,
            t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    pos, vel, acc = minimum_jerk(start, target, duration, t)
    q, qd, qdd = joint_motion(arm, pos, vel, acc)
    phi, phi1, phi2 = basis(len(coefficients), np.clip(t / duration, 0.0, 1.0))
    return q + phi @ coefficients, qd + phi1 @ coefficients / duration, qdd + phi2 @ coefficients / duration**2


def _trapezoid_weights(n: int, h: float) -> FloatArray:
    w = np.full(n, h)
    w[0] = w[-1] = h / 2.0
    return w


def plan_reach(start: Point = START, target: Point = TARGET, duration: float = MOVE_TIME,
               basis_count: int = BASIS_PER_JOINT, arm: TwoJointArm | None = None) -> Planning:
    """Minimum jerk and minimum torque change for one reach of the game arm (see the module text)."""
    from scipy.optimize import least_squares

    arm = _ARM if arm is None else arm
    if not (math.isfinite(duration) and 0.1 <= duration <= 5.0):
        raise UserError(f"a planned reach takes between 0.1 and 5 s, got {duration!r}")
    if not 1 <= basis_count <= 20:
        raise UserError(f"the planner takes 1 to 20 basis functions per joint, got {basis_count!r}")
    if math.dist(start, target) < 0.01:
        raise UserError("the reach's start and target must lie at least 1 cm apart")
    steps = max(50, round(duration / GRID_STEP))
    t = np.linspace(0.0, duration, steps + 1)
    h = t[1] - t[0]
    pos, vel, acc = minimum_jerk(start, target, duration, t)
    q0, qd0, qdd0 = joint_motion(arm, pos, vel, acc)  # raises UnreachableError (one line) off the workspace
    phi, phi1, phi2 = basis(basis_count, t / duration)
    phi1, phi2 = phi1 / duration, phi2 / duration**2
    root_weights = np.sqrt(0.5 * _trapezoid_weights(len(t), h))[:, None]

    def joints(c: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        coefficients = c.reshape(basis_count, 2)
        return q0 + phi @ coefficients, qd0 + phi1 @ coefficients, qdd0 + phi2 @ coefficients

    def torque_rate(torque: FloatArray) -> FloatArray:
        return np.gradient(torque, h, axis=0, edge_order=2)

    def residuals(c: FloatArray) -> FloatArray:
        # C = sum(residuals^2): the trapezoidal rule of 1/2 |d tau/dt|^2.
        return (root_weights * torque_rate(arm.inverse_dynamics(*joints(c)))).ravel()

    fit = least_squares(residuals, np.zeros(2 * basis_count), method="lm", xtol=1e-12, ftol=1e-12, gtol=1e-12)
    if not fit.success:  # the problem is fixed and smooth: this would be a defect, not bad input
        raise RuntimeError(f"minimum torque change did not converge: {fit.message}")

    def reach(model: str, c: FloatArray) -> PlannedReach:
        q, qd, qdd = joints(c)
        torque = arm.inverse_dynamics(q, qd, qdd)
        rate = torque_rate(torque)
        cost = float(np.sum(_trapezoid_weights(len(t), h) * 0.5 * np.sum(rate**2, axis=1)))
        return PlannedReach(model, t, q, qd, qdd, arm.hand(q), arm.hand_velocity(q, qd), torque, rate, cost)

    jerk = reach("minimum jerk", np.zeros(2 * basis_count))
    torque_change = reach("minimum torque change", fit.x)
    optimality = float(np.max(np.abs(2.0 * fit.jac.T @ fit.fun))) / max(torque_change.cost, 1e-300)
    return Planning(start, target, duration, jerk, torque_change, fit.x.reshape(basis_count, 2), int(fit.nfev),
                    optimality, arm)


class PlanningRun:
    """Both planned reaches played out and back, with the interface of ``runs.PassiveRun``.

    The motion is prescribed, so one cycle is tabulated at the step once and then indexed:
    a rest at the start, the reach, a rest at the target, the reach played backwards.
    """

    joints = 2
    rest = 0.5  # s

    def __init__(self, dt: float = 0.001, planning: Planning | None = None) -> None:
        self.planning = plan_reach() if planning is None else planning
        self.arm = self.model = self.planning.arm
        self.dt = dt
        p = self.planning
        self.cycle = 2.0 * (p.duration + self.rest)
        times = np.arange(max(1, round(self.cycle / dt))) * dt
        out_t = times - self.rest  # the reach out, resting before and after
        back = times >= self.cycle / 2.0
        # Backwards: the reach out at mirrored time, velocities negated.
        local = np.where(back, p.duration - (times - self.cycle / 2.0 - self.rest), out_t)
        sign = np.where(back, -1.0, 1.0)[:, None]
        self._rows = []
        self.speeds = []
        for which in ("jerk", "torque_change"):
            q, qd, _ = p.motion(local, which)
            self._rows.append(np.column_stack([q, sign * qd]))
            self.speeds.append(np.hypot(*self.arm.hand_velocity(q, qd).T))
        self.paths = [p.jerk.hand, p.torque_change.hand]
        self.reset()

    def reset(self) -> None:
        self.steps = 0
        self.states = [tuple(rows[0]) for rows in self._rows]
        self.previous = self.states

    @property
    def t(self) -> float:
        return self.steps * self.dt

    def step(self) -> None:
        self.steps += 1
        self.previous = self.states
        row = self.steps % len(self._rows[0])
        self.states = [tuple(rows[row]) for rows in self._rows]

    def tabulated_states(self) -> list[FloatArray]:
        """Each arm's cycle of states (n, 4), as a window frames the motion before showing it."""
        return list(self._rows)

    def arm_points(self, q1: float, q2: float) -> list[Point]:
        elbow = self.arm.elbow((q1, q2))
        hand = self.arm.hand((q1, q2))
        return [(0.0, 0.0), (float(elbow[0]), float(elbow[1])), (float(hand[0]), float(hand[1]))]

    def hand_speeds_now(self) -> tuple[float, float]:
        row = self.steps % len(self._rows[0])
        return float(self.speeds[0][row]), float(self.speeds[1][row])


def summary(p: Planning) -> str:
    jerk, mtc = p.jerk, p.torque_change
    return (f"reach ({p.start[0]:g}, {p.start[1]:g}) m to ({p.target[0]:g}, {p.target[1]:g}) m in {p.duration:g} s; "
            f"torque-change cost: minimum jerk {jerk.cost:.4g}, minimum torque change {mtc.cost:.4g} "
            f"({100 * (1 - mtc.cost / jerk.cost):.1f}% lower); largest deviation from the straight line: "
            f"minimum jerk {abs(jerk.max_deviation()):.1g} m, minimum torque change "
            f"{abs(mtc.max_deviation()) * 100:.2f} cm; peak hand speed "
            f"{jerk.speed.max():.2f} and {mtc.speed.max():.2f} m/s; peak torque shoulder "
            f"{np.abs(jerk.torque[:, 0]).max():.2f} and {np.abs(mtc.torque[:, 0]).max():.2f} N m, elbow "
            f"{np.abs(jerk.torque[:, 1]).max():.2f} and {np.abs(mtc.torque[:, 1]).max():.2f} N m; converged "
            f"(largest gradient component {p.optimality:.0e} of the cost)")
