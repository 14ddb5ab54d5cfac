"""The harder Reach tasks and the evaluation protocol: the dwell and the delay against hand-built timelines,
the noise and the field as documented, the score reward's return, checkers on every suite id, evaluate()."""

import importlib.util
import json
import math
import warnings
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import armgame.env
from armgame.env.base import EnvArgumentError
from armgame.env.center_out_batch import MAX_BATCH_ENVS, CenterOutBatchVectorEnv
from armgame.env.evaluation import evaluate, mean_interval, normalised_score
from armgame.env.policies import BotPolicy, bot_policy
from armgame.env.references import CEILINGS, REFERENCE_HITS, REFERENCES_V3
from armgame.env.suite import CENTER_OUT_SUITE, EVALUATION_SEEDS, SUITE, suite_ids
from armgame.env.variants import NOISE_FACTOR_MAX, ReachVariant
from armgame.env.vector import BATCH_MIN_ENVS, ReachV1VectorEnv, ReachVectorEnv, batch_plays
from armgame.env.vector_common import SingleEnvsVectorEnv
from armgame.errors import UserError
from armgame.game.batch.variant import BatchMuscleNoise
from armgame.game.rules import DwellRules, GameConfig
from armgame.game.session import GameSession

REACH = "armgame/Reach-v1"
#: The harder Reach ids the batch plays (the others step single envs), as docs/programs.md's id table says.
BATCHED = {"ReachDelay", "ReachHold", "ReachNoisy", "ReachField", "ReachHard"}
EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def play(env, policy, seed):
    """One whole episode; (observations, rewards, last info)."""
    obs, info = env.reset(seed=seed)
    env.action_space.seed(seed)
    observations, rewards = [obs], []
    done = False
    while not done:
        obs, reward, terminated, truncated, info = env.step(policy(obs) if policy else env.action_space.sample())
        observations.append(obs)
        rewards.append(reward)
        done = terminated or truncated
    return observations, rewards, info


# ------------------------------------------------------------------ the ids
@pytest.mark.parametrize("env_id", suite_ids())
def test_gymnasiums_checker_passes_on_every_suite_id(env_id):
    env = gym.make(env_id)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped, skip_render_check=True)
    assert env.unwrapped.continuous == ("Continuous" in env_id)
    name = env_id.split("/")[1].removesuffix("-v1").removesuffix("Continuous")
    if name in CENTER_OUT_SUITE:
        assert isinstance(gym.make_vec(env_id, num_envs=8).unwrapped, CenterOutBatchVectorEnv)
        assert env.unwrapped.trial_start == CENTER_OUT_SUITE[name]["trial_start"]
        return
    vector = type(gym.make_vec(env_id, num_envs=8).unwrapped)
    assert vector is (ReachV1VectorEnv if name in BATCHED else SingleEnvsVectorEnv), vector
    assert batch_plays(env_id, {}) == (name in BATCHED)
    for argument, value in SUITE[name].items():  # the id's arguments are the env's
        if argument == "target_radius":
            assert env.unwrapped.config.target_radius == value
        else:
            assert getattr(env.unwrapped.variant, argument) == value


def test_the_sb3_checker_passes_on_the_suite():
    pytest.importorskip("stable_baselines3")  # the rl extra, not the test extra: run where it is installed
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    for env_id in suite_ids():
        sb3_check_env(gym.make(env_id).unwrapped, warn=True)


@pytest.mark.parametrize("env_id", ["armgame/Reach-v0", REACH, "armgame/ReachContinuous-v1"])
def test_make_vec_steps_single_envs_below_the_batchs_size_and_for_what_the_batch_does_not_play(env_id):
    native = ReachV1VectorEnv if env_id.endswith("v1") else ReachVectorEnv
    for n in (1, BATCH_MIN_ENVS - 1):
        envs = gym.make_vec(env_id, num_envs=n, time_limit=0.2)
        assert isinstance(envs.unwrapped, SingleEnvsVectorEnv) and envs.num_envs == n
        singles = gym.vector.SyncVectorEnv([lambda: gym.make(env_id, time_limit=0.2) for _ in range(n)])
        envs.action_space.seed(0)
        assert gym.utils.env_checker.data_equivalence(envs.reset(seed=2), singles.reset(seed=2), exact=True)
        for _ in range(12):  # past the end: the next-step autoreset as SyncVectorEnv does it
            actions = envs.action_space.sample()
            assert gym.utils.env_checker.data_equivalence(envs.step(actions), singles.step(actions), exact=True)
    assert type(gym.make_vec(env_id, num_envs=BATCH_MIN_ENVS).unwrapped) is native
    if env_id.endswith("v1"):
        assert isinstance(gym.make_vec(env_id, num_envs=16, reward="score").unwrapped, SingleEnvsVectorEnv)
        assert isinstance(gym.make_vec(env_id, num_envs=16, motor_noise=0.1).unwrapped, ReachV1VectorEnv)
        # Noise and fields are the compiled kernel's: without it, single envs.
        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(armgame.env.vector, "compiled_available", lambda: False)
            assert isinstance(gym.make_vec(env_id, num_envs=16, motor_noise=0.1).unwrapped, SingleEnvsVectorEnv)
            assert isinstance(gym.make_vec(env_id, num_envs=16, field="curl").unwrapped, SingleEnvsVectorEnv)
            assert isinstance(gym.make_vec(env_id, num_envs=16, hold_time=0.1).unwrapped, ReachV1VectorEnv)
            with pytest.raises(EnvArgumentError, match="compiled kernel"):
                ReachV1VectorEnv(16, field="curl")
        with pytest.raises(EnvArgumentError, match="score"):
            ReachV1VectorEnv(2, reward="score")
    for bad in (0, 10**9, 2.5):
        with pytest.raises(EnvArgumentError, match="num_envs"):
            gym.make_vec(env_id, num_envs=bad)


def test_the_sb3_adapter_gives_sb3s_own_vec_env_where_no_batch_is_faster():
    pytest.importorskip("stable_baselines3")  # the rl extra, not the test extra: run where it is installed
    from stable_baselines3.common.vec_env import DummyVecEnv

    from armgame.env.sb3 import ADAPTER_MIN_ENVS, SB3VecEnv, make_sb3_vec_env

    assert isinstance(make_sb3_vec_env(REACH, ADAPTER_MIN_ENVS), SB3VecEnv)
    for env_id, n, kwargs in ((REACH, ADAPTER_MIN_ENVS - 1, {}), (REACH, 1, {}), ("armgame/CenterOutHold-v1", 32, {}),
                              (REACH, 32, {"reward": "score"}), ("armgame/CenterOut-v1", 2, {})):
        envs = make_sb3_vec_env(env_id, n, seed=4, **kwargs)
        assert isinstance(envs, DummyVecEnv) and envs.num_envs == n, env_id
        first = envs.reset()
        single = gym.make(env_id, **kwargs)
        assert np.array_equal(first[-1], single.reset(seed=4 + n - 1)[0])  # seeded as the adapter seeds


def test_bad_variant_arguments_are_refused_in_one_line():
    for kwargs, words in (({"hold_time": -0.1}, "hold_time"), ({"hold_time": math.nan}, "hold_time"),
                          ({"motor_noise": 1.5}, "motor_noise"), ({"observation_delay": 0.5}, "observation_delay"),
                          ({"observation_delay": 101}, "observation_delay"), ({"field": "magnetic"}, "field"),
                          ({"field_strength": 2.0}, "needs a field"), ({"field": "curl", "field_strength": 99},
                                                                       "field_strength"),
                          ({"target_radius": 0.0}, "target_radius"), ({"reward": "hits"}, "'score'")):
        with pytest.raises(EnvArgumentError, match=words) as caught:
            gym.make(REACH, **kwargs)
        assert "\n" not in str(caught.value)


# ------------------------------------------------------------------ the dwell
def test_the_dwell_counts_consecutive_steps_in_the_target_and_starts_again_outside():
    config = GameConfig(seed=3)
    rules = DwellRules(config, 3)
    target, dt = rules.target, config.dt
    inside, outside = (target.x, target.y), (target.x + 2 * target.radius, target.y)
    # Hand-built: in at steps 1 and 2, out at 3, in at 4, 5 and 6: the hit comes at step 6, not before.
    for step, (x, y) in enumerate([inside, inside, outside, inside, inside], start=1):
        if (x, y) == inside:  # the session calls hand_moved only on steps that end in the target
            assert not rules.hand_moved(x, y, step * dt)
    assert rules.board.hits == 0
    assert rules.hand_moved(*inside, 6 * dt) and rules.board.hits == 1 and rules.board.hit_times == [6 * dt]
    assert rules.target != target  # a new target, as the game draws it
    with pytest.raises(UserError, match="dwell"):
        DwellRules(config, 0)


def test_a_dwell_hit_is_the_step_the_hand_completes_its_stay_in_both_loops():
    """The game's hits under a dwell, step by step, against an oracle that watches the hand."""
    hold = 10
    config = GameConfig(seed=7, time_limit=20.0)
    env = gym.make(REACH, time_limit=20.0, observation_dtype="float64")
    policy = BotPolicy("model", env)
    # The model bot's keys in the plain game: a timeline that puts the hand in many targets.
    obs, _ = env.reset(seed=7)
    done = False
    while not done:
        obs, _, _, done, _ = env.step(policy(obs))
    timeline = env.unwrapped.session.timeline
    results = []
    for compiled in (True, False):
        session = GameSession(config, compiled=compiled, rules=DwellRules(config, hold))
        events, stay, hits_seen = iter(timeline), 0, []
        pending = next(events, None)
        while not session.over:
            while pending is not None and pending.step == session.steps:
                session.key_event(pending.key, pending.action)
                pending = next(events, None)
            target = session.rules.target
            hits = session.rules.board.hits
            session.advance(1)
            stay = stay + 1 if target.contains(*session.hand()) else 0
            if session.rules.board.hits != hits:
                hits_seen.append(session.steps)
                assert stay == hold, (session.steps, stay)  # a hit exactly when the stay reaches the dwell
                stay = 0
            else:
                assert stay < hold
        results.append((hits_seen, session.state))
    assert results[0] == results[1] and len(results[0][0]) >= 5  # both loops, the same game


# ------------------------------------------------------------------ the delay
def test_a_delayed_observation_is_the_one_so_many_steps_before():
    delay = 4
    late, now = gym.make(REACH, observation_delay=delay, time_limit=1.0), gym.make(REACH, time_limit=1.0)
    rng = np.random.default_rng(0)
    actions = rng.integers(0, 2, (50, 4))
    seen = [late.reset(seed=5)[0]]
    truth = [now.reset(seed=5)[0]]
    for action in actions:
        a, ra, _, _, ia = late.step(action)
        b, rb, _, _, ib = now.step(action)
        seen.append(a)
        truth.append(b)
        assert (ra, ia) == (rb, ib)  # the reward and the bookkeeping are not delayed
    for t, observation in enumerate(seen):
        assert np.array_equal(observation, truth[max(0, t - delay)]), t
    assert seen[-1] is not seen[-2]  # every observation is new data


# ------------------------------------------------------------------ noise and field
def test_motor_noise_scales_each_muscles_force_by_a_seeded_factor():
    noisy = gym.make(REACH, motor_noise=0.3, time_limit=4.0)
    plain = gym.make(REACH, time_limit=4.0)
    run = [play(noisy, None, 11), play(noisy, None, 11), play(plain, None, 11)]
    assert np.array_equal(np.array(run[0][0]), np.array(run[1][0]))  # seeded: the same game twice
    assert not np.array_equal(np.array(run[0][0]), np.array(run[2][0]))  # and not the plain game
    factors = []
    long_game = gym.make(REACH, motor_noise=0.3, time_limit=40.0)  # 2,000 decisions, each a new draw
    long_game.reset(seed=12)
    session = long_game.unwrapped.session
    base = np.array(GameConfig().muscles[0].moment[0])
    for _ in range(2000):
        long_game.step(np.zeros(4, dtype=np.int8))
        factors.append(session.muscles.moments[0][0] / base)
    factors = np.array(factors)
    assert factors.min() >= 0.0 and factors.max() <= NOISE_FACTOR_MAX
    assert abs(factors.mean() - 1.0) < 0.05 and abs(factors.std() - 0.3) < 0.05, (factors.mean(), factors.std())
    # Correlated over 50 ms: decisions 20 ms apart keep exp(-0.4) of the last draw.
    lag = np.corrcoef(factors[:-1], factors[1:])[0, 1]
    assert abs(lag - math.exp(-0.02 / 0.05)) < 0.05, lag


def test_a_zero_variant_is_the_game_itself():
    plain, zero = gym.make(REACH, time_limit=3.0), gym.make(REACH, time_limit=3.0, hold_time=0.0, motor_noise=0.0,
                                                           observation_delay=0, field=None)
    assert zero.unwrapped.variant.plain
    a, b = play(plain, None, 4), play(zero, None, 4)
    assert np.array_equal(np.array(a[0]), np.array(b[0])) and a[1] == b[1]


def test_the_curl_field_pushes_across_the_motion_and_keeps_the_speed_bound():
    field = gym.make(REACH, field="curl", field_strength=2.0, time_limit=5.0)
    plain = gym.make(REACH, time_limit=5.0)
    assert field.observation_space == plain.observation_space  # the curl field does no work
    effort = np.array([1, 0, 1, 0])
    a = [field.reset(seed=1)[0]] + [field.step(effort)[0] for _ in range(40)]
    b = [plain.reset(seed=1)[0]] + [plain.step(effort)[0] for _ in range(40)]
    assert not np.allclose(a[-1], b[-1])
    assert all(field.observation_space.contains(o) for o in a)
    viscous = gym.make(REACH, field="viscous")
    # A viscous field can do work, so no energy bound holds: its game stops at the bound instead (the guard).
    assert viscous.observation_space == plain.observation_space


def test_the_model_bot_still_scores_on_every_suite_task():
    for name in SUITE:
        env = gym.make(f"armgame/{name}-v1", time_limit=20.0)
        hits = play(env, BotPolicy("model", env), EVALUATION_SEEDS[0])[2]["hits"]
        assert hits >= (2 if name == "ReachHard" else 5), (name, hits)  # in a third of a game
    for name in CENTER_OUT_SUITE:  # a stop at home and in the target, every trial
        env = gym.make(f"armgame/{name}-v1")
        assert play(env, bot_policy("model", env), EVALUATION_SEEDS[0])[2]["hits"] == 8


# ------------------------------------------------------------------ the score reward
@pytest.mark.parametrize("kwargs", [{}, {"reset_key": True}, {"hold_time": 0.2, "motor_noise": 0.2},
                                    {"progress_weight": 0.0}])
def test_the_score_rewards_return_is_the_games_score(kwargs):
    env = gym.make(REACH, reward="score", time_limit=12.0, **kwargs)
    bot = None if kwargs.get("reset_key") else BotPolicy("model", env)
    for seed in (1, 2):
        _, rewards, info = play(env, bot, seed)
        assert math.isclose(sum(rewards), info["score"], abs_tol=1e-9), (sum(rewards), info)
        if bot is not None:
            assert info["score"] >= 3


def test_the_score_reward_is_the_score_change_plus_a_potentials_difference():
    env = gym.make(REACH, reward="score", progress_weight=10.0, time_limit=2.0)
    env.reset(seed=3)
    base = env.unwrapped
    edges, score = [], 0
    for t in range(100):
        before = base.session.rules.board.score
        _, reward, _, truncated, info = env.step(np.array([1, 0, 0, 1]) if t % 20 < 10 else np.array([0, 1, 1, 0]))
        hand, target = base.session.hand(), base.session.rules.target
        edge = 0.0 if truncated else max(0.0, math.hypot(hand[0] - target.x, hand[1] - target.y) - target.radius)
        phi_before = 0.0 if t == 0 else -edges[-1]
        assert math.isclose(reward, (info["score"] - before) + 10.0 * (-edge - phi_before), abs_tol=1e-12)
        edges.append(edge)
        score = info["score"]
    assert truncated and score == info["score"]


# ------------------------------------------------------------------ evaluate
def test_evaluate_is_deterministic_and_reports_an_interval():
    a = evaluate("random", REACH, games=3, time_limit=5.0)
    b = evaluate("random", REACH, games=3, time_limit=5.0)
    assert a == b and a.seeds == tuple(EVALUATION_SEEDS[:3])
    low, high = a.ci95
    assert low <= a.mean_hits <= high
    assert a.hits_per_minute == pytest.approx(a.mean_hits * 12.0)
    assert a.normalised is None  # another time limit than the references': no normalised score
    model = evaluate("model", REACH, seeds=[5])  # the id's own arguments: a normalised score
    assert model.normalised == pytest.approx(normalised_score(REACH, model.mean_hits)) and 0.5 < model.normalised < 1.5
    low, high = REFERENCE_HITS[REACH]["random"], CEILINGS[REACH]["hits"]
    assert (normalised_score(REACH, low, protocol=2), normalised_score(REACH, high, protocol=2)) == (0.0, 1.0)
    # Protocol 3, the default: the fixed reference is 1, whatever the best mean measured since.
    reference = REFERENCES_V3[REACH]
    assert (normalised_score(REACH, reference["random"]), normalised_score(REACH, reference["hits"])) == (0.0, 1.0)
    assert normalised_score(REACH, high) > 1.0  # protocol 2's ceiling, PPO's mean, is above the reference
    assert normalised_score("armgame/Reach-v0", 50.0) is None
    assert mean_interval([2, 4]) == pytest.approx((3 - 12.706 * 1.0, 3 + 12.706 * 1.0), abs=1e-3)
    for bad in ({"games": 0}, {"games": 1.5}, {"seeds": []}):
        with pytest.raises(EnvArgumentError):
            evaluate("random", REACH, **bad)
    with pytest.raises(EnvArgumentError, match="policy"):
        evaluate("clever", REACH, games=1)


def test_hits_a_minute_has_an_interval_over_games_of_different_lengths():
    """Hits a minute is total hits over total minutes; its interval (``ratio_interval``) comes from each game's hits
    and length, so episodes that all hit every trial still spread by how long they took (before, the hits'
    interval over a mean episode: 45.7-45.7 for the CenterOut reference)."""
    from armgame.env.evaluation import Evaluation, ratio_interval

    hits = [8] * 6
    near, far = [0.17, 0.18, 0.175, 0.172, 0.178, 0.176], [0.12, 0.24, 0.15, 0.21, 0.175, 0.176]
    for minutes in (near, far):
        ratio = sum(hits) / sum(minutes)
        low, high = ratio_interval(hits, minutes)
        assert low < ratio < high
    assert np.ptp(ratio_interval(hits, far)) > 3 * np.ptp(ratio_interval(hits, near))  # wider with the spread
    # Games of one length: the hits' t interval over that length, as before there were lengths to spread.
    assert ratio_interval([1, 3, 2], [0.5] * 3) == pytest.approx(tuple(v / 0.5 for v in mean_interval([1, 3, 2])))
    # One game, or every game the same rate: the ratio twice, no crash; never below 0 when told so.
    assert ratio_interval([8], [0.2]) == (40.0, 40.0)
    assert ratio_interval([4, 8], [0.1, 0.2]) == pytest.approx((40.0, 40.0))
    assert ratio_interval([0, 0, 1], [1.0, 1.0, 1.0], low=0.0)[0] == 0.0 < ratio_interval([0, 0, 1], [1.0] * 3)[1]
    with pytest.raises(ValueError, match="as many"):
        ratio_interval([1, 2], [0.5])
    made = Evaluation("armgame/CenterOut-v1", "x", (1, 2, 3, 4, 5, 6), tuple(hits), tuple(hits), float(np.mean(far)),
                      None, game_minutes=tuple(far))
    assert made.hits_per_minute == pytest.approx(8 / np.mean(far))  # the same number as ever
    assert made.hits_per_minute_ci95 == ratio_interval(hits, far, low=0.0)
    # evaluate keeps each game's minutes: a CenterOut episode lasts as its trials take.
    result = evaluate("model", "armgame/CenterOut-v1", games=3)
    assert len(result.game_minutes) == 3 and len(set(result.game_minutes)) > 1
    assert result.minutes == pytest.approx(np.mean(result.game_minutes))
    low, high = result.hits_per_minute_ci95
    assert low < result.hits_per_minute < high
    assert evaluate("random", REACH, games=2, time_limit=5.0).game_minutes == (5.0 / 60, 5.0 / 60)


def test_a_counts_interval_is_clipped_to_the_values_it_can_take():
    """Student's t is symmetric, so five seeds of which one is far above the rest give a count's mean a negative
    lower end (PPO on ReachMemory-v1: -5.4 to 12.3); clipped, it keeps t's upper end and starts at 0."""
    seeds = [0.5, 0.2, 0.0, 0.3, 16.1]
    low, high = mean_interval(seeds)
    assert low < 0
    assert mean_interval(seeds, low=0.0) == (0.0, high)
    assert mean_interval([7.9, 8.0, 6.5, 8.0, 8.0], low=0.0, high=8.0)[1] == 8.0
    from armgame.env.evaluation import Evaluation

    rare = Evaluation(REACH, "random", (1, 2, 3, 4), (0, 0, 0, 1), (0, 0, 0, 1), 1.0, None)
    assert rare.ci95 == (0.0, mean_interval(rare.hits)[1]) and rare.hits_per_minute_ci95[0] == 0.0


class Model:
    """A model with SB3's ``predict``: a fixed linear policy of the observation (one row or many)."""

    def __init__(self, size):
        self.weights = np.random.default_rng(1).standard_normal((size, 4))

    def predict(self, observation, deterministic=True):
        return (np.asarray(observation) @ self.weights > 0).astype(np.int8), None


@pytest.mark.parametrize("env_id", [REACH, "armgame/CenterOut-v1"])
def test_a_models_games_played_together_are_its_games_played_one_by_one(env_id):
    model = Model(gym.make(env_id).observation_space.shape[0])
    kwargs = {"time_limit": 3.0} if env_id == REACH else {}
    together = evaluate(model, env_id, seeds=[3, 4, 5], **kwargs)
    alone = evaluate(lambda obs: model.predict(obs[None])[0][0], env_id, seeds=[3, 4, 5], **kwargs)
    assert together.hits == alone.hits and together.scores == alone.scores and together.policy == "Model"
    assert together.minutes == alone.minutes > 0


def test_the_reference_scores_are_evaluates_own():
    """The random and model-bot references that normalise every score: the first games of their runs."""
    assert set(REFERENCE_HITS) == {REACH, "armgame/ReachContinuous-v1", "armgame/CenterOut-v1",
                                   "armgame/CenterOutContinuous-v1", *suite_ids()}
    for env_id in (REACH, "armgame/ReachHold-v1"):
        for policy in ("random", "model"):
            reference = REFERENCE_HITS[env_id]
            result = evaluate(policy, env_id, games=3)  # the first three of the games the reference played
            assert list(result.hits) == reference[f"{policy}_first"][:3], (env_id, policy)


def test_the_registry_lists_every_id_the_docs_name():
    assert set(suite_ids()) <= set(gym.registry)
    assert {ReachVariant.of(**{k: v for k, v in args.items() if k != "target_radius"}).plain
            for args in SUITE.values()} == {False}
    assert armgame.env.SUITE is SUITE


@pytest.mark.slow  # about 1.6 s: test_env_v1 trains the same method on the plain game in the suite; CI runs this
def test_the_small_learner_still_beats_random_play_on_a_harder_task():
    """examples/train_es.py's cross-entropy method, smaller than tests/test_env_v1.py runs it, on the delayed game."""
    spec = importlib.util.spec_from_file_location("train_es", EXAMPLES / "train_es.py")
    es = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(es)
    env_id = "armgame/ReachDelayContinuous-v1"
    policy, history = es.cem(generations=10, population=32, seconds=2.0, seed=0, env_id=env_id)
    learned = es.hits_per_game(policy, games=8, seconds=10.0, seed=100, env_id=env_id)
    random = es.hits_per_game(None, games=8, seconds=10.0, seed=100, env_id=env_id)
    assert history[-1][1] > history[0][1]  # the population's return rose
    assert learned.mean() >= 1.0 and learned.mean() >= 4 * random.mean(), (learned, random)


def test_the_docs_reference_table_and_the_ceilings_are_the_committed_results():
    """docs/programs.md's reference table is ``reference_scores.py table`` of the committed results (the bots and
    protocol 1's PPO in armgame/env/references.py, the controller's and PPO's runs under benchmarks/results), and
    references.py's CEILINGS, which normalise every score, are ``reference_scores.py ceilings`` of the same files."""
    from armgame.env.references import CEILINGS

    root = Path(__file__).resolve().parent.parent
    spec = importlib.util.spec_from_file_location("reference_scores", root / "benchmarks" / "reference_scores.py")
    scores = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(scores)
    assert scores.ceilings() == CEILINGS
    assert set(CEILINGS) == set(REFERENCE_HITS)
    for env_id, ceiling in CEILINGS.items():
        # A ceiling is at least every reference policy's score on the same games, and a twin's at least its key id's.
        assert ceiling["hits"] >= max(REFERENCE_HITS[env_id][p] for p in ("random", "naive", "model")), env_id
        key = env_id.replace("Continuous", "")
        assert ceiling["hits"] >= CEILINGS[key]["hits"], env_id
        # And an id without the observation delay at least its delayed variant's: the delay can only cost.
        for delayed in scores.delayed_variants(list(CEILINGS)).get(env_id, ()):
            assert ceiling["hits"] >= CEILINGS[delayed]["hits"], env_id
    text = (root / "docs" / "programs.md").read_text(encoding="utf-8")
    assert scores.table() in text
    # The page's reading of the table: PPO's shortfall from the ceiling, by the table's PPO column.
    short, budgets = {}, {}
    for row in scores.table().splitlines()[2:]:
        cells = [c.strip() for c in row.strip("|").split("|")]
        short[cells[0].strip("`")] = round(100 * (1 - float(cells[-1])))
        budgets[cells[0].strip("`")] = cells[4].split(",")[0]
    prose = " ".join(text.split())
    # Where PPO ran five seeds at 4 M steps or more, it is the ceiling or within a few % of it.
    long = [name for name in short if "Continuous" not in name and "CenterOut" not in name and budgets[name] != "0.5 M"]
    tops = [name.removesuffix("-v1") for name in long if short[name] == 0]
    near = [name.removesuffix("-v1") for name in long if short[name] > 0]
    assert (f"it is the ceiling ({', '.join(tops)}) or within {max(short[n + '-v1'] for n in near)} % of it "
            f"({', '.join(near)})") in prose
    # The delay's cost with continuous actions, at its budget and at protocol 1's 500,000 (references.py).
    twin = "ReachDelayContinuous-v1"
    early = round(100 * (1 - (REFERENCE_HITS[f"armgame/{twin}"]["ppo"] - REFERENCE_HITS[f"armgame/{twin}"]["random"])
                          / (CEILINGS[f"armgame/{twin}"]["hits"] - REFERENCE_HITS[f"armgame/{twin}"]["random"])))
    assert budgets[twin] == "4 M" and (f"With continuous actions the delay costs PPO {short[twin]} % at 4 M steps "
                                       f"({early} % at 500,000") in prose
    # With continuous actions at 4 M steps, ReachHard's twin the farthest; the rows still at 500,000 within a bound.
    hard = "ReachHardContinuous-v1"
    twins = [n for n in short if "Continuous" in n and "CenterOut" not in n and budgets[n] == "4 M" and n != hard]
    early_rows = [n for n in short if budgets[n] == "0.5 M" and "CenterOut" not in n]
    named = {n: n.removesuffix("-v1").removesuffix("Continuous") for n in short}
    assert budgets[hard] == "4 M" and short[hard] > max(short[n] for n in twins + early_rows)
    assert all("Continuous" in n for n in early_rows)
    reading = (f"is ReachHard's continuous twin ({short[hard]} %); the other twins at 4 M steps are within "
               f"{max(short[n] for n in twins)} % ({', '.join(named[n] for n in twins)})")
    if early_rows:
        reading += (f", and those still at 500,000 steps within {max(short[n] for n in early_rows)} % "
                    f"({', '.join(named[n] for n in early_rows)})")
    assert reading + ("" if early_rows else ".") in prose


def test_a_ceiling_is_the_best_candidate_and_reaches_the_ids_that_play_the_same_game():
    """``reference_scores._ceilings_of`` on made-up results: PPO's five-seed runs beat the controller on the delayed
    id, so the delay-free id and both twins take that ceiling; fewer than five seeds never count."""
    root = Path(__file__).resolve().parent.parent
    spec = importlib.util.spec_from_file_location("reference_scores", root / "benchmarks" / "reference_scores.py")
    scores = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(scores)
    ids = ("armgame/Reach-v1", "armgame/ReachContinuous-v1", "armgame/ReachDelay-v1", "armgame/ReachDelayContinuous-v1")
    assert scores.delayed_variants(list(ids)) == {"armgame/Reach-v1": ["armgame/ReachDelay-v1"],
                                                  "armgame/ReachContinuous-v1": ["armgame/ReachDelayContinuous-v1"]}
    reference = {env_id: {"random": 0.5, "model": 50.0} for env_id in ids}
    controller = {"armgame/Reach-v1": (72.0, 71.0, 73.0, 100, "armgame/Reach-v1"),
                  "armgame/ReachDelay-v1": (72.0, 71.0, 73.0, 100, "armgame/Reach-v1")}
    runs = {"armgame/ReachDelay-v1": {4_000_000: [75.0, 76.0, 77.0, 78.0, 79.0]},
            "armgame/ReachContinuous-v1": {4_000_000: [90.0, 90.0, 90.0, 90.0]}}  # four seeds: not a candidate
    tops = scores._ceilings_of(reference, controller, runs)
    assert tops["armgame/ReachDelay-v1"] == {"hits": 77.0, "by": "PPO, 4,000,000 env steps, 5 seeds"}
    assert tops["armgame/Reach-v1"] == {"hits": 77.0, "by": "ReachDelay-v1's ceiling (a delay can only cost)"}
    assert tops["armgame/ReachDelayContinuous-v1"]["hits"] == tops["armgame/ReachContinuous-v1"]["hits"] == 77.0
    assert list(tops) == list(ids)  # in the reference's order, whatever order they were worked out in
    runs["armgame/ReachDelay-v1"] = {4_000_000: [60.0] * 5}
    assert scores._ceilings_of(reference, controller, runs)["armgame/Reach-v1"]["by"] == \
        "the shooting controller (100 games)"


def test_the_off_policy_recipe_runs(capsys):
    pytest.importorskip("stable_baselines3")  # the rl extra, not the test extra: run where it is installed
    spec = importlib.util.spec_from_file_location("train_sac", EXAMPLES / "train_sac.py")
    sac = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(sac)
    assert sac.main(["--minutes", "0.05", "--envs", "2", "--eval-every", "400", "--games", "1",
                     "--test-games", "1"]) == 0
    out = capsys.readouterr().out
    assert "hits per game" in out and "best validation mean hits per game" in out



def test_the_size_cap_of_each_suite_ids_vector_env_is_the_one_the_docs_state():
    """A suite id the batch does not play is single envs in Gymnasium's SyncVectorEnv: at most
    SingleEnvsVectorEnv.MAX_ENVS; one it plays (BATCHED) takes the native env's memory budget over a game's, a
    delay's ring included. Each is refused in one line past its cap, as docs/programs.md says."""
    cap = SingleEnvsVectorEnv.MAX_ENVS
    guide = " ".join((Path(__file__).resolve().parent.parent / "docs" / "programs.md").read_text(encoding="utf-8")
                     .split())
    assert f"holds at most {cap:,} envs" in guide
    for env_id in suite_ids():
        name = env_id.split("/")[1].removesuffix("-v1").removesuffix("Continuous")
        if name in BATCHED:
            ring = 15 * 4 * (SUITE[name].get("observation_delay", -1) + 1)  # float32 observations, delay + 1
            noise = BatchMuscleNoise.BYTES_PER_GAME if SUITE[name].get("motor_noise") else 0
            most = armgame.env.vector.MAX_ENV_MEMORY // (armgame.env.vector.BYTES_PER_ENV + ring + noise)
            assert f"`{name}-v1` and its twin at most {most:,} envs" in guide
            with pytest.raises(EnvArgumentError, match=f"at most {most:,} games"):
                gym.make_vec(env_id, num_envs=most + 1, vectorization_mode="vector_entry_point")
            continue
        if name in CENTER_OUT_SUITE:  # the CenterOut batch (issue 52): its own cap, past SyncVectorEnv's
            most = MAX_BATCH_ENVS
            assert f"It holds up to {most:,} envs" in guide
            with pytest.raises(EnvArgumentError, match=f"from 1 to {most:,}, got {most + 1}"):
                gym.make_vec(env_id, num_envs=most + 1, vectorization_mode="vector_entry_point")
            continue
        with pytest.raises(EnvArgumentError, match=f"from 1 to {cap}, got {cap + 1}"):
            gym.make_vec(env_id, num_envs=cap + 1, vectorization_mode="vector_entry_point")


def test_the_docs_motornet_table_is_the_committed_run():
    """docs/programs.md's table beside MotorNet is the committed run's (benchmarks/results/env_speed_motornet.json),
    each id's median ratios and its rate at 8,192 envs, and every suite Reach id made 1 M env steps per CPU second."""
    root = Path(__file__).resolve().parent.parent
    run = json.loads((root / "benchmarks" / "results" / "env_speed_motornet.json").read_text(encoding="utf-8"))
    guide = (root / "docs" / "programs.md").read_text(encoding="utf-8")
    sizes = ("1", "4", "16", "64", "256", "1024", "4096", "8192")
    for env_id, found in run["ids"].items():
        ratios = " | ".join(f"{found['sizes'][n]['ratio']['median']:.2f}" for n in sizes)
        fastest = f"{found['sizes']['8192']['make_vec']['cpu']['median']:,.0f}"
        assert f"| `{env_id.split('/')[1]}` | {ratios} | {fastest} |" in guide, env_id
        assert found["batched"] and found["sizes"]["8192"]["make_vec"]["cpu"]["median"] >= 1e6, env_id
    # From 256 envs, 20 times MotorNet is more than the batch makes at any size: the docs' figures are the run's.
    slowest = min(found["sizes"]["256"]["motornet"]["cpu"]["median"] for found in run["ids"].values())
    fastest_id, fastest, at = max(((env_id, found["sizes"][n]["make_vec"]["cpu"]["median"], n)
                                   for env_id, found in run["ids"].items() for n in sizes), key=lambda f: f[1])
    prose = " ".join(guide.split())
    assert 20 * slowest > fastest and (
        f"20 times MotorNet's slowest rate at 256 envs ({slowest:,.0f}) is {20 * slowest / 1e6:.2f} M env steps per "
        f"CPU second, and the fastest rate in the table is {fastest / 1e6:.2f} M (`{fastest_id.split('/')[1]}` at "
        f"{int(at):,})") in prose
    assert set(run["ids"]) == {i for i in suite_ids() if "Reach" in i} | {
        "armgame/Reach-v0", "armgame/ReachContinuous-v0", "armgame/Reach-v1", "armgame/ReachContinuous-v1"}


def test_the_docs_env_share_of_ppo_is_the_committed_run():
    """docs/programs.md's table of the env's share of PPO's training (benchmarks/results/sb3_env_share.json,
    ``sb3_speed.py --share``) and what it says of 20 times MotorNet between 4 and 1,024 envs are the runs' figures."""
    root = Path(__file__).resolve().parent.parent
    results = root / "benchmarks" / "results"
    run = json.loads((results / "sb3_env_share.json").read_text(encoding="utf-8"))
    guide = (root / "docs" / "programs.md").read_text(encoding="utf-8")
    prose = " ".join(guide.split())
    motornet_us = 1e6 / run["motornet"]["cpu"]["median"]
    gains, losses = [], []
    for env_id, e in run["ids"].items():
        assert e["ppo_us_per_step"] == pytest.approx(e["us_per_step"] - e["env_us_per_step"])
        assert e["with_20x_motornet_us_per_step"] == pytest.approx(e["ppo_us_per_step"] + motornet_us / 20)
        now, mn, x20 = (1e6 / e[k] for k in ("us_per_step", "with_motornet_us_per_step",
                                            "with_20x_motornet_us_per_step"))
        share = e["share"]
        assert x20 / now - 1 <= share["max"], env_id  # a faster env saves at most its share
        gains.append(100 * (x20 / now - 1))
        losses.append(100 * (1 - mn / now))
        row = (f"| `{env_id.split('/')[1]}` | {now:,.0f} | {e['ppo_us_per_step']:.1f} | {e['env_us_per_step']:.1f} | "
               f"{100 * share['median']:.1f} % ({100 * share['min']:.1f}-{100 * share['max']:.1f}) | {mn:,.0f} | "
               f"{x20:,.0f} ({gains[-1]:+.1f} %) |")
        assert row in guide, row
    cpu = run["motornet"]["cpu"]
    assert (f"{cpu['median']:,.0f} env steps per CPU second ({motornet_us:.1f} µs a step; {cpu['min']:,.0f} to "
            f"{cpu['max']:,.0f})") in prose
    assert (f"would make its training {min(gains):.1f} to {max(gains):.1f} % faster, never more than the env's "
            f"share, where MotorNet's env in armgame's place makes it {min(losses):.1f} to {max(losses):.1f} % "
            "slower") in prose
    # The fixed cost of a vector step: the side-by-side run's rates at 4 envs.
    speed = json.loads((results / "env_speed_motornet.json").read_text(encoding="utf-8"))
    at4 = {env_id: 4e6 / found["sizes"]["4"]["make_vec"]["cpu"]["median"] for env_id, found in speed["ids"].items()}
    theirs = 4e6 / speed["ids"][REACH]["sizes"]["4"]["motornet"]["cpu"]["median"]
    fastest, slowest = min(at4, key=at4.__getitem__), max(at4, key=at4.__getitem__)
    assert (f"{at4[fastest]:.0f} to {at4[slowest]:.0f} µs at 4 envs in the run above (`{fastest.split('/')[1]}` to "
            f"`{slowest.split('/')[1]}`), against MotorNet's {theirs:.0f} µs") in prose
