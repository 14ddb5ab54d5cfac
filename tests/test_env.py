"""The Gymnasium envs: Gymnasium's own checker, determinism, an episode is a game, bots as policies."""

import doctest
import json
import math
import os
import subprocess
import sys
import warnings

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import armgame.env
from armgame.env.policies import BotPolicy
from armgame.env.reach import EnvArgumentError, ReachEnv, speed_bound
from armgame.game.bots import ReachingBot, play_bot
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession

REACH, CONTINUOUS = "armgame/Reach-v0", "armgame/ReachContinuous-v0"


def rollout(env, seed, steps, action_seed=0):
    """Observations, rewards, truncations and infos of a random-action run, reset on each episode end."""
    env.action_space.seed(action_seed)
    obs, info = env.reset(seed=seed)
    out = [(obs, 0.0, False, info)]
    for _ in range(steps):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        assert terminated is False
        out.append((obs, reward, truncated, info))
        if truncated:
            obs, info = env.reset()
            out.append((obs, 0.0, False, info))
    return out


def test_ids_are_registered_by_the_package():
    assert set(armgame.env.ENV_IDS) <= set(gym.registry)
    assert gym.spec(REACH).entry_point == "armgame.env.reach:ReachEnv"
    assert gym.spec(CONTINUOUS).vector_entry_point == "armgame.env.vector:reach_vector_env"


@pytest.mark.parametrize(("env_id", "kwargs"), [(REACH, {}), (REACH, {"reset_key": True}),
                                               (REACH, {"decision_steps": 1, "time_limit": 2.0}),
                                               (REACH, {"decision_steps": 7, "time_limit": 0.23}),  # 0.232 s
                                               (CONTINUOUS, {}), (CONTINUOUS, {"reset_key": True})])
def test_gymnasiums_checker_passes_without_a_warning(env_id, kwargs):
    env = gym.make(env_id, **kwargs)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # Gymnasium's checker reports its doubts as warnings
        check_env(env.unwrapped)  # renders in both modes too (SDL's dummy drivers)
    env.close()


def test_the_same_seed_gives_the_same_rollout_bit_for_bit():
    a = rollout(gym.make(REACH, time_limit=1.0), seed=5, steps=120)
    b = rollout(gym.make(REACH, time_limit=1.0), seed=5, steps=120)
    assert len(a) == len(b) == 123  # two episode ends of 50 steps each, each followed by a reset
    for (oa, ra, ta, ia), (ob, rb, tb, ib) in zip(a, b, strict=True):
        assert oa.tobytes() == ob.tobytes() and ra == rb and ta == tb and ia == ib
    other = rollout(gym.make(REACH, time_limit=1.0), seed=6, steps=1)
    assert other[0][0][8:10].tolist() != a[0][0][8:10].tolist()  # another seed, another first target


def test_an_episode_is_the_game_of_its_seed_and_replays_from_its_timeline():
    env = gym.make(REACH, time_limit=3.0, decision_steps=3)
    env.action_space.seed(1)
    obs, _ = env.reset(seed=10)
    session = env.unwrapped.session
    assert session.config.seed == 10 and (obs[8], obs[9]) == (session.rules.target.x, session.rules.target.y)
    assert GameSession(GameConfig(seed=10)).rules.target == session.rules.target  # armgame play --seed 10
    total, steps, truncated = 0.0, 0, False
    while not truncated:
        obs, reward, _, truncated, info = env.step(env.action_space.sample())
        total, steps = total + reward, steps + 1
    assert steps == env.unwrapped.settings.episode_steps == 250  # 750 physics steps, 3 a step
    assert obs[10] == 0.0 and session.over
    replay = GameSession(GameConfig(seed=10, time_limit=3.0)).play(session.timeline)
    assert replay == session.result() and replay.score == info["score"] == total
    with pytest.raises(gym.error.ResetNeeded):
        env.unwrapped.step(env.action_space.sample())


def test_the_reward_is_hits_minus_the_reset_cost():
    env = gym.make(REACH, reset_key=True, time_limit=20.0)
    assert env.action_space == gym.spaces.MultiBinary(5)
    keys_only = gym.make(REACH, time_limit=20.0)
    policy = BotPolicy("model", keys_only)
    obs, _ = env.reset(seed=2)
    rewards, info = [], {}
    for step in range(1000):
        reset = step % 150 == 149
        action = np.append(np.zeros(4, np.int8) if reset else policy(obs), 1 if reset else 0)
        obs, reward, _, _, info = env.step(action)
        rewards.append(reward)
        if reset:  # back at rest in the start posture, muscles relaxed; the bot starts over from there
            assert obs[:8].tolist() == [math.radians(45.0), math.radians(90.0)] + [0.0] * 6
            policy = BotPolicy("model", keys_only)
    assert info["resets"] == 6 and info["hits"] >= 6
    assert sum(rewards) == info["hits"] - info["resets"] and set(rewards) <= {-1.0, 0.0, 1.0}
    assert info["score"] >= sum(rewards)  # the game's score never drops below 0, the return may


def test_a_reset_without_a_seed_draws_the_game_from_the_envs_generator():
    env = gym.make(REACH)
    env.reset(seed=7)
    first = env.unwrapped.session.config.seed
    env.reset()
    drawn = env.unwrapped.session.config.seed
    env.reset(seed=7)
    env.reset()
    assert first == 7 and drawn != 7 and env.unwrapped.session.config.seed == drawn


@pytest.mark.parametrize("name", ["model", "naive"])
def test_a_bot_scores_through_the_env_what_it_scores_in_the_game(name):
    config = GameConfig(seed=4, time_limit=6.0)
    game = play_bot(config, name)  # the game's bot, deciding every physics step
    env = gym.make(REACH, time_limit=6.0, decision_steps=1)
    policy = BotPolicy(name, env)
    for _ in range(2):  # the second episode checks that the policy starts afresh
        obs, _ = env.reset(seed=4)
        total, truncated, info = 0.0, False, {}
        while not truncated:
            obs, reward, _, truncated, info = env.step(policy(obs))
            total += reward
        assert total == info["hits"] == game.result().hits >= 1
        assert env.unwrapped.session.timeline == game.timeline


def test_a_bot_at_the_envs_decision_step_plays_the_same_game_as_in_the_game():
    env = gym.make(REACH, time_limit=6.0)  # 20 ms decisions
    policy = BotPolicy("model", env)
    obs, _ = env.reset(seed=4)
    truncated = False
    while not truncated:
        obs, _, _, truncated, info = env.step(policy(obs))
    game = play_bot(GameConfig(seed=4, time_limit=6.0), ReachingBot("model", True, control_period=0.02))
    assert env.unwrapped.session.timeline == game.timeline and info["hits"] == game.result().hits >= 1
    with pytest.raises(ValueError, match="control_period"):
        BotPolicy(ReachingBot("model", True), env)


def test_no_action_drives_the_arm_past_the_speed_bound():
    env = gym.make(REACH, time_limit=8.0, decision_steps=10)
    bound = speed_bound(env.unwrapped.config)
    assert 30.0 < bound < 40.0
    fastest = 0.0
    # Flat out one way, then the other, and random presses: the spins that build up speed.
    for pattern in ([1, 0, 1, 0], [1, 0, 0, 1], [0, 1, 1, 0]):
        obs, _ = env.reset(seed=0)
        for step in range(200):
            action = np.array(pattern if step < 100 else [1 - p for p in pattern], dtype=np.int8)
            obs, *_ = env.step(action)
            assert obs in env.observation_space
            fastest = max(fastest, abs(obs[2]), abs(obs[3]))
    assert 3.0 < fastest < bound


def test_bad_arguments_and_actions_are_refused_in_one_line():
    for kwargs, word in [({"decision_steps": 0}, "decision_steps"), ({"time_limit": -1.0}, "time_limit must be a"),
                         ({"time_limit": "60"}, "time_limit"), ({"render_mode": "ascii"}, "render_mode"),
                         ({"render_size": (0, 10)}, "render_size"), ({"config": {}}, "config"),
                         ({"reset_key": "yes"}, "reset_key")]:
        with pytest.raises(ValueError, match=word) as caught:
            ReachEnv(**kwargs)
        assert "\n" not in str(caught.value)
    env = ReachEnv()
    with pytest.raises(EnvArgumentError, match="seed"):
        env.reset(seed=-1)
    env.reset(seed=1)
    for action in ([1, 0, 1], [2, 0, 0, 0], np.full(4, 0.5)):
        with pytest.raises(ValueError, match="zeros or ones"):
            env.step(action)


def test_rgb_array_frames_show_the_game():
    from armgame.ui.render import PALETTES, GameRenderer

    HAND, TARGET = PALETTES["okabe-ito"].hand, PALETTES["okabe-ito"].target

    env = gym.make(REACH, render_mode="rgb_array", render_size=(300, 200))
    obs, _ = env.reset(seed=3)
    frame = env.render()
    assert frame.shape == (200, 300, 3) and frame.dtype == np.uint8
    session = env.unwrapped.session
    view = GameRenderer(session.muscles.keys, ("",) * 4).layout((300, 200), session).view  # the scene's place
    x, y = view.to_screen(obs[8], obs[9])
    assert tuple(frame[y, x]) == TARGET
    hx, hy = env.unwrapped.session.hand()
    x, y = view.to_screen(hx, hy)
    assert tuple(frame[y, x]) == HAND
    env.close()


def test_the_docstring_examples_run():
    import armgame.env.policies
    import armgame.env.reach
    import armgame.env.vector

    for module in (armgame.env.reach, armgame.env.policies, armgame.env.vector):
        failed, attempted = doctest.testmod(module)
        assert attempted >= 2 and failed == 0, module.__name__


@pytest.mark.parametrize("env_id", ["armgame/Reach-v0", "armgame/CenterOut-v0"])
def test_pygame_is_imported_only_to_render_and_never_starts_the_mixer(env_id):
    code = """
import json, os, sys
import armgame
report = {"armgame": sorted(m for m in ("gymnasium", "pygame") if m in sys.modules)}
import gymnasium as gym
import armgame.env
env_id = sys.argv[1]
env = gym.make(env_id)
env.reset(seed=1)
env.step(env.action_space.sample())
report["headless"] = "pygame" in sys.modules
for mode in ("rgb_array", "human"):
    env = gym.make(env_id, render_mode=mode, render_size=(64, 64))
    env.reset(seed=1)
    env.step(env.action_space.sample())
    env.render()
    import pygame
    report[mode] = [pygame.mixer.get_init(), pygame.display.get_init()]
    env.close()
print(json.dumps(report))
"""
    env = dict(os.environ, SDL_VIDEODRIVER="dummy", SDL_AUDIODRIVER="dummy")
    run = subprocess.run([sys.executable, "-c", code, env_id], capture_output=True, text=True, env=env, check=True)
    report = json.loads(run.stdout.strip().splitlines()[-1])
    assert report == {"armgame": [], "headless": False, "rgb_array": [None, False], "human": [None, True]}


def test_the_envs_muscle_tables_are_the_games_muscles():
    """Reach's and CenterOut's docstrings (each env's page, as Gymnasium's envs document themselves) each spell out
    the action's muscles: their keys, names and torques are ``game.muscles.DEFAULT_MUSCLES``', so a muscle changed
    there fails here until both tables say so."""
    import re

    from armgame.env.center_out import CenterOutEnv
    from armgame.game.muscles import DEFAULT_MUSCLES

    def torque(spec) -> str:
        joint, value = ("shoulder", spec.moment[0]) if spec.moment[0] else ("elbow", spec.moment[1])
        return f"{joint} {value:+g}"

    expected = [(str(i), m.key, m.name, torque(m)) for i, m in enumerate(DEFAULT_MUSCLES)]
    for env in (ReachEnv, CenterOutEnv):
        rows = re.findall(r"^\s*\| (\d)\s+\| (\w)\s+\| ([a-z ]+?)\s+\| (\w+ [+-][\d.]+)\s+\|$", env.__doc__, re.M)
        assert rows == expected, env.__name__
