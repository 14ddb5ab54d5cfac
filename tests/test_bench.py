"""The benchmark's pieces: the MuJoCo model equals ours, the batch stepper equals the single-arm
integrator, the counters count, and ``armgame bench`` runs end to end."""

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from armgame.bench.measure import counting, step_torques
from armgame.bench.mjcf import build_model, load_mujoco, mass_matrix_and_bias
from armgame.physics import GAME_ARM, SCHEMES, TUTORIAL_ARM, Integrator, TwoJointArm
from armgame.physics.batch import BatchRK4
from armgame.scenes import SCENES

ROOT = Path(__file__).resolve().parent.parent
ARMS = {
    "game": GAME_ARM,
    "tutorial": TUTORIAL_ARM,
    "damped tutorial": TUTORIAL_ARM.replace(damping1=0.3, damping2=0.1),
    "damped game": GAME_ARM.replace(damping1=0.2, damping2=0.4),
}


@pytest.mark.parametrize("arm", list(ARMS))
def test_mujoco_model_matrices_equal_ours(arm):
    mujoco = load_mujoco()
    if mujoco is None:
        pytest.skip("mujoco not installed (the optional bench extra)")
    params = ARMS[arm]
    model = TwoJointArm(params)
    rng = np.random.default_rng(1)
    for q1, q2, w1, w2 in rng.uniform(-4, 4, (5, 4)):
        full, bias = mass_matrix_and_bias(mujoco, params, (q1, q2), (w1, w2))
        np.testing.assert_allclose(full, model.mass_matrix([q1, q2]), rtol=1e-12, atol=1e-14)
        ours = model.coriolis([q1, q2], [w1, w2]) + model.gravity([q1, q2])
        np.testing.assert_allclose(bias, ours, rtol=1e-11, atol=1e-12)


def test_mujoco_rk4_steps_like_ours():
    mujoco = load_mujoco()
    if mujoco is None:
        pytest.skip("mujoco not installed (the optional bench extra)")
    params = ARMS["damped tutorial"]
    mj_model, data = build_model(mujoco, params, 0.002, "RK4")
    state = (0.3, 1.2, 2.0, -1.0)
    data.qpos[:], data.qvel[:] = state[:2], state[2:]
    data.qfrc_applied[:] = (0.4, -0.2)
    mujoco.mj_step(mj_model, data, nstep=100)
    ours = Integrator("rk4", TwoJointArm(params)).run(state, (0.4, -0.2), 0.002, 100)[-1]
    np.testing.assert_allclose([*data.qpos, *data.qvel], ours, rtol=1e-10, atol=1e-11)


@pytest.mark.parametrize("arm", list(ARMS))
def test_batch_rk4_agrees_with_single_arm_rk4(arm):
    model = TwoJointArm(ARMS[arm])
    rng = np.random.default_rng(2)
    states = rng.uniform(-3, 3, (7, 4))
    torques = rng.uniform(-1, 1, (7, 2))
    batch = BatchRK4(model, states, torques)
    batch.run(0.002, 200)
    single = Integrator("rk4", model)
    for state, torque, got in zip(states, torques, batch.states, strict=True):
        s = tuple(state)
        for _ in range(200):
            s = single.step(s, torque, 0.002)
        np.testing.assert_allclose(got, s, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize(("dt", "speed"), [(0.001, 3.0), (0.05, 20.0)], ids=["series", "full-trig"])
def test_batch_elbow_trig_by_angle_addition_is_exact_to_round_off(dt, speed):
    """Small increments take the series; large ones (here up to 0.5 rad) fall back to sin and cos."""
    model = TwoJointArm(GAME_ARM)
    rng = np.random.default_rng(5)
    states = np.column_stack([rng.uniform(-3, 3, (9, 2)), rng.uniform(-speed, speed, (9, 2))])
    batch = BatchRK4(model, states, (0.4, -0.3))
    batch.step(dt)
    single = Integrator("rk4", model)
    expected = [single.step(tuple(x), (0.4, -0.3), dt) for x in states]
    np.testing.assert_allclose(batch.states, expected, rtol=1e-13, atol=1e-13)


def test_batch_threads_give_the_same_result_as_one_thread():
    model = TwoJointArm(GAME_ARM)
    rng = np.random.default_rng(4)
    states, torques = rng.uniform(-3, 3, (101, 4)), rng.uniform(-1, 1, (101, 2))
    one, two = BatchRK4(model, states, torques), BatchRK4(model, states, torques)
    one.run(0.001, 20)
    two.run(0.001, 20, threads=2)
    np.testing.assert_array_equal(one.states, two.states)


def test_batch_rejects_a_badly_shaped_state():
    with pytest.raises(ValueError, match=r"\(n, 4\)"):
        BatchRK4(TwoJointArm(GAME_ARM), np.zeros((3, 3)))


def test_rhs_counters_count_evaluations_per_step():
    model = TwoJointArm(GAME_ARM)
    expected = {"euler": 1, "symplectic-euler": 1, "rk4": 4}
    for name, per_step in expected.items():
        dyn, count = counting(model.component_dynamics("float"))
        step = SCHEMES[name].build(dyn)
        step(0.1, 0.2, 0.3, 0.4, 0.0, 0.0, 0.01)
        assert count[0] == per_step, name
    # The counting copy leaves the model's own closures untouched.
    assert model.component_dynamics("float").accel.__name__.startswith("accel")


def test_step_torques_switch_on_the_nearest_step():
    segments = ((0.0, (1.0, 0.0)), (0.2, (0.0, -1.0)), (0.5, (0.0, 0.0)))
    torques = step_torques(segments, 0.1, 7)
    assert torques == [(1.0, 0.0)] * 2 + [(0.0, -1.0)] * 3 + [(0.0, 0.0)] * 2


def test_game_scene_is_deterministic_and_switches_on_the_bench_grid():
    game = SCENES["game"]
    assert game.model.params == GAME_ARM
    assert game.initial == (math.pi / 4, math.pi / 2, 0.0, 0.0)
    assert game.duration == 60.0 and game.free_after == 60.0
    for start, (t1, t2) in game.torque_segments:
        assert abs(start / 0.2 - round(start / 0.2)) < 1e-9
        assert all(t == 0.0 or 0.5 <= abs(t) <= 1.0 for t in (t1, t2))
    from armgame.scenes import game_torque_script

    assert game_torque_script() == game.torque_segments


def test_bench_quick_json_runs_end_to_end(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = tmp_path / "out"
    proc = subprocess.run(
        [sys.executable, "-m", "armgame", "bench", "--quick", "--json", "--cases", "stiff",
         "--integrators", "rk4,euler", "--out", str(out)],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    payload = json.loads(proc.stdout)
    ours = [r for r in payload["rows"] if r["family"] == "armgame"]
    assert {r["method"] for r in ours} == {"rk4", "euler"}
    assert all(r["case"] == "stiff" for r in payload["rows"])
    assert {"tutorial", "scipy"} <= {r["family"] for r in payload["rows"]}
    assert payload["bars"]["rk4_step_us"] > 0 and payload["bars"]["batch_rate"] > 0
    assert payload["machine"]["numpy"] == np.__version__
    assert (out / "bench.csv").read_text().startswith("case,method,family")
    assert (out / "work_precision.png").stat().st_size > 0 and (out / "convergence.png").stat().st_size > 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # nothing else written, no MUJOCO_LOG.TXT


def test_bench_refuses_an_unknown_case_in_one_line(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, "-m", "armgame", "bench", "--cases", "nope"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2
    assert "unknown case 'nope'" in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
