"""The browser's engine (``armgame/classroom/static/engine.js``) is ``GameSession``, bit for bit.

One ``node`` process (``tests/engine_runner.mjs``) plays a batch of games through the engine; the same
configurations and key timelines are played by ``GameSession`` (its compiled loop, and its Python loop for
a share of them), and everything a game shows or hands in must be equal to the bit: score, hits, resets,
hit times, the final state, target, hand and activations, the recorded timeline and which events acted.
The games: 1,000 short random ones (taps, long holds, chords, repeats, resets, tab, unknown keys, events
at step 0 and at the clock's last steps, seeds near 0 and near 2^63 - 1, other arms, steps, keys and
targets), pairs of knife-edge games (a target radius one ulp either side of the hand's closest approach),
and full 60 s standard games whose replays, written by the engine, the server's ``Replay`` reads, verifies
and identifies as the Python game's.

Skipped only where ``node`` is missing and ``ARMGAME_REQUIRE_BROWSER`` is unset (CI sets it).
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import random
import shutil
import struct
import subprocess
import sys
from pathlib import Path

import pytest

import armgame
from armgame.game.bots import Autopilot, make_bot
from armgame.game.rules import GAME_PLAY_ARM, GameConfig, hand_position
from armgame.game.session import GameSession
from armgame.physics import trig
from armgame.records.identity import game_digest
from armgame.records.replay import Replay, config_from_dict, config_to_dict
from armgame.records.rulesets import REHEARSAL, class_game_name, config_digest

ROOT = Path(__file__).resolve().parent.parent
RUNNER = ROOT / "tests" / "engine_runner.mjs"
NODE = shutil.which("node")
if NODE is None and not os.environ.get("ARMGAME_REQUIRE_BROWSER"):
    pytest.skip("node (Node.js) is not installed, and ARMGAME_REQUIRE_BROWSER is unset: the browser's engine "
                "is not checked here (CI sets it)", allow_module_level=True)

SHORT_GAMES = 1000
TOP_SEED = 2**63 - 1
sys.path.insert(0, str(ROOT / "benchmarks"))
from class_speed import student_timeline  # noqa: E402


def bits(x: float) -> str:
    return struct.pack(">d", x).hex()


def run_node(request: dict) -> dict:
    assert NODE is not None, "ARMGAME_REQUIRE_BROWSER is set but node is not installed"
    done = subprocess.run([NODE, str(RUNNER)], input=json.dumps(request), capture_output=True, text=True,
                          timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


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
    """The standard game and its variants, a few seconds long, each with a random seed of some size."""
    seeds = (0, 1, 2, 3, TOP_SEED, TOP_SEED - 1, TOP_SEED - 2, 2**32 - 1, 2**32, 2**53 + 1)
    configs = []
    for i in range(SHORT_GAMES):
        seed = seeds[i] if i < len(seeds) else rng.choice(
            (rng.randrange(100), rng.randrange(2**32), rng.randrange(2**63), TOP_SEED - rng.randrange(100)))
        kind = i % 10
        arm, dt, radius, keys = GAME_PLAY_ARM, 0.004, 0.05, None
        if kind in (1, 2, 7):
            radius = rng.choice((0.15, 0.2, 0.25))  # hits come often
        elif kind == 3:
            arm = GAME_PLAY_ARM.replace(damping1=0.0, damping2=0.0)  # the unforced accel
        elif kind == 4:
            arm = GAME_PLAY_ARM.replace(gravity=9.81)  # the accel with gravity and damping
        elif kind == 5:
            dt = rng.choice((0.002, 0.005, 0.01))
        elif kind == 6:
            keys = "asdf"
        config = GameConfig(arm=arm, dt=dt, target_radius=radius, seed=seed, time_limit=rng.choice((1.0, 2.0, 3.0)))
        if keys:
            from armgame.game.muscles import remap_keys
            config = GameConfig(**{**config.__dict__, "muscles": remap_keys(config.muscles, keys)})
        configs.append(config)
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
    request["games"].append({"config": {**config_to_dict(GameConfig()), "integrator": "euler"}, "events": []})
    answer = run_node(request)
    return {"games": games, "knife": knife, "full": full, "answer": answer}


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


def test_configs_it_cannot_play_are_refused_in_one_line(played):
    error = played["answer"]["games"][-1]["error"]
    assert "RK4" in error and "euler" in error and "\n" not in error


def test_the_engine_names_this_armgame():
    assert run_node({})["armgame_version"] == armgame.__version__


def test_python_random_in_javascript():
    rng = random.Random(3)
    seeds = [0, 1, 2, 42, 2**31, 2**32 - 1, 2**32, 2**32 + 1, 2**53 - 1, 2**53 + 1, 2**62, TOP_SEED - 1, TOP_SEED]
    seeds += [rng.randrange(2**bits_) for bits_ in range(1, 64) for _ in range(3)]
    request = {"random": [[str(s), 5] for s in seeds] + [["12345678901234567890", 1500]]}
    answer = run_node(request)["random"]
    for (seed, count), got in zip(request["random"], answer, strict=True):
        python = random.Random(int(seed))
        assert got == [bits(python.random()) for _ in range(count)], seed


def test_the_arm_sine_the_muscle_rates_and_the_standard_config():
    rng = random.Random(4)
    angles = [0.0, -0.0, 1e-300, math.pi / 4, math.pi / 2, -math.pi, 1e15, -1e15, 1.0000001e15, 3.0e5, 700.0]
    angles += [rng.uniform(-10, 10) for _ in range(3000)] + [rng.uniform(-1e6, 1e6) for _ in range(500)]
    # the muscles' rates: -expm1(-dt / T) over replays' ranges (dt 1e-4 to 0.02 s, T from dt to 10 s)
    ratios = [-rng.uniform(1e-4, 0.02) / rng.uniform(1e-3, 10.0) for _ in range(3000)] + [-1.0, -20.0, -0.05, -0.04]
    seeds = [0, 10, 2**53 + 1, TOP_SEED]
    rehearsals = [[str(s), REHEARSAL.config.time_limit] for s in seeds]  # the rehearsal's clock, as its join says
    answer = run_node({"sin_cos": angles, "expm1": ratios, "standard": [str(s) for s in seeds] + rehearsals})
    for x, got in zip(angles, answer["sin_cos"], strict=True):
        want = [bits(v) for v in trig.sin_cos_python(x)]
        assert got == want == [bits(v) for v in trig.sin_cos(x)], x
    for x, got in zip(ratios, answer["expm1"], strict=True):
        assert got == bits(math.expm1(x)), x
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


def test_an_arm_whose_square_python_rounds_otherwise_is_refused():
    """Python's ``x ** 2`` is the C library's ``pow``, which glibc rounds within 0.52 ulp, not always as
    ``x * x``: the engine, which squares by multiplying, refuses an arm whose square lies that near a tie."""
    from fractions import Fraction

    rng = random.Random(6)
    near_ties = []
    for _ in range(100_000):
        x = rng.uniform(0.1, 0.3)
        square = x * x
        if abs(Fraction(x) ** 2 - Fraction(square)) > Fraction(math.ulp(square)) * 49 / 100:
            near_ties.append(x)
            if len(near_ties) == 3:
                break
    assert len(near_ties) == 3
    # The presets are far from ties (the engine plays them: the games above).
    arms = [GAME_PLAY_ARM.replace(r1=x) for x in near_ties]
    answer = run_node({"games": [{"config": config_dict(GameConfig(arm=arm)), "events": []} for arm in arms]})
    for got in answer["games"]:
        assert "r1" in got["error"] and "rounding tie" in got["error"] and "\n" not in got["error"]


def test_the_engine_is_served_and_needs_nothing_a_strict_page_refuses():
    """Served by name as JavaScript (an ES module must be); no imports, no eval, no C library trig."""
    from armgame.classroom import page

    source = (ROOT / "armgame" / "classroom" / "static" / "engine.js").read_text(encoding="utf-8")
    served = page.response("engine.js")
    assert served.status_code == 200 and served.media_type.startswith("text/javascript")
    assert served.body == source.encode("utf-8")
    code = "\n".join(line.split("//")[0] for line in source.splitlines())
    for banned in ("eval(", "new Function", "import ", "import(", "Math.sin", "Math.cos", "WebAssembly", "require("):
        assert banned not in code, banned
