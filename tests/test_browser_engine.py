"""The browser's engine (``armgame/classroom/static/engine.js``) is ``GameSession``, bit for bit.

One ``node`` process (``tests/engine_runner.mjs``) plays a batch of games through the engine; the same
configurations and key timelines are played by ``GameSession`` (its compiled loop, and its Python loop for
a share of them), and everything a game shows or hands in must be equal to the bit: score, hits, resets,
hit times, the final state, target, hand and activations, the recorded timeline and which events acted.
The games: 1,000 short random ones (taps, long holds, chords, repeats, resets, tab, unknown keys, events
at step 0 and at the clock's last steps, seeds near 0 and near 2^63 - 1, other clocks and target sizes), pairs
of knife-edge games (a target radius one ulp either side of the hand's closest approach),
and full 60 s standard games whose replays, written by the engine, the server's ``Replay`` reads, verifies
and identifies as the Python game's. The engine plays only the class's game (its arm, muscles and step: the
numbers in constants.js); any other config is refused in one line.

Skipped only where ``node`` is missing and ``ARMGAME_REQUIRE_BROWSER`` is unset (CI sets it).
"""

from __future__ import annotations

import dataclasses
import json
import math
import random
import sys
from pathlib import Path

import pytest
from node import bits, run_node, skip_without_node

import armgame
from armgame.game.bots import Autopilot, make_bot
from armgame.game.muscles import remap_keys
from armgame.game.rules import GAME_PLAY_ARM, GameConfig, hand_position
from armgame.game.session import GameSession
from armgame.physics import trig
from armgame.records.identity import game_digest
from armgame.records.replay import Replay, config_from_dict, config_to_dict
from armgame.records.rulesets import REHEARSAL, class_game_name, config_digest

ROOT = Path(__file__).resolve().parent.parent
RUNNER = ROOT / "tests" / "engine_runner.mjs"
skip_without_node("the browser's engine is not checked here")

SHORT_GAMES = 1000
TOP_SEED = 2**63 - 1
sys.path.insert(0, str(ROOT / "benchmarks"))
from class_speed import student_timeline  # noqa: E402


def config_dict(config: GameConfig) -> dict:
    """A config as the page gets it: JSON, with a seed above 2^53 as its decimal string (a JS Number would
    round it)."""
    data = config_to_dict(config)
    if config.seed > 2**53:
        data["seed"] = str(config.seed)
    return data


def random_events(rng: random.Random, total: int) -> list[list]:
    """A random timeline: taps, holds, chords, repeats, resets, tab and unknown keys, edges included."""
    events = []
    for _ in range(rng.choice((0, 3, 10, 30, 60))):
        step = rng.choice((0, 0, total - 1, total, rng.randrange(total), rng.randrange(total)))
        key = rng.choice(("d", "f", "j", "k", "d", "f", "j", "k", "space", "tab", "x", "Escape", "D"))
        action = rng.choice(("down", "down", "up", "press"))
        events.append([step, key, action])
        if key in "dfjk" and rng.random() < 0.6:  # a tap or a long hold, released later; sometimes a chord
            events.append([min(total, step + rng.choice((0, 1, 2, 10, 80, 400))), key, "up"])
            if rng.random() < 0.3:
                events.append([step, rng.choice("dfjk"), "down"])
    events.sort(key=lambda e: e[0])
    return events


def short_configs(rng: random.Random) -> list[GameConfig]:
    """The class's game, a few seconds long, each with a random seed of some size, some with wide targets."""
    seeds = (0, 1, 2, 3, TOP_SEED, TOP_SEED - 1, TOP_SEED - 2, 2**32 - 1, 2**32, 2**53 + 1)
    configs = []
    for i in range(SHORT_GAMES):
        seed = seeds[i] if i < len(seeds) else rng.choice(
            (rng.randrange(100), rng.randrange(2**32), rng.randrange(2**63), TOP_SEED - rng.randrange(100)))
        radius = rng.choice((0.15, 0.2, 0.25)) if i % 10 in (1, 2, 3, 7) else 0.05  # wide ones: hits come often
        configs.append(GameConfig(target_radius=radius, seed=seed, time_limit=rng.choice((1.0, 2.0, 3.0))))
    return configs


def play_python(config: GameConfig, events: list, compiled: bool, stop: int | None = None) -> tuple[GameSession, dict]:
    """``TimelineInput.run_to``'s way, recording which events acted."""
    session = GameSession(config, compiled=compiled)
    limit = min(session.total_steps if stop is None else stop, session.total_steps)
    applied = []
    for step, key, action in events:
        if step > limit:
            break
        session.advance(step - session.steps)
        applied.append(session.key_event(key, action))
    session.advance(limit - session.steps)
    board, target = session.rules.board, session.rules.target
    return session, {
        "score": board.score, "hits": board.hits, "resets": board.resets, "steps": session.steps,
        "hit_times": [bits(t) for t in board.hit_times], "state": [bits(v) for v in session.state],
        "target": [bits(target.x), bits(target.y), bits(target.radius)],
        "hand": [bits(v) for v in hand_position(config.arm.l1, config.arm.l2, *session.state[:2])],
        "timeline": [[e.step, e.key, e.action] for e in session.timeline], "applied": applied,
        "tries": session.rules.tries, "arm_visible": session.rules.arm_visible,
        "activation": [bits(a) for a in session.muscles.activation],
        "interpolated": [bits(a) for a in session.interpolated_angles(0.25)], "time_left": bits(session.time_left),
    }


def knife_edge_games(count: int) -> list[tuple[GameConfig, list]]:
    """Pairs of games whose first hit is decided by one ulp of the target's radius.

    A random timeline is played step by step with a radius of 8 cm until its first hit, keeping the hand's
    closest approach to the first target (the squared distance d2 at some step). The same game with the
    smallest radius r whose r * r >= d2 hits there, and with the next radius down it misses: the hand grazes
    the target's edge to the last bit, where a hand an ulp off would decide the other way. Kept where the
    Python shows exactly that (a radius can also move the first target: then that pair is not used)."""
    rng = random.Random(38)
    out: list[tuple[GameConfig, list]] = []
    seed = 0
    while len(out) < 2 * count and seed < 40 * count:
        seed += 1
        config = GameConfig(seed=seed, time_limit=2.0, target_radius=0.08)
        events = random_events(rng, config.total_steps)
        session = GameSession(config, compiled=False)
        best, best_step, pending = math.inf, -1, list(events)
        while not session.over and session.rules.board.hits == 0:
            while pending and pending[0][0] <= session.steps:
                session.key_event(*pending.pop(0)[1:])
            session.advance(1)
            if session.rules.board.hits:
                break
            hx, hy = hand_position(config.arm.l1, config.arm.l2, *session.state[:2])
            target = session.rules.target
            d2 = (hx - target.x) * (hx - target.x) + (hy - target.y) * (hy - target.y)
            if d2 < best:
                best, best_step = d2, session.steps
        if best_step < 0 or math.sqrt(best) > 0.1:  # wider targets make hit storms: slow, and no sharper
            continue
        r = math.sqrt(best)
        while r * r < best:
            r = math.nextafter(r, math.inf)
        while math.nextafter(r, 0.0) * math.nextafter(r, 0.0) >= best:
            r = math.nextafter(r, 0.0)
        hit = GameConfig(**{**config.__dict__, "target_radius": r})
        miss = GameConfig(**{**config.__dict__, "target_radius": math.nextafter(r, 0.0)})
        _, with_hit = play_python(hit, events, compiled=True)
        _, with_miss = play_python(miss, events, compiled=True)
        first = bits(best_step * config.dt)
        if with_hit["hit_times"][:1] == [first] and first not in with_miss["hit_times"]:
            out += [(hit, events), (miss, events)]
    return out


@pytest.fixture(scope="module")
def played() -> dict:
    rng = random.Random(2026)
    games = []
    for i, config in enumerate(short_configs(rng)):
        if i % 10 == 8:  # a bot's keys, which hit targets as no random script does
            bot = GameSession(config)
            Autopilot(bot, make_bot(("model", "naive")[i % 20 // 10])).play()
            games.append((config, [[e.step, e.key, e.action] for e in bot.timeline]))
        else:
            games.append((config, random_events(rng, config.total_steps)))
    knife = knife_edge_games(6)
    full = [(GameConfig(seed=seed), [[e.step, e.key, e.action] for e in
                                     student_timeline(random.Random(seed % 1000), 0.004, 60.0)])
            for seed in (10, 0, TOP_SEED)]
    bot = GameSession(GameConfig(seed=7))
    Autopilot(bot, make_bot("model")).play()
    full.append((GameConfig(seed=7), [[e.step, e.key, e.action] for e in bot.timeline]))
    everything = games + knife + full
    request = {"games": [{"config": config_dict(c), "events": e, "frame": rng.choice((1, 3, 16, 250, 10**6)),
                          "replay": f"Player {i}" if i >= len(games) + len(knife) else None}
                         for i, (c, e) in enumerate(everything)]}
    answer = run_node(RUNNER, request)
    return {"games": games, "knife": knife, "full": full, "answer": answer}


@pytest.mark.slow  # node's 1,000 games (3 s): CI's slow tier; the suite plays test_golden's game through the engine
def test_short_random_games_are_the_python_games_bit_for_bit(played):
    games, answer = played["games"], played["answer"]["games"]
    assert len(games) >= 1000
    hits = resets = hidden = ignored = 0
    for i, (config, events) in enumerate(games):
        _, want = play_python(config, events, compiled=True)
        assert answer[i] == want, f"game {i} (seed {config.seed}): the engine and the compiled loop differ"
        if i % 4 == 0:  # the Python loop, the compiled one's reference
            assert play_python(config, events, compiled=False)[1] == want
        hits += want["hits"]
        resets += want["resets"]
        hidden += not want["arm_visible"]
        ignored += want["applied"].count(False)
    # The games did what they are for: hits, resets, tab, and events the session ignores.
    assert hits >= 150 and resets >= 100 and hidden >= 100 and ignored >= 1000, (hits, resets, hidden, ignored)


@pytest.mark.slow  # the same node run: CI's slow tier
def test_knife_edge_hits_are_decided_alike(played):
    knife, answer = played["knife"], played["answer"]["games"]
    start = len(played["games"])
    assert len(knife) >= 6, "too few knife-edge games found"
    for j, (config, events) in enumerate(knife):
        _, want = play_python(config, events, compiled=True)
        assert answer[start + j] == want
        assert play_python(config, events, compiled=False)[1] == want
    # each pair: one ulp of radius apart, a hit and a miss at the graze
    assert all(answer[start + j]["hit_times"][:1] != answer[start + j + 1]["hit_times"][:1]
               for j in range(0, len(knife), 2))


@pytest.mark.slow  # the same node run: CI's slow tier
def test_full_games_hand_in_replays_the_server_verifies(played):
    full, answer = played["full"], played["answer"]["games"]
    start = len(played["games"]) + len(played["knife"])
    for j, (config, events) in enumerate(full):
        session, want = play_python(config, events, compiled=True)
        got = answer[start + j]
        assert {k: v for k, v in got.items() if k != "replay"} == want
        assert want["steps"] == 15000 and want["hits"] > 0
        replay = Replay.from_bytes(got["replay"].encode("utf-8"), "the engine's replay")
        ok, recomputed = replay.verify()
        assert ok, recomputed
        assert replay.config == config and replay.player == f"Player {start + j}"
        assert (replay.driven, replay.driver, replay.version) == ("keyboard", "browser", armgame.__version__)
        python_replay = Replay.from_session(session, "keyboard", None, "someone")
        assert replay.result == python_replay.result
        assert game_digest(replay) == game_digest(python_replay)


OTHER_GAMES = {
    "arm": GameConfig(arm=GAME_PLAY_ARM.replace(damping1=0.0, damping2=0.0)),  # the unforced accel
    "gravity": GameConfig(arm=GAME_PLAY_ARM.replace(gravity=9.81)),
    "r1": GameConfig(arm=GAME_PLAY_ARM.replace(r1=0.18)),
    "dt": GameConfig(dt=0.002),
    "keys": GameConfig(muscles=remap_keys(GameConfig().muscles, "asdf")),
    "moment": GameConfig(muscles=(dataclasses.replace(GameConfig().muscles[0], moment=(1.6, 0.0)),
                                  *GameConfig().muscles[1:])),
    "rise": GameConfig(muscles=(dataclasses.replace(GameConfig().muscles[0], rise_time=0.09),
                                *GameConfig().muscles[1:])),
    "range": GameConfig(target_elbow_range=(40.0, 90.0)),
    "euler": GameConfig(integrator="euler"),
}


def test_configs_it_cannot_play_are_refused_in_one_line():
    """The engine plays the class's game only: another arm, step, muscle or integrator is refused, naming it."""
    request = {"games": [{"config": config_dict(c), "events": []} for c in OTHER_GAMES.values()]}
    answer = run_node(RUNNER, request)["games"]
    names = {"arm": "arm", "gravity": "arm", "r1": "arm", "dt": "dt", "keys": "muscles", "moment": "muscles",
             "rise": "muscles", "range": "target_elbow_range", "euler": "euler"}
    for (kind, config), got in zip(OTHER_GAMES.items(), answer, strict=True):
        assert config != GameConfig(), kind
        assert "error" in got and names[kind] in got["error"] and "\n" not in got["error"], (kind, got)


def test_the_engine_names_this_armgame():
    assert run_node(RUNNER, {})["armgame_version"] == armgame.__version__


def test_python_random_in_javascript():
    rng = random.Random(3)
    seeds = [0, 1, 2, 42, 2**31, 2**32 - 1, 2**32, 2**32 + 1, 2**53 - 1, 2**53 + 1, 2**62, TOP_SEED - 1, TOP_SEED]
    seeds += [rng.randrange(2**bits_) for bits_ in range(1, 64) for _ in range(3)]
    request = {"random": [[str(s), 5] for s in seeds] + [["12345678901234567890", 1500]]}
    answer = run_node(RUNNER, request)["random"]
    for (seed, count), got in zip(request["random"], answer, strict=True):
        python = random.Random(int(seed))
        assert got == [bits(python.random()) for _ in range(count)], seed


def test_the_arm_sine_and_the_standard_config():
    rng = random.Random(4)
    angles = [0.0, -0.0, 1e-300, math.pi / 4, math.pi / 2, -math.pi, 1e15, -1e15, 1.0000001e15, 3.0e5, 700.0]
    angles += [rng.uniform(-10, 10) for _ in range(3000)] + [rng.uniform(-1e6, 1e6) for _ in range(500)]
    seeds = [0, 10, 2**53 + 1, TOP_SEED]
    rehearsals = [[str(s), REHEARSAL.config.time_limit] for s in seeds]  # the rehearsal's clock, as its join says
    answer = run_node(RUNNER, {"sin_cos": angles, "standard": [str(s) for s in seeds] + rehearsals})
    for x, got in zip(angles, answer["sin_cos"], strict=True):
        want = [bits(v) for v in trig.sin_cos_python(x)]
        assert got == want == [bits(v) for v in trig.sin_cos(x)], x
    for seed, text in zip(seeds, answer["standard"][:len(seeds)], strict=True):
        data = json.loads(text)
        assert data == config_to_dict(GameConfig(seed=seed))
        assert config_from_dict(data) == GameConfig(seed=seed)
    for seed, text in zip(seeds, answer["standard"][len(seeds):], strict=True):
        config = config_from_dict(json.loads(text))  # as the class reads the replay's config
        assert config == dataclasses.replace(REHEARSAL.config, seed=seed)
        assert class_game_name(config) == "rehearsal" and config_digest(config) == REHEARSAL.digest


def test_a_hit_is_decided_on_the_rules_hand():
    """The session's hand for a hit is ``hand_position`` (the arm's sine), not the C library's, in both loops."""
    config = GameConfig(seed=5, time_limit=10.0)
    for compiled in (True, False):
        session = GameSession(config, compiled=compiled)
        seen = []
        hand_moved, advance = session.rules.hand_moved, session.advance

        def record(x: float, y: float, t: float, hand_moved=hand_moved, seen=seen) -> bool:
            seen.append((x, y))
            return hand_moved(x, y, t)

        def one_step(n: int, advance=advance, session=session, seen=seen) -> int:
            ran = 0
            for _ in range(n):
                ran += advance(1)
                if seen:
                    assert seen.pop() == hand_position(config.arm.l1, config.arm.l2, *session.state[:2])
            return ran

        session.rules.hand_moved, session.advance = record, one_step
        Autopilot(session, make_bot("model")).play()
        assert session.rules.board.hits >= 3


def test_the_engine_is_served_and_needs_nothing_a_strict_page_refuses():
    """Served by name as JavaScript (an ES module must be), with the constants it imports, its only import; no eval,
    no C library trig."""
    import re

    from armgame.classroom import page

    for name in ("engine.js", "constants.js"):
        source = (ROOT / "armgame" / "classroom" / "static" / name).read_text(encoding="utf-8")
        served = page.response(name)
        assert served.status_code == 200 and served.media_type.startswith("text/javascript")
        assert served.body == source.encode("utf-8")
        code = "\n".join(line.split("//")[0] for line in source.splitlines())
        assert re.findall(r'from "([^"]*)"', code) == (["./constants.js"] if name == "engine.js" else [])
        code = re.sub(r'import \{[^}]*\} from "./constants.js";', "", code)
        banned = ("eval(", "new Function", "import ", "import(", "Math.sin", "Math.cos", "WebAssembly", "require(")
        assert not [word for word in banned if word in code], name


def test_the_engine_speed_the_docs_give_is_the_committed_run():
    """docs/development.md's "a 60 s game in X ms" is benchmarks/browser_engine_speed.py's committed run."""
    root = Path(__file__).resolve().parent.parent
    run = json.loads((root / "benchmarks" / "results" / "browser_engine_speed.json").read_text(encoding="utf-8"))
    prose = " ".join((root / "docs" / "development.md").read_text(encoding="utf-8").split())
    assert run["steps_a_game"] == 15000 and run["node"].startswith("v20.") and len(run["ms"]) == run["games"]
    assert run["best_ms"] == min(run["ms"]) and run["median_ms"] == sorted(run["ms"])[len(run["ms"]) // 2]
    assert (f"in {run['best_ms']:.1f} ms at best of {run['games']} games in Node 20, {run['median_ms']:.1f} ms the "
            f"median") in prose
    assert f"load average {run['load_average'][0]:.1f}), some {run['us_a_step_best']:.2f} us a step" in prose
