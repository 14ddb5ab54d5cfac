"""Bots in the lab: the game's reaching bots, and one that adapts to the perturbation trial by trial.

``LabBot`` is the game's ``ReachingBot`` (minimum-jerk plans tracked by computed torque
through an internal model, keys pressed by sigma-delta; armgame/game/bots.py) told that a lab
run returns the arm home between trials: at each new trial it forgets what it saw before the
jump, as a player's eyes would.

The ``adaptive`` bot adds to the ``model`` bot's internal model an estimate of the
perturbation, updated after each trial by a state-space learner (the two-rate model of Smith,
Ghazizadeh & Shadmehr 2006, ``armgame.lab.learner``):

* a curl field: its internal model adds the torque ``J(q)^T b^ [[0, 1], [-1, 0]] v`` it expects
  the field to exert, which it cancels and predicts. After a trial it measures the field it met
  by least squares on what it felt: from the states it saw every control period, the torque
  the arm's motion needed (inverse dynamics, accelerations by central differences) minus its
  muscles' torque is the external torque, fitted as ``b`` times the unit field's torque. The
  learner's error is ``e = b_measured - b^``.
* a full-matrix viscous field (a protocol with a ``viscous`` block): its internal model holds a
  matrix ``B^`` (four numbers, learned by four learners at once) instead of ``b^``. After a trial it
  fits the correction ``dB`` (the learner's error) by least squares on the same external torque less
  the torque ``J^T B^ v`` it expected, with a small ridge toward ``dB = 0``: a reach along ``u``
  shows ``B u`` and little else, and the ridge keeps the rest near zero. The targets' directions
  together teach the whole matrix, more slowly than the curl's one number (each reach corrects about
  half of it).
* a visual rotation: it aims its true hand at the target rotated by ``-theta^`` about home.
  After a trial it measures the rotation as the angle from its true hand's displacement (felt)
  to the shown hand's (seen) at the trial's end; ``e = theta_measured - theta^``.

So with the field on, errors start large and shrink as ``b^`` grows; on a catch trial or in
washout, the bot still expects the field and errs the other way (the after-effect), and
unlearns at the learner's rates. On an error-clamp (channel) trial the channel holds the hand on
the straight line, so there is no movement error to learn from: the learner's error is 0 and only
its retentions act (Smith et al. 2006 model channel trials so), which is what lets spontaneous
recovery show. Mirror and joint-space displays are not learned by this bot (it
plays them as the model bot does): they need more than one parameter.

Issue 41. **The frame its field is held in** (``frame``, ``FRAMES``): ``hand`` (the default, as above: a
curl's ``b^`` or a matrix ``B^`` at the hand, whose torque ``J(q)^T B^ v`` follows the arm to any posture
as the same hand field) or ``joint`` (a matrix ``W^`` at the joints, the torque ``W^ qdot`` whatever the
posture: learned by the same least squares on the external torque, with the design ``qdot``). At the
posture it is learned at the two predict the same forces; at another they differ, which is what the
``frames`` preset tests. **What it sees**: a trial that hides the cursor (``TrialPlan.feedback``) gives it
no cursor to log; with ``endpoint`` feedback it measures the rotation from where the cursor was shown at
the end, with ``none`` it sees no visual error at all, and its rotation learner is taught 0 (its
retentions act, as on a channel trial). What it feels (the field's torque) it learns from on every trial.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import UserError
from ..game.bots import CurlLoad, MatrixLoad, MotorNoise, ReachingBot
from ..words import unknown_name
from .learner import TUNING_WIDTH_DEG, DirectionalLearner, TwoRateLearner
from .session import LabSession

LAB_BOT_NAMES = ("model", "naive", "adaptive")
#: The adaptive bot's internal model of the curl field and the rotation: ``global`` (one estimate for every
#: direction: it generalizes fully, by construction) or ``local`` (``DirectionalLearner``: Gaussian tuning over
#: movement direction, so what it learns in one direction falls off with the angle from it).
REPRESENTATIONS = ("global", "local")
#: The coordinates its internal model holds a force field in (issue 41): at the hand, or at the joints.
FRAMES = ("hand", "joint")
#: The viscous field's fit: the ridge toward no correction, as a fraction of the fit's mean curvature.
RIDGE = 0.01


@dataclass(frozen=True)
class LearningRates:
    """The two-rate learner's retention (A) and learning (B) rates, fast and slow; the defaults and what is known
    of their source: ``armgame.lab.learner``. ``TwoRateLearner`` checks them (0 to 1, the fast process
    forgetting and learning faster)."""

    retention_fast: float = 0.59
    retention_slow: float = 0.992
    rate_fast: float = 0.21
    rate_slow: float = 0.02


class LabBot(ReachingBot):
    """A reaching bot for the lab: forgets its view at each new trial; learns if given rates."""

    def __init__(self, name: str, interaction: bool, rates: LearningRates | None = None,
                 representation: str = "global", width_deg: float = TUNING_WIDTH_DEG, frame: str = "hand") -> None:
        super().__init__(name, interaction)
        if representation not in REPRESENTATIONS:
            raise UserError(unknown_name("learner representation", representation, REPRESENTATIONS))
        if frame not in FRAMES:
            raise UserError(unknown_name("learner frame", frame, FRAMES))
        self.frame = frame
        self.rates = rates
        self.representation = representation
        self.width_deg = float(width_deg)
        self._trial: int | None = None
        #: The direction (degrees) of the trial it is on: where a local learner's estimates are read and taught.
        self._direction = 0.0
        self._log: list[tuple[float, float, float, float, float, float, float, float, float, float]] = []
        self.curl_learner: TwoRateLearner | DirectionalLearner | None = None
        self.rotation_learner: TwoRateLearner | DirectionalLearner | None = None
        if rates is not None:
            self.curl_learner = TwoRateLearner(rates.retention_fast, rates.retention_slow, rates.rate_fast,
                                               rates.rate_slow)
            self.rotation_learner = TwoRateLearner(rates.retention_fast, rates.retention_slow, rates.rate_fast,
                                                   rates.rate_slow)
            if representation == "local":
                self.curl_learner = DirectionalLearner(self.curl_learner, width_deg)
                self.rotation_learner = DirectionalLearner(self.rotation_learner, width_deg)
        #: (trial, measured field b, estimate b^ it reached with; measured rotation, estimate) per trial.
        self.history: list[tuple[int, float, float, float, float]] = []
        #: With a viscous field in the protocol: the learner of ``B^`` (row by row, b11 b12 b21 b22), made at the
        #: first trial.
        self.matrix_learner: TwoRateLearner | None = None
        #: (trial, the correction dB it measured: b11 b12 b21 b22) per trial, with a viscous field.
        self.matrix_history: list[tuple[int, np.ndarray]] = []
        #: A hand field ``F = B v`` (N s/m) its internal model holds from the start, on top of what it learns:
        #: the bot that knows the field (how the presets' fields are checked to be counterable with the keys).
        self.known_field: tuple[tuple[float, float], tuple[float, float]] | None = None

    # ------------------------------------------------------------- the estimates
    def describe(self) -> str:
        """Its learner's representation, in words, for every run's output (empty for a bot that does not learn)."""
        if self.rates is None:
            return ""
        if self.representation == "local":
            return (f"local learner: Gaussian tuning over movement direction, bases of s.d. {self.width_deg:g} deg "
                    "(learning falls off with the angle from the trained direction)")
        return "global learner: one estimate for every direction (it generalizes fully)"

    def frame_words(self) -> str:
        """The frame its field is held in, in words, for every adaptive run's output (empty for a bot that does
        not learn)."""
        if self.rates is None:
            return ""
        if self.frame == "joint":
            return ("force fields held in joint coordinates: torque W^ qdot at the joints, the same torque at any "
                    "posture (--frame hand holds them at the hand)")
        return ("force fields held in hand coordinates: force B^ v at the hand, the same force at any posture "
                "(--frame joint holds them at the joints)")

    def _estimate_of(self, learner: TwoRateLearner | DirectionalLearner | None) -> float:
        if learner is None:
            return 0.0
        if isinstance(learner, DirectionalLearner):
            return learner.at(self._direction)
        return float(learner.estimate)

    def _teach(self, learner: TwoRateLearner | DirectionalLearner, error: float) -> None:
        if isinstance(learner, DirectionalLearner):
            learner.update(error, self._direction)
        else:
            learner.update(error)

    @property
    def curl_estimate(self) -> float:
        """b^ (N s/m) for the trial it is on (a local learner's, in that trial's direction)."""
        return self._estimate_of(self.curl_learner)

    @property
    def rotation_estimate(self) -> float:
        """Radians, counter-clockwise (a local learner's, in the direction of the trial it is on)."""
        return self._estimate_of(self.rotation_learner)

    @property
    def matrix_estimate(self) -> tuple[tuple[float, float], tuple[float, float]] | None:
        """``B^`` (N s/m) of a viscous field (with ``frame = "joint"``: ``W^``, N m s/rad), or None when the bot
        learns ``b^`` (the curl) instead."""
        if self.matrix_learner is None:
            return None
        b11, b12, b21, b22 = (float(v) for v in self.matrix_learner.estimate)  # type: ignore[union-attr]
        return (b11, b12), (b21, b22)

    def _expected_field(self) -> tuple[tuple[float, float], tuple[float, float]] | None:
        """The matrix its internal model adds beyond the learned curl: the known field plus the learned ``B^``."""
        learned = self.matrix_estimate if self.frame == "hand" else None
        if learned is None:
            return self.known_field
        known = self.known_field or ((0.0, 0.0), (0.0, 0.0))
        return tuple(tuple(k + e for k, e in zip(kr, er, strict=True))  # type: ignore[return-value]
                     for kr, er in zip(known, learned, strict=True))

    def _install(self, session: LabSession) -> None:
        p = session.config.arm
        l1, l2 = p.l1, p.l2
        b = self.curl_estimate
        kinds = {block.perturbation.kind for block in session.protocol.blocks}
        if self.rates is not None and self.matrix_learner is None \
                and ("viscous" in kinds or "joint_viscous" in kinds or (self.frame == "joint" and "curl" in kinds)):
            r = self.rates
            self.matrix_learner = TwoRateLearner(r.retention_fast, r.retention_slow, r.rate_fast, r.rate_slow,
                                                 fast=np.zeros(4), slow=np.zeros(4))
        expected = self._expected_field()
        if self.frame == "joint" and self.matrix_learner is not None:
            (w11, w12), (w21, w22) = self.matrix_estimate  # type: ignore[misc]
            self.load_estimate = JointMatrixLoad(w11, w12, w21, w22, None if self.known_field is None else
                                                 MatrixLoad(l1, l2, *self.known_field[0], *self.known_field[1]))
        elif expected is not None:
            (k11, k12), (k21, k22) = expected
            # plus the learned curl b^ [[0, 1], [-1, 0]]
            self.load_estimate = MatrixLoad(l1, l2, k11, k12 + b, k21 - b, k22)
        elif b != 0.0:
            self.load_estimate = CurlLoad(l1, l2, b)
        else:
            self.load_estimate = None
        theta = self.rotation_estimate
        if theta != 0.0:
            hx, hy = session.home
            c, s = math.cos(-theta), math.sin(-theta)

            def aim(x: float, y: float) -> tuple[float, float]:
                dx, dy = x - hx, y - hy
                return hx + c * dx - s * dy, hy + s * dx + c * dy
            self.aim = aim
        else:
            self.aim = None

    # ------------------------------------------------------------------- act
    def act(self, session: LabSession) -> list[tuple[str, str]]:  # type: ignore[override]
        if session.over:
            return []
        if session.trial_index != self._trial:
            if self._trial is not None and self.rates is not None and session.outcomes:
                self._learn(session)
            self._trial = session.trial_index
            # The direction it will move in: its target's (the envs' policy sees no plan, and learns globally).
            plan = getattr(session, "plan", None)
            if plan is not None:
                self._direction = plan.target_deg
            self._bind(session)  # the arm jumped home: what the bot saw before is no use now
            self._install(session)
            self._log = []
        if self.rates is not None and session.phase == "reach":
            q1, q2, w1, w2 = session.state
            t1, t2 = session.muscles.torque()
            x, y = session.hand()
            # It logs the cursor only when it is shown: a trial without vision gives it none to learn from.
            cx, cy = session.cursor if getattr(session, "cursor_visible", True) else (math.nan, math.nan)
            self._log.append((q1, q2, w1, w2, t1, t2, x, y, cx, cy))
        return super().act(session)

    # ----------------------------------------------------------------- learn
    def _learn(self, session: LabSession) -> None:
        outcome = session.outcomes[-1]
        log = self._log
        assert self.curl_learner is not None and self.rotation_learner is not None
        b_hat, theta_hat = self.curl_estimate, self.rotation_estimate
        b_seen = self._measure_curl(session, log)
        feedback = getattr(outcome.plan, "feedback", "full")
        if feedback == "full":
            theta_seen = self._measure_rotation(session, log)
        elif feedback == "endpoint" and log and outcome.xs:  # the cursor shown where the reach ended
            theta_seen = self._measure_rotation(session, [(*log[-1][:8], outcome.xs[-1], outcome.ys[-1])],
                                                outcome.plan.home)
        else:
            theta_seen = theta_hat  # nothing seen: no visual error (the retentions act, as in a channel)
        self.history.append((outcome.plan.index, b_seen, b_hat, theta_seen, theta_hat))
        if self.matrix_learner is not None:
            correction = self._measure_matrix(session, log)
            self.matrix_history.append((outcome.plan.index, correction))
            self.matrix_learner.update(0.0 if outcome.plan.channel else correction)
        if outcome.plan.channel:  # held on the line: no error to learn from
            self._teach(self.curl_learner, 0.0)
            self._teach(self.rotation_learner, 0.0)
            return
        if self.matrix_learner is not None:
            self._teach(self.rotation_learner, theta_seen - theta_hat)
            return  # the matrix holds the curl too
        self._teach(self.curl_learner, b_seen - b_hat)
        self._teach(self.rotation_learner, theta_seen - theta_hat)

    def _measure_curl(self, session: LabSession, log: list) -> float:
        """The curl field's b that best explains the external torque felt over the reach (0 if none moved)."""
        if len(log) < 5:
            return 0.0
        l1, l2 = session.model.params.l1, session.model.params.l2
        num = den = 0.0
        for q1, q2, w1, w2, r1, r2 in self._external_torques(session, log):
            fx, fy = curl_unit_force(l1, l2, q1, q2, w1, w2)
            g1, g2 = curl_unit_torque(l1, l2, q1, q2, fx, fy)
            num += r1 * g1 + r2 * g2
            den += g1 * g1 + g2 * g2
        return num / den if den > 1e-12 else 0.0

    def _external_torques(self, session: LabSession, log: list):
        """Per control period inside the log: (q1, q2, w1, w2, external torque 1, 2) by inverse dynamics."""
        assert self._setup is not None
        period = self._setup[0]
        arm = session.model
        k1, k2 = arm.params.damping1, arm.params.damping2
        for k in range(1, len(log) - 1):
            q1, q2, w1, w2, t1, t2, *_ = log[k]
            qd1 = (log[k + 1][2] - log[k - 1][2]) / (2.0 * period)
            qd2 = (log[k + 1][3] - log[k - 1][3]) / (2.0 * period)
            bc, h = arm.b * math.cos(q2), arm.b * math.sin(q2)
            m11, m12 = arm.a + 2.0 * bc, arm.d + bc
            need1 = m11 * qd1 + m12 * qd2 - h * (2.0 * w1 * w2 + w2 * w2) + k1 * w1
            need2 = m12 * qd1 + arm.d * qd2 + h * w1 * w1 + k2 * w2
            yield q1, q2, w1, w2, need1 - t1, need2 - t2

    def _measure_matrix(self, session: LabSession, log: list) -> np.ndarray:
        """The correction ``dB`` (b11 b12 b21 b22) the reach showed: the external torque felt less the torque
        ``J^T B^ v`` it expected, fitted as ``J^T dB v`` by least squares with a small ridge
        (``RIDGE`` of the fit's mean curvature) toward ``dB = 0``. A reach mostly along ``u`` shows ``B u``
        well and the rest of ``B`` hardly at all: the ridge keeps what it cannot see near zero instead of
        letting noise write it. Zeros if the hand did not move."""
        if len(log) < 5:
            return np.zeros(4)
        l1, l2 = session.config.arm.l1, session.config.arm.l2
        # What it expected is what it predicted with this trial: _install's load (the matrix learner,
        # when there is one, always gives it one), unchanged until this trial is learned from.
        expected = self.load_estimate
        assert isinstance(expected, (MatrixLoad, JointMatrixLoad))
        g = np.zeros((4, 4))
        h = np.zeros(4)
        if self.frame == "joint":  # tau = W qdot: d tau / d (w11, w12, w21, w22) = [[w1, w2, 0, 0], [0, 0, w1, w2]]
            for q1, q2, w1, w2, r1, r2 in self._external_torques(session, log):
                t1, t2 = expected(q1, q2, w1, w2)
                design = np.array([[w1, w2, 0.0, 0.0], [0.0, 0.0, w1, w2]])
                g += design.T @ design
                h += design.T @ np.array([r1 - t1, r2 - t2])
            scale = np.trace(g) / 4.0
            return np.zeros(4) if scale < 1e-12 else np.linalg.solve(g + RIDGE * scale * np.eye(4), h)
        for q1, q2, w1, w2, r1, r2 in self._external_torques(session, log):
            vy, mvx = curl_unit_force(l1, l2, q1, q2, w1, w2)
            vx = -mvx
            t1, t2 = expected(q1, q2, w1, w2)
            # d torque / d (b11, b12, b21, b22): J^T applied to (vx, 0), (vy, 0), (0, vx), (0, vy).
            design = np.array([curl_unit_torque(l1, l2, q1, q2, vx, 0.0), curl_unit_torque(l1, l2, q1, q2, vy, 0.0),
                               curl_unit_torque(l1, l2, q1, q2, 0.0, vx), curl_unit_torque(l1, l2, q1, q2, 0.0, vy)]).T
            g += design.T @ design
            h += design.T @ np.array([r1 - t1, r2 - t2])
        scale = np.trace(g) / 4.0
        if scale < 1e-12:
            return np.zeros(4)
        return np.linalg.solve(g + RIDGE * scale * np.eye(4), h)

    @staticmethod
    def _measure_rotation(session: LabSession, log: list, home: tuple[float, float] | None = None) -> float:
        """The angle from the felt displacement to the seen one at the trial's end (0 if the hand stayed home)."""
        if not log:
            return 0.0
        hx, hy = session.home if home is None else home
        _q1, _q2, _w1, _w2, _t1, _t2, x, y, cx, cy = log[-1]
        dx, dy, sx, sy = x - hx, y - hy, cx - hx, cy - hy
        if math.hypot(dx, dy) < 0.2 * session.protocol.distance:
            return 0.0
        return math.atan2(dx * sy - dy * sx, dx * sx + dy * sy)


@dataclass(frozen=True)
class JointMatrixLoad:
    """A viscous field at the joints as a bot believes it: ``W qdot`` N m (``frame = "joint"``), plus a known hand
    field if it holds one."""

    w11: float
    w12: float
    w21: float
    w22: float
    hand: MatrixLoad | None = None

    def __call__(self, q1: float, q2: float, w1: float, w2: float) -> tuple[float, float]:
        t1, t2 = self.w11 * w1 + self.w12 * w2, self.w21 * w1 + self.w22 * w2
        if self.hand is not None:
            e1, e2 = self.hand(q1, q2, w1, w2)
            t1, t2 = t1 + e1, t2 + e2
        return t1, t2


def curl_unit_force(l1: float, l2: float, q1: float, q2: float, w1: float, w2: float) -> tuple[float, float]:
    """The curl field's force at b = 1 N s/m: (vy, -vx) with v the hand's velocity."""
    s1, c1 = math.sin(q1), math.cos(q1)
    s12, c12 = math.sin(q1 + q2), math.cos(q1 + q2)
    vx = (-l1 * s1 - l2 * s12) * w1 - l2 * s12 * w2
    vy = (l1 * c1 + l2 * c12) * w1 + l2 * c12 * w2
    return vy, -vx


def curl_unit_torque(l1: float, l2: float, q1: float, q2: float, fx: float, fy: float) -> tuple[float, float]:
    """J(q)^T (fx, fy)."""
    s1, c1 = math.sin(q1), math.cos(q1)
    s12, c12 = math.sin(q1 + q2), math.cos(q1 + q2)
    return (-l1 * s1 - l2 * s12) * fx + (l1 * c1 + l2 * c12) * fy, -l2 * s12 * fx + l2 * c12 * fy


#: The rates of a learner that learns nothing more: what it holds stays as it was set (``holding_bot``).
FROZEN = LearningRates(0.0, 1.0, 0.0, 0.0)


def holding_bot(frame: str, matrix: np.ndarray) -> LabBot:
    """The adaptive bot whose learned field in ``frame`` is ``matrix`` (``B^``, N s/m, at the hand; ``W^``, N m s/rad,
    at the joints), learning nothing more: with the true field, a learner that compensates it exactly (issue 50: the
    frames index is calibrated against it, ``designs.held_field_indices``)."""
    bot = make_lab_bot("adaptive", FROZEN, frame=frame)
    r = FROZEN
    bot.matrix_learner = TwoRateLearner(r.retention_fast, r.retention_slow, r.rate_fast, r.rate_slow,
                                        fast=np.zeros(4), slow=np.asarray(matrix, dtype=float).reshape(4))
    return bot


def make_lab_bot(name: str, rates: LearningRates | None = None, representation: str = "global",
                 width_deg: float = TUNING_WIDTH_DEG, noise: MotorNoise | None = None, frame: str = "hand") -> LabBot:
    """``model``, ``naive`` (the game's bots) or ``adaptive`` (the model bot learning the perturbation, with a
    ``global`` or ``local`` representation of it: ``REPRESENTATIONS``), with ``noise`` on its motor command if
    given (``MotorNoise``: the keys it presses carry it)."""
    if name == "model":
        bot = LabBot("model", interaction=True)
    elif name == "naive":
        bot = LabBot("naive", interaction=False)
    elif name == "adaptive":
        bot = LabBot("adaptive", interaction=True, rates=rates or LearningRates(), representation=representation,
                     width_deg=width_deg, frame=frame)
    else:
        raise UserError(unknown_name("lab bot", name, LAB_BOT_NAMES))
    bot.noise = noise
    return bot
