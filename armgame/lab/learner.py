"""Trial-by-trial adaptation: the two-rate state-space model of Smith, Ghazizadeh & Shadmehr (2006).

Two processes learn from the same error ``e(n)`` on trial n and add up to the net adaptation:

    x_f(n+1) = A_f x_f(n) + B_f e(n)        the fast process: learns fast, forgets fast
    x_s(n+1) = A_s x_s(n) + B_s e(n)        the slow process: learns slowly, retains well
    x(n)     = x_f(n) + x_s(n)

with retentions ``A`` and learning rates ``B`` in [0, 1], ``A_f < A_s`` and ``B_f > B_s``. When the
learner compensates a disturbance ``f(n)``, the error it sees is ``e(n) = f(n) - x(n)``; an
error-clamp trial (the error held at zero whatever the learner does) is ``e(n) = 0``, so only the
retentions act. The model reproduces fast early learning with a slow tail, spontaneous recovery
(after a brief counter-adaptation, error-clamp trials let the fast process decay and the slow one's
older adaptation re-emerge) and savings, but only under a condition: re-learning is faster when
re-exposure finds the two processes apart (after a counter-adaptation that brought the net adaptation,
but not the slow state, back to zero). After a plain null washout long enough to bring the net
adaptation back to zero both processes have decayed together, and with the defaults re-learning is
barely faster (half the field compensated in 22 trials the first time, 21 after a 160-trial washout;
2 after a 4-trial counter-field: ``tests/test_lab.py`` checks both). With ``rate_fast = 0`` the fast
process never moves from zero and the model is a single-rate learner ``x(n+1) = A_s x(n) + B_s e(n)``.

Defaults: A_f = 0.59, A_s = 0.992, B_f = 0.21, B_s = 0.02 (retention per trial: the fast process keeps
59% of its state, half-life 1.3 trials; the slow one 99.2%, half-life 86 trials). Their source, and what
is and is not verified: these four values are what model code in circulation labels "Smith et al. 2006"
(next to Joiner & Smith 2008's A_f 0.85, A_s 0.998, B_f 0.11, B_s 0.021); a second set, A_f 0.92,
A_s 0.996, B_f 0.03, B_s 0.004, is also quoted under the same citation. The paper itself (PLoS Biol
4(6):e179) could not be read where this was written, so which of its figures or tables each set comes
from is NOT verified here; check it before quoting either as the paper's fit. What the tests do verify is
what these values do: the signatures above, with the numbers given.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import UserError


class LearnerParameterError(UserError, ValueError):
    """An impossible learner setting; the message names it and its value."""


Estimate = float | np.ndarray


@dataclass
class TwoRateLearner:
    """A two-rate learner (Smith, Ghazizadeh & Shadmehr 2006); its state may be a float or an array.

    An array state holds a vector of independent estimates (for example one per target direction,
    or one per student of a simulated class) updated by errors of the same shape or by a scalar.

    >>> learner = TwoRateLearner()
    >>> learner.update(1.0)
    >>> round(learner.fast, 2), round(learner.slow, 2), round(learner.estimate, 2)
    (0.21, 0.02, 0.23)
    """

    retention_fast: float = 0.59
    retention_slow: float = 0.992
    rate_fast: float = 0.21
    rate_slow: float = 0.02
    fast: Estimate = 0.0
    slow: Estimate = 0.0

    def __post_init__(self) -> None:
        for name in ("retention_fast", "retention_slow", "rate_fast", "rate_slow"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 <= value <= 1.0:
                raise LearnerParameterError(f"learner {name.replace('_', ' ')} must be a number from 0 to 1, "
                                            f"got {value!r}")
        if self.rate_fast > 0.0:  # with rate_fast = 0 there is no fast process to order
            if not self.retention_fast < self.retention_slow:
                raise LearnerParameterError(
                    f"the fast process must forget faster: retention fast ({self.retention_fast:g}) must be "
                    f"below retention slow ({self.retention_slow:g})")
            if not self.rate_fast > self.rate_slow:
                raise LearnerParameterError(
                    f"the fast process must learn faster: rate fast ({self.rate_fast:g}) must be above "
                    f"rate slow ({self.rate_slow:g})")
        for name in ("fast", "slow"):
            state = getattr(self, name)
            if not np.all(np.isfinite(state)):
                raise LearnerParameterError(f"learner {name} state must be finite, got {state!r}")
            setattr(self, name, np.array(state, dtype=np.float64) if np.ndim(state) else float(state))

    @classmethod
    def single_rate(cls, retention: float = 0.992, rate: float = 0.02) -> TwoRateLearner:
        """One process ``x(n+1) = A x(n) + B e(n)``: the two-rate model with the fast process off."""
        return cls(retention_fast=0.0, retention_slow=retention, rate_fast=0.0, rate_slow=rate)

    @property
    def estimate(self) -> Estimate:
        """The net adaptation ``x = x_f + x_s``."""
        return self.fast + self.slow

    def update(self, error: Estimate) -> None:
        """Learn from one trial's error ``e(n)`` (0 on an error-clamp trial); both processes step once.

        A non-finite error is refused (``ValueError``) rather than left to poison every later trial.
        """
        if not np.all(np.isfinite(error)):
            raise ValueError(f"learner error must be finite, got {error!r}")
        self.fast = self.retention_fast * self.fast + self.rate_fast * error
        self.slow = self.retention_slow * self.slow + self.rate_slow * error


def simulate(learner: TwoRateLearner, disturbance: Sequence[float] | np.ndarray,
             clamped: Sequence[bool] | np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Run ``learner`` through a schedule of trials and return its states *before* each trial.

    On trial n the learner compensates ``x(n)`` of ``disturbance[n]`` and sees the error
    ``f(n) - x(n)``, or zero where ``clamped[n]`` (an error-clamp trial). Returns arrays of the
    trials' ``error``, ``estimate``, ``fast`` and ``slow``; the learner is left after the last trial.
    Scalar learners only.
    """
    f = np.asarray(disturbance, dtype=np.float64)
    clamp = np.zeros(f.shape, dtype=bool) if clamped is None else np.asarray(clamped, dtype=bool)
    if f.ndim != 1 or clamp.shape != f.shape:
        raise ValueError("disturbance and clamped must be one-dimensional and of the same length")
    if not np.isfinite(f).all():
        raise ValueError("disturbance must be finite")
    if np.ndim(learner.fast) or np.ndim(learner.slow):
        raise ValueError("simulate runs a scalar learner")
    out = {name: np.empty(f.size) for name in ("error", "estimate", "fast", "slow")}
    for n, value in enumerate(f):
        out["fast"][n], out["slow"][n] = learner.fast, learner.slow
        out["estimate"][n] = learner.estimate
        out["error"][n] = error = 0.0 if clamp[n] else value - learner.estimate
        learner.update(error)
    return out


#: The local learner's tuning (docs/lab.md, "Generalization"): Gaussian bases over movement direction, this wide
#: (s.d., degrees), centred every 360 / ``TUNING_CENTRES`` degrees. A choice, not a fit: with bases of s.d. 30 deg,
#: what is learned in one direction carries over to 0.57 of it at 45 deg and 0.105 at 90 deg (``generalization``), the
#: local fall-off force-field studies report (Thoroughman & Shadmehr 2000; Donchin et al. 2003), without the
#: partial bimodal generalization to the opposite direction some of them found. The generalization is wider than
#: a basis: a Gaussian of s.d. 30 x sqrt 2 = 42.4 deg, the overlap of two tunings.
TUNING_WIDTH_DEG = 30.0
TUNING_CENTRES = 16
MIN_TUNING_WIDTH_DEG = 5.0
MAX_TUNING_WIDTH_DEG = 180.0


class DirectionalLearner:
    """A two-rate learner of a quantity that depends on movement direction (a state-dependent representation).

    The estimate for a movement in direction ``theta`` is ``x(theta) = sum_i w_i phi_i(theta)``, with ``phi``
    the normalised Gaussian tuning of ``centres`` bases over direction (s.d. ``width_deg``; normalised so that
    equal weights give the same estimate in every direction) and the weights ``w = w_f + w_s`` the state of a
    two-rate learner. A trial in direction ``theta`` with error ``e`` updates the weights by
    ``e phi(theta) / |phi(theta)|^2``: in that direction the estimate follows the two-rate equations exactly,
    and elsewhere by ``generalization(delta)``, the overlap of the two directions' tunings. An error-clamp
    trial (``e = 0``) lets the retentions act on every weight.
    """

    def __init__(self, learner: TwoRateLearner, width_deg: float = TUNING_WIDTH_DEG,
                 centres: int = TUNING_CENTRES) -> None:
        if isinstance(width_deg, bool) or not isinstance(width_deg, (int, float)) \
                or not MIN_TUNING_WIDTH_DEG <= width_deg <= MAX_TUNING_WIDTH_DEG:
            raise LearnerParameterError(f"tuning width must be a number of degrees from {MIN_TUNING_WIDTH_DEG:g} to "
                                        f"{MAX_TUNING_WIDTH_DEG:g}, got {width_deg!r}")
        self.width_deg = float(width_deg)
        self.centres = np.arange(centres) * (360.0 / centres)
        self.learner = TwoRateLearner(learner.retention_fast, learner.retention_slow, learner.rate_fast,
                                      learner.rate_slow, fast=np.zeros(centres), slow=np.zeros(centres))

    def tuning(self, direction_deg: float) -> np.ndarray:
        """``phi(theta)``: the bases' normalised activations for a movement in that direction."""
        d = (direction_deg - self.centres + 180.0) % 360.0 - 180.0
        g = np.exp(-0.5 * (d / self.width_deg) ** 2)
        return g / g.sum()

    def at(self, direction_deg: float) -> float:
        """The estimate for a movement in that direction (degrees counter-clockwise from +x)."""
        return float(self.tuning(direction_deg) @ self.learner.estimate)

    def update(self, error: float, direction_deg: float) -> None:
        """Learn from a trial in that direction (``error`` 0 on an error-clamp trial)."""
        phi = self.tuning(direction_deg)
        self.learner.update(error * phi / float(phi @ phi))

    def generalization(self, delta_deg: float, direction_deg: float = 0.0) -> float:
        """What one trial's learning in ``direction_deg`` changes ``delta_deg`` away, as a fraction of its change
        there: ``phi(theta + delta) . phi(theta) / |phi(theta)|^2``."""
        phi = self.tuning(direction_deg)
        return float(self.tuning(direction_deg + delta_deg) @ phi / (phi @ phi))
