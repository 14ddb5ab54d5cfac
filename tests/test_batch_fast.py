"""The fast kernels (``BatchGameSession(configs, exact=False)``) against the single session.

Both kernels have one: numpy's and the compiled one take the elbow's cos and sin by angle
addition. numpy's series only run from ``SERIES_MIN_GAMES`` games (2,048): these tests lower
that to one game, so that a handful of games exercises the very arithmetic a large batch runs.
The compiled kernel's run at any size.
"""

import math
import random
from contextlib import contextmanager

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_batch import KERNELS, KEYS, games_one_by_one, student_timeline

import armgame.game.batch.session as batch_module
from armgame.game.batch import STATE_TOLERANCE, BatchGameSession, compiled, replay_many
from armgame.game.rules import GAME_PLAY_ARM, GameConfig, Target
from armgame.game.session import GameSession, InputEvent

#: What the fast kernel's states stay within over these tests' 60 s student games (the largest seen
#: was 1.4e-14; over 1,000 games with random keys, 1.7e-11); ``STATE_TOLERANCE`` is the stated bound.
MEASURED = STATE_TOLERANCE / 1000


@contextmanager
def series_for_any_batch(**constants):
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(batch_module, "SERIES_MIN_GAMES", 1)
        for name, value in constants.items():
            mp.setattr(batch_module, name, value)
            if name == "SERIES_LIMIT":
                mp.setattr(compiled, name, value)
        yield


def largest_difference(batch: BatchGameSession, i: int, single: GameSession) -> float:
    return max(abs(a - b) for a, b in zip(batch.state(i), single.state, strict=True))


def assert_same_results(batch: BatchGameSession, i: int, single: GameSession) -> float:
    """Hits, score, resets, steps, targets and keys exactly; returns the largest state difference."""
    assert batch.result(i) == single.result()
    assert batch.rules[i].board == single.rules.board
    assert batch.rules[i].target == single.rules.target
    assert batch.held[i].tolist() == single.held
    np.testing.assert_allclose(batch.activation[i], single.muscles.activation, rtol=0.0, atol=0.0)
    worst = largest_difference(batch, i, single)
    assert worst <= STATE_TOLERANCE
    return worst


@pytest.mark.parametrize("kernel", KERNELS)
@settings(max_examples=10, deadline=None)
@given(
    seeds=st.lists(st.integers(0, 2**63 - 1), min_size=1, max_size=5),
    durations=st.lists(st.sampled_from([0.5, 1.0, 2.0, 4.0]), min_size=5, max_size=5),
    stops=st.lists(st.one_of(st.none(), st.integers(0, 1000)), min_size=5, max_size=5),
    radius=st.sampled_from([0.05, 0.2]),
    timeline_seed=st.integers(0, 2**32 - 1),
)
def test_fast_batch_equals_single_sessions_on_random_timelines(kernel, seeds, durations, stops, radius, timeline_seed):
    """Random keys, resets, tab, stray keys, games of different lengths, some stopped early."""
    rng = random.Random(timeline_seed)
    configs = [GameConfig(seed=s, time_limit=durations[i], target_radius=radius) for i, s in enumerate(seeds)]
    timelines = [student_timeline(rng, c.dt, c.time_limit) for c in configs]
    stop_steps = stops[:len(configs)]
    with series_for_any_batch():
        batch = BatchGameSession(configs, exact=False, kernel=kernel)
        results = batch.play(timelines, stop_steps)
        assert results == replay_many(configs, timelines, stop_steps, kernel=kernel)
    for i, (c, timeline, stop) in enumerate(zip(configs, timelines, stop_steps, strict=True)):
        single = GameSession(c)
        assert results[i] == single.play(timeline, stop)
        assert_same_results(batch, i, single)


#: The numpy kernel's 60 s games (about 2 s) run in CI after the suite (pytest -m slow): the same kernel is held
#: to the single sessions on shorter games by the tests around, and the compiled one on these long ones.
LONG_KERNELS = [pytest.param(k, marks=pytest.mark.slow) if k == "numpy" else k for k in KERNELS]


@pytest.mark.parametrize("kernel", LONG_KERNELS)
def test_full_games_stay_within_round_off_and_score_the_same(kernel):
    """60 s games with a large target (many hits and near misses): the largest state difference, measured."""
    configs, timelines, singles = games_one_by_one(16, 7)  # test_batch's games: one set of references
    with series_for_any_batch():
        batch = BatchGameSession(configs, exact=False, kernel=kernel)
        results = batch.play(timelines)
    worst = 0.0
    for i, (single, result) in enumerate(singles):
        assert results[i] == result
        worst = max(worst, assert_same_results(batch, i, single))
    assert sum(r.hits for r in results) > 50 and sum(r.resets for r in results) > 0
    # Not zero: the series really ran (the exact kernel is bit for bit here); far below the bound.
    assert 0.0 < worst <= MEASURED


@pytest.mark.parametrize("kernel", KERNELS)
def test_the_step_api_with_levels_and_resets_equals_single_sessions(kernel):
    rng = np.random.default_rng(5)
    configs = [GameConfig(seed=s, time_limit=3.0, target_radius=0.15) for s in range(4)]
    singles = [GameSession(c) for c in configs]
    with series_for_any_batch():
        batch = BatchGameSession(configs, exact=False, kernel=kernel)
        for turn in range(150):
            if turn % 2:
                levels = rng.choice([0.0, 0.4, 1.0], size=(4, 4))
                batch.set_levels(levels)
                for s, row in zip(singles, levels, strict=True):
                    s.set_muscle_levels(row.tolist())
            elif rng.random() < 0.1:
                batch.reset_arms(np.ones(4, dtype=bool))
                for s in singles:
                    s.key_event("space", "down")
            batch.advance(5)
            for s in singles:
                s.advance(5)
    for i, s in enumerate(singles):
        assert_same_results(batch, i, s)


@pytest.mark.parametrize("kernel", KERNELS)
def test_a_step_beyond_the_series_range_falls_back_to_the_exact_arithmetic(kernel):
    """With the range at zero every step falls back: bit for bit the exact kernel."""
    configs = [GameConfig(seed=s, time_limit=2.0) for s in range(3)]
    timelines = [student_timeline(random.Random(s), configs[0].dt, 2.0) for s in range(3)]
    exact = BatchGameSession(configs)
    exact.play(timelines)
    with series_for_any_batch(SERIES_LIMIT=0.0):
        fallen = BatchGameSession(configs, exact=False, kernel=kernel)
        fallen.play(timelines)
    assert np.array_equal(fallen._x[:4], exact._x[:4])
    with series_for_any_batch():
        fast = BatchGameSession(configs, exact=False, kernel=kernel)
        fast.play(timelines)
    assert not np.array_equal(fast._x[:4], exact._x[:4])  # the series did run: the test can fail


@pytest.mark.parametrize("kernel", KERNELS)
def test_large_steps_and_spins_beyond_the_series_range_still_equal_the_single_session(kernel):
    """dt = 40 ms and a frictionless arm: elbow increments well past 0.1 rad, some steps fall back."""
    arm = GAME_PLAY_ARM.replace(damping1=0.0, damping2=0.0)
    configs = [GameConfig(seed=s, time_limit=6.0, dt=0.04, arm=arm, target_radius=0.1) for s in range(3)]
    timelines = [[InputEvent(0, k, "down") for k in KEYS[:1 + s]] for s in range(3)]
    with series_for_any_batch():
        batch = BatchGameSession(configs, exact=False, kernel=kernel)
        results = batch.play(timelines)
    assert float(np.abs(batch.w2).max()) * configs[0].dt > batch_module.SERIES_LIMIT
    for i, (c, timeline) in enumerate(zip(configs, timelines, strict=True)):
        single = GameSession(c)
        assert results[i] == single.play(timeline)
        assert_same_results(batch, i, single)


def knife_edge_game(inside: bool) -> tuple[GameConfig, list[InputEvent], Target]:
    """A target whose edge passes within a few ulps of where the hand is after step 60."""
    script = [InputEvent(0, "d", "down"), InputEvent(10, "j", "down"), InputEvent(40, "d", "up")]
    config = GameConfig(time_limit=1.0)
    probe = GameSession(config)
    probe.play(script, stop_step=59)
    px, py = probe.hand()
    probe.advance(1)
    hx, hy = probe.hand()
    r = config.target_radius * (1.0 - 1e-15 if inside else 1.0 + 1e-15)
    length = math.dist((hx, hy), (px, py))
    return config, script, Target(hx + r * (hx - px) / length, hy + r * (hy - py) / length, config.target_radius)


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize("inside", [True, False])
def test_a_decision_on_the_knife_edge_marks_the_game(kernel, inside):
    config, script, edge = knife_edge_game(inside)
    with series_for_any_batch():
        batch = BatchGameSession([config, config], exact=False, kernel=kernel)
    batch.rules[0].target = edge
    batch.target_x[0], batch.target_y[0] = edge.x, edge.y
    batch.play([script, script])
    assert batch.knife_edge.tolist() == [True, False]
    exact = BatchGameSession([config, config])  # the exact kernel never needs the mark
    exact.rules[0].target = edge
    exact.target_x[0], exact.target_y[0] = edge.x, edge.y
    exact.play([script, script])
    assert not exact.knife_edge.any()


@pytest.mark.parametrize("kernel", KERNELS)
def test_replay_many_plays_games_marked_on_the_knife_edge_again_alone(kernel, monkeypatch):
    """With every decided hit marked (a huge knife edge), replay_many plays every scoring game alone."""
    configs = [GameConfig(seed=s, time_limit=4.0, target_radius=0.25) for s in range(4)]
    timelines = [student_timeline(random.Random(s), configs[0].dt, 4.0, extras=False) for s in range(4)]
    alone = []
    play = GameSession.play

    def spy(self, *args, **kwargs):
        alone.append(self.config.seed)
        return play(self, *args, **kwargs)

    monkeypatch.setattr(GameSession, "play", spy)
    with series_for_any_batch(KNIFE_EDGE=10.0):
        results = replay_many(configs, timelines, kernel=kernel)
    scorers = {c.seed for c, r in zip(configs, results, strict=True) if r.hits}
    assert len(scorers) >= 2 and scorers <= set(alone)  # every hit was decided, so marked
    alone.clear()
    with series_for_any_batch():
        assert replay_many(configs, timelines, kernel=kernel) == results
    assert alone == []
    assert results == [play(GameSession(c), t) for c, t in zip(configs, timelines, strict=True)]


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize("arm", ["vertical", "biarticular"])
def test_gravity_and_two_joint_muscles_in_the_fast_kernel(kernel, arm):
    """Gravity's own cos terms and muscles acting on both joints, through the series."""
    from armgame.game.muscles import DEFAULT_MUSCLES, MuscleSpec

    kwargs = ({"arm": GAME_PLAY_ARM.replace(gravity=9.81)} if arm == "vertical" else
              {"muscles": tuple(MuscleSpec(m.name, m.key, (m.moment[0] + 0.3, m.moment[1] - 0.2), 0.05, 0.12)
                                for m in DEFAULT_MUSCLES)})
    configs = [GameConfig(seed=s, time_limit=5.0, target_radius=0.15, **kwargs) for s in range(3)]
    timelines = [student_timeline(random.Random(s), configs[0].dt, 5.0) for s in range(3)]
    with series_for_any_batch():
        batch = BatchGameSession(configs, exact=False, kernel=kernel)
        results = batch.play(timelines)
    for i, (c, timeline) in enumerate(zip(configs, timelines, strict=True)):
        single = GameSession(c)
        assert results[i] == single.play(timeline)
        assert_same_results(batch, i, single)


@pytest.mark.parametrize("kernel", KERNELS)
def test_games_longer_than_the_fast_kernels_limit_run_the_exact_kernel(kernel):
    """Round-off grows with the game's length: past FAST_MAX_SECONDS the batch keeps to the exact kernel."""
    short, long = (GameConfig(time_limit=batch_module.FAST_MAX_SECONDS + extra) for extra in (0.0, 0.004))
    timelines = [[InputEvent(0, "d", "down"), InputEvent(100, "k", "down")]] * 2
    with series_for_any_batch():
        fast = BatchGameSession([short, short], exact=False, kernel=kernel)
        kept = BatchGameSession([short, long], exact=False, kernel=kernel)
    exact = BatchGameSession([short, long])
    for batch in (fast, kept, exact):
        batch.play(timelines, [3000, 3000])
    assert np.array_equal(kept._x, exact._x)
    assert not np.array_equal(fast._x, exact._x)
