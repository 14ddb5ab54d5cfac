"""Issue 29: blocks that name their targets, probe trials spread evenly over directions and trials, the
per-direction baseline, channel traces, and the adapting bot's local (direction-tuned) learner."""

import csv
import itertools
import json
import math
from collections import Counter
from dataclasses import replace

import numpy as np
import pytest

from armgame.cli import main
from armgame.errors import UserError
from armgame.lab.bots import make_lab_bot
from armgame.lab.learner import DirectionalLearner, TwoRateLearner
from armgame.lab.metrics import read_trials_csv
from armgame.lab.perturbations import Perturbation
from armgame.lab.presets import lesson, preset
from armgame.lab.protocol import Block, Protocol, with_catch_trials
from armgame.lab.protocol_file import load_protocol, protocol_as_dict, protocol_from_dict
from armgame.lab.record import LabTask
from armgame.lab.session import LabSession, lab_config, schedule

CURL = Perturbation.make("curl", b=2.0)


def probes_of(plans, block):
    return [(i, q) for i, q in enumerate(q for q in plans if q.block == block) if q.catch or q.channel]


# ------------------------------------------------------------------ the balanced placement
@pytest.mark.parametrize("protocol", [
    preset("spontaneous"), preset("generalization"), with_catch_trials(preset("curl"), 6),
    Protocol("mixed", (Block("a", 60, CURL, catch_trials=5, channel_trials=11),)),
], ids=["spontaneous", "generalization", "curl-catch", "mixed"])
def test_probes_are_spread_evenly_over_directions_and_never_back_to_back(protocol):
    for seed in (1, 2, 10):
        plans = schedule(protocol, seed, 0.004, (0.0, 0.5))
        assert plans == schedule(protocol, seed, 0.004, (0.0, 0.5))
        for b, block in enumerate(protocol.blocks):
            if block.channel_block or not block.probes:
                continue
            cycle = len(block.targets_of(protocol))
            probed = probes_of(plans, b)
            where = [i for i, _ in probed]
            assert len(where) == block.probes and min(where) >= cycle
            assert all(later - earlier >= 2 for earlier, later in itertools.pairwise(where))
            for kind in ("catch", "channel"):
                counts = Counter(q.target for _, q in probed if getattr(q, kind))
                counts = [counts.get(t, 0) for t in block.probe_targets_of(protocol)]
                assert max(counts) - min(counts) <= 1, (seed, b, kind, counts)
            # the other trials keep whole cycles of the block's own targets
            ordinary = [q.target for q in plans if q.block == b and not (q.catch or q.channel)]
            for c in range(0, len(ordinary) - len(ordinary) % cycle, cycle):
                assert sorted(ordinary[c:c + cycle]) == sorted(block.targets_of(protocol))
    # The case: seed 1 put five of the spontaneous exposure's channel trials at 0 deg and none at 45.
    old = schedule(replace(preset("spontaneous"), probe_schedule="random"), 1, 0.004, (0.0, 0.5))
    placed = Counter(q.target_deg for _, q in probes_of(old, 1))
    assert placed[0.0] == 5 and placed[45.0] == 0  # docs/lab.md, "Probe trials": five at 0 deg, none at 45


def test_generalization_trains_one_direction_and_probes_them_all():
    p = preset("generalization")
    plans = schedule(p, 10, 0.004, (0.0, 0.5))
    test = [q for q in plans if q.block == 2]
    assert {q.target_deg for q in test if not q.channel} == {90.0}
    assert Counter(q.target_deg for q in test if q.channel) == dict.fromkeys(range(0, 360, 45), 2)
    assert {q.target_deg for q in plans if q.block == 0 and q.channel} == set(map(float, range(0, 360, 45)))
    assert protocol_from_dict(json.loads(json.dumps(protocol_as_dict(p)))) == p
    assert protocol_as_dict(p)["blocks"][2]["probe_directions_deg"] == [float(a) for a in range(0, 360, 45)]


def test_back_to_back_probes_only_when_asked(tmp_path):
    text = ("targets = 4\n{}\n[[blocks]]\ntrials = 10\nperturbation = 'curl'\nb = 2.0\ncatch_trials = 2\n"
            "channel_trials = 2\n")
    path = tmp_path / "p.toml"
    path.write_text(text.format(""))
    with pytest.raises(UserError, match=r"^.*blocks\[0\]: 4 catch and channel trials in the 6 trials after its first "
                                        r"cycle: at most 3 when no two follow one another \(consecutive_probes"):
        load_protocol(path)
    path.write_text(text.format("consecutive_probes = true"))
    p = load_protocol(path)
    assert p.consecutive_probes and protocol_as_dict(p)["consecutive_probes"] is True
    assert sum(q.catch or q.channel for q in schedule(p, 3, 0.004, (0.0, 0.5))) == 4


@pytest.mark.parametrize("block, top, message", [
    ("directions_deg = [30]", "", "blocks[0].directions_deg[0]: 30 deg is not a target's direction (they are 0, 90, "
                                  "180, 270)"),
    ("directions_deg = [90, 450]", "", "blocks[0].directions_deg[1] must be a finite number from -360 to 360"),
    ("directions_deg = [90, -270]", "", "blocks[0].directions_deg[1]: -270 deg is named twice"),
    ("directions_deg = []", "", "blocks[0].directions_deg must be a list of 1 to 4"),
    ("directions_deg = 'up'", "", "blocks[0].directions_deg must be a list of 1 to 4"),
    ("probe_directions_deg = [0]", "", "blocks[0].probe_directions_deg: block 'block 1' has no catch or channel"),
    ("channel_trials = 1\nprobe_directions_deg = [0]", "probe_schedule = 'random'",
     'blocks[0].probe_directions_deg needs probe_schedule = "balanced"'),
    ("channel_trials = 1", "probe_schedule = 'even'", "probe_schedule must be one of balanced, random, got 'even'"),
    ("channel_trials = 1", "consecutive_probes = 1", "consecutive_probes must be true or false, got 1"),
])
def test_bad_directions_and_probe_settings_get_one_line(tmp_path, block, top, message):
    path = tmp_path / "p.toml"
    path.write_text(f"targets = 4\n{top}\n[[blocks]]\ntrials = 12\n{block}\n")
    with pytest.raises(UserError) as exc:
        load_protocol(path)
    assert message in str(exc.value) and "\n" not in str(exc.value)


# ------------------------------------------------------------------ old runs, the class, the envs
def quick(protocol):
    """A run with no keys: every trial times out at once (no bot, a few thousand steps)."""
    config = lab_config(protocol, 5)
    session = LabSession(config, protocol)
    session.play([], session.total_steps)
    return config, session


def test_a_replay_recorded_before_the_balanced_placement_still_verifies():
    timing = dict(targets=4, timeout=0.2, delay=(0.0, 0.0), hold_time=0.0)
    old = Protocol("old", (Block("a", 16, CURL, catch_trials=2, channel_trials=3),), probe_schedule="random",
                   **timing)
    config, session = quick(old)
    recorded = LabTask.of(session).as_dict()
    del recorded["protocol"]["probe_schedule"]  # as a replay written before the key existed
    task = LabTask.from_dict(json.loads(json.dumps(recorded)), config, session.steps)
    assert task.protocol.probe_schedule == "random"
    assert task.verify(config, [], session.result())[0]
    # Read as a file is, the same protocol places its probes elsewhere: the recorded default matters.
    assert protocol_from_dict(recorded["protocol"]).probe_schedule == "balanced"
    assert schedule(replace(old, probe_schedule="balanced"), 5, config.dt, session.home) != session.plans
    # A protocol without probes is written as before and reads back equal either way (the class curve groups
    # runs by protocol: an old lesson replay and a new one stay one class).
    assert set(protocol_as_dict(lesson())) == set(protocol_as_dict(protocol_from_dict(protocol_as_dict(lesson())))) \
        and "probe_schedule" not in protocol_as_dict(lesson())
    assert protocol_from_dict(protocol_as_dict(lesson()), recorded=True) == lesson()


def test_the_versioned_envs_keep_their_schedule():
    pytest.importorskip("gymnasium")
    from armgame.env.center_out import run_protocol

    for name in ("spontaneous", "null"):
        ran = run_protocol(name, None)
        assert ran == replace(preset(name), probe_schedule="random")
    assert run_protocol("generalization", None) == preset("generalization")  # new, and needs the placement


# ------------------------------------------------------------------ the learners
def test_the_local_learner_generalizes_by_its_tuning_and_the_global_one_everywhere():
    local = DirectionalLearner(TwoRateLearner())
    assert [round(local.generalization(d), 3) for d in (0, 45, 90, 180)] == [1.0, 0.57, 0.105, 0.0]
    plain = TwoRateLearner()
    for _ in range(30):  # trained on 90 deg only, against a field of 1
        local.update(1.0 - local.at(90.0), 90.0)
        plain.update(1.0 - plain.estimate)
    assert local.at(90.0) == pytest.approx(plain.estimate, rel=1e-12)  # the two-rate dynamics where it trains
    assert local.at(135.0) == pytest.approx(local.at(45.0)) and 0.4 < local.at(45.0) / local.at(90.0) < 0.75
    assert local.at(270.0) < 0.01 * local.at(90.0)
    with pytest.raises(UserError, match="tuning width must be a number of degrees from 5 to 180, got 1"):
        DirectionalLearner(TwoRateLearner(), 1)
    bot, flat = make_lab_bot("adaptive", representation="local"), make_lab_bot("adaptive")
    assert "local learner: Gaussian tuning over movement direction, bases of s.d. 30 deg" in bot.describe()
    assert flat.describe().startswith("global learner") and make_lab_bot("model").describe() == ""
    with pytest.raises(UserError, match="learner representation"):
        make_lab_bot("adaptive", representation="wide")


GENERALIZATION = """
name = "gen"
targets = 4
timeout = 1.5

[[blocks]]
name = "baseline"
trials = 4
channel_trials = 4

[[blocks]]
name = "exposure"
trials = 6
perturbation = "curl"
b = 2.0
directions_deg = [90]

[[blocks]]
name = "test"
trials = 9
perturbation = "curl"
b = 2.0
directions_deg = [90]
channel_trials = 4
probe_directions_deg = [0, 90, 180, 270]
"""


def test_generalization_falls_off_with_the_local_learner_and_not_the_global_one(tmp_path, capsys):
    path = tmp_path / "gen.toml"
    path.write_text(GENERALIZATION)
    by_angle = {}
    for representation in ("local", "global"):
        assert main(["lab", str(path), "--bot", "adaptive", "--headless", "--representation", representation,
                     "--record", str(tmp_path / f"{representation}.json"), "--out", str(tmp_path / representation),
                     "--no-figures"]) == 0
        out = capsys.readouterr().out
        assert f"the adaptive bot's {representation} learner" in out
        line = next(x for x in out.splitlines() if "by angle from the trained 90 deg (less each direction" in x)
        by_angle[representation] = dict(item.split() for item in line.split("): ")[1].split(", "))
    local, flat = ({k: float(v) for k, v in by_angle[r].items()} for r in ("local", "global"))
    assert local["+0"] > 0.3 and max(abs(local["+90"]), abs(local["-90"]), abs(local["+180"])) < 0.25 * local["+0"]
    assert min(flat.values()) > 0.6 * flat["+0"]
    # analyze: the baseline subtracted per direction, and each channel trial's force over time.
    assert main(["analyze", str(tmp_path / "local.json"), "--out", str(tmp_path / "a"), "--subtract-baseline",
                 "--channel-traces"]) == 0
    assert "adaptation index less each direction's baseline, which was: 0 deg " in capsys.readouterr().out
    rows = read_trials_csv(tmp_path / "a" / "local.trials.csv")
    base = [r for r in rows if r["perturbation"] == "channel" and r["block"] == "baseline"]
    assert len(base) == 4 and all(r["adaptation_index"] == 0.0 for r in base)
    with open(tmp_path / "a" / "local.channel_traces.csv", newline="") as f:
        traces = list(csv.DictReader(f))
    channel = [r for r in rows if r["perturbation"] == "channel"]
    assert {int(t["trial"]) for t in traces} == {r["trial"] for r in channel}
    first = [t for t in traces if int(t["trial"]) == channel[-1]["trial"]]
    force, cancel = (np.array([float(t[k]) for t in first]) for k in ("channel_force_n", "cancelling_force_n"))
    raw = float(cancel @ force / (cancel @ cancel))  # the index, from the traces
    assert math.isfinite(raw) and float(first[1]["time_s"]) == pytest.approx(0.004)
    plain = {r["trial"]: r for r in read_trials_csv(tmp_path / "local" / "trials.csv")}
    assert plain[channel[-1]["trial"]]["adaptation_index"] == pytest.approx(raw, rel=1e-9)
    # the subtracted index is the raw one less its direction's baseline (the baseline's own, raw)
    offset = {r["target_deg"]: r["adaptation_index"] for r in plain.values()
              if r["perturbation"] == "channel" and r["block"] == "baseline"}
    last = channel[-1]
    assert last["adaptation_index"] == pytest.approx(raw - offset[last["target_deg"]], rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("argv, message", [
    (["analyze", "r.json", "--channel-traces", "--fit", "two-rate"], "--channel-traces needs --out"),
    (["analyze", "--class", "d", "--out", "o", "--subtract-baseline"], "apply to replays, not --class"),
    (["lab", "curl", "--bot", "model", "--headless", "--representation", "local"], "add --bot adaptive"),
    (["lab", "curl", "--bot", "adaptive", "--headless", "--tuning-width", "20"], "add --representation local"),
    (["lab", "curl", "--bot", "adaptive", "--headless", "--representation", "local", "--tuning-width", "nan"],
     "tuning width must be a number of degrees from 5 to 180"),
])
def test_probe_and_learner_options_errors_are_one_line(argv, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "d").mkdir()
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


def test_subtract_baseline_never_blanks_a_direction_the_baseline_did_not_probe(tmp_path, capsys):
    """Issue 39: ``spontaneous``'s baseline probes 4 of its 8 directions, and --subtract-baseline blanked every
    channel trial to the other 4 (32 of 68). A direction without its own baseline takes the nearest probed
    direction's (the mean of the two when two are as near), and the output names them."""
    from armgame.lab.analysis import baseline_for, baseline_offsets, subtract_baseline, trial_rows

    assert baseline_for({0.0: 0.25, 90.0: -0.25, 180.0: 0.5}, 45.0) == (0.0, (0.0, 90.0))
    assert baseline_for({0.0: 0.25, 90.0: -0.25, 180.0: 0.5}, 135.0) == (0.125, (90.0, 180.0))
    assert baseline_for({0.0: 0.25, 180.0: 0.5}, 315.0) == (0.25, (0.0,))
    assert baseline_for({0.0: 0.25}, 0.0) == (0.25, (0.0,))
    spontaneous = preset("spontaneous")
    plans = schedule(spontaneous, 10, 0.004, (0.0, 0.5))
    probed = {p.target_deg for p in plans if p.channel and p.block == 0}
    assert len(probed) == 4 < len({p.target_deg for p in plans if p.channel})  # the case the issue found
    curl = Perturbation.make("curl", b=2.0)
    protocol = Protocol("probes", (Block("baseline", 8, channel_trials=2),
                                   Block("exposure", 12, curl, channel_trials=4)), targets=4)
    session = LabSession(lab_config(protocol, 3), protocol)
    from armgame.game.bots import Autopilot

    Autopilot(session, make_lab_bot("model")).play()
    rows = trial_rows(session)
    offsets = baseline_offsets(session, rows)
    assert len(offsets) == 2
    less = subtract_baseline(session, rows)
    exposed = [r for r in less if r["perturbation"] == "channel" and r["block"] == "exposure"]
    assert len({r["target_deg"] for r in exposed}) == 4 and all(math.isfinite(r["adaptation_index"]) for r in exposed)
    for before, after in zip(rows, less, strict=True):
        if after in exposed:
            base, _ = baseline_for(offsets, before["target_deg"])
            assert after["adaptation_index"] == before["adaptation_index"] - base
    from armgame.records.replay import Replay, now_iso

    path = tmp_path / "p.json"
    Replay(session.config, tuple(session.timeline), session.result(), "bot", "model", None, now_iso(),
           task=LabTask.of(session)).save(path)
    assert main(["analyze", str(path), "--out", str(tmp_path / "t"), "--subtract-baseline"]) == 0
    assert "no baseline channel trial to " in capsys.readouterr().out


@pytest.mark.parametrize(("argv", "representation"), [
    (["generalization"], "local"),  # the preset's point, without a flag (issue 39)
    (["generalization", "--representation", "global"], "global"),  # its control, by name
    (["curl"], "global"),
])
def test_the_generalization_preset_runs_the_local_learner_by_default(argv, representation, monkeypatch):
    import armgame.lab.bots

    made = []

    def capture(name, rates=None, representation="global", *rest, **options):
        made.append(representation)
        raise SystemExit(0)  # the learner chosen is all this test needs: no run
    monkeypatch.setattr(armgame.lab.bots, "make_lab_bot", capture)
    with pytest.raises(SystemExit):
        main(["lab", *argv, "--bot", "adaptive", "--headless"])
    assert made == [representation]
