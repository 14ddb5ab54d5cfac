"""The CenterOut ids' reference controller: time-optimal bang-bang shooting into each trial's target and its stay.

Protocol 3 scores the CenterOut ids by hits a minute, and every policy worth citing hits all of an episode's
trials, so what ranks them is the time from each go cue to its hit (the delays before the go cues are the
task's, the same for every policy). This controller is ``armgame.env.ceiling.ShootingController``'s search,
aimed at the lab's rules instead of the game's, to say how short that time can be::

    import armgame.env
    from armgame.env.center_out_reference import CenterOutShootingController

    result = armgame.env.evaluate("shooting", "armgame/CenterOut-v1", games=2,
                                  policy_factory=CenterOutShootingController)

**What it does.** In a hold (home shown) it presses nothing: the lab puts the arm back at home, at rest, with
the muscles relaxed at every trial's end, so the arm stays there and a Hold id's go cue comes after the trial's
delay, as soon as it can. At the go cue it searches bang-bang plans (each joint's muscle of a pair full on for
``n1`` decisions, then its antagonist for ``n2``, then both off) for the one that completes the stay in the target
soonest: the cursor inside the target's disc for the hold time's physics steps in a row (``hold_steps``, 0.2 s),
which is the lab's hit. Every ``replan`` decisions it rolls the running plan and its neighbours out again from the
state reached and keeps the best, searching afresh if none hits any more. Nothing after the hit counts: the lab
sends the arm home at rest, so unlike Reach's controller it weighs no next target (``beta`` 0).

**What it knows.** The true state of the env's ``LabSession`` (``env.unwrapped.session``: joint angles and
velocities, the four activations, the phase, the shown target and how many steps in a row the cursor has stayed in
it, ``LabSession.stayed``) and the task's rules (the lab's arm and muscles, the target radius and hold time). Its
plans are rolled out by the game's own step in C (``_ckernel.shoot``: the muscles' activation and RK4 at the
physics' 4 ms), the step the lab's unperturbed trials take, so a plan's predicted hit is the lab's to the physics
step (``tests/test_center_out_reference.py``). It does not read the trials to come (``session.plans``): it learns
each target at its go cue, from the phase, as the observation shows it, so it is no oracle. It plans every trial
on the unperturbed arm and cursor: on a perturbed trial (a field, a visual transform, a channel; none in the suite
ids' episodes, the ``null`` protocol's baseline trials) its plans are wrong and only the closed loop corrects. It
acts through the env's ``step`` (keys, or levels -1 and 1 for the continuous twins: muscle levels 0 and 1, which
act exactly as keys), so every hit is the env's. It needs the compiled kernel.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..game.session import kernel_mode, kernel_params
from ..game.variant import FIELD_CODES
from ..lab.session import REACH, lab_config
from ..physics.twojoint import TwoJointArm
from .ceiling import Goal, ShootingController, _shoot, pressed, shifted
from .center_out import CenterOutBaseEnv
from .errors import EnvArgumentError


class CenterOutShootingController(ShootingController):
    """Time-optimal bang-bang shooting into each CenterOut trial's target and its stay; still at home in a hold.

    A policy of one env (``policy_factory`` for ``armgame.env.evaluate``; see the module's docstring). Arguments:
    ``horizon`` (decisions) bounds a plan; ``replan`` (decisions; 0: never) is the closed loop's rhythm;
    ``coarse`` and ``fine`` the search's grids (decisions); ``margin`` (m) aims that far inside the target.
    """

    def __init__(self, env: Any, horizon: int = 40, replan: int = 1, coarse: int = 6, fine: int = 1,
                 margin: float = 0.001, reach: int = 1, afresh: bool = False, finer: int = 3) -> None:
        if _shoot is None:
            raise EnvArgumentError("the shooting controller needs the compiled kernel (reinstall with a C compiler: "
                                   "pip install -e .)")
        base = env.unwrapped
        if not isinstance(base, CenterOutBaseEnv):
            raise EnvArgumentError(f"the CenterOut shooting controller plays the CenterOut ids, not "
                                   f"{type(base).__name__}")
        self.env = base
        protocol = base.protocol
        config = lab_config(protocol, 0)  # what a run's seed changes (its trials) is not the model
        dt = config.dt
        moments = [m.moment for m in config.muscles]
        self.params = np.array(kernel_params(TwoJointArm(config.arm), dt, [m[0] for m in moments],
                                             [m[1] for m in moments]))
        self.mode = kernel_mode(config.arm)
        self.rates = np.array([-math.expm1(-dt / m.rise_time) for m in config.muscles]
                              + [-math.expm1(-dt / m.decay_time) for m in config.muscles])
        self.field = np.array([FIELD_CODES[None], 0.0, 0.0, 0.0, 0.0])
        self.substeps = base.decision_steps
        self.decision_time = dt * self.substeps
        self.continuous = base.continuous
        self.hold = max(1, round(protocol.hold_time / dt))  # LabSession.hold_steps
        self.radius = protocol.target_radius
        # The arm goes home at rest after every trial: the state at a hit carries nothing to the next.
        self.margin, self.beta, self.horizon, self.replan, self.research = margin, 0.0, horizon, replan, True
        self.afresh = afresh
        self._prepare_search(coarse, fine, reach)
        self._grids = (self._coarse_pairs, self._pairs_of(self._options(finer)))
        #: The physics step at which the running plan started (its predicted hit is this plus ``predicted_steps``).
        self.plan_step = 0

    def __call__(self, observation: Any) -> np.ndarray:
        session = self.env.session
        if session.phase != REACH:
            # A hold: the arm was put home at rest, so pressing nothing keeps it in home until the go cue.
            self.target = None
            return self._action(0, 0)
        target = session.rules.target
        x0 = np.array(session.state, dtype=np.float64)
        act0 = np.array(session.muscles.activation, dtype=np.float64)
        goal = Goal(target.x, target.y, self.hold, session.stayed)
        if target is not self.target or self.position >= self.horizon:
            self.search(x0, act0, goal)
            self.target = target
            self.plan_step = session.steps
        elif self.replan and self.position % self.replan == 0:
            if self.afresh:
                self.search_from(shifted(self.best, self.position), x0, act0, goal)
            else:
                self.refine(shifted(self.best, self.position), math.inf, -1, x0, act0, goal)
            self.plan_step = session.steps
            if self.predicted_steps < 0 and self.research:  # the running plan and its neighbours all miss now
                self.search(x0, act0, goal)
        s, e = pressed(self.best, self.position)
        self.position += 1
        return self._action(s, e)

    def search(self, x0: np.ndarray, act0: np.ndarray, goal: Goal) -> None:
        """``ShootingController.search`` on the coarse grid, and where no plan of it completes the stay, again on
        the ``finer`` grid (a coarse grid of 6 decisions missed one of the eight directions from rest), before the
        plan that enters the target soonest."""
        for pairs in self._grids:
            self._coarse_pairs = pairs
            self._search(x0, act0, goal)
            if self.predicted_steps >= 0:
                break
        self._coarse_pairs = self._grids[0]
        if self.predicted_steps < 0 and goal.hold > 1:
            self._search(x0, act0, goal._replace(hold=1, dwelt=0))
            self.predicted_steps = -1  # the stay's hit is not what it plans

    def search_from(self, plan: np.ndarray, x0: np.ndarray, act0: np.ndarray, goal: Goal) -> None:
        """The whole search again from the state reached, the running ``plan`` its first candidate: each plan has
        one switch a joint, and searching anew every decision lets the path played switch again."""
        best, cost, steps = self._best(plan[None, :], x0, act0, goal)
        for pairs in (self._coarse_pairs[::16], self._coarse_pairs):
            candidate, c, s = self._best(pairs, x0, act0, goal, cost)
            if c < cost:
                best, cost, steps = candidate, c, s
        for joint in (0, 1):
            pairs = np.tile(best, (len(self._fine_options), 1))
            pairs[:, 3 * joint:3 * joint + 3] = self._fine_options
            candidate, c, s = self._best(pairs, x0, act0, goal, cost)
            if c < cost:
                best, cost, steps = candidate, c, s
        self.refine(best, cost, steps, x0, act0, goal)

    def _action(self, s: int, e: int) -> np.ndarray:
        keys = np.array([s > 0, s < 0, e > 0, e < 0], dtype=np.float32)
        if self.continuous:
            return 2.0 * keys - 1.0
        return keys.astype(np.int8)


__all__ = ["CenterOutShootingController"]
