"""A first reference controller that knows the task (issue 40, item 1), measured: not yet a ceiling.

    python benchmarks/mpc_probe.py                      # 4 games of 20 s: about a minute of CPU
    python benchmarks/mpc_probe.py --games 2 --seconds 10

Model-predictive control with the true arm model and the true state on ``armgame/ReachContinuous-v1``:
before every other decision it plans the four muscles' levels over the next 400 ms (4 segments of
100 ms, levels in [0, 1]) by the cross-entropy method (192 candidates, 4 rounds), each candidate rolled
out on the arm's own equations (``Integrator("rk4", TwoJointArm, "numpy")``, one RK4 step a decision of
20 ms, the muscles' first-order activation exact over the step and its mean driving the torque), and
scores a candidate by the time until the hand enters the target plus its distance to the target's edge
until then (it plans at a coarser rate than the physics, as the issue allows). It knows the present
target only: the next one is drawn when this one is hit. It prints its hits per minute beside the model
bot's on the same games (the test games' first ``--games`` seeds) and its CPU seconds per second of game.

What it showed (AMD EPYC, 2 cores, shared; the default run): on the first four test games' first 20 s,
18, 19, 17 and 18 hits, 54.0 a minute, against the model bot's 49.5 on the same seconds (53.2 a minute
over whole games), and at 0.50 CPU seconds per second of game. That is below PPO's 69.7 a game: it is
a reference, not a ceiling. Variants tried while building it did no better (a longer horizon, finer
segments, more candidates, planning at the physics' 4 ms, an exhaustive search over bang-bang keys, a
term for the next target's expected distance: 54 to 60 a minute on two such games). A reach from rest
is slow whatever the controller (the muscles rise in 80 ms), so PPO's rate needs the hand's momentum
carried from one target to the next: a ceiling must plan over the next target's distribution (targets
are drawn uniformly in a joint-space box, ``GameConfig``), not the present target alone, and needs its
rollouts batched in C to be evaluated on 100 games an id within minutes. So the normalised score stays
the model bot's (protocol 1) until every id has a ceiling (CenterOut's is known: the model bot hits 8 of
8 in all 100 test episodes, the most an episode holds).
"""

from __future__ import annotations

import argparse
import sys
import time

import gymnasium as gym
import numpy as np

import armgame.env
from armgame.env.suite import EVALUATION_SEEDS
from armgame.game.muscles import MuscleSet
from armgame.physics.integrators import Integrator
from armgame.physics.twojoint import TwoJointArm

ENV_ID = "armgame/ReachContinuous-v1"


class ShootingController:
    """The cross-entropy method over piecewise-constant muscle levels, on the true model from the true state."""

    def __init__(self, env: gym.Env, horizon: int = 20, segments: int = 4, candidates: int = 192, rounds: int = 4,
                 plan_every: int = 2, step_cost: float = 1.0, margin: float = 0.9, seed: int = 0) -> None:
        settings = env.unwrapped.settings
        config = settings.config
        self.steps_per_decision = settings.decision_steps
        self.dt = config.dt * settings.decision_steps
        self.step = Integrator("rk4", TwoJointArm(config.arm), "numpy").step_components
        muscles = MuscleSet(config.muscles, config.dt)
        self.moments = np.array([m.moment for m in config.muscles])
        self.rise, self.decay = np.array(muscles._rise), np.array(muscles._decay)
        self.l1, self.l2, self.radius = config.arm.l1, config.arm.l2, config.target_radius
        self.horizon, self.segments, self.candidates, self.rounds = horizon, segments, candidates, rounds
        self.plan_every, self.step_cost, self.margin = plan_every, step_cost, margin
        self.rng = np.random.default_rng(seed)
        self.mean = np.full((segments, 4), 0.5)
        self.plan: np.ndarray | None = None
        self.decisions = 0
        self.position = 0

    def cost(self, state: tuple[float, ...], activation: np.ndarray, target: tuple[float, float],
             goals: np.ndarray) -> np.ndarray:
        """Each candidate's decisions until the hand enters (0.9 of) the target, plus its edge distances (m)."""
        n = goals.shape[0]
        q1, q2, w1, w2 = (np.full(n, v) for v in state[:4])
        a = np.tile(activation, (n, 1))
        cost, inside = np.zeros(n), np.zeros(n, dtype=bool)
        for t in range(self.horizon):
            goal = goals[:, t]
            rate = np.where(goal > a, self.rise, self.decay)
            after = goal + (a - goal) * (1.0 - rate) ** self.steps_per_decision
            torque = (0.5 * (a + after)) @ self.moments
            q1, q2, w1, w2 = self.step(q1, q2, w1, w2, torque[:, 0], torque[:, 1], self.dt)
            a = after
            hx = self.l1 * np.cos(q1) + self.l2 * np.cos(q1 + q2)
            hy = self.l1 * np.sin(q1) + self.l2 * np.sin(q1 + q2)
            edge = np.maximum(0.0, np.hypot(hx - target[0], hy - target[1]) - self.margin * self.radius)
            cost += np.where(inside, 0.0, edge + self.step_cost)
            inside |= edge <= 0.0
        return cost

    def _expand(self, plans: np.ndarray) -> np.ndarray:
        return np.repeat(plans, -(-self.horizon // self.segments), axis=1)[:, :self.horizon]

    def act(self, state: tuple[float, ...], activation: np.ndarray, target: tuple[float, float]) -> np.ndarray:
        """The next decision's levels, -1 to 1 (the env's continuous action)."""
        if self.plan is None or self.decisions % self.plan_every == 0:
            mean, spread = self.mean.copy(), np.full((self.segments, 4), 0.4)
            for _ in range(self.rounds):
                plans = np.clip(mean + spread * self.rng.standard_normal((self.candidates, self.segments, 4)), 0, 1)
                plans[0] = np.clip(mean, 0.0, 1.0)
                cost = self.cost(state, activation, target, self._expand(plans))
                elite = plans[np.argsort(cost)[:max(4, self.candidates // 10)]]
                mean, spread = elite.mean(axis=0), elite.std(axis=0) + 0.02
            self.plan, self.position = self._expand(mean[None])[0], 0
            self.mean = np.concatenate([mean[1:], np.full((1, 4), 0.5)])  # the plan shifted, warm-starts the next
        levels = self.plan[self.position]
        self.position += 1
        self.decisions += 1
        return (2.0 * levels - 1.0).astype(np.float32)


def play(seed: int, seconds: float) -> int:
    env = gym.make(ENV_ID, time_limit=seconds, observation_dtype="float64")
    controller = ShootingController(env)
    env.reset(seed=seed)
    done = False
    while not done:
        session = env.unwrapped.session
        target = session.rules.target
        action = controller.act(session.state, np.array(session.muscles.activation), (target.x, target.y))
        _, _, terminated, truncated, info = env.step(action)
        done = terminated or truncated
    return int(info["hits"])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--games", type=int, default=4)
    parser.add_argument("--seconds", type=float, default=20.0)
    args = parser.parse_args(argv)
    seeds = list(EVALUATION_SEEDS[:args.games])
    start = time.process_time()
    hits = [play(seed, args.seconds) for seed in seeds]
    cpu = time.process_time() - start
    bot = armgame.env.evaluate("model", ENV_ID, seeds=seeds, time_limit=args.seconds)
    per_minute = 60.0 / args.seconds
    print(f"shooting controller: {hits} hits, {np.mean(hits) * per_minute:.1f} a minute "
          f"({cpu / (args.games * args.seconds):.2f} CPU s per game second)")
    print(f"model bot on the same games: {list(bot.hits)} hits, {bot.mean_hits * per_minute:.1f} a minute")
    return 0


if __name__ == "__main__":
    sys.exit(main())
