"""The batched session against the single one: same hits, score, resets and steps, states to round-off.

The main tests run on both kernels: numpy, and the compiled one (bit for bit everywhere).
``ARMGAME_REQUIRE_COMPILED=1`` (set by ``.ci/run``) makes a missing build fail here instead of
leaving the compiled kernel untested.
"""

import functools
import itertools
import math
import os
import random
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from armgame.errors import UserError
from armgame.game.batch import STATE_TOLERANCE, BatchGameSession, batch_problem, compiled, replay_many
from armgame.game.muscles import DEFAULT_MUSCLES, MuscleLevelError, MuscleSet, MuscleSpec, remap_keys
from armgame.game.rules import GAME_PLAY_ARM, GameConfig, Target
from armgame.game.session import GameSession, InputEvent, TimelineInput
from armgame.records.replay import Replay

KEYS = ("d", "f", "j", "k")


KERNELS = ["numpy", "compiled"] if compiled.AVAILABLE or os.environ.get("ARMGAME_REQUIRE_COMPILED") else ["numpy"]


def batch_of(configs, kernel: str) -> BatchGameSession:
    batch = BatchGameSession(configs, kernel=kernel)
    assert (batch.compiled is not None) == (kernel == "compiled" and configs[0].integrator == "rk4")
    return batch


def student_timeline(rng: random.Random, dt: float, seconds: float, extras: bool = True) -> list[InputEvent]:
    """Keys switching every 0.1-0.5 s as a student's do; with ``extras``, resets, tab and stray keys too."""
    events, held, t = [], set(), 0.0
    while True:
        t += rng.uniform(0.1, 0.5)
        if t >= seconds + 0.5:  # a little past the end: late events must be ignored
            return events
        step = round(t / dt)
        key = rng.choice(KEYS)
        events.append(InputEvent(step, key, "up" if key in held else "down"))
        held ^= {key}
        if extras:
            r = rng.random()
            if r < 0.04:
                events.append(InputEvent(step, "space", rng.choice(("down", "up"))))
            elif r < 0.06:
                events.append(InputEvent(step, "tab", "down"))
            elif r < 0.08:  # a repeat of a held key, or an unknown key: both ignored
                events.append(InputEvent(step, rng.choice((key, "x")), "down"))


def assert_same_game(batch: BatchGameSession, i: int, single: GameSession) -> None:
    assert batch.result(i) == single.result()
    assert int(batch.steps[i]) == single.steps
    assert batch.rules[i].target == single.rules.target
    assert batch.rules[i].board == single.rules.board
    assert (batch.target_x[i], batch.target_y[i]) == (single.rules.target.x, single.rules.target.y)
    assert bool(batch.arm_visible[i]) == single.rules.arm_visible
    assert batch.held[i].tolist() == single.held
    # Both kernels are bit for bit the single session: the same operations in the same order, the arm's
    # trig included (physics.trig: numpy's and C's are the Python one's, operation for operation).
    assert batch.state(i) == single.state
    assert batch.activation[i].tolist() == list(single.muscles.activation)


@pytest.mark.parametrize("kernel", KERNELS)
@settings(max_examples=12, deadline=None)
@given(
    seeds=st.lists(st.integers(0, 2**63 - 1), min_size=1, max_size=5),
    durations=st.lists(st.sampled_from([0.5, 1.0, 2.0, 3.0]), min_size=5, max_size=5),
    stops=st.lists(st.one_of(st.none(), st.integers(0, 800)), min_size=5, max_size=5),
    radius=st.sampled_from([0.05, 0.2]),
    timeline_seed=st.integers(0, 2**32 - 1),
)
def test_batch_equals_single_sessions_on_random_timelines(kernel, seeds, durations, stops, radius, timeline_seed):
    """Random keys, resets, tab, stray keys, games of different lengths, some stopped early."""
    rng = random.Random(timeline_seed)
    configs = [GameConfig(seed=s, time_limit=durations[i], target_radius=radius) for i, s in enumerate(seeds)]
    timelines = [student_timeline(rng, c.dt, c.time_limit) for c in configs]
    stop_steps = stops[:len(configs)]
    batch = batch_of(configs, kernel)
    results = batch.play(timelines, stop_steps)
    for i, (c, timeline, stop) in enumerate(zip(configs, timelines, stop_steps, strict=True)):
        single = GameSession(c)
        assert results[i] == single.play(timeline, stop)
        assert_same_game(batch, i, single)


ARMS = {"game": GAME_PLAY_ARM, "vertical": GAME_PLAY_ARM.replace(gravity=9.81),
        "frictionless": GAME_PLAY_ARM.replace(damping1=0.0, damping2=0.0)}


@pytest.mark.parametrize("kernel", KERNELS)
@settings(max_examples=6, deadline=None)
@given(arm=st.sampled_from(sorted(ARMS)), integrator=st.sampled_from(["rk4", "euler", "symplectic-euler"]),
       muscles=st.sampled_from(["default", "remapped", "biarticular"]), timeline_seed=st.integers(0, 2**32 - 1))
def test_every_arm_and_batchable_integrator_equals_the_single_session(kernel, arm, integrator, muscles, timeline_seed):
    """The kernel's gravity, damping and plain variants, the generic path, other keys and moment arms."""
    rng = random.Random(timeline_seed)
    muscles = {"default": DEFAULT_MUSCLES, "remapped": remap_keys(DEFAULT_MUSCLES, "jkdf"),
               "biarticular": tuple(MuscleSpec(m.name, m.key, (m.moment[0] + 0.3, m.moment[1] - 0.2), 0.05, 0.12)
                                    for m in DEFAULT_MUSCLES)}[muscles]
    configs = [GameConfig(seed=s, time_limit=2.0, arm=ARMS[arm], integrator=integrator, muscles=muscles,
                          target_radius=0.15) for s in range(3)]
    timelines = [student_timeline(rng, c.dt, c.time_limit) for c in configs]
    batch = batch_of(configs, kernel)
    results = batch.play(timelines)
    for i, (c, timeline) in enumerate(zip(configs, timelines, strict=True)):
        single = GameSession(c)
        assert results[i] == single.play(timeline)
        assert_same_game(batch, i, single)


@functools.cache
def games_one_by_one(count: int, rng_seed: int) -> tuple[list, list, list]:
    """``count`` games of 45 and 60 s with a large target, played one by one with ``GameSession``:
    once for every kernel's test in a module (only read after)."""
    rng = random.Random(rng_seed)
    configs = [GameConfig(seed=s, time_limit=60.0 if s % 2 else 45.0, target_radius=0.12) for s in range(count)]
    timelines = [student_timeline(rng, c.dt, c.time_limit) for c in configs]
    singles = []
    for c, timeline in zip(configs, timelines, strict=True):
        single = GameSession(c)
        singles.append((single, single.play(timeline)))
    return configs, timelines, singles


#: The numpy kernel's 60 s games (about 3.5 s: its step is numpy calls on 16 games) run in CI after the suite
#: (pytest -m slow): the same kernel is held bit for bit on shorter games by the tests above.
LONG_KERNELS = [pytest.param(k, marks=pytest.mark.slow) if k == "numpy" else k for k in KERNELS]


@pytest.mark.parametrize("kernel", LONG_KERNELS)
def test_many_long_games_equal_the_single_session(kernel):
    """60 s games with a large target (many hits, many near misses): also the largest state difference."""
    configs, timelines, singles = games_one_by_one(16, 7)
    batch = batch_of(configs, kernel)
    results = batch.play(timelines)
    worst = 0.0
    for i, (single, result) in enumerate(singles):
        assert results[i] == result
        assert_same_game(batch, i, single)
        worst = max(worst, max(abs(a - b) for a, b in zip(batch.state(i), single.state, strict=True)))
    assert sum(r.hits for r in results) > 50 and sum(r.resets for r in results) > 0
    assert worst == 0.0


def test_round_off_in_sin_and_cos_stays_well_within_the_stated_tolerance():
    """The arm's trig an ulp off (as the C library's, which the arm used before version 0.3, is from the
    arm's own): the states stay far within the fast kernels' tolerance and the games are the same."""
    from armgame.physics import trig
    from armgame.physics.integrators import scheme
    from armgame.physics.twojoint import largest_abs_float

    noise = random.Random(0)

    def an_ulp_off(f):
        def g(x):
            y, r = f(x), noise.random()
            return math.nextafter(y, math.inf) if r < 0.25 else math.nextafter(y, -math.inf) if r < 0.5 else y
        return g

    off_sin, off_cos = an_ulp_off(trig.sin), an_ulp_off(trig.cos)
    worst = 0.0
    for game in range(2):
        config = GameConfig(time_limit=60.0)
        timeline = student_timeline(random.Random(game), config.dt, 60.0, extras=False)
        exact, off = GameSession(config), GameSession(config)
        off._physics_step = scheme("rk4").build(
            off.model._build_components(lambda x: (off_sin(x), off_cos(x)), off_cos, off_sin, largest_abs_float))
        feed_exact, feed_off = TimelineInput(timeline), TimelineInput(timeline)
        for step in range(100, config.total_steps + 1, 100):
            feed_exact.run_to(exact, step)
            feed_off.run_to(off, step)
            worst = max(worst, *(abs(u - v) for u, v in zip(exact.state, off.state, strict=True)))
        assert exact.result() == off.result()
    assert 0.0 < worst < STATE_TOLERANCE / 100


#: A short game whose hand crosses ``knife_edge_target``'s edge at step 60.
KNIFE_SCRIPT = [InputEvent(0, "d", "down"), InputEvent(10, "j", "down"), InputEvent(40, "d", "up")]


def knife_edge_target(config: GameConfig, inside: bool) -> Target:
    """A target whose edge passes within a few ulps of where ``KNIFE_SCRIPT``'s hand is after step 60:
    its centre just ahead of the hand along its motion, so the hand is outside before and, by a hair,
    inside (or outside) after."""
    probe = GameSession(config, compiled=False)
    probe.play(KNIFE_SCRIPT, stop_step=59)
    px, py = probe.hand()
    probe.advance(1)
    hx, hy = probe.hand()
    r = config.target_radius * (1.0 - 1e-15 if inside else 1.0 + 1e-15)
    ux, uy = (hx - px) / math.dist((hx, hy), (px, py)), (hy - py) / math.dist((hx, hy), (px, py))
    return Target(hx + r * ux, hy + r * uy, config.target_radius)


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize("inside", [True, False])
def test_a_hit_on_the_knife_edge_is_decided_as_the_single_session_decides(kernel, inside):
    """A target whose edge passes within a few ulps of where the hand will be."""
    script = KNIFE_SCRIPT
    config = GameConfig(time_limit=1.0)
    edge = knife_edge_target(config, inside)
    single = GameSession(config)
    single.rules.target = edge
    batch = batch_of([config, config], kernel)
    for i in range(2):
        batch.rules[i].target = edge
        batch.target_x[i], batch.target_y[i] = edge.x, edge.y
    expected = single.play(script)
    assert (60 * config.dt in single.rules.board.hit_times) == inside
    assert batch.play([script, script]) == [expected, expected]
    assert_same_game(batch, 0, single)


@pytest.mark.parametrize("kernel", KERNELS)
def test_the_step_api_equals_keys_levels_and_resets_of_single_sessions(kernel):
    """set_held, set_levels, reset_arms, advance and restart, as a vector environment drives them."""
    rng = np.random.default_rng(3)
    configs = [GameConfig(seed=s, time_limit=2.0 + s % 3, target_radius=0.15) for s in range(6)]
    batch = batch_of(configs, kernel)
    singles = [GameSession(c) for c in configs]
    for turn in range(120):
        if turn % 3 == 0:
            held = rng.random((6, 4)) < 0.4
            batch.set_held(held)
            for s, row in zip(singles, held, strict=True):
                for key, down in zip(KEYS, row, strict=True):
                    s.key_event(key, "down" if down else "up")
        elif turn % 3 == 1:
            levels = rng.choice([0.0, 0.3, 0.7, 1.0], size=(6, 4))
            mask = rng.random(6) < 0.5
            batch.set_levels(levels[mask], mask)
            for s, row, chosen in zip(singles, levels, mask, strict=True):
                if chosen:
                    s.set_muscle_levels(row)
        else:
            mask = rng.random(6) < 0.05
            batch.reset_arms(mask)
            for s, chosen in zip(singles, mask, strict=True):
                if chosen:
                    s.key_event("space", "down")
        steps = int(rng.integers(1, 30))
        batch.advance(steps)
        for s in singles:
            s.advance(steps)
        if turn == 60:
            mask = np.array([True, False, True, False, False, False])
            batch.restart(mask, [101, 102])
            singles[0] = GameSession(replace(configs[0], seed=101))
            singles[2] = GameSession(replace(configs[2], seed=102))
        for i, s in enumerate(singles):
            assert_same_game(batch, i, s)
    assert batch.over.sum() >= 4 and sum(s.rules.board.hits for s in singles) > 0


def test_levels_zero_and_one_are_the_keys():
    by_key, by_level = MuscleSet(DEFAULT_MUSCLES, 0.004), MuscleSet(DEFAULT_MUSCLES, 0.004)
    for on in (True, False, True):
        for i in range(4):
            by_key.command(i, on)
            by_level.set_level(i, 1.0 if on else 0.0)
        for _ in range(50):
            by_key.step()
            by_level.step()
        assert (by_key.goal, by_key.rate, by_key.activation) == (by_level.goal, by_level.rate, by_level.activation)


def test_a_level_is_approached_from_either_side_without_crossing():
    muscles = MuscleSet(DEFAULT_MUSCLES, 0.004)
    muscles.set_level(0, 0.6)
    trace = []
    for _ in range(400):
        muscles.step()
        trace.append(muscles.activation[0])
    assert all(b >= a for a, b in itertools.pairwise(trace)) and max(trace) <= 0.6 and trace[-1] > 0.59
    muscles.set_level(0, 0.2)
    assert muscles.rate[0] == MuscleSet(DEFAULT_MUSCLES, 0.004).rate[0]  # a relaxed muscle's rate: its decay
    for _ in range(400):
        muscles.step()
    assert 0.2 <= muscles.activation[0] < 0.21


@pytest.mark.parametrize("levels", [(0.5, 0.5, 0.5), (0.0, 1.0, float("nan"), 0.0), (0.0, 1.1, 0.0, 0.0),
                                    (-0.1, 0.0, 0.0, 0.0)])
def test_bad_muscle_levels_are_refused_and_change_nothing(levels):
    session = GameSession(GameConfig())
    with pytest.raises(MuscleLevelError):
        session.set_muscle_levels(levels)
    assert session.muscles.goal == [0.0] * 4
    batch = BatchGameSession([GameConfig()])
    if len(levels) == 4:
        with pytest.raises(MuscleLevelError):
            batch.set_levels(np.array([levels]))
        batch.advance(25)  # a goal half set would show: the relaxed arm's activations would rise from 0
        assert batch.activation.tolist() == [[0.0] * 4]


def test_continuous_levels_move_the_arm_and_are_not_recorded():
    session = GameSession(GameConfig(time_limit=1.0))
    session.set_muscle_levels([0.5, 0.0, 0.25, 0.0])
    session.advance(100)
    assert session.timeline == [] and session.state[2] != 0.0
    assert 0.49 < session.muscles.activation[0] < 0.5


def test_games_that_cannot_share_a_batch_are_refused_naming_the_field():
    with pytest.raises(UserError, match="target_radius"):
        BatchGameSession([GameConfig(), GameConfig(target_radius=0.1)])
    with pytest.raises(UserError, match="arm"):
        BatchGameSession([GameConfig(), GameConfig(arm=GAME_PLAY_ARM.replace(damping1=0.1))])
    with pytest.raises(UserError, match="gauss4"):
        BatchGameSession([GameConfig(integrator="gauss4")])
    assert batch_problem([GameConfig(seed=1, time_limit=5.0), GameConfig(seed=2, scene="other")]) is None


def test_replay_many_groups_what_can_share_a_batch_and_plays_the_rest_alone():
    rng = random.Random(11)
    configs = [GameConfig(seed=1, time_limit=2.0), GameConfig(seed=2, time_limit=1.5, integrator="gauss4"),
               GameConfig(seed=3, time_limit=2.0, target_radius=0.2), GameConfig(seed=4, time_limit=2.0),
               GameConfig(seed=5, time_limit=2.0, target_radius=0.2), GameConfig(seed=6, time_limit=1.0),
               GameConfig(seed=7, time_limit=2.0, dt=0.002)]
    timelines = [student_timeline(rng, c.dt, c.time_limit) for c in configs]
    stops = [None, None, 300, None, None, 100, None]
    expected = [GameSession(c).play(t, s) for c, t, s in zip(configs, timelines, stops, strict=True)]
    assert replay_many(configs, timelines, stops, batch_size=2) == expected


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize("games", [3, 8])  # most of the batch playing on, or most of it stopped
def test_games_stopped_early_keep_the_state_of_their_last_step_and_its_events(kernel, games):
    rng = random.Random(4)
    configs = [GameConfig(seed=s, time_limit=3.0 if s else 1.0, target_radius=0.15) for s in range(games)]
    timelines = [student_timeline(rng, c.dt, c.time_limit, extras=False) for c in configs]
    stops = [None] * games
    for i in (1, 2):  # quit at an event's step, with a reset (space) among its events
        at = timelines[i][len(timelines[i]) // 2].step
        timelines[i] = [e for e in timelines[i] if e.step <= at] + [InputEvent(at, "space", "down")]
        stops[i] = at
    batch = batch_of(configs, kernel)
    results = batch.play(timelines, stops)
    for i in range(games):
        single = GameSession(configs[i])
        assert results[i] == single.play(timelines[i], stops[i])
        assert_same_game(batch, i, single)
    assert results[1].resets >= 1 and batch.state(1)[2:] == (0.0, 0.0)


@pytest.mark.parametrize("kernel", KERNELS)
def test_play_with_no_events_and_a_stop_at_zero(kernel):
    configs = [GameConfig(seed=1, time_limit=0.5), GameConfig(seed=2, time_limit=0.5)]
    batch = batch_of(configs, kernel)
    results = batch.play([[], [InputEvent(0, "space", "down")]], [None, 0])
    assert [r.steps for r in results] == [125, 0] and results[1].resets == 1
    assert batch.state(1) == (math.radians(45.0), math.radians(90.0), 0.0, 0.0)


# ------------------------------------------------------------------ scoring a class from the command line

def write_scripts(folder, count: int, seconds: float = 3.0) -> list:
    folder.mkdir(exist_ok=True)
    paths = []
    for i in range(count):
        rng = random.Random(i)
        lines = [f"{e.step * 0.004:.3f} {e.key} {e.action}" for e in student_timeline(rng, 0.004, seconds)]
        path = folder / f"student{i:02d}.txt"
        path.write_text("# a student\n" + "\n".join(lines) + "\n")
        paths.append(path)
    return paths


def test_play_many_scripts_prints_one_json_line_each_equal_to_playing_them_alone(tmp_path, capsys):
    import json

    from armgame.cli import main

    paths = write_scripts(tmp_path / "class", 4)
    order = [paths[2], paths[0], paths[3]]
    assert main(["play", "--headless", "--seed", "5", "--duration", "3", "--json", "--script",
                 *map(str, order)]) == 0
    lines = capsys.readouterr().out.splitlines()
    for line, path in zip(lines, order, strict=True):
        assert main(["play", "--headless", "--seed", "5", "--duration", "3", "--json", "--script", str(path)]) == 0
        alone = json.loads(capsys.readouterr().out)
        assert json.loads(line) == {"script": str(path), **alone}


def test_script_given_twice_adds_up(tmp_path, capsys):
    from armgame.cli import main

    a, b = write_scripts(tmp_path / "class", 2, seconds=1.0)
    assert main(["play", "--headless", "--duration", "1", "--script", str(a), "--script", str(b)]) == 0
    assert [line.split(": ")[0] for line in capsys.readouterr().out.splitlines()] == [str(a), str(b)]


def test_a_folder_of_scripts_plays_its_txt_files_in_sorted_order_and_follows_no_link(tmp_path, capsys):
    import json

    from armgame.cli import main

    folder = tmp_path / "class"
    paths = write_scripts(folder, 3)
    (folder / "notes.md").write_text("not a script")
    (folder / ".hidden.txt").write_text("0.0 x down\n")
    outside = tmp_path / "outside.txt"
    outside.write_text("0.0 d down\n")
    (folder / "link.txt").symlink_to(outside)
    (folder / "sub.txt").mkdir()
    assert main(["play", "--headless", "--duration", "3", "--json", "--script", str(folder)]) == 0
    scripts = [json.loads(line)["script"] for line in capsys.readouterr().out.splitlines()]
    assert scripts == [str(p) for p in paths]
    assert main(["play", "--headless", "--duration", "3", "--script", str(folder)]) == 0
    assert capsys.readouterr().out.splitlines()[0].startswith(f"{paths[0]}: score ")


@pytest.mark.parametrize(("extra", "message"), [
    (["--name", "Ann"], "--name, --record and --join are for one game"),
    (["--record", "x.json"], "--name, --record and --join are for one game"),
    (["--join", "127.0.0.1:8765", "--code", "ACDE"], "--name, --record and --join are for one game"),
    (["--bot", "model"], "--bot and --script"),
])
def test_options_for_one_game_are_refused_for_many_in_one_line(tmp_path, capsys, extra, message):
    from armgame.cli import main

    paths = write_scripts(tmp_path / "class", 2)
    assert main(["play", "--headless", "--script", *map(str, paths), *extra]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and message in err
    assert not (tmp_path / "x.json").exists()


def test_a_class_run_is_bounded_and_checks_every_script_before_playing(tmp_path, capsys, monkeypatch):
    import armgame.game.batch.scripts as batch_module
    from armgame.cli import main

    paths = write_scripts(tmp_path / "class", 3)
    monkeypatch.setattr(batch_module, "MAX_SCRIPTS", 2)
    assert main(["play", "--headless", "--script", str(tmp_path / "class")]) == 2
    assert "more than the 2" in capsys.readouterr().err
    monkeypatch.setattr(batch_module, "MAX_SCRIPTS", 100)
    monkeypatch.setattr(batch_module, "MAX_SCRIPT_EVENTS", 5)
    assert main(["play", "--headless", "--script", *map(str, paths)]) == 2
    assert "more than 5 events" in capsys.readouterr().err
    monkeypatch.setattr(batch_module, "MAX_SCRIPT_EVENTS", 10**6)
    paths[2].write_text("0.0 d down\nbad line\n")
    played = []
    monkeypatch.setattr(batch_module, "replay_many", lambda *a, **k: played.append(a))
    assert main(["play", "--headless", "--script", *map(str, paths)]) == 2
    assert "student02.txt, line 2" in capsys.readouterr().err and not played


# ------------------------------------------------------------------ verifying many replays

def recorded(seed: int, seconds: float = 2.0, player: str | None = "Ann", **config) -> Replay:
    session = GameSession(GameConfig(seed=seed, time_limit=seconds, **config))
    session.play(student_timeline(random.Random(seed), session.config.dt, seconds, extras=True))
    return Replay.from_session(session, "script", f"s{seed}.txt", player)


def test_verify_replays_equals_verifying_each_alone():
    from dataclasses import replace as dc_replace

    from armgame.records.batch_verify import verify_replays

    replays = [recorded(s) for s in range(4)] + [recorded(9, integrator="gauss4"), recorded(8, target_radius=0.2)]
    replays[1] = dc_replace(replays[1], result=dc_replace(replays[1].result, score=replays[1].result.score + 1))
    quit_early = GameSession(GameConfig(seed=5, time_limit=3.0))
    quit_early.play([InputEvent(0, "d", "down")], stop_step=200)
    replays.append(Replay.from_session(quit_early, "keyboard"))
    batched, alone = verify_replays(replays), [r.verify() for r in replays]
    assert [ok for ok, _ in batched] == [ok for ok, _ in alone] == [True, False, True, True, True, True, True]
    assert [v for v in batched if v[0]] == [v for v in alone if v[0]]  # the failing game is played to its end


def test_verify_a_folder_of_replays_in_batches(tmp_path, capsys, monkeypatch):
    from dataclasses import replace as dc_replace

    import armgame.records.batch_verify as bv
    from armgame.cli import main

    folder = tmp_path / "replays"
    folder.mkdir()
    for s in range(5):
        recorded(s).save(folder / f"game{s}.json")
    bad = recorded(7)
    dc_replace(bad, result=dc_replace(bad.result, hits=bad.result.hits + 1, score=bad.result.score + 1)).save(
        folder / "game7.json")
    (folder / "broken.json").write_text('{"format": "armgame-replay"')
    recorded(6).save(tmp_path / "outside.json")
    (folder / "link.json").symlink_to(tmp_path / "outside.json")
    (folder / "notes.txt").write_text("not a replay")
    monkeypatch.setattr(bv, "CHUNK", 3)  # several chunks
    assert main(["verify", str(folder)]) == 2
    lines = capsys.readouterr().out.splitlines()
    names = ["broken.json", *(f"game{s}.json" for s in range(5)), "game7.json"]  # sorted; link.json not followed
    assert [line.split(": ")[0] for line in lines[:-1]] == [str(folder / n) for n in names]
    assert lines[0].startswith(f"{folder / 'broken.json'}: BAD REPLAY: ")
    assert sum(": matches: " in line for line in lines) == 5
    assert ": DIFFERS: " in lines[6] and "game7.json" in lines[6]
    assert lines[-1] == f"{folder}: 7 replays, 1 differ, 1 unreadable"
    (folder / "broken.json").unlink()
    assert main(["verify", str(folder)]) == 1
    (folder / "game7.json").unlink()
    assert main(["verify", str(folder)]) == 0
    capsys.readouterr()
    (tmp_path / "empty").mkdir()
    assert main(["verify", str(tmp_path / "empty")]) == 2
    assert "no score table (scores.json) and no replays (*.json)" in capsys.readouterr().err


def test_verify_a_table_checks_its_entries_in_batches_as_one_by_one(tmp_path, capsys, monkeypatch):
    import armgame.records.batch_verify as bv
    from armgame.cli import main
    from armgame.records.scores import ScoreTable

    table = ScoreTable(tmp_path / "scores")
    entries = [table.add(recorded(s, player=f"student {s}")) for s in range(6)]
    table.replay_path(entries[1]).unlink()  # REPLAY MISSING
    path = table.replay_path(entries[3])  # REPLAY CHANGED
    path.write_bytes(path.read_bytes().replace(b'"player": "student 3"', b'"player": "student 9"'))
    monkeypatch.setattr(bv, "CHUNK", 4)
    ordered = sorted(table.read()[0], key=lambda e: e.when)
    assert list(bv.check_entries(table, ordered)) == [(e, table.check(e)) for e in ordered]
    assert main(["verify", str(tmp_path / "scores")]) == 1
    out = capsys.readouterr().out.splitlines()
    assert sum(line.endswith(": ok") for line in out) == 4 and out[-1].endswith("6 entries, 2 flagged")
