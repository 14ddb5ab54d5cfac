"""Fitting the two-rate model to a run (armgame/lab/fit.py, armgame analyze --fit): recovered rates from
learners with known rates, the constraints kept, one-line errors."""

import math
from pathlib import Path

import numpy as np
import pytest

from armgame.lab.fit import CHI2_1_95, compare, fit_learner, fit_two_rate, run_model
from armgame.lab.learner import TwoRateLearner, simulate

TRUE = {"retention_fast": 0.59, "retention_slow": 0.992, "rate_fast": 0.21, "rate_slow": 0.02}


def test_run_model_is_the_learner():
    f = np.r_[np.zeros(3), np.ones(20), -np.ones(3), np.zeros(5)]
    clamped = np.r_[np.zeros(26, bool), np.ones(5, bool)]
    np.testing.assert_array_equal(run_model(*TRUE.values(), f, clamped),
                                  simulate(TwoRateLearner(**TRUE), f, clamped)["estimate"])


def test_errors_of_a_learner_with_known_rates_give_them_back_within_the_intervals():
    """A learner with the bot's default rates, its errors seen through a gain (-2 cm per unit of field, as
    the bot's perpendicular error) with 1 mm of noise: the fit's 95% intervals hold the truth."""
    rng = np.random.default_rng(3)
    f = np.r_[np.zeros(8), np.ones(60), -np.ones(4), np.ones(40)]
    clamped = np.zeros(f.size, bool)
    y = -0.02 * simulate(TwoRateLearner(**TRUE), f, clamped)["error"] + rng.normal(0.0, 0.001, f.size)
    comparison = compare(f, clamped, y)
    fit = comparison.full
    assert fit.model == "two-rate" and comparison.simple.model == "one-rate"
    # A counter-field separates the processes: both criteria and the likelihood ratio want the two rates.
    assert comparison.preferred("aic") == comparison.preferred("bic") == "two-rate"
    assert comparison.delta_bic > 10 and comparison.p_value < 1e-6
    for name, value in TRUE.items():
        low, high = fit.intervals[name]
        assert low < value < high, (name, value, fit.intervals[name])
        assert high - low < 0.5
    assert fit.values["gain"] == pytest.approx(-0.02, rel=0.05)
    v = fit.values
    assert 0 < v["retention_fast"] < v["retention_slow"] < 1 and 0 < v["rate_slow"] < v["rate_fast"] < 1
    assert 0.0007 < fit.rms < 0.0013 and fit.r_squared > 0.9 and fit.n == f.size
    assert any("A_f = " in line for line in fit.lines()) and "residual: rms" in fit.lines()[-2]
    # docs/lab.md counts the parameters AIC and BIC charge for: the counts these fits use.
    doc = " ".join((Path(__file__).resolve().parent.parent / "docs" / "lab.md").read_text(encoding="utf-8").split())
    assert (f"({fit.n_parameters} for the two-rate model fitted to errors, {comparison.simple.n_parameters} for the "
            "one-rate)") in doc


def test_channel_indices_of_the_spontaneous_recovery_paradigm_give_the_rates_back():
    """Only the channel trials are observed (the index is the learner's estimate), yet exposure, the
    counter-field and the rebound in the clamp block pin all four rates."""
    rng = np.random.default_rng(5)
    f = np.r_[np.zeros(8), np.ones(120), -np.ones(4), np.zeros(40)]
    channel = np.zeros(f.size, bool)
    channel[12:128:8] = True
    channel[132:] = True
    x = simulate(TwoRateLearner(**TRUE), f, channel)["estimate"]
    y = np.where(channel, x + rng.normal(0.0, 0.03, f.size), np.nan)
    fit = fit_two_rate(f, channel, y, "index")
    assert "gain" not in fit.values and fit.n == channel.sum()
    for name, value in TRUE.items():
        low, high = fit.intervals[name]
        assert low < value < high, (name, value, fit.intervals[name])


def test_a_learner_the_data_cannot_see_gives_wide_intervals_not_false_precision():
    """Errors of a single-rate learner (no fast process at all): the fit cannot place the fast process's
    retention, and says so with a wide interval."""
    f = np.r_[np.zeros(8), np.ones(60)]
    y = 0.01 * simulate(TwoRateLearner.single_rate(0.98, 0.1), f)["error"]
    fit = fit_two_rate(f, np.zeros(f.size, bool), y)
    low, high = fit.intervals["retention_fast"]
    assert high - low > 0.3 or fit.values["rate_fast"] - fit.values["rate_slow"] < 0.05


@pytest.mark.parametrize("args, message", [
    ((np.ones(5), np.zeros(5, bool), np.ones(5)), "5 trials with a value: a two-rate fit needs at least 8"),
    ((np.zeros(20), np.zeros(20, bool), np.ones(20)), "no trial had a disturbance"),
    ((np.ones(20), np.zeros(19, bool), np.ones(20)), "of the same length"),
    ((np.ones(20), np.ones(20, bool), np.ones(20)), "0 trials with a value"),
])
def test_data_that_cannot_be_fitted_are_one_line_value_errors(args, message):
    with pytest.raises(ValueError, match=message):
        fit_two_rate(*args)


def test_the_likelihood_aic_and_bic_are_the_gaussian_ones_at_the_fitted_noise():
    """Checked against scipy's normal density at sigma = the rms residual, and the textbook AIC and BIC."""
    from scipy.stats import norm

    rng = np.random.default_rng(11)
    f = np.r_[np.zeros(6), np.ones(30)]
    y = 0.01 * simulate(TwoRateLearner.single_rate(0.9, 0.2), f)["error"] + rng.normal(0.0, 0.001, f.size)
    fit = fit_learner("one-rate", f, np.zeros(f.size, bool), y)
    residuals = y - fit.predicted
    assert fit.rms == pytest.approx(math.sqrt(np.mean(residuals ** 2)), rel=1e-12)
    log_l = float(np.sum(norm.logpdf(residuals, scale=fit.rms)))
    assert fit.log_likelihood == pytest.approx(log_l, rel=1e-10)
    assert fit.n_parameters == 4  # A, B, k and the noise
    assert fit.aic == pytest.approx(2 * 4 - 2 * log_l) and fit.bic == pytest.approx(4 * math.log(36) - 2 * log_l)
    d = fit.as_dict("m")
    assert d["model"] == "one-rate" and set(d["parameters"]) == {"A", "B", "k"}
    assert d["intervals"] == "profile likelihood" and d["aic"] == pytest.approx(fit.aic)


def test_one_rate_data_give_their_rates_back_and_the_intervals_cover_them():
    """A single-rate learner's noisy errors, 6 draws: the one-rate model's profile intervals hold each true value
    in most draws (a valid 95% interval misses more than 2 of 6 with probability 2e-3; one a third as wide
    misses about 6 in 10), the interval's ends lie where the deviance has risen by chi2(1, 0.95), and the
    comparison does not claim a fast process the data do not have. The coverage over 200 draws is the
    benchmark's (benchmarks/fit_coverage.py)."""
    f = np.r_[np.zeros(4), np.ones(30), np.zeros(6)]
    clamped = np.zeros(f.size, bool)
    truth = {"retention": 0.95, "rate": 0.1, "gain": -0.02}
    error = simulate(TwoRateLearner.single_rate(0.95, 0.1), f)["error"]
    rng = np.random.default_rng(7)
    covered = dict.fromkeys(truth, 0)
    for _ in range(6):
        y = truth["gain"] * error + rng.normal(0.0, 0.002, f.size)
        fit = fit_learner("one-rate", f, clamped, y)
        for name, value in truth.items():
            low, high = fit.intervals[name]
            covered[name] += low < value < high
            assert low <= fit.values[name] <= high
    assert min(covered.values()) >= 4, covered
    # At the retention's upper end, A held there and B and k refitted (here by a bounded scalar search, the
    # gain in closed form) cost chi2(1, 0.95) in 2 ln L.
    from scipy.optimize import minimize_scalar

    high = fit.intervals["retention"][1]

    def rss(rate: float) -> float:
        g = f - run_model(0.0, high, 0.0, rate, f, clamped)
        return float(np.sum((g * (g @ y) / (g @ g) - y) ** 2))

    held = minimize_scalar(rss, bounds=(1e-6, 1 - 1e-6), method="bounded", options={"xatol": 1e-9}).fun
    rss_best = float(np.sum((fit.predicted - y) ** 2))
    assert f.size * math.log(held / rss_best) == pytest.approx(CHI2_1_95, abs=0.02)
    comparison = compare(f, clamped, y)
    assert comparison.preferred("bic") == "one-rate" and comparison.likelihood_ratio < CHI2_1_95 * 2
