"""Issue 41: coordinate frames (a block's posture, the joint-space field, the adaptive bot's frame), probes without
vision (hidden cursor, endpoint feedback, the bot seeing only what it is shown), fields mixed trial by trial, and
the two new fits recovering known parameters."""

import json
import math
from collections import Counter
from dataclasses import replace

import numpy as np
import pytest

from armgame.game.bots import Autopilot
from armgame.lab.analysis import trial_rows
from armgame.lab.bots import LearningRates, make_lab_bot
from armgame.lab.designs import frames_summary, hand_twin, jacobian, joint_twin
from armgame.lab.metrics import read_trials_csv, write_trials_csv
from armgame.lab.perturbations import Perturbation
from armgame.lab.presets import FRAMES_TEST_POSTURE, VISCOUS_B, preset
from armgame.lab.protocol import Block, Protocol
from armgame.lab.protocol_file import load_protocol, protocol_as_dict, protocol_from_dict
from armgame.lab.record import LabTask
from armgame.lab.session import LabSession, lab_config
from armgame.lab.trialfit import (
    fit_generalization,
    fit_state_space,
    simulate_generalization,
    simulate_state_space,
)

L1, L2 = 0.34, 0.46
VISCOUS = Perturbation.make("viscous", b11=VISCOUS_B[0][0], b12=VISCOUS_B[0][1], b21=VISCOUS_B[1][0],
                            b22=VISCOUS_B[1][1])


def _run(protocol: Protocol, bot, seed: int = 10) -> LabSession:
    session = LabSession(lab_config(protocol, seed), protocol)
    Autopilot(session, bot).play()
    return session


# ------------------------------------------------------------------------------------ protocols
@pytest.mark.parametrize("name", ["frames", "rotation-generalization", "random-fields"])
def test_the_designs_presets_round_trip(name):
    p = preset(name)
    assert protocol_from_dict(json.loads(json.dumps(protocol_as_dict(p)))) == p


def test_a_file_sets_posture_feedback_and_mix_and_bad_values_are_refused(tmp_path):
    path = tmp_path / "d.toml"
    path.write_text("""
targets = 4
[[blocks]]
name = "baseline"
trials = 8
catch_trials = 2
probe_feedback = "none"
[[blocks]]
name = "mixed"
trials = 16
perturbation = "joint_viscous"
matrix = [[0.1, -0.2], [0.3, 0.05]]
mix = ["on", "off", "opposite"]
feedback = "endpoint"
home_shoulder_deg = 100
home_elbow_deg = 80
""")
    p = load_protocol(path)
    mixed = p.blocks[1]
    assert mixed.home_posture_deg == (100.0, 80.0) and mixed.feedback == "endpoint"
    assert mixed.mix == ("on", "off", "opposite") and mixed.perturbation.joint_matrix == ((0.1, -0.2), (0.3, 0.05))
    assert protocol_from_dict(json.loads(json.dumps(protocol_as_dict(p)))) == p
    for bad, words in (('feedback = "dim"', "feedback"), ('mix = ["on", "sometimes"]', "mix"),
                       ("home_shoulder_deg = 10", "both")):
        path.write_text(f"[[blocks]]\nname = \"b\"\ntrials = 8\nperturbation = \"curl\"\nb = 2.0\n{bad}\n")
        with pytest.raises(Exception, match=words):
            load_protocol(path)
    path.write_text("[[blocks]]\nname = \"b\"\ntrials = 16\ncatch_trials = 2\n")  # nothing to catch, full vision
    with pytest.raises(Exception, match="probe_feedback"):
        load_protocol(path)


def test_mixed_fields_are_balanced_per_direction_seeded_and_in_the_replay():
    p = preset("random-fields")
    plans = LabSession(lab_config(p, 3), p).plans
    mixed = [plan for plan in plans if plan.block == 1]
    per = Counter((plan.target, plan.active.kind) for plan in mixed)
    assert {per[(t, "curl")] for t in range(8)} == {per[(t, "none")] for t in range(8)} == {12}
    assert plans == LabSession(lab_config(p, 3), p).plans
    assert [plan.active for plan in plans] != [plan.active for plan in LabSession(lab_config(p, 4), p).plans]
    short = replace(p, blocks=(replace(p.blocks[1], trials=16),), targets=8)
    session = _run(short, make_lab_bot("model"))
    task = LabTask.of(session)
    assert task.fields == tuple(plan.active.label() for plan in session.plans)
    back = LabTask.from_dict(json.loads(json.dumps(task.as_dict())), session.config, session.steps)
    assert back.fields == task.fields
    assert back.verify(session.config, session.timeline, session.result())[0]
    forged = replace(back, fields=tuple(reversed(task.fields)))
    assert not forged.verify(session.config, session.timeline, session.result())[0]


# ------------------------------------------------------------------------------------------ frames
def test_a_joint_field_is_its_hand_twin_where_it_was_learned_and_turns_with_the_shoulder():
    qa = tuple(math.radians(a) for a in (45.0, 90.0))
    qb = tuple(math.radians(a) for a in FRAMES_TEST_POSTURE)
    b = np.asarray(VISCOUS_B)
    w = joint_twin(VISCOUS_B, L1, L2, qa)
    # The physics: the joint load's torque W qdot equals J^T B v at the training posture, for any joint velocity.
    load = Perturbation.make("joint_viscous", w11=w[0, 0], w12=w[0, 1], w21=w[1, 0], w22=w[1, 1]).loads((0.0, 0.0))
    assert load is not None and load.hand is None
    qdot = np.array([0.7, -1.3])
    j = jacobian(L1, L2, *qa)
    assert np.allclose(np.asarray(load.joint.viscosity) @ qdot, j.T @ b @ (j @ qdot), rtol=1e-12, atol=1e-15)
    # At the test posture (the shoulder turned 90 deg) the joint field is R B R^T at the hand: nearly -B here.
    rot = np.array([[0.0, -1.0], [1.0, 0.0]])
    assert np.allclose(hand_twin(w, L1, L2, qb), rot @ b @ rot.T, atol=1e-12)
    assert np.allclose(rot @ b @ rot.T, -b, atol=0.25)


def _frames_protocol() -> Protocol:
    home_b = FRAMES_TEST_POSTURE
    return Protocol("frames-short", (
        Block("baseline 2", 12, channel_trials=4, home_posture_deg=home_b),
        Block("exposure", 16, VISCOUS),
        Block("test", 4, VISCOUS, channel_trials=4, home_posture_deg=home_b),
    ), targets=4)


@pytest.mark.parametrize("frame", ["hand", "joint"])
def test_the_frames_test_reads_the_frame_the_bot_learned_in(frame):
    """A quick learner (single rate 0.6) trained at one posture, channel trials at the other: each frame's index
    is positive for the frame it holds the field in and negative for the other (the two nearly opposite here)."""
    bot = make_lab_bot("adaptive", LearningRates(0.0, 0.999, 0.0, 0.6), frame=frame)
    assert frame in bot.frame_words()
    session = _run(_frames_protocol(), bot)
    assert session.finished and session.home_q == tuple(math.radians(a) for a in FRAMES_TEST_POSTURE)
    tests = [o for o in session.outcomes if o.plan.block == 2]
    assert {o.plan.home for o in tests} == {session.home} and session.plans[12].home != session.home
    (summary,) = frames_summary(session, trial_rows(session))
    assert summary["reads_as"] == frame and summary["less_baseline"]
    ours, other = (summary["hand"], summary["joint"]) if frame == "hand" else (summary["joint"], summary["hand"])
    assert ours > 0.3 and other < -0.2


# ------------------------------------------------------------------------------------ no vision
def _rotation(feedback: str) -> Protocol:
    return Protocol("nv", (Block("exposure", 8, Perturbation.make("rotation", angle=30.0), feedback=feedback),),
                    targets=4)


def test_without_vision_the_cursor_hides_the_reach_ends_where_it_stops_and_the_bot_learns_nothing_seen():
    seen = {}
    for feedback in ("endpoint", "none"):
        bot = make_lab_bot("adaptive")
        seen[feedback] = (_run(_rotation(feedback), bot), bot)
    none_session, none_bot = seen["none"]
    assert none_session.finished and none_bot.rotation_estimate == 0.0  # never saw an error
    assert seen["endpoint"][1].rotation_estimate > 0.05  # the endpoint showed it the rotation
    assert all(o.plan.feedback == "none" for o in none_session.outcomes)
    # Without a cursor the rotated reach does not home in: it ends where the hand stopped, off the target.
    assert sum(o.hit for o in none_session.outcomes) < len(none_session.outcomes)
    assert max(o.end_step - o.go_step for o in none_session.outcomes) * none_session.config.dt < 3.0
    rows = trial_rows(none_session)
    assert {r["feedback"] for r in rows} == {"none"}


def test_the_session_hides_the_cursor_only_in_the_reach():
    p = _rotation("none")
    session = LabSession(lab_config(p, 10), p)
    assert session.cursor_visible
    while session.phase != "reach":
        session.advance(1)
    assert not session.cursor_visible


def test_an_old_table_without_the_new_columns_reads_with_full_feedback(tmp_path):
    rows = trial_rows(_run(_rotation("full"), make_lab_bot("model")))
    path = tmp_path / "t.csv"
    write_trials_csv(path, rows)
    lines = path.read_text().splitlines()
    keep = len(lines[0].split(",")) - 6  # the four issue-41 columns and the home posture's two are the last
    path.write_text("\n".join(",".join(line.split(",")[:keep]) for line in lines) + "\n")
    back = read_trials_csv(path)
    assert {r["feedback"] for r in back} == {"full"} and all(math.isnan(r["disturbance"]) for r in back)
    assert all(math.isnan(r["home_shoulder_deg"]) and math.isnan(r["home_elbow_deg"]) for r in back)


def test_every_trial_names_its_home_posture():
    """A frames run trains at one posture and tests at another: each row says which, as its block's posture."""
    protocol = _frames_protocol()
    session = _run(protocol, make_lab_bot("model"))
    rows = trial_rows(session)
    postures = {(r["home_shoulder_deg"], r["home_elbow_deg"]) for r in rows}
    assert postures == {tuple(map(float, b.posture_of(protocol))) for b in protocol.blocks} and len(postures) == 2
    for r, o in zip(rows, session.outcomes, strict=True):
        assert (r["home_shoulder_deg"], r["home_elbow_deg"]) == protocol.blocks[o.plan.block].posture_of(protocol)
    assert (FRAMES_TEST_POSTURE[0], FRAMES_TEST_POSTURE[1]) in postures


# ------------------------------------------------------------------------------------------- fits
def test_the_trial_by_trial_fit_recovers_a_generalization_function_with_an_opposite_lobe():
    truth_c = [0.2, 0.1, 0.02, 0.0, 0.06]
    rng = np.random.default_rng(7)
    target = np.concatenate([rng.permutation(8) for _ in range(50)])
    f = rng.integers(0, 2, target.size).astype(float)
    y = simulate_generalization(rng, target, 8, f, 0.9, truth_c, -0.02, 0.002)
    fit = fit_generalization(target, 8, f, y)
    truth = {"a": 0.9, "k": -0.02, **{f"c({a})": c for a, c in zip((0, 45, 90, 135, 180), truth_c, strict=True)}}
    for name, value in truth.items():
        low, high = fit.intervals[name]
        assert low <= value <= high, (name, value, fit.intervals[name])
    assert fit.intervals["c(180)"][0] > 0.0  # the opposite lobe, found
    assert abs(fit.values["c(45)"] / fit.values["c(0)"] - 0.5) < 0.15


def test_the_state_space_fit_separates_process_from_output_noise():
    f = np.concatenate([np.zeros(20), np.ones(200), -np.ones(10), np.zeros(120)])
    clamp = np.zeros(f.size, dtype=bool)
    truth = {"A": 0.97, "B": 0.12, "k": -0.02, "Q": 0.05 ** 2, "R": 0.001 ** 2}
    y = simulate_state_space(np.random.default_rng(11), f, clamp, truth["A"], truth["B"], truth["k"], truth["Q"],
                             truth["R"])
    fit = fit_state_space(f, clamp, y)
    for name, value in truth.items():
        low, high = fit.intervals[name]
        assert low <= value <= high, (name, value, fit.intervals[name])
    assert 0.5 < fit.values["Q"] / truth["Q"] < 2.0


@pytest.mark.parametrize("kind", ["error", "index"])
def test_a_state_space_fit_whose_process_noise_reaches_zero_reports_an_unbounded_interval(kind):
    """No process noise at all (a deterministic learner, or a bot's run): Q's likelihood never falls off towards 0,
    its Wald interval's ends run past any float, and the fit once stopped on exp's OverflowError (a frames run's
    replay, spontaneous --fit-on index). The interval is reported as unbounded instead, and JSON keeps it as null."""
    f = np.concatenate([np.zeros(8), np.ones(24), np.zeros(8)])
    clamp = np.zeros(f.size, dtype=bool)
    clamp[:: 2 if kind == "index" else 4] = True
    y = simulate_state_space(np.random.default_rng(0), f, clamp, 0.95, 0.1, 1.0, 0.0, 0.01, kind)
    fit = fit_state_space(f, clamp, y, kind)
    low, high = fit.intervals["Q"]
    assert low == 0.0 and math.isinf(high) and fit.values["Q"] < 1e-3
    assert any(line.startswith("  Q = ") and "to unbounded)" in line for line in fit.lines("cm", 100.0))
    parameters = json.loads(json.dumps(fit.as_dict("cm"), allow_nan=False))["parameters"]
    assert parameters["Q"]["ci95_high"] is None


def test_the_docs_account_of_the_bots_random_fields_run_is_its_learners_and_protocols():
    """docs/lab.md says why the bot's random-fields run shows no generalization function: its fast process
    forgets 41% a trial, a direction comes back about 8 trials later, its slow process learns 2% an error."""
    from pathlib import Path

    from armgame.lab.learner import TwoRateLearner
    from armgame.lab.presets import preset

    text = " ".join((Path(__file__).resolve().parent.parent / "docs" / "lab.md").read_text(encoding="utf-8").split())
    learner = TwoRateLearner()
    forgets, learns = round(100 * (1 - learner.retention_fast)), round(100 * learner.rate_slow)
    directions = preset("random-fields").targets  # each direction once a cycle: back after about that many
    assert f"fast process forgets {forgets}% a trial" in text and f"learns {learns}% of an error" in text
    assert f"comes about {directions} trials later" in text
