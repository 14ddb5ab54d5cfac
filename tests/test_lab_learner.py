"""The two-rate learner of Smith, Ghazizadeh & Shadmehr (2006): its equations and its signatures."""

import doctest

import numpy as np
import pytest

from armgame.errors import UserError
from armgame.lab import learner as learner_module
from armgame.lab.learner import LearnerParameterError, TwoRateLearner, simulate


def test_defaults_are_the_documented_values():
    learner = TwoRateLearner()
    assert (learner.retention_fast, learner.retention_slow, learner.rate_fast, learner.rate_slow) == \
        (0.59, 0.992, 0.21, 0.02)
    assert learner.estimate == 0.0


def test_first_steps_match_the_equations_by_hand():
    learner = TwoRateLearner()
    out = simulate(learner, [1.0, 1.0, 1.0])
    # trial 1: e = 1; x_f = 0.21, x_s = 0.02.   trial 2: e = 1 - 0.23 = 0.77;
    # x_f = 0.59 * 0.21 + 0.21 * 0.77 = 0.2856, x_s = 0.992 * 0.02 + 0.02 * 0.77 = 0.03524.
    np.testing.assert_allclose(out["error"], [1.0, 0.77, 1.0 - 0.2856 - 0.03524], rtol=1e-12)
    np.testing.assert_allclose(out["fast"], [0.0, 0.21, 0.2856], rtol=1e-12)
    np.testing.assert_allclose(out["slow"], [0.0, 0.02, 0.03524], rtol=1e-12)
    e3 = 1.0 - 0.2856 - 0.03524
    assert learner.fast == pytest.approx(0.59 * 0.2856 + 0.21 * e3, rel=1e-12)
    assert learner.slow == pytest.approx(0.992 * 0.03524 + 0.02 * e3, rel=1e-12)


def test_a_constant_error_sums_a_geometric_series():
    learner = TwoRateLearner()
    for _ in range(30):
        learner.update(0.5)
    assert learner.fast == pytest.approx(0.21 * 0.5 * (1 - 0.59**30) / (1 - 0.59), rel=1e-12)
    assert learner.slow == pytest.approx(0.02 * 0.5 * (1 - 0.992**30) / (1 - 0.992), rel=1e-12)


def test_fast_early_learning_then_a_slow_tail():
    out = simulate(TwoRateLearner(), np.ones(300))
    x = out["estimate"]
    assert np.all(np.diff(x[:20]) > 0)
    assert x[10] > 0.5 * x[-1]                    # most of it in the first ten trials
    assert x[-1] - x[150] > 0.01                   # and still creeping up 150 trials later
    assert out["fast"][5] > out["slow"][5]         # early on the fast process carries it
    assert out["slow"][-1] > 2 * out["fast"][-1]   # late, the slow one
    # the classic two time constants: the early rise beats a single-rate learner with the slow rate...
    single = simulate(TwoRateLearner.single_rate(0.992, 0.02), np.ones(300))["estimate"]
    assert x[10] > 2 * single[10]


def exposure_then_counter(learner, exposure=200):
    """Adapt to +1, then to -1 until the net adaptation is back to zero (Smith et al.'s paradigm)."""
    simulate(learner, np.ones(exposure))
    counter = 0
    while learner.estimate > 0.0:
        simulate(learner, [-1.0])
        counter += 1
        assert counter < 100
    return counter


def test_savings_on_re_exposure():
    naive = simulate(TwoRateLearner(), np.ones(10))["estimate"]
    learner = TwoRateLearner()
    exposure_then_counter(learner)
    assert learner.estimate == pytest.approx(0.0, abs=0.1)
    assert learner.slow > 0.2 > 0 > learner.fast     # the slow memory outlives the washout
    again = simulate(learner, np.ones(10))["estimate"]
    assert again[-1] - again[0] > 1.2 * (naive[-1] - naive[0])
    # a single-rate learner zeroed by the washout has nothing left to save
    single = TwoRateLearner.single_rate(0.95, 0.1)
    simulate(single, np.ones(200))
    single.slow = 0.0
    np.testing.assert_array_equal(simulate(single, np.ones(10))["estimate"],
                                  simulate(TwoRateLearner.single_rate(0.95, 0.1), np.ones(10))["estimate"])


def test_spontaneous_recovery_in_error_clamp_trials():
    learner = TwoRateLearner()
    counter = exposure_then_counter(learner)
    assert 3 <= counter <= 40  # a short counter-adaptation
    clamp = simulate(learner, np.zeros(60), clamped=np.ones(60, dtype=bool))
    x = clamp["estimate"]
    assert np.all(clamp["error"] == 0.0)
    peak = int(np.argmax(x))
    assert x[peak] > 0.25 and 3 <= peak < 59        # the old adaptation re-emerges, then fades
    assert x[-1] < x[peak]
    single = TwoRateLearner.single_rate()
    simulate(single, np.ones(200))
    while single.estimate > 0.0:
        simulate(single, [-1.0])
    assert np.all(simulate(single, np.zeros(60), np.ones(60, dtype=bool))["estimate"] <= 0.0)  # none in one rate


def test_arrays_hold_independent_learners():
    vector = TwoRateLearner(fast=np.zeros(3), slow=np.zeros(3))
    scalars = [TwoRateLearner() for _ in range(3)]
    rng = np.random.default_rng(4)
    for _ in range(20):
        errors = rng.normal(size=3)
        vector.update(errors)
        for s, e in zip(scalars, errors, strict=True):
            s.update(float(e))
    np.testing.assert_allclose(vector.estimate, [s.estimate for s in scalars], rtol=1e-14)
    vector.update(1.0)  # a scalar error reaches every estimate
    assert vector.estimate.shape == (3,)
    with pytest.raises(ValueError, match="scalar learner"):
        simulate(vector, [1.0])


@pytest.mark.parametrize(("options", "message"), [
    ({"retention_fast": 1.2}, "retention fast must be a number from 0 to 1"),
    ({"rate_slow": -0.1}, "rate slow must be a number from 0 to 1"),
    ({"rate_fast": float("nan")}, "rate fast must be"),
    ({"rate_fast": True}, "rate fast must be"),
    ({"rate_fast": "0.2"}, "rate fast must be"),
    ({"retention_fast": 0.995}, "forget faster"),
    ({"rate_fast": 0.01}, "learn faster"),
    ({"slow": float("inf")}, "slow state must be finite"),
])
def test_impossible_settings_are_one_line_user_errors(options, message):
    with pytest.raises(LearnerParameterError, match=message) as info:
        TwoRateLearner(**options)
    assert isinstance(info.value, UserError) and isinstance(info.value, ValueError)
    assert "\n" not in str(info.value)


def test_single_rate_is_the_fast_process_switched_off():
    single = TwoRateLearner.single_rate(0.9, 0.3)
    for e in (1.0, -0.5, 0.25):
        single.update(e)
    assert single.fast == 0.0
    assert single.slow == pytest.approx(0.9 * (0.9 * 0.3 * 1.0 + 0.3 * -0.5) + 0.3 * 0.25, rel=1e-14)


def test_non_finite_errors_are_refused():
    learner = TwoRateLearner()
    with pytest.raises(ValueError, match="finite"):
        learner.update(float("nan"))
    with pytest.raises(ValueError, match="finite"):
        simulate(learner, [1.0, float("inf")])
    assert learner.estimate == 0.0


def test_module_examples():
    assert doctest.testmod(learner_module).failed == 0
