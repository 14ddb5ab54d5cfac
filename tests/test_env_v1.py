"""The v1 envs: checkers, observations that are the session's, the dense reward's formula, vector == single
under reset masks and every autoreset mode, CenterOut trials a random policy starts, and learnability."""

import doctest
import importlib.util
import math
import os
import warnings
from pathlib import Path

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env, data_equivalence
from gymnasium.vector import AutoresetMode, SyncVectorEnv

import armgame.env
import armgame.env.center_out_v1
import armgame.env.features
import armgame.env.reach_v1
import armgame.env.vector
from armgame.env.base import EnvArgumentError
from armgame.env.center_out_v1 import CenterOutVectorEnv
from armgame.env.vector import ReachV1VectorEnv
from armgame.game.rules import DwellRules, GameConfig
from armgame.lab.protocol import Block, Protocol
from armgame.lab.session import REACH as REACH_PHASE

REACH, CONTINUOUS = "armgame/Reach-v1", "armgame/ReachContinuous-v1"
CENTER_OUT, CENTER_OUT_CONTINUOUS = "armgame/CenterOut-v1", "armgame/CenterOutContinuous-v1"
EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


@pytest.fixture(autouse=True)
def batch_at_every_size(monkeypatch):
    """These tests hold the batched vector env to single envs on a few games, where make_vec would otherwise
    step single envs (``BATCH_MIN_ENVS``); tests/test_env_suite.py tests that choice."""
    monkeypatch.setattr(armgame.env.vector, "BATCH_MIN_ENVS", 1)


def edge_of(point, target) -> float:
    """The distance from ``point`` (the hand, or the cursor) to ``target``'s edge, 0 inside: what the dense
    reward's progress is measured in (``features.edge_distance``)."""
    return float(armgame.env.features.edge_distance(point[0], point[1], target.x, target.y, target.radius))


def example(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize(("env_id", "kwargs"), [
    (REACH, {}), (REACH, {"reset_key": True, "reward": "sparse"}), (CONTINUOUS, {}),
    (CENTER_OUT, {}), (CENTER_OUT_CONTINUOUS, {"episode_trials": "block", "protocol": "rotation"}),
    (CENTER_OUT, {"trial_start": "hold", "reward": "sparse", "time_cost": 0.1})])
def test_gymnasiums_checker_passes_on_every_v1_env(env_id, kwargs):
    env = gym.make(env_id, **kwargs)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped)
    assert env.observation_space.dtype == np.float32
    if env.unwrapped.continuous:
        assert env.action_space == gym.spaces.Box(-1.0, 1.0, env.action_space.shape, np.float32)
    env.close()


def test_the_v1_ids_and_their_vector_entry_points_are_registered():
    assert set(armgame.env.V1_IDS + armgame.env.CENTER_OUT_V1_IDS) <= set(gym.registry)
    assert isinstance(gym.make_vec(REACH, num_envs=2).unwrapped, ReachV1VectorEnv)
    assert isinstance(gym.make_vec(CENTER_OUT, num_envs=2).unwrapped, CenterOutVectorEnv)


def test_each_version_is_a_sibling_of_the_other_not_its_subclass():
    """Gymnasium's way: v1 derives from the versions' shared base, never from v0, so a change to v0 cannot
    reach v1; and every registered id's class is one version's, not two."""
    from armgame.env.center_out import CenterOutBaseEnv, CenterOutEnv
    from armgame.env.center_out_v1 import CenterOutV1Env
    from armgame.env.reach import ReachBaseEnv, ReachEnv
    from armgame.env.reach_v1 import ReachV1Env

    for v0, v1, base in ((ReachEnv, ReachV1Env, ReachBaseEnv), (CenterOutEnv, CenterOutV1Env, CenterOutBaseEnv)):
        assert not issubclass(v1, v0) and not issubclass(v0, v1)
        assert issubclass(v0, base) and issubclass(v1, base)
        assert (v0.version, v1.version) == (0, 1)
    for env_id in [i for i in gym.registry if i.startswith("armgame/")]:
        env = gym.make(env_id).unwrapped
        assert f"-v{env.version}" in env_id
        assert isinstance(env, ReachBaseEnv | CenterOutBaseEnv)
        assert isinstance(env, ReachEnv | CenterOutEnv) == (env.version == 0)
        env.close()


@pytest.mark.parametrize("module", [armgame.env.features, armgame.env.reach_v1, armgame.env.center_out_v1,
                                    armgame.env.vector])
def test_the_docstrings_examples_run(module):
    failed, attempted = doctest.testmod(module)
    assert failed == 0 and attempted > 0


def test_observations_are_the_sessions_hand_and_target():
    env = gym.make(REACH, time_limit=2.0)
    env.action_space.seed(3)
    obs, _ = env.reset(seed=3)
    session = env.unwrapped.session
    arm = session.config.arm
    for _ in range(100):
        obs, *_ = env.step(env.action_space.sample())
        q1, q2, w1, w2 = session.state
        hx, hy = session.hand()
        # The hand's velocity by finite differences of the session's own hand, over a tiny step in time.
        eps = 1e-7
        ax = arm.l1 * math.cos(q1 + w1 * eps) + arm.l2 * math.cos(q1 + q2 + (w1 + w2) * eps)
        ay = arm.l1 * math.sin(q1 + w1 * eps) + arm.l2 * math.sin(q1 + q2 + (w1 + w2) * eps)
        target = session.rules.target
        expected = [hx, hy, (ax - hx) / eps, (ay - hy) / eps, target.x - hx, target.y - hy]
        assert np.allclose(obs[8:14], expected, rtol=1e-5, atol=2e-5)
        assert obs[4:8].tolist() == pytest.approx(session.muscles.activation, abs=1e-7)
        assert obs[14] == pytest.approx(session.time_left / 2.0, abs=1e-7)
        assert obs in env.observation_space


def test_observations_stay_within_their_bounds_at_full_effort():
    env = gym.make(REACH, time_limit=4.0)
    obs, _ = env.reset(seed=0)
    speeds = []
    for step in range(200):  # both flexors on: the arm swings to its fastest, then alternates
        action = np.array([1, 0, 1, 0] if (step // 40) % 2 == 0 else [0, 1, 0, 1])
        obs, *_ = env.step(action)
        assert obs in env.observation_space
        speeds.append(abs(obs[10:12]).max())
    assert 0.5 < max(speeds) < env.observation_space.high[10]


def game_return_by_formula(env_id, seed, steps, action_seed, **kwargs):
    """The dense return summed step by step, and the formula's total from each target's starting
    distance (float64, from the session), the last target's final distance, hits and resets."""
    env = gym.make(env_id, **kwargs)
    base = env.unwrapped
    env.action_space.seed(action_seed)
    env.reset(seed=seed)
    session = base.session

    def edge():
        hx, hy = session.hand()
        t = session.rules.target
        return max(0.0, math.hypot(hx - t.x, hy - t.y) - t.radius)

    starts, total, info = [edge()], 0.0, {}
    for _ in range(steps):
        action = env.action_space.sample()
        if base.settings.reset_key:
            action[4] = action[4] * (np.random.default_rng(len(starts) + _).random() < 0.03)
        hits = session.rules.board.hits
        _, reward, _, truncated, info = env.step(action)
        total += reward
        starts += [edge()] * (session.rules.board.hits - hits)
        if truncated:
            break
    s = base.settings
    formula = s.progress_weight * (sum(starts[:-1]) + starts[-1] - edge()) + s.hit_bonus * info["hits"] \
        - base.config.reset_cost * info["resets"]
    return total, formula, info


@pytest.mark.parametrize(("env_id", "kwargs"), [(REACH, {}), (CONTINUOUS, {"reset_key": True}),
                                               (REACH, {"progress_weight": 3.0, "hit_bonus": 0.5})])
def test_the_dense_rewards_sum_over_a_game_is_its_formula(env_id, kwargs):
    from armgame.env.policies import BotPolicy

    # A bot hits targets (so the restart at each new target is exercised); random play moves away too.
    env = gym.make("armgame/Reach-v0", time_limit=6.0)
    policy, obs = BotPolicy("model", env), env.reset(seed=4)[0]
    v1 = gym.make(REACH, time_limit=6.0, **{k: v for k, v in kwargs.items() if k != "reset_key"})
    v1.reset(seed=4)
    session = v1.unwrapped.session
    total, starts = 0.0, [edge_of(session.hand(), session.rules.target)]
    while True:
        action = policy(obs)
        obs, *_ = env.step(action)
        hits = session.rules.board.hits
        _, reward, _, truncated, info = v1.step(action)
        total += reward
        starts += [edge_of(session.hand(), session.rules.target)] * (session.rules.board.hits - hits)
        if truncated:
            break
    s = v1.unwrapped.settings
    assert info["hits"] >= 3
    last = edge_of(session.hand(), session.rules.target)
    assert total == pytest.approx(s.progress_weight * (sum(starts) - last) + s.hit_bonus * info["hits"], abs=1e-9)
    total, formula, info = game_return_by_formula(env_id, seed=8, steps=300, action_seed=1, time_limit=6.0, **kwargs)
    assert total == pytest.approx(formula, abs=1e-9)
    if kwargs.get("reset_key"):
        assert info["resets"] >= 1


def test_sparse_reward_is_one_per_hit():
    env = gym.make(REACH, reward="sparse", time_limit=6.0)
    from armgame.env.policies import BotPolicy

    keys = gym.make("armgame/Reach-v0", time_limit=6.0)
    policy = BotPolicy("model", keys)
    obs, _ = keys.reset(seed=4)
    env.reset(seed=4)
    total = 0.0
    for _ in range(300):
        action = policy(obs)
        obs, *_ = keys.step(action)
        _, reward, _, _, info = env.step(action)
        total += reward
    assert total == info["hits"] == info["score"] >= 3


def test_seeded_rollouts_repeat_bit_for_bit():
    def rollout():
        env = gym.make(CONTINUOUS, time_limit=1.0)
        env.action_space.seed(5)
        out = [env.reset(seed=5)[0].tobytes()]
        for _ in range(60):
            obs, reward, _, truncated, info = env.step(env.action_space.sample())
            out.append((obs.tobytes(), reward, truncated, tuple(info.items())))
            if truncated:
                out.append(env.reset()[0].tobytes())
        return out

    assert rollout() == rollout()


def test_bad_v1_arguments_are_refused_in_one_line():
    for kwargs in ({"reward": "shaped"}, {"progress_weight": -1.0}, {"hit_bonus": True}):
        with pytest.raises(EnvArgumentError, match=next(iter(kwargs))):
            gym.make(REACH, **kwargs)
    for kwargs in ({"trial_start": "now"}, {"episode_trials": 0}, {"episode_trials": "run"}):
        with pytest.raises(EnvArgumentError, match=next(iter(kwargs))):
            gym.make(CENTER_OUT, **kwargs)
    center_out = gym.make(CENTER_OUT)
    with pytest.raises(EnvArgumentError, match="jointspace"):  # its cursor would leave the bounded space
        center_out.reset(seed=0, options={"protocol": "jointspace"})
    center_out.reset(seed=0, options={"protocol": "rotation"})  # a rotated cursor stays within bounds
    assert gym.make(CENTER_OUT, protocol="jointspace").observation_space.high[8] == np.inf
    env = gym.make(CONTINUOUS)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"\[-1, 1\]"):
        env.step(np.full(4, np.nan))


# ------------------------------------------------------------------ vector == single
def same_step(a, b, exact_obs):
    (oa, ra, ta, ua, ia), (ob, rb, tb, ub, ib) = a, b
    if exact_obs:
        assert data_equivalence(oa, ob, exact=True)
    else:  # the batch's fast kernel rounds differently (STATE_TOLERANCE); float32 rounds on top
        assert np.abs(oa - ob).max() <= 1e-5
    assert np.allclose(ra, rb, rtol=0, atol=1e-9) and ta.tolist() == tb.tolist() and ua.tolist() == ub.tolist()
    finals = {k for k in ia if "final_obs" in k}
    rest = {k: v for k, v in ia.items() if k not in finals}
    assert data_equivalence(rest, {k: v for k, v in ib.items() if k not in finals}, exact=True), (ia, ib)
    if "final_obs" in ia:
        assert ia["_final_obs"].tolist() == ib["_final_obs"].tolist()
        for x, y in zip(ia["final_obs"], ib["final_obs"], strict=True):
            assert (x is None) == (y is None) and (x is None or np.abs(x - y).max() <= 1e-5)


@pytest.mark.parametrize("mode", list(AutoresetMode))
@pytest.mark.parametrize("env_id", [REACH, CONTINUOUS, "armgame/Reach-v0"])
def test_the_vector_env_equals_sync_vector_env_under_random_reset_masks(env_id, mode):
    n, rng = 4, np.random.default_rng(7)
    kwargs = {"time_limit": 0.3, "decision_steps": 4}  # 19 steps a game, the last one of 3 physics steps
    native = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", autoreset_mode=mode,
                          **kwargs)
    singles = SyncVectorEnv([lambda: gym.make(env_id, **kwargs) for _ in range(n)], autoreset_mode=mode)
    assert native.metadata["autoreset_mode"] is mode
    native.action_space.seed(1)
    a, b = native.reset(seed=11), singles.reset(seed=11)
    # v0's float64 observation is the single env's bit for bit where the batch runs the exact numpy kernel.
    exact = env_id.endswith("v0") and native.unwrapped.parts[0][1].compiled is None
    assert data_equivalence(a, b, exact=True)
    resets, ended = _step_both_with_masked_resets(native, singles, mode, rng, n, steps=90, every=(13, 6),
                                                  exact=exact)
    assert resets >= 7 and ended >= 4


def _step_both_with_masked_resets(native, singles, mode, rng, n: int, steps: int, every: tuple[int, int],
                                  exact: bool) -> tuple[int, int]:
    """The same random actions on both vector envs for ``steps`` steps, a masked reset (random seeds or none) at
    every ``every[0]``-th step from ``every[1]`` and wherever Disabled mode needs one; each step's results held
    equal (``same_step``). Returns how many masked resets and how many games ended."""
    resets = ended = 0
    for step in range(steps):
        if step % every[0] == every[1] or (mode is AutoresetMode.DISABLED and singles._autoreset_envs.any()):
            mask = rng.random(n) < 0.5
            if mode is AutoresetMode.DISABLED:
                mask |= singles._autoreset_envs
            if mask.any():
                seed = [int(s) if rng.random() < 0.5 else None for s in rng.integers(0, 1000, n)]
                ra = native.reset(seed=seed, options={"reset_mask": mask})
                rb = singles.reset(seed=seed, options={"reset_mask": mask})
                assert data_equivalence(ra[1], rb[1], exact=True)
                assert np.abs(ra[0] - rb[0]).max() <= 1e-5
                resets += 1
        actions = native.action_space.sample()
        a, b = native.step(actions), singles.step(actions)
        same_step(a, b, exact)
        ended += int(a[3].sum())
    return resets, ended


@pytest.mark.parametrize("mode", list(AutoresetMode))
@pytest.mark.parametrize(("env_id", "extra"), [
    ("armgame/ReachDelay-v1", {}), ("armgame/ReachDelayContinuous-v1", {}),
    (REACH, {"observation_delay": 1, "observation_dtype": "float64"}),
    (CONTINUOUS, {"observation_delay": 23, "reset_key": True, "reward": "sparse"}),  # longer than a game
    ("armgame/ReachHold-v1", {}), ("armgame/ReachHoldContinuous-v1", {}),
    (CONTINUOUS, {"hold_time": 0.04, "observation_delay": 2, "config": GameConfig(target_radius=0.2)}),
    ("armgame/ReachNoisy-v1", {}), ("armgame/ReachNoisyContinuous-v1", {"motor_noise": 1.0}),
    ("armgame/ReachField-v1", {}), ("armgame/ReachFieldContinuous-v1", {"field_strength": -50.0}),
    (REACH, {"field": "viscous", "field_strength": 2.0, "target_radius": 0.2}),
    ("armgame/ReachHard-v1", {}), ("armgame/ReachHardContinuous-v1", {"target_radius": 0.2}),
])
def test_the_harder_vector_env_equals_sync_vector_env_under_random_reset_masks(env_id, extra, mode):
    """The observation delay in the batched env (each game's ring of past observations) hands out what each single
    env's deque does, the batch's dwell scores what each single game's ``DwellRules`` does, and its motor noise
    (each game's own stream) and field push as each single game's do: through steps, restarts of either
    autoreset, SameStep's final observations and masked resets."""
    n, rng = 5, np.random.default_rng(3)
    kwargs = {"time_limit": 0.3, "decision_steps": 4, **extra}
    native = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", autoreset_mode=mode,
                          **kwargs)
    assert isinstance(native.unwrapped, ReachV1VectorEnv)
    singles = SyncVectorEnv([lambda: gym.make(env_id, **kwargs) for _ in range(n)], autoreset_mode=mode)
    native.action_space.seed(2)
    a, b = native.reset(seed=5), singles.reset(seed=5)
    assert data_equivalence(a[1], b[1], exact=True) and np.abs(a[0] - b[0]).max() <= 1e-5
    resets, ended = _step_both_with_masked_resets(native, singles, mode, rng, n, steps=120, every=(11, 4),
                                                  exact=False)
    assert resets >= 9 and ended >= 4


@pytest.mark.parametrize("kernel", ["numpy", None])
@pytest.mark.parametrize("hold_time", [0.2, 0.05])
def test_the_batchs_dwell_equals_single_envs_with_bots_scoring(hold_time, kernel, monkeypatch):
    """Random play seldom reaches a target, so the model bot plays: every hit the batch's dwell scores (the hand
    held in the target ``hold_time``, rules.DwellRules seeing each step inside) is the single env's, through two
    games each; and the dwell changes the games (a test that would pass had both sides lost it would not)."""
    from armgame.env.policies import BotPolicy
    from armgame.game.batch import BatchGameSession

    if kernel:  # both kernels flag a hand inside its target after every step: numpy's here, else the compiled one
        monkeypatch.setattr(armgame.env.vector, "BatchGameSession",
                            lambda *args, **kw: BatchGameSession(*args, **kw, kernel=kernel))
    n, kwargs = 4, {"time_limit": 2.0, "hold_time": hold_time, "observation_dtype": "float64"}
    native = gym.make_vec(REACH, num_envs=n, vectorization_mode="vector_entry_point", **kwargs)
    assert isinstance(native.unwrapped, ReachV1VectorEnv)
    singles = SyncVectorEnv([lambda: gym.make(REACH, **kwargs) for _ in range(n)])
    plain = gym.make_vec(REACH, num_envs=n, vectorization_mode="vector_entry_point",
                         **{**kwargs, "hold_time": 0.0})
    policies = [BotPolicy("model", gym.make(REACH, **kwargs)) for _ in range(n)]
    a, b, c = native.reset(seed=40), singles.reset(seed=40), plain.reset(seed=40)
    rules = native.unwrapped.parts[0][1].rules[0]
    assert (native.unwrapped.parts[0][1].compiled is None) == (kernel == "numpy")
    assert isinstance(rules, DwellRules) and rules.hold_steps == round(hold_time / 0.004)
    hits = plain_hits = 0
    for _ in range(2 * (native.unwrapped.settings.episode_steps + 1)):
        actions = np.array([policy(row) for policy, row in zip(policies, a[0], strict=True)])
        a, b, c = native.step(actions), singles.step(actions), plain.step(actions)
        same_step(a, b, False)
        hits += int(a[4]["hits"].sum())
        plain_hits += int(c[4]["hits"].sum())
    assert hits > 0 and hits != plain_hits


@pytest.mark.parametrize("env_id", ["armgame/ReachHard-v1", "armgame/ReachNoisyContinuous-v1"])
def test_the_batchs_noise_and_field_equal_single_envs_with_bots_scoring(env_id):
    """The model bot scores on the batch's noisy, pushed games the hits it scores on single envs, through two games."""
    from armgame.env.policies import BotPolicy

    n, kwargs = 4, {"time_limit": 3.0, "observation_dtype": "float64"}
    native = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", **kwargs)
    singles = SyncVectorEnv([lambda: gym.make(env_id, **kwargs) for _ in range(n)])
    policies = [BotPolicy("model", gym.make(env_id, **kwargs)) for _ in range(n)]
    a, b = native.reset(seed=60), singles.reset(seed=60)
    assert isinstance(native.unwrapped, ReachV1VectorEnv) and native.unwrapped.parts[0][1].variant is not None
    hits = 0
    for _ in range(2 * (native.unwrapped.settings.episode_steps + 1)):
        actions = np.array([policy(row) for policy, row in zip(policies, a[0], strict=True)])
        a, b = native.step(actions), singles.step(actions)
        same_step(a, b, False)
        hits += int(a[4]["hits"].sum())
    assert hits > 0


@pytest.mark.parametrize("mode", list(AutoresetMode))
def test_a_runaway_in_the_batch_ends_its_game_as_the_single_env_ends_it(mode):
    """A viscous field beyond its range (set directly, as tests/test_env_protocol.py does) and the keys that feed
    each arm energy: every game runs away, terminated with info["stopped"], restarted as each autoreset mode says."""
    from armgame.env.variants import ReachVariant

    n, kwargs = 3, {"time_limit": 6.0, "observation_dtype": "float64"}
    beyond = ReachVariant(field="viscous", field_strength=10.0)
    native = gym.make_vec(REACH, num_envs=n, vectorization_mode="vector_entry_point", autoreset_mode=mode, **kwargs)
    native.unwrapped.variant = beyond
    singles = SyncVectorEnv([lambda: gym.make(REACH, **kwargs) for _ in range(n)], autoreset_mode=mode)
    for env in singles.envs:
        env.unwrapped.variant = beyond
    a, b = native.reset(seed=8), singles.reset(seed=8)
    stops = 0
    for _ in range(400):
        if mode is AutoresetMode.DISABLED and singles._autoreset_envs.any():
            mask = singles._autoreset_envs.copy()
            a, b = native.reset(options={"reset_mask": mask}), singles.reset(options={"reset_mask": mask})
            assert np.abs(a[0] - b[0]).max() <= 1e-9
        w = a[0][:, 2:4]
        actions = np.column_stack([w[:, 0] > 0, w[:, 0] <= 0, w[:, 1] > 0, w[:, 1] <= 0]).astype(np.int64)
        a, b = native.step(actions), singles.step(actions)
        same_step(a, b, False)
        if a[2].any():
            stops += int(a[2].sum())
            assert not (a[2] & a[3]).any()
            info = a[4]["final_info"] if mode is AutoresetMode.SAME_STEP else a[4]
            assert all("past 34.4 rad/s" in info["stopped"][i] for i in np.flatnonzero(a[2]))
    assert stops >= n


def test_a_delayed_observation_is_the_one_delay_steps_old():
    """The ring's arithmetic on its own (the comparison above would pass if both sides lost the delay)."""
    plain = ReachV1VectorEnv(3, observation_dtype="float64")
    delayed = ReachV1VectorEnv(3, observation_dtype="float64", observation_delay=2)
    first = plain.reset(seed=1)[0]
    assert (delayed.reset(seed=1)[0] == first).all()
    seen = [first, first]
    actions = np.ones((3, 4))
    for _ in range(6):
        now = plain.step(actions)[0]
        assert (delayed.step(actions)[0] == seen[-2]).all() and not (now == seen[-2]).all()
        seen.append(now)
    with pytest.raises(EnvArgumentError, match="observation_delay"):
        ReachV1VectorEnv(2, observation_delay=101)


def test_a_reset_mask_is_checked_as_gymnasium_checks_it():
    envs = ReachV1VectorEnv(3)
    with pytest.raises(EnvArgumentError, match="first reset"):
        envs.reset(options={"reset_mask": np.array([True, False, False])})
    envs.reset(seed=0)
    for mask in ([True, False, True], np.array([1, 0, 1]), np.zeros(3, dtype=bool), np.ones(2, dtype=bool)):
        with pytest.raises(EnvArgumentError, match="reset_mask"):
            envs.reset(options={"reset_mask": mask})
    with pytest.raises(EnvArgumentError, match="unknown reset option"):
        envs.reset(options={"protocol": "curl"})


def test_disabled_autoreset_asks_for_a_masked_reset():
    envs = ReachV1VectorEnv(2, time_limit=0.1, autoreset_mode="Disabled")
    envs.reset(seed=0)
    for _ in range(5):
        *_, truncated, _ = envs.step(np.zeros((2, 4)))
    assert truncated.all()
    with pytest.raises(gym.error.ResetNeeded, match="reset_mask"):
        envs.step(np.zeros((2, 4)))
    envs.reset(options={"reset_mask": np.array([True, True])})
    envs.step(np.zeros((2, 4)))


def test_the_vector_env_renders_each_games_frame_as_the_single_env_does():
    envs = gym.make_vec("armgame/Reach-v0", num_envs=2, vectorization_mode="vector_entry_point",
                        render_mode="rgb_array", render_size=(120, 90))
    singles = SyncVectorEnv([lambda: gym.make("armgame/Reach-v0", render_mode="rgb_array", render_size=(120, 90))
                             for _ in range(2)])
    envs.reset(seed=3)
    singles.reset(seed=3)
    for _ in range(10):
        actions = np.array([[1, 0, 1, 0], [0, 1, 0, 0]])
        envs.step(actions)
        singles.step(actions)
    frames, expected = envs.render(), singles.render()
    assert len(frames) == 2 and frames[0].shape == (90, 120, 3)
    assert all(np.array_equal(f, g) for f, g in zip(frames, expected, strict=True))
    assert not np.array_equal(frames[0], frames[1])  # two games, two pictures
    envs.close()


# ------------------------------------------------------------------ CenterOut-v1
def test_a_random_policy_starts_center_out_trials_and_episodes_end_after_their_trials():
    env = gym.make(CENTER_OUT, continue_run=True)
    env.action_space.seed(0)
    obs, info = env.reset(seed=2)
    trials, episodes, reaches, steps = [], 0, [], 0
    while episodes < 2:
        obs, _, terminated, truncated, info = env.step(env.action_space.sample())
        steps += 1
        assert obs in env.observation_space and not truncated
        reaches += info.get("reaches", [])
        if terminated:
            episodes += 1
            trials.append(info["trial"])
            obs, info = env.reset()  # the same run goes on at its next trial
            assert info["trial"] == trials[-1] and obs[14] == 0.0
    assert trials == [8, 16] and len(reaches) == 16
    assert steps < 16 * (1.0 + 3.0 + 0.1) / 0.02  # each trial starts after its delay and ends by its time-out
    assert env.unwrapped.session.config.seed == 2  # one run


def test_block_episodes_follow_the_protocols_blocks():
    protocol = Protocol("short", (Block("baseline", 2), Block("exposure", 3)))
    env = gym.make(CENTER_OUT, protocol=protocol, episode_trials="block", continue_run=True)
    env.action_space.seed(1)
    env.reset(seed=5)
    blocks = []
    for _ in range(3):
        start, terminated = env.unwrapped.session.block.name, False
        while not terminated:
            *_, terminated, _, info = env.step(env.action_space.sample())
        blocks.append((start, info["trials_done"]))
        env.reset()
    # The run's last trial ends it: the third episode is a new run, drawn from the env's generator.
    assert blocks == [("baseline", 2), ("exposure", 5), ("baseline", 2)]
    assert env.unwrapped.session.config.seed != 5


def play_center_out(env, steps: int | None = None) -> dict:
    """Random keys until the episode ends (or for ``steps`` steps); the last info."""
    terminated, done = False, 0
    while not terminated and done != steps:
        *_, terminated, _, info = env.step(env.action_space.sample())
        done += 1
    return info


def test_an_unseeded_center_out_reset_starts_a_fresh_run_unless_asked_to_continue():
    protocol = Protocol("short", (Block("baseline", 2), Block("exposure", 3)))
    fresh = gym.make(CENTER_OUT, protocol=protocol, episode_trials="block")
    going_on = gym.make(CENTER_OUT, protocol=protocol, episode_trials="block", continue_run=True)
    for env in (fresh, going_on):
        env.action_space.seed(1)
        env.reset(seed=5)
        play_center_out(env)
    obs, info = fresh.reset()
    assert fresh.unwrapped.session.config.seed != 5 and info == {"trial": 0, "trials_done": 0, "hits": 0,
                                                                  "block": "baseline"}
    assert obs[14] == obs[15] == 0.0  # a hold, just begun
    obs, info = going_on.reset()
    assert going_on.unwrapped.session.config.seed == 5 and info["trial"] == 2 and info["block"] == "exposure"
    # The trial ended within the last step, which ran on in the next trial's hold, the arm taken home.
    assert obs[14] == 0.0 and 0.0 <= obs[15] < going_on.unwrapped.decision_time
    # Mid-episode (the arm on its way, the trial under way) no reset goes on with it: a new run.
    for env in (fresh, going_on):
        seed = env.unwrapped.session.config.seed
        for _ in range(60):  # past the longest delay (1 s), short of a hit's 0.2 s in the target
            *_, terminated, truncated, _ = env.step(env.action_space.sample())
        assert not (terminated or truncated) and env.unwrapped.session.phase == REACH_PHASE  # a reach under way
        obs, info = env.reset()
        session = env.unwrapped.session
        assert session.config.seed != seed and session.steps == 0 and info["trial"] == 0
        assert obs[2] == obs[3] == 0.0 and obs[14] == obs[15] == 0.0  # at rest, a hold just begun
    with pytest.raises(EnvArgumentError, match="continue_run"):
        gym.make(CENTER_OUT, continue_run="yes")


def test_center_out_dense_reward_is_progress_toward_the_shown_target():
    env = gym.make(CENTER_OUT, time_cost=0.5)
    base = env.unwrapped
    env.reset(seed=4)
    session = base.session
    total, starts, action = 0.0, [], np.array([0, 0, 0, 0])
    for step in range(400):
        shown = (session.trial_index, session.phase)
        edge = edge_of(session.cursor, session.rules.target)
        _, reward, *_ = env.step(np.array([1, 0, 0, 1]) if step % 50 < 10 else action)
        hits_bonus = sum(r["hit"] for r in _[-1].get("reaches", []))
        after = edge_of(session.cursor, session.rules.target)
        expected = (10.0 * (edge - after) if (session.trial_index, session.phase) == shown else 0.0) \
            + hits_bonus - 0.5 * 0.02
        assert reward == pytest.approx(expected, abs=1e-12)
        total += reward
        starts.append(shown)
    assert len(set(starts)) >= 4  # go cues and trial ends were crossed


def test_the_center_out_vector_env_is_sync_vector_env_of_v1_envs():
    envs = gym.make_vec(CENTER_OUT_CONTINUOUS, num_envs=3, autoreset_mode="SameStep", episode_trials=1)
    singles = SyncVectorEnv([lambda: gym.make(CENTER_OUT_CONTINUOUS, episode_trials=1) for _ in range(3)],
                            autoreset_mode="SameStep")
    envs.action_space.seed(0)
    a, b = envs.reset(seed=9), singles.reset(seed=9)
    assert data_equivalence(a, b, exact=True)
    ended = 0
    for _ in range(300):
        actions = envs.action_space.sample()
        a, b = envs.step(actions), singles.step(actions)
        assert data_equivalence(a[:4], b[:4], exact=True)
        assert repr(a[4]) == repr(b[4])  # a reach's measures hold NaN where they do not apply: NaN != NaN
        ended += int(a[2].sum())
    assert ended >= 3
    with pytest.raises(EnvArgumentError):
        gym.make_vec(CENTER_OUT, num_envs=2, autoreset_mode="Later")
    with pytest.raises(EnvArgumentError, match="trial_start"):
        gym.make_vec(CENTER_OUT, num_envs=2, trial_start="never")


# ------------------------------------------------------------------ learnable
def test_a_small_evolution_strategy_clearly_beats_random_play():
    es = example("train_es")
    policy, history = es.cem(generations=20, population=32, seconds=3.0, seed=0)
    learned = es.hits_per_game(policy, games=8, seconds=20.0, seed=100)
    random = es.hits_per_game(None, games=8, seconds=20.0, seed=100)
    assert history[-1][1] > history[0][1]  # the population's return rose
    assert learned.mean() >= 1.0 and learned.mean() >= 4 * random.mean(), (learned, random)


def test_the_sb3_adapter_trains_ppo():
    pytest.importorskip("stable_baselines3")  # the rl extra, not the test extra: run where it is installed
    from stable_baselines3 import PPO
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    from armgame.env.sb3 import make_sb3_vec_env

    sb3_check_env(gym.make(REACH).unwrapped, warn=True)
    envs = make_sb3_vec_env(REACH, 4, seed=0, time_limit=0.2)
    obs = envs.reset()
    assert obs.shape == (4, 15)
    dones = np.zeros(4, dtype=bool)
    for _ in range(10):
        obs, _, dones, infos = envs.step(np.ones((4, 4), dtype=np.int8))
    assert dones.all() and all("terminal_observation" in i and i["TimeLimit.truncated"] for i in infos)
    assert obs[:, 14].tolist() == [1.0] * 4  # the next games already began
    PPO("MlpPolicy", envs, n_steps=16, batch_size=32, device="cpu").learn(64)


@pytest.mark.parametrize("env_id", [REACH, CONTINUOUS, CENTER_OUT])
def test_float64_observations_on_request_are_the_float32_ones_unrounded(env_id):
    wide, narrow = gym.make(env_id, observation_dtype="float64"), gym.make(env_id)
    assert wide.observation_space.dtype == np.float64 and narrow.observation_space.dtype == np.float32
    wide.action_space.seed(2)
    a, b = wide.reset(seed=2)[0], narrow.reset(seed=2)[0]
    for _ in range(50):
        action = wide.action_space.sample()
        a, b = wide.step(action)[0], narrow.step(action)[0]
        assert a.dtype == np.float64 and a in wide.observation_space
        assert a.astype(np.float32).tobytes() == b.tobytes()
    if env_id != CENTER_OUT:
        envs = gym.make_vec(env_id, num_envs=2, observation_dtype=np.float64)
        assert envs.reset(seed=0)[0].dtype == np.float64
    with pytest.raises(EnvArgumentError, match="observation_dtype"):
        gym.make(env_id, observation_dtype="float16")
