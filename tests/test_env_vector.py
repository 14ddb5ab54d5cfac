"""The native vector env: make_vec's vector entry point, next-step autoreset, and N single envs' equal."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import data_equivalence
from gymnasium.vector import AutoresetMode, SyncVectorEnv
from hypothesis import given, settings
from hypothesis import strategies as st

import armgame.env
import armgame.env.vector
import armgame.game.batch.session
from armgame.env.policies import BotPolicy
from armgame.env.reach import EnvArgumentError
from armgame.env.vector import ReachVectorEnv
from armgame.game.batch import STATE_TOLERANCE

REACH, CONTINUOUS = "armgame/Reach-v0", "armgame/ReachContinuous-v0"


@pytest.fixture(autouse=True)
def batch_at_every_size(monkeypatch):
    """These tests hold the batched vector env to single envs on a few games, where make_vec would otherwise
    step single envs (``BATCH_MIN_ENVS``); tests/test_env_suite.py tests that choice."""
    monkeypatch.setattr(armgame.env.vector, "BATCH_MIN_ENVS", 1)


def make_pair(env_id, n, **kwargs):
    native = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", **kwargs)
    singles = SyncVectorEnv([lambda: gym.make(env_id, **kwargs) for _ in range(n)])
    return native, singles


def assert_same_step(a, b, step):
    (oa, ra, ta, ua, ia), (ob, rb, tb, ub, ib) = a, b
    assert np.abs(oa - ob).max() <= STATE_TOLERANCE, step
    assert data_equivalence(oa[:, 4:], ob[:, 4:], exact=True), step  # activations, target, clock: exactly
    assert ra.dtype == rb.dtype and ra.tolist() == rb.tolist(), step
    assert ta.tolist() == tb.tolist() and ua.tolist() == ub.tolist(), step
    assert data_equivalence(ia, ib, exact=True), (step, ia, ib)


@pytest.mark.parametrize("env_id", [REACH, CONTINUOUS])
def test_make_vec_gives_the_native_vector_env(env_id):
    envs = gym.make_vec(env_id, num_envs=5, vectorization_mode="vector_entry_point", time_limit=2.0)
    assert isinstance(envs, ReachVectorEnv) and envs.num_envs == 5
    assert envs.metadata["autoreset_mode"] is AutoresetMode.NEXT_STEP
    single = gym.make(env_id, time_limit=2.0)
    assert envs.single_action_space == single.action_space
    assert envs.single_observation_space == single.observation_space
    assert envs.action_space.shape == (5, 4) and envs.observation_space.shape == (5, 11)
    assert gym.make_vec(env_id, num_envs=2).unwrapped.__class__ is ReachVectorEnv  # the default mode for these ids
    obs, info = envs.reset(seed=1)
    assert obs in envs.observation_space and info["_hits"].all()


@pytest.mark.parametrize("series", ["exact", "series"])
@pytest.mark.parametrize("kwargs", [{}, {"reset_key": True, "decision_steps": 4}])
def test_the_vector_env_equals_single_envs_with_bots_playing_and_autoresets(kwargs, series, monkeypatch):
    # Bots score, so rewards are not all zero; 1.5 s games end twice (with 4 physics steps a decision
    # the last decision of a game holds 3).
    if series == "series":  # the fast kernel of 2,048 and more envs, here on four
        monkeypatch.setattr(armgame.game.batch.session, "SERIES_MIN_GAMES", 1)
    native, singles = make_pair(REACH, 4, time_limit=1.5, **kwargs)
    keys_env = gym.make(REACH, time_limit=1.5, decision_steps=kwargs.get("decision_steps", 5))
    policies = [BotPolicy(name, keys_env) for name in ("model", "naive", "model", "naive")]
    rng = np.random.default_rng(0)
    a, b = native.reset(seed=30), singles.reset(seed=30)
    assert data_equivalence(a, b, exact=True)
    obs, truncations, hits, costs = a[0], 0, 0, 0
    for step in range(2 * (native.unwrapped.settings.episode_steps + 1) + 3):
        actions = np.array([policy(row) for policy, row in zip(policies, obs, strict=True)])
        if kwargs:
            actions = np.column_stack([actions, rng.random(4) < 0.02])
        a, b = native.step(actions), singles.step(actions)
        assert_same_step(a, b, step)
        obs = a[0]
        truncations += int(a[3].sum())
        hits += int((a[1] > 0).sum())
        costs += int((a[1] < 0).sum())
    assert truncations == 8 and hits >= 3 and (costs >= 3 if kwargs else costs == 0)


def test_the_continuous_vector_env_equals_single_envs():
    native, singles = make_pair(CONTINUOUS, 3, time_limit=0.5, reset_key=True)
    native.action_space.seed(2)
    a, b = native.reset(seed=[5, 9, 5]), singles.reset(seed=[5, 9, 5])
    assert data_equivalence(a, b, exact=True)
    for step in range(60):
        actions = native.action_space.sample() * 1.2 - 0.1  # out of range too: clipped by both
        assert_same_step(native.step(actions), singles.step(actions), step)


def test_games_split_over_several_batches_equal_single_envs(monkeypatch):
    monkeypatch.setattr(armgame.env.vector, "GAMES_PER_BATCH", 2)
    native, singles = make_pair(REACH, 5, time_limit=0.3, reset_key=True)
    native.action_space.seed(4)
    a, b = native.reset(seed=100), singles.reset(seed=100)
    assert len(native.unwrapped.parts) == 3 and data_equivalence(a, b, exact=True)
    for step in range(40):  # 15 steps a game: two autoresets
        actions = native.action_space.sample()
        actions[:, 4] &= np.random.default_rng(step).random(5) < 0.1
        assert_same_step(native.step(actions), singles.step(actions), step)
    a, b = native.reset(), singles.reset()  # unseeded: each game's own generator draws the next seed
    assert data_equivalence(a, b, exact=True)


@settings(max_examples=12, deadline=None)
@given(n=st.integers(1, 4), decision_steps=st.integers(1, 7), time_limit=st.sampled_from([0.1, 0.23, 0.4]),
       continuous=st.booleans(), reset_key=st.booleans(), seed=st.integers(0, 2**62), action_seed=st.integers(0, 99),
       series=st.booleans())
def test_any_vector_env_equals_its_single_envs(n, decision_steps, time_limit, continuous, reset_key, seed,
                                               action_seed, series):
    env_id = CONTINUOUS if continuous else REACH
    with pytest.MonkeyPatch.context() as mp:
        if series:  # the fast kernel of 2,048 and more envs
            mp.setattr(armgame.game.batch.session, "SERIES_MIN_GAMES", 1)
        native, singles = make_pair(env_id, n, time_limit=time_limit, decision_steps=decision_steps,
                                    reset_key=reset_key)
        native.reset(seed=seed)  # builds the batches (which keep their kernel) while the patch holds
    native.action_space.seed(action_seed)
    a, b = native.reset(seed=seed), singles.reset(seed=seed)
    assert data_equivalence(a, b, exact=True)
    for step in range(2 * (native.unwrapped.settings.episode_steps + 1) + 1):
        actions = native.action_space.sample()
        if reset_key:  # a press now and then, not every other step
            actions[:, 4] = actions[:, 4] * (np.random.default_rng(step).random(n) < 0.1)
        a = native.step(actions)
        assert a[0] in native.observation_space
        assert_same_step(a, singles.step(actions), step)


def test_next_step_autoreset():
    envs = gym.make_vec(REACH, num_envs=2, vectorization_mode="vector_entry_point", time_limit=0.1)
    obs, _ = envs.reset(seed=3)
    first = obs.copy()
    held = np.ones((2, 4), dtype=np.int8)
    for _ in range(4):
        obs, reward, terminated, truncated, _ = envs.step(held)
        assert not truncated.any() and not terminated.any()
    obs, reward, terminated, truncated, info = envs.step(held)  # 5 x 20 ms: the games end
    assert truncated.all() and not terminated.any() and (obs[:, 10] == 0.0).all()
    obs, reward, terminated, truncated, info = envs.step(held)  # the action is ignored: new games start
    assert not truncated.any() and (reward == 0).all() and (obs[:, 10] == 0.1).all()
    assert (obs[:, 2:8] == 0.0).all() and (obs[:, :2] == first[:, :2]).all()  # at rest, relaxed
    assert (obs[:, 8:10] != first[:, 8:10]).all()  # the next games' seeds are drawn, not repeated
    assert info["hits"].tolist() == [0, 0]
    obs, *_ = envs.step(held)
    assert (obs[:, 4:8] > 0).all()  # and the games play on


def test_gymnasiums_vector_wrappers_read_the_episodes():
    envs = gym.make_vec(REACH, num_envs=3, time_limit=0.5)  # the vector entry point is the default
    envs = gym.wrappers.vector.RecordEpisodeStatistics(envs)
    envs.reset(seed=0)
    envs.action_space.seed(0)
    episodes = []
    for _ in range(52):  # 25 steps a game, then the autoreset step
        *_, info = envs.step(envs.action_space.sample())
        if "episode" in info:
            episodes.append(info["episode"]["l"][info["_episode"]].tolist())
    assert episodes == [[25, 25, 25], [25, 25, 25]]


def test_bad_vector_arguments_and_actions_are_refused():
    for kwargs in ({"num_envs": 0}, {"num_envs": True}, {"render_mode": "human"}, {"decision_steps": -2},
                   {"autoreset_mode": "sometimes"}):
        with pytest.raises(EnvArgumentError):
            ReachVectorEnv(**{"num_envs": 2, **kwargs})
    envs = ReachVectorEnv(2)
    with pytest.raises(gym.error.ResetNeeded):
        envs.step(np.zeros((2, 4)))
    with pytest.raises(EnvArgumentError, match="seed"):
        envs.reset(seed=[1, 2, 3])
    envs.reset(seed=0)
    for actions in (np.zeros((3, 4)), np.full((2, 4), 2)):
        with pytest.raises(ValueError, match="zeros and ones"):
            envs.step(actions)
    levels = ReachVectorEnv(2, continuous=True)
    levels.reset(seed=0)
    with pytest.raises(ValueError, match="finite"):
        levels.step(np.full((2, 4), np.nan))


def test_the_speed_benchmark_runs():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parent.parent / "benchmarks" / "env_speed.py"
    spec = importlib.util.spec_from_file_location("env_speed", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    result = bench.measure(quick=True, sizes=(3,), seconds=0.02, repeats=2)
    rates = result["vector"][3]["reach"]["wall"]
    assert rates["repeats"] == 2 and 0 < rates["min"] <= rates["median"] <= rates["max"]
    assert result["single_ratio"]["median"] > 0
    shares = bench.profile(num_envs=8, steps=3)
    assert shares and 0.0 < sum(share for _, share in shares) <= 1.0 + 1e-9


def test_the_v1_vector_env_takes_each_argument_of_the_single_env_with_its_default():
    """``gym.make_vec`` hands the same keyword arguments to the batched env or, where it does not play them, to
    single envs (``SingleEnvsVectorEnv``): the two signatures are written twice (each public constructor spells its
    arguments out), so an argument added to one, or a default changed in one, fails here."""
    import inspect

    from armgame.env.reach_v1 import ReachV1Env
    from armgame.env.vector import ReachV1VectorEnv

    single = inspect.signature(ReachV1Env.__init__).parameters
    batched = inspect.signature(ReachV1VectorEnv.__init__).parameters
    assert set(batched) - set(single) == {"num_envs", "autoreset_mode"}
    assert {name: batched[name].default for name in single} == {name: p.default for name, p in single.items()}
