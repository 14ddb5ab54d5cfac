"""Autopilots: bots that play the game by pressing the four muscle keys, as a player would.

A bot is an input source like the keyboard or a script: before a physics step it looks at
what a player sees (the arm, the target, the clock and the four activation bars) and
returns key presses and releases, which go through ``GameSession.key_event`` and into the
session's timeline. So a bot game replays headless from its timeline bit for bit, and the
same bot drives a headless game and the window through the same ``Autopilot``.

Both bots plan every reach the same way: a minimum-jerk (quintic) joint trajectory from the
arm's current state to the target's inverse-kinematics posture, lasting the shortest time
whose torques, by the bot's own model, fit within the muscles. They track it with the same
computed-torque law, ``tau = M^(qdd_d + kp e + kd e') + C^ + B qd``, and turn the torque
into keys the same way. They differ only in the internal model (M^, C^):

* ``model`` knows the arm's dynamics: the full mass matrix and the Coriolis-centrifugal
  torques, the interaction torques included.
* ``naive`` drives each joint as if the other did not move: its mass matrix is the diagonal
  of the true one and it has no Coriolis-centrifugal torques.

Keys are binary, so a bot turns a desired torque into presses with a one-step-ahead
sigma-delta on the muscles' activations: at each decision it predicts, from the muscle model
(which a practised player learns from the bars), the activation each key choice gives one
control period later, and picks the antagonist pair whose net torque then comes nearest the
desired one.

Bots decide every ``CONTROL_PERIOD`` (4 ms): the game's physics rate (250 Hz), so a bot can
press or release before any step, as the keyboard can. The muscles' 80-100 ms time constants
filter the presses, so one decision moves an activation by at most 5 percent of its range (a
ripple of at most 0.07 N m). Under a finer physics step the bot still decides every 4 ms, on
whole steps, so its play hardly depends on the step.

Nothing here is random unless asked: a bot's game is a function of the game's seed. A bot given
``MotorNoise`` (the lab's ``--motor-noise``; never the game's ranked bots) varies its motor command
from a seeded stream of its own, before the command becomes keys: the keys it presses carry the noise,
so its timeline replays (and verifies) bit for bit with no noise re-drawn.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Protocol

from .._native import load
from ..errors import UserError
from ..physics.twojoint import TwoJointArm
from ..words import unknown_name
from .rules import GameConfig, Target
from .session import DOWN, UP, GameResult, GameSession

#: The compiled forward model (setup.py builds it where a C compiler is found); a build of another
#: version of _cbots.c is not used: its calling convention may differ.
_cbots = load("armgame.game._cbots", 1)
_c_predict = None if _cbots is None else _cbots.predict

CONTROL_PERIOD = 0.004
#: The cost of keys down in a decision, per key (``ReachingBot.act``).
_NO_PRESS, _ONE_PRESS, _TWO_PRESSES = 1e-4 * 0, 1e-4 * 1, 1e-4 * 2


class Bot(Protocol):
    """An input source: ``act`` is called before every ``period_steps``-th physics step."""

    name: str

    def period_steps(self, dt: float) -> int: ...

    def act(self, session: GameSession) -> list[tuple[str, str]]: ...


@dataclass(frozen=True)
class MotorNoise:
    """Signal-dependent noise on a bot's motor command (Harris & Wolpert 1998: the s.d. grows with the signal).

    Each joint's commanded torque (the net activation of its muscle pair, times its moment) is multiplied by
    ``1 + n``, where ``n`` is a Gaussian process of s.d. ``level`` (a coefficient of variation) correlated
    over ``correlation_time`` seconds (first-order autoregressive, one draw per decision and joint): a
    command held for a while is held with one error, as a force held by a person drifts, rather than
    jittering every 4 ms where the muscles would filter it out. ``seed`` starts the stream (numpy's PCG64,
    the same numbers on every machine)."""

    level: float
    seed: int
    correlation_time: float = 0.05

    def __post_init__(self) -> None:
        if not (math.isfinite(self.level) and 0.0 <= self.level <= 1.0):
            raise UserError(f"motor noise must be from 0 to 1 (a coefficient of variation), got {self.level!r}")
        if not (math.isfinite(self.correlation_time) and 0.0 < self.correlation_time <= 10.0):
            raise UserError(f"the motor noise's correlation time must be from 0 to 10 s, got {self.correlation_time!r}")

    def as_dict(self) -> dict[str, object]:
        return {"level": self.level, "correlation_time_s": self.correlation_time, "seed": self.seed}


class _NoiseStream:
    """The noise factors of ``MotorNoise``, one pair per decision, drawn in blocks (a decision every 4 ms)."""

    BLOCK = 2048

    def __init__(self, noise: MotorNoise, period: float) -> None:
        import numpy as np

        self._rng = np.random.Generator(np.random.PCG64(noise.seed))
        self._keep = math.exp(-period / noise.correlation_time)
        self._fresh = noise.level * math.sqrt(1.0 - self._keep * self._keep)
        # Started from its stationary spread, so the first reach is as noisy as the last.
        first = self._rng.standard_normal(2) * noise.level
        self.state = [float(first[0]), float(first[1])]
        self._draws: list[float] = []

    def next(self) -> tuple[float, float]:
        if len(self._draws) < 2:
            self._draws = self._rng.standard_normal(self.BLOCK).tolist()[::-1]
        draws, keep, fresh, state = self._draws, self._keep, self._fresh, self.state
        state[0] = keep * state[0] + fresh * draws.pop()
        state[1] = keep * state[1] + fresh * draws.pop()
        return state[0], state[1]


# ---------------------------------------------------------------- internal models
@dataclass(frozen=True)
class InternalModel:
    """The bot's belief about the arm: ``torque(q, qd, qdd)`` and ``inertia(q, v)`` (M^ v)."""

    name: str
    interaction: bool  # whether it knows the off-diagonal inertia and the Coriolis-centrifugal torques
    a: float
    b: float
    d: float
    k1: float
    k2: float

    @classmethod
    def of(cls, config: GameConfig, interaction: bool) -> InternalModel:
        p = config.arm
        if p.has_gravity:
            raise UserError("the bots play the game's horizontal arm: they know no gravity")
        arm = TwoJointArm(p)  # the true arm's inertia constants; "naive" then drops what it does not know
        return cls("model" if interaction else "naive", interaction, arm.a, arm.b, arm.d, p.damping1, p.damping2)

    def inertial(self, q2: float, v1: float, v2: float) -> tuple[float, float]:
        bc = self.b * math.cos(q2)
        m11 = self.a + 2.0 * bc
        if not self.interaction:
            return m11 * v1, self.d * v2
        m12 = self.d + bc
        return m11 * v1 + m12 * v2, m12 * v1 + self.d * v2

    def bias(self, q2: float, w1: float, w2: float) -> tuple[float, float]:
        """Coriolis-centrifugal plus damping torques (what holds no acceleration)."""
        if not self.interaction:
            return self.k1 * w1, self.k2 * w2
        h = self.b * math.sin(q2)
        return -h * (2.0 * w1 * w2 + w2 * w2) + self.k1 * w1, h * w1 * w1 + self.k2 * w2

    def accel(self, q2: float, w1: float, w2: float, t1: float, t2: float) -> tuple[float, float]:
        """The motion the model expects from torques (t1, t2): its forward model."""
        c1, c2 = self.bias(q2, w1, w2)
        f1, f2 = t1 - c1, t2 - c2
        bc = self.b * math.cos(q2)
        m11 = self.a + 2.0 * bc
        if not self.interaction:
            return f1 / m11, f2 / self.d
        m12 = self.d + bc
        r = 1.0 / (m11 * self.d - m12 * m12)
        return (self.d * f1 - m12 * f2) * r, (m11 * f2 - m12 * f1) * r

    def predict(self, state: tuple[float, float, float, float], commands: Iterable[tuple],
                period: float, load: Callable[[float, float, float, float], tuple[float, float]] | None = None,
                ) -> tuple[float, float, float, float]:
        """Step ``state`` through ``commands`` (rows ending in the torques t1, t2, each held ``period`` s)
        with ``accel`` and semi-implicit Euler, adding ``load(q1, q2, w1, w2)`` to the torques.

        This loop is where the bots spend their time (a reaction time's worth of steps before every
        decision), so it is ``accel`` and ``bias`` written out: the same operations in the same order,
        so it gives exactly what calling them step by step gives (a test holds it to ``==``). With no
        load or a ``CurlLoad`` it runs compiled (``_cbots.c``, the same operations again) where the
        install built it: about five times faster, the same floats.
        """
        if _c_predict is not None:
            if load is None:
                return _c_predict(state, commands, period, self.a, self.b, self.d, self.k1, self.k2,
                                  self.interaction, None, 0.0, 0.0)
            if type(load) is CurlLoad:
                return _c_predict(state, commands, period, self.a, self.b, self.d, self.k1, self.k2,
                                  self.interaction, load.b, load.l1, load.l2)
        return self.predict_in_python(state, commands, period, load)

    def predict_in_python(self, state: tuple[float, float, float, float], commands: Iterable[tuple],
                          period: float,
                          load: Callable[[float, float, float, float], tuple[float, float]] | None = None,
                          ) -> tuple[float, float, float, float]:
        """``predict`` in Python: where the compiled loop was not built, for other loads, and for its tests."""
        q1, q2, w1, w2 = state
        a, b, d, k1, k2 = self.a, self.b, self.d, self.k1, self.k2
        interaction = self.interaction
        for row in commands:
            t1, t2 = row[-2], row[-1]
            if load is not None:
                e1, e2 = load(q1, q2, w1, w2)
                t1, t2 = t1 + e1, t2 + e2
            if interaction:
                h = b * math.sin(q2)
                f1 = t1 - (-h * (2.0 * w1 * w2 + w2 * w2) + k1 * w1)
                f2 = t2 - (h * w1 * w1 + k2 * w2)
                bc = b * math.cos(q2)
                m11 = a + 2.0 * bc
                m12 = d + bc
                r = 1.0 / (m11 * d - m12 * m12)
                a1, a2 = (d * f1 - m12 * f2) * r, (m11 * f2 - m12 * f1) * r
            else:
                f1, f2 = t1 - k1 * w1, t2 - k2 * w2
                a1, a2 = f1 / (a + 2.0 * (b * math.cos(q2))), f2 / d
            w1 += a1 * period
            w2 += a2 * period
            q1 += w1 * period
            q2 += w2 * period
        return q1, q2, w1, w2

    def torque(self, q2: float, w1: float, w2: float, a1: float, a2: float) -> tuple[float, float]:
        i1, i2 = self.inertial(q2, a1, a2)
        c1, c2 = self.bias(q2, w1, w2)
        return i1 + c1, i2 + c2


@dataclass(frozen=True)
class CurlLoad:
    """A curl field at the hand as a bot believes it: ``J(q)^T b (vy, -vx)`` N m, v the hand's velocity.

    The lab's adapting bot learns ``b`` and sets this as its ``load_estimate``; a plain value rather
    than a closure, so ``InternalModel.predict`` can hand it to the compiled loop.
    """

    l1: float
    l2: float
    b: float

    def __call__(self, q1: float, q2: float, w1: float, w2: float) -> tuple[float, float]:
        # The hand Jacobian formed once (the order of operations is _cbots.c's too).
        l1, l2, b = self.l1, self.l2, self.b
        s12, c12 = math.sin(q1 + q2), math.cos(q1 + q2)
        jx1, jy1 = -l1 * math.sin(q1) - l2 * s12, l1 * math.cos(q1) + l2 * c12
        jx2, jy2 = -l2 * s12, l2 * c12
        fx = b * (jy1 * w1 + jy2 * w2)
        fy = b * -(jx1 * w1 + jx2 * w2)
        return jx1 * fx + jy1 * fy, jx2 * fx + jy2 * fy


@dataclass(frozen=True)
class MatrixLoad:
    """A viscous field at the hand as a bot believes it: ``J(q)^T K v`` N m, ``K`` = ((k11, k12), (k21, k22)).

    The lab's adapting bot sets it when it learns a full matrix (a curl estimate is in ``K`` then too);
    the Jacobian formed once, in ``CurlLoad``'s order of operations.
    """

    l1: float
    l2: float
    k11: float
    k12: float
    k21: float
    k22: float

    def __call__(self, q1: float, q2: float, w1: float, w2: float) -> tuple[float, float]:
        l1, l2 = self.l1, self.l2
        s12, c12 = math.sin(q1 + q2), math.cos(q1 + q2)
        jx1, jy1 = -l1 * math.sin(q1) - l2 * s12, l1 * math.cos(q1) + l2 * c12
        jx2, jy2 = -l2 * s12, l2 * c12
        vx, vy = jx1 * w1 + jx2 * w2, jy1 * w1 + jy2 * w2
        fx, fy = self.k11 * vx + self.k12 * vy, self.k21 * vx + self.k22 * vy
        return jx1 * fx + jy1 * fy, jx2 * fx + jy2 * fy


# --------------------------------------------------------------------- planning
@dataclass(frozen=True)
class Quintic:
    """One joint's minimum-jerk-like path: a quintic from (q0, v0, a0) to (qf, 0, 0) in time T."""

    c: tuple[float, float, float, float, float, float]
    duration: float
    end: float

    @classmethod
    def between(cls, q0: float, v0: float, a0: float, qf: float, duration: float) -> Quintic:
        t = duration
        h = qf - q0
        c3 = (20.0 * h - (12.0 * v0) * t - (3.0 * a0) * t * t) / (2.0 * t**3)
        c4 = (-30.0 * h + (16.0 * v0) * t + (3.0 * a0) * t * t) / (2.0 * t**4)
        c5 = (12.0 * h - (6.0 * v0) * t - a0 * t * t) / (2.0 * t**5)
        return cls((q0, v0, 0.5 * a0, c3, c4, c5), duration, qf)

    def at(self, t: float) -> tuple[float, float, float]:
        if t >= self.duration:
            return self.end, 0.0, 0.0
        c0, c1, c2, c3, c4, c5 = self.c
        q = c0 + t * (c1 + t * (c2 + t * (c3 + t * (c4 + t * c5))))
        v = c1 + t * (2.0 * c2 + t * (3.0 * c3 + t * (4.0 * c4 + t * 5.0 * c5)))
        a = 2.0 * c2 + t * (6.0 * c3 + t * (12.0 * c4 + t * 20.0 * c5))
        return q, v, a


def target_posture(config: GameConfig, x: float, y: float, q1_now: float) -> tuple[float, float]:
    """The elbow-flexed (q2 > 0) posture with the hand at (x, y), shoulder angle unwrapped near ``q1_now``.

    The game draws its targets with the elbow flexed, and reaching the other solution would
    swing the forearm through the straight-arm singularity.
    """
    l1, l2 = config.arm.l1, config.arm.l2
    c2 = (x * x + y * y - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
    q2 = math.acos(min(1.0, max(-1.0, c2)))
    q1 = math.atan2(y, x) - math.atan2(l2 * math.sin(q2), l1 + l2 * math.cos(q2))
    q1 += 2.0 * math.pi * round((q1_now - q1) / (2.0 * math.pi))
    return q1, q2


# ---------------------------------------------------------------------- the bot
@dataclass
class _Plan:
    target: Target
    start: float
    paths: tuple[Quintic, Quintic]
    retry_at: float


class ReachingBot:
    """Plans minimum-jerk reaches and tracks them by computed torque through its internal model."""

    #: Candidate reach durations (s); the planner takes the shortest whose torques fit.
    DURATIONS = tuple(0.2 + 0.025 * i for i in range(57))
    #: Fraction of each joint's strength the plan may use: the rest is left for feedback.
    TORQUE_MARGIN = 0.9
    #: Feedback gains on the joint error, as accelerations (1/s^2 and 1/s): critically damped at about 1.2 Hz.
    KP = 60.0
    KD = 15.5
    #: How long after a plan's end the bot waits, holding the posture, before it replans a miss.
    SETTLE = 0.1
    #: What a player sees is this old (s): a visual reaction time.
    REACTION_TIME = 0.25

    def __init__(self, name: str, interaction: bool, control_period: float = CONTROL_PERIOD) -> None:
        self.name = name
        self.interaction = interaction
        self.control_period = control_period
        self._model: InternalModel | None = None
        self._config: GameConfig | None = None
        self._plan: _Plan | None = None
        self._setup: tuple | None = None
        self._history: deque = deque()
        #: What the bot believes pushes on the arm besides its muscles, ``(q1, q2, w1, w2) -> (t1, t2)`` N m,
        #: and where it aims for a target, ``(x, y) -> (x, y)``: None in the game; the lab's adapting bot
        #: (armgame/lab/bots.py) learns both.
        self.load_estimate: Callable[[float, float, float, float], tuple[float, float]] | None = None
        self.aim: Callable[[float, float], tuple[float, float]] | None = None
        #: Noise on its motor command (``MotorNoise``), None for none: the game's bots never have any.
        self.noise: MotorNoise | None = None
        self._noise_stream: _NoiseStream | None = None

    def period_steps(self, dt: float) -> int:
        return max(1, round(self.control_period / dt))

    # -------------------------------------------------------------- set-up
    def _bind(self, session: GameSession) -> None:
        config = session.config
        self._config = config
        self._model = InternalModel.of(config, self.interaction)
        period = self.period_steps(config.dt) * config.dt
        joints = []
        # Each joint's agonist (positive moment) and antagonist, with their rates over one period.
        for j in (0, 1):
            pos = max(range(4), key=lambda i: session.muscles.moments[i][j])
            neg = min(range(4), key=lambda i: session.muscles.moments[i][j])
            spec_p, spec_n = config.muscles[pos], config.muscles[neg]
            joints.append((
                pos, neg, session.muscles.moments[pos][j], session.muscles.moments[neg][j],
                -math.expm1(-period / spec_p.rise_time), -math.expm1(-period / spec_p.decay_time),
                -math.expm1(-period / spec_n.rise_time), -math.expm1(-period / spec_n.decay_time),
            ))
        self._setup = (period, tuple(joints))
        self._plan = None
        self._history = deque()

    def _strength(self, j: int) -> float:
        assert self._setup is not None
        jp = self._setup[1][j]
        return min(jp[2], -jp[3])

    def _replan(self, target: Target, state: tuple[float, float, float, float], now: float) -> None:
        assert self._model is not None and self._config is not None
        q1, q2, w1, w2 = state
        x, y = (target.x, target.y) if self.aim is None else self.aim(target.x, target.y)
        f1, f2 = target_posture(self._config, x, y, q1)
        # The plan starts at zero acceleration: the bot does not see acceleration.
        limit1, limit2 = self.TORQUE_MARGIN * self._strength(0), self.TORQUE_MARGIN * self._strength(1)
        model = self._model
        paths = None
        for duration in self.DURATIONS:
            paths = (Quintic.between(q1, w1, 0.0, f1, duration), Quintic.between(q2, w2, 0.0, f2, duration))
            fits = True
            for i in range(13):
                t = duration * i / 12.0
                p1, v1, a1 = paths[0].at(t)
                p2, v2, a2 = paths[1].at(t)
                t1, t2 = model.torque(p2, v1, v2, a1, a2)
                if self.load_estimate is not None:
                    e1, e2 = self.load_estimate(p1, p2, v1, v2)
                    t1, t2 = t1 - e1, t2 - e2
                if abs(t1) > limit1 or abs(t2) > limit2:
                    fits = False
                    break
            if fits:
                break
        assert paths is not None
        self._plan = _Plan(target, now, paths, now + paths[0].duration + self.SETTLE)

    def _estimate(self) -> tuple[float, float, float, float]:
        """The arm now, predicted from what the bot saw a reaction time ago and the torques it has
        commanded since (an efference copy), through its own forward model."""
        assert self._model is not None and self._setup is not None
        history = self._history
        return self._model.predict(history[0][0], history, self._setup[0], self.load_estimate)

    def _commanded(self, want1: float, want2: float) -> tuple[float, float]:
        """The joints' torques the bot commands for the torques it wants: the same, or with its motor noise."""
        if self.noise is None:
            return want1, want2
        if self._noise_stream is None:
            assert self._setup is not None
            self._noise_stream = _NoiseStream(self.noise, self._setup[0])
        n1, n2 = self._noise_stream.next()
        return want1 * (1.0 + n1), want2 * (1.0 + n2)

    # ----------------------------------------------------------------- act
    def act(self, session: GameSession) -> list[tuple[str, str]]:
        if session.over:
            return []
        if self._config is not session.config:
            self._bind(session)
        assert self._model is not None and self._setup is not None
        period, joints = self._setup
        if not self._history:
            # Before the first move the arm sat still at its start posture with the first target shown.
            lag = max(1, round(self.REACTION_TIME / period))
            self._history = deque([(session.state, session.rules.target, 0.0, 0.0)] * lag, maxlen=lag)
        now = session.time
        seen_target = self._history[0][1]
        q1, q2, w1, w2 = self._estimate()
        plan = self._plan
        if plan is None or plan.target is not seen_target or now >= plan.retry_at:
            self._replan(seen_target, (q1, q2, w1, w2), now)
            plan = self._plan
            assert plan is not None
        # The torque wanted one period from now, when this decision's presses have had their effect.
        t = now + period - plan.start
        d1, v1, a1 = plan.paths[0].at(t)
        d2, v2, a2 = plan.paths[1].at(t)
        p1, p2 = q1 + w1 * period, q2 + w2 * period
        u1 = a1 + self.KP * (d1 - p1) + self.KD * (v1 - w1)
        u2 = a2 + self.KP * (d2 - p2) + self.KD * (v2 - w2)
        i1, i2 = self._model.inertial(p2, u1, u2)
        c1, c2 = self._model.bias(p2, w1, w2)
        if self.load_estimate is not None:
            e1, e2 = self.load_estimate(p1, p2, w1, w2)
            c1, c2 = c1 - e1, c2 - e2
        events: list[tuple[str, str]] = []
        act, held, keys = session.muscles.activation, session.held, session.muscles.keys
        applied = []
        for (pos, neg, mp, mn, rp, dp, rn, dn), want in zip(joints, self._commanded(i1 + c1, i2 + c2), strict=True):
            ap, an = act[pos], act[neg]
            # Predicted activations one period on, with each muscle's key down or up.
            ap_on, ap_off = ap + (1.0 - ap) * rp, ap - ap * dp
            an_on, an_off = an + (1.0 - an) * rn, an - an * dn
            # The four choices (neither key, agonist, antagonist, both) in that order, the first cheapest
            # kept, with a little cost on each key down: pushing against oneself is wasted effort. Written
            # out rather than looped: this runs twice a decision, a decision every physics step.
            n0 = mp * ap_off + mn * an_off
            n1 = mp * ap_on + mn * an_off
            n2 = mp * ap_off + mn * an_on
            n3 = mp * ap_on + mn * an_on
            k0 = (n0 - want) ** 2 + _NO_PRESS
            k1 = (n1 - want) ** 2 + _ONE_PRESS
            k2 = (n2 - want) ** 2 + _ONE_PRESS
            k3 = (n3 - want) ** 2 + _TWO_PRESSES
            best, best_cost, best_net = 0, math.inf, 0.0
            if k0 < best_cost:
                best, best_cost, best_net = 0, k0, n0
            if k1 < best_cost:
                best, best_cost, best_net = 1, k1, n1
            if k2 < best_cost:
                best, best_cost, best_net = 2, k2, n2
            if k3 < best_cost:
                best, best_net = 3, n3
            # The torque over the coming period, for the forward model: between now's and the end's.
            applied.append(0.5 * (mp * ap + mn * an + best_net))
            on = best == 1 or best == 3
            if on != held[pos]:
                events.append((keys[pos], DOWN if on else UP))
            on = best >= 2
            if on != held[neg]:
                events.append((keys[neg], DOWN if on else UP))
        self._history.append((session.state, session.rules.target, applied[0], applied[1]))
        return events


BOT_NAMES = ("model", "naive")


def make_bot(name: str) -> ReachingBot:
    """A fresh bot by name: ``model`` (knows the interaction torques) or ``naive`` (does not)."""
    if name == "model":
        return ReachingBot("model", interaction=True)
    if name == "naive":
        return ReachingBot("naive", interaction=False)
    raise UserError(unknown_name("bot", name, BOT_NAMES))


# ----------------------------------------------------------------- the driver
class Autopilot:
    """A session with a bot at the keys: ``advance(n)`` runs n physics steps, letting the bot act
    before every step that starts one of its control periods.

    The bot acts at whole multiples of its period counted from the start of the game, never
    at frame boundaries, so the window (any frame rate) and a headless run give the same
    timeline. It quacks like a ``GameSession`` for ``RealTimeDriver`` (``config``, ``advance``).
    """

    def __init__(self, session: GameSession, bot: Bot) -> None:
        self.session = session
        self.bot = bot
        self.config = session.config
        self.period = bot.period_steps(session.config.dt)

    def advance(self, n: int) -> int:
        session, period = self.session, self.period
        done = 0
        while done < n and not session.over:
            offset = session.steps % period
            if offset == 0:
                for key, action in self.bot.act(session):
                    session.key_event(key, action)
            ran = session.advance(min(n - done, period - offset))
            if ran == 0:
                break
            done += ran
        return done

    def play(self) -> GameResult:
        """The whole game, headless, as fast as the machine allows."""
        self.advance(self.session.total_steps - self.session.steps)
        return self.session.result()


def play_bot(config: GameConfig, bot: Bot | str) -> GameSession:
    """Play one whole game headless with ``bot`` (an instance or a name); returns the finished session."""
    session = GameSession(config)
    Autopilot(session, make_bot(bot) if isinstance(bot, str) else bot).play()
    return session
