"""The centre-out task (armgame/lab/): protocols and their files, the trial schedule, the session's rules,
perturbations per trial, determinism, and lab replays that verify."""

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from armgame.errors import UserError
from armgame.game.bots import Autopilot
from armgame.game.session import InputEvent
from armgame.lab.bots import make_lab_bot
from armgame.lab.perturbations import Perturbation, joint_space, mirror, rotation
from armgame.lab.presets import CURL_B, PRESETS, VISCOUS_B, preset
from armgame.lab.protocol import Block, Protocol, with_catch_trials
from armgame.lab.protocol_file import load_protocol, protocol_as_dict, protocol_from_dict
from armgame.lab.record import LabTask
from armgame.lab.session import LabSession, lab_config, schedule
from armgame.records.replay import Replay, now_iso
from armgame.records.scores import ScoreTable


def short(perturbation: Perturbation, trials=(4, 8, 4), **options) -> Protocol:
    kinds = (Perturbation(), perturbation, Perturbation())
    names = ("baseline", "exposure", "washout")
    return Protocol("short", tuple(Block(n, t, k) for n, t, k in zip(names, trials, kinds, strict=True)), **options)


def bot_run(protocol: Protocol, bot: str = "model", seed: int = 3):
    session = LabSession(lab_config(protocol, seed), protocol)
    player = make_lab_bot(bot)
    Autopilot(session, player).play()
    return session, player


def perpendicular(session: LabSession, outcome) -> float:
    """The signed peak distance from the home-target line (+ = counter-clockwise side)."""
    hx, hy = session.home
    tx, ty = outcome.plan.position
    ux, uy = (tx - hx) / math.hypot(tx - hx, ty - hy), (ty - hy) / math.hypot(tx - hx, ty - hy)
    d = (np.array(outcome.xs) - hx) * -uy + (np.array(outcome.ys) - hy) * ux
    return float(d[np.argmax(np.abs(d))])


# ------------------------------------------------------------------ protocols
@pytest.mark.parametrize("name", PRESETS)
def test_presets_round_trip_through_plain_data(name):
    p = preset(name)
    assert protocol_from_dict(json.loads(json.dumps(protocol_as_dict(p)))) == p
    if name in ("savings", "spontaneous", "generalization"):
        assert p.blocks[1].perturbation == Perturbation.make("curl", b=CURL_B)
        return
    if name in ("frames", "rotation-generalization", "random-fields"):  # issue 41's: tests/test_lab_designs.py
        return
    assert [b.name for b in p.blocks] == ["baseline", "exposure", "washout"]
    assert p.blocks[1].perturbation.kind == {"null": "none", "lesson": "curl"}.get(name, name)


def test_toml_protocol_file(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text("""
name = "class A"
targets = 4
distance = 0.12
timeout = 2.5

[[blocks]]
name = "baseline"
trials = 8

[[blocks]]
name = "exposure"
trials = 20
perturbation = "curl"
b = -1.5
catch_trials = 3

[[blocks]]
name = "washout"
trials = 8
""")
    p = load_protocol(path)
    assert (p.name, p.targets, p.distance, p.timeout, p.trials) == ("class A", 4, 0.12, 2.5, 36)
    assert p.blocks[1].perturbation == Perturbation.make("curl", b=-1.5)
    assert p.blocks[1].catch_trials == 3
    assert p.blocks[0].instruction.startswith("Reach straight")


@pytest.mark.parametrize("text, message", [
    ("blocks = []", "blocks must be a list of 1 to 20 blocks"),
    ("distance = 5\n[[blocks]]\ntrials = 3", "distance must be a finite number from 0.01 to 0.3, got 5.0"),
    ("colour = 1\n[[blocks]]\ntrials = 3", "has unknown field(s) colour"),
    ("[[blocks]]\ntrials = 0", "blocks[0].trials must be from 1 to 2000, got 0"),
    ("[[blocks]]\ntrials = 3\nperturbation = 'gravity'", "blocks[0].perturbation must be one of none, curl"),
    ("[[blocks]]\ntrials = 3\nperturbation = 'curl'\nangle = 3", "blocks[0] has unknown field(s) angle"),
    ("[[blocks]]\ntrials = 3\nperturbation = 'curl'\nb = 'x'", "blocks[0].b must be a number, got 'x'"),
    ("[[blocks]]\ntrials = 12\ncatch_trials = 2", "blocks[0].catch_trials: block 'block 1' has no perturbation"),
    ("[[blocks]]\ntrials = 9\nperturbation = 'curl'\ncatch_trials = 2", "catch_trials must be at most"),
    ("delay_min = 2.0\n[[blocks]]\ntrials = 3", "delay_min (2 s) must not exceed delay_max (1 s)"),
    ("[[blocks]]\ntrials = 1500\n[[blocks]]\ntrials = 1500", "more than 2000"),
    ("[[blocks]\ntrials = 3", "not valid TOML"),
    ("home_elbow_deg = 1.0\n[[blocks]]\ntrials = 3", "home_elbow_deg must be a finite number from 5 to 175"),
    (f"distance = 1{'0' * 400}\n[[blocks]]\ntrials = 3", "distance must be a finite number from 0.01 to 0.3, got inf"),
    (f"[[blocks]]\ntrials = 3\nperturbation = 'curl'\nb = -1{'0' * 400}", "blocks[0].b must be a finite number "
                                                                       "from -50 to 50, got -inf"),
])
def test_bad_protocol_files_get_one_line_naming_the_key(tmp_path, text, message):
    path = tmp_path / "p.toml"
    path.write_text(text)
    with pytest.raises(UserError) as err:
        load_protocol(path)
    assert message in str(err.value) and "\n" not in str(err.value) and str(path) in str(err.value)


def test_hostile_protocol_files(tmp_path):
    big = tmp_path / "big.toml"
    big.write_bytes(b"#" * (300 * 1024))
    binary = tmp_path / "bin.toml"
    binary.write_bytes(b"\xff\xfe\x00")
    for path, message in ((big, "too large"), (binary, "not a text file"), (tmp_path, "is a folder"),
                          (tmp_path / "none.toml", "no such protocol file")):
        with pytest.raises(UserError, match=message):
            load_protocol(path)


def test_unreachable_targets_are_refused():
    p = short(Perturbation(), distance=0.3, home_posture_deg=(45.0, 10.0))
    with pytest.raises(UserError, match="out of reach"):
        LabSession(lab_config(p, 0), p)


# ------------------------------------------------------------------- schedule
def test_schedule_cycles_targets_and_draws_delays_and_catch_trials():
    # The placement replays recorded before issue 29 ran (the balanced one: tests/test_lab_probes.py).
    p = replace(with_catch_trials(preset("curl"), 6), probe_schedule="random")
    config = lab_config(p, 5)
    plans = schedule(p, 5, config.dt, (0.0, 0.5))
    assert len(plans) == p.trials == 120
    start = 0
    for block in p.blocks:
        mine = plans[start:start + block.trials]
        for c in range(0, block.trials - block.trials % 8, 8):
            assert sorted(t.target for t in mine[c:c + 8]) == list(range(8))
        catch = [t.index - start for t in mine if t.catch]
        assert len(catch) == block.catch_trials and all(i >= 8 for i in catch)
        start += block.trials
    delays = [t.delay_steps * config.dt for t in plans]
    assert 0.5 - config.dt <= min(delays) and max(delays) <= 1.0 + config.dt and np.std(delays) > 0.1
    assert schedule(p, 5, config.dt, (0.0, 0.5)) == plans
    assert schedule(p, 6, config.dt, (0.0, 0.5)) != plans
    assert [t.active.kind for t in plans[16:96]].count("none") == 6


def test_targets_lie_evenly_around_home():
    p = preset("null")
    positions = p.target_positions((0.1, 0.5))
    assert len(positions) == 8
    for i, (x, y) in enumerate(positions):
        assert math.isclose(math.hypot(x - 0.1, y - 0.5), 0.10)
        assert math.isclose(math.degrees(math.atan2(y - 0.5, x - 0.1)) % 360.0, 45.0 * i, abs_tol=1e-9)


# --------------------------------------------------------------- the session
def test_no_input_every_trial_times_out_after_its_delay():
    p = short(Perturbation(), trials=(2, 1, 1), timeout=1.0)
    session = LabSession(lab_config(p, 1), p)
    session.play([])
    assert session.finished and session.over and len(session.outcomes) == 4
    previous_end = 0
    for o in session.outcomes:
        assert not o.hit
        assert o.go_step - previous_end == o.plan.delay_steps  # the hand sat at home all along
        assert o.end_step - o.go_step == round(1.0 / session.config.dt)
        assert len(o.xs) == o.end_step - o.go_step + 1
        assert (o.xs[0], o.ys[0]) == pytest.approx(session.home)
        previous_end = o.end_step
    assert session.result().hits == 0 and session.steps == previous_end


def test_leaving_home_delays_the_go_cue():
    p = short(Perturbation(), trials=(1, 1, 1), timeout=0.5)
    session = LabSession(lab_config(p, 1), p)
    # d held for 0.3 s from the start moves the hand out of home; the hold restarts once the arm is back.
    session.play([InputEvent(0, "d", "down"), InputEvent(75, "d", "up"), InputEvent(100, "space", "down")])
    first = session.outcomes[0]
    assert first.go_step >= 100 + first.plan.delay_steps
    assert session.result().resets == 1


def test_space_during_a_reach_is_no_movement_and_marks_the_trial(tmp_path):
    """Issue 39: a volunteer's space ("hand home") mid-reach jumped the hand home in one physics step, and the
    whole path, jump included, was measured: peak speeds of tens of metres a second. The reach ends where the
    hand was sent home, the trial says so (hand_sent_home), and the class curve leaves it out."""
    from armgame.lab.analysis import trial_rows
    from armgame.lab.figures import class_curve
    from armgame.lab.metrics import Reach, reach_metrics, read_trials_csv, write_trials_csv

    p = short(Perturbation(), trials=(1, 1, 1), timeout=1.5)
    session = LabSession(lab_config(p, 1), p)
    go = session.plans[0].delay_steps  # the hand rests at home: the first go cue comes after the delay
    # The shoulder and elbow flexors held from the go cue throw the hand far out; space 0.4 s in sends it home.
    session.play([InputEvent(go, "d", "down"), InputEvent(go, "j", "down"), InputEvent(go + 100, "space", "down"),
                  InputEvent(go + 101, "d", "up"), InputEvent(go + 101, "j", "up")])
    first, second = session.outcomes[0], session.outcomes[1]
    assert first.go_step == go and first.home_at == 101 and second.home_at is None
    path = np.column_stack([first.xs, first.ys])
    assert np.hypot(*(path[101] - path[100])) > 0.1  # the jump home really is in the recorded path
    dt = session.config.dt
    whole = reach_metrics(Reach((first.go_step + np.arange(len(first.xs))) * dt, path, session.home,
                                first.plan.position, first.go_step * dt, first.hit))
    assert whole.peak_speed_m_per_s > 10.0  # what the table said before: no arm moves so
    rows = trial_rows(session)
    assert rows[0]["hand_sent_home"] is True and rows[1]["hand_sent_home"] is False
    assert 0.1 < rows[0]["peak_speed_m_per_s"] < 3.0  # the reach before the jump: a physical speed
    assert rows[0]["movement_time_s"] > 0.1
    write_trials_csv(tmp_path / "t.csv", rows)
    back = read_trials_csv(tmp_path / "t.csv")
    assert [r["hand_sent_home"] for r in back] == [True, False, False]
    curve = class_curve([back, back], "peak_speed_m_per_s")
    assert [c["n"] for c in curve] == [0, 2, 2]  # the abandoned reach is in nobody's curve
    # The replay still verifies bit for bit: the measures changed, not a step.
    again = LabSession(lab_config(p, 1), p)
    again.play(session.timeline, session.steps)
    assert again.trial_records() == session.trial_records() and again.outcomes[0].xs == first.xs


def test_model_bot_hits_every_target_and_reaches_straight():
    session, _ = bot_run(short(Perturbation()))
    assert session.result().hits == len(session.outcomes) == 16
    assert max(abs(perpendicular(session, o)) for o in session.outcomes) < 0.01


def test_same_protocol_seed_and_timeline_give_the_same_trials_bit_for_bit():
    p = short(Perturbation.make("curl", b=CURL_B))
    a, _ = bot_run(p)
    b, _ = bot_run(p)
    replayed = LabSession(lab_config(p, 3), p)
    replayed.play(a.timeline, a.steps)
    for other in (b, replayed):
        assert other.trial_records() == a.trial_records()
        assert all(x.xs == y.xs and x.ys == y.ys for x, y in zip(a.outcomes, other.outcomes, strict=True))
        assert other.state == a.state


def test_curl_scaling_deflects_the_model_bot_by_centimetres():
    """The preset's b: the model bot (knows the arm, not the field) is pushed clockwise by centimetres."""
    p = Protocol("scan", (Block("exposure", 8, Perturbation.make("curl", b=CURL_B)),))
    naive_to_field, _ = bot_run(p)
    deflections = [perpendicular(naive_to_field, o) for o in naive_to_field.outcomes]
    assert all(d < 0 for d in deflections)  # b > 0: clockwise, the right of the reach
    assert 0.015 < -np.mean(deflections) < 0.05, deflections


def test_a_bot_that_knows_the_field_counters_it_with_its_keys():
    """A bot whose internal model holds the preset's field (b^ = b, no learning) cancels it within its
    muscles' strength and reaches as straight as without a field."""
    p = Protocol("scan", (Block("exposure", 8, Perturbation.make("curl", b=CURL_B)),))
    knowing = make_lab_bot("adaptive")
    knowing.curl_learner.slow = CURL_B
    knowing.curl_learner.retention_slow, knowing.curl_learner.rate_slow, knowing.curl_learner.rate_fast = 1.0, 0, 0
    session = LabSession(lab_config(p, 3), p)
    Autopilot(session, knowing).play()
    assert session.result().hits == 8
    assert max(abs(perpendicular(session, o)) for o in session.outcomes) < 0.01
    # Its own measurement of the field it met (the learner's input) is close to the truth.
    assert all(abs(b - CURL_B) < 0.1 * CURL_B for _, b, *_ in knowing.history)


@pytest.mark.parametrize("show, x, y, q, expected", [
    (rotation(90.0, (1.0, 1.0)), 2.0, 1.0, (0, 0), (1.0, 2.0)),
    (mirror(90.0, (1.0, 1.0)), 1.5, 1.2, (0, 0), (0.5, 1.2)),
    (mirror(0.0, (1.0, 1.0)), 1.5, 1.2, (0, 0), (1.5, 0.8)),
    (joint_space(0.25, (1.0, 1.0), (0.5, 1.0)), 9.0, 9.0, (0.7, 0.6), (1.05, 0.9)),
])
def test_visual_transforms(show, x, y, q, expected):
    assert show(x, y, *q) == pytest.approx(expected)


def test_rotation_moves_the_scored_hand():
    """Under a 30 deg rotation the model bot reaches the true target, so the shown hand, which is scored,
    lands 30 deg counter-clockwise of it and the trials time out."""
    p = short(Perturbation.make("rotation", angle=30.0), trials=(2, 3, 2), timeout=1.5)
    session, _ = bot_run(p)
    for o in session.outcomes:
        hx, hy = session.home
        angle = math.degrees(math.atan2(o.ys[-1] - hy, o.xs[-1] - hx))
        off = (angle - o.plan.target_deg + 180.0) % 360.0 - 180.0
        if o.plan.perturbation.kind == "rotation":
            assert not o.hit and off == pytest.approx(30.0, abs=3.0)
        else:
            assert o.hit and abs(off) < 5.0


# ------------------------------------------------------------------- replays
def _replay(session, tmp_path, name="run.json"):
    replay = Replay(session.config, tuple(session.timeline), session.result(), "bot", "model", None, now_iso(),
                    task=LabTask.of(session))
    path = tmp_path / name
    replay.save(path)
    return path


def test_lab_replay_verifies_and_tampering_is_caught(tmp_path):
    session, _ = bot_run(short(Perturbation.make("curl", b=CURL_B), trials=(2, 3, 2)))
    path = _replay(session, tmp_path)
    loaded = Replay.load(path)
    assert loaded.task.protocol == session.protocol and loaded.task.trials == tuple(
        tuple(t) for t in session.trial_records())
    assert loaded.verify()[0]
    data = json.loads(path.read_text())
    data["task"]["trials"][1][2] += 1  # a trial said to end one step later
    path.write_text(json.dumps(data))
    assert not Replay.load(path).verify()[0]
    data = json.loads(path.read_text())
    data["task"]["trials"][1][2] -= 1
    data["task"]["protocol"]["blocks"][1]["b"] = 1.0  # another field than the one played
    path.write_text(json.dumps(data))
    assert not Replay.load(path).verify()[0]


@pytest.mark.parametrize("change, message", [
    (lambda d: d["task"].update(kind="maze"), "task.kind must be 'centre-out'"),
    (lambda d: d["task"]["trials"][0].__setitem__(3, "yes"), "must be [target, go_step, end_step, hit]"),
    (lambda d: d["task"]["trials"].append([0, 1, 2, True]), "task.trials must be a list of at most 3 trials"),
    (lambda d: d["task"]["trials"][0].__setitem__(0, 99), "task.trials[0] target must be from 0 to 7"),
    (lambda d: d["task"]["protocol"].update(targets=0), "task.protocol: targets must be from 1 to 64"),
    (lambda d: d["task"].pop("protocol"), "task lacks protocol"),
    (lambda d: d.update(scene="game") or d["config"].update(scene="game") or d["result"].update(scene="game"),
     "a replay with a task must have scene 'lab'"),
])
def test_bad_lab_replays_get_one_line(tmp_path, change, message):
    p = short(Perturbation(), trials=(1, 1, 1), timeout=0.5)
    session = LabSession(lab_config(p, 1), p)
    session.play([])
    path = _replay(session, tmp_path)
    data = json.loads(path.read_text())
    change(data)
    path.write_text(json.dumps(data))
    with pytest.raises(UserError) as err:
        Replay.load(path)
    assert message in str(err.value) and "\n" not in str(err.value)


def test_lab_runs_never_enter_the_high_score_table(tmp_path):
    p = short(Perturbation(), trials=(1, 1, 1), timeout=0.5)
    session = LabSession(lab_config(p, 1), p)
    session.play([])
    replay = Replay.load(_replay(session, tmp_path)).with_player("Ada")
    assert replay.task is not None
    with pytest.raises(ValueError, match="never enters the high-score table"):
        ScoreTable(tmp_path / "scores").add(replay)


# ------------------------------------------------------------ the adapting bot
def adaptive_run(perturbation: Perturbation, rates=None, exposure=24, catch=0, seed=4):
    from armgame.lab.bots import LearningRates

    blocks = (Block("baseline", 8, Perturbation()), Block("exposure", exposure, perturbation, catch),
              Block("washout", 8, Perturbation()))
    p = Protocol("fast", blocks, timeout=1.5)
    session = LabSession(lab_config(p, seed), p)
    bot = make_lab_bot("adaptive", rates or LearningRates(0.6, 0.99, 0.4, 0.1))
    Autopilot(session, bot).play()
    return session, bot


def test_adaptive_bot_learns_a_visual_rotation():
    """Initial direction error starts near the rotation (+30 deg, counter-clockwise), decays as the bot
    aims the other way, and errs clockwise on the first washout trials."""
    from armgame.lab.analysis import trial_rows

    session, bot = adaptive_run(Perturbation.make("rotation", angle=30.0))
    rows = trial_rows(session)
    error = {b: np.array([r["initial_direction_error_deg"] for r in rows if r["block"] == b])
             for b in ("baseline", "exposure", "washout")}
    assert abs(error["baseline"].mean()) < 6.0
    assert 20.0 < error["exposure"][0] < 40.0
    assert abs(error["exposure"][-8:].mean()) < 0.5 * error["exposure"][0]
    assert error["washout"][:2].mean() < -10.0
    measured = [h[3] for h in bot.history if session.plans[h[0]].active.kind == "rotation"]
    assert np.allclose(np.degrees(measured), 30.0, atol=1.0)  # what it saw against what it felt


def test_catch_trials_show_the_learned_field():
    """On a catch trial late in exposure the field is off but the bot still expects it: the reach errs
    the other way (counter-clockwise), an after-effect within the exposure block."""
    session, _ = adaptive_run(Perturbation.make("curl", b=CURL_B), exposure=32, catch=3)
    late = [o for o in session.outcomes if o.plan.block == 1 and o.plan.index >= 8 + 16]
    catch = [perpendicular(session, o) for o in session.outcomes if o.plan.catch]
    assert len(catch) == 3
    assert [o.plan.catch for o in session.outcomes].count(True) == 3
    field = [perpendicular(session, o) for o in late if not o.plan.catch]
    assert np.mean(field) < 0 and all(c > 0.01 for c in catch)


def test_a_bot_that_does_not_learn_shows_no_after_effect():
    from armgame.lab.bots import LearningRates

    session, bot = adaptive_run(Perturbation.make("curl", b=CURL_B), rates=LearningRates(0.59, 0.992, 0.0, 0.0))
    washout = [perpendicular(session, o) for o in session.outcomes if o.plan.block == 2]
    exposure = [perpendicular(session, o) for o in session.outcomes if o.plan.block == 1]
    assert bot.curl_estimate == 0.0
    assert max(abs(w) for w in washout) < 0.006 and np.mean(exposure[-8:]) < -0.015


@pytest.mark.parametrize("perturbation", [
    Perturbation.make("constant", fx=1.0, fy=-0.5), Perturbation.make("spring", stiffness=20.0),
    Perturbation.make("curl", b=-CURL_B), Perturbation.make("viscous", b11=-1.0, b12=-1.0, b21=-1.0, b22=1.0),
    Perturbation.make("mirror", axis=90.0),
    Perturbation.make("jointspace", gain=0.25)], ids=lambda p: p.kind)
def test_every_perturbation_changes_the_reach_it_is_on(perturbation, tmp_path):
    """The same target and bot with and without each perturbation: the shown path differs on the perturbed
    trial only, and the run's replay verifies."""
    p = Protocol("each", (Block("a", 1, Perturbation()), Block("b", 1, perturbation), Block("c", 1, Perturbation())),
                 targets=1, first_target_deg=30.0, timeout=1.0)
    session, _ = bot_run(p)
    null, _ = bot_run(Protocol("each", tuple(Block(n, 1, Perturbation()) for n in "abc"), targets=1,
                               first_target_deg=30.0, timeout=1.0))
    for o, n in zip(session.outcomes, null.outcomes, strict=True):
        apart = max(math.dist(a, b) for a, b in zip(zip(o.xs, o.ys, strict=True), zip(n.xs, n.ys, strict=True),
                                                    strict=False))
        assert (apart > 0.005) == (o.plan.block == 1), (o.plan.block, apart)
        assert o.xs[0] == pytest.approx(session.home[0]) and o.ys[0] == pytest.approx(session.home[1])
    assert Replay.load(_replay(session, tmp_path)).verify()[0]


def test_a_replay_whose_start_posture_is_not_its_protocols_home_is_refused(tmp_path):
    p = short(Perturbation(), trials=(1, 1, 1), timeout=0.5)
    session = LabSession(lab_config(p, 1), p)
    session.play([])
    path = _replay(session, tmp_path)
    data = json.loads(path.read_text())
    data["config"]["start_posture"][0] += 0.01
    path.write_text(json.dumps(data))
    with pytest.raises(UserError, match="differs from its protocol's home posture"):
        Replay.load(path).verify()


def test_a_lab_run_whose_state_goes_non_finite_stops_in_one_line():
    """The lab's loop runs inside GameSession.advance, so a blow-up is caught as in the game."""
    from armgame.game.session import NonFiniteStateError

    p = short(Perturbation())
    session = LabSession(lab_config(p, 1), p)
    session.advance(10)
    session._step = lambda q1, q2, w1, w2, t1, t2, dt: (q1, q2, math.inf, w2)  # a physics that blows up
    with pytest.raises(NonFiniteStateError, match="non-finite"):
        session.advance(10)


# ------------------------------------------------ the viscous field and error-clamp channels
def test_viscous_matrix_in_a_protocol_file(tmp_path):
    path = tmp_path / "v.toml"
    path.write_text('[[blocks]]\ntrials = 4\nperturbation = "viscous"\nmatrix = [[-1.2625, -1.4], [-1.4, 1.3875]]\n')
    p = load_protocol(path)
    assert p.blocks[0].perturbation == preset("viscous").blocks[1].perturbation
    assert p.blocks[0].perturbation.matrix == ((-1.2625, -1.4), (-1.4, 1.3875)) == VISCOUS_B
    assert protocol_from_dict(json.loads(json.dumps(protocol_as_dict(p)))) == p
    assert p.blocks[0].perturbation.label() == "viscous B=[[-1.2625, -1.4], [-1.4, 1.3875]] N s/m"


@pytest.mark.parametrize("text, message", [
    ("perturbation = 'viscous'\nmatrix = [1, 2, 3, 4]", "blocks[0].matrix must be [[b11, b12], [b21, b22]]"),
    ("perturbation = 'viscous'\nmatrix = [[1, 2], [3]]", "blocks[0].matrix must be [[b11, b12], [b21, b22]]"),
    ("perturbation = 'viscous'\nmatrix = [[1, 2], [3, 99]]", "blocks[0].matrix[1][1] must be a finite number from -50"),
    ("perturbation = 'viscous'\nmatrix = [[1, 'x'], [3, 4]]", "blocks[0].matrix[0][1] must be a number"),
    ("perturbation = 'viscous'\nb = 2", "blocks[0] has unknown field(s) b"),
    ("perturbation = 'curl'\nmatrix = [[1, 2], [3, 4]]", "blocks[0] has unknown field(s) matrix"),
    ("channel_trials = 13", "blocks[0].channel_trials must be at most the block's trials (12)"),
    ("channel_trials = -1", "blocks[0].channel_trials must be from 0 to 2000"),
    ("channel_trials = 5", "blocks[0].channel_trials must be at most trials - targets - catch_trials (4)"),
    ("perturbation = 'curl'\ncatch_trials = 2\nchannel_trials = 3",
     "channel_trials must be at most trials - targets - catch_trials (2)"),
    ("perturbation = 'curl'\ncatch_trials = 2\nchannel_trials = 12", "is all channel trials: none to catch"),
])
def test_bad_viscous_and_channel_fields_get_one_line(tmp_path, text, message):
    path = tmp_path / "p.toml"
    path.write_text("[[blocks]]\ntrials = 12\n" + text + "\n")
    with pytest.raises(UserError) as err:
        load_protocol(path)
    assert message in str(err.value) and "\n" not in str(err.value)


@pytest.mark.parametrize("top, message", [
    ("channel_stiffness = 0", "channel_stiffness must be a finite number above 0 and at most 20000, got 0.0"),
    ("channel_stiffness = 1e9", "channel_stiffness must be a finite number above 0 and at most 20000"),
    ("channel_damping = -1", "channel_damping must be a finite number from 0 to 500"),
])
def test_bad_channel_settings_get_one_line(tmp_path, top, message):
    path = tmp_path / "p.toml"
    path.write_text(top + "\n[[blocks]]\ntrials = 3\nchannel_trials = 3\n")
    with pytest.raises(UserError, match=message.replace("(", r"\(").replace(")", r"\)")):
        load_protocol(path)


def test_a_channel_too_stiff_for_the_physics_step_is_refused():
    """Stiffness and damping are checked against dt: 20,000 N/m on 0.77 kg rings at 160/s, |s| dt = 0.65
    at the game's 4 ms, but 500 N s/m damps at 650/s, |s| dt = 2.6, near RK4's edge: refused."""
    ok = Protocol("c", (Block("c", 1, Perturbation(), channel_trials=1),), channel_stiffness=20000.0,
                  channel_damping=150.0)
    LabSession(lab_config(ok, 1), ok)
    stiff = replace(ok, channel_damping=500.0)
    with pytest.raises(UserError, match=r"too stiff for the physics step of 0.004 s.*must be at most 1") as err:
        LabSession(lab_config(stiff, 1), stiff)
    assert "\n" not in str(err.value)
    LabSession(lab_config(stiff, 1, dt=0.001), stiff)  # a finer step takes it


def test_channel_trials_are_drawn_after_the_first_cycle_and_apart_from_catch_trials():
    p = Protocol("c", (Block("a", 40, Perturbation.make("curl", b=CURL_B), catch_trials=5, channel_trials=9),
                       Block("b", 6, Perturbation(), channel_trials=6)))
    plans = schedule(p, 7, 0.004, (0.0, 0.5))
    first = [q for q in plans if q.block == 0]
    assert sum(q.channel for q in first) == 9 and sum(q.catch for q in first) == 5
    assert not any(q.channel and q.catch for q in plans)
    assert not any(q.channel or q.catch for q in first[:8])
    assert all(q.channel and q.active == Perturbation() for q in plans if q.block == 1)
    # A protocol without channels draws nothing for them: its schedule is the one it always had.
    plain = replace(p, blocks=(replace(p.blocks[0], channel_trials=0), replace(p.blocks[1], channel_trials=0)))
    assert [q.channel for q in schedule(plain, 7, 0.004, (0.0, 0.5))] == [False] * 46


def test_viscous_scaling_deflects_the_model_bot_and_a_bot_that_knows_it_counters_it():
    """The preset's B (the published field / 8): the model bot is pushed by centimetres, to either side
    by direction as in Shadmehr & Mussa-Ivaldi's figures; with B in its internal model it reaches straight."""
    p = Protocol("scan", (Block("exposure", 8, preset("viscous").blocks[1].perturbation),), **QUICK)
    pushed, _ = bot_run(p)
    deflections = np.array([perpendicular(pushed, o) for o in pushed.outcomes])
    assert 0.01 < np.mean(np.abs(deflections)) < 0.04 and (deflections > 0).any() and (deflections < 0).any()
    knowing = make_lab_bot("model")
    knowing.known_field = VISCOUS_B
    session = LabSession(lab_config(p, 3), p)
    Autopilot(session, knowing).play()
    assert session.result().hits == 8
    assert max(abs(perpendicular(session, o)) for o in session.outcomes) < 0.006


QUICK = {"timeout": 1.5, "delay": (0.1, 0.1), "hold_time": 0.1}


#: How far (m) a channel trial may let the hand off its line.
CHANNEL_HOLD = 0.0015


def channel_run(b_hat: float, trials: int = 8):
    p = Protocol("clamp", (Block("clamp", trials, Perturbation.make("curl", b=CURL_B), channel_trials=trials),),
                 **QUICK)
    bot = make_lab_bot("model")
    bot.known_field = ((0.0, b_hat), (-b_hat, 0.0))
    session = LabSession(lab_config(p, 3), p)
    Autopilot(session, bot).play()
    return session


def test_the_channel_holds_the_hand_on_the_line_and_the_index_reads_what_was_learned():
    """A bot expecting the whole field (b^ = b) presses into the channel with the force that would cancel
    it: index about 1; expecting none, about 0. The hand stays within a millimetre of the line."""
    from armgame.lab.analysis import trial_rows

    indices, worst = {}, 0.0
    for b_hat in (0.0, CURL_B):
        session = channel_run(b_hat)
        assert session.result().hits == 8
        worst = max(worst, *(abs(perpendicular(session, o)) for o in session.outcomes))
        assert worst < CHANNEL_HOLD
        rows = trial_rows(session)
        assert all(r["perturbation"] == "channel" for r in rows)
        assert all(len(o.channel_force) == len(o.xs) for o in session.outcomes)
        indices[b_hat] = np.median([r["adaptation_index"] for r in rows])
        peak = np.array([r["channel_force_peak_n"] for r in rows])
        assert np.all(np.isfinite(peak))
    assert abs(indices[0.0]) < 0.1 and abs(indices[CURL_B] - 1.0) < 0.1, indices
    # docs/lab.md quotes this test's bound and what it measured: neither may drift from the code.
    doc = " ".join((Path(__file__).resolve().parent.parent / "docs" / "lab.md").read_text(encoding="utf-8").split())
    assert (f"within {math.ceil(10_000 * worst) / 10:.1f} mm of the line in the tests' channel trials (which allow "
            f"{1000 * CHANNEL_HOLD:.1f} mm)") in doc
    assert f"and the hand stays within {1000 * CHANNEL_HOLD:.1f} mm of the line" in doc


def test_the_adaptive_bot_learns_nothing_from_a_channel_trial():
    """On a channel trial the learner's error is 0: only its retentions act. Replaying the bot's own history
    through a fresh learner, with 0 on the channel trials, gives its estimate exactly; with what it
    measured in the channel instead, it would not."""
    from armgame.lab.learner import TwoRateLearner

    p = Protocol("sr", (Block("exposure", 6, Perturbation.make("curl", b=CURL_B)),
                        Block("clamp", 3, Perturbation.make("curl", b=CURL_B), channel_trials=3)), targets=2, **QUICK)
    session = LabSession(lab_config(p, 4), p)
    bot = make_lab_bot("adaptive")
    Autopilot(session, bot).play()
    channel = {o.plan.index for o in session.outcomes if o.plan.channel}
    clamped, measured = TwoRateLearner(), TwoRateLearner()
    for index, b_seen, b_hat, *_ in bot.history:
        clamped.update(0.0 if index in channel else b_seen - b_hat)
        measured.update(b_seen - b_hat)
    assert clamped.estimate == bot.curl_estimate
    assert abs(measured.estimate - bot.curl_estimate) > 0.01


def test_a_lab_replay_with_channels_and_a_viscous_field_verifies_and_tampering_is_caught(tmp_path):
    p = Protocol("mixed", (Block("a", 3, preset("viscous").blocks[1].perturbation, channel_trials=1),
                           Block("b", 2, Perturbation(), channel_trials=2)), targets=2, **QUICK)
    session, _ = bot_run(p)
    path = _replay(session, tmp_path)
    loaded = Replay.load(path)
    assert loaded.task.protocol == p and loaded.verify()[0]
    data = json.loads(path.read_text())
    del data["task"]["protocol"]["blocks"][0]["channel_trials"]  # the channel trial said to be a field trial
    path.write_text(json.dumps(data))
    assert not Replay.load(path).verify()[0]
    data["task"]["protocol"]["blocks"][0]["channel_trials"] = 1
    data["task"]["protocol"]["channel_stiffness"] = 2500.0  # another channel than the one played
    path.write_text(json.dumps(data))
    assert not Replay.load(path).verify()[0]


def test_the_paradigms_presets_show_their_signatures_in_the_bots_learner():
    """The presets' block lengths, run through the adaptive bot's default learner (cheap: no arm): the
    counter-field brings the adaptation back to about zero, after which the clamp block rebounds toward
    the first field (spontaneous recovery) and re-exposure re-learns far faster (savings); after a plain
    null washout long enough to zero the adaptation, re-learning is barely faster."""
    from armgame.lab.analysis import disturbance_schedule
    from armgame.lab.fit import run_model
    from armgame.lab.presets import savings

    def estimate(protocol):
        plans = schedule(protocol, 10, 0.004, (0.0, 0.5))
        f, clamped = disturbance_schedule(protocol, plans)
        return run_model(0.59, 0.992, 0.21, 0.02, f, clamped), [q.block_name for q in plans]

    x, blocks = estimate(preset("spontaneous"))
    clamp = x[[i for i, b in enumerate(blocks) if b == "clamp"]]
    assert abs(clamp[0]) < 0.1 and clamp.max() > 0.35 and np.argmax(clamp) > 3

    def trials_to_half(x, blocks, name):
        block = np.array([x[i] for i, b in enumerate(blocks) if b == name])
        return int(np.argmax(block >= 0.5))

    x, blocks = estimate(preset("savings"))
    first, again = trials_to_half(x, blocks, "exposure"), trials_to_half(x, blocks, "re-exposure")
    assert first >= 20 and again <= 3, (first, again)
    x, blocks = estimate(savings(counter=0))
    assert abs(x[blocks.index("re-exposure")]) < 0.05
    assert trials_to_half(x, blocks, "re-exposure") >= first - 3


def test_the_adaptive_bot_measures_what_a_viscous_field_shows_along_each_reach():
    """With a viscous field the bot's learner holds a matrix B^. A reach along u shows B u only: with its
    learning off (B^ = 0) the correction it measures, dB u, is the field's B u within 20% (the field bends the
    path, and the sideways velocity's share is read as if along u), and it learns
    the matrix over the targets' directions: B^ moves toward B."""
    from armgame.lab.bots import LearningRates

    field = preset("viscous").blocks[1].perturbation
    p = Protocol("v", (Block("exposure", 4, field),), targets=4, **QUICK)
    still = make_lab_bot("adaptive", LearningRates(0.59, 0.992, 0.0, 0.0))
    session = LabSession(lab_config(p, 2), p)
    Autopilot(session, still).play()
    b = np.asarray(VISCOUS_B)
    for index, correction in still.matrix_history[:3]:
        tx, ty = session.plans[index].position
        u = np.array([tx - session.home[0], ty - session.home[1]]) / p.distance
        np.testing.assert_allclose(correction.reshape(2, 2) @ u, b @ u, atol=0.2 * np.linalg.norm(b @ u))
    assert still.matrix_estimate == ((0.0, 0.0), (0.0, 0.0)) and still.curl_estimate == 0.0
    learning = make_lab_bot("adaptive", LearningRates(0.6, 0.99, 0.4, 0.1))
    session = LabSession(lab_config(p, 2), p)
    Autopilot(session, learning).play()
    learned = np.asarray(learning.matrix_estimate)
    assert np.sum(learned * b) > 0.2 * np.sum(b * b) and learning.curl_estimate == 0.0
