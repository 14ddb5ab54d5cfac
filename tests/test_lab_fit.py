"""Fitting the two-rate model to a run (armgame/lab/fit.py, armgame analyze --fit): recovered rates from
learners with known rates, the constraints kept, one-line errors."""

import numpy as np
import pytest

from armgame.lab.fit import fit_two_rate, run_model
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
    fit = fit_two_rate(f, clamped, y)
    for name, value in TRUE.items():
        low, high = fit.intervals[name]
        assert low < value < high, (name, value, fit.intervals[name])
        assert high - low < 0.5
    assert fit.values["gain"] == pytest.approx(-0.02, rel=0.05)
    v = fit.values
    assert 0 < v["retention_fast"] < v["retention_slow"] < 1 and 0 < v["rate_slow"] < v["rate_fast"] < 1
    assert 0.0007 < fit.rms < 0.0013 and fit.r_squared > 0.9 and fit.n == f.size
    assert any("A_f = " in line for line in fit.lines()) and "residual: rms" in fit.lines()[-1]


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
