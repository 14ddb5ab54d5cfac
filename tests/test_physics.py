"""The two- and one-joint models: parameters, kinematics, dynamics, single vs batch."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from armgame.physics import (
    GAME_ARM,
    PENDULUM,
    TUTORIAL_ARM,
    OneJointArm,
    OneJointParams,
    ParameterError,
    TwoJointArm,
    UnreachableError,
)

angles = st.floats(-10.0, 10.0, allow_nan=False)
speeds = st.floats(-50.0, 50.0, allow_nan=False)
torques = st.floats(-20.0, 20.0, allow_nan=False)
DAMPED_TUTORIAL = TUTORIAL_ARM.replace(damping1=0.3, damping2=0.2)


@pytest.mark.parametrize(
    ("changes", "field"),
    [({"l1": -0.3}, "l1"), ({"m2": 0.0}, "m2"), ({"i1": math.nan}, "i1"), ({"r2": 0.5}, "r2"),
     ({"gravity": -9.81}, "gravity"), ({"damping2": math.inf}, "damping2")],
)
def test_impossible_parameters_name_the_field_and_value(changes, field):
    with pytest.raises(ParameterError, match=field) as info:
        TUTORIAL_ARM.replace(**changes)
    assert repr(next(iter(changes.values()))) in str(info.value)


def test_one_joint_parameters_are_validated():
    with pytest.raises(ParameterError, match="r must not exceed l"):
        OneJointParams(l=0.3, r=0.5, m=1.0, i=0.01)
    with pytest.raises(ParameterError, match="unknown"):
        PENDULUM.replace(length=2.0)


def test_presets_match_the_tutorial():
    assert (TUTORIAL_ARM.l1, TUTORIAL_ARM.l2, TUTORIAL_ARM.r1, TUTORIAL_ARM.r2) == (0.3384, 0.4554, 0.1692, 0.2277)
    assert TUTORIAL_ARM.gravity == 9.81 and GAME_ARM.gravity == 0.0
    assert (PENDULUM.m, PENDULUM.r, PENDULUM.i) == (1.65, 0.5, 0.025)


@settings(max_examples=200, deadline=None)
@given(q1=angles, q2=angles)
def test_mass_matrix_symmetric_positive_definite(q1, q2):
    m = TwoJointArm(TUTORIAL_ARM).mass_matrix([q1, q2])
    assert m[0, 1] == m[1, 0]
    assert np.all(np.linalg.eigvalsh(m) > 0.0)


@settings(max_examples=200, deadline=None)
@given(q1=angles, q2=angles, w1=speeds, w2=speeds, t1=torques, t2=torques)
def test_inverse_dynamics_undoes_forward_dynamics(q1, q2, w1, w2, t1, t2):
    arm = TwoJointArm(DAMPED_TUTORIAL)
    q, qd, tau = np.array([q1, q2]), np.array([w1, w2]), np.array([t1, t2])
    qdd = arm.forward_dynamics(q, qd, tau)
    scale = 1.0 + np.max(np.abs(arm.coriolis(q, qd))) + np.max(np.abs(tau))
    np.testing.assert_allclose(arm.inverse_dynamics(q, qd, qdd), tau, atol=1e-12 * scale)


@pytest.mark.parametrize("params", [TUTORIAL_ARM, DAMPED_TUTORIAL, GAME_ARM, GAME_ARM.replace(damping1=0.2)],
                         ids=["gravity", "gravity+damping", "plain", "damping"])
@settings(max_examples=50, deadline=None)
@given(q1=angles, q2=angles, w1=speeds, w2=speeds, t1=torques, t2=torques)
def test_component_closures_equal_array_methods(params, q1, q2, w1, w2, t1, t2):
    arm = TwoJointArm(params)
    dyn = arm.component_dynamics("float")
    qdd = arm.forward_dynamics([q1, q2], [w1, w2], [t1, t2])
    np.testing.assert_allclose(dyn.accel(q1, q2, w1, w2, t1, t2), qdd, rtol=1e-11, atol=1e-9)
    p = arm.momentum([q1, q2], [w1, w2])
    np.testing.assert_allclose(dyn.momentum(q1, q2, w1, w2), p, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(dyn.velocity(q1, q2, *p), [w1, w2], rtol=1e-9, atol=1e-9)


def test_batch_equals_single_state():
    arm = TwoJointArm(DAMPED_TUTORIAL)
    rng = np.random.default_rng(1)
    q = rng.uniform(-3, 3, (3, 5, 2))
    qd = rng.uniform(-5, 5, (3, 5, 2))
    tau = rng.uniform(-2, 2, (3, 5, 2))
    batch = {
        "hand": arm.hand(q), "jacobian": arm.jacobian(q), "mass": arm.mass_matrix(q),
        "qdd": arm.forward_dynamics(q, qd, tau), "energy": arm.energy(q, qd),
    }
    for i in range(3):
        for j in range(5):
            single = {
                "hand": arm.hand(q[i, j]), "jacobian": arm.jacobian(q[i, j]), "mass": arm.mass_matrix(q[i, j]),
                "qdd": arm.forward_dynamics(q[i, j], qd[i, j], tau[i, j]), "energy": arm.energy(q[i, j], qd[i, j]),
            }
            for key, value in single.items():
                np.testing.assert_array_equal(batch[key][i, j], value, err_msg=key)


def test_hand_start_of_the_tutorial_passive_run():
    arm = TwoJointArm(TUTORIAL_ARM)
    np.testing.assert_allclose(arm.hand([-math.pi / 2, math.pi / 2]), [0.4554, -0.3384], atol=1e-15)
    np.testing.assert_allclose(arm.elbow([-math.pi / 2, math.pi / 2]), [0.0, -0.3384], atol=1e-15)


@settings(max_examples=100, deadline=None)
@given(q1=angles, q2=angles)
def test_jacobian_matches_finite_differences(q1, q2):
    arm = TwoJointArm(GAME_ARM)
    q = np.array([q1, q2])
    h = 1e-6
    numeric = np.column_stack([(arm.hand(q + h * e) - arm.hand(q - h * e)) / (2 * h) for e in np.eye(2)])
    np.testing.assert_allclose(arm.jacobian(q), numeric, atol=1e-8)


@settings(max_examples=200, deadline=None)
@given(q1=st.floats(-math.pi, math.pi), q2=st.floats(0.05, math.pi - 0.05), sign=st.sampled_from([1.0, -1.0]))
def test_inverse_kinematics_round_trip_both_elbows(q1, q2, sign):
    arm = TwoJointArm(TUTORIAL_ARM)
    hand = arm.hand([q1, sign * q2])
    q = arm.inverse_kinematics(hand, elbow_sign=sign)
    np.testing.assert_allclose(arm.hand(q), hand, atol=1e-12)
    assert math.copysign(1.0, q[1]) == sign
    np.testing.assert_allclose(q[1], sign * q2, atol=1e-7)
    up, down = arm.inverse_kinematics_both(hand)
    np.testing.assert_allclose(arm.hand(up), arm.hand(down), atol=1e-12)


@pytest.mark.parametrize("point", [(0.9, 0.0), (0.05, 0.05), (math.nan, 0.0)])
def test_unreachable_points_raise_a_clear_error(point):
    with pytest.raises(UnreachableError, match="out of reach"):
        TwoJointArm(TUTORIAL_ARM).inverse_kinematics(point)


def test_horizontal_arm_has_no_gravity_torque():
    arm = TwoJointArm(GAME_ARM)
    np.testing.assert_array_equal(arm.gravity(np.random.default_rng(0).uniform(-3, 3, (10, 2))), 0.0)


def test_one_joint_arm_dynamics_and_energy():
    arm = OneJointArm(PENDULUM)
    assert arm.inertia == pytest.approx(0.025 + 1.65 * 0.25)
    # The tutorial's start (theta = 90 deg) is horizontal: q = 0, hand at (l, 0).
    np.testing.assert_allclose(arm.hand(0.0), [0.5, 0.0])
    qdd = arm.forward_dynamics(0.0, 0.0, 0.0)
    assert qdd == pytest.approx(-(1.65 * 9.81 * 0.5) / (0.025 + 1.65 * 0.25))
    assert arm.inverse_dynamics(0.3, 1.0, arm.forward_dynamics(0.3, 1.0, 0.7)) == pytest.approx(0.7)
    assert arm.potential_energy(-math.pi / 2) == pytest.approx(0.0, abs=1e-15)
