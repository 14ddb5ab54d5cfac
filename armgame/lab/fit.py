"""Fitting the two-rate model (``armgame.lab.learner``) to one run's trials: a student's rates, with intervals.

The model is the learner's: on trial n the learner has compensated ``x(n) = x_f(n) + x_s(n)`` of the
disturbance ``f(n)`` (in units of the run's field: +1 the field, -1 the opposite field, 0 none or a
catch trial) and learns from ``e(n) = f(n) - x(n)``, or from nothing on an error-clamp trial. What is
observed is either

* ``error``: a per-trial error measure (the perpendicular error for force fields, the initial direction
  error for displays), modelled as ``y(n) = k (f(n) - x(n))`` with a fitted gain ``k`` (metres or degrees
  per unit of uncompensated field; its sign is the field's direction), on the trials that are not
  channels; or
* ``index``: the adaptation index of the channel trials, modelled as ``y(n) = x(n)``.

``fit_two_rate`` finds ``A_f, A_s, B_f, B_s`` (and ``k``) by nonlinear least squares
(``scipy.optimize.least_squares``) under the model's constraints, ``0 < A_f < A_s < 1`` and
``0 < B_s < B_f < 1``, kept by fitting ``A_f = a``, ``A_s = a + (1 - a) u``, ``B_f = b``, ``B_s = b v``
with ``a, b, u, v`` bounded in (0, 1). The 95% confidence intervals come from the Jacobian at the
optimum (``cov = s^2 (J^T J)^-1`` with ``s^2`` the residual variance, mapped to the model's
parameters by the delta method, +-1.96 standard errors, cut at 0 and 1): a local, large-sample
approximation, wide where the data cannot tell a parameter apart, which is itself worth reading. The work is
bounded: a fixed set of starting points, each with a bounded number of evaluations.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..words import plural

PARAMETER_NAMES = ("retention_fast", "retention_slow", "rate_fast", "rate_slow")
SYMBOLS = {"retention_fast": "A_f", "retention_slow": "A_s", "rate_fast": "B_f", "rate_slow": "B_s", "gain": "k"}
OBSERVED = ("error", "index")
#: Starting points (a, u, b, v): fast forgetting and learning from modest to strong, slow learning a tenth.
_STARTS = ((0.6, 0.9, 0.2, 0.1), (0.85, 0.9, 0.1, 0.2), (0.4, 0.95, 0.4, 0.05), (0.9, 0.5, 0.05, 0.3))
_EDGE = 1e-6
MAX_EVALUATIONS = 400


@dataclass(frozen=True)
class TwoRateFit:
    """A fit: the parameters, their 95% confidence intervals, the residual, and the data and curve."""

    observed_kind: str
    values: dict[str, float]
    intervals: dict[str, tuple[float, float]]
    #: Root mean square of the residuals (the data's unit), and the fraction of the data's variance explained.
    rms: float
    r_squared: float
    n: int
    observed: np.ndarray
    predicted: np.ndarray
    estimate: np.ndarray

    def lines(self, unit: str = "", scale: float = 1.0) -> list[str]:
        """The fit as printed: one line per parameter, then the residual; the gain and the residual in
        ``unit``, ``scale`` times the data's own (a student reads cm, the data is in m)."""
        out = []
        for name in PARAMETER_NAMES:
            low, high = self.intervals[name]
            out.append(f"  {SYMBOLS[name]} = {self.values[name]:.4g}  (95% CI {low:.4g} to {high:.4g})")
        per = f" {unit}" if unit else ""
        if "gain" in self.values:
            low, high = (scale * v for v in self.intervals["gain"])
            out.append(f"  k = {scale * self.values['gain']:.4g}{per} per unit of field  (95% CI {low:.4g} to "
                       f"{high:.4g})")
        out.append(f"  residual: rms {scale * self.rms:.4g}{per} over {self.n} trials, R^2 = {self.r_squared:.3f}")
        return out

    def as_dict(self, unit: str) -> dict[str, object]:
        """The fit as a file keeps it: each parameter's value and 95% interval, the residual and R^2, in the
        data's own ``unit`` (SI: m, deg, or "" for the adaptation index)."""
        names = (*PARAMETER_NAMES, *(("gain",) if "gain" in self.values else ()))

        def number(v: float) -> float | None:  # JSON has no NaN: an undefined value is null
            return float(v) if math.isfinite(v) else None

        return {
            "fitted_to": self.observed_kind,
            "trials": self.n,
            "parameters": {SYMBOLS[name]: {"value": number(self.values[name]),
                                           "ci95_low": number(self.intervals[name][0]),
                                           "ci95_high": number(self.intervals[name][1])} for name in names},
            **({"gain_unit": f"{unit} per unit of field"} if "gain" in self.values else {}),
            "residual_rms": number(self.rms),
            "residual_unit": unit,
            "r_squared": number(self.r_squared),
        }


def _parameters(theta: np.ndarray) -> tuple[float, float, float, float]:
    a, u, b, v = theta[:4]
    return a, a + (1.0 - a) * u, b, b * v


def run_model(retention_fast: float, retention_slow: float, rate_fast: float, rate_slow: float,
              disturbance: np.ndarray, clamped: np.ndarray) -> np.ndarray:
    """``x(n)`` before each trial, from zero (the learner's equations, as ``learner.simulate`` runs them)."""
    fast = slow = 0.0
    x = np.empty(disturbance.size)
    for n in range(disturbance.size):
        x[n] = fast + slow
        e = 0.0 if clamped[n] else disturbance[n] - x[n]
        fast = retention_fast * fast + rate_fast * e
        slow = retention_slow * slow + rate_slow * e
    return x


def fit_two_rate(disturbance: Sequence[float] | np.ndarray, clamped: Sequence[bool] | np.ndarray,
                 observed: Sequence[float] | np.ndarray, observed_kind: str = "error") -> TwoRateFit:
    """Fit the two-rate model to ``observed`` (NaN where a trial has no value) given each trial's
    ``disturbance`` and whether it was ``clamped``; see the module docstring. Raises ValueError when the
    data cannot support a fit (fewer than 8 observed trials, or no disturbance at all)."""
    from scipy.optimize import least_squares

    if observed_kind not in OBSERVED:
        raise ValueError(f"observed_kind must be one of {', '.join(OBSERVED)}, got {observed_kind!r}")
    f = np.asarray(disturbance, dtype=np.float64)
    clamp = np.asarray(clamped, dtype=bool)
    y = np.asarray(observed, dtype=np.float64)
    if not (f.ndim == 1 and clamp.shape == f.shape and y.shape == f.shape):
        raise ValueError("disturbance, clamped and observed must be one-dimensional and of the same length")
    if not np.isfinite(f).all():
        raise ValueError("the disturbance must be finite")
    seen = np.isfinite(y)
    if observed_kind == "error":
        seen &= ~clamp
    if seen.sum() < 8:
        raise ValueError(f"{plural(int(seen.sum()), 'trial')} with a value: a two-rate fit needs at least 8")
    if not np.any(f[~clamp] != 0.0):
        raise ValueError("no trial had a disturbance to learn from: nothing to fit")
    with_gain = observed_kind == "error"

    def predict(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x = run_model(*_parameters(theta), f, clamp)
        return (theta[4] * (f - x) if with_gain else x), x

    def residuals(theta: np.ndarray) -> np.ndarray:
        return (predict(theta)[0] - y)[seen]

    scale = float(np.max(np.abs(y[seen]))) or 1.0
    low = [_EDGE] * 4 + ([-np.inf] if with_gain else [])
    high = [1.0 - _EDGE] * 4 + ([np.inf] if with_gain else [])
    best = None
    for start in _STARTS:
        theta0 = np.array(start + ((_gain_start(f, y, seen, scale),) if with_gain else ()))
        result = least_squares(residuals, theta0, bounds=(low, high), max_nfev=MAX_EVALUATIONS, x_scale="jac")
        if best is None or result.cost < best.cost:
            best = result
    assert best is not None
    theta = best.x
    r = best.fun
    n, p = r.size, theta.size
    dof = max(1, n - p)
    s2 = float(r @ r) / dof
    values = dict(zip(PARAMETER_NAMES, _parameters(theta), strict=True))
    if with_gain:
        values["gain"] = float(theta[4])
    intervals = _intervals(theta, best.jac, s2, with_gain)
    predicted, x = predict(theta)
    total = float(np.sum((y[seen] - y[seen].mean()) ** 2))
    return TwoRateFit(observed_kind, {k: float(v) for k, v in values.items()}, intervals,
                      math.sqrt(float(r @ r) / n), 1.0 - float(r @ r) / total if total > 0 else math.nan, n,
                      np.where(seen, y, np.nan), predicted, x)


def _gain_start(f: np.ndarray, y: np.ndarray, seen: np.ndarray, scale: float) -> float:
    """The gain that best explains the first disturbed trials' errors before any learning."""
    first = np.flatnonzero(seen & (f != 0.0))[:3]
    return float(np.mean(y[first] / f[first])) if first.size else scale


def _intervals(theta: np.ndarray, jac: np.ndarray, s2: float, with_gain: bool) -> dict[str, tuple[float, float]]:
    """95% intervals by the delta method from the fitted parameters' covariance ``s^2 (J^T J)^-1``."""
    a, u, b, v = theta[:4]
    # d(A_f, A_s, B_f, B_s, k) / d(a, u, b, v, k)
    g = np.zeros((theta.size, theta.size))
    g[0, 0] = 1.0
    g[1, 0], g[1, 1] = 1.0 - u, 1.0 - a
    g[2, 2] = 1.0
    g[3, 2], g[3, 3] = v, b
    if with_gain:
        g[4, 4] = 1.0
    try:
        cov = np.linalg.pinv(jac.T @ jac) * s2
        errors = np.sqrt(np.clip(np.diag(g @ cov @ g.T), 0.0, None))
    except np.linalg.LinAlgError:
        errors = np.full(theta.size, np.inf)
    values = [*_parameters(theta), *((theta[4],) if with_gain else ())]
    names = (*PARAMETER_NAMES, *(("gain",) if with_gain else ()))
    # The rates live in [0, 1]: a symmetric interval that reaches past an edge is cut there.
    return {name: (float(value - 1.96 * e), float(value + 1.96 * e)) if name == "gain"
            else (max(0.0, float(value - 1.96 * e)), min(1.0, float(value + 1.96 * e)))
            for name, value, e in zip(names, values, errors, strict=True)}
