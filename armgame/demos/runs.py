"""Passive arms stepped by the fixed-step integrators: the pendulum, passive and chaos demos.

A window and a headless run step the very same object (``PassiveRun.step``): headless is N calls
of the fixed step, the window calls it as real time accrues. So what a class sees is exactly what
the CSV holds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import UserError
from ..physics.integrators import SCHEMES, Integrator
from ..physics.params import TUTORIAL_ARM
from ..physics.twojoint import TwoJointArm
from ..scenes import get_scene
from ..words import unknown_name

State = tuple[float, float, float, float]
Point = tuple[float, float]

#: The chaos demo's second arm starts this far (rad) from the first, at the shoulder.
CHAOS_OFFSET = 1e-6
#: Upper arm straight up, forearm horizontal: enough energy for the motion to be chaotic. The
#: tutorial's own start (hanging, elbow at 90 deg) is too calm: its two copies stay within
#: microns for minutes.
CHAOS_START: State = (math.pi / 2, math.pi / 2, 0.0, 0.0)
#: Hands further apart than this (m) read as two arms on a projected 800 px scene (about 4 px).
VISIBLY_APART = 0.01


def check_fixed_step(integrator: str, dt: float) -> None:
    if integrator not in SCHEMES:
        raise UserError(unknown_name("integrator", integrator, SCHEMES))
    if not (math.isfinite(dt) and 0.0 < dt <= 0.05):
        raise UserError(f"--dt must be a positive number of seconds no larger than 0.05, got {dt!r}")


class PassiveRun:
    """One or more unforced arms of the same model, stepped together at a fixed step."""

    def __init__(self, model, initials: list[State], joints: int, integrator: str = "rk4",
                 dt: float = 0.001) -> None:
        check_fixed_step(integrator, dt)
        self.model = model
        self.joints = joints
        self.initials = [tuple(map(float, s)) for s in initials]
        self.dt = dt
        self._step = Integrator(integrator, model).step_components
        self.reset()

    def reset(self) -> None:
        self.steps = 0
        self.states: list[State] = list(self.initials)
        self.previous: list[State] = list(self.initials)

    @property
    def t(self) -> float:
        # Counting steps rather than summing dt keeps the clock exact over long runs.
        return self.steps * self.dt

    def step(self) -> None:
        dt, step = self.dt, self._step
        self.previous = self.states
        self.states = [step(q1, q2, w1, w2, 0.0, 0.0, dt) for q1, q2, w1, w2 in self.states]
        self.steps += 1

    def arm_points(self, q1: float, q2: float) -> list[Point]:
        """Shoulder, (elbow,) hand in metres for the joint angles (q2 ignored for one joint)."""
        if self.joints == 1:
            x, y = self.model.hand(q1)
            return [(0.0, 0.0), (float(x), float(y))]
        elbow = self.model.elbow((q1, q2))
        hand = self.model.hand((q1, q2))
        return [(0.0, 0.0), (float(elbow[0]), float(elbow[1])), (float(hand[0]), float(hand[1]))]

    def hand_distance(self) -> float:
        """Distance between the first two arms' hands (m)."""
        a, b = (self.arm_points(s[0], s[1])[-1] for s in self.states[:2])
        return math.hypot(a[0] - b[0], a[1] - b[1])


def pendulum_run(integrator: str = "rk4", dt: float = 0.001) -> PassiveRun:
    scene = get_scene("pendulum")
    return PassiveRun(scene.model, [scene.initial], joints=1, integrator=integrator, dt=dt)


def passive_run(integrator: str = "rk4", dt: float = 0.001) -> PassiveRun:
    scene = get_scene("passive")
    return PassiveRun(scene.model, [scene.initial], joints=2, integrator=integrator, dt=dt)


def chaos_run(integrator: str = "rk4", dt: float = 0.001) -> PassiveRun:
    q1, q2, w1, w2 = CHAOS_START
    return PassiveRun(TwoJointArm(TUTORIAL_ARM), [CHAOS_START, (q1 + CHAOS_OFFSET, q2, w1, w2)], joints=2,
                      integrator=integrator, dt=dt)


@dataclass(frozen=True)
class Recording:
    t: NDArray[np.float64]  # (samples,)
    states: NDArray[np.float64]  # (samples, arms, 4)


def record(run: PassiveRun, duration: float, sample_rate: float) -> Recording:
    """Reset ``run`` and step it for ``duration`` s, keeping a sample about every 1/``sample_rate`` s."""
    if not (math.isfinite(duration) and duration > 0.0):
        raise UserError(f"--duration must be a positive, finite number of seconds, got {duration!r}")
    run.reset()
    steps = math.floor(duration / run.dt + 1e-9)
    every = max(1, round(1.0 / (sample_rate * run.dt)))
    kept = np.arange(0, steps + 1, every)
    states = np.empty((len(kept), len(run.states), 4))
    states[0] = run.states
    row = 1
    for i in range(1, steps + 1):
        run.step()
        if row < len(kept) and kept[row] == i:
            states[row] = run.states
            row += 1
    return Recording(kept * run.dt, states)
