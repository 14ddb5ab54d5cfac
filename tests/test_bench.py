"""The benchmark's pieces: the MuJoCo model equals ours, the batch stepper equals the single-arm
integrator, the counters count, and ``armgame bench`` runs end to end."""

import json
import math
import os

import numpy as np
import pytest

from armgame.bench.measure import counting, step_torques
from armgame.bench.mjcf import build_model, load_mujoco, mass_matrix_and_bias
from armgame.physics import GAME_ARM, SCHEMES, TUTORIAL_ARM, Integrator, TwoJointArm
from armgame.physics.batch import BatchRK4
from armgame.scenes import SCENES

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


@pytest.mark.slow  # the benchmark's smoke run (about 5 s): CI runs it after the suite; figures read on a slide below
def test_bench_quick_json_runs_end_to_end(tmp_path, monkeypatch, capsys, bench_slides):
    """In-process (the subprocess proved only that Python starts): the real command, parser to JSON,
    and its one-case figures (the smallest grid, two cells) read on a slide."""
    from armgame.cli import main

    monkeypatch.chdir(tmp_path)
    out = tmp_path / "out"
    code = main(["bench", "--quick", "--json", "--cases", "stiff", "--integrators", "rk4,euler", "--out", str(out)])
    assert code in (0, None)
    payload = json.loads(capsys.readouterr().out)
    ours = [r for r in payload["rows"] if r["family"] == "armgame"]
    assert {r["method"] for r in ours} == {"rk4", "euler"}
    assert all(r["case"] == "stiff" for r in payload["rows"])
    assert {"tutorial", "scipy"} <= {r["family"] for r in payload["rows"]}
    assert payload["bars"]["rk4_step_us"] > 0 and payload["bars"]["batch_rate"] > 0
    # The compiled RK4's rows (what the game runs): the Python step's states bit for bit, so its errors.
    from armgame.bench import compiled

    built = [r for r in payload["rows"] if r["family"] == "compiled"]
    if compiled.available() or os.environ.get("ARMGAME_REQUIRE_COMPILED"):
        python_rows = {r["setting"]: r for r in ours if r["method"] == "rk4"}
        assert [r["setting"] for r in built] == list(python_rows) and payload["bars"]["game_step_us"] > 0
        for r in built:
            twin = python_rows[r["setting"]]
            assert (r["method"], r["hand_error"], r["energy_drift"], r["blew_up"]) == (
                "rk4 (compiled)", twin["hand_error"], twin["energy_drift"], twin["blew_up"])
    else:
        assert built == [] and any("not built" in note for note in payload["notes"])
    assert payload["machine"]["numpy"] == np.__version__
    assert (out / "bench.csv").read_text().startswith("case,method,family")
    assert (out / "work_precision.png").stat().st_size > 0 and (out / "convergence.png").stat().st_size > 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # nothing else written, no MUJOCO_LOG.TXT
    assert len(bench_slides) == 2
    _assert_bench_slides(bench_slides, ["stiff"])


def test_bench_refuses_an_unknown_case_in_one_line(tmp_path, monkeypatch, capsys):
    from armgame.cli import main

    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exc:  # argparse's own exit, as `armgame bench --cases nope` gives
        main(["bench", "--cases", "nope"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "unknown case 'nope'" in err and len(err.strip().splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------- figures and the printed report
def _synthetic_rows():
    """Rows shaped like a full run's: five cases, ours at eight steps, three peers at tolerances."""
    from armgame.bench.measure import STEPS, Row, step_label

    rows = []
    for c, case in enumerate(("passive", "propeller", "upright", "stiff", "game")):
        for name, order in (("euler", 1), ("symplectic-euler", 1), ("rk4", 4), ("midpoint", 2), ("gauss4", 4)):
            for dt in STEPS:
                error = min(0.5, 10.0 ** c * dt**order)
                rows.append(Row(case, name, "armgame", step_label(dt), dt, None, 2e-4 / dt * 1e-3, 1 / dt,
                                error, error, blew_up=(case == "stiff" and dt > 0.02)))
        for method, family, cost in (("odeint (tutorial)", "tutorial", 0.02), ("solve_ivp RK45", "scipy", 0.008),
                                     ("mujoco rk4", "mujoco", 0.002)):
            for tol in (1e-6, 1e-8, 1e-10):
                rows.append(Row(case, method, family, f"tol={tol:g}", None, tol, cost * (1 - math.log10(tol) / 10),
                                500.0, tol, tol, False))
    return rows


@pytest.fixture
def bench_slides(monkeypatch):
    from armgame.bench import figures

    captured, real = [], figures.save

    def keep(fig, path):
        captured.append(fig)
        return real(fig, path)

    monkeypatch.setattr(figures, "save", keep)
    return captured


def _assert_bench_slides(slides, cases):
    from figure_checks import assert_reads_on_a_slide

    for fig in slides:
        assert_reads_on_a_slide(fig)
        panels = [ax for ax in fig.get_axes() if ax.axison]
        assert [ax.get_title() for ax in panels] == cases
        assert len(fig.get_axes()) == len(panels) + 1  # and one cell for the legend
        colours = {}  # a method keeps its colour in every panel
        for ax in panels:
            for line in ax.get_lines():
                if not line.get_label().startswith("_"):
                    assert colours.setdefault(line.get_label(), line.get_color()) == line.get_color()
    legend = [t.get_text() for ax in slides[1].get_axes() if ax.get_legend() for t in ax.get_legend().texts]
    assert legend[-3:] == ["slope 1 (reference)", "slope 2 (reference)", "slope 4 (reference)"]


def test_bench_figures_read_on_a_slide(tmp_path, monkeypatch):
    """The fullest grid, five cases and every method, laid out as saving lays it out (not painted
    into a PNG: test_bench_quick_json_runs_end_to_end saves a real run's one-case figures and checks
    them on a slide too)."""
    from armgame.bench import figures

    slides = []
    monkeypatch.setattr(figures, "save", lambda fig, path: slides.append(fig))
    rows = _synthetic_rows()
    figures.work_precision(rows, tmp_path / "wp.png")
    figures.convergence(rows, tmp_path / "conv.png")
    assert len(slides) == 2
    _assert_bench_slides(slides, ["passive", "propeller", "upright", "stiff", "game"])


def test_the_slide_check_catches_a_legend_on_the_data_and_overlapping_labels():
    from figure_checks import assert_reads_on_a_slide

    from armgame import plotstyle

    with plotstyle.slide_style():
        fig = plotstyle.slide_figure()
        ax = fig.subplots()
        ax.plot([0, 1], [0, 1], label="a line")
        ax.legend(loc="upper left")
    with pytest.raises(AssertionError, match="legend on the data"):
        assert_reads_on_a_slide(fig)
    ax.get_legend().remove()
    ax.text(0.5, 0.5, "slope 1")
    ax.text(0.5, 0.5, "slope 2")
    with pytest.raises(AssertionError, match="overlaps"):
        assert_reads_on_a_slide(fig)
    ax.texts[-1].remove()
    ax.set_xlabel("tiny", fontsize=6)
    with pytest.raises(AssertionError):
        assert_reads_on_a_slide(fig)


def test_text_report_prints_the_ratios_and_the_machine():
    from armgame.bench.report import text_report
    from armgame.bench.run import Result

    bars = {"odeint_ratio": 17.4, "odeint_detail": "rk4 dt=1/250", "rk4_step_us": 2.5,
            "rk4_numpy_single_step_us": 9.0, "mujoco_rk4_step_us": 7.0, "mujoco_rk4_c_loop_step_us": 6.5,
            "mujoco_ratio": 2.8, "mujoco_c_loop_ratio": 2.6, "batch_rate": 10.3e6, "batch_threads": 1,
            "batch_rate_1_thread": 10.3e6, "batch_rate_2_thread": 7.0e6, "batch_rate_integrator_numpy": 6.7e6}
    machine = {"cpu": "Intel(R) Xeon(R) CPU @ 2.20GHz", "cores": "2", "system": "Linux", "python": "3.11.7",
               "numpy": "2.4.6", "scipy": "1.17.1", "mujoco": "4.0.0", "matplotlib": "3.11.2", "load": "3.1 2.0 1.5"}
    text = text_report(Result([], bars, {}, machine, [], 12.0))
    assert "17x faster (MISSES the 20x bar)" in text
    assert "stepped from Python -> 2.8x (meets the 2.5x bar)" in text
    assert "10.3 M arm-steps/s with 1 thread (meets the 10 M bar) [1 thread 10.3 M, 2 threads 7.0 M" in text
    assert "machine: Intel(R) Xeon(R) CPU @ 2.20GHz, 2 cores, Linux; load average 3.1 2.0 1.5" in text
    assert "versions: python 3.11.7, numpy 2.4.6, scipy 1.17.1, mujoco 4.0.0" in text
    # Compiled, the bars are the game's loop's, against the goals; the Python step's beside them.
    bars |= {"odeint_ratio": 310.0, "odeint_ratio_python": 16.0, "odeint_compiled": True, "game_step_us": 0.11,
             "rk4_c_step_us": 0.1, "mujoco_ratio": 52.0, "mujoco_c_loop_ratio": 45.0, "mujoco_ratio_python": 2.8,
             "mujoco_c_loop_ratio_python": 2.6}
    text = text_report(Result([], bars, {}, machine, [], 12.0))
    assert "310x faster (meets the 300x bar); the Python step 16x" in text
    assert "the game's compiled loop 0.110 us (muscles and hit test included)" in text
    assert "the game's loop 45.0x faster (meets the 40x bar)" in text
