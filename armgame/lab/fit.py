"""Fitting a learner (``armgame.lab.learner``) to one run's trials: a student's rates, with intervals, and
which of two models the data support.

The models are the learner's. On trial n the learner has compensated ``x(n)`` of the disturbance ``f(n)``
(in units of the run's field: +1 the field, -1 the opposite field, 0 none or a catch trial) and learns from
``e(n) = f(n) - x(n)``, or from nothing on an error-clamp trial:

* ``two-rate`` (Smith, Ghazizadeh & Shadmehr 2006): ``x = x_f + x_s``, ``x_f(n+1) = A_f x_f(n) + B_f e(n)``,
  ``x_s(n+1) = A_s x_s(n) + B_s e(n)``, with ``0 < A_f < A_s < 1`` and ``0 < B_s < B_f < 1`` (kept by
  fitting ``A_f = a``, ``A_s = a + (1 - a) u``, ``B_f = b``, ``B_s = b v`` with ``a, u, b, v`` in (0, 1));
* ``one-rate``: ``x(n+1) = A x(n) + B e(n)``, ``0 < A, B < 1``. It is the two-rate model's edge
  ``A_f = A_s``, ``B_f + B_s = B``: the two are nested.

What is observed is either

* ``error``: a per-trial error measure (the perpendicular error for force fields, the initial direction
  error for displays), modelled as ``y(n) = k (f(n) - x(n))`` with a gain ``k`` (metres or degrees per unit
  of uncompensated field; its sign is the field's direction), on the trials that are not channels; or
* ``index``: the adaptation index of the channel trials, modelled as ``y(n) = x(n)``.

**The noise model and the fit.** ``y(n)`` is the model's value plus independent Gaussian noise of one
standard deviation ``sigma``; the parameters are fitted by maximum likelihood. For this model that is least
squares (``scipy.optimize.least_squares`` from a fixed set of starting points, each with a bounded number of
evaluations; the gain, which enters linearly, is solved exactly at every evaluation), with ``sigma^2`` the
mean squared residual and the log-likelihood ``-n/2 (ln(2 pi sigma^2) + 1)``. ``sigma`` counts as a
parameter: the two-rate model fitted to errors has 6 (four rates, ``k``, ``sigma``), the one-rate 4.
AIC = 2 p - 2 ln L and BIC = p ln n - 2 ln L compare models: the lower is the better supported.

**The intervals** are 95% profile-likelihood intervals: the values ``c`` of a parameter at which the best
fit with that parameter held at ``c`` (the others refitted) is still within ``chi2(1, 0.95) / 2 = 1.92`` of
the maximum log-likelihood. Unlike the Jacobian's symmetric interval they follow the likelihood's own shape
(lopsided near an edge of (0, 1)) and need no linearisation; they are still large-sample intervals, and an
interval that spans most of (0, 1) says the data cannot place that parameter. Their coverage is measured by
``benchmarks/fit_coverage.py``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..words import plural

MODELS = ("one-rate", "two-rate")
PARAMETER_NAMES = ("retention_fast", "retention_slow", "rate_fast", "rate_slow")
ONE_RATE_NAMES = ("retention", "rate")
SYMBOLS = {"retention_fast": "A_f", "retention_slow": "A_s", "rate_fast": "B_f", "rate_slow": "B_s", "gain": "k",
           "retention": "A", "rate": "B"}
OBSERVED = ("error", "index")
#: chi-squared with 1 degree of freedom, its 95th percentile: the profile's drop in 2 ln L at an interval's ends.
CHI2_1_95 = 3.841458820694124
INTERVALS = "profile likelihood"
#: Starting points in the unit box: (a, u, b, v) for two-rate, fast forgetting and learning from modest to
#: strong, slow learning a tenth; (A, B) for one-rate.
_STARTS = {"two-rate": ((0.6, 0.9, 0.2, 0.1), (0.85, 0.9, 0.1, 0.2), (0.4, 0.95, 0.4, 0.05), (0.9, 0.5, 0.05, 0.3)),
           "one-rate": ((0.9, 0.1), (0.99, 0.03), (0.6, 0.4))}
_EDGE = 1e-6
MAX_EVALUATIONS = 400
#: The profile's search: evaluations of each refit, and how closely an interval's end is placed.
PROFILE_EVALUATIONS = 200
PROFILE_TOLERANCE = 1e-4


@dataclass(frozen=True)
class LearnerFit:
    """A fit: the model, its parameters with 95% profile-likelihood intervals, the noise and the likelihood,
    the residual, and the data and curve."""

    observed_kind: str
    values: dict[str, float]
    intervals: dict[str, tuple[float, float]]
    #: Root mean square of the residuals (the data's unit; the noise's fitted s.d.), and the fraction of the
    #: data's variance explained.
    rms: float
    r_squared: float
    n: int
    observed: np.ndarray
    predicted: np.ndarray
    estimate: np.ndarray
    model: str = "two-rate"
    log_likelihood: float = math.nan
    #: Parameters counted by AIC and BIC: the rates, the gain if any, and the noise's s.d.
    n_parameters: int = 0
    interval_method: str = INTERVALS
    names: tuple[str, ...] = field(default=PARAMETER_NAMES)

    @property
    def aic(self) -> float:
        return 2.0 * self.n_parameters - 2.0 * self.log_likelihood

    @property
    def bic(self) -> float:
        return self.n_parameters * math.log(self.n) - 2.0 * self.log_likelihood

    def lines(self, unit: str = "", scale: float = 1.0) -> list[str]:
        """The fit as printed: one line per parameter, then the residual and the likelihood; the gain and the
        residual in ``unit``, ``scale`` times the data's own (a student reads cm, the data is in m)."""
        out = []
        for name in self.names:
            low, high = self.intervals[name]
            out.append(f"  {SYMBOLS[name]} = {self.values[name]:.4g}  (95% CI {low:.4g} to {high:.4g})")
        per = f" {unit}" if unit else ""
        if "gain" in self.values:
            low, high = (scale * v for v in self.intervals["gain"])
            out.append(f"  k = {scale * self.values['gain']:.4g}{per} per unit of field  (95% CI {low:.4g} to "
                       f"{high:.4g})")
        out.append(f"  residual: rms {scale * self.rms:.4g}{per} over {self.n} trials, R^2 = {self.r_squared:.3f}")
        out.append(f"  log-likelihood {self.log_likelihood:.2f} (Gaussian noise, s.d. = the rms), "
                   f"{self.n_parameters} parameters: AIC {self.aic:.2f}, BIC {self.bic:.2f}")
        return out

    def as_dict(self, unit: str) -> dict[str, object]:
        """The fit as a file keeps it: the model, each parameter's value and 95% interval, the residual and R^2,
        the log-likelihood, AIC and BIC, in the data's own ``unit`` (SI: m, deg, or "" for the index)."""
        names = (*self.names, *(("gain",) if "gain" in self.values else ()))
        return {
            "model": self.model,
            "fitted_to": self.observed_kind,
            "trials": self.n,
            "parameters": {SYMBOLS[name]: {"value": _number(self.values[name]),
                                           "ci95_low": _number(self.intervals[name][0]),
                                           "ci95_high": _number(self.intervals[name][1])} for name in names},
            "intervals": self.interval_method,
            **({"gain_unit": f"{unit} per unit of field"} if "gain" in self.values else {}),
            "residual_rms": _number(self.rms),
            "residual_unit": unit,
            "r_squared": _number(self.r_squared),
            "noise_model": "gaussian, constant s.d. (the rms)",
            "log_likelihood": _number(self.log_likelihood),
            "n_parameters": self.n_parameters,
            "aic": _number(self.aic),
            "bic": _number(self.bic),
        }


#: The name the two-rate fit had before the one-rate model joined it.
TwoRateFit = LearnerFit


def _number(v: float) -> float | None:  # JSON has no NaN: an undefined value is null
    return float(v) if math.isfinite(v) else None


def run_model(retention_fast: float, retention_slow: float, rate_fast: float, rate_slow: float,
              disturbance: np.ndarray, clamped: np.ndarray) -> np.ndarray:
    """``x(n)`` before each trial, from zero (the learner's equations, as ``learner.simulate`` runs them)."""
    return np.array(_run(retention_fast, retention_slow, rate_fast, rate_slow, disturbance.tolist(),
                         clamped.tolist()))


def _run(af: float, as_: float, bf: float, bs: float, f: list[float], clamp: list[bool]) -> list[float]:
    # Plain floats: a fit's profiles run this tens of thousands of times.
    fast = slow = 0.0
    x = []
    append = x.append
    for fn, c in zip(f, clamp, strict=True):
        xn = fast + slow
        append(xn)
        e = 0.0 if c else fn - xn
        fast = af * fast + bf * e
        slow = as_ * slow + bs * e
    return x


# ------------------------------------------------------------------ the models' coordinates
# Each model maps a point of the unit box to its natural parameters, and for a profile, holding natural
# parameter j at c, maps the box's remaining coordinates to all of them (and back, for a warm start).

def _two_rate(z: Sequence[float]) -> tuple[float, float, float, float]:
    a, u, b, v = z
    return a, a + (1.0 - a) * u, b, b * v


def _two_rate_box(p: Sequence[float]) -> list[float]:
    af, as_, bf, bs = p
    return [af, (as_ - af) / (1.0 - af), bf, bs / bf]


def _two_rate_fixed(j: int, c: float, z: Sequence[float]) -> tuple[float, float, float, float]:
    if j == 0:
        return c, c + (1.0 - c) * z[0], z[1], z[1] * z[2]
    if j == 1:
        return c * z[0], c, z[1], z[1] * z[2]
    if j == 2:
        return z[0], z[0] + (1.0 - z[0]) * z[1], c, c * z[2]
    return z[0], z[0] + (1.0 - z[0]) * z[1], c + (1.0 - c) * z[2], c


def _two_rate_fixed_box(j: int, c: float, p: Sequence[float]) -> list[float]:
    af, as_, bf, bs = p
    if j == 0:
        return [(as_ - c) / (1.0 - c), bf, bs / bf]
    if j == 1:
        return [af / c, bf, bs / bf]
    if j == 2:
        return [af, (as_ - af) / (1.0 - af), bs / c]
    return [af, (as_ - af) / (1.0 - af), (bf - c) / (1.0 - c)]


def _one_rate_fixed(j: int, c: float, z: Sequence[float]) -> tuple[float, float]:
    return (c, z[0]) if j == 0 else (z[0], c)


@dataclass(frozen=True)
class _Model:
    names: tuple[str, ...]
    natural: Callable[[Sequence[float]], tuple[float, ...]]
    box: Callable[[Sequence[float]], list[float]]
    fixed: Callable[[int, float, Sequence[float]], tuple[float, ...]]
    fixed_box: Callable[[int, float, Sequence[float]], list[float]]

    def rates(self, p: Sequence[float]) -> tuple[float, float, float, float]:
        """The two-rate equations' four numbers (one-rate: the slow process alone)."""
        if len(p) == 2:
            return 0.0, p[0], 0.0, p[1]
        return p[0], p[1], p[2], p[3]


_MODELS = {
    "two-rate": _Model(PARAMETER_NAMES, _two_rate, _two_rate_box, _two_rate_fixed, _two_rate_fixed_box),
    "one-rate": _Model(ONE_RATE_NAMES, lambda z: (z[0], z[1]), lambda p: [p[0], p[1]], _one_rate_fixed,
                       lambda j, c, p: [p[1 - j]]),
}


def fit_two_rate(disturbance: Sequence[float] | np.ndarray, clamped: Sequence[bool] | np.ndarray,
                 observed: Sequence[float] | np.ndarray, observed_kind: str = "error") -> LearnerFit:
    """``fit_learner`` of the two-rate model."""
    return fit_learner("two-rate", disturbance, clamped, observed, observed_kind)


def fit_learner(model: str, disturbance: Sequence[float] | np.ndarray, clamped: Sequence[bool] | np.ndarray,
                observed: Sequence[float] | np.ndarray, observed_kind: str = "error",
                start: Sequence[float] | None = None) -> LearnerFit:
    """Fit ``model`` (``one-rate`` or ``two-rate``) to ``observed`` (NaN where a trial has no value) given each
    trial's ``disturbance`` and whether it was ``clamped``, by maximum likelihood; see the module docstring.
    ``start``: one more starting point, in the model's natural parameters. Raises ValueError when the data
    cannot support a fit (fewer than 8 observed trials, or no disturbance at all)."""
    from scipy.optimize import least_squares

    if model not in _MODELS:
        raise ValueError(f"model must be one of {', '.join(MODELS)}, got {model!r}")
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
        raise ValueError(f"{plural(int(seen.sum()), 'trial')} with a value: a {model} fit needs at least 8")
    if not np.any(f[~clamp] != 0.0):
        raise ValueError("no trial had a disturbance to learn from: nothing to fit")
    spec = _MODELS[model]
    with_gain = observed_kind == "error"
    f_list, clamp_list = f.tolist(), clamp.tolist()
    ys = y[seen]

    def curve(p: Sequence[float], gain: float | None = None) -> tuple[np.ndarray, np.ndarray, float]:
        """(prediction on the seen trials, x on every trial, the gain): the gain, when not given, is the
        least-squares one for these rates (it enters linearly)."""
        x = np.array(_run(*spec.rates(p), f_list, clamp_list))
        if not with_gain:
            return x[seen], x, math.nan
        g = (f - x)[seen]
        if gain is None:
            gg = float(g @ g)
            gain = float(g @ ys) / gg if gg > 0.0 else 0.0
        return gain * g, x, gain

    def fit_box(to_natural: Callable[[np.ndarray], Sequence[float]], starts: Sequence[Sequence[float]],
                gain: float | None, evaluations: int):
        def residuals(z: np.ndarray) -> np.ndarray:
            return curve(to_natural(z), gain)[0] - ys
        best = None
        for z0 in starts:
            z0 = np.clip(np.asarray(z0, dtype=np.float64), _EDGE, 1.0 - _EDGE)
            result = least_squares(residuals, z0, bounds=(_EDGE, 1.0 - _EDGE), max_nfev=evaluations,
                                   x_scale="jac")
            if best is None or result.cost < best.cost:
                best = result
        return best

    starts = [list(z) for z in _STARTS[model]]
    if start is not None:
        starts.append(spec.box(start))
    best = fit_box(spec.natural, starts, None, MAX_EVALUATIONS)
    assert best is not None
    p = spec.natural(best.x)
    predicted_seen, x, gain = curve(p)
    rss = float(np.sum((predicted_seen - ys) ** 2))
    n = int(seen.sum())
    values = dict(zip(spec.names, (float(v) for v in p), strict=True))
    if with_gain:
        values["gain"] = gain
    log_l = _log_likelihood(rss, n)
    intervals = _profiles(spec, p, gain, rss, n, fit_box, curve, ys, with_gain)
    predicted = gain * (f - x) if with_gain else x.copy()
    total = float(np.sum((ys - ys.mean()) ** 2))
    return LearnerFit(observed_kind, values, intervals, math.sqrt(rss / n),
                      1.0 - rss / total if total > 0 else math.nan, n, np.where(seen, y, np.nan), predicted, x,
                      model, log_l, len(spec.names) + int(with_gain) + 1, INTERVALS, spec.names)


def _log_likelihood(rss: float, n: int) -> float:
    """The Gaussian log-likelihood at the maximum-likelihood noise s.d. (``sigma^2 = rss / n``)."""
    if rss <= 0.0:
        return math.inf
    return -0.5 * n * (math.log(2.0 * math.pi * rss / n) + 1.0)


def _profiles(spec: _Model, p: Sequence[float], gain: float, rss: float, n: int, fit_box, curve, ys: np.ndarray,
              with_gain: bool) -> dict[str, tuple[float, float]]:
    """Each parameter's 95% profile-likelihood interval: where the refitted residual sum of squares reaches
    ``rss * exp(chi2(1, 0.95) / n)`` (the drop in 2 ln L, with sigma profiled out, is ``n ln(rss_c / rss)``)."""
    limit = rss * math.exp(CHI2_1_95 / n) if rss > 0.0 else 0.0
    intervals: dict[str, tuple[float, float]] = {}
    for j, name in enumerate(spec.names):
        def refit(c: float, warm: Sequence[float], j: int = j) -> tuple[float, list[float]]:
            """(the refitted rss less the limit, the refit's parameters) with parameter j held at c."""
            best = fit_box(lambda z: spec.fixed(j, c, z), [spec.fixed_box(j, c, warm)], None, PROFILE_EVALUATIONS)
            return 2.0 * best.cost - limit, list(spec.fixed(j, c, best.x))

        low = _walk(refit, p[j], _EDGE, list(p), 0.0)
        high = _walk(refit, p[j], 1.0 - _EDGE, list(p), 1.0)
        assert low is not None and high is not None
        intervals[name] = (low, high)
    if with_gain:
        def refit_gain(k: float, warm: Sequence[float]) -> tuple[float, list[float]]:
            best = fit_box(spec.natural, [spec.box(warm)], k, PROFILE_EVALUATIONS)
            return 2.0 * best.cost - limit, list(spec.natural(best.x))

        ends = []
        for sign in (-1.0, 1.0):
            # The gain is unbounded: the search steps out, doubling, until the likelihood has dropped enough.
            inner, warm, step, end = gain, list(p), 0.5 * abs(gain) or 1e-3, sign * math.inf
            for _ in range(30):
                outer = inner + sign * step
                excess, solution = refit_gain(outer, warm)
                if excess > 0.0:
                    end = _walk(refit_gain, inner, outer, warm, None, steps=(1.0,))
                    break
                inner, warm, step = outer, solution, 2.0 * step
            ends.append(end)
        intervals["gain"] = (float(min(ends)), float(max(ends)))
    return intervals


#: Where the profile is refitted on the way out from the estimate to an edge, as fractions of the way: each
#: refit starts from the last, so the profile follows one valley instead of jumping between minima.
_WALK = (0.05, 0.2, 0.5, 1.0)


def _walk(refit, centre: float, edge: float, warm: list[float], unbounded: float | None,
          steps: Sequence[float] = _WALK) -> float | None:
    """The value between ``centre`` (inside the interval) and ``edge`` where ``refit``'s excess crosses 0, by
    steps out and then Brent's method (each refit warm-started from the nearest point inside); ``unbounded``
    (the edge's own value) if the excess never crosses, or None with ``unbounded`` None."""
    inner = centre
    for t in steps:
        c = centre + (edge - centre) * t
        excess, solution = refit(c, warm)
        if excess > 0.0:
            outer = c
            break
        inner, warm = c, solution
    else:
        return unbounded
    from scipy.optimize import brentq

    nearest = [warm]

    def excess_from_inside(c: float) -> float:
        # Brent's method asks for points on both sides: each refit starts from the last one inside.
        excess, solution = refit(c, nearest[0])
        if excess <= 0.0:
            nearest[0] = solution
        return excess

    low, high = sorted((inner, outer))
    return float(brentq(excess_from_inside, low, high, xtol=PROFILE_TOLERANCE * max(1.0, abs(centre))))


@dataclass(frozen=True)
class Comparison:
    """Two nested fits to the same data: AIC and BIC (lower is better supported) and the likelihood ratio."""

    simple: LearnerFit
    full: LearnerFit

    @property
    def delta_aic(self) -> float:
        """AIC(simple) - AIC(full): positive favours the full model."""
        return self.simple.aic - self.full.aic

    @property
    def delta_bic(self) -> float:
        return self.simple.bic - self.full.bic

    @property
    def likelihood_ratio(self) -> float:
        """2 (ln L_full - ln L_simple), at least 0 (the simple model is the full one's edge)."""
        return max(0.0, 2.0 * (self.full.log_likelihood - self.simple.log_likelihood))

    @property
    def p_value(self) -> float:
        """Against chi-squared with the difference in parameters (2): approximate, since the one-rate model
        lies on the edge of the two-rate model's space, where the test is conservative."""
        from scipy.stats import chi2

        return float(chi2.sf(self.likelihood_ratio, self.full.n_parameters - self.simple.n_parameters))

    def preferred(self, by: str) -> str:
        delta = self.delta_aic if by == "aic" else self.delta_bic
        return self.full.model if delta > 0.0 else self.simple.model

    def lines(self) -> list[str]:
        return [f"  {self.simple.model} vs {self.full.model}: AIC {self.simple.aic:.2f} vs {self.full.aic:.2f} "
                f"(prefers {self.preferred('aic')} by {abs(self.delta_aic):.2f}), BIC {self.simple.bic:.2f} vs "
                f"{self.full.bic:.2f} (prefers {self.preferred('bic')} by {abs(self.delta_bic):.2f}); likelihood "
                f"ratio {self.likelihood_ratio:.2f}, p = {self.p_value:.3g} (chi2, 2 d.f., approximate)"]

    def as_dict(self) -> dict[str, object]:
        return {"models": [self.simple.model, self.full.model],
                "aic": {self.simple.model: _number(self.simple.aic), self.full.model: _number(self.full.aic)},
                "bic": {self.simple.model: _number(self.simple.bic), self.full.model: _number(self.full.bic)},
                "preferred_by_aic": self.preferred("aic"), "preferred_by_bic": self.preferred("bic"),
                "likelihood_ratio": _number(self.likelihood_ratio), "p_value": _number(self.p_value)}


def compare(disturbance: Sequence[float] | np.ndarray, clamped: Sequence[bool] | np.ndarray,
            observed: Sequence[float] | np.ndarray, observed_kind: str = "error") -> Comparison:
    """Both models fitted to the same data. The two-rate fit also starts from the one-rate optimum (its edge),
    so its likelihood is never below the one-rate model's for want of a starting point."""
    one = fit_learner("one-rate", disturbance, clamped, observed, observed_kind)
    a, b = one.values["retention"], one.values["rate"]
    near = (a * (1.0 - 1e-3), a, 0.5 * b * (1.0 + 1e-3), 0.5 * b * (1.0 - 1e-3))
    return Comparison(one, fit_learner("two-rate", disturbance, clamped, observed, observed_kind, start=near))
