"""The separating tier (``armgame.env.suite.TIER``): what each id's observation hides, that its game is its suite
game's hit for hit, that its games verify, and that docs/programs.md's tier table is the committed results."""

import math
import warnings
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import armgame.env  # noqa: F401  (registers the ids)
from armgame.env.base import EnvArgumentError
from armgame.env.policies import bot_policy
from armgame.env.record import replay_of
from armgame.env.suite import SUITE, TIER, TIER_GAMES, tier_ids
from armgame.env.vector_common import SingleEnvsVectorEnv
from armgame.records.replay import Replay

ROOT = Path(__file__).resolve().parent.parent
TARGET, MOTION = [12, 13], [2, 3, 4, 5, 6, 7, 10, 11]


def game_id(env_id: str) -> str:
    return f"armgame/{TIER_GAMES[env_id.split('/')[1].removesuffix('-v1')]}-v1"


def play_both(env_id: str, seed: int, steps: int):
    """The tier id and its suite game stepped with the same actions (the model bot's, which reads the observation,
    so it reads the suite game's): the observations of each, and the tier env's infos and the env itself."""
    tier = gym.make(env_id, time_limit=steps * 0.02)
    game = gym.make(game_id(env_id), time_limit=steps * 0.02)
    seen, truth, infos = [tier.reset(seed=seed)[0]], [game.reset(seed=seed)[0]], []
    bot = bot_policy("model", game)
    done = False
    while not done:
        action = bot(truth[-1])
        a, ra, ta, ua, ia = tier.step(action)
        b, rb, tb, ub, ib = game.step(action)
        assert (ra, ta, ua, ia) == (rb, tb, ub, ib)  # the reward and the bookkeeping are the game's
        seen.append(a)
        truth.append(b)
        infos.append(ia)
        done = ta or ua
    return np.array(seen), np.array(truth), infos, tier


@pytest.mark.parametrize("env_id", tier_ids())
def test_gymnasiums_checker_passes_on_every_tier_id_and_its_arguments_are_the_envs(env_id):
    env = gym.make(env_id)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped, skip_render_check=True)
    name = env_id.split("/")[1].removesuffix("-v1")
    for argument, value in TIER[name].items():
        assert getattr(env.unwrapped.variant, argument) == value
    for argument, value in SUITE.get(TIER_GAMES[name], {}).items():  # the suite game's own arguments, all kept
        assert getattr(env.unwrapped.variant, argument) == value
    # The batch hides nothing: make_vec steps single envs, each the single env's game.
    assert isinstance(gym.make_vec(env_id, num_envs=8).unwrapped, SingleEnvsVectorEnv)


def test_a_hidden_target_is_seen_only_in_the_first_observations_after_it_appears():
    seen, truth, infos, _ = play_both("armgame/ReachMemory-v1", 3, 500)
    hits = [0] + [info["hits"] for info in infos]
    assert hits[-1] >= 5
    appeared = 0
    for t in range(len(seen)):
        if hits[t] != hits[t - 1 if t else 0]:
            appeared = t  # a hit in the step before observation t: its new target shows from t on
        shown = t - appeared < 5  # 0.1 s: five observations of 20 ms
        assert np.array_equal(seen[t, TARGET], truth[t, TARGET] if shown else [0.0, 0.0]), t
        rest = [i for i in range(15) if i not in TARGET]
        assert np.array_equal(seen[t, rest], truth[t, rest]), t


def test_with_positions_only_the_velocities_and_activations_read_zero_and_nothing_else_changes():
    seen, truth, _, _ = play_both("armgame/ReachPositions-v1", 4, 300)
    assert not seen[:, MOTION].any() and np.abs(truth[1:, MOTION]).max() > 0.5
    rest = [i for i in range(15) if i not in MOTION]
    assert np.array_equal(seen[:, rest], truth[:, rest])


def test_a_hidden_target_with_a_dwell_plays_reachholds_game_hit_for_hit():
    seen, _, infos, _ = play_both("armgame/ReachMemoryHold-v1", 5, 400)
    assert infos[-1]["hits"] >= 3
    assert (seen[:, TARGET] == 0).all(axis=1).sum() > len(seen) // 2  # hidden most of the time


def test_what_is_hidden_is_hidden_before_the_delay():
    late = gym.make("armgame/Reach-v1", target_shown=0.04, observation_delay=3, time_limit=1.0)
    now = gym.make("armgame/Reach-v1", target_shown=0.04, time_limit=1.0)
    seen, truth = [late.reset(seed=2)[0]], [now.reset(seed=2)[0]]
    for action in np.random.default_rng(1).integers(0, 2, (20, 4)):
        seen.append(late.step(action)[0])
        truth.append(now.step(action)[0])
    for t, observation in enumerate(seen):
        assert np.array_equal(observation, truth[max(0, t - 3)]), t
    assert truth[1][TARGET].any() and not truth[2][TARGET].any()  # 0.04 s: two observations


@pytest.mark.parametrize("env_id", tier_ids())
def test_a_tier_game_is_recorded_and_verifies(env_id):
    _, _, infos, env = play_both(env_id, 11, 300)
    info = infos[-1]
    replay = Replay.from_bytes(replay_of(env, driver="model bot").to_bytes())
    assert replay.result.hits == info["hits"] >= 3
    assert replay.verify()[0]


def test_bad_hiding_arguments_are_refused_in_one_line():
    for kwargs, words in (({"target_shown": -0.1}, "target_shown"), ({"target_shown": math.inf}, "target_shown"),
                          ({"target_shown": "0.1"}, "target_shown"), ({"positions_only": 0}, "positions_only"),
                          ({"positions_only": None}, "positions_only")):
        with pytest.raises(EnvArgumentError, match=words) as caught:
            gym.make("armgame/Reach-v1", **kwargs)
        assert "\n" not in str(caught.value)
