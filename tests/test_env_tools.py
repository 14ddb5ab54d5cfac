"""The tools a researcher reaches for around the envs: Gymnasium's ``RecordVideo`` (moviepy: the ``video``
extra, and the test extra, so this runs wherever the suite does) and Stable-Baselines3's ``VecMonitor``
and ``evaluate_policy`` over the adapter (the ``rl`` extra: skipped without SB3, run where it is)."""

from __future__ import annotations

import warnings

import gymnasium as gym
import numpy as np
import pytest

import armgame.env  # noqa: F401  (registers the ids)

REACH = "armgame/Reach-v1"


def test_record_video_records_a_reach_v1_game_at_the_envs_frame_rate(tmp_path):
    pytest.importorskip("moviepy", reason="the test and video extras install moviepy: pip install -e '.[test]'")
    import imageio_ffmpeg  # moviepy's own ffmpeg
    from gymnasium.wrappers import RecordVideo

    folder = tmp_path / "videos"
    env = RecordVideo(gym.make(REACH, render_mode="rgb_array", time_limit=0.5, render_size=(160, 120)), str(folder),
                      episode_trigger=lambda episode: True)
    env.action_space.seed(0)
    env.reset(seed=0)
    steps, truncated = 0, False
    while not truncated:
        *_, truncated, _ = env.step(env.action_space.sample())
        steps += 1
    env.close()  # writes the file
    (video,) = folder.iterdir()
    frames = imageio_ffmpeg.read_frames(str(video))
    meta = next(frames)
    frames.close()
    assert steps == 25 and video.name == "rl-video-episode-0.mp4"
    assert meta["size"] == (160, 120) and meta["fps"] == 50.0  # the env's render_fps: one frame a decision
    assert imageio_ffmpeg.count_frames_and_secs(str(video))[0] == steps + 1  # the reset's frame and each step's


class Keys:
    """A fixed policy for SB3's ``evaluate_policy``: the same keys held in every game."""

    def __init__(self, keys: list[int]) -> None:
        self.keys = np.array(keys, dtype=np.int8)

    def predict(self, observation, state=None, episode_start=None, deterministic=False):
        return np.tile(self.keys, (len(observation), 1)), None


def test_evaluate_policy_through_vec_monitor_over_the_adapter_warns_nothing_and_scores_each_game():
    pytest.importorskip("stable_baselines3")  # the rl extra, not the test extra: run where it is installed
    from stable_baselines3.common.evaluation import evaluate_policy
    from stable_baselines3.common.vec_env import VecMonitor

    from armgame.env.sb3 import make_sb3_vec_env

    policy, kwargs = Keys([1, 0, 0, 1]), {"time_limit": 0.2}
    with pytest.warns(UserWarning, match="Monitor"):  # SB3's warning, which the wrapping below avoids
        evaluate_policy(policy, make_sb3_vec_env(REACH, 3, seed=0, **kwargs), n_eval_episodes=3)
    envs = VecMonitor(make_sb3_vec_env(REACH, 3, seed=0, **kwargs), info_keywords=("hits",))
    episodes = []

    def keep(local_vars: dict, _: dict) -> None:
        if local_vars["done"]:
            episodes.append(local_vars["info"]["episode"])

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        returns, lengths = evaluate_policy(policy, envs, n_eval_episodes=6, return_episode_rewards=True,
                                           callback=keep)
    # The same games one by one: game i is seeded i, its second game seeded by its own generator.
    expected = []
    singles = [gym.make(REACH, **kwargs) for _ in range(3)]
    for game in range(2):
        for i, env in enumerate(singles):
            env.reset(seed=i if game == 0 else None)
            total, truncated = 0.0, False
            while not truncated:
                _, reward, _, truncated, info = env.step(policy.keys)
                total += reward
            expected.append((total, info["hits"]))
    assert lengths == [10] * 6 and [e["l"] for e in episodes] == lengths
    assert returns == pytest.approx([r for r, _ in expected], rel=1e-5)
    assert [e["hits"] for e in episodes] == [h for _, h in expected]
    assert len(set(returns)) > 1  # six games, not one counted six times
