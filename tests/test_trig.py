"""The arm's own sine (armgame.physics.trig): its accuracy as stated, and the same bits in every form."""

from __future__ import annotations

import math
import random
import struct
from pathlib import Path

import mpmath
import numpy as np
import pytest

from armgame.game.batch import compiled
from armgame.physics import trig
from armgame.physics.params import GAME_ARM, TUTORIAL_ARM
from armgame.physics.twojoint import TwoJointArm

#: The worst errors the module's docstring states (ulp of the true value, measured against mpmath).
STATED = {100.0: 1.5, 1e5: 2.5}

SPECIAL = [0.0, -0.0, 1e-300, -5e-324, math.pi / 4, math.pi / 2, -math.pi / 2, math.pi, 2 * math.pi, 3 * math.pi / 4,
           1e6, -1e6, 1e9 + 0.5, 1e15, -1e15]


def _bits(x: float) -> int:
    return struct.unpack("<q", struct.pack("<d", x))[0]


def _ulps(got: float, x: float) -> float:
    with mpmath.workdps(40):
        want_s, want_c = mpmath.sin(mpmath.mpf(x)), mpmath.cos(mpmath.mpf(x))
    errors = []
    for value, want in ((got[0], want_s), (got[1], want_c)):
        nearest = float(want)
        ulp = math.ulp(nearest) if nearest != 0.0 else 5e-324
        errors.append(float(abs(mpmath.mpf(value) - want)) / ulp)
    return max(errors)


@pytest.mark.parametrize("scale", sorted(STATED))
def test_within_the_stated_ulps_of_the_true_sine(scale):
    rng = random.Random(int(scale))
    angles = [rng.uniform(-scale, scale) for _ in range(4000)] + [rng.uniform(-1.0, 1.0) for _ in range(1000)]
    worst = max(_ulps(trig.sin_cos_python(x), x) for x in angles)
    assert worst <= STATED[scale]
    assert worst > 0.5  # not the C library's (nor correctly rounded): the measurement sees the method


def test_the_docstring_and_the_physics_page_state_the_measured_bounds():
    physics = (Path(__file__).resolve().parent.parent / "docs" / "physics.md").read_text()
    claim = f"within {STATED[100.0]:g} ulp for |x| <= 100 rad, {STATED[1e5]:g} ulp up to 1e5"
    for text in (trig.__doc__, physics):
        assert claim in " ".join(text.split())
    assert f"beyond {trig.MAX_ANGLE:.0e}".replace("e+", "e") in " ".join(physics.split())


def test_python_and_numpy_give_the_same_bits():
    rng = np.random.default_rng(7)
    x = np.concatenate([rng.uniform(-4, 4, 20000), rng.uniform(-1e5, 1e5, 20000), rng.uniform(-1e15, 1e15, 2000),
                        SPECIAL, [np.nextafter(trig.MAX_ANGLE, np.inf), np.inf, -np.inf, np.nan, 1e300]])
    s, c = trig.sin_cos_array(x)
    for i, v in enumerate(x.tolist()):
        ps, pc = trig.sin_cos_python(v)
        if math.isnan(ps):
            assert math.isnan(s[i]) and math.isnan(c[i]) and math.isnan(pc), v
        else:
            assert (_bits(ps), _bits(pc)) == (_bits(float(s[i])), _bits(float(c[i]))), v


@pytest.mark.skipif(trig.sin_cos is trig.sin_cos_python, reason="the compiled _ctrig is not built here")
def test_the_compiled_sine_for_python_gives_the_python_bits():
    from armgame.physics import _ctrig

    rng = random.Random(11)
    angles = ([rng.uniform(-4, 4) for _ in range(20000)] + [rng.uniform(-1e15, 1e15) for _ in range(2000)]
              + SPECIAL + [math.nextafter(trig.MAX_ANGLE, math.inf), math.inf, math.nan, 1e300, 3, True])
    for x in angles:
        want = trig.sin_cos_python(x)
        got = _ctrig.sin_cos(x)
        assert [_bits(v) for v in got] == [_bits(v) for v in want] or all(map(math.isnan, got + want)), x
        assert _bits(_ctrig.sin(x)) == _bits(got[0]) and _bits(_ctrig.cos(x)) == _bits(got[1])
    with pytest.raises(TypeError):
        _ctrig.sin_cos("1.0")


def test_numpy_writes_into_the_arrays_given_even_its_argument():
    x = np.linspace(-7.0, 7.0, 101)
    s, c = trig.sin_cos_array(x)
    y = x.copy()
    trig.sin_cos_array(y, None, y)
    assert np.array_equal(y, c)
    out = np.empty_like(x)
    assert trig.sin_array(x, out) is out and np.array_equal(out, s)
    assert np.array_equal(trig.cos_array(x), c)


def test_beyond_the_range_and_not_finite_is_nan_never_an_error():
    for x in (math.inf, -math.inf, math.nan, 1e300, -math.nextafter(trig.MAX_ANGLE, math.inf)):
        assert all(math.isnan(v) for v in trig.sin_cos(x) + trig.sin_cos_python(x))
    with np.errstate(all="raise"):  # no warning either: the suite runs with warnings as errors
        s, c = trig.sin_cos_array(np.array([np.inf, np.nan, 1e300, 0.5]))
    assert np.isnan(s[:3]).all() and np.isnan(c[:3]).all() and s[3] == trig.sin(0.5)


def test_exact_values_and_signs():
    assert trig.sin_cos(0.0) == (0.0, 1.0) == trig.sin_cos(-0.0)
    for k in range(-8, 9):
        s, c = trig.sin_cos(k * math.pi / 2)
        assert (round(s), round(c)) == (round(math.sin(k * math.pi / 2)), round(math.cos(k * math.pi / 2)))
        assert abs(s - math.sin(k * math.pi / 2)) < 1e-15 and abs(c - math.cos(k * math.pi / 2)) < 1e-15


@pytest.mark.skipif(not compiled.AVAILABLE, reason="the compiled kernel is not built here")
@pytest.mark.parametrize("preset", [GAME_ARM, TUTORIAL_ARM], ids=["game arm", "tutorial arm, with gravity"])
def test_the_compiled_step_takes_the_same_trig_as_python(preset):
    """One RK4 step in C (``_ckernel.rk4_step``) and in Python from states whose angles span the range
    (huge ones included): the same bits, so C's ``arm_sin_cos`` is Python's (the gravity arm's cos q1 and
    cos(q1 + q2) too). The lanes are held to the one-game loop in test_lanes and test_batch."""
    from armgame.game import _ckernel
    from armgame.game.session import KERNEL_PARAMS, kernel_mode, kernel_params
    from armgame.physics.integrators import Integrator

    arm = TwoJointArm(preset)
    step = Integrator("rk4", arm).step_components
    dt = 0.004
    params = struct.pack(f"={KERNEL_PARAMS}d", *kernel_params(arm, dt, [0.0] * 4, [0.0] * 4))
    mode = kernel_mode(arm.params)
    rng = random.Random(3)
    angles = [rng.uniform(-10, 10) for _ in range(3000)] + [rng.uniform(-1e14, 1e14) for _ in range(300)] + SPECIAL
    for q2 in angles:
        q1 = rng.choice([rng.uniform(-10, 10), q2])
        w1, w2, t1, t2 = (rng.uniform(-3, 3) for _ in range(4))
        want = step(q1, q2, w1, w2, t1, t2, dt)
        got = _ckernel.rk4_step(params, mode, q1, q2, w1, w2, t1, t2, dt)
        assert [_bits(v) for v in got] == [_bits(v) for v in want], (q1, q2)
