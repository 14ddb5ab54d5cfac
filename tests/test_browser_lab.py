"""The browser's lab (``armgame/classroom/static/labengine.js``) is ``LabSession(sine="arm")``, bit for bit.

The server hands the page a run's plan (``armgame.lab.plan.lab_plan``: its config, protocol and every trial resolved
to numbers); one ``node`` process (``tests/lab_runner.mjs``) plays a batch of runs on their plans and random key
timelines, and ``LabSession`` plays the same timelines. Everything must be equal to the bit: every trial's record
(target, go-cue step, end step, hit), the SHA-256 of every trial's shown hand path (each sample's bits), the final
state, activations, cursor, target and home, score, hits, resets, the timeline and which events acted, and where
space sent the hand home in a reach. The runs cover every preset (its first trials, at its own timing) and every
preset again at a quick timing (short delays, holds and time-outs, so that a run of a few thousand steps reaches
the later blocks: posture changes, channel trials, no-cursor probes), and protocols no preset has (a joint viscous
field, a constant force and a spring, endpoint feedback, random probes, a mix with the opposite field, a display in
joint space at a second posture). A browser's run of a whole lab, handed in as a replay, verifies.

Skipped only where ``node`` is missing and ``ARMGAME_REQUIRE_BROWSER`` is unset (CI sets it).
"""

from __future__ import annotations

import dataclasses
import json
import random
import re
import urllib.request
from pathlib import Path

import pytest
from class_server import running_class
from node import bits, run_node, skip_without_node

from armgame.classroom import client
from armgame.game.bots import Autopilot
from armgame.game.session import InputEvent
from armgame.lab.bots import make_lab_bot
from armgame.lab.perturbations import NONE, Constant, Curl, JointSpace, JointViscous, Mirror, Rotation, Spring, Viscous
from armgame.lab.plan import class_plan_json, lab_plan
from armgame.lab.presets import PRESETS, preset
from armgame.lab.protocol import Block, Protocol
from armgame.lab.record import LabTask, paths_digest
from armgame.lab.session import LabSession, lab_config
from armgame.records.replay import Replay

ROOT = Path(__file__).resolve().parent.parent
RUNNER = ROOT / "tests" / "lab_runner.mjs"
skip_without_node("the browser's lab is not checked here")

TOP_SEED = 2**63 - 1
RUNS = 520
#: How far a run goes (physics steps): up to 10 s of the lab, a few trials of a preset, a dozen or more at quick
#: timing. The slow tier's sweep goes further (``test_a_longer_sweep``).
STOP_STEPS = (800, 1500, 2500)


def quick(protocol: Protocol) -> Protocol:
    """The protocol at a quick timing: go cues after 40 to 120 ms, a 40 ms hold, time-outs at 0.6 s."""
    return dataclasses.replace(protocol, name=f"{protocol.name}-quick", delay=(0.04, 0.12), hold_time=0.04,
                               timeout=0.6)


def own_protocols() -> list[Protocol]:
    """What no preset has: each load and display kind, endpoint feedback, random probes, an opposite mix."""
    timing = {"delay": (0.04, 0.1), "hold_time": 0.04, "timeout": 0.5}
    return [
        Protocol("joint-viscous", (
            Block("baseline", 4),
            Block("exposure", 12, JointViscous(0.06, -1.0, 1.1, 0.05), catch_trials=2, channel_trials=2,
                  probe_feedback="endpoint"),
            Block("test", 8, JointViscous(0.06, -1.0, 1.1, 0.05), home_posture_deg=(100.0, 70.0), channel_trials=8),
        ), targets=4, **timing),
        Protocol("loads", (
            Block("constant", 6, Constant(1.5, -2.0), feedback="endpoint"),
            Block("spring", 8, Spring(120.0), catch_trials=2, channel_trials=2, probe_feedback="none"),
            Block("curl", 8, Curl(-6.0), channel_trials=2),
        ), targets=4, probe_schedule="random", channel_stiffness=3000.0, channel_damping=40.0, **timing),
        Protocol("mixed", (
            Block("mix", 16, Viscous(-1.0, -1.5, -1.5, 1.2), mix=("on", "off", "opposite"), channel_trials=2),
            Block("rotation", 8, Rotation(-45.0), mix=("on", "opposite"), feedback="endpoint"),
        ), targets=4, first_target_deg=22.5, **timing),
        Protocol("postures", (
            Block("here", 4, JointSpace(0.3)),
            Block("there", 8, Mirror(30.0), home_posture_deg=(60.0, 110.0), catch_trials=2, probe_feedback="none"),
            Block("back", 4, NONE),
            Block("joint", 6, JointSpace(0.5), home_posture_deg=(30.0, 80.0)),
        ), targets=4, distance=0.08, target_radius=0.015, home_radius=0.015, **timing),
    ]


def protocols() -> list[Protocol]:
    presets = [preset(name) for name in PRESETS]
    return presets + [quick(p) for p in presets] + own_protocols()


def random_timeline(rng: random.Random, stop: int) -> list[list]:
    """A student at random: space brings the hand home (so go cues come), a wait, then taps and holds of the
    muscle keys (sometimes chords, repeats, a space in mid-reach, tab or a key the lab has no use for)."""
    events: list[list] = []
    step = rng.randrange(0, 40)
    while step < stop:
        events.append([step, "space", "down"])
        events.append([step + rng.choice((0, 1, 5)), "space", "up"])
        step += rng.choice((1, 20, 60, 150, 300))
        for _ in range(rng.choice((0, 1, 2, 3, 5))):
            key = rng.choice("dfjk")
            events.append([step, key, "down"])
            if rng.random() < 0.3:
                events.append([step + rng.randrange(3), rng.choice("dfjk"), "down"])
            events.append([step + rng.choice((1, 8, 20, 40, 90)), key, "up"])
            step += rng.choice((0, 5, 15, 40))
        if rng.random() < 0.1:
            key = rng.choice(("space", "tab", "x", "d"))
            events.append([step + rng.randrange(30), key, rng.choice(("down", "up"))])
        step += rng.choice((10, 60, 150, 400, 800))
    for k in ("d", "f", "j", "k"):  # nothing held at the end, so a run left alone stops moving
        events.append([step, k, "up"])
    events.sort(key=lambda e: e[0])
    return [e for e in events if e[0] <= stop + 1000]


def play_python(config, protocol, events: list, stop: int, compiled: bool = True,
                sine: str = "arm") -> tuple[LabSession, dict]:
    """``TimelineInput.run_to``'s way, recording which events acted."""
    session = LabSession(config, protocol, compiled=compiled, sine=sine)
    limit = min(stop, session.total_steps)
    applied = []
    for step, key, action in events:
        if step > limit:
            break
        session.advance(step - session.steps)
        applied.append(session.key_event(key, action))
    session.advance(limit - session.steps)
    board, target = session.rules.board, session.rules.target
    return session, {
        "trials": [list(t) for t in session.trial_records()], "steps": session.steps, "score": board.score,
        "hits": board.hits, "resets": board.resets, "finished": session.finished, "phase": session.phase,
        "trial_index": session.trial_index, "state": [bits(v) for v in session.state],
        "cursor": [bits(v) for v in session.cursor], "activation": [bits(a) for a in session.muscles.activation],
        "target": [bits(target.x), bits(target.y), bits(target.radius)], "home": [bits(v) for v in session.home],
        "home_at": [o.home_at for o in session.outcomes], "paths_sha256": paths_digest(session),
        "timeline": [[e.step, e.key, e.action] for e in session.timeline], "applied": applied,
    }


def sweep(count: int, stops: tuple[int, ...], seed: int) -> dict:
    """``count`` random runs across the protocols, each to one of ``stops``, through both engines."""
    rng = random.Random(seed)
    seeds = (0, 1, TOP_SEED, 2**53 + 1)
    plans, configs = [], []
    for i, protocol in enumerate(protocols()):
        seed = seeds[i] if i < len(seeds) else rng.choice((rng.randrange(1000), rng.randrange(2**63)))
        config = lab_config(protocol, seed, person=True)
        configs.append((config, protocol))
        plans.append(lab_plan(config, protocol))
    runs, expected = [], []
    for i in range(count):
        plan = i % len(plans)
        stop = rng.choice(stops)
        events = random_timeline(rng, stop)
        # Frames of one step, of a page's few, of the window's (never past a trial's soonest end), or all at once.
        runs.append({"plan": plan, "events": events, "stop": stop, "frame": rng.choice((0, 1, 4, 1_000_000))})
        expected.append(play_python(*configs[plan], events, stop, compiled=i % 25 != 7)[1])
    # Whole runs handed in: the lesson by the adapting bot (its keys reach and hit, as a student's do), and a
    # quick frames run at random.
    whole = []
    for name in ("lesson", "frames"):
        protocol = preset(name) if name == "lesson" else quick(preset(name))
        config = lab_config(protocol, 77, person=True)
        plans.append(lab_plan(config, protocol))
        configs.append((config, protocol))
        if name == "lesson":
            bot = LabSession(config, protocol, sine="arm")
            Autopilot(bot, make_lab_bot("adaptive")).play()
            events = [[e.step, e.key, e.action] for e in bot.timeline]
        else:
            events = random_timeline(rng, config.total_steps)
        runs.append({"plan": len(plans) - 1, "events": events, "stop": config.total_steps, "frame": 0,
                     "replay": "ada"})
        session, out = play_python(config, protocol, events, config.total_steps)
        expected.append(out)
        whole.append((session, len(runs) - 1))
    answer = run_node(RUNNER, {"plans": plans, "runs": runs}, timeout=300)
    return {"runs": runs, "expected": expected, "answer": answer, "whole": whole, "plans": plans, "configs": configs}


@pytest.fixture(scope="module")
def played() -> dict:
    return sweep(RUNS, STOP_STEPS, 50)


def same_runs(played: dict) -> None:
    got, expected = played["answer"]["runs"], played["expected"]
    assert len(got) == len(expected)
    for i, (mine, theirs) in enumerate(zip(got, expected, strict=True)):
        assert "error" not in mine, (i, mine)
        mine = {k: v for k, v in mine.items() if k != "replay"}
        assert mine == theirs, f"run {i} (plan {played['runs'][i]['plan']}) differs from LabSession"


@pytest.mark.slow  # node's 520 runs against LabSession (3 s): CI's slow tier; the suite keeps test_lab_page's lesson
def test_random_lab_runs_are_labsession_bit_for_bit(played):
    assert len(played["runs"]) >= 500
    same_runs(played)


@pytest.mark.slow  # the same node run: CI's slow tier
def test_the_c_librarys_sine_is_not_the_browsers(played):
    """Why the browser's runs take the arm's own sine: on the C library's, most of the same runs record other paths
    (their replays would not verify), and the fields' runs end in other states."""
    runs, got = played["runs"][:150], played["answer"]["runs"]
    paths = states = 0
    for i, run in enumerate(runs):
        theirs = play_python(*played["configs"][run["plan"]], run["events"], run["stop"], sine="library")[1]
        paths += theirs["paths_sha256"] != got[i]["paths_sha256"]
        states += theirs["state"] != got[i]["state"]
        assert theirs["trials"] == got[i]["trials"]  # an ulp decides a trial only on a knife's edge
    assert paths > len(runs) // 2 and states >= 1, (paths, states)


@pytest.mark.slow
def test_a_longer_sweep():
    """1,500 runs, each to 20 to 80 s of the lab: later blocks of the presets at their own timing."""
    same_runs(sweep(1500, (5000, 10000, 20000), 51))


@pytest.mark.slow  # the same node run: CI's slow tier
def test_the_runs_reach_what_they_are_meant_to_hold(played):
    """The random runs are not idle: they reach every block kind and every way a trial ends."""
    plans, runs, expected = played["plans"], played["runs"], played["expected"]
    seen: set[str] = set()
    for run, out in zip(runs, expected, strict=True):
        trials = plans[run["plan"]]["trials"]
        for i in range(len(out["trials"])):
            t = trials[i]
            load = t["load"] or {}
            seen |= {f"load {load['hand'][0]}" for _ in [0] if "hand" in load}
            seen |= {"joint load" for _ in [0] if "joint" in load}
            seen |= {f"display {t['display'][0]}" for _ in [0] if t["display"]}
            seen |= {"channel"} if t["channel"] else set()
            seen |= {"catch"} if t["catch"] else set()
            seen |= {f"feedback {t['feedback']}"}
            seen |= {"second posture"} if t["home_q"] != plans[run["plan"]]["home_q"] else set()
            seen |= {"hit"} if out["trials"][i][3] else {"miss"}
        seen |= {"home in a reach"} if any(h is not None for h in out["home_at"]) else set()
    assert seen >= {"load curl", "load viscous", "load constant", "load spring", "joint load", "display linear",
                    "display joint", "channel", "catch", "feedback full", "feedback endpoint", "feedback none",
                    "second posture", "hit", "miss", "home in a reach"}, seen
    assert sum(len(out["trials"]) for out in expected) > 2500


@pytest.mark.slow  # the same node run: CI's slow tier
def test_a_browser_lab_run_hands_in_a_replay_the_server_verifies(played):
    for session, index in played["whole"]:
        text = played["answer"]["runs"][index]["replay"]
        replay = Replay.from_bytes(text.encode())
        assert isinstance(replay.task, LabTask) and replay.task.sine == "arm"
        assert session.finished and replay.task.trials == tuple(tuple(t) for t in session.trial_records())
        assert replay.verify()[0], "the browser's lab replay does not verify"
        assert replay.driver == "browser" and replay.player == "ada"
        if index == played["whole"][0][1]:
            assert session.rules.board.hits >= 12, "the bot's lesson hits most targets"
        # One key one step later, in a reach: its path differs, and the replay no longer verifies.
        data = json.loads(text)
        reaches = [(g, e) for _t, g, e, _h in session.trial_records()]
        line = data["timeline"]
        i = next(i for i, e in enumerate(line[:-1]) if e[1] in "dfjk" and line[i + 1][0] > e[0] + 1
                 and any(go < e[0] < end for go, end in reaches))
        line[i][0] += 1
        assert not Replay.from_bytes(json.dumps(data).encode()).verify()[0]


@pytest.mark.slow  # the same node run: CI's slow tier
def test_a_replay_without_the_sine_is_the_c_librarys_as_before(played):
    """Lab replays recorded before the browser's lab (no ``sine`` in the task) replay on the C library's sine, as
    they were recorded; the same timeline on the arm's sine is another run's paths."""
    protocol = preset("curl")
    config = lab_config(protocol, 3)
    events = random_timeline(random.Random(3), 3000)
    timeline = [InputEvent(*e) for e in events]
    library = LabSession(config, protocol)
    library.play(timeline, 3000)
    arm = LabSession(config, protocol, sine="arm")
    arm.play(timeline, 3000)
    task = LabTask.of(library)
    assert task.sine == "library" and "sine" not in task.as_dict()
    assert LabTask.of(arm).as_dict()["sine"] == "arm"
    assert paths_digest(library) != paths_digest(arm)
    read = LabTask.from_dict(json.loads(json.dumps(task.as_dict())), config, 3000)
    assert read.verify(config, library.timeline, library.result())[0]


def test_the_class_serves_its_plan_and_takes_the_browsers_run_into_its_curve(tmp_path, monkeypatch):
    """``/api/labplan``: the teacher's protocol (the lesson's until one is chosen) resolved for the class's seed; the
    run the browser plays on it, handed in, is verified by the class and enters its curve."""
    def get(opened, path: str) -> dict:
        with urllib.request.urlopen(f"http://127.0.0.1:{opened.port}{path}", timeout=10) as r:
            return json.loads(r.read())

    with running_class(tmp_path / "class", seed=2**63 - 5) as opened:
        plan = get(opened, "/api/labplan")
        protocol = preset("lesson")
        config = lab_config(protocol, 2**63 - 5, person=True)
        assert plan == lab_plan(config, protocol) and plan["config"]["seed"] == str(2**63 - 5)
        assert class_plan_json(protocol, 2**63 - 5) == class_plan_json(protocol, 2**63 - 5)  # made once
        bot = LabSession(config, protocol, sine="arm")
        Autopilot(bot, make_lab_bot("adaptive")).play()
        events = [[e.step, e.key, e.action] for e in bot.timeline]
        answer = run_node(RUNNER, {"plans": [plan], "runs": [{"plan": 0, "events": events, "stop": config.total_steps,
                                                              "frame": 4, "replay": "Ann"}]}, timeout=300)
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "ann"))
        ann = client.join(client.ClassAddress.parse(f"127.0.0.1:{opened.port}"), opened.clerk.roster.code, "Ann",
                          lab=True)
        handed = client.hand_in(ann, answer["runs"][0]["replay"].encode())
        assert handed.message == "lab run handed in: in the class curve"
        assert get(opened, "/api/lab")["students"] == 1
        # The teacher chooses another protocol (from the teacher's own machine): the plan follows.
        req = urllib.request.Request(f"http://127.0.0.1:{opened.port}/api/teacher/lab",
                                     data=json.dumps({"protocol": "curl"}).encode(),
                                     headers={"Content-Type": "application/json"})
        urllib.request.urlopen(req, timeout=10).close()
        assert get(opened, "/api/labplan")["protocol"]["name"] == "curl"
    assert [run.player for run in opened.clerk.lab_runs] == ["Ann"]


@pytest.mark.slow  # the same node run: CI's slow tier
def test_plans_it_cannot_play_are_refused_in_one_line(played):
    plan = played["plans"][0]
    bad = [{**plan, "format": "x"}, {**plan, "sine": "library"}, {**plan, "trials": []},
           {**plan, "config": {**plan["config"], "scene": "game"}}]
    answer = run_node(RUNNER, {"plans": bad, "runs": [{"plan": i, "events": [], "stop": 10, "frame": 1}
                               for i in range(4)]}, timeout=300)
    errors = [r.get("error", "") for r in answer["runs"]]
    assert all(e and "\n" not in e for e in errors), errors


def test_the_lab_engine_needs_nothing_a_strict_page_refuses():
    """An ES module importing only the game's engine; no eval, no WebAssembly, no C library trig, no randomness."""
    source = (ROOT / "armgame" / "classroom" / "static" / "labengine.js").read_text(encoding="utf-8")
    code = "\n".join(line.split("//")[0] for line in source.splitlines())
    assert len(re.findall(r"^import ", code, re.MULTILINE)) == 1
    assert re.findall(r'from "([^"]*)"', code) == ["./engine.js"]
    for banned in ("eval(", "new Function", "import(", "Math.sin", "Math.cos", "Math.random", "WebAssembly",
                   "require(", "crypto."):
        assert banned not in code, banned
