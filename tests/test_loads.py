"""Loads on the arm (armgame/physics/loads.py): the hand force enters as J^T F, checked against MuJoCo's
xfrc_applied and the virtual work; a curl field does no work; a game without loads does not move."""

import math
from pathlib import Path

import numpy as np
import pytest

from armgame.bench.mjcf import build_model, load_mujoco
from armgame.game.bots import play_bot
from armgame.game.rules import GAME_PLAY_ARM, GameConfig
from armgame.game.session import GameSession, InputEvent
from armgame.physics import GAME_ARM, TUTORIAL_ARM, Integrator, TwoJointArm
from armgame.physics.loads import (
    ChannelField,
    ConstantForce,
    CurlField,
    JointLoad,
    LoadedArm,
    Loads,
    SpringField,
    ViscousField,
    hand_force_torque,
    loaded_arm,
)

#: The tolerances and the strong curl field docs/lab.md ("Perturbations in the physics") quotes:
#: test_the_docs_quote_these_tests holds the text to them.
MUJOCO_TOLERANCE = 1e-9  # joint accelerations against MuJoCo's xfrc_applied
STRONG_CURL = 13.0  # N s/m
DRIFT_TOLERANCE = 1e-7  # a passive arm's relative energy change, with the strong curl field and without
DRIFT_DT, DRIFT_STEPS = 0.001, 3000
WORK_TOLERANCE = 1e-3  # the viscous field's work against the energy change, relative to the change

FIELDS = {
    "curl": CurlField(STRONG_CURL),
    "viscous": ViscousField(((-10.1, -11.2), (-11.2, 11.1))),
    "channel": ChannelField(2000.0, 50.0, (0.1, 0.5), (0.6, 0.8)),
    "constant": ConstantForce(3.0, -2.0),
    "spring": SpringField(40.0, (0.1, 0.5)),
}
STATES = np.random.default_rng(7).uniform([-2, 0.2, -3, -3], [2, 2.8, 3, 3], (6, 4))


def _mujoco():
    mujoco = load_mujoco()
    if mujoco is None:
        pytest.skip("mujoco not installed (the optional bench extra)")
    return mujoco


@pytest.mark.parametrize("name", list(FIELDS))
@pytest.mark.parametrize("params", [GAME_PLAY_ARM, TUTORIAL_ARM], ids=["game", "tutorial"])
def test_hand_force_accelerates_the_arm_as_mujoco_xfrc_applied_does(name, params):
    """MuJoCo applies a world-frame force at the forearm's centre of mass (xfrc_applied); the same force
    at the hand is that force plus the moment (hand - com) x F. Its joint accelerations must equal ours."""
    mujoco = _mujoco()
    field = FIELDS[name]
    model, data = build_model(mujoco, params, 0.001)
    arm = TwoJointArm(params)
    accel = LoadedArm(arm, Loads(hand=field)).component_dynamics("float").accel
    forearm = model.body("forearm").id
    for q1, q2, w1, w2 in STATES:
        data.qpos[:], data.qvel[:] = (q1, q2), (w1, w2)
        mujoco.mj_kinematics(model, data)
        hand = data.xpos[forearm] + params.l2 * data.xmat[forearm].reshape(3, 3)[:, 0]
        v = arm.hand_velocity([q1, q2], [w1, w2])
        np.testing.assert_allclose(hand[:2], arm.hand([q1, q2]), atol=1e-12)
        fx, fy = field.force(hand[0], hand[1], v[0], v[1], 0.0)
        lever = hand - data.xipos[forearm]
        data.xfrc_applied[:] = 0.0
        data.xfrc_applied[forearm] = [fx, fy, 0.0, 0.0, 0.0, lever[0] * fy - lever[1] * fx]
        mujoco.mj_forward(model, data)
        ours = accel(q1, q2, w1, w2, 0.3, -0.2)
        free = arm.forward_dynamics([q1, q2], [w1, w2], [0.3, -0.2])
        data.qfrc_applied[:] = (0.3, -0.2)
        mujoco.mj_forward(model, data)
        np.testing.assert_allclose(ours, data.qacc, rtol=MUJOCO_TOLERANCE, atol=MUJOCO_TOLERANCE)
        assert np.max(np.abs(np.subtract(ours, free))) > 1e-3  # the force did something
        data.qfrc_applied[:] = 0.0


@pytest.mark.parametrize("name", list(FIELDS))
def test_hand_force_torque_is_the_virtual_work(name):
    """tau_i = dW/dq_i with W = F . x: central differences of the hand position, F held."""
    arm = TwoJointArm(GAME_ARM)
    field = FIELDS[name]
    h = 1e-6
    for q1, q2, w1, w2 in STATES:
        x = arm.hand([q1, q2])
        v = arm.hand_velocity([q1, q2], [w1, w2])
        f = np.array(field.force(x[0], x[1], v[0], v[1], 0.0))
        work = []
        for dq in ((h, 0.0), (0.0, h)):
            ahead, behind = arm.hand([q1 + dq[0], q2 + dq[1]]), arm.hand([q1 - dq[0], q2 - dq[1]])
            work.append(f @ (ahead - behind) / (2 * h))
        np.testing.assert_allclose(hand_force_torque(arm, field, [q1, q2], [w1, w2]), work, rtol=1e-7, atol=1e-8)
        # ... and the closures (written out by hand) agree with TwoJointArm's kinematics.
        tau = hand_force_torque(arm, field, [q1, q2], [w1, w2])
        loaded = LoadedArm(arm, Loads(hand=field)).component_dynamics("float").accel(q1, q2, w1, w2, 0.0, 0.0)
        np.testing.assert_allclose(loaded, arm.forward_dynamics([q1, q2], [w1, w2], tau), rtol=1e-12, atol=1e-12)


def test_numpy_closures_equal_float_closures():
    arm = TwoJointArm(GAME_PLAY_ARM)
    loads = Loads(hand=CurlField(2.0), joint=JointLoad((0.1, -0.05), ((0.2, 0.01), (0.0, 0.1))))
    loaded = LoadedArm(arm, loads)
    s = STATES
    batch = Integrator("rk4", loaded, "numpy").step(s, (0.2, 0.1), 0.004)
    single = [Integrator("rk4", loaded).step(tuple(x), (0.2, 0.1), 0.004) for x in s]
    np.testing.assert_allclose(batch, single, rtol=1e-13, atol=1e-14)


def test_joint_load_adds_its_torque():
    arm = TwoJointArm(GAME_ARM)
    accel = LoadedArm(arm, Loads(joint=JointLoad((0.1, -0.05), ((0.2, 0.01), (0.03, 0.1))))).component_dynamics().accel
    q, w = (0.4, 1.1), (0.5, -0.7)
    tau = np.array([0.3 + 0.1 + 0.2 * 0.5 + 0.01 * -0.7, -0.2 - 0.05 + 0.03 * 0.5 + 0.1 * -0.7])
    np.testing.assert_allclose(accel(*q, *w, 0.3, -0.2), arm.forward_dynamics(q, w, tau), rtol=1e-13)


@pytest.mark.parametrize("params, integrator", [(GAME_ARM, "rk4"), (TUTORIAL_ARM, "rk4"), (GAME_ARM, "gauss4")],
                         ids=["game-rk4", "tutorial-rk4", "game-gauss4"])
def test_curl_field_does_no_work(params, integrator):
    """v . B v = 0: a passive arm's energy with a strong curl field on holds exactly as without it,
    to the integrator's error, while the field visibly bends the motion."""
    arm = TwoJointArm(params)
    start, dt, steps = (0.3, 1.4, 3.0, -2.0), DRIFT_DT, DRIFT_STEPS
    free = Integrator(integrator, arm).run(start, (0.0, 0.0), dt, steps)
    curl = LoadedArm(arm, Loads(hand=CurlField(STRONG_CURL)))
    curled = Integrator(integrator, curl).run(start, (0.0, 0.0), dt, steps)
    e0 = float(arm.energy(start[:2], start[2:]))
    drift_free = np.max(np.abs(arm.energy(free[:, :2], free[:, 2:]) - e0)) / e0
    drift_curl = np.max(np.abs(arm.energy(curled[:, :2], curled[:, 2:]) - e0)) / e0
    assert drift_curl < DRIFT_TOLERANCE and drift_free < DRIFT_TOLERANCE, (drift_curl, drift_free)
    apart = np.max(np.linalg.norm(arm.hand(curled[:, :2]) - arm.hand(free[:, :2]), axis=-1))
    assert apart > 0.05  # the field acted: centimetres apart
    # A field that does work (a spring pulling the hand) changes the arm's own energy by far more.
    sprung = Integrator(integrator, LoadedArm(arm, Loads(hand=SpringField(40.0, (0.0, 0.3))))).run(
        start, (0.0, 0.0), dt, steps)
    assert np.max(np.abs(arm.energy(sprung[:, :2], sprung[:, 2:]) - e0)) / e0 > 1e-2


def test_no_load_is_the_arm_itself():
    arm = TwoJointArm(GAME_PLAY_ARM)
    assert loaded_arm(arm, None) is arm
    assert loaded_arm(arm, Loads()) is arm
    assert isinstance(loaded_arm(arm, Loads(hand=CurlField(1.0))), LoadedArm)


def test_standard_game_result_does_not_move():
    """The game with no perturbation: results pinned from the commit before loads existed (bit for bit)."""
    events, step, keys = [], 50, "dfjk"
    for i, start in enumerate(range(0, 5000, step)):
        events += [InputEvent(start, keys[i % 4], "down"), InputEvent(start + step // 2, keys[i % 4], "up")]
        if i % 50 == 49:
            events.append(InputEvent(start + step // 2, "space", "down"))
    session = GameSession(GameConfig(time_limit=20.0))
    session.play(events, 1234)
    assert [x.hex() for x in session.state] == [
        "0x1.be116ee580589p-1", "0x1.c7a92f22260cfp+0", "0x1.4dd9b49736ff0p-2", "-0x1.cd9878e368207p-2"]
    model = play_bot(GameConfig(time_limit=20.0, seed=3), "model")
    assert (model.result().hits, len(model.timeline)) == (18, 5083)
    # Version 0.3's own trig for the arm (physics.trig) moved this state by 2.2e-15 at most from the pin
    # taken with the C library's (0x1.5e45eb6859be3p+0, -0x1.6f2bf513505aap-3): the same hits and keys.
    assert [x.hex() for x in model.state] == [
        "0x1.5e45eb6859bedp+0", "0x1.83b541fb0a4f4p+0", "-0x1.6f2bf513505a6p-3", "-0x1.134f2fb4bb288p-1"]


def test_curl_sign_pushes_clockwise_of_the_motion():
    fx, fy = CurlField(2.0).force(0.0, 0.0, 1.0, 0.0, 0.0)
    assert (fx, fy) == (0.0, -2.0)  # moving along +x, pushed toward -y: clockwise
    assert math.isclose(np.dot((fx, fy), (1.0, 0.0)), 0.0)


def test_a_time_dependent_field_reads_the_clock():
    """F(x, v, t): the closures evaluate the field at clock.t, which the caller moves between steps."""

    class Pulse:
        def force(self, x, y, vx, vy, t):
            return (2.0, 0.0) if t >= 1.0 else (0.0, 0.0)

    arm = TwoJointArm(GAME_ARM)
    loads = Loads(hand=Pulse())
    accel = LoadedArm(arm, loads).component_dynamics().accel
    state = (0.5, 1.2, 0.1, -0.2)
    free = arm.forward_dynamics(state[:2], state[2:], (0.0, 0.0))
    np.testing.assert_allclose(accel(*state, 0.0, 0.0), free, rtol=1e-13)
    loads.clock.t = 1.5
    pushed = arm.forward_dynamics(state[:2], state[2:], hand_force_torque(arm, Pulse(), state[:2], state[2:], 1.5))
    np.testing.assert_allclose(accel(*state, 0.0, 0.0), pushed, rtol=1e-12)
    assert np.max(np.abs(pushed - free)) > 0.1


@pytest.mark.parametrize("integrator", ["rk4", "gauss4"])
def test_viscous_field_does_the_work_of_its_symmetric_part(integrator):
    """F = B v with Shadmehr & Mussa-Ivaldi's B: v . B v = v . sym(B) v is not zero, so the passive arm's
    energy changes, by exactly the work the field did (the power v . B v integrated along the motion)."""
    from armgame.lab.presets import PUBLISHED_VISCOUS_B

    arm = TwoJointArm(GAME_ARM)
    field = ViscousField(PUBLISHED_VISCOUS_B)
    start, dt, steps = (0.3, 1.4, 3.0, -2.0), 0.001, 300
    states = Integrator(integrator, LoadedArm(arm, Loads(hand=field))).run(start, (0.0, 0.0), dt, steps)
    energy = arm.energy(states[:, :2], states[:, 2:])
    v = arm.hand_velocity(states[:, :2], states[:, 2:])
    power = np.einsum("ni,ij,nj->n", v, np.asarray(PUBLISHED_VISCOUS_B), v)
    work = np.concatenate([[0.0], np.cumsum((power[1:] + power[:-1]) * dt / 2.0)])  # trapezoid: O(dt^2)
    change = energy - energy[0]
    assert np.max(np.abs(change)) > 10.0 * energy[0]  # it pumps the arm
    np.testing.assert_allclose(change, work, atol=WORK_TOLERANCE * np.max(np.abs(change)))
    # What docs/lab.md says this run measures: the start, the gain, and the trapezoid's error (one digit).
    off = float(np.max(np.abs(change - work)) / np.max(np.abs(change)))
    _doc_says(f"a passive arm started at {energy[0]:.1f} J gains {change[-1]:.0f} J in {steps * dt:.1f} s",
              f"to {off:.0e} of the change".replace("e-0", "e-"), f"(the trapezoid's error, the test allowing "
              f"{WORK_TOLERANCE:.0e}".replace("e-0", "e-"))
    # The antisymmetric part alone (a curl field) does none: the symmetric part does it all.
    b = np.asarray(PUBLISHED_VISCOUS_B)
    assert np.allclose(np.einsum("ni,ij,nj->n", v, (b - b.T) / 2.0, v), 0.0, atol=1e-12)


def test_channel_holds_the_hand_on_its_line_and_lets_it_run_along():
    """The channel's force is across the line only: zero on the line at rest or moving along it, a spring
    and a damper across it."""
    channel = ChannelField(2000.0, 50.0, (0.1, 0.5), (0.6, 0.8))
    assert channel.force(0.1 + 0.06, 0.5 + 0.08, 0.3, 0.4, 0.0) == pytest.approx((0.0, 0.0), abs=1e-12)
    fx, fy = channel.force(0.1 - 0.008, 0.5 + 0.006, 0.0, 0.0, 0.0)  # 1 cm to the left of the line, at rest
    assert (fx, fy) == pytest.approx((2000.0 * 0.01 * 0.8, -2000.0 * 0.01 * 0.6))
    fx, fy = channel.force(0.1, 0.5, -0.8, 0.6, 0.0)  # moving left across the line at 1 m/s
    assert (fx, fy) == pytest.approx((50.0 * 0.8, -50.0 * 0.6))
    assert channel.lateral(0.1, 0.5, -0.8, 0.6) == pytest.approx(-50.0)


def _doc_says(*phrases: str) -> None:
    doc = " ".join((Path(__file__).resolve().parent.parent / "docs" / "lab.md").read_text(encoding="utf-8").split())
    for phrase in phrases:
        assert phrase in doc, f"docs/lab.md should say {phrase!r}"


def test_the_docs_quote_these_tests():
    """docs/lab.md states these tests' tolerances as what they check: the text and the constants are one."""
    _doc_says(f"gives the same joint accelerations to {MUJOCO_TOLERANCE:.0e})".replace("e-0", "e-"),
              f"a passive arm's energy with b = {STRONG_CURL:g} N s/m on holds as well as with it off (relative "
              f"change below {DRIFT_TOLERANCE:.0e} over {DRIFT_DT * DRIFT_STEPS:g} s)".replace("e-0", "e-"))
