"""The interaction demo: a fast minimum-jerk reach and the joint torques it takes.

The hand follows Flash and Hogan's (1985) minimum-jerk path, a straight line with a bell-shaped
speed profile. Inverse kinematics turns it into joint motion and the arm's inverse dynamics into the
torques a brain would have to send. Each joint's torque is then split the way the tutorial's
"joint interaction torques" section reads the equations of motion,

    tau_i = M_ii qdd_i  +  M_ij qdd_j  +  C_i  +  G_i  (+ damping),

the first term the joint's own inertia, the next two what the *other* joint's motion costs it: its
acceleration (inertial interaction) and, through C, the velocities (Coriolis-centrifugal interaction:
C_1 holds only elbow velocity terms, C_2 only shoulder velocity). All of it comes from the model in
``armgame.physics``; nothing here re-derives the dynamics.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import UserError
from ..physics.params import GAME_ARM, STANDARD_GRAVITY
from ..physics.twojoint import TwoJointArm

FloatArray = NDArray[np.float64]
Point = tuple[float, float]

#: name, label, colour (hex): shared by the window's bars and the figure so the two read alike.
COMPONENTS: tuple[tuple[str, str, str], ...] = (
    ("own_inertial", "own inertia", "#1f77b4"),
    ("interaction_inertial", "interaction: inertial", "#ff7f0e"),
    ("coriolis_centrifugal", "interaction: Coriolis-centrifugal", "#d62728"),
    ("gravity", "gravity", "#2ca02c"),
    ("damping", "damping", "#7f7f7f"),
)


def minimum_jerk(start: ArrayLike, end: ArrayLike, duration: float,
                 t: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Position, velocity and acceleration, each (..., 2), of the minimum-jerk move at times ``t``.

    x(s) = x0 + (x1 - x0)(10 s^3 - 15 s^4 + 6 s^5), s = t / duration; before the move it rests at
    ``start`` and after it at ``end`` (velocity and acceleration are zero at both ends, so the pieces join).
    """
    x0, x1 = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    s = np.clip(np.asarray(t, dtype=float) / duration, 0.0, 1.0)[..., None]
    span = x1 - x0
    pos = x0 + span * (s**3 * (10.0 + s * (-15.0 + 6.0 * s)))
    vel = span * (s**2 * (30.0 + s * (-60.0 + 30.0 * s))) / duration
    acc = span * (s * (60.0 + s * (-180.0 + 120.0 * s))) / duration**2
    return pos, vel, acc


def hand_acceleration_bias(arm: TwoJointArm, q: ArrayLike, qd: ArrayLike) -> FloatArray:
    """dJ/dt qd: the hand's acceleration when the joints do not accelerate (centripetal terms)."""
    q, qd = np.asarray(q, dtype=float), np.asarray(qd, dtype=float)
    l1, l2 = arm.params.l1, arm.params.l2
    w1, w12 = qd[..., 0], qd[..., 0] + qd[..., 1]
    q12 = q[..., 0] + q[..., 1]
    x = -l1 * np.cos(q[..., 0]) * w1**2 - l2 * np.cos(q12) * w12**2
    y = -l1 * np.sin(q[..., 0]) * w1**2 - l2 * np.sin(q12) * w12**2
    return np.stack([x, y], axis=-1)


def joint_motion(arm: TwoJointArm, pos: ArrayLike, vel: ArrayLike, acc: ArrayLike,
                 elbow_sign: float = 1.0) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Joint angles, velocities and accelerations that move the hand as given (all (..., 2))."""
    q = arm.inverse_kinematics(pos, elbow_sign)
    jac = arm.jacobian(q)
    qd = np.linalg.solve(jac, np.asarray(vel, dtype=float)[..., None])[..., 0]
    rhs = np.asarray(acc, dtype=float) - hand_acceleration_bias(arm, q, qd)
    qdd = np.linalg.solve(jac, rhs[..., None])[..., 0]
    return q, qd, qdd


def torque_split(arm: TwoJointArm, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> dict[str, FloatArray]:
    """Each joint's inverse-dynamics torque in parts (see the module text); they sum to the total.

    Keys are the names in ``COMPONENTS``; each value is (..., 2): shoulder, elbow.
    """
    q, qd, qdd = (np.asarray(v, dtype=float) for v in (q, qd, qdd))
    m = arm.mass_matrix(q)
    return {
        "own_inertial": np.stack([m[..., 0, 0] * qdd[..., 0], m[..., 1, 1] * qdd[..., 1]], axis=-1),
        "interaction_inertial": np.stack([m[..., 0, 1] * qdd[..., 1], m[..., 1, 0] * qdd[..., 0]], axis=-1),
        "coriolis_centrifugal": arm.coriolis(q, qd),
        "gravity": arm.gravity(q),
        "damping": arm.damping(qd),
    }


@dataclass(frozen=True)
class ReachPlan:
    """Out to ``target``, a rest, back to ``home`` and a rest three times as long: one cycle that repeats. The cycle
    starts with the move out, so a projector shows motion from the first frame: at the lesson's quarter speed a
    rest first would hold the arm still for four times its length."""

    home: Point = (-0.2, 0.45)
    target: Point = (0.2, 0.45)
    move_time: float = 0.5
    rest: float = 0.4

    def __post_init__(self) -> None:
        if not (self.move_time > 0.0 and self.rest >= 0.0):
            raise UserError("a reach needs a positive movement time and a rest of zero or more")

    @property
    def out_starts(self) -> float:
        return 0.0

    @property
    def back_starts(self) -> float:
        return self.move_time + self.rest

    @property
    def cycle(self) -> float:
        return 4.0 * self.rest + 2.0 * self.move_time

    def hand(self, t: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Hand position, velocity, acceleration at times ``t`` (taken modulo the cycle)."""
        t = np.mod(np.asarray(t, dtype=float), self.cycle)
        # Each move rests at both ends with zero velocity and acceleration, so the moves just add.
        p1, v1, a1 = minimum_jerk(self.home, self.target, self.move_time, t - self.out_starts)
        p2, v2, a2 = minimum_jerk(self.target, self.home, self.move_time, t - self.back_starts)
        return p1 + p2 - np.asarray(self.target, dtype=float), v1 + v2, a1 + a2


def reach_arm(gravity: bool) -> TwoJointArm:
    """The game's arm; with gravity it swings in a vertical plane instead of the horizontal one."""
    return TwoJointArm(GAME_ARM.replace(gravity=STANDARD_GRAVITY) if gravity else GAME_ARM)


@dataclass(frozen=True)
class ReachTable:
    t: FloatArray  # (samples,)
    hand: FloatArray  # (samples, 2)
    hand_velocity: FloatArray
    q: FloatArray
    qd: FloatArray
    qdd: FloatArray
    total: FloatArray  # (samples, 2): arm.inverse_dynamics
    parts: dict[str, FloatArray]  # name -> (samples, 2)


def reach_table(arm: TwoJointArm, plan: ReachPlan, t: ArrayLike) -> ReachTable:
    t = np.asarray(t, dtype=float)
    pos, vel, acc = plan.hand(t)
    q, qd, qdd = joint_motion(arm, pos, vel, acc)
    return ReachTable(t, pos, vel, q, qd, qdd, arm.inverse_dynamics(q, qd, qdd), torque_split(arm, q, qd, qdd))


class ReachRun:
    """The planned reach played step by step, with the same interface as ``runs.PassiveRun``.

    The motion is prescribed, so one cycle is tabulated at the step once and then indexed.
    """

    joints = 2

    def __init__(self, gravity: bool = False, plan: ReachPlan | None = None, dt: float = 0.001) -> None:
        self.arm = self.model = reach_arm(gravity)
        self.gravity = gravity
        self.plan = plan or ReachPlan()
        self.dt = dt
        n = max(1, round(self.plan.cycle / dt))
        self.table = reach_table(self.arm, self.plan, np.arange(n) * dt)
        self._rows = np.column_stack([self.table.q, self.table.qd])
        self.reset()

    def reset(self) -> None:
        self.steps = 0
        self.states = [tuple(self._rows[0])]
        self.previous = self.states

    @property
    def t(self) -> float:
        return self.steps * self.dt

    def step(self) -> None:
        self.steps += 1
        self.previous = self.states
        self.states = [tuple(self._rows[self.steps % len(self._rows)])]

    def tabulated_states(self) -> list[np.ndarray]:
        """The cycle's states (n, 4), as a window frames the motion before showing it."""
        return [self._rows]

    def arm_points(self, q1: float, q2: float) -> list[Point]:
        elbow = self.arm.elbow((q1, q2))
        hand = self.arm.hand((q1, q2))
        return [(0.0, 0.0), (float(elbow[0]), float(elbow[1])), (float(hand[0]), float(hand[1]))]

    def torques_now(self) -> tuple[dict[str, tuple[float, float]], tuple[float, float]]:
        """The parts and the total torque (N m) at the current step, per joint."""
        row = self.steps % len(self._rows)
        parts = {k: (float(v[row, 0]), float(v[row, 1])) for k, v in self.table.parts.items()}
        return parts, (float(self.table.total[row, 0]), float(self.table.total[row, 1]))

    def hand_speed_now(self) -> float:
        return float(np.hypot(*self.table.hand_velocity[self.steps % len(self._rows)]))

    def torque_scales(self) -> tuple[float, float]:
        """Per joint, the largest absolute part or total over the cycle: bars keep one scale throughout."""
        stacked = np.stack([*self.table.parts.values(), self.table.total])
        biggest = np.max(np.abs(stacked), axis=(0, 1))
        return max(float(biggest[0]), 1e-9), max(float(biggest[1]), 1e-9)
