"""The Reach ids' reference controller: time-optimal bang-bang shooting on the true arm model (issue 40's ceiling).

Owns the controller the benchmark's ceiling is measured with (``benchmarks/ceiling.py`` plays it on the test
games; ``docs/programs.md``, "Reference scores", reports it). A controller that knows the task, to say how far a
learner is from what the task allows, not a policy to learn from::

    import armgame.env
    from armgame.env.ceiling import ShootingController

    result = armgame.env.evaluate("ceiling", "armgame/ReachHold-v1", games=2, time_limit=10.0,
                                  policy_factory=ShootingController)

**Method.** Model-predictive control by direct shooting over bang-bang muscle commands. Each joint's command is
one muscle of its pair full on for ``n1`` decisions, then its antagonist for ``n2``, then both off (``sign, n1,
n2`` a joint; a decision is the env's 20 ms step). At each new target it searches both joints' parameters
together on a grid of ``coarse`` decisions, then each joint's on a grid of ``fine`` with the other held, then
every switching time within one decision of the best (about 3,000 to 4,000 rollouts of up to ``horizon``
decisions); every ``replan`` decisions it rolls the plan still running and its 80 neighbours out again from the
state reached and keeps the best (closed loop). A candidate's cost is the time until the hand enters the target
(with a dwell: until it has stayed there the dwell's physics steps in a row), plus ``beta`` times the expected
time to reach the **next** target from the state at the hit: the mean, over a grid of the target box
(``GameConfig``'s joint ranges, less the targets within 3 radii of this one, which the game never draws), of the
slower joint's time as a double integrator that need only pass through its target. That term carries the hand's
momentum onward: without it the hand flies through each target in a random direction and the next reach starts
by braking. A plan that leaves a joint box (shoulder -1 to 2.8 rad, elbow 0.15 to 2.8) is refused: without it
the elbow spun through whole turns.

**What it knows.** The true state (``env.unwrapped.session``: joint angles and velocities, the four
activations, a dwell's count so far, the present target) and the true model, rolled out by the game's own step
in C (``armgame/game/_cshoot.c``: the muscles' activation, RK4 at the physics' 4 ms with the id's field at each
stage), so a plan's predicted hit is the game's to the physics step where nothing else intervenes
(``tests/test_ceiling.py``). It ignores the observation delay (it reads the true state, as a ceiling may), does
not know the motor noise's draws (its plans assume none; the closed loop corrects, and ``margin`` aims that far
inside the target) and does not know the next target, only its distribution: it is no oracle. It acts through
the env's own ``step`` (keys, or levels 0 and 1 for the continuous twins, which act exactly as keys), so every
hit is the game's, recorded and verifiable. It needs the compiled kernel (``pip install`` with a C compiler).

**What did not work** (short games of 20 s, hits a minute): the cross-entropy method over continuous levels with
one coarse RK4 step a decision and the present target only, 54 (the model bot 49.5); bang-bang on the exact model
with the present target only, 55: a reach from rest is slow whatever the controller (the muscles rise in 80 ms),
so the hand's momentum must be carried from one target to the next, which the next target's term does. Closing
the loop by refining only the running plan's switching times lost the target for good under noise and dwells
(ReachNoisy 49, ReachHold 55); searching afresh when the refined plan no longer hits gave 61 on both.
Replanning every decision rather than every third gave ReachNoisy 65 (its setting in ``benchmarks/ceiling.py``)
and Reach, ReachHold and ReachField nothing; switching times refined within two decisions rather than one gave
nothing at two to four times the CPU.

**Where it falls short.** PPO's five-seed runs at 4 M env steps pass it on Reach-v1 (by 2 hits), ReachNoisy-v1 (3),
ReachHold-v1 (1) and ReachField-v1 (12), so those ceilings are PPO's (docs/programs.md, "The ceiling"). On
ReachField-v1's game of seed 0 (the game each PPO run keeps) its hand moves as fast on average as PPO's (0.64 and
0.62 m/s) for 65 hits against PPO's 79 to 81, with the new target as far from the hand (0.42 and 0.40 m): its paths
are longer. A plan switches each joint's muscles once, so it cannot straighten a path the curl field bends; plans
of two switches a joint, and a next-reach estimate that knows the field (a value of the hit state learnt from its
own games) are the next things to try.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from ..game.rules import DwellRules
from ..game.session import compiled_kernel, kernel_mode, kernel_params
from ..game.variant import FIELD_CODES
from ..physics.twojoint import TwoJointArm
from .errors import EnvArgumentError

_ckernel = compiled_kernel()
_shoot = getattr(_ckernel, "shoot", None)

#: Every this many of the coarse grid's plans are rolled out first, to bound the rest's rollouts.
COARSE_SAMPLE = 16

#: The joint box a plan may not leave (rad): shoulder low, high, elbow low, high.
JOINT_BOX = (-1.0, 2.8, 0.15, 2.8)


class Goal(NamedTuple):
    """What a plan aims at: the target's centre (m), the dwell's physics steps in a row (1: entering it) and those
    the hand has stayed already."""

    x: float
    y: float
    hold: int
    dwelt: int


def pressed(best: np.ndarray, k: int) -> tuple[int, int]:
    """Each joint's muscle pressed at decision ``k`` of the plan ``best`` (sign, n1, n2 a joint): +1 its first, -1
    its second, 0 neither (``_cshoot.c``'s reading of a plan)."""
    out = []
    for j in (0, 3):
        s, n1, n2 = (int(v) for v in best[j:j + 3])
        out.append(s if k < n1 else -s if k < n1 + n2 else 0)
    return out[0], out[1]


def shifted(best: np.ndarray, elapsed: int) -> np.ndarray:
    """The plan ``best`` (sign, n1, n2 a joint) as it stands ``elapsed`` decisions on."""
    out = best.copy()
    for j in (0, 3):
        s, n1, n2 = best[j:j + 3]
        if elapsed <= n1:
            out[j:j + 3] = (s, n1 - elapsed, n2)
        elif elapsed <= n1 + n2:
            out[j:j + 3] = (-s, n1 + n2 - elapsed, 0)
        else:
            out[j:j + 3] = (1, 0, 0)
    return out


class ShootingController:
    """Time-optimal bang-bang shooting through the present target, with the next target's expected reach time.

    A policy of one env (``policy_factory`` for ``armgame.env.evaluate``): called with an observation, it reads
    the true state from ``env.unwrapped.session`` and returns the action. Arguments: ``beta`` weights the next
    target's expected time; ``horizon`` (decisions) bounds a plan; ``replan`` (decisions; 0: never) is the closed
    loop's rhythm; ``coarse`` and ``fine`` the search's grids (decisions); ``margin`` (m) aims that far inside the
    target; ``accel`` (rad/s^2, shoulder and elbow) is the next target's double integrator.
    """

    def __init__(self, env: Any, beta: float = 1.0, horizon: int = 75, replan: int = 3, coarse: int = 12,
                 fine: int = 3, margin: float = 0.001, accel: tuple[float, float] = (2.8, 6.9), grid: int = 5,
                 research: bool = True, reach: int = 1) -> None:
        if _shoot is None:
            raise EnvArgumentError("the shooting controller needs the compiled kernel (reinstall with a C compiler: "
                                   "pip install -e .)")
        base = env.unwrapped
        settings = getattr(base, "settings", None)
        if settings is None or not hasattr(base, "game_variant"):
            raise EnvArgumentError(f"the shooting controller plays the Reach ids, not {type(base).__name__}")
        self.env = base
        config = settings.config
        game = base.game_variant
        arm = TwoJointArm(config.arm)
        dt = config.dt
        moments = [m.moment for m in config.muscles]
        self.params = np.array(kernel_params(arm, dt, [m[0] for m in moments], [m[1] for m in moments]))
        self.mode = kernel_mode(config.arm)
        self.rates = np.array([-math.expm1(-dt / m.rise_time) for m in config.muscles]
                              + [-math.expm1(-dt / m.decay_time) for m in config.muscles])
        self.field = np.array([FIELD_CODES[game.field], *game.field_parameters], dtype=float)
        self.substeps = settings.decision_steps
        self.decision_time = dt * self.substeps
        self.continuous = settings.continuous
        self.hold = max(1, game.hold_steps)
        self.radius = config.target_radius
        self.margin, self.beta, self.horizon, self.replan, self.research = margin, beta, horizon, replan, research
        self.accel = np.array(accel)
        lo1, hi1 = np.radians(config.target_shoulder_range)
        lo2, hi2 = np.radians(config.target_elbow_range)
        g1, g2 = np.meshgrid(np.linspace(lo1, hi1, grid), np.linspace(lo2, hi2, grid))
        self.grid = np.stack([g1.ravel(), g2.ravel()], axis=1)
        l1, l2 = config.arm.l1, config.arm.l2
        self.grid_hand = np.stack([l1 * np.cos(self.grid[:, 0]) + l2 * np.cos(self.grid.sum(1)),
                                   l1 * np.sin(self.grid[:, 0]) + l2 * np.sin(self.grid.sum(1))], axis=1)
        # A target's tolerance in joint space: its radius over each joint's lever arm (roughly).
        self.tolerance = np.array([self.radius / 0.6, self.radius / l2])
        self._prepare_search(coarse, fine, reach)

    def _prepare_search(self, coarse: int, fine: int, reach: int) -> None:
        """The search's grids (``coarse`` and ``fine`` decisions, neighbours ``reach`` decisions apart) and no plan."""
        self._coarse_pairs = self._pairs_of(self._options(coarse))
        self._fine_options = self._options(fine)
        self._neighbours = np.array(np.meshgrid(*[range(-reach, reach + 1)] * 4, indexing="ij")).reshape(4, -1).T
        #: The running plan (sign, n1, n2 a joint), the decisions of it played, and the target it was made for.
        self.best = np.array([1, 0, 0, 1, 0, 0])
        self.position = 0
        self.target: Any = None
        #: The physics steps from the last plan's start to the hit it predicts (-1: none within the horizon).
        self.predicted_steps = -1

    def reset(self) -> None:
        """A new game: nothing carried over (``evaluate`` calls it before each game)."""
        self.target, self.position, self.predicted_steps = None, 0, -1

    # ------------------------------------------------------------------ the cost
    def next_time(self, states: np.ndarray, target: Goal) -> np.ndarray:
        """Each state's expected time (s) to reach the next target: the mean over the grid's targets far enough
        from this one (the game draws none within 3 radii of the hand) of the slower joint's time as a double
        integrator of acceleration ``accel`` that need only pass through its target (it need not stop)."""
        far = np.hypot(self.grid_hand[:, 0] - target.x, self.grid_hand[:, 1] - target.y) > 3.0 * self.radius
        goals = self.grid[far]
        q = states[:, None, 0:2]
        w = states[:, None, 2:4]
        delta = np.remainder(goals[None, :, :] - q + np.pi, 2.0 * np.pi) - np.pi  # the hand's: angles wrap
        sign = np.where(delta >= 0, 1.0, -1.0)
        x = np.maximum(np.abs(delta) - self.tolerance, 0.0)
        u = w * sign
        a = self.accel
        toward = (-u + np.sqrt(u * u + 2.0 * a * x)) / a
        back = -u / a + np.sqrt(2.0 * (x + u * u / (2.0 * a)) / a)
        return np.where(u >= 0, toward, back).max(axis=2).mean(axis=1)

    def rollouts(self, pairs: np.ndarray, x0: np.ndarray, act0: np.ndarray, goal: Goal,
                 bound: float = math.inf) -> np.ndarray:
        """Each plan of ``pairs`` (N, 6) rolled out by ``_ckernel.shoot``: (N, 6) rows of the hit's physics step
        (-1 none, -2 out of the box), the state then and the distance from the target's centre. ``bound`` (s): no
        plan is followed past it (one hitting later could not beat a cost already found)."""
        out = np.empty((len(pairs), 6))
        # The box refuses a plan that leaves it, not one that starts outside (noise or a field can put the arm
        # there): it is widened to hold the start, so a plan may come back in but not go further out.
        box = np.array([min(JOINT_BOX[0], x0[0] - 0.05), max(JOINT_BOX[1], x0[0] + 0.05),
                        min(JOINT_BOX[2], x0[1] - 0.05), max(JOINT_BOX[3], x0[1] + 0.05)])
        rr = max(self.radius - self.margin, 0.0) ** 2
        horizon = self.horizon if bound >= self.horizon * self.decision_time \
            else int(bound / self.decision_time) + 1
        _shoot(self.params, self.mode, self.rates, self.field, x0, act0, np.ascontiguousarray(pairs, dtype=np.int64),
               self.substeps, horizon, np.array([goal.x, goal.y, rr]), goal.hold, goal.dwelt, box, out)
        return out

    def cost(self, out: np.ndarray, goal: Goal) -> np.ndarray:
        """Each rollout's cost (s): a plan that misses ranks below every plan that hits, by its final distance."""
        hit = out[:, 0] >= 0
        t = np.where(hit, out[:, 0] * self.params[0], np.where(out[:, 0] == -1, 100.0, 1000.0) + out[:, 5])
        if self.beta and hit.any():
            t[hit] += self.beta * self.next_time(out[hit, 1:5], goal)
        return t

    # ---------------------------------------------------------------- the search
    def _options(self, step: int) -> np.ndarray:
        """Every (sign, n1, n2) of one joint on a grid of ``step`` decisions, n1 + n2 within the horizon."""
        h = self.horizon
        return np.array([(s, n1, n2) for s in (1, -1) for n1 in range(0, h + 1, step)
                         for n2 in range(0, h + 1 - n1, step) if n1 > 0 or s == 1], dtype=np.int64)

    @staticmethod
    def _pairs_of(options: np.ndarray) -> np.ndarray:
        i, j = np.meshgrid(np.arange(len(options)), np.arange(len(options)), indexing="ij")
        return np.concatenate([options[i.ravel()], options[j.ravel()]], axis=1)

    def _best(self, pairs: np.ndarray, x0: np.ndarray, act0: np.ndarray, goal: Goal,
              bound: float = math.inf) -> tuple[np.ndarray, float, int]:
        out = self.rollouts(pairs, x0, act0, goal, bound)
        costs = self.cost(out, goal)
        i = int(np.argmin(costs))
        return pairs[i], float(costs[i]), int(out[i, 0])

    def search(self, x0: np.ndarray, act0: np.ndarray, goal: Goal) -> None:
        """Both joints' (sign, n1, n2) on the coarse grid together, then each joint's on the fine grid with the other
        held (coordinate descent), then both joints' switching times within one decision of the best. Where no plan
        completes a dwell, the plan that enters the target soonest: from inside it, a dwell is within reach (a
        search that ranked the misses by where they end left the arm still, far from a target it could not reach
        and stop in within the horizon, for the rest of a game)."""
        self._search(x0, act0, goal)
        if self.predicted_steps < 0 and goal.hold > 1:
            self._search(x0, act0, goal._replace(hold=1, dwelt=0))
            self.predicted_steps = -1  # the dwell's hit is not what it plans

    def _search(self, x0: np.ndarray, act0: np.ndarray, goal: Goal) -> None:
        # A sample of the coarse grid first: its best cost bounds how far the rest is followed.
        sample = self._coarse_pairs[::COARSE_SAMPLE]
        best, cost, steps = self._best(sample, x0, act0, goal)
        candidate, c, s = self._best(self._coarse_pairs, x0, act0, goal, cost)
        if c < cost:
            best, cost, steps = candidate, c, s
        fine = self._fine_options
        for joint in (0, 1):
            pairs = np.tile(best, (len(fine), 1))
            pairs[:, 3 * joint:3 * joint + 3] = fine
            candidate, c, s = self._best(pairs, x0, act0, goal, cost)
            if c < cost:
                best, cost, steps = candidate, c, s
        self.refine(best, cost, steps, x0, act0, goal)

    def refine(self, best: np.ndarray, cost: float, steps: int, x0: np.ndarray, act0: np.ndarray, goal: Goal) -> None:
        """``best`` or the best of its neighbours (both joints' switching times within one decision of it) becomes
        the plan."""
        pairs = np.tile(best, (len(self._neighbours), 1))
        pairs[:, [1, 2, 4, 5]] = np.minimum(np.maximum(pairs[:, [1, 2, 4, 5]] + self._neighbours, 0), self.horizon)
        candidate, c, s = self._best(pairs, x0, act0, goal, cost)
        if c < cost:
            best, steps = candidate, s
        self.best = best.copy()
        self.predicted_steps = steps
        self.position = 0

    # ------------------------------------------------------------------ playing
    def __call__(self, observation: Any) -> np.ndarray:
        session = self.env.session
        rules = session.rules
        target = rules.target
        # Steps the hand has already stayed in the target (a dwell's count), where the rules keep one.
        dwelt = rules.dwell_at(session.steps) if isinstance(rules, DwellRules) else 0
        x0 = np.array(session.state, dtype=np.float64)
        act0 = np.array(session.muscles.activation, dtype=np.float64)
        goal = Goal(target.x, target.y, self.hold, dwelt)
        if target is not self.target or self.position >= self.horizon:
            self.search(x0, act0, goal)
            self.target = target
        elif self.replan and self.position % self.replan == 0:
            # Closed loop: from the state reached, the plan still running and its neighbours rolled out again.
            self.refine(shifted(self.best, self.position), math.inf, -1, x0, act0, goal)
            if self.predicted_steps < 0 and self.research:  # the running plan and its neighbours all miss now
                self.search(x0, act0, goal)
        s, e = pressed(self.best, self.position)
        self.position += 1
        keys = np.array([s > 0, s < 0, e > 0, e < 0], dtype=np.float32)
        if self.continuous:
            return 2.0 * keys - 1.0
        return keys.astype(np.int8)
