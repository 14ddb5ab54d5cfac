"""Fixed-step integrators: accuracy, energy, agreement with the reference, batch vs single."""

import math

import numpy as np
import pytest

from armgame.physics import GAME_ARM, PENDULUM, SCHEMES, TUTORIAL_ARM, Integrator, OneJointArm, TwoJointArm
from armgame.physics.integrators import UnknownIntegratorError
from armgame.physics.reference import reference_trajectory
from armgame.scenes import SCENES

PASSIVE_START = (-math.pi / 2, math.pi / 2, 0.0, 0.0)


def run_floats(name, model, state, torque, dt, steps, every=1):
    step = Integrator(name, model).step_components
    q1, q2, w1, w2 = state
    t1, t2 = torque
    out = [state]
    for i in range(steps):
        q1, q2, w1, w2 = step(q1, q2, w1, w2, t1, t2, dt)
        if (i + 1) % every == 0:
            out.append((q1, q2, w1, w2))
    return np.array(out)


def energy_of(model, states):
    return model.energy(states[:, :2], states[:, 2:])


def test_rk4_keeps_passive_energy_over_ten_seconds():
    arm = TwoJointArm(TUTORIAL_ARM)
    states = run_floats("rk4", arm, PASSIVE_START, (0.0, 0.0), 0.001, 10_000, every=100)
    energy = energy_of(arm, states)
    assert np.max(np.abs(energy - energy[0])) / abs(energy[0]) < 1e-8


@pytest.mark.parametrize(("name", "dt", "tolerance"), [("rk4", 0.001, 1e-9), ("gauss4", 0.002, 1e-9),
                                                       ("midpoint", 0.0005, 1e-3), ("euler", 1e-4, 0.05)])
def test_fixed_step_schemes_agree_with_dop853(name, dt, tolerance):
    arm = TwoJointArm(TUTORIAL_ARM)
    steps = round(2.0 / dt)
    states = run_floats(name, arm, PASSIVE_START, (0.0, 0.0), dt, steps, every=steps // 20)
    t = np.linspace(0.0, 2.0, 21)
    reference = reference_trajectory(arm, PASSIVE_START, t)
    error = np.max(np.linalg.norm(arm.hand(states[:, :2]) - arm.hand(reference[:, :2]), axis=-1))
    assert error < tolerance


def test_convergence_orders():
    arm = TwoJointArm(TUTORIAL_ARM)
    reference = reference_trajectory(arm, PASSIVE_START, [0.0, 0.5])[-1]
    for name, scheme in SCHEMES.items():
        errors = []
        for dt in (0.01, 0.005):
            final = run_floats(name, arm, PASSIVE_START, (0.0, 0.0), dt, round(0.5 / dt))[-1]
            errors.append(np.max(np.abs(final - reference)))
        observed = math.log2(errors[0] / errors[1])
        assert observed == pytest.approx(scheme.order, abs=0.3), name


@pytest.mark.slow  # ten minutes of arm, two seconds: the README's minute has no room for it
def test_energy_keeping_schemes_hold_energy_without_trend_for_600_seconds():
    arm = TwoJointArm(TUTORIAL_ARM)
    # A hard start: the arm whirling at over 10 rad/s, under gravity.
    start = (0.3, 1.0, 12.0, -15.0)
    for name, dt in (("midpoint", 0.005), ("gauss4", 0.01)):
        states = run_floats(name, arm, start, (0.0, 0.0), dt, round(600 / dt), every=round(0.5 / dt))
        energy = energy_of(arm, states)
        error = np.abs(energy - energy[0]) / energy[0]
        windows = error[1:].reshape(6, -1).max(axis=1)
        assert windows.max() < 5e-3, name
        assert windows[-1] < 2.0 * windows[0], f"{name}: energy error grows {windows}"


def test_semi_implicit_euler_on_velocities_loses_energy_after_a_fast_spin():
    """The reason the energy-keeping schemes work on momenta: this one does not keep energy."""
    arm = TwoJointArm(GAME_ARM)
    spun = run_floats("rk4", arm, (math.pi / 4, math.pi / 2, 0, 0), (2.0, -1.5), 0.001, 3000)[-1]
    kept = {}
    for name in ("symplectic-euler", "midpoint"):
        states = run_floats(name, arm, tuple(spun), (0.0, 0.0), 0.001, 10_000, every=1000)
        energy = energy_of(arm, states)
        kept[name] = energy[-1] / energy[0]
    assert kept["symplectic-euler"] < 0.5
    assert kept["midpoint"] == pytest.approx(1.0, abs=1e-3)


def test_pendulum_small_angle_period():
    arm = OneJointArm(PENDULUM)
    dt = 1e-3
    states = run_floats("rk4", arm, (-math.pi / 2 + 1e-4, 0.0, 0.0, 0.0), (0.0, 0.0), dt, 20_000)
    angle = states[:, 0] + math.pi / 2
    crossings = np.flatnonzero((angle[:-1] > 0) & (angle[1:] <= 0))
    times = (crossings + angle[crossings] / (angle[crossings] - angle[crossings + 1])) * dt
    period = np.mean(np.diff(times))
    assert period == pytest.approx(arm.small_angle_period(), rel=1e-6)


@pytest.mark.parametrize("name", list(SCHEMES))
def test_batch_steps_equal_single_steps(name):
    arm = TwoJointArm(DAMPED := TUTORIAL_ARM.replace(damping1=0.2, damping2=0.1))
    assert DAMPED.has_damping
    rng = np.random.default_rng(3)
    states = rng.uniform(-3, 3, (6, 4))
    torque = rng.uniform(-1, 1, (6, 2))
    batch = Integrator(name, arm, backend="numpy")
    single = Integrator(name, arm)
    x = states
    singles = [tuple(s) for s in states]
    for _ in range(50):
        x = batch.step(x, torque, 0.002)
        singles = [single.step(s, u, 0.002) for s, u in zip(singles, torque, strict=True)]
    np.testing.assert_allclose(x, np.array(singles), rtol=1e-11, atol=1e-11)


def test_batch_accepts_leading_dimensions():
    arm = TwoJointArm(GAME_ARM)
    x = np.zeros((2, 3, 4)) + np.array([0.5, 1.0, 0.0, 0.0])
    out = Integrator("rk4", arm, backend="numpy").step(x, (0.1, -0.1), 0.01)
    assert out.shape == (2, 3, 4)
    np.testing.assert_array_equal(out[0, 0], out[1, 2])


def test_unknown_integrator_is_refused():
    with pytest.raises(UnknownIntegratorError, match="choose one of"):
        Integrator("leapfrog", TwoJointArm(GAME_ARM))


@pytest.mark.parametrize("scene", ["passive", "propeller", "upright"])
def test_reference_solution_keeps_energy_once_torques_stop(scene):
    s = SCENES[scene]
    t = np.linspace(s.free_after if s.free_after > 0 else 0.0, s.free_after + 4.0, 41)
    states = reference_trajectory(s.model, s.initial, np.concatenate([[0.0], t]), s.torque_segments)[1:]
    energy = energy_of(s.model, states)
    assert np.max(np.abs(energy - energy[0])) / energy[0] < 1e-9


@pytest.mark.parametrize("name", ["midpoint", "gauss4"])
def test_the_implicit_schemes_float_loops_equal_their_general_loops_bit_for_bit(name):
    """One arm on floats runs a loop of its own (the largest change in line): it must be the general one's
    arithmetic exactly, converged or not, on arms with and without gravity and damping."""
    import dataclasses

    from armgame.physics.twojoint import largest_abs_float

    rng = np.random.default_rng(8)
    for params in (GAME_ARM, TUTORIAL_ARM, TUTORIAL_ARM.replace(damping1=0.2, damping2=0.1)):
        dyn = TwoJointArm(params).component_dynamics("float")
        fast = SCHEMES[name].build(dyn)
        general = SCHEMES[name].build(dataclasses.replace(dyn, largest=lambda *xs: largest_abs_float(*xs)))
        assert fast is not general and fast.__name__ != general.__name__
        for dt in (0.001, 0.02, 0.2):
            a = b = tuple(float(x) for x in rng.uniform(-3, 3, 4))
            for torque in rng.uniform(-2, 2, (40, 2)):
                try:
                    a = fast(*a, *map(float, torque), dt)
                except ValueError as exc:  # a step too large blows up: both the same way
                    with pytest.raises(ValueError, match=str(exc)):
                        general(*b, *map(float, torque), dt)
                    break
                b = general(*b, *map(float, torque), dt)
                assert [x.hex() for x in a] == [x.hex() for x in b]
