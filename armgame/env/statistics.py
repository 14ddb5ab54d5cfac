"""Aggregate scores over training seeds as a reviewer asks: the interquartile mean and stratified bootstrap intervals.

Agarwal et al. (2021, "Deep reinforcement learning at the edge of the statistical precipice") recommend,
for a few training runs per task: report the **interquartile mean** (IQM: the mean of the middle 50 % of
the runs' scores, pooled over tasks), robust to one run that failed or one that got lucky, with a 95 %
**stratified bootstrap** confidence interval (each bootstrap sample redraws, with replacement, the runs
of every task separately, so each task keeps its number of runs), by the percentile method. Their
library ``rliable`` computes these; it installs from PyPI (1.2.0, a source package) but brings arch,
statsmodels, pandas, seaborn and absl-py with it, ten packages for two functions, and imports only beside
pandas 2 (``pip install rliable==1.2.0 "pandas<3"``), so the same statistics
are here in numpy. ``tests/test_env_statistics.py`` holds them to a brute-force computation: every one
of the bootstrap's resamples of a small table enumerated.

``scores`` is an array of shape ``(runs, tasks)``: one row a training seed, one column an env id (each
run's score on a task: its mean hits on the evaluation games, or a normalised score).

>>> import numpy as np
>>> scores = np.array([[60.0, 30.0], [62.0, 20.0], [70.0, 35.0], [10.0, 28.0]])
>>> float(iqm(scores))                       # the middle four of the eight: 28, 30, 35, 60
38.25
>>> low, high = stratified_bootstrap_ci(scores, iqm, reps=2000, seed=0)
>>> bool(low <= iqm(scores) <= high)
True
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

#: rliable's default count of bootstrap samples.
DEFAULT_REPS = 50_000
#: Bootstrap samples drawn at once: bounds the index arrays' memory (reps x runs x tasks int64s).
_CHUNK = 5_000


def iqm(scores: np.ndarray) -> float | np.ndarray:
    """The interquartile mean of all the scores pooled: the mean of those between the 25th and 75th percentiles.

    As ``scipy.stats.trim_mean(scores, 0.25, axis=None)`` (rliable's definition): sorted, ``floor(n / 4)``
    cut from each end. A 3-d input ``(samples, runs, tasks)`` gives one IQM a sample."""
    x = np.asarray(scores, dtype=np.float64)
    if x.ndim == 3:
        flat = np.sort(x.reshape(x.shape[0], -1), axis=1)
        cut = flat.shape[1] // 4
        return flat[:, cut:flat.shape[1] - cut].mean(axis=1)
    flat = np.sort(x.ravel())
    if flat.size == 0:
        raise ValueError("the IQM of no scores")
    cut = flat.size // 4
    return float(flat[cut:flat.size - cut].mean())


def mean_of_tasks(scores: np.ndarray) -> float | np.ndarray:
    """The mean over runs and tasks (the aggregate the IQM is compared with); per sample for a 3-d input."""
    x = np.asarray(scores, dtype=np.float64)
    return x.reshape(x.shape[0], -1).mean(axis=1) if x.ndim == 3 else float(x.mean())


def median_of_tasks(scores: np.ndarray) -> float | np.ndarray:
    """The median over tasks of each task's mean over runs (rliable's "median"); per sample for a 3-d input."""
    x = np.asarray(scores, dtype=np.float64)
    return np.median(x.mean(axis=1), axis=1) if x.ndim == 3 else float(np.median(x.mean(axis=0)))


def stratified_bootstrap_ci(scores: np.ndarray, statistic: Callable[[np.ndarray], float | np.ndarray] = iqm, *,
                            reps: int = DEFAULT_REPS, confidence: float = 0.95,
                            seed: int = 0) -> tuple[float, float]:
    """The percentile interval of ``statistic`` over ``reps`` stratified bootstrap samples of ``scores``.

    ``scores``: ``(runs, tasks)``. Each sample redraws ``runs`` rows with replacement, independently for
    every task (column). ``statistic`` takes a ``(samples, runs, tasks)`` array and returns one value a
    sample (``iqm``, ``mean_of_tasks`` and ``median_of_tasks`` do). ``seed`` fixes the draws: the same call
    gives the same interval."""
    x = np.asarray(scores, dtype=np.float64)
    if x.ndim != 2 or x.shape[0] < 1 or x.shape[1] < 1:
        raise ValueError(f"scores must be a (runs, tasks) array, got shape {x.shape}")
    if not np.isfinite(x).all():
        raise ValueError("scores must be finite")
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must be between 0 and 1, got {confidence!r}")
    if isinstance(reps, bool) or not isinstance(reps, int) or reps < 1:
        raise ValueError(f"reps must be a whole number of samples, at least 1, got {reps!r}")
    runs, tasks = x.shape
    rng = np.random.Generator(np.random.PCG64(seed))
    columns = np.arange(tasks)
    values = []
    for start in range(0, reps, _CHUNK):
        n = min(_CHUNK, reps - start)
        rows = rng.integers(0, runs, size=(n, runs, tasks))
        values.append(np.asarray(statistic(x[rows, columns]), dtype=np.float64))
    samples = np.concatenate(values)
    tail = (1.0 - confidence) / 2.0 * 100.0
    low, high = np.percentile(samples, [tail, 100.0 - tail])
    return float(low), float(high)


def aggregate(scores: np.ndarray, *, reps: int = DEFAULT_REPS, seed: int = 0) -> dict[str, tuple[float, float, float]]:
    """IQM, mean and median of ``scores`` ``(runs, tasks)``, each as (point, low, high) with its 95 % interval."""
    out = {}
    for name, statistic in (("iqm", iqm), ("mean", mean_of_tasks), ("median", median_of_tasks)):
        low, high = stratified_bootstrap_ci(scores, statistic, reps=reps, seed=seed)
        out[name] = (float(statistic(np.asarray(scores, dtype=np.float64))), low, high)  # type: ignore[arg-type]
    return out
