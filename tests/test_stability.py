"""The defaults on the hard cases, and no key sequence can break the game's arm.

The game's integrator and step (``armgame.physics.defaults``) must, on every hard case, stay
finite, keep the energy once torques stop, and follow the DOP853 reference.
"""

import functools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from armgame.bench.measure import HARD_CASES, make_case, step_torques
from armgame.physics import GAME_ARM, Integrator, TwoJointArm
from armgame.physics.defaults import (
    GAME_DT,
    GAME_INTEGRATOR,
    SIMULATE_DT,
    SIMULATE_INTEGRATOR,
)
from armgame.physics.reference import reference_trajectory

#: Largest hand error (m) over the first 2 s and relative energy error over 60 s torque-free, per
#: default and case. The game default is chosen for 0.1 mm on the game case and 1e-6 energy on the
#: passive one; RK4 is not symplectic, so the propeller (free at 70 rad/s, 0.3 rad per 4 ms step)
#: loses a stated, bounded share of its energy there: the game's own arm never spins that fast.
BOUNDS = {
    "game-default": {"passive": (1e-4, 1e-6), "propeller": (1e-3, 0.3), "upright": (1e-4, 1e-4),
                     "stiff": (1e-4, 1e-6), "game": (1e-4, 1e-3)},
    "simulate-default": {case: (1e-6, 1e-6) for case in HARD_CASES},
}
#: Seconds of torque-free motion checked: the 60 s the bench measures for the game default; 20 s for
#: simulate's 4000 steps a second, to keep the suite fast (its drift grows no faster than the game's).
FREE_RUN = {"game-default": 60.0, "simulate-default": 20.0}


@functools.cache
def case_of(case_name: str):
    """``make_case``, once per case for both defaults' tests: the game case's start of its free run is
    a 60 s reference solve (2 s), the propeller's a 3 s one."""
    return make_case(case_name)


@functools.cache
def free_reference(case_name: str) -> np.ndarray:
    """The reference every 0.5 s over the longest free run, once per case for both defaults' tests."""
    case = case_of(case_name)
    return reference_trajectory(case.model, case.free_state, np.arange(round(max(FREE_RUN.values()) / 0.5) + 1) * 0.5)


def run(name, model, state, torques, dt, steps, every=1):
    step = Integrator(name, model).step_components
    q1, q2, w1, w2 = state
    out = [state]
    for i in range(steps):
        t1, t2 = torques[i] if torques else (0.0, 0.0)
        q1, q2, w1, w2 = step(q1, q2, w1, w2, t1, t2, dt)
        if (i + 1) % every == 0:
            out.append((q1, q2, w1, w2))
    return np.array(out)


@pytest.mark.parametrize("case_name", HARD_CASES)
@pytest.mark.parametrize(("which", "integrator", "dt"), [("game-default", GAME_INTEGRATOR, GAME_DT),
                                                          ("simulate-default", SIMULATE_INTEGRATOR, SIMULATE_DT)])
def test_default_follows_the_reference_and_keeps_energy(case_name, which, integrator, dt):
    max_error, max_drift = BOUNDS[which][case_name]
    case = case_of(case_name)
    model = case.model
    # Follows the reference over the first 2 s, torques switching on the step grid.
    steps = round(2.0 / dt)
    states = run(integrator, model, case.scene.initial, step_torques(case.segments, dt, steps), dt, steps)
    assert np.all(np.isfinite(states))
    t = np.arange(steps + 1) * dt
    reference = reference_trajectory(model, case.scene.initial, t, case.segments)
    error = np.max(np.linalg.norm(model.hand(states[:, :2]) - model.hand(reference[:, :2]), axis=-1))
    assert error < max_error
    # Keeps its energy over 60 s once torques stop (started from the reference state then).
    every = round(0.5 / dt)
    free = run(integrator, model, case.free_state, None, dt, round(FREE_RUN[which] / dt), every)
    assert np.all(np.isfinite(free))
    energy = model.energy(free[:, :2], free[:, 2:])
    e0 = energy[0]
    if model.params.has_damping:
        # Damping only takes energy away: never more than at the start, and down as the reference goes.
        assert np.all(energy <= e0 * (1 + 1e-9))
        assert every * dt == 0.5
        ref = free_reference(case_name)[: len(free)]
        drift = np.max(np.abs(energy - model.energy(ref[:, :2], ref[:, 2:]))) / e0
    else:
        drift = np.max(np.abs(energy - e0)) / e0
    assert drift < max_drift


# ----------------------------------------------------------------------------- any key sequence
MAX_TORQUE = 2.0  # N m per joint: four times the 2012 game's muscle cap of 0.5 N m
GAME_TIME = 120.0  # s


def _speed_bound(params, t: float, torque_norm: float) -> float:
    """An upper bound on |qd| (rad/s) after ``t`` seconds from rest, for the horizontal, undamped arm.

    With no gravity or damping, dE/dt = tau . qd (the work of the torques), and E = qd' M qd / 2
    >= lambda_min |qd|^2 / 2, so |tau . qd| <= |tau| sqrt(2 E / lambda_min) and
    d sqrt(E)/dt <= |tau| / sqrt(2 lambda_min). From rest, sqrt(E) <= t |tau| / sqrt(2 lambda_min),
    hence |qd| <= sqrt(2 E / lambda_min) <= t |tau| / lambda_min. M's smallest eigenvalue is at least
    det(M) / trace(M) >= (a d - d^2 - b^2) / (a + d + 2 b) for every elbow angle.
    """
    arm = TwoJointArm(params)
    lambda_min = (arm.a * arm.d - arm.d**2 - arm.b**2) / (arm.a + arm.d + 2 * arm.b)
    return t * torque_norm / lambda_min


presses = st.lists(
    st.tuples(st.floats(0.02, 4.0), st.floats(-MAX_TORQUE, MAX_TORQUE), st.floats(-MAX_TORQUE, MAX_TORQUE)),
    min_size=1, max_size=40,
)


@settings(max_examples=12, deadline=None)
@given(presses=presses)
def test_no_key_sequence_breaks_the_game_arm(presses):
    """Piecewise-constant torques over 120 s of game time, held until the next press, cycled."""
    model = TwoJointArm(GAME_ARM)
    assert not GAME_ARM.has_gravity and not GAME_ARM.has_damping  # the bound below assumes both
    segments, t, k = [], 0.0, 0
    while t < GAME_TIME:
        duration, t1, t2 = presses[k % len(presses)]
        segments.append((t, (t1, t2)))
        t += duration
        k += 1
    dt = GAME_DT
    steps = round(GAME_TIME / dt)
    every = round(1.0 / dt)
    states = run(GAME_INTEGRATOR, model, (math.pi / 4, math.pi / 2, 0.0, 0.0),
                 step_torques(segments, dt, steps), dt, steps, every)
    assert np.all(np.isfinite(states))
    times = np.arange(len(states)) * every * dt
    speed = np.linalg.norm(states[:, 2:], axis=-1)
    bound = _speed_bound(GAME_ARM, times, math.hypot(MAX_TORQUE, MAX_TORQUE))
    assert np.all(speed <= bound * (1 + 1e-6) + 1e-9)
