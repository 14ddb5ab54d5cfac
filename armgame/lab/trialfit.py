"""Two more fits of a run's trials (issue 41): the generalization function from trial-to-trial changes, and a
state-space model with process noise.

**Trial by trial** (Thoroughman & Shadmehr 2000; Donchin, Francis & Shadmehr 2003). The error ``y(n)`` of a reach
in direction ``theta_n`` under the disturbance ``f(n)`` (in units of the run's field) is modelled as

    y(n) = k f(n) - z_n(theta_n) + v(n),      z_{n+1}(theta) = a z_n(theta) + c(theta - theta_n) y(n)

``z`` is what has been learned, in the error's unit, for each direction; ``c(delta)`` is the generalization function:
the fraction of the error made in one direction that the next reach ``delta`` away corrects. With the protocol's
``K`` evenly spaced targets it has one value per angle 0, 360/K, ..., 180 (symmetric, ``c(delta) = c(-delta)``), and
``c(180)`` is free: the opposite-direction lobe Donchin et al. found is allowed, not assumed. The learner is driven
by the errors observed (the model is linear in ``k`` and ``c`` for a given ``a``: each ``a`` of a fine grid is
fitted exactly by least squares, the best ``a`` is the maximum-likelihood one for Gaussian ``v``). Intervals: 95%
profile likelihood, exact on the grid (for ``a``, where ``n ln(rss(a) / rss)`` reaches 3.84; for a linear
coefficient, the union over ``a`` of its constrained least-squares interval at that ``a``). A basis-function
state-space model in the sense of Donchin et al.: with the targets as the bases, ``B`` the circulant matrix of
``c``. Channel trials and trials without a value teach nothing and are not fitted; the state decays over them.

**State space with process noise** (Cheng & Sabes 2006). One adaptive state in units of the field,

    x(n+1) = A x(n) + B e(n) + w(n),   e(n) = f(n) - x(n) (0 on a channel trial),   w ~ N(0, Q)
    y(n)   = k e(n) + v(n)  (errors)    or    y(n) = x(n) + v(n)  (channel indices),   v ~ N(0, R)

fitted by expectation-maximization: the E-step is a Kalman filter and Rauch-Tung-Striebel smoother, the M-step
solves for ``A, B`` (a 2 x 2 regression on the smoothed moments), ``k``, ``Q`` and ``R`` in closed form; ``x(0) =
0``; EM's answer is then taken to the exact likelihood's maximum by a quasi-Newton search (EM climbs slowly near
the top). The log-likelihood is the filter's (exact). Intervals: 95% Wald intervals from the observed information (a
numerical Hessian of that log-likelihood) on scales that keep each parameter in its range (logit for ``A`` and
``B``, log for ``Q`` and ``R``). Their coverage is measured by ``benchmarks/trial_fit_coverage.py``. A deterministic
fit (``armgame.lab.fit``) puts all the noise in ``v``; this one splits it.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

#: chi-squared with 1 degree of freedom, its 95th percentile (profile intervals), and the normal's 97.5th (Wald).
CHI2_1_95 = 3.841458820694124
Z_975 = 1.959963984540054
#: The trial-by-trial fit's grid of retentions ``a``: finer toward 1, where the data put most learners.
A_GRID = np.unique(np.concatenate([np.linspace(0.0, 0.9, 181), np.linspace(0.9, 0.999, 199)]))
#: EM's iterations at most (its climb slows near the top), then at most this many quasi-Newton ones.
EM_ITERATIONS = 100
EM_TOLERANCE = 1e-9
POLISH_ITERATIONS = 200


@dataclass(frozen=True)
class GeneralizationFit:
    """The trial-by-trial fit: ``a``, ``k`` and ``c`` by angle, each with its 95% profile-likelihood interval."""

    angles_deg: tuple[float, ...]
    values: dict[str, float]
    intervals: dict[str, tuple[float, float]]
    sigma: float
    n: int
    log_likelihood: float
    r_squared: float

    @property
    def n_parameters(self) -> int:
        return len(self.values) + 1

    def lines(self, unit: str = "", scale: float = 1.0) -> list[str]:
        out = []
        for name, value in self.values.items():
            low, high = self.intervals[name]
            s = scale if name == "k" else 1.0
            what = f" {unit} per unit of field" if name == "k" and unit else ""
            out.append(f"  {name} = {s * value:.4g}{what}  (95% CI {s * low:.4g} to {s * high:.4g})")
        c0 = self.values["c(0)"]
        if c0 > 0:
            out.append("  shape c(delta) / c(0): " + ", ".join(
                f"{a:g} deg {self.values[f'c({a:g})'] / c0:+.2f}" for a in self.angles_deg))
        per = f" {unit}" if unit else ""
        out.append(f"  residual: rms {scale * self.sigma:.4g}{per} over {self.n} trials, R^2 = {self.r_squared:.3f}; "
                   f"log-likelihood {self.log_likelihood:.2f}, {self.n_parameters} parameters")
        return out

    def as_dict(self, unit: str) -> dict[str, object]:
        return {"model": "trial-by-trial", "trials": self.n,
                "parameters": {name: {"value": _number(v), "ci95_low": _number(self.intervals[name][0]),
                                      "ci95_high": _number(self.intervals[name][1])}
                               for name, v in self.values.items()},
                "angles_deg": list(self.angles_deg), "intervals": "profile likelihood",
                "gain_unit": f"{unit} per unit of field", "residual_rms": _number(self.sigma),
                "residual_unit": unit, "r_squared": _number(self.r_squared),
                "log_likelihood": _number(self.log_likelihood), "n_parameters": self.n_parameters}


def interval_text(low: float, high: float, scale: float = 1.0) -> str:
    """A 95% interval as the reports print it: an end past any number is "unbounded" (a variance whose likelihood
    never falls off), and an interval the data cannot give (a flat likelihood, a fit at its range's edge) says so."""
    if math.isnan(low) or math.isnan(high):
        return "no 95% CI: the likelihood is flat there"
    ends = ["unbounded" if math.isinf(v) else f"{scale * v:.4g}" for v in (low, high)]
    return f"95% CI {ends[0]} to {ends[1]}"


def _number(v: float) -> float | None:
    return float(v) if math.isfinite(v) else None


def _bins(targets: int) -> tuple[float, ...]:
    return tuple(360.0 * j / targets for j in range(targets // 2 + 1))


def fit_generalization(target: Sequence[int], targets: int, disturbance: Sequence[float], observed: Sequence[float],
                       clamped: Sequence[bool] | None = None) -> GeneralizationFit:
    """Fit the trial-by-trial model (module docstring) to a run: each trial's ``target`` (index of ``targets`` evenly
    spaced directions), ``disturbance``, ``observed`` error (NaN: none) and whether it was ``clamped``. Raises
    ValueError when the data cannot support it (fewer trials with a value than three times the parameters)."""
    t = np.asarray(target, dtype=int)
    f = np.asarray(disturbance, dtype=float)
    y = np.asarray(observed, dtype=float)
    clamp = np.zeros(t.shape, dtype=bool) if clamped is None else np.asarray(clamped, dtype=bool)
    if not (t.ndim == 1 and f.shape == t.shape and y.shape == t.shape and clamp.shape == t.shape):
        raise ValueError("target, disturbance, observed and clamped must be one-dimensional and of the same length")
    if targets < 2 or np.any((t < 0) | (t >= targets)):
        raise ValueError(f"targets must index {targets} directions")
    seen = np.isfinite(y) & ~clamp & np.isfinite(f)
    angles = _bins(targets)
    p = len(angles) + 2
    if seen.sum() < 3 * p:
        raise ValueError(f"{int(seen.sum())} trials with a value: the trial-by-trial fit needs at least {3 * p}")
    if not np.any(f[seen] != 0.0):
        raise ValueError("no trial had a disturbance: nothing to fit")
    # bin[t_now, t_before]: which angle of the generalization function joins the two directions.
    d = (np.arange(targets)[:, None] - np.arange(targets)[None, :]) % targets
    which = np.minimum(d, targets - d)
    teach = np.where(seen, y, 0.0)
    a = A_GRID
    decayed = np.zeros((a.size, targets))  # D_t: the errors made in direction t, decayed to trial n
    rows = np.flatnonzero(seen)
    design = np.zeros((a.size, rows.size, len(angles)))
    r = 0
    for n in range(t.size):
        if seen[n]:
            for j in range(len(angles)):
                design[:, r, j] = -decayed[:, which[t[n]] == j].sum(axis=1)
            r += 1
        decayed *= a[:, None]
        decayed[:, t[n]] += teach[n]
    ys = y[rows]
    x = np.concatenate([np.broadcast_to(f[rows][None, :, None], (a.size, rows.size, 1)), design], axis=2)
    gram = np.einsum("gni,gnj->gij", x, x)
    inverse = np.linalg.pinv(gram)
    beta = np.einsum("gij,gnj,n->gi", inverse, x, ys)
    rss = np.sum((np.einsum("gni,gi->gn", x, beta) - ys) ** 2, axis=1)
    best = int(np.argmin(rss))
    n = rows.size
    limit = rss[best] * math.exp(CHI2_1_95 / n)
    names = ("k", *(f"c({g:g})" for g in angles))
    values = {"a": float(a[best]), **{name: float(v) for name, v in zip(names, beta[best], strict=True)}}
    intervals = {"a": _grid_interval(a, n * np.log(rss / rss[best]), best)}
    inside = rss <= limit
    for i, name in enumerate(names):
        # With the others refitted, rss(c) = rss(a) + (c - beta_i(a))^2 / [(X^T X)^-1]_ii at each a.
        width = np.sqrt(np.maximum(limit - rss[inside], 0.0) * inverse[inside, i, i])
        intervals[name] = (float(np.min(beta[inside, i] - width)), float(np.max(beta[inside, i] + width)))
    total = float(np.sum((ys - ys.mean()) ** 2))
    log_l = -0.5 * n * (math.log(2.0 * math.pi * rss[best] / n) + 1.0)
    return GeneralizationFit(angles, values, intervals, math.sqrt(rss[best] / n), n, log_l,
                             1.0 - rss[best] / total if total > 0 else math.nan)


def _grid_interval(grid: np.ndarray, drop: np.ndarray, best: int) -> tuple[float, float]:
    """Where ``drop`` (the profile's rise in -2 ln L) crosses 3.84 either side of ``best``, interpolated linearly;
    the grid's end where it never does."""
    ends = []
    for step in (-1, 1):
        i = best
        while 0 <= i + step < grid.size and drop[i + step] <= CHI2_1_95:
            i += step
        if 0 <= i + step < grid.size:
            lo, hi = drop[i], drop[i + step]
            ends.append(float(grid[i] + (grid[i + step] - grid[i]) * (CHI2_1_95 - lo) / (hi - lo)))
        else:
            ends.append(float(grid[i]))
    return min(ends), max(ends)


# ------------------------------------------------------------------------------------------ state space
@dataclass(frozen=True)
class StateSpaceFit:
    """The state-space fit with process noise: ``A``, ``B``, ``k`` (errors only), ``Q``, ``R``, with 95% Wald
    intervals on the scales the module docstring names."""

    observed_kind: str
    values: dict[str, float]
    intervals: dict[str, tuple[float, float]]
    n: int
    log_likelihood: float
    iterations: int
    estimate: np.ndarray

    @property
    def n_parameters(self) -> int:
        return len(self.values)

    def lines(self, unit: str = "", scale: float = 1.0) -> list[str]:
        out = []
        for name, value in self.values.items():
            low, high = self.intervals[name]
            s, what = 1.0, ""
            if name == "k":
                s, what = scale, f" {unit} per unit of field" if unit else ""
            elif name == "R":
                s, what = scale * scale, f" {unit}^2" if unit else ""
            elif name == "Q":
                what = " (field units)^2"
            out.append(f"  {name} = {s * value:.4g}{what}  ({interval_text(low, high, s)})")
        out.append(f"  noise s.d.: process {math.sqrt(self.values['Q']):.4g} of the field a trial, output "
                   f"{scale * math.sqrt(self.values['R']):.4g}{(' ' + unit) if unit else ''}; log-likelihood "
                   f"{self.log_likelihood:.2f} (Kalman filter), {self.n_parameters} parameters, EM "
                   f"{self.iterations} iterations")
        return out

    def as_dict(self, unit: str) -> dict[str, object]:
        return {"model": "state-space", "fitted_to": self.observed_kind, "trials": self.n,
                "parameters": {name: {"value": _number(v), "ci95_low": _number(self.intervals[name][0]),
                                      "ci95_high": _number(self.intervals[name][1])}
                               for name, v in self.values.items()},
                "intervals": "Wald, observed information (logit A and B, log Q and R)",
                **({"gain_unit": f"{unit} per unit of field"} if "k" in self.values else {}),
                "Q_unit": "(units of the field)^2", "R_unit": f"{unit}^2" if unit else "",
                "log_likelihood": _number(self.log_likelihood), "n_parameters": self.n_parameters,
                "method": "expectation-maximization (Kalman smoother E-step), Cheng & Sabes 2006"}


def _filter(a: float, b: float, k: float, q: float, r: float, f: np.ndarray, learn: np.ndarray, seen: np.ndarray,
            y: np.ndarray, kind: str, smooth: bool = False):
    """The Kalman filter's log-likelihood and, with ``smooth``, the smoothed means, variances and lag-one
    covariances of ``x`` (x(0) = 0 exactly)."""
    n = f.size
    mp = np.zeros(n + 1)  # predicted mean and variance of x(n) before y(n)
    vp = np.zeros(n + 1)
    mf = np.zeros(n)
    vf = np.zeros(n)
    log_l = 0.0
    m, v = 0.0, 0.0
    for i in range(n):
        mp[i], vp[i] = m, v
        if seen[i]:
            c, d = (-k, k * f[i]) if kind == "error" else (1.0, 0.0)
            s = c * c * v + r
            innovation = y[i] - (c * m + d)
            gain = v * c / s
            m, v = m + gain * innovation, (1.0 - gain * c) * v
            log_l -= 0.5 * (math.log(2.0 * math.pi * s) + innovation * innovation / s)
        mf[i], vf[i] = m, v
        alpha = a - b if learn[i] else a
        m, v = alpha * m + (b * f[i] if learn[i] else 0.0), alpha * alpha * v + q
    mp[n], vp[n] = m, v
    if not smooth:
        return log_l
    ms, vs = np.zeros(n + 1), np.zeros(n + 1)
    cross = np.zeros(n)  # Cov(x(i), x(i+1)) smoothed
    ms[n], vs[n] = mp[n], vp[n]
    for i in range(n - 1, -1, -1):
        alpha = a - b if learn[i] else a
        j = vf[i] * alpha / vp[i + 1] if vp[i + 1] > 0 else 0.0
        ms[i] = mf[i] + j * (ms[i + 1] - mp[i + 1])
        vs[i] = vf[i] + j * j * (vs[i + 1] - vp[i + 1])
        cross[i] = j * vs[i + 1]
    return log_l, ms, vs, cross


def _prepare(disturbance, clamped, observed, observed_kind: str):
    if observed_kind not in ("error", "index"):
        raise ValueError(f"observed_kind must be error or index, got {observed_kind!r}")
    f = np.asarray(disturbance, dtype=float)
    clamp = np.asarray(clamped, dtype=bool)
    y = np.asarray(observed, dtype=float)
    if not (f.ndim == 1 and clamp.shape == f.shape and y.shape == f.shape):
        raise ValueError("disturbance, clamped and observed must be one-dimensional and of the same length")
    seen = np.isfinite(y) & (~clamp if observed_kind == "error" else clamp)
    if seen.sum() < 20:
        raise ValueError(f"{int(seen.sum())} trials with a value: the state-space fit needs at least 20")
    if not np.any(f[~clamp] != 0.0):
        raise ValueError("no trial had a disturbance to learn from: nothing to fit")
    return f, ~clamp, seen, np.where(seen, y, 0.0)


def fit_state_space(disturbance: Sequence[float] | np.ndarray, clamped: Sequence[bool] | np.ndarray,
                    observed: Sequence[float] | np.ndarray, observed_kind: str = "error") -> StateSpaceFit:
    """Fit the state-space model with process noise (module docstring) by EM; raises ValueError when the data
    cannot support it (fewer than 20 trials with a value, or no disturbance)."""
    f, learn, seen, y = _prepare(disturbance, clamped, observed, observed_kind)
    errors = observed_kind == "error"
    ys = y[seen]
    # A start from the deterministic picture: a slow single rate, the gain from the first exposure's errors.
    a, b = 0.95, 0.1
    k = float(np.mean(ys[f[seen] != 0])) if errors and np.any(f[seen] != 0) else 1.0
    k = k if errors and k != 0.0 else 1.0
    r = max(float(np.var(ys)) * 0.5, 1e-12)
    q = 0.01
    previous = -math.inf
    iterations = 0
    for iterations in range(1, EM_ITERATIONS + 1):  # noqa: B007 (the count is reported)
        log_l, ms, vs, cross = _filter(a, b, k, q, r, f, learn, seen, y, observed_kind, smooth=True)
        ex, exx = ms[:-1], vs[:-1] + ms[:-1] ** 2
        ex1, ex1x1 = ms[1:], vs[1:] + ms[1:] ** 2
        exx1 = cross + ms[:-1] * ms[1:]
        lf = np.where(learn, f, 0.0)
        lm = learn.astype(float)
        # x' = A x + B L (f - x): regressors x and L (f - x).
        s11 = exx.sum()
        s12 = np.sum(lf * ex - lm * exx)
        s22 = np.sum(lf * lf - 2.0 * lf * ex + lm * exx)
        t1 = exx1.sum()
        t2 = np.sum(lf * ex1 - lm * exx1)
        a, b = np.linalg.solve(np.array([[s11, s12], [s12, s22]]), np.array([t1, t2]))
        a, b = float(np.clip(a, 1e-6, 1.0 - 1e-6)), float(np.clip(b, 1e-6, 1.0 - 1e-6))
        resid = (ex1x1 - 2.0 * (a * exx1 + b * (lf * ex1 - lm * exx1)) + a * a * exx
                 + 2.0 * a * b * (lf * ex - lm * exx) + b * b * (lf * lf - 2.0 * lf * ex + lm * exx))
        q = max(float(np.mean(resid)), 1e-12)
        fo, mo, vo = f[seen], ex[seen], exx[seen]
        if errors:
            k = float(np.sum(ys * (fo - mo)) / np.sum(fo * fo - 2.0 * fo * mo + vo))
            r = float(np.mean(ys * ys - 2.0 * k * ys * (fo - mo) + k * k * (fo * fo - 2.0 * fo * mo + vo)))
        else:
            r = float(np.mean(ys * ys - 2.0 * ys * mo + vo))
        r = max(r, 1e-12)
        if log_l - previous < EM_TOLERANCE * max(1.0, abs(log_l)):
            break
        previous = log_l
    names = ["A", "B", *(["k"] if errors else []), "Q", "R"]
    values = {"A": a, "B": b, **({"k": k} if errors else {}), "Q": q, "R": r}
    values = _polish(values, names, f, learn, seen, y, observed_kind)
    log_l, ms, _vs, _c = _filter(values["A"], values["B"], values.get("k", 1.0), values["Q"], values["R"], f, learn,
                                 seen, y, observed_kind, smooth=True)
    intervals = _wald(values, names, f, learn, seen, y, observed_kind)
    return StateSpaceFit(observed_kind, values, intervals, int(seen.sum()), log_l, iterations, ms[:-1])


def _logistic(u: float) -> float:
    # Written both ways so neither overflows: exp of a large -u would (a Wald end far out on the logit scale).
    if u >= 0.0:
        return 1.0 / (1.0 + math.exp(-u))
    e = math.exp(u)
    return e / (1.0 + e)


def _logit(v: float) -> float:
    v = min(max(v, 1e-300), 1.0 - 1e-16)  # a rate fitted to 0 or 1 (the logistic rounds there) has a finite logit
    return math.log(v / (1.0 - v))


#: ``math.exp`` overflows past this: beyond it a variance is unbounded, which an interval reports as such.
_LOG_MAX = math.log(1.7976931348623157e308)


def _exp(u: float) -> float:
    return math.exp(u) if u < _LOG_MAX else math.inf


def _log(v: float) -> float:
    return math.log(max(v, 1e-300))  # a variance fitted to 0 (no process noise at all) keeps a finite log


_TO = {"A": _logit, "B": _logit, "k": lambda v: v, "Q": _log, "R": _log}
_FROM = {"A": _logistic, "B": _logistic, "k": lambda u: u, "Q": _exp, "R": _exp}


def _polish(values: dict[str, float], names: list[str], f, learn, seen, y, kind: str) -> dict[str, float]:
    """EM's answer taken on to the likelihood's maximum by a quasi-Newton search on the transformed scales (EM
    climbs fast at first and slowly near the top, most slowly along the split of the noise between Q and R)."""
    from scipy.optimize import minimize

    u0 = np.array([_TO[name](min(max(values[name], 1e-12), 1.0 - 1e-9) if name in "AB" else values[name])
                   for name in names])

    def cost(u: np.ndarray) -> float:
        p = {name: _FROM[name](float(v)) for name, v in zip(names, u, strict=True)}
        if not all(math.isfinite(v) for v in p.values()) or p["Q"] <= 0.0 or p["R"] <= 0.0:
            return math.inf
        return -_filter(p["A"], p["B"], p.get("k", 1.0), p["Q"], p["R"], f, learn, seen, y, kind)

    with warnings.catch_warnings():
        # A step out of the parameters' range costs inf (refused); the finite differences across it are inf - inf.
        warnings.simplefilter("ignore", RuntimeWarning)
        best = minimize(cost, u0, method="BFGS", options={"maxiter": POLISH_ITERATIONS, "gtol": 1e-6})
    u = best.x if best.fun <= cost(u0) else u0
    return {name: _FROM[name](float(v)) for name, v in zip(names, u, strict=True)}


def _wald(values: dict[str, float], names: list[str], f, learn, seen, y, kind: str) -> dict[str, tuple[float, float]]:
    """95% Wald intervals from a central-difference Hessian of the log-likelihood on the transformed scales."""
    u0 = np.array([_TO[name](values[name]) for name in names])

    def log_l(u: np.ndarray) -> float:
        p = {name: _FROM[name](float(v)) for name, v in zip(names, u, strict=True)}
        return _filter(p["A"], p["B"], p.get("k", 1.0), p["Q"], p["R"], f, learn, seen, y, kind)

    h = np.array([1e-3 * max(1.0, abs(v)) for v in u0])
    size = len(names)
    hess = np.zeros((size, size))
    base = log_l(u0)
    for i in range(size):
        for j in range(i, size):
            ei, ej = np.eye(size)[i] * h[i], np.eye(size)[j] * h[j]
            if i == j:
                value = (log_l(u0 + ei) - 2.0 * base + log_l(u0 - ei)) / (h[i] * h[i])
            else:
                value = (log_l(u0 + ei + ej) - log_l(u0 + ei - ej) - log_l(u0 - ei + ej)
                         + log_l(u0 - ei - ej)) / (4.0 * h[i] * h[j])
            hess[i, j] = hess[j, i] = value
    try:
        covariance = np.linalg.inv(-hess)
        se = np.sqrt(np.where(np.diag(covariance) > 0, np.diag(covariance), np.nan))
    except np.linalg.LinAlgError:
        se = np.full(size, np.nan)
    out: dict[str, tuple[float, float]] = {}
    for i, name in enumerate(names):
        if not math.isfinite(se[i]):
            out[name] = (math.nan, math.nan)
            continue
        ends = sorted(_FROM[name](float(u0[i] + s * Z_975 * se[i])) for s in (-1.0, 1.0))
        out[name] = (ends[0], ends[1])
    return out


def simulate_generalization(rng: np.random.Generator, target: np.ndarray, targets: int, disturbance: np.ndarray,
                            a: float, c: Sequence[float], k: float, sigma: float) -> np.ndarray:
    """Errors drawn from the trial-by-trial model (for tests and the coverage benchmark)."""
    d = (np.arange(targets)[:, None] - np.arange(targets)[None, :]) % targets
    spread = np.asarray(c)[np.minimum(d, targets - d)]  # spread[now, before]
    z = np.zeros(targets)
    y = np.empty(target.size)
    for n, t in enumerate(target):
        y[n] = k * disturbance[n] - z[t] + sigma * rng.standard_normal()
        z = a * z + spread[:, t] * y[n]
    return y


def simulate_state_space(rng: np.random.Generator, disturbance: np.ndarray, clamped: np.ndarray, a: float, b: float,
                         k: float, q: float, r: float, kind: str = "error") -> np.ndarray:
    """Observations drawn from the state-space model (for tests and the coverage benchmark); NaN where the kind
    observes nothing (channel trials for errors, the others for indices)."""
    x = 0.0
    y = np.full(disturbance.size, np.nan)
    for n, (fn, c) in enumerate(zip(disturbance, clamped, strict=True)):
        e = 0.0 if c else fn - x
        if kind == "error" and not c:
            y[n] = k * e + math.sqrt(r) * rng.standard_normal()
        elif kind == "index" and c:
            y[n] = x + math.sqrt(r) * rng.standard_normal()
        x = a * x + b * e + math.sqrt(q) * rng.standard_normal()
    return y
